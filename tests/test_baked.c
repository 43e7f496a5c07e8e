/* Baked maps (rc_scene_bake, rc_scene_load_baked): a loaded map gives the
 * baked scene's results bit for bit on the built-in backend and the same hits
 * on Embree and Vulkan; the blob is the same bytes on every bake; the arena
 * size query is exact; the loaded scene is read-only and can be instanced;
 * and every kind of bad blob is refused with its own status and message,
 * never a crash: crafted defects one by one, then random bit flips with the
 * checksum check off (so the structure checks alone stand between the flips
 * and traversal; run under ASan in CI); and a blob baked once and kept in
 * tests/data reads the same on every target. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"
#include "bvh/wide.h"
#include "scene/baked_format.h"

#define POSES 3u

typedef struct baked_map {
    rcu_mesh room, box;
    void *blob;
    size_t bytes;
} baked_map;

/* Two meshes (a referenced warehouse and a copied box inside it), committed
 * on ctx (built-in backend) with origin as the scene's origin. */
static rc_scene *two_mesh_scene(rc_context *ctx, baked_map *m, const double origin[3])
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_scene *scene = NULL;
    uint32_t geom;
    sd.max_geometries = 2;
    sd.max_triangles = (uint64_t)m->room.triangle_count + m->box.triangle_count;
    sd.max_vertices = m->box.vertex_count;
    sd.max_copied_triangles = m->box.triangle_count;
    if (origin) memcpy(sd.origin, origin, sizeof sd.origin);
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = m->room.vertices;
    md.vertex_count = m->room.vertex_count;
    md.indices = m->room.indices;
    md.triangle_count = m->room.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &geom));
    md.flags = RC_MESH_COPY;
    md.vertices = m->box.vertices;
    md.vertex_count = m->box.vertex_count;
    md.indices = m->box.indices;
    md.triangle_count = m->box.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &geom));
    RCT_OK(ctx, rc_scene_commit(scene));
    return scene;
}

static void make_meshes(baked_map *m)
{
    const float lo[3] = {2.0f, -1.0f, 0.0f}, hi[3] = {3.0f, 1.5f, 2.5f};
    memset(m, 0, sizeof *m);
    assert_int_equal(rcu_mesh_demo_map(&m->room), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &m->box), 0);
}

/* Bakes scene into a fresh 16-aligned block. */
static void bake(rc_context *ctx, const rc_scene *scene, baked_map *m)
{
    size_t need = 0, wrote = 0;
    RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &need));
    assert_true(need > RC__BAKED_HEADER && need % 64u == 0);
    m->blob = rct_alloc16(need);
    RCT_OK(ctx, rc_scene_bake(scene, m->blob, need, &wrote));
    assert_int_equal(wrote, need);
    m->bytes = need;
}

/* A context on the built-in backend with the two-mesh scene, baked into m. */
static rc_context *baked_fixture(baked_map *m, uint32_t threads, rc_scene **scene)
{
    rc_context *ctx = rct_context(RC_BACKEND_BVH, threads, 64);
    make_meshes(m);
    *scene = two_mesh_scene(ctx, m, NULL);
    bake(ctx, *scene, m);
    return ctx;
}

static void free_map(baked_map *m)
{
    free(m->blob);
    rcu_mesh_free(&m->room);
    rcu_mesh_free(&m->box);
}

static void poses_in_room(rc_pose p[POSES])
{
    p[0] = rct_pose_ypr(0.0f, 0.0f, 1.2f, 0.0, 0.0, 0.0);
    p[1] = rct_pose_ypr(-3.0f, 2.0f, 1.0f, 0.7, 0.1, -0.05);
    p[2] = rct_pose_ypr(4.5f, -2.5f, 1.5f, -2.0, -0.2, 0.3);
}

/* All attributes of a VLP-16 at POSES poses. */
static void scan(rc_context *ctx, const rc_scene *scene, rct_buffers *b)
{
    rc_sensor *s = NULL;
    rc_pose p[POSES];
    poses_in_room(p);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
    rct_buffers_alloc(b, (uint64_t)POSES * 16u * 900u, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, scene, s, p, POSES, &b->res));
    RCT_OK(ctx, rc_sensor_destroy(s));
}

