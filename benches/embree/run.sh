#!/bin/sh
# Run the Embree reference matrix REPS times (default 5), round-robin over the
# configurations so that load from other users is spread evenly, and print the
# median of every number per configuration.  Raw lines go to results/raw-*.txt.
#   usage: ./run.sh [N] [REPS]
set -eu
cd "$(dirname "$0")"
N=${1:-1000000}
REPS=${2:-5}
[ -x ./sphere_bench ] || ./build.sh
mkdir -p results
RAW=results/raw-$(date +%Y%m%d-%H%M%S)-n$N.txt
: > "$RAW"

# label | arguments
CONFIGS="medium-b1-p1|-q medium -t 1 -p 1
medium-b2-p1|-q medium -t 2 -p 1
high-b1-p1|-q high -t 1 -p 1
high-b2-p1|-q high -t 2 -p 1
medium-b2-p2|-q medium -t 2 -p 2"

r=1
while [ "$r" -le "$REPS" ]; do
    echo "$CONFIGS" | while IFS='|' read -r label args; do
        # shellcheck disable=SC2086
        line=$(./sphere_bench "$N" $args)
        echo "config=$label rep=$r load1=$(cut -d" " -f1 /proc/loadavg) $line" >> "$RAW"
        echo "rep $r $label: $(echo "$line" | tr ' ' '\n' | grep -E '^(build_s|cam_rps_core|shadow_rps_core|total_rps_core)=' | tr '\n' ' ')" >&2
    done
    r=$((r + 1))
done

# median of key $2 for config $1 (lower median when the count is even)
median() {
    grep "^config=$1 " "$RAW" | tr ' ' '\n' | sed -n "s/^$2=//p" | sort -g |
        awk '{v[NR]=$0} END {print v[int((NR+1)/2)]}'
}

echo "raw: $RAW"
echo "medians of $REPS runs, N=$N (rates in rays/s; *_core = per thread of the ray loop, wall clock; *_cpu = per CPU-second)"
KEYS="build_s build_cpu_s cam_rps_core shadow_rps_core total_rps_core total_rps cam_rps_cpu shadow_rps_cpu total_rps_cpu peak_rss_build_mib peak_rss_mib hit_fraction cam_hits prim_sum unocc_point unocc_dir backfacing_point backfacing_dir"
echo "$CONFIGS" | while IFS='|' read -r label args; do
    out="$label:"
    for k in $KEYS; do out="$out $k=$(median "$label" "$k")"; done
    echo "$out"
done
