/* A coarse occupancy grid of a scene's meshes: RC__OCC_N cells a side over
 * the scene's bounds. A cell is occupied where some triangle's box touches
 * it. It answers one question cheaply: which occupied cell does a ray reach
 * first? The Embree backend keys its tiles with that (as the built-in backend
 * keys them with its own tree, rc__mesh_order_key) to trace a call in the
 * order of the map rather than scan by scan. Only the order of work depends
 * on it, never a result, so it may be stale (a moved mesh) without harm.
 *
 * Each cell holds its chessboard distance (in cells) to the nearest occupied
 * cell, 0 for an occupied one: every cell nearer than that is empty, so the
 * walk leaps out of that empty cube in one step instead of crossing its cells
 * one by one. From inside a room that is a few steps to the walls instead of
 * some fifty (the walk was 15% of the Embree backend's time at 1M triangles
 * where the map is ordered; docs/benchmarks.md, session 27). */
#ifndef RC_SCENE_OCCUPANCY_H
#define RC_SCENE_OCCUPANCY_H

#include "rangecast/rangecast.h"

#include <stdint.h>

#define RC__OCC_N 64u
/* The distance of a cell with no occupied cell in reach (an empty grid). */
#define RC__OCC_FAR 255u

typedef struct rc__occupancy {
    float min[3];        /* the grid's corner */
    float scale[3];      /* cells a metre, per axis */
    uint64_t triangles;  /* the scene's triangle count when built */
    float bounds[6];     /* and its bounds (scene->bounds: min, then max) */
    /* cell (x, y, z) at (z * N + y) * N + x: its chessboard distance to the
     * nearest occupied cell (0: occupied), at most RC__OCC_FAR */
    uint8_t dist[RC__OCC_N * RC__OCC_N * RC__OCC_N];
} rc__occupancy;

/* Marks the cells of every triangle of the scene's own meshes (instances are
 * not looked at) within the scene's bounds (scene->bounds, set by commit). */
void rc__occupancy_build(rc__occupancy *grid, const rc_scene *scene);

/* The first occupied cell the ray org + t dir, 0 <= t <= tmax, enters (a 3-D
 * DDA from where it enters the grid, leaping across empty cubes), as the
 * Morton code of its (x, y, z) (neighbouring cells get nearby keys);
 * UINT32_MAX when it meets none. */
uint32_t rc__occupancy_key(const rc__occupancy *grid, const float org[3], const float dir[3], float tmax);

/* Bits rc__occupancy_key's codes use (keys other than UINT32_MAX stay below
 * 1 << RC__OCC_KEY_BITS). */
#define RC__OCC_KEY_BITS 18u

#endif
