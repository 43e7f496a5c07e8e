/* Public context functions: create/destroy, the arena, errors, queries. */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE 1 /* madvise */
#endif
#include "backend/backend.h"
#include "core/context.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define CONTEXT_DESC_MIN_SIZE ((uint32_t)sizeof(rc_context_desc))

uint32_t rc_version_number(void) { return RC_VERSION_NUMBER; }

const char *rc_version_string(void)
{
#define RC__STR2(x) #x
#define RC__STR(x) RC__STR2(x)
    return RC__STR(RC_VERSION_MAJOR) "." RC__STR(RC_VERSION_MINOR) "." RC__STR(RC_VERSION_PATCH);
}

int rc__context_valid(const rc_context *ctx) { return ctx != NULL && ctx->magic == RC__MAGIC_CONTEXT; }

rc_status rc__check_desc(rc_context *ctx, const void *desc, uint32_t min_size, uint32_t max_size, const char *what)
{
    uint32_t size;
    RC_RETURN_IF(ctx, desc == NULL, RC_ERR_INVALID_ARGUMENT, "%s is NULL", what);
    memcpy(&size, desc, sizeof size);
    RC_RETURN_IF(ctx, size < min_size || size > max_size, RC_ERR_STRUCT_SIZE,
                 "%s->struct_size is %u; this library knows %u (use the _desc_default() function)", what,
                 (unsigned)size, (unsigned)max_size);
    return RC_OK;
}

rc_status rc__check_reserved(rc_context *ctx, const uint32_t *words, size_t n, const char *what)
{
    size_t i;
    for (i = 0; i < n; ++i)
        RC_RETURN_IF(ctx, words[i] != 0, RC_ERR_INVALID_ARGUMENT, "%s.reserved[%u] is %u; reserved words must be 0",
                     what, (unsigned)i, (unsigned)words[i]);
    return RC_OK;
}

rc_context_desc rc_context_desc_default(void)
{
    rc_context_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = (uint32_t)sizeof d;
    return d;
}

rc_memory_stats rc_memory_stats_default(void)
{
    rc_memory_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = (uint32_t)sizeof s;
    return s;
}

/* A create-time failure's message, into why[RC__ERROR_TEXT]: there is no
 * context to hold it yet. */
static rc_status why_fail(char *why, rc_status status, const char *fmt, ...) RC__PRINTF(3, 4);
static rc_status why_fail(char *why, rc_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (vsnprintf(why, RC__ERROR_TEXT, fmt, ap) < 0) why[0] = '\0';
    va_end(ap);
    return status;
}

/* Checks the desc and resolves backend and thread count; why names the
 * field on failure. */
static rc_status resolve_desc(const rc_context_desc *desc, const rc__backend **backend, uint32_t *threads, char *why)
{
    size_t i;
    if (!desc) return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc is NULL");
    if (desc->struct_size != (uint32_t)sizeof(rc_context_desc))
        return why_fail(why, RC_ERR_STRUCT_SIZE,
                        "desc->struct_size is %u; this library knows %u (use rc_context_desc_default())",
                        (unsigned)desc->struct_size, (unsigned)sizeof(rc_context_desc));
    for (i = 0; i < sizeof desc->reserved / sizeof desc->reserved[0]; ++i)
        if (desc->reserved[i] != 0)
            return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc->reserved[%u] is %u; reserved words must be 0",
                            (unsigned)i, (unsigned)desc->reserved[i]);
    if (desc->flags & ~RC_CONTEXT_VULKAN_RAY_QUERY)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT,
                        "desc->flags is 0x%x; only RC_CONTEXT_VULKAN_RAY_QUERY (0x%x) is defined",
                        (unsigned)desc->flags, RC_CONTEXT_VULKAN_RAY_QUERY);
    if ((desc->flags & RC_CONTEXT_VULKAN_RAY_QUERY) && desc->backend != RC_BACKEND_VULKAN)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT,
                        "desc->flags has RC_CONTEXT_VULKAN_RAY_QUERY, which needs desc->backend "
                        "RC_BACKEND_VULKAN (it is %s)",
                        rc_backend_name(desc->backend));
    if (desc->backend > RC_BACKEND_VULKAN)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc->backend is %u; not an RC_BACKEND_* value",
                        (unsigned)desc->backend);
    if (desc->thread_count > RC_MAX_THREADS)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc->thread_count is %u; at most RC_MAX_THREADS (%u)",
                        (unsigned)desc->thread_count, RC_MAX_THREADS);
    if (desc->memory && ((uintptr_t)desc->memory % RC_ARENA_ALIGNMENT) != 0)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc->memory %p is not aligned to RC_ARENA_ALIGNMENT (%u)",
                        desc->memory, RC_ARENA_ALIGNMENT);
    if (desc->memory && desc->memory_size == 0)
        return why_fail(why, RC_ERR_INVALID_ARGUMENT, "desc->memory is set but desc->memory_size is 0");
    *backend = rc__backend_find(desc->backend);
    if (!*backend)
        return why_fail(why, RC_ERR_UNSUPPORTED, "desc->backend %s is not built into this library",
                        rc_backend_name(desc->backend));
    *threads = desc->thread_count ? desc->thread_count : rc__cpu_count();
