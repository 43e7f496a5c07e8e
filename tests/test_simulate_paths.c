/* The built-in backend's ways through rc_simulate against the plain
 * single-ray search of the whole scene (rc__scene_intersect): packets mesh by
 * mesh on a scene of several meshes (duplicate meshes make every hit on them
 * a tie the lower geometry id must win), packets and OnDn single rays taking
 * turns on a map above the large-mesh threshold, OnDn packets (origins a few
 * centimetres apart, like a multi-beam LiDAR's), and all again with two
 * instances searched after them, each on 1 and 2 threads, two poses, partial
 * tile groups. Every ray must report the same triangle, geometry and
 * instance, with or without prim ids asked for (without, the hits may
 * leave theirs pending, also across meshes and instances). On x86 and
 * AArch64 also the packets' refinement of a tile's hits in groups (two or
 * four at a time), against the one-hit function (the Embree backend's batches use it
 * too, with hits that carry no leaf slot). (test_packet.c and test_wide.c check the traversals bit for bit;
 * this checks the backend's grouping of tiles and meshes around them.) The
 * context's threshold is set by the test, whatever this CPU's cache. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "backend/backend.h"
#include "bvh/packet.h"
#include "core/context.h"
#include "poses.h"
#include "rc_test.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

#define RANGE_MIN 1e-4f
#define RANGE_MAX 200.0f
#define POSES 2u

static rcu_rng rng;
static double uniform(void) { return rcu_rng_uniform(&rng); }

/* What the plain search finds for ray i of the sensor at pose (identity
 * rotation: the world ray is the sensor ray moved by p): the hit's triangle
 * (returned) and geometry, or RC_INVALID_ID twice (also for a surface nearer
 * than range_min, which reads as no valid return). */
static uint32_t expected_prim(const rc_scene *scene, const rc_sensor *s, uint32_t i, const rc_pose *p, uint32_t *geom,
                              uint32_t *inst)
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
    h.prim = h.geom = h.inst = h.slot = RC_INVALID_ID;
    *geom = *inst = RC_INVALID_ID;
    if (!rc__scene_intersect(scene, &r, &h) || h.t < RANGE_MIN) return RC_INVALID_ID;
    *geom = h.geom;
    *inst = h.inst;
    return h.prim;
}

static void check_sensor(rc_context *ctx, rc_scene *scene, const rc_sensor *sensor, uint32_t rays)
{
    rc_pose poses[POSES];
    rct_buffers buf;
    uint32_t p, i, hits = 0, box_hits = 0, inst_hits = 0, small_hits = 0;
    poses[0] = rct_pose(0.0f, 0.0f, 0.0f);
    poses[1] = rct_pose(3.0f, -2.0f, 1.0f);
    rct_buffers_alloc(&buf, (uint64_t)POSES * rays,
                      RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, POSES, &buf.res));
    {
        /* without prim ids (the hits may keep theirs pending,
         * RC__PACKET_PRIMS_PENDING): the same hits, ids and ranges */
        rct_buffers ranges_only;
        rct_buffers_alloc(&ranges_only, (uint64_t)POSES * rays,
                          RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, POSES, &ranges_only.res));
        assert_memory_equal(ranges_only.res.ranges, buf.res.ranges, (size_t)POSES * rays * sizeof(float));
        assert_memory_equal(ranges_only.res.hits, buf.res.hits, (size_t)POSES * rays);
        assert_memory_equal(ranges_only.res.geom_ids, buf.res.geom_ids, (size_t)POSES * rays * sizeof(uint32_t));
        assert_memory_equal(ranges_only.res.inst_ids, buf.res.inst_ids, (size_t)POSES * rays * sizeof(uint32_t));
        rct_buffers_free(&ranges_only);
    }
    for (p = 0; p < POSES; ++p)
        for (i = 0; i < rays; ++i) {
            const uint64_t at = (uint64_t)p * rays + i;
            uint32_t want_geom, want_inst;
            const uint32_t want = expected_prim(scene, sensor, i, &poses[p], &want_geom, &want_inst);
            assert_int_equal(buf.res.prim_ids[at], want);
            assert_int_equal(buf.res.geom_ids[at], want_geom);
            assert_int_equal(buf.res.inst_ids[at], want_inst);
            inst_hits += want_inst != RC_INVALID_ID;
            assert_int_equal(buf.res.hits[at], want != RC_INVALID_ID);
            hits += buf.res.hits[at];
            box_hits += want_geom == 1u && want_inst == RC_INVALID_ID;
            small_hits += want_geom >= 3u && want_geom != RC_INVALID_ID && want_inst == RC_INVALID_ID;
        }
    /* every origin is inside the closed sphere (an OnDn origin may sit just
     * on a box); with the boxes in the scene, some rays end on them (on
     * geometry 1, never on its duplicate) */
    assert_true(hits + 2u >= POSES * rays);
    if (scene->geom_count > 1 && scene->inst_count == 0) assert_true(box_hits > 0);
    if (scene->inst_count > 0) assert_true(inst_hits > 0);
    if (scene->geom_count > 3) assert_true(small_hits > 0);
    rct_buffers_free(&buf);
}

