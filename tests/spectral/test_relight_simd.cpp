// The relight row kernel (relight_simd.cpp) at every SIMD level this CPU runs: against a scalar
// double-precision sum within float rounding, and the same bits at every level.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/relight_simd.h"
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

using spectral::SimdLevel;

struct ForcedLevel : spectral::ForcedSimdLevel {
  explicit ForcedLevel(SimdLevel level) : spectral::ForcedSimdLevel(spectral::SimdKernel::Relight, level) {}
};

// Bit for bit, with the first index that differs.
::testing::AssertionResult same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0)
      return ::testing::AssertionFailure() << "value " << i << ": " << a[i] << " and " << b[i];
  return ::testing::AssertionSuccess();
}

TEST(RelightSimd, EveryLevelMatchesTheScalarSumWithTheSameBits) {
  const std::vector<SimdLevel> targets = spectral::detail::relight_simd_levels();
  ASSERT_FALSE(targets.empty());
  EXPECT_EQ(targets.front(), SimdLevel::Baseline);
#if defined(__x86_64__)
  EXPECT_GE(targets.size(), 2u) << "a SIMD level and the portable fallback";
#endif
  // Bin counts that fill whole vectors of every width and ones that leave a tail.
  for (const int bins : {1, 5, 16, 32, 33, 64}) {
    const spectral::SpectralImage img = random_image(19, 7, bins, 2, 100u + static_cast<unsigned>(bins));
    const std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("D65"), spectral::parse_light_spectrum("F11")};
    const spectral::RelightMatrix matrix(img.bins, lights, {});
    // Reference: the float weights spectral::relight_into uses, summed in double.
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
    for (const SimdLevel target : targets) {
      const ForcedLevel forced(target);
      ASSERT_EQ(spectral::detail::relight_simd_level(), target);
      const spectral::XyzImage out = spectral::relight_image(img, matrix);
      ASSERT_EQ(out.xyz.size(), ref.size());
      for (std::size_t k = 0; k < ref.size(); ++k) {
        // Float sums of up to 128 positive terms: a few ulps of the magnitude.
        ASSERT_NEAR(out.xyz[k], ref[k], 1e-5 * mag[k] + 1e-30)
            << spectral::simd_level_name(target) << ", " << bins << " bins, value " << k;
      }
      if (first.empty())
        first = out.xyz;
      else
        EXPECT_TRUE(same_bits(out.xyz, first)) << spectral::simd_level_name(target) << ", " << bins << " bins";
    }
  }
}

TEST(RelightSimd, FoldedBispectralTermMatchesADoubleReferenceOnEveryTarget) {
  // A fluorescent image: the re-radiation (K·ē through the 3×3 output matrix) runs in the same row
  // pass as the diagonal (relight_row_terms_simd). Reference: T·M_l + output·Σ_out C·M·ē in double
  // straight from the pairs, never through K. Bin counts and |in| that leave tails on every width.
  const std::vector<SimdLevel> targets = spectral::detail::relight_simd_levels();
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
    spectral::RelightOptions opts;
    opts.exposure_ev = 0.7;
    opts.adapt_to_d65 = true;  // a full 3×3 output matrix
    const std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("LED-V1"), spectral::parse_light_spectrum("A*0.5")};
    const spectral::RelightMatrix matrix(img.bins, lights, opts);
    const spectral::Matrix3Xd c_out = spectral::bin_cmf_integrals(opts.cmf, img.bins);
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
    std::vector<float> first;
    for (const SimdLevel target : targets) {
      const ForcedLevel forced(target);
      const spectral::ReradiationWeights k = spectral::reradiation_weights(img, opts.cmf);
      std::vector<float> out(3 * img.pixel_count()), diag(3 * img.pixel_count());
      spectral::relight_into(img, matrix, out.data(), &k);
      spectral::SpectralImage plain = img;
      plain.reradiation.clear();
      for (auto& layer : plain.lights) layer.reradiation.clear();
      spectral::relight_into(plain, matrix, diag.data());
      for (std::size_t q = 0; q < ref.size(); ++q) {
        // Float rounding of the weights, of K and of sums of up to ~130 terms: a few ulps of the magnitude.
        ASSERT_NEAR(out[q], ref[q], 1e-5 * mag[q] + 1e-30)
            << spectral::simd_level_name(target) << ", " << bins << " bins, value " << q;
        rerad_share = std::max(rerad_share, std::abs(out[q] - diag[q]) / mag[q]);
      }
      if (first.empty())
        first = out;
      else
        EXPECT_TRUE(same_bits(out, first)) << spectral::simd_level_name(target) << ", " << bins << " bins";
    }
    EXPECT_GT(rerad_share, 0.05) << bins << " bins: the re-radiation is too small to be checked";
  }
}

