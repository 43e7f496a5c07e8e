/* rangecast: one invocation per ray. Generates the ray (grid models from the
 * per-axis tables, O1Dn/OnDn from the uploaded table), moves it into the map
 * frame with its pose's transform, finds the nearest hit in the scene's
 * two-level BVH (the canonical layout of src/bvh/bvh.h: the top level's
 * binary nodes, each mesh's tree as the 4-wide nodes of src/bvh/wide.h) and
 * writes the requested attributes with the CPU backend's exact semantics
 * (src/backend/results.c); for results kept on the device it also applies
 * the sensor's range noise (noise.glsl), which host results get on the host.
 *
 * This is a port of src/scene/scene_trace.c, src/bvh/mesh.c and
 * src/bvh/intersect.h; keep them in step. Every expression whose rounding
 * matters is `precise` (no FMA contraction, no reassociation), written in the
 * C code's order, so on a device with IEEE division the results are the CPU's
 * bit for bit. Differences that remain by design:
 *  - the slab test never relies on NaN (Vulkan lets devices not generate NaN):
 *    zero direction components are handled by an explicit inside test, and
 *    exit distances are widened by 1 + 2^-19 instead of 1 + 4 eps, because
 *    Vulkan allows 2.5 ULP for 1/x. Both only change which boxes are visited,
 *    never which hit is nearest (both are conservative);
 *  - grid sensors build each direction from per-axis tables on the device
 *    instead of reading the CPU's per-ray table; the float64 kernel does it
 *    in double exactly as the CPU does, the float-only one in float (an ulp
 *    or two off);
 *  - without shaderFloat64 (RC_FP64 0) exactly-zero edge functions are
 *    recomputed in float-float (Dekker) arithmetic instead of double: the
 *    same signs (watertight either way), the values may differ in the last
 *    bit; the origin-in-the-plane check (rc__tri_plane_t_double) is made in
 *    float; and the hit distance is the traversal's float t, without the
 *    CPU's float64 refinement against the triangle's plane (about 1e-6 m
 *    instead of 4e-7 m mean error at 20 m). The zero-area test is the
 *    host's, in double, at upload.
 *
 * Compile-time switches (two SPIR-V modules each): RC_FP64 (0/1), RC_CHUNKS
 * (1 or 4 storage-buffer bindings per large array, for maxStorageBufferRange),
 * RC_RAY_QUERY (0/1): 1 finds the nearest hit with GL_EXT_ray_query in the
 * driver's acceleration structure (binding 18, built by vulkan_accel.c)
 * instead of the BVH walk; ray generation, the float64 refinement and the
 * result writer are this file's either way, so the two traversals differ only
 * in which hit a ray gets where the driver's test and ours disagree (a ray
 * through an edge) and in ties between coplanar triangles.
 */
#version 450
#extension GL_GOOGLE_include_directive : require

#define RC_RAY_QUERY 0
#include "raycast.glsl"