#if !defined(RANGECAST_WITH_THREADS)
    *threads = 1;
#endif
    return RC_OK;
}

static size_t context_bytes(const rc_context_desc *desc, const rc__backend *backend, uint32_t threads)
{
    return rc__arena_cost(sizeof(rc_context)) + rc__pool_memory(threads) + backend->context_bytes(desc);
}

rc_status rc_context_memory_requirements(const rc_context_desc *desc, size_t *bytes)
{
    const rc__backend *backend = NULL;
    uint32_t threads = 1;
    char why[RC__ERROR_TEXT];
    if (!bytes) return RC_ERR_INVALID_ARGUMENT;
    RC_TRY(resolve_desc(desc, &backend, &threads, why));
    *bytes = context_bytes(desc, backend, threads);
    return RC_OK;
}

/* Messages for create failures go to the log callback only: there is no
 * context yet. */
static rc_status create_fail(const rc_context_desc *desc, rc_status status, const char *fmt, ...) RC__PRINTF(3, 4);
static rc_status create_fail(const rc_context_desc *desc, rc_status status, const char *fmt, ...)
{
    char msg[RC__ERROR_TEXT];
    va_list ap;
    if (!desc || !desc->log) return status;
    va_start(ap, fmt);
    if (vsnprintf(msg, sizeof msg, fmt, ap) < 0) msg[0] = '\0';
    va_end(ap);
    desc->log(desc->log_user, RC_LOG_ERROR, msg);
    return status;
}

