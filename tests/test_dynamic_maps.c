/* Dynamic maps on every backend against the built-in one. A world scene
 * holds a map (a sphere), a door (a box whose vertices the robot moves in
 * place) and, in half the rounds, two instances of an object scene. Random
 * sequences of what a robot does between scans (move the door and
 * rc_scene_update_mesh, move an instance, update the object's mesh and commit
 * its scene again), mixed with refused steps (a NaN vertex, a NaN pose, and a
 * commit squeezed by the backend's memory budget: Embree's allocations, or
 * Vulkan's device memory, which an in-place commit needs only when its uploads
 * are staged), run on both contexts; after
 * every commit both scan the same poses and must agree: the same hit flags
 * (but for a ray or two grazing an edge), and where they name the same
 * triangle the same range within 1e-5 relative. Each step keeps whatever
 * the backend kept from the last commit (Embree's two-level build after an
 * update, Vulkan's rewrites in place), so this checks those paths against a
 * rebuild. Seeded: a failure replays. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#if defined(RANGECAST_WITH_EMBREE)
#include "backend/embree_internal.h"
#endif
#if defined(RANGECAST_WITH_VULKAN)
#include "backend/vulkan_internal.h"
#endif

#define POSES 2u
#define RAYS (16u * 900u)

static uint64_t rng;
static uint32_t refused; /* squeezed commits the backend refused */
static const char *const op_names[5] = {"door moved", "instance moved", "object changed", "refused steps",
                                        "door moved, commit squeezed"};
static double uniform(double lo, double hi)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return lo + (hi - lo) * (double)(rng >> 11) / 9007199254740992.0;
}

typedef struct side {
    rc_context *ctx;
    rc_scene *object, *world;
    rc_sensor *lidar;
    rct_buffers out;
} side;

typedef struct world_data {
    rcu_mesh map, door, object;
    float *door_v, *object_v; /* the arrays both sides reference and the steps move */
    int instanced;
} world_data;

/* A box's vertices scaled and moved (within the sphere, in the lidar's view). */
static void place_box(const rcu_mesh *box, float *v)
{
    const double s[3] = {uniform(0.3, 1.5), uniform(0.05, 1.0), uniform(0.5, 2.0)};
    const double at[3] = {uniform(2.0, 6.0), uniform(-4.0, 4.0), uniform(-0.5, 0.5)};
    uint32_t i, k;
    for (i = 0; i < box->vertex_count; ++i)
        for (k = 0; k < 3; ++k) v[3u * i + k] = (float)(box->vertices[3u * i + k] * s[k] + at[k]);
}

static rc_pose random_pose(void)
{
    return rct_pose_ypr((float)uniform(2.0, 6.0), (float)uniform(-4.0, 4.0), (float)uniform(-0.5, 0.5),
                        uniform(-3.0, 3.0), uniform(-0.5, 0.5), uniform(-0.5, 0.5));
}

static void side_open(side *s, uint32_t backend, const world_data *w)
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t id, i;
    s->ctx = rct_context(backend, 2, 0);
    sd.max_triangles = w->object.triangle_count;
    RCT_OK(s->ctx, rc_scene_create(s->ctx, &sd, &s->object));
    md.vertices = w->object_v;
    md.vertex_count = w->object.vertex_count;
    md.indices = w->object.indices;
    md.triangle_count = w->object.triangle_count;
    RCT_OK(s->ctx, rc_scene_add_mesh(s->object, &md, &id));
    RCT_OK(s->ctx, rc_scene_commit(s->object));
    sd.max_geometries = 2;
    sd.max_instances = w->instanced ? 2u : 0u;
    sd.max_triangles = w->map.triangle_count + w->door.triangle_count;
    RCT_OK(s->ctx, rc_scene_create(s->ctx, &sd, &s->world));
    md.vertices = w->map.vertices;
    md.vertex_count = w->map.vertex_count;
    md.indices = w->map.indices;
    md.triangle_count = w->map.triangle_count;
    RCT_OK(s->ctx, rc_scene_add_mesh(s->world, &md, &id));
    md.vertices = w->door_v;
    md.vertex_count = w->door.vertex_count;
    md.indices = w->door.indices;
    md.triangle_count = w->door.triangle_count;
    RCT_OK(s->ctx, rc_scene_add_mesh(s->world, &md, &id));
    for (i = 0; i < sd.max_instances; ++i) {
        rc_instance_desc in = rc_instance_desc_default();
        in.source = s->object;
        in.transform = rct_pose(-3.0f, 3.0f * (float)i - 1.5f, 0.0f);
        RCT_OK(s->ctx, rc_scene_add_instance(s->world, &in, &id));
    }
    RCT_OK(s->ctx, rc_scene_commit(s->world));
    RCT_OK(s->ctx, rc_sensor_create_preset(s->ctx, RC_PRESET_VELODYNE_VLP16, &s->lidar));
    rct_buffers_alloc(&s->out, (uint64_t)POSES * RAYS,
                      RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
}

