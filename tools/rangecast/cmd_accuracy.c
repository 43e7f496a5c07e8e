/* rangecast accuracy: every ray of the library against the float64 reference
 * tracer (tools/common/reftrace.c): return/no-return disagreements and range
 * errors, overall and by angle of incidence. Text table, or ONE JSON line with
 * --json (keys are stable: add, never rename). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "mesh_load.h"
#include "poses.h"
#include "util.h"

#define ACC_SPHERE_RADIUS 20.0f
#define ACC_POSE_RADIUS   10.0f
#define ACC_CHUNK_BYTES   ((size_t)64 << 20)

const double rcp_acc_bin_edges[RCP_ACC_BINS + 1] = {0.0, 30.0, 60.0, 80.0, 89.0, 90.0};

void rcp_json_number(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.9g", v);
    else fprintf(f, "null");
}

void rcp_json_string(FILE *f, const char *s)
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

typedef struct err_vec {
    double *v;
    size_t n, cap;
} err_vec;

static int err_push(err_vec *e, double x)
{
    if (e->n == e->cap) {
        size_t cap = e->cap ? e->cap * 2 : 4096;
        double *p = (double *)realloc(e->v, cap * sizeof(double));
        if (!p) return -1;
        e->v = p;
        e->cap = cap;
    }
    e->v[e->n++] = x;
    return 0;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double quantile_sorted(const double *v, size_t n, double q)
{
    size_t k;
    if (n == 0) return NAN;
    k = (size_t)ceil(q * (double)n);
    if (k > 0) k--;
    if (k >= n) k = n - 1;
    return v[k];
}

static void summarise(err_vec *e, rcp_acc_errs *out)
{
    size_t i;
    double s = 0.0;
    memset(out, 0, sizeof *out);
    out->n = e->n;
    if (e->n == 0) {
        out->mean = out->max = out->p99 = out->p999 = NAN;
        return;
    }
    qsort(e->v, e->n, sizeof(double), cmp_d);
    for (i = 0; i < e->n; i++) s += e->v[i];
    out->mean = s / (double)e->n;
    out->max = e->v[e->n - 1];
    out->p99 = quantile_sorted(e->v, e->n, 0.99);
    out->p999 = quantile_sorted(e->v, e->n, 0.999);
}

/* -1: nearer than range_min, 0: no return, 1: a return. */
static int ref_class(int found, double t, double rmin)
{
    if (!found) return 0;
    return t < rmin ? -1 : 1;
}

