/* Simulate on Embree: rays go to Embree in packets (rtcIntersect4/8/16) made
 * of neighbouring rays of one scan, so a packet shares its origin and has
 * nearby directions and Embree's packet traversal visits each node once for
 * all of them.
 *
 * - Grid sensors (spherical, pinhole, cylindrical, and O1Dn/OnDn rays given
 *   in rows, such as an Ouster unit's) are cut into tiles of
 *   rows x columns whose angular extent is closest to square (a VLP-16, with
 *   rows 5x farther apart than columns, gets 1 x 8; a depth camera 2 x 4);
 *   other O1Dn and OnDn rays into runs of consecutive rays of their traced
 *   order (sorted by direction and origin, ray_order.c). Partial tiles at the edges
 *   leave lanes off. Packets go with Embree's coherent flag: it measured ~20%
 *   faster than incoherent on robust scenes.
 * - Tasks are a pose, or a slice of a pose's tiles when there are fewer poses
 *   than threads can keep busy, on the context's thread pool. Tiles do not
 *   depend on the split, so every ray is traced in the same packet whatever
 *   the thread count, and results are bit-identical for any thread count.
 * - Packet width: the widest the CPU runs natively (rtcGetDeviceProperty
 *   RTC_DEVICE_PROPERTY_NATIVE_RAY16/8/4_SUPPORTED), capped at 8 by default:
 *   16 lanes cover twice the angle and measured no faster than 8 on AVX-512
 *   (the 1M-triangle sphere with a VLP-16). rc__embree_options.packet_width
 *   overrides (1 = one rtcIntersect1 per ray).
 * - Each hit becomes the caller's attributes through rc__write_result (shared
 *   with the built-in backend), which computes only what the mask asks for;
 *   normals come from the mesh exactly as the built-in backend computes them.
 *   The search is t in (0, range_max] from the origin, as the built-in
 *   backend's: tnear is FLT_MIN, not 0, because Embree reports a hit at t = 0
 *   (a sensor on a surface) that the built-in backend does not. Nearer than
 *   range_min still blocks the beam and reads -inf (REP 117).
 * - Hits are written in batches of up to 64 rays. The float64 refinement of
 *   each range (and the normal) reads the hit triangle from the mesh's own
 *   arrays, which Embree's traversal never touches (it keeps its own copy),
 *   so on a large map each hit costs two dependent cache misses: its index
 *   triple, then its vertices. A batch prefetches every hit's triple as its
 *   packet returns and every hit's vertices a batch ahead of writing, so the
 *   misses of 64 rays overlap instead of queueing one after another
 *   (1M-triangle sphere, VLP-16: the write took ~40% of the time before).
 *   Only on large scenes (Embree's bytes and the meshes' arrays above the
 *   context's large_mesh_bytes): on small ones everything is in cache and the
 *   prefetches were 11% more instructions for nothing (1k triangles).
 * - On a map larger than half the last-level cache, a call of many scans runs
 *   ordered (core/work_order.h): chunks of poses whose tiles are keyed by the
 *   first cell of the scene's occupancy grid (embree_occupancy.h) their middle
 *   ray reaches and traced in key order, so that tiles of different poses
 *   meeting the same part of the map run back to back (+79% on the
 *   10M-triangle sphere). A batch then holds hits of several poses. */
#include "backend/embree_impl.h"
#include "bvh/packet.h" /* RC__PACKET_ORIGIN_SPREAD; RC__PREFETCH */
#include "core/work_order.h"

#include <float.h>
#include <math.h>

#define MIN_RAYS_PER_TASK 1024u
#define DEFAULT_MAX_WIDTH 8u
#define BATCH_RAYS 64u /* a multiple of every packet width */

typedef struct trace_run {
    const rc__sim_job *job;
    const rc__emb_scene *es;
    RTCScene scene;
    uint32_t width;            /* lanes: 1, 4, 8 or 16 */
    uint32_t tile_rows, tile_cols;
    uint32_t grid_rows, grid_cols; /* the layout tiles cut: the sensor's grid, or 1 x rays */
    uint32_t tiles_x, tiles_per_pose;
    uint32_t slices, tiles_per_slice;
    int coherent;
    int dups;                  /* some mesh the rays can reach has duplicate triangles */
    int prefetch;              /* the scene is large: prefetch the hits' triangles */
    const float *directions;   /* the sensor's tables */
    const float *origins;
    float range_max;
    uint32_t chunk_poses;      /* ordered runs (core/work_order.h): poses a task */
    unsigned char *order_scratch; /* ordered runs: order_scratch_stride bytes a thread */
    size_t order_scratch_stride;
} trace_run;

