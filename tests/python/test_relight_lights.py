"""How a light is given (issue 25 items 5 and 7): one spectrum for every light keeps each light's
scale in every front end alike (prizma-relight --light, a batch file, the shell, prizma.relight), and
prizma.relight takes measured spectra as (wavelengths_nm, values) arrays wherever a spectrum goes."""
import json
import subprocess

import numpy as np
import pytest

import prizma
from conftest import run_tool, tool

oiio = pytest.importorskip("OpenImageIO")


def xyz_of(path):
    inp = oiio.ImageInput.open(str(path))
    assert inp, oiio.geterror()
    try:
        return inp.read_image(0, 0, 0, 3, "float")
    finally:
        inp.close()


def test_one_spectrum_for_every_light_keeps_each_lights_recorded_scale(tiny_exr, tmp_path):
    # tiny.json records side "D65" and sky "D65*0.2": "F11" for every light is side F11, sky F11*0.2.
    run_tool("relight", tiny_exr, "--light", "side=F11", "--light", "sky=F11*0.2", "-o", tmp_path / "named.exr")
    want = xyz_of(tmp_path / "named.exr")
    run_tool("relight", tiny_exr, "--light", "F11", "-o", tmp_path / "cli.exr")
    np.testing.assert_array_equal(xyz_of(tmp_path / "cli.exr"), want)
    # A batch file's "lights": "F11", the shell's `light F11`, and Python: the same pixels.
    (tmp_path / "batch.json").write_text(json.dumps({"outputs": [{"file": "batch.exr", "lights": "F11"}]}))
    run_tool("relight", tiny_exr, "--batch", tmp_path / "batch.json")
    np.testing.assert_array_equal(xyz_of(tmp_path / "batch.exr"), want)
    shell = subprocess.run([tool("relight"), str(tiny_exr), "-i"], input="light F11\nstatus\nsave %s\n" % (tmp_path / "shell.exr"),
                           capture_output=True, text=True, timeout=120)
    assert shell.returncode == 0, shell.stderr
    assert "sky = F11*0.2 (default D65*0.2)" in shell.stdout, shell.stdout
    np.testing.assert_array_equal(xyz_of(tmp_path / "shell.exr"), want)
    np.testing.assert_array_equal(prizma.relight(tiny_exr, "F11", display=None), want)
    # The output records the scale used.
    spec = oiio.ImageInput.open(str(tmp_path / "cli.exr")).spec()
    assert [l["spectrum"] for l in json.loads(spec.get_string_attribute("prizma:lights"))] == ["F11", "F11*0.2"]


def test_a_scale_given_for_every_light_is_used_as_it_is(tiny_exr, tmp_path):
    run_tool("relight", tiny_exr, "--light", "F11*1", "-o", tmp_path / "all1.exr")
    run_tool("relight", tiny_exr, "--light", "side=F11", "--light", "sky=F11", "-o", tmp_path / "both.exr")
    np.testing.assert_array_equal(xyz_of(tmp_path / "all1.exr"), xyz_of(tmp_path / "both.exr"))
    # Named lights win over the every-light spectrum wherever they stand on the command line.
    run_tool("relight", tiny_exr, "--light", "sky=off", "--light", "A", "-o", tmp_path / "order.exr")
    np.testing.assert_array_equal(xyz_of(tmp_path / "order.exr"),
                                  prizma.relight(tiny_exr, {"side": "A", "sky": None}, display=None))
    # A light that is off stays off under a bare spectrum for every light (the shell, after `light sky off`).
    shell = subprocess.run([tool("relight"), str(tiny_exr), "-i"], input="light sky off\nlight A\nstatus\n",
                           capture_output=True, text=True, timeout=120)
    assert "sky = off (default D65*0.2)" in shell.stdout, shell.stdout


def test_lights_take_measured_spectra_as_arrays(tiny_exr, tmp_path):
    wl = np.array([380.0, 450.0, 520.0, 600.0, 700.0, 780.0])
    values = np.array([0.1, 0.7, 1.0, 0.8, 0.5, 0.3])
    csv = tmp_path / "lamp.csv"
    csv.write_text("wavelength_nm,value\n" + "".join("%r,%r\n" % (float(a), float(b)) for a, b in zip(wl, values)))
    # A pair is the csv: spectrum of the same table, for every light (keeping the sky's 0.2) or one.
    np.testing.assert_array_equal(prizma.relight(tiny_exr, (wl, values), display=None),
                                  prizma.relight(tiny_exr, {"side": f"csv:{csv}", "sky": f"csv:{csv}*0.2"}, display=None))
    np.testing.assert_array_equal(prizma.relight(tiny_exr, {"side": [list(wl), list(values)]}),
                                  prizma.relight(tiny_exr, {"side": f"csv:{csv}"}))
    np.testing.assert_array_equal(prizma.relight(tiny_exr, {"sky": {"spectrum": (wl, values), "scale": 0.5}}),
                                  prizma.relight(tiny_exr, {"sky": f"csv:{csv}*0.5"}))
    np.testing.assert_array_equal(prizma.relight(tiny_exr, {"sky": {"spectrum": "A", "scale": 2}}),
                                  prizma.relight(tiny_exr, {"sky": "A*2"}))
    # Like the other functions that take spectra.
    np.testing.assert_allclose(prizma.xyz((wl, values)), prizma.xyz(f"csv:{csv}"))
    with pytest.raises(prizma.InputError, match=r'^lights\["side"\]: must be a spectrum spec string or a pair'):
        prizma.relight(tiny_exr, {"side": (wl, values[:3])})
    with pytest.raises(prizma.InputError, match=r'^lights\["sky"\]\["scale"\]: light scale must be finite and non-negative'):
        prizma.relight(tiny_exr, {"sky": {"spectrum": (wl, values), "scale": -1}})
    with pytest.raises(prizma.InputError, match=r'^lights\["sky"\]\["scal"\]: unknown key \(known: spectrum, scale\)$'):
        prizma.relight(tiny_exr, {"sky": {"spectrum": "A", "scal": 2}})
    with pytest.raises(prizma.InputError, match=r"^lights: must be None, a light for every layer"):
        prizma.relight(tiny_exr, 3)
    with pytest.raises(prizma.InputError, match=r"^lights: value must not be negative, got -0\.1 at 380\.0 nm$"):
        prizma.relight(tiny_exr, (wl, -values))
