#pragma once
// WavelengthMap: how a sample's path lanes map to the render's bins (docs/renderer.md,
// "Wavelengths"). AllBins: one lane per bin, λ_i = lo_i + u·Δλ_i with one jitter u for all bins
// (spectral tracking); Replicated: one lane at the first bin's centre, copied to every bin (a
// wavelength-independent medium); Single: VPT's method, one bin drawn per path, its lane × n into it.
#include <algorithm>

#include "prizma/render/rng.h"
#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

enum class LaneMode { AllBins, Replicated, Single };

// What one sample drew: the jitter shared by every bin, and Single's bin.
struct WavelengthDraw {
  double u = 0.0;
  int bin = 0;
};

class WavelengthMap {
 public:
  WavelengthMap(LaneMode mode, const spectral::BinLayout& bins) : m_mode(mode), m_bins(bins) {}

  LaneMode mode() const { return m_mode; }
  int lanes() const { return m_mode == LaneMode::AllBins ? m_bins.size() : 1; }

  // Draws the sample's wavelengths into lambda_nm[lanes()] (u, then Single's bin: the stream's
  // order is part of the output).
  WavelengthDraw draw(Rng& rng, float* lambda_nm) const {
    WavelengthDraw d;
    d.u = rng.uniform_double();
    const int nb = m_bins.size();
    switch (m_mode) {
      case LaneMode::Single:
        d.bin = std::min(nb - 1, static_cast<int>(rng.uniform_double() * nb));
        lambda_nm[0] = static_cast<float>(lambda_at(d, d.bin));
        break;
      case LaneMode::AllBins:
        for (int i = 0; i < nb; ++i) lambda_nm[i] = static_cast<float>(lambda_at(d, i));
        break;
      case LaneMode::Replicated:
        lambda_nm[0] = static_cast<float>(m_bins.centre_nm(0));
        break;
    }
    return d;
  }

  // One light's lane values of a sample → its bin values out[bins].
  void to_bins(const float* lanes, const WavelengthDraw& d, double* out) const {
    const int nb = m_bins.size();
    switch (m_mode) {
      case LaneMode::AllBins:
        for (int i = 0; i < nb; ++i) out[i] = lanes[i];
        break;
      case LaneMode::Replicated:
        for (int i = 0; i < nb; ++i) out[i] = lanes[0];
        break;
      case LaneMode::Single:
        for (int i = 0; i < nb; ++i) out[i] = 0.0;
        out[d.bin] = static_cast<double>(lanes[0]) * nb;  // one bin of n drawn: weight n
        break;
    }
  }

  // Bin i's wavelength in the sample d: lo_i + u·Δλ_i.
  double lambda_at(const WavelengthDraw& d, int bin) const { return m_bins.lo_nm(bin) + d.u * m_bins.width_nm(bin); }

 private:
  LaneMode m_mode;
  spectral::BinLayout m_bins;
};

}  // namespace prizma::render
