/* Projected scans (scan_raster.h): each triangle of a small mesh meets only
 * the rays of a spherical or cylindrical scan that its bounding cone covers,
 * or those of a camera's pixels its image can cover. */
#include "bvh/scan_raster.h"

#if defined(RC__PROJECTED_SCANS)

#include "bvh/intersect.h"
#include "bvh/scan_cone.h"
#include "bvh/leaf4.h" /* rc__leaf4_have_avx2 */

#include <math.h>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif
#include <string.h>

/* rays prepared at a time */
#define RC__RASTER_CHUNK 32u

/* Per-ray constants of the watertight test, one array each (the shared
 * origin needs no copy): the shear and the axis order, kx | ky << 2 | kz << 4;
 * and each ray's nearest hit so far, its t and its triangle's id (bs
 * RC_INVALID_ID: none yet; an id is the triangle's leaf-order slot in its
 * mesh plus the slots of the meshes before it, raster_tri.id), kept in
 * arrays so that eight rays take their offers at once in lanes. */
typedef struct raster_rays {
    float *sx, *sy, *sz;
    float *bt;
    uint32_t *bs;
    unsigned char *axes;
} raster_rays;

static size_t round16(size_t n) { return (n + 15u) & ~(size_t)15u; }

size_t rc__raster_scratch_bytes(uint32_t rays)
{
    return 5u * round16((size_t)rays * sizeof(float)) + round16(rays);
}

static void scratch_split(void *scratch, uint32_t rays, raster_rays *rr)
{
    unsigned char *p = (unsigned char *)scratch;
    const size_t fl = round16((size_t)rays * sizeof(float));
    rr->sx = (float *)(void *)p;
    rr->sy = (float *)(void *)(p + fl);
    rr->sz = (float *)(void *)(p + 2u * fl);
    rr->bt = (float *)(void *)(p + 3u * fl);
    rr->bs = (uint32_t *)(void *)(p + 4u * fl);
    rr->axes = p + 5u * fl;
}

int rc__raster_grid_ok(const rc__raster_grid *g)
{
    const double half_pi = 1.5707963267948966;
    const double last = g->phi_min + (double)(g->rows - 1u) * g->phi_inc;
    if (g->rows == 0 || g->cols == 0) return 0;
    if (g->pinhole)
        return g->fx > 0.0 && g->fy > 0.0 && isfinite(g->fx) && isfinite(g->fy) && isfinite(g->cx) &&
               isfinite(g->cy);
    if (g->rows_tan) return g->row_fy > 0.0 && isfinite(g->row_fy) && isfinite(g->row_cy);
    return g->phi_min >= -half_pi && g->phi_min <= half_pi && last >= -half_pi && last <= half_pi;
}

void rc__raster_band(const rc__raster_grid *g, uint32_t row0, uint32_t rows, rc__raster_grid *band)
{
    *band = *g;
    band->rows = rows;
    band->phi_min = g->phi_min + (double)row0 * g->phi_inc;
    band->row_cy = g->row_cy - (double)row0;
    band->cy = g->cy - (double)row0;
}

/* Rays [from, rays) of the scan prepared as the packets prepare them, kept
 * as the test's constants. */
static void rays_fill(uint32_t from, uint32_t rays, const float r[9], const float org[3], const float *dirs,
                      const raster_rays *rr)
{
    uint32_t at, i;
    for (at = from; at < rays; at += RC__RASTER_CHUNK) {
        uint32_t idx[RC__RASTER_CHUNK];
        rc__ray batch[RC__RASTER_CHUNK];
        const uint32_t n = rays - at < RC__RASTER_CHUNK ? rays - at : RC__RASTER_CHUNK;
        for (i = 0; i < n; ++i) idx[i] = at + i;
        rc__rays_prepare_turned(r, org, dirs, idx, n, batch);
        for (i = 0; i < n; ++i) {
            const rc__ray *ray = &batch[i];
            rr->sx[at + i] = ray->sx;
            rr->sy[at + i] = ray->sy;
            rr->sz[at + i] = ray->sz;
            rr->axes[at + i] = (unsigned char)(ray->kx | ray->ky << 2 | ray->kz << 4);
        }
    }
}

/* rc__tri_intersect_any_area for a ray from the origin the vertices were
 * taken relative to (ra = a - org ...: the same float values the test
 * computes), its operations in its order. Returns 1 with *t on a hit, 0 on
 * a miss, -1 where that test takes a double-precision case (a zero edge
 * function, a t tiny against the triangle's depth): the caller runs the test
 * itself there. */
static RC__FORCE_INLINE int shared_origin_test(const float *ra, const float *rb, const float *rc, unsigned axes,
                                               float sx, float sy, float sz, float *t)
{
    const unsigned kx = axes & 3u, ky = (axes >> 2) & 3u, kz = axes >> 4;
    const float az = ra[kz], bz = rb[kz], cz = rc[kz];
    const float Ax = ra[kx] - sx * az, Ay = ra[ky] - sy * az;
    const float Bx = rb[kx] - sx * bz, By = rb[ky] - sy * bz;
    const float Cx = rc[kx] - sx * cz, Cy = rc[ky] - sy * cz;
    const float CxBy = Cx * By, CyBx = Cy * Bx;
    const float AxCy = Ax * Cy, AyCx = Ay * Cx;
    const float BxAy = Bx * Ay, ByAx = By * Ax;
    const float U = CxBy - CyBx, V = AxCy - AyCx, W = BxAy - ByAx;
    float det, T, tt;
    {
        const float lo = U < V ? (U < W ? U : W) : (V < W ? V : W);
        const float hi = U > V ? (U > W ? U : W) : (V > W ? V : W);
        if (lo < 0.0f && hi > 0.0f) return 0;
    }
    if ((CxBy == CyBx) | (AxCy == AyCx) | (BxAy == ByAx)) return -1;
    det = U + V + W;
    if (det == 0.0f) return 0;
    T = U * (sz * az) + V * (sz * bz) + W * (sz * cz);
    tt = T / det;
    if (!(tt > 0.0f)) return 0;
    if (tt * 1024.0f < (sz < 0.0f ? -sz : sz) * ((az < 0.0f ? -az : az) + (bz < 0.0f ? -bz : bz) +
                                                (cz < 0.0f ? -cz : cz)))
        return -1;
    *t = tt;
    return 1;
}

/* A triangle as the scan sees it: its vertices, and the same relative to
 * the origin. */
typedef struct raster_tri {
    const float *v[3];
    float rel[3][3];
    uint32_t id; /* the scan's number for it: raster_scan.base + its leaf slot */
} raster_tri;

/* A pinhole grid's camera in the map frame: a point p (relative to the
 * origin) lies at depth d = F.p, and on the image plane at ox = A.p / d,
 * oy = B.p / d. The image's rays span [ox_lo, ox_hi] x [oy_lo, oy_hi], here
 * widened by the margin, far more than a ray's float direction strays from
 * its pixel's; side[k] . p >= 0 are the four sides of that widened view (the
 * frustum). */
