/* The Vulkan compute backend's internal view, shared by src/backend/vulkan*.c.
 *
 * Objects and where they live:
 *   rc__vk_state   one per context, in the context's arena (context_bytes);
 *                  the instance, device, queue, pipelines, the per-sensor
 *                  table cache and the per-call buffers (poses, results);
 *   rc__vk_scene   one per committed scene, in the arena (scene_commit_bytes);
 *                  the scene's packed arrays in device buffers;
 *   everything Vulkan allocates (host memory through our allocation
 *   callbacks, device memory through vkAllocateMemory) is outside the arena
 *   and reported in rc_memory_stats (backend_bytes, device_bytes).
 */
#ifndef RC_BACKEND_VULKAN_INTERNAL_H
#define RC_BACKEND_VULKAN_INTERNAL_H

#include "backend/backend.h"
#include "backend/vulkan_layout.h"

#include <vulkan/vulkan.h>

#define RC__VK_PIPELINES 16u     /* cached (attribute mask, model) pipelines */
#define RC__VK_SENSOR_SLOTS 8u   /* cached sensor ray tables */
#define RC__VK_SLOTS 2u          /* result buffers in flight (double buffering) */

/* A buffer with its own memory; map != NULL when host-visible (kept mapped). */
typedef struct rc__vk_buffer {
    VkBuffer buf;
    VkDeviceMemory mem;
    VkDeviceSize size;       /* bytes usable */
    VkDeviceSize alloc_size; /* bytes of the allocation (counted in device_bytes) */
    void *map;
    uint32_t coherent;
    uint32_t kind;           /* RC__VK_MEM_* */
} rc__vk_buffer;

/* Memory kinds of rc__vk_buffer_create. */
#define RC__VK_MEM_DEVICE 0u   /* read by kernels; host-visible only on UMA devices */
#define RC__VK_MEM_UPLOAD 1u   /* written by the host, read by kernels (and staging) */
#define RC__VK_MEM_READBACK 2u /* written by kernels, read by the host (cached if possible) */

/* Where each array of a packed scene starts and how many elements it has. */
typedef struct rc__vk_pack_info {
    uint64_t nodes, refs, tris, verts, geoms, insts; /* element counts */
    uint32_t geom_count;   /* the scene's own geometries (top items below it) */
    uint32_t top_node;     /* first node of the top level */
    uint32_t top_ref;      /* first ref of the top level */
    uint32_t flags;        /* 1: one mesh and no instances (no top level needed) */
    uint32_t reserved0;
    uint64_t max_wide;     /* wide nodes of the largest mesh section (rc__vk_pack_dst.wide_scratch) */
} rc__vk_pack_info;

/* A destination for one packed array: up to 4 chunks of 2^shift elements. */
typedef struct rc__vk_span {
    unsigned char *chunk[RC__VK_MAX_CHUNKS];
    uint32_t shift;
    uint32_t elem_size;
    uint64_t base;  /* the element chunk[0] starts at (0: the whole array; a staged section: its first) */
} rc__vk_span;

typedef struct rc__vk_pack_dst {
    rc__vk_span nodes, refs, tris, verts, geoms, insts;
    rc__wnode *wide_scratch; /* rc__vk_pack_info.max_wide nodes where nodes has several chunks (a
                              * section may straddle two): each mesh is collapsed here first; NULL
                              * for one chunk: collapsed in place */
} rc__vk_pack_dst;

/* A driver acceleration structure (ray query traversal) and its storage. */
typedef struct rc__vk_accel {
    VkAccelerationStructureKHR as;
    VkDeviceAddress address;
    rc__vk_buffer storage;
} rc__vk_accel;

