"""prizma.denoise: the denoiser of prizma-render denoise on an image in memory (docs/python.md)."""
import numpy as np
import pytest

import prizma
from conftest import run_tool


def test_denoise_equals_the_tools_file(tiny_exr, tmp_path):
    raw = prizma.read(tiny_exr)
    ours = prizma.denoise(raw, threads=2)
    out = tmp_path / "clean.exr"
    run_tool("render", "denoise", tiny_exr, "-o", out, "-q")
    theirs = prizma.read(out)
    for name in raw.lights:
        np.testing.assert_array_equal(ours.lights[name], theirs.lights[name])
        np.testing.assert_array_equal(ours.variance[name], theirs.variance[name])
        # The filter changed the values and its variance is smaller than the raw one.
        assert not np.array_equal(ours.lights[name], raw.lights[name])
        assert ours.variance[name].sum() < raw.variance[name].sum()
    record = ours.attributes["denoised"]
    assert record == theirs.attributes["denoised"]
    assert record["method"] == "non-local means" and record["guides"] == ["luminance"]
    assert record["variance"] == "propagated" and record["parameters"]["window_radius_px"] == 5
    assert raw.attributes["denoised"] is None


def test_dropped_variance_round_trips_through_a_file(tiny_exr, tmp_path):
    clean = prizma.denoise(prizma.read(tiny_exr), variance="drop", window=3, strength=0.6)
    assert clean.variance == {}
    out = tmp_path / "dropped.exr"
    prizma.write(out, clean)
    back = prizma.read(out)  # rendered with --variance, denoised without: not "missing channels"
    assert back.variance == {}
    assert back.attributes["denoised"]["variance"] == "dropped"
    assert back.attributes["denoised"]["parameters"]["window_radius_px"] == 3
    np.testing.assert_array_equal(back.lights["side"], clean.lights["side"])
    # A denoised file relights like any other.
    assert prizma.relight(back, {"side": "A", "sky": "D65"}).shape == (8, 8, 3)


def test_thread_count_does_not_change_the_result(tiny_exr):
    raw = prizma.read(tiny_exr)
    one, two = prizma.denoise(raw, threads=1), prizma.denoise(raw, threads=2)
    np.testing.assert_array_equal(one.lights["sky"], two.lights["sky"])


def test_refusals(tiny_scene, tiny_exr):
    no_variance = prizma.render(tiny_scene, samples=2)
    with pytest.raises(prizma.InputError, match=r'^image: light "side" has no variance layer: .*--variance\)$'):
        prizma.denoise(no_variance)
    clean = prizma.denoise(prizma.read(tiny_exr))
    with pytest.raises(prizma.InputError, match=r"^image: is already denoised \(denoised by prizma .*\): denoise the raw"):
        prizma.denoise(clean)
    raw = prizma.read(tiny_exr)
    with pytest.raises(prizma.InputError, match=r'^variance: "keep" is neither "propagate" nor "drop"$'):
        prizma.denoise(raw, variance="keep")
    with pytest.raises(prizma.InputError, match=r"^denoise options: window radius 16 is outside \[1, 15\]"):
        prizma.denoise(raw, window=16)
    with pytest.raises(prizma.InputError, match=r"^threads: must be ≥ 0"):
        prizma.denoise(raw, threads=-1)
    with pytest.raises(prizma.InputError, match=r'^guides: "depth" is neither "luminance" nor "features"$'):
        prizma.denoise(raw, guides="depth")


def test_render_denoise_is_denoise_of_the_kept_raw_render(tiny_scene, tmp_path):
    clean, raw = tmp_path / "clean.exr", tmp_path / "raw.exr"
    run_tool("render", tiny_scene, "--denoise", "--features", "--keep-raw", raw, "-o", clean, "-q")
    kept = prizma.read(raw)
    assert kept.attributes["denoised"] is None and set(kept.variance) == {"side", "sky"}
    # --features: the guide layers, light-independent means in [0, 1]: the Monte Carlo ones and the
    # first-hit ones (hit_*), which --denoise then uses.
    hit = {n for n in kept.guides if n.startswith("hit_")}
    assert {"hit_depth", "hit_normal_x", "hit_normal_y", "hit_normal_z", "hit_albedo", "hit_density"} <= hit
    assert set(kept.guides) == {"depth", "scatter"} | hit and set(kept.guide_variance) == set(kept.guides)
    assert kept.guides["depth"].shape == (8, 8) and kept.guides["hit_depth"].shape == (8, 8)
    assert 0.0 <= kept.guides["scatter"].min() and kept.guides["scatter"].max() <= 1.0
    assert 0.0 < kept.guides["scatter"].max() and kept.guides["depth"].min() < 1.0
    ours, theirs = prizma.denoise(kept, guides="features"), prizma.read(clean)
    for name in kept.lights:
        np.testing.assert_array_equal(ours.lights[name], theirs.lights[name])
        np.testing.assert_array_equal(ours.variance[name], theirs.variance[name])
    used = theirs.attributes["denoised"]["guides"]
    assert used[0] == "luminance" and set(used[1:]) == hit  # the first-hit layers, not the Monte Carlo ones
    assert theirs.guides == {}  # the guides served the weights; the denoised file keeps none
    assert prizma.denoise(kept).attributes["denoised"]["guides"] == ["luminance"]  # the default
