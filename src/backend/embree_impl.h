/* What the Embree backend's files (embree.c, embree_scene.c, embree_trace.c)
 * share: the thin version layer over Embree 3 (Debian 12's libembree-dev 3.13)
 * and Embree 4, and the backend's state.
 *
 * Version layer: the header, the ray-query context and the intersect calls
 * differ; every other call the backend makes is the same in both.
 * RANGECAST_EMBREE_MAJOR comes from the build (the found package's major
 * version); 3 when unset. */
#ifndef RC_BACKEND_EMBREE_IMPL_H
#define RC_BACKEND_EMBREE_IMPL_H

#include "backend/backend.h"
#include "backend/embree_internal.h"
#include "backend/embree_occupancy.h"

#if defined(RANGECAST_EMBREE_MAJOR) && RANGECAST_EMBREE_MAJOR >= 4
#include <embree4/rtcore.h>
#else
#include <embree3/rtcore.h>
#endif

#if RTC_VERSION_MAJOR >= 4

/* Embree 4: the context travels inside RTCIntersectArguments. */
typedef struct rc__rtc_query {
    struct RTCRayQueryContext context;
    struct RTCIntersectArguments args;
} rc__rtc_query;

static inline void rc__rtc_query_init(rc__rtc_query *q, int coherent)
{
    rtcInitRayQueryContext(&q->context);
    rtcInitIntersectArguments(&q->args);
    q->args.context = &q->context;
    q->args.flags = coherent ? RTC_RAY_QUERY_FLAG_COHERENT : RTC_RAY_QUERY_FLAG_INCOHERENT;
}

#define RC__RTC_INTERSECT1(q, scene, rh) rtcIntersect1((scene), (rh), &(q)->args)
#define RC__RTC_INTERSECT4(q, valid, scene, rh) rtcIntersect4((valid), (scene), (rh), &(q)->args)
#define RC__RTC_INTERSECT8(q, valid, scene, rh) rtcIntersect8((valid), (scene), (rh), &(q)->args)
#define RC__RTC_INTERSECT16(q, valid, scene, rh) rtcIntersect16((valid), (scene), (rh), &(q)->args)

#else

/* Embree 3: an RTCIntersectContext passed to every call. */
typedef struct rc__rtc_query {
    struct RTCIntersectContext context;
} rc__rtc_query;

static inline void rc__rtc_query_init(rc__rtc_query *q, int coherent)
{
    rtcInitIntersectContext(&q->context);
    q->context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
}

#define RC__RTC_INTERSECT1(q, scene, rh) rtcIntersect1((scene), &(q)->context, (rh))
#define RC__RTC_INTERSECT4(q, valid, scene, rh) rtcIntersect4((valid), (scene), &(q)->context, (rh))
#define RC__RTC_INTERSECT8(q, valid, scene, rh) rtcIntersect8((valid), (scene), &(q)->context, (rh))
#define RC__RTC_INTERSECT16(q, valid, scene, rh) rtcIntersect16((valid), (scene), &(q)->context, (rh))

#endif

/* The context's backend state (its arena holds it). */
typedef struct rc__emb_device {
    rc__embree_options options; /* first: rc__embree_options_of returns it */
    rc_context *ctx;
    RTCDevice device;
    uint32_t native_width;      /* widest packet the CPU runs natively: 16, 8, 4 or 1 */
    int budget_refused;         /* the budget refused an allocation since the last check */
    int error_code;             /* first RTCError the callback recorded since the last check */
    char error_text[256];       /* its message */
} rc__emb_device;

/* One mesh of a scene as an Embree triangle geometry with the same id. */
typedef struct rc__emb_geom {
    RTCGeometry geom;           /* NULL until the first commit that sees the mesh */
    uint32_t copied;            /* 1: vertices copied into an Embree buffer (padding rule) */
    uint32_t dups_done;         /* dups reflect the current vertices */
    uint32_t dup_count;
    uint32_t reserved0;
    uint32_t *dups;             /* dup_count pairs (prim, lowest identical prim), by prim; malloc'd */
} rc__emb_geom;