typedef struct raster_cam {
    double F[3], A[3], B[3];
    double ox_lo, ox_hi, oy_lo, oy_hi;
    double margin;
    double side[4][3]; /* as (d, a, b) coefficients */
    double wside[4][3]; /* the same planes in the map frame */
} raster_cam;

/* What every test of one scan shares. */
typedef struct raster_scan {
    const rc__mesh *const *meshes; /* the scene's, in geometry order */
    uint32_t mesh_count;
    const rc__mesh *mesh;          /* the one being placed, meshes[g] */
    uint32_t base;                 /* its first id: the slots of meshes[0 .. g) */
    const rc__raster_grid *g;
    raster_rays rr;
    const float *r, *org, *dirs;
    double tmax;
    double theta_lo, theta_hi; /* the columns' azimuths' range */
    raster_cam cam;            /* pinhole grids */
} raster_scan;

/* The ray's full test, for the double-precision cases. */
RC__COLD int full_test(const raster_tri *tri, const raster_scan *sc, uint32_t ray, float *t)
{
    rc__ray full;
    float u, v;
    rc__rays_prepare_turned(sc->r, sc->org, sc->dirs, &ray, 1u, &full);
    return rc__tri_intersect_any_area(&full, tri->v[0], tri->v[1], tri->v[2], t, &u, &v);
}

/* A hit at t on ray i offered: kept when nearer than the ray's best, or as
 * near with a smaller key (rc__hit_offer_slot's rule without instances: the
 * smaller geometry id, then the smaller prim id). The meshes are placed in
 * geometry order, so a best from an earlier mesh keeps a tie. A ray with no
 * hit yet takes a hit at tmax itself. */
static RC__FORCE_INLINE void offer(const raster_tri *tri, const raster_scan *sc, uint32_t i, float t)
{
    const uint32_t best = sc->rr.bs[i];
    if (t > sc->rr.bt[i]) return;
    if (t == sc->rr.bt[i] && best != RC_INVALID_ID) {
        const uint32_t *refs = sc->mesh->bvh.refs;
        if (best < sc->base || !(refs[tri->id - sc->base] < refs[best - sc->base])) return;
    }
    sc->rr.bt[i] = t;
    sc->rr.bs[i] = tri->id;
}

/* The triangle's test of ray i, and its offer. */
static RC__FORCE_INLINE void test_ray(const raster_tri *tri, const raster_scan *sc, uint32_t i)
{
    float t;
    int got = shared_origin_test(tri->rel[0], tri->rel[1], tri->rel[2], sc->rr.axes[i], sc->rr.sx[i], sc->rr.sy[i],
                                 sc->rr.sz[i], &t);
    if (got < 0) got = full_test(tri, sc, i, &t);
    if (got) offer(tri, sc, i, t);
}

#if defined(__GNUC__) && (defined(__SSE2__) || defined(__aarch64__)) && !defined(RC__PACKET_FORCE_SCALAR)
/* Eight rays at a time in GCC's vector extension (SSE2, AVX2 or NEON; 32-bit
 * ARM's NEON flushes subnormals and keeps the scalar loop): the whole test
 * in lanes, the scalar test's operations in its order (test8); lanes with a
 * NaN or a double-precision case, and groups whose rays' axis orders
 * differ, run the scalar test. */
#define RC__RASTER_LANES 8u
typedef float rc__v8f __attribute__((vector_size(32)));
typedef int32_t rc__v8i __attribute__((vector_size(32)));
typedef unsigned char rc__v8b __attribute__((vector_size(8)));

/* (no vector arguments or returns: outside the AVX2 build those change the
 * calling convention, and gcc says so) */
#define splat8(x) ((rc__v8f){(x), (x), (x), (x), (x), (x), (x), (x)})
#define splat8i(x) ((rc__v8i){(x), (x), (x), (x), (x), (x), (x), (x)})

#define select8(m, a, b) ((rc__v8f)(((rc__v8i)(a) & (m)) | ((rc__v8i)(b) & ~(m))))
#define select8i(m, a, b) (((a) & (m)) | ((b) & ~(m)))

/* Bit k: lane k of m is set (all ones). */
static RC__FORCE_INLINE unsigned lanes_bits(const rc__v8i *mask)
{
#if defined(__SSE2__)
    __m128 h[2];
    memcpy(h, mask, sizeof h);
    return (unsigned)(_mm_movemask_ps(h[0]) | _mm_movemask_ps(h[1]) << 4);
#else
    const rc__v8i w = {1, 2, 4, 8, 16, 32, 64, 128};
    const rc__v8i m = *mask & w;
    int32_t b[8];
    memcpy(b, &m, sizeof b);
    return (unsigned)((b[0] | b[1]) | (b[2] | b[3]) | ((b[4] | b[5]) | (b[6] | b[7])));
#endif
}

/* The whole test for rays [i, i + 8), all with the axis order `axes`, in
 * lanes: the scalar test's operations in its order, so each lane's t is
 * its t; its hits nearer than the rays' best taken in lanes. Bits of *tie:
 * lanes it hits as near as their best (t in tt[]), for offer's tie rule; of
 * the return: lanes the scalar test must decide (a NaN, whose rejection the
 * lanes do not mirror; a zero edge function; a tiny t). */
static RC__FORCE_INLINE unsigned test8(const raster_tri *tri, const raster_scan *sc, uint32_t i, unsigned axes,
                                       unsigned *tie, float tt_out[8])
{
    const unsigned kx = axes & 3u, ky = (axes >> 2) & 3u, kz = axes >> 4;
    const float *ra = tri->rel[0], *rb = tri->rel[1], *rc = tri->rel[2];
    const rc__v8f az = splat8(ra[kz]), bz = splat8(rb[kz]), cz = splat8(rc[kz]), zero = splat8(0.0f);
    rc__v8f sx, sy, sz;
    memcpy(&sx, sc->rr.sx + i, sizeof sx);
    memcpy(&sy, sc->rr.sy + i, sizeof sy);
    memcpy(&sz, sc->rr.sz + i, sizeof sz);
    {
        const rc__v8f Ax = splat8(ra[kx]) - sx * az, Ay = splat8(ra[ky]) - sy * az;
        const rc__v8f Bx = splat8(rb[kx]) - sx * bz, By = splat8(rb[ky]) - sy * bz;
        const rc__v8f Cx = splat8(rc[kx]) - sx * cz, Cy = splat8(rc[ky]) - sy * cz;
        const rc__v8f CxBy = Cx * By, CyBx = Cy * Bx, AxCy = Ax * Cy, AyCx = Ay * Cx, BxAy = Bx * Ay, ByAx = By * Ax;
        const rc__v8f U = CxBy - CyBx, V = AxCy - AyCx, W = BxAy - ByAx;
        const rc__v8i neg = (U < zero) | (V < zero) | (W < zero);
        const rc__v8i pos = (U > zero) | (V > zero) | (W > zero);
        const rc__v8i ordered = (U == U) & (V == V) & (W == W);
        const rc__v8i live = ~(neg & pos) & ordered;
        const rc__v8i zero_edge = (CxBy == CyBx) | (AxCy == AyCx) | (BxAy == ByAx);
        const rc__v8f det = U + V + W;
        const rc__v8f T = U * (sz * az) + V * (sz * bz) + W * (sz * cz);
        const rc__v8f tt = T / det;
        const rc__v8i abs_bits = splat8i(0x7FFFFFFF);
        const rc__v8f asz = (rc__v8f)((rc__v8i)sz & abs_bits);
        const float depth = fabsf(ra[kz]) + fabsf(rb[kz]) + fabsf(rc[kz]);
        const rc__v8i ahead = live & ~zero_edge & (det != zero) & (tt > zero);
        const rc__v8i tiny = tt * splat8(1024.0f) < asz * splat8(depth);
        const rc__v8i hits = ahead & ~tiny, rare = ~ordered | (live & zero_edge) | (ahead & tiny);
        rc__v8f bt;
        rc__v8i bs, nearer, same;
        memcpy(&bt, sc->rr.bt + i, sizeof bt);
        memcpy(&bs, sc->rr.bs + i, sizeof bs);
        nearer = hits & (tt < bt);
        same = hits & (tt == bt);
        bt = select8(nearer, tt, bt);
        bs = select8i(nearer, splat8i((int32_t)tri->id), bs);
        memcpy(sc->rr.bt + i, &bt, sizeof bt);
        memcpy(sc->rr.bs + i, &bs, sizeof bs);
        memcpy(tt_out, &tt, sizeof tt);
        *tie = lanes_bits(&same);
        return lanes_bits(&rare);
    }
}

