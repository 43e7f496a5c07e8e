/* rc__rays_prepare_turned: rc__ray_prepare for many rays from one origin,
 * four at a time in SSE2 or AArch64 NEON (32-bit ARM has no vector division:
 * it takes the per-ray path). Every value is the one the per-ray path computes:
 * the same IEEE operations in the same order (the turn as rc__rot_apply_f,
 * reciprocals and shear constants as divisions), with selects where the
 * per-ray path branches; 1 / +-0 is +-inf in SIMD division as copysignf
 * gives it there. What it saves is the per-ray divisions and the
 * unpredictable branches on the dominant axis. */
#include "bvh/mesh.h"

#include "bvh/leaf4.h" /* rc__leaf4_have_avx2 */
#include "core/rmath.h"

#if defined(__SSE2__) && !defined(RC__PACKET_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__RAY_BATCH_SSE2 1
#elif defined(__ARM_NEON) && defined(__aarch64__) && !defined(RC__PACKET_FORCE_SCALAR)
#include <arm_neon.h>
#define RC__RAY_BATCH_NEON 1
#endif

static void prepare_one(const float r[9], const float org[3], const float *d_sensor, rc__ray *ray)
{
    float dir[3];
    rc__rot_apply_f(r, d_sensor, dir);
    rc__ray_prepare(ray, org, dir);
}

#if defined(RC__RAY_BATCH_NEON)
/* Four prepared rays in lanes: v[0..2] direction, v[3..5] reciprocal,
 * v[6..7] shear sx, sy, v[8] sz; bit i of y_bits / z_bits: ray i's kz is
 * 1 / 2 (else 0); of neg_bits: its component along kz is negative. */
typedef struct four_rays {
    float v[9][4];
    int y_bits, z_bits, neg_bits;
} four_rays;

static void scatter_four(const four_rays *f, const float org[3], rc__ray *rays)
{
    int i;
    for (i = 0; i < 4; ++i) {
        rc__ray *ray = &rays[i];
        const int kz = ((f->y_bits >> i) & 1) ? 1 : ((f->z_bits >> i) & 1) ? 2 : 0;
        const int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
        const int swap = (f->neg_bits >> i) & 1;
        ray->org[0] = org[0];
        ray->org[1] = org[1];
        ray->org[2] = org[2];
        ray->dir[0] = f->v[0][i];
        ray->dir[1] = f->v[1][i];
        ray->dir[2] = f->v[2][i];
        ray->inv_dir[0] = f->v[3][i];
        ray->inv_dir[1] = f->v[4][i];
        ray->inv_dir[2] = f->v[5][i];
        ray->kz = kz;
        ray->kx = swap ? ky : kx;
        ray->ky = swap ? kx : ky;
        ray->sx = f->v[6][i];
        ray->sy = f->v[7][i];
        ray->sz = f->v[8][i];
    }
}
#endif

#if defined(RC__RAY_BATCH_SSE2)
#include <stddef.h>

/* scatter_four's stores as four transposes: a ray's 15 fields are four rows
 * of four (the last row starts at kz, which it writes again), so each ray
 * takes four 16-byte stores in place of fifteen scalar ones and the lane
 * reads that fed them (the scatter was most of this file's instructions). */
typedef char rc__ray_rows_check[(offsetof(rc__ray, dir) == 12 && offsetof(rc__ray, inv_dir) == 24 &&
                                 offsetof(rc__ray, kx) == 36 && offsetof(rc__ray, kz) == 44 &&
                                 offsetof(rc__ray, sx) == 48 && sizeof(rc__ray) == 60)
                                    ? 1
                                    : -1];

static RC__FORCE_INLINE void store_four(__m128 a, __m128 b, __m128 c, __m128 d, rc__ray *rays, size_t offset)
{
    _MM_TRANSPOSE4_PS(a, b, c, d);
    _mm_storeu_ps((float *)(void *)((char *)&rays[0] + offset), a);
    _mm_storeu_ps((float *)(void *)((char *)&rays[1] + offset), b);
    _mm_storeu_ps((float *)(void *)((char *)&rays[2] + offset), c);
    _mm_storeu_ps((float *)(void *)((char *)&rays[3] + offset), d);
}

/* A ray's rows from lane values: origin, then the four rows store_four
 * writes (half h of the AVX build's vectors) */
static RC__FORCE_INLINE void store_rays(rc__ray *rays, const float org[3], __m128 wx, __m128 wy, __m128 wz, __m128 ix,
                                        __m128 iy, __m128 iz, __m128 kx, __m128 ky, __m128 kz, __m128 sx, __m128 sy,
                                        __m128 rz)
{
    store_four(_mm_set1_ps(org[0]), _mm_set1_ps(org[1]), _mm_set1_ps(org[2]), wx, rays, offsetof(rc__ray, org));
    store_four(wy, wz, ix, iy, rays, offsetof(rc__ray, dir[1]));
    store_four(iz, kx, ky, kz, rays, offsetof(rc__ray, inv_dir[2]));
    store_four(kz, sx, sy, rz, rays, offsetof(rc__ray, kz));
}

