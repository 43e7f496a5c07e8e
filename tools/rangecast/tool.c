#include "tool.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "baked_file.h"
#include "util.h"

static void vmessage(const char *cmd, const char *fmt, va_list ap)
{
    fprintf(stderr, "rangecast%s%s: ", cmd ? " " : "", cmd ? cmd : "");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

int rcp_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(cmd, fmt, ap);
    va_end(ap);
    if (cmd) fprintf(stderr, "Try 'rangecast %s --help'.\n", cmd);
    else fprintf(stderr, "Try 'rangecast help'.\n");
    return RCP_EXIT_USAGE;
}

int rcp_fail(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(cmd, fmt, ap);
    va_end(ap);
    return RCP_EXIT_FAIL;
}

int rcp_lib_error(const char *cmd, const rc_context *ctx, const char *call, rc_status st)
{
    const char *detail = ctx ? rc_context_last_error(ctx) : "";
    return rcp_fail(cmd, "%s failed: %s%s%s", call, rc_status_string(st), detail && *detail ? ": " : "",
                    detail ? detail : "");
}

/* The library's log: warnings go to stderr; errors come back as a status +
 * rc_context_last_error and are printed there, except a failed
 * rc_context_create's, which only the log sees: it is kept in user (a buffer
 * of RCP_LOG_TEXT bytes) for the caller to print. */
#define RCP_LOG_TEXT 512
static void log_to_stderr(void *user, uint32_t level, const char *message)
{
    static int info = -1; /* RANGECAST_LOG=info also prints the library's notes (the Vulkan device chosen ...) */
    if (info < 0) {
        const char *v = getenv("RANGECAST_LOG");
        info = v && strcmp(v, "info") == 0;
    }
    if (level == RC_LOG_INFO && info) fprintf(stderr, "rangecast: library note: %s\n", message);
    if (level == RC_LOG_WARN) fprintf(stderr, "rangecast: library warning: %s\n", message);
    if (level == RC_LOG_ERROR && user) snprintf((char *)user, RCP_LOG_TEXT, "%s", message);
}

/* rc_context_create with the log above; a refusal prints the library's
 * reason, which only the log sees. The buffer is static: the context keeps
 * log_user for its whole life (the program is single-threaded). */
static int create_context(const char *cmd, rc_context_desc *desc, rc_context **out)
{
    static char why[RCP_LOG_TEXT];
    rc_status st;
    desc->log = log_to_stderr;
    desc->log_user = why;
    why[0] = '\0';
    if ((st = rc_context_create(desc, out)) == RC_OK) return RCP_EXIT_OK;
    return rcp_fail(cmd, "rc_context_create failed: %s%s%s", rc_status_string(st), why[0] ? ": " : "", why);
}

int rcp_opt_threads(const char *cmd, int argc, char **argv, int *i, uint32_t *threads)
{
    const char *v = NULL;
    const int r = rcp_opt(argc, argv, i, "--threads", &v);
    if (r <= 0) return r;
    if (rcp_parse_u32(v, threads) != 0 || *threads > RC_MAX_THREADS) {
        rcp_usage_error(cmd, "--threads: expected 0..%u, got '%s'", RC_MAX_THREADS, v);
        return -1;
    }
    return 1;
}

int rcp_is_help(const char *arg)
{
    return strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0;
}

int rcp_opt(int argc, char **argv, int *i, const char *name, const char **value)
{
    const char *a = argv[*i];
    size_t n = strlen(name);
    if (strncmp(a, name, n) != 0) return 0;
    if (a[n] == '=') {
        *value = a + n + 1;
        return 1;
    }
    if (a[n] != 0) return 0;
    if (*i + 1 >= argc) {
        fprintf(stderr, "rangecast %s: option %s needs a value\nTry 'rangecast %s --help'.\n", argv[0],
                name, argv[0]);
        return -1;
    }
    *value = argv[++*i];
    return 1;
}

int rcp_parse_u32(const char *s, uint32_t *out)
{
    uint64_t v;
    if (rcp_parse_count(s, &v) != 0 || v > UINT32_MAX) return -1;
    *out = (uint32_t)v;
    return 0;
}

