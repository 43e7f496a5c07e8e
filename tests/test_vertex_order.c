/* A copied mesh's vertex order: the built-in backend renumbers a copy's
 * vertices in the order its leaves use them (rc__mesh_order_vertices), so a
 * map handed in with a poor numbering traces as fast as a well-ordered one.
 * Every result must stay what the caller's own numbering gives, on every
 * backend, and the copy the scene keeps (as a bake shows it) must hold the
 * same triangles, corner by corner, in a numbering that is local. */
#include <stdlib.h>
#include <string.h>

#include "bvh/mesh.h" /* RC__ORDER_COPIES */
#include "rc_test.h"

/* Deterministic shuffle (a 64-bit LCG), so a failure repeats. */
static uint32_t next_random(uint64_t *s, uint32_t bound)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)((*s >> 33) % bound);
}

/* The 20k-triangle sphere of radius 20 with its vertex array shuffled, the
 * indices remapped, EXTRA unused vertices after them and one zero-area
 * triangle (a, a, b) at the end: out owns its arrays (rcu_mesh_free). */
#define EXTRA 37u
static void shuffled_sphere(rcu_mesh *out)
{
    rcu_mesh m;
    uint32_t *to, i, v, t;
    uint64_t seed = 12345u;
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 20000, &m), 0);
    v = m.vertex_count;
    t = m.triangle_count;
    to = (uint32_t *)malloc(sizeof(uint32_t) * v);
    assert_non_null(to);
    for (i = 0; i < v; ++i) to[i] = i;
    for (i = v - 1u; i > 0; --i) {
        const uint32_t j = next_random(&seed, i + 1u), x = to[i];
        to[i] = to[j];
        to[j] = x;
    }
    assert_int_equal(rcu_mesh_reserve(out, v + EXTRA, t + 1u), 0);
    for (i = 0; i < v; ++i) memcpy(out->vertices + 3u * (size_t)to[i], m.vertices + 3u * (size_t)i, 12);
    for (i = 0; i < EXTRA; ++i) {
        out->vertices[3u * (v + i)] = 100.0f + (float)i; /* far outside: never met */
        out->vertices[3u * (v + i) + 1u] = -50.0f;
        out->vertices[3u * (v + i) + 2u] = 7.0f;
    }
    for (i = 0; i < 3u * t; ++i) out->indices[i] = to[m.indices[i]];
    out->indices[3u * t] = out->indices[3u * t + 1u] = out->indices[0];
    out->indices[3u * t + 2u] = out->indices[1];
    out->vertex_count = v + EXTRA;
    out->triangle_count = t + 1u;
    free(to);
    rcu_mesh_free(&m);
}

/* The same mesh referenced and copied gives every attribute byte for byte
 * the same (the copy renumbered on the built-in backend, as it is on its
 * own there), and the sphere's rays all hit. */
