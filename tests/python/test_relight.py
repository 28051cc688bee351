"""prizma.relight gives exactly the pixels prizma-relight writes."""
import numpy as np
import pytest

import prizma
from conftest import cli_error, run_tool

oiio = pytest.importorskip("OpenImageIO")


def read_pixels(path, dtype):
    inp = oiio.ImageInput.open(str(path))
    assert inp, oiio.geterror()
    try:
        return inp.read_image(0, 0, 0, 3, dtype)
    finally:
        inp.close()


def quantise8(rgb):
    """OpenImageIO's float → uint8 conversion (x·255 + 0.5, truncated) of values already in [0, 1]."""
    return np.floor(rgb.astype(np.float32) * np.float32(255) + np.float32(0.5)).astype(np.uint8)


def test_png_equals_the_tool(tiny_exr, tmp_path):
    png = tmp_path / "cli.png"
    run_tool("relight", tiny_exr, "--light", "side=A", "--light", "sky=off", "--exposure", "1", "-o", png)
    ours = prizma.relight(tiny_exr, {"side": "A", "sky": None}, exposure=1)
    assert ours.shape == (8, 8, 3) and ours.dtype == np.float32
    assert ours.min() >= 0 and ours.max() <= 1 and ours.max() > 0.05
    np.testing.assert_array_equal(quantise8(ours), read_pixels(png, "uint8"))


def test_xyz_exr_equals_the_tool(tiny_exr, tmp_path):
    exr = tmp_path / "cli.exr"
    run_tool("relight", tiny_exr, "--light", "sky=blackbody:3200K*2", "--cmf", "1964", "-o", exr)
    image = prizma.read(tiny_exr)  # an Image in memory works as well as a path
    ours = prizma.relight(image, {"sky": "blackbody:3200K*2"}, cmf="1964", display=None)
    np.testing.assert_array_equal(ours, read_pixels(exr, "float"))


def test_colour_space_exr_equals_the_tool(tiny_exr, tmp_path):
    exr = tmp_path / "acescg.exr"
    run_tool("relight", tiny_exr, "--light", "F11", "--adapt", "--colour-space", "ACEScg", "-o", exr)
    ours = prizma.relight(tiny_exr, "F11", adapt=True, colour_space="ACEScg")
    np.testing.assert_array_equal(ours, read_pixels(exr, "float"))


def test_default_lights_are_the_files(tiny_exr, tmp_path):
    png = tmp_path / "default.png"
    run_tool("relight", tiny_exr, "-o", png, "--display", "Display P3")
    ours = prizma.relight(tiny_exr, display="Display P3")
    np.testing.assert_array_equal(quantise8(ours), read_pixels(png, "uint8"))


def test_relight_is_linear_in_the_lights(tiny_exr):
    both = prizma.relight(tiny_exr, {"side": "D65", "sky": "D65"}, display=None)
    side = prizma.relight(tiny_exr, {"side": "D65", "sky": None}, display=None)
    sky = prizma.relight(tiny_exr, {"side": None, "sky": "D65"}, display=None)
    np.testing.assert_allclose(both, side + sky, rtol=1e-5, atol=1e-7)


def test_bad_light_spec_has_the_tools_reason(tiny_exr, tmp_path):
    message, status = cli_error("relight", tiny_exr, "--light", "side=blackbody:-5K", "-o", tmp_path / "x.png")
    assert status == 2
    with pytest.raises(prizma.InputError) as e:
        prizma.relight(tiny_exr, {"side": "blackbody:-5K"})
    assert e.value.input == 'lights["side"]'
    assert message.endswith(": " + e.value.reason), (message, e.value.reason)


def test_unknown_light_and_bad_options(tiny_exr):
    with pytest.raises(prizma.InputError, match=r'^lights: no light "key" in .*tiny\.exr \(its lights: side, sky\)$'):
        prizma.relight(tiny_exr, {"key": "D65"})
    with pytest.raises(prizma.InputError, match=r"^exposure: must be a finite number of stops within ±64$"):
        prizma.relight(tiny_exr, exposure=100)
    with pytest.raises(prizma.InputError, match=r"^cmf: "):
        prizma.relight(tiny_exr, cmf="1492")
    with pytest.raises(prizma.InputError, match="Cinema"):
        prizma.relight(tiny_exr, display="Cinema")
