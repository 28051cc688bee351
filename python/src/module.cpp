// prizma._prizma: the C++ half of the Python module (docs/python.md). Thin over the libraries: every
// function here calls the code the tools run (read_spectral_exr, write_spectral_exr, RelightSession,
// DisplayTransform, render), converting between numpy arrays and the libraries' types. The public
// API, its argument handling and docstrings live in python/prizma/__init__.py.
//
// Errors: spectral::InputError → prizma.InputError (a ValueError, with .input and .reason),
// spectral::RuntimeError and other std::exception → prizma.RuntimeFailure (a RuntimeError); what()
// is the message, the one line the tools print after "<program>: error: ".
//
// The conversions the image and relight bindings share (image_from_py, light_from, relight_session)
// live here beside the short calls that are only a conversion; the other concepts have their own
// files (colour_call.cpp: spectra, colour and the metamer and light designs; render_call.cpp: the
// render thread; denoise_call.cpp; show_call.cpp: PNG, the server).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "prizma/spectral/output_image.h"
#include "prizma/relight/relight_session.h"
#include "prizma/render/render.h"
#include "prizma/render/resume.h"
#include "prizma/render/sample_range.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/data_path.h"
#include "prizma/spectral/display.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/light_design.h"
#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/spectral/version.h"
#include "module_parts.h"
#include "native_call.h"

namespace py = pybind11;
namespace spectral = prizma::spectral;
namespace relight = prizma::relight;
namespace render = prizma::render;
using spectral::InputError;
using prizma::python::take_vector;
using prizma::python::WithoutGil;

namespace prizma::python {

std::string integer_text(const py::handle& value, const std::string& name) {
  if (!PyLong_Check(value.ptr()) || PyBool_Check(value.ptr()))
    throw InputError(name, "must be an integer (got " + std::string(py::repr(value)) + ")");
  return std::string(py::str(value));
}

py::dict image_to_py(spectral::SpectralImage&& image) {
  py::dict out;
  const auto h = static_cast<py::ssize_t>(image.height), w = static_cast<py::ssize_t>(image.width);
  const auto n = static_cast<py::ssize_t>(image.bins.size());
  out["width"] = image.width;
  out["height"] = image.height;
  out["bin_edges_nm"] = take_vector(std::vector<double>(image.bins.edges_nm()), {n + 1});
  py::dict lights, variance;
  for (auto& layer : image.lights) {
    lights[py::str(layer.name)] = take_vector(std::move(layer.data), {h, w, n});
    if (!layer.variance.empty()) variance[py::str(layer.name)] = take_vector(std::move(layer.variance), {h, w, n});
  }
  out["lights"] = lights;
  out["variance"] = variance;
  // Bispectral terms (docs/fluorescence.md): the (in, out) bin pairs, and per light H×W×pairs.
  const auto np = static_cast<py::ssize_t>(image.reradiation.size());
  std::vector<std::int32_t> pairs;
  for (const spectral::BinPair& pr : image.reradiation) {
    pairs.push_back(pr.in);
    pairs.push_back(pr.out);
  }
  out["reradiation_pairs"] = take_vector(std::move(pairs), {np, 2});
  py::dict reradiation;
  for (auto& layer : image.lights)
    if (np > 0) reradiation[py::str(layer.name)] = take_vector(std::move(layer.reradiation), {h, w, np});
  out["reradiation"] = reradiation;
  // Guide layers (prizma-render --features): name → H×W, and their variances.
  py::dict guides, guide_variance;
  for (auto& g : image.guides) {
    if (!g.variance.empty()) guide_variance[py::str(g.name)] = take_vector(std::move(g.variance), {h, w});
    guides[py::str(g.name)] = take_vector(std::move(g.value), {h, w});
  }
  out["guides"] = guides;
  out["guide_variance"] = guide_variance;
  const spectral::SpectralExrInfo& info = image.info;
  py::dict a;
  a["samples"] = info.samples;
  a["sample_range"] = info.sample_range;
  a["seed"] = info.seed;
  a["scene_hash"] = info.scene_hash;
  a["version"] = info.version;
  a["wavelength_sampling"] = info.wavelength_sampling;
  a["mis_lane_groups"] = info.mis_lane_groups;
  a["scene_path"] = info.scene_path;
  a["render_options"] = info.render_options;
  a["denoised"] = info.denoised;
  a["lights_json"] = spectral::light_records_json(info.light_records);
  a["is_prizma"] = info.is_prizma;
  out["attributes"] = a;
  return out;
}

}  // namespace prizma::python

