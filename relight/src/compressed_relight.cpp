// Compressed transport and the baked 8-bit display encoder (compressed_relight.h).
#include "prizma/relight/compressed_relight.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Imath/half.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "compressed_simd.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

#include <nlohmann/json.hpp>

namespace prizma::relight {

namespace {

// One light's 3×k weights (row-major) and its half coefficients.
struct CoeffTerm {
  const float* weights;
  const std::uint16_t* coefficients;
  int k;
};

// Adds Σ_j W[:, j]·c(x, j) for a row of pixels into out (3 floats per pixel); `row` holds the row's
// coefficients as floats (width·k, pixel-major). K > 0 fixes k.
template <int K>
void add_row(const CoeffTerm& term, const float* row, int width, float* out) {
  const int k = K > 0 ? K : term.k;
  const float* w = term.weights;
  const float* c = row;
  for (int x = 0; x < width; ++x, c += k) {
    float X = 0.0f, Y = 0.0f, Z = 0.0f;
    for (int j = 0; j < k; ++j) {
      X += w[j] * c[j];
      Y += w[k + j] * c[j];
      Z += w[2 * k + j] * c[j];
    }
    out[3 * x + 0] += X;
    out[3 * x + 1] += Y;
    out[3 * x + 2] += Z;
  }
}

using AddRow = void (*)(const CoeffTerm&, const float*, int, float*);

AddRow add_row_for(int k) {
  switch (k) {
    case 1: return &add_row<1>;
    case 2: return &add_row<2>;
    case 3: return &add_row<3>;
    case 4: return &add_row<4>;
    case 5: return &add_row<5>;
    case 6: return &add_row<6>;
    case 7: return &add_row<7>;
    case 8: return &add_row<8>;
    case 10: return &add_row<10>;
    case 12: return &add_row<12>;
    case 16: return &add_row<16>;
    default: return &add_row<0>;
  }
}

// Per layer of the transport, W_l = A·M_l·B_l as float, row-major (3·k), where A is `display`
// (XYZ → linear display RGB) or the identity; empty for lights that are off. The shape checks and the
// "off" rule are spectral::relight_into's (spectral::light_weights, relight_image.h).
std::vector<std::vector<float>> folded_weights(const CompressedTransport& transport, const spectral::RelightMatrix& matrix,
                                               const Eigen::Matrix3f* display) {
  const int n = transport.bins.size();
  const int layers = static_cast<int>(transport.lights.size());
  const std::vector<spectral::LightWeights> on = spectral::light_weights(matrix, layers, n, "compressed transport");
  const std::size_t pixels = transport.pixel_count();
  for (const CompressedLayer& layer : transport.lights) {
    if (layer.k < 1 || layer.basis.rows() != n || layer.basis.cols() != layer.k ||
        layer.coefficients.size() != pixels * static_cast<std::size_t>(layer.k)) {
      throw spectral::RuntimeError("relight: compressed layer " + layer.name + " has inconsistent sizes");
    }
  }
  std::vector<std::vector<float>> out(static_cast<std::size_t>(layers));
  for (const spectral::LightWeights& lw : on) {
    const CompressedLayer& layer = transport.lights[static_cast<std::size_t>(lw.light)];
    Eigen::Matrix<double, 3, Eigen::Dynamic> w = matrix.light(lw.light) * layer.basis.cast<double>();
    if (display != nullptr) w = Eigen::Matrix<double, 3, Eigen::Dynamic>(display->cast<double>() * w);
    std::vector<float>& row_major = out[static_cast<std::size_t>(lw.light)];
    row_major.resize(3 * static_cast<std::size_t>(layer.k));
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < layer.k; ++j) row_major[static_cast<std::size_t>(c * layer.k + j)] = static_cast<float>(w(c, j));
  }
  return out;
}

std::uint8_t quantise(float v) {
  // What OpenImageIO does converting float to uint8: clamp, scale, round half up.
  const float c = std::clamp(v, 0.0f, 1.0f);
  return static_cast<std::uint8_t>(std::floor(c * 255.0f + 0.5f));
}

}  // namespace