#if defined(RC__HIT_DISTANCES_LANES)
/* The refinement of a tile's hits in groups (rc__scene_hit_distances_d)
 * against rc__scene_hit_distance_d one at a time: the same doubles, for
 * tiles of 1..RC__PACKET_SIZE rays with misses and instance hits among
 * them, under a turned pose, each ray rep times in a row (rep 4: groups of
 * four on one triangle, the quad's shared-normal path). With no_slots every
 * third ray's hit has no leaf slot, as Embree's hits come; without, every
 * hit keeps it, as the built-in traversal's do (a one-mesh scene's rows,
 * scene_trace.c). */
static void check_distances_rep(const rc_scene *scene, const rc_sensor *s, uint32_t rays, uint32_t rep, int no_slots)
{
    const rc_pose pose = rct_pose_ypr(0.5f, -1.0f, 0.3f, 0.9, -0.3, 0.2);
    rc__xformf world;
    rc__hit hits[RC__PACKET_SIZE];
    int found[RC__PACKET_SIZE];
    uint32_t idx[RC__PACKET_SIZE];
    double td[RC__PACKET_SIZE];
    uint32_t at = 0, n = 1, i, refined = 0, insts = 0;
    rc__sensor_world_xform(s, &pose, &world);
    while (at + n <= rays) {
        for (i = 0; i < n; ++i) {
            const float *d = s->directions + 3u * (at + i / rep);
            float dw[3];
            rc__ray r;
            idx[i] = at + i / rep;
            rc__rot_apply_f(world.r, d, dw);
            rc__ray_prepare(&r, world.t, dw);
            hits[i].t = RANGE_MAX;
            hits[i].prim = hits[i].geom = hits[i].inst = hits[i].slot = RC_INVALID_ID;
            found[i] = idx[i] % 7u != 3u && rc__scene_intersect(scene, &r, &hits[i]);
            /* as Embree's hits come: no leaf slot, the mesh's own triples */
            if (no_slots && idx[i] % 3u == 1u) hits[i].slot = RC_INVALID_ID;
            insts += found[i] && hits[i].inst != RC_INVALID_ID;
        }
        rc__scene_hit_distances_d(scene, hits, found, n, &world, s->directions, idx, td);
        for (i = 0; i < n; ++i) {
            const double want =
                found[i] ? rc__scene_hit_distance_d(scene, &hits[i], &world, s->directions + 3u * idx[i], NULL) : 0.0;
            assert_memory_equal(&td[i], &want, sizeof want);
            refined += found[i];
        }
        at += n;
        n = n % RC__PACKET_SIZE + 1u;
    }
    assert_true(refined > rays / 2u);
    if (scene->inst_count > 0) assert_true(insts > 0);
}

static void check_distances(const rc_scene *scene, const rc_sensor *s, uint32_t rays)
{
    uint32_t no_slots;
    for (no_slots = 0; no_slots < 2u; ++no_slots) {
        check_distances_rep(scene, s, rays, 1u, (int)no_slots);
        check_distances_rep(scene, s, rays, 4u, (int)no_slots);
    }
}
#endif

