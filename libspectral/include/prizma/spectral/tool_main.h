#pragma once
// The shared shape of every executable's main(): maps exceptions to one stderr line and an exit code.
//   InputError / CLI11 parse errors → "prog: error: <input>: <reason>", exit 2
//   other std::exception             → "prog: error: <what>", exit 1
#include <functional>
#include <string>

namespace prizma::spectral {

constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;

// Runs body() and maps what it throws. body returns the exit code. Then flushes standard output:
// a write error there (a full disk, /dev/full) turns exit 0 into 1 with
// "prog: error: standard output: cannot write: <reason>". SIGXFSZ is ignored, so a file-size limit
// fails the write (exit 1) instead of killing the tool.
int run_tool(const std::string& program, const std::function<int()>& body);

// The standard output check of run_tool on its own (for --help / --version): returns `rc`, or
// kExitRuntime with the error line when rc is kExitOk and standard output could not be written.
int check_standard_output(const std::string& program, int rc);

// Version string "0.1.0 (git abc1234)" for --version and the files' prizma:version.
std::string prizma_version();

}  // namespace prizma::spectral