/* prepare_four: four rays, sensor-frame directions d[0..3], into
 * rays[0..3], in SSE2 (ray_prepare_lanes.h) */
#define RC__RP_NAME prepare_four
#define RC__RP_ATTR
#define RC__RP_W 4
#define RC__RP_T __m128
#define RC__RP_SET1(x) _mm_set1_ps(x)
#define RC__RP_ADD(a, b) _mm_add_ps(a, b)
#define RC__RP_MUL(a, b) _mm_mul_ps(a, b)
#define RC__RP_DIV(a, b) _mm_div_ps(a, b)
#define RC__RP_AND(a, b) _mm_and_ps(a, b)
#define RC__RP_OR(a, b) _mm_or_ps(a, b)
#define RC__RP_ANDNOT(m, a) _mm_andnot_ps(m, a)
#define RC__RP_GT(a, b) _mm_cmpgt_ps(a, b)
#define RC__RP_LT(a, b) _mm_cmplt_ps(a, b)
#define RC__RP_INT(i) _mm_castsi128_ps(_mm_set1_epi32(i))
#define RC__RP_DIRS(k) _mm_setr_ps(d[0][k], d[1][k], d[2][k], d[3][k])
#define RC__RP_STORE(four, h, org, wx, wy, wz, ix, iy, iz, kx, ky, kz, sx, sy, rz)                                   \
    store_rays(four, org, wx, wy, wz, ix, iy, iz, kx, ky, kz, sx, sy, rz)
#include "bvh/ray_prepare_lanes.h"
#endif

#if defined(RC__RAY_BATCH_NEON)
/* prepare_four in NEON: the same operations (vdivq_f32 is IEEE division) */
static void prepare_four(const float r[9], const float org[3], const float *const d[4], rc__ray *rays)
{
    static const uint32_t bit_of_lane[4] = {1u, 2u, 4u, 8u};
    const uint32x4_t lane_bits = vld1q_u32(bit_of_lane);
    const float32x4_t one = vdupq_n_f32(1.0f);
    const float vx[4] = {d[0][0], d[1][0], d[2][0], d[3][0]};
    const float vy[4] = {d[0][1], d[1][1], d[2][1], d[3][1]};
    const float vz[4] = {d[0][2], d[1][2], d[2][2], d[3][2]};
    const float32x4_t sx_ = vld1q_f32(vx), sy_ = vld1q_f32(vy), sz_ = vld1q_f32(vz);
    const float32x4_t wx = vaddq_f32(vaddq_f32(vmulq_n_f32(sx_, r[0]), vmulq_n_f32(sy_, r[1])), vmulq_n_f32(sz_, r[2]));
    const float32x4_t wy = vaddq_f32(vaddq_f32(vmulq_n_f32(sx_, r[3]), vmulq_n_f32(sy_, r[4])), vmulq_n_f32(sz_, r[5]));
    const float32x4_t wz = vaddq_f32(vaddq_f32(vmulq_n_f32(sx_, r[6]), vmulq_n_f32(sy_, r[7])), vmulq_n_f32(sz_, r[8]));
    const float32x4_t ix = vdivq_f32(one, wx), iy = vdivq_f32(one, wy), iz = vdivq_f32(one, wz);
    const float32x4_t ax = vabsq_f32(wx), ay = vabsq_f32(wy), az = vabsq_f32(wz);
    const uint32x4_t y_wins = vcgtq_f32(ay, ax);
    const uint32x4_t z_wins = vcgtq_f32(az, vbslq_f32(y_wins, ay, ax));
    const uint32x4_t y_only = vbicq_u32(y_wins, z_wins);
    const float32x4_t dz = vbslq_f32(z_wins, wz, vbslq_f32(y_only, wy, wx));
    const float32x4_t rz = vbslq_f32(z_wins, iz, vbslq_f32(y_only, iy, ix));
    const float32x4_t next = vbslq_f32(z_wins, wx, vbslq_f32(y_only, wz, wy));
    const float32x4_t after = vbslq_f32(z_wins, wy, vbslq_f32(y_only, wx, wz));
    const uint32x4_t neg = vcltq_f32(dz, vdupq_n_f32(0.0f));
    four_rays f;
    vst1q_f32(f.v[0], wx);
    vst1q_f32(f.v[1], wy);
    vst1q_f32(f.v[2], wz);
    vst1q_f32(f.v[3], ix);
    vst1q_f32(f.v[4], iy);
    vst1q_f32(f.v[5], iz);
    vst1q_f32(f.v[6], vdivq_f32(vbslq_f32(neg, after, next), dz));
    vst1q_f32(f.v[7], vdivq_f32(vbslq_f32(neg, next, after), dz));
    vst1q_f32(f.v[8], rz);
    f.y_bits = (int)vaddvq_u32(vandq_u32(y_only, lane_bits));
    f.z_bits = (int)vaddvq_u32(vandq_u32(z_wins, lane_bits));
    f.neg_bits = (int)vaddvq_u32(vandq_u32(neg, lane_bits));
    scatter_four(&f, org, rays);
}
#endif

