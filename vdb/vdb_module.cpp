// libprizma_vdb.so: OpenVDB volumes through Debian's libopenvdb, behind the C interface of
// renderer/include/prizma/render/vdb_module.h. One float grid, densified over the bounding box of its
// active voxels for the tracer's lookups, with the majorant's per-block value ranges taken from the
// tree's leaf nodes and tiles, so that the empty space between them is never visited.
#include <openvdb/io/Archive.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <sys/resource.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <ios>
#include <iostream>
#include <limits>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>

#include "prizma/render/vdb_module.h"

struct PrizmaVdbGrid {
  openvdb::FloatGrid::Ptr grid;
  openvdb::CoordBBox box;  // active voxels' bounding box, index space
};

namespace {

// A failure with its status, thrown inside the module only (never across the C interface).
struct Failure {
  int status;
  std::string message;
};

void put_message(const std::string& text, char* message, std::size_t size) {
  if (message == nullptr || size == 0) return;
  std::snprintf(message, size, "%s", text.c_str());
}

// A valid OpenVDB file needs at most about 40 bytes of memory per byte of file: a node's masks and
// compressed values expand into its table of 8-byte entries (32 KiB from 1 KiB of masks for a 16³
// internal node, 256 KiB from 8 KiB for a 32³ one), a leaf's ~2.2 KiB from at least ~70 bytes. When
// reading fails for memory and 64 bytes per file byte (and some slack) can still be had, the
// allocation that failed was for a size read from damaged bytes: bad input, not a shortage.
constexpr std::uintmax_t kMaxBytesPerFileByte = 64;
constexpr std::uintmax_t kMemorySlack = std::uintmax_t{64} << 20;

// The file's size in bytes when everything a valid file of that size needs can be allocated now;
// 0 otherwise (a real shortage, or the size is unknown).
std::uintmax_t size_if_memory_suffices(const char* path) {
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec || bytes > (std::numeric_limits<std::size_t>::max() - kMemorySlack) / kMaxBytesPerFileByte) return 0;
  void* volatile probe = std::malloc(static_cast<std::size_t>(bytes * kMaxBytesPerFileByte + kMemorySlack));
  const bool fits = probe != nullptr;
  std::free(probe);
  return fits ? bytes : 0;
}

// While a file is read, the address space may grow by at most what a valid file of its size needs
// (kMaxBytesPerFileByte per byte), plus room for the library's threads and buffers: a damaged size
// that asks for gigabytes then fails at once as std::bad_alloc (a bad file, below) instead of being
// granted by the kernel's overcommit and then written for minutes, or filling the machine's memory
// (one changed byte in data/scenes/cloud.vdb did that). The limit is the process's (RLIMIT_AS),
// lowered for the read only: the renderer reads its volume before any other work starts. Not in
// sanitizer builds, whose runtimes reserve terabytes of address space.
#if defined(__SANITIZE_ADDRESS__)
#define PRIZMA_VDB_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PRIZMA_VDB_SANITIZED 1
#endif
#endif

class ReadMemoryBound {
 public:
  explicit ReadMemoryBound([[maybe_unused]] const char* path) {
#ifndef PRIZMA_VDB_SANITIZED
    std::error_code ec;
    const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
    const std::uintmax_t in_use = address_space_in_use();
    if (ec || in_use == 0 || ::getrlimit(RLIMIT_AS, &m_saved) != 0) return;
    // Each worker thread the library may start reserves a stack (8 MiB by default).
    const std::uintmax_t room = (std::uintmax_t{1} << 30) + std::uintmax_t{16 << 20} * std::thread::hardware_concurrency();
    if (file_bytes > (std::numeric_limits<rlim_t>::max() - in_use - room) / kMaxBytesPerFileByte) return;
    const rlim_t budget = static_cast<rlim_t>(in_use + room + file_bytes * kMaxBytesPerFileByte);
    if (m_saved.rlim_cur != RLIM_INFINITY && m_saved.rlim_cur <= budget) return;  // already tighter
    rlimit bound = m_saved;
    bound.rlim_cur = budget;
    m_lowered = ::setrlimit(RLIMIT_AS, &bound) == 0;
#endif
  }
  ~ReadMemoryBound() {
    if (m_lowered) ::setrlimit(RLIMIT_AS, &m_saved);
  }
  ReadMemoryBound(const ReadMemoryBound&) = delete;
  ReadMemoryBound& operator=(const ReadMemoryBound&) = delete;

