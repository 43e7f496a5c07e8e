/* Fuzz target: the built-in backend's exactness. The input is a small mesh
 * on a coarse grid (so triangles share edges and vertices, lie in one plane,
 * collapse to lines and points, and rays start on them and graze them), one
 * sensor position and up to 64 rays, as an O1Dn sensor (the packet
 * traversal) or an OnDn one (single rays), or a spherical or pinhole grid of
 * up to 8 x 8 rays (the packets over the grid's tiles). The triangles go
 * into one mesh or are split over up to 40 (packets mesh by mesh, a walk of
 * the top-level tree from 8 meshes, past the 32 the packets take one by one
 * from 33), and the scene may hold up to
 * four instances of a scene of those meshes (turned, scaled, mirrored: the
 * two-level tree), the meshes themselves beside them or not. The traversals that take turns on
 * large maps can be forced, and the scene may then change and be traced
 * again (dynamic maps: meshes, referenced, get new vertices and a refit;
 * instances move). Promised: every ray's hit, and the triangle,
 * mesh and instance it names, are exactly those of testing every triangle of
 * every mesh and instance with the same watertight test and tie rule, one by
 * one (instances with the ray turned into their frame as the library turns
 * it): the trees' box tests only ever skip triangles that cannot win, except
 * a triangle whose t the box slack cannot cover (beyond_slack: a tie, or a
 * nearer hit by the rounding of a needle's t) and a triangle whose
 * own bounding box the slab test says the ray misses (meets_own_box). A hit's
 * point lies at its range along its ray, and its normal is a unit vector
 * facing the sensor. */
#include "fuzz_target.h"

#include <math.h>
#include <string.h>

#include "rangecast/rangecast.h"
#include "bvh/intersect.h"
#include "core/context.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

#define MAX_TRIS 256u
#define MAX_RAYS 64u
#define MAX_MESHES 40u
#define MAX_INSTANCES 4u
#define RANGE_MAX 1.0e6f

/* The flags byte: bit 0 OnDn, bits 1-4 the grid step, bit 5 every mesh
 * counts as large (the traversals take turns; their packets leave lone
 * lanes to a pool where bit 1 is set), bits 6-7 the layout. */
enum layout { ONE_MESH, MESHES, MESHES_AND_INSTANCES, INSTANCES_ONLY };

static rc_context *ctx;
static uint64_t default_large_bytes;

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
    default_large_bytes = ctx->large_mesh_bytes;
    atexit(teardown);
}

typedef struct mesh_split {
    uint32_t count;
    uint32_t first[MAX_MESHES + 1]; /* mesh m holds triangles first[m] .. first[m+1]-1 */
} mesh_split;

/* 1 when the slab test of the trees (box_hit's operations and slack, within
 * RANGE_MAX) says ray r meets the bounding box of the triangle (a, b, c).
 * Every box of a tree that holds the triangle holds that box, and the test
 * is monotonic in the planes, so where it passes every such box passes. */
static int meets_own_box(const rc__ray *r, const float *a, const float *b, const float *c)
{
    float t0 = 0.0f, t1 = RANGE_MAX;
    int k;
    for (k = 0; k < 3; ++k) {
        const float bmin = fminf(a[k], fminf(b[k], c[k])), bmax = fmaxf(a[k], fmaxf(b[k], c[k]));
        const float p = (bmin - r->org[k]) * r->inv_dir[k], q = (bmax - r->org[k]) * r->inv_dir[k];
        if (p != p || q != q) { /* 0 * inf: the origin on a plane the ray runs along */
            if (r->org[k] < bmin || r->org[k] > bmax) return 0;
            continue;
        }
        if ((p < q ? p : q) > t0) t0 = p < q ? p : q;
        if ((p < q ? q : p) < t1) t1 = p < q ? q : p;
    }
    return t0 <= t1 * RC__SLAB_FAR_SCALE;
}

/* Offers every triangle of every mesh to h, for a ray already in the meshes'
 * frame, as rc__mesh_intersect ranks them; with own_box, only those whose
 * own bounding box the ray meets (meets_own_box). */
static void offer_all(rc__hit *h, const float *verts, const mesh_split *ms, const rc__ray *ray, uint32_t inst,
                      int own_box)
{
    uint32_t m, i;
    for (m = 0; m < ms->count; ++m)
        for (i = ms->first[m]; i < ms->first[m + 1]; ++i) {
            float t, u, v;
            const float *a = verts + 9u * i;
            const uint32_t prim = i - ms->first[m];
            if (own_box && !meets_own_box(ray, a, a + 3, a + 6)) continue;
            if (rc__tri_intersect(ray, a, a + 3, a + 6, &t, &u, &v)) rc__hit_offer(h, t, prim, prim, m, inst);
        }
}

