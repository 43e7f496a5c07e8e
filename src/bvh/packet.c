/* Packet traversal over the 4-wide BVH (see packet.h and wide.h).
 *
 * A packet runs only when all its rays lie in one octant (the same sign of
 * each direction component), which holds for every tile of a scan but those
 * that straddle an axis plane. Then each slab's near plane is the same for all
 * lanes, so a node test is (plane - origin) broadcast times each lane's
 * reciprocal: 32 lanes cost a few SIMD instructions. Mixed tiles go ray by ray
 * through the single-ray traversal. Either way every ray gets exactly the hit
 * rc__mesh_intersect would give it: box tests only choose which triangles are
 * tested (conservatively), and the triangle test is the same watertight one.
 *
 * Rays with origins of their own (an OnDn sensor whose beams leave from
 * points a few millimetres apart, like an Ouster's) run as packets too: the
 * broadcast test then takes the first ray's origin moved out by the lanes'
 * largest offset along each axis, towards the near plane for entry distances
 * and away from it for exit distances (lanes_origins). That is the test of
 * every box grown by that offset, so it keeps every lane whose own ray meets
 * the box; the tests of a few live lanes (few_lanes_met) and the triangle
 * tests take each ray's own origin. */
#include "bvh/packet.h"

#include "bvh/intersect.h"
#include "bvh/leaf4.h"
#include "bvh/wide_box.h"
#include "core/common.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

/* On x86-64 this file is compiled twice (RC__PACKET_TWO_BUILDS, packet.h):
 * as itself for baseline x86-64 (the entry points named ..._sse2), and as
 * packet_avx2.c with -mavx2 (..._avx2), where the box tests take eight lanes
 * at a time and every leaf tests two lanes at once (leaf4_pair.h). The
 * entry points without a suffix, at the end, choose by the CPU
 * (rc__leaf4_have_avx2: a load and a bit test). Both builds run the same
 * operations lane for lane, without fused multiply-add, so their answers
 * are the same bit for bit. */
#if defined(RC__PACKET_AVX2_VARIANT)
#define RC__PACKET_FN(name) name##_avx2
#elif defined(RC__PACKET_TWO_BUILDS)
#define RC__PACKET_FN(name) name##_sse2
#else
#define RC__PACKET_FN(name) name
#endif

#if defined(__SSE2__) && !defined(RC__PACKET_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__PACKET_SSE2 1
#if defined(RC__PACKET_AVX2_VARIANT)
#if !defined(__AVX2__) || !defined(RC__PACKET_TWO_BUILDS)
#error "packet_avx2.c needs -mavx2 and an x86-64 GNU C compiler"
#endif
#include <immintrin.h>

#include "bvh/leaf4_pair.h"
#define RC__PACKET_AVX2 1
#endif
#elif defined(__ARM_NEON) && !defined(RC__PACKET_FORCE_SCALAR)
#include "bvh/neon_ops.h"
#define RC__PACKET_NEON 1
#endif

#define LANES RC__PACKET_SIZE
/* Three pushes per level at most, over at most RC__BVH_MAX_DEPTH levels. */
#define PACKET_STACK (3u * RC__BVH_MAX_DEPTH + 4u)
#define GROUPS (LANES / 4u)
/* lane masks are uint32_t, and the AVX2 box tests take rows of eight lanes */
typedef char rc__packet_lanes_check[LANES <= 32u && LANES % 8u == 0 ? 1 : -1];

typedef struct packet_entry {
    uint32_t child;
    uint32_t count; /* 0: a node; else a leaf's triangle count */
    uint32_t mask;  /* lanes that met its box when it was pushed */
    float tmin;     /* its lanes' entry distances bound from below: orders children, drops pops */
} packet_entry;

/* Per-lane slab data, 16-byte aligned rows of 4 lanes. */
typedef struct packet_lanes {
    float ix[LANES], iy[LANES], iz[LANES];
    float tmax[LANES];
    uint32_t near_row[3];  /* plane row of a wide node each axis enters by (wide.h) */
    /* the origin the broadcast tests take for near (entry) and far (exit)
     * planes: both the rays' shared origin, or moved apart (lanes_origins) */
    float org_near[3], org_far[3];
} packet_lanes;


/* A node's planes as the packet's box tests take them, once a node: per
 * axis k, p[k][c] = child c's entry plane less the entry origin, p[3 + k][c]
 * its exit plane less the exit origin (the interval test reads them as rows,
 * box_mask child by child; each recomputed them before). */
typedef struct node_planes {
    float p[6][4];
} node_planes;

static inline void planes_fill(const rc__wnode *n, const packet_lanes *L, node_planes *pl)
{
    uint32_t k;
#if defined(RC__PACKET_SSE2)
    for (k = 0; k < 3; ++k) {
        _mm_storeu_ps(pl->p[k], _mm_sub_ps(_mm_loadu_ps(n->box[L->near_row[k]]), _mm_set1_ps(L->org_near[k])));
        _mm_storeu_ps(pl->p[3 + k], _mm_sub_ps(_mm_loadu_ps(n->box[L->near_row[k] ^ 1u]), _mm_set1_ps(L->org_far[k])));
    }
#elif defined(RC__PACKET_NEON)
    for (k = 0; k < 3; ++k) {
        vst1q_f32(pl->p[k], vsubq_f32(vld1q_f32(n->box[L->near_row[k]]), vdupq_n_f32(L->org_near[k])));
        vst1q_f32(pl->p[3 + k], vsubq_f32(vld1q_f32(n->box[L->near_row[k] ^ 1u]), vdupq_n_f32(L->org_far[k])));
    }
#else
    uint32_t c;
    for (k = 0; k < 3; ++k)
        for (c = 0; c < 4; ++c) {
            pl->p[k][c] = n->box[L->near_row[k]][c] - L->org_near[k];
            pl->p[3 + k][c] = n->box[L->near_row[k] ^ 1u][c] - L->org_far[k];
        }
#endif
}

/* Lanes of `mask` whose ray meets child c's box (planes pl) within
 * [0, tmax]. All four groups of lanes are tested, dead ones too: skipping
 * them was a branch per group that mispredicted often enough to cost more
 * than the test. */
