#include "prizma/relight/interactive_shell.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <chrono>
#include <deque>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "prizma/relight/command_words.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::relight {

namespace {

namespace fs = std::filesystem;
using spectral::InputError;

constexpr const char* kHelp =
    "commands (arguments with blanks in quotes: display \"Display P3\"):\n"
    "  light NAME SPEC       set one light layer (SPEC: D65, A, F11, LED-B1, gaussian:550:20, blackbody:3200K, off, …*k)\n"
    "  light SPEC            set every light layer\n"
    "  exposure EV           exposure in stops\n"
    "  cmf NAME              1931, 1964, 2012-2, 2012-10\n"
    "  display NAME          OCIO display (sRGB, \"Display P3\", Rec.2020)\n"
    "  adapt on|off          Bradford adaptation from the lights' white to D65\n"
    "  undo                  take back the last change (several levels)\n"
    "  status                every current setting\n"
    "  lights                the layers, their current and default lights\n"
    "  show [blocks|sixel|kitty]  draw the image in the terminal\n"
    "  save FILE             write the current image (.png, .tif, .exr)\n"
    "  probe X Y [LIGHT]     bins, XYZ, Lab (D65 white) and sRGB at a pixel; fluorescent files: the\n"
    "                        excitation–emission map per light (or of LIGHT)\n"
    "  compare X1 Y1 X2 Y2 [R]  CIEDE2000 between two pixels or the means of two (2R+1)² squares\n"
    "  clear                 clear the screen (Ctrl-L too)\n"
    "  help                  this text\n"
    "  quit                  leave (Ctrl-D on an empty line too; Ctrl-C only cancels the line)\n";

const std::vector<std::string> kCommands = {"adapt",  "clear", "cmf",   "compare", "display", "exposure",
                                            "help",   "light", "lights", "probe",  "quit",    "save",
                                            "show",   "status", "undo"};

double to_double(const std::string& s, const std::string& input) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) throw InputError(input, "not a number: \"" + s + "\"");
  return v;
}

// A pixel coordinate or radius: a whole decimal number within [0, limit) (limit: the image's width or
// height), never a fraction, an exponent, inf or nan.
int to_index(const std::string& s, const std::string& input, long long limit, const std::string& what) {
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range) {
    throw InputError(input, s + " is outside the " + what + " (0 to " + std::to_string(limit - 1) + ")");
  }
  if (ec != std::errc() || ptr != s.data() + s.size() || s.empty()) {
    throw InputError(input, "not a whole number: \"" + s + "\"");
  }
  if (v < 0 || v >= limit) {
    throw InputError(input, s + " is outside the " + what + " (0 to " + std::to_string(limit - 1) + ")");
  }
  return static_cast<int>(v);
}

void expect_args(const std::vector<std::string>& w, std::size_t lo, std::size_t hi, const char* usage) {
  if (w.size() - 1 < lo || w.size() - 1 > hi) throw InputError(w[0], std::string("usage: ") + usage);
}

std::string vec3(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << v[0] << ' ' << v[1] << ' ' << v[2];
  return s.str();
}

