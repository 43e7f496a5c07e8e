/* A leaf's (up to) four triangles against one ray at once: the first half of
 * the watertight test (shear, edge functions, sign test) in SSE2 or NEON
 * lanes, as a filter. A lane whose three edge functions have mixed non-zero
 * signs is rejected here exactly as rc__tri_intersect would reject it: every
 * lane repeats the scalar test's operations in the same order (IEEE single
 * precision, no contraction), so its edge functions are the scalar ones bit
 * for bit. Every other lane (a possible hit, a zero edge function for the
 * double fallback, a NaN from overflow) goes to rc__tri_intersect, which
 * decides. Most triangles of a leaf are rejected here, four per few SIMD
 * instructions; the answer is the scalar test's by construction. */
#ifndef RC_BVH_LEAF4_H
#define RC_BVH_LEAF4_H

#include "bvh/intersect.h"

#if defined(__SSE2__) && !defined(RC__WIDE_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__LEAF4_SSE2 1
#elif defined(__ARM_NEON) && !defined(RC__WIDE_FORCE_SCALAR)
#include <arm_neon.h>
#define RC__LEAF4_NEON 1
#endif

/* The vertices of leaf slots first .. first + count (count <= 4; more is
 * clamped: the builder never makes more) from a mesh's leaf-ordered index
 * triples (the caller's hoisted copies of its fields). Returns the count used. */
static RC__FORCE_INLINE uint32_t rc__leaf4_vertices(const uint32_t *leaf_tris, const float *vertices, size_t stride,
                                                   uint32_t first, uint32_t count, const float *v[4][3])
{
    uint32_t i;
    if (count > 4u) count = 4u;
    for (i = 0; i < count; ++i) {
        const uint32_t *tri = leaf_tris + (size_t)3 * (first + i);
        v[i][0] = vertices + tri[0] * stride;
        v[i][1] = vertices + tri[1] * stride;
        v[i][2] = vertices + tri[2] * stride;
    }
    return count;
}

/* Bit i set for triangle i (< count) that rc__tri_intersect must still test;
 * v[i][0..2] are its vertices (slots >= count are ignored). */
static RC__FORCE_INLINE uint32_t rc__leaf4_candidates(const rc__ray *r, const float *const v[4][3], uint32_t count)
{
    const uint32_t all = (1u << count) - 1u;
#if defined(RC__LEAF4_SSE2) || defined(RC__LEAF4_NEON)
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    uint32_t reject;
    /* lane i: triangle i, or triangle 0 again for the slots past count */
    const float *const *p0 = v[0], *const *p1 = v[count > 1u ? 1 : 0];
    const float *const *p2 = v[count > 2u ? 2 : 0], *const *p3 = v[count > 3u ? 3 : 0];
#define RC__LEAF4_GATHER(vtx, k) p0[vtx][k], p1[vtx][k], p2[vtx][k], p3[vtx][k]
#if defined(RC__LEAF4_SSE2)
    {
        const __m128 ox = _mm_set1_ps(r->org[kx]), oy = _mm_set1_ps(r->org[ky]), oz = _mm_set1_ps(r->org[kz]);
        const __m128 sx = _mm_set1_ps(r->sx), sy = _mm_set1_ps(r->sy), zero = _mm_setzero_ps();
        const __m128 az = _mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(0, kz)), oz);
        const __m128 bz = _mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(1, kz)), oz);
        const __m128 cz = _mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(2, kz)), oz);
        const __m128 Ax = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(0, kx)), ox), _mm_mul_ps(sx, az));
        const __m128 Ay = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(0, ky)), oy), _mm_mul_ps(sy, az));
        const __m128 Bx = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(1, kx)), ox), _mm_mul_ps(sx, bz));
        const __m128 By = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(1, ky)), oy), _mm_mul_ps(sy, bz));
        const __m128 Cx = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(2, kx)), ox), _mm_mul_ps(sx, cz));
        const __m128 Cy = _mm_sub_ps(_mm_sub_ps(_mm_setr_ps(RC__LEAF4_GATHER(2, ky)), oy), _mm_mul_ps(sy, cz));
        const __m128 U = _mm_sub_ps(_mm_mul_ps(Cx, By), _mm_mul_ps(Cy, Bx));
        const __m128 V = _mm_sub_ps(_mm_mul_ps(Ax, Cy), _mm_mul_ps(Ay, Cx));
        const __m128 W = _mm_sub_ps(_mm_mul_ps(Bx, Ay), _mm_mul_ps(By, Ax));
        const __m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero));
        const __m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero));
        /* a lane with a NaN (overflow) goes to the scalar test, which orders
         * its comparisons its own way */
        const __m128 ordered = _mm_and_ps(_mm_cmpord_ps(U, V), _mm_cmpord_ps(W, W));
        reject = (uint32_t)_mm_movemask_ps(_mm_and_ps(_mm_and_ps(neg, pos), ordered));
    }
