/* The float64 refinement of a hit's range against a ray that runs along the
 * hit triangle's plane (fuzz_trace's finding of session 44, as a scene of
 * its own). An instance's transform moves the ray into the triangle's frame
 * in float, a hair off the plane and a hair tilted, so the watertight test
 * finds a hit at t = 0.2309; in double, through the same transform, the ray
 * runs along the plane and crosses it some 8e8 m away, far off the
 * triangle. The refinement used to take that crossing: past the range max,
 * the hit read as no return, and the wall behind it, which the hit had
 * culled, was lost too. It now keeps the traversal's t where the crossing
 * lies far from the triangle's corners' depths along the ray
 * (rc__scene_hit_distance_d), so the hit stands at the float test's t. Checked
 * with ranges alone (a tile's hits refined in groups of lanes) and with
 * every attribute (one hit at a time), for one ray and for five (a group of
 * four and one left over), on each backend built in that shares the rule
 * (the built-in BVH, and the Vulkan kernel's refine_t). */
#include <math.h>
#include <string.h>

#include "rc_test.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

#define RAYS 5u
#define RANGE_MAX 100.0f

/* The grazed triangle lies in the plane x = z of its own frame. */
static const float tri_verts[9] = {4, 4, 4, 4, -4, 4, -4, -4, -4};
static const uint32_t tri_index[3] = {0, 1, 2};
/* A wall 3 m down the ray's way, behind the triangle's hit */
static const float wall_verts[12] = {-3, 0, -2, -3, 0, 4, -3, 6, -2, -3, 6, 4};
static const uint32_t wall_index[6] = {0, 1, 2, 2, 1, 3};

static void add_mesh(rc_scene *scene, const float *v, uint32_t nv, const uint32_t *idx, uint32_t nt)
{
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t geom;
    md.vertices = v;
    md.vertex_count = nv;
    md.indices = idx;
    md.triangle_count = nt;
    assert_int_equal(rc_scene_add_mesh(scene, &md, &geom), RC_OK);
}

static rc_scene *grazing_scene(rc_context *ctx, rc_scene **source)
{
    const float q[4] = {1.0f, 1.0f, -3.0f, -1.0f}, n = sqrtf(12.0f);
    rc_scene_desc sd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rc_scene *scene;
    uint32_t inst, k;
    sd.max_triangles = 2;
    sd.max_vertices = 4;
    assert_int_equal(rc_scene_create(ctx, &sd, source), RC_OK);
    add_mesh(*source, tri_verts, 3, tri_index, 1);
    assert_int_equal(rc_scene_commit(*source), RC_OK);
    sd.max_instances = 1;
    assert_int_equal(rc_scene_create(ctx, &sd, &scene), RC_OK);
    add_mesh(scene, wall_verts, 4, wall_index, 2);
    id.source = *source;
    id.transform.position[0] = 1.0f;
    for (k = 0; k < 4; ++k) id.transform.orientation[k] = q[k] / n;
    id.scale[0] = id.scale[2] = 1.0f / 3.0f;
    id.scale[1] = 2.0f;
    assert_int_equal(rc_scene_add_instance(scene, &id, &inst), RC_OK);
    assert_int_equal(rc_scene_commit(scene), RC_OK);
    return scene;
}

static void run_backend(uint32_t backend)
{
    const float dirs[3u * RAYS] = {-1, 1, 1, -1, 1, 1, -1, 1, 1, -1, 1, 1, -1, 1, 1};
    rc_context_desc cd = rc_context_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    rc_context *ctx;
    rc_scene *scene, *source;
    rc_sensor *sensor;
    rc_pose pose = rc_pose_identity();
    float want_t, org[3] = {0, 0, 0};
    rc__ray ray;
    rc__hit h;
    uint32_t n, pass;
    if (!rct_backend_usable(backend)) skip(); /* not built in, or no device here */
    cd.backend = backend;
    cd.thread_count = 1;
    assert_int_equal(rc_context_create(&cd, &ctx), RC_OK);
    scene = grazing_scene(ctx, &source);
    rd.common.range_max = RANGE_MAX;
    rd.directions = dirs;
    rd.ray_count = RAYS;
    assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &sensor), RC_OK);

    /* the built-in traversal's hit: the instance's triangle, nearer than
     * the wall */
    rc__ray_prepare(&ray, org, sensor->directions);
    h.t = RANGE_MAX;
    h.prim = h.geom = h.inst = h.slot = RC_INVALID_ID;
    if (backend == RC_BACKEND_BVH) {
        assert_true(rc__scene_intersect(scene, &ray, &h));
        assert_int_equal(h.inst, 0);
        assert_true(h.t > 0.2f && h.t < 0.25f);
    }
    want_t = backend == RC_BACKEND_BVH ? h.t : 0.230940104f;

    for (n = 1; n <= RAYS; n += RAYS - 1u) {
        for (pass = 0; pass < 2; ++pass) {
            uint8_t hits[RAYS];
            float ranges[RAYS], points[3u * RAYS], normals[3u * RAYS];
            uint32_t insts[RAYS], prims[RAYS], geoms[RAYS], i;
            rc_results res = rc_results_default();
            rc_sensor *s = sensor;
            if (n != RAYS) {
                rd.ray_count = n;
                assert_int_equal(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &s), RC_OK);
            }
            /* pass 0: ranges alone (refined in groups); 1: every attribute */
            res.attributes = pass == 0 ? RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_INST_IDS : RC_ATTR_ALL;
            res.hits = hits;
            res.ranges = ranges;
            res.inst_ids = insts;
            res.points = points;
            res.normals = normals;
            res.prim_ids = prims;
            res.geom_ids = geoms;
            res.capacity = n;
            assert_int_equal(rc_simulate(ctx, scene, s, &pose, 1, &res), RC_OK);
            for (i = 0; i < n; ++i) {
                assert_int_equal(hits[i], 1);
                assert_int_equal(insts[i], 0);
                if (backend == RC_BACKEND_BVH)
                    assert_true(ranges[i] == want_t);
                else
                    assert_true(fabsf(ranges[i] - want_t) <= 1e-6f);
            }
            if (s != sensor) rc_sensor_destroy(s);
        }
    }
    rc_sensor_destroy(sensor);
    rc_scene_destroy(scene);
    rc_scene_destroy(source);
    rc_context_destroy(ctx);
}

static void test_grazing_builtin(void **state)
{
    (void)state;
    run_backend(RC_BACKEND_BVH);
}

static void test_grazing_vulkan(void **state)
{
    (void)state;
    run_backend(RC_BACKEND_VULKAN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_grazing_builtin), cmocka_unit_test(test_grazing_vulkan)};
    return cmocka_run_group_tests_name("grazing refinement", tests, NULL, NULL);
}
