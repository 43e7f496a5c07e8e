/* Ray queries on meshes: the watertight triangle test (known hits, closed
 * meshes shot exactly at vertices and edges, zero-area triangles, axis-parallel
 * rays, coplanar ties) and BVH traversal against brute force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh/intersect.h"
#include "bvh/mesh.h"

/* ---- helpers --------------------------------------------------------------- */

static uint64_t rng_state;

static uint32_t rng_u32(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (uint32_t)((rng_state * 2685821657736338717ull) >> 32);
}

static float rng_float(float lo, float hi)
{
    return lo + (hi - lo) * (float)(rng_u32() >> 8) * (1.0f / 16777216.0f);
}

/* A mesh the test owns: vertices (stride floats each), indices, and its BVH. */
typedef struct tmesh {
    float *v;
    uint32_t *idx;
    uint32_t nv, nt, cap_v, cap_t, stride;
    rc__mesh m;
    rc__aabb *bounds;
    void *scratch;
} tmesh;

static void tmesh_init(tmesh *t, uint32_t cap_v, uint32_t cap_t, uint32_t stride)
{
    memset(t, 0, sizeof *t);
    t->stride = stride;
    t->cap_v = cap_v;
    t->cap_t = cap_t;
    t->v = calloc((size_t)cap_v * stride, sizeof(float));
    t->idx = calloc((size_t)cap_t * 3, sizeof(uint32_t));
    assert_non_null(t->v);
    assert_non_null(t->idx);
}

static uint32_t tmesh_vertex(tmesh *t, float x, float y, float z)
{
    float *p;
    assert_true(t->nv < t->cap_v);
    p = t->v + (size_t)t->nv * t->stride;
    p[0] = x;
    p[1] = y;
    p[2] = z;
    return t->nv++;
}

static uint32_t tmesh_tri(tmesh *t, uint32_t a, uint32_t b, uint32_t c)
{
    assert_true(t->nt < t->cap_t);
    t->idx[3 * t->nt] = a;
    t->idx[3 * t->nt + 1] = b;
    t->idx[3 * t->nt + 2] = c;
    return t->nt++;
}

/* Builds the BVH (all buffers at their exact sizes, for ASan). */
static void tmesh_build(tmesh *t, uint32_t leaf)
{
    free(t->m.bvh.nodes);
    free(t->m.bvh.refs);
    free(t->bounds);
    free(t->scratch);
    t->m.vertices = t->v;
    t->m.indices = t->idx;
    t->m.stride = t->stride;
    t->m.vertex_count = t->nv;
    t->m.triangle_count = t->nt;
    t->bounds = malloc(sizeof(rc__aabb) * t->nt);
    t->scratch = malloc(rc__bvh_build_scratch_bytes(t->nt));
    t->m.bvh.nodes = malloc(sizeof(rc__bvh_node) * rc__bvh_node_count(t->nt, leaf));
    t->m.bvh.refs = malloc(sizeof(uint32_t) * t->nt);
    rc__mesh_triangle_bounds(&t->m, t->bounds);
    rc__bvh_build(t->bounds, t->nt, leaf, t->scratch, &t->m.bvh, NULL, NULL);
}

static void tmesh_free(tmesh *t)
{
    free(t->v);
    free(t->idx);
    free(t->bounds);
    free(t->scratch);
    free(t->m.bvh.nodes);
    free(t->m.bvh.refs);
}

static void hit_reset(rc__hit *h, float tmax)
{
    h->t = tmax;
    h->prim = h->geom = h->inst = RC_INVALID_ID;
}

static int cast(const tmesh *t, const float org[3], const float dir[3], rc__hit *h)
{
    rc__ray ray;
    rc__ray_prepare(&ray, org, dir);
    hit_reset(h, INFINITY);
    return rc__mesh_intersect(&t->m, &ray, 0, RC_INVALID_ID, h);
}

/* Barycentrics (weights of b and c) of the ray from org along dir on
 * triangle prim, from the triangle test (hits keep no barycentrics). */
static void barycentrics(const tmesh *t, const float org[3], const float dir[3], uint32_t prim, float *u, float *v)
{
    const uint32_t *tri = t->idx + 3 * prim;
    rc__ray ray;
    float tt;
    rc__ray_prepare(&ray, org, dir);
    assert_true(rc__tri_intersect(&ray, t->v + tri[0] * t->stride, t->v + tri[1] * t->stride,
                                  t->v + tri[2] * t->stride, &tt, u, v));
}

