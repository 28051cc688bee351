// Display transforms through OpenColorIO 2.1: the config is loaded and the CPU processor built once in
// the constructor; apply() only runs the processor, which OCIO documents as thread-safe.
#include "prizma/spectral/display.h"

#include <Eigen/LU>
#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/out_of_memory.h"

namespace OCIO = OCIO_NAMESPACE;

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

// The input space: OCIO 2.2's interchange role if the config has it, else this name.
constexpr const char* kXyzRole = "cie_xyz_d65_interchange";
constexpr const char* kXyzSpace = "CIE-XYZ-D65";

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ", ";
    out += n;
  }
  return out;
}

std::vector<std::string> list_displays(const OCIO::ConstConfigRcPtr& config) {
  std::vector<std::string> out;
  for (int i = 0; i < config->getNumDisplays(); ++i) out.emplace_back(config->getDisplay(i));
  return out;
}

std::vector<std::string> list_views(const OCIO::ConstConfigRcPtr& config, const std::string& display) {
  std::vector<std::string> out;
  for (int i = 0; i < config->getNumViews(display.c_str()); ++i) out.emplace_back(config->getView(display.c_str(), i));
  return out;
}

std::vector<std::string> list_colour_spaces(const OCIO::ConstConfigRcPtr& config) {
  std::vector<std::string> out;
  for (int i = 0; i < config->getNumColorSpaces(); ++i) out.emplace_back(config->getColorSpaceNameByIndex(i));
  return out;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  for (const auto& n : names) {
    if (n == name) return true;
  }
  return false;
}

}  // namespace

struct DisplayTransform::Impl {
  fs::path config_path;
  OCIO::ConstConfigRcPtr config;
  OCIO::ConstProcessorRcPtr processor;
  OCIO::ConstCPUProcessorRcPtr cpu;
  std::string description;
};

fs::path default_ocio_config() {
  if (const char* env = std::getenv("OCIO"); env != nullptr && env[0] != '\0') return fs::path(env);
  return data_file("ocio/config.ocio");
}

DisplayTransform::DisplayTransform(const DisplayOptions& opts) : m_impl(std::make_unique<Impl>()) {
  Impl& impl = *m_impl;
  impl.config_path = opts.config.empty() ? default_ocio_config() : opts.config;
  const std::string cfg = impl.config_path.string();

  // Load and validate the config.
  std::error_code ec;
  if (!fs::is_regular_file(impl.config_path, ec)) {
    throw InputError(cfg, fs::exists(impl.config_path, ec) ? "OCIO config is not a file"
                                                           : "OCIO config does not exist");
  }
  try {
    impl.config = OCIO::Config::CreateFromFile(cfg.c_str());
    impl.config->validate();
  } catch (const OCIO::Exception& e) {
    // OCIO wraps a failed allocation in its own exception: that is not the config's fault.
    if (message_says_out_of_memory(e.what())) {
      throw RuntimeError(cfg + ": out of memory loading the OCIO config (" + e.what() + ")");
    }
    throw InputError(cfg, std::string("cannot load OCIO config: ") + e.what());
  }

  // The XYZ input space.
  std::string src;
  if (impl.config->hasRole(kXyzRole)) {
    src = kXyzRole;
  } else if (impl.config->getColorSpace(kXyzSpace)) {
    src = kXyzSpace;
  } else {
    throw InputError(cfg, std::string("OCIO config has no \"") + kXyzSpace + "\" colour space and no " + kXyzRole +
                              " role: Prizma needs CIE XYZ (D65) as input");
  }

  // The processor: a plain colour space conversion, or a display with its view.
  OCIO::ConstProcessorRcPtr processor;
  try {
    if (!opts.colour_space.empty()) {
      if (!impl.config->getColorSpace(opts.colour_space.c_str())) {
        throw InputError("colour space", "unknown colour space \"" + opts.colour_space + "\" in " + cfg +
                                             " (valid: " + join(list_colour_spaces(impl.config)) + ")");
      }
      processor = impl.config->getProcessor(src.c_str(), opts.colour_space.c_str());
      impl.description = "CIE XYZ (D65) -> colour space \"" + opts.colour_space + "\"";
    } else {
      const auto displays = list_displays(impl.config);
      if (!contains(displays, opts.display)) {
        throw InputError("display", "unknown display \"" + opts.display + "\" in " + cfg + " (valid: " +
                                        join(displays) + ")");
      }
      std::string view = opts.view;
      if (view.empty()) {
        view = impl.config->getDefaultView(opts.display.c_str());
      } else if (!contains(list_views(impl.config, opts.display), view)) {
        throw InputError("view", "unknown view \"" + view + "\" of display \"" + opts.display + "\" in " + cfg +
                                     " (valid: " + join(list_views(impl.config, opts.display)) + ")");
      }
      auto t = OCIO::DisplayViewTransform::Create();
      t->setSrc(src.c_str());
      t->setDisplay(opts.display.c_str());
      t->setView(view.c_str());
      processor = impl.config->getProcessor(t);
      impl.description = "CIE XYZ (D65) -> display \"" + opts.display + "\", view \"" + view + "\"";
    }
    impl.processor = processor;
    // Lossless optimisation only: no fast pow/exp approximations.
    impl.cpu = processor->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32,
                                                   OCIO::OPTIMIZATION_LOSSLESS);
  } catch (const OCIO::Exception& e) {
    throw InputError(cfg, std::string("cannot build the OCIO transform: ") + e.what());
  }
  impl.description += " (OCIO config " + cfg + ")";
}

