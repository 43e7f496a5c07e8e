/* Sensors: models, validation, the precomputed direction tables, presets. */
#ifndef RC_SENSOR_SENSOR_H
#define RC_SENSOR_SENSOR_H

#include "core/context.h"
#include "core/rmath.h"
#include "noise/noise.h"

struct rc_sensor {
    uint32_t magic;
    uint32_t model;          /* RC_SENSOR_* */
    rc_context *ctx;
    struct rc_sensor *next;  /* the context's list */
    uint32_t rows, columns;  /* rows * columns = rays */
    uint32_t rays;
    uint32_t pinhole_frame;  /* RC_PINHOLE_FRAME_* */
    float range_min, range_max;
    rc_pose mount;           /* sensor_to_base */
    rc__xform mount_xform;
    float *directions;       /* 3 * rays, unit, sensor frame, in scan order */
    float *origins;          /* 3 * rays for OnDn, else NULL */
    float origin_spread2;    /* OnDn: largest squared distance of an origin from the first (m^2); else 0 */
    /* O1Dn/OnDn: the order the CPU backends trace the rays in (ray index in
     * the low 32 bits, its key above: ray_order.c), so that neighbours in a
     * run leave from near each other in near directions; NULL for grids,
     * whose scan order already is. */
    uint64_t *trace_order;
    /* The model's parameters, kept for backends that generate rays themselves. */
    rc_spherical_desc spherical;
    rc_pinhole_desc pinhole;
    rc_cylindrical_desc cylindrical;
    /* rc_sensor_set_noise; its draw count advances with each simulate (the
     * one mutable field a simulate touches: contexts are single-threaded) */
    rc__noise noise;
};

int rc__sensor_valid(const rc_sensor *sensor);

/* Validation of each desc; messages name the field ("phi.count", "fx" ...). */
rc_status rc__sensor_check_common(rc_context *ctx, const rc_sensor_common *common);
rc_status rc__sensor_check_spherical(rc_context *ctx, const rc_spherical_desc *desc);
rc_status rc__sensor_check_pinhole(rc_context *ctx, const rc_pinhole_desc *desc);
rc_status rc__sensor_check_cylindrical(rc_context *ctx, const rc_cylindrical_desc *desc);
rc_status rc__sensor_check_rays(rc_context *ctx, uint32_t model, const rc_rays_desc *desc);

/* Arena bytes of a sensor with this many rays (object + tables). */
size_t rc__sensor_bytes(uint32_t model, uint64_t rays);

/* Fill the direction table (3 floats a ray, unit) in scan order. */
void rc__sensor_fill_spherical(const rc_spherical_desc *desc, float *dirs);
void rc__sensor_fill_pinhole(const rc_pinhole_desc *desc, float *dirs);
void rc__sensor_fill_cylindrical(const rc_cylindrical_desc *desc, float *dirs);

/* Sorts the rays of an O1Dn/OnDn sensor into s->trace_order (ray_order.c). */
void rc__sensor_order_rays(rc_sensor *s);

/* Ray index at position i of the order the CPU backends trace a scan in. */
static inline uint32_t rc__sensor_traced_ray(const rc_sensor *s, uint32_t i)
{
    return s->trace_order ? (uint32_t)s->trace_order[i] : i;
}

/* Livox-style rosette directions (non-repetitive, two counter-rotating prisms). */
void rc__sensor_fill_rosette(float fov_rad, uint32_t count, float *dirs);

#endif
