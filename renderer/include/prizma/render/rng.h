#pragma once
// Rng: the per-sample random stream. Every (seed, pixel, sample index) triple gets its own PCG32
// stream (O'Neill 2014, pcg32 "XSH RR"), seeded through splitmix64 (Steele et al. 2014), so a
// render is independent of tiling and thread count and pixels never share streams (unlike VPT's
// linear hash 19x + 47y + 101s).
#include <cstdint>

namespace prizma::render {

// splitmix64 finaliser: a bijective 64-bit mix.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

class Rng {
 public:
  // The stream of sample `sample` of pixel `pixel` under `seed`.
  Rng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
    const std::uint64_t key = splitmix64(splitmix64(splitmix64(seed) ^ pixel) ^ sample);
    m_inc = (splitmix64(key ^ 0xDA3E39CB94B95BDBULL) << 1u) | 1u;
    m_state = 0;
    next_u32();
    m_state += key;
    next_u32();
  }

  std::uint32_t next_u32() {
    const std::uint64_t old = m_state;
    m_state = old * 6364136223846793005ULL + m_inc;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }

  // Uniform in the open interval (0, 1): (k + 0.5)·2^−24 for a 24-bit k, so −log(u) is finite and
  // 1 − u is never 0 either.
  float uniform() { return (static_cast<float>(next_u32() >> 8) + 0.5f) * 0x1p-24f; }
  // Uniform in (0, 1) with 53-bit resolution, for geometry.
  double uniform_double() {
    const std::uint64_t hi = next_u32() >> 5;  // 27 bits
    const std::uint64_t lo = next_u32() >> 6;  // 26 bits
    return (static_cast<double>((hi << 26) | lo) + 0.5) * 0x1p-53;
  }

 private:
  std::uint64_t m_state = 0;
  std::uint64_t m_inc = 1;
};

}  // namespace prizma::render
