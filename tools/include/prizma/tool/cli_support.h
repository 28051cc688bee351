#pragma once
// CLI11 glue shared by the executables (header-only; the apps link CLI11).
#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "prizma/spectral/version.h"
#include "prizma/tool/tool_main.h"

namespace prizma::tool {

// The check of every option that names a file or a folder: an empty value (a script's unset
// variable, -o "$OUT") is refused as a usage error naming the option, never taken as "not given".
inline CLI::Validator non_empty_path() {
  CLI::Validator check(
      [](std::string& value) { return value.empty() ? std::string("empty path ('' names no file)") : std::string(); },
      "");
  check.name("path");  // name_path_values: --help calls the value PATH
  return check;
}

// --help's name for the value of every option checked by non_empty_path(): PATH (CLI11 calls every
// std::string TEXT), in the app and its subcommands; parse_command_line applies it, so the man pages
// and the shell completion made from --help see it too. An option that names its value itself
// (type_name before parsing: "KEY=VALUE") keeps that name.
inline void name_path_values(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    if (opt->get_type_name().rfind("TEXT", 0) != 0) continue;
    try {
      opt->get_validator("path");
      opt->type_name("PATH");
    } catch (const CLI::OptionNotFound&) {
    }
  }
  for (CLI::App* sub : app.get_subcommands({})) name_path_values(*sub);
}

// Parses argv; on --help / --version prints to stdout and returns kExitOk; on a usage error prints
// "prog: error: <message>" and "Try 'prog --help'." to stderr and returns kExitUsage. Returns -1 when
// parsing succeeded and the program should go on.
inline int parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  spectral::end_startup_guard();
  name_path_values(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return check_standard_output(app.get_name(), kExitOk);
  } catch (const CLI::CallForAllHelp&) {
    std::cout << app.help("", CLI::AppFormatMode::All);
    return check_standard_output(app.get_name(), kExitOk);
  } catch (const CLI::CallForVersion&) {
    std::cout << app.get_name() << " " << spectral::prizma_version() << "\n";
    return check_standard_output(app.get_name(), kExitOk);
  } catch (const CLI::ParseError& e) {
    std::cerr << app.get_name() << ": error: " << e.what() << "\n"
              << "Try '" << app.get_name() << " --help'.\n";
    return kExitUsage;
  }
  return -1;
}

}  // namespace prizma::tool
