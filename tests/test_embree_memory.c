/* The Embree backend's memory and errors: the memory monitor behind
 * rc_memory_stats.backend_bytes, zero-copy sharing of mesh arrays, the budget
 * (public, rc_context_desc.backend_budget_mib, and internal, to the byte):
 * RC_ERR_OUT_OF_MEMORY, a scene that stays uncommitted and commits once the
 * budget allows; the exact arena figures, Embree errors turned into status
 * codes with Embree's message, and a dynamic map's commit after moving
 * instances rebuilding the instances' level only (the map's tree kept). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#include "backend/embree_internal.h"

/* RTCError values (the same in Embree 3 and 4); the test needs no Embree header. */
#define RTC_ERR_INVALID_OPERATION 3
#define RTC_ERR_OUT_OF_MEMORY 4
#define RTC_ERR_UNSUPPORTED_CPU 5

#define NEED_EMBREE()                                       \
    do {                                                    \
        if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip(); \
    } while (0)

static uint64_t backend_bytes(rc_context *ctx)
{
    rc_memory_stats s = rc_memory_stats_default();
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &s));
    return s.backend_bytes;
}

/* Commits m into a fresh one-mesh scene as flags / stride say; returns the
 * backend bytes held after the commit. */
static uint64_t committed_bytes(const rcu_mesh *m, uint32_t flags, const float *vertices, uint32_t stride)
{
    rc_context *ctx = rct_context(RC_BACKEND_EMBREE, 1, 0);
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_scene *scene;
    uint32_t g;
    uint64_t bytes;
    assert_int_equal(backend_bytes(ctx), 0);
    sd.max_triangles = m->triangle_count;
    if (flags == RC_MESH_COPY) {
        sd.max_vertices = m->vertex_count;
        sd.max_copied_triangles = m->triangle_count;
    }
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.flags = flags;
    md.vertices = vertices;
    md.vertex_stride = stride;
    md.vertex_count = m->vertex_count;
    md.indices = m->indices;
    md.triangle_count = m->triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    RCT_OK(ctx, rc_scene_commit(scene));
    bytes = backend_bytes(ctx);
    assert_true(rc__embree_options_of(ctx)->bytes_peak >= bytes);
    RCT_OK(ctx, rc_scene_destroy(scene));
    assert_int_equal(backend_bytes(ctx), 0); /* every byte Embree took came back */
    rc_context_destroy(ctx);
    return bytes;
}

/* backend_bytes follows Embree's allocations; the mesh arrays are shared
 * (not copied) except packed xyz referenced in place, which Embree's 16-byte
 * vertex loads cannot read safely: that one copy is 12 bytes a vertex. */
static void test_monitor_and_sharing(void **state)
{
    rcu_mesh m;
    float *v16;
    uint64_t referenced, copied, strided;
    uint32_t i;
    (void)state;
    NEED_EMBREE();
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &m), 0);
    v16 = (float *)malloc(sizeof(float) * 4u * m.vertex_count);
    assert_non_null(v16);
    for (i = 0; i < m.vertex_count; ++i) {
        memcpy(v16 + 4u * i, m.vertices + 3u * i, 3 * sizeof(float));
        v16[4u * i + 3u] = 0.0f;
    }
    referenced = committed_bytes(&m, RC_MESH_REFERENCE, m.vertices, 0);
    copied = committed_bytes(&m, RC_MESH_COPY, m.vertices, 0);
    strided = committed_bytes(&m, RC_MESH_REFERENCE, v16, 16);
    print_message("Embree bytes for %u triangles: referenced xyz %llu, RC_MESH_COPY %llu, stride 16 %llu\n",
                  (unsigned)m.triangle_count, (unsigned long long)referenced, (unsigned long long)copied,
                  (unsigned long long)strided);
    /* the BVH alone: more than a few bytes a triangle */
    assert_true(copied > 8u * (uint64_t)m.triangle_count);
    assert_int_equal(copied, strided);
    assert_true(referenced >= copied + 12u * (uint64_t)m.vertex_count);
    assert_true(referenced <= copied + 12u * (uint64_t)m.vertex_count + 64u);
    free(v16);
    rcu_mesh_free(&m);
}

/* The budget: too small fails the commit with RC_ERR_OUT_OF_MEMORY and a
 * message naming it, the scene stays uncommitted; with room it commits and
 * traces. For this mesh (600 KB of copied vertices, a 2 MB duplicate-triangle
 * table, ~10 MB of build) the budgets fail at the vertex copy, at the table
 * and in Embree's build, and all come back cleanly. With RC_BUILD_FAST Embree
 * builds in two levels, and so does any scene once a mesh was updated: a
 * commit after a refused two-level build crashed inside Embree 3.13 until
 * the meshes were attached afresh (embree_scene.c). */