static inline uint32_t box_mask(const node_planes *pl, uint32_t c, const packet_lanes *L, uint32_t mask)
{
    const float nx = pl->p[0][c], ny = pl->p[1][c], nz = pl->p[2][c];
    const float fx = pl->p[3][c], fy = pl->p[4][c], fz = pl->p[5][c];
    uint32_t out = 0, g;
#if defined(RC__PACKET_SSE2)
    /* x86: rows of BOX_W lanes (four in SSE2, eight in the AVX2 build), the
     * same operations lane for lane either way */
#if defined(RC__PACKET_AVX2)
#define BOX_W 8u
#define BOX_V __m256
#define BOX_SET1(x) _mm256_set1_ps(x)
#define BOX_LOAD(p) _mm256_loadu_ps(p)
#define BOX_MUL(a, b) _mm256_mul_ps(a, b)
#define BOX_MAX(a, b) _mm256_max_ps(a, b)
#define BOX_MIN(a, b) _mm256_min_ps(a, b)
#define BOX_LE_BITS(a, b) ((uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OS)))
#else
#define BOX_W 4u
#define BOX_V __m128
#define BOX_SET1(x) _mm_set1_ps(x)
#define BOX_LOAD(p) _mm_load_ps(p)
#define BOX_MUL(a, b) _mm_mul_ps(a, b)
#define BOX_MAX(a, b) _mm_max_ps(a, b)
#define BOX_MIN(a, b) _mm_min_ps(a, b)
#define BOX_LE_BITS(a, b) ((uint32_t)_mm_movemask_ps(_mm_cmple_ps(a, b)))
#endif
    const BOX_V vnx = BOX_SET1(nx), vny = BOX_SET1(ny), vnz = BOX_SET1(nz);
    const BOX_V vfx = BOX_SET1(fx), vfy = BOX_SET1(fy), vfz = BOX_SET1(fz);
    const BOX_V scale = BOX_SET1(RC__SLAB_FAR_SCALE);
    /* rows g of lanes from a to b (constants in each loop below, so each
     * unrolls) */
#define BOX_ROWS(a, b)                                                                                             \
    for (g = (a); g < (b); ++g) {                                                                                  \
        const BOX_V ix = BOX_LOAD(L->ix + BOX_W * g), iy = BOX_LOAD(L->iy + BOX_W * g);                            \
        const BOX_V iz = BOX_LOAD(L->iz + BOX_W * g);                                                              \
        /* max/min return their second operand when the first is NaN: a NaN                                       \
         * (0 * inf, origin on a plane of a parallel ray) imposes nothing */                                       \
        BOX_V t0 = BOX_MAX(BOX_MUL(vnx, ix), BOX_SET1(0.0f));                                                      \
        BOX_V t1 = BOX_MIN(BOX_MUL(vfx, ix), BOX_LOAD(L->tmax + BOX_W * g));                                       \
        t0 = BOX_MAX(BOX_MUL(vny, iy), t0);                                                                        \
        t0 = BOX_MAX(BOX_MUL(vnz, iz), t0);                                                                        \
        t1 = BOX_MIN(BOX_MUL(vfy, iy), t1);                                                                        \
        t1 = BOX_MIN(BOX_MUL(vfz, iz), t1);                                                                        \
        out |= BOX_LE_BITS(t0, BOX_MUL(t1, scale)) << (BOX_W * g);                                                 \
    }
    /* a tile's two rows part deep in the tree: lanes of one half only (one
     * row of a 2 x 16 tile) test that half's rows */
    if (!(mask >> (LANES / 2u))) {
        BOX_ROWS(0u, LANES / BOX_W / 2u)
    } else if (!(mask & ((1u << (LANES / 2u)) - 1u))) {
        BOX_ROWS(LANES / BOX_W / 2u, LANES / BOX_W)
    } else {
        BOX_ROWS(0u, LANES / BOX_W)
    }
#undef BOX_ROWS
#undef BOX_W
#undef BOX_V
#undef BOX_SET1
#undef BOX_LOAD
#undef BOX_MUL
#undef BOX_MAX
#undef BOX_MIN
#undef BOX_LE_BITS
#elif defined(RC__PACKET_NEON)
    const float32x4_t vnx = vdupq_n_f32(nx), vny = vdupq_n_f32(ny), vnz = vdupq_n_f32(nz);
    const float32x4_t vfx = vdupq_n_f32(fx), vfy = vdupq_n_f32(fy), vfz = vdupq_n_f32(fz);
    const float32x4_t scale = vdupq_n_f32(RC__SLAB_FAR_SCALE);
    for (g = 0; g < GROUPS; ++g) {
        const float32x4_t ix = vld1q_f32(L->ix + 4 * g), iy = vld1q_f32(L->iy + 4 * g);
        const float32x4_t iz = vld1q_f32(L->iz + 4 * g);
        /* SSE2's max and min: a NaN imposes nothing, as above */
        float32x4_t t0 = rc__neon_max_sse(vmulq_f32(vnx, ix), vdupq_n_f32(0.0f));
        float32x4_t t1 = rc__neon_min_sse(vmulq_f32(vfx, ix), vld1q_f32(L->tmax + 4 * g));
        t0 = rc__neon_max_sse(vmulq_f32(vny, iy), t0);
        t0 = rc__neon_max_sse(vmulq_f32(vnz, iz), t0);
        t1 = rc__neon_min_sse(vmulq_f32(vfy, iy), t1);
        t1 = rc__neon_min_sse(vmulq_f32(vfz, iz), t1);
        out |= rc__neon_bits(vcleq_f32(t0, vmulq_f32(t1, scale))) << (4 * g);
    }
#else
    {
        for (g = 0; g < LANES; ++g) {
            const float ax = nx * L->ix[g], ay = ny * L->iy[g], az = nz * L->iz[g];
            const float bx = fx * L->ix[g], by = fy * L->iy[g], bz = fz * L->iz[g];
            float t0 = 0.0f, t1 = L->tmax[g];
            t0 = ax > t0 ? ax : t0;
            t0 = ay > t0 ? ay : t0;
            t0 = az > t0 ? az : t0;
            t1 = bx < t1 ? bx : t1;
            t1 = by < t1 ? by : t1;
            t1 = bz < t1 ? bz : t1;
            if (t0 <= t1 * RC__SLAB_FAR_SCALE) out |= 1u << g;
        }
    }
#endif
    return out & mask;
}

/* The packet as a whole: per axis the smallest and largest reciprocal
 * direction over its rays (one octant, so one sign per axis). */
typedef struct packet_bounds {
    float ilo[3], ihi[3];
    float tmax;  /* largest tmax over the lanes */
    int usable;  /* 0 when a reciprocal is infinite (a zero direction component) */
} packet_bounds;

/* Children of n that some ray of the packet may meet: an interval version
 * of box_mask over all four children at once. For a fixed plane offset
 * (plane - origin) the product with the reciprocal is monotonic in the
 * reciprocal, rounding included, so the two products with the packet's
 * smallest and largest reciprocals bound every lane's product exactly as
 * box_mask computes it: a child rejected here is rejected by every lane
 * there. Children of no lane are then skipped without their all-lane tests.
 * tn[c] gets child c's entry bound for the whole packet: the order in which
 * met children are visited (it only orders work; it never culls). */
static inline uint32_t children_maybe_hit(const node_planes *pl, const packet_bounds *P, float tn[4])
{
#if defined(RC__PACKET_SSE2)
    __m128 t0 = _mm_setzero_ps(), t1 = _mm_set1_ps(P->tmax);
    uint32_t k;
    for (k = 0; k < 3; ++k) {
        const __m128 lo = _mm_set1_ps(P->ilo[k]), hi = _mm_set1_ps(P->ihi[k]);
        const __m128 pn = _mm_loadu_ps(pl->p[k]), pf = _mm_loadu_ps(pl->p[3 + k]);
        t0 = _mm_max_ps(_mm_min_ps(_mm_mul_ps(pn, lo), _mm_mul_ps(pn, hi)), t0);
        t1 = _mm_min_ps(_mm_max_ps(_mm_mul_ps(pf, lo), _mm_mul_ps(pf, hi)), t1);
    }
    _mm_store_ps(tn, t0);
    return (uint32_t)_mm_movemask_ps(_mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(RC__SLAB_FAR_SCALE))));
#elif defined(RC__PACKET_NEON)
    float32x4_t t0 = vdupq_n_f32(0.0f), t1 = vdupq_n_f32(P->tmax);
    uint32_t k;
    for (k = 0; k < 3; ++k) {
        const float32x4_t lo = vdupq_n_f32(P->ilo[k]), hi = vdupq_n_f32(P->ihi[k]);
        const float32x4_t pn = vld1q_f32(pl->p[k]), pf = vld1q_f32(pl->p[3 + k]);
        const float32x4_t a = vminq_f32(vmulq_f32(pn, lo), vmulq_f32(pn, hi));
        const float32x4_t b = vmaxq_f32(vmulq_f32(pf, lo), vmulq_f32(pf, hi));
        /* selects, as in box_mask: a NaN (0 * inf) imposes nothing, where
         * NEON's max and min would propagate it */
        t0 = rc__neon_max_sse(a, t0);
        t1 = rc__neon_min_sse(b, t1);
    }
    vst1q_f32(tn, t0);
    return rc__neon_bits(vcleq_f32(t0, vmulq_f32(t1, vdupq_n_f32(RC__SLAB_FAR_SCALE))));
#else
    uint32_t c, k, out = 0;
    for (c = 0; c < 4; ++c) {
        float t0 = 0.0f, t1 = P->tmax;
        for (k = 0; k < 3; ++k) {
            const float pn = pl->p[k][c], pf = pl->p[3 + k][c];
            const float a = pn * P->ilo[k], b = pn * P->ihi[k], d = pf * P->ilo[k], e = pf * P->ihi[k];
            const float lo = a < b ? a : b, hi = d > e ? d : e;
            t0 = lo > t0 ? lo : t0;
            t1 = hi < t1 ? hi : t1;
        }
        tn[c] = t0;
        if (t0 <= t1 * RC__SLAB_FAR_SCALE) out |= 1u << c;
    }
    return out;
#endif
}

