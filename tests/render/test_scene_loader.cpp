// load_scene as a whole: the happy path (every field), defaults, the hash, the JSON itself (syntax,
// unknown and duplicate keys, types, nesting), non-regular files and the command-line overrides. Each
// error test checks the field path ("<file>: <field path>") and the reason.
#include "scene_loader_test_support.h"

namespace prizma::render {
namespace {

using namespace scene_test;

TEST(SceneLoader, HappyPathFillsEveryField) {
  ScratchDir dir;
  const auto path = write_scene(dir, base_scene());
  const Scene s = load_scene(path);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.output, dir.path() / "out/x.exr");
  EXPECT_EQ(s.hash.size(), 16u);
  // Medium: 16³ cube_sphere, two materials.
  EXPECT_EQ(s.medium.dims, (std::array<int, 3>{16, 16, 16}));
  ASSERT_EQ(s.medium.materials.size(), 2u);
  EXPECT_EQ(s.medium.materials[0].name, "cube");
  EXPECT_DOUBLE_EQ(s.medium.materials[0].sigma_t_per_unit.eval(550.0), 3.0);
  EXPECT_DOUBLE_EQ(s.medium.materials[0].albedo.eval(550.0), 0.99);
  EXPECT_DOUBLE_EQ(s.medium.materials[1].sigma_t_per_unit.eval(550.0), 5.0);
  EXPECT_GT(s.medium.materials[1].albedo.eval(600.0), 0.0);
  EXPECT_LT(s.medium.materials[1].albedo.eval(600.0), 1.0);
  EXPECT_TRUE(s.medium.bounds_max.isApprox(Eigen::Vector3d(0.5, 0.5, 0.5)));
  // Voxels: centre = sphere (value 255 → density 1), corner empty, cube region = material 0.
  auto idx = [](int x, int y, int z) { return (static_cast<std::size_t>(z) * 16 + y) * 16 + x; };
  EXPECT_EQ(s.medium.material[idx(8, 8, 8)], 1);
  EXPECT_FLOAT_EQ(s.medium.density[idx(8, 8, 8)], 1.0f);
  EXPECT_EQ(s.medium.material[idx(0, 0, 0)], Medium::kEmpty);
  EXPECT_EQ(s.medium.material[idx(2, 8, 8)], 0);
  // Camera, lights, settings.
  EXPECT_EQ(s.camera.type, CameraType::Perspective);
  EXPECT_EQ(s.camera.width, 32);
  EXPECT_EQ(s.camera.height, 24);
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 40.0);
  EXPECT_TRUE(s.camera.position.isApprox(Eigen::Vector3d(0, 0, 3)));
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "side");
  EXPECT_TRUE(s.lights[0].direction.isApprox(Eigen::Vector3d(1, 0, 0)));  // normalised
  EXPECT_DOUBLE_EQ(s.lights[0].angular_size_deg, 1.0);
  EXPECT_EQ(s.lights[1].direction, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.lights[1].spectrum_spec, "D65");
  EXPECT_EQ(s.settings.bins, spectral::BinLayout::linear(400, 700, 12));
  EXPECT_EQ(s.settings.sample_begin, 0);
  EXPECT_EQ(s.settings.sample_end, 8);
  EXPECT_EQ(s.settings.seed, 7u);
  EXPECT_EQ(s.settings.max_bounces, 5);
  EXPECT_EQ(s.settings.wavelength_sampling, WavelengthSampling::Single);
  EXPECT_EQ(s.settings.sampler, Sampler::Sobol);
}

