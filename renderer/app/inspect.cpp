// prizma-render inspect VOLUME|SCENE: a volume's size, orientation, values and histogram, and the
// share of its voxels each material of a scene takes (docs/renderer.md, "Inspecting a volume").
#include <tbb/global_control.h>

#include <iostream>
#include <optional>
#include <string>

#include "prizma/render/volume_inspection.h"
#include "prizma/tool/cli_support.h"
#include "prizma/tool/tool_main.h"

int inspect_main(int argc, char** argv) {
  namespace render = prizma::render;
  namespace spectral = prizma::spectral;
  namespace tool = prizma::tool;
  CLI::App app{"Shows a volume's voxel count, voxel size, orientation, value range and histogram, and for a scene\n"
               "which voxels each material's range takes (first matching range wins): choose ranges from the data.\n"
               "  prizma-render inspect data/scenes/mri.json\n"
               "  prizma-render inspect head.nii.gz --bins 64",
               "prizma-render inspect"};
  app.set_version_flag("--version", spectral::prizma_version());
  std::string input;
  int bins = 32;
  app.add_option("input", input, "a scene file (.json) or a volume file (.nii, .nii.gz, .raw, .vdb)")
      ->required()
      ->check(tool::non_empty_path());
  app.add_option("--bins", bins, "histogram bins over the values that are not 0")->check(CLI::Range(1, 1000));
  if (const int rc = tool::parse_command_line(app, argc - 1, argv + 1); rc >= 0) return rc;
  return tool::run_tool("prizma-render", [&] {
    const render::InspectedVolume in = render::load_for_inspection(input);
    std::cout << render::inspection_report(in, render::volume_statistics(in, bins)) << std::flush;
    return tool::kExitOk;
  });
}
