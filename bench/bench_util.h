/*
 * bench_util — small helpers shared by the benchmark programs: a monotonic clock,
 * order statistics, and smooth callbacks for scenes without smooth objects.
 */
#ifndef BENCH_UTIL_H
#define BENCH_UTIL_H

#include <stddef.h>

#include <tclod/tclod.h>

#include "world_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a counting allocator (bench_counting_allocator) holds: bytes now, the
 * most it held since its peak was last reset, and the calls. */
typedef struct bench_counter {
    size_t held, peak;
    unsigned long allocs, frees;
} bench_counter;

/* A tclod_allocator over malloc/free that counts into c (zeroed by the caller). */
tclod_allocator bench_counting_allocator(bench_counter *c);

/* Starts a new peak: the most held from now on. */
void bench_counter_reset_peak(bench_counter *c);

/* The process's peak resident set size in MiB (getrusage), 0 when unknown. */
double bench_peak_rss_mb(void);

/* Microseconds of CLOCK_MONOTONIC. */
double bench_now_us(void);

/* Sorts values[0..n) ascending in place. */
void bench_sort(double *values, size_t n);

/* Median of n sorted values (mean of the middle two for even n); NaN for n == 0. */
double bench_median(const double *sorted, size_t n);

/* Nearest-rank percentile, p in (0, 100], of n sorted values; NaN for n == 0. */
double bench_percentile(const double *sorted, size_t n, double p);

/* The mixed solver requires smooth callbacks even for a scene without smooth objects,
 * where they are never called; these return 0 with a slope of 0. */
double bench_no_smooth(void *user, const tclod_query *q, double r, double *d_dr);

/* Parent of every node of s, in a new array of tclod_scene_node_count(s) entries (free
 * it with free), or NULL when memory runs out. */
tclod_id *bench_parents(const tclod_scene *s);

/* Objects in view of a world, mean over 16 points of its camera loop. */
unsigned long bench_world_visible(const world_scene *w);

/* Mean cost of the objects' level 1 (level 0 when objects have one level). */
double bench_world_level1_cost(const world_scene *w);

/* The budget of a random world in the benchmarks: bench_world_visible x
 * bench_world_level1_cost, enough for every visible object at level 1 on average. */
double bench_world_budget(const world_scene *w);

#ifdef __cplusplus
}
#endif

#endif /* BENCH_UTIL_H */
