/* Nearest-hit search through a scene's two levels: the top BVH over geometries
 * and instances, then each mesh's BVH (instances in their own frame); a
 * packet's walk of the top level for scenes of many meshes; the hits'
 * distances refined in double. */
#include "scene/scene.h"

#include "bvh/intersect.h"
#include "bvh/leaf4.h" /* rc__leaf4_have_avx2 */

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>
#if defined(RC__HIT_DISTANCES_SSE2) && defined(RC__LEAF4_PAIR_AVX2)
#include <immintrin.h>
#endif
#if defined(RC__PACKET_MESHES) && defined(__SSE2__)
#include <emmintrin.h>
#elif defined(RC__PACKET_MESHES) && defined(__ARM_NEON) && defined(__aarch64__)
/* lanes_in_box in NEON lanes (AArch64 only: 32-bit ARM's NEON flushes
 * subnormals, where box_hit's scalar operations would not) */
#include "bvh/neon_ops.h"
#define RC__LANES_IN_BOX_NEON 1
#endif

/* Slab test against a top-level node. Top-level boxes are few, so this is not
 * the hot loop; NaN from 0 * inf is avoided by the ordered min/max below. */
static int box_hit(const rc__ray *r, const float bmin[3], const float bmax[3], float tmax, float *tnear)
{
    float t0 = 0.0f, t1 = tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        float a = (bmin[k] - r->org[k]) * r->inv_dir[k];
        float b = (bmax[k] - r->org[k]) * r->inv_dir[k];
        float lo = a < b ? a : b, hi = a < b ? b : a;
        if (a != a || b != b) { /* 0 * inf: origin on the slab plane with a parallel ray */
            if (r->org[k] < bmin[k] || r->org[k] > bmax[k]) return 0;
            continue;
        }
        if (lo > t0) t0 = lo;
        if (hi < t1) t1 = hi;
    }
    /* Ize's bound, as in the mesh trees: rounding never rejects a box the ray
     * meets (a smaller margin could cull a mesh that a grazing ray hits, and
     * the packet path, which tests every mesh, would then disagree) */
    *tnear = t0;
    return t0 <= t1 * RC__SLAB_FAR_SCALE;
}

/* ray in the instance's frame: the same parameter t along it (its direction
 * is moved, not normalised) */
static void instance_ray(const rc__instance *in, const rc__ray *ray, rc__ray *local)
{
    float o[3], d[3];
    rc__rot_apply_f(in->to_local.r, ray->org, o);
    o[0] += in->to_local.t[0];
    o[1] += in->to_local.t[1];
    o[2] += in->to_local.t[2];
    rc__rot_apply_f(in->to_local.r, ray->dir, d);
    rc__ray_prepare(local, o, d);
}

static int instance_intersect(const rc__instance *in, uint32_t inst_id, const rc__ray *ray, rc__hit *hit)
{
    const rc_scene *src = in->source;
    rc__ray local;
    uint32_t g;
    int found = 0;
    instance_ray(in, ray, &local);
    /* Sources hold a few meshes: test each mesh's root through its own BVH. */
    for (g = 0; g < src->geom_count; ++g) found |= rc__mesh_intersect(&src->geoms[g].mesh, &local, g, inst_id, hit);
    return found;
}

int rc__scene_intersect_items(const rc_scene *scene, const rc__ray *ray, rc__hit *hit, uint32_t first)
{
    uint32_t stack[RC__BVH_MAX_DEPTH + 1];
    uint32_t sp = 0, ni = 0;
    int found = 0;
    const rc__bvh *top = &scene->top;

    if (scene->geom_count == 1 && scene->inst_count == 0)
        return rc__mesh_intersect(&scene->geoms[0].mesh, ray, 0, RC_INVALID_ID, hit);
    if (top->node_count == 0) return 0;
    for (;;) {
        const rc__bvh_node *n = &top->nodes[ni];
        float tn;
        if (box_hit(ray, n->bmin, n->bmax, hit->t, &tn)) {
            if (n->count == 0) {
                stack[sp++] = n->index + 1; /* depth is capped by the builder */
                ni = n->index;
                continue;
            } else {
                uint32_t k;
                for (k = 0; k < n->count; ++k) {
                    uint32_t item = top->refs[n->index + k];
                    if (item < first) continue;
                    if (item < scene->geom_count)
                        found |= rc__mesh_intersect(&scene->geoms[item].mesh, ray, item, RC_INVALID_ID, hit);
                    else
                        found |= instance_intersect(&scene->insts[item - scene->geom_count],
                                                    item - scene->geom_count, ray, hit);
                }
            }
        }
        if (sp == 0) break;
        ni = stack[--sp];
    }
    return found;
}

#if defined(RC__PACKET_MESHES)
/* A packet through a scene of many meshes (rc__scene_intersect_packet): the
 * top-level tree walked once for the whole packet.
 * packet_span: what a packet's rays span, per axis the range of their
 * origins and of their inverse directions, and the farthest hit so far.
 * packet_span_box_hit: 0 only when no ray of the span can pass box_hit
 * against the box: each ray's slab distances lie between the extremes of
 * the interval products (float rounding is monotone, so this holds for the
 * rounded values box_hit computes too). An axis whose inverse directions
 * change sign, or whose products are undefined (0 * inf), constrains
 * nothing. */
#if defined(__SSE2__)
/* Four lanes wide (x, y, z and one unused), the same products and
 * comparisons as the plain C below, so the same answers: the walk and its
 * spans were 16.6% of a VLP-16's instructions among 65 meshes, 6.8% so
 * (session 42). The fourth lane loads the float after each triple (a ray's
 * dir[0] or kx, a node's index or count) and is never used. */
/* The four floats at byte `at` of the struct at p (the fourth the field
 * after a triple), read through the struct's address rather than the
 * triple's, whose three floats the load passes. */
static RC__FORCE_INLINE __m128 load_after(const void *p, size_t at)
{
    return _mm_loadu_ps((const float *)(const void *)((const char *)p + at));
}

typedef struct packet_span {
    __m128 org_lo, org_hi, inv_lo, inv_hi;
    __m128 free_axes; /* all ones on an axis that constrains nothing, and lane 3 */
    float tmax;
    int one_origin; /* 1 when org_lo and org_hi are the same point */
} packet_span;

static void packet_span_of(const rc__ray *rays, uint32_t n, const rc__hit *hits, packet_span *s)
{
    const __m128 zero = _mm_setzero_ps();
    __m128 olo = load_after(&rays[0], offsetof(rc__ray, org)), ohi = olo;
    __m128 ilo = load_after(&rays[0], offsetof(rc__ray, inv_dir)), ihi = ilo;
    float tmax = hits[0].t;
    uint32_t i;
    for (i = 1; i < n; ++i) {
        const __m128 o = load_after(&rays[i], offsetof(rc__ray, org));
        const __m128 v = load_after(&rays[i], offsetof(rc__ray, inv_dir));
        olo = _mm_min_ps(olo, o);
        ohi = _mm_max_ps(ohi, o);
        ilo = _mm_min_ps(ilo, v);
        ihi = _mm_max_ps(ihi, v);
        if (hits[i].t > tmax) tmax = hits[i].t;
    }
    s->org_lo = olo;
    s->org_hi = ohi;
    s->inv_lo = ilo;
    s->inv_hi = ihi;
    /* inverse directions of both signs on an axis: it constrains nothing */
    s->free_axes = _mm_or_ps(_mm_andnot_ps(_mm_or_ps(_mm_cmpge_ps(ilo, zero), _mm_cmple_ps(ihi, zero)),
                                           _mm_castsi128_ps(_mm_set1_epi32(-1))),
                             _mm_castsi128_ps(_mm_set_epi32(-1, 0, 0, 0)));
    s->tmax = tmax;
    s->one_origin = (_mm_movemask_ps(_mm_cmpeq_ps(olo, ohi)) & 7) == 7;
}

