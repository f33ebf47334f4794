#!/bin/sh
# Are the two files the same scene? Renders run.sh's two files once each with one ray through
# every pixel centre (gtsphere --sampler center, linear PFM; Tachyon's ANTIALIASING 0, PPM),
# then compares them: ppm2pfm.py's count of pixels that differ by more than 2/255 (gtsphere's
# values clamped to 1 as Tachyon's are), `gtsphere compare` of the same two (clamped) with a
# heat map, and a side-by-side PNG (gtsphere left, Tachyon right).
#   usage: ./check.sh [N] [SIZE]       N default 1000, SIZE default 512
#   environment: DIR, FORM, GTSPHERE, TACHYON as for run.sh
set -eu
cd "$(dirname "$0")"
N=$(python3 -c "print(int(float('${1:-1000}')))")
SIZE=${2:-512}
. ./files.sh
OUT=$DIR/check-$N-$SIZE
"$GTS" render "$WRL" --width "$SIZE" --height "$SIZE" --sampler center --threads 1 \
    -o "$OUT-gtsphere.pfm" -q
"$TACHYON" "$DAT" -numthreads 1 -format PPM -o "$OUT-tachyon.ppm" > /dev/null
python3 ppm2pfm.py "$OUT-tachyon.ppm" "$OUT-tachyon.pfm" \
    --side-by-side "$OUT-gtsphere.pfm" "$OUT-side-by-side.png" --clamped "$OUT-gtsphere-clamped.pfm"
"$GTS" compare "$OUT-tachyon.pfm" "$OUT-gtsphere-clamped.pfm" --heatmap "$OUT-diff.png"
echo "pictures: $OUT-side-by-side.png (gtsphere left, Tachyon right), heat map $OUT-diff.png" >&2
