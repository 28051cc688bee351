// The relight row kernel (relight_simd.cpp) on every SIMD target this CPU runs, against a scalar
// double-precision sum: the same results within float rounding, whichever target is chosen.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "prizma/relight/relight_image.h"
#include "prizma/relight/relight_matrix.h"
#include "prizma/relight/relight_simd.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

using namespace prizma;

spectral::SpectralImage random_image(int width, int height, int bins, int layers, unsigned seed) {
  spectral::SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = spectral::BinLayout::linear(400.0, 700.0, bins);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  for (int l = 0; l < layers; ++l) {
    spectral::TransportLayer layer;
    layer.name = "l" + std::to_string(l);
    layer.data.resize(img.pixel_count() * static_cast<std::size_t>(bins));
    for (float& v : layer.data) v = u(rng);
    img.lights.push_back(std::move(layer));
  }
  return img;
}

struct ForcedTarget {
  explicit ForcedTarget(const std::string& name) { relight::detail::relight_simd_force_target(name); }
  ~ForcedTarget() { relight::detail::relight_simd_force_target(""); }
  ForcedTarget(const ForcedTarget&) = delete;
  ForcedTarget& operator=(const ForcedTarget&) = delete;
};

TEST(RelightSimd, EveryTargetMatchesTheScalarSum) {
  const std::vector<std::string> targets = relight::detail::relight_simd_targets();
  ASSERT_FALSE(targets.empty());
#if defined(__x86_64__)
  EXPECT_GE(targets.size(), 2u) << "a SIMD target and the portable fallback";
#endif
  // Bin counts that fill whole vectors of every width and ones that leave a tail.
  for (const int bins : {1, 5, 16, 32, 33, 64}) {
    const spectral::SpectralImage img = random_image(19, 7, bins, 2, 100u + static_cast<unsigned>(bins));
    const std::vector<relight::LightSpec> lights = {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")};
    const relight::RelightMatrix matrix(img.bins, lights, {});
    // Reference: the float weights relight_into uses, summed in double.
    std::vector<double> ref(3 * img.pixel_count(), 0.0), mag(3 * img.pixel_count(), 0.0);
    for (int l = 0; l < 2; ++l)
      for (std::size_t p = 0; p < img.pixel_count(); ++p)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < bins; ++i) {
            const double w = static_cast<float>(matrix.light(l)(c, i));
            const double t = img.lights[static_cast<std::size_t>(l)].data[p * static_cast<std::size_t>(bins) +
                                                                          static_cast<std::size_t>(i)];
            ref[3 * p + static_cast<std::size_t>(c)] += w * t;
            mag[3 * p + static_cast<std::size_t>(c)] += std::abs(w * t);
          }
    std::vector<float> first;
    for (const std::string& target : targets) {
      const ForcedTarget forced(target);
      ASSERT_EQ(relight::detail::relight_simd_target(), target);
      const relight::XyzImage out = relight::relight_image(img, matrix);
      ASSERT_EQ(out.xyz.size(), ref.size());
      for (std::size_t k = 0; k < ref.size(); ++k) {
        // Float sums of up to 128 positive terms: a few ulps of the magnitude.
        ASSERT_NEAR(out.xyz[k], ref[k], 1e-5 * mag[k] + 1e-30) << target << ", " << bins << " bins, value " << k;
      }
      if (first.empty()) {
        first = out.xyz;
      } else {
        for (std::size_t k = 0; k < ref.size(); ++k) ASSERT_NEAR(out.xyz[k], first[k], 2e-5 * mag[k]) << target;
      }
    }
  }
  EXPECT_EQ(relight::detail::relight_simd_target(), targets.front());
}

