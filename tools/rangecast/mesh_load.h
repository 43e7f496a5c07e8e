/* Loading maps: .ply with rcutil's own reader (fast, exact), .rcmap baked
 * maps (baked_file.h: mapped, and copied for the commands that read the
 * triangles), every other
 * format (.obj .stl .dae .gltf .glb .fbx .3ds .off ...) through Assimp's C API
 * when the program was built with it. */
#ifndef RCP_MESH_LOAD_H
#define RCP_MESH_LOAD_H

#include "meshgen.h"

/* Loads every triangle of the file into one mesh (node transforms applied,
 * points and lines dropped). 0 on success; -1 with rcu_last_error(). */
int rcp_mesh_load(const char *path, rcu_mesh *out);

/* "ply" or "ply, obj, stl, ..." : what rcp_mesh_load takes. */
const char *rcp_mesh_formats(void);

#endif
