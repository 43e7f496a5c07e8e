/* Contexts: descriptor checks, caller blocks, errors, memory figures, and the
 * exact size queries (the queried size works, one byte less fails cleanly). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

static void test_version(void **state)
{
    (void)state;
    assert_int_equal(rc_version_number(), RC_VERSION_NUMBER);
    assert_string_equal(rc_version_string(), "0.1.0");
    assert_non_null(strstr(rc_status_string(RC_ERR_OUT_OF_MEMORY), "OUT_OF_MEMORY"));
    assert_string_equal(rc_status_string(12345), "unknown status");
}

static void test_bad_descs(void **state)
{
    rc_context *ctx = (rc_context *)0x1; /* must stay untouched on failure */
    rc_context_desc d;
    static unsigned char raw[1 << 16];
    (void)state;
    assert_int_equal(rc_context_create(NULL, &ctx), RC_ERR_INVALID_ARGUMENT);
    d = rc_context_desc_default();
    assert_int_equal(rc_context_create(&d, NULL), RC_ERR_INVALID_ARGUMENT);
    d.struct_size = 8;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_STRUCT_SIZE);
    d = rc_context_desc_default();
    d.reserved[3] = 1;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_INVALID_ARGUMENT);
    d = rc_context_desc_default();
    d.backend = 42;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_INVALID_ARGUMENT);
    d = rc_context_desc_default();
    d.thread_count = RC_MAX_THREADS + 1;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_INVALID_ARGUMENT);
    d = rc_context_desc_default();
    d.flags = 4;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_INVALID_ARGUMENT);
    d = rc_context_desc_default();
    d.memory = raw + ((16u - (uintptr_t)raw % 16u) % 16u) + 4; /* misaligned */
    d.memory_size = 4096;
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_INVALID_ARGUMENT);
    d.memory = raw + ((16u - (uintptr_t)raw % 16u) % 16u);
    d.memory_size = 64; /* too small */
    assert_int_equal(rc_context_create(&d, &ctx), RC_ERR_OUT_OF_MEMORY);
    assert_ptr_equal(ctx, (rc_context *)0x1);
    /* handles that are not contexts */
    assert_string_equal(rc_context_last_error(NULL), "invalid context handle");
    rc_context_destroy(NULL);
}

static void test_caller_block_and_stats(void **state)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_memory_stats ms = rc_memory_stats_default();
    size_t need = 0, backend_need = 0;
    void *mem;
    uint32_t backend = 0, threads = 0;
    (void)state;
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 2;
    assert_int_equal(rc_context_memory_requirements(&d, &need), RC_OK);
    assert_true(need > 0 && need < 65536);
    mem = rct_alloc16(1 << 20);
    d.memory = mem;
    d.memory_size = 1 << 20;
    assert_int_equal(rc_context_create(&d, &ctx), RC_OK);
    assert_int_equal(rc_context_get_backend(ctx, &backend), RC_OK);
    assert_int_equal(backend, RC_BACKEND_BVH);
    assert_int_equal(rc_context_get_thread_count(ctx, &threads), RC_OK);
#if defined(RANGECAST_WITH_THREADS)
    assert_int_equal(threads, 2);
#else
    assert_int_equal(threads, 1); /* built without threads: all work on the caller's thread */
#endif
    assert_int_equal(rc_context_get_memory_stats(ctx, &ms), RC_OK);
    assert_int_equal(ms.arena_size, 1 << 20);
    assert_int_equal(ms.arena_used, need);
    assert_int_equal(ms.arena_peak, need);
    /* an error names its argument */
    assert_int_equal(rc_context_get_memory_stats(ctx, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "stats"));
    rc_context_destroy(ctx);
    /* AUTO is the built-in backend in every build, Embree's included, and
     * sizes its context as that backend does */
    d.backend = RC_BACKEND_AUTO;
    assert_int_equal(rc_context_memory_requirements(&d, &backend_need), RC_OK);
    assert_int_equal(backend_need, need);
    assert_int_equal(rc_context_create(&d, &ctx), RC_OK);
    assert_int_equal(rc_context_get_backend(ctx, &backend), RC_OK);
    assert_int_equal(backend, RC_BACKEND_BVH);
    rc_context_destroy(ctx);
    free(mem);
}

/* Builds a scene of the sphere with one sensor inside an arena of exactly
 * `size` bytes; returns the first failing status (or RC_OK). */
