#pragma once
// The input files of the running tool (docs/errors.md, "Outputs never replace inputs"). While an
// InputRecording lives (run_tool holds one around every tool's work), each file that libspectral's
// require_regular_file accepts is remembered by identity (device, inode): the scene, its volume,
// images and csv: spectra, the spectral EXR, shards, batch files. check_output_file then refuses an
// output that is one of them, through any spelling, hard link or symbolic link. Process-wide,
// because readers run on worker threads too; one recording at a time. Without one (libraries called
// from Python, unit tests) nothing is recorded and nothing refused.
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "prizma/spectral/input_file.h"

namespace prizma::tool {

class InputRecording : public spectral::InputRecord {
 public:
  InputRecording();
  ~InputRecording() override;
  InputRecording(const InputRecording&) = delete;
  InputRecording& operator=(const InputRecording&) = delete;

  void record(dev_t device, ino_t inode, const std::filesystem::path& path, std::string_view kind) override;
  std::optional<spectral::RecordedInput> find(dev_t device, ino_t inode) const override;
  // An input the run rewrites in place, safely because the old file is replaced only once the new
  // one is complete (prizma-render --resume FILE writes FILE again): the outputs given by these
  // option names may replace it, no other. Nothing happens when `path` is not a recorded input.
  void allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs);

 private:
  mutable std::mutex m_mutex;
  std::map<std::pair<dev_t, ino_t>, spectral::RecordedInput> m_files;  // the first name each was read under
  spectral::InputRecord* m_previous = nullptr;
};

// allow_in_place_update on the recording run_tool holds; nothing outside run_tool.
void allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs);

}  // namespace prizma::tool