int rcp_parse_count(const char *s, uint64_t *out)
{
    char *end;
    double v, mul = 1.0;
    if (!s || !*s || *s == '-' || *s == '+') return -1;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || errno) return -1;
    if (*end == 'k' || *end == 'K') mul = 1e3, end++;
    else if (*end == 'M' || *end == 'm') mul = 1e6, end++;
    else if (*end == 'G' || *end == 'g') mul = 1e9, end++;
    if (*end) return -1;
    v *= mul;
    if (!(v >= 0.0) || v > 1.8e19 || v != floor(v)) return -1;
    *out = (uint64_t)v;
    return 0;
}

int rcp_parse_float(const char *s, float *out)
{
    char *end;
    double v;
    if (!s || !*s) return -1;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v)) return -1;
    *out = (float)v;
    return 0;
}

int rcp_parse_floats(const char *s, float *out, int n)
{
    int k;
    for (k = 0; k < n; k++) {
        char *end;
        double v;
        errno = 0;
        v = strtod(s, &end);
        if (end == s || errno || !isfinite(v)) return -1;
        out[k] = (float)v;
        s = end;
        if (k + 1 < n) {
            if (*s != ',') return -1;
            s++;
        }
    }
    return *s ? -1 : 0;
}

const char *rcp_available_backends(char *buf, size_t size)
{
    static const uint32_t all[] = {RC_BACKEND_BVH, RC_BACKEND_EMBREE, RC_BACKEND_VULKAN};
    size_t k, used = 0;
    buf[0] = 0;
    for (k = 0; k < sizeof all / sizeof all[0]; k++) {
        if (!rc_backend_available(all[k])) continue;
        used += (size_t)snprintf(buf + used, used < size ? size - used : 0, "%s%s", used ? ", " : "",
                                 rc_backend_name(all[k]));
    }
    return buf;
}

int rcp_parse_backend(const char *cmd, const char *s, uint32_t *backend)
{
    char avail[64];
    uint32_t b;
    if (strcmp(s, "auto") == 0) b = RC_BACKEND_AUTO;
    else if (strcmp(s, "bvh") == 0) b = RC_BACKEND_BVH;
    else if (strcmp(s, "embree") == 0) b = RC_BACKEND_EMBREE;
    else if (strcmp(s, "vulkan") == 0) b = RC_BACKEND_VULKAN;
    else {
        rcp_usage_error(cmd, "unknown backend '%s' (choose auto or one built into this library: %s)", s,
                        rcp_available_backends(avail, sizeof avail));
        return -1;
    }
    if (b != RC_BACKEND_AUTO && !rc_backend_available(b)) {
        rcp_usage_error(cmd, "backend '%s' is not built into this library (available: %s, or auto)", s,
                        rcp_available_backends(avail, sizeof avail));
        return -1;
    }
    *backend = b;
    return 0;
}

/* Indexed by RC_BUILD_* (0..3). */
static const char *const build_quality_names[] = {"balanced", "fast", "high", "compact"};

int rcp_parse_build_quality(const char *cmd, const char *s, uint32_t *quality)
{
    uint32_t q;
    for (q = 0; q < sizeof build_quality_names / sizeof build_quality_names[0]; ++q)
        if (strcmp(s, build_quality_names[q]) == 0) {
            *quality = q;
            return 0;
        }
    rcp_usage_error(cmd, "unknown build quality '%s' (choose balanced, fast, high or compact)", s);
    return -1;
}

const char *rcp_build_quality_name(uint32_t quality)
{
    return quality < sizeof build_quality_names / sizeof build_quality_names[0] ? build_quality_names[quality]
                                                                                 : "unknown";
}

uint32_t rcp_build_quality = RC_BUILD_BALANCED;
uint32_t rcp_mesh_flags = RC_MESH_REFERENCE;

int rcp_parse_mesh_mode(const char *cmd, const char *value)
{
    if (strcmp(value, "reference") == 0)
        rcp_mesh_flags = RC_MESH_REFERENCE;
    else if (strcmp(value, "copy") == 0)
        rcp_mesh_flags = RC_MESH_COPY;
    else
        return rcp_usage_error(cmd, "--mesh: expected reference or copy, got '%s'", value), -1;
    return 0;
}
uint32_t rcp_mesh_parts = 1;

static const char *const sensor_names[] = {"vlp16",       "vlp16-360", "os1-64", "d435",
                                           "livox-mid40", "ust-10lx",  "lds-01"};

int rcp_parse_sensor(const char *cmd, const char *s, uint32_t *preset)
{
    uint32_t p = rc_preset_from_name(s);
    if (p == 0) {
        size_t k;
        char list[128];
        size_t used = 0;
        list[0] = 0;
        for (k = 0; k < sizeof sensor_names / sizeof sensor_names[0]; k++)
            used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", sensor_names[k]);
        rcp_usage_error(cmd, "unknown sensor '%s' (choose one of: %s)", s, list);
        return -1;
    }
    *preset = p;
    return 0;
}

