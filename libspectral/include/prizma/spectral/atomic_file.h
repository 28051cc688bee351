#pragma once
// Every output file of every tool goes through here (docs/errors.md, "Outputs").
//   check_output_file / check_distinct_outputs: before any work, refuse an output path that cannot be
//     written as a regular file (a folder, a device, a FIFO, a socket, a dangling symbolic link, a
//     missing or read-only folder, a name too long), one that is a file the run reads (an input
//     recorded by InputRecording, input_file.h) and two outputs of one run naming the same file.
//   write_atomically: the bytes go to a temporary in the destination's folder through AtomicOutput,
//     which checks every write; the temporary is fsync'ed, its size checked and only then renamed
//     over the destination. A failed write never leaves a partial file and never touches an existing one.
//   The outputs of one run go through an OutputGroup (output_group.h): all appear, or none.
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace prizma::spectral {

// The regular file an output path resolves to.
struct OutputTarget {
  std::filesystem::path file;  // the path itself, or a symbolic link's final target (the link is kept)
  bool exists = false;         // an existing regular file is replaced
  dev_t device = 0;            // identity: of the file when it exists, else of its folder
  ino_t inode = 0;
};

// Checks, before any work, that `path` can be written as an output and returns what it resolves to:
// a new file in an existing writable folder, or an existing regular file (through symbolic links,
// whose final target is replaced and the links kept). Throws InputError(input, …) naming the path
// when it is a folder, a character or block device, a FIFO, a socket, a symbolic link to a missing
// file or a loop, in a missing or read-only folder, when its name is longer than the file system
// allows, or when it is a file the run reads ("-o: \"s.json\" would replace \"s.json\", the scene file
// this run reads …"; allow_in_place_update names the options that may).
OutputTarget check_output_file(const std::filesystem::path& path, const std::string& input);

// Checks every output of one run with check_output_file and throws InputError (naming the second of
// the two) when two resolve to the same file: the same path spelled twice ("a.png", "./a.png"),
// symbolic links to one file, or hard links. Each entry is (path, input naming it).
void check_distinct_outputs(const std::vector<std::pair<std::filesystem::path, std::string>>& outputs);

// The temporary file being written. Every call checks the system's result; the first failure is
// recorded (error()) and every later call fails too. Thread-safe.
class AtomicOutput {
 public:
  AtomicOutput(int fd, std::filesystem::path destination, std::filesystem::path temporary);
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  // Writes all n bytes at the current position and moves it on; false when the write failed.
  bool write(const void* data, std::size_t n) noexcept;
  bool write(std::string_view text) noexcept { return write(text.data(), text.size()); }
  // Writes all n bytes at `offset`, leaving the position alone; false when the write failed.
  bool write_at(const void* data, std::size_t n, std::int64_t offset) noexcept;
  // Reads back up to n bytes at `offset` (writers that patch what they wrote); the count read.
  std::size_t read_at(void* data, std::size_t n, std::int64_t offset) noexcept;
  bool seek(std::int64_t offset) noexcept;
  std::int64_t tell() const noexcept;
  // Bytes from the start of the file to the end of the furthest write.
  std::int64_t size() const noexcept;

  // A writer's own failure (e.g. a library's message): recorded like a failed write.
  void fail(const std::string& reason) noexcept;
  bool failed() const noexcept;
  std::string error() const;

  // The file being replaced (for messages and for choosing a format by its extension).
  const std::filesystem::path& destination() const noexcept { return m_destination; }
  const std::filesystem::path& temporary() const noexcept { return m_temporary; }

 private:
  bool write_all_at(const void* data, std::size_t n, std::int64_t offset) noexcept;  // m_mutex held
  void record(const std::string& reason) noexcept;                                   // m_mutex held

  int m_fd;
  std::filesystem::path m_destination;
  std::filesystem::path m_temporary;
  mutable std::mutex m_mutex;
  std::int64_t m_pos = 0;
  std::int64_t m_size = 0;
  std::string m_error;
};

// Writes `path` atomically: resolves it as check_output_file does (a symbolic link's target is
// replaced), creates "<folder>/.prizma-tmp-<pid>-<n>-<name>" (the name's tail when that is too long
// for the file system), calls write(out), then checks that no write failed, fsyncs the temporary,
// checks its size, closes it and renames it over the destination, then fsyncs the folder. If write
// throws or anything fails, the temporary is removed and an existing destination is untouched.
// Throws InputError for a destination that is not a regular file (as check_output_file; also for a
// recorded input that no output may update in place), RuntimeError naming the path and the
// system's reason for every failure of the write, and lets a writer's own exception through when
// no write failed.
void write_atomically(const std::filesystem::path& path, const std::function<void(AtomicOutput& out)>& write);

// write_atomically of a whole file held in memory (CSV tables, JSON).
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace prizma::spectral
