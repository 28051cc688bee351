#pragma once
// C libraries (libnifti, libpng through OpenImageIO) print their own diagnostics on stderr, before
// Prizma's one error line. While one of their calls runs, StderrCapture sends file descriptor 2 to
// a temporary file; finish() restores it and returns what was printed, on one line, to be put into
// the error message. Not thread-safe: use around single-threaded library calls only.
#include <unistd.h>

#include <cstdio>
#include <string>

namespace prizma::spectral {

namespace detail {
// The real stderr while a StderrCapture is active (-1 otherwise): the fatal handlers of startup_guard
// (a library crashing or calling std::terminate while loading, e.g. the image module) put it back
// so that their one line is seen, not lost in the capture's file.
inline volatile int g_captured_stderr = -1;
}  // namespace detail

class StderrCapture {
 public:
  StderrCapture() {
    std::fflush(stderr);
    m_file = std::tmpfile();
    if (m_file == nullptr) return;
    m_saved = ::dup(STDERR_FILENO);
    if (m_saved < 0 || ::dup2(::fileno(m_file), STDERR_FILENO) < 0) {
      restore();
    } else if (detail::g_captured_stderr < 0) {
      detail::g_captured_stderr = m_saved;
    }
  }
  ~StderrCapture() { restore(); }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  // Restores stderr; returns what was printed, on one line ("" when nothing).
  std::string finish() {
    restore();
    std::string text;
    if (m_file != nullptr) {
      std::rewind(m_file);
      char buf[512];
      std::size_t n = 0;
      while ((n = std::fread(buf, 1, sizeof buf, m_file)) > 0 && text.size() < 4096) text.append(buf, n);
      std::fclose(m_file);
      m_file = nullptr;
    }
    std::string line;
    for (char c : text) {
      if (c == '\n' || c == '\r' || c == '\t') c = ' ';
      if (c == ' ' && (line.empty() || line.back() == ' ')) continue;
      line += c;
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    return line;
  }

 private:
  void restore() {
    if (m_saved >= 0) {
      if (detail::g_captured_stderr == m_saved) detail::g_captured_stderr = -1;
      std::fflush(stderr);
      ::dup2(m_saved, STDERR_FILENO);
      ::close(m_saved);
      m_saved = -1;
    }
  }
  std::FILE* m_file = nullptr;
  int m_saved = -1;
};

// " (<library>: <what it printed>)" unless empty or already part of `message`.
inline std::string library_said(const std::string& library, const std::string& printed, const std::string& message = {}) {
  if (printed.empty() || message.find(printed) != std::string::npos) return {};
  return " (" + library + ": " + printed + ")";
}

}  // namespace prizma::spectral
