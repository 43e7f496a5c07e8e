/* Public sensor functions: descriptor defaults, size queries, create/destroy,
 * info, mounting. A sensor is one arena allocation: the struct, then the
 * direction table, then (OnDn) the origin table, then (O1Dn, OnDn given as
 * one flat row) the trace order, each at a 16-aligned offset, so rc__sensor_bytes is exactly the
 * arena cost of that one block. */
#include "sensor/sensor.h"

#include <math.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Layout                                                                    */
/* ------------------------------------------------------------------------ */

typedef struct sensor_layout {
    size_t directions; /* offset of the direction table */
    size_t origins;    /* offset of the origin table (OnDn), else 0 */
    size_t order;      /* offset of the trace order (flat O1Dn, OnDn), else 0 */
    size_t total;      /* bytes of the one allocation */
} sensor_layout;

static uint64_t align16(uint64_t n) { return (n + 15u) & ~(uint64_t)15u; }

/* 0 when the sensor cannot be laid out in this platform's size_t. */
static int sensor_layout_of(uint32_t model, uint32_t rows, uint64_t rays, sensor_layout *out)
{
    const uint64_t table = align16(rays * 12u); /* 3 floats a ray */
    uint64_t total = align16(sizeof(struct rc_sensor));
    uint64_t origins = 0, order = 0;
    const uint64_t dirs = total;
    if (rays > UINT32_MAX) return 0;
    total += table;
    if (model == RC_SENSOR_ONDN) {
        origins = total;
        total += table;
    }
    /* rays given in rows keep their scan order (sensor_link) */
    if ((model == RC_SENSOR_O1DN || model == RC_SENSOR_ONDN) && rows <= 1u) {
        order = total;
        total += align16(rays * 8u);
    }
    /* leave room for the arena's header and rounding */
    if (total > (uint64_t)((size_t)-1) - 4u * RC__ARENA_ALIGN) return 0;
    out->directions = (size_t)dirs;
    out->origins = (size_t)origins;
    out->order = (size_t)order;
    out->total = (size_t)total;
    return 1;
}

size_t rc__sensor_bytes(uint32_t model, uint32_t rows, uint64_t rays)
{
    sensor_layout l;
    if (!sensor_layout_of(model, rows, rays, &l)) return 0;
    return rc__arena_cost(l.total);
}

int rc__sensor_valid(const rc_sensor *sensor)
{
    return sensor != NULL && sensor->magic == RC__MAGIC_SENSOR && rc__context_valid(sensor->ctx);
}

/* ------------------------------------------------------------------------ */
/* Defaults                                                                  */
/* ------------------------------------------------------------------------ */

/* Zero everywhere except struct_size and the mounting, which is the identity
 * (a zero quaternion is not a rotation). Ranges and counts have no sensible
 * default: the caller sets them, or takes a preset. */
static rc_sensor_common common_default(void)
{
    rc_sensor_common c;
    memset(&c, 0, sizeof c);
    c.sensor_to_base = rc_pose_identity();
    return c;
}

rc_spherical_desc rc_spherical_desc_default(void)
{
    rc_spherical_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.common = common_default();
    return d;
}

rc_pinhole_desc rc_pinhole_desc_default(void)
{
    rc_pinhole_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.frame = RC_PINHOLE_FRAME_BODY;
    d.common = common_default();
    return d;
}

rc_cylindrical_desc rc_cylindrical_desc_default(void)
{
    rc_cylindrical_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.common = common_default();
    return d;
}

rc_rays_desc rc_rays_desc_default(void)
{
    rc_rays_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.common = common_default();
    return d;
}

rc_sensor_info rc_sensor_info_default(void)
{
    rc_sensor_info i;
    memset(&i, 0, sizeof i);
    i.struct_size = (uint32_t)sizeof i;
    return i;
}

/* ------------------------------------------------------------------------ */
/* Size queries (no context: statuses only)                                   */
/* ------------------------------------------------------------------------ */

