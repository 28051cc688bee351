// run_tool and the standard output check (prizma/tool/tool_main.h).
#include "prizma/tool/tool_main.h"

#include <csignal>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/out_of_memory.h"
#include "prizma/spectral/startup_guard.h"

namespace prizma::tool {

using spectral::InputError;
using spectral::InputRecording;
using spectral::end_startup_guard;
using spectral::is_out_of_memory;

int check_standard_output(const std::string& program, int rc) {
  // std::cout is synchronised with stdio (the default), so both end in stdout's buffer; flush it
  // first, while the reason of a failure is still in errno.
  errno = 0;
  const bool flush_failed = std::fflush(stdout) != 0;
  const int err = errno;
  std::cout.flush();
  if (!flush_failed && !std::ferror(stdout) && std::cout.good()) return rc;
  if (rc != kExitOk) return rc;  // the run already failed and said why
  std::cerr << program << ": error: standard output: cannot write"
            << (flush_failed && err != 0 ? std::string(": ") + std::strerror(err) : std::string()) << "\n";
  return kExitRuntime;
}

int run_tool(const std::string& program, const std::function<int()>& body) {
  end_startup_guard();
  // A file-size limit (ulimit -f) makes a write fail with EFBIG, reported like any failed write,
  // instead of killing the process with SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  // Every file the tool reads is recorded: no output of the run may replace one (input_file.h).
  const InputRecording inputs;
  try {
    return check_standard_output(program, body());
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    std::cerr << program << ": error: out of memory\n";
    return kExitRuntime;
  } catch (const std::exception& e) {
    if (is_out_of_memory(e)) {
      std::cerr << program << ": error: out of memory: cannot start a thread (" << e.what() << ")\n";
    } else {
      std::cerr << program << ": error: " << e.what() << "\n";
    }
    return kExitRuntime;
  } catch (...) {
    std::cerr << program << ": error: unknown failure\n";
    return kExitRuntime;
  }
}

}  // namespace prizma::tool
