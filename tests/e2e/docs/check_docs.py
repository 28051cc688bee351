#!/usr/bin/env python3
"""Checks that what a docs page says about its examples' results holds (run by run-doc after the
page's blocks ran): check_docs.py PAGE RUN_DIR OUT_DIR [PAGE.md]. Exit 1 with one line per failed
claim. With PAGE.md, its colour claims (<!-- colour: … -->, colour_claims.py) are checked too,
against the images the blocks wrote and those the page shows."""
import os
import re
import sys

import numpy as np
import OpenImageIO as oiio

import colour_claims

failures = []


def claim(ok, text):
    print(("ok    " if ok else "FAIL  ") + text)
    if not ok:
        failures.append(text)


def pixels(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        sys.exit("%s: %s" % (path, buf.geterror()))
    px = np.asarray(buf.get_pixels(oiio.FLOAT), dtype=np.float64)
    return px.reshape(buf.spec().height, buf.spec().width, buf.spec().nchannels), buf.spec()


def de00_rows(text):
    """The `light  dE00` table prizma-metamer prints: {light: value}."""
    rows = {}
    for line in text.splitlines():
        m = re.match(r"^(.*\S)\s+(-?[0-9.]+)$", line)
        if m and not line.startswith("light "):
            rows[m.group(1).strip()] = float(m.group(2))
    return rows


def block(out_dir, n):
    with open(os.path.join(out_dir, "block-%d.txt" % n), encoding="utf-8") as f:
        return f.read()


def object_fraction(path, threshold=0.08):
    """Fraction of pixels unlike the background (the mean of the four corners' 4x4 pixels)."""
    px, _ = pixels(path)
    rgb = px[..., :3]
    corners = np.concatenate([rgb[:4, :4].reshape(-1, 3), rgb[:4, -4:].reshape(-1, 3),
                              rgb[-4:, :4].reshape(-1, 3), rgb[-4:, -4:].reshape(-1, 3)])
    background = corners.mean(axis=0)
    return float((np.abs(rgb - background).max(axis=2) > threshold).mean())


def user_guide(run, out):
    tour = os.path.join(run, "prizma-tour")
    for f in ("cube.exr", "cube.png", "zoom.exr", "zoom.png", "side.png", "back.png", "mixed.jpg", "p3.png",
              "side.exr", "live.png", "metamer.csv", "hide.csv"):
        claim(os.path.isfile(os.path.join(tour, f)), "step 3-5 wrote " + f)
    # Step 3: -D camera.fov_deg=35 fills more of the frame with the cube than the scene's 57°.
    wide, narrow = object_fraction(os.path.join(tour, "cube.png")), object_fraction(os.path.join(tour, "zoom.png"))
    claim(narrow > 1.5 * wide, "zoom.png (fov 35°): the cube fills more of it than of cube.png (57°): %.3f vs %.3f" %
          (narrow, wide))
    # Step 4: blue from the side, red from behind, black background, not dim.
    for name, want_blue in (("side.png", True), ("back.png", False)):
        px, _ = pixels(os.path.join(tour, name))
        rgb = px[..., :3]
        lit = rgb.max(axis=2) > 0.1
        linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)  # the sRGB curve undone
        r, b = linear[lit][:, 0].mean(), linear[lit][:, 2].mean()
        corner = max(rgb[:8, :8].max(), rgb[-8:, :8].max(), rgb[:8, -8:].max(), rgb[-8:, -8:].max())
        claim((b / r > 1.3) if want_blue else (b / r < 0.85),
              "%s looks %s: blue/red of the lit pixels' mean linear sRGB %.2f" %
              (name, "blue" if want_blue else "red", b / r))
        claim(corner < 0.03, "%s: background black (corners at most %.3f)" % (name, corner))
        claim(lit.mean() > 0.1 and np.percentile(rgb.max(axis=2), 99) > 0.4,
              "%s not flat or dim: %.0f %% of pixels lit, 99th percentile %.2f" %
              (name, 100 * lit.mean(), np.percentile(rgb.max(axis=2), 99)))
    # p3.png is tagged as Display P3: an ICC profile, not side.png's sRGB one (relight.md).
    profiles = {}
    for name in ("side.png", "p3.png"):
        _, spec = pixels(os.path.join(tour, name))
        icc = spec.getattribute("ICCProfile")
        profiles[name] = bytes(bytearray(icc)) if icc is not None else b""
    claim(len(profiles["p3.png"]) > 128 and profiles["p3.png"][36:40] == b"acsp" and
          profiles["p3.png"] != profiles["side.png"] and len(profiles["side.png"]) > 128,
          "p3.png carries an ICC profile (%d bytes) that is not side.png's sRGB one" % len(profiles["p3.png"]))
    with open(os.path.join(tour, "mixed.jpg"), "rb") as f:
        claim(f.read(3) == b"\xff\xd8\xff", "mixed.jpg is a JPEG")
    _, spec = pixels(os.path.join(tour, "side.exr"))
    claim(list(spec.channelnames) == ["R", "G", "B"] and spec.format == oiio.FLOAT,
          "side.exr is float R, G, B (linear sRGB): %s" % list(spec.channelnames))
    # Step 5: the metamer matches under D65 and differs under F11; the hiding light hides it.
    text = "\n".join(block(out, n) for n in range(1, 10) if os.path.exists(os.path.join(out, "block-%d.txt" % n)))
    # Step 2: inspect shows the histogram and the voxels each material's range takes.
    claim(re.search(r"histogram +4 bins over \[100, 255\]", text) is not None and
          re.search(r"rayleigh +\[50, 150\] \(normalised [^)]*\): [0-9 ]+ voxels", text) is not None and
          "no material:" in text, "prizma-render inspect lists the histogram and the voxels of rayleigh and sphere")
    rows = de00_rows(text.split("hiding light")[0])
    claim(rows.get("match D65", 99) < 0.5 and rows.get("split F11", 0) > 5,
          "the metamer: dE00 %.2f under D65, %.2f under F11" % (rows.get("match D65", -1), rows.get("split F11", -1)))
    rows = de00_rows(text.split("hiding light")[1] if "hiding light" in text else "")
    claim(rows.get("designed", 99) < 0.5, "the hiding light: dE00 %.2f" % rows.get("designed", -1))


