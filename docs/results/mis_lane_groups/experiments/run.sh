#!/bin/bash
# Issue 24's closing experiments (docs/renderer.md, "Why not 2×"): estimator variants that were
# measured and not kept, switched on by environment variables in a scratch build.
#
#   git worktree add /tmp/exp HEAD        (a commit holding this folder: its renderer is df2162c's)
#   cd /tmp/exp && git apply docs/results/mis_lane_groups/experiments/issue24-experiments.patch
#   cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPRIZMA_BUILD_BENCH=ON
#   cmake --build build-bench -j2 --target bench_error_vs_time bench_spectral_mis
#   CACHE=/path/to/build-bench/cache OUT=/tmp/exp-out docs/results/mis_lane_groups/experiments/run.sh
#
# The patch adds, with none of them set the same bits as df2162c:
#   PRIZMA_SPLIT=G     one path for all bins up to the first scattering, then G runs (each run's
#                      hero drawn ∝ ρ over its bins, the other lanes' w and ρ zeroed, every run from a
#                      copy of the path's generator): unbiased (the suffix is a conditional one-sample
#                      MIS estimate over the run's techniques).
#   PRIZMA_MIS_TILT=β  hero selection probabilities c_k ∝ [x_k(1 − x_k)]^−β, x_k = (k + ½)/n within the
#                      run (more paths for the edge bins; stratified by a radical inverse), ρ started at n·c_k.
#   PRIZMA_RR=1|3      Russian roulette on the mean lane weight (1) or on √(max · mean) (3) instead of
#                      the largest lane weight.
# References: the 8192-spp renders bench/error-vs-time caches (CACHE); renders at 64², up to 256 spp.
set -u
B=build-bench/bench
CACHE=${CACHE:-build-bench/cache}
OUT=${OUT:-build-bench/issue24-experiments}
mkdir -p "$OUT"
log() { echo "$(date -u '+%F %H:%M:%S') UTC, 1-minute load $(cut -d' ' -f1 /proc/loadavg): $*"; }
evt() {  # tag, VAR=value: the error-vs-time renders of $SCENES × $METHODS with that variable set
  local tag=$1 var=$2
  env "$var" $B/bench_error_vs_time --size 64 --ref-spp 8192 --max-spp 256 --threads 2 --cache "$CACHE" \
    --scenes $SCENES --methods $METHODS --out "$OUT/$tag.csv" > "$OUT/$tag.txt" 2>&1
}
{
  # (sharing.txt beside this script was re-run with main's bench_spectral_mis at 3305bf1, which prints
  # the split per path; the patched build's gives the same variances)
  log "paths per sample against sharing: bench_spectral_mis, G = 1 2 3 6 12"
  $B/bench_spectral_mis --scenes grey cube peer peer-grey --methods spectral-mis:1 spectral-mis:2 spectral-mis:3 \
    spectral-mis:6 spectral-mis:12 --spp 64 --size 64 --repeats 3 --threads 2 > "$OUT/sharing.txt" 2>&1
  log "the baseline (no variable set) and the split after the first scattering"
  SCENES="grey cube peer peer-grey"; METHODS="spectral-mis-1 spectral-mis-3"
  evt base PRIZMA_SPLIT=0
  SCENES="cube peer"; METHODS="spectral-mis-1"
  evt split3 PRIZMA_SPLIT=3
  log "selection probabilities"
  SCENES="cube peer"; METHODS="spectral-mis-1 spectral-mis-3"
  evt tilt05 PRIZMA_MIS_TILT=0.5
  evt tilt1 PRIZMA_MIS_TILT=1
  log "roulette"
  evt rr1 PRIZMA_RR=1
  evt rr3 PRIZMA_RR=3
  log "done"
} 2>&1 | tee "$OUT/log.txt"
# The figures at 256 spp (relRMSE over the volume pixels with the reference's noise subtracted).
/usr/bin/python3 - "$OUT" <<'PY'
import csv, sys
from pathlib import Path
out = Path(sys.argv[1])
for tag in ["base", "split3", "tilt05", "tilt1", "rr1", "rr3"]:
    for r in csv.DictReader(open(out / f"{tag}.csv")):
        if r["spp"] == "256":
            e, t = float(r["rel_rmse_volume_corrected"]), float(r["seconds"])
            print(f"{tag:7s} {r['scene']:9s} {r['method']:15s} relRMSE(volume) {e:.4f}  {t:6.3f} s  "
                  f"collisions/path {float(r['collisions']) / float(r['paths']):6.2f}  D65 mean ΔE00 {float(r['mean_de00']):.3f}")
PY
