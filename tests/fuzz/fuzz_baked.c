/* Fuzz target: a baked map from untrusted bytes. rc_scene_load_baked runs with
 * the checksum off, so every mutation meets the structure checks (anyone can
 * recompute a CRC), and whatever loads is scanned on the built-in backend,
 * which traverses the blob's own tree in place. Promised: a known status
 * every time, never a read outside the blob, never a hang; a loaded map
 * simulates, and its ranges are REP 117's (+inf, -inf or within range).
 * rc_baked_get_mesh gets the same bytes, and what it hands out must lie
 * inside them. */
#include "fuzz_target.h"

#include <math.h>
#include <string.h>

#include "rangecast/rangecast.h"
#include "scene/baked_format.h" /* the header's origin field */

#define RAYS 64u
#define POSES 2u

static rc_context *ctx;
static rc_sensor *sensor;

static int known(rc_status st) { return st <= RC_OK && st >= RC_ERR_IO; }

/* the context lives across inputs; freed at exit so leak checkers see
 * nothing of it */
static void teardown(void) { rc_context_destroy(ctx); }

static void setup(void)
{
    static float dirs[RAYS * 3u];
    rc_context_desc cd = rc_context_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    uint32_t i;
    cd.backend = RC_BACKEND_BVH;
    cd.thread_count = 1;
    cd.memory_size = 8u << 20;
    FZ_REQUIRE(rc_context_create(&cd, &ctx) == RC_OK, "context");
    atexit(teardown);
    /* a spiral over the sphere of directions */
    for (i = 0; i < RAYS; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / RAYS, r = sqrt(1.0 - z * z), a = 2.399963229728653 * i;
        dirs[3u * i] = (float)(r * cos(a));
        dirs[3u * i + 1u] = (float)(r * sin(a));
        dirs[3u * i + 2u] = (float)z;
    }
    rd.common.range_min = 0.05f;
    rd.common.range_max = 100.0f;
    rd.directions = dirs;
    rd.ray_count = RAYS;
    FZ_REQUIRE(rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &sensor) == RC_OK, "sensor");
}

/* Two poses near the map's own origin (any finite origin loads, as in
 * rc_scene_desc; poses are in map coordinates, so they go in double). */
static void scan(const rc_scene *scene, const unsigned char *blob)
{
    rc_pose_d poses[POSES] = {{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}},
                              {{1.0, 0.5, 1.2}, {0.0, 0.0, 0.38268343236, 0.92387953251}}};
    double origin[3];
    uint32_t p, k;
    static uint8_t hits[POSES * RAYS];
    static float ranges[POSES * RAYS];
    static uint32_t prims[POSES * RAYS];
    rc_results res = rc_results_default();
    rc_status st;
    uint32_t i;
    res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS;
    res.hits = hits;
    res.ranges = ranges;
    res.prim_ids = prims;
    res.capacity = POSES * RAYS;
    memcpy(origin, blob + RC__BK_ORIGIN, sizeof origin);
    for (p = 0; p < POSES; ++p)
        for (k = 0; k < 3u; ++k) poses[p].position[k] += origin[k];
    st = rc_simulate_d(ctx, scene, sensor, poses, POSES, &res);
    if (st != RC_OK) fprintf(stderr, "rc_simulate: %s: %s\n", rc_status_string(st), rc_context_last_error(ctx));
    FZ_REQUIRE(st == RC_OK, "a loaded map simulates");
    for (i = 0; i < POSES * RAYS; ++i) {
        const float r = ranges[i];
        FZ_REQUIRE(hits[i] <= 1u, "hit flags are 0 or 1");
        FZ_REQUIRE(hits[i] ? (r >= 0.05f && r <= 100.0f) : (isinf(r) != 0), "REP 117 ranges");
        FZ_REQUIRE(hits[i] || prims[i] == RC_INVALID_ID, "no prim id without a hit");
    }
}

static void get_meshes(const unsigned char *blob, size_t size)
{
    uint32_t g, count = 0;
    for (g = 0; g < 3u; ++g) {
        rc_mesh_desc md = rc_mesh_desc_default();
        const uintptr_t lo = (uintptr_t)blob, hi = lo + size;
        rc_status st = rc_baked_get_mesh(blob, size, g, &md, &count);
        FZ_REQUIRE(known(st), "a known status from rc_baked_get_mesh");
        if (st != RC_OK) break;
        /* what it hands out lies inside the blob */
        FZ_REQUIRE((uintptr_t)md.vertices >= lo && md.vertex_count <= (hi - (uintptr_t)md.vertices) / 16u &&
                       md.vertex_stride == 16u,
                   "baked vertices inside the blob");
        FZ_REQUIRE((uintptr_t)md.indices >= lo && md.triangle_count <= (hi - (uintptr_t)md.indices) / 12u,
                   "baked indices inside the blob");
        if (g + 1u >= count) break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    unsigned char *blob;
    rc_scene *scene = NULL;
    size_t need = 0;
    rc_status st;
    if (ctx == NULL) setup();
    /* malloc's blocks are 16-byte aligned, as the loader asks */
    blob = (unsigned char *)malloc(size ? size : 1u);
    if (blob == NULL) return 0;
    if (size) memcpy(blob, data, size);
    st = rc_scene_baked_memory_requirements(ctx, blob, size, &need);
    FZ_REQUIRE(known(st), "a known status from the size query");
    get_meshes(blob, size);
    st = rc_scene_load_baked(ctx, blob, size, RC_BAKED_SKIP_CHECKSUM, &scene);
    FZ_REQUIRE(known(st), "a known status from rc_scene_load_baked");
    FZ_REQUIRE((st == RC_OK) == (scene != NULL), "a scene exactly when RC_OK");
    if (st == RC_OK) {
        scan(scene, blob);
        FZ_REQUIRE(rc_scene_destroy(scene) == RC_OK, "destroy");
    }
    free(blob);
    return 0;
}
