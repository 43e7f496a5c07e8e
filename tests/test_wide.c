/* The 4-wide BVH: the collapse keeps every leaf once with its exact box and
 * stays within the node bound the arena reserves; nearest-hit and any-hit
 * traversal of the wide tree give the binary tree's answers bit for bit
 * (same t, u, v, triangle) on random, axis-parallel and edge-grazing rays;
 * a refit after moving vertices gives the answers of a fresh build. Built
 * twice: with the SSE2/NEON box test, and as test_wide_scalar with the
 * plain-C one. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh/intersect.h"
#include "poses.h"
#include "rc_test.h"
#include "scene/scene.h"

/* the tools' generator, seeded in main */
static rcu_rng rng;
static double uniform(void) { return rcu_rng_uniform(&rng); }

/* The scene's mesh again with its binary tree (built here) instead of the
 * wide one, so both traversals see the same triangles and leaf order. */
typedef struct binary_mesh {
    rc__mesh mesh;
    rc__bvh_node *nodes;
    uint32_t *refs;
    rc__aabb *bounds;
    void *scratch;
} binary_mesh;

static void binary_of(const rc__mesh *src, binary_mesh *b)
{
    const uint32_t t = src->triangle_count;
    b->mesh = *src;
    b->mesh.wide = NULL;
    b->mesh.wide_count = 0;
    b->mesh.leaf_tris = NULL;
    b->nodes = malloc(rc__bvh_node_count(t, RC__BVH_MESH_LEAF_SIZE) * sizeof *b->nodes);
    b->refs = malloc(t * sizeof *b->refs);
    b->bounds = malloc(t * sizeof *b->bounds);
    b->scratch = malloc(rc__bvh_build_scratch_bytes(t));
    assert_non_null(b->nodes);
    assert_non_null(b->refs);
    assert_non_null(b->bounds);
    assert_non_null(b->scratch);
    b->mesh.bvh.nodes = b->nodes;
    b->mesh.bvh.refs = b->refs;
    rc__mesh_triangle_bounds(&b->mesh, b->bounds);
    rc__bvh_build(b->bounds, t, RC__BVH_MESH_LEAF_SIZE, b->scratch, &b->mesh.bvh, NULL, NULL);
}

static void binary_free(binary_mesh *b)
{
    free(b->nodes);
    free(b->refs);
    free(b->bounds);
    free(b->scratch);
}

/* A sphere with a box inside: closed surfaces, shared edges, flat faces. */
static void test_mesh(rcu_mesh *m)
{
    rcu_mesh box;
    const float lo[3] = {-3.0f, -2.0f, -1.0f}, hi[3] = {2.0f, 4.0f, 1.5f};
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 120, 60, m), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    assert_int_equal(rcu_mesh_append(m, &box), 0);
    rcu_mesh_free(&box);
}

/* Every leaf slot reached exactly once, children after parents, each leaf
 * box the exact bounds of its triangles, each interior box the union of its
 * node's boxes, and no more nodes than the bound. */
