/* Probe, not part of the build: a depth camera (RealSense D435 preset) in a
 * room of balls, the scene built as one merged mesh or as one geometry per
 * object (the room, then each ball). Scenes of several meshes take projected
 * scans too since session 40; before, they took the packets
 * (docs/benchmarks.md). Prints the best of three timed calls of POSES poses
 * and a checksum of the ranges (equal for both layouts: the same triangles).
 * Uses the public API only.
 *
 *   gcc -O2 -std=c99 -Iinclude -Itools/common tools/probes/camera_meshes.c \
 *       build/librangecast.a build/tools/librcutil.a -lm -lpthread \
 *       [-lembree3] [-lvulkan] -o /tmp/camera_meshes
 *   /tmp/camera_meshes THREADS LAYOUT [BALLS [POSES [SEGMENTS [PRESET [BACKEND]]]]]
 * LAYOUT 0: one merged mesh; 1: the room and each ball a geometry of its own;
 * 2: the room a mesh, each ball an instance of one unit ball scene (its
 * checksum differs in the last digits: the instances' rounding).
 * BALLS (default 24, at most 1024) UV balls of SEGMENTS (default 48) segments
 * and half as many rings, 0.3 to 0.7 m, on a 6 x 6 grid in a 12 x 12 x 3 m
 * room (more than 36 balls: a finer grid, the balls smaller in proportion);
 * poses 1.5 m up, random positions within 4 m of the centre and headings.
 * PRESET: the sensor, an RC_PRESET_* number (default 3, the D435; 1 the
 * VLP-16). BACKEND: an RC_BACKEND_* number (default 1, the built-in BVH;
 * 2 Embree).
 */
#include "probe.h" /* first: it asks for POSIX */

