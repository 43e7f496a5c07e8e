/* rc_simulate: every argument is checked before anything is written. */
#include "backend/backend.h"

#include <string.h>

rc_results rc_results_default(void)
{
    rc_results r;
    memset(&r, 0, sizeof r);
    r.struct_size = (uint32_t)sizeof r;
    return r;
}

static rc_status check_buffer(rc_context *ctx, uint32_t attributes, uint32_t bit, const void *buffer, const char *name)
{
    RC_RETURN_IF(ctx, (attributes & bit) && buffer == NULL, RC_ERR_INVALID_ARGUMENT,
                 "results->%s is NULL but its attribute is requested", name);
    return RC_OK;
}

/* 1 when pose i puts the sensor (mounting included) within RC__MAX_COORD of
 * the scene's origin on every axis. */
static int sensor_in_reach(const rc_scene *scene, const rc_sensor *sensor, const rc_pose *poses,
                           const rc_pose_d *poses_d, uint32_t i, double *far)
{
    rc__xform base, world;
    uint32_t k;
    if (poses_d) {
        rc__xform_from_pose_d(&poses_d[i], &base);
    } else {
        rc__xform_from_pose(&poses[i], &base);
    }
    rc__xform_mul(&base, &sensor->mount_xform, &world);
    *far = 0.0;
    for (k = 0; k < 3; ++k) {
        const double d = fabs(world.t[k] - scene->desc.origin[k]);
        if (!(d <= *far)) *far = d; /* NaN stays: it is not in reach */
    }
    return *far <= RC__MAX_COORD;
}

static rc_status simulate(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor, const rc_pose *poses,
                         const rc_pose_d *poses_d, uint32_t pose_count, const rc_results *results)
{
    rc__sim_job job;
    uint64_t need;
    uint32_t i, a;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, !rc__scene_valid(scene), RC_ERR_INVALID_HANDLE, "scene is not a valid scene handle");
    RC_RETURN_IF(ctx, !rc__sensor_valid(sensor), RC_ERR_INVALID_HANDLE, "sensor is not a valid sensor handle");
    RC_RETURN_IF(ctx, scene->ctx != ctx, RC_ERR_INVALID_ARGUMENT, "scene belongs to another context");
    RC_RETURN_IF(ctx, sensor->ctx != ctx, RC_ERR_INVALID_ARGUMENT, "sensor belongs to another context");
    RC_RETURN_IF(ctx, !rc__scene_up_to_date(scene), RC_ERR_NOT_COMMITTED,
                 "scene is not committed (or it, or a scene it instances, changed since): call rc_scene_commit");
    RC_RETURN_IF(ctx, poses == NULL && poses_d == NULL, RC_ERR_INVALID_ARGUMENT, "poses is NULL");
    RC_RETURN_IF(ctx, pose_count == 0, RC_ERR_INVALID_ARGUMENT, "pose_count is 0");
    RC_TRY(rc__check_desc(ctx, results, (uint32_t)sizeof *results, (uint32_t)sizeof *results, "results"));
    RC_TRY(rc__check_reserved(ctx, results->reserved, 7, "results"));
    RC_RETURN_IF(ctx, (results->flags & ~RC_RESULTS_ON_DEVICE) != 0, RC_ERR_INVALID_ARGUMENT,
                 "results->flags has unknown bits 0x%x", (unsigned)(results->flags & ~RC_RESULTS_ON_DEVICE));
    RC_RETURN_IF(ctx, (results->flags & RC_RESULTS_ON_DEVICE) && ctx->backend->device_results == NULL,
                 RC_ERR_UNSUPPORTED,
                 "results->flags has RC_RESULTS_ON_DEVICE, but the context's backend (%s) has no device: "
                 "results can only go to host buffers",
                 ctx->backend->name);
    a = results->attributes;
    RC_RETURN_IF(ctx, a == 0, RC_ERR_INVALID_ARGUMENT, "results->attributes is 0: request at least one RC_ATTR_*");
    RC_RETURN_IF(ctx, (a & ~RC_ATTR_ALL) != 0, RC_ERR_INVALID_ARGUMENT,
                 "results->attributes has unknown bits 0x%x", (unsigned)(a & ~RC_ATTR_ALL));
    if (results->flags & RC_RESULTS_ON_DEVICE) goto poses_check; /* no host buffers */
    RC_TRY(check_buffer(ctx, a, RC_ATTR_HITS, results->hits, "hits"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_RANGES, results->ranges, "ranges"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_POINTS, results->points, "points"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_NORMALS, results->normals, "normals"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_PRIM_IDS, results->prim_ids, "prim_ids"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_GEOM_IDS, results->geom_ids, "geom_ids"));
    RC_TRY(check_buffer(ctx, a, RC_ATTR_INST_IDS, results->inst_ids, "inst_ids"));
    need = (uint64_t)pose_count * sensor->rays;
    RC_RETURN_IF(ctx, results->capacity < need, RC_ERR_CAPACITY,
                 "results->capacity is %llu; %u poses x %u rays need %llu", (unsigned long long)results->capacity,
                 (unsigned)pose_count, (unsigned)sensor->rays, (unsigned long long)need);
