/* The packet traversal (SSE2 / NEON / scalar box tests) gives every ray
 * exactly the hit of the single-ray traversal: same t, triangle and
 * barycentrics, bit for bit, for coherent tiles, mixed-octant tiles, axis-
 * parallel rays, planar tiles (a direction component 0 in every lane) and
 * partial packets; so do packets taking turns
 * (rc__mesh_intersect_packets), whatever their number and mix, and packets
 * whose rays leave from origins of their own (OnDn beams: millimetres to a
 * metre apart). On x86-64 both builds of the traversal (baseline SSE2 and
 * AVX2, packet.c) are run, not only the one the CPU selects. */
#include <math.h>
#include <string.h>

#include "bvh/leaf4.h"
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

static void hit_init(rc__hit *h)
{
    h->t = 1000.0f;
    h->prim = h->geom = h->inst = h->slot = RC_INVALID_ID;
}

/* Hits left with a pending prim id (RC__PACKET_PRIMS_PENDING) */
static uint64_t pending_seen;

/* Each ray's packet hit against the single-ray traversal's. A prim id may be
 * pending only with RC__PACKET_PRIMS_PENDING; its slot then gives the same
 * triangle. */
static void expect_single(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, const rc__hit *hp, const int *fp,
                          uint32_t flags)
{
    uint32_t i;
    for (i = 0; i < n; ++i) {
        rc__hit hs, h = hp[i];
        int fs;
        hit_init(&hs);
        fs = rc__mesh_intersect(mesh, &rays[i], 0, RC_INVALID_ID, &hs);
        assert_int_equal(fp[i], fs);
        if (!fs) continue;
        if (h.prim == RC__PRIM_PENDING) {
            assert_true(flags & RC__PACKET_PRIMS_PENDING);
            ++pending_seen;
            rc__hit_settle(&h, mesh->bvh.refs);
        }
        assert_int_equal(h.prim, hs.prim);
        assert_memory_equal(&h.t, &hs.t, sizeof(float));
    }
}

/* The test map: a UV sphere with a box inside (its planes make axis-aligned
 * cases). */
static const float box_lo[3] = {-3.0f, -2.0f, -1.0f}, box_hi[3] = {2.0f, 4.0f, 1.5f};
typedef struct test_map {
    rcu_mesh m, box;
    rc_context *ctx;
    const rc__mesh *mesh;
} test_map;

/* 1: the box twice over in the mesh, so each hit on it ties with its copy
 * (the tie rule keeps the smaller prim id, wherever the traversal met it) */
static int map_box_twice;

static void map_open(test_map *t)
{
    rc_scene *scene;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &t->m), 0);
    assert_int_equal(rcu_mesh_box(box_lo, box_hi, &t->box), 0);
    assert_int_equal(rcu_mesh_append(&t->m, &t->box), 0);
    if (map_box_twice) {
        /* and a third time 0.2 mm further on each axis: faces a hair
         * apart, so a box entered just before a lane's nearest hit holds a
         * nearer one */
        static const float shift = 0.0002f;
        const float lo2[3] = {box_lo[0] + shift, box_lo[1] + shift, box_lo[2] + shift};
        const float hi2[3] = {box_hi[0] + shift, box_hi[1] + shift, box_hi[2] + shift};
        rcu_mesh near_box;
        assert_int_equal(rcu_mesh_append(&t->m, &t->box), 0);
        assert_int_equal(rcu_mesh_box(lo2, hi2, &near_box), 0);
        assert_int_equal(rcu_mesh_append(&t->m, &near_box), 0);
        rcu_mesh_free(&near_box);
    }
    t->ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    scene = rct_scene_mesh(t->ctx, &t->m, RC_MESH_REFERENCE);
    t->mesh = &scene->geoms[0].mesh;
}

static void map_close(test_map *t)
{
    rc_context_destroy(t->ctx);
    rcu_mesh_free(&t->m);
    rcu_mesh_free(&t->box);
}

