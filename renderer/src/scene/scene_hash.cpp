#include "scene_hash.h"

#include <cstdio>

namespace prizma::render::scene_file {

void Fnv1a::add(const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    m_h ^= p[i];
    m_h *= 0x100000001b3ULL;
  }
}

void Fnv1a::add_spectrum(const spectral::Spectrum& s) {
  const double c = s.is_constant() ? s.eval(0.0) : 0.0;
  add(&c, sizeof c);
  add(s.wavelengths_nm().data(), s.wavelengths_nm().size() * sizeof(double));
  add(s.values().data(), s.values().size() * sizeof(double));
}

std::string Fnv1a::hex() const {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(m_h));
  return buf;
}

SceneHash::SceneHash(const std::string& text, const std::vector<SceneOverride>& overrides, const Volume& vol) {
  m_h.add(text.data(), text.size());
  for (const SceneOverride& o : overrides) {  // a render with -D is not the file's render (--resume checks)
    const std::string d = "\n-D " + o.key + "=" + o.value;
    m_h.add(d.data(), d.size());
  }
  m_h.add(vol.dims.data(), sizeof vol.dims);
  m_h.add(vol.spacing.data(), sizeof vol.spacing);
  m_voxels.run([this, &vol] { m_h.add(vol.values.data(), vol.values.size() * sizeof(float)); });
}

SceneHash::~SceneHash() { m_voxels.wait(); }

std::string SceneHash::finish(const Scene& scene) {
  m_voxels.wait();
  for (const Material& m : scene.medium.materials) {
    m_h.add(m.name.data(), m.name.size());
    m_h.add_spectrum(m.albedo);
    m_h.add_spectrum(m.sigma_t_per_unit);
    m_h.add_spectrum(m.anisotropy);
    if (m.emission.max_value() > 0.0) m_h.add_spectrum(m.emission);  // hashes of scenes without emission unchanged
    if (m.fluorescent) {  // likewise without fluorescence
      m_h.add_spectrum(m.fluorescence.absorption);
      m_h.add_spectrum(m.fluorescence.emission);
      m_h.add(&m.fluorescence.quantum_yield, sizeof m.fluorescence.quantum_yield);
    }
  }
  for (const Light& l : scene.lights)  // environment images (the scene text holds only their names)
    if (l.environment_map) m_h.add(l.environment_map->values().data(), l.environment_map->values().size() * sizeof(float));
  return m_h.hex();
}

}  // namespace prizma::render::scene_file
