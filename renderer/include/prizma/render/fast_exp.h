#pragma once
// exp_approx: e^x in float by Cody–Waite range reduction and a degree-6 polynomial, written in plain
// float arithmetic so that a loop over a path's lanes vectorises and gives the same bits at every
// SIMD level (std::exp is a libm call per lane). Relative error ≤ 2·10⁻⁷ (tests/render/
// test_spectral_mis.cpp); x is clamped to [−87, 88] (e^−87 ≈ 1.6·10⁻³⁸, the least normal float's
// order; NaN gives e^−87). Spectral MIS uses it for the lanes' transmittance ratios T_k/T_j, where
// an error of that size is below the float arithmetic of the weights themselves.
#include <bit>
#include <cstdint>

namespace prizma::render {

inline float exp_approx(float x) {
  x = x > -87.0f ? x : -87.0f;  // NaN → −87
  x = x < 88.0f ? x : 88.0f;
  // x = k·ln 2 + r, |r| ≤ ln 2 / 2; k rounded to nearest by the 1.5·2²³ trick (exact below 2²²).
  constexpr float kLog2e = 1.44269504088896341f, kRound = 12582912.0f;
  constexpr float kLn2Hi = 0.693145751953125f, kLn2Lo = 1.42860676533018704e-06f;
  const float k = (x * kLog2e + kRound) - kRound;
  const float r = (x - k * kLn2Hi) - k * kLn2Lo;
  // e^r by its Taylor polynomial to r⁶ (truncation ≤ |r|⁷/5040 ≈ 1.2·10⁻⁷ at |r| = ln 2 / 2).
  const float p =
      1.0f + r * (1.0f + r * (0.5f + r * (1.0f / 6.0f + r * (1.0f / 24.0f + r * (1.0f / 120.0f + r * (1.0f / 720.0f))))));
  const auto bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(k) + 127) << 23;  // 2^k, k ∈ [−126, 127]
  return p * std::bit_cast<float>(bits);
}

}  // namespace prizma::render
