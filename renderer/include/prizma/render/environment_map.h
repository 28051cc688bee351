#pragma once
// EnvironmentMap: an image as the angular radiance distribution of an environment light
// (docs/scene-format.md, "environment"). The radiance toward a direction is the luminance of the
// pixel it falls in (piecewise constant), at unit white: a constant image of value 1 is the uniform
// unit environment. Sampling draws directions in proportion to radiance × solid angle: a
// piecewise-constant 2D distribution over (u, v) whose rows carry the solid angle of their pixels
// (pbrt-v4, §12.5.2 "Image Infinite Lights", and Pharr, Jakob, Humphreys, 4th ed., §A.5.6).
//
// Directions are in scene space, +y up; (u, v) in [0, 1]², v = 0 the top row. The convention says
// which pixel a direction falls in:
//  - Prizma (latitude–longitude): the polar angle from +y is θ = π·v and the azimuth φ = 2π·(u − ½),
//    the direction (sin θ sin φ, cos θ, −sin θ cos φ): the image's centre is −z (what the default
//    camera looks toward), its right quarter +x.
//  - Mitsuba (Mitsuba 3's `envmap`): the same with φ = 2π·u: u = (atan2(x, −z) / 2π) mod 1, so the
//    image's left edge is −z and its centre +z: Prizma's map turned 180° about +y.
//  - PbrtEqualArea (pbrt-v4's `infinite` light with a square image): Clarberg's equal-area
//    octahedral mapping of pbrt-v4's EqualAreaSphereToSquare of the direction (x, −z, y), i.e. the
//    map's +z (its centre) is +y: pbrt-v4's light space placed as `Rotate -90 1 0 0` places it in a
//    y-up scene. Every pixel covers the same solid angle, 4π / (width · height).
// rotation_deg then turns the map about +y by that angle, counter-clockwise seen from above
// (right-handed about +y), in every convention.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace prizma::render {

// Which pixel of an environment image a direction falls in (above; the scene field "convention").
enum class EnvironmentConvention { Prizma, Mitsuba, PbrtEqualArea };

// "prizma", "mitsuba", "pbrt-equal-area" → the convention; InputError(input, …) listing them otherwise.
EnvironmentConvention parse_environment_convention(const std::string& name, const std::string& input);
const char* environment_convention_name(EnvironmentConvention c);

class EnvironmentMap {
 public:
  // From luminance values, row-major, top row first. Throws InputError(input, …) unless width and
  // height are ≥ 1, values.size() = width·height, every value is finite and ≥ 0, and one is > 0, and
  // (PbrtEqualArea) the image is square.
  EnvironmentMap(int width, int height, std::vector<float> values, double rotation_deg, const std::string& input,
                 EnvironmentConvention convention = EnvironmentConvention::Prizma);

  // Reads an image with OpenImageIO: one channel (its value), two (the first; the second is alpha)
  // or ≥ 3 (Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B of the first three; linear data).
  // Errors: InputError(input, …) for an unreadable, empty, oversized, non-finite or negative image.
  static EnvironmentMap load(const std::filesystem::path& path, double rotation_deg, const std::string& input,
                             EnvironmentConvention convention = EnvironmentConvention::Prizma);

  int width() const { return m_width; }
  int height() const { return m_height; }
  EnvironmentConvention convention() const { return m_convention; }
  const std::vector<float>& values() const { return m_values; }
  // True when every pixel has the same value (then constant_value() is the radiance everywhere).
  bool is_constant() const { return m_constant; }
  double constant_value() const { return m_values.front(); }

  // Radiance arriving from direction `dir` (unit, scene space, pointing away from the scene).
  double radiance(const Eigen::Vector3d& dir) const;
  // A direction drawn from u0, u1 in (0, 1) with density ∝ radiance over solid angle, and the
  // radiance of its pixel; returns the density per steradian (0 when the sample fell on a pole,
  // where it must be discarded).
  double sample(double u0, double u1, Eigen::Vector3d& dir, double& radiance) const;
  // The density per steradian sample() draws `dir` with.
  double pdf(const Eigen::Vector3d& dir) const;

 private:
  // (u, v) in [0, 1]² of a scene-space direction, and back.
  void to_uv(const Eigen::Vector3d& dir, double& u, double& v) const;
  Eigen::Vector3d from_uv(double u, double v) const;
  std::size_t pixel_at(double u, double v) const;

  // Solid angle per unit (u, v) area at (u, v): 2π² sin θ (latitude–longitude), 4π (equal-area).
  double jacobian(double v) const;
  // The row's weight in the marginal: sin θ of its centre (latitude–longitude), 1 (equal-area).
  double row_weight(std::size_t y) const;

  int m_width = 0;
  int m_height = 0;
  std::vector<float> m_values;
  EnvironmentConvention m_convention = EnvironmentConvention::Prizma;
  bool m_constant = false;
  double m_cos_rot = 1.0, m_sin_rot = 0.0;
  std::vector<double> m_row_cdf;  // [height + 1]: marginal over rows, ∝ Σ_x L(x, y) · row_weight(y)
  std::vector<double> m_col_cdf;  // [height][width + 1]: conditional over columns within each row
  double m_integral = 0.0;        // ∫∫ L · row weight du dv over the unit square
};

}  // namespace prizma::render
