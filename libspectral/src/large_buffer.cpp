#include "prizma/spectral/large_buffer.h"

#include <sys/mman.h>

#include <cstdint>

namespace prizma::spectral {

void allocate_zeroed(std::vector<float>& plane, std::size_t n) {
  if (plane.capacity() < n) {
    std::vector<float>().swap(plane);
    plane.reserve(n);
#ifdef MADV_HUGEPAGE
    // The 2 MB-aligned interior of the new block (no value is read or written here).
    constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
    const auto begin = reinterpret_cast<std::uintptr_t>(plane.data());
    const std::uintptr_t first = (begin + kHuge - 1) / kHuge * kHuge;
    const std::uintptr_t last = (begin + n * sizeof(float)) / kHuge * kHuge;
    if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // NOLINT(performance-no-int-to-ptr)
#endif
  }
  plane.assign(n, 0.0f);
}

}  // namespace prizma::spectral
