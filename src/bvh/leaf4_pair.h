/* Two rays of a packet against a leaf's four triangles in one pass of 8-wide
 * AVX2 lanes (lanes 0-3: the first ray, 4-7: the second), for the AVX2
 * build of the packet traversal (packet_avx2.c), which inlines it. Both
 * halves run the lane body the 4-wide test runs (leaf4_lanes.h), in IEEE
 * single precision with no fused multiply-add (the function's target does
 * not enable FMA), so each ray gets the rc__leaf4_out that SSE2 gives it,
 * bit for bit. Call it only where rc__leaf4_have_avx2() is 1. A packet's
 * leaf is met by eleven lanes on average on a 1k map, where these tests are
 * the bulk of the work. */
#ifndef RC_BVH_LEAF4_PAIR_H
#define RC_BVH_LEAF4_PAIR_H

#include "bvh/leaf4.h"

#if defined(RC__LEAF4_PAIR_AVX2)
#include <immintrin.h>

/* The lane body (leaf4_lanes.h) for eight lanes */
#define RC__VL_NAME leaf8_lanes
#define RC__VL_ATTR __attribute__((target("avx2")))
#define RC__VL_T __m256
#define RC__VL_M __m256
#define RC__VL_SET1(x) _mm256_set1_ps(x)
#define RC__VL_SUB(a, b) _mm256_sub_ps(a, b)
#define RC__VL_ADD(a, b) _mm256_add_ps(a, b)
#define RC__VL_MUL(a, b) _mm256_mul_ps(a, b)
#define RC__VL_DIV(a, b) _mm256_div_ps(a, b)
#define RC__VL_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OS)
#define RC__VL_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OS)
#define RC__VL_EQ(a, b) _mm256_cmp_ps(a, b, _CMP_EQ_OQ)
#define RC__VL_ORDERED(a, b) _mm256_cmp_ps(a, b, _CMP_ORD_Q)
#define RC__VL_UNORDERED(a, b) _mm256_cmp_ps(a, b, _CMP_UNORD_Q)
#define RC__VL_OR(a, b) _mm256_or_ps(a, b)
#define RC__VL_AND(a, b) _mm256_and_ps(a, b)
#define RC__VL_ANDNOT(a, b) _mm256_andnot_ps(a, b)
#define RC__VL_ABS(a) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a)
#define RC__VL_BITS(m) ((uint32_t)_mm256_movemask_ps(m))
#include "bvh/leaf4_lanes.h"

/* the rows (a 4-float row of the transposed leaf) of the two rays */
#define PAIR_ROW(lo, hi) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1)
#define PAIR_SET(a, b) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(a)), _mm_set1_ps(b), 1)

/* rc__leaf4_test_soa for ra into *oa and rb into *ob */
static RC__FORCE_INLINE __attribute__((target("avx2"))) void rc__leaf4_test_soa_pair(
    const rc__ray *ra, const rc__ray *rb, const rc__leaf4_soa *s, uint32_t count, rc__leaf4_out *oa,
    rc__leaf4_out *ob)
{
    const uint32_t all4 = (1u << count) - 1u;
    __m256 t;
    uint32_t hit, redo;
    leaf8_lanes(PAIR_ROW(s->c[0][ra->kx], s->c[0][rb->kx]), PAIR_ROW(s->c[0][ra->ky], s->c[0][rb->ky]),
                PAIR_ROW(s->c[0][ra->kz], s->c[0][rb->kz]), PAIR_ROW(s->c[1][ra->kx], s->c[1][rb->kx]),
                PAIR_ROW(s->c[1][ra->ky], s->c[1][rb->ky]), PAIR_ROW(s->c[1][ra->kz], s->c[1][rb->kz]),
                PAIR_ROW(s->c[2][ra->kx], s->c[2][rb->kx]), PAIR_ROW(s->c[2][ra->ky], s->c[2][rb->ky]),
                PAIR_ROW(s->c[2][ra->kz], s->c[2][rb->kz]), PAIR_SET(ra->org[ra->kx], rb->org[rb->kx]),
                PAIR_SET(ra->org[ra->ky], rb->org[rb->ky]), PAIR_SET(ra->org[ra->kz], rb->org[rb->kz]),
                PAIR_SET(ra->sx, rb->sx), PAIR_SET(ra->sy, rb->sy), PAIR_SET(ra->sz, rb->sz), all4 | all4 << 4, &hit,
                &redo, &t);
    oa->hit = hit & 15u;
    ob->hit = hit >> 4;
    oa->redo = redo & 15u;
    ob->redo = redo >> 4;
    _mm_storeu_ps(oa->t, _mm256_castps256_ps128(t));
    _mm_storeu_ps(ob->t, _mm256_extractf128_ps(t, 1));
}
#undef PAIR_ROW
#undef PAIR_SET
#endif

#endif
