/* Embree against the built-in backend, and the Embree backend's own options.
 *
 * test_parity: the same scene and rays on both backends: a ~100k
 * triangle UV sphere (radius 20, referenced packed xyz: Embree copies it), a
 * mesh of boxes (RC_MESH_COPY: shared in place), a mesh of boxes with a
 * 16-byte vertex stride (shared in place), and two scaled, rotated instances
 * of a unit box scene. Rays: 4096 random rays from random origins (OnDn: runs
 * of consecutive rays make the packets) and a VLP-16 (tiles of its grid), two
 * poses each, through every packet width (1, 4, 8, 16), with the hits'
 * triangles prefetched before the write (as on a large map) and without.
 *
 * Agreement: hit flags equal, except rays passing within 1e-6 (relative to
 * the range) of an edge of the triangle either backend hit; ranges within
 * 1e-5 relative; triangle, geometry and instance ids equal where the hit is
 * unambiguous (no edge that near); points and normals to float accuracy.
 *
 * Then: every build quality gives the same ranges; the tie rule on duplicate
 * triangles (also instanced); rc_scene_update_mesh on shared and copied
 * vertices; a sensor on a surface (t = 0 is no return); commit progress. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_test.h"

#include "backend/backend.h"
#include "backend/embree_internal.h"
#include "poses.h"

#define EDGE_REL 1e-6
#define RANGE_REL 1e-5
#define NRAYS 4096u
#define NPOSES 2u

typedef struct world {
    rcu_mesh sphere;         /* geometry 0: referenced, stride 12 */
    rcu_mesh boxes;          /* geometry 1: RC_MESH_COPY */
    rcu_mesh strided;        /* geometry 2: the same layout as boxes16 (x y z per vertex) */
    float *boxes16;          /* geometry 2 as referenced: x y z pad, stride 16 */
    rcu_mesh unit_box;       /* the instanced scene */
    rc_pose inst_pose[2];
    float inst_scale[2][3];
} world;

static void make_world(world *w)
{
    static const float lo[6][3] = {{2, 3, -4},     {-9, -2, -1.5f}, {-3, -11, 2},
                                   {6.5f, -6, 5},  {-1, 8, -9},     {10, 1, -2}};
    static const float hi[6][3] = {{4.5f, 5, -1},  {-6, 1, 2},      {1, -8.5f, 3.25f},
                                   {9, -3, 8},     {2, 9.5f, -6},   {12, 3.5f, 1}};
    const float unit_lo[3] = {-0.5f, -0.5f, -0.5f}, unit_hi[3] = {0.5f, 0.5f, 0.5f};
    uint32_t i;
    memset(w, 0, sizeof *w);
    assert_int_equal(rcu_mesh_uv_sphere_triangles(20.0f, 100000, &w->sphere), 0);
    for (i = 0; i < 6; ++i) {
        rcu_mesh b;
        assert_int_equal(rcu_mesh_box(lo[i], hi[i], &b), 0);
        assert_int_equal(rcu_mesh_append(i < 3 ? &w->boxes : &w->strided, &b), 0);
        rcu_mesh_free(&b);
    }
    w->boxes16 = (float *)malloc(sizeof(float) * 4u * w->strided.vertex_count);
    assert_non_null(w->boxes16);
    for (i = 0; i < w->strided.vertex_count; ++i) {
        memcpy(w->boxes16 + 4u * i, w->strided.vertices + 3u * i, 3 * sizeof(float));
        w->boxes16[4u * i + 3u] = -1.0f;
    }
    assert_int_equal(rcu_mesh_box(unit_lo, unit_hi, &w->unit_box), 0);
    w->inst_pose[0] = rct_pose_ypr(-4.0f, 6.0f, 4.0f, 0.4, 0.2, -0.3);
    w->inst_scale[0][0] = 3.0f;
    w->inst_scale[0][1] = 1.5f;
    w->inst_scale[0][2] = 0.75f;
    w->inst_pose[1] = rct_pose_ypr(5.0f, -12.0f, -5.0f, -1.1, 0.0, 0.6);
    w->inst_scale[1][0] = w->inst_scale[1][1] = w->inst_scale[1][2] = 2.0f;
}

static void free_world(world *w)
{
    rcu_mesh_free(&w->sphere);
    rcu_mesh_free(&w->boxes);
    rcu_mesh_free(&w->strided);
    rcu_mesh_free(&w->unit_box);
    free(w->boxes16);
}