int rcp_accuracy_run(const char *cmd, const rcp_world *w, const rc_sensor *sensor, const rcu_reftrace *ref,
                     const rcu_preset_rays *rays, const rc_pose *poses, uint32_t pose_count,
                     rcp_acc_stats *out)
{
    rc_sensor_info si = rc_sensor_info_default();
    uint32_t chunk, p, nrays;
    float *ranges = NULL;
    err_vec all, bins[RCP_ACC_BINS];
    rcu_xform mount;
    int rc = RCP_EXIT_FAIL, b;
    rc_status st;
    memset(out, 0, sizeof *out);
    memset(&all, 0, sizeof all);
    memset(bins, 0, sizeof bins);
    rc_sensor_get_info(sensor, &si);
    nrays = si.rays_per_scan;
    if (nrays != rays->rays) return rcp_fail(cmd, "the reference has %u rays a scan, the sensor %u", rays->rays, nrays);
    chunk = (uint32_t)(ACC_CHUNK_BYTES / ((size_t)nrays * sizeof(float)));
    if (chunk == 0) chunk = 1;
    if (chunk > pose_count) chunk = pose_count;
    ranges = (float *)malloc((size_t)chunk * nrays * sizeof(float));
    if (!ranges) return rcp_fail(cmd, "out of memory");
    rcu_xform_from_pose(&rays->mount, &mount);
    for (p = 0; p < pose_count; p += chunk) {
        uint32_t n = pose_count - p < chunk ? pose_count - p : chunk, s, r;
        rc_results res = rc_results_default();
        double t0;
        res.attributes = RC_ATTR_RANGES;
        res.ranges = ranges;
        res.capacity = (uint64_t)chunk * nrays;
        t0 = rcu_now();
        if ((st = rc_simulate(w->ctx, w->scene, sensor, poses + p, n, &res)) != RC_OK) {
            rcp_lib_error(cmd, w->ctx, "rc_simulate", st);
            goto out;
        }
        out->sim_s += rcu_now() - t0;
        for (s = 0; s < n; s++) {
            rcu_xform pose, x;
            rcu_xform_from_pose(&poses[p + s], &pose);
            rcu_xform_mul(&pose, &mount, &x);
            for (r = 0; r < nrays; r++) {
                double d[3], t = 0.0, nrm[3];
                uint32_t prim = 0;
                float lr = ranges[(size_t)s * nrays + r];
                int found, rcl, lcl;
                rcu_xform_dir(&x, rays->dirs + 3u * (size_t)r, d);
                found = rcu_reftrace_nearest(ref, x.t, d, rays->range_max, &t, &prim);
                rcl = ref_class(found, t, rays->range_min);
                out->rays++;
                if (isnan(lr)) {
                    out->nan_outputs++;
                    out->disagree++;
                    continue;
                }
                lcl = isfinite(lr) ? 1 : (lr < 0 ? -1 : 0);
                if (rcl == 1) out->ref_returns++;
                if (lcl == 1) out->lib_returns++;
                if (rcl != lcl) {
                    out->disagree++;
                    continue;
                }
                if (rcl == 1) {
                    double e = fabs((double)lr - t), c, ang;
                    rcu_reftrace_normal(ref, prim, nrm);
                    c = fabs(d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2]) /
                        sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    if (c > 1.0) c = 1.0;
                    ang = acos(c) * (180.0 / 3.14159265358979323846);
                    for (b = 0; b < RCP_ACC_BINS - 1; b++)
                        if (ang < rcp_acc_bin_edges[b + 1]) break;
                    if (err_push(&all, e) != 0 || err_push(&bins[b], e) != 0) {
                        rcp_fail(cmd, "out of memory for the errors");
                        goto out;
                    }
                }
            }
        }
    }
    summarise(&all, &out->all);
    for (b = 0; b < RCP_ACC_BINS; b++) summarise(&bins[b], &out->bin[b]);
    rc = RCP_EXIT_OK;
out:
    free(ranges);
    free(all.v);
    for (b = 0; b < RCP_ACC_BINS; b++) free(bins[b].v);
    return rc;
}

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast accuracy [--map FILE | --triangles N] [--poses FILE | --pose-count N] [options]\n"
        "\n"
        "Simulates the sensor with the library and traces every ray again with the\n"
        "float64 reference tracer (own BVH, watertight test in double), with the\n"
        "sensor-to-map transform in double. Reports rays whose class differs (a\n"
        "return, no return +inf, or nearer than range_min -inf), and the absolute\n"
        "range error of rays both return: mean, p99, p99.9, max, overall and by angle\n"
        "of incidence (between the ray and the reference triangle's normal).\n"
        "\n"
        "Options:\n"
        "  --map FILE        mesh map (.ply, or any Assimp format); default the UV sphere of radius 20 m\n"
        "  --triangles N     sphere size without --map (default 100k)\n"
        "  --poses FILE      raw poses (float32 x y z qx qy qz qw)\n"
        "  --pose-count N    random poses in a 10 m ball about the map's centre (default 100)\n"
        "  --seed S          seed of the random poses (default 1)\n"
        "  --sensor NAME     vlp16 (default), vlp16-360, os1-64, d435, livox-mid40\n"
        "  --backend B       auto (default), bvh, embree, vulkan\n"
        "  --threads N       library threads, 0 = all CPUs (default)\n"
        "  --json            one JSON line instead of the table\n"
        "\n"
        "JSON keys: tool version backend threads sensor map triangles poses rays disagree disagree_rate\n"
        "nan_outputs ref_returns lib_returns scans_per_s compared range_err_mean_m range_err_p99_m\n"
        "range_err_p999_m range_err_max_m by_incidence [{deg_lo deg_hi n mean_m p999_m max_m}]\n"
        "reference_build_s compare_s. Statistics of no rays are null.\n"
        "scans_per_s: the untimed-elsewhere simulate calls of this run (ranges only).\n");
}

