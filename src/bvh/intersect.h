/* The two inner tests of every CPU traversal, as static inline functions so the
 * scalar path inlines them and later SIMD/packet code can share them:
 *
 *   rc__tri_intersect   watertight ray/triangle test (Woop, Benthin, Wald 2013,
 *                       "Watertight Ray/Triangle Intersection", JCGT 2(1))
 *   rc__node_hit        robust slab test of a BVH node (Ize 2013, "Robust BVH
 *                       Ray Traversal", JCGT 2(2)), NaN-safe for zero direction
 *                       components
 *
 * Watertightness rests on two properties of the code below; keep them:
 *  - every vertex is transformed to ray space by the same expression, so a
 *    vertex shared by two triangles gets the same 2D coordinates in both;
 *  - every edge function has the form E(P,Q) = Qx*Py - Qy*Px, so the edge
 *    shared by two triangles (walked in opposite directions) gives exactly
 *    -E in the other triangle. That only holds when the compiler does not fuse
 *    a product and the subtraction into an FMA. FP contraction is off in GCC's
 *    -std=c99 mode, the pragma below turns clang's off, and each product has a
 *    second use (the zero test) so GCC does not fuse it even in gnu99 mode on
 *    FMA targets (checked on aarch64). -ffp-contract=fast in clang overrides
 *    the pragma: build the library with -ffp-contract=off to be sure, which
 *    also keeps t bit-identical between code paths.
 * Exactly zero edge functions are recomputed in double (products of floats are
 * exact there), which settles rays through edges and vertices consistently. */
#ifndef RC_BVH_INTERSECT_H
#define RC_BVH_INTERSECT_H

#include "bvh/mesh.h"

#include <float.h>
#include <stddef.h>

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

/* Slab exit distances (and the nearest hit a box is compared with) are scaled
 * by this. Ize's bound, 1 + 2 * gamma(3), is enough for rounding in
 * (plane - org) * inv_dir never to reject a box the ray meets; but a box is
 * also compared with a triangle's t from the watertight test, which carries
 * rounding of its own (a few ulps for a triangle not seen edge-on: 5.4 ulps
 * in a case fuzz_trace found, where the same triangle in an instance lay in a
 * box whose entry rounded above it). 32 ulps keep such a box, so a tie
 * between meshes or instances goes by the key whatever the order they are
 * searched in (a triangle seen edge-on, or reaching far beyond its hit point
 * along the ray, can round further than any fixed slack: docs/architecture.md,
 * "The BVH"); it cost 0.014% more instructions (docs/benchmarks.md). */
#define RC__SLAB_FAR_SCALE (1.0f + 32.0f * FLT_EPSILON)

/* Per-ray constants of the slab test. A node is read as it is laid out
 * (bmin[3], index, bmax[3], count): for each axis, the plane the ray enters by
 * (bmin where the direction is positive, bmax where it is negative, -0.0
 * included) is at byte offset near[k] of the node and the one it leaves by at
 * near[k] ^ 16, so no per-node choice is needed. */
typedef struct rc__slab_ray {
    float org[3];
    float inv[3];
    uint32_t near[3];
    float tmin; /* 0: where intervals start */
} rc__slab_ray;

static inline void rc__slab_ray_init(rc__slab_ray *s, const rc__ray *ray)
{
    int k;
    for (k = 0; k < 3; ++k) {
        s->org[k] = ray->org[k];
        s->inv[k] = ray->inv_dir[k];
        s->near[k] = (uint32_t)(offsetof(rc__bvh_node, bmin) + sizeof(float) * (size_t)k);
        if (ray->inv_dir[k] < 0.0f) s->near[k] += (uint32_t)offsetof(rc__bvh_node, bmax);
    }
    s->tmin = 0.0f;
}

/* rc__node_hit reads planes by byte offset: bmin at 0, bmax at 16. */
typedef char rc__node_layout_check[(offsetof(rc__bvh_node, bmin) == 0 &&
                                    offsetof(rc__bvh_node, bmax) == 16 &&
                                    sizeof(rc__bvh_node) == 32) ? 1 : -1];

/* The bmin/bmax component at byte offset off of a node. */
static inline float rc__node_plane(const rc__bvh_node *n, uint32_t off)
{
    return *(const float *)(const void *)((const unsigned char *)n + off);
}

