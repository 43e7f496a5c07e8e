/* The 4-wide BVH the built-in backend traverses on the CPU: the binary SAH
 * tree (bvh.h) collapsed so that every node holds up to four children, their
 * boxes stored plane by plane so one SIMD test (SSE2 on x86, NEON on ARM,
 * plain C elsewhere) meets all four at once. Leaves are not nodes: a child
 * slot either points to another node or names a leaf's run of triangles
 * (the binary tree's refs, in leaf order), so a ray reaches a leaf in about
 * half the steps of the binary tree and tests four boxes per fetch.
 *
 * Node = 128 bytes (two cache lines):
 *   box[p][c]  plane p (bmin x, bmax x, bmin y, bmax y, bmin z, bmax z) of child c
 *   child[c]   interior: node index; leaf: first slot of refs / leaf_tris;
 *              RC__WIDE_EMPTY for an unused slot (its box is empty: never met)
 *   count[c]   0 for an interior child, else the leaf's triangle count (1..4)
 * Nodes are in depth-first order, so children come after their parent: a
 * refit walks the array backwards. The root is node 0. */
#ifndef RC_BVH_WIDE_H
#define RC_BVH_WIDE_H

#include "bvh/bvh.h"

#include <stdint.h>

#define RC__WIDE_EMPTY 0xFFFFFFFFu

typedef struct rc__wnode {
    float box[6][4];
    uint32_t child[4];
    uint32_t count[4];
} rc__wnode;

/* Most nodes a collapse of a binary tree with this many leaves can make: a
 * node has at least three children unless both children of its binary root
 * are leaves, which bounds the count by (3 * leaves - 1) / 4 (+1 covers a
 * one-leaf tree, whose root is a node with one leaf child). */
uint32_t rc__wide_node_bound(uint32_t leaves);

/* Collapses bin (leaves of bin hold items refs[index .. index + count)) into
 * out, which holds rc__wide_node_bound(leaves) nodes. Returns the node count
 * (0 for an empty tree); out NULL only counts. Deterministic: the child with
 * the largest surface area is opened first, ties to the lower slot. */
uint32_t rc__wide_collapse(const rc__bvh *bin, rc__wnode *out);

/* Recomputes every box bottom-up from the triangles: leaf slot j holds the
 * vertex indices leaf_tris[3j .. 3j + 3) into vertices (stride floats apart). */
void rc__wide_refit(rc__wnode *nodes, uint32_t count, const uint32_t *leaf_tris, const float *vertices,
                    uint32_t stride);

/* Union of the root's child boxes (an empty box for no nodes). */
void rc__wide_bounds(const rc__wnode *nodes, uint32_t count, rc__aabb *out);

#endif
