/* The four-triangle leaf test (src/bvh/leaf4.h) against the scalar watertight
 * test it stands for: for every ray and triangle, rc__leaf4_test /
 * rc__leaf4_take give rc__tri_intersect's answer bit for bit (hit or miss,
 * t, u, v), from the gathered and the transposed leaf alike, and the AVX2
 * pair test (two rays in one pass, where the CPU has it) gives each ray what
 * the 4-wide test gives it. The cases aim at the test's rare paths: rays
 * through shared edges and vertices (zero edge functions), zero-area and
 * needle triangles, origins in or near a triangle's plane, huge coordinates
 * (overflow to inf and NaN), and leaves of one to four triangles. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "bvh/leaf4.h"
#include "bvh/leaf4_pair.h"
#include "poses.h"
#include "rc_test.h"

static rcu_rng rng;
static double uniform(void) { return rcu_rng_uniform(&rng); }

/* a float on a coarse grid now and then, so vertices and origins coincide
 * and rays run exactly through edges and vertices */
static float coord(float scale)
{
    const double u = uniform();
    if (u < 0.3) return (float)floor(uniform() * 5.0 - 2.0) * scale * 0.5f;
    if (u < 0.32) return (uniform() < 0.5 ? 1.0f : -1.0f) * 3.0e38f;
    return (float)(uniform() * 4.0 - 2.0) * scale;
}

static void make_ray(rc__ray *r, float tri[3][3])
{
    float org[3], dir[3];
    int k;
    const double pick = uniform();
    for (k = 0; k < 3; ++k) org[k] = coord(1.0f);
    if (pick < 0.5) {
        /* at a point of the triangle: a vertex, an edge's midpoint, or inside */
        const double a = uniform() < 0.3 ? 1.0 : uniform(), b = uniform() < 0.3 ? 0.0 : (1.0 - a) * uniform();
        for (k = 0; k < 3; ++k)
            dir[k] = (float)(a * tri[0][k] + b * tri[1][k] + (1.0 - a - b) * tri[2][k]) - org[k];
    } else if (pick < 0.6) {
        /* origin in the plane of the triangle, along an edge */
        for (k = 0; k < 3; ++k) {
            org[k] = tri[0][k];
            dir[k] = tri[1][k] - tri[0][k];
        }
    } else {
        for (k = 0; k < 3; ++k) dir[k] = coord(1.0f);
    }
    if (dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f) dir[2] = 1.0f;
    rc__ray_prepare(r, org, dir);
}

static void make_triangle(float tri[3][3])
{
    int v, k;
    const double kind = uniform();
    for (v = 0; v < 3; ++v)
        for (k = 0; k < 3; ++k) tri[v][k] = coord(1.0f);
    if (kind < 0.1) {
        /* zero area: the third vertex on the line of the first two */
        for (k = 0; k < 3; ++k) tri[2][k] = tri[0][k] + 2.0f * (tri[1][k] - tri[0][k]);
    } else if (kind < 0.15) {
        for (k = 0; k < 3; ++k) tri[2][k] = tri[1][k]; /* two vertices equal */
    } else if (kind < 0.25) {
        /* a needle: the third vertex a hair off the first edge */
        for (k = 0; k < 3; ++k) tri[2][k] = tri[0][k] + 0.5f * (tri[1][k] - tri[0][k]);
        tri[2][0] = nextafterf(tri[2][0], FLT_MAX);
    }
}

typedef struct answer {
    int hit;
    float t;
} answer;

static answer scalar_answer(const rc__ray *r, float tri[3][3])
{
    answer a;
    float u, v;
    memset(&a, 0, sizeof a);
    a.hit = rc__tri_intersect(r, tri[0], tri[1], tri[2], &a.t, &u, &v);
    if (!a.hit) a.t = 0.0f;
    return a;
}

static answer leaf_answer(const rc__leaf4_out *o, uint32_t c, const rc__ray *r, float tri[3][3])
{
    const float *tv[3];
    uint32_t known = 0, flat = 0;
    answer a;
    memset(&a, 0, sizeof a);
    tv[0] = tri[0];
    tv[1] = tri[1];
    tv[2] = tri[2];
    if ((o->hit | o->redo) >> c & 1u) a.hit = rc__leaf4_take(o, c, r, tv, &known, &flat, &a.t);
    if (!a.hit) a.t = 0.0f;
    return a;
}

static void assert_same(const answer *want, const answer *got, const char *what, uint32_t i)
{
    if (want->hit != got->hit || memcmp(&want->t, &got->t, sizeof(float)) != 0)
        fail_msg("%s, case %u: scalar hit %d t %.9g, leaf test hit %d t %.9g", what, i, want->hit, (double)want->t,
                 got->hit, (double)got->t);
}

