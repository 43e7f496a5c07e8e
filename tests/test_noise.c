/* Range noise and dropout (rc_sensor_set_noise): the statistics of what it
 * draws against the clean ranges of a plane, what a lost return looks like,
 * reproducibility over thread counts and backends, fresh noise per call, the
 * clamp to the sensor's range, and bad descs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#define PLANE_Z (-10.0f)

typedef struct fixture {
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh mesh;
    float *dirs;
    uint32_t n;
} fixture;

/* n rays fanning downwards onto a plane 10 m below: ranges 10 .. ~30 m */
static void setup(fixture *f, uint32_t backend, uint32_t threads)
{
    const float center[3] = {0.0f, 0.0f, PLANE_Z};
    uint32_t i;
    memset(f, 0, sizeof *f);
    f->n = rct_quick() ? 4000u : 20000u;
    f->dirs = (float *)malloc(sizeof(float) * 3u * f->n);
    assert_non_null(f->dirs);
    for (i = 0; i < f->n; ++i) {
        const double a = 0.61803398875 * 6.283185307179586 * i, tilt = 1.23 * (double)i / f->n;
        f->dirs[3 * i] = (float)(sin(tilt) * cos(a));
        f->dirs[3 * i + 1] = (float)(sin(tilt) * sin(a));
        f->dirs[3 * i + 2] = (float)-cos(tilt);
    }
    assert_int_equal(rcu_mesh_plane(center, 1000.0f, &f->mesh), 0);
    f->ctx = rct_context(backend, threads, 64);
    f->scene = rct_scene_mesh(f->ctx, &f->mesh, RC_MESH_REFERENCE);
    f->sensor = rct_sensor_dirs(f->ctx, f->dirs, f->n, 0.5f, 100.0f);
}

static void teardown(fixture *f)
{
    rc_context_destroy(f->ctx);
    rcu_mesh_free(&f->mesh);
    free(f->dirs);
}

static void run(fixture *f, uint32_t poses, const rct_buffers *b)
{
    rc_pose p[2];
    p[0] = rct_pose(0.0f, 0.0f, 0.0f);
    p[1] = p[0];
    RCT_OK(f->ctx, rc_simulate(f->ctx, f->scene, f->sensor, p, poses, &b->res));
}

static void set_noise(fixture *f, float mean, float sigma, float exponent, float dropout, uint64_t seed)
{
    rc_noise_desc d = rc_noise_desc_default();
    d.mean = mean;
    d.sigma = sigma;
    d.sigma_exponent = exponent;
    d.dropout = dropout;
    d.seed = seed;
    RCT_OK(f->ctx, rc_sensor_set_noise(f->sensor, &d));
}

/* Residuals (noisy - clean) / clean^exponent: their mean, deviation and the
 * share within one deviation of the mean. */
static void residual_stats(const float *clean, const float *noisy, uint32_t n, double exponent, double *mean,
                           double *sd, double *within)
{
    double s = 0.0, s2 = 0.0;
    uint32_t i, in = 0;
    for (i = 0; i < n; ++i) {
        const double r = (noisy[i] - (double)clean[i]) / pow(clean[i], exponent);
        s += r;
        s2 += r * r;
    }
    *mean = s / n;
    *sd = sqrt(s2 / n - *mean * *mean);
    for (i = 0; i < n; ++i)
        if (fabs((noisy[i] - (double)clean[i]) / pow(clean[i], exponent) - *mean) <= *sd) ++in;
    *within = (double)in / n;
}

