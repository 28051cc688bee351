// Colour spaces: sRGB matrix and curve, Lab, Bradford, ΔE76, CIEDE2000.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "prizma/spectral/colour.h"

using namespace prizma::spectral;

TEST(Colour, WhitePointsFromXy) {
  const Eigen::Vector3d w = white_d65();
  EXPECT_NEAR(w[0], 0.3127 / 0.3290, 1e-12);
  EXPECT_DOUBLE_EQ(w[1], 1.0);
  EXPECT_NEAR(w[2], (1 - 0.3127 - 0.3290) / 0.3290, 1e-12);
  const Eigen::Vector2d xy = chromaticity(white_d50());
  EXPECT_NEAR(xy[0], 0.3457, 1e-12);
  EXPECT_NEAR(xy[1], 0.3585, 1e-12);
  EXPECT_EQ(chromaticity(Eigen::Vector3d::Zero()), Eigen::Vector2d::Zero());
}

TEST(Colour, D65WhiteIsSrgbWhite) {
  // IEC 61966-2-1: the D65 white maps to R = G = B = 1 (to the 4-decimal matrix's rounding).
  const Eigen::Vector3d rgb = xyz_to_linear_srgb(white_d65());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 2e-4) << c;
  // IEC 61966-2-1 printed matrix entry.
  EXPECT_DOUBLE_EQ(xyz_to_linear_srgb_matrix()(0, 0), 3.2406);
  const Eigen::Vector3d back = linear_srgb_to_xyz(Eigen::Vector3d(0.2, 0.5, 0.9));
  EXPECT_NEAR((xyz_to_linear_srgb(back) - Eigen::Vector3d(0.2, 0.5, 0.9)).norm(), 0.0, 1e-12);
  // Y of sRGB green is ≈ 0.7152 (IEC 61966-2-1 RGB→XYZ matrix).
  EXPECT_NEAR(linear_srgb_to_xyz(Eigen::Vector3d(0, 1, 0))[1], 0.7152, 1e-4);
}

TEST(Colour, SrgbCurve) {
  EXPECT_DOUBLE_EQ(srgb_encode(0.0), 0.0);
  EXPECT_DOUBLE_EQ(srgb_encode(-0.5), 0.0);
  EXPECT_DOUBLE_EQ(srgb_decode(-0.5), 0.0);
  EXPECT_DOUBLE_EQ(srgb_encode(std::nan("")), 0.0);
  EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-12);
  EXPECT_NEAR(srgb_encode(0.18), 0.4613561295, 1e-9);  // 1.055·0.18^(1/2.4) − 0.055
  EXPECT_NEAR(srgb_encode(0.001), 0.01292, 1e-15);
  // Continuity at the breakpoint: both pieces agree to within the standard's rounding (≈ 1e-8).
  const double x0 = 0.0031308;
  const double linear_piece = 12.92 * x0;
  const double power_piece = 1.055 * std::pow(x0, 1.0 / 2.4) - 0.055;
  EXPECT_NEAR(linear_piece, power_piece, 1e-7);
  EXPECT_NEAR(srgb_encode(std::nextafter(x0, 0.0)), srgb_encode(std::nextafter(x0, 1.0)), 1e-7);
  EXPECT_NEAR(srgb_decode(std::nextafter(0.04045, 0.0)), srgb_decode(std::nextafter(0.04045, 1.0)), 1e-8);
  for (double v : {0.0005, 0.003, 0.0032, 0.05, 0.2, 0.7, 1.0}) EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 1e-12) << v;
}

TEST(Colour, LabOfWhiteAndRoundTrip) {
  const Eigen::Vector3d w = white_d50();
  const Eigen::Vector3d lab_w = xyz_to_lab(w, w);
  EXPECT_NEAR(lab_w[0], 100.0, 1e-12);
  EXPECT_NEAR(lab_w[1], 0.0, 1e-12);
  EXPECT_NEAR(lab_w[2], 0.0, 1e-12);
  // 18 % grey: L* = 116·0.18^(1/3) − 16 = 49.496
  EXPECT_NEAR(xyz_to_lab(0.18 * w, w)[0], 116.0 * std::cbrt(0.18) - 16.0, 1e-12);
  // Round trip through both branches of f (including very dark colours in the linear segment).
  for (const Eigen::Vector3d& xyz : {Eigen::Vector3d(0.3, 0.4, 0.2), Eigen::Vector3d(0.001, 0.002, 0.004),
                                     Eigen::Vector3d(0.9, 0.05, 0.6), Eigen::Vector3d(0, 0, 0)}) {
    const Eigen::Vector3d back = lab_to_xyz(xyz_to_lab(xyz, w), w);
    EXPECT_NEAR((back - xyz).norm(), 0.0, 1e-12) << xyz.transpose();
  }
}

TEST(Colour, BradfordMapsWhiteToWhite) {
  const Eigen::Matrix3d m = bradford_adaptation(white_d65(), white_d50());
  EXPECT_NEAR((m * white_d65() - white_d50()).norm(), 0.0, 1e-12);
  const Eigen::Matrix3d back = bradford_adaptation(white_d50(), white_d65());
  EXPECT_NEAR((back * m - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  // Published D65→D50 Bradford matrix (Lindbloom, computed from the same xy whites), first row.
  EXPECT_NEAR(m(0, 0), 1.0478112, 2e-4);
  EXPECT_NEAR(m(0, 1), 0.0228866, 2e-4);
  EXPECT_NEAR(m(0, 2), -0.0501270, 2e-4);
}

TEST(Colour, DeltaE76IsEuclidean) {
  EXPECT_DOUBLE_EQ(delta_e76({50, 0, 0}, {53, 4, 0}), 5.0);
  EXPECT_DOUBLE_EQ(delta_e76({50, 10, -3}, {50, 10, -3}), 0.0);
}
