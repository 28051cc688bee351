#include "prizma/spectral/spectrum_spec.h"

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "csv_table.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {

using detail::dquote;
using detail::format_double;

namespace {

struct NamedFile {
  const char* name;
  const char* file;
};

// Named illuminants and the data/ tables they load (sources: data/spectra/SOURCES.md).
constexpr std::array<NamedFile, 15> kIlluminants{{
    {"A", "spectra/illuminant_A_5nm.csv"},
    {"D50", "spectra/illuminant_D50_5nm.csv"},
    {"D65", "spectra/illuminant_D65_5nm.csv"},
    {"E", "spectra/illuminant_E_5nm.csv"},
    {"F2", "spectra/illuminant_F2.csv"},
    {"F11", "spectra/illuminant_F11.csv"},
    {"LED-B1", "spectra/led_B1.csv"},
    {"LED-B2", "spectra/led_B2.csv"},
    {"LED-B3", "spectra/led_B3.csv"},
    {"LED-B4", "spectra/led_B4.csv"},
    {"LED-B5", "spectra/led_B5.csv"},
    {"LED-BH1", "spectra/led_BH1.csv"},
    {"LED-RGB1", "spectra/led_RGB1.csv"},
    {"LED-V1", "spectra/led_V1.csv"},
    {"LED-V2", "spectra/led_V2.csv"},
}};

constexpr const char* kColorCheckerFile = "spectra/colorchecker_reflectance.csv";
constexpr const char* kForms =
    "cc:<patch>, cc:<1..24>, blackbody:<T>K, gaussian:<centre>:<fwhm>, box:<lo>:<hi>, csv:<path>, a number, SPEC*factor";

// Second radiation constant c2 = hc/k (CODATA 2018), in nm·K; Wien's displacement constant b, nm·K.
constexpr double kPlanckC2_nmK = 1.438776877e7;
constexpr double kWienB_nmK = 2.897771955e6;

// Upper-case, no '-', '_' or spaces: "led_b1" and "LED-B1" both become "LEDB1".
std::string illuminant_key(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '-' || c == '_' || c == ' ') continue;
    out += (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
  }
  return out;
}

// ColorChecker names: lower-case, parenthesised suffix dropped, no spaces/hyphens/underscores.
std::string patch_key(std::string_view s) {
  const auto paren = s.find('(');
  if (paren != std::string_view::npos) s = s.substr(0, paren);
  std::string out;
  for (char c : detail::to_lower(s)) {
    if (c == '-' || c == '_' || c == ' ' || c == '\t') continue;
    out += c;
  }
  return out;
}

// The name with its trailing number removed ("white9.5" → "white"), or empty when there is none.
std::string strip_trailing_number(const std::string& key) {
  std::size_t end = key.size();
  while (end > 0 && ((key[end - 1] >= '0' && key[end - 1] <= '9') || key[end - 1] == '.')) --end;
  return (end == key.size() || end == 0) ? std::string() : key.substr(0, end);
}

// Display form used in lists: lower-case words joined by '-', parenthesised suffix dropped.
std::string patch_display(std::string_view s) {
  const auto paren = s.find('(');
  if (paren != std::string_view::npos) s = s.substr(0, paren);
  std::string out;
  for (char c : detail::to_lower(detail::trim(s))) out += (c == ' ' || c == '_') ? '-' : c;
  return out;
}

Spectrum load_table_spectrum(const std::filesystem::path& path, std::size_t column) {
  const auto t = detail::read_csv_table(path, column + 1);
  detail::check_increasing_wavelengths(t, path);
  std::vector<double> lam, val;
  for (const auto& r : t.rows) {
    lam.push_back(r[0]);
    val.push_back(r[column]);
  }
  return Spectrum(std::move(lam), std::move(val), path.string());
}

// Cached data tables (thread-safe; loaded on first use).
std::mutex g_cache_mutex;
std::map<std::string, Spectrum> g_illuminants;

struct ColorChecker {
  std::vector<std::string> names;  // display names in chart order
  std::vector<std::string> keys;   // normalised names
  std::vector<Spectrum> spectra;
};
std::optional<ColorChecker> g_colorchecker;

