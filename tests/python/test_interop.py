"""Files other tools read right: preview R, G, B channels, re-encoded files, chromaticities."""
import shutil
import subprocess

import numpy as np
import pytest

import prizma
from conftest import run_tool

oiio = pytest.importorskip("OpenImageIO")


def channels(path, names):
    inp = oiio.ImageInput.open(str(path))
    assert inp, oiio.geterror()
    try:
        spec = inp.spec()
        index = [spec.channelnames.index(n) for n in names]
        everything = inp.read_image(0, 0, 0, spec.nchannels, "float")
        return everything[:, :, index], spec
    finally:
        inp.close()


def oiiotool(*args):
    exe = shutil.which("oiiotool")
    if not exe:
        pytest.skip("oiiotool not installed (Debian openimageio-tools)")
    subprocess.run([exe, *map(str, args)], check=True, capture_output=True, timeout=60)


def test_preview_channels_are_the_default_relight_in_linear_srgb(tiny_exr):
    rgb, spec = channels(tiny_exr, ["R", "G", "B"])
    assert rgb.max() > 0.01
    ours = prizma.relight(tiny_exr, colour_space="Linear sRGB")  # what prizma-relight makes by default
    np.testing.assert_allclose(rgb, ours, rtol=1e-4, atol=1e-6)
    # Readers of the spectral layout ignore them: the lights and bins are as before.
    image = prizma.read(tiny_exr)
    assert list(image.lights) == ["side", "sky"] and image.bins == 6