/* rays_fill for whole groups of eight rays in lanes: rc__ray_prepare's
 * values (the turn as rc__rot_apply_f, the dominant axis by the same
 * comparisons, the shear as divisions); returns the rays done. */
static RC__FORCE_INLINE uint32_t rays_fill8(uint32_t rays, const float r[9], const float *dirs,
                                            const raster_rays *rr)
{
    uint32_t at, k;
    for (at = 0; at + RC__RASTER_LANES <= rays; at += RC__RASTER_LANES) {
        float in[3][8];
        rc__v8f x, y, z, dx, dy, dz, ax, ay, az, m;
        rc__v8i is1, is2, neg, code;
        for (k = 0; k < RC__RASTER_LANES; ++k) {
            in[0][k] = dirs[(size_t)(at + k) * 3u];
            in[1][k] = dirs[(size_t)(at + k) * 3u + 1u];
            in[2][k] = dirs[(size_t)(at + k) * 3u + 2u];
        }
        memcpy(&x, in[0], sizeof x);
        memcpy(&y, in[1], sizeof y);
        memcpy(&z, in[2], sizeof z);
        dx = splat8(r[0]) * x + splat8(r[1]) * y + splat8(r[2]) * z;
        dy = splat8(r[3]) * x + splat8(r[4]) * y + splat8(r[5]) * z;
        dz = splat8(r[6]) * x + splat8(r[7]) * y + splat8(r[8]) * z;
        ax = (rc__v8f)((rc__v8i)dx & splat8i(0x7FFFFFFF));
        ay = (rc__v8f)((rc__v8i)dy & splat8i(0x7FFFFFFF));
        az = (rc__v8f)((rc__v8i)dz & splat8i(0x7FFFFFFF));
        is1 = ay > ax;
        m = select8(is1, ay, ax);
        is2 = az > m;
        {
            /* kz = 0: (kx, ky) = (y, z); 1: (z, x); 2: (x, y); swapped where
             * the kz component is negative */
            const rc__v8f dkz = select8(is2, dz, select8(is1, dy, dx));
            const rc__v8f dkx0 = select8(is2, dx, select8(is1, dz, dy));
            const rc__v8f dky0 = select8(is2, dy, select8(is1, dx, dz));
            rc__v8f sx, sy, sz;
            neg = dkz < splat8(0.0f);
            sx = select8(neg, dky0, dkx0) / dkz;
            sy = select8(neg, dkx0, dky0) / dkz;
            sz = splat8(1.0f) / dkz;
            memcpy(rr->sx + at, &sx, sizeof sx);
            memcpy(rr->sy + at, &sy, sizeof sy);
            memcpy(rr->sz + at, &sz, sizeof sz);
        }
        /* kx | ky << 2 | kz << 4 */
        code = select8i(is2, select8i(neg, splat8i(33), splat8i(36)),
                        select8i(is1, select8i(neg, splat8i(24), splat8i(18)), select8i(neg, splat8i(6), splat8i(9))));
        {
            /* the eight codes narrowed to bytes in lanes, stored at once */
            const rc__v8b bytes = __builtin_convertvector(code, rc__v8b);
            memcpy(rr->axes + at, &bytes, sizeof bytes);
        }
    }
    return at;
}

/* Rays [first, first + n): eight at a time where their axis orders agree. */
static RC__FORCE_INLINE void test_run(const raster_tri *tri, const raster_scan *sc, uint32_t first, uint32_t n)
{
    const uint32_t rays = sc->g->rows * sc->g->cols;
    const uint32_t whole = (n + RC__RASTER_LANES - 1u) / RC__RASTER_LANES * RC__RASTER_LANES;
    /* a run's last rays in a whole group of lanes: testing a ray the cone
     * does not cover costs nothing but the test */
    const uint32_t end = first + (first + whole <= rays ? whole : n);
    uint32_t i = first;
    for (; i + RC__RASTER_LANES <= end; i += RC__RASTER_LANES) {
        const unsigned char *ax = sc->rr.axes + i;
        uint64_t eight, same;
        memcpy(&eight, ax, sizeof eight);
        same = (uint64_t)ax[0] * 0x0101010101010101ull;
        if (eight == same) {
            float tt[8];
            unsigned tie, rare = test8(tri, sc, i, ax[0], &tie, tt);
            while (tie) {
                const unsigned k = (unsigned)__builtin_ctz(tie);
                tie &= tie - 1u;
                offer(tri, sc, i + k, tt[k]);
            }
            while (rare) {
                const unsigned k = (unsigned)__builtin_ctz(rare);
                rare &= rare - 1u;
                test_ray(tri, sc, i + k);
            }
        } else {
            uint32_t k;
            for (k = 0; k < RC__RASTER_LANES; ++k) test_ray(tri, sc, i + k);
        }
    }
    for (; i < end; ++i) test_ray(tri, sc, i);
}
#else
static RC__FORCE_INLINE void test_run(const raster_tri *tri, const raster_scan *sc, uint32_t first, uint32_t n)
{
    uint32_t i;
    for (i = first; i < first + n; ++i) test_ray(tri, sc, i);
}
#endif

/* The rays of rows [i0, i1] whose azimuths lie within [lo, hi] up to whole
 * turns (hi - lo < 2 pi), tested run by run: each turn's columns found once
 * for all the rows (the order of the offers changes nothing). */