/* Every triangle, the same test and the same acceptance rule. */
static int brute(const tmesh *t, const rc__ray *ray, rc__hit *h)
{
    uint32_t i;
    int found = 0;
    for (i = 0; i < t->nt; ++i) {
        const uint32_t *tri = t->idx + 3 * i;
        float tt, u, v;
        if (!rc__tri_intersect(ray, t->v + tri[0] * t->stride, t->v + tri[1] * t->stride,
                               t->v + tri[2] * t->stride, &tt, &u, &v))
            continue;
        if (tt > h->t || (tt == h->t && !(i < h->prim))) continue;
        h->t = tt;
        h->prim = i;
        found = 1;
    }
    return found;
}

/* A closed mesh: the surface of the cube [-1,1]^3 cut into n x n squares per
 * face (two triangles each), vertices shared through an (n+1)^3 grid, then
 * optionally pushed onto the sphere of the given radius. */
static void make_cube(tmesh *t, uint32_t n, int sphere, float radius)
{
    const uint32_t g = n + 1;
    uint32_t *id = malloc(sizeof(uint32_t) * g * g * g);
    int face;
    uint32_t i;
    for (i = 0; i < g * g * g; ++i) id[i] = RC_INVALID_ID;
    tmesh_init(t, 6 * g * g, 12 * n * n, 3);
    for (face = 0; face < 6; ++face) {
        const int axis = face / 2, u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
        const uint32_t fixed = face % 2 ? n : 0;
        uint32_t a, b;
        for (a = 0; a < n; ++a) {
            for (b = 0; b < n; ++b) {
                uint32_t q[4], c;
                for (c = 0; c < 4; ++c) {
                    uint32_t gi[3], key;
                    gi[axis] = fixed;
                    gi[u_axis] = a + (c == 1 || c == 2);
                    gi[v_axis] = b + (c >= 2);
                    key = (gi[0] * g + gi[1]) * g + gi[2];
                    if (id[key] == RC_INVALID_ID) {
                        float p[3];
                        int k;
                        for (k = 0; k < 3; ++k) p[k] = -1.0f + 2.0f * (float)gi[k] / (float)n;
                        if (sphere) {
                            float s = radius / sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                            for (k = 0; k < 3; ++k) p[k] *= s;
                        } else {
                            for (k = 0; k < 3; ++k) p[k] *= radius;
                        }
                        id[key] = tmesh_vertex(t, p[0], p[1], p[2]);
                    }
                    q[c] = id[key];
                }
                /* alternate the diagonal so both kinds of shared edges occur */
                if ((a + b) % 2) {
                    tmesh_tri(t, q[0], q[1], q[2]);
                    tmesh_tri(t, q[0], q[2], q[3]);
                } else {
                    tmesh_tri(t, q[0], q[1], q[3]);
                    tmesh_tri(t, q[1], q[2], q[3]);
                }
            }
        }
    }
    free(id);
}

/* UV sphere with triangle fans at the poles (a vertex shared by `seg`
 * triangles). */
static void make_uv_sphere(tmesh *t, uint32_t rings, uint32_t seg, float r)
{
    uint32_t i, j, south;
    tmesh_init(t, 2 + (rings - 1) * seg, 2 * seg * (rings - 1), 3);
    tmesh_vertex(t, 0.0f, 0.0f, r);
    for (i = 1; i < rings; ++i) {
        double th = 3.14159265358979323846 * i / rings;
        for (j = 0; j < seg; ++j) {
            double ph = 2.0 * 3.14159265358979323846 * j / seg;
            tmesh_vertex(t, (float)(r * sin(th) * cos(ph)), (float)(r * sin(th) * sin(ph)),
                         (float)(r * cos(th)));
        }
    }
    south = tmesh_vertex(t, 0.0f, 0.0f, -r);
    for (j = 0; j < seg; ++j) tmesh_tri(t, 0, 1 + j, 1 + (j + 1) % seg);
    for (i = 1; i + 1 < rings; ++i) {
        for (j = 0; j < seg; ++j) {
            uint32_t a = 1 + (i - 1) * seg + j, b = 1 + (i - 1) * seg + (j + 1) % seg;
            uint32_t c = 1 + i * seg + j, d = 1 + i * seg + (j + 1) % seg;
            tmesh_tri(t, a, c, b);
            tmesh_tri(t, b, c, d);
        }
    }
    for (j = 0; j < seg; ++j) tmesh_tri(t, 1 + (rings - 2) * seg + j, south, 1 + (rings - 2) * seg + (j + 1) % seg);
}

static const float *vtx(const tmesh *t, uint32_t i)
{
    return t->v + (size_t)i * t->stride;
}

