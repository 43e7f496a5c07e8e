/* A triangle mesh with its BVH, and single-ray nearest-hit traversal with the
 * watertight ray/triangle test of Woop, Benthin and Wald (2013). */
#ifndef RC_BVH_MESH_H
#define RC_BVH_MESH_H

#include "bvh/bvh.h"
#include "bvh/wide.h"

#include <stddef.h>
#include <stdint.h>

typedef struct rc__mesh {
    const float *vertices;     /* vertex i at vertices + i * stride (floats) */
    const uint32_t *indices;   /* 3 per triangle */
    uint32_t stride;           /* floats between vertices (>= 3) */
    uint32_t vertex_count;
    uint32_t triangle_count;
    /* The longest edge of a triangle in leaf_tris (folded flats count 0),
     * set at commit where projected scans are built (rc__raster_longest_edge)
     * for a spinning sensor's choice of them; 0 elsewhere. */
    float longest_edge;
    rc__bvh bvh;               /* items are triangle indices */
    /* The triangles' vertex indices again, in leaf order (3 per bvh.refs
     * slot), so a leaf's triangles are one contiguous read instead of one
     * dependent miss each; NULL until the scene's commit fills it. */
    const uint32_t *leaf_tris;
    /* The 4-wide tree the CPU traverses (wide.h), when the backend built one
     * (the built-in backend does; the Vulkan backend keeps the binary tree,
     * which is then in bvh.nodes). Its leaves index bvh.refs and leaf_tris. */
    const rc__wnode *wide;
    uint32_t wide_count;
    /* 1 when leaf_tris holds every zero-area triangle as (a, a, a)
     * (rc__mesh_fold_flats), which no test ever hits: the leaf tests then
     * skip the per-hit zero-area check. 0 (a test's own triples, a baked map
     * with a zero-area triangle) keeps it. */
    uint32_t flats_folded;
} rc__mesh;

/* A ray prepared for traversal: origin, direction (any length, not zero),
 * reciprocal direction for slab tests, and the shear constants of the
 * watertight test. t is measured in units of |dir|. */
typedef struct rc__ray {
    float org[3];
    float dir[3];
    float inv_dir[3];
    int kx, ky, kz;
    float sx, sy, sz;
} rc__ray;

/* Nearest hit found so far. t = tmax before the search. */
typedef struct rc__hit {
    float t;           /* no barycentrics: no result needs them (rc__tri_intersect
                        * computes them for whoever does) */
    uint32_t prim;     /* triangle index within its mesh */
    uint32_t geom;     /* geometry id within its scene */
    uint32_t inst;     /* instance id or RC_INVALID_ID */
    uint32_t slot;     /* prim's leaf-order slot in its mesh (bvh.refs, leaf_tris): a
                        * cached read of its vertex indices; RC_INVALID_ID if unknown */
} rc__hit;

void rc__ray_prepare(rc__ray *ray, const float org[3], const float dir[3]);
/* rays[i] = rc__ray_prepare(org, R dirs[idx[i]]) for i < n, R the row-major
 * turn r (rc__rot_apply_f), the same values bit for bit; SIMD where there is
 * SSE2 (ray_batch.c). */
void rc__rays_prepare_turned(const float r[9], const float org[3], const float *dirs, const uint32_t *idx,
                             uint32_t n, rc__ray *rays);

/* Renumbers the vertices of a mesh whose arrays are its scene's own (a
 * copy: vertices packed, stride 3, both writable) in the order its leaves
 * first use them (bvh.refs order; vertices no triangle uses last, in their
 * order), and rewrites indices to match. Every triangle keeps its index and
 * its corners' order, so every hit, id and normal stays the same; what
 * changes is that a leaf's corners lie near each other and near its
 * neighbours' wherever the caller's numbering put them (a 1M-triangle sphere
 * with a shuffled vertex array traced 9% slower without it,
 * docs/benchmarks.md). scratch holds rc__mesh_order_scratch_bytes(vertex
 * count) bytes, 4-byte aligned. */
#if !defined(__OPTIMIZE_SIZE__)
/* Left out of -Os builds (the static core for small boards, whose size
 * budget it would pass, docs/benchmarks.md): a copy then keeps the caller's
 * numbering, with the same results. */
#define RC__ORDER_COPIES 1
size_t rc__mesh_order_scratch_bytes(uint64_t vertex_count);
void rc__mesh_order_vertices(const rc__mesh *mesh, float *vertices, uint32_t *indices, void *scratch);
#endif

/* Fills out (3 per slot, leaf order) with the vertex indices of triangle
 * refs[slot]. */
void rc__mesh_fill_leaf_tris(const rc__mesh *mesh, uint32_t *out);
/* Gives the triangles that rc__mesh_fold_flats folded their indices back
 * (a sequential pass: few triples are folded). */