TEST(SceneLoader, DefaultsWhenOptionalFieldsAreMissing) {
  ScratchDir dir;
  json j = base_scene();
  for (const char* k : {"camera", "bins", "samples", "seed", "max_bounces", "wavelength_sampling", "sampler", "output", "description"}) {
    j.erase(k);
  }
  const Scene s = load_scene(write_scene(dir, j, "minimal.json"));
  EXPECT_EQ(s.output, dir.path() / "minimal.exr");
  EXPECT_EQ(s.camera.width, 256);
  EXPECT_EQ(s.settings.sample_end, 64);
  EXPECT_EQ(s.settings.seed, 1u);
  EXPECT_EQ(s.settings.max_bounces, -1);
  EXPECT_EQ(s.settings.wavelength_sampling, WavelengthSampling::Auto);
  EXPECT_EQ(s.settings.sampler, Sampler::Independent);
  EXPECT_EQ(s.settings.event_probabilities, EventProbabilities::Auto);
  EXPECT_EQ(s.settings.bins, spectral::BinLayout());
  // The scheme is a scene field, so -D sets it too.
  EXPECT_EQ(load_scene(dir / "minimal.json", {parse_scene_override("event_probabilities=implicit")})
                .settings.event_probabilities,
            EventProbabilities::Implicit);
  // Spectral MIS's lane groups: auto (0) unless the scene or -D gives a count.
  EXPECT_EQ(s.settings.mis_lane_groups, 0);
  EXPECT_EQ(load_scene(dir / "minimal.json", {parse_scene_override("mis_lane_groups=3")}).settings.mis_lane_groups, 3);
  EXPECT_EQ(load_scene(dir / "minimal.json", {parse_scene_override("mis_lane_groups=auto")}).settings.mis_lane_groups, 0);
}

TEST(SceneLoader, HashIsStableAndFollowsTheText) {
  ScratchDir dir;
  json j = base_scene();
  const std::string h1 = load_scene(write_scene(dir, j)).hash;
  EXPECT_EQ(load_scene(write_scene(dir, j)).hash, h1);
  j["seed"] = 8;
  EXPECT_NE(load_scene(write_scene(dir, j)).hash, h1);
}

TEST(SceneLoader, HashIsPinned) {
  // The hash is stored in every render (prizma:sceneHash) and --resume and merge compare it, so its
  // value may not change: this scene's hash (text, volume, material spectra, an emitting material,
  // a -D override) as prizma-render 7909c5a printed it, before the hash's FNV-1a moved into
  // libspectral's prizma/spectral/fnv1a.h (shared with the pixel checksum).
  const std::string text =
      R"({"volume": {"type": "procedural", "name": "cube_sphere", "resolution": 8}, "materials": )"
      R"([{"name": "haze", "range": [50, 150], "albedo": 0.9, "extinction": {"spectrum": )"
      R"("gaussian:450:200", "scale": 3}, "anisotropy": 0.2}, {"name": "core", "range": [200, )"
      R"(255], "albedo": "cc:orange", "extinction": 10, "anisotropy": 0, "emission": 0.5}], )"
      R"("camera": {"type": "orthographic", "position": [0, 0, 2], "look_at": [0, 0, 0], "up": )"
      R"([0, 1, 0], "ortho_height": 1.2, "width": 4, "height": 4}, "lights": [{"name": "side", )"
      R"("direction": [1, 0, 0], "spectrum": "D65"}], "bins": "linear:400:700:6", "samples": 2, )"
      R"("seed": 3})";
  ScratchDir dir;
  const auto path = dir.write("pinned.json", text);
  EXPECT_EQ(load_scene(path).hash, "1910e1d1e5423f5e");
  EXPECT_EQ(load_scene(path, {parse_scene_override("seed=5")}).hash, "f61d58170c1f0930");
  EXPECT_EQ(load_scene_text(text, "scene", dir.path()).hash, "1910e1d1e5423f5e");
}

TEST(SceneLoaderErrors, MalformedJsonReportsLineAndColumn) {
  ScratchDir dir;
  const auto path = dir.write("bad.json", "{\n  \"samples\": 4,\n  \"seed\" 3\n}\n");
  const InputError e = load_error(path);
  EXPECT_EQ(e.input(), path.string());
  EXPECT_NE(e.reason().find("line 3, column"), std::string::npos) << e.what();
}

TEST(SceneLoaderErrors, MissingFile) {
  ScratchDir dir;
  EXPECT_THROW(load_scene(dir / "absent.json"), InputError);
}

TEST(SceneLoaderErrors, UnknownFields) {
  ScratchDir dir;
  expect_errors(dir, {
      {"sampels", "unknown field", [](json& j) { j["sampels"] = 4; }},
      {"materials[1].albdo", "unknown field", [](json& j) { j["materials"][1]["albdo"] = 0.5; }},
      {"camera.fov", "unknown field", [](json& j) { j["camera"]["fov"] = 30; }},
      // raw-only field on a procedural volume
      {"volume.dims", "unknown field",
       [](json& j) { j["volume"]["dims"] = {16, 16, 16}; }},
  });
}

