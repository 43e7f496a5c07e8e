/* Probe, not part of the build: does an 8-wide BVH beat a 4-wide one for
 * single incoherent rays? Both are collapsed from the same binary SAH tree by
 * the same rule as src/bvh/wide.c (open the child of largest area until the
 * node is full), traversed by the same plain code (W is the only difference:
 * the box loop is left to the compiler's vectoriser, AVX2 here) and tested
 * with the library's watertight triangle test, so both find the same hits
 * (checked). Neither has the library's turns or prefetches: this measures the
 * width alone (docs/benchmarks.md, session 11).
 *
 *   gcc -O3 -mavx2 -ffp-contract=off -std=gnu99 -Isrc -Iinclude -Itools/common \
 *       tools/probes/wide_width.c build/librangecast.a build/tools/librcutil.a \
 *       -lm -lpthread -lembree3 -lvulkan -o /tmp/wide_width
 *   /tmp/wide_width RAYS TRIANGLES            (defaults 1000000 1000000)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bvh/bvh.h"
#include "bvh/intersect.h"
#include "bvh/mesh.h"
#include "meshgen.h"

static const rc__bvh_node *bin;
static const uint32_t *leaf_tris;
static const float *verts;

static float half_area(uint32_t b)
{
    const rc__bvh_node *n = &bin[b];
    const float dx = n->bmax[0] - n->bmin[0], dy = n->bmax[1] - n->bmin[1], dz = n->bmax[2] - n->bmin[2];
    return dx * dy + dy * dz + dz * dx;
}

/* The children binary node b opens into, up to w of them (wide.c's rule). */
static uint32_t open_children(uint32_t b, uint32_t w, uint32_t *kids)
{
    uint32_t k, c;
    if (bin[b].count) {
        kids[0] = b;
        return 1;
    }
    kids[0] = bin[b].index;
    kids[1] = bin[b].index + 1u;
    for (k = 2; k < w;) {
        int best = -1;
        float best_area = 0.0f;
        for (c = 0; c < k; ++c)
            if (bin[kids[c]].count == 0 && (best < 0 || half_area(kids[c]) > best_area)) {
                best = (int)c;
                best_area = half_area(kids[c]);
            }
        if (best < 0) break;
        c = kids[best];
        kids[best] = bin[c].index;
        kids[k++] = bin[c].index + 1u;
    }
    return k;
}

/* The leaf's triangles against ray r, shrinking *best. */
static void test_leaf(const rc__ray *r, uint32_t first, uint32_t count, float *best)
{
    uint32_t t;
    for (t = first; t < first + count; ++t) {
        const uint32_t *q = leaf_tris + 3u * t;
        float tt, u, v;
        if (rc__tri_intersect(r, verts + 3u * q[0], verts + 3u * q[1], verts + 3u * q[2], &tt, &u, &v) && tt < *best)
            *best = tt;
    }
}