static rc_scene *build_scene(rc_context *ctx, const world *w)
{
    rc_scene *box, *top;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    uint32_t g, i;
    box = rct_scene_mesh(ctx, &w->unit_box, RC_MESH_REFERENCE);
    sd.max_geometries = 3;
    sd.max_instances = 2;
    sd.max_triangles = (uint64_t)w->sphere.triangle_count + w->boxes.triangle_count + w->strided.triangle_count;
    sd.max_vertices = w->boxes.vertex_count;
    sd.max_copied_triangles = w->boxes.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &top));
    md.vertices = w->sphere.vertices;
    md.vertex_count = w->sphere.vertex_count;
    md.indices = w->sphere.indices;
    md.triangle_count = w->sphere.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(top, &md, &g));
    md.flags = RC_MESH_COPY;
    md.vertices = w->boxes.vertices;
    md.vertex_count = w->boxes.vertex_count;
    md.indices = w->boxes.indices;
    md.triangle_count = w->boxes.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(top, &md, &g));
    md.flags = RC_MESH_REFERENCE;
    md.vertices = w->boxes16;
    md.vertex_stride = 16;
    md.vertex_count = w->strided.vertex_count;
    md.indices = w->strided.indices;
    md.triangle_count = w->strided.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(top, &md, &g));
    assert_int_equal(g, 2);
    for (i = 0; i < 2; ++i) {
        id.source = box;
        id.transform = w->inst_pose[i];
        memcpy(id.scale, w->inst_scale[i], sizeof id.scale);
        RCT_OK(ctx, rc_scene_add_instance(top, &id, &g));
    }
    RCT_OK(ctx, rc_scene_commit(top));
    return top;
}

/* Triangle (inst, geom, prim) of the world in map coordinates, double. */
static void world_triangle(const world *w, uint32_t inst, uint32_t geom, uint32_t prim, double v[3][3])
{
    const rcu_mesh *m;
    int k, j;
    if (inst != RC_INVALID_ID) {
        const rc_pose *p = &w->inst_pose[inst];
        rc__xform x;
        m = &w->unit_box;
        rc__xform_from_pose(p, &x);
        for (k = 0; k < 3; ++k) {
            const float *a = m->vertices + 3u * m->indices[3u * prim + (uint32_t)k];
            double s[3];
            for (j = 0; j < 3; ++j) s[j] = (double)a[j] * w->inst_scale[inst][j];
            for (j = 0; j < 3; ++j)
                v[k][j] = x.r[3 * j] * s[0] + x.r[3 * j + 1] * s[1] + x.r[3 * j + 2] * s[2] + x.t[j];
        }
        return;
    }
    m = geom == 0 ? &w->sphere : geom == 1 ? &w->boxes : &w->strided;
    for (k = 0; k < 3; ++k)
        for (j = 0; j < 3; ++j) v[k][j] = m->vertices[3u * m->indices[3u * prim + (uint32_t)k] + (uint32_t)j];
}

/* Distance from the ray's hit on the triangle's plane to the nearest edge
 * line of the triangle, over the distance along the ray. */
