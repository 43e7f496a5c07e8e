/* rcutil: the stability cases (see stability_cases.h). One generator per case
 * fills a spec (meshes, instances, origin, rays, poses, tolerance); one runner
 * builds it in the library and in the reference tracer and checks every ray. */
#include "stability_cases.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshgen.h"
#include "poses.h"
#include "reftrace.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define MAX_MESHES 4
#define MAX_INSTS 4

typedef struct stab_inst {
    rc_pose pose;
    float scale[3];
} stab_inst;

typedef struct stab_spec {
    rcu_mesh meshes[MAX_MESHES];
    uint32_t mesh_count;
    stab_inst insts[MAX_INSTS]; /* inst_count 0: the meshes are the scene's own geometries */
    uint32_t inst_count;
    double origin[3];
    float *dirs;
    uint32_t ray_count, ray_cap;
    float rmin, rmax;
    rc_pose_d poses[16];
    uint32_t pose_count;
    double tol_abs, tol_rel;
    int check_keys;
} stab_spec;

static const char *const case_names[RCU_STAB_CASE_COUNT] = {
    "grazing", "degenerate", "on_surface", "axis_parallel", "long_short", "instance_scale", "far_origin",
    "coplanar"};
static const char *const case_about[RCU_STAB_CASE_COUNT] = {
    "rays within 0.01 deg of a large tiled plane (above, below, in it), sensor 1 cm above and on it",
    "zero-area, repeated-vertex, collinear, needle and sliver triangles mixed into a closed room; rays aimed at them",
    "sensor on a tiled plane (inside a face, on an edge, on a vertex) and 1e-6 m above it, range_min 0 and 0.1",
    "rays with exact zero components (axes, face and space diagonals) from origins on box faces, edges, vertices",
    "a 1 mm box around the sensor (ranges ~1e-3 m) and a wall 1e4 m away",
    "instances scaled 1e-3, 1e3 and non-uniformly (0.5, 3, 0.2) and rotated: ranges and normals",
    "a room 1e3, 1e4, 1e5, 1e6 m from the map origin via rc_scene_desc.origin and rc_simulate_d",
    "exact duplicate triangles within a mesh, across geometries and across instances: smallest key wins"};

const char *rcu_stab_case_name(int index)
{
    return index >= 0 && index < RCU_STAB_CASE_COUNT ? case_names[index] : NULL;
}

const char *rcu_stab_case_about(int index)
{
    return index >= 0 && index < RCU_STAB_CASE_COUNT ? case_about[index] : NULL;
}

/* ---- building blocks ---------------------------------------------------- */

static int add_ray(stab_spec *s, double x, double y, double z)
{
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0)) return 0;
    if (s->ray_count == s->ray_cap) {
        uint32_t cap = s->ray_cap ? s->ray_cap * 2 : 256;
        float *p = (float *)realloc(s->dirs, (size_t)cap * 3 * sizeof(float));
        if (!p) return -1;
        s->dirs = p;
        s->ray_cap = cap;
    }
    s->dirs[3u * s->ray_count] = (float)(x / len);
    s->dirs[3u * s->ray_count + 1] = (float)(y / len);
    s->dirs[3u * s->ray_count + 2] = (float)(z / len);
    s->ray_count++;
    return 0;
}

static int add_random_rays(stab_spec *s, uint32_t n, uint64_t seed)
{
    rcu_rng rng;
    uint32_t i;
    rcu_rng_seed(&rng, seed);
    for (i = 0; i < n; i++) {
        double z = 2.0 * rcu_rng_uniform(&rng) - 1.0, a = 2.0 * PI * rcu_rng_uniform(&rng);
        double r = sqrt(1.0 - z * z);
        if (add_ray(s, r * cos(a), r * sin(a), z) != 0) return -1;
    }
    return 0;
}

/* Rays from p towards target + jitter (uniform in a cube of half-size j). */
static int add_aimed_rays(stab_spec *s, const double p[3], const double target[3], double j, uint32_t n,
                          rcu_rng *rng)
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        double d[3];
        int k;
        for (k = 0; k < 3; k++) d[k] = target[k] + (i ? j * (2.0 * rcu_rng_uniform(rng) - 1.0) : 0.0) - p[k];
        if (add_ray(s, d[0], d[1], d[2]) != 0) return -1;
    }
    return 0;
}

static void set_pose(rc_pose_d *p, double x, double y, double z, double yaw)
{
    memset(p, 0, sizeof *p);
    p->position[0] = x;
    p->position[1] = y;
    p->position[2] = z;
    p->orientation[2] = sin(0.5 * yaw);
    p->orientation[3] = cos(0.5 * yaw);
}

/* Horizontal tiled square z = h, n x n quads, half size hs (shared vertices). */
static int grid_plane(float hs, float h, uint32_t n, rcu_mesh *m)
{
    uint32_t i, j;
    if (rcu_mesh_reserve(m, (uint64_t)(n + 1) * (n + 1), 2ull * n * n) != 0) return -1;
    for (j = 0; j <= n; j++)
        for (i = 0; i <= n; i++) {
            float *v = m->vertices + 3u * m->vertex_count++;
            v[0] = -hs + 2.0f * hs * (float)i / (float)n;
            v[1] = -hs + 2.0f * hs * (float)j / (float)n;
            v[2] = h;
        }
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            uint32_t *t = m->indices + 3u * m->triangle_count;
            t[0] = a; t[1] = b; t[2] = c;
            t[3] = a; t[4] = c; t[5] = d;
            m->triangle_count += 2;
        }
    return 0;
}

