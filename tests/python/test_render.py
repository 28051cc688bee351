"""prizma.render: the renderer of prizma-render, from a file or a dict, with progress and Ctrl-C."""
import json
import os
import signal
import subprocess
import sys

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


def test_a_dict_is_rendered_without_writing_a_file(tiny_scene, tmp_path, monkeypatch):
    """The scene of a dict is read from memory: nothing appears in the folder while it renders (a
    temporary there failed in a read-only folder and stayed behind after SIGTERM)."""
    monkeypatch.chdir(tmp_path)
    seen = []
    prizma.render(tiny_dict(tiny_scene), samples=2, samples_per_pass=1,
                  progress=lambda report: seen.append(os.listdir(tmp_path)))
    assert seen == [[], []]


@pytest.mark.parametrize("argument, value, option", [
    ("seed", -1, "--seed"), ("seed", 2**64, "--seed"), ("width", 0, "--width"), ("width", 2**70, "--width"),
    ("height", -3, "--height"), ("samples", 2**63, "--spp")])
def test_integer_arguments_fail_in_one_line_as_the_tools_options(tiny_scene, tmp_path, argument, value, option):
    message, status = cli_error("render", tiny_scene, "-o", tmp_path / "x.exr", option, str(value))
    assert status == 2 and message.startswith(option + ": ")
    with pytest.raises(prizma.InputError) as e:
        prizma.render(tiny_scene, **{argument: value})
    assert str(e.value) == argument + message[len(option):]
    assert e.value.input == argument


@pytest.mark.parametrize("arguments, message", [
    ({"threads": -1}, "threads: must be in [0, 65536] (0: all cores) (got -1)"),
    ({"samples_per_pass": 2**64}, "samples_per_pass: must be in [0, 1099511627776] (0: automatic) (got 18446744073709551616)"),
    ({"seed": "3"}, "seed: must be an integer (got '3')"),
    ({"samples": 2.5}, "samples: must be an integer (got 2.5)"),
    ({"width": True}, "width: must be an integer (got True)")])
def test_other_integer_arguments_fail_in_one_line(tiny_scene, arguments, message):
    with pytest.raises(prizma.InputError) as e:
        prizma.render(tiny_scene, **arguments)
    assert str(e.value) == message


EXIT_WHILE_CALLING = r'''
import sys, threading, prizma
kind, path = sys.argv[1], sys.argv[2]
started = threading.Event()
def work():
    if kind == "render":
        prizma.render(path, samples=10**9, samples_per_pass=1, progress=lambda report: started.set())
    image = prizma.read(path)
    while True:
        prizma.relight(image, "A")
        started.set()
threading.Thread(target=work, daemon=True).start()
started.wait(60)
print("exiting", flush=True)
'''


@pytest.mark.parametrize("kind", ["render", "relight"])
def test_the_interpreter_exits_cleanly_while_a_thread_calls_in(tiny_scene, tiny_exr, kind):
    """The interpreter exits while a daemon thread renders or relights: exit 0, nothing on stderr
    (it aborted with "terminate called without an active exception", exit 134)."""
    path = tiny_scene if kind == "render" else str(tiny_exr)
    proc = subprocess.run([sys.executable, "-c", EXIT_WHILE_CALLING, kind, path], capture_output=True, text=True,
                          timeout=120)
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "exiting\n", "")
