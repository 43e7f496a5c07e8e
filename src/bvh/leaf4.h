/* A leaf's (up to) four triangles against one ray at once: the watertight
 * test (shear, edge functions, sign test, determinant, distance) in SSE2 or
 * NEON lanes. Every lane repeats the scalar test's operations in the same
 * order (IEEE single precision, no contraction), so a lane's edge functions
 * and t are rc__tri_intersect's bit for bit, and a lane that
 * test would reject is rejected here. Lanes that reach one of its rare
 * double-precision cases (a zero edge function, a NaN from overflow, an
 * origin in the triangle's plane) go to rc__tri_intersect, which decides.
 * 32-bit ARM runs only the first half in lanes, as a filter (see
 * RC__LEAF4_FULL). The answer is the scalar test's by construction. */
#ifndef RC_BVH_LEAF4_H
#define RC_BVH_LEAF4_H

#include "bvh/intersect.h"

#include <float.h>
#include <stdint.h>

#if defined(__AVX2__)
#include <immintrin.h> /* rc__leaf4_vertices_full */
#endif

#if defined(__SSE2__) && !defined(RC__WIDE_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__LEAF4_SSE2 1
#elif defined(__ARM_NEON) && !defined(RC__WIDE_FORCE_SCALAR)
#include "bvh/neon_ops.h"
#define RC__LEAF4_NEON 1
#endif

/* The vertices of leaf slots first .. first + count (count <= 4; more is
 * clamped: the builder never makes more) from a mesh's leaf-ordered index
 * triples (the caller's hoisted copies of its fields). Returns the count used. */
static RC__FORCE_INLINE uint32_t rc__leaf4_vertices(const uint32_t *leaf_tris, const float *vertices, size_t stride,
                                                   uint32_t first, uint32_t count, const float *v[4][3])
{
    uint32_t k;
    const uint32_t *tri = leaf_tris + (size_t)3 * first;
    /* every leaf but one holds four (the builder fills them): with the
     * count a constant the loop unrolls (1M -2.1% instructions) */
    if (count >= 4u) count = 4u;
    if (count == 4u)
        for (k = 0; k < 12u; ++k) v[k / 3u][k % 3u] = vertices + tri[k] * stride;
    else
        for (k = 0; k < 3u * count; ++k) v[k / 3u][k % 3u] = vertices + tri[k] * stride;
    return count;
}

#if defined(__AVX2__)
/* rc__leaf4_vertices for a full leaf (count 4) in the AVX2 build: the same
 * twelve pointers, four at a time (each index widened and scaled in a
 * 64-bit lane; a stride in floats times 4 fits the multiply's 32-bit
 * operand, vertex_stride being a uint32_t of bytes; an x86-64 pointer is its
 * address as a 64-bit integer): 15 instructions for 48, but a few cycles
 * more before the first pointer is ready, which only a leaf tested by
 * several lanes hides. */
static RC__FORCE_INLINE void rc__leaf4_vertices_full(const uint32_t *leaf_tris, const float *vertices, size_t stride,
                                                     uint32_t first, const float *v[4][3])
{
    const uint32_t *tri = leaf_tris + (size_t)3 * first;
    const __m256i scale = _mm256_set1_epi64x((long long)(stride * sizeof(float)));
    const __m256i base = _mm256_set1_epi64x((long long)(uintptr_t)vertices);
    uint32_t k;
    for (k = 0; k < 3u; ++k) {
        const __m256i idx = _mm256_cvtepu32_epi64(_mm_loadu_si128((const __m128i *)(const void *)(tri + 4u * k)));
        _mm256_storeu_si256((__m256i *)(void *)&v[0][0] + k, _mm256_add_epi64(base, _mm256_mul_epu32(idx, scale)));
    }
}
#endif

/* For traversals taking turns: the first bytes of what a ray or packet
 * visits next (count 0: wide node `child`, both its cache lines; else the
 * leaf's index triples), and, once those are in, a leaf's vertices. */
