#include "prizma/spectral/half_float.h"

#include <half.h>

namespace prizma::spectral {

void round_to_half(std::vector<float>& values) {
  for (float& v : values) v = static_cast<float>(half(v));
}

}  // namespace prizma::spectral
