/* The trace order of O1Dn/OnDn sensors (src/sensor/ray_order.c): a
 * permutation of the rays, sorted by its key, with rays of one key cell
 * together; grids have none; and the order changes no result: the same rays
 * given in another order give, ray for ray, the same bits on every CPU
 * backend (white-box: includes sensor/sensor.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "poses.h"
#include "rc_test.h"
#include "sensor/sensor.h"

#define RAYS 3000u

/* Random rays (rcutil's, as bench --sensor random-ondn makes them): origins
 * in a 2 m ball, directions anywhere. */
static void random_rays(float *org, float *dir) { rcu_rays_random(RAYS, 2.0f, 11u, org, dir); }

static rc_sensor *ondn(rc_context *ctx, const float *org, const float *dir)
{
    rc_rays_desc d = rc_rays_desc_default();
    rc_sensor *s = NULL;
    d.common.range_min = 0.05f;
    d.common.range_max = 100.0f;
    d.directions = dir;
    d.origins = org;
    d.ray_count = RAYS;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s));
    return s;
}

static void test_order_is_a_sorted_permutation(void **state)
{
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 16);
    float *org = (float *)malloc(sizeof(float) * 3u * RAYS), *dir = (float *)malloc(sizeof(float) * 3u * RAYS);
    unsigned char *seen = (unsigned char *)calloc(RAYS, 1);
    rc_sensor *s, *grid = NULL;
    uint32_t i, runs = 1;
    (void)state;
    random_rays(org, dir);
    s = ondn(ctx, org, dir);
    assert_non_null(s->trace_order);
    for (i = 0; i < RAYS; ++i) {
        const uint32_t r = rc__sensor_traced_ray(s, i);
        assert_true(r < RAYS);
        assert_int_equal(seen[r], 0);
        seen[r] = 1;
        if (i) {
            assert_true(s->trace_order[i - 1] < s->trace_order[i]);
            runs += (s->trace_order[i - 1] >> 32) != (s->trace_order[i] >> 32);
        }
    }
    /* 3,000 rays in 2^30 cells: mostly one a cell, but never in input order */
    assert_true(runs > RAYS / 2u);
    for (i = 0; i < RAYS && rc__sensor_traced_ray(s, i) == i; ++i) {
    }
    assert_true(i < RAYS);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &grid));
    assert_null(grid->trace_order);
    assert_int_equal(rc__sensor_traced_ray(grid, 77), 77);
    rc_context_destroy(ctx);
    free(org);
    free(dir);
    free(seen);
}

/* The rays reversed make another trace order of the same rays (ties of a key
 * cell go by index): every attribute of ray i equals that of ray N-1-i. */
static void check_order_free(uint32_t backend)
{
    rcu_mesh sphere;
    rc_context *ctx = rct_context(backend, 2, 32);
    float *org = (float *)malloc(sizeof(float) * 3u * RAYS), *dir = (float *)malloc(sizeof(float) * 3u * RAYS);
    float *rorg = (float *)malloc(sizeof(float) * 3u * RAYS), *rdir = (float *)malloc(sizeof(float) * 3u * RAYS);
    rc_scene *scene;
    rc_sensor *a, *b;
    rct_buffers x, y;
    rc_pose p = rct_pose_ypr(0.3f, -0.2f, 0.1f, 0.4, 0.1, -0.2);
    uint32_t i;
    assert_int_equal(rcu_mesh_uv_sphere(10.0f, 96, 48, &sphere), 0);
    scene = rct_scene_mesh(ctx, &sphere, RC_MESH_REFERENCE);
    random_rays(org, dir);
    for (i = 0; i < RAYS; ++i) {
        memcpy(rorg + 3u * i, org + 3u * (RAYS - 1u - i), 3 * sizeof(float));
        memcpy(rdir + 3u * i, dir + 3u * (RAYS - 1u - i), 3 * sizeof(float));
    }
    a = ondn(ctx, org, dir);
    b = ondn(ctx, rorg, rdir);
    rct_buffers_alloc(&x, RAYS, RC_ATTR_ALL);
    rct_buffers_alloc(&y, RAYS, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, a, &p, 1, &x.res));
    RCT_OK(ctx, rc_simulate(ctx, scene, b, &p, 1, &y.res));
    for (i = 0; i < RAYS; ++i) {
        const uint32_t j = RAYS - 1u - i;
        assert_int_equal(x.res.hits[i], y.res.hits[j]);
        assert_memory_equal(&x.res.ranges[i], &y.res.ranges[j], sizeof(float));
        assert_memory_equal(&x.res.points[3u * i], &y.res.points[3u * j], 3 * sizeof(float));
        assert_memory_equal(&x.res.normals[3u * i], &y.res.normals[3u * j], 3 * sizeof(float));
        assert_int_equal(x.res.prim_ids[i], y.res.prim_ids[j]);
    }
    assert_int_equal(x.res.hits[0], 1); /* inside a closed sphere every ray hits */
    rct_buffers_free(&x);
    rct_buffers_free(&y);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
    free(org);
    free(dir);
    free(rorg);
    free(rdir);
}

static void test_results_do_not_depend_on_order(void **state)
{
    (void)state;
    check_order_free(RC_BACKEND_BVH);
    if (rct_backend_usable(RC_BACKEND_EMBREE)) check_order_free(RC_BACKEND_EMBREE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order_is_a_sorted_permutation),
        cmocka_unit_test(test_results_do_not_depend_on_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
