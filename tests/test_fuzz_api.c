/* Random values in every numeric field of every descriptor, pose and result
 * request (NaN, infinities, zero, negative, huge counts, stray bits in flags
 * and reserved words), with pointers that are valid for the counts given:
 * the library must answer each call with a known status, never crash or
 * overrun (the suite runs under ASan+UBSan and valgrind), and what it
 * returns RC_OK for must hold up: simulate then writes only hits of 0 or 1
 * and ranges that are +inf, -inf or inside the sensor's range. Baked maps
 * (now and then damaged, or loaded from too few bytes) and Ouster sensors
 * (rc_ouster_rays) take part. Seeded, so a failure replays. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#define MAX_VERTS 64u
#define MAX_TRIS 96u
#define MAX_RAYS 256u
#define MAX_POSES 4u
#define MAX_STRIDE 8u /* floats */

static uint64_t rng_state;
/* how far rounds got: contexts, committed meshes, committed worlds, sensors, simulates */
static unsigned long reached[5];

static uint32_t next_u32(void)
{
    /* xorshift64*: enough to spread values, fixed per seed */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (uint32_t)((rng_state * 0x2545F4914F6CDD1Dull) >> 32);
}

static uint32_t below(uint32_t n) { return n ? next_u32() % n : 0u; }

/* Every draw is its own statement (or behind ?:): C leaves the order of two
 * calls in one expression to the compiler, and a seed must replay the same
 * round in every build. */

/* 1 for about one field in 40: with some twenty fields an object, most
 * calls see one hostile value or none, so rounds get far enough to use what
 * they made. */
static int hostile(void) { return below(40) == 0; }

static float uniform(float lo, float hi) { return lo + (hi - lo) * (float)(next_u32() >> 8) * (1.0f / 16777216.0f); }

/* In [lo, hi], or now and then NaN, an infinity, 0, -1, huge or tiny. */
static float any_float(float lo, float hi)
{
    static const float odd[7] = {0.0f, -1.0f, 3.0e38f, 1.0e-30f, -3.0e38f, 0.0f, 0.0f};
    if (!hostile()) return uniform(lo, hi);
    switch (below(3)) {
    case 0: return NAN;
    case 1: return below(2) ? INFINITY : -INFINITY;
    default: return odd[below(7)];
    }
}

/* 1 .. sensible, or now and then 0, 2^32-1 or a power of two. */
static uint32_t any_count(uint32_t sensible)
{
    if (!hostile()) return 1u + below(sensible);
    switch (below(3)) {
    case 0: return 0u;
    case 1: return 0xFFFFFFFFu;
    default: return 1u << below(32);
    }
}

/* 0, or now and then stray bits (flags, reserved words). */
static uint32_t any_word(void) { return hostile() ? next_u32() | 1u : 0u; }

static void any_pose(rc_pose *p, float extent)
{
    uint32_t k;
    for (k = 0; k < 3; ++k) p->position[k] = any_float(-extent, extent);
    for (k = 0; k < 4; ++k) p->orientation[k] = uniform(-0.5f, 0.5f);
    if (!hostile()) { /* usually a unit quaternion */
        float n = 0.0f;
        for (k = 0; k < 4; ++k) n += p->orientation[k] * p->orientation[k];
        n = sqrtf(n);
        for (k = 0; k < 4; ++k) p->orientation[k] = n > 0.0f ? p->orientation[k] / n : (k == 3);
    }
    if (hostile()) {
        const uint32_t k2 = below(4);
        p->orientation[k2] = any_float(-2.0f, 2.0f);
    }
}

static void fill_common(rc_sensor_common *c)
{
    c->range_min = hostile() ? any_float(-1.0f, 50.0f) : (float)below(3) * 0.1f;
    c->range_max = hostile() ? any_float(-1.0f, 200.0f) : 10.0f + (float)below(100);
    any_pose(&c->sensor_to_base, 1.0f);
}

static int known_status(rc_status st) { return st <= RC_OK && st >= RC_ERR_IO; }