typedef struct rc__vk_scene {
    rc__vk_buffer nodes[RC__VK_MAX_CHUNKS], tris[RC__VK_MAX_CHUNKS], verts[RC__VK_MAX_CHUNKS];
    rc__vk_buffer refs, geoms, insts;
    uint32_t node_chunks, tri_chunks, vert_chunks;
    uint32_t chunked;          /* some array spans several bindings: the 4-binding kernel */
    uint32_t pack_serial;      /* tags used while another scene instancing this one packs */
    uint32_t pack_first_geom;
    uint32_t fill_serial;
    rc__vk_pack_info info;
    /* ray query traversal (vulkan_accel.c): the top level, and the bottom
     * levels it instances: [0] the scene's own meshes (when it has any), then
     * one per instanced source scene, in packing order; pack_blas tags a
     * source with its index while another scene commits */
    rc__vk_accel tlas;
    rc__vk_accel *blas;        /* blas_count entries, from the driver's host allocator */
    uint32_t blas_count;
    uint32_t pack_blas;
    uint32_t accel_serial;
    /* 1 when the device arrays hold the scene as of its last successful
     * commit (0 from the start of a commit until it succeeds): a commit that
     * only moved instances then rewrites only their records and the top
     * level (vulkan_scene.c) */
    uint32_t current;
    uint32_t full_uploads, top_updates, mesh_updates; /* commits of each kind (test hook) */
    /* wide nodes of each own mesh's collapse (rc__vk_wide_counts, kept so a
     * commit that only moves instances does not walk every tree again) */
    uint32_t *wide_nodes;      /* wide_cap entries, from the driver's host allocator */
    uint32_t wide_cap;
} rc__vk_scene;

typedef struct rc__vk_pipeline {
    VkPipeline pipe;
    uint32_t attributes;
    uint32_t model;
    uint32_t chunked;        /* the 4-binding kernel */
    uint32_t reserved0;
    uint64_t last_use;
} rc__vk_pipeline;

typedef struct rc__vk_sensor_slot {
    const rc_sensor *sensor; /* identity is checked by content hash too */
    uint64_t hash;
    uint64_t last_use;
    uint32_t model;          /* RC__VK_MODEL_* */
    uint32_t rays;
    rc__vk_buffer table;
} rc__vk_sensor_slot;

typedef struct rc__vk_state {
    rc_context *ctx;
    const char *want_device;  /* rc_context_desc.device, during init only */
    uint32_t want_ray_query;  /* RC_CONTEXT_VULKAN_RAY_QUERY or RANGECAST_VULKAN_RAY_QUERY=1 */
    uint32_t stats;           /* RANGECAST_VULKAN_PIPELINE_STATS=1 and the extension: log kernel statistics */
    VkAllocationCallbacks alloc;
    uint64_t host_bytes;     /* bytes the driver holds through our callbacks */
    uint64_t device_bytes;   /* bytes of VkDeviceMemory we hold, all kinds */
    uint64_t budget_bytes;   /* most device_bytes may reach (rc_context_desc.backend_budget_mib); 0 = no limit */
    uint64_t heap_bytes;     /* of which in RC__VK_MEM_DEVICE memory */

    VkInstance instance;
    VkPhysicalDevice phys;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    uint32_t lost;           /* VK_ERROR_DEVICE_LOST seen: only destroy works */
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties mem_props;
    uint64_t max_alloc;      /* maxMemoryAllocationSize */
    uint64_t max_binding;    /* maxStorageBufferRange (or the test override) */
    uint64_t heap_size;      /* size of the heap device buffers come from */
    uint32_t subgroup_size;
    uint32_t fp64;           /* shaderFloat64 enabled: the RC_FP64 1 kernel */
    uint32_t debug_flags;    /* RC__VK_FLAGS_SKEW_DIV (tests), _SKIP_WALK, _SKIP_REFINE (measurements) */
    uint32_t ray_query;      /* trace with VK_KHR_ray_query (RC_CONTEXT_VULKAN_RAY_QUERY) */
    uint32_t scratch_align;  /* minAccelerationStructureScratchOffsetAlignment */
    PFN_vkGetBufferDeviceAddress get_address;
    PFN_vkCreateAccelerationStructureKHR create_as;
    PFN_vkDestroyAccelerationStructureKHR destroy_as;
    PFN_vkGetAccelerationStructureBuildSizesKHR as_sizes;
    PFN_vkCmdBuildAccelerationStructuresKHR build_as;
    PFN_vkGetAccelerationStructureDeviceAddressKHR as_address;
    uint32_t chunks;         /* most bindings per large array: 1 or 4 */
    uint32_t node_shift, tri_shift, vert_shift;
    uint32_t wg_size;        /* workgroup size */
    uint32_t device_mappable;/* device memory is host-visible: no staging copies */
    uint64_t slot_bytes;     /* most bytes of results one dispatch writes */

    VkCommandPool cmd_pool;
    VkCommandBuffer cmd[RC__VK_SLOTS];
    VkFence fence[RC__VK_SLOTS];
    uint32_t inflight[RC__VK_SLOTS];
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout pipe_layout;
    VkDescriptorPool desc_pool;
    VkShaderModule module[2];/* the 1-binding kernel; the 4-binding one (when chunks == 4) */
    VkPipelineCache cache;
    rc__vk_pipeline pipes[RC__VK_PIPELINES];
    rc__vk_sensor_slot sensors[RC__VK_SENSOR_SLOTS];
    rc__vk_buffer xforms;
    rc__vk_buffer out[RC__VK_SLOTS];
    rc__vk_buffer dev_out;   /* results kept on the device (RC_RESULTS_ON_DEVICE) */
    rc_device_results dev_res; /* what dev_out holds; struct_size 0 when nothing valid */
    uint64_t clock;          /* use counter for the caches */
    uint32_t serial;         /* pack serial */
    uint32_t reserved0;
    char device_name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
} rc__vk_state;

