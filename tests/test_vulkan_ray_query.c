/* The Vulkan backend's ray query traversal (RC_CONTEXT_VULKAN_RAY_QUERY).
 *
 * On a device without VK_KHR_ray_query (Debian 12's lavapipe 22.3) the flag
 * must be refused with RC_ERR_UNSUPPORTED and a message naming what is
 * missing. On one with it (bookworm-backports' lavapipe 25, selected by
 * tests/CMakeLists.txt with RC_TEST_REQUIRE_RAY_QUERY=1, which makes a refusal
 * a failure) the two traversals of one device must agree on a VLP-16 batch in
 * a sphere holding instanced boxes (scaled, one mirrored): hits, ranges to the
 * bit where the same triangle is hit (both refine it in float64), ids; and the
 * driver's structures must show in the context's device memory. The shared
 * suites run on the ray query traversal too (the *_rq tests). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

static char last_log[1024];

static void keep_log(void *user, uint32_t level, const char *message)
{
    (void)user;
    (void)level;
    snprintf(last_log, sizeof last_log, "%s", message);
}

/* A Vulkan context, with the ray query traversal or without; NULL (and the
 * status) when the device refuses it. */
static rc_context *vulkan_context(uint32_t flags, rc_status *status)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    d.backend = RC_BACKEND_VULKAN;
    d.thread_count = 2;
    d.memory_size = (size_t)64 << 20;
    d.flags = flags;
    d.log = keep_log;
    last_log[0] = '\0';
    *status = rc_context_create(&d, &ctx);
    return ctx;
}

/* NULL when this machine's device has no ray query (the refusal checked). */
static rc_context *ray_query_context(void)
{
    rc_status st;
    rc_context *ctx = vulkan_context(RC_CONTEXT_VULKAN_RAY_QUERY, &st);
    if (st == RC_OK) {
        if (!strstr(last_log, "ray query traversal")) fail_msg("create's log '%s' lacks the traversal", last_log);
        return ctx;
    }
    if (rct_env_on("RC_TEST_REQUIRE_RAY_QUERY"))
        fail_msg("RC_CONTEXT_VULKAN_RAY_QUERY refused where it is required: %s (%s)", rc_status_string(st), last_log);
    assert_int_equal(st, RC_ERR_UNSUPPORTED);
    assert_null(ctx);
    if (!strstr(last_log, "RC_CONTEXT_VULKAN_RAY_QUERY") ||
        (!strstr(last_log, "VK_KHR") && !strstr(last_log, "Vulkan 1.2") && !strstr(last_log, "feature")))
        fail_msg("the refusal's message '%s' does not say what is missing", last_log);
    print_message("device without ray query, refused as expected: %s\n", last_log);
    return NULL;
}

static void test_flag_on_this_device(void **state)
{
    rc_context *ctx;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip();
    ctx = ray_query_context();
    if (ctx) rc_context_destroy(ctx);
}

typedef struct world {
    rc_scene *box, *scene;
    rc_sensor *sensor;
    rct_buffers out;
} world;

/* A sphere of radius 20 m with three instanced boxes inside (scaled, one
 * mirrored), traced with VLP-16 from poses near the centre. */
static void trace_world(rc_context *ctx, const rcu_mesh *sphere, const rcu_mesh *box, const rc_pose *poses,
                        uint32_t pose_count, world *w)
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t id, i;
    memset(w, 0, sizeof *w);
    w->box = rct_scene_mesh(ctx, box, RC_MESH_REFERENCE);
    sd.max_geometries = 1;
    sd.max_instances = 3;
    sd.max_triangles = sphere->triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &w->scene));
    md.vertices = sphere->vertices;
    md.vertex_count = sphere->vertex_count;
    md.indices = sphere->indices;
    md.triangle_count = sphere->triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(w->scene, &md, &id));
    for (i = 0; i < 3; ++i) {
        rc_instance_desc in = rc_instance_desc_default();
        in.source = w->box;
        in.transform = rct_pose_ypr(6.0f - 5.0f * (float)i, 2.0f * (float)i - 3.0f, 0.4f * (float)i, 0.9 * i, 0.1,
                                    -0.2 * i);
        in.scale[0] = i == 2 ? -1.5f : 1.0f + 0.5f * (float)i;
        in.scale[1] = 1.0f + 0.25f * (float)i;
        in.scale[2] = 2.0f;
        RCT_OK(ctx, rc_scene_add_instance(w->scene, &in, &id));
    }
    RCT_OK(ctx, rc_scene_commit(w->scene));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &w->sensor));
    rct_buffers_alloc(&w->out, (uint64_t)pose_count * 16u * 900u, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, w->scene, w->sensor, poses, pose_count, &w->out.res));
}