void set_half_coefficients(CompressedLayer& layer, const Eigen::MatrixXf& basis, const std::vector<float>& coefficients) {
  const auto k = static_cast<std::size_t>(basis.cols());
  if (k < 1 || coefficients.size() % k != 0) {
    throw spectral::RuntimeError("compressed layer " + layer.name + ": " + std::to_string(coefficients.size()) +
                                 " coefficients for k = " + std::to_string(k));
  }
  float largest = 0.0f;
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    if (!std::isfinite(coefficients[i])) {
      throw spectral::RuntimeError("compressed layer " + layer.name + ": non-finite coefficient at pixel " +
                                   std::to_string(i / k) + ", coefficient " + std::to_string(i % k));
    }
    largest = std::max(largest, std::fabs(coefficients[i]));
  }
  // 2^e with largest / 2^e in [2^14, 2^15): within half's range (65504) with room for rounding, and
  // as far above half's subnormals (below 2^-14) as it goes. Powers of two scale exactly.
  const int e = largest > 0.0f ? std::max(std::ilogb(largest) - 14, -100) : 0;
  const float down = std::ldexp(1.0f, -e);
  layer.k = static_cast<int>(k);
  layer.basis = basis * std::ldexp(1.0f, e);
  layer.coefficients.resize(coefficients.size());
  for (std::size_t i = 0; i < coefficients.size(); ++i) layer.coefficients[i] = half(coefficients[i] * down).bits();
}

Eigen::VectorXf reconstructed_spectrum(const CompressedLayer& layer, std::size_t p) {
  Eigen::VectorXf c(layer.k);
  detail::half_to_float(layer.coefficients.data() + p * static_cast<std::size_t>(layer.k), static_cast<std::size_t>(layer.k),
                        c.data());
  return layer.basis * c;
}

CompressedTransport compress_transport(const spectral::SpectralImage& image, const spectral::BasisCriterion& criterion) {
  CompressedTransport out;
  out.width = image.width;
  out.height = image.height;
  out.bins = image.bins;
  const int n = image.bins.size();
  const std::size_t pixels = image.pixel_count();
  for (const spectral::TransportLayer& layer : image.lights) {
    if (layer.data.size() != pixels * static_cast<std::size_t>(n)) {
      throw spectral::RuntimeError("compress: layer " + layer.name + " has " + std::to_string(layer.data.size()) +
                                   " values, expected " + std::to_string(pixels * static_cast<std::size_t>(n)));
    }
    const spectral::SpectralBasis basis = spectral::spectral_basis(layer.data.data(), pixels, n);
    const spectral::BasisChoice choice =
        spectral::choose_basis_size(basis, layer.data.data(), pixels, image.bins, criterion);
    CompressedLayer c;
    c.name = layer.name;
    // Half coefficients and their errors; one more coefficient while rounding breaks the bound
    // (k = n: as good as it gets).
    for (c.k = choice.k;; ++c.k) {
      std::vector<float> values = spectral::project_coefficients(basis, c.k, layer.data.data(), pixels);
      set_half_coefficients(c, spectral::basis_columns(basis, c.k), values);
      detail::half_to_float(c.coefficients.data(), c.coefficients.size(), values.data());
      c.errors = spectral::reconstruction_errors(c.basis, values.data(), layer.data.data(), pixels, image.bins, criterion);
      const bool ok = std::all_of(c.errors.begin(), c.errors.end(),
                                  [&](const spectral::BasisError& e) { return e.percentile <= criterion.max_delta_e; });
      if (ok || c.k >= n) break;
    }
    out.lights.push_back(std::move(c));
  }
  return out;
}

std::vector<std::vector<float>> coefficient_weights(const CompressedTransport& transport, const spectral::RelightMatrix& matrix) {
  return folded_weights(transport, matrix, nullptr);
}

void relight_compressed_into(const CompressedTransport& transport, const spectral::RelightMatrix& matrix, float* xyz_out) {
  // W_l = M_l·B_l once per light setting, float, row-major; "off" lights are skipped.
  const std::vector<std::vector<float>> weights = coefficient_weights(transport, matrix);
  std::vector<CoeffTerm> terms;
  std::vector<AddRow> kernels;
  for (std::size_t t = 0; t < weights.size(); ++t) {
    if (weights[t].empty()) continue;
    const CompressedLayer& layer = transport.lights[t];
    terms.push_back({weights[t].data(), layer.coefficients.data(), layer.k});
    kernels.push_back(add_row_for(layer.k));
  }
  const int width = transport.width;
  int max_k = 1;
  for (const CoeffTerm& t : terms) max_k = std::max(max_k, t.k);
  const detail::HalfToFloatKernel half_to_float = detail::half_to_float_kernel();  // the SIMD level chosen now
  tbb::parallel_for(tbb::blocked_range<int>(0, transport.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> row(static_cast<std::size_t>(width) * static_cast<std::size_t>(max_k));
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      float* out = xyz_out + 3 * first;
      std::fill(out, out + 3 * static_cast<std::size_t>(width), 0.0f);
      for (std::size_t t = 0; t < terms.size(); ++t) {
        const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(terms[t].k);
        half_to_float(terms[t].coefficients + first * static_cast<std::size_t>(terms[t].k), count, row.data());
        kernels[t](terms[t], row.data(), width, out);
      }
    }
  });
}

