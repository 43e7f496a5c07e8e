/* The Embree backend: the device, its memory monitor and budget, error
 * mapping, and the backend table. Scenes are in embree_scene.c, tracing in
 * embree_trace.c.
 *
 * - One Embree device per context, configured with "threads=N" (N = the
 *   context's thread count) for its builds. Embree allocates internally (tier 2
 *   of the memory rules): every allocation goes through the memory monitor,
 *   which counts it (rc_memory_stats.backend_bytes) and refuses it past the
 *   budget (rc_context_desc.backend_budget_mib, kept in
 *   rc__embree_options.budget_bytes; 0 = unlimited, the default; the arena
 *   size never covers Embree). A refused allocation makes
 *   Embree abandon the commit with RTC_ERROR_OUT_OF_MEMORY, which becomes
 *   RC_ERR_OUT_OF_MEMORY.
 * - Errors: device creation failure, the device's error callback, and
 *   rtcGetDeviceError after each sequence of calls become rangecast statuses
 *   (RC_ERR_OUT_OF_MEMORY for RTC_ERROR_OUT_OF_MEMORY, RC_ERR_UNSUPPORTED for
 *   RTC_ERROR_UNSUPPORTED_CPU, RC_ERR_BACKEND for the rest) with Embree's
 *   message in the last-error text.
 * - With TBB as Embree's tasking system (Debian's build), "threads=N" is a
 *   process-wide limit while the device lives: several contexts with
 *   different thread counts build with the smallest. Tracing runs on the
 *   context's own thread pool and is not affected. */
#include "backend/embree_impl.h"
#include "core/cache_size.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

/* The monitor is called from Embree's build threads at once. C99 has no
 * atomics: GCC and Clang builtins here; other compilers get plain updates,
 * exact only when Embree builds on one thread. */
#if defined(__GNUC__) || defined(__clang__)
static uint64_t atomic_add(uint64_t *p, uint64_t v) { return __atomic_add_fetch(p, v, __ATOMIC_RELAXED); }
static uint64_t atomic_load(const uint64_t *p) { return __atomic_load_n(p, __ATOMIC_RELAXED); }
static void atomic_max(uint64_t *p, uint64_t v)
{
    uint64_t cur = __atomic_load_n(p, __ATOMIC_RELAXED);
    while (v > cur && !__atomic_compare_exchange_n(p, &cur, v, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
    }
}
static void atomic_flag_set(int *p) { __atomic_store_n(p, 1, __ATOMIC_RELAXED); }
#else
static uint64_t atomic_add(uint64_t *p, uint64_t v) { return *p += v; }
static uint64_t atomic_load(const uint64_t *p) { return *p; }
static void atomic_max(uint64_t *p, uint64_t v)
{
    if (v > *p) *p = v;
}
static void atomic_flag_set(int *p) { *p = 1; }
#endif

static const char *error_name(int code)
{
    switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
    default: return "RTC_ERROR (unknown code)";
    }
}

static rc_status status_of(int code)
{
    switch (code) {
    case RTC_ERROR_OUT_OF_MEMORY: return RC_ERR_OUT_OF_MEMORY;
    case RTC_ERROR_UNSUPPORTED_CPU: return RC_ERR_UNSUPPORTED;
    default: return RC_ERR_BACKEND;
    }
}

static void record(rc__emb_device *d, int code, const char *message)
{
    if (d->error_code != RTC_ERROR_NONE) return; /* keep the first: it is the cause */
    d->error_code = code;
    if (message) {
        strncpy(d->error_text, message, sizeof d->error_text - 1u);
        d->error_text[sizeof d->error_text - 1u] = '\0';
    } else {
        d->error_text[0] = '\0';
    }
}

static void on_error(void *user, enum RTCError code, const char *message)
{
    record((rc__emb_device *)user, (int)code, message);
}

/* bytes > 0: about to allocate (post false) or allocated (post true); bytes <
 * 0: freed. Refusing (false) cancels the Embree operation; an allocation
 * refused before it happened is not counted, one refused after is (Embree
 * frees it later through this monitor). */
static bool on_memory(void *user, ssize_t bytes, bool post)
{
    rc__emb_device *d = (rc__emb_device *)user;
    uint64_t now = atomic_add(&d->options.bytes_now, (uint64_t)(int64_t)bytes);
    uint64_t budget = d->options.budget_bytes;
    if (bytes > 0 && budget != 0 && now > budget) {
        atomic_flag_set(&d->budget_refused);
        if (!post) {
            atomic_add(&d->options.bytes_now, (uint64_t)(-(int64_t)bytes));
            return false;
        }
        atomic_max(&d->options.bytes_peak, now);
        return false;
    }
    if (bytes > 0) {
        atomic_max(&d->options.bytes_peak, now);
        atomic_add(&d->options.bytes_allocated, (uint64_t)bytes); /* told before or after, once */
    }
    return true;
}

void rc__emb_clear(rc__emb_device *d)
{
    (void)rtcGetDeviceError(d->device);
    d->error_code = RTC_ERROR_NONE;
    d->error_text[0] = '\0';
    d->budget_refused = 0;
}

