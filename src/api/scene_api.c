/* Public scene functions: argument checks, then the scene layer. */
#include "backend/backend.h"
#include "scene/scene.h"

#include <math.h>
#include <string.h>

rc_scene *rc__scene_place(void *block, const rc_scene_desc *desc);

rc_scene_desc rc_scene_desc_default(void)
{
    rc_scene_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    return d;
}

rc_mesh_desc rc_mesh_desc_default(void)
{
    rc_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    return d;
}

rc_instance_desc rc_instance_desc_default(void)
{
    rc_instance_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.transform = rc_pose_identity();
    d.scale[0] = d.scale[1] = d.scale[2] = 1.0f;
    return d;
}

rc_scene_info rc_scene_info_default(void)
{
    rc_scene_info i;
    memset(&i, 0, sizeof i);
    i.struct_size = (uint32_t)sizeof i;
    return i;
}

static rc_status check_scene_desc(rc_context *ctx, const rc_scene_desc *desc)
{
    RC_TRY(rc__check_desc(ctx, desc, (uint32_t)sizeof *desc, (uint32_t)sizeof *desc, "desc"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof desc->reserved / sizeof desc->reserved[0], "desc"));
    RC_RETURN_IF(ctx, desc->flags != 0, RC_ERR_INVALID_ARGUMENT, "desc->flags is 0x%x; no flags are defined yet",
                 (unsigned)desc->flags);
    RC_RETURN_IF(ctx, desc->build_quality > RC_BUILD_COMPACT, RC_ERR_INVALID_ARGUMENT,
                 "desc->build_quality is %u; use RC_BUILD_BALANCED, _FAST, _HIGH or _COMPACT (0..3)",
                 (unsigned)desc->build_quality);
    RC_RETURN_IF(ctx, desc->max_triangles > 0xFFFFFFF0u, RC_ERR_INVALID_ARGUMENT,
                 "desc->max_triangles is %llu; at most 4294967280 are supported",
                 (unsigned long long)desc->max_triangles);
    RC_RETURN_IF(ctx, desc->max_copied_triangles > desc->max_triangles, RC_ERR_INVALID_ARGUMENT,
                 "desc->max_copied_triangles (%llu) exceeds desc->max_triangles (%llu)",
                 (unsigned long long)desc->max_copied_triangles, (unsigned long long)desc->max_triangles);
    RC_RETURN_IF(ctx, desc->max_vertices > 0xFFFFFFF0u, RC_ERR_INVALID_ARGUMENT,
                 "desc->max_vertices is %llu; at most 4294967280 are supported",
                 (unsigned long long)desc->max_vertices);
    RC_RETURN_IF(ctx, desc->max_triangles == 0 && desc->max_instances == 0, RC_ERR_INVALID_ARGUMENT,
                 "desc->max_triangles and desc->max_instances are both 0: the scene could hold nothing");
    RC_RETURN_IF(ctx, !isfinite(desc->origin[0]) || !isfinite(desc->origin[1]) || !isfinite(desc->origin[2]),
                 RC_ERR_NON_FINITE, "desc->origin is (%g, %g, %g): not finite", desc->origin[0], desc->origin[1],
                 desc->origin[2]);
    RC_RETURN_IF(ctx, desc->max_instances > 0x00FFFFFFu || desc->max_geometries > 0x00FFFFFFu,
                 RC_ERR_INVALID_ARGUMENT, "desc->max_geometries/max_instances above 16777215");
    /* The size arithmetic runs in size_t: on a 32-bit build, capacities whose
     * bytes could pass the address space would wrap it (a tiny block for a
     * large copy). Every backend's scene takes well under this bound (the
     * built-in backend's commit peaks near 112 bytes a triangle). */
    {
        const uint64_t bound = desc->max_triangles * 256u + desc->max_vertices * 32u +
                               desc->max_copied_triangles * 16u +
                               ((uint64_t)desc->max_geometries + desc->max_instances + 2u) * 1024u + (1u << 20);
        RC_RETURN_IF(ctx, bound > (uint64_t)SIZE_MAX, RC_ERR_INVALID_ARGUMENT,
                     "desc->max_triangles %llu, max_vertices %llu: more bytes than this build can address",
                     (unsigned long long)desc->max_triangles, (unsigned long long)desc->max_vertices);
    }
    return RC_OK;
}

