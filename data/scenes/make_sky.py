#!/usr/bin/python3
"""Writes data/scenes/sky.exr, the environment map of sky_haze.json: a 128 × 64 equirectangular
(lat-long) luminance image (docs/scene-format.md, "Environment maps"): a sky brighter toward the
horizon (0.6 at the zenith, 1.0 at the horizon), a dark ground (0.08), and a sun disc of angular
radius 4° and radiance 600 at 25° elevation to the right (+x), a little behind the volume (azimuth
80° from −z toward +x). One channel, float, ZIP-compressed; deterministic.
    make_sky.py [OUTPUT]   (default: sky.exr next to this script)"""
import math
import os
import sys

import numpy as np
import OpenImageIO as oiio

W, H = 128, 64
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "sky.exr")

# Pixel-centre directions in the map's convention: θ from +y, φ = 2π(u − ½) from −z toward +x.
v = (np.arange(H) + 0.5) / H
u = (np.arange(W) + 0.5) / W
theta = math.pi * v[:, None]
phi = 2.0 * math.pi * (u[None, :] - 0.5)
d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta) * np.ones_like(phi), -np.sin(theta) * np.cos(phi)], axis=-1)

elevation = np.pi / 2 - theta
sky = np.where(elevation > 0, 1.0 - 0.4 * np.sin(elevation), 0.08) * np.ones_like(phi)
sun_el, sun_az = math.radians(25.0), math.radians(80.0)
sun = np.array([math.cos(sun_el) * math.sin(sun_az), math.sin(sun_el), -math.cos(sun_el) * math.cos(sun_az)])
sky = np.where(d @ sun > math.cos(math.radians(4.0)), 600.0, sky).astype(np.float32)

spec = oiio.ImageSpec(W, H, 1, oiio.FLOAT)
spec.channelnames = ("Y",)
spec.attribute("compression", "zip")
spec.attribute("Software", "prizma data/scenes/make_sky.py")
o = oiio.ImageOutput.create(out)
if o is None or not o.open(out, spec):
    raise SystemExit("make_sky.py: cannot write " + out + ": " + oiio.geterror())
o.write_image(sky[:, :, None])
o.close()