static double edge_closeness(const double o[3], const double d[3], double v[3][3])
{
    double e1[3], e2[3], n[3], w0[3], dn, t, p[3], best = INFINITY;
    int k, j;
    for (j = 0; j < 3; ++j) {
        e1[j] = v[1][j] - v[0][j];
        e2[j] = v[2][j] - v[0][j];
        w0[j] = v[0][j] - o[j];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    dn = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (dn == 0.0) return 0.0;
    t = (n[0] * w0[0] + n[1] * w0[1] + n[2] * w0[2]) / dn;
    for (j = 0; j < 3; ++j) p[j] = o[j] + t * d[j];
    for (k = 0; k < 3; ++k) {
        const double *a = v[k], *b = v[(k + 1) % 3];
        double e[3], q[3], c[3], len, dist;
        for (j = 0; j < 3; ++j) {
            e[j] = b[j] - a[j];
            q[j] = p[j] - a[j];
        }
        c[0] = q[1] * e[2] - q[2] * e[1];
        c[1] = q[2] * e[0] - q[0] * e[2];
        c[2] = q[0] * e[1] - q[1] * e[0];
        len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        dist = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / len;
        if (dist < best) best = dist;
    }
    return best / (fabs(t) > 1e-9 ? fabs(t) : 1e-9);
}

typedef struct tally {
    uint32_t compared, ambiguous, hit_mismatch, id_mismatch;
} tally;

/* Compares one batch element by element. */
static void compare(const world *w, const rc_sensor *sensor, const rc_pose *poses, uint32_t pose_count,
                    const rct_buffers *ref, const rct_buffers *emb, const char *what, tally *tl)
{
    uint32_t rays = sensor->rays, p, r;
    for (p = 0; p < pose_count; ++p) {
        rc__xformf world_x;
        rc__sensor_world_xform(sensor, &poses[p], &world_x);
        for (r = 0; r < rays; ++r) {
            uint64_t k = (uint64_t)p * rays + r;
            float of[3], df[3];
            double o[3], d[3], close = INFINITY;
            int j, hr = ref->res.hits[k], he = emb->res.hits[k];
            /* the float ray both backends traced, as they compute it */
            rc__rot_apply_f(world_x.r, sensor->directions + 3u * r, df);
            if (sensor->origins) {
                rc__rot_apply_f(world_x.r, sensor->origins + 3u * r, of);
                for (j = 0; j < 3; ++j) of[j] += world_x.t[j];
            } else {
                for (j = 0; j < 3; ++j) of[j] = world_x.t[j];
            }
            for (j = 0; j < 3; ++j) {
                o[j] = of[j];
                d[j] = df[j];
            }
            if (hr) {
                double v[3][3];
                world_triangle(w, ref->res.inst_ids[k], ref->res.geom_ids[k], ref->res.prim_ids[k], v);
                close = edge_closeness(o, d, v);
            }
            if (he) {
                double v[3][3], c;
                world_triangle(w, emb->res.inst_ids[k], emb->res.geom_ids[k], emb->res.prim_ids[k], v);
                c = edge_closeness(o, d, v);
                if (c < close) close = c;
            }
            tl->compared++;
            if (close < EDGE_REL) {
                tl->ambiguous++;
                if (hr && he && fabs(ref->res.ranges[k] - emb->res.ranges[k]) > RANGE_REL * ref->res.ranges[k])
                    fail_msg("%s: element %llu near an edge: ranges %.9g (bvh) and %.9g (embree) differ", what,
                             (unsigned long long)k, (double)ref->res.ranges[k], (double)emb->res.ranges[k]);
                continue;
            }
            if (hr != he) {
                tl->hit_mismatch++;
                fail_msg("%s: element %llu: hit %d (bvh) vs %d (embree), edge closeness %.3g", what,
                         (unsigned long long)k, hr, he, close);
            }
            if (!hr) {
                assert_true(isinf(emb->res.ranges[k]) && isinf(ref->res.ranges[k]));
                continue;
            }
            if (fabs(ref->res.ranges[k] - emb->res.ranges[k]) > RANGE_REL * ref->res.ranges[k])
                fail_msg("%s: element %llu: range %.9g (bvh) vs %.9g (embree)", what, (unsigned long long)k,
                         (double)ref->res.ranges[k], (double)emb->res.ranges[k]);
            if (ref->res.prim_ids[k] != emb->res.prim_ids[k] || ref->res.geom_ids[k] != emb->res.geom_ids[k] ||
                ref->res.inst_ids[k] != emb->res.inst_ids[k]) {
                tl->id_mismatch++;
                fail_msg("%s: element %llu: ids (inst %u, geom %u, prim %u) (bvh) vs (inst %u, geom %u, prim %u) "
                         "(embree), edge closeness %.3g",
                         what, (unsigned long long)k, ref->res.inst_ids[k], ref->res.geom_ids[k],
                         ref->res.prim_ids[k], emb->res.inst_ids[k], emb->res.geom_ids[k], emb->res.prim_ids[k],
                         close);
            }
            for (j = 0; j < 3; ++j) {
                float pr = ref->res.points[3u * k + (uint32_t)j], pe = emb->res.points[3u * k + (uint32_t)j];
                float nr = ref->res.normals[3u * k + (uint32_t)j], ne = emb->res.normals[3u * k + (uint32_t)j];
                if (fabs(pr - pe) > RANGE_REL * ref->res.ranges[k] + 1e-6)
                    fail_msg("%s: element %llu: point[%d] %.9g vs %.9g", what, (unsigned long long)k, j, (double)pr,
                             (double)pe);
                if (nr != ne) fail_msg("%s: element %llu: normal[%d] %.9g vs %.9g", what, (unsigned long long)k, j,
                                       (double)nr, (double)ne);
            }
        }
    }
}

static rc_sensor *random_rays_sensor(rc_context *ctx, float *origins, float *dirs)
{
    rc_rays_desc d = rc_rays_desc_default();
    rc_sensor *s = NULL;
    d.common.range_min = 0.0f;
    d.common.range_max = 100.0f;
    d.directions = dirs;
    d.origins = origins;
    d.ray_count = NRAYS;
    RCT_OK(ctx, rc_sensor_create_rays(ctx, RC_SENSOR_ONDN, &d, &s));
    return s;
}

static void make_rays(float *origins, float *dirs)
{
    rcu_rng rng;
    uint32_t i;
    rcu_rng_seed(&rng, 20240611u);
    for (i = 0; i < NRAYS; ++i) {
        double z = 2.0 * rcu_rng_uniform(&rng) - 1.0, a = 6.283185307179586 * rcu_rng_uniform(&rng);
        double rr = sqrt(1.0 - z * z), rad = 12.0 * cbrt(rcu_rng_uniform(&rng));
        double z2 = 2.0 * rcu_rng_uniform(&rng) - 1.0, a2 = 6.283185307179586 * rcu_rng_uniform(&rng);
        double rr2 = sqrt(1.0 - z2 * z2);
        dirs[3 * i] = (float)(rr * cos(a));
        dirs[3 * i + 1] = (float)(rr * sin(a));
        dirs[3 * i + 2] = (float)z;
        origins[3 * i] = (float)(rad * rr2 * cos(a2));
        origins[3 * i + 1] = (float)(rad * rr2 * sin(a2));
        origins[3 * i + 2] = (float)(rad * z2);
    }
}

static void test_parity(void **state)
{
    static const uint32_t widths[] = {0, 1, 4, 8, 16};
    rc_context *cb, *ce;
    rc_scene *sb, *se;
    rc_sensor *rays_b, *rays_e, *lidar_b, *lidar_e;
    rc__embree_options *opt;
    world w;
    float *origins = (float *)malloc(sizeof(float) * 3u * NRAYS), *dirs = (float *)malloc(sizeof(float) * 3u * NRAYS);
    rct_buffers ref_rays, ref_lidar, emb;
    rc_pose poses[NPOSES], lidar_poses[NPOSES];
    tally tl;
    uint32_t i, lidar_rays = 16u * 900u;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_non_null(origins);
    assert_non_null(dirs);
    make_world(&w);
    make_rays(origins, dirs);
    poses[0] = rct_pose(0, 0, 0);
    poses[1] = rct_pose_ypr(0.5f, -0.25f, 0.125f, 0.9, -0.35, 0.2);
    rcu_poses_random(NPOSES, 10.0f, 7u, lidar_poses);

    cb = rct_context(RC_BACKEND_BVH, 2, 128);
    ce = rct_context(RC_BACKEND_EMBREE, 2, 64);
    opt = rc__embree_options_of(ce);
    assert_non_null(opt);
    assert_null(rc__embree_options_of(cb));
    sb = build_scene(cb, &w);
    se = build_scene(ce, &w);
    rays_b = random_rays_sensor(cb, origins, dirs);
    rays_e = random_rays_sensor(ce, origins, dirs);
    RCT_OK(cb, rc_sensor_create_preset(cb, RC_PRESET_VELODYNE_VLP16, &lidar_b));
    RCT_OK(ce, rc_sensor_create_preset(ce, RC_PRESET_VELODYNE_VLP16, &lidar_e));

    rct_buffers_alloc(&ref_rays, NPOSES * NRAYS, RC_ATTR_ALL);
    rct_buffers_alloc(&ref_lidar, NPOSES * lidar_rays, RC_ATTR_ALL);
    rct_buffers_alloc(&emb, NPOSES * lidar_rays, RC_ATTR_ALL);
    RCT_OK(cb, rc_simulate(cb, sb, rays_b, poses, NPOSES, &ref_rays.res));
    RCT_OK(cb, rc_simulate(cb, sb, lidar_b, lidar_poses, NPOSES, &ref_lidar.res));

    memset(&tl, 0, sizeof tl);
    /* every width, with the hits' triangles prefetched (as on a large map:
     * the threshold pinned to 0) and without */
    for (i = 0; i < 2u * (sizeof widths / sizeof widths[0]); ++i) {
        char what[96];
        const char *pf = i % 2u ? "prefetched" : "not prefetched";
        opt->packet_width = widths[i / 2u];
        ce->large_mesh_bytes = i % 2u ? 0u : UINT64_MAX;
        rct_buffers_fill(&emb, 0xCD);
        RCT_OK(ce, rc_simulate(ce, se, rays_e, poses, NPOSES, &emb.res));
        snprintf(what, sizeof what, "random rays, packet width %u, %s", (unsigned)opt->packet_width, pf);
        compare(&w, rays_e, poses, NPOSES, &ref_rays, &emb, what, &tl);
        rct_buffers_fill(&emb, 0xCD);
        RCT_OK(ce, rc_simulate(ce, se, lidar_e, lidar_poses, NPOSES, &emb.res));
        snprintf(what, sizeof what, "VLP-16, packet width %u, %s", (unsigned)opt->packet_width, pf);
        compare(&w, lidar_e, lidar_poses, NPOSES, &ref_lidar, &emb, what, &tl);
    }
    print_message("parity: %u elements compared, %u within %.0e of an edge (skipped), 0 mismatches\n",
                  (unsigned)tl.compared, (unsigned)tl.ambiguous, EDGE_REL);
    /* edges are rare: a handful per million */
    assert_true(tl.ambiguous * 1000u < tl.compared);

    rct_buffers_free(&ref_rays);
    rct_buffers_free(&ref_lidar);
    rct_buffers_free(&emb);
    rc_context_destroy(cb);
    rc_context_destroy(ce);
    free_world(&w);
    free(origins);
    free(dirs);
}

/* rc_scene_desc.build_quality: every value gives the built-in backend's
 * answers on both backends (the built-in one accepts and ignores it); on
 * Embree COMPACT holds fewer bytes than BALANCED and FAST other bytes (its
 * two-level build), so both reach Embree. */
static void test_build_quality(void **state)
{
    static const uint32_t qualities[] = {RC_BUILD_BALANCED, RC_BUILD_FAST, RC_BUILD_HIGH, RC_BUILD_COMPACT};
    static const uint32_t backends[] = {RC_BACKEND_BVH, RC_BACKEND_EMBREE};
    rcu_mesh m;
    rct_buffers ref, cur;
    rc_pose poses[3];
    uint64_t embree_bytes[4] = {0, 0, 0, 0};
    uint32_t q, b, rays = 16u * 360u;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 200, 100, &m), 0);
    rcu_poses_random(3, 10.0f, 11u, poses);
    rct_buffers_alloc(&ref, 3u * rays, RC_ATTR_RANGES | RC_ATTR_HITS);
    rct_buffers_alloc(&cur, 3u * rays, RC_ATTR_RANGES | RC_ATTR_HITS);
    {
        rc_context *ctx = rct_context(RC_BACKEND_BVH, 2, 0);
        rc_scene *s = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
        rc_sensor *sensor;
        RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
        RCT_OK(ctx, rc_simulate(ctx, s, sensor, poses, 3, &ref.res));
        rc_context_destroy(ctx);
    }
    for (b = 0; b < 2; ++b)
        for (q = 0; q < 4; ++q) {
            rc_context *ctx = rct_context(backends[b], 2, 0);
            rc_memory_stats ms = rc_memory_stats_default();
            rc_scene *s = rct_scene_uncommitted(ctx, &m, RC_MESH_REFERENCE, qualities[q]);
            rc_sensor *sensor;
            uint32_t i;
            RCT_OK(ctx, rc_scene_commit(s));
            RCT_OK(ctx, rc_context_get_memory_stats(ctx, &ms));
            if (backends[b] == RC_BACKEND_EMBREE) {
                const rc__embree_options *opt = rc__embree_options_of(ctx);
                assert_int_equal(opt->robust, 1); /* robust whatever the quality */
                assert_int_equal(opt->tie_rule, 1);
                assert_int_equal(opt->budget_bytes, 0);
                embree_bytes[q] = ms.backend_bytes;
            }
            RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
            RCT_OK(ctx, rc_simulate(ctx, s, sensor, poses, 3, &cur.res));
            for (i = 0; i < 3u * rays; ++i) {
                assert_int_equal(cur.res.hits[i], 1);
                assert_int_equal(ref.res.hits[i], 1);
                if (fabs(cur.res.ranges[i] - ref.res.ranges[i]) > RANGE_REL * ref.res.ranges[i])
                    fail_msg("%s, build quality %u, ray %u: %.9g vs %.9g", rc_backend_name(backends[b]),
                             (unsigned)qualities[q], (unsigned)i, (double)cur.res.ranges[i],
                             (double)ref.res.ranges[i]);
            }
            rc_context_destroy(ctx);
        }
    print_message("Embree bytes: balanced %llu, fast %llu, high %llu, compact %llu\n",
                  (unsigned long long)embree_bytes[0], (unsigned long long)embree_bytes[1],
                  (unsigned long long)embree_bytes[2], (unsigned long long)embree_bytes[3]);
    assert_true(embree_bytes[3] > 0 && embree_bytes[3] < embree_bytes[0]);
    assert_true(embree_bytes[1] != embree_bytes[0]); /* FAST is Embree's two-level LOW build */
    rct_buffers_free(&ref);
    rct_buffers_free(&cur);
    rcu_mesh_free(&m);
}

