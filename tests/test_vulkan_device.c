/* Vulkan device choice through rc_context_desc.device: by name substring, by
 * index, and a clear RC_ERR_UNSUPPORTED when nothing matches. */
#include "rc_test.h"

static rc_status create_with(const char *device)
{
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    rc_status st;
    d.backend = RC_BACKEND_VULKAN;
    d.thread_count = 1;
    d.memory_size = (size_t)4 << 20;
    d.device = device;
    st = rc_context_create(&d, &ctx);
    if (st == RC_OK) rc_context_destroy(ctx);
    return st;
}

static void test_device_choice(void **state)
{
    (void)state;
    if (!rct_backend_usable(RC_BACKEND_VULKAN)) skip();
    assert_int_equal(create_with(NULL), RC_OK);
    assert_int_equal(create_with("0"), RC_OK);
    assert_int_equal(create_with("no-such-gpu-xyz"), RC_ERR_UNSUPPORTED);
    assert_int_equal(create_with("99"), RC_ERR_UNSUPPORTED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_device_choice)};
    return cmocka_run_group_tests_name("vulkan device choice", tests, NULL, NULL);
}