/* Shoots from org exactly at every vertex and at points along every edge of a
 * closed mesh that contains org; returns how many rays escaped. With
 * use_brute, tests every triangle instead of the BVH. */
static uint32_t count_escapes(const tmesh *t, const float org[3], int use_brute)
{
    static const float params[] = {0.5f, 0.25f, 1.0f / 3.0f, 0.125f, 0.7f, 0.9f, 0.01f};
    uint32_t tri, e, escapes = 0, rays = 0;
    for (tri = 0; tri < t->nt; ++tri) {
        for (e = 0; e < 3; ++e) {
            const float *a = vtx(t, t->idx[3 * tri + e]), *b = vtx(t, t->idx[3 * tri + (e + 1) % 3]);
            size_t p;
            for (p = 0; p <= sizeof params / sizeof params[0]; ++p) {
                float target[3], dir[3];
                rc__hit h;
                rc__ray ray;
                int k, found;
                for (k = 0; k < 3; ++k) {
                    /* p == count: the vertex itself */
                    target[k] = p == sizeof params / sizeof params[0] ? a[k] : a[k] + params[p] * (b[k] - a[k]);
                    dir[k] = target[k] - org[k];
                }
                rc__ray_prepare(&ray, org, dir);
                hit_reset(&h, INFINITY);
                found = use_brute ? brute(t, &ray, &h) : rc__mesh_intersect(&t->m, &ray, 0, RC_INVALID_ID, &h);
                ++rays;
                if (!found) ++escapes;
                else assert_true(h.t > 0.0f);
            }
        }
    }
    assert_true(rays > 0);
    return escapes;
}

/* ---- tests ----------------------------------------------------------------- */

static void test_ray_prepare(void **state)
{
    static const float o[3] = {1.0f, 2.0f, 3.0f};
    static const float d1[3] = {0.0f, 0.0f, 1.0f};
    static const float d2[3] = {0.0f, 0.0f, -2.0f};
    static const float d3[3] = {-3.0f, 1.0f, 2.0f};
    static const float d4[3] = {0.5f, -4.0f, -0.0f};
    rc__ray r;
    (void)state;
    rc__ray_prepare(&r, o, d1);
    assert_int_equal(r.kz, 2);
    assert_int_equal(r.kx, 0);
    assert_int_equal(r.ky, 1);
    assert_true(r.sx == 0.0f && r.sy == 0.0f && r.sz == 1.0f);
    assert_true(isinf(r.inv_dir[0]) && r.inv_dir[0] > 0.0f);
    rc__ray_prepare(&r, o, d2);
    assert_int_equal(r.kz, 2);
    assert_int_equal(r.kx, 1); /* swapped: winding kept for a negative dir[kz] */
    assert_int_equal(r.ky, 0);
    assert_true(r.sz == -0.5f);
    rc__ray_prepare(&r, o, d3);
    assert_int_equal(r.kz, 0);
    assert_true(r.sx == d3[r.kx] / -3.0f && r.sy == d3[r.ky] / -3.0f);
    rc__ray_prepare(&r, o, d4);
    assert_int_equal(r.kz, 1);
    assert_true(isinf(r.inv_dir[2]) && r.inv_dir[2] < 0.0f); /* -0.0 gives -inf */
}

