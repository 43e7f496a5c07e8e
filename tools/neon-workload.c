/* Fixed workload for tools/neon-icount.sh (instruction counts of the packet
 * box test: NEON / SSE2 vs scalar vs single rays). Not built by CMake.
 *
 * A UV sphere of radius 10 m, STACKS x SLICES quads: 2 * SLICES * STACKS
 * triangles less the 2 * SLICES degenerate ones at the poles = 9,800; one
 * VLP-16 (16 x 900 rays) at two poses inside it; one thread.
 * With the argument 0 it stops before rc_simulate (the baseline).
 * Prints a checksum of the ranges so the builds can be checked to agree. */
#include <rangecast/rangecast.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define STACKS 50u
#define SLICES 100u
#define RADIUS 10.0f
#define POSES 2u

static float verts[3 * (SLICES * (STACKS + 1u))];
static uint32_t tris[3 * 2 * SLICES * STACKS];
static float ranges[POSES * 16u * 900u];

int main(int argc, char **argv)
{
    /* "neon-workload 0": everything but rc_simulate (the baseline subtracted
     * to get the simulate-only count) */
    const int simulate = !(argc > 1 && argv[1][0] == '0');
    const double pi = 3.14159265358979323846;
    uint32_t i, j, nv = 0, nt = 0;
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL;
    rc_sensor *lidar = NULL;
    rc_results res = rc_results_default();
    rc_pose poses[POSES] = {{{0.0f, 0.0f, 1.0f}, {0, 0, 0, 1}},
                            {{1.5f, -0.7f, 0.3f}, {0, 0, 0.0998334f, 0.9950042f}}};
    uint32_t geom = 0, hits = 0;
    double sum = 0.0;

    for (i = 0; i <= STACKS; ++i) {
        const double phi = pi * (double)i / STACKS; /* 0 at the top pole */
        for (j = 0; j < SLICES; ++j) {
            const double th = 2.0 * pi * (double)j / SLICES;
            verts[nv++] = (float)(RADIUS * sin(phi) * cos(th));
            verts[nv++] = (float)(RADIUS * sin(phi) * sin(th));
            verts[nv++] = (float)(RADIUS * cos(phi));
        }
    }
    for (i = 0; i < STACKS; ++i) {
        for (j = 0; j < SLICES; ++j) {
            const uint32_t a = i * SLICES + j, b = i * SLICES + (j + 1u) % SLICES;
            const uint32_t c = a + SLICES, d = b + SLICES;
            if (i != 0u) { /* the top row's first triangle is degenerate */
                tris[nt++] = a; tris[nt++] = c; tris[nt++] = b;
            }
            if (i != STACKS - 1u) { /* so is the bottom row's second */
                tris[nt++] = b; tris[nt++] = c; tris[nt++] = d;
            }
        }
    }

    cd.backend = RC_BACKEND_BVH;
    cd.thread_count = 1;
    cd.memory_size = (size_t)16 << 20;
    if (rc_context_create(&cd, &ctx) != RC_OK) { fprintf(stderr, "context\n"); return 1; }
    sd.max_geometries = 1;
    sd.max_triangles = nt / 3u;
    if (rc_scene_create(ctx, &sd, &scene) != RC_OK) goto fail;
    md.vertices = verts; md.vertex_count = nv / 3u;
    md.indices = tris; md.triangle_count = nt / 3u;
    if (rc_scene_add_mesh(scene, &md, &geom) != RC_OK) goto fail;
    if (rc_scene_commit(scene) != RC_OK) goto fail;
    if (rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &lidar) != RC_OK) goto fail;
    res.attributes = RC_ATTR_RANGES;
    res.ranges = ranges;
    res.capacity = POSES * 16u * 900u;
    if (!simulate) {
        printf("triangles %u (no simulate)\n", nt / 3u);
        rc_context_destroy(ctx);
        return 0;
    }
    if (rc_simulate(ctx, scene, lidar, poses, POSES, &res) != RC_OK) goto fail;
    for (i = 0; i < POSES * 16u * 900u; ++i) {
        if (isfinite(ranges[i])) { sum += ranges[i]; ++hits; }
    }
    printf("triangles %u rays %u hits %u sum %.6f\n", nt / 3u, POSES * 16u * 900u, hits, sum);
    rc_context_destroy(ctx);
    return 0;
fail:
    fprintf(stderr, "%s\n", rc_context_last_error(ctx));
    rc_context_destroy(ctx);
    return 1;
}
