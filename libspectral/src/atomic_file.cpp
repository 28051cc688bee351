// Outputs: checked before the work, written through a temporary whose every write, fsync and close
// is checked, renamed over the destination only when complete. POSIX rename() within one folder is
// atomic, so readers see the old file or the new one, never a part.
#include "prizma/spectral/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <system_error>
#include <tuple>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "atomic_file_detail.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

std::atomic<unsigned long> g_counter{0};

std::string quoted(const fs::path& p) { return "\"" + p.string() + "\""; }
std::string errno_text(int err) { return std::strerror(err); }

// The longest file name the folder's file system takes (NAME_MAX, 255 on Linux file systems).
std::size_t name_max(const fs::path& folder) {
  errno = 0;
  const long n = ::pathconf(folder.c_str(), _PC_NAME_MAX);
  return n > 0 ? static_cast<std::size_t>(n) : 255;
}

// Room kept for the temporary's folder part of the path beyond the destination's.
constexpr std::size_t kPathMax = PATH_MAX;

// What resolve() found wrong: `input` problems are the path itself (exit 2 in every case); folder
// problems found at write time are run-time failures (the folder was fine when the run began).
struct Resolved {
  OutputTarget target;
  fs::path folder;
  std::string problem;  // empty when the path can be written
  bool folder_problem = false;
};

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// long on purpose: one walk over the path (links, kinds, folder) whose every refusal names the case.
Resolved resolve(const fs::path& path) {
  Resolved r;
  const std::string p = quoted(path);
  if (path.empty()) {
    r.problem = "empty file name";
    return r;
  }
  if (!path.has_filename()) {
    r.problem = p + " is not a file name (it ends in '/')";
    return r;
  }
  r.target.file = path;
  const auto name_too_long = [&](const fs::path& file, const fs::path& folder) {
    const std::size_t name_len = file.filename().string().size();
    const std::size_t limit = name_max(folder);
    if (name_len <= limit) return false;
    r.problem = "the file name of " + p + " is " + std::to_string(name_len) + " bytes long; this file system allows " +
                std::to_string(limit);
    return true;
  };
  if (name_too_long(path, path.parent_path().empty() ? fs::path(".") : path.parent_path())) return r;
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (S_ISLNK(st.st_mode)) {
      // A symbolic link: its final target is the file replaced, the link stays a link.
      if (::stat(path.c_str(), &st) != 0) {
        const int err = errno;
        std::error_code ec;
        const fs::path to = fs::read_symlink(path, ec);
        if (err == ENOENT) {
          r.problem = p + " is a symbolic link to a file that does not exist (" + quoted(to) +
                      "); give the file's own path, or remove the link";
        } else if (err == ELOOP) {
          r.problem = p + ": too many levels of symbolic links";
        } else {
          r.problem = p + ": cannot follow the symbolic link (" + errno_text(err) + ")";
        }
        return r;
      }
      std::error_code ec;
      r.target.file = fs::canonical(path, ec);
      if (ec) {
        r.problem = p + ": cannot follow the symbolic link (" + ec.message() + ")";
        return r;
      }
    }
    if (!S_ISREG(st.st_mode)) {
      r.problem = p + " is " + kind_of(st.st_mode) + "; an output must be a regular file";
      return r;
    }
    r.target.exists = true;
    r.target.device = st.st_dev;
    r.target.inode = st.st_ino;
  } else if (errno == ELOOP) {
    r.problem = p + ": too many levels of symbolic links";
    return r;
  } else if (errno == ENOTDIR) {
    r.problem = "a part of " + p + " is not a folder";
    return r;
  } else if (errno == ENAMETOOLONG) {
    r.problem = p + " is too long a path for this system";
    return r;
  } else if (errno != ENOENT) {
    const int err = errno;
    r.folder = r.target.file.parent_path().empty() ? fs::path(".") : r.target.file.parent_path();
    r.problem = "folder " + quoted(r.folder) + " of " + p + " is not accessible (" + errno_text(err) + ")";
    r.folder_problem = true;
    return r;
  }

  // The folder the temporary goes into: it must exist and be writable.
  r.folder = r.target.file.parent_path().empty() ? fs::path(".") : r.target.file.parent_path();
  struct stat dst {};
  if (::stat(r.folder.c_str(), &dst) != 0 || !S_ISDIR(dst.st_mode)) {
    r.problem = "folder " + quoted(r.folder) + " of " + p + " does not exist";
    r.folder_problem = true;
    return r;
  }
  if (::access(r.folder.c_str(), W_OK | X_OK) != 0) {
    const int err = errno;
    r.problem = "folder " + quoted(r.folder) + " of " + p + " is not writable (" + errno_text(err) + ")";
    r.folder_problem = true;
    return r;
  }
  if (!r.target.exists) {
    r.target.device = dst.st_dev;
    r.target.inode = dst.st_ino;
  }
  if (name_too_long(r.target.file, r.folder)) return r;
  if ((r.folder / r.target.file.filename()).string().size() + 64 >= kPathMax) {
    r.problem = p + " is too long a path for this system";
    return r;
  }
  return r;
}