static void test_single_triangle(void **state)
{
    static const float org[3] = {0.25f, 0.25f, 0.0f};
    static const float up[3] = {0.0f, 0.0f, 1.0f}, up2[3] = {0.0f, 0.0f, 2.0f};
    static const float down[3] = {0.0f, 0.0f, -1.0f};
    static const float outside[3] = {1.0f, 1.0f, 0.0f};
    tmesh t;
    rc__hit h;
    rc__ray ray;
    float u, v;
    int winding;
    (void)state;
    for (winding = 0; winding < 2; ++winding) {
        uint32_t a, b, c;
        tmesh_init(&t, 3, 1, 3);
        a = tmesh_vertex(&t, 0.0f, 0.0f, 5.0f);
        b = tmesh_vertex(&t, 1.0f, 0.0f, 5.0f);
        c = tmesh_vertex(&t, 0.0f, 1.0f, 5.0f);
        if (winding) tmesh_tri(&t, a, c, b);
        else tmesh_tri(&t, a, b, c);
        tmesh_build(&t, 4);

        assert_true(cast(&t, org, up, &h));
        assert_true(h.t == 5.0f);
        barycentrics(&t, org, up, h.prim, &u, &v);
        assert_true(u == 0.25f && v == 0.25f);
        assert_int_equal(h.prim, 0);
        assert_int_equal(h.geom, 0);
        assert_int_equal(h.inst, RC_INVALID_ID);

        /* t is in units of |dir| */
        assert_true(cast(&t, org, up2, &h));
        assert_true(h.t == 2.5f);

        /* behind the origin, beside the triangle */
        assert_false(cast(&t, org, down, &h));
        assert_false(cast(&t, outside, up, &h));

        /* farther than the current nearest: no hit, hit left alone */
        rc__ray_prepare(&ray, org, up);
        hit_reset(&h, 4.0f);
        assert_false(rc__mesh_intersect(&t.m, &ray, 7, 9, &h));
        assert_true(h.t == 4.0f);
        assert_int_equal(h.prim, RC_INVALID_ID);

        /* geometry and instance ids come from the arguments */
        hit_reset(&h, INFINITY);
        assert_true(rc__mesh_intersect(&t.m, &ray, 7, 9, &h));
        assert_int_equal(h.geom, 7);
        assert_int_equal(h.inst, 9);

        /* a tie at exactly hit->t: taken only with a smaller key */
        hit_reset(&h, 5.0f);
        h.inst = 9;
        h.geom = 7;
        h.prim = 0;
        assert_false(rc__mesh_intersect(&t.m, &ray, 7, 9, &h));
        h.prim = 1;
        assert_true(rc__mesh_intersect(&t.m, &ray, 7, 9, &h));
        assert_int_equal(h.prim, 0);

        /* occlusion: strictly before tmax */
        assert_true(rc__mesh_occluded(&t.m, &ray, INFINITY));
        assert_true(rc__mesh_occluded(&t.m, &ray, 5.5f));
        assert_false(rc__mesh_occluded(&t.m, &ray, 5.0f));
        rc__ray_prepare(&ray, org, down);
        assert_false(rc__mesh_occluded(&t.m, &ray, INFINITY));
        tmesh_free(&t);
    }
}

/* A plane z = d of two triangles: rays from many origins and directions hit at
 * z = d, at the point the barycentrics name. */
static void test_plane_distance(void **state)
{
    const float d = 7.5f;
    tmesh t;
    uint32_t i;
    (void)state;
    tmesh_init(&t, 4, 2, 3);
    tmesh_vertex(&t, -100.0f, -100.0f, d);
    tmesh_vertex(&t, 100.0f, -100.0f, d);
    tmesh_vertex(&t, 100.0f, 100.0f, d);
    tmesh_vertex(&t, -100.0f, 100.0f, d);
    tmesh_tri(&t, 0, 1, 2);
    tmesh_tri(&t, 0, 2, 3);
    tmesh_build(&t, 4);
    rng_state = 1;
    for (i = 0; i < 20000; ++i) {
        float org[3], dir[3], p[3], u, v;
        const uint32_t *tri;
        const float *a, *b, *c;
        rc__hit h;
        int k;
        org[0] = rng_float(-10.0f, 10.0f);
        org[1] = rng_float(-10.0f, 10.0f);
        org[2] = rng_float(-5.0f, 5.0f);
        dir[0] = rng_float(-1.0f, 1.0f);
        dir[1] = rng_float(-1.0f, 1.0f);
        dir[2] = rng_float(0.2f, 1.0f);
        if (i % 4 == 0) { /* straight up from a dyadic origin: every step exact */
            dir[0] = dir[1] = 0.0f;
            dir[2] = 1.0f;
            for (k = 0; k < 3; ++k) org[k] = floorf(org[k] * 8.0f) / 8.0f;
        }
        assert_true(cast(&t, org, dir, &h));
        assert_float_equal(org[2] + h.t * dir[2], d, 2e-5);
        if (i % 4 == 0) assert_true(h.t * dir[2] == d - org[2]);
        tri = t.idx + 3 * h.prim;
        a = vtx(&t, tri[0]);
        b = vtx(&t, tri[1]);
        c = vtx(&t, tri[2]);
        barycentrics(&t, org, dir, h.prim, &u, &v);
        assert_true(u >= 0.0f && v >= 0.0f && u + v <= 1.0f + 1e-6f);
        for (k = 0; k < 3; ++k) {
            p[k] = (1.0f - u - v) * a[k] + u * b[k] + v * c[k];
            assert_float_equal(p[k], org[k] + h.t * dir[k], 1e-4);
        }
    }
    tmesh_free(&t);
}

/* The heart of it: rays aimed exactly at every vertex and at points on every
 * shared edge of closed meshes never slip through, from the centre and from
 * off-centre origins, through the BVH (two leaf sizes) and through every
 * triangle directly. */