/* count triangles (1..4) and two rays aimed at them */
static void make_case(float tris[4][3][3], uint32_t *count, rc__ray *ra, rc__ray *rb)
{
    uint32_t i;
    *count = 1u + (uint32_t)(uniform() * 4.0);
    if (*count > 4u) *count = 4u;
    for (i = 0; i < *count; ++i) make_triangle(tris[i]);
    make_ray(ra, tris[(uint32_t)(uniform() * *count) % *count]);
    make_ray(rb, tris[(uint32_t)(uniform() * *count) % *count]);
    /* a packet's rays share their origin */
    if (uniform() < 0.5) rc__ray_prepare(rb, ra->org, rb->dir);
}

static void leaf_of(float tris[4][3][3], uint32_t count, const float *vt[4][3])
{
    uint32_t i, v;
    for (i = 0; i < 4; ++i)
        for (v = 0; v < 3; ++v) vt[i][v] = tris[i < count ? i : 0][v];
}

static void test_leaf_equals_scalar(void **state)
{
    uint32_t i, c, hits = 0, redos = 0;
    (void)state;
    for (i = 0; i < 200000u; ++i) {
        float tris[4][3][3];
        const float *vt[4][3];
        rc__leaf4_soa soa;
        rc__leaf4_out og, os;
        rc__ray r, unused;
        uint32_t count;
        make_case(tris, &count, &r, &unused);
        leaf_of(tris, count, vt);
        rc__leaf4_test(&r, (const float *const(*)[3])vt, count, &og);
        rc__leaf4_transpose((const float *const(*)[3])vt, count, &soa);
        rc__leaf4_test_soa(&r, &soa, count, &os);
        assert_int_equal(og.hit, os.hit);
        assert_int_equal(og.redo, os.redo);
        assert_int_equal((og.hit | og.redo) >> count, 0);
        for (c = 0; c < count; ++c) {
            const answer want = scalar_answer(&r, tris[c]);
            const answer got = leaf_answer(&og, c, &r, tris[c]);
            assert_same(&want, &got, "gathered leaf", i);
            got.hit ? ++hits : 0;
            redos += (og.redo >> c) & 1u;
        }
    }
    /* the cases reach hits and the scalar test's own paths */
    print_message("leaf test: %u hits, %u triangles left to the scalar test\n", hits, redos);
    assert_true(hits > 10000u);
    assert_true(redos > 1000u);
}

#if defined(RC__LEAF4_PAIR_AVX2)
/* the pair is inlined where it is used; this test's copy is a function of
 * its own, compiled for AVX2 */
static __attribute__((target("avx2"), noinline)) void pair_test(const rc__ray *ra, const rc__ray *rb,
                                                                const rc__leaf4_soa *s, uint32_t count,
                                                                rc__leaf4_out *oa, rc__leaf4_out *ob)
{
    rc__leaf4_test_soa_pair(ra, rb, s, count, oa, ob);
}
#endif

static void test_avx2_pair(void **state)
{
#if defined(RC__LEAF4_PAIR_AVX2)
    uint32_t i;
    (void)state;
    if (!rc__leaf4_have_avx2()) {
        print_message("no AVX2 on this CPU: the pair test is not used here\n");
        skip();
    }
    for (i = 0; i < 200000u; ++i) {
        float tris[4][3][3];
        const float *vt[4][3];
        rc__leaf4_soa soa;
        rc__leaf4_out pa, pb, sa, sb;
        rc__ray ra, rb;
        uint32_t count, c;
        make_case(tris, &count, &ra, &rb);
        leaf_of(tris, count, vt);
        rc__leaf4_transpose((const float *const(*)[3])vt, count, &soa);
        pair_test(&ra, &rb, &soa, count, &pa, &pb);
        rc__leaf4_test_soa(&ra, &soa, count, &sa);
        rc__leaf4_test_soa(&rb, &soa, count, &sb);
        assert_int_equal(pa.hit, sa.hit);
        assert_int_equal(pa.redo, sa.redo);
        assert_int_equal(pb.hit, sb.hit);
        assert_int_equal(pb.redo, sb.redo);
        for (c = 0; c < count; ++c) {
            answer want = leaf_answer(&sa, c, &ra, tris[c]);
            answer got = leaf_answer(&pa, c, &ra, tris[c]);
            assert_same(&want, &got, "AVX2 pair, first ray", i);
            want = leaf_answer(&sb, c, &rb, tris[c]);
            got = leaf_answer(&pb, c, &rb, tris[c]);
            assert_same(&want, &got, "AVX2 pair, second ray", i);
        }
    }
#else
    (void)state;
    print_message("the AVX2 pair test is not built for this target\n");
    skip();
#endif
}

int main(void)
{
    rcu_rng_seed(&rng, 0x2545F4914F6CDD1Dull);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_leaf_equals_scalar),
        cmocka_unit_test(test_avx2_pair),
    };
    return cmocka_run_group_tests_name("leaf test", tests, NULL, NULL);
}
