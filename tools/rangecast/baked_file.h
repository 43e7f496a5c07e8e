/* Baked maps (.rcmap, rc_scene_bake) in the program: the file is mapped
 * read-only for the life of the program, so the library loads it in place as
 * a robot would; the commands that need the triangles themselves (the
 * float64 reference, bounds) get a plain copy through rcp_mesh_load. */
#ifndef RCP_BAKED_FILE_H
#define RCP_BAKED_FILE_H

#include <stddef.h>

#include "meshgen.h"

typedef struct rcp_baked {
    const void *blob;  /* page-aligned mapping of the whole file */
    size_t bytes;
} rcp_baked;

/* Maps path and copies its mesh's triangles into out; a map of several
 * geometries (made with the C API) is refused, since the commands' float64
 * reference finds a hit's triangle by prim id alone. Remembers the mapping
 * for rcp_baked_of(out). 0 on success; -1 with rcu_last_error(). */
int rcp_baked_load_mesh(const char *path, rcu_mesh *out);

/* The baked map mesh was read from by rcp_baked_load_mesh, else NULL. */
const rcp_baked *rcp_baked_of(const rcu_mesh *mesh);

/* Writes blob to path through a temporary file in the same folder, renamed
 * into place once complete (a failed write leaves no file). 0 or -1 with
 * rcu_last_error(). */
int rcp_baked_write(const char *path, const void *blob, size_t bytes);

#endif