/* Appends one triangle with the given corners to m. */
static int add_tri(rcu_mesh *m, const double a[3], const double b[3], const double c[3])
{
    rcu_mesh t;
    float v[9];
    uint32_t idx[3] = {0, 1, 2};
    int k, r;
    for (k = 0; k < 3; k++) {
        v[k] = (float)a[k];
        v[3 + k] = (float)b[k];
        v[6 + k] = (float)c[k];
    }
    t.vertices = v;
    t.indices = idx;
    t.vertex_count = 3;
    t.triangle_count = 1;
    r = rcu_mesh_append(m, &t);
    return r;
}

static int append_box(rcu_mesh *m, float x0, float y0, float z0, float x1, float y1, float z1)
{
    const float lo[3] = {x0, y0, z0}, hi[3] = {x1, y1, z1};
    rcu_mesh b;
    int r;
    memset(&b, 0, sizeof b);
    if (rcu_mesh_box(lo, hi, &b) != 0) return -1;
    r = rcu_mesh_append(m, &b);
    rcu_mesh_free(&b);
    return r;
}

/* ---- the cases ----------------------------------------------------------- */
/* Each returns 1 when it filled spec for sub-run `sub`, 0 when there are no
 * more sub-runs, -1 on failure. */

static int gen_grazing(stab_spec *s, int sub, int quick)
{
    uint32_t n = quick ? 256 : 2048, i;
    rcu_rng rng;
    if (sub > 0) return 0;
    if (grid_plane(5000.0f, 0.0f, 32, &s->meshes[0]) != 0) return -1;
    s->mesh_count = 1;
    rcu_rng_seed(&rng, 11);
    for (i = 0; i < n; i++) {
        /* elevation within +-0.01 deg; every 16th exactly 0 (a zero z) */
        double e = (i % 16 == 0) ? 0.0 : (2.0 * rcu_rng_uniform(&rng) - 1.0) * 0.01 * DEG;
        double a = 2.0 * PI * rcu_rng_uniform(&rng);
        if (add_ray(s, cos(e) * cos(a), cos(e) * sin(a), i % 16 == 0 ? 0.0 : sin(e)) != 0) return -1;
    }
    set_pose(&s->poses[0], 0.0, 0.0, (double)0.01f, 0.0);
    set_pose(&s->poses[1], 123.25, -77.5, (double)0.01f, 0.3);
    set_pose(&s->poses[2], 0.0, 0.0, 0.0, 0.0);          /* on a grid vertex, in the plane */
    set_pose(&s->poses[3], 17.0, 3.0, 0.0, 1.1);         /* inside a face, in the plane */
    s->pose_count = 4;
    s->rmin = 0.0f;
    s->rmax = 1e4f;
    s->tol_abs = 1e-4;
    s->tol_rel = 1e-5;
    return 1;
}

static int gen_degenerate(stab_spec *s, int sub, int quick)
{
    uint32_t groups = quick ? 60 : 400, i;
    rcu_rng rng;
    rcu_mesh *m = &s->meshes[0];
    const double eye[3] = {0.25, 0.125, 0.5};
    if (sub > 0) return 0;
    if (append_box(m, -5, -4, -1, 5, 4, 3) != 0 || append_box(m, 1, 1, -1, 2, 2, 1) != 0) return -1;
    s->mesh_count = 1;
    rcu_rng_seed(&rng, 22);
    for (i = 0; i < groups; i++) {
        double p[3], q[3], mid[3], perp[3], c[3];
        int k, kind = (int)(i % 6);
        /* on a 1/1024 grid, so the midpoint is exact in float and the
         * collinear triangles below are exactly collinear */
        for (k = 0; k < 3; k++) {
            p[k] = floor((-4.0 + 8.0 * rcu_rng_uniform(&rng)) * 1024.0) / 1024.0;
            q[k] = p[k] + floor((rcu_rng_uniform(&rng) - 0.5) * 1024.0) / 1024.0;
        }
        p[2] = floor((-0.9 + 3.8 * rcu_rng_uniform(&rng)) * 1024.0) / 1024.0;
        if (i % 12 == 11) { /* on the wall x = 5, over its shared diagonal */
            p[0] = q[0] = 5.0;
            p[1] = -4.0 + 8.0 * (double)(i % 7) / 7.0;
            p[2] = -1.0 + 4.0 * (double)(i % 7) / 7.0;
        }
        for (k = 0; k < 3; k++) mid[k] = 0.5 * (p[k] + q[k]);
        perp[0] = -(q[1] - p[1]);
        perp[1] = q[0] - p[0];
        perp[2] = 0.3;
        switch (kind) {
        case 0: /* a point */
            if (add_tri(m, p, p, p) != 0) return -1;
            memcpy(c, p, sizeof c);
            break;
        case 1: /* a repeated vertex */
            if (add_tri(m, p, p, q) != 0) return -1;
            memcpy(c, mid, sizeof c);
            break;
        case 2: /* collinear: a vertex in the middle of the opposite edge */
            if (add_tri(m, p, q, mid) != 0) return -1;
            memcpy(c, mid, sizeof c);
            break;
        case 3: /* the collinear one in another order */
            if (add_tri(m, mid, p, q) != 0) return -1;
            for (k = 0; k < 3; k++) c[k] = 0.75 * p[k] + 0.25 * q[k];
            break;
        case 4: { /* a needle 1e-4 m wide (valid, may be hit) */
            double r3[3];
            for (k = 0; k < 3; k++) r3[k] = p[k] + 1e-4 * perp[k];
            if (add_tri(m, p, q, r3) != 0) return -1;
            for (k = 0; k < 3; k++) c[k] = (p[k] + q[k] + r3[k]) / 3.0;
            break;
        }
        default: { /* a sliver: the apex 1e-5 m off the long edge's middle */
            double r3[3];
            for (k = 0; k < 3; k++) r3[k] = mid[k] + 1e-5 * perp[k];
            if (add_tri(m, p, q, r3) != 0) return -1;
            for (k = 0; k < 3; k++) c[k] = (p[k] + q[k] + r3[k]) / 3.0;
            break;
        }
        }
        if (add_aimed_rays(s, eye, c, 0.0, 1, &rng) != 0) return -1;
        /* also at a corner of the zero-area ones (a needle's or sliver's
         * corner is ambiguous by float rounding: not aimed at) */
        if (kind < 4 && add_aimed_rays(s, eye, p, 0.0, 1, &rng) != 0) return -1;
    }
    if (add_random_rays(s, quick ? 200 : 2000, 23) != 0) return -1;
    set_pose(&s->poses[0], eye[0], eye[1], eye[2], 0.0);
    s->pose_count = 1;
    s->rmin = 0.0f;
    s->rmax = 100.0f;
    s->tol_abs = 1e-5;
    s->tol_rel = 1e-6;
    return 1;
}