TEST(SceneLoaderErrors, DuplicateKeys) {
  ScratchDir dir;
  const InputError e = load_error(dir.write("dup.json", R"({"samples": 4, "samples": 5})"));
  EXPECT_NE(e.reason().find("duplicate key \"samples\""), std::string::npos) << e.what();
}

// A number beyond the range of a double makes nlohmann::json throw out_of_range, not parse_error:
// found by fuzz_scene (a 300-digit number); it must still be an InputError naming where it is.
TEST(SceneLoaderErrors, NumberBeyondDouble) {
  ScratchDir dir;
  const auto huge = dir.write("huge.json", "{\n  \"samples\": 4,\n  \"seed\": 1e400\n}");
  EXPECT_EQ(load_error(huge).reason(), "number 1e400 at line 3, column 11 is beyond the range of a double");
  const auto digits = dir.write("digits.json", "{\"samples\": " + std::string(400, '9') + "}");
  EXPECT_EQ(load_error(digits).reason(),
            "number " + std::string(24, '9') + "... at line 1, column 13 is beyond the range of a double");
}

TEST(SceneLoaderErrors, WrongTypes) {
  ScratchDir dir;
  expect_errors(dir, {
      {"samples", "must be an integer", [](json& j) { j["samples"] = "8"; }},
      {"samples", "must be an integer", [](json& j) { j["samples"] = 2.5; }},
      {"camera.position", "array of 3 numbers", [](json& j) { j["camera"]["position"] = {0, 0}; }},
      {"lights[0].direction[1]", "must be a number", [](json& j) { j["lights"][0]["direction"][1] = "up"; }},
      {"materials[0].albedo", "spectrum spec", [](json& j) { j["materials"][0]["albedo"] = json::array({0.5}); }},
      {"materials", "must be an array", [](json& j) { j["materials"] = json::object(); }},
  });
}

