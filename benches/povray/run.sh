#!/bin/sh
# gtsphere against POV-Ray 3.7 on lit gas: first the mapping check on one gas sphere, then
# the thick clouds cloud-N (gtsphere bench gas --write) rendered by both at PX x PX pixel
# centres on one thread, each whole command timed REPS times (median), and the two images
# compared with `gtsphere compare` (POV-Ray's image as the one judged, gtsphere's as the
# reference). Files go to results/<date>/ (git-ignored).
#   usage: ./run.sh [SIZES] [REPS]      SIZES comma-separated, default 1000,10000,100000
#   environment: PX (default 128), SAMPLES (POV-Ray media samples on the clouds, default
#                16), ONE_SAMPLES (on the one sphere, default "16 64 256": the convergence),
#                GTSPHERE (default ../../target/release/gtsphere, built if missing)
set -eu
cd "$(dirname "$0")"
SIZES=${1:-1000,10000,100000}
REPS=${2:-3}
PX=${PX:-128}
SAMPLES=${SAMPLES:-16}
ONE_SAMPLES=${ONE_SAMPLES:-16 64 256}
GTS=${GTSPHERE:-../../target/release/gtsphere}
command -v povray > /dev/null || {
    echo "povray not found: apt-get update && apt-get install -y povray" >&2
    exit 1
}
[ -x "$GTS" ] || (cd ../.. && cargo build --release)
OUT=results/$(date +%Y%m%d-%H%M%S)
mkdir -p "$OUT"
echo "results in $OUT; load $(cut -d' ' -f1-3 /proc/loadavg); $(povray --version 2>&1 | grep -m1 POV-Ray)" >&2

now() { date +%s.%N; }
# median of the numbers on stdin (lower median for an even count)
median() { sort -g | awk '{v[NR]=$0} END {print v[int((NR+1)/2)]}'; }
# largest value of a PFM (for the exposure that brings POV-Ray's 16-bit PNG near 1)
pfm_max() {
    python3 -c "
import struct, sys
d = open(sys.argv[1], 'rb').read()
parts = d.split(b'\n', 3)
w, h = map(int, parts[1].split())
print(max(struct.unpack('<%df' % (3 * w * h), parts[3][:12 * w * h])))" "$1"
}
# Renders $1 (a .wrl) with both renderers, REPS times each, taking them in turn so that load
# from other users falls on both alike; $2 names the outputs, $3 is POV-Ray's media samples.
both() {
    wrl=$1
    name=$2
    samples=$3
    gts_img=$OUT/$name-gtsphere.pfm
    "$GTS" render "$wrl" -o "$gts_img" --width "$PX" --height "$PX" --sampler center --threads 1 2> /dev/null
    top=$(pfm_max "$gts_img")
    exposure=$(python3 -c "print(0.9 / $top if $top > 0 else 1.0)")
    python3 wrl2pov.py "$wrl" "$OUT/$name.pov" --samples "$samples" --width "$PX" --height "$PX" --exposure "$exposure" 2> /dev/null
    : > "$OUT/$name-times.txt"
    r=1
    while [ "$r" -le "$REPS" ]; do
        t0=$(now)
        "$GTS" render "$wrl" -o "$gts_img" --width "$PX" --height "$PX" --sampler center --threads 1 2> "$OUT/$name-gtsphere.log"
        t1=$(now)
        povray +I"$OUT/$name.pov" +O"$OUT/$name-povray.png" +W"$PX" +H"$PX" -D -A +FN16 File_Gamma=1.0 +WT1 2> "$OUT/$name-povray.log"
        t2=$(now)
        echo "gtsphere $(echo "$t1 - $t0" | bc -l) povray $(echo "$t2 - $t1" | bc -l)" >> "$OUT/$name-times.txt"
        r=$((r + 1))
    done
    python3 png2pfm.py "$OUT/$name-povray.png" "$OUT/$name-povray.pfm" --exposure "$exposure"
    g=$(awk '{print $2}' "$OUT/$name-times.txt" | median)
    p=$(awk '{print $4}' "$OUT/$name-times.txt" | median)
    cmp=$("$GTS" compare "$OUT/$name-povray.pfm" "$gts_img" --heatmap "$OUT/$name-diff.png")
    rel=$(echo "$cmp" | sed -n 's/^relative rmse *//p')
    psnr=$(echo "$cmp" | sed -n 's/^psnr *//p')
    parse=$(sed -n 's/^ *Parse Time: .*(\(.*\) seconds)/\1/p' "$OUT/$name-povray.log" | head -1)
    trace=$(sed -n 's/^ *Trace Time: .*(\(.*\) seconds)/\1/p' "$OUT/$name-povray.log" | head -1)
    printf '| %s | %s | %.3f | %.3f | %s | %s | %s | %s | %.3g |\n' "$name" "$samples" "$g" "$p" "${parse:-?}" "${trace:-?}" "$rel" "$psnr" "$exposure"
}

echo "| scene | POV-Ray media samples | gtsphere s (whole command) | POV-Ray s (whole command) | POV-Ray parse s | POV-Ray trace s | rel. RMS POV-Ray vs gtsphere | PSNR | exposure |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for s in $ONE_SAMPLES; do
    both one-sphere.wrl "one-sphere-s$s" "$s"
done
"$GTS" bench gas --write "$OUT" --sizes "$SIZES" --clouds thick 2> /dev/null
for n in $(echo "$SIZES" | tr ',' ' '); do
    both "$OUT/cloud-thick-$n.wrl" "cloud-thick-$n" "$SAMPLES"
done
echo "medians of $REPS runs, $PX x $PX pixel centres, one thread each; POV-Ray media samples $SAMPLES" >&2
