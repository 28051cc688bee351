#pragma once
// Checks shared by every reader of a user's input file: the file must be a regular file (a FIFO,
// a device or a socket would block or never end), and JSON text must not nest deeper than a sane
// bound (nlohmann::json recurses to print and to compare values).
#include <filesystem>
#include <string>
#include <string_view>

namespace prizma::spectral {

// Deepest nesting of arrays and objects accepted in any JSON input (scene, batch file, the lights
// record of a spectral EXR). Real files nest fewer than 10 levels.
constexpr int kMaxJsonDepth = 128;

// Throws InputError(input, reason) unless `path` names a regular file (through symbolic links).
// The reason says what the path really is: "no such file", "is a folder, not a <kind>", "is a
// FIFO (named pipe), not a regular file", "is a character device, not a regular file", "is a
// symbolic link loop", "cannot be accessed: Permission denied", ... `kind` names what was expected,
// with its article ("a scene file", "an OpenEXR file"). `input` defaults to the path.
void require_regular_file(const std::filesystem::path& path, std::string_view kind, const std::string& input = {});

// Throws InputError(input, "JSON nested deeper than N levels at line L, column C") when `text`
// nests arrays and objects deeper than kMaxJsonDepth (brackets inside strings do not count).
void check_json_depth(std::string_view text, const std::string& input);

}  // namespace prizma::spectral
