/* Single-ray nearest-hit and any-hit traversal of the 4-wide BVH (wide.h).
 *
 * Each step fetches one node and meets the ray with its four child boxes at
 * once: SSE2 on x86-64, NEON on ARM, a plain loop elsewhere (or with
 * RC__WIDE_FORCE_SCALAR, for tests and instruction counts). The slab test is
 * the robust one of intersect.h lane by lane, so the wide and binary trees
 * cull exactly as conservatively: both test the triangles that can matter
 * with the same watertight test and tie rule, and give the same hit, bit for
 * bit. Children met are visited nearest first; the others wait on a stack
 * with their entry distance and are dropped once a nearer hit is known. */
#include "bvh/mesh.h"

#include "bvh/intersect.h"
#include "bvh/leaf4.h"
#include "bvh/wide_box.h"
#include "core/common.h"

/* Three pushes per level at most, over at most RC__BVH_MAX_DEPTH levels. */
#define STACK_SIZE (3u * RC__BVH_MAX_DEPTH + 4u)

/* Per-ray constants: origin, reciprocal direction, and which plane row
 * (0..5) of a node each axis enters by. (Keeping them splatted in memory
 * measured 15% slower than splatting per node: the compiler keeps these in
 * registers.) */
typedef struct wide_ray {
    float org[3];
    float inv[3];
    uint32_t near_row[3];
} wide_ray;

static void wide_ray_init(wide_ray *w, const rc__ray *r)
{
    int k;
    for (k = 0; k < 3; ++k) {
        w->org[k] = r->org[k];
        w->inv[k] = r->inv_dir[k];
        /* -0 counts as negative, as in rc__slab_ray_init */
        w->near_row[k] = 2u * (uint32_t)k + (r->inv_dir[k] < 0.0f ? 1u : 0u);
    }
}

/* Index of the lowest set bit (mask != 0). A loop on purpose: masks are
 * mostly 1 and the loop's branch predicts well; __builtin_ctz measured 10%
 * slower over the whole traversal (gcc 12, x86-64). */
static RC__FORCE_INLINE uint32_t lowest_bit(uint32_t mask)
{
    uint32_t c = 0;
    while (!((mask >> c) & 1u)) ++c;
    return c;
}

/* Bit c set when the ray meets child c's box within [0, tmax]
 * (conservatively, Ize's bound); tn[c] gets the entry distance. */
static RC__FORCE_INLINE uint32_t wide_box_test(const rc__wnode *n, const wide_ray *w, float tmax, float tn[4])
{
    return rc__wide_box_test(n, w->near_row, w->org, w->inv, tmax, tn);
}

static RC__FORCE_INLINE int wide_traverse(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst,
                                     rc__hit *hit, float tmax, int any_hit)
{
    const rc__wnode *nodes = mesh->wide;
    const uint32_t *refs = mesh->bvh.refs;
    const uint32_t *leaf_tris = mesh->leaf_tris;
    const uint32_t flats_known = mesh->flats_folded ? 0xFu : 0u; /* leaf4.h: rc__leaf4_take */
    const float *vertices = mesh->vertices;
    const size_t stride = mesh->stride;
    const rc__ray r = *ray;
    wide_ray w;
    rc__wide_entry stack[STACK_SIZE + 4u]; /* room for one node's children past the end */
    uint32_t sp = 0, child = 0, count = 0;
    float tcur = tmax;
    int found = 0;

    if (mesh->wide_count == 0) return 0;
    wide_ray_init(&w, &r);
    for (;;) {
        if (count == 0) {
            const rc__wnode *n = &nodes[child];
            float tn[4] RC__ALIGN16;
            uint32_t mask = wide_box_test(n, &w, tcur, tn);
            if (mask == 0) goto pop;
            {
                uint32_t c = lowest_bit(mask);
                mask &= mask - 1u;
                if (mask == 0) { /* one child met: no ordering, no push */
                    child = n->child[c];
                    count = n->count[c];
                    continue;
                }
                {
                    /* two to four met: sorted by entry distance straight
                     * onto the stack, farthest first; the nearest, on top,
                     * is visited next */
                    rc__wide_entry *const e = stack + sp;
                    uint32_t m = rc__wide_add_sorted(e, 0, n, c, tn);
                    while (mask) {
                        c = lowest_bit(mask);
                        mask &= mask - 1u;
                        m = rc__wide_add_sorted(e, m, n, c, tn);
                    }
                    child = e[m - 1].child;
                    count = e[m - 1].count;
                    /* the builder caps depth so the pushes fit; a corrupt
                     * tree loses its nearest branches instead of the stack
                     * (which has room for one node's children past its end) */
                    sp += m - 1u;
                    if (RC__UNLIKELY(sp > STACK_SIZE)) sp = STACK_SIZE;
                    continue;
                }
            }
        } else {
            const float *vt[4][3];
            rc__leaf4_out lo;
            uint32_t cand, known = flats_known, flat = 0;
            count = rc__leaf4_vertices(leaf_tris, vertices, stride, child, count, vt);
            rc__leaf4_test(&r, (const float *const(*)[3])vt, count, &lo);
            cand = lo.hit | lo.redo;
            while (cand) {
                const uint32_t j = child + lowest_bit(cand);
                const float *const *tv = vt[j - child];
                float t;
                cand &= cand - 1u;
                if (!rc__leaf4_take(&lo, j - child, &r, tv, &known, &flat, &t)) continue;
                if (any_hit) {
                    if (t < tmax) return 1;
                    continue;
                }
                if (t > tcur || !rc__hit_offer_slot(hit, t, refs, j, geom, inst)) continue;
                tcur = t;
                found = 1;
            }
        }
    pop:
        for (;;) {
            if (sp == 0) {
                if (found) rc__hit_settle(hit, refs);
                return found;
            }
            --sp;
            /* with the box test's slack: a box whose entry distance rounds
             * just above t may still hold a triangle at t (a tie) */
            if (stack[sp].tnear <= tcur * RC__SLAB_FAR_SCALE) {
                child = stack[sp].child;
                count = stack[sp].count;
                break;
            }
        }
    }
}

