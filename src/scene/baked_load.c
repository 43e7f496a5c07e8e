/* Loading a baked map (baked_format.h) in place. Everything traversal relies
 * on is checked before the scene exists, so a blob that passes cannot make
 * the library read outside it or loop:
 *   - the header's constants, sizes and the checksum;
 *   - every section inside the blob, on its 64-byte boundary;
 *   - vertices finite and within reach, indices below the vertex count;
 *   - each leaf slot's triangle below the triangle count and its vertex
 *     indices those of that triangle;
 *   - each node's children: an unused slot exactly as the collapse leaves it
 *     (an empty box), an inner child after its parent (so every descent ends),
 *     a leaf's run inside the slots; and every box holding what lies below
 *     it, so the baked tree culls nothing a fresh build would test;
 *   - the nodes one tree in depth-first order: each reached once (no node
 *     shared by two parents, which could make traversal work exponential),
 *     none left over, no deeper than a build makes.
 * Traversal stacks still drop entries past their size instead of
 * overflowing (wide_trace.c, packet.c). */
#include "bvh/intersect.h"
#include "bvh/scan_raster.h"
#include "scene/baked_format.h"
#include "scene/scene.h"

#include <math.h>

#define CORRUPT RC_ERR_CORRUPT_DATA

static int all_zero(const unsigned char *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (p[i]) return 0;
    return 1;
}

rc_status rc__baked_scene_desc(rc_context *ctx, const unsigned char *blob, size_t bytes, int prebuilt,
                               rc_scene_desc *desc)
{
    uint32_t version, order, geoms, quality, g;
    uint64_t total, triangles = 0;
    double origin[3];
    RC_RETURN_IF(ctx, bytes < RC__BAKED_HEADER, CORRUPT, "baked map: %llu bytes; a baked map has at least %u",
                 (unsigned long long)bytes, RC__BAKED_HEADER);
    RC_RETURN_IF(ctx, memcmp(blob, RC__BAKED_MAGIC, 8) != 0, CORRUPT,
                 "baked map: the first 8 bytes are not a baked map's (\\x89RCMAP\\r\\n)");
    order = rc__bk_u32(blob, RC__BK_BYTE_ORDER);
    RC_RETURN_IF(ctx, order == 0x04030201u, RC_ERR_UNSUPPORTED,
                 "baked map: written on a machine of the other byte order; bake it again on this one");
    RC_RETURN_IF(ctx, order != RC__BAKED_BYTE_ORDER, CORRUPT, "baked map: byte-order mark 0x%08x is neither order",
                 (unsigned)order);
    version = rc__bk_u32(blob, RC__BK_VERSION);
    RC_RETURN_IF(ctx, version != RC_BAKED_MAP_VERSION, RC_ERR_UNSUPPORTED,
                 "baked map: format version %u; this library reads version %u (bake the map again with it)",
                 (unsigned)version, RC_BAKED_MAP_VERSION);
    total = rc__bk_u64(blob, RC__BK_TOTAL);
    RC_RETURN_IF(ctx, total != (uint64_t)bytes, CORRUPT,
                 "baked map: the header says %llu bytes and the blob has %llu (truncated, or the wrong size passed)",
                 (unsigned long long)total, (unsigned long long)bytes);
    geoms = rc__bk_u32(blob, RC__BK_GEOMETRIES);
    RC_RETURN_IF(ctx, geoms == 0 || geoms > 0x00FFFFFFu, CORRUPT, "baked map: geometry count %u (1..16777215)",
                 (unsigned)geoms);
    RC_RETURN_IF(ctx, rc__bk_u32(blob, RC__BK_HEADER_BYTES) != rc__bk_header_bytes(geoms) ||
                          rc__bk_header_bytes(geoms) > total,
                 CORRUPT, "baked map: header size %u does not fit %u geometries in %llu bytes",
                 (unsigned)rc__bk_u32(blob, RC__BK_HEADER_BYTES), (unsigned)geoms, (unsigned long long)total);
    RC_RETURN_IF(ctx, rc__bk_u32(blob, RC__BK_NODE_BYTES) != sizeof(rc__wnode) ||
                          rc__bk_u32(blob, RC__BK_LEAF_SIZE) != RC__BVH_MESH_LEAF_SIZE ||
                          rc__bk_u32(blob, RC__BK_VERTEX_FLOATS) != RC__BAKED_VERTEX_FLOATS,
                 CORRUPT, "baked map: node size %u, leaf size %u, vertex floats %u; version 1 has 128, 4 and 4",
                 (unsigned)rc__bk_u32(blob, RC__BK_NODE_BYTES), (unsigned)rc__bk_u32(blob, RC__BK_LEAF_SIZE),
                 (unsigned)rc__bk_u32(blob, RC__BK_VERTEX_FLOATS));
    memcpy(origin, blob + RC__BK_ORIGIN, sizeof origin);
    RC_RETURN_IF(ctx, !isfinite(origin[0]) || !isfinite(origin[1]) || !isfinite(origin[2]), CORRUPT,
                 "baked map: the origin is not finite");
    quality = rc__bk_u32(blob, RC__BK_QUALITY);
    RC_RETURN_IF(ctx, quality > RC_BUILD_COMPACT, CORRUPT, "baked map: build quality %u (0..3)", (unsigned)quality);
    RC_RETURN_IF(ctx, !all_zero(blob + RC__BK_QUALITY + 4u, RC__BAKED_HEADER - (RC__BK_QUALITY + 4u)), CORRUPT,
                 "baked map: reserved header bytes are not zero");
    for (g = 0; g < geoms; ++g) triangles += rc__bk_u32(blob, RC__BAKED_HEADER + (size_t)g * RC__BAKED_RECORD + RC__BR_TRIANGLES);
    RC_RETURN_IF(ctx, triangles > 0xFFFFFFF0u, CORRUPT, "baked map: %llu triangles in all; a scene holds at most 4294967280",
                 (unsigned long long)triangles);
    *desc = rc_scene_desc_default();
    desc->max_geometries = geoms;
    /* the built-in backend keeps the baked trees where they are: its commit
     * builds only the top level, so no mesh capacity is reserved */
    desc->max_triangles = prebuilt ? 0u : triangles;
    memcpy(desc->origin, origin, sizeof origin);
    desc->build_quality = quality;
    return RC_OK;
}

