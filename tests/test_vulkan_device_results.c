/* Results kept on the device (RC_RESULTS_ON_DEVICE): a consumer reads the
 * exposed VkBuffer through its own Vulkan calls on the exposed device and
 * finds, bit for bit, what rc_simulate writes to host buffers; the buffer's
 * description goes stale at the next simulate; too large a batch is a
 * capacity error, not a device fault. With noise on the sensor the kernel
 * applies it there: the same returns lost as the host's pass, the same
 * spread within float rounding (float64 kernel) or within GLSL's loose
 * log/cos (float-only kernel). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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

/* One noisy batch, on the host and on the device, from two sensors with the
 * same noise (so both use draw `calls - 1` on their last call): hit flags
 * (dropout) equal, ranges and points within tol (metres, plus 1e-6
 * relative). *moved counts returns whose range (or, without ranges, point)
 * the noise changed; returns how many of those ranges were bit-identical;
 * *max_diff gets the largest range difference (m). */
static uint64_t compare_noisy(rc_context *ctx, rc_scene *scene, const rc_noise_desc *noise, uint32_t attributes,
                              const rc_pose *poses, uint32_t pose_count, uint32_t calls, double tol, uint64_t *moved,
                              double *max_diff)
{
    rc_sensor *hs, *ds, *clean;
    rct_buffers host, ref;
    rc_results dev = rc_results_default();
    rc_device_results dr = rc_device_results_default();
    readback rb;
    const unsigned char *base;
    const uint64_t n = (uint64_t)pose_count * 16u * 900u;
    uint64_t k, same = 0;
    uint32_t c, words = 0, a;
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &hs));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &ds));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &clean));
    RCT_OK(ctx, rc_sensor_set_noise(hs, noise));
    RCT_OK(ctx, rc_sensor_set_noise(ds, noise));
    rct_buffers_alloc(&host, n, RC_ATTR_ALL);
    rct_buffers_alloc(&ref, n, RC_ATTR_ALL);
    host.res.attributes = attributes;
    dev.attributes = attributes;
    dev.flags = RC_RESULTS_ON_DEVICE;
    /* the clean scan first: a host simulate makes the device results stale */
    RCT_OK(ctx, rc_simulate(ctx, scene, clean, poses, pose_count, &ref.res));
    for (c = 0; c < calls; ++c) {
        RCT_OK(ctx, rc_simulate(ctx, scene, hs, poses, pose_count, &host.res));
        RCT_OK(ctx, rc_simulate(ctx, scene, ds, poses, pose_count, &dev));
    }
    RCT_OK(ctx, rc_context_get_device_results(ctx, &dr));
    for (a = 0; a < 7; ++a) words += (attributes >> a) & 1u ? (a == 2 || a == 3 ? 3u : 1u) : 0u;
    assert_true(dr.bytes == n * words * 4u);
    read_device_buffer(&dr, &rb);
    base = (const unsigned char *)rb.map;
    *moved = 0;
    *max_diff = 0.0;
    for (k = 0; k < n; ++k) {
        if (attributes & RC_ATTR_HITS) {
            uint32_t h;
            memcpy(&h, base + dr.offsets[0] + 4u * k, 4);
            if (h != host.res.hits[k]) fail_msg("element %llu: hit %u on the device, %u on the host",
                                                (unsigned long long)k, h, host.res.hits[k]);
        }
        if (attributes & RC_ATTR_RANGES) {
            float r;
            const float want = host.res.ranges[k];
            memcpy(&r, base + dr.offsets[1] + 4u * k, 4);
            if (isinf(want) || isinf(r)) {
                if (memcmp(&r, &want, 4) != 0)
                    fail_msg("element %llu: range %g on the device, %g on the host", (unsigned long long)k, (double)r,
                             (double)want);
            } else if (fabs((double)r - (double)want) > tol + 1e-6 * fabs((double)want)) {
                fail_msg("element %llu: range %.9g on the device, %.9g on the host", (unsigned long long)k, (double)r,
                         (double)want);
            }
            if (isfinite(want) && isfinite(r) && fabs((double)r - (double)want) > *max_diff)
                *max_diff = fabs((double)r - (double)want);
            if (isfinite(want) && want != ref.res.ranges[k]) {
                ++*moved;
                same += memcmp(&r, &want, 4) == 0;
            }
        }
        if (attributes & RC_ATTR_POINTS) {
            float p[3];
            uint32_t i;
            memcpy(p, base + dr.offsets[2] + 12u * k, 12);
            for (i = 0; i < 3; ++i) {
                const float want = host.res.points[3u * k + i];
                if (isnan(want) != isnan(p[i]) ||
                    (!isnan(want) && fabs((double)p[i] - (double)want) > tol + 1e-6 * (fabs((double)want) + 1.0)))
                    fail_msg("element %llu: point[%u] %.9g on the device, %.9g on the host", (unsigned long long)k, i,
                             (double)p[i], (double)want);
            }
            if (!(attributes & RC_ATTR_RANGES))
                *moved += !isnan(host.res.points[3u * k]) && host.res.points[3u * k] != ref.res.points[3u * k];
        }
    }
    readback_free(&rb);
    rct_buffers_free(&host);
    rct_buffers_free(&ref);
    rc_sensor_destroy(hs);
    rc_sensor_destroy(ds);
    rc_sensor_destroy(clean);
    return same;
}

