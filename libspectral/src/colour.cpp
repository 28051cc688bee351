#include "prizma/spectral/colour.h"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

namespace prizma::spectral {

namespace {

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }
double rad(double degrees) { return degrees * std::numbers::pi / 180.0; }

// CIE 1976 L*a*b* constants (CIE 015:2018 §8.2.1, exact rational forms).
constexpr double kLabEpsilon = 216.0 / 24389.0;
constexpr double kLabKappa = 24389.0 / 27.0;

double lab_f(double t) { return t > kLabEpsilon ? std::cbrt(t) : (kLabKappa * t + 16.0) / 116.0; }
double lab_f_inv(double f) {
  const double f3 = f * f * f;
  return f3 > kLabEpsilon ? f3 : (116.0 * f - 16.0) / kLabKappa;
}

}  // namespace

Eigen::Vector3d xy_to_xyz(double x, double y, double luminance) {
  if (y == 0.0) return Eigen::Vector3d::Zero();
  return {x * luminance / y, luminance, (1.0 - x - y) * luminance / y};
}

Eigen::Vector3d white_d65() { return xy_to_xyz(0.3127, 0.3290); }
Eigen::Vector3d white_d50() { return xy_to_xyz(0.3457, 0.3585); }

Eigen::Vector2d chromaticity(const Eigen::Vector3d& xyz) {
  const double s = xyz.sum();
  if (s == 0.0 || !std::isfinite(s)) return Eigen::Vector2d::Zero();
  return {xyz[0] / s, xyz[1] / s};
}

// IEC 61966-2-1:1999 §5.2, the XYZ → linear RGB matrix as printed (4 decimals). The reverse
// transform is its exact inverse, so a round trip is the identity to rounding.
Eigen::Matrix3d xyz_to_linear_srgb_matrix() {
  Eigen::Matrix3d m;
  m << 3.2406, -1.5372, -0.4986,
      -0.9689, 1.8758, 0.0415,
       0.0557, -0.2040, 1.0570;
  return m;
}

Eigen::Vector3d xyz_to_linear_srgb(const Eigen::Vector3d& xyz) { return xyz_to_linear_srgb_matrix() * xyz; }

Eigen::Vector3d linear_srgb_to_xyz(const Eigen::Vector3d& rgb) {
  static const Eigen::Matrix3d inv = xyz_to_linear_srgb_matrix().inverse();
  return inv * rgb;
}

