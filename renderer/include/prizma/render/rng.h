#pragma once
// Rng: the per-sample random stream. Every (seed, pixel, sample index) triple gets its own PCG32
// stream (O'Neill 2014, pcg32 "XSH RR"), seeded through splitmix64 (Steele et al. 2014), so a
// render is independent of tiling and thread count and pixels never share streams (unlike VPT's
// linear hash 19x + 47y + 101s).
//
// Sampler::Sobol (docs/renderer.md, "Samplers") gives the first kSobolDimensions draws of a path
// (uniform() / uniform_double() calls, in the order the path makes them) from a randomised
// quasi-Monte Carlo point instead, after pbrt-v4's PaddedSobolSampler (Pharr et al. 2023, §8.7):
// dimensions 2k, 2k+1 are the 2-D Sobol' (0,2)-sequence over the pixel's sample index, the index
// shuffled and each coordinate Owen-scrambled with seeds hashed from (seed, pixel, k) — Burley's
// hash-based nested uniform scramble (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
// Each point is uniform on [0,1)^d (the scramble adds a uniform random seed before a bijection), so
// every estimate stays unbiased; any 2^m samples of a pixel starting at a multiple of 2^m are a
// (0,m,2)-net in each dimension pair. A point depends on (seed, pixel, sample index) only, so sample
// ranges, shards, resume and thread counts give the same samples. Draws after the first
// kSobolDimensions, and next_u32(), always come from the PCG stream.
#include <cstdint>
#include <string>
#include <string_view>

namespace prizma::render {

// Where a path's first random numbers come from (scene field "sampler", --sampler).
enum class Sampler {
  Independent,  // all from the sample's PCG32 stream
  Sobol,        // the first kSobolDimensions from a padded, Owen-scrambled Sobol' point
};

// "independent" / "sobol"; parse_sampler throws InputError(input, …) for any other name.
std::string sampler_name(Sampler s);
Sampler parse_sampler(std::string_view name, std::string_view input = "sampler");

// splitmix64 finaliser: a bijective 64-bit mix.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

namespace sobol {

constexpr std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
  return (x >> 16) | (x << 16);
}

// The Laine–Karras permutation (Burley 2020's constants): bit b of the result depends on bits ≤ b
// only, and x + seed makes it uniform for a uniform seed.
constexpr std::uint32_t laine_karras(std::uint32_t x, std::uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}
// Burley's nested uniform scramble: Laine–Karras on the bit-reversed value, so bit b of the result
// depends on bits ≥ b only (an Owen-style scramble: aligned intervals of size 2^−m map onto aligned
// intervals) and, with a uniform random seed, the result is uniform.
constexpr std::uint32_t nested_uniform_scramble(std::uint32_t x, std::uint32_t seed) {
  return reverse_bits(laine_karras(reverse_bits(x), seed));
}

// The Sobol' sequence's first two dimensions at index i, as 32-bit fractions: the van der Corput
// radical inverse and the second generator matrix (Kollig & Keller 2002's sobol2: column k is
// v_k, v_0 = 2^31, v_{k+1} = v_k ^ (v_k >> 1)).
constexpr std::uint32_t sobol_dim0(std::uint32_t i) { return reverse_bits(i); }
constexpr std::uint32_t sobol_dim1_reference(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return r;
}
// The matrix (and the matrix followed by a bit reversal) is linear over GF(2): one table of 256
// column sums per index byte.
struct Dim1Tables {
  std::uint32_t t[4][256];
};
constexpr Dim1Tables make_dim1_tables(bool reversed) {
  Dim1Tables d{};
  for (int b = 0; b < 4; ++b)
    for (std::uint32_t k = 0; k < 256; ++k) {
      const std::uint32_t v = sobol_dim1_reference(k << (8 * b));
      d.t[b][k] = reversed ? reverse_bits(v) : v;
    }
  return d;
}
inline constexpr Dim1Tables kDim1 = make_dim1_tables(false);
inline constexpr Dim1Tables kDim1Reversed = make_dim1_tables(true);
constexpr std::uint32_t apply(const Dim1Tables& m, std::uint32_t i) {
  return m.t[0][i & 255u] ^ m.t[1][(i >> 8) & 255u] ^ m.t[2][(i >> 16) & 255u] ^ m.t[3][i >> 24];
}
constexpr std::uint32_t sobol_dim1(std::uint32_t i) { return apply(kDim1, i); }
// reverse_bits(sobol_dim1(i)).
constexpr std::uint32_t sobol_dim1_reversed(std::uint32_t i) { return apply(kDim1Reversed, i); }

}  // namespace sobol