static void budget_case(uint32_t quality)
{
    static const uint64_t budgets[] = {64u << 10, 1200u << 10, 4u << 20};
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *sensor;
    rc_scene_info info = rc_scene_info_default();
    rc__embree_options *opt;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t i, g, round;
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &m), 0);
    ctx = rct_context(RC_BACKEND_EMBREE, 2, 0);
    opt = rc__embree_options_of(ctx);
    assert_non_null(opt);
    assert_int_equal(opt->budget_bytes, 0); /* no budget unless asked */
    sd.max_triangles = m.triangle_count;
    sd.build_quality = quality;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = m.vertices;
    md.vertex_count = m.vertex_count;
    md.indices = m.indices;
    md.triangle_count = m.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rct_buffers_alloc(&buf, 16u * 360u, RC_ATTR_HITS | RC_ATTR_RANGES);
    for (round = 0; round < 2; ++round) {
        /* round 1: the mesh updated, so the first two-level build of a
         * balanced scene (a fast one refits) */
        if (round == 1) RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        for (i = 0; i < sizeof budgets / sizeof budgets[0]; ++i) {
            rc_status st;
            opt->budget_bytes = round == 0 ? budgets[i] : backend_bytes(ctx) + budgets[i] / 2u;
            st = rc_scene_commit(scene);
            if (round == 1 && quality == RC_BUILD_FAST && i > 0 && st == RC_OK) continue; /* refitted */
            if (st != RC_ERR_OUT_OF_MEMORY)
                fail_msg("budget %llu: commit gave %s (%s)", (unsigned long long)opt->budget_bytes,
                         rc_status_string(st), rc_context_last_error(ctx));
            if (!strstr(rc_context_last_error(ctx), "budget"))
                fail_msg("budget %llu: message does not name the budget: %s", (unsigned long long)opt->budget_bytes,
                         rc_context_last_error(ctx));
            print_message("quality %u, round %u, budget %llu: %s\n", (unsigned)quality, (unsigned)round,
                          (unsigned long long)opt->budget_bytes, rc_context_last_error(ctx));
            assert_true(backend_bytes(ctx) <= opt->budget_bytes);
            RCT_OK(ctx, rc_scene_get_info(scene, &info));
            assert_int_equal(info.committed, 0);
            assert_int_equal(rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res), RC_ERR_NOT_COMMITTED);
        }
        opt->budget_bytes = 0;
        RCT_OK(ctx, rc_scene_commit(scene));
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < 16u * 360u; ++i) {
            assert_int_equal(buf.res.hits[i], 1);
            assert_true(buf.res.ranges[i] > 19.9f && buf.res.ranges[i] <= 20.0f);
        }
    }
    /* a budget above what is held lets a later commit through */
    opt->budget_bytes = backend_bytes(ctx) * 4u;
    RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
    RCT_OK(ctx, rc_scene_commit(scene));
    RCT_OK(ctx, rc_scene_destroy(scene));
    assert_int_equal(backend_bytes(ctx), 0);
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
    rc_context_destroy(ctx);
}

static void test_budget(void **state)
{
    (void)state;
    NEED_EMBREE();
    budget_case(RC_BUILD_BALANCED);
    budget_case(RC_BUILD_FAST);
}

/* The public budget, rc_context_desc.backend_budget_mib: 1 MiB cannot hold
 * what Embree and the backend's tables need for the 100k-triangle sphere
 * (about 7 MB; the first allocation past 1 MiB is refused); 64 MiB can. */
static void test_public_budget(void **state)
{
    (void)state;
    NEED_EMBREE();
    rct_check_budget(RC_BACKEND_EMBREE, RC_PRESET_VELODYNE_VLP16_360, 16u * 360u);
}

/* rc_scene_memory_requirements is exact on Embree too (the arena holds only
 * the backend's small tables; Embree's memory is outside it): the queried
 * block works, one byte less fails cleanly with RC_ERR_OUT_OF_MEMORY. */
