#define _POSIX_C_SOURCE 200809L
#include "rc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const uint32_t rct_backends[3] = {RC_BACKEND_BVH, RC_BACKEND_EMBREE, RC_BACKEND_VULKAN};

int rct_quick(void)
{
    const char *q = getenv("RC_TEST_QUICK");
    return q && q[0] && q[0] != '0';
}

int rct_env_on(const char *name)
{
    const char *v = getenv(name);
    return v && v[0] && v[0] != '0';
}

/* NVIDIA's Vulkan driver can be loaded only about 25 times in one process:
 * the loader dlopens it at every vkCreateInstance and dlcloses it at
 * vkDestroyInstance, and glibc does not give back the static TLS the driver
 * takes (docs/architecture.md, "Vulkan on NVIDIA"). A suite makes contexts
 * case after case, so the first usable Vulkan context is kept until exit: the
 * driver stays loaded, as in an application that keeps its context. */
static rc_context *vulkan_anchor;

static void drop_vulkan_anchor(void)
{
    rc_context_destroy(vulkan_anchor);
    vulkan_anchor = NULL;
}

int rct_backend_usable(uint32_t backend)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_status st;
    const char *skip = getenv("RC_TEST_SKIP_BACKENDS"); /* e.g. "vulkan" under valgrind */
    if (!rc_backend_available(backend)) {
        print_message("SKIP: backend %s is not built in\n", rc_backend_name(backend));
        return 0;
    }
    if (skip && strstr(skip, rc_backend_name(backend))) {
        print_message("SKIP: backend %s is in RC_TEST_SKIP_BACKENDS\n", rc_backend_name(backend));
        return 0;
    }
    d.backend = backend;
    d.thread_count = 1;
    d.memory_size = (size_t)1 << 20;
    st = rc_context_create(&d, &ctx);
    if (st != RC_OK && backend == RC_BACKEND_VULKAN && rct_env_on("RC_TEST_REQUIRE_RAY_QUERY"))
        fail_msg("backend vulkan is required here (RC_TEST_REQUIRE_RAY_QUERY) but not usable: %s",
                 rc_status_string(st));
    if (st != RC_OK) {
        print_message("SKIP: backend %s is built in but not usable here: %s\n", rc_backend_name(backend),
                      rc_status_string(st));
        return 0;
    }
    if (backend == RC_BACKEND_VULKAN && !vulkan_anchor && atexit(drop_vulkan_anchor) == 0) {
        vulkan_anchor = ctx;
        return 1;
    }
    rc_context_destroy(ctx);
    return 1;
}

rc_context *rct_context(uint32_t backend, uint32_t threads, size_t arena_mb)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_status st;
    d.backend = backend;
    d.thread_count = threads;
    d.memory_size = (arena_mb ? arena_mb : 64) << 20;
    st = rc_context_create(&d, &ctx);
    if (st != RC_OK) fail_msg("rc_context_create(%s): %s", rc_backend_name(backend), rc_status_string(st));
    return ctx;
}

rc_scene *rct_scene_uncommitted(rc_context *ctx, const rcu_mesh *mesh, uint32_t flags, uint32_t build_quality)
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_scene *scene = NULL;
    uint32_t geom = 99;
    sd.max_geometries = 1;
    sd.max_triangles = mesh->triangle_count;
    if (flags == RC_MESH_COPY) {
        sd.max_vertices = mesh->vertex_count;
        sd.max_copied_triangles = mesh->triangle_count;
    }
    sd.build_quality = build_quality;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.flags = flags;
    md.vertices = mesh->vertices;
    md.vertex_count = mesh->vertex_count;
    md.indices = mesh->indices;
    md.triangle_count = mesh->triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &geom));
    assert_int_equal(geom, 0);
    return scene;
}

static uint64_t budgeted_bytes(rc_context *ctx, uint32_t backend)
{
    rc_memory_stats ms = rc_memory_stats_default();
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &ms));
    return backend == RC_BACKEND_VULKAN ? ms.device_bytes : ms.backend_bytes;
}

