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
    /* AUTO is the built-in backend on every platform: it outran the Embree
     * backend on every grid sensor and O1Dn pattern measured (1.1-4x), keeps
     * to the caller's arena, and is what ARM boards (no Embree) run, so a
     * desktop and the robot trace with the same code. Embree wins incoherent OnDn rays from scattered
     * origins; callers ask for it by name (docs/benchmarks.md, session 34). */
    case RC_BACKEND_AUTO:
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
