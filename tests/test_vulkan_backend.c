/* The Vulkan backend's own contracts: the C/GLSL layout (read back on the
 * device), the packed arrays (a C traversal of them finds exactly what the
 * scene's own traversal finds), device choice, memory figures and arena
 * accounting, binding limits, the sensor cache, device loss, and commits
 * that only moved instances rewriting only the instances and the top level. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "backend/vulkan_internal.h"
#include "poses.h"
#include "rc_test.h"

#define NEED_VULKAN()                                   \
    do {                                                \
        if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip(); \
    } while (0)

static char g_log[1024];

static void capture_log(void *user, uint32_t level, const char *message)
{
    (void)user;
    size_t n = strlen(g_log);
    if (level == RC_LOG_ERROR && n + 2 < sizeof g_log) snprintf(g_log + n, sizeof g_log - n, "%s\n", message);
}

static void test_layout_contract(void **state)
{
    rc_context *ctx;
    (void)state;
    NEED_VULKAN();
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    RCT_OK(ctx, rc__vk_layout_check(ctx));
    rc_context_destroy(ctx);
}

/* A scene of two meshes (one strided) and four instances of a two-mesh scene. */
typedef struct scene_set {
    rcu_mesh sphere, box, cyl;
    float *strided;
    rc_scene *src, *world;
} scene_set;

static void scenes_make(rc_context *ctx, scene_set *s)
{
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, base[3] = {0, 0, -1};
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    uint32_t g, i;
    memset(s, 0, sizeof *s);
    assert_int_equal(rcu_mesh_uv_sphere(15.0f, 64, 32, &s->sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &s->box), 0);
    assert_int_equal(rcu_mesh_cylinder(base, 0.5f, 2.0f, 16, &s->cyl), 0);
    s->strided = (float *)calloc(5u * s->box.vertex_count, sizeof(float));
    assert_non_null(s->strided);
    for (i = 0; i < s->box.vertex_count; ++i) memcpy(s->strided + 5u * i, s->box.vertices + 3u * i, 12);
    /* the instanced source: a box and a cylinder */
    sd.max_geometries = 2;
    sd.max_triangles = s->box.triangle_count + s->cyl.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &s->src));
    md.vertices = s->box.vertices;
    md.vertex_count = s->box.vertex_count;
    md.indices = s->box.indices;
    md.triangle_count = s->box.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(s->src, &md, &g));
    md.vertices = s->cyl.vertices;
    md.vertex_count = s->cyl.vertex_count;
    md.indices = s->cyl.indices;
    md.triangle_count = s->cyl.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(s->src, &md, &g));
    RCT_OK(ctx, rc_scene_commit(s->src));
    /* the world: sphere, a strided box, four instances */
    sd.max_geometries = 2;
    sd.max_instances = 4;
    sd.max_triangles = s->sphere.triangle_count + s->box.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &s->world));
    md.vertices = s->sphere.vertices;
    md.vertex_count = s->sphere.vertex_count;
    md.indices = s->sphere.indices;
    md.triangle_count = s->sphere.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(s->world, &md, &g));
    md.vertices = s->strided;
    md.vertex_stride = 20;
    md.vertex_count = s->box.vertex_count;
    md.indices = s->box.indices;
    md.triangle_count = s->box.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(s->world, &md, &g));
    id.source = s->src;
    for (i = 0; i < 4; ++i) {
        id.transform = rct_pose_ypr(-6.0f + 4.0f * (float)i, 3.0f - 2.0f * (float)i, 0.5f * (float)i, 0.7 * i, 0.2, 0.1 * i);
        id.scale[0] = 1.0f + 0.5f * (float)i;
        id.scale[1] = 1.5f;
        id.scale[2] = 0.75f + 0.25f * (float)i;
        RCT_OK(ctx, rc_scene_add_instance(s->world, &id, &g));
    }
    RCT_OK(ctx, rc_scene_commit(s->world));
}

static void scenes_free(scene_set *s)
{
    rcu_mesh_free(&s->sphere);
    rcu_mesh_free(&s->box);
    rcu_mesh_free(&s->cyl);
    free(s->strided);
}