/* The ray in instance inst's frame (world with inst RC_INVALID_ID), turned as
 * the library's two-level traversal turns it. */
static void ray_in_frame(const rc_scene *scene, uint32_t inst, const float org[3], const float dir[3], rc__ray *out)
{
    rc__ray ray;
    float o[3], d[3];
    const rc__instance *in;
    rc__ray_prepare(&ray, org, dir);
    if (inst == RC_INVALID_ID) {
        *out = ray;
        return;
    }
    in = &scene->insts[inst];
    rc__rot_apply_f(in->to_local.r, ray.org, o);
    o[0] += in->to_local.t[0];
    o[1] += in->to_local.t[1];
    o[2] += in->to_local.t[2];
    rc__rot_apply_f(in->to_local.r, ray.dir, d);
    rc__ray_prepare(out, o, d);
}

/* The nearest hit by testing everything: the scene's own meshes, and each
 * instance's meshes with the ray turned into its frame (with own_box, only
 * the triangles whose own box the ray meets). */
static rc__hit brute_nearest(const rc_scene *scene, int own_meshes, const float *verts, const mesh_split *ms,
                             const float org[3], const float dir[3], int own_box)
{
    rc__ray ray;
    rc__hit h;
    uint32_t k;
    h.t = RANGE_MAX;
    h.prim = h.geom = h.inst = h.slot = RC_INVALID_ID;
    if (own_meshes) {
        ray_in_frame(scene, RC_INVALID_ID, org, dir, &ray);
        offer_all(&h, verts, ms, &ray, RC_INVALID_ID, own_box);
    }
    for (k = 0; k < scene->inst_count; ++k) {
        ray_in_frame(scene, k, org, dir, &ray);
        offer_all(&h, verts, ms, &ray, k, own_box);
    }
    return h;
}

/* The exact distance along r to the plane of (a, b, c), in double (float
 * inputs are exact there, and so nearly is this). */
static double plane_distance(const rc__ray *r, const float *a, const float *b, const float *c)
{
    const double e1x = (double)b[0] - a[0], e1y = (double)b[1] - a[1], e1z = (double)b[2] - a[2];
    const double e2x = (double)c[0] - a[0], e2y = (double)c[1] - a[1], e2z = (double)c[2] - a[2];
    const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
    return (nx * ((double)a[0] - r->org[0]) + ny * ((double)a[1] - r->org[1]) + nz * ((double)a[2] - r->org[2])) /
           (nx * r->dir[0] + ny * r->dir[1] + nz * r->dir[2]);
}

/* 1 when the library's hit (geom, prim, inst), at t by the same test, is
 * no nearer than the nearest of all triangles h (at the same t it names a
 * larger key), and h's triangle lies further beyond t than the trees' slack
 * covers. The trees drop a box whose entry distance passes the nearest t so
 * far by more than RC__SLAB_FAR_SCALE (less the slab test's own 4 ulps); a
 * box holding h's triangle enters no later than the triangle's exact
 * distance, so only then can it be dropped once the library's hit is found:
 * the documented limit of triangles whose t carries more rounding than the
 * slack (docs/architecture.md, "The BVH"), not a traversal fault. */
static int beyond_slack(const rc_scene *scene, const float *verts, const mesh_split *ms, const float org[3],
                        const float dir[3], const rc__hit *h, uint32_t geom, uint32_t prim, uint32_t inst)
{
    rc__ray lr, hr;
    rc__hit lib;
    const float *lib_tri, *h_tri;
    float t, u, v;
    if (h->prim == RC_INVALID_ID || geom >= ms->count || prim >= ms->first[geom + 1] - ms->first[geom]) return 0;
    lib.prim = prim;
    lib.geom = geom;
    lib.inst = inst;
    lib_tri = verts + 9u * (ms->first[geom] + prim);
    ray_in_frame(scene, inst, org, dir, &lr);
    if (!rc__tri_intersect(&lr, lib_tri, lib_tri + 3, lib_tri + 6, &t, &u, &v) || t < h->t) return 0;
    if (t == h->t && !rc__hit_key_less(h->inst, h->geom, h->prim, &lib)) return 0;
    h_tri = verts + 9u * (ms->first[h->geom] + h->prim);
    ray_in_frame(scene, h->inst, org, dir, &hr);
    return plane_distance(&hr, h_tri, h_tri + 3, h_tri + 6) > (double)t * (1.0 + 28.0 * FLT_EPSILON);
}

