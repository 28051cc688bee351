"""Bispectral (fluorescence) files written by another tool: the Python module writes a re-radiation
matrix per light (prizma.write), prizma-relight reads the file, and its relit XYZ equals the value
computed here in numpy from the CIE 1931 table: per light, XYZ = Σ_bins W·T + C·(M·ē), W the
relighter's weights (∫_bin E·cmf, white-normalised), C[c][out] = ∫_out cmf_c, ē the light's bin
averages with the same normalisation (docs/fluorescence.md, "Relighting")."""
import os

import numpy as np
import pytest

import prizma
from conftest import run_tool

EDGES = np.linspace(400.0, 700.0, 7)  # 6 bins of 50 nm
N = len(EDGES) - 1
H, W = 3, 4
# Lights constant inside each bin (box spectra on the bin edges): their bin averages are exact.
LIGHTS = {"uv": "box:400:450", "lamp": "box:450:650*0.5"}


def cmf_bin_integrals():
    """C[c][i] = ∫_{bin i} cmf_c dλ, exact for the 1 nm piecewise-linear table (edges on whole nm)."""
    table = np.loadtxt(os.path.join(prizma.data_dir(), "spectra", "cie1931_xyz2deg_1nm.csv"), delimiter=",",
                       skiprows=1)
    c = np.zeros((3, N))
    for i in range(N):
        rows = table[(table[:, 0] >= EDGES[i]) & (table[:, 0] <= EDGES[i + 1])]
        for k in range(3):
            c[k, i] = np.trapz(rows[:, k + 1], rows[:, 0])
    return c


def box_bin_averages(spec):
    """Bin averages of "box:lo:hi[*s]" (1 inside, 0 outside), before normalisation, and the scale."""
    body, _, scale = spec.partition("*")
    lo, hi = (float(v) for v in body.split(":")[1:])
    mids = 0.5 * (EDGES[:-1] + EDGES[1:])
    return ((mids > lo) & (mids < hi)).astype(float), float(scale or 1.0)


def expected_xyz(image, cmf):
    total = np.zeros((H, W, 3))
    for name, spec in LIGHTS.items():
        e, scale = box_bin_averages(spec)
        # Relative to white: the light scaled so a perfect white (T = 1) has Y = 1, then its factor.
        e = scale * e / (cmf[1] @ e)
        t = image.lights[name].astype(np.float64)
        m = image.reradiation_matrix(name).astype(np.float64)  # [y, x, out, in]
        radiance = t * e + np.einsum("yxoi,i->yxo", m, e)
        total += np.einsum("co,yxo->yxc", cmf, radiance)
    return total


def make_image():
    rng = np.random.default_rng(5)
    lights = {name: rng.uniform(0.0, 0.5, (H, W, N)).astype(np.float32) for name in LIGHTS}
    matrices = {}
    for name in LIGHTS:
        m = np.zeros((H, W, N, N), dtype=np.float32)
        # A dye absorbing in bins 0–1 (400–500 nm) and emitting in bins 3–5 (550–700 nm).
        for i in (0, 1):
            for o in (3, 4, 5):
                m[:, :, o, i] = rng.uniform(0.0, 0.2, (H, W))
        matrices[name] = m
    return prizma.Image(lights, EDGES, attributes={"samples": 1}, reradiation=matrices)


def test_matrices_become_the_layouts_pairs(tmp_path):
    image = make_image()
    assert image.reradiation_pairs.tolist() == [[0, 3], [0, 4], [0, 5], [1, 3], [1, 4], [1, 5]]
    path = tmp_path / "bi.exr"
    prizma.write(path, image)
    back = prizma.read(path)
    assert back.reradiation_pairs.tolist() == image.reradiation_pairs.tolist()
    for name in LIGHTS:
        np.testing.assert_array_equal(back.reradiation[name], image.reradiation[name])
        np.testing.assert_array_equal(back.reradiation_matrix(name), image.reradiation_matrix(name))
    # The channels are the layout's: T.<in>nm.<out>nm per light layer, excitation first.
    import OpenImageIO as oiio
    import re
    found = set()
    for n in oiio.ImageInput.open(str(path)).spec().channelnames:
        m = re.match(r"^(?:(\w+)\.)?T\.([0-9,]+)nm\.([0-9,]+)nm$", n)
        if m:
            found.add((m.group(1), float(m.group(2).replace(",", ".")), float(m.group(3).replace(",", "."))))
    assert ("uv", 425.0, 575.0) in found and ("lamp", 475.0, 675.0) in found
    assert (None, 425.0, 575.0) in found  # the top-level sum for readers of the published layout
    # Per light the 6 pairs held; at the top level every pair with λin < λout of the 6 bins (15), as
    # the JCGT reference reader needs them (0 where no light holds one).
    assert len([f for f in found if f[0] is not None]) == 2 * 6
    assert len([f for f in found if f[0] is None]) == 6 * 5 // 2
    assert all(i < o for layer, i, o in found if layer is None)