 private:
  // The process's address space in bytes (/proc/self/statm, first field in pages); 0 when unknown.
  static std::uintmax_t address_space_in_use() {
    std::ifstream statm("/proc/self/statm");
    std::uintmax_t pages = 0;
    if (!(statm >> pages)) return 0;
    return pages * static_cast<std::uintmax_t>(::sysconf(_SC_PAGESIZE));
  }
  rlimit m_saved{};
  bool m_lowered = false;
};

// Where an exception comes from: reading the file (whatever OpenVDB throws there is about the file's
// bytes, a bad_alloc included when memory is plentiful), or working on a grid already in memory.
enum class Stage { ReadingFile, InMemory };

// Runs `body`, mapping every exception to a status and one line of message.
template <class Body>
int guarded(const char* path, Stage stage, char* message, std::size_t size, Body&& body) {
  const bool reading = stage == Stage::ReadingFile;
  const auto bad_file = [&](const std::string& why) {
    put_message("not a readable OpenVDB file (" + why + ")", message, size);
    return PRIZMA_VDB_BAD_FILE;
  };
  const auto failed = [&](const std::string& why) {
    put_message(why, message, size);
    return PRIZMA_VDB_FAILED;
  };
  try {
    body();
    return PRIZMA_VDB_OK;
  } catch (const Failure& f) {
    put_message(f.message, message, size);
    return f.status;
  } catch (const std::bad_alloc&) {
    if (const std::uintmax_t bytes = reading ? size_if_memory_suffices(path) : 0; bytes > 0) {
      return bad_file("corrupt: a size in it asks for more memory than any valid file of " + std::to_string(bytes) +
                      " bytes needs");
    }
    put_message("out of memory", message, size);
    return PRIZMA_VDB_OUT_OF_MEMORY;
  } catch (const openvdb::Exception& e) {
    return reading ? bad_file(e.what()) : failed(e.what());
  } catch (const std::ios_base::failure& e) {
    return reading ? bad_file(e.what()) : failed(e.what());
  } catch (const std::system_error& e) {  // a thread that could not start: not the file's fault
    return failed(e.what());
  } catch (const std::exception& e) {  // std::length_error from a damaged size, …
    return reading ? bad_file(e.what()) : failed(e.what());
  } catch (...) {
    return failed("unknown error in the VDB module");
  }
}

// OpenVDB logs what it notices in a file it still reads (an unknown format version, a multi-buffer
// tree): libopenvdb's own code through log4cplus, whose console appender writes to std::cout in
// colour, and its header code compiled here (without log4cplus) to std::cerr as "WARNING: …". While a
// file is read both streams write into a buffer instead, and the messages go back to the renderer,
// which reports them as its own warnings. Only for the read: the renderer reads volumes on one thread.
class LibraryLogCapture {
 public:
  LibraryLogCapture() : m_out(std::cout.rdbuf(m_text.rdbuf())), m_err(std::cerr.rdbuf(m_text.rdbuf())) {}
  ~LibraryLogCapture() { restore(); }
  LibraryLogCapture(const LibraryLogCapture&) = delete;
  LibraryLogCapture& operator=(const LibraryLogCapture&) = delete;