static rc_scene_desc scene_desc_for(const rcu_mesh *mesh, const rcu_mesh *parts, uint32_t part_count)
{
    rc_scene_desc sd = rc_scene_desc_default();
    uint64_t vertices = mesh->vertex_count;
    uint32_t k;
    if (part_count > 1)
        for (vertices = 0, k = 0; k < part_count; k++) vertices += parts[k].vertex_count;
    sd.max_geometries = part_count > 1 ? part_count : 1;
    sd.max_triangles = mesh->triangle_count;
    /* referenced in place (the default), or room for its copy (bench --mesh copy) */
    sd.max_vertices = rcp_mesh_flags == RC_MESH_COPY ? vertices : 0;
    sd.max_copied_triangles = rcp_mesh_flags == RC_MESH_COPY ? mesh->triangle_count : 0;
    sd.build_quality = rcp_build_quality;
    return sd;
}

int rcp_arena_bytes(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                    const rcu_mesh *parts, uint32_t part_count, const uint32_t *presets, uint32_t preset_count,
                    size_t *total, size_t *scene_bytes)
{
    rc_context_desc cd = rc_context_desc_default();
    size_t ctx_bytes = 0, sb = 0, sum;
    rc_status st;
    uint32_t k;
    cd.backend = backend;
    cd.device = rcp_device;
    cd.flags = rcp_context_flags;
    cd.thread_count = threads;
    if ((st = rc_context_memory_requirements(&cd, &ctx_bytes)) != RC_OK)
        return rcp_lib_error(cmd, NULL, "rc_context_memory_requirements", st);
    sum = ctx_bytes;
    if (mesh) {
        /* The scene's figure needs a context of the same backend: make a small
         * one (one thread, an arena of just its own size) to ask it. */
        rc_context_desc pd = cd;
        rc_context *probe = NULL;
        rc_scene_desc sd = scene_desc_for(mesh, parts, part_count);
        size_t probe_bytes = 0;
        pd.thread_count = 1;
        if ((st = rc_context_memory_requirements(&pd, &probe_bytes)) != RC_OK)
            return rcp_lib_error(cmd, NULL, "rc_context_memory_requirements", st);
        pd.memory_size = probe_bytes;
        const rcp_baked *baked = rcp_baked_of(mesh);
        if (create_context(cmd, &pd, &probe) != RCP_EXIT_OK) return RCP_EXIT_FAIL;
        st = baked ? rc_scene_baked_memory_requirements(probe, baked->blob, baked->bytes, &sb)
                   : rc_scene_memory_requirements(probe, &sd, &sb);
        if (st != RC_OK) {
            rcp_lib_error(cmd, probe, baked ? "rc_scene_baked_memory_requirements" : "rc_scene_memory_requirements",
                          st);
            rc_context_destroy(probe);
            return RCP_EXIT_FAIL;
        }
        rc_context_destroy(probe);
        sum += sb;
    }
    for (k = 0; k < preset_count; k++) {
        size_t b = 0;
        if ((st = rc_sensor_memory_requirements_preset(presets[k], &b)) != RC_OK)
            return rcp_lib_error(cmd, NULL, "rc_sensor_memory_requirements_preset", st);
        sum += b;
    }
    *total = sum;
    if (scene_bytes) *scene_bytes = sb;
    return RCP_EXIT_OK;
}

/* A commit's progress on a terminal: "rangecast CMD: bvh build 42%" rewritten
 * in place, a line per stage. Off when stderr is not a terminal (logs, CI)
 * and for maps that build in a blink. */
#define RCP_PROGRESS_MIN_TRIANGLES 500000u
typedef struct commit_progress {
    const char *cmd;
    char stage[32];
    int percent;
} commit_progress;

/* Ends the stage on the line: 100% when the work it measured is done (a
 * builder's last report can fall short of 1, or come as the next stage). */
static void finish_stage(commit_progress *p, int done)
{
    if (!p->stage[0] || p->percent >= 100) return;
    if (done) fprintf(stderr, "\rrangecast %s: %s 100%%", p->cmd, p->stage);
    fputc('\n', stderr);
    p->percent = 100;
}

