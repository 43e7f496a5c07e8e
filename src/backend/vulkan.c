/* The Vulkan compute backend: the scene's canonical two-level BVH (the same
 * one the BVH backend builds; each mesh's tree collapsed into the same 4-wide
 * nodes the BVH backend walks) packed into storage buffers and traversed by a
 * GLSL 450 compute kernel (kernels/raycast.comp, embedded as SPIR-V), one
 * invocation per ray, the whole batch of poses in one dispatch (or a few when
 * the result buffers' size forces it).
 *
 * Files: vulkan.c (this table, init/deinit, stats, the layout self-check),
 * vulkan_device.c (instance, device choice, memory, errors), vulkan_scene.c
 * (commit), vulkan_pack.c (packing + its C traversal), vulkan_sensor.c (ray
 * tables), vulkan_sim.c (pipelines, simulate), vulkan_shaders.c (SPIR-V).
 *
 * Device: the first discrete GPU, else integrated, else any (Mesa's lavapipe
 * CPU device); RANGECAST_VULKAN_DEVICE picks one by index or name substring
 * (rc_context_desc.device overrides it). AUTO never picks Vulkan.
 *
 * Memory: the arena holds only rc__vk_state (context_bytes) and one
 * rc__vk_scene per committed scene next to its BVH (scene_commit_bytes);
 * Vulkan's host allocations go through counting callbacks (backend_bytes),
 * device memory is counted in device_bytes.
 *
 * Errors: every VkResult becomes a status whose message names the call and the
 * result (rc__vk_result_name); VK_ERROR_DEVICE_LOST gives RC_ERR_DEVICE_LOST
 * and from then on every call but destroy returns it.
 *
 * Workgroup size: 64 by default (the subgroup size where that is larger;
 * RANGECAST_VULKAN_WG overrides): a warp/wave or two on GPUs. On lavapipe
 * (subgroup 8, 256-bit SIMD) 16, 32, 64 and 128 cost the same CPU time
 * within 3% (VLP-16 on a 100k-triangle sphere), so 64 there too.
 *
 * Lavapipe runs every branch of a SIMD group masked rather than skipping it,
 * so its cost follows the kernel's code size per loop iteration: the kernel
 * keeps one inlined copy of the traversal, the 4-binding loads only for
 * scenes that need them, and the zero-area test on the host. */
#include "backend/vulkan_internal.h"

#include <string.h>

static int vk_available(void) { return rc__vk_loader_ok(); }

static size_t vk_context_bytes(const rc_context_desc *desc)
{
    (void)desc;
    return rc__arena_cost(sizeof(rc__vk_state));
}

static void teardown(rc__vk_state *st)
{
    uint32_t i;
    if (st->device != VK_NULL_HANDLE) {
        (void)vkDeviceWaitIdle(st->device);
        rc__vk_sensor_cache_clear(st);
        rc__vk_buffer_destroy(st, &st->xforms);
        for (i = 0; i < RC__VK_SLOTS; ++i) rc__vk_buffer_destroy(st, &st->out[i]);
        rc__vk_buffer_destroy(st, &st->dev_out);
        rc__vk_pipelines_destroy(st);
    }
    rc__vk_device_destroy(st);
}

