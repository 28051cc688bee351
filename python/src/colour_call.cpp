// prizma._prizma's spectra and colour (docs/python.md): spectrum values, XYZ, CIELAB, ΔE2000, the
// named spectra, and the metamer and light designs prizma-metamer runs.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "module_parts.h"
#include "native_call.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/light_design.h"
#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::python {

using spectral::InputError;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A spectrum as Python gives it: a spec string, or a pair (wavelengths_nm, values) of equal-length
// 1-D arrays (a tuple or a list: a measured table, read as a csv: file would be).
spectral::Spectrum spectrum_from(const py::handle& spec, const std::string& input) {
  if (py::isinstance<py::str>(spec)) return spectral::parse_spectrum(spec.cast<std::string>(), {input, {}});
  if ((py::isinstance<py::tuple>(spec) || py::isinstance<py::list>(spec)) && py::len(spec) == 2) {
    const auto t = spec.cast<py::sequence>();
    DoubleArray wl = DoubleArray::ensure(t[0]), v = DoubleArray::ensure(t[1]);
    if (!wl || !v || wl.ndim() != 1 || v.ndim() != 1 || wl.size() != v.size()) {
      PyErr_Clear();
      throw InputError(input, "must be a spectrum spec string or a pair (wavelengths_nm, values) of equal-length 1-D arrays");
    }
    return spectral::Spectrum(std::vector<double>(wl.data(), wl.data() + wl.size()),
                              std::vector<double>(v.data(), v.data() + v.size()), input);
  }
  throw InputError(input, "must be a spectrum spec string or a pair (wavelengths_nm, values)");
}