using prizma::python::image_to_py;
using prizma::python::integer_text;
using prizma::python::spectrum_from;

namespace {

// The exception types (owned by the module object; kept alive for the process).
PyObject* g_input_error = nullptr;
PyObject* g_runtime_failure = nullptr;

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// ---------------------------------------------------------------------------------------------
// SpectralImage ↔ Python. The Python side is a plain dict (prizma.Image wraps it):
//   width, height, bin_edges_nm (float64 n+1), lights {name: float32 H×W×n}, variance {name: …},
//   attributes {samples, sample_range, seed, scene_hash, version, wavelength_sampling, mis_lane_groups,
//               scene_path, render_options, denoised, lights_json, is_prizma}

template <typename T>
T attribute_or(const py::dict& attrs, const char* key, T fallback) {
  if (!attrs.contains(key) || attrs[key].is_none()) return fallback;
  try {
    return attrs[key].cast<T>();
  } catch (const py::cast_error&) {
    throw InputError(std::string("attributes[\"") + key + "\"]",
                     std::string("must be ") + (std::is_same_v<T, std::string> ? "a string" : "an integer"));
  }
}

// Copies one H×W×n array into a layer buffer, checking its shape.
std::vector<float> layer_values(const py::handle& obj, const std::string& what, int& width, int& height, int bins) {
  FloatArray a = FloatArray::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw InputError(what, "is not an array of numbers");
  }
  if (a.ndim() != 3) throw InputError(what, "must be an array of shape (height, width, bins), not " + std::to_string(a.ndim()) + "-D");
  const auto h = static_cast<int>(a.shape(0)), w = static_cast<int>(a.shape(1)), n = static_cast<int>(a.shape(2));
  if (width == 0 && height == 0) {
    width = w;
    height = h;
  }
  if (h != height || w != width || n != bins) {
    throw InputError(what, "has shape (" + std::to_string(h) + ", " + std::to_string(w) + ", " + std::to_string(n) +
                               "), expected (" + std::to_string(height) + ", " + std::to_string(width) + ", " +
                               std::to_string(bins) + ")");
  }
  return std::vector<float>(a.data(), a.data() + a.size());
}