static RC__PREFETCH_INLINE void rc__prefetch_next(const rc__wnode *nodes, const uint32_t *leaf_tris, uint32_t child,
                                                 uint32_t count)
{
    if (count == 0) {
        const char *p = (const char *)&nodes[child];
        RC__PREFETCH(p);
        RC__PREFETCH(p + 64);
    } else {
        /* a full leaf's 48 bytes of triples cross a cache line at half the
         * slots (those at byte 32 or 48 of a line): its last byte too */
        const char *p = (const char *)(leaf_tris + (size_t)3 * child);
        RC__PREFETCH(p);
        RC__PREFETCH(p + 12u * count - 1u);
    }
}

/* A leaf's vertices prefetched, for traversals taking turns: the turn
 * before its test reads its index triples and starts the vertex loads. */
static RC__PREFETCH_INLINE void rc__leaf4_stage(const uint32_t *leaf_tris, const float *vertices, size_t stride,
                                                uint32_t first, uint32_t count)
{
    const float *vt[4][3];
    const uint32_t n = rc__leaf4_vertices(leaf_tris, vertices, stride, first, count, vt);
    uint32_t i;
    for (i = 0; i < n; ++i) {
        RC__PREFETCH(vt[i][0]);
        RC__PREFETCH(vt[i][1]);
        RC__PREFETCH(vt[i][2]);
    }
}

/* A leaf's (up to) four triangles transposed for the SIMD test:
 * c[vertex][axis][slot], slots past the leaf's count repeating slot 0. A
 * packet transposes a leaf once and filters every live lane from it. */
typedef struct rc__leaf4_soa {
    float c[3][3][4];
} rc__leaf4_soa;

static RC__FORCE_INLINE void rc__leaf4_transpose(const float *const v[4][3], uint32_t count, rc__leaf4_soa *s)
{
#if defined(RC__LEAF4_SSE2)
    /* each row built in a register and stored whole: the tests load rows,
     * and a row load waits for four one-float stores to reach the cache
     * (no store forwarding from several stores) */
    const float *const *p0 = v[0], *const *p1 = v[count > 1u ? 1 : 0];
    const float *const *p2 = v[count > 2u ? 2 : 0], *const *p3 = v[count > 3u ? 3 : 0];
    uint32_t vx, k;
    for (vx = 0; vx < 3; ++vx)
        for (k = 0; k < 3; ++k) _mm_storeu_ps(s->c[vx][k], _mm_setr_ps(p0[vx][k], p1[vx][k], p2[vx][k], p3[vx][k]));
#else
    uint32_t i, vx, k;
    for (i = 0; i < 4; ++i) {
        const float *const *t = v[i < count ? i : 0];
        for (vx = 0; vx < 3; ++vx)
            for (k = 0; k < 3; ++k) s->c[vx][k][i] = t[vx][k];
    }
#endif
}

/* Four float lanes, written once for SSE2 and NEON: the lane body
 * (leaf4_lanes.h) uses only these operations (no fused multiply-add:
 * products round as in C). */