/* Ray indices of the lanes of a tile (rows x columns, row-major); lanes past
 * the grid's edge get RC_INVALID_ID. */
static inline void tile_rays(const trace_run *run, uint32_t tile, uint32_t *ray)
{
    uint32_t ty = tile / run->tiles_x, tx = tile - ty * run->tiles_x;
    uint32_t row0 = ty * run->tile_rows, col0 = tx * run->tile_cols;
    uint32_t r, c, l = 0;
    for (r = 0; r < run->tile_rows; ++r)
        for (c = 0; c < run->tile_cols; ++c, ++l)
            ray[l] = (row0 + r < run->grid_rows && col0 + c < run->grid_cols)
                         ? rc__sensor_traced_ray(run->job->sensor, (row0 + r) * run->grid_cols + col0 + c)
                         : RC_INVALID_ID;
}

/* Ray r of the scan in the map frame. */
static inline void ray_world(const trace_run *run, const rc__xformf *world, uint32_t r, float org[3], float dir[3])
{
    rc__rot_apply_f(world->r, run->directions + (size_t)r * 3u, dir);
    if (run->origins) {
        rc__rot_apply_f(world->r, run->origins + (size_t)r * 3u, org);
        org[0] += world->t[0];
        org[1] += world->t[1];
        org[2] += world->t[2];
    } else {
        org[0] = world->t[0];
        org[1] = world->t[1];
        org[2] = world->t[2];
    }
}

/* Hits held back until their triangles are in cache (see the top). */
typedef struct hit_batch {
    uint32_t count;
    uint32_t pose[BATCH_RAYS];   /* relative to the task's first pose */
    uint32_t ray[BATCH_RAYS];
    uint8_t found[BATCH_RAYS];
    rc__hit hit[BATCH_RAYS];
} hit_batch;

/* Prefetches what rc__scene_hit_distance_d and rc__scene_hit_normal read for
 * an Embree hit, in two stages: stage 0 its triangle's index triple in the
 * mesh's own array (Embree's hits have no leaf slot), stage 1 its three
 * vertices (this reads the triple, so run stage 0 well before). Here, beside
 * its only user, and not in the static core, which never needs it; forced
 * inline (RC__PREFETCH_INLINE, intersect.h), or gcc may delete its calls. */
static RC__PREFETCH_INLINE void hit_prefetch(const rc_scene *scene, const rc__hit *hit, int stage)
{
    const rc__mesh *mesh = hit->inst == RC_INVALID_ID ? &scene->geoms[hit->geom].mesh
                                                      : &scene->insts[hit->inst].source->geoms[hit->geom].mesh;
    const uint32_t *tri = mesh->indices + (size_t)3 * hit->prim;
    int i;
    if (stage == 0) {
        RC__PREFETCH(tri);
        return;
    }
    for (i = 0; i < 3; ++i) RC__PREFETCH(mesh->vertices + (size_t)tri[i] * mesh->stride);
}

/* Adds ray r's hit from Embree (prefetching its index triple). */
static inline void batch_add(const trace_run *run, hit_batch *b, uint32_t pose, uint32_t r, float tfar,
                             uint32_t prim, uint32_t geom, uint32_t inst)
{
    rc__hit *hit = &b->hit[b->count];
    int found = geom != RTC_INVALID_GEOMETRY_ID;
    b->pose[b->count] = pose;
    b->ray[b->count] = r;
    b->found[b->count] = (uint8_t)found;
    b->count++;
    if (!found) {
        hit->t = INFINITY;
        hit->prim = hit->geom = hit->inst = hit->slot = RC_INVALID_ID;
        return;
    }
    hit->t = tfar;
    hit->geom = geom;
    hit->prim = prim;
    hit->slot = RC_INVALID_ID; /* Embree's own order */
    /* the own meshes: directly, or through a split scene's identity instance */
    hit->inst = inst == RTC_INVALID_GEOMETRY_ID || inst == run->es->mesh_inst_id ? RC_INVALID_ID
                                                                                : inst - run->es->max_geoms;
    /* a twin instance (same source, same transform) gives the same hit: the
     * lowest one reports it, as in the built-in backend */
    if (hit->inst != RC_INVALID_ID && run->es->twins_any) hit->inst = run->es->inst_twin[hit->inst];
    if (run->dups) {
        const rc__emb_scene *src = run->es;
        if (hit->inst != RC_INVALID_ID)
            src = (const rc__emb_scene *)run->job->scene->insts[hit->inst].source->backend_scene;
        if (src->geoms[geom].dup_count) hit->prim = rc__emb_canonical_prim(&src->geoms[geom], prim);
    }
    if (run->prefetch) hit_prefetch(run->job->scene, hit, 0);
}