static void print_stats_json(const char *backend, uint32_t threads, const char *sensor, const char *map,
                             uint32_t triangles, uint32_t poses, const rcp_acc_stats *s, const char *extra)
{
    int b;
    printf("{\"tool\":\"rangecast accuracy\",\"version\":\"%s\",\"backend\":\"%s\",\"threads\":%u,"
           "\"sensor\":\"%s\",\"map\":",
           rc_version_string(), backend, threads, sensor);
    rcp_json_string(stdout, map);
    printf(",\"triangles\":%u,\"poses\":%u,\"rays\":%llu,\"disagree\":%llu,\"disagree_rate\":", triangles, poses,
           (unsigned long long)s->rays, (unsigned long long)s->disagree);
    rcp_json_number(stdout, s->rays ? (double)s->disagree / (double)s->rays : NAN);
    printf(",\"nan_outputs\":%llu,\"ref_returns\":%llu,\"lib_returns\":%llu,\"scans_per_s\":",
           (unsigned long long)s->nan_outputs, (unsigned long long)s->ref_returns,
           (unsigned long long)s->lib_returns);
    rcp_json_number(stdout, s->sim_s > 0 ? poses / s->sim_s : NAN);
    printf(",\"compared\":%llu,\"range_err_mean_m\":", (unsigned long long)s->all.n);
    rcp_json_number(stdout, s->all.mean);
    printf(",\"range_err_p99_m\":");
    rcp_json_number(stdout, s->all.p99);
    printf(",\"range_err_p999_m\":");
    rcp_json_number(stdout, s->all.p999);
    printf(",\"range_err_max_m\":");
    rcp_json_number(stdout, s->all.max);
    printf(",\"by_incidence\":[");
    for (b = 0; b < RCP_ACC_BINS; b++) {
        printf("%s{\"deg_lo\":%g,\"deg_hi\":%g,\"n\":%llu,\"mean_m\":", b ? "," : "", rcp_acc_bin_edges[b],
               rcp_acc_bin_edges[b + 1], (unsigned long long)s->bin[b].n);
        rcp_json_number(stdout, s->bin[b].mean);
        printf(",\"p999_m\":");
        rcp_json_number(stdout, s->bin[b].p999);
        printf(",\"max_m\":");
        rcp_json_number(stdout, s->bin[b].max);
        printf("}");
    }
    printf("]%s}\n", extra ? extra : "");
}

