#pragma once
// Colour spaces: XYZ ↔ linear sRGB (IEC 61966-2-1), the sRGB transfer function, CIELAB, Bradford
// chromatic adaptation, ΔE76 and CIEDE2000. Pure functions on Eigen vectors.
#include <Eigen/Core>

namespace prizma::spectral {

// White points (Y = 1) from CIE 015 xy: D65 (0.3127, 0.3290), D50 (0.3457, 0.3585).
Eigen::Vector3d white_d65();
Eigen::Vector3d white_d50();
Eigen::Vector3d xy_to_xyz(double x, double y, double luminance = 1.0);
// Chromaticity (x, y); (0, 0) for black.
Eigen::Vector2d chromaticity(const Eigen::Vector3d& xyz);

// IEC 61966-2-1 matrices (D65 white).
Eigen::Matrix3d xyz_to_linear_srgb_matrix();
Eigen::Vector3d xyz_to_linear_srgb(const Eigen::Vector3d& xyz);
Eigen::Vector3d linear_srgb_to_xyz(const Eigen::Vector3d& rgb);
// sRGB transfer function (piecewise, 0.0031308 / 12.92 / 2.4), and its inverse. Negative in → 0 out.
double srgb_encode(double linear);
double srgb_decode(double encoded);

Eigen::Vector3d xyz_to_lab(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white_xyz);
Eigen::Vector3d lab_to_xyz(const Eigen::Vector3d& lab, const Eigen::Vector3d& white_xyz);

// Bradford chromatic adaptation from one white to another (von Kries in the Bradford cone space).
Eigen::Matrix3d bradford_adaptation(const Eigen::Vector3d& from_white_xyz, const Eigen::Vector3d& to_white_xyz);

double delta_e76(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2);
// CIEDE2000 (Sharma, Wu, Dalal 2005), kL = kC = kH = 1.
double delta_e2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2);

}  // namespace prizma::spectral
