/* rcutil: triangle meshes in PLY files (no external libraries).
 *
 * The reader takes ascii, binary_little_endian and binary_big_endian files:
 * element vertex with x y z of any scalar type (other properties skipped),
 * element face with a list property (vertex_indices / vertex_index, else the
 * first list) of any integer count and index types; polygons are split into
 * fans, faces with fewer than 3 vertices are dropped; other elements skipped.
 * One vertex element, before the faces; element counts are plain decimal and
 * must fit in the file (checked before anything is allocated).
 * The writer writes binary little-endian: float x y z, list uchar int
 * vertex_indices, which every PLY reader (Assimp, MeshLab, Blender, Open3D)
 * takes. */
#ifndef RCU_PLY_H
#define RCU_PLY_H

#include "meshgen.h"

/* Reads a PLY mesh. 0 on success; -1 with rcu_last_error() naming the file and
 * the problem (bad header, truncated data, an index past the vertex count ...). */
int rcu_mesh_read_ply(const char *path, rcu_mesh *out);

/* Writes a binary little-endian PLY. */
int rcu_mesh_write_ply(const char *path, const rcu_mesh *mesh);

#endif
