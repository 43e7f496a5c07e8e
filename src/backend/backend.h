/* The one internal interface every backend implements. Each backend file
 * exports exactly one table; the core never tests which backends exist except
 * through rc__backend_find. */
#ifndef RC_BACKEND_BACKEND_H
#define RC_BACKEND_BACKEND_H

#include "bvh/scan_raster.h"
#include "core/context.h"
#include "core/rmath.h"
#include "scene/scene.h"
#include "sensor/sensor.h"

/* One simulate call, checked and ready. */
typedef struct rc__sim_job {
    const rc_scene *scene;
    const rc_sensor *sensor;
    const rc_pose *poses;      /* checked: finite, near-unit quaternions; NULL when poses_d is set */
    const rc_pose_d *poses_d;  /* double poses (rc_simulate_d), else NULL */
    uint32_t pose_count;
    uint32_t attributes;       /* RC_ATTR_* */
    const rc_results *out;
    uint32_t flags;            /* RC_RESULTS_* (ON_DEVICE only where device_results is set) */
    /* results on the device: the sensor's noise (NULL: none) for the backend
     * to apply there, draw key rc__noise_key(seed, draws). Host results get
     * the host's pass after simulate instead, whatever the backend. */
    const struct rc__noise *noise;
    uint64_t noise_key;
} rc__sim_job;

typedef struct rc__backend {
    uint32_t id;
    const char *name;
    /* 1 when compiled in and usable on this machine in principle. */
    int (*available)(void);
    /* Arena bytes init takes. */
    size_t (*context_bytes)(const rc_context_desc *desc);
    /* Exact peak arena bytes commit takes for a scene of these capacities. */
    size_t (*scene_commit_bytes)(const rc_scene_desc *desc);
    rc_status (*init)(rc_context *ctx, const rc_context_desc *desc);
    void (*deinit)(rc_context *ctx);
    rc_status (*scene_commit)(rc_scene *scene, rc_progress_fn progress, void *user);
    void (*scene_release)(rc_scene *scene);
    rc_status (*simulate)(rc_context *ctx, const rc__sim_job *job);
    /* Adds backend_bytes / device_bytes. May be NULL. */
    void (*memory_stats)(const rc_context *ctx, rc_memory_stats *stats);
    /* Where the last RC_RESULTS_ON_DEVICE call left its results; NULL for
     * backends without a device (they reject that flag). */
    rc_status (*device_results)(rc_context *ctx, rc_device_results *out);
} rc__backend;

/* NULL when that backend is not compiled in. AUTO resolves to the best one present. */
const rc__backend *rc__backend_find(uint32_t id);

extern const rc__backend rc__backend_bvh;

/* Per-pose transform sensor -> map: pose * mount (float pose, no scene origin). */
void rc__sensor_world_xform(const rc_sensor *sensor, const rc_pose *pose, rc__xformf *out);
/* Sensor -> scene frame of pose i of a job: pose (float or double) * mount,
 * minus the scene's origin, composed in double and then cast. Every backend
 * uses this, so far-from-origin maps keep float precision everywhere. */
void rc__job_world_xform(const rc__sim_job *job, uint32_t pose, rc__xformf *out);

/* Writes every requested attribute of element k from a hit (or none).
 * dir_s / org_s: the ray in the sensor frame (unit dir). hit->t is the range.
 * n_world: unit geometric normal in the map frame (ignored when no hit).
 * world: sensor -> map transform (to bring the normal into the sensor frame). */
void rc__write_result(const rc__sim_job *job, uint64_t k, const float dir_s[3], const float *org_s,
                      int found, const rc__hit *hit, const float n_world[3], const rc__xformf *world);

/* rc__write_result for rays first .. first + n - 1 of one pose of a
 * one-origin sensor (element base + ray; no normals passed in), whose
 * distances the caller refined already: td[i], as rc__scene_hit_distance_d
 * gives it for hits[i] (a projected scan's). */
void rc__write_results_run(const rc__sim_job *job, uint64_t base, uint32_t first, uint32_t n, const int *found,
                           const rc__hit *hits, const double *td, const rc__xformf *world);

#if defined(RC__PROJECTED_SCANS)
/* The sensor's rays as a projected scan's grid (bvh.c): 0 for a model or
 * grid that has none (O1Dn, OnDn, rays of their own origins, a spherical
 * grid past a pole). */
int rc__raster_grid_of(const rc_sensor *s, rc__raster_grid *g);
#endif

#if defined(RC__HIT_DISTANCES_LANES)
/* rc__write_result for n rays of one pose of a one-origin sensor (a packet
 * tile, or a run of the Embree backend's batch; n <= RC__PACKET_SIZE; ray i
 * is element base + idx[i]; no normals passed in), their distances refined
 * two or four at a time (rc__scene_hit_distances_d) */
void rc__write_results_tile(const rc__sim_job *job, uint64_t base, const uint32_t *idx, uint32_t n, const int *found,
                            const rc__hit *hits, const rc__xformf *world);
#endif

#endif
