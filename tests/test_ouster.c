/* rc_ouster_rays: known rays of a made-up four-beam Ouster (the lidar-to-
 * sensor turn, beam origins, the clockwise encoder), every bad desc refused
 * with nothing written, and on every backend a scan of a closed box whose
 * ranges match the walls computed in float64 from the same rays, with points
 * at origin + range * direction. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#define BEAMS 4u
#define PI 3.14159265358979323846

static const double k_alt[BEAMS] = {15.0, 5.0, -5.0, -15.0};
static const double k_azi[BEAMS] = {3.0, -1.0, 1.0, -3.0};

static rc_ouster_desc four_beams(uint32_t columns)
{
    rc_ouster_desc d = rc_ouster_desc_default();
    d.beams = BEAMS;
    d.columns = columns;
    d.altitudes_deg = k_alt;
    d.azimuths_deg = k_azi;
    d.beam_to_lidar[3] = 15.806; /* an OS1's beam origin, mm */
    return d;
}

static void test_known_rays(void **state)
{
    rc_ouster_desc d = four_beams(8);
    float o[3 * BEAMS * 8], dir[3 * BEAMS * 8];
    rc_rays_desc rays;
    double offset = 0.0, a = 1.0 * PI / 180.0, p = 5.0 * PI / 180.0, te = 2.0 * PI * 0.75;
    (void)state;
    assert_int_equal(rc_ouster_rays(&d, &rays, o, dir, &offset), RC_OK);
    assert_int_equal(rays.ray_count, BEAMS * 8u);
    assert_int_equal(rays.width, 8);
    assert_int_equal(rays.height, BEAMS);
    assert_ptr_equal(rays.origins, o);
    assert_true(fabs(offset - 0.015806) < 1e-12);
    /* beam 1 (altitude 5, azimuth -1), column 0: encoder 2 pi, so the ray
     * turns +1 degree from lidar +x; the default lidar-to-sensor turns that
     * 180 degrees about z and lifts the origin 36.18 mm */
    assert_true(fabs(dir[24] - (float)(-cos(a) * cos(p))) < 1e-7f);
    assert_true(fabs(dir[25] - (float)(-sin(a) * cos(p))) < 1e-7f);
    assert_true(fabs(dir[26] - (float)sin(p)) < 1e-7f);
    assert_true(fabsf(o[24] + 0.015806f) < 1e-8f && fabsf(o[25]) < 1e-8f && fabsf(o[26] - 0.03618f) < 1e-8f);
    /* column 2 of 8: encoder 270 degrees, clockwise seen from above */
    assert_true(fabs(o[6] - (float)(-0.015806 * cos(te))) < 1e-8);
    assert_true(fabs(o[7] - (float)(-0.015806 * sin(te))) < 1e-8);
}

static void test_bad_descs(void **state)
{
    float o[3 * BEAMS * 8], dir[3 * BEAMS * 8];
    const double nan_alt[BEAMS] = {15.0, NAN, 0.0, 0.0};
    rc_ouster_desc d;
    size_t i;
    struct {
        int edit;
        rc_status want;
    } cases[] = {{0, RC_ERR_STRUCT_SIZE},       {1, RC_ERR_INVALID_ARGUMENT}, {2, RC_ERR_INVALID_ARGUMENT},
                 {3, RC_ERR_INVALID_ARGUMENT},  {4, RC_ERR_NON_FINITE},       {5, RC_ERR_INVALID_ARGUMENT},
                 {6, RC_ERR_INVALID_ARGUMENT},  {7, RC_ERR_INVALID_ARGUMENT}, {8, RC_ERR_NON_FINITE},
                 {9, RC_ERR_INVALID_ARGUMENT},  {10, RC_ERR_INVALID_ARGUMENT}};
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        d = four_beams(8);
        switch (cases[i].edit) {
        case 0: d.struct_size = 8; break;
        case 1: d.beams = 0; break;
        case 2: d.columns = 1u << 23; break;              /* 4 x 2^23 rays: past 2^24 */
        case 3: d.azimuths_deg = NULL; break;
        case 4: d.altitudes_deg = nan_alt; break;
        case 5: d.lidar_to_sensor[10] = -1.0; break;       /* a mirror, not a turn */
        case 6: d.beam_to_lidar[0] = 2.0; break;           /* a scale */
        case 7: d.reserved[3] = 1; break;
        case 9: d.beam_to_lidar[3] = 1.6e110; break;       /* finite, but inf as a float origin */
        case 10: d.lidar_to_sensor[11] = -2.0e11; break;   /* 2e8 m: past the 1e8 m a component */
        default: d.lidar_to_sensor[3] = INFINITY; break;
        }
        memset(o, 0xA5, sizeof o);
        if (rc_ouster_rays(&d, NULL, o, dir, NULL) != cases[i].want)
            fail_msg("case %d: got %s", cases[i].edit, rc_status_string(rc_ouster_rays(&d, NULL, o, dir, NULL)));
        assert_int_equal(((unsigned char *)o)[0], 0xA5);
    }
    d = four_beams(8);
    assert_int_equal(rc_ouster_rays(&d, NULL, NULL, dir, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_ouster_rays(NULL, NULL, o, dir, NULL), RC_ERR_INVALID_ARGUMENT);
}