/* Prefetches the vertices of every hit of a batch (their index triples were
 * prefetched as the hits came in). Forced inline like hit_prefetch: a
 * function that only prefetches looks free of side effects to gcc, which
 * then deletes its calls (this one's were, for a -8% at 1M, until the
 * prefetch helper it called moved here from the core in session 25). */
static RC__PREFETCH_INLINE void batch_prefetch(const trace_run *run, const hit_batch *b)
{
    uint32_t i;
    if (!run->prefetch) return;
    for (i = 0; i < b->count; ++i)
        if (b->found[i]) hit_prefetch(run->job->scene, &b->hit[i], 1);
}

/* Writes the batch's rays: entry i is of pose pose0 + b->pose[i], whose
 * transform is worlds[b->pose[i]]. */
static void batch_write(const trace_run *run, const rc__xformf *worlds, uint32_t pose0, hit_batch *b)
{
    const rc__sim_job *job = run->job;
    uint32_t i = 0;
#if defined(RC__HIT_DISTANCES_SSE2)
    /* one-origin sensors: up to a packet's worth of entries of one pose at a
     * time, their hits refined two or four at a time */
    while (!run->origins && i < b->count) {
        int found[RC__PACKET_SIZE];
        uint32_t n = 0;
        while (n < RC__PACKET_SIZE && i + n < b->count && b->pose[i + n] == b->pose[i]) {
            found[n] = b->found[i + n];
            ++n;
        }
        rc__write_results_tile(job, (uint64_t)(pose0 + b->pose[i]) * job->sensor->rays, &b->ray[i], n, found,
                               &b->hit[i], &worlds[b->pose[i]]);
        i += n;
    }
#endif
    for (; i < b->count; ++i) {
        uint32_t r = b->ray[i];
        const float *ds = run->directions + (size_t)r * 3u;
        const float *os = run->origins ? run->origins + (size_t)r * 3u : NULL;
        rc__write_result(job, (uint64_t)(pose0 + b->pose[i]) * job->sensor->rays + r, ds, os, b->found[i], &b->hit[i],
                         NULL, &worlds[b->pose[i]]);
    }
    b->count = 0;
}

/* One tile through rtcIntersectW: fill the SoA packet, trace, write. Embree
 * loads the valid mask as one vector: it sits right after the packet, whose
 * size is a multiple of its (vector) alignment, so it is aligned too. */
#define RC__EMB_TILE_FN(NAME, W, RAYHIT, INTERSECT)                                                          \
    static void NAME(const trace_run *run, const rc__xformf *world, uint32_t pose, uint32_t tile,          \
                     rc__rtc_query *q, hit_batch *b)                                                          \
    {                                                                                                         \
        struct {                                                                                              \
            struct RAYHIT rh;                                                                                 \
            int valid[W];                                                                                     \
        } pk;                                                                                                 \
        uint32_t ray[W];                                                                                      \
        uint32_t l;                                                                                           \
        tile_rays(run, tile, ray);                                                                            \
        for (l = 0; l < (W); ++l) {                                                                           \
            float org[3], dir[3];                                                                             \
            if (ray[l] != RC_INVALID_ID) {                                                                    \
                pk.valid[l] = -1;                                                                             \
                ray_world(run, world, ray[l], org, dir);                                                      \
            } else {                                                                                          \
                pk.valid[l] = 0;                                                                              \
                org[0] = world->t[0], org[1] = world->t[1], org[2] = world->t[2];                             \
                dir[0] = 1.0f, dir[1] = 0.0f, dir[2] = 0.0f;                                                  \
            }                                                                                                 \
            pk.rh.ray.org_x[l] = org[0];                                                                      \
            pk.rh.ray.org_y[l] = org[1];                                                                      \
            pk.rh.ray.org_z[l] = org[2];                                                                      \
            pk.rh.ray.dir_x[l] = dir[0];                                                                      \
            pk.rh.ray.dir_y[l] = dir[1];                                                                      \
            pk.rh.ray.dir_z[l] = dir[2];                                                                      \
            pk.rh.ray.tnear[l] = FLT_MIN;                                                                     \
            pk.rh.ray.tfar[l] = run->range_max;                                                               \
            pk.rh.ray.time[l] = 0.0f;                                                                         \
            pk.rh.ray.mask[l] = 0xFFFFFFFFu;                                                                  \
            pk.rh.ray.id[l] = l;                                                                              \
            pk.rh.ray.flags[l] = 0;                                                                           \
            pk.rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;                                                    \
            pk.rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;                                                    \
            pk.rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;                                                 \
        }                                                                                                     \
        INTERSECT(q, pk.valid, run->scene, &pk.rh);                                                           \
        for (l = 0; l < (W); ++l)                                                                             \
            if (pk.valid[l])                                                                                  \
                batch_add(run, b, pose, ray[l], pk.rh.ray.tfar[l],                                            \
                          pk.rh.hit.primID[l], pk.rh.hit.geomID[l], pk.rh.hit.instID[0][l]);                  \
    }