def test_written_images_carry_the_preview_too(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    out = tmp_path / "again.exr"
    prizma.write(out, image)
    np.testing.assert_array_equal(channels(out, ["R", "G", "B"])[0], channels(tiny_exr, ["R", "G", "B"])[0])


@pytest.mark.parametrize("how,named,atol", [
    # (an 8×8 render: Prizma writes it uncompressed, docs/spectral-exr.md "Compression")
    (["-d", "half", "--compression", "b44"], "the lossy B44, Prizma writes an image this small uncompressed", None),  # 4×4 blocks, ±25 %
    (["--compression", "pxr24"], "the lossy PXR24, Prizma writes an image this small uncompressed", 0.01),
    (["-d", "half"], "it was written by OpenImageIO", 0.01),
])
def test_reencoded_file_is_named_as_such_and_read_with_no_verify(tiny_exr, tmp_path, how, named, atol):
    copy = tmp_path / "reencoded.exr"
    oiiotool(tiny_exr, *how, "-o", copy)
    proc = run_tool("relight", copy, "-o", tmp_path / "x.png", check=False)
    assert proc.returncode == 2, proc.stderr
    assert "pixel data do not match prizma:checksum: the file was probably re-encoded by another tool" in proc.stderr
    assert named in proc.stderr and "--no-verify" in proc.stderr
    with pytest.raises(prizma.InputError, match=r"probably re-encoded.*prizma\.read\(path, verify=False\) reads it$"):
        prizma.read(copy)
    run_tool("relight", copy, "--no-verify", "-o", tmp_path / "x.png")
    back = prizma.read(copy, verify=False)
    original = prizma.read(tiny_exr)
    np.testing.assert_array_equal(back.bin_edges_nm, original.bin_edges_nm)  # exact edges survive
    for name in original.lights:
        assert np.isfinite(back.lights[name]).all()
        if atol is not None:
            np.testing.assert_allclose(back.lights[name], original.lights[name], rtol=0.05, atol=atol)


@pytest.mark.parametrize("drop,named", [
    # oiiotool --ch splits its list at commas, and the layout's names hold one (T.412,500000nm): by index.
    (lambda n: ".var." in n, "the file lacks the variance channels side.var.T.*, sky.var.T.* (the render wrote them: "
                             "prizma:renderOptions \"variance\": true)"),
    (lambda n: n.startswith("T."), "the file lacks the top-level T channels (T.<λ>nm: the sum of the lights"),
])
def test_channels_another_tool_removed_are_named(tiny_exr, tmp_path, drop, named):
    # Issue 25 item 16: a file whose channels oiiotool --ch removed was refused as "probably re-encoded".
    names = list(oiio.ImageInput.open(str(tiny_exr)).spec().channelnames)
    keep = [str(i) for i, n in enumerate(names) if not drop(n)]
    cut = tmp_path / "cut.exr"
    oiiotool(tiny_exr, "--ch", ",".join(keep), "-o", cut)
    proc = run_tool("relight", cut, "-o", tmp_path / "x.png", check=False)
    assert proc.returncode == 2, proc.stderr
    assert "pixel data do not match prizma:checksum: " + named in proc.stderr, proc.stderr
    assert "another tool left them out (oiiotool --ch, say); --no-verify reads what is there" in proc.stderr
    assert "probably re-encoded" not in proc.stderr
    run_tool("relight", cut, "--no-verify", "-o", tmp_path / "x.png")


def test_tiff_and_jpeg_outputs_carry_the_provenance(tiny_exr, tmp_path):
    # relight.md: every output records how it was made; TIFF and JPEG hold the prizma: keys as one JSON
    # object in their description, and the display they are encoded for in Exif and the ICC profile.
    import json
    for name in ("p3.tif", "p3.jpg"):
        out = tmp_path / name
        run_tool("relight", tiny_exr, "--light", "F11", "--display", "Display P3", "-o", out)
        spec = oiio.ImageInput.open(str(out)).spec()
        provenance = json.loads(spec.get_string_attribute("ImageDescription"))
        assert provenance["prizma:source"] == str(tiny_exr)
        assert provenance["prizma:display"] == "Display P3"
        assert [l["spectrum"] for l in json.loads(provenance["prizma:lights"])] == ["F11", "F11*0.2"]
        assert spec.get_string_attribute("Software").startswith("prizma-relight ")
        if name.endswith(".jpg"):  # uncalibrated: not sRGB, see the profile (OpenImageIO still says sRGB)
            assert spec.get_int_attribute("Exif:ColorSpace") == 0xFFFF
        assert len(spec.getattribute("ICCProfile")) > 128


def test_exr_outputs_carry_chromaticities(tiny_exr, tmp_path):
    xyz_out, srgb_out, aces_out = tmp_path / "xyz.exr", tmp_path / "srgb.exr", tmp_path / "aces.exr"
    run_tool("relight", tiny_exr, "-o", xyz_out)
    run_tool("relight", tiny_exr, "--colour-space", "Linear sRGB", "-o", srgb_out)
    run_tool("relight", tiny_exr, "--colour-space", "ACEScg", "-o", aces_out)
    np.testing.assert_allclose(channels(srgb_out, ["R"])[1].getattribute("chromaticities"),
                               [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290], atol=2e-4)
    # Every tag takes the file's RGB back to the relit XYZ (the standard RGB → XYZ from xy). The XYZ
    # output follows OpenEXR's convention (issue 25 item 12): R, G, B channels holding X, Y, Z with
    # XYZ's chromaticities, so its matrix is the identity and an RGBA reader gets the colours.
    xyz = prizma.relight(tiny_exr, display=None)
    xyz_of = lambda xy: np.array([xy[0], xy[1], 1 - xy[0] - xy[1]])  # up to a scale (XYZ's blue has y = 0)
    for out in (xyz_out, aces_out):
        rgb, spec = channels(out, ["R", "G", "B"])
        assert list(spec.channelnames) == ["R", "G", "B"], spec.channelnames
        c = np.array(spec.getattribute("chromaticities"), dtype=np.float64).reshape(4, 2)
        prim = np.stack([xyz_of(c[k]) for k in range(3)], axis=1)
        white = xyz_of(c[3]) / c[3][1]  # the white at Y = 1
        to_xyz = prim * np.linalg.solve(prim, white)
        if out == xyz_out:
            np.testing.assert_allclose(c.ravel(), [1, 0, 0, 1, 0, 0, 1 / 3, 1 / 3], atol=1e-7)
            np.testing.assert_allclose(to_xyz, np.eye(3), atol=1e-6)
        np.testing.assert_allclose(rgb @ to_xyz.T, xyz, rtol=1e-3, atol=1e-5)
