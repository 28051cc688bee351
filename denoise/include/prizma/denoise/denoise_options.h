#pragma once
// DenoiseOptions: the parameters of the denoiser's weights (docs/denoise.md, "Parameters").
namespace prizma::denoise {

// What denoise() writes into the variance layers of its output.
enum class VarianceOutput {
  // Σ_q W(p,q)²·Var(q): the variance of the filtered value around its own expectation, treating the
  // weights as fixed and the pixels' estimates as independent. The filter's bias is not in it.
  Propagate,
  // No variance layers in the output.
  Drop,
};

struct DenoiseOptions {
  // Kernels cover the (2r+1)² pixels around each pixel, r in [1, 15].
  int window_radius_px = 5;
  // Patches of (2f+1)² pixels are compared (Rousselle et al. 2012), f in [0, 7].
  int patch_radius_px = 3;
  // k of the patch distance d² = ((u_p − u_q)² − (V_p + min(V_p, V_q))) / (ε + k²(V_p + V_q)), > 0:
  // larger averages more (and blurs more).
  float patch_k = 0.45f;
  // A second k, ≥ 0 (0: none): each pixel's kernel then uses whichever of patch_k and patch_k_wide
  // gives the smaller SURE estimate of the filtered luminance's error, averaged over the
  // (2s+1)² pixels around it, s = sure_radius_px in [0, 15] (docs/denoise.md, "The weights").
  float patch_k_wide = 1.0f;
  int sure_radius_px = 3;
  // The centre test: a neighbour whose value differs from the pixel's by z > t standard errors
  // (z² = (u_p − u_q)² / (V_p + V_q)) gets its weight multiplied by e^−(z² − t²), so a pixel keeps
  // out neighbours that disagree beyond their noise even when their patches match (thin structures,
  // isolated features). Pure noise exceeds t = 3 in 0.3 % of pairs. 0 turns the test off.
  float centre_threshold_se = 3.0f;
  // k_f of the feature distance ((f_p − f_q)² − (V_p + min(V_p, V_q))) / (k_f² · max(τ, V_p, |∇f_p|²))
  // (Rousselle et al. 2013), > 0.
  float feature_k = 0.6f;
  // τ of the feature distance as a fraction of the square of the feature's range over the image, > 0.
  float feature_tau = 1e-4f;
  VarianceOutput variance = VarianceOutput::Propagate;
  // Side of the square tiles the weights are computed and applied in, 8–64 pixels (a tile's kernels
  // take 4·(2r+1)²·side² bytes per thread: 0.5 MB by default, 16 MB at r = 15 and 64); the result
  // does not depend on it (nor on the thread count).
  int tile_size_px = 32;
};

}  // namespace prizma::denoise
