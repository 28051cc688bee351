#!/usr/bin/env python3
"""What the docs and the demo say an image looks like, measured (issue 25 item 6).

A colour claim in a docs page is an HTML comment beside the sentence it checks:

    <!-- colour: FILE REGION: WORDS -->

FILE is an image the page's blocks write (found in the folder they ran in) or one of docs/images/;
REGION one of REGIONS below; WORDS the colour the sentence gives, in the vocabulary of describe():
words separated by blanks must all hold ("olive grey"), alternatives are joined by "|" or "-"
("red-orange": red or orange, the sentence names a hue between them).

The colour is measured, never guessed: the region's mean display value is decoded to linear light
with the display the file records (prizma:display, else sRGB), converted to XYZ and to CIELAB (D65
white, the display's own white), and named by its lightness, chroma and hue angle (describe()).

    colour_claims.py lint FILE.md…          every sentence about a colour carries its claim
    colour_claims.py check DOCS_DIR         every claim against the image the page shows (docs/images)
    colour_claims.py demo STDOUT OUT_DIR    scripts/demo's closing list against its images

check_docs.py checks the claims of a page against what its blocks wrote (check_claims with RUN).

Exit 1 with one line per claim that does not hold.
"""
import json
import math
import os
import re
import sys

import numpy as np

HUE_WORDS = ("red", "orange", "yellow", "green", "cyan", "blue", "purple", "pink")
SYNONYMS = {"gray": "grey", "violet": "purple", "magenta": "pink", "reddish": "red", "bluish": "blue",
            "greenish": "green", "yellowish": "yellow", "neutral": "grey"}
# The HSV hue angle (degrees, of the sRGB encoding) where each hue name starts, going round from red
# at 0°: orange 30°, yellow 60°, green 120°, cyan 180°, blue 240°, violet 270°, magenta 300°.
HUE_STARTS = ((0, "red"), (15, "orange"), (45, "yellow"), (70, "green"), (160, "cyan"), (200, "blue"),
              (255, "purple"), (290, "pink"), (345, "red"))
COLOUR_WORDS = set(HUE_WORDS) | set(SYNONYMS) | {"grey", "white", "black", "olive"}

# xy of red, green, blue, white and the curve (encoded → linear) of the displays Prizma encodes for.
DISPLAYS = {
    "sRGB": ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06), (0.3127, 0.3290), "srgb"),
    "Display P3": ((0.680, 0.320), (0.265, 0.690), (0.150, 0.060), (0.3127, 0.3290), "srgb"),
    "Rec.2020": ((0.708, 0.292), (0.170, 0.797), (0.131, 0.046), (0.3127, 0.3290), "2.4"),
}


def rgb_to_xyz_matrix(display):
    r, g, b, w, _ = DISPLAYS[display]
    xyz = lambda xy: np.array([xy[0] / xy[1], 1.0, (1 - xy[0] - xy[1]) / xy[1]])
    prim = np.stack([xyz(r), xyz(g), xyz(b)], axis=1)
    return prim * np.linalg.solve(prim, xyz(w))


def decode(values, curve):
    v = np.clip(values, 0.0, 1.0)
    if curve == "srgb":
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    return v ** 2.4


def encode_srgb(linear):
    v = np.clip(linear, 0.0, None)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def lab(xyz, white):
    def f(t):
        return np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    fx, fy, fz = (f(xyz[i] / white[i]) for i in range(3))
    return np.array([116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)])


def describe(lab_value, srgb_encoded):
    """The words that truthfully name a colour: when its CIELAB chroma is low, white, grey or black
    by its lightness; its hue by the HSV hue angle of its sRGB encoding (how an RGB triple is named:
    CIELAB's hue angle crowds sRGB's blue and violet together at 300°), and the neighbouring hue within
    6° of a boundary; olive for a dark, weak yellow-green. Returns (set of words, a short text)."""
    L, a, b = (float(x) for x in lab_value)
    C = math.hypot(a, b)
    r, g, bl = (float(x) for x in np.clip(srgb_encoded, 0.0, 1.0))
    hi, lo = max(r, g, bl), min(r, g, bl)
    h = 0.0
    if hi > lo:
        if hi == r:
            h = (60.0 * (g - bl) / (hi - lo)) % 360
        elif hi == g:
            h = 60.0 * (bl - r) / (hi - lo) + 120
        else:
            h = 60.0 * (r - g) / (hi - lo) + 240
    words = set()
    if L < 12:
        words |= {"black"}
    if C < 25:  # a neutral: white above L* 88, black below 20, grey between (overlapping at the ends)
        if L > 88:
            words |= {"white"}
        if L < 20:
            words |= {"black"}
        if 12 <= L <= 90:
            words |= {"grey"}
    if C >= 8:
        for angle in (h, h - 6, h + 6):
            angle %= 360
            name = HUE_STARTS[-1][1]
            for start, hue in HUE_STARTS:
                if angle >= start:
                    name = hue
            words.add(name)
        if 45 <= h < 100 and L < 70 and C < 45:
            words.add("olive")
    text = "L* %.0f, C* %.0f, hue %.0f°" % (L, C, h)
    return words, text