static void test_watertight_closed_meshes(void **state)
{
    static const float centre[3] = {0.0f, 0.0f, 0.0f};
    static const float off[3] = {0.3f, -0.2f, 0.1f};
    static const float off2[3] = {-1.1f, 0.6f, 0.9f};
    tmesh t;
    int kind;
    (void)state;
    for (kind = 0; kind < 3; ++kind) {
        if (kind == 0) make_cube(&t, 12, 1, 3.7f);       /* cube-sphere */
        else if (kind == 1) make_uv_sphere(&t, 24, 40, 2.3f); /* pole fans */
        else make_cube(&t, 8, 0, 2.5f);                  /* flat faces: collinear edges */
        tmesh_build(&t, 4);
        assert_int_equal(count_escapes(&t, centre, 0), 0);
        assert_int_equal(count_escapes(&t, off, 0), 0);
        assert_int_equal(count_escapes(&t, off2, 0), 0);
        tmesh_build(&t, 1);
        assert_int_equal(count_escapes(&t, centre, 0), 0);
        assert_int_equal(count_escapes(&t, off, 0), 0);
        assert_int_equal(count_escapes(&t, centre, 1), 0);
        tmesh_free(&t);
    }
}

/* Random directions from random inside points of a fine closed mesh: every
 * ray hits, near the surface. */
static void test_watertight_random_rays(void **state)
{
    tmesh t;
    uint32_t i, misses = 0;
    (void)state;
    make_uv_sphere(&t, 90, 120, 20.0f);
    tmesh_build(&t, 4);
    rng_state = 77;
    for (i = 0; i < 100000; ++i) {
        float org[3], dir[3];
        rc__hit h;
        int k;
        for (k = 0; k < 3; ++k) {
            org[k] = rng_float(-10.0f, 10.0f);
            dir[k] = rng_float(-1.0f, 1.0f);
        }
        if (i % 5 == 0) dir[i % 3] = 0.0f;
        if (i % 7 == 0) dir[(i + 1) % 3] = -0.0f;
        if (dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f) dir[2] = 1.0f;
        if (!cast(&t, org, dir, &h)) {
            ++misses;
            continue;
        }
        {
            float p[3], r;
            for (k = 0; k < 3; ++k) p[k] = org[k] + h.t * dir[k];
            r = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            assert_true(r > 19.9f && r <= 20.001f);
        }
    }
    assert_int_equal(misses, 0);
    tmesh_free(&t);
}

/* Zero-area triangles (repeated index, repeated position, collinear points)
 * are never hit, even by rays aimed exactly at them; the real triangle behind
 * them is. */
static void test_zero_area_never_hit(void **state)
{
    tmesh t;
    uint32_t real, i;
    const float eye[3] = {0.0f, 0.0f, 0.0f};
    (void)state;
    tmesh_init(&t, 32, 16, 3);
    {
        uint32_t a = tmesh_vertex(&t, 0.5f, 0.25f, 5.0f);
        uint32_t b = tmesh_vertex(&t, 0.625f, 0.5f, 5.0625f); /* a + 0.5 d, d = (.25,.5,.125) */
        uint32_t c = tmesh_vertex(&t, 1.0f, 1.25f, 5.25f);    /* a + 2 d: exactly collinear */
        uint32_t a2 = tmesh_vertex(&t, 0.5f, 0.25f, 5.0f);    /* same position as a */
        uint32_t e = tmesh_vertex(&t, -1.0f, 2.0f, 4.0f);
        uint32_t f = tmesh_vertex(&t, -1.0f, -2.0f, 4.0f);
        uint32_t g = tmesh_vertex(&t, -1.0f, 0.0f, 4.0f);     /* on the segment e-f */
        uint32_t h0 = tmesh_vertex(&t, 2.0f, 2.0f, 6.0f);
        uint32_t h1 = tmesh_vertex(&t, 3.0f, 3.0f, 6.0f);
        tmesh_tri(&t, a, b, c);
        tmesh_tri(&t, c, b, a);
        tmesh_tri(&t, a, a2, e);  /* two vertices at one position */
        tmesh_tri(&t, e, e, f);   /* repeated index */
        tmesh_tri(&t, e, g, f);   /* collinear, axis-aligned */
        tmesh_tri(&t, f, g, e);
        tmesh_tri(&t, h0, h1, h0);
        tmesh_tri(&t, a, c, b);
    }
    {
        uint32_t p = tmesh_vertex(&t, -500.0f, -500.0f, 100.0f);
        uint32_t q = tmesh_vertex(&t, 500.0f, -500.0f, 100.0f);
        uint32_t r = tmesh_vertex(&t, 0.0f, 800.0f, 100.0f);
        real = tmesh_tri(&t, p, q, r);
    }
    tmesh_build(&t, 1);
    /* aim at every degenerate vertex and along every degenerate edge */
    for (i = 0; i < real; ++i) {
        uint32_t e;
        for (e = 0; e < 3; ++e) {
            const float *a = vtx(&t, t.idx[3 * i + e]), *b = vtx(&t, t.idx[3 * i + (e + 1) % 3]);
            static const float params[] = {0.0f, 0.5f, 0.25f, 0.75f, 1.0f / 3.0f};
            size_t p;
            for (p = 0; p < sizeof params / sizeof params[0]; ++p) {
                float dir[3];
                rc__hit h;
                rc__ray ray;
                int k;
                for (k = 0; k < 3; ++k) dir[k] = a[k] + params[p] * (b[k] - a[k]) - eye[k];
                assert_true(cast(&t, eye, dir, &h));
                assert_int_equal(h.prim, real);
                rc__ray_prepare(&ray, eye, dir);
                hit_reset(&h, INFINITY);
                assert_true(brute(&t, &ray, &h));
                assert_int_equal(h.prim, real);
            }
        }
    }
    /* and from the side, in their own planes */
    {
        static const float side[3] = {-1.0f, 0.0f, 0.0f};
        static const float from[3] = {5.0f, 0.0f, 4.0f};
        rc__hit h;
        assert_false(cast(&t, from, side, &h));
    }
    tmesh_free(&t);
}