std::string ms_text(double ms) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << ms << " ms";
  return s.str();
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The excitation–emission map of a bispectral pixel for one light: a row per emission (out) bin that
// the file holds pairs for, longest wavelength on top, a column per excitation (in) bin; each held
// M[out][in] as a digit 0–9 of the pixel's largest value (round(9·M/max): 9 is the largest, 0 a value
// below 1/18 of it), '.' for zero, '\' on the diagonal (the T bins above), blank where the file holds
// no pair.
std::string excitation_emission_map(const spectral::SpectralImage& img, const std::string& light,
                                    const std::vector<float>& values) {
  std::vector<int> ins, outs;
  float max = 0.0f;
  std::size_t arg = 0;
  for (std::size_t q = 0; q < img.reradiation.size(); ++q) {
    ins.push_back(img.reradiation[q].in);
    outs.push_back(img.reradiation[q].out);
    if (values[q] > max) {
      max = values[q];
      arg = q;
    }
  }
  for (auto* v : {&ins, &outs}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  auto nm = [&](int bin) { return std::to_string(static_cast<int>(std::lround(img.bins.centre_nm(bin)))); };
  std::ostringstream o;
  o << "  excitation–emission " << light << ": M[out][in] as 0–9 of its largest, ";
  if (max > 0.0f) {
    o << std::setprecision(4) << max << " (" << nm(img.reradiation[arg].in) << " → " << nm(img.reradiation[arg].out)
      << " nm)";
  } else {
    o << "0 (no re-radiation at this pixel)";
  }
  o << "; . zero, \\ diagonal\n    out\\in";
  for (int in : ins) o << std::setw(4) << nm(in);
  o << "\n";
  for (auto it = outs.rbegin(); it != outs.rend(); ++it) {
    o << "    " << std::setw(6) << nm(*it);
    for (int in : ins) {
      char cell = ' ';
      if (in == *it) cell = '\\';
      for (std::size_t q = 0; q < img.reradiation.size(); ++q) {
        if (img.reradiation[q].in != in || img.reradiation[q].out != *it) continue;
        const float v = values[q];
        cell = v == 0.0f || !(max > 0.0f) ? '.' : static_cast<char>('0' + std::clamp(static_cast<int>(std::lround(9.0 * v / max)), 0, 9));
      }
      o << "   " << cell;
    }
    o << "\n";
  }
  return o.str();
}

// The state of one session besides the RelightSession: undo levels, the drawing protocol once known.
class Shell {
 public:
  Shell(RelightSession& session, std::ostream& out, const InteractiveOptions& opts)
      : m_session(session), m_out(out), m_opts(opts) {}

  // After a change: relight, report the time, rewrite the preview, draw with --show-every.
  void refresh(bool first = false) {
    const double ms = m_session.relight();
    m_last_relight_ms = ms;
    std::string line = "relit in " + ms_text(ms);
    if (!m_opts.preview.empty()) {
      const auto start = std::chrono::steady_clock::now();
      m_session.save(m_opts.preview, "--preview");
      line += ", preview written in " + ms_text(ms_since(start));
    }
    m_out << line << "\n";
    if (m_opts.show_every || (first && m_opts.show)) draw(std::nullopt);
  }

  // Draws the image; a protocol whose image would not reach the screen (inside tmux) is an InputError
  // saying what to do, never a drawing of nothing.
  void draw(std::optional<ImageProtocol> forced) {
    if (!forced && !m_protocol) m_protocol = m_opts.detect_protocol ? m_opts.detect_protocol() : m_opts.protocol;
    const ImageProtocol protocol = forced ? *forced : *m_protocol;
    ImageRoute route;
    if (protocol != ImageProtocol::Blocks && m_opts.image_route) route = m_opts.image_route(protocol);
    if (!route.shown) throw InputError(std::string("show ") + image_protocol_name(protocol), route.why);
    const TerminalSize size = m_opts.terminal_size ? m_opts.terminal_size() : m_opts.terminal;
    const spectral::XyzImage& img = m_session.xyz();
    m_out << std::flush;
    draw_terminal_image(m_out, spectral::to_display(img, m_session.display()), img.width, img.height, protocol, size, 3,
                        route.tmux_passthrough);
    if (route.tmux_passthrough) m_out << "(kitty graphics through tmux's passthrough: tmux neither moves nor clears them)\n";
  }

  // Applies a change through `change` (which throws, leaving the session as it was, on bad input),
  // keeps the settings before it for undo, relights.
  template <typename Change>
  void change(Change&& change) {
    RelightSettings before = m_session.settings();
    change();
    m_undo.push_back(std::move(before));
    while (m_undo.size() > std::max<std::size_t>(1, m_opts.undo_levels)) m_undo.pop_front();
    refresh();
  }

  void undo() {
    if (m_undo.empty()) throw InputError("undo", "nothing to undo");
    m_session.apply(m_undo.back());
    m_undo.pop_back();
    m_out << "undone (" << m_undo.size() << " more level" << (m_undo.size() == 1 ? "" : "s") << ")\n";
    refresh();
  }

  // The line that ends every command that does not relight: its own time and the last relight's.
  std::string timing(const char* done, std::chrono::steady_clock::time_point start) const {
    return std::string(done) + " in " + ms_text(ms_since(start)) + " (last relight " + ms_text(m_last_relight_ms) + ")\n";
  }

  void status() {
    const RelightSettings& s = m_session.settings();
    const auto& img = m_session.image();
    std::ostringstream o;
    o << "file        " << m_session.source() << " (" << img.width << "×" << img.height << ", " << img.bins.size()
      << " bins " << img.bins.min_nm() << "–" << img.bins.max_nm() << " nm)\n";
    if (const std::string denoised = spectral::denoised_summary(img.info); !denoised.empty())
      o << "filter      " << denoised << "\n";
    for (std::size_t l = 0; l < s.lights.size(); ++l) {
      o << "light       " << m_session.light_names()[l] << " = " << s.lights[l].text << " (default "
        << m_session.default_lights()[l].text << ")\n";
    }
    o << "exposure    " << s.relight.exposure_ev << " EV\n"
      << "cmf         " << spectral::observer_name(s.relight.cmf) << "\n"
      << "display     " << s.output.display.display;
    if (!s.output.display.view.empty()) o << ", view " << s.output.display.view;
    o << "\n"
      << "adaptation  " << (s.relight.adapt_to_d65 ? "on (Bradford, lights' white to D65)" : "off") << "\n"
      << "units       "
      << (s.relight.units == spectral::LightUnits::Absolute ? "absolute" : "relative (white under each light: Y = 1)")
      << "\n"
      << "preview     " << (m_opts.preview.empty() ? std::string("none") : m_opts.preview.string()) << "\n"
      << "show        " << (m_opts.show_every ? "after every change" : "on request (show)");
    if (m_protocol) o << ", " << image_protocol_name(*m_protocol);
    o << "\n"
      << "undo        " << m_undo.size() << " level" << (m_undo.size() == 1 ? "" : "s") << "\n"
      << "last relight " << ms_text(m_last_relight_ms) << "\n";
    m_out << o.str();
  }

 private:
  RelightSession& m_session;
  std::ostream& m_out;
  const InteractiveOptions& m_opts;
  std::deque<RelightSettings> m_undo;
  std::optional<ImageProtocol> m_protocol;
  double m_last_relight_ms = 0.0;
};

bool parse_on_off(const std::string& s) {
  if (s == "on") return true;
  if (s == "off") return false;
  throw InputError("adapt", "on or off, not \"" + s + "\"");
}

// long on purpose: the shell's command table: one short branch per command, listed together.
void run_command(RelightSession& session, Shell& shell, std::ostream& out, const std::vector<std::string>& w,
                 const InteractiveOptions& opts) {
  const std::string& cmd = w[0];
  const long long width = session.image().width, height = session.image().height;
  const std::string size = std::to_string(width) + "×" + std::to_string(height) + " image";
  if (cmd == "help") {
    expect_args(w, 0, 1, "help");
    out << kHelp;
  } else if (cmd == "clear") {
    expect_args(w, 0, 0, "clear");
    if (opts.terminal_output) out << "\x1b[H\x1b[2J" << std::flush;  // home, erase the screen (as clear(1) without E3)
  } else if (cmd == "lights") {
    expect_args(w, 0, 0, "lights");
    out << session.describe_lights();
  } else if (cmd == "status") {
    expect_args(w, 0, 0, "status");
    shell.status();
  } else if (cmd == "light") {
    expect_args(w, 1, 2, "light [NAME] SPEC");
    shell.change([&] { w.size() == 2 ? session.set_light("", w[1]) : session.set_light(w[1], w[2]); });
  } else if (cmd == "exposure") {
    expect_args(w, 1, 1, "exposure EV");
    const double ev = to_double(w[1], "exposure");
    shell.change([&] { session.set_exposure(ev); });
  } else if (cmd == "cmf") {
    expect_args(w, 1, 1, "cmf NAME");
    const spectral::Observer obs = spectral::parse_observer(w[1], "cmf");
    shell.change([&] { session.set_cmf(obs); });
  } else if (cmd == "display") {
    expect_args(w, 1, 1, "display NAME (quoted when it has blanks: display \"Display P3\")");
    shell.change([&] { session.set_display(w[1]); });
  } else if (cmd == "adapt") {
    expect_args(w, 1, 1, "adapt on|off");
    const bool on = parse_on_off(w[1]);
    shell.change([&] {
      RelightSettings s = session.settings();
      s.relight.adapt_to_d65 = on;
      session.apply(std::move(s));
    });
  } else if (cmd == "undo") {
    expect_args(w, 0, 0, "undo");
    shell.undo();
  } else if (cmd == "show") {
    expect_args(w, 0, 1, "show [blocks|sixel|kitty]");
    std::optional<ImageProtocol> forced;
    if (w.size() == 2) {
      forced = parse_image_protocol(w[1]);
      if (!forced) throw InputError("show", "blocks, sixel or kitty, not \"" + w[1] + "\"");
    }
    const auto start = std::chrono::steady_clock::now();
    shell.draw(forced);
    out << shell.timing("drawn", start);
  } else if (cmd == "save") {
    expect_args(w, 1, 1, "save FILE");
    const auto start = std::chrono::steady_clock::now();
    session.save(w[1], "save");
    out << "saved " << w[1] << " in " << ms_text(ms_since(start)) << "\n";
  } else if (cmd == "probe") {
    expect_args(w, 2, 3, "probe X Y [LIGHT]");
    const auto start = std::chrono::steady_clock::now();
    const int only = w.size() == 4 ? session.light_index(w[3], "probe LIGHT") : -1;
    const ProbeResult r = session.probe(to_index(w[1], "probe X", width, size), to_index(w[2], "probe Y", height, size));
    out << "probe " << r.x << ' ' << r.y << "\n";
    for (std::size_t l = 0; l < r.bins.size(); ++l) {
      out << "  bins " << session.light_names()[l] << ":";
      for (float v : r.bins[l]) out << ' ' << v;
      out << "\n";
    }
    for (std::size_t l = 0; l < r.reradiation.size(); ++l)
      if (only < 0 || static_cast<std::size_t>(only) == l)
        out << excitation_emission_map(session.image(), session.light_names()[l], r.reradiation[l]);
    out << "  XYZ " << vec3(r.xyz) << "\n  Lab " << vec3(r.lab) << "\n  sRGB " << vec3(r.srgb) << "\n";
    out << "  " << shell.timing("probed", start);
  } else if (cmd == "compare") {
    expect_args(w, 4, 5, "compare X1 Y1 X2 Y2 [R]");
    const auto start = std::chrono::steady_clock::now();
    const int r = w.size() == 6 ? to_index(w[5], "compare R", std::max(width, height) + 1, "radius range of the " + size) : 0;
    const CompareResult c =
        session.compare(to_index(w[1], "compare X1", width, size), to_index(w[2], "compare Y1", height, size),
                        to_index(w[3], "compare X2", width, size), to_index(w[4], "compare Y2", height, size), r);
    std::ostringstream de;
    de << std::fixed << std::setprecision(6) << c.delta_e2000;
    out << "compare\n  Lab1 " << vec3(c.lab1) << "\n  Lab2 " << vec3(c.lab2) << "\n  dE2000 " << de.str() << "\n";
    out << "  " << shell.timing("compared", start);
  } else {
    throw InputError(cmd, "unknown command (try 'help')");
  }
}

std::vector<std::string> file_candidates(const std::string& partial, const std::string& prefix = "") {
  const std::size_t slash = partial.rfind('/');
  const std::string dir_text = slash == std::string::npos ? "" : partial.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? partial : partial.substr(slash + 1);
  std::vector<std::string> out;
  std::error_code ec;
  fs::directory_iterator it(dir_text.empty() ? fs::path(".") : fs::path(dir_text), ec);
  for (int n = 0; !ec && it != fs::directory_iterator() && n < 2000; it.increment(ec), ++n) {
    const std::string entry = it->path().filename().string();
    if (entry.compare(0, name.size(), name) != 0 || (entry[0] == '.' && name.empty())) continue;
    std::error_code dir_ec;
    out.push_back(prefix + dir_text + entry + (it->is_directory(dir_ec) ? "/" : ""));
  }
  return out;
}

std::vector<std::string> spec_candidates(const std::string& partial) {
  if (partial.rfind("csv:", 0) == 0) return file_candidates(partial.substr(4), "csv:");
  std::vector<std::string> out = spectral::named_illuminants();
  for (const char* s : {"off", "blackbody:", "gaussian:", "box:", "csv:"}) out.emplace_back(s);
  return out;
}

}  // namespace

