/* Scene commit for the Vulkan backend: build the canonical two-level BVH in
 * the arena (exactly as the BVH backend does), then pack it with the meshes
 * into device buffers (vulkan_pack.c).
 *
 * Large arrays (nodes, triangles, vertices) are split into up to 4 buffers of
 * at most maxStorageBufferRange bytes, one binding each, when the device has
 * the bindings for it (st->chunks); refs, geometries and instances have one
 * binding. Only a scene that needs the split runs the 4-binding kernel (each
 * load picks its binding: a cost on masked-execution devices like lavapipe). A scene that needs more fails with RC_ERR_OUT_OF_MEMORY naming the
 * array and the limit; so does one that does not fit the device heap, which is
 * checked before allocating so it never reaches the driver's limits.
 * With the ray query traversal the commit also builds the driver's
 * acceleration structures (vulkan_accel.c).
 * A commit that keeps the packed layout (a dynamic map: a large static map,
 * a few moving objects, maybe a mesh updated in place) keeps the buffers:
 * after moving instances it rewrites the instance records and the top level
 * and rebuilds only the top-level acceleration structure (its cost is the
 * instances', not the map's); it also rewrites the sections of the meshes
 * that changed, directly where device memory is mapped and through a staging
 * buffer sized to them where it is not.
 * Arena use: the rc__vk_scene record plus the BVH (rc__scene_bvh_commit_bytes). */
#include "backend/vulkan_internal.h"

#include <string.h>

size_t rc__vk_scene_commit_bytes(const rc_scene_desc *desc)
{
    return rc__scene_bvh_commit_bytes(desc) + rc__arena_cost(sizeof(rc__vk_scene));
}

static void release_buffers(rc__vk_state *st, rc__vk_scene *sv)
{
    uint32_t c;
    for (c = 0; c < RC__VK_MAX_CHUNKS; ++c) {
        rc__vk_buffer_destroy(st, &sv->nodes[c]);
        rc__vk_buffer_destroy(st, &sv->tris[c]);
        rc__vk_buffer_destroy(st, &sv->verts[c]);
    }
    rc__vk_buffer_destroy(st, &sv->refs);
    rc__vk_buffer_destroy(st, &sv->geoms);
    rc__vk_buffer_destroy(st, &sv->insts);
    rc__vk_accel_release(st, sv);
    sv->node_chunks = sv->tri_chunks = sv->vert_chunks = sv->chunked = 0;
    memset(&sv->info, 0, sizeof sv->info);
}

void rc__vk_scene_release(rc_scene *scene)
{
    rc__vk_scene *sv = (rc__vk_scene *)scene->backend_scene;
    if (!sv) return;
    release_buffers(rc__vk(scene->ctx), sv);
    rc__vk_host_free(rc__vk(scene->ctx), sv->wide_nodes);
    rc__arena_free(&scene->ctx->arena, sv);
    scene->backend_scene = NULL;
}

/* One packed array: its element count, size and where its buffers go. */
typedef struct array_plan {
    const char *name;
    uint64_t count;
    uint32_t elem_size;
    uint32_t shift;     /* elements per buffer = 2^shift */
    uint32_t max_chunks;
    uint32_t chunks;
    rc__vk_buffer *bufs;
    uint64_t staging_off[RC__VK_MAX_CHUNKS];
} array_plan;

static uint64_t chunk_elems(const array_plan *a, uint32_t c)
{
    const uint64_t per = (uint64_t)1 << a->shift, first = (uint64_t)c * per;
    const uint64_t left = a->count > first ? a->count - first : 0;
    return left < per ? left : per;
}

static rc_status plan_array(rc__vk_state *st, array_plan *a)
{
    const uint64_t per = (uint64_t)1 << a->shift;
    const uint64_t limit = per * a->max_chunks;
    a->chunks = a->count ? (uint32_t)((a->count + per - 1u) / per) : 1u;
    RC_RETURN_IF(st->ctx, a->count > limit || a->count > 0xFFFFFFFFu, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: the scene needs %llu %s (%llu bytes); %s holds at most %llu in %u binding%s of "
                 "maxStorageBufferRange = %llu bytes",
                 (unsigned long long)a->count, a->name, (unsigned long long)a->count * a->elem_size, st->device_name,
                 (unsigned long long)(limit < 0xFFFFFFFFu ? limit : 0xFFFFFFFFu), (unsigned)a->max_chunks,
                 a->max_chunks > 1 ? "s" : "", (unsigned long long)st->max_binding);
    return RC_OK;
}

