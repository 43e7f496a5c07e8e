/* Ordered runs, the part both CPU backends share (backend/results.c): how many poses a chunk
 * takes, and the layout of a thread's scratch. A backend keys each tile of a
 * chunk (the built-in backend by its tree, rc__mesh_order_key; Embree's by
 * the occupancy grid, backend/embree_occupancy.h), sorts the keys
 * (rc__radix_sort_pairs) and traces the tiles in that order, so that tiles
 * of different poses that meet the same part of a large map run back to back
 * and find it in cache. The order never changes a result. */
#ifndef RC_CORE_WORK_ORDER_H
#define RC_CORE_WORK_ORDER_H

#include <stddef.h>
#include <stdint.h>

/* Tiles a chunk sorts. Below the minimum a chunk meets each part of the map
 * too seldom to gain (10M sphere, VLP-16, 2 threads: 9 poses a chunk -2%,
 * 25 poses +10%, 100 +27%, 250 +34%; measured with the built-in backend's
 * tiles of 16 rays, which passes the minimum for its tiles' size: the same
 * rays a chunk); the maximum bounds the scratch (16 bytes a tile: 4 MiB a
 * thread). */
#define RC__ORDER_MIN_RECORDS 16384u
#define RC__ORDER_MAX_RECORDS 262144u
/* Most poses a chunk takes (bounds the transforms' part of the scratch). */
#define RC__ORDER_MAX_POSES 4096u

/* Poses a chunk takes: as few chunks as the cap allows, a multiple of the
 * thread count so that no thread is left with the last one alone; 0 when a
 * chunk would sort fewer than min_records tiles (too few to gain). (Inline, like the two below: the
 * static core library's size is budgeted.) */
static inline uint32_t rc__order_chunk_poses(uint32_t pose_count, uint32_t threads, uint32_t tiles_per_pose,
                                             uint32_t min_records)
{
    uint32_t max_chunk, tasks, chunk;
    if (tiles_per_pose == 0 || threads == 0) return 0;
    max_chunk = RC__ORDER_MAX_RECORDS / tiles_per_pose;
    if (max_chunk > RC__ORDER_MAX_POSES) max_chunk = RC__ORDER_MAX_POSES;
    if (max_chunk == 0) return 0;
    tasks = (pose_count + max_chunk - 1u) / max_chunk;
    tasks = (tasks + threads - 1u) / threads * threads;
    chunk = (pose_count + tasks - 1u) / tasks;
    return (uint64_t)chunk * tiles_per_pose < min_records ? 0u : chunk;
}

/* A thread's scratch: keys and records, each twice (the sort moves through
 * the second pair), then the chunk's world transforms (world_bytes each). */
typedef struct rc__order_scratch {
    uint32_t *keys, *records, *tmp_keys, *tmp_records;
    void *worlds;
} rc__order_scratch;

static inline size_t rc__order_worlds_offset(size_t records)
{
    return (records * 4u * sizeof(uint32_t) + 15u) / 16u * 16u;
}

/* Bytes of one thread's scratch for chunks of chunk_poses. */
static inline size_t rc__order_scratch_bytes(uint32_t chunk_poses, uint32_t tiles_per_pose, size_t world_bytes)
{
    return rc__order_worlds_offset((size_t)chunk_poses * tiles_per_pose) + (size_t)chunk_poses * world_bytes;
}

/* Cuts block (16-aligned, rc__order_scratch_bytes long) into its parts. */
static inline void rc__order_scratch_split(void *block, uint32_t chunk_poses, uint32_t tiles_per_pose,
                                           rc__order_scratch *out)
{
    const size_t cap = (size_t)chunk_poses * tiles_per_pose;
    out->keys = (uint32_t *)block;
    out->records = out->keys + cap;
    out->tmp_keys = out->records + cap;
    out->tmp_records = out->tmp_keys + cap;
    out->worlds = (unsigned char *)block + rc__order_worlds_offset(cap);
}

/* Sorting of (key, value) pairs by key: least significant digit first, eight
 * bits a pass, stable, no allocation (the caller hands in a second pair of
 * arrays to move through). */
/* Sorts keys[0..n) ascending, moving values[i] with keys[i] (equal keys keep
 * their order). Only the low `bits` bits of the keys are looked at (at most
 * 32). tmp_keys and tmp_values hold n entries each; on return the sorted
 * pairs are in keys and values, and the tmp arrays hold nothing useful. */
void rc__radix_sort_pairs(uint32_t *keys, uint32_t *values, uint32_t *tmp_keys, uint32_t *tmp_values, uint32_t n,
                          uint32_t bits);

#endif
