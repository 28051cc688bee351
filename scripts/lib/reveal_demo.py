"""reveal-demo: real data — the Colin27 MRI template (data/scenes/mri.json) with two tissues given
materials that are metameric under white light (D65); one render, then lights designed from the render
that hide or reveal the difference between the tissues.

Steps
1. Materials: tissue A keeps a natural reflectance a1, tissue B gets a metamer of it under D65
   (prizma-metamer metamer; split light F11).
2. Label render (segmentation only): tissue A narrow-band blue, tissue B narrow-band red, the others
   black; each pixel where one tissue clearly dominates belongs to that tissue's region.
3. The render. The region means of the transport bins of A and B are the spectra that the relighter
   will turn into the regions' colours; prizma-metamer light designs, from them, a light with D65's
   luminance that hides the difference (ΔE00 → 0) and one that reveals it (ΔE00 as large as
   possible), in the render's bins.
4. Relit under D65, the hiding and the revealing light: ΔE00 between the regions' mean XYZ.
Claim: revealing ΔE00 > D65 ΔE00 + 5 and > hiding ΔE00 + 5; hiding ΔE00 < D65 ΔE00.
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import prizma_demo as pd  # noqa: E402
from prizma_demo import plt  # noqa: E402

ALBEDO_A = "cc:2"  # light skin (ColorChecker Classic)
SPLIT = "F11"


def pick_materials(scene, names):
    mats = [m.get("name", "material%d" % i) for i, m in enumerate(scene["materials"])]
    idx = []
    for n in names:
        if n not in mats:
            raise pd.DemoFailure("mri.json has no material %r (materials: %s)" % (n, ", ".join(mats)))
        idx.append(mats.index(n))
    return idx


def main():
    import argparse  # noqa: F401
    args = pd.parse_args("reveal-demo", __doc__.splitlines()[0], 192, 32, 24, 8)
    out = args.out
    tools = pd.Tools()
    base = pd.load_scene_copy(pd.ROOT / "data" / "scenes" / "mri.json")
    tissue_names = [m.get("name") for m in base["materials"]]
    a_name, b_name = TISSUES if all(t in tissue_names for t in TISSUES) else tissue_names[-2:]
    ia, ib = pick_materials(base, [a_name, b_name])

    # 1. Metameric materials (reflectance domain, continuous integrals).
    pd.tabulate(tools, ALBEDO_A, out / "albedo_a.csv")
    pd.run([tools.metamer, "metamer", "--albedo", "csv:%s" % (out / "albedo_a.csv"), "--match-light", "D65",
            "--split-light", SPLIT, "-o", out / "albedo_b.csv"])

    # 2. Label render.
    label = json.loads(json.dumps(base))
    for i, m in enumerate(label["materials"]):
        m["albedo"] = "box:380:480" if i == ia else ("box:620:780" if i == ib else 0.0)
    pd.write_scene(label, out / "mri_labels.json")
    pd.render(tools, out / "mri_labels.json", out / "labels.exr", args.size, max(4, args.spp // 2), args.seed)
    t_label, edges = pd.combined_transport(out / "labels.exr", base)
    centres = 0.5 * (np.array(edges[:-1]) + np.array(edges[1:]))
    blue = t_label[:, :, centres < 480].sum(axis=2)
    red = t_label[:, :, centres > 620].sum(axis=2)
    level = np.percentile(blue + red, 99)
    if not level > 0:
        raise pd.DemoFailure("the label render shows neither tissue")
    mask_a = (blue > 3.0 * red) & (blue > 0.1 * level)
    mask_b = (red > 3.0 * blue) & (red > 0.1 * level)
    if mask_a.sum() == 0 or mask_b.sum() == 0:
        raise pd.DemoFailure("a tissue has no region in the image (%d, %d pixels)" % (mask_a.sum(), mask_b.sum()))
    np.save(out / "masks.npy", np.stack([mask_a, mask_b]))

    # 3. The render and the lights designed from it.
    final = json.loads(json.dumps(base))
    final["materials"][ia]["albedo"] = "csv:albedo_a.csv"
    final["materials"][ib]["albedo"] = "csv:albedo_b.csv"
    pd.write_scene(final, out / "mri_metamers.json")
    pd.render(tools, out / "mri_metamers.json", out / "mri.exr", args.size, args.spp, args.seed)
    t, edges = pd.combined_transport(out / "mri.exr", base)
    bins = pd.bins_spec(edges)
    for name, mask in (("a", mask_a), ("b", mask_b)):
        lam, val = pd.staircase(edges, pd.region_mean(t, mask))
        pd.write_spectrum_csv(out / ("region_%s.csv" % name), lam, val, "transport")
    designs = {}
    for goal in ("hide", "reveal"):
        designs[goal] = pd.run([tools.metamer, "--bins", bins, "light", "--albedo-a", "csv:%s" % (out / "region_a.csv"),
                                "--albedo-b", "csv:%s" % (out / "region_b.csv"), "--" + goal, "-o", out / ("light_%s.csv" % goal)])

    # 4. Relight and measure.
    lights = {"D65": "D65", "hide": "csv:%s" % (out / "light_hide.csv"), "reveal": "csv:%s" % (out / "light_reveal.csv")}
    measured, rows = {}, []
    for key, spec in lights.items():
        pd.run([tools.relight, out / "mri.exr"] + pd.relight_args(base, spec) + ["-o", out / ("relit_%s.exr" % key)],
               quiet=True)
        # Displayed adapted to D65 (Bradford); the measurement is in CIELAB relative to the light's white.
        pd.run([tools.relight, out / "mri.exr"] + pd.relight_args(base, spec) +
               ["--adapt", "-o", out / ("relit_%s.png" % key)], quiet=True)
        xyz = pd.xyz_image(out / ("relit_%s.exr" % key))
        de = pd.delta_e(tools, spec, bins, pd.region_mean(xyz, mask_a), pd.region_mean(xyz, mask_b))
        measured[key] = de
        rows.append([key, "%.2f" % de])
    pd.figure_of_images([(out / "relit_D65.png", "D65: ΔE00 = %.1f" % measured["D65"]),
                         (out / "relit_hide.png", "hiding light: ΔE00 = %.1f" % measured["hide"]),
                         (out / "relit_reveal.png", "revealing light: ΔE00 = %.1f" % measured["reveal"])],
                        out / "mri_side_by_side.png", title="Colin27 MRI, %s vs %s (one render)" % (a_name, b_name),
                        crop=pd.bounding_box(mask_a | mask_b, 0.05))
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    for name, colour in (("a", "tab:green"), ("b", "tab:purple")):
        ll, vv = pd.read_spectrum_csv(out / ("albedo_%s.csv" % name))
        ax.plot(ll, vv, color=colour, label="albedo %s (%s)" % (name.upper(), a_name if name == "a" else b_name))
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("albedo")
    ax.set_ylim(0, 1.02)
    ax2 = ax.twinx()
    for key, colour in (("hide", "0.4"), ("reveal", "tab:red")):
        ll, vv = pd.read_spectrum_csv(out / ("light_%s.csv" % key))
        ax2.plot(ll, vv / vv.max(), color=colour, ls="--", lw=0.9, label="%s light" % key)
    pd.finish_spectra_plot(fig, ax, ax2, out / "mri_spectra.png")
    pd.write_table(out / "results.md", ["light", "ΔE00 between the tissues' regions (relit image)"], rows)
    (out / "design_hide.txt").write_text(designs["hide"])
    (out / "design_reveal.txt").write_text(designs["reveal"])
    (out / "results.json").write_text(json.dumps({"tissues": [a_name, b_name], "size": args.size, "spp": args.spp,
                                                  "delta_e00": measured}, indent=2) + "\n")
    if not measured["reveal"] > measured["D65"] + 5.0:
        raise pd.DemoFailure("revealing ΔE00 %.2f is not > D65's %.2f + 5" % (measured["reveal"], measured["D65"]))
    if not measured["reveal"] > measured["hide"] + 5.0:
        raise pd.DemoFailure("revealing ΔE00 %.2f is not > hiding %.2f + 5" % (measured["reveal"], measured["hide"]))
    if not measured["hide"] < measured["D65"]:
        raise pd.DemoFailure("hiding ΔE00 %.2f is not < D65's %.2f" % (measured["hide"], measured["D65"]))
    print("OK: tissue contrast ΔE00 %.2f under D65, %.2f hidden, %.2f revealed."
          % (measured["D65"], measured["hide"], measured["reveal"]))


TISSUES = ("grey_matter", "white_matter")

if __name__ == "__main__":
    pd.main_wrapper(main)
