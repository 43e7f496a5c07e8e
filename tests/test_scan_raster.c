/* Projected scans (bvh/scan_raster.h): a spherical, cylindrical or pinhole
 * scan traced triangle by triangle must give every ray the hit the tree's
 * single-ray search gives, bit for bit (t, triangle, hit or not), and each
 * hit's distance refined in double as the writer refines the tree's. Checked
 * on spherical grids that wrap, overlap themselves (more than a turn of
 * columns), run backwards, reach within 0.07 rad of the poles, or hold one
 * row or one column, and cylindrical ones (a panorama, one running backwards
 * from 73 degrees up to 83 down, one row), and pinhole ones (body and
 * optical frames, a principal point off the image, a long lens, a 143
 * degree one, one row, one column); whole, and in bands of rows; in a
 * coarse sphere with
 * the sensor close to its wall (a triangle's bounding sphere around the
 * origin), in a box room with the ceiling across the z axis (a pole inside
 * a triangle), with the sensor in the floor's plane and with rays through
 * the walls' diagonals (the test's double-precision cases), on a mesh whose
 * zero-area triangles are left unfolded (no ray here rounds into one, so
 * that only shows they change nothing), under turned poses and a mounting,
 * with range limits that cut triangles off, with and without the mesh's
 * tree, and with every triangle twice (ties); a long lens on a wall of
 * tiny triangles whose corners lie on its pixels' rays; scenes of two to
 * four meshes (each mesh's tree searched in turn; copies of meshes and twins
 * within one, so hits tie across meshes and within one); and the
 * placement's atan2 against libm's. Then through rc_simulate (a VLP-16, the
 * cylindrical panorama and the first camera) on a room as one mesh and as
 * three: every attribute of a call that takes the projected scan equals,
 * byte for byte, a context without arena room for its scratch (the packets),
 * on 1 and 3 threads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "backend/backend.h"
#include "bvh/intersect.h"
#include "bvh/scan_cone.h"
#include "bvh/scan_raster.h"
#include "core/context.h"
#include "rc_test.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

#if defined(RC__PROJECTED_SCANS)
typedef struct grid_case {
    float theta_min, theta_inc;
    uint32_t cols;
    float phi_min, phi_inc;
    uint32_t rows;
} grid_case;

static const grid_case grids[] = {
    {-3.14159265f, 0.00698132f, 900u, -0.261799f, 0.0349066f, 16u}, /* VLP-16 */
    {2.0f, -0.05f, 150u, -1.5f, 0.1f, 31u},                        /* backwards, 7.5 rad, near the poles */
    {-0.5f, 0.01f, 37u, 0.3f, 0.0f, 1u},                           /* one row, a part of a turn */
    {2.9f, 0.0f, 1u, -0.2f, 0.07f, 7u},                            /* one column */
    {-1.0f, 0.013f, 500u, 1.0f, -0.11f, 23u},                      /* rows downwards to -1.42 */
};

/* Cylindrical grids: rows at heights (cy - v) / fy on a unit cylinder. */
typedef struct cyl_case {
    float theta_min, theta_inc;
    uint32_t cols;
    uint32_t height;
    float fy, cy;
} cyl_case;

static const cyl_case cyls[] = {
    {-3.14159265f, 0.0087266f, 720u, 64u, 40.0f, 31.5f}, /* a panorama, +-38 degrees */
    {1.0f, -0.02f, 200u, 90u, 6.0f, 20.0f},              /* backwards, 73 degrees up to 83 down */
    {0.3f, 0.01f, 50u, 1u, 10.0f, -3.0f},                /* one row, 17 degrees up */
};

/* Pinhole grids: pixel (v, u) along optical ((u - cx) / fx, (v - cy) / fy, 1). */
typedef struct cam_case {
    uint32_t width, height;
    float fx, fy, cx, cy;
    uint32_t frame;
} cam_case;

static const cam_case cams[] = {
    {64u, 48u, 40.0f, 40.0f, 31.5f, 24.0f, RC_PINHOLE_FRAME_BODY},      /* a depth camera's 77 x 62 degrees */
    {50u, 30u, 30.0f, 45.0f, -10.0f, 40.0f, RC_PINHOLE_FRAME_OPTICAL}, /* the principal point off the image */
    {40u, 30u, 2000.0f, 2000.0f, 20.0f, 15.0f, RC_PINHOLE_FRAME_BODY}, /* a long lens: 1.1 degrees */
    {60u, 40u, 10.0f, 10.0f, 29.5f, 19.5f, RC_PINHOLE_FRAME_OPTICAL},  /* 143 x 126 degrees */
    {40u, 1u, 25.0f, 25.0f, 19.0f, 0.3f, RC_PINHOLE_FRAME_BODY},       /* one row */
    {1u, 25u, 25.0f, 20.0f, 0.0f, 12.0f, RC_PINHOLE_FRAME_OPTICAL},    /* one column */
};

#define NGRIDS (uint32_t)(sizeof grids / sizeof grids[0])
#define NCYLS (uint32_t)(sizeof cyls / sizeof cyls[0])
#define NCAMS (uint32_t)(sizeof cams / sizeof cams[0])

/* The range limits, a mounting (NULL: none) and the columns' azimuths. */
static void set_common(rc_sensor_common *c, rc_angle_axis *theta, float rmin, float rmax, const rc_pose *mount,
                       float theta_min, float theta_inc, uint32_t cols)
{
    c->range_min = rmin;
    c->range_max = rmax;
    if (mount) c->sensor_to_base = *mount;
    theta->min = theta_min;
    theta->increment = theta_inc;
    theta->count = cols;
}

static rc_sensor *cyl_sensor(rc_context *ctx, const cyl_case *cc, float rmin, float rmax, const rc_pose *mount)
{
    rc_cylindrical_desc d = rc_cylindrical_desc_default();
    rc_sensor *s = NULL;
    set_common(&d.common, &d.theta, rmin, rmax, mount, cc->theta_min, cc->theta_inc, cc->cols);
    d.height = cc->height;
    d.fy = cc->fy;
    d.cy = cc->cy;
    RCT_OK(ctx, rc_sensor_create_cylindrical(ctx, &d, &s));
    return s;
}

