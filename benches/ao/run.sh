#!/bin/sh
# docs/evaluation.md's tables: each AO method and Tachyon's AO against gtsphere's exact AO.
#   usage: benches/ao/run.sh [SCENE...]     (pymol, random, fcc; default all three)
#   environment: DIR (default /tmp/gtsphere-ao-eval), GTSPHERE (default target/release/gtsphere),
#                TACHYON (default tachyon), SIZE (default 384), REACH (default 4),
#                INF_SIZE (default 192)
# Two parts per scene. At reach REACH, SIZE x SIZE: every method and Tachyon against exact AO
# at that reach. At any distance (no --ao-reach), INF_SIZE x INF_SIZE, as exact AO at any
# distance costs far more per pixel: Tachyon (which has no AO distance) at 4 to 1024 samples
# and gtsphere's mc at 16, 256 and 1024 rays, both rendered again at INF_SIZE, against exact AO
# at any distance (rows "inf ...").
# Prints one line per method: scene, method, seconds (wall, one run), RMSE and largest error
# against exact, the mean of (method - exact) over the pixels where either is nonzero, and the
# correlation of that error between horizontal neighbours (0 for independent noise); heat maps
# (error scale 0 to 0.5) go to $DIR.
set -eu
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
DIR=${DIR:-/tmp/gtsphere-ao-eval}
GTS=${GTSPHERE:-$ROOT/target/release/gtsphere}
TACHYON=${TACHYON:-tachyon}
SIZE=${SIZE:-384}
REACH=${REACH:-4}
INF_SIZE=${INF_SIZE:-192}
mkdir -p "$DIR"

secs() { python3 -c "import time; print('%.2f' % time.time())"; }

since() { python3 -c "print('%.2f' % ($(secs) - $1))"; }

compare() {  # scene method seconds image [reference, default exact]
    ref=$DIR/$1-${5:-exact}.npy
    line=$("$GTS" compare "$4" "$ref" --heatmap "$DIR/$1-$2-error.png" --heatmap-max 0.5)
    mean=$(python3 -c "
import numpy as np
a, b = (np.load(f).astype(float) for f in ('$4', '$ref'))
a, b = (x if x.ndim == 2 else x[..., 0] for x in (a, b))
a, b = np.nan_to_num(a), np.nan_to_num(b)
m = (a != 0) | (b != 0)
e, p = a - b, m[:, 1:] & m[:, :-1]
c = np.corrcoef(e[:, 1:][p], e[:, :-1][p])[0, 1]
print('mean difference %+.4f over %d pixels, neighbour correlation %.2f'
      % (e[m].mean(), m.sum(), c))")
    echo "$1 | $2 | $3 | $(echo "$line" | tr '\n' ' ') $mean"
}

render() {  # scene name options...: at $SIZE, reach $REACH; prints the seconds
    s=$1; n=$2; shift 2
    t0=$(secs)
    "$GTS" render "$DIR/$s.wrl" --viewpoint eval --integrator ao --ao-reach "$REACH" \
        --width "$SIZE" --height "$SIZE" --sampler center -o "$DIR/$s-$n.npy" -q "$@"
    since "$t0"
}

renderinf() {  # scene name options...: at $INF_SIZE, any distance; prints the seconds
    s=$1; n=$2; shift 2
    t0=$(secs)
    "$GTS" render "$DIR/$s-inf.wrl" --viewpoint eval --integrator ao \
        --width "$INF_SIZE" --height "$INF_SIZE" --sampler center -o "$DIR/$s-inf-$n.npy" -q "$@"
    since "$t0"
}

run_tachyon() {  # scene samples: $DIR/$1.dat to $DIR/$1-tachyon$2.npy; prints the seconds
    t0=$(secs)
    "$TACHYON" "$DIR/$1.dat" -add_skylight 1 -skylight_samples "$2" -format PPM48 \
        -o "$DIR/$1-tachyon$2.ppm" > /dev/null
    t=$(since "$t0")
    python3 "$ROOT/benches/ao/ppm48.py" "$DIR/$1-tachyon$2.ppm" "$DIR/$1-tachyon$2.npy"
    echo "$t"
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
    for n in 4 16 64 256; do
        t=$(run_tachyon "$s" "$n"); compare "$s" "tachyon$n" "$t" "$DIR/$s-tachyon$n.npy"
    done

    # any distance, at $INF_SIZE: Tachyon has no AO distance, so this is its like-for-like row
    python3 "$ROOT/benches/ao/scenes.py" "$s" "$DIR/$s-inf.wrl" "$DIR/$s-inf.dat" \
        --size "$INF_SIZE"
    t=$(renderinf "$s" exact); echo "$s | inf exact ($INF_SIZE) | $t |"
    for n in 16 256 1024; do
        t=$(renderinf "$s" "mc$n" --ao-method mc --ao-samples "$n")
        compare "$s" "inf-mc$n" "$t" "$DIR/$s-inf-mc$n.npy" inf-exact
    done
    for n in 4 16 64 256 1024; do
        t=$(run_tachyon "$s-inf" "$n")
        compare "$s" "inf-tachyon$n" "$t" "$DIR/$s-inf-tachyon$n.npy" inf-exact
    done
done

# the page's pictures: exact AO, then the heat maps of sum, voxel, directions 64, Tachyon 256
for s in ${*:-pymol random fcc}; do
    python3 "$ROOT/benches/ao/montage.py" "$DIR/$s-montage.png" "$DIR/$s-exact.npy" \
        "$DIR/$s-sum-error.png" "$DIR/$s-voxel-error.png" "$DIR/$s-dir64-error.png" \
        "$DIR/$s-tachyon256-error.png"
done
