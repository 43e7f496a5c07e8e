/* A map above RC__LARGE_MESH_BYTES through rc_simulate, where the built-in
 * backend's traversals take turns (packets for one-origin sensors, single
 * rays for OnDn): every ray reports the triangle the plain single-ray
 * traversal finds, on 1 and 2 threads, over partial tile groups and both
 * poses. (test_packet.c and test_wide.c check the traversals bit for bit on
 * a small map; this checks the backend's grouping of tiles around them.) The
 * context's threshold is set to the floor, whatever this CPU's cache, so the
 * map counts as large everywhere. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh/packet.h"
#include "core/context.h"
#include "poses.h"
#include "rc_test.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

#define RANGE_MIN 0.01f
#define RANGE_MAX 200.0f
#define POSES 2u

static rcu_rng rng;
static double uniform(void) { return rcu_rng_uniform(&rng); }

/* The triangle the single-ray traversal finds for ray i of the sensor at
 * pose (identity rotation: the world ray is the sensor ray moved by p). */
static uint32_t expected_prim(const rc__mesh *mesh, const rc_sensor *s, uint32_t i, const rc_pose *p)
{
    float org[3], dir[3];
    rc__ray r;
    rc__hit h;
    uint32_t k;
    for (k = 0; k < 3; ++k) {
        org[k] = (s->origins ? s->origins[3u * i + k] : 0.0f) + p->position[k];
        dir[k] = s->directions[3u * i + k];
    }
    rc__ray_prepare(&r, org, dir);
    h.t = RANGE_MAX;
    h.u = h.v = 0.0f;
    h.prim = h.geom = h.inst = h.slot = RC_INVALID_ID;
    return rc__mesh_intersect(mesh, &r, 0, RC_INVALID_ID, &h) ? h.prim : RC_INVALID_ID;
}

static void check_sensor(rc_context *ctx, rc_scene *scene, const rc_sensor *sensor, uint32_t rays)
{
    const rc__mesh *mesh = &scene->geoms[0].mesh;
    rc_pose poses[POSES];
    rct_buffers buf;
    uint32_t p, i, hits = 0;
    poses[0] = rct_pose(0.0f, 0.0f, 0.0f);
    poses[1] = rct_pose(3.0f, -2.0f, 1.0f);
    rct_buffers_alloc(&buf, (uint64_t)POSES * rays, RC_ATTR_HITS | RC_ATTR_PRIM_IDS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, POSES, &buf.res));
    for (p = 0; p < POSES; ++p)
        for (i = 0; i < rays; ++i) {
            const uint64_t at = (uint64_t)p * rays + i;
            const uint32_t want = expected_prim(mesh, sensor, i, &poses[p]);
            assert_int_equal(buf.res.prim_ids[at], want);
            assert_int_equal(buf.res.hits[at], want != RC_INVALID_ID);
            hits += buf.res.hits[at];
        }
    /* every origin is inside the closed sphere */
    assert_int_equal(hits, POSES * rays);
    rct_buffers_free(&buf);
}

static void test_large_map_turns(void **state)
{
    /* 1,000 + 3 rays: 62 full tiles of 16 and a partial one, so groups of
     * eight end short */
    const uint32_t rays = 1003u;
    float *dirs = (float *)malloc(sizeof(float) * 3u * rays), *orgs = (float *)malloc(sizeof(float) * 3u * rays);
    rcu_mesh m;
    uint32_t threads, i, k;
    (void)state;
    assert_non_null(dirs);
    assert_non_null(orgs);
    /* 2 x 560 x 280 = 313,600 triangles: above the threshold */
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 560, 280, &m), 0);
    for (i = 0; i < rays; ++i) {
        /* a sweep in scan order (coherent runs for packets) and random
         * origins within 5 m for OnDn */
        const double yaw = 6.283185307 * i / rays, pitch = 0.4 * sin(0.37 * i);
        dirs[3 * i] = (float)(cos(pitch) * cos(yaw));
        dirs[3 * i + 1] = (float)(cos(pitch) * sin(yaw));
        dirs[3 * i + 2] = (float)sin(pitch);
        for (k = 0; k < 3; ++k) orgs[3 * i + k] = (float)((uniform() - 0.5) * 10.0);
    }
    for (threads = 1; threads <= 2; ++threads) {
        rc_context *ctx = rct_context(RC_BACKEND_BVH, threads, 128);
        rc_scene *scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
        rc_rays_desc d = rc_rays_desc_default();
        rc_sensor *o1dn, *ondn = NULL;
        assert_true(ctx->large_mesh_bytes >= RC__LARGE_MESH_BYTES);
        ctx->large_mesh_bytes = RC__LARGE_MESH_BYTES;
        assert_int_equal(rc__mesh_is_large(&scene->geoms[0].mesh, ctx->large_mesh_bytes), 1);
        o1dn = rct_sensor_dirs(ctx, dirs, rays, RANGE_MIN, RANGE_MAX);
        d.common.range_min = RANGE_MIN;
        d.common.range_max = RANGE_MAX;
        d.directions = dirs;
        d.origins = orgs;
        d.ray_count = rays;
        RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &ondn));
        check_sensor(ctx, scene, o1dn, rays);
        check_sensor(ctx, scene, ondn, rays);
        rc_sensor_destroy(o1dn);
        rc_sensor_destroy(ondn);
        rc_context_destroy(ctx);
    }
    rcu_mesh_free(&m);
    free(dirs);
    free(orgs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_large_map_turns)};
    rcu_rng_seed(&rng, 0x2545F4914F6CDD1Dull);
    return cmocka_run_group_tests_name("large map", tests, NULL, NULL);
}
