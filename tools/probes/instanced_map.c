/* Probe, not part of the build: VLP-16 scans a second in a dynamic map, the
 * UV sphere as the scene's own mesh with INSTANCES boxes instanced into it
 * (`rangecast bench` has no instances). Rays of a scene with instances go
 * one by one through the top-level tree; on maps larger than the cache the
 * built-in backend orders them (docs/benchmarks.md, session 20). Prints the
 * best of three timed calls of POSES poses and a checksum of the ranges, to
 * compare builds. Uses the public API only.
 *
 *   gcc -O2 -std=c99 -Iinclude -Itools/common tools/probes/instanced_map.c \
 *       build/librangecast.a build/tools/librcutil.a -lm -lpthread \
 *       [-lembree3] [-lvulkan] -o /tmp/instanced_map
 *   /tmp/instanced_map THREADS BACKEND TRIANGLES [POSES [INSTANCES [SPREAD]]]   (BACKEND: 1 bvh, 2 embree)
 * SPREAD 0 (default): poses along a line, turned alike; 1: random positions
 * within 6 m of the centre and random headings, as `rangecast bench` draws.
 */
#include "probe.h" /* first: it asks for POSIX */

#include <math.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_context *ctx = NULL;
    rc_scene *box = NULL, *world = NULL;
    rc_sensor *sensor = NULL;
    rcu_mesh sphere, cube;
    rc_pose *poses;
    float *ranges;
    uint32_t poses_n, insts, spread, i, id, rays = 16u * 1800u;
    double best, sum;
    if (argc < 4) {
        fprintf(stderr, "usage: %s THREADS BACKEND TRIANGLES [POSES [INSTANCES]]\n", argv[0]);
        return 2;
    }
    cd.thread_count = (uint32_t)atoi(argv[1]);
    cd.backend = (uint32_t)atoi(argv[2]);
    poses_n = argc > 4 ? (uint32_t)atoi(argv[4]) : 200u;
    insts = argc > 5 ? (uint32_t)atoi(argv[5]) : 10u;
    spread = argc > 6 ? (uint32_t)atoi(argv[6]) : 0u;
    cd.memory_size = (size_t)1536 << 20; /* a 10M map, and the calls' ordering scratch */
    if (rcu_mesh_uv_sphere_triangles(20.0f, strtoull(argv[3], NULL, 10), &sphere) != 0 ||
        rcu_mesh_box(lo, hi, &cube) != 0)
        return fail(NULL, "meshes");
    if (rc_context_create(&cd, &ctx) != RC_OK) return fail(NULL, "rc_context_create");
    sd.max_triangles = cube.triangle_count;
    if (rc_scene_create(ctx, &sd, &box) != RC_OK || probe_add_mesh(box, &cube, RC_MESH_REFERENCE) != RC_OK || rc_scene_commit(box) != RC_OK)
        return fail(ctx, "box scene");
    sd.max_triangles = sphere.triangle_count;
    sd.max_instances = insts;
    if (rc_scene_create(ctx, &sd, &world) != RC_OK || probe_add_mesh(world, &sphere, RC_MESH_REFERENCE) != RC_OK) return fail(ctx, "map");
    for (i = 0; i < insts; ++i) {
        rc_instance_desc in = rc_instance_desc_default();
        in.source = box;
        in.transform = rc_pose_identity();
        in.transform.position[0] = 3.0f + (float)i;
        in.transform.position[1] = (float)(i % 3u) - 1.0f;
        if (rc_scene_add_instance(world, &in, &id) != RC_OK) return fail(ctx, "instance");
    }
    if (rc_scene_commit(world) != RC_OK) return fail(ctx, "commit");
    if (rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor) != RC_OK) return fail(ctx, "sensor");
    poses = (rc_pose *)malloc(sizeof *poses * poses_n);
    ranges = (float *)malloc(sizeof *ranges * rays * (size_t)poses_n);
    if (!poses || !ranges) return fail(NULL, "memory");
    srand(1);
    for (i = 0; i < poses_n; ++i) {
        poses[i] = rc_pose_identity();
        if (spread) {
            const double yaw = 6.283185307179586 * rand() / RAND_MAX;
            poses[i].position[0] = (float)(12.0 * rand() / RAND_MAX - 6.0);
            poses[i].position[1] = (float)(12.0 * rand() / RAND_MAX - 6.0);
            poses[i].position[2] = (float)(4.0 * rand() / RAND_MAX - 2.0);
            poses[i].orientation[2] = (float)sin(yaw / 2.0); /* about z: (x, y, z, w) */
            poses[i].orientation[3] = (float)cos(yaw / 2.0);
        } else {
            poses[i].position[0] = -5.0f + 10.0f * (float)i / (float)poses_n;
            poses[i].position[1] = 2.0f * sinf((float)i);
        }
    }
    if (probe_time_ranges(ctx, world, sensor, poses, poses_n, rays, ranges, &best, &sum) != 0) return 1;
    printf("%u triangles, %u instances, %u threads: %.1f scans/s (best of 3), range checksum %.6f\n",
           sphere.triangle_count, insts, cd.thread_count, poses_n / best, sum);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&cube);
    free(poses);
    free(ranges);
    return 0;
}
