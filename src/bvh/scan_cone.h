/* Placing a bounding sphere on a spherical scan's grid (scan_raster.c): the
 * rows its cone from the origin can reach, and the azimuths a triangle
 * spans. Everything here errs wide: a row or column it gives too many costs
 * a test, one it misses would lose a hit. Private to scan_raster.c. */
#ifndef RC_BVH_SCAN_CONE_H
#define RC_BVH_SCAN_CONE_H

#include "bvh/scan_raster.h"

#include <math.h>
#include <stdint.h>

#if defined(__GNUC__)
#define RC__CONE_INLINE inline __attribute__((always_inline))
#else
#define RC__CONE_INLINE inline
#endif

#define RC__TWO_PI 6.283185307179586
#define RC__HALF_PI 1.5707963267948966

/* Angular slack added to every cone (radians): the float rays (the
 * direction table, then the turn into the map frame) lie within about 1e-7
 * of their grid angles, and the float test's hits within a few ulps of the
 * triangle; 1e-4 is orders beyond both, and costs a scan of 0.4-degree
 * columns about 3% more tests. The test's rounding grows with the vertices'
 * distance against the triangle's (RC__CONE_SPREAD_SLACK), and the angles
 * below are rc__cone_atan2's (RC__CONE_ATAN_ERROR). */
#define RC__CONE_SLACK 1e-4
#define RC__CONE_SPREAD_SLACK 1e-5
#define RC__CONE_ATAN_ERROR 1e-9

/* s = the sum of (-z2)^k / (2k + 1) for k = 0..9, for a double or a lane
 * vector of them (type T): atan z = z * s where z2 = z * z. By Estrin's
 * scheme, pairs of terms then powers z2^2, z2^4, z2^8: a chain of 7
 * operations instead of Horner's 18 (the series' latency was 7% of a 10k
 * scan), the same terms. */
#define RC__CONE_ATAN_SERIES(T, s, z2)                                                               \
    do {                                                                                             \
        const T u2_ = (z2) * (z2), u4_ = u2_ * u2_, u8_ = u4_ * u4_;                                 \
        const T p01_ = 1.0 - (z2) * (1.0 / 3.0), p23_ = 1.0 / 5.0 - (z2) * (1.0 / 7.0);            \
        const T p45_ = 1.0 / 9.0 - (z2) * (1.0 / 11.0), p67_ = 1.0 / 13.0 - (z2) * (1.0 / 15.0);    \
        const T p89_ = 1.0 / 17.0 - (z2) * (1.0 / 19.0);                                             \
        s = (p01_ + u2_ * p23_) + u4_ * (p45_ + u2_ * p67_) + u8_ * p89_;                            \
    } while (0)

/* atan2(y, x) within RC__CONE_ATAN_ERROR, without libm's cost (at 10k
 * triangles its calls were a fifth of a scan): folded to an argument z in
 * [0, tan(pi / 8)], then the alternating series of atan z to its z^19
 * term, whose error is below z^21 / 21 < 5e-10. (0, 0) gives 0. */
static inline double rc__cone_atan2(double y, double x)
{
    const double ax = fabs(x), ay = fabs(y);
    const double big = ax > ay ? ax : ay, small = ax > ay ? ay : ax;
    double z, z2, s, a = 0.0;
    if (big == 0.0) return 0.0;
    if (small > 0.41421356237309503 * big) {
        /* atan q = pi / 4 + atan((q - 1) / (q + 1)) for q = small / big:
         * one division */
        z = (small - big) / (small + big);
        a = 0.78539816339744831;
    } else {
        z = small / big;
    }
    z2 = z * z;
    RC__CONE_ATAN_SERIES(double, s, z2);
    a += z * s;
    if (ay > ax) a = RC__HALF_PI - a;
    if (x < 0.0) a = 3.141592653589793 - a;
    return y < 0.0 ? -a : a;
}

/* The indices k of values base + k * inc (k < count) within [lo, hi]:
 * [*k0, *k1], empty when *k0 > *k1. inv = 1 / inc: a multiplication's
 * rounding only moves a bound that lies within a few ulps of a grid value,
 * and every [lo, hi] here carries a slack far beyond that. */
static inline void rc__cone_index_range(double base, double inc, double inv, uint32_t count, double lo, double hi,
                                        int64_t *k0, int64_t *k1)
{
    double a, b;
    if (inc == 0.0) {
        const int in = base >= lo && base <= hi;
        *k0 = 0;
        *k1 = in ? 0 : -1;
        return;
    }
    a = (lo - base) * inv;
    b = (hi - base) * inv;
    if (a > b) {
        const double s = a;
        a = b;
        b = s;
    }
    a = ceil(a);
    b = floor(b);
    if (!(a <= b) || b < 0.0 || a > (double)count - 1.0) {
        /* empty (converting a bound far outside the grid would overflow) */
        *k0 = 0;
        *k1 = -1;
        return;
    }
    *k0 = a < 0.0 ? 0 : (int64_t)a;
    *k1 = b > (double)count - 1.0 ? (int64_t)count - 1 : (int64_t)b;
}

