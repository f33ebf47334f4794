/*
 * Independent f64 cross-check of sphere_bench's counts (no Embree).
 *
 * Same scene, camera, lights and shadow-ray rules as sphere_bench.c (see
 * README.md), traced in double precision with an analytic ray-sphere test and
 * a uniform grid.  Prints the same checksums and can write the same primID
 * image, so the two can be compared pixel by pixel.
 *
 *   exact_check [N] [--f32] [-o FILE]
 *     --f32   round centres and radius to f32 first, as Embree stores them
 *             (default: the f64 values straight from the generator)
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define IMG_W 1024
#define IMG_H 1024

static uint64_t splitmix_state = 1;

static uint64_t splitmix64(void)
{
    uint64_t z = (splitmix_state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static double uniform01(void) { return (double)(splitmix64() >> 11) * 0x1.0p-53; }

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* scene and grid */
static size_t n_spheres;
static double *centre, radius;
static int grid_n;              /* cells per axis */
static double grid_lo, cell;    /* grid covers [grid_lo, grid_lo + grid_n*cell]^3 */
static uint32_t *cell_start, *cell_items;

static int clamp_cell(int v) { return v < 0 ? 0 : v >= grid_n ? grid_n - 1 : v; }
static size_t cell_index(int x, int y, int z) { return ((size_t)z * grid_n + y) * grid_n + x; }

/* smallest t > 0 where the ray meets sphere k, or +inf */
static double hit_sphere(uint32_t k, const double o[3], const double d[3])
{
    double oc[3] = {o[0] - centre[3 * k], o[1] - centre[3 * k + 1], o[2] - centre[3 * k + 2]};
    double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    double c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - radius * radius;
    double h = b * b - c;
    if (h < 0) return INFINITY;
    h = sqrt(h);
    double t = -b - h;
    if (t > 0) return t;
    t = -b + h;
    return t > 0 ? t : INFINITY;
}

/* Nearest sphere hit with t < tmax (any hit if any_hit), or -1.  3D DDA. */
static long trace(const double o[3], const double d[3], double tmax, double *t_out, int any_hit)
{
    double hi = grid_lo + grid_n * cell, t0 = 0, t1 = tmax;
    for (int a = 0; a < 3; a++) {
        double inv = 1.0 / d[a], ta = (grid_lo - o[a]) * inv, tb = (hi - o[a]) * inv;
        if (ta > tb) { double s = ta; ta = tb; tb = s; }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    if (t0 > t1) return -1;
    int c[3], step[3];
    double t_next[3], t_delta[3];
    for (int a = 0; a < 3; a++) {
        c[a] = clamp_cell((int)floor((o[a] + t0 * d[a] - grid_lo) / cell));
        step[a] = d[a] > 0 ? 1 : -1;
        double boundary = grid_lo + (c[a] + (d[a] > 0)) * cell;
        t_next[a] = d[a] != 0 ? (boundary - o[a]) / d[a] : INFINITY;
        t_delta[a] = d[a] != 0 ? cell / fabs(d[a]) : INFINITY;
    }
    long best = -1;
    double best_t = tmax;
    for (;;) {
        size_t id = cell_index(c[0], c[1], c[2]);
        for (uint32_t q = cell_start[id]; q < cell_start[id + 1]; q++) {
            uint32_t k = cell_items[q];
            double t = hit_sphere(k, o, d);
            if (t < best_t || (t == best_t && (long)k < best)) {
                best_t = t;
                best = k;
                if (any_hit) { *t_out = best_t; return best; }
            }
        }
        int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
        if (best >= 0 && best_t <= t_next[a]) break; /* nearest hit lies inside this cell */
        if (t_next[a] > t1) break;
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= grid_n) break;
        t_next[a] += t_delta[a];
    }
    *t_out = best_t;
    return best;
}

