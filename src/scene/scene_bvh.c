/* Commit for the built-in structure. One arena block, sized from the scene's
 * capacities so the size query is exact, holds the top level and every mesh's
 * tree; a scratch block for item bounds and the builder lives only during
 * commit. Two shapes of mesh tree:
 *   binary (the Vulkan backend uploads it): nodes persist in the block;
 *   wide (the built-in backend traverses it): the binary tree is built in
 *     scratch and collapsed into 4-wide nodes (bvh/wide.h). The block
 *     reserves the most nodes a collapse can make, and gives back what the
 *     collapse did not use once all meshes are built, so the peak (what the
 *     size query returns) depends on the counts alone while the bytes kept
 *     are the ones used. */
#include "bvh/scan_raster.h"
#include "scene/scene.h"

#include <string.h>

typedef struct accel_layout {
    size_t mesh_nodes, top_nodes, mesh_refs, top_refs; /* capacities (counts) */
    size_t wide_nodes;                                  /* capacity of the wide node region */
    size_t refs_offset;                                 /* byte offsets in the block payload */
    size_t leaf_tris_offset;
    size_t wide_offset;
    size_t bytes;                                       /* block payload */
    size_t scratch_items;                               /* largest build */
    size_t scratch_nodes;                               /* binary nodes built in scratch (wide) */
    size_t scratch_front;                               /* scratch bytes before those nodes */
    size_t scratch_bytes;
} accel_layout;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static void layout_of(const rc_scene_desc *d, int wide, accel_layout *l)
{
    size_t geoms = d->max_geometries ? d->max_geometries : 1u;
    size_t items = geoms + d->max_instances;
    size_t t = (size_t)d->max_triangles;
    size_t leaves = (t + RC__BVH_MESH_LEAF_SIZE - 1u) / RC__BVH_MESH_LEAF_SIZE;
    /* sum over meshes of 2*ceil(T_g/4)-1 is at most 2*ceil(T/4) + G - 2; each
     * mesh's range is padded to an even start (+1 each) so that, with the
     * array placed as below, every sibling pair shares one 64-byte line */
    size_t binary_nodes = t ? 2u * leaves + 2u * geoms : 0u;
    memset(l, 0, sizeof *l);
    l->top_nodes = 2u * items - 1u;
    l->mesh_refs = t;
    l->top_refs = items;
    if (wide) {
        /* sum of rc__wide_node_bound over meshes: ceil(T_g/4) sums to at
         * most ceil(T/4) + G, and each bound adds 3/4 + 1 */
        l->wide_nodes = t ? (3u * (leaves + geoms) + 3u * geoms) / 4u + geoms + 1u : 0u;
        l->scratch_nodes = binary_nodes;
    } else {
        l->mesh_nodes = binary_nodes;
    }
    l->refs_offset = align16((l->mesh_nodes + l->top_nodes) * sizeof(rc__bvh_node));
    l->leaf_tris_offset = l->refs_offset + align16((l->mesh_refs + l->top_refs) * sizeof(uint32_t));
    l->wide_offset = l->leaf_tris_offset + align16(l->mesh_refs * 3u * sizeof(uint32_t));
    /* + 64: room to shift the block so that binary nodes[1] (binary) or the
     * wide nodes (wide) start on a 64-byte line */
    l->bytes = l->wide_offset + l->wide_nodes * sizeof(rc__wnode) + 64u;
    l->scratch_items = t > items ? t : items;
    l->scratch_front = align16(l->scratch_items * sizeof(rc__aabb)) +
                       rc__bvh_build_scratch_bytes((uint32_t)l->scratch_items);
    /* a copied mesh's vertices are put in leaf order (rc__mesh_order_vertices)
     * in the front part once its tree is built: room for the most a scene
     * copies (a mesh of few triangles may have many vertices) */
#if defined(RC__ORDER_COPIES)
    if (wide && rc__mesh_order_scratch_bytes(d->max_vertices) > l->scratch_front)
        l->scratch_front = align16(rc__mesh_order_scratch_bytes(d->max_vertices));
#endif
    l->scratch_bytes = l->scratch_front + l->scratch_nodes * sizeof(rc__bvh_node);
}

