/* Ouster lidars from their beam intrinsics (rc_ouster_rays): every ray's
 * origin and direction worked out in double from the header's formulas, then
 * stored as float. No context: statuses only. */
#include "core/common.h"

#include <math.h>
#include <string.h>

#define OUSTER_PI 3.14159265358979323846
#define MAX_TRANSLATION_MM 1.0e11 /* 1e8 m */

rc_ouster_desc rc_ouster_desc_default(void)
{
    static const double lidar_to_sensor[16] = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
    rc_ouster_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    d.beam_to_lidar[0] = d.beam_to_lidar[5] = d.beam_to_lidar[10] = d.beam_to_lidar[15] = 1.0;
    memcpy(d.lidar_to_sensor, lidar_to_sensor, sizeof lidar_to_sensor);
    return d;
}

static int finite_all(const double *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* The 3x3 part of a row-major 4x4 is a rotation (within 1e-6), and its last
 * row is 0 0 0 1. */
static int rigid(const double m[16])
{
    int i, j, k;
    double det;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double dot = 0.0;
            for (k = 0; k < 3; ++k) dot += m[4 * k + i] * m[4 * k + j];
            if (fabs(dot - (i == j ? 1.0 : 0.0)) > 1e-6) return 0;
        }
    det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
          m[2] * (m[4] * m[9] - m[5] * m[8]);
    return det > 0.0 && m[12] == 0.0 && m[13] == 0.0 && m[14] == 0.0 && m[15] == 1.0;
}

static void apply(const double m[16], const double v[3], int point, double out[3])
{
    int i;
    for (i = 0; i < 3; ++i)
        out[i] = m[4 * i] * v[0] + m[4 * i + 1] * v[1] + m[4 * i + 2] * v[2] + (point ? m[4 * i + 3] : 0.0);
}

rc_status rc_ouster_rays(const rc_ouster_desc *desc, rc_rays_desc *rays, float *origins, float *directions,
                         double *beam_offset_m)
{
    const double *b2l, *l2s;
    double bx, bz;
    uint32_t u, v, k;
    if (desc == NULL || origins == NULL || directions == NULL) return RC_ERR_INVALID_ARGUMENT;
    if (desc->struct_size != sizeof *desc) return RC_ERR_STRUCT_SIZE;
    if (desc->reserved0 != 0 || desc->beams == 0 || desc->columns == 0 ||
        desc->beams > RC_OUSTER_MAX_RAYS / desc->columns || desc->altitudes_deg == NULL || desc->azimuths_deg == NULL)
        return RC_ERR_INVALID_ARGUMENT;
    for (k = 0; k < sizeof desc->reserved / sizeof desc->reserved[0]; ++k)
        if (desc->reserved[k] != 0) return RC_ERR_INVALID_ARGUMENT;
    b2l = desc->beam_to_lidar;
    l2s = desc->lidar_to_sensor;
    if (!finite_all(desc->altitudes_deg, desc->beams) || !finite_all(desc->azimuths_deg, desc->beams) ||
        !finite_all(b2l, 16) || !finite_all(l2s, 16))
        return RC_ERR_NON_FINITE;
    if (!rigid(b2l) || !rigid(l2s)) return RC_ERR_INVALID_ARGUMENT;
    bx = b2l[3];
    bz = b2l[11];
    /* the origins become floats and OnDn origins within reach: a finite
     * 1e110 mm would turn into inf (and a double out of float's range is
     * undefined to convert); 1e11 mm a component keeps them within 1e9 m */
    if (!(fabs(bx) <= MAX_TRANSLATION_MM) || !(fabs(bz) <= MAX_TRANSLATION_MM) ||
        !(fabs(l2s[3]) <= MAX_TRANSLATION_MM) || !(fabs(l2s[7]) <= MAX_TRANSLATION_MM) ||
        !(fabs(l2s[11]) <= MAX_TRANSLATION_MM))
        return RC_ERR_INVALID_ARGUMENT;
    for (u = 0; u < desc->beams; ++u) {
        const double ta = -desc->azimuths_deg[u] * (OUSTER_PI / 180.0);
        const double p = desc->altitudes_deg[u] * (OUSTER_PI / 180.0);
        for (v = 0; v < desc->columns; ++v) {
            const double te = 2.0 * OUSTER_PI * (1.0 - (double)v / (double)desc->columns);
            const double d[3] = {cos(te + ta) * cos(p), sin(te + ta) * cos(p), sin(p)};
            const double o[3] = {bx * cos(te), bx * sin(te), bz};
            const size_t i = 3u * ((size_t)u * desc->columns + v);
            double ds[3], os[3], len;
            apply(l2s, d, 0, ds);
            apply(l2s, o, 1, os);
            len = sqrt(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2]);
            for (k = 0; k < 3; ++k) {
                directions[i + k] = (float)(ds[k] / len);
                origins[i + k] = (float)(os[k] / 1000.0);
            }
        }
    }
    if (rays) {
        rc_rays_desc r = rc_rays_desc_default();
        r.common.range_min = 0.3f;
        r.common.range_max = 120.0f;
        r.directions = directions;
        r.origins = origins;
        r.ray_count = desc->beams * desc->columns;
        r.width = desc->columns;
        r.height = desc->beams;
        *rays = r;
    }
    if (beam_offset_m) *beam_offset_m = sqrt(bx * bx + bz * bz) / 1000.0;
    return RC_OK;
}
