// The scene's materials (docs/scene-format.md, "Materials"): each material's spectra, its value range
// and density ramp (the transfer function's rule), emission and fluorescence; or the VPT-style
// transfer-function image instead; and the check that the trackers can step through the medium built
// from them.
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "prizma/render/fluorescence.h"
#include "prizma/spectral/bin_layout.h"
#include "scene_reader.h"

namespace prizma::render::scene_file {

namespace {

using spectral::Spectrum;

// Densities are stored as float; extinction × density is what the trackers step through: one step
// per unit of optical depth, so a path crosses the volume (largest side 1, diagonal ≤ √3) in at
// most about kMaxExtinctionPerUnit · √3 steps. Beyond this a render would not end.
constexpr double kMaxDensity = 1e30;
constexpr double kMaxExtinctionPerUnit = 1e6;
// Emitted radiance Le at density 1: the tracer adds w·σa·density·Le/μ̄ per collision in float, with
// σt·density ≤ kMaxExtinctionPerUnit, so each term stays below 10¹² and a path's sum over its at most
// 2²⁸ steps below 10²¹ (3e38, float's largest, became NaN and then no light). A brighter emitter is
// the emission layer relit with a larger scale (--light emission=D65*1000).
constexpr double kMaxEmission = 1e6;

// A spectrum that must be ≥ 0 and finite at every wavelength.
Spectrum non_negative_spectrum(const Reader& rd, const json& j, const std::string& path) {
  Spectrum s = rd.spectrum(j, path);
  if (!(s.min_value() >= 0.0) || !std::isfinite(s.max_value()))
    rd.fail(path, "must be ≥ 0 and finite at every wavelength (got values in [" + num(s.min_value()) + ", " +
                      num(s.max_value()) + "])");
  return s;
}

// A material's "fluorescence": {"absorption": SPEC, "emission": SPEC, "quantum_yield": q}
// (docs/scene-format.md). The emission's scale does not matter (the renderer normalises its area).
void read_fluorescence(const Reader& rd, const json& j, const std::string& path, Material& m) {
  rd.expect_object(j, path, {"absorption", "emission", "quantum_yield"});
  for (const char* key : {"absorption", "emission", "quantum_yield"})
    if (!j.contains(key)) rd.fail(Reader::join(path, key), "is required");
  Fluorescence f;
  f.absorption = non_negative_spectrum(rd, j.at("absorption"), Reader::join(path, "absorption"));
  const std::string ep = Reader::join(path, "emission");
  f.emission = non_negative_spectrum(rd, j.at("emission"), ep);
  if (!(fluorescence_emission_area(f.emission) > 0.0))
    rd.fail(ep, "has no area over 360–830 nm: the re-emitted photons need a spectrum to be drawn from");
  const std::string qp = Reader::join(path, "quantum_yield");
  f.quantum_yield = rd.number(j.at("quantum_yield"), qp);
  if (!(f.quantum_yield >= 0.0 && f.quantum_yield <= 1.0))
    rd.fail(qp, "must be in [0, 1], the fraction of absorbed photons re-emitted (got " + num(f.quantum_yield) + ")");
  m.fluorescent = true;
  m.fluorescence = std::move(f);
}

// A material's "units": raw volume values (default), or normalised to [0, 1] by the scene's
// normalisation.
bool read_normalised_units(const Reader& rd, const json& mj, const std::string& mp) {
  if (!mj.contains("units")) return false;
  const std::string up = Reader::join(mp, "units");
  const std::string u = rd.string(mj.at("units"), up);
  if (u == "normalised" || u == "normalized") return true;
  if (u != "raw") rd.fail(up, "must be \"raw\" or \"normalised\" (got \"" + u + "\")");
  return false;
}

// A material's "range" [lo, hi] into the rule, in raw values. Normalised values clamp to [0, 1], so
// the ends 0 and 1 reach past the normalisation range (to ∓∞).
void read_range(const Reader& rd, const json& r, const std::string& rp, bool normalised, const ValueNormalisation& norm,
                MaterialRule& rule) {
  if (!r.is_array() || r.size() != 2) rd.fail(rp, "must be [lo, hi] (got " + Reader::describe(r) + ")");
  const double lo = rd.number(r[0], Reader::index(rp, 0));
  const double hi = rd.number(r[1], Reader::index(rp, 1));
  if (!(lo <= hi)) rd.fail(rp, "lo must be ≤ hi (got [" + num(lo) + ", " + num(hi) + "])");
  if (normalised && (lo < 0.0 || hi > 1.0)) {
    rd.fail(rp, "normalised values must be in [0, 1] (got [" + num(lo) + ", " + num(hi) + "])");
  }
  const double inf = std::numeric_limits<double>::infinity();
  rule.value_lo = !normalised ? lo : lo <= 0.0 ? -inf : norm.from_unit(lo);
  rule.value_hi = !normalised ? hi : hi >= 1.0 ? inf : norm.from_unit(hi);
}

// A material's "density": a number, or a ramp [[value, density], …] with strictly increasing values.
void read_density(const Reader& rd, const json& d, const std::string& dp, bool normalised,
                  const ValueNormalisation& norm, MaterialRule& rule) {
  if (d.is_number()) {
    const double v = rd.number(d, dp);
    if (v < 0.0) rd.fail(dp, "must be ≥ 0 (got " + num(v) + ")");
    if (v > kMaxDensity) rd.fail(dp, "must be at most " + num(kMaxDensity) + " (got " + num(v) + ")");
    rule.density.values = {0.0};
    rule.density.densities = {v};
    return;
  }
  if (!d.is_array() || d.empty()) {
    rd.fail(dp, "must be a number or [[value, density], …] with at least one point (got " + Reader::describe(d) + ")");
  }
  for (std::size_t k = 0; k < d.size(); ++k) {
    const std::string pp = Reader::index(dp, k);
    if (!d[k].is_array() || d[k].size() != 2) rd.fail(pp, "must be [value, density] (got " + Reader::describe(d[k]) + ")");
    double v = rd.number(d[k][0], Reader::index(pp, 0));
    const double dens = rd.number(d[k][1], Reader::index(pp, 1));
    if (dens < 0.0) rd.fail(Reader::index(pp, 1), "must be ≥ 0 (got " + num(dens) + ")");
    if (dens > kMaxDensity) {
      rd.fail(Reader::index(pp, 1), "must be at most " + num(kMaxDensity) + " (got " + num(dens) + ")");
    }
    if (normalised) v = norm.from_unit(v);
    if (!rule.density.values.empty() && !(v > rule.density.values.back())) {
      rd.fail(Reader::index(pp, 0), "values must be strictly increasing (got " + d[k][0].dump() + " after " +
                                        d[k - 1][0].dump() + ")");
    }
    rule.density.values.push_back(v);
    rule.density.densities.push_back(dens);
  }
}

// A material's spectra: albedo and extinction (required), anisotropy, emission, fluorescence.
void read_optics(const Reader& rd, const json& mj, const std::string& mp, Material& m) {
  const std::string ap = Reader::join(mp, "albedo");
  const std::string ep = Reader::join(mp, "extinction");
  if (!mj.contains("albedo")) rd.fail(ap, "is required");
  if (!mj.contains("extinction")) rd.fail(ep, "is required");
  m.albedo = rd.spectrum(mj.at("albedo"), ap);
  m.sigma_t_per_unit = rd.spectrum(mj.at("extinction"), ep);
  m.anisotropy = mj.contains("anisotropy") ? rd.spectrum(mj.at("anisotropy"), Reader::join(mp, "anisotropy"),
                                                         spectral::SpectrumValues::Signed)
                                           : Spectrum::constant(0.0);
  validate_material(m, rd.input(mp));
  if (mj.contains("emission")) {
    const std::string emp = Reader::join(mp, "emission");
    m.emission = non_negative_spectrum(rd, mj.at("emission"), emp);
    if (m.emission.max_value() > kMaxEmission) {
      rd.fail(emp, "must be at most " + num(kMaxEmission) + " at every wavelength (got " + num(m.emission.max_value()) +
                       "); scale the emission layer when relighting instead (--light NAME=SPEC*factor)");
    }
  }
  if (mj.contains("fluorescence")) read_fluorescence(rd, mj.at("fluorescence"), Reader::join(mp, "fluorescence"), m);
}

}  // namespace

TransferFunction read_materials(const Reader& rd, const json& j, const ValueNormalisation& norm) {
  const std::string path = "materials";
  if (!j.is_array()) rd.fail(path, "must be an array of materials (got " + Reader::describe(j) + ")");
  if (j.empty()) rd.fail(path, "must have at least one material");
  if (j.size() > 65534) rd.fail(path, "at most 65534 materials are supported (got " + std::to_string(j.size()) + ")");
  TransferFunction tf;
  std::set<std::string> names;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string mp = Reader::index(path, i);
    const json& mj = j[i];
    rd.expect_object(mj, mp, {"name", "range", "units", "albedo", "extinction", "anisotropy", "density", "emission",
                              "fluorescence"});
    Material m;
    m.name = mj.contains("name") ? rd.string(mj.at("name"), Reader::join(mp, "name")) : "material" + std::to_string(i);
    if (m.name.empty()) rd.fail(Reader::join(mp, "name"), "must not be empty");
    if (!names.insert(m.name).second) rd.fail(Reader::join(mp, "name"), "duplicate material name \"" + m.name + "\"");
    const bool normalised = read_normalised_units(rd, mj, mp);  // units of the range and the density ramp's values
    MaterialRule rule;
    rule.material = static_cast<int>(i);
    if (mj.contains("range")) read_range(rd, mj.at("range"), Reader::join(mp, "range"), normalised, norm, rule);
    read_optics(rd, mj, mp, m);
    if (mj.contains("density")) read_density(rd, mj.at("density"), Reader::join(mp, "density"), normalised, norm, rule);
    tf.materials.push_back(std::move(m));
    tf.rules.push_back(std::move(rule));
  }
  return tf;
}