static void span_of(const array_plan *a, const rc__vk_buffer *staging, rc__vk_span *s)
{
    uint32_t c;
    memset(s, 0, sizeof *s);
    s->shift = a->shift;
    s->elem_size = a->elem_size;
    for (c = 0; c < a->chunks; ++c)
        s->chunk[c] = staging ? (unsigned char *)staging->map + a->staging_off[c] : (unsigned char *)a->bufs[c].map;
}

/* 1 when the device arrays hold this scene as of its last successful commit
 * and the packed layout can stay: no mesh or instance added since (a mesh
 * updated in place, or a source committed again, keeps the counts). */
static int layout_kept(const rc_scene *scene, const rc__vk_scene *sv)
{
    return sv->current && sv->info.geom_count == scene->geom_count && sv->info.insts == scene->inst_count;
}

/* changed[g] = own mesh g changed since the last commit (read before the
 * build, which clears the dirty marks); returns 1 when a mesh changed, own
 * or in an instanced source committed again since. */
static int meshes_changed(const rc_scene *scene, uint8_t *changed)
{
    uint32_t i;
    int any = 0;
    for (i = 0; i < scene->geom_count; ++i) {
        changed[i] = scene->geoms[i].dirty != 0;
        any |= changed[i];
    }
    for (i = 0; i < scene->inst_count; ++i) any |= scene->insts[i].source->version != scene->source_versions[i];
    return any;
}

/* A span over one device array's buffers (mapped, or a staging map). */
static rc__vk_span span_over(const rc__vk_buffer *bufs, uint32_t chunks, uint32_t shift, uint32_t elem_size)
{
    rc__vk_span sp;
    uint32_t c;
    memset(&sp, 0, sizeof sp);
    sp.shift = shift;
    sp.elem_size = elem_size;
    for (c = 0; c < chunks; ++c) sp.chunk[c] = (unsigned char *)bufs[c].map;
    return sp;
}

/* Copies count elements of a chunked device array from staging (at src_off)
 * to element first on, chunk by chunk. */
static rc_status copy_chunked(rc__vk_state *st, const rc__vk_buffer *staging, VkDeviceSize src_off,
                              const rc__vk_buffer *bufs, uint32_t shift, uint32_t elem_size, uint64_t first,
                              uint64_t count)
{
    const uint64_t per = (uint64_t)1 << shift;
    while (count) {
        const uint64_t c = first >> shift, off = first & (per - 1u), n = count < per - off ? count : per - off;
        RC_TRY(rc__vk_copy_region(st, staging, &bufs[c], src_off, off * elem_size, n * elem_size));
        src_off += n * elem_size;
        first += n;
        count -= n;
    }
    return RC_OK;
}

/* Host memory the pack collapses each mesh's tree into (info->max_wide
 * nodes), needed only where the nodes span several bindings (chunks > 1): a
 * section may then straddle two; else NULL, and each tree is collapsed in
 * place. */
static rc_status wide_scratch(rc__vk_state *st, const rc__vk_pack_info *info, uint32_t chunks, rc__wnode **out)
{
    const uint64_t bytes = info->max_wide * sizeof(rc__wnode);
    *out = NULL;
    if (chunks <= 1) return RC_OK;
    *out = bytes == (size_t)bytes ? (rc__wnode *)rc__vk_host_alloc(st, (size_t)(bytes ? bytes : 1u)) : NULL;
    RC_RETURN_IF(st->ctx, *out == NULL, RC_ERR_OUT_OF_MEMORY,
                 "rc_scene_commit: no host memory to collapse a mesh's BVH for Vulkan (%llu bytes)",
                 (unsigned long long)bytes);
    return RC_OK;
}

/* Upper bound of the meshes rc__vk_pack_changed can name (a source
 * instanced twice counts twice). */
static uint32_t sections_bound(const rc_scene *scene)
{
    uint32_t i, n = scene->geom_count;
    for (i = 0; i < scene->inst_count; ++i) n += scene->insts[i].source->geom_count;
    return n;
}

