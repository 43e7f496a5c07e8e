// The public header compiles as C++ (and links from C++ without name mangling).
#include <rangecast/rangecast.h>

int main()
{
    rc_context_desc d = rc_context_desc_default();
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 1;
    d.memory_size = 1 << 20;
    rc_context *ctx = nullptr;
    if (rc_context_create(&d, &ctx) != RC_OK) return 1;
    rc_context_destroy(ctx);
    return rc_version_number() == RC_VERSION_NUMBER ? 0 : 1;
}
