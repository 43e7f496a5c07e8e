/* The scene suite every backend runs: analytic scenes with known answers,
 * every attribute, instancing, REP 117 ranges, watertightness and thread-count
 * independence. Backends that are absent are skipped with a message. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"
#include "reference.h"

#define DEG (3.14159265358979323846 / 180.0)


#define NEED_BACKEND(b)                       \
    do {                                      \
        if (!rct_backend_usable(b)) skip();   \
    } while (0)

/* Rotation of a pose in double (the float64 reference's transform). */
static void pose_rotation(const rc_pose *pose, double R[9])
{
    rcu_xform x;
    int i, j;
    rcu_xform_from_pose(pose, &x);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) R[3 * i + j] = x.r[i][j];
}

/* A wall: the plane x = d, a big square, normal -x. */
static void wall_mesh(float d, rcu_mesh *m)
{
    const float p0[3] = {d, -1000.0f, -1000.0f}, p1[3] = {d, 1000.0f, -1000.0f};
    const float p2[3] = {d, 1000.0f, 1000.0f}, p3[3] = {d, -1000.0f, 1000.0f};
    assert_int_equal(rcu_mesh_quad(p0, p1, p2, p3, m), 0);
}

/* Plane at distance d: every ray of a fan reads d / cos(angle), with points,
 * normals facing the sensor and ids. */
