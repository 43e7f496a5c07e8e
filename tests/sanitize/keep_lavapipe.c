/* Linked into every program of an AddressSanitizer build with the Vulkan
 * backend (the tests and the rangecast program the CLI tests run): keeps
 * Mesa's lavapipe mapped until exit. The Vulkan loader closes the driver at
 * every vkDestroyInstance, but the driver's one-time allocations are never
 * freed (on AMD CPUs util_cpu_detect's L3 masks, 128 bytes each time it is
 * loaded), and tests/lsan.supp can name only a library that is still mapped
 * when LeakSanitizer looks, at exit: a closed one shows as "<unknown module>"
 * and fails the run. Found on a Zen 4 VM in session 27. Opened before main,
 * so before the loader's first open: every later open finds it loaded. */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>

#if defined(__GNUC__)
__attribute__((constructor)) static void keep_lavapipe_loaded(void)
{
    (void)dlopen("libvulkan_lvp.so", RTLD_LAZY | RTLD_NODELETE); /* absent: nothing to keep */
}
#endif