/* Tile number `tile` of the test: nearby directions around a random centre;
 * some straddle axis planes, some are widely spread, some partial, some have
 * exact zero components or start on a box plane. With own_origins each ray
 * leaves from its own point near the tile's (2 mm, 3 cm or 0.8 m away at
 * most; rays 0, 2, 4 ... keep the tile's coordinate on a box plane).
 * Returns the ray count. */
static uint32_t make_tile(uint32_t tile, rc__ray rays[RC__PACKET_SIZE], rc__hit hits[RC__PACKET_SIZE],
                          int found[RC__PACKET_SIZE], int own_origins)
{
    static const double jitter[3] = {0.002, 0.03, 0.8};
    float org[3], dir[3], ray_org[3];
    double yaw = uniform() * 6.283185307, pitch = (uniform() - 0.5) * 3.0;
    double spread = (tile % 5 == 0) ? 0.5 : 0.02;
    uint32_t n = (tile % 7 == 0) ? 1u + (uint32_t)(uniform() * RC__PACKET_SIZE) % RC__PACKET_SIZE : RC__PACKET_SIZE;
    uint32_t i;
    for (i = 0; i < 3; ++i) org[i] = (float)((uniform() - 0.5) * 12.0);
    if (tile % 11 == 0) org[0] = box_lo[0];
    if (tile % 19 == 0 && (tile / 19) % 2 == 0) {
        const uint32_t k = (tile / 19) % 3;
        org[k] = (tile / 38) % 2 ? box_hi[k] : box_lo[k];
    }
    if (tile % 23 == 0) org[(tile / 23) % 3] = box_hi[(tile / 23) % 3];
    for (i = 0; i < n; ++i) {
        double y = yaw + (uniform() - 0.5) * spread, p = pitch + (uniform() - 0.5) * spread;
        dir[0] = (float)(cos(p) * cos(y));
        dir[1] = (float)(cos(p) * sin(y));
        dir[2] = (float)sin(p);
        if (tile % 13 == 0) dir[i % 3] = 0.0f;
        if (tile % 17 == 0) dir[(i + 1) % 3] = -0.0f;
        /* planar tiles (an upright 2-D scanner): one component 0 in every
         * lane, the same sign; every other one of them from a box plane
         * of that axis, where plane - origin is 0 and 0 * inf is NaN */
        if (tile % 19 == 0) dir[(tile / 19) % 3] = (tile / 57) % 2 ? -0.0f : 0.0f;
        /* and with a few lanes near but not at 0 (finite and infinite
         * reciprocals in one packet) */
        if (tile % 23 == 0) dir[(tile / 23) % 3] = i % 3 ? -0.0f : -1e-6f * (float)(i + 1);
        memcpy(ray_org, org, sizeof org);
        if (own_origins) {
            uint32_t k;
            for (k = 0; k < 3; ++k)
                if (i % 2 || tile % 11 != 0 || k != 0) ray_org[k] += (float)((uniform() - 0.5) * 2.0 * jitter[tile % 3]);
        }
        rc__ray_prepare(&rays[i], ray_org, dir);
        hit_init(&hits[i]);
        found[i] = 0;
    }
    return n;
}

typedef void (*packet_fn)(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom, uint32_t inst,
                          rc__hit *hits, int *found, uint32_t flags);
typedef void (*packets_fn)(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays, const uint32_t *n,
                           uint32_t geom, uint32_t inst, rc__hit *const *hits, int *const *found, uint32_t flags);
typedef void (*meshes_fn)(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count, const rc__ray *rays,
                          uint32_t n, uint32_t inst, rc__hit *hits, int *found, uint32_t flags);

/* A build of the traversal: the entry points, or one of the two x86-64
 * builds behind them. */
typedef struct packet_build {
    const char *name;
    packet_fn one;
    packets_fn many;
    meshes_fn meshes;
} packet_build;

static const packet_build selected = {"selected by the CPU", rc__mesh_intersect_packet, rc__mesh_intersect_packets,
                                      rc__mesh_intersect_packet_meshes};
#if defined(RC__PACKET_TWO_BUILDS)
static const packet_build baseline = {"baseline SSE2", rc__mesh_intersect_packet_sse2,
                                      rc__mesh_intersect_packets_sse2, rc__mesh_intersect_packet_meshes_sse2};