static rc_status vk_init(rc_context *ctx, const rc_context_desc *desc)
{
    rc__vk_state *st;
    rc_status s;
    st = (rc__vk_state *)rc__arena_calloc(&ctx->arena, sizeof *st);
    RC_RETURN_IF(ctx, st == NULL, RC_ERR_OUT_OF_MEMORY, "arena has no room for the Vulkan backend state (%llu bytes)",
                 (unsigned long long)rc__arena_cost(sizeof *st));
    st->ctx = ctx;
    st->want_device = desc->device;
    st->want_ray_query = (desc->flags & RC_CONTEXT_VULKAN_RAY_QUERY) != 0;
    st->budget_bytes = (uint64_t)desc->backend_budget_mib << 20;
    ctx->backend_data = st;
    s = rc__vk_device_create(st);
    st->want_device = NULL; /* the caller's string is not kept */
    if (s == RC_OK) s = rc__vk_pipelines_create(st);
    if (s != RC_OK) {
        teardown(st);
        rc__arena_free(&ctx->arena, st);
        ctx->backend_data = NULL;
        return s;
    }
    rc__log(ctx, RC_LOG_INFO,
            "vulkan: %s (Vulkan %u.%u), %s kernel, %u binding(s) per large array of at most %llu bytes, "
            "workgroup %u, subgroup %u, device memory %s, %s",
            st->device_name, (unsigned)VK_API_VERSION_MAJOR(st->props.apiVersion),
            (unsigned)VK_API_VERSION_MINOR(st->props.apiVersion), st->fp64 ? "float64" : "float-only",
            (unsigned)st->chunks, (unsigned long long)st->max_binding, (unsigned)st->wg_size,
            (unsigned)st->subgroup_size, st->device_mappable ? "mapped" : "staged",
            st->ray_query ? "ray query traversal" : "compute traversal");
    return RC_OK;
}

static void vk_deinit(rc_context *ctx)
{
    rc__vk_state *st = rc__vk(ctx);
    if (!st) return;
    teardown(st);
    rc__arena_free(&ctx->arena, st);
    ctx->backend_data = NULL;
}

static void vk_memory_stats(const rc_context *ctx, rc_memory_stats *stats)
{
    const rc__vk_state *st = rc__vk(ctx);
    if (!st) return;
    stats->backend_bytes += st->host_bytes;
    stats->device_bytes += st->device_bytes;
}

const rc__backend rc__backend_vulkan = {
    RC_BACKEND_VULKAN,
    "vulkan",
    vk_available,
    vk_context_bytes,
    rc__vk_scene_commit_bytes,
    vk_init,
    vk_deinit,
    rc__vk_scene_commit,
    rc__vk_scene_release,
    rc__vk_simulate,
    vk_memory_stats,
    rc__vk_device_results,
};

/* ---- test hooks --------------------------------------------------------------- */

void rc__vk_debug_mark_lost(rc_context *ctx)
{
    if (rc__context_valid(ctx) && ctx->backend_id == RC_BACKEND_VULKAN && rc__vk(ctx)) rc__vk(ctx)->lost = 1;
}

void rc__vk_debug_scene_uploads(const rc_scene *scene, uint32_t *full, uint32_t *top, uint32_t *meshes)
{
    const rc__vk_scene *sv = (const rc__vk_scene *)scene->backend_scene;
    *full = sv ? sv->full_uploads : 0u;
    *top = sv ? sv->top_updates : 0u;
    *meshes = sv ? sv->mesh_updates : 0u;
}

const char *rc__vk_device_name(const rc_context *ctx, int *fp64, uint32_t *chunks)
{
    const rc__vk_state *st;
    if (!rc__context_valid(ctx) || ctx->backend_id != RC_BACKEND_VULKAN || !rc__vk(ctx)) return NULL;
    st = rc__vk(ctx);
    if (fp64) *fp64 = (int)st->fp64;
    if (chunks) *chunks = st->chunks;
    return st->device_name;
}

/* Known, distinct values for element 1 of each array (element 0 is noise). */
static void check_values(rc__bvh_node node[2], rc__vk_geom geom[2], rc__vk_inst inst[2])
{
    int i;
    memset(node, 0xA5, 2 * sizeof *node);
    memset(geom, 0x5A, 2 * sizeof *geom);
    memset(inst, 0x3C, 2 * sizeof *inst);
    for (i = 0; i < 3; ++i) {
        node[1].bmin[i] = -1.5f - (float)i;
        node[1].bmax[i] = 2.25f + (float)i;
    }
    node[1].index = 0x01020304u;
    node[1].count = 0x0A0B0C0Du;
    geom[1].node_base = 11;
    geom[1].ref_base = 22;
    geom[1].tri_base = 33;
    geom[1].geom_id = 44;
    for (i = 0; i < 12; ++i) {
        inst[1].to_local[i] = 0.125f * (float)(i + 1);
        inst[1].n2w[i] = -0.5f * (float)(i + 1);
    }
    inst[1].first_geom = 0xCAFEu;
    inst[1].geom_count = 0xBEEFu;
    inst[1].pad0 = 7;
    inst[1].pad1 = 9;
    for (i = 0; i < 24; ++i) inst[1].to_world_d[i] = 0x10000u * (uint32_t)(i + 1) + 0x77u;
}