static int gen_on_surface(stab_spec *s, int sub, int quick)
{
    if (sub > 1) return 0;
    if (grid_plane(20.0f, 0.0f, 8, &s->meshes[0]) != 0) return -1;
    if (append_box(&s->meshes[0], -25, -25, -1, 25, 25, 5) != 0) return -1;
    s->mesh_count = 1;
    if (add_random_rays(s, quick ? 300 : 2000, 33) != 0) return -1;
    set_pose(&s->poses[0], 0.5, 0.25, 0.0, 0.0);   /* inside a face */
    set_pose(&s->poses[1], 2.5, 0.0, 0.0, 0.4);    /* on a quad's diagonal? no: on an edge of the grid */
    set_pose(&s->poses[2], 0.0, 0.0, 0.0, 0.0);    /* on a vertex */
    set_pose(&s->poses[3], 0.5, 0.25, (double)1e-6f, 0.0);
    set_pose(&s->poses[4], 5.0, 5.0, (double)1e-6f, 0.9);
    set_pose(&s->poses[5], 1.25, 1.25, 0.0, 0.0);  /* on a quad's diagonal */
    s->pose_count = 6;
    s->rmin = sub == 0 ? 0.0f : 0.1f;
    s->rmax = 100.0f;
    s->tol_abs = 1e-5;
    s->tol_rel = 1e-6;
    return 1;
}

static int gen_axis_parallel(stab_spec *s, int sub, int quick)
{
    rcu_mesh *m = &s->meshes[0];
    int x, y, z;
    (void)quick;
    if (sub > 0) return 0;
    if (append_box(m, -8, -6, -2, 8, 6, 4) != 0 || append_box(m, 1, 1, 0, 2, 2, 1) != 0 ||
        append_box(m, -3, -1, -1, -2, 1, 0.5f) != 0 || append_box(m, 2, -2, 0, 3, -1, 1) != 0)
        return -1;
    s->mesh_count = 1;
    for (x = -1; x <= 1; x++)
        for (y = -1; y <= 1; y++)
            for (z = -1; z <= 1; z++)
                if ((x || y || z) && add_ray(s, x, y, z) != 0) return -1;
    set_pose(&s->poses[0], 0.0, 0.0, 0.0, 0.0);
    set_pose(&s->poses[1], 0.0, 1.0, 0.5, 0.0);   /* in the plane y = 1 of box A's face */
    set_pose(&s->poses[2], 1.5, 0.0, 1.0, 0.0);   /* in the plane of A's top */
    set_pose(&s->poses[3], 0.0, 2.0, 1.0, 0.0);   /* on the line of A's top back edge */
    set_pose(&s->poses[4], -2.5, 1.0, 0.0, 0.0);  /* on B's face y = 1 (in its plane, outside) */
    set_pose(&s->poses[5], 0.0, -1.0, 0.0, 0.0);  /* on the line of C's bottom edge y=-1 z=0 */
    set_pose(&s->poses[6], 1.0, 1.0, 1.0, 0.0);   /* on A's corner */
    set_pose(&s->poses[7], 2.0, -1.5, 0.5, 0.0);  /* on C's face x = 2 */
    set_pose(&s->poses[8], 0.0, 0.0, 4.0, 0.0);   /* on the room's ceiling */
    s->pose_count = 9;
    s->rmin = 0.0f;
    s->rmax = 100.0f;
    s->tol_abs = 1e-5;
    s->tol_rel = 1e-6;
    return 1;
}

