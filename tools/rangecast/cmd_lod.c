/* rangecast lod: levels of detail of a map with meshoptimizer's simplifier,
 * each measured for speed (scans/s), memory (scene bytes) and range error
 * against the full map's float64 reference; the coarsest level whose p99
 * error stays under the tolerance is written out. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "mesh_load.h"
#include "ply.h"
#include "poses.h"
#include "util.h"

#if defined(RANGECAST_WITH_MESHOPT)
#include <meshoptimizer.h>
#endif

#define LOD_MAX_LEVELS 12
#define LOD_MAX_DISAGREE 0.01 /* a level may change at most 1% of the rays' return/no-return */

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast lod --map FILE -o OUT.ply [options]\n"
        "\n"
        "Simplifies the map (meshoptimizer, meshopt_simplify) to a series of target\n"
        "errors (absolute, in metres: tolerance x 0.05, 0.1, 0.25, 0.5, 1, 2, 4, 8),\n"
        "and for the full map and each level measures scans/s (the library, ranges\n"
        "only), the scene's bytes (arena + backend) and the range error against the\n"
        "FULL map's float64 reference at the same poses. Picks the coarsest level\n"
        "with p99 error <= tolerance and at most 1%% of rays changing between return\n"
        "and no return, and writes it as PLY.\n"
        "\n"
        "Options:\n"
        "  --map FILE        the full map (.ply, or any Assimp format)\n"
        "  -o FILE           output PLY of the chosen level\n"
        "  --tolerance M     p99 range error allowed, metres (default 0.03)\n"
        "  --sensor NAME     vlp16 (default), vlp16-360, os1-64, d435, livox-mid40,\n"
        "                    ust-10lx, lds-01 (2-D scanners)\n"
        "  --poses FILE      raw poses; default random poses inside the map's bounds\n"
        "  --pose-count N    random poses (default 50)\n"
        "  --seed S          their seed (default 1)\n"
        "  --backend B       auto (default), bvh, embree, vulkan\n"
        "  --threads N       library threads, 0 = all CPUs (default)\n"
        "  --json            one JSON line per level instead of the table\n"
        "\n"
        "JSON keys (per level): tool backend threads sensor map level target_error_m triangles\n"
        "bytes scans_per_s range_err_mean_m range_err_p99_m range_err_p999_m range_err_max_m\n"
        "disagree_rate chosen.\n");
}

#if defined(RANGECAST_WITH_MESHOPT)
/* Random poses uniform in the middle 80% of the bounds, random orientations. */
static void poses_in_bounds(const float b[6], uint32_t n, uint64_t seed, rc_pose *out)
{
    rcu_rng rng;
    uint32_t i;
    int k;
    rcu_poses_random(n, 1.0f, seed, out); /* orientations */
    rcu_rng_seed(&rng, seed ^ 0x9e3779b97f4a7c15ull);
    for (i = 0; i < n; i++)
        for (k = 0; k < 3; k++) {
            double ext = (double)b[k + 3] - b[k];
            out[i].position[k] = (float)(b[k] + ext * (0.1 + 0.8 * rcu_rng_uniform(&rng)));
        }
}

typedef struct lod_level {
    double target_m;   /* 0: the full map */
    rcu_mesh mesh;
    uint64_t bytes;
    rcp_acc_stats s;
    int ok;
} lod_level;

/* Simplified copy of m with only the vertices it uses. */
static int simplify(const rcu_mesh *m, double target_m, rcu_mesh *out)
{
    size_t nidx = (size_t)m->triangle_count * 3, got, i;
    unsigned int *dst = (unsigned int *)malloc(nidx * sizeof(unsigned int));
    uint32_t *remap = (uint32_t *)malloc((size_t)m->vertex_count * sizeof(uint32_t));
    float scale = meshopt_simplifyScale(m->vertices, m->vertex_count, 12);
    float err = 0.0f;
    memset(out, 0, sizeof *out);
    if (!dst || !remap) goto oom;
    got = meshopt_simplify(dst, m->indices, nidx, m->vertices, m->vertex_count, 12, 3,
                           scale > 0 ? (float)(target_m / scale) : 0.0f, 0, &err);
    if (got < 3) got = 0;
    if (rcu_mesh_reserve(out, m->vertex_count, got / 3) != 0) goto oom;
    for (i = 0; i < m->vertex_count; i++) remap[i] = UINT32_MAX;
    for (i = 0; i < got; i++) {
        uint32_t v = dst[i];
        if (remap[v] == UINT32_MAX) {
            remap[v] = out->vertex_count;
            memcpy(out->vertices + 3u * out->vertex_count, m->vertices + 3u * (size_t)v, 12);
            out->vertex_count++;
        }
        out->indices[i] = remap[v];
    }
    out->triangle_count = (uint32_t)(got / 3);
    free(dst);
    free(remap);
    return 0;
oom:
    free(dst);
    free(remap);
    rcu_mesh_free(out);
    return rcu_fail("out of memory simplifying %u triangles", m->triangle_count);
}
#endif