/* The valid mask's alignment above relies on these. */
typedef char rc__emb_packet4_size_check[(sizeof(struct RTCRayHit4) % 16u) == 0 ? 1 : -1];
typedef char rc__emb_packet8_size_check[(sizeof(struct RTCRayHit8) % 32u) == 0 ? 1 : -1];
typedef char rc__emb_packet16_size_check[(sizeof(struct RTCRayHit16) % 64u) == 0 ? 1 : -1];

RC__EMB_TILE_FN(tile4, 4, RTCRayHit4, RC__RTC_INTERSECT4)
RC__EMB_TILE_FN(tile8, 8, RTCRayHit8, RC__RTC_INTERSECT8)
RC__EMB_TILE_FN(tile16, 16, RTCRayHit16, RC__RTC_INTERSECT16)

/* One ray through rtcIntersect1 (packet_width 1). */
static void tile1(const trace_run *run, const rc__xformf *world, uint32_t pose, uint32_t tile, rc__rtc_query *q,
                  hit_batch *b)
{
    struct RTCRayHit rh;
    float org[3], dir[3];
    uint32_t r;
    tile_rays(run, tile, &r);
    if (r == RC_INVALID_ID) return;
    ray_world(run, world, r, org, dir);
    rh.ray.org_x = org[0];
    rh.ray.org_y = org[1];
    rh.ray.org_z = org[2];
    rh.ray.dir_x = dir[0];
    rh.ray.dir_y = dir[1];
    rh.ray.dir_z = dir[2];
    rh.ray.tnear = FLT_MIN;
    rh.ray.tfar = run->range_max;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RC__RTC_INTERSECT1(q, run->scene, &rh);
    batch_add(run, b, pose, r, rh.ray.tfar, rh.hit.primID, rh.hit.geomID, rh.hit.instID[0]);
}

/* Traces count tiles in order, writing hits a batch behind so that one
 * batch's triangles arrive while the next is traced: recs[i] = pose *
 * tiles_per_pose + tile (pose relative to pose0, whose transforms are
 * worlds[]), or with recs NULL (scan order, no division a tile) tiles
 * first + i of pose0. */
static void trace_tiles(const trace_run *run, const uint32_t *recs, uint32_t first, uint32_t count, uint32_t pose0,
                        const rc__xformf *worlds)
{
    rc__rtc_query q;
    hit_batch b[2]; /* one fills while the other's vertices arrive */
    uint32_t i, cur = 0;
    rc__rtc_query_init(&q, run->coherent);
    b[0].count = b[1].count = 0;
    for (i = 0; i < count; ++i) {
        const uint32_t pose = recs ? recs[i] / run->tiles_per_pose : 0u;
        const uint32_t t = recs ? recs[i] % run->tiles_per_pose : first + i;
        switch (run->width) {
        case 16: tile16(run, &worlds[pose], pose, t, &q, &b[cur]); break;
        case 8: tile8(run, &worlds[pose], pose, t, &q, &b[cur]); break;
        case 4: tile4(run, &worlds[pose], pose, t, &q, &b[cur]); break;
        default: tile1(run, &worlds[pose], pose, t, &q, &b[cur]); break;
        }
        if (b[cur].count + run->width > BATCH_RAYS) {
            batch_prefetch(run, &b[cur]);
            cur ^= 1u;
            batch_write(run, worlds, pose0, &b[cur]);
        }
    }
    batch_prefetch(run, &b[cur]);
    batch_write(run, worlds, pose0, &b[cur ^ 1u]);
    batch_write(run, worlds, pose0, &b[cur]);
}

