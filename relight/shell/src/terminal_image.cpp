#include "prizma/relight/terminal_image.h"

#include <poll.h>
#include <sixel.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "prizma/relight/terminal_preview.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

const char* image_protocol_name(ImageProtocol p) {
  switch (p) {
    case ImageProtocol::Blocks: return "blocks";
    case ImageProtocol::Sixel: return "sixel";
    case ImageProtocol::Kitty: return "kitty";
  }
  return "blocks";
}

std::optional<ImageProtocol> parse_image_protocol(std::string_view name) {
  if (name == "blocks") return ImageProtocol::Blocks;
  if (name == "sixel") return ImageProtocol::Sixel;
  if (name == "kitty") return ImageProtocol::Kitty;
  return std::nullopt;
}

namespace {

int env_int(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long n = std::strtol(v, &end, 10);
  return (*end == '\0' && n > 0 && n < 100000) ? static_cast<int>(n) : 0;
}

std::string env_string(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

TerminalSize terminal_size(int fd) {
  TerminalSize size;
  winsize ws{};
  if (::ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
    size.columns = ws.ws_col;
    size.rows = ws.ws_row;
    size.width_px = ws.ws_xpixel;
    size.height_px = ws.ws_ypixel;
    return size;
  }
  if (const int c = env_int("COLUMNS")) size.columns = c;
  if (const int r = env_int("LINES")) size.rows = r;
  return size;
}

TerminalEnvironment TerminalEnvironment::from_process() {
  TerminalEnvironment env;
  env.prizma_images = env_string("PRIZMA_TERMINAL_IMAGES");
  env.term = env_string("TERM");
  env.term_program = env_string("TERM_PROGRAM");
  env.kitty_window_id = env_string("KITTY_WINDOW_ID");
  env.tmux = env_string("TMUX");
  return env;
}

std::optional<ImageProtocol> image_protocol_from_environment(const TerminalEnvironment& env) {
  if (auto forced = parse_image_protocol(env.prizma_images)) return forced;
  if (env.term == "dumb") return ImageProtocol::Blocks;
  // tmux passes the outer terminal's variables on to its panes but draws the screen itself.
  if (!env.tmux.empty() || env.term_program == "tmux") return std::nullopt;
  if (!env.kitty_window_id.empty() || env.term == "xterm-kitty" || env.term_program == "ghostty") {
    return ImageProtocol::Kitty;
  }
  if (env.term_program == "WezTerm" || env.term_program == "iTerm.app" || starts_with(env.term, "foot") ||
      starts_with(env.term, "mlterm") || starts_with(env.term, "contour") || starts_with(env.term, "yaft")) {
    return ImageProtocol::Sixel;
  }
  return std::nullopt;
}

ImageProtocol image_protocol_from_replies(std::string_view replies) {
  // Kitty graphics: "\x1b_Gi=31;OK\x1b\\".
  if (replies.find("\x1b_Gi=31;OK") != std::string_view::npos) return ImageProtocol::Kitty;
  // DA1: "\x1b[?" attributes separated by ';' then 'c'; attribute 4 is sixel graphics.
  const std::size_t start = replies.find("\x1b[?");
  if (start == std::string_view::npos) return ImageProtocol::Blocks;
  const std::size_t end = replies.find('c', start);
  if (end == std::string_view::npos) return ImageProtocol::Blocks;
  std::string_view attrs = replies.substr(start + 3, end - start - 3);
  while (!attrs.empty()) {
    const std::size_t semi = attrs.find(';');
    if (attrs.substr(0, semi) == "4") return ImageProtocol::Sixel;
    if (semi == std::string_view::npos) break;
    attrs.remove_prefix(semi + 1);
  }
  return ImageProtocol::Blocks;
}

ImageProtocol query_image_protocol(int in_fd, int out_fd, int timeout_ms, bool ask_kitty) {
  if (!::isatty(in_fd) || !::isatty(out_fd)) return ImageProtocol::Blocks;
  termios saved{};
  if (::tcgetattr(in_fd, &saved) != 0) return ImageProtocol::Blocks;
  termios raw = saved;
  raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  if (::tcsetattr(in_fd, TCSANOW, &raw) != 0) return ImageProtocol::Blocks;
  // Kitty graphics query, DA1, then DSR, which every terminal answers ("\x1b[0n"), last: replies come
  // in order, so once the DSR reply is in, nothing else is coming.
  static constexpr std::string_view kKittyQuery = "\x1b_Gi=31,s=1,v=1,a=q,t=d,f=24;AAAA\x1b\\";
  const std::string query = std::string(ask_kitty ? kKittyQuery : "") + "\x1b[c\x1b[5n";
  std::string replies;
  bool answered = false;
  if (::write(out_fd, query.data(), query.size()) == static_cast<ssize_t>(query.size())) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (!answered) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd p{in_fd, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
      char buf[256];
      const ssize_t n = ::read(in_fd, buf, sizeof buf);
      if (n <= 0) break;
      replies.append(buf, static_cast<std::size_t>(n));
      answered = replies.find("\x1b[0n") != std::string::npos;
    }
  }
  // A late reply would otherwise be read as typed keys.
  ::tcsetattr(in_fd, answered ? TCSANOW : TCSAFLUSH, &saved);
  return image_protocol_from_replies(replies);
}

ImageProtocol detect_image_protocol(int in_fd, int out_fd) {
  if (!::isatty(out_fd)) return ImageProtocol::Blocks;
  const TerminalEnvironment env = TerminalEnvironment::from_process();
  if (auto p = image_protocol_from_environment(env)) return *p;
  return query_image_protocol(in_fd, out_fd, kTerminalReplyTimeoutMs, env.tmux.empty());
}

Rgb8Image resample_rgb8(const std::vector<float>& rgb, int width, int height, int to_width, int to_height) {
  Rgb8Image out;
  if (width <= 0 || height <= 0 || to_width <= 0 || to_height <= 0) return out;
  out.width = to_width;
  out.height = to_height;
  out.pixels.resize(3 * static_cast<std::size_t>(to_width) * static_cast<std::size_t>(to_height));
  for (int ty = 0; ty < to_height; ++ty) {
    const int y0 = static_cast<int>(static_cast<long long>(ty) * height / to_height);
    const int y1 = std::max(y0 + 1, static_cast<int>(static_cast<long long>(ty + 1) * height / to_height));
    for (int tx = 0; tx < to_width; ++tx) {
      const int x0 = static_cast<int>(static_cast<long long>(tx) * width / to_width);
      const int x1 = std::max(x0 + 1, static_cast<int>(static_cast<long long>(tx + 1) * width / to_width));
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        int count = 0;
        for (int y = y0; y < std::min(y1, height); ++y)
          for (int x = x0; x < std::min(x1, width); ++x, ++count) {
            const float v = rgb[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + x) + c];
            sum += std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
          }
        out.pixels[3 * (static_cast<std::size_t>(ty) * to_width + tx) + c] =
            static_cast<std::uint8_t>(count ? std::lround(255.0 * sum / count) : 0);
      }
    }
  }
  return out;
}