std::vector<std::string> complete_command(RelightSession& session, const std::vector<std::string>& before,
                                          const std::string& partial) {
  if (before.empty()) return kCommands;
  const std::string& cmd = before[0];
  const std::size_t arg = before.size();  // 1: the first argument is being typed
  const std::vector<std::string>& lights = session.light_names();
  if (cmd == "light" && arg == 1) {
    std::vector<std::string> out = lights;
    for (auto& s : spec_candidates(partial)) out.push_back(std::move(s));
    return out;
  }
  if (cmd == "light" && arg == 2 && std::find(lights.begin(), lights.end(), before[1]) != lights.end()) {
    return spec_candidates(partial);
  }
  if (cmd == "display" && arg == 1) {
    try {
      return session.display().displays();
    } catch (const std::exception&) {
      return {};
    }
  }
  if (cmd == "cmf" && arg == 1) return {"1931", "1964", "2012-2", "2012-10"};
  if (cmd == "adapt" && arg == 1) return {"on", "off"};
  if (cmd == "show" && arg == 1) return {"blocks", "sixel", "kitty"};
  if (cmd == "help" && arg == 1) return kCommands;
  if (cmd == "save" && arg == 1) return file_candidates(partial);
  if (cmd == "probe" && arg == 3) return lights;
  return {};
}

