// The fused compressed-relight row (compressed_simd.h), compiled for every x86 SIMD level with
// Highway and chosen at run time, as relight_simd.cpp does. Per block of lanes: the coefficients of
// each light are de-interleaved (LoadInterleaved2/3/4 for k ≤ 4, gathers otherwise), multiplied into
// linear display RGB with the folded 3×k weights, and each channel is encoded by the small table: one
// gather for the guess, one for the next threshold, one compare. Targets differ only in float
// rounding of the sums (FMA or not); one machine always gives the same bytes.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "compressed_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>

#include "compressed_simd.h"

HWY_BEFORE_NAMESPACE();
namespace prizma::relight::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

// Linear RGB of one pixel, scalar (tails).
void pixel_rgb(const SimdCoeffLayer* layers, int layer_count, std::size_t p, float rgb[3]) {
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  for (int l = 0; l < layer_count; ++l) {
    const int k = layers[l].k;
    const float* w = layers[l].weights;
    const float* c = layers[l].coefficients + p * static_cast<std::size_t>(k);
    for (int j = 0; j < k; ++j) {
      rgb[0] += w[j] * c[j];
      rgb[1] += w[k + j] * c[j];
      rgb[2] += w[2 * k + j] * c[j];
    }
  }
}

std::uint8_t code_scalar(const SimdEncoder& e, int c, float v) {
  if (!(v > 0.0f)) v = 0.0f;  // negatives (and NaN) take the code of 0
  const float x = std::min(v * e.lut_scale, static_cast<float>(e.lut_size - 1));
  int code = e.lut[c][static_cast<int>(x)];
  if (v >= e.thresholds[c][code + 1]) ++code;
  return static_cast<std::uint8_t>(code);
}

}  // namespace

void CompressedRowToDisplay8(const SimdCoeffLayer* layers, int layer_count, std::size_t first_pixel, int width,
                             const SimdEncoder& e, float* scratch, std::uint8_t* out) {
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  using V = hn::Vec<decltype(d)>;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const auto zero = hn::Zero(d);
  const auto lut_max = hn::Set(d, static_cast<float>(e.lut_size - 1));
  const auto scale = hn::Set(d, e.lut_scale);
  const auto one = hn::Set(di, 1);
  float* codes = scratch;  // 3 · lanes floats' room, as int32
  std::int32_t* code_i = reinterpret_cast<std::int32_t*>(codes);
  int x = 0;
  for (; x + lanes <= width; x += lanes) {
    const std::size_t p = first_pixel + static_cast<std::size_t>(x);
    auto r = zero, g = zero, b = zero;
    for (int l = 0; l < layer_count; ++l) {
      const int k = layers[l].k;
      const float* HWY_RESTRICT w = layers[l].weights;
      const float* HWY_RESTRICT c = layers[l].coefficients + p * static_cast<std::size_t>(k);
      auto add = [&](int j, V cj) {
        r = hn::MulAdd(hn::Set(d, w[j]), cj, r);
        g = hn::MulAdd(hn::Set(d, w[k + j]), cj, g);
        b = hn::MulAdd(hn::Set(d, w[2 * k + j]), cj, b);
      };
      if (k == 4) {
        V c0, c1, c2, c3;
        hn::LoadInterleaved4(d, c, c0, c1, c2, c3);
        add(0, c0), add(1, c1), add(2, c2), add(3, c3);
      } else if (k == 3) {
        V c0, c1, c2;
        hn::LoadInterleaved3(d, c, c0, c1, c2);
        add(0, c0), add(1, c1), add(2, c2);
      } else if (k == 2) {
        V c0, c1;
        hn::LoadInterleaved2(d, c, c0, c1);
        add(0, c0), add(1, c1);
      } else {
        const auto base = hn::Mul(hn::Iota(di, 0), hn::Set(di, k));
        for (int j = 0; j < k; ++j) add(j, hn::GatherIndex(d, c, hn::Add(base, hn::Set(di, j))));
      }
    }
    const V v[3] = {r, g, b};
    for (int ch = 0; ch < 3; ++ch) {
      const auto vc = hn::Max(v[ch], zero);
      const auto idx = hn::ConvertTo(di, hn::Min(hn::Mul(vc, scale), lut_max));
      auto code = hn::GatherIndex(di, e.lut[ch], idx);
      const auto next = hn::GatherIndex(d, e.thresholds[ch], hn::Add(code, one));
      code = hn::IfThenElse(hn::RebindMask(di, hn::Ge(vc, next)), hn::Add(code, one), code);
      hn::StoreU(code, di, code_i + ch * lanes);
    }
    std::uint8_t* o = out + 3 * static_cast<std::size_t>(x);
    for (int i = 0; i < lanes; ++i) {
      o[3 * i + 0] = static_cast<std::uint8_t>(code_i[i]);
      o[3 * i + 1] = static_cast<std::uint8_t>(code_i[lanes + i]);
      o[3 * i + 2] = static_cast<std::uint8_t>(code_i[2 * lanes + i]);
    }
  }
  for (; x < width; ++x) {
    float rgb[3];
    pixel_rgb(layers, layer_count, first_pixel + static_cast<std::size_t>(x), rgb);
    for (int ch = 0; ch < 3; ++ch) out[3 * static_cast<std::size_t>(x) + static_cast<std::size_t>(ch)] = code_scalar(e, ch, rgb[ch]);
  }
}

}  // namespace prizma::relight::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace prizma::relight::detail {

HWY_EXPORT(CompressedRowToDisplay8);

void compressed_row_to_display8(const SimdCoeffLayer* layers, int layer_count, std::size_t first_pixel, int width,
                                const SimdEncoder& encoder, float* scratch, std::uint8_t* out) {
  HWY_DYNAMIC_DISPATCH(CompressedRowToDisplay8)(layers, layer_count, first_pixel, width, encoder, scratch, out);
}

}  // namespace prizma::relight::detail
#endif