static size_t commit_bytes(const rc_scene_desc *desc, int wide)
{
    accel_layout l;
    layout_of(desc, wide, &l);
    return rc__arena_cost(l.bytes) + rc__arena_cost(l.scratch_bytes);
}

size_t rc__scene_bvh_commit_bytes(const rc_scene_desc *desc) { return commit_bytes(desc, 0); }
size_t rc__scene_wide_commit_bytes(const rc_scene_desc *desc) { return commit_bytes(desc, 1); }

size_t rc__scene_accel_bytes(const rc_scene *scene);
size_t rc__scene_accel_bytes(const rc_scene *scene)
{
    return scene->top_block ? rc__arena_cost(scene->accel_block_bytes) : 0u;
}

void rc__scene_release_bvh(rc_scene *scene)
{
    uint32_t g;
    if (!scene->top_block) return;
    rc__arena_free(&scene->ctx->arena, scene->top_block);
    scene->top_block = NULL;
    scene->accel_block_bytes = 0;
    memset(&scene->top, 0, sizeof scene->top);
    for (g = 0; g < scene->geom_count; ++g) {
        if (scene->geoms[g].baked) continue; /* its tree lives in the blob */
        memset(&scene->geoms[g].mesh.bvh, 0, sizeof scene->geoms[g].mesh.bvh);
        scene->geoms[g].mesh.leaf_tris = NULL;
        scene->geoms[g].mesh.wide = NULL;
        scene->geoms[g].mesh.wide_count = 0;
        scene->geoms[g].dirty = 1;
    }
}

static void aabb_empty(rc__aabb *b)
{
    b->min[0] = b->min[1] = b->min[2] = 3.0e38f;
    b->max[0] = b->max[1] = b->max[2] = -3.0e38f;
}

static void aabb_grow(rc__aabb *b, const float p[3])
{
    int k;
    for (k = 0; k < 3; ++k) {
        if (p[k] < b->min[k]) b->min[k] = p[k];
        if (p[k] > b->max[k]) b->max[k] = p[k];
    }
}

/* Bounds of an instance: the 8 corners of its source's box, transformed. */
static void instance_bounds(rc__instance *in)
{
    const rc__aabb *sb = &in->source->bounds;
    int c;
    aabb_empty(&in->bounds);
    for (c = 0; c < 8; ++c) {
        float p[3], q[3];
        p[0] = (c & 1) ? sb->max[0] : sb->min[0];
        p[1] = (c & 2) ? sb->max[1] : sb->min[1];
        p[2] = (c & 4) ? sb->max[2] : sb->min[2];
        rc__rot_apply_f(in->to_world.r, p, q);
        q[0] += in->to_world.t[0];
        q[1] += in->to_world.t[1];
        q[2] += in->to_world.t[2];
        aabb_grow(&in->bounds, q);
    }
    /* float rounding of the transform: widen by a relative hair so no hit is culled */
    for (c = 0; c < 3; ++c) {
        float pad = 1e-6f * (1.0f + (in->bounds.max[c] - in->bounds.min[c]) + (float)fabs(in->bounds.max[c]) +
                             (float)fabs(in->bounds.min[c]));
        in->bounds.min[c] -= pad;
        in->bounds.max[c] += pad;
    }
}

static void mesh_bounds(const rc__mesh *mesh, rc__aabb *out)
{
    const rc__bvh *bvh = &mesh->bvh;
    if (mesh->wide) {
        rc__wide_bounds(mesh->wide, mesh->wide_count, out);
        return;
    }
    if (bvh->node_count == 0) {
        aabb_empty(out);
        return;
    }
    memcpy(out->min, bvh->nodes[0].bmin, sizeof out->min);
    memcpy(out->max, bvh->nodes[0].bmax, sizeof out->max);
}

