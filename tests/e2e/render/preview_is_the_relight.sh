#!/bin/sh
# prizma-render --preview is the render's default relight, written as prizma-relight writes it
# (issue 22): no pixel of `prizma-render SCENE -o p.exr --preview p.png` differs from `prizma-relight
# p.exr -o r.png`, and both record the same relight (prizma:lights, exposure, observer, units,
# display, bins; the same ICC profile but for its creation date). With --half the preview relights
# the values the half file holds (it relit the render's floats: up to 1 code apart in 0.2 % of the
# pixels of this scene).
#   preview_is_the_relight.sh RENDER RELIGHT OIIOTOOL SCENE WORK_DIR [--half]
set -eu
render=$1 relight=$2 oiiotool=$3 scene=$4 work=$5
shift 5
rm -rf "$work" && mkdir -p "$work" && cd "$work"
"$render" "$scene" -D camera.width=128 -D camera.height=128 --spp 4 --threads 2 -q "$@" -o p.exr --preview p.png
"$relight" p.exr -o r.png -q
"$oiiotool" p.png r.png --fail 0 --failpercent 0 --warn 0 --diff
# What each records, but for who wrote it and from which path, and when its profile was made.
describe() { "$oiiotool" --info -v "$1" | grep -v -e '^ *Software:' -e '^ *prizma:source:' -e 'creation_date' -e '^[^ ]'; }
describe p.png >p.txt
describe r.png >r.txt
grep -q 'prizma:lights' p.txt || { echo "the preview records no prizma:lights" >&2; exit 1; }
diff p.txt r.txt