def test_prizma_relight_reads_a_python_written_bispectral_file(tmp_path):
    image = make_image()
    path = tmp_path / "bi.exr"
    prizma.write(path, image)
    out = tmp_path / "relit.exr"
    run_tool("relight", path, *sum((["--light", f"{n}={s}"] for n, s in LIGHTS.items()), []), "-o", out)
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(str(out))
    names = list(buf.spec().channelnames)
    got = np.asarray(buf.get_pixels(oiio.FLOAT)).reshape(H, W, -1)[:, :, [names.index(c) for c in "RGB"]]  # X, Y, Z
    want = expected_xyz(image, cmf_bin_integrals())
    np.testing.assert_allclose(got, want, rtol=2e-5, atol=1e-7)
    # The bispectral part matters: without it the values differ by far more than the tolerance.
    plain = prizma.Image(image.lights, EDGES, attributes={"samples": 1})
    diagonal_only = expected_xyz(plain, cmf_bin_integrals())
    assert np.abs(got - diagonal_only).max() > 1e-2
    # The module's own relight agrees with the tool.
    xyz = prizma.relight(prizma.read(path), LIGHTS, display=None)
    np.testing.assert_allclose(xyz, got, rtol=1e-5, atol=1e-7)


def test_reradiation_matrices_are_checked():
    image = make_image()
    bad = {name: image.reradiation_matrix(name) for name in LIGHTS}
    bad["uv"][0, 0, 2, 2] = 1.0
    with pytest.raises(prizma.InputError, match="diagonal"):
        prizma.Image(image.lights, EDGES, reradiation=bad)
    with pytest.raises(prizma.InputError, match="shape"):
        prizma.Image(image.lights, EDGES, reradiation={"uv": np.zeros((H, W, N, N - 1))})


def test_a_light_without_its_terms_is_refused(tmp_path):
    image = make_image()
    del image.reradiation["lamp"]
    with pytest.raises(prizma.InputError, match=r'reradiation\["lamp"\]'):
        prizma.write(tmp_path / "x.exr", image)
    assert not (tmp_path / "x.exr").exists()


def test_prizma_relight_reads_a_hand_written_reference_layout_file(tmp_path):
    """A file written through OpenEXR channels only (OpenImageIO, no prizma: attributes), after the
    rules of docs/spectral-exr.md: T.<λ>nm per bin, T.<in>nm.<out>nm for the re-radiation."""
    import OpenImageIO as oiio
    centres = [425, 475, 525, 575, 625, 675]
    pairs = [(0, 3), (1, 4)]
    names = ["T.%dnm" % c for c in centres] + ["T.%dnm.%dnm" % (centres[i], centres[o]) for i, o in pairs]
    rng = np.random.default_rng(9)
    pixels = rng.uniform(0.05, 0.4, (H, W, len(names))).astype(np.float32)
    path = tmp_path / "hand.exr"
    spec = oiio.ImageSpec(W, H, len(names), oiio.FLOAT)
    spec.channelnames = tuple(names)
    spec.attribute("spectralLayoutVersion", "1.0")
    spec.attribute("compression", "zip")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    back = prizma.read(path)
    np.testing.assert_allclose(back.bin_edges_nm, EDGES)  # centres 50 nm apart: the edges between them
    assert back.reradiation_pairs.tolist() == [list(p) for p in pairs]
    (light,) = back.lights
    relit = tmp_path / "hand_relit.exr"
    run_tool("relight", path, "--light", f"{light}=box:400:500", "-o", relit)
    buf = oiio.ImageBuf(str(relit))
    ch = list(buf.spec().channelnames)
    got = np.asarray(buf.get_pixels(oiio.FLOAT)).reshape(H, W, -1)[:, :, [ch.index(c) for c in "RGB"]]  # X, Y, Z
    cmf = cmf_bin_integrals()
    e = np.array([1.0, 1.0, 0, 0, 0, 0])
    e = e / (cmf[1] @ e)
    radiance = pixels[:, :, :6].astype(np.float64) * e
    for k, (i, o) in enumerate(pairs):
        radiance[:, :, o] += pixels[:, :, 6 + k] * e[i]
    np.testing.assert_allclose(got, np.einsum("co,yxo->yxc", cmf, radiance), rtol=2e-5, atol=1e-7)