  // The messages, one per line, without colour codes, level prefixes or blank lines.
  std::string finish() {
    restore();
    const std::string text = m_text.str();
    std::string lines, line;
    for (std::size_t i = 0; i <= text.size(); ++i) {
      if (i < text.size() && text[i] == '\x1b') {  // an ANSI sequence: ESC [ parameters letter
        while (i + 1 < text.size() && !std::isalpha(static_cast<unsigned char>(text[i + 1]))) ++i;
        ++i;
        continue;
      }
      if (i < text.size() && text[i] != '\n' && text[i] != '\r') {
        line += text[i];
        continue;
      }
      const std::size_t start = line.find_first_not_of(' ');
      line = start == std::string::npos ? std::string() : line.substr(start);
      for (const char* level : {"WARNING: ", "WARN: ", "ERROR: ", "INFO: "})
        if (line.rfind(level, 0) == 0) line.erase(0, std::strlen(level));
      if (!line.empty()) lines += (lines.empty() ? "" : "\n") + line;
      line.clear();
    }
    return lines;
  }

 private:
  void restore() {
    if (m_out == nullptr) return;
    std::cout.flush();
    std::cerr.flush();
    std::cout.rdbuf(m_out);
    std::cerr.rdbuf(m_err);
    m_out = nullptr;
  }
  std::ostringstream m_text;  // first: the streams are pointed at it in the initialisers below
  std::streambuf* m_out;
  std::streambuf* m_err;
};

// OpenVDB 10 reads a size from the file into a variable it has not initialised and goes on with it
// when the read ran into the end of the file (io::bloscFromStream, the string reader): a file cut
// short then asks for whatever that variable held, a few bytes or terabytes (AddressSanitizer aborts
// on it), and its error changed from run to run (1 in ~30 under AddressSanitizer). So before
// io::File reads a file, its layout is walked as io::File::open walks it, with the library's own
// readers (the header, the file's metadata, each grid's descriptor) on a stream that throws at the
// file's end, and every grid must end inside the file. A file that passes holds every byte its
// grids announce; one that fails is named cut short, with the byte where it ends.
class LayoutCheck : private openvdb::io::Archive {
 public:
  static void run(const char* path) { LayoutCheck().walk(path); }

 private:
  void walk(const char* path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return;  // io::File says what is wrong with opening it
    const std::int64_t file_bytes = in.tellg();
    in.seekg(0);
    const std::string end = std::to_string(file_bytes);
    const auto refuse = [](const std::string& why) {
      throw Failure{PRIZMA_VDB_BAD_FILE, "not a readable OpenVDB file (" + why + ")"};
    };
    if (file_bytes == 0) refuse("the file is empty");
    in.exceptions(std::ios::failbit | std::ios::badbit | std::ios::eofbit);
    LibraryLogCapture unheard;  // what the library notices here, io::File::open notices again, heard
    try {
      readHeader(in);
      if (!inputHasGridOffsets()) return;  // written as a stream: io::File reads it whole, in order
      setFormatVersion(in);
      setLibraryVersion(in);
      setDataCompression(in);
      openvdb::MetaMap().readMeta(in);
      for (std::int32_t i = 0, n = readGridCount(in); i < n; ++i) {
        openvdb::io::GridDescriptor grid;
        grid.read(in);
        const std::string name = "grid \"" + grid.gridName() + "\"";
        if (grid.getGridPos() < 0 || grid.getEndPos() < grid.getGridPos())
          refuse("corrupt: " + name + " at bytes " + std::to_string(grid.getGridPos()) + " to " +
                 std::to_string(grid.getEndPos()));
        if (grid.getEndPos() > file_bytes)
          refuse("cut short: " + name + " ends at byte " + std::to_string(grid.getEndPos()) + ", the file at byte " + end);
        grid.seekToEnd(in);
      }
    } catch (const std::ios_base::failure&) {
      refuse("cut short: the file ends at byte " + end + ", inside its header or a grid's descriptor");
    }
  }
};

// Floor division for block indices of voxels that may lie one voxel outside the box.
int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

