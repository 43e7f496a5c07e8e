/* The stability suite: the cases where ray casters fail (grazing rays,
 * degenerate triangles, sensors on surfaces, axis-parallel rays, very long and
 * short ranges, scaled instances, far-from-origin maps, coplanar duplicates),
 * every backend against the float64 reference tracer. The cases themselves are
 * tools/common/stability_cases.c, shared with `rangecast stability`, which
 * writes docs/stability.md. Absent backends are skipped with a message.
 *
 * Never allowed on any backend: NaN outputs on a return, hits on zero-area
 * triangles. Everything else must be exactly right (0 wrong rays) unless the
 * (backend, case) pair is in known_issues below: limitations of a backend
 * library we do not control (Embree), printed loudly instead of failing, so a
 * fix shows up as "now clean: remove it from known_issues". Every case is
 * enforced on the built-in backend. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>

#include "poses.h"
#include "rc_test.h"
#include "reftrace.h"
#include "stability_cases.h"
#if defined(RANGECAST_WITH_EMBREE)
#include "backend/embree_internal.h"
#endif

typedef struct known_issue {
    uint32_t backend; /* RC_BACKEND_*; 0 = every backend */
    int kase;
    const char *what;
} known_issue;

static const known_issue known_issues[] = {
    /* Embree's own traversal: documented limitations of that backend (the
     * built-in and reference agree); the counts are in docs/stability.md. */
    {RC_BACKEND_EMBREE, RCU_STAB_AXIS_PARALLEL,
     "rays through a box's silhouette vertex or edge exactly miss it (the built-in backend counts them)"},
    {RC_BACKEND_EMBREE, RCU_STAB_COPLANAR,
     "exact duplicates across geometries: not the smallest (geometry, triangle); twin instances are matched"},
};


#define NEED_BACKEND(b)                     \
    do {                                    \
        if (!rct_backend_usable(b)) skip(); \
    } while (0)

static const known_issue *known(uint32_t backend, int kase)
{
    size_t i;
    for (i = 0; i < sizeof known_issues / sizeof known_issues[0]; i++)
        if ((known_issues[i].backend == 0 || known_issues[i].backend == backend) && known_issues[i].kase == kase)
            return &known_issues[i];
    return NULL;
}

static void check_case(uint32_t backend, int kase, uint32_t threads, rcu_stab_configure_fn configure,
                       void *user, const char *label)
{
    rcu_stab_options opt;
    rcu_stab_result r;
    const known_issue *k = configure ? NULL : known(backend, kase);
    memset(&opt, 0, sizeof opt);
    opt.backend = backend;
    opt.threads = threads;
    opt.quick = rct_quick();
    opt.configure = configure;
    opt.configure_user = user;
    if (rcu_stab_run(kase, &opt, &r) != 0) fail_msg("%s on %s: %s", rcu_stab_case_name(kase), rc_backend_name(backend), r.note);
    print_message("%s %s%s threads %u: %llu / %llu rays wrong, max range error %.3g m%s%s\n",
                  rc_backend_name(backend), label, rcu_stab_case_name(kase), threads, (unsigned long long)r.wrong,
                  (unsigned long long)r.rays, r.max_err, r.wrong ? "; first: " : "", r.wrong ? r.note : "");
    assert_true(r.rays > 0);
    if (r.nan_outputs) fail_msg("%s: %llu NaN outputs: %s", rcu_stab_case_name(kase), (unsigned long long)r.nan_outputs, r.note);
    if (r.degenerate_hits)
        fail_msg("%s: %llu hits on zero-area triangles: %s", rcu_stab_case_name(kase),
                 (unsigned long long)r.degenerate_hits, r.note);
    if (configure) return; /* a non-default configuration: counted, not judged */
    if (k) {
        if (r.wrong == 0)
            print_message("NOTE: known issue now clean on %s/%s: remove it from known_issues\n",
                          rc_backend_name(backend), rcu_stab_case_name(kase));
        else
            print_message("KNOWN LIBRARY ISSUE (reported) %s/%s: %s\n", rc_backend_name(backend),
                          rcu_stab_case_name(kase), k->what);
        if (kase == RCU_STAB_DEGENERATE) {
            /* the slivers' range error is all that is known there */
            assert_int_equal(r.class_mismatch, 0);
            assert_int_equal(r.bad_normals, 0);
            assert_true(r.max_err < 5e-3);
        }
        return;
    }
    if (r.wrong) fail_msg("%s on %s: %llu of %llu rays wrong; first: %s", rcu_stab_case_name(kase), rc_backend_name(backend),
                          (unsigned long long)r.wrong, (unsigned long long)r.rays, r.note);
    if (kase == RCU_STAB_FAR_ORIGIN) assert_true(r.max_err < 1e-3);
}

#define CASE_TEST(fn, kase)                                   \
    static void fn(void **state)                              \
    {                                                         \
        uint32_t b = rct_backend_of(state);                       \
        NEED_BACKEND(b);                                      \
        check_case(b, kase, 2, NULL, NULL, "");               \
    }

