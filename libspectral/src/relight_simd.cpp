// The relight inner loop XYZ = Σ_l M_l·T_l for a row of pixels, compiled by Highway for every x86
// level (SSE4, AVX2, AVX-512 and the portable fallback) and run at the level
// choose_simd_level picks for SimdKernel::Relight (hwy_levels.h).
//
// Same bits at every level (and with every compiler). A pixel's products w·t go into 16 running
// sums, value j into sum j mod 16 (two 8-float vectors on AVX2 and AVX-512, four of 4 on SSE4,
// sixteen scalars on the fallback), each as a product rounded then a sum rounded (no FMA: this file
// is compiled with -ffp-contract=off), then the 16 sums are added in one fixed tree: (j, j+8),
// (j, j+4), (j, j+2), (j, j+1). Every level performs the same IEEE operations on the same operands
// (tests/relight/relight_simd_test.cpp compares them bit for bit), so the level is a matter of speed.
//
// At most 256-bit vectors, on AVX-512 too. A transport buffer is a std::vector<float>, and glibc
// starts a large allocation 16 bytes past a page boundary (the header of its mmap'd chunk), so
// with 32 bins every pixel starts 16 bytes past a 64-byte line: every 512-bit load of it spans two
// lines, against one 256-bit load in two. On the AMD EPYC (family 1Ah) of issue 26 the former
// 512-bit kernel was the slowest level (2.4× the streaming read, quiet, against 1.35× at AVX2;
// 1.3–1.8× the CPU time of the same loop with 256-bit loads, interleaved on the loaded VM), and on
// 64-byte aligned rows it was no faster than 256-bit loads (bench_relight BM_WideLoadAlignment;
// docs/results.md, "SIMD dispatch").
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "relight_simd.cpp"
#define HWY_DISABLED_TARGETS HWY_SSSE3  // SSE4 is the 128-bit level (simd_choice.h)
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/cache_control.h>
#include <hwy/highway.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "prizma/spectral/relight_simd.h"

HWY_BEFORE_NAMESPACE();
namespace prizma::spectral::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

constexpr std::size_t kSums = kRelightSums;  // running sums per pixel and channel
using D = hn::CappedTag<float, 8>;           // at most 256 bits (above)
using V = hn::Vec<D>;
constexpr std::size_t kLanes = hn::MaxLanes(D());
constexpr std::size_t kVectors = kSums / kLanes;  // vectors per block of 16 values
static_assert(kSums % kLanes == 0, "a block of sums is whole vectors");
using Vectors = std::make_index_sequence<kVectors>;
// How far ahead of a pixel its terms' values are prefetched. Interleaved CPU time of one thread
// over the 1024² bench image on the loaded VM, against no prefetch: 1 KB ahead 7 % more, 2 KB 6 %
// less, 4 KB 12 % less, 6–8 KB 15–20 % less (the hardware prefetcher alone leaves loads waiting).
constexpr std::size_t kPrefetchBytes = 8192;

// A term as the row pass reads it: where pixel 0's values start, values per pixel, its weights in
// three rows `stride` floats apart (a multiple of 16 floats, zeros past n, 64-byte aligned), how
// many values make whole blocks of 16, and the end of the term's values of this row.
struct RowTerm {
  const float* values;
  std::size_t n;
  const float* weights;
  std::size_t stride;
  std::size_t whole;
  const float* row_end;
};

// Adds one block's products to one channel's 16 sums: `t` the values (only the first `valid`
// count: the others are read but replaced by zeros, whose products with the zero weights add +0,
// which leaves a sum unchanged, a sum that starts at +0 never being −0; vectors wholly past
// `valid` are skipped, the same), `w` the channel's weights of the block (aligned).
template <std::size_t... I>
HWY_INLINE void add_block(V* sums, const float* HWY_RESTRICT t, const float* HWY_RESTRICT w, std::size_t valid,
                          std::index_sequence<I...>) {
  const D d;
  auto add = [&](std::size_t i, V& sum) HWY_ATTR {
    if (i * kLanes >= valid) return;
    V v = hn::LoadU(d, t + i * kLanes);
    if (valid < (i + 1) * kLanes) v = hn::IfThenElseZero(hn::FirstN(d, valid - i * kLanes), v);
    sum = hn::Add(sum, hn::Mul(hn::Load(d, w + i * kLanes), v));
  };
  (add(I, sums[I]), ...);
}

// Adds one block of a term to the sums of channels c0 … c0 + kChannels − 1 (sums[k] of channel c0 + k).
template <std::size_t kChannels, std::size_t... C>
HWY_INLINE void add_channels(V (&sums)[kChannels][kVectors], const float* HWY_RESTRICT t, const RowTerm& r,
                             std::size_t j, std::size_t c0, std::size_t valid, std::index_sequence<C...>) {
  (add_block(sums[C], t, r.weights + (c0 + C) * r.stride + j, valid, Vectors()), ...);
}

// Adds pixel p's products of a term: whole blocks in place; a last partial block in place while its
// 16 values lie inside the row (its lanes past the term's values are the next pixel's, zeroed), from
// a copy near the row's end (past the row may be past the buffer). Here and below: inline calls with
// constant indices (fold expressions), no callbacks, so that the sums stay in registers.
template <std::size_t kChannels>
HWY_INLINE void add_term(V (&sums)[kChannels][kVectors], const RowTerm& r, std::size_t p, std::size_t c0) {
  constexpr auto channels = std::make_index_sequence<kChannels>();
  const float* t = r.values + p * r.n;
  std::size_t j = 0;
  for (; j < r.whole; j += kSums) add_channels(sums, t + j, r, j, c0, kSums, channels);
  if (j == r.n) return;
  if (t + j + kSums <= r.row_end) {
    add_channels(sums, t + j, r, j, c0, r.n - j, channels);
  } else {
    float tail[kSums] = {};
    std::copy(t + j, t + r.n, tail);
    add_channels(sums, tail, r, j, c0, r.n - j, channels);
  }
}