/* Section [off, off + size) lies inside the blob, past the header, aligned. */
static int section_ok(uint64_t off, uint64_t size, uint64_t header, uint64_t total)
{
    return off % RC__BAKED_ALIGN == 0 && off >= header && off <= total && size <= total - off;
}

rc_status rc__baked_read_geometry(rc_context *ctx, const unsigned char *blob, uint64_t total, uint32_t g,
                                  rc__baked_geom *r)
{
    const unsigned char *rec = blob + RC__BAKED_HEADER + (size_t)g * RC__BAKED_RECORD;
    const uint64_t header = rc__bk_header_bytes(rc__bk_u32(blob, RC__BK_GEOMETRIES));
    uint64_t t;
    r->vertices = rc__bk_u32(rec, RC__BR_VERTICES);
    r->triangles = rc__bk_u32(rec, RC__BR_TRIANGLES);
    r->nodes = rc__bk_u32(rec, RC__BR_NODES);
    r->off_vertices = rc__bk_u64(rec, RC__BR_OFF_VERTICES);
    r->off_indices = rc__bk_u64(rec, RC__BR_OFF_INDICES);
    r->off_refs = rc__bk_u64(rec, RC__BR_OFF_REFS);
    r->off_leaf_tris = rc__bk_u64(rec, RC__BR_OFF_LEAF_TRIS);
    r->off_nodes = rc__bk_u64(rec, RC__BR_OFF_NODES);
    t = r->triangles;
    RC_RETURN_IF(ctx, r->vertices == 0 || r->vertices > 0xFFFFFFF0u || r->triangles == 0 || r->triangles > 0xFFFFFFF0u,
                 CORRUPT, "baked map: geometry %u has %u vertices and %u triangles (1..4294967280 each)",
                 (unsigned)g, (unsigned)r->vertices, (unsigned)r->triangles);
    RC_RETURN_IF(ctx, r->nodes == 0 || r->nodes > rc__wide_node_bound((uint32_t)((t + 3u) / 4u)), CORRUPT,
                 "baked map: geometry %u has %u tree nodes; %u triangles make 1..%u", (unsigned)g, (unsigned)r->nodes,
                 (unsigned)r->triangles, (unsigned)rc__wide_node_bound((uint32_t)((t + 3u) / 4u)));
    RC_RETURN_IF(ctx, !all_zero(rec + 12u, 4u) || !all_zero(rec + 56u, 8u), CORRUPT,
                 "baked map: geometry %u's reserved fields are not zero", (unsigned)g);
    RC_RETURN_IF(ctx, !section_ok(r->off_vertices, (uint64_t)r->vertices * 16u, header, total) ||
                          !section_ok(r->off_indices, t * 12u, header, total) ||
                          !section_ok(r->off_refs, t * 4u, header, total) ||
                          !section_ok(r->off_leaf_tris, t * 12u, header, total) ||
                          !section_ok(r->off_nodes, (uint64_t)r->nodes * sizeof(rc__wnode), header, total),
                 CORRUPT, "baked map: a section of geometry %u lies outside the blob or off its 64-byte boundary",
                 (unsigned)g);
    return RC_OK;
}