/* 1 when the library's answer for a ray (hit, and its geom, prim, inst)
 * names the nearest hit h, or one that h lies beyond by more than the
 * trees' slack (beyond_slack). */
static int library_is(const rc_scene *scene, const float *verts, const mesh_split *ms, const float org[3],
                      const float dir[3], const rc__hit *h, uint8_t hit, uint32_t geom, uint32_t prim, uint32_t inst)
{
    if ((h->prim != RC_INVALID_ID) != (hit != 0)) return 0;
    return !hit || (prim == h->prim && geom == h->geom && inst == h->inst) ||
           beyond_slack(scene, verts, ms, org, dir, h, geom, prim, inst);
}

/* Adds the split meshes to scene: copied, or referenced where the input
 * moves them later (the arrays then stay put until the scene goes). */
static void add_meshes(rc_scene *scene, const float *verts, const uint32_t *indices, const mesh_split *ms,
                       int referenced)
{
    uint32_t m, geom;
    for (m = 0; m < ms->count; ++m) {
        rc_mesh_desc md = rc_mesh_desc_default();
        const uint32_t n = ms->first[m + 1] - ms->first[m];
        md.flags = referenced ? 0u : RC_MESH_COPY;
        md.vertices = verts + 9u * ms->first[m];
        md.vertex_count = 3u * n;
        md.indices = indices;
        md.triangle_count = n;
        FZ_REQUIRE(rc_scene_add_mesh(scene, &md, &geom) == RC_OK, "a mesh on the grid is accepted");
        FZ_REQUIRE(geom == m, "geometry ids count up");
    }
}

static rc_scene *new_scene(uint32_t tris, uint32_t meshes, uint32_t instances)
{
    rc_scene_desc sd = rc_scene_desc_default();
    rc_scene *scene = NULL;
    sd.max_geometries = meshes;
    sd.max_instances = instances;
    sd.max_triangles = meshes ? tris : 0u;
    sd.max_vertices = meshes ? 3u * tris : 0u;
    sd.max_copied_triangles = meshes ? tris : 0u;
    FZ_REQUIRE(rc_scene_create(ctx, &sd, &scene) == RC_OK, "scene");
    return scene;
}

/* A grid sensor from the input's last bytes, or NULL where the input keeps
 * the rays it gave (kind 0) or its grid is one the API refuses (a finding
 * only if the refusal is not the documented one). */
static rc_sensor *grid_sensor(reader *r, uint32_t *rays)
{
    const uint8_t kind = next(r) % 4u;
    const uint32_t rows = 1u + next(r) % 8u, cols = 1u + next(r) % 8u;
    rc_sensor *sensor = NULL;
    rc_status st = RC_OK;
    if (kind == 1u) {
        rc_spherical_desc d = rc_spherical_desc_default();
        d.common.range_min = 0.0f;
        d.common.range_max = RANGE_MAX;
        d.theta.min = (float)(int8_t)next(r) * (3.14159265f / 64.0f);
        d.theta.increment = (float)(int8_t)next(r) * (3.14159265f / 512.0f);
        d.theta.count = cols;
        d.phi.min = (float)(int8_t)next(r) * (3.14159265f / 256.0f);
        d.phi.increment = (float)(int8_t)next(r) * (3.14159265f / 1024.0f);
        d.phi.count = rows;
        st = rc_sensor_create_spherical(ctx, &d, &sensor);
    } else if (kind >= 2u) {
        rc_pinhole_desc d = rc_pinhole_desc_default();
        d.frame = kind == 3u ? RC_PINHOLE_FRAME_OPTICAL : RC_PINHOLE_FRAME_BODY;
        d.common.range_min = 0.0f;
        d.common.range_max = RANGE_MAX;
        d.width = cols;
        d.height = rows;
        d.fx = 1.0f + (float)next(r);
        d.fy = 1.0f + (float)next(r);
        d.cx = (float)(int8_t)next(r) * 0.25f;
        d.cy = (float)(int8_t)next(r) * 0.25f;
        st = rc_sensor_create_pinhole(ctx, &d, &sensor);
    }
    FZ_REQUIRE(st == RC_OK || st == RC_ERR_INVALID_ARGUMENT, "a grid sensor is made or refused as documented");
    if (sensor) *rays = rows * cols;
    return sensor;
}

