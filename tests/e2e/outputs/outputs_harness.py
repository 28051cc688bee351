"""What the output checks share (check-outputs, check-run-outputs; tests/e2e/outputs.cmake): the
command line, running a tool with limits, and checking its exit status, its one-line error and the
files it must leave alone.

A script defines case_<name>() functions and ends with harness.main(globals())."""
import argparse
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import time

ap = argparse.ArgumentParser()
ap.add_argument("--render", required=True)
ap.add_argument("--relight", required=True)
ap.add_argument("--metamer", required=True)
ap.add_argument("--scene", required=True)
ap.add_argument("--work", required=True)
ap.add_argument("--io-faults", help="the LD_PRELOAD library of io_faults.cpp (case io_faults)")
ap.add_argument("--max-seconds", type=float, default=120, help="limit of every run")
ap.add_argument("case")
a = argparse.Namespace()  # filled by main(); scripts read it as harness.a

FAILURES = []
HUGE_SPP = "100000000"  # a render that would run for hours: an error must come before it starts
QUICK_S = 30.0          # "before any work": well under the time any real render would take


def fail(msg):
    FAILURES.append(msg)


def run(cmd, cwd, fsize=None, stdout=None, timeout=None, env=None):
    timeout = min(timeout or a.max_seconds, a.max_seconds)
    def limit():
        if fsize is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # as (trap '' XFSZ; ulimit -f ...)
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=cwd, preexec_fn=limit, stdin=subprocess.DEVNULL, stdout=stdout or subprocess.PIPE,
                           stderr=subprocess.PIPE, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        fail(f"{' '.join(cmd)}: ran past {timeout} s (the check did not come before the work)")
        return None
    p.elapsed = time.monotonic() - start
    p.err = p.stderr.decode("utf-8", "replace")
    return p


def expect_error(p, cmd, rc, regex, quick=False):
    """Exit code rc and exactly one stderr line '<prog>: error: ...' matching regex."""
    if p is None:
        return
    what = " ".join(os.path.basename(c) if i == 0 else c for i, c in enumerate(cmd))
    prog = os.path.basename(cmd[0])
    lines = p.err.splitlines()
    if p.returncode != rc:
        fail(f"{what}: exit {p.returncode}, expected {rc}; stderr: {p.err.strip()}")
    elif len(lines) != 1:
        fail(f"{what}: stderr has {len(lines)} lines, expected 1: {p.err.strip()}")
    elif not lines[0].startswith(prog + ": error: "):
        fail(f"{what}: stderr does not start with '{prog}: error: ': {lines[0]}")
    elif not re.search(regex, lines[0]):
        fail(f"{what}: the message does not say /{regex}/: {lines[0]}")
    elif quick and p.elapsed > QUICK_S:
        fail(f"{what}: refused only after {p.elapsed:.1f} s (after the work?)")
    else:
        print(f"ok: exit {rc}: {lines[0]}")


def expect_ok(p, cmd):
    if p is not None and p.returncode != 0:
        fail(f"{' '.join(cmd)}: exit {p.returncode}: {p.err.strip()}")


def snapshot(path):
    st = os.lstat(path)
    data = open(path, "rb").read() if stat.S_ISREG(st.st_mode) else None
    return (stat.S_IFMT(st.st_mode), st.st_ino, st.st_mtime_ns, data)


def expect_unchanged(path, before):
    if not os.path.lexists(path):
        fail(f"{path}: removed")
    elif snapshot(path) != before:
        fail(f"{path}: changed or replaced")


def expect_no_temporaries(folder):
    """No temporary (.prizma-tmp-*) and no kept link to a replaced file (.prizma-old-*) in folder."""
    left = [f for f in os.listdir(folder) if f.startswith((".prizma-tmp-", ".prizma-old-"))]
    if left:
        fail(f"{folder}: temporaries left behind: {left}")


def case_dir():
    d = os.path.join(a.work, a.case)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def scene_exr():
    return os.path.join(a.work, "scene.exr")


def shards():
    return [os.path.join(a.work, "shard0.exr"), os.path.join(a.work, "shard1.exr")]


OLD = b"the old file: a failed run must leave these bytes\n" * 4


def old_file(d, name):
    path = os.path.join(d, name)
    with open(path, "wb") as f:
        f.write(OLD)
    return path, snapshot(path)


def main(namespace):
    """Parses the command line and runs the case it names among namespace's case_* functions."""
    vars(a).update(vars(ap.parse_args()))
    cases = {name[5:]: fn for name, fn in namespace.items() if name.startswith("case_")}
    if a.case not in cases:
        sys.exit(f"{os.path.basename(sys.argv[0])}: unknown case {a.case} (known: {', '.join(cases)})")
    a.render, a.relight, a.metamer, a.scene = (os.path.abspath(x) for x in (a.render, a.relight, a.metamer, a.scene))
    a.work = os.path.abspath(a.work)
    cases[a.case]()
    if FAILURES:
        print(f"FAIL: {a.case}", file=sys.stderr)
        for f in FAILURES:
            print("  - " + f, file=sys.stderr)
        sys.exit(1)
    print(f"ok: {a.case}")
