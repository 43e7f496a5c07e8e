# GLSL compute kernels -> SPIR-V embedded as uint32_t arrays in generated
# headers (${CMAKE_CURRENT_BINARY_DIR}/generated/<name>.h), compiled at build
# time by glslangValidator; the library never compiles shaders at run time.
#
# raycast.comp is compiled four times: with and without float64 (devices
# without shaderFloat64 cannot even load a module that declares it) and with
# 1 or 4 storage-buffer bindings per large array (4 lets one array exceed
# maxStorageBufferRange, but needs 18 storage buffers per stage).
# raycast_rq.comp (the same body with GL_EXT_ray_query, for
# RC_CONTEXT_VULKAN_RAY_QUERY) is compiled the same four ways for Vulkan 1.2.
#
# rc_add_shader_dependencies(target) makes a target wait for the headers.

set(RC_KERNEL_DIR ${CMAKE_CURRENT_SOURCE_DIR}/kernels)
set(RC_GENERATED_DIR ${CMAKE_CURRENT_BINARY_DIR}/generated)
file(MAKE_DIRECTORY ${RC_GENERATED_DIR})
file(GLOB RC_KERNEL_INCLUDES CONFIGURE_DEPENDS ${RC_KERNEL_DIR}/*.glsl)
set(RC_SHADER_HEADERS "")

# rc_compile_shader(<source .comp> <array name> [defines...]); a define
# TARGET=vulkan1.2 picks the target environment (default vulkan1.1).
function(rc_compile_shader source name)
  set(out ${RC_GENERATED_DIR}/${name}.h)
  set(defs "")
  set(target vulkan1.1)
  foreach(d ${ARGN})
    if(d MATCHES "^TARGET=(.*)$")
      set(target ${CMAKE_MATCH_1})
    else()
      list(APPEND defs -D${d})
    endif()
  endforeach()
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${GLSLANG_VALIDATOR} -V --target-env ${target} ${defs} --vn ${name} -o ${out}
            ${RC_KERNEL_DIR}/${source}
    DEPENDS ${RC_KERNEL_DIR}/${source} ${RC_KERNEL_INCLUDES}
    WORKING_DIRECTORY ${RC_KERNEL_DIR}
    COMMENT "glslang: ${source} -> generated/${name}.h"
    VERBATIM)
  set(RC_SHADER_HEADERS ${RC_SHADER_HEADERS} ${out} PARENT_SCOPE)
endfunction()

rc_compile_shader(raycast.comp rc__spv_raycast_f64_c4 RC_FP64=1 RC_CHUNKS=4)
rc_compile_shader(raycast.comp rc__spv_raycast_f32_c4 RC_FP64=0 RC_CHUNKS=4)
rc_compile_shader(raycast.comp rc__spv_raycast_f64_c1 RC_FP64=1 RC_CHUNKS=1)
rc_compile_shader(raycast.comp rc__spv_raycast_f32_c1 RC_FP64=0 RC_CHUNKS=1)
rc_compile_shader(raycast_rq.comp rc__spv_raycast_rq_f64_c4 RC_FP64=1 RC_CHUNKS=4 TARGET=vulkan1.2)
rc_compile_shader(raycast_rq.comp rc__spv_raycast_rq_f32_c4 RC_FP64=0 RC_CHUNKS=4 TARGET=vulkan1.2)
rc_compile_shader(raycast_rq.comp rc__spv_raycast_rq_f64_c1 RC_FP64=1 RC_CHUNKS=1 TARGET=vulkan1.2)
rc_compile_shader(raycast_rq.comp rc__spv_raycast_rq_f32_c1 RC_FP64=0 RC_CHUNKS=1 TARGET=vulkan1.2)
rc_compile_shader(layout_check.comp rc__spv_layout_check)

add_custom_target(rangecast_shaders DEPENDS ${RC_SHADER_HEADERS})
# The one source that includes the headers recompiles when they change.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/src/backend/vulkan_shaders.c
  PROPERTIES OBJECT_DEPENDS "${RC_SHADER_HEADERS}")

function(rc_add_shader_dependencies target)
  add_dependencies(${target} rangecast_shaders)
endfunction()