static void world_free(world *w)
{
    rc_sensor_destroy(w->sensor);
    RCT_OK(NULL, rc_scene_destroy(w->scene));
    RCT_OK(NULL, rc_scene_destroy(w->box));
    rct_buffers_free(&w->out);
}

static void test_agrees_with_compute(void **state)
{
    const uint32_t pose_count = rct_quick() ? 4u : 24u;
    rc_context *rq, *cs;
    rc_status st;
    rcu_mesh sphere, box;
    rc_pose poses[24];
    world a, b;
    rc_memory_stats ma = rc_memory_stats_default(), mb = rc_memory_stats_default();
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    uint64_t n, k, same_bits = 0, hit_diff = 0, id_diff = 0, returns = 0;
    uint32_t i;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip();
    rq = ray_query_context();
    if (!rq) skip();
    cs = vulkan_context(0, &st);
    assert_int_equal(st, RC_OK);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, rct_quick() ? 20000u : 100000u, &sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    for (i = 0; i < pose_count; ++i)
        poses[i] = rct_pose_ypr(1.5f * sinf((float)i), 2.0f * cosf(0.7f * (float)i), 0.3f * (float)(i % 5) - 0.6f,
                                0.37 * i, 0.05 * (double)(i % 3), -0.04 * (double)(i % 4));
    trace_world(rq, &sphere, &box, poses, pose_count, &a);
    trace_world(cs, &sphere, &box, poses, pose_count, &b);
    n = (uint64_t)pose_count * 16u * 900u;
    for (k = 0; k < n; ++k) {
        const float ra = a.out.res.ranges[k], rb = b.out.res.ranges[k];
        if (a.out.res.hits[k] != b.out.res.hits[k]) {
            ++hit_diff;
            continue;
        }
        if (!a.out.res.hits[k]) continue;
        ++returns;
        if (memcmp(&ra, &rb, sizeof ra) == 0) ++same_bits;
        if (fabsf(ra - rb) > 1e-5f * rb) fail_msg("element %llu: ranges %.9g (ray query) and %.9g (compute)",
                                                  (unsigned long long)k, (double)ra, (double)rb);
        if (a.out.res.prim_ids[k] != b.out.res.prim_ids[k] || a.out.res.geom_ids[k] != b.out.res.geom_ids[k] ||
            a.out.res.inst_ids[k] != b.out.res.inst_ids[k])
            ++id_diff;
        else if (fabsf(a.out.res.normals[3 * k] - b.out.res.normals[3 * k]) > 1e-6f)
            fail_msg("element %llu: same triangle, different normals", (unsigned long long)k);
    }
    print_message("ray query against compute: %llu elements, %llu returns, %llu ranges bit-identical, %llu hit "
                  "flags and %llu ids differ\n",
                  (unsigned long long)n, (unsigned long long)returns, (unsigned long long)same_bits,
                  (unsigned long long)hit_diff, (unsigned long long)id_diff);
    /* the boxes are hit, and so is the sphere, through instances on both */
    for (k = 0, i = 0; k < n; ++k) i += a.out.res.inst_ids[k] != RC_INVALID_ID;
    assert_true(i > 100u);
    /* only rays through an edge may differ (the driver's test against ours) */
    assert_true(hit_diff * 10000u <= n);
    assert_true(id_diff * 1000u <= returns);
    assert_true(same_bits * 100u >= returns * 99u);
    /* the driver's structures are device memory of the context */
    RCT_OK(rq, rc_context_get_memory_stats(rq, &ma));
    RCT_OK(cs, rc_context_get_memory_stats(cs, &mb));
    assert_true(ma.device_bytes > mb.device_bytes);
    world_free(&a);
    world_free(&b);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
    rc_context_destroy(rq);
    rc_context_destroy(cs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flag_on_this_device),
        cmocka_unit_test(test_agrees_with_compute),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