poses_check:
    for (i = 0; i < pose_count; ++i) {
        rc_status st = poses ? rc__pose_check(&poses[i]) : rc__pose_check_d(&poses_d[i]);
        double far;
        RC_RETURN_IF(ctx, st == RC_ERR_NON_FINITE, st, "poses[%u] has a NaN or infinite value", (unsigned)i);
        RC_RETURN_IF(ctx, st != RC_OK, st,
                     "poses[%u].orientation is not a unit quaternion (|q| = 1 within 1e-3 is normalised; "
                     "farther off is rejected)",
                     (unsigned)i);
        RC_RETURN_IF(ctx, !sensor_in_reach(scene, sensor, poses, poses_d, i, &far), RC_ERR_INVALID_ARGUMENT,
                     "poses[%u] puts the sensor %g m from the scene's origin (mounting included); rays start "
                     "at most %g m from it",
                     (unsigned)i, far, RC__MAX_COORD);
    }
    job.scene = scene;
    job.sensor = sensor;
    job.poses = poses;
    job.poses_d = poses_d;
    job.pose_count = pose_count;
    job.attributes = a;
    job.out = results;
    job.flags = results->flags;
    job.noise = NULL;
    job.noise_key = 0;
    if (sensor->noise.enabled && (results->flags & RC_RESULTS_ON_DEVICE)) {
        /* no host buffers to pass over: the backend applies it on the device */
        job.noise = &sensor->noise;
        job.noise_key = rc__noise_key(sensor->noise.seed, sensor->noise.draws);
    }
    RC_TRY(ctx->backend->simulate(ctx, &job));
    if (job.noise) {
        ((rc_sensor *)sensor)->noise.draws++;
    } else if (sensor->noise.enabled) {
        rc__noise_job nj;
        nj.out = results;
        nj.attributes = a;
        nj.pose_count = pose_count;
        nj.rays = sensor->rays;
        nj.origins = sensor->origins;
        nj.range_min = sensor->range_min;
        nj.range_max = sensor->range_max;
        rc__noise_apply(ctx->pool, &sensor->noise, &nj);
        /* the next call draws fresh noise (the sensor is the context's, and
         * a context is used by one thread at a time) */
        ((rc_sensor *)sensor)->noise.draws++;
    }
    return RC_OK;
}

rc_status rc_simulate(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor, const rc_pose *poses,
                      uint32_t pose_count, const rc_results *results)
{
    if (!poses && rc__context_valid(ctx)) {
        rc__clear_error(ctx);
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "poses is NULL");
    }
    return simulate(ctx, scene, sensor, poses, NULL, pose_count, results);
}

rc_status rc_simulate_d(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor, const rc_pose_d *poses,
                        uint32_t pose_count, const rc_results *results)
{
    if (!poses && rc__context_valid(ctx)) {
        rc__clear_error(ctx);
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "poses is NULL");
    }
    return simulate(ctx, scene, sensor, NULL, poses, pose_count, results);
}

rc_device_results rc_device_results_default(void)
{
    rc_device_results r;
    memset(&r, 0, sizeof r);
    r.struct_size = (uint32_t)sizeof r;
    return r;
}

rc_status rc_context_get_device_results(rc_context *ctx, rc_device_results *out)
{
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    RC_RETURN_IF(ctx, out == NULL, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(rc__check_desc(ctx, out, (uint32_t)sizeof *out, (uint32_t)sizeof *out, "out"));
    RC_RETURN_IF(ctx, ctx->backend->device_results == NULL, RC_ERR_UNSUPPORTED,
                 "the context's backend (%s) has no device: its results are in host buffers", ctx->backend->name);
    return ctx->backend->device_results(ctx, out);
}