DisplayTransform::~DisplayTransform() = default;
DisplayTransform::DisplayTransform(DisplayTransform&&) noexcept = default;
DisplayTransform& DisplayTransform::operator=(DisplayTransform&&) noexcept = default;

void DisplayTransform::apply(float* xyz_interleaved, std::size_t pixel_count) const {
  if (pixel_count == 0) return;
  // Chunks keep the per-call image description small; OCIO's CPU processor is stateless per call.
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  for (std::size_t start = 0; start < pixel_count; start += kChunk) {
    const std::size_t n = std::min(kChunk, pixel_count - start);
    OCIO::PackedImageDesc desc(xyz_interleaved + 3 * start, static_cast<long>(n), 1, 3);
    try {
      m_impl->cpu->apply(desc);
    } catch (const OCIO::Exception& e) {
      throw RuntimeError(std::string("OCIO transform failed: ") + e.what());
    }
  }
}

const fs::path& DisplayTransform::config_path() const { return m_impl->config_path; }

std::string DisplayTransform::description() const { return m_impl->description; }

std::vector<std::string> DisplayTransform::displays() const { return list_displays(m_impl->config); }

std::vector<std::string> DisplayTransform::colour_spaces() const { return list_colour_spaces(m_impl->config); }

// long on purpose: OpenColorIO's GPU shader description copied field by field into ours.
DisplayShader DisplayTransform::gpu_shader(const std::string& function_name) const {
  DisplayShader out;
  out.function_name = function_name;
  try {
    const auto gpu = m_impl->processor->getOptimizedGPUProcessor(OCIO::OPTIMIZATION_LOSSLESS);
    OCIO::GpuShaderDescRcPtr desc = OCIO::GpuShaderDesc::CreateShaderDesc();
    desc->setLanguage(OCIO::GPU_LANGUAGE_GLSL_ES_3_0);
    desc->setFunctionName(function_name.c_str());
    desc->setResourcePrefix("ocio_");
    gpu->extractGpuShaderInfo(desc);
    out.glsl = desc->getShaderText();
    for (unsigned i = 0; i < desc->getNumUniforms(); ++i) {
      OCIO::GpuShaderDesc::UniformData data;
      DisplayShader::Uniform u;
      u.name = desc->getUniform(i, data);
      switch (data.m_type) {
        case OCIO::UNIFORM_DOUBLE: u.type = "double"; u.values = {data.m_getDouble()}; break;
        case OCIO::UNIFORM_BOOL: u.type = "bool"; u.values = {data.m_getBool() ? 1.0 : 0.0}; break;
        case OCIO::UNIFORM_FLOAT3: {
          u.type = "float3";
          const auto v = data.m_getFloat3();
          u.values = {v[0], v[1], v[2]};
          break;
        }
        case OCIO::UNIFORM_VECTOR_FLOAT: {
          u.type = "vector_float";
          const float* v = data.m_vectorFloat.m_getVector();
          u.values.assign(v, v + data.m_vectorFloat.m_getSize());
          break;
        }
        case OCIO::UNIFORM_VECTOR_INT: {
          u.type = "vector_int";
          const int* v = data.m_vectorInt.m_getVector();
          u.values.assign(v, v + data.m_vectorInt.m_getSize());
          break;
        }
        case OCIO::UNIFORM_UNKNOWN: throw RuntimeError("OCIO GPU shader: uniform " + u.name + " has an unknown type");
      }
      out.uniforms.push_back(std::move(u));
    }
    for (unsigned i = 0; i < desc->getNumTextures(); ++i) {
      const char* name = nullptr;
      const char* sampler = nullptr;
      unsigned width = 0, height = 0;
      OCIO::GpuShaderDesc::TextureType channel{};
      OCIO::Interpolation interpolation{};
      desc->getTexture(i, name, sampler, width, height, channel, interpolation);
      DisplayShader::Texture t;
      t.name = name;
      t.sampler = sampler;
      t.width = static_cast<int>(width);
      t.height = static_cast<int>(std::max(height, 1u));
      t.channels = channel == OCIO::GpuShaderDesc::TEXTURE_RED_CHANNEL ? 1 : 3;
      t.linear = interpolation != OCIO::INTERP_NEAREST;
      const float* values = nullptr;
      desc->getTextureValues(i, values);
      t.values.assign(values, values + static_cast<std::size_t>(t.width) * t.height * t.channels);
      out.textures.push_back(std::move(t));
    }
    for (unsigned i = 0; i < desc->getNum3DTextures(); ++i) {
      const char* name = nullptr;
      const char* sampler = nullptr;
      unsigned edge = 0;
      OCIO::Interpolation interpolation{};
      desc->get3DTexture(i, name, sampler, edge, interpolation);
      DisplayShader::Texture t;
      t.name = name;
      t.sampler = sampler;
      t.width = t.height = t.depth = static_cast<int>(edge);
      t.channels = 3;
      t.linear = interpolation != OCIO::INTERP_NEAREST;
      const float* values = nullptr;
      desc->get3DTextureValues(i, values);
      t.values.assign(values, values + static_cast<std::size_t>(edge) * edge * edge * 3);
      out.textures.push_back(std::move(t));
    }
  } catch (const OCIO::Exception& e) {
    throw RuntimeError(std::string("OCIO GPU shader: ") + e.what());
  }
  return out;
}