#define DEFINE_WIDTH(W)                                                                                       \
    typedef struct node##W {                                                                                  \
        float box[6][W];                                                                                      \
        uint32_t child[W], count[W];                                                                          \
    } node##W;                                                                                                \
    static node##W *nodes##W;                                                                                 \
    static uint32_t count##W;                                                                                 \
                                                                                                              \
    static uint32_t emit##W(uint32_t b)                                                                       \
    {                                                                                                         \
        const uint32_t w = count##W++;                                                                        \
        uint32_t kids[W], k = open_children(b, W, kids), c, p;                                                \
        for (c = 0; c < W; ++c) {                                                                             \
            node##W *n = &nodes##W[w];                                                                        \
            for (p = 0; p < 3; ++p) {                                                                         \
                n->box[2 * p][c] = c < k ? bin[kids[c]].bmin[p] : INFINITY;                                   \
                n->box[2 * p + 1][c] = c < k ? bin[kids[c]].bmax[p] : -INFINITY;                              \
            }                                                                                                 \
            n->count[c] = c < k ? bin[kids[c]].count : 0u;                                                    \
            n->child[c] = c < k ? bin[kids[c]].index : ~0u;                                                   \
        }                                                                                                     \
        for (c = 0; c < k; ++c)                                                                               \
            if (bin[kids[c]].count == 0) nodes##W[w].child[c] = emit##W(kids[c]);                            \
        return w;                                                                                             \
    }                                                                                                         \
                                                                                                              \
    /* Nearest hit distance (inf for none); *visits counts nodes. */                                         \
    static float trace##W(const rc__ray *r, unsigned long *visits)                                            \
    {                                                                                                         \
        uint32_t stack[4 * W * RC__BVH_MAX_DEPTH], node = 0;                                                  \
        float entry[4 * W * RC__BVH_MAX_DEPTH], best = INFINITY;                                              \
        const int sx = r->inv_dir[0] < 0.0f, sy = r->inv_dir[1] < 0.0f, sz = r->inv_dir[2] < 0.0f;          \
        int sp = 0;                                                                                           \
        for (;;) {                                                                                            \
            const node##W *n = &nodes##W[node];                                                               \
            float tn[W], tf[W], near[W];                                                                      \
            uint32_t c, met = 0, order[W];                                                                    \
            int i;                                                                                            \
            ++*visits;                                                                                        \
            for (c = 0; c < W; ++c) {                                                                         \
                const float x0 = (n->box[0 + sx][c] - r->org[0]) * r->inv_dir[0];                             \
                const float x1 = (n->box[1 - sx][c] - r->org[0]) * r->inv_dir[0];                             \
                const float y0 = (n->box[2 + sy][c] - r->org[1]) * r->inv_dir[1];                             \
                const float y1 = (n->box[3 - sy][c] - r->org[1]) * r->inv_dir[1];                             \
                const float z0 = (n->box[4 + sz][c] - r->org[2]) * r->inv_dir[2];                             \
                const float z1 = (n->box[5 - sz][c] - r->org[2]) * r->inv_dir[2];                             \
                float a = x0 > y0 ? x0 : y0, b = x1 < y1 ? x1 : y1;                                           \
                a = a > z0 ? a : z0;                                                                          \
                a = a > 0.0f ? a : 0.0f;                                                                      \
                b = b < z1 ? b : z1;                                                                          \
                b = b < best ? b : best;                                                                      \
                tn[c] = a;                                                                                    \
                tf[c] = b * 1.0000004f; /* conservative far plane */                                          \
            }                                                                                                 \
            for (c = 0; c < W; ++c) /* met children, nearest first */                                        \
                if (tn[c] <= tf[c]) {                                                                         \
                    uint32_t j = met++;                                                                       \
                    for (; j > 0 && near[j - 1] > tn[c]; --j) {                                               \
                        near[j] = near[j - 1];                                                                \
                        order[j] = order[j - 1];                                                              \
                    }                                                                                         \
                    near[j] = tn[c];                                                                          \
                    order[j] = c;                                                                             \
                }                                                                                             \
            for (i = (int)met - 1; i >= 0; --i) { /* leaves now, nodes pushed far first */                   \
                c = order[i];                                                                                 \
                if (n->count[c]) {                                                                            \
                    test_leaf(r, n->child[c], n->count[c], &best);                                            \
                } else {                                                                                      \
                    stack[sp] = n->child[c];                                                                  \
                    entry[sp++] = near[i];                                                                    \
                }                                                                                             \
            }                                                                                                 \
            do {                                                                                              \
                if (sp == 0) return best;                                                                     \
                --sp;                                                                                         \
            } while (!(entry[sp] < best));                                                                    \
            node = stack[sp];                                                                                 \
        }                                                                                                     \
    }

DEFINE_WIDTH(4)
DEFINE_WIDTH(8)

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static uint64_t rng = 88172645463325252ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