static int packet_span_box_hit(const packet_span *s, const rc__bvh_node *nd)
{
    const __m128 lo_b = load_after(nd, offsetof(rc__bvh_node, bmin)), hi_b = load_after(nd, offsetof(rc__bvh_node, bmax));
    const __m128 inf = _mm_set1_ps(INFINITY);
    const __m128 d0 = _mm_sub_ps(lo_b, s->org_hi), d2 = _mm_sub_ps(hi_b, s->org_hi);
    const __m128 p0 = _mm_mul_ps(d0, s->inv_lo), p1 = _mm_mul_ps(d0, s->inv_hi);
    const __m128 p4 = _mm_mul_ps(d2, s->inv_lo), p5 = _mm_mul_ps(d2, s->inv_hi);
    /* 0 * inf met on an axis: it constrains nothing */
    __m128 skip = _mm_or_ps(s->free_axes, _mm_or_ps(_mm_cmpunord_ps(p0, p1), _mm_cmpunord_ps(p4, p5)));
    __m128 lo = _mm_min_ps(_mm_min_ps(p0, p1), _mm_min_ps(p4, p5));
    __m128 hi = _mm_max_ps(_mm_max_ps(p0, p1), _mm_max_ps(p4, p5));
    if (!s->one_origin) {
        /* the products from the other end of the origins' range too (with
         * one origin they are the same values) */
        const __m128 d1 = _mm_sub_ps(lo_b, s->org_lo), d3 = _mm_sub_ps(hi_b, s->org_lo);
        const __m128 p2 = _mm_mul_ps(d1, s->inv_lo), p3 = _mm_mul_ps(d1, s->inv_hi);
        const __m128 p6 = _mm_mul_ps(d3, s->inv_lo), p7 = _mm_mul_ps(d3, s->inv_hi);
        skip = _mm_or_ps(skip, _mm_or_ps(_mm_cmpunord_ps(p2, p3), _mm_cmpunord_ps(p6, p7)));
        lo = _mm_min_ps(lo, _mm_min_ps(_mm_min_ps(p2, p3), _mm_min_ps(p6, p7)));
        hi = _mm_max_ps(hi, _mm_max_ps(_mm_max_ps(p2, p3), _mm_max_ps(p6, p7)));
    }
    lo = _mm_or_ps(_mm_andnot_ps(skip, lo), _mm_and_ps(skip, _mm_sub_ps(_mm_setzero_ps(), inf)));
    hi = _mm_or_ps(_mm_andnot_ps(skip, hi), _mm_and_ps(skip, inf));
    lo = _mm_max_ps(lo, _mm_movehl_ps(lo, lo));
    lo = _mm_max_ss(lo, _mm_shuffle_ps(lo, lo, 1));
    hi = _mm_min_ps(hi, _mm_movehl_ps(hi, hi));
    hi = _mm_min_ss(hi, _mm_shuffle_ps(hi, hi, 1));
    {
        const float t0 = _mm_cvtss_f32(lo), t1 = _mm_cvtss_f32(hi);
        return (t0 > 0.0f ? t0 : 0.0f) <= (t1 < s->tmax ? t1 : s->tmax) * RC__SLAB_FAR_SCALE;
    }
}
#else
typedef struct packet_span {
    float org_lo[3], org_hi[3], inv_lo[3], inv_hi[3], tmax;
} packet_span;

static void packet_span_of(const rc__ray *rays, uint32_t n, const rc__hit *hits, packet_span *s)
{
    uint32_t i, k;
    for (k = 0; k < 3; ++k) {
        s->org_lo[k] = s->org_hi[k] = rays[0].org[k];
        s->inv_lo[k] = s->inv_hi[k] = rays[0].inv_dir[k];
    }
    s->tmax = hits[0].t;
    for (i = 1; i < n; ++i) {
        for (k = 0; k < 3; ++k) {
            const float o = rays[i].org[k], v = rays[i].inv_dir[k];
            s->org_lo[k] = o < s->org_lo[k] ? o : s->org_lo[k];
            s->org_hi[k] = o > s->org_hi[k] ? o : s->org_hi[k];
            s->inv_lo[k] = v < s->inv_lo[k] ? v : s->inv_lo[k];
            s->inv_hi[k] = v > s->inv_hi[k] ? v : s->inv_hi[k];
        }
        if (hits[i].t > s->tmax) s->tmax = hits[i].t;
    }
}

static int packet_span_box_hit(const packet_span *s, const rc__bvh_node *nd)
{
    const float *bmin = nd->bmin, *bmax = nd->bmax;
    float t0 = 0.0f, t1 = s->tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        float d[4], lo, hi;
        int j, undefined = 0;
        if (!(s->inv_lo[k] >= 0.0f || s->inv_hi[k] <= 0.0f)) continue;
        d[0] = bmin[k] - s->org_hi[k];
        d[1] = bmin[k] - s->org_lo[k];
        d[2] = bmax[k] - s->org_hi[k];
        d[3] = bmax[k] - s->org_lo[k];
        lo = hi = d[0] * s->inv_lo[k];
        for (j = 0; j < 8; ++j) {
            const float p = d[j >> 1] * (j & 1 ? s->inv_hi[k] : s->inv_lo[k]);
            undefined |= p != p;
            lo = p < lo ? p : lo;
            hi = p > hi ? p : hi;
        }
        if (undefined) continue; /* 0 * inf met */
        if (lo > t0) t0 = lo;
        if (hi < t1) t1 = hi;
    }
    return t0 <= t1 * RC__SLAB_FAR_SCALE;
}
#endif

/* The span's farthest hit again, after some of its rays found nearer ones
 * (their origins and directions stay). */
static void packet_span_narrow(packet_span *s, const rc__hit *hits, uint32_t n)
{
    float tmax = hits[0].t;
    uint32_t i;
    for (i = 1; i < n; ++i)
        if (hits[i].t > tmax) tmax = hits[i].t;
    s->tmax = tmax;
}

/* The packet's rays as rows of lanes (lanes past n repeat ray 0), for
 * lanes_in_box: filled once a walk, when it first meets an instance. */
typedef struct lane_rows {
    float org[3][RC__PACKET_SIZE], inv[3][RC__PACKET_SIZE];
    int finite; /* 1 when no inverse direction is infinite: no 0 * inf */
} lane_rows;

static void lane_rows_fill(lane_rows *lr, const rc__ray *rays, uint32_t n)
{
#if defined(__SSE2__) || defined(RC__LANES_IN_BOX_NEON)
    uint32_t i, k;
    lr->finite = 1;
    for (i = 0; i < RC__PACKET_SIZE; ++i) {
        const rc__ray *r = &rays[i < n ? i : 0];
        for (k = 0; k < 3; ++k) {
            lr->org[k][i] = r->org[k];
            lr->inv[k][i] = r->inv_dir[k];
            lr->finite &= fabsf(r->inv_dir[k]) <= FLT_MAX;
        }
    }
#else
    /* (lanes_in_box tests ray by ray: no rows) */
    (void)lr, (void)rays, (void)n;
#endif
}

