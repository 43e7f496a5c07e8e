/* Baked maps (.rcmap, rc_scene_bake) in the program: the file is mapped
 * read-only for the life of the program, so the library loads it in place as
 * a robot would; the commands that need the triangles themselves (the
 * float64 reference, bounds) get a plain copy through rcp_mesh_load. */
#ifndef RCP_BAKED_FILE_H
#define RCP_BAKED_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "meshgen.h"

typedef struct rcp_baked {
    const void *blob;  /* page-aligned mapping of the whole file */
    size_t bytes;
} rcp_baked;

/* Maps path and copies its meshes' triangles into out, geometry after
 * geometry (a map baked with the C API or Python may hold several): the
 * commands that need the triangles (the float64 reference, bounds) see one
 * mesh, and rcp_mesh_triangle finds a hit's. Remembers the mapping for
 * rcp_baked_of(out). 0 on success; -1 with rcu_last_error(). */
int rcp_baked_load_mesh(const char *path, rcu_mesh *out);

/* The index in mesh of the triangle a hit names by (geom id, prim id): for
 * a baked map's copy, where that geometry's triangles start plus prim; for
 * any other mesh (one geometry), prim. UINT64_MAX when out of range. */
uint64_t rcp_mesh_triangle(const rcu_mesh *mesh, uint32_t geom, uint32_t prim);

/* The baked map mesh was read from by rcp_baked_load_mesh, else NULL. */
const rcp_baked *rcp_baked_of(const rcu_mesh *mesh);

/* Writes blob to path through a temporary file in the same folder, renamed
 * into place once complete (a failed write leaves no file). 0 or -1 with
 * rcu_last_error(). */
int rcp_baked_write(const char *path, const void *blob, size_t bytes);

#endif
