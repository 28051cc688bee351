#pragma once
// What the live page relights from, as the texture layers it uploads and the weights its shader
// multiplies them by (docs/relight.md, "What the page does"): the session's transport bins, four per
// RGBA texel (bispectral files add each light's re-radiation weights K after its bins), or, when the
// session relights from spectral-basis coefficients (prizma-relight compress), each light's k
// coefficients, four per texel, with W_l = M_l·B_l as weights: the very numbers relight_compressed_into
// uses, so the canvas is the CLI's compressed relight.
#include <map>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include "prizma/spectral/relight_image.h"
#include "prizma/relight/relight_session.h"

namespace prizma::relight {

class PageTransport {
 public:
  // Values per texel (RGBA); values past a light's last are zero.
  static constexpr int kValuesPerTexel = 4;

  // Keeps a reference to the session; its image and coefficients must outlive this.
  explicit PageTransport(const RelightSession& session);

  bool from_coefficients() const { return m_session.coefficients() != nullptr; }
  // Texel groups per light for what is relit (bins or coefficients; the largest k of the lights),
  // and, bispectral files only, the groups of K that follow them.
  int groups() const;
  int reradiation_groups() const;

  // For /api/info: "transport" ("bins" or "coefficients"), "groups", "binsPerTexel", "reradiation"
  // (bispectral: pairs, in bins, groups; else null) and "coefficients" (per light k, the basis as n×k
  // column-major floats with its power-of-two scale, and the file's recorded ΔE00 errors; else null).
  nlohmann::json describe() const;

  // One texture layer, RGBA texels of every pixel, rows top first, little-endian float or half: group
  // g of light l (bins or coefficients 4g…4g+3); for g past groups(), values 4g'…4g'+3 of the light's
  // K (3·|in| per pixel) for observer `cmf`. Coefficients are stored as half: their half texels are
  // the file's bits, their float texels exact. Thread-safe.
  std::string layer(int light, int group, bool half, spectral::Observer cmf);

  // For /api/weights (without its "state"): "white", the mix's white XYZ, and "lights": per light
  // "name", "on" and "w" (3 rows of the values per pixel the layers hold,
  // row-major X, Y, Z; n for bins, k_l for coefficients); bispectral files add "wr", the weights of K.
  nlohmann::json weights(const RelightSettings& settings) const;

 private:
  const RelightSession& m_session;
  std::mutex m_mutex;  // guards the cache of K
  std::map<spectral::Observer, spectral::ReradiationWeights> m_reradiation;  // per observer, on first use
};

}  // namespace prizma::relight