/* A scene's Embree state (scene->backend_scene), one arena block taken at the
 * first commit: geometries keep their ids, instance i has id max_geoms + i.
 * A scene that can hold instances (a dynamic map) keeps its own meshes apart,
 * in mesh_scene, placed in the top scene by one identity instance (id
 * mesh_inst_id): a commit that only moved instances then rebuilds the top
 * scene over the instances, not Embree's tree over every triangle of the map.
 * Instancing such a scene instances its mesh_scene. Once one of its meshes
 * has been updated (rc_scene_update_mesh) the scene holding the meshes builds
 * in two levels (dynamic; embree_scene.c, mesh_scene_settings). */
typedef struct rc__emb_scene {
    RTCScene scene;             /* what rays are traced against */
    uint32_t max_geoms;
    uint32_t max_insts;
    rc__emb_geom *geoms;        /* max_geoms */
    RTCGeometry *insts;         /* max_insts */
    RTCScene mesh_scene;        /* the own meshes when split, else NULL (they are in scene) */
    RTCGeometry mesh_inst;      /* scene's identity instance of mesh_scene (once it has meshes) */
    uint32_t mesh_inst_id;      /* max_geoms + max_insts */
    uint32_t dynamic;           /* 1 once a mesh was updated: the meshes' scene builds in two levels */
    uint32_t unfinished;        /* 1 while a commit has not completed (it failed, or runs) */
    uint32_t twins_any;         /* 1 when some instance has a lower twin (inst_twin) */
    /* The tie rule across instances: inst_twin[i] is the lowest instance with
     * the same source and the same transform bit for bit (i itself when none),
     * found at commit through twin_slots (twin_mask + 1 of them). Such twins
     * give the same hit at the same distance; the tracer reports the lowest,
     * as the built-in backend does. */
    uint32_t *inst_twin;        /* max_insts */
    uint32_t *twin_slots;
    uint32_t twin_mask;
    uint32_t reserved0;
    /* The own meshes' occupancy (backend/embree_occupancy.h) that keys ordered runs,
     * on large scenes without instances; NULL elsewhere. Malloc'd, counted
     * against the budget. */
    rc__occupancy *occupancy;
} rc__emb_scene;

/* embree_scene.c: bytes of the scene's own meshes' index and vertex arrays. */
uint64_t rc__emb_mesh_array_bytes(const rc_scene *scene);

/* The scene holding es's own meshes, which is what instancing es instances. */
static inline RTCScene rc__emb_mesh_scene(const rc__emb_scene *es)
{
    return es->mesh_scene ? es->mesh_scene : es->scene;
}

/* embree.c: the backend's one table (registry.c names it too). */
extern const rc__backend rc__backend_embree;

/* embree.c: turns Embree's pending error (rtcGetDeviceError, the error
 * callback, a refused budget) into a status with Embree's message naming
 * `what`; RC_OK when there is none. Clears it. */
rc_status rc__emb_check(rc__emb_device *d, const char *what);
/* Clears any pending error before a sequence of Embree calls. */
void rc__emb_clear(rc__emb_device *d);
/* Counts bytes the backend mallocs itself (negative when freed) against the
 * budget: RC_ERR_OUT_OF_MEMORY (message written) when it would pass it. */
rc_status rc__emb_account(rc__emb_device *d, int64_t bytes, const char *what);

/* embree_scene.c */
size_t rc__emb_scene_bytes(const rc_scene_desc *desc);
rc_status rc__emb_scene_commit(rc_scene *scene, rc_progress_fn progress, void *user);
void rc__emb_scene_release(rc_scene *scene);
/* Lowest triangle identical to prim (itself when none), by the dup table. */
uint32_t rc__emb_canonical_prim(const rc__emb_geom *g, uint32_t prim);

/* embree_trace.c */
rc_status rc__emb_simulate(rc_context *ctx, const rc__sim_job *job);

#endif
