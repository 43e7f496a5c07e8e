/* rangecast bench: scans per second and range accuracy on one map, as ONE JSON
 * line on stdout. Scripts parse that line: keep its keys and the flags stable
 * (add, never rename or remove). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "baked_file.h"
#include "mesh_load.h"
#include "ouster_json.h"
#include "poses.h"
#include "reference.h"
#include "tool.h"
#if defined(RANGECAST_TOOL_WITH_EMBREE)
#include "embree_single.h"
#endif
#include "util.h"

#define BENCH_SPHERE_RADIUS 20.0f  /* the standard workload (see ANCHORS.md) */
#define BENCH_POSE_RADIUS   10.0f
#define BENCH_TIMED_BYTES   ((size_t)128 << 20) /* ranges buffer of the timed loop ... */
#define BENCH_TIMED_POSES   1000u                 /* ... and poses per rc_simulate call (default) */
#define BENCH_CHECK_BYTES   ((size_t)64 << 20)  /* buffers of the accuracy pass */
/* --sensor random-ondn: incoherent OnDn rays, as many as a VLP-16 scan, with
 * origins in a ball about the sensor and VLP-16 ranges; a fixed layout (its
 * own seed), placed by each pose like any sensor */
#define BENCH_ONDN_RAYS     14400u
#define BENCH_ONDN_RADIUS   5.0f
#define BENCH_ONDN_SEED     7u
#define BENCH_ONDN_RANGE_MIN 0.5f
#define BENCH_ONDN_RANGE_MAX 130.0f

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast bench [--map FILE] [--poses FILE] [options]\n"
        "\n"
        "Times rc_simulate on a map and checks its ranges; prints ONE JSON line.\n"
        "Without --map: the standard workload, a closed UV sphere of radius 20 m;\n"
        "without --poses: random poses uniform in a ball of radius 10 m (about the\n"
        "origin, or the centre of --map's bounds) with uniformly random orientations.\n"
        "\n"
        "Options:\n"
        "  --map FILE         mesh map (.ply, a baked .rcmap, or any Assimp format)\n"
        "  --poses FILE       raw poses: float32 LE x y z qx qy qz qw per pose, or a TUM\n"
        "                     trajectory (.tum/.txt: lines 'timestamp x y z qx qy qz qw')\n"
        "  --sensor NAME      vlp16 (default), vlp16-360, os1-64, d435, livox-mid40,\n"
        "                     ust-10lx, lds-01 (2-D scanners);\n"
        "                     random-ondn: 14,400 incoherent OnDn rays (origins in a 5 m ball,\n"
        "                     random directions, fixed layout), the ray order for --ranges-out\n"        "                     ouster:FILE.json: an Ouster unit from its metadata (rc_ouster_rays;\n"
        "                     each ray from its beam origin, 0.3 .. 120 m)\n"
        "  --backend B        auto (default), bvh, embree, vulkan; embree-single: a plain rtcIntersect1 loop\n"
        "  --device NAME      vulkan: device index or name substring (default: first GPU, else any)\n"
        "  --vulkan-traversal T  vulkan: compute (default: the kernel's own BVH walk) or ray-query\n"
        "                     (VK_KHR_ray_query on the driver's structures, RC_CONTEXT_VULKAN_RAY_QUERY)\n"
        "  --results-on-device  vulkan: the timed calls keep their ranges on the GPU\n"
        "                     (RC_RESULTS_ON_DEVICE), so the download is not timed\n"
        "  --build-quality Q  balanced (default), fast, high, compact: rc_scene_desc.build_quality\n"
        "                     (Embree's build; the built-in backend has one build)\n"
        "  --mesh M           reference (default): the map's arrays used in place; copy: copied\n"
        "                     into the arena (RC_MESH_COPY; bytes_per_triangle then counts the copy)\n"
        "  --meshes N         the map cut into N meshes of consecutive triangles, each a geometry\n"
        "                     with its own vertices, as a world of separate objects (default 1)\n"
        "  --threads N        worker threads, 0 = all CPUs (default)\n"
        "  --repeat K         timed repeats of the whole pose set; the median counts (default 3)\n"
        "  --triangles N      sphere size without --map: 1k, 10k, 100k, 1M (default), 10M, ...\n"
        "  --pose-count N     random poses without --poses (default 1000)\n"
        "  --poses-per-call N poses an rc_simulate call of the timed loop takes (default 1000;\n"
        "                     1 measures a robot's one-scan call, its latency 1 / scans_per_s)\n"
        "  --seed S           seed of the random poses (default 1)\n"
        "  --ranges-out FILE  write the ranges: float32 [pose][row][column], +inf no return\n"
        "  -h, --help         this text\n"
        "\n"
        "JSON keys: backend threads sensor map triangles vertices poses rays_per_scan repeat\n"
        "build_s scans_per_s rays_per_s repeat_s peak_rss_bytes arena_bytes scene_bytes\n"
        "bytes_per_triangle backend_bytes device_bytes total_bytes_per_triangle hit_fraction\n"
        "range_err_mean_m range_err_p999_m range_err_max_m hit_mismatch ranges_consistent\n"
        "build_quality baked_map_bytes vulkan_traversal poses_per_call results_on_device mesh\n"
        "meshes.\n"
        "bytes_per_triangle: the committed scene's arena bytes (rc_scene_get_info) per\n"
        "triangle; total_bytes_per_triangle adds what Embree/Vulkan hold outside the arena.\n"
        "A baked map (.rcmap, rangecast bake) is loaded in place: build_s is then the load\n"
        "(rc_scene_load_baked), and the mesh and tree it holds are baked_map_bytes (null\n"
        "for other maps), outside the arena.\n"
        "Timing: all poses, up to --poses-per-call a call (without that option, fewer\n"
        "when 128 MiB of ranges would not hold 1000), ranges only, after a warm-up of\n"
        "8 scans.\n"
        "Accuracy (untimed): each hit's range against the float64 distance from the\n"
        "pose's sensor origin along the float64 ray to the hit triangle's plane.\n"
        "hit_mismatch (sphere only, else null): rays the closed sphere must return\n"
        "within [range_min, range_max] that come back without a hit, or vice versa.\n"
        "peak_rss_bytes is taken after the timed loop, before the accuracy pass.\n");
}