int run_interactive(RelightSession& session, LineReader& in, std::ostream& out, const InteractiveOptions& opts) {
  Shell shell(session, out, opts);
  int failures = 0;
  try {
    shell.refresh(true);
  } catch (const std::exception& e) {
    out << "error: " << e.what() << "\n";
    ++failures;
  }
  std::string line;
  while (true) {
    out << std::flush;
    if (!in.read_line(line)) break;
    try {
      const std::vector<std::string> w = split_words(line);
      if (w.empty()) continue;
      if (w[0] == "quit" || w[0] == "exit") break;
      run_command(session, shell, out, w, opts);
    } catch (const std::exception& e) {
      out << "error: " << e.what() << "\n";
      ++failures;
    }
  }
  out << std::flush;
  return failures;
}

int run_interactive(RelightSession& session, std::istream& in, std::ostream& out, const InteractiveOptions& opts) {
  StreamLineReader reader(in, opts.prompt ? &out : nullptr);
  return run_interactive(session, reader, out, opts);
}

int run_interactive_terminal(RelightSession& session, InteractiveOptions opts, std::ostream& warnings) {
  const bool in_tty = ::isatty(STDIN_FILENO) != 0, out_tty = ::isatty(STDOUT_FILENO) != 0;
  opts.terminal_size = [] { return terminal_size(STDOUT_FILENO); };
  if (out_tty && !opts.detect_protocol) {
    opts.detect_protocol = [] { return detect_image_protocol(STDIN_FILENO, STDOUT_FILENO); };
  }
  if (out_tty && !opts.image_route) {
    opts.image_route = [](ImageProtocol p) { return image_route(p, tmux_facts(p, STDIN_FILENO, STDOUT_FILENO)); };
  }
  opts.terminal_output = out_tty;
  if (!in_tty || !out_tty) {
    opts.prompt = opts.prompt || in_tty;
    return run_interactive(session, std::cin, std::cout, opts);
  }
  TerminalReaderOptions ro;
  ro.history_file = default_history_file();
  ro.completer = [&session](const std::vector<std::string>& before, const std::string& partial) {
    return complete_command(session, before, partial);
  };
  ro.warnings = &warnings;
  const std::unique_ptr<LineReader> reader = make_terminal_line_reader(std::move(ro));
  // As in bash, Ctrl-C never ends the session: at the prompt the reader takes it as a key (it cancels
  // the line); while a command runs (they take milliseconds) it is ignored, so a key pressed a moment
  // late does not end the session either. Restored when the session ends.
  struct sigaction ignore{}, before{};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  ::sigaction(SIGINT, &ignore, &before);
  int failures = 0;
  try {
    failures = run_interactive(session, *reader, std::cout, opts);
  } catch (...) {
    ::sigaction(SIGINT, &before, nullptr);
    throw;
  }
  ::sigaction(SIGINT, &before, nullptr);
  return failures;
}

}  // namespace prizma::relight