/* Small boxes that make a scene of more meshes than the packets take mesh
 * by mesh (RC__PACKET_MAX_MESHES): the top-level walk a packet */
#define SMALL_BOXES 37u
static rcu_mesh small_boxes[SMALL_BOXES];

/* A scene of the sphere and, with boxes 1, a box (geometry 1) and the same
 * box again (geometry 2), all referenced; with boxes 2 also two instances of
 * a scene of the box, one where the own box is (hits there tie between
 * geometry 1 and instance 0, which the instance wins: the tie rule orders
 * by instance id first, and own meshes have none) and one turned beside it
 * (*src holds that scene). Boxes 3 and 4: as 1 and 2 with the small boxes
 * after the three meshes (40 meshes). */
static rc_scene *make_scene(rc_context *ctx, const rcu_mesh *sphere, const rcu_mesh *box, int boxes, rc_scene **src)
{
    const rcu_mesh *parts[3 + SMALL_BOXES];
    const uint32_t count = boxes >= 3 ? 3u + SMALL_BOXES : boxes ? 3u : 1u;
    uint32_t j;
    rc_pose at[2];
    parts[0] = sphere;
    parts[1] = parts[2] = box;
    for (j = 0; j < SMALL_BOXES; ++j) parts[3 + j] = &small_boxes[j];
    *src = NULL;
    if (boxes != 2 && boxes != 4) return rct_scene_meshes(ctx, parts, count);
    *src = rct_scene_meshes(ctx, &box, 1u);
    at[0] = rct_pose(0.0f, 0.0f, 0.0f);
    at[1] = rct_pose_ypr(-9.0f, 3.0f, 0.0f, 0.7, 0.0, 0.2);
    return rct_scene_instanced(ctx, parts, count, *src, at, 2u);
}

/* orgs: origins up to 5 m apart (single rays); beams: up to 6 cm apart
 * (packets, whose box tests grow by their spread) */
static void run_paths(const rcu_mesh *sphere, const rcu_mesh *box, uint64_t large_bytes, int boxes,
                      const float *dirs, const float *orgs, const float *beams, uint32_t rays)
{
    uint32_t threads;
    for (threads = 1; threads <= 2; ++threads) {
        rc_context *ctx = rct_context(RC_BACKEND_BVH, threads, 128);
        rc_scene *scene, *src;
        rc_sensor *o1dn, *ondn, *ondn_beams;
        assert_true(ctx->large_mesh_bytes >= RC__LARGE_MESH_BYTES);
        ctx->large_mesh_bytes = large_bytes;
        /* a large mesh's packets take turns (1 thread) or leave their lone
         * lanes to a pool (2 threads) */
        ctx->lone_pool_bytes = threads == 2u ? large_bytes : UINT64_MAX;
        scene = make_scene(ctx, sphere, box, boxes, &src);
        assert_int_equal(rc__mesh_is_large(&scene->geoms[0].mesh, large_bytes), large_bytes == RC__LARGE_MESH_BYTES);
        o1dn = rct_sensor_dirs(ctx, dirs, rays, RANGE_MIN, RANGE_MAX);
        ondn = rct_sensor_rays(ctx, dirs, orgs, rays, RANGE_MIN, RANGE_MAX);
        ondn_beams = rct_sensor_rays(ctx, dirs, beams, rays, RANGE_MIN, RANGE_MAX);
        assert_true(ondn->origin_spread2 > RC__PACKET_ORIGIN_SPREAD * RC__PACKET_ORIGIN_SPREAD);
        assert_true(ondn_beams->origin_spread2 > 0.0f &&
                    ondn_beams->origin_spread2 <= RC__PACKET_ORIGIN_SPREAD * RC__PACKET_ORIGIN_SPREAD);
        check_sensor(ctx, scene, o1dn, rays);
#if defined(RC__HIT_DISTANCES_LANES)
        check_distances(scene, o1dn, rays);
#endif
        check_sensor(ctx, scene, ondn, rays);
        check_sensor(ctx, scene, ondn_beams, rays);
        rc_sensor_destroy(o1dn);
        rc_sensor_destroy(ondn);
        rc_sensor_destroy(ondn_beams);
        rc_scene_destroy(scene);
        if (src) rc_scene_destroy(src);
        rc_context_destroy(ctx);
    }
}

