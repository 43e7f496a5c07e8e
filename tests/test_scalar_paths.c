/* The plain-C box tests (what riscv64 and other targets without SSE2 or NEON
 * run) against the SIMD ones this machine runs: wide_trace.c and packet.c are
 * compiled again here with their SIMD paths off and their functions renamed,
 * and both versions must give the same hits, bit for bit. */
#define RC__WIDE_FORCE_SCALAR 1
#define RC__PACKET_FORCE_SCALAR 1
#define rc__mesh_intersect_wide scalar_intersect_wide
#define rc__mesh_occluded_wide scalar_occluded_wide
#define rc__mesh_intersect_rays scalar_intersect_rays
#define rc__mesh_order_key scalar_order_key
#include "../src/bvh/wide_trace.c"
#undef rc__mesh_intersect_rays
#define rc__mesh_intersect_packet scalar_intersect_packet
#define rc__mesh_intersect_packets scalar_intersect_packets
#define rc__mesh_intersect_packet_meshes scalar_intersect_packet_meshes
#include "../src/bvh/packet.c"
#undef rc__mesh_intersect_packet
#undef rc__mesh_intersect_packets
#undef rc__mesh_intersect_packet_meshes
#undef rc__mesh_intersect_wide
#undef rc__mesh_occluded_wide

#include <math.h>
#include <string.h>

#include "poses.h"
#include "rc_test.h"
#include "scene/scene.h"

int rc__mesh_intersect_wide(const rc__mesh *mesh, const rc__ray *ray, uint32_t geom, uint32_t inst, rc__hit *hit);
int rc__mesh_occluded_wide(const rc__mesh *mesh, const rc__ray *ray, float tmax);
void rc__mesh_intersect_packet(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom, uint32_t inst,
                               rc__hit *hits, int *found, uint32_t flags);

/* the tools' generator, seeded in main */
static rcu_rng rng;
static double uniform(void) { return rcu_rng_uniform(&rng); }

static void hit_init(rc__hit *h)
{
    h->t = 1e30f; /* t is in units of |dir|, some directions are short */
    h->prim = h->geom = h->inst = RC_INVALID_ID;
}

static void same_hit(int fa, const rc__hit *a, int fb, const rc__hit *b)
{
    assert_int_equal(fa, fb);
    if (!fa) return;
    assert_int_equal(a->prim, b->prim);
    assert_memory_equal(&a->t, &b->t, sizeof(float));
}

static void test_scalar_equals_simd(void **state)
{
    rcu_mesh m, box;
    const float lo[3] = {-3.0f, -2.0f, -1.0f}, hi[3] = {2.0f, 4.0f, 1.5f};
    rc_context *ctx;
    rc_scene *scene;
    const rc__mesh *mesh;
    uint32_t tile, i, k, tiles = rct_quick() ? 200u : 2000u, hits = 0, rays = 0;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 150, 75, &m), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    assert_int_equal(rcu_mesh_append(&m, &box), 0);
    ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
    mesh = &scene->geoms[0].mesh;
    assert_non_null(mesh->wide);
    for (tile = 0; tile < tiles; ++tile) {
        float org[3];
        rc__ray r[RC__PACKET_SIZE];
        rc__hit hs[RC__PACKET_SIZE], hv[RC__PACKET_SIZE], h1[RC__PACKET_SIZE];
        int fs[RC__PACKET_SIZE], fv[RC__PACKET_SIZE], f1[RC__PACKET_SIZE];
        /* every third tile an OnDn packet: each ray from its own origin */
        const int own = tile % 3 == 1;
        double yaw = uniform() * 6.283185307, pitch = (uniform() - 0.5) * 3.0;
        double spread = (tile % 5 == 0) ? 0.5 : 0.02;
        for (k = 0; k < 3; ++k) org[k] = (float)((uniform() - 0.5) * 12.0);
        if (tile % 11 == 0) org[1] = hi[1]; /* on a box plane */
        for (i = 0; i < RC__PACKET_SIZE; ++i) {
            double y = yaw + (uniform() - 0.5) * spread, p = pitch + (uniform() - 0.5) * spread;
            float dir[3];
            dir[0] = (float)(cos(p) * cos(y));
            dir[1] = (float)(cos(p) * sin(y));
            dir[2] = (float)sin(p);
            if (tile % 13 == 0) dir[i % 3] = 0.0f;
            if (tile % 17 == 0) dir[(i + 1) % 3] = -0.0f;
            if (own) {
                float o[3];
                for (k = 0; k < 3; ++k) o[k] = org[k] + (float)((uniform() - 0.5) * (tile % 2 ? 0.06 : 1.0));
                rc__ray_prepare(&r[i], o, dir);
            } else {
                rc__ray_prepare(&r[i], org, dir);
            }
        }
        /* single rays: scalar vs SIMD box tests */
        for (i = 0; i < RC__PACKET_SIZE; ++i) {
            rc__hit a, b;
            int fa, fb;
            hit_init(&a);
            hit_init(&b);
            fa = scalar_intersect_wide(mesh, &r[i], 0, RC_INVALID_ID, &a);
            fb = rc__mesh_intersect_wide(mesh, &r[i], 0, RC_INVALID_ID, &b);
            same_hit(fa, &a, fb, &b);
            f1[i] = fb;
            h1[i] = b;
            assert_int_equal(scalar_occluded_wide(mesh, &r[i], 1e30f), rc__mesh_occluded_wide(mesh, &r[i], 1e30f));
            hits += (uint32_t)fa;
            ++rays;
        }
        /* packets: scalar vs SIMD lanes */
        for (i = 0; i < RC__PACKET_SIZE; ++i) {
            hit_init(&hs[i]);
            hit_init(&hv[i]);
            fs[i] = fv[i] = 0;
        }
        scalar_intersect_packet(mesh, r, RC__PACKET_SIZE, 0, RC_INVALID_ID, hs, fs, own ? RC__PACKET_OWN_ORIGINS : 0u);
        rc__mesh_intersect_packet(mesh, r, RC__PACKET_SIZE, 0, RC_INVALID_ID, hv, fv, own ? RC__PACKET_OWN_ORIGINS : 0u);
        for (i = 0; i < RC__PACKET_SIZE; ++i) {
            same_hit(fs[i], &hs[i], fv[i], &hv[i]);
            same_hit(f1[i], &h1[i], fv[i], &hv[i]); /* and the single ray's */
        }
    }
    assert_int_equal(hits, rays); /* inside a closed sphere: every ray hits */
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
    rcu_mesh_free(&box);
}

int main(void)
{
    rcu_rng_seed(&rng, 0x2545F4914F6CDD1Dull);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_scalar_equals_simd)};
    return cmocka_run_group_tests_name("scalar box tests", tests, NULL, NULL);
}