#if defined(RC__LEAF4_PAIR_AVX2) && !defined(RC__WIDE_FORCE_SCALAR)
/* The same traversal in VEX encoding where the CPU has AVX2 (the same SSE2
 * operations, the same answers): three-operand forms drop the register
 * copies of the two-operand build. */
static __attribute__((target("avx2"))) int intersect_wide_vex(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom,
                                                             uint32_t inst, rc__hit *hit)
{
    return wide_traverse(mesh, ray, geom, inst, hit, hit->t, 0);
}
#endif

int rc__mesh_intersect_wide(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst, rc__hit *hit)
{
#if defined(RC__LEAF4_PAIR_AVX2) && !defined(RC__WIDE_FORCE_SCALAR)
    if (rc__leaf4_have_avx2()) return intersect_wide_vex(mesh, ray, geom, inst, hit);
#endif
    return wide_traverse(mesh, ray, geom, inst, hit, hit->t, 0);
}

int rc__mesh_occluded_wide(const rc__mesh *mesh, const rc__ray *ray, float tmax)
{
    return wide_traverse(mesh, ray, 0, 0, NULL, tmax, 1);
}

/* Rays taking turns (rc__mesh_intersect_rays): one ray's traversal as a
 * resumable state. A turn handles one node, or one half of a leaf: the first
 * half reads its vertex indices and prefetches the vertices, the second tests
 * them. After a node the ray prefetches the one it visits next. The tests,
 * their order and the tie rule are those of wide_traverse, so every ray gets
 * the same hit, bit for bit. */
typedef struct ray_turns {
    rc__ray r;
    wide_ray w;
    rc__hit *hit;
    float tcur;
    uint32_t sp, child, count, staged;
    int found, settling;
    rc__wide_entry stack[STACK_SIZE + 4u]; /* room for one node's children past the end */
} ray_turns;

static void turns_start(ray_turns *T, const rc__ray *ray, rc__hit *hit)
{
    T->r = *ray;
    wide_ray_init(&T->w, ray);
    T->hit = hit;
    T->tcur = hit->t;
    T->sp = T->child = T->count = T->staged = 0;
    T->found = T->settling = 0;
}

/* One turn of T; 0 once its traversal is over (prim id settled). */
static RC__FORCE_INLINE int turns_step(ray_turns *T, const rc__mesh *mesh, uint32_t geom, uint32_t inst)
{
    if (T->settling) {
        rc__hit_settle(T->hit, mesh->bvh.refs);
        return 0;
    }
    if (T->count == 0) {
        const rc__wnode *n = &mesh->wide[T->child];
        float tn[4] RC__ALIGN16;
        uint32_t mask = wide_box_test(n, &T->w, T->tcur, tn);
        if (mask) {
            rc__wide_entry *const e = T->stack + T->sp; /* as wide_traverse: sorted onto the stack */
            uint32_t m = 0;
            while (mask) {
                const uint32_t c = lowest_bit(mask);
                mask &= mask - 1u;
                m = rc__wide_add_sorted(e, m, n, c, tn);
            }
            T->child = e[m - 1].child;
            T->count = e[m - 1].count;
            T->sp += m - 1u;
            if (RC__UNLIKELY(T->sp > STACK_SIZE)) T->sp = STACK_SIZE;
            T->staged = 0;
            rc__prefetch_next(mesh->wide, mesh->leaf_tris, T->child, T->count);
            return 1;
        }
    } else if (!T->staged) {
        rc__leaf4_stage(mesh->leaf_tris, mesh->vertices, mesh->stride, T->child, T->count);
        T->staged = 1;
        return 1;
    } else {
        const float *vt[4][3];
        const uint32_t count = rc__leaf4_vertices(mesh->leaf_tris, mesh->vertices, mesh->stride, T->child, T->count, vt);
        rc__leaf4_out lo;
        uint32_t cand, known = mesh->flats_folded ? 0xFu : 0u, flat = 0;
        rc__leaf4_test(&T->r, (const float *const(*)[3])vt, count, &lo);
        cand = lo.hit | lo.redo;
        while (cand) {
            const uint32_t j = T->child + lowest_bit(cand);
            const float *const *tv = vt[j - T->child];
            float t;
            cand &= cand - 1u;
            if (!rc__leaf4_take(&lo, j - T->child, &T->r, tv, &known, &flat, &t)) continue;
            if (t > T->tcur || !rc__hit_offer_slot(T->hit, t, mesh->bvh.refs, j, geom, inst)) continue;
            T->tcur = t;
            T->found = 1;
        }
    }
    for (;;) {
        if (T->sp == 0) {
            /* the hit's prim id is a read from refs, a miss on a large map:
             * prefetch it and settle in a turn of its own */
            if (!T->found || T->hit->prim != RC__PRIM_PENDING) return 0;
            RC__PREFETCH(mesh->bvh.refs + T->hit->slot);
            T->settling = 1;
            return 1;
        }
        --T->sp;
        if (T->stack[T->sp].tnear <= T->tcur * RC__SLAB_FAR_SCALE) {
            T->child = T->stack[T->sp].child;
            T->count = T->stack[T->sp].count;
            T->staged = 0;
            rc__prefetch_next(mesh->wide, mesh->leaf_tris, T->child, T->count);
            return 1;
        }
    }
}

