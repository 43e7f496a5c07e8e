/* The built-in backend: the scene's two-level BVH (4-wide mesh trees,
 * bvh/wide.h), traversed on the CPU by the
 * context's thread pool. Rays of a scan are traced in tiles (neighbouring rows
 * and columns of a grid sensor, or runs of consecutive O1Dn rays) that share
 * the sensor's origin, so the packet traversal serves a tile per node fetch
 * (mesh by mesh in scenes of fewer than RC__PACKET_WALK_MESHES meshes, a
 * packet's walk of the top-level tree in scenes of more; instances after
 * them, a packet's walk again, each instance met taking the packet).
 * Work is split into tasks of one pose, or of a slice of a pose's tiles when
 * there are fewer poses than threads can keep busy; on a mesh larger than the
 * cache, of a chunk of poses whose tiles run in the order of the mesh's tree
 * (ordered runs, below). Each ray's answer depends only on the ray (the packet
 * changes the order of work, not the result), so neither the split nor the
 * order ever changes a bit. */
#include "backend/backend.h"
#include "bvh/packet.h"
#include "bvh/scan_raster.h"
#include "core/cache_size.h"
#include "core/work_order.h"

#include <math.h>
#include <string.h>

#define MIN_TILES_PER_TASK 64u
/* Most meshes a scene may have for packets to test each one per tile: with
 * more, the per-mesh root tests cost more than the packets save (a 100k VLP-16
 * map cut into M meshes, 1 thread, against ray by ray: M = 2 +56%, 8 +34%,
 * 16 +30%, 32 +13%, 64 even, 128 -18%). */
#define RC__PACKET_MAX_MESHES 32u
/* Scenes of more meshes walk their top-level tree a packet
 * (rc__scene_intersect_packet) where the build has it; -Os builds send
 * their rays one by one. */
#if defined(RC__PACKET_MESHES)
#define RC__PACKET_SCENE_MESHES UINT32_MAX
#else
#define RC__PACKET_SCENE_MESHES RC__PACKET_MAX_MESHES
#endif
/* Scenes of at least this many meshes walk the top-level tree a packet even
 * when the packets could take every mesh: the walk skips the meshes a packet
 * misses. A VLP-16 in a room of balls, each its own mesh, walk against every
 * mesh (session 42, 2 threads, two runs): 2 meshes -4 to -17%, 4 -3%,
 * 9 -1 to +1%, 12 +1 to +2.5%, 16 -1.5 to +4%, 25 +5 to +8%; with the
 * walk's test in SSE2, instructions (callgrind): 2 meshes +3.0%, 4 +1.4%,
 * 6 +0.3%, 7 -0.3%, 8 -0.7%, 9 -1.2%. */
#define RC__PACKET_WALK_MESHES 8u
/* Projected scans (scan_raster.h) for meshes of at most this many triangles
 * per ray of the scan. On the sphere against the packets (session 32, one
 * thread each, run side by side on the two cores): a VLP-16 (14,400 rays)
 * at 10k +39 to +44%, 14k +24 to +51%, 20k +2 to +15%, 24k -1 to -9%, 30k
 * -10 to -22%; an OS1-64 (65,536 rays) at 30k +45 to +50%, 50k +8 to +13%,
 * 65k even, 80k -5 to -14%. */
#ifndef RC__RASTER_TRIANGLES_PER_RAY /* (overridden to measure other sizes) */
#define RC__RASTER_TRIANGLES_PER_RAY 1.0
#endif
/* sim_run.large holds one bit per mesh */
typedef char rc__packet_meshes_check[RC__PACKET_MAX_MESHES <= 32u ? 1 : -1];

typedef struct tiling {
    uint32_t tile_rows, tile_cols;   /* rays a tile spans */
    uint32_t grid_rows, grid_cols;   /* tiles a scan has */
} tiling;