#define CHECK_STATUS(call)                                                                  \
    do {                                                                                    \
        rc_status st_ = (call);                                                             \
        if (!known_status(st_)) fail_msg("%s returned %d (seed %lu)", #call, (int)st_, seed); \
    } while (0)

/* A sensor from random fields of a random model, or NULL when refused. */
static rc_sensor *any_sensor(rc_context *ctx, const float *dirs, const float *orgs, unsigned long seed)
{
    rc_sensor *s = NULL;
    rc_status st;
    switch (below(6)) {
    case 0: {
        rc_spherical_desc d = rc_spherical_desc_default();
        fill_common(&d.common);
        d.theta.min = any_float(-4.0f, 4.0f);
        d.theta.increment = any_float(-0.1f, 0.1f);
        d.theta.count = any_count(40);
        d.phi.min = any_float(-2.0f, 2.0f);
        d.phi.increment = any_float(-0.1f, 0.1f);
        d.phi.count = any_count(6);
        d.reserved[7] = any_word();
        st = rc_sensor_create_spherical(ctx, &d, &s);
        break;
    }
    case 1: {
        rc_pinhole_desc d = rc_pinhole_desc_default();
        fill_common(&d.common);
        d.frame = hostile() ? next_u32() : below(2);
        d.width = any_count(16);
        d.height = any_count(12);
        d.fx = any_float(-10.0f, 50.0f);
        d.fy = any_float(-10.0f, 50.0f);
        d.cx = any_float(-5.0f, 20.0f);
        d.cy = any_float(-5.0f, 20.0f);
        st = rc_sensor_create_pinhole(ctx, &d, &s);
        break;
    }
    case 2: {
        rc_cylindrical_desc d = rc_cylindrical_desc_default();
        fill_common(&d.common);
        d.theta.min = any_float(-4.0f, 4.0f);
        d.theta.increment = any_float(-0.1f, 0.1f);
        d.theta.count = any_count(30);
        d.height = any_count(8);
        d.fy = any_float(-10.0f, 20.0f);
        d.cy = any_float(-5.0f, 10.0f);
        st = rc_sensor_create_cylindrical(ctx, &d, &s);
        break;
    }
    case 4: {
        /* an Ouster unit: counts stay within these arrays unless they are
         * ones rc_ouster_rays must refuse (0, or past 2^24 rays) */
        double alt[4], azi[4];
        float o[3 * 32], dd[3 * 32];
        rc_ouster_desc od = rc_ouster_desc_default();
        rc_rays_desc d;
        uint32_t k;
        od.beams = hostile() ? (below(2) ? 0u : 0xFFFFFFFFu) : 1u + below(4);
        od.columns = hostile() ? (below(2) ? 0u : 0x40000000u) : 1u + below(8);
        for (k = 0; k < 4; ++k) {
            alt[k] = any_float(-45.0f, 45.0f);
            azi[k] = any_float(-5.0f, 5.0f);
        }
        od.altitudes_deg = hostile() ? NULL : alt;
        od.azimuths_deg = azi;
        od.beam_to_lidar[3] = any_float(0.0f, 30.0f);
        od.lidar_to_sensor[below(16)] += hostile() ? any_float(-1.0f, 1.0f) : 0.0f;
        od.reserved[7] = any_word();
        st = rc_ouster_rays(&od, &d, o, dd, NULL);
        if (!known_status(st)) fail_msg("rc_ouster_rays returned %d (seed %lu)", (int)st, seed);
        if (st == RC_OK) {
            fill_common(&d.common);
            st = rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s);
        }
        break;
    }
    case 3:
    default: {
        rc_rays_desc d = rc_rays_desc_default();
        const uint32_t model = below(2) ? RC_SENSOR_O1DN : RC_SENSOR_ONDN;
        fill_common(&d.common);
        d.directions = hostile() ? NULL : dirs;
        d.origins = model == RC_SENSOR_ONDN && !hostile() ? orgs : NULL;
        d.ray_count = hostile() ? 0u : 1u + below(MAX_RAYS); /* never more than the arrays hold */
        d.width = hostile() ? any_count(16) : 0u;
        d.height = hostile() ? any_count(16) : 0u;
        st = rc_sensor_create_rays(ctx, hostile() ? next_u32() : model, &d, &s);
        break;
    }
    }
    if (!known_status(st)) fail_msg("sensor create returned %d (seed %lu)", (int)st, seed);
    if (st != RC_OK) return NULL;
    if (below(3) == 0) {
        rc_noise_desc nd = rc_noise_desc_default();
        nd.mean = any_float(-0.1f, 0.1f);
        nd.sigma = any_float(0.0f, 0.2f);
        nd.sigma_exponent = any_float(0.0f, 2.0f);
        nd.dropout = any_float(0.0f, 1.0f);
        nd.seed = next_u32();
        CHECK_STATUS(rc_sensor_set_noise(s, &nd));
    }
    return s;
}

