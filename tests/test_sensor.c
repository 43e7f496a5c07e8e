/* Sensor layer: direction formulas of every model, presets, validation of every
 * descriptor field, memory accounting against the arena. White-box where the
 * public API has no view (the direction table): includes sensor/sensor.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rangecast/rangecast.h"
#include "rc_test.h"
#include "sensor/sensor.h"

#define PI 3.14159265358979323846
#define DEG(x) ((x) * (PI / 180.0))
#define ARENA_BYTES ((size_t)64 << 20)

/* ------------------------------------------------------------------------ */
/* Helpers                                                                   */
/* ------------------------------------------------------------------------ */

static void assert_near_impl(double a, double b, double tol, const char *what, const char *file, int line)
{
    if (!(fabs(a - b) <= tol)) {
        print_error("%s: %.9g vs %.9g (tol %g)\n", what, a, b, tol);
        _fail(file, line);
    }
}
#define assert_near(a, b, tol) assert_near_impl((double)(a), (double)(b), (tol), #a " ~ " #b, __FILE__, __LINE__)

static void assert_dir_impl(const float *d, double x, double y, double z, double tol, const char *file, int line)
{
    const double n = sqrt(x * x + y * y + z * z);
    assert_near_impl(d[0], x / n, tol, "dir.x", file, line);
    assert_near_impl(d[1], y / n, tol, "dir.y", file, line);
    assert_near_impl(d[2], z / n, tol, "dir.z", file, line);
}
#define assert_dir(d, x, y, z, tol) assert_dir_impl((d), (x), (y), (z), (tol), __FILE__, __LINE__)

static void assert_unit_table(const float *d, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; ++i) {
        const float *v = d + (size_t)i * 3u;
        assert_near(sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]), 1.0, 1e-6);
    }
}

static uint64_t arena_used(const rc_context *ctx)
{
    rc_memory_stats st = rc_memory_stats_default();
    assert_int_equal(rc_context_get_memory_stats(ctx, &st), RC_OK);
    return st.arena_used;
}

static rc_context_desc context_desc(void)
{
    rc_context_desc cd = rc_context_desc_default();
    cd.backend = RC_BACKEND_BVH;
    cd.thread_count = 1;
    return cd;
}

static int setup_ctx(void **state)
{
    rc_context_desc cd = context_desc();
    rc_context *ctx = NULL;
    cd.memory_size = ARENA_BYTES;
    if (rc_context_create(&cd, &ctx) != RC_OK) return -1;
    *state = ctx;
    return 0;
}

static int teardown_ctx(void **state)
{
    rc_context_destroy((rc_context *)*state);
    return 0;
}

/* 16-aligned block inside a malloc'd one (malloc gives only 8 on armhf). */
typedef struct block {
    void *raw;
    void *aligned;
} block;

static block block_alloc(size_t size)
{
    block b;
    b.raw = malloc(size + 16u);
    assert_non_null(b.raw);
    b.aligned = (void *)(((uintptr_t)b.raw + 15u) & ~(uintptr_t)15u);
    return b;
}

/* A valid desc of each model. */
static rc_spherical_desc good_spherical(void)
{
    rc_spherical_desc d = rc_spherical_desc_default();
    d.common.range_min = 0.1f;
    d.common.range_max = 50.0f;
    d.theta.min = (float)DEG(-90.0);
    d.theta.increment = (float)DEG(3.0);
    d.theta.count = 61;
    d.phi.min = (float)DEG(20.0);
    d.phi.increment = (float)DEG(-5.0); /* descending rows are allowed */
    d.phi.count = 9;
    return d;
}

static rc_pinhole_desc good_pinhole(void)
{
    rc_pinhole_desc d = rc_pinhole_desc_default();
    d.common.range_min = 0.1f;
    d.common.range_max = 10.0f;
    d.width = 640;
    d.height = 480;
    d.fx = 500.0f;
    d.fy = 400.0f;
    d.cx = 320.0f;
    d.cy = 240.0f;
    return d;
}

static rc_cylindrical_desc good_cylindrical(void)
{
    rc_cylindrical_desc d = rc_cylindrical_desc_default();
    d.common.range_min = 0.0f;
    d.common.range_max = 30.0f;
    d.theta.min = (float)-PI;
    d.theta.increment = (float)DEG(1.0);
    d.theta.count = 360;
    d.height = 10;
    d.fy = 5.0f;
    d.cy = 4.5f;
    return d;
}

static const float k_dirs[4 * 3] = {2.0f, 0.0f, 0.0f, 0.0f, -3.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 1e-20f};
static const float k_origins[4 * 3] = {0.0f, 0.0f, 0.0f, 1.0f, 2.0f, 3.0f, -1.0f, 0.5f, 0.0f, 0.0f, 0.0f, -7.0f};

static rc_rays_desc good_rays(void)
{
    rc_rays_desc d = rc_rays_desc_default();
    d.common.range_min = 0.0f;
    d.common.range_max = 5.0f;
    d.directions = k_dirs;
    d.ray_count = 4;
    return d;
}

/* ------------------------------------------------------------------------ */
/* Direction formulas                                                        */
/* ------------------------------------------------------------------------ */

static void test_vlp16_preset(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();
    const float *d;
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s), RC_OK);
    assert_non_null(s);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.model, RC_SENSOR_SPHERICAL);
    assert_int_equal(info.rows, 16);
    assert_int_equal(info.columns, 900);
    assert_int_equal(info.rays_per_scan, 16 * 900);
    assert_near(info.range_min, 0.5, 0.0);
    assert_near(info.range_max, 130.0, 0.0);
    d = s->directions;
    /* ray 0: phi -15 deg, theta -180 deg */
    assert_dir(d, cos(DEG(-15.0)) * cos(DEG(-180.0)), cos(DEG(-15.0)) * sin(DEG(-180.0)), sin(DEG(-15.0)), 1e-6);
    /* row 7 (phi -1 deg), column 450 (theta 0): index row * columns + column */
    assert_dir(d + (7u * 900u + 450u) * 3u, cos(DEG(-1.0)), 0.0, sin(DEG(-1.0)), 1e-6);
    /* row 15 (phi +15), column 899 (theta 179.6) */
    assert_dir(d + (15u * 900u + 899u) * 3u, cos(DEG(15.0)) * cos(DEG(179.6)), cos(DEG(15.0)) * sin(DEG(179.6)),
               sin(DEG(15.0)), 1e-5);
    /* row 3 (phi -9), column 225 (theta -90): looks right (-y) and down */
    assert_dir(d + (3u * 900u + 225u) * 3u, 0.0, -cos(DEG(9.0)), sin(DEG(-9.0)), 1e-5);
    assert_unit_table(d, 16u * 900u);
    /* the model's desc is kept for backends */
    assert_int_equal(s->spherical.theta.count, 900);
    assert_int_equal(s->spherical.phi.count, 16);
    assert_int_equal(s->spherical.struct_size, sizeof(rc_spherical_desc));
    assert_null(s->origins);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_other_spherical_presets(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();
    rc_spherical_desc d;

    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.rows, 16);
    assert_int_equal(info.columns, 360);
    /* column 90: theta = -90 deg */
    assert_dir(s->directions + (0u * 360u + 90u) * 3u, 0.0, -cos(DEG(-15.0)), sin(DEG(-15.0)), 1e-5);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);

    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_OUSTER_OS1_64, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.rows, 64);
    assert_int_equal(info.columns, 1024);
    assert_near(info.range_min, 0.3, 1e-7);
    assert_near(info.range_max, 120.0, 0.0);
    /* top row is +22.5 deg, column 512 is theta 0 */
    assert_dir(s->directions + (63u * 1024u + 512u) * 3u, cos(DEG(22.5)), 0.0, sin(DEG(22.5)), 1e-5);
    assert_dir(s->directions, -cos(DEG(-22.5)), 0.0, sin(DEG(-22.5)), 1e-5);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);

    assert_int_equal(rc_preset_spherical(RC_PRESET_OUSTER_OS1_64, &d), RC_OK);
    assert_near(d.phi.increment, DEG(45.0 / 63.0), 1e-7);
    assert_near(d.theta.increment, DEG(360.0 / 1024.0), 1e-7);
}