const Spectrum& illuminant(const NamedFile& nf) {
  std::lock_guard lock(g_cache_mutex);
  auto it = g_illuminants.find(nf.name);
  if (it == g_illuminants.end()) {
    it = g_illuminants.emplace(nf.name, load_table_spectrum(data_file(nf.file), 1)).first;
  }
  return it->second;
}

const ColorChecker& colorchecker() {
  std::lock_guard lock(g_cache_mutex);
  if (!g_colorchecker) {
    const auto path = data_file(kColorCheckerFile);
    const auto t = detail::read_csv_table(path, 25, 25);
    detail::check_increasing_wavelengths(t, path);
    if (t.header.size() != 25) throw RuntimeError(path.string() + ": expected a header naming the 24 patches");
    ColorChecker cc;
    std::vector<double> lam;
    for (const auto& r : t.rows) lam.push_back(r[0]);
    for (std::size_t c = 1; c <= 24; ++c) {
      std::vector<double> val;
      for (const auto& r : t.rows) val.push_back(r[c]);
      cc.names.push_back(patch_display(t.header[c]));
      cc.keys.push_back(patch_key(t.header[c]));
      cc.spectra.emplace_back(lam, std::move(val), path.string());
    }
    g_colorchecker = std::move(cc);
  }
  return *g_colorchecker;
}

std::string known_list() {
  std::string out;
  for (const auto& nf : kIlluminants) out += std::string(nf.name) + ", ";
  return out + kForms;
}

// The one sign rule of spec values (constants and csv: rows): the quantity decides. A negative value
// of a quantity that is ≥ 0 is refused: "<what> must not be negative, got <shown>".
void check_sign(double v, SpectrumValues values, const std::string& input, std::string_view what,
                const std::string& shown) {
  if (values == SpectrumValues::NonNegative && v < 0.0)
    throw InputError(input, std::string(what) + " must not be negative, got " + shown);
}

// A finite number from `tok`, or an InputError naming `what`.
double number(std::string_view tok, const char* what, const SpecContext& ctx, std::string_view spec) {
  double v = 0.0;
  if (!detail::parse_double(tok, v)) {
    throw InputError(ctx.input, std::string("bad ") + what + " " + dquote(detail::trim(tok)) + " in " + dquote(spec));
  }
  if (!std::isfinite(v)) {
    throw InputError(ctx.input, std::string(what) + " is not a finite number: " + dquote(detail::trim(tok)) + " in " +
                                    dquote(spec));
  }
  return v;
}

Spectrum parse_colorchecker(std::string_view name, const SpecContext& ctx, std::string_view spec) {
  const ColorChecker& cc = colorchecker();
  int index = 0;
  if (detail::parse_int(name, index)) {
    if (index < 1 || index > 24) {
      throw InputError(ctx.input, "ColorChecker patch number must be 1..24, got " + dquote(detail::trim(name)));
    }
    return cc.spectra[static_cast<std::size_t>(index - 1)];
  }
  const std::string key = patch_key(name);
  for (std::size_t i = 0; i < cc.keys.size(); ++i) {
    if (cc.keys[i] == key) return cc.spectra[i];
  }
  // "white" for "white 9.5", "black" for "black 2": the name without its number when unique.
  std::optional<std::size_t> match;
  int matches = 0;
  for (std::size_t i = 0; i < cc.keys.size(); ++i) {
    if (!key.empty() && strip_trailing_number(cc.keys[i]) == key) {
      match = i;
      ++matches;
    }
  }
  if (matches == 1) return cc.spectra[*match];
  std::string list;
  for (const auto& n : cc.names) list += (list.empty() ? "" : ", ") + n;
  throw InputError(ctx.input, "unknown ColorChecker patch " + dquote(spec) + " (known: " + list + ", or 1..24)");
}

