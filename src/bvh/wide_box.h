/* One ray against the four child boxes of a wide node (wide.h) at once: SSE2
 * on x86-64, NEON on ARM, a plain loop elsewhere (or with
 * RC__WIDE_FORCE_SCALAR, for tests and instruction counts). The single-ray
 * traversal tests every node this way, and a packet does for each of its
 * last few live lanes (packet.c). Each lane repeats the robust slab test of
 * intersect.h, so every path culls exactly as conservatively. */
#ifndef RC_BVH_WIDE_BOX_H
#define RC_BVH_WIDE_BOX_H

#include "bvh/intersect.h"
#include "bvh/wide.h"

#include <stdint.h>

#if defined(__SSE2__) && !defined(RC__WIDE_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__WIDE_BOX_SSE2 1
#elif defined(__ARM_NEON) && !defined(RC__WIDE_FORCE_SCALAR)
#include "bvh/neon_ops.h"
#define RC__WIDE_BOX_NEON 1
#endif

#if defined(RC__WIDE_BOX_SSE2)
/* The slab test of one ray against four children, given each child's
 * entry (pn) and exit (pf) planes less the ray's origin along x, y, z and
 * the ray's reciprocal (broadcast): lane c all ones where it meets child c
 * within [0, tmax], *near its entry distances. max/min return the second
 * operand when the first is NaN (0 * inf: the origin on a plane of a
 * parallel ray): such a plane imposes nothing. A packet's rays that share
 * one origin take the planes once for all of them (packet.c). */
static RC__FORCE_INLINE __m128 rc__wide_box_from_planes(__m128 pnx, __m128 pny, __m128 pnz, __m128 pfx, __m128 pfy,
                                                        __m128 pfz, __m128 ix, __m128 iy, __m128 iz, float tmax,
                                                        __m128 *near)
{
    __m128 t0 = _mm_max_ps(_mm_mul_ps(pnx, ix), _mm_setzero_ps());
    __m128 t1 = _mm_min_ps(_mm_mul_ps(pfx, ix), _mm_set1_ps(tmax));
    t0 = _mm_max_ps(_mm_mul_ps(pny, iy), t0);
    t1 = _mm_min_ps(_mm_mul_ps(pfy, iy), t1);
    t0 = _mm_max_ps(_mm_mul_ps(pnz, iz), t0);
    t1 = _mm_min_ps(_mm_mul_ps(pfz, iz), t1);
    *near = t0;
    return _mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(RC__SLAB_FAR_SCALE)));
}

/* rc__wide_box_test's answer before it is read out as bits: lane c all ones
 * where the ray meets child c (a packet's few lanes gather these: packet.c) */
static RC__FORCE_INLINE __m128 rc__wide_box_lanes(const rc__wnode *n, const uint32_t near_row[3], const float org[3],
                                                  const float inv[3], float tmax, float tn[4])
{
    const __m128 ox = _mm_set1_ps(org[0]), oy = _mm_set1_ps(org[1]), oz = _mm_set1_ps(org[2]);
    __m128 near, in;
    in = rc__wide_box_from_planes(
        _mm_sub_ps(_mm_load_ps(n->box[near_row[0]]), ox), _mm_sub_ps(_mm_load_ps(n->box[near_row[1]]), oy),
        _mm_sub_ps(_mm_load_ps(n->box[near_row[2]]), oz), _mm_sub_ps(_mm_load_ps(n->box[near_row[0] ^ 1u]), ox),
        _mm_sub_ps(_mm_load_ps(n->box[near_row[1] ^ 1u]), oy), _mm_sub_ps(_mm_load_ps(n->box[near_row[2] ^ 1u]), oz),
        _mm_set1_ps(inv[0]), _mm_set1_ps(inv[1]), _mm_set1_ps(inv[2]), tmax, &near);
    _mm_store_ps(tn, near);
    return in;
}
#endif

/* Bit c set when the ray from org with reciprocal direction inv meets child
 * c's box within [0, tmax] (conservatively, Ize's bound); tn[c] gets the
 * entry distance. near_row[k] is the plane row axis k enters by (wide.h). */