static void test_device_noise_matches_host(void **state)
{
    rcu_mesh m;
    rc_pose poses[3];
    rc_noise_desc flat = rc_noise_desc_default(), grow = rc_noise_desc_default();
    int fp64_kernel;
    (void)state;
    NEED_VULKAN();
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 60, 30, &m), 0);
    poses[0] = rct_pose(5.0f, 0.0f, 0.0f);
    poses[1] = rct_pose_ypr(-6.0f, 3.0f, 0.5f, 0.7, 0.1, -0.2);
    poses[2] = rct_pose_ypr(0.0f, 8.0f, -2.0f, -2.0, -0.3, 0.05);
    flat.mean = 0.01f;
    flat.sigma = 0.03f;
    flat.dropout = 0.25f;
    flat.seed = 1234;
    grow.sigma = 0.002f;
    grow.sigma_exponent = 1.7f; /* pow on the device */
    grow.seed = 99;
    for (fp64_kernel = 1; fp64_kernel >= 0; --fp64_kernel) {
        /* the float-only kernel: GLSL's log and cos (cos within 2^-11 absolute) */
        const double tol = fp64_kernel ? 0.0 : 0.01 * 0.03;
        rc_context *ctx;
        rc_scene *scene;
        uint64_t moved = 0, n = 3u * 16u * 900u, same;
        double diff = 0.0;
        if (!fp64_kernel) setenv("RANGECAST_VULKAN_NO_FP64", "1", 1);
        ctx = rct_context(RC_BACKEND_VULKAN, 2, 0);
        if (!fp64_kernel) unsetenv("RANGECAST_VULKAN_NO_FP64");
        scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
        /* every attribute, the second call's draw */
        same = compare_noisy(ctx, scene, &flat, RC_ATTR_ALL, poses, 3, 2, tol, &moved, &diff);
        print_message("%s kernel, constant noise and dropout: %llu of %llu moved ranges bit-identical, "
                      "largest difference %.3g m (sigma %g m)\n",
                      fp64_kernel ? "float64" : "float-only", (unsigned long long)same, (unsigned long long)moved,
                      diff, (double)flat.sigma);
        assert_true(moved > n / 2u); /* the noise is there: 3/4 of the returns kept, all of them moved */
        if (fp64_kernel) assert_true(same == moved); /* the host's draws and arithmetic, to the bit */
        /* points only (the range comes from the point), noise growing with range */
        (void)compare_noisy(ctx, scene, &grow, RC_ATTR_POINTS | RC_ATTR_HITS, poses, 3, 1, tol, &moved, &diff);
        assert_true(moved > n / 2u);
        /* dropout alone, hits alone: the same returns lost */
        flat.sigma = flat.mean = 0.0f;
        (void)compare_noisy(ctx, scene, &flat, RC_ATTR_HITS, poses, 3, 1, 0.0, &moved, &diff);
        flat.sigma = 0.03f;
        flat.mean = 0.01f;
        rc_context_destroy(ctx);
    }
    rcu_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_device_results_match_host),
                                       cmocka_unit_test(test_device_noise_matches_host)};
    return cmocka_run_group_tests_name("vulkan device results", tests, NULL, NULL);
}