Spectrum blackbody(std::string_view arg, const SpecContext& ctx, std::string_view spec) {
  std::string_view t = detail::trim(arg);
  if (!t.empty() && (t.back() == 'K' || t.back() == 'k')) t.remove_suffix(1);
  const double kelvin = number(t, "temperature", ctx, spec);
  if (kelvin < 1.0 || kelvin > 1e6) {
    throw InputError(ctx.input, "blackbody temperature must be in [1, 1e6] K, got " + dquote(detail::trim(arg)));
  }
  // Planck's law up to a constant: B(λ) ∝ λ^−5 / (e^{c2/(λT)} − 1), divided by its value at Wien's
  // peak λ_max = b/T so the peak (wherever it lies) is 1. Tabulated at 1 nm over 300–900 nm.
  auto planck = [kelvin](double lambda_nm) {
    const double denom = std::expm1(kPlanckC2_nmK / (lambda_nm * kelvin));
    return std::isfinite(denom) ? std::pow(lambda_nm / 100.0, -5.0) / denom : 0.0;
  };
  const double peak = planck(kWienB_nmK / kelvin);
  std::vector<double> lam, val;
  for (int l = 300; l <= 900; ++l) {
    lam.push_back(l);
    val.push_back(planck(l) / peak);
  }
  return Spectrum(std::move(lam), std::move(val), ctx.input);
}

Spectrum gaussian(std::string_view arg, const SpecContext& ctx, std::string_view spec) {
  const auto f = detail::split(arg, ':');
  if (f.size() != 2) throw InputError(ctx.input, "bad spectrum " + dquote(spec) + " (expected gaussian:<centre>:<fwhm>)");
  const double centre = number(f[0], "gaussian centre", ctx, spec);
  const double fwhm = number(f[1], "gaussian FWHM", ctx, spec);
  if (centre <= 0.0 || centre > 1e5) {
    throw InputError(ctx.input, "gaussian centre must be in (0, 1e5] nm, got " + format_double(centre));
  }
  if (fwhm < 1e-3 || fwhm > 1e4) {
    throw InputError(ctx.input, "gaussian FWHM must be in [0.001, 1e4] nm, got " + format_double(fwhm));
  }
  // Peak 1 at the centre, tabulated over ±6σ with step ≤ FWHM/40 (piecewise-linear error
  // < 1e-4 of the integral) and a sample on the centre.
  const double sigma = fwhm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  const int half = static_cast<int>(std::ceil(6.0 * sigma / (fwhm / 40.0)));
  const double step = 6.0 * sigma / half;
  std::vector<double> lam, val;
  for (int i = -half; i <= half; ++i) {
    const double x = i * step;
    lam.push_back(centre + x);
    val.push_back(std::exp(-0.5 * (x / sigma) * (x / sigma)));
  }
  return Spectrum(std::move(lam), std::move(val), ctx.input);
}

Spectrum box(std::string_view arg, const SpecContext& ctx, std::string_view spec) {
  const auto f = detail::split(arg, ':');
  if (f.size() != 2) throw InputError(ctx.input, "bad spectrum " + dquote(spec) + " (expected box:<lo>:<hi>)");
  const double lo = number(f[0], "box lower wavelength", ctx, spec);
  const double hi = number(f[1], "box upper wavelength", ctx, spec);
  if (lo < 0.0) throw InputError(ctx.input, "box lower wavelength must not be negative, got " + format_double(lo));
  if (!(lo < hi)) {
    throw InputError(ctx.input, "box range must increase, got " + format_double(lo) + " to " + format_double(hi) + " nm");
  }
  return Spectrum({lo, hi}, {1.0, 1.0}, ctx.input);
}

