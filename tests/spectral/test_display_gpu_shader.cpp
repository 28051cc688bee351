// DisplayTransform::gpu_shader: OpenColorIO's GLSL ES 3.0 for the live page, with its LUT textures.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "prizma/spectral/display.h"

namespace fs = std::filesystem;
using namespace prizma::spectral;

namespace {

const fs::path kConfig = fs::path(PRIZMA_TEST_DATA_DIR) / "ocio" / "config.ocio";

TEST(DisplayGpuShader, PrizmaDisplaysAreLutFreeGlslFunctions) {
  for (const char* display : {"sRGB", "Display P3", "Rec.2020"}) {
    DisplayOptions opts;
    opts.config = kConfig;
    opts.display = display;
    const DisplayShader shader = DisplayTransform(opts).gpu_shader("toDisplay");
    EXPECT_EQ(shader.function_name, "toDisplay");
    EXPECT_NE(shader.glsl.find("vec4 toDisplay(vec4 inPixel)"), std::string::npos) << shader.glsl;
    EXPECT_NE(shader.glsl.find("pow("), std::string::npos) << display << ": the transfer curve";
    EXPECT_TRUE(shader.textures.empty()) << display;
    EXPECT_TRUE(shader.uniforms.empty()) << display;
  }
}

// A config whose display goes through a 1D LUT file: the shader samples it and the texture comes out
// with its values.
TEST(DisplayGpuShader, LutTexturesComeWithTheirValues) {
  const fs::path dir = fs::temp_directory_path() / ("prizma_gpu_shader_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "curve.spi1d") << "Version 1\nFrom 0.0 1.0\nLength 5\nComponents 1\n{\n0\n0.2\n0.45\n0.7\n1\n}\n";
  std::ofstream(dir / "config.ocio") << R"(ocio_profile_version: 2
search_path: "."
roles:
  default: lin
  cie_xyz_d65_interchange: CIE-XYZ-D65
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  LUT:
    - !<View> {name: Standard, colorspace: curved}
colorspaces:
  - !<ColorSpace> {name: lin}
  - !<ColorSpace>
    name: CIE-XYZ-D65
    to_scene_reference: !<MatrixTransform> {matrix: [3.2406, -1.5372, -0.4986, 0, -0.9689, 1.8758, 0.0415, 0, 0.0557, -0.204, 1.057, 0, 0, 0, 0, 1]}
  - !<ColorSpace>
    name: curved
    from_scene_reference: !<FileTransform> {src: curve.spi1d, interpolation: linear}
)";
  DisplayOptions opts;
  opts.config = dir / "config.ocio";
  opts.display = "LUT";
  const DisplayShader shader = DisplayTransform(opts).gpu_shader();
  ASSERT_EQ(shader.textures.size(), 1u) << shader.glsl;
  const DisplayShader::Texture& t = shader.textures[0];
  EXPECT_EQ(t.depth, 0);
  EXPECT_GT(t.width, 0);
  EXPECT_EQ(t.values.size(), static_cast<std::size_t>(t.width) * t.height * t.channels);
  EXPECT_NE(shader.glsl.find(t.sampler), std::string::npos) << shader.glsl;
  fs::remove_all(dir);
}

}  // namespace
