/* Validation of the sensor descriptors. Every failure names the field and its
 * value. ctx may be NULL (the size queries, which have no context): then only
 * the status comes back. Nothing here writes anything but the error text. */
#include "sensor/sensor.h"

#include <math.h>

/* The first released size of each descriptor (version 0.1). A later version
 * that appends fields keeps accepting these. */
#define SPHERICAL_MIN_SIZE   ((uint32_t)sizeof(rc_spherical_desc))
#define PINHOLE_MIN_SIZE     ((uint32_t)sizeof(rc_pinhole_desc))
#define CYLINDRICAL_MIN_SIZE ((uint32_t)sizeof(rc_cylindrical_desc))
#define RAYS_MIN_SIZE        ((uint32_t)sizeof(rc_rays_desc))

static rc_status check_finite(rc_context *ctx, float v, const char *name)
{
    if (!isfinite(v)) return rc__fail(ctx, RC_ERR_NON_FINITE, "%s is %g: must be finite", name, (double)v);
    return RC_OK;
}

static rc_status check_positive(rc_context *ctx, float v, const char *name)
{
    RC_TRY(check_finite(ctx, v, name));
    if (!(v > 0.0f)) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "%s is %g: must be > 0", name, (double)v);
    return RC_OK;
}

static rc_status check_count(rc_context *ctx, uint32_t v, const char *name)
{
    if (v == 0) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "%s is 0: must be at least 1", name);
    return RC_OK;
}

/* min and increment finite, count > 0. An increment of 0 would stack every ray
 * of the axis on one direction; it is allowed only for a one-value axis (a
 * single-row scanner, phi.count = 1), where it is never used. */
static rc_status check_axis(rc_context *ctx, const rc_angle_axis *axis, const char *min_name,
                            const char *inc_name, const char *count_name)
{
    RC_TRY(check_finite(ctx, axis->min, min_name));
    RC_TRY(check_finite(ctx, axis->increment, inc_name));
    RC_TRY(check_count(ctx, axis->count, count_name));
    if (axis->increment == 0.0f && axis->count > 1)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "%s is 0 with %s = %u: every ray would point the same way",
                        inc_name, count_name, axis->count);
    return RC_OK;
}

/* rows x columns must fit the 32-bit rays_per_scan and the direction tables
 * must fit the address space (a 32-bit target overflows far earlier). */
static rc_status check_ray_count(rc_context *ctx, uint32_t model, uint64_t rows, uint64_t columns)
{
    const uint64_t rays = rows * columns; /* both < 2^32: no overflow */
    if (rays > UINT32_MAX)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc: %llu x %llu = %llu rays, more than the 4294967295 a scan can hold",
                        (unsigned long long)rows, (unsigned long long)columns, (unsigned long long)rays);
    if (rc__sensor_bytes(model, 1u, rays) == 0) /* the largest layout: with a trace order */
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc: %llu rays: the direction table (%llu bytes) does not fit this platform's size_t",
                        (unsigned long long)rays, (unsigned long long)(rays * 12u));
    return RC_OK;
}

rc_status rc__sensor_check_common(rc_context *ctx, const rc_sensor_common *common)
{
    const rc_pose *p = &common->sensor_to_base;
    rc_status st;
    RC_TRY(check_finite(ctx, common->range_min, "desc.common.range_min"));
    RC_TRY(check_finite(ctx, common->range_max, "desc.common.range_max"));
    if (common->range_min < 0.0f)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "desc.common.range_min is %g: must be >= 0",
                        (double)common->range_min);
    if (!(common->range_max > common->range_min))
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc.common.range_max is %g: must be > desc.common.range_min (%g)",
                        (double)common->range_max, (double)common->range_min);
    st = rc__pose_check(p);
    if (st == RC_ERR_NON_FINITE)
        return rc__fail(ctx, st,
                        "desc.common.sensor_to_base is not finite: position (%g, %g, %g), orientation (%g, %g, %g, %g)",
                        (double)p->position[0], (double)p->position[1], (double)p->position[2],
                        (double)p->orientation[0], (double)p->orientation[1], (double)p->orientation[2],
                        (double)p->orientation[3]);
    if (st != RC_OK)
        return rc__fail(ctx, st,
                        "desc.common.sensor_to_base.orientation (%g, %g, %g, %g) is not a unit quaternion "
                        "(norm must be within 1e-3 of 1; identity is 0, 0, 0, 1)",
                        (double)p->orientation[0], (double)p->orientation[1], (double)p->orientation[2],
                        (double)p->orientation[3]);
    return RC_OK;
}

rc_status rc__sensor_check_spherical(rc_context *ctx, const rc_spherical_desc *desc)
{
    RC_TRY(rc__check_desc(ctx, desc, SPHERICAL_MIN_SIZE, (uint32_t)sizeof(*desc), "desc"));
    RC_TRY(rc__check_reserved(ctx, &desc->reserved0, 1, "desc.reserved0"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof(desc->reserved) / sizeof(desc->reserved[0]),
                              "desc.reserved"));
    RC_TRY(rc__sensor_check_common(ctx, &desc->common));
    RC_TRY(check_axis(ctx, &desc->theta, "desc.theta.min", "desc.theta.increment", "desc.theta.count"));
    RC_TRY(check_axis(ctx, &desc->phi, "desc.phi.min", "desc.phi.increment", "desc.phi.count"));
    return check_ray_count(ctx, RC_SENSOR_SPHERICAL, desc->phi.count, desc->theta.count);
}