/* The tie rule: a mesh holding its triangles twice reports the lower copy on
 * every ray, as the built-in backend does, also inside an instance. */
static void test_duplicate_triangles(void **state)
{
    rcu_mesh a, both;
    rc_context *ctx;
    rc_scene *scene, *top;
    rc_sensor *sensor;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    const float lo[3] = {2, -1, -1}, hi[3] = {4, 1, 1.5f};
    uint32_t i, n = 16u * 360u, g;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_uv_sphere(8.0f, 48, 24, &a), 0);
    memset(&both, 0, sizeof both);
    assert_int_equal(rcu_mesh_append(&both, &a), 0);
    assert_int_equal(rcu_mesh_append(&both, &a), 0);
    rcu_mesh_free(&a);
    assert_int_equal(rcu_mesh_box(lo, hi, &a), 0);
    assert_int_equal(rcu_mesh_append(&both, &a), 0); /* and a box inside it, once */
    ctx = rct_context(RC_BACKEND_EMBREE, 2, 0);
    scene = rct_scene_mesh(ctx, &both, RC_MESH_REFERENCE);
    sd.max_instances = 1;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &top));
    id.source = scene;
    RCT_OK(ctx, rc_scene_add_instance(top, &id, &g));
    RCT_OK(ctx, rc_scene_commit(top));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16_360, &sensor));
    rct_buffers_alloc(&buf, n, RC_ATTR_HITS | RC_ATTR_PRIM_IDS | RC_ATTR_INST_IDS);
    for (g = 0; g < 2; ++g) {
        RCT_OK(ctx, rc_simulate(ctx, g ? top : scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < n; ++i) {
            uint32_t prim = buf.res.prim_ids[i];
            assert_int_equal(buf.res.hits[i], 1);
            /* sphere copies are a.triangle_count apart; the box follows both */
            if (prim >= both.triangle_count - 12u) continue;
            if (prim >= (both.triangle_count - 12u) / 2u)
                fail_msg("ray %u hit the second copy (prim %u)", (unsigned)i, (unsigned)prim);
            assert_int_equal(buf.res.inst_ids[i], g ? 0u : RC_INVALID_ID);
        }
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&a);
    rcu_mesh_free(&both);
    rc_context_destroy(ctx);
}

