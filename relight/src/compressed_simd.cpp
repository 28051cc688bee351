// The fused compressed-relight row (compressed_simd.h), compiled by Highway for every x86 level and
// run at the level spectral::choose_simd_level picks (prizma/spectral/hwy_levels.h), as
// libspectral's relight_simd.cpp is. Per block of lanes (one pixel per lane): the half coefficients
// of each light are de-interleaved (LoadInterleaved2/3/4 of 16-bit lanes for k ≤ 4; layers of
// larger k are first converted for the whole row and gathered), widened to float (F16C where the
// target has it: exact either way), multiplied into linear display RGB with the folded 3×k weights,
// and each channel is encoded by the step table: one gather of a 32-bit entry (the code and where
// the next step lies), one integer compare; the codes are narrowed to bytes and stored interleaved.
// Each coefficient is read from memory once and nothing but the 8-bit codes is written. The row's
// tail goes through the same block on zero-padded copies, so every pixel gets the same arithmetic.
// Same bytes at every level: a pixel is one lane, its sums run over the layers and coefficients in
// the same order at every width, each a product rounded then a sum rounded (no FMA: this file is
// compiled with -ffp-contract=off); the encoding is integer
// (tests/relight/compressed_relight_test.cpp).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "compressed_simd.cpp"
#define HWY_DISABLED_TARGETS HWY_SSSE3  // SSE4 is the 128-bit level (simd_choice.h)
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/cache_control.h>
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>

#include "compressed_simd.h"

HWY_BEFORE_NAMESPACE();
namespace prizma::relight::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DH = hn::Rebind<std::uint16_t, DF>;      // one 16-bit lane per float lane
using DF16 = hn::Rebind<hwy::float16_t, DF>;
using DB = hn::Rebind<std::uint8_t, DF>;
using VF = hn::Vec<DF>;
static_assert(HWY_LANES(float) <= kMaxSimdLanes, "the tail buffers hold one block of the widest target");
constexpr int kPrefetchBytes = 1024;  // how far ahead of the block the coefficients are prefetched

VF widen(hn::Vec<DH> h) {
  const DF d;
  const DF16 d16;
  return hn::PromoteTo(d, hn::BitCast(d16, h));
}

// One block of Lanes(DF) pixels: `coeff[l]` the first of the block's halves of small-k layer l,
// `big[l]` its floats for layers of k > 4 (row-converted); writes 3·lanes codes to `out`.
HWY_INLINE void block(const SimdCoeffLayer* layers, int layer_count, const std::uint16_t* const* coeff,
                      const float* const* big, const SimdEncoder& e, std::uint8_t* HWY_RESTRICT out) {
  const DF d;
  const DI di;
  const DH dh;
  const DB db;
  VF r = hn::Zero(d), g = hn::Zero(d), b = hn::Zero(d);
  for (int l = 0; l < layer_count; ++l) {
    const int k = layers[l].k;
    const float* HWY_RESTRICT w = layers[l].weights;
    auto add = [&](int j, VF cj) HWY_ATTR {
      r = hn::Add(r, hn::Mul(hn::Set(d, w[j]), cj));
      g = hn::Add(g, hn::Mul(hn::Set(d, w[k + j]), cj));
      b = hn::Add(b, hn::Mul(hn::Set(d, w[2 * k + j]), cj));
    };
    const std::uint16_t* HWY_RESTRICT c = coeff[l];
    if (k == 4) {
      hn::Vec<DH> h0, h1, h2, h3;
      hn::LoadInterleaved4(dh, c, h0, h1, h2, h3);
      add(0, widen(h0)), add(1, widen(h1)), add(2, widen(h2)), add(3, widen(h3));
    } else if (k == 3) {
      hn::Vec<DH> h0, h1, h2;
      hn::LoadInterleaved3(dh, c, h0, h1, h2);
      add(0, widen(h0)), add(1, widen(h1)), add(2, widen(h2));
    } else if (k == 2) {
      hn::Vec<DH> h0, h1;
      hn::LoadInterleaved2(dh, c, h0, h1);
      add(0, widen(h0)), add(1, widen(h1));
    } else if (k == 1) {
      add(0, widen(hn::LoadU(dh, c)));
    } else {
      const float* HWY_RESTRICT f = big[l];
      const auto base = hn::Mul(hn::Iota(di, 0), hn::Set(di, k));
      for (int j = 0; j < k; ++j) add(j, hn::GatherIndex(d, f, hn::Add(base, hn::Set(di, j))));
    }
  }
  const auto zero = hn::Zero(d);
  const auto lo_bits = hn::Set(di, e.lo_bits), hi_bits = hn::Set(di, e.hi_bits);
  const auto base = hn::Set(di, e.base);
  const auto low_mask = hn::Set(di, (1 << e.shift) - 1);
  const auto code_mask = hn::Set(di, 255);
  const auto one = hn::Set(di, 1);
  const VF v[3] = {r, g, b};
  hn::Vec<DB> codes[3];
  for (int ch = 0; ch < 3; ++ch) {
    // Negatives (and NaN) take the code of 0; the bit patterns of non-negative floats are ordered.
    const auto bits = hn::Min(hn::Max(hn::BitCast(di, hn::Max(v[ch], zero)), lo_bits), hi_bits);
    const auto entry =
        hn::GatherIndex(di, reinterpret_cast<const std::int32_t*>(e.entries[ch]), hn::Sub(hn::ShiftRightSame(bits, e.shift), base));
    // low ≥ step as low > step − 1 (Highway 1.0 has no integer ≥).
    const auto step_here = hn::Gt(hn::And(bits, low_mask), hn::Sub(hn::ShiftRight<8>(entry), one));
    // The mask as a vector is −1 where the value is at or past the bucket's step.
    const auto code = hn::Sub(hn::And(entry, code_mask), hn::VecFromMask(di, step_here));
    codes[ch] = hn::DemoteTo(db, code);  // 0..255
  }
  hn::StoreInterleaved3(codes[0], codes[1], codes[2], db, out);
}

}  // namespace