static int gen_long_short(stab_spec *s, int sub, int quick)
{
    rcu_mesh *m = &s->meshes[0];
    const float p0[3] = {1e4f, -5e3f, -5e3f}, p1[3] = {1e4f, 5e3f, -5e3f}, p2[3] = {1e4f, 5e3f, 5e3f},
                p3[3] = {1e4f, -5e3f, 5e3f};
    rcu_mesh wall;
    rcu_rng rng;
    uint32_t i, n = quick ? 200 : 1000;
    if (sub > 0) return 0;
    memset(&wall, 0, sizeof wall);
    if (append_box(m, -1e-3f, -1e-3f, -1e-3f, 1e-3f, 1e-3f, 1e-3f) != 0) return -1;
    if (rcu_mesh_quad(p0, p1, p2, p3, &wall) != 0 || rcu_mesh_append(m, &wall) != 0) {
        rcu_mesh_free(&wall);
        return -1;
    }
    rcu_mesh_free(&wall);
    s->mesh_count = 1;
    /* rays: a 20 deg cone about +x; seen from inside the box they hit it,
     * from outside the far wall */
    rcu_rng_seed(&rng, 44);
    for (i = 0; i < n; i++) {
        double a = 20.0 * DEG * sqrt(rcu_rng_uniform(&rng)), b = 2.0 * PI * rcu_rng_uniform(&rng);
        if (add_ray(s, cos(a), sin(a) * cos(b), sin(a) * sin(b)) != 0) return -1;
    }
    if (add_random_rays(s, n, 45) != 0) return -1; /* all around: from inside, the box */
    set_pose(&s->poses[0], 0.0, 0.0, 0.0, 0.0);
    set_pose(&s->poses[1], (double)2.5e-4f, (double)-5e-4f, (double)1e-4f, 0.0);
    set_pose(&s->poses[2], 1.0, 0.0, 0.0, 0.0); /* outside the box: the cone reaches the wall */
    s->pose_count = 3;
    s->rmin = 0.0f;
    s->rmax = 2e4f;
    s->tol_abs = 1e-7;
    s->tol_rel = 3e-7;
    return 1;
}

static int gen_instance_scale(stab_spec *s, int sub, int quick)
{
    rcu_mesh *cube = &s->meshes[0], *ball = &s->meshes[1];
    const double eye[3] = {0.125, 0.25, 0.375};
    const double tiny_c[3] = {3.0, 0.0, 0.25}, odd_c[3] = {-2.0, 1.0, 0.0};
    rcu_rng rng;
    uint32_t n = quick ? 100 : 600;
    if (sub > 0) return 0;
    if (append_box(cube, -0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f) != 0) return -1;
    if (rcu_mesh_uv_sphere(0.25f, 16, 8, ball) != 0) return -1;
    {
        const float t[3] = {0.0f, 0.0f, 0.75f}; /* the ball sits on the cube */
        rcu_mesh_transform(ball, 0.0f, t);
    }
    s->mesh_count = 2;
    /* 0: huge (a 1 km room around the sensor), 1: tiny (1 mm cube), 2: non-uniform, rotated */
    memset(s->insts, 0, sizeof s->insts);
    s->insts[0].pose.orientation[3] = 1.0f;
    s->insts[0].scale[0] = s->insts[0].scale[1] = s->insts[0].scale[2] = 1e3f;
    s->insts[1].pose.position[0] = (float)tiny_c[0];
    s->insts[1].pose.position[2] = (float)tiny_c[2];
    s->insts[1].pose.orientation[2] = (float)sin(0.2);
    s->insts[1].pose.orientation[3] = (float)cos(0.2);
    s->insts[1].scale[0] = s->insts[1].scale[1] = s->insts[1].scale[2] = 1e-3f;
    s->insts[2].pose.position[0] = (float)odd_c[0];
    s->insts[2].pose.position[1] = (float)odd_c[1];
    {
        /* yaw 0.7 then pitch 0.3: q = qz(0.7) * qy(0.3) */
        double cz = cos(0.35), sz = sin(0.35), cy = cos(0.15), sy = sin(0.15);
        s->insts[2].pose.orientation[0] = (float)(-sz * sy);
        s->insts[2].pose.orientation[1] = (float)(cz * sy);
        s->insts[2].pose.orientation[2] = (float)(sz * cy);
        s->insts[2].pose.orientation[3] = (float)(cz * cy);
    }
    s->insts[2].scale[0] = 0.5f;
    s->insts[2].scale[1] = 3.0f;
    s->insts[2].scale[2] = 0.2f;
    s->inst_count = 3;
    rcu_rng_seed(&rng, 55);
    if (add_aimed_rays(s, eye, tiny_c, 4e-4, n, &rng) != 0) return -1;
    {
        const double ball_c[3] = {tiny_c[0], tiny_c[1], tiny_c[2] + 0.75e-3};
        if (add_aimed_rays(s, eye, ball_c, 2e-4, n / 2, &rng) != 0) return -1;
    }
    if (add_aimed_rays(s, eye, odd_c, 0.6, n, &rng) != 0) return -1;
    if (add_random_rays(s, n, 56) != 0) return -1;
    set_pose(&s->poses[0], eye[0], eye[1], eye[2], 0.0);
    s->pose_count = 1;
    s->rmin = 0.0f;
    s->rmax = 2000.0f;
    s->tol_abs = 1e-5;
    s->tol_rel = 1e-6;
    return 1;
}

