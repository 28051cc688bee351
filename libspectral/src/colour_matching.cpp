#include "prizma/spectral/colour_matching.h"

#include <array>
#include <cmath>
#include <memory>
#include <mutex>

#include "csv_table.h"
#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {

using detail::format_double;

namespace {

const char* table_file(Observer obs) {
  switch (obs) {
    case Observer::Cie1931_2deg: return "spectra/cie1931_xyz2deg_1nm.csv";
    case Observer::Cie1964_10deg: return "spectra/cie1964_xyz10deg_1nm.csv";
    case Observer::Cie2012_2deg: return "spectra/cie2012_xyz2deg_1nm.csv";
    case Observer::Cie2012_10deg: return "spectra/cie2012_xyz10deg_1nm.csv";
  }
  return "";
}

}  // namespace

Observer parse_observer(std::string_view name, std::string_view input) {
  std::string n = detail::to_lower(detail::trim(name));
  // Accept an optional "cie" prefix and "_" / " " as "-", and a trailing "deg"/"°" on the field.
  if (n.rfind("cie", 0) == 0) n = n.substr(3);
  for (char& c : n) {
    if (c == '_' || c == ' ') c = '-';
  }
  if (!n.empty() && n.front() == '-') n.erase(0, 1);
  if (n.size() > 3 && n.compare(n.size() - 3, 3, "deg") == 0) n.resize(n.size() - 3);
  if (n == "1931" || n == "2" || n == "1931-2") return Observer::Cie1931_2deg;
  if (n == "1964" || n == "10" || n == "1964-10") return Observer::Cie1964_10deg;
  if (n == "2012" || n == "2006" || n == "2012-2" || n == "2006-2" || n == "2015" || n == "2015-2")
    return Observer::Cie2012_2deg;
  if (n == "2012-10" || n == "2006-10" || n == "2015-10") return Observer::Cie2012_10deg;
  throw InputError(std::string(input), "unknown colour matching functions " + detail::dquote(detail::trim(name)) +
                                           " (known: cie1931-2, cie1964-10, cie2012-2, cie2012-10)");
}

std::string observer_name(Observer obs) {
  switch (obs) {
    case Observer::Cie1931_2deg: return "cie1931-2";
    case Observer::Cie1964_10deg: return "cie1964-10";
    case Observer::Cie2012_2deg: return "cie2012-2";
    case Observer::Cie2012_10deg: return "cie2012-10";
  }
  return "unknown";
}

ColorMatching::ColorMatching(Observer obs, Spectrum x, Spectrum y, Spectrum z)
    : m_observer(obs), m_xyz{std::move(x), std::move(y), std::move(z)} {}

const ColorMatching& ColorMatching::get(Observer obs) {
  static std::array<std::once_flag, 4> once;
  static std::array<std::unique_ptr<ColorMatching>, 4> tables;
  const auto idx = static_cast<std::size_t>(obs);
  if (idx >= tables.size()) throw RuntimeError("unknown observer");
  std::call_once(once[idx], [&] {
    const auto path = data_file(table_file(obs));
    const auto t = detail::read_csv_table(path, 4, 4);
    detail::check_increasing_wavelengths(t, path);
    std::vector<double> lam, x, y, z;
    for (const auto& r : t.rows) {
      lam.push_back(r[0]);
      x.push_back(r[1]);
      y.push_back(r[2]);
      z.push_back(r[3]);
    }
    const std::string in = path.string();
    tables[idx].reset(new ColorMatching(obs, Spectrum(lam, x, in), Spectrum(lam, y, in), Spectrum(lam, z, in)));
  });
  return *tables[idx];
}

double ColorMatching::lo_nm() const { return m_xyz[1].domain_lo_nm(); }
double ColorMatching::hi_nm() const { return m_xyz[1].domain_hi_nm(); }

Eigen::Vector3d ColorMatching::integrate(const Spectrum& s) const {
  Eigen::Vector3d out;
  for (int c = 0; c < 3; ++c) out[c] = m_xyz[c].integrate_product(s, lo_nm(), hi_nm());
  return out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> relight_weights(const ColorMatching& cmf, const Spectrum& light,
                                                          const BinLayout& bins, LightUnits units) {
  const int n = bins.size();
  Eigen::Matrix<double, 3, Eigen::Dynamic> m(3, n);
  // Exact ∫_{bin} E·cmf_c dλ of the two piecewise-linear tables (never bin averages multiplied);
  // both are zero outside their tables, so a bin reaching past the CMF table weighs only its inside.
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) m(c, i) = cmf.channel(c).integrate_product(light, bins.lo_nm(i), bins.hi_nm(i));
  }
  const double y_total = m.row(1).sum();
  if (!(y_total > 0.0) || !std::isfinite(y_total)) {
    throw InputError("light", "the light has no energy where ȳ > 0 inside the bins (" + format_double(bins.min_nm()) +
                                  "–" + format_double(bins.max_nm()) + " nm): ∫E·ȳ dλ = " + format_double(y_total));
  }
  if (units == LightUnits::RelativeToWhite) m /= y_total;
  return m;
}

std::string cmf_coverage_note(const ColorMatching& cmf, const BinLayout& bins) {
  if (bins.min_nm() >= cmf.lo_nm() && bins.max_nm() <= cmf.hi_nm()) return "";
  return "bins " + format_double(bins.min_nm()) + "–" + format_double(bins.max_nm()) + " nm reach outside the " +
         observer_name(cmf.observer()) + " colour matching table (" + format_double(cmf.lo_nm()) + "–" +
         format_double(cmf.hi_nm()) + " nm); the functions are taken as zero there";
}

}  // namespace prizma::spectral