typedef struct sim_run {
    const rc__sim_job *job;
    tiling tl;
    uint32_t tiles;                  /* per pose */
    uint32_t slices;                 /* tasks per pose */
    uint32_t tiles_per_slice;
    int packets;                     /* 1 when tiles go through the packet traversal */
    uint32_t packet_flags;           /* RC__PACKET_OWN_ORIGINS when each ray has its own origin (OnDn),
                                      * RC__PACKET_PRIMS_PENDING when the call writes no prim ids or normals */
    uint32_t in_flight;              /* tiles traced at once: RC__PACKETS_IN_FLIGHT with a large mesh (1 when
                                      * ordered in a map the cache nearly holds), else 1 */
    int rays_by_mesh;                /* 1 when single rays go mesh by mesh, taking turns in large ones */
    uint32_t chunk_poses;            /* ordered runs: poses a task */
    uint32_t order_depth;            /* ordered runs: depth of the key (rc__mesh_order_key) */
    uint32_t order_mesh;             /* ordered runs: the mesh whose tree gives the key */
    unsigned char *order_scratch;    /* ordered runs: order_scratch_stride bytes per thread */
    size_t order_scratch_stride;
    uint32_t large;                  /* bit g: mesh g is large (rc__mesh_is_large), for scenes of
                                      * up to RC__PACKET_MAX_MESHES meshes */
    uint32_t pooled;                 /* bit g: large mesh g past ctx->lone_pool_bytes too */
#if defined(RC__PROJECTED_SCANS)
    rc__raster_grid grid;            /* projected scans: the sensor's grid */
    unsigned char *raster_scratch;   /* projected scans: raster_stride bytes per thread */
    size_t raster_stride;
    uint32_t raster_band_rows;       /* projected scans: rows a band (the whole scan where it fits) */
    uint32_t raster_bands;           /* projected scans: bands a scan (tasks a pose) */
    uint32_t raster_mesh_count;      /* projected scans: the scene's meshes, in geometry order */
    const rc__mesh *raster_meshes[RC__PACKET_MAX_MESHES];
#endif
} sim_run;

/* Tile shape: RC__PACKET_SIZE rays, as close to square in angle as the sensor's grid
 * allows. */
static void choose_tiling(const rc_sensor *s, tiling *tl)
{
    double row_step = 1.0, col_step = 1.0, best = 1e300;
    uint32_t tr;
    if (!rc__sensor_grid_steps(s, &row_step, &col_step)) row_step = 1e9; /* flat rays: runs of RC__PACKET_SIZE */
    tl->tile_rows = 1;
    for (tr = 1; tr <= RC__PACKET_SIZE; tr *= 2) {
        uint32_t tc = RC__PACKET_SIZE / tr;
        double h = tr * (row_step > 0 ? row_step : 1.0), w = tc * (col_step > 0 ? col_step : 1.0);
        double aspect = h > w ? h / w : w / h;
        if (tr > s->rows) break;
        if (aspect < best) {
            best = aspect;
            tl->tile_rows = tr;
        }
    }
    tl->tile_cols = RC__PACKET_SIZE / tl->tile_rows;
    tl->grid_rows = (s->rows + tl->tile_rows - 1) / tl->tile_rows;
    tl->grid_cols = (s->columns + tl->tile_cols - 1) / tl->tile_cols;
}

/* An OnDn ray in the map frame (one-origin rays: rc__rays_prepare_turned). */
static void world_ray_ondn(const rc__xformf *world, const float *ds, const float *os, rc__ray *ray)
{
    float org[3], dir[3];
    rc__rot_apply_f(world->r, ds, dir);
    rc__rot_apply_f(world->r, os, org);
    org[0] += world->t[0];
    org[1] += world->t[1];
    org[2] += world->t[2];
    rc__ray_prepare(ray, org, dir);
}

static void hit_reset(rc__hit *hit, float tmax)
{
    hit->t = tmax;
    hit->prim = hit->geom = hit->inst = hit->slot = RC_INVALID_ID;
}

/* A group of tiles through the scene. One-origin sensors go in packets
 * through the scene's own meshes, mesh by mesh (each mesh's traversal starts
 * from the nearest hit so far, and the tie rule makes the order of meshes
 * irrelevant); the packets of a large mesh take turns. Other rays go one by
 * one: mesh by mesh too when the scene has a large mesh to take turns in,
 * else through both levels of the scene. After packets, each packet walks
 * the top level for the instances (own meshes skipped), each instance met
 * taking the packet in its frame; after runs, each ray goes through the
 * instances alone: a map with objects instanced into it keeps its packets. */
