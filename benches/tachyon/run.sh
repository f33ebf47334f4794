#!/bin/sh
# gtsphere against Tachyon on `bench trace`'s scene (N random opaque spheres, two lights):
# gen.py writes the scene as VRML and as Tachyon's .dat (once per N, kept in DIR), then the
# two whole commands run in turn ROUNDS times, each timed by the wall clock:
#   gtsphere render DIR/spheres-N.wrl --width S --height S --spp 1 --threads 1 -o DIR/gtsphere.png --stats
#   tachyon DIR/spheres-N-S.dat -numthreads 1 -format PNG -o DIR/tachyon.png
# and the medians are printed as one table, with each program's own split of its time.
# (--stats only prints: the counters and timers run either way.)
#   usage: ./run.sh [N] [ROUNDS]        N default 1000000 (1e6 is accepted), ROUNDS default 5
#   environment: DIR (default /tmp/gtsphere-tachyon), SIZE (image side, default 512),
#                FORM (proto: `gtsphere convert`'s PROTO Particle lines, the default; plain:
#                Transform/Shape/Sphere nodes), GTSPHERE (default ../../target/release/gtsphere,
#                built if missing), TACHYON (default tachyon)
set -eu
cd "$(dirname "$0")"
N=$(python3 -c "print(int(float('${1:-1000000}')))")
ROUNDS=${2:-5}
SIZE=${SIZE:-512}
. ./files.sh
RAW=$DIR/times-$N-$FORM-$(date +%Y%m%d-%H%M%S).txt
: > "$RAW"
echo "raw times in $RAW; $("$GTS" --version); Tachyon $("$TACHYON" -version 2>&1 | head -1) ($(dpkg-query -W -f '${Version}' tachyon-bin-nox 2>/dev/null || echo '?'))" >&2

now() { date +%s.%N; }
# $1 - $2 with 3 decimals
minus() { awk "BEGIN {printf \"%.3f\", $1 - $2}"; }
# "KEY VALUE" for the value after label $3 in file $2 (gtsphere's --stats lines, Tachyon's
# timing lines), or "KEY -"
field() {
    v=$(sed -n "s/^ *$3 *:* *\([0-9.]*\).*/\1/p" "$2" | head -1)
    echo "$1 ${v:--}"
}
# Peak resident memory (MB) and CPU time (user + system s) of the last command, as
# "${1}_mb X ${1}_cpu Y", when GNU time is there. On a shared machine the CPU time is the
# steadier number.
TIME=
[ -x /usr/bin/time ] && TIME="/usr/bin/time -f %M_%U_%S -o $DIR/usage"
usage() {
    if [ -n "$TIME" ]; then
        tr '_' ' ' < "$DIR/usage" |
            awk -v p="$1" '{printf "%s_mb %.0f %s_cpu %.2f", p, $1 * 1024 / 1e6, p, $2 + $3}'
    else
        echo "${1}_mb - ${1}_cpu -"
    fi
}
# median of key $1 in the raw file (lower median for an even count)
median() {
    awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}' "$RAW" | sort -g |
        awk '{v[NR] = $0} END {print v[int((NR + 1) / 2)]}'
}

L=$DIR/gtsphere.log
T=$DIR/tachyon.log
r=1
while [ "$r" -le "$ROUNDS" ]; do
    load=$(cut -d' ' -f1 /proc/loadavg)
    t0=$(now)
    $TIME "$GTS" render "$WRL" --width "$SIZE" --height "$SIZE" --spp 1 --threads 1 \
        -o "$DIR/gtsphere.png" --stats > "$L" 2>&1
    t1=$(now)
    g_use=$(usage g)
    $TIME "$TACHYON" "$DAT" -numthreads 1 -format PNG -o "$DIR/tachyon.png" > "$T" 2>&1
    t2=$(now)
    t_use=$(usage t)
    g=$(minus "$t1" "$t0")
    t=$(minus "$t2" "$t1")
    line="round $r load1 $load gtsphere $g $g_use tachyon $t $t_use ratio $(awk "BEGIN {printf \"%.2f\", $t / $g}")"
    line="$line $(field g_load "$L" 'load seconds') $(field g_prepare "$L" 'prepare seconds')"
    line="$line $(field g_grids "$L" 'light grids seconds') $(field g_render "$L" 'render seconds')"
    line="$line $(field t_parse "$T" 'Scene Parsing Time') $(field t_prep "$T" 'Preprocessing Time')"
    line="$line $(field t_trace "$T" 'Ray Tracing Time') $(field t_io "$T" 'Image I\/O Time')"
    echo "$line" >> "$RAW"
    echo "$line" >&2
    r=$((r + 1))
done

mb() { awk "BEGIN {printf \"%.1f\", $(stat -c %s "$1") / 1e6}"; }
G=$(median gtsphere)
T=$(median tachyon)
RATIOS=$(awk '{for (i = 1; i < NF; i++) if ($i == "ratio") print $(i + 1)}' "$RAW" | sort -g | tr '\n' ' ')
echo "| N | VRML ($FORM) / .dat MB | gtsphere s | tachyon s | tachyon / gtsphere | CPU s gtsphere / tachyon | gtsphere load / prepare / light grids / render s | tachyon parse / preprocess / trace / image s | peak MB gtsphere / tachyon |"
echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '| %s | %s / %s | %.3f | %.3f | %.2f | %s / %s | %s / %s / %s / %s | %s / %s / %s / %s | %s / %s |\n' \
    "$N" "$(mb "$WRL")" "$(mb "$DAT")" "$G" "$T" "$(awk "BEGIN {print $T / $G}")" \
    "$(median g_cpu)" "$(median t_cpu)" \
    "$(median g_load)" "$(median g_prepare)" "$(median g_grids)" "$(median g_render)" \
    "$(median t_parse)" "$(median t_prep)" "$(median t_trace)" "$(median t_io)" \
    "$(median g_mb)" "$(median t_mb)"
echo "medians of $ROUNDS alternating rounds ($SIZE x $SIZE, 1 spp, 1 thread each, whole commands, wall clock); per-round ratios: $RATIOS" >&2