static int gen_far_origin(stab_spec *s, int sub, int quick)
{
    static const double offsets[4] = {1e3, 1e4, 1e5, 1e6};
    rcu_mesh *m = &s->meshes[0];
    double off;
    uint32_t i;
    if (sub >= 4) return 0;
    off = offsets[sub];
    if (append_box(m, -6, -4, 0, 6, 4, 3) != 0 || append_box(m, 1, 1, 0, 2, 2, 1) != 0) return -1;
    {
        const float lo[3] = {-4, -3, 0}, hi[3] = {-2, -1, 0.8f};
        rcu_mesh w;
        memset(&w, 0, sizeof w);
        if (rcu_mesh_wedge(lo, hi, &w) != 0 || rcu_mesh_append(m, &w) != 0) {
            rcu_mesh_free(&w);
            return -1;
        }
        rcu_mesh_free(&w);
    }
    s->mesh_count = 1;
    s->origin[0] = off + 0.123;
    s->origin[1] = off * 0.5 + 0.456;
    s->origin[2] = 30.0;
    if (add_random_rays(s, quick ? 256 : 2048, 66) != 0) return -1;
    for (i = 0; i < 4; i++)
        set_pose(&s->poses[i], s->origin[0] + 1.0000005 - 0.5 * i, s->origin[1] + 0.5000007 * i,
                 s->origin[2] + 1.25, 0.4 * i);
    s->pose_count = 4;
    s->rmin = 0.0f;
    s->rmax = 100.0f;
    s->tol_abs = 1e-3; /* the bound; expect ~1e-5 */
    s->tol_rel = 0.0;
    return 1;
}

static int gen_coplanar(stab_spec *s, int sub, int quick)
{
    rcu_mesh wall;
    uint32_t i, n = quick ? 128 : 1024;
    rcu_rng rng;
    if (sub > 1) return 0;
    memset(&wall, 0, sizeof wall);
    if (grid_plane(10.0f, 0.0f, 4, &wall) != 0) return -1;
    {   /* stand it up: the plane x = 3 (rotate z -> x: (x, y, z) -> (z + 3, y, x)) */
        uint32_t v;
        for (v = 0; v < wall.vertex_count; v++) {
            float *p = wall.vertices + 3u * v, x = p[0];
            p[0] = p[2] + 3.0f;
            p[2] = x;
        }
    }
    if (sub == 0) {
        /* geom 0: the wall; geom 1: the wall twice (duplicates within and across) */
        if (rcu_mesh_append(&s->meshes[0], &wall) != 0 || rcu_mesh_append(&s->meshes[1], &wall) != 0 ||
            rcu_mesh_append(&s->meshes[1], &wall) != 0)
            goto fail;
        s->mesh_count = 2;
    } else {
        /* one source geometry with the wall twice, three instances at one transform */
        if (rcu_mesh_append(&s->meshes[0], &wall) != 0 || rcu_mesh_append(&s->meshes[0], &wall) != 0) goto fail;
        s->mesh_count = 1;
        memset(s->insts, 0, sizeof s->insts);
        for (i = 0; i < 3; i++) {
            s->insts[i].pose.position[0] = 0.5f;
            s->insts[i].pose.orientation[2] = (float)sin(0.1);
            s->insts[i].pose.orientation[3] = (float)cos(0.1);
            s->insts[i].scale[0] = s->insts[i].scale[1] = s->insts[i].scale[2] = 1.0f;
        }
        s->inst_count = 3;
    }
    rcu_mesh_free(&wall);
    rcu_rng_seed(&rng, 77);
    for (i = 0; i < n; i++) {
        /* include rays through the grid's vertices and edges */
        /* inner edges and vertices only: the outer boundary is a silhouette,
         * where a float-rounded ray may fall either side */
        double y = (i % 8 == 0) ? 5.0 * (double)(int)(i % 3) - 5.0 : 16.0 * rcu_rng_uniform(&rng) - 8.0;
        double z = (i % 4 == 0) ? 5.0 * (double)(int)((i / 4) % 3) - 5.0 : 16.0 * rcu_rng_uniform(&rng) - 8.0;
        if (add_ray(s, 3.0, y, z) != 0) return -1;
    }
    set_pose(&s->poses[0], 0.0, 0.0, 0.0, 0.0);
    s->pose_count = 1;
    s->rmin = 0.0f;
    s->rmax = 100.0f;
    s->tol_abs = 1e-5;
    s->tol_rel = 1e-6;
    s->check_keys = 1;
    return 1;
fail:
    rcu_mesh_free(&wall);
    return -1;
}

typedef int (*gen_fn)(stab_spec *s, int sub, int quick);
static const gen_fn generators[RCU_STAB_CASE_COUNT] = {
    gen_grazing, gen_degenerate, gen_on_surface, gen_axis_parallel, gen_long_short, gen_instance_scale,
    gen_far_origin, gen_coplanar};

