#pragma once
// The two halves of write_atomically, shared with OutputGroup (output_group.cpp): a complete
// temporary, then its rename into place.
#include <filesystem>
#include <functional>
#include <string>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral::detail {

// A temporary written, checked, fsync'ed and closed, beside the file it is to replace.
struct CompleteTemporary {
  std::filesystem::path destination;  // as given (messages)
  std::filesystem::path target;       // the regular file replaced (a symbolic link's final target)
  std::filesystem::path folder;       // target's folder, where the temporary is
  std::filesystem::path temporary;
  bool existed = false;               // target existed when the temporary was made
};

// write_atomically up to the rename: resolves `path` (InputError as check_output_file, also for a
// recorded input no output may update in place), writes through AtomicOutput and checks the whole.
// On failure the temporary is removed and RuntimeError says "<path>: cannot write: <reason> (<note>)",
// the note saying the existing file is unchanged and then `also_unwritten` ("render.exr was not
// written either"), when not empty.
CompleteTemporary write_temporary(const std::filesystem::path& path,
                                  const std::function<void(AtomicOutput& out)>& write,
                                  const std::string& also_unwritten);

// "<path>: cannot write: <reason> (<note>)" (no parentheses when the note is empty).
RuntimeError write_failure(const std::filesystem::path& path, const std::string& reason, const std::string& note);

// A fresh name ".prizma-old-<pid>-<n>-<name>" for a link to the file a temporary replaces.
std::string backup_name(const CompleteTemporary& t);

// fsync of a folder (its renames on disk): "" when done or not supported, else the system's reason.
std::string flush_folder(const std::filesystem::path& folder);

std::string quoted_path(const std::filesystem::path& p);

}  // namespace prizma::spectral::detail