int main(int argc, char **argv)
{
    size_t n = 1000000;
    int f32 = 0;
    const char *out = NULL;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--f32")) f32 = 1;
        else if (!strcmp(argv[a], "-o") && a + 1 < argc) out = argv[++a];
        else if (argv[a][0] >= '0' && argv[a][0] <= '9') n = (size_t)strtod(argv[a], NULL);
        else { fprintf(stderr, "usage: %s [N] [--f32] [-o FILE]\n", argv[0]); return 2; }
    }
    n_spheres = n;
    centre = malloc(n * 3 * sizeof(double));
    radius = 0.6 / cbrt((double)n);
    if (f32) radius = (float)radius;
    for (size_t i = 0; i < 3 * n; i++) {
        double v = 2.0 * uniform01() - 1.0;
        centre[i] = f32 ? (double)(float)v : v;
    }

    /* grid: each sphere goes into every cell its bounding box touches */
    double c0 = cpu_now();
    grid_n = (int)(cbrt((double)n) * 0.8);
    if (grid_n < 1) grid_n = 1;
    grid_lo = -1.0 - radius;
    cell = (2.0 + 2.0 * radius) / grid_n;
    size_t cells = (size_t)grid_n * grid_n * grid_n;
    cell_start = calloc(cells + 1, sizeof(uint32_t));
    uint32_t *fill = NULL;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            for (size_t i = 1; i <= cells; i++) cell_start[i] += cell_start[i - 1];
            cell_items = malloc(sizeof(uint32_t) * cell_start[cells]);
            fill = calloc(cells, sizeof(uint32_t));
        }
        for (size_t k = 0; k < n; k++) {
            int lo[3], hi[3];
            for (int a = 0; a < 3; a++) {
                lo[a] = clamp_cell((int)floor((centre[3 * k + a] - radius - grid_lo) / cell));
                hi[a] = clamp_cell((int)floor((centre[3 * k + a] + radius - grid_lo) / cell));
            }
            for (int z = lo[2]; z <= hi[2]; z++)
                for (int y = lo[1]; y <= hi[1]; y++)
                    for (int x = lo[0]; x <= hi[0]; x++) {
                        size_t id = cell_index(x, y, z);
                        if (pass == 0) cell_start[id + 1]++;
                        else cell_items[cell_start[id] + fill[id]++] = (uint32_t)k;
                    }
        }
    }
    free(fill);
    double c1 = cpu_now();

    uint32_t *img = malloc(sizeof(uint32_t) * IMG_W * IMG_H);
    const double tan_half = tan(0.785398 / 2.0), s3 = 1.0 / sqrt(3.0);
    uint64_t hits = 0, prim_sum = 0, unocc_point = 0, unocc_dir = 0;
    for (int j = 0; j < IMG_H; j++)
        for (int i = 0; i < IMG_W; i++) {
            double u = (i + 0.5) / IMG_W, v = (j + 0.5) / IMG_H;
            double d[3] = {(2 * u - 1) * tan_half, (1 - 2 * v) * tan_half, -1};
            double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; a++) d[a] /= l;
            double o[3] = {0, 0, 4}, t;
            long k = trace(o, d, INFINITY, &t, 0);
            img[(size_t)j * IMG_W + i] = k < 0 ? 0xFFFFFFFFu : (uint32_t)k;
            if (k < 0) continue;
            hits++;
            prim_sum += (uint64_t)k;
            double p[3], nrm[3], q[3];
            for (int a = 0; a < 3; a++) p[a] = o[a] + t * d[a];
            for (int a = 0; a < 3; a++) nrm[a] = p[a] - centre[3 * k + a];
            l = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
            for (int a = 0; a < 3; a++) q[a] = p[a] + 1e-4 * nrm[a] / l;
            double L[3] = {3 - q[0], 3 - q[1], 3 - q[2]};
            double dist = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
            for (int a = 0; a < 3; a++) L[a] /= dist;
            if (trace(q, L, dist, &t, 1) < 0) unocc_point++;
            double D[3] = {s3, s3, s3};
            if (trace(q, D, INFINITY, &t, 1) < 0) unocc_dir++;
        }
    double c2 = cpu_now();

    if (out) {
        FILE *f = fopen(out, "wb");
        if (!f) { perror(out); return 1; }
        for (size_t k = 0; k < (size_t)IMG_W * IMG_H; k++) {
            unsigned char b[4] = {img[k] & 0xFF, (img[k] >> 8) & 0xFF, (img[k] >> 16) & 0xFF, img[k] >> 24};
            fwrite(b, 1, 4, f);
        }
        fclose(f);
    }
    printf("n=%zu precision=%s cam_hits=%llu prim_sum=%llu unocc_point=%llu unocc_dir=%llu "
           "grid_cpu_s=%.3f rays_cpu_s=%.3f\n",
           n, f32 ? "f32-data" : "f64", (unsigned long long)hits, (unsigned long long)prim_sum,
           (unsigned long long)unocc_point, (unsigned long long)unocc_dir, c1 - c0, c2 - c1);
    return 0;
}