int main(int argc, char **argv)
{
    const uint32_t rays_n = argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 1000000u;
    const uint64_t want = argc > 2 ? strtoull(argv[2], NULL, 10) : 1000000u;
    rcu_mesh m;
    rc__bvh bvh;
    rc__aabb *bounds;
    rc__ray *rays;
    float *t4, *t8;
    uint32_t *lt, i, tris;
    void *scratch;
    int round, k, v;
    if (rcu_mesh_uv_sphere_triangles(20.0f, want, &m) != 0) return 1;
    tris = m.triangle_count;
    verts = m.vertices;
    bounds = (rc__aabb *)malloc(sizeof *bounds * tris);
    for (i = 0; i < tris; ++i) {
        for (k = 0; k < 3; ++k) {
            bounds[i].min[k] = INFINITY;
            bounds[i].max[k] = -INFINITY;
        }
        for (v = 0; v < 3; ++v)
            for (k = 0; k < 3; ++k) {
                const float x = m.vertices[3u * m.indices[3u * i + (uint32_t)v] + (uint32_t)k];
                if (x < bounds[i].min[k]) bounds[i].min[k] = x;
                if (x > bounds[i].max[k]) bounds[i].max[k] = x;
            }
    }
    bvh.nodes = (rc__bvh_node *)malloc(sizeof(rc__bvh_node) * rc__bvh_node_count(tris, 4u));
    bvh.refs = (uint32_t *)malloc(sizeof(uint32_t) * tris);
    scratch = malloc(rc__bvh_build_scratch_bytes(tris)); /* glibc: 16-aligned on x86_64 */
    rc__bvh_build(bounds, tris, 4u, scratch, &bvh, NULL, NULL);
    bin = bvh.nodes;
    lt = (uint32_t *)malloc(12u * tris);
    for (i = 0; i < tris; ++i) memcpy(lt + 3u * i, m.indices + 3u * bvh.refs[i], 12u);
    leaf_tris = lt;
    nodes4 = (node4 *)malloc(sizeof(node4) * bvh.node_count);
    nodes8 = (node8 *)malloc(sizeof(node8) * bvh.node_count);
    emit4(0);
    emit8(0);
    printf("%u triangles: %u 4-wide nodes (%zu bytes), %u 8-wide nodes (%zu bytes)\n", tris, count4,
           count4 * sizeof(node4), count8, count8 * sizeof(node8));
    /* origins uniform in the 10 m ball, directions uniform: incoherent */
    rays = (rc__ray *)malloc(sizeof *rays * rays_n);
    for (i = 0; i < rays_n; ++i) {
        double o[3], d[3], n2;
        float of[3], df[3];
        do {
            for (k = 0; k < 3; ++k) o[k] = 2.0 * uniform() - 1.0;
        } while (o[0] * o[0] + o[1] * o[1] + o[2] * o[2] > 1.0);
        do {
            for (k = 0; k < 3; ++k) d[k] = 2.0 * uniform() - 1.0;
            n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        } while (n2 > 1.0 || n2 < 1e-6);
        for (k = 0; k < 3; ++k) {
            of[k] = (float)(10.0 * o[k]);
            df[k] = (float)d[k];
        }
        rc__ray_prepare(&rays[i], of, df);
    }
    t4 = (float *)malloc(sizeof(float) * rays_n);
    t8 = (float *)malloc(sizeof(float) * rays_n);
    for (round = 0; round < 3; ++round) {
        unsigned long v4 = 0, v8 = 0, differ = 0;
        const double a = now();
        double b, c;
        for (i = 0; i < rays_n; ++i) t4[i] = trace4(&rays[i], &v4);
        b = now();
        for (i = 0; i < rays_n; ++i) t8[i] = trace8(&rays[i], &v8);
        c = now();
        for (i = 0; i < rays_n; ++i) differ += t4[i] != t8[i];
        printf("4-wide %.2f Mrays/s (%.1f nodes a ray), 8-wide %.2f Mrays/s (%.1f), 8/4 = %.3f, %lu hits differ\n",
               rays_n / (b - a) / 1e6, (double)v4 / rays_n, rays_n / (c - b) / 1e6, (double)v8 / rays_n,
               (b - a) / (c - b), differ);
    }
    return 0;
}