static const packet_build avx2 = {"AVX2", rc__mesh_intersect_packet_avx2, rc__mesh_intersect_packets_avx2,
                                  rc__mesh_intersect_packet_meshes_avx2};
#endif

static void packet_equals_single(const packet_build *b, uint32_t flags)
{
    test_map t;
    uint32_t tile, tiles = rct_quick() ? 300u : 3000u;
    const int own_origins = (flags & RC__PACKET_OWN_ORIGINS) != 0u;
    print_message("packets: %s build%s%s\n", b->name, own_origins ? ", own origins" : "",
                  flags & RC__PACKET_PRIMS_PENDING ? ", prim ids pending" : "");
    map_open(&t);
    for (tile = 0; tile < tiles; ++tile) {
        rc__ray rays[RC__PACKET_SIZE];
        rc__hit hits[RC__PACKET_SIZE];
        int found[RC__PACKET_SIZE];
        const uint32_t n = make_tile(tile, rays, hits, found, own_origins);
        b->one(t.mesh, rays, n, 0, RC_INVALID_ID, hits, found, flags);
        expect_single(t.mesh, rays, n, hits, found, flags);
    }
    map_close(&t);
}

/* Groups of 1..RC__PACKETS_IN_FLIGHT packets taking turns (each group mixes
 * the tile kinds above, so some members fall back to the plain path). */