// long on purpose: one check per key of prizma.Image's dict, in the dict's order, each naming the key.
spectral::SpectralImage image_from_py(const py::dict& d) {
  spectral::SpectralImage image;
  {
    DoubleArray edges = DoubleArray::ensure(d["bin_edges_nm"]);
    if (!edges || edges.ndim() != 1) {
      PyErr_Clear();
      throw InputError("bin_edges_nm", "must be a 1-D sequence of bin edges in nm");
    }
    try {
      image.bins = spectral::BinLayout::from_edges(std::vector<double>(edges.data(), edges.data() + edges.size()));
    } catch (const InputError& e) {
      throw InputError("bin_edges_nm", e.reason());
    }
  }
  const int bins = image.bins.size();
  const py::dict lights = d["lights"].cast<py::dict>();
  if (lights.empty()) throw InputError("lights", "the image has no light layers");
  const py::dict variance = d.contains("variance") && !d["variance"].is_none() ? d["variance"].cast<py::dict>() : py::dict();
  for (const auto& item : lights) {
    spectral::TransportLayer layer;
    layer.name = item.first.cast<std::string>();
    const std::string what = "lights[\"" + layer.name + "\"]";
    layer.data = layer_values(item.second, what, image.width, image.height, bins);
    if (variance.contains(item.first)) {
      layer.variance = layer_values(variance[item.first], "variance[\"" + layer.name + "\"]", image.width, image.height, bins);
    }
    image.lights.push_back(std::move(layer));
  }
  for (const auto& item : variance) {
    if (!lights.contains(item.first)) {
      throw InputError("variance[\"" + item.first.cast<std::string>() + "\"]", "has no light layer of that name");
    }
  }
  // Bispectral terms: reradiation_pairs (P×2 bin indices, in then out) and reradiation {light: H×W×P};
  // the writer checks the pairs (in range, off the diagonal, sorted, the same for every light).
  if (d.contains("reradiation_pairs") && !d["reradiation_pairs"].is_none()) {
    using IntArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
    IntArray pairs = IntArray::ensure(d["reradiation_pairs"]);
    if (!pairs || (pairs.size() != 0 && !(pairs.ndim() == 2 && pairs.shape(1) == 2))) {
      PyErr_Clear();
      throw InputError("reradiation_pairs", "must be an array of (in, out) bin index pairs, shape (pairs, 2)");
    }
    for (py::ssize_t k = 0; k + 1 < pairs.size(); k += 2) {
      const std::int64_t in = pairs.data()[k], o = pairs.data()[k + 1];
      if (in < 0 || o < 0 || in >= bins || o >= bins)
        throw InputError("reradiation_pairs", "pair (" + std::to_string(in) + ", " + std::to_string(o) + ") is outside the " +
                                                  std::to_string(bins) + " bins");
      image.reradiation.push_back({static_cast<int>(in), static_cast<int>(o)});
    }
  }
  const py::dict reradiation =
      d.contains("reradiation") && !d["reradiation"].is_none() ? d["reradiation"].cast<py::dict>() : py::dict();
  const int np = static_cast<int>(image.reradiation.size());
  for (const auto& item : reradiation)
    if (!lights.contains(item.first))
      throw InputError("reradiation[\"" + item.first.cast<std::string>() + "\"]", "has no light layer of that name");
  if (np > 0) {
    for (auto& layer : image.lights) {
      const std::string what = "reradiation[\"" + layer.name + "\"]";
      if (!reradiation.contains(py::str(layer.name))) throw InputError(what, "missing: every light needs its bispectral terms");
      layer.reradiation = layer_values(reradiation[py::str(layer.name)], what, image.width, image.height, np);
    }
  } else if (!reradiation.empty()) {
    throw InputError("reradiation", "given without reradiation_pairs");
  }
  // Guide layers: {name: H×W×1} and their variances (Image._native adds the last axis).
  const py::dict guides = d.contains("guides") && !d["guides"].is_none() ? d["guides"].cast<py::dict>() : py::dict();
  const py::dict guide_var =
      d.contains("guide_variance") && !d["guide_variance"].is_none() ? d["guide_variance"].cast<py::dict>() : py::dict();
  for (const auto& item : guides) {
    spectral::GuideLayer& g = image.guides.emplace_back();
    g.name = item.first.cast<std::string>();
    g.value = layer_values(item.second, "guides[\"" + g.name + "\"]", image.width, image.height, 1);
    if (guide_var.contains(item.first))
      g.variance = layer_values(guide_var[item.first], "guide_variance[\"" + g.name + "\"]", image.width, image.height, 1);
  }
  for (const auto& item : guide_var)
    if (!guides.contains(item.first))
      throw InputError("guide_variance[\"" + item.first.cast<std::string>() + "\"]", "has no guide of that name");
  const py::dict attrs = d.contains("attributes") && !d["attributes"].is_none() ? d["attributes"].cast<py::dict>() : py::dict();
  spectral::SpectralExrInfo& info = image.info;
  info.samples = attribute_or<std::int64_t>(attrs, "samples", 0);
  info.sample_range = attribute_or<std::string>(attrs, "sample_range", "");
  if (attrs.contains("seed") && !attrs["seed"].is_none())
    info.seed = render::scene_seed_override(integer_text(attrs["seed"], "attributes[\"seed\"]"), "attributes[\"seed\"]");
  info.scene_hash = attribute_or<std::string>(attrs, "scene_hash", "");
  info.version = attribute_or<std::string>(attrs, "version", "");
  info.wavelength_sampling = attribute_or<std::string>(attrs, "wavelength_sampling", "");
  info.mis_lane_groups = attribute_or<int>(attrs, "mis_lane_groups", 0);
  info.scene_path = attribute_or<std::string>(attrs, "scene_path", "");
  info.render_options = attribute_or<std::string>(attrs, "render_options", "");
  info.denoised = attribute_or<std::string>(attrs, "denoised", "");
  if (const std::string text = attribute_or<std::string>(attrs, "lights_json", ""); !text.empty())
    info.light_records = spectral::parse_light_records(text, "attributes[\"lights\"]");
  info.is_prizma = true;
  return image;
}

