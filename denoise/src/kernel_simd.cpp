// The denoiser's inner loops for every x86 SIMD level (Highway, HWY_DYNAMIC_DISPATCH): the weights
// of one neighbour offset over a tile, the kernels' normalisation, and the application of a pixel's
// kernel to every plane. Only per-lane IEEE operations, no fused multiply-add, and an exponential of
// our own built from them: every level gives the same bits (kernel_simd.h).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "kernel_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "kernel_simd.h"
#include "prizma/denoise/simd_target.h"

HWY_BEFORE_NAMESPACE();
namespace prizma::denoise::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<float>;
using V = hn::Vec<D>;

// e^-x for x ≥ 0 (the weights' exponents), 0 above kCutExponent: Cody–Waite reduction x·log2(e) = n + t,
// then a degree-6 Taylor polynomial of e^r, |r| ≤ ln2/2 (relative error below 2e-7), times 2^n built
// from its bits. Multiplies and adds only, so the same bits on every target.
HWY_INLINE V ExpNegative(D d, V x) {
  const hn::RebindToSigned<D> di;
  const V neg = hn::Neg(hn::Min(x, hn::Set(d, kCutExponent)));
  const V n = hn::Round(hn::Mul(neg, hn::Set(d, 1.44269504088896341f)));
  V r = hn::Sub(neg, hn::Mul(n, hn::Set(d, 0.693359375f)));  // ln 2, high part (exact in float)
  r = hn::Sub(r, hn::Mul(n, hn::Set(d, -2.12194440e-4f)));   // ln 2, low part
  V p = hn::Set(d, 1.0f / 720.0f);
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 120.0f));
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 24.0f));
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 6.0f));
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 0.5f));
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f));
  p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f));
  const auto bits = hn::ShiftLeft<23>(hn::Add(hn::ConvertTo(di, n), hn::Set(di, 127)));
  const V result = hn::Mul(p, hn::BitCast(d, bits));
  return hn::IfThenElseZero(hn::Lt(x, hn::Set(d, kCutExponent)), result);
}

// ((a − b)² − (va + min(va, vb))) / (eps + va + vb): Rousselle et al. 2012's variance-cancelled
// distance with k = 1 (the min keeps a noisy neighbour from cancelling more than the centre's own
// variance); the patch mean is divided by k² afterwards, so candidates of k share it.
HWY_INLINE V Distance(V a, V b, V va, V vb, V eps) {
  const V diff = hn::Sub(a, b);
  const V num = hn::Sub(hn::Mul(diff, diff), hn::Add(va, hn::Min(va, vb)));
  return hn::Div(num, hn::Add(eps, hn::Add(va, vb)));
}