static void test_simulate_paths(void **state)
{
    /* 1,000 + 3 rays: 62 full tiles of 16 and a partial one, so groups of
     * eight end short */
    const uint32_t rays = 1003u;
    const float lo[3] = {2.0f, -3.0f, -2.0f}, hi[3] = {6.0f, 3.0f, 2.0f};
    float *dirs = (float *)malloc(sizeof(float) * 3u * rays), *orgs = (float *)malloc(sizeof(float) * 3u * rays);
    float *beams = (float *)malloc(sizeof(float) * 3u * rays);
    rcu_mesh sphere, box;
    uint32_t i, k;
    (void)state;
    assert_non_null(dirs);
    assert_non_null(orgs);
    assert_non_null(beams);
    /* 2 x 560 x 280 = 313,600 triangles: above the threshold's floor */
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 560, 280, &sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    for (i = 0; i < SMALL_BOXES; ++i) {
        /* on a ring 9 to 15 m out, some across the sweep's pitch */
        const double yaw = 6.283185307 * i / SMALL_BOXES, r = 9.0 + 6.0 * (i % 3u) / 2.0;
        float blo[3], bhi[3];
        blo[0] = (float)(r * cos(yaw));
        blo[1] = (float)(r * sin(yaw));
        blo[2] = -3.0f + 1.5f * (float)(i % 4u);
        for (k = 0; k < 3; ++k) bhi[k] = blo[k] + 0.6f + 0.3f * (float)((i + k) % 3u);
        assert_int_equal(rcu_mesh_box(blo, bhi, &small_boxes[i]), 0);
    }
    for (i = 0; i < rays; ++i) {
        /* a sweep in scan order (coherent runs for packets) and random
         * origins within 5 m for OnDn */
        const double yaw = 6.283185307 * i / rays, pitch = 0.4 * sin(0.37 * i);
        dirs[3 * i] = (float)(cos(pitch) * cos(yaw));
        dirs[3 * i + 1] = (float)(cos(pitch) * sin(yaw));
        dirs[3 * i + 2] = (float)sin(pitch);
        for (k = 0; k < 3; ++k) {
            orgs[3 * i + k] = (float)((uniform() - 0.5) * 10.0);
            beams[3 * i + k] = (float)((uniform() - 0.5) * 0.06);
        }
    }
    /* turns (the floor makes the sphere large), then plain packets */
    run_paths(&sphere, &box, RC__LARGE_MESH_BYTES, 0, dirs, orgs, beams, rays);
    run_paths(&sphere, &box, RC__LARGE_MESH_BYTES, 1, dirs, orgs, beams, rays);
    run_paths(&sphere, &box, UINT64_MAX, 1, dirs, orgs, beams, rays);
    /* instances after packets and runs, taking turns or not */
    run_paths(&sphere, &box, RC__LARGE_MESH_BYTES, 2, dirs, orgs, beams, rays);
    run_paths(&sphere, &box, UINT64_MAX, 2, dirs, orgs, beams, rays);
    /* many meshes: the top-level walk a packet (the sphere taking turns,
     * or not and with instances after) */
    run_paths(&sphere, &box, RC__LARGE_MESH_BYTES, 3, dirs, orgs, beams, rays);
    run_paths(&sphere, &box, UINT64_MAX, 4, dirs, orgs, beams, rays);
    for (i = 0; i < SMALL_BOXES; ++i) rcu_mesh_free(&small_boxes[i]);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
    free(dirs);
    free(orgs);
    free(beams);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_simulate_paths)};
    rcu_rng_seed(&rng, 0x2545F4914F6CDD1Dull);
    return cmocka_run_group_tests_name("simulate paths", tests, NULL, NULL);
}
