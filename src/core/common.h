/* Internal basics shared by every layer: status helpers and error macros. */
#ifndef RC_CORE_COMMON_H
#define RC_CORE_COMMON_H

#include "rangecast/rangecast.h"

#include <stddef.h>
#include <stdint.h>

struct rc_context;

#if defined(__GNUC__)
#define RC__PRINTF(a, b) __attribute__((format(printf, a, b)))
#define RC__LIKELY(x) __builtin_expect(!!(x), 1)
#define RC__UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define RC__PRINTF(a, b)
#define RC__LIKELY(x) (x)
#define RC__UNLIKELY(x) (x)
#endif

#define RC__MIN(a, b) ((a) < (b) ? (a) : (b))
#define RC__MAX(a, b) ((a) > (b) ? (a) : (b))

/* Records status and a formatted message as the context's last error (and
 * sends it to the log callback); returns status so callers can write
 * `return rc__fail(ctx, RC_ERR_..., "...")`. ctx may be NULL. */
rc_status rc__fail(struct rc_context *ctx, rc_status status, const char *fmt, ...) RC__PRINTF(3, 4);

/* Clears the last error (called at the start of public functions). */
void rc__clear_error(struct rc_context *ctx);

/* Debug/info message to the log callback, if any (built with the Vulkan
 * backend only, its one caller: error.c). */
void rc__log(const struct rc_context *ctx, uint32_t level, const char *fmt, ...) RC__PRINTF(3, 4);

#define RC_RETURN_IF(ctx, cond, status, ...)                  \
    do {                                                      \
        if (RC__UNLIKELY(cond)) return rc__fail((ctx), (status), __VA_ARGS__); \
    } while (0)

#define RC_TRY(expr)                      \
    do {                                  \
        rc_status rc__s_ = (expr);        \
        if (rc__s_ != RC_OK) return rc__s_; \
    } while (0)

/* 1 when every one of n floats is finite. */
int rc__all_finite(const float *v, size_t n);

#endif
