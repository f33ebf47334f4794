/*
 * Embree 3 reference for gtsphere's sphere-tracing benchmark.
 *
 * Builds a BVH over N random spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT), traces
 * one primary ray per pixel of a 1024x1024 image with rtcIntersect1, then one
 * occlusion ray (rtcOccluded1) per camera hit to each of two lights, and
 * prints timings, rates, peak RSS and hit counts as one line of key=value
 * pairs.  See README.md beside this file for the exact scene definition.
 *
 * Not part of CI.  Build with ./build.sh, run the full matrix with ./run.sh.
 */
#define _GNU_SOURCE
#include <embree3/rtcore.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <pmmintrin.h>
#include <xmmintrin.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define IMG_W 1024
#define IMG_H 1024
#define FOV_Y 0.785398          /* radians, vertical (square image) */
#define SHADOW_EPS 1e-4f        /* offset of shadow-ray origin along the normal */

/* ---- scene generator (must match the Rust benchmark bit for bit) ---- */

static uint64_t splitmix_state = 1;

static uint64_t splitmix64(void)
{
    uint64_t z = (splitmix_state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static double uniform01(void)
{
    return (double)(splitmix64() >> 11) * 0x1.0p-53;
}

/* ---- timing ---- */

static double now_wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double now_cpu_thread(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double now_cpu_process(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void error_handler(void *user, enum RTCError code, const char *str)
{
    (void)user;
    fprintf(stderr, "embree error %d: %s\n", (int)code, str ? str : "");
    exit(1);
}

static RTCScene build_scene(RTCDevice dev, const float *spheres, size_t n,
                            enum RTCBuildQuality quality)
{
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float *vb = (float *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                 RTC_FORMAT_FLOAT4, 4 * sizeof(float), n);
    memcpy(vb, spheres, n * 4 * sizeof(float));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    return scene;
}

static void usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s [N] [-t BUILD_THREADS] [-q medium|high|low] [-p TRACE_THREADS] [-c CONFIG] [-o FILE]\n"
            "  N              number of spheres (default 1000000)\n"
            "  -t T           Embree device threads for the BVH build (\"threads=T\"), default 1\n"
            "  -q Q           build quality, default medium\n"
            "  -p P           threads for the ray loops (OpenMP), default 1 = per-core numbers\n"
            "  -c CONFIG      more rtcNewDevice config, e.g. \"verbose=2\" or \"isa=avx2\"\n"
            "  -o FILE        write the primID image: 1024*1024 little-endian u32, row 0 (top)\n"
            "                 first, 0xFFFFFFFF where the camera ray misses\n",
            argv0);
    exit(2);
}

/* Per-pixel result of the camera pass, consumed by the shadow pass. */
typedef struct {
    float p[3];   /* hit point org + t*dir */
    float n[3];   /* unit geometric normal */
    uint32_t prim;
    uint32_t hit;
} Hit;

int main(int argc, char **argv)
{
    size_t n = 1000000;
    int build_threads = 1, trace_threads = 1;
    enum RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
    const char *quality_name = "medium";
    const char *extra_cfg = NULL;
    const char *prim_out = NULL;

    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "-t") && a + 1 < argc) build_threads = atoi(argv[++a]);
        else if (!strcmp(argv[a], "-p") && a + 1 < argc) trace_threads = atoi(argv[++a]);
        else if (!strcmp(argv[a], "-c") && a + 1 < argc) extra_cfg = argv[++a];
        else if (!strcmp(argv[a], "-o") && a + 1 < argc) prim_out = argv[++a];
        else if (!strcmp(argv[a], "-q") && a + 1 < argc) {
            quality_name = argv[++a];
            if (!strcmp(quality_name, "medium")) quality = RTC_BUILD_QUALITY_MEDIUM;
            else if (!strcmp(quality_name, "high")) quality = RTC_BUILD_QUALITY_HIGH;
            else if (!strcmp(quality_name, "low")) quality = RTC_BUILD_QUALITY_LOW;
            else usage(argv[0]);
        } else if (argv[a][0] >= '0' && argv[a][0] <= '9') n = (size_t)strtod(argv[a], NULL);
        else usage(argv[0]);
    }
    if (n == 0 || build_threads < 1 || trace_threads < 1) usage(argv[0]);
#ifndef _OPENMP
    if (trace_threads != 1) {
        fprintf(stderr, "built without OpenMP: -p must be 1\n");
        return 2;
    }