TEST(RelightSimd, SameTargetSameBits) {
  // One machine, one target: repeated relights are bit-identical (rows are independent of threads).
  const spectral::SpectralImage img = random_image(64, 32, 16, 2, 7u);
  const std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("A"), spectral::parse_light_spectrum("D65")};
  const spectral::RelightMatrix matrix(img.bins, lights, {});
  const spectral::XyzImage a = spectral::relight_image(img, matrix);
  const spectral::XyzImage b = spectral::relight_image(img, matrix);
  EXPECT_EQ(a.xyz, b.xyz);
}

// A row of values that ends exactly where an inaccessible page begins: a read past its end faults.
class RowBeforeGuardPage {
 public:
  explicit RowBeforeGuardPage(std::size_t floats) {
    const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    m_pages = (floats * sizeof(float) + page - 1) / page + 1;
    m_size = m_pages * page;
    void* p = ::mmap(nullptr, m_size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::runtime_error("mmap failed");
    m_base = static_cast<char*>(p);
    ::mprotect(m_base + m_size - page, page, PROT_NONE);
    m_values = reinterpret_cast<float*>(m_base + m_size - page) - floats;
  }
  ~RowBeforeGuardPage() { ::munmap(m_base, m_size); }
  RowBeforeGuardPage(const RowBeforeGuardPage&) = delete;
  RowBeforeGuardPage& operator=(const RowBeforeGuardPage&) = delete;
  float* values() const { return m_values; }

 private:
  char* m_base = nullptr;
  std::size_t m_pages = 0, m_size = 0;
  float* m_values = nullptr;
};

TEST(RelightSimd, TheLastBlockNeverReadsPastTheRow) {
  // The kernel reads a pixel's last (partial) block of 16 values in place, past the pixel's own
  // values, except where that would leave the row: here the row is the end of a readable mapping,
  // so a read past it would crash. Value counts below, at and above one block; 1–9 pixels.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const int n : {1, 3, 5, 15, 17, 33, 40})
    for (const int width : {1, 2, 3, 9}) {
      const std::size_t floats = static_cast<std::size_t>(n) * static_cast<std::size_t>(width);
      const RowBeforeGuardPage row(floats);
      for (std::size_t i = 0; i < floats; ++i) row.values()[i] = u(rng);
      std::vector<float> weights(3 * static_cast<std::size_t>(n));
      for (float& w : weights) w = u(rng);
      const spectral::detail::SimdTerm term{weights.data(), row.values(), n};
      std::vector<float> first;
      for (const SimdLevel level : spectral::detail::relight_simd_levels()) {
        std::vector<float> out(3 * static_cast<std::size_t>(width));
        spectral::detail::relight_row_kernel(level)(&term, 1, 0, width, out.data());
        for (int x = 0; x < width; ++x)
          for (int c = 0; c < 3; ++c) {
            double ref = 0.0, mag = 0.0;
            for (int j = 0; j < n; ++j) {
              const double p = static_cast<double>(weights[static_cast<std::size_t>(c * n + j)]) *
                               row.values()[static_cast<std::size_t>(x * n + j)];
              ref += p;
              mag += std::abs(p);
            }
            ASSERT_NEAR(out[static_cast<std::size_t>(3 * x + c)], ref, 1e-6 * mag + 1e-30)
                << spectral::simd_level_name(level) << ", n " << n << ", width " << width;
          }
        if (first.empty())
          first = out;
        else
          EXPECT_TRUE(same_bits(out, first)) << spectral::simd_level_name(level) << ", n " << n << ", width " << width;
      }
    }
}

}  // namespace
