#include "reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rcu_xform_from_pose(const rc_pose *pose, rcu_xform *out)
{
    double x = pose->orientation[0], y = pose->orientation[1], z = pose->orientation[2],
           w = pose->orientation[3];
    double n = sqrt(x * x + y * y + z * z + w * w);
    if (n > 0.0) {
        x /= n;
        y /= n;
        z /= n;
        w /= n;
    }
    out->r[0][0] = 1.0 - 2.0 * (y * y + z * z);
    out->r[0][1] = 2.0 * (x * y - w * z);
    out->r[0][2] = 2.0 * (x * z + w * y);
    out->r[1][0] = 2.0 * (x * y + w * z);
    out->r[1][1] = 1.0 - 2.0 * (x * x + z * z);
    out->r[1][2] = 2.0 * (y * z - w * x);
    out->r[2][0] = 2.0 * (x * z - w * y);
    out->r[2][1] = 2.0 * (y * z + w * x);
    out->r[2][2] = 1.0 - 2.0 * (x * x + y * y);
    out->t[0] = pose->position[0];
    out->t[1] = pose->position[1];
    out->t[2] = pose->position[2];
}

void rcu_xform_mul(const rcu_xform *a, const rcu_xform *b, rcu_xform *out)
{
    rcu_xform o;
    int i, j;
    for (i = 0; i < 3; i++) {
        for (j = 0; j < 3; j++)
            o.r[i][j] = a->r[i][0] * b->r[0][j] + a->r[i][1] * b->r[1][j] + a->r[i][2] * b->r[2][j];
        o.t[i] = a->r[i][0] * b->t[0] + a->r[i][1] * b->t[1] + a->r[i][2] * b->t[2] + a->t[i];
    }
    *out = o;
}

void rcu_xform_dir(const rcu_xform *x, const double d[3], double out[3])
{
    double o[3];
    int i;
    for (i = 0; i < 3; i++) o[i] = x->r[i][0] * d[0] + x->r[i][1] * d[1] + x->r[i][2] * d[2];
    memcpy(out, o, sizeof o);
}

void rcu_xform_point(const rcu_xform *x, const double p[3], double out[3])
{
    double o[3];
    int i;
    rcu_xform_dir(x, p, o);
    for (i = 0; i < 3; i++) out[i] = o[i] + x->t[i];
}

static void normalize_into(double *d, double x, double y, double z)
{
    double n = sqrt(x * x + y * y + z * z);
    d[0] = x / n;
    d[1] = y / n;
    d[2] = z / n;
}

void rcu_preset_rays_free(rcu_preset_rays *rays)
{
    if (!rays) return;
    free(rays->dirs);
    free(rays->origins);
    memset(rays, 0, sizeof *rays);
}

