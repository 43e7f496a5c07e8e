/* Every bad input to scenes and simulate: its own status, a message naming the
 * argument, and nothing written to the output buffers. */
#include <math.h>
#include <string.h>

#include "rc_test.h"

typedef struct fixture {
    rc_context *ctx;
    rcu_mesh mesh;
    rc_scene *scene;
    rc_sensor *sensor;
    rct_buffers buf;
} fixture;

static int setup(void **state)
{
    static fixture f;
    const float lo[3] = {-4, -4, -4}, hi[3] = {4, 4, 4};
    memset(&f, 0, sizeof f);
    f.ctx = rct_context(RC_BACKEND_BVH, 2, 16);
    assert_int_equal(rcu_mesh_box(lo, hi, &f.mesh), 0);
    f.scene = rct_scene_mesh(f.ctx, &f.mesh, RC_MESH_REFERENCE);
    RCT_OK(f.ctx, rc_sensor_create_preset(f.ctx, RC_PRESET_VELODYNE_VLP16_360, &f.sensor));
    rct_buffers_alloc(&f.buf, 2 * 16 * 360, RC_ATTR_ALL);
    rct_buffers_fill(&f.buf, 0x5A);
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = (fixture *)*state;
    rct_buffers_free(&f->buf);
    rc_context_destroy(f->ctx);
    rcu_mesh_free(&f->mesh);
    return 0;
}

#define EXPECT_FAIL(f, call, status, word)                                                          \
    do {                                                                                            \
        rc_status s_ = (call);                                                                      \
        if (s_ != (status))                                                                         \
            fail_msg("%s gave %s, expected %s (%s)", #call, rc_status_string(s_), rc_status_string(status), \
                     rc_context_last_error((f)->ctx));                                              \
        if ((word) && !strstr(rc_context_last_error((f)->ctx), (word)))                             \
            fail_msg("%s: message '%s' does not name '%s'", #call, rc_context_last_error((f)->ctx), (word)); \
        assert_true(rct_buffers_untouched(&(f)->buf, 0x5A));                                       \
    } while (0)

static void test_simulate_bad_input(void **state)
{
    fixture *f = (fixture *)*state;
    rc_pose poses[2] = {rc_pose_identity(), rc_pose_identity()};
    rc_results r = f->buf.res;
    rc_context *other = rct_context(RC_BACKEND_BVH, 1, 16);
    rc_scene *uncommitted, *foreign;
    rc_scene_desc sd = rc_scene_desc_default();
    sd.max_triangles = 12;
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &uncommitted));
    foreign = rct_scene_mesh(other, &f->mesh, RC_MESH_REFERENCE);

    assert_int_equal(rc_simulate(NULL, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_HANDLE);
    EXPECT_FAIL(f, rc_simulate(f->ctx, NULL, f->sensor, poses, 1, &r), RC_ERR_INVALID_HANDLE, "scene");
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, NULL, poses, 1, &r), RC_ERR_INVALID_HANDLE, "sensor");
    EXPECT_FAIL(f, rc_simulate(f->ctx, foreign, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "context");
    EXPECT_FAIL(f, rc_simulate(f->ctx, uncommitted, f->sensor, poses, 1, &r), RC_ERR_NOT_COMMITTED, "commit");
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, NULL, 1, &r), RC_ERR_INVALID_ARGUMENT, "poses");
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 0, &r), RC_ERR_INVALID_ARGUMENT, "pose_count");
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, NULL), RC_ERR_INVALID_ARGUMENT, "results");
    r.capacity = 16 * 360 - 1;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_CAPACITY, "capacity");
    r = f->buf.res;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 3, &r), RC_ERR_CAPACITY, "capacity");
    r.struct_size = 12;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_STRUCT_SIZE, "struct_size");
    r = f->buf.res;
    r.reserved[6] = 1;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "reserved");
    r = f->buf.res;
    r.flags = 0x80;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "flags");
    r.flags = RC_RESULTS_ON_DEVICE; /* the built-in backend has no device */
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_UNSUPPORTED, "RC_RESULTS_ON_DEVICE");
    {
        rc_device_results dr = rc_device_results_default();
        EXPECT_FAIL(f, rc_context_get_device_results(f->ctx, &dr), RC_ERR_UNSUPPORTED, "no device");
        EXPECT_FAIL(f, rc_context_get_device_results(f->ctx, NULL), RC_ERR_INVALID_ARGUMENT, "out");
    }
    r = f->buf.res;
    r.attributes = 0;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "attributes");
    r.attributes = 0x100;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "attributes");
    r = f->buf.res;
    r.normals = NULL;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 1, &r), RC_ERR_INVALID_ARGUMENT, "normals");
    r = f->buf.res;
    poses[1].position[2] = NAN; /* the second pose is bad: nothing of the first is written either */
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 2, &r), RC_ERR_NON_FINITE, "poses[1]");
    poses[1] = rc_pose_identity();
    poses[1].orientation[0] = INFINITY;
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 2, &r), RC_ERR_NON_FINITE, "poses[1]");
    poses[1] = rc_pose_identity();
    poses[1].orientation[3] = 0.5f; /* |q| = 0.5: rejected */
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 2, &r), RC_ERR_INVALID_ARGUMENT, "unit");
    poses[1].orientation[3] = 0.0f; /* zero quaternion */
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, poses, 2, &r), RC_ERR_INVALID_ARGUMENT, "unit");
    {
        rc_pose_d pd[1];
        memset(pd, 0, sizeof pd);
        pd[0].orientation[3] = 1.0;
        pd[0].position[0] = INFINITY;
        EXPECT_FAIL(f, rc_simulate_d(f->ctx, f->scene, f->sensor, pd, 1, &r), RC_ERR_NON_FINITE, "poses[0]");
        EXPECT_FAIL(f, rc_simulate_d(f->ctx, f->scene, f->sensor, NULL, 1, &r), RC_ERR_INVALID_ARGUMENT, "poses");
        pd[0].position[0] = 0.0;
        pd[0].orientation[3] = 0.9;
        EXPECT_FAIL(f, rc_simulate_d(f->ctx, f->scene, f->sensor, pd, 1, &r), RC_ERR_INVALID_ARGUMENT, "unit");
    }
    /* near-unit quaternions are normalised and accepted */
    poses[1].orientation[3] = 1.0005f;
    RCT_OK(f->ctx, rc_simulate(f->ctx, f->scene, f->sensor, poses, 2, &r));
    assert_true(fabs(r.ranges[16 * 360] - r.ranges[0]) < 1e-6);
    rc_context_destroy(other);
}

