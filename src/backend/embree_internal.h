/* The Embree backend's internal knobs, for tests and in-tree tools. Nothing here
 * is public API: the public header stays free of backend-specific fields, and
 * this header needs no Embree header either.
 *
 * A context created with RC_BACKEND_EMBREE (or AUTO resolving to it) carries
 * one rc__embree_options, filled with the defaults below at create; change
 * fields between calls (never while rc_simulate runs). Options read at commit
 * (budget, robust, tie rule) apply to the next commit of each scene;
 * packet_width applies to the next simulate. A scene's build quality is public:
 * rc_scene_desc.build_quality. */
#ifndef RC_BACKEND_EMBREE_INTERNAL_H
#define RC_BACKEND_EMBREE_INTERNAL_H

#include "core/context.h"

#include <stdint.h>

typedef struct rc__embree_options {
    /* Bytes Embree may hold outside the arena (its BVHs and buffers, as its
     * memory monitor reports them, plus the backend's own commit tables).
     * 0 = unlimited. Set at create from rc_context_desc.backend_budget_mib;
     * tests change it to the byte. An allocation that would pass it makes the
     * commit fail with RC_ERR_OUT_OF_MEMORY; the scene stays uncommitted and
     * can be committed again after raising the budget. */
    uint64_t budget_bytes;
    /* 1 (default): RTC_SCENE_FLAG_ROBUST. Without it Embree's faster triangle
     * and box tests let rays slip through shared edges of closed meshes. */
    uint32_t robust;
    /* Rays per Embree query: 0 (default) = the widest packet the CPU runs
     * natively, capped at 8 (see embree.c); 4, 8 or 16 = rtcIntersect4/8/16;
     * 1 = one rtcIntersect1 per ray (for comparisons). */
    uint32_t packet_width;
    /* 1 (default): exact duplicate triangles of a mesh (same three vertex
     * positions in the same order) report the lowest triangle index, as the
     * built-in backend's tie rule does. 0: whichever Embree finds. */
    uint32_t tie_rule;
    /* Bytes the memory monitor and the backend's own tables report now, and
     * their high-water mark (read only). */
    uint64_t bytes_now;
    uint64_t bytes_peak;
    /* Every byte the memory monitor let Embree allocate (read only): a
     * rebuild shows here even when it frees as much as it takes. */
    uint64_t bytes_allocated;
} rc__embree_options;

/* The options of an Embree context; NULL when ctx is not one. */
rc__embree_options *rc__embree_options_of(rc_context *ctx);

/* Creates and releases an Embree device with this configuration string (as
 * rtcNewDevice takes it), through the same error path as context creation:
 * RC_OK, or RC_ERR_BACKEND / RC_ERR_OUT_OF_MEMORY / RC_ERR_UNSUPPORTED with
 * Embree's message in ctx's last error. ctx must be an Embree context. */
rc_status rc__embree_probe_device(rc_context *ctx, const char *config);

/* What Embree's error callback does: records an error (an RTCError code and
 * its message) that the next backend call turns into a status (tests inject
 * errors through it). */
void rc__embree_record_error(rc_context *ctx, int rtc_error, const char *message);

#endif