/* The map's triangle that a hit on geometry geom, triangle prim names
 * (UINT64_MAX for none): with --meshes, part geom's triangles start at
 * rcu_mesh_part_first. */
static uint64_t mesh_triangle(const rcu_mesh *mesh, uint32_t geom, uint32_t prim)
{
    uint32_t first;
    if (rcp_mesh_parts <= 1) return rcp_mesh_triangle(mesh, geom, prim);
    if (geom >= rcp_mesh_parts) return UINT64_MAX;
    first = rcu_mesh_part_first(mesh->triangle_count, rcp_mesh_parts, geom);
    if (prim >= rcu_mesh_part_first(mesh->triangle_count, rcp_mesh_parts, geom + 1u) - first) return UINT64_MAX;
    return (uint64_t)first + prim;
}

/* JSON string (the map path) with the few escapes it can need. */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

/* A number, or null when it is not finite. */
static void json_number(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.9g", v);
    else fprintf(f, "null");
}

static void swap_float(float *a, float *b)
{
    float t = *a;
    *a = *b;
    *b = t;
}

/* k-th smallest of v[0..n) (v is reordered): quickselect with a three-way
 * partition, so runs of equal errors (many are exactly 0) cost nothing. */
static float select_kth(float *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        float a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi - 1];
        float pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            if (v[i] < pivot) swap_float(&v[lt++], &v[i++]);
            else if (v[i] > pivot) swap_float(&v[i], &v[--gt]);
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return pivot;
    }
    return v[lo];
}

typedef struct accuracy {
    uint64_t rays, hits, mismatch, bad_prims, inconsistent, differing;
    double err_sum, err_max, err_p999;
    float *errs;
    size_t nerr, cap;
} accuracy;

static int push_err(accuracy *a, float e)
{
    if (a->nerr == a->cap) {
        size_t cap = a->cap ? a->cap * 2 : (size_t)1 << 20;
        float *p = (float *)realloc(a->errs, cap * sizeof(float));
        if (!p) return -1;
        a->errs = p;
        a->cap = cap;
    }
    a->errs[a->nerr++] = e;
    return 0;
}

/* Inscribed radius of a closed convex mesh about the origin: the smallest
 * distance from the origin to a triangle's plane. */
