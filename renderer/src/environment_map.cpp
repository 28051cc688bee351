// EnvironmentMap: a radiance image in one of three conventions (latitude–longitude as Prizma or
// Mitsuba 3 lay it out, pbrt-v4's equal-area square), its piecewise-constant 2D sampling
// distribution, and reading it with OpenImageIO.
#include "prizma/render/environment_map.h"


#include <algorithm>
#include <cmath>
#include <numbers>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "checked_picture.h"
#include "prizma/spectral/error.h"

namespace prizma::render {

using spectral::InputError;

namespace {

// Environment images: at most 2^25 pixels (8192 × 4096), and at most this many decoded bytes per
// byte of file, so that a tiny file claiming a huge image is refused before anything is allocated.
constexpr long long kMaxEnvironmentPixels = 1LL << 25;
constexpr long long kMaxEnvironmentExpansion = 4096;

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Index of the interval of a CDF (size n + 1, cdf[0] = 0, cdf[n] = total) that holds x.
std::size_t find_interval(const double* cdf, std::size_t n, double x) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, x);
  const auto i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - cdf - 1, 0));
  return std::min(i, n - 1);
}

// Clarberg's equal-area mapping between the unit square and the sphere ("Fast Equal-Area Mapping of
// the (Hemi)Sphere using SIMD", JGT 2008), as pbrt-v4 writes it (util/math.cpp,
// EqualAreaSquareToSphere and EqualAreaSphereToSquare; there atan is a polynomial within 1e-6):
// the square's centre is +z, its corners −z, its edges' midpoints the equator.
Eigen::Vector3d equal_area_square_to_sphere(double px, double py) {
  const double u = 2.0 * px - 1.0, v = 2.0 * py - 1.0;
  const double up = std::abs(u), vp = std::abs(v);
  const double signed_distance = 1.0 - (up + vp);  // from the diagonal: > 0 in the upper hemisphere
  const double r = 1.0 - std::abs(signed_distance);
  const double phi = (r == 0.0 ? 1.0 : (vp - up) / r + 1.0) * std::numbers::pi / 4.0;
  const double z = std::copysign(1.0 - r * r, signed_distance);
  const double s = r * std::sqrt(std::max(0.0, 2.0 - r * r));
  return {std::copysign(std::cos(phi), u) * s, std::copysign(std::sin(phi), v) * s, z};
}

void equal_area_sphere_to_square(const Eigen::Vector3d& d, double& px, double& py) {
  const double x = std::abs(d.x()), y = std::abs(d.y()), z = std::abs(d.z());
  const double r = std::sqrt(std::max(0.0, 1.0 - z));
  const double a = std::max(x, y), b = a == 0.0 ? 0.0 : std::min(x, y) / a;
  double phi = std::atan(b) * 2.0 / std::numbers::pi;
  if (x < y) phi = 1.0 - phi;
  double v = phi * r, u = r - v;
  if (d.z() < 0.0) {
    std::swap(u, v);
    u = 1.0 - u;
    v = 1.0 - v;
  }
  px = 0.5 * (std::copysign(u, d.x()) + 1.0);
  py = 0.5 * (std::copysign(v, d.y()) + 1.0);
}

}  // namespace

EnvironmentConvention parse_environment_convention(const std::string& name, const std::string& input) {
  if (name == "prizma") return EnvironmentConvention::Prizma;
  if (name == "mitsuba") return EnvironmentConvention::Mitsuba;
  if (name == "pbrt-equal-area") return EnvironmentConvention::PbrtEqualArea;
  throw InputError(input, "unknown convention \"" + name + "\" (known: prizma, mitsuba, pbrt-equal-area)");
}