/* Axis-parallel rays (direction components exactly +0.0 or -0.0) inside an
 * axis-aligned box mesh, from origins on the vertex grid lines and on node box
 * planes: always a hit, at the exact distance. */
static void test_axis_parallel_box(void **state)
{
    static const float coords[] = {-0.75f, -0.5f, -0.25f, 0.0f, 0.25f, 0.5f, 0.75f, 0.3f};
    const size_t nc = sizeof coords / sizeof coords[0];
    tmesh t;
    uint32_t leaf_i;
    (void)state;
    make_cube(&t, 4, 0, 1.0f); /* [-1,1]^3, grid step 0.5 */
    for (leaf_i = 0; leaf_i < 2; ++leaf_i) {
        size_t x, y, z;
        tmesh_build(&t, leaf_i ? 4 : 1);
        for (x = 0; x < nc; ++x) {
            for (y = 0; y < nc; ++y) {
                for (z = 0; z < nc; ++z) {
                    const float org[3] = {coords[x], coords[y], coords[z]};
                    int axis, sign, zero_sign;
                    for (axis = 0; axis < 3; ++axis) {
                        for (sign = -1; sign <= 1; sign += 2) {
                            for (zero_sign = 0; zero_sign < 2; ++zero_sign) {
                                float dir[3];
                                rc__hit h;
                                int k;
                                for (k = 0; k < 3; ++k) dir[k] = zero_sign ? -0.0f : 0.0f;
                                dir[axis] = (float)sign;
                                assert_true(cast(&t, org, dir, &h));
                                /* exact for the dyadic coordinates */
                                if (coords[x] != 0.3f && coords[y] != 0.3f && coords[z] != 0.3f)
                                    assert_true(h.t == 1.0f - (float)sign * org[axis]);
                                else
                                    assert_float_equal(h.t, 1.0f - (float)sign * org[axis], 1e-6);
                            }
                        }
                    }
                }
            }
        }
        /* on the surface, along a face plane: grazes the coplanar face (no hit)
         * and meets the opposite face's edge */
        {
            static const float o1[3] = {0.25f, -1.0f, 0.25f}, d1[3] = {1.0f, 0.0f, 0.0f};
            static const float o2[3] = {-1.0f, -1.0f, -1.0f}, d2[3] = {1.0f, -0.0f, 0.0f};
            static const float o3[3] = {0.5f, 1.0f, -1.0f}, d3[3] = {-0.0f, -0.0f, 1.0f};
            rc__hit h;
            assert_true(cast(&t, o1, d1, &h));
            assert_true(h.t == 0.75f);
            assert_true(cast(&t, o2, d2, &h)); /* along a cube edge to the far corner */
            assert_true(h.t == 2.0f);
            assert_true(cast(&t, o3, d3, &h));
            assert_true(h.t == 2.0f);
        }
    }
    tmesh_free(&t);
}

/* Coplanar duplicates: the smaller prim index wins, whatever the positions,
 * windings and traversal order; across calls the smaller (inst, geom) wins. */
