#pragma once
// The interactive command loop of prizma-relight -i, reading commands from a LineReader: a terminal
// with line editing, history and completion, or any stream (a pipe, a file, a test's string).
//   light NAME SPEC | light SPEC   exposure EV   cmf NAME   display NAME   adapt on|off   undo
//   status   lights   show [PROTOCOL]   save FILE   probe X Y   compare X1 Y1 X2 Y2 [R]   clear   help
//   quit
#include <cstddef>
#include <filesystem>
#include <functional>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "prizma/relight/line_reader.h"
#include "prizma/relight/relight_session.h"
#include "prizma/relight/terminal_image.h"

namespace prizma::relight {

struct InteractiveOptions {
  std::filesystem::path preview;  // rewritten after every change when non-empty
  bool show = false;              // draw the image once, at the start
  bool show_every = false;        // draw the image after every change
  bool prompt = false;            // stream input: print "> " before each command
  // How images are drawn: `detect_protocol`, when set, is asked once, at the first drawing (the
  // terminal runner queries the terminal there); else `protocol`.
  ImageProtocol protocol = ImageProtocol::Blocks;
  std::function<ImageProtocol()> detect_protocol;
  // The window to fit images to: `terminal_size`, when set, is asked at every drawing; else `terminal`.
  TerminalSize terminal;
  std::function<TerminalSize()> terminal_size;
  // Asked before every sixel or kitty drawing, when set: whether it would reach the screen (inside
  // tmux: image_route, terminal_image.h); a drawing that would not is an error saying what to do.
  std::function<ImageRoute(ImageProtocol)> image_route;
  bool terminal_output = false;   // `out` is a terminal: `clear` clears it (else `clear` writes nothing)
  std::size_t undo_levels = 100;  // changes `undo` can take back
};

// Runs until "quit" or end of input. A failing command prints "error: <message>" to `out` and the
// session goes on. Returns the number of commands that failed.
int run_interactive(RelightSession& session, LineReader& in, std::ostream& out, const InteractiveOptions& opts);
int run_interactive(RelightSession& session, std::istream& in, std::ostream& out, const InteractiveOptions& opts);

// std::cin / std::cout: with libedit (history in default_history_file(), completion, terminal images
// detected) when both are terminals, else plain lines. Warnings (history not saved) go to `warnings`.
int run_interactive_terminal(RelightSession& session, InteractiveOptions opts, std::ostream& warnings);

// What Tab offers for the word being typed: command names, light names, light specs (libspectral's
// named spectra, off, blackbody:, gaussian:, box:, csv:FILE), the OCIO config's displays, observers,
// on/off, protocols, file names for save.
std::vector<std::string> complete_command(RelightSession& session, const std::vector<std::string>& before,
                                          const std::string& partial);

}  // namespace prizma::relight
