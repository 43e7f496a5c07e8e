/* The context object (internal view). Everything a context owns lives in its
 * arena; scenes and sensors are linked so destroy can release backend state. */
#ifndef RC_CORE_CONTEXT_H
#define RC_CORE_CONTEXT_H

#include "core/arena.h"
#include "core/common.h"
#include "core/threads.h"

#define RC__MAGIC_CONTEXT 0x52434358u /* "RCCX" */
#define RC__MAGIC_SCENE   0x52435343u /* "RCSC" */
#define RC__MAGIC_SENSOR  0x52435345u /* "RCSE" */
#define RC__MAGIC_DEAD    0xDEADDEADu

#define RC__ERROR_TEXT 512

struct rc__backend;
struct rc_scene;
struct rc_sensor;

struct rc_context {
    uint32_t magic;
    uint32_t backend_id;            /* RC_BACKEND_BVH / _EMBREE / _VULKAN */
    const struct rc__backend *backend;
    void *backend_data;             /* the backend's own state, allocated by its init */
    rc__arena arena;
    void *owned_block;              /* the malloc'd block, NULL when it is the caller's */
    rc__pool *pool;
    uint32_t thread_count;
    uint32_t reserved0;
    /* The built-in backend's traversals take turns in meshes larger than this
     * (rc__large_mesh_threshold of the CPU's last-level cache); the Embree
     * backend prefetches its hits' triangles in scenes larger than this. */
    uint64_t large_mesh_bytes;
    /* The built-in backend orders a call's tiles on meshes larger than this
     * (rc__ordered_mesh_threshold; UINT64_MAX: never). */
    uint64_t ordered_mesh_bytes;
    /* Ordered, the built-in backend's packets take turns only in meshes
     * larger than this: eight times the last-level cache (0 when its size
     * is unknown: always). Ordered, a map the cache nearly holds is met
     * mostly in cache, and the turns' bookkeeping costs more than it
     * hides: on an AMD VM with a 32 MiB L3 (docs/benchmarks.md, session
     * 27), VLP-16, 2 threads, one tile at a time against turns measured 1M
     * triangles (30 MiB) +19%, 2M +5%, 4M +3.5%, 10M -3%; session 46, 1
     * thread, against the lone lanes' pool: 2M (99 MiB) +15%, 5M (245 MiB)
     * +7 to +10%, 10M (494 MiB) -8%. */
    uint64_t ordered_turns_bytes;
    /* The built-in backend's packets of a mesh larger than this leave their
     * lone lanes to a pool taking turns (RC__PACKET_LONE_POOL), where
     * between large_mesh_bytes and this the packets themselves take turns:
     * eight times the last-level cache (0 when unknown: every large mesh).
     * Session 46, 1 thread, one pose a call (unordered): 1M -10% against the
     * packets' turns, 10M +8%; ordered 2M +14%, 10M +9-10%. */
    uint64_t lone_pool_bytes;
    /* A spinning sensor's projected scan needs every triangle's edges at
     * most this fraction of the map's bounding box diagonal (the built-in
     * backend's RC__RASTER_EDGE_FRACTION; tests raise it to put rooms
     * through the projected scans). */
    double raster_edge_fraction;
    rc_log_fn log;
    void *log_user;
    struct rc_scene *scenes;        /* singly linked, newest first */
    struct rc_sensor *sensors;
    rc_status last_status;
    char last_error[RC__ERROR_TEXT];
};

/* Checks a context handle: RC_OK or RC_ERR_INVALID_HANDLE (no message can be
 * stored when the handle itself is bad). */
int rc__context_valid(const rc_context *ctx);

/* Validates the common prefix of a descriptor: non-NULL, struct_size between
 * min_size (the first released size) and sizeof. Writes a message naming
 * `what` on failure. */
rc_status rc__check_desc(rc_context *ctx, const void *desc, uint32_t min_size, uint32_t max_size,
                         const char *what);
/* Checks n reserved words are zero. */
rc_status rc__check_reserved(rc_context *ctx, const uint32_t *words, size_t n, const char *what);

#endif
