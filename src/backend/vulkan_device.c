/* Vulkan plumbing: result names, errors, the host allocation callbacks that
 * count the driver's memory, the instance and the choice of device, memory
 * types, buffers and one-shot copies.
 *
 * Environment variables read at context creation (a public desc field for the
 * device should replace the first; the others are for tests and experiments):
 *   RANGECAST_VULKAN_DEVICE       device index (as enumerated) or a substring of
 *                                 its name, case-insensitive; default: the first
 *                                 discrete GPU, else integrated, else any
 *   RANGECAST_VULKAN_NO_FP64      1: use the float-only kernel even with shaderFloat64
 *   RANGECAST_VULKAN_CHUNKS       1: one binding per large array (else 4 when the
 *                                 device has 18 storage buffers per stage)
 *   RANGECAST_VULKAN_MAX_BINDING  bytes: pretend maxStorageBufferRange is smaller
 *   RANGECAST_VULKAN_STAGING      1: upload through staging copies even where
 *                                 device memory is host-visible
 *   RANGECAST_VULKAN_WG           workgroup size (power of two, 8..1024)
 *   RANGECAST_VULKAN_SLOT_MB      MiB of results one dispatch may write (default 64 on
 *                                 a discrete GPU, else 8)
 *   RANGECAST_VULKAN_RAY_QUERY    1: as RC_CONTEXT_VULKAN_RAY_QUERY (runs a test
 *                                 suite on the ray query traversal unchanged)
 *   RANGECAST_VULKAN_SKEW_DIV     1: the kernel's float divisions start 2 ulps off
 *                                 (div_rn must put them right; test_stability)
 *   RANGECAST_VULKAN_PIPELINE_STATS 1: log the driver's statistics of each kernel
 *                                 (registers, spills; vulkan_stats.c)
 *   RANGECAST_VULKAN_SKIP         walk or refine: the kernel skips that stage, for
 *                                 measuring what it costs (wrong results) */
