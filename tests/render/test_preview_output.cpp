// write_preview through write_atomically's checked temporary: a preview that cannot be written
// completely (a file-size limit) is a RuntimeError and the old file is untouched.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"

namespace fs = std::filesystem;

TEST(PreviewOutput, WriteBeyondFileSizeLimitFailsAndKeepsTheOldFile) {
  const fs::path dir = fs::temp_directory_path() / ("prizma-test-preview-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  prizma::spectral::SpectralImage image;
  image.width = 32;
  image.height = 24;
  image.bins = prizma::spectral::BinLayout::linear(400.0, 700.0, 6);
  prizma::spectral::TransportLayer layer;
  layer.name = "key";
  for (std::size_t k = 0; k < image.pixel_count() * 6; ++k) layer.data.push_back(static_cast<float>(k % 97) / 97.0f);
  image.lights.push_back(layer);
  const fs::path dest = dir / "preview.png";
  { std::ofstream(dest, std::ios::binary) << "old bytes"; }

  std::string msg;
  struct rlimit old {};
  ::getrlimit(RLIMIT_FSIZE, &old);
  const auto handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit lim = old;
  lim.rlim_cur = 200;  // bytes: the PNG is larger
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &lim), 0);
  try {
    prizma::render::write_preview(dest, image, {});
  } catch (const prizma::spectral::RuntimeError& e) {
    msg = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, handler);

  EXPECT_EQ(msg, dest.string() + ": cannot write: File too large (the existing file is unchanged)");
  std::ifstream in(dest, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "old bytes");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);  // no temporary
  // Without the limit the same call writes the preview.
  prizma::render::write_preview(dest, image, {});
  EXPECT_GT(fs::file_size(dest), 200u);
  fs::remove_all(dir);
}