static uint64_t align16(uint64_t n) { return (n + 15u) & ~(uint64_t)15u; }

/* Staging bytes for one mesh's sections, each 16-aligned. */
static uint64_t section_bytes(const rc__vk_section *m)
{
    return align16(sizeof(rc__vk_geom)) + align16(m->nodes * sizeof(rc__bvh_node)) + align16(m->refs * 4u) +
           align16(m->tris * 12u) + align16(m->verts * 12u);
}

/* A span over one section of an array, at off in the staging buffer. */
static rc__vk_span span_section(const rc__vk_buffer *staging, uint64_t off, uint64_t first, uint32_t elem_size)
{
    rc__vk_span sp;
    memset(&sp, 0, sizeof sp);
    sp.chunk[0] = (unsigned char *)staging->map + off;
    sp.shift = 62u; /* one chunk */
    sp.elem_size = elem_size;
    sp.base = first;
    return sp;
}

/* Writes the meshes' sections into staging from off on and copies them into the
 * device arrays (discrete GPUs: only what changed crosses the bus). */
static rc_status stage_sections(rc__vk_state *st, rc__vk_scene *sv, const rc__vk_section *m, uint32_t n,
                                const rc__vk_buffer *staging, uint64_t off, rc__wnode *scratch)
{
    uint32_t k;
    rc_status s = RC_OK;
    for (k = 0; k < n && s == RC_OK; ++k) {
        const uint64_t o_geom = off, o_node = o_geom + align16(sizeof(rc__vk_geom));
        const uint64_t o_ref = o_node + align16(m[k].nodes * sizeof(rc__bvh_node));
        const uint64_t o_tri = o_ref + align16(m[k].refs * 4u), o_vert = o_tri + align16(m[k].tris * 12u);
        rc__vk_pack_dst dst;
        memset(&dst, 0, sizeof dst);
        dst.geoms = span_section(staging, o_geom, m[k].geom, (uint32_t)sizeof(rc__vk_geom));
        dst.nodes = span_section(staging, o_node, m[k].node, (uint32_t)sizeof(rc__bvh_node));
        dst.refs = span_section(staging, o_ref, m[k].ref, 4u);
        dst.tris = span_section(staging, o_tri, m[k].tri, 12u);
        dst.verts = span_section(staging, o_vert, m[k].vert, 12u);
        dst.wide_scratch = scratch;
        rc__vk_pack_section(&m[k], &dst);
        s = rc__vk_copy_region(st, staging, &sv->geoms, o_geom, m[k].geom * sizeof(rc__vk_geom),
                               sizeof(rc__vk_geom));
        if (s == RC_OK && m[k].nodes)
            s = copy_chunked(st, staging, o_node, sv->nodes, st->node_shift, (uint32_t)sizeof(rc__bvh_node), m[k].node,
                             m[k].nodes);
        if (s == RC_OK && m[k].refs) s = rc__vk_copy_region(st, staging, &sv->refs, o_ref, m[k].ref * 4u, m[k].refs * 4u);
        if (s == RC_OK && m[k].tris) s = copy_chunked(st, staging, o_tri, sv->tris, st->tri_shift, 12u, m[k].tri, m[k].tris);
        if (s == RC_OK && m[k].verts)
            s = copy_chunked(st, staging, o_vert, sv->verts, st->vert_shift, 12u, m[k].vert, m[k].verts);
        off += section_bytes(&m[k]);
    }
    return s;
}

/* A commit that keeps the packed layout, in place: the instance records and
 * the top level rewritten, and with changed (not NULL) the sections of the
 * meshes that changed too (and, for ray query, their bottom levels built
 * again); the rest of the device arrays and bottom levels kept. Mapped device
 * memory is written directly; otherwise what changes goes through one
 * staging buffer and region copies. *done 0 when the layout differs after
 * all (the caller uploads everything). */