rc_status rc_scene_memory_requirements(const rc_context *ctx, const rc_scene_desc *desc, size_t *bytes)
{
    rc_context *c = (rc_context *)ctx;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(c);
    RC_RETURN_IF(c, bytes == NULL, RC_ERR_INVALID_ARGUMENT, "bytes is NULL");
    RC_TRY(check_scene_desc(c, desc));
    *bytes = rc__scene_object_bytes(desc) + ctx->backend->scene_commit_bytes(desc);
    return RC_OK;
}

rc_scene *rc__scene_new(rc_context *ctx, const rc_scene_desc *desc)
{
    void *block = rc__arena_alloc(&ctx->arena, rc__scene_object_bytes(desc) - RC__ARENA_HEADER);
    rc_scene *s;
    if (block == NULL) {
        rc__fail(ctx, RC_ERR_OUT_OF_MEMORY,
                 "arena has no room for the scene (%llu bytes; largest free block %llu; see "
                 "rc_scene_memory_requirements)",
                 (unsigned long long)rc__scene_object_bytes(desc),
                 (unsigned long long)rc__arena_largest_free(&ctx->arena));
        return NULL;
    }
    s = rc__scene_place(block, desc);
    s->ctx = ctx;
    s->magic = RC__MAGIC_SCENE;
    s->next = ctx->scenes;
    ctx->scenes = s;
    return s;
}

void rc__scene_free(rc_scene *scene)
{
    rc_context *ctx = scene->ctx;
    rc_scene **link;
    uint32_t i;
    if (ctx->backend->scene_release) ctx->backend->scene_release(scene);
    rc__scene_release_bvh(scene);
    for (i = 0; i < scene->inst_count; ++i) ((rc_scene *)scene->insts[i].source)->instanced_by--;
    for (link = &ctx->scenes; *link; link = &(*link)->next)
        if (*link == scene) {
            *link = scene->next;
            break;
        }
    scene->magic = RC__MAGIC_DEAD;
    rc__arena_free(&ctx->arena, scene);
}

rc_status rc_scene_create(rc_context *ctx, const rc_scene_desc *desc, rc_scene **out)
{
    rc_scene *s;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, out == NULL, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(check_scene_desc(ctx, desc));
    s = rc__scene_new(ctx, desc);
    if (s == NULL) return RC_ERR_OUT_OF_MEMORY;
    *out = s;
    return RC_OK;
}

rc_status rc_scene_destroy(rc_scene *scene)
{
    rc_context *ctx;
    if (scene == NULL) return RC_OK;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->instanced_by > 0, RC_ERR_MISUSE,
                 "scene is the source of %u instance(s) in other scenes; destroy those scenes first",
                 (unsigned)scene->instanced_by);
    rc__scene_free(scene);
    return RC_OK;
}

