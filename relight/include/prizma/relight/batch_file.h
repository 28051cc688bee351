#pragma once
// Batch files: one JSON file listing output images, each with its own lights, exposure, CMF and
// display, all relit from one load of the spectral file (format: docs/relight.md).
#include <filesystem>
#include <ostream>
#include <vector>

#include "prizma/relight/relight_session.h"

namespace prizma::relight {

struct BatchOutput {
  std::filesystem::path file;  // resolved against the batch file's folder
  RelightSettings settings;
};

// Reads and validates the whole batch against the session's layers, starting every output from
// `base` (the command line's settings). Every output is checked (specs, display, writable path)
// before anything is written. Throws InputError naming "<batch.json>: outputs[i].<key>".
std::vector<BatchOutput> read_batch_file(const std::filesystem::path& path, const RelightSession& session,
                                         const RelightSettings& base);

// Relights and writes each output in turn into `group` (the run's outputs: none appears before its
// commit(); null: each as it is written); `log` (may be null) gets one line per file with its time.
void run_batch(RelightSession& session, const std::vector<BatchOutput>& outputs, std::ostream* log,
               spectral::OutputGroup* group = nullptr);

}  // namespace prizma::relight