void OffsetWeights(const OffsetJob& j) {
  const D d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const int f = j.patch_radius, r = j.window_radius;
  const int region_h = j.tile_h + 2 * f;
  const int region_wp = padded(j.tile_wp + 2 * f);
  const V eps = hn::Set(d, j.eps), zero = hn::Zero(d);
  // Per-pixel distances over the tile grown by f (the patches' pixels).
  for (int y = 0; y < region_h; ++y) {
    const float* a = j.lum + static_cast<std::ptrdiff_t>(y + r) * j.lum_stride + r;
    const float* va = j.lum_var + static_cast<std::ptrdiff_t>(y + r) * j.lum_stride + r;
    const float* b = j.lum + static_cast<std::ptrdiff_t>(y + r + j.dy) * j.lum_stride + r + j.dx;
    const float* vb = j.lum_var + static_cast<std::ptrdiff_t>(y + r + j.dy) * j.lum_stride + r + j.dx;
    float* out = j.d2 + static_cast<std::ptrdiff_t>(y) * region_wp;
    for (int x = 0; x < region_wp; x += lanes)
      hn::StoreU(Distance(hn::LoadU(d, a + x), hn::LoadU(d, b + x), hn::LoadU(d, va + x), hn::LoadU(d, vb + x), eps),
                d, out + x);
  }
  // Patch sums: horizontal then vertical, each a fixed-order sum of 2f + 1 terms.
  for (int y = 0; y < region_h; ++y) {
    const float* in = j.d2 + static_cast<std::ptrdiff_t>(y) * region_wp;
    float* out = j.hsum + static_cast<std::ptrdiff_t>(y) * j.tile_wp;
    for (int x = 0; x < j.tile_wp; x += lanes) {
      V s = hn::LoadU(d, in + x);
      for (int t = 1; t <= 2 * f; ++t) s = hn::Add(s, hn::LoadU(d, in + x + t));
      hn::StoreU(s, d, out + x);
    }
  }
  const V inv_area = hn::Set(d, j.inv_patch_area), ct2 = hn::Set(d, j.centre_t2);
  const auto neighbour = hn::Ne(hn::Set(d, static_cast<float>(j.dx != 0 || j.dy != 0)), zero);  // all lanes
  for (int y = 0; y < j.tile_h; ++y) {
    const std::ptrdiff_t centre_row = static_cast<std::ptrdiff_t>(y + r + f) * j.lum_stride + r + f;
    const std::ptrdiff_t neighbour_row = static_cast<std::ptrdiff_t>(y + r + f + j.dy) * j.lum_stride + r + f + j.dx;
    for (int x = 0; x < j.tile_wp; x += lanes) {
      V patch = hn::LoadU(d, j.hsum + static_cast<std::ptrdiff_t>(y) * j.tile_wp + x);
      for (int t = 1; t <= 2 * f; ++t)
        patch = hn::Add(patch, hn::LoadU(d, j.hsum + static_cast<std::ptrdiff_t>(y + t) * j.tile_wp + x));
      const V mean_d2 = hn::Mul(patch, inv_area);
      const std::ptrdiff_t t = static_cast<std::ptrdiff_t>(y) * j.tile_wp + x;
      // What the candidates share: the centre test and the features.
      V shared = zero, feature = zero;
      if (j.centre_t2 > 0.0f) {
        // z² − t², z the centres' difference in standard errors: 0 below t, steep above it.
        const V diff = hn::Sub(hn::LoadU(d, j.lum + centre_row + x), hn::LoadU(d, j.lum + neighbour_row + x));
        const V v = hn::Add(hn::LoadU(d, j.lum_var + centre_row + x), hn::LoadU(d, j.lum_var + neighbour_row + x));
        shared = hn::Max(zero, hn::Div(hn::Sub(hn::Mul(diff, diff), hn::Mul(ct2, v)), hn::Add(eps, v)));
      }
      for (int k = 0; k < j.feature_count; ++k) {
        const TileFeature& ft = j.features[k];
        const std::ptrdiff_t c = static_cast<std::ptrdiff_t>(y + r) * j.feature_stride + r + x;
        const std::ptrdiff_t q = static_cast<std::ptrdiff_t>(y + r + j.dy) * j.feature_stride + r + j.dx + x;
        const V diff = hn::Sub(hn::LoadU(d, ft.value + c), hn::LoadU(d, ft.value + q));
        const V vp = hn::LoadU(d, ft.variance + c), vq = hn::LoadU(d, ft.variance + q);
        const V num = hn::Sub(hn::Mul(diff, diff), hn::Add(vp, hn::Min(vp, vq)));
        feature = hn::Max(feature, hn::Div(num, hn::LoadU(d, ft.denominator + t)));
      }
      // A centre of zero variance is exact (every sample the same: rays that all missed the volume),
      // so it keeps its own value: no neighbour may pull a noise-free background toward a noisy edge.
      const auto exact = hn::And(hn::Eq(hn::LoadU(d, j.lum_var + centre_row + x), zero), neighbour);
      for (int c = 0; c < j.candidates; ++c) {
        const V colour = hn::Add(hn::Max(zero, hn::Mul(mean_d2, hn::LoadU(d, j.inv_k2[c] + t))), shared);
        hn::StoreU(hn::IfThenZeroElse(exact, ExpNegative(d, hn::Max(colour, feature))), d, j.weights[c] + t);
      }
    }
  }
}

void NormaliseKernels(float* kernels, int kernel_size, int count) {
  const D d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  for (int x = 0; x < count; x += lanes) {
    V sum = hn::LoadU(d, kernels + x);
    for (int o = 1; o < kernel_size; ++o) sum = hn::Add(sum, hn::LoadU(d, kernels + static_cast<std::ptrdiff_t>(o) * count + x));
    for (int o = 0; o < kernel_size; ++o) {
      float* w = kernels + static_cast<std::ptrdiff_t>(o) * count + x;
      hn::StoreU(hn::Div(hn::LoadU(d, w), sum), d, w);
    }
  }
}

void MultiplyAddRows(const float* w, int w_stride, const float* v, int v_stride, float* acc, int acc_stride, int rows,
                     int width) {
  const D d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  for (int y = 0; y < rows; ++y) {
    const float* wr = w + static_cast<std::ptrdiff_t>(y) * w_stride;
    const float* vr = v + static_cast<std::ptrdiff_t>(y) * v_stride;
    float* ar = acc + static_cast<std::ptrdiff_t>(y) * acc_stride;
    for (int x = 0; x < width; x += lanes)
      hn::StoreU(hn::Add(hn::LoadU(d, ar + x), hn::Mul(hn::LoadU(d, wr + x), hn::LoadU(d, vr + x))), d, ar + x);
  }
}

