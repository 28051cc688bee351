"""Shared helpers of the demonstration scripts (metamerism-demo, scattering-demo, reveal-demo).

They run the Prizma executables, read their EXR files with OpenImageIO, measure regions of relit
images and draw figures with matplotlib. Colour differences are computed by the library's CIEDE2000
through `prizma-metamer delta-e` (not re-implemented here).
"""
import argparse
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


class DemoFailure(Exception):
    """The demonstration's claim did not hold (exit code 1)."""


def parse_args(name, description, default_size, default_spp, small_size, small_spp):
    p = argparse.ArgumentParser(prog=name, description=description)
    p.add_argument("out", nargs="?", default=str(ROOT / "demo-out" / name), help="output folder (default: demo-out/%s)" % name)
    p.add_argument("--small", action="store_true", help="tiny image and few samples (the ctest run)")
    p.add_argument("--size", type=int, help="image width and height in pixels (default %d, --small %d)" % (default_size, small_size))
    p.add_argument("--spp", type=int, help="samples per pixel (default %d, --small %d)" % (default_spp, small_spp))
    p.add_argument("--seed", type=int, default=1, help="render seed")
    args = p.parse_args()
    if args.size is None:
        args.size = small_size if args.small else default_size
    if args.spp is None:
        args.spp = small_spp if args.small else default_spp
    args.out = Path(args.out).resolve()
    args.out.mkdir(parents=True, exist_ok=True)
    return args


class Tools:
    """Where the executables are: $PRIZMA_RENDER / $PRIZMA_RELIGHT / $PRIZMA_METAMER, else the build
    folder ($PRIZMA_BUILD_DIR, default build/)."""

    def __init__(self):
        build = Path(os.environ.get("PRIZMA_BUILD_DIR", ROOT / "build"))
        self.render = self._find("PRIZMA_RENDER", build / "renderer" / "prizma-render")
        self.relight = self._find("PRIZMA_RELIGHT", build / "relight" / "prizma-relight")
        self.metamer = self._find("PRIZMA_METAMER", build / "libspectral" / "prizma-metamer")

    @staticmethod
    def _find(var, default):
        path = Path(os.environ.get(var, default))
        if not path.is_file():
            raise DemoFailure("%s not found (build first with scripts/build, or set %s)" % (path, var))
        return str(path)


def run(cmd, quiet=False):
    """Runs a command; raises DemoFailure with its stderr when it fails. Returns stdout."""
    cmd = [str(c) for c in cmd]
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise DemoFailure("command failed (exit %d): %s\n%s%s" % (r.returncode, " ".join(cmd), r.stdout, r.stderr))
    if not quiet and r.stdout.strip():
        print(r.stdout.rstrip(), flush=True)
    return r.stdout


def read_image(path):
    """(pixels as float32 H×W×C, channel names, ImageSpec)."""
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise DemoFailure("%s: %s" % (path, buf.geterror()))
    spec = buf.spec()
    pixels = buf.get_pixels(oiio.FLOAT)
    if pixels is None:
        raise DemoFailure("%s: cannot read pixels: %s" % (path, buf.geterror()))
    return np.asarray(pixels, dtype=np.float64).reshape(spec.height, spec.width, spec.nchannels), list(spec.channelnames), spec


_T_CHANNEL = re.compile(r"^(?:(?P<layer>.+)\.)?T\.(?P<nm>[0-9]*,?[0-9]*)nm$")


def spectral_layer(path, light=None):
    """Transport bins of one light's layer (None: the top-level layer) as H×W×n sorted by wavelength,
    and the bin edges from prizma:binEdgesNm."""
    pixels, names, spec = read_image(path)
    chosen = []
    for i, n in enumerate(names):
        m = _T_CHANNEL.match(n)
        if m and m.group("layer") == light:
            chosen.append((float(m.group("nm").replace(",", ".")), i))
    if not chosen:
        raise DemoFailure("%s: no spectral channels for layer %s" % (path, light or "(top level)"))
    chosen.sort()
    edges = spec.getattribute("prizma:binEdgesNm")
    return pixels[:, :, [i for _, i in chosen]], (list(edges) if edges is not None else None)


def bins_spec(edges):
    return "edges:" + ",".join("%.6g" % e for e in edges)


