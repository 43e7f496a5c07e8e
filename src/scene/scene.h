/* Scenes: meshes (geometries), instances of other scenes, and the two-level
 * structure the built-in backend traverses (a top-level BVH over the scene's
 * geometries and instances, one BVH per mesh). */
#ifndef RC_SCENE_SCENE_H
#define RC_SCENE_SCENE_H

#include "bvh/mesh.h"
#include "bvh/packet.h" /* RC__PACKET_MESHES */
#include "core/context.h"
#include "core/rmath.h"

typedef struct rc__geometry {
    rc__mesh mesh;
    void *bvh_block;          /* arena block holding mesh.bvh nodes and refs */
    uint32_t flags;           /* RC_MESH_* */
    uint32_t dirty;           /* 1: build, 2: refit at the next commit */
    uint32_t baked;           /* 1: mesh.wide, bvh.refs and leaf_tris lie in a baked map (never rebuilt) */
    uint32_t reserved0;
} rc__geometry;

typedef struct rc__instance {
    const struct rc_scene *source;
    rc_pose pose;
    float scale[3];
    uint32_t reserved0;
    rc__xformf to_world;      /* source -> this scene, scale included (r = R * diag(s)) */
    rc__xformf to_local;      /* inverse of to_world */
    float normal_to_world[9]; /* R * diag(1/s): local normals -> scene normals (normalise after) */
    rc__aabb bounds;          /* in this scene */
} rc__instance;

struct rc_scene {
    uint32_t magic;
    uint32_t committed;       /* 1 when the structure matches the content */
    rc_context *ctx;
    struct rc_scene *next;    /* the context's list */
    rc_scene_desc desc;       /* capacities as created */
    uint32_t geom_count;
    uint32_t inst_count;
    rc__geometry *geoms;      /* max_geometries */
    rc__instance *insts;      /* max_instances */
    float *copy_vertices;     /* max_vertices * 3 */
    uint32_t *copy_indices;   /* max_copied_triangles * 3 */
    uint64_t copied_vertices_used;
    uint64_t copied_triangles_used;
    uint64_t triangle_count;  /* over all own meshes */
    uint32_t instanced_by;    /* number of instances (in other scenes) that use this scene */
    uint32_t top_dirty;       /* top level needs rebuilding */
    uint32_t baked;           /* 1: loaded from a baked map (read-only) */
    uint32_t reserved1;
    uint64_t version;         /* bumped at every successful commit */
    uint64_t *source_versions;/* per instance: source->version seen at the last commit */
    rc__bvh top;              /* items: geometries 0..geom_count-1, then instances */
    void *top_block;
    size_t accel_block_bytes; /* top_block's payload as kept after commit */
    rc__aabb bounds;
    void *backend_scene;      /* backend's own state (Embree scene, Vulkan buffers) */
};

int rc__scene_valid(const rc_scene *scene);

/* Arena bytes of the scene object and its tables (at create). */
size_t rc__scene_object_bytes(const rc_scene_desc *desc);

/* Builds or refits the built-in two-level BVH of the scene: mesh BVHs that are
 * dirty, then the top level. Used by the BVH backend and by the Vulkan backend
 * (which uploads it). Exact peak arena use: rc__scene_bvh_commit_bytes. */
rc_status rc__scene_build_bvh(rc_scene *scene, rc_progress_fn progress, void *user);
size_t rc__scene_bvh_commit_bytes(const rc_scene_desc *desc);
/* The same with each mesh's tree collapsed to 4-wide nodes (bvh/wide.h), for
 * the built-in backend; the binary mesh trees exist only during commit. */
rc_status rc__scene_build_wide(rc_scene *scene, rc_progress_fn progress, void *user);
size_t rc__scene_wide_commit_bytes(const rc_scene_desc *desc);
void rc__scene_release_bvh(rc_scene *scene);

/* A scene object in the context's arena, linked into its list (scene_api.c);
 * NULL with the message written when the arena has no room. */
rc_scene *rc__scene_new(rc_context *ctx, const rc_scene_desc *desc);
/* Releases a scene that no other scene instances: backend state, tree, object. */
void rc__scene_free(rc_scene *scene);

/* Baked maps (baked_write.c, baked_load.c). The bytes rc__scene_bake
 * writes for a committed scene of meshes with wide trees, and the writer
 * (blob holds exactly that many bytes). */
uint64_t rc__scene_baked_bytes(const rc_scene *scene);
void rc__scene_bake(const rc_scene *scene, unsigned char *blob);
/* The scene desc a baked blob loads as on a backend (header checked;
 * messages to ctx). */
rc_status rc__baked_scene_desc(rc_context *ctx, const unsigned char *blob, size_t bytes, int prebuilt,
                               rc_scene_desc *desc);
