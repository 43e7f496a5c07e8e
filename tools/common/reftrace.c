/* rcutil: float64 reference ray caster (see reftrace.h). Median-split BVH in
 * double, Woop's watertight ray/triangle test in double. Plain and slow on
 * purpose where speed would cost clarity; still fast enough for a few million
 * rays on a million triangles. */
#include "reftrace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RT_LEAF_SIZE 4u
#define RT_STACK 128

typedef struct rt_node {
    double lo[3], hi[3];
    uint32_t first; /* leaf: first index into prims; inner: right child */
    uint32_t count; /* leaf: triangles (> 0); inner: 0 (left child is this + 1) */
} rt_node;

struct rcu_reftrace {
    double *v;          /* 9 per triangle: a, b, c */
    uint8_t *degenerate;
    uint32_t tri_count;
    uint32_t *prims;    /* non-degenerate triangles in BVH order */
    uint32_t prim_count;
    rt_node *nodes;
    uint32_t node_count, node_cap;
    double *centroid;   /* build only */
};

static int tri_zero_area(const double *a, const double *b, const double *c)
{
    const double e1x = b[0] - a[0], e1y = b[1] - a[1], e1z = b[2] - a[2];
    const double e2x = c[0] - a[0], e2y = c[1] - a[1], e2z = c[2] - a[2];
    return e1y * e2z - e1z * e2y == 0.0 && e1z * e2x - e1x * e2z == 0.0 && e1x * e2y - e1y * e2x == 0.0;
}

static void swap_u32(uint32_t *a, uint32_t *b)
{
    uint32_t t = *a;
    *a = *b;
    *b = t;
}

/* Reorders p[0..n) so p[k] has the k-th smallest centroid on axis (quickselect). */
static void select_centroid(const double *cen, uint32_t *p, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        double pivot = cen[3u * p[lo + (hi - lo) / 2] + (uint32_t)axis];
        uint32_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            double c = cen[3u * p[i] + (uint32_t)axis];
            if (c < pivot) swap_u32(&p[lt++], &p[i++]);
            else if (c > pivot) swap_u32(&p[i], &p[--gt]);
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return;
    }
}

static int push_node(rcu_reftrace *rt, uint32_t *index)
{
    if (rt->node_count == rt->node_cap) {
        uint32_t cap = rt->node_cap ? rt->node_cap * 2u : 1024u;
        rt_node *n = (rt_node *)realloc(rt->nodes, (size_t)cap * sizeof *n);
        if (!n) return -1;
        rt->nodes = n;
        rt->node_cap = cap;
    }
    *index = rt->node_count++;
    return 0;
}

static int build_node(rcu_reftrace *rt, uint32_t first, uint32_t count, int depth)
{
    uint32_t ni, i, half;
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int k, axis = 0;
    if (push_node(rt, &ni) != 0) return -1;
    for (i = first; i < first + count; i++) {
        const double *v = rt->v + 9u * (size_t)rt->prims[i];
        const double *c = rt->centroid + 3u * (size_t)rt->prims[i];
        int j;
        for (k = 0; k < 3; k++) {
            for (j = 0; j < 3; j++) {
                if (v[3 * j + k] < lo[k]) lo[k] = v[3 * j + k];
                if (v[3 * j + k] > hi[k]) hi[k] = v[3 * j + k];
            }
            if (c[k] < clo[k]) clo[k] = c[k];
            if (c[k] > chi[k]) chi[k] = c[k];
        }
    }
    memcpy(rt->nodes[ni].lo, lo, sizeof lo);
    memcpy(rt->nodes[ni].hi, hi, sizeof hi);
    for (k = 1; k < 3; k++)
        if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
    if (count <= RT_LEAF_SIZE || depth >= RT_STACK - 8 || !(chi[axis] > clo[axis])) {
        rt->nodes[ni].first = first;
        rt->nodes[ni].count = count;
        return 0;
    }
    half = count / 2;
    select_centroid(rt->centroid, rt->prims + first, count, half, axis);
    rt->nodes[ni].count = 0;
    if (build_node(rt, first, half, depth + 1) != 0) return -1;
    rt->nodes[ni].first = rt->node_count; /* (nodes may have moved: index again) */
    return build_node(rt, first + half, count - half, depth + 1);
}

