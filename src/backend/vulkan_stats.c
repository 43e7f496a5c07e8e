/* What the driver made of a kernel: with RANGECAST_VULKAN_PIPELINE_STATS=1 and
 * a device that offers VK_KHR_pipeline_executable_properties (NVIDIA's
 * driver, Mesa's), every pipeline is created with its statistics captured and
 * they are logged at RC_LOG_INFO: register count, spills, local memory, code
 * size, as the driver names them. A kernel change that looks free in the
 * GLSL can cost registers (fewer warps in flight) or spill to local memory on
 * a GPU; this says which, without a vendor profiler (Nsight Compute does not
 * read Vulkan compute). */
#include "backend/vulkan_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char rc__vk_stats_extension[] = "VK_KHR_pipeline_executable_properties";

int rc__vk_stats_wanted(rc__vk_state *st)
{
    const char *v = getenv("RANGECAST_VULKAN_PIPELINE_STATS");
    uint32_t n = 0, i;
    VkExtensionProperties *ext;
    int found = 0;
    if (!v || strcmp(v, "1") != 0) return 0;
    if (rc__vk_device_extensions(st, &ext, &n) != RC_OK) return 0;
    for (i = 0; i < n && !found; ++i) found = strcmp(ext[i].extensionName, rc__vk_stats_extension) == 0;
    rc__vk_host_free(st, ext);
    if (!found)
        rc__log(st->ctx, RC_LOG_INFO, "vulkan: %s does not offer %s: no pipeline statistics", st->device_name,
                rc__vk_stats_extension);
    return found;
}

static void stat_text(const VkPipelineExecutableStatisticKHR *s, char *out, size_t size)
{
    switch (s->format) {
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
        snprintf(out, size, "%s", s->value.b32 ? "yes" : "no");
        break;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
        snprintf(out, size, "%lld", (long long)s->value.i64);
        break;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
        snprintf(out, size, "%llu", (unsigned long long)s->value.u64);
        break;
    default:
        snprintf(out, size, "%g", s->value.f64);
        break;
    }
}

void rc__vk_stats_log(rc__vk_state *st, VkPipeline pipe, uint32_t attributes, uint32_t model)
{
    PFN_vkGetPipelineExecutableStatisticsKHR get = (PFN_vkGetPipelineExecutableStatisticsKHR)vkGetDeviceProcAddr(
        st->device, "vkGetPipelineExecutableStatisticsKHR");
    VkPipelineExecutableInfoKHR info;
    VkPipelineExecutableStatisticKHR stats[32];
    char line[1024], value[48];
    uint32_t n = 32, i;
    size_t used;
    if (!get) return;
    memset(&info, 0, sizeof info);
    info.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR;
    info.pipeline = pipe;
    info.executableIndex = 0;
    memset(stats, 0, sizeof stats);
    for (i = 0; i < n; ++i) stats[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
    if (get(st->device, &info, &n, stats) < 0) return; /* VK_INCOMPLETE keeps the first 32 */
    used = (size_t)snprintf(line, sizeof line, "vulkan: kernel (attributes 0x%x, model %u):", (unsigned)attributes,
                            (unsigned)model);
    for (i = 0; i < n && used < sizeof line; ++i) {
        stat_text(&stats[i], value, sizeof value);
        used += (size_t)snprintf(line + used, sizeof line - used, "%s %s %s", i ? ";" : "", stats[i].name, value);
    }
    rc__log(st->ctx, RC_LOG_INFO, "%s", line);
}
