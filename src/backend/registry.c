/* Which backends are compiled in, and what AUTO means. */
#include "backend/backend.h"

#if defined(RANGECAST_WITH_EMBREE)
extern const rc__backend rc__backend_embree;
#endif
#if defined(RANGECAST_WITH_VULKAN)
extern const rc__backend rc__backend_vulkan;
#endif

const rc__backend *rc__backend_find(uint32_t id)
{
    switch (id) {
    case RC_BACKEND_AUTO:
#if defined(RANGECAST_WITH_EMBREE)
        if (rc__backend_embree.available()) return &rc__backend_embree;
#endif
        return &rc__backend_bvh;
    case RC_BACKEND_BVH: return &rc__backend_bvh;
#if defined(RANGECAST_WITH_EMBREE)
    case RC_BACKEND_EMBREE: return &rc__backend_embree;
#endif
#if defined(RANGECAST_WITH_VULKAN)
    case RC_BACKEND_VULKAN: return &rc__backend_vulkan;
#endif
    default: return NULL;
    }
}

int rc_backend_available(uint32_t backend)
{
    const rc__backend *b = backend == RC_BACKEND_AUTO ? NULL : rc__backend_find(backend);
    if (backend == RC_BACKEND_AUTO) return 1;
    return b != NULL && b->available();
}

const char *rc_backend_name(uint32_t backend)
{
    switch (backend) {
    case RC_BACKEND_AUTO: return "auto";
    case RC_BACKEND_BVH: return "bvh";
    case RC_BACKEND_EMBREE: return "embree";
    case RC_BACKEND_VULKAN: return "vulkan";
    default: return "unknown";
    }
}