static void packets_in_turns_equal_single(const packet_build *b, uint32_t flags)
{
    const int own_origins = (flags & RC__PACKET_OWN_ORIGINS) != 0u;
    test_map t;
    static rc__ray rays[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
    static rc__hit hits[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
    static int found[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
    uint32_t group, tile = 0, groups = rct_quick() ? 60u : 600u;
    print_message("packets in turns: %s build%s%s%s\n", b->name, own_origins ? ", own origins" : "",
                  flags & RC__PACKET_PRIMS_PENDING ? ", prim ids pending" : "",
                  flags & RC__PACKET_LONE_POOL ? ", lone lanes in a pool" : "");
    map_open(&t);
    for (group = 0; group < groups; ++group) {
        const uint32_t k = 1u + group % RC__PACKETS_IN_FLIGHT;
        const rc__ray *pr[RC__PACKETS_IN_FLIGHT];
        rc__hit *ph[RC__PACKETS_IN_FLIGHT];
        int *pf[RC__PACKETS_IN_FLIGHT];
        uint32_t n[RC__PACKETS_IN_FLIGHT], j;
        for (j = 0; j < k; ++j, ++tile) {
            n[j] = make_tile(tile, rays[j], hits[j], found[j], own_origins);
            pr[j] = rays[j];
            ph[j] = hits[j];
            pf[j] = found[j];
        }
        b->many(t.mesh, k, pr, n, 0, RC_INVALID_ID, ph, pf, flags);
        for (j = 0; j < k; ++j) expect_single(t.mesh, rays[j], n[j], hits[j], found[j], flags);
    }
    map_close(&t);
}

/* One packet through several meshes at once (rc__mesh_intersect_packet_meshes)
 * against the same packet mesh by mesh: the sphere, the box and a copy of
 * the box (each hit on the box ties with its copy), given in four orders, one
 * with the sphere's tree taken away (that mesh then goes ray by ray, and
 * the lanes are filled for the next one). Every field of every hit the same,
 * pending prims included. */
#if defined(RC__PACKET_MESHES)
static void packet_meshes_equal_meshwise(const packet_build *b, uint32_t flags)
{
    static const uint32_t orders[4][3] = {{0, 1, 2}, {2, 1, 0}, {1, 0, 2}, {0, 2, 1}};
    const int own_origins = (flags & RC__PACKET_OWN_ORIGINS) != 0u;
    rcu_mesh sphere, box;
    const rcu_mesh *ms[3];
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_scene *scene;
    rc__mesh bare;
    uint32_t tile, tiles = rct_quick() ? 200u : 2000u, ties = 0;
    print_message("packets through meshes: %s build%s%s\n", b->name, own_origins ? ", own origins" : "",
                  flags & RC__PACKET_PRIMS_PENDING ? ", prim ids pending" : "");
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &sphere), 0);
    assert_int_equal(rcu_mesh_box(box_lo, box_hi, &box), 0);
    ms[0] = &sphere;
    ms[1] = &box;
    ms[2] = &box;
    scene = rct_scene_meshes(ctx, ms, 3u);
    bare = scene->geoms[0].mesh;
    bare.wide = NULL;
    bare.wide_count = 0;
    for (tile = 0; tile < tiles; ++tile) {
        rc__ray rays[RC__PACKET_SIZE];
        rc__hit hits[RC__PACKET_SIZE], want[RC__PACKET_SIZE];
        int found[RC__PACKET_SIZE], want_found[RC__PACKET_SIZE];
        const uint32_t n = make_tile(tile, rays, hits, found, own_origins), *order = orders[tile % 4u];
        const rc__mesh *meshes[3];
        uint32_t geoms[3], i;
        for (i = 0; i < 3u; ++i) {
            geoms[i] = order[i];
            meshes[i] = tile % 8u == 3u && order[i] == 0u ? &bare : &scene->geoms[order[i]].mesh;
        }
        memcpy(want, hits, sizeof want);
        memcpy(want_found, found, sizeof want_found);
        b->meshes(meshes, geoms, 3u, rays, n, RC_INVALID_ID, hits, found, flags);
        for (i = 0; i < 3u; ++i) b->one(meshes[i], rays, n, geoms[i], RC_INVALID_ID, want, want_found, flags);
        for (i = 0; i < n; ++i) {
            assert_int_equal(found[i], want_found[i]);
            assert_memory_equal(&hits[i].t, &want[i].t, sizeof(float));
            assert_int_equal(hits[i].prim, want[i].prim);
            assert_int_equal(hits[i].geom, want[i].geom);
            assert_int_equal(hits[i].slot, want[i].slot);
            ties += found[i] && hits[i].geom == 1u;
        }
    }
    /* the box's hits all tie with its copy's, and the box keeps them */
    assert_true(ties > 0);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
}

#endif

/* A packet through a scene of 43 meshes (more than the packets take mesh
 * by mesh): the top-level walk, its interval box test and its batches of
 * RC__SCENE_PACKET_BATCH give each ray rc__scene_intersect_items's hit. The
 * small boxes share planes with the tiles' origins (make_tile) and the big
 * box has a copy (ties across the batches); some tiles leave the sphere and
 * the copy to the caller (skip), some start from nearer hits. */
/* A walk's hit (found) against rc__scene_intersect_items' (want_found): the
 * same t bit for bit, instance, geometry and prim (a pending prim settled
 * against its own mesh's refs, and only with the flag). Returns found. */
static int walk_hit_equal(const rc_scene *scene, const rc__hit *got, int found, const rc__hit *want, int want_found,
                          uint32_t flags)
{
    rc__hit h = *got;
    assert_int_equal(found, want_found);
    if (!found) return 0;
    assert_memory_equal(&h.t, &want->t, sizeof(float));
    assert_int_equal(h.inst, want->inst);
    assert_int_equal(h.geom, want->geom);
    if (h.prim == RC__PRIM_PENDING) {
        const rc_scene *owner = h.inst == RC_INVALID_ID ? scene : scene->insts[h.inst].source;
        assert_true(flags & RC__PACKET_PRIMS_PENDING);
        rc__hit_settle(&h, owner->geoms[h.geom].mesh.bvh.refs);
    }
    assert_int_equal(h.prim, want->prim);
    return 1;
}

static void scene_packet_equals_items(uint32_t flags)
{
    enum { SMALL = 40, MESHES = SMALL + 3 };
    const int own_origins = (flags & RC__PACKET_OWN_ORIGINS) != 0u;
    rcu_mesh sphere, box, small[SMALL];
    const rcu_mesh *ms[MESHES];
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_scene *scene;
    uint32_t tile, tiles = rct_quick() ? 200u : 2000u, j, met[MESHES] = {0}, geoms_met = 0;
    print_message("a packet through 43 meshes%s%s\n", own_origins ? ", own origins" : "",
                  flags & RC__PACKET_PRIMS_PENDING ? ", prim ids pending" : "");
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 60, 30, &sphere), 0);
    assert_int_equal(rcu_mesh_box(box_lo, box_hi, &box), 0);
    ms[0] = &sphere;
    ms[1] = &box;
    ms[2] = &box;
    for (j = 0; j < SMALL; ++j) {
        float lo[3], hi[3];
        uint32_t k;
        lo[0] = -9.0f + 4.0f * (float)(j % 5u);
        lo[1] = -9.0f + 5.0f * (float)((j / 5u) % 4u);
        lo[2] = -4.0f + 5.0f * (float)(j / 20u);
        for (k = 0; k < 3; ++k) hi[k] = lo[k] + 0.5f + 0.25f * (float)((j + k) % 4u);
        /* every third box on a plane of the big box's: the origins of
         * make_tile's planar and axis tiles */
        if (j % 3u == 0) {
            k = (j / 3u) % 3u;
            lo[k] = j % 2u ? box_lo[k] : box_hi[k];
            hi[k] = lo[k] + 0.75f;
        }
        assert_int_equal(rcu_mesh_box(lo, hi, &small[j]), 0);
        ms[3 + j] = &small[j];
    }
    scene = rct_scene_meshes(ctx, ms, MESHES);
    for (tile = 0; tile < tiles; ++tile) {
        rc__ray rays[RC__PACKET_SIZE];
        rc__hit hits[RC__PACKET_SIZE], want[RC__PACKET_SIZE];
        int found[RC__PACKET_SIZE], want_found[RC__PACKET_SIZE];
        const uint32_t n = make_tile(tile, rays, hits, found, own_origins), skip = tile % 3u == 1u ? 5u : 0u;
        uint32_t i;
        if (tile % 4u == 2u)
            for (i = 0; i < n; i += 2u) hits[i].t = 4.0f;
        memcpy(want, hits, sizeof want);
        memcpy(want_found, found, sizeof want_found);
        rc__scene_intersect_packet(scene, rays, n, skip, hits, found, flags);
        for (j = 0; j < 32u; ++j)
            if ((skip >> j) & 1u)
                rc__mesh_intersect_packet(&scene->geoms[j].mesh, rays, n, j, RC_INVALID_ID, hits, found, flags);
        for (i = 0; i < n; ++i) want_found[i] |= rc__scene_intersect_items(scene, &rays[i], &want[i], 0u);
        for (i = 0; i < n; ++i)
            if (walk_hit_equal(scene, &hits[i], found[i], &want[i], want_found[i], flags))
                geoms_met += met[hits[i].geom]++ == 0u;
    }
    /* many meshes were met (22 of 43 in the quick run's 200 tiles, 42 in
     * 2,000), and the box won every tie with its copy */
    assert_true(geoms_met >= (rct_quick() ? 15u : 30u));
    assert_int_equal(met[2], 0u);
    assert_true(met[1] > 0u);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
    for (j = 0; j < SMALL; ++j) rcu_mesh_free(&small[j]);
}