// "<kind><pid>-<n>-<name>" (kind ".prizma-tmp-" for temporaries, ".prizma-old-" for the links an
// OutputGroup keeps to the files it replaces), keeping the tail of the name (its extension) when the
// whole would be longer than the file system allows.
std::string temporary_name(const std::string& name, std::size_t limit, const char* kind = ".prizma-tmp-") {
  const std::string prefix = kind + std::to_string(::getpid()) + "-" + std::to_string(g_counter.fetch_add(1)) + "-";
  if (prefix.size() + name.size() <= limit) return prefix + name;
  std::size_t cut = name.size() - (limit - prefix.size());
  // Do not cut a UTF-8 sequence in two.
  while (cut < name.size() && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) ++cut;
  return prefix + name.substr(cut);
}

void remove_quietly(const fs::path& p) {
  std::error_code ec;
  fs::remove(p, ec);
}

// "a scene file" → "the scene file".
std::string definite(const std::string& kind) {
  for (const std::string_view article : {"a ", "an "})
    if (kind.rfind(article, 0) == 0) return "the " + kind.substr(article.size());
  return kind;
}

// Why the output `path` (option `input`, resolved to `target`) may not be written: it is an input
// the run has read (InputRecording), and not one `input` may update in place. "" when it may.
// `input` empty: any output allowed to update the input in place may (write time, after the check).
std::string replaces_input(const OutputTarget& target, const fs::path& path, const std::string& input) {
  if (!target.exists) return {};
  const std::optional<RecordedInput> in = recorded_input(target.device, target.inode);
  if (!in) return {};
  const auto& allowed = in->replaced_by;
  if (input.empty() ? !allowed.empty() : std::find(allowed.begin(), allowed.end(), input) != allowed.end()) return {};
  return quoted(path) + " would replace " + quoted(in->path) + ", " + definite(in->kind) +
         " this run reads (an output never replaces an input)";
}

}  // namespace

OutputTarget check_output_file(const fs::path& path, const std::string& input) {
  Resolved r = resolve(path);
  if (r.problem.empty()) r.problem = replaces_input(r.target, path, input);
  if (!r.problem.empty()) throw InputError(input, r.problem);
  return r.target;
}

