"""fluorescence-demo: a tissue phantom with a fluorescent inclusion (data/scenes/fluorescent_phantom.json),
rendered once and relit under daylight (D65) and a violet LED: the inclusion is nearly invisible
under D65 and glows under the LED.

The phantom is a milky scattering cube; a sphere inside it is the same tissue plus a PpIX-like dye
(protoporphyrin IX, the dye of fluorescence-guided brain surgery: it absorbs violet light in its
Soret band around 405 nm and emits red at 635 and 704 nm). Under daylight the dye takes a little
violet, to which the eye is nearly blind, and gives back a little deep red; under a violet LED
(405 nm) everything the tissue reflects is violet, and the dye turns it into red light that the eye
sees far better.

Steps
1. Label render (its own seed, one bin per region, no dye): the inclusion alone, dense and white,
   in the first bin, the tissue thin in the second: the inclusion's pixels (where it is bright), and
   a ring of tissue pixels around it (its surroundings).
2. The render: one bispectral file (prizma-render writes the off-diagonal transport M[out][in] as
   T.<in>nm.<out>nm channels per light, docs/fluorescence.md). A control render of the same scene
   without the dye (same seed) shows how much of the difference is the geometry alone.
3. The one render relit under D65 and under the LED (prizma-relight: T·E + M·E, then XYZ); the
   regions' mean XYZ → CIELAB relative to each light's white → CIEDE2000 (prizma-metamer delta-e).
Claim: ΔE00 between the inclusion and its surroundings < 2 under D65 and > 20 under the LED.
"""
import json
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import prizma_demo as pd  # noqa: E402
from prizma_demo import plt  # noqa: E402

DAYLIGHT = "D65"
LED = "gaussian:405:20"  # a violet LED: 405 nm, 20 nm FWHM
LED_NAME = "violet LED (405 nm)"
REPORT_LIGHTS = [("D65", DAYLIGHT), ("A", "A"), ("LED-B1 (white LED)", "LED-B1"), (LED_NAME, LED)]
HIDDEN_BELOW = 2.0
GLOWS_ABOVE = 20.0

_BISPECTRAL = re.compile(r"^(?:(?P<layer>.+)\.)?T\.(?P<inn>[0-9]*,?[0-9]*)nm\.(?P<out>[0-9]*,?[0-9]*)nm$")


def absolute_fluorescence_paths(scene, scene_path):
    """The csv: spectra of the fluorescence fields made absolute (load_scene_copy does the others)."""
    base = Path(scene_path).resolve().parent
    for m in scene.get("materials", []):
        fl = m.get("fluorescence")
        if not isinstance(fl, dict):
            continue
        for key in ("absorption", "emission"):
            v = fl.get(key)
            if isinstance(v, str) and v.startswith("csv:") and not Path(v[4:]).is_absolute():
                fl[key] = "csv:" + str((base / v[4:]).resolve())


def dilate(mask, steps):
    """Binary dilation by `steps` pixels (8-neighbourhood)."""
    out = mask.copy()
    for _ in range(steps):
        grown = out.copy()
        grown[1:, :] |= out[:-1, :]
        grown[:-1, :] |= out[1:, :]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        grown[1:, 1:] |= out[:-1, :-1]
        grown[:-1, :-1] |= out[1:, 1:]
        grown[1:, :-1] |= out[:-1, 1:]
        grown[:-1, 1:] |= out[1:, :-1]
        out = grown
    return out