static rc_sensor *cam_sensor(rc_context *ctx, const cam_case *cc, float rmin, float rmax, const rc_pose *mount)
{
    rc_pinhole_desc d = rc_pinhole_desc_default();
    rc_angle_axis unused;
    rc_sensor *s = NULL;
    set_common(&d.common, &unused, rmin, rmax, mount, 0.0f, 0.0f, 0u);
    d.frame = cc->frame;
    d.width = cc->width;
    d.height = cc->height;
    d.fx = cc->fx;
    d.fy = cc->fy;
    d.cx = cc->cx;
    d.cy = cc->cy;
    RCT_OK(ctx, rc_sensor_create_pinhole(ctx, &d, &s));
    return s;
}

static rc_sensor *grid_sensor(rc_context *ctx, const grid_case *gc, float rmin, float rmax, const rc_pose *mount)
{
    rc_spherical_desc d = rc_spherical_desc_default();
    rc_sensor *s = NULL;
    set_common(&d.common, &d.theta, rmin, rmax, mount, gc->theta_min, gc->theta_inc, gc->cols);
    d.phi.min = gc->phi_min;
    d.phi.increment = gc->phi_inc;
    d.phi.count = gc->rows;
    RCT_OK(ctx, rc_sensor_create_spherical(ctx, &d, &s));
    return s;
}

/* 1: check_pose's projected scans without the mesh's tree */
static int flat;
/* rows a band of check_pose's scans (0: the whole scan at once) */
static uint32_t band_rows;

/* The projected scan of rows [row0, row0 + rows) of g into hits, found and
 * td (the whole scan's arrays), its hits in runs of 37 rays (the last one
 * shorter). */
#define MAX_MESHES 4u

static void scan_band(const rc_scene *scene, const rc_sensor *s, const rc__raster_grid *g, const rc__xformf *world,
                      uint32_t row0, uint32_t rows, rc__hit *hits, int *found, double *td)
{
    const uint32_t base = row0 * g->cols, n_rays = rows * g->cols, count = scene->geom_count;
    const float *dirs = s->directions + (size_t)base * 3u;
    void *scratch = malloc(rc__raster_scratch_bytes(n_rays));
    const rc__mesh *meshes[MAX_MESHES];
    rc__mesh bare[MAX_MESHES];
    rc__raster_grid band;
    uint32_t i;
    assert_non_null(scratch);
    assert_true(count >= 1u && count <= MAX_MESHES);
    for (i = 0; i < count; ++i) {
        /* flat: without the trees (meshes no built-in commit made), every
         * triangle placed; the trees stay for the search below */
        bare[i] = scene->geoms[i].mesh;
        if (flat) {
            bare[i].wide = NULL;
            bare[i].wide_count = 0;
        }
        meshes[i] = &bare[i];
    }
    rc__raster_band(g, row0, rows, &band);
    rc__raster_scan(meshes, count, &band, world, dirs, s->range_max, scratch);
    for (i = 0; i < n_rays; i += 37u) {
        const uint32_t n = n_rays - i < 37u ? n_rays - i : 37u;
        rc__raster_hits(meshes, count, n_rays, world, dirs, scratch, i, n, hits + base + i, found + base + i,
                        td + base + i);
    }
    free(scratch);
}

/* The projected scan of one pose against rc__mesh_intersect ray by ray,
 * over each of the scene's meshes in turn (as the packets go); returns the
 * rays that hit. */
static uint32_t check_pose(const rc_scene *scene, const rc_sensor *s, const rc_pose *pose)
{
    rc__raster_grid g;
    rc__xformf world;
    const uint32_t rays = s->rays;
    rc__hit *hits = malloc(rays * sizeof *hits);
    double *td = malloc(rays * sizeof *td);
    int *found = malloc(rays * sizeof *found);
    uint32_t i, row0, hit_count = 0;
    assert_true(hits && found && td);
    assert_true(rc__raster_grid_of(s, &g));
    rc__sensor_world_xform(s, pose, &world);
    for (row0 = 0; row0 < g.rows; row0 += band_rows ? band_rows : g.rows) {
        const uint32_t n = band_rows && g.rows - row0 > band_rows ? band_rows : g.rows - row0;
        scan_band(scene, s, &g, &world, row0, n, hits, found, td);
    }
    for (i = 0; i < rays; ++i) {
        rc__ray ray;
        rc__hit want;
        int want_found = 0;
        uint32_t m;
        rc__rays_prepare_turned(world.r, world.t, s->directions, &i, 1u, &ray);
        want.t = s->range_max;
        want.prim = want.geom = want.inst = want.slot = RC_INVALID_ID;
        for (m = 0; m < scene->geom_count; ++m)
            want_found |= rc__mesh_intersect(&scene->geoms[m].mesh, &ray, m, RC_INVALID_ID, &want);
        if (want_found != found[i]) fail_msg("ray %u: found %d, the tree %d", i, found[i], want_found);
        if (!want_found) continue;
        ++hit_count;
        if (memcmp(&want.t, &hits[i].t, sizeof want.t) != 0 || want.prim != hits[i].prim || want.geom != hits[i].geom)
            fail_msg("ray %u: t %.9g on %u of mesh %u, the tree %.9g on %u of mesh %u", i, (double)hits[i].t,
                     hits[i].prim, hits[i].geom, (double)want.t, want.prim, want.geom);
        assert_int_equal(hits[i].slot, want.slot);
        assert_int_equal(hits[i].inst, RC_INVALID_ID);
        {
            /* the distance refined as the writer would refine it */
            const double want_td = rc__scene_hit_distance_d(scene, &want, &world, s->directions + 3u * i, NULL);
            if (memcmp(&want_td, &td[i], sizeof want_td) != 0)
                fail_msg("ray %u: refined %.17g, the writer's %.17g", i, td[i], want_td);
        }
    }
    free(td);
    free(hits);
    free(found);
    return hit_count;
}

