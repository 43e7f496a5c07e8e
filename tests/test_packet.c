/* The packet traversal (SSE2 / NEON / scalar box tests) gives every ray
 * exactly the hit of the single-ray traversal: same t, triangle and
 * barycentrics, bit for bit, for coherent tiles, mixed-octant tiles, axis-
 * parallel rays and partial packets. */
#include <math.h>
#include <string.h>

#include "bvh/packet.h"
#include "rc_test.h"
#include "scene/scene.h"

static uint64_t rng = 88172645463325252ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static void compare_tile(const rc__mesh *mesh, const float org[3], const float (*dirs)[3], uint32_t n)
{
    rc__ray rays[RC__PACKET_SIZE];
    rc__hit hp[RC__PACKET_SIZE], hs;
    int fp[RC__PACKET_SIZE], fs;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        rc__ray_prepare(&rays[i], org, dirs[i]);
        hp[i].t = 1000.0f;
        hp[i].u = hp[i].v = 0.0f;
        hp[i].prim = hp[i].geom = hp[i].inst = RC_INVALID_ID;
        fp[i] = 0;
    }
    rc__mesh_intersect_packet(mesh, rays, n, 0, RC_INVALID_ID, hp, fp);
    for (i = 0; i < n; ++i) {
        hs.t = 1000.0f;
        hs.u = hs.v = 0.0f;
        hs.prim = hs.geom = hs.inst = RC_INVALID_ID;
        fs = rc__mesh_intersect(mesh, &rays[i], 0, RC_INVALID_ID, &hs);
        assert_int_equal(fp[i], fs);
        if (!fs) continue;
        assert_int_equal(hp[i].prim, hs.prim);
        assert_memory_equal(&hp[i].t, &hs.t, sizeof(float));
        assert_memory_equal(&hp[i].u, &hs.u, sizeof(float));
        assert_memory_equal(&hp[i].v, &hs.v, sizeof(float));
    }
}

static void test_packet_equals_single(void **state)
{
    rcu_mesh m, box;
    const float lo[3] = {-3.0f, -2.0f, -1.0f}, hi[3] = {2.0f, 4.0f, 1.5f};
    rc_context *ctx;
    rc_scene *scene;
    const rc__mesh *mesh;
    uint32_t tile, i, tiles = rct_quick() ? 300u : 3000u;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &m), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    assert_int_equal(rcu_mesh_append(&m, &box), 0);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    mesh = &scene->geoms[0].mesh;
    for (tile = 0; tile < tiles; ++tile) {
        float org[3], dirs[RC__PACKET_SIZE][3];
        /* a tile of nearby directions around a random centre; some straddle
         * axis planes, some are widely spread, some partial */
        double yaw = uniform() * 6.283185307, pitch = (uniform() - 0.5) * 3.0;
        double spread = (tile % 5 == 0) ? 0.5 : 0.02;
        uint32_t n = (tile % 7 == 0) ? 1u + (uint32_t)(uniform() * RC__PACKET_SIZE) % RC__PACKET_SIZE
                                     : RC__PACKET_SIZE;
        for (i = 0; i < 3; ++i) org[i] = (float)((uniform() - 0.5) * 12.0);
        if (tile % 11 == 0) org[0] = lo[0]; /* origin on a box plane */
        for (i = 0; i < n; ++i) {
            double y = yaw + (uniform() - 0.5) * spread, p = pitch + (uniform() - 0.5) * spread;
            dirs[i][0] = (float)(cos(p) * cos(y));
            dirs[i][1] = (float)(cos(p) * sin(y));
            dirs[i][2] = (float)sin(p);
            if (tile % 13 == 0) dirs[i][i % 3] = 0.0f; /* exact zero components */
            if (tile % 17 == 0) dirs[i][(i + 1) % 3] = -0.0f;
        }
        compare_tile(mesh, org, (const float(*)[3])dirs, n);
    }
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
    rcu_mesh_free(&box);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_packet_equals_single)};
    return cmocka_run_group_tests_name("packet traversal", tests, NULL, NULL);
}
