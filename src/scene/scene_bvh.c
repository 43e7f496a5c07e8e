/* Commit for the built-in structure: one arena block (sized from the scene's
 * capacities, so the size query is exact) holds every mesh BVH and the top
 * level; a scratch block for item bounds and the builder lives only during
 * commit. */
#include "scene/scene.h"

#include <string.h>

typedef struct accel_layout {
    size_t mesh_nodes, top_nodes, mesh_refs, top_refs; /* capacities (counts) */
    size_t leaf_tris_offset;                            /* byte offset of the leaf-ordered index triples */
    size_t bytes;                                       /* block payload */
    size_t scratch_items;                               /* largest build */
    size_t scratch_bytes;
} accel_layout;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static void layout_of(const rc_scene_desc *d, accel_layout *l)
{
    size_t geoms = d->max_geometries ? d->max_geometries : 1u;
    size_t items = geoms + d->max_instances;
    size_t t = (size_t)d->max_triangles;
    /* sum over meshes of 2*ceil(T_g/4)-1 is at most 2*ceil(T/4) + G - 2; each
     * mesh's range is padded to an even start (+1 each) so that, with the
     * array placed as below, every sibling pair shares one 64-byte line */
    l->mesh_nodes = t ? 2u * ((t + RC__BVH_MESH_LEAF_SIZE - 1u) / RC__BVH_MESH_LEAF_SIZE) + 2u * geoms : 0u;
    l->top_nodes = 2u * items - 1u;
    l->mesh_refs = t;
    l->top_refs = items;
    l->leaf_tris_offset = align16((l->mesh_nodes + l->top_nodes) * sizeof(rc__bvh_node)) +
                          align16((l->mesh_refs + l->top_refs) * sizeof(uint32_t));
    /* + 64: room to shift the node array so that nodes[1] is 64-byte aligned */
    l->bytes = l->leaf_tris_offset + align16(l->mesh_refs * 3u * sizeof(uint32_t)) + 64u;
    l->scratch_items = t > items ? t : items;
    l->scratch_bytes = align16(l->scratch_items * sizeof(rc__aabb)) +
                       rc__bvh_build_scratch_bytes((uint32_t)l->scratch_items);
}

size_t rc__scene_bvh_commit_bytes(const rc_scene_desc *desc)
{
    accel_layout l;
    layout_of(desc, &l);
    return rc__arena_cost(l.bytes) + rc__arena_cost(l.scratch_bytes);
}

size_t rc__scene_accel_bytes(const rc_scene *scene);
size_t rc__scene_accel_bytes(const rc_scene *scene)
{
    accel_layout l;
    if (!scene->top_block) return 0;
    layout_of(&scene->desc, &l);
    return rc__arena_cost(l.bytes);
}

