"""prizma.read / prizma.write: the spectral EXR layout, round trips, checksum, errors."""
import os

import numpy as np
import pytest

import prizma
from conftest import cli_error, run_tool


def test_read_gives_the_layout(tiny_exr):
    image = prizma.read(tiny_exr)
    assert list(image.lights) == ["side", "sky"]
    assert image.bins == 6 and image.width == 8 and image.height == 8
    np.testing.assert_array_equal(image.bin_edges_nm, np.linspace(400, 700, 7))
    np.testing.assert_allclose(image.wavelengths_nm, [425, 475, 525, 575, 625, 675])
    for name, layer in image.lights.items():
        assert layer.dtype == np.float32 and layer.shape == (8, 8, 6)
        assert np.isfinite(layer).all() and layer.max() > 0
        assert image.variance[name].shape == (8, 8, 6)
    a = image.attributes
    assert a["samples"] == 4 and a["sample_range"] == "0:4" and a["seed"] == 3
    assert [l["name"] for l in a["lights"]] == ["side", "sky"]
    assert a["lights"][1]["spectrum"] == "D65*0.2"
    assert a["is_prizma"] is True


def test_arrays_are_views_of_the_readers_buffers(tiny_exr):
    image = prizma.read(tiny_exr)
    layer = image.lights["side"]
    assert not layer.flags.owndata and layer.base is not None  # over the C++ buffer, not a copy
    assert layer.flags.c_contiguous and layer.flags.writeable