/* Checks the whole blob (checksum unless skip_checksum) and creates the
 * scene, ready for its backend's commit: prebuilt (the built-in backend)
 * takes the baked trees in place, else the meshes are marked for a build. */
rc_status rc__scene_load_baked(rc_context *ctx, const unsigned char *blob, size_t bytes, int skip_checksum,
                               int prebuilt, rc_scene **out);

/* 1 when every instance's source is committed at the version seen at our commit. */
int rc__scene_up_to_date(const rc_scene *scene);

/* Nearest hit in the scene along ray (scene coordinates), 0 < t < hit->t,
 * among the top level's items from first on (0: everything; geom_count: the
 * instances only, after the own meshes were searched another way). Returns 1
 * when hit was updated. */
int rc__scene_intersect_items(const rc_scene *scene, const rc__ray *ray, rc__hit *hit, uint32_t first);
static inline int rc__scene_intersect(const rc_scene *scene, const rc__ray *ray, rc__hit *hit)
{
    return rc__scene_intersect_items(scene, ray, hit, 0u);
}

#if defined(RC__PACKET_MESHES)
/* Meshes a packet walks together: at most this many a call of
 * rc__mesh_intersect_packet_meshes. */
#define RC__SCENE_PACKET_BATCH 32u
/* A packet (rc__mesh_intersect_packet's rays, n, hits, found and flags)
 * through the scene's own meshes, any number of them: the top-level tree
 * is walked once for the whole packet, and the meshes some ray of it may
 * meet go through rc__mesh_intersect_packet_meshes, RC__SCENE_PACKET_BATCH
 * at a time. Meshes g < 32 with bit g of skip set are left out (the caller
 * traces them another way); instances are left out. The same hits as
 * rc__scene_intersect_items ray by ray up to the instances. */
void rc__scene_intersect_packet(const rc_scene *scene, const rc__ray *rays, uint32_t n, uint32_t skip, rc__hit *hits,
                                int *found, uint32_t flags);
/* The same walk through the scene's instances only (after its own meshes were
 * searched another way): each instance some ray may meet takes the packet,
 * its rays moved into the instance's frame as rc__scene_intersect_items
 * moves each, through its source's meshes. The same hits as
 * rc__scene_intersect_items(scene, ray, hit, geom_count) ray by ray. */
void rc__scene_intersect_packet_instances(const rc_scene *scene, const rc__ray *rays, uint32_t n, rc__hit *hits,
                                          int *found, uint32_t flags);
#endif

/* The hit's distance recomputed in double: the ray (sensor-frame direction
 * dir_s and origin org_s, NULL for the sensor's own origin, through the
 * scan's world transform in double) against the plane of the hit triangle
 * (through its instance's transform in double). Returns hit->t where the ray
 * is parallel to the plane, and where it crosses the plane far off the
 * triangle (more than 1/4096 of t away, and further from corner a's depth
 * along the ray than twice the other corners' spread from it: a ray along
 * the plane, hit by the float test's rounding; docs/architecture.md). */
double rc__scene_hit_distance_d(const rc_scene *scene, const rc__hit *hit, const rc__xformf *world,
                                const float dir_s[3], const float *org_s);

#if defined(__SSE2__) && !defined(RC__WIDE_FORCE_SCALAR)
#include <emmintrin.h>
#define RC__HIT_DISTANCES_SSE2 1 /* x86's parts of the grouped refinement and writer */
#endif
/* rc__scene_hit_distance_d for the n rays of a tile of a one-origin sensor
 * (ray i: sensor direction directions[3 * idx[i]], hit hits[i] where
 * found[i]), two hits at a time in SSE2 doubles (four in AVX where the CPU
 * has AVX2) or AArch64 NEON doubles, each value bit for bit the scalar
 * function's; td[i] = 0 where found[i] is 0. (1k sphere: the refinement one
 * hit at a time was 17% of the instructions.) Left out of -Os builds on
 * AArch64 (the static core's size budget), where tiles are written ray by
 * ray with the same values. */
#if defined(RC__HIT_DISTANCES_SSE2) ||                                                                               \
    (defined(__aarch64__) && defined(__ARM_NEON) && !defined(__OPTIMIZE_SIZE__) && !defined(RC__WIDE_FORCE_SCALAR))
#define RC__HIT_DISTANCES_LANES 1
void rc__scene_hit_distances_d(const rc_scene *scene, const rc__hit *hits, const int *found, uint32_t n,
                               const rc__xformf *world, const float *directions, const uint32_t *idx, double *td);
#endif

/* Unit geometric normal of a hit, in the scene's frame. */
void rc__scene_hit_normal(const rc_scene *scene, const rc__hit *hit, float n[3]);

#endif