static void test_crc32c_check_value(void **state)
{
    unsigned char data[1000];
    uint32_t one_by_one = 0;
    size_t i;
    (void)state;
    assert_int_equal(rc__crc32c(0, "123456789", 9), 0xE3069283u);
    assert_int_equal(rc__crc32c(rc__crc32c(0, "12345", 5), "6789", 4), 0xE3069283u);
    assert_int_equal(rc__crc32c(0, "", 0), 0u);
    /* the 8-byte steps agree with the byte loop */
    for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)(i * 37u + (i >> 3));
    for (i = 0; i < sizeof data; ++i) one_by_one = rc__crc32c(one_by_one, data + i, 1);
    assert_int_equal(rc__crc32c(0, data, sizeof data), one_by_one);
}

/* Loading on the built-in backend: every attribute bit-identical to the
 * scene that was baked, for 1 and 2 threads, in an arena of exactly the
 * queried size (and one 16-byte step less fails cleanly). */
static void test_load_bit_identical(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene;
    rct_buffers want;
    uint32_t threads;
    (void)state;
    make_meshes(&m);
    ctx = rct_context(RC_BACKEND_BVH, 2, 64);
    scene = two_mesh_scene(ctx, &m, NULL);
    bake(ctx, scene, &m);
    scan(ctx, scene, &want);
    rc_context_destroy(ctx);
    for (threads = 1; threads <= 2; ++threads) {
        rc_context_desc cd = rc_context_desc_default();
        size_t ctx_bytes = 0, scene_bytes = 0, sensor_bytes = 0;
        rc_context *c = NULL;
        rc_scene *loaded = NULL;
        rc_scene_info info = rc_scene_info_default();
        rct_buffers got;
        void *arena;
        cd.backend = RC_BACKEND_BVH;
        cd.thread_count = threads;
        RCT_OK(NULL, rc_context_memory_requirements(&cd, &ctx_bytes));
        RCT_OK(NULL, rc_sensor_memory_requirements_preset(RC_PRESET_VELODYNE_VLP16, &sensor_bytes));
        /* the size query needs a context: a first one of a generous size */
        c = rct_context(RC_BACKEND_BVH, threads, 4);
        RCT_OK(c, rc_scene_baked_memory_requirements(c, m.blob, m.bytes, &scene_bytes));
        rc_context_destroy(c);
        /* the arena holds the scene's tables and top level, not the blob */
        assert_true(scene_bytes < m.bytes / 4u);
        arena = rct_alloc16(ctx_bytes + scene_bytes + sensor_bytes);
        cd.memory = arena;
        cd.memory_size = ctx_bytes + scene_bytes - 16u;
        RCT_OK(NULL, rc_context_create(&cd, &c));
        assert_int_equal(rc_scene_load_baked(c, m.blob, m.bytes, 0, &loaded), RC_ERR_OUT_OF_MEMORY);
        assert_null(loaded);
        assert_non_null(strstr(rc_context_last_error(c), "arena"));
        rc_context_destroy(c);
        cd.memory_size = ctx_bytes + scene_bytes + sensor_bytes;
        RCT_OK(NULL, rc_context_create(&cd, &c));
        RCT_OK(c, rc_scene_load_baked(c, m.blob, m.bytes, 0, &loaded));
        RCT_OK(c, rc_scene_get_info(loaded, &info));
        assert_int_equal(info.geometry_count, 2);
        assert_int_equal(info.committed, 1);
        assert_int_equal(info.triangle_count, (uint64_t)m.room.triangle_count + m.box.triangle_count);
        scan(c, loaded, &got);
        rct_assert_same_results(&want, &got);
        rct_buffers_free(&got);
        rc_context_destroy(c);
        free(arena);
    }
    rct_buffers_free(&want);
    free_map(&m);
}

/* The same scene bakes to the same bytes: twice in a row, built on 1 thread
 * or 2, and baked again after loading. */