static void linear_span(rc__vk_span *sp, uint64_t count, uint32_t elem)
{
    memset(sp, 0, sizeof *sp);
    sp->shift = 31;
    sp->elem_size = elem;
    sp->chunk[0] = (unsigned char *)malloc((size_t)(count ? count : 1) * elem);
    assert_non_null(sp->chunk[0]);
}

/* The packed arrays, walked by the C traversal with the CPU's inner tests,
 * give bit for bit what rc__scene_intersect gives: the packing is right. */
static void test_packed_arrays(void **state)
{
    rc_context *ctx;
    rc__vk_state *st;
    scene_set s;
    rc__vk_pack_info info;
    rc__vk_pack_dst dst;
    rc__vk_packed p;
    rcu_rng rng;
    uint32_t i, hits = 0;
    (void)state;
    NEED_VULKAN();
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    st = rc__vk(ctx);
    scenes_make(ctx, &s);
    rc__vk_pack_count(s.world, ++st->serial, &info);
    assert_int_equal(info.geoms, 4);  /* 2 own + the source's 2, once */
    assert_int_equal(info.insts, 4);
    linear_span(&dst.nodes, info.nodes, sizeof(rc__bvh_node));
    linear_span(&dst.refs, info.refs, 4);
    linear_span(&dst.tris, info.tris, 12);
    linear_span(&dst.verts, info.verts, 12);
    linear_span(&dst.geoms, info.geoms, sizeof(rc__vk_geom));
    linear_span(&dst.insts, info.insts, sizeof(rc__vk_inst));
    assert_true(info.max_wide > 0);
    dst.wide_scratch = NULL; /* one chunk: every tree collapsed in place */
    rc__vk_pack_fill(s.world, st->serial, &info, &dst);
    p.info = info;
    p.nodes = (const rc__bvh_node *)(const void *)dst.nodes.chunk[0];
    p.refs = (const uint32_t *)(const void *)dst.refs.chunk[0];
    p.tris = (const uint32_t *)(const void *)dst.tris.chunk[0];
    p.verts = (const float *)(const void *)dst.verts.chunk[0];
    p.geoms = (const rc__vk_geom *)(const void *)dst.geoms.chunk[0];
    p.insts = (const rc__vk_inst *)(const void *)dst.insts.chunk[0];
    rcu_rng_seed(&rng, 5);
    for (i = 0; i < 50000; ++i) {
        float o[3], d[3];
        rc__ray ray;
        rc__hit a, b;
        int fa, fb, k;
        for (k = 0; k < 3; ++k) {
            o[k] = (float)(16.0 * rcu_rng_uniform(&rng) - 8.0);
            d[k] = (float)(2.0 * rcu_rng_uniform(&rng) - 1.0);
        }
        if (i % 100 == 0) d[i / 100 % 3] = 0.0f; /* axis-parallel components */
        rc__ray_prepare(&ray, o, d);
        a.t = b.t = 100.0f;
        a.prim = a.geom = a.inst = b.prim = b.geom = b.inst = RC_INVALID_ID;
        fa = rc__scene_intersect(s.world, &ray, &a);
        fb = rc__vk_packed_intersect(&p, &ray, &b);
        assert_int_equal(fa, fb);
        if (memcmp(&a.t, &b.t, 4) != 0 || a.prim != b.prim || a.geom != b.geom || a.inst != b.inst)
            fail_msg("ray %u: scene t %.9g prim %u geom %u inst %u; packed t %.9g prim %u geom %u inst %u", i,
                     (double)a.t, a.prim, a.geom, a.inst, (double)b.t, b.prim, b.geom, b.inst);
        hits += (uint32_t)fa;
    }
    assert_true(hits > 40000); /* inside the sphere nearly every ray hits something */
    free(dst.nodes.chunk[0]);
    free(dst.refs.chunk[0]);
    free(dst.tris.chunk[0]);
    free(dst.verts.chunk[0]);
    free(dst.geoms.chunk[0]);
    free(dst.insts.chunk[0]);
    scenes_free(&s);
    rc_context_destroy(ctx);
}