void rct_check_budget(uint32_t backend, uint32_t preset, uint32_t rays)
{
    static const uint32_t budgets_mib[] = {1u, 64u};
    const float r_lo = 19.9f, r_hi = 20.0f;
    rcu_mesh sphere;
    const rcu_mesh *mesh = &sphere;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    uint32_t b, i;
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &sphere), 0);
    rct_buffers_alloc(&buf, rays, RC_ATTR_HITS | RC_ATTR_RANGES);
    for (b = 0; b < 2; ++b) {
        rc_context_desc d = rc_context_desc_default();
        rc_scene_info info = rc_scene_info_default();
        rc_context *ctx = NULL;
        rc_scene *scene;
        rc_sensor *sensor;
        uint64_t budget = (uint64_t)budgets_mib[b] << 20, before;
        rc_status st;
        d.backend = backend;
        d.thread_count = 2;
        d.memory_size = (size_t)64 << 20;
        d.backend_budget_mib = budgets_mib[b];
        RCT_OK(NULL, rc_context_create(&d, &ctx));
        RCT_OK(ctx, rc_sensor_create_preset(ctx, preset, &sensor));
        scene = rct_scene_uncommitted(ctx, mesh, RC_MESH_REFERENCE, RC_BUILD_BALANCED);
        before = budgeted_bytes(ctx, backend);
        st = rc_scene_commit(scene);
        assert_true(budgeted_bytes(ctx, backend) <= budget);
        if (budgets_mib[b] == 1u) {
            if (st != RC_ERR_OUT_OF_MEMORY || !strstr(rc_context_last_error(ctx), "budget"))
                fail_msg("%s, 1 MiB budget: commit gave %s (%s)", rc_backend_name(backend), rc_status_string(st),
                         rc_context_last_error(ctx));
            print_message("1 MiB budget refused: %s\n", rc_context_last_error(ctx));
            /* Vulkan frees every buffer of the failed commit (Embree keeps the
             * meshes it made for the next commit) */
            if (backend == RC_BACKEND_VULKAN) assert_true(budgeted_bytes(ctx, backend) == before);
            RCT_OK(ctx, rc_scene_get_info(scene, &info));
            assert_int_equal(info.committed, 0);
            assert_int_equal(rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res), RC_ERR_NOT_COMMITTED);
        } else {
            RCT_OK(ctx, st);
            RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
            for (i = 0; i < rays; ++i) {
                assert_int_equal(buf.res.hits[i], 1);
                assert_true(buf.res.ranges[i] >= r_lo && buf.res.ranges[i] <= r_hi);
            }
        }
        rc_context_destroy(ctx);
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&sphere);
}

rc_scene *rct_scene_mesh(rc_context *ctx, const rcu_mesh *mesh, uint32_t flags)
{
    rc_scene *scene = rct_scene_uncommitted(ctx, mesh, flags, RC_BUILD_BALANCED);
    RCT_OK(ctx, rc_scene_commit(scene));
    return scene;
}

rc_scene *rct_scene_meshes(rc_context *ctx, const rcu_mesh *const *meshes, uint32_t count)
{
    return rct_scene_instanced(ctx, meshes, count, NULL, NULL, 0);
}

rc_scene *rct_scene_instanced(rc_context *ctx, const rcu_mesh *const *meshes, uint32_t count, const rc_scene *src,
                              const rc_pose *transforms, uint32_t inst_count)
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_scene *scene = NULL;
    uint32_t g, id;
    sd.max_geometries = count;
    sd.max_triangles = 0;
    sd.max_instances = inst_count;
    for (g = 0; g < count; ++g) sd.max_triangles += meshes[g]->triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    for (g = 0; g < count; ++g) {
        rc_mesh_desc md = rc_mesh_desc_default();
        md.vertices = meshes[g]->vertices;
        md.vertex_count = meshes[g]->vertex_count;
        md.indices = meshes[g]->indices;
        md.triangle_count = meshes[g]->triangle_count;
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &id));
        assert_int_equal(id, g);
    }
    for (g = 0; g < inst_count; ++g) {
        rc_instance_desc in = rc_instance_desc_default();
        in.source = src;
        in.transform = transforms[g];
        RCT_OK(ctx, rc_scene_add_instance(scene, &in, &id));
        assert_int_equal(id, g);
    }
    RCT_OK(ctx, rc_scene_commit(scene));
    return scene;
}