Spectrum parse_unscaled(std::string_view s, const SpecContext& ctx) {
  if (s.empty()) throw InputError(ctx.input, "empty spectrum (known: " + known_list() + ")");
  // A plain number is a constant spectrum.
  double v = 0.0;
  if (detail::parse_double(s, v)) {
    if (!std::isfinite(v)) throw InputError(ctx.input, "constant spectrum is not a finite number: " + dquote(s));
    check_sign(v, ctx.values, ctx.input, "constant spectrum", dquote(s));
    return Spectrum::constant(v);
  }
  const auto colon = s.find(':');
  if (colon != std::string_view::npos) {
    const std::string kind = detail::to_lower(detail::trim(s.substr(0, colon)));
    const std::string_view arg = s.substr(colon + 1);
    if (kind == "cc") return parse_colorchecker(arg, ctx, s);
    if (kind == "blackbody" || kind == "bb") return blackbody(arg, ctx, s);
    if (kind == "gaussian") return gaussian(arg, ctx, s);
    if (kind == "box") return box(arg, ctx, s);
    if (kind == "csv") {
      const std::filesystem::path rel(std::string(detail::trim(arg)));
      if (rel.empty()) throw InputError(ctx.input, "csv: needs a file path");
      const auto path = (rel.is_relative() && !ctx.base_dir.empty()) ? ctx.base_dir / rel : rel;
      return read_spectrum_csv(path, ctx.values);
    }
    throw InputError(ctx.input, "unknown spectrum " + dquote(s) + " (known: " + known_list() + ")");
  }
  const std::string key = illuminant_key(s);
  for (const auto& nf : kIlluminants) {
    if (illuminant_key(nf.name) == key) return illuminant(nf);
  }
  throw InputError(ctx.input, "unknown spectrum " + dquote(s) + " (known: " + known_list() + ")");
}

}  // namespace

Spectrum parse_spectrum(std::string_view spec, const SpecContext& ctx) {
  const std::string_view s = detail::trim(spec);
  // "SPEC*factor": the factor is the text after the last '*' (so "D65*2*0.5" works). A negative
  // factor is allowed (difference spectra); consumers that need non-negative spectra check.
  const auto star = s.rfind('*');
  if (star != std::string_view::npos) {
    const std::string_view base = detail::trim(s.substr(0, star));
    const double factor = number(s.substr(star + 1), "scale factor", ctx, s);
    if (base.empty()) throw InputError(ctx.input, "nothing to scale in " + dquote(s));
    const Spectrum inner = parse_spectrum(base, ctx);
    try {
      return inner.scaled(factor);
    } catch (const InputError& e) {
      throw InputError(ctx.input, e.reason() + " in " + dquote(s));
    }
  }
  return parse_unscaled(s, ctx);
}

std::vector<std::string> named_illuminants() {
  std::vector<std::string> out;
  for (const auto& nf : kIlluminants) out.emplace_back(nf.name);
  return out;
}

std::vector<std::string> colorchecker_patches() {
  std::vector<std::string> out;
  for (const auto& n : colorchecker().names) out.push_back("cc:" + n);
  return out;
}

Spectrum read_spectrum_csv(const std::filesystem::path& path, SpectrumValues values) {
  const auto t = detail::read_csv_table(path, 2, 2);
  detail::check_increasing_wavelengths(t, path);
  std::vector<double> lam, val;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const std::string where = path.string() + ":" + std::to_string(t.line_numbers[r]);
    if (t.rows[r][0] <= 0.0) {
      throw InputError(where, "wavelength must be positive, got " + format_double(t.rows[r][0]));
    }
    check_sign(t.rows[r][1], values, where, "value", format_double(t.rows[r][1]));
    lam.push_back(t.rows[r][0]);
    val.push_back(t.rows[r][1]);
  }
  if (lam.size() < 2) throw InputError(path.string(), "a spectrum needs at least 2 lines of data, got 1");
  return Spectrum(std::move(lam), std::move(val), path.string());
}

void write_spectrum_csv(const std::filesystem::path& path, const Spectrum& s, std::string_view value_name) {
  // A constant (or the zero spectrum) is written over the colour matching range, where it matters.
  std::vector<double> lam = s.wavelengths_nm();
  std::vector<double> val = s.values();
  if (s.is_constant() || lam.empty()) {
    lam = {BinLayout::kMinNm, BinLayout::kMaxNm};
    val = {s.eval(BinLayout::kMinNm), s.eval(BinLayout::kMaxNm)};
  }
  std::ostringstream text;
  text << "wavelength_nm," << value_name << "\n";
  for (std::size_t i = 0; i < lam.size(); ++i) text << format_double(lam[i]) << "," << format_double(val[i]) << "\n";
  write_file_atomically(path, text.str());
}

}  // namespace prizma::spectral
