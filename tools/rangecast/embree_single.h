/* `rangecast bench --backend embree-single`: the baseline most Embree users
 * write by hand, to compare rangecast's Embree backend with. Built only when
 * the program is built with Embree (RANGECAST_TOOL_WITH_EMBREE). */
#ifndef RCT_EMBREE_SINGLE_H
#define RCT_EMBREE_SINGLE_H

#include <stdint.h>

#include "rangecast/rangecast.h"

/* Traces pose_count scans of ray_count rays each the plain way: its own Embree
 * device ("threads=<threads>") and scene (the mesh copied into Embree's own
 * buffers, default scene flags and build quality, as most users set it up),
 * then a parallel-for over the poses on `threads` pthreads, each thread
 * calling rtcIntersect1 once per ray (direction rotated by the pose, origin at
 * the pose's position).
 *
 * vertices: x y z per vertex (vertex_count); indices: 3 per triangle.
 * directions: ray_count unit directions in the sensor frame, scan order (for a
 *   spherical sensor: row-major, as rangecast's table). Poses are the sensor's
 *   poses in the map (no mounting transform).
 * range_min / range_max: the search is [0, range_max]; a hit nearer than
 *   range_min reads -inf, no hit +inf (REP 117, as rangecast).
 * threads: 1 or more. repeat: how many times the whole batch is traced (>= 1);
 *   the timing covers all of them.
 * scans_per_s: pose_count * repeat / wall seconds of tracing.
 * build_s: wall seconds of device, buffers and rtcCommitScene.
 * origins: NULL (every ray starts at the pose's position), or 3 floats a
 *   ray in the sensor frame (OnDn), placed by the pose like the directions.
 * ranges_out: NULL, or pose_count * ray_count floats receiving the last
 *   repeat's ranges (index pose * ray_count + ray).
 * Returns 0, or -1 with the reason in rcu_last_error() (bad argument, Embree
 * error, thread start failure). */
int rct_embree_single_bench(const float *vertices, uint32_t vertex_count, const uint32_t *indices,
                            uint32_t triangle_count, const float *directions, const float *origins,
                            uint32_t ray_count,
                            float range_min, float range_max, const rc_pose *poses, uint32_t pose_count,
                            uint32_t threads, int repeat, double *scans_per_s, double *build_s,
                            float *ranges_out);

#endif