void check_distinct_outputs(const std::vector<std::pair<fs::path, std::string>>& outputs) {
  // Identity: an existing file by (device, inode); a new one by its folder's and its name.
  using Key = std::tuple<bool, dev_t, ino_t, std::string>;
  std::map<Key, std::size_t> seen;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& [path, input] = outputs[i];
    const OutputTarget t = check_output_file(path, input);
    const Key key{t.exists, t.device, t.inode, t.exists ? std::string() : t.file.filename().string()};
    const auto [it, inserted] = seen.emplace(key, i);
    if (!inserted) {
      const auto& [first_path, first_input] = outputs[it->second];
      throw InputError(input, quoted(path) + " is the same file as " + first_input + " (" + quoted(first_path) +
                                  "): one run cannot write two outputs into one file");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// AtomicOutput

AtomicOutput::AtomicOutput(int fd, fs::path destination, fs::path temporary)
    : m_fd(fd), m_destination(std::move(destination)), m_temporary(std::move(temporary)) {}

void AtomicOutput::record(const std::string& reason) noexcept {
  if (!m_error.empty()) return;
  try {
    m_error = reason.empty() ? std::string("write failed") : reason;
  } catch (...) {
    // Out of memory while recording: keep a fixed reason (the string is empty, SSO fits it).
    m_error = "write failed";
  }
}

bool AtomicOutput::write_all_at(const void* data, std::size_t n, std::int64_t offset) noexcept {
  if (!m_error.empty()) return false;
  if (offset < 0) {
    record("negative file position");
    return false;
  }
  const char* bytes = static_cast<const char*>(data);
  std::size_t done = 0;
  while (done < n) {
    const ssize_t w = ::pwrite(m_fd, bytes + done, n - done, static_cast<off_t>(offset) + static_cast<off_t>(done));
    if (w < 0) {
      if (errno == EINTR) continue;
      record(errno_text(errno));
      return false;
    }
    if (w == 0) {
      record(errno_text(ENOSPC));
      return false;
    }
    done += static_cast<std::size_t>(w);
  }
  if (offset + static_cast<std::int64_t>(n) > m_size) m_size = offset + static_cast<std::int64_t>(n);
  return true;
}

bool AtomicOutput::write(const void* data, std::size_t n) noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  if (!write_all_at(data, n, m_pos)) return false;
  m_pos += static_cast<std::int64_t>(n);
  return true;
}

bool AtomicOutput::write_at(const void* data, std::size_t n, std::int64_t offset) noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  return write_all_at(data, n, offset);
}

std::size_t AtomicOutput::read_at(void* data, std::size_t n, std::int64_t offset) noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  if (!m_error.empty() || offset < 0) return 0;
  char* bytes = static_cast<char*>(data);
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pread(m_fd, bytes + done, n - done, static_cast<off_t>(offset) + static_cast<off_t>(done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    done += static_cast<std::size_t>(r);
  }
  return done;
}

bool AtomicOutput::seek(std::int64_t offset) noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  if (!m_error.empty()) return false;
  if (offset < 0) {
    record("seek to a negative file position");
    return false;
  }
  m_pos = offset;
  return true;
}

std::int64_t AtomicOutput::tell() const noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  return m_pos;
}

std::int64_t AtomicOutput::size() const noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  return m_size;
}

void AtomicOutput::fail(const std::string& reason) noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  record(reason);
}

bool AtomicOutput::failed() const noexcept {
  const std::lock_guard<std::mutex> lock(m_mutex);
  return !m_error.empty();
}

std::string AtomicOutput::error() const {
  const std::lock_guard<std::mutex> lock(m_mutex);
  return m_error;
}

// ---------------------------------------------------------------------------------------------
// write_atomically: a complete temporary (detail::write_temporary), then detail::put_in_place