static void test_bake_is_deterministic(void **state)
{
    baked_map a, b;
    rc_context *c1 = rct_context(RC_BACKEND_BVH, 1, 64), *c2 = rct_context(RC_BACKEND_BVH, 2, 64);
    rc_scene *s1, *s2, *loaded = NULL;
    size_t n = 0;
    void *again;
    (void)state;
    make_meshes(&a);
    make_meshes(&b);
    s1 = two_mesh_scene(c1, &a, NULL);
    s2 = two_mesh_scene(c2, &b, NULL);
    bake(c1, s1, &a);
    bake(c2, s2, &b);
    assert_int_equal(a.bytes, b.bytes);
    assert_memory_equal(a.blob, b.blob, a.bytes);
    RCT_OK(c2, rc_scene_load_baked(c2, a.blob, a.bytes, 0, &loaded));
    again = rct_alloc16(a.bytes);
    RCT_OK(c2, rc_scene_bake(loaded, again, a.bytes, &n));
    assert_int_equal(n, a.bytes);
    assert_memory_equal(again, a.blob, a.bytes);
    free(again);
    rc_context_destroy(c1);
    rc_context_destroy(c2);
    free_map(&a);
    free_map(&b);
}

/* A far origin travels with the map: rc_simulate_d on the loaded scene gives
 * the baked scene's bits. */
static void test_origin_kept(void **state)
{
    const double origin[3] = {512345.25, 5401234.5, 87.0};
    baked_map m;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 2, 64);
    rc_scene *scene, *loaded = NULL;
    rc_sensor *s = NULL;
    rc_pose_d p;
    rct_buffers want, got;
    (void)state;
    make_meshes(&m);
    scene = two_mesh_scene(ctx, &m, origin);
    bake(ctx, scene, &m);
    RCT_OK(ctx, rc_scene_load_baked(ctx, m.blob, m.bytes, 0, &loaded));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
    memset(&p, 0, sizeof p);
    p.position[0] = origin[0] + 1.0;
    p.position[1] = origin[1] - 0.5;
    p.position[2] = origin[2] + 1.2;
    p.orientation[3] = 1.0;
    rct_buffers_alloc(&want, 16u * 900u, RC_ATTR_RANGES | RC_ATTR_GEOM_IDS);
    rct_buffers_alloc(&got, 16u * 900u, RC_ATTR_RANGES | RC_ATTR_GEOM_IDS);
    RCT_OK(ctx, rc_simulate_d(ctx, scene, s, &p, 1, &want.res));
    RCT_OK(ctx, rc_simulate_d(ctx, loaded, s, &p, 1, &got.res));
    assert_memory_equal(want.res.ranges, got.res.ranges, want.n * sizeof(float));
    assert_memory_equal(want.res.geom_ids, got.res.geom_ids, want.n * sizeof(uint32_t));
    assert_true(isfinite(want.res.ranges[0]) && want.res.ranges[0] > 0.5f);
    rct_buffers_free(&want);
    rct_buffers_free(&got);
    rc_context_destroy(ctx);
    free_map(&m);
}

/* Embree and Vulkan build their own structure from the blob's meshes: the
 * same hits and geometry ids as the built-in backend, ranges within 1e-5
 * relative. */
static void test_other_backends(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene;
    rct_buffers want;
    size_t b;
    int ran = 0;
    (void)state;
    ctx = baked_fixture(&m, 2, &scene);
    scan(ctx, scene, &want);
    rc_context_destroy(ctx);
    for (b = 1; b < 3; ++b) {
        rc_context *c;
        rc_scene *loaded = NULL;
        rct_buffers got;
        uint64_t k, mismatched = 0;
        size_t need = 0;
        if (!rct_backend_usable(rct_backends[b])) continue;
        c = rct_context(rct_backends[b], 2, 64);
        RCT_OK(c, rc_scene_baked_memory_requirements(c, m.blob, m.bytes, &need));
        RCT_OK(c, rc_scene_load_baked(c, m.blob, m.bytes, 0, &loaded));
        scan(c, loaded, &got);
        for (k = 0; k < want.n; ++k) {
            const float w = want.res.ranges[k], g = got.res.ranges[k];
            if (want.res.hits[k] != got.res.hits[k] || want.res.geom_ids[k] != got.res.geom_ids[k] ||
                (isfinite(w) && fabsf(w - g) > 1e-5f * fabsf(w)) || (!isfinite(w) && w != g))
                ++mismatched;
        }
        print_message("%s: %llu of %llu rays differ from the built-in backend\n", rc_backend_name(rct_backends[b]),
                      (unsigned long long)mismatched, (unsigned long long)want.n);
        /* rays grazing an edge may go either way on another backend's test */
        assert_true(mismatched <= want.n / 2000u);
        rct_buffers_free(&got);
        rc_context_destroy(c);
        ran = 1;
    }
    rct_buffers_free(&want);
    free_map(&m);
    if (!ran) skip();
}