int rcu_preset_rays_f64(uint32_t preset, rcu_preset_rays *out)
{
    uint32_t model = rc_preset_model(preset);
    const rc_sensor_common *common = NULL;
    rc_spherical_desc sd;
    rc_pinhole_desc pd;
    rc_rays_desc rd;
    rc_status st;
    uint32_t i, j;
    memset(out, 0, sizeof *out);
    out->model = model;
    if (model == RC_SENSOR_SPHERICAL) {
        sd = rc_spherical_desc_default();
        if ((st = rc_preset_spherical(preset, &sd)) != RC_OK)
            return rcu_fail("rc_preset_spherical(%u): %s", preset, rc_status_string(st));
        common = &sd.common;
        out->rows = sd.phi.count;
        out->columns = sd.theta.count;
        out->rays = out->rows * out->columns;
        out->dirs = (double *)malloc((size_t)out->rays * 3u * sizeof(double));
        if (!out->dirs) return rcu_fail("out of memory");
        for (i = 0; i < out->rows; i++) {
            double phi = (double)sd.phi.min + (double)i * (double)sd.phi.increment;
            for (j = 0; j < out->columns; j++) {
                double theta = (double)sd.theta.min + (double)j * (double)sd.theta.increment;
                double *d = out->dirs + 3u * ((size_t)i * out->columns + j);
                d[0] = cos(phi) * cos(theta);
                d[1] = cos(phi) * sin(theta);
                d[2] = sin(phi);
            }
        }
    } else if (model == RC_SENSOR_PINHOLE) {
        pd = rc_pinhole_desc_default();
        if ((st = rc_preset_pinhole(preset, &pd)) != RC_OK)
            return rcu_fail("rc_preset_pinhole(%u): %s", preset, rc_status_string(st));
        common = &pd.common;
        out->forward_axis = pd.frame == RC_PINHOLE_FRAME_OPTICAL ? 2u : 0u;
        out->rows = pd.height;
        out->columns = pd.width;
        out->rays = out->rows * out->columns;
        out->dirs = (double *)malloc((size_t)out->rays * 3u * sizeof(double));
        if (!out->dirs) return rcu_fail("out of memory");
        for (i = 0; i < out->rows; i++) {
            for (j = 0; j < out->columns; j++) {
                double ox = ((double)j - pd.cx) / pd.fx, oy = ((double)i - pd.cy) / pd.fy;
                double *d = out->dirs + 3u * ((size_t)i * out->columns + j);
                if (pd.frame == RC_PINHOLE_FRAME_OPTICAL)
                    normalize_into(d, ox, oy, 1.0);
                else
                    normalize_into(d, 1.0, -ox, -oy);
            }
        }
    } else if (model == RC_SENSOR_O1DN) {
        float *fd;
        uint32_t count = 0;
        rd = rc_rays_desc_default();
        if ((st = rc_preset_rays(preset, &rd, NULL, &count)) != RC_OK || count == 0)
            return rcu_fail("rc_preset_rays(%u): %s", preset, rc_status_string(st));
        fd = (float *)malloc((size_t)count * 3u * sizeof(float));
        out->dirs = (double *)malloc((size_t)count * 3u * sizeof(double));
        if (!fd || !out->dirs) {
            free(fd);
            rcu_preset_rays_free(out);
            return rcu_fail("out of memory");
        }
        rd = rc_rays_desc_default();
        if ((st = rc_preset_rays(preset, &rd, fd, &count)) != RC_OK) {
            free(fd);
            rcu_preset_rays_free(out);
            return rcu_fail("rc_preset_rays(%u): %s", preset, rc_status_string(st));
        }
        common = &rd.common;
        out->rays = count;
        out->columns = rd.width ? rd.width : count;
        out->rows = rd.height ? rd.height : 1;
        for (i = 0; i < count; i++)
            normalize_into(out->dirs + 3u * (size_t)i, fd[3u * i], fd[3u * i + 1], fd[3u * i + 2]);
        free(fd);
    } else {
        return rcu_fail("preset %u has model %u, which the reference does not cover", preset, model);
    }
    out->range_min = common->range_min;
    out->range_max = common->range_max;
    out->mount = common->sensor_to_base;
    /* a zero desc quaternion means "default" = identity */
    if (out->mount.orientation[0] == 0.0f && out->mount.orientation[1] == 0.0f &&
        out->mount.orientation[2] == 0.0f && out->mount.orientation[3] == 0.0f)
        out->mount.orientation[3] = 1.0f;
    return 0;
}

int rcu_rays_f64(const float *origins, const float *dirs, uint32_t count, float range_min, float range_max,
                 rcu_preset_rays *out)
{
    uint32_t i;
    memset(out, 0, sizeof *out);
    out->dirs = (double *)malloc((size_t)count * 3 * sizeof(double));
    out->origins = (double *)malloc((size_t)count * 3 * sizeof(double));
    if (!out->dirs || !out->origins) {
        rcu_preset_rays_free(out);
        return rcu_fail("out of memory for %u rays", count);
    }
    for (i = 0; i < count; i++) {
        normalize_into(out->dirs + 3u * (size_t)i, dirs[3u * i], dirs[3u * i + 1], dirs[3u * i + 2]);
        out->origins[3u * i] = origins[3u * i];
        out->origins[3u * i + 1] = origins[3u * i + 1];
        out->origins[3u * i + 2] = origins[3u * i + 2];
    }
    out->rays = count;
    out->rows = 1;
    out->columns = count;
    out->model = RC_SENSOR_ONDN;
    out->range_min = range_min;
    out->range_max = range_max;
    out->mount.orientation[3] = 1.0f;
    return 0;
}

double rcu_ray_plane_distance(const double o[3], const double d[3], const float *v0, const float *v1,
                              const float *v2)
{
    double e1[3], e2[3], n[3], w[3], den;
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)v1[k] - (double)v0[k];
        e2[k] = (double)v2[k] - (double)v0[k];
        w[k] = (double)v0[k] - o[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (den == 0.0) return NAN;
    return (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]) / den;
}

double rcu_ray_sphere_exit(const double o[3], const double d[3], double radius)
{
    double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
    double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - radius * radius;
    if (c > 0.0) return NAN;
    return -b + sqrt(b * b - c);
}