static double inscribed_radius(const rcu_mesh *m)
{
    double best = INFINITY;
    uint32_t t;
    static const double origin[3] = {0, 0, 0};
    for (t = 0; t < m->triangle_count; t++) {
        const float *v0 = m->vertices + 3u * (size_t)m->indices[3u * t];
        const float *v1 = m->vertices + 3u * (size_t)m->indices[3u * t + 1];
        const float *v2 = m->vertices + 3u * (size_t)m->indices[3u * t + 2];
        double e1[3], e2[3], n[3], len, d;
        int k;
        for (k = 0; k < 3; k++) {
            e1[k] = (double)v1[k] - v0[k];
            e2[k] = (double)v2[k] - v0[k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len == 0.0) continue;
        d = fabs(n[0] * ((double)v0[0] - origin[0]) + n[1] * ((double)v0[1] - origin[1]) +
                 n[2] * ((double)v0[2] - origin[2])) / len;
        if (d < best) best = d;
    }
    return best;
}

typedef struct bench_args {
    const char *map, *poses_path, *ranges_out;
    uint32_t preset, backend, threads, repeat, pose_count;
    uint32_t poses_per_call; /* most poses an rc_simulate call of the timed loop takes */
    int set_poses_per_call;
    int on_device; /* --results-on-device: the timed calls keep results on the GPU */
    uint64_t triangles, seed;
    const char *sensor_name;
    int set_triangles, set_pose_count, set_seed;
    int embree_single; /* --backend embree-single: the hand-written rtcIntersect1 loop */
    int ondn;          /* --sensor random-ondn or ouster:FILE: an OnDn sensor of the bench's rays */
    const char *ouster_path; /* --sensor ouster:FILE */
} bench_args;

/* The rays of --sensor random-ondn (sensor frame); 0 or -1 (out of memory). */
static int random_rays(rcp_rays *r)
{
    memset(r, 0, sizeof *r);
    r->origins = (float *)malloc(sizeof(float) * 3u * BENCH_ONDN_RAYS);
    r->dirs = (float *)malloc(sizeof(float) * 3u * BENCH_ONDN_RAYS);
    if (!r->origins || !r->dirs) {
        rcp_rays_free(r);
        return -1;
    }
    rcu_rays_random(BENCH_ONDN_RAYS, BENCH_ONDN_RADIUS, BENCH_ONDN_SEED, r->origins, r->dirs);
    r->count = r->width = BENCH_ONDN_RAYS;
    r->height = 1;
    r->range_min = BENCH_ONDN_RANGE_MIN;
    r->range_max = BENCH_ONDN_RANGE_MAX;
    return 0;
}

/* The float64 reference rays of the bench's sensor. */
static int bench_reference(const bench_args *a, const rcp_rays *ondn, rcu_preset_rays *ref)
{
    if (a->ondn) return rcu_rays_f64(ondn->origins, ondn->dirs, ondn->count, ondn->range_min, ondn->range_max, ref);
    return rcu_preset_rays_f64(a->preset, ref);
}

static int parse_args(int argc, char **argv, bench_args *a)
{
    const char *cmd = "bench";
    int i, r;
    rcp_order_room = 1; /* calls of many scans: room for ordered runs */
    memset(a, 0, sizeof *a);
    a->sensor_name = "vlp16";
    a->backend = RC_BACKEND_AUTO;
    a->repeat = 3;
    a->pose_count = 1000;
    a->poses_per_call = BENCH_TIMED_POSES;
    a->triangles = 1000000;
    a->seed = 1;
    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            exit(RCP_EXIT_OK);
        }
#define OPT(name) ((r = rcp_opt(argc, argv, &i, name, &v)) != 0)
        if (OPT("--map")) { if (r < 0) return -1; a->map = v; }
        else if (OPT("--poses")) { if (r < 0) return -1; a->poses_path = v; }
        else if (OPT("--ranges-out")) { if (r < 0) return -1; a->ranges_out = v; }
        else if (OPT("--sensor")) {
            if (r < 0) return -1;
            a->ouster_path = NULL;
            a->ondn = 0;
            if (strcmp(v, "random-ondn") == 0) {
                a->ondn = 1;
            } else if (strncmp(v, RCP_OUSTER_PREFIX, strlen(RCP_OUSTER_PREFIX)) == 0) {
                a->ondn = 1;
                a->ouster_path = v + strlen(RCP_OUSTER_PREFIX);
            } else if (rcp_parse_sensor(cmd, v, &a->preset) != 0) {
                fprintf(stderr, "rangecast bench: (bench also takes random-ondn: incoherent OnDn rays, and "
                                "ouster:FILE.json)\n");
                return -1;
            }
            a->sensor_name = v;
        } else if (OPT("--backend")) {
            if (r < 0) return -1;
            if (strcmp(v, "embree-single") == 0) {
#if defined(RANGECAST_TOOL_WITH_EMBREE)
                a->embree_single = 1;
                a->backend = RC_BACKEND_EMBREE;
#else
                return rcp_usage_error(cmd, "--backend embree-single needs the program built with Embree"), -1;
#endif
            } else if (rcp_parse_backend(cmd, v, &a->backend) != 0) {
                return -1;
            }
        } else if (OPT("--device")) {
            if (r < 0) return -1;
            rcp_device = v;
        } else if (OPT("--vulkan-traversal")) {
            if (r < 0) return -1;
            if (strcmp(v, "compute") == 0)
                rcp_context_flags &= ~RC_CONTEXT_VULKAN_RAY_QUERY;
            else if (strcmp(v, "ray-query") == 0)
                rcp_context_flags |= RC_CONTEXT_VULKAN_RAY_QUERY;
            else
                return rcp_usage_error(cmd, "--vulkan-traversal: expected compute or ray-query, got '%s'", v), -1;
        } else if (strcmp(argv[i], "--results-on-device") == 0) {
            a->on_device = 1;
        } else if (OPT("--mesh")) {
            if (r < 0 || rcp_parse_mesh_mode(cmd, v) != 0) return -1;
        } else if (OPT("--meshes")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &rcp_mesh_parts) != 0 || rcp_mesh_parts == 0)
                return rcp_usage_error(cmd, "--meshes: expected a count >= 1, got '%s'", v), -1;
        } else if (OPT("--build-quality")) {
            if (r < 0) return -1;
            if (rcp_parse_build_quality(cmd, v, &rcp_build_quality) != 0) return -1;
        } else if (OPT("--threads")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->threads) != 0 || a->threads > RC_MAX_THREADS)
                return rcp_usage_error(cmd, "--threads: expected 0..%u, got '%s'", RC_MAX_THREADS, v), -1;
        } else if (OPT("--repeat")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->repeat) != 0 || a->repeat == 0)
                return rcp_usage_error(cmd, "--repeat: expected a count >= 1, got '%s'", v), -1;
        } else if (OPT("--triangles")) {
            if (r < 0) return -1;
            if (rcp_parse_count(v, &a->triangles) != 0 || a->triangles < 8 || a->triangles > 4000000000ull)
                return rcp_usage_error(cmd, "--triangles: expected 8 .. 4G (suffixes k, M, G), got '%s'", v), -1;
            a->set_triangles = 1;
        } else if (OPT("--pose-count")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->pose_count) != 0 || a->pose_count == 0)
                return rcp_usage_error(cmd, "--pose-count: expected a count >= 1, got '%s'", v), -1;
            a->set_pose_count = 1;
        } else if (OPT("--poses-per-call")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->poses_per_call) != 0 || a->poses_per_call == 0)
                return rcp_usage_error(cmd, "--poses-per-call: expected a count >= 1, got '%s'", v), -1;
            a->set_poses_per_call = 1;
        } else if (OPT("--seed")) {
            if (r < 0) return -1;
            if (rcp_parse_count(v, &a->seed) != 0)
                return rcp_usage_error(cmd, "--seed: expected an unsigned integer, got '%s'", v), -1;
            a->set_seed = 1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]), -1;
        }
