#pragma once
// Shared pieces of the libFuzzer targets: a per-process scratch folder, file writing, and the one
// rule every target checks — bad input may throw prizma::spectral::InputError and nothing else.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "prizma/spectral/error.h"

namespace prizma::fuzz {

// A scratch folder unique to this process, removed at exit.
class ScratchDir {
 public:
  explicit ScratchDir(std::string_view tag) {
    std::error_code ec;
    std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    if (ec) base = "/tmp";
    m_path = base / ("prizma-fuzz-" + std::string(tag) + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(m_path, ec);
    std::filesystem::create_directories(m_path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz harness: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// Runs f; returns true when it returned normally, false when it threw InputError. Any other
// exception is a bug of the code under test: print it and abort, so libFuzzer records the input.
template <class F>
bool accepts(const char* what, F&& f) {
  try {
    f();
    return true;
  } catch (const prizma::spectral::InputError&) {
    return false;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "BUG: %s threw a non-InputError exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "BUG: %s threw a non-std exception\n", what);
    std::abort();
  }
}

// An invariant that valid output must keep; a failure is a bug.
#define PRIZMA_FUZZ_CHECK(cond, ...)                                        \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::fprintf(stderr, "BUG: invariant failed: %s: ", #cond);          \
      std::fprintf(stderr, __VA_ARGS__);                                   \
      std::fprintf(stderr, "\n");                                          \
      std::abort();                                                        \
    }                                                                      \
  } while (0)

}  // namespace prizma::fuzz