rc_status rc__vk_layout_check(rc_context *ctx)
{
    rc__vk_state *st = rc__vk(ctx);
    rc__bvh_node node[2];
    rc__vk_geom geom[2];
    rc__vk_inst inst[2];
    uint32_t expect[RC__VK_LAYOUT_CHECK_WORDS];
    rc__vk_buffer in[3], out;
    VkDescriptorSetLayoutBinding b[4];
    VkDescriptorSetLayoutCreateInfo sli;
    VkPipelineLayoutCreateInfo pli;
    VkShaderModuleCreateInfo smi;
    VkComputePipelineCreateInfo ci;
    VkDescriptorSetAllocateInfo dai;
    VkDescriptorBufferInfo bi[4];
    VkWriteDescriptorSet w[4];
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout pipe_layout = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipeline pipe = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkResult r = VK_SUCCESS;
    const char *what = "";
    size_t bytes = 0;
    uint32_t i;
    rc_status s = RC_OK;

    RC_RETURN_IF(ctx, ctx->backend_id != RC_BACKEND_VULKAN || !st, RC_ERR_MISUSE, "not a Vulkan context");
    RC_RETURN_IF(ctx, st->lost, RC_ERR_DEVICE_LOST, "vulkan: the device was lost; destroy the context");
    check_values(node, geom, inst);
    memcpy(expect, &node[1], 32);
    memcpy(expect + 8, &geom[1], 16);
    memcpy(expect + 12, &inst[1], sizeof inst[1]);
    memset(in, 0, sizeof in);
    memset(&out, 0, sizeof out);
    if (s == RC_OK) s = rc__vk_buffer_create(st, sizeof node, RC__VK_MEM_UPLOAD, "layout check", &in[0]);
    if (s == RC_OK) s = rc__vk_buffer_create(st, sizeof geom, RC__VK_MEM_UPLOAD, "layout check", &in[1]);
    if (s == RC_OK) s = rc__vk_buffer_create(st, sizeof inst, RC__VK_MEM_UPLOAD, "layout check", &in[2]);
    if (s == RC_OK) s = rc__vk_buffer_create(st, sizeof expect, RC__VK_MEM_READBACK, "layout check", &out);
    if (s != RC_OK) goto done;
    memcpy(in[0].map, node, sizeof node);
    memcpy(in[1].map, geom, sizeof geom);
    memcpy(in[2].map, inst, sizeof inst);
    memset(out.map, 0, sizeof expect);
    for (i = 0; i < 3 && s == RC_OK; ++i) s = rc__vk_buffer_flush(st, &in[i]);
    if (s == RC_OK) s = rc__vk_buffer_flush(st, &out);
    if (s != RC_OK) goto done;

    for (i = 0; i < 4; ++i) {
        memset(&b[i], 0, sizeof b[i]);
        b[i].binding = i;
        b[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&sli, 0, sizeof sli);
    sli.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    sli.bindingCount = 4;
    sli.pBindings = b;
    what = "vkCreateDescriptorSetLayout";
    r = vkCreateDescriptorSetLayout(st->device, &sli, RC__VK_OBJ_ALLOC, &set_layout);
    if (r != VK_SUCCESS) goto vkfail;
    memset(&pli, 0, sizeof pli);
    pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &set_layout;
    what = "vkCreatePipelineLayout";
    r = vkCreatePipelineLayout(st->device, &pli, RC__VK_OBJ_ALLOC, &pipe_layout);
    if (r != VK_SUCCESS) goto vkfail;
    memset(&smi, 0, sizeof smi);
    smi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smi.pCode = rc__vk_layout_check_spirv(&bytes);
    smi.codeSize = bytes;
    what = "vkCreateShaderModule";
    r = vkCreateShaderModule(st->device, &smi, RC__VK_OBJ_ALLOC, &module);
    if (r != VK_SUCCESS) goto vkfail;
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = pipe_layout;
    what = "vkCreateComputePipelines";
    r = vkCreateComputePipelines(st->device, VK_NULL_HANDLE, 1, &ci, RC__VK_OBJ_ALLOC, &pipe);
    if (r != VK_SUCCESS) goto vkfail;
    what = "vkResetDescriptorPool";
    r = vkResetDescriptorPool(st->device, st->desc_pool, 0);
    if (r != VK_SUCCESS) goto vkfail;
    memset(&dai, 0, sizeof dai);
    dai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dai.descriptorPool = st->desc_pool;
    dai.descriptorSetCount = 1;
    dai.pSetLayouts = &set_layout;
    what = "vkAllocateDescriptorSets";
    r = vkAllocateDescriptorSets(st->device, &dai, &set);
    if (r != VK_SUCCESS) goto vkfail;
    for (i = 0; i < 4; ++i) {
        bi[i].buffer = i < 3 ? in[i].buf : out.buf;
        bi[i].offset = 0;
        bi[i].range = VK_WHOLE_SIZE;
        memset(&w[i], 0, sizeof w[i]);
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstSet = set;
        w[i].dstBinding = i;
        w[i].descriptorCount = 1;
        w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[i].pBufferInfo = &bi[i];
    }
    vkUpdateDescriptorSets(st->device, 4, w, 0, NULL);
    s = rc__vk_begin(st, 0);
    if (s != RC_OK) goto done;
    vkCmdBindPipeline(st->cmd[0], VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    vkCmdBindDescriptorSets(st->cmd[0], VK_PIPELINE_BIND_POINT_COMPUTE, pipe_layout, 0, 1, &set, 0, NULL);
    vkCmdDispatch(st->cmd[0], 1, 1, 1);
    rc__vk_barrier(st, st->cmd[0], VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    what = "vkEndCommandBuffer";
    r = vkEndCommandBuffer(st->cmd[0]);
    if (r != VK_SUCCESS) goto vkfail;
    s = rc__vk_submit(st, 0);
    if (s == RC_OK) s = rc__vk_wait(st, 0);
    if (s == RC_OK) s = rc__vk_buffer_invalidate(st, &out);
    if (s != RC_OK) goto done;
    for (i = 0; i < RC__VK_LAYOUT_CHECK_WORDS; ++i) {
        uint32_t got;
        memcpy(&got, (const unsigned char *)out.map + 4u * i, 4);
        if (got != expect[i]) {
            s = rc__fail(ctx, RC_ERR_BACKEND,
                         "vulkan: layout contract broken: word %u of the node/geom/inst records reads 0x%08x in "
                         "GLSL, 0x%08x in C (kernels/layout.glsl vs src/backend/vulkan_layout.h)",
                         (unsigned)i, (unsigned)got, (unsigned)expect[i]);
            break;
        }
    }
    goto done;
vkfail:
    s = rc__vk_fail(st, r, what);
done:
    if (pipe != VK_NULL_HANDLE) vkDestroyPipeline(st->device, pipe, RC__VK_OBJ_ALLOC);
    if (module != VK_NULL_HANDLE) vkDestroyShaderModule(st->device, module, RC__VK_OBJ_ALLOC);
    if (pipe_layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(st->device, pipe_layout, RC__VK_OBJ_ALLOC);
    if (set_layout != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(st->device, set_layout, RC__VK_OBJ_ALLOC);
    for (i = 0; i < 3; ++i) rc__vk_buffer_destroy(st, &in[i]);
    rc__vk_buffer_destroy(st, &out);
    return s;
}