static rc_status build_in(size_t size, const rcu_mesh *m, uint32_t flags, int with_instance)
{
    rc_context_desc d = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL, *top = NULL;
    rc_sensor *sensor = NULL;
    void *mem = rct_alloc16(size);
    rc_status st;
    uint32_t id;
    float ranges[16 * 360];
    rc_results res = rc_results_default();
    rc_pose pose = rct_pose(0, 0, 0);
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 1;
    d.memory = mem;
    d.memory_size = size;
    st = rc_context_create(&d, &ctx);
    if (st != RC_OK) {
        free(mem);
        return st;
    }
    sd.max_triangles = m->triangle_count;
    if (flags == RC_MESH_COPY) {
        sd.max_vertices = m->vertex_count;
        sd.max_copied_triangles = m->triangle_count;
    }
    md.flags = flags;
    md.vertices = m->vertices;
    md.vertex_count = m->vertex_count;
    md.indices = m->indices;
    md.triangle_count = m->triangle_count;
    /* Persistent objects first: the commit's scratch then comes on top of them,
     * and the sum of the queries is exactly the peak. */
    st = rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor);
    if (st == RC_OK) st = rc_scene_create(ctx, &sd, &scene);
    if (st == RC_OK) st = rc_scene_add_mesh(scene, &md, &id);
    if (st == RC_OK) st = rc_scene_commit(scene);
    if (st == RC_OK && with_instance) {
        rc_scene_desc td = rc_scene_desc_default();
        rc_instance_desc idesc = rc_instance_desc_default();
        td.max_instances = 3;
        idesc.source = scene;
        st = rc_scene_create(ctx, &td, &top);
        if (st == RC_OK) st = rc_scene_add_instance(top, &idesc, &id);
        if (st == RC_OK) st = rc_scene_commit(top);
    }
    if (st == RC_OK) {
        res.attributes = RC_ATTR_RANGES;
        res.ranges = ranges;
        res.capacity = 16 * 360;
        st = rc_simulate(ctx, with_instance ? top : scene, sensor, &pose, 1, &res);
        if (st == RC_OK && !(ranges[0] > 9.0f && ranges[0] < 10.5f)) st = -999;
    }
    if (st == RC_ERR_OUT_OF_MEMORY) assert_true(strlen(rc_context_last_error(ctx)) > 10);
    rc_context_destroy(ctx);
    free(mem);
    return st;
}

static size_t required(const rcu_mesh *m, uint32_t flags, int with_instance)
{
    rc_context_desc d = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_context *ctx = NULL;
    size_t c = 0, s = 0, t = 0, se = 0;
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 1;
    assert_int_equal(rc_context_memory_requirements(&d, &c), RC_OK);
    d.memory_size = 1 << 20;
    assert_int_equal(rc_context_create(&d, &ctx), RC_OK);
    sd.max_triangles = m->triangle_count;
    if (flags == RC_MESH_COPY) {
        sd.max_vertices = m->vertex_count;
        sd.max_copied_triangles = m->triangle_count;
    }
    assert_int_equal(rc_scene_memory_requirements(ctx, &sd, &s), RC_OK);
    if (with_instance) {
        rc_scene_desc td = rc_scene_desc_default();
        td.max_instances = 3;
        assert_int_equal(rc_scene_memory_requirements(ctx, &td, &t), RC_OK);
    }
    assert_int_equal(rc_sensor_memory_requirements_preset(RC_PRESET_VELODYNE_VLP16_360, &se), RC_OK);
    rc_context_destroy(ctx);
    return c + s + t + se;
}

/* The arena sweep: the queried size works; one byte less fails with
 * RC_ERR_OUT_OF_MEMORY and no crash or leak. */
static void test_arena_sizing_exact(void **state)
{
    rcu_mesh meshes[2];
    uint32_t flags, k, i;
    int inst;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(10.0f, 37, 19, &meshes[0]), 0);
    /* the same triangles among many more vertices than they use: a copy's
     * renumbering (rc__mesh_order_vertices) then needs more commit scratch
     * than the builder, and the query must count it */
    assert_int_equal(rcu_mesh_reserve(&meshes[1], meshes[0].vertex_count + 20000u, meshes[0].triangle_count), 0);
    memcpy(meshes[1].vertices, meshes[0].vertices, 12u * meshes[0].vertex_count);
    for (i = 0; i < 3u * 20000u; ++i) meshes[1].vertices[3u * meshes[0].vertex_count + i] = (float)(i % 7u);
    memcpy(meshes[1].indices, meshes[0].indices, 12u * meshes[0].triangle_count);
    meshes[1].vertex_count = meshes[0].vertex_count + 20000u;
    meshes[1].triangle_count = meshes[0].triangle_count;
    for (k = 0; k < 2u; ++k)
        for (inst = 0; inst < 2; ++inst)
            for (flags = 0; flags < 2; ++flags) {
                const rcu_mesh *m = &meshes[k];
                size_t need = required(m, flags, inst);
                assert_int_equal(build_in(need, m, flags, inst), RC_OK);
                /* With one scene the sum is exact. With a second (instancing) scene
                 * the first one's commit scratch is free again when the second
                 * commits, so the sum is an upper bound by that much. */
                if (!inst) {
                    assert_int_equal(build_in(need - 1, m, flags, inst), RC_ERR_OUT_OF_MEMORY);
                    assert_int_equal(build_in(need - 16, m, flags, inst), RC_ERR_OUT_OF_MEMORY);
                }
            }
    rcu_mesh_free(&meshes[0]);
    rcu_mesh_free(&meshes[1]);
}

/* Bytes per triangle of the committed structure (the budget: at most
 * 64 copied, 40 referenced). */