#if defined(__SSE2__)
/* box_hit's operations four lanes at a time: its selects are minps
 * (a < b ? a : b) and maxps with the operands swapped (b > a ? b : a), its
 * updates of t0 and t1 maxps and minps, so the answers are the same. NEON
 * takes SSE2's min and max (neon_ops.h). */
typedef __m128 lanes_f;
typedef __m128 lanes_m;
#define LANES_LOAD(p) _mm_loadu_ps(p)
#define LANES_SET1(x) _mm_set1_ps(x)
#define LANES_SUB(a, b) _mm_sub_ps(a, b)
#define LANES_MUL(a, b) _mm_mul_ps(a, b)
#define LANES_MIN(a, b) _mm_min_ps(a, b)
#define LANES_MAX(a, b) _mm_max_ps(a, b)
#define LANES_LT(a, b) _mm_cmplt_ps(a, b)
#define LANES_GT(a, b) _mm_cmpgt_ps(a, b)
#define LANES_LE(a, b) _mm_cmple_ps(a, b)
#define LANES_UNORDERED(a, b) _mm_cmpunord_ps(a, b)
#define LANES_NONE() _mm_setzero_ps()
#define LANES_OR(m, k) _mm_or_ps(m, k)
#define LANES_AND(m, k) _mm_and_ps(m, k)
#define LANES_ANDNOT(m, k) _mm_andnot_ps(m, k) /* ~m & k */
#define LANES_SELECT(m, a, b) _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b))
#define LANES_BITS(m) ((uint32_t)_mm_movemask_ps(m))
#elif defined(RC__LANES_IN_BOX_NEON)
typedef float32x4_t lanes_f;
typedef uint32x4_t lanes_m;
#define LANES_LOAD(p) vld1q_f32(p)
#define LANES_SET1(x) vdupq_n_f32(x)
#define LANES_SUB(a, b) vsubq_f32(a, b)
#define LANES_MUL(a, b) vmulq_f32(a, b)
#define LANES_MIN(a, b) rc__neon_min_sse(a, b)
#define LANES_MAX(a, b) rc__neon_max_sse(a, b)
#define LANES_LT(a, b) vcltq_f32(a, b)
#define LANES_GT(a, b) vcgtq_f32(a, b)
#define LANES_LE(a, b) vcleq_f32(a, b)
#define LANES_UNORDERED(a, b) vmvnq_u32(vandq_u32(vceqq_f32(a, a), vceqq_f32(b, b)))
#define LANES_NONE() vdupq_n_u32(0u)
#define LANES_OR(m, k) vorrq_u32(m, k)
#define LANES_AND(m, k) vandq_u32(m, k)
#define LANES_ANDNOT(m, k) vbicq_u32(k, m) /* ~m & k */
#define LANES_SELECT(m, a, b) vbslq_f32(m, a, b)
#define LANES_BITS(m) rc__neon_bits(m)
#endif

/* The lanes of the packet (rays[0 .. n), at most RC__PACKET_SIZE, as rows
 * lr) whose own ray passes box_hit against nd's box within its hit so far:
 * the same test the single-ray walk gives each ray before an instance, so
 * a lane left out could not have found a hit there. A VLP-16 among 64
 * instanced balls (session 43): 46% of the lanes of a packet that meets an
 * instance's box meet it themselves, and 35% of those meetings have none. */
static uint32_t lanes_in_box(const lane_rows *lr, const rc__ray *rays, const rc__hit *hits, uint32_t n,
                             const rc__bvh_node *nd)
{
    uint32_t out = 0, g;
#if defined(LANES_LOAD)
    const lanes_f scale = LANES_SET1(RC__SLAB_FAR_SCALE);
    float tmax[RC__PACKET_SIZE];
    (void)rays;
    for (g = 0; g < n; ++g) tmax[g] = hits[g].t;
    for (; g < RC__PACKET_SIZE; ++g) tmax[g] = -1.0f; /* lanes past n: never met */
    for (g = 0; g < n; g += 4u) {
        lanes_f t0 = LANES_SET1(0.0f), t1 = LANES_LOAD(tmax + g);
        lanes_m reject = LANES_NONE();
        uint32_t k;
        for (k = 0; k < 3u; ++k) {
            const lanes_f o = LANES_LOAD(lr->org[k] + g), iv = LANES_LOAD(lr->inv[k] + g);
            const lanes_f bmin = LANES_SET1(nd->bmin[k]), bmax = LANES_SET1(nd->bmax[k]);
            const lanes_f a = LANES_MUL(LANES_SUB(bmin, o), iv), b = LANES_MUL(LANES_SUB(bmax, o), iv);
            const lanes_f lo = LANES_MIN(a, b), hi = LANES_MAX(b, a);
            if (lr->finite) { /* (a constant over the loop) */
                t0 = LANES_MAX(lo, t0);
                t1 = LANES_MIN(hi, t1);
            } else {
                /* 0 * inf: the origin on the slab's plane, the ray parallel
                 * to it; outside the slab it misses, inside this axis
                 * imposes nothing */
                const lanes_m nan = LANES_UNORDERED(a, b);
                reject = LANES_OR(reject, LANES_AND(nan, LANES_OR(LANES_LT(o, bmin), LANES_GT(o, bmax))));
                t0 = LANES_SELECT(nan, t0, LANES_MAX(lo, t0));
                t1 = LANES_SELECT(nan, t1, LANES_MIN(hi, t1));
            }
        }
        out |= LANES_BITS(LANES_ANDNOT(reject, LANES_LE(t0, LANES_MUL(t1, scale)))) << g;
    }
#else
    (void)lr;
    for (g = 0; g < n; ++g) {
        float tn;
        out |= (uint32_t)box_hit(&rays[g], nd->bmin, nd->bmax, hits[g].t, &tn) << g;
    }
#endif
    return n >= 32u ? out : out & ((1u << n) - 1u);
}

/* A packet's lanes `live` (of rays[0 .. n)) through one instance: their
 * rays moved as instance_ray moves each (rays that share an origin still
 * share it, bit for bit), then through the source's meshes
 * RC__SCENE_PACKET_BATCH at a time. A shared origin is moved once and the
 * directions prepared four at a time (rc__rays_prepare_turned: instance_ray's
 * values; the preparation was 11% of a VLP-16's instructions among 64
 * instanced balls, session 42). Lanes not live sit out (copies of the live
 * lanes' hits go through instead); a lone lane goes through
 * instance_intersect. */