static void test_mesh_bad_input(void **state)
{
    fixture *f = (fixture *)*state;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_scene *s = NULL;
    uint32_t id = 77;
    float verts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint32_t tri[3] = {0, 1, 2};
    sd.max_triangles = 2;
    sd.max_geometries = 2;
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &s));
    md.vertices = verts;
    md.vertex_count = 3;
    md.indices = tri;
    md.triangle_count = 1;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, NULL, &id), RC_ERR_INVALID_ARGUMENT, "desc");
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, NULL), RC_ERR_INVALID_ARGUMENT, "geom_id");
    assert_int_equal(rc_scene_add_mesh(NULL, &md, &id), RC_ERR_INVALID_HANDLE);
    md.struct_size = 4;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_STRUCT_SIZE, "struct_size");
    md = rc_mesh_desc_default();
    md.vertices = verts;
    md.vertex_count = 3;
    md.indices = tri;
    md.triangle_count = 1;
    md.flags = 9;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "flags");
    md.flags = RC_MESH_REFERENCE;
    md.vertices = NULL;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "vertices");
    md.vertices = verts;
    md.vertex_count = 0;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "vertex_count");
    md.vertex_count = 3;
    md.triangle_count = 0;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "triangle_count");
    md.triangle_count = 1;
    md.vertex_stride = 10;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "vertex_stride");
    md.vertex_stride = 0;
    verts[4] = NAN;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_NON_FINITE, "vertices[1]");
    verts[4] = INFINITY;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_NON_FINITE, "vertices[1]");
    verts[4] = 0.0f;
    tri[2] = 3;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_OUT_OF_RANGE, "indices[2]");
    tri[2] = 2;
    md.reserved[0] = 5;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_INVALID_ARGUMENT, "reserved");
    md.reserved[0] = 0;
    md.flags = RC_MESH_COPY; /* the scene has no copy capacity */
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_CAPACITY, "max_vertices");
    md.flags = RC_MESH_REFERENCE;
    assert_int_equal(id, 77);
    /* commit of an empty scene */
    EXPECT_FAIL(f, rc_scene_commit(s), RC_ERR_INVALID_ARGUMENT, "empty");
    RCT_OK(f->ctx, rc_scene_add_mesh(s, &md, &id));
    RCT_OK(f->ctx, rc_scene_add_mesh(s, &md, &id));
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &id), RC_ERR_CAPACITY, "full");
    RCT_OK(f->ctx, rc_scene_commit(s));
    EXPECT_FAIL(f, rc_scene_update_mesh(s, 5), RC_ERR_OUT_OF_RANGE, "geom_id");
    RCT_OK(f->ctx, rc_scene_destroy(s));
    /* a destroyed scene is an invalid handle */
    assert_int_equal(rc_scene_commit(s), RC_ERR_INVALID_HANDLE);
}

