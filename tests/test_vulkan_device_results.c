/* Results kept on the device (RC_RESULTS_ON_DEVICE): a consumer reads the
 * exposed VkBuffer through its own Vulkan calls on the exposed device and
 * finds, bit for bit, what rc_simulate writes to host buffers; the buffer's
 * description goes stale at the next simulate; too large a batch is a
 * capacity error, not a device fault. */
#include <math.h>
#include <string.h>

#include <vulkan/vulkan.h>

#include "rc_test.h"

#define NEED_VULKAN()                                       \
    do {                                                    \
        if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip(); \
    } while (0)

/* The consumer's side: copy bytes [0, size) of the rangecast buffer into a
 * host-visible buffer of our own and map it. */
typedef struct readback {
    VkDevice device;
    VkBuffer buf;
    VkDeviceMemory mem;
    void *map;
} readback;

static void read_device_buffer(const rc_device_results *dr, readback *rb)
{
    VkDevice dev;
    VkPhysicalDevice phys;
    VkBuffer src;
    VkBufferCreateInfo bi;
    VkMemoryRequirements req;
    VkPhysicalDeviceMemoryProperties mp;
    VkMemoryAllocateInfo ai;
    VkCommandPoolCreateInfo pi;
    VkCommandPool pool;
    VkCommandBufferAllocateInfo cai;
    VkCommandBuffer cb;
    VkCommandBufferBeginInfo begin;
    VkBufferCopy copy;
    VkSubmitInfo si;
    VkQueue queue;
    VkPhysicalDeviceProperties props;
    uint32_t t, type = UINT32_MAX;
    memcpy(&dev, &dr->device, sizeof dev);
    memcpy(&phys, &dr->physical_device, sizeof phys);
    memcpy(&src, &dr->buffer, sizeof src);
    rb->device = dev;
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = dr->bytes;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    assert_int_equal(vkCreateBuffer(dev, &bi, NULL, &rb->buf), VK_SUCCESS);
    vkGetBufferMemoryRequirements(dev, rb->buf, &req);
    vkGetPhysicalDeviceMemoryProperties(phys, &mp);
    for (t = 0; t < mp.memoryTypeCount && type == UINT32_MAX; ++t)
        if ((req.memoryTypeBits & (1u << t)) &&
            (mp.memoryTypes[t].propertyFlags & (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) ==
                (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT))
            type = t;
    assert_true(type != UINT32_MAX);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    assert_int_equal(vkAllocateMemory(dev, &ai, NULL, &rb->mem), VK_SUCCESS);
    assert_int_equal(vkBindBufferMemory(dev, rb->buf, rb->mem, 0), VK_SUCCESS);

    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.queueFamilyIndex = dr->queue_family;
    assert_int_equal(vkCreateCommandPool(dev, &pi, NULL, &pool), VK_SUCCESS);
    memset(&cai, 0, sizeof cai);
    cai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cai.commandPool = pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    assert_int_equal(vkAllocateCommandBuffers(dev, &cai, &cb), VK_SUCCESS);
    memset(&begin, 0, sizeof begin);
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    assert_int_equal(vkBeginCommandBuffer(cb, &begin), VK_SUCCESS);
    vkGetPhysicalDeviceProperties(phys, &props);
    if (props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) {
        /* the consumer's own barrier: rangecast's compute writes before our
         * copy (lavapipe 22.3 crashes in vkCmdPipelineBarrier on a device with
         * allocation callbacks, as ours has; a CPU device needs none) */
        VkMemoryBarrier mb;
        memset(&mb, 0, sizeof mb);
        mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
        mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0,
                             NULL, 0, NULL);
    }
    copy.srcOffset = 0;
    copy.dstOffset = 0;
    copy.size = dr->bytes;
    vkCmdCopyBuffer(cb, src, rb->buf, 1, &copy);
    assert_int_equal(vkEndCommandBuffer(cb), VK_SUCCESS);
    vkGetDeviceQueue(dev, dr->queue_family, 0, &queue);
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    assert_int_equal(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
    assert_int_equal(vkQueueWaitIdle(queue), VK_SUCCESS);
    vkDestroyCommandPool(dev, pool, NULL);
    assert_int_equal(vkMapMemory(dev, rb->mem, 0, VK_WHOLE_SIZE, 0, &rb->map), VK_SUCCESS);
}

static void readback_free(readback *rb)
{
    vkUnmapMemory(rb->device, rb->mem);
    vkDestroyBuffer(rb->device, rb->buf, NULL);
    vkFreeMemory(rb->device, rb->mem, NULL);
}

static void test_device_results_match_host(void **state)
{
    rcu_mesh m, box;
    const float lo[3] = {-3.0f, -2.0f, -1.0f}, hi[3] = {2.0f, 4.0f, 1.5f};
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rc_pose poses[3];
    rct_buffers host;
    rc_results dev = rc_results_default();
    rc_device_results dr = rc_device_results_default();
    readback rb;
    uint64_t n, k;
    const unsigned char *base;
    uint32_t valid = 0;
    (void)state;
    NEED_VULKAN();
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 60, 30, &m), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    assert_int_equal(rcu_mesh_append(&m, &box), 0);
    ctx = rct_context(RC_BACKEND_VULKAN, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
    poses[0] = rct_pose(5.0f, 0.0f, 0.0f);
    poses[1] = rct_pose_ypr(-6.0f, 3.0f, 0.5f, 0.7, 0.1, -0.2);
    poses[2] = rct_pose_ypr(0.0f, 8.0f, -2.0f, -2.0, -0.3, 0.05);
    n = 3u * 16u * 900u;
    rct_buffers_alloc(&host, n, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 3, &host.res));

    /* nothing on the device yet */
    assert_int_equal(rc_context_get_device_results(ctx, &dr), RC_ERR_INVALID_ARGUMENT);

    dev.attributes = RC_ATTR_ALL;
    dev.flags = RC_RESULTS_ON_DEVICE; /* no host buffers, no capacity */
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 3, &dev));
    RCT_OK(ctx, rc_context_get_device_results(ctx, &dr));
    assert_int_equal(dr.attributes, RC_ATTR_ALL);
    assert_true(dr.elements == n);
    assert_true(dr.buffer != 0 && dr.device != 0 && dr.physical_device != 0 && dr.instance != 0);
    assert_true(dr.bytes == n * (1u + 1u + 3u + 3u + 1u + 1u + 1u) * 4u);
    for (k = 0; k < 7; ++k) assert_true(dr.offsets[k] < dr.bytes && dr.offsets[k] % 4u == 0);

    read_device_buffer(&dr, &rb);
    base = (const unsigned char *)rb.map;
    for (k = 0; k < n; ++k) {
        uint32_t h;
        memcpy(&h, base + dr.offsets[0] + 4u * k, 4);
        assert_int_equal(h, host.res.hits[k]);
        valid += h;
        assert_memory_equal(base + dr.offsets[1] + 4u * k, &host.res.ranges[k], 4);
        assert_memory_equal(base + dr.offsets[2] + 12u * k, &host.res.points[3u * k], 12);
        assert_memory_equal(base + dr.offsets[3] + 12u * k, &host.res.normals[3u * k], 12);
        assert_memory_equal(base + dr.offsets[4] + 4u * k, &host.res.prim_ids[k], 4);
        assert_memory_equal(base + dr.offsets[5] + 4u * k, &host.res.geom_ids[k], 4);
        assert_memory_equal(base + dr.offsets[6] + 4u * k, &host.res.inst_ids[k], 4);
    }
    assert_true(valid > n / 2u); /* inside a closed sphere: most rays return */
    readback_free(&rb);

    /* ranges only: one array at offset 0, the others absent */
    dev.attributes = RC_ATTR_RANGES;
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 3, &dev));
    RCT_OK(ctx, rc_context_get_device_results(ctx, &dr));
    assert_true(dr.offsets[1] == 0 && dr.bytes == n * 4u);
    assert_true(dr.offsets[0] == UINT64_MAX && dr.offsets[6] == UINT64_MAX);
    read_device_buffer(&dr, &rb);
    assert_memory_equal(rb.map, host.res.ranges, (size_t)n * 4u);
    readback_free(&rb);

    /* a host simulate makes the description stale */
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 1, &host.res));
    assert_int_equal(rc_context_get_device_results(ctx, &dr), RC_ERR_INVALID_ARGUMENT);

    rct_buffers_free(&host);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
    rcu_mesh_free(&box);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_device_results_match_host)};
    return cmocka_run_group_tests_name("vulkan device results", tests, NULL, NULL);
}
