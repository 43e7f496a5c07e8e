/* The driver's acceleration structures for the ray query traversal
 * (RC_CONTEXT_VULKAN_RAY_QUERY, kernels/raycast_rq.comp), built at commit
 * beside the packed arrays the compute kernel walks.
 *
 * Bottom levels: one for the scene's own meshes (geometry k = mesh k) and one
 * per scene its instances use, each source once, in the order the packing
 * meets them. Each mesh's triangles go in leaf order, as in the packed
 * triangle array, so the primitive index the query reports is the leaf slot:
 * the kernel reads the prim id from refs and the triangle from tris as after
 * its own walk. Zero-area triangles (rc__tri_zero_area, as the packing decides
 * them) are written (a, a, a), as in the packed arrays. (The spec's way to
 * switch a triangle off, a vertex with a NaN coordinate, made lavapipe 25.0's
 * builder lose whole subtrees: 2,463 of the stability suite's 2,668
 * degenerate-case rays wrong, against 1 with (a, a, a).) Top level: one
 * instance for the own meshes (custom index 0) and one per rangecast instance
 * (custom index = id + 1, transform = source to scene, scale included).
 *
 * The build inputs live in host-visible buffers for the build only; the
 * structures stay in device memory, counted with the backend's buffers and
 * under its budget. Every source's bottom level is this scene's own copy, as
 * the packed arrays are: a source committed again later cannot pull a
 * structure from under this scene. */
#include "backend/vulkan_internal.h"

#include "bvh/intersect.h"

#include <string.h>

/* Instance custom indices have 24 bits; 0 is the own meshes. */
#define MAX_INSTANCES 0xFFFFFEu

static void accel_destroy(rc__vk_state *st, rc__vk_accel *a)
{
    if (a->as != VK_NULL_HANDLE) st->destroy_as(st->device, a->as, RC__VK_OBJ_ALLOC);
    rc__vk_buffer_destroy(st, &a->storage);
    memset(a, 0, sizeof *a);
}

void rc__vk_accel_release(rc__vk_state *st, rc__vk_scene *sv)
{
    uint32_t i;
    if (!st->ray_query) return;
    accel_destroy(st, &sv->tlas);
    for (i = 0; i < sv->blas_count; ++i) accel_destroy(st, &sv->blas[i]);
    if (sv->blas) rc__vk_host_free(st, sv->blas);
    sv->blas = NULL;
    sv->blas_count = 0;
}

/* Creates a structure of the type over n geometries (primitive counts in
 * ranges and counts) and builds it on the device, waiting for the build. */
