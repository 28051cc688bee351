// libFuzzer target: read_spectral_exr on arbitrary bytes written to a temporary .exr file.
// Inputs are capped at 64 KiB, and inputs whose header declares a data window of more than
// kMaxPixels pixels are skipped: a 500-byte file may declare 6697591×9 pixels, and reading it
// legitimately allocates and zero-fills ~700 MB before OpenEXR finds the data missing (20–40 s
// under ASan), which would only slow the fuzzer down. Attributes declaring more bytes than the file
// holds, or whose content disagrees with their size, are not skipped: the reader itself refuses
// them (docs/errors.md).
// InputError is the expected answer to a bad file; any other exception, a crash, undefined
// behaviour or an image that breaks the SpectralImage invariants is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

constexpr std::size_t kMaxInputBytes = 64 * 1024;
constexpr std::int64_t kMaxPixels = 1 << 14;  // × up to ~3000 channels in 64 KiB: ≤ 200 MB

// True when a "dataWindow" box2i attribute in the bytes declares more than kMaxPixels pixels.
bool declares_huge_window(std::string_view bytes) {
  static constexpr std::string_view kKey("dataWindow\0box2i\0", 17);
  for (std::size_t at = bytes.find(kKey); at != std::string_view::npos; at = bytes.find(kKey, at + 1)) {
    const std::size_t box = at + kKey.size() + 4;  // after the attribute's int32 size
    if (box + 16 > bytes.size()) return false;
    std::int32_t v[4];
    std::memcpy(v, bytes.data() + box, sizeof(v));
    const std::int64_t w = std::int64_t{v[2]} - v[0] + 1;
    const std::int64_t h = std::int64_t{v[3]} - v[1] + 1;
    if (w > 0 && h > 0 && (w > kMaxPixels || h > kMaxPixels || w * h > kMaxPixels)) return true;
  }
  return false;
}

void check_image(const prizma::spectral::SpectralImage& img) {
  PRIZMA_FUZZ_CHECK(img.width > 0 && img.height > 0, "%d x %d", img.width, img.height);
  PRIZMA_FUZZ_CHECK(!img.lights.empty(), "no light layers");
  const std::size_t n = img.pixel_count() * static_cast<std::size_t>(img.bins.size());
  for (const auto& light : img.lights) {
    PRIZMA_FUZZ_CHECK(light.data.size() == n, "light '%s' has %zu values, expected %zu", light.name.c_str(),
                      light.data.size(), n);
    PRIZMA_FUZZ_CHECK(light.variance.empty() || light.variance.size() == n, "light '%s' variance has %zu values",
                      light.name.c_str(), light.variance.size());
  }
  const auto& e = img.bins.edges_nm();
  for (std::size_t i = 1; i < e.size(); ++i) PRIZMA_FUZZ_CHECK(e[i] > e[i - 1], "edges not increasing at %zu", i);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInputBytes) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (declares_huge_window(bytes)) return 0;
  static const prizma::fuzz::ScratchDir dir("spectral_exr");
  const auto path = dir.path() / "input.exr";
  prizma::fuzz::write_file(path, bytes);
  prizma::fuzz::accepts("read_spectral_exr", [&] { check_image(prizma::spectral::read_spectral_exr(path)); });
  return 0;
}