rc_status rc_sensor_memory_requirements_spherical(const rc_spherical_desc *desc, size_t *bytes)
{
    if (!bytes) return RC_ERR_INVALID_ARGUMENT;
    RC_TRY(rc__sensor_check_spherical(NULL, desc));
    *bytes = rc__sensor_bytes(RC_SENSOR_SPHERICAL, desc->phi.count, (uint64_t)desc->phi.count * desc->theta.count);
    return RC_OK;
}

rc_status rc_sensor_memory_requirements_pinhole(const rc_pinhole_desc *desc, size_t *bytes)
{
    if (!bytes) return RC_ERR_INVALID_ARGUMENT;
    RC_TRY(rc__sensor_check_pinhole(NULL, desc));
    *bytes = rc__sensor_bytes(RC_SENSOR_PINHOLE, desc->height, (uint64_t)desc->width * desc->height);
    return RC_OK;
}

rc_status rc_sensor_memory_requirements_cylindrical(const rc_cylindrical_desc *desc, size_t *bytes)
{
    if (!bytes) return RC_ERR_INVALID_ARGUMENT;
    RC_TRY(rc__sensor_check_cylindrical(NULL, desc));
    *bytes = rc__sensor_bytes(RC_SENSOR_CYLINDRICAL, desc->height, (uint64_t)desc->theta.count * desc->height);
    return RC_OK;
}

rc_status rc_sensor_memory_requirements_rays(uint32_t model, const rc_rays_desc *desc, size_t *bytes)
{
    if (!bytes) return RC_ERR_INVALID_ARGUMENT;
    RC_TRY(rc__sensor_check_rays(NULL, model, desc));
    *bytes = rc__sensor_bytes(model, desc->height > 1u ? desc->height : 1u, desc->ray_count);
    return RC_OK;
}

rc_status rc_sensor_memory_requirements_preset(uint32_t preset, size_t *bytes)
{
    const uint32_t model = rc_preset_model(preset);
    if (!bytes || model == 0) return RC_ERR_INVALID_ARGUMENT;
    if (model == RC_SENSOR_SPHERICAL) {
        rc_spherical_desc d;
        RC_TRY(rc_preset_spherical(preset, &d));
        return rc_sensor_memory_requirements_spherical(&d, bytes);
    }
    if (model == RC_SENSOR_PINHOLE) {
        rc_pinhole_desc d;
        RC_TRY(rc_preset_pinhole(preset, &d));
        return rc_sensor_memory_requirements_pinhole(&d, bytes);
    }
    {
        rc_rays_desc d;
        uint32_t n = 0;
        RC_TRY(rc_preset_rays(preset, &d, NULL, &n));
        *bytes = rc__sensor_bytes(model, d.height > 1u ? d.height : 1u, n);
        return RC_OK;
    }
}

/* ------------------------------------------------------------------------ */
/* Create / destroy                                                          */
/* ------------------------------------------------------------------------ */

static void normalise_pose(const rc_pose *in, rc_pose *out)
{
    const double x = in->orientation[0], y = in->orientation[1];
    const double z = in->orientation[2], w = in->orientation[3];
    const double n = sqrt(x * x + y * y + z * z + w * w); /* checked: within 1e-3 of 1 */
    *out = *in;
    out->orientation[0] = (float)(x / n);
    out->orientation[1] = (float)(y / n);
    out->orientation[2] = (float)(z / n);
    out->orientation[3] = (float)(w / n);
}

/* Allocates and fills the fixed part of a sensor whose desc is checked; the
 * caller fills the tables and then links it. Nothing is allocated on failure. */