static void test_arena_exact(void **state)
{
    rcu_mesh m;
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 2, 3};
    size_t need_ctx, need_scene, extra;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    (void)state;
    NEED_EMBREE();
    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    sd.max_geometries = 2;
    sd.max_instances = 3;
    sd.max_triangles = 12;
    md.vertices = m.vertices;
    md.vertex_count = m.vertex_count;
    md.indices = m.indices;
    md.triangle_count = m.triangle_count;
    for (extra = 0; extra < 2; ++extra) {
        rc_context_desc cd = rc_context_desc_default();
        rc_context *ctx = NULL;
        rc_scene *scene;
        void *block;
        size_t size;
        uint32_t g;
        rc_status st;
        cd.backend = RC_BACKEND_EMBREE;
        cd.thread_count = 1;
        assert_int_equal(rc_context_memory_requirements(&cd, &need_ctx), RC_OK);
        /* the scene query needs a context of the backend: ask a throwaway one */
        {
            rc_context *q = rct_context(RC_BACKEND_EMBREE, 1, 1);
            RCT_OK(q, rc_scene_memory_requirements(q, &sd, &need_scene));
            rc_context_destroy(q);
        }
        size = need_ctx + need_scene - (extra ? 0u : 1u);
        block = rct_alloc16(size);
        cd.memory = block;
        cd.memory_size = size;
        RCT_OK(NULL, rc_context_create(&cd, &ctx));
        RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
        st = rc_scene_commit(scene);
        if (extra) {
            RCT_OK(ctx, st);
        } else {
            assert_int_equal(st, RC_ERR_OUT_OF_MEMORY);
            assert_non_null(strstr(rc_context_last_error(ctx), "arena"));
        }
        rc_context_destroy(ctx);
        free(block);
    }
    rcu_mesh_free(&m);
}

/* Embree's errors become status codes with Embree's message: a device that
 * cannot be made, and errors arriving through the error callback (mapped by
 * code: out of memory, unsupported CPU, anything else is RC_ERR_BACKEND). */
static void test_error_mapping(void **state)
{
    static const struct {
        int code;
        rc_status status;
        const char *name;
    } cases[] = {
        {RTC_ERR_INVALID_OPERATION, RC_ERR_BACKEND, "RTC_ERROR_INVALID_OPERATION"},
        {RTC_ERR_OUT_OF_MEMORY, RC_ERR_OUT_OF_MEMORY, "RTC_ERROR_OUT_OF_MEMORY"},
        {RTC_ERR_UNSUPPORTED_CPU, RC_ERR_UNSUPPORTED, "RTC_ERROR_UNSUPPORTED_CPU"},
        {1, RC_ERR_BACKEND, "RTC_ERROR_UNKNOWN"},
    };
    rcu_mesh m;
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 2, 3};
    rc_context *ctx, *bvh;
    rc_scene *scene;
    rc_status st;
    uint32_t i;
    (void)state;
    NEED_EMBREE();
    ctx = rct_context(RC_BACKEND_EMBREE, 2, 0);
    bvh = rct_context(RC_BACKEND_BVH, 1, 1);
    assert_int_equal(rc__embree_probe_device(bvh, "threads=1"), RC_ERR_INVALID_ARGUMENT);
    RCT_OK(ctx, rc__embree_probe_device(ctx, "threads=1"));

    /* a configuration Embree rejects: rtcNewDevice fails */
    st = rc__embree_probe_device(ctx, "threads=not-a-number,frobnicate=1");
    assert_int_equal(st, RC_ERR_BACKEND);
    assert_non_null(strstr(rc_context_last_error(ctx), "rtcNewDevice"));
    assert_non_null(strstr(rc_context_last_error(ctx), "Embree"));
    print_message("device failure: %s\n", rc_context_last_error(ctx));

    assert_int_equal(rcu_mesh_box(lo, hi, &m), 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        rc__embree_record_error(ctx, cases[i].code, "injected by the test");
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        st = rc_scene_commit(scene);
        if (st != cases[i].status)
            fail_msg("code %d: %s, expected %s", cases[i].code, rc_status_string(st),
                     rc_status_string(cases[i].status));
        assert_non_null(strstr(rc_context_last_error(ctx), "injected by the test"));
        assert_non_null(strstr(rc_context_last_error(ctx), cases[i].name));
        /* reported once: the next commit goes through */
        RCT_OK(ctx, rc_scene_commit(scene));
    }
    rc_context_destroy(bvh);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* Adds m to scene as a referenced mesh over vertices (m's own, or a moved
 * copy); returns its geometry id. */
static uint32_t add_mesh(rc_context *ctx, rc_scene *scene, const rcu_mesh *m, const float *vertices)
{
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t id;
    md.vertices = vertices;
    md.vertex_count = m->vertex_count;
    md.indices = m->indices;
    md.triangle_count = m->triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &id));
    return id;
}

/* The dynamic-map tests' map (a 100k-triangle sphere of radius 20 m) and
 * moving object (a unit box at the origin). */