static RC__FORCE_INLINE uint32_t rc__wide_box_test(const rc__wnode *n, const uint32_t near_row[3], const float org[3],
                                                   const float inv[3], float tmax, float tn[4])
{
#if defined(RC__WIDE_BOX_SSE2)
    return (uint32_t)_mm_movemask_ps(rc__wide_box_lanes(n, near_row, org, inv, tmax, tn));
#else
    const float *nx = n->box[near_row[0]], *fx = n->box[near_row[0] ^ 1u];
    const float *ny = n->box[near_row[1]], *fy = n->box[near_row[1] ^ 1u];
    const float *nz = n->box[near_row[2]], *fz = n->box[near_row[2] ^ 1u];
#if defined(RC__WIDE_BOX_NEON)
    const float32x4_t ox = vdupq_n_f32(org[0]), oy = vdupq_n_f32(org[1]), oz = vdupq_n_f32(org[2]);
    const float32x4_t ix = vdupq_n_f32(inv[0]), iy = vdupq_n_f32(inv[1]), iz = vdupq_n_f32(inv[2]);
    /* SSE2's max and min, so a NaN plane imposes nothing here either */
    float32x4_t t0 = rc__neon_max_sse(vmulq_f32(vsubq_f32(vld1q_f32(nx), ox), ix), vdupq_n_f32(0.0f));
    float32x4_t t1 = rc__neon_min_sse(vmulq_f32(vsubq_f32(vld1q_f32(fx), ox), ix), vdupq_n_f32(tmax));
    t0 = rc__neon_max_sse(vmulq_f32(vsubq_f32(vld1q_f32(ny), oy), iy), t0);
    t0 = rc__neon_max_sse(vmulq_f32(vsubq_f32(vld1q_f32(nz), oz), iz), t0);
    t1 = rc__neon_min_sse(vmulq_f32(vsubq_f32(vld1q_f32(fy), oy), iy), t1);
    t1 = rc__neon_min_sse(vmulq_f32(vsubq_f32(vld1q_f32(fz), oz), iz), t1);
    vst1q_f32(tn, t0);
    return rc__neon_bits(vcleq_f32(t0, vmulq_f32(t1, vdupq_n_f32(RC__SLAB_FAR_SCALE))));
#else
    uint32_t mask = 0;
    int c;
    for (c = 0; c < 4; ++c) {
        const float ax = (nx[c] - org[0]) * inv[0], ay = (ny[c] - org[1]) * inv[1];
        const float az = (nz[c] - org[2]) * inv[2];
        const float bx = (fx[c] - org[0]) * inv[0], by = (fy[c] - org[1]) * inv[1];
        const float bz = (fz[c] - org[2]) * inv[2];
        float t0 = 0.0f, t1 = tmax;
        t0 = ax > t0 ? ax : t0;
        t0 = ay > t0 ? ay : t0;
        t0 = az > t0 ? az : t0;
        t1 = bx < t1 ? bx : t1;
        t1 = by < t1 ? by : t1;
        t1 = bz < t1 ? bz : t1;
        tn[c] = t0;
        if (t0 <= t1 * RC__SLAB_FAR_SCALE) mask |= 1u << c;
    }
    return mask;
#endif
#endif
}

/* A child waiting on a single ray's traversal stack (wide_trace.c, and a
 * packet's lone lane in packet.c), with its entry distance. */
typedef struct rc__wide_entry {
    uint32_t child;
    uint32_t count;
    float tnear;
} rc__wide_entry;

/* Adds child c of n (entry distance tn[c]) to e[0..m), kept in stack order:
 * farthest first, so the nearest is on top and visited next (of equal ones
 * the earlier); returns m + 1. */
static RC__FORCE_INLINE uint32_t rc__wide_add_sorted(rc__wide_entry *e, uint32_t m, const rc__wnode *n, uint32_t c,
                                                     const float tn[4])
{
    rc__wide_entry x;
    uint32_t i;
    x.child = n->child[c];
    x.count = n->count[c];
    x.tnear = tn[c];
    for (i = m; i > 0 && e[i - 1].tnear <= x.tnear; --i) e[i] = e[i - 1];
    e[i] = x;
    return m + 1;
}

#endif