/* A loaded scene cannot change; it commits (a no-op) and can be instanced:
 * an instance moved by t sees what the map sees from a pose moved by -t. */
static void test_read_only_and_instanced(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene, *loaded = NULL, *world = NULL;
    rc_scene_desc wd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_sensor *s = NULL;
    rc_pose p = rct_pose(0.5f, 0.5f, 1.2f), q = rct_pose(10.5f, 0.5f, 1.2f);
    rct_buffers a, b;
    uint32_t out = 0;
    uint64_t k;
    (void)state;
    ctx = baked_fixture(&m, 2, &scene);
    RCT_OK(ctx, rc_scene_load_baked(ctx, m.blob, m.bytes, 0, &loaded));
    md.vertices = m.box.vertices;
    md.vertex_count = m.box.vertex_count;
    md.indices = m.box.indices;
    md.triangle_count = m.box.triangle_count;
    assert_int_equal(rc_scene_add_mesh(loaded, &md, &out), RC_ERR_MISUSE);
    assert_non_null(strstr(rc_context_last_error(ctx), "read-only"));
    assert_int_equal(rc_scene_update_mesh(loaded, 0), RC_ERR_MISUSE);
    assert_int_equal(rc_scene_add_instance(loaded, &id, &out), RC_ERR_MISUSE);
    assert_int_equal(rc_scene_set_instance_transform(loaded, 0, &p, NULL), RC_ERR_MISUSE);
    RCT_OK(ctx, rc_scene_commit(loaded));

    wd.max_instances = 1;
    RCT_OK(ctx, rc_scene_create(ctx, &wd, &world));
    id.source = loaded;
    id.transform = rct_pose(10.0f, 0.0f, 0.0f);
    RCT_OK(ctx, rc_scene_add_instance(world, &id, &out));
    RCT_OK(ctx, rc_scene_commit(world));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
    rct_buffers_alloc(&a, 16u * 900u, RC_ATTR_RANGES | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
    rct_buffers_alloc(&b, 16u * 900u, RC_ATTR_RANGES | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
    RCT_OK(ctx, rc_simulate(ctx, loaded, s, &p, 1, &a.res));
    RCT_OK(ctx, rc_simulate(ctx, world, s, &q, 1, &b.res));
    for (k = 0; k < a.n; ++k) {
        if (!isfinite(a.res.ranges[k])) {
            assert_true(a.res.ranges[k] == b.res.ranges[k]);
            continue;
        }
        assert_true(fabsf(a.res.ranges[k] - b.res.ranges[k]) <= 1e-4f);
        assert_int_equal(a.res.geom_ids[k], b.res.geom_ids[k]);
        assert_int_equal(b.res.inst_ids[k], 0);
    }
    /* the loaded scene cannot go while the world instances it */
    assert_int_equal(rc_scene_destroy(loaded), RC_ERR_MISUSE);
    RCT_OK(ctx, rc_scene_destroy(world));
    RCT_OK(ctx, rc_scene_destroy(loaded));
    rct_buffers_free(&a);
    rct_buffers_free(&b);
    rc_context_destroy(ctx);
    free_map(&m);
}

/* rc_baked_get_mesh hands out the blob's meshes; a scene built from them on
 * the built-in backend is the baked scene again, bit for bit. */
static void test_get_mesh(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene, *rebuilt = NULL;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rct_buffers want, got;
    uint32_t count = 0, g, geom;
    (void)state;
    ctx = baked_fixture(&m, 2, &scene);
    assert_int_equal(rc_baked_get_mesh(m.blob, m.bytes, 0, NULL, &count), RC_OK);
    assert_int_equal(count, 2);
    assert_int_equal(rc_baked_get_mesh(m.blob, m.bytes, 2, &md, NULL), RC_ERR_OUT_OF_RANGE);
    sd.max_geometries = 2;
    sd.max_triangles = (uint64_t)m.room.triangle_count + m.box.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &rebuilt));
    for (g = 0; g < count; ++g) {
        RCT_OK(ctx, rc_baked_get_mesh(m.blob, m.bytes, g, &md, NULL));
        assert_int_equal(md.vertex_stride, 16);
        assert_int_equal(md.triangle_count, g ? m.box.triangle_count : m.room.triangle_count);
        RCT_OK(ctx, rc_scene_add_mesh(rebuilt, &md, &geom));
    }
    /* the same triangles corner by corner (a copied mesh's vertices are
     * renumbered in leaf order at commit, so compare coordinates) */
    for (g = 0; g < 3u * m.box.triangle_count; ++g)
        assert_memory_equal((const float *)md.vertices + 4u * (size_t)md.indices[g],
                            m.box.vertices + 3u * (size_t)m.box.indices[g], 12);
    RCT_OK(ctx, rc_scene_commit(rebuilt));
    scan(ctx, scene, &want);
    scan(ctx, rebuilt, &got);
    rct_assert_same_results(&want, &got);
    md.struct_size = 8;
    assert_int_equal(rc_baked_get_mesh(m.blob, m.bytes, 0, &md, NULL), RC_ERR_STRUCT_SIZE);
    rct_buffers_free(&want);
    rct_buffers_free(&got);
    rc_context_destroy(ctx);
    free_map(&m);
}