static rc_status update_in_place(rc__vk_state *st, rc_scene *scene, rc__vk_scene *sv, const uint8_t *changed,
                                 int *done)
{
    rc__vk_pack_info info;
    rc__vk_pack_dst dst;
    rc__vk_buffer staging;
    rc__vk_section *meshes = NULL;
    const uint64_t inst_bytes = (uint64_t)scene->inst_count * sizeof(rc__vk_inst);
    const uint64_t node_bytes = (uint64_t)scene->top.node_count * sizeof(rc__bvh_node);
    const uint64_t ref_bytes = (uint64_t)scene->top.item_count * 4u;
    uint32_t serial, c, n = 0, k;
    rc_status s = RC_OK;
    *done = 0;
    if (++st->serial == 0) ++st->serial;
    serial = st->serial;
    rc__vk_pack_count(scene, serial, &info);
    if (memcmp(&info, &sv->info, sizeof info) != 0) return RC_OK;
    *done = 1;
    if (changed) {
        const uint32_t bound = sections_bound(scene);
        meshes = (rc__vk_section *)rc__vk_host_alloc(st, (size_t)(bound ? bound : 1u) * sizeof *meshes);
        RC_RETURN_IF(st->ctx, meshes == NULL, RC_ERR_OUT_OF_MEMORY,
                     "rc_scene_commit: no host memory for the Vulkan commit's list of %u meshes", (unsigned)bound);
        n = rc__vk_pack_changed(scene, serial, changed, meshes, bound);
    }
    memset(&dst, 0, sizeof dst);
    if (n) {
        /* staged sections are one chunk each */
        s = wide_scratch(st, &info, st->device_mappable ? sv->node_chunks : 1u, &dst.wide_scratch);
        if (s != RC_OK) {
            rc__vk_host_free(st, meshes);
            return s;
        }
    }
    if (st->device_mappable) {
        dst.nodes = span_over(sv->nodes, sv->node_chunks, st->node_shift, (uint32_t)sizeof(rc__bvh_node));
        dst.tris = span_over(sv->tris, sv->tri_chunks, st->tri_shift, 12u);
        dst.verts = span_over(sv->verts, sv->vert_chunks, st->vert_shift, 12u);
        dst.refs = span_over(&sv->refs, 1, 31u, 4u);
        dst.geoms = span_over(&sv->geoms, 1, 31u, (uint32_t)sizeof(rc__vk_geom));
        dst.insts = span_over(&sv->insts, 1, 31u, (uint32_t)sizeof(rc__vk_inst));
        for (k = 0; k < n; ++k) rc__vk_pack_section(&meshes[k], &dst);
        rc__vk_pack_fill_top(scene, &info, &dst);
        for (c = 0; c < RC__VK_MAX_CHUNKS && s == RC_OK; ++c) {
            if (c < sv->node_chunks) s = rc__vk_buffer_flush(st, &sv->nodes[c]);
            if (s == RC_OK && n && c < sv->tri_chunks) s = rc__vk_buffer_flush(st, &sv->tris[c]);
            if (s == RC_OK && n && c < sv->vert_chunks) s = rc__vk_buffer_flush(st, &sv->verts[c]);
        }
        if (s == RC_OK) s = rc__vk_buffer_flush(st, &sv->refs);
        if (s == RC_OK) s = rc__vk_buffer_flush(st, &sv->geoms);
        if (s == RC_OK) s = rc__vk_buffer_flush(st, &sv->insts);
    } else {
        /* staged: records, top nodes and refs one after another, then the
         * changed meshes' sections, then copied */
        const uint64_t node_off = (inst_bytes + 31u) & ~(uint64_t)31u, ref_off = node_off + node_bytes;
        uint64_t bytes = align16(ref_off + ref_bytes);
        const uint64_t mesh_off = bytes;
        for (k = 0; k < n; ++k) bytes += section_bytes(&meshes[k]);
        s = rc__vk_buffer_create(st, bytes, RC__VK_MEM_UPLOAD, "upload staging", &staging);
        if (s == RC_OK) {
            dst.insts = span_over(&staging, 1, 31u, (uint32_t)sizeof(rc__vk_inst));
            dst.nodes = span_over(&staging, 1, 31u, (uint32_t)sizeof(rc__bvh_node));
            dst.refs = span_over(&staging, 1, 31u, 4u);
            /* the top level at the start of its staging section, not at its index */
            info.top_node = (uint32_t)(node_off / sizeof(rc__bvh_node));
            info.top_ref = (uint32_t)(ref_off / 4u);
            rc__vk_pack_fill_top(scene, &info, &dst);
            s = stage_sections(st, sv, meshes, n, &staging, mesh_off, dst.wide_scratch);
            if (s == RC_OK && inst_bytes) s = rc__vk_copy_region(st, &staging, &sv->insts, 0, 0, inst_bytes);
            if (s == RC_OK)
                s = copy_chunked(st, &staging, node_off, sv->nodes, st->node_shift, (uint32_t)sizeof(rc__bvh_node),
                                 sv->info.top_node, scene->top.node_count);
            if (s == RC_OK && ref_bytes) /* a copy of 0 bytes is not valid Vulkan */
                s = rc__vk_copy_region(st, &staging, &sv->refs, ref_off, (uint64_t)sv->info.top_ref * 4u,
                                       ref_bytes);
            rc__vk_buffer_destroy(st, &staging);
        }
    }
    rc__vk_host_free(st, meshes);
    rc__vk_host_free(st, dst.wide_scratch);
    if (s == RC_OK && st->ray_query)
        s = rc__vk_accel_update(scene, serial, changed);
    return s;
}