static void one_round(unsigned long seed, uint32_t backend)
{
    static float verts[MAX_VERTS * MAX_STRIDE];
    static uint32_t tris[MAX_TRIS * 3];
    static float dirs[MAX_RAYS * 3], orgs[MAX_RAYS * 3];
    static uint8_t hits[MAX_POSES * 4096];
    static float ranges[MAX_POSES * 4096], points[MAX_POSES * 4096 * 3], normals[MAX_POSES * 4096 * 3];
    static uint32_t ids[3][MAX_POSES * 4096];
    rc_context_desc cd = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_scene *mesh_scene = NULL, *world = NULL, *baked = NULL;
    unsigned char *blob = NULL;
    rc_sensor *sensor = NULL;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_pose poses[MAX_POSES];
    rc_results res = rc_results_default();
    rc_sensor_info info = rc_sensor_info_default();
    uint32_t i, geom = 0, inst = 0, n_poses, nv, nt, stride;
    rc_status st;

    rng_state = 0x9E3779B97F4A7C15ull * (seed + 1u);
    /* never Vulkan at random: its driver is slow to start, and the valgrind
     * run leaves it out */
    cd.backend = hostile() ? (uint32_t[]){RC_BACKEND_AUTO, RC_BACKEND_BVH, 4u, 77u}[below(4)] : backend;
    cd.thread_count = hostile() ? (below(2) ? 0u : RC_MAX_THREADS + 1u + below(100)) : 1u + below(3);
    cd.flags = any_word();
    cd.memory_size = hostile() ? (size_t)below(1u << 20) : (size_t)(8u << 20);
    cd.reserved[6] = any_word();
    st = rc_context_create(&cd, &ctx);
    if (!known_status(st)) fail_msg("rc_context_create returned %d (seed %lu)", (int)st, seed);
    if (st != RC_OK) return;
    reached[0]++;

    /* a mesh: random vertices (some non-finite), indices (some out of range) */
    stride = 3u + below(MAX_STRIDE - 2u);
    nv = 1u + below(MAX_VERTS);
    nt = 1u + below(MAX_TRIS);
    /* a few collapsed (zero-area) triangles from vertices at the same place */
    for (i = 0; i < nv * stride; ++i) verts[i] = below(16) ? uniform(-5.0f, 5.0f) : 0.0f;
    if (hostile()) {
        const uint32_t at = below(nv * stride);
        verts[at] = any_float(-5.0f, 5.0f);
    }
    if (hostile()) verts[below(nv * stride)] = NAN;
    for (i = 0; i < nt * 3u; ++i) tris[i] = below(nv);
    if (hostile()) {
        const uint32_t at = below(nt * 3u);
        tris[at] = next_u32();
    }
    sd.max_geometries = hostile() ? next_u32() : 1u + below(2);
    sd.max_instances = hostile() ? any_count(3) : 0u;
    if (hostile()) {
        const uint64_t big = next_u32();
        sd.max_triangles = big << below(32);
    } else {
        sd.max_triangles = nt + below(10);
    }
    sd.max_vertices = hostile() ? (uint64_t)any_count(100) : nv;
    sd.max_copied_triangles = hostile() ? (uint64_t)any_count(100) : nt;
    if (hostile()) sd.origin[2] = (double)any_float(-1e6f, 1e6f);
    sd.build_quality = hostile() ? next_u32() : below(4);
    sd.flags = any_word();
    CHECK_STATUS(rc_scene_create(ctx, &sd, &mesh_scene));
    if (mesh_scene) {
        md.flags = hostile() ? next_u32() : below(2);
        md.vertices = hostile() ? NULL : verts;
        md.vertex_count = hostile() ? 0u : nv;
        /* 0 means 12 bytes, within the array for any stride here */
        md.vertex_stride = hostile() ? (below(2) ? 4u * stride + 2u : 0u) : 4u * stride;
        md.indices = hostile() ? NULL : tris;
        md.triangle_count = hostile() ? 0u : nt;
        CHECK_STATUS(rc_scene_add_mesh(mesh_scene, &md, &geom));
        st = rc_scene_commit(mesh_scene);
        if (!known_status(st)) fail_msg("rc_scene_commit returned %d (seed %lu)", (int)st, seed);
        reached[1] += st == RC_OK;
    }
    /* sometimes the mesh baked and loaded back, now and then with a byte
     * changed and the checksum check skipped */
    if (mesh_scene && below(4) == 0) {
        size_t need = 0, wrote = 0;
        st = rc_scene_bake(mesh_scene, NULL, 0, &need);
        if (!known_status(st)) fail_msg("rc_scene_bake returned %d (seed %lu)", (int)st, seed);
        if (st == RC_OK) {
            blob = (unsigned char *)rct_alloc16(need);
            /* defined garbage for a bake refused below (capacity one short) to leave */
            memset(blob, 0xA5, need);
            CHECK_STATUS(rc_scene_bake(mesh_scene, blob, hostile() ? need - 1u : need, &wrote));
            if (hostile()) blob[below((uint32_t)need)] ^= (unsigned char)(1u + below(255));
            st = rc_scene_load_baked(ctx, blob, hostile() ? need - 64u : need,
                                     hostile() ? next_u32() : below(2) * RC_BAKED_SKIP_CHECKSUM, &baked);
            if (!known_status(st)) fail_msg("rc_scene_load_baked returned %d (seed %lu)", (int)st, seed);
        }
    }
    /* sometimes a world of instances of it */
    if (mesh_scene && below(3) == 0) {
        rc_scene_desc wd = rc_scene_desc_default();
        wd.max_geometries = 0;
        wd.max_instances = 1u + below(3);
        wd.max_triangles = 0;
        CHECK_STATUS(rc_scene_create(ctx, &wd, &world));
        if (world) {
            for (i = 0; i < wd.max_instances + below(2); ++i) {
                rc_instance_desc id = rc_instance_desc_default();
                id.source = hostile() ? NULL : mesh_scene;
                any_pose(&id.transform, 5.0f);
                id.scale[0] = any_float(0.1f, 3.0f);
                if (hostile()) id.scale[0] = -id.scale[0];
                id.scale[1] = below(2) ? id.scale[0] : any_float(0.1f, 3.0f);
                id.scale[2] = below(2) ? id.scale[0] : any_float(0.1f, 3.0f);
                if (getenv("RC_FUZZ_TRACE"))
                    fprintf(stderr, "  instance at %g %g %g, %g %g %g %g, scale %g %g %g\n",
                            (double)id.transform.position[0], (double)id.transform.position[1],
                            (double)id.transform.position[2], (double)id.transform.orientation[0],
                            (double)id.transform.orientation[1], (double)id.transform.orientation[2],
                            (double)id.transform.orientation[3], (double)id.scale[0], (double)id.scale[1],
                            (double)id.scale[2]);
                CHECK_STATUS(rc_scene_add_instance(world, &id, &inst));
            }
            st = rc_scene_commit(world);
            if (!known_status(st)) fail_msg("rc_scene_commit returned %d (seed %lu)", (int)st, seed);
            reached[2] += st == RC_OK;
        }
    }

    for (i = 0; i < MAX_RAYS * 3u; ++i) {
        dirs[i] = any_float(-1.0f, 1.0f);
        orgs[i] = any_float(-2.0f, 2.0f);
    }
    sensor = any_sensor(ctx, dirs, orgs, seed);
    reached[3] += sensor != NULL;

    if (sensor) {
        const rc_scene *target = world && below(2) ? world : baked && below(2) ? baked : mesh_scene;
        RCT_OK(ctx, rc_sensor_get_info(sensor, &info));
        n_poses = 1u + below(MAX_POSES);
        for (i = 0; i < n_poses; ++i) any_pose(&poses[i], 3.0f);
        res.attributes = hostile() ? next_u32() : 1u + below(RC_ATTR_ALL);
        res.capacity = (uint64_t)n_poses * info.rays_per_scan;
        if (hostile()) res.capacity = below(2) ? res.capacity - 1u : 0u;
        if (res.capacity > MAX_POSES * 4096u || (uint64_t)n_poses * info.rays_per_scan > MAX_POSES * 4096u) {
            res.capacity = MAX_POSES * 4096u; /* a sensor too large for the buffers: refused below */
        }
        res.hits = hostile() ? NULL : hits;
        res.ranges = hostile() ? NULL : ranges;
        res.points = points;
        res.normals = normals;
        res.prim_ids = ids[0];
        res.geom_ids = ids[1];
        res.inst_ids = ids[2];
        res.flags = hostile() ? next_u32() : 0u;
        res.reserved[6] = any_word();
        memset(ranges, 0, sizeof ranges);
        memset(hits, 7, sizeof hits);
        if (getenv("RC_FUZZ_TRACE")) {
            fprintf(stderr, "  sensor model %u %ux%u range %g..%g, %s, origin %g %g %g, attributes 0x%x\n", info.model,
                    info.rows, info.columns, (double)info.range_min, (double)info.range_max,
                    target == world ? "instances" : "mesh", sd.origin[0], sd.origin[1], sd.origin[2],
                    res.attributes);
            for (i = 0; i < n_poses; ++i)
                fprintf(stderr, "  pose %g %g %g, %g %g %g %g\n", (double)poses[i].position[0],
                        (double)poses[i].position[1], (double)poses[i].position[2], (double)poses[i].orientation[0],
                        (double)poses[i].orientation[1], (double)poses[i].orientation[2],
                        (double)poses[i].orientation[3]);
        }
        st = rc_simulate(ctx, target, sensor, poses, hostile() ? 0u : n_poses, &res);
        if (!known_status(st)) fail_msg("rc_simulate returned %d (seed %lu)", (int)st, seed);
        reached[4] += st == RC_OK;
        if (st == RC_OK) {
            const uint64_t n = (uint64_t)n_poses * info.rays_per_scan;
            uint64_t k;
            for (k = 0; k < n; ++k) {
                if ((res.attributes & RC_ATTR_HITS) && hits[k] > 1u)
                    fail_msg("hits[%lu] = %u (seed %lu)", (unsigned long)k, hits[k], seed);
                if ((res.attributes & RC_ATTR_RANGES) && !isinf(ranges[k]) &&
                    !(ranges[k] >= info.range_min && ranges[k] <= info.range_max))
                    fail_msg("ranges[%lu] = %g outside [%g, %g] (seed %lu)", (unsigned long)k, (double)ranges[k],
                             (double)info.range_min, (double)info.range_max, seed);
            }
        }
    }
    /* destroy in a random order of the parts, then the context */
    if (below(2)) CHECK_STATUS(rc_sensor_destroy(sensor));
    if (below(2) && world) CHECK_STATUS(rc_scene_destroy(world));
    if (getenv("RC_FUZZ_TRACE"))
        fprintf(stderr, "  reached: mesh %d world %d sensor %d simulate %d (%s)\n", mesh_scene != NULL, world != NULL,
                sensor != NULL, (int)st, rc_context_last_error(ctx));
    rc_context_destroy(ctx);
    free(blob); /* after the scene that referenced it */
}

