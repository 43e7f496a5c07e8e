/* Parity of the Vulkan backend with the built-in BVH backend on the same
 * scenes, rays and poses: a ~100k-triangle sphere with boxes (own geometries,
 * one with a strided vertex array, and instances of a box scene), random
 * O1Dn and OnDn rays, a VLP-16 batch, pinhole (both frames) and cylindrical
 * cameras; with the float64 kernel, the float-only kernel, and with tiny
 * binding limits (arrays split over 4 bindings, many dispatches, staged
 * uploads); and a UTM-scale map (scene origin, rc_simulate_d).
 *
 * Rules: hits and ids equal, except for rays whose BVH answer itself changes
 * when the direction is nudged by 1e-6 (relative): rays through an edge or a
 * vertex. Ranges, points and normals within 1e-5 (relative to the range).
 * The report line gives how many elements were bit-identical. With the
 * float64 kernel, a hit on the same triangle must have the same range to the
 * bit: that kernel recomputes it as the CPU does. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "backend/vulkan_internal.h"
#include "poses.h"
#include "rc_test.h"
#include "sensor/sensor.h"

#define PI 3.14159265358979323846

typedef struct world {
    rcu_mesh sphere, boxes, unit_box;
    float *strided; /* boxes' vertices at a 16-byte stride */
} world;

typedef struct side {
    rc_context *ctx;
    rc_scene *scene, *box;
} side;

static world g_world;

static void world_make(world *w)
{
    static const float lo[4][3] = {{2, 2, -1}, {-8, -3, -4}, {-1, -12, 2}, {5, -6, -9}};
    static const float hi[4][3] = {{4, 3, 1}, {-6, 3, 0}, {1, -10, 8}, {9, -2, -7}};
    const float ulo[3] = {-0.5f, -0.5f, -0.5f}, uhi[3] = {0.5f, 0.5f, 0.5f};
    uint32_t i;
    memset(w, 0, sizeof *w);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &w->sphere), 0);
    for (i = 0; i < 4; ++i) {
        rcu_mesh b;
        assert_int_equal(rcu_mesh_box(lo[i], hi[i], &b), 0);
        assert_int_equal(rcu_mesh_append(&w->boxes, &b), 0);
        rcu_mesh_free(&b);
    }
    assert_int_equal(rcu_mesh_box(ulo, uhi, &w->unit_box), 0);
    w->strided = (float *)malloc(sizeof(float) * 4u * w->boxes.vertex_count);
    assert_non_null(w->strided);
    for (i = 0; i < w->boxes.vertex_count; ++i) {
        memcpy(w->strided + 4u * i, w->boxes.vertices + 3u * i, 3 * sizeof(float));
        w->strided[4u * i + 3] = NAN; /* never read */
    }
}

static int setup(void **state)
{
    (void)state;
    world_make(&g_world);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    rcu_mesh_free(&g_world.sphere);
    rcu_mesh_free(&g_world.boxes);
    rcu_mesh_free(&g_world.unit_box);
    free(g_world.strided);
    return 0;
}

/* World scene: sphere (geometry 0), boxes (geometry 1, strided), 3 instances of a unit box. */
static void side_make(side *s, uint32_t backend)
{
    const world *w = &g_world;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    uint32_t g, i;
    s->ctx = rct_context(backend, 2, 128);
    s->box = rct_scene_mesh(s->ctx, &w->unit_box, RC_MESH_REFERENCE);
    sd.max_geometries = 2;
    sd.max_instances = 3;
    sd.max_triangles = (uint64_t)w->sphere.triangle_count + w->boxes.triangle_count;
    RCT_OK(s->ctx, rc_scene_create(s->ctx, &sd, &s->scene));
    md.vertices = w->sphere.vertices;
    md.vertex_count = w->sphere.vertex_count;
    md.indices = w->sphere.indices;
    md.triangle_count = w->sphere.triangle_count;
    RCT_OK(s->ctx, rc_scene_add_mesh(s->scene, &md, &g));
    md.vertices = w->strided;
    md.vertex_stride = 16;
    md.vertex_count = w->boxes.vertex_count;
    md.indices = w->boxes.indices;
    md.triangle_count = w->boxes.triangle_count;
    RCT_OK(s->ctx, rc_scene_add_mesh(s->scene, &md, &g));
    id.source = s->box;
    for (i = 0; i < 3; ++i) {
        id.transform = rct_pose_ypr(-6.0f + 6.0f * (float)i, 7.0f, -2.0f + (float)i, 0.4 * i, 0.3, -0.2 * i);
        id.scale[0] = 1.0f + (float)i;
        id.scale[1] = 2.0f;
        id.scale[2] = 0.5f + 0.25f * (float)i;
        RCT_OK(s->ctx, rc_scene_add_instance(s->scene, &id, &g));
    }
    RCT_OK(s->ctx, rc_scene_commit(s->scene));
}