/* The 2-D scanner presets: one row at phi 0, columns in a ROS LaserScan's
 * order, and ranges in a closed box room (-2..2 x -3..3 m) where each ray
 * meets a wall at min(2 / |cos theta|, 3 / |sin theta|), or returns +inf past
 * the LDS-01's 3.5 m (the room's corners are 3.6 m away). */
static void check_scanner_in_room(rc_context *ctx, rc_sensor *s, double theta0_deg, double step_deg, uint32_t n,
                                  double rmax)
{
    static const float lo[3] = {-2, -3, -1}, hi[3] = {2, 3, 1};
    rcu_mesh box;
    rc_results res = rc_results_default();
    rc_pose pose = rc_pose_identity();
    rc_scene *room;
    float *ranges = (float *)malloc(sizeof(float) * n);
    uint32_t j, far = 0;
    assert_non_null(ranges);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    room = rct_scene_mesh(ctx, &box, RC_MESH_COPY);
    res.attributes = RC_ATTR_RANGES;
    res.ranges = ranges;
    res.capacity = n;
    assert_int_equal(rc_simulate(ctx, room, s, &pose, 1, &res), RC_OK);
    for (j = 0; j < n; ++j) {
        const double th = DEG(theta0_deg + step_deg * j), c = fabs(cos(th)), sn = fabs(sin(th));
        const double want = fmin(c > 1e-12 ? 2.0 / c : INFINITY, sn > 1e-12 ? 3.0 / sn : INFINITY);
        if (fabs(want - rmax) < 1e-3) continue; /* at range max either answer is right */
        if (want > rmax) {
            assert_true(isinf(ranges[j]) && ranges[j] > 0.0f);
            ++far;
        } else {
            assert_near(ranges[j], want, 1e-5 * want);
        }
    }
    if (rmax < 3.6) assert_true(far > 0); /* the corners are out of reach */
    assert_int_equal(rc_scene_destroy(room), RC_OK);
    rcu_mesh_free(&box);
    free(ranges);
}

static void test_laser_scanner_presets(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();

    assert_int_equal(rc_preset_model(RC_PRESET_HOKUYO_UST10LX), RC_SENSOR_SPHERICAL);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_HOKUYO_UST10LX, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.rows, 1);
    assert_int_equal(info.columns, 1081);
    assert_near(info.range_min, 0.06, 1e-7);
    assert_near(info.range_max, 10.0, 0.0);
    assert_dir(s->directions, cos(DEG(-135.0)), sin(DEG(-135.0)), 0.0, 1e-6);
    assert_dir(s->directions + 540u * 3u, 1.0, 0.0, 0.0, 1e-6);          /* straight ahead */
    assert_dir(s->directions + 900u * 3u, cos(DEG(90.0)), 1.0, 0.0, 1e-5); /* left: counterclockwise */
    assert_dir(s->directions + 1080u * 3u, cos(DEG(135.0)), sin(DEG(135.0)), 0.0, 1e-5);
    assert_unit_table(s->directions, 1081u);
    check_scanner_in_room(ctx, s, -135.0, 0.25, 1081u, 10.0);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);

    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_ROBOTIS_LDS01, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.rows, 1);
    assert_int_equal(info.columns, 360);
    assert_near(info.range_min, 0.12, 1e-7);
    assert_near(info.range_max, 3.5, 0.0);
    assert_dir(s->directions, 1.0, 0.0, 0.0, 1e-7);
    assert_dir(s->directions + 90u * 3u, 0.0, 1.0, 0.0, 1e-6);
    assert_dir(s->directions + 359u * 3u, cos(DEG(359.0)), sin(DEG(359.0)), 0.0, 1e-6);
    check_scanner_in_room(ctx, s, 0.0, 1.0, 360u, 3.5);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

