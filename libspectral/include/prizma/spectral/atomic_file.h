#pragma once
// Atomic output: write to a temporary in the destination folder, then rename over the destination.
// A failed or interrupted write never leaves a partial file and never destroys an existing one.
#include <filesystem>
#include <functional>

namespace prizma::spectral {

// Calls write(tmp_path) where tmp_path is "<dir>/.prizma-tmp-<pid>-<n>-<filename>" (it keeps the
// destination's extension, so OpenImageIO picks the same format), then renames it to `path`.
// If write throws, the temporary is removed and the exception propagates. Throws RuntimeError when
// the folder is not writable or the rename fails.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp_path)>& write);

}  // namespace prizma::spectral