void fit_to_terminal(int width, int height, const TerminalSize& term, int reserved_rows, int& out_width,
                     int& out_height) {
  const int rows = std::max(1, term.rows - std::max(0, reserved_rows));
  const double cell_w = term.width_px > 0 ? static_cast<double>(term.width_px) / term.columns : 10.0;
  const double cell_h = term.height_px > 0 ? static_cast<double>(term.height_px) / term.rows : 20.0;
  const double max_w = cell_w * term.columns, max_h = cell_h * rows;
  double scale = std::min(max_w / std::max(width, 1), max_h / std::max(height, 1));
  if (scale > 1.0) scale = std::min(8.0, std::floor(scale));
  out_width = std::max(1, static_cast<int>(std::floor(width * scale)));
  out_height = std::max(1, static_cast<int>(std::floor(height * scale)));
}

std::string encode_sixel(const Rgb8Image& image) {
  std::string out;
  if (image.width <= 0 || image.height <= 0) return out;
  std::vector<unsigned char> pixels(image.pixels.begin(), image.pixels.end());  // libsixel takes non-const
  sixel_output_t* output = nullptr;
  sixel_dither_t* dither = nullptr;
  auto write = [](char* data, int size, void* priv) {
    static_cast<std::string*>(priv)->append(data, static_cast<std::size_t>(size));
    return size;
  };
  SIXELSTATUS status = sixel_output_new(&output, write, &out, nullptr);
  if (!SIXEL_FAILED(status)) status = sixel_dither_new(&dither, 256, nullptr);
  if (!SIXEL_FAILED(status)) {
    status = sixel_dither_initialize(dither, pixels.data(), image.width, image.height, SIXEL_PIXELFORMAT_RGB888,
                                     SIXEL_LARGE_AUTO, SIXEL_REP_AUTO, SIXEL_QUALITY_AUTO);
  }
  if (!SIXEL_FAILED(status)) status = sixel_encode(pixels.data(), image.width, image.height, 8, dither, output);
  if (dither) sixel_dither_unref(dither);
  if (output) sixel_output_unref(output);
  if (SIXEL_FAILED(status)) {
    throw spectral::RuntimeError(std::string("sixel encoding failed: ") + sixel_helper_format_error(status));
  }
  return out;
}