static void instance_intersect_packet(const rc__instance *in, uint32_t inst_id, const rc__ray *rays, uint32_t n,
                                      uint32_t live, rc__hit *hits, int *found, uint32_t flags)
{
    const rc_scene *src = in->source;
    rc__ray local[RC__PACKET_SIZE];
    rc__hit sub_hits[RC__PACKET_SIZE], *h = hits;
    int sub_found[RC__PACKET_SIZE], *f = found;
    uint32_t idx[RC__PACKET_SIZE];
    const rc__mesh *meshes[RC__SCENE_PACKET_BATCH];
    uint32_t geoms[RC__SCENE_PACKET_BATCH], i, g, count, m = 0;
    if (n > RC__PACKET_SIZE) { /* (a packet is at most that: not met) */
        for (i = 0; i < n; ++i) found[i] |= instance_intersect(in, inst_id, &rays[i], &hits[i]);
        return;
    }
    if (!(live & (live - 1u))) {
        const uint32_t lane = rc__lowest_bit(live);
        found[lane] |= instance_intersect(in, inst_id, &rays[lane], &hits[lane]);
        return;
    }
    for (; live; live &= live - 1u) idx[m++] = rc__lowest_bit(live);
    if (m < n) {
        for (i = 0; i < m; ++i) {
            sub_hits[i] = hits[idx[i]];
            sub_found[i] = 0;
        }
        h = sub_hits;
        f = sub_found;
    }
    if (flags & RC__PACKET_OWN_ORIGINS) {
        for (i = 0; i < m; ++i) instance_ray(in, &rays[idx[i]], &local[i]);
    } else {
        float o[3], dirs[3u * RC__PACKET_SIZE];
        rc__rot_apply_f(in->to_local.r, rays[0].org, o);
        o[0] += in->to_local.t[0];
        o[1] += in->to_local.t[1];
        o[2] += in->to_local.t[2];
        for (i = 0; i < m; ++i) memcpy(dirs + 3u * idx[i], rays[idx[i]].dir, sizeof rays[idx[i]].dir);
        rc__rays_prepare_turned(in->to_local.r, o, dirs, idx, m, local);
    }
    for (g = 0; g < src->geom_count; g += count) {
        for (count = 0; count < RC__SCENE_PACKET_BATCH && g + count < src->geom_count; ++count) {
            meshes[count] = &src->geoms[g + count].mesh;
            geoms[count] = g + count;
        }
        rc__mesh_intersect_packet_meshes(meshes, geoms, count, local, m, inst_id, h, f, flags);
    }
    if (m < n)
        for (i = 0; i < m; ++i) {
            hits[idx[i]] = sub_hits[i];
            found[idx[i]] |= sub_found[i];
        }
}

/* The walk of rc__scene_intersect_packet (instances 0: the own meshes) and
 * of rc__scene_intersect_packet_instances (instances 1) */
static void packet_walk(const rc_scene *scene, const rc__ray *rays, uint32_t n, uint32_t skip, rc__hit *hits,
                        int *found, uint32_t flags, int instances)
{
    uint32_t stack[RC__BVH_MAX_DEPTH + 1];
    const rc__mesh *batch[RC__SCENE_PACKET_BATCH];
    uint32_t batch_geoms[RC__SCENE_PACKET_BATCH];
    uint32_t sp = 0, ni = 0, count = 0;
    const rc__bvh *top = &scene->top;
    packet_span span;
    lane_rows rows;
    int rows_filled = 0;
    if (n == 0 || top->node_count == 0) return;
    packet_span_of(rays, n, hits, &span);
    for (;;) {
        const rc__bvh_node *nd = &top->nodes[ni];
        if (packet_span_box_hit(&span, nd)) {
            if (nd->count == 0) {
                stack[sp++] = nd->index + 1; /* depth is capped by the builder */
                ni = nd->index;
                continue;
            } else {
                uint32_t k;
                for (k = 0; k < nd->count; ++k) {
                    const uint32_t item = top->refs[nd->index + k];
                    if (instances) {
                        uint32_t live;
                        if (item < scene->geom_count) continue;
                        if (n > RC__PACKET_SIZE) { /* (a packet is at most that: not met) */
                            live = 0xFFFFFFFFu;
                        } else {
                            if (!rows_filled) {
                                lane_rows_fill(&rows, rays, n);
                                rows_filled = 1;
                            }
                            live = lanes_in_box(&rows, rays, hits, n, nd);
                            if (!live) continue;
                        }
                        instance_intersect_packet(&scene->insts[item - scene->geom_count], item - scene->geom_count,
                                                  rays, n, live, hits, found, flags);
                        packet_span_narrow(&span, hits, n);
                        continue;
                    }
                    if (item >= scene->geom_count || (item < 32u && ((skip >> item) & 1u))) continue;
                    batch[count] = &scene->geoms[item].mesh;
                    batch_geoms[count++] = item;
                    if (count == RC__SCENE_PACKET_BATCH) {
                        /* the hits found so far narrow the rest of the walk */
                        rc__mesh_intersect_packet_meshes(batch, batch_geoms, count, rays, n, RC_INVALID_ID, hits,
                                                         found, flags);
                        count = 0;
                        packet_span_narrow(&span, hits, n);
                    }
                }
            }
        }
        if (sp == 0) break;
        ni = stack[--sp];
    }
    if (count) rc__mesh_intersect_packet_meshes(batch, batch_geoms, count, rays, n, RC_INVALID_ID, hits, found, flags);
}

void rc__scene_intersect_packet(const rc_scene *scene, const rc__ray *rays, uint32_t n, uint32_t skip, rc__hit *hits,
                                int *found, uint32_t flags)
{
    packet_walk(scene, rays, n, skip, hits, found, flags, 0);
}

void rc__scene_intersect_packet_instances(const rc_scene *scene, const rc__ray *rays, uint32_t n, rc__hit *hits,
                                          int *found, uint32_t flags)
{
    packet_walk(scene, rays, n, 0u, hits, found, flags, 1);
}
#endif

/* The mesh of a hit and its instance transform (NULL without one). */
static const rc__mesh *hit_mesh(const rc_scene *scene, const rc__hit *hit, const rc__xformf **x)
{
    if (hit->inst == RC_INVALID_ID) {
        *x = NULL;
        return &scene->geoms[hit->geom].mesh;
    }
    *x = &scene->insts[hit->inst].to_world;
    return &scene->insts[hit->inst].source->geoms[hit->geom].mesh;
}

void rc__scene_hit_normal(const rc_scene *scene, const rc__hit *hit, float n[3])
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    float local[3];
    double len;
    rc__mesh_triangle_normal(mesh, hit->prim, local);
    if (x) {
        rc__rot_apply_f(scene->insts[hit->inst].normal_to_world, local, n);
    } else {
        n[0] = local[0];
        n[1] = local[1];
        n[2] = local[2];
    }
    len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (len > 0.0) {
        n[0] = (float)(n[0] / len);
        n[1] = (float)(n[1] / len);
        n[2] = (float)(n[2] / len);
    }
}

/* The hit triangle's vertex indices: the leaf-ordered copy was just read by
 * the built-in triangle test (cached); the mesh's own index array is a miss on
 * a large map. */
static const uint32_t *hit_triangle(const rc__mesh *mesh, const rc__hit *hit)
{
    return hit->slot != RC_INVALID_ID && mesh->leaf_tris ? mesh->leaf_tris + (size_t)3 * hit->slot
                                                         : mesh->indices + (size_t)3 * hit->prim;
}

/* r * (px, py, pz) in double, r row-major 3x3 (force-inlined: the results
 * stay in registers). */
static RC__FORCE_INLINE void rot_d(const double r[9], double px, double py, double pz, double *x, double *y,
                                   double *z)
{
    *x = r[0] * px + r[1] * py + r[2] * pz;
    *y = r[3] * px + r[4] * py + r[5] * pz;
    *z = r[6] * px + r[7] * py + r[8] * pz;
}