std::string grid_names(openvdb::io::File& file) {
  std::string names;
  for (auto it = file.beginName(); it != file.endName(); ++it) names += (names.empty() ? "" : ", ") + it.gridName();
  return names;
}

// The grid's index → world map must be a scale and a translation (voxels aligned with the axes), as
// the renderer's volume is an axis-aligned box; returns the voxel size per axis.
std::array<double, 3> axis_aligned_voxel_size(const openvdb::FloatGrid& grid) {
  const openvdb::math::Transform& xf = grid.transform();
  if (!xf.isLinear())
    throw Failure{PRIZMA_VDB_BAD_GRID, "has a non-linear (frustum) transform; only axis-aligned voxels are supported"};
  const openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
  std::array<double, 3> size{};
  for (int r = 0; r < 3; ++r) {
    size[r] = std::abs(m(r, r));
    for (int c = 0; c < 3; ++c) {
      if (c != r && std::abs(m(r, c)) > 1e-9 * (std::abs(m(r, r)) + std::abs(m(c, c)))) {
        throw Failure{PRIZMA_VDB_BAD_GRID, "has a rotated or sheared transform; only axis-aligned voxels are supported"};
      }
    }
    if (!(size[r] > 0.0) || !std::isfinite(size[r]))
      throw Failure{PRIZMA_VDB_BAD_GRID, "has a degenerate voxel size " + std::to_string(m(r, r))};
  }
  return size;
}

int open_grid(const char* path, const char* grid_name, PrizmaVdbGrid** out, PrizmaVdbGridInfo* info, char* message,
              std::size_t size) {
  *out = nullptr;
  info->warnings[0] = '\0';
  PrizmaVdbGrid* made = nullptr;
  const int rc = guarded(path, Stage::ReadingFile, message, size, [&] {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    // The grid, by name, as a float grid.
    openvdb::GridBase::Ptr base;
    LibraryLogCapture log;
    const ReadMemoryBound bound(path);
    LayoutCheck::run(path);
    openvdb::io::File file(path);
    file.open(false);  // no delayed loading: the file is read now, not behind our back later
    if (!file.hasGrid(grid_name)) {
      const std::string names = grid_names(file);
      file.close();
      throw Failure{PRIZMA_VDB_BAD_FILE, "no grid named \"" + std::string(grid_name) + "\" (" +
                                             (names.empty() ? std::string("the file holds no grids")
                                                            : "grids in the file: " + names) + ")"};
    }
    base = file.readGrid(grid_name);
    file.close();
    put_message(log.finish(), info->warnings, sizeof info->warnings);
    const openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) throw Failure{PRIZMA_VDB_BAD_GRID, "is of type " + base->valueType() + ", not float"};
    // A level set holds signed distances to a surface (negative inside, the background a narrow band
    // away), not densities: read as density it would render a hollow shell of the band.
    if (grid->getGridClass() == openvdb::GRID_LEVEL_SET) {
      throw Failure{PRIZMA_VDB_BAD_GRID,
                    "is a level set (signed distances to a surface, not densities); convert it to a fog volume first "
                    "(openvdb::tools::sdfToFogVolume, or Houdini's Convert VDB to Fog)"};
    }
    if (grid->activeVoxelCount() == 0) throw Failure{PRIZMA_VDB_BAD_GRID, "has no active voxels (empty grid)"};
    const std::array<double, 3> voxel_size = axis_aligned_voxel_size(*grid);
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    const openvdb::Coord dim = box.dim();
    for (int a = 0; a < 3; ++a) {
      info->dims[a] = dim[a];
      info->voxel_size[a] = voxel_size[a];
    }
    made = new PrizmaVdbGrid{grid, box};
  });
  if (rc == PRIZMA_VDB_OK) *out = made;
  return rc;
}

