#pragma once
// The base scene and the load helpers of the scene loader tests (test_scene_*.cpp).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <sys/stat.h>

#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render::scene_test {

using nlohmann::json;
using spectral::InputError;
using testing::ScratchDir;

inline json base_scene() {
  return json::parse(R"({
    "description": "test scene",
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 16},
    "materials": [
      {"name": "cube", "range": [50, 150], "albedo": 0.99, "extinction": {"spectrum": "1", "scale": 3},
       "anisotropy": 0},
      {"name": "sphere", "range": [200, 255], "albedo": "cc:dark-skin", "extinction": 5,
       "density": [[200, 0.5], [255, 1]]}
    ],
    "camera": {"type": "perspective", "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "fov_deg": 40, "width": 32, "height": 24},
    "lights": [{"name": "side", "direction": [2, 0, 0], "spectrum": "D65", "angular_size_deg": 1},
               {"name": "sky", "direction": [0, 0, 0]}],
    "bins": "linear:400:700:12",
    "samples": 8,
    "seed": 7,
    "max_bounces": 5,
    "wavelength_sampling": "single",
    "sampler": "sobol",
    "output": "out/x.exr"
  })");
}

inline std::filesystem::path write_scene(const ScratchDir& dir, const json& j, const std::string& name = "scene.json") {
  return dir.write(name, j.dump(2));
}

// Loads and expects an InputError with input "<file>: <field>" and a reason containing `reason`.
inline void expect_error(const ScratchDir& dir, const json& j, const std::string& field, const std::string& reason) {
  const auto path = write_scene(dir, j);
  try {
    load_scene(path);
    FAIL() << "no error; expected " << field << ": " << reason;
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), path.string() + (field.empty() ? "" : ": " + field)) << e.what();
    EXPECT_NE(e.reason().find(reason), std::string::npos) << e.what();
  }
}

// A row of a table of loader errors: an edit of base_scene() and the error it must give.
struct BadEdit {
  std::string field;   // the error's input after "<file>: "
  std::string reason;  // part of its reason
  std::function<void(json&)> edit;
};

// Each row on a fresh base_scene(): expect_error(dir, edited scene, field, reason).
inline void expect_errors(const ScratchDir& dir, const std::vector<BadEdit>& rows) {
  for (const BadEdit& row : rows) {
    SCOPED_TRACE(row.field + ": " + row.reason);
    json j = base_scene();
    row.edit(j);
    expect_error(dir, j, row.field, row.reason);
  }
}

// The InputError that loading `path` throws; a test failure (and an empty error) when none is thrown.
inline InputError load_error(const std::filesystem::path& path) {
  try {
    load_scene(path);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << path << ": no InputError";
  return InputError("", "");
}

}  // namespace prizma::render::scene_test
