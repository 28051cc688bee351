#include "prizma/render/majorant_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "prizma/render/volume.h"

namespace prizma::render {

namespace {
float majorant_over_values(const Medium& medium, const std::vector<float>& sigma_t_max, float v_lo, float v_hi);
CellControl control_over_values(const Medium& medium, const std::vector<float>& sigma_t_max, float v_lo, float v_hi);
CellSpectralBound bound_over_values(const Medium& medium, float v_lo, float v_hi);

// μ̄r for a cell of one material whose densities lie in [d_c, d_max]: at a point of density d the
// tracer computes (d − d_c)·σt(λ) in float, at most (d_max − d_c)·σt_max by monotone rounding; one
// float ulp up as the majorants (0 stays 0: a homogeneous cell takes no steps).
float residual_majorant(float d_c, float d_max, float sigma_t_max) {
  const float r = (d_max - d_c) * sigma_t_max;
  return r > 0.0f ? std::nextafter(r, std::numeric_limits<float>::infinity()) : 0.0f;
}

// Runs body(cy, cz) for every row of cells (a y, z pair; the x cells of a row are the body's), rows
// in parallel. Every cell's majorant is computed from the volume alone and written by the one task
// that owns its row, so the grid is the same whatever the thread count.
template <class Body>
void for_each_cell_row(const std::array<int, 3>& cells, Body&& body) {
  const int rows = cells[1] * cells[2];
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& r) {
    for (int row = r.begin(); row != r.end(); ++row) body(row % cells[1], row / cells[1]);
  });
}
}  // namespace

MajorantGrid::MajorantGrid(const Medium& medium, const std::vector<float>& sigma_t_max, int cell_voxels)
    : m_min(medium.bounds_min), m_max_corner(medium.bounds_max) {
  const auto& d = medium.dims;
  for (int a = 0; a < 3; ++a) m_cells[a] = cell_voxels > 0 ? (d[a] + cell_voxels - 1) / cell_voxels : 1;
  // Cells are aligned with voxel boundaries, so a cell's majorant bounds exactly the voxels it holds;
  // the last cell along an axis may hold fewer voxels and extends only to the box's edge.
  std::array<int, 3> span{};
  for (int a = 0; a < 3; ++a) {
    span[a] = cell_voxels > 0 ? cell_voxels : d[a];
    const double voxel = (m_max_corner[a] - m_min[a]) / d[a];
    m_cell_size[a] = voxel * span[a];
  }
  m_majorant.assign(static_cast<std::size_t>(m_cells[0]) * m_cells[1] * m_cells[2], 0.0f);
  m_control.assign(m_majorant.size(), CellControl{});
  m_bound.assign(m_majorant.size(), CellSpectralBound{});
  bool blocks_fit = !medium.block_range.empty();
  for (int a = 0; a < 3; ++a) blocks_fit = blocks_fit && (span[a] % Volume::kBlockVoxels == 0 || m_cells[a] == 1);
  if (blocks_fit) {
    build_from_blocks(medium, sigma_t_max, span);
  } else if (medium.interpolation == Interpolation::Trilinear) {
    build_trilinear(medium, sigma_t_max, span);
  } else {
    for_each_cell_row(m_cells, [&](int cy, int cz) {
      const int z1 = std::min(d[2], (cz + 1) * span[2]), y1 = std::min(d[1], (cy + 1) * span[1]);
      const std::size_t row0 = (static_cast<std::size_t>(cz) * m_cells[1] + cy) * m_cells[0];
      float* row = m_majorant.data() + row0;
      // Per cell of the row: its one material (kNone until a voxel is seen; `mixed` once a second
      // material or an empty voxel is; `two` once a second material is: no spectral bound), and its
      // least and largest density.
      std::vector<CellControl> ctl(static_cast<std::size_t>(m_cells[0]));
      std::vector<float> d_max(ctl.size(), 0.0f);
      std::vector<char> mixed(ctl.size(), 0), two(ctl.size(), 0);
      for (auto& c : ctl) c.density = std::numeric_limits<float>::infinity();
      for (int z = cz * span[2]; z < z1; ++z)
        for (int y = cy * span[1]; y < y1; ++y)
          for (int x = 0; x < d[0]; ++x) {
            const std::size_t v = (static_cast<std::size_t>(z) * d[1] + y) * d[0] + x;
            const std::uint16_t m = medium.material[v];
            const int cx = x / span[0];
            const float dv = medium.density[v];
            if (m == Medium::kEmpty || !(dv > 0.0f)) {  // empty space: σt = 0, no positive control
              mixed[cx] = 1;
              continue;
            }
            float& cell = row[cx];
            cell = std::max(cell, dv * sigma_t_max[m]);
            CellControl& c = ctl[cx];
            if (c.material != m && c.material != CellControl::kNone) mixed[cx] = two[cx] = 1;
            c.material = m;
            c.density = std::min(c.density, dv);
            d_max[cx] = std::max(d_max[cx], dv);
          }
      for (std::size_t cx = 0; cx < ctl.size(); ++cx) {
        if (!two[cx] && ctl[cx].material != CellControl::kNone)  // every voxel's d·σt ≤ d_max·σt exactly
          m_bound[row0 + cx] = CellSpectralBound{d_max[cx], ctl[cx].material};
        if (mixed[cx] || ctl[cx].material == CellControl::kNone) continue;
        ctl[cx].residual = residual_majorant(ctl[cx].density, d_max[cx], sigma_t_max[ctl[cx].material]);
        m_control[row0 + cx] = ctl[cx];
      }
    });
  }
  if (!medium.clip.empty()) zero_clipped_cells(medium);
  for (float mu : m_majorant) m_max = std::max(m_max, mu);
  // Cells without a control: plain ratio tracking against the majorant.
  for (std::size_t k = 0; k < m_control.size(); ++k)
    if (m_control[k].material == CellControl::kNone) m_control[k].residual = m_majorant[k];
}