static rc_status check_mesh(rc_context *ctx, const rc_mesh_desc *d)
{
    uint32_t stride;
    uint64_t i;
    RC_TRY(rc__check_desc(ctx, d, (uint32_t)sizeof *d, (uint32_t)sizeof *d, "desc"));
    RC_TRY(rc__check_reserved(ctx, d->reserved, 8, "desc"));
    RC_RETURN_IF(ctx, d->reserved0 != 0, RC_ERR_INVALID_ARGUMENT, "desc->reserved0 must be 0");
    RC_RETURN_IF(ctx, d->flags > RC_MESH_COPY, RC_ERR_INVALID_ARGUMENT,
                 "desc->flags is 0x%x; use RC_MESH_REFERENCE (0) or RC_MESH_COPY (1)", (unsigned)d->flags);
    RC_RETURN_IF(ctx, d->vertices == NULL, RC_ERR_INVALID_ARGUMENT, "desc->vertices is NULL");
    RC_RETURN_IF(ctx, d->indices == NULL, RC_ERR_INVALID_ARGUMENT, "desc->indices is NULL");
    RC_RETURN_IF(ctx, d->vertex_count == 0, RC_ERR_INVALID_ARGUMENT, "desc->vertex_count is 0");
    RC_RETURN_IF(ctx, d->triangle_count == 0, RC_ERR_INVALID_ARGUMENT, "desc->triangle_count is 0");
    RC_RETURN_IF(ctx, d->vertex_count > 0xFFFFFFF0u, RC_ERR_INVALID_ARGUMENT,
                 "desc->vertex_count is %llu; at most 4294967280", (unsigned long long)d->vertex_count);
    RC_RETURN_IF(ctx, d->triangle_count > 0xFFFFFFF0u, RC_ERR_INVALID_ARGUMENT,
                 "desc->triangle_count is %llu; at most 4294967280", (unsigned long long)d->triangle_count);
    stride = d->vertex_stride ? d->vertex_stride : 12u;
    RC_RETURN_IF(ctx, stride < 12u || stride % 4u != 0, RC_ERR_INVALID_ARGUMENT,
                 "desc->vertex_stride is %u; it must be 0 or a multiple of 4 that is at least 12", (unsigned)stride);
    for (i = 0; i < d->vertex_count; ++i) {
        const float *v = d->vertices + i * (stride / 4u);
        RC_RETURN_IF(ctx, !rc__all_finite(v, 3), RC_ERR_NON_FINITE, "desc->vertices[%llu] is (%g, %g, %g): not finite",
                     (unsigned long long)i, (double)v[0], (double)v[1], (double)v[2]);
        RC_RETURN_IF(ctx, !rc__in_reach3(v), RC_ERR_INVALID_ARGUMENT,
                     "desc->vertices[%llu] is (%g, %g, %g): farther than %g m from the scene's origin "
                     "(rc_scene_desc.origin)",
                     (unsigned long long)i, (double)v[0], (double)v[1], (double)v[2], RC__MAX_COORD);
    }
    for (i = 0; i < d->triangle_count * 3u; ++i)
        RC_RETURN_IF(ctx, d->indices[i] >= d->vertex_count, RC_ERR_OUT_OF_RANGE,
                     "desc->indices[%llu] (triangle %llu) is %u; vertex_count is %llu", (unsigned long long)i,
                     (unsigned long long)(i / 3u), (unsigned)d->indices[i], (unsigned long long)d->vertex_count);
    return RC_OK;
}

