// The live page's Save: which names it may write in --save-dir (save_folder.h).
#include "prizma/relight/save_folder.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <regex>

#include "prizma/spectral/output_image.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace fs = std::filesystem;
using spectral::InputError;

namespace {

// A saved file's name: a plain name, no folder, no leading dot.
const std::regex kSaveName("[A-Za-z0-9][A-Za-z0-9._-]{0,127}");

}  // namespace

SaveFolder::SaveFolder(fs::path folder, const fs::path& served_file) : m_folder(std::move(folder)) {
  std::error_code ec;
  if (!fs::is_directory(m_folder, ec)) {
    throw InputError("--save-dir", "\"" + m_folder.string() + "\" is not an existing folder");
  }
  if (::access(m_folder.c_str(), W_OK | X_OK) != 0) {
    throw InputError("--save-dir", "folder \"" + m_folder.string() + "\" is not writable");
  }
  struct stat st{};
  if (::stat(served_file.c_str(), &st) == 0) {
    m_served_known = true;
    m_served_dev = st.st_dev;
    m_served_ino = st.st_ino;
  }
}

fs::path SaveFolder::save(const std::string& name, const std::function<void(const fs::path&)>& write) {
  if (!std::regex_match(name, kSaveName)) {
    throw InputError("file", "\"" + name + "\" is not a plain file name (letters, digits, '.', '_', '-')");
  }
  spectral::output_format_for(name, "file");
  const fs::path path = m_folder / name;
  struct stat st{};
  const bool exists = ::lstat(path.c_str(), &st) == 0;
  if (exists && S_ISLNK(st.st_mode)) {
    throw InputError("file", "\"" + name + "\" is a symbolic link in the save folder; Save does not follow links");
  }
  if (exists && m_served_known && st.st_dev == m_served_dev && st.st_ino == m_served_ino) {
    throw InputError("file", "\"" + name + "\" is the file being served; Save never replaces it");
  }
  if (!exists && m_created >= kMaxCreatedFiles) {
    throw InputError("file", "this server has already created " + std::to_string(kMaxCreatedFiles) +
                                 " files; save over one of them, or restart prizma-relight --serve");
  }
  write(path);
  if (!exists) ++m_created;
  return path;
}

}  // namespace prizma::relight