rc_status rc__emb_check(rc__emb_device *d, const char *what)
{
    int code = (int)rtcGetDeviceError(d->device);
    int refused = d->budget_refused;
    rc_status st;
    if (code == RTC_ERROR_NONE) code = d->error_code;
    if (code == RTC_ERROR_NONE && refused) code = RTC_ERROR_OUT_OF_MEMORY;
    if (code == RTC_ERROR_NONE) return RC_OK;
    st = status_of(code);
    if (refused)
        rc__fail(d->ctx, st,
                 "%s: Embree: %s (%s): the Embree memory budget of %llu bytes would be exceeded (%llu bytes held)",
                 what, d->error_text[0] ? d->error_text : "allocation refused", error_name(code),
                 (unsigned long long)d->options.budget_bytes,
                 (unsigned long long)atomic_load(&d->options.bytes_now));
    else
        rc__fail(d->ctx, st, "%s: Embree: %s (%s)", what, d->error_text[0] ? d->error_text : "no message",
                 error_name(code));
    d->error_code = RTC_ERROR_NONE;
    d->error_text[0] = '\0';
    d->budget_refused = 0;
    return st;
}

rc_status rc__emb_account(rc__emb_device *d, int64_t bytes, const char *what)
{
    uint64_t now = atomic_add(&d->options.bytes_now, (uint64_t)bytes);
    uint64_t budget = d->options.budget_bytes;
    if (bytes > 0 && budget != 0 && now > budget) {
        atomic_add(&d->options.bytes_now, (uint64_t)(-bytes));
        return rc__fail(d->ctx, RC_ERR_OUT_OF_MEMORY,
                        "%s: %lld bytes for the Embree backend's tables would pass its memory budget of %llu bytes "
                        "(%llu bytes held)",
                        what, (long long)bytes, (unsigned long long)budget,
                        (unsigned long long)(now - (uint64_t)bytes));
    }
    if (bytes > 0) atomic_max(&d->options.bytes_peak, now);
    return RC_OK;
}

/* rtcNewDevice, then the callbacks. On failure d->device is NULL and the
 * message names Embree's error. */
static rc_status open_device(rc_context *ctx, rc__emb_device *d, const char *config)
{
    d->ctx = ctx;
    d->device = rtcNewDevice(config);
    if (!d->device) {
        int code = (int)rtcGetDeviceError(NULL);
        if (code == RTC_ERROR_NONE) code = RTC_ERROR_UNKNOWN;
        return rc__fail(ctx, status_of(code), "Embree: rtcNewDevice(\"%s\") failed: %s", config, error_name(code));
    }
    rtcSetDeviceErrorFunction(d->device, on_error, d);
    rtcSetDeviceMemoryMonitorFunction(d->device, on_memory, d);
    return rc__emb_check(d, "Embree device setup");
}

static uint32_t native_width(RTCDevice device)
{
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) return 16;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) return 8;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) return 4;
    return 1;
}

rc__embree_options *rc__embree_options_of(rc_context *ctx)
{
    if (!rc__context_valid(ctx) || ctx->backend != &rc__backend_embree || !ctx->backend_data) return NULL;
    return &((rc__emb_device *)ctx->backend_data)->options;
}

rc_status rc__embree_probe_device(rc_context *ctx, const char *config)
{
    rc__emb_device probe;
    rc_status st;
    if (!rc__embree_options_of(ctx)) return RC_ERR_INVALID_ARGUMENT;
    memset(&probe, 0, sizeof probe);
    st = open_device(ctx, &probe, config ? config : "");
    if (probe.device) rtcReleaseDevice(probe.device);
    return st;
}

void rc__embree_record_error(rc_context *ctx, int rtc_error, const char *message)
{
    if (!rc__embree_options_of(ctx)) return;
    record((rc__emb_device *)ctx->backend_data, rtc_error, message);
}

static int emb_available(void) { return 1; }

static size_t emb_context_bytes(const rc_context_desc *desc)
{
    (void)desc;
    return rc__arena_cost(sizeof(rc__emb_device));
}

static rc_status emb_init(rc_context *ctx, const rc_context_desc *desc)
{
    rc__emb_device *d;
    char config[64];
    rc_status st;
    d = (rc__emb_device *)rc__arena_calloc(&ctx->arena, sizeof *d);
    RC_RETURN_IF(ctx, d == NULL, RC_ERR_OUT_OF_MEMORY, "arena has no room for the Embree backend's state");
    d->options.budget_bytes = (uint64_t)desc->backend_budget_mib << 20;
    d->options.robust = 1;
    d->options.tie_rule = 1;
    snprintf(config, sizeof config, "threads=%u,verbose=0", (unsigned)ctx->thread_count);
    st = open_device(ctx, d, config);
    if (st != RC_OK) {
        if (d->device) rtcReleaseDevice(d->device);
        rc__arena_free(&ctx->arena, d);
        return st;
    }
    d->native_width = native_width(d->device);
    ctx->large_mesh_bytes = rc__large_mesh_threshold(rc__last_level_cache_bytes());
    ctx->ordered_mesh_bytes = rc__ordered_mesh_threshold(rc__last_level_cache_bytes());
    ctx->backend_data = d;
    return RC_OK;
}

static void emb_deinit(rc_context *ctx)
{
    rc__emb_device *d = (rc__emb_device *)ctx->backend_data;
    if (!d) return;
    rtcReleaseDevice(d->device);
    rc__arena_free(&ctx->arena, d);
    ctx->backend_data = NULL;
}

static void emb_memory_stats(const rc_context *ctx, rc_memory_stats *stats)
{
    const rc__emb_device *d = (const rc__emb_device *)ctx->backend_data;
    if (d) stats->backend_bytes += atomic_load(&d->options.bytes_now);
}

const rc__backend rc__backend_embree = {
    RC_BACKEND_EMBREE,     "embree",   emb_available,         emb_context_bytes, rc__emb_scene_bytes,
    emb_init,              emb_deinit, rc__emb_scene_commit,  rc__emb_scene_release,
    rc__emb_simulate,      emb_memory_stats,       NULL,
};
