#pragma once
// Errors carried by every Prizma library: InputError for bad user input (exit code 2 in the tools),
// anything else derived from std::exception is a run-time failure (exit code 1).
#include <stdexcept>
#include <string>

namespace prizma::spectral {

// Bad user input. `input` names where it came from (a file path, "--bins", "scene.json:
// materials[1].albedo"); `reason` says what is wrong. what() is "<input>: <reason>".
class InputError : public std::runtime_error {
 public:
  InputError(std::string input, std::string reason)
      : std::runtime_error(input.empty() ? reason : input + ": " + reason),
        m_input(std::move(input)),
        m_reason(std::move(reason)) {}
  const std::string& input() const noexcept { return m_input; }
  const std::string& reason() const noexcept { return m_reason; }

 private:
  std::string m_input;
  std::string m_reason;
};

// A failure that is not the user's input (I/O after validation, library failure). Exit code 1.
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace prizma::spectral
