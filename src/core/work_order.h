/* Ordered runs, the part both CPU backends share: how many poses a chunk
 * takes, and the layout of a thread's scratch. A backend keys each tile of a
 * chunk (the built-in backend by its tree, rc__mesh_order_key; Embree's by
 * the occupancy grid, scene/occupancy.h), sorts the keys
 * (rc__radix_sort_pairs) and traces the tiles in that order, so that tiles
 * of different poses that meet the same part of a large map run back to back
 * and find it in cache. The order never changes a result. */
#ifndef RC_CORE_WORK_ORDER_H
#define RC_CORE_WORK_ORDER_H

#include <stddef.h>
#include <stdint.h>

/* Tiles a chunk sorts. Below the minimum a chunk meets each part of the map
 * too seldom to gain (10M sphere, VLP-16, 2 threads: 9 poses a chunk -2%,
 * 25 poses +10%, 100 +27%, 250 +34%); the maximum bounds the scratch (16
 * bytes a tile: 4 MiB a thread). */
#define RC__ORDER_MIN_RECORDS 16384u
#define RC__ORDER_MAX_RECORDS 262144u
/* Most poses a chunk takes (bounds the transforms' part of the scratch). */
#define RC__ORDER_MAX_POSES 4096u

/* Poses a chunk takes: as few chunks as the cap allows, a multiple of the
 * thread count so that no thread is left with the last one alone; 0 when a
 * chunk would sort too few tiles to gain. */
uint32_t rc__order_chunk_poses(uint32_t pose_count, uint32_t threads, uint32_t tiles_per_pose);

/* A thread's scratch: keys and records, each twice (the sort moves through
 * the second pair), then the chunk's world transforms (world_bytes each). */
typedef struct rc__order_scratch {
    uint32_t *keys, *records, *tmp_keys, *tmp_records;
    void *worlds;
} rc__order_scratch;

/* Bytes of one thread's scratch for chunks of chunk_poses. */
size_t rc__order_scratch_bytes(uint32_t chunk_poses, uint32_t tiles_per_pose, size_t world_bytes);
/* Cuts block (16-aligned, rc__order_scratch_bytes long) into its parts. */
void rc__order_scratch_split(void *block, uint32_t chunk_poses, uint32_t tiles_per_pose, rc__order_scratch *out);

#endif
