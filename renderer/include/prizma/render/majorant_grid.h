#pragma once
// MajorantGrid: macrocells of kCellVoxels³ voxels over the medium, each holding an upper bound of the
// extinction σt(λ) inside it over every wavelength of the render (density × the material's largest
// σt in the bins' range; with trilinear interpolation, the largest σt that any value between the
// cell's and its neighbours' voxel values classifies to). Free-flight and transmittance sampling walk the cells with a 3-D DDA
// (Amanatides & Woo 1987), so cells whose majorant is 0 cost one step. With one cell it is the single
// global majorant (settings.use_majorant_grid = false).
//
// Each cell also holds the control of residual ratio tracking (Novák, Georgiev, Hanika, Jarosz
// 2014): where every point of the cell holds one material m with density ≥ d_c > 0, the control
// extinction is σc(λ) = d_c·σt_m(λ) per lane (the path's wavelengths), and the residual majorant
// μ̄r = (d_max − d_c)·max σt_m bounds σt − σc there; a homogeneous cell has μ̄r = 0.
//
// And its spectral bound, for spectral MIS's per-lane majorants (docs/renderer.md, "Spectral MIS"):
// where every non-empty point of the cell holds one material m at density ≤ d_max, lane i's majorant
// is d_max·σt_m(λ_i), exact at the path's own wavelengths and with no per-bin table (memory: 8 bytes
// per cell whatever the bin count); elsewhere every lane takes the cell's majorant.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "prizma/render/camera.h"
#include "prizma/render/scene.h"

namespace prizma::render {

// A cell's control: material kNone = no control (σc = 0 and residual = the cell's majorant).
struct CellControl {
  static constexpr std::uint16_t kNone = 0xffff;  // = Medium::kEmpty
  float residual = 0.0f;  // μ̄r ≥ σt − σc at every point of the cell and wavelength of the render
  float density = 0.0f;   // d_c: σc(λ) = d_c·σt_material(λ)
  std::uint16_t material = kNone;
};

// A cell's spectral bound: material kNone = none (the cell holds two materials, or none).
struct CellSpectralBound {
  static constexpr std::uint16_t kNone = 0xffff;  // = Medium::kEmpty
  float density_max = 0.0f;  // d_max ≥ the density at every point of the cell holding `material`
  std::uint16_t material = kNone;
};

class MajorantGrid {
 public:
  static constexpr int kCellVoxels = 8;

  MajorantGrid() = default;
  // sigma_t_max[m]: the largest σt per unit density of material m over the render's wavelengths.
  // cell_voxels ≤ 0 builds one cell over the whole box.
  MajorantGrid(const Medium& medium, const std::vector<float>& sigma_t_max, int cell_voxels = kCellVoxels);

  const std::array<int, 3>& cells() const { return m_cells; }
  float majorant(int cx, int cy, int cz) const {
    return m_majorant[(static_cast<std::size_t>(cz) * m_cells[1] + cy) * m_cells[0] + cx];
  }
  const CellControl& control(const std::array<int, 3>& c) const {
    return m_control[(static_cast<std::size_t>(c[2]) * m_cells[1] + c[1]) * m_cells[0] + c[0]];
  }
  const CellSpectralBound& spectral_bound(const std::array<int, 3>& c) const {
    return m_bound[(static_cast<std::size_t>(c[2]) * m_cells[1] + c[1]) * m_cells[0] + c[0]];
  }
  float max_majorant() const { return m_max; }
  const Eigen::Vector3d& bounds_min() const { return m_min; }
  const Eigen::Vector3d& bounds_max() const { return m_max_corner; }
  const Eigen::Vector3d& cell_size() const { return m_cell_size; }

 private:
  void build_trilinear(const Medium& medium, const std::vector<float>& sigma_t_max, const std::array<int, 3>& span);
  void build_from_blocks(const Medium& medium, const std::vector<float>& sigma_t_max, const std::array<int, 3>& span);
  void zero_clipped_cells(const Medium& medium);

  std::array<int, 3> m_cells{1, 1, 1};
  Eigen::Vector3d m_min{0, 0, 0}, m_max_corner{0, 0, 0}, m_cell_size{1, 1, 1};
  std::vector<float> m_majorant;
  std::vector<CellControl> m_control;
  std::vector<CellSpectralBound> m_bound;
  float m_max = 0.0f;
};

// Parametric interval [t_enter, t_exit] of a ray inside an axis-aligned box; false when it misses
// (or only touches it, or the box lies behind the origin).
bool intersect_box(const Ray& ray, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double& t_enter,
                   double& t_exit);

// Walks the cells a ray segment [t_min, t_max] crosses, in order: next() gives each cell's
// [t0, t1] and majorant. The ray must start inside or enter the grid's box within the segment.
class MajorantTraversal {
 public:
  MajorantTraversal(const MajorantGrid& grid, const Ray& ray, double t_min, double t_max);
  struct Segment {
    double t0, t1;
    float majorant;
    std::array<int, 3> cell;
  };
  // False when the segment is exhausted.
  bool next(Segment& seg);

 private:
  const MajorantGrid* m_grid;
  double m_t = 0, m_t_max = 0;
  std::array<int, 3> m_cell{0, 0, 0}, m_step{0, 0, 0};
  std::array<double, 3> m_next_t{0, 0, 0}, m_delta_t{0, 0, 0};
  bool m_done = true;
};

}  // namespace prizma::render