/* 1 when the ray meets the node's box within [0, tmax] (conservatively);
 * *tnear gets the entry distance (>= 0). A zero direction component gives an
 * infinite reciprocal, and a NaN (0 * inf) where the origin lies exactly on a
 * plane: the comparisons below are written so a NaN never replaces the running
 * value, i.e. that plane imposes nothing (the box is closed). An empty box
 * (min = +inf, max = -inf) is always missed. */
static inline int rc__node_hit(const rc__bvh_node *n, const rc__slab_ray *s, float tmax, float *tnear)
{
    const float nx = (rc__node_plane(n, s->near[0]) - s->org[0]) * s->inv[0];
    const float ny = (rc__node_plane(n, s->near[1]) - s->org[1]) * s->inv[1];
    const float nz = (rc__node_plane(n, s->near[2]) - s->org[2]) * s->inv[2];
    const float fx = (rc__node_plane(n, s->near[0] ^ 16u) - s->org[0]) * s->inv[0];
    const float fy = (rc__node_plane(n, s->near[1] ^ 16u) - s->org[1]) * s->inv[1];
    const float fz = (rc__node_plane(n, s->near[2] ^ 16u) - s->org[2]) * s->inv[2];
    float tn = s->tmin, tf = tmax;
    /* a > b ? a : b keeps b when a is NaN; b is never NaN */
    tn = nx > tn ? nx : tn;
    tn = ny > tn ? ny : tn;
    tn = nz > tn ? nz : tn;
    tf = fx < tf ? fx : tf;
    tf = fy < tf ? fy : tf;
    tf = fz < tf ? fz : tf;
    *tnear = tn;
    return tn <= tf * RC__SLAB_FAR_SCALE;
}

/* RC__COLD: a rarely taken path kept out of line (and no warning where a
 * file includes this header without using it). */
#if defined(__GNUC__)
#define RC__COLD static __attribute__((noinline, unused))
#if defined(__OPTIMIZE_SIZE__)
/* -Os asks for size: the compiler decides (forcing every hot helper inline
 * at each of its callers cost the aarch64 core 7.9 KB) */
#define RC__FORCE_INLINE inline
#else
#define RC__FORCE_INLINE inline __attribute__((always_inline))
#endif
/* Helpers that only prefetch are inlined even at -Os: gcc 12 finds such a
 * helper free of side effects and deletes its calls before inlining it (at
 * -Os the turns and the push prefetch fetched nothing). */
#define RC__PREFETCH_INLINE inline __attribute__((always_inline))
#define RC__ALIGN16 __attribute__((aligned(16)))
#define RC__PREFETCH(p) __builtin_prefetch(p)
#else
#define RC__COLD static inline
#define RC__FORCE_INLINE inline
#define RC__PREFETCH_INLINE inline
#define RC__ALIGN16
#define RC__PREFETCH(p) ((void)(p))
#endif

/* Index of the lowest set bit of m (m != 0): where the set bits are lanes or
 * slots that lie anywhere in a mask, a loop shifting to the next one would
 * mispredict on the gaps. */
static RC__FORCE_INLINE uint32_t rc__lowest_bit(uint32_t m)
{
#if defined(__GNUC__)
    return (uint32_t)__builtin_ctz(m);
#else
    uint32_t b = 0;
    while (!((m >> b) & 1u)) ++b;
    return b;
#endif
}

/* double to float without overflow (huge coordinates). */
static inline float rc__clamp_to_float(double d)
{
    return d > FLT_MAX ? FLT_MAX : d < -FLT_MAX ? -FLT_MAX : (float)d;
}

/* Exactly zero edge function(s): recompute all three in double. */
RC__COLD void rc__tri_edges_double(float Ax, float Ay, float Bx, float By, float Cx, float Cy,
                                   float *U, float *V, float *W)
{
    const double CxBy = (double)Cx * (double)By, CyBx = (double)Cy * (double)Bx;
    const double AxCy = (double)Ax * (double)Cy, AyCx = (double)Ay * (double)Cx;
    const double BxAy = (double)Bx * (double)Ay, ByAx = (double)By * (double)Ax;
    *U = rc__clamp_to_float(CxBy - CyBx);
    *V = rc__clamp_to_float(AxCy - AyCx);
    *W = rc__clamp_to_float(BxAy - ByAx);
}