/* Every ray of a custom spherical sensor against the header's formula. */
static void test_spherical_formula(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_spherical_desc d = good_spherical();
    rc_sensor *s = NULL;
    uint32_t i, j;
    assert_int_equal(rc_sensor_create_spherical(ctx, &d, &s), RC_OK);
    assert_int_equal(s->rows, d.phi.count);
    assert_int_equal(s->columns, d.theta.count);
    for (i = 0; i < d.phi.count; ++i)
        for (j = 0; j < d.theta.count; ++j) {
            const double phi = (double)d.phi.min + i * (double)d.phi.increment;
            const double theta = (double)d.theta.min + j * (double)d.theta.increment;
            assert_dir(s->directions + ((size_t)i * d.theta.count + j) * 3u, cos(phi) * cos(theta),
                       cos(phi) * sin(theta), sin(phi), 1e-6);
        }
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_single_row_axis(void **state)
{
    /* A 2D scanner: one row, increment 0 is fine when count is 1. */
    rc_context *ctx = (rc_context *)*state;
    rc_spherical_desc d = good_spherical();
    rc_sensor *s = NULL;
    d.phi.min = 0.0f;
    d.phi.increment = 0.0f;
    d.phi.count = 1;
    assert_int_equal(rc_sensor_create_spherical(ctx, &d, &s), RC_OK);
    assert_dir(s->directions, 0.0, -1.0, 0.0, 1e-6); /* theta -90 */
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_pinhole_frames(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_pinhole_desc d = good_pinhole();
    rc_sensor *body = NULL, *optical = NULL;
    const uint32_t w = 640;
    assert_int_equal(rc_sensor_create_pinhole(ctx, &d, &body), RC_OK);
    d.frame = RC_PINHOLE_FRAME_OPTICAL;
    assert_int_equal(rc_sensor_create_pinhole(ctx, &d, &optical), RC_OK);
    assert_int_equal(body->rows, 480);
    assert_int_equal(body->columns, 640);
    assert_int_equal(body->pinhole_frame, RC_PINHOLE_FRAME_BODY);
    assert_int_equal(optical->pinhole_frame, RC_PINHOLE_FRAME_OPTICAL);

    /* centre pixel (u = cx, v = cy; no half-pixel offset): +x body, +z optical */
    assert_dir(body->directions + (240u * w + 320u) * 3u, 1.0, 0.0, 0.0, 1e-7);
    assert_dir(optical->directions + (240u * w + 320u) * 3u, 0.0, 0.0, 1.0, 1e-7);
    /* to the right (u > cx): -y in body, +x in optical */
    assert_dir(body->directions + (240u * w + 400u) * 3u, 1.0, -80.0 / 500.0, 0.0, 1e-6);
    assert_dir(optical->directions + (240u * w + 400u) * 3u, 80.0 / 500.0, 0.0, 1.0, 1e-6);
    assert_true(body->directions[(240u * w + 400u) * 3u + 1] < 0.0f);
    assert_true(optical->directions[(240u * w + 400u) * 3u + 0] > 0.0f);
    /* below (v > cy): -z in body, +y in optical */
    assert_dir(body->directions + (440u * w + 320u) * 3u, 1.0, 0.0, -200.0 / 400.0, 1e-6);
    assert_dir(optical->directions + (440u * w + 320u) * 3u, 0.0, 200.0 / 400.0, 1.0, 1e-6);
    /* a corner: pixel (0, 0) */
    assert_dir(body->directions, 1.0, 320.0 / 500.0, 240.0 / 400.0, 1e-6);
    assert_dir(optical->directions, -320.0 / 500.0, -240.0 / 400.0, 1.0, 1e-6);
    assert_unit_table(body->directions, 640u * 480u);
    assert_unit_table(optical->directions, 640u * 480u);
    assert_near(body->pinhole.fx, 500.0, 0.0);
    assert_int_equal(rc_sensor_destroy(body), RC_OK);
    assert_int_equal(rc_sensor_destroy(optical), RC_OK);
}

static void test_d435_preset(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_pinhole_desc d;
    rc_sensor *s = NULL;
    assert_int_equal(rc_preset_pinhole(RC_PRESET_REALSENSE_D435, &d), RC_OK);
    assert_int_equal(d.width, 848);
    assert_int_equal(d.height, 480);
    assert_int_equal(d.frame, RC_PINHOLE_FRAME_BODY);
    assert_near(d.fx, 424.0 / tan(DEG(43.5)), 1e-3);
    assert_near(d.fy, 240.0 / tan(DEG(29.0)), 1e-3);
    assert_near(d.cx, 424.0, 0.0);
    assert_near(d.cy, 240.0, 0.0);
    assert_near(d.common.range_min, 0.1, 1e-7);
    assert_near(d.common.range_max, 10.0, 0.0);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_REALSENSE_D435, &s), RC_OK);
    /* optical axis at (424, 240); column 0 is 43.5 deg to the left (+y) */
    assert_dir(s->directions + (240u * 848u + 424u) * 3u, 1.0, 0.0, 0.0, 1e-7);
    assert_dir(s->directions + (240u * 848u + 0u) * 3u, cos(DEG(43.5)), sin(DEG(43.5)), 0.0, 1e-6);
    /* row 0 is 29 deg up */
    assert_dir(s->directions + (0u * 848u + 424u) * 3u, cos(DEG(29.0)), 0.0, sin(DEG(29.0)), 1e-6);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_cylindrical_formula(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_cylindrical_desc d = good_cylindrical();
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();
    uint32_t v, j;
    assert_int_equal(rc_sensor_create_cylindrical(ctx, &d, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.model, RC_SENSOR_CYLINDRICAL);
    assert_int_equal(info.rows, 10);
    assert_int_equal(info.columns, 360);
    for (v = 0; v < d.height; ++v)
        for (j = 0; j < d.theta.count; ++j) {
            const double theta = (double)d.theta.min + j * (double)d.theta.increment;
            const double h = ((double)d.cy - v) / (double)d.fy;
            assert_dir(s->directions + ((size_t)v * d.theta.count + j) * 3u, cos(theta), sin(theta), h, 1e-6);
        }
    /* row 0 looks up (h = 0.9), row 9 down; column 180 is theta 0 */
    assert_dir(s->directions + (0u * 360u + 180u) * 3u, 1.0, 0.0, 0.9, 1e-6);
    assert_dir(s->directions + (9u * 360u + 180u) * 3u, 1.0, 0.0, -0.9, 1e-6);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_rosette(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    const double half = DEG(38.4 / 2.0);
    rc_rays_desc d;
    uint32_t n = 0, i, quadrant[4] = {0, 0, 0, 0};
    float *dirs, *again;
    double max_angle = 0.0;
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();

    assert_int_equal(rc_preset_model(RC_PRESET_LIVOX_MID40), RC_SENSOR_O1DN);
    assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, &d, NULL, &n), RC_OK);
    assert_int_equal(n, 10000);
    assert_int_equal(d.ray_count, 10000);
    assert_null(d.directions);
    assert_near(d.common.range_min, 0.1, 1e-7);
    assert_near(d.common.range_max, 260.0, 0.0);

    dirs = (float *)calloc((size_t)n * 3u, sizeof(float));
    again = (float *)calloc((size_t)n * 3u, sizeof(float));
    assert_non_null(dirs);
    assert_non_null(again);
    /* a buffer too small: RC_ERR_CAPACITY and nothing written */
    {
        uint32_t small = n - 1;
        assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, NULL, dirs, &small), RC_ERR_CAPACITY);
        assert_int_equal(small, n - 1);
        for (i = 0; i < n * 3u; ++i) assert_true(dirs[i] == 0.0f);
    }
    assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, &d, dirs, &n), RC_OK);
    assert_ptr_equal(d.directions, dirs);
    assert_unit_table(dirs, n);
    for (i = 0; i < n; ++i) {
        const float *v = dirs + (size_t)i * 3u;
        const double angle = acos(RC__MIN(1.0, (double)v[0]));
        assert_true(v[0] > 0.0f);
        assert_true(angle <= half + 1e-5);
        if (angle > max_angle) max_angle = angle;
        if (angle > 0.5 * half) quadrant[(v[1] >= 0.0f ? 0 : 1) + (v[2] >= 0.0f ? 0 : 2)]++;
    }
    /* it fills the cone: reaches its edge, outer rays in every quadrant */
    assert_true(max_angle > 0.99 * half);
    for (i = 0; i < 4; ++i) assert_true(quadrant[i] > n / 20u);
    /* deterministic */
    assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, NULL, again, &n), RC_OK);
    assert_memory_equal(dirs, again, (size_t)n * 3u * sizeof(float));

    /* the preset sensor holds exactly these, one row of 10,000 */
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_LIVOX_MID40, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.model, RC_SENSOR_O1DN);
    assert_int_equal(info.rows, 1);
    assert_int_equal(info.columns, 10000);
    assert_int_equal(info.rays_per_scan, 10000);
    assert_memory_equal(s->directions, dirs, (size_t)n * 3u * sizeof(float));
    assert_null(s->origins);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);

    /* a rays desc filled by the preset creates the same sensor (up to the
     * last bit: create_rays normalises the float directions again) */
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d, &s), RC_OK);
    for (i = 0; i < n * 3u; ++i) assert_near(s->directions[i], dirs[i], 1e-7);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
    free(dirs);
    free(again);
}

