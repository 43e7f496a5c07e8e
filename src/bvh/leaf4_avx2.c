/* Two rays of a packet against a leaf's four triangles in one pass of 8-wide
 * AVX2 lanes (lanes 0-3: the first ray, 4-7: the second), on x86-64 CPUs
 * that have AVX2 (checked at run time: the library is built for baseline
 * x86-64). Each half repeats rc__leaf4_run (leaf4.h) operation for operation
 * in IEEE single precision, with no fused multiply-add (the target below
 * does not enable FMA), so each ray gets the rc__leaf4_out that SSE2 gives
 * it, bit for bit. A packet's leaf is met by eleven lanes on average on a 1k
 * map, where these tests are the bulk of the work. */
#include "bvh/leaf4.h"

#if defined(RC__LEAF4_PAIR_AVX2)
#include <immintrin.h>

int rc__leaf4_have_avx2(void)
{
    return __builtin_cpu_supports("avx2") ? 1 : 0;
}

/* the rows (a 4-float row of the transposed leaf) of the two rays */
#define PAIR_ROW(lo, hi) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1)
#define PAIR_SET(a, b) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(a)), _mm_set1_ps(b), 1)

__attribute__((target("avx2"))) void rc__leaf4_test_soa_pair(const rc__ray *ra, const rc__ray *rb,
                                                              const rc__leaf4_soa *s, uint32_t count,
                                                              rc__leaf4_out *oa, rc__leaf4_out *ob)
{
    const uint32_t all4 = (1u << count) - 1u, all = all4 | all4 << 4;
    const __m256 zero = _mm256_setzero_ps();
    const __m256 ox = PAIR_SET(ra->org[ra->kx], rb->org[rb->kx]);
    const __m256 oy = PAIR_SET(ra->org[ra->ky], rb->org[rb->ky]);
    const __m256 oz = PAIR_SET(ra->org[ra->kz], rb->org[rb->kz]);
    const __m256 sx = PAIR_SET(ra->sx, rb->sx), sy = PAIR_SET(ra->sy, rb->sy);
    const __m256 az = _mm256_sub_ps(PAIR_ROW(s->c[0][ra->kz], s->c[0][rb->kz]), oz);
    const __m256 bz = _mm256_sub_ps(PAIR_ROW(s->c[1][ra->kz], s->c[1][rb->kz]), oz);
    const __m256 cz = _mm256_sub_ps(PAIR_ROW(s->c[2][ra->kz], s->c[2][rb->kz]), oz);
    const __m256 Ax = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[0][ra->kx], s->c[0][rb->kx]), ox), _mm256_mul_ps(sx, az));
    const __m256 Ay = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[0][ra->ky], s->c[0][rb->ky]), oy), _mm256_mul_ps(sy, az));
    const __m256 Bx = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[1][ra->kx], s->c[1][rb->kx]), ox), _mm256_mul_ps(sx, bz));
    const __m256 By = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[1][ra->ky], s->c[1][rb->ky]), oy), _mm256_mul_ps(sy, bz));
    const __m256 Cx = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[2][ra->kx], s->c[2][rb->kx]), ox), _mm256_mul_ps(sx, cz));
    const __m256 Cy = _mm256_sub_ps(_mm256_sub_ps(PAIR_ROW(s->c[2][ra->ky], s->c[2][rb->ky]), oy), _mm256_mul_ps(sy, cz));
    const __m256 CxBy = _mm256_mul_ps(Cx, By), CyBx = _mm256_mul_ps(Cy, Bx);
    const __m256 AxCy = _mm256_mul_ps(Ax, Cy), AyCx = _mm256_mul_ps(Ay, Cx);
    const __m256 BxAy = _mm256_mul_ps(Bx, Ay), ByAx = _mm256_mul_ps(By, Ax);
    const __m256 U = _mm256_sub_ps(CxBy, CyBx), V = _mm256_sub_ps(AxCy, AyCx), W = _mm256_sub_ps(BxAy, ByAx);
    const __m256 neg = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_LT_OS), _mm256_cmp_ps(V, zero, _CMP_LT_OS)),
                                    _mm256_cmp_ps(W, zero, _CMP_LT_OS));
    const __m256 pos = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_GT_OS), _mm256_cmp_ps(V, zero, _CMP_GT_OS)),
                                    _mm256_cmp_ps(W, zero, _CMP_GT_OS));
    const __m256 ordered = _mm256_and_ps(_mm256_cmp_ps(U, V, _CMP_ORD_Q), _mm256_cmp_ps(W, W, _CMP_ORD_Q));
    const __m256 rejected = _mm256_and_ps(_mm256_and_ps(neg, pos), ordered);
    const __m256 redo = _mm256_andnot_ps(
        rejected,
        _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, V, _CMP_UNORD_Q), _mm256_cmp_ps(W, W, _CMP_UNORD_Q)),
                     _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(CxBy, CyBx, _CMP_EQ_OQ), _mm256_cmp_ps(AxCy, AyCx, _CMP_EQ_OQ)),
                                  _mm256_cmp_ps(BxAy, ByAx, _CMP_EQ_OQ))));
    const __m256 settled = _mm256_or_ps(rejected, redo);
    __m256 tt = zero, det = zero, Vs = zero, Ws = zero;
    uint32_t hit = 0, redo_bits;
    if (all & ~(uint32_t)_mm256_movemask_ps(settled)) {
        const __m256 sz = PAIR_SET(ra->sz, rb->sz);
        const __m256 T = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(U, _mm256_mul_ps(sz, az)),
                                                     _mm256_mul_ps(V, _mm256_mul_ps(sz, bz))),
                                       _mm256_mul_ps(W, _mm256_mul_ps(sz, cz)));
        const __m256 sign = _mm256_set1_ps(-0.0f);
        __m256 pass, tiny, extent;
        det = _mm256_add_ps(_mm256_add_ps(U, V), W);
        tt = _mm256_div_ps(T, det);
        pass = _mm256_andnot_ps(_mm256_or_ps(settled, _mm256_cmp_ps(det, zero, _CMP_EQ_OQ)),
                                _mm256_cmp_ps(tt, zero, _CMP_GT_OS));
        extent = _mm256_add_ps(_mm256_add_ps(_mm256_andnot_ps(sign, az), _mm256_andnot_ps(sign, bz)),
                               _mm256_andnot_ps(sign, cz));
        tiny = _mm256_and_ps(pass, _mm256_cmp_ps(_mm256_mul_ps(tt, _mm256_set1_ps(1024.0f)),
                                                 _mm256_mul_ps(_mm256_andnot_ps(sign, sz), extent), _CMP_LT_OS));
        redo_bits = all & (uint32_t)_mm256_movemask_ps(_mm256_or_ps(redo, tiny));
        hit = all & (uint32_t)_mm256_movemask_ps(_mm256_andnot_ps(tiny, pass));
        Vs = V;
        Ws = W;
    } else {
        redo_bits = all & (uint32_t)_mm256_movemask_ps(redo);
    }
    oa->hit = hit & 15u;
    ob->hit = hit >> 4;
    oa->redo = redo_bits & 15u;
    ob->redo = redo_bits >> 4;
    _mm_storeu_ps(oa->t, _mm256_castps256_ps128(tt));
    _mm_storeu_ps(ob->t, _mm256_extractf128_ps(tt, 1));
    _mm_storeu_ps(oa->V, _mm256_castps256_ps128(Vs));
    _mm_storeu_ps(ob->V, _mm256_extractf128_ps(Vs, 1));
    _mm_storeu_ps(oa->W, _mm256_castps256_ps128(Ws));
    _mm_storeu_ps(ob->W, _mm256_extractf128_ps(Ws, 1));
    _mm_storeu_ps(oa->det, _mm256_castps256_ps128(det));
    _mm_storeu_ps(ob->det, _mm256_extractf128_ps(det, 1));
}
#else
/* ISO C wants a declaration in every translation unit */
typedef int rc__leaf4_avx2_unused;
#endif
