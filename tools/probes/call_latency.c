/* Probe, not part of the build: how long one small rc_simulate call takes, the
 * call a robot makes thousands of times a second (one pose, few rays). A ring
 * of RAYS O1Dn rays (or a VLP-16 when RAYS is 0) at one pose inside the UV
 * sphere, called back to back for a second; prints microseconds a call
 * (docs/benchmarks.md, session 15). Uses the public API only.
 *
 *   gcc -O2 -std=c99 -Iinclude -Itools/common tools/probes/call_latency.c \
 *       build/librangecast.a build/tools/librcutil.a -lm -lpthread \
 *       [-lembree3] [-lvulkan] -o /tmp/call_latency
 *   /tmp/call_latency THREADS BACKEND RAYS [TRIANGLES]   (BACKEND: 1 bvh, 2 embree)
 */
#include "probe.h" /* first: it asks for POSIX */

#include <math.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_results res = rc_results_default();
    rc_pose pose = rc_pose_identity();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL;
    rc_sensor *sensor = NULL;
    rcu_mesh mesh;
    uint32_t rays, i;
    unsigned long long tris;
    float *ranges;
    double t0, t;
    long calls = 0;
    if (argc < 4) {
        fprintf(stderr, "usage: %s THREADS BACKEND RAYS [TRIANGLES]\n", argv[0]);
        return 2;
    }
    cd.thread_count = (uint32_t)atoi(argv[1]);
    cd.backend = (uint32_t)atoi(argv[2]);
    rays = (uint32_t)atoi(argv[3]);
    tris = argc > 4 ? strtoull(argv[4], NULL, 10) : 1000ull;
    if (rcu_mesh_uv_sphere_triangles(20.0f, tris, &mesh) != 0) return fail(NULL, "sphere");
    if (rc_context_create(&cd, &ctx) != RC_OK) return fail(NULL, "rc_context_create");
    sd.max_triangles = mesh.triangle_count;
    if (rc_scene_create(ctx, &sd, &scene) != RC_OK || probe_add_mesh(scene, &mesh, 0) != RC_OK ||
        rc_scene_commit(scene) != RC_OK)
        return fail(ctx, "scene");
    if (rays == 0) {
        if (rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor) != RC_OK) return fail(ctx, "sensor");
        rays = 16u * 900u;
    } else {
        rc_rays_desc rd = rc_rays_desc_default();
        float *dirs = (float *)malloc(sizeof(float) * 3u * rays);
        if (!dirs) return fail(NULL, "malloc");
        for (i = 0; i < rays; ++i) {
            const double a = 6.283185307179586 * i / rays;
            dirs[3 * i] = (float)cos(a);
            dirs[3 * i + 1] = (float)sin(a);
            dirs[3 * i + 2] = 0.1f;
        }
        rd.directions = dirs;
        rd.ray_count = rays;
        rd.common.range_min = 0.1f;
        rd.common.range_max = 100.0f;
        if (rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &sensor) != RC_OK) return fail(ctx, "sensor");
        free(dirs);
    }
    ranges = (float *)malloc(sizeof(float) * rays);
    if (!ranges) return fail(NULL, "malloc");
    res.attributes = RC_ATTR_RANGES;
    res.ranges = ranges;
    res.capacity = rays;
    t0 = now_s();
    do {
        for (i = 0; i < 100; ++i, ++calls) {
            pose.position[0] = (float)(calls % 100) * 0.01f;
            if (rc_simulate(ctx, scene, sensor, &pose, 1, &res) != RC_OK) return fail(ctx, "rc_simulate");
        }
        t = now_s() - t0;
    } while (t < 1.0);
    printf("threads %u backend %u rays %u triangles %u: %.1f us a call\n", cd.thread_count, cd.backend, rays,
           mesh.triangle_count, 1e6 * t / (double)calls);
    free(ranges);
    rc_context_destroy(ctx);
    rcu_mesh_free(&mesh);
    return 0;
}