#if defined(RC__RAY_BATCH_SSE2) || defined(RC__RAY_BATCH_NEON)
/* rays[0..n / 4 * 4): four at a time */
static RC__FORCE_INLINE uint32_t prepare_fours(const float r[9], const float org[3], const float *dirs,
                                               const uint32_t *idx, uint32_t n, rc__ray *rays)
{
    uint32_t i;
    for (i = 0; i + 4u <= n; i += 4u) {
        const float *d[4];
        d[0] = dirs + (size_t)idx[i] * 3u;
        d[1] = dirs + (size_t)idx[i + 1u] * 3u;
        d[2] = dirs + (size_t)idx[i + 2u] * 3u;
        d[3] = dirs + (size_t)idx[i + 3u] * 3u;
        prepare_four(r, org, d, rays + i);
    }
    return i;
}
#endif

#if defined(RC__RAY_BATCH_SSE2) && defined(RC__LEAF4_PAIR_AVX2)
#include <immintrin.h>

/* prepare_four for eight rays in AVX lanes (ray_prepare_lanes.h), stored
 * four at a time */
#define RC__RP_NAME prepare_eight
#define RC__RP_ATTR __attribute__((target("avx2")))
#define RC__RP_W 8
#define RC__RP_T __m256
#define RC__RP_SET1(x) _mm256_set1_ps(x)
#define RC__RP_ADD(a, b) _mm256_add_ps(a, b)
#define RC__RP_MUL(a, b) _mm256_mul_ps(a, b)
#define RC__RP_DIV(a, b) _mm256_div_ps(a, b)
#define RC__RP_AND(a, b) _mm256_and_ps(a, b)
#define RC__RP_OR(a, b) _mm256_or_ps(a, b)
#define RC__RP_ANDNOT(m, a) _mm256_andnot_ps(m, a)
#define RC__RP_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OS)
#define RC__RP_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OS)
#define RC__RP_INT(i) _mm256_castsi256_ps(_mm256_set1_epi32(i))
#define RC__RP_DIRS(k) _mm256_setr_ps(d[0][k], d[1][k], d[2][k], d[3][k], d[4][k], d[5][k], d[6][k], d[7][k])
#define RC__RP_HALF(v, h) ((h) ? _mm256_extractf128_ps(v, 1) : _mm256_castps256_ps128(v))
#define RC__RP_STORE(four, h, org, wx, wy, wz, ix, iy, iz, kx, ky, kz, sx, sy, rz)                                   \
    store_rays(four, org, RC__RP_HALF(wx, h), RC__RP_HALF(wy, h), RC__RP_HALF(wz, h), RC__RP_HALF(ix, h),          \
               RC__RP_HALF(iy, h), RC__RP_HALF(iz, h), RC__RP_HALF(kx, h), RC__RP_HALF(ky, h), RC__RP_HALF(kz, h),  \
               RC__RP_HALF(sx, h), RC__RP_HALF(sy, h), RC__RP_HALF(rz, h))
#include "bvh/ray_prepare_lanes.h"
#undef RC__RP_HALF

/* prepare_fours where the CPU has AVX2: eight rays a pass in AVX lanes (a
 * 1k map: ray preparation -19% instructions), the rest four at a time in
 * VEX-encoded SSE2, whose three-operand forms drop the two-operand build's
 * register copies (-30% before the eight). */
static __attribute__((target("avx2"))) uint32_t prepare_fours_vex(const float r[9], const float org[3],
                                                                  const float *dirs, const uint32_t *idx, uint32_t n,
                                                                  rc__ray *rays)
{
    uint32_t i, k;
    for (i = 0; i + 8u <= n; i += 8u) {
        const float *d[8];
        for (k = 0; k < 8u; ++k) d[k] = dirs + (size_t)idx[i + k] * 3u;
        prepare_eight(r, org, d, rays + i);
    }
    return i + prepare_fours(r, org, dirs, idx + i, n - i, rays + i);
}
#endif

void rc__rays_prepare_turned(const float r[9], const float org[3], const float *dirs, const uint32_t *idx,
                             uint32_t n, rc__ray *rays)
{
    uint32_t i = 0;
#if defined(RC__RAY_BATCH_SSE2) && defined(RC__LEAF4_PAIR_AVX2)
    if (rc__leaf4_have_avx2())
        i = prepare_fours_vex(r, org, dirs, idx, n, rays);
    else
#endif
#if defined(RC__RAY_BATCH_SSE2) || defined(RC__RAY_BATCH_NEON)
        i = prepare_fours(r, org, dirs, idx, n, rays);
#endif
    for (; i < n; ++i) prepare_one(r, org, dirs + (size_t)idx[i] * 3u, &rays[i]);
}