/* Allocation callbacks of objects below the device: NULL, so the driver uses
 * the device's (ours, counting). Passing ours per object as well tripped
 * lavapipe 22.3, which frees some per-object memory with the device allocator. */
#define RC__VK_OBJ_ALLOC NULL

static inline rc__vk_state *rc__vk(const rc_context *ctx) { return (rc__vk_state *)ctx->backend_data; }

/* vulkan_device.c --------------------------------------------------------- */

/* "VK_ERROR_DEVICE_LOST" etc. Never NULL. */
const char *rc__vk_result_name(VkResult r);
/* Turns a failed VkResult into a status with a message naming the call and
 * the result; VK_ERROR_DEVICE_LOST marks the state lost. */
rc_status rc__vk_fail(rc__vk_state *st, VkResult r, const char *what);
#define RC__VK_TRY(st, call, what)                           \
    do {                                                     \
        VkResult rc__vk_r_ = (call);                         \
        if (rc__vk_r_ != VK_SUCCESS) return rc__vk_fail((st), rc__vk_r_, (what)); \
    } while (0)

/* 1 when a Vulkan 1.1 loader is present. */
int rc__vk_loader_ok(void);
/* Instance, device choice (RANGECAST_VULKAN_DEVICE), queue, limits, memory types. */
rc_status rc__vk_device_create(rc__vk_state *st);
/* The chosen device's extensions, in memory from rc__vk_host_alloc (free it). */
rc_status rc__vk_device_extensions(rc__vk_state *st, VkExtensionProperties **out, uint32_t *count);

/* Pipeline statistics (vulkan_stats.c): the extension's name; whether they
 * were asked for and the device has it; log one pipeline's. */
extern const char rc__vk_stats_extension[];
int rc__vk_stats_wanted(rc__vk_state *st);
void rc__vk_stats_log(rc__vk_state *st, VkPipeline pipe, uint32_t attributes, uint32_t model);
void rc__vk_device_destroy(rc__vk_state *st);

/* Creates a buffer of size bytes (storage + transfer usage) in memory of the
 * given kind (RC__VK_MEM_*); host-visible memory is mapped.
 * RC_ERR_OUT_OF_MEMORY, with `what` in the message, when it cannot fit. */
rc_status rc__vk_buffer_create(rc__vk_state *st, VkDeviceSize size, uint32_t kind, const char *what,
                               rc__vk_buffer *out);
/* The same with more usage bits (acceleration structure storage or build
 * input); VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT among them allocates the
 * memory for device addresses. */