// The fixed tree over one channel's 16 sums: (j, j + 8) first, then (j, j + 4), (j, j + 2), (j, j + 1):
// across the vectors while there are several, then within the last one.
template <class DV>
HWY_INLINE float add_lanes(DV /* tag */, hn::Vec<DV> v) {
#if HWY_TARGET == HWY_SCALAR
  return hn::GetLane(v);
#else
  if constexpr (hn::MaxLanes(DV()) == 1) {
    return hn::GetLane(v);
  } else {
    const hn::Half<DV> dh;
    return add_lanes(dh, hn::Add(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v)));
  }
#endif
}
template <std::size_t kCount, std::size_t... I>
HWY_INLINE void add_halves(V* v, std::index_sequence<I...>) {
  ((v[I] = hn::Add(v[I], v[I + kCount / 2])), ...);
}
template <std::size_t kCount>
HWY_INLINE float add_sums(V* v) {
  if constexpr (kCount == 1) {
    return add_lanes(D(), v[0]);
  } else {
    add_halves<kCount>(v, std::make_index_sequence<kCount / 2>());
    return add_sums<kCount / 2>(v);
  }
}

// Pixel p's sums of channels c0 … c0 + kChannels − 1 over every term, through the tree, into out[c0 …].
template <std::size_t... I>
HWY_INLINE void zero(V (&v)[kVectors], std::index_sequence<I...>) {
  ((v[I] = hn::Zero(D())), ...);
}
template <std::size_t kChannels, std::size_t... C>
HWY_INLINE void pixel_channels(const RowTerm* rows, std::size_t count, std::size_t p, std::size_t c0, float* out,
                               std::index_sequence<C...>) {
  V sums[kChannels][kVectors];
  (zero(sums[C], Vectors()), ...);
  for (std::size_t l = 0; l < count; ++l) add_term(sums, rows[l], p, c0);
  ((out[c0 + C] = add_sums<kVectors>(sums[C])), ...);
}

}  // namespace

// relight_simd.h, SimdTerm. Per term, the weights are first copied into rows of whole blocks
// (zeros past n) from a 64-byte boundary, so that every block's weights are aligned whole vectors.
void RelightRowTermsSimd(const SimdTerm* terms, int term_count, std::size_t first_pixel, int width, float* out) {
  const std::size_t count = static_cast<std::size_t>(std::max(term_count, 0));
  std::size_t total = 0;
  for (std::size_t l = 0; l < count; ++l) total += 3 * ((static_cast<std::size_t>(terms[l].n) + kSums - 1) / kSums * kSums);
  std::vector<float> storage(total + 16, 0.0f);
  float* w = storage.data() + (16 - (reinterpret_cast<std::uintptr_t>(storage.data()) / sizeof(float)) % 16) % 16;
  std::vector<RowTerm> rows(count);
  const std::size_t row_end = first_pixel + static_cast<std::size_t>(width);
  for (std::size_t l = 0; l < count; ++l) {
    const std::size_t n = static_cast<std::size_t>(terms[l].n), stride = (n + kSums - 1) / kSums * kSums;
    for (std::size_t c = 0; c < 3; ++c) std::copy(terms[l].weights + c * n, terms[l].weights + (c + 1) * n, w + c * stride);
    rows[l] = {terms[l].values, n, w, stride, n - n % kSums, terms[l].values + row_end * n};
    w += 3 * stride;
  }
  for (int x = 0; x < width; ++x) {
    const std::size_t p = first_pixel + static_cast<std::size_t>(x);
    for (std::size_t l = 0; l < count; ++l) {  // each cache line of the values once (prefetches never fault)
      const char* ahead = reinterpret_cast<const char*>(rows[l].values + p * rows[l].n) + kPrefetchBytes;
      for (std::size_t b = 0; b < rows[l].n * sizeof(float); b += 64) hwy::Prefetch(ahead + b);
    }
    if constexpr (kVectors <= 4) {
      // The three channels' sums at once (6 vectors on AVX2, 12 on SSE4): each value is loaded once.
      pixel_channels<3>(rows.data(), count, p, 0, out + 3 * x, std::make_index_sequence<3>());
    } else {
      // Scalars: one channel at a time, so that its 16 sums fit the registers (the values are read
      // three times, from L1). The same operations on each sum, in the same order.
      pixel_channels<1>(rows.data(), count, p, 0, out + 3 * x, std::make_index_sequence<1>());
      pixel_channels<1>(rows.data(), count, p, 1, out + 3 * x, std::make_index_sequence<1>());
      pixel_channels<1>(rows.data(), count, p, 2, out + 3 * x, std::make_index_sequence<1>());
    }
  }
}

}  // namespace prizma::spectral::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "prizma/spectral/hwy_levels.h"

namespace prizma::spectral::detail {

HWY_EXPORT(RelightRowTermsSimd);

namespace {
const HwyKernel<RelightRowKernel> kRelightRow{HWY_DISPATCH_TABLE(RelightRowTermsSimd), SimdKernel::Relight};
}  // namespace

std::vector<SimdLevel> relight_simd_levels() { return kRelightRow.levels(); }
RelightRowKernel relight_row_kernel(SimdLevel level) { return kRelightRow.at(level); }
SimdLevel relight_simd_level() { return kRelightRow.chosen_level(); }
RelightRowKernel relight_row_kernel() { return kRelightRow.chosen(); }
std::string relight_simd_target_name(SimdLevel level) { return hwy_target_name(level); }

}  // namespace prizma::spectral::detail
#endif
