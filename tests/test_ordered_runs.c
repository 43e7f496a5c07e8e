/* Ordered runs (core/work_order.h): on maps larger than the cache a call's
 * tiles are traced in the order of a key (the built-in backend's
 * rc__mesh_order_key, the Embree backend's occupancy grid), not scan order.
 * Checked here: the radix sort, both keys against brute-force searches, and
 * that an ordered call on either backend writes every attribute
 * bit for bit as a call in scan order does, on 1, 2 and 3 threads, for
 * packets and for OnDn runs, on one mesh and on a scene of several, with and without arena room for its
 * scratch. The context's thresholds are set by the test, whatever this CPU's
 * cache. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh/intersect.h"
#include "bvh/mesh.h"
#include "bvh/packet.h"
#include "core/context.h"
#include "core/work_order.h"
#if defined(RANGECAST_WITH_EMBREE)
#include "backend/embree_occupancy.h"
#endif
#include "poses.h"
#include "rc_test.h"
#include "scene/scene.h"

/* 60 VLP-16 poses (14,400 rays, TILES tiles each): every chunk holds at
 * least the minimum of tiles (16,384 of 16 rays, as many rays in tiles of
 * RC__PACKET_SIZE) on 1, 2 and 3 threads, so every call below is ordered */
#define TILES (14400u / RC__PACKET_SIZE)
#define POSES 60u

static rcu_rng rng;

static void test_radix_sort(void **state)
{
    const uint32_t n = 5000u;
    uint32_t *keys = malloc(n * sizeof *keys), *vals = malloc(n * sizeof *vals);
    uint32_t *tk = malloc(n * sizeof *tk), *tv = malloc(n * sizeof *tv), *seen = calloc(n, sizeof *seen);
    uint32_t bits, i;
    (void)state;
    assert_true(keys && vals && tk && tv && seen);
    /* an even and an odd number of passes, and keys with few distinct values
     * so that stability shows */
    for (bits = 7u; bits <= 32u; bits += 25u) {
        for (i = 0; i < n; ++i) {
            keys[i] = (uint32_t)(rcu_rng_uniform(&rng) * 4294967295.0) >> (32u - bits);
            if (i % 3u == 0) keys[i] &= 0x7u;
            vals[i] = i;
        }
        rc__radix_sort_pairs(keys, vals, tk, tv, n, bits);
        memset(seen, 0, n * sizeof *seen);
        for (i = 0; i < n; ++i) {
            assert_true(vals[i] < n);
            ++seen[vals[i]];
            if (i > 0) {
                assert_true(keys[i - 1u] <= keys[i]);
                if (keys[i - 1u] == keys[i]) assert_true(vals[i - 1u] < vals[i]);
            }
        }
        for (i = 0; i < n; ++i) assert_int_equal(seen[i], 1);
    }
    /* no element: nothing read or written */
    rc__radix_sort_pairs(keys, vals, tk, tv, 0u, 32u);
    free(keys), free(vals), free(tk), free(tv), free(seen);
}

/* Entry distance of the ray into box c of node n within [0, tmax], or -1
 * when it misses (a plain slab test in float, the conservative far bound of
 * the traversal's). */
static float box_entry(const rc__wnode *n, uint32_t c, const rc__ray *r, float tmax)
{
    float t0 = 0.0f, t1 = tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        float a = (n->box[2 * k][c] - r->org[k]) * r->inv_dir[k], b = (n->box[2 * k + 1][c] - r->org[k]) * r->inv_dir[k];
        if (a > b) {
            const float s = a;
            a = b, b = s;
        }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
    }
    return t0 <= t1 * RC__SLAB_FAR_SCALE ? t0 : -1.0f;
}

/* The smallest entry distance over every subtree the key can name (a child
 * at depth `depth`, or a leaf above it) whose box and whose ancestors' boxes
 * the ray meets. */
static float brute_first_entry(const rc__mesh *mesh, uint32_t node, uint32_t d, uint32_t depth, const rc__ray *r,
                               float tmax)
{
    const rc__wnode *n = &mesh->wide[node];
    float best = INFINITY;
    uint32_t c;
    for (c = 0; c < 4u; ++c) {
        float t;
        if (n->child[c] == RC__WIDE_EMPTY) continue;
        t = box_entry(n, c, r, tmax);
        if (t < 0.0f) continue;
        if (n->count[c] == 0 && d + 1u < depth) t = brute_first_entry(mesh, n->child[c], d + 1u, depth, r, tmax);
        if (t < best) best = t;
    }
    return best;
}

