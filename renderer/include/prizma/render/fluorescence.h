#pragma once
// Fluorescence in the film: which bispectral terms M[out][in] a scene can make (docs/fluorescence.md).
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

// The area the renderer normalises a fluorescence emission spectrum by: ∫ e dλ over its table,
// clipped to 360–830 nm (constants: over 360–830 nm).
double fluorescence_emission_area(const spectral::Spectrum& emission);

struct FluorescenceLayout {
  bool any = false;                      // some material fluoresces with q > 0
  std::vector<spectral::BinPair> pairs;  // off-diagonal terms (in ≠ out) that can be non-zero, sorted
  std::vector<int> diagonal;             // bins that are both an in and an out bin (their term adds to T)
};

// In bins: where some fluorescent material absorbs (σf > 0 somewhere in the bin); out bins: where its
// emission is > 0. Every in × out pair of one material can be non-zero (several events chain
// materials, so the union over all materials' ins and outs is taken).
FluorescenceLayout fluorescence_layout(const Medium& medium, const spectral::BinLayout& bins);

}  // namespace prizma::render

namespace prizma::render {

// Draws an excitation wavelength λin for `--wavelength-sampling single` (one wavelength per path):
// with density ∝ σf(λ)·λ over [lo_nm, hi_nm] (the render's bins), the photons a dye absorbs weighted
// by the energy factor of the energy-radiance convention (docs/fluorescence.md). Cells: the breakpoints
// of σf's table and a grid of at most kCellNm, ∫ σf·λ exact on each (σf linear inside a cell); a draw
// picks a cell by its integral and λ uniformly inside it, so the weight σf(λ)·λ / (Λ·pdf(λ)) is close
// to 1 (exactly 1 where σf is constant).
class ExcitationSampler {
 public:
  static constexpr double kCellNm = 1.0;
  ExcitationSampler() = default;
  ExcitationSampler(const spectral::Spectrum& sigma_f, double lo_nm, double hi_nm);
  // Λ = ∫_{lo}^{hi} σf(λ)·λ dλ (nm² per scene unit); 0: the dye absorbs nothing in the range.
  double total() const { return m_total; }
  struct Draw {
    double lambda_nm = 0.0;
    double weight = 0.0;  // σf(λ)·λ / (Λ·pdf(λ)), mean 1
  };
  // u uniform in [0, 1); total() must be > 0.
  Draw sample(double u) const;

 private:
  const spectral::Spectrum* m_sigma_f = nullptr;  // not owned (the scene's material)
  std::vector<double> m_edges_nm;  // cell edges
  std::vector<double> m_cdf;       // cumulative ∫ σf·λ up to each edge (m_cdf[0] = 0)
  double m_total = 0.0;
};

}  // namespace prizma::render
