/* Small vector and rigid-transform math. Poses are composed in double so that a
 * float32 map keeps its precision; rays are cast in float. */
#ifndef RC_CORE_RMATH_H
#define RC_CORE_RMATH_H

#include "rangecast/rangecast.h"

#include <math.h>

/* Rotation (row-major 3x3) and translation: p' = R p + t. */
typedef struct rc__xform {
    double r[9];
    double t[3];
} rc__xform;

/* Float copy of a transform for the hot loops, with the double original kept
 * for the once-per-hit float64 refinement of the distance. */
typedef struct rc__xformf {
    float r[9];
    float t[3];
    double rd[9];
    double td[3];
} rc__xformf;

/* Bounds that keep every ray a backend sees valid. Per axis, in metres:
 * vertices (from their scene's origin), instance translations, a sensor
 * placed by a pose (mounting included, from the scene's origin) and an OnDn
 * ray's origin (in its sensor frame) lie within RC__MAX_COORD; instance
 * scales lie within [RC__MIN_SCALE, RC__MAX_SCALE] in magnitude. Embree takes
 * a ray that starts past 1.8e18, in the world or in an instance's frame, as
 * invalid (its assertions abort the process: a scale of 1e-30 did that); with
 * these a ray starts within about 4e15 in any frame, and float positions a
 * million kilometres out mean nothing anyway. */
#define RC__MAX_COORD 1.0e9
#define RC__MIN_SCALE 1.0e-6
#define RC__MAX_SCALE 1.0e6

static inline int rc__in_reach3(const float v[3])
{
    return fabsf(v[0]) <= (float)RC__MAX_COORD && fabsf(v[1]) <= (float)RC__MAX_COORD &&
           fabsf(v[2]) <= (float)RC__MAX_COORD;
}

/* Checks a pose: finite, quaternion norm within 1e-3 of 1. Returns RC_OK,
 * RC_ERR_NON_FINITE or RC_ERR_INVALID_ARGUMENT (norm off). */
rc_status rc__pose_check(const rc_pose *pose);
/* Pose to transform (the quaternion normalised). */
void rc__xform_from_pose(const rc_pose *pose, rc__xform *out);
void rc__xform_from_pose_d(const rc_pose_d *pose, rc__xform *out);
/* rc__pose_check for double poses. */
rc_status rc__pose_check_d(const rc_pose_d *pose);
/* out = a * b  (apply b first). out may alias neither. */
void rc__xform_mul(const rc__xform *a, const rc__xform *b, rc__xform *out);
void rc__xform_to_float(const rc__xform *x, rc__xformf *out);

static inline void rc__rot_apply_f(const float r[9], const float v[3], float out[3])
{
    out[0] = r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    out[1] = r[3] * v[0] + r[4] * v[1] + r[5] * v[2];
    out[2] = r[6] * v[0] + r[7] * v[1] + r[8] * v[2];
}

/* R^T v */
static inline void rc__rot_apply_transposed_f(const float r[9], const float v[3], float out[3])
{
    out[0] = r[0] * v[0] + r[3] * v[1] + r[6] * v[2];
    out[1] = r[1] * v[0] + r[4] * v[1] + r[7] * v[2];
    out[2] = r[2] * v[0] + r[5] * v[1] + r[8] * v[2];
}

static inline float rc__dot3f(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void rc__cross3f(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

#endif