def label_masks(tools, base, dyed, out, size, spp, seed):
    """(inclusion, surroundings) pixel masks from a two-bin label render."""
    label = json.loads(json.dumps(base))
    label["bins"] = "edges:380,580,780"
    for i, m in enumerate(label["materials"]):
        m.pop("fluorescence", None)
        m["anisotropy"] = 0
        if i == dyed:
            m["albedo"], m["extinction"] = "box:380:580", 60
        else:
            m["albedo"], m["extinction"] = "box:580:780", 0.5
    pd.write_scene(label, out / "labels.json")
    pd.render(tools, out / "labels.json", out / "labels.exr", size, spp, seed)
    # The directional light only (the environment light is seen directly around the object).
    key = next(l["name"] for l in base["lights"] if any(l.get("direction", [0, 0, 0])))
    t, _ = pd.spectral_layer(out / "labels.exr", key if len(base["lights"]) > 1 else None)
    inc, tis = t[:, :, 0], t[:, :, 1]
    level = np.percentile(inc, 99)
    if not level > 0:
        raise pd.DemoFailure("the label render does not show the inclusion")
    inclusion = inc > 0.5 * level
    near = inc > 0.02 * level
    tissue_level = np.percentile(tis, 99)
    in_cube = (tis > 0.2 * tissue_level) | near
    # Surroundings: tissue pixels in a ring a little way out from the inclusion's edge (the light the
    # dye re-emits spreads into the tissue around it; the ring starts beyond most of it).
    ring = dilate(near, max(2, size // 16)) & ~dilate(near, max(1, size // 48)) & in_cube & ~near
    if inclusion.sum() < 4 or ring.sum() < 4:
        raise pd.DemoFailure("regions too small (inclusion %d, surroundings %d pixels)" % (inclusion.sum(), ring.sum()))
    return inclusion, ring


def relit_xyz(tools, exr, base, spec, out, key, png_exposure=None):
    """The region colours' source: the image relit under `spec` (every light of the scene given that
    spectrum times its own scale), linear XYZ; optionally a PNG at the given exposure (EV)."""
    pd.run([tools.relight, exr] + pd.relight_args(base, spec) + ["-o", out / ("relit_%s.exr" % key)], quiet=True)
    if png_exposure is not None:
        pd.run([tools.relight, exr] + pd.relight_args(base, spec) +
               ["--exposure", "%.3f" % png_exposure, "-o", out / ("relit_%s.png" % key)], quiet=True)
    return pd.xyz_image(out / ("relit_%s.exr" % key))


def bispectral_region_mean(exr, base, mask):
    """Σ_l scale_l · M_l averaged over the region: (in centres, out centres, matrix[out][in])."""
    pixels, names, _ = pd.read_image(exr)
    scales = dict(pd.light_scales(base))
    several = len(scales) > 1
    terms = {}
    for i, n in enumerate(names):
        m = _BISPECTRAL.match(n)
        if not m:
            continue
        layer = m.group("layer")
        if several and layer not in scales:
            continue  # the top-level sum of a file with several lights
        scale = scales.get(layer, 1.0) if several else next(iter(scales.values()), 1.0)
        key = (float(m.group("inn").replace(",", ".")), float(m.group("out").replace(",", ".")))
        terms[key] = terms.get(key, 0.0) + scale * pixels[:, :, i][mask].mean()
    if not terms:
        raise pd.DemoFailure("%s: no bispectral channels" % exr)
    ins = sorted({k[0] for k in terms})
    outs = sorted({k[1] for k in terms})
    mat = np.zeros((len(outs), len(ins)))
    for (li, lo), v in terms.items():
        mat[outs.index(lo), ins.index(li)] = v
    return np.array(ins), np.array(outs), mat


def main():
    args = pd.parse_args("fluorescence-demo", __doc__.splitlines()[0], 192, 64, 48, 128)
    out = args.out
    tools = pd.Tools()
    source = pd.ROOT / "data" / "scenes" / "fluorescent_phantom.json"
    base = pd.load_scene_copy(source)
    absolute_fluorescence_paths(base, source)
    mats = base["materials"]
    dyed = next((i for i, m in enumerate(mats) if "fluorescence" in m), None)
    if dyed is None or len(mats) != 2:
        raise pd.DemoFailure("fluorescent_phantom.json must have two materials, one with a fluorescence field")

    # 1. Regions.
    inclusion, ring = label_masks(tools, base, dyed, out, args.size, args.spp, args.seed + 2)
    np.save(out / "masks.npy", np.stack([inclusion, ring]))

    # 2. The render, and the control without the dye.
    pd.write_scene(base, out / "phantom.json")
    pd.render(tools, out / "phantom.json", out / "phantom.exr", args.size, args.spp, args.seed)
    plain = json.loads(json.dumps(base))
    plain["materials"][dyed].pop("fluorescence")
    pd.write_scene(plain, out / "phantom_without_dye.json")
    pd.render(tools, out / "phantom_without_dye.json", out / "phantom_without_dye.exr", args.size, args.spp, args.seed)
    _, edges = pd.spectral_layer(out / "phantom.exr")
    bins = pd.bins_spec(edges)

    # 3. Relight the one render and measure.
    measured, control, regions = {}, {}, {}
    for name, spec in REPORT_LIGHTS:
        key = re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_")
        xyz = relit_xyz(tools, out / "phantom.exr", base, spec, out, key)
        a, b = pd.region_mean(xyz, inclusion), pd.region_mean(xyz, ring)
        measured[name] = pd.delta_e(tools, spec, bins, a, b)
        regions[name] = {"inclusion_xyz": list(a), "surroundings_xyz": list(b)}
        xyz0 = relit_xyz(tools, out / "phantom_without_dye.exr", plain, spec, out, key + "_without_dye")
        control[name] = pd.delta_e(tools, spec, bins, pd.region_mean(xyz0, inclusion), pd.region_mean(xyz0, ring))
    # Display: daylight as it is. Under the LED (white-normalised: a perfect white has Y = 1) violet
    # light has X and Z far above its Y (the eye is some 200 times less sensitive at 405 nm than at
    # 635 nm), so that image is shown darker: the 99.5th percentile of its largest channel at 1 (no
    # adaptation: the violet stays violet, the glow pink, as under a surgical blue-violet lamp).
    xyz_led = pd.xyz_image(out / ("relit_%s.exr" % re.sub(r"[^A-Za-z0-9]+", "_", LED_NAME).strip("_")))
    led_ev = float(np.log2(1.0 / max(np.percentile(xyz_led.max(axis=2), 99.5), 1e-9)))
    relit_xyz(tools, out / "phantom.exr", base, DAYLIGHT, out, "D65", png_exposure=0.0)
    relit_xyz(tools, out / "phantom.exr", base, LED, out, "LED", png_exposure=led_ev)
    relit_xyz(tools, out / "phantom_without_dye.exr", plain, LED, out, "LED_without_dye", png_exposure=led_ev)

    # Figures: the relit images; the spectra; the inclusion's excitation–emission matrix.
    pd.figure_of_images([(out / "relit_D65.png", "D65: ΔE00 = %.2f" % measured["D65"]),
                         (out / "relit_LED.png", "violet LED: ΔE00 = %.1f" % measured[LED_NAME]),
                         (out / "relit_LED_without_dye.png", "violet LED, no dye (control)")],
                        out / "phantom_side_by_side.png",
                        title="One render relit: D65 (0 EV) and a 405 nm LED (%+.1f EV)" % led_ev)
    fl = mats[dyed]["fluorescence"]
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    la, va = pd.tabulate(tools, fl["absorption"], out / "dye_absorption.csv")
    le, ve = pd.tabulate(tools, fl["emission"], out / "dye_emission.csv")
    ax.fill_between(la, va / va.max(), color="tab:purple", alpha=0.35, label="dye absorption σf (Soret band, 405 nm)")
    ax.fill_between(le, ve / ve.max(), color="tab:red", alpha=0.35, label="dye emission (635, 704 nm)")
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("relative absorption / emission")
    ax.set_ylim(0, 1.05)
    ax.set_xlim(380, 780)
    ax2 = ax.twinx()
    for name, spec, colour in (("D65", DAYLIGHT, "0.4"), (LED_NAME, LED, "tab:blue")):
        ll, lv = pd.tabulate(tools, spec, out / ("light_%s.csv" % re.sub(r"[^A-Za-z0-9]+", "_", name)))
        ax2.plot(ll, lv / lv.max(), color=colour, lw=1.0, ls="--", label=name)
    pd.finish_spectra_plot(fig, ax, ax2, out / "phantom_spectra.png")
    ins, outs, mat = bispectral_region_mean(out / "phantom.exr", base, inclusion)
    fig, axm = plt.subplots(figsize=(4.2, 3.6))
    step_in = ins[1] - ins[0] if len(ins) > 1 else 20.0
    step_out = outs[1] - outs[0] if len(outs) > 1 else 20.0
    im = axm.imshow(mat, origin="lower", aspect="auto", cmap="magma",
                    extent=[ins[0] - step_in / 2, ins[-1] + step_in / 2, outs[0] - step_out / 2, outs[-1] + step_out / 2])
    fig.colorbar(im, ax=axm, label="M[out][in] (inclusion mean)")
    axm.set_xlabel("excitation bin centre λin (nm)")
    axm.set_ylabel("emission bin centre λout (nm)")
    axm.set_title("excitation–emission matrix of the render", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "phantom_matrix.png", dpi=80)
    plt.close(fig)

    rows = []
    for name, _ in REPORT_LIGHTS:
        role = "hides" if name == "D65" else ("reveals" if name == LED_NAME else "")
        rows.append([name, role, "%.2f" % measured[name], "%.2f" % control[name]])
    pd.write_table(out / "results.md", ["light", "claim", "ΔE00 inclusion vs surroundings", "same, without the dye"], rows)
    summary = {"size": args.size, "spp": args.spp, "seed": args.seed, "bins": bins, "led": LED,
               "led_display_ev": led_ev, "region_pixels": [int(inclusion.sum()), int(ring.sum())],
               "bispectral_pairs": int(np.count_nonzero(mat)), "delta_e00": measured,
               "delta_e00_without_dye": control, "regions": regions}
    (out / "results.json").write_text(json.dumps(summary, indent=2) + "\n")
    if not measured["D65"] < HIDDEN_BELOW:
        raise pd.DemoFailure("ΔE00 under D65 is %.2f, not < %g: the dye is not hidden" % (measured["D65"], HIDDEN_BELOW))
    if not measured[LED_NAME] > GLOWS_ABOVE:
        raise pd.DemoFailure("ΔE00 under the violet LED is %.2f, not > %g: the dye does not glow"
                             % (measured[LED_NAME], GLOWS_ABOVE))
    print("OK: the dyed inclusion is hidden under D65 (ΔE00 %.2f < %g) and glows under the violet LED "
          "(ΔE00 %.1f > %g), from one render." % (measured["D65"], HIDDEN_BELOW, measured[LED_NAME], GLOWS_ABOVE))
    print("Images and plots: %s (phantom_side_by_side.png, phantom_spectra.png, phantom_matrix.png)" % out)


if __name__ == "__main__":
    pd.main_wrapper(main)