typedef struct lod_args {
    const char *map, *out_path, *poses_path, *sensor_name;
    uint32_t preset, backend, threads, pose_count;
    uint64_t seed;
    float tolerance;
    int json;
} lod_args;

#if defined(RANGECAST_WITH_MESHOPT)
static int lod_run(const lod_args *a)
{
    const char *cmd = "lod", *map = a->map, *sensor_name = a->sensor_name;
    uint32_t preset = a->preset, backend = a->backend, threads = a->threads, pose_count = a->pose_count, nl = 0, l;
    float tolerance = a->tolerance;
    int json = a->json, r, rc = RCP_EXIT_FAIL, chosen = 0;
    static const double factors[] = {0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0};
    lod_level levels[LOD_MAX_LEVELS];
    rcu_mesh full;
    rc_pose *poses = NULL;
    rcu_reftrace *ref = NULL;
    rcu_preset_rays rays;
    memset(levels, 0, sizeof levels);
    memset(&full, 0, sizeof full);
    memset(&rays, 0, sizeof rays);
    if (rcp_mesh_load(map, &full) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    if (a->poses_path) {
        if (rcu_poses_read(a->poses_path, &poses, &pose_count) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
    } else {
        float b[6];
        rcu_mesh_bounds(&full, b);
        poses = (rc_pose *)malloc((size_t)pose_count * sizeof *poses);
        if (!poses) {
            rcp_fail(cmd, "out of memory");
            goto done;
        }
        poses_in_bounds(b, pose_count, a->seed, poses);
    }
    if (rcu_preset_rays_f64(preset, &rays) != 0 || rcu_reftrace_build(&full, &ref) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    /* level 0: the full map itself (its own error is the library's float error) */
    levels[0].target_m = 0.0;
    if (rcu_mesh_append(&levels[0].mesh, &full) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    nl = 1;
    for (l = 0; l < sizeof factors / sizeof factors[0] && nl < LOD_MAX_LEVELS; l++) {
        levels[nl].target_m = tolerance * factors[l];
        if (simplify(&full, levels[nl].target_m, &levels[nl].mesh) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        if (levels[nl].mesh.triangle_count == 0) {
            rcu_mesh_free(&levels[nl].mesh);
            break;
        }
        nl++;
    }
    for (l = 0; l < nl; l++) {
        rcp_world w;
        rc_scene_info si = rc_scene_info_default();
        rc_memory_stats ms = rc_memory_stats_default();
        if (rcp_world_create(cmd, backend, threads, &levels[l].mesh, &preset, 1, &w) != RCP_EXIT_OK) goto done;
        rc_scene_get_info(w.scene, &si);
        rc_context_get_memory_stats(w.ctx, &ms);
        levels[l].bytes = si.bytes + ms.backend_bytes + ms.device_bytes;
        /* a warm-up scan, then the measured pass (its simulate time gives scans/s) */
        {
            float *tmp = (float *)malloc((size_t)rays.rays * sizeof(float));
            rc_results res = rc_results_default();
            if (tmp) {
                res.attributes = RC_ATTR_RANGES;
                res.ranges = tmp;
                res.capacity = rays.rays;
                rc_simulate(w.ctx, w.scene, w.sensors[0], poses, 1, &res);
                free(tmp);
            }
        }
        r = rcp_accuracy_run(cmd, &w, w.sensors[0], ref, &rays, poses, pose_count, &levels[l].s);
        if (r != RCP_EXIT_OK) {
            rcp_world_destroy(&w);
            goto done;
        }
        levels[l].ok = levels[l].s.all.p99 <= tolerance &&
                       (double)levels[l].s.disagree <= LOD_MAX_DISAGREE * (double)levels[l].s.rays;
        if (levels[l].ok) chosen = (int)l;
        if (l == 0) {
            backend = w.backend;
            threads = w.threads;
        }
        rcp_world_destroy(&w);
    }
    for (l = 0; l < nl; l++) {
        const lod_level *L = &levels[l];
        double sps = L->s.sim_s > 0 ? pose_count / L->s.sim_s : NAN;
        double dr = L->s.rays ? (double)L->s.disagree / (double)L->s.rays : NAN;
        if (json) {
            printf("{\"tool\":\"rangecast lod\",\"version\":\"%s\",\"backend\":\"%s\",\"threads\":%u,\"sensor\":\"%s\","
                   "\"map\":",
                   rc_version_string(), rc_backend_name(backend), threads, sensor_name);
            rcp_json_string(stdout, map);
            printf(",\"level\":%u,\"target_error_m\":%.6g,\"triangles\":%u,\"bytes\":%llu,\"scans_per_s\":", l,
                   L->target_m, L->mesh.triangle_count, (unsigned long long)L->bytes);
            rcp_json_number(stdout, sps);
            printf(",\"range_err_mean_m\":");
            rcp_json_number(stdout, L->s.all.mean);
            printf(",\"range_err_p99_m\":");
            rcp_json_number(stdout, L->s.all.p99);
            printf(",\"range_err_p999_m\":");
            rcp_json_number(stdout, L->s.all.p999);
            printf(",\"range_err_max_m\":");
            rcp_json_number(stdout, L->s.all.max);
            printf(",\"disagree_rate\":");
            rcp_json_number(stdout, dr);
            printf(",\"chosen\":%s}\n", (int)l == chosen ? "true" : "false");
        } else {
            char bb[32];
            if (l == 0)
                printf("rangecast lod: %s, %s, %u poses, tolerance p99 <= %g m, <= %g%% disagreements\n"
                       "%5s %12s %10s %12s %10s %12s %12s %10s\n",
                       map, sensor_name, pose_count, tolerance, 100 * LOD_MAX_DISAGREE, "level", "target [m]",
                       "triangles", "bytes", "scans/s", "p99 [m]", "p99.9 [m]", "disagree");
            printf("%5u %12.4g %10u %12s %10.1f %12.3g %12.3g %9.3g%%%s\n", l, L->target_m, L->mesh.triangle_count,
                   rcp_bytes(L->bytes, bb, sizeof bb), sps, L->s.all.p99, L->s.all.p999, 100 * dr,
                   (int)l == chosen ? "  <- chosen" : (L->ok ? "" : "  (over)"));
        }
    }
    if (rcu_mesh_write_ply(a->out_path, &levels[chosen].mesh) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    if (!json)
        printf("wrote level %d (%u triangles) to %s\n", chosen, levels[chosen].mesh.triangle_count, a->out_path);
    rc = RCP_EXIT_OK;
done:
    for (l = 0; l < LOD_MAX_LEVELS; l++) rcu_mesh_free(&levels[l].mesh);
    rcu_reftrace_free(ref);
    rcu_preset_rays_free(&rays);
    free(poses);
    rcu_mesh_free(&full);
    return rc;
}
#endif

int rcp_cmd_lod(int argc, char **argv)
{
    const char *cmd = "lod";
    lod_args a;
    int i, r;
    memset(&a, 0, sizeof a);
    a.sensor_name = "vlp16";
    a.backend = RC_BACKEND_AUTO;
    a.pose_count = 50;
    a.seed = 1;
    a.tolerance = 0.03f;
    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
#define OPT(name) ((r = rcp_opt(argc, argv, &i, name, &v)) != 0)
        if (OPT("--map")) { if (r < 0) return RCP_EXIT_USAGE; a.map = v; }
        else if (OPT("-o")) { if (r < 0) return RCP_EXIT_USAGE; a.out_path = v; }
        else if (OPT("--poses")) { if (r < 0) return RCP_EXIT_USAGE; a.poses_path = v; }
        else if (OPT("--tolerance")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_float(v, &a.tolerance) != 0 || !(a.tolerance > 0.0f))
                return rcp_usage_error(cmd, "--tolerance: expected metres > 0, got '%s'", v);
        } else if (OPT("--sensor")) {
            if (r < 0 || rcp_parse_sensor(cmd, v, &a.preset) != 0) return RCP_EXIT_USAGE;
            a.sensor_name = v;
        } else if (OPT("--backend")) {
            if (r < 0 || rcp_parse_backend(cmd, v, &a.backend) != 0) return RCP_EXIT_USAGE;
        } else if (OPT("--threads")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_u32(v, &a.threads) != 0 || a.threads > RC_MAX_THREADS)
                return rcp_usage_error(cmd, "--threads: expected 0..%u, got '%s'", RC_MAX_THREADS, v);
        } else if (OPT("--pose-count")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_u32(v, &a.pose_count) != 0 || a.pose_count == 0)
                return rcp_usage_error(cmd, "--pose-count: expected a count >= 1, got '%s'", v);
        } else if (OPT("--seed")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_count(v, &a.seed) != 0) return rcp_usage_error(cmd, "--seed: expected an integer, got '%s'", v);
        } else if (strcmp(argv[i], "--json") == 0) {
            a.json = 1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
#undef OPT
    }
    if (!a.map) return rcp_usage_error(cmd, "--map is required");
    if (!a.out_path) return rcp_usage_error(cmd, "-o OUT.ply is required");
    if (a.preset == 0) a.preset = rc_preset_from_name(a.sensor_name);
#if defined(RANGECAST_WITH_MESHOPT)
    return lod_run(&a);
#else
    return rcp_fail(cmd, "this rangecast was built without meshoptimizer (libmeshoptimizer-dev)");
#endif
}
