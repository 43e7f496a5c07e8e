/* The built-in backend: the scene's two-level BVH, traversed on the CPU by the
 * context's thread pool. Work is split into tasks of one pose, or of a slice of
 * a pose's rays when there are fewer poses than threads can keep busy; each ray
 * is computed on its own, so the split never changes a result. */
#include "backend/backend.h"

#include <string.h>

#define MIN_RAYS_PER_TASK 1024u

typedef struct sim_run {
    const rc__sim_job *job;
    uint32_t slices;           /* tasks per pose */
    uint32_t rays_per_slice;
} sim_run;

static void trace_task(void *user, uint32_t task, uint32_t thread)
{
    const sim_run *run = (const sim_run *)user;
    const rc__sim_job *job = run->job;
    const rc_sensor *sensor = job->sensor;
    const rc_scene *scene = job->scene;
    uint32_t pose = task / run->slices;
    uint32_t first = (task % run->slices) * run->rays_per_slice;
    uint32_t last = first + run->rays_per_slice;
    uint64_t base = (uint64_t)pose * sensor->rays;
    rc__xformf world;
    uint32_t r;
    (void)thread;
    if (last > sensor->rays) last = sensor->rays;
    rc__sensor_world_xform(sensor, &job->poses[pose], &world);
    for (r = first; r < last; ++r) {
        const float *ds = sensor->directions + (size_t)r * 3u;
        const float *os = sensor->origins ? sensor->origins + (size_t)r * 3u : NULL;
        float org[3], dir[3];
        rc__ray ray;
        rc__hit hit;
        int found;
        rc__rot_apply_f(world.r, ds, dir);
        if (os) {
            rc__rot_apply_f(world.r, os, org);
            org[0] += world.t[0];
            org[1] += world.t[1];
            org[2] += world.t[2];
        } else {
            org[0] = world.t[0];
            org[1] = world.t[1];
            org[2] = world.t[2];
        }
        rc__ray_prepare(&ray, org, dir);
        hit.t = sensor->range_max;
        hit.u = hit.v = 0.0f;
        hit.prim = hit.geom = hit.inst = RC_INVALID_ID;
        found = rc__scene_intersect(scene, &ray, &hit);
        rc__write_result(job, base + r, ds, os, found, &hit, NULL, &world);
    }
}

static rc_status bvh_simulate(rc_context *ctx, const rc__sim_job *job)
{
    sim_run run;
    uint32_t rays = job->sensor->rays;
    uint32_t threads = ctx->thread_count;
    run.job = job;
    run.slices = 1;
    /* Few poses: cut each scan into slices so every thread has work. */
    if (threads > 1 && job->pose_count < threads * 4u) {
        uint32_t want = (threads * 4u + job->pose_count - 1u) / job->pose_count;
        uint32_t max_slices = rays / MIN_RAYS_PER_TASK;
        run.slices = want < max_slices ? want : (max_slices ? max_slices : 1u);
    }
    run.rays_per_slice = (rays + run.slices - 1u) / run.slices;
    rc__pool_run(ctx->pool, job->pose_count * run.slices, trace_task, &run);
    return RC_OK;
}

static int bvh_available(void) { return 1; }
static size_t bvh_context_bytes(const rc_context_desc *desc)
{
    (void)desc;
    return 0;
}
static rc_status bvh_init(rc_context *ctx, const rc_context_desc *desc)
{
    (void)ctx;
    (void)desc;
    return RC_OK;
}
static void bvh_deinit(rc_context *ctx) { (void)ctx; }
static rc_status bvh_commit(rc_scene *scene, rc_progress_fn progress, void *user)
{
    return rc__scene_build_bvh(scene, progress, user);
}

const rc__backend rc__backend_bvh = {
    RC_BACKEND_BVH,   "bvh",      bvh_available, bvh_context_bytes, rc__scene_bvh_commit_bytes,
    bvh_init,         bvh_deinit, bvh_commit,    NULL,              bvh_simulate,
    NULL,
};