static void test_plane_at_distance(void **state)
{
    uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh m;
    float dirs[3 * 64];
    rct_buffers buf;
    rc_pose pose = rct_pose(0.0f, 0.0f, 0.0f);
    uint32_t i;
    const float d = 7.25f;
    NEED_BACKEND(b);
    ctx = rct_context(b, 1, 0);
    wall_mesh(d, &m);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    for (i = 0; i < 64; ++i) {
        double yaw = (-60.0 + 120.0 * i / 63.0) * DEG, pitch = (-30.0 + 60.0 * ((i * 7) % 64) / 63.0) * DEG;
        dirs[3 * i] = (float)(cos(pitch) * cos(yaw));
        dirs[3 * i + 1] = (float)(cos(pitch) * sin(yaw));
        dirs[3 * i + 2] = (float)sin(pitch);
    }
    sensor = rct_sensor_dirs(ctx, dirs, 64, 0.1f, 100.0f);
    rct_buffers_alloc(&buf, 64, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    for (i = 0; i < 64; ++i) {
        double dn[3], len, expect;
        int k;
        for (k = 0; k < 3; ++k) dn[k] = dirs[3 * i + k];
        len = sqrt(dn[0] * dn[0] + dn[1] * dn[1] + dn[2] * dn[2]);
        expect = d / (dn[0] / len);
        assert_int_equal(buf.res.hits[i], 1);
        assert_true(fabs(buf.res.ranges[i] - expect) <= 1e-5 * expect);
        assert_true(fabs(buf.res.points[3 * i] - d) <= 1e-4);
        assert_true(fabs(buf.res.normals[3 * i] + 1.0f) <= 1e-6);
        assert_true(fabs(buf.res.normals[3 * i + 1]) <= 1e-6);
        assert_true(buf.res.prim_ids[i] <= 1);
        assert_int_equal(buf.res.geom_ids[i], 0);
        assert_int_equal(buf.res.inst_ids[i], RC_INVALID_ID);
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* Distance from the origin o to the inside of a box along d. */
static double box_exit(const double o[3], const double d[3], const float lo[3], const float hi[3], int *axis)
{
    double best = INFINITY;
    int k;
    for (k = 0; k < 3; ++k) {
        double t = INFINITY;
        if (d[k] > 0) t = (hi[k] - o[k]) / d[k];
        if (d[k] < 0) t = (lo[k] - o[k]) / d[k];
        if (t < best) {
            best = t;
            *axis = k;
        }
    }
    return best;
}

/* A closed box room seen by a VLP-16 from a rotated pose: every ray hits at the
 * analytic range; normals are the wall's axis, facing the sensor. */
static void test_box_room_vlp16(void **state)
{
    uint32_t b = rct_backend_of(state);
    const float lo[3] = {-5.0f, -4.0f, -1.0f}, hi[3] = {6.0f, 3.0f, 2.5f};
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rc_sensor_info info = rc_sensor_info_default();
    rc_spherical_desc sd;
    rcu_mesh m;
    rct_buffers buf;
    rc_pose pose = rct_pose_ypr(0.5f, -0.25f, 0.3f, 0.7, 0.1, -0.05);
    uint32_t r, c;
    NEED_BACKEND(b);
    ctx = rct_context(b, 2, 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_COPY);
    rcu_mesh_free(&m); /* copied: the scene no longer needs it */
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
    RCT_OK(ctx, rc_sensor_get_info(sensor, &info));
    assert_int_equal(info.rows, 16);
    assert_int_equal(info.columns, 900);
    rct_buffers_alloc(&buf, info.rays_per_scan, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    assert_int_equal(rc_preset_spherical(RC_PRESET_VELODYNE_VLP16, &sd), RC_OK);
    {
        /* world rotation of the pose, in double */
        double R[9], o[3] = {pose.position[0], pose.position[1], pose.position[2]};
        pose_rotation(&pose, R);
        for (r = 0; r < 16; ++r)
            for (c = 0; c < 900; ++c) {
                uint32_t k = r * 900 + c;
                double th = sd.theta.min + c * (double)sd.theta.increment, ph = sd.phi.min + r * (double)sd.phi.increment;
                double ds[3] = {cos(ph) * cos(th), cos(ph) * sin(th), sin(ph)}, dw[3];
                int axis = -1, j;
                double expect;
                for (j = 0; j < 3; ++j) dw[j] = R[3 * j] * ds[0] + R[3 * j + 1] * ds[1] + R[3 * j + 2] * ds[2];
                expect = box_exit(o, dw, lo, hi, &axis);
                assert_int_equal(buf.res.hits[k], 1);
                if (fabs(buf.res.ranges[k] - expect) > 2e-5 * expect + 1e-5)
                    fail_msg("ray %u: range %.7f expected %.7f", k, (double)buf.res.ranges[k], expect);
                for (j = 0; j < 3; ++j)
                    assert_true(fabs(buf.res.points[3 * k + j] - ds[j] * expect) <= 1e-4 * expect + 1e-4);
                {
                    /* the normal in the map frame is -sign(d) along the hit axis */
                    double nm[3] = {0, 0, 0}, ns[3];
                    nm[axis] = dw[axis] > 0 ? -1.0 : 1.0;
                    for (j = 0; j < 3; ++j) ns[j] = R[j] * nm[0] + R[3 + j] * nm[1] + R[6 + j] * nm[2];
                    for (j = 0; j < 3; ++j) assert_true(fabs(buf.res.normals[3 * k + j] - ns[j]) <= 1e-5);
                }
                assert_true(buf.res.prim_ids[k] < 12);
            }
    }
    rct_buffers_free(&buf);
    rc_context_destroy(ctx);
}

/* Inside a fine sphere: every ray hits, its range is the exact (double)
 * distance to the plane of the reported triangle, and that triangle is the one
 * a brute-force search finds. */
static void test_inside_sphere(void **state)
{
    uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh m;
    rct_buffers buf;
    rc_pose poses[3];
    uint32_t rays, i, p;
    double max_err = 0.0;
    NEED_BACKEND(b);
    poses[0] = rct_pose(0, 0, 0);
    poses[1] = rct_pose_ypr(3.0f, -2.0f, 1.5f, 1.0, 0.3, 0.2);
    poses[2] = rct_pose_ypr(-8.0f, 4.0f, -5.0f, -2.0, -0.4, 1.0);
    ctx = rct_context(b, 2, 0);
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 96, 48, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rays = 16 * 360;
    rct_buffers_alloc(&buf, 3u * rays, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 3, &buf.res));
    for (p = 0; p < 3; ++p) {
        rc_spherical_desc sd;
        double R[9], o[3];
        assert_int_equal(rc_preset_spherical(RC_PRESET_VELODYNE_VLP16_360, &sd), RC_OK);
        for (i = 0; i < 3; ++i) o[i] = poses[p].position[i];
        pose_rotation(&poses[p], R);
        for (i = 0; i < rays; ++i) {
            uint32_t k = p * rays + i, r = i / 360, c = i % 360, prim;
            double th = sd.theta.min + c * (double)sd.theta.increment, ph = sd.phi.min + r * (double)sd.phi.increment;
            double ds[3] = {cos(ph) * cos(th), cos(ph) * sin(th), sin(ph)}, dw[3], t, tb;
            const uint32_t *tri;
            int j;
            for (j = 0; j < 3; ++j) dw[j] = R[3 * j] * ds[0] + R[3 * j + 1] * ds[1] + R[3 * j + 2] * ds[2];
            assert_int_equal(buf.res.hits[k], 1);
            prim = buf.res.prim_ids[k];
            assert_true(prim < m.triangle_count);
            tri = m.indices + 3u * prim;
            t = rct_ray_plane_t(o, dw, m.vertices + 3u * tri[0], m.vertices + 3u * tri[1], m.vertices + 3u * tri[2]);
            if (fabs(buf.res.ranges[k] - t) > max_err) max_err = fabs(buf.res.ranges[k] - t);
            if ((i % 97) == 0) { /* brute force on a sample: same nearest surface */
                rct_brute_nearest(&m, o, dw, &tb);
                assert_true(fabs(tb - buf.res.ranges[k]) <= 1e-4);
            }
        }
    }
    /* float32 at 20 m: a few micrometres */
    if (max_err > 2e-5) fail_msg("max range error %.3g m against float64", max_err);
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* REP 117: nearer than range_min blocks the beam and reads -inf; nothing within
 * range_max reads +inf; invalid returns give hit 0, NaN points/normals and
 * RC_INVALID_ID ids. */
static void test_rep117_limits(void **state)
{
    uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh wall, far_wall;
    float dirs[9] = {1, 0, 0, -1, 0, 0, 0, 1, 0};
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t g, i;
    NEED_BACKEND(b);
    ctx = rct_context(b, 1, 0);
    wall_mesh(0.2f, &wall);    /* +x at 0.2 m: nearer than range_min 0.5 */
    wall_mesh(-200.0f, &far_wall); /* -x at 200 m: beyond range_max 130 */
    sd.max_geometries = 2;
    sd.max_triangles = 4;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = wall.vertices;
    md.vertex_count = wall.vertex_count;
    md.indices = wall.indices;
    md.triangle_count = wall.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    md.vertices = far_wall.vertices;
    md.indices = far_wall.indices;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    assert_int_equal(g, 1);
    RCT_OK(ctx, rc_scene_commit(scene));
    sensor = rct_sensor_dirs(ctx, dirs, 3, 0.5f, 130.0f);
    rct_buffers_alloc(&buf, 3, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    assert_true(isinf(buf.res.ranges[0]) && buf.res.ranges[0] < 0); /* too near */
    assert_true(isinf(buf.res.ranges[1]) && buf.res.ranges[1] > 0); /* beyond max */
    assert_true(isinf(buf.res.ranges[2]) && buf.res.ranges[2] > 0); /* nothing */
    for (i = 0; i < 3; ++i) {
        assert_int_equal(buf.res.hits[i], 0);
        assert_true(isnan(buf.res.points[3 * i]) && isnan(buf.res.points[3 * i + 2]));
        assert_true(isnan(buf.res.normals[3 * i + 1]));
        assert_int_equal(buf.res.prim_ids[i], RC_INVALID_ID);
        assert_int_equal(buf.res.geom_ids[i], RC_INVALID_ID);
        assert_int_equal(buf.res.inst_ids[i], RC_INVALID_ID);
    }
    /* with range_max 300 the far wall is a valid return of geometry 1 */
    {
        rc_sensor *s2 = rct_sensor_dirs(ctx, dirs, 3, 0.5f, 300.0f);
        RCT_OK(ctx, rc_simulate(ctx, scene, s2, &pose, 1, &buf.res));
        assert_int_equal(buf.res.hits[1], 1);
        assert_true(fabs(buf.res.ranges[1] - 200.0f) < 1e-3);
        assert_int_equal(buf.res.geom_ids[1], 1);
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&wall);
    rcu_mesh_free(&far_wall);
    rc_context_destroy(ctx);
}

/* Instances: a unit box placed twice (translated + rotated + non-uniform
 * scale); the answers are the transformed box's, with instance ids and
 * normals that stay perpendicular to the scaled faces. */
static void test_instances(void **state)
{
    uint32_t b = rct_backend_of(state);
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    rc_context *ctx;
    rc_scene *box, *world;
    rc_sensor *sensor;
    rcu_mesh m;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    uint32_t i0, i1;
    /* ray 0: +x towards instance 0 at x = 10 (scale x 2: face at 9);
     * ray 1: +y towards instance 1 at y = 5, rotated 90 deg about z, scale (1, 3, 1):
     *        after rotation its local x (scale 1) lies along world y → face at 4.5;
     * ray 2: +z: nothing. */
    float dirs[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    NEED_BACKEND(b);
    ctx = rct_context(b, 1, 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    box = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    sd.max_geometries = 1;
    sd.max_instances = 2;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &world));
    id.source = box;
    id.transform = rct_pose(10.0f, 0.0f, 0.0f);
    id.scale[0] = 2.0f;
    id.scale[1] = 1.0f;
    id.scale[2] = 1.0f;
    RCT_OK(ctx, rc_scene_add_instance(world, &id, &i0));
    id.transform = rct_pose_ypr(0.0f, 5.0f, 0.0f, 90.0 * DEG, 0.0, 0.0);
    id.scale[0] = 1.0f;
    id.scale[1] = 3.0f;
    RCT_OK(ctx, rc_scene_add_instance(world, &id, &i1));
    assert_int_equal(i0, 0);
    assert_int_equal(i1, 1);
    RCT_OK(ctx, rc_scene_commit(world));
    sensor = rct_sensor_dirs(ctx, dirs, 3, 0.1f, 100.0f);
    rct_buffers_alloc(&buf, 3, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, world, sensor, &pose, 1, &buf.res));
    assert_int_equal(buf.res.hits[0], 1);
    assert_true(fabs(buf.res.ranges[0] - 9.0f) < 1e-5);
    assert_int_equal(buf.res.inst_ids[0], 0);
    assert_int_equal(buf.res.geom_ids[0], 0);
    assert_true(fabs(buf.res.normals[0] + 1.0f) < 1e-5);
    assert_int_equal(buf.res.hits[1], 1);
    assert_true(fabs(buf.res.ranges[1] - 4.5f) < 1e-5);
    assert_int_equal(buf.res.inst_ids[1], 1);
    assert_true(fabs(buf.res.normals[4] + 1.0f) < 1e-5);
    assert_int_equal(buf.res.hits[2], 0);
    /* move instance 0 (dynamic map): stale until commit, then the new answer */
    {
        rc_pose moved = rct_pose(20.0f, 0.0f, 0.0f);
        const float s[3] = {2.0f, 1.0f, 1.0f};
        RCT_OK(ctx, rc_scene_set_instance_transform(world, 0, &moved, s));
        assert_int_equal(rc_simulate(ctx, world, sensor, &pose, 1, &buf.res), RC_ERR_NOT_COMMITTED);
        RCT_OK(ctx, rc_scene_commit(world));
        RCT_OK(ctx, rc_simulate(ctx, world, sensor, &pose, 1, &buf.res));
        assert_true(fabs(buf.res.ranges[0] - 19.0f) < 1e-5);
    }
    /* a source that is instanced cannot be destroyed first */
    assert_int_equal(rc_scene_destroy(box), RC_ERR_MISUSE);
    RCT_OK(ctx, rc_scene_destroy(world));
    RCT_OK(ctx, rc_scene_destroy(box));
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* Watertightness: rays from inside closed meshes aimed exactly at every vertex
 * and at points on every edge. None may escape. */
static void check_closed(uint32_t b, const rcu_mesh *m, const float origin[3])
{
    rc_context *ctx = rct_context(b, 2, 0);
    rc_scene *scene = rct_scene_mesh(ctx, m, RC_MESH_REFERENCE);
    uint32_t n = m->vertex_count + 3u * m->triangle_count * 3u, i, k = 0, escapes = 0;
    float *dirs = (float *)malloc(sizeof(float) * 3u * n);
    rc_sensor *sensor;
    rct_buffers buf;
    rc_pose pose = rct_pose(origin[0], origin[1], origin[2]);
    static const float ts[3] = {0.5f, 0.25f, 0.8125f};
    assert_non_null(dirs);
    for (i = 0; i < m->vertex_count; ++i, ++k) {
        int j;
        for (j = 0; j < 3; ++j) dirs[3 * k + j] = m->vertices[3 * i + j] - origin[j];
    }
    for (i = 0; i < m->triangle_count; ++i) {
        int e, s, j;
        for (e = 0; e < 3; ++e)
            for (s = 0; s < 3; ++s, ++k) {
                const float *a = m->vertices + 3u * m->indices[3 * i + e];
                const float *c = m->vertices + 3u * m->indices[3 * i + (e + 1) % 3];
                for (j = 0; j < 3; ++j) dirs[3 * k + j] = a[j] + ts[s] * (c[j] - a[j]) - origin[j];
            }
    }
    sensor = rct_sensor_dirs(ctx, dirs, n, 0.0f, 1.0e5f);
    rct_buffers_alloc(&buf, n, RC_ATTR_HITS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    for (i = 0; i < n; ++i) escapes += buf.res.hits[i] ? 0u : 1u;
    if (escapes) fail_msg("%u of %u rays aimed at edges and vertices escaped", escapes, n);
    rct_buffers_free(&buf);
    free(dirs);
    rc_context_destroy(ctx);
}

static void test_watertight(void **state)
{
    uint32_t b = rct_backend_of(state);
    rcu_mesh m;
    const float lo[3] = {-1.0f, -2.0f, -3.0f}, hi[3] = {4.0f, 5.0f, 6.0f};
    const float c0[3] = {0, 0, 0}, c1[3] = {0.3f, -0.7f, 0.1f}, c2[3] = {1.0f, 1.0f, 1.0f};
    NEED_BACKEND(b);
    if (b == RC_BACKEND_VULKAN && rct_env_on("RANGECAST_VULKAN_RAY_QUERY")) {
        /* the driver's triangle test decides; test_vulkan_ray_query counts
         * its escapes against the compute traversal's none */
        print_message("SKIP: the ray query traversal is as watertight as the driver (RANGECAST_VULKAN_RAY_QUERY)\n");
        skip();
    }
    assert_int_equal(rcu_mesh_uv_sphere(5.0f, 40, 20, &m), 0);
    check_closed(b, &m, c0);
    check_closed(b, &m, c1);
    rcu_mesh_free(&m);
    assert_int_equal(rcu_mesh_uv_sphere(1000.0f, 17, 11, &m), 0);
    check_closed(b, &m, c1);
    rcu_mesh_free(&m);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    check_closed(b, &m, c0);  /* axis-parallel rays hit the box's edges exactly */
    check_closed(b, &m, c2);
    rcu_mesh_free(&m);
}

/* Thread count never changes a single bit of the results. */
static void test_thread_independence(void **state)
{
    uint32_t b = rct_backend_of(state);
    static const uint32_t counts[] = {1, 2, 3, 7};
    rcu_mesh m;
    rct_buffers ref, cur;
    rc_pose poses[5];
    uint32_t t, i, rays = 16 * 360;
    NEED_BACKEND(b);
    for (i = 0; i < 5; ++i) poses[i] = rct_pose_ypr(1.0f * i, -0.5f * i, 0.2f * i, 0.3 * i, 0.05 * i, -0.1 * i);
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 120, 60, &m), 0);
    rct_buffers_alloc(&ref, 5u * rays, RC_ATTR_ALL);
    rct_buffers_alloc(&cur, 5u * rays, RC_ATTR_ALL);
    for (t = 0; t < 4; ++t) {
        rc_context *ctx = rct_context(b, counts[t], 0);
        rc_scene *scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
        rc_sensor *sensor;
        rct_buffers *out = t == 0 ? &ref : &cur;
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 5, &out->res));
        if (t > 0) {
            assert_memory_equal(ref.res.ranges, cur.res.ranges, 5u * rays * 4u);
            assert_memory_equal(ref.res.hits, cur.res.hits, 5u * rays);
            assert_memory_equal(ref.res.points, cur.res.points, 5u * rays * 12u);
            assert_memory_equal(ref.res.normals, cur.res.normals, 5u * rays * 12u);
            assert_memory_equal(ref.res.prim_ids, cur.res.prim_ids, 5u * rays * 4u);
        }
        rc_context_destroy(ctx);
    }
    rct_buffers_free(&ref);
    rct_buffers_free(&cur);
    rcu_mesh_free(&m);
}

/* Only requested attributes are written; the others keep the caller's bytes. */
static void test_only_requested_attributes(void **state)
{
    uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh m;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    const float lo[3] = {-3, -3, -3}, hi[3] = {3, 3, 3};
    uint8_t before[64];
    NEED_BACKEND(b);
    ctx = rct_context(b, 1, 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rct_buffers_alloc(&buf, 16 * 360, RC_ATTR_RANGES | RC_ATTR_GEOM_IDS);
    rct_buffers_fill(&buf, 0xAB);
    memset(before, 0xAB, sizeof before);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    assert_memory_equal(buf.res.hits, before, 64);
    assert_memory_equal(buf.res.points, before, 64);
    assert_memory_equal(buf.res.normals, before, 64);
    assert_memory_equal(buf.res.prim_ids, before, 64);
    assert_memory_equal(buf.res.inst_ids, before, 64);
    assert_true(buf.res.ranges[0] > 3.0f && buf.res.ranges[0] < 6.0f);
    assert_int_equal(buf.res.geom_ids[0], 0);
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* Coplanar duplicate triangles: the lower triangle index wins, every time. */
static void test_coplanar_tie(void **state)
{
    uint32_t b = rct_backend_of(state);
    rcu_mesh a, both;
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    float dirs[3 * 16];
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    uint32_t i;
    NEED_BACKEND(b);
    wall_mesh(3.0f, &a);
    memset(&both, 0, sizeof both);
    assert_int_equal(rcu_mesh_append(&both, &a), 0);
    assert_int_equal(rcu_mesh_append(&both, &a), 0); /* triangles 2, 3 duplicate 0, 1 */
    ctx = rct_context(b, 1, 0);
    scene = rct_scene_mesh(ctx, &both, RC_MESH_REFERENCE);
    for (i = 0; i < 16; ++i) {
        dirs[3 * i] = 1.0f;
        dirs[3 * i + 1] = -0.5f + i / 15.0f;
        dirs[3 * i + 2] = 0.3f - 0.04f * i;
    }
    sensor = rct_sensor_dirs(ctx, dirs, 16, 0.0f, 100.0f);
    rct_buffers_alloc(&buf, 16, RC_ATTR_PRIM_IDS | RC_ATTR_HITS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    for (i = 0; i < 16; ++i) {
        assert_int_equal(buf.res.hits[i], 1);
        assert_true(buf.res.prim_ids[i] <= 1);
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&a);
    rcu_mesh_free(&both);
    rc_context_destroy(ctx);
}

/* Depth camera facing a wall: range = d / cos(angle off the axis), both frames. */
static void test_pinhole_wall(void **state)
{
    uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *body, *optical;
    rc_pinhole_desc pd = rc_pinhole_desc_default();
    rcu_mesh m;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    uint32_t u, v;
    NEED_BACKEND(b);
    ctx = rct_context(b, 2, 0);
    wall_mesh(4.0f, &m);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    pd.common.range_min = 0.1f;
    pd.common.range_max = 50.0f;
    pd.width = 64;
    pd.height = 48;
    pd.fx = pd.fy = 40.0f;
    pd.cx = 32.0f;
    pd.cy = 24.0f;
    RCT_OK(ctx, rc_sensor_create_pinhole(ctx, &pd, &body));
    rct_buffers_alloc(&buf, 64 * 48, RC_ATTR_RANGES | RC_ATTR_POINTS);
    RCT_OK(ctx, rc_simulate(ctx, scene, body, &pose, 1, &buf.res));
    for (v = 0; v < 48; ++v)
        for (u = 0; u < 64; ++u) {
            double x = (u - 32.0) / 40.0, y = (v - 24.0) / 40.0, expect = 4.0 * sqrt(1 + x * x + y * y);
            uint32_t k = v * 64 + u;
            assert_true(fabs(buf.res.ranges[k] - expect) < 1e-5 * expect);
            assert_true(fabs(buf.res.points[3 * k + 1] + 4.0 * x) < 1e-4); /* right of centre: -y */
        }
    /* optical frame: the camera looks along its z; mount it so z points along +x */
    pd.frame = RC_PINHOLE_FRAME_OPTICAL;
    pd.common.sensor_to_base = rct_pose_ypr(0, 0, 0, -90.0 * DEG, 0.0, -90.0 * DEG);
    RCT_OK(ctx, rc_sensor_create_pinhole(ctx, &pd, &optical));
    RCT_OK(ctx, rc_simulate(ctx, scene, optical, &pose, 1, &buf.res));
    for (v = 0; v < 48; v += 5)
        for (u = 0; u < 64; u += 7) {
            double x = (u - 32.0) / 40.0, y = (v - 24.0) / 40.0, expect = 4.0 * sqrt(1 + x * x + y * y);
            uint32_t k = v * 64 + u;
            assert_true(fabs(buf.res.ranges[k] - expect) < 1e-5 * expect);
            assert_true(fabs(buf.res.points[3 * k + 2] - 4.0) < 1e-4); /* depth along optical z */
            assert_true(fabs(buf.res.points[3 * k] - 4.0 * x) < 1e-4);
        }
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}


/* A room far from the origin (UTM-like map coordinates): the scene's origin is
 * the room's corner, vertices are local, poses are double map coordinates.
 * Ranges stay within a micrometre-scale error at every offset up to 1e6 m. */
static void test_far_from_origin(void **state)
{
    uint32_t b = rct_backend_of(state);
    static const double offsets[4] = {1e3, 1e4, 1e5, 1e6};
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {12.0f, 8.0f, 3.0f};
    rcu_mesh m;
    float dirs[3 * 8];
    uint32_t k, i;
    NEED_BACKEND(b);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    for (i = 0; i < 8; ++i) {
        double a = i * 0.785398163397448;
        dirs[3 * i] = (float)cos(a);
        dirs[3 * i + 1] = (float)sin(a);
        dirs[3 * i + 2] = 0.1f;
    }
    for (k = 0; k < 4; ++k) {
        rc_context *ctx = rct_context(b, 1, 0);
        rc_scene_desc sd = rc_scene_desc_default();
        rc_mesh_desc md = rc_mesh_desc_default();
        rc_scene *scene;
        rc_sensor *sensor;
        rct_buffers buf;
        rc_pose_d pose;
        uint32_t g;
        const double o[3] = {offsets[k] + 0.123, offsets[k] * 0.5 + 0.456, 30.0};
        sd.max_triangles = m.triangle_count;
        sd.origin[0] = o[0];
        sd.origin[1] = o[1];
        sd.origin[2] = o[2];
        RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
        md.vertices = m.vertices;
        md.vertex_count = m.vertex_count;
        md.indices = m.indices;
        md.triangle_count = m.triangle_count;
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
        RCT_OK(ctx, rc_scene_commit(scene));
        sensor = rct_sensor_dirs(ctx, dirs, 8, 0.1f, 100.0f);
        memset(&pose, 0, sizeof pose);
        pose.position[0] = o[0] + 4.0000005; /* sub-millimetre parts must survive */
        pose.position[1] = o[1] + 3.0000007;
        pose.position[2] = o[2] + 1.0;
        pose.orientation[3] = 1.0;
        rct_buffers_alloc(&buf, 8, RC_ATTR_RANGES | RC_ATTR_HITS);
        RCT_OK(ctx, rc_simulate_d(ctx, scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < 8; ++i) {
            const double p[3] = {4.0000005, 3.0000007, 1.0};
            double d[3], len, expect;
            int axis = -1;
            d[0] = dirs[3 * i];
            d[1] = dirs[3 * i + 1];
            d[2] = dirs[3 * i + 2];
            len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            d[0] /= len;
            d[1] /= len;
            d[2] /= len;
            expect = box_exit(p, d, lo, hi, &axis);
            assert_int_equal(buf.res.hits[i], 1);
            if (fabs(buf.res.ranges[i] - expect) > 1e-5)
                fail_msg("offset %g ray %u: range %.7f expected %.7f", offsets[k], i, (double)buf.res.ranges[i], expect);
        }
        rct_buffers_free(&buf);
        rc_context_destroy(ctx);
    }
    rcu_mesh_free(&m);
}

/* A triangle whose vertices move between collinear (zero area: never hit)
 * and whole, through rc_scene_update_mesh and commits: rays aimed along the
 * collinear segment read the wall behind it, rays aimed inside the whole
 * triangle read the triangle. The built-in backend keeps its leaves' zero-area
 * triangles folded to (a, a, a) (bvh/mesh.h: flats_folded) and must unfold
 * and fold again on every refit; a baked copy of the collinear state reads
 * the same bits. */
static void zero_area_scan(rc_context *ctx, rc_scene *scene, rc_sensor *sensor, const float *dirs, uint32_t n,
                           int whole, float *ranges_out)
{
    rct_buffers buf;
    rc_pose pose = rct_pose(0.0f, 0.0f, 0.0f);
    uint32_t i;
    rct_buffers_alloc(&buf, n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
    for (i = 0; i < n; ++i) {
        const double len = sqrt((double)dirs[3 * i] * dirs[3 * i] + (double)dirs[3 * i + 1] * dirs[3 * i + 1] +
                                (double)dirs[3 * i + 2] * dirs[3 * i + 2]);
        /* rays 0..15 aim inside the whole triangle, 16..31 at the collinear
         * segment (an edge of the whole triangle: either answer there), the
         * rest at the wall; the triangle is at x = 5, the wall at x = 10 */
        const int on_triangle = whole && (i < 16u || (i < 32u && buf.res.prim_ids[i] == 2u));
        const double expect = (on_triangle ? 5.0 : 10.0) * len / dirs[3 * i];
        assert_int_equal(buf.res.hits[i], 1);
        if (fabs(buf.res.ranges[i] - expect) > 1e-5 * expect || (buf.res.prim_ids[i] == 2u) != on_triangle)
            fail_msg("%s, ray %u: range %.7f prim %u, expected %.7f on the %s", whole ? "whole" : "collinear", i,
                     (double)buf.res.ranges[i], (unsigned)buf.res.prim_ids[i], expect,
                     on_triangle ? "triangle" : "wall");
        if (ranges_out) ranges_out[i] = buf.res.ranges[i];
    }
    rct_buffers_free(&buf);
}

static void test_zero_area_updates(void **state)
{
    enum { RAYS = 64 };
    uint32_t b = rct_backend_of(state);
    /* wall x = 10 (two triangles), then a, b, c at x = 5 with c = a + 2 (b - a) */
    static const float wall_and_segment[3 * 7] = {10.0f, -50.0f, -50.0f, 10.0f, 50.0f, -50.0f, 10.0f, 50.0f, 50.0f,
                                                  10.0f, -50.0f, 50.0f, 5.0f,  -1.0f, -0.5f, 5.0f,  0.0f,
                                                  0.0f,  5.0f,  1.0f,  0.5f};
    static const uint32_t tris[9] = {0, 1, 2, 0, 2, 3, 4, 5, 6};
    const float whole_c[3] = {5.0f, 1.0f, -2.0f};
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rcu_mesh m;
    float dirs[3 * RAYS], live[RAYS];
    uint32_t i, round;
    NEED_BACKEND(b);
    ctx = rct_context(b, 2, 0);
    m.vertex_count = 7;
    m.triangle_count = 3;
    m.vertices = (float *)malloc(sizeof wall_and_segment);
    m.indices = (uint32_t *)malloc(sizeof tris);
    assert_non_null(m.vertices);
    assert_non_null(m.indices);
    memcpy(m.vertices, wall_and_segment, sizeof wall_and_segment);
    memcpy(m.indices, tris, sizeof tris);
    /* rays 0..15: a + s (b - a) + w (c' - b), inside a, b, c' (s > w > 0);
     * 16..31: a + s (c - a), on the collinear segment (exact in float);
     * 32..63: the wall away from both */
    for (i = 0; i < 16u; ++i) {
        const float s = 0.1f + 0.8f * (float)(i / 2u) / 7.0f, w = (i & 1u) ? 0.05f : 0.02f;
        dirs[3 * i] = 5.0f;
        dirs[3 * i + 1] = -1.0f + s + w;
        dirs[3 * i + 2] = -0.5f + s * 0.5f - 2.0f * w;
    }
    for (; i < 32u; ++i) {
        const float s = (float)(i - 16u) / 8.0f; /* 0, 1/8 ... 15/8 of b - a */
        dirs[3 * i] = 5.0f;
        dirs[3 * i + 1] = -1.0f + s;
        dirs[3 * i + 2] = -0.5f + 0.5f * s;
    }
    for (; i < RAYS; ++i) {
        dirs[3 * i] = 5.0f;
        dirs[3 * i + 1] = 2.0f + 0.05f * (float)(i - RAYS / 2);
        dirs[3 * i + 2] = 1.5f;
    }
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    sensor = rct_sensor_dirs(ctx, dirs, RAYS, 0.1f, 100.0f);
    zero_area_scan(ctx, scene, sensor, dirs, RAYS, 0, NULL);
    for (round = 0; round < 2; ++round) {
        memcpy(m.vertices + 3 * 6, whole_c, sizeof whole_c);
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        RCT_OK(ctx, rc_scene_commit(scene));
        zero_area_scan(ctx, scene, sensor, dirs, RAYS, 1, NULL);
        memcpy(m.vertices + 3 * 6, wall_and_segment + 3 * 6, 3 * sizeof(float));
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        RCT_OK(ctx, rc_scene_commit(scene));
        zero_area_scan(ctx, scene, sensor, dirs, RAYS, 0, live);
    }
    if (b == RC_BACKEND_BVH) {
        /* baked: the file keeps whole triples; the loaded map checks areas */
        size_t need = 0, n = 0;
        void *blob;
        rc_scene *loaded = NULL;
        float baked[RAYS];
        RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &need));
        blob = rct_alloc16(need);
        RCT_OK(ctx, rc_scene_bake(scene, blob, need, &n));
        RCT_OK(ctx, rc_scene_load_baked(ctx, blob, n, 0, &loaded));
        zero_area_scan(ctx, loaded, sensor, dirs, RAYS, 0, baked);
        assert_memory_equal(baked, live, sizeof live);
        rc_scene_destroy(loaded);
        free(blob);
    }
    rc_sensor_destroy(sensor);
    rc_scene_destroy(scene);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

/* Ranges alone (the writer's loop without points and normals) against the
 * same call with every attribute (its loop that tests each), bit for bit: a
 * room with an opening, one pose 0.3 m from a wall (too near: -inf),
 * range_max short of the far walls (+inf), through a spinning LiDAR and a
 * camera (packets, or projected scans, in the built-in backend), three
 * poses. */
static void test_ranges_alone(void **state)
{
    uint32_t b = rct_backend_of(state);
    const float lo[3] = {-3.0f, -2.0f, -0.2f}, hi[3] = {6.0f, 3.0f, 2.5f};
    const rc_pose poses[3] = {rct_pose_ypr(-2.7f, 0.5f, 1.0f, 2.8, 0.1, 0.0),
                              rct_pose_ypr(1.0f, 1.0f, 1.2f, -2.0, 0.2, 0.4), rct_pose(0.5f, -1.7f, 0.8f)};
    rc_context *ctx;
    rc_scene *scene;
    rcu_mesh m;
    int k;
    NEED_BACKEND(b);
    ctx = rct_context(b, 2, 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    memmove(m.indices, m.indices + 6u, (m.triangle_count - 2u) * 3u * sizeof(uint32_t));
    m.triangle_count -= 2u;
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    for (k = 0; k < 2; ++k) {
        rc_sensor *s = NULL;
        rct_buffers all, alone;
        uint64_t i, near = 0, none = 0, ok = 0;
        const uint32_t rays = k == 0 ? 16u * 900u : 61u * 45u;
        if (k == 0) {
            rc_spherical_desc d = rc_spherical_desc_default();
            d.common.range_min = 0.5f;
            d.common.range_max = 5.0f;
            d.theta.min = (float)(-180.0 * DEG);
            d.theta.increment = (float)(0.4 * DEG);
            d.theta.count = 900u;
            d.phi.min = (float)(-15.0 * DEG);
            d.phi.increment = (float)(2.0 * DEG);
            d.phi.count = 16u;
            RCT_OK(ctx, rc_sensor_create_spherical(ctx, &d, &s));
        } else {
            rc_pinhole_desc d = rc_pinhole_desc_default();
            d.common.range_min = 0.5f;
            d.common.range_max = 5.0f;
            d.width = 61u; /* rows of 61 rays: runs that end mid-group */
            d.height = 45u;
            d.fx = d.fy = 40.0f;
            d.cx = 30.0f;
            d.cy = 22.0f;
            RCT_OK(ctx, rc_sensor_create_pinhole(ctx, &d, &s));
        }
        rct_buffers_alloc(&all, 3u * rays, RC_ATTR_ALL);
        rct_buffers_alloc(&alone, 3u * rays, RC_ATTR_RANGES);
        RCT_OK(ctx, rc_simulate(ctx, scene, s, poses, 3u, &all.res));
        RCT_OK(ctx, rc_simulate(ctx, scene, s, poses, 3u, &alone.res));
        assert_memory_equal(all.res.ranges, alone.res.ranges, all.n * sizeof(float));
        for (i = 0; i < all.n; ++i) {
            const float r = alone.res.ranges[i];
            near += isinf(r) && r < 0.0f;
            none += isinf(r) && r > 0.0f;
            ok += !isinf(r);
        }
        assert_true(near > 0 && none > 0 && ok > all.n / 4u);
        rct_buffers_free(&all);
        rct_buffers_free(&alone);
        rc_sensor_destroy(s);
    }
    rc_scene_destroy(scene);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        RCT_FOR_BACKENDS(test_plane_at_distance), RCT_FOR_BACKENDS(test_box_room_vlp16),
        RCT_FOR_BACKENDS(test_inside_sphere),     RCT_FOR_BACKENDS(test_rep117_limits),
        RCT_FOR_BACKENDS(test_instances),         RCT_FOR_BACKENDS(test_watertight),
        RCT_FOR_BACKENDS(test_thread_independence), RCT_FOR_BACKENDS(test_only_requested_attributes),
        RCT_FOR_BACKENDS(test_coplanar_tie),      RCT_FOR_BACKENDS(test_pinhole_wall),
        RCT_FOR_BACKENDS(test_far_from_origin),   RCT_FOR_BACKENDS(test_zero_area_updates),
        RCT_FOR_BACKENDS(test_ranges_alone),
    };
    return cmocka_run_group_tests_name("scenes (every backend)", tests, NULL, NULL);
}