spectral::XyzImage relight_compressed(const CompressedTransport& transport, const spectral::RelightMatrix& matrix) {
  spectral::XyzImage out;
  out.width = transport.width;
  out.height = transport.height;
  out.xyz.resize(3 * transport.pixel_count());
  relight_compressed_into(transport, matrix, out.xyz.data());
  return out;
}

// long on purpose: the bake and its check against the full transform belong together: one bisection state, then the check.
DisplayEncoder8::DisplayEncoder8(const spectral::DisplayTransform& display) : m_display(&display) {
  const std::optional<spectral::DisplayMatrixCurve> split = display.split_matrix_curve();
  if (!split) return;
  m_matrix = split->matrix.cast<float>();
  // code_c(v) of the curve for a batch of values (one per pixel, the same in the three channels).
  auto codes = [&](const std::vector<float>& values) {
    std::vector<float> rgb(3 * values.size());
    for (std::size_t i = 0; i < values.size(); ++i) rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = values[i];
    split->curve(rgb.data(), values.size());
    std::vector<std::uint8_t> out(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) out[i] = std::isfinite(rgb[i]) ? quantise(rgb[i]) : 0;
    return out;  // out[3·i + c]
  };
  // The top of the bracket: where every channel reaches 255, or 2^40.
  float hi = 1.0f;
  while (hi < 1.1e12f) {
    const auto c = codes({hi});
    if (c[0] == 255 && c[1] == 255 && c[2] == 255) break;
    hi *= 2.0f;
  }
  const auto at_zero = codes({0.0f});
  const auto at_hi = codes({hi});
  // Bisection on the bit patterns of non-negative floats (monotone in the value), all 3·255
  // thresholds at once: invariant code(lo) < j ≤ code(hi).
  struct Search {
    int channel, code;
    std::uint32_t lo, hi;
  };
  std::vector<Search> open;
  for (int c = 0; c < 3; ++c) {
    for (int j = 1; j < 256; ++j) {
      float& t = m_thresholds[static_cast<std::size_t>(c)][static_cast<std::size_t>(j)];
      if (at_zero[static_cast<std::size_t>(c)] >= j) t = 0.0f;
      else if (at_hi[static_cast<std::size_t>(c)] < j) t = std::numeric_limits<float>::infinity();
      else open.push_back({c, j, 0u, std::bit_cast<std::uint32_t>(hi)});
    }
  }
  while (true) {
    std::vector<float> mids;
    std::vector<std::size_t> which;
    for (std::size_t i = 0; i < open.size(); ++i) {
      if (open[i].hi - open[i].lo > 1) {
        mids.push_back(std::bit_cast<float>(open[i].lo + (open[i].hi - open[i].lo) / 2));
        which.push_back(i);
      }
    }
    if (mids.empty()) break;
    const auto c = codes(mids);
    for (std::size_t m = 0; m < mids.size(); ++m) {
      Search& s = open[which[m]];
      const std::uint32_t mid = std::bit_cast<std::uint32_t>(mids[m]);
      if (c[3 * m + static_cast<std::size_t>(s.channel)] >= s.code) s.hi = mid;
      else s.lo = mid;
    }
  }
  for (const Search& s : open) {
    m_thresholds[static_cast<std::size_t>(s.channel)][static_cast<std::size_t>(s.code)] = std::bit_cast<float>(s.hi);
  }
  for (std::size_t c = 0; c < 3; ++c) {
    const auto& thr = m_thresholds[c];
    // Thresholds must not decrease (a monotone curve); otherwise the bake is not valid.
    for (std::size_t j = 2; j < 256; ++j)
      if (thr[j] < thr[j - 1]) return;
    m_guess[c].resize(0x7F80);
    for (std::uint32_t b = 0; b < 0x7F80; ++b) {
      const float v = std::bit_cast<float>(b << 16);
      m_guess[c][b] = static_cast<std::uint8_t>(std::upper_bound(thr.begin() + 1, thr.begin() + 256, v) - (thr.begin() + 1));
    }
  }
  for (auto& thr : m_thresholds) thr[256] = std::numeric_limits<float>::infinity();
  // Check the bake against the full transform on deterministic colours, dark ones and negatives too.
  constexpr std::size_t kChecks = 4096;
  std::vector<float> xyz(3 * kChecks);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto uniform = [&]() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<float>(static_cast<double>(state >> 11) * 0x1.0p-53);
  };
  for (std::size_t i = 0; i < kChecks; ++i) {
    const float scale = std::pow(10.0f, -4.0f + 4.5f * uniform());
    for (int c = 0; c < 3; ++c) xyz[3 * i + static_cast<std::size_t>(c)] = scale * (1.2f * uniform() - 0.1f);
  }
  std::vector<float> reference = xyz;
  display.apply(reference.data(), kChecks);
  m_baked = true;
  std::vector<std::uint8_t> fast(3 * kChecks);
  encode_chunk(xyz.data(), kChecks, fast.data());
  for (std::size_t i = 0; i < fast.size(); ++i) {
    const int ref = std::isfinite(reference[i]) ? quantise(reference[i]) : 0;
    if (std::abs(ref - int{fast[i]}) > 1) {
      m_baked = false;
      break;
    }
  }
  if (m_baked) build_step_table();
}

