#pragma once
// Allocating a large image plane: a 1024² × 32-bin plane is 128 MB, 32 k first-touch page faults in
// 4 KB pages. On a virtual machine those faults cost a third of a denoise; asked for in 2 MB pages
// (transparent huge pages, which Debian's default "madvise" mode gives on request) they are 64.
#include <cstddef>
#include <vector>

namespace prizma::spectral {

// Sizes `plane` to `n` zeros, asking for huge pages when it is allocated here (an empty vector). The
// advice changes no value: where huge pages are not offered, the plane is the same.
void allocate_zeroed(std::vector<float>& plane, std::size_t n);

}  // namespace prizma::spectral