int copy_dense(const PrizmaVdbGrid* g, float* values, char* message, std::size_t size) {
  return guarded(nullptr, Stage::InMemory, message, size, [&] {
    // Dense over the active bounding box (index space), x fastest, through the library's copyToDense,
    // run serially on slabs of z in parallel: its own parallel split takes the middle of a box as
    // (min + max) / 2 in 32 bits, which overflows past 2^30 voxels from the origin (a grid out there,
    // or one byte changed in a file) and then writes outside the box.
    const openvdb::Coord lo = g->box.min(), hi = g->box.max();
    const std::size_t slab = static_cast<std::size_t>(g->box.dim().x()) * static_cast<std::size_t>(g->box.dim().y());
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, std::int64_t{g->box.dim().z()}),
                      [&](const tbb::blocked_range<std::int64_t>& r) {
                        const openvdb::CoordBBox part(openvdb::Coord(lo.x(), lo.y(), lo.z() + static_cast<int>(r.begin())),
                                                      openvdb::Coord(hi.x(), hi.y(), lo.z() + static_cast<int>(r.end() - 1)));
                        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
                            part, values + static_cast<std::size_t>(r.begin()) * slab);
                        openvdb::tools::copyToDense(*g->grid, dense, /*serial=*/true);
                      });
  });
}

int block_ranges(const PrizmaVdbGrid* g, int kB, float* ranges, char* message, std::size_t size) {
  return guarded(nullptr, Stage::InMemory, message, size, [&] {
    if (kB < 1) throw Failure{PRIZMA_VDB_FAILED, "block size must be positive"};
    const openvdb::Coord dim = g->box.dim();
    const int dims[3] = {dim.x(), dim.y(), dim.z()};
    int nb[3];
    for (int a = 0; a < 3; ++a) nb[a] = (dims[a] + kB - 1) / kB;
    const std::size_t blocks = static_cast<std::size_t>(nb[0]) * nb[1] * nb[2];
    // The background (outside every node) widens every block's range.
    const float inf = std::numeric_limits<float>::infinity();
    const float bg = g->grid->background();
    for (std::size_t k = 0; k < blocks; ++k) {
      ranges[2 * k] = std::isfinite(bg) ? bg : inf;
      ranges[2 * k + 1] = std::isfinite(bg) ? bg : -inf;
    }
    // Each leaf voxel and each tile (active or not) widens the range of the blocks whose
    // interpolation stencil it meets: block c's points interpolate voxels c·B − 1 … c·B + B.
    const openvdb::Coord origin = g->box.min();
    for (auto it = g->grid->tree().cbeginValueAll(); it; ++it) {
      const float v = *it;
      if (!std::isfinite(v)) continue;
      openvdb::CoordBBox b;
      it.getBoundingBox(b);
      int lo[3], hi[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        // The voxels of this value inside the dense box, relative to its origin (64-bit: tiles reach far).
        const long long i0 = std::max<long long>(0, static_cast<long long>(b.min()[a]) - origin[a]);
        const long long i1 = std::min<long long>(dims[a] - 1, static_cast<long long>(b.max()[a]) - origin[a]);
        if (i0 > i1) {
          inside = false;
          break;
        }
        lo[a] = std::max(0, floor_div(static_cast<int>(i0) - 1, kB));
        hi[a] = std::min(nb[a] - 1, floor_div(static_cast<int>(i1) + 1, kB));
      }
      if (!inside) continue;
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            float* r = ranges + 2 * ((static_cast<std::size_t>(z) * nb[1] + y) * nb[0] + x);
            r[0] = std::min(r[0], v);
            r[1] = std::max(r[1], v);
          }
    }
  });
}

void close_grid(PrizmaVdbGrid* g) { delete g; }

const PrizmaVdbModule kModule{PRIZMA_VDB_ABI_VERSION, open_grid, copy_dense, block_ranges, close_grid};

}  // namespace

extern "C" __attribute__((visibility("default"))) const PrizmaVdbModule* prizma_vdb_module_v1() { return &kModule; }