static void test_gaussian_range_noise(void **state)
{
    fixture f;
    rct_buffers clean, noisy;
    double mean, sd, within;
    uint32_t i;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 2);
    rct_buffers_alloc(&clean, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&noisy, f.n, RC_ATTR_RANGES | RC_ATTR_POINTS | RC_ATTR_HITS);
    run(&f, 1, &clean);
    for (i = 0; i < f.n; ++i) assert_true(clean.res.ranges[i] >= 10.0f && clean.res.ranges[i] < 40.0f);
    set_noise(&f, 0.02f, 0.05f, 0.0f, 0.0f, 7);
    run(&f, 1, &noisy);
    residual_stats(clean.res.ranges, noisy.res.ranges, f.n, 0.0, &mean, &sd, &within);
    /* mean within 5 standard errors, deviation within 5%, a normal's 68.3% within one */
    assert_true(fabs(mean - 0.02) < 5.0 * 0.05 / sqrt(f.n));
    assert_true(fabs(sd - 0.05) < 0.0025);
    assert_true(fabs(within - 0.6827) < 0.03);
    for (i = 0; i < f.n; ++i) {
        const float *p = noisy.res.points + 3u * i, *d = f.dirs + 3u * i;
        const double len = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
        assert_int_equal(noisy.res.hits[i], 1);
        /* the point moved along its ray to the noisy range */
        assert_true(fabs(len - noisy.res.ranges[i]) < 1e-5 * noisy.res.ranges[i]);
        assert_true(fabs(p[0] / len - d[0]) < 1e-5 && fabs(p[1] / len - d[1]) < 1e-5 &&
                    fabs(p[2] / len - d[2]) < 1e-5);
    }
    rct_buffers_free(&clean);
    rct_buffers_free(&noisy);
    teardown(&f);
}

static void test_noise_grows_with_range(void **state)
{
    fixture f;
    rct_buffers clean, noisy;
    double mean, sd, within;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 1);
    rct_buffers_alloc(&clean, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&noisy, f.n, RC_ATTR_RANGES);
    run(&f, 1, &clean);
    set_noise(&f, 0.0f, 0.001f, 2.0f, 0.0f, 11);
    run(&f, 1, &noisy);
    /* divided by r^2 the residuals are N(0, 0.001) */
    residual_stats(clean.res.ranges, noisy.res.ranges, f.n, 2.0, &mean, &sd, &within);
    assert_true(fabs(mean) < 5.0 * 0.001 / sqrt(f.n));
    assert_true(fabs(sd - 0.001) < 0.00005);
    /* and not with exponent 0: the raw residuals are far wider than 0.001 */
    residual_stats(clean.res.ranges, noisy.res.ranges, f.n, 0.0, &mean, &sd, &within);
    assert_true(sd > 0.1);
    rct_buffers_free(&clean);
    rct_buffers_free(&noisy);
    teardown(&f);
}

static void test_dropout_loses_whole_returns(void **state)
{
    fixture f;
    rct_buffers clean, noisy;
    uint32_t i, lost = 0;
    double share, tol;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 2);
    rct_buffers_alloc(&clean, f.n, RC_ATTR_ALL);
    rct_buffers_alloc(&noisy, f.n, RC_ATTR_ALL);
    run(&f, 1, &clean);
    set_noise(&f, 0.0f, 0.0f, 0.0f, 0.3f, 3);
    run(&f, 1, &noisy);
    for (i = 0; i < f.n; ++i) {
        if (noisy.res.hits[i]) {
            /* a kept return is exactly the clean one (no range noise asked) */
            assert_memory_equal(noisy.res.ranges + i, clean.res.ranges + i, sizeof(float));
            assert_memory_equal(noisy.res.points + 3u * i, clean.res.points + 3u * i, 3 * sizeof(float));
            assert_int_equal(noisy.res.prim_ids[i], clean.res.prim_ids[i]);
            continue;
        }
        ++lost;
        assert_true(isinf(noisy.res.ranges[i]) && noisy.res.ranges[i] > 0.0f);
        assert_true(isnan(noisy.res.points[3u * i]) && isnan(noisy.res.normals[3u * i + 2u]));
        assert_int_equal(noisy.res.prim_ids[i], RC_INVALID_ID);
        assert_int_equal(noisy.res.geom_ids[i], RC_INVALID_ID);
        assert_int_equal(noisy.res.inst_ids[i], RC_INVALID_ID);
    }
    share = (double)lost / f.n;
    tol = 5.0 * sqrt(0.3 * 0.7 / f.n);
    if (fabs(share - 0.3) > tol) fail_msg("dropout 0.3 lost %.4f of the returns", share);
    rct_buffers_free(&clean);
    rct_buffers_free(&noisy);
    teardown(&f);
}

/* Two calls of two poses each with the same noise on one backend and thread
 * count, into a and b. */