static void side_free(side *s) { rc_context_destroy(s->ctx); }

/* 1 while the Vulkan side runs the float64 kernel: ranges of hits on the
 * same triangle must then be bit-identical */
static int exact_ranges;

typedef struct tally {
    uint64_t elements, identical, hit_diff, prim_diff, edge_ok;
    uint64_t same_hits, same_ranges; /* hits on the same triangle, and those with bit-identical ranges */
    double max_range_rel;
} tally;

/* Does the BVH answer for this ray change under a 1e-6 relative nudge? */
static int near_edge(const side *bvh, const rc_pose *pose, const float d[3], const float *o, float rmin, float rmax,
                     uint32_t model)
{
    float dirs[3 * 7], origins[3 * 7];
    rc_rays_desc rd = rc_rays_desc_default();
    rc_sensor *s = NULL;
    rct_buffers buf;
    rc_pose poses[1];
    int k, changed = 0;
    for (k = 0; k < 7; ++k) {
        int j;
        for (j = 0; j < 3; ++j) {
            dirs[3 * k + j] = d[j];
            origins[3 * k + j] = o ? o[j] : 0.0f;
        }
        if (k > 0) dirs[3 * k + (k - 1) / 2] += ((k & 1) ? 1e-6f : -1e-6f);
    }
    rd.common.range_min = rmin;
    rd.common.range_max = rmax;
    rd.directions = dirs;
    rd.origins = model == RC_SENSOR_ONDN ? origins : NULL;
    rd.ray_count = 7;
    RCT_OK(bvh->ctx, rc_sensor_create_rays(bvh->ctx, model == RC_SENSOR_ONDN ? RC_SENSOR_ONDN : RC_SENSOR_O1DN, &rd, &s));
    rct_buffers_alloc(&buf, 7, RC_ATTR_HITS | RC_ATTR_PRIM_IDS | RC_ATTR_GEOM_IDS | RC_ATTR_INST_IDS);
    poses[0] = *pose;
    RCT_OK(bvh->ctx, rc_simulate(bvh->ctx, bvh->scene, s, poses, 1, &buf.res));
    for (k = 1; k < 7; ++k)
        if (buf.res.hits[k] != buf.res.hits[0] || buf.res.prim_ids[k] != buf.res.prim_ids[0] ||
            buf.res.geom_ids[k] != buf.res.geom_ids[0] || buf.res.inst_ids[k] != buf.res.inst_ids[0])
            changed = 1;
    rct_buffers_free(&buf);
    rc_sensor_destroy(s);
    return changed;
}