static RC__FORCE_INLINE void test_rows(const raster_tri *tri, const raster_scan *sc, int64_t i0, int64_t i1, double lo,
                                       double hi)
{
    const rc__raster_grid *g = sc->g;
    const double turns = 1.0 / RC__TWO_PI; /* (slack covers the rounding, as in rc__cone_index_range) */
    const double k_first = ceil((sc->theta_lo - hi) * turns), k_last = floor((sc->theta_hi - lo) * turns);
    double k;
    for (k = k_first; k <= k_last; k += 1.0) {
        int64_t j0, j1, i;
        rc__cone_index_range(g->theta_min, g->theta_inc, g->theta_inv, g->cols, lo + k * RC__TWO_PI,
                             hi + k * RC__TWO_PI, &j0, &j1);
        if (j0 > j1) continue;
        for (i = i0; i <= i1; ++i) test_run(tri, sc, (uint32_t)i * g->cols + (uint32_t)j0, (uint32_t)(j1 - j0 + 1));
    }
}

/* Every ray of the scan. */
static void raster_rows_all(const raster_tri *tri, const raster_scan *sc)
{
    uint32_t i;
    for (i = 0; i < sc->g->rows; ++i) test_run(tri, sc, i * sc->g->cols, sc->g->cols);
}

#if !defined(RC__CONE_LANES)
/* The rays the triangle's bounding sphere's cone covers. */
static RC__FORCE_INLINE void raster_triangle(raster_tri *tri, const raster_scan *sc)
{
    const rc__raster_grid *g = sc->g;
    double m[3], r2 = 0.0, far2 = 0.0, tlo, thi;
    rc__cone c;
    int64_t i;
    int k, place;
    for (k = 0; k < 3; ++k) m[k] = ((double)tri->rel[0][k] + tri->rel[1][k] + tri->rel[2][k]) / 3.0;
    for (k = 0; k < 3; ++k) {
        const double dx = tri->rel[k][0] - m[0], dy = tri->rel[k][1] - m[1], dz = tri->rel[k][2] - m[2];
        const double e2 = dx * dx + dy * dy + dz * dz;
        const double f2 = (double)tri->rel[k][0] * tri->rel[k][0] + (double)tri->rel[k][1] * tri->rel[k][1] +
                          (double)tri->rel[k][2] * tri->rel[k][2];
        if (e2 > r2) r2 = e2;
        if (f2 > far2) far2 = f2;
    }
    place = rc__cone_place(g, sc->r, sc->tmax, m, sqrt(r2) * (1.0 + 1e-9), sqrt(far2), &c);
    if (place == RC__CONE_NONE) return;
    if (place == RC__CONE_AROUND) {
        raster_rows_all(tri, sc);
    } else if (c.lo <= -RC__HALF_PI || c.hi >= RC__HALF_PI || !rc__cone_azimuths(&c, sc->r, &tri->rel[0][0], &tlo, &thi)) {
        /* a pole in the cone: whole rows */
        for (i = c.i0; i <= c.i1; ++i) test_run(tri, sc, (uint32_t)i * g->cols, g->cols);
    } else {
        test_rows(tri, sc, c.i0, c.i1, tlo, thi);
    }
}

#endif

#if defined(RC__CONE_LANES)
/* n (1..4) triangles placed at once in lanes (scan_cone.h), then each
 * through the rays it covers, as raster_triangle does one. */
static RC__FORCE_INLINE void raster_four(raster_tri *tris, int n, const raster_scan *sc)
{
    const rc__raster_grid *g = sc->g;
    const float *r = sc->r;
    const rc__v4d zero = rc__v4d_splat(0.0), two_pi = rc__v4d_splat(RC__TWO_PI);
    double in[3][3][4], lo_out[4], hi_out[4], tlo_out[4], thi_out[4];
    int64_t skip_out[4], around_out[4], az_out[4];
    rc__v4d v[3][3], m[3], u[3], r2 = zero, far2 = zero, rad, far, d, rho, slack, q, alpha, phi, lo, hi;
    rc__v4d th[3], el[3], xs, ys, zs, t0, t1, t2, lo3, g0, g1, g2, steep, saz, azlo, azhi, bulge;
    rc__v4l skip, around, w0, w1, az_ok, clear;
    int c, j, k;
    for (c = 0; c < 3; ++c)
        for (j = 0; j < 3; ++j) {
            for (k = 0; k < 4; ++k) in[c][j][k] = tris[k < n ? k : 0].rel[c][j];
            memcpy(&v[c][j], in[c][j], sizeof v[c][j]);
        }
    for (j = 0; j < 3; ++j) m[j] = (v[0][j] + v[1][j] + v[2][j]) / 3.0;
    for (c = 0; c < 3; ++c) {
        const rc__v4d dx = v[c][0] - m[0], dy = v[c][1] - m[1], dz = v[c][2] - m[2];
        const rc__v4d e2 = dx * dx + dy * dy + dz * dz;
        const rc__v4d f2 = v[c][0] * v[c][0] + v[c][1] * v[c][1] + v[c][2] * v[c][2];
        r2 = rc__v4d_max(e2, r2);
        far2 = rc__v4d_max(f2, far2);
    }
    for (j = 0; j < 3; ++j) u[j] = (double)r[j] * m[0] + (double)r[3 + j] * m[1] + (double)r[6 + j] * m[2];
    rad = r2;
    far = far2;
    d = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    rho = u[0] * u[0] + u[1] * u[1];
    rc__v4d_sqrt(&rad);
    rc__v4d_sqrt(&far);
    rc__v4d_sqrt(&d);
    rc__v4d_sqrt(&rho);
    rad *= 1.0 + 1e-9;
    q = rc__v4d_max(d * d - rad * rad, zero);
    rc__v4d_sqrt(&q);
    skip = (d - rad) * (1.0 - 1e-5) > rc__v4d_splat(sc->tmax);
    around = d <= rad * (1.0 + 1e-6);
    slack = RC__CONE_SLACK + RC__CONE_SPREAD_SLACK * far / rc__v4d_select(around, rc__v4d_splat(1.0), d - rad) +
            RC__CONE_ATAN_ERROR;
    rc__cone_atan2_4(&rad, &q, &alpha);
    alpha += slack;
    rc__cone_atan2_4(&u[2], &rho, &phi);
    lo = phi - alpha;
    hi = phi + alpha;
    /* the corners' azimuths and elevations */
    for (c = 0; c < 3; ++c) {
        rc__v4d rc;
        xs = (double)r[0] * v[c][0] + (double)r[3] * v[c][1] + (double)r[6] * v[c][2];
        ys = (double)r[1] * v[c][0] + (double)r[4] * v[c][1] + (double)r[7] * v[c][2];
        zs = (double)r[2] * v[c][0] + (double)r[5] * v[c][1] + (double)r[8] * v[c][2];
        rc__cone_atan2_4(&ys, &xs, &th[c]);
        rc = xs * xs + ys * ys;
        rc__v4d_sqrt(&rc);
        rc__cone_atan2_4(&zs, &rc, &el[c]);
    }
    /* the rows: where the cone clears the poles, those the triangle's
     * corners' elevations reach, widened by the slack and by how far an
     * edge can bulge beyond its ends (on a great circle |e''| <= tan |e|,
     * tan |e| <= 1 / (pi/2 - steep) in the cone, and an edge spans at most
     * 2 alpha: a bulge of at most tan(steep) (2 alpha)^2 / 8). The cone's
     * rows were half as many again as these on the 10k sphere. */
    steep = rc__v4d_max(hi, -lo);
    bulge = alpha * alpha * 0.5 / (RC__HALF_PI - steep) + slack;
    t0 = rc__v4d_min(rc__v4d_min(el[0], el[1]), el[2]) - bulge;
    t2 = rc__v4d_max(rc__v4d_max(el[0], el[1]), el[2]) + bulge;
    clear = (hi < RC__HALF_PI) & (lo > -RC__HALF_PI);
    lo = rc__v4d_select(clear & (t0 > lo), t0, lo);
    hi = rc__v4d_select(clear & (t2 < hi), t2, hi);
    /* the corners' azimuths, sorted; the arc is the complement of the widest gap */
    t0 = rc__v4d_min(th[0], th[1]);
    t2 = rc__v4d_max(th[0], th[1]);
    lo3 = rc__v4d_min(t2, th[2]);
    t2 = rc__v4d_max(t2, th[2]);
    t1 = rc__v4d_max(t0, lo3);
    t0 = rc__v4d_min(t0, lo3);
    g2 = t0 + two_pi - t2;
    g0 = t1 - t0;
    g1 = t2 - t1;
    w0 = g0 > g2;
    w1 = g1 > rc__v4d_select(w0, g0, g2);
    saz = slack * RC__HALF_PI / (RC__HALF_PI - steep);
    azlo = rc__v4d_select(w1, t2, rc__v4d_select(w0, t1, t0)) - saz;
    azhi = rc__v4d_select(w1, t1 + two_pi, rc__v4d_select(w0, t0 + two_pi, t2)) + saz;
    az_ok = (azhi - azlo < two_pi) & (saz < 0.5) & (lo > -RC__HALF_PI) & (hi < RC__HALF_PI);
    memcpy(lo_out, &lo, sizeof lo_out);
    memcpy(hi_out, &hi, sizeof hi_out);
    memcpy(tlo_out, &azlo, sizeof tlo_out);
    memcpy(thi_out, &azhi, sizeof thi_out);
    memcpy(skip_out, &skip, sizeof skip_out);
    memcpy(around_out, &around, sizeof around_out);
    memcpy(az_out, &az_ok, sizeof az_out);
    for (k = 0; k < n; ++k) {
        int64_t i0, i1, i;
        if (skip_out[k]) continue;
        if (around_out[k]) {
            raster_rows_all(&tris[k], sc);
            continue;
        }
        rc__cone_rows(g, lo_out[k], hi_out[k], &i0, &i1);
        if (i0 > i1) continue;
        if (!az_out[k]) {
            /* a pole in the cone: whole rows */
            for (i = i0; i <= i1; ++i) test_run(&tris[k], sc, (uint32_t)i * g->cols, g->cols);
        } else {
            test_rows(&tris[k], sc, i0, i1, tlo_out[k], thi_out[k]);
        }
    }
}
#endif