namespace {

// The largest σt that any value in [v_lo, v_hi] classifies to: for every rule whose range meets it,
// its ramp's largest density there × the material's largest σt (plus one float ulp: the tracer
// evaluates the ramp at the point in double and rounds).
float majorant_over_values(const Medium& medium, const std::vector<float>& sigma_t_max, float v_lo, float v_hi) {
  if (!(v_lo <= v_hi)) return 0.0f;
  float mu = 0.0f;
  for (const MaterialRule& r : medium.rules) {
    const double a = std::max<double>(r.value_lo, v_lo), b = std::min<double>(r.value_hi, v_hi);
    if (!(a <= b)) continue;
    const auto dmax = static_cast<float>(r.density.max_over(a, b));
    mu = std::max(mu, dmax * sigma_t_max[static_cast<std::size_t>(r.material)]);
  }
  if (mu > 0.0f) mu = std::nextafter(mu, std::numeric_limits<float>::infinity());
  return mu;
}

// The control of a cell whose points take values in [v_lo, v_hi] (finite): when the first rule
// that meets the range holds all of it (so every point classifies to its material) and its ramp's
// least density there is > 0, d_c is that least density (the tracer's float of the ramp's double,
// which rounding keeps ≥ float(least)); otherwise none.
CellControl control_over_values(const Medium& medium, const std::vector<float>& sigma_t_max, float v_lo, float v_hi) {
  CellControl c;
  if (!(v_lo <= v_hi)) return c;
  for (const MaterialRule& r : medium.rules) {
    if (!(std::max<double>(r.value_lo, v_lo) <= std::min<double>(r.value_hi, v_hi))) continue;
    if (!(r.value_lo <= v_lo && v_hi <= r.value_hi)) return c;
    const auto d_c = static_cast<float>(r.density.min_over(v_lo, v_hi));
    if (!(d_c > 0.0f)) return c;
    const auto d_max = static_cast<float>(r.density.max_over(v_lo, v_hi));
    c.material = static_cast<std::uint16_t>(r.material);
    c.density = d_c;
    c.residual = residual_majorant(d_c, d_max, sigma_t_max[static_cast<std::size_t>(r.material)]);
    return c;
  }
  return c;
}

// The spectral bound of a cell whose points take values in [v_lo, v_hi]: when every rule that meets
// the range names one material (so every point classifies to it or to empty space), that material
// and the largest density of those rules' ramps there, one float ulp up (the tracer evaluates the
// ramp at the point in double and rounds, as for the majorant); otherwise none.
CellSpectralBound bound_over_values(const Medium& medium, float v_lo, float v_hi) {
  CellSpectralBound b;
  if (!(v_lo <= v_hi)) return b;
  float d_max = 0.0f;
  for (const MaterialRule& r : medium.rules) {
    const double a = std::max<double>(r.value_lo, v_lo), z = std::min<double>(r.value_hi, v_hi);
    if (!(a <= z)) continue;
    const auto m = static_cast<std::uint16_t>(r.material);
    if (b.material != CellSpectralBound::kNone && b.material != m) return CellSpectralBound{};
    b.material = m;
    d_max = std::max(d_max, static_cast<float>(r.density.max_over(a, z)));
  }
  if (b.material == CellSpectralBound::kNone || !(d_max > 0.0f)) return CellSpectralBound{};
  b.density_max = std::nextafter(d_max, std::numeric_limits<float>::infinity());
  return b;
}

}  // namespace