static void trace_group(const sim_run *run, const rc_scene *scene, uint32_t group,
                        rc__ray (*rays)[RC__PACKET_SIZE], const uint32_t *n, rc__hit (*hits)[RC__PACKET_SIZE],
                        int (*found)[RC__PACKET_SIZE])
{
    uint32_t g, k, i;
    if (run->packets) {
        const rc__ray *prays[RC__PACKETS_IN_FLIGHT];
        rc__hit *phits[RC__PACKETS_IN_FLIGHT];
        int *pfound[RC__PACKETS_IN_FLIGHT];
        /* the meshes each packet goes through alone, all in one call */
        const rc__mesh *alone[RC__PACKET_MAX_MESHES];
        uint32_t alone_geoms[RC__PACKET_MAX_MESHES], alone_count = 0;
        const uint32_t direct = scene->geom_count <= RC__PACKET_MAX_MESHES ? scene->geom_count : RC__PACKET_MAX_MESHES;
        for (k = 0; k < group; ++k) {
            prays[k] = rays[k];
            phits[k] = hits[k];
            pfound[k] = found[k];
        }
        for (g = 0; g < direct; ++g) {
            const rc__mesh *mesh = &scene->geoms[g].mesh;
            if (group > 1 && ((run->large >> g) & 1u)) {
#if defined(RC__PACKET_HAS_LONE_POOL)
                rc__mesh_intersect_packets(mesh, group, prays, n, g, RC_INVALID_ID, phits, pfound,
                                           run->packet_flags | ((run->pooled >> g) & 1u ? RC__PACKET_LONE_POOL : 0u));
#else
                rc__mesh_intersect_packets(mesh, group, prays, n, g, RC_INVALID_ID, phits, pfound, run->packet_flags);
#endif
            } else {
                alone[alone_count] = mesh;
                alone_geoms[alone_count++] = g;
            }
        }
#if defined(RC__PACKET_MESHES)
        if (scene->geom_count >= RC__PACKET_WALK_MESHES) {
            /* many meshes: all but those taking turns go through the
             * top-level tree a packet */
            for (k = 0; k < group; ++k)
                rc__scene_intersect_packet(scene, rays[k], n[k], group > 1 ? run->large : 0u, hits[k], found[k],
                                           run->packet_flags);
            alone_count = 0;
        } else if (alone_count > 1u) {
            for (k = 0; k < group; ++k)
                rc__mesh_intersect_packet_meshes(alone, alone_geoms, alone_count, rays[k], n[k], RC_INVALID_ID,
                                                 hits[k], found[k], run->packet_flags);
            alone_count = 0;
        }
#endif
        for (g = 0; g < alone_count; ++g)
            for (k = 0; k < group; ++k)
                rc__mesh_intersect_packet(alone[g], rays[k], n[k], alone_geoms[g], RC_INVALID_ID, hits[k], found[k],
                                          run->packet_flags);
    } else if (run->rays_by_mesh) {
        for (g = 0; g < scene->geom_count; ++g) {
            const rc__mesh *mesh = &scene->geoms[g].mesh;
            if ((run->large >> g) & 1u) {
                /* full tiles lie back to back: one run keeps the turns full */
                uint32_t full = 0;
                while (full + 1 < group && n[full] == RC__PACKET_SIZE) ++full;
                rc__mesh_intersect_rays(mesh, rays[0], full * RC__PACKET_SIZE + n[full], g, RC_INVALID_ID, hits[0],
                                        found[0]);
                for (k = full + 1; k < group; ++k)
                    rc__mesh_intersect_rays(mesh, rays[k], n[k], g, RC_INVALID_ID, hits[k], found[k]);
            } else {
                for (k = 0; k < group; ++k)
                    for (i = 0; i < n[k]; ++i) found[k][i] |= rc__mesh_intersect(mesh, &rays[k][i], g, RC_INVALID_ID, &hits[k][i]);
            }
        }
    }
    /* the instances (all items without packets or runs: a scene of many
     * meshes); after the own meshes each ray keeps its nearest hit, and
     * the tie rule does not depend on the order. Packets walk the top-level
     * tree for them too (a VLP-16 among 64 instanced balls, 2 threads: 85
     * scans/s ray by ray, 207 in packets, Embree 243-250; session 42). */
#if defined(RC__PACKET_MESHES)
    if (run->packets && scene->inst_count != 0) {
        for (k = 0; k < group; ++k)
            rc__scene_intersect_packet_instances(scene, rays[k], n[k], hits[k], found[k], run->packet_flags);
        return;
    }
#endif
    if (scene->inst_count != 0 || (!run->packets && !run->rays_by_mesh)) {
        const uint32_t from = run->packets || run->rays_by_mesh ? scene->geom_count : 0u;
        for (k = 0; k < group; ++k)
            for (i = 0; i < n[k]; ++i) found[k][i] |= rc__scene_intersect_items(scene, &rays[k][i], &hits[k][i], from);
    }
}

/* A tile's place in the scan: its first row and column, and how many of
 * its rows and columns the scan holds (the last tiles may be clipped). */
typedef struct tile_extent {
    uint32_t r0, c0, rows_in, cols_in;
} tile_extent;

static RC__FORCE_INLINE void tile_extent_of(const sim_run *run, uint32_t tile, tile_extent *e)
{
    const rc_sensor *sensor = run->job->sensor;
    const tiling *tl = &run->tl;
    e->r0 = (tile / tl->grid_cols) * tl->tile_rows;
    e->c0 = (tile % tl->grid_cols) * tl->tile_cols;
    e->rows_in = sensor->rows - e->r0 < tl->tile_rows ? sensor->rows - e->r0 : tl->tile_rows;
    e->cols_in = sensor->columns - e->c0 < tl->tile_cols ? sensor->columns - e->c0 : tl->tile_cols;
}