/* A scale from one byte: mirrors, powers of two and others. */
static float scale_of(uint8_t b)
{
    static const float scales[8] = {1.0f, 2.0f, 0.5f, -1.0f, 3.0f, 0.25f, -1.5f, 1.0f / 3.0f};
    return scales[b & 7u];
}

/* An instance's placement from the input: a point on the grid, a unit
 * quaternion, a scale an axis. */
static void placement(reader *r, float scale, rc_pose *transform, float scales[3])
{
    float q[4], n2 = 0.0f;
    uint32_t m;
    for (m = 0; m < 3u; ++m) transform->position[m] = coord(r, scale);
    for (m = 0; m < 4u; ++m) {
        q[m] = (float)(int8_t)next(r);
        n2 += q[m] * q[m];
    }
    if (n2 == 0.0f) q[3] = n2 = 1.0f;
    for (m = 0; m < 4u; ++m) transform->orientation[m] = q[m] / sqrtf(n2);
    for (m = 0; m < 3u; ++m) scales[m] = scale_of(next(r));
}

/* What one trace of the scene checks against: its meshes' triangles (verts,
 * split by ms; the instances' source holds the same), whether the scene has
 * them as its own, and the sensor's place. */
typedef struct trace_case {
    const rc_scene *scene;
    const rc_sensor *sensor;
    const float *verts;
    const mesh_split *ms;
    int own_meshes;
    float pos[3];
    const float *origins; /* an OnDn sensor's offsets (zeros for one origin) */
    uint32_t rays;
} trace_case;

/* Simulates the case's one pose and checks every ray: the hit it names is
 * that of testing every triangle (library_is), its point lies at its range
 * along the ray, its normal is a unit vector facing the sensor. */
static void simulate_and_check(const trace_case *c)
{
    static float ranges[MAX_RAYS], points[MAX_RAYS * 3u], normals[MAX_RAYS * 3u];
    static uint32_t prims[MAX_RAYS], geoms[MAX_RAYS], insts[MAX_RAYS];
    static uint8_t hits[MAX_RAYS];
    rc_results res = rc_results_default();
    rc_pose pose = rc_pose_identity();
    uint32_t i, k;
    memcpy(pose.position, c->pos, sizeof c->pos);
    res.attributes = RC_ATTR_ALL;
    res.hits = hits;
    res.ranges = ranges;
    res.points = points;
    res.normals = normals;
    res.prim_ids = prims;
    res.geom_ids = geoms;
    res.inst_ids = insts;
    res.capacity = c->rays;
    FZ_REQUIRE(rc_simulate(ctx, c->scene, c->sensor, &pose, 1, &res) == RC_OK, "simulate");
    for (i = 0; i < c->rays; ++i) {
        /* the rays as the library traces them: its unit directions, the
         * pose's translation (the turn is the identity) */
        const float *d = c->sensor->directions + 3u * i, *o = c->origins + 3u * i, *p = points + 3u * i;
        const float *nv = normals + 3u * i;
        float org[3];
        double len2 = 0.0, facing = 0.0, off2 = 0.0;
        rc__hit h, hb;
        for (k = 0; k < 3u; ++k) org[k] = c->pos[k] + o[k];
        h = brute_nearest(c->scene, c->own_meshes, c->verts, c->ms, org, d, 0);
        /* or the nearest of the triangles whose own box the ray meets: a
         * triangle test can report a hit (by its rounding) on a triangle
         * whose box the slab test says the ray leaves at once, an origin on
         * a face of that box moving out of it (docs/architecture.md, "The
         * BVH"); the trees may skip such a triangle */
        if (!library_is(c->scene, c->verts, c->ms, org, d, &h, hits[i], geoms[i], prims[i], insts[i]))
            hb = brute_nearest(c->scene, c->own_meshes, c->verts, c->ms, org, d, 1);
        else
            hb = h;
        if (!library_is(c->scene, c->verts, c->ms, org, d, &hb, hits[i], geoms[i], prims[i], insts[i])) {
            fprintf(stderr,
                    "ray %u: library hit %u prim %u geom %u inst %u range %.9g; every triangle: prim %u geom %u "
                    "inst %u t %.9g\n",
                    (unsigned)i, (unsigned)hits[i], (unsigned)prims[i], (unsigned)geoms[i], (unsigned)insts[i],
                    (double)ranges[i], (unsigned)h.prim, (unsigned)h.geom, (unsigned)h.inst, (double)h.t);
            FZ_REQUIRE(0, "the trees' nearest hit is the nearest of all triangles");
        }
        if (!hits[i]) continue;
        for (k = 0; k < 3u; ++k) {
            const double want = (double)o[k] + (double)d[k] * (double)ranges[i];
            off2 += (p[k] - want) * (p[k] - want);
            len2 += (double)nv[k] * nv[k];
            facing += (double)nv[k] * d[k];
        }
        FZ_REQUIRE(ranges[i] >= 0.0f && ranges[i] <= RANGE_MAX, "a hit's range lies in the sensor's interval");
        FZ_REQUIRE(sqrt(off2) <= 1e-5 * ((double)ranges[i] + fabs(o[0]) + fabs(o[1]) + fabs(o[2])) + 1e-30,
                   "a hit's point lies at its range along its ray");
        FZ_REQUIRE(fabs(len2 - 1.0) <= 1e-5, "a hit's normal is a unit vector");
        FZ_REQUIRE(facing <= 1e-6, "a hit's normal faces the sensor");
    }
}

