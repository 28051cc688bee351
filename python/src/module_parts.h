#pragma once
// What module.cpp and the *_call.cpp files share (the Python module prizma._prizma, docs/python.md).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::relight {
class RelightSession;
}

namespace prizma::python {

namespace py = pybind11;

// A numpy array that owns `values` (moved, not copied): the array's base is a capsule that deletes
// the vector when numpy lets go of it.
template <typename T>
py::array_t<T> take_vector(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(values));
  py::capsule base(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), owner->data(), base);
}

// An integer argument the way the tools take an option: a Python int's decimal text, to be checked
// by the same code as the option (scene_integer_override, scene_seed_override). Anything else (a
// bool, a float, a string) is InputError(name, "must be an integer (got …)").
std::string integer_text(const py::handle& value, const std::string& name);

// A SpectralImage as the dict prizma.Image wraps (its arrays own the image's buffers, moved).
py::dict image_to_py(spectral::SpectralImage&& image);

// The dict prizma.Image._native() gives, as a SpectralImage (InputError naming the bad entry).
spectral::SpectralImage image_from_dict(const py::dict& image);

// A spectrum as Python gives it: a spec string, or a pair (wavelengths_nm, values) of equal-length
// 1-D arrays (InputError naming `input` otherwise). colour_call.cpp.
spectral::Spectrum spectrum_from(const py::handle& spec, const std::string& input);

// Defines prizma._prizma's spectra and colour functions on `m` (colour_call.cpp): spectrum, xyz, lab,
// delta_e2000, named_spectra, metamer, design_light.
void bind_colour(py::module_& m);

// prizma._prizma.denoise (denoise_call.cpp): variance "propagate" or "drop", guides "luminance" or
// "features" (the image's guide layers too), the DenoiseOptions' window and patch radii, patch_k
// (strength) and centre threshold; threads 0 = all cores.
py::dict denoise_image(const py::dict& image, const std::string& variance, const std::string& guides,
                       int window_radius_px, int patch_radius_px, double strength, double centre_threshold_se,
                       int threads);

// prizma._prizma.render (render_call.cpp): scene is a scene file's path or, with scene_is_json, a
// scene's JSON text whose relative paths resolve against base_dir (nothing is written).
py::dict render_scene(const std::string& scene, bool scene_is_json, const std::string& base_dir,
                      const py::object& samples, const py::object& threads, const py::object& seed,
                      const py::object& width, const py::object& height, const std::optional<std::string>& bins,
                      bool variance, const py::object& samples_per_pass, const py::object& progress);

// show_call.cpp: the PNG prizma-relight writes for the session's current settings, as bytes
// (Image._repr_png_); and the prizma-relight executable prizma.serve runs (the installed tree's, else
// the build tree's; empty when there is none).
py::bytes relight_png(relight::RelightSession& session);
std::string relight_tool_path();

}  // namespace prizma::python
