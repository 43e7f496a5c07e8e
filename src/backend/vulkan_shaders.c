/* The SPIR-V of the kernels, embedded at build time (cmake/Shaders.cmake
 * compiles kernels/<name>.comp with glslangValidator into generated/rc__spv_<name>.h). This is
 * the only file that includes those headers. */
#include "backend/vulkan_internal.h"

#include <stdint.h>

#include "rc__spv_layout_check.h"
#include "rc__spv_raycast_f32_c1.h"
#include "rc__spv_raycast_f32_c4.h"
#include "rc__spv_raycast_f64_c1.h"
#include "rc__spv_raycast_f64_c4.h"

const uint32_t *rc__vk_raycast_spirv(int fp64, uint32_t chunks, size_t *bytes)
{
    if (fp64 && chunks > 1) {
        *bytes = sizeof rc__spv_raycast_f64_c4;
        return rc__spv_raycast_f64_c4;
    }
    if (fp64) {
        *bytes = sizeof rc__spv_raycast_f64_c1;
        return rc__spv_raycast_f64_c1;
    }
    if (chunks > 1) {
        *bytes = sizeof rc__spv_raycast_f32_c4;
        return rc__spv_raycast_f32_c4;
    }
    *bytes = sizeof rc__spv_raycast_f32_c1;
    return rc__spv_raycast_f32_c1;
}

const uint32_t *rc__vk_layout_check_spirv(size_t *bytes)
{
    *bytes = sizeof rc__spv_layout_check;
    return rc__spv_layout_check;
}
