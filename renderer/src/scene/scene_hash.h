#pragma once
// The scene hash (prizma:sceneHash, what --resume and merge check): 64-bit FNV-1a of the scene text,
// the -D overrides, the volume's size, spacing and values, the materials' spectra (which csv files
// or images may supply) and the environment images (the text holds only their names).
#include <tbb/task_group.h>

#include <cstdint>
#include <string>
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/fnv1a.h"

namespace prizma::render::scene_file {

// FNV-1a takes one multiply per byte in sequence (1.5 ms for a 64³ volume), so the voxels are hashed
// in a task beside the rest of the loading (the classification); the value is the same on any
// thread count.
class SceneHash {
 public:
  // The text, the overrides and the volume (kept by reference until finish(): it must live as long).
  SceneHash(const std::string& text, const std::vector<SceneOverride>& overrides, const Volume& vol);
  ~SceneHash();  // waits for the voxels' task (a load that failed unwinds through here)
  SceneHash(const SceneHash&) = delete;
  SceneHash& operator=(const SceneHash&) = delete;

  // The materials and environment images of the loaded scene, then the hex digest.
  std::string finish(const Scene& scene);

 private:
  spectral::Fnv1a m_h;  // over bytes (prizma/spectral/fnv1a.h, the checksum's FNV-1a)
  tbb::task_group m_voxels;
};

}  // namespace prizma::render::scene_file