int rcu_reftrace_build_d(const double *vertices, uint32_t vertex_count, const uint32_t *indices,
                         uint32_t triangle_count, rcu_reftrace **out)
{
    rcu_reftrace *rt;
    uint32_t t;
    if (!vertices || !indices || triangle_count == 0 || !out) return rcu_fail("reftrace: empty mesh");
    rt = (rcu_reftrace *)calloc(1, sizeof *rt);
    if (!rt) return rcu_fail("reftrace: out of memory");
    rt->tri_count = triangle_count;
    rt->v = (double *)malloc((size_t)triangle_count * 9 * sizeof(double));
    rt->degenerate = (uint8_t *)calloc(triangle_count, 1);
    rt->prims = (uint32_t *)malloc((size_t)triangle_count * sizeof(uint32_t));
    rt->centroid = (double *)malloc((size_t)triangle_count * 3 * sizeof(double));
    if (!rt->v || !rt->degenerate || !rt->prims || !rt->centroid) {
        rcu_reftrace_free(rt);
        return rcu_fail("reftrace: out of memory for %u triangles", triangle_count);
    }
    for (t = 0; t < triangle_count; t++) {
        double *v = rt->v + 9u * (size_t)t;
        int j, k;
        for (j = 0; j < 3; j++) {
            uint32_t vi = indices[3u * (size_t)t + (uint32_t)j];
            if (vi >= vertex_count) {
                rcu_reftrace_free(rt);
                return rcu_fail("reftrace: triangle %u has vertex index %u past %u", t, vi, vertex_count);
            }
            for (k = 0; k < 3; k++) v[3 * j + k] = vertices[3u * (size_t)vi + (uint32_t)k];
        }
        for (k = 0; k < 3; k++) rt->centroid[3u * (size_t)t + (uint32_t)k] = (v[k] + v[3 + k] + v[6 + k]) / 3.0;
        rt->degenerate[t] = (uint8_t)tri_zero_area(v, v + 3, v + 6);
        if (!rt->degenerate[t]) rt->prims[rt->prim_count++] = t;
    }
    if (rt->prim_count > 0 && build_node(rt, 0, rt->prim_count, 0) != 0) {
        rcu_reftrace_free(rt);
        return rcu_fail("reftrace: out of memory for the BVH");
    }
    free(rt->centroid);
    rt->centroid = NULL;
    *out = rt;
    return 0;
}

int rcu_reftrace_build(const rcu_mesh *mesh, rcu_reftrace **out)
{
    double *v;
    size_t i, n;
    int r;
    if (!mesh || mesh->triangle_count == 0 || mesh->vertex_count == 0) return rcu_fail("reftrace: empty mesh");
    n = (size_t)mesh->vertex_count * 3;
    v = (double *)malloc(n * sizeof(double));
    if (!v) return rcu_fail("reftrace: out of memory");
    for (i = 0; i < n; i++) v[i] = mesh->vertices[i];
    r = rcu_reftrace_build_d(v, mesh->vertex_count, mesh->indices, mesh->triangle_count, out);
    free(v);
    return r;
}

void rcu_reftrace_free(rcu_reftrace *rt)
{
    if (!rt) return;
    free(rt->v);
    free(rt->degenerate);
    free(rt->prims);
    free(rt->nodes);
    free(rt->centroid);
    free(rt);
}

uint32_t rcu_reftrace_triangle_count(const rcu_reftrace *rt) { return rt ? rt->tri_count : 0; }

int rcu_reftrace_degenerate(const rcu_reftrace *rt, uint32_t prim)
{
    return prim < rt->tri_count ? rt->degenerate[prim] != 0 : 1;
}

