/* Pipelines and rc_simulate on the Vulkan backend.
 *
 * One pipeline per (attribute mask, ray model, 1- or 4-binding kernel),
 * specialised at creation (workgroup size, mask, model, chunk sizes) and
 * cached. A call uploads its poses' sensor-to-scene transforms (pose * mount
 * minus the scene's origin, composed in double on the host; 12 floats for the
 * rays and 12 doubles for the float64 refinement of each hit's distance),
 * then runs the whole batch as few dispatches as the result buffers allow:
 * element k = pose * rays + ray is one invocation, and a dispatch covers a
 * contiguous range of k. With more than one dispatch, two result buffers
 * alternate so the host copies one while the device fills the other. Results
 * are written as 32-bit words (hits as 0/1 words, floats by their bits) into
 * host-visible, host-cached memory and copied into the caller's arrays (hits
 * narrowed to bytes). */
#include "backend/vulkan_internal.h"

#include "noise/noise.h"

#include <math.h>
#include <string.h>

static void layout_binding(VkDescriptorSetLayoutBinding *b, uint32_t binding, VkDescriptorType type)
{
    memset(b, 0, sizeof *b);
    b->binding = binding;
    b->descriptorType = type;
    b->descriptorCount = 1;
    b->stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
}

rc_status rc__vk_pipelines_create(rc__vk_state *st)
{
    VkDescriptorSetLayoutBinding b[RC__VK_BINDINGS + 1u];
    VkDescriptorSetLayoutCreateInfo sli;
    VkPushConstantRange pcr;
    VkPipelineLayoutCreateInfo pli;
    VkDescriptorPoolSize ps[2];
    VkDescriptorPoolCreateInfo dpi;
    VkShaderModuleCreateInfo smi;
    VkPipelineCacheCreateInfo pci;
    uint32_t i, n = 0;
    size_t bytes = 0;

    for (i = 0; i < RC__VK_BINDINGS; ++i) {
        const int chunk_slot = i < 12u && (i % 4u) != 0u;
        if (chunk_slot && st->chunks == 1) continue; /* the 1-binding kernel declares only 0, 4, 8 */
        layout_binding(&b[n++], i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    }
    if (st->ray_query) layout_binding(&b[n++], RC__VK_BIND_TLAS, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR);
    memset(&sli, 0, sizeof sli);
    sli.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    sli.bindingCount = n;
    sli.pBindings = b;
    RC__VK_TRY(st, vkCreateDescriptorSetLayout(st->device, &sli, RC__VK_OBJ_ALLOC, &st->set_layout),
               "vkCreateDescriptorSetLayout");
    memset(&pcr, 0, sizeof pcr);
    pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pcr.size = (uint32_t)sizeof(rc__vk_push);
    memset(&pli, 0, sizeof pli);
    pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &st->set_layout;
    pli.pushConstantRangeCount = 1;
    pli.pPushConstantRanges = &pcr;
    RC__VK_TRY(st, vkCreatePipelineLayout(st->device, &pli, RC__VK_OBJ_ALLOC, &st->pipe_layout), "vkCreatePipelineLayout");
    ps[0].type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    ps[0].descriptorCount = (RC__VK_SLOTS + 1u) * RC__VK_BINDINGS;
    ps[1].type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    ps[1].descriptorCount = RC__VK_SLOTS + 1u;
    memset(&dpi, 0, sizeof dpi);
    dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpi.maxSets = RC__VK_SLOTS + 1u;
    dpi.poolSizeCount = st->ray_query ? 2u : 1u;
    dpi.pPoolSizes = ps;
    RC__VK_TRY(st, vkCreateDescriptorPool(st->device, &dpi, RC__VK_OBJ_ALLOC, &st->desc_pool), "vkCreateDescriptorPool");
    for (i = 0; i < (st->chunks > 1 ? 2u : 1u); ++i) {
        memset(&smi, 0, sizeof smi);
        smi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        smi.pCode = rc__vk_raycast_spirv((int)st->fp64, i ? RC__VK_MAX_CHUNKS : 1u, (int)st->ray_query, &bytes);
        smi.codeSize = bytes;
        RC__VK_TRY(st, vkCreateShaderModule(st->device, &smi, RC__VK_OBJ_ALLOC, &st->module[i]), "vkCreateShaderModule");
    }
    memset(&pci, 0, sizeof pci);
    pci.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    RC__VK_TRY(st, vkCreatePipelineCache(st->device, &pci, RC__VK_OBJ_ALLOC, &st->cache), "vkCreatePipelineCache");
    return RC_OK;
}

void rc__vk_pipelines_destroy(rc__vk_state *st)
{
    uint32_t i;
    if (st->device == VK_NULL_HANDLE) return;
    for (i = 0; i < RC__VK_PIPELINES; ++i) {
        if (st->pipes[i].pipe != VK_NULL_HANDLE) vkDestroyPipeline(st->device, st->pipes[i].pipe, RC__VK_OBJ_ALLOC);
        memset(&st->pipes[i], 0, sizeof st->pipes[i]);
    }
    if (st->cache != VK_NULL_HANDLE) vkDestroyPipelineCache(st->device, st->cache, RC__VK_OBJ_ALLOC);
    for (i = 0; i < 2; ++i) {
        if (st->module[i] != VK_NULL_HANDLE) vkDestroyShaderModule(st->device, st->module[i], RC__VK_OBJ_ALLOC);
        st->module[i] = VK_NULL_HANDLE;
    }
    if (st->desc_pool != VK_NULL_HANDLE) vkDestroyDescriptorPool(st->device, st->desc_pool, RC__VK_OBJ_ALLOC);
    if (st->pipe_layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(st->device, st->pipe_layout, RC__VK_OBJ_ALLOC);
    if (st->set_layout != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(st->device, st->set_layout, RC__VK_OBJ_ALLOC);
    st->cache = VK_NULL_HANDLE;
    st->desc_pool = VK_NULL_HANDLE;
    st->pipe_layout = VK_NULL_HANDLE;
    st->set_layout = VK_NULL_HANDLE;
}

static rc_status get_pipeline(rc__vk_state *st, uint32_t attributes, uint32_t model, uint32_t chunked,
                              VkPipeline *out)
{
    VkSpecializationMapEntry map[6];
    VkSpecializationInfo spec;
    VkComputePipelineCreateInfo ci;
    uint32_t values[6];
    rc__vk_pipeline *slot = NULL;
    uint32_t i;
    ++st->clock;
    for (i = 0; i < RC__VK_PIPELINES; ++i) {
        rc__vk_pipeline *p = &st->pipes[i];
        if (p->pipe != VK_NULL_HANDLE && p->attributes == attributes && p->model == model && p->chunked == chunked) {
            p->last_use = st->clock;
            *out = p->pipe;
            return RC_OK;
        }
    }
    for (i = 0; i < RC__VK_PIPELINES; ++i) {
        rc__vk_pipeline *p = &st->pipes[i];
        if (p->pipe == VK_NULL_HANDLE) {
            slot = p;
            break;
        }
        if (!slot || p->last_use < slot->last_use) slot = p;
    }
    if (slot->pipe != VK_NULL_HANDLE) vkDestroyPipeline(st->device, slot->pipe, RC__VK_OBJ_ALLOC);
    memset(slot, 0, sizeof *slot);
    values[0] = st->wg_size;
    values[1] = attributes;
    values[2] = model;
    values[3] = st->node_shift;
    values[4] = st->tri_shift;
    values[5] = st->vert_shift;
    for (i = 0; i < 6; ++i) {
        map[i].constantID = i;
        map[i].offset = i * 4u;
        map[i].size = 4;
    }
    memset(&spec, 0, sizeof spec);
    spec.mapEntryCount = 6;
    spec.pMapEntries = map;
    spec.dataSize = sizeof values;
    spec.pData = values;
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = st->module[chunked ? 1 : 0];
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = &spec;
    ci.layout = st->pipe_layout;
    if (st->stats) ci.flags = VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
    RC__VK_TRY(st, vkCreateComputePipelines(st->device, st->cache, 1, &ci, RC__VK_OBJ_ALLOC, &slot->pipe),
               "vkCreateComputePipelines");
    if (st->stats) rc__vk_stats_log(st, slot->pipe, attributes, model);
    slot->attributes = attributes;
    slot->model = model;
    slot->chunked = chunked;
    slot->last_use = st->clock;
    *out = slot->pipe;
    return RC_OK;
}

/* Words per element of each attribute, in RC_ATTR_* bit order. */
static const uint32_t attr_words[7] = {1, 1, 3, 3, 1, 1, 1};

static void write_sets(rc__vk_state *st, const rc__vk_scene *sv, const rc__vk_sensor_slot *table, VkDescriptorSet set,
                       const rc__vk_buffer *out)
{
    VkDescriptorBufferInfo info[RC__VK_BINDINGS];
    VkWriteDescriptorSet w[RC__VK_BINDINGS + 1u];
    VkWriteDescriptorSetAccelerationStructureKHR wa;
    uint32_t i, n = 0;
    for (i = 0; i < RC__VK_BINDINGS; ++i) {
        const rc__vk_buffer *b;
        const uint32_t c = i % 4u;
        if (i < 12u && c != 0u && st->chunks == 1) continue;
        if (i < 4u)
            b = &sv->nodes[c < sv->node_chunks ? c : 0];
        else if (i < 8u)
            b = &sv->tris[c < sv->tri_chunks ? c : 0];
        else if (i < 12u)
            b = &sv->verts[c < sv->vert_chunks ? c : 0];
        else if (i == RC__VK_BIND_REFS)
            b = &sv->refs;
        else if (i == RC__VK_BIND_GEOMS)
            b = &sv->geoms;
        else if (i == RC__VK_BIND_INSTS)
            b = &sv->insts;
        else if (i == RC__VK_BIND_XFORMS)
            b = &st->xforms;
        else if (i == RC__VK_BIND_RAYS)
            b = &table->table;
        else
            b = out;
        info[n].buffer = b->buf;
        info[n].offset = 0;
        info[n].range = b->size;
        memset(&w[n], 0, sizeof w[n]);
        w[n].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[n].dstSet = set;
        w[n].dstBinding = i;
        w[n].descriptorCount = 1;
        w[n].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[n].pBufferInfo = &info[n];
        ++n;
    }
    if (st->ray_query) {
        memset(&wa, 0, sizeof wa);
        wa.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
        wa.accelerationStructureCount = 1;
        wa.pAccelerationStructures = &sv->tlas.as;
        memset(&w[n], 0, sizeof w[n]);
        w[n].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[n].pNext = &wa;
        w[n].dstSet = set;
        w[n].dstBinding = RC__VK_BIND_TLAS;
        w[n].descriptorCount = 1;
        w[n].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
        ++n;
    }
    vkUpdateDescriptorSets(st->device, n, w, 0, NULL);
}

/* A dispatch in flight: which elements its slot holds. */
typedef struct pending {
    uint64_t first;
    uint32_t count;
    uint32_t busy;
} pending;

/* Section offsets (words) of a dispatch of n elements. */
static void sections(uint32_t attributes, uint32_t n, uint32_t off[7])
{
    uint32_t a, at = 0;
    for (a = 0; a < 7; ++a) {
        off[a] = at;
        if (attributes & (1u << a)) at += attr_words[a] * n;
    }
}

/* Copying a slot out is the host's share of a call, and for large batches the
 * larger share: 10,000 VLP-16 poses are 576 MB of ranges, which one thread
 * copied at about 7 GB/s out of the H100's host-visible memory, so the copy
 * and not the GPU set the pace (docs/benchmarks.md). Pieces of 64k elements
 * go to the context's pool; a slot smaller than that stays on the caller's
 * thread and wakes nobody. */
#define RC__VK_COPY_PIECE 65536u

typedef struct copy_run {
    const rc_results *r;
    const uint32_t *src;
    uint32_t off[7];
    uint32_t attributes;
    uint32_t n;  /* elements in the slot */
    uint64_t k;  /* the slot's first element in the caller's arrays */
} copy_run;

static void copy_task(void *user, uint32_t task, uint32_t thread)
{
    const copy_run *c = (const copy_run *)user;
    const rc_results *r = c->r;
    const uint32_t *src = c->src;
    const uint32_t i0 = task * RC__VK_COPY_PIECE;
    const uint32_t n = c->n - i0 < RC__VK_COPY_PIECE ? c->n - i0 : RC__VK_COPY_PIECE;
    const uint64_t k = c->k + i0;
    uint32_t i;
    (void)thread;
    if (c->attributes & RC_ATTR_HITS) {
        const uint32_t *h = src + c->off[0] + i0;
        uint8_t *d = r->hits + k;
        for (i = 0; i < n; ++i) d[i] = (uint8_t)h[i];
    }
    if (c->attributes & RC_ATTR_RANGES) memcpy(r->ranges + k, src + c->off[1] + i0, (size_t)n * 4u);
    if (c->attributes & RC_ATTR_POINTS) memcpy(r->points + 3u * k, src + c->off[2] + 3u * i0, (size_t)n * 12u);
    if (c->attributes & RC_ATTR_NORMALS) memcpy(r->normals + 3u * k, src + c->off[3] + 3u * i0, (size_t)n * 12u);
    if (c->attributes & RC_ATTR_PRIM_IDS) memcpy(r->prim_ids + k, src + c->off[4] + i0, (size_t)n * 4u);
    if (c->attributes & RC_ATTR_GEOM_IDS) memcpy(r->geom_ids + k, src + c->off[5] + i0, (size_t)n * 4u);
    if (c->attributes & RC_ATTR_INST_IDS) memcpy(r->inst_ids + k, src + c->off[6] + i0, (size_t)n * 4u);
}

static rc_status copy_out(rc__vk_state *st, const rc__sim_job *job, uint32_t slot, const pending *p)
{
    copy_run c;
    RC_TRY(rc__vk_buffer_invalidate(st, &st->out[slot]));
    c.r = job->out;
    c.src = (const uint32_t *)st->out[slot].map;
    c.attributes = job->attributes;
    c.n = p->count;
    c.k = p->first;
    sections(job->attributes, c.n, c.off);
    rc__pool_run(st->ctx->pool, (c.n + RC__VK_COPY_PIECE - 1u) / RC__VK_COPY_PIECE, copy_task, &c);
    return RC_OK;
}

/* A buffer of at least bytes (at most cap), kept across calls. */
static rc_status ensure_buffer(rc__vk_state *st, rc__vk_buffer *b, uint64_t bytes, uint64_t cap, uint32_t kind,
                               const char *what)
{
    if (b->buf != VK_NULL_HANDLE && b->size >= bytes) return RC_OK;
    rc__vk_buffer_destroy(st, b);
    /* grow by half again so a slowly growing batch does not reallocate every call */
    if (bytes < cap) bytes = bytes + bytes / 2u < cap ? bytes + bytes / 2u : cap;
    return rc__vk_buffer_create(st, bytes, kind, what, b);
}

/* Handle values as the public struct carries them (pointers on some ABIs,
 * 64-bit integers on others). */
static uint64_t handle_bits(const void *handle, size_t size)
{
    uint64_t v = 0;
    memcpy(&v, handle, size < sizeof v ? size : sizeof v);
    return v;
}

static rc_status record_dispatch(rc__vk_state *st, uint32_t slot, VkPipeline pipe, VkDescriptorSet set,
                                 const rc__vk_push *push, uint32_t groups_y, int on_device)
{
    VkCommandBuffer cb = st->cmd[slot];
    RC_TRY(rc__vk_begin(st, slot));
    /* scene buffers filled by staging copies in earlier submissions */
    rc__vk_barrier(st, cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, st->pipe_layout, 0, 1, &set, 0, NULL);
    vkCmdPushConstants(cb, st->pipe_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, (uint32_t)sizeof *push, push);
    vkCmdDispatch(cb, push->groups_x, groups_y, 1);
    if (on_device) /* results stay for later device work (the consumer's) */
        rc__vk_barrier(st, cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT);
    else
        rc__vk_barrier(st, cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    RC__VK_TRY(st, vkEndCommandBuffer(cb), "vkEndCommandBuffer");
    return rc__vk_submit(st, slot);
}

/* The noise words of the push constants (kernels/noise.glsl). */
static void noise_push(const rc__sim_job *job, rc__vk_push *push)
{
    const rc__noise *nz = job->noise;
    /* a return is lost when its uniform (m + 1) / 2^53 <= dropout, i.e. when
     * m < floor(dropout * 2^53) (exact: a power-of-two scale of a float) */
    const uint64_t drop = (uint64_t)floor((double)nz->dropout * 9007199254740992.0);
    push->noise_key[0] = (uint32_t)job->noise_key;
    push->noise_key[1] = (uint32_t)(job->noise_key >> 32);
    push->noise_drop[0] = (uint32_t)drop;
    push->noise_drop[1] = (uint32_t)(drop >> 32);
    push->noise_mean = nz->mean;
    push->noise_sigma = nz->sigma;
    push->noise_exponent = nz->exponent;
    push->noise_flags = RC__VK_NOISE_ON | (nz->mean != 0.0f || nz->sigma != 0.0f ? RC__VK_NOISE_MOVES : 0u) |
                        (nz->dropout > 0.0f ? RC__VK_NOISE_DROPS : 0u);
}

static rc_status simulate(rc__vk_state *st, const rc__sim_job *job)
{
    const rc_sensor *sensor = job->sensor;
    const rc__vk_scene *sv = (const rc__vk_scene *)job->scene->backend_scene;
    const uint32_t rays = sensor->rays;
    const uint64_t total = (uint64_t)job->pose_count * rays;
    const VkPhysicalDeviceLimits *lim = &st->props.limits;
    rc__vk_sensor_slot *table = NULL;
    VkPipeline pipe = VK_NULL_HANDLE;
    VkDescriptorSet sets[RC__VK_SLOTS];
    VkDescriptorSetAllocateInfo dai;
    VkDescriptorSetLayout layouts[RC__VK_SLOTS];
    pending pend[RC__VK_SLOTS];
    uint32_t words = 0, a, p, slots, d, dev_off[7];
    uint64_t per, first;
    unsigned char *xf;
    const int on_device = (job->flags & RC_RESULTS_ON_DEVICE) != 0;

    RC_RETURN_IF(st->ctx, sv == NULL || sv->refs.buf == VK_NULL_HANDLE ||
                              (st->ray_query && sv->tlas.as == VK_NULL_HANDLE),
                 RC_ERR_NOT_COMMITTED, "vulkan: the scene has no device copy; commit it");
    RC_RETURN_IF(st->ctx, rays > 0x80000000u, RC_ERR_UNSUPPORTED, "vulkan: sensors of more than 2^31 rays");
    RC_TRY(rc__vk_sensor_table(st, sensor, &table));
    RC_TRY(get_pipeline(st, job->attributes, table->model, sv->chunked, &pipe));

    /* sensor -> scene per pose, composed in double (rc__job_world_xform: float
     * or double poses, the scene's origin subtracted), as floats and doubles */
    RC_RETURN_IF(st->ctx, (uint64_t)job->pose_count * sizeof(rc__vk_xform) > st->max_binding, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: %u poses need %llu bytes of transforms; one binding holds %llu (maxStorageBufferRange)",
                 (unsigned)job->pose_count, (unsigned long long)job->pose_count * sizeof(rc__vk_xform),
                 (unsigned long long)st->max_binding);
    RC_TRY(ensure_buffer(st, &st->xforms, (uint64_t)job->pose_count * sizeof(rc__vk_xform), st->max_binding,
                         RC__VK_MEM_UPLOAD, "pose transforms"));
    xf = (unsigned char *)st->xforms.map;
    for (p = 0; p < job->pose_count; ++p) {
        rc__xformf w;
        rc__vk_xform x;
        double dw[12];
        int r;
        rc__job_world_xform(job, p, &w);
        for (r = 0; r < 3; ++r) {
            x.rows[4 * r + 0] = w.r[3 * r + 0];
            x.rows[4 * r + 1] = w.r[3 * r + 1];
            x.rows[4 * r + 2] = w.r[3 * r + 2];
            x.rows[4 * r + 3] = w.t[r];
        }
        memcpy(dw, w.rd, 9 * sizeof(double));
        memcpy(dw + 9, w.td, 3 * sizeof(double));
        memcpy(x.d, dw, sizeof x.d);
        memcpy(xf + (size_t)p * sizeof x, &x, sizeof x);
    }
    RC_TRY(rc__vk_buffer_flush(st, &st->xforms));

    /* elements per dispatch: the result slot's size, the dispatch grid */
    for (a = 0; a < 7; ++a)
        if (job->attributes & (1u << a)) words += attr_words[a];
    per = st->slot_bytes / (4u * words);
    {
        const uint64_t grid = (uint64_t)st->wg_size * lim->maxComputeWorkGroupCount[0] * lim->maxComputeWorkGroupCount[1];
        if (per > grid) per = grid;
    }
    if (per > 0x80000000u) per = 0x80000000u;
    if (per == 0) per = 1;
    if (per > total) per = total;
    slots = total > per ? RC__VK_SLOTS : 1u;
    if (on_device) {
        /* one array per attribute over the whole batch, in one binding */
        const uint64_t bytes = total * words * 4u;
        RC_RETURN_IF(st->ctx, bytes > st->max_binding, RC_ERR_CAPACITY,
                     "vulkan: %llu elements x %u words of results on the device need %llu bytes; one binding holds "
                     "%llu (maxStorageBufferRange): simulate fewer poses per call",
                     (unsigned long long)total, (unsigned)words, (unsigned long long)bytes,
                     (unsigned long long)st->max_binding);
        RC_TRY(ensure_buffer(st, &st->dev_out, bytes, st->max_binding, RC__VK_MEM_DEVICE, "device results"));
        sections(job->attributes, (uint32_t)total, dev_off);
    } else {
        for (a = 0; a < slots; ++a)
            RC_TRY(ensure_buffer(st, &st->out[a], per * words * 4u, st->slot_bytes, RC__VK_MEM_READBACK, "results"));
    }

    RC__VK_TRY(st, vkResetDescriptorPool(st->device, st->desc_pool, 0), "vkResetDescriptorPool");
    for (a = 0; a < slots; ++a) layouts[a] = st->set_layout;
    memset(&dai, 0, sizeof dai);
    dai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dai.descriptorPool = st->desc_pool;
    dai.descriptorSetCount = slots;
    dai.pSetLayouts = layouts;
    RC__VK_TRY(st, vkAllocateDescriptorSets(st->device, &dai, sets), "vkAllocateDescriptorSets");
    for (a = 0; a < slots; ++a) write_sets(st, sv, table, sets[a], on_device ? &st->dev_out : &st->out[a]);

    memset(pend, 0, sizeof pend);
    for (first = 0, d = 0; first < total; ++d) {
        const uint32_t s = d % slots;
        const uint32_t n = (uint32_t)(total - first < per ? total - first : per);
        const uint32_t groups = (n + st->wg_size - 1u) / st->wg_size;
        rc__vk_push push;
        uint32_t groups_y;
        if (pend[s].busy) {
            RC_TRY(rc__vk_wait(st, s));
            if (!on_device) RC_TRY(copy_out(st, job, s, &pend[s]));
            pend[s].busy = 0;
        }
        memset(&push, 0, sizeof push);
        push.first_pose = (uint32_t)(first / rays);
        push.first_ray = (uint32_t)(first % rays);
        push.count = n;
        push.rays = rays;
        push.columns = sensor->columns;
        push.rows = sensor->rows;
        push.range_min = sensor->range_min;
        push.range_max = sensor->range_max;
        push.geom_count = sv->info.geom_count;
        push.top_node = sv->info.top_node;
        push.top_ref = sv->info.top_ref;
        push.flags = (sv->info.flags & ~(RC__VK_FLAGS_NEVER_SET | RC__VK_FLAGS_DEBUG)) | st->debug_flags;
        push.groups_x = groups < lim->maxComputeWorkGroupCount[0] ? groups : lim->maxComputeWorkGroupCount[0];
        groups_y = (groups + push.groups_x - 1u) / push.groups_x;
        if (job->noise) noise_push(job, &push);
        if (on_device) { /* this dispatch's elements of the batch-wide arrays */
            for (a = 0; a < 7; ++a) push.off[a] = dev_off[a] + (uint32_t)first * attr_words[a];
        } else {
            sections(job->attributes, n, push.off);
        }
        RC_TRY(record_dispatch(st, s, pipe, sets[s], &push, groups_y, on_device));
        pend[s].first = first;
        pend[s].count = n;
        pend[s].busy = 1;
        first += n;
    }
    for (a = 0; a < slots; ++a) { /* the older one first: d is one past the last dispatch */
        const uint32_t s = (d + a) % slots;
        if (!pend[s].busy) continue;
        RC_TRY(rc__vk_wait(st, s));
        if (!on_device) RC_TRY(copy_out(st, job, s, &pend[s]));
        pend[s].busy = 0;
    }
    if (on_device) {
        rc_device_results *r = &st->dev_res;
        memset(r, 0, sizeof *r);
        r->struct_size = (uint32_t)sizeof *r;
        r->attributes = job->attributes;
        r->elements = total;
        r->buffer = handle_bits(&st->dev_out.buf, sizeof st->dev_out.buf);
        r->bytes = total * words * 4u;
        for (a = 0; a < 7; ++a)
            r->offsets[a] = (job->attributes & (1u << a)) ? (uint64_t)dev_off[a] * 4u : UINT64_MAX;
        r->instance = handle_bits(&st->instance, sizeof st->instance);
        r->physical_device = handle_bits(&st->phys, sizeof st->phys);
        r->device = handle_bits(&st->device, sizeof st->device);
        r->queue_family = st->queue_family;
    }
    return RC_OK;
}

rc_status rc__vk_simulate(rc_context *ctx, const rc__sim_job *job)
{
    rc__vk_state *st = rc__vk(ctx);
    rc_status s;
    uint32_t i;
    RC_RETURN_IF(ctx, st->lost, RC_ERR_DEVICE_LOST, "vulkan: the device was lost; destroy the context");
    st->dev_res.struct_size = 0; /* any call may reuse or resize the device buffer */
    s = simulate(st, job);
    if (s != RC_OK) /* leave nothing in flight that writes into buffers we may free */
        for (i = 0; i < RC__VK_SLOTS; ++i)
            if (st->inflight[i] && !st->lost) (void)rc__vk_wait(st, i);
    return s;
}

rc_status rc__vk_device_results(rc_context *ctx, rc_device_results *out)
{
    rc__vk_state *st = rc__vk(ctx);
    RC_RETURN_IF(ctx, st->lost, RC_ERR_DEVICE_LOST, "vulkan: the device was lost; destroy the context");
    RC_RETURN_IF(ctx, st->dev_res.struct_size == 0, RC_ERR_INVALID_ARGUMENT,
                 "no results are on the device: the last rc_simulate on this context did not set "
                 "RC_RESULTS_ON_DEVICE in results->flags (or failed)");
    *out = st->dev_res;
    return RC_OK;
}