static void test_order_key(void **state)
{
    rcu_mesh sphere;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 64);
    rc_scene *scene;
    const rc__mesh *mesh;
    uint32_t depth, i, named = 0;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 120, 60, &sphere), 0);
    scene = rct_scene_mesh(ctx, &sphere, RC_MESH_REFERENCE);
    mesh = &scene->geoms[0].mesh;
    assert_non_null(mesh->wide);
    for (depth = 1u; depth <= 5u; depth += 2u)
        for (i = 0; i < 300u; ++i) {
            float org[3], dir[3], want, got;
            uint32_t key, k;
            rc__ray r;
            for (k = 0; k < 3; ++k) {
                org[k] = (float)((rcu_rng_uniform(&rng) - 0.5) * 20.0);
                dir[k] = (float)(rcu_rng_uniform(&rng) - 0.5);
            }
            rc__ray_prepare(&r, org, dir);
            key = rc__mesh_order_key(mesh, &r, 1e6f, depth);
            want = brute_first_entry(mesh, 0u, 0u, depth, &r, 1e6f);
            /* from inside the closed sphere every ray enters some subtree */
            assert_true(isfinite(want));
            assert_int_not_equal(key, UINT32_MAX);
            assert_true(key / 4u < mesh->wide_count);
            got = box_entry(&mesh->wide[key / 4u], key % 4u, &r, 1e6f);
            assert_true(got >= 0.0f);
            assert_true(got == want);
            named += key != 0u;
        }
    /* a ray that leaves before any box: no key */
    {
        const float org[3] = {100.0f, 0.0f, 0.0f}, dir[3] = {1.0f, 0.0f, 0.0f};
        rc__ray r;
        rc__ray_prepare(&r, org, dir);
        assert_int_equal(rc__mesh_order_key(mesh, &r, 1e6f, 3u), UINT32_MAX);
    }
    assert_true(named > 0u);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
}

#if defined(RANGECAST_WITH_EMBREE)
static uint32_t cell_distance(const rc__occupancy *g, uint32_t x, uint32_t y, uint32_t z)
{
    return g->dist[(z * RC__OCC_N + y) * RC__OCC_N + x];
}

static int occupied(const rc__occupancy *g, uint32_t x, uint32_t y, uint32_t z) { return cell_distance(g, x, y, z) == 0; }

/* The cell a key names (the Morton code's bits gathered back per axis). */
static void key_cell(uint32_t key, uint32_t c[3])
{
    uint32_t b, k;
    c[0] = c[1] = c[2] = 0;
    for (b = 0; b < 6u; ++b)
        for (k = 0; k < 3; ++k) c[k] |= ((key >> (3u * b + k)) & 1u) << b;
}

/* The cell of point p, or -1 outside the grid. */
static int cell_at(const rc__occupancy *g, const double p[3], uint32_t c[3])
{
    int k;
    for (k = 0; k < 3; ++k) {
        const double v = (p[k] - g->min[k]) * g->scale[k];
        if (!(v >= 0.0 && v < (double)RC__OCC_N)) return -1;
        c[k] = (uint32_t)v;
    }
    return 0;
}

/* The key is the first occupied cell along the ray: decoded, it is occupied,
 * the ray passes through it, and points sampled along the ray before it
 * (away from cell faces, where float and double may disagree) lie in no
 * occupied cell. */