/* A packet whose live lanes have thinned out (deep in the tree on large maps
 * every ray hits its own triangle) tests them one by one: FEW_LANES single-ray
 * tests of all four boxes cost less than one packet test of each box over
 * every lane (1M-triangle sphere: +3-9% scans/s; 10M: +25%; six or eight
 * lanes measured slower than four). */
#define FEW_LANES 4u

/* 1 when mask has at most FEW_LANES lanes: one instruction where the build
 * has POPCNT (the AVX2 build: every AVX2 CPU has it), else the lowest
 * FEW_LANES bits cleared one by one. */
static RC__FORCE_INLINE int few_lanes(uint32_t mask)
{
#if defined(__POPCNT__)
    return __builtin_popcount(mask) <= (int)FEW_LANES;
#else
    uint32_t j;
    for (j = 0; j < FEW_LANES; ++j) mask &= mask - 1u;
    return mask == 0;
#endif
}

/* The lanes of mask (at most FEW_LANES), each against the four children of
 * n: met[c] gets the lanes that meet child c, the same bits box_mask gives
 * (the same operations in the same order, from each ray's own origin), tn[c]
 * the nearest of their entry
 * distances (a lower bound for every lane, as packet_entry.tmin needs).
 * Returns the children some lane meets. */
static RC__FORCE_INLINE uint32_t few_lanes_met(const rc__wnode *n, const packet_lanes *L, const rc__ray *rays,
                                              uint32_t mask, uint32_t met[4], float tn[4])
{
#if defined(RC__WIDE_BOX_SSE2)
    /* each lane's four answers as lane masks, ANDed with the lane's bit and
     * ORed: met[c] in lane c of one register (bits moved one by one into
     * four words were a quarter of these visits' instructions) */
    __m128i metv = _mm_loadu_si128((const __m128i *)(const void *)met);
    __m128 near = _mm_set1_ps(INFINITY); /* entry distances are never NaN: min(tl, inf) = tl */
    while (mask) {
        const uint32_t lane = rc__lowest_bit(mask);
        float inv[3], tl[4] RC__ALIGN16;
        __m128 in;
        mask &= mask - 1u;
        inv[0] = L->ix[lane];
        inv[1] = L->iy[lane];
        inv[2] = L->iz[lane];
        in = rc__wide_box_lanes(n, L->near_row, rays[lane].org, inv, L->tmax[lane], tl);
        metv = _mm_or_si128(metv, _mm_and_si128(_mm_castps_si128(in), _mm_set1_epi32((int)(1u << lane))));
        near = _mm_min_ps(_mm_load_ps(tl), near);
    }
    _mm_store_ps(tn, near);
    _mm_storeu_si128((__m128i *)(void *)met, metv);
    return (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(metv, _mm_setzero_si128()))) ^ 0xFu;
#else
    uint64_t lo = 0, hi = 0; /* bits 32c + lane (lo: children 0, 1; hi: 2, 3): lane meets child c */
    uint32_t any = 0;
    int first = 1;
    while (mask) {
        const uint32_t lane = rc__lowest_bit(mask);
        float inv[3], tl[4];
        uint32_t h, c;
        mask &= mask - 1u;
        inv[0] = L->ix[lane];
        inv[1] = L->iy[lane];
        inv[2] = L->iz[lane];
        /* the first lane's entry distances go straight to tn (a select
         * there, on a flag, measured as a mispredicted branch per child) */
        h = rc__wide_box_test(n, L->near_row, rays[lane].org, inv, L->tmax[lane], first ? tn : tl);
        any |= h;
        /* bits 0 and 1 of h to bits 0 and 32 of lo, bits 2 and 3 to those of hi */
        lo |= ((uint64_t)(h & 3u) * 0x80000001u & 0x100000001u) << lane;
        hi |= ((uint64_t)(h >> 2) * 0x80000001u & 0x100000001u) << lane;
        if (!first)
            for (c = 0; c < 4; ++c) tn[c] = tl[c] < tn[c] ? tl[c] : tn[c];
        first = 0;
    }
    met[0] |= (uint32_t)lo;
    met[1] |= (uint32_t)(lo >> 32);
    met[2] |= (uint32_t)hi;
    met[3] |= (uint32_t)(hi >> 32);
    return any;
#endif
}

#if defined(RC__WIDE_BOX_SSE2)
/* few_lanes_met for rays that share one origin (no RC__PACKET_OWN_ORIGINS):
 * each plane less the origin is then every lane's own (n - o), so it is
 * computed once for the node and each lane runs only the rest of
 * rc__wide_box_lanes' test (rc__wide_box_from_planes): the same bits and
 * entry distances, without a lane's six loads and subtractions. */
static RC__FORCE_INLINE uint32_t few_lanes_met_shared(const rc__wnode *n, const packet_lanes *L, uint32_t mask,
                                                     uint32_t met[4], float tn[4])
{
    const __m128 pnx = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[0]]), _mm_set1_ps(L->org_near[0]));
    const __m128 pny = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[1]]), _mm_set1_ps(L->org_near[1]));
    const __m128 pnz = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[2]]), _mm_set1_ps(L->org_near[2]));
    const __m128 pfx = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[0] ^ 1u]), _mm_set1_ps(L->org_far[0]));
    const __m128 pfy = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[1] ^ 1u]), _mm_set1_ps(L->org_far[1]));
    const __m128 pfz = _mm_sub_ps(_mm_load_ps(n->box[L->near_row[2] ^ 1u]), _mm_set1_ps(L->org_far[2]));
    __m128i metv = _mm_loadu_si128((const __m128i *)(const void *)met);
    __m128 near = _mm_set1_ps(INFINITY); /* entry distances are never NaN: min(t0, inf) = t0 */
    while (mask) {
        const uint32_t lane = rc__lowest_bit(mask);
        __m128 t0;
        const __m128 in = rc__wide_box_from_planes(pnx, pny, pnz, pfx, pfy, pfz, _mm_set1_ps(L->ix[lane]),
                                                   _mm_set1_ps(L->iy[lane]), _mm_set1_ps(L->iz[lane]),
                                                   L->tmax[lane], &t0);
        mask &= mask - 1u;
        metv = _mm_or_si128(metv, _mm_and_si128(_mm_castps_si128(in), _mm_set1_epi32((int)(1u << lane))));
        near = _mm_min_ps(t0, near);
    }
    _mm_store_ps(tn, near);
    _mm_storeu_si128((__m128i *)(void *)met, metv);
    return (uint32_t)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(metv, _mm_setzero_si128()))) ^ 0xFu;
}
#endif

/* L->tmax[lane] = t, written as the whole row of four lanes: the box tests
 * load rows, and a row load right after a one-lane store cannot be
 * forwarded from it (the load waits for the store to reach the cache). */
static inline void lane_set_tmax(packet_lanes *L, uint32_t lane, float t)
{
#if defined(RC__PACKET_SSE2)
    float *row = L->tmax + (lane & ~3u);
    const __m128 sel = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_set1_epi32((int)(lane & 3u)), _mm_setr_epi32(0, 1, 2, 3)));
    _mm_store_ps(row, _mm_or_ps(_mm_and_ps(sel, _mm_set1_ps(t)), _mm_andnot_ps(sel, _mm_load_ps(row))));
#elif defined(RC__PACKET_NEON)
    static const uint32_t slot[4] = {0u, 1u, 2u, 3u};
    float *row = L->tmax + (lane & ~3u);
    const uint32x4_t sel = vceqq_u32(vdupq_n_u32(lane & 3u), vld1q_u32(slot));
    vst1q_f32(row, vbslq_f32(sel, vdupq_n_f32(t), vld1q_f32(row)));
#else
    L->tmax[lane] = t;
#endif
}

/* Largest tmax over the lanes (unused lanes hold -1). */
static inline float lanes_tmax(const packet_lanes *L)
{
#if defined(RC__PACKET_SSE2)
    __m128 a = _mm_load_ps(L->tmax);
    uint32_t q;
    for (q = 4; q < LANES; q += 4) a = _mm_max_ps(a, _mm_load_ps(L->tmax + q));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(1, 0, 3, 2)));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_cvtss_f32(a);
#elif defined(RC__PACKET_NEON)
    float32x4_t a = vld1q_f32(L->tmax);
    float32x2_t b;
    uint32_t q;
    for (q = 4; q < LANES; q += 4) a = vmaxq_f32(a, vld1q_f32(L->tmax + q));
    b = vpmax_f32(vget_low_f32(a), vget_high_f32(a));
    return vget_lane_f32(vpmax_f32(b, b), 0);