static void test_copy_gives_the_same_results(void **state)
{
    const uint32_t b = rct_backend_of(state);
    rc_context *ctx;
    rc_scene *ref, *copy;
    rc_sensor *sensor;
    rcu_mesh m = {0};
    rct_buffers a, c;
    rc_sensor_info info = rc_sensor_info_default();
    rc_pose poses[4];
    uint64_t k;
    if (!rct_backend_usable(b)) skip();
    poses[0] = rct_pose_ypr(0.0f, 0.0f, 0.0f, 0.0, 0.0, 0.0);
    poses[1] = rct_pose_ypr(5.0f, -3.0f, 2.0f, 0.7, 0.2, -0.1);
    poses[2] = rct_pose_ypr(-8.0f, 4.0f, -1.5f, -2.1, -0.4, 0.3);
    poses[3] = rct_pose_ypr(1.0f, 9.0f, 3.0f, 2.9, 1.1, 0.6);
    shuffled_sphere(&m);
    ctx = rct_context(b, 2, 0);
    ref = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    copy = rct_scene_mesh(ctx, &m, RC_MESH_COPY);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
    RCT_OK(ctx, rc_sensor_get_info(sensor, &info));
    rct_buffers_alloc(&a, 4u * (uint64_t)info.rays_per_scan, RC_ATTR_ALL);
    rct_buffers_alloc(&c, 4u * (uint64_t)info.rays_per_scan, RC_ATTR_ALL);
    RCT_OK(ctx, rc_simulate(ctx, ref, sensor, poses, 4, &a.res));
    RCT_OK(ctx, rc_simulate(ctx, copy, sensor, poses, 4, &c.res));
    rct_assert_same_results(&a, &c);
    for (k = 0; k < a.n; ++k) {
        assert_int_equal(a.res.hits[k], 1);
        assert_true(a.res.prim_ids[k] < m.triangle_count - 1u); /* never the zero-area one */
    }
    rct_buffers_free(&a);
    rct_buffers_free(&c);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

static uint64_t mean_index_gap(const uint32_t *indices, uint64_t triangles)
{
    uint64_t sum = 0, t;
    for (t = 0; t < triangles; ++t) {
        const uint32_t a = indices[3u * t], b = indices[3u * t + 1u], c = indices[3u * t + 2u];
        sum += (a > b ? a - b : b - a) + (a > c ? a - c : c - a);
    }
    return sum / (2u * triangles);
}

/* The built-in backend's copy, as a bake writes it: the same triangles in
 * the same order, each corner at the same coordinates, every vertex once
 * (the unused ones last, in their order), and a triangle's corners numbered
 * close together where the shuffle had scattered them. */
static void test_copy_is_renumbered_in_leaf_order(void **state)
{
    rc_context *ctx;
    rc_scene *copy;
    rcu_mesh m = {0};
    rc_mesh_desc md = rc_mesh_desc_default();
    size_t bytes = 0;
    void *blob;
    const float *bv;
    const uint32_t *bi;
    uint32_t *seen, t, k, used = 0;
    uint64_t before, after;
    (void)state;
#if !defined(RC__ORDER_COPIES)
    skip(); /* an -Os build keeps a copy's numbering */
#endif
    shuffled_sphere(&m);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    copy = rct_scene_mesh(ctx, &m, RC_MESH_COPY);
    RCT_OK(ctx, rc_scene_bake(copy, NULL, 0, &bytes));
    blob = rct_alloc16(bytes);
    RCT_OK(ctx, rc_scene_bake(copy, blob, bytes, &bytes));
    RCT_OK(ctx, rc_baked_get_mesh(blob, bytes, 0, &md, NULL));
    assert_int_equal(md.vertex_count, m.vertex_count);
    assert_int_equal(md.triangle_count, m.triangle_count);
    bv = md.vertices;
    bi = md.indices;
    seen = (uint32_t *)calloc(m.vertex_count, sizeof(uint32_t));
    assert_non_null(seen);
    for (t = 0; t < m.triangle_count; ++t)
        for (k = 0; k < 3u; ++k) {
            const uint32_t was = m.indices[3u * t + k], now = bi[3u * t + k];
            const float *p = bv + (size_t)now * (md.vertex_stride / sizeof(float));
            assert_true(now < m.vertex_count);
            assert_memory_equal(p, m.vertices + 3u * (size_t)was, 12);
            /* one new number per old vertex */
            if (seen[was] == 0) {
                seen[was] = now + 1u;
                ++used;
            } else {
                assert_int_equal(seen[was], now + 1u);
            }
        }
    assert_int_equal(used, m.vertex_count - EXTRA);
    for (k = 0; k < EXTRA; ++k) {
        const float *p = bv + (size_t)(used + k) * (md.vertex_stride / sizeof(float));
        assert_memory_equal(p, m.vertices + 3u * (size_t)(used + k), 12);
    }
    before = mean_index_gap(m.indices, m.triangle_count - 1u);
    after = mean_index_gap(bi, m.triangle_count - 1u);
    print_message("mean index gap of a triangle's corners: shuffled %llu, kept %llu\n", (unsigned long long)before,
                  (unsigned long long)after);
    assert_true(after * 10u < before);
    free(seen);
    free(blob);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        RCT_FOR_BACKENDS(test_copy_gives_the_same_results),
        cmocka_unit_test(test_copy_is_renumbered_in_leaf_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
