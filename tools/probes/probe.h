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

#endif