static int two_calls(uint32_t backend, uint32_t threads, rct_buffers *a, rct_buffers *b)
{
    fixture f;
    if (!rct_backend_usable(backend)) return 0;
    setup(&f, backend, threads);
    rct_buffers_alloc(a, 2u * f.n, RC_ATTR_RANGES | RC_ATTR_HITS | RC_ATTR_POINTS);
    rct_buffers_alloc(b, 2u * f.n, RC_ATTR_RANGES | RC_ATTR_HITS | RC_ATTR_POINTS);
    set_noise(&f, 0.0f, 0.03f, 0.0f, 0.1f, 42);
    run(&f, 2, a);
    run(&f, 2, b);
    teardown(&f);
    return 1;
}

static void test_same_calls_same_noise_everywhere(void **state)
{
    rct_buffers ref_a, ref_b, a, b;
    uint32_t bi, i, n, same = 0;
    (void)state;
    assert_true(two_calls(RC_BACKEND_BVH, 1, &ref_a, &ref_b));
    n = (uint32_t)(ref_a.n / 2u);
    /* each call, and each pose of a call, draws its own numbers (returns
     * lost in both, +inf twice, do not count) */
    for (i = 0; i < n; ++i) {
        same += isfinite(ref_a.res.ranges[i]) && ref_a.res.ranges[i] == ref_b.res.ranges[i];
        same += isfinite(ref_a.res.ranges[i]) && ref_a.res.ranges[i] == ref_a.res.ranges[n + i];
    }
    if (same > n / 100u) fail_msg("%u of %u noisy ranges repeat across calls or poses", same, 2u * n);
    for (bi = 0; bi < 3; ++bi) {
        const uint32_t threads = bi == 0 ? 3u : 2u;
        if (!two_calls(rct_backends[bi], threads, &a, &b)) continue;
        /* the float64-refined ranges agree across backends to the bit, and so does the noise */
        assert_memory_equal(a.res.hits, ref_a.res.hits, a.n);
        assert_memory_equal(b.res.hits, ref_b.res.hits, b.n);
        for (i = 0; i < a.n; ++i) {
            if (!a.res.hits[i]) continue;
            if (fabsf(a.res.ranges[i] - ref_a.res.ranges[i]) > 1e-5f * ref_a.res.ranges[i] ||
                fabsf(b.res.ranges[i] - ref_b.res.ranges[i]) > 1e-5f * ref_b.res.ranges[i])
                fail_msg("%s, %u threads: element %u differs", rc_backend_name(rct_backends[bi]), threads, i);
        }
        rct_buffers_free(&a);
        rct_buffers_free(&b);
    }
    rct_buffers_free(&ref_a);
    rct_buffers_free(&ref_b);
}

static void test_set_noise_restarts_the_draws(void **state)
{
    fixture f;
    rct_buffers first, again;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 2);
    rct_buffers_alloc(&first, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&again, f.n, RC_ATTR_RANGES);
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.0f, 5);
    run(&f, 1, &first);
    run(&f, 1, &again);
    assert_memory_not_equal(first.res.ranges, again.res.ranges, f.n * sizeof(float));
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.0f, 5);
    run(&f, 1, &again);
    assert_memory_equal(first.res.ranges, again.res.ranges, f.n * sizeof(float));
    /* another seed, other numbers */
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.0f, 6);
    run(&f, 1, &again);
    assert_memory_not_equal(first.res.ranges, again.res.ranges, f.n * sizeof(float));
    rct_buffers_free(&first);
    rct_buffers_free(&again);
    teardown(&f);
}

