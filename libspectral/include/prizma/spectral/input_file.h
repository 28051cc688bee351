#pragma once
// Checks shared by every reader of a user's input file: the file must be a regular file (a FIFO,
// a device or a socket would block or never end), and JSON text must not nest deeper than a sane
// bound (nlohmann::json recurses to print and to compare values). Every file accepted is recorded
// as an input of the run, so that no output of the run replaces it (InputRecording).
#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace prizma::spectral {

// Deepest nesting of arrays and objects accepted in any JSON input (scene, batch file, the lights
// record of a spectral EXR). Real files nest fewer than 10 levels.
constexpr int kMaxJsonDepth = 128;

// Throws InputError(input, reason) unless `path` names a regular file (through symbolic links).
// The reason says what the path really is: "no such file", "is a folder, not a <kind>", "is a
// FIFO (named pipe), not a regular file", "is a character device, not a regular file", "is a
// symbolic link loop", "cannot be accessed: Permission denied", ... `kind` names what was expected,
// with its article ("a scene file", "an OpenEXR file"). `input` defaults to the path. While an
// InputRecording lives, the file accepted is recorded as an input of the run.
void require_regular_file(const std::filesystem::path& path, std::string_view kind, const std::string& input = {});

// The input files of the running tool (docs/errors.md, "Outputs never replace inputs"). While one
// lives (run_tool holds one around every tool's work), each file require_regular_file accepts is
// remembered by identity (device, inode): the scene, its volume, images and csv: spectra, the spectral
// EXR, shards, batch files. check_output_file then refuses an output that is one of them, through
// any spelling, hard link or symbolic link. Process-wide, because readers run on worker threads
// too; one recording at a time. Without one (libraries called from Python, unit tests) nothing is
// recorded and nothing refused.
class InputRecording {
 public:
  InputRecording();
  ~InputRecording();
  InputRecording(const InputRecording&) = delete;
  InputRecording& operator=(const InputRecording&) = delete;
};

struct RecordedInput {
  std::filesystem::path path;            // as its reader named it
  std::string kind;                      // "a scene file", "an OpenEXR file"
  std::vector<std::string> replaced_by;  // output options allowed to replace it (allow_in_place_update)
};

// The recorded input that is the file (device, inode), if any.
std::optional<RecordedInput> recorded_input(dev_t device, ino_t inode);

// An input the run rewrites in place, safely because the old file is replaced only once the new one
// is complete (prizma-render --resume FILE writes FILE again): the outputs given by these option
// names may replace it, no other. Nothing happens when `path` is not a recorded input.
void allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs);

// Throws InputError(input, "JSON nested deeper than N levels at line L, column C") when `text`
// nests arrays and objects deeper than kMaxJsonDepth (brackets inside strings do not count).
void check_json_depth(std::string_view text, const std::string& input);

}  // namespace prizma::spectral
