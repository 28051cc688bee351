#pragma once
// The interactive command loop of prizma-relight -i, reading commands from any stream (a terminal or
// a pipe), so tests drive it without a terminal.
//   light NAME SPEC | light SPEC   exposure EV   cmf NAME   display NAME   save FILE
//   probe X Y   compare X1 Y1 X2 Y2 [R]   lights   help   quit
#include <filesystem>
#include <istream>
#include <ostream>

#include "prizma/relight/relight_session.h"

namespace prizma::relight {

struct InteractiveOptions {
  std::filesystem::path preview;  // rewritten after every change when non-empty
  bool show = false;              // print a terminal thumbnail after every change
  bool prompt = false;            // print "> " before each command (terminals)
};

// Runs until "quit" or end of input. A failing command prints "error: <message>" to `out` and the
// session goes on. Returns the number of commands that failed.
int run_interactive(RelightSession& session, std::istream& in, std::ostream& out,
                    const InteractiveOptions& opts);

}  // namespace prizma::relight