/* The sensor's ray indices of one tile, in tracing order; returns the count. */
static uint32_t tile_indices(const sim_run *run, uint32_t tile, uint32_t idx[RC__PACKET_SIZE])
{
    const rc_sensor *sensor = run->job->sensor;
    const uint32_t cols = sensor->columns;
    /* the tile's extent and the order table in locals, read once (the
     * stores to idx would otherwise make the compiler read them again a
     * ray) */
    tile_extent e;
    const uint64_t *order = sensor->trace_order;
    uint32_t n = 0, a, b, rows_in, cols_in;
    tile_extent_of(run, tile, &e);
    rows_in = e.rows_in;
    cols_in = e.cols_in;
    for (a = 0; a < rows_in; ++a) {
        const uint32_t first = (e.r0 + a) * cols + e.c0;
        for (b = 0; b < cols_in; ++b) idx[n++] = order ? (uint32_t)order[first + b] : first + b;
    }
    return n;
}

/* tile_indices(run, tile, idx)[n / 2], the tile's middle ray, without the
 * others (ordered runs key each tile by it) */
static uint32_t tile_middle(const sim_run *run, uint32_t tile)
{
    const rc_sensor *sensor = run->job->sensor;
    tile_extent e;
    uint32_t m, at;
    tile_extent_of(run, tile, &e);
    m = e.rows_in * e.cols_in / 2u;
    at = (e.r0 + m / e.cols_in) * sensor->columns + e.c0 + m % e.cols_in;
    return sensor->trace_order ? (uint32_t)sensor->trace_order[at] : at;
}

/* Ray idx of the sensor in the map frame, as tile_rays turns it. */
static void world_ray(const rc_sensor *sensor, const rc__xformf *world, const uint32_t *idx, rc__ray *ray)
{
    if (sensor->origins)
        world_ray_ondn(world, sensor->directions + (size_t)*idx * 3u, sensor->origins + (size_t)*idx * 3u, ray);
    else
        rc__rays_prepare_turned(world->r, world->t, sensor->directions, idx, 1u, ray);
}

/* Rays of one tile, turned into the map frame, with their hits reset;
 * returns the tile's ray count. */
static uint32_t tile_rays(const sim_run *run, const rc__xformf *world, uint32_t tile, uint32_t idx[RC__PACKET_SIZE],
                          rc__ray rays[RC__PACKET_SIZE], rc__hit hits[RC__PACKET_SIZE], int found[RC__PACKET_SIZE])
{
    const rc_sensor *sensor = run->job->sensor;
    const float range_max = sensor->range_max;
    const uint32_t n = tile_indices(run, tile, idx);
    uint32_t i;
    if (!sensor->origins) rc__rays_prepare_turned(world->r, world->t, sensor->directions, idx, n, rays);
    for (i = 0; i < n; ++i) {
        if (sensor->origins) world_ray(sensor, world, &idx[i], &rays[i]);
        hit_reset(&hits[i], range_max);
        found[i] = 0;
    }
    return n;
}

/* count tiles traced run->in_flight at a time: recs[i] = pose * tiles + tile
 * (pose relative to pose0, whose world transforms are worlds[]), or with
 * recs NULL (scan order, no division a tile) tiles first + i of pose0. */
