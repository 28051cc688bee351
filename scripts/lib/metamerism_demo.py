"""metamerism-demo: two spheres whose materials are metamers — the same colour under D65, different
under a second light — rendered once and relit under both lights; the colour difference is measured
from the relit images.

Steps
1. Calibration render: both spheres get the same staircase albedo (one constant value per 10 nm bin,
   0 … 1). Because extinction and anisotropy are grey, the transport at a wavelength depends only on
   the albedo at that wavelength, so each sphere's region mean per bin gives its albedo → transport
   response R(a) (a volume is not a surface: multiple scattering makes R non-linear).
2. Design: the left sphere's albedo a1 gives the transport u1 = R_left(a1). prizma-metamer designs u2
   with the same XYZ under D65 in the render's bins and maximal ΔE00 under the split light, bounded by
   what the right sphere can reach; the right sphere's albedo is a2 = R_right⁻¹(u2).
3. One render with a1 and a2, relit under D65, the split light and the standard list; region means of
   the relit linear XYZ images → CIELAB → CIEDE2000 (library code via prizma-metamer delta-e).
Claim: ΔE00 < 1 under D65 and > 10 under the split light, measured in the relit images.
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import prizma_demo as pd  # noqa: E402
from prizma_demo import plt  # noqa: E402

MATCH_LIGHT = "D65"
REPORT_LIGHTS = ["D65", "A", "F2", "F11", "LED-B3"]
CALIBRATION_BINS = 40  # 10 nm over 380–780 nm


def material_indices(scene):
    """(left, right): the materials covering raw values 100 and 200 (the metamer_pair volume)."""
    mats = scene["materials"]
    found = {}
    for i, m in enumerate(mats):
        r = m.get("range")
        if r is None or m.get("units", "raw") != "raw":
            continue
        for v in (100, 200):
            if r[0] <= v <= r[1] and v not in found:
                found[v] = i
    if 100 in found and 200 in found:
        return found[100], found[200]
    if len(mats) >= 2:
        return 0, 1
    raise pd.DemoFailure("the scene needs two materials (values 100 and 200)")


def main():
    args = pd.parse_args("metamerism-demo", __doc__.splitlines()[0], 192, 64, 64, 128)
    out = args.out
    tools = pd.Tools()
    split_light = "F11"
    albedo_spec = "cc:4"  # foliage (ColorChecker Classic), a smooth natural reflectance
    source_scene = pd.ROOT / "data" / "scenes" / "metamers.json"
    base = pd.load_scene_copy(source_scene)
    left, right = material_indices(base)
    final_bins = base.get("bins", "linear:380:780:16")

    # 1. Calibration render with a staircase albedo on both spheres.
    cal_edges = list(np.linspace(380.0, 780.0, CALIBRATION_BINS + 1))
    steps = np.linspace(0.0, 1.0, CALIBRATION_BINS)
    lam, val = pd.staircase(cal_edges, steps)
    pd.write_spectrum_csv(out / "calibration_albedo.csv", lam, val, "albedo")
    cal = json.loads(json.dumps(base))
    cal["bins"] = "edges:" + ",".join("%g" % e for e in cal_edges)
    for i in (left, right):
        cal["materials"][i]["albedo"] = "csv:calibration_albedo.csv"
    pd.write_scene(cal, out / "calibration.json")
    # Twice the samples: its noise goes into the design of the right albedo.
    pd.render(tools, out / "calibration.json", out / "calibration.exr", args.size, 2 * args.spp, args.seed + 1)
    t_cal, _ = pd.combined_transport(out / "calibration.exr", base)
    # The spheres' regions: pixels where the first bin (albedo 0: no scattering, only the background
    # seen through the medium) is nearly dark, i.e. the sphere is opaque along the whole pixel.
    background = t_cal[:, :, 0]
    opaque = background < 0.02 * max(background.max(), 1e-12)
    half = opaque.shape[1] // 2
    masks = [opaque.copy(), opaque.copy()]
    masks[0][:, half:] = False
    masks[1][:, :half] = False
    if masks[0].sum() == 0 or masks[1].sum() == 0:
        raise pd.DemoFailure("no opaque sphere pixels found (%d, %d)" % (masks[0].sum(), masks[1].sum()))
    np.save(out / "masks.npy", np.stack(masks))
    response = [pd.region_mean(t_cal, m) for m in masks]  # R_side at the albedo values `steps`
    for r in response:
        if not (np.all(np.isfinite(r)) and r[-1] > 0):
            raise pd.DemoFailure("calibration render has no usable response")
    # Monotone (noise can make neighbours swap at tiny sample counts).
    response = [np.maximum.accumulate(r) for r in response]

    # 2. Design in the transport domain of the final render's bins.
    lam1, a1 = pd.tabulate(tools, albedo_spec, out / "albedo_left_reference.csv")
    # Transport divided by the most both spheres can reach, so the design's bounds are [0, 1]; matching
    # XYZ is linear, so the scale does not change which spectra match.
    u_max = float(min(response[0][-1], response[1][-1]))
    u1 = np.interp(a1, steps, response[0]) / u_max
    if u1.max() > 1.0:
        raise pd.DemoFailure("the right sphere cannot reach the left sphere's transport (%.3f > 1)" % u1.max())
    pd.write_spectrum_csv(out / "transport_left.csv", lam1, u1, "transport")
    # Designed in the render's bins (the scene's own "bins" string): what the relit image will show.
    design = pd.run([tools.metamer, "--bins", final_bins, "metamer", "--albedo", "csv:%s" % (out / "transport_left.csv"),
                     "--match-light", MATCH_LIGHT, "--split-light", split_light, "-o", out / "transport_right.csv"])
    lam2, u2 = pd.read_spectrum_csv(out / "transport_right.csv")
    u2 = u2 * u_max
    grid = np.arange(380.0, 780.0 + 0.5, 1.0)
    u2_fine = np.interp(grid, lam2, u2)
    a2 = np.interp(u2_fine, response[1], steps)  # R_right⁻¹ (monotone)
    a1_fine = np.interp(grid, lam1, a1)
    pd.write_spectrum_csv(out / "albedo_left.csv", grid, a1_fine, "albedo")
    pd.write_spectrum_csv(out / "albedo_right.csv", grid, np.clip(a2, 0.0, 1.0), "albedo")

    # 3. The render, relit.
    final = json.loads(json.dumps(base))
    final["materials"][left]["albedo"] = "csv:albedo_left.csv"
    final["materials"][right]["albedo"] = "csv:albedo_right.csv"
    pd.write_scene(final, out / "metamers.json")
    pd.render(tools, out / "metamers.json", out / "metamers.exr", args.size, args.spp, args.seed,
              preview=out / "metamers_preview.png")
    _, edges = pd.spectral_layer(out / "metamers.exr")
    bins = pd.bins_spec(edges)
    rows = []
    measured = {}
    for light in REPORT_LIGHTS + ([split_light] if split_light not in REPORT_LIGHTS else []):
        exr = out / ("relit_%s.exr" % light)
        pd.run([tools.relight, out / "metamers.exr"] + pd.relight_args(base, light) + ["-o", exr], quiet=True)
        xyz = pd.xyz_image(exr)
        xyz_l, xyz_r = (pd.region_mean(xyz, m) for m in masks)
        de = pd.delta_e(tools, light, bins, xyz_l, xyz_r)
        measured[light] = de
        role = "match" if light == MATCH_LIGHT else ("split" if light == split_light else "")
        rows.append([light, role, "%.2f" % de])
    for light in (MATCH_LIGHT, split_light):
        # Displayed adapted to D65 (Bradford), as the eye adapts to a light; the measurement above is
        # in CIELAB relative to each light's own white.
        pd.run([tools.relight, out / "metamers.exr"] + pd.relight_args(base, light) +
               ["--adapt", "--exposure", "1", "-o", out / ("relit_%s.png" % light)], quiet=True)

    # Figures: the two relit images, the spectra.
    pd.figure_of_images([(out / ("relit_%s.png" % MATCH_LIGHT), "%s: ΔE00 = %.2f" % (MATCH_LIGHT, measured[MATCH_LIGHT])),
                         (out / ("relit_%s.png" % split_light), "%s: ΔE00 = %.2f" % (split_light, measured[split_light]))],
                        out / "metamers_side_by_side.png", title="One render, two lights (displayed adapted to D65, +1 EV)",
                        crop=pd.bounding_box(masks[0] | masks[1], 0.1))
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    ax.plot(grid, a1_fine, color="tab:green", label="left albedo (%s)" % albedo_spec)
    ax.plot(grid, np.clip(a2, 0, 1), color="tab:purple", label="right albedo (designed metamer)")
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("single-scattering albedo")
    ax.set_ylim(0, 1.02)
    ax2 = ax.twinx()
    for light, colour in ((MATCH_LIGHT, "0.5"), (split_light, "tab:orange")):
        ll, lv = pd.tabulate(tools, light, out / ("light_%s.csv" % light))
        ax2.plot(ll, lv / lv.max(), color=colour, lw=0.8, ls="--", label=light)
    pd.finish_spectra_plot(fig, ax, ax2, out / "metamers_spectra.png")
    fig, ax = plt.subplots(figsize=(3.6, 3.0))
    ax.plot(steps, response[0], ".-", label="left sphere")
    ax.plot(steps, response[1], ".-", label="right sphere")
    ax.set_xlabel("albedo")
    ax.set_ylabel("mean transport (region)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "response.png", dpi=80)
    plt.close(fig)

    table = pd.write_table(out / "results.md", ["light", "role", "ΔE00 measured (relit image)"], rows)
    (out / "design.txt").write_text(design)
    summary = {"albedo": albedo_spec, "split_light": split_light, "size": args.size, "spp": args.spp,
               "bins": final_bins, "delta_e00": measured}
    (out / "results.json").write_text(json.dumps(summary, indent=2) + "\n")
    if not measured[MATCH_LIGHT] < 1.0:
        raise pd.DemoFailure("ΔE00 under %s is %.2f, not < 1" % (MATCH_LIGHT, measured[MATCH_LIGHT]))
    if not measured[split_light] > 10.0:
        raise pd.DemoFailure("ΔE00 under %s is %.2f, not > 10" % (split_light, measured[split_light]))
    print("OK: the metamers match under %s (ΔE00 %.2f < 1) and differ under %s (ΔE00 %.2f > 10)."
          % (MATCH_LIGHT, measured[MATCH_LIGHT], split_light, measured[split_light]))
    del table


if __name__ == "__main__":
    pd.main_wrapper(main)