#include <math.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    const float lo[3] = {-6.0f, -6.0f, 0.0f}, hi[3] = {6.0f, 6.0f, 3.0f};
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL, *ball_scene = NULL;
    rc_sensor *sensor = NULL;
    rc_sensor_info info = rc_sensor_info_default();
    rcu_mesh room, *balls, merged;
    rc_pose *poses;
    float *ranges;
    uint32_t layout, nballs, poses_n, segments, preset, cols, rays, i, g;
    double best, sum;
    if (argc < 3) {
        fprintf(stderr, "usage: %s THREADS LAYOUT [BALLS [POSES [SEGMENTS [PRESET [BACKEND]]]]]\n", argv[0]);
        return 2;
    }
    cd.thread_count = (uint32_t)atoi(argv[1]);
    layout = (uint32_t)atoi(argv[2]);
    nballs = argc > 3 ? (uint32_t)atoi(argv[3]) : 24u;
    poses_n = argc > 4 ? (uint32_t)atoi(argv[4]) : 60u;
    segments = argc > 5 ? (uint32_t)atoi(argv[5]) : 48u;
    preset = argc > 6 ? (uint32_t)atoi(argv[6]) : RC_PRESET_REALSENSE_D435;
    cd.backend = argc > 7 ? (uint32_t)atoi(argv[7]) : RC_BACKEND_BVH;
    if (nballs > 1024u || segments < 3u) return fail(NULL, "at most 1024 balls, at least 3 segments");
    balls = (rcu_mesh *)calloc(nballs + 1u, sizeof *balls);
    if (!balls) return fail(NULL, "memory");
    for (cols = 6u; nballs > 36u && cols * cols < nballs;) ++cols;
    cd.memory_size = (size_t)512 << 20;
    if (rcu_mesh_box(lo, hi, &room) != 0 || rcu_mesh_box(lo, hi, &merged) != 0) return fail(NULL, "room");
    for (i = 0; i < nballs; ++i) {
        /* up to 36 balls on session 40's 6 x 6 grid; more on a finer one,
         * the balls smaller in proportion */
        const float step = 10.8f / (float)cols, scale = step / 1.8f;
        const float at[3] = {-5.4f + step * (0.5f + (float)(i % cols)), -5.4f + step * (0.5f + (float)(i / cols)),
                             0.5f + 0.4f * (float)(i % 4u)};
        if (rcu_mesh_uv_sphere(scale * (0.3f + 0.1f * (float)(i % 5u)), segments, segments / 2u, &balls[i]) != 0)
            return fail(NULL, "ball");
        rcu_mesh_transform(&balls[i], 0.0f, at);
        if (rcu_mesh_append(&merged, &balls[i]) != 0) return fail(NULL, "merge");
    }
    if (rc_context_create(&cd, &ctx) != RC_OK) return fail(NULL, "rc_context_create");
    sd.max_geometries = layout == 1u ? nballs + 1u : 1u;
    sd.max_triangles = layout == 2u ? room.triangle_count : merged.triangle_count;
    sd.max_instances = layout == 2u ? nballs : 0u;
    if (rc_scene_create(ctx, &sd, &scene) != RC_OK) return fail(ctx, "scene");
    if (layout == 2u) {
        /* the room, and each ball an instance of one unit ball (scaled and
         * placed as its mesh is in the other layouts, to within rounding) */
        rc_scene_desc bd = rc_scene_desc_default();
        rcu_mesh unit;
        if (rcu_mesh_uv_sphere(1.0f, segments, segments / 2u, &unit) != 0) return fail(NULL, "unit ball");
        bd.max_triangles = bd.max_copied_triangles = unit.triangle_count;
        bd.max_vertices = unit.vertex_count;
        if (rc_scene_create(ctx, &bd, &ball_scene) != RC_OK || probe_add_mesh(ball_scene, &unit, RC_MESH_COPY) != RC_OK ||
            rc_scene_commit(ball_scene) != RC_OK)
            return fail(ctx, "unit ball scene");
        rcu_mesh_free(&unit);
        if (probe_add_mesh(scene, &room, RC_MESH_REFERENCE) != RC_OK) return fail(ctx, "room mesh");
        for (g = 0; g < nballs; ++g) {
            rc_instance_desc id = rc_instance_desc_default();
            const float step = 10.8f / (float)cols, scale = step / 1.8f;
            const float r = scale * (0.3f + 0.1f * (float)(g % 5u));
            id.source = ball_scene;
            id.transform = rc_pose_identity();
            id.transform.position[0] = -5.4f + step * (0.5f + (float)(g % cols));
            id.transform.position[1] = -5.4f + step * (0.5f + (float)(g / cols));
            id.transform.position[2] = 0.5f + 0.4f * (float)(g % 4u);
            id.scale[0] = id.scale[1] = id.scale[2] = r;
            uint32_t inst_id;
            if (rc_scene_add_instance(scene, &id, &inst_id) != RC_OK) return fail(ctx, "instance");
        }
    } else if (layout) {
        if (probe_add_mesh(scene, &room, RC_MESH_REFERENCE) != RC_OK) return fail(ctx, "room mesh");
        for (g = 0; g < nballs; ++g)
            if (probe_add_mesh(scene, &balls[g], RC_MESH_REFERENCE) != RC_OK) return fail(ctx, "ball mesh");
    } else if (probe_add_mesh(scene, &merged, RC_MESH_REFERENCE) != RC_OK) {
        return fail(ctx, "merged mesh");
    }
    if (rc_scene_commit(scene) != RC_OK) return fail(ctx, "commit");
    if (rc_sensor_create_preset(ctx, preset, &sensor) != RC_OK || rc_sensor_get_info(sensor, &info) != RC_OK)
        return fail(ctx, "sensor");
    rays = info.rays_per_scan;
    poses = (rc_pose *)malloc(sizeof *poses * poses_n);
    ranges = (float *)malloc(sizeof *ranges * rays * (size_t)poses_n);
    if (!poses || !ranges) return fail(NULL, "memory");
    srand(1);
    for (i = 0; i < poses_n; ++i) {
        const double yaw = 6.283185307179586 * rand() / RAND_MAX;
        poses[i] = rc_pose_identity();
        poses[i].position[0] = (float)(8.0 * rand() / RAND_MAX - 4.0);
        poses[i].position[1] = (float)(8.0 * rand() / RAND_MAX - 4.0);
        poses[i].position[2] = 1.5f;
        poses[i].orientation[2] = (float)sin(yaw / 2.0); /* about z: (x, y, z, w) */
        poses[i].orientation[3] = (float)cos(yaw / 2.0);
    }
    if (probe_time_ranges(ctx, scene, sensor, poses, poses_n, rays, ranges, &best, &sum) != 0) return 1;
    printf("%u triangles in %u geometries, %u threads: %.1f scans/s (best of 3), range checksum %.6f\n",
           merged.triangle_count, layout == 1u ? nballs + 1u : layout == 2u ? nballs + 1u : 1u, cd.thread_count,
           poses_n / best, sum);
    rc_context_destroy(ctx);
    rcu_mesh_free(&room);
    rcu_mesh_free(&merged);
    for (i = 0; i < nballs; ++i) rcu_mesh_free(&balls[i]);
    free(balls);
    free(poses);
    free(ranges);
    return 0;
}
