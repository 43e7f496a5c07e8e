/* Coherent traversal: up to RC__PACKET_SIZE rays that share one origin (a tile
 * of a scan), or whose origins lie close together (an OnDn sensor's beams),
 * walk the mesh BVH together. Each node is fetched once for the
 * packet and its box tested against every active ray in fixed-width loops the
 * compiler turns into SIMD (SSE on x86-64, NEON on ARM); leaves run the same
 * watertight test as single rays, per active ray. Every ray gets exactly the
 * hit rc__mesh_intersect would give it: the packet changes the order of work,
 * not the answer. */
#ifndef RC_BVH_PACKET_H
#define RC_BVH_PACKET_H

#include "bvh/leaf4.h"
#include "bvh/mesh.h"

/* 32 rays a packet (16 before session 28): twice the rays share each node
 * fetch, box test setup and leaf transpose. 2 threads, VLP-16 on the sphere:
 * 1k +18%, 10k +21%, 100k +5%, 1M +5% (OS1-64 +11%), 10M -4% (noise
 * 0.87-1.06); docs/benchmarks.md. */
#define RC__PACKET_SIZE 32u

/* An OnDn sensor whose origins all lie within this of its first (m) traces in
 * packets (RC__PACKET_OWN_ORIGINS below; the built-in backend decides): the beams of
 * one multi-beam LiDAR (an Ouster's 15.8 mm off its axis, other makes' few
 * centimetres). Rays from farther apart go one by one. */
#define RC__PACKET_ORIGIN_SPREAD 0.25f

/* flags of the traversals below */
/* Each ray has its own origin. Without it rays[0..n) share org (only
 * rays[0].org is read for the broadcast box tests); with it the box tests
 * grow by the largest offset between the origins (any offset is correct;
 * offsets much larger than the map's smallest boxes only cost time). */
#define RC__PACKET_OWN_ORIGINS 1u
/* A hit may keep RC__PRIM_PENDING for its prim id (its slot and geometry say
 * which triangle): for a caller that writes no prim ids or normals. It then
 * skips a read of bvh.refs a hit, a cache miss on large maps (rc__hit_settle
 * gives the id). A later search's tie needs no such id: the key compares
 * instance and geometry first, and rc__hit_offer_slot resolves a pending id
 * only against its own mesh. */
#define RC__PACKET_PRIMS_PENDING 2u
/* rc__mesh_intersect_packets only: the packets run one by one and leave
 * their lone lanes to a pool taking turns (a mesh far past the caches),
 * instead of taking turns themselves. Not in -Os builds (the static core's
 * size budget), which have no lone lanes: RC__PACKET_HAS_LONE_POOL says. */
#define RC__PACKET_LONE_POOL 4u
#if !defined(__OPTIMIZE_SIZE__)
#define RC__PACKET_HAS_LONE_POOL 1
#endif

/* hits[i].t holds ray i's tmax on entry; found[i] is set to 1 where a hit
 * was recorded (found[] is not cleared). flags: RC__PACKET_* above. */
void rc__mesh_intersect_packet(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom,
                               uint32_t inst, rc__hit *hits, int *found, uint32_t flags);

/* One packet through several meshes, meshes[m] as geometry geoms[m] (any
 * order: the tie rule does not depend on it), the same answers as
 * rc__mesh_intersect_packet mesh by mesh. The packet's lanes are filled
 * once for all the meshes, where each call would fill them again (a VLP-16
 * in a room of 24 balls, 217k triangles as 25 meshes, 2 threads: 1.17-1.25x
 * the scans/s, still about 0.8x those of the same room as one mesh). Left out of -Os builds (the
 * static core for small boards, whose size budget has no room): they call
 * rc__mesh_intersect_packet mesh by mesh. */
#if !defined(__OPTIMIZE_SIZE__)
#define RC__PACKET_MESHES 1
void rc__mesh_intersect_packet_meshes(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count,
                                      const rc__ray *rays, uint32_t n, uint32_t inst, rc__hit *hits, int *found,
                                      uint32_t flags);
#endif

/* Several packets at once, for a mesh past the caches: their fetches
 * overlap (same answers as one by one). The packets take turns node by
 * node, or with RC__PACKET_LONE_POOL run one by one, each subtree one lane
 * alone meets joining a pool of such lanes that take turns:
 * packet k is rays[k][0..n[k]) with hits[k] and found[k] as above. At most
 * RC__PACKETS_IN_FLIGHT packets; one goes the plain way. */
#define RC__PACKETS_IN_FLIGHT 8u
void rc__mesh_intersect_packets(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays,
                                const uint32_t *n, uint32_t geom, uint32_t inst, rc__hit *const *hits,
                                int *const *found, uint32_t flags);

/* Where leaf4.h has its AVX2 pairs (x86-64, GNU C) the traversal is built
 * twice (packet.c): for baseline x86-64 and for AVX2. The functions above
 * choose by the CPU; these are the two builds, for tests (call the _avx2
 * ones only where rc__leaf4_have_avx2() is 1). */
#if defined(RC__LEAF4_PAIR_AVX2) && !defined(RC__PACKET_FORCE_SCALAR)
#define RC__PACKET_TWO_BUILDS 1
void rc__mesh_intersect_packet_sse2(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom,
                                    uint32_t inst, rc__hit *hits, int *found, uint32_t flags);
void rc__mesh_intersect_packets_sse2(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays,
                                     const uint32_t *n, uint32_t geom, uint32_t inst, rc__hit *const *hits,
                                     int *const *found, uint32_t flags);
#if defined(RC__PACKET_MESHES)
void rc__mesh_intersect_packet_meshes_sse2(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count,
                                           const rc__ray *rays, uint32_t n, uint32_t inst, rc__hit *hits, int *found,
                                           uint32_t flags);
#endif
void rc__mesh_intersect_packet_avx2(const rc__mesh *mesh, const rc__ray *rays, uint32_t n, uint32_t geom,
                                    uint32_t inst, rc__hit *hits, int *found, uint32_t flags);
void rc__mesh_intersect_packets_avx2(const rc__mesh *mesh, uint32_t packets, const rc__ray *const *rays,
                                     const uint32_t *n, uint32_t geom, uint32_t inst, rc__hit *const *hits,
                                     int *const *found, uint32_t flags);
#if defined(RC__PACKET_MESHES)
void rc__mesh_intersect_packet_meshes_avx2(const rc__mesh *const *meshes, const uint32_t *geoms, uint32_t count,
                                           const rc__ray *rays, uint32_t n, uint32_t inst, rc__hit *hits, int *found,
                                           uint32_t flags);
#endif
#endif

#endif