rc_status rc_context_create(const rc_context_desc *desc, rc_context **out)
{
    const rc__backend *backend = NULL;
    uint32_t threads = 1;
    rc__arena arena;
    void *block;
    void *owned = NULL;
    size_t size;
    rc_context *ctx;
    rc_status st;
    char why[RC__ERROR_TEXT];

    if (!out) return create_fail(desc, RC_ERR_INVALID_ARGUMENT, "rc_context_create: out is NULL");
    st = resolve_desc(desc, &backend, &threads, why);
    if (st != RC_OK) return create_fail(desc, st, "rc_context_create: %s", why);
    if (!backend->available())
        return create_fail(desc, RC_ERR_UNSUPPORTED, "rc_context_create: backend %s is built in but not usable here",
                           backend->name);

    size = desc->memory ? desc->memory_size : (desc->memory_size ? desc->memory_size : RC_DEFAULT_ARENA_SIZE);
    if (size < context_bytes(desc, backend, threads))
        return create_fail(desc, RC_ERR_OUT_OF_MEMORY,
                           "rc_context_create: desc->memory_size is %lu bytes; this context needs %lu "
                           "(rc_context_memory_requirements)",
                           (unsigned long)size, (unsigned long)context_bytes(desc, backend, threads));
    block = desc->memory;
    if (!block) {
        /* The one allocation of the library. malloc aligns to 16 on x86_64
         * and aarch64 but only to 8 on 32-bit ARM (glibc armhf, newlib), so
         * take RC_ARENA_ALIGNMENT - 1 more and align up (C99: no
         * posix_memalign/aligned_alloc); owned keeps malloc's pointer. */
        if (size > (size_t)-1 - (RC_ARENA_ALIGNMENT - 1))
            return create_fail(desc, RC_ERR_OUT_OF_MEMORY, "rc_context_create: memory_size too large");
        owned = malloc(size + (RC_ARENA_ALIGNMENT - 1));
        if (!owned) return create_fail(desc, RC_ERR_OUT_OF_MEMORY, "rc_context_create: malloc of the arena failed");
        block = (unsigned char *)owned + ((RC_ARENA_ALIGNMENT - (uintptr_t)owned % RC_ARENA_ALIGNMENT) % RC_ARENA_ALIGNMENT);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        /* Ask for transparent huge pages where the block spans whole 2 MiB
         * pages: a large map's tree is reached at random, and fewer TLB
         * misses measured +6% scans/s on the 10M-triangle sphere. Advice
         * only: a kernel without THP ignores it. */
        {
            const uintptr_t huge = (uintptr_t)2 << 20, lo = ((uintptr_t)owned + huge - 1) & ~(huge - 1);
            const uintptr_t hi = ((uintptr_t)owned + size) & ~(huge - 1);
            if (hi > lo) (void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
        }
#endif
    }
    rc__arena_init(&arena, block, size);
    ctx = (rc_context *)rc__arena_calloc(&arena, sizeof *ctx);
    if (!ctx) {
        free(owned);
        return create_fail(desc, RC_ERR_OUT_OF_MEMORY, "rc_context_create: arena too small");
    }
    ctx->arena = arena; /* from here on the context owns the arena state */
    ctx->magic = RC__MAGIC_CONTEXT;
    ctx->owned_block = owned;
    ctx->backend = backend;
    ctx->backend_id = backend->id;
    ctx->log = desc->log;
    ctx->log_user = desc->log_user;
    ctx->thread_count = threads;

    st = rc__pool_create(&ctx->arena, threads, &ctx->pool);
    if (st == RC_OK) st = backend->init(ctx, desc);
    if (st != RC_OK) {
        /* the reason is in the dying context's last error: copy it out first */
        memcpy(why, ctx->last_error, sizeof why);
        why[sizeof why - 1] = '\0';
        if (!ctx->pool) snprintf(why, sizeof why, "%u worker threads could not start", (unsigned)(threads - 1));
        if (ctx->pool) rc__pool_destroy(&ctx->arena, ctx->pool);
        ctx->magic = RC__MAGIC_DEAD;
        rc__arena_fini(&ctx->arena);
        free(owned);
        return create_fail(desc, st, "rc_context_create: %s", why[0] ? why : "the backend failed to start");
    }
    *out = ctx;
    return RC_OK;
}

void rc_context_destroy(rc_context *ctx)
{
    void *owned;
    rc__arena arena;
    if (!rc__context_valid(ctx)) return;
    /* Release backend state of scenes (Embree scenes, GPU buffers) before the
     * backend itself; the memory goes with the arena. Scenes that instance
     * others come first in the list (newest first), so sources outlive users. */
    {
        rc_scene *s;
        rc_sensor *se;
        for (s = ctx->scenes; s; s = s->next) {
            if (ctx->backend->scene_release) ctx->backend->scene_release(s);
            s->magic = RC__MAGIC_DEAD;
        }
        for (se = ctx->sensors; se; se = se->next) se->magic = RC__MAGIC_DEAD;
    }
    ctx->backend->deinit(ctx);
    rc__pool_destroy(&ctx->arena, ctx->pool);
    owned = ctx->owned_block;
    ctx->magic = RC__MAGIC_DEAD;
    arena = ctx->arena;
    rc__arena_fini(&arena);
    free(owned);
}

rc_status rc_context_get_backend(const rc_context *ctx, uint32_t *backend)
{
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    if (!backend) return rc__fail((rc_context *)ctx, RC_ERR_INVALID_ARGUMENT, "backend is NULL");
    *backend = ctx->backend_id;
    return RC_OK;
}

rc_status rc_context_get_thread_count(const rc_context *ctx, uint32_t *count)
{
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    if (!count) return rc__fail((rc_context *)ctx, RC_ERR_INVALID_ARGUMENT, "count is NULL");
    *count = ctx->thread_count;
    return RC_OK;
}

rc_status rc_context_get_memory_stats(const rc_context *ctx, rc_memory_stats *stats)
{
    rc_memory_stats s;
    if (!rc__context_valid(ctx)) return RC_ERR_INVALID_HANDLE;
    if (!stats) return rc__fail((rc_context *)ctx, RC_ERR_INVALID_ARGUMENT, "stats is NULL");
    if (stats->struct_size < 8 || stats->struct_size > sizeof s)
        return rc__fail((rc_context *)ctx, RC_ERR_STRUCT_SIZE, "stats->struct_size is %u; expected %u",
                        (unsigned)stats->struct_size, (unsigned)sizeof s);
    s = rc_memory_stats_default();
    s.arena_size = ctx->arena.size;
    s.arena_used = ctx->arena.used;
    s.arena_peak = ctx->arena.peak;
    if (ctx->backend->memory_stats) ctx->backend->memory_stats(ctx, &s);
    s.struct_size = stats->struct_size; /* an older, shorter struct gets its prefix */
    memcpy(stats, &s, stats->struct_size);
    return RC_OK;
}