/* How far (a fraction of the traversal's t) the refinement takes a hit
 * without checking the crossing against the triangle
 * (rc__scene_hit_distance_d; the lanes of hit_distance_lanes.h leave
 * further ones to it) */
#define RC__REFINE_NEAR (1.0 / 4096.0)

/* Written with scalar locals, not arrays: gcc pairs array elements into
 * 16-byte loads of values it had just stored 8 bytes at a time, and the CPU
 * cannot forward two stores into one load (a stall of a dozen cycles or
 * more, which made this function 18% of the time on a 1k map). */
double rc__scene_hit_distance_d(const rc_scene *scene, const rc__hit *hit, const rc__xformf *world,
                                const float dir_s[3], const float *org_s)
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    const uint32_t *tri = hit_triangle(mesh, hit);
    const float *p0 = mesh->vertices + (size_t)tri[0] * mesh->stride;
    const float *p1 = mesh->vertices + (size_t)tri[1] * mesh->stride;
    const float *p2 = mesh->vertices + (size_t)tri[2] * mesh->stride;
    double dx, dy, dz, ox = world->td[0], oy = world->td[1], oz = world->td[2];
    double ax, ay, az, bx, by, bz, cx, cy, cz, e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz, dn, w;
    /* the ray in the scene frame, in double */
    rot_d(world->rd, dir_s[0], dir_s[1], dir_s[2], &dx, &dy, &dz);
    if (org_s) {
        double px, py, pz;
        rot_d(world->rd, org_s[0], org_s[1], org_s[2], &px, &py, &pz);
        ox += px, oy += py, oz += pz;
    }
    if (x) {
        rot_d(x->rd, p0[0], p0[1], p0[2], &ax, &ay, &az);
        rot_d(x->rd, p1[0], p1[1], p1[2], &bx, &by, &bz);
        rot_d(x->rd, p2[0], p2[1], p2[2], &cx, &cy, &cz);
        ax += x->td[0], ay += x->td[1], az += x->td[2];
        bx += x->td[0], by += x->td[1], bz += x->td[2];
        cx += x->td[0], cy += x->td[1], cz += x->td[2];
    } else {
        ax = p0[0], ay = p0[1], az = p0[2];
        bx = p1[0], by = p1[1], bz = p1[2];
        cx = p2[0], cy = p2[1], cz = p2[2];
    }
    e1x = bx - ax, e1y = by - ay, e1z = bz - az;
    e2x = cx - ax, e2y = cy - ay, e2z = cz - az;
    nx = e1y * e2z - e1z * e2y;
    ny = e1z * e2x - e1x * e2z;
    nz = e1x * e2y - e1y * e2x;
    dn = nx * dx + ny * dy + nz * dz;
    w = nx * (ax - ox) + ny * (ay - oy) + nz * (az - oz);
    /* a ray parallel to the plane keeps the traversal's t */
    if (dn == 0.0 || !isfinite(w / dn)) return hit->t;
    {
        /* Rounding moves a hit's t by a few ulps, some hundreds for needles
         * or rays moved through far instances: a crossing that near is the
         * better distance (the lanes decide those alone). One further off
         * is checked against the triangle: a crossing on it lies between
         * its corners' depths along the ray, and so does the float test's t
         * (it weighs them), so within the spread of the other corners'
         * depths from corner a's (twice over, and the same 1/4096 of t for
         * rounding) the crossing is the better distance, grazing rays' too.
         * One further off is off the triangle: the ray runs along its
         * plane, and the float test found the hit by rounding. The
         * traversal's t stays then, as where the ray is parallel; the
         * crossing could be anywhere, even past the range max, which would
         * read as no return and hide the hit behind that the float hit
         * culled (fuzz_trace, session 44). */
        const double q = w / dn, t = hit->t, near = RC__REFINE_NEAR * t;
        return fabs(q - t) > near && fabs(q - (((ax - ox) * dx + (ay - oy) * dy) + (az - oz) * dz)) >
                                         2.0 * (fabs((e1x * dx + e1y * dy) + e1z * dz) +
                                                fabs((e2x * dx + e2y * dy) + e2z * dz)) +
                                             near
                   ? t
                   : q;
    }
}

#if defined(RC__HIT_DISTANCES_LANES)
#if defined(RC__HIT_DISTANCES_SSE2)
/* Hits refined two at a time in SSE2 doubles (hit_distance_lanes.h) */
#define RC__HD_NAME distance_lanes2
#define RC__HD_ATTR
#define RC__HD_W 2
#define RC__HD_T __m128d
#define RC__HD_SET1(x) _mm_set1_pd(x)
#define RC__HD_ADD(a, b) _mm_add_pd(a, b)
#define RC__HD_SUB(a, b) _mm_sub_pd(a, b)
#define RC__HD_MUL(a, b) _mm_mul_pd(a, b)
#define RC__HD_DIV(a, b) _mm_div_pd(a, b)
#define RC__HD_GATHER(p, k) _mm_setr_pd((double)(p)[0][k], (double)(p)[1][k])
/* NLT is true for NaN: a quotient not below inf is inf or NaN */
#define RC__HD_ODD(dn, q)                                                                                            \
    _mm_movemask_pd(_mm_or_pd(_mm_cmpeq_pd(dn, _mm_setzero_pd()),                                                   \
                              _mm_cmpnlt_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), q), _mm_set1_pd(INFINITY))))
#define RC__HD_FAR(q, t, c)                                                                                          \
    _mm_movemask_pd(_mm_cmpgt_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), _mm_sub_pd(q, t)), _mm_mul_pd(_mm_set1_pd(c), t)))
#define RC__HD_HIT_T(h, at) _mm_setr_pd((double)(h)[(at)[0]].t, (double)(h)[(at)[1]].t)
#define RC__HD_STORE(p, v) _mm_storeu_pd(p, v)
#include "scene/hit_distance_lanes.h"
#else
/* ... or in AArch64 NEON doubles: the same IEEE operations (the build turns
 * fused multiply-add off), so the same values */
#include <arm_neon.h>
#define RC__HD_NAME distance_lanes2
#define RC__HD_ATTR
#define RC__HD_W 2
#define RC__HD_T float64x2_t
#define RC__HD_SET1(x) vdupq_n_f64(x)
#define RC__HD_ADD(a, b) vaddq_f64(a, b)
#define RC__HD_SUB(a, b) vsubq_f64(a, b)
#define RC__HD_MUL(a, b) vmulq_f64(a, b)
#define RC__HD_DIV(a, b) vdivq_f64(a, b)
#define RC__HD_GATHER(p, k) vsetq_lane_f64((double)(p)[1][k], vdupq_n_f64((double)(p)[0][k]), 1)
/* not |q| < inf: inf or NaN */
#define RC__HD_ODD(dn, q) rc__hd_odd_neon(dn, q)
#define RC__HD_FAR(q, t, c) rc__hd_far_neon(q, t, c)
#define RC__HD_HIT_T(h, at) vsetq_lane_f64((double)(h)[(at)[1]].t, vdupq_n_f64((double)(h)[(at)[0]].t), 1)
#define RC__HD_STORE(p, v) vst1q_f64(p, v)
static inline int rc__hd_odd_neon(float64x2_t dn, float64x2_t q)
{
    const uint64x2_t odd = vorrq_u64(vceqq_f64(dn, vdupq_n_f64(0.0)),
                                     veorq_u64(vcltq_f64(vabsq_f64(q), vdupq_n_f64(INFINITY)), vdupq_n_u64(~0ull)));
    return (int)((vgetq_lane_u64(odd, 0) & 1u) | (vgetq_lane_u64(odd, 1) & 2u));
}
static inline int rc__hd_far_neon(float64x2_t q, float64x2_t t, double c)
{
    const uint64x2_t m = vcgtq_f64(vabsq_f64(vsubq_f64(q, t)), vmulq_f64(vdupq_n_f64(c), t));
    return (int)((vgetq_lane_u64(m, 0) & 1u) | (vgetq_lane_u64(m, 1) & 2u));
}
#include "scene/hit_distance_lanes.h"
#endif