static void trace_task(void *user, uint32_t task, uint32_t thread)
{
    const trace_run *run = (const trace_run *)user;
    uint32_t pose = task / run->slices;
    uint32_t first = (task % run->slices) * run->tiles_per_slice;
    uint32_t last = first + run->tiles_per_slice;
    rc__xformf world;
    (void)thread;
    if (last > run->tiles_per_pose) last = run->tiles_per_pose;
    rc__job_world_xform(run->job, pose, &world);
    trace_tiles(run, NULL, first, last - first, pose, &world);
}

/* Ordered runs (core/work_order.h): a chunk of poses whose tiles are keyed
 * by the first occupied cell their middle ray reaches and traced in key
 * order. */
static void trace_ordered_task(void *user, uint32_t task, uint32_t thread)
{
    const trace_run *run = (const trace_run *)user;
    const rc__sim_job *job = run->job;
    uint32_t pose0 = task * run->chunk_poses, poses = run->chunk_poses, p, t, count;
    rc__order_scratch sc;
    rc__xformf *worlds;
    rc__order_scratch_split(run->order_scratch + (size_t)thread * run->order_scratch_stride, run->chunk_poses,
                            run->tiles_per_pose, &sc);
    worlds = (rc__xformf *)sc.worlds;
    if (poses > job->pose_count - pose0) poses = job->pose_count - pose0;
    count = poses * run->tiles_per_pose;
    for (p = 0; p < poses; ++p) {
        rc__job_world_xform(job, pose0 + p, &worlds[p]);
        for (t = 0; t < run->tiles_per_pose; ++t) {
            const uint32_t i = p * run->tiles_per_pose + t;
            uint32_t ray[16], n = 0;
            float org[3], dir[3];
            tile_rays(run, t, ray);
            while (n < run->width && ray[n] != RC_INVALID_ID) ++n;
            ray_world(run, &worlds[p], ray[n / 2u], org, dir);
            sc.keys[i] = rc__occupancy_key(run->es->occupancy, org, dir, run->range_max);
            if (sc.keys[i] == UINT32_MAX) sc.keys[i] = 0; /* meets nothing: any place will do */
            sc.records[i] = i;
        }
    }
    rc__radix_sort_pairs(sc.keys, sc.records, sc.tmp_keys, sc.tmp_records, count, RC__OCC_KEY_BITS);
    trace_tiles(run, sc.records, 0u, count, pose0, worlds);
}

static uint32_t pick_width(const rc__emb_device *d)
{
    uint32_t want = d->options.packet_width;
    uint32_t w = d->native_width < DEFAULT_MAX_WIDTH ? d->native_width : DEFAULT_MAX_WIDTH;
    if (want == 1u || want == 4u || want == 8u || want == 16u) return want;
    return w;
}

/* Tile of w lanes (rows x columns) whose angular extent is closest to square,
 * never taller than the grid: a VLP-16 (2 degrees between rows, 0.4 between
 * columns) gets 1 x 8, an OS1-64 or a depth camera 2 x 4. Fewer rows on a tie.
 * dv, dh: the steps between rows and columns (rc__sensor_grid_steps). */
static void tile_shape(double dv, double dh, uint32_t w, uint32_t rows, int grid, uint32_t *tile_rows,
                       uint32_t *tile_cols)
{
    double best = HUGE_VAL;
    uint32_t r;
    *tile_rows = 1;
    *tile_cols = w;
    if (!grid || rows < 2) return;
    if (!(dv > 0.0) || !(dh > 0.0)) return;
    for (r = 1; r <= w && r <= rows; r *= 2) {
        double cost = fabs(log((r * dv) / ((w / r) * dh)));
        if (cost < best - 1e-9) {
            best = cost;
            *tile_rows = r;
            *tile_cols = w / r;
        }
    }
}

/* 1 when a mesh of the scene or of an instanced scene has duplicate triangles. */
static int scene_has_dups(const rc_scene *scene)
{
    const rc__emb_scene *es = (const rc__emb_scene *)scene->backend_scene;
    uint32_t i, g;
    for (g = 0; g < scene->geom_count; ++g)
        if (es->geoms[g].dup_count) return 1;
    for (i = 0; i < scene->inst_count; ++i) {
        const rc_scene *src = scene->insts[i].source;
        const rc__emb_scene *ss = (const rc__emb_scene *)src->backend_scene;
        for (g = 0; g < src->geom_count; ++g)
            if (ss->geoms[g].dup_count) return 1;
    }
    return 0;
}

