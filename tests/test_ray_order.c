/* The trace order of O1Dn/OnDn sensors (src/sensor/ray_order.c): a
 * permutation of the rays, sorted by its key, with rays of one key cell
 * together; grids have none, nor have rays given in rows (traced in tiles of
 * their scan order); and the order changes no result: the same rays
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

/* An OnDn sensor of the RAYS rays, flat (width 0) or in rows of width. */
static rc_sensor *ondn_shaped(rc_context *ctx, const float *org, const float *dir, uint32_t width)
{
    rc_rays_desc d = rc_rays_desc_default();
    rc_sensor *s = NULL;
    d.common.range_min = 0.05f;
    d.common.range_max = 100.0f;
    d.directions = dir;
    d.origins = org;
    d.ray_count = RAYS;
    d.width = width;
    d.height = width ? RAYS / width : 0u;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s));
    return s;
}

static rc_sensor *ondn(rc_context *ctx, const float *org, const float *dir) { return ondn_shaped(ctx, org, dir, 0u); }

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
    {
        /* rays in rows (60 x 50): scan order, cut into tiles by the steps
         * between the centre ray and its neighbours; a flat list has none */
        rc_sensor *rows = ondn_shaped(ctx, org, dir, 50u);
        double dv = 0.0, dh = 0.0;
        const uint32_t centre = 29u * 50u + 24u;
        const float *c = rows->directions + 3u * centre, *below = c + 3u * 50u, *right = c + 3u;
        const double h2 = (double)c[0] * c[0] + (double)c[1] * c[1];
        rc_rays_desc flat_d = rc_rays_desc_default(), rows_d;
        size_t flat_bytes = 0, rows_bytes = 0;
        assert_null(rows->trace_order);
        assert_int_equal(rc__sensor_traced_ray(rows, 77), 77);
        /* no order table: 8 bytes a ray less than the flat list */
        flat_d.common.range_min = 0.05f;
        flat_d.common.range_max = 100.0f;
        flat_d.directions = dir;
        flat_d.origins = org;
        flat_d.ray_count = RAYS;
        rows_d = flat_d;
        rows_d.width = 50u;
        rows_d.height = RAYS / 50u;
        assert_int_equal(rc_sensor_memory_requirements_rays(RC_SENSOR_ONDN, &flat_d, &flat_bytes), RC_OK);
        assert_int_equal(rc_sensor_memory_requirements_rays(RC_SENSOR_ONDN, &rows_d, &rows_bytes), RC_OK);
        assert_int_equal(flat_bytes - rows_bytes, 8u * RAYS);
        assert_int_equal(rc__sensor_grid_steps(rows, &dv, &dh), 1);
        /* the sines of the elevation and azimuth steps */
        assert_true(dv == fabs((double)below[2] - c[2]));
        assert_true(fabs(dh - fabs((double)c[0] * right[1] - (double)c[1] * right[0]) / h2) < 1e-15);
        assert_int_equal(rc__sensor_grid_steps(s, &dv, &dh), 0);
        assert_int_equal(rc__sensor_grid_steps(grid, &dv, &dh), 1);
        assert_true(fabs(dv - 2.0 * 3.14159265358979 / 180.0) < 1e-6 && fabs(dh - 0.4 * 3.14159265358979 / 180.0) < 1e-6);
    }
    rc_context_destroy(ctx);
    free(org);
    free(dir);
    free(seen);
}

/* The rays reversed make another trace order of the same rays (ties of a key
 * cell go by index): every attribute of ray i equals that of ray N-1-i. The
 * same rays given in rows (no sort: tiles of the scan order) give ray i's
 * attributes bit for bit too. */
static void check_order_free(uint32_t backend)
{
    rcu_mesh sphere;
    rc_context *ctx = rct_context(backend, 2, 32);
    float *org = (float *)malloc(sizeof(float) * 3u * RAYS), *dir = (float *)malloc(sizeof(float) * 3u * RAYS);
    float *rorg = (float *)malloc(sizeof(float) * 3u * RAYS), *rdir = (float *)malloc(sizeof(float) * 3u * RAYS);
    rc_scene *scene;
    rc_sensor *a, *b, *c;
    rct_buffers x, y, z;
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
    c = ondn_shaped(ctx, org, dir, 50u);
    rct_buffers_alloc(&x, RAYS, RC_ATTR_ALL);
    rct_buffers_alloc(&y, RAYS, RC_ATTR_ALL);
    rct_buffers_alloc(&z, RAYS, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, a, &p, 1, &x.res));
    RCT_OK(ctx, rc_simulate(ctx, scene, b, &p, 1, &y.res));
    RCT_OK(ctx, rc_simulate(ctx, scene, c, &p, 1, &z.res));
    for (i = 0; i < RAYS; ++i) {
        const uint32_t j = RAYS - 1u - i;
        assert_int_equal(x.res.hits[i], z.res.hits[i]);
        assert_memory_equal(&x.res.ranges[i], &z.res.ranges[i], sizeof(float));
        assert_memory_equal(&x.res.normals[3u * i], &z.res.normals[3u * i], 3 * sizeof(float));
        assert_int_equal(x.res.prim_ids[i], z.res.prim_ids[i]);
        assert_int_equal(x.res.hits[i], y.res.hits[j]);
        assert_memory_equal(&x.res.ranges[i], &y.res.ranges[j], sizeof(float));
        assert_memory_equal(&x.res.points[3u * i], &y.res.points[3u * j], 3 * sizeof(float));
        assert_memory_equal(&x.res.normals[3u * i], &y.res.normals[3u * j], 3 * sizeof(float));
        assert_int_equal(x.res.prim_ids[i], y.res.prim_ids[j]);
    }
    assert_int_equal(x.res.hits[0], 1); /* inside a closed sphere every ray hits */
    rct_buffers_free(&x);
    rct_buffers_free(&y);
    rct_buffers_free(&z);
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