#include "backend/vulkan_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *rc__vk_result_name(VkResult r)
{
    switch (r) {
#define RC__VK_NAME(x) \
    case x: return #x;
        RC__VK_NAME(VK_SUCCESS)
        RC__VK_NAME(VK_NOT_READY)
        RC__VK_NAME(VK_TIMEOUT)
        RC__VK_NAME(VK_EVENT_SET)
        RC__VK_NAME(VK_EVENT_RESET)
        RC__VK_NAME(VK_INCOMPLETE)
        RC__VK_NAME(VK_ERROR_OUT_OF_HOST_MEMORY)
        RC__VK_NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        RC__VK_NAME(VK_ERROR_INITIALIZATION_FAILED)
        RC__VK_NAME(VK_ERROR_DEVICE_LOST)
        RC__VK_NAME(VK_ERROR_MEMORY_MAP_FAILED)
        RC__VK_NAME(VK_ERROR_LAYER_NOT_PRESENT)
        RC__VK_NAME(VK_ERROR_EXTENSION_NOT_PRESENT)
        RC__VK_NAME(VK_ERROR_FEATURE_NOT_PRESENT)
        RC__VK_NAME(VK_ERROR_INCOMPATIBLE_DRIVER)
        RC__VK_NAME(VK_ERROR_TOO_MANY_OBJECTS)
        RC__VK_NAME(VK_ERROR_FORMAT_NOT_SUPPORTED)
        RC__VK_NAME(VK_ERROR_FRAGMENTED_POOL)
        RC__VK_NAME(VK_ERROR_UNKNOWN)
        RC__VK_NAME(VK_ERROR_OUT_OF_POOL_MEMORY)
        RC__VK_NAME(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        RC__VK_NAME(VK_ERROR_FRAGMENTATION)
        RC__VK_NAME(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        RC__VK_NAME(VK_ERROR_VALIDATION_FAILED_EXT)
        RC__VK_NAME(VK_ERROR_INVALID_SHADER_NV)
#undef RC__VK_NAME
    default: return "VK_ERROR_(unknown)";
    }
}

rc_status rc__vk_fail(rc__vk_state *st, VkResult r, const char *what)
{
    rc_status s;
    switch (r) {
    case VK_ERROR_OUT_OF_HOST_MEMORY:
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
    case VK_ERROR_OUT_OF_POOL_MEMORY:
    case VK_ERROR_FRAGMENTED_POOL:
    case VK_ERROR_FRAGMENTATION:
    case VK_ERROR_TOO_MANY_OBJECTS: s = RC_ERR_OUT_OF_MEMORY; break;
    case VK_ERROR_DEVICE_LOST:
        s = RC_ERR_DEVICE_LOST;
        st->lost = 1;
        break;
    case VK_ERROR_INCOMPATIBLE_DRIVER:
    case VK_ERROR_FEATURE_NOT_PRESENT:
    case VK_ERROR_EXTENSION_NOT_PRESENT:
    case VK_ERROR_LAYER_NOT_PRESENT: s = RC_ERR_UNSUPPORTED; break;
    default: s = RC_ERR_BACKEND; break;
    }
    return rc__fail(st->ctx, s, "vulkan: %s failed: %s (%d)", what, rc__vk_result_name(r), (int)r);
}

/* ---- host allocation callbacks ----------------------------------------------
 * Every block carries a 16-byte header just below the pointer the driver
 * gets: the size asked for and the distance back to malloc's pointer. The
 * total is kept with atomic adds (drivers may allocate from their threads). */

typedef struct vk_block_header {
    size_t size;
    size_t back;
} vk_block_header;

static void count_bytes(rc__vk_state *st, int64_t delta)
{
#if defined(__GNUC__)
    __atomic_add_fetch(&st->host_bytes, (uint64_t)delta, __ATOMIC_RELAXED);
#else
    st->host_bytes += (uint64_t)delta;
#endif
}

static void *VKAPI_PTR vk_host_alloc(void *user, size_t size, size_t align, VkSystemAllocationScope scope)
{
    rc__vk_state *st = (rc__vk_state *)user;
    unsigned char *raw, *p;
    vk_block_header h;
    (void)scope;
    if (size == 0) return NULL;
    if (align < 16) align = 16;
    if (size > (size_t)-1 - align - sizeof h) return NULL;
    raw = (unsigned char *)malloc(size + align + sizeof h);
    if (!raw) return NULL;
    p = raw + sizeof h;
    p += (align - ((uintptr_t)p % align)) % align;
    h.size = size;
    h.back = (size_t)(p - raw);
    memcpy(p - sizeof h, &h, sizeof h);
    count_bytes(st, (int64_t)size);
    return p;
}

static void VKAPI_PTR vk_host_free(void *user, void *mem)
{
    rc__vk_state *st = (rc__vk_state *)user;
    unsigned char *p = (unsigned char *)mem;
    vk_block_header h;
    if (!p) return;
    memcpy(&h, p - sizeof h, sizeof h);
    count_bytes(st, -(int64_t)h.size);
    free(p - h.back);
}

static void *VKAPI_PTR vk_host_realloc(void *user, void *old, size_t size, size_t align, VkSystemAllocationScope scope)
{
    vk_block_header h;
    void *p;
    if (!old) return vk_host_alloc(user, size, align, scope);
    if (size == 0) {
        vk_host_free(user, old);
        return NULL;
    }
    p = vk_host_alloc(user, size, align, scope);
    if (!p) return NULL;
    memcpy(&h, (unsigned char *)old - sizeof h, sizeof h);
    memcpy(p, old, h.size < size ? h.size : size);
    vk_host_free(user, old);
    return p;
}

void *rc__vk_host_alloc(rc__vk_state *st, size_t size)
{
    return vk_host_alloc(st, size, 16, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
}

void rc__vk_host_free(rc__vk_state *st, void *p) { vk_host_free(st, p); }

/* ---- instance and device ------------------------------------------------------ */

int rc__vk_loader_ok(void)
{
    uint32_t version = 0;
    if (vkEnumerateInstanceVersion(&version) != VK_SUCCESS) return 0;
    return version >= VK_API_VERSION_1_1;
}

static int env_flag(const char *name)
{
    const char *v = getenv(name);
    return v && v[0] && v[0] != '0';
}

static uint64_t env_u64(const char *name, uint64_t fallback)
{
    const char *v = getenv(name);
    char *end = NULL;
    unsigned long long x;
    if (!v || !v[0]) return fallback;
    x = strtoull(v, &end, 10);
    if (end == v || *end) return fallback;
    return (uint64_t)x;
}

static int lower(int c) { return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c; }

static int contains_nocase(const char *hay, const char *needle)
{
    size_t i, j;
    for (i = 0; hay[i]; ++i) {
        for (j = 0; needle[j] && hay[i + j] && lower(hay[i + j]) == lower(needle[j]); ++j) {
        }
        if (!needle[j]) return 1;
    }
    return needle[0] == '\0';
}

static int type_rank(VkPhysicalDeviceType t)
{
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
    }
}

static int compute_family(VkPhysicalDevice pd, uint32_t *family)
{
    VkQueueFamilyProperties q[16];
    uint32_t n = 16, i, best = UINT32_MAX;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, q);
    for (i = 0; i < n; ++i) {
        if (!(q[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || q[i].queueCount == 0) continue;
        /* a compute family without graphics is often an async queue: prefer the first general one */
        if (best == UINT32_MAX || (q[best].queueFlags & VK_QUEUE_GRAPHICS_BIT) == 0) best = i;
        if (q[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) break;
    }
    if (best == UINT32_MAX) return 0;
    *family = best;
    return 1;
}

#define RC__VK_MAX_DEVICES 16u

static rc_status pick_device(rc__vk_state *st)
{
    VkPhysicalDevice devs[RC__VK_MAX_DEVICES];
    VkPhysicalDeviceProperties props[RC__VK_MAX_DEVICES];
    uint32_t n = RC__VK_MAX_DEVICES, i, family = 0;
    int best = -1;
    const char *want = st->want_device ? st->want_device : getenv("RANGECAST_VULKAN_DEVICE");
    char names[384];
    size_t used = 0;
    VkResult r = vkEnumeratePhysicalDevices(st->instance, &n, devs);
    if (r != VK_SUCCESS && r != VK_INCOMPLETE) return rc__vk_fail(st, r, "vkEnumeratePhysicalDevices");
    names[0] = '\0';
    for (i = 0; i < n; ++i) {
        vkGetPhysicalDeviceProperties(devs[i], &props[i]);
        if (used < sizeof names - 1) {
            int w = snprintf(names + used, sizeof names - used, "%s%u: %s", i ? ", " : "", (unsigned)i,
                             props[i].deviceName);
            if (w > 0) used += (size_t)w;
            if (used >= sizeof names) used = sizeof names - 1;
        }
    }
    if (n == 0) return rc__fail(st->ctx, RC_ERR_UNSUPPORTED, "vulkan: no Vulkan device on this machine");
    if (want && want[0]) {
        char *end = NULL;
        unsigned long idx = strtoul(want, &end, 10);
        if (end != want && *end == '\0') {
            if (idx >= n)
                return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                                "vulkan: device \"%s\" (rc_context_desc.device or RANGECAST_VULKAN_DEVICE) but there are %u devices (%s)", want, (unsigned)n,
                                names);
            best = (int)idx;
        } else {
            for (i = 0; i < n && best < 0; ++i)
                if (contains_nocase(props[i].deviceName, want)) best = (int)i;
            if (best < 0)
                return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                                "vulkan: device \"%s\" (rc_context_desc.device or RANGECAST_VULKAN_DEVICE) matches no device (%s)", want, names);
        }
        if (props[best].apiVersion < VK_API_VERSION_1_1 || !compute_family(devs[best], &family))
            return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                            "vulkan: device %d (%s) lacks Vulkan 1.1 or a compute queue", best,
                            props[best].deviceName);
    } else {
        for (i = 0; i < n; ++i) {
            uint32_t f;
            if (props[i].apiVersion < VK_API_VERSION_1_1 || !compute_family(devs[i], &f)) continue;
            if (best < 0 || type_rank(props[i].deviceType) < type_rank(props[best].deviceType)) best = (int)i;
        }
        if (best < 0)
            return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                            "vulkan: no device with Vulkan 1.1 and a compute queue (%s)", names);
        compute_family(devs[best], &family);
    }
    st->phys = devs[best];
    st->props = props[best];
    st->queue_family = family;
    memcpy(st->device_name, props[best].deviceName, sizeof st->device_name);
    return RC_OK;
}