#if defined(RC__LEAF4_SSE2)
typedef __m128 rc__v4;
typedef __m128 rc__v4mask;
#define RC__V4_SET1(x) _mm_set1_ps(x)
#define RC__V4_SUB(a, b) _mm_sub_ps(a, b)
#define RC__V4_MUL(a, b) _mm_mul_ps(a, b)
#define RC__V4_LT(a, b) _mm_cmplt_ps(a, b)
#define RC__V4_GT(a, b) _mm_cmpgt_ps(a, b)
#define RC__V4_OR(a, b) _mm_or_ps(a, b)
#define RC__V4_AND(a, b) _mm_and_ps(a, b)
#define RC__V4_ORDERED(a, b) _mm_cmpord_ps(a, b)
#define RC__V4_LOAD(p) _mm_loadu_ps(p)
#define RC__V4_ADD(a, b) _mm_add_ps(a, b)
#define RC__V4_DIV(a, b) _mm_div_ps(a, b)
#define RC__V4_EQ(a, b) _mm_cmpeq_ps(a, b)
#define RC__V4_ABS(a) _mm_andnot_ps(_mm_set1_ps(-0.0f), a)
#define RC__V4_STORE(p, a) _mm_storeu_ps(p, a)
#define RC__V4_ANDNOT(a, b) _mm_andnot_ps(a, b) /* ~a & b */
#define RC__V4_UNORDERED(a, b) _mm_cmpunord_ps(a, b)
static RC__FORCE_INLINE uint32_t rc__v4_bits(rc__v4mask m) { return (uint32_t)_mm_movemask_ps(m); }
#elif defined(RC__LEAF4_NEON)
typedef float32x4_t rc__v4;
typedef uint32x4_t rc__v4mask;
#define RC__V4_SET1(x) vdupq_n_f32(x)
#define RC__V4_SUB(a, b) vsubq_f32(a, b)
#define RC__V4_MUL(a, b) vmulq_f32(a, b)
#define RC__V4_LT(a, b) vcltq_f32(a, b)
#define RC__V4_GT(a, b) vcgtq_f32(a, b)
#define RC__V4_OR(a, b) vorrq_u32(a, b)
#define RC__V4_AND(a, b) vandq_u32(a, b)
#define RC__V4_ORDERED(a, b) vandq_u32(vceqq_f32(a, a), vceqq_f32(b, b))
#define RC__V4_LOAD(p) vld1q_f32(p)
#define RC__V4_ADD(a, b) vaddq_f32(a, b)
#define RC__V4_EQ(a, b) vceqq_f32(a, b)
#define RC__V4_ABS(a) vabsq_f32(a)
#define RC__V4_STORE(p, a) vst1q_f32(p, a)
#define RC__V4_ANDNOT(a, b) vbicq_u32(b, a) /* ~a & b */
#define RC__V4_UNORDERED(a, b) vmvnq_u32(RC__V4_ORDERED(a, b))
#if defined(__aarch64__)
#define RC__V4_DIV(a, b) vdivq_f32(a, b) /* 32-bit NEON has no division */
#endif
static RC__FORCE_INLINE uint32_t rc__v4_bits(rc__v4mask m) { return rc__neon_bits(m); }
#endif

/* The watertight test of one ray against a leaf's (up to) four triangles,
 * as far as the SIMD lanes take it (rc__leaf4_test): bit i of hit says
 * triangle i is met at t[i], unless it has zero area (rc__leaf4_take
 * checks that, for the few triangles a ray is offered); bit i of redo says
 * rc__tri_intersect must decide (a zero edge function, a NaN from overflow,
 * an origin near the triangle's plane: its double-precision cases). Every
 * other triangle misses. */
typedef struct rc__leaf4_out {
    float t[4];
    uint32_t hit, redo;
} rc__leaf4_out;

#if defined(RC__LEAF4_SSE2) && defined(__x86_64__) && defined(__GNUC__) && !defined(RC__LEAF4_NO_AVX2)
/* Two rays at once in 8-wide AVX2 lanes (leaf4_pair.h), for packets on CPUs
 * that have AVX2. */
#define RC__LEAF4_PAIR_AVX2 1
/* a load and a bit test (libgcc's CPU model, filled at start-up; it counts
 * AVX2 only where the OS saves the wide registers): cheap enough per packet */
static RC__FORCE_INLINE int rc__leaf4_have_avx2(void) { return __builtin_cpu_supports("avx2") ? 1 : 0; }
#endif

#if defined(RC__LEAF4_SSE2) || (defined(RC__LEAF4_NEON) && defined(__aarch64__))
/* The whole test in lanes, not only its reject half: every lane repeats the
 * scalar test's operations in the same order, so t is its own bit for bit,
 * and the scalar test is left only its rare cases (it redid the shear and
 * the edge functions for every candidate: 9% of the time of a 1k map).
 * 32-bit ARM keeps the filter: its NEON flushes subnormals to zero and has
 * no division. */
#define RC__LEAF4_FULL 1
#endif