/* The part of polygon in (n corners, (d, a, b) each) on the side k . x >= 0
 * of a plane through the origin, into out (n + 1 corners at most). */
static int clip_side(const double in[][3], int n, const double k[3], double out[][3])
{
    int i, m = 0;
    for (i = 0; i < n; ++i) {
        const double *p = in[i], *q = in[i + 1 < n ? i + 1 : 0];
        const double fp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
        const double fq = k[0] * q[0] + k[1] * q[1] + k[2] * q[2];
        if (fp >= 0.0) {
            memcpy(out[m], p, sizeof out[m]);
            ++m;
        }
        if ((fp >= 0.0) != (fq >= 0.0)) {
            const double f = fp / (fp - fq);
            int c;
            for (c = 0; c < 3; ++c) out[m][c] = p[c] + f * (q[c] - p[c]);
            ++m;
        }
    }
    return m;
}

/* First and last index k in [0, count) with lo <= (k - c) / f <= hi (the
 * image's columns or rows as ox or oy; f > 0), empty (k0 > k1) when none:
 * widened by a millionth of a pixel and of the coordinate for the rounding
 * of the products. */
static void pixel_range(double lo, double hi, double c, double f, uint32_t count, int64_t *k0, int64_t *k1)
{
    double a = c + f * lo, b = c + f * hi;
    a -= 1e-6 * (1.0 + fabs(a));
    b += 1e-6 * (1.0 + fabs(b));
    if (!(a <= b) || b < 0.0 || a > (double)count - 1.0) {
        *k0 = 1;
        *k1 = 0;
        return;
    }
    a = ceil(a);
    b = floor(b);
    *k0 = a < 0.0 ? 0 : (int64_t)a;
    *k1 = b > (double)count - 1.0 ? (int64_t)count - 1 : (int64_t)b;
}

/* Columns a triangle spans (in groups of lanes, twice over) before its
 * columns are found row by row */
#define RC__RASTER_SPAN_COLUMNS 8

/* The pixels a triangle can cover: its corners in the camera's (d, a, b),
 * clipped to the widened frustum, projected; their bounds, clamped to the
 * view (the clipped corners lie in it, up to rounding), are the rows and
 * columns tested. A corner at the frustum's apex (d = 0: the triangle
 * passes through the sensor) has no projection: then every ray. */
