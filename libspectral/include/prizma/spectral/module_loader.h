#pragma once
// Prizma's modules: shared objects holding the code that needs a heavy library the tools do not
// link (OpenImageIO: imageio/, OpenVDB: vdb/), loaded with dlopen the first time it is needed so a
// run that needs neither never maps them (start-up, docs/results.md). A module is looked for, in order:
//   $<env_var> (a path: for tests and unusual installs; nothing else is tried then)
//   <folder of code_file()>/<file>   (next to the tool, or next to the Python module's _prizma.so)
//   installed_module_dir()/<file>    (<prefix>/lib/prizma: the installed layout, installed_prefix.h)
//   <build_path>                     (the build tree's module, the path it was built at)
#include <filesystem>
#include <string>
#include <vector>

namespace prizma::spectral {

struct ModuleSpec {
  std::string file;        // "libprizma_vdb.so"
  std::string env_var;     // "PRIZMA_VDB_MODULE"
  std::string name;        // "VDB module": the words of the messages
  std::string needed_for;  // "needed for OpenVDB volumes"
  std::string build_path;  // may be empty
  // Under an address-space limit (ulimit -v), refuse to load unless this much is left: for modules
  // whose libraries fail uncatchably inside their initialisers when a mapping fails. 0: no check.
  long long address_space_needed_mb = 0;
};

// The paths looked at, in order (above).
std::vector<std::filesystem::path> module_candidates(const ModuleSpec& spec);

// dlopen (RTLD_NOW | RTLD_LOCAL) of the first candidate that exists, under a LoadGuard (a crash or
// an exception in the module's libraries' initialisers is one line, exit 1); never dlclose'd.
// `chosen` is the path loaded. Throws RuntimeError:
//   "cannot find the <name> <file> (<needed_for>; looked in: …)"
//   "cannot load the <name> <path>: <dlerror>"
//   "out of memory loading the <name> <path> (…)"   (a mapping that failed under a memory limit)
void* open_module(const ModuleSpec& spec, std::filesystem::path& chosen);

}  // namespace prizma::spectral