/* What rc_scene_bake refuses: uncommitted, instances, another backend, no
 * room (nothing written), NULL bytes. */
static void test_bake_refusals(void **state)
{
    baked_map m;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 64);
    rc_scene *scene, *world = NULL;
    rc_scene_desc wd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    unsigned char *small;
    size_t need = 0, n = 0, i;
    uint32_t inst;
    (void)state;
    make_meshes(&m);
    scene = two_mesh_scene(ctx, &m, NULL);
    RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &need));
    small = (unsigned char *)rct_alloc16(need);
    memset(small, 0xA5, need);
    assert_int_equal(rc_scene_bake(scene, small, need - 1u, &n), RC_ERR_CAPACITY);
    assert_non_null(strstr(rc_context_last_error(ctx), "capacity"));
    for (i = 0; i < need; ++i) assert_int_equal(small[i], 0xA5);
    assert_int_equal(rc_scene_bake(scene, small, need, NULL), RC_ERR_INVALID_ARGUMENT);
    RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
    assert_int_equal(rc_scene_bake(scene, small, need, &n), RC_ERR_NOT_COMMITTED);
    RCT_OK(ctx, rc_scene_commit(scene));
    wd.max_instances = 1;
    RCT_OK(ctx, rc_scene_create(ctx, &wd, &world));
    id.source = scene;
    RCT_OK(ctx, rc_scene_add_instance(world, &id, &inst));
    RCT_OK(ctx, rc_scene_commit(world));
    assert_int_equal(rc_scene_bake(world, small, need, &n), RC_ERR_UNSUPPORTED);
    assert_non_null(strstr(rc_context_last_error(ctx), "instance"));
    assert_int_equal(rc_scene_bake(NULL, small, need, &n), RC_ERR_INVALID_HANDLE);
    rc_context_destroy(ctx);
    if (rct_backend_usable(RC_BACKEND_EMBREE)) {
        rc_context *e = rct_context(RC_BACKEND_EMBREE, 1, 64);
        rc_scene *es = two_mesh_scene(e, &m, NULL);
        assert_int_equal(rc_scene_bake(es, small, need, &n), RC_ERR_UNSUPPORTED);
        assert_non_null(strstr(rc_context_last_error(e), "RC_BACKEND_BVH"));
        rc_context_destroy(e);
    }
    free(small);
    free_map(&m);
}

/* A copy of the blob with one change, its checksum made right again. */
static unsigned char *edited(const baked_map *m)
{
    unsigned char *b = (unsigned char *)rct_alloc16(m->bytes + 16u);
    memcpy(b, m->blob, m->bytes);
    return b;
}