static int show_progress(void *user, const char *stage, double fraction)
{
    commit_progress *p = (commit_progress *)user;
    const int percent = (int)(fraction * 100.0 + 0.5);
    if (strcmp(stage, p->stage) != 0) {
        finish_stage(p, 1); /* a new stage: the one before is over */
        if (fraction >= 1.0) return 1; /* a stage that starts done is only a marker ("commit") */
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->percent = -1;
    }
    if (percent == p->percent) return 1;
    p->percent = percent;
    fprintf(stderr, "\rrangecast %s: %s %3d%%", p->cmd, stage, percent);
    if (percent >= 100) fputc('\n', stderr);
    fflush(stderr);
    return 1;
}

void rcp_world_destroy(rcp_world *world)
{
    uint32_t k;
    if (!world) return;
    rc_context_destroy(world->ctx); /* scenes and sensors go with it */
    for (k = 0; k < world->part_count; k++) rcu_mesh_free(&world->parts[k]);
    free(world->parts);
    memset(world, 0, sizeof *world);
}

const char *rcp_device = NULL;
uint32_t rcp_context_flags = 0;
int rcp_order_room = 0;

/* Bytes a sensor of the caller's rays adds to rcp_arena_bytes' figure. */
static int rays_sensor_bytes(const char *cmd, uint32_t model, const rc_rays_desc *rays, size_t *bytes)
{
    rc_status st = rc_sensor_memory_requirements_rays(model, rays, bytes);
    if (st != RC_OK) return rcp_lib_error(cmd, NULL, "rc_sensor_memory_requirements_rays", st);
    return RCP_EXIT_OK;
}

static int world_create(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                        const uint32_t *presets, uint32_t preset_count, uint32_t rays_model,
                        const rc_rays_desc *rays, rcp_world *w);

int rcp_world_create(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                     const uint32_t *presets, uint32_t preset_count, rcp_world *w)
{
    return world_create(cmd, backend, threads, mesh, presets, preset_count, 0, NULL, w);
}

int rcp_world_create_rays(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                          uint32_t model, const rc_rays_desc *rays, rcp_world *w)
{
    return world_create(cmd, backend, threads, mesh, NULL, 0, model, rays, w);
}