rc_status rc__vk_scene_commit(rc_scene *scene, rc_progress_fn progress, void *user)
{
    rc_context *ctx = scene->ctx;
    rc__vk_state *st = rc__vk(ctx);
    rc__vk_scene *sv = (rc__vk_scene *)scene->backend_scene;
    rc__vk_pack_info info;
    rc__vk_pack_dst dst;
    rc__vk_buffer staging;
    array_plan arrays[6];
    uint64_t staging_bytes = 0;
    uint32_t serial, a, c;
    rc_status s = RC_OK;

    RC_RETURN_IF(ctx, st->lost, RC_ERR_DEVICE_LOST, "vulkan: the device was lost; destroy the context");
    if (!sv) {
        sv = (rc__vk_scene *)rc__arena_calloc(&ctx->arena, sizeof *sv);
        RC_RETURN_IF(ctx, sv == NULL, RC_ERR_OUT_OF_MEMORY,
                     "arena has no room for the Vulkan scene record (%llu bytes; largest free block %llu)",
                     (unsigned long long)rc__arena_cost(sizeof *sv),
                     (unsigned long long)rc__arena_largest_free(&ctx->arena));
        scene->backend_scene = sv;
    }
    {
        /* what the last upload lets this commit keep, judged before the build */
        int in_place = layout_kept(scene, sv), changed_meshes = 0, done = 0, moved = 0;
        uint8_t *changed = (uint8_t *)rc__vk_host_alloc(st, scene->geom_count + 1u);
        if (changed) changed_meshes = meshes_changed(scene, changed);
        /* what changed is rewritten in place: directly where device memory
         * is mapped (UMA boards, lavapipe), else through staging */
        in_place = in_place && changed != NULL;
        sv->current = 0; /* until this commit succeeds */
        s = rc__scene_build_bvh(scene, progress, user);
        /* the trees built again: their wide node counts (all without the marks) */
        if (s == RC_OK) s = rc__vk_wide_counts(st, scene, changed, &moved);
        if (moved) in_place = 0;
        if (s == RC_OK && in_place) {
            s = update_in_place(st, scene, sv, changed_meshes ? changed : NULL, &done);
            if (s != RC_OK) release_buffers(st, sv);
        }
        rc__vk_host_free(st, changed);
        if (s != RC_OK) return s;
        if (done) {
            if (changed_meshes)
                sv->mesh_updates++;
            else
                sv->top_updates++;
            sv->current = 1;
            return RC_OK;
        }
    }
    release_buffers(st, sv);

    if (++st->serial == 0) ++st->serial;
    serial = st->serial;
    rc__vk_pack_count(scene, serial, &info);

    memset(arrays, 0, sizeof arrays);
    arrays[0].name = "BVH nodes";
    arrays[0].count = info.nodes;
    arrays[0].elem_size = (uint32_t)sizeof(rc__bvh_node);
    arrays[0].shift = st->node_shift;
    arrays[0].max_chunks = st->chunks;
    arrays[0].bufs = sv->nodes;
    arrays[1].name = "triangles";
    arrays[1].count = info.tris;
    arrays[1].elem_size = 12u;
    arrays[1].shift = st->tri_shift;
    arrays[1].max_chunks = st->chunks;
    arrays[1].bufs = sv->tris;
    arrays[2].name = "vertices";
    arrays[2].count = info.verts;
    arrays[2].elem_size = 12u;
    arrays[2].shift = st->vert_shift;
    arrays[2].max_chunks = st->chunks;
    arrays[2].bufs = sv->verts;
    arrays[3].name = "BVH refs";
    arrays[3].count = info.refs;
    arrays[3].elem_size = 4u;
    arrays[3].bufs = &sv->refs;
    arrays[4].name = "geometry records";
    arrays[4].count = info.geoms;
    arrays[4].elem_size = (uint32_t)sizeof(rc__vk_geom);
    arrays[4].bufs = &sv->geoms;
    arrays[5].name = "instance records";
    arrays[5].count = info.insts;
    arrays[5].elem_size = (uint32_t)sizeof(rc__vk_inst);
    arrays[5].bufs = &sv->insts;
    for (a = 3; a < 6; ++a) { /* one binding each */
        uint64_t bytes = st->max_binding < st->max_alloc ? st->max_binding : st->max_alloc;
        uint32_t shift = 0;
        while (shift < 31u && ((uint64_t)2 << shift) * arrays[a].elem_size <= bytes) ++shift;
        arrays[a].shift = shift;
        arrays[a].max_chunks = 1;
    }
    for (a = 0; a < 6; ++a) RC_TRY(plan_array(st, &arrays[a]));

    /* Device buffers (every array gets at least one, so each binding is valid). */
    for (a = 0; a < 6 && s == RC_OK; ++a)
        for (c = 0; c < arrays[a].chunks && s == RC_OK; ++c) {
            const uint64_t bytes = chunk_elems(&arrays[a], c) * arrays[a].elem_size;
            arrays[a].staging_off[c] = staging_bytes;
            staging_bytes += (bytes + 15u) & ~(uint64_t)15u;
            s = rc__vk_buffer_create(st, bytes, RC__VK_MEM_DEVICE, arrays[a].name, &arrays[a].bufs[c]);
        }
    sv->node_chunks = arrays[0].chunks;
    sv->tri_chunks = arrays[1].chunks;
    sv->vert_chunks = arrays[2].chunks;
    sv->chunked = sv->node_chunks > 1 || sv->tri_chunks > 1 || sv->vert_chunks > 1;
    if (s != RC_OK) goto fail;

    memset(&staging, 0, sizeof staging);
    if (!st->device_mappable) {
        s = rc__vk_buffer_create(st, staging_bytes, RC__VK_MEM_UPLOAD, "upload staging", &staging);
        if (s != RC_OK) goto fail;
    }
    span_of(&arrays[0], st->device_mappable ? NULL : &staging, &dst.nodes);
    span_of(&arrays[1], st->device_mappable ? NULL : &staging, &dst.tris);
    span_of(&arrays[2], st->device_mappable ? NULL : &staging, &dst.verts);
    span_of(&arrays[3], st->device_mappable ? NULL : &staging, &dst.refs);
    span_of(&arrays[4], st->device_mappable ? NULL : &staging, &dst.geoms);
    span_of(&arrays[5], st->device_mappable ? NULL : &staging, &dst.insts);
    s = wide_scratch(st, &info, arrays[0].chunks, &dst.wide_scratch);
    if (s != RC_OK) {
        rc__vk_buffer_destroy(st, &staging);
        goto fail;
    }
    rc__vk_pack_fill(scene, serial, &info, &dst);
    rc__vk_host_free(st, dst.wide_scratch);

    for (a = 0; a < 6 && s == RC_OK; ++a)
        for (c = 0; c < arrays[a].chunks && s == RC_OK; ++c) {
            const uint64_t bytes = chunk_elems(&arrays[a], c) * arrays[a].elem_size;
            if (st->device_mappable)
                s = rc__vk_buffer_flush(st, &arrays[a].bufs[c]);
            else if (bytes)
                s = rc__vk_copy(st, &staging, &arrays[a].bufs[c], arrays[a].staging_off[c], bytes);
        }
    rc__vk_buffer_destroy(st, &staging);
    if (s == RC_OK && st->ray_query) s = rc__vk_accel_build(scene, serial);
    if (s != RC_OK) goto fail;
    sv->info = info;
    sv->full_uploads++;
    sv->current = 1;
    return RC_OK;
fail:
    release_buffers(st, sv);
    return s;
}