void rcu_reftrace_normal(const rcu_reftrace *rt, uint32_t prim, double n[3])
{
    const double *v;
    double e1[3], e2[3], len;
    int k;
    n[0] = n[1] = n[2] = 0.0;
    if (prim >= rt->tri_count || rt->degenerate[prim]) return;
    v = rt->v + 9u * (size_t)prim;
    for (k = 0; k < 3; k++) {
        e1[k] = v[3 + k] - v[k];
        e2[k] = v[6 + k] - v[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0)
        for (k = 0; k < 3; k++) n[k] /= len;
}

/* Per-ray constants of the watertight test and the slab test. */
typedef struct rt_ray {
    double o[3], d[3], inv[3];
    int kx, ky, kz;
    double sx, sy, sz;
} rt_ray;

static void ray_setup(rt_ray *r, const double o[3], const double d[3])
{
    int k;
    double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
    for (k = 0; k < 3; k++) {
        r->o[k] = o[k];
        r->d[k] = d[k];
        r->inv[k] = d[k] != 0.0 ? 1.0 / d[k] : 0.0;
    }
    r->kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
    r->kx = (r->kz + 1) % 3;
    r->ky = (r->kx + 1) % 3;
    if (d[r->kz] < 0.0) { /* keep the winding */
        int t = r->kx;
        r->kx = r->ky;
        r->ky = t;
    }
    r->sx = d[r->kx] / d[r->kz];
    r->sy = d[r->ky] / d[r->kz];
    r->sz = 1.0 / d[r->kz];
}

/* Entry distance of the ray into the box, or -1 when it misses [0, tmax].
 * Zero direction components constrain nothing but the origin's slab (no
 * 0 * inf); the exit distance is widened by a few ulps (Ize 2013). */
static double box_enter(const rt_ray *r, const rt_node *n, double tmax)
{
    double tn = 0.0, tf = tmax;
    int k;
    for (k = 0; k < 3; k++) {
        if (r->d[k] == 0.0) {
            if (r->o[k] < n->lo[k] || r->o[k] > n->hi[k]) return -1.0;
        } else {
            double t0 = (n->lo[k] - r->o[k]) * r->inv[k], t1 = (n->hi[k] - r->o[k]) * r->inv[k];
            if (t0 > t1) {
                double s = t0;
                t0 = t1;
                t1 = s;
            }
            t1 *= 1.0 + 1e-14;
            if (t0 > tn) tn = t0;
            if (t1 < tf) tf = t1;
        }
    }
    return tn <= tf ? tn : -1.0;
}

/* Woop et al. 2013 in double; exact-zero edge functions are redone in long
 * double. 1 with *t when 0 < t (units of |d|). */
static int tri_hit(const rt_ray *r, const double *a, const double *b, const double *c, double *t)
{
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    const double az = a[kz] - r->o[kz], bz = b[kz] - r->o[kz], cz = c[kz] - r->o[kz];
    const double Ax = (a[kx] - r->o[kx]) - r->sx * az, Ay = (a[ky] - r->o[ky]) - r->sy * az;
    const double Bx = (b[kx] - r->o[kx]) - r->sx * bz, By = (b[ky] - r->o[ky]) - r->sy * bz;
    const double Cx = (c[kx] - r->o[kx]) - r->sx * cz, Cy = (c[ky] - r->o[ky]) - r->sy * cz;
    double U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax, det, T = 0.0;
    if (U == 0.0 || V == 0.0 || W == 0.0) {
        U = (double)((long double)Cx * By - (long double)Cy * Bx);
        V = (double)((long double)Ax * Cy - (long double)Ay * Cx);
        W = (double)((long double)Bx * Ay - (long double)By * Ax);
    }
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return 0;
    det = U + V + W;
    if (det == 0.0) return 0;
    (void)T;
    /* inside: the distance to the triangle's plane, n . (a - o) / n . d, in
     * double. Unlike the sheared T / det it is exactly 0 for an origin on an
     * axis-aligned face (no 1e-16 self-hits), and it is what the library's
     * float64 refinement computes. */
    {
        double e1[3], e2[3], n[3], w[3], dn;
        int k;
        for (k = 0; k < 3; k++) {
            e1[k] = b[k] - a[k];
            e2[k] = c[k] - a[k];
            w[k] = a[k] - r->o[k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        dn = n[0] * r->d[0] + n[1] * r->d[1] + n[2] * r->d[2];
        if (dn == 0.0) return 0;
        *t = (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]) / dn;
    }
    return *t > 0.0;
}

int rcu_reftrace_nearest(const rcu_reftrace *rt, const double o[3], const double d[3], double tmax,
                         double *t, uint32_t *prim)
{
    rt_ray r;
    uint32_t stack[RT_STACK], sp = 0, best_prim = UINT32_MAX, ni;
    double best = tmax;
    if (!rt || rt->prim_count == 0) return 0;
    if (!(d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0)) return 0;
    ray_setup(&r, o, d);
    if (box_enter(&r, &rt->nodes[0], best) < 0.0) return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const rt_node *n;
        ni = stack[--sp];
        n = &rt->nodes[ni];
        if (n->count > 0) {
            uint32_t i;
            for (i = n->first; i < n->first + n->count; i++) {
                uint32_t p = rt->prims[i];
                const double *v = rt->v + 9u * (size_t)p;
                double th;
                if (tri_hit(&r, v, v + 3, v + 6, &th) &&
                    (th < best || (th == best && (best_prim == UINT32_MAX || p < best_prim)))) {
                    best = th;
                    best_prim = p;
                }
            }
        } else {
            uint32_t l = ni + 1, rr = n->first;
            double tl = box_enter(&r, &rt->nodes[l], best), tr = box_enter(&r, &rt->nodes[rr], best);
            if (tl >= 0.0 && tr >= 0.0) {
                /* nearer child on top */
                if (tl <= tr) {
                    stack[sp++] = rr;
                    stack[sp++] = l;
                } else {
                    stack[sp++] = l;
                    stack[sp++] = rr;
                }
            } else if (tl >= 0.0) {
                stack[sp++] = l;
            } else if (tr >= 0.0) {
                stack[sp++] = rr;
            }
        }
    }
    if (best_prim == UINT32_MAX) return 0;
    *t = best;
    *prim = best_prim;
    return 1;
}
