/* The C half of the std430 layout contract with the GLSL kernels. The GLSL
 * half, with the offsets written out, is kernels/layout.glsl; the static
 * asserts below fail the build when a C struct drifts, and
 * tests/test_vulkan_layout.c has kernels/layout_check.comp read known values
 * back on the device, which fails when the GLSL side drifts. */
#ifndef RC_BACKEND_VULKAN_LAYOUT_H
#define RC_BACKEND_VULKAN_LAYOUT_H

#include "bvh/bvh.h"
#include "bvh/wide.h"

#include <stddef.h>
#include <stdint.h>

/* One mesh in the concatenated scene arrays (GLSL: struct Geom). */
typedef struct rc__vk_geom {
    uint32_t node_base; /* its wide root takes nodes[node_base .. + 4); wide node k slots node_base + 4k .. */
    uint32_t ref_base;  /* its refs start at refs[ref_base] */
    uint32_t tri_base;  /* leaf slot j's triangle is tris[tri_base + j] (leaf order, global vertex indices) */
    uint32_t geom_id;   /* geometry id within its own scene */
} rc__vk_geom;

/* One instance (GLSL: struct Inst). Rows of 3x4 matrices (R | t). */
typedef struct rc__vk_inst {
    float to_local[12];   /* scene -> source frame, scale included */
    float n2w[12];        /* source normals -> scene (R * S^-1), w unused */
    uint32_t first_geom;  /* its source's first rc__vk_geom */
    uint32_t geom_count;  /* its source's geometries */
    uint32_t pad0, pad1;
    uint32_t to_world_d[24]; /* source -> scene in double: R row-major, t; (low, high) words */
} rc__vk_inst;

/* One pose's transform (GLSL: 9 uvec4 of Xforms): sensor -> scene frame as
 * float rows (R | t), then in double (R row-major, t; (low, high) words). */
typedef struct rc__vk_xform {
    float rows[12];
    uint32_t d[24];
} rc__vk_xform;

/* Push constants of raycast.comp (GLSL: uniform PC), 28 words. */
typedef struct rc__vk_push {
    uint32_t first_pose, first_ray, count, rays;
    uint32_t columns, rows;
    float range_min, range_max;
    uint32_t geom_count, top_node, top_ref, groups_x, flags;
    uint32_t off[7]; /* word offsets of hits, ranges, points, normals, prim, geom, inst */
    /* range noise of results kept on the device (kernels/noise.glsl) */
    uint32_t noise_key[2];  /* rc__noise_key(seed, draw), low word first */
    uint32_t noise_drop[2]; /* floor(dropout * 2^53): a return is lost below it */
    float noise_mean, noise_sigma, noise_exponent;
    uint32_t noise_flags;   /* RC__VK_NOISE_* */
} rc__vk_push;

/* rc__vk_push.flags: bit 0 one mesh and no instances (rc__vk_pack_info.flags);
 * bit 31 is never set: the kernel ORs it into values it must keep rounded to
 * float (raycast.glsl, f32), a zero the shader compiler cannot fold away. */
#define RC__VK_FLAGS_NEVER_SET 0x80000000u
/* bit 30, for tests only (RANGECAST_VULKAN_SKEW_DIV=1): the kernel's float
 * divisions start 2 ulps off, as a driver's OpFDiv may, so that lavapipe,
 * which divides exactly, shows whether div_rn puts them right */
#define RC__VK_FLAGS_SKEW_DIV 0x40000000u
/* bits 29 and 28, for measurements only (RANGECAST_VULKAN_SKIP=walk or
 * refine): the kernel skips the BVH walk (each ray takes slot 0's triangle
 * as its hit at half the range) or the float64 refinement of the range, so
 * that the difference in time is what that stage costs on a GPU no profiler
 * reads (results are wrong in either mode) */
#define RC__VK_FLAGS_SKIP_WALK 0x20000000u
#define RC__VK_FLAGS_SKIP_REFINE 0x10000000u
#define RC__VK_FLAGS_DEBUG (RC__VK_FLAGS_SKEW_DIV | RC__VK_FLAGS_SKIP_WALK | RC__VK_FLAGS_SKIP_REFINE)

