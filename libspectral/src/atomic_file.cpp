// Atomic output: write a temporary beside the destination, flush it to disk, rename it over the
// destination. POSIX rename() within one folder is atomic, so readers see the old file or the new one.
#include "prizma/spectral/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "prizma/spectral/error.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

std::atomic<unsigned long> g_counter{0};

std::string quoted(const fs::path& p) { return "\"" + p.string() + "\""; }

// Best-effort fsync of a file or folder; failures are ignored (some file systems refuse fsync on
// folders), the rename is what makes the write atomic.
void sync_path(const fs::path& p, bool is_dir) {
  const int fd = ::open(p.c_str(), is_dir ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) return;
  (void)::fsync(fd);
  (void)::close(fd);
}

void remove_quietly(const fs::path& p) {
  std::error_code ec;
  fs::remove(p, ec);
}

}  // namespace

void write_atomically(const fs::path& path, const std::function<void(const fs::path& tmp_path)>& write) {
  if (path.empty()) throw RuntimeError("cannot write a file with an empty path");
  if (!path.has_filename()) throw RuntimeError(quoted(path) + ": not a file name");
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();

  // The folder must exist and be writable: say so clearly instead of letting the writer fail obscurely.
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw RuntimeError(quoted(path) + ": cannot write: folder " + quoted(dir) + " does not exist");
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw RuntimeError(quoted(path) + ": cannot write: folder " + quoted(dir) +
                       " is not writable (" + std::strerror(errno) + ")");
  }
  if (fs::is_directory(path, ec)) {
    throw RuntimeError(quoted(path) + ": cannot write: it is a folder");
  }

  const std::string tmp_name = ".prizma-tmp-" + std::to_string(::getpid()) + "-" +
                               std::to_string(g_counter.fetch_add(1)) + "-" + path.filename().string();
  const fs::path tmp = dir / tmp_name;

  try {
    write(tmp);
  } catch (...) {
    remove_quietly(tmp);
    throw;
  }

  if (!fs::exists(tmp, ec)) {
    throw RuntimeError(quoted(path) + ": the writer did not create the temporary file " + quoted(tmp));
  }
  sync_path(tmp, false);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    remove_quietly(tmp);
    throw RuntimeError(quoted(path) + ": cannot rename " + quoted(tmp) + " into place (" + reason + ")");
  }
  sync_path(dir, true);
}

}  // namespace prizma::spectral