/* Every grid at every pose on a scene of the meshes ms[0 .. count) (one:
 * rct_scene_mesh's scene); at least min_hits of all their rays hit. */
static void check_meshes(const rcu_mesh *const *ms, uint32_t count, const rc_pose *poses, uint32_t pose_count,
                         float rmin, float rmax, double min_hits, int unfold)
{
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_scene *scene = count == 1u ? rct_scene_mesh(ctx, ms[0], RC_MESH_REFERENCE) : rct_scene_meshes(ctx, ms, count);
    const rc_pose mount = rct_pose_ypr(0.1f, -0.05f, 0.2f, 0.3, 0.2, -0.1);
    uint64_t rays = 0, hit = 0;
    uint32_t k, p;
    flat = unfold == 2;
    for (k = 0; unfold && k < count; ++k) {
        /* the tests' own triples: zero-area triangles whole, checked */
        rc__mesh *mesh = &scene->geoms[k].mesh;
        assert_true(mesh->flats_folded);
        rc__mesh_unfold_flats(mesh, (uint32_t *)(uintptr_t)mesh->leaf_tris);
        mesh->flats_folded = 0;
    }
    for (k = 0; k < NGRIDS + NCYLS + NCAMS; ++k) {
        rc_sensor *s;
        if (k < NGRIDS)
            s = grid_sensor(ctx, &grids[k], rmin, rmax, k == 4 ? &mount : NULL);
        else if (k < NGRIDS + NCYLS)
            s = cyl_sensor(ctx, &cyls[k - NGRIDS], rmin, rmax, k == NGRIDS + 1u ? &mount : NULL);
        else
            s = cam_sensor(ctx, &cams[k - NGRIDS - NCYLS], rmin, rmax, k == NGRIDS + NCYLS + 1u ? &mount : NULL);
        for (p = 0; p < pose_count; ++p) {
            /* every other pose in bands of a third of the rows */
            band_rows = p % 2u ? s->rows / 3u + 1u : 0u;
            hit += check_pose(scene, s, &poses[p]);
            rays += s->rays;
        }
        band_rows = 0;
        rc_sensor_destroy(s);
    }
    if (hit < min_hits * (double)rays) fail_msg("%llu of %llu rays hit", (unsigned long long)hit, (unsigned long long)rays);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
}

static void check_mesh(const rcu_mesh *m, const rc_pose *poses, uint32_t pose_count, float rmin, float rmax,
                       double min_hits, int unfold)
{
    check_meshes(&m, 1u, poses, pose_count, rmin, rmax, min_hits, unfold);
}

/* check_mesh with the mesh's tree (its zero-area triangles unfolded when
 * `unfold`), then without it. */
static void check_tree_and_flat(const rcu_mesh *m, const rc_pose *poses, uint32_t pose_count, float rmax,
                                double min_hits, int unfold)
{
    check_mesh(m, poses, pose_count, 0.0f, rmax, min_hits, unfold);
    check_mesh(m, poses, pose_count, 0.0f, rmax, min_hits, 2);
    flat = 0;
}

/* The placement's atan2 within its stated error of libm's, all around. */
static void test_atan2(void **state)
{
    double worst = 0.0;
    int i, k;
    (void)state;
    for (i = 0; i < 200000; ++i) {
        const double a = -3.14159 + 6.28318 * (double)i / 199999.0;
        for (k = 0; k < 3; ++k) {
            const double len = k == 0 ? 1e-6 : k == 1 ? 1.0 : 3e7;
            const double y = len * sin(a), x = len * cos(a);
            double e = fabs(rc__cone_atan2(y, x) - atan2(y, x));
            if (e > 3.0) e = fabs(e - RC__TWO_PI); /* the same angle either side of the cut */
            if (e > worst) worst = e;
#if defined(RC__CONE_LANES)
            {
                /* the lanes' version, in every lane */
                const double ys[4] = {y, -y, y, -y}, xs[4] = {x, x, -x, -x};
                double got[4];
                rc__v4d vy, vx, va;
                int l;
                memcpy(&vy, ys, sizeof vy);
                memcpy(&vx, xs, sizeof vx);
                rc__cone_atan2_4(&vy, &vx, &va);
                memcpy(got, &va, sizeof got);
                for (l = 0; l < 4; ++l) {
                    e = fabs(got[l] - atan2(ys[l], xs[l]));
                    if (e > 3.0) e = fabs(e - RC__TWO_PI);
                    if (e > worst) worst = e;
                }
            }
#endif
        }
    }
    /* the axes and diagonals exactly */
    assert_true(fabs(rc__cone_atan2(1.0, 0.0) - RC__HALF_PI) <= RC__CONE_ATAN_ERROR);
    assert_true(fabs(rc__cone_atan2(-2.0, -2.0) + 0.75 * 3.141592653589793) <= RC__CONE_ATAN_ERROR);
    assert_true(rc__cone_atan2(0.0, 0.0) == 0.0);
#if defined(RC__CONE_LANES)
    {
        const double ys[4] = {0.0, 1.0, -2.0, 1e-300}, xs[4] = {0.0, 0.0, -2.0, 1e-300};
        double got[4];
        rc__v4d vy, vx, va;
        memcpy(&vy, ys, sizeof vy);
        memcpy(&vx, xs, sizeof vx);
        rc__cone_atan2_4(&vy, &vx, &va);
        memcpy(got, &va, sizeof got);
        assert_true(got[0] == 0.0);
        assert_true(fabs(got[1] - RC__HALF_PI) <= RC__CONE_ATAN_ERROR);
        assert_true(fabs(got[2] + 0.75 * 3.141592653589793) <= RC__CONE_ATAN_ERROR);
        assert_true(fabs(got[3] - 0.25 * 3.141592653589793) <= RC__CONE_ATAN_ERROR);
    }
#endif
    if (worst > RC__CONE_ATAN_ERROR) fail_msg("worst error %.3g", worst);
}