static uint32_t floor_log2(uint64_t x)
{
    uint32_t s = 0;
    while (x > 1u) {
        x >>= 1;
        ++s;
    }
    return s;
}

/* log2 of the elements of elem_size bytes one binding can hold (<= 31). */
static uint32_t chunk_shift(const rc__vk_state *st, uint64_t elem_size)
{
    uint64_t bytes = st->max_binding < st->max_alloc ? st->max_binding : st->max_alloc;
    uint32_t s = floor_log2(bytes / elem_size);
    return s > 31u ? 31u : s;
}

static int find_type(const rc__vk_state *st, uint32_t bits, VkMemoryPropertyFlags need, VkMemoryPropertyFlags want)
{
    uint32_t i;
    int fallback = -1;
    for (i = 0; i < st->mem_props.memoryTypeCount; ++i) {
        VkMemoryPropertyFlags f = st->mem_props.memoryTypes[i].propertyFlags;
        if (!(bits & (1u << i)) || (f & need) != need) continue;
        if ((f & want) == want) return (int)i;
        if (fallback < 0) fallback = (int)i;
    }
    return fallback;
}

/* Memory type of a kind for a buffer whose memoryTypeBits are bits. */
static int type_for(const rc__vk_state *st, uint32_t kind, uint32_t bits)
{
    const VkMemoryPropertyFlags hv = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, hc = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags dl = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    int t;
    if (kind == RC__VK_MEM_UPLOAD) { /* host writes, device reads: ReBAR/UMA memory when there is some */
        t = find_type(st, bits, hv | hc, dl);
        return t >= 0 ? t : find_type(st, bits, hv, 0);
    }
    if (kind == RC__VK_MEM_READBACK) {
        t = find_type(st, bits, hv | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, hc);
        return t >= 0 ? t : find_type(st, bits, hv, hc);
    }
    if (st->device_mappable) {
        t = find_type(st, bits, dl | hv, hc);
        if (t >= 0) return t;
    }
    t = find_type(st, bits, dl, 0);
    return t >= 0 ? t : find_type(st, bits, 0, 0);
}

rc_status rc__vk_buffer_create(rc__vk_state *st, VkDeviceSize size, uint32_t kind, const char *what, rc__vk_buffer *out)
{
    return rc__vk_buffer_create_usage(st, size, kind, 0, what, out);
}

VkDeviceAddress rc__vk_buffer_address(const rc__vk_state *st, const rc__vk_buffer *b)
{
    VkBufferDeviceAddressInfo ai;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
    ai.buffer = b->buf;
    return st->get_address(st->device, &ai);
}