static void test_scene_desc_bad_input(void **state)
{
    fixture *f = (fixture *)*state;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_scene *s = (rc_scene *)0x1;
    size_t bytes = 0;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "max_triangles");
    sd.max_triangles = 10;
    sd.max_copied_triangles = 11;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "max_copied_triangles");
    sd.max_copied_triangles = 0;
    sd.flags = 1;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "flags");
    sd.flags = 0;
    sd.build_quality = RC_BUILD_COMPACT + 1u;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "build_quality");
    EXPECT_FAIL(f, rc_scene_memory_requirements(f->ctx, &sd, &bytes), RC_ERR_INVALID_ARGUMENT, "build_quality");
    sd.build_quality = RC_BUILD_BALANCED;
    sd.reserved[6] = 1;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "reserved[6]");
    sd.reserved[6] = 0;
    sd.max_triangles = (uint64_t)1 << 40;
    EXPECT_FAIL(f, rc_scene_memory_requirements(f->ctx, &sd, &bytes), RC_ERR_INVALID_ARGUMENT, "max_triangles");
    sd.max_triangles = 10;
    sd.origin[1] = NAN;
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_NON_FINITE, "origin");
    sd.origin[1] = 0.0;
    sd.max_triangles = (uint64_t)1 << 26;
    sd.max_vertices = (uint64_t)1 << 26; /* 768 MiB of vertex copies do not fit in 16 MiB */
    if (sizeof(size_t) < 8u) /* nor in a 32-bit address space with the tree's bytes */
        EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "can address");
    else
        EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_OUT_OF_MEMORY, "arena");
    assert_ptr_equal(s, (rc_scene *)0x1);
    /* capacities whose bytes wrap a 32-bit size_t (12 bytes a copied vertex:
     * 2^32 + 8) are refused there, not sized as a few bytes; a 64-bit build
     * sizes them whole */
    sd.max_triangles = 10;
    sd.max_vertices = 0x15555556u;
#if SIZE_MAX <= 0xFFFFFFFFu
    EXPECT_FAIL(f, rc_scene_memory_requirements(f->ctx, &sd, &bytes), RC_ERR_INVALID_ARGUMENT, "can address");
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_INVALID_ARGUMENT, "max_vertices");
#else
    assert_int_equal(rc_scene_memory_requirements(f->ctx, &sd, &bytes), RC_OK);
    assert_true((uint64_t)bytes >= (uint64_t)0x15555556u * 12u);
    EXPECT_FAIL(f, rc_scene_create(f->ctx, &sd, &s), RC_ERR_OUT_OF_MEMORY, "arena");
#endif
    assert_ptr_equal(s, (rc_scene *)0x1);
}

static void test_instance_bad_input(void **state)
{
    fixture *f = (fixture *)*state;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rc_scene *top = NULL, *top2 = NULL;
    uint32_t inst = 9;
    rc_pose p = rc_pose_identity();
    float bad_scale[3] = {1.0f, 0.0f, 1.0f};
    sd.max_instances = 1;
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &top));
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &top2));
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_HANDLE, "source");
    id.source = top;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "itself");
    id.source = top2;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_UNSUPPORTED, "one level");
    id.source = f->scene;
    id.scale[1] = 0.0f;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "scale[1]");
    id.scale[1] = NAN;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_NON_FINITE, "scale[1]");
    id.scale[1] = 1.0f;
    id.transform.orientation[3] = 2.0f;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "quaternion");
    id.transform = rc_pose_identity();
    RCT_OK(f->ctx, rc_scene_add_instance(top, &id, &inst));
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_CAPACITY, "max_instances");
    EXPECT_FAIL(f, rc_scene_set_instance_transform(top, 3, &p, NULL), RC_ERR_OUT_OF_RANGE, "inst_id");
    EXPECT_FAIL(f, rc_scene_set_instance_transform(top, 0, &p, bad_scale), RC_ERR_INVALID_ARGUMENT, "scale[1]");
    RCT_OK(f->ctx, rc_scene_commit(top));
    RCT_OK(f->ctx, rc_scene_destroy(top));
    RCT_OK(f->ctx, rc_scene_destroy(top2));
}

/* Positions a million kilometres out and scales of 1e-7 or 1e7 are refused
 * with a message, on every path that places a ray (Embree aborted the process
 * on such rays: tests/test_fuzz_api.c found it); the bounds themselves pass. */