#else
    float m = L->tmax[0];
    uint32_t i;
    for (i = 1; i < LANES; ++i) m = L->tmax[i] > m ? L->tmax[i] : m;
    return m;
#endif
}

#if !defined(RC__PACKET_SSE2)
/* 1 when every ray of the packet has the same direction signs (by the sign of
 * its reciprocal, so -0 counts as negative, as in the single-ray test). */
static int one_octant(const rc__ray *rays, uint32_t n, uint32_t near_row[3])
{
    uint32_t i, k;
    for (k = 0; k < 3; ++k) {
        const int neg = rays[0].inv_dir[k] < 0.0f;
        for (i = 1; i < n; ++i)
            if ((rays[i].inv_dir[k] < 0.0f) != neg) return 0;
        near_row[k] = 2u * k + (neg ? 1u : 0u);
    }
    return 1;
}
#endif

static int octant_of(const rc__ray *r)
{
    return (r->inv_dir[0] < 0.0f) | (r->inv_dir[1] < 0.0f) << 1 | (r->inv_dir[2] < 0.0f) << 2;
}

/* The next part of a tile that straddles an axis plane: its rays not yet in
 * *done that share the first such ray's octant, copied to sub (hits to
 * sub_hits, found cleared, their places in idx) and added to *done.
 * Returns their count. */
static uint32_t octant_part(const rc__ray *rays, const rc__hit *hits, uint32_t n, uint32_t *done, rc__ray *sub,
                            rc__hit *sub_hits, int *sub_found, uint32_t *idx)
{
    uint32_t i, m = 0;
    int oct = -1;
    for (i = 0; i < n; ++i) {
        if ((*done >> i) & 1u) continue;
        if (oct < 0) oct = octant_of(&rays[i]);
        if (octant_of(&rays[i]) != oct) continue;
        idx[m] = i;
        sub[m] = rays[i];
        sub_hits[m] = hits[i];
        sub_found[m] = 0;
        ++m;
        *done |= 1u << i;
    }
    return m;
}

#if defined(RC__PACKET_MESHES)
static void packet_meshes(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count, const rc__ray *rays,
                          uint32_t n, uint32_t inst, rc__hit *hits, int *found, uint32_t flags, int split);
#endif

/* A tile that straddles an axis plane, through meshes[0 .. count): one
 * packet per octant present (a ray alone goes through the single-ray
 * traversal), through all of them (mesh by mesh, each mesh would split the
 * tile again: a sixth of a VLP-16's instructions among 65 meshes went
 * there, session 42). */
static void split_by_octant(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count,
                            const rc__ray *rays, uint32_t n, uint32_t inst, rc__hit *hits, int *found, uint32_t flags)
{
    uint32_t done = 0, i, j;
    while (done != (n >= 32u ? 0xFFFFFFFFu : (1u << n) - 1u)) {
        rc__ray sub[LANES];
        rc__hit sub_hits[LANES];
        int sub_found[LANES];
        uint32_t idx[LANES];
        const uint32_t m = octant_part(rays, hits, n, &done, sub, sub_hits, sub_found, idx);
        if (m == 1) {
            for (j = 0; j < count; ++j)
                sub_found[0] |= rc__mesh_intersect(meshes[j], &sub[0], geoms[j], inst, &sub_hits[0]);
        } else {
#if defined(RC__PACKET_MESHES)
            if (count > 1u)
                packet_meshes(meshes, geoms, count, sub, m, inst, sub_hits, sub_found, flags, 0);
            else
#endif
                for (j = 0; j < count; ++j)
                    RC__PACKET_FN(rc__mesh_intersect_packet)(meshes[j], sub, m, geoms[j], inst, sub_hits, sub_found,
                                                             flags);
        }
        for (i = 0; i < m; ++i) {
            hits[idx[i]] = sub_hits[i];
            found[idx[i]] |= sub_found[i];
        }
    }
}

/* One packet's traversal as a resumable state, so that several packets can
 * take turns (rc__mesh_intersect_packets). Taking turns, a packet prefetches
 * the node it visits next, and a leaf takes two turns: the first reads its
 * vertex indices and prefetches the vertices, the second tests them. */
typedef struct packet_trav {
    packet_lanes L RC__ALIGN16;
    packet_bounds P;
    const rc__ray *rays;
    rc__hit *hits;
    int *found;
    uint32_t n, sp, child, count, mask;
    uint32_t staged; /* 1 once the current leaf's vertices are prefetched */
    uint32_t settling; /* 1 once the traversal is over and the prim ids are on their way */
    uint32_t flags;    /* RC__PACKET_* (packet.h) */
    /* up to three pushes per level, and room for one node's children past the end */
    packet_entry stack[PACKET_STACK + 4u];
} packet_trav;

#if defined(RC__PACKET_SSE2)
/* A ray's reciprocal is read as one 16-byte row (the int after it is the
 * fourth lane, ignored) */
typedef char rc__packet_ray_row_check[offsetof(rc__ray, inv_dir) + 4 * sizeof(float) <= sizeof(rc__ray) ? 1 : -1];
#endif

#if defined(RC__PACKET_SSE2)
/* Rays i .. i + 3 into L (lanes past n repeat ray 0 and never hit), and
 * into lanes_fill's running bounds */
static RC__FORCE_INLINE void lanes_row(packet_lanes *L, const rc__ray *rays, const rc__hit *hits, uint32_t i, uint32_t n,
                                      __m128 *lo, __m128 *hi, __m128 *nan, __m128 *tm)
{
    __m128 r0 = _mm_loadu_ps(rays[i < n ? i : 0].inv_dir);
    __m128 r1 = _mm_loadu_ps(rays[i + 1 < n ? i + 1 : 0].inv_dir);
    __m128 r2 = _mm_loadu_ps(rays[i + 2 < n ? i + 2 : 0].inv_dir);
    __m128 r3 = _mm_loadu_ps(rays[i + 3 < n ? i + 3 : 0].inv_dir);
    const __m128 t = _mm_setr_ps(i < n ? hits[i].t : -1.0f, i + 1 < n ? hits[i + 1].t : -1.0f,
                                 i + 2 < n ? hits[i + 2].t : -1.0f, i + 3 < n ? hits[i + 3].t : -1.0f);
    *lo = _mm_min_ps(*lo, _mm_min_ps(_mm_min_ps(r0, r1), _mm_min_ps(r2, r3)));
    *hi = _mm_max_ps(*hi, _mm_max_ps(_mm_max_ps(r0, r1), _mm_max_ps(r2, r3)));
    *nan = _mm_or_ps(*nan, _mm_or_ps(_mm_cmpunord_ps(r0, r1), _mm_cmpunord_ps(r2, r3)));
    *tm = _mm_max_ps(*tm, t);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    _mm_store_ps(L->ix + i, r0);
    _mm_store_ps(L->iy + i, r1);
    _mm_store_ps(L->iz + i, r2);
    _mm_store_ps(L->tmax + i, t);
}
#endif

/* Fills L from the packet's rays and P with its bounds: per axis the
 * smallest and largest reciprocal, and the largest tmax. 0 when the rays do
 * not share one octant (L and P are then unusable). Lanes past n repeat ray 0
 * and never hit (tmax -1).
 * SSE2 takes four rays a row at a time, transposes them and stores whole
 * rows: the box tests load rows, and a row load right after one-lane stores
 * would wait for them to reach the cache. The bounds come from the same
 * registers (a scalar pass over the lanes was 40 instructions a ray). */
