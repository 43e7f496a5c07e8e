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
#include "rc__spv_raycast_rq_f32_c1.h"
#include "rc__spv_raycast_rq_f32_c4.h"
#include "rc__spv_raycast_rq_f64_c1.h"
#include "rc__spv_raycast_rq_f64_c4.h"

/* The variant's array and its size. */
#define RC__SPV(name)          \
    do {                       \
        *bytes = sizeof name;  \
        return name;           \
    } while (0)

const uint32_t *rc__vk_raycast_spirv(int fp64, uint32_t chunks, int ray_query, size_t *bytes)
{
    if (ray_query) {
        if (fp64 && chunks > 1) RC__SPV(rc__spv_raycast_rq_f64_c4);
        if (fp64) RC__SPV(rc__spv_raycast_rq_f64_c1);
        if (chunks > 1) RC__SPV(rc__spv_raycast_rq_f32_c4);
        RC__SPV(rc__spv_raycast_rq_f32_c1);
    }
    if (fp64 && chunks > 1) RC__SPV(rc__spv_raycast_f64_c4);
    if (fp64) RC__SPV(rc__spv_raycast_f64_c1);
    if (chunks > 1) RC__SPV(rc__spv_raycast_f32_c4);
    RC__SPV(rc__spv_raycast_f32_c1);
}

const uint32_t *rc__vk_layout_check_spirv(size_t *bytes)
{
    *bytes = sizeof rc__spv_layout_check;
    return rc__spv_layout_check;
}
