"""reveal-demo: real data — the Colin27 MRI template (data/scenes/mri.json) with two tissues given
materials that look the same under white light (D65) in the rendered image; one render, then lights
designed from the render that hide or reveal the difference between the tissues.

Steps
1. Materials as surfaces: tissue A keeps a natural reflectance a_A; a surface metamer b0 of it under
   D65 (prizma-metamer metamer, split light F11) is the starting point for tissue B.
2. Calibration render. Extinction and anisotropy are grey, so the transport at a wavelength depends
   only on the two tissues' albedos at that wavelength: T_region(a_A(λ), a_B(λ)). One render whose
   bins each hold one pair (a_A, a_B) of an 11 × 11 grid gives, per region, that response table.
   The regions come from the same render: where tissue A alone is bright (a_A high, a_B = 0) and
   tissue B is dark, the pixel is A's, and the other way round.
3. Design in the image: multiple scattering makes the transport non-linear in the albedo and the
   regions differ in depth and shading, so b0 inside the volume does not match a_A (measured by an
   extra render with b0). The tissue-B albedo a_B = b0 + three smooth bumps is solved (Newton) so
   that the regions' predicted mean XYZ under D65 are equal (the relighter's weights, from
   prizma-metamer weights).
4. The render with a_A and a_B. The region means of its transport bins are the spectra that the
   relighter turns into the regions' colours; prizma-metamer light designs from them a light that
   reveals the difference (ΔE00 as large as possible, D65's luminance) and one that hides it again
   where F11 shows it (the light closest to F11, with F11's luminance, under which they match).
5. Relit under D65, A, F11, the hiding and the revealing light: ΔE00 between the regions' mean XYZ.
Claim: ΔE00 < 1 under D65 and under the hiding light, > 10 under the revealing light.
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import prizma_demo as pd  # noqa: E402
from prizma_demo import plt  # noqa: E402

ALBEDO_A = "cc:2"  # light skin (ColorChecker Classic)
MATCH = "D65"
SPLIT = "F11"
HIDE_REFERENCE = SPLIT  # hide the difference F11 shows, with a light close to F11
TISSUES = ("grey_matter", "white_matter")
# Albedo values of the calibration grid (denser towards 1, where multiple scattering bends the response).
GRID = np.array([0.0, 0.15, 0.3, 0.45, 0.6, 0.7, 0.8, 0.87, 0.93, 0.97, 1.0])
# Smooth corrections of tissue B's albedo: gaussian bumps (centre nm, standard deviation nm).
BUMPS = ((450.0, 40.0), (540.0, 40.0), (620.0, 40.0))
FINE = np.arange(380.0, 780.0 + 0.5, 1.0)  # 1 nm tables of the albedos


def pick_materials(scene, names):
    mats = [m.get("name", "material%d" % i) for i, m in enumerate(scene["materials"])]
    if len(mats) != 2:
        raise pd.DemoFailure("mri.json must have exactly two materials (the tissues), it has %d" % len(mats))
    idx = []
    for n in names:
        if n not in mats:
            raise pd.DemoFailure("mri.json has no material %r (materials: %s)" % (n, ", ".join(mats)))
        idx.append(mats.index(n))
    return idx


def bilinear(table, a, b):
    """table[i, j] = response at (GRID[i], GRID[j]); a, b arrays in [0, 1]."""
    a = np.clip(a, 0.0, 1.0)
    b = np.clip(b, 0.0, 1.0)
    i = np.clip(np.searchsorted(GRID, a, side="right") - 1, 0, len(GRID) - 2)
    j = np.clip(np.searchsorted(GRID, b, side="right") - 1, 0, len(GRID) - 2)
    fa = (a - GRID[i]) / (GRID[i + 1] - GRID[i])
    fb = (b - GRID[j]) / (GRID[j + 1] - GRID[j])
    return ((1 - fa) * (1 - fb) * table[i, j] + fa * (1 - fb) * table[i + 1, j] +
            (1 - fa) * fb * table[i, j + 1] + fa * fb * table[i + 1, j + 1])


class Predictor:
    """Region-mean transport per render bin for given albedo tables, from the calibration response.
    The renderer estimates each bin's average over λ (a uniform wavelength per bin and path), so the
    prediction averages the response over 40 wavelengths inside each bin."""

    def __init__(self, tables, weights_csv):
        rows = np.loadtxt(weights_csv, delimiter=",", skiprows=1, ndmin=2)
        self.edges = list(rows[:, 0]) + [rows[-1, 1]]
        self.weights = rows[:, 2:5].T  # 3 × bins
        t = (np.arange(40) + 0.5) / 40
        self.lam = rows[:, :1] + t[None, :] * (rows[:, 1:2] - rows[:, :1])  # bins × 40
        self.tables = tables

    def transport(self, a_fine, b_fine):
        a = np.interp(self.lam, FINE, a_fine)
        b = np.interp(self.lam, FINE, b_fine)
        return [bilinear(t, a, b).mean(axis=1) for t in self.tables]

    def xyz(self, a_fine, b_fine):
        return [self.weights @ u for u in self.transport(a_fine, b_fine)]


def solve_albedo_b(pred, a_fine, b0_fine):
    """a_B = clip(b0 + Σ c_j bump_j, 0, 1) with the regions' XYZ under the match light equal (Newton
    with a finite-difference Jacobian and step halving)."""
    bumps = np.array([np.exp(-0.5 * ((FINE - c) / s) ** 2) for c, s in BUMPS])

    def albedo(c):
        return np.clip(b0_fine + c @ bumps, 0.0, 1.0)

    def residual(c):
        xa, xb = pred.xyz(a_fine, albedo(c))
        return (xb - xa) / xa[1]

    c = np.zeros(len(BUMPS))
    f = residual(c)
    for _ in range(30):
        if np.abs(f).max() < 1e-7:
            break
        jac = np.empty((3, len(BUMPS)))
        for j in range(len(BUMPS)):
            dc = np.zeros(len(BUMPS))
            dc[j] = 1e-4
            jac[:, j] = (residual(c + dc) - f) / 1e-4
        step = np.linalg.lstsq(jac, -f, rcond=None)[0]
        t = 1.0
        while t > 1e-3:
            f_new = residual(c + t * step)
            if np.linalg.norm(f_new) < np.linalg.norm(f):
                break
            t *= 0.5
        c, f = c + t * step, f_new
    if not np.abs(f).max() < 1e-5:
        raise pd.DemoFailure("no smooth correction of tissue B's albedo matches tissue A in the image "
                             "(relative XYZ residual %.2g)" % np.abs(f).max())
    return albedo(c), c


def label_masks(tools, base, ia, ib, out, size, spp, seed):
    """The tissues' regions from a two-bin label render (its own seed: regions chosen from the same
    noise as the calibration would favour pixels whose noise is high, a bias of the response):
    tissue A reflects only the blue bin, tissue B only the red one; a pixel belongs to a tissue where
    that tissue's bin is bright and three times the other's."""
    label = json.loads(json.dumps(base))
    label["bins"] = "edges:380,580,780"
    label["materials"][ia]["albedo"] = "box:380:580"
    label["materials"][ib]["albedo"] = "box:580:780"
    pd.write_scene(label, out / "labels.json")
    pd.render(tools, out / "labels.json", out / "labels.exr", size, spp, seed)
    t, _ = pd.combined_transport(out / "labels.exr", base)
    only_a, only_b = t[:, :, 0], t[:, :, 1]
    level = np.percentile(only_a + only_b, 99)
    if not level > 0:
        raise pd.DemoFailure("the label render shows neither tissue")
    mask_a = (only_a > 3.0 * only_b) & (only_a > 0.1 * level)
    mask_b = (only_b > 3.0 * only_a) & (only_b > 0.1 * level)
    if mask_a.sum() == 0 or mask_b.sum() == 0:
        raise pd.DemoFailure("a tissue has no region in the image (%d, %d pixels)" % (mask_a.sum(), mask_b.sum()))
    return mask_a, mask_b


def calibration(tools, base, ia, ib, masks, out, size, spp, seed):
    """The response tables of the two regions (len(GRID)² arrays) from one render."""
    n = len(GRID)
    edges = list(np.linspace(380.0, 780.0, n * n + 1))
    values = {ia: np.repeat(GRID, n), ib: np.tile(GRID, n)}  # bin i·n + j holds (GRID[i], GRID[j])
    cal = json.loads(json.dumps(base))
    cal["bins"] = pd.bins_spec(edges)
    for idx, name in ((ia, "a"), (ib, "b")):
        lam, val = pd.staircase(edges, values[idx])
        pd.write_spectrum_csv(out / ("calibration_albedo_%s.csv" % name), lam, val, "albedo")
        cal["materials"][idx]["albedo"] = "csv:calibration_albedo_%s.csv" % name
    pd.write_scene(cal, out / "calibration.json")
    pd.render(tools, out / "calibration.json", out / "calibration.exr", size, spp, seed)
    t, _ = pd.combined_transport(out / "calibration.exr", base)
    t = t.reshape(t.shape[0], t.shape[1], n, n)
    tables = []
    for mask in masks:
        table = pd.region_mean(t, mask)
        # Monotone in both albedos (noise could make neighbours swap at tiny sample counts).
        tables.append(np.maximum.accumulate(np.maximum.accumulate(table, axis=0), axis=1))
    return tables


def measure(tools, exr, base, spec, bins, masks, out, key, png=True):
    """ΔE00 between the regions in the image relit under `spec` (and a PNG adapted to D65)."""
    pd.run([tools.relight, exr] + pd.relight_args(base, spec) + ["-o", out / ("relit_%s.exr" % key)], quiet=True)
    if png:
        pd.run([tools.relight, exr] + pd.relight_args(base, spec) + ["--adapt", "-o", out / ("relit_%s.png" % key)],
               quiet=True)
    xyz = pd.xyz_image(out / ("relit_%s.exr" % key))
    return pd.delta_e(tools, spec, bins, pd.region_mean(xyz, masks[0]), pd.region_mean(xyz, masks[1]))


def main():
    args = pd.parse_args("reveal-demo", __doc__.splitlines()[0], 192, 64, 64, 64)
    out = args.out
    tools = pd.Tools()
    base = pd.load_scene_copy(pd.ROOT / "data" / "scenes" / "mri.json")
    a_name, b_name = TISSUES
    ia, ib = pick_materials(base, TISSUES)
    render_bins = base.get("bins", "linear:380:780:16")

    # 1. Materials as surfaces.
    lam, val = pd.tabulate(tools, ALBEDO_A, out / "albedo_a.csv")
    a_fine = np.interp(FINE, lam, val)
    pd.run([tools.metamer, "metamer", "--albedo", "csv:%s" % (out / "albedo_a.csv"), "--match-light", MATCH,
            "--split-light", SPLIT, "-o", out / "albedo_b_surface.csv"])
    lam, val = pd.read_spectrum_csv(out / "albedo_b_surface.csv")
    b0_fine = np.interp(FINE, lam, val)

    # 2. Regions and calibration (twice the samples and their own seeds: the calibration's noise goes
    # into the design).
    masks = label_masks(tools, base, ia, ib, out, args.size, 2 * args.spp, args.seed + 2)
    tables = calibration(tools, base, ia, ib, masks, out, args.size, 2 * args.spp, args.seed + 1)
    np.save(out / "masks.npy", np.stack(masks))
    np.save(out / "response.npy", np.stack(tables))

    # 3. Tissue B's albedo for a match in the image.
    pd.run([tools.metamer, "--bins", render_bins, "weights", "--light", MATCH, "-o", out / "weights_D65.csv"], quiet=True)
    pred = Predictor(tables, out / "weights_D65.csv")
    bins = pd.bins_spec(pred.edges)
    b_fine, coeffs = solve_albedo_b(pred, a_fine, b0_fine)
    pd.write_spectrum_csv(out / "albedo_b.csv", FINE, b_fine, "albedo")
    predicted_surface = pd.delta_e(tools, MATCH, bins, *pred.xyz(a_fine, b0_fine))

    def scene_with(b_csv, name):
        s = json.loads(json.dumps(base))
        s["materials"][ia]["albedo"] = "csv:albedo_a.csv"
        s["materials"][ib]["albedo"] = "csv:%s" % b_csv
        pd.write_scene(s, out / name)
        return out / name

    # The surface metamer as it is, for comparison (same seed as the final render).
    pd.render(tools, scene_with("albedo_b_surface.csv", "mri_surface_metamers.json"), out / "mri_surface.exr",
              args.size, args.spp, args.seed)
    # 4. The render, and the lights designed from its regions.
    pd.render(tools, scene_with("albedo_b.csv", "mri_metamers.json"), out / "mri.exr", args.size, args.spp, args.seed)
    t, _ = pd.combined_transport(out / "mri.exr", base)
    for name, mask in (("a", masks[0]), ("b", masks[1])):
        lam, val = pd.staircase(pred.edges, pd.region_mean(t, mask))
        pd.write_spectrum_csv(out / ("region_%s.csv" % name), lam, val, "transport")
    regions = ["--albedo-a", "csv:%s" % (out / "region_a.csv"), "--albedo-b", "csv:%s" % (out / "region_b.csv")]
    designs = {
        "hide": pd.run([tools.metamer, "--bins", bins, "light"] + regions +
                       ["--hide", "--reference", HIDE_REFERENCE, "-o", out / "light_hide.csv"]),
        "reveal": pd.run([tools.metamer, "--bins", bins, "light"] + regions + ["--reveal", "-o", out / "light_reveal.csv"]),
    }

    # 5. Relight and measure.
    measured = {"D65 (surface metamer)": measure(tools, out / "mri_surface.exr", base, MATCH, bins, masks, out,
                                                 "surface_D65")}
    lights = {"D65": MATCH, "A": "A", "F11": SPLIT, "hide": "csv:%s" % (out / "light_hide.csv"),
              "reveal": "csv:%s" % (out / "light_reveal.csv")}
    for key, spec in lights.items():
        measured[key] = measure(tools, out / "mri.exr", base, spec, bins, masks, out, key)
    rows = [["D65", "tissue B = surface metamer (uncalibrated)", "%.2f" % measured["D65 (surface metamer)"]],
            ["D65", "match (calibrated)", "%.2f" % measured["D65"]],
            ["A (tungsten)", "", "%.2f" % measured["A"]],
            ["F11", "split light of the surface design", "%.2f" % measured["F11"]],
            ["hide", "designed, closest to F11", "%.2f" % measured["hide"]],
            ["reveal", "designed, D65's luminance", "%.2f" % measured["reveal"]]]

    crop = pd.bounding_box(masks[0] | masks[1], 0.05)
    pd.figure_of_images([(out / "relit_D65.png", "D65: ΔE00 = %.2f" % measured["D65"]),
                         (out / "relit_F11.png", "F11: ΔE00 = %.1f" % measured["F11"]),
                         (out / "relit_hide.png", "hiding light: ΔE00 = %.2f" % measured["hide"]),
                         (out / "relit_reveal.png", "revealing light: ΔE00 = %.1f" % measured["reveal"])],
                        out / "mri_side_by_side.png", title="Colin27 MRI, %s vs %s (one render, displayed adapted to D65)"
                        % (a_name, b_name), crop=crop)
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    ax.plot(FINE, a_fine, color="tab:green", label="albedo A (%s, %s)" % (a_name, ALBEDO_A))
    ax.plot(FINE, b0_fine, color="tab:purple", ls=":", label="surface metamer of A")
    ax.plot(FINE, b_fine, color="tab:purple", label="albedo B (%s, calibrated)" % b_name)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("single-scattering albedo")
    ax.set_ylim(0, 1.02)
    ax2 = ax.twinx()
    for key, colour in (("hide", "tab:orange"), ("reveal", "tab:red")):
        ll, vv = pd.read_spectrum_csv(out / ("light_%s.csv" % key))
        ax2.plot(ll, vv / vv.max(), color=colour, ls="--", lw=0.9, label="%s light" % key)
    pd.finish_spectra_plot(fig, ax, ax2, out / "mri_spectra.png")

    pd.write_table(out / "results.md", ["light", "", "ΔE00 between the tissues' regions (relit image)"], rows)
    (out / "design_hide.txt").write_text(designs["hide"])
    (out / "design_reveal.txt").write_text(designs["reveal"])
    summary = {"tissues": [a_name, b_name], "size": args.size, "spp": args.spp, "region_pixels":
               [int(m.sum()) for m in masks], "bump_coefficients": list(coeffs),
               "predicted_delta_e00_surface_metamer_D65": predicted_surface, "delta_e00": measured}
    (out / "results.json").write_text(json.dumps(summary, indent=2) + "\n")
    print("calibration model: the surface metamer was predicted at ΔE00 %.2f under D65, measured %.2f"
          % (predicted_surface, measured["D65 (surface metamer)"]))
    if not measured["D65"] < 1.0:
        raise pd.DemoFailure("ΔE00 under D65 is %.2f, not < 1" % measured["D65"])
    if not measured["hide"] < 1.0:
        raise pd.DemoFailure("ΔE00 under the hiding light is %.2f, not < 1" % measured["hide"])
    if not measured["reveal"] > 10.0:
        raise pd.DemoFailure("ΔE00 under the revealing light is %.2f, not > 10" % measured["reveal"])
    print("OK: the tissues match under D65 (ΔE00 %.2f) and under the hiding light (%.2f); the revealing "
          "light separates them (%.1f)." % (measured["D65"], measured["hide"], measured["reveal"]))


if __name__ == "__main__":
    pd.main_wrapper(main)