#else
    {
        static const uint32_t bits[4] = {1u, 2u, 4u, 8u};
        const float g[9][4] = {{RC__LEAF4_GATHER(0, kx)}, {RC__LEAF4_GATHER(0, ky)}, {RC__LEAF4_GATHER(0, kz)},
                               {RC__LEAF4_GATHER(1, kx)}, {RC__LEAF4_GATHER(1, ky)}, {RC__LEAF4_GATHER(1, kz)},
                               {RC__LEAF4_GATHER(2, kx)}, {RC__LEAF4_GATHER(2, ky)}, {RC__LEAF4_GATHER(2, kz)}};
        const float32x4_t ox = vdupq_n_f32(r->org[kx]), oy = vdupq_n_f32(r->org[ky]), oz = vdupq_n_f32(r->org[kz]);
        const float32x4_t sx = vdupq_n_f32(r->sx), sy = vdupq_n_f32(r->sy), zero = vdupq_n_f32(0.0f);
        const float32x4_t az = vsubq_f32(vld1q_f32(g[2]), oz), bz = vsubq_f32(vld1q_f32(g[5]), oz);
        const float32x4_t cz = vsubq_f32(vld1q_f32(g[8]), oz);
        /* vmul + vsub, never vmls/vfms: the products must round as in C */
        const float32x4_t Ax = vsubq_f32(vsubq_f32(vld1q_f32(g[0]), ox), vmulq_f32(sx, az));
        const float32x4_t Ay = vsubq_f32(vsubq_f32(vld1q_f32(g[1]), oy), vmulq_f32(sy, az));
        const float32x4_t Bx = vsubq_f32(vsubq_f32(vld1q_f32(g[3]), ox), vmulq_f32(sx, bz));
        const float32x4_t By = vsubq_f32(vsubq_f32(vld1q_f32(g[4]), oy), vmulq_f32(sy, bz));
        const float32x4_t Cx = vsubq_f32(vsubq_f32(vld1q_f32(g[6]), ox), vmulq_f32(sx, cz));
        const float32x4_t Cy = vsubq_f32(vsubq_f32(vld1q_f32(g[7]), oy), vmulq_f32(sy, cz));
        const float32x4_t U = vsubq_f32(vmulq_f32(Cx, By), vmulq_f32(Cy, Bx));
        const float32x4_t V = vsubq_f32(vmulq_f32(Ax, Cy), vmulq_f32(Ay, Cx));
        const float32x4_t W = vsubq_f32(vmulq_f32(Bx, Ay), vmulq_f32(By, Ax));
        const uint32x4_t neg = vorrq_u32(vorrq_u32(vcltq_f32(U, zero), vcltq_f32(V, zero)), vcltq_f32(W, zero));
        const uint32x4_t pos = vorrq_u32(vorrq_u32(vcgtq_f32(U, zero), vcgtq_f32(V, zero)), vcgtq_f32(W, zero));
        /* a lane with a NaN (overflow) goes to the scalar test */
        const uint32x4_t ordered = vandq_u32(vandq_u32(vceqq_f32(U, U), vceqq_f32(V, V)), vceqq_f32(W, W));
        const uint32x4_t m = vandq_u32(vandq_u32(vandq_u32(neg, pos), ordered), vld1q_u32(bits));
        const uint32x2_t s2 = vorr_u32(vget_low_u32(m), vget_high_u32(m));
        reject = vget_lane_u32(s2, 0) | vget_lane_u32(s2, 1);
    }
#endif
#undef RC__LEAF4_GATHER
    return all & ~reject;
#else
    (void)r;
    (void)v;
    return all;
#endif
}

#endif