rc_status rc__vk_buffer_create_usage(rc__vk_state *st, VkDeviceSize size, uint32_t kind, VkBufferUsageFlags usage,
                                     const char *what, rc__vk_buffer *out)
{
    VkBufferCreateInfo bi;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo ai;
    VkMemoryAllocateFlagsInfo af;
    VkMemoryPropertyFlags flags;
    VkResult r;
    int type;
    memset(out, 0, sizeof *out);
    if (size < 16) size = 16;
    size = (size + 15u) & ~(VkDeviceSize)15u;
    RC_RETURN_IF(st->ctx, size > st->max_alloc, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: the %s buffer needs %llu bytes; this device allocates at most %llu "
                 "(maxMemoryAllocationSize)",
                 what, (unsigned long long)size, (unsigned long long)st->max_alloc);
    RC_RETURN_IF(st->ctx, kind == RC__VK_MEM_DEVICE && st->heap_bytes + size > st->heap_size, RC_ERR_OUT_OF_MEMORY,
                 "vulkan: the %s buffer needs %llu bytes; %llu of the device heap's %llu are in use", what,
                 (unsigned long long)size, (unsigned long long)st->heap_bytes, (unsigned long long)st->heap_size);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size;
    bi.usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | usage;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    r = vkCreateBuffer(st->device, &bi, RC__VK_OBJ_ALLOC, &out->buf);
    if (r != VK_SUCCESS) {
        out->buf = VK_NULL_HANDLE;
        return rc__vk_fail(st, r, "vkCreateBuffer");
    }
    vkGetBufferMemoryRequirements(st->device, out->buf, &req);
    type = type_for(st, kind, req.memoryTypeBits);
    if (type < 0) {
        rc__vk_buffer_destroy(st, out);
        return rc__fail(st->ctx, RC_ERR_UNSUPPORTED, "vulkan: no memory type for the %s buffer", what);
    }
    if (st->budget_bytes && st->device_bytes + req.size > st->budget_bytes) {
        rc__vk_buffer_destroy(st, out);
        return rc__fail(st->ctx, RC_ERR_OUT_OF_MEMORY,
                        "vulkan: the %s buffer needs %llu bytes; with the %llu bytes held it would pass the "
                        "backend budget of %llu bytes (rc_context_desc.backend_budget_mib)",
                        what, (unsigned long long)req.size, (unsigned long long)st->device_bytes,
                        (unsigned long long)st->budget_bytes);
    }
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = (uint32_t)type;
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
        memset(&af, 0, sizeof af);
        af.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
        af.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        ai.pNext = &af;
    }
    r = vkAllocateMemory(st->device, &ai, RC__VK_OBJ_ALLOC, &out->mem);
    if (r != VK_SUCCESS) {
        out->mem = VK_NULL_HANDLE;
        rc__vk_buffer_destroy(st, out);
        if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
            return rc__fail(st->ctx, RC_ERR_OUT_OF_MEMORY,
                            "vulkan: vkAllocateMemory of %llu bytes for the %s buffer failed: %s",
                            (unsigned long long)req.size, what, rc__vk_result_name(r));
        return rc__vk_fail(st, r, "vkAllocateMemory");
    }
    out->size = size;
    out->alloc_size = req.size;
    out->kind = kind;
    st->device_bytes += req.size;
    if (kind == RC__VK_MEM_DEVICE) st->heap_bytes += req.size;
    r = vkBindBufferMemory(st->device, out->buf, out->mem, 0);
    if (r != VK_SUCCESS) {
        rc__vk_buffer_destroy(st, out);
        return rc__vk_fail(st, r, "vkBindBufferMemory");
    }
    flags = st->mem_props.memoryTypes[type].propertyFlags;
    out->coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) ? 1u : 0u;
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
        r = vkMapMemory(st->device, out->mem, 0, VK_WHOLE_SIZE, 0, &out->map);
        if (r != VK_SUCCESS) {
            out->map = NULL;
            rc__vk_buffer_destroy(st, out);
            return rc__vk_fail(st, r, "vkMapMemory");
        }
    }
    return RC_OK;
}

void rc__vk_buffer_destroy(rc__vk_state *st, rc__vk_buffer *b)
{
    if (b->buf != VK_NULL_HANDLE) vkDestroyBuffer(st->device, b->buf, RC__VK_OBJ_ALLOC);
    if (b->mem != VK_NULL_HANDLE) {
        vkFreeMemory(st->device, b->mem, RC__VK_OBJ_ALLOC); /* unmaps too */
        st->device_bytes -= b->alloc_size;
        if (b->kind == RC__VK_MEM_DEVICE) st->heap_bytes -= b->alloc_size;
    }
    memset(b, 0, sizeof *b);
}

rc_status rc__vk_buffer_flush(rc__vk_state *st, const rc__vk_buffer *b)
{
    VkMappedMemoryRange range;
    if (!b->map || b->coherent) return RC_OK;
    memset(&range, 0, sizeof range);
    range.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE;
    range.memory = b->mem;
    range.size = VK_WHOLE_SIZE;
    RC__VK_TRY(st, vkFlushMappedMemoryRanges(st->device, 1, &range), "vkFlushMappedMemoryRanges");
    return RC_OK;
}

rc_status rc__vk_buffer_invalidate(rc__vk_state *st, const rc__vk_buffer *b)
{
    VkMappedMemoryRange range;
    if (!b->map || b->coherent) return RC_OK;
    memset(&range, 0, sizeof range);
    range.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE;
    range.memory = b->mem;
    range.size = VK_WHOLE_SIZE;
    RC__VK_TRY(st, vkInvalidateMappedMemoryRanges(st->device, 1, &range), "vkInvalidateMappedMemoryRanges");
    return RC_OK;
}

rc_status rc__vk_wait(rc__vk_state *st, uint32_t slot)
{
    VkResult r;
    if (!st->inflight[slot]) return RC_OK;
    st->inflight[slot] = 0;
    r = vkWaitForFences(st->device, 1, &st->fence[slot], VK_TRUE, UINT64_MAX);
    if (r != VK_SUCCESS) return rc__vk_fail(st, r, "vkWaitForFences");
    RC__VK_TRY(st, vkResetFences(st->device, 1, &st->fence[slot]), "vkResetFences");
    return RC_OK;
}

