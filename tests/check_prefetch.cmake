# The traversals' prefetches survive a build for size (-Os): compiles each
# file of FILES to assembly with the project's compiler and target flags at
# -Os and counts its prefetch instructions (x86 prefetch*, AArch64 prfm,
# 32-bit ARM pld). gcc 12 had deleted all but one in each file: helpers that
# only prefetch looked free of side effects to it at -Os, where they were not
# forced inline (session 23), and nothing else showed it.
#
#   cmake -DCC=<compiler> -DFLAGS="<target flags>" -DROOT=<source tree>
#         -DFILES="src/bvh/packet.c;src/bvh/wide_trace.c" -DMIN=4 -P check_prefetch.cmake
separate_arguments(flag_list UNIX_COMMAND "${FLAGS}")
foreach(f IN LISTS FILES)
  execute_process(COMMAND ${CC} ${flag_list} -Os -std=c99 -DNDEBUG -I${ROOT}/src -I${ROOT}/include -S -o -
                          ${ROOT}/${f}
                  OUTPUT_VARIABLE asm ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "check_prefetch: compiling ${f} at -Os failed:\n${err}")
  endif()
  string(REGEX MATCHALL "\n[ \t]+(prefetch[a-z0-9]*|prfm|pld)[ \t]" hits "${asm}")
  list(LENGTH hits n)
  if(n LESS MIN)
    message(FATAL_ERROR "check_prefetch: ${f} at -Os has ${n} prefetch instructions, expected at least ${MIN} "
                        "(a prefetch helper lost its forced inlining?)")
  endif()
  message(STATUS "${f} at -Os: ${n} prefetch instructions")
endforeach()