static int lanes_fill(packet_lanes *L, packet_bounds *P, const rc__ray *rays, uint32_t n, const rc__hit *hits)
{
    uint32_t i, k;
    int finite = 1;
#if defined(RC__PACKET_SSE2)
    const __m128 zero = _mm_setzero_ps();
    const __m128 first = _mm_loadu_ps(rays[0].inv_dir);
    const int neg = _mm_movemask_ps(_mm_cmplt_ps(first, zero)) & 7;
    __m128 lo = first, hi = first, nan = _mm_cmpunord_ps(first, first), tm = _mm_set1_ps(hits[0].t);
    float l4[4], h4[4], t4[4];
    int mixed;
    /* a full tile (most) without the tests for lanes past n */
    if (n == LANES)
        for (i = 0; i < LANES; i += 4) lanes_row(L, rays, hits, i, LANES, &lo, &hi, &nan, &tm);
    else
        for (i = 0; i < LANES; i += 4) lanes_row(L, rays, hits, i, n, &lo, &hi, &nan, &tm);
    /* direction signs by "< 0", as in the single-ray test: an axis is
     * mixed when its smallest reciprocal is negative and its largest not
     * (lo <= hi); a NaN (never from a finite direction) could hide from
     * min and max, so then ray by ray */
    mixed = _mm_movemask_ps(_mm_cmplt_ps(lo, zero)) ^ _mm_movemask_ps(_mm_cmplt_ps(hi, zero));
    if (_mm_movemask_ps(nan) & 7)
        for (mixed = 0, i = 0; i < n; ++i) mixed |= octant_of(&rays[i]) ^ neg;
    if (mixed & 7) return 0;
    _mm_storeu_ps(l4, lo);
    _mm_storeu_ps(h4, hi);
    _mm_storeu_ps(t4, tm);
    finite = !(_mm_movemask_ps(nan) & 7);
    P->tmax = t4[0];
    for (k = 1; k < 4; ++k) P->tmax = t4[k] > P->tmax ? t4[k] : P->tmax;
    for (k = 0; k < 3; ++k) {
        L->near_row[k] = 2u * k + (uint32_t)((neg >> k) & 1);
        P->ilo[k] = l4[k];
        P->ihi[k] = h4[k];
    }
#else
    if (!one_octant(rays, n, L->near_row)) return 0;
    for (k = 0; k < 3; ++k) P->ilo[k] = P->ihi[k] = rays[0].inv_dir[k];
    P->tmax = hits[0].t;
    for (i = 0; i < n; ++i) {
        const float *inv = rays[i].inv_dir;
        L->ix[i] = inv[0];
        L->iy[i] = inv[1];
        L->iz[i] = inv[2];
        L->tmax[i] = hits[i].t;
        P->tmax = hits[i].t > P->tmax ? hits[i].t : P->tmax;
        for (k = 0; k < 3; ++k) {
            P->ilo[k] = inv[k] < P->ilo[k] ? inv[k] : P->ilo[k];
            P->ihi[k] = inv[k] > P->ihi[k] ? inv[k] : P->ihi[k];
            finite &= inv[k] == inv[k];
        }
    }
    for (; i < LANES; ++i) {
        L->ix[i] = L->ix[0];
        L->iy[i] = L->iy[0];
        L->iz[i] = L->iz[0];
        L->tmax[i] = -1.0f;
    }
#endif
    /* an infinite reciprocal (a zero direction component) gives box_mask's
     * NaN cases, and a tmax beyond float range inf * 0: the interval test
     * cannot bound those, except on an axis where every lane has the same
     * reciprocal (an upright 2-D scanner's z, all +inf): there its products
     * are each lane's own, NaN included, and NaN imposes nothing in both */
    for (k = 0; k < 3; ++k) finite &= (P->ilo[k] > -FLT_MAX && P->ihi[k] < FLT_MAX) || P->ilo[k] == P->ihi[k];
    P->usable = finite && P->tmax < FLT_MAX;
    return 1;
}

/* L->org_near and org_far (see the top; L->near_row set): rays[0]'s origin,
 * or with own_origins each axis moved by the lanes' largest offset from it,
 * grown by 2^-10 of itself and 2^-20 of the coordinate: more than the
 * roundings of the offset and of the moved coordinate, so the box the test
 * stands for holds every lane's own box. */
static void lanes_origins(packet_lanes *L, const rc__ray *rays, uint32_t n, int own_origins)
{
    uint32_t i, k;
    for (k = 0; k < 3; ++k) {
        const float o = rays[0].org[k];
        float d = 0.0f;
        if (own_origins)
            for (i = 1; i < n; ++i) {
                const float e = fabsf(rays[i].org[k] - o);
                d = e > d ? e : d;
            }
        if (d == 0.0f) {
            L->org_near[k] = L->org_far[k] = o;
            continue;
        }
        d += d * 0x1p-10f + fabsf(o) * 0x1p-20f;
        if (L->near_row[k] & 1u) d = -d; /* towards -k: entering by the max plane */
        L->org_near[k] = o + d;
        L->org_far[k] = o - d;
    }
}

/* Starts T on the root. 0 when the packet cannot run as one (empty, too
 * large, mixed octants, no tree): the caller takes the rays another way. */
static int trav_init(packet_trav *T, const rc__mesh *mesh, const rc__ray *rays, uint32_t n, rc__hit *hits,
                     int *found, uint32_t flags)
{
    if (n == 0 || n > LANES || mesh->wide == NULL || mesh->wide_count == 0) return 0;
    if (!lanes_fill(&T->L, &T->P, rays, n, hits)) return 0;
    lanes_origins(&T->L, rays, n, (flags & RC__PACKET_OWN_ORIGINS) != 0u);
    T->flags = flags;
    T->mask = (n >= 32u ? 0u : (1u << n)) - 1u;
    T->rays = rays;
    T->hits = hits;
    T->found = found;
    T->n = n;
    T->sp = 0;
    T->child = 0;
    T->count = 0;
    T->staged = T->settling = 0;
    return 1;
}

/* Offers lane's hits among a leaf's triangles (first slot child, vertices
 * vt) as rc__leaf4_test found them in *lo; sets *shrunk when the lane's
 * tmax shrank. */
static RC__FORCE_INLINE void leaf_lane_offer(packet_trav *T, const rc__mesh *mesh, const float *vt[4][3],
                                             uint32_t child, uint32_t lane, const rc__leaf4_out *lo, uint32_t *known,
                                             uint32_t *flat, uint32_t geom, uint32_t inst, int *shrunk)
{
    uint32_t cand = lo->hit | lo->redo;
#if defined(RC__LEAF4_FULL) && defined(RC__PACKET_SSE2)
    if (cand && !lo->redo && (*known & cand) == cand && !(*flat & cand)) {
        /* hits the lanes settled, on triangles known not to be flat (most
         * offers): rc__leaf4_take would take each at the lanes' t, so offer
         * them straight and set the lane's tmax once (x86 only: 288 bytes
         * that the aarch64 core's size budget does not have) */
        rc__hit *h = &T->hits[lane];
        int took = 0;
        while (cand) {
            const uint32_t c = rc__lowest_bit(cand);
            cand &= cand - 1u;
            took |= rc__hit_offer_slot(h, lo->t[c], mesh->bvh.refs, child + c, geom, inst);
        }
        if (took) {
            lane_set_tmax(&T->L, lane, h->t);
            T->found[lane] = 1;
            *shrunk = 1;
        }
        return;
    }
#endif
    while (cand) {
        const uint32_t c = rc__lowest_bit(cand); /* a triangle slot here, not a lane */
        float t;
        cand &= cand - 1u;
        if (!rc__leaf4_take(lo, c, &T->rays[lane], vt[c], known, flat, &t)) continue;
        if (!rc__hit_offer_slot(&T->hits[lane], t, mesh->bvh.refs, child + c, geom, inst)) continue;
        lane_set_tmax(&T->L, lane, t);
        T->found[lane] = 1;
        *shrunk = 1;
    }
}

/* A subtree entry (child, count) that only lane still meets, traversed for
 * that lane alone as the single-ray traversal does (wide_trace.c), with the
 * packet's prefetch on push: no lane masks, and the lane's own tmax, not
 * the packet's largest, drops what it pushed. Deep in a large map most
 * entries hold one lane (1M sphere: 0.41 of the 1.73 node visits a ray, and
 * 0.77 of the 1.13 leaf visits). The tests, offers and tie rule are the
 * packet's, so the lane gets the same hit. Sets *shrunk when its tmax
 * shrank. */
#if !defined(__OPTIMIZE_SIZE__)
/* Left out of -Os builds (the static core for small boards: its 1.4 KB on
 * aarch64 would take that core past its 200 KB budget, docs/benchmarks.md);
 * there a lone lane stays in the packet, with the same results. */