static int box_holds(const rc__wnode *n, uint32_t c, const float p[3])
{
    return n->box[0][c] <= p[0] && p[0] <= n->box[1][c] && n->box[2][c] <= p[1] && p[1] <= n->box[3][c] &&
           n->box[4][c] <= p[2] && p[2] <= n->box[5][c];
}

/* Child slot c of node i (inner child: a node after i, whose used slots'
 * boxes lie inside slot c's box; leaf: triangles whose vertices do). */
static rc_status check_slot(rc_context *ctx, uint32_t g, const rc__baked_geom *r, const rc__wnode *nodes, uint32_t i,
                            uint32_t c, const float *vertices, const uint32_t *leaf_tris)
{
    const rc__wnode *n = &nodes[i];
    const uint32_t child = n->child[c], count = n->count[c];
    uint32_t k, j;
    if (child == RC__WIDE_EMPTY) {
        for (k = 0; k < 3u; ++k)
            RC_RETURN_IF(ctx, count != 0 || !(n->box[2u * k][c] == INFINITY && n->box[2u * k + 1u][c] == -INFINITY),
                         CORRUPT, "baked map: geometry %u, node %u: unused slot %u is not empty", (unsigned)g,
                         (unsigned)i, (unsigned)c);
        return RC_OK;
    }
    for (k = 0; k < 6u; ++k)
        RC_RETURN_IF(ctx, isnan(n->box[k][c]), CORRUPT, "baked map: geometry %u, node %u: slot %u's box has a NaN",
                     (unsigned)g, (unsigned)i, (unsigned)c);
    if (count == 0) {
        const rc__wnode *m;
        RC_RETURN_IF(ctx, child <= i || child >= r->nodes, CORRUPT,
                     "baked map: geometry %u, node %u: slot %u points to node %u (children come after their parent, "
                     "below %u)",
                     (unsigned)g, (unsigned)i, (unsigned)c, (unsigned)child, (unsigned)r->nodes);
        m = &nodes[child];
        for (j = 0; j < 4u; ++j) {
            float lo[3], hi[3];
            if (m->child[j] == RC__WIDE_EMPTY) continue;
            for (k = 0; k < 3u; ++k) {
                lo[k] = m->box[2u * k][j];
                hi[k] = m->box[2u * k + 1u][j];
            }
            RC_RETURN_IF(ctx, !box_holds(n, c, lo) || !box_holds(n, c, hi), CORRUPT,
                         "baked map: geometry %u, node %u: slot %u's box does not hold node %u's", (unsigned)g,
                         (unsigned)i, (unsigned)c, (unsigned)child);
        }
        return RC_OK;
    }
    RC_RETURN_IF(ctx, count > RC__BVH_MESH_LEAF_SIZE || child >= r->triangles || count > r->triangles - child, CORRUPT,
                 "baked map: geometry %u, node %u: slot %u holds leaf slots %u..%u of %u", (unsigned)g, (unsigned)i,
                 (unsigned)c, (unsigned)child, (unsigned)(child + count - 1u), (unsigned)r->triangles);
    for (j = child; j < child + count; ++j)
        for (k = 0; k < 3u; ++k)
            RC_RETURN_IF(ctx, !box_holds(n, c, vertices + (size_t)leaf_tris[3u * j + k] * RC__BAKED_VERTEX_FLOATS),
                         CORRUPT, "baked map: geometry %u, node %u: slot %u's box does not hold its triangles",
                         (unsigned)g, (unsigned)i, (unsigned)c);
    return RC_OK;
}