static void test_bytes_per_triangle(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *ref, *copy;
    rc_scene_info ri = rc_scene_info_default(), ci = rc_scene_info_default();
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &m), 0);
    ctx = rct_context(RC_BACKEND_BVH, 1, 64);
    ref = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    copy = rct_scene_mesh(ctx, &m, RC_MESH_COPY);
    RCT_OK(ctx, rc_scene_get_info(ref, &ri));
    RCT_OK(ctx, rc_scene_get_info(copy, &ci));
    assert_int_equal(ri.committed, 1);
    assert_int_equal(ri.triangle_count, m.triangle_count);
    print_message("bytes/triangle: referenced %.1f, copied %.1f\n", (double)ri.bytes / m.triangle_count,
                  (double)ci.bytes / m.triangle_count);
    assert_true((double)ri.bytes / m.triangle_count <= 40.0);
    assert_true((double)ci.bytes / m.triangle_count <= 64.0);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

static int logged;
static void count_log(void *user, uint32_t level, const char *msg)
{
    (void)user;
    (void)msg;
    if (level == RC_LOG_ERROR) logged++;
}

static void test_log_callback(void **state)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_scene *s = NULL;
    (void)state;
    d.log = count_log;
    d.memory_size = 1 << 20;
    assert_int_equal(rc_context_create(&d, &ctx), RC_OK);
    logged = 0;
    assert_int_equal(rc_scene_create(ctx, NULL, &s), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(logged, 1);
    assert_non_null(strstr(rc_context_last_error(ctx), "desc"));
    rc_context_destroy(ctx);
}

/* A failed create has no context: its message goes to the log callback, and
 * it names the field. */
static char last_log[1024];
static void keep_log(void *user, uint32_t level, const char *msg)
{
    (void)user;
    if (level == RC_LOG_ERROR) snprintf(last_log, sizeof last_log, "%s", msg);
}

static void expect_create(rc_context_desc *d, rc_status status, const char *part)
{
    rc_context *ctx = NULL;
    last_log[0] = '\0';
    d->log = keep_log;
    assert_int_equal(rc_context_create(d, &ctx), status);
    assert_null(ctx);
    if (!strstr(last_log, part)) fail_msg("create's message '%s' lacks '%s'", last_log, part);
}

static void test_create_messages_name_the_field(void **state)
{
    rc_context_desc d;
    static unsigned char raw[4096 + 16];
    unsigned char *aligned = raw + ((16u - (uintptr_t)raw % 16u) % 16u);
    (void)state;
    d = rc_context_desc_default();
    d.struct_size = 8;
    expect_create(&d, RC_ERR_STRUCT_SIZE, "desc->struct_size is 8");
    d = rc_context_desc_default();
    d.reserved[3] = 1;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "desc->reserved[3] is 1");
    d = rc_context_desc_default();
    d.backend = 42;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "desc->backend is 42");
    d = rc_context_desc_default();
    d.thread_count = RC_MAX_THREADS + 1;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "desc->thread_count is 257");
    d = rc_context_desc_default();
    d.flags = 4;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "desc->flags is 0x4");
    d = rc_context_desc_default();
    d.flags = RC_CONTEXT_VULKAN_RAY_QUERY;
    d.backend = RC_BACKEND_BVH;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "needs desc->backend RC_BACKEND_VULKAN (it is bvh)");
    d.backend = RC_BACKEND_AUTO;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "needs desc->backend RC_BACKEND_VULKAN");
    d = rc_context_desc_default();
    d.memory = aligned + 4;
    d.memory_size = 4000;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "not aligned to RC_ARENA_ALIGNMENT");
    d.memory = aligned;
    d.memory_size = 0;
    expect_create(&d, RC_ERR_INVALID_ARGUMENT, "desc->memory_size is 0");
    d.memory_size = 64;
    expect_create(&d, RC_ERR_OUT_OF_MEMORY, "desc->memory_size is 64 bytes; this context needs");
    if (!rc_backend_available(RC_BACKEND_EMBREE)) {
        d = rc_context_desc_default();
        d.backend = RC_BACKEND_EMBREE;
        expect_create(&d, RC_ERR_UNSUPPORTED, "embree is not built into this library");
    }
    if (rct_backend_usable(RC_BACKEND_VULKAN)) {
        /* the backend's own reason comes through (where a Vulkan driver
         * exists: under qemu the loader finds none, a reason of its own) */
        d = rc_context_desc_default();
        d.backend = RC_BACKEND_VULKAN;
        d.device = "no-such-gpu-anywhere";
        expect_create(&d, RC_ERR_UNSUPPORTED, "no-such-gpu-anywhere");
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version),          cmocka_unit_test(test_bad_descs),
        cmocka_unit_test(test_caller_block_and_stats), cmocka_unit_test(test_arena_sizing_exact),
        cmocka_unit_test(test_bytes_per_triangle), cmocka_unit_test(test_log_callback),
        cmocka_unit_test(test_create_messages_name_the_field),
    };
    return cmocka_run_group_tests_name("context", tests, NULL, NULL);
}