#define RC__PACKET_LONE_LANE 1
/* A lone lane's node: the children the lane meets sorted onto e, farthest
 * first (the nearest, on top, is visited next; of equal ones the earlier),
 * each fetched now. Returns their count. */
static RC__FORCE_INLINE uint32_t lone_node(const packet_trav *T, const rc__mesh *mesh, uint32_t lane, uint32_t child,
                                           rc__wide_entry *e)
{
    const rc__wnode *nodes = mesh->wide;
    const rc__wnode *n = &nodes[child];
    const rc__ray *ray = &T->rays[lane];
    float tn[4] RC__ALIGN16;
    uint32_t met = rc__wide_box_test(n, T->L.near_row, ray->org, ray->inv_dir, T->L.tmax[lane], tn), m = 0;
    while (met) {
        const uint32_t c = rc__lowest_bit(met);
        met &= met - 1u;
        if (n->child[c] == RC__WIDE_EMPTY) continue;
        rc__prefetch_next(nodes, mesh->leaf_tris, n->child[c], n->count[c]);
        m = rc__wide_add_sorted(e, m, n, c, tn);
    }
    return m;
}

/* A lone lane's leaf (child, count): its triangles tested and the hits
 * offered. Sets *shrunk when the lane's tmax shrank. */
static RC__FORCE_INLINE void lone_leaf(packet_trav *T, const rc__mesh *mesh, uint32_t lane, uint32_t child,
                                       uint32_t count, uint32_t geom, uint32_t inst, int *shrunk)
{
    const rc__ray *ray = &T->rays[lane];
    const float *vt[4][3];
    const uint32_t n_tri = rc__leaf4_vertices(mesh->leaf_tris, mesh->vertices, mesh->stride, child, count, vt);
    rc__leaf4_out lo;
    uint32_t known = mesh->flats_folded ? 0xFu : 0u, flat = 0;
#if defined(RC__PACKET_AVX2)
    if (n_tri == 4u)
        rc__leaf4_test(ray, (const float *const(*)[3])vt, 4u, &lo);
    else
#endif
        rc__leaf4_test(ray, (const float *const(*)[3])vt, n_tri, &lo);
    leaf_lane_offer(T, mesh, vt, child, lane, &lo, &known, &flat, geom, inst, shrunk);
}

static RC__FORCE_INLINE void lone_lane(packet_trav *T, const rc__mesh *mesh, uint32_t lane, uint32_t child,
                                       uint32_t count, uint32_t geom, uint32_t inst, int *shrunk)
{
    rc__wide_entry stack[PACKET_STACK + 4u]; /* room for one node's children past the end */
    uint32_t sp = 0;
    for (;;) {
        if (count == 0) {
            rc__wide_entry *const e = stack + sp;
            const uint32_t m = lone_node(T, mesh, lane, child, e);
            if (m > 0) {
                child = e[m - 1].child;
                count = e[m - 1].count;
                sp += m - 1u;
                if (RC__UNLIKELY(sp > PACKET_STACK)) sp = PACKET_STACK;
                continue;
            }
        } else {
            lone_leaf(T, mesh, lane, child, count, geom, inst, shrunk);
        }
        /* pop (with the box test's slack, as the single-ray traversal: a box
         * whose entry rounds just above t may hold a tie) */
        for (;;) {
            if (sp == 0) return;
            --sp;
            if (stack[sp].tnear <= T->L.tmax[lane] * RC__SLAB_FAR_SCALE) break;
        }
        child = stack[sp].child;
        count = stack[sp].count;
    }
}
#endif

/* 1 when every lane of e has since found a hit nearer than e's box, so its
 * box tests would drop them all: tmin bounds the entry distances of its
 * lanes from below, and the tmax of one lane (an entry of one lane, most of
 * them deep in a large map), or P.tmax for several, their nearest hits from
 * above. The lane's own tmax drops what P.tmax, the packet's largest,
 * keeps (the lone lane's pop does the same). */
static RC__FORCE_INLINE int entry_beyond(const packet_trav *T, const packet_entry *e)
{
#if !defined(__OPTIMIZE_SIZE__)
    /* (-Os builds keep to P.tmax: these 32 bytes would take the static core
     * past its budget; the same results) */
    if (!(e->mask & (e->mask - 1u))) return e->tmin > T->L.tmax[rc__lowest_bit(e->mask)] * RC__SLAB_FAR_SCALE;
#endif
    return T->P.usable && e->tmin > T->P.tmax * RC__SLAB_FAR_SCALE;
}

/* Handles T's current node or leaf and moves to the next entry. With
 * interleaved set (a constant at every call) it works in turns as described
 * above; with a pool (below) each subtree one lane alone meets goes there.
 * 0 when the traversal is over (prim ids settled, except with a pool: its
 * lanes may still be searching, and the caller settles them). */
#if defined(RC__PACKET_LONE_LANE)
typedef struct lone_pool lone_pool;
static void pool_add(lone_pool *pool, packet_trav *T, uint32_t lane, uint32_t child, uint32_t count,
                     const rc__mesh *mesh, uint32_t geom, uint32_t inst);
#else
typedef void lone_pool;
#endif