static rc_status create_with_device(const char *device, rc_context **ctx)
{
    rc_context_desc d = rc_context_desc_default();
    rc_status st;
    d.backend = RC_BACKEND_VULKAN;
    d.thread_count = 1;
    d.memory_size = (size_t)4 << 20;
    d.log = capture_log;
    g_log[0] = '\0';
    setenv("RANGECAST_VULKAN_DEVICE", device, 1);
    st = rc_context_create(&d, ctx);
    unsetenv("RANGECAST_VULKAN_DEVICE");
    return st;
}

static void test_device_choice(void **state)
{
    rc_context *ctx = NULL;
    rc_context_desc d = rc_context_desc_default();
    uint32_t backend = 99;
    const char *name;
    char lowered[256];
    size_t i;
    (void)state;
    NEED_VULKAN();
    /* by index and by name (any case) */
    assert_int_equal(create_with_device("0", &ctx), RC_OK);
    name = rc__vk_device_name(ctx, NULL, NULL);
    assert_non_null(name);
    print_message("device 0: %s\n", name);
    for (i = 0; name[i] && i + 1 < sizeof lowered; ++i)
        lowered[i] = (char)(name[i] >= 'A' && name[i] <= 'Z' ? name[i] - 'A' + 'a' : name[i]);
    lowered[i < 3 ? i : 3] = '\0';
    rc_context_destroy(ctx);
    assert_int_equal(create_with_device(lowered, &ctx), RC_OK);
    rc_context_destroy(ctx);
    /* no such device: UNSUPPORTED with a message naming the variable */
    assert_int_equal(create_with_device("no-such-gpu-anywhere", &ctx), RC_ERR_UNSUPPORTED);
    assert_non_null(strstr(g_log, "RANGECAST_VULKAN_DEVICE"));
    assert_int_equal(create_with_device("97", &ctx), RC_ERR_UNSUPPORTED);
    assert_non_null(strstr(g_log, "97"));
    /* AUTO never picks Vulkan */
    d.thread_count = 1;
    d.memory_size = (size_t)1 << 20;
    RCT_OK(NULL, rc_context_create(&d, &ctx));
    RCT_OK(ctx, rc_context_get_backend(ctx, &backend));
    assert_int_not_equal(backend, RC_BACKEND_VULKAN);
    rc_context_destroy(ctx);
}

/* Arena figures are exact; device and driver memory are reported and given back. */
static void test_memory_accounting(void **state)
{
    rc_context_desc d = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_memory_stats ms = rc_memory_stats_default();
    size_t cbytes = 0, sbytes = 0, ebytes = 0;
    rcu_mesh m;
    int attempt;
    (void)state;
    NEED_VULKAN();
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 20000, &m), 0);
    d.backend = RC_BACKEND_VULKAN;
    d.thread_count = 1;
    sd.max_triangles = m.triangle_count;
    md.vertices = m.vertices;
    md.vertex_count = m.vertex_count;
    md.indices = m.indices;
    md.triangle_count = m.triangle_count;
    assert_int_equal(rc_context_memory_requirements(&d, &cbytes), RC_OK);
    assert_int_equal(rc_sensor_memory_requirements_preset(RC_PRESET_VELODYNE_VLP16, &ebytes), RC_OK);
    for (attempt = 0; attempt < 2; ++attempt) {
        rc_context *ctx = NULL;
        rc_scene *scene = NULL;
        rc_sensor *sensor = NULL;
        uint32_t g;
        size_t total;
        void *block;
        rc_status st;
        rct_buffers buf;
        rc_pose pose = rct_pose(1, 2, 3);
        if (attempt == 0) {
            /* the scene's requirement needs a context of this backend */
            d.memory = NULL;
            d.memory_size = (size_t)8 << 20;
            RCT_OK(NULL, rc_context_create(&d, &ctx));
            RCT_OK(ctx, rc_scene_memory_requirements(ctx, &sd, &sbytes));
            rc_context_destroy(ctx);
        }
        total = cbytes + sbytes + ebytes - (attempt ? 16u : 0u);
        block = rct_alloc16(total);
        assert_non_null(block);
        d.memory = block;
        d.memory_size = total;
        RCT_OK(NULL, rc_context_create(&d, &ctx));
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
        RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
        st = rc_scene_commit(scene);
        if (attempt == 1) {
            assert_int_equal(st, RC_ERR_OUT_OF_MEMORY);
        } else {
            RCT_OK(ctx, st);
            RCT_OK(ctx, rc_context_get_memory_stats(ctx, &ms));
            assert_int_equal(ms.arena_peak, total); /* every byte, exactly */
            assert_true(ms.device_bytes >= (uint64_t)m.triangle_count * 12u);
            assert_true(ms.backend_bytes > 0);
            print_message("arena %llu bytes (context %llu, scene %llu, sensor %llu); device %llu; driver host %llu\n",
                          (unsigned long long)total, (unsigned long long)cbytes, (unsigned long long)sbytes,
                          (unsigned long long)ebytes, (unsigned long long)ms.device_bytes,
                          (unsigned long long)ms.backend_bytes);
            rct_buffers_alloc(&buf, 16 * 900, RC_ATTR_RANGES);
            RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
            assert_true(buf.res.ranges[0] > 0.0f && isfinite(buf.res.ranges[0]));
            rct_buffers_free(&buf);
            {
                uint64_t with_scene = ms.device_bytes;
                RCT_OK(ctx, rc_scene_destroy(scene));
                RCT_OK(ctx, rc_context_get_memory_stats(ctx, &ms));
                assert_true(ms.device_bytes < with_scene);
                assert_true(ms.device_bytes <= with_scene - (uint64_t)m.triangle_count * 12u);
            }
        }
        rc_context_destroy(ctx);
        free(block);
    }
    rcu_mesh_free(&m);
}