const char* environment_convention_name(EnvironmentConvention c) {
  switch (c) {
    case EnvironmentConvention::Mitsuba: return "mitsuba";
    case EnvironmentConvention::PbrtEqualArea: return "pbrt-equal-area";
    case EnvironmentConvention::Prizma: break;
  }
  return "prizma";
}

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<float> values, double rotation_deg,
                               const std::string& input, EnvironmentConvention convention)
    : m_width(width), m_height(height), m_values(std::move(values)), m_convention(convention) {
  if (width < 1 || height < 1) throw InputError(input, "image is empty");
  if (convention == EnvironmentConvention::PbrtEqualArea && width != height) {
    throw InputError(input, "a pbrt-equal-area map is square (got " + std::to_string(width) + "×" +
                                std::to_string(height) + ")");
  }
  const std::size_t n = static_cast<std::size_t>(width) * height;
  if (m_values.size() != n) throw InputError(input, "image has " + std::to_string(m_values.size()) + " values for " +
                                                        std::to_string(width) + "×" + std::to_string(height) + " pixels");
  if (!std::isfinite(rotation_deg)) throw InputError(input, "rotation must be finite");
  double peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const float v = m_values[i];
    const std::string where = "pixel (" + std::to_string(i % width) + ", " + std::to_string(i / width) + ")";
    if (!std::isfinite(v)) throw InputError(input, where + " is not finite (" + num(v) + ")");
    if (v < 0.0f) throw InputError(input, where + " is negative (" + num(v) + ")");
    peak = std::max(peak, static_cast<double>(v));
  }
  if (!(peak > 0.0)) throw InputError(input, "every pixel is 0 (the light would send nothing)");
  m_constant = std::all_of(m_values.begin(), m_values.end(), [&](float v) { return v == m_values.front(); });
  const double r = rotation_deg * std::numbers::pi / 180.0;
  m_cos_rot = std::cos(r);
  m_sin_rot = std::sin(r);

  // Row marginal ∝ Σ_x L(x, y) · row_weight(y) and per-row conditionals ∝ L(x, y) (cumulative, in double).
  m_row_cdf.assign(static_cast<std::size_t>(height) + 1, 0.0);
  m_col_cdf.assign(static_cast<std::size_t>(height) * (width + 1), 0.0);
  for (int y = 0; y < height; ++y) {
    double* c = m_col_cdf.data() + static_cast<std::size_t>(y) * (width + 1);
    for (int x = 0; x < width; ++x) c[x + 1] = c[x] + m_values[static_cast<std::size_t>(y) * width + x];
    m_row_cdf[y + 1] = m_row_cdf[y] + c[width] * row_weight(static_cast<std::size_t>(y));
  }
  m_integral = m_row_cdf[height] / (static_cast<double>(width) * height);
}

EnvironmentMap EnvironmentMap::load(const std::filesystem::path& path, double rotation_deg, const std::string& input,
                                    EnvironmentConvention convention) {
  const std::string file = path.string();
  CheckedPicture picture = read_picture_checked(
      path, {"an environment image", "an environment map", "image library", kMaxEnvironmentPixels, kMaxEnvironmentExpansion},
      input);
  const int w = picture.width, h = picture.height, nc = picture.channels;
  const long long pixels = static_cast<long long>(w) * h;
  std::vector<float> all = std::move(picture.pixels);
  // The first three channels (R, G, B) or the one channel of a grey image.
  const int channels = std::min(nc, 3);
  std::vector<float> px(static_cast<std::size_t>(pixels) * channels);
  for (std::size_t i = 0; i < static_cast<std::size_t>(pixels); ++i)
    for (int c = 0; c < channels; ++c) px[i * channels + c] = all[i * nc + c];
  all = std::vector<float>();
  std::vector<float> lum(static_cast<std::size_t>(pixels));
  for (std::size_t i = 0; i < lum.size(); ++i) {
    const float* p = px.data() + i * channels;
    if (channels < 3) {
      lum[i] = p[0];
    } else {
      // A non-finite or negative channel is reported as such, not hidden in the sum.
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(p[c]) || p[c] < 0.0f)
          throw InputError(input, "image " + file + ": pixel (" + std::to_string(i % w) + ", " + std::to_string(i / w) +
                                      ") channel " + "RGB"[c] + " = " + num(p[c]) + " (must be finite and ≥ 0)");
      lum[i] = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
    }
  }
  try {
    return EnvironmentMap(w, h, std::move(lum), rotation_deg, input, convention);
  } catch (const InputError& e) {
    throw InputError(input, "image " + file + ": " + e.reason());  // names the file, as the reader's errors do
  }
}

