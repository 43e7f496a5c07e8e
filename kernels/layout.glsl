/* rangecast: the std430 layout contract between the C side
 * (src/backend/vulkan_layout.h) and the GLSL kernels. Change both together.
 *
 * Every struct below has the same size and member offsets as its C twin; the
 * C header checks sizes and offsets with static asserts, and
 * tests/test_vulkan_layout.c uploads known values and has
 * kernels/layout_check.comp read them back member by member, so a mismatch on
 * either side fails the build or that test.
 *
 *   Node  (32 bytes) = rc__bvh_node, the canonical BVH node, uploaded as is
 *         for the top level:
 *           off  0 vec3 bmin   | off 12 uint index
 *           off 16 vec3 bmax   | off 28 uint count
 *         interior: count == 0, children nodes[base + index], nodes[base + index + 1]
 *         leaf:     count >= 1, items refs[ref_base + index .. + count)
 *         (std430 puts a vec3 at a 16-byte boundary and the following uint in
 *         its 4th word: exactly the C struct.) The top level's nodes.
 *   WNode (128 bytes = 4 Node slots, 4-aligned) = rc__wnode (src/bvh/wide.h),
 *         a mesh's 4-wide node, read as 8 uvec4 of the same bindings:
 *           uvec4 0..5  box planes bmin x, bmax x, bmin y, bmax y, bmin z,
 *                       bmax z (float bits), one lane per child
 *           uvec4 6     child: wide node index (relative) or first leaf slot;
 *                       0xFFFFFFFF for an empty slot
 *           uvec4 7     count: 0 for a node, else the leaf's triangles (1..4)
 *   Geom  (16 bytes) = rc__vk_geom: where one mesh's arrays start in the
 *         concatenated scene arrays (node_base: its wide root's first slot),
 *         and its geometry id within its own scene.
 *           off 0 node_base | off 4 ref_base | off 8 tri_base | off 12 geom_id
 *         tris[tri_base + j] (3 uints, vertex indices already offset into
 *         the concatenated vertex array) is the triangle of the mesh's leaf
 *         slot j, i.e. of refs[ref_base + j] (leaf order).
 *   Inst  (208 bytes) = rc__vk_inst:
 *           off  0 vec4 to_local[3]   rows of (R | t): scene -> source frame
 *           off 48 vec4 n2w[3]        rows of the normal matrix (w unused)
 *           off 96 uint first_geom    first Geom of its source scene
 *           off 100 uint geom_count   geometries of the source
 *           off 104 uint pad[2]
 *           off 112 uint to_world_d[24]  source -> scene in double, R row-major
 *                                     then t, each double as (low, high) words
 *                                     (for the float64 refinement of t)
 *   Xform (144 bytes a pose, 9 uvec4): rows[3] of (R | t) as float bits, then
 *         the same transform in double (R row-major then t, (low, high)
 *         words): sensor -> scene frame (the scene's origin subtracted).
 *   Vertices: 3 floats each (tightly packed, any input stride repacked).
 *   Triangles: 3 uints each.
 */
#ifndef RC_LAYOUT_GLSL
#define RC_LAYOUT_GLSL

struct Node {
    vec3 bmin;
    uint index;
    vec3 bmax;
    uint count;
};

struct Geom {
    uint node_base;
    uint ref_base;
    uint tri_base;
    uint geom_id;
};

struct Inst {
    vec4 to_local[3];
    vec4 n2w[3];
    uint first_geom;
    uint geom_count;
    uint pad0;
    uint pad1;
    uint to_world_d[24];
};

#define XFORM_UVEC4S 9u /* per pose */

#define RC_INVALID_ID 0xFFFFFFFFu

/* Attribute bits (RC_ATTR_*). */
#define ATTR_HITS     0x01u
#define ATTR_RANGES   0x02u
#define ATTR_POINTS   0x04u
#define ATTR_NORMALS  0x08u
#define ATTR_PRIM_IDS 0x10u
#define ATTR_GEOM_IDS 0x20u
#define ATTR_INST_IDS 0x40u

/* Ray models (specialization constant MODEL). */
#define MODEL_O1DN        0u
#define MODEL_ONDN        1u
#define MODEL_SPHERICAL   2u
#define MODEL_PINHOLE     3u /* body frame */
#define MODEL_PINHOLE_OPT 4u /* optical frame */
#define MODEL_CYLINDRICAL 5u

#endif