def test_write_read_round_trip(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    out = tmp_path / "copy.exr"
    prizma.write(out, image)
    back = prizma.read(out)
    assert list(back.lights) == list(image.lights)
    for name in image.lights:
        np.testing.assert_array_equal(back.lights[name], image.lights[name])
        np.testing.assert_array_equal(back.variance[name], image.variance[name])
    np.testing.assert_array_equal(back.bin_edges_nm, image.bin_edges_nm)
    for key in ("samples", "sample_range", "seed", "scene_hash", "wavelength_sampling", "mis_lane_groups", "lights"):
        assert back.attributes[key] == image.attributes[key], key
    # tiny.json's chromatic haze: spectral MIS in 2 lane groups under auto, recorded in the file
    assert (image.attributes["wavelength_sampling"], image.attributes["mis_lane_groups"]) == ("spectral-mis", 2)
    assert prizma.checksum(back) == prizma.checksum(image)


def test_write_an_image_made_in_numpy(tmp_path):
    rng = np.random.default_rng(7)
    edges = [400.0, 433.3, 500.0, 612.5, 700.0]  # uneven bins survive exactly
    lights = {"key": rng.random((3, 5, 4), dtype=np.float32),
              "fill": rng.random((3, 5, 4)).astype(np.float64)}  # float64 is converted
    image = prizma.Image(lights, edges, attributes={"samples": 16, "lights": [{"name": "key"}, {"name": "fill"}]})
    out = tmp_path / "made.exr"
    prizma.write(out, image)
    back = prizma.read(out)
    assert list(back.lights) == ["key", "fill"]
    np.testing.assert_array_equal(back.bin_edges_nm, edges)
    np.testing.assert_array_equal(back.lights["key"], lights["key"])
    np.testing.assert_array_equal(back.lights["fill"], lights["fill"].astype(np.float32))
    assert back.attributes["samples"] == 16


def test_half_round_trip(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    out = tmp_path / "half.exr"
    prizma.write(out, image, half=True)
    back = prizma.read(out)
    np.testing.assert_array_equal(back.lights["sky"], image.lights["sky"].astype(np.float16).astype(np.float32))


def test_write_refuses_nan_and_leaves_the_old_file(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    out = tmp_path / "keep.exr"
    prizma.write(out, image)
    before = out.read_bytes()
    image.lights["sky"][2, 1, 3] = np.nan
    with pytest.raises(prizma.InputError) as e:
        prizma.write(out, image)
    assert str(e.value) == f'{out}: light "sky": NaN at pixel (1, 2), bin 3'
    assert e.value.input == str(out) and e.value.reason == 'light "sky": NaN at pixel (1, 2), bin 3'
    assert isinstance(e.value, ValueError)
    assert out.read_bytes() == before


def test_write_refuses_a_bad_shape(tmp_path):
    image = prizma.Image({"a": np.zeros((2, 2, 3), np.float32), "b": np.zeros((2, 3, 3), np.float32)},
                         [400, 500, 600, 700])
    with pytest.raises(prizma.InputError, match=r'lights\["b"\]: has shape \(2, 3, 3\), expected \(2, 2, 3\)'):
        prizma.write(tmp_path / "x.exr", image)
    assert not (tmp_path / "x.exr").exists()


def test_errors_carry_the_tools_message(tmp_path):
    missing = tmp_path / "missing.exr"
    message, status = cli_error("relight", missing, "-o", tmp_path / "x.png")
    assert status == 2
    with pytest.raises(prizma.InputError) as e:
        prizma.read(missing)
    assert str(e.value) == message


def test_damaged_file_is_refused_like_the_tool_refuses_it(tiny_exr, tmp_path):
    data = bytearray(tiny_exr.read_bytes())
    # Flip one bit of the last pixel bytes: the file still decodes, the checksum no longer matches.
    data[-3] ^= 0x01
    bad = tmp_path / "damaged.exr"
    bad.write_bytes(bytes(data))
    message, status = cli_error("relight", bad, "-o", tmp_path / "x.png")
    assert status == 2
    assert message.endswith("(the file is damaged; --no-verify reads it anyway)"), message
    with pytest.raises(prizma.InputError) as e:
        prizma.read(bad)
    # The same message, naming Python's way to read it anyway instead of the tool's option.
    assert str(e.value) == message.replace("--no-verify", "prizma.read(path, verify=False)")


def test_unwritable_destination_is_an_input_error(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    with pytest.raises(prizma.InputError) as e:
        prizma.write(tmp_path / "no" / "such" / "folder.exr", image)
    assert "folder.exr" in str(e.value)


@pytest.mark.parametrize("lights, message", [
    ("[{not json", r'attributes\["lights"\]: is not valid JSON'),
    ([{"name": "key"}, {"spectrum": "D65"}], r'attributes\["lights"\]\[1\]: has no "name"'),
    ([{"name": "key", "direction": [0, 1]}, {"name": "fill"}],
     r'attributes\["lights"\]\[0\]: "direction" must be an array of 3 numbers'),
    ([{"name": "key"}, {"name": "back"}], r'prizma:lights announces light "back" but the file has no layer for it'),
])
def test_write_refuses_lights_its_reader_would_refuse(tmp_path, lights, message):
    # One light record (light_record.h) reads and writes prizma:lights: what write accepts reads back.
    layers = {"key": np.ones((2, 2, 3), np.float32), "fill": np.ones((2, 2, 3), np.float32)}
    image = prizma.Image(layers, np.array([400.0, 500.0, 600.0, 700.0]), attributes={"lights": lights})
    out = tmp_path / "lights.exr"
    with pytest.raises(prizma.InputError, match=message):
        prizma.write(out, image)
    assert not out.exists()


def test_paths_with_a_nul_are_refused_as_open_refuses_them(tiny_exr, tiny_scene, tmp_path):
    """A NUL would cut the path short in C++ ("a.exr\\0.txt" read or written as a.exr): ValueError."""
    image = prizma.read(tiny_exr)
    existing = tmp_path / "a.exr"
    prizma.write(existing, image)
    before = existing.read_bytes()
    calls = [
        ("path", lambda: prizma.read(str(existing) + "\0.txt")),
        ("path", lambda: prizma.write(str(existing) + "\0.txt", image)),
        ("image", lambda: prizma.relight(os.fsencode(existing) + b"\0x")),
        ("config", lambda: prizma.relight(image, config=str(tmp_path) + "\0cfg.ocio")),
        ("scene", lambda: prizma.render(tiny_scene + "\0.json", samples=1)),
        ("base_dir", lambda: prizma.render({}, base_dir=str(tmp_path) + "\0")),
    ]
    for name, call in calls:
        with pytest.raises(ValueError) as e:
            call()
        assert isinstance(e.value, prizma.InputError)
        assert str(e.value) == f"{name}: embedded null byte"
    assert existing.read_bytes() == before


def test_write_stores_only_lights_its_own_reader_takes(tiny_exr, tmp_path):
    image = prizma.read(tiny_exr)
    out = tmp_path / "lights.exr"
    image.attributes["lights"][0]["angularSizeDeg"] = float("nan")  # json.dumps would write NaN: not JSON
    with pytest.raises(prizma.InputError, match=r'^attributes\["lights"\]: cannot be stored as JSON'):
        prizma.write(out, image)
    image.attributes["lights"] = "not JSON"
    with pytest.raises(prizma.InputError, match=r'^attributes\["lights"\]: is not valid JSON$'):
        prizma.write(out, image)
    image.attributes["lights"] = _nested(200)
    with pytest.raises(prizma.InputError, match=r'^attributes\["lights"\]: JSON nested deeper than 128 levels'):
        prizma.write(out, image)
    assert not out.exists()
    # What it writes reads back as written.
    lights = [{"name": "side", "spectrum": "A", "direction": [0.5, 0.0, 1.0]}, {"name": "sky", "spectrum": "F11"}]
    image.attributes["lights"] = lights
    prizma.write(out, image)
    assert prizma.read(out).attributes["lights"] == lights


def _nested(depth):
    value = []
    for _ in range(depth - 1):
        value = [value]
    return value


def test_the_largest_seed_is_recorded_exactly(tiny_scene, tmp_path):
    """prizma:seed holds every 64-bit seed (2^64 − 1 was recorded as −1)."""
    out = tmp_path / "seed.exr"
    run_tool("render", tiny_scene, "-o", out, "-q", "--spp", "1", "--seed", str(2**64 - 1))
    image = prizma.read(out)
    assert image.attributes["seed"] == 2**64 - 1
    again = tmp_path / "again.exr"
    prizma.write(again, image)
    assert prizma.read(again).attributes["seed"] == 2**64 - 1
    image.attributes["seed"] = -1
    with pytest.raises(prizma.InputError, match=r'^attributes\["seed"\]: must be an integer ≥ 0'):
        prizma.write(again, image)
