#include "prizma/spectral/bin_layout.h"

#include <algorithm>
#include <cmath>

#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {

using detail::format_double;

namespace {

constexpr const char* kDefaultInput = "bins";

void check_range_args(double lo_nm, double hi_nm, int n, std::string_view input) {
  const std::string in(input);
  if (n < 1) throw InputError(in, "need at least 1 bin, got " + std::to_string(n));
  if (n > BinLayout::kMaxBins) {
    throw InputError(in, "too many bins: " + std::to_string(n) + " (at most " +
                             std::to_string(BinLayout::kMaxBins) + ")");
  }
  if (!std::isfinite(lo_nm) || !std::isfinite(hi_nm)) {
    throw InputError(in, "bin range must be finite, got " + format_double(lo_nm) + " to " + format_double(hi_nm) + " nm");
  }
  for (double v : {lo_nm, hi_nm}) {
    if (v < BinLayout::kMinNm || v > BinLayout::kMaxNm) {
      throw InputError(in, "bin edge " + format_double(v) + " nm is outside [" + format_double(BinLayout::kMinNm) +
                               ", " + format_double(BinLayout::kMaxNm) + "] nm");
    }
  }
  if (!(lo_nm < hi_nm)) {
    throw InputError(in, "bin range must increase, got " + format_double(lo_nm) + " to " + format_double(hi_nm) + " nm");
  }
}

// Validates edges; `input` names the source for the message.
void validate_edges(const std::vector<double>& e, std::string_view input) {
  const std::string in(input);
  if (e.size() < 2) {
    throw InputError(in, "need at least 1 bin (2 edges), got " + std::to_string(e.size()) + " edge" +
                             (e.size() == 1 ? "" : "s"));
  }
  if (e.size() - 1 > static_cast<std::size_t>(BinLayout::kMaxBins)) {
    throw InputError(in, "too many bins: " + std::to_string(e.size() - 1) + " (at most " +
                             std::to_string(BinLayout::kMaxBins) + ")");
  }
  for (double v : e) {
    if (!std::isfinite(v)) throw InputError(in, "bin edge is not a finite number: " + format_double(v));
    if (v <= 0.0) throw InputError(in, "bin edge must be positive, got " + format_double(v) + " nm");
    if (v < BinLayout::kMinNm || v > BinLayout::kMaxNm) {
      throw InputError(in, "bin edge " + format_double(v) + " nm is outside [" + format_double(BinLayout::kMinNm) +
                               ", " + format_double(BinLayout::kMaxNm) + "] nm");
    }
  }
  for (std::size_t i = 1; i < e.size(); ++i) {
    if (e[i] == e[i - 1]) throw InputError(in, "duplicate bin edge " + format_double(e[i]) + " nm");
    if (e[i] < e[i - 1]) {
      throw InputError(in, "bin edges are not sorted: " + format_double(e[i]) + " nm follows " +
                               format_double(e[i - 1]) + " nm");
    }
  }
}

std::vector<double> linear_edges(double lo_nm, double hi_nm, int n) {
  std::vector<double> e(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i <= n; ++i) e[i] = lo_nm + (hi_nm - lo_nm) * (static_cast<double>(i) / n);
  e.front() = lo_nm;
  e.back() = hi_nm;
  return e;
}

std::vector<double> exponential_edges(double lo_nm, double hi_nm, int n, double k) {
  if (k == 0.0) return linear_edges(lo_nm, hi_nm, n);
  std::vector<double> e(static_cast<std::size_t>(n) + 1);
  const double denom = std::expm1(k);
  for (int i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / n;
    e[i] = lo_nm + (hi_nm - lo_nm) * (std::expm1(k * t) / denom);
  }
  e.front() = lo_nm;
  e.back() = hi_nm;
  return e;
}

}  // namespace

BinLayout::BinLayout() : m_edges(linear_edges(380.0, 780.0, 16)) {}

namespace {
// Factories that carry the caller's input name (the public ones use "bins").
struct Factory {
  static BinLayout linear(double lo_nm, double hi_nm, int n, std::string_view input) {
    check_range_args(lo_nm, hi_nm, n, input);
    auto e = linear_edges(lo_nm, hi_nm, n);
    return BinLayout::from_edges(checked(std::move(e), input));
  }
  static BinLayout exponential(double lo_nm, double hi_nm, int n, double k, std::string_view input) {
    check_range_args(lo_nm, hi_nm, n, input);
    if (!std::isfinite(k) || k < -10.0 || k > 10.0) {
      throw InputError(std::string(input), "exponential bin factor must be in [-10, 10], got " + format_double(k));
    }
    auto e = exponential_edges(lo_nm, hi_nm, n, k);
    return BinLayout::from_edges(checked(std::move(e), input));
  }
  static std::vector<double> checked(std::vector<double> e, std::string_view input) {
    validate_edges(e, input);
    return e;
  }
};
}  // namespace

