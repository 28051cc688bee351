// Relighting a bispectral (fluorescent) image: out = M·E, then XYZ, through the per-pixel
// K[c][in] = Σ_out cmf_c(out)·M[out][in] (docs/fluorescence.md), against a hand evaluation from the
// CIE table and the light's exact shape.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/relight_matrix.h"
#include "spectral/relight_test_util.h"

namespace prizma::spectral {
namespace {

std::vector<LightSpectrum> lights(const std::vector<std::string>& specs) {
  std::vector<LightSpectrum> out;
  for (const auto& s : specs) out.push_back(parse_light_spectrum(s));
  return out;
}

// ∫ f dλ by the trapezoid rule on a 0.05 nm grid.
double hand_integral(const std::function<double(double)>& f, double lo, double hi) {
  const int steps = static_cast<int>(std::lround((hi - lo) / 0.05));
  const double h = (hi - lo) / steps;
  double sum = 0.0;
  for (int k = 0; k <= steps; ++k) sum += (k == 0 || k == steps ? 0.5 : 1.0) * f(lo + k * h);
  return sum * h;
}

// The same XYZ by hand: per light, radiance per out bin L = T·E inside the bin plus the constant
// Σ_in M[out][in]·ē_in, integrated against the CIE 1931 table, normalised by ∫E·ȳ over the bins.
std::vector<double> hand_xyz(const spectral::SpectralImage& img, const std::vector<std::function<double(double)>>& e) {
  static const test::Table cmf = test::read_table("cie1931_xyz2deg_1nm.csv");
  const int n = img.bins.size();
  std::vector<double> out(3 * img.pixel_count(), 0.0);
  for (std::size_t l = 0; l < img.lights.size(); ++l) {
    double y = 0.0;
    std::vector<double> ebar(n);
    for (int i = 0; i < n; ++i) {
      y += test::hand_weight(cmf, 1, e[l], img.bins.lo_nm(i), img.bins.hi_nm(i));
      ebar[i] = hand_integral(e[l], img.bins.lo_nm(i), img.bins.hi_nm(i)) / img.bins.width_nm(i);
    }
    if (!(y > 0.0)) continue;  // a dark light adds nothing
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      std::vector<double> rerad(n, 0.0);
      for (std::size_t k = 0; k < img.reradiation.size(); ++k)
        rerad[img.reradiation[k].out] += img.lights[l].reradiation[p * img.reradiation.size() + k] * ebar[img.reradiation[k].in];
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < n; ++i) {
          const double t = img.lights[l].data[p * n + i];
          out[3 * p + c] += (t * test::hand_weight(cmf, c, e[l], img.bins.lo_nm(i), img.bins.hi_nm(i)) +
                             rerad[i] * test::hand_weight(cmf, c, [](double) { return 1.0; }, img.bins.lo_nm(i), img.bins.hi_nm(i))) / y;
        }
    }
  }
  return out;
}

TEST(BispectralRelight, MatchesTheHandIntegralOfMTimesE) {
  const auto img = test::fluorescent_image();
  const auto violet = [](double l) { return std::exp(-4.0 * std::log(2.0) * (l - 420.0) * (l - 420.0) / (30.0 * 30.0)); };
  const auto flat = [](double) { return 1.0; };
  const XyzImage got = relight_image(img, RelightMatrix(img.bins, lights({"gaussian:420:30", "E*0.5"}), {}));
  std::vector<double> want = hand_xyz(img, {violet, flat});
  const std::vector<double> sky_only = hand_xyz(img, {[](double) { return 0.0; }, flat});
  ASSERT_EQ(got.xyz.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    // E*0.5: the scale applies after normalisation; the hand sum used scale 1 for "sky".
    const double w = want[k] - 0.5 * sky_only[k];
    EXPECT_NEAR(got.xyz[k], w, 2e-3 * std::abs(w) + 1e-5) << k;
  }
  // Without the bispectral terms the image is darker in X (red): the re-radiation was counted.
  auto diag = img;
  diag.reradiation.clear();
  for (auto& l : diag.lights) l.reradiation.clear();
  const XyzImage plain = relight_image(diag, RelightMatrix(img.bins, lights({"gaussian:420:30", "E*0.5"}), {}));
  EXPECT_GT(got.xyz[0], plain.xyz[0] + 0.01f);
}

TEST(BispectralRelight, PrecomputedWeightsGiveTheSameImage) {
  const auto img = test::fluorescent_image();
  RelightOptions o;
  o.exposure_ev = 1.0;
  o.adapt_to_d65 = true;
  const RelightMatrix m(img.bins, lights({"LED-V1", "off"}), o);
  const ReradiationWeights k = reradiation_weights(img, o.cmf);
  EXPECT_EQ(k.in_bins, (std::vector<int>{0, 1}));
  std::vector<float> a(3 * img.pixel_count()), b(3 * img.pixel_count());
  relight_into(img, m, a.data());
  relight_into(img, m, b.data(), &k);
  EXPECT_EQ(a, b);
  // A light that is off adds nothing, bispectral terms included.
  const XyzImage off = relight_image(img, RelightMatrix(img.bins, lights({"off", "off"}), {}));
  for (float v : off.xyz) EXPECT_EQ(v, 0.0f);
}

TEST(BispectralRelight, PreviewChannelsIncludeTheReradiation) {
  // The R, G, B channels written with a fluorescent image are prizma-relight's default image (each
  // light at its recorded spectrum) in linear sRGB: the diagonal and the re-radiated light, here
  // through relight_image's K path against the writer's per-pair sum (spectral_exr.cpp).
  auto img = test::fluorescent_image();
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"uv","spectrum":"LED-V1"},{"name":"sky","spectrum":"D65*0.2"}])", "test");
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("prizma-bispectral-preview-" + std::to_string(::getpid()) + ".exr");
  spectral::write_spectral_exr(path, img);
  auto in = OIIO::ImageInput::open(path.string());
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec spec = in->spec();
  std::vector<float> px(static_cast<std::size_t>(spec.width * spec.height * spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  in->close();
  std::filesystem::remove(path);
  const int ch[3] = {spec.channelindex("R"), spec.channelindex("G"), spec.channelindex("B")};
  ASSERT_GE(ch[0], 0);
  const XyzImage want = relight_image(img, RelightMatrix(img.bins, lights({"LED-V1", "D65*0.2"}), {}));
  auto diag = img;
  diag.reradiation.clear();
  for (auto& l : diag.lights) l.reradiation.clear();
  const XyzImage plain = relight_image(diag, RelightMatrix(img.bins, lights({"LED-V1", "D65*0.2"}), {}));
  const Eigen::Matrix3d to_rgb = spectral::xyz_to_linear_srgb_matrix();
  double largest_rerad = 0.0;
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    const Eigen::Vector3d rgb = to_rgb * want.at(static_cast<int>(p) % img.width, static_cast<int>(p) / img.width);
    const Eigen::Vector3d rgb_plain = to_rgb * plain.at(static_cast<int>(p) % img.width, static_cast<int>(p) / img.width);
    for (int c = 0; c < 3; ++c) {
      const double got = px[p * static_cast<std::size_t>(spec.nchannels) + static_cast<std::size_t>(ch[c])];
      EXPECT_NEAR(got, rgb[c], 1e-5 * std::abs(rgb[c]) + 1e-6) << "pixel " << p << " channel " << c;
      largest_rerad = std::max(largest_rerad, std::abs(rgb[c] - rgb_plain[c]));
    }
  }
  EXPECT_GT(largest_rerad, 0.01);  // the re-radiation is large enough to be seen by the check
}

}  // namespace
}  // namespace prizma::spectral