static void test_o1dn_normalised(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_rays_desc d = good_rays();
    rc_sensor *s = NULL;
    rc_sensor_info info = rc_sensor_info_default();
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, &info), RC_OK);
    assert_int_equal(info.model, RC_SENSOR_O1DN);
    assert_int_equal(info.rows, 1); /* width = height = 0: one row of ray_count */
    assert_int_equal(info.columns, 4);
    assert_int_equal(info.rays_per_scan, 4);
    assert_dir(s->directions + 0, 1.0, 0.0, 0.0, 0.0);
    assert_dir(s->directions + 3, 0.0, -1.0, 0.0, 0.0);
    assert_dir(s->directions + 6, 1.0, 1.0, 1.0, 1e-7);
    assert_dir(s->directions + 9, 0.0, 0.0, 1.0, 0.0); /* tiny but non-zero */
    assert_null(s->origins);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);

    d.width = 2;
    d.height = 2;
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d, &s), RC_OK);
    assert_int_equal(s->rows, 2);
    assert_int_equal(s->columns, 2);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_ondn_origins(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_rays_desc d = good_rays();
    rc_sensor *s = NULL;
    d.origins = k_origins;
    d.width = 4;
    d.height = 1;
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s), RC_OK);
    assert_int_equal(s->model, RC_SENSOR_ONDN);
    assert_non_null(s->origins);
    assert_memory_equal(s->origins, k_origins, sizeof k_origins);
    assert_dir(s->directions + 3, 0.0, -1.0, 0.0, 0.0);
    assert_true(((uintptr_t)s->origins % 16u) == 0);
    assert_true(((uintptr_t)s->directions % 16u) == 0);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

/* ------------------------------------------------------------------------ */
/* Bad input, table-driven                                                    */
/* ------------------------------------------------------------------------ */

enum { K_SPH, K_PIN, K_CYL, K_O1DN, K_ONDN, K_MODEL3 };

typedef struct descs {
    rc_spherical_desc sph;
    rc_pinhole_desc pin;
    rc_cylindrical_desc cyl;
    rc_rays_desc rays;
    float dirs[12];
    float orgs[12];
} descs;

typedef struct bad_case {
    const char *name;
    int kind;
    void (*mutate)(descs *d);
    rc_status expect;
} bad_case;

#define MUT(fn, ...) \
    static void fn(descs *d) { __VA_ARGS__; }

MUT(nothing, (void)d)
MUT(sph_size_small, d->sph.struct_size = (uint32_t)sizeof(rc_spherical_desc) - 4u)
MUT(sph_size_large, d->sph.struct_size = (uint32_t)sizeof(rc_spherical_desc) + 4u)
MUT(sph_size_zero, d->sph.struct_size = 0)
MUT(sph_reserved0, d->sph.reserved0 = 1)
MUT(sph_reserved7, d->sph.reserved[7] = 1)
MUT(sph_rmin_nan, d->sph.common.range_min = (float)NAN)
MUT(sph_rmax_inf, d->sph.common.range_max = (float)INFINITY)
MUT(sph_rmin_neg, d->sph.common.range_min = -1.0f)
MUT(sph_rmin_eq, d->sph.common.range_min = d->sph.common.range_max)
MUT(sph_rmin_gt, d->sph.common.range_min = 60.0f)
MUT(sph_zero_ranges, d->sph.common.range_min = 0.0f; d->sph.common.range_max = 0.0f)
MUT(sph_theta_count0, d->sph.theta.count = 0)
MUT(sph_phi_count0, d->sph.phi.count = 0)
MUT(sph_theta_inc0, d->sph.theta.increment = 0.0f)
MUT(sph_phi_inc0, d->sph.phi.increment = 0.0f)
MUT(sph_phi_min_nan, d->sph.phi.min = (float)NAN)
MUT(sph_theta_inc_inf, d->sph.theta.increment = (float)-INFINITY)
MUT(sph_too_many, d->sph.theta.count = 65536u; d->sph.phi.count = 65537u)
MUT(sph_quat_zero, d->sph.common.sensor_to_base.orientation[3] = 0.0f)
MUT(sph_quat_long, d->sph.common.sensor_to_base.orientation[3] = 2.0f)
MUT(sph_quat_nan, d->sph.common.sensor_to_base.orientation[0] = (float)NAN)
MUT(sph_pos_inf, d->sph.common.sensor_to_base.position[2] = (float)INFINITY)
MUT(pin_fx_nan, d->pin.fx = (float)NAN)
MUT(pin_fx_zero, d->pin.fx = 0.0f)
MUT(pin_fy_neg, d->pin.fy = -400.0f)
MUT(pin_cx_inf, d->pin.cx = (float)INFINITY)
MUT(pin_cy_nan, d->pin.cy = (float)NAN)
MUT(pin_width0, d->pin.width = 0)
MUT(pin_height0, d->pin.height = 0)
MUT(pin_frame2, d->pin.frame = 2)
MUT(pin_reserved, d->pin.reserved[0] = 0xFFFFFFFFu)
MUT(pin_size_small, d->pin.struct_size = 8)
MUT(pin_rmax_nan, d->pin.common.range_max = (float)NAN)
MUT(cyl_fy0, d->cyl.fy = 0.0f)
MUT(cyl_cy_nan, d->cyl.cy = (float)NAN)
MUT(cyl_height0, d->cyl.height = 0)
MUT(cyl_theta_count0, d->cyl.theta.count = 0)
MUT(cyl_theta_inc0, d->cyl.theta.increment = 0.0f)
MUT(cyl_reserved0, d->cyl.reserved0 = 3)
MUT(cyl_size_small, d->cyl.struct_size = 4)
MUT(rays_dirs_null, d->rays.directions = NULL)
MUT(rays_zero_dir, d->dirs[6] = 0.0f; d->dirs[7] = 0.0f; d->dirs[8] = -0.0f)
MUT(rays_nan_dir, d->dirs[4] = (float)NAN)
MUT(rays_count0, d->rays.ray_count = 0)
MUT(rays_shape_bad, d->rays.width = 3; d->rays.height = 1)
MUT(rays_shape_half, d->rays.width = 4; d->rays.height = 0)
MUT(rays_reserved, d->rays.reserved[3] = 1)
MUT(rays_reserved0, d->rays.reserved0 = 1)
MUT(rays_size_small, d->rays.struct_size = 16)
MUT(rays_origins_o1dn, d->rays.origins = d->orgs)
MUT(ondn_origins_null, d->rays.origins = NULL)
MUT(ondn_origin_nan, d->orgs[11] = (float)NAN)
MUT(rays_rmin_neg, d->rays.common.range_min = -0.5f)