// ---------------------------------------------------------------------------------------------
// Files

py::dict read_file(const std::string& path, bool verify) {
  spectral::SpectralImage image;
  {
    const WithoutGil released;
    spectral::ExrReadOptions opts;
    opts.verify_checksum = verify;
    opts.unverified_read = "prizma.read(path, verify=False)";
    image = spectral::read_spectral_exr(path, opts);
  }
  return image_to_py(std::move(image));
}

void write_file(const std::string& path, const py::dict& image_dict, bool half) {
  spectral::check_output_file(path, "path");  // as the tools check -o: a missing folder is bad input
  spectral::SpectralImage image = image_from_py(image_dict);
  const WithoutGil released;
  spectral::ExrWriteOptions opts;
  opts.pixel_type = half ? spectral::ExrPixelType::Half : spectral::ExrPixelType::Float;
  spectral::write_spectral_exr(path, image, opts);
}

std::string checksum(const py::dict& image_dict) { return spectral::spectral_pixel_checksum(image_from_py(image_dict)); }

// ---------------------------------------------------------------------------------------------
// Relighting: a RelightSession, as prizma-relight runs it.

std::unique_ptr<relight::RelightSession> open_session(const py::object& source) {
  if (py::isinstance<py::dict>(source)) {
    spectral::SpectralImage image = image_from_py(source.cast<py::dict>());
    const WithoutGil released;
    return std::make_unique<relight::RelightSession>(std::move(image), "image");
  }
  const std::string path = source.cast<std::string>();
  const WithoutGil released;
  return std::make_unique<relight::RelightSession>(path);
}

// A light as Python gives it: a light spec string ("A*0.5", "off"), None (off), a spectrum pair
// (wavelengths_nm, values) (a measured SPD, normalised as any light), or the scene file's object
// {"spectrum": spec or pair, "scale": s}. A pair without "scale" says no scale, so given for every
// light it keeps each light's scale (RelightSession::set_every_light), as a bare spec string does.
relight::LightSpec light_from(const py::handle& value, const std::string& input) {
  if (value.is_none()) return relight::parse_light_spec("off", {input, {}});
  if (py::isinstance<py::str>(value)) return relight::parse_light_spec(value.cast<std::string>(), {input, {}});
  if (py::isinstance<py::dict>(value)) {
    const auto d = value.cast<py::dict>();
    for (const auto& item : d) {
      const std::string key = py::str(item.first);
      if (key != "spectrum" && key != "scale") throw InputError(input + "[\"" + key + "\"]", "unknown key (known: spectrum, scale)");
    }
    if (!d.contains("spectrum") || d["spectrum"].is_none() || py::isinstance<py::dict>(d["spectrum"]))
      throw InputError(input, "needs \"spectrum\": a spec string or a pair (wavelengths_nm, values)");
    relight::LightSpec light = light_from(d["spectrum"], input + "[\"spectrum\"]");
    if (!d.contains("scale")) return light;
    const py::object scale_obj = d["scale"];
    const std::string scale_input = input + "[\"scale\"]";
    if (!(PyFloat_Check(scale_obj.ptr()) || PyLong_Check(scale_obj.ptr())) || PyBool_Check(scale_obj.ptr()))
      throw InputError(scale_input, "must be a number (got " + std::string(py::repr(scale_obj)) + ")");
    const double scale = scale_obj.cast<double>() * light.scale;
    if (!std::isfinite(scale) || scale < 0.0)
      throw InputError(scale_input, "light scale must be finite and non-negative (got " + std::string(py::repr(scale_obj)) + ")");
    if (scale > spectral::kMaxLightScale)
      throw InputError(scale_input, "light scale " + std::string(py::repr(py::float_(scale))) +
                                        " is above 1e+12, the most a relight can apply without overflowing");
    light.text += "*" + std::string(py::repr(py::float_(scale_obj.cast<double>())));
    light.scale = scale;
    light.scaled = true;
    light.off = light.off || scale == 0.0;
    return light;
  }
  relight::LightSpec light;
  light.spectrum = spectrum_from(value, input);
  const std::vector<double>& wl = light.spectrum.wavelengths_nm();
  for (std::size_t k = 0; k < wl.size(); ++k) {  // a light, as a csv: light is (spectrum_spec.h: NonNegative)
    if (light.spectrum.values()[k] < 0.0) {
      throw InputError(input, "value must not be negative, got " + std::string(py::repr(py::float_(light.spectrum.values()[k]))) +
                                  " at " + std::string(py::repr(py::float_(wl[k]))) + " nm");
    }
  }
  light.text = "(wavelengths_nm, values): " + std::to_string(wl.size()) + " samples, " +
               std::string(py::repr(py::float_(wl.front()))) + "–" + std::string(py::repr(py::float_(wl.back()))) + " nm";
  return light;
}

