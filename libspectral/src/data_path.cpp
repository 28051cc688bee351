#include "prizma/spectral/data_path.h"

#include <dlfcn.h>

#include <cstdlib>
#include <system_error>

#include "prizma/spectral/error.h"

namespace prizma::spectral {

namespace {

bool is_dir(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_directory(p, ec);
}

}  // namespace

std::filesystem::path data_dir() {
  // 1. Explicit override.
  if (const char* env = std::getenv("PRIZMA_DATA_DIR"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env);
  }
  // 2. Installed layout, relative to the executable (<prefix>/bin/<exe> → <prefix>/share/prizma):
  //    an installed tree works wherever it is moved, and does not depend on the source tree.
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  std::filesystem::path installed;
  if (!ec && !exe.empty()) {
#ifdef PRIZMA_INSTALL_DATA_RELATIVE
    installed = (exe.parent_path() / PRIZMA_INSTALL_DATA_RELATIVE).lexically_normal();
#else
    installed = exe.parent_path().parent_path() / "share" / "prizma";
#endif
    if (is_dir(installed)) return installed;
  }
  // 2b. This code inside a shared object that is not the executable: the Python module, installed
  //     as <prefix>/lib/python3.X/site-packages/prizma/_prizma.so → <prefix>/share/prizma.
  {
    static const char anchor = 0;
    Dl_info info{};
    if (::dladdr(&anchor, &info) != 0 && info.dli_fname != nullptr && *info.dli_fname != '\0') {
      const std::filesystem::path so = std::filesystem::absolute(std::filesystem::path(info.dli_fname), ec);
      if (!ec && so != exe) {
        const auto prefix = so.parent_path().parent_path().parent_path().parent_path().parent_path();
        if (is_dir(prefix / "share" / "prizma")) return prefix / "share" / "prizma";
      }
    }
  }
  // 3. The source tree's data/ recorded at build time (running from the build tree).
#ifdef PRIZMA_SOURCE_DATA_DIR
  {
    const std::filesystem::path source_dir(PRIZMA_SOURCE_DATA_DIR);
    if (!source_dir.empty() && is_dir(source_dir)) return source_dir;
  }
#endif
  if (!installed.empty()) return installed;
  return std::filesystem::path("share") / "prizma";
}

std::filesystem::path data_file(const std::filesystem::path& relative) {
  const auto p = data_dir() / relative;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) {
    throw RuntimeError(p.string() + ": data file not found (set PRIZMA_DATA_DIR to Prizma's data folder)");
  }
  return p;
}

}  // namespace prizma::spectral
