/* Worker pool: workers sleep on a condition variable between runs; a run hands
 * out task indices under a mutex (tasks are coarse: a pose or a tile of rays,
 * so the lock is cheap). The calling thread works too, and a run ends when its
 * tasks are done, not when every worker has woken: waking a sleeping thread
 * takes tens of microseconds, which a small call (a few rays) must not wait
 * for. A run of one task never wakes anyone. */
#define _POSIX_C_SOURCE 200809L
#include "core/threads.h"

#include <string.h>

#if defined(RANGECAST_WITH_THREADS)
#include <pthread.h>
#include <unistd.h>
#endif

struct rc__pool {
    uint32_t thread_count;
#if defined(RANGECAST_WITH_THREADS)
    pthread_mutex_t lock;
    pthread_cond_t wake;     /* workers wait here for a new run or shutdown */
    pthread_cond_t idle;     /* the caller waits here for workers to finish */
    uint64_t generation;     /* bumped per run */
    uint32_t next_task;
    uint32_t task_count;
    uint32_t done;           /* tasks of the current run finished */
    int shutdown;
    rc__task_fn fn;
    void *user;
    pthread_t *threads;      /* thread_count - 1 */
    uint32_t started;
    uint32_t ready;          /* workers that have read their argument */
#endif
};

uint32_t rc__cpu_count(void)
{
#if defined(RANGECAST_WITH_THREADS) && defined(_SC_NPROCESSORS_ONLN)
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n >= 1) return n > (long)RC_MAX_THREADS ? RC_MAX_THREADS : (uint32_t)n;
#endif
    return 1;
}

size_t rc__pool_memory(uint32_t thread_count)
{
    size_t bytes = rc__arena_cost(sizeof(rc__pool));
#if defined(RANGECAST_WITH_THREADS)
    if (thread_count > 1) bytes += rc__arena_cost(sizeof(pthread_t) * (thread_count - 1));
#else
    (void)thread_count;
#endif
    return bytes;
}

uint32_t rc__pool_thread_count(const rc__pool *pool) { return pool->thread_count; }

#if defined(RANGECAST_WITH_THREADS)
/* Takes tasks until none are left. Called with the lock held; returns with it
 * held. A worker that wakes after its run has ended finds no task: fn and
 * user are only read for a task taken while the run is still open, so the
 * caller's run (and its stack) outlives every use of them. */
static void drain(rc__pool *pool, uint32_t thread)
{
    while (pool->next_task < pool->task_count) {
        uint32_t task = pool->next_task++;
        pthread_mutex_unlock(&pool->lock);
        pool->fn(pool->user, task, thread);
        pthread_mutex_lock(&pool->lock);
        if (++pool->done == pool->task_count) pthread_cond_signal(&pool->idle);
    }
}

typedef struct worker_arg {
    rc__pool *pool;
    uint32_t index;
} worker_arg;

static void *worker_main(void *arg)
{
    rc__pool *pool = ((worker_arg *)arg)->pool;
    uint32_t index = ((worker_arg *)arg)->index;
    uint64_t seen;
    pthread_mutex_lock(&pool->lock);
    seen = pool->generation;
    ++pool->ready;
    pthread_cond_signal(&pool->idle); /* the creator waits for every worker */
    for (;;) {
        while (!pool->shutdown && pool->generation == seen) pthread_cond_wait(&pool->wake, &pool->lock);
        if (pool->shutdown) break;
        seen = pool->generation;
        drain(pool, index);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}
#endif

rc_status rc__pool_create(rc__arena *arena, uint32_t thread_count, rc__pool **out)
{
    rc__pool *pool = (rc__pool *)rc__arena_calloc(arena, sizeof *pool);
    if (!pool) return RC_ERR_OUT_OF_MEMORY;
    if (thread_count == 0) thread_count = 1;
    pool->thread_count = thread_count;
#if defined(RANGECAST_WITH_THREADS)
    if (thread_count > 1) {
        /* Each worker reads its index from a small array kept on this stack
         * until it has started (the start handshake below). */
        worker_arg args[RC_MAX_THREADS];
        uint32_t i;
        pool->threads = (pthread_t *)rc__arena_alloc(arena, sizeof(pthread_t) * (thread_count - 1));
        if (!pool->threads) {
            rc__arena_free(arena, pool);
            return RC_ERR_OUT_OF_MEMORY;
        }
        pthread_mutex_init(&pool->lock, NULL);
        pthread_cond_init(&pool->wake, NULL);
        pthread_cond_init(&pool->idle, NULL);
        for (i = 0; i + 1 < thread_count; ++i) {
            args[i].pool = pool;
            args[i].index = i + 1;
            if (pthread_create(&pool->threads[i], NULL, worker_main, &args[i]) != 0) break;
            pool->started++;
        }
        /* Every worker reads its argument before its first wait. */
        pthread_mutex_lock(&pool->lock);
        while (pool->ready < pool->started) pthread_cond_wait(&pool->idle, &pool->lock);
        pthread_mutex_unlock(&pool->lock);
        if (pool->started + 1 != thread_count) {
            rc__pool_destroy(arena, pool);
            return RC_ERR_BACKEND;
        }
    }
#else
    pool->thread_count = 1;
#endif
    *out = pool;
    return RC_OK;
}

void rc__pool_run(rc__pool *pool, uint32_t task_count, rc__task_fn fn, void *user)
{
#if defined(RANGECAST_WITH_THREADS)
    if (pool->thread_count > 1 && task_count > 1) {
        pthread_mutex_lock(&pool->lock);
        pool->fn = fn;
        pool->user = user;
        pool->task_count = task_count;
        pool->next_task = 0;
        pool->done = 0;
        pool->generation++;
        pthread_cond_broadcast(&pool->wake);
        drain(pool, 0);
        while (pool->done < task_count) pthread_cond_wait(&pool->idle, &pool->lock);
        pthread_mutex_unlock(&pool->lock);
        return;
    }
#else
    (void)pool;
#endif
    {
        uint32_t t;
        for (t = 0; t < task_count; ++t) fn(user, t, 0);
    }
}

void rc__pool_destroy(rc__arena *arena, rc__pool *pool)
{
    if (!pool) return;
#if defined(RANGECAST_WITH_THREADS)
    if (pool->thread_count > 1) {
        uint32_t i;
        pthread_mutex_lock(&pool->lock);
        pool->shutdown = 1;
        pthread_cond_broadcast(&pool->wake);
        pthread_mutex_unlock(&pool->lock);
        for (i = 0; i < pool->started; ++i) pthread_join(pool->threads[i], NULL);
        pthread_mutex_destroy(&pool->lock);
        pthread_cond_destroy(&pool->wake);
        pthread_cond_destroy(&pool->idle);
        rc__arena_free(arena, pool->threads);
    }
#endif
    rc__arena_free(arena, pool);
}
