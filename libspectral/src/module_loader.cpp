#include "prizma/spectral/module_loader.h"

#include <dlfcn.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <system_error>

#include "prizma/spectral/error.h"
#include "prizma/spectral/installed_prefix.h"
#include "prizma/spectral/out_of_memory.h"
#include "prizma/spectral/startup_guard.h"

namespace prizma::spectral {

namespace {

namespace fs = std::filesystem;

bool address_space_limited() {
  rlimit lim{};
  return ::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY;
}

// MB of address space left under RLIMIT_AS (VmSize against the limit).
long long address_space_left_mb() {
  rlimit lim{};
  ::getrlimit(RLIMIT_AS, &lim);
  long long used_kb = 0;
  if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f) != nullptr)
      if (std::sscanf(line, "VmSize: %lld kB", &used_kb) == 1) break;
    std::fclose(f);
  }
  return static_cast<long long>(lim.rlim_cur / (1024 * 1024)) - used_kb / 1024;
}

}  // namespace

std::vector<fs::path> module_candidates(const ModuleSpec& spec) {
  std::vector<fs::path> out;
  if (const char* env = std::getenv(spec.env_var.c_str()); env != nullptr && *env != '\0') {
    out.emplace_back(env);
    return out;  // explicit: nothing else
  }
  if (const fs::path code = code_file(); !code.empty()) out.push_back(code.parent_path() / spec.file);
  if (const fs::path dir = installed_module_dir(); !dir.empty()) {
    const fs::path installed = dir / spec.file;
    if (out.empty() || out.front() != installed) out.push_back(installed);
  }
  if (!spec.build_path.empty()) out.emplace_back(spec.build_path);
  return out;
}

void* open_module(const ModuleSpec& spec, fs::path& chosen) {
  const std::vector<fs::path> paths = module_candidates(spec);
  chosen.clear();
  for (const fs::path& p : paths) {
    std::error_code ec;
    if (fs::exists(p, ec)) {
      chosen = p;
      break;
    }
  }
  if (chosen.empty()) {
    std::string looked;
    for (const fs::path& p : paths) looked += (looked.empty() ? "" : ", ") + p.string();
    throw RuntimeError("cannot find the " + spec.name + " " + spec.file + " (" + spec.needed_for +
                       "; looked in: " + looked + ")");
  }
  if (spec.address_space_needed_mb > 0 && address_space_limited()) {
    const long long left_mb = address_space_left_mb();
    if (left_mb < spec.address_space_needed_mb) {
      throw RuntimeError("out of memory loading the " + spec.name + " " + chosen.string() + " (" +
                         std::to_string(left_mb) + " MB of address space left under the limit; it maps about " +
                         std::to_string(spec.address_space_needed_mb) + " MB)");
    }
  }
  void* handle = nullptr;
  {
    // The module's libraries may start threads and allocate in their initialisers: a crash or an
    // exception there under a memory limit is reported as out of memory, as before main.
    const LoadGuard guard("loading the " + spec.name + " " + chosen.string());
    handle = ::dlopen(chosen.c_str(), RTLD_NOW | RTLD_LOCAL);
  }
  if (handle == nullptr) {
    const char* e = ::dlerror();
    const std::string why = e != nullptr ? e : "unknown error";
    if (message_says_out_of_memory(why) ||
        (address_space_limited() && why.find("failed to map segment") != std::string::npos)) {
      throw RuntimeError("out of memory loading the " + spec.name + " " + chosen.string() + " (" + why + ")");
    }
    throw RuntimeError("cannot load the " + spec.name + " " + chosen.string() + ": " + why);
  }
  return handle;
}

}  // namespace prizma::spectral