/* Twin instances (the same source at the same transform, bit for bit) give
 * the same hit at the same distance: Embree's backend reports the lowest of
 * them, as the built-in backend does. Instances 1 and 3 are twins of 0;
 * instance 2 sits elsewhere (moved 0.5 m, so it is nearer on half the rays)
 * and keeps its own id. The twins move together between commits and stay
 * twins; moving instance 3 away parts it from them. */
static void test_twin_instances(void **state)
{
    rcu_mesh ball;
    rc_context *ctx[2];
    rc_scene *src[2], *top[2];
    rc_sensor *sensor[2];
    rct_buffers buf[2];
    uint32_t b, i, step, id, n = 16u * 360u;
    /* off the centre: rays from it run exactly along the sphere's seams, where
     * two triangles tie and the backends may name either */
    rc_pose pose = rct_pose(0.013f, -0.021f, 0.017f);
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_uv_sphere(8.0f, 48, 24, &ball), 0);
    for (b = 0; b < 2; ++b) {
        rc_scene_desc sd = rc_scene_desc_default();
        ctx[b] = rct_context(b ? RC_BACKEND_EMBREE : RC_BACKEND_BVH, 2, 0);
        src[b] = rct_scene_mesh(ctx[b], &ball, RC_MESH_REFERENCE);
        sd.max_instances = 4;
        RCT_OK(ctx[b], rc_scene_create(ctx[b], &sd, &top[b]));
        for (i = 0; i < 4; ++i) {
            rc_instance_desc idd = rc_instance_desc_default();
            idd.source = src[b];
            if (i == 2) idd.transform.position[0] = 0.5f;
            RCT_OK(ctx[b], rc_scene_add_instance(top[b], &idd, &id));
        }
        RCT_OK(ctx[b], rc_sensor_create_preset(ctx[b], RC_PRESET_VELODYNE_VLP16_360, &sensor[b]));
        rct_buffers_alloc(&buf[b], n, RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS | RC_ATTR_INST_IDS);
    }
    for (step = 0; step < 3; ++step) {
        uint32_t seen[4] = {0, 0, 0, 0};
        for (b = 0; b < 2; ++b) {
            if (step > 0) {
                /* step 1: the twins move together; step 2: instance 3 leaves
                 * them, to the other side (nearest where y > 0) */
                rc_pose p = rct_pose(0.0f, 0.25f, 0.0f);
                RCT_OK(ctx[b], rc_scene_set_instance_transform(top[b], 0, &p, NULL));
                RCT_OK(ctx[b], rc_scene_set_instance_transform(top[b], 1, &p, NULL));
                if (step == 2) p.position[1] = -0.25f;
                RCT_OK(ctx[b], rc_scene_set_instance_transform(top[b], 3, &p, NULL));
            }
            RCT_OK(ctx[b], rc_scene_commit(top[b]));
            RCT_OK(ctx[b], rc_simulate(ctx[b], top[b], sensor[b], &pose, 1, &buf[b].res));
        }
        for (i = 0; i < n; ++i) {
            assert_int_equal(buf[1].res.hits[i], buf[0].res.hits[i]);
            if (!buf[0].res.hits[i]) continue;
            assert_int_equal(buf[1].res.inst_ids[i], buf[0].res.inst_ids[i]);
            assert_int_equal(buf[1].res.prim_ids[i], buf[0].res.prim_ids[i]);
            assert_memory_equal(&buf[1].res.ranges[i], &buf[0].res.ranges[i], sizeof(float));
            seen[buf[1].res.inst_ids[i] & 3u]++;
        }
        /* the lowest twin and instance 2 report; the twins 1 (and 3 while a
         * twin) never do */
        assert_true(seen[0] > 0);
        assert_true(seen[2] > 0);
        assert_int_equal(seen[1], 0);
        if (step < 2)
            assert_int_equal(seen[3], 0);
        else
            assert_true(seen[3] > 0); /* parted from its twins, it reports itself */
    }
    for (b = 0; b < 2; ++b) {
        rct_buffers_free(&buf[b]);
        rc_context_destroy(ctx[b]);
    }
    rcu_mesh_free(&ball);
}