rc_status rc__vk_submit(rc__vk_state *st, uint32_t slot)
{
    VkSubmitInfo si;
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &st->cmd[slot];
    RC__VK_TRY(st, vkQueueSubmit(st->queue, 1, &si, st->fence[slot]), "vkQueueSubmit");
    st->inflight[slot] = 1;
    return RC_OK;
}

rc_status rc__vk_begin(rc__vk_state *st, uint32_t slot)
{
    VkCommandBufferBeginInfo bi;
    RC_TRY(rc__vk_wait(st, slot));
    RC__VK_TRY(st, vkResetCommandBuffer(st->cmd[slot], 0), "vkResetCommandBuffer");
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    RC__VK_TRY(st, vkBeginCommandBuffer(st->cmd[slot], &bi), "vkBeginCommandBuffer");
    return RC_OK;
}

void rc__vk_barrier(rc__vk_state *st, VkCommandBuffer cb, VkPipelineStageFlags src_stage, VkAccessFlags src,
                    VkPipelineStageFlags dst_stage, VkAccessFlags dst)
{
    VkMemoryBarrier mb;
    /* lavapipe 22.3 frees a stack array through the device's allocation
     * callbacks in vkCmdPipelineBarrier (it crashes whenever callbacks are
     * set). A CPU device executes submissions in order on memory the host
     * sees, so there the barrier is skipped. */
    if (st->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) return;
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = src;
    mb.dstAccessMask = dst;
    vkCmdPipelineBarrier(cb, src_stage, dst_stage, 0, 1, &mb, 0, NULL, 0, NULL);
}

rc_status rc__vk_copy(rc__vk_state *st, const rc__vk_buffer *src, const rc__vk_buffer *dst, VkDeviceSize src_off,
                      VkDeviceSize size)
{
    return rc__vk_copy_region(st, src, dst, src_off, 0, size);
}

