/* The packet traversal (packet.c) compiled a second time, for x86-64 CPUs
 * with AVX2: CMake gives this file -mavx2 -mno-fma, and packet.c's entry
 * points hand packets to the ones built here (named ..._avx2) after a
 * run-time check, so the library itself stays baseline x86-64. The box tests
 * run in two rows of eight lanes instead of four rows of four, and leaves
 * test two lanes at a time. */
#include "bvh/packet.h"

#if defined(RC__PACKET_TWO_BUILDS)
#if !defined(__AVX2__)
#error "packet_avx2.c is built with -mavx2 (CMakeLists.txt sets it for this file)"
#endif
#define RC__PACKET_AVX2_VARIANT 1
#include "packet.c"
#else
/* ISO C wants a declaration in every translation unit */
typedef int rc__packet_avx2_unused;
#endif