BinLayout BinLayout::linear(double lo_nm, double hi_nm, int n) { return Factory::linear(lo_nm, hi_nm, n, kDefaultInput); }

BinLayout BinLayout::exponential(double lo_nm, double hi_nm, int n, double k) {
  return Factory::exponential(lo_nm, hi_nm, n, k, kDefaultInput);
}

BinLayout BinLayout::from_edges(std::vector<double> edges_nm) {
  validate_edges(edges_nm, kDefaultInput);
  return BinLayout(std::move(edges_nm));
}

BinLayout BinLayout::parse(std::string_view spec, std::string_view input) {
  const std::string in(input);
  const std::string_view s = detail::trim(spec);
  if (s.empty()) {
    throw InputError(in, "empty bin layout (expected linear:LO:HI:N, exp:LO:HI:N:K or edges:E0,E1,...)");
  }
  const auto colon = s.find(':');
  if (colon == std::string_view::npos) {
    throw InputError(in, "bad bin layout " + detail::dquote(s) +
                             " (expected linear:LO:HI:N, exp:LO:HI:N:K or edges:E0,E1,...)");
  }
  const std::string kind = detail::to_lower(detail::trim(s.substr(0, colon)));
  const std::string_view rest = s.substr(colon + 1);

  auto number = [&](std::string_view tok, const char* what) {
    double v = 0.0;
    if (!detail::parse_double(tok, v)) {
      throw InputError(in, std::string("bad ") + what + " " + detail::dquote(detail::trim(tok)) + " in " +
                               detail::dquote(s));
    }
    if (!std::isfinite(v)) {
      throw InputError(in, std::string(what) + " is not a finite number: " + detail::dquote(detail::trim(tok)));
    }
    return v;
  };
  auto count = [&](std::string_view tok) {
    int n = 0;
    if (!detail::parse_int(tok, n)) {
      throw InputError(in, "bad bin count " + detail::dquote(detail::trim(tok)) + " in " + detail::dquote(s) +
                               " (expected a whole number)");
    }
    return n;
  };

  if (kind == "linear" || kind == "lin") {
    const auto f = detail::split(rest, ':');
    if (f.size() != 3) {
      throw InputError(in, "bad bin layout " + detail::dquote(s) + " (expected linear:LO:HI:N)");
    }
    return Factory::linear(number(f[0], "lower wavelength"), number(f[1], "upper wavelength"), count(f[2]), input);
  }
  if (kind == "exp" || kind == "log" || kind == "exponential") {
    const auto f = detail::split(rest, ':');
    if (f.size() != 4) {
      throw InputError(in, "bad bin layout " + detail::dquote(s) + " (expected exp:LO:HI:N:K)");
    }
    return Factory::exponential(number(f[0], "lower wavelength"), number(f[1], "upper wavelength"), count(f[2]),
                                number(f[3], "exponential factor"), input);
  }
  if (kind == "edges") {
    std::vector<double> e;
    for (std::string_view tok : detail::split(rest, ',')) e.push_back(number(tok, "bin edge"));
    validate_edges(e, input);
    return BinLayout(std::move(e));
  }
  throw InputError(in, "unknown bin layout kind " + detail::dquote(s.substr(0, colon)) +
                           " (known: linear, exp, log, edges)");
}

int BinLayout::find(double lambda_nm) const {
  if (!(lambda_nm >= m_edges.front() && lambda_nm <= m_edges.back())) return -1;
  if (lambda_nm == m_edges.back()) return size() - 1;
  const auto it = std::upper_bound(m_edges.begin(), m_edges.end(), lambda_nm);
  return static_cast<int>(it - m_edges.begin()) - 1;
}

std::string BinLayout::to_string() const {
  // A layout that is exactly linear is written in its short form; anything else lists its edges
  // with shortest round-trip formatting, so parse(to_string()) == *this always.
  const int n = size();
  if (linear_edges(min_nm(), max_nm(), n) == m_edges) {
    return "linear:" + format_double(min_nm()) + ":" + format_double(max_nm()) + ":" + std::to_string(n);
  }
  std::string out = "edges:";
  for (std::size_t i = 0; i < m_edges.size(); ++i) {
    if (i) out += ',';
    out += format_double(m_edges[i]);
  }
  return out;
}

}  // namespace prizma::spectral