static RC__FORCE_INLINE void raster_pinhole(const raster_tri *tri, const raster_scan *sc)
{
    const raster_cam *cam = &sc->cam;
    const rc__raster_grid *g = sc->g;
    double poly[2][8][3], px[8], py[8], olo = INFINITY, ohi = -INFINITY, vlo = INFINITY, vhi = -INFINITY;
    int n = 3, k, c, cur = 0, projected = 1;
    int64_t i0, i1, j0, j1, i;
    for (c = 0; c < 3; ++c) {
        const double x = tri->rel[c][0], y = tri->rel[c][1], z = tri->rel[c][2];
        poly[0][c][0] = cam->F[0] * x + cam->F[1] * y + cam->F[2] * z;
        poly[0][c][1] = cam->A[0] * x + cam->A[1] * y + cam->A[2] * z;
        poly[0][c][2] = cam->B[0] * x + cam->B[1] * y + cam->B[2] * z;
    }
    for (k = 0; k < 4 && n > 0; ++k) {
        n = clip_side((const double(*)[3])poly[cur], n, cam->side[k], poly[cur ^ 1]);
        cur ^= 1;
    }
    if (n == 0) return;
    for (c = 0; c < n; ++c) {
        const double d = poly[cur][c][0];
        double ox, oy;
        if (!(d > 0.0)) {
            olo = vlo = -INFINITY;
            ohi = vhi = INFINITY;
            projected = 0;
            break;
        }
        ox = px[c] = poly[cur][c][1] / d;
        oy = py[c] = poly[cur][c][2] / d;
        if (!(ox == ox) || !(oy == oy)) { /* (inf / inf from a corner far out) */
            olo = vlo = -INFINITY;
            ohi = vhi = INFINITY;
            projected = 0;
            break;
        }
        olo = ox < olo ? ox : olo;
        ohi = ox > ohi ? ox : ohi;
        vlo = oy < vlo ? oy : vlo;
        vhi = oy > vhi ? oy : vhi;
    }
    /* a ray strays from its pixel's direction by less than the margin:
     * the pixels of the bounds widened by it */
    olo = olo - cam->margin > cam->ox_lo ? olo - cam->margin : cam->ox_lo;
    ohi = ohi + cam->margin < cam->ox_hi ? ohi + cam->margin : cam->ox_hi;
    vlo = vlo - cam->margin > cam->oy_lo ? vlo - cam->margin : cam->oy_lo;
    vhi = vhi + cam->margin < cam->oy_hi ? vhi + cam->margin : cam->oy_hi;
    pixel_range(olo, ohi, g->cx, g->fx, g->cols, &j0, &j1);
    pixel_range(vlo, vhi, g->cy, g->fy, g->rows, &i0, &i1);
    if (j0 > j1) return;
    if (!projected || i0 == i1 || j1 - j0 < 2 * RC__RASTER_SPAN_COLUMNS) {
        for (i = i0; i <= i1; ++i) test_run(tri, sc, (uint32_t)i * g->cols + (uint32_t)j0, (uint32_t)(j1 - j0 + 1));
        return;
    }
    /* a large triangle: row by row, the columns the polygon reaches within
     * the margin of the row's oy (a convex polygon's extent there lies at
     * its edges' points in that band) */
    for (i = i0; i <= i1; ++i) {
        const double oy = ((double)i - g->cy) / g->fy, ylo = oy - cam->margin, yhi = oy + cam->margin;
        double a = INFINITY, b = -INFINITY;
        int64_t r0 = j0, r1 = j1;
        int odd = 0;
        for (c = 0; c < n; ++c) {
            const int e = c + 1 < n ? c + 1 : 0;
            const double lo = py[c] < py[e] ? py[c] : py[e], hi = py[c] < py[e] ? py[e] : py[c];
            double xa, xb;
            if (hi < ylo || lo > yhi) continue;
            if (py[e] == py[c]) {
                xa = px[c];
                xb = px[e];
            } else {
                const double slope = (px[e] - px[c]) / (py[e] - py[c]);
                xa = px[c] + ((lo > ylo ? lo : ylo) - py[c]) * slope;
                xb = px[c] + ((hi < yhi ? hi : yhi) - py[c]) * slope;
            }
            odd |= !(xa == xa) || !(xb == xb);
            a = xa < a ? xa : a;
            a = xb < a ? xb : a;
            b = xa > b ? xa : b;
            b = xb > b ? xb : b;
        }
        /* a NaN (which corners in the view should not give) keeps the box's columns */
        if (!odd) {
            if (!(a <= b)) continue;
            a = a - cam->margin > cam->ox_lo ? a - cam->margin : cam->ox_lo;
            b = b + cam->margin < cam->ox_hi ? b + cam->margin : cam->ox_hi;
            pixel_range(a, b, g->cx, g->fx, g->cols, &r0, &r1);
        }
        if (r0 <= r1) test_run(tri, sc, (uint32_t)i * g->cols + (uint32_t)r0, (uint32_t)(r1 - r0 + 1));
    }
}

/* 1 when some point of a box (centre m relative to the origin, half
 * extents h) may lie in the camera's widened view and within tmax of the
 * origin. */
static RC__FORCE_INLINE int pinhole_box_visible(const raster_scan *sc, const double m[3], const double h[3])
{
    const double h2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2], m2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    int p;
    /* the box's nearest point is no nearer than its bounding sphere's */
    if (sqrt(m2) - sqrt(h2) > sc->tmax * (1.0 + 1e-6)) return 0;
    for (p = 0; p < 4; ++p) {
        const double *w = sc->cam.wside[p];
        const double reach = fabs(w[0]) * h[0] + fabs(w[1]) * h[1] + fabs(w[2]) * h[2];
        if (w[0] * m[0] + w[1] * m[1] + w[2] * m[2] + reach < 0.0) return 0;
    }
    return 1;
}

/* Triangles [first, first + count) of the leaf order. */
static RC__FORCE_INLINE void raster_slots(const raster_scan *sc, uint32_t first, uint32_t count)
{
    const rc__mesh *mesh = sc->mesh;
    const float *verts = mesh->vertices;
    const size_t stride = mesh->stride;
    raster_tri tris[4];
    int n = 0;
    uint32_t s;
    for (s = first; s < first + count; ++s) {
        const uint32_t *ix = mesh->leaf_tris + (size_t)s * 3u;
        raster_tri *tri = &tris[n];
        int k, c;
        /* a folded flat (a, a, a), or any such triple: never hit */
        if (ix[0] == ix[1] && ix[1] == ix[2]) continue;
        for (c = 0; c < 3; ++c) {
            tri->v[c] = verts + (size_t)ix[c] * stride;
            for (k = 0; k < 3; ++k) tri->rel[c][k] = tri->v[c][k] - sc->org[k];
        }
        tri->id = sc->base + s;
        /* zero area: never hit (the tests skip what a commit folded) */
        if (!mesh->flats_folded && rc__tri_zero_area(tri->v[0], tri->v[1], tri->v[2])) continue;
        if (sc->g->pinhole) {
            raster_pinhole(tri, sc);
            continue;
        }
#if defined(RC__CONE_LANES)
        if (++n == 4) {
            raster_four(tris, n, sc);
            n = 0;
        }
#else
        raster_triangle(tri, sc);
#endif
    }
#if defined(RC__CONE_LANES)
    if (n) raster_four(tris, n, sc);
#endif
}

/* The mesh's 4-wide tree from the root, leaves in it placed triangle by
 * triangle: a child box whose bounding sphere's cone meets no row (a
 * spinning LiDAR's rows see a band of elevations), or lies wholly beyond
 * the range, is passed over with everything in it. */