static rc_status build(rc_scene *scene, int wide, rc_progress_fn progress, void *user)
{
    rc_context *ctx = scene->ctx;
    accel_layout l;
    unsigned char *scratch, *base;
    rc__aabb *item_bounds;
    void *builder_scratch;
    rc__bvh_node *nodes, *scratch_nodes;
    rc__wnode *wnodes;
    uint32_t *refs, *leaf_tris;
    size_t node_off = 0, ref_off = 0, wide_off = 0;
    uint32_t g, i, items;

    layout_of(&scene->desc, wide, &l);
    if (wide && scene->top_block) {
        /* A rebuilt mesh may collapse to more nodes than it had, and the
         * block was trimmed: start over (refits alone keep the block). */
        for (g = 0; g < scene->geom_count; ++g)
            if (scene->geoms[g].dirty == 1) break;
        if (g < scene->geom_count) rc__scene_release_bvh(scene);
    }
    if (!scene->top_block) {
        scene->top_block = rc__arena_alloc(&ctx->arena, l.bytes);
        RC_RETURN_IF(ctx, scene->top_block == NULL, RC_ERR_OUT_OF_MEMORY,
                     "arena has no room for the BVH (%llu bytes; largest free block %llu)",
                     (unsigned long long)rc__arena_cost(l.bytes),
                     (unsigned long long)rc__arena_largest_free(&ctx->arena));
        scene->accel_block_bytes = l.bytes;
    }
    scratch = (unsigned char *)rc__arena_alloc(&ctx->arena, l.scratch_bytes);
    if (scratch == NULL) {
        const size_t largest = rc__arena_largest_free(&ctx->arena);
        if (wide) rc__scene_release_bvh(scene); /* nothing half-built stays */
        RC_RETURN_IF(ctx, 1, RC_ERR_OUT_OF_MEMORY,
                     "arena has no room for the BVH build scratch (%llu bytes; largest free block %llu)",
                     (unsigned long long)rc__arena_cost(l.scratch_bytes), (unsigned long long)largest);
    }
    item_bounds = (rc__aabb *)(void *)scratch;
    builder_scratch = scratch + align16(l.scratch_items * sizeof(rc__aabb));
    scratch_nodes = (rc__bvh_node *)(void *)(scratch + l.scratch_front);
    base = (unsigned char *)scene->top_block;
    if (wide) {
        /* wide nodes on a 64-byte line: each node is two whole lines */
        base += (64u - (uintptr_t)(base + l.wide_offset) % 64u) % 64u;
    } else {
        /* Sibling pairs start at odd indices (the builder places the root at
         * 0 and pairs after it): with nodes[1] on a 64-byte boundary each
         * pair is one cache line, one miss per traversal step. */
        base += (96u - (uintptr_t)base % 64u) % 64u;
    }
    nodes = (rc__bvh_node *)(void *)base;
    refs = (uint32_t *)(void *)(base + l.refs_offset);
    leaf_tris = (uint32_t *)(void *)(base + l.leaf_tris_offset);
    wnodes = (rc__wnode *)(void *)(base + l.wide_offset);

    for (g = 0; g < scene->geom_count; ++g) {
        rc__geometry *geo = &scene->geoms[g];
        rc__mesh *mesh = &geo->mesh;
        uint32_t n = rc__bvh_node_count(mesh->triangle_count, RC__BVH_MESH_LEAF_SIZE);
        uint32_t *lt = leaf_tris + 3u * ref_off;
        if (geo->baked) continue; /* a baked map's tree, in place; the block reserved nothing for it */
        if (geo->dirty == 1) {
            mesh->bvh.nodes = wide ? scratch_nodes : nodes + node_off;
            mesh->bvh.refs = refs + ref_off;
            rc__mesh_triangle_bounds(mesh, item_bounds);
            rc__bvh_build_mt(item_bounds, mesh->triangle_count, RC__BVH_MESH_LEAF_SIZE, builder_scratch, &mesh->bvh,
                             ctx->pool, progress, user);
            /* a copy is the scene's own: its vertices in the order the
             * leaves read them (the item bounds and the builder's scratch
             * are spent; the binary nodes after them are still needed) */
#if defined(RC__ORDER_COPIES)
            if (wide && (geo->flags & RC_MESH_COPY) && mesh->stride == 3u)
                rc__mesh_order_vertices(mesh, (float *)(uintptr_t)mesh->vertices, (uint32_t *)(uintptr_t)mesh->indices,
                                        scratch);
#endif
            rc__mesh_fill_leaf_tris(mesh, lt);
            rc__mesh_fold_flats(mesh, lt);
            mesh->flats_folded = 1;
            mesh->leaf_tris = lt;
            if (wide) {
                mesh->wide = wnodes + wide_off;
                mesh->wide_count = rc__wide_collapse(&mesh->bvh, wnodes + wide_off);
#if defined(RC__PROJECTED_SCANS)
                mesh->longest_edge = rc__raster_longest_edge(mesh);
#endif
                /* the binary nodes were scratch: only refs stay */
                mesh->bvh.nodes = NULL;
                mesh->bvh.node_count = 0;
            }
        } else if (geo->dirty == 2) {
            /* moved vertices can make a zero-area triangle whole (or the
             * reverse): boxes from the whole triples, then fold again */
            rc__mesh_unfold_flats(mesh, lt);
            if (wide) {
                rc__wide_refit((rc__wnode *)(uintptr_t)mesh->wide, mesh->wide_count, lt, mesh->vertices, mesh->stride);
            } else {
                rc__mesh_triangle_bounds(mesh, item_bounds);
                rc__bvh_refit(&mesh->bvh, item_bounds);
            }
            rc__mesh_fold_flats(mesh, lt); /* flats_folded stays 1, from the build */
#if defined(RC__PROJECTED_SCANS)
            if (wide) mesh->longest_edge = rc__raster_longest_edge(mesh);
#endif
        }
        geo->dirty = 0;
        node_off += n + (n & 1u); /* the next mesh starts at an even index */
        ref_off += mesh->triangle_count;
        wide_off += mesh->wide_count;
    }
    if (wide) {
        /* give back the node slots the collapses did not use */
        const size_t keep = (size_t)((unsigned char *)(wnodes + wide_off) - (unsigned char *)scene->top_block);
        if (keep < scene->accel_block_bytes) {
            rc__arena_shrink(&ctx->arena, scene->top_block, keep);
            scene->accel_block_bytes = keep;
        }
    }

    /* Top level over geometries then instances (binary in both shapes). */
    items = scene->geom_count + scene->inst_count;
    for (g = 0; g < scene->geom_count; ++g) mesh_bounds(&scene->geoms[g].mesh, &item_bounds[g]);
    for (i = 0; i < scene->inst_count; ++i) {
        instance_bounds(&scene->insts[i]);
        item_bounds[scene->geom_count + i] = scene->insts[i].bounds;
    }
    scene->top.nodes = nodes + l.mesh_nodes;
    scene->top.refs = refs + l.mesh_refs;
    rc__bvh_build_mt(item_bounds, items, RC__BVH_TOP_LEAF_SIZE, builder_scratch, &scene->top, ctx->pool, NULL, NULL);
    {
        rc__aabb b;
        if (scene->top.node_count == 0) {
            aabb_empty(&b);
        } else {
            memcpy(b.min, scene->top.nodes[0].bmin, sizeof b.min);
            memcpy(b.max, scene->top.nodes[0].bmax, sizeof b.max);
        }
        scene->bounds = b;
    }
    scene->top_dirty = 0;
    rc__arena_free(&ctx->arena, scratch);
    if (progress) progress(user, "commit", 1.0);
    return RC_OK;
}

rc_status rc__scene_build_bvh(rc_scene *scene, rc_progress_fn progress, void *user)
{
    return build(scene, 0, progress, user);
}

rc_status rc__scene_build_wide(rc_scene *scene, rc_progress_fn progress, void *user)
{
    return build(scene, 1, progress, user);
}