def holds(claim_words, measured):
    """claim_words: "olive grey", "red|orange", "red-orange"; every blank-separated part must hold,
    a part holds when one of its |- alternatives is among the measured words."""
    for part in claim_words.split():
        alternatives = [SYNONYMS.get(w, w) for w in re.split(r"[|-]", part.lower()) if w]
        if not any(w in measured for w in alternatives):
            return False
    return True


def read_display_image(path):
    """(pixels H×W×3 in [0, 1] as stored, the display the file was encoded for)."""
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise SystemExit("%s: %s" % (path, buf.geterror()))
    spec = buf.spec()
    px = np.asarray(buf.get_pixels(oiio.FLOAT), dtype=np.float64).reshape(spec.height, spec.width, spec.nchannels)
    display = spec.get_string_attribute("prizma:display", "")
    if not display:
        try:
            display = json.loads(spec.get_string_attribute("ImageDescription", "{}")).get("prizma:display", "")
        except ValueError:
            display = ""
    return px[..., :3], display if display in DISPLAYS else "sRGB"


def region_mask(name, h, w, px):
    """Named regions, in image fractions: those of the cube_sphere scene's default camera (fov 57.3°
    at distance 2: the sphere, radius 0.25, is a disc of radius 0.23 of the half-height; the cube's
    front face spans 0.46 of it), the ColorChecker chart's patches, halves, boxes, lit pixels."""
    y, x = np.mgrid[0:h, 0:w]
    u, v = (x + 0.5) / w * 2 - 1, (y + 0.5) / h * 2 - 1  # −1 … 1, +v downward
    r, box = np.hypot(u, v), np.maximum(np.abs(u), np.abs(v))
    lit = px.max(axis=2) > 0.1
    if name == "sphere":
        return r < 0.19
    if name == "cube":
        return (box < 0.42) & (r > 0.29)
    if name == "background":
        return box > 0.62
    if name == "lit":
        return lit
    if name == "all":
        return np.ones((h, w), dtype=bool)
    if name in ("left", "right"):
        return (u < 0) if name == "left" else (u >= 0)
    m = re.fullmatch(r"patch:(\d+)", name)
    if m:  # relight/examples/colorchecker_chart.cpp: 6 × 4 patches of 24 px, 4 px apart, 172 × 116
        p = int(m.group(1)) - 1
        x0, y0 = 4 + 28 * (p % 6) + 4, 4 + 28 * (p // 6) + 4
        scale_x, scale_y = w / 172.0, h / 116.0
        return (x >= x0 * scale_x) & (x < (x0 + 16) * scale_x) & (y >= y0 * scale_y) & (y < (y0 + 16) * scale_y)
    m = re.fullmatch(r"box:([0-9.]+):([0-9.]+):([0-9.]+):([0-9.]+)", name)
    if m:
        x0, y0, x1, y1 = (float(g) for g in m.groups())
        return (x >= x0 * w) & (x < x1 * w) & (y >= y0 * h) & (y < y1 * h)
    raise SystemExit("unknown region %r (known: sphere, cube, background, lit, all, left, right, patch:N, "
                     "box:x0:y0:x1:y1)" % name)


def measure(path, region):
    """(words, text) of the mean colour of `region` in the image at `path`. A region written
    "pixels@REGION" is measured pixel by pixel instead: its words are those naming at least 10 % of
    its chromatic pixels (CIELAB chroma ≥ CHROMATIC), for images whose colours interleave at pixel scale (a
    mean of purple and green patches is grey)."""
    px, display = read_display_image(path)
    h, w = px.shape[:2]
    per_pixel = region.startswith("pixels@")
    mask = region_mask(region[len("pixels@"):] if per_pixel else region, h, w, px)
    if not mask.any():
        return set(), "no pixels in region %s" % region
    _, _, _, _, curve = DISPLAYS[display]
    m = rgb_to_xyz_matrix(display)
    to_srgb = np.linalg.inv(rgb_to_xyz_matrix("sRGB"))
    white = m @ np.ones(3)
    if not per_pixel:
        xyz = m @ decode(px[mask], curve).mean(axis=0)
        words, text = describe(lab(xyz, white), encode_srgb(to_srgb @ xyz))
        return words, "%s (%s, %d pixels, %s)" % (text, display, int(mask.sum()), "/".join(sorted(words)) or "-")
    counts, chromatic = {}, 0
    for value in decode(px[mask], curve):
        xyz = m @ value
        L, a, b = lab(xyz, white)
        if math.hypot(a, b) < CHROMATIC:
            continue
        chromatic += 1
        for word in describe((L, a, b), encode_srgb(to_srgb @ xyz))[0]:
            counts[word] = counts.get(word, 0) + 1
    words = {wd for wd, k in counts.items() if chromatic and k >= 0.1 * chromatic}
    shares = ", ".join("%s %.0f%%" % (wd, 100.0 * k / chromatic) for wd, k in sorted(counts.items(), key=lambda t: -t[1])[:5])
    return words, "%d of %d pixels chromatic: %s (%s)" % (chromatic, int(mask.sum()), shares or "-", display)


CHROMATIC = 8  # CIELAB chroma from which a pixel has a hue (describe(): below 8 it is grey only)
CLAIM = re.compile(r"<!--\s*colour:\s*(\S+)\s+(\S+):\s*([^>]*?)\s*-->")


def claims_of(text):
    """[(line number, file, region, words)] of a page's colour claims."""
    out = []
    for n, line in enumerate(text.split("\n"), 1):
        for m in CLAIM.finditer(line):
            out.append((n, m.group(1), m.group(2), m.group(3)))
    return out


class Results:
    def __init__(self):
        self.failures = []

    def claim(self, ok, text):
        print(("ok    " if ok else "FAIL  ") + text)
        if not ok:
            self.failures.append(text)


def check_claims(page, docs_dir, run_dir, results):
    """Checks each claim of `page` against every copy of its image that exists: the one the page's
    blocks wrote (in run_dir, when given) and the one the page shows (docs_dir/FILE or
    docs_dir/images/FILE). Without run_dir a claim about an image only the blocks write is left for
    the run (ctest label docs). Returns how many images were checked."""
    checked = 0
    with open(page, encoding="utf-8") as f:
        text = f.read()
    for n, image, region, words in claims_of(text):
        candidates = ([os.path.join(run_dir, image)] if run_dir else []) + \
            [os.path.join(docs_dir, image), os.path.join(docs_dir, "images", image)]
        found = [p for p in candidates if os.path.isfile(p)]
        if not found:
            if run_dir:
                results.claim(False, "%s:%d: %s: no such image" % (os.path.basename(page), n, image))
            continue
        for path in found:
            measured, desc = measure(path, region)
            results.claim(holds(words, measured), "%s:%d: %s %s looks %s: %s" % (
                os.path.basename(page), n, os.path.relpath(path, run_dir if run_dir and path.startswith(run_dir) else docs_dir),
                region, words, desc))
            checked += 1
    return checked


# A sentence about how something looks: a colour word near a verb of seeing, or beside an image.
VISUAL = re.compile(r"\b(looks?|appears?|turns?|shows?|seen|scatters?|glows?|glow)\b|\.(png|jpg|jpeg)\b|!\[", re.I)
COLOUR_WORD = re.compile(r"\b(%s)\b" % "|".join(sorted(COLOUR_WORDS, key=len, reverse=True)), re.I)
HUE_WORD = re.compile(r"\b(%s)\b" % "|".join(sorted(COLOUR_WORDS - {"grey", "gray", "white", "black", "neutral"},
                                                     key=len, reverse=True)), re.I)
# Colour words that are names, not descriptions of an image: data (cc:orange, "orange sphere" the
# material), light names, white points, observers.
NOT_A_CLAIM = re.compile(r"cc:\S+|orange sphere|grey (cube|medium|cloud|path|time|matter|σ|render)|white (matter|point|balance)|"
                         r"perfect white|a white\b|white under|white has|white \(|white's|whites?\b(?! turn)|black-2|"
                         r"blackbody|royal-blue|blue (lanes|bins|end)|red (ones|lanes|bins|peaks)|red CI|green run|"
                         r"red \(1, 0\)|green \(0, 1\)|blue \(0, 0\)|blue LED|violet (LED|light|bins|in|band)|"
                         r"grey extinction|grey, forward|dark purple|pale yellow|dark grey where|"
                         r"emits red|deep red|into red|reflects only|Soret|\bPpIX\b|(blue|red) (bin|one)s?\b|"
                         r"\(blue\) (bins|lanes)|reddest bin|white patch|neutral \d|thick, blue one", re.I)


def paragraphs(text):
    """(first line number, text) of each paragraph or table row outside code blocks."""
    out, block, start, fenced = [], [], 0, False
    for n, line in enumerate(text.split("\n"), 1):
        if line.strip().startswith("```"):
            fenced = not fenced
            if block:
                out.append((start, "\n".join(block)))
                block = []
            continue
        if fenced:
            continue
        if not line.strip() or line.startswith("|"):
            if block:
                out.append((start, "\n".join(block)))
                block = []
            if line.startswith("|"):
                out.append((n, line))
            continue
        if not block:
            start = n
        block.append(line)
    if block:
        out.append((start, "\n".join(block)))
    return out


def lint(page, results):
    """Every paragraph (or table row) that says how something looks in a colour carries a colour
    claim, or says why it cannot be measured (`<!-- colour: none (why) -->`)."""
    with open(page, encoding="utf-8") as f:
        text = f.read()
    for n, para in paragraphs(text):
        if "<!-- colour:" in para:
            continue
        stripped = NOT_A_CLAIM.sub(" ", re.sub(r"`[^`]*`", " ", re.sub(r"<!--.*?-->", " ", para, flags=re.S)))
        # Per sentence: a hue word, or grey / white / black with a verb of seeing in the same sentence.
        found = None
        for sentence in re.split(r"(?<=[.;:!?])\s+|\|", stripped):
            hue = HUE_WORD.search(sentence)
            neutral = COLOUR_WORD.search(sentence) if VISUAL.search(sentence) else None
            found = found or hue or neutral
        if found:
            word = found.group(0)
            results.claim(False, "%s:%d: a sentence about a colour (\"%s\") with no colour claim: %s" % (
                os.path.basename(page), n, word, " ".join(para.split())[:160]))


# scripts/demo's closing list: "  FILE   what it is: the SUBJECT looks WORDS[, the SUBJECT WORDS]".
DEMO_LINE = re.compile(r"^\s+(\S+\.png)\s+(.*)$")
DEMO_SUBJECT = re.compile(r"\bthe (sphere|cube|background)\b(?: looks)? ((?:[a-z|-]+ ?)+?)(?=,|;|$| \()")


def demo(stdout_path, out_dir, results):
    with open(stdout_path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    checked = 0
    for line in lines:
        m = DEMO_LINE.match(line)
        if not m or not COLOUR_WORD.search(m.group(2)):
            continue
        said = False
        for s in DEMO_SUBJECT.finditer(m.group(2)):
            words = " ".join(w for w in s.group(2).split() if any(part in COLOUR_WORDS for part in re.split(r"[|-]", w)))
            if not words:
                continue
            measured, desc = measure(os.path.join(out_dir, m.group(1)), s.group(1))
            results.claim(holds(words, measured), "demo: %s: the %s looks %s: %s" % (m.group(1), s.group(1), words, desc))
            said = checked = checked + 1
        if not said:
            results.claim(False, "demo: a colour the check cannot read (say 'the sphere|cube|background looks …'): " + line.strip())
    return checked


def main():
    results = Results()
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "lint":
        for page in sys.argv[2:]:
            lint(page, results)
    elif what == "check":
        docs_dir = sys.argv[2]
        pages = [os.path.join(docs_dir, p) for p in sorted(os.listdir(docs_dir)) if p.endswith(".md")]
        n = sum(check_claims(p, docs_dir, None, results) for p in pages)
        results.claim(n > 0, "%d colour claims checked on the images the docs show" % n)
    elif what == "demo":
        results.claim(demo(sys.argv[2], sys.argv[3], results) >= 2, "the demo's colour sentences were read")
    else:
        sys.exit(__doc__)
    if results.failures:
        print("%d colour claim(s) do not hold" % len(results.failures))
        sys.exit(1)


if __name__ == "__main__":
    main()
