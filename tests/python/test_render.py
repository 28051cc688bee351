"""prizma.render: the renderer of prizma-render, from a file or a dict, with progress and Ctrl-C."""
import json
import os
import signal

import numpy as np
import pytest

import prizma
from conftest import cli_error, run_tool


def tiny_dict(tiny_scene):
    with open(tiny_scene, encoding="utf-8") as f:
        return json.load(f)


def test_render_equals_the_tools_file(tiny_scene, tiny_exr):
    ours = prizma.render(tiny_scene, variance=True, threads=2)
    theirs = prizma.read(tiny_exr)
    assert list(ours.lights) == ["side", "sky"]
    for name in theirs.lights:
        np.testing.assert_array_equal(ours.lights[name], theirs.lights[name])
        np.testing.assert_array_equal(ours.variance[name], theirs.variance[name])
    assert ours.attributes["scene_hash"] == theirs.attributes["scene_hash"]
    assert ours.attributes["scene_path"] == os.path.abspath(tiny_scene)
    assert ours.stats["samples_completed"] == 4 and not ours.stats["interrupted"]


def test_render_a_dict_with_overrides_and_progress(tiny_scene, tmp_path):
    scene = tiny_dict(tiny_scene)
    reports = []
    image = prizma.render(scene, samples=6, width=5, height=3, bins="linear:400:700:4", seed=9,
                          samples_per_pass=2, progress=reports.append)
    assert image.lights["side"].shape == (3, 5, 4)
    assert image.attributes["samples"] == 6 and image.attributes["seed"] == 9
    assert [r["samples_done"] for r in reports] == [2, 4, 6]
    assert all(r["samples_total"] == 6 for r in reports)
    assert not [p for p in os.listdir(".") if p.startswith(".prizma-scene-")]  # the temporary scene is gone
    # A written render reads back the same.
    out = tmp_path / "dict.exr"
    prizma.write(out, image)
    np.testing.assert_array_equal(prizma.read(out).lights["sky"], image.lights["sky"])


def test_thread_count_does_not_change_the_image(tiny_scene):
    one = prizma.render(tiny_scene, threads=1, samples=3)
    two = prizma.render(tiny_scene, threads=2, samples=3)
    np.testing.assert_array_equal(one.lights["side"], two.lights["side"])


def test_ctrl_c_stops_the_render_and_keeps_the_passes_done(tiny_scene):
    scene = tiny_dict(tiny_scene)
    scene["camera"]["width"] = scene["camera"]["height"] = 32
    calls = []

    def interrupt(report):
        calls.append(report["samples_done"])
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C sends

    with pytest.raises(KeyboardInterrupt) as e:
        prizma.render(scene, samples=100000, samples_per_pass=1, progress=interrupt)
    partial = e.value.image
    assert partial is not None
    done = partial.attributes["samples"]
    assert 1 <= done < 100000
    assert partial.attributes["sample_range"] == f"0:{done}"
    assert np.isfinite(partial.lights["side"]).all()


def test_an_exception_in_the_callback_stops_the_render(tiny_scene):
    def fail(report):
        raise ZeroDivisionError("stop")

    with pytest.raises(ZeroDivisionError):
        prizma.render(tiny_scene, samples=64, samples_per_pass=1, progress=fail)


def test_scene_errors_are_the_tools(tiny_scene, tmp_path):
    bad = tmp_path / "bad.json"
    scene = tiny_dict(tiny_scene)
    scene["materials"][0]["albedo"] = 1.5
    bad.write_text(json.dumps(scene))
    message, status = cli_error("render", bad, "-o", tmp_path / "x.exr")
    assert status == 2
    with pytest.raises(prizma.InputError) as e:
        prizma.render(bad)
    assert str(e.value) == message
    # From a dict the message names "scene" instead of a temporary file.
    with pytest.raises(prizma.InputError) as e:
        prizma.render(scene)
    assert str(e.value) == "scene" + message[len(str(bad)):]
    assert e.value.input.startswith("scene")
    with pytest.raises(prizma.InputError, match=r"^samples: "):
        prizma.render(tiny_scene, samples=0)