/* rc_context_desc.backend_budget_mib caps the device memory: 1 MiB cannot
 * hold the 100k-triangle sphere (its index array alone is 1.2 MB); 64 MiB can. */
static void test_budget(void **state)
{
    (void)state;
    NEED_VULKAN();
    rct_check_budget(RC_BACKEND_VULKAN, RC_PRESET_VELODYNE_VLP16, 16u * 900u);
}

/* A scene over the (test-lowered) binding limit: RC_ERR_OUT_OF_MEMORY naming
 * the array and maxStorageBufferRange; the context stays usable. */
static void test_binding_limits(void **state)
{
    rc_context *ctx;
    rc_scene *scene;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rcu_mesh big, small;
    uint32_t g;
    const char *err;
    (void)state;
    NEED_VULKAN();
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 20000, &big), 0);
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 16, 8, &small), 0);
    setenv("RANGECAST_VULKAN_MAX_BINDING", "65536", 1);
    setenv("RANGECAST_VULKAN_CHUNKS", "1", 1);
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    unsetenv("RANGECAST_VULKAN_MAX_BINDING");
    unsetenv("RANGECAST_VULKAN_CHUNKS");
    sd.max_triangles = big.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = big.vertices;
    md.vertex_count = big.vertex_count;
    md.indices = big.indices;
    md.triangle_count = big.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    assert_int_equal(rc_scene_commit(scene), RC_ERR_OUT_OF_MEMORY);
    err = rc_context_last_error(ctx);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "maxStorageBufferRange"));
    assert_non_null(strstr(err, "BVH nodes"));
    RCT_OK(ctx, rc_scene_destroy(scene));
    scene = rct_scene_mesh(ctx, &small, RC_MESH_REFERENCE);
    {
        rc_sensor *sensor;
        rct_buffers buf;
        rc_pose pose = rct_pose(0, 0, 0);
        uint32_t i;
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
        rct_buffers_alloc(&buf, 16 * 360, RC_ATTR_HITS | RC_ATTR_RANGES);
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < 16 * 360; ++i) assert_true(buf.res.hits[i] == 1 && buf.res.ranges[i] < 5.0f);
        rct_buffers_free(&buf);
    }
    rc_context_destroy(ctx);
    rcu_mesh_free(&big);
    rcu_mesh_free(&small);
}

/* VLP-16 ranges and hits of one pose inside a sphere, from a context made
 * with the environment variable name=value (NULL: none). */