rc_status rc__vk_copy_region(rc__vk_state *st, const rc__vk_buffer *src, const rc__vk_buffer *dst,
                             VkDeviceSize src_off, VkDeviceSize dst_off, VkDeviceSize size)
{
    VkBufferCopy region;
    RC_TRY(rc__vk_buffer_flush(st, src));
    RC_TRY(rc__vk_begin(st, 0));
    region.srcOffset = src_off;
    region.dstOffset = dst_off;
    region.size = size;
    vkCmdCopyBuffer(st->cmd[0], src->buf, dst->buf, 1, &region);
    rc__vk_barrier(st, st->cmd[0], VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    RC__VK_TRY(st, vkEndCommandBuffer(st->cmd[0]), "vkEndCommandBuffer");
    RC_TRY(rc__vk_submit(st, 0));
    return rc__vk_wait(st, 0);
}

/* ---- context-level setup ------------------------------------------------------ */

static rc_status device_limits(rc__vk_state *st)
{
    VkPhysicalDeviceSubgroupProperties sub;
    VkPhysicalDeviceMaintenance3Properties m3;
    VkPhysicalDeviceProperties2 p2;
    VkPhysicalDeviceFeatures feats;
    const VkPhysicalDeviceLimits *lim = &st->props.limits;
    uint64_t env;
    memset(&sub, 0, sizeof sub);
    memset(&m3, 0, sizeof m3);
    memset(&p2, 0, sizeof p2);
    sub.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    m3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES;
    m3.pNext = &sub;
    p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p2.pNext = &m3;
    vkGetPhysicalDeviceProperties2(st->phys, &p2);
    st->subgroup_size = sub.subgroupSize ? sub.subgroupSize : 1u;
    st->max_alloc = m3.maxMemoryAllocationSize ? m3.maxMemoryAllocationSize : ((uint64_t)1 << 30);
    st->max_binding = lim->maxStorageBufferRange;
    env = env_u64("RANGECAST_VULKAN_MAX_BINDING", 0);
    if (env >= 1024 && env < st->max_binding) st->max_binding = env & ~(uint64_t)15u;
    vkGetPhysicalDeviceFeatures(st->phys, &feats);
    st->fp64 = feats.shaderFloat64 && !env_flag("RANGECAST_VULKAN_NO_FP64");
    st->debug_flags = env_flag("RANGECAST_VULKAN_SKEW_DIV") ? RC__VK_FLAGS_SKEW_DIV : 0u;
    {
        const char *skip = getenv("RANGECAST_VULKAN_SKIP");
        if (skip && strcmp(skip, "walk") == 0) st->debug_flags |= RC__VK_FLAGS_SKIP_WALK;
        if (skip && strcmp(skip, "refine") == 0) st->debug_flags |= RC__VK_FLAGS_SKIP_REFINE;
    }

    RC_RETURN_IF(st->ctx, lim->maxPushConstantsSize < sizeof(rc__vk_push), RC_ERR_UNSUPPORTED,
                 "vulkan: %s has %u bytes of push constants; rangecast needs %u", st->device_name,
                 (unsigned)lim->maxPushConstantsSize, (unsigned)sizeof(rc__vk_push));
    if (lim->maxPerStageDescriptorStorageBuffers >= RC__VK_BINDINGS && lim->maxPerStageResources >= RC__VK_BINDINGS &&
        env_u64("RANGECAST_VULKAN_CHUNKS", 4) != 1)
        st->chunks = RC__VK_MAX_CHUNKS;
    else
        st->chunks = 1;
    RC_RETURN_IF(st->ctx, lim->maxPerStageDescriptorStorageBuffers < RC__VK_BINDINGS - 9u, RC_ERR_UNSUPPORTED,
                 "vulkan: %s binds %u storage buffers per stage; rangecast needs %u", st->device_name,
                 (unsigned)lim->maxPerStageDescriptorStorageBuffers, (unsigned)(RC__VK_BINDINGS - 9u));
    st->node_shift = chunk_shift(st, sizeof(rc__bvh_node));
    st->tri_shift = chunk_shift(st, 12u);
    st->vert_shift = chunk_shift(st, 12u);

    /* Workgroup size: one ray per invocation. 64 fills a warp/wave on every GPU
     * (and is what lavapipe runs best, see the report in vulkan.c). */
    env = env_u64("RANGECAST_VULKAN_WG", 0);
    st->wg_size = 64u;
    if (st->subgroup_size > 64u) st->wg_size = st->subgroup_size;
    if (env >= 8 && env <= 1024 && (env & (env - 1u)) == 0) st->wg_size = (uint32_t)env;
    if (st->wg_size > lim->maxComputeWorkGroupSize[0]) st->wg_size = lim->maxComputeWorkGroupSize[0];
    if (st->wg_size > lim->maxComputeWorkGroupInvocations) st->wg_size = lim->maxComputeWorkGroupInvocations;

    /* 8 MiB (2M ranges a dispatch): on lavapipe 32 MiB left the device idle
     * while the host copied (98 against 142 scans/s for 1000 VLP-16 poses);
     * 2 and 8 measured the same. A discrete GPU takes 64 MiB: fewer, larger
     * dispatches kept an H100 busier (10,000 VLP-16 poses on the 1M sphere,
     * results kept on the device: 89.0k -> 97.9k scans/s) */
    {
        const uint64_t mib = st->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? 64u : 8u;
        env = env_u64("RANGECAST_VULKAN_SLOT_MB", mib);
        st->slot_bytes = (env ? env : mib) << 20;
    }
    if (st->slot_bytes > st->max_binding) st->slot_bytes = st->max_binding & ~(uint64_t)15u;
    if (st->slot_bytes > st->max_alloc) st->slot_bytes = st->max_alloc & ~(uint64_t)15u;
    return RC_OK;
}

/* Is device memory host-visible (UMA, lavapipe), and how big is its heap? */
static rc_status probe_memory(rc__vk_state *st)
{
    VkBufferCreateInfo bi;
    VkMemoryRequirements req;
    VkBuffer probe = VK_NULL_HANDLE;
    int t;
    vkGetPhysicalDeviceMemoryProperties(st->phys, &st->mem_props);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = 256;
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    RC__VK_TRY(st, vkCreateBuffer(st->device, &bi, RC__VK_OBJ_ALLOC, &probe), "vkCreateBuffer");
    vkGetBufferMemoryRequirements(st->device, probe, &req);
    vkDestroyBuffer(st->device, probe, RC__VK_OBJ_ALLOC);
    st->device_mappable = 0;
    t = find_type(st, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
    if (t < 0) t = find_type(st, req.memoryTypeBits, 0, 0);
    RC_RETURN_IF(st->ctx, t < 0, RC_ERR_UNSUPPORTED, "vulkan: %s has no memory type for storage buffers",
                 st->device_name);
    /* On a device whose only device-local memory is host-visible (UMA), map it
     * directly. A discrete GPU's host-visible device-local type (ReBAR) is
     * usually small: there we stage. */
    if ((st->mem_props.memoryTypes[t].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) &&
        st->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU && !env_flag("RANGECAST_VULKAN_STAGING"))
        st->device_mappable = 1;
    st->heap_size = st->mem_props.memoryHeaps[st->mem_props.memoryTypes[t].heapIndex].size;
    return RC_OK;
}

/* ---- ray query (RC_CONTEXT_VULKAN_RAY_QUERY) ------------------------------- */

static const char *const ray_query_extensions[] = {"VK_KHR_acceleration_structure", "VK_KHR_ray_query",
                                                   "VK_KHR_deferred_host_operations"};

typedef struct rq_features {
    VkPhysicalDeviceBufferDeviceAddressFeatures bda;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel;
    VkPhysicalDeviceRayQueryFeaturesKHR query;
} rq_features;

/* The chosen device has what the ray query traversal needs: Vulkan 1.2, the
 * extensions and their features. RC_ERR_UNSUPPORTED naming what is missing. */
/* The device's extension names, through the counting allocator (a list on
 * the stack would be 260 bytes an entry, on a thread whose stack may be
 * small; a fixed-size one could come back VK_INCOMPLETE). */
rc_status rc__vk_device_extensions(rc__vk_state *st, VkExtensionProperties **out, uint32_t *count)
{
    uint32_t n = 0;
    VkResult r = vkEnumerateDeviceExtensionProperties(st->phys, NULL, &n, NULL);
    *out = NULL;
    *count = 0;
    if (r != VK_SUCCESS) return rc__vk_fail(st, r, "vkEnumerateDeviceExtensionProperties");
    *out = (VkExtensionProperties *)rc__vk_host_alloc(st, (size_t)(n ? n : 1) * sizeof **out);
    RC_RETURN_IF(st->ctx, *out == NULL, RC_ERR_OUT_OF_MEMORY, "vulkan: no host memory for %u extension names",
                 (unsigned)n);
    r = vkEnumerateDeviceExtensionProperties(st->phys, NULL, &n, *out);
    if (r != VK_SUCCESS && r != VK_INCOMPLETE) {
        rc__vk_host_free(st, *out);
        *out = NULL;
        return rc__vk_fail(st, r, "vkEnumerateDeviceExtensionProperties");
    }
    *count = n;
    return RC_OK;
}

static rc_status ray_query_support(rc__vk_state *st)
{
    VkExtensionProperties *ext;
    uint32_t n, i, k;
    VkPhysicalDeviceFeatures2 f2;
    VkPhysicalDeviceAccelerationStructurePropertiesKHR ap;
    VkPhysicalDeviceProperties2 p2;
    rq_features rq;
    RC_RETURN_IF(st->ctx, st->props.apiVersion < VK_API_VERSION_1_2, RC_ERR_UNSUPPORTED,
                 "vulkan: RC_CONTEXT_VULKAN_RAY_QUERY needs Vulkan 1.2; %s has %u.%u", st->device_name,
                 (unsigned)VK_VERSION_MAJOR(st->props.apiVersion), (unsigned)VK_VERSION_MINOR(st->props.apiVersion));
    RC_TRY(rc__vk_device_extensions(st, &ext, &n));
    for (k = 0; k < sizeof ray_query_extensions / sizeof ray_query_extensions[0]; ++k) {
        int found = 0;
        for (i = 0; i < n && !found; ++i) found = strcmp(ext[i].extensionName, ray_query_extensions[k]) == 0;
        if (!found) {
            rc__vk_host_free(st, ext);
            return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                            "vulkan: RC_CONTEXT_VULKAN_RAY_QUERY needs %s, which %s does not offer (Mesa's lavapipe "
                            "has it from 23.1 on)",
                            ray_query_extensions[k], st->device_name);
        }
    }
    rc__vk_host_free(st, ext);
    memset(&rq, 0, sizeof rq);
    rq.bda.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES;
    rq.bda.pNext = &rq.accel;
    rq.accel.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    rq.accel.pNext = &rq.query;
    rq.query.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
    memset(&f2, 0, sizeof f2);
    f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    f2.pNext = &rq.bda;
    vkGetPhysicalDeviceFeatures2(st->phys, &f2);
    RC_RETURN_IF(st->ctx, !rq.bda.bufferDeviceAddress || !rq.accel.accelerationStructure || !rq.query.rayQuery,
                 RC_ERR_UNSUPPORTED,
                 "vulkan: RC_CONTEXT_VULKAN_RAY_QUERY: %s lacks a feature it needs (bufferDeviceAddress %u, "
                 "accelerationStructure %u, rayQuery %u)",
                 st->device_name, (unsigned)rq.bda.bufferDeviceAddress, (unsigned)rq.accel.accelerationStructure,
                 (unsigned)rq.query.rayQuery);
    memset(&ap, 0, sizeof ap);
    ap.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
    memset(&p2, 0, sizeof p2);
    p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p2.pNext = &ap;
    vkGetPhysicalDeviceProperties2(st->phys, &p2);
    st->scratch_align = ap.minAccelerationStructureScratchOffsetAlignment;
    if (st->scratch_align == 0) st->scratch_align = 1;
    return RC_OK;
}

/* The extension's entry points, through the device (no link-time dependency
 * on a Vulkan 1.2 loader). */
static rc_status ray_query_functions(rc__vk_state *st)
{
    st->get_address = (PFN_vkGetBufferDeviceAddress)vkGetDeviceProcAddr(st->device, "vkGetBufferDeviceAddress");
    st->create_as =
        (PFN_vkCreateAccelerationStructureKHR)vkGetDeviceProcAddr(st->device, "vkCreateAccelerationStructureKHR");
    st->destroy_as =
        (PFN_vkDestroyAccelerationStructureKHR)vkGetDeviceProcAddr(st->device, "vkDestroyAccelerationStructureKHR");
    st->as_sizes = (PFN_vkGetAccelerationStructureBuildSizesKHR)vkGetDeviceProcAddr(
        st->device, "vkGetAccelerationStructureBuildSizesKHR");
    st->build_as =
        (PFN_vkCmdBuildAccelerationStructuresKHR)vkGetDeviceProcAddr(st->device, "vkCmdBuildAccelerationStructuresKHR");
    st->as_address = (PFN_vkGetAccelerationStructureDeviceAddressKHR)vkGetDeviceProcAddr(
        st->device, "vkGetAccelerationStructureDeviceAddressKHR");
    RC_RETURN_IF(st->ctx, !st->get_address || !st->create_as || !st->destroy_as || !st->as_sizes || !st->build_as ||
                              !st->as_address,
                 RC_ERR_BACKEND, "vulkan: %s enabled VK_KHR_acceleration_structure but lacks one of its functions",
                 st->device_name);
    st->ray_query = 1;
    return RC_OK;
}

rc_status rc__vk_device_create(rc__vk_state *st)
{
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkDeviceQueueCreateInfo qi;
    VkDeviceCreateInfo dci;
    VkPhysicalDeviceFeatures enable;
    rq_features rq;
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR pe;
    const char *names[4];
    uint32_t name_count = 0;
    VkCommandPoolCreateInfo pci;
    VkCommandBufferAllocateInfo cai;
    VkFenceCreateInfo fi;
    const float priority = 1.0f;
    uint32_t i;

    if (env_flag("RANGECAST_VULKAN_RAY_QUERY")) st->want_ray_query = 1;
    st->alloc.pUserData = st;
    st->alloc.pfnAllocation = vk_host_alloc;
    st->alloc.pfnReallocation = vk_host_realloc;
    st->alloc.pfnFree = vk_host_free;
    RC_RETURN_IF(st->ctx, !rc__vk_loader_ok(), RC_ERR_UNSUPPORTED,
                 "vulkan: no Vulkan 1.1 loader (vkEnumerateInstanceVersion)");
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "rangecast";
    app.pEngineName = "rangecast";
    app.engineVersion = RC_VERSION_NUMBER;
    /* 1.2 for buffer device addresses, which ray query's structures need */
    app.apiVersion = st->want_ray_query ? VK_API_VERSION_1_2 : VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    {
        VkResult r = vkCreateInstance(&ici, &st->alloc, &st->instance);
        if (r != VK_SUCCESS) {
            st->instance = VK_NULL_HANDLE;
            if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
                return rc__fail(st->ctx, RC_ERR_UNSUPPORTED,
                                "vulkan: vkCreateInstance failed: VK_ERROR_INCOMPATIBLE_DRIVER (no Vulkan driver)");
            return rc__vk_fail(st, r, "vkCreateInstance");
        }
    }
    RC_TRY(pick_device(st));
    RC_TRY(device_limits(st));
    if (st->want_ray_query) RC_TRY(ray_query_support(st));
    st->stats = (uint32_t)rc__vk_stats_wanted(st);

    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qi.queueFamilyIndex = st->queue_family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    memset(&enable, 0, sizeof enable);
    enable.shaderFloat64 = st->fp64 ? VK_TRUE : VK_FALSE;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qi;
    dci.pEnabledFeatures = &enable;
    if (st->stats) {
        memset(&pe, 0, sizeof pe);
        pe.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
        pe.pipelineExecutableInfo = VK_TRUE;
        dci.pNext = &pe;
        names[name_count++] = rc__vk_stats_extension;
    }
    if (st->want_ray_query) {
        memset(&rq, 0, sizeof rq);
        rq.bda.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES;
        rq.bda.bufferDeviceAddress = VK_TRUE;
        rq.bda.pNext = &rq.accel;
        rq.accel.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
        rq.accel.accelerationStructure = VK_TRUE;
        rq.accel.pNext = &rq.query;
        rq.query.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
        rq.query.rayQuery = VK_TRUE;
        rq.query.pNext = (void *)dci.pNext;
        dci.pNext = &rq.bda;
        for (i = 0; i < sizeof ray_query_extensions / sizeof ray_query_extensions[0]; ++i)
            names[name_count++] = ray_query_extensions[i];
    }
    dci.enabledExtensionCount = name_count;
    dci.ppEnabledExtensionNames = name_count ? names : NULL;
    {
        VkResult r = vkCreateDevice(st->phys, &dci, &st->alloc, &st->device);
        if (r != VK_SUCCESS) {
            st->device = VK_NULL_HANDLE;
            return rc__vk_fail(st, r, "vkCreateDevice");
        }
    }
    vkGetDeviceQueue(st->device, st->queue_family, 0, &st->queue);
    if (st->want_ray_query) RC_TRY(ray_query_functions(st));
    RC_TRY(probe_memory(st));

    memset(&pci, 0, sizeof pci);
    pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = st->queue_family;
    RC__VK_TRY(st, vkCreateCommandPool(st->device, &pci, RC__VK_OBJ_ALLOC, &st->cmd_pool), "vkCreateCommandPool");
    memset(&cai, 0, sizeof cai);
    cai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cai.commandPool = st->cmd_pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = RC__VK_SLOTS;
    RC__VK_TRY(st, vkAllocateCommandBuffers(st->device, &cai, st->cmd), "vkAllocateCommandBuffers");
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    for (i = 0; i < RC__VK_SLOTS; ++i)
        RC__VK_TRY(st, vkCreateFence(st->device, &fi, RC__VK_OBJ_ALLOC, &st->fence[i]), "vkCreateFence");
    return RC_OK;
}

void rc__vk_device_destroy(rc__vk_state *st)
{
    uint32_t i;
    if (st->device != VK_NULL_HANDLE) {
        (void)vkDeviceWaitIdle(st->device); /* may report a lost device: destroy anyway */
        for (i = 0; i < RC__VK_SLOTS; ++i) {
            if (st->fence[i] != VK_NULL_HANDLE) vkDestroyFence(st->device, st->fence[i], RC__VK_OBJ_ALLOC);
            st->fence[i] = VK_NULL_HANDLE;
            st->inflight[i] = 0;
        }
        if (st->cmd_pool != VK_NULL_HANDLE) vkDestroyCommandPool(st->device, st->cmd_pool, RC__VK_OBJ_ALLOC);
        st->cmd_pool = VK_NULL_HANDLE;
        vkDestroyDevice(st->device, &st->alloc);
        st->device = VK_NULL_HANDLE;
    }
    if (st->instance != VK_NULL_HANDLE) vkDestroyInstance(st->instance, &st->alloc);
    st->instance = VK_NULL_HANDLE;
}