def metamerism(run, out):
    texts = [block(out, n) for n in range(1, 10) if os.path.exists(os.path.join(out, "block-%d.txt" % n))]
    text = "\n".join(texts)
    parts = re.split(r"(?m)^(?=metamer of |revealing light|hiding light)", text)
    metamer = [p for p in parts if p.startswith("metamer of")]
    reveal = [p for p in parts if p.startswith("revealing light")]
    hide = [p for p in parts if p.startswith("hiding light")]
    claim(len(metamer) == 1 and len(reveal) == 2 and len(hide) == 1,
          "one metamer, two revealing lights, one hiding light designed (%d, %d, %d)" %
          (len(metamer), len(reveal), len(hide)))
    if metamer:
        rows = de00_rows(metamer[0])
        claim(rows.get("match D65", 99) < 0.5, "metamer: dE00 under the match light D65 %.3f" % rows.get("match D65", -1))
        claim(rows.get("split F11", 0) > 5, "metamer: dE00 under the split light F11 %.2f" % rows.get("split F11", -1))
    # The lights of the first block are designed for the pair just made: cc:4 and its metamer, which
    # match under D65 (the standard list's D65 row) — a light for another pair would show a difference.
    for p in reveal[:1] + hide:
        rows = de00_rows(p)
        claim(rows.get("D65", 99) < 0.5, "the light is designed for the metamer pair (dE00 %.3f under D65)" %
              rows.get("D65", -1))
    for p in reveal:
        rows = de00_rows(p)
        d, ref = rows.get("designed", 0), rows.get("reference D65", 99)
        claim(d > ref + 5 and d > 10, "revealing light: dE00 %.2f, under the reference D65 %.2f" % (d, ref))
    for p in hide:
        rows = de00_rows(p)
        d, ref = rows.get("designed", 99), rows.get("reference A", 0)
        claim(d < 0.5 and ref > d, "hiding light: dE00 %.3f, under the reference A %.2f" % (d, ref))


def relight(run, out):
    for f in ("cs.exr", "relight_cs_side.png", "relight_cs_back.png", "relight_cs_mixed.png", "cc.exr", "relight_d65.png",
              "relight_a.png", "relight_a_adapt.png", "relight_f11.png", "relight_rim.png", "relight_narrow.png", "a.png",
              "cc_coef.exr", "cc_compact.exr", "relight_compact.png"):
        claim(os.path.isfile(os.path.join(run, f)), "the examples wrote " + f)
    # The interactive session's numbers, as the page prints them (the chart is synthetic: exact).
    text = "\n".join(block(out, n) for n in range(1, 10) if os.path.exists(os.path.join(out, "block-%d.txt" % n)))
    # (to the 6th decimal ± 2: the page's numbers are of an earlier build, float sums may differ in the last digit)
    for key, want in (("XYZ", [0.953604, 0.869455, 0.306993]), ("dE2000", [14.516177])):
        m = re.search(r"^  %s ((?:[-0-9.]+ ?)+)$" % key, text, re.M)
        got = [float(v) for v in m.group(1).split()] if m else []
        claim(len(got) == len(want) and all(abs(g - w) <= 2e-6 for g, w in zip(got, want)),
              "the session prints %s %s (the page: %s)" % (key, got, want))
    m = re.search(r"^key: k = (\d+) of 32 bins", text, re.M)
    claim(m is not None and m.group(1) == "14", "compress keeps k = 14 of 32 bins for the key light (got %s)" %
          (m.group(1) if m else "no line"))


def main():
    page, run, out = sys.argv[1:4]
    {"user-guide": user_guide, "metamerism": metamerism, "relight": relight}[page](run, out)
    if len(sys.argv) > 4:
        results = colour_claims.Results()
        docs_dir = os.path.dirname(os.path.abspath(sys.argv[4]))
        n = colour_claims.check_claims(sys.argv[4], docs_dir, run, results)
        failures.extend(results.failures)
        print("%d colour claims checked" % n)
    if failures:
        print("%d claim(s) of %s.md do not hold" % (len(failures), page))
        sys.exit(1)
    print("every checked claim of %s.md holds" % page)


if __name__ == "__main__":
    main()
