#include "prizma/spectral/installed_prefix.h"

#include <dlfcn.h>
#include <link.h>

#include <system_error>

namespace prizma::spectral {

namespace fs = std::filesystem;

fs::path code_file() {
  // The object that holds this function: dladdr1 gives its link map, whose name is empty for the
  // main executable (the tools) and the path it was opened by for a shared object (_prizma.so).
  static const char anchor = 0;
  Dl_info info{};
  link_map* map = nullptr;
  std::error_code ec;
  if (::dladdr1(&anchor, &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) != 0 && map != nullptr &&
      map->l_name != nullptr && *map->l_name != '\0') {
    const fs::path so = fs::absolute(fs::path(map->l_name), ec);
    return ec ? fs::path() : so.lexically_normal();
  }
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe;
}

fs::path installed_prefix() {
  const fs::path file = code_file();
  if (file.empty()) return {};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec && file == exe) {
#ifdef PRIZMA_INSTALL_PREFIX_FROM_BINDIR
    fs::path prefix = (file.parent_path() / PRIZMA_INSTALL_PREFIX_FROM_BINDIR).lexically_normal();
    return prefix.has_filename() ? prefix : prefix.parent_path();  // "/x/bin/.." → "/x", not "/x/"
#else
    return file.parent_path().parent_path();
#endif
  }
  // <prefix>/lib/python3.X/site-packages/prizma/_prizma.so: five folders up.
  return file.parent_path().parent_path().parent_path().parent_path().parent_path();
}

fs::path installed_module_dir() {
  const fs::path prefix = installed_prefix();
  return prefix.empty() ? fs::path() : prefix / "lib" / "prizma";
}

}  // namespace prizma::spectral
