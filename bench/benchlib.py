"""Shared helpers of the bench/ drivers: locating the repository and the build, building a benchmark
target on demand, recording the machine load, and reading CSV files."""
import csv
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"


def build_dir():
    return Path(os.environ.get("PRIZMA_BUILD_DIR", ROOT / "build-bench"))


def ensure_built(target):
    """Configures (with PRIZMA_BUILD_BENCH=ON) and builds `target` in the bench build folder
    (-j$PRIZMA_JOBS, default 2)."""
    bdir = build_dir()
    exe = bdir / "bench" / target
    if not (bdir / "CMakeCache.txt").exists():
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(bdir), "-DPRIZMA_BUILD_BENCH=ON"], check=True)
    subprocess.run(["cmake", "--build", str(bdir), "-j" + os.environ.get("PRIZMA_JOBS", "2"), "--target", target],
                   check=True, stdout=subprocess.DEVNULL)
    return exe


def load_average():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def machine_note():
    """One line saying when and under which load a measurement ran."""
    cpus = os.cpu_count()
    return (f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {cpus} CPUs, "
            f"load average (1/5/15 min) {load_average()}")


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run(cmd):
    print("+", " ".join(str(c) for c in cmd), file=sys.stderr, flush=True)
    subprocess.run([str(c) for c in cmd], check=True, cwd=ROOT)
