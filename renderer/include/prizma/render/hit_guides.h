#pragma once
// The deterministic guide layers of --features (docs/spectral-exr.md, "Guide layers"; docs/denoise.md,
// "Guides"): where each camera ray's optical depth reaches 1, found by marching the ray through the
// medium at fixed steps, never by sampling. Like the first-hit albedo, normal and depth that NFOR and
// OIDN take from a surface renderer, they are noise-free: a pixel's value is the mean over a fixed
// 2×2 grid of sub-pixel rays and its variance that mean's spread, the same at any samples, seed,
// thread count or shard. No light enters them, so the denoised file still relights exactly.
#include <string>
#include <vector>

#include "prizma/render/camera.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

class PathTracer;

// The layers' names, in the order hit_guides() returns them: "hit_depth" (distance from where the
// ray enters the volume's bounds to the point of optical depth 1, as a fraction of the bounds'
// diagonal; 1 when the ray leaves the bounds before), "hit_normal_x", "hit_normal_y",
// "hit_normal_z" (the unit vector against the gradient of the extinction there, world axes; 0 when
// no hit), "hit_albedo" (the white-light luminance of the single-scattering albedo there; 0 when
// no hit), "hit_density" (the reference extinction there times the bounds' diagonal; 0 when no hit)
// and, for each directional light k of scene.lights (not point, emission or environment), "hit_lightK":
// the transmittance from the hit toward it (0 when no hit). Only the lights' directions enter, never
// their spectra: relighting stays exact. Optical depth and gradient use each material's reference
// extinction: σt per unit averaged over the scene's bins weighted by the CIE 1931 ȳ at the bins'
// centres (plain average when ȳ is 0 over every bin), times the density.
std::vector<std::string> hit_guide_names(const Scene& scene);

// The layers for every pixel of `camera`, marching with half the smallest voxel side as the step
// (midpoint rule) through `tracer`'s medium (PathTracer::lookup). Parallel over rows; the result does
// not depend on the thread count.
std::vector<spectral::GuideLayer> hit_guides(const Scene& scene, const CameraModel& camera, const PathTracer& tracer);

}  // namespace prizma::render