/* rc_scene_update_mesh: vertices changed in place reach Embree at the next
 * commit, for a mesh Embree shares (stride 16) and one it copied (packed xyz
 * referenced in place). */
static void test_update_mesh(void **state)
{
    const float p0[3] = {3, -50, -50}, p1[3] = {3, 50, -50}, p2[3] = {3, 50, 50}, p3[3] = {3, -50, 50};
    float dirs[3 * 3] = {1, 0, 0, 1, 0.2f, 0.1f, 1, -0.3f, 0.05f};
    rcu_mesh wall;
    float v16[4 * 4];
    rc_context *ctx;
    rc_sensor *sensor;
    rct_buffers buf;
    rc_pose pose = rct_pose(0, 0, 0);
    uint32_t i, pass;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_quad(p0, p1, p2, p3, &wall), 0);
    for (i = 0; i < 4; ++i) {
        memcpy(v16 + 4 * i, wall.vertices + 3 * i, 3 * sizeof(float));
        v16[4 * i + 3] = 0.0f;
    }
    ctx = rct_context(RC_BACKEND_EMBREE, 2, 0);
    sensor = rct_sensor_dirs(ctx, dirs, 3, 0.0f, 100.0f);
    rct_buffers_alloc(&buf, 3, RC_ATTR_RANGES);
    for (pass = 0; pass < 2; ++pass) {
        rc_scene_desc sd = rc_scene_desc_default();
        rc_mesh_desc md = rc_mesh_desc_default();
        rc_scene *scene;
        float *verts = pass ? v16 : wall.vertices;
        uint32_t stride = pass ? 4u : 3u, g;
        sd.max_triangles = wall.triangle_count;
        RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
        md.vertices = verts;
        md.vertex_stride = stride * 4u;
        md.vertex_count = wall.vertex_count;
        md.indices = wall.indices;
        md.triangle_count = wall.triangle_count;
        RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
        RCT_OK(ctx, rc_scene_commit(scene));
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
        assert_true(fabs(buf.res.ranges[0] - 3.0f) < 1e-5);
        for (i = 0; i < 4; ++i) verts[stride * i] = 6.0f; /* the wall moves to x = 6 */
        RCT_OK(ctx, rc_scene_update_mesh(scene, 0));
        assert_int_equal(rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res), RC_ERR_NOT_COMMITTED);
        RCT_OK(ctx, rc_scene_commit(scene));
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < 3; ++i) {
            double expect = 6.0 / (dirs[3 * i] / sqrt(dirs[3 * i] * dirs[3 * i] + dirs[3 * i + 1] * dirs[3 * i + 1] +
                                                       dirs[3 * i + 2] * dirs[3 * i + 2]));
            if (fabs(buf.res.ranges[i] - expect) > 1e-5 * expect)
                fail_msg("pass %u ray %u: %.7f, expected %.7f", (unsigned)pass, (unsigned)i, (double)buf.res.ranges[i],
                         expect);
        }
        RCT_OK(ctx, rc_scene_destroy(scene));
    }
    rct_buffers_free(&buf);
    rcu_mesh_free(&wall);
    rc_context_destroy(ctx);
}

