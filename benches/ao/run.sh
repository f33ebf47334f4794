#!/bin/sh
# docs/evaluation.md's tables: each AO method and Tachyon's AO against gtsphere's exact AO.
#   usage: benches/ao/run.sh [SCENE...]     (pymol, random, fcc; default all three)
#   environment: DIR (default /tmp/gtsphere-ao-eval), GTSPHERE (default target/release/gtsphere),
#                TACHYON (default tachyon), SIZE (default 384), REACH (default 4)
# Prints one line per method: scene, method, seconds (wall, one run), RMSE and largest error
# against exact; heat maps (error scale 0 to 0.5) go to $DIR.
set -eu
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
DIR=${DIR:-/tmp/gtsphere-ao-eval}
GTS=${GTSPHERE:-$ROOT/target/release/gtsphere}
TACHYON=${TACHYON:-tachyon}
SIZE=${SIZE:-384}
REACH=${REACH:-4}
mkdir -p "$DIR"

secs() { python3 -c "import time; print('%.2f' % time.time())"; }

compare() {  # scene method seconds image
    line=$("$GTS" compare "$4" "$DIR/$1-exact.npy" --heatmap "$DIR/$1-$2-error.png" \
        --heatmap-max 0.5)
    echo "$1 | $2 | $3 | $(echo "$line" | tr '\n' ' ')"
}

render() {  # scene name options...
    s=$1; n=$2; shift 2
    t0=$(secs)
    "$GTS" render "$DIR/$s.wrl" --viewpoint eval --integrator ao --ao-reach "$REACH" \
        --width "$SIZE" --height "$SIZE" --sampler center -o "$DIR/$s-$n.npy" -q "$@"
    t1=$(secs)
    python3 -c "print('%.2f' % ($t1 - $t0))"
}

for s in ${*:-pymol random fcc}; do
    python3 "$ROOT/benches/ao/scenes.py" "$s" "$DIR/$s.wrl" "$DIR/$s.dat" --size "$SIZE"
    t=$(render "$s" exact)
    echo "$s | exact | $t |"
    t=$(render "$s" exact); echo "$s | exact (again) | $t |"
    t=$(render "$s" mc16 --ao-method mc --ao-samples 16); compare "$s" mc16 "$t" "$DIR/$s-mc16.npy"
    t=$(render "$s" mc256 --ao-method mc --ao-samples 256); compare "$s" mc256 "$t" "$DIR/$s-mc256.npy"
    t=$(render "$s" dir64 --ao-method directions --ao-directions 64); compare "$s" dir64 "$t" "$DIR/$s-dir64.npy"
    t=$(render "$s" sum --ao-method sum); compare "$s" sum "$t" "$DIR/$s-sum.npy"
    t=$(render "$s" voxel --ao-method voxel); compare "$s" voxel "$t" "$DIR/$s-voxel.npy"
    # Tachyon's AO has no reach: also judged against mc at any distance, 1024 rays
    "$GTS" render "$DIR/$s.wrl" --viewpoint eval --integrator ao --ao-method mc \
        --ao-samples 1024 --width "$SIZE" --height "$SIZE" --sampler center \
        -o "$DIR/$s-mcinf.npy" -q
    for n in 4 16 64 256; do
        t0=$(secs)
        "$TACHYON" "$DIR/$s.dat" -add_skylight 1 -skylight_samples "$n" -format PPM48 \
            -o "$DIR/$s-tachyon$n.ppm" > /dev/null
        t1=$(secs)
        python3 "$ROOT/benches/ao/ppm48.py" "$DIR/$s-tachyon$n.ppm" "$DIR/$s-tachyon$n.npy"
        compare "$s" "tachyon$n" "$(python3 -c "print('%.2f' % ($t1 - $t0))")" "$DIR/$s-tachyon$n.npy"
        line=$("$GTS" compare "$DIR/$s-tachyon$n.npy" "$DIR/$s-mcinf.npy")
        echo "$s | tachyon$n against mc 1024 at any distance | | $(echo "$line" | tr '\n' ' ')"
    done
done

# the page's pictures: exact AO, then the heat maps of sum, voxel, directions 64, Tachyon 256
for s in ${*:-pymol random fcc}; do
    python3 "$ROOT/benches/ao/montage.py" "$DIR/$s-montage.png" "$DIR/$s-exact.npy" \
        "$DIR/$s-sum-error.png" "$DIR/$s-voxel-error.png" "$DIR/$s-dir64-error.png" \
        "$DIR/$s-tachyon256-error.png"
done