static void check_structure(const rc__mesh *mesh)
{
    const rc__wnode *w = mesh->wide;
    uint32_t *seen = calloc(mesh->triangle_count, sizeof *seen);
    uint32_t i, c, j, k, leaves = (mesh->triangle_count + 3u) / 4u;
    assert_non_null(seen);
    assert_non_null(w);
    assert_true(mesh->wide_count >= 1);
    assert_true(mesh->wide_count <= rc__wide_node_bound(leaves));
    for (i = 0; i < mesh->wide_count; ++i) {
        uint32_t used = 0;
        for (c = 0; c < 4; ++c) {
            float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            if (w[i].child[c] == RC__WIDE_EMPTY) {
                assert_true(w[i].box[0][c] > w[i].box[1][c]);
                continue;
            }
            ++used;
            if (w[i].count[c] > 0) {
                assert_true(w[i].count[c] <= RC__BVH_MESH_LEAF_SIZE);
                for (j = w[i].child[c]; j < w[i].child[c] + w[i].count[c]; ++j) {
                    assert_true(j < mesh->triangle_count);
                    ++seen[j];
                    for (k = 0; k < 3; ++k) {
                        const float *p = mesh->vertices + (size_t)mesh->leaf_tris[3u * j + k] * mesh->stride;
                        uint32_t a;
                        for (a = 0; a < 3; ++a) {
                            lo[a] = p[a] < lo[a] ? p[a] : lo[a];
                            hi[a] = p[a] > hi[a] ? p[a] : hi[a];
                        }
                    }
                }
            } else {
                const rc__wnode *s = &w[w[i].child[c]];
                uint32_t d, a;
                assert_true(w[i].child[c] > i);
                assert_true(w[i].child[c] < mesh->wide_count);
                for (d = 0; d < 4; ++d) {
                    if (s->child[d] == RC__WIDE_EMPTY) continue;
                    for (a = 0; a < 3; ++a) {
                        lo[a] = s->box[2 * a][d] < lo[a] ? s->box[2 * a][d] : lo[a];
                        hi[a] = s->box[2 * a + 1][d] > hi[a] ? s->box[2 * a + 1][d] : hi[a];
                    }
                }
            }
            for (k = 0; k < 3; ++k) {
                assert_true(w[i].box[2 * k][c] == lo[k]);
                assert_true(w[i].box[2 * k + 1][c] == hi[k]);
            }
        }
        assert_true(used >= (i == 0 && mesh->triangle_count <= 4 ? 1u : 2u));
    }
    for (j = 0; j < mesh->triangle_count; ++j) assert_int_equal(seen[j], 1);
    free(seen);
}

/* t is in units of |dir|, and some directions here are short: no limit */
#define FAR 1e30f

static void hit_init(rc__hit *h, float t)
{
    h->t = t;
    h->prim = h->geom = h->inst = h->slot = RC_INVALID_ID;
}

/* One ray through both trees: same found flag and the same hit bit for bit,
 * and the same any-hit answer. */
static void compare_ray(const rc__mesh *wide, const rc__mesh *binary, const float org[3], const float dir[3])
{
    rc__ray r;
    rc__hit hw, hb;
    int fw, fb;
    rc__ray_prepare(&r, org, dir);
    hit_init(&hw, FAR);
    hit_init(&hb, FAR);
    fw = rc__mesh_intersect(wide, &r, 0, RC_INVALID_ID, &hw);
    fb = rc__mesh_intersect(binary, &r, 0, RC_INVALID_ID, &hb);
    assert_int_equal(fw, fb);
    if (fw) {
        assert_int_equal(hw.prim, hb.prim);
        assert_memory_equal(&hw.t, &hb.t, sizeof(float));
        assert_int_equal(rc__mesh_occluded(wide, &r, hw.t * 1.001f), 1);
    }
    assert_int_equal(rc__mesh_occluded(wide, &r, FAR), rc__mesh_occluded(binary, &r, FAR));
}

/* Ray i of a random test: an origin in the sphere, a random direction,
 * every seventh axis-parallel. */
static void random_ray(uint32_t i, float org[3], float dir[3])
{
    double y = uniform() * 6.283185307, p = (uniform() - 0.5) * 3.1;
    uint32_t k;
    for (k = 0; k < 3; ++k) org[k] = (float)((uniform() - 0.5) * 12.0);
    dir[0] = (float)(cos(p) * cos(y));
    dir[1] = (float)(cos(p) * sin(y));
    dir[2] = (float)sin(p);
    if (i % 7 == 0) dir[i % 3] = 0.0f; /* axis-parallel */
}

static void random_rays(const rc__mesh *wide, const rc__mesh *binary, uint32_t rays)
{
    uint32_t i, k, hits = 0;
    for (i = 0; i < rays; ++i) {
        float org[3], dir[3];
        random_ray(i, org, dir);
        if (i % 11 == 0) dir[(i + 1) % 3] = -0.0f;
        if (i % 13 == 0) org[0] = -3.0f;              /* on the box's plane */
        if (i % 17 == 0) {                            /* at a shared vertex of the sphere */
            const float *v = wide->vertices + (size_t)wide->indices[3u * (i % wide->triangle_count)] * wide->stride;
            for (k = 0; k < 3; ++k) dir[k] = v[k] - org[k];
        }
        compare_ray(wide, binary, org, dir);
        {
            rc__ray r;
            rc__hit h;
            rc__ray_prepare(&r, org, dir);
            hit_init(&h, FAR);
            hits += (uint32_t)rc__mesh_intersect(wide, &r, 0, RC_INVALID_ID, &h);
        }
    }
    /* every ray starts inside the closed sphere */
    assert_int_equal(hits, rays);
}

