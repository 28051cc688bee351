// Writes a real OpenVDB level set for tests/e2e/errors.cmake: openvdb::tools::createLevelSetSphere
// (radius 0.3 about the origin, voxels of 0.02, a narrow band of 3 voxels each side), grid class
// GRID_LEVEL_SET, named "density" so that only its class can be what the renderer refuses.
// Usage: prizma_test_make_level_set_vdb OUT.vdb
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: prizma_test_make_level_set_vdb OUT.vdb\n");
    return 2;
  }
  try {
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.3f, openvdb::Vec3f(0.0f), 0.02f, 3.0f);
    sphere->setName("density");
    openvdb::io::File file(argv[1]);
    file.write({sphere});
    file.close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "prizma_test_make_level_set_vdb: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
