/* Sensors: models, validation, the precomputed direction tables, presets. */
#ifndef RC_SENSOR_SENSOR_H
#define RC_SENSOR_SENSOR_H

#include "core/context.h"
#include "core/rmath.h"
#include "noise/noise.h"

#include <math.h>

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

/* Arena bytes of a sensor with this many rays in this many rows (object +
 * tables; only a flat O1Dn/OnDn list, one row, has a trace order). */
size_t rc__sensor_bytes(uint32_t model, uint32_t rows, uint64_t rays);

/* Fill the direction table (3 floats a ray, unit) in scan order. */
void rc__sensor_fill_spherical(const rc_spherical_desc *desc, float *dirs);
void rc__sensor_fill_pinhole(const rc_pinhole_desc *desc, float *dirs);
void rc__sensor_fill_cylindrical(const rc_cylindrical_desc *desc, float *dirs);

/* 1 when the CPU backends trace the sensor in tiles of rows x columns in
 * scan order (spherical, pinhole, cylindrical, and O1Dn/OnDn rays given with
 * more than one row, such as an Ouster unit's beams x columns), with the
 * angular steps between neighbouring rows and columns at the grid's centre
 * (radians; for rays, about the sines of the elevation step between rows
 * and the azimuth step between columns: only their ratio shapes the tiles);
 * 0 for a flat list of rays, traced in runs of the sorted order. */
static inline int rc__sensor_grid_steps(const rc_sensor *s, double *row_step, double *col_step)
{
    switch (s->model) {
    case RC_SENSOR_SPHERICAL:
        *row_step = fabs((double)s->spherical.phi.increment);
        *col_step = fabs((double)s->spherical.theta.increment);
        return 1;
    case RC_SENSOR_PINHOLE:
        *row_step = 1.0 / s->pinhole.fy;
        *col_step = 1.0 / s->pinhole.fx;
        return 1;
    case RC_SENSOR_CYLINDRICAL:
        *row_step = 1.0 / s->cylindrical.fy;
        *col_step = fabs((double)s->cylindrical.theta.increment);
        return 1;
    default: {
        /* rays: as for a spinning LiDAR's beams (whose rows may sit degrees
         * apart in azimuth: an Ouster's staggered beams), the sine-like steps
         * of elevation to the next row's ray (z, the directions being unit)
         * and of azimuth to the next column's (the z of their cross product
         * over the horizontal length squared), from the centre ray */
        const float *a, *next_row;
        double h2;
        if (s->rows < 2u) return 0;
        a = s->directions + (size_t)3 * ((s->rows - 1u) / 2u * s->columns + (s->columns - 1u) / 2u);
        next_row = a + (size_t)3 * s->columns;
        h2 = (double)a[0] * a[0] + (double)a[1] * a[1];
        *row_step = *col_step = fabs((double)next_row[2] - a[2]);
        if (s->columns > 1u && h2 > 1e-12) /* a[3], a[4]: the next column's x, y */
            *col_step = fabs((double)a[0] * a[4] - (double)a[1] * a[3]) / h2;
        return 1;
    }
    }
}

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