static void map_and_box(rcu_mesh *sphere, rcu_mesh *box)
{
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000u, sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, box), 0);
}

/* Asserts that out[0] (Embree) and out[1] (built-in) hold the same n rays:
 * hit flags, ranges within 1e-5 relative and the ids in ids0/ids1. Returns
 * how many hits have an id other than `other`. */
static uint32_t same_scans(const rct_buffers out[2], uint32_t n, const uint32_t *ids0, const uint32_t *ids1,
                           uint32_t other)
{
    uint32_t k, count = 0;
    for (k = 0; k < n; ++k) {
        assert_int_equal(out[0].res.hits[k], out[1].res.hits[k]);
        if (!out[0].res.hits[k]) continue;
        assert_true(fabsf(out[0].res.ranges[k] - out[1].res.ranges[k]) <= 1e-5f * out[1].res.ranges[k]);
        assert_int_equal(ids0[k], ids1[k]);
        count += ids0[k] != other;
    }
    return count;
}

/* A dynamic map: a 100k-triangle sphere with three instanced boxes. Moving
 * the boxes and committing must not rebuild Embree's tree over the sphere
 * (its meshes sit in their own Embree scene, embree_impl.h): what Embree
 * allocates for that commit is a small fraction of what a rebuild of the
 * sphere (after rc_scene_update_mesh) allocates. The scans after each commit
 * match the built-in backend's. */
static void test_moving_instances_keeps_the_map(void **state)
{
    rcu_mesh sphere, box;
    rc_context *ctx[2];
    rc_scene *src[2], *world[2];
    rc_sensor *lidar[2];
    rct_buffers out[2];
    uint64_t before, moved, rebuilt;
    uint32_t b, i, id, n = 16u * 900u;
    (void)state;
    NEED_EMBREE();
    map_and_box(&sphere, &box);
    for (b = 0; b < 2; ++b) {
        rc_scene_desc sd = rc_scene_desc_default();
        ctx[b] = rct_context(b == 0 ? RC_BACKEND_EMBREE : RC_BACKEND_BVH, 2, 0);
        src[b] = rct_scene_mesh(ctx[b], &box, RC_MESH_REFERENCE);
        sd.max_geometries = 1;
        sd.max_instances = 3;
        sd.max_triangles = sphere.triangle_count;
        RCT_OK(ctx[b], rc_scene_create(ctx[b], &sd, &world[b]));
        (void)add_mesh(ctx[b], world[b], &sphere, sphere.vertices);
        for (i = 0; i < 3; ++i) {
            rc_instance_desc in = rc_instance_desc_default();
            in.source = src[b];
            in.transform = rct_pose(3.0f * (float)i - 3.0f, 2.0f, 0.0f);
            RCT_OK(ctx[b], rc_scene_add_instance(world[b], &in, &id));
        }
        RCT_OK(ctx[b], rc_scene_commit(world[b]));
        RCT_OK(ctx[b], rc_sensor_create_preset(ctx[b], RC_PRESET_VELODYNE_VLP16, &lidar[b]));
        rct_buffers_alloc(&out[b], n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_INST_IDS);
    }
    before = rc__embree_options_of(ctx[0])->bytes_allocated;
    for (b = 0; b < 2; ++b) {
        const rc_pose pose = rct_pose_ypr(0.5f, -0.5f, 0.2f, 0.3, 0.0, 0.0);
        for (i = 0; i < 3; ++i) {
            const rc_pose p = rct_pose_ypr(3.0f * (float)i - 2.0f, 1.0f, 0.3f, 0.5 + i, 0.1, 0.0);
            RCT_OK(ctx[b], rc_scene_set_instance_transform(world[b], i, &p, NULL));
        }
        RCT_OK(ctx[b], rc_scene_commit(world[b]));
        RCT_OK(ctx[b], rc_simulate(ctx[b], world[b], lidar[b], &pose, 1, &out[b].res));
    }
    moved = rc__embree_options_of(ctx[0])->bytes_allocated - before;
    /* the moved boxes are in view */
    assert_true(same_scans(out, n, out[0].res.inst_ids, out[1].res.inst_ids, RC_INVALID_ID) > 50u);
    /* the sphere's vertices updated: its tree is rebuilt */
    before = rc__embree_options_of(ctx[0])->bytes_allocated;
    RCT_OK(ctx[0], rc_scene_update_mesh(world[0], 0));
    RCT_OK(ctx[0], rc_scene_commit(world[0]));
    rebuilt = rc__embree_options_of(ctx[0])->bytes_allocated - before;
    print_message("Embree allocated %llu bytes for a commit after moving instances, %llu after updating the map\n",
                  (unsigned long long)moved, (unsigned long long)rebuilt);
    assert_true(rebuilt > 1000000u);
    assert_true(moved * 20u < rebuilt);
    for (b = 0; b < 2; ++b) {
        rct_buffers_free(&out[b]);
        rc_context_destroy(ctx[b]);
    }
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
}