/* Instances take the packets too (rc__scene_intersect_packet_instances): the
 * same hits as rc__scene_intersect_items ray by ray over the instances, for
 * instances turned, scaled (uniformly, per axis, mirrored) and one an exact
 * copy of another (its ties lost to the lower instance id), a source of two
 * meshes, lanes that start from nearer hits, and every flag combination. */
static void instances_packet_equals_items(uint32_t flags)
{
    enum { INSTANCES = 12 };
    const int own_origins = (flags & RC__PACKET_OWN_ORIGINS) != 0u;
    const float lo[3] = {-1.0f, -0.8f, -0.6f}, hi[3] = {1.0f, 0.8f, 0.6f};
    rcu_mesh sphere, box, ball, ball2;
    const rcu_mesh *own[2], *parts[2];
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 0);
    rc_scene *src, *scene;
    rc_scene_desc sd = rc_scene_desc_default();
    uint32_t tile, tiles = rct_quick() ? 200u : 2000u, j, met[INSTANCES] = {0}, insts_met = 0;
    print_message("a packet through %u instances%s%s\n", (unsigned)INSTANCES, own_origins ? ", own origins" : "",
                  flags & RC__PACKET_PRIMS_PENDING ? ", prim ids pending" : "");
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 60, 30, &sphere), 0);
    assert_int_equal(rcu_mesh_box(box_lo, box_hi, &box), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &ball), 0);
    {
        const float at[3] = {1.6f, 0.0f, 0.3f};
        assert_int_equal(rcu_mesh_uv_sphere(0.7f, 12, 6, &ball2), 0);
        rcu_mesh_transform(&ball2, 0.0f, at);
        parts[0] = &ball;
        parts[1] = &ball2;
        src = rct_scene_meshes(ctx, parts, 2u);
    }
    own[0] = &sphere;
    own[1] = &box;
    sd.max_geometries = 2u;
    sd.max_triangles = sphere.triangle_count + box.triangle_count;
    sd.max_instances = INSTANCES;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    for (j = 0; j < 2u; ++j) {
        rc_mesh_desc md = rc_mesh_desc_default();
        uint32_t id;
        md.vertices = own[j]->vertices;
        md.vertex_count = own[j]->vertex_count;
        md.indices = own[j]->indices;
        md.triangle_count = own[j]->triangle_count;
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &id));
    }
    for (j = 0; j < INSTANCES; ++j) {
        rc_instance_desc in = rc_instance_desc_default();
        const uint32_t k = j == INSTANCES - 1u ? j - 1u : j; /* the last a copy of the one before */
        const double yaw = 0.7 * k, half = 0.5 * yaw;
        uint32_t id;
        in.source = src;
        in.transform = rc_pose_identity();
        in.transform.position[0] = -7.5f + 5.0f * (float)(k % 4u);
        in.transform.position[1] = -6.0f + 6.0f * (float)((k / 4u) % 3u);
        in.transform.position[2] = -3.0f + 2.5f * (float)(k % 3u);
        in.transform.orientation[2] = (float)sin(half);
        in.transform.orientation[3] = (float)cos(half);
        if (k % 4u == 1u) in.scale[0] = in.scale[1] = in.scale[2] = 1.5f;
        if (k % 4u == 2u) in.scale[0] = 1.0f, in.scale[1] = 2.0f, in.scale[2] = 0.5f;
        if (k % 4u == 3u) in.scale[0] = -1.0f, in.scale[1] = 1.0f, in.scale[2] = 1.0f;
        RCT_OK(ctx, rc_scene_add_instance(scene, &in, &id));
    }
    RCT_OK(ctx, rc_scene_commit(scene));
    for (tile = 0; tile < tiles; ++tile) {
        rc__ray rays[RC__PACKET_SIZE];
        rc__hit hits[RC__PACKET_SIZE], want[RC__PACKET_SIZE];
        int found[RC__PACKET_SIZE], want_found[RC__PACKET_SIZE];
        const uint32_t n = make_tile(tile, rays, hits, found, own_origins);
        uint32_t i;
        if (tile % 4u == 2u)
            for (i = 0; i < n; i += 2u) hits[i].t = 4.0f;
        memcpy(want, hits, sizeof want);
        memcpy(want_found, found, sizeof want_found);
        rc__scene_intersect_packet_instances(scene, rays, n, hits, found, flags);
        for (i = 0; i < n; ++i) want_found[i] |= rc__scene_intersect_items(scene, &rays[i], &want[i], scene->geom_count);
        for (i = 0; i < n; ++i)
            if (walk_hit_equal(scene, &hits[i], found[i], &want[i], want_found[i], flags))
                insts_met += met[hits[i].inst]++ == 0u;
    }
    /* most instances were met, and the copy lost every tie to its original */
    assert_true(insts_met >= (rct_quick() ? 5u : 8u));
    assert_int_equal(met[INSTANCES - 1u], 0u);
    assert_true(met[INSTANCES - 2u] > 0u);
    rc_scene_destroy(scene);
    rc_scene_destroy(src);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
    rcu_mesh_free(&ball);
    rcu_mesh_free(&ball2);
}

