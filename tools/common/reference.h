/* rcutil: float64 reference geometry for checking the library: rigid
 * transforms, the ray table of every sensor preset recomputed in double from
 * the header's formulas, and exact ray/triangle-plane and ray/sphere distances. */
#ifndef RCU_REFERENCE_H
#define RCU_REFERENCE_H

#include <stdint.h>

#include "rangecast/rangecast.h"
#include "util.h"

/* x -> r * x + t, in double. */
typedef struct rcu_xform {
    double r[3][3];
    double t[3];
} rcu_xform;

/* The transform of a pose (the quaternion is normalised in double). */
void rcu_xform_from_pose(const rc_pose *pose, rcu_xform *out);
/* out = a * b (apply b first). out may alias a or b. */
void rcu_xform_mul(const rcu_xform *a, const rcu_xform *b, rcu_xform *out);
void rcu_xform_point(const rcu_xform *x, const double p[3], double out[3]);
void rcu_xform_dir(const rcu_xform *x, const double d[3], double out[3]);

/* The rays of a preset in the sensor frame, in scan order, unit length,
 * computed in double from the preset's desc (rc_preset_spherical/_pinhole) or
 * its float directions (rc_preset_rays) with the header's formulas. *dirs is
 * malloc'd, 3 doubles a ray; origins (OnDn only) are not supported.
 * mount, range_min/max, rows, columns may be NULL. */
typedef struct rcu_preset_rays {
    double *dirs;
    uint32_t rays, rows, columns;
    uint32_t model;
    uint32_t forward_axis;  /* the viewing axis in the sensor frame: 0 (x), or 2 (z) for RC_PINHOLE_FRAME_OPTICAL */
    double range_min, range_max;
    rc_pose mount;          /* sensor_to_base */
    double *origins;        /* OnDn (rcu_rays_f64): 3 doubles a ray, sensor frame; else NULL */
} rcu_preset_rays;
int rcu_preset_rays_f64(uint32_t preset, rcu_preset_rays *out);
/* The same for an OnDn sensor of the caller's rays (directions normalised in
 * double, origins as given), identity mount. */
int rcu_rays_f64(const float *origins, const float *dirs, uint32_t count, float range_min, float range_max,
                 rcu_preset_rays *out);
void rcu_preset_rays_free(rcu_preset_rays *rays);

/* Distance t along the ray o + t d (d unit) to the plane of triangle v0 v1 v2,
 * in double; NaN when the ray is parallel to the plane or the triangle is
 * degenerate. */
double rcu_ray_plane_distance(const double o[3], const double d[3], const float *v0, const float *v1,
                              const float *v2);

/* Exit distance of the ray o + t d (d unit, o inside) from the sphere of the
 * given radius about the origin; NaN when o is outside. */
double rcu_ray_sphere_exit(const double o[3], const double d[3], double radius);

#endif