class Rng {
 public:
  // Draws of a path that come from the Sobol' point (Sampler::Sobol): 4 pairs. The first four are
  // the pixel position (2) and the wavelength offset with the first flight (or Single's bin).
  static constexpr int kSobolDimensions = 8;

  // The stream of sample `sample` of pixel `pixel` under `seed`.
  Rng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
    const std::uint64_t key = splitmix64(splitmix64(splitmix64(seed) ^ pixel) ^ sample);
    m_inc = (splitmix64(key ^ 0xDA3E39CB94B95BDBULL) << 1u) | 1u;
    m_state = 0;
    next_u32();
    m_state += key;
    next_u32();
  }
  // The same under `sampler`: Independent is the stream above; Sobol starts with the sample's
  // Sobol' point of `dimensions` draws (even, ≥ 0; sample indices are taken modulo 2^32).
  Rng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample, Sampler sampler,
      int dimensions = kSobolDimensions)
      : Rng(seed, pixel, sample) {
    if (sampler != Sampler::Sobol) return;
    m_pixel_key = splitmix64(splitmix64(splitmix64(seed ^ 0x5B0B5C2A1D3E4F60ULL)) ^ pixel);
    m_index_reversed = sobol::reverse_bits(static_cast<std::uint32_t>(sample));
    m_qmc_end = dimensions;
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
  float uniform() {
    const std::uint32_t bits = m_qmc_next < m_qmc_end ? next_qmc() : next_u32();
    return (static_cast<float>(bits >> 8) + 0.5f) * 0x1p-24f;
  }
  // Uniform in (0, 1) with 53-bit resolution, for geometry (a Sobol' draw: its 32 bits, then 21
  // from the stream).
  double uniform_double() {
    std::uint64_t bits = 0;
    if (m_qmc_next < m_qmc_end) {
      const std::uint64_t hi = next_qmc();
      bits = (hi << 21) | (next_u32() >> 11);
    } else {
      const std::uint64_t hi = next_u32() >> 5;  // 27 bits
      const std::uint64_t lo = next_u32() >> 6;  // 26 bits
      bits = (hi << 26) | lo;
    }
    return (static_cast<double>(bits) + 0.5) * 0x1p-53;
  }

 private:
  // The next Sobol' coordinate as a 32-bit fraction; a pair's second coordinate is made with its first.
  // Pair k: index i = nested_uniform_scramble(sample, s0), x = nested_uniform_scramble(sobol_dim0(i), s1),
  // y = nested_uniform_scramble(sobol_dim1(i), s2), with the reversals that cancel left out
  // (sobol_dim0 is itself a reversal).
  std::uint32_t next_qmc() {
    const int d = m_qmc_next++;
    if (d & 1) return m_qmc_second;
    const std::uint64_t h0 = splitmix64(m_pixel_key + static_cast<std::uint64_t>(d));
    const std::uint64_t h1 = splitmix64(h0);
    const std::uint32_t i = sobol::reverse_bits(sobol::laine_karras(m_index_reversed, static_cast<std::uint32_t>(h0)));
    m_qmc_second = sobol::reverse_bits(sobol::laine_karras(sobol::sobol_dim1_reversed(i), static_cast<std::uint32_t>(h1)));
    return sobol::reverse_bits(sobol::laine_karras(i, static_cast<std::uint32_t>(h0 >> 32)));
  }

  std::uint64_t m_state = 0;
  std::uint64_t m_inc = 1;
  std::uint64_t m_pixel_key = 0;  // Sobol: the pixel's scramble key
  std::uint32_t m_index_reversed = 0;  // Sobol: the sample index, bit-reversed
  std::uint32_t m_qmc_second = 0;
  int m_qmc_next = 0;
  int m_qmc_end = 0;  // 0: independent
};

}  // namespace prizma::render
