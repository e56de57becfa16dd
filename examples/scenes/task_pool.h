/*
 * A small task system of the kind a host engine has, for tclod_tasks: a
 * fixed set of threads that run the ranges of one task at a time, the
 * calling thread included (worker 0). Workers claim ranges from a shared
 * counter, spin a little while waiting for the next task and then sleep.
 * POSIX threads; elsewhere every task runs on the calling thread.
 *
 *   task_pool *pool = task_pool_create(2);
 *   desc.tasks = task_pool_tasks(pool);
 *   ...
 *   task_pool_destroy(pool);
 */
#ifndef TCLOD_TASK_POOL_H
#define TCLOD_TASK_POOL_H

#include <tclod/tclod.h>

typedef struct task_pool task_pool;

/* A pool of `workers` workers (the caller's thread and workers - 1 threads),
 * 1 .. TCLOD_MAX_WORKERS; NULL when threads cannot be made. */
task_pool *task_pool_create(uint32_t workers);
void task_pool_destroy(task_pool *pool);

/* The tclod_tasks that run on the pool. */
tclod_tasks task_pool_tasks(task_pool *pool);

#endif /* TCLOD_TASK_POOL_H */
