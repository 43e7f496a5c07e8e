/* The direction tables of the grid models and the Livox-style rosette. Each
 * direction is computed in double exactly as the public header writes it,
 * normalised in double and stored as float (unit up to float rounding), in
 * scan order: ray = row * columns + column. */
#include "sensor/sensor.h"

#include <math.h>

#define SENSOR_PI 3.14159265358979323846

static void store_unit(double x, double y, double z, float *out)
{
    const double n = sqrt(x * x + y * y + z * z);
    out[0] = (float)(x / n);
    out[1] = (float)(y / n);
    out[2] = (float)(z / n);
}

/* Angle of value k of an axis: min + k * increment, in double so that a long
 * axis does not accumulate float error. */
static double axis_value(const rc_angle_axis *axis, uint32_t k)
{
    return (double)axis->min + (double)k * (double)axis->increment;
}

void rc__sensor_fill_spherical(const rc_spherical_desc *desc, float *dirs)
{
    uint32_t i, j;
    for (i = 0; i < desc->phi.count; ++i) {
        const double phi = axis_value(&desc->phi, i);
        const double cp = cos(phi), sp = sin(phi);
        float *row = dirs + (size_t)i * desc->theta.count * 3u;
        for (j = 0; j < desc->theta.count; ++j) {
            const double theta = axis_value(&desc->theta, j);
            store_unit(cp * cos(theta), cp * sin(theta), sp, row + (size_t)j * 3u);
        }
    }
}

void rc__sensor_fill_pinhole(const rc_pinhole_desc *desc, float *dirs)
{
    uint32_t u, v;
    for (v = 0; v < desc->height; ++v) {
        const double oy = ((double)v - (double)desc->cy) / (double)desc->fy;
        float *row = dirs + (size_t)v * desc->width * 3u;
        for (u = 0; u < desc->width; ++u) {
            const double ox = ((double)u - (double)desc->cx) / (double)desc->fx;
            /* optical o = (ox, oy, 1): z forward, x right, y down */
            if (desc->frame == RC_PINHOLE_FRAME_OPTICAL)
                store_unit(ox, oy, 1.0, row + (size_t)u * 3u);
            else
                store_unit(1.0, -ox, -oy, row + (size_t)u * 3u); /* (o.z, -o.x, -o.y) */
        }
    }
}

void rc__sensor_fill_cylindrical(const rc_cylindrical_desc *desc, float *dirs)
{
    uint32_t v, j;
    for (v = 0; v < desc->height; ++v) {
        const double h = ((double)desc->cy - (double)v) / (double)desc->fy;
        float *row = dirs + (size_t)v * desc->theta.count * 3u;
        for (j = 0; j < desc->theta.count; ++j) {
            const double theta = axis_value(&desc->theta, j);
            store_unit(cos(theta), sin(theta), h, row + (size_t)j * 3u);
        }
    }
}

/* A Risley-prism rosette, as Livox's Mid-40 scans. Each of two wedge prisms
 * deflects the beam by a fixed angle a about an axis it spins, the two in
 * opposite directions at rates f1 and f2 (turns per frame). To first order the
 * deflections add as vectors in the angle plane:
 *     p(t) = a (cos 2pi f1 t, sin 2pi f1 t) + a (cos 2pi f2 t, -sin 2pi f2 t)
 * |p| = 2a |cos(pi (f1 + f2) t)|: a rose whose petals all pass through the
 * centre, f1 + f2 petals per frame, the petal axis turning at (f1 - f2) / 2.
 * With 2a = fov / 2 every ray lies in the field-of-view cone. The rates' ratio
 * is the golden ratio (the "most irrational" number), so the pattern never
 * repeats and successive petals spread evenly round the circle: f1 + f2 = 100
 * petals per frame, f1 = 100 / phi, f2 = 100 / phi^2. Ray k of count is at
 * t = k / count, so a denser scan traces the same curve. The result depends
 * only on (fov, count): deterministic. The angle-plane vector (p_y, p_z) is
 * the offset off the x axis towards y (left) and z (up); it becomes the
 * direction at angle |p| from +x. */
void rc__sensor_fill_rosette(float fov_rad, uint32_t count, float *dirs)
{
    const double half = 0.5 * (double)fov_rad; /* cone half-angle */
    const double a = 0.5 * half;               /* one prism's deflection */
    const double golden = 0.5 * (sqrt(5.0) - 1.0); /* 1 / phi */
    const double f1 = 100.0 * golden;
    const double f2 = 100.0 - f1; /* = 100 / phi^2 */
    uint32_t k;
    for (k = 0; k < count; ++k) {
        const double t = (double)k / (double)count;
        const double w1 = 2.0 * SENSOR_PI * f1 * t, w2 = 2.0 * SENSOR_PI * f2 * t;
        double py = a * (cos(w1) + cos(w2));
        double pz = a * (sin(w1) - sin(w2));
        double r = sqrt(py * py + pz * pz);
        float *d = dirs + (size_t)k * 3u;
        if (r > half) { /* rounding only: |p| <= 2a = half exactly */
            py *= half / r;
            pz *= half / r;
            r = half;
        }
        if (r > 0.0) {
            const double s = sin(r) / r;
            store_unit(cos(r), s * py, s * pz, d);
        } else {
            d[0] = 1.0f;
            d[1] = 0.0f;
            d[2] = 0.0f;
        }
    }
}
