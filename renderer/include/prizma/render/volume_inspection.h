#pragma once
// What `prizma-render inspect VOLUME|SCENE` shows (docs/renderer.md, "Inspecting a volume"): a
// volume's voxel count, size and orientation, its values (range, exact zeros, a histogram) and, for a
// scene, the share of the voxels each material's range takes — so that material ranges are chosen
// from the data rather than guessed.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "prizma/render/transfer_function.h"
#include "prizma/render/volume.h"

namespace prizma::render {

// A volume as a scene reads it, with what the scene makes of its values.
struct InspectedVolume {
  Volume volume;
  std::string input;                  // the file given (for the report's first line)
  bool from_scene = false;
  ValueNormalisation normalisation;   // the scene's ("auto": the volume's finite min and max)
  bool normalisation_given = false;   // the scene has a "normalisation" object
  TransferFunction transfer;          // the scene's materials and rules, in raw values (empty for a volume file)
};

// Reads a scene file (.json: its volume, normalisation and materials or transfer-function image, as
// load_scene reads them, without building the medium) or a volume file (.nii, .nii.gz, .raw, .vdb
// with its "density" grid: as a scene's "volume" of that type reads it). InputError as those do; an
// unknown extension names the ones known. Defined in scene/scene_loader.cpp, with the scene reader's sections.
InspectedVolume load_for_inspection(const std::filesystem::path& path);

struct VolumeStatistics {
  std::uint64_t voxels = 0, non_finite = 0, zeros = 0;
  double min = 0.0, max = 0.0, mean = 0.0;  // over the finite values
  // The histogram of the finite values that are not exactly 0 (background, reported apart) over
  // [min, max], `counts.size()` equal bins (the last closed).
  std::vector<std::uint64_t> counts;
  double histogram_lo = 0.0, histogram_hi = 0.0;
  // Per rule of the transfer function (first matching rule wins, as the renderer classifies voxel
  // centres): the voxels it takes; then the voxels no rule takes.
  std::vector<std::uint64_t> rule_voxels;
  std::uint64_t unassigned = 0;
};

// One pass over the voxels; histogram_bins ≥ 1.
VolumeStatistics volume_statistics(const InspectedVolume& in, int histogram_bins);

// The report, one fact per line (what prizma-render inspect prints).
std::string inspection_report(const InspectedVolume& in, const VolumeStatistics& stats);

}  // namespace prizma::render
