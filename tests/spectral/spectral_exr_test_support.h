#pragma once
// The fixture and file helpers of the spectral EXR tests (test_spectral_exr_*.cpp): a scratch folder per
// test, random transport layers, files of the published layout written by plain OpenEXR code, header
// rewrites.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <ImfChannelList.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfVecAttribute.h>
#include <ImfOutputFile.h>
#include <ImfPreviewImage.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfThreading.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "scratch_files.h"

namespace prizma::spectral::exr_test {

namespace fs = std::filesystem;

class SpectralExr : public ::testing::Test {
 protected:
  void SetUp() override {
    m_dir = test::scratch_dir("exr", ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(m_dir); }
  fs::path file(const std::string& name) const { return m_dir / name; }
  fs::path m_dir;
};

// Random transport in [0, 2), a fixed seed per light.
inline TransportLayer make_layer(const std::string& name, int w, int h, int bins, unsigned seed, bool variance) {
  TransportLayer l;
  l.name = name;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  l.data.resize(static_cast<std::size_t>(w) * h * bins);
  for (auto& v : l.data) v = u(rng);
  if (variance) {
    l.variance.resize(l.data.size());
    for (auto& v : l.variance) v = 1e-3f * u(rng);
  }
  return l;
}

inline SpectralImage make_image(int w, int h, const BinLayout& bins, const std::vector<std::string>& names,
                         bool variance = false) {
  SpectralImage img;
  img.width = w;
  img.height = h;
  img.bins = bins;
  unsigned seed = 1;
  for (const auto& n : names) img.lights.push_back(make_layer(n, w, h, bins.size(), seed++, variance));
  return img;
}

inline std::vector<std::string> channel_names(const fs::path& p) {
  Imf::InputFile f(p.c_str());
  std::vector<std::string> out;
  for (auto it = f.header().channels().begin(); it != f.header().channels().end(); ++it) out.push_back(it.name());
  return out;
}

inline bool has_channel(const fs::path& p, const std::string& name) {
  Imf::InputFile f(p.c_str());
  return f.header().channels().findChannel(name) != nullptr;
}

// Writes a file of the published layout with plain OpenEXR code: one value per channel, constant over
// the image, channel names given verbatim.
inline void write_plain_exr(const fs::path& p, int w, int h, const std::vector<std::string>& names,
                     const std::vector<float>& values, Imf::PixelType type = Imf::FLOAT) {
  Imf::Header header(w, h);
  header.insert("spectralLayoutVersion", Imf::StringAttribute("1.0"));
  for (const auto& n : names) header.channels().insert(n, Imf::Channel(type));
  std::vector<std::vector<float>> planes(names.size());
  std::vector<std::vector<half>> half_planes(names.size());
  Imf::FrameBuffer fb;
  for (std::size_t c = 0; c < names.size(); ++c) {
    planes[c].assign(static_cast<std::size_t>(w) * h, values[c]);
    half_planes[c].assign(planes[c].size(), half(values[c]));
    char* base = type == Imf::HALF ? reinterpret_cast<char*>(half_planes[c].data())
                                   : reinterpret_cast<char*>(planes[c].data());
    const std::size_t elem = type == Imf::HALF ? sizeof(half) : sizeof(float);
    fb.insert(names[c], Imf::Slice(type, base, elem, elem * static_cast<std::size_t>(w)));
  }
  Imf::OutputFile out(p.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(h);
}

// Copies a float file to `out` with its header changed by `edit`; the pixels are kept as they are.
inline fs::path rewrite_header(const fs::path& in_path, const fs::path& out, const std::function<void(Imf::Header&)>& edit) {
  Imf::InputFile in(in_path.c_str());
  Imf::Header h = in.header();
  const Imath::Box2i dw = h.dataWindow();
  const std::size_t w = static_cast<std::size_t>(dw.max.x - dw.min.x + 1);
  const std::size_t rows = static_cast<std::size_t>(dw.max.y - dw.min.y + 1);
  std::size_t channels = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) ++channels;
  std::vector<float> buf(w * rows * channels);
  Imf::FrameBuffer fb;
  std::size_t c = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it, ++c) {
    fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, buf.data() + c, dw, channels * sizeof(float),
                                          channels * w * sizeof(float)));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  edit(h);
  Imf::OutputFile o(out.c_str(), h);
  o.setFrameBuffer(fb);
  o.writePixels(static_cast<int>(rows));
  return out;
}

// Copies an EXR, letting `edit` change any channel's values (read and written as float).
inline fs::path rewrite_pixels(const fs::path& in_path, const fs::path& out,
                               const std::function<void(const std::string& channel, std::vector<float>& values)>& edit) {
  Imf::InputFile in(in_path.c_str());
  const Imf::Header h = in.header();
  const Imath::Box2i dw = h.dataWindow();
  const std::size_t pixels = static_cast<std::size_t>(dw.max.x - dw.min.x + 1) * (dw.max.y - dw.min.y + 1);
  std::map<std::string, std::vector<float>> values;
  Imf::FrameBuffer fb;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    auto& v = values[it.name()];
    v.resize(pixels);
    fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, v.data(), dw, sizeof(float),
                                          sizeof(float) * static_cast<std::size_t>(dw.max.x - dw.min.x + 1)));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (auto& [name, v] : values) edit(name, v);
  Imf::OutputFile o(out.c_str(), h);
  o.setFrameBuffer(fb);
  o.writePixels(dw.max.y - dw.min.y + 1);
  return out;
}

// The little-endian int32 at `at` in `bytes`.
inline std::int64_t le_u32_at(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}

inline std::string read_error(const fs::path& p, const ExrReadOptions& opts = {}) {
  try {
    read_spectral_exr(p, opts);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace prizma::spectral::exr_test