std::uint32_t DisplayEncoder8::StepTable::code(int channel, float v) const {
  const std::int32_t b = std::clamp(std::bit_cast<std::int32_t>(std::max(v, 0.0f)), lo_bits, hi_bits);
  const std::uint32_t e = entries[static_cast<std::size_t>(channel)][static_cast<std::size_t>((b >> shift) - base)];
  const auto low = static_cast<std::uint32_t>(b & ((std::int32_t{1} << shift) - 1));
  return (e & 255u) + (low >= (e >> 8) ? 1u : 0u);
}

// The step table: buckets of 2^shift consecutive float bit patterns (a fixed fraction of an octave,
// so narrow where the curve's steps are close, wide where they are far apart) between just below the
// smallest positive threshold and the largest finite one, for the widest buckets (shift from 16 down
// to 12) that hold at most one threshold each and fit in 16384 entries. Bit patterns of non-negative
// floats are ordered as their values, so a compare of the low bits is the exact v ≥ threshold test.
// Checked against the thresholds (both sides of every step, and 4096 spread values) before it is used.
void DisplayEncoder8::build_step_table() {
  float first = std::numeric_limits<float>::infinity(), last = 0.0f;
  for (const auto& thr : m_thresholds) {
    for (std::size_t j = 1; j < 256 && std::isfinite(thr[j]); ++j) {
      if (thr[j] > 0.0f) first = std::min(first, thr[j]);
      last = std::max(last, thr[j]);
    }
  }
  if (!std::isfinite(first) || !(last > 0.0f)) return;
  auto code_at = [&](std::size_t c, float v) {  // the number of thresholds ≤ v: the code of v ≥ 0
    const auto& thr = m_thresholds[c];
    return static_cast<std::uint32_t>(std::upper_bound(thr.begin() + 1, thr.begin() + 256, v) - (thr.begin() + 1));
  };
  const auto first_bits = std::bit_cast<std::int32_t>(first), hi_bits = std::bit_cast<std::int32_t>(last);
  for (int shift = 16; shift >= 12; --shift) {
    const std::int32_t lo_bits = ((first_bits - 1) >> shift) << shift;  // below every positive threshold
    const std::int32_t base = lo_bits >> shift;
    const std::size_t size = static_cast<std::size_t>((hi_bits >> shift) - base + 1);
    if (size > 16384) return;
    StepTable t;
    t.shift = shift;
    t.base = base;
    t.lo_bits = lo_bits;
    t.hi_bits = hi_bits;
    const std::uint32_t none = 1u << shift;
    bool fits = true;
    for (std::size_t c = 0; c < 3 && fits; ++c) {
      t.entries[c].resize(size);
      for (std::size_t i = 0; i < size && fits; ++i) {
        const std::int32_t start = (base + static_cast<std::int32_t>(i)) << shift;
        const std::int32_t end = start + static_cast<std::int32_t>(none) - 1;  // the bucket's last bit pattern
        const std::uint32_t code = code_at(c, std::bit_cast<float>(start));
        const std::uint32_t steps = code_at(c, std::bit_cast<float>(end)) - code;
        if (steps > 1) fits = false;
        const std::uint32_t step = steps == 0 ? none
                                              : static_cast<std::uint32_t>(
                                                    std::bit_cast<std::int32_t>(m_thresholds[c][code + 1]) - start);
        t.entries[c][i] = code | (step << 8);
      }
    }
    if (!fits) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<float> probes = {0.0f, -1.0f, -0.0f, first, last, 2.0f * last, 1e30f};
      for (std::size_t j = 1; j < 256 && std::isfinite(m_thresholds[c][j]); ++j) {
        probes.push_back(m_thresholds[c][j]);
        probes.push_back(std::nextafter(m_thresholds[c][j], -1.0f));
      }
      for (int i = 0; i < 4096; ++i) probes.push_back(last * static_cast<float>(i) / 4000.0f);
      for (const float v : probes)
        if (t.code(static_cast<int>(c), v) != code_at(c, std::max(v, 0.0f))) return;
    }
    m_steps = std::move(t);
    return;
  }
}