/* The nodes form one tree laid out depth first, as the collapse writes it
 * (wide.c): a walk from the root that takes inner children in slot order
 * meets nodes 0, 1, 2 ... each exactly once. The slot checks alone would let
 * a node be reached from several parents, and a chain of nodes whose four
 * slots all lead to the next makes a traversal's work grow fourfold per link:
 * a scan that never ends instead of a crash. */
static rc_status check_tree_order(rc_context *ctx, uint32_t g, const rc__baked_geom *r, const rc__wnode *nodes)
{
    /* pending siblings: at most three a level over the depth a build keeps */
    uint32_t stack[3u * RC__BVH_MAX_DEPTH + 4u];
    uint32_t sp = 0, expect = 0, node = 0;
    for (;;) {
        uint32_t kids[4], k = 0, c;
        RC_RETURN_IF(ctx, node != expect, CORRUPT,
                     "baked map: geometry %u: the tree reaches node %u where a depth-first walk is at node %u "
                     "(each node once, in the order a build writes them)",
                     (unsigned)g, (unsigned)node, (unsigned)expect);
        ++expect;
        for (c = 0; c < 4u; ++c)
            if (nodes[node].child[c] != RC__WIDE_EMPTY && nodes[node].count[c] == 0) kids[k++] = nodes[node].child[c];
        if (k > 0) {
            RC_RETURN_IF(ctx, sp + k - 1u > sizeof stack / sizeof stack[0], CORRUPT,
                         "baked map: geometry %u: the tree is deeper than a build makes (%u levels at most)",
                         (unsigned)g, (unsigned)RC__BVH_MAX_DEPTH);
            while (k > 1u) stack[sp++] = kids[--k];
            node = kids[0];
            continue;
        }
        if (sp == 0) break;
        node = stack[--sp];
    }
    RC_RETURN_IF(ctx, expect != r->nodes, CORRUPT,
                 "baked map: geometry %u: the tree reaches %u of its %u nodes", (unsigned)g, (unsigned)expect,
                 (unsigned)r->nodes);
    return RC_OK;
}

/* The mesh's flats_folded (bvh/mesh.h) for a file's triples, which are
 * whole (as the mesh's indices): 1 when no triangle has zero area but those
 * with a repeated index, which the leaf tests never hit (an edge function
 * exactly 0 sends them to the scalar test, which checks the area). */
static uint32_t flats_folded(const rc__baked_geom *r, const float *v, const uint32_t *lt)
{
    uint32_t i;
    for (i = 0; i < r->triangles; ++i) {
        const uint32_t *t = lt + 3u * (size_t)i;
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
        if (rc__tri_zero_area(v + (size_t)t[0] * RC__BAKED_VERTEX_FLOATS, v + (size_t)t[1] * RC__BAKED_VERTEX_FLOATS,
                              v + (size_t)t[2] * RC__BAKED_VERTEX_FLOATS))
            return 0;
    }
    return 1;
}