static void side_close(side *s)
{
    rct_buffers_free(&s->out);
    rc_context_destroy(s->ctx);
}

/* Both sides scan the same poses; returns the rays that hit the door or an
 * instance (so a round can show it looked at what moved). */
static uint32_t compare_scans(side sides[2], unsigned long seed, uint32_t step, const char *op)
{
    const rc_pose poses[POSES] = {rct_pose_ypr(0.0f, 0.0f, 0.0f, uniform(-3.0, 3.0), 0.0, 0.0),
                                  rct_pose_ypr(1.0f, -1.0f, 0.3f, uniform(-3.0, 3.0), 0.1, 0.0)};
    const rc_results *a = &sides[1].out.res, *r = &sides[0].out.res;
    uint32_t b, k, flags = 0, moved = 0;
    for (b = 0; b < 2; ++b) RCT_OK(sides[b].ctx, rc_simulate(sides[b].ctx, sides[b].world, sides[b].lidar, poses,
                                                           POSES, &sides[b].out.res));
    for (k = 0; k < POSES * RAYS; ++k) {
        if (a->hits[k] != r->hits[k]) {
            ++flags;
            continue;
        }
        if (!a->hits[k]) continue;
        moved += r->geom_ids[k] == 1u || r->inst_ids[k] != RC_INVALID_ID;
        if (a->geom_ids[k] != r->geom_ids[k] || a->inst_ids[k] != r->inst_ids[k] || a->prim_ids[k] != r->prim_ids[k])
            continue; /* another triangle at a shared edge */
        if (!(fabsf(a->ranges[k] - r->ranges[k]) <= 1e-5f * r->ranges[k]))
            fail_msg("seed %lu step %u (%s) ray %u: range %.9g against the built-in %.9g", seed, step, op, k,
                     (double)a->ranges[k], (double)r->ranges[k]);
    }
    if (flags > 2u)
        fail_msg("seed %lu step %u (%s): %u hit flags differ from the built-in backend's", seed, step, op, flags);
    return moved;
}

/* Caps what the backend may hold outside the arena at what it holds now plus
 * extra bytes (Embree's allocations, Vulkan's device memory); extra 0 lifts
 * the cap. 0 when the backend has no cap to set. */
static int squeeze_budget(rc_context *ctx, uint32_t backend, uint64_t extra)
{
#if defined(RANGECAST_WITH_EMBREE)
    if (backend == RC_BACKEND_EMBREE) {
        rc__embree_options *opt = rc__embree_options_of(ctx);
        rc_memory_stats ms = rc_memory_stats_default();
        RCT_OK(ctx, rc_context_get_memory_stats(ctx, &ms));
        opt->budget_bytes = extra ? ms.backend_bytes + extra : 0u;
        return 1;
    }
#endif
#if defined(RANGECAST_WITH_VULKAN)
    if (backend == RC_BACKEND_VULKAN) {
        rc__vk_state *st = rc__vk(ctx);
        st->budget_bytes = extra ? st->device_bytes + extra : 0u;
        return 1;
    }
#endif
    (void)ctx;
    (void)backend;
    (void)extra;
    return 0;
}

/* Commits the world on both sides; a refused commit must leave nothing to
 * simulate. With squeeze, the backend's budget is capped for the commit
 * (Embree or Vulkan may then refuse it: out of memory, the scene
 * uncommitted) and lifted again, and the commit repeated. */
static void commit_both(side sides[2], uint32_t backend, int squeeze, unsigned long seed, uint32_t step)
{
    rc_status st;
    RCT_OK(sides[0].ctx, rc_scene_commit(sides[0].world));
    /* from 1 byte to 64 KiB of room, evenly in log scale */
    if (squeeze && squeeze_budget(sides[1].ctx, backend, (uint64_t)exp(uniform(0.0, 11.09)))) {
        st = rc_scene_commit(sides[1].world);
        (void)squeeze_budget(sides[1].ctx, backend, 0u);
        if (st == RC_OK) return;
        ++refused;
        if (st != RC_ERR_OUT_OF_MEMORY)
            fail_msg("seed %lu step %u: squeezed commit gave %s (%s)", seed, step, rc_status_string(st),
                     rc_context_last_error(sides[1].ctx));
        {
            const rc_pose at = rct_pose(0.0f, 0.0f, 0.0f);
            assert_int_equal(rc_simulate(sides[1].ctx, sides[1].world, sides[1].lidar, &at, 1, &sides[1].out.res),
                             RC_ERR_NOT_COMMITTED);
        }
    }
    st = rc_scene_commit(sides[1].world);
    if (st != RC_OK)
        fail_msg("seed %lu step %u: commit gave %s (%s)", seed, step, rc_status_string(st),
                 rc_context_last_error(sides[1].ctx));
}