/* check under every flag combination (0, own origins, prim ids pending,
 * both) where the build has the top-level walk; -Os builds skip */
static void each_flag_walk(void (*check)(uint32_t), const char *without)
{
#if defined(RC__PACKET_MESHES)
    uint32_t flags;
    (void)without;
    for (flags = 0; flags < 4u; ++flags) check(flags);
#else
    (void)check;
    print_message("an -Os build: %s go ray by ray\n", without);
    skip();
#endif
}

static void test_instances_packet_equals_items(void **state)
{
    (void)state;
    each_flag_walk(instances_packet_equals_items, "instances");
}

static void test_scene_packet_equals_items(void **state)
{
    (void)state;
    each_flag_walk(scene_packet_equals_items, "scenes of many meshes");
}

static void test_packet_meshes_equal_meshwise(void **state)
{
    (void)state;
#if defined(RC__PACKET_MESHES)
    {
        uint32_t flags;
        /* 0, own origins, prim ids pending, both */
        for (flags = 0; flags < 4u; ++flags) packet_meshes_equal_meshwise(&selected, flags);
#if defined(RC__PACKET_TWO_BUILDS)
        packet_meshes_equal_meshwise(&baseline, 0);
        if (rc__leaf4_have_avx2()) packet_meshes_equal_meshwise(&avx2, RC__PACKET_PRIMS_PENDING);
#endif
    }
#else
    print_message("an -Os build: packets go mesh by mesh\n");
    skip();
#endif
}