static const bad_case k_bad[] = {
    {"spherical struct_size too small", K_SPH, sph_size_small, RC_ERR_STRUCT_SIZE},
    {"spherical struct_size too large", K_SPH, sph_size_large, RC_ERR_STRUCT_SIZE},
    {"spherical struct_size 0", K_SPH, sph_size_zero, RC_ERR_STRUCT_SIZE},
    {"spherical reserved0", K_SPH, sph_reserved0, RC_ERR_INVALID_ARGUMENT},
    {"spherical reserved[7]", K_SPH, sph_reserved7, RC_ERR_INVALID_ARGUMENT},
    {"spherical range_min NaN", K_SPH, sph_rmin_nan, RC_ERR_NON_FINITE},
    {"spherical range_max inf", K_SPH, sph_rmax_inf, RC_ERR_NON_FINITE},
    {"spherical range_min < 0", K_SPH, sph_rmin_neg, RC_ERR_INVALID_ARGUMENT},
    {"spherical range_min == range_max", K_SPH, sph_rmin_eq, RC_ERR_INVALID_ARGUMENT},
    {"spherical range_min > range_max", K_SPH, sph_rmin_gt, RC_ERR_INVALID_ARGUMENT},
    {"spherical ranges left 0", K_SPH, sph_zero_ranges, RC_ERR_INVALID_ARGUMENT},
    {"spherical theta.count 0", K_SPH, sph_theta_count0, RC_ERR_INVALID_ARGUMENT},
    {"spherical phi.count 0", K_SPH, sph_phi_count0, RC_ERR_INVALID_ARGUMENT},
    {"spherical theta.increment 0", K_SPH, sph_theta_inc0, RC_ERR_INVALID_ARGUMENT},
    {"spherical phi.increment 0", K_SPH, sph_phi_inc0, RC_ERR_INVALID_ARGUMENT},
    {"spherical phi.min NaN", K_SPH, sph_phi_min_nan, RC_ERR_NON_FINITE},
    {"spherical theta.increment -inf", K_SPH, sph_theta_inc_inf, RC_ERR_NON_FINITE},
    {"spherical more than 2^32 rays", K_SPH, sph_too_many, RC_ERR_INVALID_ARGUMENT},
    {"spherical zero quaternion", K_SPH, sph_quat_zero, RC_ERR_INVALID_ARGUMENT},
    {"spherical quaternion norm 2", K_SPH, sph_quat_long, RC_ERR_INVALID_ARGUMENT},
    {"spherical quaternion NaN", K_SPH, sph_quat_nan, RC_ERR_NON_FINITE},
    {"spherical position inf", K_SPH, sph_pos_inf, RC_ERR_NON_FINITE},
    {"pinhole fx NaN", K_PIN, pin_fx_nan, RC_ERR_NON_FINITE},
    {"pinhole fx 0", K_PIN, pin_fx_zero, RC_ERR_INVALID_ARGUMENT},
    {"pinhole fy < 0", K_PIN, pin_fy_neg, RC_ERR_INVALID_ARGUMENT},
    {"pinhole cx inf", K_PIN, pin_cx_inf, RC_ERR_NON_FINITE},
    {"pinhole cy NaN", K_PIN, pin_cy_nan, RC_ERR_NON_FINITE},
    {"pinhole width 0", K_PIN, pin_width0, RC_ERR_INVALID_ARGUMENT},
    {"pinhole height 0", K_PIN, pin_height0, RC_ERR_INVALID_ARGUMENT},
    {"pinhole frame 2", K_PIN, pin_frame2, RC_ERR_INVALID_ARGUMENT},
    {"pinhole reserved[0]", K_PIN, pin_reserved, RC_ERR_INVALID_ARGUMENT},
    {"pinhole struct_size 8", K_PIN, pin_size_small, RC_ERR_STRUCT_SIZE},
    {"pinhole range_max NaN", K_PIN, pin_rmax_nan, RC_ERR_NON_FINITE},
    {"cylindrical fy 0", K_CYL, cyl_fy0, RC_ERR_INVALID_ARGUMENT},
    {"cylindrical cy NaN", K_CYL, cyl_cy_nan, RC_ERR_NON_FINITE},
    {"cylindrical height 0", K_CYL, cyl_height0, RC_ERR_INVALID_ARGUMENT},
    {"cylindrical theta.count 0", K_CYL, cyl_theta_count0, RC_ERR_INVALID_ARGUMENT},
    {"cylindrical theta.increment 0", K_CYL, cyl_theta_inc0, RC_ERR_INVALID_ARGUMENT},
    {"cylindrical reserved0", K_CYL, cyl_reserved0, RC_ERR_INVALID_ARGUMENT},
    {"cylindrical struct_size 4", K_CYL, cyl_size_small, RC_ERR_STRUCT_SIZE},
    {"o1dn directions NULL", K_O1DN, rays_dirs_null, RC_ERR_INVALID_ARGUMENT},
    {"o1dn zero direction", K_O1DN, rays_zero_dir, RC_ERR_INVALID_ARGUMENT},
    {"o1dn NaN direction", K_O1DN, rays_nan_dir, RC_ERR_NON_FINITE},
    {"o1dn ray_count 0", K_O1DN, rays_count0, RC_ERR_INVALID_ARGUMENT},
    {"o1dn width x height != ray_count", K_O1DN, rays_shape_bad, RC_ERR_INVALID_ARGUMENT},
    {"o1dn height 0, width set", K_O1DN, rays_shape_half, RC_ERR_INVALID_ARGUMENT},
    {"o1dn reserved[3]", K_O1DN, rays_reserved, RC_ERR_INVALID_ARGUMENT},
    {"o1dn reserved0", K_O1DN, rays_reserved0, RC_ERR_INVALID_ARGUMENT},
    {"o1dn struct_size 16", K_O1DN, rays_size_small, RC_ERR_STRUCT_SIZE},
    {"o1dn with origins", K_O1DN, rays_origins_o1dn, RC_ERR_INVALID_ARGUMENT},
    {"o1dn range_min < 0", K_O1DN, rays_rmin_neg, RC_ERR_INVALID_ARGUMENT},
    {"ondn origins NULL", K_ONDN, ondn_origins_null, RC_ERR_INVALID_ARGUMENT},
    {"ondn NaN origin", K_ONDN, ondn_origin_nan, RC_ERR_NON_FINITE},
    {"ondn zero direction", K_ONDN, rays_zero_dir, RC_ERR_INVALID_ARGUMENT},
    {"rays model 3 (cylindrical)", K_MODEL3, nothing, RC_ERR_INVALID_ARGUMENT},
};