void DisplayEncoder8::encode_chunk(const float* xyz, std::size_t pixels, std::uint8_t* rgb) const {
  if (!m_baked) {
    std::vector<float> buf(xyz, xyz + 3 * pixels);
    for (float& v : buf)
      if (!std::isfinite(v)) v = 0.0f;
    m_display->apply(buf.data(), pixels);
    for (std::size_t i = 0; i < buf.size(); ++i) rgb[i] = std::isfinite(buf[i]) ? quantise(buf[i]) : 0;
    return;
  }
  for (std::size_t p = 0; p < pixels; ++p) {
    float in[3];
    for (int c = 0; c < 3; ++c) {
      const float v = xyz[3 * p + static_cast<std::size_t>(c)];
      in[c] = std::isfinite(v) ? v : 0.0f;
    }
    for (int c = 0; c < 3; ++c) {
      const float v = m_matrix(c, 0) * in[0] + m_matrix(c, 1) * in[1] + m_matrix(c, 2) * in[2];
      const std::uint32_t bits = std::bit_cast<std::uint32_t>(v);
      std::uint32_t code;
      if (bits & 0x80000000u) {
        code = m_guess[static_cast<std::size_t>(c)][0];  // negative: the code of 0
      } else if (bits >= 0x7F800000u) {
        code = 255;
      } else {
        code = m_guess[static_cast<std::size_t>(c)][bits >> 16];
        const auto& thr = m_thresholds[static_cast<std::size_t>(c)];
        while (code < 255 && v >= thr[code + 1]) ++code;
      }
      rgb[3 * p + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(code);
    }
  }
}

void DisplayEncoder8::encode(const float* xyz, std::size_t pixels, std::uint8_t* rgb) const {
  constexpr std::size_t kChunk = 16384;
  const std::size_t chunks = (pixels + kChunk - 1) / kChunk;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::size_t first = i * kChunk;
      const std::size_t count = std::min(kChunk, pixels - first);
      encode_chunk(xyz + 3 * first, count, rgb + 3 * first);
    }
  });
}

}  // namespace prizma::relight

