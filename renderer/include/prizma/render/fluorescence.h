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
