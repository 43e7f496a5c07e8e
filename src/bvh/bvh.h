/* The canonical BVH: one binned-SAH builder for every backend.
 *
 * Layout (also what the Vulkan kernels read, as std430):
 *   node  = 32 bytes { float bmin[3]; uint32 index; float bmax[3]; uint32 count; }
 *   interior: count == 0, children are nodes[index] and nodes[index + 1]
 *   leaf:     count >= 1, items refs[index .. index + count)
 *   root is nodes[0].
 *
 * Leaves hold exactly leaf_size items except one that holds the remainder, so a
 * tree over n items has exactly rc__bvh_node_count(n, leaf_size) =
 * 2 * ceil(n / leaf_size) - 1 nodes whatever the geometry. That makes every
 * memory figure a function of the counts alone: the size queries are exact and
 * firmware can size its block ahead. (The SAH picks the axis and the place of
 * each split; the place is rounded to a multiple of leaf_size.) */
#ifndef RC_BVH_BVH_H
#define RC_BVH_BVH_H

#include "core/threads.h"
#include "rangecast/rangecast.h"

#include <stddef.h>
#include <stdint.h>

#define RC__BVH_MESH_LEAF_SIZE 4u  /* triangles per leaf in mesh BVHs */
#define RC__BVH_TOP_LEAF_SIZE 1u   /* geometries/instances per leaf in a scene's top level */
/* The builder keeps every leaf at depth <= RC__BVH_MAX_DEPTH (root = 0), so a
 * traversal stack of RC__BVH_MAX_DEPTH entries never overflows. */
#define RC__BVH_MAX_DEPTH 64u

typedef struct rc__aabb {
    float min[3];
    float max[3];
} rc__aabb;

typedef struct rc__bvh_node {
    float bmin[3];
    uint32_t index;
    float bmax[3];
    uint32_t count;
} rc__bvh_node;

typedef struct rc__bvh {
    rc__bvh_node *nodes;   /* node_count nodes */
    uint32_t *refs;        /* item_count item indices, in leaf order */
    uint32_t node_count;
    uint32_t item_count;
    uint32_t leaf_size;
    uint32_t reserved0;
} rc__bvh;

/* 2 * ceil(items / leaf_size) - 1 (0 for 0 items). */
uint32_t rc__bvh_node_count(uint32_t items, uint32_t leaf_size);
/* Bytes of scratch rc__bvh_build needs for this many items (excluding the item
 * bounds the caller provides and the nodes/refs arrays). */
size_t rc__bvh_build_scratch_bytes(uint32_t items);

/* Builds over items (item_bounds[i] for item i; empty boxes, min > max, are
 * allowed: degenerate items go somewhere but never enlarge other nodes).
 * out->nodes must hold rc__bvh_node_count(items, leaf_size) nodes and out->refs
 * items entries; scratch holds rc__bvh_build_scratch_bytes(items) bytes, 16-aligned.
 * The result depends only on the inputs (deterministic). progress may be NULL. */
void rc__bvh_build(const rc__aabb *item_bounds, uint32_t items, uint32_t leaf_size, void *scratch,
                   rc__bvh *out, rc_progress_fn progress, void *progress_user);

/* The same build with the subtrees below the top levels spread over pool's
 * threads (pool NULL or one thread: on the caller's thread). The tree is the
 * one rc__bvh_build makes, bit for bit, for any thread count; progress is
 * called on the caller's thread only. */
void rc__bvh_build_mt(const rc__aabb *item_bounds, uint32_t items, uint32_t leaf_size, void *scratch,
                      rc__bvh *out, rc__pool *pool, rc_progress_fn progress, void *progress_user);

/* Recomputes every node's bounds bottom-up from new item bounds (same items). */
void rc__bvh_refit(rc__bvh *bvh, const rc__aabb *item_bounds);

#endif
