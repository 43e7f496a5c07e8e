/* Collapse of the binary SAH tree into 4-wide nodes, refit and bounds (wide.h). */
#include "bvh/wide.h"

#include <math.h>

uint32_t rc__wide_node_bound(uint32_t leaves)
{
    if (leaves == 0) return 0;
    return (3u * leaves + 3u) / 4u + 1u;
}

static float half_area(const rc__bvh_node *n)
{
    const float dx = n->bmax[0] - n->bmin[0], dy = n->bmax[1] - n->bmin[1], dz = n->bmax[2] - n->bmin[2];
    if (!(dx >= 0.0f) || !(dy >= 0.0f) || !(dz >= 0.0f)) return -1.0f; /* empty */
    return dx * dy + dy * dz + dz * dx;
}

static void slot_empty(rc__wnode *w, int c)
{
    int k;
    for (k = 0; k < 3; ++k) {
        w->box[2 * k][c] = INFINITY;  /* +inf: min above max, never met */
        w->box[2 * k + 1][c] = -INFINITY;
    }
    w->child[c] = RC__WIDE_EMPTY;
    w->count[c] = 0;
}

typedef struct collapse_ctx {
    const rc__bvh_node *bin;
    rc__wnode *out;
    uint32_t count;
} collapse_ctx;

/* Emits the node whose children are those of binary node b (or b itself when
 * b is a leaf: the one-leaf tree). Recursion depth is the binary depth, which
 * the builder caps at RC__BVH_MAX_DEPTH. */
static uint32_t emit(collapse_ctx *cc, uint32_t b)
{
    const rc__bvh_node *bin = cc->bin;
    const uint32_t w = cc->count++;
    uint32_t kids[4], k, c;
    if (bin[b].count != 0) {
        kids[0] = b;
        k = 1;
    } else {
        kids[0] = bin[b].index;
        kids[1] = bin[b].index + 1u;
        k = 2;
    }
    while (k < 4) {
        int best = -1;
        float best_area = 0.0f;
        for (c = 0; c < k; ++c) {
            const float a = half_area(&bin[kids[c]]);
            if (bin[kids[c]].count == 0 && (best < 0 || a > best_area)) {
                best = (int)c;
                best_area = a;
            }
        }
        if (best < 0) break;
        {
            const uint32_t open = kids[best];
            kids[best] = bin[open].index;
            kids[k++] = bin[open].index + 1u;
        }
    }
    for (c = 0; c < 4 && cc->out; ++c) {
        rc__wnode *node = &cc->out[w];
        if (c >= k) {
            slot_empty(node, (int)c);
            continue;
        }
        node->box[0][c] = bin[kids[c]].bmin[0];
        node->box[1][c] = bin[kids[c]].bmax[0];
        node->box[2][c] = bin[kids[c]].bmin[1];
        node->box[3][c] = bin[kids[c]].bmax[1];
        node->box[4][c] = bin[kids[c]].bmin[2];
        node->box[5][c] = bin[kids[c]].bmax[2];
        node->count[c] = bin[kids[c]].count;
        node->child[c] = bin[kids[c]].index;
    }
    for (c = 0; c < k; ++c)
        if (bin[kids[c]].count == 0) {
            const uint32_t child = emit(cc, kids[c]);
            if (cc->out) cc->out[w].child[c] = child;
        }
    return w;
}

uint32_t rc__wide_collapse(const rc__bvh *bin, rc__wnode *out)
{
    collapse_ctx cc;
    if (bin->node_count == 0) return 0;
    cc.bin = bin->nodes;
    cc.out = out;
    cc.count = 0;
    emit(&cc, 0);
    return cc.count;
}

static void grow(float box[6], const float *p)
{
    int k;
    for (k = 0; k < 3; ++k) {
        if (p[k] < box[2 * k]) box[2 * k] = p[k];
        if (p[k] > box[2 * k + 1]) box[2 * k + 1] = p[k];
    }
}

void rc__wide_refit(rc__wnode *nodes, uint32_t count, const uint32_t *leaf_tris, const float *vertices,
                    uint32_t stride)
{
    uint32_t i = count;
    while (i-- > 0) {
        rc__wnode *w = &nodes[i];
        int c, k;
        for (c = 0; c < 4; ++c) {
            float box[6] = {INFINITY, -INFINITY, INFINITY, -INFINITY,
                            INFINITY, -INFINITY};
            if (w->child[c] == RC__WIDE_EMPTY) continue;
            if (w->count[c] > 0) {
                uint32_t j, v;
                for (j = w->child[c]; j < w->child[c] + w->count[c]; ++j)
                    for (v = 0; v < 3; ++v) grow(box, vertices + (size_t)leaf_tris[3u * j + v] * stride);
            } else {
                const rc__wnode *sub = &nodes[w->child[c]];
                int s;
                for (s = 0; s < 4; ++s) {
                    if (sub->child[s] == RC__WIDE_EMPTY) continue;
                    for (k = 0; k < 3; ++k) {
                        if (sub->box[2 * k][s] < box[2 * k]) box[2 * k] = sub->box[2 * k][s];
                        if (sub->box[2 * k + 1][s] > box[2 * k + 1]) box[2 * k + 1] = sub->box[2 * k + 1][s];
                    }
                }
            }
            for (k = 0; k < 6; ++k) w->box[k][c] = box[k];
        }
    }
}

void rc__wide_bounds(const rc__wnode *nodes, uint32_t count, rc__aabb *out)
{
    int c, k;
    for (k = 0; k < 3; ++k) {
        out->min[k] = 3.0e38f;
        out->max[k] = -3.0e38f;
    }
    if (count == 0) return;
    for (c = 0; c < 4; ++c) {
        if (nodes[0].child[c] == RC__WIDE_EMPTY) continue;
        for (k = 0; k < 3; ++k) {
            if (nodes[0].box[2 * k][c] < out->min[k]) out->min[k] = nodes[0].box[2 * k][c];
            if (nodes[0].box[2 * k + 1][c] > out->max[k]) out->max[k] = nodes[0].box[2 * k + 1][c];
        }
    }
}