void HalfToFloat(const std::uint16_t* in, std::size_t count, float* out) {
  const DF d;
  const DH dh;
  std::size_t i = 0;
  for (; i + hn::Lanes(d) <= count; i += hn::Lanes(d)) hn::StoreU(widen(hn::LoadU(dh, in + i)), d, out + i);
  for (; i < count; ++i) out[i] = hn::GetLane(widen(hn::Set(dh, in[i])));
}

void CompressedRowToDisplay8(const SimdCoeffLayer* layers, int layer_count, std::size_t first_pixel, int width,
                             const SimdEncoder& e, float* scratch, std::uint8_t* out) {
  const DF d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const int count = std::min(layer_count, kMaxFusedLayers);  // the caller's limit
  const std::uint16_t* coeff[kMaxFusedLayers];
  const float* big[kMaxFusedLayers];
  // Per layer of k > 4: its row converted to float in the scratch, zero-padded by a block.
  float* s = scratch;
  for (int l = 0; l < count; ++l) {
    const int k = layers[l].k;
    const std::uint16_t* c = layers[l].coefficients + first_pixel * static_cast<std::size_t>(k);
    coeff[l] = c;
    big[l] = nullptr;
    if (k > 4) {
      const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(k);
      HalfToFloat(c, n, s);
      std::fill(s + n, s + n + static_cast<std::size_t>(kMaxSimdLanes) * static_cast<std::size_t>(k), 0.0f);
      big[l] = s;
      s += static_cast<std::size_t>(width + kMaxSimdLanes) * static_cast<std::size_t>(k);
    }
  }
  int x = 0;
  for (; x + lanes <= width; x += lanes) {
    // The coefficients a few blocks ahead, each cache line of them once (the hardware prefetcher
    // alone left the loads waiting for memory: about 30 % of the kernel's samples).
    for (int l = 0; l < count; ++l) {
      if (big[l] != nullptr) continue;
      const auto* ahead = reinterpret_cast<const char*>(coeff[l]) + kPrefetchBytes;
      const int bytes = lanes * layers[l].k * static_cast<int>(sizeof(std::uint16_t));
      for (int off = 0; off < bytes; off += 64) hwy::Prefetch(ahead + off);
    }
    block(layers, count, coeff, big, e, out + 3 * static_cast<std::size_t>(x));
    for (int l = 0; l < count; ++l) {
      coeff[l] += static_cast<std::size_t>(lanes) * static_cast<std::size_t>(layers[l].k);
      if (big[l] != nullptr) big[l] += static_cast<std::size_t>(lanes) * static_cast<std::size_t>(layers[l].k);
    }
  }
  if (x < width) {  // the tail: the same block on zero-padded copies
    const int rest = width - x;
    std::uint16_t tail[kMaxFusedLayers][kMaxSimdLanes * 4] = {};
    for (int l = 0; l < count; ++l) {
      if (big[l] != nullptr) continue;
      std::copy(coeff[l], coeff[l] + static_cast<std::size_t>(rest) * static_cast<std::size_t>(layers[l].k), tail[l]);
      coeff[l] = tail[l];
    }
    std::uint8_t codes[3 * kMaxSimdLanes];
    block(layers, count, coeff, big, e, codes);
    std::memcpy(out + 3 * static_cast<std::size_t>(x), codes, 3 * static_cast<std::size_t>(rest));
  }
}

}  // namespace prizma::relight::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "prizma/spectral/hwy_levels.h"

namespace prizma::relight::detail {

HWY_EXPORT(CompressedRowToDisplay8);
HWY_EXPORT(HalfToFloat);

namespace {
using spectral::SimdKernel;
using spectral::detail::HwyKernel;
const HwyKernel<CompressedRowKernel> kCompressedRow{HWY_DISPATCH_TABLE(CompressedRowToDisplay8), SimdKernel::CompressedFrame};
const HwyKernel<HalfToFloatKernel> kHalfToFloat{HWY_DISPATCH_TABLE(HalfToFloat), SimdKernel::HalfToFloat};
}  // namespace

std::vector<spectral::SimdLevel> compressed_frame_levels() { return kCompressedRow.levels(); }
std::vector<spectral::SimdLevel> half_to_float_levels() { return kHalfToFloat.levels(); }
CompressedRowKernel compressed_row_kernel(spectral::SimdLevel level) { return kCompressedRow.at(level); }
CompressedRowKernel compressed_row_kernel() { return kCompressedRow.chosen(); }
HalfToFloatKernel half_to_float_kernel(spectral::SimdLevel level) { return kHalfToFloat.at(level); }
HalfToFloatKernel half_to_float_kernel() { return kHalfToFloat.chosen(); }

}  // namespace prizma::relight::detail
#endif