static void test_occupancy_key(void **state)
{
    rcu_mesh sphere;
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 64);
    rc_scene *scene;
    rc__occupancy *g = malloc(sizeof *g);
    uint32_t i, found = 0;
    (void)state;
    assert_non_null(g);
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 120, 60, &sphere), 0);
    scene = rct_scene_mesh(ctx, &sphere, RC_MESH_REFERENCE);
    rc__occupancy_build(g, scene);
    assert_int_equal(g->triangles, sphere.triangle_count);
    /* the centre of the sphere is empty, its shell is not */
    assert_false(occupied(g, RC__OCC_N / 2u, RC__OCC_N / 2u, RC__OCC_N / 2u));
    assert_true(occupied(g, 0u, RC__OCC_N / 2u, RC__OCC_N / 2u));
    /* each cell's distance is its chessboard distance to the nearest
     * occupied cell, found here by looking at every cell */
    for (i = 0; i < 40u; ++i) {
        const uint32_t x = i == 0 ? RC__OCC_N / 2u : (uint32_t)(rcu_rng_uniform(&rng) * RC__OCC_N),
                       y = i == 0 ? RC__OCC_N / 2u : (uint32_t)(rcu_rng_uniform(&rng) * RC__OCC_N),
                       z = i == 0 ? RC__OCC_N / 2u : (uint32_t)(rcu_rng_uniform(&rng) * RC__OCC_N);
        uint32_t best = RC__OCC_FAR, qx, qy, qz;
        for (qz = 0; qz < RC__OCC_N; ++qz)
            for (qy = 0; qy < RC__OCC_N; ++qy)
                for (qx = 0; qx < RC__OCC_N; ++qx) {
                    const uint32_t dx = qx > x ? qx - x : x - qx, dy = qy > y ? qy - y : y - qy,
                                   dz = qz > z ? qz - z : z - qz;
                    uint32_t d = dx > dy ? dx : dy;
                    d = dz > d ? dz : d;
                    if (d < best && occupied(g, qx, qy, qz)) best = d;
                }
        assert_int_equal(cell_distance(g, x, y, z), best);
        /* the walk leaps from the centre: the sphere is 32 cells away, and its
         * nearest cell by the chessboard metric lies on a diagonal, 32 / sqrt(3) */
        if (i == 0) assert_true(best >= 16u);
    }
    for (i = 0; i < 500u; ++i) {
        float org[3], dir[3];
        uint32_t key, c[3], k;
        double enter = 0.0, leave = 1e30, t;
        for (k = 0; k < 3; ++k) {
            org[k] = (float)((rcu_rng_uniform(&rng) - 0.5) * 20.0);
            dir[k] = (float)(rcu_rng_uniform(&rng) - 0.5);
        }
        key = rc__occupancy_key(g, org, dir, 1e6f);
        assert_int_not_equal(key, UINT32_MAX); /* from inside the closed sphere */
        assert_true(key < (1u << RC__OCC_KEY_BITS));
        key_cell(key, c);
        assert_true(occupied(g, c[0], c[1], c[2]));
        for (k = 0; k < 3; ++k) {
            const double lo = g->min[k] + c[k] / (double)g->scale[k], hi = g->min[k] + (c[k] + 1u) / (double)g->scale[k];
            double a = (lo - org[k]) / dir[k], e = (hi - org[k]) / dir[k];
            if (a > e) {
                const double s = a;
                a = e, e = s;
            }
            enter = a > enter ? a : enter;
            leave = e < leave ? e : leave;
        }
        assert_true(enter <= leave * (1.0 + 1e-4) + 1e-4);
        for (t = 0.0; t < enter - 1e-3; t += 0.01) {
            const double p[3] = {org[0] + t * dir[0], org[1] + t * dir[1], org[2] + t * dir[2]};
            uint32_t q[3];
            int near_face = 0;
            for (k = 0; k < 3; ++k) {
                const double v = (p[k] - g->min[k]) * g->scale[k];
                near_face |= fabs(v - floor(v + 0.5)) < 1e-3;
            }
            if (near_face || cell_at(g, p, q) != 0) continue;
            assert_false(occupied(g, q[0], q[1], q[2]));
        }
        ++found;
    }
    assert_int_equal(found, 500u);
    /* a ray that leaves the grid without meeting it, one that starts beyond
     * tmax of it, and a NaN direction: no key */
    {
        const float away[3] = {100.0f, 0.0f, 0.0f}, out[3] = {1.0f, 0.0f, 0.0f}, in[3] = {-1.0f, 0.0f, 0.0f};
        const float nan_dir[3] = {NAN, 0.0f, 1.0f}, centre[3] = {0.0f, 0.0f, 0.0f};
        assert_int_equal(rc__occupancy_key(g, away, out, 1e6f), UINT32_MAX);
        assert_int_equal(rc__occupancy_key(g, away, in, 50.0f), UINT32_MAX);
        assert_int_not_equal(rc__occupancy_key(g, away, in, 1e6f), UINT32_MAX);
        assert_int_equal(rc__occupancy_key(g, centre, nan_dir, 1e6f), UINT32_MAX);
    }
    free(g);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
}