// A session with prizma.relight's arguments applied. lights: None (the file's defaults), one light
// for every layer (light_from: a spec string or a (wavelengths_nm, values) pair), or {name: light}
// (light_from, None for off).
std::unique_ptr<relight::RelightSession> relight_session(const py::object& source, const py::object& lights,
                                                         double exposure_ev, const std::string& cmf,
                                                         const std::optional<std::string>& display,
                                                         const std::optional<std::string>& colour_space, bool adapt,
                                                         bool absolute, const std::string& config) {
  std::unique_ptr<relight::RelightSession> session = open_session(source);
  relight::RelightSettings s = session->settings();
  if (py::isinstance<py::dict>(lights)) {
    for (const auto& item : lights.cast<py::dict>()) {
      const std::string name = py::str(item.first);
      const int l = session->light_index(name, "lights");
      s.lights[static_cast<std::size_t>(l)] = light_from(item.second, "lights[\"" + name + "\"]");
    }
  } else if (!lights.is_none()) {
    if (!py::isinstance<py::str>(lights) && !py::isinstance<py::tuple>(lights) && !py::isinstance<py::list>(lights))
      throw InputError("lights", "must be None, a light for every layer (a spectrum spec or a pair (wavelengths_nm, "
                                 "values)), or a dict {name: light or None}");
    session->set_every_light(s.lights, light_from(lights, "lights"));
  }
  s.relight.exposure_ev = exposure_ev;
  s.relight.cmf = spectral::parse_observer(cmf, "cmf");
  s.relight.adapt_to_d65 = adapt;
  s.relight.units = absolute ? spectral::LightUnits::Absolute : spectral::LightUnits::RelativeToWhite;
  s.output.display.config = config;
  if (display) s.output.display.display = *display;
  if (colour_space) s.output.display.colour_space = *colour_space;
  session->apply(s, {"exposure", "bit_depth"});
  return session;
}

py::array_t<float> relight_image(const py::object& source, const py::object& lights, double exposure_ev,
                                 const std::string& cmf, const std::optional<std::string>& display,
                                 const std::optional<std::string>& colour_space, bool adapt, bool absolute,
                                 const std::string& config) {
  const std::unique_ptr<relight::RelightSession> session =
      relight_session(source, lights, exposure_ev, cmf, display, colour_space, adapt, absolute, config);
  const int w = session->image().width, h = session->image().height;
  std::vector<float> pixels;
  {
    const WithoutGil released;
    session->relight();
    const spectral::XyzImage& xyz = session->xyz();
    // Exactly what write_output_image writes before quantisation: PNG/TIFF the display, clamped; EXR
    // the linear colour space, or XYZ as is (non-finite values 0 in every case).
    if (colour_space) {
      const auto opts = spectral::transform_options(spectral::OutputFormat::Exr, session->settings().output);
      const spectral::DisplayTransform transform(opts);
      pixels = spectral::to_display(xyz, transform);
    } else if (display) {
      pixels = spectral::to_display(xyz, session->display());
      for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    } else {
      pixels = xyz.xyz;
      for (float& v : pixels)
        if (!std::isfinite(v)) v = 0.0f;
    }
  }
  return take_vector(std::move(pixels), {h, w, 3});
}