static void sphere_scan(const char *name, const char *value, float *ranges, uint8_t *hits)
{
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rct_buffers buf;
    rcu_mesh m;
    rc_pose pose = rct_pose(1.0f, -2.0f, 0.5f);
    const uint32_t n = 16u * 360u;
    if (name) setenv(name, value, 1);
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    if (name) unsetenv(name);
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 64, 32, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rct_buffers_alloc(&buf, n, RC_ATTR_HITS | RC_ATTR_RANGES);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    memcpy(ranges, buf.res.ranges, n * sizeof *ranges);
    memcpy(hits, buf.res.hits, n);
    rct_buffers_free(&buf);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* The measurement switches reach the kernel (tools/device/gpu-run.sh split
 * reads its stages' costs from them): without the walk every ray takes
 * triangle slot 0's plane, so ranges leave the sphere; without the float64
 * refinement hits stay and ranges move by float rounding only. The
 * statistics switch, which lavapipe cannot honour, changes nothing. */
static void test_measurement_switches(void **state)
{
    enum { N = 16 * 360 };
    static float full[N], other[N];
    static uint8_t hits[N], other_hits[N];
    uint32_t i, moved = 0, off_sphere = 0;
    (void)state;
    NEED_VULKAN();
    sphere_scan(NULL, NULL, full, hits);
    for (i = 0; i < N; ++i) assert_true(hits[i] == 1 && full[i] > 17.0f && full[i] < 23.0f);
    sphere_scan("RANGECAST_VULKAN_SKIP", "refine", other, other_hits);
    for (i = 0; i < N; ++i) {
        assert_int_equal(other_hits[i], 1);
        assert_true(fabsf(other[i] - full[i]) <= 1e-5f * full[i]);
        moved += other[i] != full[i];
    }
    print_message("skip refine: %u of %u ranges differ in rounding\n", moved, (unsigned)N);
    assert_true(moved > 0);
    sphere_scan("RANGECAST_VULKAN_SKIP", "walk", other, other_hits);
    for (i = 0; i < N; ++i) off_sphere += !(other_hits[i] == 1 && other[i] > 17.0f && other[i] < 23.0f);
    print_message("skip walk: %u of %u rays off the sphere\n", off_sphere, (unsigned)N);
    assert_true(off_sphere > N / 2);
    sphere_scan("RANGECAST_VULKAN_PIPELINE_STATS", "1", other, other_hits);
    assert_memory_equal(other, full, sizeof full);
    assert_memory_equal(other_hits, hits, sizeof hits);
}

/* A sensor destroyed and another created in its place (same arena address,
 * same ray count, other directions) is never served the old cached rays. */
static void test_sensor_cache(void **state)
{
    rc_context *ctx;
    rc_scene *scene;
    rcu_mesh m;
    const float lo[3] = {-2, -3, -4}, hi[3] = {5, 6, 7};
    float dirs_a[3 * 4] = {1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0};
    float dirs_b[3 * 4] = {0, -1, 0, 0, 0, -1, 1, 0, 0, 0, 1, 0};
    const float expect_a[4] = {5, 6, 7, 2}, expect_b[4] = {3, 4, 5, 6};
    rc_sensor *a, *b;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    int i;
    (void)state;
    NEED_VULKAN();
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    rct_buffers_alloc(&buf, 4, RC_ATTR_RANGES);
    a = rct_sensor_dirs(ctx, dirs_a, 4, 0.1f, 100.0f);
    RCT_OK(ctx, rc_simulate(ctx, scene, a, &pose, 1, &buf.res));
    for (i = 0; i < 4; ++i) assert_true(fabsf(buf.res.ranges[i] - expect_a[i]) < 1e-5f);
    RCT_OK(ctx, rc_sensor_destroy(a));
    b = rct_sensor_dirs(ctx, dirs_b, 4, 0.1f, 100.0f);
    if (a == b) print_message("the new sensor took the old one's address\n");
    RCT_OK(ctx, rc_simulate(ctx, scene, b, &pose, 1, &buf.res));
    for (i = 0; i < 4; ++i) assert_true(fabsf(buf.res.ranges[i] - expect_b[i]) < 1e-5f);
    /* mounting changes take effect (the transform is uploaded per call) */
    {
        rc_pose mount = rct_pose(1.0f, 0.0f, 0.0f);
        RCT_OK(ctx, rc_sensor_set_mounting(b, &mount));
        RCT_OK(ctx, rc_simulate(ctx, scene, b, &pose, 1, &buf.res));
        assert_true(fabsf(buf.res.ranges[2] - 4.0f) < 1e-5f); /* +x from x = 1 */
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* After a device loss every call but destroy says so; destroy is clean. */
static void test_device_lost(void **state)
{
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh m;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    (void)state;
    NEED_VULKAN();
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 16, 8, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rct_buffers_alloc(&buf, 16 * 360, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    rc__vk_debug_mark_lost(ctx);
    rct_buffers_fill(&buf, 0x77);
    assert_int_equal(rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res), RC_ERR_DEVICE_LOST);
    assert_non_null(strstr(rc_context_last_error(ctx), "lost"));
    assert_true(rct_buffers_untouched(&buf, 0x77));
    RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
    assert_int_equal(rc_scene_commit(scene), RC_ERR_DEVICE_LOST);
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* No driver (the loader finds no ICD): UNSUPPORTED with a message, cleanly. */
static void test_no_driver(void **state)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_status st;
    (void)state;
    NEED_VULKAN();
    d.backend = RC_BACKEND_VULKAN;
    d.thread_count = 1;
    d.memory_size = (size_t)1 << 20;
    d.log = capture_log;
    g_log[0] = '\0';
    {
        /* the test's own driver choice (the ray query runs set one) comes back after */
        const char *was = getenv("VK_ICD_FILENAMES");
        char *keep = was ? strdup(was) : NULL;
        setenv("VK_ICD_FILENAMES", "/nonexistent/rangecast_icd.json", 1);
        setenv("VK_DRIVER_FILES", "/nonexistent/rangecast_icd.json", 1);
        st = rc_context_create(&d, &ctx);
        if (keep) setenv("VK_ICD_FILENAMES", keep, 1);
        else unsetenv("VK_ICD_FILENAMES");
        unsetenv("VK_DRIVER_FILES");
        free(keep);
    }
    print_message("%s", g_log);
    assert_int_equal(st, RC_ERR_UNSUPPORTED);
    assert_null(ctx);
    assert_non_null(strstr(g_log, "vulkan:"));
}

/* Result names for the messages. */
/* A dynamic map on the device: a static sphere (the map) and three instanced
 * boxes moved between scans. A commit that only moved instances rewrites
 * their records and the top level in place (no new device memory), and the
 * scans match the built-in backend's after every move; a mesh updated in
 * place (the map's own, or a source's) has its sections rewritten in place,
 * directly where device memory is mapped and through staging where it is not
 * (RANGECAST_VULKAN_STAGING); adding an instance uploads everything. */
typedef struct dyn_world {
    rc_context *ctx;
    rc_scene *box, *world;
    rc_sensor *lidar;
    rcu_mesh box_mesh;
} dyn_world;

static void dyn_make(dyn_world *w, uint32_t backend, const rcu_mesh *sphere)
{
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t id, i;
    memset(w, 0, sizeof *w);
    assert_int_equal(rcu_mesh_box(lo, hi, &w->box_mesh), 0);
    w->ctx = rct_context(backend, 2, 0);
    w->box = rct_scene_mesh(w->ctx, &w->box_mesh, RC_MESH_REFERENCE);
    sd.max_geometries = 1;
    sd.max_instances = 4;
    sd.max_triangles = sphere->triangle_count;
    RCT_OK(w->ctx, rc_scene_create(w->ctx, &sd, &w->world));
    md.vertices = sphere->vertices;
    md.vertex_count = sphere->vertex_count;
    md.indices = sphere->indices;
    md.triangle_count = sphere->triangle_count;
    RCT_OK(w->ctx, rc_scene_add_mesh(w->world, &md, &id));
    for (i = 0; i < 3; ++i) {
        rc_instance_desc in = rc_instance_desc_default();
        in.source = w->box;
        in.transform = rct_pose(3.0f * (float)i - 3.0f, 2.0f, 0.0f);
        RCT_OK(w->ctx, rc_scene_add_instance(w->world, &in, &id));
    }
    RCT_OK(w->ctx, rc_scene_commit(w->world));
    RCT_OK(w->ctx, rc_sensor_create_preset(w->ctx, RC_PRESET_VELODYNE_VLP16, &w->lidar));
}

static void dyn_move(dyn_world *w, uint32_t step)
{
    uint32_t i;
    for (i = 0; i < 3; ++i) {
        const rc_pose p = rct_pose_ypr(3.0f * (float)i - 3.0f + 0.5f * (float)step, 2.0f - 0.3f * (float)step,
                                       0.2f * (float)i, 0.4 * step + i, 0.1 * i, 0.0);
        const float scale[3] = {1.0f + 0.1f * (float)step, 1.0f, 2.0f};
        RCT_OK(w->ctx, rc_scene_set_instance_transform(w->world, i, &p, scale));
    }
    RCT_OK(w->ctx, rc_scene_commit(w->world));
}

static void dyn_scan(dyn_world *w, rct_buffers *b)
{
    const rc_pose pose = rct_pose_ypr(0.5f, -0.5f, 0.2f, 0.3, 0.0, 0.0);
    RCT_OK(w->ctx, rc_simulate(w->ctx, w->world, w->lidar, &pose, 1, &b->res));
}

static void dyn_free(dyn_world *w)
{
    rc_context_destroy(w->ctx);
    rcu_mesh_free(&w->box_mesh);
}

/* hits and ids equal, ranges within 1e-5 (relative) */
static void dyn_compare(const rct_buffers *a, const rct_buffers *b, uint64_t n)
{
    uint64_t k, boxes = 0;
    for (k = 0; k < n; ++k) {
        assert_int_equal(a->res.hits[k], b->res.hits[k]);
        if (!a->res.hits[k]) continue;
        if (fabsf(a->res.ranges[k] - b->res.ranges[k]) > 1e-5f * b->res.ranges[k])
            fail_msg("element %llu: %.9g on Vulkan, %.9g on the built-in backend", (unsigned long long)k,
                     (double)a->res.ranges[k], (double)b->res.ranges[k]);
        assert_int_equal(a->res.inst_ids[k], b->res.inst_ids[k]);
        boxes += a->res.inst_ids[k] != RC_INVALID_ID;
    }
    assert_true(boxes > 50u); /* the moved boxes are in view */
}

/* The same move on Vulkan and on the built-in backend, then both scans compared. */
static void dyn_step(dyn_world *v, dyn_world *c, uint32_t step, rct_buffers *bv, rct_buffers *bc, uint64_t n)
{
    dyn_move(v, step);
    dyn_move(c, step);
    dyn_scan(v, bv);
    dyn_scan(c, bc);
    dyn_compare(bv, bc, n);
}

static void test_dynamic_commit_rewrites_only_the_top(void **state)
{
    rcu_mesh sphere;
    int staged;
    const uint64_t n = 16u * 900u;
    (void)state;
    NEED_VULKAN();
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, rct_quick() ? 5000u : 50000u, &sphere), 0);
    for (staged = 0; staged <= 1; ++staged) {
        dyn_world v, c;
        rct_buffers bv, bc;
        rc_memory_stats m0 = rc_memory_stats_default(), m1 = rc_memory_stats_default();
        uint32_t full = 0, top = 0, meshes = 0, step;
        if (staged) setenv("RANGECAST_VULKAN_STAGING", "1", 1);
        dyn_make(&v, RC_BACKEND_VULKAN, &sphere);
        unsetenv("RANGECAST_VULKAN_STAGING");
        dyn_make(&c, RC_BACKEND_BVH, &sphere);
        rct_buffers_alloc(&bv, n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_INST_IDS);
        rct_buffers_alloc(&bc, n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_INST_IDS);
        for (step = 1; step <= 4; ++step) {
            dyn_step(&v, &c, step, &bv, &bc, n);
            /* after the first scan (which sets up the per-call buffers) */
            if (step == 1) RCT_OK(v.ctx, rc_context_get_memory_stats(v.ctx, &m0));
        }
        rc__vk_debug_scene_uploads(v.world, &full, &top, &meshes);
        assert_int_equal(full, 1);
        assert_int_equal(top, 4);
        assert_int_equal(meshes, 0);
        RCT_OK(v.ctx, rc_context_get_memory_stats(v.ctx, &m1));
        assert_true(m1.device_bytes == m0.device_bytes); /* the same buffers, rewritten */
        /* a source's mesh changed (and re-committed): its sections rewritten
         * in place, mapped or staged */
        v.box_mesh.vertices[0] += 0.25f;
        c.box_mesh.vertices[0] += 0.25f;
        RCT_OK(v.ctx, rc_scene_update_mesh(v.box, 0));
        RCT_OK(c.ctx, rc_scene_update_mesh(c.box, 0));
        RCT_OK(v.ctx, rc_scene_commit(v.box));
        RCT_OK(c.ctx, rc_scene_commit(c.box));
        dyn_step(&v, &c, 5, &bv, &bc, n);
        /* the map's own mesh updated in place (both worlds reference it):
         * shrunk by 2%, so every range that reaches it changes, then back */
        for (step = 0; step < 3u * sphere.vertex_count; ++step) sphere.vertices[step] *= 0.98f;
        RCT_OK(v.ctx, rc_scene_update_mesh(v.world, 0));
        RCT_OK(c.ctx, rc_scene_update_mesh(c.world, 0));
        dyn_step(&v, &c, 6, &bv, &bc, n);
        for (step = 0; step < 3u * sphere.vertex_count; ++step) sphere.vertices[step] /= 0.98f;
        RCT_OK(v.ctx, rc_scene_update_mesh(v.world, 0));
        RCT_OK(c.ctx, rc_scene_update_mesh(c.world, 0));
        dyn_step(&v, &c, 7, &bv, &bc, n);
        rc__vk_debug_scene_uploads(v.world, &full, &top, &meshes);
        assert_int_equal(full, 1);
        assert_int_equal(meshes, 3);
        assert_int_equal(top, 4);
        RCT_OK(v.ctx, rc_context_get_memory_stats(v.ctx, &m1));
        assert_true(m1.device_bytes == m0.device_bytes); /* still the same buffers */
        /* one more instance: the layout changes, the next commit uploads */
        {
            rc_instance_desc in = rc_instance_desc_default();
            uint32_t id;
            in.source = v.box;
            in.transform = rct_pose(0.0f, -4.0f, 0.0f);
            RCT_OK(v.ctx, rc_scene_add_instance(v.world, &in, &id));
            in.source = c.box;
            RCT_OK(c.ctx, rc_scene_add_instance(c.world, &in, &id));
        }
        dyn_step(&v, &c, 8, &bv, &bc, n);
        rc__vk_debug_scene_uploads(v.world, &full, &top, &meshes);
        assert_int_equal(full, 2); /* a new instance: the layout changed */
        rct_buffers_free(&bv);
        rct_buffers_free(&bc);
        dyn_free(&v);
        dyn_free(&c);
    }
    rcu_mesh_free(&sphere);
}

static void test_result_names(void **state)
{
    (void)state;
    assert_string_equal(rc__vk_result_name(VK_ERROR_DEVICE_LOST), "VK_ERROR_DEVICE_LOST");
    assert_string_equal(rc__vk_result_name(VK_ERROR_OUT_OF_DEVICE_MEMORY), "VK_ERROR_OUT_OF_DEVICE_MEMORY");
    assert_string_equal(rc__vk_result_name((VkResult)-123456), "VK_ERROR_(unknown)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_result_names),    cmocka_unit_test(test_layout_contract),
        cmocka_unit_test(test_packed_arrays),   cmocka_unit_test(test_device_choice),
        cmocka_unit_test(test_memory_accounting), cmocka_unit_test(test_budget),
        cmocka_unit_test(test_binding_limits),
        cmocka_unit_test(test_measurement_switches),
        cmocka_unit_test(test_sensor_cache),    cmocka_unit_test(test_device_lost),
        cmocka_unit_test(test_no_driver),
        cmocka_unit_test(test_dynamic_commit_rewrites_only_the_top),
    };
    return cmocka_run_group_tests_name("vulkan backend", tests, NULL, NULL);
}
