#include "core/work_order.h"

#include "core/rmath.h"
#include "rangecast/rangecast.h"

/* what RC_SIMULATE_SCRATCH_PER_THREAD promises: the largest scratch (the
 * backends keep an rc__xformf a pose), the arena's header and rounding */
typedef char rc__order_scratch_bound_check[(RC__ORDER_MAX_RECORDS * 16u + 16u +
                                                RC__ORDER_MAX_POSES * sizeof(rc__xformf) + 32u <=
                                            RC_SIMULATE_SCRATCH_PER_THREAD)
                                               ? 1
                                               : -1];

uint32_t rc__order_chunk_poses(uint32_t pose_count, uint32_t threads, uint32_t tiles_per_pose)
{
    uint32_t max_chunk, tasks, chunk;
    if (tiles_per_pose == 0 || threads == 0) return 0;
    max_chunk = RC__ORDER_MAX_RECORDS / tiles_per_pose;
    if (max_chunk > RC__ORDER_MAX_POSES) max_chunk = RC__ORDER_MAX_POSES;
    if (max_chunk == 0) return 0;
    tasks = (pose_count + max_chunk - 1u) / max_chunk;
    tasks = (tasks + threads - 1u) / threads * threads;
    chunk = (pose_count + tasks - 1u) / tasks;
    return (uint64_t)chunk * tiles_per_pose < RC__ORDER_MIN_RECORDS ? 0u : chunk;
}

static size_t worlds_offset(size_t records) { return (records * 4u * sizeof(uint32_t) + 15u) / 16u * 16u; }

size_t rc__order_scratch_bytes(uint32_t chunk_poses, uint32_t tiles_per_pose, size_t world_bytes)
{
    return worlds_offset((size_t)chunk_poses * tiles_per_pose) + (size_t)chunk_poses * world_bytes;
}

void rc__order_scratch_split(void *block, uint32_t chunk_poses, uint32_t tiles_per_pose, rc__order_scratch *out)
{
    const size_t cap = (size_t)chunk_poses * tiles_per_pose;
    out->keys = (uint32_t *)block;
    out->records = out->keys + cap;
    out->tmp_keys = out->records + cap;
    out->tmp_records = out->tmp_keys + cap;
    out->worlds = (unsigned char *)block + worlds_offset(cap);
}