#endif

    /* Scene: centres in f64 from SplitMix64, then rounded to f32. */
    const double radius_d = 0.6 / cbrt((double)n);
    const float radius = (float)radius_d;
    float *spheres = (float *)malloc(n * 4 * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        double ux = uniform01(), uy = uniform01(), uz = uniform01();
        spheres[4 * i + 0] = (float)(2.0 * ux - 1.0);
        spheres[4 * i + 1] = (float)(2.0 * uy - 1.0);
        spheres[4 * i + 2] = (float)(2.0 * uz - 1.0);
        spheres[4 * i + 3] = radius;
    }

    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    char cfg[256];
    snprintf(cfg, sizeof cfg, "threads=%d%s%s", build_threads, extra_cfg ? "," : "",
             extra_cfg ? extra_cfg : "");
    RTCDevice dev = rtcNewDevice(cfg);
    if (!dev) {
        fprintf(stderr, "rtcNewDevice failed: %d\n", (int)rtcGetDeviceError(NULL));
        return 1;
    }
    rtcSetDeviceErrorFunction(dev, error_handler, NULL);
    if (!rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED)) {
        fprintf(stderr, "this Embree was built without point/sphere geometry\n");
        return 1;
    }

    /* Warm-up: a tiny build so thread-pool start-up is not charged to the timed build. */
    {
        RTCScene warm = build_scene(dev, spheres, n < 1000 ? n : 1000, quality);
        rtcCommitScene(warm);
        rtcReleaseScene(warm);
    }

    RTCScene scene = build_scene(dev, spheres, n, quality);
    double w0 = now_wall(), c0 = now_cpu_process();
    rtcCommitScene(scene);
    double build_s = now_wall() - w0, build_cpu_s = now_cpu_process() - c0;
    free(spheres); /* Embree holds its own copy in the geometry buffer */
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const double rss_build_mib = ru.ru_maxrss / 1024.0; /* peak up to the end of the build */

    /* Camera. */
    const double tan_half = tan(FOV_Y / 2.0);
    const double aspect = (double)IMG_W / (double)IMG_H;
    const float cam[3] = {0.0f, 0.0f, 4.0f};

    Hit *hits = (Hit *)calloc((size_t)IMG_W * IMG_H, sizeof(Hit));
    uint64_t cam_hits = 0, prim_sum = 0;
    double cam_wall = 0, cam_cpu = 0;

#ifdef _OPENMP
    omp_set_num_threads(trace_threads);
#endif

    /* ---- camera rays ---- */
    w0 = now_wall();
#pragma omp parallel reduction(+ : cam_hits, prim_sum, cam_cpu)
    {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);         /* as Embree recommends */
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        double tc0 = now_cpu_thread();
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
#pragma omp for schedule(dynamic, 4)
        for (int j = 0; j < IMG_H; j++) {
            for (int i = 0; i < IMG_W; i++) {
                double u = (i + 0.5) / IMG_W, v = (j + 0.5) / IMG_H;
                double dx = (2.0 * u - 1.0) * tan_half * aspect;
                double dy = (1.0 - 2.0 * v) * tan_half;
                double dz = -1.0;
                double inv = 1.0 / sqrt(dx * dx + dy * dy + dz * dz);
                struct RTCRayHit rh;
                rh.ray.org_x = cam[0]; rh.ray.org_y = cam[1]; rh.ray.org_z = cam[2];
                rh.ray.dir_x = (float)(dx * inv);
                rh.ray.dir_y = (float)(dy * inv);
                rh.ray.dir_z = (float)(dz * inv);
                rh.ray.tnear = 0.0f;
                rh.ray.tfar = INFINITY;
                rh.ray.time = 0.0f;
                rh.ray.mask = 0xFFFFFFFFu;
                rh.ray.id = 0;
                rh.ray.flags = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &ctx, &rh);
                if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
                    Hit *h = &hits[(size_t)j * IMG_W + i];
                    float t = rh.ray.tfar;
                    h->p[0] = rh.ray.org_x + t * rh.ray.dir_x;
                    h->p[1] = rh.ray.org_y + t * rh.ray.dir_y;
                    h->p[2] = rh.ray.org_z + t * rh.ray.dir_z;
                    float nl = 1.0f / sqrtf(rh.hit.Ng_x * rh.hit.Ng_x + rh.hit.Ng_y * rh.hit.Ng_y +
                                            rh.hit.Ng_z * rh.hit.Ng_z);
                    h->n[0] = rh.hit.Ng_x * nl;
                    h->n[1] = rh.hit.Ng_y * nl;
                    h->n[2] = rh.hit.Ng_z * nl;
                    h->prim = rh.hit.primID;
                    h->hit = 1;
                    cam_hits++;
                    prim_sum += rh.hit.primID;
                }
            }
        }
        cam_cpu += now_cpu_thread() - tc0;
    }
    cam_wall = now_wall() - w0;

    /* ---- shadow rays: one to each light per camera hit ---- */
    const float lp[3] = {3.0f, 3.0f, 3.0f};             /* point light position */
    const float ld = (float)(1.0 / sqrt(3.0));          /* toward the directional light */
    uint64_t unocc_point = 0, unocc_dir = 0, backfacing_point = 0, backfacing_dir = 0;
    double sh_cpu = 0;
    w0 = now_wall();