/* 1 when (b - a) x (c - a) is exactly zero (to double precision): a zero-area
 * triangle. Sheared 2D coordinates of a collinear triangle can round to a
 * non-zero area, so the hit path checks this explicitly (it runs only for rays
 * that pass the inside test). */
RC__COLD int rc__tri_zero_area(const float *a, const float *b, const float *c)
{
    const double e1x = (double)b[0] - a[0], e1y = (double)b[1] - a[1], e1z = (double)b[2] - a[2];
    const double e2x = (double)c[0] - a[0], e2y = (double)c[1] - a[1], e2z = (double)c[2] - a[2];
    return e1y * e2z - e1z * e2y == 0.0 && e1z * e2x - e1x * e2z == 0.0 &&
           e1x * e2y - e1y * e2x == 0.0;
}

/* Distance along the ray to the plane of (a, b, c) in double (float inputs
 * are exact there); 0 when it is not positive or not finite. */
RC__COLD int rc__tri_plane_t_double(const rc__ray *r, const float *a, const float *b, const float *c, float *t)
{
    const double e1x = (double)b[0] - a[0], e1y = (double)b[1] - a[1], e1z = (double)b[2] - a[2];
    const double e2x = (double)c[0] - a[0], e2y = (double)c[1] - a[1], e2z = (double)c[2] - a[2];
    const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
    const double w = nx * ((double)a[0] - r->org[0]) + ny * ((double)a[1] - r->org[1]) + nz * ((double)a[2] - r->org[2]);
    const double dn = nx * r->dir[0] + ny * r->dir[1] + nz * r->dir[2];
    const double td = w / dn;
    if (!(td > 0.0) || !(td < 3.0e38)) return 0;
    *t = (float)td;
    return *t > 0.0f;
}

/* rc__tri_intersect less its last step, the zero-area check: for callers
 * that know the answer already (leaf4.h: rc__leaf4_take). A triangle of zero
 * area that this passes has a hit only by rounding. */
static RC__FORCE_INLINE int rc__tri_intersect_any_area(const rc__ray *r, const float *a, const float *b,
                                                       const float *c, float *t, float *u, float *v)
{
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    const float ox = r->org[kx], oy = r->org[ky], oz = r->org[kz];
    const float sx = r->sx, sy = r->sy;
    /* vertices relative to the origin, then sheared so the ray is +z */
    const float az = a[kz] - oz, bz = b[kz] - oz, cz = c[kz] - oz;
    const float Ax = (a[kx] - ox) - sx * az, Ay = (a[ky] - oy) - sy * az;
    const float Bx = (b[kx] - ox) - sx * bz, By = (b[ky] - oy) - sy * bz;
    const float Cx = (c[kx] - ox) - sx * cz, Cy = (c[ky] - oy) - sy * cz;
    /* Each product has a second use (the zero test below), which also keeps
     * GCC from fusing it into an FMA with the subtraction even where FP
     * contraction is on: the shared edge must give exactly -E in both
     * triangles. U is exactly 0 when its two products are equal. */
    const float CxBy = Cx * By, CyBx = Cy * Bx;
    const float AxCy = Ax * Cy, AyCx = Ay * Cx;
    const float BxAy = Bx * Ay, ByAx = By * Ax;
    float U = CxBy - CyBx; /* E(B, C) */
    float V = AxCy - AyCx; /* E(C, A) */
    float W = BxAy - ByAx; /* E(A, B) */
    float det, T, tt;
    /* Rounding is monotonic, so a non-zero float edge function has the sign of
     * the exact one: mixed non-zero signs reject at once. Only then are zeros
     * settled in double. */
    {
        /* min/max instead of six branches (NaN only from overflow: it makes
         * det or t NaN below, which rejects) */
        const float lo = U < V ? (U < W ? U : W) : (V < W ? V : W);
        const float hi = U > V ? (U > W ? U : W) : (V > W ? V : W);
        if (lo < 0.0f && hi > 0.0f) return 0;
    }
    if ((CxBy == CyBx) | (AxCy == AyCx) | (BxAy == ByAx)) {
        rc__tri_edges_double(Ax, Ay, Bx, By, Cx, Cy, &U, &V, &W);
        if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
    }
    det = U + V + W;
    if (det == 0.0f) return 0;
    T = U * (r->sz * az) + V * (r->sz * bz) + W * (r->sz * cz);
    tt = T / det;
    if (!(tt > 0.0f)) return 0;
    /* t tiny against the triangle's own extent along the ray: the origin lies
     * (nearly) in the triangle's plane, where rounding of the sheared
     * coordinates can fake a small positive t (a sensor on a floor would see
     * the floor at 1e-6 m). Decide that rare case in double. */
    if (tt * 1024.0f < (r->sz < 0.0f ? -r->sz : r->sz) * ((az < 0.0f ? -az : az) + (bz < 0.0f ? -bz : bz) +
                                                           (cz < 0.0f ? -cz : cz))) {
        if (!rc__tri_plane_t_double(r, a, b, c, &tt)) return 0;
    }
    *t = tt;
    *u = V / det;
    *v = W / det;
    return 1;
}