static void spec_free(stab_spec *s)
{
    uint32_t i;
    for (i = 0; i < MAX_MESHES; i++) rcu_mesh_free(&s->meshes[i]);
    free(s->dirs);
    memset(s, 0, sizeof *s);
}

/* ---- the runner ----------------------------------------------------------- */

static void quat_matrix(const double q_in[4], double r[3][3])
{
    double n = sqrt(q_in[0] * q_in[0] + q_in[1] * q_in[1] + q_in[2] * q_in[2] + q_in[3] * q_in[3]);
    double x = q_in[0] / n, y = q_in[1] / n, z = q_in[2] / n, w = q_in[3] / n;
    r[0][0] = 1 - 2 * (y * y + z * z);
    r[0][1] = 2 * (x * y - z * w);
    r[0][2] = 2 * (x * z + y * w);
    r[1][0] = 2 * (x * y + z * w);
    r[1][1] = 1 - 2 * (x * x + z * z);
    r[1][2] = 2 * (y * z - x * w);
    r[2][0] = 2 * (x * z - y * w);
    r[2][1] = 2 * (y * z + x * w);
    r[2][2] = 1 - 2 * (x * x + y * y);
}

typedef struct flat_scene {
    double *v;            /* map coordinates */
    uint32_t *idx;
    uint32_t vcount, tcount;
    uint32_t geom_base[MAX_MESHES];
    uint32_t inst_stride; /* triangles of one instance (all geometries) */
    uint32_t *canon;      /* check_keys: smallest flat index of an identical triangle */
} flat_scene;

/* canon[t]: the smallest index of a triangle with the same three corners in
 * the same order (O(n^2): the cases that check keys are small). */
static int canonical_duplicates(flat_scene *f)
{
    uint32_t t, u;
    f->canon = (uint32_t *)malloc((size_t)f->tcount * sizeof(uint32_t));
    if (!f->canon) return -1;
    for (t = 0; t < f->tcount; t++) {
        f->canon[t] = t;
        for (u = 0; u < t; u++) {
            int k, same = 1;
            for (k = 0; k < 9 && same; k++)
                same = f->v[3u * (size_t)f->idx[3u * t + (uint32_t)k / 3] + (uint32_t)k % 3] ==
                       f->v[3u * (size_t)f->idx[3u * u + (uint32_t)k / 3] + (uint32_t)k % 3];
            if (same) {
                f->canon[t] = u;
                break;
            }
        }
    }
    return 0;
}

static int flatten(const stab_spec *s, flat_scene *f)
{
    uint32_t copies = s->inst_count ? s->inst_count : 1, c, g, vtot = 0, ttot = 0, vb = 0, tb = 0;
    memset(f, 0, sizeof *f);
    for (g = 0; g < s->mesh_count; g++) {
        f->geom_base[g] = ttot;
        vtot += s->meshes[g].vertex_count;
        ttot += s->meshes[g].triangle_count;
    }
    f->inst_stride = ttot;
    f->v = (double *)malloc((size_t)vtot * copies * 3 * sizeof(double));
    f->idx = (uint32_t *)malloc((size_t)ttot * copies * 3 * sizeof(uint32_t));
    if (!f->v || !f->idx) return -1;
    for (c = 0; c < copies; c++) {
        double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, t[3] = {0, 0, 0}, sc[3] = {1, 1, 1};
        int k;
        if (s->inst_count) {
            const stab_inst *in = &s->insts[c];
            double q[4];
            for (k = 0; k < 4; k++) q[k] = in->pose.orientation[k];
            quat_matrix(q, r);
            for (k = 0; k < 3; k++) {
                t[k] = in->pose.position[k];
                sc[k] = in->scale[k];
            }
        }
        for (g = 0; g < s->mesh_count; g++) {
            const rcu_mesh *m = &s->meshes[g];
            uint32_t i;
            for (i = 0; i < m->vertex_count; i++) {
                double p[3];
                double *o = f->v + 3u * (size_t)(vb + i);
                for (k = 0; k < 3; k++) p[k] = sc[k] * (double)m->vertices[3u * i + (uint32_t)k];
                for (k = 0; k < 3; k++)
                    o[k] = r[k][0] * p[0] + r[k][1] * p[1] + r[k][2] * p[2] + t[k] + s->origin[k];
            }
            for (i = 0; i < 3u * m->triangle_count; i++) f->idx[3u * (size_t)tb + i] = m->indices[i] + vb;
            vb += m->vertex_count;
            tb += m->triangle_count;
        }
    }
    f->vcount = vb;
    f->tcount = tb;
    return 0;
}

