/* Probe, not part of the build: create, use and destroy Vulkan contexts in a
 * loop, as a test suite does, and report the first failure with the library's
 * log text, and the threads and file descriptors the process holds every ten
 * rounds.
 *
 * On an H100 with NVIDIA's driver 580 (docs/benchmarks.md, session 18) the
 * 22nd to 30th context fails: VK_LOADER_DEBUG=error shows
 * "libnvidia-tls.so.580.159.04: cannot allocate memory in static TLS block".
 * The loader dlopens the driver at every vkCreateInstance and dlcloses it at
 * vkDestroyInstance, and glibc does not give back the static TLS that the
 * driver's initial-exec TLS takes. Keeping one context (or any VkInstance)
 * alive for the life of the process keeps the driver loaded and avoids it.
 * Pinning the driver with dlopen(RTLD_NODELETE) was tried and aborted the
 * next vkDestroyDevice ("free(): invalid pointer"), with or without our
 * allocation callbacks.
 *
 *   gcc -O2 -std=c99 -Iinclude -Itools/common tools/probes/vk_contexts.c \
 *       build/librangecast.a build/tools/librcutil.a -lm -lpthread -lvulkan -o /tmp/vk_contexts
 *   /tmp/vk_contexts ROUNDS [anchor]   (anchor: one more context kept meanwhile)
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshgen.h"
#include "rangecast/rangecast.h"

static void log_line(void *user, uint32_t level, const char *message)
{
    (void)user;
    if (level <= RC_LOG_WARN) fprintf(stderr, "  log %u: %s\n", (unsigned)level, message);
}

static int count_entries(const char *path)
{
    DIR *d = opendir(path);
    struct dirent *e;
    int n = 0;
    if (!d) return -1;
    while ((e = readdir(d)) != NULL)
        if (e->d_name[0] != '.') n++;
    closedir(d);
    return n;
}

int main(int argc, char **argv)
{
    const float lo[3] = {0, 0, 0}, hi[3] = {4, 3, 2};
    int rounds = argc > 1 ? atoi(argv[1]) : 200, i;
    rcu_mesh box;
    float ranges[16 * 900];
    rc_context *anchor = NULL;
    if (rcu_mesh_box(lo, hi, &box) != 0) return 1;
    if (argc > 2 && strcmp(argv[2], "anchor") == 0) {
        rc_context_desc ad = rc_context_desc_default();
        ad.backend = RC_BACKEND_VULKAN;
        ad.memory_size = (size_t)1 << 20;
        if (rc_context_create(&ad, &anchor) != RC_OK) return 1;
    }
    for (i = 0; i < rounds; i++) {
        rc_context_desc cd = rc_context_desc_default();
        rc_scene_desc sd = rc_scene_desc_default();
        rc_mesh_desc md = rc_mesh_desc_default();
        rc_results res = rc_results_default();
        rc_pose pose = rc_pose_identity();
        rc_context *ctx = NULL;
        rc_scene *scene = NULL;
        rc_sensor *lidar = NULL;
        uint32_t g;
        rc_status st;
        cd.backend = RC_BACKEND_VULKAN;
        cd.thread_count = 1;
        cd.memory_size = (size_t)64 << 20;
        cd.log = log_line;
        if ((st = rc_context_create(&cd, &ctx)) != RC_OK) {
            printf("round %d: rc_context_create: %s\n", i, rc_status_string(st));
            return 1;
        }
        sd.max_triangles = box.triangle_count;
        md.vertices = box.vertices;
        md.vertex_count = box.vertex_count;
        md.indices = box.indices;
        md.triangle_count = box.triangle_count;
        pose.position[0] = 2.0f;
        pose.position[1] = 1.5f;
        pose.position[2] = 1.0f;
        res.attributes = RC_ATTR_RANGES;
        res.ranges = ranges;
        res.capacity = 16 * 900;
        if (rc_scene_create(ctx, &sd, &scene) != RC_OK || rc_scene_add_mesh(scene, &md, &g) != RC_OK ||
            rc_scene_commit(scene) != RC_OK || rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &lidar) != RC_OK ||
            rc_simulate(ctx, scene, lidar, &pose, 1, &res) != RC_OK) {
            printf("round %d: %s\n", i, rc_context_last_error(ctx));
            rc_context_destroy(ctx);
            return 1;
        }
        rc_context_destroy(ctx);
        if (i % 10 == 0)
            printf("round %d: ok, %d threads, %d fds\n", i, count_entries("/proc/self/task"),
                   count_entries("/proc/self/fd"));
    }
    printf("%d rounds ok%s\n", rounds, anchor ? " (with an anchor context)" : "");
    rc_context_destroy(anchor);
    rcu_mesh_free(&box);
    return 0;
}