static rc_status sensor_make(rc_context *ctx, uint32_t model, uint32_t rows, uint32_t columns,
                             const rc_sensor_common *common, rc_sensor **out)
{
    const uint64_t rays = (uint64_t)rows * columns;
    sensor_layout l;
    unsigned char *mem;
    rc_sensor *s;
    if (!sensor_layout_of(model, rows, rays, &l)) /* the checks already refuse this */
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "sensor of %llu rays too large", (unsigned long long)rays);
    mem = (unsigned char *)rc__arena_alloc(&ctx->arena, l.total);
    if (!mem)
        return rc__fail(ctx, RC_ERR_OUT_OF_MEMORY,
                        "sensor of %u x %u rays needs %llu bytes of arena (rc_sensor_memory_requirements_*); "
                        "the largest free block holds %llu",
                        rows, columns, (unsigned long long)rc__sensor_bytes(model, rows, rays),
                        (unsigned long long)rc__arena_largest_free(&ctx->arena));
    s = (rc_sensor *)(void *)mem;
    memset(s, 0, sizeof *s);
    s->magic = RC__MAGIC_SENSOR;
    s->model = model;
    s->ctx = ctx;
    s->rows = rows;
    s->columns = columns;
    s->rays = (uint32_t)rays;
    s->pinhole_frame = RC_PINHOLE_FRAME_BODY;
    s->range_min = common->range_min;
    s->range_max = common->range_max;
    normalise_pose(&common->sensor_to_base, &s->mount);
    rc__xform_from_pose(&s->mount, &s->mount_xform);
    s->directions = (float *)(void *)(mem + l.directions);
    s->origins = model == RC_SENSOR_ONDN ? (float *)(void *)(mem + l.origins) : NULL;
    s->trace_order = l.order ? (uint64_t *)(void *)(mem + l.order) : NULL;
    *out = s;
    return RC_OK;
}

/* Links a filled sensor into its context (sorting a flat O1Dn/OnDn sensor's
 * rays first: their tables are complete now). O1Dn/OnDn rays given as a grid
 * of several rows have no order table: they keep their scan order, which the
 * backends cut into tiles (an Ouster unit's beams x columns: 2 x 8 tiles ran
 * 5-12% faster than runs of the sorted order). */
static void sensor_link(rc_context *ctx, rc_sensor *s)
{
    if (s->trace_order) rc__sensor_order_rays(s);
    s->next = ctx->sensors;
    ctx->sensors = s;
}

/* Copies a checked desc (struct_size <= sizeof) into the sensor's zeroed copy;
 * the copy's mounting is the normalised one the sensor uses. */
#define COPY_DESC(dst, src, s)                             \
    do {                                                   \
        memset(&(dst), 0, sizeof(dst));                    \
        memcpy(&(dst), (src), (src)->struct_size);         \
        (dst).struct_size = (uint32_t)sizeof(dst);         \
        (dst).common.sensor_to_base = (s)->mount;          \
    } while (0)

rc_status rc_sensor_create_spherical(rc_context *ctx, const rc_spherical_desc *desc, rc_sensor **out)
{
    rc_sensor *s = NULL;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    if (!out) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(rc__sensor_check_spherical(ctx, desc));
    RC_TRY(sensor_make(ctx, RC_SENSOR_SPHERICAL, desc->phi.count, desc->theta.count, &desc->common, &s));
    COPY_DESC(s->spherical, desc, s);
    rc__sensor_fill_spherical(&s->spherical, s->directions);
    sensor_link(ctx, s);
    *out = s;
    return RC_OK;
}

rc_status rc_sensor_create_pinhole(rc_context *ctx, const rc_pinhole_desc *desc, rc_sensor **out)
{
    rc_sensor *s = NULL;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    if (!out) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(rc__sensor_check_pinhole(ctx, desc));
    RC_TRY(sensor_make(ctx, RC_SENSOR_PINHOLE, desc->height, desc->width, &desc->common, &s));
    COPY_DESC(s->pinhole, desc, s);
    s->pinhole_frame = desc->frame;
    rc__sensor_fill_pinhole(&s->pinhole, s->directions);
    sensor_link(ctx, s);
    *out = s;
    return RC_OK;
}

rc_status rc_sensor_create_cylindrical(rc_context *ctx, const rc_cylindrical_desc *desc, rc_sensor **out)
{
    rc_sensor *s = NULL;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    if (!out) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(rc__sensor_check_cylindrical(ctx, desc));
    RC_TRY(sensor_make(ctx, RC_SENSOR_CYLINDRICAL, desc->height, desc->theta.count, &desc->common, &s));
    COPY_DESC(s->cylindrical, desc, s);
    rc__sensor_fill_cylindrical(&s->cylindrical, s->directions);
    sensor_link(ctx, s);
    *out = s;
    return RC_OK;
}