/* Bytes of the meshes' own index and vertex arrays that the refinement reads,
 * over every scene of the context (each once, like Embree's bytes: a scene
 * that instances another reads both). */
static uint64_t context_mesh_bytes(const rc_context *ctx)
{
    const rc_scene *scene;
    uint64_t bytes = 0;
    for (scene = ctx->scenes; scene; scene = scene->next) bytes += rc__emb_mesh_array_bytes(scene);
    return bytes;
}

rc_status rc__emb_simulate(rc_context *ctx, const rc__sim_job *job)
{
    const rc__emb_device *d = (const rc__emb_device *)ctx->backend_data;
    const rc_sensor *sensor = job->sensor;
    uint32_t threads = ctx->thread_count;
    uint32_t tiles_y;
    trace_run run;
    double dv = 0.0, dh = 0.0;
    /* grid sensors, and rays given in rows (an Ouster unit's beams x columns) */
    const int grid = rc__sensor_grid_steps(sensor, &dv, &dh);

    run.job = job;
    run.es = (const rc__emb_scene *)job->scene->backend_scene;
    RC_RETURN_IF(ctx, run.es == NULL, RC_ERR_NOT_COMMITTED, "scene has no Embree scene: call rc_scene_commit");
    run.scene = run.es->scene;
    run.directions = sensor->directions;
    run.origins = sensor->origins;
    run.range_max = sensor->range_max;
    run.dups = scene_has_dups(job->scene);
    /* Embree's structures compete for the same cache */
    run.prefetch = d->options.bytes_now + context_mesh_bytes(ctx) > ctx->large_mesh_bytes;
    run.width = pick_width(d);
    run.grid_rows = grid ? sensor->rows : 1u;
    run.grid_cols = grid ? sensor->columns : sensor->rays;
    tile_shape(dv, dh, run.width, run.grid_rows, grid, &run.tile_rows, &run.tile_cols);
    run.tiles_x = (run.grid_cols + run.tile_cols - 1u) / run.tile_cols;
    tiles_y = (run.grid_rows + run.tile_rows - 1u) / run.tile_rows;
    run.tiles_per_pose = run.tiles_x * tiles_y;
    /* one origin, or a multi-beam LiDAR's beams (as the built-in backend's packets) */
    run.coherent = sensor->origins == NULL ||
                   sensor->origin_spread2 <= RC__PACKET_ORIGIN_SPREAD * RC__PACKET_ORIGIN_SPREAD;
    run.slices = 1;
    /* Few poses: cut each scan into slices (of whole tiles) so every thread has work. */
    if (threads > 1 && job->pose_count < threads * 4u) {
        uint32_t want = (threads * 4u + job->pose_count - 1u) / job->pose_count;
        uint32_t max_slices = sensor->rays / MIN_RAYS_PER_TASK;
        run.slices = want < max_slices ? want : (max_slices ? max_slices : 1u);
        if (run.slices > run.tiles_per_pose) run.slices = run.tiles_per_pose;
    }
    run.tiles_per_slice = (run.tiles_per_pose + run.slices - 1u) / run.slices;
    /* a map larger than the cache, with an occupancy grid: ordered runs on
     * scratch borrowed from the arena (without room, scan by scan) */
    run.chunk_poses = 0;
    run.order_scratch = NULL;
    if (run.es->occupancy && d->options.bytes_now + context_mesh_bytes(ctx) > ctx->ordered_mesh_bytes)
        run.chunk_poses = rc__order_chunk_poses(job->pose_count, threads, run.tiles_per_pose, RC__ORDER_MIN_RECORDS);
    if (run.chunk_poses) {
        run.order_scratch_stride = rc__order_scratch_bytes(run.chunk_poses, run.tiles_per_pose, sizeof(rc__xformf));
        run.order_scratch = (unsigned char *)rc__arena_alloc(&ctx->arena, run.order_scratch_stride * threads);
    }
    if (run.order_scratch) {
        rc__pool_run(ctx->pool, (job->pose_count + run.chunk_poses - 1u) / run.chunk_poses, trace_ordered_task, &run);
        rc__arena_free(&ctx->arena, run.order_scratch);
    } else {
        rc__pool_run(ctx->pool, job->pose_count * run.slices, trace_task, &run);
    }
    /* rtcIntersect reports only misuse (e.g. an uncommitted scene), which the
     * checks before this call rule out; report it all the same. */
    return rc__emb_check((rc__emb_device *)ctx->backend_data, "rc_simulate");
}