#if defined(RC__LEAF4_PAIR_AVX2)
/* ... and four at a time in AVX doubles where the CPU has AVX2
 * (rc__leaf4_have_avx2; the target does not enable fused multiply-add) */
#define RC__HD_NAME distance_lanes4
#define RC__HD_ATTR __attribute__((target("avx2")))
#define RC__HD_W 4
#define RC__HD_T __m256d
#define RC__HD_SET1(x) _mm256_set1_pd(x)
#define RC__HD_ADD(a, b) _mm256_add_pd(a, b)
#define RC__HD_SUB(a, b) _mm256_sub_pd(a, b)
#define RC__HD_MUL(a, b) _mm256_mul_pd(a, b)
#define RC__HD_DIV(a, b) _mm256_div_pd(a, b)
#define RC__HD_GATHER(p, k) _mm256_cvtps_pd(_mm_setr_ps((p)[0][k], (p)[1][k], (p)[2][k], (p)[3][k]))
#define RC__HD_ODD(dn, q)                                                                                            \
    _mm256_movemask_pd(_mm256_or_pd(_mm256_cmp_pd(dn, _mm256_setzero_pd(), _CMP_EQ_OQ),                           \
                                    _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), q),                       \
                                                  _mm256_set1_pd(INFINITY), _CMP_NLT_UQ)))
#define RC__HD_FAR(q, t, c)                                                                                          \
    _mm256_movemask_pd(_mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), _mm256_sub_pd(q, t)),                  \
                                     _mm256_mul_pd(_mm256_set1_pd(c), t), _CMP_GT_OQ))
#define RC__HD_HIT_T(h, at)                                                                                          \
    _mm256_cvtps_pd(_mm_setr_ps((h)[(at)[0]].t, (h)[(at)[1]].t, (h)[(at)[2]].t, (h)[(at)[3]].t))
#define RC__HD_STORE(p, v) _mm256_storeu_pd(p, v)
#include "scene/hit_distance_lanes.h"
#endif

/* The vertices of hits[at[0 .. count)] (own meshes) and their sensor
 * directions */
typedef struct hit_group {
    const float *a[4], *b[4], *c[4], *dir[4];
} hit_group;

static RC__FORCE_INLINE void group_fill(const rc_scene *scene, const rc__hit *hits, const uint32_t *at, uint32_t count,
                                        const float *directions, const uint32_t *idx, hit_group *g)
{
    const rc__mesh *one = scene->geom_count == 1 ? &scene->geoms[0].mesh : NULL;
    uint32_t i, slots = 1;
    for (i = 0; i < count; ++i) {
        g->dir[i] = directions + (size_t)idx[at[i]] * 3u;
        slots &= hits[at[i]].slot != RC_INVALID_ID;
    }
    if (one && one->leaf_tris && slots) {
        /* one own mesh, every hit with its leaf slot (the built-in
         * backend's map): the mesh's fields read once, not once a hit */
        const float *vertices = one->vertices;
        const uint32_t *leaf_tris = one->leaf_tris;
        const size_t stride = one->stride;
        for (i = 0; i < count; ++i) {
            const uint32_t *tri = leaf_tris + (size_t)3 * hits[at[i]].slot;
            g->a[i] = vertices + (size_t)tri[0] * stride;
            g->b[i] = vertices + (size_t)tri[1] * stride;
            g->c[i] = vertices + (size_t)tri[2] * stride;
        }
        return;
    }
    for (i = 0; i < count; ++i) {
        const rc__hit *h = &hits[at[i]];
        const rc__mesh *m = &scene->geoms[h->geom].mesh;
        const uint32_t *tri = hit_triangle(m, h);
        g->a[i] = m->vertices + (size_t)tri[0] * m->stride;
        g->b[i] = m->vertices + (size_t)tri[1] * m->stride;
        g->c[i] = m->vertices + (size_t)tri[2] * m->stride;
    }
}

/* The lanes far (bits of at[]) whose quotient lies further from the
 * traversal's t than the lanes decide (hit_distance_lanes.h), one by one */
static void refine_far(const rc_scene *scene, const rc__hit *hits, const uint32_t *at, int far, const rc__xformf *world,
                       const float *directions, const uint32_t *idx, double *td)
{
    for (; far; far &= far - 1) {
        const uint32_t i = at[rc__lowest_bit((uint32_t)far)];
        td[i] = rc__scene_hit_distance_d(scene, &hits[i], world, directions + (size_t)idx[i] * 3u, NULL);
    }
}

/* rc__scene_hit_distance_d of hits at[0], at[1] */
static void refine_two(const rc_scene *scene, const rc__hit *hits, const uint32_t *at, const rc__xformf *world,
                       const float *directions, const uint32_t *idx, double *td)
{
    hit_group g;
    int far;
    group_fill(scene, hits, at, 2u, directions, idx, &g);
    far = distance_lanes2(g.a, g.b, g.c, g.dir, world, hits, at, td);
    if (RC__UNLIKELY(far)) refine_far(scene, hits, at, far, world, directions, idx, td);
}

/* rc__scene_hit_distance_d of two instances' hits at[0], at[1] in two
 * lanes of doubles (SSE2, or NEON on AArch64: CPUs without AVX2 and ARM
 * boards): each hit's corners turned by its instance's to_world, lane by
 * lane rot_d's operations and the translation in their order, then
 * distance_lanes2's: the same values. */
