// Writes data/scenes/cloud.vdb, the example OpenVDB volume of data/scenes/cloud_vdb.json, through
// libopenvdb: a float grid "density" of blobby smoke around a hot core, 40³ voxels of 0.025 units
// at most, only voxels with density > 0.01 active (the rest is the background 0 and never stored).
// Deterministic (a fixed linear congruential generator; only the UUID OpenVDB puts in the file header differs between runs). Usage: prizma-make-cloud-vdb OUT.vdb
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <vector>

namespace {

struct Blob {
  double x, y, z, radius, weight;
};

// Numerical Recipes' LCG: a fixed sequence in [0, 1) on every platform.
double next_unit(std::uint32_t& state) {
  state = state * 1664525u + 1013904223u;
  return static_cast<double>(state >> 8) / 16777216.0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: prizma-make-cloud-vdb OUT.vdb\n");
    return 2;
  }
  try {
    openvdb::initialize();
    // Smoke: blobs scattered around the centre; the core: one dense blob whose values pass 0.75.
    std::vector<Blob> blobs;
    std::uint32_t state = 13;
    for (int i = 0; i < 14; ++i) {
      const double r = 0.12 + 0.1 * next_unit(state);
      blobs.push_back({0.5 + 0.5 * (next_unit(state) - 0.5), 0.45 + 0.45 * (next_unit(state) - 0.5),
                       0.5 + 0.5 * (next_unit(state) - 0.5), r, 0.5 + 0.3 * next_unit(state)});
    }
    blobs.push_back({0.5, 0.38, 0.5, 0.16, 1.1});
    constexpr int kN = 40;
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0 / kN));
    auto acc = grid->getAccessor();
    for (int z = 0; z < kN; ++z)
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          const double p[3] = {(x + 0.5) / kN, (y + 0.5) / kN, (z + 0.5) / kN};
          double d = 0.0;
          for (const Blob& b : blobs) {
            const double dx = p[0] - b.x, dy = p[1] - b.y, dz = p[2] - b.z;
            const double q = (dx * dx + dy * dy + dz * dz) / (b.radius * b.radius);
            if (q < 1.0) d += b.weight * (1.0 - q) * (1.0 - q);  // smooth, compact kernel
          }
          d = std::min(d, 1.0);
          if (d > 0.01) acc.setValue(openvdb::Coord(x, y, z), static_cast<float>(d));
        }
    grid->setSaveFloatAsHalf(true);  // a smaller file; values are read back as float
    openvdb::io::File file(argv[1]);
    const openvdb::GridPtrVec grids{grid};
    file.write(grids);
    file.close();
    std::printf("%s: %llu active voxels\n", argv[1], static_cast<unsigned long long>(grid->activeVoxelCount()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "prizma-make-cloud-vdb: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