#undef OPT
    }
    if (a->preset == 0 && !a->ondn) a->preset = rc_preset_from_name(a->sensor_name);
    if (a->map && a->set_triangles)
        fprintf(stderr, "rangecast bench: note: --triangles is ignored with --map\n");
    if (a->poses_path && (a->set_pose_count || a->set_seed))
        fprintf(stderr, "rangecast bench: note: --pose-count and --seed are ignored with --poses\n");
    if (a->on_device && a->backend != RC_BACKEND_VULKAN)
        return rcp_usage_error(cmd, "--results-on-device needs --backend vulkan"), -1;
    if (a->embree_single && rcp_mesh_parts > 1)
        return rcp_usage_error(cmd, "--meshes needs rc_simulate: not with --backend embree-single (one geometry)"),
               -1;
    if (a->embree_single && a->set_poses_per_call)
        fprintf(stderr, "rangecast bench: note: --poses-per-call is ignored with --backend embree-single "
                        "(its loop makes no rc_simulate calls)\n");
    return 0;
}

#if defined(RANGECAST_TOOL_WITH_EMBREE)
/* --backend embree-single: the plain rtcIntersect1 loop most Embree users write
 * (tools/rangecast/embree_single.c), timed the same way, printed with the same
 * keys. Accuracy keys that need triangle ids are null; hit_mismatch counts
 * escaped rays on the generated sphere. */
