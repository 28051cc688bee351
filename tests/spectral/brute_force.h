#pragma once
// Reference integration for the libspectral tests, independent of Spectrum's exact integrator.
#include "prizma/spectral/spectrum.h"

namespace prizma::spectral::test_support {

// Brute-force midpoint rule for ∫_lo^hi a·b dλ with n steps.
inline double midpoint(const Spectrum& a, const Spectrum& b, double lo, double hi, int n) {
  const double h = (hi - lo) / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = lo + (i + 0.5) * h;
    sum += a.eval(x) * b.eval(x);
  }
  return sum * h;
}

}  // namespace prizma::spectral::test_support