/* The dynamic-map step, from the input's bytes after the sensor's: each
 * mesh may take new vertices (rewritten in place and the scenes told, so the
 * next commits refit its trees: their boxes, and which triangles are folded
 * flat for having zero area), each instance may move. A scene whose
 * instances' source changed is refused until it commits again. Returns 1
 * when anything changed (both scenes committed again), 0 when nothing did. */
static int move_scene(reader *r, float scale, float *verts, const mesh_split *ms, rc_scene *scene,
                      rc_scene *source, uint32_t instances, const trace_case *c)
{
    uint32_t m, i, k;
    int moved = 0, source_moved = 0;
    for (m = 0; m < ms->count; ++m) {
        if (!(next(r) & 1u)) continue;
        for (i = 9u * ms->first[m]; i < 9u * ms->first[m + 1]; ++i) verts[i] = coord(r, scale);
        if (c->own_meshes) FZ_REQUIRE(rc_scene_update_mesh(scene, m) == RC_OK, "a moved mesh is taken");
        if (source) FZ_REQUIRE(rc_scene_update_mesh(source, m) == RC_OK, "a moved source mesh is taken");
        moved = 1;
        source_moved |= source != NULL;
    }
    for (k = 0; k < instances; ++k) {
        rc_pose transform = rc_pose_identity();
        float scales[3];
        if (!(next(r) & 1u)) continue;
        placement(r, scale, &transform, scales);
        FZ_REQUIRE(rc_scene_set_instance_transform(scene, k, &transform, scales) == RC_OK,
                   "a move on the grid is accepted");
        moved = 1;
    }
    if (!moved) return 0;
    if (source_moved) {
        static float ranges[MAX_RAYS];
        rc_results res = rc_results_default();
        rc_pose pose = rc_pose_identity();
        FZ_REQUIRE(rc_scene_commit(source) == RC_OK, "the moved source commits");
        for (i = 0; i < c->rays; ++i) ranges[i] = -7.0f;
        res.attributes = RC_ATTR_RANGES;
        res.ranges = ranges;
        res.capacity = c->rays;
        FZ_REQUIRE(rc_simulate(ctx, scene, c->sensor, &pose, 1, &res) == RC_ERR_NOT_COMMITTED,
                   "a scene whose instances' source changed is refused until it commits");
        for (i = 0; i < c->rays; ++i) FZ_REQUIRE(ranges[i] == -7.0f, "a refused call writes nothing");
    }
    FZ_REQUIRE(rc_scene_commit(scene) == RC_OK, "the moved scene commits");
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static float verts[MAX_TRIS * 9u], origins[MAX_RAYS * 3u], dirs[MAX_RAYS * 3u];
    static uint32_t indices[MAX_TRIS * 3u];
    reader r;
    uint8_t flags, rays_byte;
    int ondn, own_meshes, dynamic;
    enum layout layout;
    float scale, pos[3];
    uint32_t tris, rays, i, k, m, instances = 0;
    mesh_split ms;
    rc_rays_desc rd = rc_rays_desc_default();
    rc_scene *scene = NULL, *source = NULL;
    rc_sensor *sensor = NULL;
    trace_case tc;
    rc_status st;
    if (ctx == NULL) setup();
    r.p = data;
    r.left = size;
    flags = next(&r);
    ondn = flags & 1u;
    scale = ldexpf(1.0f, (int)((flags >> 1) & 15u) - 9); /* grid steps 1/512 .. 64 */
    ctx->large_mesh_bytes = (flags & 32u) ? 0u : default_large_bytes;
    /* large meshes' packets: every other grid step leaves lone lanes to the pool */
    ctx->lone_pool_bytes = (flags & 2u) ? 0u : UINT64_MAX;
    layout = (enum layout)(flags >> 6);
    tris = 1u + next(&r) % MAX_TRIS;
    /* the rays' byte: bits 0-5 the count, bit 6 a dynamic map (the meshes
     * referenced, moved after the first trace) */
    rays_byte = next(&r);
    rays = 1u + rays_byte % MAX_RAYS;
    dynamic = (rays_byte & 64u) != 0;
    for (k = 0; k < 3u; ++k) pos[k] = coord(&r, scale);
    for (i = 0; i < rays; ++i) {
        for (k = 0; k < 3u; ++k) dirs[3u * i + k] = (float)(int8_t)next(&r);
        if (dirs[3u * i] == 0.0f && dirs[3u * i + 1] == 0.0f && dirs[3u * i + 2] == 0.0f) dirs[3u * i] = 1.0f;
        for (k = 0; k < 3u; ++k) origins[3u * i + k] = ondn ? coord(&r, scale) : 0.0f;
    }
    for (i = 0; i < tris * 9u; ++i) verts[i] = coord(&r, scale);
    for (i = 0; i < tris * 3u; ++i) indices[i] = i;

    /* the meshes: tris split into nearly equal runs */
    ms.count = layout == ONE_MESH ? 1u : 1u + next(&r) % MAX_MESHES;
    if (ms.count > tris) ms.count = tris;
    for (m = 0; m <= ms.count; ++m) ms.first[m] = (uint32_t)((uint64_t)tris * m / ms.count);
    own_meshes = layout != INSTANCES_ONLY;

    if (layout == MESHES_AND_INSTANCES || layout == INSTANCES_ONLY) {
        instances = (layout == INSTANCES_ONLY ? 1u : 0u) + next(&r) % (MAX_INSTANCES + 1u);
        if (instances > MAX_INSTANCES) instances = MAX_INSTANCES;
        source = new_scene(tris, ms.count, 0u);
        add_meshes(source, verts, indices, &ms, dynamic);
        FZ_REQUIRE(rc_scene_commit(source) == RC_OK, "the instances' source commits");
    }
    scene = new_scene(tris, own_meshes ? ms.count : 0u, instances);
    if (own_meshes) add_meshes(scene, verts, indices, &ms, dynamic);
    for (k = 0; k < instances; ++k) {
        rc_instance_desc id = rc_instance_desc_default();
        uint32_t inst_id;
        id.source = source;
        placement(&r, scale, &id.transform, id.scale);
        st = rc_scene_add_instance(scene, &id, &inst_id);
        FZ_REQUIRE(st == RC_OK, "an instance on the grid is accepted");
        FZ_REQUIRE(inst_id == k, "instance ids count up");
    }
    FZ_REQUIRE(rc_scene_commit(scene) == RC_OK, "commit");

    sensor = grid_sensor(&r, &rays);
    if (sensor) { /* one origin: the OnDn offsets read above go unused */
        ondn = 0;
        memset(origins, 0, sizeof origins);
    }
    rd.common.range_min = 0.0f;
    rd.common.range_max = RANGE_MAX;
    rd.directions = dirs;
    rd.origins = ondn ? origins : NULL;
    rd.ray_count = rays;
    if (sensor == NULL) {
        st = rc_sensor_create_rays(ctx, ondn ? RC_SENSOR_ONDN : RC_SENSOR_O1DN, &rd, &sensor);
        FZ_REQUIRE(st == RC_OK, "sensor");
    }
    tc.scene = scene;
    tc.sensor = sensor;
    tc.verts = verts;
    tc.ms = &ms;
    tc.own_meshes = own_meshes;
    memcpy(tc.pos, pos, sizeof pos);
    tc.origins = origins;
    tc.rays = rays;
    simulate_and_check(&tc);
    if (dynamic && move_scene(&r, scale, verts, &ms, scene, source, instances, &tc)) simulate_and_check(&tc);
    FZ_REQUIRE(rc_sensor_destroy(sensor) == RC_OK, "sensor destroy");
    FZ_REQUIRE(rc_scene_destroy(scene) == RC_OK, "scene destroy");
    if (source) FZ_REQUIRE(rc_scene_destroy(source) == RC_OK, "source destroy");
    return 0;
}
