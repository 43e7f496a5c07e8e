/* A program built against an installed rangecast (find_package or pkg-config). */
#include <rangecast/rangecast.h>
#include <stdio.h>

int main(void)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 1;
    d.memory_size = 1 << 20;
    if (rc_context_create(&d, &ctx) != RC_OK) return 1;
    rc_context_destroy(ctx);
    printf("rangecast %s\n", rc_version_string());
    return rc_version_number() == RC_VERSION_NUMBER ? 0 : 1;
}