#define RC__VK_NOISE_ON 1u
#define RC__VK_NOISE_MOVES 2u
#define RC__VK_NOISE_DROPS 4u

#define RC__VK_ASSERT(cond, name) typedef char rc__vk_layout_assert_##name[(cond) ? 1 : -1]

RC__VK_ASSERT(sizeof(rc__bvh_node) == 32, node_size);
RC__VK_ASSERT(offsetof(rc__bvh_node, bmin) == 0, node_bmin);
RC__VK_ASSERT(offsetof(rc__bvh_node, index) == 12, node_index);
RC__VK_ASSERT(offsetof(rc__bvh_node, bmax) == 16, node_bmax);
RC__VK_ASSERT(offsetof(rc__bvh_node, count) == 28, node_count);
/* a mesh's wide node takes four node slots (kernels/layout.glsl, WNode) */
RC__VK_ASSERT(sizeof(rc__wnode) == 4 * sizeof(rc__bvh_node), wnode_slots);
RC__VK_ASSERT(offsetof(rc__wnode, child) == 96 && offsetof(rc__wnode, count) == 112, wnode_members);
RC__VK_ASSERT(sizeof(rc__vk_geom) == 16, geom_size);
RC__VK_ASSERT(offsetof(rc__vk_geom, tri_base) == 8, geom_tri_base);
RC__VK_ASSERT(offsetof(rc__vk_geom, geom_id) == 12, geom_geom_id);
RC__VK_ASSERT(sizeof(rc__vk_inst) == 208, inst_size);
RC__VK_ASSERT(offsetof(rc__vk_inst, to_world_d) == 112, inst_to_world_d);
RC__VK_ASSERT(sizeof(rc__vk_xform) == 144, xform_size);
RC__VK_ASSERT(sizeof(double) == 8, double_size);
RC__VK_ASSERT(offsetof(rc__vk_inst, n2w) == 48, inst_n2w);
RC__VK_ASSERT(offsetof(rc__vk_inst, first_geom) == 96, inst_first_geom);
RC__VK_ASSERT(offsetof(rc__vk_inst, geom_count) == 100, inst_geom_count);
RC__VK_ASSERT(sizeof(rc__vk_push) == 112, push_size);
RC__VK_ASSERT(offsetof(rc__vk_push, noise_key) == 80, push_noise_key);
RC__VK_ASSERT(offsetof(rc__vk_push, noise_flags) == 108, push_noise_flags);
RC__VK_ASSERT(offsetof(rc__vk_push, range_min) == 24, push_range_min);
RC__VK_ASSERT(offsetof(rc__vk_push, off) == 52, push_off);

/* Binding numbers of raycast.comp. */
#define RC__VK_BIND_NODES 0u   /* 0..3: chunks */
#define RC__VK_BIND_TRIS 4u    /* 4..7 */
#define RC__VK_BIND_VERTS 8u   /* 8..11 */
#define RC__VK_BIND_REFS 12u
#define RC__VK_BIND_GEOMS 13u
#define RC__VK_BIND_INSTS 14u
#define RC__VK_BIND_XFORMS 15u
#define RC__VK_BIND_RAYS 16u
#define RC__VK_BIND_OUT 17u
#define RC__VK_BINDINGS 18u   /* storage buffers */
#define RC__VK_BIND_TLAS 18u   /* the ray query kernel's acceleration structure */
#define RC__VK_MAX_CHUNKS 4u

/* Values of the MODEL specialization constant. */
#define RC__VK_MODEL_O1DN 0u
#define RC__VK_MODEL_ONDN 1u
#define RC__VK_MODEL_SPHERICAL 2u
#define RC__VK_MODEL_PINHOLE 3u
#define RC__VK_MODEL_PINHOLE_OPT 4u
#define RC__VK_MODEL_CYLINDRICAL 5u

/* Words layout_check.comp writes. */
#define RC__VK_LAYOUT_CHECK_WORDS 64u

#endif