static void test_sphere(void **state)
{
    rcu_mesh m;
    const rc_pose poses[] = {
        rct_pose(0.0f, 0.0f, 0.0f),
        rct_pose_ypr(4.6f, 0.3f, -0.2f, 0.7, 1.2, -0.4),   /* 0.4 m from the wall */
        rct_pose_ypr(-1.0f, 2.0f, 0.5f, -2.0, 1.5707963, 0.0), /* pitched up: the z axis level */
        rct_pose_ypr(0.5f, -4.2f, 1.0f, 3.1, -0.6, 2.5),
    };
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 14u, 9u, &m), 0);
    check_mesh(&m, poses, 4u, 0.0f, 100.0f, 0.999, 0);
    rcu_mesh_free(&m);
    /* finer (the corners that touch a cone's edge near more rows), and a
     * range that ends short of most of the wall: triangles wholly beyond
     * it are skipped */
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 60u, 30u, &m), 0);
    check_mesh(&m, poses, 4u, 0.0f, 100.0f, 0.999, 0);
    check_mesh(&m, poses + 1, 1u, 0.0f, 4.5f, 0.2, 0);
    rcu_mesh_free(&m);
}

/* A sensor in the floor's plane (a rounded t near 0) and the middle of a
 * room whose walls' diagonals pass through the rays along the axes (zero
 * edge functions): the test's double-precision cases. */
static void test_rare_cases(void **state)
{
    const float lo[3] = {-4.0f, -4.0f, -1.0f}, hi[3] = {4.0f, 4.0f, 1.0f};
    const float flo[3] = {-4.1f, -3.3f, 0.3f}, fhi[3] = {5.2f, 4.7f, 2.9f};
    const grid_case axes = {-3.14159265f, 0.785398163f, 8u, 0.0f, 0.0f, 1u};
    const rc_pose centre = rct_pose(0.0f, 0.0f, 0.0f);
    const rc_pose on_floor[] = {rct_pose(0.7f, 0.2f, 0.3f), rct_pose_ypr(-1.3f, 1.1f, 0.3f, 0.4, 0.0, 0.0)};
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rcu_mesh room, floor_room;
    rc_scene *scene;
    rc_sensor *s;
    uint32_t p;
    (void)state;
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    scene = rct_scene_mesh(ctx, &room, RC_MESH_REFERENCE);
    s = grid_sensor(ctx, &axes, 0.0f, 50.0f, NULL);
    assert_int_equal(check_pose(scene, s, &centre), 8u);
    rc_sensor_destroy(s);
    rc_scene_destroy(scene);
    assert_int_equal(rcu_mesh_box(flo, fhi, &floor_room), 0);
    scene = rct_scene_mesh(ctx, &floor_room, RC_MESH_REFERENCE);
    s = grid_sensor(ctx, &grids[0], 0.0f, 50.0f, NULL);
    for (p = 0; p < 2u; ++p) assert_true(check_pose(scene, s, &on_floor[p]) > s->rays / 3u);
    rc_sensor_destroy(s);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&room);
    rcu_mesh_free(&floor_room);
}

static void test_box_room(void **state)
{
    const float lo[3] = {-4.0f, -3.0f, 0.0f}, hi[3] = {5.0f, 4.0f, 2.5f};
    rcu_mesh m;
    const rc_pose poses[] = {
        rct_pose(0.0f, 0.0f, 0.0f), /* in the floor's plane */
        rct_pose(1.0f, 2.0f, 1.2f),
        rct_pose_ypr(-3.9f, 3.9f, 2.4f, 0.4, 0.3, 0.2), /* a corner */
        rct_pose_ypr(0.0f, 0.0f, 1.0f, 0.0, 1.5707963, 0.0),
    };
    (void)state;
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    check_mesh(&m, poses, 4u, 0.0f, 50.0f, 0.45, 0);
    rcu_mesh_free(&m);
}

/* Zero-area triangles across the view, left in the triples: never hit. */
static void test_unfolded_flats(void **state)
{
    const float lo[3] = {-4.0f, -3.0f, -1.0f}, hi[3] = {5.0f, 4.0f, 2.5f};
    rcu_mesh m, flats;
    const rc_pose poses[] = {rct_pose(0.0f, 0.0f, 0.0f), rct_pose_ypr(1.0f, -1.0f, 0.5f, 0.5, 0.2, 0.1)};
    uint32_t i;
    (void)state;
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    assert_int_equal(rcu_mesh_reserve(&flats, 9u, 3u), 0);
    for (i = 0; i < 9u; ++i) {
        /* three collinear points a triangle (exactly: small integers and
         * halves), lines from the walls inwards */
        const float s = (float)(i % 3u), k = (float)(i / 3u);
        flats.vertices[3u * i] = 2.0f - k + s * (k - 1.0f);
        flats.vertices[3u * i + 1u] = s * (1.0f - 0.5f * k);
        flats.vertices[3u * i + 2u] = 0.5f * s;
    }
    for (i = 0; i < 9u; ++i) flats.indices[i] = i;
    flats.vertex_count = 9u;
    flats.triangle_count = 3u;
    assert_int_equal(rcu_mesh_append(&m, &flats), 0);
    check_tree_and_flat(&m, poses, 2u, 50.0f, 0.45, 1);
    rcu_mesh_free(&flats);
    rcu_mesh_free(&m);
}

/* Ribbons of tiny triangles (2e-4 rad across) 40 m away whose middle edges
 * lie on the rows' elevations, seen by a grid of VLP-16 rows and columns
 * 5e-4 rad apart: the rays run along the edges, and the rows found from
 * the corners' elevations must still give each ray both triangles of its
 * edge. (Cutting the rows' slack of 1e-4 rad down to the edges' bulge, a
 * few 1e-9 here, still passes: the rays' and the test's rounding stays
 * within that, so the slack is a margin no test here can show.) */