void MajorantGrid::build_from_blocks(const Medium& medium, const std::vector<float>& sigma_t_max,
                                     const std::array<int, 3>& span) {
  // A sparse volume (OpenVDB) gives each block of kBlockVoxels³ voxels the range of values its points
  // interpolate between, neighbours included, from the tree's nodes; a cell is a union of whole blocks.
  // The bound over a value range holds for nearest lookups too (a voxel's value lies in its block's
  // range), so both interpolations use it.
  constexpr int kB = Volume::kBlockVoxels;
  std::array<int, 3> nb{};
  for (int a = 0; a < 3; ++a) nb[a] = (medium.dims[a] + kB - 1) / kB;
  for_each_cell_row(m_cells, [&](int cy, int cz) {
      for (int cx = 0; cx < m_cells[0]; ++cx) {
        const int c[3] = {cx, cy, cz};
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          lo[a] = m_cells[a] == 1 ? 0 : c[a] * span[a] / kB;
          hi[a] = m_cells[a] == 1 ? nb[a] - 1 : std::min(nb[a] - 1, (c[a] + 1) * span[a] / kB - 1);
        }
        float v_lo = std::numeric_limits<float>::infinity(), v_hi = -v_lo;
        for (int z = lo[2]; z <= hi[2]; ++z)
          for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
              const auto& r = medium.block_range[(static_cast<std::size_t>(z) * nb[1] + y) * nb[0] + x];
              v_lo = std::min(v_lo, r[0]);
              v_hi = std::max(v_hi, r[1]);
            }
        const std::size_t k = (static_cast<std::size_t>(cz) * m_cells[1] + cy) * m_cells[0] + cx;
        m_majorant[k] = majorant_over_values(medium, sigma_t_max, v_lo, v_hi);
        m_bound[k] = bound_over_values(medium, v_lo, v_hi);
      }
  });
}

void MajorantGrid::zero_clipped_cells(const Medium& medium) {
  // A cell whose every corner lies on the removed side of one clip plane holds no medium (the side
  // is a half-space, so the whole box does): its majorant 0 stays a bound and costs one DDA step.
  // A cell that some plane cuts holds empty points, so it keeps no control.
  for_each_cell_row(m_cells, [&](int cy, int cz) {
      for (int cx = 0; cx < m_cells[0]; ++cx) {
        const std::size_t k = (static_cast<std::size_t>(cz) * m_cells[1] + cy) * m_cells[0] + cx;
        const Eigen::Vector3d lo = m_min + Eigen::Vector3d(cx, cy, cz).cwiseProduct(m_cell_size);
        const Eigen::Vector3d hi = lo + m_cell_size;
        for (const ClipPlane& p : medium.clip) {
          // The box's corners with the least and the largest dot(normal, ·).
          double least = 0.0, largest = 0.0;
          for (int a = 0; a < 3; ++a) {
            least += p.normal[a] * (p.normal[a] >= 0.0 ? lo[a] : hi[a]);
            largest += p.normal[a] * (p.normal[a] >= 0.0 ? hi[a] : lo[a]);
          }
          if (largest > p.offset) m_control[k] = CellControl{};
          if (least > p.offset) {
            m_majorant[k] = 0.0f;
            break;
          }
        }
      }
  });
}

