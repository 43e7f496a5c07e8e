/* rcutil: point clouds from simulated scans, written as PLY or PCD.
 *
 * Only valid returns are kept. Points stay in the sensor frame unless poses
 * are given, in which case they are moved to the map frame
 * (pose * sensor_to_base * point, in double). */
#ifndef RCU_CLOUD_H
#define RCU_CLOUD_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "rangecast/rangecast.h"
#include "util.h"

/* Optional fields besides x y z (all float32 but ring). */
#define RCU_CLOUD_RANGE     0x1u /* "range": metres along the ray */
#define RCU_CLOUD_INTENSITY 0x2u /* "intensity": |cos| of the incidence angle, a Lambertian stand-in (needs normals) */
#define RCU_CLOUD_RING      0x4u /* "ring" (uint16): the scan row, as Velodyne drivers publish it */

typedef struct rcu_cloud {
    uint32_t fields;     /* RCU_CLOUD_* */
    size_t count, capacity;
    float *xyz;          /* 3 per point */
    float *range;        /* with RCU_CLOUD_RANGE */
    float *intensity;    /* with RCU_CLOUD_INTENSITY */
    uint16_t *ring;      /* with RCU_CLOUD_RING */
} rcu_cloud;

void rcu_cloud_init(rcu_cloud *cloud, uint32_t fields);
void rcu_cloud_free(rcu_cloud *cloud);

/* A batch of scans as rc_simulate wrote it: element pose * rays_per_scan + ray. */
typedef struct rcu_scan_view {
    const float *points;           /* 3 per ray, sensor frame (required) */
    const uint8_t *hits;           /* NULL: a finite point counts as a return */
    const float *ranges;           /* for "range"; NULL: |point| */
    const float *normals;          /* for "intensity"; NULL: intensity 1 */
    uint32_t rays_per_scan;
    uint32_t columns;              /* for "ring" (row = ray / columns); 0 = rays_per_scan */
    uint32_t pose_count;
    const rc_pose *poses;          /* base-to-map, one per scan; NULL keeps the sensor frame */
    const rc_pose *sensor_to_base; /* the mounting; NULL = identity */
} rcu_scan_view;

/* Appends the valid returns of every scan in the view. */
int rcu_cloud_append(rcu_cloud *cloud, const rcu_scan_view *view);

/* PLY (binary little-endian, or ascii) with fields x y z [range] [intensity] [ring]. */
int rcu_cloud_write_ply(const char *path, const rcu_cloud *cloud, int ascii);
/* PCD v0.7 (DATA binary, or ascii), FIELDS x y z [range] [intensity] [ring]. */
int rcu_cloud_write_pcd(const char *path, const rcu_cloud *cloud, int ascii);
/* By the extension: .ply or .pcd (else an error). */
int rcu_cloud_write(const char *path, const rcu_cloud *cloud, int ascii);

/* A cloud written batch by batch, for more scans than memory holds (a long
 * trajectory): a batch is held until the next comes, then its records go
 * to a body file beside the output (PATH.body.partial); close writes the
 * header, whose count is known only then, and the records after it (copied
 * from the body, or the one batch straight), in the same format as
 * rcu_cloud_write (.ply or .pcd by the extension). Only one batch is in
 * memory at a time. Every function returns 0, or -1 with rcu_last_error();
 * after a failure of append call abort. Nothing is left at PATH unless
 * close succeeds. */
typedef struct rcu_cloud_stream {
    char *path, *body_path;
    FILE *out, *body;
    int pcd, ascii;
    rcu_cloud batch; /* its fields are the file's; it holds the batch in hand */
    size_t count;    /* records in the body */
} rcu_cloud_stream;

/* Opens PATH, so that a path that cannot be written fails before the work. */
int rcu_cloud_stream_open(rcu_cloud_stream *s, const char *path, uint32_t fields, int ascii);
/* Appends the valid returns of every scan in the view (as rcu_cloud_append). */
int rcu_cloud_stream_append(rcu_cloud_stream *s, const rcu_scan_view *view);
/* Writes PATH whole and removes the body; s is released either way. */
int rcu_cloud_stream_close(rcu_cloud_stream *s);
/* Removes the body and PATH; s is released. Safe on a released stream. */
void rcu_cloud_stream_abort(rcu_cloud_stream *s);

#endif