TEST(RelightSimd, FoldedBispectralTermMatchesADoubleReferenceOnEveryTarget) {
  // A fluorescent image: the re-radiation (K·ē through the 3×3 output matrix) runs in the same row
  // pass as the diagonal (relight_row_terms_simd). Reference: T·M_l + output·Σ_out C·M·ē in double
  // straight from the pairs, never through K. Bin counts and |in| that leave tails on every width.
  const std::vector<std::string> targets = relight::detail::relight_simd_targets();
  for (const int bins : {5, 12, 33}) {
    spectral::SpectralImage img = random_image(13, 5, bins, 2, 300u + static_cast<unsigned>(bins));
    for (int in = 0; in < bins / 2; ++in)
      for (int out = bins / 2; out < bins; out += 2) img.reradiation.push_back({in, out});
    std::mt19937 rng(77u + static_cast<unsigned>(bins));
    std::uniform_real_distribution<float> u(0.0f, 0.3f);
    for (auto& layer : img.lights) {
      layer.reradiation.resize(img.pixel_count() * img.reradiation.size());
      for (float& v : layer.reradiation) v = u(rng);
    }
    relight::RelightOptions opts;
    opts.exposure_ev = 0.7;
    opts.adapt_to_d65 = true;  // a full 3×3 output matrix
    const std::vector<relight::LightSpec> lights = {relight::parse_light_spec("LED-V1"), relight::parse_light_spec("A*0.5")};
    const relight::RelightMatrix matrix(img.bins, lights, opts);
    const relight::Matrix3Xd c_out = relight::bin_cmf_integrals(opts.cmf, img.bins);
    std::vector<double> ref(3 * img.pixel_count(), 0.0), mag(3 * img.pixel_count(), 0.0);
    const std::size_t np = img.reradiation.size(), nb = static_cast<std::size_t>(bins);
    for (std::size_t l = 0; l < 2; ++l) {
      const Eigen::VectorXd& e = matrix.light_bin_average(static_cast<int>(l));
      for (std::size_t p = 0; p < img.pixel_count(); ++p) {
        Eigen::Vector3d rr = Eigen::Vector3d::Zero(), rr_mag = Eigen::Vector3d::Zero();
        for (std::size_t q = 0; q < np; ++q) {
          const auto& pr = img.reradiation[q];
          const double m = img.lights[l].reradiation[p * np + q];
          rr += c_out.col(pr.out) * m * e[pr.in];
          rr_mag += (c_out.col(pr.out) * m * e[pr.in]).cwiseAbs();
        }
        const Eigen::Vector3d add = matrix.output() * rr;
        const Eigen::Vector3d add_mag = matrix.output().cwiseAbs() * rr_mag;
        for (int c = 0; c < 3; ++c) {
          double sum = 0.0, sum_mag = 0.0;
          for (std::size_t i = 0; i < nb; ++i) {
            const double t = matrix.light(static_cast<int>(l))(c, static_cast<Eigen::Index>(i)) * img.lights[l].data[p * nb + i];
            sum += t;
            sum_mag += std::abs(t);
          }
          ref[3 * p + static_cast<std::size_t>(c)] += sum + add[c];
          mag[3 * p + static_cast<std::size_t>(c)] += sum_mag + add_mag[c];
        }
      }
    }
    double rerad_share = 0.0;  // the test must see the re-radiation: a sizeable part of the result
    for (const std::string& target : targets) {
      const ForcedTarget forced(target);
      const relight::ReradiationWeights k = relight::reradiation_weights(img, opts.cmf);
      std::vector<float> out(3 * img.pixel_count()), diag(3 * img.pixel_count());
      relight::relight_into(img, matrix, out.data(), &k);
      spectral::SpectralImage plain = img;
      plain.reradiation.clear();
      for (auto& layer : plain.lights) layer.reradiation.clear();
      relight::relight_into(plain, matrix, diag.data());
      for (std::size_t q = 0; q < ref.size(); ++q) {
        // Float rounding of the weights, of K and of sums of up to ~130 terms: a few ulps of the magnitude.
        ASSERT_NEAR(out[q], ref[q], 1e-5 * mag[q] + 1e-30) << target << ", " << bins << " bins, value " << q;
        rerad_share = std::max(rerad_share, std::abs(out[q] - diag[q]) / mag[q]);
      }
    }
    EXPECT_GT(rerad_share, 0.05) << bins << " bins: the re-radiation is too small to be checked";
  }
}

TEST(RelightSimd, SameTargetSameBits) {
  // One machine, one target: repeated relights are bit-identical (rows are independent of threads).
  const spectral::SpectralImage img = random_image(64, 32, 16, 2, 7u);
  const std::vector<relight::LightSpec> lights = {relight::parse_light_spec("A"), relight::parse_light_spec("D65")};
  const relight::RelightMatrix matrix(img.bins, lights, {});
  const relight::XyzImage a = relight::relight_image(img, matrix);
  const relight::XyzImage b = relight::relight_image(img, matrix);
  EXPECT_EQ(a.xyz, b.xyz);
}

}  // namespace