static void test_collapse_structure(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    (void)state;
    test_mesh(&m);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    check_structure(&scene->geoms[0].mesh);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* Meshes of 1..9 triangles: the one-leaf tree, partial nodes, empty slots. */
static void test_small_meshes(void **state)
{
    rcu_mesh m;
    uint32_t t;
    (void)state;
    test_mesh(&m);
    for (t = 1; t <= 9; ++t) {
        rcu_mesh part = m;
        rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
        rc_scene *scene;
        binary_mesh b;
        uint32_t i;
        part.triangle_count = t;
        scene = rct_scene_mesh(ctx, &part, RC_MESH_REFERENCE);
        check_structure(&scene->geoms[0].mesh);
        binary_of(&scene->geoms[0].mesh, &b);
        for (i = 0; i < 200; ++i) {
            float org[3] = {0.0f, 0.0f, 0.0f}, dir[3];
            const float *v = m.vertices + (size_t)m.indices[3u * (i % t) + i % 3] * 3u;
            dir[0] = v[0] + (float)(uniform() - 0.5) * 0.3f;
            dir[1] = v[1] + (float)(uniform() - 0.5) * 0.3f;
            dir[2] = v[2] + (float)(uniform() - 0.5) * 0.3f;
            compare_ray(&scene->geoms[0].mesh, &b.mesh, org, dir);
        }
        binary_free(&b);
        rc_context_destroy(ctx);
    }
    rcu_mesh_free(&m);
}

static void test_wide_equals_binary(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    binary_mesh b;
    (void)state;
    test_mesh(&m);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    binary_of(&scene->geoms[0].mesh, &b);
    random_rays(&scene->geoms[0].mesh, &b.mesh, rct_quick() ? 3000u : 30000u);
    binary_free(&b);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* Rays taking turns (rc__mesh_intersect_rays) in runs of every length
 * around the number in flight: each gets rc__mesh_intersect's answer, bit
 * for bit, and its found flag (or-ed in); some start with a shorter tmax. */
static void test_rays_in_turns(void **state)
{
    static const uint32_t runs[] = {0, 1, 5, 8, 9, 16, 37, 128};
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    const rc__mesh *mesh;
    uint32_t round, rounds = rct_quick() ? 8u : 60u, hits_seen = 0;
    (void)state;
    test_mesh(&m);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    mesh = &scene->geoms[0].mesh;
    for (round = 0; round < rounds; ++round) {
        const uint32_t n = runs[round % (sizeof runs / sizeof runs[0])];
        rc__ray rays[128];
        rc__hit hits[128];
        int found[128];
        uint32_t i;
        for (i = 0; i < n; ++i) {
            float org[3], dir[3];
            random_ray(i, org, dir);
            rc__ray_prepare(&rays[i], org, dir);
            hit_init(&hits[i], i % 5 == 0 ? 2.0f : FAR); /* some end before any surface */
            found[i] = i % 3 == 0; /* set flags stay set */
        }
        rc__mesh_intersect_rays(mesh, rays, n, 0, RC_INVALID_ID, hits, found);
        for (i = 0; i < n; ++i) {
            rc__hit h;
            int f;
            hit_init(&h, i % 5 == 0 ? 2.0f : FAR);
            f = rc__mesh_intersect(mesh, &rays[i], 0, RC_INVALID_ID, &h);
            assert_int_equal(found[i], f | (i % 3 == 0));
            hits_seen += (uint32_t)f;
            if (!f) continue;
            assert_int_equal(hits[i].prim, h.prim);
            assert_int_equal(hits[i].slot, h.slot);
            assert_memory_equal(&hits[i].t, &h.t, sizeof(float));
        }
    }
    assert_true(hits_seen > 0);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* Move the vertices (a dynamic map), update and commit: the refit tree
 * holds exact boxes again and answers as a binary tree built afresh. */
static void test_refit(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    binary_mesh b;
    uint32_t i;
    (void)state;
    test_mesh(&m);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    for (i = 0; i < m.vertex_count; ++i) {
        m.vertices[3u * i] *= 0.9f;
        m.vertices[3u * i + 2] += 0.25f * m.vertices[3u * i + 1] / 20.0f;
    }
    RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
    RCT_OK(ctx, rc_scene_commit(scene));
    check_structure(&scene->geoms[0].mesh);
    binary_of(&scene->geoms[0].mesh, &b);
    random_rays(&scene->geoms[0].mesh, &b.mesh, rct_quick() ? 1000u : 10000u);
    binary_free(&b);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

/* A mesh added after the first commit: the trimmed block is released and
 * every mesh rebuilt; both meshes answer (each against its own binary tree),
 * the block kept is what the trees use, and the same arena can do it again. */
static void test_add_mesh_after_commit(void **state)
{
    rcu_mesh a, b;
    const float lo[3] = {-3.0f, -2.0f, -1.0f}, hi[3] = {2.0f, 4.0f, 1.5f};
    rc_context *ctx;
    rc_scene *scene;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_scene_info i1 = rc_scene_info_default(), i2 = rc_scene_info_default();
    binary_mesh ba, bb;
    uint32_t g, round;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 120, 60, &a), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &b), 0);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    sd.max_geometries = 2;
    sd.max_triangles = a.triangle_count + b.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = a.vertices;
    md.vertex_count = a.vertex_count;
    md.indices = a.indices;
    md.triangle_count = a.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    RCT_OK(ctx, rc_scene_commit(scene));
    RCT_OK(ctx, rc_scene_get_info(scene, &i1));
    md.vertices = b.vertices;
    md.vertex_count = b.vertex_count;
    md.indices = b.indices;
    md.triangle_count = b.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    for (round = 0; round < 2; ++round) {
        uint32_t k;
        RCT_OK(ctx, rc_scene_commit(scene));
        check_structure(&scene->geoms[0].mesh);
        check_structure(&scene->geoms[1].mesh);
        binary_of(&scene->geoms[0].mesh, &ba);
        binary_of(&scene->geoms[1].mesh, &bb);
        for (k = 0; k < 500; ++k) {
            float org[3] = {0.0f, 0.0f, 0.0f}, dir[3];
            double y = uniform() * 6.283185307, p = (uniform() - 0.5) * 3.0;
            dir[0] = (float)(cos(p) * cos(y));
            dir[1] = (float)(cos(p) * sin(y));
            dir[2] = (float)sin(p);
            compare_ray(&scene->geoms[0].mesh, &ba.mesh, org, dir);
            compare_ray(&scene->geoms[1].mesh, &bb.mesh, org, dir);
        }
        binary_free(&ba);
        binary_free(&bb);
        RCT_OK(ctx, rc_scene_get_info(scene, &i2));
        assert_true(i2.bytes > i1.bytes); /* the box's tree and refs were added */
        /* the scene is full (2 geometries): refused, and the next round's
         * commit of the unchanged scene keeps the trees as they are */
        assert_int_not_equal(rc_scene_add_mesh(scene, &md, &g), RC_OK);
    }
    rc_context_destroy(ctx);
    rcu_mesh_free(&a);
    rcu_mesh_free(&b);
}

int main(void)
{
    rcu_rng_seed(&rng, 0x9E3779B97F4A7C15ull);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_collapse_structure),
        cmocka_unit_test(test_small_meshes),
        cmocka_unit_test(test_wide_equals_binary),
        cmocka_unit_test(test_rays_in_turns),
        cmocka_unit_test(test_refit),
        cmocka_unit_test(test_add_mesh_after_commit),
    };
    return cmocka_run_group_tests_name("wide BVH", tests, NULL, NULL);
}