namespace detail {

RuntimeError write_failure(const fs::path& path, const std::string& reason, const std::string& note) {
  return RuntimeError(path.string() + ": cannot write: " + reason + (note.empty() ? "" : " (" + note + ")"));
}

CompleteTemporary write_temporary(const fs::path& path, const std::function<void(AtomicOutput& out)>& write,
                                  const std::string& also_unwritten) {
  const Resolved r = resolve(path);
  if (!r.problem.empty()) {
    if (r.folder_problem) throw RuntimeError(path.string() + ": cannot write: " + r.problem);
    throw InputError(path.string(), r.problem);
  }
  // The writers that skip check_output_file still never replace an input (docs/errors.md).
  if (const std::string problem = replaces_input(r.target, path, {}); !problem.empty())
    throw InputError(path.string(), problem);
  const bool existed = r.target.exists;
  std::string note = existed ? "the existing file is unchanged" : "";
  if (!also_unwritten.empty()) note += (note.empty() ? "" : "; ") + also_unwritten;
  const auto failure = [&](const std::string& reason) { return write_failure(path, reason, note); };

  const fs::path tmp = r.folder / temporary_name(r.target.file.filename().string(), name_max(r.folder));
  const int fd = ::open(tmp.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    throw failure("cannot create the temporary " + quoted(tmp) + " (" + errno_text(err) + ")");
  }
  bool fd_open = true;
  const auto abandon = [&] {
    if (fd_open) (void)::close(fd);
    fd_open = false;
    remove_quietly(tmp);
  };

  AtomicOutput out(fd, path, tmp);
  try {
    // A replaced file keeps its permissions.
    struct stat old {};
    if (existed && ::stat(r.target.file.c_str(), &old) == 0 && ::fchmod(fd, old.st_mode & 07777) != 0) {
      const int err = errno;
      out.fail("cannot set the permissions of the temporary (" + errno_text(err) + ")");
    }
    if (!out.failed()) write(out);
  } catch (...) {
    abandon();
    if (out.failed()) throw failure(out.error());  // the write's own failure is the cause
    throw;
  }

  // Complete? Every write succeeded, the file holds exactly what was written, and it is on disk.
  std::string problem = out.error();
  if (problem.empty() && out.size() == 0) problem = "nothing was written";
  struct stat st {};
  if (problem.empty()) {
    if (::fstat(fd, &st) != 0) {
      const int err = errno;
      problem = "cannot check the temporary (" + errno_text(err) + ")";
    } else if (st.st_size != static_cast<off_t>(out.size())) {
      problem = "the temporary holds " + std::to_string(st.st_size) + " bytes, " + std::to_string(out.size()) +
                " were written";
    }
  }
  if (problem.empty() && ::fsync(fd) != 0) {
    const int err = errno;
    problem = "cannot flush to disk (" + errno_text(err) + ")";
  }
  if (problem.empty()) {
    fd_open = false;
    if (::close(fd) != 0) problem = "cannot close the temporary (" + errno_text(errno) + ")";
  }
  if (!problem.empty()) {
    abandon();
    throw failure(problem);
  }
  return {path, r.target.file, r.folder, tmp, existed};
}

std::string backup_name(const CompleteTemporary& t) {
  return temporary_name(t.target.filename().string(), name_max(t.folder), ".prizma-old-");
}

std::string flush_folder(const fs::path& folder) {
  const int dfd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return {};
  const int rc = ::fsync(dfd);
  const int err = errno;
  (void)::close(dfd);
  // File systems that cannot sync a folder say EINVAL (or ENOTSUP, EROFS): nothing to flush.
  if (rc != 0 && err != EINVAL && err != ENOTSUP && err != EROFS) return errno_text(err);
  return {};
}

std::string quoted_path(const fs::path& p) { return quoted(p); }

}  // namespace detail

void write_atomically(const fs::path& path, const std::function<void(AtomicOutput& out)>& write) {
  const detail::CompleteTemporary t = detail::write_temporary(path, write, {});
  if (::rename(t.temporary.c_str(), t.target.c_str()) != 0) {
    const std::string reason = errno_text(errno);
    remove_quietly(t.temporary);
    throw detail::write_failure(path, "cannot rename " + quoted(t.temporary) + " into place (" + reason + ")",
                                t.existed ? "the existing file is unchanged" : "");
  }
  // The rename itself on disk.
  if (const std::string err = detail::flush_folder(t.folder); !err.empty()) {
    throw RuntimeError(path.string() + ": written, but its folder " + quoted(t.folder) +
                       " could not be flushed to disk (" + err + ")");
  }
}

void write_file_atomically(const fs::path& path, std::string_view content) {
  write_atomically(path, [&](AtomicOutput& out) { out.write(content); });
}

}  // namespace prizma::spectral
