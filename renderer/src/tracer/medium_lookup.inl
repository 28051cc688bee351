// PathTracer, the medium at a point: its material and density (nearest voxel, or trilinear
// interpolation of the values then post-classification), clip planes applied. Part of
// path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

void PathTracer::lookup(const Eigen::Vector3d& p, std::uint16_t& material, float& density) const {
  const Medium& med = *m_medium;
  if (!med.clip.empty() && med.clipped(p)) {  // cut away: empty, so a null collision (unbiased)
    material = Medium::kEmpty;
    density = 0.0f;
    return;
  }
  if (m_trilinear) {
    classify(interpolate(p), material, density);
    return;
  }
  int idx[3];
  for (int a = 0; a < 3; ++a)
    idx[a] = std::clamp(static_cast<int>((p[a] - med.bounds_min[a]) * m_inv_voxel[a]), 0, med.dims[a] - 1);
  const std::size_t v = (static_cast<std::size_t>(idx[2]) * med.dims[1] + idx[1]) * med.dims[0] + idx[0];
  material = med.material[v];
  density = med.density[v];
}

float PathTracer::interpolate(const Eigen::Vector3d& p) const {
  // Trilinear between voxel centres (voxel i's centre at continuous coordinate i + 0.5), clamped to
  // the edge voxels within half a voxel of the box's faces. A point whose eight voxels include a
  // non-finite value is empty (NaN). The result is clamped to the eight values' range so that the
  // majorant grid's bound over that range holds exactly, float rounding included.
  const Medium& med = *m_medium;
  int i0[3], i1[3];
  float f[3];
  for (int a = 0; a < 3; ++a) {
    const double x = (p[a] - med.bounds_min[a]) * m_inv_voxel[a] - 0.5;
    const double fl = std::floor(x);
    f[a] = static_cast<float>(x - fl);
    const int i = static_cast<int>(fl);
    i0[a] = std::clamp(i, 0, med.dims[a] - 1);
    i1[a] = std::clamp(i + 1, 0, med.dims[a] - 1);
  }
  const std::size_t nx = static_cast<std::size_t>(med.dims[0]), nxy = nx * med.dims[1];
  const float* v = med.value.data();
  auto at = [&](int x, int y, int z) { return v[static_cast<std::size_t>(z) * nxy + static_cast<std::size_t>(y) * nx + x]; };
  const float c000 = at(i0[0], i0[1], i0[2]), c100 = at(i1[0], i0[1], i0[2]);
  const float c010 = at(i0[0], i1[1], i0[2]), c110 = at(i1[0], i1[1], i0[2]);
  const float c001 = at(i0[0], i0[1], i1[2]), c101 = at(i1[0], i0[1], i1[2]);
  const float c011 = at(i0[0], i1[1], i1[2]), c111 = at(i1[0], i1[1], i1[2]);
  const float lo = std::min({c000, c100, c010, c110, c001, c101, c011, c111});
  const float hi = std::max({c000, c100, c010, c110, c001, c101, c011, c111});
  if (!std::isfinite(lo) || !std::isfinite(hi) ||
      !std::isfinite(c000 + c100 + c010 + c110 + c001 + c101 + c011 + c111))
    return std::numeric_limits<float>::quiet_NaN();
  const float x00 = c000 + f[0] * (c100 - c000), x10 = c010 + f[0] * (c110 - c010);
  const float x01 = c001 + f[0] * (c101 - c001), x11 = c011 + f[0] * (c111 - c011);
  const float y0 = x00 + f[1] * (x10 - x00), y1 = x01 + f[1] * (x11 - x01);
  return std::clamp(y0 + f[2] * (y1 - y0), lo, hi);
}

void PathTracer::classify(float value, std::uint16_t& material, float& density) const {
  // Post-classification, exactly as build_medium classifies a voxel: the first rule whose range
  // holds the value, its density ramp at the value; empty when none matches or the density is 0.
  material = Medium::kEmpty;
  density = 0.0f;
  if (!std::isfinite(value)) return;
  const double v = value;
  for (const MaterialRule& r : m_medium->rules) {
    if (v >= r.value_lo && v <= r.value_hi) {
      const auto d = static_cast<float>(r.density.eval(v));
      if (d > 0.0f) {
        material = static_cast<std::uint16_t>(r.material);
        density = d;
      }
      return;
    }
  }
}

}  // namespace prizma::render
