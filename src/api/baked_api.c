/* Public baked-map functions: argument checks, then the scene layer
 * (scene/baked_write.c, scene/baked_load.c). */
#include "backend/backend.h"
#include "scene/baked_format.h"
#include "scene/scene.h"

#include <string.h>

rc_status rc_scene_bake(const rc_scene *scene, void *blob, size_t capacity, size_t *bytes)
{
    rc_context *ctx;
    uint64_t need;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, bytes == NULL, RC_ERR_INVALID_ARGUMENT, "bytes is NULL");
    RC_RETURN_IF(ctx, ctx->backend_id != RC_BACKEND_BVH, RC_ERR_UNSUPPORTED,
                 "a baked map holds the built-in backend's tree: bake a scene of a context created with "
                 "RC_BACKEND_BVH (this one uses %s)",
                 ctx->backend->name);
    RC_RETURN_IF(ctx, !rc__scene_up_to_date(scene), RC_ERR_NOT_COMMITTED,
                 "scene is not committed (or changed since): commit it before baking");
    RC_RETURN_IF(ctx, scene->inst_count > 0 || scene->geom_count == 0, RC_ERR_UNSUPPORTED,
                 "scene has %u instance(s): a baked map holds a scene of meshes only (bake each instanced scene "
                 "and instance the loaded ones)",
                 (unsigned)scene->inst_count);
    need = rc__scene_baked_bytes(scene);
    RC_RETURN_IF(ctx, need > (uint64_t)SIZE_MAX, RC_ERR_CAPACITY,
                 "the baked map would take %llu bytes, more than this machine can address", (unsigned long long)need);
    if (blob == NULL) {
        *bytes = (size_t)need;
        return RC_OK;
    }
    RC_RETURN_IF(ctx, capacity < need, RC_ERR_CAPACITY, "capacity is %llu bytes; the baked map takes %llu",
                 (unsigned long long)capacity, (unsigned long long)need);
    rc__scene_bake(scene, (unsigned char *)blob);
    *bytes = (size_t)need;
    return RC_OK;
}

static rc_status check_blob(rc_context *ctx, const void *blob, size_t bytes)
{
    RC_RETURN_IF(ctx, blob == NULL, RC_ERR_INVALID_ARGUMENT, "blob is NULL");
    RC_RETURN_IF(ctx, bytes == 0, RC_ERR_INVALID_ARGUMENT, "bytes is 0");
    RC_RETURN_IF(ctx, (uintptr_t)blob % 16u != 0, RC_ERR_INVALID_ARGUMENT,
                 "blob is at %p, not on a 16-byte boundary (mmap and aligned_alloc give one; 32-bit malloc may not)",
                 blob);
    return RC_OK;
}

rc_status rc_scene_baked_memory_requirements(const rc_context *ctx, const void *blob, size_t bytes,
                                             size_t *arena_bytes)
{
    rc_context *c = (rc_context *)ctx;
    rc_scene_desc d;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(c);
    RC_RETURN_IF(c, arena_bytes == NULL, RC_ERR_INVALID_ARGUMENT, "arena_bytes is NULL");
    RC_TRY(check_blob(c, blob, bytes));
    RC_TRY(rc__baked_scene_desc(c, (const unsigned char *)blob, bytes, ctx->backend_id == RC_BACKEND_BVH, &d));
    *arena_bytes = rc__scene_object_bytes(&d) + ctx->backend->scene_commit_bytes(&d);
    return RC_OK;
}

rc_status rc_scene_load_baked(rc_context *ctx, const void *blob, size_t bytes, uint32_t flags, rc_scene **out)
{
    rc_scene *s = NULL;
    rc_status st;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, out == NULL, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(check_blob(ctx, blob, bytes));
    RC_RETURN_IF(ctx, (flags & ~RC_BAKED_SKIP_CHECKSUM) != 0, RC_ERR_INVALID_ARGUMENT,
                 "flags is 0x%x; the only flag is RC_BAKED_SKIP_CHECKSUM (0x1)", (unsigned)flags);
    RC_TRY(rc__scene_load_baked(ctx, (const unsigned char *)blob, bytes, (flags & RC_BAKED_SKIP_CHECKSUM) != 0,
                                ctx->backend_id == RC_BACKEND_BVH, &s));
    /* the built-in backend builds the top level only; others their own structure */
    st = ctx->backend->scene_commit(s, NULL, NULL);
    if (st != RC_OK) {
        rc__scene_free(s); /* the backend wrote the message */
        return st;
    }
    s->committed = 1;
    s->version = 1;
    *out = s;
    return RC_OK;
}

rc_status rc_baked_get_mesh(const void *blob, size_t bytes, uint32_t geom_id, rc_mesh_desc *mesh,
                            uint32_t *geometry_count)
{
    const unsigned char *b = (const unsigned char *)blob;
    rc_scene_desc d;
    rc__baked_geom r;
    if (blob == NULL || bytes == 0 || (uintptr_t)blob % 16u != 0) return RC_ERR_INVALID_ARGUMENT;
    if (mesh == NULL && geometry_count == NULL) return RC_ERR_INVALID_ARGUMENT;
    if (mesh != NULL && mesh->struct_size != sizeof *mesh) return RC_ERR_STRUCT_SIZE;
    RC_TRY(rc__baked_scene_desc(NULL, b, bytes, 0, &d));
    if (geometry_count) *geometry_count = d.max_geometries;
    if (mesh == NULL) return RC_OK;
    if (geom_id >= d.max_geometries) return RC_ERR_OUT_OF_RANGE;
    RC_TRY(rc__baked_read_geometry(NULL, b, bytes, geom_id, &r));
    *mesh = rc_mesh_desc_default();
    mesh->flags = RC_MESH_REFERENCE;
    mesh->vertices = (const float *)(const void *)(b + r.off_vertices);
    mesh->vertex_count = r.vertices;
    mesh->vertex_stride = RC__BAKED_VERTEX_FLOATS * (uint32_t)sizeof(float);
    mesh->indices = (const uint32_t *)(const void *)(b + r.off_indices);
    mesh->triangle_count = r.triangles;
    return RC_OK;
}