namespace {

std::string base64(const std::uint8_t* data, std::size_t n) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  for (std::size_t i = 0; i < n; i += 3) {
    const std::uint32_t b = (std::uint32_t{data[i]} << 16) | (i + 1 < n ? std::uint32_t{data[i + 1]} << 8 : 0u) |
                            (i + 2 < n ? std::uint32_t{data[i + 2]} : 0u);
    out += kDigits[(b >> 18) & 63];
    out += kDigits[(b >> 12) & 63];
    out += i + 1 < n ? kDigits[(b >> 6) & 63] : '=';
    out += i + 2 < n ? kDigits[b & 63] : '=';
  }
  return out;
}

}  // namespace

std::string encode_kitty(const Rgb8Image& image) {
  std::string out;
  if (image.width <= 0 || image.height <= 0) return out;
  const std::string payload = base64(image.pixels.data(), image.pixels.size());
  // The protocol takes at most 4096 bytes of base64 per escape; m=1 on every chunk but the last.
  constexpr std::size_t kChunk = 4096;
  for (std::size_t pos = 0; pos < payload.size(); pos += kChunk) {
    const bool last = pos + kChunk >= payload.size();
    out += "\x1b_G";
    if (pos == 0) out += "a=T,f=24,q=2,s=" + std::to_string(image.width) + ",v=" + std::to_string(image.height) + ",";
    out += last ? "m=0;" : "m=1;";
    out.append(payload, pos, kChunk);
    out += "\x1b\\";
  }
  return out;
}

ImageRoute image_route(ImageProtocol protocol, const TmuxFacts& tmux) {
  ImageRoute route;
  if (!tmux.inside || protocol == ImageProtocol::Blocks) return route;
  if (protocol == ImageProtocol::Sixel && !tmux.sixel) {
    route.shown = false;
    route.why = "this tmux draws no sixel images (its device attributes lack sixel): a tmux built with sixel "
                "(3.4 or later, configured with --enable-sixel) does, or run prizma-relight outside tmux; "
                "'show blocks' draws here";
  } else if (protocol == ImageProtocol::Kitty) {
    route.shown = tmux.passthrough;
    route.tmux_passthrough = tmux.passthrough;
    if (!tmux.passthrough) {
      route.why = "inside tmux, kitty graphics reach the terminal only through tmux's passthrough, which is off: "
                  "run 'tmux set -g allow-passthrough on' (tmux 3.3 or later; the outer terminal must draw kitty "
                  "graphics) and show kitty again; 'show blocks' draws here";
    }
  }
  return route;
}

namespace {

// What `command` (run by /bin/sh) writes on stdout, its end of line removed; empty when it fails.
std::string command_output(const char* command) {
  FILE* p = ::popen(command, "r");
  if (!p) return {};
  std::string out;
  char buf[256];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  if (::pclose(p) != 0) return {};
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

}  // namespace

TmuxFacts tmux_facts(ImageProtocol protocol, int in_fd, int out_fd) {
  TmuxFacts facts;
  facts.inside = !TerminalEnvironment::from_process().tmux.empty();
  if (!facts.inside) return facts;
  if (protocol == ImageProtocol::Sixel) {
    facts.sixel = query_image_protocol(in_fd, out_fd, 300, false) == ImageProtocol::Sixel;
  } else if (protocol == ImageProtocol::Kitty) {
    // A flag in tmux 3.3 (0 / 1), a choice in later ones (off / on / all).
    const std::string v = command_output("tmux display-message -p '#{allow-passthrough}' 2>/dev/null");
    facts.passthrough = v == "1" || v == "on" || v == "all" || v == "2";
  }
  return facts;
}

std::string tmux_passthrough(std::string_view escapes) {
  std::string out;
  while (!escapes.empty()) {
    const std::size_t st = escapes.find("\x1b\\");
    const std::size_t end = st == std::string_view::npos ? escapes.size() : st + 2;
    out += "\x1bPtmux;";
    for (const char c : escapes.substr(0, end)) {
      if (c == '\x1b') out += '\x1b';
      out += c;
    }
    out += "\x1b\\";
    escapes.remove_prefix(end);
  }
  return out;
}

void draw_terminal_image(std::ostream& out, const std::vector<float>& rgb, int width, int height,
                         ImageProtocol protocol, const TerminalSize& term, int reserved_rows, bool through_tmux) {
  if (protocol == ImageProtocol::Blocks) {
    print_terminal_thumbnail(out, rgb, width, height, term.columns, std::max(1, term.rows - reserved_rows));
    return;
  }
  int w = 0, h = 0;
  fit_to_terminal(width, height, term, reserved_rows, w, h);
  const Rgb8Image small = resample_rgb8(rgb, width, height, w, h);
  const std::string escapes = protocol == ImageProtocol::Sixel ? encode_sixel(small) : encode_kitty(small);
  out << (through_tmux ? tmux_passthrough(escapes) : escapes) << "\n" << std::flush;
}

}  // namespace prizma::relight