XYZ_CHROMATICITIES = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 / 3.0, 1.0 / 3.0)


def xyz_image(path):
    """The X, Y, Z of an XYZ EXR from prizma-relight: channels R, G, B with XYZ's chromaticities
    (OpenEXR's convention, docs/relight.md)."""
    pixels, names, spec = read_image(path)
    chroma = spec.getattribute("chromaticities")
    if names[:3] != ["R", "G", "B"] or chroma is None or \
            not np.allclose(np.asarray(chroma, dtype=np.float64), XYZ_CHROMATICITIES, atol=1e-6):
        raise DemoFailure("%s: expected R, G, B channels holding X, Y, Z (XYZ chromaticities); got %s, chromaticities %s"
                          % (path, ", ".join(names), chroma))
    return pixels[:, :, :3]


def side_masks(total, fraction=0.5):
    """Masks of the bright core of the object in the left and the right half of the image: pixels
    above `fraction` of the half's 99th percentile of `total` (robust to a few noisy pixels)."""
    h, w = total.shape
    masks = []
    for lo, hi in ((0, w // 2), (w - w // 2, w)):
        part = np.zeros_like(total, dtype=bool)
        level = np.percentile(total[:, lo:hi], 99)
        if not level > 0:
            raise DemoFailure("no object visible in image columns %d..%d" % (lo, hi))
        part[:, lo:hi] = total[:, lo:hi] > fraction * level
        masks.append(part)
    return masks


def region_mean(image, mask):
    if mask.sum() == 0:
        raise DemoFailure("empty region")
    return image[mask].mean(axis=0)


def delta_e(tools, light, bins, xyz_a, xyz_b):
    """CIEDE2000 between two XYZ colours of an image relit under `light` (Lab white: a perfect white
    reflector under that light in the render's bins, Y = 1)."""
    out = run([tools.metamer, "--bins", bins, "delta-e", "--light", light,
               "--xyz-a", ",".join("%.9g" % v for v in xyz_a), "--xyz-b", ",".join("%.9g" % v for v in xyz_b)], quiet=True)
    m = re.search(r"dE00:\s*([0-9.eE+-]+)", out)
    if not m:
        raise DemoFailure("unexpected prizma-metamer delta-e output: " + out)
    return float(m.group(1))


def write_spectrum_csv(path, lambda_nm, values, name="value"):
    with open(path, "w") as f:
        f.write("wavelength_nm,%s\n" % name)
        for l, v in zip(lambda_nm, values):
            f.write("%.6f,%.9g\n" % (l, v))


def read_spectrum_csv(path):
    rows = []
    for line in open(path):
        line = line.split("#")[0].strip()
        if not line:
            continue
        try:
            rows.append([float(x) for x in line.split(",")[:2]])
        except ValueError:
            continue  # header
    a = np.array(rows)
    return a[:, 0], a[:, 1]


def bounding_box(mask, margin=0.15):
    """(y0, y1, x0, x1) around the True pixels of `mask`, grown by `margin` of the larger side, square."""
    ys, xs = np.nonzero(mask)
    h, w = mask.shape
    cy, cx = 0.5 * (ys.min() + ys.max()), 0.5 * (xs.min() + xs.max())
    half = 0.5 * max(ys.max() - ys.min(), xs.max() - xs.min()) * (1 + 2 * margin) + 1
    y0, y1 = int(max(0, cy - half)), int(min(h, cy + half + 1))
    x0, x1 = int(max(0, cx - half)), int(min(w, cx + half + 1))
    return y0, y1, x0, x1


def figure_of_images(items, out_path, title=None, width_in=3.2, crop=None):
    """A row of images with captions: items = [(png_path, caption), …]; crop = (y0, y1, x0, x1)."""
    fig, axes = plt.subplots(1, len(items), figsize=(width_in * len(items), width_in + 0.5))
    if len(items) == 1:
        axes = [axes]
    for ax, (png, caption) in zip(axes, items):
        img, _, _ = read_image(png)
        if crop is not None:
            img = img[crop[0]:crop[1], crop[2]:crop[3]]
        ax.imshow(np.clip(img[:, :, :3], 0, 1), interpolation="nearest")
        ax.set_title(caption, fontsize=9)
        ax.axis("off")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(out_path, dpi=80)
    plt.close(fig)


def finish_spectra_plot(fig, ax, ax_lights, out_path):
    """Labels the lights' axis (relative power), merges both axes' legends and saves the figure."""
    ax_lights.set_ylabel("relative power")
    ax_lights.set_ylim(0, 1.05)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax_lights.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(out_path, dpi=80)
    plt.close(fig)


def write_table(path, header, rows):
    """A Markdown table, also printed."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(str(c) for c in r) + " |")
    text = "\n".join(lines) + "\n"
    Path(path).write_text(text)
    print(text)
    return text


def main_wrapper(main):
    try:
        main()
    except DemoFailure as e:
        print("FAILED: %s" % e, file=sys.stderr)
        sys.exit(1)


def load_scene_copy(scene_path):
    """The scene's JSON with relative file paths (volume, transfer-function image) made absolute, so
    the copy can be written into the output folder."""
    scene_path = Path(scene_path).resolve()
    scene = json.loads(scene_path.read_text())
    base = scene_path.parent
    vol = scene.get("volume", {})
    if isinstance(vol, dict) and "path" in vol and not os.path.isabs(vol["path"]):
        vol["path"] = str((base / vol["path"]).resolve())
    tf = scene.get("transfer_function")
    if isinstance(tf, dict) and "image" in tf and not os.path.isabs(tf["image"]):
        tf["image"] = str((base / tf["image"]).resolve())
    for m in scene.get("materials", []):
        for key in ("albedo", "extinction", "anisotropy"):
            v = m.get(key)
            if isinstance(v, str) and v.startswith("csv:") and not os.path.isabs(v[4:]):
                m[key] = "csv:" + str((base / v[4:]).resolve())
    scene.pop("output", None)
    return scene


def write_scene(scene, path):
    Path(path).write_text(json.dumps(scene, indent=2) + "\n")
    return path


def render(tools, scene_path, exr, size, spp, seed=1, preview=None):
    cmd = [tools.render, scene_path, "-o", exr, "--spp", spp, "--width", size, "--height", size, "--seed", seed]
    if preview:
        cmd += ["--preview", preview]
    run(cmd)


def tabulate(tools, spec, out_csv, step=1.0, lo=380.0, hi=780.0):
    run([tools.metamer, "tabulate", "--spectrum", spec, "--from", lo, "--to", hi, "--step", step, "-o", out_csv], quiet=True)
    return read_spectrum_csv(out_csv)


def staircase(edges, values):
    """A tabulated spectrum constant inside each bin (value jumps within 1e-3 nm of the edges), so its
    bin averages are the given values."""
    lam, val = [], []
    for lo, hi, v in zip(edges[:-1], edges[1:], values):
        lam += [lo + 1e-3, hi - 1e-3]
        val += [v, v]
    return lam, val


def light_scales(scene):
    """[(name, scale)] of the scene's lights: the factor of their default spectrum ("D65*0.3" → 0.3),
    so relit images keep the scene's balance between lights."""
    out = []
    for l in scene.get("lights", []):
        spec = l.get("spectrum", "D65")
        scale = 1.0
        if isinstance(spec, dict):
            scale = float(spec.get("scale", 1.0))
            spec = spec.get("spectrum", "D65")
        if isinstance(spec, str) and "*" in spec:
            try:
                scale *= float(spec.rsplit("*", 1)[1])
            except ValueError:
                pass
        out.append((l["name"], scale))
    return out


def relight_args(scene, spec, only=None):
    """--light arguments giving every light (or only the lights in `only`, the others off) the spectrum
    `spec` times the light's own scale."""
    args = []
    for name, scale in light_scales(scene):
        if only is not None and name not in only:
            value = "off"
        else:
            value = spec if scale == 1.0 else "%s*%.9g" % (spec, scale)
        args += ["--light", "%s=%s" % (name, value)]
    return args


def combined_transport(exr, scene):
    """Σ_l scale_l · T_l: the transport that relight_args(scene, …) multiplies by the light, and the
    bin edges."""
    lights = light_scales(scene)
    if len(lights) < 2:
        t, edges = spectral_layer(exr)
        return t * (lights[0][1] if lights else 1.0), edges
    total, edges = None, None
    for name, scale in lights:
        t, edges = spectral_layer(exr, name)
        total = scale * t if total is None else total + scale * t
    return total, edges
