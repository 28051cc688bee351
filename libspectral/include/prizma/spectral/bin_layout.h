#pragma once
// BinLayout: n piecewise-constant spectral bins given by strictly increasing edges λ0 < … < λn (nm).
#include <string>
#include <string_view>
#include <vector>

namespace prizma::spectral {

class BinLayout {
 public:
  // Wavelength range the bins may cover: the union of the colour matching tables (360–830 nm).
  static constexpr double kMinNm = 360.0;
  static constexpr double kMaxNm = 830.0;
  static constexpr int kMaxBins = 1024;

  // Default: 16 bins of 25 nm over 380–780 nm.
  BinLayout();

  // n equal bins over [lo_nm, hi_nm]. Throws InputError (input "bins") when invalid.
  static BinLayout linear(double lo_nm, double hi_nm, int n);
  // VPT's "logarithmic" layout (really exponential spacing): edge fraction
  // x_i = (e^{k t} − 1)/(e^k − 1), t = i/n, k in [−10, 10]; k = 0 is linear, k > 0 gives narrow
  // bins at the blue end.
  static BinLayout exponential(double lo_nm, double hi_nm, int n, double k);
  // Custom edges: finite, strictly increasing, within [kMinNm, kMaxNm], at least 2 values.
  static BinLayout from_edges(std::vector<double> edges_nm);
  // Parses "linear:400:700:12", "exp:400:700:12:1.5" (alias "log:"), "edges:400,450,500".
  // `input` names the source for error messages (e.g. "--bins").
  static BinLayout parse(std::string_view spec, std::string_view input = "bins");

  int size() const { return static_cast<int>(m_edges.size()) - 1; }
  const std::vector<double>& edges_nm() const { return m_edges; }
  double lo_nm(int i) const { return m_edges[i]; }
  double hi_nm(int i) const { return m_edges[i + 1]; }
  double centre_nm(int i) const { return 0.5 * (m_edges[i] + m_edges[i + 1]); }
  double width_nm(int i) const { return m_edges[i + 1] - m_edges[i]; }
  double min_nm() const { return m_edges.front(); }
  double max_nm() const { return m_edges.back(); }
  // Index of the bin containing lambda_nm (half-open [lo, hi), the last bin closed), or -1.
  int find(double lambda_nm) const;
  // A spec string that parse() turns back into this layout ("edges:…" in general).
  std::string to_string() const;

  friend bool operator==(const BinLayout&, const BinLayout&) = default;

 private:
  explicit BinLayout(std::vector<double> edges_nm) : m_edges(std::move(edges_nm)) {}
  std::vector<double> m_edges;
};

}  // namespace prizma::spectral