static void test_coplanar_ties(void **state)
{
    static const float org[3] = {0.2f, 0.3f, 0.0f};
    static const float dir[3] = {0.01f, -0.02f, 1.0f};
    uint32_t first, second, leaf_i;
    (void)state;
    rng_state = 3;
    for (leaf_i = 0; leaf_i < 2; ++leaf_i) {
        for (first = 0; first < 12; first += 3) {
            for (second = first + 1; second < 14; second += 4) {
                tmesh t;
                uint32_t i, a, b, c;
                rc__hit h;
                tmesh_init(&t, 3 + 3 * 14, 14, 3);
                a = tmesh_vertex(&t, -1.0f, -1.0f, 2.0f);
                b = tmesh_vertex(&t, 2.0f, -1.0f, 2.0f);
                c = tmesh_vertex(&t, 0.0f, 2.0f, 2.0f);
                for (i = 0; i < 14; ++i) {
                    if (i == first) {
                        tmesh_tri(&t, a, b, c);
                    } else if (i == second) {
                        if (i % 2) tmesh_tri(&t, c, b, a);  /* other winding */
                        else tmesh_tri(&t, b, c, a);
                    } else { /* clutter elsewhere, to shuffle the tree */
                        float x = rng_float(-20.0f, 20.0f), y = rng_float(5.0f, 20.0f);
                        uint32_t p = tmesh_vertex(&t, x, y, 1.0f);
                        uint32_t q = tmesh_vertex(&t, x + 1.0f, y, 3.0f);
                        uint32_t r = tmesh_vertex(&t, x, y + 1.0f, 2.0f);
                        tmesh_tri(&t, p, q, r);
                    }
                }
                tmesh_build(&t, leaf_i ? 4 : 1);
                assert_true(cast(&t, org, dir, &h));
                assert_int_equal(h.prim, first);
                tmesh_free(&t);
            }
        }
    }
    /* the same mesh as several geometries / instances, in either call order */
    {
        tmesh t;
        rc__ray ray;
        rc__hit h;
        tmesh_init(&t, 3, 1, 3);
        tmesh_vertex(&t, -1.0f, -1.0f, 2.0f);
        tmesh_vertex(&t, 2.0f, -1.0f, 2.0f);
        tmesh_vertex(&t, 0.0f, 2.0f, 2.0f);
        tmesh_tri(&t, 0, 1, 2);
        tmesh_build(&t, 4);
        rc__ray_prepare(&ray, org, dir);
        hit_reset(&h, INFINITY);
        assert_true(rc__mesh_intersect(&t.m, &ray, 3, RC_INVALID_ID, &h));
        assert_true(rc__mesh_intersect(&t.m, &ray, 1, RC_INVALID_ID, &h));
        assert_false(rc__mesh_intersect(&t.m, &ray, 2, RC_INVALID_ID, &h));
        assert_int_equal(h.geom, 1);
        hit_reset(&h, INFINITY);
        assert_true(rc__mesh_intersect(&t.m, &ray, 1, RC_INVALID_ID, &h));
        assert_false(rc__mesh_intersect(&t.m, &ray, 3, RC_INVALID_ID, &h));
        assert_int_equal(h.geom, 1);
        /* instance ids come first in the key */
        assert_true(rc__mesh_intersect(&t.m, &ray, 5, 2, &h));
        assert_false(rc__mesh_intersect(&t.m, &ray, 0, 4, &h));
        assert_true(rc__mesh_intersect(&t.m, &ray, 9, 0, &h));
        assert_int_equal(h.inst, 0);
        assert_int_equal(h.geom, 9);
        tmesh_free(&t);
    }
}

/* A random triangle soup plus a sphere: the BVH finds exactly what testing
 * every triangle finds (same prim, same t, same barycentrics), for both leaf
 * sizes, with finite and infinite tmax, and occlusion agrees. */
