/* Projected scans: a spherical, cylindrical or pinhole scan of a small mesh
 * (or a few, a scene's geometries) traced triangle by triangle instead of
 * ray by ray. A spinning sensor's
 * rays are found from angles: each triangle's bounding sphere, seen from the
 * sensor, covers a cone, and the rows and columns of the scan's grid that
 * can fall in that cone are found from the grid's angles. A camera's are
 * found on its image: the triangle, clipped to the view's frustum, projects
 * to a polygon whose corners bound the pixels it can cover. Only those rays
 * run the watertight test against the triangle. The mesh's tree is walked
 * once a scan (or a band of its rows), only to pass over boxes no row meets
 * (or outside the camera's view), so on a mesh with fewer triangles than the scan has rays
 * this costs a few tests a ray where the packets pay their node visits
 * (docs/architecture.md, "Projected scans"). Cones, clip planes and pixel
 * bounds are widened beyond every rounding of the test, and each test is
 * rc__tri_intersect_any_area's operations in its order (its rare cases run
 * that function itself), so every ray gets the nearest hit, tie rule
 * included, that any traversal of the tree gives: the same bits. */
#ifndef RC_BVH_SCAN_RASTER_H
#define RC_BVH_SCAN_RASTER_H

#include "bvh/mesh.h"
#include "core/rmath.h"

#include <stddef.h>
#include <stdint.h>

/* Left out where CMake's RANGECAST_PROJECTED_SCANS is off (by default in
 * MinSizeRel builds, as the static core for small boards is built: they take
 * about 12 KB of text on aarch64, more than the core's size budget has left,
 * docs/benchmarks.md). Calls then take the packets, with the same results.
 * Left out too in the single-rays benchmarking build (RANGECAST_NO_PACKETS,
 * backend/bvh.c), which traces every ray through the tree. */
#if !defined(RANGECAST_NO_PROJECTED_SCANS) && !defined(RANGECAST_NO_PACKETS)
#define RC__PROJECTED_SCANS 1

/* A spherical grid: ray (row i, column j) points along phi_min + i * phi_inc
 * (elevation) and theta_min + j * theta_inc (azimuth), x forward, z up. A
 * cylindrical one (rows_tan 1) has the same columns, and row v at the
 * elevation atan((row_cy - v) / row_fy), row_fy > 0 (rc_cylindrical_desc):
 * phi_min and phi_inc are then unused. A pinhole one (pinhole 1, rows the
 * image's height, cols its width) has pixel (v, u) looking along optical
 * (ox, oy, 1), ox = (u - cx) / fx, oy = (v - cy) / fy, fx, fy > 0: the
 * sensor frame's (1, -ox, -oy), or (ox, oy, 1) itself when optical is 1
 * (rc_pinhole_desc); only those fields are used. A band of rows [r0, r0 + n)
 * of any of them is the grid rc__raster_band gives. */
typedef struct rc__raster_grid {
    uint32_t rows, cols;
    double phi_min, phi_inc;
    double theta_min, theta_inc;
    int rows_tan;
    double row_cy, row_fy;
    int pinhole, optical;
    double fx, fy, cx, cy;
    /* 1 / phi_inc and 1 / theta_inc (0 for 0): rc__raster_scan sets them */
    double phi_inv, theta_inv;
} rc__raster_grid;

/* Rows [row0, row0 + rows) of g as a grid of their own: its ray (i, j) is
 * g's (row0 + i, j), its rays the sensor's directions from row0 * cols on. */
void rc__raster_band(const rc__raster_grid *g, uint32_t row0, uint32_t rows, rc__raster_grid *band);

/* 1 when every row's elevation lies within [-pi/2, pi/2] (a cone's rows are
 * found from its elevations, which take only that range): always so for a
 * cylindrical grid with row_fy > 0. A pinhole grid needs finite intrinsics,
 * fx and fy positive. */
int rc__raster_grid_ok(const rc__raster_grid *g);

/* The longest edge of mesh's triangles as its leaf_tris give them (0 for
 * none), for rc__mesh.longest_edge: a triangle long against the map makes a
 * spinning sensor's projected scan test every ray of the rows its cone
 * covers, so such maps take the packets (src/backend/bvh.c). One pass at
 * commit, so that a call does not pay it. */
float rc__raster_longest_edge(const rc__mesh *mesh);

/* Scratch bytes rc__raster_scan needs for a scan of `rays` rays (16-byte
 * multiples). */
size_t rc__raster_scratch_bytes(uint32_t rays);

/* Traces one scan on meshes[0 .. mesh_count), mesh_count >= 1, the
 * geometries 0, 1, ... of a scene without instances (a mesh without
 * triangles is passed over): every ray i = row * cols + column of the grid,
 * its nearest hit over all of them kept in scratch
 * (rc__raster_scratch_bytes(rays)) for rc__raster_hits, as near ties go in
 * rc__hit_offer_slot (the smaller geometry id, then prim id). The meshes'
 * triangles together number less than RC_INVALID_ID. world turns the
 * sensor's unit directions dirs (scan order) into the map frame as the
 * packets' rc__rays_prepare_turned does. */
void rc__raster_scan(const rc__mesh *const *meshes, uint32_t mesh_count, const rc__raster_grid *g,
                     const rc__xformf *world, const float *dirs, float tmax, void *scratch);

/* Rays [first, first + n) of the scan of `rays` rays that rc__raster_scan
 * left in scratch (the same meshes, world and dirs), as the writer takes
 * them: hits[i] and found[i] for ray first + i as rc__mesh_intersect over
 * meshes[0], meshes[1], ... (geometry ids 0, 1, ...) gives them from hits
 * reset to (tmax, no id), prims settled, and for each hit td[i], its
 * distance refined in double as rc__scene_hit_distance_d gives it. A run at
 * a time, so that the writer reads them from the cache. */
void rc__raster_hits(const rc__mesh *const *meshes, uint32_t mesh_count, uint32_t rays, const rc__xformf *world,
                     const float *dirs, void *scratch, uint32_t first, uint32_t n, rc__hit *hits, int *found,
                     double *td);

#endif /* RC__PROJECTED_SCANS */

#endif