/* A map and a mesh that changes (a door, a deformable object) in one scene:
 * after the first update the scene's meshes stand in Embree's two-level
 * build, so updating the small mesh refits it and rebuilds the level over the
 * meshes only; the sphere's tree is kept. Each commit's allocations are a
 * small fraction of the first (whole) rebuild's, and the scans match the
 * built-in backend's after every move. */
static void test_updating_a_small_mesh_keeps_the_map(void **state)
{
    rcu_mesh sphere, box;
    rc_context *ctx[2];
    rc_scene *world[2];
    rc_sensor *lidar[2];
    rct_buffers out[2];
    float *moving[2];
    uint64_t before, first = 0, later = 0;
    uint32_t b, i, step, seen = 0, n = 16u * 900u;
    (void)state;
    NEED_EMBREE();
    map_and_box(&sphere, &box);
    for (b = 0; b < 2; ++b) {
        rc_scene_desc sd = rc_scene_desc_default();
        ctx[b] = rct_context(b == 0 ? RC_BACKEND_EMBREE : RC_BACKEND_BVH, 2, 0);
        moving[b] = (float *)malloc(sizeof(float) * 3u * box.vertex_count);
        assert_non_null(moving[b]);
        memcpy(moving[b], box.vertices, sizeof(float) * 3u * box.vertex_count);
        sd.max_geometries = 2;
        sd.max_triangles = sphere.triangle_count + box.triangle_count;
        RCT_OK(ctx[b], rc_scene_create(ctx[b], &sd, &world[b]));
        assert_int_equal(add_mesh(ctx[b], world[b], &sphere, sphere.vertices), 0);
        assert_int_equal(add_mesh(ctx[b], world[b], &box, moving[b]), 1);
        RCT_OK(ctx[b], rc_scene_commit(world[b]));
        RCT_OK(ctx[b], rc_sensor_create_preset(ctx[b], RC_PRESET_VELODYNE_VLP16, &lidar[b]));
        rct_buffers_alloc(&out[b], n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_GEOM_IDS);
    }
    for (step = 0; step < 3; ++step) {
        const rc_pose pose = rct_pose_ypr(0.5f, -0.5f, 0.2f, 0.3, 0.0, 0.0);
        for (b = 0; b < 2; ++b) {
            /* the box moves and stretches along x */
            for (i = 0; i < box.vertex_count; ++i) {
                moving[b][3u * i] = box.vertices[3u * i] * (1.0f + 0.5f * (float)step) + 2.0f + (float)step;
                moving[b][3u * i + 1u] = box.vertices[3u * i + 1u] + 1.0f;
            }
            before = rc__embree_options_of(ctx[0])->bytes_allocated;
            RCT_OK(ctx[b], rc_scene_update_mesh(world[b], 1));
            RCT_OK(ctx[b], rc_scene_commit(world[b]));
            if (b == 0) {
                const uint64_t bytes = rc__embree_options_of(ctx[0])->bytes_allocated - before;
                if (step == 0)
                    first = bytes;
                else
                    later = bytes > later ? bytes : later;
            }
            RCT_OK(ctx[b], rc_simulate(ctx[b], world[b], lidar[b], &pose, 1, &out[b].res));
        }
        seen += same_scans(out, n, out[0].res.geom_ids, out[1].res.geom_ids, 0u);
    }
    print_message("Embree allocated %llu bytes for the first commit after an update, at most %llu for later ones\n",
                  (unsigned long long)first, (unsigned long long)later);
    assert_true(seen > 30u); /* the box is in view */
    assert_true(first > 1000000u);
    assert_true(later * 20u < first);
    for (b = 0; b < 2; ++b) {
        rct_buffers_free(&out[b]);
        rc_context_destroy(ctx[b]);
        free(moving[b]);
    }
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_monitor_and_sharing),
        cmocka_unit_test(test_budget),
        cmocka_unit_test(test_public_budget),
        cmocka_unit_test(test_arena_exact),
        cmocka_unit_test(test_error_mapping),
        cmocka_unit_test(test_moving_instances_keeps_the_map),
        cmocka_unit_test(test_updating_a_small_mesh_keeps_the_map),
    };
    return cmocka_run_group_tests_name("embree memory and errors", tests, NULL, NULL);
}