static void test_bvh_matches_brute_force(void **state)
{
    tmesh t, s;
    uint32_t i, leaf_i, hits = 0;
    (void)state;
    rng_state = 2718;
    make_uv_sphere(&s, 12, 16, 6.0f);
    tmesh_init(&t, 3 * 2500 + s.nv, 2500 + s.nt, 3);
    for (i = 0; i < 2500; ++i) {
        float c[3], sz = rng_float(0.05f, 2.0f);
        uint32_t a, b, d;
        int k;
        for (k = 0; k < 3; ++k) c[k] = rng_float(-10.0f, 10.0f);
        a = tmesh_vertex(&t, c[0], c[1], c[2]);
        b = tmesh_vertex(&t, c[0] + rng_float(-sz, sz), c[1] + rng_float(-sz, sz), c[2] + rng_float(-sz, sz));
        d = tmesh_vertex(&t, c[0] + rng_float(-sz, sz), c[1] + rng_float(-sz, sz), c[2] + rng_float(-sz, sz));
        if (i % 97 == 0) d = b; /* a few degenerate ones */
        tmesh_tri(&t, a, b, d);
    }
    for (i = 0; i < s.nv; ++i) tmesh_vertex(&t, s.v[3 * i], s.v[3 * i + 1], s.v[3 * i + 2]);
    for (i = 0; i < s.nt; ++i) tmesh_tri(&t, 2500 * 3 + s.idx[3 * i], 2500 * 3 + s.idx[3 * i + 1], 2500 * 3 + s.idx[3 * i + 2]);
    tmesh_free(&s);
    for (leaf_i = 0; leaf_i < 2; ++leaf_i) {
        tmesh_build(&t, leaf_i ? 4 : 1);
        for (i = 0; i < 6000; ++i) {
            float org[3], dir[3], tmax = i % 3 ? INFINITY : rng_float(0.5f, 20.0f);
            rc__ray ray;
            rc__hit hb, hv;
            int k, fb, fv;
            for (k = 0; k < 3; ++k) {
                org[k] = rng_float(-12.0f, 12.0f);
                dir[k] = rng_float(-1.0f, 1.0f);
            }
            if (i % 11 == 0) dir[i % 3] = 0.0f;
            if (i % 13 == 0) dir[(i + 2) % 3] = -0.0f;
            if (dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f) dir[0] = 1.0f;
            rc__ray_prepare(&ray, org, dir);
            hit_reset(&hb, tmax);
            hit_reset(&hv, tmax);
            fb = brute(&t, &ray, &hb);
            fv = rc__mesh_intersect(&t.m, &ray, 0, RC_INVALID_ID, &hv);
            assert_int_equal(fb, fv);
            assert_int_equal(rc__mesh_occluded(&t.m, &ray, tmax), fb);
            if (!fb) continue;
            ++hits;
            assert_int_equal(hb.prim, hv.prim);
            assert_true(hb.t == hv.t);
        }
    }
    assert_true(hits > 3000); /* the comparison saw plenty of hits */
    tmesh_free(&t);
}

/* Normals, bounds and a vertex stride larger than 3 (interleaved data). */
static void test_normals_bounds_stride(void **state)
{
    static const float org[3] = {0.25f, 0.25f, 0.0f}, up[3] = {0.0f, 0.0f, 1.0f};
    tmesh t;
    rc__aabb b[2];
    float n[3];
    rc__hit h;
    uint32_t i;
    (void)state;
    tmesh_init(&t, 6, 2, 5);
    for (i = 0; i < 6; ++i) t.v[5 * i + 3] = t.v[5 * i + 4] = NAN; /* not positions */
    tmesh_vertex(&t, 0.0f, 0.0f, 5.0f);
    tmesh_vertex(&t, 2.0f, 0.0f, 5.0f);
    tmesh_vertex(&t, 0.0f, 3.0f, 5.0f);
    tmesh_vertex(&t, 10.0f, 10.0f, 1.0f);
    tmesh_vertex(&t, 11.0f, 10.0f, -1.0f);
    tmesh_vertex(&t, 10.0f, 12.0f, 2.0f);
    tmesh_tri(&t, 0, 1, 2);
    tmesh_tri(&t, 3, 4, 5);
    tmesh_build(&t, 4);
    rc__mesh_triangle_normal(&t.m, 0, n);
    assert_true(n[0] == 0.0f && n[1] == 0.0f && n[2] == 6.0f);
    rc__mesh_triangle_bounds(&t.m, b);
    assert_true(b[0].min[0] == 0.0f && b[0].max[0] == 2.0f && b[0].max[1] == 3.0f);
    assert_true(b[0].min[2] == 5.0f && b[0].max[2] == 5.0f);
    assert_true(b[1].min[0] == 10.0f && b[1].max[0] == 11.0f && b[1].min[2] == -1.0f && b[1].max[2] == 2.0f);
    assert_true(cast(&t, org, up, &h));
    assert_true(h.t == 5.0f);
    assert_int_equal(h.prim, 0);
    tmesh_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ray_prepare),
        cmocka_unit_test(test_single_triangle),
        cmocka_unit_test(test_plane_distance),
        cmocka_unit_test(test_watertight_closed_meshes),
        cmocka_unit_test(test_watertight_random_rays),
        cmocka_unit_test(test_zero_area_never_hit),
        cmocka_unit_test(test_axis_parallel_box),
        cmocka_unit_test(test_coplanar_ties),
        cmocka_unit_test(test_bvh_matches_brute_force),
        cmocka_unit_test(test_normals_bounds_stride),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