static void reseal(unsigned char *b, size_t bytes) { rc__bk_put32(b, RC__BK_CHECKSUM, rc__baked_checksum(b, bytes)); }

static void expect_refused(rc_context *ctx, const unsigned char *b, size_t bytes, uint32_t flags, rc_status want,
                           const char *words, const char *what)
{
    rc_scene *s = NULL;
    rc_memory_stats before = rc_memory_stats_default(), after = rc_memory_stats_default();
    rc_status st;
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &before));
    st = rc_scene_load_baked(ctx, b, bytes, flags, &s);
    if (st != want || s != NULL || !strstr(rc_context_last_error(ctx), words))
        fail_msg("%s: got %s (%s), want %s with \"%s\"", what, rc_status_string(st), rc_context_last_error(ctx),
                 rc_status_string(want), words);
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &after));
    assert_int_equal(before.arena_used, after.arena_used);
}

/* First record's field of the first geometry. */
static uint64_t rec64(const unsigned char *b, size_t off) { return rc__bk_u64(b + RC__BAKED_HEADER, off); }

static void test_bad_blobs(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene, *s = NULL;
    unsigned char *b;
    uint64_t nodes, lt, verts;
    rc__wnode node;
    (void)state;
    ctx = baked_fixture(&m, 1, &scene);
    nodes = rec64((const unsigned char *)m.blob, RC__BR_OFF_NODES);
    lt = rec64((const unsigned char *)m.blob, RC__BR_OFF_LEAF_TRIS);
    verts = rec64((const unsigned char *)m.blob, RC__BR_OFF_VERTICES);

    assert_int_equal(rc_scene_load_baked(ctx, NULL, m.bytes, 0, &s), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_scene_load_baked(ctx, m.blob, m.bytes, 0, NULL), RC_ERR_INVALID_ARGUMENT);
    assert_int_equal(rc_scene_load_baked(ctx, m.blob, m.bytes, 0x2u, &s), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "RC_BAKED_SKIP_CHECKSUM"));
    assert_int_equal(rc_scene_load_baked(NULL, m.blob, m.bytes, 0, &s), RC_ERR_INVALID_HANDLE);

    b = edited(&m);
    memmove(b + 8, b, m.bytes); /* 8-byte aligned only */
    assert_int_equal(rc_scene_load_baked(ctx, b + 8, m.bytes, 0, &s), RC_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rc_context_last_error(ctx), "16-byte"));
    free(b);

    b = edited(&m);
    expect_refused(ctx, b, m.bytes - 64u, 0, RC_ERR_CORRUPT_DATA, "truncated", "64 bytes short");
    expect_refused(ctx, b, 100u, 0, RC_ERR_CORRUPT_DATA, "at least 128", "shorter than a header");
    b[1] = 'X';
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "not a baked map", "magic");
    free(b);

    b = edited(&m);
    rc__bk_put32(b, RC__BK_VERSION, 2u);
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_UNSUPPORTED, "version 2", "version");
    rc__bk_put32(b, RC__BK_VERSION, 1u);
    rc__bk_put32(b, RC__BK_BYTE_ORDER, 0x04030201u);
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_UNSUPPORTED, "byte order", "byte order");
    free(b);

    b = edited(&m);
    b[m.bytes / 2u] ^= 0x10u; /* one bit anywhere */
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "checksum", "a flipped bit");
    free(b);

    /* structure checks, each with a right checksum */
    b = edited(&m);
    memcpy(&node, b + nodes, sizeof node);
    node.child[0] = 0; /* the root pointing to itself: a loop */
    node.count[0] = 0;
    memcpy(b + nodes, &node, sizeof node);
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "children come after", "a loop");
    free(b);

    b = edited(&m);
    {
        /* the root's second inner child replaced by its first, under a box
         * holding both: every slot check passes, yet node 1 is reached twice
         * (a chain of such links multiplies traversal work per link) */
        uint32_t c, first = 4, second = 4, k;
        memcpy(&node, b + nodes, sizeof node);
        for (c = 0; c < 4; ++c)
            if (node.child[c] != RC__WIDE_EMPTY && node.count[c] == 0) {
                if (first == 4) {
                    first = c;
                } else if (second == 4) {
                    second = c;
                }
            }
        assert_true(second < 4); /* the fixture's root has two inner children */
        assert_int_equal(node.child[first], 1);
        for (k = 0; k < 3; ++k) {
            const float lo = node.box[2 * k][first] < node.box[2 * k][second] ? node.box[2 * k][first]
                                                                              : node.box[2 * k][second];
            const float hi = node.box[2 * k + 1][first] > node.box[2 * k + 1][second] ? node.box[2 * k + 1][first]
                                                                                      : node.box[2 * k + 1][second];
            node.box[2 * k][first] = node.box[2 * k][second] = lo;
            node.box[2 * k + 1][first] = node.box[2 * k + 1][second] = hi;
        }
        node.child[second] = 1;
        memcpy(b + nodes, &node, sizeof node);
    }
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "depth-first walk", "a node with two parents");
    free(b);

    b = edited(&m);
    memcpy(&node, b + nodes, sizeof node);
    node.box[1][0] = node.box[0][0]; /* slot 0's box loses its width in x */
    memcpy(b + nodes, &node, sizeof node);
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "does not hold", "a shrunk box");
    free(b);

    b = edited(&m);
    rc__bk_put32(b, (size_t)lt, 0xFFFFFF00u); /* a leaf slot's vertex index past the vertices */
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "leaf slot 0", "a leaf index");
    free(b);

    b = edited(&m);
    {
        const float nan = NAN;
        memcpy(b + verts, &nan, sizeof nan);
    }
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "vertex 0", "a NaN vertex");
    free(b);

    b = edited(&m);
    rc__bk_put64(b + RC__BAKED_HEADER, RC__BR_OFF_NODES, m.bytes - 64u); /* nodes running off the end */
    reseal(b, m.bytes);
    expect_refused(ctx, b, m.bytes, 0, RC_ERR_CORRUPT_DATA, "outside the blob", "a section past the end");
    free(b);

    rc_context_destroy(ctx);
    free_map(&m);
}

