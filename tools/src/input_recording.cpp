#include "prizma/tool/input_recording.h"

#include <sys/stat.h>

namespace prizma::tool {

namespace {
InputRecording* g_current = nullptr;  // the recording run_tool holds (one at a time)
}  // namespace

InputRecording::InputRecording() {
  m_previous = spectral::set_input_record(this);
  g_current = this;
}

InputRecording::~InputRecording() {
  spectral::set_input_record(m_previous);
  if (g_current == this) g_current = nullptr;
}

void InputRecording::record(dev_t device, ino_t inode, const std::filesystem::path& path, std::string_view kind) {
  const std::lock_guard lock(m_mutex);
  m_files.try_emplace({device, inode}, spectral::RecordedInput{path, std::string(kind), {}});
}

std::optional<spectral::RecordedInput> InputRecording::find(dev_t device, ino_t inode) const {
  const std::lock_guard lock(m_mutex);
  const auto it = m_files.find({device, inode});
  if (it == m_files.end()) return std::nullopt;
  return it->second;
}

void InputRecording::allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  const std::lock_guard lock(m_mutex);
  const auto it = m_files.find({st.st_dev, st.st_ino});
  if (it != m_files.end()) it->second.replaced_by = outputs;
}

void allow_in_place_update(const std::filesystem::path& path, const std::vector<std::string>& outputs) {
  if (g_current != nullptr) g_current->allow_in_place_update(path, outputs);
}

}  // namespace prizma::tool