/* Grid shape of an O1Dn/OnDn scan: width x height, or 1 row of ray_count. */
static void rays_shape(const rc_rays_desc *desc, uint32_t *rows, uint32_t *columns)
{
    if (desc->width == 0 && desc->height == 0) {
        *rows = 1;
        *columns = desc->ray_count;
    } else {
        *rows = desc->height;
        *columns = desc->width;
    }
}

rc_status rc_sensor_create_rays(rc_context *ctx, uint32_t model, const rc_rays_desc *desc, rc_sensor **out)
{
    rc_sensor *s = NULL;
    uint32_t rows, columns, i;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    if (!out) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    RC_TRY(rc__sensor_check_rays(ctx, model, desc));
    rays_shape(desc, &rows, &columns);
    RC_TRY(sensor_make(ctx, model, rows, columns, &desc->common, &s));
    for (i = 0; i < desc->ray_count; ++i) {
        const float *d = desc->directions + (size_t)i * 3u;
        float *o = s->directions + (size_t)i * 3u;
        const double x = d[0], y = d[1], z = d[2];
        const double n = sqrt(x * x + y * y + z * z); /* checked: > 0 */
        o[0] = (float)(x / n);
        o[1] = (float)(y / n);
        o[2] = (float)(z / n);
    }
    s->origin_spread2 = 0.0f;
    if (s->origins) {
        memcpy(s->origins, desc->origins, (size_t)desc->ray_count * 3u * sizeof(float));
        for (i = 1; i < desc->ray_count; ++i) {
            /* origins are checked finite and within reach: no overflow */
            const float *o = s->origins + (size_t)i * 3u;
            const float dx = o[0] - s->origins[0], dy = o[1] - s->origins[1], dz = o[2] - s->origins[2];
            const float d2 = dx * dx + dy * dy + dz * dz;
            s->origin_spread2 = d2 > s->origin_spread2 ? d2 : s->origin_spread2;
        }
    }
    sensor_link(ctx, s);
    *out = s;
    return RC_OK;
}

rc_status rc_sensor_create_preset(rc_context *ctx, uint32_t preset, rc_sensor **out)
{
    const uint32_t model = rc_preset_model(preset);
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(ctx);
    if (!out) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "out is NULL");
    switch (model) {
    case RC_SENSOR_SPHERICAL: {
        rc_spherical_desc d;
        RC_TRY(rc_preset_spherical(preset, &d));
        return rc_sensor_create_spherical(ctx, &d, out);
    }
    case RC_SENSOR_PINHOLE: {
        rc_pinhole_desc d;
        RC_TRY(rc_preset_pinhole(preset, &d));
        return rc_sensor_create_pinhole(ctx, &d, out);
    }
    case RC_SENSOR_O1DN:
    case RC_SENSOR_ONDN: {
        /* Generated straight into the sensor's table: no scratch buffer. */
        rc_rays_desc d;
        rc_sensor *s = NULL;
        uint32_t n = 0, rows, columns;
        rc_status st = rc_preset_rays(preset, &d, NULL, &n);
        if (st != RC_OK) return rc__fail(ctx, st, "preset %u: its rays could not be generated", preset);
        d.ray_count = n;
        rays_shape(&d, &rows, &columns);
        RC_TRY(rc__sensor_check_common(ctx, &d.common));
        RC_TRY(sensor_make(ctx, model, rows, columns, &d.common, &s));
        st = rc_preset_rays(preset, NULL, s->directions, &n);
        if (st != RC_OK) { /* cannot happen: same preset, same count */
            s->magic = RC__MAGIC_DEAD;
            rc__arena_free(&ctx->arena, s);
            return rc__fail(ctx, st, "preset %u: its rays could not be generated", preset);
        }
        sensor_link(ctx, s);
        *out = s;
        return RC_OK;
    }
    default:
        return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT,
                        "preset is %u: not a known RC_PRESET_* (see rc_preset_from_name)", preset);
    }
}

