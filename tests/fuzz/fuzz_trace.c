/* Fuzz target: the built-in backend's exactness. The input is a small mesh
 * on a coarse grid (so triangles share edges and vertices, lie in one plane,
 * collapse to lines and points, and rays start on them and graze them), one
 * sensor position and up to 64 rays, as an O1Dn sensor (the packet
 * traversal) or an OnDn one (single rays). Promised: every ray's hit, and the
 * triangle it names, are exactly those of testing every triangle with the
 * same watertight test and tie rule, one by one: the tree's box tests only
 * ever skip triangles that cannot win. */
#include "fuzz_target.h"

#include <math.h>
#include <string.h>

#include "rangecast/rangecast.h"
#include "bvh/intersect.h"
#include "sensor/sensor.h"

#define MAX_TRIS 256u
#define MAX_RAYS 64u
#define RANGE_MAX 1.0e6f

static rc_context *ctx;

typedef struct reader {
    const uint8_t *p;
    size_t left;
} reader;

/* the next byte, 0 past the end (so every input means something) */
static uint8_t next(reader *r)
{
    if (r->left == 0) return 0;
    --r->left;
    return *r->p++;
}

static float coord(reader *r, float scale) { return (float)(int8_t)next(r) * scale; }

/* the context lives across inputs; freed at exit so leak checkers see
 * nothing of it */
static void teardown(void) { rc_context_destroy(ctx); }

static void setup(void)
{
    rc_context_desc cd = rc_context_desc_default();
    cd.backend = RC_BACKEND_BVH;
    cd.thread_count = 1;
    cd.memory_size = 8u << 20;
    FZ_REQUIRE(rc_context_create(&cd, &ctx) == RC_OK, "context");
    atexit(teardown);
}

/* The nearest hit by testing every triangle, as rc__mesh_intersect ranks them. */
static rc__hit brute_nearest(const float *verts, uint32_t tris, const float org[3], const float dir[3])
{
    rc__ray ray;
    rc__hit h;
    uint32_t i;
    rc__ray_prepare(&ray, org, dir);
    h.t = RANGE_MAX;
    h.u = h.v = 0.0f;
    h.prim = h.geom = h.inst = h.slot = RC_INVALID_ID;
    for (i = 0; i < tris; ++i) {
        float t, u, v;
        const float *a = verts + 9u * i;
        if (rc__tri_intersect(&ray, a, a + 3, a + 6, &t, &u, &v)) rc__hit_offer(&h, t, u, v, i, i, 0u, RC_INVALID_ID);
    }
    return h;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static float verts[MAX_TRIS * 9u], origins[MAX_RAYS * 3u], dirs[MAX_RAYS * 3u], ranges[MAX_RAYS];
    static uint32_t indices[MAX_TRIS * 3u], prims[MAX_RAYS];
    static uint8_t hits[MAX_RAYS];
    reader r;
    uint8_t flags;
    int ondn;
    float scale, pos[3];
    uint32_t tris, rays, i, k, geom;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    rc_results res = rc_results_default();
    rc_pose pose = rc_pose_identity();
    rc_scene *scene = NULL;
    rc_sensor *sensor = NULL;
    rc_status st;
    if (ctx == NULL) setup();
    r.p = data;
    r.left = size;
    flags = next(&r);
    ondn = flags & 1u;
    scale = ldexpf(1.0f, (int)((flags >> 1) & 15u) - 9); /* grid steps 1/512 .. 64 */
    tris = 1u + next(&r) % MAX_TRIS;
    rays = 1u + next(&r) % MAX_RAYS;
    for (k = 0; k < 3u; ++k) pos[k] = coord(&r, scale);
    for (i = 0; i < rays; ++i) {
        for (k = 0; k < 3u; ++k) dirs[3u * i + k] = (float)(int8_t)next(&r);
        if (dirs[3u * i] == 0.0f && dirs[3u * i + 1] == 0.0f && dirs[3u * i + 2] == 0.0f) dirs[3u * i] = 1.0f;
        for (k = 0; k < 3u; ++k) origins[3u * i + k] = ondn ? coord(&r, scale) : 0.0f;
    }
    for (i = 0; i < tris * 9u; ++i) verts[i] = coord(&r, scale);
    for (i = 0; i < tris * 3u; ++i) indices[i] = i;

    sd.max_geometries = 1;
    sd.max_triangles = tris;
    sd.max_vertices = 3u * tris;
    sd.max_copied_triangles = tris;
    md.flags = RC_MESH_COPY;
    md.vertices = verts;
    md.vertex_count = 3u * tris;
    md.indices = indices;
    md.triangle_count = tris;
    rd.common.range_min = 0.0f;
    rd.common.range_max = RANGE_MAX;
    rd.directions = dirs;
    rd.origins = ondn ? origins : NULL;
    rd.ray_count = rays;
    FZ_REQUIRE(rc_scene_create(ctx, &sd, &scene) == RC_OK, "scene");
    FZ_REQUIRE(rc_scene_add_mesh(scene, &md, &geom) == RC_OK, "a mesh on the grid is accepted");
    FZ_REQUIRE(rc_scene_commit(scene) == RC_OK, "commit");
    st = rc_sensor_create_rays(ctx, ondn ? RC_SENSOR_ONDN : RC_SENSOR_O1DN, &rd, &sensor);
    FZ_REQUIRE(st == RC_OK, "sensor");
    memcpy(pose.position, pos, sizeof pos);
    res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS;
    res.hits = hits;
    res.ranges = ranges;
    res.prim_ids = prims;
    res.capacity = rays;
    FZ_REQUIRE(rc_simulate(ctx, scene, sensor, &pose, 1, &res) == RC_OK, "simulate");
    for (i = 0; i < rays; ++i) {
        /* the rays as the library traces them: its unit directions, the
         * pose's translation (the turn is the identity) */
        float org[3];
        rc__hit h;
        for (k = 0; k < 3u; ++k) org[k] = pos[k] + origins[3u * i + k];
        h = brute_nearest(verts, tris, org, sensor->directions + 3u * i);
        if ((h.prim != RC_INVALID_ID) != (hits[i] != 0) || (hits[i] && prims[i] != h.prim)) {
            fprintf(stderr, "ray %u: library hit %u prim %u range %.9g; every triangle: prim %u t %.9g\n", (unsigned)i,
                    (unsigned)hits[i], (unsigned)prims[i], (double)ranges[i], (unsigned)h.prim, (double)h.t);
            FZ_REQUIRE(0, "the tree's nearest hit is the nearest of all triangles");
        }
    }
    FZ_REQUIRE(rc_sensor_destroy(sensor) == RC_OK, "sensor destroy");
    FZ_REQUIRE(rc_scene_destroy(scene) == RC_OK, "scene destroy");
    return 0;
}