/* A sensor on a surface: the built-in backend searches t > 0, so the surface
 * under the origin is not a return; Embree (which would report t = 0) agrees. */
static void test_sensor_on_surface(void **state)
{
    const float centre[3] = {0, 0, 0};
    float dirs[3 * 3] = {0.3f, 0.2f, 1.0f, 0.1f, -0.2f, -1.0f, 1.0f, 0.0f, 0.0f};
    rcu_mesh m;
    uint32_t b;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_plane(centre, 5.0f, &m), 0);
    for (b = RC_BACKEND_BVH; b <= RC_BACKEND_EMBREE; ++b) {
        rc_context *ctx = rct_context(b, 1, 0);
        rc_scene *scene = rct_scene_mesh(ctx, &m, RC_MESH_REFERENCE);
        rc_sensor *sensor = rct_sensor_dirs(ctx, dirs, 3, 0.0f, 10.0f);
        rc_pose pose = rct_pose(0.5f, 0.25f, 0.0f);
        rct_buffers buf;
        uint32_t i;
        rct_buffers_alloc(&buf, 3, RC_ATTR_HITS | RC_ATTR_RANGES);
        RCT_OK(ctx, rc_simulate(ctx, scene, sensor, &pose, 1, &buf.res));
        for (i = 0; i < 3; ++i) {
            if (buf.res.hits[i] != 0 || !(isinf(buf.res.ranges[i]) && buf.res.ranges[i] > 0))
                fail_msg("%s, ray %u: hit %u range %g", rc_backend_name(b), (unsigned)i, (unsigned)buf.res.hits[i],
                         (double)buf.res.ranges[i]);
        }
        rct_buffers_free(&buf);
        rc_context_destroy(ctx);
    }
    rcu_mesh_free(&m);
}