static RC__FORCE_INLINE int trav_step(packet_trav *T, const rc__mesh *mesh, uint32_t geom, uint32_t inst,
                                      int interleaved, lone_pool *pool)
{
    const rc__wnode *nodes = mesh->wide;
    packet_lanes *L = &T->L;
    uint32_t child = T->child, mask = T->mask;
    /* settling and staged belong to turns: a packet alone never sets them */
    if (interleaved && T->settling) {
        uint32_t i;
        for (i = 0; i < T->n; ++i) rc__hit_settle(&T->hits[i], mesh->bvh.refs);
        return 0;
    }
#if defined(RC__PACKET_LONE_LANE)
    if (!interleaved && !(mask & (mask - 1u))) {
        /* one live lane: the rest of this subtree is that lane's alone */
        if (pool) {
            pool_add(pool, T, rc__lowest_bit(mask), child, T->count, mesh, geom, inst);
        } else {
            int shrunk = 0;
            lone_lane(T, mesh, rc__lowest_bit(mask), child, T->count, geom, inst, &shrunk);
            if (shrunk && T->P.usable) T->P.tmax = lanes_tmax(L);
        }
    } else
#endif
    if (T->count == 0) {
        const rc__wnode *nd = &nodes[child];
        /* the met children go straight onto the stack, farthest first: the
         * last is visited next, the others stay pushed */
        packet_entry *const S = T->stack + T->sp;
        float tn[4] RC__ALIGN16 = {0.0f, 0.0f, 0.0f, 0.0f};
        uint32_t lanes_met[4] = {0u, 0u, 0u, 0u};
        node_planes pl;
        uint32_t m = 0, c, j, maybe;
        const int few = few_lanes(mask);
        if (few) {
            /* at most FEW_LANES live lanes: each meets the four boxes at once
             * (the single-ray test), cheaper than every box over all lanes */
#if defined(RC__WIDE_BOX_SSE2)
            if (!(T->flags & RC__PACKET_OWN_ORIGINS))
                maybe = few_lanes_met_shared(nd, L, mask, lanes_met, tn);
            else
#endif
                maybe = few_lanes_met(nd, L, T->rays, mask, lanes_met, tn);
        } else {
            planes_fill(nd, L, &pl);
            maybe = T->P.usable ? children_maybe_hit(&pl, &T->P, tn) : 0xFu;
        }
        while (maybe) {
            uint32_t mc;
            c = rc__lowest_bit(maybe); /* a child slot here, not a lane */
            maybe &= maybe - 1u;
            if (nd->child[c] == RC__WIDE_EMPTY) continue;
            mc = few ? lanes_met[c] : box_mask(&pl, c, L, mask);
            if (!mc) continue;
            /* without turns, fetch what each met child needs first (a node,
             * or a leaf's index triples) now, while the packet works on
             * the nearest one: in a map past the private caches each is
             * otherwise a miss the packet waits for when it gets there
             * (1M sphere, under the turns' threshold here: +9-17%; 1k-100k,
             * and 10M with turns, within noise) */
            if (!interleaved) rc__prefetch_next(nodes, mesh->leaf_tris, nd->child[c], nd->count[c]);
            {
                /* sorted by the packet's smallest entry distance, nearest on
                 * top; of equal ones the earlier is visited first */
                packet_entry x;
                x.child = nd->child[c];
                x.count = nd->count[c];
                x.mask = mc;
                x.tmin = tn[c];
                for (j = m; j > 0 && S[j - 1].tmin <= x.tmin; --j) S[j] = S[j - 1];
                S[j] = x;
                ++m;
            }
        }
        if (m > 0) {
            T->child = S[m - 1].child;
            T->count = S[m - 1].count;
            T->mask = S[m - 1].mask;
            /* the builder caps depth so the pushes fit; a deeper tree (a
             * hostile baked map) loses its nearest branches instead of the
             * stack (which has room for one node's children past its end) */
            T->sp += m - 1u;
            if (RC__UNLIKELY(T->sp > PACKET_STACK)) T->sp = PACKET_STACK;
            if (interleaved) T->staged = 0;
            goto next;
        }
    } else if (interleaved && !T->staged) {
        rc__leaf4_stage(mesh->leaf_tris, mesh->vertices, mesh->stride, child, T->count);
        T->staged = 1;
        return 1;
    } else {
        /* lane by lane: the leaf's four triangles (transposed once for all
         * lanes) through the SIMD watertight test (leaf4.h); two lanes at a
         * time in the AVX2 build */
        const rc__ray *rays = T->rays;
        const float *vt[4][3];
        uint32_t n_tri;
        rc__leaf4_soa soa RC__ALIGN16;
        rc__leaf4_out lo;
        uint32_t m = mask, known = mesh->flats_folded ? 0xFu : 0u, flat = 0;
        int shrunk = 0;
#if defined(RC__PACKET_AVX2)
        /* a full leaf met by several lanes: its pointers four at a time
         * (100k -2.0%, 1M -1.6% instructions); a lone lane's leaf waits on
         * them, and there the vector path's longer chain measured 1M -2.5%;
         * with turns (10M) it measured 0.95-1.01 */
        if (!interleaved && T->count >= 4u && (m & (m - 1u))) {
            rc__leaf4_vertices_full(mesh->leaf_tris, mesh->vertices, mesh->stride, child, vt);
            n_tri = 4u;
        } else
#endif
            n_tri = rc__leaf4_vertices(mesh->leaf_tris, mesh->vertices, mesh->stride, child, T->count, vt);
#if defined(RC__LEAF4_SSE2)
        /* one live lane (most leaf visits on a large map): its rows gathered
         * in registers, without the copy (1M +2.6%); the loop below then has
         * nothing left */
        if (!(m & (m - 1u))) {
            const uint32_t lane = rc__lowest_bit(m);
#if defined(RC__PACKET_AVX2)
            /* four triangles (nearly every leaf) as a constant: no selects for missing slots */
            if (n_tri == 4u)
                rc__leaf4_test(&rays[lane], (const float *const(*)[3])vt, 4u, &lo);
            else
#endif
                rc__leaf4_test(&rays[lane], (const float *const(*)[3])vt, n_tri, &lo);
            leaf_lane_offer(T, mesh, vt, child, lane, &lo, &known, &flat, geom, inst, &shrunk);
            m = 0;
        } else
#endif
        rc__leaf4_transpose((const float *const(*)[3])vt, n_tri, &soa);
        while (m) {
            const uint32_t lane = rc__lowest_bit(m);
            m &= m - 1u;
#if defined(RC__PACKET_AVX2)
            if (m) {
                const uint32_t lane2 = rc__lowest_bit(m);
                rc__leaf4_out lo2;
                m &= m - 1u;
                rc__leaf4_test_soa_pair(&rays[lane], &rays[lane2], &soa, n_tri, &lo, &lo2);
                leaf_lane_offer(T, mesh, vt, child, lane, &lo, &known, &flat, geom, inst, &shrunk);
                leaf_lane_offer(T, mesh, vt, child, lane2, &lo2, &known, &flat, geom, inst, &shrunk);
                continue;
            }
#endif
            rc__leaf4_test_soa(&rays[lane], &soa, n_tri, &lo);
            leaf_lane_offer(T, mesh, vt, child, lane, &lo, &known, &flat, geom, inst, &shrunk);
        }
        if (shrunk && T->P.usable) T->P.tmax = lanes_tmax(L); /* hits only shrink tmax: tighten the bound */
    }
    /* pop; lanes that have since found nearer hits drop out in the box tests
     * of the next turn (tmax per lane) */
    do {
        if (T->sp == 0) {
            uint32_t i;
            if ((T->flags & RC__PACKET_PRIMS_PENDING) || pool) return 0;
            if (interleaved) {
                /* a prim id is a read from refs, a miss on a large map:
                 * prefetch them and settle in a turn of their own */
                for (i = 0; i < T->n; ++i)
                    if (T->hits[i].prim == RC__PRIM_PENDING) RC__PREFETCH(mesh->bvh.refs + T->hits[i].slot);
                T->settling = 1;
                return 1;
            }
            for (i = 0; i < T->n; ++i) rc__hit_settle(&T->hits[i], mesh->bvh.refs);
            return 0;
        }
        --T->sp;
    } while (entry_beyond(T, &T->stack[T->sp]));
    if (interleaved) T->staged = 0;
    T->child = T->stack[T->sp].child;
    T->count = T->stack[T->sp].count;
    T->mask = T->stack[T->sp].mask;
next:
    if (interleaved) rc__prefetch_next(nodes, mesh->leaf_tris, T->child, T->count);
    return 1;
}

void RC__PACKET_FN(rc__mesh_intersect_packet)(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom,
                                              uint32_t inst, rc__hit *hits, int *found, uint32_t flags)
{
    packet_trav T;
    uint32_t i;
    if (n == 0) return;
    if (n > LANES || mesh->wide == NULL) {
        for (i = 0; i < n; ++i) found[i] |= rc__mesh_intersect(mesh, &rays[i], geom, inst, &hits[i]);
        return;
    }
    if (mesh->wide_count == 0) return;
    if (!trav_init(&T, mesh, rays, n, hits, found, flags)) {
        split_by_octant(&mesh, &geom, 1u, rays, n, inst, hits, found, flags);
        return;
    }
    while (trav_step(&T, mesh, geom, inst, 0, NULL)) {
    }
}

#if defined(RC__PACKET_MESHES)
/* rc__mesh_intersect_packet_meshes; split 0: a part split_by_octant made
 * (one octant), which is never split again here */
static void packet_meshes(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count, const rc__ray *rays,
                          uint32_t n, uint32_t inst, rc__hit *hits, int *found, uint32_t flags, int split)
{
    packet_trav T;
    uint32_t m = 0;
    int filled = 0;
    if (n > 0 && n <= LANES)
        for (; m < count; ++m) {
            const rc__mesh *mesh = meshes[m];
            if (mesh->wide == NULL || mesh->wide_count == 0) {
                RC__PACKET_FN(rc__mesh_intersect_packet)(mesh, rays, n, geoms[m], inst, hits, found, flags);
                continue;
            }
            if (!filled) {
                if (!trav_init(&T, mesh, rays, n, hits, found, flags)) {
                    /* mixed octants: one packet an octant, through the rest */
                    if (split) {
                        split_by_octant(meshes + m, geoms + m, count - m, rays, n, inst, hits, found, flags);
                        return;
                    }
                    break;
                }
                filled = 1;
            } else {
                /* the lanes stay filled (their tmax the hits' so far, P.tmax
                 * their largest): the traversal starts over at the root */
                T.mask = (n >= 32u ? 0u : (1u << n)) - 1u;
                T.sp = T.child = T.count = 0;
                T.staged = T.settling = 0;
            }
            while (trav_step(&T, mesh, geoms[m], inst, 0, NULL)) {
            }
        }
    for (; m < count; ++m) RC__PACKET_FN(rc__mesh_intersect_packet)(meshes[m], rays, n, geoms[m], inst, hits, found, flags);
}

void RC__PACKET_FN(rc__mesh_intersect_packet_meshes)(const rc__mesh *const *meshes, const uint32_t *geoms,
                                                     uint32_t count, const rc__ray *rays, uint32_t n, uint32_t inst,
                                                     rc__hit *hits, int *found, uint32_t flags)
{
    packet_meshes(meshes, geoms, count, rays, n, inst, hits, found, flags, 1);
}
#endif