TransferFunction read_tf_image(const Reader& rd, const json& j, const ValueNormalisation& norm) {
  const std::string path = "transfer_function";
  rd.expect_object(j, path, {"image", "extinction_scale", "wavelength_range_nm"});
  if (!j.contains("image")) rd.fail(Reader::join(path, "image"), "is required");
  if (!j.contains("extinction_scale")) rd.fail(Reader::join(path, "extinction_scale"), "is required");
  const auto image = rd.file_path(j.at("image"), Reader::join(path, "image"));
  const double scale = rd.positive(j.at("extinction_scale"), Reader::join(path, "extinction_scale"));
  double lo = 400.0;
  double hi = 700.0;
  if (j.contains("wavelength_range_nm")) {
    const std::string wp = Reader::join(path, "wavelength_range_nm");
    const json& w = j.at("wavelength_range_nm");
    if (!w.is_array() || w.size() != 2) rd.fail(wp, "must be [lo, hi] in nm (got " + Reader::describe(w) + ")");
    lo = rd.number(w[0], Reader::index(wp, 0));
    hi = rd.number(w[1], Reader::index(wp, 1));
    if (!(lo < hi) || lo < spectral::BinLayout::kMinNm || hi > spectral::BinLayout::kMaxNm) {
      rd.fail(wp, "must be increasing within [360, 830] nm (got [" + num(lo) + ", " + num(hi) + "])");
    }
  }
  return read_transfer_function_image(image, scale, lo, hi, norm, rd.input(Reader::join(path, "image")));
}