static void one_round(uint32_t backend, unsigned long seed, uint32_t *moved)
{
    world_data w;
    side sides[2];
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {0.5f, 0.5f, 0.5f};
    uint32_t b, step, steps = rct_quick() ? 6u : 14u;
    rng = 0x9E3779B97F4A7C15ull * (seed + 1u);
    memset(&w, 0, sizeof w);
    w.instanced = (int)(seed & 1u);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 5000u, &w.map), 0);
    assert_int_equal(rcu_mesh_box(lo, hi, &w.door), 0);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(0.7f, 200u, &w.object), 0);
    w.door_v = (float *)malloc(sizeof(float) * 3u * w.door.vertex_count);
    w.object_v = (float *)malloc(sizeof(float) * 3u * w.object.vertex_count);
    assert_true(w.door_v != NULL && w.object_v != NULL);
    place_box(&w.door, w.door_v);
    memcpy(w.object_v, w.object.vertices, sizeof(float) * 3u * w.object.vertex_count);
    side_open(&sides[0], RC_BACKEND_BVH, &w);
    side_open(&sides[1], backend, &w);
    *moved += compare_scans(sides, seed, 0, "first commit");
    for (step = 1; step <= steps; ++step) {
        const uint32_t op = (uint32_t)uniform(0.0, 5.0);
        int squeeze = 0;
        if (op == 0) { /* the door moves */
            place_box(&w.door, w.door_v);
            for (b = 0; b < 2; ++b) RCT_OK(sides[b].ctx, rc_scene_update_mesh(sides[b].world, 1));
        } else if (op == 1 && w.instanced) { /* an instance moves */
            const rc_pose p = random_pose();
            const uint32_t i = (uint32_t)uniform(0.0, 2.0);
            for (b = 0; b < 2; ++b) RCT_OK(sides[b].ctx, rc_scene_set_instance_transform(sides[b].world, i, &p, NULL));
        } else if (op == 2) { /* the object changes shape: its scene is committed again */
            const float s = (float)uniform(0.5, 1.5);
            uint32_t i;
            for (i = 0; i < 3u * w.object.vertex_count; ++i) w.object_v[i] = w.object.vertices[i] * s;
            for (b = 0; b < 2; ++b) {
                RCT_OK(sides[b].ctx, rc_scene_update_mesh(sides[b].object, 0));
                RCT_OK(sides[b].ctx, rc_scene_commit(sides[b].object));
            }
        } else if (op == 3) { /* refused: a NaN vertex (put back at once), a NaN pose */
            const rc_pose bad = rct_pose(NAN, 0.0f, 0.0f);
            const float keep = w.door_v[4];
            w.door_v[4] = NAN;
            for (b = 0; b < 2; ++b)
                assert_int_equal(rc_scene_update_mesh(sides[b].world, 1), RC_ERR_NON_FINITE);
            w.door_v[4] = keep;
            if (w.instanced)
                for (b = 0; b < 2; ++b)
                    assert_int_not_equal(rc_scene_set_instance_transform(sides[b].world, 0, &bad, NULL), RC_OK);
            /* and a real update, so the commit below has work */
            for (b = 0; b < 2; ++b) RCT_OK(sides[b].ctx, rc_scene_update_mesh(sides[b].world, 1));
        } else { /* the commit after a door move squeezed by the backend's budget */
            place_box(&w.door, w.door_v);
            for (b = 0; b < 2; ++b) RCT_OK(sides[b].ctx, rc_scene_update_mesh(sides[b].world, 1));
            squeeze = 1;
        }
        commit_both(sides, backend, squeeze, seed, step);
        *moved += compare_scans(sides, seed, step, op_names[op]);
    }
    side_close(&sides[1]);
    side_close(&sides[0]);
    free(w.door_v);
    free(w.object_v);
    rcu_mesh_free(&w.map);
    rcu_mesh_free(&w.door);
    rcu_mesh_free(&w.object);
}

static void run_backend(uint32_t backend)
{
    unsigned long seed, rounds = rct_quick() ? 4u : 12u;
    uint32_t moved = 0;
    if (!rct_backend_usable(backend)) skip();
    refused = 0;
    for (seed = 0; seed < rounds; ++seed) one_round(backend, seed, &moved);
    print_message("%lu rounds on %s: %u ray hits on what moved, %u commits refused by the budget\n", rounds,
                  rc_backend_name(backend), moved, refused);
    assert_true(moved > 1000u); /* the scans looked at the door and the instances */
    if (backend == RC_BACKEND_EMBREE) assert_true(refused > 0u); /* and went through refused commits */
}

static void test_dynamic_embree(void **state)
{
    (void)state;
    run_backend(RC_BACKEND_EMBREE);
}

static void test_dynamic_vulkan(void **state)
{
    (void)state;
    run_backend(RC_BACKEND_VULKAN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dynamic_embree),
        cmocka_unit_test(test_dynamic_vulkan),
    };
    return cmocka_run_group_tests_name("dynamic maps against the built-in backend", tests, NULL, NULL);
}
