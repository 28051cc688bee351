#pragma once
// WavelengthMap: the wavelength sampler, how a sample's path lanes are drawn and map to the render's
// bins (docs/renderer.md, "Wavelengths"). AllBins: one lane per bin, λ_i = lo_i + u·Δλ_i with one
// jitter u for all bins (spectral tracking), and under spectral MIS a hero lane per sample;
// Replicated: one lane at the first bin's centre, copied to every bin (a wavelength-independent
// medium); Single: VPT's method, one bin drawn per path, its lane × n into it. A mode is draw()
// (the lanes' wavelengths and the hero) and to_bins() (the lanes' values into the bins). Spectral
// MIS with lane groups (RenderSettings::mis_lane_groups = G > 1): the bins in G runs of neighbouring
// bins, and a sample is G paths, one per run, each carrying its run's lanes with a hero among them.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "prizma/render/rng.h"
#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

enum class LaneMode { AllBins, Replicated, Single };

// What one path of a sample drew: the jitter shared by its bins, Single's bin, spectral MIS's hero
// lane, and the path's lanes: bins [first, first + lanes) (every bin but with lane groups).
struct WavelengthDraw {
  double u = 0.0;
  int bin = 0;
  int hero = -1;  // the lane the path is sampled for (hero_lane), among its lanes; −1: no spectral MIS
  int first = 0;  // the bin of the path's lane 0
  int lanes = 1;  // the path's lane count (PathScratch::lanes for this path)
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
  // lane; only with several lanes (AllBins). groups: spectral MIS's lane groups (resolve_mis_lane_groups,
  // render.h; 1 = every bin on one path; clamped to [1, bins]).
  WavelengthMap(LaneMode mode, const spectral::BinLayout& bins, bool hero = false, int groups = 1)
      : m_mode(mode), m_bins(bins), m_hero(hero && mode == LaneMode::AllBins),
        m_groups(m_hero ? std::clamp(groups, 1, bins.size()) : 1) {
    for (int k = 0; k < m_groups; ++k) m_hero_order.push_back(van_der_corput_order(group_size(k)));
  }

  LaneMode mode() const { return m_mode; }
  bool has_hero() const { return m_hero; }
  // The most lanes a path carries (PathTracer::prepare's count).
  int lanes() const { return m_mode == LaneMode::AllBins ? m_bins.size() : 1; }
  // Paths per sample: the lane groups (1 without spectral MIS).
  int groups() const { return m_groups; }
  // Lane group k's bins [group_begin(k), group_begin(k + 1)).
  int group_begin(int k) const { return run_begin(k, m_bins.size(), m_groups); }
  int group_size(int k) const { return group_begin(k + 1) - group_begin(k); }
  // Run k's first bin when n bins are split into `groups` runs: k·n/groups rounded down (the runs'
  // sizes differ by at most one).
  static int run_begin(int k, int n, int groups) { return static_cast<int>(static_cast<std::int64_t>(k) * n / groups); }

  // Draws the wavelengths of the sample's path for lane group `group` (0 without groups) into
  // lambda_nm[d.lanes] (u, then Single's bin: the stream's order is part of the output) and, under
  // spectral MIS, its hero lane hero_lane(at, group).
  WavelengthDraw draw(Rng& rng, float* lambda_nm, const SampleIndex& at, int group = 0) const {
    WavelengthDraw d;
    d.first = group_begin(group);
    d.lanes = m_mode == LaneMode::AllBins ? group_size(group) : 1;
    if (m_hero) d.hero = hero_lane(at.seed, at.pixel, at.sample, group) - d.first;
    d.u = rng.uniform_double();
    const int nb = m_bins.size();
    switch (m_mode) {
      case LaneMode::Single:
        d.bin = std::min(nb - 1, static_cast<int>(rng.uniform_double() * nb));
        lambda_nm[0] = static_cast<float>(lambda_at(d, d.bin));
        break;
      case LaneMode::AllBins:
        for (int i = 0; i < d.lanes; ++i) lambda_nm[i] = static_cast<float>(lambda_at(d, d.first + i));
        break;
      case LaneMode::Replicated:
        lambda_nm[0] = static_cast<float>(m_bins.centre_nm(0));
        break;
    }
    return d;
  }

  // One light's lane values of a path → its bin values out[bins]: all of them, or with lane groups
  // the path's group's (every group has its own path in each sample).
  void to_bins(const float* lanes, const WavelengthDraw& d, double* out) const {
    const int nb = m_bins.size();
    switch (m_mode) {
      case LaneMode::AllBins:
        for (int i = 0; i < d.lanes; ++i) out[d.first + i] = lanes[i];
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

  // The bins to_bins(…, d, …) writes: [first, first + lanes) with all bins' lanes, every bin else.
  std::pair<int, int> bin_range(const WavelengthDraw& d) const {
    if (m_mode == LaneMode::AllBins) return {d.first, d.first + d.lanes};
    return {0, m_bins.size()};
  }

  // Spectral MIS's hero lane (a bin) of a pixel's sample in lane group k of n bins:
  // begin_k + (o + π(s mod n)) mod n, o hashed from (seed, pixel), π the group's lanes in van der
  // Corput order (floor(n·φ₂(i)) for i = 0, 1, …, each lane at its first appearance: 0, 16, 8, 24, …
  // for 32 bins; 0, 6, 3, 9, 1, 7, … for 12). Any n consecutive samples of a pixel take every bin of
  // the group once (stratified: over whole cycles the balance heuristic's choice of technique adds
  // no variance), the first N < n of a cycle spread evenly over the bins (16 samples of 32 bins take
  // every other bin, where plain turns would take half the spectrum), and each sample's lane is
  // uniform over o. A function of (seed, pixel, sample) only: threads, shards and resumes give the
  // same lanes.
  int hero_lane(std::uint64_t seed, std::uint64_t pixel, std::int64_t sample, int group = 0) const {
    const std::vector<int>& order = m_hero_order[static_cast<std::size_t>(group)];
    const auto n = static_cast<std::uint64_t>(order.size());
    const std::uint64_t offset = splitmix64(splitmix64(seed) ^ pixel) % n;
    return group_begin(group) + static_cast<int>((offset + order[static_cast<std::uint64_t>(sample) % n]) % n);
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
  int m_groups;                                // spectral MIS's lane groups (1: none)
  std::vector<std::vector<int>> m_hero_order;  // hero_lane's π, per lane group
};

}  // namespace prizma::render