// out[0, kVectors·lanes) = Σ_t w_t·in[delta_t·ch + ·) for kVectors whole vectors of channels, one
// independent sum per vector, so that one tap's adds do not wait on each other's latency. Each value
// is 0 + w₀v₀ + w₁v₁ + … in tap order whatever kVectors is: the same bits.
template <int kVectors>
HWY_INLINE void SumTaps(D d, const float* in, std::ptrdiff_t ch, const std::ptrdiff_t* delta, const float* w, int taps,
                        float* out) {
  const int lanes = static_cast<int>(hn::Lanes(d));
  V acc[kVectors];
  for (int v = 0; v < kVectors; ++v) acc[v] = hn::Zero(d);
  for (int t = 0; t < taps; ++t) {
    const V wt = hn::Set(d, w[t]);
    const float* src = in + delta[t] * ch;
    for (int v = 0; v < kVectors; ++v) acc[v] = hn::Add(acc[v], hn::Mul(wt, hn::LoadU(d, src + v * lanes)));
  }
  for (int v = 0; v < kVectors; ++v) hn::StoreU(acc[v], d, out + v * lanes);
}

void ApplyPixel(const ApplyPlane* planes, int plane_count, std::ptrdiff_t pixel, const std::ptrdiff_t* delta,
                const float* weight, const float* weight_squared, int taps) {
  const D d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  for (int k = 0; k < plane_count; ++k) {
    const ApplyPlane& pl = planes[k];
    const std::ptrdiff_t ch = pl.channels;
    const float* w = pl.squared ? weight_squared : weight;
    const float* in = pl.in + pixel * ch;
    float* out = pl.out + pixel * ch;
    int c0 = 0;
    for (; c0 + 4 * lanes <= pl.channels; c0 += 4 * lanes) SumTaps<4>(d, in + c0, ch, delta, w, taps, out + c0);
    for (; c0 + 2 * lanes <= pl.channels; c0 += 2 * lanes) SumTaps<2>(d, in + c0, ch, delta, w, taps, out + c0);
    for (; c0 + lanes <= pl.channels; c0 += lanes) SumTaps<1>(d, in + c0, ch, delta, w, taps, out + c0);
    if (c0 < pl.channels) {  // the last, partial vector: masked loads never touch memory past the image
      const auto m = hn::FirstN(d, static_cast<std::size_t>(pl.channels - c0));
      V acc = hn::Zero(d);
      for (int t = 0; t < taps; ++t)
        acc = hn::Add(acc, hn::Mul(hn::Set(d, w[t]), hn::MaskedLoad(m, d, in + delta[t] * ch + c0)));
      hn::BlendedStore(acc, m, d, out + c0);
    }
  }
}

}  // namespace prizma::denoise::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace prizma::denoise::detail {

HWY_EXPORT(OffsetWeights);
HWY_EXPORT(NormaliseKernels);
HWY_EXPORT(ApplyPixel);
HWY_EXPORT(MultiplyAddRows);

void offset_weights(const OffsetJob& job) { HWY_DYNAMIC_DISPATCH(OffsetWeights)(job); }

void normalise_kernels(float* kernels, int kernel_size, int count) {
  HWY_DYNAMIC_DISPATCH(NormaliseKernels)(kernels, kernel_size, count);
}

void apply_pixel(const ApplyPlane* planes, int plane_count, std::ptrdiff_t pixel, const std::ptrdiff_t* delta,
                 const float* weight, const float* weight_squared, int taps) {
  HWY_DYNAMIC_DISPATCH(ApplyPixel)(planes, plane_count, pixel, delta, weight, weight_squared, taps);
}

void multiply_add_rows(const float* w, int w_stride, const float* v, int v_stride, float* acc, int acc_stride, int rows,
                       int width) {
  HWY_DYNAMIC_DISPATCH(MultiplyAddRows)(w, w_stride, v, v_stride, acc, acc_stride, rows, width);
}

std::vector<std::string> simd_targets() {
  std::vector<std::string> names;
  for (const std::int64_t t : hwy::SupportedAndGeneratedTargets()) names.emplace_back(hwy::TargetName(t));
  return names;
}

void force_simd_target(const std::string& name) {
  if (name.empty()) {
    hwy::SetSupportedTargetsForTest(0);
    return;
  }
  for (const std::int64_t t : hwy::SupportedAndGeneratedTargets())
    if (name == hwy::TargetName(t)) {
      hwy::SetSupportedTargetsForTest(t);
      return;
    }
}

}  // namespace prizma::denoise::detail
#endif
