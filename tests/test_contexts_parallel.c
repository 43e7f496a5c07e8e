/* Separate contexts on separate threads at the same time: the header lets an
 * application run one context per thread (a filter per core), so nothing in
 * the library may be shared behind the contexts' backs. Four threads each
 * create, use and destroy their own contexts (bvh, Embree and Vulkan where
 * usable, round robin) three times over and must get, to the bit, the ranges
 * one context on the main thread got before. The suite also runs under
 * ASan+UBSan. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#define WORKERS 4
#define ROUNDS 3
#define POSES 4u
#define RAYS (16u * 900u)

typedef struct expected {
    uint32_t backend;
    int usable;
    float ranges[POSES * RAYS];
} expected;

static rcu_mesh sphere;
static rc_pose poses[POSES];
static expected want[3];

typedef struct worker {
    uint32_t backend;
    const float *want;
    char error[256]; /* "" when every round matched */
    float ranges[POSES * RAYS];
} worker;

/* One context's scan of the poses into ranges; "" or what failed into error. */
static void scan(uint32_t backend, uint32_t threads, float *ranges, char *error, size_t error_size)
{
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_results res = rc_results_default();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL;
    rc_sensor *lidar = NULL;
    uint32_t geom = 0;
    rc_status st;
    const char *call = "rc_context_create";
    error[0] = '\0';
    cd.backend = backend;
    cd.thread_count = threads;
    cd.memory_size = (size_t)32 << 20;
    if ((st = rc_context_create(&cd, &ctx)) != RC_OK) goto fail;
    sd.max_triangles = sphere.triangle_count;
    call = "rc_scene_create";
    if ((st = rc_scene_create(ctx, &sd, &scene)) != RC_OK) goto fail;
    md.vertices = sphere.vertices;
    md.vertex_count = sphere.vertex_count;
    md.indices = sphere.indices;
    md.triangle_count = sphere.triangle_count;
    call = "rc_scene_add_mesh";
    if ((st = rc_scene_add_mesh(scene, &md, &geom)) != RC_OK) goto fail;
    call = "rc_scene_commit";
    if ((st = rc_scene_commit(scene)) != RC_OK) goto fail;
    call = "rc_sensor_create_preset";
    if ((st = rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &lidar)) != RC_OK) goto fail;
    res.attributes = RC_ATTR_RANGES;
    res.ranges = ranges;
    res.capacity = POSES * RAYS;
    call = "rc_simulate";
    if ((st = rc_simulate(ctx, scene, lidar, poses, POSES, &res)) != RC_OK) goto fail;
    rc_context_destroy(ctx);
    return;
fail:
    snprintf(error, error_size, "%s on %s: %s (%s)", call, rc_backend_name(backend), rc_status_string(st),
             ctx ? rc_context_last_error(ctx) : "no context");
    rc_context_destroy(ctx);
}

static void *work(void *arg)
{
    worker *w = (worker *)arg;
    int round;
    for (round = 0; round < ROUNDS && !w->error[0]; ++round) {
        scan(w->backend, 1u + (uint32_t)round % 2u, w->ranges, w->error, sizeof w->error);
        if (!w->error[0] && memcmp(w->ranges, w->want, sizeof w->ranges) != 0)
            snprintf(w->error, sizeof w->error, "%s, round %d: ranges differ from the main thread's",
                     rc_backend_name(w->backend), round);
    }
    return NULL;
}

static void test_contexts_on_threads(void **state)
{
    static worker workers[WORKERS];
    pthread_t threads[WORKERS];
    char error[256];
    uint32_t b, i, usable = 0;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 20000u, &sphere), 0);
    for (i = 0; i < POSES; ++i)
        poses[i] = rct_pose_ypr(2.0f * (float)i - 3.0f, 1.5f * (float)i, 0.5f, 0.7 * i, 0.1 * i, -0.05 * i);
    for (b = 0; b < 3; ++b) {
        want[b].backend = rct_backends[b];
        want[b].usable = rct_backend_usable(rct_backends[b]);
        if (!want[b].usable) continue;
        scan(rct_backends[b], 1u, want[b].ranges, error, sizeof error);
        if (error[0]) fail_msg("%s", error);
        ++usable;
    }
    assert_true(usable >= 1u);
    for (i = 0, b = 0; i < WORKERS; ++i) {
        while (!want[b % 3u].usable) ++b;
        workers[i].backend = want[b % 3u].backend;
        workers[i].want = want[b % 3u].ranges;
        workers[i].error[0] = '\0';
        ++b;
        assert_int_equal(pthread_create(&threads[i], NULL, work, &workers[i]), 0);
    }
    for (i = 0; i < WORKERS; ++i) assert_int_equal(pthread_join(threads[i], NULL), 0);
    for (i = 0; i < WORKERS; ++i)
        if (workers[i].error[0]) fail_msg("worker %u: %s", i, workers[i].error);
    rcu_mesh_free(&sphere);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contexts_on_threads),
    };
    return cmocka_run_group_tests_name("contexts_parallel", tests, NULL, NULL);
}
