#pragma once
// WavelengthMap: the wavelength sampler, how a sample's path lanes are drawn and map to the render's
// bins (docs/renderer.md, "Wavelengths"). AllBins: one lane per bin, λ_i = lo_i + u·Δλ_i with one
// jitter u for all bins (spectral tracking), and under spectral MIS a hero lane per sample;
// Replicated: one lane at the first bin's centre, copied to every bin (a wavelength-independent
// medium); Single: VPT's method, one bin drawn per path, its lane × n into it. A mode is draw()
// (the lanes' wavelengths and the hero) and to_bins() (the lanes' values into the bins).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "prizma/render/rng.h"
#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

enum class LaneMode { AllBins, Replicated, Single };

// What one sample drew: the jitter shared by every bin, Single's bin, and spectral MIS's hero lane.
struct WavelengthDraw {
  double u = 0.0;
  int bin = 0;
  int hero = -1;  // the lane the path is sampled for (hero_lane); −1: none (no spectral MIS)
};

// Which sample of the render a draw is for (the hero lane is a function of it).
struct SampleIndex {
  std::uint64_t seed = 0;
  std::uint64_t pixel = 0;
  std::int64_t sample = 0;
};

class WavelengthMap {
 public:
  // hero: spectral MIS (WavelengthSampling::SpectralMis), each draw also picks the sample's hero
  // lane; only with several lanes (AllBins).
  WavelengthMap(LaneMode mode, const spectral::BinLayout& bins, bool hero = false)
      : m_mode(mode), m_bins(bins), m_hero(hero && mode == LaneMode::AllBins),
        m_hero_order(van_der_corput_order(lanes())) {}

  LaneMode mode() const { return m_mode; }
  bool has_hero() const { return m_hero; }
  int lanes() const { return m_mode == LaneMode::AllBins ? m_bins.size() : 1; }

  // Draws the sample's wavelengths into lambda_nm[lanes()] (u, then Single's bin: the stream's
  // order is part of the output) and, under spectral MIS, its hero lane hero_lane(at).
  WavelengthDraw draw(Rng& rng, float* lambda_nm, const SampleIndex& at) const {
    WavelengthDraw d;
    if (m_hero) d.hero = hero_lane(at.seed, at.pixel, at.sample);
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

  // Spectral MIS's hero lane of a pixel's sample: (o + π(s mod n)) mod n, o hashed from (seed,
  // pixel), π the lanes in van der Corput order (floor(n·φ₂(i)) for i = 0, 1, …, each lane at its
  // first appearance: 0, 16, 8, 24, … for 32 bins; 0, 6, 3, 9, 1, 7, … for 12). Any n consecutive
  // samples of a pixel take every bin once (stratified: over whole cycles the balance heuristic's
  // choice of technique adds no variance), the first N < n of a cycle spread evenly over the bins
  // (16 samples of 32 bins take every other bin, where plain turns would take half the spectrum), and
  // each sample's lane is uniform over o. A function of (seed, pixel, sample) only: threads, shards
  // and resumes give the same lanes.
  int hero_lane(std::uint64_t seed, std::uint64_t pixel, std::int64_t sample) const {
    const auto n = static_cast<std::uint64_t>(m_hero_order.size());
    const std::uint64_t offset = splitmix64(splitmix64(seed) ^ pixel) % n;
    return static_cast<int>((offset + m_hero_order[static_cast<std::uint64_t>(sample) % n]) % n);
  }

  // Bin i's wavelength in the sample d: lo_i + u·Δλ_i.
  double lambda_at(const WavelengthDraw& d, int bin) const { return m_bins.lo_nm(bin) + d.u * m_bins.width_nm(bin); }

 private:
  // hero_lane's π: the lanes 0 … n − 1 in the order floor(n·φ₂(i)) first reaches them, φ₂ the base-2
  // radical inverse (every lane is reached: consecutive values of φ₂ over i < 2^k are 2^−k apart).
  static std::vector<int> van_der_corput_order(int n) {
    std::vector<int> order;
    std::vector<char> seen(static_cast<std::size_t>(n), 0);
    for (std::uint32_t i = 0; static_cast<int>(order.size()) < n; ++i) {
      double phi = 0.0, digit = 0.5;
      for (std::uint32_t k = i; k != 0; k >>= 1, digit *= 0.5)
        if (k & 1u) phi += digit;
      const int lane = std::min(n - 1, static_cast<int>(phi * n));
      if (!seen[static_cast<std::size_t>(lane)]) {
        seen[static_cast<std::size_t>(lane)] = 1;
        order.push_back(lane);
      }
    }
    return order;
  }

  LaneMode m_mode;
  spectral::BinLayout m_bins;
  bool m_hero;
  std::vector<int> m_hero_order;  // hero_lane's π
};

}  // namespace prizma::render
