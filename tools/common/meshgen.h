/* rcutil: triangle meshes in plain arrays and generators for the standard
 * workloads (UV spheres), test shapes (boxes, planes, cylinders, wedges) and the
 * demo warehouse. All generators are deterministic: the same call gives the same
 * bytes on every platform.
 *
 * Errors: functions returning int give 0 on success and -1 on failure, with the
 * reason in rcu_last_error(). On failure *out is left empty (all zero). */
#ifndef RCU_MESHGEN_H
#define RCU_MESHGEN_H

#include <stddef.h>
#include <stdint.h>

#include "util.h"

typedef struct rcu_mesh {
    float *vertices;       /* x, y, z per vertex (malloc'd) */
    uint32_t *indices;     /* 3 vertex indices per triangle (malloc'd) */
    uint32_t vertex_count;
    uint32_t triangle_count;
} rcu_mesh;

/* Frees the arrays and zeroes the struct. NULL is a no-op. */
void rcu_mesh_free(rcu_mesh *mesh);

/* Allocates an empty mesh with room for the given counts (counts stay 0). */
int rcu_mesh_reserve(rcu_mesh *mesh, uint64_t vertices, uint64_t triangles);

/* Closed UV sphere centred at the origin: poles are single vertices, the seam
 * shares its vertices, every edge is shared by exactly two triangles, and every
 * triangle winds counter-clockwise seen from outside (normals point out).
 * segments_around >= 3 (longitude), rings >= 2 (latitude bands).
 * Vertices: segments_around * (rings - 1) + 2; triangles: 2 * segments_around * (rings - 1). */
int rcu_mesh_uv_sphere(float radius, uint32_t segments_around, uint32_t rings, rcu_mesh *out);

/* The segments/rings rcu_mesh_uv_sphere_triangles uses for a target count. */
void rcu_uv_sphere_shape(uint64_t approx_triangles, uint32_t *segments_around, uint32_t *rings);

/* A UV sphere with about approx_triangles triangles (segments ~ 2 * rings ~
 * sqrt(approx_triangles), so quads are near square at the equator). Standard
 * workloads: 1k, 10k, 100k, 1M, 10M triangles (990, 9,996, 99,852, 999,996,
 * 10,001,400: within 1%). */
int rcu_mesh_uv_sphere_triangles(float radius, uint64_t approx_triangles, rcu_mesh *out);

/* Closed axis-aligned box (8 shared vertices, 12 triangles, normals out). */
int rcu_mesh_box(const float min[3], const float max[3], rcu_mesh *out);

/* Horizontal square of 2 triangles at height center[2], side 2 * half_size,
 * normal +z. */
int rcu_mesh_plane(const float center[3], float half_size, rcu_mesh *out);

/* A quad p0 p1 p2 p3 (in order around it) as 2 triangles (p0 p1 p2, p0 p2 p3). */
int rcu_mesh_quad(const float p0[3], const float p1[3], const float p2[3], const float p3[3],
                  rcu_mesh *out);

/* Closed upright cylinder: bottom centre base[3], radius, height, segments >= 3
 * (caps are fans around a centre vertex). Triangles: 4 * segments. */
int rcu_mesh_cylinder(const float base[3], float radius, float height, uint32_t segments,
                      rcu_mesh *out);

/* Closed wedge (a ramp): the box min..max whose top face slopes from z = min[2]
 * at x = min[0] up to z = max[2] at x = max[0]. 6 vertices, 8 triangles. */
int rcu_mesh_wedge(const float min[3], const float max[3], rcu_mesh *out);

/* Appends src to dst (dst may be empty/zeroed); src is unchanged. */
int rcu_mesh_append(rcu_mesh *dst, const rcu_mesh *src);

/* Cuts mesh into `parts` meshes (1 <= parts <= triangle_count) of
 * consecutive triangles: part k holds triangles [first(k), first(k + 1)),
 * first(k) = triangle_count * k / parts (rcu_mesh_part_first), with only the
 * vertices they use, in the order they first use them. out holds `parts`
 * meshes (freed with rcu_mesh_free each); on failure none is left. 0 or -1
 * with rcu_last_error(). */
int rcu_mesh_split(const rcu_mesh *mesh, uint32_t parts, rcu_mesh *out);
uint32_t rcu_mesh_part_first(uint32_t triangles, uint32_t parts, uint32_t k);

/* Moves every vertex: rotate about z by yaw (radians), then translate. */
void rcu_mesh_transform(rcu_mesh *mesh, float yaw, const float translation[3]);

/* Axis-aligned bounds: min xyz, max xyz (all 0 for an empty mesh). */
void rcu_mesh_bounds(const rcu_mesh *mesh, float bounds[6]);

/* The demo warehouse: a closed room x in [-10, 10], y in [-6, 6], z in [0, 4]
 * with pillars, pallet racks with crates, stacked boxes, barrels, a ramp up to
 * a loading platform, and a ball. A few thousand triangles; deterministic. */
int rcu_mesh_demo_map(rcu_mesh *out);

#endif