/* Distance from o (inside the box) along d to its walls, in double. */
static double box_distance(const float o[3], const float d[3], const double lo[3], const double hi[3])
{
    double t = INFINITY;
    int k;
    for (k = 0; k < 3; ++k) {
        if (d[k] > 0.0f) t = fmin(t, (hi[k] - o[k]) / d[k]);
        if (d[k] < 0.0f) t = fmin(t, (lo[k] - o[k]) / d[k]);
    }
    return t;
}

static void box_scan(uint32_t backend)
{
    const float lo[3] = {-3.0f, -2.0f, -1.5f}, hi[3] = {4.0f, 5.0f, 2.5f};
    const double lod[3] = {-3.0, -2.0, -1.5}, hid[3] = {4.0, 5.0, 2.5};
    const uint32_t columns = 256, n = BEAMS * 256u;
    rc_ouster_desc d = four_beams(columns);
    float *o = (float *)malloc(sizeof(float) * 3u * n), *dir = (float *)malloc(sizeof(float) * 3u * n);
    rc_rays_desc rays;
    rcu_mesh room;
    rc_context *ctx = rct_context(backend, 2, 16);
    rc_scene *scene;
    rc_sensor *s = NULL;
    rc_pose p = rct_pose(0.0f, 0.0f, 0.0f);
    rct_buffers buf;
    uint32_t k;
    assert_non_null(o);
    assert_non_null(dir);
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    scene = rct_scene_mesh(ctx, &room, RC_MESH_REFERENCE);
    assert_int_equal(rc_ouster_rays(&d, &rays, o, dir, NULL), RC_OK);
    rays.common.range_min = 0.05f;
    rays.common.range_max = 50.0f;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &rays, &s));
    rct_buffers_alloc(&buf, n, RC_ATTR_RANGES | RC_ATTR_POINTS);
    RCT_OK(ctx, rc_simulate(ctx, scene, s, &p, 1, &buf.res));
    for (k = 0; k < n; ++k) {
        const double want = box_distance(o + 3u * k, dir + 3u * k, lod, hid), got = buf.res.ranges[k];
        int c;
        if (!(fabs(got - want) <= 2e-5 * want))
            fail_msg("%s, ray %u: range %.9g, the wall is at %.9g", rc_backend_name(backend), (unsigned)k, got, want);
        for (c = 0; c < 3; ++c)
            assert_true(fabs(buf.res.points[3u * k + c] - (o[3u * k + c] + want * dir[3u * k + c])) < 1e-4);
    }
    rct_buffers_free(&buf);
    rc_context_destroy(ctx);
    rcu_mesh_free(&room);
    free(o);
    free(dir);
}

static void test_box_scan_every_backend(void **state)
{
    size_t b;
    (void)state;
    for (b = 0; b < 3; ++b)
        if (rct_backend_usable(rct_backends[b])) box_scan(rct_backends[b]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_rays),
        cmocka_unit_test(test_bad_descs),
        cmocka_unit_test(test_box_scan_every_backend),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
