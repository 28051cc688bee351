#pragma once
// Where the live page's Save writes (prizma-relight --serve --save-dir DIR; docs/relight.md, "Save"):
// plain file names inside one folder, never the file being served (the same file by device and
// inode, so also a hard link to it), never through a symbolic link (one with the name is refused, so
// a link cannot lead a write out of the folder), and at most kMaxCreatedFiles new files in one run
// (a page gone wrong, or a script, cannot fill the disk with names).
#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <string>

namespace prizma::relight {

class SaveFolder {
 public:
  static constexpr int kMaxCreatedFiles = 1000;

  // Throws InputError("--save-dir", …) when `folder` is not an existing writable folder.
  // `served_file`: the spectral file the page shows.
  SaveFolder(std::filesystem::path folder, const std::filesystem::path& served_file);

  const std::filesystem::path& folder() const { return m_folder; }

  // Writes `name` through `write(path)` (which must write the file atomically, as
  // RelightSession::save does) and returns the path written. Throws InputError("file", …) when the
  // name is refused: not a plain name of an image format (letters, digits, '.', '_', '-'; .png,
  // .tif, .jpg, .exr), a symbolic link, the served file, or a new file past kMaxCreatedFiles.
  // Not thread-safe: call with the session's lock held.
  std::filesystem::path save(const std::string& name, const std::function<void(const std::filesystem::path&)>& write);

  int created() const { return m_created; }

 private:
  std::filesystem::path m_folder;
  bool m_served_known = false;  // the served file could be looked up (it may have gone since it was read)
  dev_t m_served_dev = 0;
  ino_t m_served_ino = 0;
  int m_created = 0;  // files this run created (names that did not exist before its Save)
};

}  // namespace prizma::relight
