#include "prizma/spectral/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <utility>

#include "prizma/spectral/error.h"

namespace prizma::spectral {
namespace {

// The record InputRecording keeps: by (device, inode), the first name each file was read under.
struct InputRecord {
  std::mutex mutex;
  bool active = false;
  std::map<std::pair<dev_t, ino_t>, RecordedInput> files;
};

InputRecord& input_record() {
  static InputRecord record;
  return record;
}

void record_input(const struct stat& st, const std::filesystem::path& path, std::string_view kind) {
  InputRecord& r = input_record();
  const std::lock_guard lock(r.mutex);
  if (!r.active) return;
  r.files.try_emplace({st.st_dev, st.st_ino}, RecordedInput{path, std::string(kind), {}});
}

}  // namespace

InputRecording::InputRecording() {
  InputRecord& r = input_record();
  const std::lock_guard lock(r.mutex);
  r.active = true;
  r.files.clear();
}

InputRecording::~InputRecording() {
  InputRecord& r = input_record();
  const std::lock_guard lock(r.mutex);
  r.active = false;
  r.files.clear();
}

std::optional<RecordedInput> recorded_input(dev_t device, ino_t inode) {
  InputRecord& r = input_record();
  const std::lock_guard lock(r.mutex);
  const auto it = r.files.find({device, inode});
  if (it == r.files.end()) return std::nullopt;
  return it->second;
}

void allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  InputRecord& r = input_record();
  const std::lock_guard lock(r.mutex);
  const auto it = r.files.find({st.st_dev, st.st_ino});
  if (it != r.files.end()) it->second.replaced_by = outputs;
}

void require_regular_file(const std::filesystem::path& path, std::string_view kind, const std::string& input) {
  const std::string name = input.empty() ? path.string() : input;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    struct stat lst {};
    if (err == ENOENT && ::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {
      throw InputError(name, "is a symbolic link to a file that does not exist");
    }
    switch (err) {
      case ENOENT: throw InputError(name, "no such file");
      case ELOOP: throw InputError(name, "is a symbolic link loop (too many levels of symbolic links)");
      case ENOTDIR: throw InputError(name, "no such file (a folder on its path is a file)");
      default: throw InputError(name, std::string("cannot be accessed: ") + std::strerror(err));
    }
  }
  if (S_ISREG(st.st_mode)) {
    record_input(st, path, kind);
    return;
  }
  const std::string want(kind);
  if (S_ISDIR(st.st_mode)) throw InputError(name, "is a folder, not " + want);
  const char* what = S_ISFIFO(st.st_mode)  ? "a FIFO (named pipe)"
                     : S_ISCHR(st.st_mode) ? "a character device"
                     : S_ISBLK(st.st_mode) ? "a block device"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "not a regular file";
  throw InputError(name, std::string("is ") + what + "; " + want + " must be a regular file");
}

void check_json_depth(std::string_view text, const std::string& input) {
  int depth = 0;
  bool in_string = false;
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < text.size(); ++i, ++column) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      column = 0;
      continue;
    }
    if (in_string) {
      if (c == '\\') {
        ++i;
        ++column;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        throw InputError(input, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels at line " +
                                    std::to_string(line) + ", column " + std::to_string(column));
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

}  // namespace prizma::spectral