/* The rows whose elevations lie within [lo, hi]: [*i0, *i1], empty when
 * *i0 > *i1. A cylindrical grid's row v = cy - fy tan(e) falls as e rises
 * (libm's tan is within an ulp or so: the slack covers it); elevations
 * beyond +-pi/2 reach the last row on that side. */
static inline void rc__cone_rows(const rc__raster_grid *g, double lo, double hi, int64_t *i0, int64_t *i1)
{
    double top, bottom;
    if (!g->rows_tan) {
        rc__cone_index_range(g->phi_min, g->phi_inc, g->phi_inv, g->rows, lo, hi, i0, i1);
        return;
    }
    top = hi >= RC__HALF_PI ? -HUGE_VAL : g->row_cy - g->row_fy * tan(hi);
    bottom = lo <= -RC__HALF_PI ? HUGE_VAL : g->row_cy - g->row_fy * tan(lo);
    rc__cone_index_range(0.0, 1.0, 1.0, g->rows, top, bottom, i0, i1);
}

/* Where a sphere's cone falls on the grid. */
typedef struct rc__cone {
    double lo, hi;  /* its elevations (radians, slack included) */
    double slack;   /* the slack an azimuth takes at elevation 0 */
    int64_t i0, i1; /* the rows within [lo, hi] */
} rc__cone;

#define RC__CONE_NONE 0   /* no row, or wholly beyond tmax */
#define RC__CONE_ROWS 1   /* rows i0 .. i1 */
#define RC__CONE_AROUND 2 /* the origin is in the sphere: any ray */

/* The cone of the sphere about m (map frame, relative to the origin) of
 * radius rad, whose points lie within far of the origin, as the sensor
 * turned by r (row-major, sensor to map) sees it. */
static inline int rc__cone_place(const rc__raster_grid *g, const float r[9], double tmax, const double m[3],
                                 double rad, double far, rc__cone *c)
{
    double u[3], d, rho, alpha, phi_c;
    int k;
    /* the sensor frame: the turn's transpose */
    for (k = 0; k < 3; ++k) u[k] = r[k] * m[0] + r[3 + k] * m[1] + r[6 + k] * m[2];
    d = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    /* wholly beyond the range (t counts |dir|, within 1e-6 of 1) */
    if ((d - rad) * (1.0 - 1e-5) > tmax) return RC__CONE_NONE;
    if (d <= rad * (1.0 + 1e-6)) {
        /* every row and azimuth */
        c->lo = -RC__HALF_PI;
        c->hi = RC__HALF_PI;
        c->slack = 0.0;
        c->i0 = 0;
        c->i1 = (int64_t)g->rows - 1;
        return RC__CONE_AROUND;
    }
    rho = sqrt(u[0] * u[0] + u[1] * u[1]);
    c->slack = RC__CONE_SLACK + RC__CONE_SPREAD_SLACK * far / (d - rad) + RC__CONE_ATAN_ERROR;
    /* asin(rad / d), and the centre's elevation */
    alpha = rc__cone_atan2(rad, sqrt(d * d - rad * rad)) + c->slack;
    phi_c = rc__cone_atan2(u[2], rho);
    c->lo = phi_c - alpha;
    c->hi = phi_c + alpha;
    rc__cone_rows(g, c->lo, c->hi, &c->i0, &c->i1);
    return c->i0 <= c->i1 ? RC__CONE_ROWS : RC__CONE_NONE;
}

/* The azimuths a triangle (corners rel[0..9), map frame, relative to the origin)
 * spans in the sensor frame, widened by the cone's slack: [*lo, *hi]; 0
 * when that is every azimuth. Its cone c is clear of the poles, so the
 * triangle holds neither. A great circle not through a pole crosses each
 * meridian once, so an edge's azimuths run the short way between its ends'
 * and the triangle spans the shortest arc that holds its corners' (the
 * complement of the widest gap between them). An azimuth at elevation phi
 * takes slack / cos phi, and cos phi >= (pi / 2 - |phi|) * 2 / pi. */