namespace prizma::relight {

CompressedTransport take_coefficients(spectral::SpectralImage& image, const std::string& source) {
  if (!image.has_coefficients()) throw spectral::InputError(source, "has no spectral-basis coefficients");
  CompressedTransport out;
  out.width = image.width;
  out.height = image.height;
  out.bins = image.bins;
  const int n = image.bins.size();
  for (spectral::TransportLayer& layer : image.lights) {
    spectral::LayerCoefficients& c = layer.coefficients;
    if (c.basis.size() != static_cast<std::size_t>(c.k) * static_cast<std::size_t>(n) ||
        c.values.size() != static_cast<std::size_t>(c.k) * image.pixel_count()) {
      throw spectral::InputError(source, "the coefficients of light \"" + layer.name + "\" have inconsistent sizes");
    }
    CompressedLayer l;
    l.name = layer.name;
    set_half_coefficients(l, Eigen::Map<const Eigen::MatrixXf>(c.basis.data(), n, c.k), c.values);
    std::vector<float>().swap(c.values);
    l.errors = c.errors;
    out.lights.push_back(std::move(l));
  }
  return out;
}

std::string criterion_json(const spectral::BasisCriterion& criterion) {
  const nlohmann::json j = {{"maxDeltaE00", criterion.max_delta_e},
                            {"percentile", criterion.percentile},
                            {"lights", criterion.lights},
                            {"cmf", spectral::observer_name(criterion.cmf)},
                            {"maxSamples", criterion.max_samples}};
  return j.dump();
}

void store_coefficients(spectral::SpectralImage& image, const CompressedTransport& transport,
                        const spectral::BasisCriterion& criterion, bool compact) {
  if (transport.lights.size() != image.lights.size() || transport.width != image.width ||
      transport.height != image.height || transport.bins.size() != image.bins.size()) {
    throw spectral::RuntimeError("store_coefficients: the compressed transport does not match the image");
  }
  for (std::size_t l = 0; l < image.lights.size(); ++l) {
    const CompressedLayer& c = transport.lights[l];
    spectral::TransportLayer& layer = image.lights[l];
    layer.coefficients.k = c.k;
    layer.coefficients.basis.assign(c.basis.data(), c.basis.data() + c.basis.size());  // column-major: vector-major
    layer.coefficients.values.resize(c.coefficients.size());  // the half values, as floats
    detail::half_to_float(c.coefficients.data(), c.coefficients.size(), layer.coefficients.values.data());
    layer.coefficients.errors = c.errors;
    if (compact) {
      layer.data = {};
      layer.variance = {};
    }
  }
  image.coefficient_criterion = criterion_json(criterion);
}

CompressedTransport compress_spectral_exr(const std::filesystem::path& input, const std::filesystem::path& output,
                                          const CompressFileOptions& options) {
  const spectral::BasisCriterion& criterion = options.criterion;
  if (!std::isfinite(criterion.max_delta_e) || criterion.max_delta_e <= 0.0) {
    throw spectral::InputError("--max-error", "must be a positive CIEDE2000 difference, e.g. 0.5");
  }
  spectral::ExrReadOptions read;
  read.verify_checksum = options.verify_checksum;
  read.allow_compact = true;  // to say what it is, below
  spectral::SpectralImage image = spectral::read_spectral_exr(input, read);
  if (image.compact()) {
    throw spectral::InputError(input.string(), "is a compact file (coefficients only, no transport bins): compress "
                                               "needs the bins; compress the file it was made from");
  }
  if (!image.reradiation.empty()) {
    throw spectral::InputError(input.string(), "is a bispectral (fluorescent) file: the coefficients would leave out its "
                                               "re-radiation terms, so compress does not take it");
  }
  const CompressedTransport transport = compress_transport(image, criterion);
  store_coefficients(image, transport, criterion, options.compact);
  spectral::write_spectral_exr(output, image);
  return transport;
}

void relight_compressed_to_display8(const CompressedTransport& transport, const spectral::RelightMatrix& matrix,
                                    const DisplayEncoder8& encoder, std::uint8_t* rgb_out) {
  const std::size_t pixels = transport.pixel_count();
  if (!encoder.baked() || encoder.step_table().empty() || transport.lights.size() > detail::kMaxFusedLayers) {
    std::vector<float> xyz(3 * pixels);
    relight_compressed_into(transport, matrix, xyz.data());
    encoder.encode(xyz.data(), pixels, rgb_out);
    return;
  }
  const std::vector<std::vector<float>> weights = folded_weights(transport, matrix, &encoder.matrix());
  std::vector<detail::SimdCoeffLayer> terms;
  for (std::size_t t = 0; t < weights.size(); ++t) {
    if (weights[t].empty()) continue;
    terms.push_back({weights[t].data(), transport.lights[t].coefficients.data(), transport.lights[t].k});
  }
  const DisplayEncoder8::StepTable& steps = encoder.step_table();
  detail::SimdEncoder enc;
  for (int c = 0; c < 3; ++c) enc.entries[c] = steps.entries[static_cast<std::size_t>(c)].data();
  enc.shift = steps.shift;
  enc.base = steps.base;
  enc.lo_bits = steps.lo_bits;
  enc.hi_bits = steps.hi_bits;
  const int width = transport.width;
  const std::size_t scratch_floats = detail::compressed_row_scratch(terms.data(), static_cast<int>(terms.size()), width);
  const detail::CompressedRowKernel row_kernel = detail::compressed_row_kernel();  // the SIMD level chosen now
  tbb::parallel_for(tbb::blocked_range<int>(0, transport.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> scratch(scratch_floats);
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      row_kernel(terms.data(), static_cast<int>(terms.size()), first, width, enc, scratch.data(), rgb_out + 3 * first);
    }
  });
}

}  // namespace prizma::relight