// issue 11: deeply nested JSON crashed (SIGSEGV in nlohmann's recursive dump); now one InputError.
TEST(SceneLoader, RefusesJsonNestedTooDeeply) {
  ScratchDir dir;
  const std::string deep = "{\"description\": " + std::string(70000, '[') + std::string(70000, ']') + "}";
  const InputError e = load_error(dir.write("deep.json", deep));
  EXPECT_EQ(e.input(), (dir / "deep.json").string());
  EXPECT_NE(e.reason().find("nested deeper than"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("line 1, column"), std::string::npos) << e.what();
  // Brackets inside strings do not count.
  json j = base_scene();
  j["description"] = std::string(1000, '[');
  EXPECT_NO_THROW(load_scene(write_scene(dir, j)));
}

// issue 11: a directory, a FIFO and a symlink loop all said "does not exist".
TEST(SceneLoader, SaysWhatANonRegularSceneIs) {
  ScratchDir dir;
  std::filesystem::create_directory(dir / "folder.json");
  EXPECT_NE(load_error(dir / "folder.json").reason().find("is a folder"), std::string::npos);
  ASSERT_EQ(::mkfifo((dir / "pipe.json").c_str(), 0600), 0);
  EXPECT_NE(load_error(dir / "pipe.json").reason().find("FIFO"), std::string::npos);  // and no hang
  std::filesystem::create_symlink(dir / "loop_b.json", dir / "loop_a.json");
  std::filesystem::create_symlink(dir / "loop_a.json", dir / "loop_b.json");
  EXPECT_NE(load_error(dir / "loop_a.json").reason().find("symbolic link loop"), std::string::npos);
  std::filesystem::create_symlink(dir / "nowhere.json", dir / "dangling.json");
  EXPECT_NE(load_error(dir / "dangling.json").reason().find("does not exist"), std::string::npos);
  EXPECT_NE(load_error(dir / "absent.json").reason().find("no such file"), std::string::npos);
  EXPECT_NE(load_error("/dev/null").reason().find("character device"), std::string::npos);
}

// issue 11: command-line values obey exactly the scene's ranges (--width 20000 bypassed 16384,
// --seed -1 wrapped, --width 1e9 exited 1).
TEST(SceneLoader, CommandLineOverridesObeyTheSceneRanges) {
  EXPECT_EQ(scene_integer_override("640", "camera.width", "--width"), 640);
  EXPECT_EQ(scene_integer_override("16384", "camera.height", "--height"), 16384);
  EXPECT_EQ(scene_integer_override("1099511627776", "samples", "--spp"), std::int64_t{1} << 40);
  EXPECT_EQ(scene_seed_override("18446744073709551615", "--seed"), 18446744073709551615ULL);
  auto error = [](auto f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error([] { scene_integer_override("20000", "camera.width", "--width"); }),
            "--width: must be in [1, 16384] (got 20000)");
  EXPECT_EQ(error([] { scene_integer_override("0", "camera.height", "--height"); }),
            "--height: must be in [1, 16384] (got 0)");
  EXPECT_NE(error([] { scene_integer_override("1e9", "camera.width", "--width"); }).find("--width: must be an integer"),
            std::string::npos);
  EXPECT_NE(error([] { scene_integer_override("8.7", "samples", "--spp"); }).find("--spp: must be an integer"),
            std::string::npos);
  EXPECT_NE(error([] { scene_integer_override("many", "samples", "--spp"); }).find("--spp: must be an integer"),
            std::string::npos);
  EXPECT_EQ(error([] { scene_integer_override("1099511627777", "samples", "--spp"); }),
            "--spp: must be in [1, 1099511627776] (got 1099511627777)");
  EXPECT_NE(error([] { scene_seed_override("-1", "--seed"); }).find("--seed: must be an integer ≥ 0"), std::string::npos);
  EXPECT_NE(error([] { scene_seed_override("18446744073709551616", "--seed"); }).find("--seed: must be an integer"),
            std::string::npos);
}

// -D KEY=VALUE (prizma-render): a field set by its path, typed by the field it replaces, checked as
// the file is, errors named by the option; the overrides change the scene's hash.
TEST(SceneLoader, DefineOverridesAnyFieldByItsPath) {
  ScratchDir dir;
  const auto path = write_scene(dir, base_scene());
  const Scene plain = load_scene(path);
  const Scene s = load_scene(path, {parse_scene_override("camera.fov_deg=30"), parse_scene_override("lights.sky.spectrum=A"),
                                    parse_scene_override("lights[0].direction=[0, 1, 0]"),
                                    parse_scene_override("bins=linear:400:700:4"), parse_scene_override("seed=9"),
                                    parse_scene_override("normalization={\"min\": 0, \"max\": 255}")});
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 30.0);
  EXPECT_EQ(s.lights[1].spectrum_spec, "A");
  EXPECT_TRUE(s.lights[0].direction.isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_EQ(s.settings.bins, spectral::BinLayout::linear(400, 700, 4));
  EXPECT_EQ(s.settings.seed, 9u);
  EXPECT_NE(s.hash, plain.hash);
  EXPECT_EQ(load_scene(path, {parse_scene_override("seed=9")}).hash, load_scene(path, {parse_scene_override("seed=9")}).hash);
  auto error = [&](const std::vector<std::string>& defines) {
    try {
      std::vector<SceneOverride> o;
      for (const auto& d : defines) o.push_back(parse_scene_override(d));
      load_scene(path, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error({"camera.fov_deg=300"}), "-D camera.fov_deg: must be in (0, 180) (got 300)");
  EXPECT_EQ(error({"samples=many"}), "-D samples: must be an integer (got string \"many\")");
  EXPECT_EQ(error({"lights.fill.spectrum=A"}), "-D lights.fill.spectrum: lights has no element named \"fill\" (2 elements: side, sky)");
  EXPECT_EQ(error({"seed=1", "seed=2"}), "-D seed: is given twice");
  EXPECT_EQ(error({"lights[0].spectrum=A", "lights.side.spectrum=A"}), "-D lights.side.spectrum: is given twice");
  EXPECT_EQ(error({"camera..width=3"}).rfind("-D camera..width: malformed key", 0), 0u);
  EXPECT_EQ(error({"seed"}).rfind("-D seed: expected KEY=VALUE", 0), 0u);
  EXPECT_EQ(error({"normalization=\"auto\"", "normalisation=\"auto\""}),
            "-D normalization: give normalisation or normalization (the same field), not both");
}

}  // namespace
}  // namespace prizma::render