/* Watertight test of triangle (a, b, c), either winding. On a hit with t > 0
 * returns 1 with *t (in units of |dir|), the barycentrics *u (weight of b) and
 * *v (weight of c): the point is (1 - u - v) a + u b + v c, as in Embree. The
 * caller compares t with its current nearest. A triangle of zero area is
 * never hit (on 0, *t, *u and *v may have been written). */
static RC__FORCE_INLINE int rc__tri_intersect(const rc__ray *r, const float *a, const float *b,
                                              const float *c, float *t, float *u, float *v)
{
    return rc__tri_intersect_any_area(r, a, b, c, t, u, v) && !rc__tri_zero_area(a, b, c);
}

/* Tie rule of rc__mesh_intersect: (inst, geom, prim) lexicographically smaller. */
static inline int rc__hit_key_less(uint32_t inst, uint32_t geom, uint32_t prim, const rc__hit *h)
{
    if (inst != h->inst) return inst < h->inst;
    if (geom != h->geom) return geom < h->geom;
    return prim < h->prim;
}

/* Records t on triangle prim as the nearest hit when it beats *h: nearer,
 * or as near with a smaller key. Returns 1 when it did. */
static inline void rc__hit_record(rc__hit *h, float t, uint32_t prim, uint32_t slot, uint32_t geom, uint32_t inst)
{
    h->t = t;
    h->prim = prim;
    h->slot = slot;
    h->geom = geom;
    h->inst = inst;
}

static inline int rc__hit_offer(rc__hit *h, float t, uint32_t prim, uint32_t slot, uint32_t geom, uint32_t inst)
{
    if (t > h->t || (t == h->t && !rc__hit_key_less(inst, geom, prim, h))) return 0;
    rc__hit_record(h, t, prim, slot, geom, inst);
    return 1;
}

/* Prim id of a hit recorded by rc__hit_offer_slot and not yet settled. */
#define RC__PRIM_PENDING 0xFFFFFFFEu

/* rc__hit_offer for triangle refs[slot] of the mesh being traversed, without
 * reading refs[slot] unless there is a tie: the hit keeps only its slot and a
 * pending prim until rc__hit_settle. The references are a separate array from
 * the leaf data, and reading one per candidate hit measured as a cache miss
 * on large maps; one read per ray at the end is off the traversal's path. */
static inline int rc__hit_offer_slot(rc__hit *h, float t, const uint32_t *refs, uint32_t slot, uint32_t geom,
                                     uint32_t inst)
{
    if (t > h->t) return 0;
    if (t == h->t) {
        /* a hit another mesh's search left pending (RC__PACKET_PRIMS_PENDING)
         * is not resolved against this mesh's refs: the key decides by
         * instance or geometry before it reads the prim */
        if (h->prim == RC__PRIM_PENDING && h->geom == geom && h->inst == inst) h->prim = refs[h->slot];
        if (!rc__hit_key_less(inst, geom, refs[slot], h)) return 0;
    }
    rc__hit_record(h, t, RC__PRIM_PENDING, slot, geom, inst);
    return 1;
}

/* Resolves the pending prim id of a hit from rc__hit_offer_slot. */
static inline void rc__hit_settle(rc__hit *h, const uint32_t *refs)
{
    if (h->prim == RC__PRIM_PENDING) h->prim = refs[h->slot];
}

#endif