void rc__mesh_intersect_rays(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom, uint32_t inst,
                             rc__hit *hits, int *found)
{
    ray_turns T[RC__RAYS_IN_FLIGHT];
    uint32_t slot_ray[RC__RAYS_IN_FLIGHT];
    uint32_t next = 0, live = 0, k;
    if (mesh->wide == NULL || mesh->wide_count == 0) {
        for (k = 0; k < n; ++k) found[k] |= rc__mesh_intersect(mesh, &rays[k], geom, inst, &hits[k]);
        return;
    }
    /* a slot whose ray is done takes the next one, so the turns stay full */
    for (k = 0; k < RC__RAYS_IN_FLIGHT && next < n; ++k, ++next) {
        turns_start(&T[k], &rays[next], &hits[next]);
        slot_ray[k] = next;
        live |= 1u << k;
    }
    while (live) {
        for (k = 0; k < RC__RAYS_IN_FLIGHT; ++k) {
            if (!((live >> k) & 1u) || turns_step(&T[k], mesh, geom, inst)) continue;
            found[slot_ray[k]] |= T[k].found;
            if (next < n) {
                turns_start(&T[k], &rays[next], &hits[next]);
                slot_ray[k] = next++;
            } else {
                live &= ~(1u << k);
            }
        }
    }
}

/* The ordering key of a ray (mesh.h): the subtree at depth `depth` whose box
 * the ray enters first, searched through the top of the tree only. */
uint32_t rc__mesh_order_key(const rc__mesh *mesh, const rc__ray *ray, float tmax, uint32_t depth)
{
    struct {
        uint32_t node, depth;
        float tnear;
    } stack[3u * RC__ORDER_MAX_DEPTH + 1u];
    uint32_t sp = 0, key = UINT32_MAX;
    float best = tmax;
    wide_ray w;
    if (!mesh->wide || mesh->wide_count == 0) return UINT32_MAX;
    if (depth > RC__ORDER_MAX_DEPTH) depth = RC__ORDER_MAX_DEPTH;
    wide_ray_init(&w, ray);
    stack[0].node = 0;
    stack[0].depth = 0;
    stack[0].tnear = 0.0f;
    sp = 1;
    while (sp) {
        const uint32_t node = stack[sp - 1u].node, d = stack[sp - 1u].depth;
        const rc__wnode *n = &mesh->wide[node];
        uint32_t mask, c;
        float tn[4];
        if (stack[--sp].tnear > best) continue;
        mask = wide_box_test(n, &w, best, tn);
        /* the search is over every box the ray meets above the depth,
         * pruned by the nearest entry so far; the children go onto the
         * stack nearest on top, so that a near subtree is found early and
         * prunes the rest (1M sphere: -70% of the key's instructions
         * against slot order; its time, a few per cent of a call, went
         * unchanged on the AMD VM: it waits on memory) */
        {
            const uint32_t base = sp;
            for (c = 0; c < 4; ++c) {
                uint32_t j;
                if (!((mask >> c) & 1u) || n->child[c] == RC__WIDE_EMPTY || tn[c] > best) continue;
                if (n->count[c] != 0 || d + 1u >= depth) {
                    if (tn[c] < best || key == UINT32_MAX) {
                        best = tn[c];
                        key = node * 4u + c;
                    }
                    continue;
                }
                for (j = sp; j > base && stack[j - 1u].tnear < tn[c]; --j) stack[j] = stack[j - 1u];
                stack[j].node = n->child[c];
                stack[j].depth = d + 1u;
                stack[j].tnear = tn[c];
                ++sp;
            }
        }
    }
    return key;
}