rc_status rc__sensor_check_pinhole(rc_context *ctx, const rc_pinhole_desc *desc)
{
    RC_TRY(rc__check_desc(ctx, desc, PINHOLE_MIN_SIZE, (uint32_t)sizeof(*desc), "desc"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof(desc->reserved) / sizeof(desc->reserved[0]),
                              "desc.reserved"));
    if (desc->frame != RC_PINHOLE_FRAME_BODY && desc->frame != RC_PINHOLE_FRAME_OPTICAL)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc.frame is %u: must be RC_PINHOLE_FRAME_BODY (0) or RC_PINHOLE_FRAME_OPTICAL (1)",
                        desc->frame);
    RC_TRY(rc__sensor_check_common(ctx, &desc->common));
    RC_TRY(check_count(ctx, desc->width, "desc.width"));
    RC_TRY(check_count(ctx, desc->height, "desc.height"));
    RC_TRY(check_positive(ctx, desc->fx, "desc.fx"));
    RC_TRY(check_positive(ctx, desc->fy, "desc.fy"));
    RC_TRY(check_finite(ctx, desc->cx, "desc.cx"));
    RC_TRY(check_finite(ctx, desc->cy, "desc.cy"));
    return check_ray_count(ctx, RC_SENSOR_PINHOLE, desc->height, desc->width);
}

rc_status rc__sensor_check_cylindrical(rc_context *ctx, const rc_cylindrical_desc *desc)
{
    RC_TRY(rc__check_desc(ctx, desc, CYLINDRICAL_MIN_SIZE, (uint32_t)sizeof(*desc), "desc"));
    RC_TRY(rc__check_reserved(ctx, &desc->reserved0, 1, "desc.reserved0"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof(desc->reserved) / sizeof(desc->reserved[0]),
                              "desc.reserved"));
    RC_TRY(rc__sensor_check_common(ctx, &desc->common));
    RC_TRY(check_axis(ctx, &desc->theta, "desc.theta.min", "desc.theta.increment", "desc.theta.count"));
    RC_TRY(check_count(ctx, desc->height, "desc.height"));
    RC_TRY(check_positive(ctx, desc->fy, "desc.fy"));
    RC_TRY(check_finite(ctx, desc->cy, "desc.cy"));
    return check_ray_count(ctx, RC_SENSOR_CYLINDRICAL, desc->height, desc->theta.count);
}

rc_status rc__sensor_check_rays(rc_context *ctx, uint32_t model, const rc_rays_desc *desc)
{
    uint32_t i;
    if (model != RC_SENSOR_O1DN && model != RC_SENSOR_ONDN)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "model is %u: must be RC_SENSOR_O1DN (%u) or RC_SENSOR_ONDN (%u)", model,
                        (unsigned)RC_SENSOR_O1DN, (unsigned)RC_SENSOR_ONDN);
    RC_TRY(rc__check_desc(ctx, desc, RAYS_MIN_SIZE, (uint32_t)sizeof(*desc), "desc"));
    RC_TRY(rc__check_reserved(ctx, &desc->reserved0, 1, "desc.reserved0"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof(desc->reserved) / sizeof(desc->reserved[0]),
                              "desc.reserved"));
    RC_TRY(rc__sensor_check_common(ctx, &desc->common));
    RC_TRY(check_count(ctx, desc->ray_count, "desc.ray_count"));
    if ((desc->width != 0 || desc->height != 0) &&
        (uint64_t)desc->width * desc->height != desc->ray_count)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc.width x desc.height is %u x %u: must equal desc.ray_count (%u), or both be 0",
                        desc->width, desc->height, desc->ray_count);
    if (!desc->directions) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "desc.directions is NULL");
    if (model == RC_SENSOR_ONDN && !desc->origins)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "desc.origins is NULL: RC_SENSOR_ONDN needs an origin per ray");
    /* Rejected rather than ignored: a caller passing origins to O1Dn expects them used. */
    if (model == RC_SENSOR_O1DN && desc->origins)
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "desc.origins is set for RC_SENSOR_O1DN (one origin): use RC_SENSOR_ONDN or pass NULL");
    RC_TRY(check_ray_count(ctx, model, 1, desc->ray_count));
    for (i = 0; i < desc->ray_count; ++i) {
        const float *d = desc->directions + (size_t)i * 3u;
        double n2;
        if (!rc__all_finite(d, 3))
            return rc__fail(ctx, RC_ERR_NON_FINITE, "desc.directions[%u] is (%g, %g, %g): must be finite", i,
                            (double)d[0], (double)d[1], (double)d[2]);
        n2 = (double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2];
        if (n2 == 0.0)
            return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "desc.directions[%u] is (%g, %g, %g): zero length",
                            i, (double)d[0], (double)d[1], (double)d[2]);
        if (desc->origins) {
            const float *o = desc->origins + (size_t)i * 3u;
            if (!rc__all_finite(o, 3))
                return rc__fail(ctx, RC_ERR_NON_FINITE, "desc.origins[%u] is (%g, %g, %g): must be finite", i,
                                (double)o[0], (double)o[1], (double)o[2]);
            if (!rc__in_reach3(o))
                return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                                "desc.origins[%u] is (%g, %g, %g): farther than %g m from the sensor", i,
                                (double)o[0], (double)o[1], (double)o[2], RC__MAX_COORD);
        }
    }
    return RC_OK;
}
