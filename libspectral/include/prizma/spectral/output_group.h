#pragma once
// OutputGroup: the outputs of one run (a render's EXR and its preview, a batch's images) made visible
// together or not at all (docs/errors.md, "All or nothing").
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "prizma/spectral/atomic_file.h"

namespace prizma::spectral {

// write(): what write_atomically does up to the rename: the temporary beside the destination is
//   written, checked, fsync'ed and closed, and kept. When it fails, every temporary of the group is
//   removed and the error (as write_atomically's) adds which outputs were not written either.
// commit(): renames each temporary over its destination, in the order written, after keeping a hard
//   link (".prizma-old-…" beside it) to each file it replaces. When a rename fails, the outputs
//   already renamed are put back (the old file from its link, a new one removed) and RuntimeError
//   says which were; then the links are removed and each folder fsync'ed.
// Destroyed without commit() (an exception, a failed write): its temporaries are removed and no
//   output of the run appears.
// Not promised: between the first and last rename (no writing, microseconds) a reader may see some
// outputs new and some old, and a crash there (power loss, SIGKILL) leaves that mix with the
// ".prizma-old-…" links holding the replaced files. Where no hard link can be made (a file system
// without them) a replaced file cannot be put back: the error then says so.
class OutputGroup {
 public:
  OutputGroup();
  ~OutputGroup();
  OutputGroup(const OutputGroup&) = delete;
  OutputGroup& operator=(const OutputGroup&) = delete;

  void write(const std::filesystem::path& path, const std::function<void(AtomicOutput& out)>& writer);
  void commit();
  // Outputs written and not yet committed.
  std::size_t size() const;

 private:
  struct File;
  void discard() noexcept;
  // Undoes the renames of the first `count` files (the old file back from its link, a new one
  // removed); says what was undone and what could not be.
  std::string put_back(std::size_t count);
  std::vector<File> m_files;
};

// With a group, group->write(path, writer) (the file appears at its commit()); without,
// write_atomically(path, writer).
void write_atomically(const std::filesystem::path& path, const std::function<void(AtomicOutput& out)>& writer,
                      OutputGroup* group);

}  // namespace prizma::spectral