int rcp_cmd_accuracy(int argc, char **argv)
{
    const char *cmd = "accuracy", *map = NULL, *poses_path = NULL, *sensor_name = "vlp16";
    uint32_t preset = 0, backend = RC_BACKEND_AUTO, threads = 0, pose_count = 100, b;
    uint64_t triangles = 100000, seed = 1;
    int json = 0, i, r, rc = RCP_EXIT_FAIL;
    rcu_mesh mesh;
    rc_pose *poses = NULL;
    rcp_world w;
    rcu_reftrace *ref = NULL;
    rcu_preset_rays rays;
    rcp_acc_stats s;
    double t0, ref_build_s;
    memset(&mesh, 0, sizeof mesh);
    memset(&w, 0, sizeof w);
    memset(&rays, 0, sizeof rays);
    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
#define OPT(name) ((r = rcp_opt(argc, argv, &i, name, &v)) != 0)
        if (OPT("--map")) { if (r < 0) return RCP_EXIT_USAGE; map = v; }
        else if (OPT("--poses")) { if (r < 0) return RCP_EXIT_USAGE; poses_path = v; }
        else if (OPT("--sensor")) {
            if (r < 0 || rcp_parse_sensor(cmd, v, &preset) != 0) return RCP_EXIT_USAGE;
            sensor_name = v;
        } else if (OPT("--backend")) {
            if (r < 0 || rcp_parse_backend(cmd, v, &backend) != 0) return RCP_EXIT_USAGE;
        } else if (OPT("--threads")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_u32(v, &threads) != 0 || threads > RC_MAX_THREADS)
                return rcp_usage_error(cmd, "--threads: expected 0..%u, got '%s'", RC_MAX_THREADS, v);
        } else if (OPT("--triangles")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_count(v, &triangles) != 0 || triangles < 8 || triangles > 4000000000ull)
                return rcp_usage_error(cmd, "--triangles: expected 8 .. 4G, got '%s'", v);
        } else if (OPT("--pose-count")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_u32(v, &pose_count) != 0 || pose_count == 0)
                return rcp_usage_error(cmd, "--pose-count: expected a count >= 1, got '%s'", v);
        } else if (OPT("--seed")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_count(v, &seed) != 0) return rcp_usage_error(cmd, "--seed: expected an integer, got '%s'", v);
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
#undef OPT
    }
    if (preset == 0) preset = rc_preset_from_name(sensor_name);
    if (map) {
        if (rcp_mesh_load(map, &mesh) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    } else if (rcu_mesh_uv_sphere_triangles(ACC_SPHERE_RADIUS, triangles, &mesh) != 0) {
        return rcp_fail(cmd, "%s", rcu_last_error());
    }
    if (poses_path) {
        if (rcu_poses_read(poses_path, &poses, &pose_count) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
    } else {
        float bb[6], c[3];
        int k;
        rcu_mesh_bounds(&mesh, bb);
        for (k = 0; k < 3; k++) c[k] = 0.5f * (bb[k] + bb[k + 3]);
        poses = (rc_pose *)malloc((size_t)pose_count * sizeof *poses);
        if (!poses) {
            rcp_fail(cmd, "out of memory");
            goto done;
        }
        rcu_poses_random_about(pose_count, ACC_POSE_RADIUS, seed, c, poses);
    }
    if (rcu_preset_rays_f64(preset, &rays) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    t0 = rcu_now();
    if (rcu_reftrace_build(&mesh, &ref) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    ref_build_s = rcu_now() - t0;
    if (rcp_world_create(cmd, backend, threads, &mesh, &preset, 1, &w) != RCP_EXIT_OK) goto done;
    t0 = rcu_now();
    if (rcp_accuracy_run(cmd, &w, w.sensors[0], ref, &rays, poses, pose_count, &s) != RCP_EXIT_OK) goto done;
    if (json) {
        char extra[96];
        snprintf(extra, sizeof extra, ",\"reference_build_s\":%.6g,\"compare_s\":%.6g", ref_build_s,
                 rcu_now() - t0);
        print_stats_json(rc_backend_name(w.backend), w.threads, sensor_name, map ? map : "uv_sphere_r20",
                         mesh.triangle_count, pose_count, &s, extra);
    } else {
        printf("rangecast accuracy: %s, %u threads, %s, %s (%u triangles), %u poses, %llu rays\n",
               rc_backend_name(w.backend), w.threads, sensor_name, map ? map : "UV sphere r=20 m",
               mesh.triangle_count, pose_count, (unsigned long long)s.rays);
        printf("reference build %.3f s, comparison %.3f s, library %.1f scans/s\n", ref_build_s,
               rcu_now() - t0, s.sim_s > 0 ? pose_count / s.sim_s : 0.0);
        printf("disagreements (return / +inf / -inf): %llu of %llu rays (%.3g%%), NaN ranges: %llu\n",
               (unsigned long long)s.disagree, (unsigned long long)s.rays,
               s.rays ? 100.0 * (double)s.disagree / (double)s.rays : 0.0, (unsigned long long)s.nan_outputs);
        printf("returns: reference %llu, library %llu\n\n", (unsigned long long)s.ref_returns,
               (unsigned long long)s.lib_returns);
        printf("%-14s %10s %12s %12s %12s %12s\n", "incidence", "rays", "mean [m]", "p99 [m]", "p99.9 [m]",
               "max [m]");
        printf("%-14s %10llu %12.3g %12.3g %12.3g %12.3g\n", "all", (unsigned long long)s.all.n, s.all.mean,
               s.all.p99, s.all.p999, s.all.max);
        for (b = 0; b < RCP_ACC_BINS; b++) {
            char label[32];
            snprintf(label, sizeof label, "%g-%g deg", rcp_acc_bin_edges[b], rcp_acc_bin_edges[b + 1]);
            printf("%-14s %10llu %12.3g %12.3g %12.3g %12.3g\n", label, (unsigned long long)s.bin[b].n,
                   s.bin[b].mean, s.bin[b].p99, s.bin[b].p999, s.bin[b].max);
        }
    }
    rc = RCP_EXIT_OK;
done:
    rcp_world_destroy(&w);
    rcu_reftrace_free(ref);
    rcu_preset_rays_free(&rays);
    free(poses);
    rcu_mesh_free(&mesh);
    return rc;
}