static void trace_tiles(const sim_run *run, const uint32_t *recs, uint32_t first, uint32_t count, uint32_t pose0,
                        const rc__xformf *worlds)
{
    const rc__sim_job *job = run->job;
    const rc_sensor *sensor = job->sensor;
    uint32_t at;
    /* Tiles go in groups of run->in_flight: in a large map their packets take
     * turns, so that one's memory fetches overlap the others' work. */
    for (at = 0; at < count; at += run->in_flight) {
        uint32_t idx[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
        rc__ray rays[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
        rc__hit hits[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
        int found[RC__PACKETS_IN_FLIGHT][RC__PACKET_SIZE];
        uint32_t pose[RC__PACKETS_IN_FLIGHT];
        uint32_t n[RC__PACKETS_IN_FLIGHT], group = count - at < run->in_flight ? count - at : run->in_flight;
        uint32_t k, i;
        for (k = 0; k < group; ++k) {
            pose[k] = recs ? recs[at + k] / run->tiles : 0u;
            n[k] = tile_rays(run, &worlds[pose[k]], recs ? recs[at + k] % run->tiles : first + at + k, idx[k], rays[k],
                             hits[k], found[k]);
        }
        trace_group(run, job->scene, group, rays, n, hits, found);
        for (k = 0; k < group; ++k) {
            uint64_t base = (uint64_t)(pose0 + pose[k]) * sensor->rays;
#if defined(RC__HIT_DISTANCES_LANES)
            if (!sensor->origins) {
                rc__write_results_tile(job, base, idx[k], n[k], found[k], hits[k], &worlds[pose[k]]);
                continue;
            }
#endif
            for (i = 0; i < n[k]; ++i) {
                const float *os = sensor->origins ? sensor->origins + (size_t)idx[k][i] * 3u : NULL;
                rc__write_result(job, base + idx[k][i], sensor->directions + (size_t)idx[k][i] * 3u, os, found[k][i],
                                 &hits[k][i], NULL, &worlds[pose[k]]);
            }
        }
    }
}

static void trace_task(void *user, uint32_t task, uint32_t thread)
{
    const sim_run *run = (const sim_run *)user;
    uint32_t pose = task / run->slices;
    uint32_t first = (task % run->slices) * run->tiles_per_slice;
    uint32_t last = first + run->tiles_per_slice;
    rc__xformf world;
    (void)thread;
    if (last > run->tiles) last = run->tiles;
    rc__job_world_xform(run->job, pose, &world);
    trace_tiles(run, NULL, first, last - first, pose, &world);
}

/* Ordered runs (maps larger than the cache): a task is a chunk of poses whose
 * tiles are traced in the order of their centre rays' keys
 * (rc__mesh_order_key), so that tiles of different poses that meet the same
 * part of the tree run back to back and find it in cache. The order of work
 * never changes a result. Scratch per thread: keys and records twice over
 * (the radix sort moves through the second pair), then the chunk's world
 * transforms. */
static void trace_ordered_task(void *user, uint32_t task, uint32_t thread)
{
    const sim_run *run = (const sim_run *)user;
    const rc__sim_job *job = run->job;
    const rc_sensor *sensor = job->sensor;
    const rc__mesh *mesh = &job->scene->geoms[run->order_mesh].mesh;
    rc__order_scratch sc;
    uint32_t *keys, *recs;
    rc__xformf *worlds;
    uint32_t pose0 = task * run->chunk_poses, poses = run->chunk_poses, p, t, count;
    rc__order_scratch_split(run->order_scratch + (size_t)thread * run->order_scratch_stride, run->chunk_poses,
                            run->tiles, &sc);
    keys = sc.keys;
    recs = sc.records;
    worlds = (rc__xformf *)sc.worlds;
    if (poses > job->pose_count - pose0) poses = job->pose_count - pose0;
    count = poses * run->tiles;
    for (p = 0; p < poses; ++p) {
        rc__job_world_xform(job, pose0 + p, &worlds[p]);
        for (t = 0; t < run->tiles; ++t) {
            /* the tile's middle ray, as the traversal will turn it (only
             * that one: preparing the whole tile twice was 4% of a 1M call) */
            const uint32_t i = p * run->tiles + t, mid = tile_middle(run, t);
            rc__ray ray;
            world_ray(sensor, &worlds[p], &mid, &ray);
            keys[i] = rc__mesh_order_key(mesh, &ray, sensor->range_max, run->order_depth);
            recs[i] = i;
        }
    }
    /* a ray that enters nothing (UINT32_MAX) sorts last: any place will do */
    rc__radix_sort_pairs(keys, recs, sc.tmp_keys, sc.tmp_records, count, 32u);
    trace_tiles(run, recs, 0u, count, pose0, worlds);
}

#if defined(RC__PROJECTED_SCANS)
/* rays a projected scan hands the writer at a time */
#define RC__RASTER_WRITE_RUN 64u

/* One band of rows of one pose's projected scan (scan_raster.h), then its
 * results, a run at a time. A scan takes several bands where its rays would
 * not fit a thread's scratch at once (a depth camera's image), or where a
 * call of few poses spreads each over the threads. */
static void raster_task(void *user, uint32_t task, uint32_t thread)
{
    const sim_run *run = (const sim_run *)user;
    const rc__sim_job *job = run->job;
    const rc_sensor *sensor = job->sensor;
    const uint32_t pose = task / run->raster_bands, row0 = (task % run->raster_bands) * run->raster_band_rows;
    const uint32_t rows = run->grid.rows - row0 < run->raster_band_rows ? run->grid.rows - row0 : run->raster_band_rows;
    const uint32_t rays = rows * run->grid.cols, base = row0 * run->grid.cols;
    const float *dirs = sensor->directions + (size_t)base * 3u;
    unsigned char *scratch = run->raster_scratch + (size_t)thread * run->raster_stride;
    rc__hit hits[RC__RASTER_WRITE_RUN];
    int found[RC__RASTER_WRITE_RUN];
    double td[RC__RASTER_WRITE_RUN];
    rc__xformf world;
    rc__raster_grid band;
    uint32_t first;
    rc__job_world_xform(job, pose, &world);
    rc__raster_band(&run->grid, row0, rows, &band);
    rc__raster_scan(run->raster_meshes, run->raster_mesh_count, &band, &world, dirs, sensor->range_max, scratch);
    for (first = 0; first < rays; first += RC__RASTER_WRITE_RUN) {
        const uint32_t n = rays - first < RC__RASTER_WRITE_RUN ? rays - first : RC__RASTER_WRITE_RUN;
        rc__raster_hits(run->raster_meshes, run->raster_mesh_count, rays, &world, dirs, scratch, first, n, hits, found,
                        td);
        rc__write_results_run(job, (uint64_t)pose * sensor->rays, base + first, n, found, hits, td, &world);
    }
}

int rc__raster_grid_of(const rc_sensor *s, rc__raster_grid *g)
{
    memset(g, 0, sizeof *g);
    g->rows = s->rows;
    g->cols = s->columns;
    if (s->model == RC_SENSOR_SPHERICAL) {
        g->phi_min = s->spherical.phi.min;
        g->phi_inc = s->spherical.phi.increment;
        g->theta_min = s->spherical.theta.min;
        g->theta_inc = s->spherical.theta.increment;
    } else if (s->model == RC_SENSOR_CYLINDRICAL) {
        g->rows_tan = 1;
        g->row_cy = s->cylindrical.cy;
        g->row_fy = s->cylindrical.fy;
        g->theta_min = s->cylindrical.theta.min;
        g->theta_inc = s->cylindrical.theta.increment;
    } else if (s->model == RC_SENSOR_PINHOLE) {
        g->pinhole = 1;
        g->optical = s->pinhole.frame == RC_PINHOLE_FRAME_OPTICAL;
        g->fx = s->pinhole.fx;
        g->fy = s->pinhole.fy;
        g->cx = s->pinhole.cx;
        g->cy = s->pinhole.cy;
    } else {
        return 0;
    }
    return !s->origins && rc__raster_grid_ok(g);
}

/* A spinning sensor's projected scan tests each triangle against the rays
 * of its bounding sphere's cone, so a triangle large against the map (a
 * room's wall seen from inside the room) covers whole rows, and every ray of
 * them pays its test: the VLP-16 in the demo warehouse (2,780 triangles)
 * traced 335 scans/s so, Embree 1,700, and in an empty 12 x 12 x 3 m box
 * (12 triangles) 444, Embree 1,052. Such maps take the packets: 1 when no
 * triangle's edge is longer than this fraction of the meshes' bounding box
 * diagonal (the 1k sphere's longest, 5.4 m of 69 m, passes). The longest
 * edge is found at commit (rc__mesh.longest_edge): a pass a call cost 8-13%
 * of a one-pose call on the 10k sphere (session 42). (A camera's scan clips
 * each triangle to its view and pays no such cost.) */
#define RC__RASTER_EDGE_FRACTION 0.1
static int raster_triangles_small(const sim_run *run, double fraction)
{
    double edge = 0.0, diag2 = 0.0;
    rc__aabb all, b;
    uint32_t g, k;
    for (k = 0; k < 3; ++k) {
        all.min[k] = INFINITY;
        all.max[k] = -INFINITY;
    }
    for (g = 0; g < run->raster_mesh_count; ++g) {
        const rc__mesh *mesh = run->raster_meshes[g];
        edge = mesh->longest_edge > edge ? mesh->longest_edge : edge;
        rc__wide_bounds(mesh->wide, mesh->wide_count, &b);
        for (k = 0; k < 3; ++k) {
            all.min[k] = b.min[k] < all.min[k] ? b.min[k] : all.min[k];
            all.max[k] = b.max[k] > all.max[k] ? b.max[k] : all.max[k];
        }
    }
    for (k = 0; k < 3; ++k)
        if (all.max[k] >= all.min[k]) diag2 += ((double)all.max[k] - all.min[k]) * ((double)all.max[k] - all.min[k]);
    return edge * edge <= fraction * fraction * diag2;
}

/* Sets up a projected scan when it pays: a spherical, cylindrical or
 * pinhole sensor over a scene of up to RC__PACKET_MAX_MESHES meshes, no
 * instances, with few triangles against the scan's rays (and for a
 * spinning sensor, none large against the map), and the scratch
 * borrowed from the arena's free space (without room the call takes the
 * packets: the same results). A scene of several meshes placed mesh by mesh
 * costs what their merged mesh does, where the packets pay every mesh's
 * root a tile (a D435 in a room of 24 balls, 53k triangles: 60 scans/s as
 * 25 meshes against 265 as one, session 40). Returns 1 when
 * run->raster_scratch was allocated. */
static int plan_raster(rc_context *ctx, const rc__sim_job *job, sim_run *run)
{
    const rc_scene *scene = job->scene;
    const rc_sensor *s = job->sensor;
    double triangles = 0.0;
    uint32_t band, g;
    if (scene->geom_count == 0 || scene->geom_count > RC__PACKET_MAX_MESHES || scene->inst_count != 0) return 0;
    for (g = 0; g < scene->geom_count; ++g) {
        const rc__mesh *mesh = &scene->geoms[g].mesh;
        /* a mesh without triangles has no tree, and nothing to place */
        if (!mesh->leaf_tris && mesh->bvh.item_count != 0) return 0;
        triangles += (double)mesh->bvh.item_count;
        run->raster_meshes[g] = mesh;
    }
    run->raster_mesh_count = scene->geom_count;
    if (triangles > RC__RASTER_TRIANGLES_PER_RAY * (double)s->rays) return 0;
    if (!rc__raster_grid_of(s, &run->grid)) return 0;
    if (!run->grid.pinhole && !raster_triangles_small(run, ctx->raster_edge_fraction)) return 0;
    /* the most rows a band whose scratch fits a thread's share */
    band = s->rows;
    while (band > 0 && rc__raster_scratch_bytes(band * s->columns) > RC_SIMULATE_SCRATCH_PER_THREAD)
        band = rc__raster_scratch_bytes(s->columns) > RC_SIMULATE_SCRATCH_PER_THREAD ? 0 : band / 2u;
    if (band == 0) return 0;
    /* a call of few poses cut into slices (bvh_simulate): as many bands */
    if (run->slices > 1 && (s->rows + run->slices - 1u) / run->slices < band)
        band = (s->rows + run->slices - 1u) / run->slices;
    run->raster_band_rows = band;
    run->raster_bands = (s->rows + band - 1u) / band;
    run->raster_stride = rc__raster_scratch_bytes(band * s->columns);
    run->raster_scratch = (unsigned char *)rc__arena_alloc(&ctx->arena, run->raster_stride * ctx->thread_count);
    return run->raster_scratch != NULL;
}

#endif

/* Sets up an ordered run when it pays: an own mesh larger than the cache
 * (with instances too: a map and the objects moving in it), and enough tiles
 * a task to meet its subtrees more than once. The scratch is
 * borrowed from the arena's free space for the call; without room the call
 * runs in scan order (the same results). Returns 1 when run->order_scratch
 * was allocated. */
static int plan_ordered(rc_context *ctx, const rc__sim_job *job, sim_run *run)
{
    const rc_scene *scene = job->scene;
    uint32_t threads = ctx->thread_count, g, chunk;
    uint64_t biggest = 0;
    /* every path traces tiles: packets, OnDn runs going mesh by mesh, and
     * single rays through the top level (instances); the key is the biggest
     * own mesh's, the map a scene's instances move in */
    for (g = 0; g < scene->geom_count; ++g) {
        const rc__mesh *mesh = &scene->geoms[g].mesh;
        const uint64_t bytes = rc__mesh_bytes(mesh);
        if (mesh->wide && bytes > biggest) {
            biggest = bytes;
            run->order_mesh = g;
        }
    }
    /* larger than the cache, and large enough that packets take turns */
    if (biggest <= ctx->ordered_mesh_bytes || biggest <= ctx->large_mesh_bytes) return 0;
    /* the minimum was measured with tiles of 16 rays: as many rays a chunk */
    chunk = rc__order_chunk_poses(job->pose_count, threads, run->tiles,
                                  RC__ORDER_MIN_RECORDS * 16u / RC__PACKET_SIZE);
    if (chunk == 0) return 0;
    run->chunk_poses = chunk;
    run->order_depth = 1;
    /* subtrees of 512 to 2,048 triangles (a key's depth measured even from
     * about 600 to 10,000 at 10M) */
    while (run->order_depth < RC__ORDER_MAX_DEPTH &&
           ((uint64_t)2048u << (2u * run->order_depth)) < scene->geoms[run->order_mesh].mesh.triangle_count)
        ++run->order_depth;
    run->order_scratch_stride = rc__order_scratch_bytes(chunk, run->tiles, sizeof(rc__xformf));
    run->order_scratch = (unsigned char *)rc__arena_alloc(&ctx->arena, run->order_scratch_stride * threads);
    if (!run->order_scratch) return 0;
    /* ordered packets in a map the cache nearly holds: one tile at a time
     * (ctx->ordered_turns_bytes) */
    if (run->packets && biggest <= ctx->ordered_turns_bytes) run->in_flight = 1;
    return 1;
}

static rc_status bvh_simulate(rc_context *ctx, const rc__sim_job *job)
{
    sim_run run;
    uint32_t threads = ctx->thread_count;
    const rc_sensor *s = job->sensor;
    memset(&run, 0, sizeof run);
    run.job = job;
    choose_tiling(s, &run.tl);
    run.tiles = run.tl.grid_rows * run.tl.grid_cols;
    /* Packets need one shared origin, or origins close together (an OnDn
     * sensor's beams: packet.c) (instances are searched ray by ray after
     * them); a scene of many meshes walks its top-level tree a packet
     * instead of testing every mesh's root per tile, or in -Os builds goes
     * ray by ray. */
    run.packet_flags = (s->origins != NULL ? RC__PACKET_OWN_ORIGINS : 0u) |
                       (job->attributes & (RC_ATTR_PRIM_IDS | RC_ATTR_NORMALS) ? 0u : RC__PACKET_PRIMS_PENDING);
    run.packets = (s->origins == NULL || s->origin_spread2 <= RC__PACKET_ORIGIN_SPREAD * RC__PACKET_ORIGIN_SPREAD) &&
                  job->scene->geom_count >= 1 && job->scene->geom_count <= RC__PACKET_SCENE_MESHES;
#if defined(RANGECAST_NO_PACKETS) /* benchmarking switch: single rays only */
    run.packets = 0;
#endif
    if (run.packets || job->scene->geom_count <= RC__PACKET_MAX_MESHES) {
        uint32_t g;
        for (g = 0; g < job->scene->geom_count && g < RC__PACKET_MAX_MESHES; ++g)
            if (rc__mesh_is_large(&job->scene->geoms[g].mesh, ctx->large_mesh_bytes)) {
                run.large |= 1u << g;
#if defined(RC__PACKET_HAS_LONE_POOL)
                if (rc__mesh_is_large(&job->scene->geoms[g].mesh, ctx->lone_pool_bytes)) run.pooled |= 1u << g;
#endif
            }
    }
    /* packets of a large mesh take turns (in a scene of many meshes, of
     * one among the first 32); single rays (OnDn) go mesh by mesh when a
     * large mesh lets them take turns, 128 rays a run */
    run.rays_by_mesh = !run.packets && run.large != 0;
    run.in_flight = run.large ? RC__PACKETS_IN_FLIGHT : 1u;
    run.slices = 1;
    /* Few poses: cut each scan into slices so every thread has work. */
    if (threads > 1 && job->pose_count < threads * 4u) {
        uint32_t want = (threads * 4u + job->pose_count - 1u) / job->pose_count;
        uint32_t max_slices = run.tiles / MIN_TILES_PER_TASK;
        run.slices = want < max_slices ? want : (max_slices ? max_slices : 1u);
    }
    run.tiles_per_slice = (run.tiles + run.slices - 1u) / run.slices;
#if defined(RC__PROJECTED_SCANS) && !defined(RANGECAST_NO_PACKETS)
    if (plan_raster(ctx, job, &run)) {
        rc__pool_run(ctx->pool, job->pose_count * run.raster_bands, raster_task, &run);
        rc__arena_free(&ctx->arena, run.raster_scratch);
        return RC_OK;
    }
#endif
    if (plan_ordered(ctx, job, &run)) {
        /* ordered, a map's instances go with it ray by ray: on the 10M
         * sphere with ten boxes 449 against 361 scans/s for packets first
         * (tools/probes/instanced_map.c); out of order, packets win */
        if (job->scene->inst_count) run.packets = run.rays_by_mesh = 0;
        rc__pool_run(ctx->pool, (job->pose_count + run.chunk_poses - 1u) / run.chunk_poses, trace_ordered_task, &run);
        rc__arena_free(&ctx->arena, run.order_scratch);
        return RC_OK;
    }
    rc__pool_run(ctx->pool, job->pose_count * run.slices, trace_task, &run);
    return RC_OK;
}

static int bvh_available(void) { return 1; }
static size_t bvh_context_bytes(const rc_context_desc *desc)
{
    (void)desc;
    return 0;
}
static rc_status bvh_init(rc_context *ctx, const rc_context_desc *desc)
{
    (void)desc;
    const uint64_t llc = rc__last_level_cache_bytes();
    ctx->large_mesh_bytes = rc__large_mesh_threshold(llc);
    ctx->ordered_mesh_bytes = rc__ordered_mesh_threshold(llc);
    ctx->ordered_turns_bytes = llc * 8u; /* 0 when unknown; it picks only how packets go */
#if defined(RC__PACKET_HAS_LONE_POOL)
    ctx->lone_pool_bytes = llc * 8u;
#endif
#if defined(RC__PROJECTED_SCANS)
    ctx->raster_edge_fraction = RC__RASTER_EDGE_FRACTION;
#endif
    return RC_OK;
}
static void bvh_deinit(rc_context *ctx) { (void)ctx; }
static rc_status bvh_commit(rc_scene *scene, rc_progress_fn progress, void *user)
{
    return rc__scene_build_wide(scene, progress, user);
}

const rc__backend rc__backend_bvh = {
    RC_BACKEND_BVH,   "bvh",      bvh_available, bvh_context_bytes, rc__scene_wide_commit_bytes,
    bvh_init,         bvh_deinit, bvh_commit,    NULL,              bvh_simulate,
    NULL,             NULL,
};
