// write_output_image through write_atomically's checked temporary: the bytes OpenImageIO writes are
// the file (read back), and a write that fails (a file-size limit) fails the image, for every format.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <OpenImageIO/imageio.h>

#include <csignal>
#include <fstream>
#include <sstream>
#include <string>

#include "prizma/spectral/output_image.h"
#include "prizma/spectral/error.h"
#include "spectral/relight_test_util.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

XyzImage gradient(int w, int h) {
  XyzImage img;
  img.width = w;
  img.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = static_cast<float>(x) / w, v = static_cast<float>(y) / h;
      img.xyz.insert(img.xyz.end(), {0.2f + 0.5f * u, 0.3f + 0.4f * v, 0.1f + 0.3f * u * v});
    }
  return img;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A file-size limit for the scope, SIGXFSZ ignored: a write past it fails with EFBIG.
struct FileSizeLimit {
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old);
    handler = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim = old;
    lim.rlim_cur = bytes;
    ok = ::setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, handler);
  }
  struct rlimit old {};
  void (*handler)(int) = nullptr;
  bool ok = false;
};

TEST(OutputImage, EveryFormatWritesThroughTheCheckedTemporaryAndReadsBack) {
  const fs::path dir = test::scratch_dir("output-formats");
  const XyzImage img = gradient(64, 48);
  for (const char* name : {"a.png", "a16.png", "a.tif", "a16.tiff", "a.exr"}) {
    OutputOptions opts;
    opts.bit_depth = std::string(name).find("16") != std::string::npos ? 16 : 8;
    write_output_image(dir / name, img, opts, {{"Software", "prizma test"}});
    auto in = OIIO::ImageInput::open((dir / name).string());
    ASSERT_TRUE(in) << name << ": " << OIIO::geterror();
    EXPECT_EQ(in->spec().width, 64) << name;
    EXPECT_EQ(in->spec().height, 48) << name;
    EXPECT_EQ(in->spec().get_string_attribute("Software"), "prizma test") << name;
    std::vector<float> px(64 * 48 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data())) << name << ": " << in->geterror();
    if (std::string(name) == "a.exr") {
      EXPECT_EQ(px, img.xyz);  // linear XYZ, bit for bit
    }
  }
  fs::remove_all(dir);
}

TEST(OutputImage, WriteBeyondFileSizeLimitFailsForEveryFormatAndKeepsTheOldFile) {
  const fs::path dir = test::scratch_dir("output-fsize");
  const XyzImage img = gradient(32, 24);
  for (const char* name : {"old.png", "old.tif", "old.exr"}) {
    const fs::path dest = dir / name;
    { std::ofstream(dest, std::ios::binary) << "old bytes"; }
    std::string msg;
    {
      FileSizeLimit limit(200);
      ASSERT_TRUE(limit.ok);
      try {
        write_output_image(dest, img, OutputOptions{}, {});
      } catch (const spectral::RuntimeError& e) {
        msg = e.what();
      }
    }
    EXPECT_EQ(msg, dest.string() + ": cannot write: File too large (the existing file is unchanged)") << name;
    EXPECT_EQ(read_all(dest), "old bytes") << name;
  }
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3);  // no temporaries
  fs::remove_all(dir);
}

}  // namespace
}  // namespace prizma::spectral
