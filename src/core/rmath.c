/* Pose checks and rigid transforms in double. */
#include "core/rmath.h"

#include "core/common.h"

rc_status rc__pose_check(const rc_pose *pose)
{
    const float *q = pose->orientation;
    double n2;
    if (!rc__all_finite(pose->position, 3) || !rc__all_finite(q, 4)) return RC_ERR_NON_FINITE;
    n2 = (double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3];
    /* |q| within 1e-3 of 1  <=>  |q|^2 within about 2e-3 of 1 */
    if (!(fabs(sqrt(n2) - 1.0) <= 1e-3)) return RC_ERR_INVALID_ARGUMENT;
    return RC_OK;
}

static void xform_from(const double p[3], const double q[4], rc__xform *out);

void rc__xform_from_pose(const rc_pose *pose, rc__xform *out)
{
    const double p[3] = {pose->position[0], pose->position[1], pose->position[2]};
    const double q[4] = {pose->orientation[0], pose->orientation[1], pose->orientation[2], pose->orientation[3]};
    xform_from(p, q, out);
}

void rc__xform_from_pose_d(const rc_pose_d *pose, rc__xform *out) { xform_from(pose->position, pose->orientation, out); }

rc_status rc__pose_check_d(const rc_pose_d *pose)
{
    const double *q = pose->orientation;
    int i;
    for (i = 0; i < 3; ++i)
        if (!isfinite(pose->position[i])) return RC_ERR_NON_FINITE;
    for (i = 0; i < 4; ++i)
        if (!isfinite(q[i])) return RC_ERR_NON_FINITE;
    if (!(fabs(sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) - 1.0) <= 1e-3))
        return RC_ERR_INVALID_ARGUMENT;
    return RC_OK;
}

static void xform_from(const double p[3], const double q[4], rc__xform *out)
{
    double x = q[0], y = q[1];
    double z = q[2], w = q[3];
    double n = sqrt(x * x + y * y + z * z + w * w);
    if (n > 0.0) {
        x /= n; y /= n; z /= n; w /= n;
    } else {
        x = y = z = 0.0; w = 1.0;
    }
    out->r[0] = 1.0 - 2.0 * (y * y + z * z);
    out->r[1] = 2.0 * (x * y - z * w);
    out->r[2] = 2.0 * (x * z + y * w);
    out->r[3] = 2.0 * (x * y + z * w);
    out->r[4] = 1.0 - 2.0 * (x * x + z * z);
    out->r[5] = 2.0 * (y * z - x * w);
    out->r[6] = 2.0 * (x * z - y * w);
    out->r[7] = 2.0 * (y * z + x * w);
    out->r[8] = 1.0 - 2.0 * (x * x + y * y);
    out->t[0] = p[0];
    out->t[1] = p[1];
    out->t[2] = p[2];
}

void rc__xform_mul(const rc__xform *a, const rc__xform *b, rc__xform *out)
{
    int i, j;
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j)
            out->r[i * 3 + j] = a->r[i * 3 + 0] * b->r[0 * 3 + j] + a->r[i * 3 + 1] * b->r[1 * 3 + j] +
                                a->r[i * 3 + 2] * b->r[2 * 3 + j];
        out->t[i] = a->r[i * 3 + 0] * b->t[0] + a->r[i * 3 + 1] * b->t[1] + a->r[i * 3 + 2] * b->t[2] + a->t[i];
    }
}

void rc__xform_to_float(const rc__xform *x, rc__xformf *out)
{
    int i;
    for (i = 0; i < 9; ++i) {
        out->r[i] = (float)x->r[i];
        out->rd[i] = x->r[i];
    }
    for (i = 0; i < 3; ++i) {
        out->t[i] = (float)x->t[i];
        out->td[i] = x->t[i];
    }
}

rc_pose rc_pose_identity(void)
{
    rc_pose p = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}};
    return p;
}