static void note(rcu_stab_result *out, uint32_t pose, uint32_t ray, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void note(rcu_stab_result *out, uint32_t pose, uint32_t ray, const char *fmt, ...)
{
    va_list ap;
    size_t len;
    if (out->note[0]) return;
    va_start(ap, fmt);
    vsnprintf(out->note, sizeof out->note, fmt, ap);
    va_end(ap);
    len = strlen(out->note);
    snprintf(out->note + len, sizeof out->note - len, " (pose %u ray %u)", pose, ray);
}

static int run_spec(const stab_spec *s, const rcu_stab_options *opt, rcu_stab_result *out)
{
    rc_context_desc cd = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_scene *src = NULL, *top = NULL;
    rc_sensor *sensor = NULL;
    rc_results res = rc_results_default();
    flat_scene f;
    rcu_reftrace *ref = NULL;
    uint64_t n = (uint64_t)s->pose_count * s->ray_count, e;
    uint8_t *hits = NULL;
    float *ranges = NULL, *points = NULL, *normals = NULL;
    uint32_t *prims = NULL, *geoms = NULL, *insts = NULL, g, p;
    rc_status st = RC_OK;
    const char *call = "";
    int rc = -1;
    memset(&f, 0, sizeof f);
    if (flatten(s, &f) != 0 || (s->check_keys && canonical_duplicates(&f) != 0) ||
        rcu_reftrace_build_d(f.v, f.vcount, f.idx, f.tcount, &ref) != 0) {
        snprintf(out->note, sizeof out->note, "reference: %s", rcu_last_error());
        goto done;
    }
    hits = (uint8_t *)malloc(n);
    ranges = (float *)malloc(n * sizeof(float));
    points = (float *)malloc(n * 3 * sizeof(float));
    normals = (float *)malloc(n * 3 * sizeof(float));
    prims = (uint32_t *)malloc(n * sizeof(uint32_t));
    geoms = (uint32_t *)malloc(n * sizeof(uint32_t));
    insts = (uint32_t *)malloc(n * sizeof(uint32_t));
    if (!hits || !ranges || !points || !normals || !prims || !geoms || !insts) {
        snprintf(out->note, sizeof out->note, "out of memory");
        goto done;
    }
    cd.backend = opt->backend;
    cd.flags = opt->context_flags;
    cd.thread_count = opt->threads;
    cd.memory_size = (size_t)64 << 20;
#define LIB(expr)                              \
    do {                                       \
        call = #expr;                          \
        if ((st = (expr)) != RC_OK) goto fail; \
    } while (0)
    LIB(rc_context_create(&cd, &ctx));
    if (opt->configure) opt->configure(ctx, opt->configure_user);
    {
        rc_scene_desc sd = rc_scene_desc_default();
        sd.max_geometries = s->mesh_count;
        sd.max_triangles = f.inst_stride;
        if (!s->inst_count) memcpy(sd.origin, s->origin, sizeof sd.origin);
        LIB(rc_scene_create(ctx, &sd, &src));
        for (g = 0; g < s->mesh_count; g++) {
            rc_mesh_desc md = rc_mesh_desc_default();
            uint32_t id = 0;
            md.vertices = s->meshes[g].vertices;
            md.vertex_count = s->meshes[g].vertex_count;
            md.indices = s->meshes[g].indices;
            md.triangle_count = s->meshes[g].triangle_count;
            LIB(rc_scene_add_mesh(src, &md, &id));
        }
        LIB(rc_scene_commit(src));
        top = src;
        if (s->inst_count) {
            rc_scene_desc td = rc_scene_desc_default();
            uint32_t i, id;
            td.max_geometries = 1;
            td.max_instances = s->inst_count;
            memcpy(td.origin, s->origin, sizeof td.origin);
            LIB(rc_scene_create(ctx, &td, &top));
            for (i = 0; i < s->inst_count; i++) {
                rc_instance_desc id_ = rc_instance_desc_default();
                id_.source = src;
                id_.transform = s->insts[i].pose;
                memcpy(id_.scale, s->insts[i].scale, sizeof id_.scale);
                LIB(rc_scene_add_instance(top, &id_, &id));
            }
            LIB(rc_scene_commit(top));
        }
    }
    {
        rc_rays_desc rd = rc_rays_desc_default();
        rd.common.range_min = s->rmin;
        rd.common.range_max = s->rmax;
        rd.directions = s->dirs;
        rd.ray_count = s->ray_count;
        LIB(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &sensor));
    }
    res.attributes = RC_ATTR_ALL;
    res.capacity = n;
    res.hits = hits;
    res.ranges = ranges;
    res.points = points;
    res.normals = normals;
    res.prim_ids = prims;
    res.geom_ids = geoms;
    res.inst_ids = insts;
    LIB(rc_simulate_d(ctx, top, sensor, s->poses, s->pose_count, &res));
#undef LIB
    for (p = 0; p < s->pose_count; p++) {
        double r[3][3];
        uint32_t ray;
        quat_matrix(s->poses[p].orientation, r);
        for (ray = 0; ray < s->ray_count; ray++) {
            double ds[3], d[3], t = 0.0, len;
            uint32_t prim = 0, lib_prim = UINT32_MAX;
            int k, found, rcl, lcl, bad = 0;
            e = (uint64_t)p * s->ray_count + ray;
            for (k = 0; k < 3; k++) ds[k] = s->dirs[3u * ray + (uint32_t)k];
            len = sqrt(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2]);
            for (k = 0; k < 3; k++) ds[k] /= len;
            for (k = 0; k < 3; k++) d[k] = r[k][0] * ds[0] + r[k][1] * ds[1] + r[k][2] * ds[2];
            found = rcu_reftrace_nearest(ref, s->poses[p].position, d, s->rmax, &t, &prim);
            rcl = !found ? 0 : (t < s->rmin ? -1 : 1);
            lcl = ranges[e] == INFINITY ? 0 : ranges[e] == -INFINITY ? -1 : 1;
            out->rays++;
            if (lcl == 1 && hits[e]) {
                /* ids -> flat index */
                uint32_t gi = geoms[e], ii = insts[e];
                int ok = gi < s->mesh_count && prims[e] < s->meshes[gi < MAX_MESHES ? gi : 0].triangle_count &&
                         (s->inst_count ? ii < s->inst_count : ii == RC_INVALID_ID);
                if (!ok) {
                    out->key_mismatch++;
                    bad = 1;
                    note(out, p, ray, "ids out of range: geom %u prim %u inst %u", gi, prims[e], ii);
                } else {
                    lib_prim = (s->inst_count ? ii * f.inst_stride : 0) + f.geom_base[gi] + prims[e];
                    if (rcu_reftrace_degenerate(ref, lib_prim)) {
                        out->degenerate_hits++;
                        bad = 1;
                        note(out, p, ray, "hit on zero-area triangle %u at range %g", lib_prim, (double)ranges[e]);
                    }
                }
            }
            if (!isnan(ranges[e]) && (lcl == 1) != (hits[e] != 0)) {
                out->class_mismatch++;
                bad = 1;
                note(out, p, ray, "hit flag %u with range %g", (unsigned)hits[e], (double)ranges[e]);
            }
            if (isnan(ranges[e])) {
                out->nan_outputs++;
                bad = 1;
                note(out, p, ray, "NaN range");
            } else if (rcl != lcl) {
                out->class_mismatch++;
                bad = 1;
                note(out, p, ray, "library range %g, reference %g (class %d)", (double)ranges[e], found ? t : INFINITY, rcl);
            } else if (rcl == 1) {
                double err = fabs((double)ranges[e] - t), nref[3], ns[3], nl[3], nlen, dot, face;
                if (err > out->max_err) out->max_err = err;
                if (err > s->tol_abs + s->tol_rel * t) {
                    out->range_errors++;
                    bad = 1;
                    note(out, p, ray, "range %.9g, reference %.9g (error %.3g; flat triangle %u, reference %u)",
                         (double)ranges[e], t, err, lib_prim, prim);
                }
                for (k = 0; k < 3; k++) {
                    nl[k] = normals[3 * e + (uint64_t)k];
                    if (!isfinite(nl[k]) || !isfinite(points[3 * e + (uint64_t)k])) {
                        out->nan_outputs++;
                        bad = 1;
                        note(out, p, ray, "non-finite point or normal at range %g", (double)ranges[e]);
                        break;
                    }
                }
                if (k == 3) {
                    /* the reference normal of the triangle the library hit (ties: same plane) */
                    rcu_reftrace_normal(ref, lib_prim != UINT32_MAX ? lib_prim : prim, nref);
                    for (k = 0; k < 3; k++) ns[k] = r[0][k] * nref[0] + r[1][k] * nref[1] + r[2][k] * nref[2];
                    nlen = sqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
                    dot = (nl[0] * ns[0] + nl[1] * ns[1] + nl[2] * ns[2]) / (nlen > 0 ? nlen : 1);
                    face = nl[0] * ds[0] + nl[1] * ds[1] + nl[2] * ds[2];
                    if (fabs(nlen - 1.0) > 1e-4 || fabs(dot) < 1.0 - 1e-5 || face > 1e-6) {
                        out->bad_normals++;
                        bad = 1;
                        note(out, p, ray, "normal |n| %.7f, |n.n_ref| %.7f, n.d %.3g", nlen, fabs(dot), face);
                    }
                }
                if (s->check_keys && lib_prim != UINT32_MAX && f.canon[lib_prim] != lib_prim) {
                    out->key_mismatch++;
                    bad = 1;
                    note(out, p, ray, "hit flat triangle %u, an exact copy of %u (the smaller key)", lib_prim,
                         f.canon[lib_prim]);
                }
            }
            if (bad) out->wrong++;
        }
    }
    rc = 0;
    goto done;