static void test_edges_on_rows(void **state)
{
    const grid_case fine = {0.37f, 0.0005f, 120u, grids[0].phi_min, grids[0].phi_inc, 16u};
    const uint32_t segs = 300u;
    const double step = 2e-4, range = 40.0;
    const rc_pose centre = rct_pose(0.0f, 0.0f, 0.0f);
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_sensor *sensor = grid_sensor(ctx, &fine, 0.0f, 50.0f, NULL);
    rc_scene *scene;
    rcu_mesh m;
    uint32_t b, k, level;
    (void)state;
    assert_int_equal(rcu_mesh_reserve(&m, fine.rows * 3u * (segs + 1u), fine.rows * 4u * segs), 0);
    for (b = 0; b < fine.rows; ++b) {
        const double row = (double)fine.phi_min + b * (double)fine.phi_inc;
        const uint32_t v0 = m.vertex_count;
        for (level = 0; level < 3u; ++level)
            for (k = 0; k <= segs; ++k) {
                const double e = row + ((double)level - 1.0) * step, a = 0.4 + ((double)k - 0.5 * segs) * step;
                float *v = m.vertices + 3u * m.vertex_count++;
                v[0] = (float)(range * cos(e) * cos(a));
                v[1] = (float)(range * cos(e) * sin(a));
                v[2] = (float)(range * sin(e));
            }
        for (level = 0; level < 2u; ++level)
            for (k = 0; k < segs; ++k) {
                const uint32_t q = v0 + level * (segs + 1u) + k, up = q + segs + 1u;
                uint32_t *t = m.indices + 3u * m.triangle_count;
                t[0] = q, t[1] = q + 1u, t[2] = up + 1u;
                t[3] = q, t[4] = up + 1u, t[5] = up;
                m.triangle_count += 2u;
            }
    }
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    /* the columns within 0.4 +- 0.03 of every row */
    assert_true(check_pose(scene, sensor, &centre) >= 16u * 118u);
    rc_scene_destroy(scene);
    rc_sensor_destroy(sensor);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* A long lens (1.1 degrees across) facing a wall of tiny triangles 30 m
 * away whose corners lie on its pixels' rays (the sensor's own unit
 * directions, scaled): every ray runs through a corner shared by six
 * triangles, and the pixels found from the projected corners must still
 * give each ray all of them (the watertight test then picks one). */
static void test_corners_on_pixels(void **state)
{
    const cam_case lens = cams[2];
    cam_case wider = lens;
    const rc_pose poses[] = {rct_pose(0.0f, 0.0f, 0.0f), rct_pose_ypr(0.0f, 0.0f, 0.0f, 0.0, 0.0, 0.0)};
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_sensor *sensor = cam_sensor(ctx, &lens, 0.0f, 50.0f, NULL), *grid;
    rc_scene *scene;
    rcu_mesh m;
    uint32_t u, v, p;
    (void)state;
    /* one pixel more on each side: the same rays, as (u - cx) is exact */
    wider.width += 2u;
    wider.height += 2u;
    wider.cx += 1.0f;
    wider.cy += 1.0f;
    grid = cam_sensor(ctx, &wider, 0.0f, 50.0f, NULL);
    assert_int_equal(rcu_mesh_reserve(&m, grid->rays, 2u * (wider.width - 1u) * (wider.height - 1u)), 0);
    for (u = 0; u < grid->rays; ++u) {
        float *x = m.vertices + 3u * m.vertex_count++;
        for (v = 0; v < 3u; ++v) x[v] = 30.0f * grid->directions[3u * u + v];
    }
    for (v = 0; v + 1u < wider.height; ++v)
        for (u = 0; u + 1u < wider.width; ++u) {
            const uint32_t q = v * wider.width + u, down = q + wider.width;
            uint32_t *t = m.indices + 3u * m.triangle_count;
            t[0] = q, t[1] = q + 1u, t[2] = down + 1u;
            t[3] = q, t[4] = down + 1u, t[5] = down;
            m.triangle_count += 2u;
        }
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    for (p = 0; p < 2u; ++p) {
        band_rows = p ? 7u : 0u;
        assert_int_equal(check_pose(scene, sensor, &poses[p]), sensor->rays);
    }
    band_rows = 0;
    rc_scene_destroy(scene);
    rc_sensor_destroy(grid);
    rc_sensor_destroy(sensor);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* Every triangle twice (a copy appended: its own vertices, the same
 * values): each hit ties, at the same t, with its copy, and the smaller
 * prim id must win whichever the scan meets first (the offers' tie rule,
 * taken in lanes and in the scalar offer). */
static void test_coincident_copies(void **state)
{
    rcu_mesh m, copy;
    const rc_pose poses[] = {rct_pose(0.0f, 0.0f, 0.0f), rct_pose_ypr(1.1f, -0.7f, 0.4f, 2.2, 0.3, -0.5)};
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 14u, 9u, &m), 0);
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 14u, 9u, &copy), 0);
    assert_int_equal(rcu_mesh_append(&m, &copy), 0);
    check_tree_and_flat(&m, poses, 2u, 100.0f, 0.999, 0);
    rcu_mesh_free(&copy);
    rcu_mesh_free(&m);
}

/* A scene of four meshes: a room, a ball in it with every triangle twice,
 * the ball again and the room again (each its own copy of the values).
 * Every hit on the room ties with its copy three meshes later, and every
 * hit on the ball with its twin in the same mesh and its copy in the next:
 * the smaller geometry id wins across meshes whichever is placed first, and
 * within the second mesh (whose triangles are numbered after the room's)
 * the smaller prim id; the ball is met before the room behind it, and the
 * room copy's walls after the ball. With the trees and without. */