static rc_status accel_build(rc__vk_state *st, VkAccelerationStructureTypeKHR type, uint32_t n,
                             const VkAccelerationStructureGeometryKHR *geoms,
                             const VkAccelerationStructureBuildRangeInfoKHR *ranges, const uint32_t *counts,
                             const char *what, rc__vk_accel *out)
{
    VkAccelerationStructureBuildGeometryInfoKHR build;
    const VkAccelerationStructureBuildGeometryInfoKHR *info = &build;
    VkAccelerationStructureBuildSizesInfoKHR sizes;
    VkAccelerationStructureCreateInfoKHR ci;
    VkAccelerationStructureDeviceAddressInfoKHR ai;
    rc__vk_buffer scratch;
    VkDeviceAddress at;
    VkResult r;
    rc_status s;
    memset(&build, 0, sizeof build);
    build.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
    build.type = type;
    build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    build.geometryCount = n;
    build.pGeometries = geoms;
    memset(&sizes, 0, sizeof sizes);
    sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    st->as_sizes(st->device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, info, counts, &sizes);
    RC_TRY(rc__vk_buffer_create_usage(st, sizes.accelerationStructureSize, RC__VK_MEM_DEVICE,
                                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                          VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                      what, &out->storage));
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
    ci.buffer = out->storage.buf;
    ci.size = sizes.accelerationStructureSize;
    ci.type = type;
    r = st->create_as(st->device, &ci, RC__VK_OBJ_ALLOC, &out->as);
    if (r != VK_SUCCESS) {
        out->as = VK_NULL_HANDLE;
        accel_destroy(st, out);
        return rc__vk_fail(st, r, "vkCreateAccelerationStructureKHR");
    }
    s = rc__vk_buffer_create_usage(st, sizes.buildScratchSize + st->scratch_align, RC__VK_MEM_DEVICE,
                                   VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, "acceleration structure scratch",
                                   &scratch);
    if (s != RC_OK) {
        accel_destroy(st, out);
        return s;
    }
    at = rc__vk_buffer_address(st, &scratch);
    at = (at + st->scratch_align - 1u) / st->scratch_align * st->scratch_align;
    build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    build.dstAccelerationStructure = out->as;
    build.scratchData.deviceAddress = at;
    s = rc__vk_begin(st, 0);
    if (s == RC_OK) {
        st->build_as(st->cmd[0], 1, info, &ranges);
        /* the next build (a top level over this one) or the kernels read it */
        rc__vk_barrier(st, st->cmd[0], VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        r = vkEndCommandBuffer(st->cmd[0]);
        s = r == VK_SUCCESS ? rc__vk_submit(st, 0) : rc__vk_fail(st, r, "vkEndCommandBuffer");
    }
    if (s == RC_OK) s = rc__vk_wait(st, 0);
    rc__vk_buffer_destroy(st, &scratch);
    if (s != RC_OK) {
        accel_destroy(st, out);
        return s;
    }
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
    ai.accelerationStructure = out->as;
    out->address = st->as_address(st->device, &ai);
    return RC_OK;
}

/* A host-visible buffer a build reads through its device address. */
static rc_status input_buffer(rc__vk_state *st, VkDeviceSize bytes, const char *what, rc__vk_buffer *out)
{
    return rc__vk_buffer_create_usage(st, bytes, RC__VK_MEM_UPLOAD,
                                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                          VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                      what, out);
}

static VkDeviceSize align16(VkDeviceSize x) { return (x + 15u) & ~(VkDeviceSize)15u; }

/* Bytes of one mesh's build input: its vertices, then its triangles' indices. */
static VkDeviceSize mesh_vertex_bytes(const rc__mesh *m) { return align16((VkDeviceSize)m->vertex_count * 12u); }
static VkDeviceSize mesh_index_bytes(const rc__mesh *m) { return align16((VkDeviceSize)m->triangle_count * 12u); }

/* Writes mesh m's input at dst: vertices packed to 3 floats, then the
 * triangles in leaf order (zero-area ones as (a, a, a)). */
static void fill_input(const rc__mesh *m, unsigned char *dst)
{
    float *v = (float *)(void *)dst;
    uint32_t *idx = (uint32_t *)(void *)(dst + mesh_vertex_bytes(m));
    uint32_t i;
    for (i = 0; i < m->vertex_count; ++i) memcpy(v + 3u * i, m->vertices + (size_t)i * m->stride, 3 * sizeof(float));
    for (i = 0; i < m->triangle_count; ++i) {
        const uint32_t *t = m->indices + (size_t)3u * m->bvh.refs[i];
        const int flat = rc__tri_zero_area(m->vertices + (size_t)t[0] * m->stride,
                                           m->vertices + (size_t)t[1] * m->stride,
                                           m->vertices + (size_t)t[2] * m->stride);
        idx[3u * i] = t[0];
        idx[3u * i + 1u] = flat ? t[0] : t[1];
        idx[3u * i + 2u] = flat ? t[0] : t[2];
    }
}

/* The bottom level over a scene's meshes (geometry k = mesh k). */
static rc_status build_bottom(rc__vk_state *st, const rc_scene *src, rc__vk_accel *out)
{
    const uint32_t n = src->geom_count;
    VkAccelerationStructureGeometryKHR *geoms;
    VkAccelerationStructureBuildRangeInfoKHR *ranges;
    uint32_t *counts;
    rc__vk_buffer input;
    VkDeviceSize bytes = 0, at = 0;
    VkDeviceAddress base;
    uint32_t g;
    rc_status s;
    for (g = 0; g < n; ++g) bytes += mesh_vertex_bytes(&src->geoms[g].mesh) + mesh_index_bytes(&src->geoms[g].mesh);
    RC_TRY(input_buffer(st, bytes, "acceleration structure input", &input));
    geoms = (VkAccelerationStructureGeometryKHR *)rc__vk_host_alloc(
        st, (size_t)n * (sizeof *geoms + sizeof *ranges + sizeof *counts));
    if (!geoms) {
        rc__vk_buffer_destroy(st, &input);
        return rc__fail(st->ctx, RC_ERR_OUT_OF_MEMORY, "vulkan: no host memory for %u geometry records", (unsigned)n);
    }
    ranges = (VkAccelerationStructureBuildRangeInfoKHR *)(void *)(geoms + n);
    counts = (uint32_t *)(void *)(ranges + n);
    base = rc__vk_buffer_address(st, &input);
    for (g = 0; g < n; ++g) {
        const rc__mesh *m = &src->geoms[g].mesh;
        VkAccelerationStructureGeometryTrianglesDataKHR *tri = &geoms[g].geometry.triangles;
        fill_input(m, (unsigned char *)input.map + at);
        memset(&geoms[g], 0, sizeof geoms[g]);
        geoms[g].sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
        geoms[g].geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
        geoms[g].flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        tri->sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
        tri->vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        tri->vertexData.deviceAddress = base + at;
        tri->vertexStride = 12;
        tri->maxVertex = m->vertex_count - 1u;
        tri->indexType = VK_INDEX_TYPE_UINT32;
        tri->indexData.deviceAddress = base + at + mesh_vertex_bytes(m);
        memset(&ranges[g], 0, sizeof ranges[g]);
        ranges[g].primitiveCount = m->triangle_count;
        counts[g] = m->triangle_count;
        at += mesh_vertex_bytes(m) + mesh_index_bytes(m);
    }
    s = rc__vk_buffer_flush(st, &input);
    if (s == RC_OK)
        s = accel_build(st, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, n, geoms, ranges, counts,
                        "bottom-level acceleration structure", out);
    rc__vk_host_free(st, geoms);
    rc__vk_buffer_destroy(st, &input);
    return s;
}

static void instance_record(VkAccelerationStructureInstanceKHR *rec, const rc__xformf *to_world, uint32_t custom,
                            VkDeviceAddress blas)
{
    int r;
    memset(rec, 0, sizeof *rec);
    for (r = 0; r < 3; ++r) {
        rec->transform.matrix[r][0] = to_world ? to_world->r[3 * r + 0] : (r == 0 ? 1.0f : 0.0f);
        rec->transform.matrix[r][1] = to_world ? to_world->r[3 * r + 1] : (r == 1 ? 1.0f : 0.0f);
        rec->transform.matrix[r][2] = to_world ? to_world->r[3 * r + 2] : (r == 2 ? 1.0f : 0.0f);
        rec->transform.matrix[r][3] = to_world ? to_world->t[r] : 0.0f;
    }
    rec->instanceCustomIndex = custom;
    rec->mask = 0xFFu;
    rec->instanceShaderBindingTableRecordOffset = 0;
    /* a mirroring scale flips the winding: culling is off either way */
    rec->flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    rec->accelerationStructureReference = blas;
}

static rc_status build_top(rc__vk_state *st, rc_scene *scene, rc__vk_scene *sv)
{
    const uint32_t own = scene->geom_count > 0 ? 1u : 0u, count = own + scene->inst_count;
    VkAccelerationStructureInstanceKHR *recs;
    VkAccelerationStructureGeometryKHR geom;
    VkAccelerationStructureBuildRangeInfoKHR range;
    rc__vk_buffer input;
    uint32_t i;
    rc_status s;
    RC_TRY(input_buffer(st, (VkDeviceSize)count * sizeof *recs, "acceleration structure instances", &input));
    recs = (VkAccelerationStructureInstanceKHR *)input.map;
    if (own) instance_record(&recs[0], NULL, 0u, sv->blas[0].address);
    for (i = 0; i < scene->inst_count; ++i) {
        const rc__instance *in = &scene->insts[i];
        const rc__vk_scene *src = (const rc__vk_scene *)in->source->backend_scene;
        instance_record(&recs[own + i], &in->to_world, i + 1u, sv->blas[src->pack_blas].address);
    }
    s = rc__vk_buffer_flush(st, &input);
    if (s == RC_OK) {
        memset(&geom, 0, sizeof geom);
        geom.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
        geom.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
        geom.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        geom.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
        geom.geometry.instances.arrayOfPointers = VK_FALSE;
        geom.geometry.instances.data.deviceAddress = rc__vk_buffer_address(st, &input);
        memset(&range, 0, sizeof range);
        range.primitiveCount = count;
        s = accel_build(st, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 1, &geom, &range, &count,
                        "top-level acceleration structure", &sv->tlas);
    }
    rc__vk_buffer_destroy(st, &input);
    return s;
}

/* Numbers the bottom levels: the own meshes' (when the scene has any) 0,
 * then each source in packing order (serial tags them for this commit).
 * Returns how many there are. */
static uint32_t number_sources(rc_scene *scene, uint32_t serial)
{
    uint32_t n = scene->geom_count > 0 ? 1u : 0u, i;
    for (i = 0; i < scene->inst_count; ++i) {
        rc__vk_scene *src = (rc__vk_scene *)scene->insts[i].source->backend_scene;
        if (src->accel_serial == serial) continue;
        src->accel_serial = serial;
        src->pack_blas = n++;
    }
    return n;
}

/* 1 when an own mesh changed (changed[g]). */
static int own_changed(const rc_scene *scene, const uint8_t *changed)
{
    uint32_t g;
    for (g = 0; g < scene->geom_count; ++g)
        if (changed[g]) return 1;
    return 0;
}

rc_status rc__vk_accel_update(rc_scene *scene, uint32_t serial, const uint8_t *changed)
{
    rc__vk_state *st = rc__vk(scene->ctx);
    rc__vk_scene *sv = (rc__vk_scene *)scene->backend_scene;
    rc_status s = RC_OK;
    uint32_t i;
    if (number_sources(scene, serial) != sv->blas_count || sv->blas_count == 0) {
        /* not the bottom levels of these sources: build them all, tagged afresh */
        if (++st->serial == 0) ++st->serial;
        return rc__vk_accel_build(scene, st->serial);
    }
    if (changed) {
        /* the own meshes' bottom level when one of them changed, and each
         * source's when it was committed again since the scene's last commit */
        if (scene->geom_count > 0 && own_changed(scene, changed)) {
            accel_destroy(st, &sv->blas[0]);
            s = build_bottom(st, scene, &sv->blas[0]);
        }
        for (i = 0; i < scene->inst_count && s == RC_OK; ++i) {
            const rc_scene *source = scene->insts[i].source;
            rc__vk_scene *src = (rc__vk_scene *)source->backend_scene;
            if (src->accel_serial != serial) continue; /* seen already */
            src->accel_serial = serial - 1u;             /* once */
            if (source->version == scene->source_versions[i]) continue;
            accel_destroy(st, &sv->blas[src->pack_blas]);
            s = build_bottom(st, source, &sv->blas[src->pack_blas]);
        }
    }
    if (s == RC_OK) {
        accel_destroy(st, &sv->tlas);
        s = build_top(st, scene, sv);
    }
    if (s != RC_OK) rc__vk_accel_release(st, sv);
    return s;
}

rc_status rc__vk_accel_build(rc_scene *scene, uint32_t serial)
{
    rc__vk_state *st = rc__vk(scene->ctx);
    rc__vk_scene *sv = (rc__vk_scene *)scene->backend_scene;
    const uint32_t own = scene->geom_count > 0 ? 1u : 0u;
    uint32_t n, i;
    rc_status s = RC_OK;
    rc__vk_accel_release(st, sv);
    RC_RETURN_IF(scene->ctx, scene->inst_count > MAX_INSTANCES, RC_ERR_UNSUPPORTED,
                 "vulkan: the ray query traversal takes at most %u instances a scene (24-bit custom indices); "
                 "this one has %u",
                 (unsigned)MAX_INSTANCES, (unsigned)scene->inst_count);
    n = number_sources(scene, serial);
    sv->blas = (rc__vk_accel *)rc__vk_host_alloc(st, (size_t)n * sizeof *sv->blas);
    RC_RETURN_IF(scene->ctx, sv->blas == NULL, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: no host memory for %u acceleration structure records", (unsigned)n);
    memset(sv->blas, 0, (size_t)n * sizeof *sv->blas);
    sv->blas_count = n;
    if (own) s = build_bottom(st, scene, &sv->blas[0]);
    for (i = 0; i < scene->inst_count && s == RC_OK; ++i) {
        const rc_scene *source = scene->insts[i].source;
        rc__vk_scene *src = (rc__vk_scene *)source->backend_scene;
        if (src->accel_serial != serial) continue; /* built already */
        src->accel_serial = serial - 1u;             /* once */
        s = build_bottom(st, source, &sv->blas[src->pack_blas]);
    }
    if (s == RC_OK) s = build_top(st, scene, sv);
    if (s != RC_OK) rc__vk_accel_release(st, sv);
    return s;
}
