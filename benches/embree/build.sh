#!/bin/sh
# Build the Embree 3 reference benchmark against Debian's system Embree.
# Needs: apt-get install -y libembree-dev   (Debian 12: Embree 3.13.5)
# Not part of CI.
set -eu
cd "$(dirname "$0")"
set -x
gcc -O3 -fopenmp -Wall -Wextra -o sphere_bench sphere_bench.c -lembree3 -lm
gcc -O2 -Wall -Wextra -o exact_check exact_check.c -lm