static void test_meshes(void **state)
{
    const float lo[3] = {-4.0f, -3.0f, -1.0f}, hi[3] = {5.0f, 4.0f, 2.5f};
    const float at[3] = {1.5f, 0.5f, 0.8f};
    const rc_pose poses[] = {rct_pose(0.0f, 0.0f, 0.3f), rct_pose_ypr(-2.5f, -1.0f, 1.2f, 0.3, 0.2, -0.1),
                             rct_pose_ypr(3.9f, 3.1f, 2.0f, -2.6, 0.4, 0.3)};
    rcu_mesh room, twins, ball, room2;
    const rcu_mesh *ms[4];
    (void)state;
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &room2), 0);
    assert_int_equal(rcu_mesh_uv_sphere(0.9f, 16u, 9u, &twins), 0);
    assert_int_equal(rcu_mesh_uv_sphere(0.9f, 16u, 9u, &ball), 0);
    assert_int_equal(rcu_mesh_append(&twins, &ball), 0);
    rcu_mesh_transform(&twins, 0.0f, at);
    rcu_mesh_transform(&ball, 0.0f, at);
    ms[0] = &room;
    ms[1] = &twins;
    ms[2] = &ball;
    ms[3] = &room2;
    check_meshes(ms, 4u, poses, 3u, 0.0f, 50.0f, 0.45, 0);
    check_meshes(ms, 4u, poses, 3u, 0.0f, 50.0f, 0.45, 2);
    flat = 0;
    /* the ball alone before the room: the nearer mesh placed first */
    ms[0] = &ball;
    ms[1] = &room;
    check_meshes(ms, 2u, poses, 3u, 0.5f, 50.0f, 0.45, 0);
    rcu_mesh_free(&room);
    rcu_mesh_free(&room2);
    rcu_mesh_free(&twins);
    rcu_mesh_free(&ball);
}

/* enough for 3 threads to take a pose each (fewer poses than 4 a thread
 * split scans into slices, which take the packets) */
#define POSES 12u

/* A sensor that leaves the arena about `left` bytes free. */
static rc_sensor *fill_arena(rc_context *ctx, size_t left)
{
    rc_memory_stats st = rc_memory_stats_default();
    rc_spherical_desc d = rc_spherical_desc_default();
    rc_sensor *s = NULL;
    size_t bytes = 0;
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &st));
    d.common.range_max = 10.0f;
    d.theta.increment = 1e-4f;
    d.theta.count = 1u;
    d.phi.count = 1u;
    RCT_OK(ctx, rc_sensor_memory_requirements_spherical(&d, &bytes));
    assert_true(st.arena_size > st.arena_used + left + bytes);
    d.theta.count = (uint32_t)((st.arena_size - st.arena_used - left) / 12u);
    do {
        d.theta.count -= 64u;
        RCT_OK(ctx, rc_sensor_memory_requirements_spherical(&d, &bytes));
    } while (st.arena_used + bytes + left > st.arena_size);
    RCT_OK(ctx, rc_sensor_create_spherical(ctx, &d, &s));
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &st));
    assert_true(st.arena_size - st.arena_used < 2u * left);
    return s;
}

/* Every attribute of calls with ctx (room for the projected scan's scratch)
 * and tight (none: the packets), byte for byte: a VLP-16 (kind 0), the
 * first cylindrical grid (1) or the first camera, 0.8 to 4 m (2). */
