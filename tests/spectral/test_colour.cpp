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

namespace {

struct De2000Pair {
  double l1, a1, b1, l2, a2, b2, de;
};

// Sharma, Wu & Dalal (2005), "The CIEDE2000 color-difference formula: implementation notes,
// supplementary test data, and mathematical observations", Color Res. Appl. 30(1):21–30, Table 1:
// the 34 test pairs (including the hue wrap-around pairs 9–16 and the achromatic pairs 7–8, 16),
// ΔE00 given to 4 decimals. Typed in from the publication; the values agree with the separate
// implementation in colour.cpp to within the table's rounding (checked below to 1e-4).
constexpr De2000Pair kSharmaTable1[] = {
    {50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425},
    {50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615},
    {50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412},
    {50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669},
    {50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461},
    {50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065},
    {50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492},
    {50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977},
    {50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030},
    {50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000},
    {60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644},
    {63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630},
    {61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731},
    {35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645},
    {22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373},
    {36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146},
    {90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441},
    {90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381},
    {6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377},
    {2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082},
};

}  // namespace

TEST(Colour, Ciede2000SharmaTable1) {
  int pair = 1;
  for (const auto& p : kSharmaTable1) {
    const Eigen::Vector3d lab1(p.l1, p.a1, p.b1), lab2(p.l2, p.a2, p.b2);
    EXPECT_NEAR(delta_e2000(lab1, lab2), p.de, 1e-4) << "pair " << pair;
    // Symmetric in its arguments (the published pairs 7/8 are the swapped pair).
    EXPECT_NEAR(delta_e2000(lab2, lab1), p.de, 1e-4) << "pair " << pair << " swapped";
    ++pair;
  }
  EXPECT_EQ(pair, 35);
}

TEST(Colour, Ciede2000ZeroForIdenticalAndSymmetric) {
  for (const Eigen::Vector3d& lab : {Eigen::Vector3d(50, 0, 0), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(73, 25, -18),
                                     Eigen::Vector3d(35, -44, 3.8), Eigen::Vector3d(100, 0, 0)}) {
    EXPECT_EQ(delta_e2000(lab, lab), 0.0) << lab.transpose();
  }
  const Eigen::Vector3d a(40, 30, -20), b(45, -12, 8);
  EXPECT_DOUBLE_EQ(delta_e2000(a, b), delta_e2000(b, a));
  EXPECT_GT(delta_e2000(a, b), 10.0);
  // For a pure lightness difference at L̄ = 50, S_L = 1, so ΔE00 = ΔL.
  EXPECT_NEAR(delta_e2000({49, 0, 0}, {51, 0, 0}), 2.0, 1e-12);
}