static void test_reach_bounds(void **state)
{
    fixture *f = (fixture *)*state;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    rc_scene *s = NULL, *top = NULL;
    rc_sensor *ondn = NULL;
    rc_pose far = rct_pose(0.0f, 2.0e9f, 0.0f), near = rct_pose(0.0f, 0.0f, 0.0f);
    rc_pose_d far_d = {{1.5e9, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}};
    rc_results r = f->buf.res;
    float verts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 2.0e9f};
    const float dir[3] = {1.0f, 0.0f, 0.0f}, org_far[3] = {0.0f, 0.0f, -2.0e9f};
    float edge[3] = {1.0e-6f, 1.0e6f, -1.0e6f}, tiny[3] = {1.0f, 1.0e-7f, 1.0f}, huge[3] = {1.0f, 1.0f, -1.0e7f};
    uint32_t tri[3] = {0, 1, 2}, g = 0, inst = 0;
    sd.max_triangles = 1;
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &s));
    md.vertices = verts;
    md.vertex_count = 3;
    md.indices = tri;
    md.triangle_count = 1;
    EXPECT_FAIL(f, rc_scene_add_mesh(s, &md, &g), RC_ERR_INVALID_ARGUMENT, "vertices[2]");
    verts[8] = 1.0e9f;
    RCT_OK(f->ctx, rc_scene_add_mesh(s, &md, &g));
    RCT_OK(f->ctx, rc_scene_commit(s));
    verts[8] = -3.0e9f; /* a referenced mesh changed in place */
    EXPECT_FAIL(f, rc_scene_update_mesh(s, 0), RC_ERR_INVALID_ARGUMENT, "vertex 2 of geometry 0");
    verts[8] = 0.0f;

    sd = rc_scene_desc_default();
    sd.max_instances = 1;
    RCT_OK(f->ctx, rc_scene_create(f->ctx, &sd, &top));
    id.source = f->scene;
    id.transform = far;
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "transform.position");
    id.transform = near;
    memcpy(id.scale, tiny, sizeof tiny);
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "scale[1]");
    memcpy(id.scale, huge, sizeof huge);
    EXPECT_FAIL(f, rc_scene_add_instance(top, &id, &inst), RC_ERR_INVALID_ARGUMENT, "scale[2]");
    memcpy(id.scale, edge, sizeof edge);
    RCT_OK(f->ctx, rc_scene_add_instance(top, &id, &inst));
    EXPECT_FAIL(f, rc_scene_set_instance_transform(top, 0, &near, tiny), RC_ERR_INVALID_ARGUMENT, "scale[1]");
    EXPECT_FAIL(f, rc_scene_set_instance_transform(top, 0, &far, NULL), RC_ERR_INVALID_ARGUMENT, "position");
    RCT_OK(f->ctx, rc_scene_commit(top));

    rd.common.range_min = 0.1f;
    rd.common.range_max = 10.0f;
    rd.directions = dir;
    rd.origins = org_far;
    rd.ray_count = 1;
    EXPECT_FAIL(f, rc_sensor_create_rays(f->ctx, RC_SENSOR_ONDN, &rd, &ondn), RC_ERR_INVALID_ARGUMENT, "origins[0]");
    assert_null(ondn);

    /* poses: the sensor (mounting included) within 1e9 m of the scene origin */
    EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, &far, 1, &r), RC_ERR_INVALID_ARGUMENT, "poses[0]");
    EXPECT_FAIL(f, rc_simulate_d(f->ctx, f->scene, f->sensor, &far_d, 1, &r), RC_ERR_INVALID_ARGUMENT, "poses[0]");
    {
        rc_pose mount = rct_pose(0.0f, 0.0f, 9.9e8f);
        rc_pose up = rct_pose(0.0f, 0.0f, 2.0e7f);
        RCT_OK(f->ctx, rc_sensor_set_mounting(f->sensor, &mount));
        EXPECT_FAIL(f, rc_simulate(f->ctx, f->scene, f->sensor, &up, 1, &r), RC_ERR_INVALID_ARGUMENT,
                    "mounting included");
        mount = rc_pose_identity();
        RCT_OK(f->ctx, rc_sensor_set_mounting(f->sensor, &mount));
    }
    RCT_OK(f->ctx, rc_scene_destroy(top));
    RCT_OK(f->ctx, rc_scene_destroy(s));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_simulate_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(test_mesh_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(test_scene_desc_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(test_instance_bad_input, setup, teardown),
        cmocka_unit_test_setup_teardown(test_reach_bounds, setup, teardown),
    };
    return cmocka_run_group_tests_name("bad input", tests, NULL, NULL);
}
