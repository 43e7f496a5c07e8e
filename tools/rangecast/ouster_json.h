/* --sensor ouster:FILE: an Ouster unit from its metadata JSON (cJSON), as the
 * OnDn rays rc_ouster_rays makes of its beam intrinsics. Both layouts are
 * read: the nested one of current firmware (beam_intrinsics,
 * lidar_intrinsics, lidar_data_format, config_params) and the flat legacy one. */
#ifndef RCP_OUSTER_JSON_H
#define RCP_OUSTER_JSON_H

#include <stdint.h>

#include "rangecast/rangecast.h"

/* The rays of a sensor the program made itself (OnDn, sensor frame). */
typedef struct rcp_rays {
    float *origins, *dirs;      /* 3 floats a ray (malloc'd) */
    uint32_t count, width, height;
    float range_min, range_max;
    /* an Ouster frame (tools/common/ouster_frame.h): pixel_shift_by_row, one
     * a row (malloc'd; NULL when the metadata has none), and column_window,
     * inclusive (0 .. width - 1 when the metadata has none) */
    int32_t *pixel_shift;
    uint32_t window_start, window_end;
} rcp_rays;

/* The prefix that names an Ouster metadata file in --sensor. */
#define RCP_OUSTER_PREFIX "ouster:"

/* Reads path into out (range 0.3 .. 120 m, an OS1's: the metadata has no
 * limits), with the frame's pixel_shift_by_row and column_window where the
 * metadata has them (lidar_data_format, or data_format). 0, or -1 with
 * rcu_last_error() naming the file and the problem. */
int rcp_ouster_load(const char *path, rcp_rays *out);

void rcp_rays_free(rcp_rays *rays);

/* An OnDn desc for rc_sensor_create_rays over the rays (pointing at them). */
rc_rays_desc rcp_rays_desc(const rcp_rays *rays);

#endif