double srgb_encode(double linear) {
  if (!(linear > 0.0)) return 0.0;
  if (linear <= 0.0031308) return 12.92 * linear;
  return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double srgb_decode(double encoded) {
  if (!(encoded > 0.0)) return 0.0;
  if (encoded <= 0.04045) return encoded / 12.92;
  return std::pow((encoded + 0.055) / 1.055, 2.4);
}

Eigen::Vector3d xyz_to_lab(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white_xyz) {
  const double fx = lab_f(xyz[0] / white_xyz[0]);
  const double fy = lab_f(xyz[1] / white_xyz[1]);
  const double fz = lab_f(xyz[2] / white_xyz[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Eigen::Vector3d lab_to_xyz(const Eigen::Vector3d& lab, const Eigen::Vector3d& white_xyz) {
  const double fy = (lab[0] + 16.0) / 116.0;
  const double fx = fy + lab[1] / 500.0;
  const double fz = fy - lab[2] / 200.0;
  // For Y use L* directly in the linear segment (exact inverse of L* = κ·Y/Yn there).
  const double yr = lab[0] > kLabKappa * kLabEpsilon ? fy * fy * fy : lab[0] / kLabKappa;
  return {lab_f_inv(fx) * white_xyz[0], yr * white_xyz[1], lab_f_inv(fz) * white_xyz[2]};
}

// Bradford cone response matrix (Lam 1985; as in CIECAM97s and ICC v4 Annex E).
Eigen::Matrix3d bradford_adaptation(const Eigen::Vector3d& from_white_xyz, const Eigen::Vector3d& to_white_xyz) {
  Eigen::Matrix3d b;
  b << 0.8951, 0.2664, -0.1614,
      -0.7502, 1.7135, 0.0367,
       0.0389, -0.0685, 1.0296;
  const Eigen::Vector3d src = b * from_white_xyz;
  const Eigen::Vector3d dst = b * to_white_xyz;
  const Eigen::Matrix3d scale = dst.cwiseQuotient(src).asDiagonal();
  return b.inverse() * scale * b;
}

double delta_e76(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2) { return (lab1 - lab2).norm(); }

// CIEDE2000 following Sharma, Wu & Dalal, "The CIEDE2000 color-difference formula: implementation
// notes, supplementary test data, and mathematical observations", Color Res. Appl. 30 (2005),
// equations (1)–(17), with kL = kC = kH = 1.
double delta_e2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2) {
  const double l1 = lab1[0], a1 = lab1[1], b1 = lab1[2];
  const double l2 = lab2[0], a2 = lab2[1], b2 = lab2[2];
  // (2)–(7): a' and C', h' in degrees [0, 360); h' = 0 where a' = b' = 0.
  const double c1 = std::hypot(a1, b1), c2 = std::hypot(a2, b2);
  const double c_bar = 0.5 * (c1 + c2);
  const double c_bar7 = std::pow(c_bar, 7.0);
  const double g = 0.5 * (1.0 - std::sqrt(c_bar7 / (c_bar7 + std::pow(25.0, 7.0))));
  const double a1p = (1.0 + g) * a1, a2p = (1.0 + g) * a2;
  const double c1p = std::hypot(a1p, b1), c2p = std::hypot(a2p, b2);
  auto hue = [](double b, double ap) {
    if (b == 0.0 && ap == 0.0) return 0.0;
    double h = deg(std::atan2(b, ap));
    if (h < 0.0) h += 360.0;
    return h;
  };
  const double h1p = hue(b1, a1p), h2p = hue(b2, a2p);
  // (8)–(10): differences; Δh' = 0 when either chroma is zero, else wrapped to (−180, 180].
  const double dlp = l2 - l1;
  const double dcp = c2p - c1p;
  double dhp = 0.0;
  if (c1p * c2p != 0.0) {
    dhp = h2p - h1p;
    if (dhp > 180.0) dhp -= 360.0;
    else if (dhp < -180.0) dhp += 360.0;
  }
  const double dHp = 2.0 * std::sqrt(c1p * c2p) * std::sin(rad(dhp / 2.0));
  // (11)–(14): means; mean hue is the plain sum when either chroma is zero.
  const double lbp = 0.5 * (l1 + l2);
  const double cbp = 0.5 * (c1p + c2p);
  double hbp = h1p + h2p;
  if (c1p * c2p != 0.0) {
    if (std::abs(h1p - h2p) <= 180.0) hbp *= 0.5;
    else if (h1p + h2p < 360.0) hbp = 0.5 * (hbp + 360.0);
    else hbp = 0.5 * (hbp - 360.0);
  }
  // (15)–(17): weights and rotation term.
  const double t = 1.0 - 0.17 * std::cos(rad(hbp - 30.0)) + 0.24 * std::cos(rad(2.0 * hbp)) +
                   0.32 * std::cos(rad(3.0 * hbp + 6.0)) - 0.20 * std::cos(rad(4.0 * hbp - 63.0));
  const double d_theta = 30.0 * std::exp(-((hbp - 275.0) / 25.0) * ((hbp - 275.0) / 25.0));
  const double cbp7 = std::pow(cbp, 7.0);
  const double rc = 2.0 * std::sqrt(cbp7 / (cbp7 + std::pow(25.0, 7.0)));
  const double lb50 = (lbp - 50.0) * (lbp - 50.0);
  const double sl = 1.0 + 0.015 * lb50 / std::sqrt(20.0 + lb50);
  const double sc = 1.0 + 0.045 * cbp;
  const double sh = 1.0 + 0.015 * cbp * t;
  const double rt = -std::sin(rad(2.0 * d_theta)) * rc;
  const double tl = dlp / sl, tc = dcp / sc, th = dHp / sh;
  return std::sqrt(std::max(0.0, tl * tl + tc * tc + th * th + rt * tc * th));
}

}  // namespace prizma::spectral