#if defined(RC__LEAF4_SSE2) || defined(RC__LEAF4_NEON)
/* The lane body (leaf4_lanes.h) for four lanes. */
#define RC__VL_NAME rc__leaf4_lanes
#define RC__VL_ATTR
#define RC__VL_T rc__v4
#define RC__VL_M rc__v4mask
#define RC__VL_SET1 RC__V4_SET1
#define RC__VL_SUB RC__V4_SUB
#define RC__VL_ADD RC__V4_ADD
#define RC__VL_MUL RC__V4_MUL
#define RC__VL_DIV RC__V4_DIV
#define RC__VL_LT RC__V4_LT
#define RC__VL_GT RC__V4_GT
#define RC__VL_EQ RC__V4_EQ
#define RC__VL_ORDERED RC__V4_ORDERED
#define RC__VL_UNORDERED RC__V4_UNORDERED
#define RC__VL_OR RC__V4_OR
#define RC__VL_AND RC__V4_AND
#define RC__VL_ANDNOT RC__V4_ANDNOT
#define RC__VL_ABS RC__V4_ABS
#define RC__VL_BITS rc__v4_bits
#if !defined(RC__LEAF4_FULL)
#define RC__VL_FILTER_ONLY 1
#define RC__VL_TINY(a) vcaltq_f32(a, vdupq_n_f32(FLT_MIN))
#endif
#include "bvh/leaf4_lanes.h"

/* Triangles i < count given their a, b, c coordinates along kx, ky, kz
 * (separate arguments, not an array: an array of vectors made gcc keep them
 * in memory, +8% instructions on aarch64). */
static RC__FORCE_INLINE void rc__leaf4_run(const rc__ray *r, rc__v4 ax, rc__v4 ay, rc__v4 az, rc__v4 bx, rc__v4 by,
                                          rc__v4 bz, rc__v4 cx, rc__v4 cy, rc__v4 cz, uint32_t count,
                                          rc__leaf4_out *o)
{
    rc__v4 t;
    rc__leaf4_lanes(ax, ay, az, bx, by, bz, cx, cy, cz, RC__V4_SET1(r->org[r->kx]), RC__V4_SET1(r->org[r->ky]),
                    RC__V4_SET1(r->org[r->kz]), RC__V4_SET1(r->sx), RC__V4_SET1(r->sy), RC__V4_SET1(r->sz),
                    (1u << count) - 1u, &o->hit, &o->redo, &t);
#if defined(RC__LEAF4_FULL)
    RC__V4_STORE(o->t, t);
#else
    (void)t;
#endif
}
#endif

/* rc__leaf4_out for ray r and the triangles v[i][0..2], i < count (slots
 * past count are ignored). */
static RC__FORCE_INLINE void rc__leaf4_test(const rc__ray *r, const float *const v[4][3], uint32_t count,
                                           rc__leaf4_out *o)
{
#if defined(RC__LEAF4_SSE2) || defined(RC__LEAF4_NEON)
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    /* lane i: triangle i, or triangle 0 again for the slots past count */
    const float *const *p0 = v[0], *const *p1 = v[count > 1u ? 1 : 0];
    const float *const *p2 = v[count > 2u ? 2 : 0], *const *p3 = v[count > 3u ? 3 : 0];
#if defined(RC__LEAF4_SSE2)
#define RC__LEAF4_GATHER(vtx, k) _mm_setr_ps(p0[vtx][k], p1[vtx][k], p2[vtx][k], p3[vtx][k])
    rc__leaf4_run(r, RC__LEAF4_GATHER(0, kx), RC__LEAF4_GATHER(0, ky), RC__LEAF4_GATHER(0, kz),
                  RC__LEAF4_GATHER(1, kx), RC__LEAF4_GATHER(1, ky), RC__LEAF4_GATHER(1, kz), RC__LEAF4_GATHER(2, kx),
                  RC__LEAF4_GATHER(2, ky), RC__LEAF4_GATHER(2, kz), count, o);
#else
    /* NEON: one table, nine loads (building each vector lane by lane measured
     * 8% more instructions over the single-ray traversal) */
#define RC__LEAF4_GATHER(vtx, k) {p0[vtx][k], p1[vtx][k], p2[vtx][k], p3[vtx][k]}
    const float c[9][4] = {RC__LEAF4_GATHER(0, kx), RC__LEAF4_GATHER(0, ky), RC__LEAF4_GATHER(0, kz),
                           RC__LEAF4_GATHER(1, kx), RC__LEAF4_GATHER(1, ky), RC__LEAF4_GATHER(1, kz),
                           RC__LEAF4_GATHER(2, kx), RC__LEAF4_GATHER(2, ky), RC__LEAF4_GATHER(2, kz)};
    rc__leaf4_run(r, vld1q_f32(c[0]), vld1q_f32(c[1]), vld1q_f32(c[2]), vld1q_f32(c[3]), vld1q_f32(c[4]),
                  vld1q_f32(c[5]), vld1q_f32(c[6]), vld1q_f32(c[7]), vld1q_f32(c[8]), count, o);
#endif
#undef RC__LEAF4_GATHER
#else
    (void)r;
    (void)v;
    o->redo = (1u << count) - 1u;
    o->hit = 0;
#endif
}