// Float overflow makes a majorant infinite and a step zero; a huge optical depth never ends.
void check_trackable(const Reader& rd, const Medium& med, bool has_materials) {
  // The largest density per material, over the voxels in parallel (a maximum: the same on any thread count).
  using Maxima = std::vector<float>;
  const Maxima max_density = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, med.material.size(), 1 << 16), Maxima(med.materials.size(), 0.0f),
      [&](const tbb::blocked_range<std::size_t>& r, Maxima acc) {
        // By runs of one material (a volume's neighbouring voxels mostly share theirs): the maximum
        // stays in a register instead of a load and store of acc[m] per voxel.
        std::uint16_t run = Medium::kEmpty;
        float run_max = 0.0f;
        const auto flush = [&] {
          if (run != Medium::kEmpty && run < acc.size()) acc[run] = std::max(acc[run], run_max);
        };
        for (std::size_t v = r.begin(); v != r.end(); ++v) {
          const std::uint16_t m = med.material[v];
          if (m != run) {
            flush();
            run = m;
            run_max = 0.0f;
          }
          run_max = std::max(run_max, med.density[v]);
        }
        flush();
        return acc;
      },
      [](Maxima a, const Maxima& b) {
        for (std::size_t m = 0; m < a.size(); ++m) a[m] = std::max(a[m], b[m]);
        return a;
      });
  for (std::size_t m = 0; m < med.materials.size(); ++m) {
    if (!(max_density[m] > 0.0f)) continue;
    const Material& mat = med.materials[m];
    const double sigma_f = mat.fluorescent ? mat.fluorescence.absorption.max_value() : 0.0;
    const double mu = (mat.sigma_t_per_unit.max_value() + sigma_f) * static_cast<double>(max_density[m]);
    if (mu <= kMaxExtinctionPerUnit) continue;
    const std::string field = has_materials ? Reader::join(Reader::index("materials", m), "extinction")
                                            : "transfer_function.extinction_scale";
    rd.fail(field, "extinction × density reaches " + num(mu) + " per unit length (material \"" +
                       med.materials[m].name + "\"); the tracker steps through at most " +
                       num(kMaxExtinctionPerUnit) + " per unit length (the volume's largest side is 1 unit)");
  }
}

}  // namespace prizma::render::scene_file