std::optional<DisplayMatrixCurve> DisplayTransform::split_matrix_curve() const {
  try {
    const OCIO::ConstGroupTransformRcPtr group = m_impl->processor->createGroupTransform();
    Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
    OCIO::GroupTransformRcPtr tail = OCIO::GroupTransform::Create();
    bool in_tail = false;
    for (int i = 0; i < group->getNumTransforms(); ++i) {
      const OCIO::ConstTransformRcPtr t = group->getTransform(i);
      const OCIO::TransformType type = t->getTransformType();
      if (type == OCIO::TRANSFORM_TYPE_MATRIX && !in_tail) {
        const auto m = OCIO::DynamicPtrCast<const OCIO::MatrixTransform>(t);
        double m44[16], offset[4];
        m->getMatrix(m44);
        m->getOffset(offset);
        if (offset[0] != 0.0 || offset[1] != 0.0 || offset[2] != 0.0) return std::nullopt;
        Eigen::Matrix3d step;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) step(r, c) = m44[4 * r + c];
        if (m->getDirection() == OCIO::TRANSFORM_DIR_INVERSE) step = step.inverse().eval();
        matrix = step * matrix;
        continue;
      }
      switch (type) {
        case OCIO::TRANSFORM_TYPE_EXPONENT:
        case OCIO::TRANSFORM_TYPE_EXPONENT_WITH_LINEAR:
        case OCIO::TRANSFORM_TYPE_LOG:
        case OCIO::TRANSFORM_TYPE_LOG_AFFINE:
        case OCIO::TRANSFORM_TYPE_LOG_CAMERA:
        case OCIO::TRANSFORM_TYPE_RANGE:
          break;
        case OCIO::TRANSFORM_TYPE_LUT1D:
          if (OCIO::DynamicPtrCast<const OCIO::Lut1DTransform>(t)->getHueAdjust() != OCIO::HUE_NONE) return std::nullopt;
          break;
        default:
          return std::nullopt;
      }
      in_tail = true;
      tail->appendTransform(t->createEditableCopy());
    }
    const OCIO::ConstCPUProcessorRcPtr cpu = m_impl->config->getProcessor(tail)->getOptimizedCPUProcessor(
        OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_LOSSLESS);
    DisplayMatrixCurve out;
    out.matrix = matrix;
    out.curve = [cpu](float* rgb, std::size_t pixels) {
      if (pixels == 0) return;
      OCIO::PackedImageDesc desc(rgb, static_cast<long>(pixels), 1, 3);
      cpu->apply(desc);
    };
    return out;
  } catch (const OCIO::Exception&) {
    return std::nullopt;
  }
}

}  // namespace prizma::spectral