static void test_noise_stays_in_range_and_off_is_off(void **state)
{
    fixture f;
    rct_buffers clean, out;
    rc_noise_desc zero = rc_noise_desc_default();
    uint32_t i;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 2);
    rct_buffers_alloc(&clean, f.n, RC_ATTR_RANGES | RC_ATTR_HITS);
    rct_buffers_alloc(&out, f.n, RC_ATTR_RANGES | RC_ATTR_HITS);
    run(&f, 1, &clean);
    set_noise(&f, 0.0f, 100.0f, 0.0f, 0.0f, 1);
    run(&f, 1, &out);
    for (i = 0; i < f.n; ++i) {
        assert_int_equal(out.res.hits[i], 1);
        assert_true(out.res.ranges[i] >= 0.5f && out.res.ranges[i] <= 100.0f);
    }
    /* absurd noise: every range clamped, none NaN */
    set_noise(&f, 0.0f, 3.0e38f, 4.0f, 0.0f, 2);
    run(&f, 1, &out);
    for (i = 0; i < f.n; ++i) {
        assert_int_equal(out.res.hits[i], 1);
        assert_true(out.res.ranges[i] == 0.5f || out.res.ranges[i] == 100.0f);
    }
    /* all-zero noise and NULL both switch it off: the clean bits again */
    zero.seed = 99;
    RCT_OK(f.ctx, rc_sensor_set_noise(f.sensor, &zero));
    run(&f, 1, &out);
    assert_memory_equal(out.res.ranges, clean.res.ranges, f.n * sizeof(float));
    set_noise(&f, 0.0f, 1.0f, 0.0f, 0.0f, 1);
    RCT_OK(f.ctx, rc_sensor_set_noise(f.sensor, NULL));
    run(&f, 1, &out);
    assert_memory_equal(out.res.ranges, clean.res.ranges, f.n * sizeof(float));
    rct_buffers_free(&clean);
    rct_buffers_free(&out);
    teardown(&f);
}

/* Returns told apart by whatever was requested: points alone move as far as
 * the ranges do; inst_ids alone stay as traced. */
static void test_attribute_subsets(void **state)
{
    fixture f;
    rct_buffers ranges, points, ids;
    uint32_t i;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 2);
    rct_buffers_alloc(&ranges, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&points, f.n, RC_ATTR_POINTS);
    rct_buffers_alloc(&ids, f.n, RC_ATTR_INST_IDS);
    set_noise(&f, 0.1f, 0.05f, 0.0f, 0.0f, 9);
    run(&f, 1, &ranges);
    set_noise(&f, 0.1f, 0.05f, 0.0f, 0.0f, 9);
    run(&f, 1, &points);
    for (i = 0; i < f.n; ++i) {
        const float *p = points.res.points + 3u * i;
        const double len = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
        if (fabs(len - ranges.res.ranges[i]) > 2e-5 * ranges.res.ranges[i])
            fail_msg("ray %u: point at %.7f m, range %.7f m", i, len, (double)ranges.res.ranges[i]);
    }
    /* an instance of the plane, every return dropped: inst_ids alone cannot
     * tell returns apart and stay as traced (0); with hits they are lost */
    {
        rc_scene_desc wd = rc_scene_desc_default();
        rc_instance_desc id = rc_instance_desc_default();
        rc_scene *world = NULL;
        rc_pose p = rct_pose(0.0f, 0.0f, 0.0f);
        uint32_t inst = 9;
        rct_buffers lost;
        wd.max_geometries = 0;
        wd.max_instances = 1;
        RCT_OK(f.ctx, rc_scene_create(f.ctx, &wd, &world));
        id.source = f.scene;
        RCT_OK(f.ctx, rc_scene_add_instance(world, &id, &inst));
        RCT_OK(f.ctx, rc_scene_commit(world));
        rct_buffers_alloc(&lost, f.n, RC_ATTR_HITS | RC_ATTR_INST_IDS);
        set_noise(&f, 0.0f, 0.05f, 0.0f, 1.0f, 9);
        RCT_OK(f.ctx, rc_simulate(f.ctx, world, f.sensor, &p, 1, &ids.res));
        RCT_OK(f.ctx, rc_simulate(f.ctx, world, f.sensor, &p, 1, &lost.res));
        for (i = 0; i < f.n; ++i) {
            assert_int_equal(ids.res.inst_ids[i], 0);
            assert_int_equal(lost.res.hits[i], 0);
            assert_int_equal(lost.res.inst_ids[i], RC_INVALID_ID);
        }
        rct_buffers_free(&lost);
    }
    rct_buffers_free(&ranges);
    rct_buffers_free(&points);
    rct_buffers_free(&ids);
    teardown(&f);
}