rc_sensor *rct_sensor_rays(rc_context *ctx, const float *dirs, const float *origins, uint32_t n, float rmin,
                           float rmax)
{
    rc_rays_desc d = rc_rays_desc_default();
    rc_sensor *s = NULL;
    d.common.range_min = rmin;
    d.common.range_max = rmax;
    d.directions = dirs;
    d.origins = origins;
    d.ray_count = n;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, origins ? RC_SENSOR_ONDN : RC_SENSOR_O1DN, &d, &s));
    return s;
}

rc_sensor *rct_sensor_dirs(rc_context *ctx, const float *dirs, uint32_t n, float rmin, float rmax)
{
    return rct_sensor_rays(ctx, dirs, NULL, n, rmin, rmax);
}

double rct_ray_plane_t(const double o[3], const double d[3], const float v0[3], const float v1[3], const float v2[3])
{
    double e1[3], e2[3], n[3], w[3], dn;
    int k;
    for (k = 0; k < 3; ++k) {
        e1[k] = (double)v1[k] - v0[k];
        e2[k] = (double)v2[k] - v0[k];
        w[k] = (double)v0[k] - o[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    dn = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (dn == 0.0) return INFINITY;
    return (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]) / dn;
}

uint32_t rct_brute_nearest(const rcu_mesh *mesh, const double o[3], const double d[3], double *t_out)
{
    uint32_t best = UINT32_MAX, i;
    double bt = INFINITY;
    for (i = 0; i < mesh->triangle_count; ++i) {
        const float *a = mesh->vertices + 3u * mesh->indices[3u * i];
        const float *b = mesh->vertices + 3u * mesh->indices[3u * i + 1];
        const float *c = mesh->vertices + 3u * mesh->indices[3u * i + 2];
        double e1[3], e2[3], p[3], s[3], q[3], det, u, v, t;
        int k;
        for (k = 0; k < 3; ++k) {
            e1[k] = (double)b[k] - a[k];
            e2[k] = (double)c[k] - a[k];
            s[k] = o[k] - a[k];
        }
        p[0] = d[1] * e2[2] - d[2] * e2[1];
        p[1] = d[2] * e2[0] - d[0] * e2[2];
        p[2] = d[0] * e2[1] - d[1] * e2[0];
        det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (det == 0.0) continue;
        u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
        q[0] = s[1] * e1[2] - s[2] * e1[1];
        q[1] = s[2] * e1[0] - s[0] * e1[2];
        q[2] = s[0] * e1[1] - s[1] * e1[0];
        v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        if (u < -1e-9 || v < -1e-9 || u + v > 1.0 + 1e-9 || t <= 0.0) continue;
        if (t < bt) {
            bt = t;
            best = i;
        }
    }
    *t_out = bt;
    return best;
}

rc_pose rct_pose(float x, float y, float z)
{
    rc_pose p = rc_pose_identity();
    p.position[0] = x;
    p.position[1] = y;
    p.position[2] = z;
    return p;
}

rc_pose rct_pose_ypr(float x, float y, float z, double yaw, double pitch, double roll)
{
    rc_pose p = rct_pose(x, y, z);
    double cy = cos(yaw * 0.5), sy = sin(yaw * 0.5);
    double cp = cos(pitch * 0.5), sp = sin(pitch * 0.5);
    double cr = cos(roll * 0.5), sr = sin(roll * 0.5);
    p.orientation[3] = (float)(cr * cp * cy + sr * sp * sy);
    p.orientation[0] = (float)(sr * cp * cy - cr * sp * sy);
    p.orientation[1] = (float)(cr * sp * cy + sr * cp * sy);
    p.orientation[2] = (float)(cr * cp * sy - sr * sp * cy);
    return p;
}

void rct_buffers_alloc(rct_buffers *b, uint64_t n, uint32_t attributes)
{
    memset(b, 0, sizeof *b);
    b->res = rc_results_default();
    b->res.attributes = attributes;
    b->res.capacity = n;
    b->n = n;
    b->res.hits = (uint8_t *)malloc(n);
    b->res.ranges = (float *)malloc(n * sizeof(float));
    b->res.points = (float *)malloc(n * 3 * sizeof(float));
    b->res.normals = (float *)malloc(n * 3 * sizeof(float));
    b->res.prim_ids = (uint32_t *)malloc(n * sizeof(uint32_t));
    b->res.geom_ids = (uint32_t *)malloc(n * sizeof(uint32_t));
    b->res.inst_ids = (uint32_t *)malloc(n * sizeof(uint32_t));
    assert_non_null(b->res.hits);
    assert_non_null(b->res.inst_ids);
}

void rct_buffers_fill(rct_buffers *b, unsigned char pattern)
{
    uint64_t n = b->n;
    memset(b->res.hits, pattern, n);
    memset(b->res.ranges, pattern, n * sizeof(float));
    memset(b->res.points, pattern, n * 3 * sizeof(float));
    memset(b->res.normals, pattern, n * 3 * sizeof(float));
    memset(b->res.prim_ids, pattern, n * sizeof(uint32_t));
    memset(b->res.geom_ids, pattern, n * sizeof(uint32_t));
    memset(b->res.inst_ids, pattern, n * sizeof(uint32_t));
}

static int all_bytes(const void *p, size_t n, unsigned char v)
{
    const unsigned char *c = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i)
        if (c[i] != v) return 0;
    return 1;
}