#if defined(RC__HIT_DISTANCES_SSE2)
#define RC__D2 __m128d
#define RC__D2_OF(a, b) _mm_setr_pd(a, b)
#define RC__D2_ADD(a, b) _mm_add_pd(a, b)
#define RC__D2_MUL(a, b) _mm_mul_pd(a, b)
#else
#define RC__D2 float64x2_t
#define RC__D2_OF(a, b) vsetq_lane_f64(b, vdupq_n_f64(a), 1)
#define RC__D2_ADD(a, b) vaddq_f64(a, b)
#define RC__D2_MUL(a, b) vmulq_f64(a, b)
#endif
static void refine_two_instanced(const rc_scene *scene, const rc__hit *hits, const uint32_t *at,
                                 const rc__xformf *world, const float *directions, const uint32_t *idx, double *td)
{
    const float *p[2][3], *dir[2];
    const double *r[2], *t[2];
    RC__D2 q[3][3];
    uint32_t i, c, k;
    int far;
    for (i = 0; i < 2u; ++i) {
        const rc__xformf *x;
        const rc__mesh *mesh = hit_mesh(scene, &hits[at[i]], &x);
        const uint32_t *tri = hit_triangle(mesh, &hits[at[i]]);
        for (c = 0; c < 3u; ++c) p[i][c] = mesh->vertices + (size_t)tri[c] * mesh->stride;
        dir[i] = directions + (size_t)idx[at[i]] * 3u;
        r[i] = x->rd;
        t[i] = x->td;
    }
    /* q[c][k]: coordinate k of corner c in the scene's frame */
    for (c = 0; c < 3u; ++c)
        for (k = 0; k < 3u; ++k)
            q[c][k] = RC__D2_ADD(
                RC__D2_ADD(RC__D2_ADD(RC__D2_MUL(RC__D2_OF(r[0][3u * k], r[1][3u * k]),
                                                 RC__D2_OF((double)p[0][c][0], (double)p[1][c][0])),
                                      RC__D2_MUL(RC__D2_OF(r[0][3u * k + 1u], r[1][3u * k + 1u]),
                                                 RC__D2_OF((double)p[0][c][1], (double)p[1][c][1]))),
                           RC__D2_MUL(RC__D2_OF(r[0][3u * k + 2u], r[1][3u * k + 2u]),
                                      RC__D2_OF((double)p[0][c][2], (double)p[1][c][2]))),
                RC__D2_OF(t[0][k], t[1][k]));
    far = distance_lanes2_corners(RC__D2_OF((double)dir[0][0], (double)dir[1][0]),
                                  RC__D2_OF((double)dir[0][1], (double)dir[1][1]),
                                  RC__D2_OF((double)dir[0][2], (double)dir[1][2]), q[0][0], q[0][1], q[0][2], q[1][0],
                                  q[1][1], q[1][2], q[2][0], q[2][1], q[2][2], world, hits, at, td);
    if (RC__UNLIKELY(far)) refine_far(scene, hits, at, far, world, directions, idx, td);
}
#undef RC__D2
#undef RC__D2_OF
#undef RC__D2_ADD
#undef RC__D2_MUL

#if defined(RC__LEAF4_PAIR_AVX2)
/* The three floats at p as a row (x, y, z, 0): the fourth element is masked
 * out, so the load never reaches past the end of the array (a masked-out
 * element cannot fault) */
static RC__FORCE_INLINE __attribute__((target("avx2"))) __m128 row3(const float *p)
{
    return _mm_maskload_ps(p, _mm_setr_epi32(-1, -1, -1, 0));
}

/* Columns x, y, z of the rows r0 .. r3, widened to doubles */
static RC__FORCE_INLINE __attribute__((target("avx2"))) void columns4(__m128 r0, __m128 r1, __m128 r2, __m128 r3,
                                                                      __m256d *x, __m256d *y, __m256d *z)
{
    const __m128 t0 = _mm_unpacklo_ps(r0, r1), t1 = _mm_unpacklo_ps(r2, r3);
    const __m128 t2 = _mm_unpackhi_ps(r0, r1), t3 = _mm_unpackhi_ps(r2, r3);
    *x = _mm256_cvtps_pd(_mm_movelh_ps(t0, t1));
    *y = _mm256_cvtps_pd(_mm_movehl_ps(t1, t0));
    *z = _mm256_cvtps_pd(_mm_movelh_ps(t2, t3));
}

/* refine_four for hits of one own mesh with leaf-ordered triangles, each
 * with its leaf slot (the built-in backend's map): each corner and direction
 * read as one row and the rows transposed. group_fill's sixteen pointers
 * went through the stack and were read three times each (100k sphere: 322
 * instructions a call). The values are distance_lanes4's: the same
 * operations on the same coordinates. */
static RC__FORCE_INLINE __attribute__((target("avx2"))) int refine_four_rows(const rc__mesh *const mesh[4],
                                                                              const rc__hit *hits, const uint32_t *at,
                                                                              const rc__xformf *world,
                                                                              const float *directions,
                                                                              const uint32_t *idx, double *td)
{
    __m128 ra[4], rb[4], rc[4], rd[4];
    __m256d px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz;
    uint32_t i;
    for (i = 0; i < 4u; ++i) {
        const uint32_t *tri = mesh[i]->leaf_tris + (size_t)3 * hits[at[i]].slot;
        const float *const v = mesh[i]->vertices;
        const size_t stride = mesh[i]->stride;
        ra[i] = row3(v + tri[0] * stride);
        rb[i] = row3(v + tri[1] * stride);
        rc[i] = row3(v + tri[2] * stride);
        rd[i] = row3(directions + (size_t)idx[at[i]] * 3u);
    }
    columns4(rd[0], rd[1], rd[2], rd[3], &px, &py, &pz);
    columns4(ra[0], ra[1], ra[2], ra[3], &ax, &ay, &az);
    columns4(rb[0], rb[1], rb[2], rb[3], &bx, &by, &bz);
    columns4(rc[0], rc[1], rc[2], rc[3], &cx, &cy, &cz);
    return distance_lanes4_corners(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz, world, hits, at, td);
}