/* A flat map (one axis of the grid has no extent) and directions that are
 * zero, denormal or along an axis: the walk ends, and any key it gives names
 * an occupied cell. From above, a ray straight down meets the plane's cells. */
static void test_occupancy_key_flat(void **state)
{
    rcu_mesh plane;
    const float centre[3] = {0.0f, 0.0f, 0.0f};
    rc_context *ctx = rct_context(RC_BACKEND_BVH, 1, 16);
    rc_scene *scene;
    rc__occupancy *g = malloc(sizeof *g);
    const float tiny = 1e-40f; /* denormal: its reciprocal overflows */
    const float dirs[][3] = {{0.0f, 0.0f, -1.0f}, {1.0f, 0.0f, 0.0f},  {0.0f, 0.0f, 0.0f},  {tiny, 0.0f, -1.0f},
                             {tiny, tiny, -tiny}, {1.0f, 1.0f, -1.0f}, {-1.0f, tiny, 0.0f}, {0.3f, -0.2f, -tiny}};
    const float orgs[][3] = {{0.0f, 0.0f, 5.0f}, {-20.0f, 0.0f, 0.0f}, {3.0f, -2.0f, 0.0f}, {0.5f, 0.5f, 1.0f}};
    uint32_t i, j;
    (void)state;
    assert_non_null(g);
    assert_int_equal(rcu_mesh_plane(centre, 10.0f, &plane), 0);
    scene = rct_scene_mesh(ctx, &plane, RC_MESH_REFERENCE);
    rc__occupancy_build(g, scene);
    assert_true(g->scale[2] == 0.0f);
    for (i = 0; i < sizeof orgs / sizeof orgs[0]; ++i)
        for (j = 0; j < sizeof dirs / sizeof dirs[0]; ++j) {
            const uint32_t key = rc__occupancy_key(g, orgs[i], dirs[j], 1e6f);
            uint32_t c[3];
            if (key == UINT32_MAX) continue;
            key_cell(key, c);
            assert_true(occupied(g, c[0], c[1], c[2]));
        }
    assert_int_not_equal(rc__occupancy_key(g, orgs[0], dirs[0], 1e6f), UINT32_MAX);
    assert_int_not_equal(rc__occupancy_key(g, orgs[0], dirs[3], 1e6f), UINT32_MAX);
    free(g);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&plane);
}

#endif

/* A scene of the sphere and, with box set, a box inside it (geometry 0, so
 * that the key's mesh is not the first). With *src set instead (instanced),
 * the box is two turned instances of a scene of its own, made into *src:
 * on the built-in backend rays then go one by one through the top level,
 * and the sphere, the scene's own mesh, still gives the key (tree or grid). */
static rc_scene *make_scene(rc_context *ctx, const rcu_mesh *sphere, const rcu_mesh *box, rc_scene **src)
{
    const rcu_mesh *parts[2];
    rc_pose at[2];
    parts[0] = box ? box : sphere;
    parts[1] = sphere;
    if (!src) return rct_scene_meshes(ctx, parts, box ? 2u : 1u);
    *src = rct_scene_meshes(ctx, &box, 1u);
    at[0] = rct_pose_ypr(0.0f, 0.0f, 0.0f, 0.0, 0.0, 0.1);
    at[1] = rct_pose_ypr(-9.0f, 4.0f, 0.0f, 0.4, 0.0, 0.1);
    return rct_scene_instanced(ctx, &sphere, 1u, *src, at, 2u);
}

/* Simulates the sensor at POSES poses into buf; returns the arena bytes the
 * call borrowed at its peak. */
static uint64_t simulate_all(rc_context *ctx, const rc_scene *scene, const rc_sensor *vlp, const rc_pose *poses,
                             rct_buffers *buf)
{
    rc_memory_stats before, after;
    memset(&before, 0, sizeof before);
    memset(&after, 0, sizeof after);
    before.struct_size = after.struct_size = sizeof before;
    ctx->arena.peak = ctx->arena.used; /* so that what the call borrows shows */
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &before));
    rct_buffers_fill(buf, 0xA5);
    RCT_OK(ctx, rc_simulate(ctx, scene, vlp, poses, POSES, &buf->res));
    RCT_OK(ctx, rc_context_get_memory_stats(ctx, &after));
    assert_int_equal(after.arena_used, before.arena_used);
    return after.arena_peak - before.arena_peak;
}