rc_status rc_sensor_destroy(rc_sensor *sensor)
{
    rc_context *ctx;
    rc_sensor **link;
    if (!sensor) return RC_OK;
    if (!rc__sensor_valid(sensor)) return RC_ERR_INVALID_HANDLE;
    ctx = sensor->ctx;
    rc__clear_error(ctx);
    for (link = &ctx->sensors; *link && *link != sensor; link = &(*link)->next) {
    }
    /* A sensor with the right magic missing from its context's list is a forged
     * or corrupted handle: refuse rather than free memory we do not own. */
    if (!*link) return rc__fail(ctx, RC_ERR_INVALID_HANDLE, "sensor %p is not one of this context's sensors",
                                (void *)sensor);
    *link = sensor->next;
    sensor->next = NULL;
    sensor->magic = RC__MAGIC_DEAD;
    rc__arena_free(&ctx->arena, sensor);
    return RC_OK;
}

/* ------------------------------------------------------------------------ */
/* Queries and mounting                                                      */
/* ------------------------------------------------------------------------ */

rc_status rc_sensor_get_info(const rc_sensor *sensor, rc_sensor_info *info)
{
    rc_sensor_info i;
    rc_context *ctx;
    if (!rc__sensor_valid(sensor)) return RC_ERR_INVALID_HANDLE;
    ctx = sensor->ctx;
    rc__clear_error(ctx);
    RC_TRY(rc__check_desc(ctx, info, (uint32_t)sizeof(rc_sensor_info), (uint32_t)sizeof(rc_sensor_info), "info"));
    i = rc_sensor_info_default();
    i.model = sensor->model;
    i.rows = sensor->rows;
    i.columns = sensor->columns;
    i.rays_per_scan = sensor->rays;
    i.range_min = sensor->range_min;
    i.range_max = sensor->range_max;
    i.struct_size = info->struct_size;
    memcpy(info, &i, info->struct_size);
    return RC_OK;
}

rc_noise_desc rc_noise_desc_default(void)
{
    rc_noise_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    return d;
}

rc_status rc_sensor_set_noise(rc_sensor *sensor, const rc_noise_desc *noise)
{
    if (!rc__sensor_valid(sensor)) return RC_ERR_INVALID_HANDLE;
    rc__clear_error(sensor->ctx);
    if (noise) RC_TRY(rc__noise_check(sensor->ctx, noise));
    rc__noise_set(&sensor->noise, noise);
    return RC_OK;
}

rc_status rc_sensor_set_mounting(rc_sensor *sensor, const rc_pose *sensor_to_base)
{
    rc_context *ctx;
    rc_status st;
    if (!rc__sensor_valid(sensor)) return RC_ERR_INVALID_HANDLE;
    ctx = sensor->ctx;
    rc__clear_error(ctx);
    if (!sensor_to_base) return rc__fail(ctx, RC_ERR_INVALID_ARGUMENT, "sensor_to_base is NULL");
    st = rc__pose_check(sensor_to_base);
    if (st != RC_OK) {
        const rc_pose *p = sensor_to_base;
        return rc__fail(ctx, st,
                        "sensor_to_base is position (%g, %g, %g), orientation (%g, %g, %g, %g): %s", (double)p->position[0],
                        (double)p->position[1], (double)p->position[2], (double)p->orientation[0],
                        (double)p->orientation[1], (double)p->orientation[2], (double)p->orientation[3],
                        st == RC_ERR_NON_FINITE ? "must be finite"
                                                : "the quaternion's norm must be within 1e-3 of 1");
    }
    normalise_pose(sensor_to_base, &sensor->mount);
    rc__xform_from_pose(&sensor->mount, &sensor->mount_xform);
    /* keep the model's desc copy in step (backends may read it) */
    if (sensor->model == RC_SENSOR_SPHERICAL) sensor->spherical.common.sensor_to_base = sensor->mount;
    if (sensor->model == RC_SENSOR_PINHOLE) sensor->pinhole.common.sensor_to_base = sensor->mount;
    if (sensor->model == RC_SENSOR_CYLINDRICAL) sensor->cylindrical.common.sensor_to_base = sensor->mount;
    return RC_OK;
}