static void test_packet_equals_single(void **state)
{
    (void)state;
    packet_equals_single(&selected, 0);
}

static void test_packets_in_turns_equal_single(void **state)
{
    (void)state;
    packets_in_turns_equal_single(&selected, 0);
    packets_in_turns_equal_single(&selected, RC__PACKET_LONE_POOL);
}

/* OnDn packets: each ray from its own origin */
static void test_own_origins_equal_single(void **state)
{
    (void)state;
    packet_equals_single(&selected, RC__PACKET_OWN_ORIGINS);
    packets_in_turns_equal_single(&selected, RC__PACKET_OWN_ORIGINS);
}

/* Prim ids left pending (a call that writes none): the same hits, and the
 * slot names the single-ray traversal's triangle; without the flag none is
 * left pending (expect_single) */
static void test_pending_prims_equal_single(void **state)
{
    (void)state;
    pending_seen = 0;
    packet_equals_single(&selected, RC__PACKET_PRIMS_PENDING);
    packets_in_turns_equal_single(&selected, RC__PACKET_PRIMS_PENDING | RC__PACKET_OWN_ORIGINS);
    assert_true(pending_seen > 0);
}

/* Ties and near ties within one mesh (the box, its copy, and a copy 0.2 mm
 * off): a box entered at or just before a lane's nearest t may hold the hit
 * that wins, so every traversal keeps the slack of the box test where it
 * drops entries (packets, lone lanes, lone lanes in a pool): cutting it to
 * 1 - 1e-4 fails here */
static void test_ties_equal_single(void **state)
{
    (void)state;
    map_box_twice = 1;
    packet_equals_single(&selected, 0);
    packets_in_turns_equal_single(&selected, 0);
    packets_in_turns_equal_single(&selected, RC__PACKET_OWN_ORIGINS | RC__PACKET_LONE_POOL);
}

/* The ties test's map back to one box, even when an assertion ended it
 * early (cmocka runs later tests after a failure) */
static int ties_teardown(void **state)
{
    (void)state;
    map_box_twice = 0;
    return 0;
}

/* A tie with a hit another mesh's search left pending: the key decides by
 * geometry (the pending hit's 0 before 1) without resolving the pending prim
 * against this mesh's refs, which its slot does not index (one entry here) */
