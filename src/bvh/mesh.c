/* Single-ray queries on a triangle mesh with its BVH: ray setup, triangle
 * bounds, ordered nearest-hit traversal, any-hit occlusion, triangle normals.
 * The inner tests are in intersect.h. */
#include "bvh/mesh.h"

#include "bvh/intersect.h"
#include "core/common.h"

#include <math.h>
#include <string.h>

void rc__ray_prepare(rc__ray *ray, const float org[3], const float dir[3])
{
    float ax, ay, az, m;
    int k, kz = 0;
    for (k = 0; k < 3; ++k) {
        ray->org[k] = org[k];
        ray->dir[k] = dir[k];
        /* +-inf for a +-0 component (spelled out: no division by zero for
         * sanitizers to flag) */
        ray->inv_dir[k] = dir[k] != 0.0f ? 1.0f / dir[k] : copysignf(INFINITY, dir[k]);
    }
    ax = fabsf(dir[0]);
    ay = fabsf(dir[1]);
    az = fabsf(dir[2]);
    m = ax;
    if (ay > m) {
        kz = 1;
        m = ay;
    }
    if (az > m) kz = 2;
    ray->kz = kz;
    ray->kx = kz == 2 ? 0 : kz + 1;
    ray->ky = ray->kx == 2 ? 0 : ray->kx + 1;
    if (dir[kz] < 0.0f) { /* keep the winding: swap kx and ky */
        int t = ray->kx;
        ray->kx = ray->ky;
        ray->ky = t;
    }
    ray->sx = dir[ray->kx] / dir[kz];
    ray->sy = dir[ray->ky] / dir[kz];
    ray->sz = ray->inv_dir[kz]; /* 1 / dir[kz], already computed (kz's component is the largest: not 0) */
}

static const float *rc__vertex(const rc__mesh *mesh, uint32_t i)
{
    return mesh->vertices + (size_t)i * mesh->stride;
}

void rc__mesh_triangle_bounds(const rc__mesh *mesh, rc__aabb *out)
{
    uint32_t i;
    int k;
    for (i = 0; i < mesh->triangle_count; ++i) {
        const uint32_t *tri = mesh->indices + (size_t)3 * i;
        const float *a = rc__vertex(mesh, tri[0]), *b = rc__vertex(mesh, tri[1]);
        const float *c = rc__vertex(mesh, tri[2]);
        for (k = 0; k < 3; ++k) {
            float lo = a[k], hi = a[k];
            lo = b[k] < lo ? b[k] : lo;
            hi = b[k] > hi ? b[k] : hi;
            lo = c[k] < lo ? c[k] : lo;
            hi = c[k] > hi ? c[k] : hi;
            out[i].min[k] = lo;
            out[i].max[k] = hi;
        }
    }
}

#if defined(RC__ORDER_COPIES)
size_t rc__mesh_order_scratch_bytes(uint64_t vertex_count)
{
    /* the new number of each vertex, and a copy of the old array */
    return (size_t)vertex_count * (sizeof(uint32_t) + 3u * sizeof(float));
}

void rc__mesh_order_vertices(const rc__mesh *mesh, float *vertices, uint32_t *indices, void *scratch)
{
    const uint32_t vertex_count = mesh->vertex_count;
    uint32_t *const renumber = (uint32_t *)scratch;
    float *const old = (float *)(void *)(renumber + vertex_count);
    uint32_t next = 0, j, k;
    for (j = 0; j < vertex_count; ++j) renumber[j] = UINT32_MAX;
    for (j = 0; j < mesh->triangle_count; ++j) {
        const uint32_t *tri = indices + (size_t)3 * mesh->bvh.refs[j];
        for (k = 0; k < 3u; ++k)
            if (renumber[tri[k]] == UINT32_MAX) renumber[tri[k]] = next++;
    }
    for (j = 0; j < vertex_count; ++j)
        if (renumber[j] == UINT32_MAX) renumber[j] = next++;
    memcpy(old, vertices, (size_t)vertex_count * 3u * sizeof(float));
    for (j = 0; j < vertex_count; ++j) memcpy(vertices + (size_t)3 * renumber[j], old + (size_t)3 * j, 3u * sizeof(float));
    for (j = 0; j < 3u * mesh->triangle_count; ++j) indices[j] = renumber[indices[j]];
}
#endif

void rc__mesh_fill_leaf_tris(const rc__mesh *mesh, uint32_t *out)
{
    uint32_t j;
    for (j = 0; j < mesh->triangle_count; ++j)
        memcpy(out + (size_t)3 * j, mesh->indices + (size_t)3 * mesh->bvh.refs[j], 3 * sizeof(uint32_t));
}

void rc__mesh_unfold_flats(const rc__mesh *mesh, uint32_t *leaf_tris)
{
    uint32_t j;
    for (j = 0; j < mesh->triangle_count; ++j) {
        uint32_t *t = leaf_tris + (size_t)3 * j;
        if (t[0] == t[1] && t[1] == t[2]) memcpy(t, mesh->indices + (size_t)3 * mesh->bvh.refs[j], 3 * sizeof(uint32_t));
    }
}

void rc__mesh_fold_flats(const rc__mesh *mesh, uint32_t *leaf_tris)
{
    uint32_t j;
    for (j = 0; j < mesh->triangle_count; ++j) {
        uint32_t *t = leaf_tris + (size_t)3 * j;
        if (rc__tri_zero_area(rc__vertex(mesh, t[0]), rc__vertex(mesh, t[1]), rc__vertex(mesh, t[2])))
            t[1] = t[2] = t[0];
    }
}