rc_status rc__vk_buffer_create_usage(rc__vk_state *st, VkDeviceSize size, uint32_t kind, VkBufferUsageFlags usage,
                                     const char *what, rc__vk_buffer *out);
VkDeviceAddress rc__vk_buffer_address(const rc__vk_state *st, const rc__vk_buffer *b);
/* Host memory through the driver's counting allocator (backend_bytes). */
void *rc__vk_host_alloc(rc__vk_state *st, size_t size);
void rc__vk_host_free(rc__vk_state *st, void *p);
void rc__vk_buffer_destroy(rc__vk_state *st, rc__vk_buffer *b);
/* Makes host writes visible / device writes visible to the host (non-coherent memory). */
rc_status rc__vk_buffer_flush(rc__vk_state *st, const rc__vk_buffer *b);
rc_status rc__vk_buffer_invalidate(rc__vk_state *st, const rc__vk_buffer *b);
/* Records, submits and waits for copies src -> dst (regions). */
rc_status rc__vk_copy(rc__vk_state *st, const rc__vk_buffer *src, const rc__vk_buffer *dst, VkDeviceSize src_off,
                      VkDeviceSize size);
/* The same into dst at dst_off. */
rc_status rc__vk_copy_region(rc__vk_state *st, const rc__vk_buffer *src, const rc__vk_buffer *dst,
                             VkDeviceSize src_off, VkDeviceSize dst_off, VkDeviceSize size);
/* Command slots (command buffer + fence): wait for one (no-op when idle),
 * begin recording into it (waits first), submit it. */
rc_status rc__vk_wait(rc__vk_state *st, uint32_t slot);
rc_status rc__vk_begin(rc__vk_state *st, uint32_t slot);
rc_status rc__vk_submit(rc__vk_state *st, uint32_t slot);
/* A global memory barrier (skipped on CPU devices, see vulkan_device.c). */
void rc__vk_barrier(rc__vk_state *st, VkCommandBuffer cb, VkPipelineStageFlags src_stage, VkAccessFlags src,
                    VkPipelineStageFlags dst_stage, VkAccessFlags dst);

/* vulkan_shaders.c -------------------------------------------------------- */

/* SPIR-V of raycast.comp for the variant, and of layout_check.comp. */
const uint32_t *rc__vk_raycast_spirv(int fp64, uint32_t chunks, int ray_query, size_t *bytes);
const uint32_t *rc__vk_layout_check_spirv(size_t *bytes);

/* vulkan_pack.c ----------------------------------------------------------- */

/* After a build: the wide node count of every own mesh whose tree changed
 * (changed[g]; all of them for changed NULL or a first count). *moved 1 when
 * a count changed (a rebuilt tree of another shape) or all were taken: the
 * sections after it move, so the packed layout cannot be kept. */
rc_status rc__vk_wide_counts(rc__vk_state *st, rc_scene *scene, const uint8_t *changed, int *moved);
/* Counts the packed arrays of a scene whose BVH is built (and its wide node
 * counts taken); tags the instance sources' rc__vk_scene with serial. */
void rc__vk_pack_count(rc_scene *scene, uint32_t serial, rc__vk_pack_info *info);
/* Writes them (after rc__vk_pack_count with the same serial). */
void rc__vk_pack_fill(rc_scene *scene, uint32_t serial, const rc__vk_pack_info *info, const rc__vk_pack_dst *dst);
/* One mesh's place in the packed arrays: the first element of each of its
 * sections and their lengths (nodes from where the cursor stood, so a
 * padding node before its pair-aligned start is included). */
typedef struct rc__vk_section {
    const rc__mesh *mesh;
    uint32_t geom_id;   /* within its own scene */
    uint64_t geom;      /* its geometry record */
    uint64_t node, nodes, ref, refs, tri, tris, vert, verts;
    uint64_t wide;      /* its wide nodes */
} rc__vk_section;
/* The meshes a commit that keeps the layout must write again: own geometry g
 * where changed[g], and every mesh of an instanced source re-committed since
 * the scene's last commit (after rc__vk_pack_count with serial). Fills up to
 * max of them into out and returns how many there are. */