rc_status rc_scene_add_mesh(rc_scene *scene, const rc_mesh_desc *desc, uint32_t *geom_id)
{
    rc_context *ctx;
    rc__geometry *g;
    uint32_t stride;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->baked, RC_ERR_MISUSE, "the scene was loaded from a baked map and is read-only");
    RC_RETURN_IF(ctx, geom_id == NULL, RC_ERR_INVALID_ARGUMENT, "geom_id is NULL");
    RC_TRY(check_mesh(ctx, desc));
    RC_RETURN_IF(ctx, scene->geom_count >= scene->desc.max_geometries, RC_ERR_CAPACITY,
                 "scene is full: it was created with max_geometries = %u", (unsigned)scene->desc.max_geometries);
    RC_RETURN_IF(ctx, scene->triangle_count + desc->triangle_count > scene->desc.max_triangles, RC_ERR_CAPACITY,
                 "scene holds %llu triangles and this mesh adds %llu: more than max_triangles = %llu",
                 (unsigned long long)scene->triangle_count, (unsigned long long)desc->triangle_count,
                 (unsigned long long)scene->desc.max_triangles);
    if (desc->flags == RC_MESH_COPY) {
        RC_RETURN_IF(ctx, scene->copied_vertices_used + desc->vertex_count > scene->desc.max_vertices,
                     RC_ERR_CAPACITY, "copying %llu vertices exceeds the scene's max_vertices = %llu (%llu used)",
                     (unsigned long long)desc->vertex_count, (unsigned long long)scene->desc.max_vertices,
                     (unsigned long long)scene->copied_vertices_used);
        RC_RETURN_IF(ctx, scene->copied_triangles_used + desc->triangle_count > scene->desc.max_copied_triangles,
                     RC_ERR_CAPACITY,
                     "copying %llu triangles exceeds the scene's max_copied_triangles = %llu (%llu used)",
                     (unsigned long long)desc->triangle_count, (unsigned long long)scene->desc.max_copied_triangles,
                     (unsigned long long)scene->copied_triangles_used);
    }
    stride = desc->vertex_stride ? desc->vertex_stride / 4u : 3u;
    g = &scene->geoms[scene->geom_count];
    memset(g, 0, sizeof *g);
    g->flags = desc->flags;
    g->mesh.vertex_count = (uint32_t)desc->vertex_count;
    g->mesh.triangle_count = (uint32_t)desc->triangle_count;
    if (desc->flags == RC_MESH_COPY) {
        float *v = scene->copy_vertices + scene->copied_vertices_used * 3u;
        uint32_t *t = scene->copy_indices + scene->copied_triangles_used * 3u;
        uint64_t i;
        for (i = 0; i < desc->vertex_count; ++i) memcpy(v + i * 3u, desc->vertices + i * stride, 3 * sizeof(float));
        memcpy(t, desc->indices, (size_t)desc->triangle_count * 3u * sizeof(uint32_t));
        scene->copied_vertices_used += desc->vertex_count;
        scene->copied_triangles_used += desc->triangle_count;
        g->mesh.vertices = v;
        g->mesh.indices = t;
        g->mesh.stride = 3;
    } else {
        g->mesh.vertices = desc->vertices;
        g->mesh.indices = desc->indices;
        g->mesh.stride = stride;
    }
    g->dirty = 1;
    scene->triangle_count += desc->triangle_count;
    scene->committed = 0;
    scene->top_dirty = 1;
    *geom_id = scene->geom_count++;
    return RC_OK;
}

rc_status rc_scene_update_mesh(rc_scene *scene, uint32_t geom_id)
{
    rc_context *ctx;
    rc__geometry *g;
    uint32_t i;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->baked, RC_ERR_MISUSE, "the scene was loaded from a baked map and is read-only");
    RC_RETURN_IF(ctx, geom_id >= scene->geom_count, RC_ERR_OUT_OF_RANGE, "geom_id %u: the scene has %u geometries",
                 (unsigned)geom_id, (unsigned)scene->geom_count);
    g = &scene->geoms[geom_id];
    for (i = 0; i < g->mesh.vertex_count; ++i) {
        const float *v = g->mesh.vertices + (size_t)i * g->mesh.stride;
        RC_RETURN_IF(ctx, !rc__all_finite(v, 3), RC_ERR_NON_FINITE, "vertex %u of geometry %u is not finite",
                     (unsigned)i, (unsigned)geom_id);
        RC_RETURN_IF(ctx, !rc__in_reach3(v), RC_ERR_INVALID_ARGUMENT,
                     "vertex %u of geometry %u is (%g, %g, %g): farther than %g m from the scene's origin",
                     (unsigned)i, (unsigned)geom_id, (double)v[0], (double)v[1], (double)v[2], RC__MAX_COORD);
    }
    if (g->dirty == 0) g->dirty = 2;
    scene->committed = 0;
    scene->top_dirty = 1;
    return RC_OK;
}