static RC__FORCE_INLINE void raster_tree(const raster_scan *sc)
{
    const rc__wnode *nodes = sc->mesh->wide;
    uint32_t stack[3u * RC__BVH_MAX_DEPTH + 4u], sp = 0, node = 0;
    for (;;) {
        const rc__wnode *n = &nodes[node];
        int c;
        for (c = 0; c < 4; ++c) {
            double m[3], h[3];
            int k;
            if (n->child[c] == RC__WIDE_EMPTY) continue;
            for (k = 0; k < 3; ++k) {
                const double lo = n->box[2 * k][c], hi = n->box[2 * k + 1][c];
                m[k] = 0.5 * (lo + hi) - sc->org[k];
                h[k] = 0.5 * (hi - lo);
            }
            if (sc->g->pinhole) {
                if (!pinhole_box_visible(sc, m, h)) continue;
            } else {
                const double rad = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]) * (1.0 + 1e-9);
                rc__cone cone;
                if (rc__cone_place(sc->g, sc->r, sc->tmax, m, rad,
                                   sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) + rad, &cone) == RC__CONE_NONE)
                    continue;
            }
            if (n->count[c])
                raster_slots(sc, n->child[c], n->count[c]);
            else /* at most 3 a level stay: the bound holds (wide depth <= the binary tree's) */
                stack[sp++] = n->child[c];
        }
        if (sp == 0) break;
        node = stack[--sp];
    }
}

/* The scan's rays, then each mesh's triangles through them, in geometry
 * order: by its tree where it has one (the built-in backend's commit builds
 * it), else all. */
static RC__FORCE_INLINE void raster_all(raster_scan *sc)
{
    const uint32_t rays = sc->g->rows * sc->g->cols;
    uint32_t g, base = 0;
#if defined(RC__RASTER_LANES)
    rays_fill(rays_fill8(rays, sc->r, sc->dirs, &sc->rr), rays, sc->r, sc->org, sc->dirs, &sc->rr);
#else
    rays_fill(0u, rays, sc->r, sc->org, sc->dirs, &sc->rr);
#endif
    for (g = 0; g < sc->mesh_count; ++g) {
        const rc__mesh *mesh = sc->meshes[g];
        sc->mesh = mesh;
        sc->base = base;
        base += mesh->bvh.item_count;
        if (mesh->bvh.item_count == 0) continue;
        if (mesh->wide && mesh->wide_count)
            raster_tree(sc);
        else
            raster_slots(sc, 0u, mesh->bvh.item_count);
    }
}

#if defined(RC__LEAF4_PAIR_AVX2) && defined(RC__RASTER_LANES)
/* The same in AVX2's 256-bit lanes (no fused multiply-add: the same bits). */
static __attribute__((target("avx2"), noinline)) void raster_all_avx2(raster_scan *sc) { raster_all(sc); }
#endif
static void raster_all_base(raster_scan *sc) { raster_all(sc); }

/* The plane of the triangle with corners v as rc__scene_hit_distance_d
 * computes it (a mesh of the scene's own: no instance transform), from the
 * origin od: normal n, offset *w. */
static void plane(const float *const v[3], const double od[3], double n[3], double *w)
{
    const double ax = v[0][0], ay = v[0][1], az = v[0][2];
    const double e1x = v[1][0] - ax, e1y = v[1][1] - ay, e1z = v[1][2] - az;
    const double e2x = v[2][0] - ax, e2y = v[2][1] - ay, e2z = v[2][2] - az;
    n[0] = e1y * e2z - e1z * e2y;
    n[1] = e1z * e2x - e1x * e2z;
    n[2] = e1x * e2y - e1y * e2x;
    *w = n[0] * (ax - od[0]) + n[1] * (ay - od[1]) + n[2] * (az - od[2]);
}

/* The camera of a pinhole grid turned by r (raster_cam). The margin is
 * 1e-5 (1 + ox^2 + oy^2) at the view's widest, where the rays' float
 * directions (their unit vectors, the turn) stray from the pixels' by about
 * 1e-7 as much (on a long lens, fx 2000, a hundredth of a pixel). */
static void camera_setup(const rc__raster_grid *g, const float r[9], raster_cam *cam)
{
    const int f = g->optical ? 2 : 0, a = g->optical ? 0 : 1, b = g->optical ? 1 : 2;
    const double sa = g->optical ? 1.0 : -1.0; /* body frame: (1, -ox, -oy) */
    double mx, my, m;
    int k;
    for (k = 0; k < 3; ++k) {
        cam->F[k] = (double)r[3 * k + f];
        cam->A[k] = sa * (double)r[3 * k + a];
        cam->B[k] = sa * (double)r[3 * k + b];
    }
    cam->ox_lo = -g->cx / g->fx;
    cam->ox_hi = ((double)g->cols - 1.0 - g->cx) / g->fx;
    cam->oy_lo = -g->cy / g->fy;
    cam->oy_hi = ((double)g->rows - 1.0 - g->cy) / g->fy;
    mx = fabs(cam->ox_lo) > fabs(cam->ox_hi) ? fabs(cam->ox_lo) : fabs(cam->ox_hi);
    my = fabs(cam->oy_lo) > fabs(cam->oy_hi) ? fabs(cam->oy_lo) : fabs(cam->oy_hi);
    m = 1e-5 * (1.0 + mx * mx + my * my);
    cam->margin = m;
    cam->ox_lo -= m;
    cam->ox_hi += m;
    cam->oy_lo -= m;
    cam->oy_hi += m;
    cam->side[0][0] = -cam->ox_lo, cam->side[0][1] = 1.0, cam->side[0][2] = 0.0;
    cam->side[1][0] = cam->ox_hi, cam->side[1][1] = -1.0, cam->side[1][2] = 0.0;
    cam->side[2][0] = -cam->oy_lo, cam->side[2][1] = 0.0, cam->side[2][2] = 1.0;
    cam->side[3][0] = cam->oy_hi, cam->side[3][1] = 0.0, cam->side[3][2] = -1.0;
    for (k = 0; k < 4; ++k) {
        int j;
        for (j = 0; j < 3; ++j)
            cam->wside[k][j] = cam->side[k][0] * cam->F[j] + cam->side[k][1] * cam->A[j] + cam->side[k][2] * cam->B[j];
    }
}

void rc__raster_scan(const rc__mesh *const *meshes, uint32_t mesh_count, const rc__raster_grid *g,
                     const rc__xformf *world, const float *dirs, float tmax, void *scratch)
{
    const uint32_t rays = g->rows * g->cols;
    rc__raster_grid grid = *g;
    raster_scan sc;
    uint32_t i;
    grid.phi_inv = g->phi_inc != 0.0 ? 1.0 / g->phi_inc : 0.0;
    grid.theta_inv = g->theta_inc != 0.0 ? 1.0 / g->theta_inc : 0.0;
    sc.meshes = meshes;
    sc.mesh_count = mesh_count;
    sc.mesh = NULL;
    sc.base = 0;
    sc.g = &grid;
    scratch_split(scratch, rays, &sc.rr);
    sc.r = world->r;
    sc.org = world->t;
    sc.dirs = dirs;
    sc.tmax = (double)tmax;
    {
        const double last = g->theta_min + (double)(g->cols - 1u) * g->theta_inc;
        sc.theta_lo = last < g->theta_min ? last : g->theta_min;
        sc.theta_hi = last < g->theta_min ? g->theta_min : last;
    }
    if (g->pinhole) camera_setup(g, world->r, &sc.cam);
    for (i = 0; i < rays; ++i) {
        sc.rr.bt[i] = tmax;
        sc.rr.bs[i] = RC_INVALID_ID;
    }
#if defined(RC__LEAF4_PAIR_AVX2) && defined(RC__RASTER_LANES)
    if (rc__leaf4_have_avx2())
        raster_all_avx2(&sc);
    else
#endif
        raster_all_base(&sc);
}