#if defined(RC__PACKET_LONE_LANE)
/* Lone lanes taking turns (rc__mesh_intersect_packets with
 * RC__PACKET_LONE_POOL, for a mesh far past the caches): the packets run one
 * by one, without turns, and each subtree one lane alone meets goes to a
 * pool of POOL_SLOTS such lanes, each a resumable single-ray traversal
 * (lone_lane's, a node or half a leaf a turn), which take turns while the
 * pool is full and at the end. Deep in a map past the caches nearly every
 * visit is a lone lane's (10M: 59% of the node visits and all but 0.2% of
 * the leaf visits of packets taking turns), so the fetches overlap there,
 * while the packets' steps above keep the cheaper bookkeeping of a packet
 * alone. A lane's subtrees may be in the pool at once, and the packet may
 * go on with that lane meanwhile: each offers its hits to the lane's
 * nearest, whose tie rule does not depend on the order. */
#define POOL_SLOTS 8u
typedef struct lone_trav {
    packet_trav *T; /* the lane's packet: its ray, tmax and hit */
    uint32_t lane, child, count, sp;
    uint32_t staged; /* 1 once the current leaf's vertices are prefetched */
    int shrunk;
    rc__wide_entry stack[PACKET_STACK + 4u]; /* room for one node's children past the end */
} lone_trav;

struct lone_pool {
    lone_trav slot[POOL_SLOTS];
    uint32_t live;
};

/* One turn of S: a node, or half a leaf (the first prefetches its
 * vertices, the second tests them). 0 once its subtree is searched. */
static RC__FORCE_INLINE int lone_step(lone_trav *S, const rc__mesh *mesh, uint32_t geom, uint32_t inst)
{
    packet_trav *const T = S->T;
    const uint32_t lane = S->lane;
    if (S->count == 0) {
        rc__wide_entry *const e = S->stack + S->sp;
        const uint32_t m = lone_node(T, mesh, lane, S->child, e);
        if (m > 0) {
            /* the nearest is visited next turn */
            S->child = e[m - 1].child;
            S->count = e[m - 1].count;
            S->sp += m - 1u;
            if (RC__UNLIKELY(S->sp > PACKET_STACK)) S->sp = PACKET_STACK;
            return 1;
        }
    } else if (!S->staged) {
        rc__leaf4_stage(mesh->leaf_tris, mesh->vertices, mesh->stride, S->child, S->count);
        S->staged = 1;
        return 1;
    } else {
        S->staged = 0;
        lone_leaf(T, mesh, lane, S->child, S->count, geom, inst, &S->shrunk);
    }
    /* pop (with the box test's slack, as lone_lane) */
    for (;;) {
        if (S->sp == 0) {
            if (S->shrunk && T->P.usable) T->P.tmax = lanes_tmax(&T->L);
            return 0;
        }
        --S->sp;
        if (S->stack[S->sp].tnear <= T->L.tmax[lane] * RC__SLAB_FAR_SCALE) break;
    }
    S->child = S->stack[S->sp].child;
    S->count = S->stack[S->sp].count;
    return 1;
}

/* Every searching lane of the pool takes one turn. */
static void pool_round(lone_pool *pool, const rc__mesh *mesh, uint32_t geom, uint32_t inst)
{
    uint32_t k;
    for (k = 0; k < POOL_SLOTS; ++k)
        if (((pool->live >> k) & 1u) && !lone_step(&pool->slot[k], mesh, geom, inst)) pool->live &= ~(1u << k);
}

/* Lane lane of T searches subtree (child, count) in the pool: the pool
 * takes turns until a slot is free. The entry was fetched when pushed. */
static void pool_add(lone_pool *pool, packet_trav *T, uint32_t lane, uint32_t child, uint32_t count,
                     const rc__mesh *mesh, uint32_t geom, uint32_t inst)
{
    lone_trav *S;
    while (pool->live == (1u << POOL_SLOTS) - 1u) pool_round(pool, mesh, geom, inst);
    S = &pool->slot[rc__lowest_bit(~pool->live)];
    pool->live |= 1u << (uint32_t)(S - pool->slot);
    S->T = T;
    S->lane = lane;
    S->child = child;
    S->count = count;
    S->sp = 0;
    S->staged = 0;
    S->shrunk = 0;
}
#endif

void RC__PACKET_FN(rc__mesh_intersect_packets)(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays,
                                               const uint32_t *n, uint32_t geom, uint32_t inst, rc__hit *const *hits,
                                               int *const *found, uint32_t flags)
{
    packet_trav T[RC__PACKETS_IN_FLIGHT];
    uint32_t live = 0, k;
    if (packets > RC__PACKETS_IN_FLIGHT) packets = RC__PACKETS_IN_FLIGHT;
    if (packets == 1) {
        RC__PACKET_FN(rc__mesh_intersect_packet)(mesh, rays[0], n[0], geom, inst, hits[0], found[0], flags);
        return;
    }
#if defined(RC__PACKET_LONE_LANE)
    if (flags & RC__PACKET_LONE_POOL) {
        lone_pool pool;
        pool.live = 0;
        for (k = 0; k < packets; ++k) {
            if (!trav_init(&T[k], mesh, rays[k], n[k], hits[k], found[k], flags)) {
                RC__PACKET_FN(rc__mesh_intersect_packet)(mesh, rays[k], n[k], geom, inst, hits[k], found[k], flags);
                continue;
            }
            live |= 1u << k;
            while (trav_step(&T[k], mesh, geom, inst, 0, &pool)) {
            }
        }
        while (pool.live) pool_round(&pool, mesh, geom, inst);
        /* the lanes' prim ids once every search is over */
        if (!(flags & RC__PACKET_PRIMS_PENDING))
            for (k = 0; k < packets; ++k)
                if ((live >> k) & 1u) {
                    uint32_t i;
                    for (i = 0; i < n[k]; ++i) rc__hit_settle(&hits[k][i], mesh->bvh.refs);
                }
        return;
    }
#endif
    for (k = 0; k < packets; ++k) {
        if (trav_init(&T[k], mesh, rays[k], n[k], hits[k], found[k], flags))
            live |= 1u << k;
        else
            RC__PACKET_FN(rc__mesh_intersect_packet)(mesh, rays[k], n[k], geom, inst, hits[k], found[k], flags);
    }
    /* take turns: while one packet's next node or leaf is on its way from
     * memory, the others work */
    while (live) {
        for (k = 0; k < packets; ++k)
            if (((live >> k) & 1u) && !trav_step(&T[k], mesh, geom, inst, 1, NULL)) live &= ~(1u << k);
    }
}

#if defined(RC__PACKET_TWO_BUILDS) && !defined(RC__PACKET_AVX2_VARIANT)
void rc__mesh_intersect_packet(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom,
                               uint32_t inst, rc__hit *hits, int *found, uint32_t flags)
{
    if (rc__leaf4_have_avx2())
        rc__mesh_intersect_packet_avx2(mesh, rays, n, geom, inst, hits, found, flags);
    else
        rc__mesh_intersect_packet_sse2(mesh, rays, n, geom, inst, hits, found, flags);
}

#if defined(RC__PACKET_MESHES)
void rc__mesh_intersect_packet_meshes(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count,
                                      const rc__ray *rays, uint32_t n, uint32_t inst, rc__hit *hits, int *found,
                                      uint32_t flags)
{
    if (rc__leaf4_have_avx2())
        rc__mesh_intersect_packet_meshes_avx2(meshes, geoms, count, rays, n, inst, hits, found, flags);
    else
        rc__mesh_intersect_packet_meshes_sse2(meshes, geoms, count, rays, n, inst, hits, found, flags);
}
#endif

void rc__mesh_intersect_packets(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays,
                                const uint32_t *n, uint32_t geom, uint32_t inst, rc__hit *const *hits,
                                int *const *found, uint32_t flags)
{
    if (rc__leaf4_have_avx2())
        rc__mesh_intersect_packets_avx2(mesh, packets, rays, n, geom, inst, hits, found, flags);
    else
        rc__mesh_intersect_packets_sse2(mesh, packets, rays, n, geom, inst, hits, found, flags);
}
#endif