static void make_descs(descs *d)
{
    memset(d, 0, sizeof *d);
    d->sph = good_spherical();
    d->pin = good_pinhole();
    d->cyl = good_cylindrical();
    memcpy(d->dirs, k_dirs, sizeof d->dirs);
    memcpy(d->orgs, k_origins, sizeof d->orgs);
    d->rays = good_rays();
    d->rays.directions = d->dirs;
}

static rc_status create_kind(rc_context *ctx, int kind, descs *d, rc_sensor **out)
{
    switch (kind) {
    case K_SPH: return rc_sensor_create_spherical(ctx, &d->sph, out);
    case K_PIN: return rc_sensor_create_pinhole(ctx, &d->pin, out);
    case K_CYL: return rc_sensor_create_cylindrical(ctx, &d->cyl, out);
    case K_O1DN: return rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d->rays, out);
    case K_ONDN: return rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d->rays, out);
    default: return rc_sensor_create_rays(ctx, RC_SENSOR_CYLINDRICAL, &d->rays, out);
    }
}

static rc_status requirements_kind(int kind, descs *d, size_t *bytes)
{
    switch (kind) {
    case K_SPH: return rc_sensor_memory_requirements_spherical(&d->sph, bytes);
    case K_PIN: return rc_sensor_memory_requirements_pinhole(&d->pin, bytes);
    case K_CYL: return rc_sensor_memory_requirements_cylindrical(&d->cyl, bytes);
    case K_O1DN: return rc_sensor_memory_requirements_rays(RC_SENSOR_O1DN, &d->rays, bytes);
    case K_ONDN: return rc_sensor_memory_requirements_rays(RC_SENSOR_ONDN, &d->rays, bytes);
    default: return rc_sensor_memory_requirements_rays(RC_SENSOR_CYLINDRICAL, &d->rays, bytes);
    }
}

static void test_bad_inputs(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *const sentinel = (rc_sensor *)(uintptr_t)0x1234;
    const uint64_t used0 = arena_used(ctx);
    size_t i;
    int kind;

    /* the unmutated descs of every kind are valid (ONDN needs its origins) */
    for (kind = K_SPH; kind <= K_ONDN; ++kind) {
        descs d;
        rc_sensor *s = NULL;
        make_descs(&d);
        if (kind == K_ONDN) d.rays.origins = d.orgs;
        assert_int_equal(create_kind(ctx, kind, &d, &s), RC_OK);
        assert_int_equal(rc_sensor_destroy(s), RC_OK);
    }
    assert_int_equal(arena_used(ctx), used0);

    for (i = 0; i < sizeof k_bad / sizeof k_bad[0]; ++i) {
        const bad_case *c = &k_bad[i];
        descs d;
        rc_sensor *out = sentinel;
        size_t bytes = 777;
        rc_status st, st_req;
        make_descs(&d);
        if (c->kind == K_ONDN) d.rays.origins = d.orgs;
        c->mutate(&d);
        st = create_kind(ctx, c->kind, &d, &out);
        st_req = requirements_kind(c->kind, &d, &bytes);
        if (st != c->expect || st_req != c->expect || out != sentinel || bytes != 777 ||
            arena_used(ctx) != used0 || rc_context_last_error(ctx)[0] == '\0') {
            print_error("case '%s': create %d, requirements %d, expected %d; out %s; bytes %s; message '%s'\n",
                        c->name, (int)st, (int)st_req, (int)c->expect, out == sentinel ? "untouched" : "WRITTEN",
                        bytes == 777 ? "untouched" : "WRITTEN", rc_context_last_error(ctx));
            fail();
        }
    }
    assert_null(((rc_context *)ctx)->sensors);
}