static rc_status check_geometry(rc_context *ctx, const unsigned char *blob, uint32_t g, const rc__baked_geom *r)
{
    const float *v = (const float *)(const void *)(blob + r->off_vertices);
    const uint32_t *idx = (const uint32_t *)(const void *)(blob + r->off_indices);
    const uint32_t *refs = (const uint32_t *)(const void *)(blob + r->off_refs);
    const uint32_t *lt = (const uint32_t *)(const void *)(blob + r->off_leaf_tris);
    const rc__wnode *nodes = (const rc__wnode *)(const void *)(blob + r->off_nodes);
    uint64_t i;
    uint32_t c;
    for (i = 0; i < r->vertices; ++i) {
        const float *p = v + i * RC__BAKED_VERTEX_FLOATS;
        RC_RETURN_IF(ctx, !rc__all_finite(p, 3) || !rc__in_reach3(p), CORRUPT,
                     "baked map: geometry %u, vertex %llu is (%g, %g, %g): not finite or farther than %g m",
                     (unsigned)g, (unsigned long long)i, (double)p[0], (double)p[1], (double)p[2], RC__MAX_COORD);
    }
    for (i = 0; i < (uint64_t)r->triangles * 3u; ++i)
        RC_RETURN_IF(ctx, idx[i] >= r->vertices, CORRUPT,
                     "baked map: geometry %u, triangle %llu has vertex index %u of %u", (unsigned)g,
                     (unsigned long long)(i / 3u), (unsigned)idx[i], (unsigned)r->vertices);
    for (i = 0; i < r->triangles; ++i)
        RC_RETURN_IF(ctx, refs[i] >= r->triangles || memcmp(lt + 3u * i, idx + 3u * (size_t)refs[i], 12) != 0, CORRUPT,
                     "baked map: geometry %u, leaf slot %llu does not match a triangle", (unsigned)g,
                     (unsigned long long)i);
    for (i = 0; i < r->nodes; ++i)
        for (c = 0; c < 4u; ++c) RC_TRY(check_slot(ctx, g, r, nodes, (uint32_t)i, c, v, lt));
    return check_tree_order(ctx, g, r, nodes);
}

rc_status rc__scene_load_baked(rc_context *ctx, const unsigned char *blob, size_t bytes, int skip_checksum,
                               int prebuilt, rc_scene **out)
{
    rc_scene_desc d;
    rc_scene *s;
    uint32_t g, geoms;
    RC_TRY(rc__baked_scene_desc(ctx, blob, bytes, prebuilt, &d));
    if (!skip_checksum) {
        const uint32_t want = rc__bk_u32(blob, RC__BK_CHECKSUM), got = rc__baked_checksum(blob, bytes);
        RC_RETURN_IF(ctx, want != got, CORRUPT,
                     "baked map: checksum 0x%08x, the header says 0x%08x (the bytes changed since baking)",
                     (unsigned)got, (unsigned)want);
    }
    geoms = d.max_geometries;
    for (g = 0; g < geoms; ++g) {
        rc__baked_geom r;
        RC_TRY(rc__baked_read_geometry(ctx, blob, bytes, g, &r));
        RC_TRY(check_geometry(ctx, blob, g, &r));
    }
    s = rc__scene_new(ctx, &d);
    if (s == NULL) return RC_ERR_OUT_OF_MEMORY; /* message written */
    for (g = 0; g < geoms; ++g) {
        rc__geometry *geo = &s->geoms[g];
        rc__mesh *m = &geo->mesh;
        rc__baked_geom r;
        rc__baked_read_geometry(ctx, blob, bytes, g, &r);
        geo->flags = RC_MESH_REFERENCE;
        m->vertices = (const float *)(const void *)(blob + r.off_vertices);
        m->indices = (const uint32_t *)(const void *)(blob + r.off_indices);
        m->stride = RC__BAKED_VERTEX_FLOATS;
        m->vertex_count = r.vertices;
        m->triangle_count = r.triangles;
        if (prebuilt) {
            m->bvh.refs = (uint32_t *)(uintptr_t)(blob + r.off_refs); /* read only: never rebuilt */
            m->bvh.item_count = r.triangles;
            m->bvh.leaf_size = RC__BVH_MESH_LEAF_SIZE;
            m->leaf_tris = (const uint32_t *)(const void *)(blob + r.off_leaf_tris);
            m->wide = (const rc__wnode *)(const void *)(blob + r.off_nodes);
            m->wide_count = r.nodes;
            m->flats_folded = flats_folded(&r, m->vertices, m->leaf_tris);
#if defined(RC__PROJECTED_SCANS)
            m->longest_edge = rc__raster_longest_edge(m);
#endif
            geo->baked = 1;
            geo->dirty = 0;
        } else {
            geo->dirty = 1;
        }
        s->triangle_count += r.triangles;
    }
    s->geom_count = geoms;
    s->baked = 1;
    s->top_dirty = 1;
    *out = s;
    return RC_OK;
}