#pragma omp parallel reduction(+ : unocc_point, unocc_dir, backfacing_point, backfacing_dir, sh_cpu)
    {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);         /* as Embree recommends */
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        double tc0 = now_cpu_thread();
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
#pragma omp for schedule(dynamic, 4)
        for (int j = 0; j < IMG_H; j++) {
            for (int i = 0; i < IMG_W; i++) {
                const Hit *h = &hits[(size_t)j * IMG_W + i];
                if (!h->hit) continue;
                float o[3] = {h->p[0] + SHADOW_EPS * h->n[0], h->p[1] + SHADOW_EPS * h->n[1],
                              h->p[2] + SHADOW_EPS * h->n[2]};
                struct RTCRay r;
                /* point light at (3,3,3), segment up to the light */
                float lx = lp[0] - o[0], ly = lp[1] - o[1], lz = lp[2] - o[2];
                float dist = sqrtf(lx * lx + ly * ly + lz * lz);
                float id = 1.0f / dist;
                r.org_x = o[0]; r.org_y = o[1]; r.org_z = o[2];
                r.dir_x = lx * id; r.dir_y = ly * id; r.dir_z = lz * id;
                r.tnear = 0.0f; r.tfar = dist;
                r.time = 0.0f; r.mask = 0xFFFFFFFFu; r.id = 0; r.flags = 0;
                if (r.dir_x * h->n[0] + r.dir_y * h->n[1] + r.dir_z * h->n[2] <= 0.0f)
                    backfacing_point++;
                rtcOccluded1(scene, &ctx, &r);
                if (r.tfar >= 0.0f) unocc_point++; /* tfar = -inf when occluded */
                /* directional light along (-1,-1,-1): shadow ray toward +(1,1,1)/sqrt3 */
                r.org_x = o[0]; r.org_y = o[1]; r.org_z = o[2];
                r.dir_x = ld; r.dir_y = ld; r.dir_z = ld;
                r.tnear = 0.0f; r.tfar = INFINITY;
                r.time = 0.0f; r.mask = 0xFFFFFFFFu; r.id = 0; r.flags = 0;
                if (ld * (h->n[0] + h->n[1] + h->n[2]) <= 0.0f) backfacing_dir++;
                rtcOccluded1(scene, &ctx, &r);
                if (r.tfar >= 0.0f) unocc_dir++;
            }
        }
        sh_cpu += now_cpu_thread() - tc0;
    }
    double sh_wall = now_wall() - w0;

    const uint64_t cam_rays = (uint64_t)IMG_W * IMG_H;
    const uint64_t sh_rays = 2 * cam_hits;
    /* per-core rates: rays / (wall time * threads used by the loop) */
    const double p = (double)trace_threads;
    getrusage(RUSAGE_SELF, &ru);

    printf("embree=%s n=%zu radius=%.9g quality=%s build_threads=%d trace_threads=%d "
           "build_s=%.6f build_cpu_s=%.6f "
           "cam_rays=%llu cam_s=%.6f cam_cpu_s=%.6f cam_rps_core=%.0f "
           "shadow_rays=%llu shadow_s=%.6f shadow_cpu_s=%.6f shadow_rps_core=%.0f "
           "total_rps_core=%.0f total_rps=%.0f "
           "cam_rps_cpu=%.0f shadow_rps_cpu=%.0f total_rps_cpu=%.0f "
           "hit_fraction=%.6f cam_hits=%llu prim_sum=%llu "
           "unocc_point=%llu unocc_dir=%llu backfacing_point=%llu backfacing_dir=%llu "
           "peak_rss_build_mib=%.1f peak_rss_mib=%.1f\n",
           RTC_VERSION_STRING, n, (double)radius, quality_name, build_threads, trace_threads,
           build_s, build_cpu_s,
           (unsigned long long)cam_rays, cam_wall, cam_cpu, cam_rays / (cam_wall * p),
           (unsigned long long)sh_rays, sh_wall, sh_cpu, sh_rays / (sh_wall * p),
           (cam_rays + sh_rays) / ((cam_wall + sh_wall) * p),
           (cam_rays + sh_rays) / (cam_wall + sh_wall),
           cam_rays / cam_cpu, sh_rays / sh_cpu, (cam_rays + sh_rays) / (cam_cpu + sh_cpu),
           (double)cam_hits / cam_rays, (unsigned long long)cam_hits,
           (unsigned long long)prim_sum, (unsigned long long)unocc_point,
           (unsigned long long)unocc_dir, (unsigned long long)backfacing_point,
           (unsigned long long)backfacing_dir, rss_build_mib, ru.ru_maxrss / 1024.0);

    if (prim_out) {
        FILE *f = fopen(prim_out, "wb");
        if (!f) { perror(prim_out); return 1; }
        for (size_t k = 0; k < (size_t)IMG_W * IMG_H; k++) {
            uint32_t id = hits[k].hit ? hits[k].prim : 0xFFFFFFFFu;
            unsigned char b[4] = {id & 0xFF, (id >> 8) & 0xFF, (id >> 16) & 0xFF, id >> 24};
            fwrite(b, 1, 4, f);
        }
        fclose(f);
    }

    free(hits);
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    return 0;
}
