/* The worker pool (src/core/threads.c): every task of a run runs exactly
 * once, on a thread the pool owns, and the run has finished with it when
 * rc__pool_run returns, also when runs follow each other faster than
 * sleeping workers wake. A run of one task stays on the caller's thread. */
#include "core/arena.h"
#include "core/threads.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#if defined(RANGECAST_WITH_THREADS)
#include <pthread.h>
#endif

#define MAX_TASKS 64u

typedef struct run_log {
    uint32_t counts[MAX_TASKS]; /* times each task ran */
    uint32_t thread[MAX_TASKS]; /* which thread ran it */
    uint32_t tasks;             /* tasks of this run */
    uint32_t thread_count;
#if defined(RANGECAST_WITH_THREADS)
    pthread_t caller;
    int foreign[MAX_TASKS];     /* 1: not the caller's thread */
#endif
} run_log;

static void log_task(void *user, uint32_t task, uint32_t thread)
{
    run_log *log = (run_log *)user;
    /* a task past the run's count, or one from a finished run landing here,
     * shows up as a count other than 1 */
    if (task < MAX_TASKS) {
        log->counts[task]++;
        log->thread[task] = thread;
#if defined(RANGECAST_WITH_THREADS)
        log->foreign[task] = !pthread_equal(pthread_self(), log->caller);
#endif
    }
}

/* One run with its log on this frame's stack: a worker still using it after
 * the run returned would write into the next call's log. */
static void one_run(rc__pool *pool, uint32_t threads, uint32_t tasks)
{
    run_log log;
    uint32_t t;
    memset(&log, 0, sizeof log);
    log.tasks = tasks;
    log.thread_count = threads;
#if defined(RANGECAST_WITH_THREADS)
    log.caller = pthread_self();
#endif
    rc__pool_run(pool, tasks, log_task, &log);
    for (t = 0; t < MAX_TASKS; ++t) {
        assert_int_equal(log.counts[t], t < tasks ? 1u : 0u);
        if (t < tasks) assert_true(log.thread[t] < rc__pool_thread_count(pool));
    }
    if (tasks == 1) {
        /* one task: no worker is woken for it */
        assert_int_equal(log.thread[0], 0u);
#if defined(RANGECAST_WITH_THREADS)
        assert_int_equal(log.foreign[0], 0);
#endif
    }
}

static rc__pool *make_pool(uint32_t threads, void **block, rc__arena *arena)
{
    const size_t bytes = rc__pool_memory(threads);
    rc__pool *pool = NULL;
    *block = malloc(bytes);
    assert_non_null(*block);
    rc__arena_init(arena, *block, bytes);
    assert_int_equal(rc__pool_create(arena, threads, &pool), RC_OK);
    return pool;
}

static void test_every_task_once(void **state)
{
    static const uint32_t sizes[] = {0, 1, 2, 3, 5, 17, MAX_TASKS};
    static const uint32_t thread_counts[] = {1, 2, 3, 8};
    uint32_t ti, i;
    (void)state;
    for (ti = 0; ti < sizeof thread_counts / sizeof thread_counts[0]; ++ti) {
        void *block;
        rc__arena arena;
        rc__pool *pool = make_pool(thread_counts[ti], &block, &arena);
        /* back to back: workers still waking from one run meet the next */
        for (i = 0; i < 3000; ++i) one_run(pool, thread_counts[ti], sizes[i % (sizeof sizes / sizeof sizes[0])]);
        rc__pool_destroy(&arena, pool);
        free(block);
    }
}

static void test_single_tasks_stay_on_caller(void **state)
{
    void *block;
    rc__arena arena;
    rc__pool *pool = make_pool(4, &block, &arena);
    uint32_t i;
    (void)state;
    for (i = 0; i < 2000; ++i) one_run(pool, 4, 1);
    rc__pool_destroy(&arena, pool);
    free(block);
}

/* A pool created and destroyed with no run in between: the workers' start
 * handshake must not depend on a first run. */
static void test_create_destroy_without_runs(void **state)
{
    uint32_t i;
    (void)state;
    for (i = 0; i < 50; ++i) {
        void *block;
        rc__arena arena;
        rc__pool *pool = make_pool(1u + i % 6u, &block, &arena);
        rc__pool_destroy(&arena, pool);
        free(block);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_task_once),
        cmocka_unit_test(test_single_tasks_stay_on_caller),
        cmocka_unit_test(test_create_destroy_without_runs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
