#include "prizma/spectral/tool_main.h"

#include <exception>
#include <iostream>
#include <new>

#include "prizma/spectral/error.h"

#ifndef PRIZMA_VERSION
#define PRIZMA_VERSION "0.0.0"
#endif
namespace prizma::spectral {

namespace detail {
// Generated at build time by cmake/PrizmaRevision.cmake ("" when unknown).
const char* git_revision();
}  // namespace detail

std::string prizma_version() {
  std::string v = PRIZMA_VERSION;
  const std::string rev = detail::git_revision();
  if (!rev.empty()) v += " (git " + rev + ")";
  return v;
}

int run_tool(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    std::cerr << program << ": error: out of memory\n";
    return kExitRuntime;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitRuntime;
  } catch (...) {
    std::cerr << program << ": error: unknown failure\n";
    return kExitRuntime;
  }
}

}  // namespace prizma::spectral
