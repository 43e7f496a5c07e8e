/* NEON operations that the SIMD paths (wide_box.h, packet.c, leaf4.h)
 * share, where NEON has no single instruction with SSE2's meaning. */
#ifndef RC_BVH_NEON_OPS_H
#define RC_BVH_NEON_OPS_H

#include "bvh/intersect.h"

#if defined(__ARM_NEON)
#include <arm_neon.h>

#include <stdint.h>

/* "a > b ? a : b" per lane, as SSE2's max: b where a is NaN (0 * inf, an
 * origin on the plane of a parallel ray: such a plane imposes nothing).
 * NEON's own max would propagate the NaN. */
static RC__FORCE_INLINE float32x4_t rc__neon_max_sse(float32x4_t a, float32x4_t b)
{
    return vbslq_f32(vcgtq_f32(a, b), a, b);
}

/* "a < b ? a : b" per lane, as SSE2's min */
static RC__FORCE_INLINE float32x4_t rc__neon_min_sse(float32x4_t a, float32x4_t b)
{
    return vbslq_f32(vcltq_f32(a, b), a, b);
}

/* Lane i's mask (all ones or zero) as bit i, as SSE2's movemask: five
 * instructions, so callers combine masks before reading them out. */
static RC__FORCE_INLINE uint32_t rc__neon_bits(uint32x4_t m)
{
    static const uint32_t bits[4] = {1u, 2u, 4u, 8u};
    const uint32x4_t b = vandq_u32(m, vld1q_u32(bits));
    const uint32x2_t s2 = vorr_u32(vget_low_u32(b), vget_high_u32(b));
    return vget_lane_u32(s2, 0) | vget_lane_u32(s2, 1);
}
#endif

#endif