/* An OnDn sensor of 14,400 rays (TILES runs, as many tiles as a VLP-16
 * has): origins within 1 m, directions sweeping like a scan, so that runs
 * are coherent as an Ouster unit's are. */
static float ondn_dirs[3u * 14400u], ondn_orgs[3u * 14400u];
static rc_sensor *make_sensor(rc_context *ctx, int ondn)
{
    rc_rays_desc d = rc_rays_desc_default();
    rc_sensor *s = NULL;
    if (!ondn) {
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &s));
        return s;
    }
    d.common.range_min = 0.1f;
    d.common.range_max = 100.0f;
    d.directions = ondn_dirs;
    d.origins = ondn_orgs;
    d.ray_count = 14400u;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s));
    return s;
}

/* Scan order on 1 thread is the reference; ordered calls on 1..3 threads
 * must match it and must have borrowed their scratch (the arena's peak rose
 * by at least 16 bytes a tile of a chunk; Embree's tiles of 8 or 4 rays are
 * more than the built-in backend's TILES a pose). The thresholds are set
 * before commit, where the Embree backend makes its occupancy grid. */
static void check_ordered(uint32_t backend, const rcu_mesh *sphere, const rcu_mesh *box, const rc_pose *poses,
                          int ondn, int instanced)
{
    const uint64_t n = (uint64_t)POSES * 14400u;
    rct_buffers want, got;
    uint32_t threads;
    rct_buffers_alloc(&want, n, RC_ATTR_ALL);
    rct_buffers_alloc(&got, n, RC_ATTR_ALL);
    for (threads = 1; threads <= 3; ++threads) {
        rc_context *ctx = rct_context(backend, threads, 64);
        rc_scene *scene, *src = NULL;
        rc_sensor *sensor;
        uint64_t borrowed;
        ctx->large_mesh_bytes = 0;
        scene = make_scene(ctx, sphere, box, instanced ? &src : NULL);
        sensor = make_sensor(ctx, ondn);
        if (threads == 1) {
            ctx->ordered_mesh_bytes = UINT64_MAX;
            assert_int_equal(simulate_all(ctx, scene, sensor, poses, &want), 0);
        }
        ctx->ordered_mesh_bytes = 0;
        /* ordered packets taking turns (1 thread), leaving their lone lanes
         * to a pool taking turns (3 threads: a map far past the caches) and
         * one tile at a time (2 threads: a map the cache nearly holds) */
        ctx->ordered_turns_bytes = threads == 2u ? UINT64_MAX : 0u;
        ctx->lone_pool_bytes = threads == 3u ? 0u : UINT64_MAX;
        borrowed = simulate_all(ctx, scene, sensor, poses, &got);
        assert_true(borrowed >= (uint64_t)threads * 16u * TILES * ((POSES + threads - 1u) / threads));
        rct_assert_same_results(&want, &got);
        rc_sensor_destroy(sensor);
        rc_scene_destroy(scene);
        if (src) rc_scene_destroy(src);
        rc_context_destroy(ctx);
    }
    rct_buffers_free(&want);
    rct_buffers_free(&got);
}

static void random_poses(rc_pose *poses)
{
    uint32_t p;
    for (p = 0; p < POSES; ++p) {
        const double yaw = 6.283185307 * rcu_rng_uniform(&rng), pitch = 1.2 * (rcu_rng_uniform(&rng) - 0.5);
        poses[p] = rct_pose_ypr((float)((rcu_rng_uniform(&rng) - 0.5) * 12.0), (float)((rcu_rng_uniform(&rng) - 0.5) * 12.0),
                                (float)((rcu_rng_uniform(&rng) - 0.5) * 8.0), yaw, pitch, 0.3 * pitch);
    }
}

