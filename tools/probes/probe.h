/* What the probes share (they are not part of the build: each is compiled by
 * hand, as its header says, with -Itools/common). */
#ifndef RC_PROBE_H
#define RC_PROBE_H

#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <time.h>

#include "meshgen.h"
#include "rangecast/rangecast.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* Prints what failed (with the context's last error when there is one); 1. */
static int fail(const rc_context *ctx, const char *what)
{
    fprintf(stderr, "%s: %s\n", what, ctx ? rc_context_last_error(ctx) : "failed");
    return 1;
}

/* Adds the generated mesh m to scene with the mesh flags given. */
static rc_status probe_add_mesh(rc_scene *scene, const rcu_mesh *m, uint32_t flags)
{
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t id;
    md.vertices = m->vertices;
    md.vertex_count = m->vertex_count;
    md.indices = m->indices;
    md.triangle_count = m->triangle_count;
    md.flags = flags;
    return rc_scene_add_mesh(scene, &md, &id);
}

/* The ranges of poses[0 .. n) simulated into ranges (rays a scan) four
 * times, the first to warm up; *best_s gets the best of the other three and
 * *checksum the sum of every 997th finite range. 0, or 1 with the error
 * printed. */
static inline int probe_time_ranges(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor, const rc_pose *poses,
                                    uint32_t n, uint32_t rays, float *ranges, double *best_s, double *checksum)
{
    rc_results res = rc_results_default();
    uint64_t i;
    int rep;
    res.attributes = RC_ATTR_RANGES;
    res.ranges = ranges;
    res.capacity = (uint64_t)rays * n;
    *best_s = 1e30;
    *checksum = 0.0;
    for (rep = 0; rep < 4; ++rep) {
        const double t0 = now_s();
        if (rc_simulate(ctx, scene, sensor, poses, n, &res) != RC_OK) return fail(ctx, "rc_simulate");
        if (rep && now_s() - t0 < *best_s) *best_s = now_s() - t0;
    }
    for (i = 0; i < res.capacity; i += 997u)
        if (ranges[i] == ranges[i] && ranges[i] - ranges[i] == 0.0f) *checksum += ranges[i];
    return 0;
}

#endif