/* The 4 x 4 doubles rows r0 .. r3 as columns (c[j] lane i = r_i[j]) */
static RC__FORCE_INLINE __attribute__((target("avx2"))) void transpose4d(__m256d r0, __m256d r1, __m256d r2,
                                                                         __m256d r3, __m256d c[4])
{
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    c[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    c[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    c[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    c[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/* rc__scene_hit_distance_d of four instances' hits at[0 .. 4), in AVX
 * doubles: each hit's corners turned by its instance's to_world (its rd and
 * td read as three rows of four doubles, rd[8] and td adjacent, and
 * transposed), lane by lane rot_d's operations and the translation in their
 * order, then distance_lanes4's: the same values. One at a time they were
 * 9% of a VLP-16's instructions among 64 instanced balls (session 43). */
static __attribute__((target("avx2"))) void refine_four_instanced(const rc_scene *scene, const rc__hit *hits,
                                                                  const uint32_t *at, const rc__xformf *world,
                                                                  const float *directions, const uint32_t *idx,
                                                                  double *td)
{
    __m128 ra[4], rb[4], rc[4], rd[4];
    __m256d q[4][3], m[12], px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz;
    uint32_t i;
    int far;
    for (i = 0; i < 4u; ++i) {
        const rc__hit *h = &hits[at[i]];
        const rc__xformf *x;
        const rc__mesh *mesh = hit_mesh(scene, h, &x);
        const uint32_t *tri = hit_triangle(mesh, h);
        const float *const v = mesh->vertices;
        const size_t stride = mesh->stride;
        ra[i] = row3(v + tri[0] * stride);
        rb[i] = row3(v + tri[1] * stride);
        rc[i] = row3(v + tri[2] * stride);
        rd[i] = row3(directions + (size_t)idx[at[i]] * 3u);
        q[i][0] = _mm256_loadu_pd(x->rd);
        q[i][1] = _mm256_loadu_pd(x->rd + 4);
        q[i][2] = _mm256_loadu_pd(x->rd + 8); /* rd[8], td[0 .. 2] */
    }
    transpose4d(q[0][0], q[1][0], q[2][0], q[3][0], m);
    transpose4d(q[0][1], q[1][1], q[2][1], q[3][1], m + 4);
    transpose4d(q[0][2], q[1][2], q[2][2], q[3][2], m + 8);
    columns4(rd[0], rd[1], rd[2], rd[3], &px, &py, &pz);
    columns4(ra[0], ra[1], ra[2], ra[3], &ax, &ay, &az);
    columns4(rb[0], rb[1], rb[2], rb[3], &bx, &by, &bz);
    columns4(rc[0], rc[1], rc[2], rc[3], &cx, &cy, &cz);
    /* m[0 .. 8] the lanes' rd, m[9 .. 11] their td */
#define RC__TURN(px_, py_, pz_, k)                                                                                 \
    _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m[3 * (k)], px_), _mm256_mul_pd(m[3 * (k) + 1], py_)), \
                                _mm256_mul_pd(m[3 * (k) + 2], pz_)),                                               \
                  m[9 + (k)])
    far = distance_lanes4_corners(px, py, pz, RC__TURN(ax, ay, az, 0), RC__TURN(ax, ay, az, 1),
                                  RC__TURN(ax, ay, az, 2), RC__TURN(bx, by, bz, 0), RC__TURN(bx, by, bz, 1),
                                  RC__TURN(bx, by, bz, 2), RC__TURN(cx, cy, cz, 0), RC__TURN(cx, cy, cz, 1),
                                  RC__TURN(cx, cy, cz, 2), world, hits, at, td);
    if (RC__UNLIKELY(far)) refine_far(scene, hits, at, far, world, directions, idx, td);
#undef RC__TURN
}

/* rc__scene_hit_distances_d for a one-mesh scene without instances whose
 * mesh has leaf-ordered triangles: its found rays four at a time in rows,
 * the last few one at a time. 0 (td then partly written) when a found hit
 * has no leaf slot (not the built-in traversal's): the caller starts over. */
static __attribute__((target("avx2"))) int refine_rows_tile(const rc_scene *scene, const rc__hit *hits,
                                                           const int *found, uint32_t n, const rc__xformf *world,
                                                           const float *directions, const uint32_t *idx, double *td)
{
    const rc__mesh *one = &scene->geoms[0].mesh;
    const rc__mesh *const meshes[4] = {one, one, one, one};
    uint32_t own[4], k = 0, i;
    int far;
    for (i = 0; i < n; ++i) {
        td[i] = 0.0;
        own[k] = i;
        k += found[i] != 0;
        if (k < 4u) continue;
        if ((hits[own[0]].slot == RC_INVALID_ID) | (hits[own[1]].slot == RC_INVALID_ID) |
            (hits[own[2]].slot == RC_INVALID_ID) | (hits[own[3]].slot == RC_INVALID_ID))
            return 0;
        far = refine_four_rows(meshes, hits, own, world, directions, idx, td);
        if (RC__UNLIKELY(far)) refine_far(scene, hits, own, far, world, directions, idx, td);
        k = 0;
    }
    for (i = 0; i < k; ++i)
        td[own[i]] = rc__scene_hit_distance_d(scene, &hits[own[i]], world, directions + (size_t)idx[own[i]] * 3u, NULL);
    return 1;
}

/* ... of hits at[0 .. 4), all of it in VEX encoding: from rows where each
 * hit's own mesh has leaf-ordered triangles and the hit its slot (a scene
 * of several meshes through the built-in backend; a VLP-16 among 65 meshes
 * -0.8% of its instructions, session 42) */
static __attribute__((target("avx2"))) void refine_four(const rc_scene *scene, const rc__hit *hits,
                                                       const uint32_t *at, const rc__xformf *world,
                                                       const float *directions, const uint32_t *idx, double *td)
{
    const rc__mesh *meshes[4];
    uint32_t i, rows = 1;
    int far;
    hit_group g;
    for (i = 0; i < 4u; ++i) {
        meshes[i] = &scene->geoms[hits[at[i]].geom].mesh;
        rows &= (meshes[i]->leaf_tris != NULL) & (hits[at[i]].slot != RC_INVALID_ID);
    }
    if (rows) {
        far = refine_four_rows(meshes, hits, at, world, directions, idx, td);
    } else {
        group_fill(scene, hits, at, 4u, directions, idx, &g);
        far = distance_lanes4(g.a, g.b, g.c, g.dir, world, hits, at, td);
    }
    if (RC__UNLIKELY(far)) refine_far(scene, hits, at, far, world, directions, idx, td);
}
#endif

/* One group of hits refined together: four where the CPU has AVX2 (size 4),
 * else two; instanced picks the instances' kind (each hit moved into its
 * instance's frame). */
static RC__FORCE_INLINE void refine_group(const rc_scene *scene, int instanced, uint32_t size, const rc__hit *hits,
                                          const uint32_t *at, const rc__xformf *world, const float *directions,
                                          const uint32_t *idx, double *td)
{
#if defined(RC__LEAF4_PAIR_AVX2)
    if (size == 4u) {
        if (instanced)
            refine_four_instanced(scene, hits, at, world, directions, idx, td);
        else
            refine_four(scene, hits, at, world, directions, idx, td);
        return;
    }
#endif
    (void)size;
    if (instanced)
        refine_two_instanced(scene, hits, at, world, directions, idx, td);
    else
        refine_two(scene, hits, at, world, directions, idx, td);
}

/* The last count (< 4) hits of a kind: in pairs, then one alone. */
static void refine_rest(const rc_scene *scene, int instanced, const rc__hit *hits, const uint32_t *at, uint32_t count,
                        const rc__xformf *world, const float *directions, const uint32_t *idx, double *td)
{
    uint32_t i;
    for (i = 0; i + 1u < count; i += 2u) refine_group(scene, instanced, 2u, hits, at + i, world, directions, idx, td);
    if (count & 1u)
        td[at[i]] = rc__scene_hit_distance_d(scene, &hits[at[i]], world, directions + (size_t)idx[at[i]] * 3u, NULL);
}

void rc__scene_hit_distances_d(const rc_scene *scene, const rc__hit *hits, const int *found, uint32_t n,
                               const rc__xformf *world, const float *directions, const uint32_t *idx, double *td)
{
    /* own-mesh and instances' hits wait in own[] and inst[] for a group of
     * lanes: four where the CPU has AVX2, else two; the last ones go in
     * pairs and alone (every path gives the scalar function's values). Two
     * arrays and counters, not one indexed by the kind: the counters stay
     * in registers (an indexed pair cost 28% more instructions here). */
    uint32_t own[4], inst[4], k = 0, ki = 0, group = 2u, i;
#if defined(RC__LEAF4_PAIR_AVX2)
    if (rc__leaf4_have_avx2()) {
        group = 4u;
        /* one own mesh, no instances (the built-in backend's map): rows */
        if (scene->geom_count == 1 && scene->inst_count == 0 && scene->geoms[0].mesh.leaf_tris &&
            refine_rows_tile(scene, hits, found, n, world, directions, idx, td))
            return;
    }
#endif
    for (i = 0; i < n; ++i) {
        if (!found[i]) {
            td[i] = 0.0;
        } else if (hits[i].inst != RC_INVALID_ID) {
            inst[ki++] = i;
            if (ki < group) continue;
            refine_group(scene, 1, group, hits, inst, world, directions, idx, td);
            ki = 0;
        } else {
            own[k++] = i;
            if (k < group) continue;
            refine_group(scene, 0, group, hits, own, world, directions, idx, td);
            k = 0;
        }
    }
    refine_rest(scene, 1, hits, inst, ki, world, directions, idx, td);
    refine_rest(scene, 0, hits, own, k, world, directions, idx, td);
}
#endif
