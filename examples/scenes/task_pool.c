/*
 * task_pool.h's pool. One task runs at a time: enqueue publishes it under a
 * new generation, workers and then the caller (in finish) claim its ranges
 * with a compare-and-swap on (generation, next range), so that a worker
 * late for one task can never claim a range of the next, and finish waits
 * until every range is done.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "task_pool.h"

#include <stdlib.h>
#include <string.h>

#if defined(__unix__) && (defined(__GNUC__) || defined(__clang__))
#define TASK_POOL_THREADS 1
#include <pthread.h>
#include <sched.h>
#else
#define TASK_POOL_THREADS 0
#endif

#if TASK_POOL_THREADS

/* Polls of the task word before a waiting worker sleeps. */
#define SPINS 400000

typedef struct worker_arg {
    struct task_pool *pool;
    uint32_t index;
} worker_arg;

struct task_pool {
    uint32_t workers;
    pthread_t threads[TCLOD_MAX_WORKERS];
    worker_arg args[TCLOD_MAX_WORKERS];
    uint32_t started;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int quit;          /* under lock */
    uint32_t sleepers; /* under lock */
    /* the task: written by enqueue before it publishes the generation, read
     * by a worker only once it has claimed one of its ranges */
    tclod_task_fn *fn;
    void *ctx;
    uint32_t count, range;
    /* generation << 32 | ranges << 16 | next range to claim (atomic) */
    uint64_t word;
    uint32_t done; /* ranges done (atomic) */
};

/* The most ranges of one task. */
#define MAX_RANGES 0xffffu

/* Claims and runs ranges of the task of generation `gen` until none is left. */
static void run_ranges(task_pool *p, uint64_t gen, uint32_t worker) {
    for (;;) {
        uint64_t w = __atomic_load_n(&p->word, __ATOMIC_ACQUIRE);
        uint32_t next = (uint32_t)(w & 0xffffu), ranges = (uint32_t)((w >> 16) & 0xffffu);
        uint32_t start, end;
        if ((w >> 32) != gen || next >= ranges)
            return;
        if (!__atomic_compare_exchange_n(&p->word, &w, w + 1u, 0, __ATOMIC_ACQ_REL,
                                         __ATOMIC_ACQUIRE))
            continue;
        start = next * p->range;
        end = p->count - start > p->range ? start + p->range : p->count;
        p->fn(start, end, worker, p->ctx);
        __atomic_fetch_add(&p->done, 1u, __ATOMIC_ACQ_REL);
    }
}

static void *worker_main(void *arg) {
    task_pool *p = ((worker_arg *)arg)->pool;
    uint32_t index = ((worker_arg *)arg)->index;
    uint64_t seen = 0;
    for (;;) {
        uint64_t gen;
        int spins = 0;
        while ((gen = __atomic_load_n(&p->word, __ATOMIC_ACQUIRE) >> 32) == seen) {
            if (++spins < SPINS)
                continue;
            pthread_mutex_lock(&p->lock);
            p->sleepers++;
            while (!p->quit && (__atomic_load_n(&p->word, __ATOMIC_ACQUIRE) >> 32) == seen)
                pthread_cond_wait(&p->wake, &p->lock);
            p->sleepers--;
            if (p->quit) {
                pthread_mutex_unlock(&p->lock);
                return NULL;
            }
            pthread_mutex_unlock(&p->lock);
            spins = 0;
        }
        seen = gen;
        run_ranges(p, gen, index);
    }
}

static void *pool_enqueue(tclod_task_fn *task, uint32_t item_count, uint32_t min_range,
                          void *task_ctx, void *user) {
    task_pool *p = (task_pool *)user;
    uint32_t range = min_range > 0 ? min_range : 1u, ranges;
    uint64_t gen = (__atomic_load_n(&p->word, __ATOMIC_ACQUIRE) >> 32) + 1u;
    /* a few ranges per worker, so that a slow worker does not hold the rest */
    if (item_count / (4u * p->workers) > range)
        range = item_count / (4u * p->workers);
    if (item_count / range >= MAX_RANGES)
        range = item_count / MAX_RANGES + 1u;
    ranges = item_count / range + (item_count % range != 0);
    p->fn = task;
    p->ctx = task_ctx;
    p->count = item_count;
    p->range = range;
    __atomic_store_n(&p->done, 0u, __ATOMIC_RELAXED);
    __atomic_store_n(&p->word, gen << 32 | (uint64_t)ranges << 16, __ATOMIC_RELEASE);
    pthread_mutex_lock(&p->lock);
    if (p->sleepers)
        pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    return p;
}

static void pool_finish(void *task, void *user) {
    task_pool *p = (task_pool *)user;
    uint64_t w = __atomic_load_n(&p->word, __ATOMIC_ACQUIRE);
    uint32_t ranges = (uint32_t)((w >> 16) & 0xffffu);
    (void)task;
    run_ranges(p, w >> 32, 0u);
    while (__atomic_load_n(&p->done, __ATOMIC_ACQUIRE) != ranges)
        sched_yield();
}

task_pool *task_pool_create(uint32_t workers) {
    task_pool *p;
    uint32_t i;
    if (workers < 1u || workers > TCLOD_MAX_WORKERS)
        return NULL;
    p = (task_pool *)calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->workers = workers;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    for (i = 1; i < workers; ++i) {
        worker_arg *a = &p->args[i];
        a->pool = p;
        a->index = i;
        if (pthread_create(&p->threads[i], NULL, worker_main, a) != 0)
            break;
        p->started++;
    }
    if (p->started != workers - 1u) {
        task_pool_destroy(p);
        return NULL;
    }
    return p;
}

void task_pool_destroy(task_pool *p) {
    uint32_t i;
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    /* a spinning worker sleeps, sees quit and leaves */
    for (i = 1; i <= p->started; ++i)
        pthread_join(p->threads[i], NULL);
    pthread_mutex_destroy(&p->lock);
    pthread_cond_destroy(&p->wake);
    free(p);
}

#else /* no threads: every task runs on the calling thread */

struct task_pool {
    uint32_t workers;
};

static void *pool_enqueue(tclod_task_fn *task, uint32_t item_count, uint32_t min_range,
                          void *task_ctx, void *user) {
    (void)min_range;
    (void)user;
    task(0, item_count, 0, task_ctx);
    return NULL;
}

static void pool_finish(void *task, void *user) {
    (void)task;
    (void)user;
}

task_pool *task_pool_create(uint32_t workers) {
    task_pool *p;
    if (workers < 1u || workers > TCLOD_MAX_WORKERS)
        return NULL;
    p = (task_pool *)calloc(1, sizeof *p);
    if (p)
        p->workers = workers;
    return p;
}

void task_pool_destroy(task_pool *p) {
    free(p);
}

#endif

tclod_tasks task_pool_tasks(task_pool *p) {
    tclod_tasks t;
    memset(&t, 0, sizeof t);
    t.worker_count = p->workers;
    t.enqueue = pool_enqueue;
    t.finish = pool_finish;
    t.user = p;
    return t;
}
