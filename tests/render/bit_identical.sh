#!/usr/bin/env bash
# bit_identical.sh: renders a matrix of scenes with two prizma-render binaries and checks that every
# output is the same to the bit (docs/renderer.md, "Checking a refactor bit for bit"). For a change
# of the tracer that must not change its output: keep a copy of the binary built before it.
#
#   tests/render/bit_identical.sh REF_BINARY NEW_BINARY [WORK_DIR]
#
# Every case runs both binaries with the same arguments; the two runs must exit alike, and when they
# wrote a file, idiff must find every channel (light layers, variance, bispectral) equal with no
# tolerance and iinfo must list the same attributes (prizma:checksum included) but the version and
# the compression.
# Prints one line per case and exits 1 when any case differs. Not run by ctest (it needs a second
# binary); a few minutes (about 100 renders of 32×32 pixels).
set -u
if [[ $# -lt 2 ]]; then
  echo "usage: $0 REF_BINARY NEW_BINARY [WORK_DIR]" >&2
  exit 2
fi
ref=$(realpath "$1")
new=$(realpath "$2")
root=$(cd "$(dirname "$0")/../.." && pwd)
work=${3:-$(mktemp -d /tmp/bit-identical.XXXXXX)}
mkdir -p "$work"
for tool in idiff iinfo; do
  command -v "$tool" >/dev/null || { echo "$0: error: $tool: not found (Debian openimageio-tools)" >&2; exit 2; }
done
cd "$root"

small=(-D camera.width=32 -D camera.height=32 -q)
# Every example scene (the MRI scenes read Debian mricron-data templates; a missing file fails alike).
scenes=()
for f in data/scenes/*.json; do scenes+=("$(basename "$f" .json)"); done
cases=()
for s in "${scenes[@]}"; do
  cases+=("$s|--threads 1")
  cases+=("$s|--threads 2 --variance")
  cases+=("$s|--threads 1 --wavelength-sampling single")
  cases+=("$s|--threads 2 --wavelength-sampling single --variance")
done
# Options that take other branches of the render loop.
cases+=("cube_sphere|--threads 2 --no-majorant-grid")
cases+=("cube_sphere|--threads 2 --samples 8:40 --target-error 0.05 --variance")
cases+=("cube_sphere|--threads 1 --bins linear:380:780:64")
cases+=("cube_sphere|--threads 1 --bins linear:500:520:1")
cases+=("metamers|--threads 2 -D max_bounces=2")
cases+=("fluorescent_dye|--threads 2 --bins linear:400:700:4 --variance")

failed=0
rendered=0
k=0
for c in "${cases[@]}"; do
  scene=${c%%|*}
  read -r -a opts <<<"${c#*|}"
  [[ " ${opts[*]} " == *" --samples "* ]] || opts+=(--spp 16)
  k=$((k + 1))
  a="$work/$k-ref.exr" b="$work/$k-new.exr"
  rm -f "$a" "$b"
  "$ref" "data/scenes/$scene.json" "${small[@]}" "${opts[@]}" -o "$a" >"$work/$k-ref.log" 2>&1
  ra=$?
  "$new" "data/scenes/$scene.json" "${small[@]}" "${opts[@]}" -o "$b" >"$work/$k-new.log" 2>&1
  rb=$?
  what="$scene ${opts[*]}"
  if [[ $ra -ne $rb ]]; then
    echo "DIFFERS  $what: exit $ra vs $rb"
    failed=1
    continue
  fi
  if [[ ! -e $a ]]; then
    if cmp -s "$work/$k-ref.log" "$work/$k-new.log"; then
      echo "same     $what (exit $ra, no file, same message)"
    else
      echo "DIFFERS  $what: exit $ra, messages differ"
      failed=1
    fi
    continue
  fi
  rendered=$((rendered + 1))
  if ! idiff -q -fail 0 -failpercent 0 -warn 0 -a "$a" "$b" >"$work/$k-idiff.log" 2>&1; then
    echo "DIFFERS  $what: pixels ($work/$k-idiff.log)"
    failed=1
    continue
  fi
  # The compression is how the file is stored, not what was rendered (small images are written
  # uncompressed since 2026-12-02, PIZ before): idiff has compared the values.
  if ! diff <(iinfo -v "$a" | grep -v 'prizma:version\|compression:\|^'"$a") <(iinfo -v "$b" | grep -v 'prizma:version\|compression:\|^'"$b") \
      >"$work/$k-attr.log"; then
    echo "DIFFERS  $what: attributes ($work/$k-attr.log)"
    failed=1
    continue
  fi
  echo "same     $what ($(iinfo -v "$a" | grep -c 'channel\|T\.' | tr -d '\n') lines, checksum $(iinfo -v "$a" | sed -n 's/.*prizma:checksum: *//p'))"
done
if [[ $failed -eq 0 ]]; then
  echo "all ${#cases[@]} cases bit-identical ($rendered of them wrote a file)"
else
  echo "some cases differ"
fi
exit $failed
