"""scattering-demo: the seed paper's figure 1 — a scattering cube with a sphere inside, rendered once
with two lights ("side" and "back") and relit with only one of them: lit from the side the medium
looks blue (short wavelengths scatter more), lit from behind it looks red (what passes through lost
its blue). The blue/red ratio of the object's region is measured in linear sRGB from each relit image.
Claim: blue/red > 1 lit from the side, < 1 lit from behind.
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import prizma_demo as pd  # noqa: E402

LIGHT = "D65"


def main():
    args = pd.parse_args("scattering-demo", __doc__.splitlines()[0], 192, 64, 24, 16)
    out = args.out
    tools = pd.Tools()
    scene = pd.ROOT / "data" / "scenes" / "cube_sphere.json"
    names = [l["name"] for l in json.loads(scene.read_text()).get("lights", [])]
    for needed in ("side", "back"):
        if needed not in names:
            raise pd.DemoFailure("%s has no light named %s (lights: %s)" % (scene, needed, ", ".join(names)))
    pd.render(tools, scene, out / "cube_sphere.exr", args.size, args.spp, args.seed, preview=out / "cube_sphere_preview.png")
    t, _ = pd.spectral_layer(out / "cube_sphere.exr", "side")
    # The object's region: where the side-lit transport is above 20 % of its 99th percentile.
    total = t.sum(axis=2)
    mask = total > 0.2 * np.percentile(total, 99)
    if mask.sum() == 0:
        raise pd.DemoFailure("nothing visible under the side light")
    np.save(out / "mask.npy", mask)
    rows, ratio = [], {}
    scene_json = json.loads(scene.read_text())
    for lit in ("side", "back"):
        light_args = pd.relight_args(scene_json, LIGHT, only={lit})
        # Displayed 3 stops brighter (the medium is thin and dark); the ratio is measured in the EXR.
        pd.run([tools.relight, out / "cube_sphere.exr"] + light_args + ["--exposure", "3", "-o", out / ("%s_only.png" % lit)],
               quiet=True)
        pd.run([tools.relight, out / "cube_sphere.exr"] + light_args +
               ["--colour-space", "Linear sRGB", "-o", out / ("%s_only.exr" % lit)], quiet=True)
        rgb_pixels, names_c, _ = pd.read_image(out / ("%s_only.exr" % lit))
        rgb = rgb_pixels[:, :, [names_c.index(c) for c in ("R", "G", "B")]]
        mean = pd.region_mean(rgb, mask)
        if not mean[0] > 0:
            raise pd.DemoFailure("no red light in the region lit from the %s" % lit)
        ratio[lit] = float(mean[2] / mean[0])
        rows.append([lit, "%.4f" % mean[0], "%.4f" % mean[1], "%.4f" % mean[2], "%.2f" % ratio[lit]])
    pd.figure_of_images([(out / "side_only.png", "side light only: B/R = %.2f" % ratio["side"]),
                         (out / "back_only.png", "back light only: B/R = %.2f" % ratio["back"])],
                        out / "scattering_side_by_side.png", title="One render, relit with one light at a time (D65, +3 EV)",
                        crop=pd.bounding_box(mask, 0.1))
    pd.write_table(out / "results.md", ["lit from", "R", "G", "B", "blue/red"], rows)
    (out / "results.json").write_text(json.dumps({"size": args.size, "spp": args.spp, "blue_red": ratio}, indent=2) + "\n")
    if not ratio["side"] > 1.0:
        raise pd.DemoFailure("lit from the side, blue/red = %.3f is not > 1" % ratio["side"])
    if not ratio["back"] < 1.0:
        raise pd.DemoFailure("lit from behind, blue/red = %.3f is not < 1" % ratio["back"])
    print("OK: blue/red %.2f from the side (> 1), %.2f from behind (< 1)." % (ratio["side"], ratio["back"]))


if __name__ == "__main__":
    pd.main_wrapper(main)