static inline int rc__cone_azimuths(const rc__cone *c, const float r[9], const float *rel, double *lo, double *hi)
{
    const double steep = c->hi > -c->lo ? c->hi : -c->lo;
    const double slack = c->slack * RC__HALF_PI / (RC__HALF_PI - steep);
    double th[3], gap, t;
    int k, widest;
    for (k = 0; k < 3; ++k) {
        const float *v = rel + 3 * k;
        const double x = (double)r[0] * v[0] + (double)r[3] * v[1] + (double)r[6] * v[2];
        const double y = (double)r[1] * v[0] + (double)r[4] * v[1] + (double)r[7] * v[2];
        th[k] = rc__cone_atan2(y, x);
    }
    /* sorted, then the widest of the three gaps (the last wraps) */
    if (th[0] > th[1]) t = th[0], th[0] = th[1], th[1] = t;
    if (th[1] > th[2]) t = th[1], th[1] = th[2], th[2] = t;
    if (th[0] > th[1]) t = th[0], th[0] = th[1], th[1] = t;
    widest = 2;
    gap = th[0] + RC__TWO_PI - th[2];
    if (th[1] - th[0] > gap) widest = 0, gap = th[1] - th[0];
    if (th[2] - th[1] > gap) widest = 1;
    /* the arc starts after the widest gap and ends before it */
    *lo = th[widest == 2 ? 0 : widest + 1] - slack;
    *hi = th[widest] + (widest == 2 ? 0.0 : RC__TWO_PI) + slack;
    return *hi - *lo < RC__TWO_PI && slack < 0.5;
}

#if defined(__GNUC__) && (defined(__SSE2__) || defined(__aarch64__)) && !defined(RC__PACKET_FORCE_SCALAR)
/* Four cones at once in lanes of doubles (GCC's vector extension: AVX2,
 * SSE2 pairs or NEON pairs), a leaf's triangles: the placement above is a
 * chain of divisions and roots, and its latency, not its instructions, held
 * a scan of a 10k map at half the packets' instructions a cycle. Each lane
 * computes what rc__cone_place and rc__cone_azimuths compute, by the same
 * formulas (the bounds hold for the same reasons; the values may differ in
 * their last bits, which the slack covers many times over). */
#define RC__CONE_LANES 1
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#else
#include <arm_neon.h>
#endif
typedef double rc__v4d __attribute__((vector_size(32)));
typedef int64_t rc__v4l __attribute__((vector_size(32)));
#define rc__v4d_splat(x) ((rc__v4d){(x), (x), (x), (x)})
#define rc__v4d_select(m, a, b) ((rc__v4d)(((rc__v4l)(a) & (m)) | ((rc__v4l)(b) & ~(m))))
#define rc__v4d_min(a, b) rc__v4d_select((a) < (b), a, b)
#define rc__v4d_max(a, b) rc__v4d_select((a) > (b), a, b)

/* Square roots of four lanes in place (the vector extension has none): two
 * lanes an instruction with SSE2 or AArch64's NEON, as correctly rounded as
 * libm's. The placement takes eight roots a triangle. */
static RC__CONE_INLINE void rc__v4d_sqrt(rc__v4d *v)
{
    double a[4];
    memcpy(a, v, sizeof a);
#if defined(__SSE2__)
    _mm_storeu_pd(a, _mm_sqrt_pd(_mm_loadu_pd(a)));
    _mm_storeu_pd(a + 2, _mm_sqrt_pd(_mm_loadu_pd(a + 2)));
#else
    vst1q_f64(a, vsqrtq_f64(vld1q_f64(a)));
    vst1q_f64(a + 2, vsqrtq_f64(vld1q_f64(a + 2)));
#endif
    memcpy(v, a, sizeof a);
}

/* rc__cone_atan2 in lanes, its branches as selects (into *out: no vector
 * returns, which change the calling convention outside the AVX2 build) */
static RC__CONE_INLINE void rc__cone_atan2_4(const rc__v4d *yp, const rc__v4d *xp, rc__v4d *out)
{
    const rc__v4d y = *yp, x = *xp, zero = rc__v4d_splat(0.0);
    const rc__v4d ax = rc__v4d_select(x < zero, -x, x), ay = rc__v4d_select(y < zero, -y, y);
    const rc__v4l steep = ay > ax;
    const rc__v4d big = rc__v4d_select(steep, ay, ax), small = rc__v4d_select(steep, ax, ay);
    const rc__v4l none = big == zero;
    const rc__v4l fold = small > 0.41421356237309503 * big;
    const rc__v4d z = rc__v4d_select(fold, small - big, small) /
                      rc__v4d_select(none, rc__v4d_splat(1.0), rc__v4d_select(fold, small + big, big));
    const rc__v4d z2 = z * z;
    rc__v4d s, a;
    RC__CONE_ATAN_SERIES(rc__v4d, s, z2);
    a = rc__v4d_select(fold, rc__v4d_splat(0.78539816339744831), zero) + z * s;
    a = rc__v4d_select(steep, RC__HALF_PI - a, a);
    a = rc__v4d_select(x < zero, 3.141592653589793 - a, a);
    a = rc__v4d_select(y < zero, -a, a);
    *out = rc__v4d_select(none, zero, a);
}
#endif

#endif