int rct_buffers_untouched(const rct_buffers *b, unsigned char pattern)
{
    uint64_t n = b->n;
    return all_bytes(b->res.hits, n, pattern) && all_bytes(b->res.ranges, n * 4, pattern) &&
           all_bytes(b->res.points, n * 12, pattern) && all_bytes(b->res.normals, n * 12, pattern) &&
           all_bytes(b->res.prim_ids, n * 4, pattern) && all_bytes(b->res.geom_ids, n * 4, pattern) &&
           all_bytes(b->res.inst_ids, n * 4, pattern);
}

void rct_buffers_free(rct_buffers *b)
{
    free(b->res.hits);
    free(b->res.ranges);
    free(b->res.points);
    free(b->res.normals);
    free(b->res.prim_ids);
    free(b->res.geom_ids);
    free(b->res.inst_ids);
    memset(b, 0, sizeof *b);
}

void *rct_alloc16(size_t size)
{
    void *p = NULL;
    if (posix_memalign(&p, 16, size ? size : 16) != 0) return NULL;
    return p;
}

void rct_assert_same_results(const rct_buffers *a, const rct_buffers *b)
{
    const uint64_t n = a->n;
    assert_int_equal(a->n, b->n);
    assert_memory_equal(a->res.hits, b->res.hits, n);
    assert_memory_equal(a->res.ranges, b->res.ranges, n * sizeof(float));
    assert_memory_equal(a->res.points, b->res.points, n * 3u * sizeof(float));
    assert_memory_equal(a->res.normals, b->res.normals, n * 3u * sizeof(float));
    assert_memory_equal(a->res.prim_ids, b->res.prim_ids, n * sizeof(uint32_t));
    assert_memory_equal(a->res.geom_ids, b->res.geom_ids, n * sizeof(uint32_t));
    assert_memory_equal(a->res.inst_ids, b->res.inst_ids, n * sizeof(uint32_t));
}