static void compare_calls(rc_context *ctx, rc_context *tight, const rcu_mesh *const *ms, uint32_t count,
                          uint32_t threads, int kind)
{
    const uint32_t attrs = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_POINTS | RC_ATTR_NORMALS | RC_ATTR_PRIM_IDS |
                           RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS;
    rc_pose poses[POSES];
    rc_scene *sa = count == 1u ? rct_scene_mesh(ctx, ms[0], RC_MESH_REFERENCE) : rct_scene_meshes(ctx, ms, count);
    rc_scene *sb = count == 1u ? rct_scene_mesh(tight, ms[0], RC_MESH_REFERENCE) : rct_scene_meshes(tight, ms, count);
    rc_sensor *a = NULL, *b = NULL, *filler;
    rc_memory_stats before = rc_memory_stats_default(), after = rc_memory_stats_default();
    rct_buffers ba, bb;
    uint32_t p, ninf = 0, pinf = 0;
    uint64_t i;
    if (kind == 1) {
        a = cyl_sensor(ctx, &cyls[0], 0.5f, 130.0f, NULL);
        b = cyl_sensor(tight, &cyls[0], 0.5f, 130.0f, NULL);
    } else if (kind == 2) {
        a = cam_sensor(ctx, &cams[0], 0.8f, 4.0f, NULL);
        b = cam_sensor(tight, &cams[0], 0.8f, 4.0f, NULL);
    } else {
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &a));
        RCT_OK(tight, rc_sensor_create_preset(tight, RC_PRESET_VELODYNE_VLP16, &b));
    }
    /* three of them within 0.2 m of a wall, the ceiling or the ball */
    poses[0] = rct_pose_ypr(-2.0f, 1.5f, 0.0f, 0.3, -0.5, 0.0);
    poses[1] = rct_pose_ypr(-2.8f, -1.8f, 0.1f, 1.2, 0.3, 0.1);
    poses[2] = rct_pose_ypr(3.0f, 2.5f, 2.3f, -0.7, 0.6, -0.2);
    poses[3] = rct_pose_ypr(0.0f, 0.0f, 1.0f, 2.5, 1.1, 0.4);
    poses[4] = rct_pose_ypr(1.5f, 0.5f, 2.0f, -2.0, -0.2, 0.9);
    poses[5] = rct_pose_ypr(2.0f, -1.5f, 0.5f, 0.0, -1.2, 0.0);
    for (p = 6; p < POSES; ++p) {
        poses[p] = poses[p - 6u];
        poses[p].position[2] += 0.05f;
    }
    rct_buffers_alloc(&ba, POSES * a->rays, attrs);
    rct_buffers_alloc(&bb, POSES * b->rays, attrs);
    /* the room's walls are long against it: put them through the projected
     * scan all the same (test_large_triangles checks the default) */
    ctx->raster_edge_fraction = 1e6;
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &before));
    RCT_OK(ctx, rc_simulate(ctx, sa, a, poses, POSES, &ba.res));
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &after));
    /* the call took the projected scan: it borrowed the scratch for each of
     * the context's threads (one in a build without threads) */
    assert_true(before.arena_peak < before.arena_used + ctx->thread_count * rc__raster_scratch_bytes(a->rays));
    assert_true(after.arena_peak >= before.arena_used + ctx->thread_count * rc__raster_scratch_bytes(a->rays));
    assert_true(ctx->thread_count == threads || ctx->thread_count == 1u);
    filler = fill_arena(tight, rc__raster_scratch_bytes(b->rays) / 2u);
    RCT_OK(tight, rc_context_get_memory_stats(tight, &before));
    RCT_OK(tight, rc_simulate(tight, sb, b, poses, POSES, &bb.res));
    RCT_OK(tight, rc_context_get_memory_stats(tight, &after));
    /* this one could not: nothing borrowed */
    assert_true(after.arena_peak == before.arena_peak);
    assert_memory_equal(ba.res.hits, bb.res.hits, ba.n);
    assert_memory_equal(ba.res.ranges, bb.res.ranges, ba.n * sizeof(float));
    assert_memory_equal(ba.res.points, bb.res.points, ba.n * 3u * sizeof(float));
    assert_memory_equal(ba.res.normals, bb.res.normals, ba.n * 3u * sizeof(float));
    assert_memory_equal(ba.res.prim_ids, bb.res.prim_ids, ba.n * sizeof(uint32_t));
    assert_memory_equal(ba.res.geom_ids, bb.res.geom_ids, ba.n * sizeof(uint32_t));
    assert_memory_equal(ba.res.inst_ids, bb.res.inst_ids, ba.n * sizeof(uint32_t));
    for (i = 0; i < ba.n; ++i) {
        ninf += ba.res.ranges[i] < 0.0f && isinf(ba.res.ranges[i]);
        pinf += ba.res.ranges[i] > 0.0f && isinf(ba.res.ranges[i]);
    }
    /* the box room of compare_simulate has both: walls nearer than
     * range_min (0.5 m; the camera's 0.8 m) and openings or walls with
     * nothing within range */
    assert_true(ninf > 0 && pinf > 0 && ninf + pinf < ba.n / 2u);
    /* one pose: on 3 threads its scan is cut into bands of rows, a task
     * each (the packets' slices) */
    RCT_OK(ctx, rc_simulate(ctx, sa, a, poses + 3, 1u, &ba.res));
    RCT_OK(tight, rc_simulate(tight, sb, b, poses + 3, 1u, &bb.res));
    assert_memory_equal(ba.res.ranges, bb.res.ranges, a->rays * sizeof(float));
    assert_memory_equal(ba.res.prim_ids, bb.res.prim_ids, a->rays * sizeof(uint32_t));
    assert_memory_equal(ba.res.normals, bb.res.normals, a->rays * 3u * sizeof(float));
    rct_buffers_free(&ba);
    rct_buffers_free(&bb);
    rc_sensor_destroy(a);
    rc_sensor_destroy(b);
    rc_sensor_destroy(filler);
    rc_scene_destroy(sa);
    rc_scene_destroy(sb);
}

/* 1 when rc_simulate of one pose of sensor s over scene borrowed scratch
 * for the projected scan (the arena's peak grew by each thread's share);
 * the peak is a high-water mark, so ctx must not have reached it before */
static int took_raster(rc_context *ctx, rc_scene *scene, rc_sensor *s)
{
    rc_memory_stats before = rc_memory_stats_default(), after = rc_memory_stats_default();
    const rc_pose pose = rct_pose_ypr(0.5f, 0.3f, 1.0f, 0.4, 0.1, 0.0);
    const uint64_t need = ctx->thread_count * rc__raster_scratch_bytes(s->rays);
    rct_buffers b;
    rct_buffers_alloc(&b, s->rays, RC_ATTR_RANGES);
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &before));
    assert_true(before.arena_peak < before.arena_used + need);
    RCT_OK(ctx, rc_simulate(ctx, scene, s, &pose, 1u, &b.res));
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &after));
    rct_buffers_free(&b);
    return after.arena_peak >= before.arena_used + need;
}

enum { MAP_COMMITTED, MAP_STRETCHED, MAP_STRETCHED_BACK, MAP_BAKED };

/* took_raster on a fresh context: mesh as a referenced scene, seen by
 * sensor 0 a VLP-16, 1 a cylindrical one, 2 a camera. MAP_STRETCHED: one
 * vertex then moved out to 3 times its distance from the origin and the mesh
 * refit (rc_scene_update_mesh, commit); MAP_STRETCHED_BACK: then put back
 * and refit again; MAP_BAKED: the scene baked and the blob loaded. fraction
 * > 0 sets the context's raster_edge_fraction. */
static int raster_choice(rcu_mesh *mesh, int sensor, int how, double fraction)
{
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_scene *scene = rct_scene_mesh(ctx, mesh, RC_MESH_REFERENCE), *use = scene;
    rc_sensor *s = NULL;
    float *v = mesh->vertices + 3u * (mesh->vertex_count / 2u);
    const float keep[3] = {v[0], v[1], v[2]};
    void *blob = NULL;
    int took;
    if (fraction > 0.0) ctx->raster_edge_fraction = fraction;
    if (how == MAP_STRETCHED || how == MAP_STRETCHED_BACK) {
        v[0] *= 3.0f;
        v[1] *= 3.0f;
        v[2] *= 3.0f;
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        RCT_OK(ctx, rc_scene_commit(scene));
    }
    if (how == MAP_STRETCHED_BACK) {
        memcpy(v, keep, sizeof keep);
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        RCT_OK(ctx, rc_scene_commit(scene));
    }
    if (how == MAP_BAKED) {
        size_t bytes = 0;
        RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &bytes));
        blob = rct_alloc16(bytes); /* (32-bit ARM's malloc gives 8-byte alignment) */
        assert_non_null(blob);
        RCT_OK(ctx, rc_scene_bake(scene, blob, bytes, &bytes));
        RCT_OK(ctx, rc_scene_load_baked(ctx, blob, bytes, 0, &use));
    }
    if (sensor == 0)
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
    else if (sensor == 1)
        s = cyl_sensor(ctx, &cyls[0], 0.5f, 130.0f, NULL);
    else
        s = cam_sensor(ctx, &cams[0], 0.8f, 4.0f, NULL);
    took = took_raster(ctx, use, s);
    memcpy(v, keep, sizeof keep);
    rc_sensor_destroy(s);
    if (use != scene) rc_scene_destroy(use);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    free(blob);
    return took;
}