static void fuzz(uint32_t backend)
{
    /* RC_FUZZ_ROUNDS=N explores further; RC_FUZZ_TRACE prints each seed */
    const char *env = getenv("RC_FUZZ_ROUNDS");
    unsigned long rounds = env ? strtoul(env, NULL, 10) : rct_quick() ? 300u : 3000u;
    unsigned long seed;
    if (!rct_backend_usable(backend)) skip();
    /* a Vulkan context takes ~90 ms to start on lavapipe: fewer rounds */
    if (backend == RC_BACKEND_VULKAN) rounds = rounds / 15u ? rounds / 15u : 1u;
    memset(reached, 0, sizeof reached);
    for (seed = 0; seed < rounds; ++seed) {
        if (getenv("RC_FUZZ_TRACE")) fprintf(stderr, "seed %lu\n", seed);
        one_round(seed, backend);
    }
    print_message("%lu rounds on %s: %lu contexts, %lu meshes and %lu worlds committed, %lu sensors, %lu simulates\n",
                  rounds, rc_backend_name(backend), reached[0], reached[1], reached[2], reached[3], reached[4]);
    /* the rounds must reach every stage often enough to mean something (a
     * handful of rounds may not) */
    if (rounds >= 20u) assert_true(reached[4] > 0u && reached[2] > 0u);
    if (rounds >= 200u) assert_true(reached[4] > rounds / 50u && reached[2] > rounds / 50u);
}

static void test_fuzz_bvh(void **state)
{
    (void)state;
    fuzz(RC_BACKEND_BVH);
}

static void test_fuzz_embree(void **state)
{
    (void)state;
    fuzz(RC_BACKEND_EMBREE);
}

static void test_fuzz_vulkan(void **state)
{
    (void)state;
    fuzz(RC_BACKEND_VULKAN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fuzz_bvh),
        cmocka_unit_test(test_fuzz_embree),
        cmocka_unit_test(test_fuzz_vulkan),
    };
    return cmocka_run_group_tests_name("fuzz_api", tests, NULL, NULL);
}
