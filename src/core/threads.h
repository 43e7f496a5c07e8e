/* A fixed pool of worker threads started at context creation. run() hands out
 * task indices 0..count-1 to the workers and the calling thread; it returns when
 * all are done. Which thread runs which task never changes a result: tasks write
 * disjoint outputs. Built without RANGECAST_WITH_THREADS (or with 1 thread)
 * everything runs on the caller's thread. */
#ifndef RC_CORE_THREADS_H
#define RC_CORE_THREADS_H

#include "core/arena.h"
#include "rangecast/rangecast.h"

#include <stdint.h>

typedef struct rc__pool rc__pool;

/* thread index is 0 for the caller, 1..n-1 for workers. */
typedef void (*rc__task_fn)(void *user, uint32_t task, uint32_t thread);

/* Arena bytes a pool of n threads takes (rc__arena_cost included). */
size_t rc__pool_memory(uint32_t thread_count);
/* Starts thread_count - 1 workers. RC_ERR_OUT_OF_MEMORY, RC_ERR_BACKEND
 * (pthread_create failed). */
rc_status rc__pool_create(rc__arena *arena, uint32_t thread_count, rc__pool **out);
void rc__pool_destroy(rc__arena *arena, rc__pool *pool);
uint32_t rc__pool_thread_count(const rc__pool *pool);
void rc__pool_run(rc__pool *pool, uint32_t task_count, rc__task_fn fn, void *user);

/* Online CPUs (at least 1). */
uint32_t rc__cpu_count(void);

#endif