static void test_ordered_matches_scan_order(void **state)
{
    const float lo[3] = {2.0f, -3.0f, -2.0f}, hi[3] = {6.0f, 3.0f, 2.0f};
    rc_pose poses[POSES];
    rcu_mesh sphere, box;
    uint32_t i, k, b;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &sphere), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &box), 0);
    random_poses(poses);
    for (i = 0; i < 14400u; ++i) {
        const double yaw = 6.283185307 * (i % 900u) / 900.0, pitch = 0.5 * ((double)(i / 900u) / 15.0 - 0.5);
        ondn_dirs[3u * i] = (float)(cos(pitch) * cos(yaw));
        ondn_dirs[3u * i + 1u] = (float)(cos(pitch) * sin(yaw));
        ondn_dirs[3u * i + 2u] = (float)sin(pitch);
        for (k = 0; k < 3u; ++k) ondn_orgs[3u * i + k] = (float)(rcu_rng_uniform(&rng) - 0.5);
    }
    for (b = 0; b < 2u; ++b) {
        const uint32_t backend = b ? RC_BACKEND_EMBREE : RC_BACKEND_BVH;
        if (!rct_backend_usable(backend)) continue;
        /* packets, then OnDn runs (single rays mesh by mesh on the built-in
         * backend) */
        check_ordered(backend, &sphere, NULL, poses, 0, 0);
        check_ordered(backend, &sphere, NULL, poses, 1, 0);
        /* two meshes: the built-in key comes from the larger, the box is
         * searched too */
        check_ordered(backend, &sphere, &box, poses, 0, 0);
        check_ordered(backend, &sphere, &box, poses, 1, 0);
        /* a map with instances */
        check_ordered(backend, &sphere, &box, poses, 0, 1);
    }
    rcu_mesh_free(&sphere);
    rcu_mesh_free(&box);
}

/* An arena with no room for the scratch: the call runs in scan order, with
 * the same results and nothing borrowed. */
static void check_without_room(uint32_t backend)
{
    const uint64_t n = (uint64_t)POSES * 14400u;
    rc_pose poses[POSES];
    rct_buffers want, got;
    rcu_mesh sphere;
    rc_context *ctx = rct_context(backend, 2, 64);
    rc_scene *scene;
    rc_sensor *vlp = NULL;
    void *hog;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &sphere), 0);
    random_poses(poses);
    ctx->large_mesh_bytes = 0;
    scene = make_scene(ctx, &sphere, NULL, NULL);
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &vlp));
    rct_buffers_alloc(&want, n, RC_ATTR_RANGES | RC_ATTR_PRIM_IDS);
    rct_buffers_alloc(&got, n, RC_ATTR_RANGES | RC_ATTR_PRIM_IDS);
    /* the arena's free space taken but for a few bytes */
    hog = rc__arena_alloc(&ctx->arena, rc__arena_largest_free(&ctx->arena) - 64u);
    assert_non_null(hog);
    ctx->ordered_mesh_bytes = 0;
    assert_int_equal(simulate_all(ctx, scene, vlp, poses, &got), 0);
    ctx->ordered_mesh_bytes = UINT64_MAX;
    assert_int_equal(simulate_all(ctx, scene, vlp, poses, &want), 0);
    assert_memory_equal(want.res.ranges, got.res.ranges, n * sizeof(float));
    assert_memory_equal(want.res.prim_ids, got.res.prim_ids, n * sizeof(uint32_t));
    rc__arena_free(&ctx->arena, hog);
    rct_buffers_free(&want);
    rct_buffers_free(&got);
    rc_sensor_destroy(vlp);
    rc_scene_destroy(scene);
    rc_context_destroy(ctx);
    rcu_mesh_free(&sphere);
}

static void test_ordered_without_room(void **state)
{
    (void)state;
    check_without_room(RC_BACKEND_BVH);
    if (rct_backend_usable(RC_BACKEND_EMBREE)) check_without_room(RC_BACKEND_EMBREE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_radix_sort),
        cmocka_unit_test(test_order_key),
#if defined(RANGECAST_WITH_EMBREE)
        cmocka_unit_test(test_occupancy_key),
        cmocka_unit_test(test_occupancy_key_flat),
#endif
        cmocka_unit_test(test_ordered_matches_scan_order),
        cmocka_unit_test(test_ordered_without_room),
    };
    rcu_rng_seed(&rng, 0x9E3779B97F4A7C15ull);
    return cmocka_run_group_tests_name("ordered runs", tests, NULL, NULL);
}