namespace {

// ---------------------------------------------------------------------------------------------
// Spectra and colour

std::pair<py::array_t<double>, py::array_t<double>> spectrum_values(const py::object& spec,
                                                                    const std::optional<DoubleArray>& at) {
  const spectral::Spectrum s = spectrum_from(spec, "spectrum");
  std::vector<double> wl;
  if (at) {
    wl.assign(at->data(), at->data() + at->size());
  } else if (s.is_constant()) {
    for (int l = static_cast<int>(spectral::BinLayout::kMinNm); l <= static_cast<int>(spectral::BinLayout::kMaxNm); ++l)
      wl.push_back(l);
  } else {
    wl = s.wavelengths_nm();
  }
  std::vector<double> v(wl.size());
  for (std::size_t k = 0; k < wl.size(); ++k) v[k] = s.eval(wl[k]);
  const auto n = static_cast<py::ssize_t>(wl.size());
  return {take_vector(std::move(wl), {n}), take_vector(std::move(v), {n})};
}

// XYZ of a spectrum: ∫ s·cmf dλ (no illuminant), or of a reflectance under an illuminant,
// ∫ R·E·cmf dλ / ∫ E·ȳ dλ (a perfect white has Y = 1), the product R·E tabulated at 1 nm.
py::array_t<double> xyz_of_spectrum(const py::object& spec, const py::object& illuminant, const std::string& cmf_name) {
  const spectral::ColorMatching& cmf = spectral::ColorMatching::get(spectral::parse_observer(cmf_name, "cmf"));
  const spectral::Spectrum s = spectrum_from(spec, "spectrum");
  Eigen::Vector3d out;
  if (illuminant.is_none()) {
    out = cmf.integrate(s);
  } else {
    const spectral::Spectrum e = spectrum_from(illuminant, "illuminant");
    std::vector<double> wl, prod;
    for (double l = std::ceil(cmf.lo_nm()); l <= cmf.hi_nm(); l += 1.0) {
      wl.push_back(l);
      prod.push_back(s.eval(l) * e.eval(l));
    }
    const Eigen::Vector3d white = cmf.integrate(e);
    if (!(white[1] > 0.0)) throw InputError("illuminant", "has no energy where the colour matching function ȳ > 0");
    out = cmf.integrate(spectral::Spectrum(std::move(wl), std::move(prod), "spectrum × illuminant")) / white[1];
  }
  return take_vector(std::vector<double>{out[0], out[1], out[2]}, {3});
}

// Applies f to every 3-vector of the last axis of a (…, 3) array; returns (…, 3) or (…) results.
py::array_t<double> lab_of(const DoubleArray& xyz_values, const std::optional<DoubleArray>& white_xyz) {
  if (xyz_values.ndim() < 1 || xyz_values.shape(xyz_values.ndim() - 1) != 3) {
    throw InputError("xyz", "must be an array whose last axis has 3 values (X, Y, Z)");
  }
  Eigen::Vector3d white = spectral::white_d65();
  if (white_xyz) {
    if (white_xyz->size() != 3) throw InputError("white", "must be 3 values (X, Y, Z)");
    white = {white_xyz->data()[0], white_xyz->data()[1], white_xyz->data()[2]};
  }
  std::vector<double> out(static_cast<std::size_t>(xyz_values.size()));
  const double* in = xyz_values.data();
  for (std::size_t k = 0; k + 2 < out.size(); k += 3) {
    const Eigen::Vector3d lab = spectral::xyz_to_lab({in[k], in[k + 1], in[k + 2]}, white);
    out[k] = lab[0];
    out[k + 1] = lab[1];
    out[k + 2] = lab[2];
  }
  return take_vector(std::move(out), std::vector<py::ssize_t>(xyz_values.shape(), xyz_values.shape() + xyz_values.ndim()));
}

py::object delta_e2000(const DoubleArray& lab1, const DoubleArray& lab2) {
  if (lab1.ndim() < 1 || lab1.shape(lab1.ndim() - 1) != 3) throw InputError("lab1", "must be an array whose last axis has 3 values (L*, a*, b*)");
  if (lab2.ndim() < 1 || lab2.shape(lab2.ndim() - 1) != 3) throw InputError("lab2", "must be an array whose last axis has 3 values (L*, a*, b*)");
  const bool same = lab1.ndim() == lab2.ndim() && std::equal(lab1.shape(), lab1.shape() + lab1.ndim(), lab2.shape());
  const bool one1 = lab1.size() == 3, one2 = lab2.size() == 3;
  if (!same && !one1 && !one2) throw InputError("lab2", "must have the shape of lab1 (or be a single colour)");
  const DoubleArray& shape_of = one1 ? lab2 : lab1;
  const std::size_t count = static_cast<std::size_t>(shape_of.size()) / 3;
  std::vector<double> out(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double* a = lab1.data() + (one1 ? 0 : 3 * k);
    const double* b = lab2.data() + (one2 ? 0 : 3 * k);
    out[k] = spectral::delta_e2000({a[0], a[1], a[2]}, {b[0], b[1], b[2]});
  }
  if (shape_of.ndim() == 1) return py::float_(out[0]);
  return take_vector(std::move(out), std::vector<py::ssize_t>(shape_of.shape(), shape_of.shape() + shape_of.ndim() - 1));
}

// ---------------------------------------------------------------------------------------------
// Metamers and lights: the designs prizma-metamer runs.

spectral::ColourSetting colour_setting(const std::string& cmf, const std::optional<std::string>& bins) {
  spectral::ColourSetting c;
  c.observer = spectral::parse_observer(cmf, "cmf");
  if (bins) c.bins = spectral::BinLayout::parse(*bins, "bins");
  return c;
}

std::pair<py::array_t<double>, py::array_t<double>> spectrum_table(const spectral::Spectrum& s) {
  const auto n = static_cast<py::ssize_t>(s.wavelengths_nm().size());
  return {take_vector(std::vector<double>(s.wavelengths_nm()), {n}), take_vector(std::vector<double>(s.values()), {n})};
}

py::dict metamer(const py::object& albedo, const py::object& match_light, const py::object& split_light,
                 const std::string& cmf, const std::optional<std::string>& bins, int basis_size, double min_split_delta_e) {
  spectral::MetamerOptions opts;
  opts.colour = colour_setting(cmf, bins);
  opts.basis_size = basis_size;
  opts.min_split_delta_e = min_split_delta_e;
  const spectral::Spectrum a = spectrum_from(albedo, "albedo");
  const spectral::Spectrum m = spectrum_from(match_light, "match light");
  const spectral::Spectrum sp = spectrum_from(split_light, "split light");
  spectral::MetamerResult r;
  {
    const WithoutGil released;
    r = spectral::design_metamer(a, m, sp, opts);
  }
  py::dict out;
  out["reflectance"] = spectrum_table(r.reflectance);
  out["delta_e_match"] = r.delta_e_match;
  out["delta_e_split"] = r.delta_e_split;
  return out;
}

py::dict design_light(const py::object& albedo_a, const py::object& albedo_b, const std::string& goal,
                      const py::object& reference, const std::vector<py::object>& primaries, const std::string& cmf,
                      const std::optional<std::string>& bins, double max_power_ratio) {
  spectral::LightDesignOptions opts;
  opts.colour = colour_setting(cmf, bins);
  opts.max_power_ratio = max_power_ratio;
  spectral::LightGoal g;
  if (goal == "hide") g = spectral::LightGoal::Hide;
  else if (goal == "reveal") g = spectral::LightGoal::Reveal;
  else throw InputError("goal", "must be \"hide\" or \"reveal\", not \"" + goal + "\"");
  const spectral::Spectrum a = spectrum_from(albedo_a, "albedo-a");
  const spectral::Spectrum b = spectrum_from(albedo_b, "albedo-b");
  const spectral::Spectrum ref = spectrum_from(reference, "reference light");
  std::vector<spectral::Spectrum> prims;
  for (std::size_t i = 0; i < primaries.size(); ++i) prims.push_back(spectrum_from(primaries[i], "primaries[" + std::to_string(i) + "]"));
  spectral::LightDesignResult r;
  {
    const WithoutGil released;
    r = spectral::design_light(a, b, g, ref, prims, opts);
  }
  py::dict out;
  out["light"] = spectrum_table(r.light);
  const auto n_weights = static_cast<py::ssize_t>(r.weights.size());
  out["weights"] = take_vector(std::move(r.weights), {n_weights});
  out["delta_e"] = r.delta_e;
  out["delta_e_reference"] = r.delta_e_reference;
  return out;
}

}  // namespace

void bind_colour(py::module_& m) {
  m.def("spectrum", &spectrum_values, py::arg("spec"), py::arg("wavelengths_nm") = py::none());
  m.def("xyz", &xyz_of_spectrum, py::arg("spectrum"), py::arg("illuminant"), py::arg("cmf"));
  m.def("lab", &lab_of, py::arg("xyz"), py::arg("white") = py::none());
  m.def("delta_e2000", &delta_e2000, py::arg("lab1"), py::arg("lab2"));
  m.def("named_spectra", [] {
    std::vector<std::string> names = spectral::named_illuminants();
    for (const auto& p : spectral::colorchecker_patches()) names.push_back(p);
    return names;
  });
  m.def("metamer", &metamer, py::arg("albedo"), py::arg("match_light"), py::arg("split_light"), py::arg("cmf"),
        py::arg("bins"), py::arg("basis_size"), py::arg("min_split_delta_e"));
  m.def("design_light", &design_light, py::arg("albedo_a"), py::arg("albedo_b"), py::arg("goal"),
        py::arg("reference"), py::arg("primaries"), py::arg("cmf"), py::arg("bins"), py::arg("max_power_ratio"));
}

}  // namespace prizma::python