static void expect_bad(fixture *f, rc_noise_desc d, rc_status status, const char *part)
{
    assert_int_equal(rc_sensor_set_noise(f->sensor, &d), status);
    if (!strstr(rc_context_last_error(f->ctx), part))
        fail_msg("message '%s' lacks '%s'", rc_context_last_error(f->ctx), part);
}

static void test_bad_noise(void **state)
{
    fixture f;
    rct_buffers first, after;
    rc_noise_desc d;
    (void)state;
    setup(&f, RC_BACKEND_BVH, 1);
    rct_buffers_alloc(&first, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&after, f.n, RC_ATTR_RANGES);
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.0f, 5);
    run(&f, 1, &first);
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.0f, 5);
    assert_int_equal(rc_sensor_set_noise(NULL, NULL), RC_ERR_INVALID_HANDLE);
    d = rc_noise_desc_default();
    d.struct_size = 12;
    expect_bad(&f, d, RC_ERR_STRUCT_SIZE, "noise->struct_size");
    d = rc_noise_desc_default();
    d.mean = NAN;
    expect_bad(&f, d, RC_ERR_NON_FINITE, "noise->mean");
    d = rc_noise_desc_default();
    d.sigma = INFINITY;
    expect_bad(&f, d, RC_ERR_NON_FINITE, "noise->sigma");
    d = rc_noise_desc_default();
    d.sigma = -0.1f;
    expect_bad(&f, d, RC_ERR_INVALID_ARGUMENT, "noise->sigma is -0.1");
    d = rc_noise_desc_default();
    d.sigma_exponent = -1.0f;
    expect_bad(&f, d, RC_ERR_INVALID_ARGUMENT, "noise->sigma_exponent");
    d = rc_noise_desc_default();
    d.dropout = 1.5f;
    expect_bad(&f, d, RC_ERR_INVALID_ARGUMENT, "noise->dropout is 1.5");
    d = rc_noise_desc_default();
    d.reserved[2] = 1;
    expect_bad(&f, d, RC_ERR_INVALID_ARGUMENT, "reserved[2]");
    /* every failure left the noise as set, draw count included */
    run(&f, 1, &after);
    assert_memory_equal(first.res.ranges, after.res.ranges, f.n * sizeof(float));
    rct_buffers_free(&first);
    rct_buffers_free(&after);
    teardown(&f);
}

/* Results kept on the device get their noise there (test_vulkan_device_results
 * compares it with the host's pass), and such a call uses up a draw as a host
 * call does: the host call after it gets draw 1. */
static void test_noise_on_device_uses_a_draw(void **state)
{
    fixture f;
    rc_results res = rc_results_default();
    rc_pose p = rct_pose(0.0f, 0.0f, 0.0f);
    rct_buffers after_device, second;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip();
    setup(&f, RC_BACKEND_VULKAN, 1);
    rct_buffers_alloc(&after_device, f.n, RC_ATTR_RANGES);
    rct_buffers_alloc(&second, f.n, RC_ATTR_RANGES);
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.1f, 5);
    res.attributes = RC_ATTR_RANGES;
    res.flags = RC_RESULTS_ON_DEVICE;
    RCT_OK(f.ctx, rc_simulate(f.ctx, f.scene, f.sensor, &p, 1, &res));
    run(&f, 1, &after_device);
    set_noise(&f, 0.0f, 0.05f, 0.0f, 0.1f, 5); /* restarts the draws: two host calls */
    run(&f, 1, &second);
    run(&f, 1, &second);
    assert_memory_equal(after_device.res.ranges, second.res.ranges, f.n * sizeof(float));
    rct_buffers_free(&after_device);
    rct_buffers_free(&second);
    teardown(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gaussian_range_noise),
        cmocka_unit_test(test_noise_grows_with_range),
        cmocka_unit_test(test_dropout_loses_whole_returns),
        cmocka_unit_test(test_same_calls_same_noise_everywhere),
        cmocka_unit_test(test_set_noise_restarts_the_draws),
        cmocka_unit_test(test_noise_stays_in_range_and_off_is_off),
        cmocka_unit_test(test_attribute_subsets),
        cmocka_unit_test(test_bad_noise),
        cmocka_unit_test(test_noise_on_device_uses_a_draw),
    };
    return cmocka_run_group_tests_name("noise", tests, NULL, NULL);
}
