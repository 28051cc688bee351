#pragma once
// The C interface of the VDB module libprizma_vdb.so (vdb/vdb_module.cpp), the only code that links
// OpenVDB: Debian's libopenvdb brings log4cplus, Blosc, Boost.Iostreams and four compressors (22
// libraries and 34 MB resident for `prizma-render --version` when it was linked). The renderer loads
// the module the first time a "vdb" volume is read (load_vdb_volume, renderer/src/volume_vdb.cpp),
// looked for as every module is (prizma/spectral/module_loader.h; $PRIZMA_VDB_MODULE first).
// Plain C types only, and no exception ever crosses it: every call returns a status and, when it
// fails, one line in `message` (always NUL-terminated, cut to message_size).
#include <stddef.h>

extern "C" {

#define PRIZMA_VDB_ABI_VERSION 2  // 2: PrizmaVdbGridInfo::warnings
#define PRIZMA_VDB_ENTRY_POINT "prizma_vdb_module_v1"

enum PrizmaVdbStatus {
  PRIZMA_VDB_OK = 0,
  PRIZMA_VDB_BAD_FILE = 1,       // the file: not readable as OpenVDB (damaged, truncated, sizes no valid
                                 // file of its length holds), or no grid of that name (input error)
  PRIZMA_VDB_BAD_GRID = 2,       // the grid: not float, a level set, empty, a transform that is not
                                 // axis-aligned (input error)
  PRIZMA_VDB_OUT_OF_MEMORY = 3,  // an allocation failed
  PRIZMA_VDB_FAILED = 4          // anything else (run-time failure)
};

typedef struct PrizmaVdbGrid PrizmaVdbGrid;  // a float grid read into memory

struct PrizmaVdbGridInfo {
  int dims[3];           // voxels of the active bounding box (index space), x, y, z
  double voxel_size[3];  // from the grid's linear transform, > 0 and finite
  // What OpenVDB logged while it read the file (it still read it: e.g. an unknown format version),
  // one message per line without colours, NUL-terminated; empty when it logged nothing.
  char warnings[1024];
};

struct PrizmaVdbModule {
  int abi_version;  // PRIZMA_VDB_ABI_VERSION
  // Reads the float grid `grid` of the file `path` (not delayed: the file is closed on return).
  // On PRIZMA_VDB_OK *out holds it (close_grid frees it) and *info describes it.
  int (*open_grid)(const char* path, const char* grid, PrizmaVdbGrid** out, struct PrizmaVdbGridInfo* info,
                   char* message, size_t message_size);
  // Writes the active bounding box densely into `values` (dims[0]·dims[1]·dims[2] floats, x fastest).
  int (*copy_dense)(const PrizmaVdbGrid* grid, float* values, char* message, size_t message_size);
  // The value range [lo, hi] per block of block_voxels³ voxels (blocks aligned with the box's first
  // voxel, x fastest; 2 floats per block, ⌈dims/block_voxels⌉ blocks per axis) that a point of the
  // block can interpolate between: every leaf voxel, tile and the background widens the range of the
  // blocks whose stencil (voxels c·B − 1 … c·B + B) it meets; lo > hi: no finite value there.
  int (*block_ranges)(const PrizmaVdbGrid* grid, int block_voxels, float* ranges, char* message,
                      size_t message_size);
  void (*close_grid)(PrizmaVdbGrid* grid);
};

// The module's one export.
typedef const struct PrizmaVdbModule* (*PrizmaVdbEntry)(void);

}  // extern "C"