static int world_create(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                        const uint32_t *presets, uint32_t preset_count, uint32_t rays_model,
                        const rc_rays_desc *rays, rcp_world *w)
{
    rc_context_desc cd = rc_context_desc_default();
    rc_status st;
    uint32_t k;
    const char *call;
    memset(w, 0, sizeof *w);
    if (preset_count > RCP_MAX_SENSORS) return rcp_fail(cmd, "too many sensors");
    if (mesh && rcp_mesh_parts > 1 && !rcp_baked_of(mesh)) {
        /* bench --meshes: the map as that many meshes of its own */
        w->parts = (rcu_mesh *)calloc(rcp_mesh_parts, sizeof *w->parts);
        if (!w->parts) return rcp_fail(cmd, "out of memory for %u meshes", rcp_mesh_parts);
        if (rcu_mesh_split(mesh, rcp_mesh_parts, w->parts) != 0) {
            rcp_fail(cmd, "--meshes %u: %s", rcp_mesh_parts, rcu_last_error());
            rcp_world_destroy(w);
            return RCP_EXIT_FAIL;
        }
        w->part_count = rcp_mesh_parts;
    }
    if (rcp_arena_bytes(cmd, backend, threads, mesh, w->parts, w->part_count, presets, preset_count,
                        &w->arena_bytes, &w->scene_bytes) != RCP_EXIT_OK) {
        rcp_world_destroy(w);
        return RCP_EXIT_FAIL;
    }
    if (rays) {
        size_t b = 0;
        if (rays_sensor_bytes(cmd, rays_model, rays, &b) != RCP_EXIT_OK) {
            rcp_world_destroy(w);
            return RCP_EXIT_FAIL;
        }
        w->arena_bytes += b;
    }
    if (rcp_order_room && mesh) {
        long cpus = threads ? (long)threads : sysconf(_SC_NPROCESSORS_ONLN);
        if (cpus < 1) cpus = 1;
        if (cpus > (long)RC_MAX_THREADS) cpus = (long)RC_MAX_THREADS;
        w->arena_bytes += (size_t)cpus * RC_SIMULATE_SCRATCH_PER_THREAD;
    }
    cd.backend = backend;
    cd.device = rcp_device;
    cd.flags = rcp_context_flags;
    cd.thread_count = threads;
    cd.memory = NULL;             /* the library mallocs exactly this much, once */
    cd.memory_size = w->arena_bytes;
    if (create_context(cmd, &cd, &w->ctx) != RCP_EXIT_OK) {
        rcp_world_destroy(w);
        return RCP_EXIT_FAIL;
    }
    rc_context_get_backend(w->ctx, &w->backend);
    rc_context_get_thread_count(w->ctx, &w->threads);
    if (mesh && rcp_baked_of(mesh)) {
        /* a baked map: loaded in place, checked, no build */
        const rcp_baked *baked = rcp_baked_of(mesh);
        const double t0 = rcu_now();
        call = "rc_scene_load_baked";
        if ((st = rc_scene_load_baked(w->ctx, baked->blob, baked->bytes, 0, &w->scene)) != RC_OK) goto fail;
        w->build_s = rcu_now() - t0;
    } else if (mesh) {
        rc_scene_desc sd = scene_desc_for(mesh, w->parts, w->part_count);
        rc_mesh_desc md = rc_mesh_desc_default();
        uint32_t geom = 0, part;
        double t0;
        call = "rc_scene_create";
        if ((st = rc_scene_create(w->ctx, &sd, &w->scene)) != RC_OK) goto fail;
        call = "rc_scene_add_mesh";
        for (part = 0; part < (w->part_count ? w->part_count : 1u); part++) {
            const rcu_mesh *m = w->part_count ? &w->parts[part] : mesh;
            md.flags = rcp_mesh_flags;
            md.vertices = m->vertices;
            md.vertex_count = m->vertex_count;
            md.indices = m->indices;
            md.triangle_count = m->triangle_count;
            if ((st = rc_scene_add_mesh(w->scene, &md, &geom)) != RC_OK) goto fail;
        }
        call = "rc_scene_commit";
        t0 = rcu_now();
        if (mesh->triangle_count >= RCP_PROGRESS_MIN_TRIANGLES && isatty(STDERR_FILENO)) {
            commit_progress p;
            memset(&p, 0, sizeof p);
            p.cmd = cmd;
            st = rc_scene_commit_with_progress(w->scene, show_progress, &p);
            finish_stage(&p, st == RC_OK);
        } else {
            st = rc_scene_commit(w->scene);
        }
        if (st != RC_OK) goto fail;
        w->build_s = rcu_now() - t0;
    }
    call = "rc_sensor_create_preset";
    for (k = 0; k < preset_count; k++) {
        if ((st = rc_sensor_create_preset(w->ctx, presets[k], &w->sensors[k])) != RC_OK) goto fail;
        w->sensor_count++;
    }
    if (rays) {
        call = "rc_sensor_create_rays";
        if ((st = rc_sensor_create_rays(w->ctx, rays_model, rays, &w->sensors[w->sensor_count])) != RC_OK) goto fail;
        w->sensor_count++;
    }
    return RCP_EXIT_OK;
fail:
    rcp_lib_error(cmd, w->ctx, call, st);
    if (st == RC_ERR_OUT_OF_MEMORY)
        fprintf(stderr, "rangecast %s: (the arena was sized with rc_*_memory_requirements to %zu bytes; "
                        "the library's size query and its use disagree)\n", cmd, w->arena_bytes);
    rcp_world_destroy(w);
    return RCP_EXIT_FAIL;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double rcp_median(double *v, size_t n)
{
    if (n == 0) return NAN;
    qsort(v, n, sizeof v[0], cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

const char *rcp_thousands(uint64_t v, char *buf, size_t size)
{
    char tmp[32];
    int n = snprintf(tmp, sizeof tmp, "%llu", (unsigned long long)v), i, o = 0;
    for (i = 0; i < n && (size_t)o + 2 < size; i++) {
        if (i > 0 && (n - i) % 3 == 0) buf[o++] = ',';
        buf[o++] = tmp[i];
    }
    buf[o] = 0;
    return buf;
}

const char *rcp_bytes(uint64_t v, char *buf, size_t size)
{
    if (v >= (1ull << 30)) snprintf(buf, size, "%.2f GiB", (double)v / (double)(1ull << 30));
    else if (v >= (1ull << 20)) snprintf(buf, size, "%.1f MiB", (double)v / (double)(1ull << 20));
    else if (v >= (1ull << 10)) snprintf(buf, size, "%.1f KiB", (double)v / 1024.0);
    else snprintf(buf, size, "%llu B", (unsigned long long)v);
    return buf;
}