static int same_bits(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

static void compare(const side *bvh, const rc_sensor *sb, const rc_pose *poses, uint32_t pose_count,
                    const rct_buffers *a, const rct_buffers *b, tally *t)
{
    const struct rc_sensor *in = (const struct rc_sensor *)sb;
    const uint32_t rays = in->rays;
    uint64_t k, n = (uint64_t)pose_count * rays;
    for (k = 0; k < n; ++k) {
        const uint32_t p = (uint32_t)(k / rays), r = (uint32_t)(k % rays);
        int ids_equal = a->res.hits[k] == b->res.hits[k] && a->res.prim_ids[k] == b->res.prim_ids[k] &&
                        a->res.geom_ids[k] == b->res.geom_ids[k] && a->res.inst_ids[k] == b->res.inst_ids[k];
        t->elements++;
        if (ids_equal && a->res.hits[k]) {
            t->same_hits++;
            t->same_ranges += same_bits(&a->res.ranges[k], &b->res.ranges[k], 4);
        }
        if (ids_equal && same_bits(&a->res.ranges[k], &b->res.ranges[k], 4) &&
            same_bits(a->res.points + 3 * k, b->res.points + 3 * k, 12) &&
            same_bits(a->res.normals + 3 * k, b->res.normals + 3 * k, 12))
            t->identical++;
        if (!ids_equal) {
            if (a->res.hits[k] != b->res.hits[k])
                t->hit_diff++;
            else
                t->prim_diff++;
            if (!near_edge(bvh, &poses[p], in->directions + 3u * r, in->origins ? in->origins + 3u * r : NULL,
                           in->range_min, in->range_max, in->model))
                fail_msg("pose %u ray %u: bvh hit %u prim %u geom %u inst %u range %.9g; vulkan hit %u prim %u geom "
                         "%u inst %u range %.9g, and the ray is not near an edge",
                         p, r, a->res.hits[k], a->res.prim_ids[k], a->res.geom_ids[k], a->res.inst_ids[k],
                         (double)a->res.ranges[k], b->res.hits[k], b->res.prim_ids[k], b->res.geom_ids[k],
                         b->res.inst_ids[k], (double)b->res.ranges[k]);
            t->edge_ok++;
        }
        if (a->res.hits[k] && b->res.hits[k]) {
            const double ra = a->res.ranges[k], rb = b->res.ranges[k], rel = fabs(ra - rb) / ra;
            int j;
            if (rel > t->max_range_rel) t->max_range_rel = rel;
            if (rel > 1e-5) fail_msg("pose %u ray %u: range %.9g (bvh) vs %.9g (vulkan)", p, r, ra, rb);
            for (j = 0; j < 3; ++j) {
                if (fabs(a->res.points[3 * k + j] - b->res.points[3 * k + j]) > 1e-5 * ra)
                    fail_msg("pose %u ray %u: point[%d] %.9g vs %.9g", p, r, j, (double)a->res.points[3 * k + j],
                             (double)b->res.points[3 * k + j]);
                if (ids_equal && fabs(a->res.normals[3 * k + j] - b->res.normals[3 * k + j]) > 1e-5)
                    fail_msg("pose %u ray %u: normal[%d] %.9g vs %.9g", p, r, j, (double)a->res.normals[3 * k + j],
                             (double)b->res.normals[3 * k + j]);
            }
        } else if (!a->res.hits[k] && !b->res.hits[k]) {
            /* both invalid: the same REP 117 reading (+inf / -inf), NaN points, invalid ids */
            if (!same_bits(&a->res.ranges[k], &b->res.ranges[k], 4))
                fail_msg("pose %u ray %u: no-return range %g vs %g", p, r, (double)a->res.ranges[k],
                         (double)b->res.ranges[k]);
            if (!isnan(b->res.points[3 * k]) || !isnan(b->res.normals[3 * k + 2]) || b->res.prim_ids[k] != RC_INVALID_ID)
                fail_msg("pose %u ray %u: invalid return with a point, normal or id", p, r);
        }
    }
    /* mismatches are rare by nature: more than 1 in 10^4 means something else */
    if ((t->hit_diff + t->prim_diff) * 10000u > t->elements + 10000u)
        fail_msg("%llu of %llu elements differ", (unsigned long long)(t->hit_diff + t->prim_diff),
                 (unsigned long long)t->elements);
}

static void run_both(side *bvh, side *vk, rc_sensor *sb, rc_sensor *sv, const rc_pose *poses, uint32_t n,
                     tally *t)
{
    rc_sensor_info info = rc_sensor_info_default();
    rct_buffers a, b;
    RCT_OK(bvh->ctx, rc_sensor_get_info(sb, &info));
    rct_buffers_alloc(&a, (uint64_t)n * info.rays_per_scan, RC_ATTR_ALL);
    rct_buffers_alloc(&b, (uint64_t)n * info.rays_per_scan, RC_ATTR_ALL);
    rct_buffers_fill(&b, 0xCD);
    RCT_OK(bvh->ctx, rc_simulate(bvh->ctx, bvh->scene, sb, poses, n, &a.res));
    RCT_OK(vk->ctx, rc_simulate(vk->ctx, vk->scene, sv, poses, n, &b.res));
    compare(bvh, sb, poses, n, &a, &b, t);
    rct_buffers_free(&a);
    rct_buffers_free(&b);
}

static void random_dirs(uint32_t n, uint64_t seed, float *dirs, float *origins)
{
    rcu_rng rng;
    uint32_t i;
    rcu_rng_seed(&rng, seed);
    for (i = 0; i < n; ++i) {
        double z = 2.0 * rcu_rng_uniform(&rng) - 1.0, a = 2.0 * PI * rcu_rng_uniform(&rng);
        double s = sqrt(1.0 - z * z);
        dirs[3 * i] = (float)(s * cos(a));
        dirs[3 * i + 1] = (float)(s * sin(a));
        dirs[3 * i + 2] = (float)z;
        if (origins) {
            int j;
            for (j = 0; j < 3; ++j) origins[3 * i + j] = (float)(rcu_rng_uniform(&rng) - 0.5);
        }
    }
    /* a few axis-parallel rays: zero direction components */
    for (i = 0; i < 6 && i < n; ++i) {
        dirs[3 * i] = dirs[3 * i + 1] = dirs[3 * i + 2] = 0.0f;
        dirs[3 * i + i / 2] = (i & 1) ? -1.0f : 1.0f;
    }
}

static void report(const char *what, const tally *t)
{
    print_message("%-28s %8llu elements, %6.2f%% bit-identical, %llu hit / %llu id differences (all at edges), "
                  "max range difference %.2g relative\n",
                  what, (unsigned long long)t->elements, 100.0 * (double)t->identical / (double)t->elements,
                  (unsigned long long)t->hit_diff, (unsigned long long)t->prim_diff, t->max_range_rel);
    if (exact_ranges && t->same_ranges != t->same_hits)
        fail_msg("%s: %llu of %llu hits on the same triangle have a range that is not bit-identical (float64 kernel)",
                 what, (unsigned long long)(t->same_hits - t->same_ranges), (unsigned long long)t->same_hits);
}

/* The whole comparison under the current environment (kernel variant, limits). */
static void parity_suite(const char *label, int quick)
{
    side bvh, vk;
    tally t;
    char what[64];
    const uint32_t nrays = quick ? 4000u : 20000u, nposes = quick ? 3u : 8u, vposes = quick ? 4u : 16u;
    rc_pose poses[16];
    float *dirs = (float *)malloc(sizeof(float) * 3u * nrays);
    float *origins = (float *)malloc(sizeof(float) * 3u * nrays);
    rc_rays_desc rd = rc_rays_desc_default();
    rc_sensor *sb, *sv;
    assert_non_null(dirs);
    assert_non_null(origins);
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) {
        free(dirs);
        free(origins);
        skip();
    }
    side_make(&bvh, RC_BACKEND_BVH);
    side_make(&vk, RC_BACKEND_VULKAN);
    exact_ranges = rc__vk(vk.ctx)->fp64 != 0;
    rcu_poses_random(16, 10.0f, 7, poses);

    /* random O1Dn rays */
    random_dirs(nrays, 11, dirs, NULL);
    rd.common.range_min = 0.3f;
    rd.common.range_max = 60.0f;
    rd.directions = dirs;
    rd.ray_count = nrays;
    RCT_OK(bvh.ctx, rc_sensor_create_rays(bvh.ctx, RC_SENSOR_O1DN, &rd, &sb));
    RCT_OK(vk.ctx, rc_sensor_create_rays(vk.ctx, RC_SENSOR_O1DN, &rd, &sv));
    memset(&t, 0, sizeof t);
    run_both(&bvh, &vk, sb, sv, poses, nposes, &t);
    snprintf(what, sizeof what, "%s o1dn", label);
    report(what, &t);

    /* OnDn: origins spread around the pose, a range_min that cuts some hits (-inf) */
    random_dirs(nrays, 12, dirs, origins);
    rd.origins = origins;
    rd.common.range_min = 2.0f;
    rd.common.range_max = 25.0f;
    rd.common.sensor_to_base = rct_pose_ypr(0.1f, -0.2f, 0.3f, 0.5, 0.1, -0.3);
    RCT_OK(bvh.ctx, rc_sensor_create_rays(bvh.ctx, RC_SENSOR_ONDN, &rd, &sb));
    RCT_OK(vk.ctx, rc_sensor_create_rays(vk.ctx, RC_SENSOR_ONDN, &rd, &sv));
    memset(&t, 0, sizeof t);
    run_both(&bvh, &vk, sb, sv, poses + 8, nposes, &t);
    snprintf(what, sizeof what, "%s ondn", label);
    report(what, &t);

    /* VLP-16, the standard workload's sensor, a batch of poses */
    RCT_OK(bvh.ctx, rc_sensor_create_preset(bvh.ctx, RC_PRESET_VELODYNE_VLP16, &sb));
    RCT_OK(vk.ctx, rc_sensor_create_preset(vk.ctx, RC_PRESET_VELODYNE_VLP16, &sv));
    memset(&t, 0, sizeof t);
    run_both(&bvh, &vk, sb, sv, poses, vposes, &t);
    snprintf(what, sizeof what, "%s vlp16", label);
    report(what, &t);

    /* pinhole, both frames, and a cylindrical panorama */
    {
        rc_pinhole_desc pd = rc_pinhole_desc_default();
        rc_cylindrical_desc cd = rc_cylindrical_desc_default();
        assert_int_equal(rc_preset_pinhole(RC_PRESET_REALSENSE_D435, &pd), RC_OK);
        pd.common.range_max = 40.0f;
        { /* a quarter (quick: a sixteenth) of the D435's pixels, same field of view */
            const float k = quick ? 4.0f : 2.0f;
            pd.width = (uint32_t)((float)pd.width / k);
            pd.height = (uint32_t)((float)pd.height / k);
            pd.fx /= k;
            pd.fy /= k;
            pd.cx /= k;
            pd.cy /= k;
        }
        RCT_OK(bvh.ctx, rc_sensor_create_pinhole(bvh.ctx, &pd, &sb));
        RCT_OK(vk.ctx, rc_sensor_create_pinhole(vk.ctx, &pd, &sv));
        memset(&t, 0, sizeof t);
        run_both(&bvh, &vk, sb, sv, poses + 3, 2, &t);
        pd.frame = RC_PINHOLE_FRAME_OPTICAL;
        RCT_OK(bvh.ctx, rc_sensor_create_pinhole(bvh.ctx, &pd, &sb));
        RCT_OK(vk.ctx, rc_sensor_create_pinhole(vk.ctx, &pd, &sv));
        run_both(&bvh, &vk, sb, sv, poses + 5, 2, &t);
        snprintf(what, sizeof what, "%s pinhole", label);
        report(what, &t);
        cd.common.range_min = 0.2f;
        cd.common.range_max = 80.0f;
        cd.theta.min = (float)-PI;
        cd.theta.increment = (float)(2.0 * PI / 720.0);
        cd.theta.count = 720;
        cd.height = 64;
        cd.fy = 60.0f;
        cd.cy = 31.5f;
        RCT_OK(bvh.ctx, rc_sensor_create_cylindrical(bvh.ctx, &cd, &sb));
        RCT_OK(vk.ctx, rc_sensor_create_cylindrical(vk.ctx, &cd, &sv));
        memset(&t, 0, sizeof t);
        run_both(&bvh, &vk, sb, sv, poses + 7, 3, &t);
        snprintf(what, sizeof what, "%s cylindrical", label);
        report(what, &t);
    }
    side_free(&bvh);
    side_free(&vk);
    free(dirs);
    free(origins);
}

