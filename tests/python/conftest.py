"""Shared fixtures of the prizma Python tests (run by ctest: python.pytest, label python).

ctest sets PYTHONPATH to the build's python/ folder, PRIZMA_DATA_DIR, and the paths of the tools
(PRIZMA_RENDER, PRIZMA_RELIGHT) whose output files the module must reproduce.
"""
import os
import subprocess

import pytest

import prizma

SCENE_DIR = os.environ.get("PRIZMA_TEST_SCENE_DIR", os.path.join(os.path.dirname(__file__), "..", "e2e", "render"))


def tool(name):
    path = os.environ.get("PRIZMA_" + name.upper())
    if not path:
        pytest.skip(f"PRIZMA_{name.upper()} not set (run through ctest)")
    return path


def run_tool(name, *args, check=True):
    """Runs prizma-<name>; returns the CompletedProcess (text)."""
    proc = subprocess.run([tool(name), *map(str, args)], capture_output=True, text=True, timeout=120)
    if check and proc.returncode != 0:
        raise AssertionError(f"prizma-{name} {' '.join(map(str, args))} failed ({proc.returncode}): {proc.stderr}")
    return proc


def cli_error(name, *args):
    """The one-line message prizma-<name> prints after "prizma-<name>: error: ", and its exit status."""
    proc = run_tool(name, *args, check=False)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    prefix = f"prizma-{name}: error: "
    assert lines[0].startswith(prefix), lines[0]
    return lines[0][len(prefix):], proc.returncode


def _fail_skips_in_ci(report):
    """tests/missing-tool's rule: a test skipped for a missing tool (pytest.importorskip, oiiotool)
    fails with CI=true, where every test must run."""
    if report.skipped and os.environ.get("CI") == "true" and not hasattr(report, "wasxfail"):
        report.outcome = "failed"
        report.longrepr = f"skipped with CI=true (a missing tool fails instead of skipping): {report.longrepr}"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    _fail_skips_in_ci((yield).get_result())


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    _fail_skips_in_ci((yield).get_result())


@pytest.fixture(scope="session")
def tiny_scene():
    return os.path.join(SCENE_DIR, "tiny.json")


@pytest.fixture(scope="session")
def tiny_exr(tmp_path_factory, tiny_scene):
    """tests/e2e/render/tiny.json rendered by prizma-render (8×8, lights side and sky, 6 bins)."""
    out = tmp_path_factory.mktemp("render") / "tiny.exr"
    run_tool("render", tiny_scene, "-o", out, "-q", "--variance")
    return out