void rc__scene_release_bvh(rc_scene *scene)
{
    uint32_t g;
    if (!scene->top_block) return;
    rc__arena_free(&scene->ctx->arena, scene->top_block);
    scene->top_block = NULL;
    memset(&scene->top, 0, sizeof scene->top);
    for (g = 0; g < scene->geom_count; ++g) {
        memset(&scene->geoms[g].mesh.bvh, 0, sizeof scene->geoms[g].mesh.bvh);
        scene->geoms[g].mesh.leaf_tris = NULL;
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

static void node_bounds(const rc__bvh *bvh, rc__aabb *out)
{
    if (bvh->node_count == 0) {
        aabb_empty(out);
        return;
    }
    memcpy(out->min, bvh->nodes[0].bmin, sizeof out->min);
    memcpy(out->max, bvh->nodes[0].bmax, sizeof out->max);
}

rc_status rc__scene_build_bvh(rc_scene *scene, rc_progress_fn progress, void *user)
{
    rc_context *ctx = scene->ctx;
    accel_layout l;
    unsigned char *scratch;
    rc__aabb *item_bounds;
    void *builder_scratch;
    rc__bvh_node *nodes;
    uint32_t *refs, *leaf_tris;
    size_t node_off = 0, ref_off = 0;
    uint32_t g, i, items;

    layout_of(&scene->desc, &l);
    if (!scene->top_block) {
        scene->top_block = rc__arena_alloc(&ctx->arena, l.bytes);
        RC_RETURN_IF(ctx, scene->top_block == NULL, RC_ERR_OUT_OF_MEMORY,
                     "arena has no room for the BVH (%llu bytes; largest free block %llu)",
                     (unsigned long long)rc__arena_cost(l.bytes),
                     (unsigned long long)rc__arena_largest_free(&ctx->arena));
    }
    scratch = (unsigned char *)rc__arena_alloc(&ctx->arena, l.scratch_bytes);
    RC_RETURN_IF(ctx, scratch == NULL, RC_ERR_OUT_OF_MEMORY,
                 "arena has no room for the BVH build scratch (%llu bytes; largest free block %llu)",
                 (unsigned long long)rc__arena_cost(l.scratch_bytes),
                 (unsigned long long)rc__arena_largest_free(&ctx->arena));
    item_bounds = (rc__aabb *)(void *)scratch;
    builder_scratch = scratch + align16(l.scratch_items * sizeof(rc__aabb));
    {
        /* Sibling pairs start at odd indices (the builder places the root at
         * 0 and pairs after it): with nodes[1] on a 64-byte boundary each
         * pair is one cache line, one miss per traversal step. */
        unsigned char *base = (unsigned char *)scene->top_block;
        base += (96u - (uintptr_t)base % 64u) % 64u;
        nodes = (rc__bvh_node *)(void *)base;
        leaf_tris = (uint32_t *)(void *)(base + l.leaf_tris_offset);
        refs = (uint32_t *)(void *)(base + align16((l.mesh_nodes + l.top_nodes) * sizeof(rc__bvh_node)));
    }

    for (g = 0; g < scene->geom_count; ++g) {
        rc__geometry *geo = &scene->geoms[g];
        uint32_t n = rc__bvh_node_count(geo->mesh.triangle_count, RC__BVH_MESH_LEAF_SIZE);
        if (geo->dirty == 1) {
            geo->mesh.bvh.nodes = nodes + node_off;
            geo->mesh.bvh.refs = refs + ref_off;
            rc__mesh_triangle_bounds(&geo->mesh, item_bounds);
            rc__bvh_build(item_bounds, geo->mesh.triangle_count, RC__BVH_MESH_LEAF_SIZE, builder_scratch,
                          &geo->mesh.bvh, progress, user);
            {
                uint32_t *lt = leaf_tris + 3u * ref_off, j;
                for (j = 0; j < geo->mesh.triangle_count; ++j)
                    memcpy(lt + 3u * j, geo->mesh.indices + 3u * (size_t)geo->mesh.bvh.refs[j], 3 * sizeof(uint32_t));
                geo->mesh.leaf_tris = lt;
            }
        } else if (geo->dirty == 2) {
            rc__mesh_triangle_bounds(&geo->mesh, item_bounds);
            rc__bvh_refit(&geo->mesh.bvh, item_bounds);
        }
        geo->dirty = 0;
        node_off += n + (n & 1u); /* the next mesh starts at an even index */
        ref_off += geo->mesh.triangle_count;
    }

    /* Top level over geometries then instances. */
    items = scene->geom_count + scene->inst_count;
    for (g = 0; g < scene->geom_count; ++g) node_bounds(&scene->geoms[g].mesh.bvh, &item_bounds[g]);
    for (i = 0; i < scene->inst_count; ++i) {
        instance_bounds(&scene->insts[i]);
        item_bounds[scene->geom_count + i] = scene->insts[i].bounds;
    }
    scene->top.nodes = nodes + l.mesh_nodes;
    scene->top.refs = refs + l.mesh_refs;
    rc__bvh_build(item_bounds, items, RC__BVH_TOP_LEAF_SIZE, builder_scratch, &scene->top, NULL, NULL);
    node_bounds(&scene->top, &scene->bounds);
    scene->top_dirty = 0;
    rc__arena_free(&ctx->arena, scratch);
    if (progress) progress(user, "commit", 1.0);
    return RC_OK;
}