static void test_null_arguments(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *const sentinel = (rc_sensor *)(uintptr_t)0x1234;
    rc_sensor *out = sentinel, *s = NULL;
    descs d;
    size_t bytes = 5;
    rc_sensor_info info = rc_sensor_info_default();
    rc_pose pose = rc_pose_identity();
    make_descs(&d);

    /* NULL context */
    assert_int_equal(rc_sensor_create_spherical(NULL, &d.sph, &out), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_create_pinhole(NULL, &d.pin, &out), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_create_cylindrical(NULL, &d.cyl, &out), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_create_rays(NULL, RC_SENSOR_O1DN, &d.rays, &out), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_create_preset(NULL, RC_PRESET_VELODYNE_VLP16, &out), RC_ERR_INVALID_HANDLE);
    assert_ptr_equal(out, sentinel);

    /* NULL desc: the message names it */
    assert_int_equal(rc_sensor_create_spherical(ctx, NULL, &out), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "desc"));
    assert_int_equal(rc_sensor_create_pinhole(ctx, NULL, &out), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_cylindrical(ctx, NULL, &out), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, NULL, &out), RC_ERR_INVALID_ARGUMENT);
    assert_ptr_equal(out, sentinel);

    /* NULL out */
    assert_int_equal(rc_sensor_create_spherical(ctx, &d.sph, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_pinhole(ctx, &d.pin, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_cylindrical(ctx, &d.cyl, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d.rays, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_null(ctx->sensors);

    /* unknown preset */
    assert_int_equal(rc_sensor_create_preset(ctx, 0, &out), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_create_preset(ctx, 99, &out), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "99"));
    assert_ptr_equal(out, sentinel);

    /* size queries */
    assert_int_equal(rc_sensor_memory_requirements_spherical(NULL, &bytes), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_spherical(&d.sph, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_pinhole(NULL, &bytes), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_cylindrical(NULL, &bytes), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_rays(RC_SENSOR_O1DN, NULL, &bytes), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_preset(99, &bytes), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_memory_requirements_preset(RC_PRESET_OUSTER_OS1_64, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(bytes, 5);

    /* handles */
    assert_int_equal(rc_sensor_destroy(NULL), RC_OK);
    assert_int_equal(rc_sensor_get_info(NULL, &info), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_set_mounting(NULL, &pose), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_get_info((const rc_sensor *)(const void *)ctx, &info), RC_ERR_INVALID_HANDLE);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &s), RC_OK);
    assert_int_equal(rc_sensor_get_info(s, NULL), RC_ERR_INVALID_ARGUMENT);
    info.struct_size = 0;
    assert_int_equal(rc_sensor_get_info(s, &info), RC_ERR_STRUCT_SIZE);
    assert_int_equal(info.rows, 0);
    assert_int_equal(rc_sensor_set_mounting(s, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_presets_api(void **state)
{
    rc_spherical_desc sd = rc_spherical_desc_default();
    rc_pinhole_desc pd = rc_pinhole_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    uint32_t n = 0;
    float one[3];
    (void)state;
    assert_int_equal(rc_preset_from_name("vlp16"), RC_PRESET_VELODYNE_VLP16);
    assert_int_equal(rc_preset_from_name("vlp16-360"), RC_PRESET_VELODYNE_VLP16_360);
    assert_int_equal(rc_preset_from_name("os1-64"), RC_PRESET_OUSTER_OS1_64);
    assert_int_equal(rc_preset_from_name("d435"), RC_PRESET_REALSENSE_D435);
    assert_int_equal(rc_preset_from_name("livox-mid40"), RC_PRESET_LIVOX_MID40);
    assert_int_equal(rc_preset_from_name("ust-10lx"), RC_PRESET_HOKUYO_UST10LX);
    assert_int_equal(rc_preset_from_name("LDS-01"), RC_PRESET_ROBOTIS_LDS01);
    assert_int_equal(rc_preset_from_name("VLP16"), RC_PRESET_VELODYNE_VLP16);
    assert_int_equal(rc_preset_from_name("vlp1"), 0);
    assert_int_equal(rc_preset_from_name("vlp16x"), 0);
    assert_int_equal(rc_preset_from_name(""), 0);
    assert_int_equal(rc_preset_from_name(NULL), 0);

    assert_int_equal(rc_preset_model(RC_PRESET_VELODYNE_VLP16), RC_SENSOR_SPHERICAL);
    assert_int_equal(rc_preset_model(RC_PRESET_REALSENSE_D435), RC_SENSOR_PINHOLE);
    assert_int_equal(rc_preset_model(0), 0);
    assert_int_equal(rc_preset_model(1000), 0);

    /* wrong model, NULL desc: nothing written */
    sd.theta.count = 7;
    assert_int_equal(rc_preset_spherical(RC_PRESET_REALSENSE_D435, &sd), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(sd.theta.count, 7);
    assert_int_equal(rc_preset_spherical(RC_PRESET_VELODYNE_VLP16, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_preset_pinhole(RC_PRESET_VELODYNE_VLP16, &pd), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_preset_pinhole(RC_PRESET_REALSENSE_D435, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_preset_rays(RC_PRESET_VELODYNE_VLP16, &rd, NULL, &n), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, &rd, NULL, NULL), RC_ERR_INVALID_ARGUMENT);
    n = 1;
    assert_int_equal(rc_preset_rays(RC_PRESET_LIVOX_MID40, &rd, one, &n), RC_ERR_CAPACITY);
    assert_int_equal(rd.ray_count, 0);

    /* a filled preset is a valid desc, with the identity mounting */
    assert_int_equal(rc_preset_spherical(RC_PRESET_VELODYNE_VLP16, &sd), RC_OK);
    assert_int_equal(sd.struct_size, sizeof sd);
    assert_near(sd.phi.min, DEG(-15.0), 1e-7);
    assert_near(sd.phi.increment, DEG(2.0), 1e-7);
    assert_near(sd.theta.min, -PI, 1e-6);
    assert_near(sd.theta.increment, DEG(0.4), 1e-7);
    assert_near(sd.common.sensor_to_base.orientation[3], 1.0, 0.0);
    assert_int_equal(rc__sensor_check_spherical(NULL, &sd), RC_OK);
}

/* ------------------------------------------------------------------------ */
/* Memory                                                                    */
/* ------------------------------------------------------------------------ */

static void test_requirements_match_arena(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    const uint64_t used0 = arena_used(ctx);
    int kind;
    uint32_t preset;
    for (kind = K_SPH; kind <= K_ONDN; ++kind) {
        descs d;
        size_t bytes = 0;
        uint64_t before;
        rc_sensor *s = NULL;
        make_descs(&d);
        if (kind == K_ONDN) d.rays.origins = d.orgs;
        assert_int_equal(requirements_kind(kind, &d, &bytes), RC_OK);
        before = arena_used(ctx);
        assert_int_equal(create_kind(ctx, kind, &d, &s), RC_OK);
        assert_int_equal(arena_used(ctx) - before, bytes);
        assert_int_equal(rc_sensor_destroy(s), RC_OK);
        assert_int_equal(arena_used(ctx), before);
    }
    for (preset = 1; preset <= 5; ++preset) {
        size_t bytes = 0;
        uint64_t before;
        rc_sensor *s = NULL;
        assert_int_equal(rc_sensor_memory_requirements_preset(preset, &bytes), RC_OK);
        before = arena_used(ctx);
        assert_int_equal(rc_sensor_create_preset(ctx, preset, &s), RC_OK);
        assert_int_equal(arena_used(ctx) - before, bytes);
        assert_int_equal(rc_sensor_destroy(s), RC_OK);
    }
    /* the ray tables dominate: VLP-16 is 14,400 x 12 bytes plus a small struct */
    {
        size_t bytes = 0;
        assert_int_equal(rc_sensor_memory_requirements_preset(RC_PRESET_VELODYNE_VLP16, &bytes), RC_OK);
        assert_true(bytes >= 14400u * 12u && bytes < 14400u * 12u + 1024u);
    }
    assert_int_equal(arena_used(ctx), used0);
}

/* A block of exactly context + sensor bytes works; one byte less fails with
 * RC_ERR_OUT_OF_MEMORY and leaves everything as it was. */
static void exact_fit(int kind, uint32_t preset)
{
    rc_context_desc cd = context_desc();
    size_t cbytes = 0, sbytes = 0;
    descs d;
    int less;
    make_descs(&d);
    if (kind == K_ONDN) d.rays.origins = d.orgs;
    assert_int_equal(rc_context_memory_requirements(&cd, &cbytes), RC_OK);
    if (preset)
        assert_int_equal(rc_sensor_memory_requirements_preset(preset, &sbytes), RC_OK);
    else
        assert_int_equal(requirements_kind(kind, &d, &sbytes), RC_OK);
    for (less = 0; less <= 1; ++less) {
        block b = block_alloc(cbytes + sbytes);
        rc_context *ctx = NULL;
        rc_sensor *const sentinel = (rc_sensor *)(uintptr_t)0x1234;
        rc_sensor *s = sentinel;
        rc_status st;
        uint64_t used;
        cd.memory = b.aligned;
        cd.memory_size = cbytes + sbytes - (size_t)less;
        assert_int_equal(rc_context_create(&cd, &ctx), RC_OK);
        used = arena_used(ctx);
        st = preset ? rc_sensor_create_preset(ctx, preset, &s) : create_kind(ctx, kind, &d, &s);
        if (!less) {
            assert_int_equal(st, RC_OK);
            assert_ptr_not_equal(s, sentinel);
            assert_int_equal(arena_used(ctx), used + sbytes);
            assert_int_equal(rc_sensor_destroy(s), RC_OK);
            assert_int_equal(arena_used(ctx), used);
        } else {
            assert_int_equal(st, RC_ERR_OUT_OF_MEMORY);
            assert_ptr_equal(s, sentinel);
            assert_int_equal(arena_used(ctx), used);
            assert_non_null(strstr(rc_context_last_error(ctx), "arena"));
            assert_null(ctx->sensors);
        }
        rc_context_destroy(ctx);
        free(b.raw);
    }
}

static void test_exact_arena(void **state)
{
    int kind;
    uint32_t preset;
    (void)state;
    for (kind = K_SPH; kind <= K_ONDN; ++kind) exact_fit(kind, 0);
    for (preset = 1; preset <= 5; ++preset) exact_fit(K_SPH, preset);
}

/* ------------------------------------------------------------------------ */
/* Lifetime and mounting                                                     */
/* ------------------------------------------------------------------------ */

static void test_list_and_destroy(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_sensor *a = NULL, *b = NULL, *c = NULL;
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &a), RC_OK);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_REALSENSE_D435, &b), RC_OK);
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_LIVOX_MID40, &c), RC_OK);
    assert_ptr_equal(ctx->sensors, c);
    assert_ptr_equal(c->next, b);
    assert_ptr_equal(b->next, a);
    assert_null(a->next);
    assert_ptr_equal(a->ctx, ctx);
    assert_true(rc__sensor_valid(b));
    assert_int_equal(rc_sensor_destroy(b), RC_OK);
    assert_ptr_equal(ctx->sensors, c);
    assert_ptr_equal(c->next, a);
    assert_int_equal(rc_sensor_destroy(c), RC_OK);
    assert_ptr_equal(ctx->sensors, a);
    assert_int_equal(rc_sensor_destroy(a), RC_OK);
    assert_null(ctx->sensors);
    /* a sensor left alive is freed with its context (teardown) */
    assert_int_equal(rc_sensor_create_preset(ctx, RC_PRESET_OUSTER_OS1_64, &a), RC_OK);
}

static void test_set_mounting(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    rc_spherical_desc d = good_spherical();
    rc_sensor *s = NULL;
    rc_pose p = rc_pose_identity(), bad;
    const double h = sqrt(0.5) * 1.0005; /* 90 deg yaw, norm 1.0005: normalised */
    /* mounting given at create */
    d.common.sensor_to_base.position[2] = 1.5f;
    assert_int_equal(rc_sensor_create_spherical(ctx, &d, &s), RC_OK);
    assert_near(s->mount_xform.t[2], 1.5, 0.0);
    assert_near(s->mount_xform.r[0], 1.0, 1e-12);

    p.position[0] = 0.2f;
    p.orientation[2] = (float)h;
    p.orientation[3] = (float)h;
    assert_int_equal(rc_sensor_set_mounting(s, &p), RC_OK);
    assert_near(s->mount.orientation[2], sqrt(0.5), 1e-7);
    assert_near(s->mount.orientation[3], sqrt(0.5), 1e-7);
    assert_near(s->mount.position[0], 0.2, 1e-7);
    assert_near(s->spherical.common.sensor_to_base.orientation[3], sqrt(0.5), 1e-7);
    /* R maps x to y */
    assert_near(s->mount_xform.r[0], 0.0, 1e-7);
    assert_near(s->mount_xform.r[3], 1.0, 1e-7);
    assert_near(s->mount_xform.t[0], 0.2, 1e-7);

    bad = p;
    bad.orientation[3] = 0.0f;
    bad.orientation[2] = 0.5f;
    assert_int_equal(rc_sensor_set_mounting(s, &bad), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "sensor_to_base"));
    bad = p;
    bad.position[1] = (float)NAN;
    assert_int_equal(rc_sensor_set_mounting(s, &bad), RC_ERR_NON_FINITE);
    /* unchanged by the failures */
    assert_near(s->mount.orientation[3], sqrt(0.5), 1e-7);
    assert_near(s->mount_xform.t[0], 0.2, 1e-7);
    assert_int_equal(rc_sensor_set_mounting(s, &p), RC_OK);
    assert_string_equal(rc_context_last_error(ctx), ""); /* cleared by a good call */
    assert_int_equal(rc_sensor_destroy(s), RC_OK);
}

static void test_error_messages(void **state)
{
    rc_context *ctx = (rc_context *)*state;
    descs d;
    rc_sensor *s = NULL;
    make_descs(&d);
    d.pin.fx = (float)NAN;
    assert_int_equal(rc_sensor_create_pinhole(ctx, &d.pin, &s), RC_ERR_NON_FINITE);
    assert_non_null(strstr(rc_context_last_error(ctx), "fx"));
    make_descs(&d);
    d.sph.phi.count = 0;
    assert_int_equal(rc_sensor_create_spherical(ctx, &d.sph, &s), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "phi.count"));
    make_descs(&d);
    d.sph.common.range_min = 60.0f;
    assert_int_equal(rc_sensor_create_spherical(ctx, &d.sph, &s), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "range_max"));
    assert_non_null(strstr(rc_context_last_error(ctx), "60"));
    make_descs(&d);
    d.dirs[9] = d.dirs[10] = d.dirs[11] = 0.0f;
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &d.rays, &s), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "directions[3]"));
    assert_null(ctx->sensors);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_vlp16_preset, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_other_spherical_presets, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_laser_scanner_presets, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_spherical_formula, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_single_row_axis, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_pinhole_frames, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_d435_preset, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_cylindrical_formula, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_rosette, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_o1dn_normalised, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_ondn_origins, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_bad_inputs, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_null_arguments, setup_ctx, teardown_ctx),
        cmocka_unit_test(test_presets_api),
        cmocka_unit_test_setup_teardown(test_requirements_match_arena, setup_ctx, teardown_ctx),
        cmocka_unit_test(test_exact_arena),
        cmocka_unit_test_setup_teardown(test_list_and_destroy, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_set_mounting, setup_ctx, teardown_ctx),
        cmocka_unit_test_setup_teardown(test_error_messages, setup_ctx, teardown_ctx),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
