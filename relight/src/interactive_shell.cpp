#include "prizma/relight/interactive_shell.h"

#include <charconv>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "prizma/relight/terminal_preview.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

using spectral::InputError;

constexpr const char* kHelp =
    "commands:\n"
    "  light NAME SPEC       set one light layer (SPEC: D65, A, F11, gaussian:550:20, blackbody:3200K, off, …*k)\n"
    "  light SPEC            set every light layer\n"
    "  exposure EV           exposure in stops\n"
    "  cmf NAME              1931, 1964, 2012-2, 2012-10\n"
    "  display NAME          OCIO display (sRGB, …)\n"
    "  save FILE             write the current image (.png, .tif, .exr)\n"
    "  probe X Y             bins, XYZ, Lab (D65 white) and sRGB at a pixel\n"
    "  compare X1 Y1 X2 Y2 [R]  CIEDE2000 between two pixels or the means of two (2R+1)² squares\n"
    "  lights                the layers and their current lights\n"
    "  help                  this text\n"
    "  quit                  leave (end of input does too)\n";

std::vector<std::string> split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

double to_double(const std::string& s, const std::string& input) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) throw InputError(input, "not a number: \"" + s + "\"");
  return v;
}

int to_int(const std::string& s, const std::string& input) {
  int v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) throw InputError(input, "not an integer: \"" + s + "\"");
  return v;
}

void expect_args(const std::vector<std::string>& w, std::size_t lo, std::size_t hi, const char* usage) {
  if (w.size() - 1 < lo || w.size() - 1 > hi) throw InputError(w[0], std::string("usage: ") + usage);
}

std::string vec3(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << v[0] << ' ' << v[1] << ' ' << v[2];
  return s.str();
}

// After a change: relight, report the time, rewrite the preview and show the thumbnail.
void refresh(RelightSession& session, std::ostream& out, const InteractiveOptions& opts) {
  const double ms = session.relight();
  std::ostringstream line;
  line << "relit in " << std::fixed << std::setprecision(2) << ms << " ms\n";
  out << line.str();
  if (!opts.preview.empty()) session.save(opts.preview);
  if (opts.show) {
    const XyzImage& img = session.xyz();
    print_terminal_thumbnail(out, to_display(img, session.display()), img.width, img.height);
  }
}

}  // namespace

int run_interactive(RelightSession& session, std::istream& in, std::ostream& out, const InteractiveOptions& opts) {
  int failures = 0;
  try {
    refresh(session, out, opts);
  } catch (const std::exception& e) {
    out << "error: " << e.what() << "\n";
    ++failures;
  }
  std::string line;
  while (true) {
    if (opts.prompt) out << "> " << std::flush;
    if (!std::getline(in, line)) break;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    const std::vector<std::string> w = split(line);
    if (w.empty()) continue;
    const std::string& cmd = w[0];
    try {
      if (cmd == "quit" || cmd == "exit") {
        break;
      } else if (cmd == "help") {
        out << kHelp;
      } else if (cmd == "lights") {
        out << session.describe_lights();
      } else if (cmd == "light") {
        expect_args(w, 1, 2, "light [NAME] SPEC");
        if (w.size() == 2) {
          session.set_light("", w[1]);
        } else {
          session.set_light(w[1], w[2]);
        }
        refresh(session, out, opts);
      } else if (cmd == "exposure") {
        expect_args(w, 1, 1, "exposure EV");
        session.set_exposure(to_double(w[1], "exposure"));
        refresh(session, out, opts);
      } else if (cmd == "cmf") {
        expect_args(w, 1, 1, "cmf NAME");
        session.set_cmf(spectral::parse_observer(w[1], "cmf"));
        refresh(session, out, opts);
      } else if (cmd == "display") {
        expect_args(w, 1, 1, "display NAME");
        session.set_display(w[1]);
        refresh(session, out, opts);
      } else if (cmd == "save") {
        expect_args(w, 1, 1, "save FILE");
        session.save(w[1]);
        out << "saved " << w[1] << "\n";
      } else if (cmd == "probe") {
        expect_args(w, 2, 2, "probe X Y");
        const ProbeResult r = session.probe(to_int(w[1], "probe X"), to_int(w[2], "probe Y"));
        out << "probe " << r.x << ' ' << r.y << "\n";
        for (std::size_t l = 0; l < r.bins.size(); ++l) {
          out << "  bins " << session.light_names()[l] << ":";
          for (float v : r.bins[l]) out << ' ' << v;
          out << "\n";
        }
        out << "  XYZ " << vec3(r.xyz) << "\n  Lab " << vec3(r.lab) << "\n  sRGB " << vec3(r.srgb) << "\n";
      } else if (cmd == "compare") {
        expect_args(w, 4, 5, "compare X1 Y1 X2 Y2 [R]");
        const int r = w.size() == 6 ? to_int(w[5], "compare R") : 0;
        const CompareResult c = session.compare(to_int(w[1], "compare X1"), to_int(w[2], "compare Y1"),
                                                to_int(w[3], "compare X2"), to_int(w[4], "compare Y2"), r);
        std::ostringstream de;
        de << std::fixed << std::setprecision(6) << c.delta_e2000;
        out << "compare\n  Lab1 " << vec3(c.lab1) << "\n  Lab2 " << vec3(c.lab2) << "\n  dE2000 " << de.str() << "\n";
      } else {
        throw InputError(cmd, "unknown command (try 'help')");
      }
    } catch (const std::exception& e) {
      out << "error: " << e.what() << "\n";
      ++failures;
    }
  }
  return failures;
}

}  // namespace prizma::relight
