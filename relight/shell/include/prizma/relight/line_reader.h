#pragma once
// LineReader: where the interactive shell's command lines come from. Two implementations: a plain
// stream (pipes, files, tests) and a terminal with line editing, history and tab completion
// (Debian's libedit).
#include <cstdio>
#include <filesystem>
#include <functional>
#include <istream>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace prizma::relight {

class LineReader {
 public:
  virtual ~LineReader() = default;
  // Reads the next line (no newline). Returns false at the end of input.
  virtual bool read_line(std::string& line) = 0;
};

// Reads plain lines from a stream; prints `prompt` to `prompt_out` (when given) before each.
class StreamLineReader final : public LineReader {
 public:
  explicit StreamLineReader(std::istream& in, std::ostream* prompt_out = nullptr, std::string prompt = "> ");
  bool read_line(std::string& line) override;

 private:
  std::istream& m_in;
  std::ostream* m_prompt_out;
  std::string m_prompt;
};

// Tab completion: given the words before the one being typed (unquoted) and that word's beginning,
// the candidates for it (full words, unquoted; those not starting with `partial` are dropped by the
// reader). A candidate ending in ':' or '/' is a prefix: no blank is added after it.
using Completer = std::function<std::vector<std::string>(const std::vector<std::string>& before,
                                                         const std::string& partial)>;

struct TerminalReaderOptions {
  std::string program = "prizma-relight";  // libedit's name for ~/.editrc sections
  std::string prompt = "relight> ";
  std::filesystem::path history_file;  // empty: history for this session only
  int history_size = 1000;
  Completer completer;
  FILE* in = stdin;
  FILE* out = stdout;
  std::ostream* warnings = nullptr;  // history that cannot be written: one warning here
};

// Emacs-style line editing on a terminal (arrow keys, Ctrl-R search, …), history loaded from and
// saved (after every line, atomically) to options.history_file, Tab completing through the completer
// with quotes where a word needs them. A history file that cannot be read or written is a warning,
// never an error.
std::unique_ptr<LineReader> make_terminal_line_reader(TerminalReaderOptions options);

// $XDG_STATE_HOME/prizma/relight_history, $XDG_STATE_HOME defaulting to ~/.local/state (a relative
// XDG_STATE_HOME is ignored, per the XDG base directory spec); empty when neither it nor HOME is set.
std::filesystem::path default_history_file(const std::string& name = "relight_history");

// The candidates of `candidates` that start with `partial`, and their longest common prefix.
std::vector<std::string> matching_candidates(const std::vector<std::string>& candidates, const std::string& partial);
std::string common_prefix(const std::vector<std::string>& words);

}  // namespace prizma::relight
