/* Status strings and the context's last-error message. */
#include "core/context.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *rc_status_string(rc_status status)
{
    switch (status) {
    case RC_OK: return "RC_OK: success";
    case RC_ERR_INVALID_ARGUMENT: return "RC_ERR_INVALID_ARGUMENT: an argument is missing or out of its domain";
    case RC_ERR_INVALID_HANDLE: return "RC_ERR_INVALID_HANDLE: a handle is NULL, destroyed or of another kind";
    case RC_ERR_MISUSE: return "RC_ERR_MISUSE: the call is not allowed in this state";
    case RC_ERR_OUT_OF_MEMORY: return "RC_ERR_OUT_OF_MEMORY: not enough memory";
    case RC_ERR_CAPACITY: return "RC_ERR_CAPACITY: more than the object was created to hold";
    case RC_ERR_UNSUPPORTED: return "RC_ERR_UNSUPPORTED: not built in or not available here";
    case RC_ERR_BACKEND: return "RC_ERR_BACKEND: the backend reported an error";
    case RC_ERR_DEVICE_LOST: return "RC_ERR_DEVICE_LOST: the device was lost";
    case RC_ERR_CORRUPT_DATA: return "RC_ERR_CORRUPT_DATA: data failed its checks";
    case RC_ERR_NOT_COMMITTED: return "RC_ERR_NOT_COMMITTED: the scene is not committed";
    case RC_ERR_NON_FINITE: return "RC_ERR_NON_FINITE: a value is NaN or infinite";
    case RC_ERR_OUT_OF_RANGE: return "RC_ERR_OUT_OF_RANGE: an index is past the end of its array";
    case RC_ERR_STRUCT_SIZE: return "RC_ERR_STRUCT_SIZE: a descriptor's struct_size is not one this library knows";
    case RC_ERR_IO: return "RC_ERR_IO: a file could not be read or written";
    default: return "unknown status";
    }
}

static void format_into(char *buf, size_t n, const char *fmt, va_list ap)
{
    int w = vsnprintf(buf, n, fmt, ap);
    if (w < 0) buf[0] = '\0';
}

rc_status rc__fail(struct rc_context *ctx, rc_status status, const char *fmt, ...)
{
    va_list ap;
    if (!ctx || ctx->magic != RC__MAGIC_CONTEXT) return status;
    va_start(ap, fmt);
    format_into(ctx->last_error, sizeof ctx->last_error, fmt, ap);
    va_end(ap);
    ctx->last_status = status;
    if (ctx->log) ctx->log(ctx->log_user, RC_LOG_ERROR, ctx->last_error);
    return status;
}

void rc__clear_error(struct rc_context *ctx)
{
    if (!ctx || ctx->magic != RC__MAGIC_CONTEXT) return;
    ctx->last_error[0] = '\0';
    ctx->last_status = RC_OK;
}

#if defined(RANGECAST_WITH_VULKAN)
/* Only the Vulkan backend logs beyond errors (rc__fail): the static core,
 * built without it, leaves this out (its aarch64 size budget). Drop the
 * guard when the core itself logs. */
void rc__log(const struct rc_context *ctx, uint32_t level, const char *fmt, ...)
{
    char buf[RC__ERROR_TEXT];
    va_list ap;
    if (!ctx || !ctx->log) return;
    va_start(ap, fmt);
    format_into(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ctx->log(ctx->log_user, level, buf);
}
#endif

int rc__all_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

const char *rc_context_last_error(const rc_context *ctx)
{
    if (!ctx || ctx->magic != RC__MAGIC_CONTEXT) return "invalid context handle";
    return ctx->last_error;
}