static rc_status check_instance_pose(rc_context *ctx, const rc_pose *pose, const float scale[3], float out[3])
{
    rc_status st = rc__pose_check(pose);
    int i;
    RC_RETURN_IF(ctx, st == RC_ERR_NON_FINITE, st, "transform has a NaN or infinite value");
    RC_RETURN_IF(ctx, st != RC_OK, st, "transform.orientation is not a unit quaternion (norm off by more than 1e-3)");
    RC_RETURN_IF(ctx, !rc__in_reach3(pose->position), RC_ERR_INVALID_ARGUMENT,
                 "transform.position is (%g, %g, %g): farther than %g m from the scene's origin",
                 (double)pose->position[0], (double)pose->position[1], (double)pose->position[2], RC__MAX_COORD);
    if (scale[0] == 0.0f && scale[1] == 0.0f && scale[2] == 0.0f) {
        out[0] = out[1] = out[2] = 1.0f;
        return RC_OK;
    }
    for (i = 0; i < 3; ++i) {
        RC_RETURN_IF(ctx, !isfinite(scale[i]), RC_ERR_NON_FINITE, "scale[%d] is not finite", i);
        RC_RETURN_IF(ctx, scale[i] == 0.0f, RC_ERR_INVALID_ARGUMENT, "scale[%d] is 0", i);
        RC_RETURN_IF(ctx, !(fabsf(scale[i]) >= (float)RC__MIN_SCALE && fabsf(scale[i]) <= (float)RC__MAX_SCALE),
                     RC_ERR_INVALID_ARGUMENT, "scale[%d] is %g; its magnitude must lie in [%g, %g]", i,
                     (double)scale[i], RC__MIN_SCALE, RC__MAX_SCALE);
        out[i] = scale[i];
    }
    return RC_OK;
}

/* to_world = T * R * S; to_local its inverse; normals go through R * S^-1. */
static void instance_set(rc__instance *in, const rc_pose *pose, const float scale[3])
{
    rc__xform x;
    int i, j;
    in->pose = *pose;
    memcpy(in->scale, scale, sizeof in->scale);
    rc__xform_from_pose(pose, &x);
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) {
            in->to_world.rd[i * 3 + j] = x.r[i * 3 + j] * scale[j];
            in->to_world.r[i * 3 + j] = (float)in->to_world.rd[i * 3 + j];
            in->normal_to_world[i * 3 + j] = (float)(x.r[i * 3 + j] / scale[j]);
            in->to_local.r[j * 3 + i] = (float)(x.r[i * 3 + j] / scale[j]);
        }
        in->to_world.t[i] = (float)x.t[i];
        in->to_world.td[i] = x.t[i];
    }
    for (j = 0; j < 3; ++j) {
        double t = 0.0;
        for (i = 0; i < 3; ++i) t -= x.r[i * 3 + j] * x.t[i];
        in->to_local.t[j] = (float)(t / scale[j]);
    }
}

rc_status rc_scene_add_instance(rc_scene *scene, const rc_instance_desc *desc, uint32_t *inst_id)
{
    rc_context *ctx;
    float scale[3];
    rc__instance *in;
    rc_scene *src;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->baked, RC_ERR_MISUSE, "the scene was loaded from a baked map and is read-only");
    RC_RETURN_IF(ctx, inst_id == NULL, RC_ERR_INVALID_ARGUMENT, "inst_id is NULL");
    RC_TRY(rc__check_desc(ctx, desc, (uint32_t)sizeof *desc, (uint32_t)sizeof *desc, "desc"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, 8, "desc"));
    RC_RETURN_IF(ctx, desc->reserved0 != 0, RC_ERR_INVALID_ARGUMENT, "desc->reserved0 must be 0");
    src = (rc_scene *)desc->source;
    RC_RETURN_IF(ctx, !rc__scene_valid(src), RC_ERR_INVALID_HANDLE, "desc->source is not a valid scene");
    RC_RETURN_IF(ctx, src->ctx != ctx, RC_ERR_INVALID_ARGUMENT, "desc->source belongs to another context");
    RC_RETURN_IF(ctx, src == scene, RC_ERR_INVALID_ARGUMENT, "a scene cannot instance itself");
    RC_RETURN_IF(ctx, src->inst_count > 0 || src->desc.max_instances > 0, RC_ERR_UNSUPPORTED,
                 "desc->source can hold instances; only scenes of meshes can be instanced (one level)");
    RC_TRY(check_instance_pose(ctx, &desc->transform, desc->scale, scale));
    RC_RETURN_IF(ctx, scene->inst_count >= scene->desc.max_instances, RC_ERR_CAPACITY,
                 "scene is full: it was created with max_instances = %u", (unsigned)scene->desc.max_instances);
    in = &scene->insts[scene->inst_count];
    memset(in, 0, sizeof *in);
    in->source = src;
    instance_set(in, &desc->transform, scale);
    src->instanced_by++;
    scene->source_versions[scene->inst_count] = 0;
    scene->committed = 0;
    scene->top_dirty = 1;
    *inst_id = scene->inst_count++;
    return RC_OK;
}