/* Random bit flips with the checksum check off: every load either refuses
 * with RC_ERR_CORRUPT_DATA or gives a scene that simulates (any ranges; the
 * point is that nothing reads outside the blob or hangs). */
static void test_random_flips_never_crash(void **state)
{
    baked_map m;
    rc_context *ctx;
    rc_scene *scene;
    rc_sensor *s = NULL;
    rct_buffers buf;
    rc_pose p[POSES];
    unsigned char *b;
    uint64_t x = 0x9E3779B97F4A7C15ull;
    uint32_t round, rounds = rct_quick() ? 200u : 3000u, loaded = 0;
    const char *env = getenv("RC_FUZZ_ROUNDS"); /* explores further, as in test_fuzz_api */
    (void)state;
    if (env && atoi(env) > 0) rounds = (uint32_t)atoi(env);
    ctx = baked_fixture(&m, 1, &scene);
    RCT_OK(ctx, rc_scene_destroy(scene));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
    rct_buffers_alloc(&buf, (uint64_t)POSES * 16u * 900u, RC_ATTR_ALL);
    poses_in_room(p);
    b = (unsigned char *)rct_alloc16(m.bytes);
    for (round = 0; round < rounds; ++round) {
        rc_scene *l = NULL;
        rc_status st;
        uint32_t flips = 1u + (uint32_t)(x >> 62), f;
        memcpy(b, m.blob, m.bytes);
        for (f = 0; f < flips; ++f) {
            uint64_t at;
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            /* half the flips in the header, records and nodes, where the checks are */
            at = (x & 1u) ? (x >> 8) % (RC__BAKED_HEADER + 2u * RC__BAKED_RECORD) : (x >> 8) % m.bytes;
            b[at] ^= (unsigned char)(1u << ((x >> 4) & 7u));
        }
        st = rc_scene_load_baked(ctx, b, m.bytes, RC_BAKED_SKIP_CHECKSUM, &l);
        if (st != RC_OK) {
            if (st != RC_ERR_CORRUPT_DATA && st != RC_ERR_UNSUPPORTED)
                fail_msg("round %u: %s (%s)", round, rc_status_string(st), rc_context_last_error(ctx));
            continue;
        }
        ++loaded;
        RCT_OK(ctx, rc_simulate(ctx, l, s, p, POSES, &buf.res));
        RCT_OK(ctx, rc_scene_destroy(l));
    }
    print_message("%u of %u flipped blobs passed the structure checks and simulated\n", loaded, rounds);
    /* flips in padding and in the pad float of vertices change nothing */
    assert_true(loaded > 0 && loaded < rounds);
    free(b);
    rct_buffers_free(&buf);
    rc_context_destroy(ctx);
    free_map(&m);
}

