// The live page's texture layers and shader weights (page_transport.h).
#include "page_transport.h"

#include <Imath/half.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "prizma/relight/compressed_relight.h"
#include "prizma/spectral/bispectral.h"

namespace prizma::relight {

namespace {

using json = nlohmann::json;

int texel_groups(int values) { return (values + PageTransport::kValuesPerTexel - 1) / PageTransport::kValuesPerTexel; }

int largest_k(const CompressedTransport& c) {
  int k = 0;
  for (const CompressedLayer& layer : c.lights) k = std::max(k, layer.k);
  return k;
}

// Texels of `values_per_pixel` values per pixel (at `read(p, i)`), values [4g, 4g + 4), as float or half
// bytes; values past the last are 0.
template <class Read>
std::string texels(std::size_t pixels, int values_per_pixel, int g, bool half, Read read) {
  const std::size_t bytes = half ? sizeof(std::uint16_t) : sizeof(float);
  std::string out(pixels * PageTransport::kValuesPerTexel * bytes, '\0');
  for (std::size_t p = 0; p < pixels; ++p) {
    for (int c = 0; c < PageTransport::kValuesPerTexel; ++c) {
      const int i = g * PageTransport::kValuesPerTexel + c;
      if (i >= values_per_pixel) continue;
      char* at = out.data() + (p * PageTransport::kValuesPerTexel + static_cast<std::size_t>(c)) * bytes;
      read(p, i, half, at);
    }
  }
  return out;
}

void put(float v, bool half, char* at) {
  if (half) {
    const std::uint16_t bits = Imath::half(v).bits();
    std::memcpy(at, &bits, sizeof bits);
  } else {
    std::memcpy(at, &v, sizeof v);
  }
}

}  // namespace

PageTransport::PageTransport(const RelightSession& session) : m_session(session) {}

int PageTransport::groups() const {
  if (const CompressedTransport* c = m_session.coefficients()) return texel_groups(largest_k(*c));
  return texel_groups(m_session.image().bins.size());
}

int PageTransport::reradiation_groups() const {
  const auto& img = m_session.image();
  return img.reradiation.empty() ? 0 : texel_groups(3 * static_cast<int>(spectral::reradiation_in_bins(img).size()));
}

json PageTransport::describe() const {
  const auto& img = m_session.image();
  // Bispectral files: per light ⌈3·|in|/4⌉ more texture layers after the diagonal's, holding K
  // (X, Y, Z rows of |in| values each) for one observer.
  json rerad = nullptr;
  if (!img.reradiation.empty()) {
    json pairs = json::array();
    for (const auto& pr : img.reradiation) pairs.push_back({pr.in, pr.out});
    rerad = {{"inBins", spectral::reradiation_in_bins(img)}, {"groups", reradiation_groups()}, {"pairs", pairs}};
  }
  json coefficients = nullptr;
  if (const CompressedTransport* c = m_session.coefficients()) {
    json lights = json::array();
    for (const CompressedLayer& layer : c->lights) {
      json errors = json::array();
      for (const spectral::BasisError& e : layer.errors)
        errors.push_back({{"light", e.light}, {"percentile", e.percentile}, {"max", e.max}});
      const std::vector<float> basis(layer.basis.data(), layer.basis.data() + layer.basis.size());  // column-major
      lights.push_back({{"k", layer.k}, {"basis", basis}, {"errors", errors}});
    }
    coefficients = {{"lights", lights}, {"compact", img.compact()}};
  }
  return {{"transport", from_coefficients() ? "coefficients" : "bins"}, {"groups", groups()}, {"binsPerTexel", kValuesPerTexel},
          {"reradiation", rerad}, {"coefficients", coefficients}};
}

std::string PageTransport::layer(int light, int group, bool half, spectral::Observer cmf) {
  const auto& img = m_session.image();
  const std::size_t pixels = img.pixel_count();
  const auto l = static_cast<std::size_t>(light);
  if (group < groups()) {
    if (const CompressedTransport* c = m_session.coefficients()) {
      const CompressedLayer& layer = c->lights[l];
      const std::uint16_t* bits = layer.coefficients.data();
      const auto k = static_cast<std::size_t>(layer.k);
      return texels(pixels, layer.k, group, half, [&](std::size_t p, int i, bool as_half, char* at) {
        const std::uint16_t b = bits[p * k + static_cast<std::size_t>(i)];
        if (as_half) {
          std::memcpy(at, &b, sizeof b);  // the file's own bits
        } else {
          Imath::half h;
          h.setBits(b);
          put(static_cast<float>(h), false, at);  // exact
        }
      });
    }
    const std::vector<float>& data = img.lights[l].data;
    const int n = img.bins.size();
    return texels(pixels, n, group, half, [&](std::size_t p, int i, bool as_half, char* at) {
      put(data[p * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)], as_half, at);
    });
  }
  const std::lock_guard lock(m_mutex);
  auto it = m_reradiation.find(cmf);
  if (it == m_reradiation.end()) it = m_reradiation.emplace(cmf, spectral::reradiation_weights(img, cmf)).first;
  const std::vector<float>& k = it->second.per_light[l];
  const int n = 3 * static_cast<int>(it->second.in_bins.size());
  return texels(pixels, n, group - groups(), half, [&](std::size_t p, int i, bool as_half, char* at) {
    put(k[p * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)], as_half, at);
  });
}

json PageTransport::weights(const RelightSettings& s) const {
  const auto& img = m_session.image();
  const spectral::RelightMatrix m(img.bins, s.lights, s.relight);
  const CompressedTransport* c = m_session.coefficients();
  const std::vector<std::vector<float>> folded = c ? coefficient_weights(*c, m) : std::vector<std::vector<float>>{};
  spectral::ReradiationWeights in_bins;  // only the in bins: the weights of K do not depend on K
  in_bins.in_bins = spectral::reradiation_in_bins(img);
  json lights = json::array();
  for (int l = 0; l < m.light_count(); ++l) {
    const auto index = static_cast<std::size_t>(l);
    json light = {{"name", m_session.light_names()[index]}};
    if (c) {  // W_l = M_l·B_l, what relight_compressed_into multiplies the coefficients by (empty: off)
      const int k = c->lights[index].k;
      light["on"] = !folded[index].empty();
      light["w"] = folded[index].empty() ? std::vector<float>(3 * static_cast<std::size_t>(k), 0.0f) : folded[index];
    } else {
      const spectral::Matrix3Xd& w = m.light(l);
      std::vector<double> rows;  // row-major X, Y, Z rows of n weights
      for (int r = 0; r < 3; ++r)
        for (int i = 0; i < m.bin_count(); ++i) rows.push_back(w(r, i));
      light["on"] = !w.isZero(0.0);
      light["w"] = rows;
    }
    // Bispectral: the weights of K (3 × 3·|in|, row-major), what relight_into uses (relight_image.h).
    if (!img.reradiation.empty()) light["wr"] = spectral::reradiation_term_weights(m, in_bins, l).weights;
    lights.push_back(std::move(light));
  }
  const Eigen::Vector3d white = m.mix_white_xyz();
  return {{"lights", lights}, {"white", {white.x(), white.y(), white.z()}}};
}

}  // namespace prizma::relight
