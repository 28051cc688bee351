#include "scene_hash.h"

namespace prizma::render::scene_file {

namespace {

// A spectrum as the hash has always taken it: its constant (0 when tabulated), wavelengths, values.
void add_spectrum(spectral::Fnv1a& h, const spectral::Spectrum& s) {
  const double c = s.is_constant() ? s.eval(0.0) : 0.0;
  h.add_bytes(&c, sizeof c);
  h.add_bytes(s.wavelengths_nm().data(), s.wavelengths_nm().size() * sizeof(double));
  h.add_bytes(s.values().data(), s.values().size() * sizeof(double));
}

}  // namespace

SceneHash::SceneHash(const std::string& text, const std::vector<SceneOverride>& overrides, const Volume& vol) {
  m_h.add_bytes(text.data(), text.size());
  for (const SceneOverride& o : overrides) {  // a render with -D is not the file's render (--resume checks)
    const std::string d = "\n-D " + o.key + "=" + o.value;
    m_h.add_bytes(d.data(), d.size());
  }
  m_h.add_bytes(vol.dims.data(), sizeof vol.dims);
  m_h.add_bytes(vol.spacing.data(), sizeof vol.spacing);
  m_voxels.run([this, &vol] { m_h.add_bytes(vol.values.data(), vol.values.size() * sizeof(float)); });
}

SceneHash::~SceneHash() { m_voxels.wait(); }

std::string SceneHash::finish(const Scene& scene) {
  m_voxels.wait();
  for (const Material& m : scene.medium.materials) {
    m_h.add_bytes(m.name.data(), m.name.size());
    add_spectrum(m_h, m.albedo);
    add_spectrum(m_h, m.sigma_t_per_unit);
    add_spectrum(m_h, m.anisotropy);
    if (m.emission.max_value() > 0.0) add_spectrum(m_h, m.emission);  // hashes of scenes without emission unchanged
    if (m.fluorescent) {  // likewise without fluorescence
      add_spectrum(m_h, m.fluorescence.absorption);
      add_spectrum(m_h, m.fluorescence.emission);
      m_h.add_bytes(&m.fluorescence.quantum_yield, sizeof m.fluorescence.quantum_yield);
    }
  }
  for (const Light& l : scene.lights)  // environment images (the scene text holds only their names)
    if (l.environment_map) m_h.add_bytes(l.environment_map->values().data(), l.environment_map->values().size() * sizeof(float));
  return m_h.hex();
}

}  // namespace prizma::render::scene_file