static void test_pending_prim_from_another_mesh(void **state)
{
    static const uint32_t refs_of_geom1[1] = {7u};
    rc__hit h;
    (void)state;
    h.t = 2.0f;
    h.prim = RC__PRIM_PENDING;
    h.slot = 1000u;
    h.geom = 0u;
    h.inst = RC_INVALID_ID;
    assert_int_equal(rc__hit_offer_slot(&h, 2.0f, refs_of_geom1, 0u, 1u, RC_INVALID_ID), 0);
    assert_int_equal(h.prim, RC__PRIM_PENDING);
    assert_int_equal(h.slot, 1000u);
    /* the later geometry's nearer hit still wins */
    assert_int_equal(rc__hit_offer_slot(&h, 1.5f, refs_of_geom1, 0u, 1u, RC_INVALID_ID), 1);
    rc__hit_settle(&h, refs_of_geom1);
    assert_int_equal(h.prim, 7u);
    assert_int_equal(h.geom, 1u);
}

/* Both x86-64 builds, whichever the CPU selects (the AVX2 one where it has
 * AVX2). */
static void test_both_builds_equal_single(void **state)
{
    (void)state;
#if defined(RC__PACKET_TWO_BUILDS)
    uint32_t flags;
    /* 0, own origins, prim ids pending, both; each packets in turns and
     * lone lanes in a pool */
    for (flags = 0; flags < 4u; ++flags) {
        packet_equals_single(&baseline, flags);
        packets_in_turns_equal_single(&baseline, flags);
        packets_in_turns_equal_single(&baseline, flags | RC__PACKET_LONE_POOL);
    }
    if (!rc__leaf4_have_avx2()) {
        print_message("no AVX2 on this CPU: its build is not run\n");
        return;
    }
    for (flags = 0; flags < 4u; ++flags) {
        packet_equals_single(&avx2, flags);
        packets_in_turns_equal_single(&avx2, flags);
        packets_in_turns_equal_single(&avx2, flags | RC__PACKET_LONE_POOL);
    }
#else
    print_message("one build of the traversal on this target\n");
    skip();
#endif
}

/* Turns start above the threshold: RC__LARGE_MESH_BYTES, or an eighth of a
 * large last-level cache. */
static void test_large_mesh_threshold(void **state)
{
    rc__mesh m;
    (void)state;
    memset(&m, 0, sizeof m);
    m.stride = 3;
    m.triangle_count = 1000;
    m.vertex_count = 500;
    m.wide_count = 100;
    assert_int_equal(rc__mesh_is_large(&m, RC__LARGE_MESH_BYTES), 0);
    m.triangle_count = 10000000;
    m.vertex_count = 5000000;
    m.wide_count = 1000000;
    assert_int_equal(rc__mesh_is_large(&m, RC__LARGE_MESH_BYTES), 1);
    assert_int_equal(rc__mesh_is_large(&m, (uint64_t)1 << 30), 0);
    assert_true(rc__large_mesh_threshold(0) == RC__LARGE_MESH_BYTES);
    assert_true(rc__large_mesh_threshold(2u << 20) == RC__LARGE_MESH_BYTES);
    assert_true(rc__large_mesh_threshold((uint64_t)260 << 20) == (uint64_t)260 << 17);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_packet_equals_single),
                                       cmocka_unit_test(test_packets_in_turns_equal_single),
                                       cmocka_unit_test(test_own_origins_equal_single),
                                       cmocka_unit_test(test_pending_prims_equal_single),
                                       cmocka_unit_test(test_pending_prim_from_another_mesh),
                                       cmocka_unit_test_teardown(test_ties_equal_single, ties_teardown),
                                       cmocka_unit_test(test_both_builds_equal_single),
                                       cmocka_unit_test(test_packet_meshes_equal_meshwise),
                                       cmocka_unit_test(test_scene_packet_equals_items),
                                       cmocka_unit_test(test_instances_packet_equals_items),
                                       cmocka_unit_test(test_large_mesh_threshold)};
    return cmocka_run_group_tests_name("packet traversal", tests, NULL, NULL);
}
