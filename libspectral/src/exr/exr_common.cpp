// The spectral EXR layer's shared parts (exr_common.h).
#include "exr/exr_common.h"

#include <ImfChannelList.h>
#include <ImfThreading.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::exr {

// Threads for compressing and decompressing chunks. The count given to Imf::InputFile/OutputFile is
// only how many chunks may be in flight: the work runs on OpenEXR's global thread pool, which has no
// threads until it is given some, so without setGlobalThreadCount every file was decoded on one core
// (a 512×512, 32-bin, two-light PIZ file read in 1.35 s).
int io_threads() {
  static const int count = [] {
    const unsigned hc = std::thread::hardware_concurrency();
    const int n = static_cast<int>(std::clamp(hc, 1u, 8u));
    if (Imf::globalThreadCount() < n) Imf::setGlobalThreadCount(n);
    return n;
  }();
  return count;
}

// PIZ encodes 15–30 MB of floats per CPU second (a 24×24, 35-channel image: 5–7 ms, more than
// rendering it at 1 spp) and saved nothing on such renders (bench_peer.json at 1–256 spp: 81.96 KB
// PIZ, 82.33 KB uncompressed); below 1 MiB the most any compression could save is a few hundred KB.
constexpr std::size_t kUncompressedMaxBytes = std::size_t{1} << 20;

std::size_t stored_pixel_bytes(const Imf::Header& h) {
  const Imath::Box2i dw = h.dataWindow();
  const auto pixels = static_cast<std::size_t>(std::max(0, dw.max.x - dw.min.x + 1)) *
                      static_cast<std::size_t>(std::max(0, dw.max.y - dw.min.y + 1));
  std::size_t per_pixel = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
    per_pixel += it.channel().type == Imf::HALF ? sizeof(half) : sizeof(float);
  return pixels * per_pixel;
}

// The compression Prizma writes for a file of this header's size and channels.
Imf::Compression prizma_compression(const Imf::Header& h) {
  return stored_pixel_bytes(h) <= kUncompressedMaxBytes ? Imf::NO_COMPRESSION : Imf::PIZ_COMPRESSION;
}

bool valid_light_name(std::string_view name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

void check_finite(const std::vector<float>& values, int width, int bins, const std::string& what,
                  const std::string& path) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      const std::size_t pixel = k / static_cast<std::size_t>(bins);
      std::ostringstream os;
      os << what << ": " << (std::isnan(values[k]) ? "NaN" : "infinite value") << " at pixel ("
         << pixel % static_cast<std::size_t>(width) << ", " << pixel / static_cast<std::size_t>(width) << "), bin "
         << k % static_cast<std::size_t>(bins);
      throw InputError(path, os.str());
    }
  }
}

}  // namespace prizma::spectral::exr

namespace prizma::spectral {

int SpectralImage::find_light(std::string_view name) const {
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace prizma::spectral