void rc__mesh_unfold_flats(const rc__mesh *mesh, uint32_t *leaf_tris);
/* Rewrites every zero-area triangle (rc__tri_zero_area) of those triples as
 * (a, a, a), in place (then set flats_folded once they are the mesh's
 * leaf_tris). Boxes are computed from the triples before this. */
void rc__mesh_fold_flats(const rc__mesh *mesh, uint32_t *leaf_tris);

/* Item bounds of every triangle (for the builder). */
void rc__mesh_triangle_bounds(const rc__mesh *mesh, rc__aabb *out);

/* Searches the mesh for a hit with 0 < t < hit->t (or t == hit->t and a smaller
 * (inst, geom, prim) key: the tie rule that makes coplanar overlaps pick the
 * same triangle on every backend and thread count). Zero-area triangles never
 * hit. On a closer hit, updates *hit (t, prim, and geom/inst from the
 * arguments) and returns 1; else 0. */
int rc__mesh_intersect(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst,
                       rc__hit *hit);

/* The same searches over the 4-wide tree (wide_trace.c); rc__mesh_intersect
 * and rc__mesh_occluded take this path when mesh->wide is set. */
int rc__mesh_intersect_wide(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst,
                            rc__hit *hit);
int rc__mesh_occluded_wide(const rc__mesh *mesh, const rc__ray *ray, float tmax);

/* rays[0..n) one by one as rc__mesh_intersect would (found[i] |= its
 * result: found[] is not cleared, so a scene's meshes can be searched in
 * turn), but up to RC__RAYS_IN_FLIGHT of them taking turns node by node,
 * so that one ray's memory fetches overlap the others' work: for maps larger
 * than the caches (rc__mesh_is_large). */
#define RC__RAYS_IN_FLIGHT 8u
void rc__mesh_intersect_rays(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom, uint32_t inst,
                             rc__hit *hits, int *found);

/* Bytes of the mesh's nodes, leaf triangles and vertices: what a traversal
 * reads. */
uint64_t rc__mesh_bytes(const rc__mesh *mesh);
/* 1 when rc__mesh_bytes exceeds threshold: then traversals taking turns pay. */
int rc__mesh_is_large(const rc__mesh *mesh, uint64_t threshold);

/* An ordering key for the ray: which subtree `depth` levels down the 4-wide
 * tree (at most RC__ORDER_MAX_DEPTH) its path enters first within (0, tmax),
 * as node * 4 + child slot (leaves above that depth count as subtrees), or
 * UINT32_MAX when it enters none. Nodes are depth-first, so work sorted by
 * key walks the tree's subtrees one after another: rays with the same key
 * mostly meet the same nodes and triangles, and tracing them back to back
 * finds those in cache. Only the top of the tree is read. */
#define RC__ORDER_MAX_DEPTH 12u
uint32_t rc__mesh_order_key(const rc__mesh *mesh, const rc__ray *ray, float tmax, uint32_t depth);

/* That threshold for a CPU whose last-level cache holds llc bytes (0:
 * unknown): the larger of RC__LARGE_MESH_BYTES and llc / 8. Measured on a
 * Xeon VM with a 260 MB L3 (docs/benchmarks.md): turns cost 4% at 1k
 * triangles and 11-15% for packets at 100k-300k (3.7-11 MB, all in cache),
 * break even for packets and gain 40% for single rays at 1M (37 MB), and
 * gain 47-88% at 10M. 8 MiB is above the last cache level of the ARM boards
 * this is for (2-4 MB), where a 1M map already waits on DRAM. */
#define RC__LARGE_MESH_BYTES (8u << 20)
uint64_t rc__large_mesh_threshold(uint64_t llc);

/* Mesh bytes above which the built-in backend orders a call's tiles by
 * rc__mesh_order_key (backend/bvh.c), and the Embree backend by its
 * occupancy grid: half the last-level cache, or RC__ORDERED_MESH_BYTES when
 * its size is unknown. (Tests set the context's ordered_mesh_bytes to 0 or
 * UINT64_MAX to force either way.) Measured on a Xeon VM
 * with a 480 MB L3 (docs/benchmarks.md): +27-34% at 10M triangles (540 MB),
 * even at 1M (54 MB, in cache), -8% at 100k (in cache, ordered by force). */
#define RC__ORDERED_MESH_BYTES ((uint64_t)64u << 20)
uint64_t rc__ordered_mesh_threshold(uint64_t llc);

/* 1 when any hit with 0 < t < tmax exists (shadow/occlusion query). */
int rc__mesh_occluded(const rc__mesh *mesh, const rc__ray *ray, float tmax);

/* Geometric normal of triangle prim (unnormalised, (v1-v0) x (v2-v0)). */
void rc__mesh_triangle_normal(const rc__mesh *mesh, uint32_t prim, float n[3]);

#endif