void EnvironmentMap::to_uv(const Eigen::Vector3d& d, double& u, double& v) const {
  // Scene → map space: rotate by −rotation about +y.
  const double x = m_cos_rot * d.x() - m_sin_rot * d.z();
  const double z = m_sin_rot * d.x() + m_cos_rot * d.z();
  if (m_convention == EnvironmentConvention::PbrtEqualArea) {
    equal_area_sphere_to_square({x, -z, d.y()}, u, v);  // pbrt's light space: its +z is our +y
    return;
  }
  v = std::acos(std::clamp(d.y(), -1.0, 1.0)) / std::numbers::pi;
  u = std::atan2(x, -z) / (2.0 * std::numbers::pi) + 0.5;
  if (m_convention == EnvironmentConvention::Mitsuba) u = u >= 0.5 ? u - 0.5 : u + 0.5;  // Mitsuba's u = 0 is −z
}

Eigen::Vector3d EnvironmentMap::from_uv(double u, double v) const {
  double x, y, z;
  if (m_convention == EnvironmentConvention::PbrtEqualArea) {
    const Eigen::Vector3d w = equal_area_square_to_sphere(u, v);
    x = w.x();
    y = w.z();
    z = -w.y();
  } else {
    const double theta = std::numbers::pi * v;
    const double phi = 2.0 * std::numbers::pi * (m_convention == EnvironmentConvention::Mitsuba ? u : u - 0.5);
    const double st = std::sin(theta);
    x = st * std::sin(phi);
    y = std::cos(theta);
    z = -st * std::cos(phi);
  }
  // Map → scene space: rotate by +rotation about +y.
  return {m_cos_rot * x + m_sin_rot * z, y, -m_sin_rot * x + m_cos_rot * z};
}

double EnvironmentMap::jacobian(double v) const {
  if (m_convention == EnvironmentConvention::PbrtEqualArea) return 4.0 * std::numbers::pi;
  return 2.0 * std::numbers::pi * std::numbers::pi * std::sin(std::numbers::pi * v);
}

double EnvironmentMap::row_weight(std::size_t y) const {
  if (m_convention == EnvironmentConvention::PbrtEqualArea) return 1.0;
  return std::sin(std::numbers::pi * (static_cast<double>(y) + 0.5) / m_height);
}

std::size_t EnvironmentMap::pixel_at(double u, double v) const {
  const int x = std::clamp(static_cast<int>(u * m_width), 0, m_width - 1);
  const int y = std::clamp(static_cast<int>(v * m_height), 0, m_height - 1);
  return static_cast<std::size_t>(y) * m_width + x;
}

double EnvironmentMap::radiance(const Eigen::Vector3d& dir) const {
  if (m_constant) return m_values.front();
  double u, v;
  to_uv(dir, u, v);
  return m_values[pixel_at(u, v)];
}

double EnvironmentMap::sample(double u0, double u1, Eigen::Vector3d& dir, double& radiance) const {
  // Row from the marginal, column from the row's conditional, uniform within the pixel.
  const double row_target = u1 * m_row_cdf[m_height];
  const std::size_t y = find_interval(m_row_cdf.data(), static_cast<std::size_t>(m_height), row_target);
  const double row_w = m_row_cdf[y + 1] - m_row_cdf[y];
  const double fy = row_w > 0.0 ? std::clamp((row_target - m_row_cdf[y]) / row_w, 0.0, 1.0) : 0.5;
  const double* c = m_col_cdf.data() + y * (static_cast<std::size_t>(m_width) + 1);
  const double col_target = u0 * c[m_width];
  const std::size_t x = find_interval(c, static_cast<std::size_t>(m_width), col_target);
  const double col_w = c[x + 1] - c[x];
  const double fx = col_w > 0.0 ? std::clamp((col_target - c[x]) / col_w, 0.0, 1.0) : 0.5;
  const double u = (static_cast<double>(x) + fx) / m_width, v = (static_cast<double>(y) + fy) / m_height;
  dir = from_uv(u, v);
  radiance = m_values[y * static_cast<std::size_t>(m_width) + x];
  const double jac = jacobian(v);
  if (!(jac > 0.0)) return 0.0;
  // p(u, v) = L · row weight / ∫∫ L · row weight du dv; dω = jacobian · du dv.
  return radiance * row_weight(y) / m_integral / jac;
}

double EnvironmentMap::pdf(const Eigen::Vector3d& dir) const {
  double u, v;
  to_uv(dir, u, v);
  const double jac = jacobian(v);
  if (!(jac > 0.0)) return 0.0;
  const std::size_t px = pixel_at(u, v);
  return m_values[px] * row_weight(px / static_cast<std::size_t>(m_width)) / m_integral / jac;
}

}  // namespace prizma::render