fail:
    snprintf(out->note, sizeof out->note, "%s -> %s: %s", call, rc_status_string(st),
             ctx ? rc_context_last_error(ctx) : "");
done:
    rc_context_destroy(ctx);
    rcu_reftrace_free(ref);
    free(f.v);
    free(f.idx);
    free(f.canon);
    free(hits);
    free(ranges);
    free(points);
    free(normals);
    free(prims);
    free(geoms);
    free(insts);
    return rc;
}

int rcu_stab_run(int index, const rcu_stab_options *opt, rcu_stab_result *out)
{
    int sub;
    memset(out, 0, sizeof *out);
    if (index < 0 || index >= RCU_STAB_CASE_COUNT) {
        snprintf(out->note, sizeof out->note, "no case %d", index);
        return -1;
    }
    for (sub = 0;; sub++) {
        stab_spec s;
        int r;
        memset(&s, 0, sizeof s);
        r = generators[index](&s, sub, opt->quick);
        if (r == 0) {
            spec_free(&s);
            break;
        }
        if (r < 0) {
            snprintf(out->note, sizeof out->note, "generator: %s", rcu_last_error());
            spec_free(&s);
            return -1;
        }
        out->tol_abs = s.tol_abs;
        out->tol_rel = s.tol_rel;
        r = run_spec(&s, opt, out);
        spec_free(&s);
        if (r != 0) return -1;
    }
    return 0;
}