/* tests/data/box_room.rcmap: a closed box room x -2..4, y -3..5, z -1..2,
 * baked by this test (RC_BAKED_WRITE_GOLDEN=1 writes it anew; do that only
 * with a format version bump). Every target reads it and sees the walls at
 * their distances, and bakes the same room to the same bytes: the format is
 * the same on every architecture and has not changed under its version. */
static void test_golden_blob(void **state)
{
    static const float dirs[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    static const float want[6] = {4.0f, 2.0f, 5.0f, 3.0f, 2.0f, 1.0f};
    const float lo[3] = {-2.0f, -3.0f, -1.0f}, hi[3] = {4.0f, 5.0f, 2.0f};
    const char *path = RC_TEST_DATA_DIR "/box_room.rcmap";
    rcu_mesh room;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 16);
    rc_scene *scene, *loaded = NULL;
    rc_sensor *s;
    rc_pose p = rct_pose(0.0f, 0.0f, 0.0f);
    rct_buffers buf;
    unsigned char *golden, *fresh;
    size_t bytes = 0, n = 0, k;
    FILE *f;
    (void)state;
    assert_int_equal(rcu_mesh_box(lo, hi, &room), 0);
    scene = rct_scene_mesh(ctx, &room, RC_MESH_REFERENCE);
    RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &bytes));
    fresh = (unsigned char *)rct_alloc16(bytes);
    RCT_OK(ctx, rc_scene_bake(scene, fresh, bytes, &n));
    if (getenv("RC_BAKED_WRITE_GOLDEN")) {
        f = fopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(fresh, 1, bytes, f), bytes);
        assert_int_equal(fclose(f), 0);
    }
    f = fopen(path, "rb");
    if (f == NULL) fail_msg("%s: cannot open", path);
    golden = (unsigned char *)rct_alloc16(bytes + 1u);
    n = fread(golden, 1, bytes + 1u, f);
    fclose(f);
    if (n != bytes || memcmp(golden, fresh, bytes) != 0)
        fail_msg("the box room bakes to other bytes than %s (%llu bytes, golden %llu): a format change needs "
                 "RC_BAKED_MAP_VERSION bumped",
                 path, (unsigned long long)bytes, (unsigned long long)n);
    RCT_OK(ctx, rc_scene_load_baked(ctx, golden, n, 0, &loaded));
    s = rct_sensor_dirs(ctx, dirs, 6, 0.1f, 100.0f);
    rct_buffers_alloc(&buf, 6, RC_ATTR_RANGES);
    RCT_OK(ctx, rc_simulate(ctx, loaded, s, &p, 1, &buf.res));
    for (k = 0; k < 6; ++k)
        if (fabsf(buf.res.ranges[k] - want[k]) > 1e-6f)
            fail_msg("ray %u: range %.9g, the wall is at %g", (unsigned)k, (double)buf.res.ranges[k], (double)want[k]);
    rct_buffers_free(&buf);
    free(golden);
    free(fresh);
    rc_context_destroy(ctx);
    rcu_mesh_free(&room);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32c_check_value),
        cmocka_unit_test(test_load_bit_identical),
        cmocka_unit_test(test_bake_is_deterministic),
        cmocka_unit_test(test_origin_kept),
        cmocka_unit_test(test_other_backends),
        cmocka_unit_test(test_read_only_and_instanced),
        cmocka_unit_test(test_get_mesh),
        cmocka_unit_test(test_bake_refusals),
        cmocka_unit_test(test_bad_blobs),
        cmocka_unit_test(test_random_flips_never_crash),
        cmocka_unit_test(test_golden_blob),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