void rc__mesh_triangle_normal(const rc__mesh *mesh, uint32_t prim, float n[3])
{
    const uint32_t *tri = mesh->indices + (size_t)3 * prim;
    const float *a = rc__vertex(mesh, tri[0]), *b = rc__vertex(mesh, tri[1]);
    const float *c = rc__vertex(mesh, tri[2]);
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

#if defined(__GNUC__)
#define RC__NOINLINE __attribute__((noinline))
#else
#define RC__NOINLINE
#endif

typedef struct rc__trav_entry {
    uint32_t index; /* the node's index and count fields */
    uint32_t count;
    float tnear;
} rc__trav_entry;

/* Out of line on purpose: when GCC sees s.tmin == 0 it may turn
 * max(tnear, 0) into a data-dependent branch (measured ~5% slower). */
static RC__NOINLINE void rc__slab_init_opaque(rc__slab_ray *s, const rc__ray *ray)
{
    rc__slab_ray_init(s, ray);
}

/* Ordered traversal: at an interior node both children are tested, the nearer
 * is visited next and the farther pushed with its entry distance; entries are
 * dropped when popped if they start beyond the nearest hit. Boxes with entry
 * distance equal to the current t are still visited (the tie rule). The loop
 * carries the (index, count) fields of the node to visit, read when its box
 * was tested (software prefetching one level ahead measured 3-6% slower).
 * With any_hit, returns at the first hit with t < tmax. */
static RC__FORCE_INLINE int rc__traverse(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom,
                                          uint32_t inst, rc__hit *hit, float tmax, int any_hit)
{
    const rc__bvh_node *nodes = mesh->bvh.nodes;
    const uint32_t *refs = mesh->bvh.refs;
    const uint32_t *indices = mesh->indices;
    const float *vertices = mesh->vertices;
    const size_t stride = mesh->stride;
    const rc__ray r = *ray;
    rc__slab_ray s;
    rc__trav_entry stack[RC__BVH_MAX_DEPTH];
    uint32_t sp = 0, index, count;
    float tcur = tmax, tn;
    int found = 0;

    if (mesh->bvh.node_count == 0) return 0;
    rc__slab_init_opaque(&s, &r);
    if (!rc__node_hit(&nodes[0], &s, tcur, &tn)) return 0;
    index = nodes[0].index;
    count = nodes[0].count;
    for (;;) {
        if (count == 0) {
            const rc__bvh_node *a = nodes + index, *b = a + 1;
            const uint32_t ai = a->index, ac = a->count, bi = b->index, bc = b->count;
            float t0, t1;
            int h0, h1;
            h0 = rc__node_hit(a, &s, tcur, &t0);
            h1 = rc__node_hit(b, &s, tcur, &t1);
            if (h0 && h1) {
                rc__trav_entry e;
                if (t1 < t0) {
                    index = bi;
                    count = bc;
                    e.index = ai;
                    e.count = ac;
                    e.tnear = t0;
                } else {
                    index = ai;
                    count = ac;
                    e.index = bi;
                    e.count = bc;
                    e.tnear = t1;
                }
                /* the builder caps depth so this always holds; a deeper
                 * (corrupt) tree loses branches instead of the stack */
                if (RC__LIKELY(sp < RC__BVH_MAX_DEPTH)) stack[sp++] = e;
                continue;
            }
            if (h0) {
                index = ai;
                count = ac;
                continue;
            }
            if (h1) {
                index = bi;
                count = bc;
                continue;
            }
        } else {
            const uint32_t end = index + count;
            uint32_t j;
            for (j = index; j < end; ++j) {
                const uint32_t prim = refs[j];
                const uint32_t *tri = indices + (size_t)3 * prim;
                float t, u, v;
                if (!rc__tri_intersect(&r, vertices + tri[0] * stride, vertices + tri[1] * stride,
                                       vertices + tri[2] * stride, &t, &u, &v))
                    continue;
                if (any_hit) {
                    if (t < tmax) return 1;
                    continue;
                }
                if (!rc__hit_offer(hit, t, prim, j, geom, inst)) continue;
                tcur = t;
                found = 1;
            }
        }
        for (;;) {
            if (sp == 0) return found;
            --sp;
            /* with the box test's slack: a box whose entry distance rounds
             * just above t may still hold a triangle at t (a tie) */
            if (stack[sp].tnear <= tcur * RC__SLAB_FAR_SCALE) {
                index = stack[sp].index;
                count = stack[sp].count;
                break;
            }
        }
    }
}

int rc__mesh_intersect(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst,
                       rc__hit *hit)
{
    if (mesh->wide) return rc__mesh_intersect_wide(mesh, ray, geom, inst, hit);
    return rc__traverse(mesh, ray, geom, inst, hit, hit->t, 0);
}

int rc__mesh_occluded(const rc__mesh *mesh, const rc__ray *ray, float tmax)
{
    if (mesh->wide) return rc__mesh_occluded_wide(mesh, ray, tmax);
    return rc__traverse(mesh, ray, 0, 0, NULL, tmax, 1);
}

uint64_t rc__mesh_bytes(const rc__mesh *mesh)
{
    return (uint64_t)mesh->wide_count * sizeof(rc__wnode) + (uint64_t)mesh->triangle_count * 4u * sizeof(uint32_t) +
           (uint64_t)mesh->vertex_count * mesh->stride * sizeof(float);
}

int rc__mesh_is_large(const rc__mesh *mesh, uint64_t threshold) { return rc__mesh_bytes(mesh) > threshold; }

uint64_t rc__large_mesh_threshold(uint64_t llc)
{
    return llc / 8u > RC__LARGE_MESH_BYTES ? llc / 8u : RC__LARGE_MESH_BYTES;
}

uint64_t rc__ordered_mesh_threshold(uint64_t llc)
{
    return llc ? llc / 2u : RC__ORDERED_MESH_BYTES;
}