typedef struct progress_log {
    uint32_t calls;
    double last;
    int ok;
} progress_log;

static int on_progress(void *user, const char *stage, double fraction)
{
    progress_log *log = (progress_log *)user;
    log->calls++;
    if (!stage || !(fraction >= 0.0 && fraction <= 1.0)) log->ok = 0;
    log->last = fraction;
    return 1;
}

/* rc_scene_commit_with_progress reports Embree's build, ending at 1. */
static void test_commit_progress(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    progress_log log = {0, -1.0, 1};
    uint32_t g;
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_EMBREE)) skip();
    assert_int_equal(rcu_mesh_uv_sphere_triangles(5.0f, 200000, &m), 0);
    ctx = rct_context(RC_BACKEND_EMBREE, 2, 0);
    sd.max_triangles = m.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.vertices = m.vertices;
    md.vertex_count = m.vertex_count;
    md.indices = m.indices;
    md.triangle_count = m.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    RCT_OK(ctx, rc_scene_commit_with_progress(scene, on_progress, &log));
    print_message("progress: %u reports\n", (unsigned)log.calls);
    assert_true(log.calls >= 2);
    assert_true(log.ok);
    assert_true(log.last == 1.0);
    rc_context_destroy(ctx);
    rcu_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parity),
        cmocka_unit_test(test_build_quality),
        cmocka_unit_test(test_duplicate_triangles),
        cmocka_unit_test(test_twin_instances),
        cmocka_unit_test(test_update_mesh),
        cmocka_unit_test(test_sensor_on_surface),
        cmocka_unit_test(test_commit_progress),
    };
    return cmocka_run_group_tests_name("embree parity", tests, NULL, NULL);
}