uint32_t rc__vk_pack_changed(rc_scene *scene, uint32_t serial, const uint8_t *changed, rc__vk_section *out,
                             uint32_t max);
/* Writes one mesh's sections (its padding node, geometry record, nodes, refs,
 * triangles and vertices) into dst, as rc__vk_pack_fill writes them. */
void rc__vk_pack_section(const rc__vk_section *s, const rc__vk_pack_dst *dst);
/* Writes only what a commit that moved instances changes: the instance
 * records and the top level's nodes and refs (after rc__vk_pack_count). */
void rc__vk_pack_fill_top(const rc_scene *scene, const rc__vk_pack_info *info, const rc__vk_pack_dst *dst);

/* Host copy of packed arrays (linear, one chunk each). nodes holds each
 * mesh's wide nodes (4 slots each) and the top level's binary ones. */
typedef struct rc__vk_packed {
    rc__vk_pack_info info;
    const rc__bvh_node *nodes;
    const uint32_t *refs;
    const uint32_t *tris;
    const float *verts;
    const rc__vk_geom *geoms;
    const rc__vk_inst *insts;
} rc__vk_packed;

/* The C traversal of the packed arrays, with the CPU's own inner tests: must
 * find exactly what rc__scene_intersect finds (the test proves the packing). */
int rc__vk_packed_intersect(const rc__vk_packed *p, const rc__ray *ray, rc__hit *hit);

/* vulkan_scene.c ---------------------------------------------------------- */

rc_status rc__vk_scene_commit(rc_scene *scene, rc_progress_fn progress, void *user);
void rc__vk_scene_release(rc_scene *scene);
size_t rc__vk_scene_commit_bytes(const rc_scene_desc *desc);

/* vulkan_accel.c ----------------------------------------------------------- */

/* Builds the scene's driver acceleration structures from its packed meshes
 * (after rc__vk_pack_count with serial tagged the instance sources). */
rc_status rc__vk_accel_build(rc_scene *scene, uint32_t serial);
/* A commit that kept the packed layout: with changed NULL (instances moved)
 * only the top level is built again; with changed (rc__vk_pack_changed's
 * marks for own meshes) also the own meshes' bottom level when one of them
 * changed and the bottom level of each source committed again since, the
 * others kept. */
rc_status rc__vk_accel_update(rc_scene *scene, uint32_t serial, const uint8_t *changed);
void rc__vk_accel_release(rc__vk_state *st, rc__vk_scene *sv);

/* vulkan_sensor.c --------------------------------------------------------- */

/* The sensor's ray table on the device (uploaded on first use, cached). */
rc_status rc__vk_sensor_table(rc__vk_state *st, const rc_sensor *sensor, rc__vk_sensor_slot **out);
void rc__vk_sensor_cache_clear(rc__vk_state *st);

/* vulkan_sim.c ------------------------------------------------------------- */

rc_status rc__vk_pipelines_create(rc__vk_state *st);
void rc__vk_pipelines_destroy(rc__vk_state *st);
rc_status rc__vk_simulate(rc_context *ctx, const rc__sim_job *job);
/* rc_context_get_device_results for the Vulkan backend. */
rc_status rc__vk_device_results(rc_context *ctx, rc_device_results *out);

/* vulkan.c (tests) ---------------------------------------------------------- */

/* Runs layout_check.comp on known values: RC_OK when GLSL reads every member
 * where C wrote it, else RC_ERR_BACKEND naming the first mismatch. */
rc_status rc__vk_layout_check(rc_context *ctx);
/* Test hook: behave as if the device had been lost. */
void rc__vk_debug_mark_lost(rc_context *ctx);
/* Test hook: how many commits of the scene uploaded everything, how many
 * only rewrote the instances and the top level, and how many rewrote the
 * changed meshes in place too. */
void rc__vk_debug_scene_uploads(const rc_scene *scene, uint32_t *full, uint32_t *top, uint32_t *meshes);
/* Test hook: the device name and whether the float64 kernel runs. */
const char *rc__vk_device_name(const rc_context *ctx, int *fp64, uint32_t *chunks);

#endif
