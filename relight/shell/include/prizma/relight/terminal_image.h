#pragma once
// Drawing an image inline in a terminal: sixel (through libsixel), the kitty graphics protocol, or
// true-colour "▀" half blocks everywhere else; which one a terminal takes is detected from its
// environment or, failing that, by asking it (device attributes) with a timeout.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace prizma::relight {

enum class ImageProtocol { Blocks, Sixel, Kitty };

// "blocks", "sixel", "kitty"; parse returns nullopt for anything else.
const char* image_protocol_name(ImageProtocol p);
std::optional<ImageProtocol> parse_image_protocol(std::string_view name);

// Character cells and, when the terminal reports them, pixels of the whole window.
struct TerminalSize {
  int columns = 80, rows = 24;
  int width_px = 0, height_px = 0;  // 0: unknown
};
// TIOCGWINSZ on fd; else $COLUMNS / $LINES; else 80×24.
TerminalSize terminal_size(int fd);

// The environment variables that tell terminals apart.
struct TerminalEnvironment {
  std::string prizma_images;  // PRIZMA_TERMINAL_IMAGES: blocks | sixel | kitty forces one
  std::string term, term_program, kitty_window_id, tmux;
  static TerminalEnvironment from_process();
};
// What the environment alone says; nullopt when only asking the terminal can tell. Inside tmux the
// outer terminal's variables are ignored (tmux answers for itself).
std::optional<ImageProtocol> image_protocol_from_environment(const TerminalEnvironment& env);
// What a terminal's replies to the kitty graphics query and to DA1 ("\x1b[?62;4;22c": 4 = sixel) say.
ImageProtocol image_protocol_from_replies(std::string_view replies);
// How long the query waits for the terminal's replies. Every terminal answers DSR, in milliseconds
// when it is not busy; on a loaded machine tmux took over 300 ms (the bound until issue 21), and a
// reply that comes after the query has given up is read by the line editor as typed keys
// ("1;2cquit: unknown command"). So the query waits for the DSR reply itself; only a pseudo-terminal
// whose other end answers nothing (a script) costs the whole bound, once per session.
constexpr int kTerminalReplyTimeoutMs = 5000;
// Sends the kitty graphics query (when ask_kitty), DA1 and DSR to out_fd and reads the replies from
// in_fd (raw mode, restored after) until the DSR reply, at most timeout_ms. Blocks when either is not
// a terminal or nothing answers in time: it never waits longer.
ImageProtocol query_image_protocol(int in_fd, int out_fd, int timeout_ms = kTerminalReplyTimeoutMs,
                                   bool ask_kitty = true);
// Environment first, then the query (only when both fds are terminals; inside tmux without the kitty
// query, which tmux would take for a window title).
ImageProtocol detect_image_protocol(int in_fd, int out_fd);

// Whether an image drawn with a protocol reaches the screen, and how. Inside tmux (TMUX set) tmux
// draws the pane itself: sixel images only when tmux was built with sixel (3.4 or later, configured
// with --enable-sixel; it then answers the device-attributes query with attribute 4), kitty graphics
// only through tmux's passthrough (allow-passthrough on, tmux 3.3 or later), each escape wrapped for
// it. Outside tmux, and half blocks everywhere, images go as they are.
struct TmuxFacts {
  bool inside = false;       // TMUX is set
  bool sixel = false;        // tmux answered DA1 with attribute 4
  bool passthrough = false;  // allow-passthrough is on (or all) for this pane
};
struct ImageRoute {
  bool shown = true;              // false: nothing would appear on the screen; `why` says what to do
  bool tmux_passthrough = false;  // send the escapes through tmux's passthrough (tmux_passthrough())
  std::string why;
};
ImageRoute image_route(ImageProtocol protocol, const TmuxFacts& tmux);
// The facts for this process: TMUX from the environment; inside tmux only, and only what `protocol`
// needs, tmux's answer to DA1 on the terminal (in_fd, out_fd: query_image_protocol) or
// `tmux display-message -p '#{allow-passthrough}'` (tmux found through TMUX, as every tmux client).
TmuxFacts tmux_facts(ImageProtocol protocol, int in_fd, int out_fd);
// Escape sequences, each ending in ST (ESC \), wrapped one by one in tmux's passthrough:
// ESC P tmux; <the sequence with every ESC doubled> ESC \ (one at a time: tmux limits a sequence's size).
std::string tmux_passthrough(std::string_view escapes);

// An interleaved 8-bit RGB image.
struct Rgb8Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;
};
// Display-encoded float RGB (clamped to [0, 1], non-finite → 0) box-filtered to width × height.
Rgb8Image resample_rgb8(const std::vector<float>& rgb, int width, int height, int to_width, int to_height);
// The pixel size to draw a width × height image at in a terminal of this size: it fits the window
// less `reserved_rows` text lines, shrunk keeping the aspect ratio, or enlarged by a whole factor
// (at most 8) when it is small. Cells of unknown pixel size count as 10 × 20 pixels.
void fit_to_terminal(int width, int height, const TerminalSize& term, int reserved_rows, int& out_width,
                     int& out_height);

// The escape sequences themselves (tests decode them).
std::string encode_sixel(const Rgb8Image& image);  // DCS … ST, 256 colours; throws RuntimeError if libsixel fails
std::string encode_kitty(const Rgb8Image& image);  // APC G chunks (f=24, a=T, q=2: no replies), base64

// Draws the image sized to the terminal with the protocol, and a newline after it; sixel and kitty
// escapes through tmux's passthrough when `through_tmux`.
void draw_terminal_image(std::ostream& out, const std::vector<float>& rgb, int width, int height,
                         ImageProtocol protocol, const TerminalSize& term, int reserved_rows = 3,
                         bool through_tmux = false);

}  // namespace prizma::relight
