/* rangecast: the ray casting kernel with the nearest hit found by
 * GL_EXT_ray_query in the driver's acceleration structure (vulkan_accel.c
 * builds it) instead of the BVH walk: everything else is raycast.glsl's, as
 * in raycast.comp. For devices with VK_KHR_ray_query
 * (RC_CONTEXT_VULKAN_RAY_QUERY). Compiled for Vulkan 1.2 (SPIR-V 1.5). */
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_ray_query : require

#define RC_RAY_QUERY 1
#include "raycast.glsl"