/* A spinning sensor's projected scan tests each triangle against its whole
 * bounding cone: a room's walls, long against the room, cover whole rows
 * (a VLP-16 in the demo warehouse ran at a fifth of Embree's speed so).
 * Such a map takes the packets; a camera still takes the projected scan
 * (it clips triangles to its view), as does a map of small triangles, and
 * the room too when the context's fraction allows it. The longest edge is
 * found at commit, so a refit and a baked map's load must find it too. */
static void test_large_triangles(void **state)
{
    const float lo[3] = {-3.0f, -2.0f, -0.2f}, hi[3] = {4.0f, 3.0f, 2.5f};
    rcu_mesh room, ball;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    (void)state;
    assert_true(ctx->raster_edge_fraction > 0.0 && ctx->raster_edge_fraction < 0.5);
    rc_context_destroy(ctx);
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    /* 32 x 16 segments: edges of at most 2.3 m against a diagonal of 28 m */
    assert_int_equal(rcu_mesh_uv_sphere(8.0f, 32u, 16u, &ball), 0);
    assert_false(raster_choice(&room, 0, MAP_COMMITTED, 0.0));
    assert_false(raster_choice(&room, 1, MAP_COMMITTED, 0.0));
    assert_true(raster_choice(&room, 2, MAP_COMMITTED, 0.0));
    assert_true(raster_choice(&ball, 0, MAP_COMMITTED, 0.0));
    assert_true(raster_choice(&ball, 1, MAP_COMMITTED, 0.0));
    assert_true(raster_choice(&room, 0, MAP_COMMITTED, 1.0));
    /* a vertex of the ball stretched out: edges of 16 m against 39 */
    assert_false(raster_choice(&ball, 0, MAP_STRETCHED, 0.0));
    assert_true(raster_choice(&ball, 0, MAP_STRETCHED_BACK, 0.0));
    assert_false(raster_choice(&room, 0, MAP_BAKED, 0.0));
    assert_true(raster_choice(&ball, 0, MAP_BAKED, 0.0));
    rcu_mesh_free(&room);
    rcu_mesh_free(&ball);
}

static void test_simulate(void **state)
{
    const float lo[3] = {-3.0f, -2.0f, -0.2f}, hi[3] = {4.0f, 3.0f, 2.5f};
    rcu_mesh room, sphere, open_room, face;
    uint32_t threads;
    (void)state;
    /* the room's floor, walls and ceiling, and a ball in it; the room's
     * corner at (-3, -2) is cut open by the ball's range of sight */
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &open_room), 0);
    assert_int_equal(rcu_mesh_uv_sphere(0.8f, 24u, 12u, &sphere), 0);
    {
        const float at[3] = {1.5f, 0.5f, 1.0f};
        rcu_mesh_transform(&sphere, 0.0f, at);
    }
    assert_int_equal(rcu_mesh_append(&room, &sphere), 0);
    /* an opening: the box's first two triangles (a face) dropped */
    memmove(room.indices, room.indices + 6u, (room.triangle_count - 2u) * 3u * sizeof(uint32_t));
    room.triangle_count -= 2u;
    memmove(open_room.indices, open_room.indices + 6u, (open_room.triangle_count - 2u) * 3u * sizeof(uint32_t));
    open_room.triangle_count -= 2u;
    /* and as a scene of three meshes: the open room, the ball, and the
     * room's next face again (its copy's hits tie with the room's and lose) */
    assert_int_equal(rcu_mesh_box(lo, hi, &face), 0);
    memmove(face.indices, face.indices + 6u, 6u * sizeof(uint32_t));
    face.triangle_count = 2u;
    for (threads = 1; threads <= 3; threads += 2) {
        int kind, scene;
        for (scene = 0; scene < 2; ++scene)
            for (kind = 0; kind < 3; ++kind) {
                const rcu_mesh *split[3] = {&open_room, &sphere, &face};
                const rcu_mesh *whole = &room;
                rc_context *ctx = rct_context(RC_BACKEND_BVH, threads, 0);
                rc_context *tight = rct_context(RC_BACKEND_BVH, threads, 0);
                if (scene)
                    compare_calls(ctx, tight, split, 3u, threads, kind);
                else
                    compare_calls(ctx, tight, &whole, 1u, threads, kind);
                rc_context_destroy(ctx);
                rc_context_destroy(tight);
            }
    }
    rcu_mesh_free(&face);
    rcu_mesh_free(&open_room);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&room);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_atan2),
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_box_room),
        cmocka_unit_test(test_rare_cases),
        cmocka_unit_test(test_unfolded_flats),
        cmocka_unit_test(test_coincident_copies),
        cmocka_unit_test(test_meshes),
        cmocka_unit_test(test_edges_on_rows),
        cmocka_unit_test(test_corners_on_pixels),
        cmocka_unit_test(test_large_triangles),
        cmocka_unit_test(test_simulate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
#else
int main(void)
{
    print_message("projected scans are left out of this build (RANGECAST_PROJECTED_SCANS off): nothing to test\n");
    return 0;
}
#endif
