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

// Runs body() and maps what it throws. body returns the exit code.
int run_tool(const std::string& program, const std::function<int()>& body);

// Version string "0.1.0 (git abc1234)" for --version and the files' prizma:version.
std::string prizma_version();

}  // namespace prizma::spectral