/* rc__leaf4_test from a transposed leaf (the same tests, bit for bit). */
static RC__FORCE_INLINE void rc__leaf4_test_soa(const rc__ray *r, const rc__leaf4_soa *s, uint32_t count,
                                               rc__leaf4_out *o)
{
#if defined(RC__LEAF4_SSE2) || defined(RC__LEAF4_NEON)
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    rc__leaf4_run(r, RC__V4_LOAD(s->c[0][kx]), RC__V4_LOAD(s->c[0][ky]), RC__V4_LOAD(s->c[0][kz]),
                  RC__V4_LOAD(s->c[1][kx]), RC__V4_LOAD(s->c[1][ky]), RC__V4_LOAD(s->c[1][kz]),
                  RC__V4_LOAD(s->c[2][kx]), RC__V4_LOAD(s->c[2][ky]), RC__V4_LOAD(s->c[2][kz]), count, o);
#else
    (void)r;
    (void)s;
    o->redo = (1u << count) - 1u;
    o->hit = 0;
#endif
}

/* Triangle c of a leaf tested by rc__leaf4_test: 1 with *t as
 * rc__tri_intersect gives it when it is hit, else 0. tv: its vertices.
 * The zero-area check depends on the triangle alone: *known and *flat keep
 * its answers per slot (bit c), so a leaf that a packet's lanes test in
 * turn runs it once per triangle (1k sphere: 4% of the time, once a lane).
 * Callers start *known at 0xF for a mesh whose flats_folded is set: there a
 * zero-area triangle is (a, a, a), which is never hit (the lanes find its
 * edge functions all exactly 0 and hand it to the scalar test, and the
 * vertex compare below ends it), so no hit needs the check. */
static RC__FORCE_INLINE int rc__leaf4_take(const rc__leaf4_out *o, uint32_t c, const rc__ray *r,
                                          const float *const tv[3], uint32_t *known, uint32_t *flat, float *t)
{
    float u, v; /* the scalar test's barycentrics: no result needs them */
#if defined(RC__LEAF4_FULL)
    const uint32_t scalar = (o->redo >> c) & 1u; /* else a hit the lanes settled */
#else
    const uint32_t scalar = 1u; /* the lanes only filter */
    (void)o;
#endif
    /* only the scalar test's cases can hold two vertices the same (a folded
     * zero-area triangle) */
    if (!scalar)
        *t = o->t[c];
    else if (!(tv[0] != tv[1] && rc__tri_intersect_any_area(r, tv[0], tv[1], tv[2], t, &u, &v)))
        return 0;
    if (!((*known >> c) & 1u)) {
        *known |= 1u << c;
        *flat |= (uint32_t)rc__tri_zero_area(tv[0], tv[1], tv[2]) << c;
    }
    return !((*flat >> c) & 1u);
}

#endif