void MajorantGrid::build_trilinear(const Medium& medium, const std::vector<float>& sigma_t_max,
                                   const std::array<int, 3>& span) {
  // A point of cell c lies between voxel centres whose indices run from c·span − 1 to c·span + span
  // (clamped to the volume), and its interpolated value lies between the least and the largest of
  // those voxels' values (the tracer clamps it so, against float rounding). The classification of a
  // value is not monotone (a bright voxel beside a dark one passes through every material between
  // them), so the bound is the largest σt over that whole value range: for every rule whose range
  // meets [v_lo, v_hi], its ramp's largest density there × the material's largest σt.
  const auto& d = medium.dims;
  for_each_cell_row(m_cells, [&](int cy, int cz) {
      for (int cx = 0; cx < m_cells[0]; ++cx) {
        const int c[3] = {cx, cy, cz};
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::max(0, c[a] * span[a] - 1);
          hi[a] = std::min(d[a] - 1, c[a] * span[a] + span[a]);
        }
        float v_lo = std::numeric_limits<float>::infinity(), v_hi = -v_lo;
        bool any_empty = false;
        for (int z = lo[2]; z <= hi[2]; ++z)
          for (int y = lo[1]; y <= hi[1]; ++y) {
            const float* row = medium.value.data() + (static_cast<std::size_t>(z) * d[1] + y) * d[0];
            for (int x = lo[0]; x <= hi[0]; ++x) {
              if (!std::isfinite(row[x])) {  // a point touching it is empty space
                any_empty = true;
                continue;
              }
              v_lo = std::min(v_lo, row[x]);
              v_hi = std::max(v_hi, row[x]);
            }
          }
        const std::size_t k = (static_cast<std::size_t>(cz) * m_cells[1] + cy) * m_cells[0] + cx;
        m_majorant[k] = majorant_over_values(medium, sigma_t_max, v_lo, v_hi);
        m_bound[k] = bound_over_values(medium, v_lo, v_hi);  // empty points (any_empty) stay below any bound
        if (!any_empty) m_control[k] = control_over_values(medium, sigma_t_max, v_lo, v_hi);
      }
  });
}

bool intersect_box(const Ray& ray, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double& t_enter,
                   double& t_exit) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double inv = 1.0 / ray.direction[a];
    double ta = (lo[a] - ray.origin[a]) * inv;
    double tb = (hi[a] - ray.origin[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    // A ray parallel to a slab: inside gives (−inf, inf), outside (inf, inf) or NaN on the plane.
    if (std::isnan(ta) || std::isnan(tb)) {
      if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return false;
      continue;
    }
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  t_enter = t0;
  t_exit = t1;
  return t1 > t0;
}

MajorantTraversal::MajorantTraversal(const MajorantGrid& grid, const Ray& ray, double t_min, double t_max)
    : m_grid(&grid), m_t(t_min), m_t_max(t_max) {
  if (!(t_max > t_min)) return;
  m_done = false;
  const double t_mid = t_min + 1e-9 * (t_max - t_min);
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    const double cs = grid.cell_size()[a], lo = grid.bounds_min()[a];
    const int n = grid.cells()[a];
    m_cell[a] = std::clamp(static_cast<int>(std::floor((o + t_mid * d - lo) / cs)), 0, n - 1);
    if (d > 0) {
      m_step[a] = 1;
      m_next_t[a] = (lo + (m_cell[a] + 1) * cs - o) / d;
      m_delta_t[a] = cs / d;
    } else if (d < 0) {
      m_step[a] = -1;
      m_next_t[a] = (lo + m_cell[a] * cs - o) / d;
      m_delta_t[a] = -cs / d;
    } else {
      m_step[a] = 0;
      m_next_t[a] = std::numeric_limits<double>::infinity();
      m_delta_t[a] = 0;
    }
  }
}

bool MajorantTraversal::next(Segment& seg) {
  if (m_done) return false;
  int axis = 0;
  if (m_next_t[1] < m_next_t[axis]) axis = 1;
  if (m_next_t[2] < m_next_t[axis]) axis = 2;
  const double t1 = std::min(m_next_t[axis], m_t_max);
  seg.t0 = m_t;
  seg.t1 = t1;
  seg.cell = m_cell;
  seg.majorant = m_grid->majorant(m_cell[0], m_cell[1], m_cell[2]);
  m_t = t1;
  if (m_next_t[axis] >= m_t_max) {
    m_done = true;
  } else {
    m_cell[axis] += m_step[axis];
    m_next_t[axis] += m_delta_t[axis];
    if (m_cell[axis] < 0 || m_cell[axis] >= m_grid->cells()[axis]) m_done = true;
  }
  return true;
}

}  // namespace prizma::render