rc_status rc_scene_set_instance_transform(rc_scene *scene, uint32_t inst_id, const rc_pose *transform,
                                          const float scale[3])
{
    rc_context *ctx;
    float s[3];
    static const float unit[3] = {1.0f, 1.0f, 1.0f};
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->baked, RC_ERR_MISUSE, "the scene was loaded from a baked map and is read-only");
    RC_RETURN_IF(ctx, inst_id >= scene->inst_count, RC_ERR_OUT_OF_RANGE, "inst_id %u: the scene has %u instances",
                 (unsigned)inst_id, (unsigned)scene->inst_count);
    RC_RETURN_IF(ctx, transform == NULL, RC_ERR_INVALID_ARGUMENT, "transform is NULL");
    RC_TRY(check_instance_pose(ctx, transform, scale ? scale : unit, s));
    instance_set(&scene->insts[inst_id], transform, s);
    scene->committed = 0;
    scene->top_dirty = 1;
    return RC_OK;
}

rc_status rc_scene_commit_with_progress(rc_scene *scene, rc_progress_fn progress, void *user)
{
    rc_context *ctx;
    rc_status st;
    uint32_t i;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, scene->geom_count == 0 && scene->inst_count == 0, RC_ERR_INVALID_ARGUMENT,
                 "scene is empty: add a mesh or an instance before commit");
    for (i = 0; i < scene->inst_count; ++i)
        RC_RETURN_IF(ctx, !scene->insts[i].source->committed, RC_ERR_NOT_COMMITTED,
                     "the source scene of instance %u is not committed", (unsigned)i);
    st = ctx->backend->scene_commit(scene, progress, user);
    if (st != RC_OK) {
        scene->committed = 0;
        return st; /* the backend wrote the message */
    }
    for (i = 0; i < scene->inst_count; ++i) scene->source_versions[i] = scene->insts[i].source->version;
    scene->committed = 1;
    scene->version++;
    return RC_OK;
}

rc_status rc_scene_commit(rc_scene *scene) { return rc_scene_commit_with_progress(scene, NULL, NULL); }

rc_status rc_scene_get_bounds(const rc_scene *scene, float bounds[6])
{
    rc_context *ctx;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, bounds == NULL, RC_ERR_INVALID_ARGUMENT, "bounds is NULL");
    RC_RETURN_IF(ctx, !scene->committed, RC_ERR_NOT_COMMITTED, "scene is not committed");
    memcpy(bounds, scene->bounds.min, 3 * sizeof(float));
    memcpy(bounds + 3, scene->bounds.max, 3 * sizeof(float));
    return RC_OK;
}

size_t rc__scene_accel_bytes(const rc_scene *scene);

rc_status rc_scene_get_info(const rc_scene *scene, rc_scene_info *info)
{
    rc_context *ctx;
    rc_scene_info i;
    uint32_t g;
    if (!rc__scene_valid(scene)) return RC_ERR_INVALID_HANDLE;
    ctx = scene->ctx;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, info == NULL, RC_ERR_INVALID_ARGUMENT, "info is NULL");
    RC_RETURN_IF(ctx, info->struct_size < 8 || info->struct_size > sizeof i, RC_ERR_STRUCT_SIZE,
                 "info->struct_size is %u; expected %u", (unsigned)info->struct_size, (unsigned)sizeof i);
    i = rc_scene_info_default();
    i.geometry_count = scene->geom_count;
    i.instance_count = scene->inst_count;
    i.committed = (uint32_t)rc__scene_up_to_date(scene);
    i.triangle_count = scene->triangle_count;
    for (g = 0; g < scene->geom_count; ++g) i.bvh_nodes += scene->geoms[g].mesh.bvh.node_count;
    i.bvh_nodes += scene->top.node_count;
    i.bytes = rc__scene_object_bytes(&scene->desc) + rc__scene_accel_bytes(scene);
    i.struct_size = info->struct_size;
    memcpy(info, &i, info->struct_size);
    return RC_OK;
}