CASE_TEST(test_grazing, RCU_STAB_GRAZING)
CASE_TEST(test_degenerate, RCU_STAB_DEGENERATE)
CASE_TEST(test_on_surface, RCU_STAB_ON_SURFACE)
CASE_TEST(test_axis_parallel, RCU_STAB_AXIS_PARALLEL)
CASE_TEST(test_long_short, RCU_STAB_LONG_SHORT)
CASE_TEST(test_instance_scale, RCU_STAB_INSTANCE_SCALE)
CASE_TEST(test_far_origin, RCU_STAB_FAR_ORIGIN)

/* Coplanar duplicates: the smallest key on every thread count. */
static void test_coplanar(void **state)
{
    uint32_t b = rct_backend_of(state), threads;
    NEED_BACKEND(b);
    for (threads = 1; threads <= 3; threads++) check_case(b, RCU_STAB_COPLANAR, threads, NULL, NULL, "");
}

#if defined(RANGECAST_WITH_EMBREE)
static void embree_not_robust(rc_context *ctx, void *user)
{
    rc__embree_options *o = rc__embree_options_of(ctx);
    (void)user;
    if (o) o->robust = 0;
}
#endif

/* Embree without RTC_SCENE_FLAG_ROBUST: every case is run and counted (no
 * judgement beyond NaN and zero-area hits): the numbers show what the robust
 * default buys. */
static void test_embree_not_robust(void **state)
{
    (void)state;
#if defined(RANGECAST_WITH_EMBREE)
    {
        int c;
        NEED_BACKEND(RC_BACKEND_EMBREE);
        for (c = 0; c < RCU_STAB_CASE_COUNT; c++) check_case(RC_BACKEND_EMBREE, c, 2, embree_not_robust, NULL, "(not robust) ");
    }
#else
    print_message("SKIP: backend embree is not built in\n");
    skip();
#endif
}

/* The reference itself: against the brute-force double test of the support
 * library on a closed sphere (every ray from inside must hit, same triangle
 * distance), and exactly on a box's analytic exits (axis-parallel rays too). */
static void test_reference_self_check(void **state)
{
    rcu_mesh sphere, box;
    rcu_reftrace *rt = NULL, *rb = NULL;
    rcu_rng rng;
    const float lo[3] = {-2, -1, -0.5f}, hi[3] = {3, 1.5f, 2};
    uint32_t i, n = rct_quick() ? 500 : 5000;
    (void)state;
    memset(&sphere, 0, sizeof sphere);
    memset(&box, 0, sizeof box);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(5.0f, 2000, &sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    assert_int_equal(rcu_reftrace_build(&sphere, &rt), 0);
    assert_int_equal(rcu_reftrace_build(&box, &rb), 0);
    rcu_rng_seed(&rng, 5);
    for (i = 0; i < n; i++) {
        double o[3], d[3], t = 0.0, tb = 0.0, z, a, r;
        uint32_t prim = 0, bp;
        int k;
        for (k = 0; k < 3; k++) o[k] = 0.9 * rcu_rng_uniform(&rng) - 0.45; /* inside both */
        z = 2.0 * rcu_rng_uniform(&rng) - 1.0;
        a = 6.283185307179586 * rcu_rng_uniform(&rng);
        r = sqrt(1.0 - z * z);
        d[0] = r * cos(a);
        d[1] = r * sin(a);
        d[2] = z;
        if (i % 7 == 0) { /* axis-parallel */
            d[0] = d[1] = d[2] = 0.0;
            d[i % 3] = (i & 8) ? 1.0 : -1.0;
        }
        assert_int_equal(rcu_reftrace_nearest(rt, o, d, 100.0, &t, &prim), 1);
        bp = rct_brute_nearest(&sphere, o, d, &tb);
        assert_true(bp != UINT32_MAX);
        if (fabs(t - tb) > 1e-9 * tb) fail_msg("ray %u: reference %.17g, brute force %.17g", i, t, tb);
        assert_int_equal(rcu_reftrace_nearest(rb, o, d, 100.0, &t, &prim), 1);
        {
            double best = INFINITY;
            for (k = 0; k < 3; k++) {
                double tk = d[k] > 0 ? (hi[k] - o[k]) / d[k] : d[k] < 0 ? (lo[k] - o[k]) / d[k] : INFINITY;
                if (tk < best) best = tk;
            }
            if (fabs(t - best) > 1e-12 * best) fail_msg("box ray %u: reference %.17g, analytic %.17g", i, t, best);
        }
        /* the normal is unit */
        {
            double nn[3];
            rcu_reftrace_normal(rb, prim, nn);
            assert_true(fabs(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] - 1.0) < 1e-12);
        }
    }
    rcu_reftrace_free(rt);
    rcu_reftrace_free(rb);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_self_check),
        RCT_FOR_BACKENDS(test_grazing),        RCT_FOR_BACKENDS(test_degenerate),     RCT_FOR_BACKENDS(test_on_surface),
        RCT_FOR_BACKENDS(test_axis_parallel),  RCT_FOR_BACKENDS(test_long_short),     RCT_FOR_BACKENDS(test_instance_scale),
        RCT_FOR_BACKENDS(test_far_origin),     RCT_FOR_BACKENDS(test_coplanar),       cmocka_unit_test(test_embree_not_robust),
    };
    return cmocka_run_group_tests_name("stability (every backend against the float64 reference)", tests, NULL, NULL);
}