static void test_parity_default(void **state)
{
    (void)state;
    parity_suite("float64 kernel:", rct_quick());
}

static void test_parity_float_only(void **state)
{
    (void)state;
    setenv("RANGECAST_VULKAN_NO_FP64", "1", 1);
    parity_suite("float-only kernel:", 1);
    unsetenv("RANGECAST_VULKAN_NO_FP64");
}

/* 512 KiB bindings: nodes over 4 buffers, triangles over 3, many dispatches
 * through two alternating result buffers, uploads through staging copies. */
static void test_parity_split_bindings(void **state)
{
    (void)state;
    setenv("RANGECAST_VULKAN_MAX_BINDING", "524288", 1);
    setenv("RANGECAST_VULKAN_STAGING", "1", 1);
    parity_suite("split bindings, staged:", 1);
    unsetenv("RANGECAST_VULKAN_MAX_BINDING");
    unsetenv("RANGECAST_VULKAN_STAGING");
}

/* A UTM-scale map: scene origin far away, double poses (rc_simulate_d). */
static void test_parity_far_origin(void **state)
{
    const double origin[3] = {512345.25, 4987654.5, 213.75};
    side sides[2];
    rc_pose base[8];
    rc_pose_d poses[8];
    rct_buffers a, b;
    uint32_t i, k, n, diff = 0, identical = 0;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip();
    rcu_poses_random(8, 10.0f, 21, base);
    for (i = 0; i < 8; ++i) {
        for (k = 0; k < 3; ++k) poses[i].position[k] = origin[k] + base[i].position[k];
        for (k = 0; k < 4; ++k) poses[i].orientation[k] = base[i].orientation[k];
    }
    for (i = 0; i < 2; ++i) {
        rc_scene_desc sd = rc_scene_desc_default();
        rc_mesh_desc md = rc_mesh_desc_default();
        rc_sensor *sensor;
        uint32_t g;
        sides[i].ctx = rct_context(i ? RC_BACKEND_VULKAN : RC_BACKEND_BVH, 2, 64);
        sd.max_triangles = g_world.sphere.triangle_count;
        memcpy(sd.origin, origin, sizeof sd.origin);
        RCT_OK(sides[i].ctx, rc_scene_create(sides[i].ctx, &sd, &sides[i].scene));
        md.vertices = g_world.sphere.vertices;
        md.vertex_count = g_world.sphere.vertex_count;
        md.indices = g_world.sphere.indices;
        md.triangle_count = g_world.sphere.triangle_count;
        RCT_OK(sides[i].ctx, rc_scene_add_mesh(sides[i].scene, &md, &g));
        RCT_OK(sides[i].ctx, rc_scene_commit(sides[i].scene));
        RCT_OK(sides[i].ctx, rc_sensor_create_preset(sides[i].ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
        rct_buffers_alloc(i ? &b : &a, 8u * 14400u, RC_ATTR_ALL);
        RCT_OK(sides[i].ctx, rc_simulate_d(sides[i].ctx, sides[i].scene, sensor, poses, 8, i ? &b.res : &a.res));
    }
    n = 8u * 14400u;
    for (k = 0; k < n; ++k) {
        assert_int_equal(a.res.hits[k], 1); /* inside a closed sphere */
        if (a.res.prim_ids[k] != b.res.prim_ids[k] || a.res.hits[k] != b.res.hits[k]) ++diff;
        if (fabs(a.res.ranges[k] - b.res.ranges[k]) > 1e-5 * a.res.ranges[k])
            fail_msg("ray %u: range %.9g (bvh) vs %.9g (vulkan)", k, (double)a.res.ranges[k], (double)b.res.ranges[k]);
        identical += memcmp(&a.res.ranges[k], &b.res.ranges[k], 4) == 0 &&
                     memcmp(a.res.points + 3u * k, b.res.points + 3u * k, 12) == 0 &&
                     memcmp(a.res.normals + 3u * k, b.res.normals + 3u * k, 12) == 0;
    }
    print_message("far origin, double poses:     %8u elements, %6.2f%% bit-identical, %u id differences\n", n,
                  100.0 * identical / n, diff);
    assert_true(diff * 10000u <= n);
    rct_buffers_free(&a);
    rct_buffers_free(&b);
    side_free(&sides[0]);
    side_free(&sides[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parity_default),
        cmocka_unit_test(test_parity_float_only),
        cmocka_unit_test(test_parity_split_bindings),
        cmocka_unit_test(test_parity_far_origin),
    };
    return cmocka_run_group_tests_name("vulkan parity with the BVH backend", tests, setup, teardown);
}