/* The hits of rays [first, first + n), and their distances refined: the
 * plane is kept while neighbouring rays share their triangle, and four rays
 * on one triangle are refined at once in lanes of doubles where there are
 * any (the division a ray was half the time of the scalar loop, its latency
 * in the way of every result). Each lane repeats the scalar refinement's
 * operations in their order. */
/* Which mesh a triangle id (raster_tri.id) belongs to: *g and the id range
 * [*lo, *hi) of meshes[*g], moved only when id lies outside it (a run's
 * neighbouring rays mostly meet one mesh). */
static RC__FORCE_INLINE void mesh_of_id(const rc__mesh *const *meshes, uint32_t mesh_count, uint32_t id, uint32_t *g,
                                        uint32_t *lo, uint32_t *hi)
{
    if (id >= *lo && id < *hi) return;
    *g = 0;
    *lo = 0;
    *hi = meshes[0]->bvh.item_count;
    while (id >= *hi && *g + 1u < mesh_count) {
        *lo = *hi;
        *hi += meshes[++*g]->bvh.item_count;
    }
}

static RC__FORCE_INLINE void hits_run(const rc__mesh *const *meshes, uint32_t mesh_count, const rc__xformf *world,
                                      const float *dirs, const raster_rays *rr, uint32_t first, uint32_t n,
                                      rc__hit *hits, int *found, double *td)
{
    const double *r = world->rd;
    const uint32_t *bs = rr->bs + first;
    const float *bt = rr->bt + first, *p = dirs + (size_t)first * 3u;
    uint32_t i, last = RC_INVALID_ID, g = 0, lo = 0, hi = 0;
    double nv[3] = {0.0, 0.0, 0.0}, w = 0.0;
    for (i = 0; i < n; ++i) {
        const uint32_t id = bs[i];
        hits[i].t = bt[i];
        hits[i].geom = hits[i].prim = hits[i].inst = hits[i].slot = RC_INVALID_ID;
        found[i] = id != RC_INVALID_ID;
        if (id == RC_INVALID_ID) continue;
        mesh_of_id(meshes, mesh_count, id, &g, &lo, &hi);
        hits[i].prim = meshes[g]->bvh.refs[id - lo];
        hits[i].geom = g;
        hits[i].slot = id - lo;
    }
    for (i = 0; i < n;) {
        const uint32_t id = bs[i];
        if (id == RC_INVALID_ID) {
            ++i;
            continue;
        }
        if (id != last) {
            const rc__mesh *mesh = meshes[hits[i].geom];
            const uint32_t *ix = mesh->leaf_tris + (size_t)hits[i].slot * 3u;
            const float *v[3];
            int c;
            for (c = 0; c < 3; ++c) v[c] = mesh->vertices + (size_t)ix[c] * mesh->stride;
            plane(v, world->td, nv, &w);
            last = id;
        }
#if defined(RC__CONE_LANES)
        if (i + 4u <= n && bs[i + 1u] == id && bs[i + 2u] == id && bs[i + 3u] == id) {
            const float *d = p + (size_t)i * 3u;
            const rc__v4d x = {d[0], d[3], d[6], d[9]}, y = {d[1], d[4], d[7], d[10]}, z = {d[2], d[5], d[8], d[11]};
            const rc__v4d dx = r[0] * x + r[1] * y + r[2] * z;
            const rc__v4d dy = r[3] * x + r[4] * y + r[5] * z;
            const rc__v4d dz = r[6] * x + r[7] * y + r[8] * z;
            const rc__v4d dn = nv[0] * dx + nv[1] * dy + nv[2] * dz;
            const rc__v4d t = {bt[i], bt[i + 1u], bt[i + 2u], bt[i + 3u]};
            rc__v4d q = w / dn;
            /* dn == 0 gives an infinite or NaN q: then the float t, as below */
            q = rc__v4d_select(q - q == rc__v4d_splat(0.0), q, t);
            memcpy(td + i, &q, sizeof q);
            i += 4u;
            continue;
        }
#endif
        {
            const float *d = p + (size_t)i * 3u;
            const double dx = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
            const double dy = r[3] * d[0] + r[4] * d[1] + r[5] * d[2];
            const double dz = r[6] * d[0] + r[7] * d[1] + r[8] * d[2];
            const double dn = nv[0] * dx + nv[1] * dy + nv[2] * dz, q = w / dn;
            td[i] = dn == 0.0 || !isfinite(q) ? (double)bt[i] : q;
            ++i;
        }
    }
}

#if defined(RC__LEAF4_PAIR_AVX2) && defined(RC__CONE_LANES)
static __attribute__((target("avx2"), noinline)) void hits_run_avx2(const rc__mesh *const *meshes,
                                                                  uint32_t mesh_count, const rc__xformf *world,
                                                                  const float *dirs, const raster_rays *rr,
                                                                  uint32_t first, uint32_t n, rc__hit *hits,
                                                                  int *found, double *td)
{
    hits_run(meshes, mesh_count, world, dirs, rr, first, n, hits, found, td);
}
#endif

void rc__raster_hits(const rc__mesh *const *meshes, uint32_t mesh_count, uint32_t rays, const rc__xformf *world,
                     const float *dirs, void *scratch, uint32_t first, uint32_t n, rc__hit *hits, int *found,
                     double *td)
{
    raster_rays rr;
    scratch_split(scratch, rays, &rr);
#if defined(RC__LEAF4_PAIR_AVX2) && defined(RC__CONE_LANES)
    if (rc__leaf4_have_avx2()) {
        hits_run_avx2(meshes, mesh_count, world, dirs, &rr, first, n, hits, found, td);
        return;
    }
#endif
    hits_run(meshes, mesh_count, world, dirs, &rr, first, n, hits, found, td);
}

float rc__raster_longest_edge(const rc__mesh *mesh)
{
    double longest2 = 0.0;
    uint32_t t, c, k;
    if (!mesh->leaf_tris) return 0.0f;
    for (t = 0; t < mesh->bvh.item_count; ++t) {
        const float *v[3];
        for (c = 0; c < 3; ++c) v[c] = mesh->vertices + (size_t)mesh->leaf_tris[3u * t + c] * mesh->stride;
        for (c = 0; c < 3; ++c) {
            const float *a = v[c], *b = v[(c + 1u) % 3u];
            double e2 = 0.0;
            for (k = 0; k < 3; ++k) {
                const double d = (double)a[k] - (double)b[k];
                e2 += d * d;
            }
            longest2 = e2 > longest2 ? e2 : longest2;
        }
    }
    return (float)sqrt(longest2);
}
#else
typedef int rc__scan_raster_left_out; /* ISO C: no empty translation unit */
#endif