void translate_exception(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const InputError& e) {
    PyObject* inst = PyObject_CallFunction(g_input_error, "s", e.what());
    if (inst == nullptr) return;  // the call set its own error
    PyObject_SetAttrString(inst, "input", py::str(e.input()).ptr());
    PyObject_SetAttrString(inst, "reason", py::str(e.reason()).ptr());
    PyErr_SetObject(g_input_error, inst);
    Py_DECREF(inst);
  } catch (const std::bad_alloc&) {
    throw;  // pybind11: MemoryError
  } catch (const py::error_already_set&) {
    throw;
  } catch (const py::builtin_exception&) {
    throw;
  } catch (const std::exception& e) {
    PyErr_SetString(g_runtime_failure, e.what());
  }
}

}  // namespace

spectral::SpectralImage prizma::python::image_from_dict(const py::dict& image) { return image_from_py(image); }

PYBIND11_MODULE(_prizma, m) {
  m.doc() = "C++ half of the prizma module; use the functions of `prizma` (docs/python.md).";
  g_input_error = PyErr_NewExceptionWithDoc(
      "prizma.InputError",
      "Bad input (a file, a spec, an argument): the error the tools report with exit status 2. A ValueError; "
      "str(e) is the one-line message, e.input names what was wrong, e.reason says why.",
      PyExc_ValueError, nullptr);
  g_runtime_failure = PyErr_NewExceptionWithDoc(
      "prizma.RuntimeFailure",
      "A failure that is not the input's fault (I/O after validation, a library): the tools' exit status 1. "
      "A RuntimeError.",
      PyExc_RuntimeError, nullptr);
  m.add_object("InputError", py::handle(g_input_error));
  m.add_object("RuntimeFailure", py::handle(g_runtime_failure));
  py::register_exception_translator(translate_exception);

  m.def("version", [] { return spectral::prizma_version(); });
  m.def("data_dir", [] { return spectral::data_dir().string(); });
  m.def("read", &read_file, py::arg("path"), py::arg("verify") = true);
  m.def("write", &write_file, py::arg("path"), py::arg("image"), py::arg("half") = false);
  m.def("checksum", &checksum, py::arg("image"));
  m.def("relight", &relight_image, py::arg("source"), py::arg("lights"), py::arg("exposure"), py::arg("cmf"),
        py::arg("display"), py::arg("colour_space"), py::arg("adapt"), py::arg("absolute"), py::arg("config"));
  prizma::python::bind_colour(m);
  m.def("render", &prizma::python::render_scene, py::arg("scene"), py::arg("scene_is_json"), py::arg("base_dir"), py::arg("samples"),
        py::arg("threads"), py::arg("seed"), py::arg("width"), py::arg("height"), py::arg("bins"), py::arg("variance"),
        py::arg("samples_per_pass"), py::arg("progress"));
  m.def("relight_png",
        [](const py::object& source, const py::object& lights, double exposure, const std::string& cmf,
           const std::string& display, bool adapt, bool absolute, const std::string& config) {
          return prizma::python::relight_png(
              *relight_session(source, lights, exposure, cmf, display, std::nullopt, adapt, absolute, config));
        },
        py::arg("source"), py::arg("lights"), py::arg("exposure"), py::arg("cmf"), py::arg("display"), py::arg("adapt"),
        py::arg("absolute"), py::arg("config"));
  m.def("relight_tool_path", &prizma::python::relight_tool_path);
  m.def("denoise", &prizma::python::denoise_image, py::arg("image"), py::arg("variance"), py::arg("guides"), py::arg("window"),
        py::arg("patch"), py::arg("strength"), py::arg("centre_threshold"), py::arg("threads"));
  prizma::python::register_exit_hook();
}