static int bench_embree_single(const bench_args *a, const rcp_rays *ondn, const rcu_mesh *mesh,
                               const rc_pose *poses, uint32_t pose_count, int is_sphere)
{
    const char *cmd = "bench";
    rcu_preset_rays ref;
    float *dirs = NULL, *ranges = NULL;
    double sps = 0.0, build_s = 0.0;
    uint64_t k, n, escaped = 0, hits = 0;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    uint32_t threads = a->threads ? a->threads : (ncpu > 0 ? (uint32_t)ncpu : 1u);
    int rc = RCP_EXIT_FAIL;
    memset(&ref, 0, sizeof ref);
    if (bench_reference(a, ondn, &ref) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    n = (uint64_t)pose_count * ref.rays;
    dirs = (float *)malloc((size_t)ref.rays * 3 * sizeof(float));
    ranges = (float *)malloc((size_t)n * sizeof(float));
    if (!dirs || !ranges) {
        rcp_fail(cmd, "out of memory for %u scans", pose_count);
        goto out;
    }
    for (k = 0; k < (uint64_t)ref.rays * 3; k++) dirs[k] = (float)ref.dirs[k];
    if (rct_embree_single_bench(mesh->vertices, mesh->vertex_count, mesh->indices, mesh->triangle_count, dirs,
                                a->ondn ? ondn->origins : NULL, ref.rays, (float)ref.range_min,
                                (float)ref.range_max, poses, pose_count, threads, (int)a->repeat, &sps, &build_s,
                                ranges) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto out;
    }
    for (k = 0; k < n; k++) {
        if (isfinite(ranges[k])) hits++;
        else escaped++;
    }
    printf("{\"tool\":\"rangecast bench\",\"version\":\"%s\",\"backend\":\"embree-single\",\"threads\":%u,"
           "\"sensor\":\"%s\",\"triangles\":%u,\"poses\":%u,\"rays_per_scan\":%u,\"repeat\":%u,"
           "\"build_s\":%.6g,\"scans_per_s\":%.6g,\"rays_per_s\":%.6g,\"peak_rss_bytes\":%llu,"
           "\"hit_fraction\":%.9g,\"hit_mismatch\":",
           rc_version_string(), threads, a->sensor_name, mesh->triangle_count, pose_count, ref.rays, a->repeat,
           build_s, sps, sps * ref.rays, (unsigned long long)rcu_peak_rss_bytes(), (double)hits / (double)n);
    if (is_sphere) printf("%llu}\n", (unsigned long long)escaped);
    else printf("null}\n");
    rc = RCP_EXIT_OK;
out:
    free(dirs);
    free(ranges);
    rcu_preset_rays_free(&ref);
    return rc;
}
#endif

int rcp_cmd_bench(int argc, char **argv)
{
    const char *cmd = "bench";
    bench_args a;
    rcu_mesh mesh;
    rc_pose *poses = NULL;
    uint32_t pose_count = 0, rays, batch, chunk, p, rep;
    rcp_world w;
    rcp_rays ondn;
    rc_sensor_info si = rc_sensor_info_default();
    rc_scene_info scinfo = rc_scene_info_default();
    rc_memory_stats ms = rc_memory_stats_default();
    rcu_preset_rays ref;
    float *ranges = NULL, *cranges = NULL;
    uint8_t *chits = NULL;
    uint32_t *cprims = NULL, *cgeoms = NULL;
    double *rep_s = NULL, median_s, scans_per_s, sphere_in = 0.0;
    uint64_t peak_rss;
    uint32_t last_batch_start;
    accuracy acc;
    FILE *rout = NULL;
    int rout_opened = 0;
    rc_status st;
    int rc = RCP_EXIT_FAIL, is_sphere;

    if (parse_args(argc, argv, &a) != 0) return RCP_EXIT_USAGE;
    is_sphere = a.map == NULL;
    memset(&mesh, 0, sizeof mesh);
    memset(&w, 0, sizeof w);
    memset(&ref, 0, sizeof ref);
    memset(&acc, 0, sizeof acc);
    memset(&ondn, 0, sizeof ondn);

    /* The map. */
    if (is_sphere) {
        if (rcu_mesh_uv_sphere_triangles(BENCH_SPHERE_RADIUS, a.triangles, &mesh) != 0)
            return rcp_fail(cmd, "%s", rcu_last_error());
    } else if (rcp_mesh_load(a.map, &mesh) != 0) {
        return rcp_fail(cmd, "%s", rcu_last_error());
    }
    if (rcp_mesh_parts > 1 && rcp_baked_of(&mesh)) {
        rcp_usage_error(cmd, "--meshes: %s is a baked map, which keeps the meshes it was baked with", a.map);
        rc = RCP_EXIT_USAGE;
        goto done;
    }
    if (rcp_mesh_parts > mesh.triangle_count) {
        rcp_usage_error(cmd, "--meshes %u: the map has %u triangles", rcp_mesh_parts, mesh.triangle_count);
        rc = RCP_EXIT_USAGE;
        goto done;
    }

    if (a.ouster_path && rcp_ouster_load(a.ouster_path, &ondn) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    if (a.ondn && !a.ouster_path && random_rays(&ondn) != 0) {
        rcp_fail(cmd, "out of memory for the OnDn rays");
        goto done;
    }

    /* The poses. */
    if (a.poses_path) {
        if (rcu_poses_read(a.poses_path, &poses, &pose_count) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
    } else {
        float b[6], centre[3] = {0, 0, 0};
        int k;
        if (!is_sphere) {
            rcu_mesh_bounds(&mesh, b);
            for (k = 0; k < 3; k++) centre[k] = 0.5f * (b[k] + b[k + 3]);
        }
        pose_count = a.pose_count;
        poses = (rc_pose *)malloc((size_t)pose_count * sizeof *poses);
        if (!poses) {
            rcp_fail(cmd, "out of memory for %u poses", pose_count);
            goto done;
        }
        rcu_poses_random_about(pose_count, BENCH_POSE_RADIUS, a.seed, centre, poses);
    }

#if defined(RANGECAST_TOOL_WITH_EMBREE)
    if (a.embree_single) {
        rc = bench_embree_single(&a, &ondn, &mesh, poses, pose_count, is_sphere);
        goto done;
    }
#endif
    if (a.ondn) {
        const rc_rays_desc rd = rcp_rays_desc(&ondn);
        if (rcp_world_create_rays(cmd, a.backend, a.threads, &mesh, RC_SENSOR_ONDN, &rd, &w) != RCP_EXIT_OK)
            goto done;
    } else if (rcp_world_create(cmd, a.backend, a.threads, &mesh, &a.preset, 1, &w) != RCP_EXIT_OK) {
        goto done;
    }
    rc_sensor_get_info(w.sensors[0], &si);
    rc_scene_get_info(w.scene, &scinfo);
    rays = si.rays_per_scan;

    /* ---- timed loop: ranges only, all poses in batches ---- */
    /* the 128 MiB cap sizes the default; an explicit --poses-per-call is taken
     * as given (a GPU needs 10,000 VLP-16 poses a call, 576 MB of ranges) */
    batch = (uint32_t)(BENCH_TIMED_BYTES / sizeof(float) / rays);
    if (batch == 0) batch = 1;
    if (batch > a.poses_per_call || a.set_poses_per_call) batch = a.poses_per_call;
    if (batch > pose_count) batch = pose_count;
    if ((uint64_t)batch * rays > (uint64_t)(SIZE_MAX / sizeof(float))) { /* 32-bit hosts */
        rcp_fail(cmd, "--poses-per-call %u: %u scans of %u ranges do not fit in this address space", batch, batch,
                 rays);
        goto done;
    }
    ranges = (float *)malloc((size_t)batch * rays * sizeof(float));
    rep_s = (double *)malloc(a.repeat * sizeof(double));
    if (!ranges || !rep_s) {
        rcp_fail(cmd, "out of memory for %u scans of ranges", batch);
        goto done;
    }
    {
        rc_results res = rc_results_default();
        res.attributes = RC_ATTR_RANGES;
        res.ranges = ranges;
        res.capacity = (uint64_t)batch * rays;
        if (a.on_device) res.flags = RC_RESULTS_ON_DEVICE;
        /* warm-up: touch the whole buffer (page faults stay out of the timing),
         * then a few scans (caches, threads, GPU pipelines) */
        memset(ranges, 0, (size_t)batch * rays * sizeof(float));
        if ((st = rc_simulate(w.ctx, w.scene, w.sensors[0], poses, batch < 8 ? batch : 8, &res)) != RC_OK) {
            rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
            goto done;
        }
        last_batch_start = 0;
        for (rep = 0; rep < a.repeat; rep++) {
            double t0 = rcu_now();
            for (p = 0; p < pose_count; p += batch) {
                uint32_t n = pose_count - p < batch ? pose_count - p : batch;
                if ((st = rc_simulate(w.ctx, w.scene, w.sensors[0], poses + p, n, &res)) != RC_OK) {
                    rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
                    goto done;
                }
                last_batch_start = p;
            }
            rep_s[rep] = rcu_now() - t0;
        }
        /* the last batch once more into `ranges`, untimed, for the check below */
        res.flags = 0;
        if (a.on_device && (st = rc_simulate(w.ctx, w.scene, w.sensors[0], poses + last_batch_start,
                                             pose_count - last_batch_start < batch ? pose_count - last_batch_start
                                                                                    : batch,
                                             &res)) != RC_OK) {
            rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
            goto done;
        }
    }
    peak_rss = rcu_peak_rss_bytes();
    {
        double *sorted = (double *)malloc(a.repeat * sizeof(double));
        if (!sorted) {
            rcp_fail(cmd, "out of memory");
            goto done;
        }
        memcpy(sorted, rep_s, a.repeat * sizeof(double));
        median_s = rcp_median(sorted, a.repeat);
        free(sorted);
    }
    scans_per_s = median_s > 0.0 ? (double)pose_count / median_s : INFINITY;
    rc_context_get_memory_stats(w.ctx, &ms);

    /* ---- accuracy pass (untimed) ---- */
    if (bench_reference(&a, &ondn, &ref) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    if (ref.rays != rays) {
        rcp_fail(cmd, "the reference has %u rays a scan but the sensor %u", ref.rays, rays);
        goto done;
    }
    if (is_sphere) sphere_in = inscribed_radius(&mesh) * (1.0 - 1e-6);
    chunk = (uint32_t)(BENCH_CHECK_BYTES / (rays * (sizeof(float) + 1 + sizeof(uint32_t))));
    if (chunk == 0) chunk = 1;
    if (chunk > pose_count) chunk = pose_count;
    cranges = (float *)malloc((size_t)chunk * rays * sizeof(float));
    chits = (uint8_t *)malloc((size_t)chunk * rays);
    cprims = (uint32_t *)malloc((size_t)chunk * rays * sizeof(uint32_t));
    cgeoms = (uint32_t *)malloc((size_t)chunk * rays * sizeof(uint32_t));
    if (!cranges || !chits || !cprims || !cgeoms) {
        rcp_fail(cmd, "out of memory for the accuracy pass");
        goto done;
    }
    if (a.ranges_out && !(rout = fopen(a.ranges_out, "wb"))) {
        rcp_fail(cmd, "%s: cannot open for writing", a.ranges_out);
        goto done;
    }
    rout_opened = rout != NULL;
    {
        rc_results res = rc_results_default();
        rcu_xform mount;
        rcu_xform_from_pose(&ref.mount, &mount);
        /* (geom id, prim id) name the hit triangle: a baked map may hold several meshes */
        res.attributes = RC_ATTR_RANGES | RC_ATTR_HITS | RC_ATTR_PRIM_IDS | RC_ATTR_GEOM_IDS;
        res.ranges = cranges;
        res.hits = chits;
        res.prim_ids = cprims;
        res.geom_ids = cgeoms;
        res.capacity = (uint64_t)chunk * rays;
        for (p = 0; p < pose_count; p += chunk) {
            uint32_t n = pose_count - p < chunk ? pose_count - p : chunk, s, r;
            if ((st = rc_simulate(w.ctx, w.scene, w.sensors[0], poses + p, n, &res)) != RC_OK) {
                rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
                goto done;
            }
            if (rout) {
                size_t k, cnt = (size_t)n * rays;
                unsigned char buf[4096];
                for (k = 0; k < cnt; k += sizeof buf / 4) {
                    size_t m = cnt - k < sizeof buf / 4 ? cnt - k : sizeof buf / 4, j;
                    for (j = 0; j < m; j++) rcu_store_f32le(buf + 4 * j, cranges[k + j]);
                    if (fwrite(buf, 4, m, rout) != m) {
                        rcp_fail(cmd, "%s: write error", a.ranges_out);
                        goto done;
                    }
                }
            }
            for (s = 0; s < n; s++) {
                uint32_t pose_index = p + s;
                rcu_xform pose, x;
                const float *rr = cranges + (size_t)s * rays;
                const uint8_t *hh = chits + (size_t)s * rays;
                const uint32_t *pp = cprims + (size_t)s * rays, *gg = cgeoms + (size_t)s * rays;
                /* the timed loop's last batch is still in `ranges`: the same
                 * poses must give the same bits with a different attribute mask */
                if (pose_index >= last_batch_start &&
                    memcmp(rr, ranges + (size_t)(pose_index - last_batch_start) * rays, (size_t)rays * 4) != 0)
                    acc.differing++;
                rcu_xform_from_pose(&poses[pose_index], &pose);
                rcu_xform_mul(&pose, &mount, &x);
                for (r = 0; r < rays; r++) {
                    double d[3], o[3];
                    int hit = hh[r] != 0;
                    acc.rays++;
                    if (hit != (isfinite(rr[r]) != 0)) acc.inconsistent++;
                    rcu_xform_dir(&x, ref.dirs + 3u * (size_t)r, d);
                    if (ref.origins) {
                        rcu_xform_point(&x, ref.origins + 3u * (size_t)r, o);
                    } else {
                        memcpy(o, x.t, sizeof o);
                    }
                    if (hit) {
                        acc.hits++;
                        const uint64_t tri = mesh_triangle(&mesh, gg[r], pp[r]);
                        if (tri >= mesh.triangle_count) {
                            acc.bad_prims++;
                        } else {
                            const uint32_t *t = mesh.indices + 3u * (size_t)tri;
                            double tr = rcu_ray_plane_distance(o, d, mesh.vertices + 3u * (size_t)t[0],
                                                               mesh.vertices + 3u * (size_t)t[1],
                                                               mesh.vertices + 3u * (size_t)t[2]);
                            double e = fabs((double)rr[r] - tr);
                            if (!isfinite(e)) e = INFINITY;
                            acc.err_sum += e;
                            if (e > acc.err_max) acc.err_max = e;
                            if (push_err(&acc, (float)e) != 0) {
                                rcp_fail(cmd, "out of memory for the range errors");
                                goto done;
                            }
                        }
                    }
                    if (is_sphere) {
                        double t_out = rcu_ray_sphere_exit(o, d, BENCH_SPHERE_RADIUS * (1.0 + 1e-6));
                        double t_in = rcu_ray_sphere_exit(o, d, sphere_in);
                        int must_hit = t_out <= ref.range_max && t_in >= ref.range_min;
                        int must_miss = t_in > ref.range_max || t_out < ref.range_min;
                        if ((must_hit && !hit) || (must_miss && hit)) acc.mismatch++;
                    }
                }
            }
        }
    }
    if (rout) {
        int bad = fclose(rout) != 0;
        rout = NULL;
        if (bad) {
            rcp_fail(cmd, "%s: write error", a.ranges_out);
            goto done;
        }
    }
    if (acc.nerr > 0) {
        size_t k = (size_t)ceil(0.999 * (double)acc.nerr) - 1;
        if (k >= acc.nerr) k = acc.nerr - 1;
        acc.err_p999 = select_kth(acc.errs, acc.nerr, k);
    }
    if (acc.inconsistent)
        fprintf(stderr, "rangecast bench: warning: %llu rays have hit != isfinite(range)\n",
                (unsigned long long)acc.inconsistent);
    if (acc.bad_prims)
        fprintf(stderr, "rangecast bench: warning: %llu hits report a triangle index past the mesh\n",
                (unsigned long long)acc.bad_prims);
    if (acc.differing)
        fprintf(stderr, "rangecast bench: warning: %llu scans give different ranges with "
                        "RANGES|HITS|PRIM_IDS|GEOM_IDS than with RANGES alone\n", (unsigned long long)acc.differing);
    if (is_sphere && acc.rays > 0 && acc.hits == 0)
        fprintf(stderr,
                "rangecast bench: note: no ray returned: %s reaches %g m, and the standard sphere lies 10 to 30 m "
                "from its poses. For a short-range sensor bench a map of its scale, e.g.\n"
                "  rangecast gen --sphere 100k --radius 3 -o small.ply && rangecast gen --poses 1000 --radius 1 -o "
                "near.bin\n  rangecast bench --map small.ply --poses near.bin --sensor %s\n",
                a.sensor_name, ref.range_max, a.sensor_name);

    /* ---- the JSON line ---- */
    {
        FILE *f = stdout;
        printf("{\"tool\":\"rangecast bench\",\"version\":\"%s\",\"backend\":\"%s\",\"threads\":%u,"
               "\"sensor\":\"%s\",\"map\":",
               rc_version_string(), rc_backend_name(w.backend), w.threads, a.sensor_name);
        json_string(f, is_sphere ? "uv_sphere_r20" : a.map);
        printf(",\"triangles\":%u,\"vertices\":%u,\"poses\":%u,\"rays_per_scan\":%u,\"repeat\":%u,",
               mesh.triangle_count, mesh.vertex_count, pose_count, rays, a.repeat);
        printf("\"seed\":");
        if (a.poses_path) printf("null");
        else printf("%llu", (unsigned long long)a.seed);
        printf(",\"build_s\":");
        json_number(f, w.build_s);
        printf(",\"scans_per_s\":");
        json_number(f, scans_per_s);
        printf(",\"rays_per_s\":");
        json_number(f, scans_per_s * rays);
        printf(",\"repeat_s\":[");
        for (rep = 0; rep < a.repeat; rep++) {
            if (rep) putchar(',');
            json_number(f, rep_s[rep]);
        }
        printf("],\"peak_rss_bytes\":%llu,\"arena_bytes\":%llu,\"scene_bytes\":%llu,"
               "\"bytes_per_triangle\":",
               (unsigned long long)peak_rss, (unsigned long long)w.arena_bytes,
               (unsigned long long)scinfo.bytes);
        json_number(f, (double)scinfo.bytes / (double)mesh.triangle_count);
        printf(",\"backend_bytes\":%llu,\"device_bytes\":%llu,\"total_bytes_per_triangle\":",
               (unsigned long long)ms.backend_bytes, (unsigned long long)ms.device_bytes);
        json_number(f, (double)(scinfo.bytes + ms.backend_bytes + ms.device_bytes) / (double)mesh.triangle_count);
        printf(",\"hit_fraction\":");
        json_number(f, acc.rays ? (double)acc.hits / (double)acc.rays : NAN);
        printf(",\"range_err_mean_m\":");
        json_number(f, acc.nerr ? acc.err_sum / (double)acc.nerr : NAN);
        printf(",\"range_err_p999_m\":");
        json_number(f, acc.nerr ? acc.err_p999 : NAN);
        printf(",\"range_err_max_m\":");
        json_number(f, acc.nerr ? acc.err_max : NAN);
        printf(",\"hit_mismatch\":");
        if (is_sphere) printf("%llu", (unsigned long long)acc.mismatch);
        else printf("null");
        printf(",\"ranges_consistent\":%s,\"build_quality\":\"%s\",\"baked_map_bytes\":",
               acc.differing == 0 && acc.inconsistent == 0 && acc.bad_prims == 0 ? "true" : "false",
               rcp_build_quality_name(rcp_build_quality));
        if (rcp_baked_of(&mesh)) printf("%llu", (unsigned long long)rcp_baked_of(&mesh)->bytes);
        else printf("null");
        if (w.backend == RC_BACKEND_VULKAN)
            printf(",\"vulkan_traversal\":\"%s\"",
                   (rcp_context_flags & RC_CONTEXT_VULKAN_RAY_QUERY) ? "ray-query" : "compute");
        else
            printf(",\"vulkan_traversal\":null");
        printf(",\"poses_per_call\":%u,\"results_on_device\":%s,\"mesh\":\"%s\",\"meshes\":%u}\n", batch,
               a.on_device ? "true" : "false", rcp_mesh_flags == RC_MESH_COPY ? "copy" : "reference",
               rcp_mesh_parts);
        fflush(stdout);
    }
    rc = RCP_EXIT_OK;

done:
    rcp_rays_free(&ondn);
    if (rout) fclose(rout);
    /* a failed run leaves no half-written ranges behind */
    if (rc != RCP_EXIT_OK && a.ranges_out && rout_opened) rcu_remove_partial(a.ranges_out);
    rcp_world_destroy(&w);
    rcu_preset_rays_free(&ref);
    free(acc.errs);
    free(cranges);
    free(chits);
    free(cprims);
    free(cgeoms);
    free(ranges);
    free(rep_s);
    free(poses);
    rcu_mesh_free(&mesh);
    return rc;
}
