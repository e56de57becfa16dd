/*
 * bench_util — see bench_util.h.
 */
#include "bench_util.h"

#include <math.h>
#include <stdlib.h>
#include <time.h>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h>
#endif

static void *bench_counted_alloc(size_t size, void *ctx) {
    bench_counter *c = (bench_counter *)ctx;
    void *p = malloc(size);
    if (p) {
        c->held += size;
        c->allocs++;
        if (c->held > c->peak)
            c->peak = c->held;
    }
    return p;
}

static void bench_counted_free(void *ptr, size_t size, void *ctx) {
    bench_counter *c = (bench_counter *)ctx;
    c->held -= size;
    c->frees++;
    free(ptr);
}

tclod_allocator bench_counting_allocator(bench_counter *c) {
    tclod_allocator a;
    a.alloc = bench_counted_alloc;
    a.free = bench_counted_free;
    a.ctx = c;
    return a;
}

void bench_counter_reset_peak(bench_counter *c) {
    c->peak = c->held;
}

double bench_peak_rss_mb(void) {
#if defined(__unix__) || defined(__APPLE__)
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0.0;
#if defined(__APPLE__)
    return (double)ru.ru_maxrss / (1024.0 * 1024.0); /* bytes */
#else
    return (double)ru.ru_maxrss / 1024.0; /* KiB */
#endif
#else
    return 0.0;
#endif
}

double bench_now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int bench_compare(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void bench_sort(double *values, size_t n) {
    if (n > 1)
        qsort(values, n, sizeof *values, bench_compare);
}

double bench_median(const double *sorted, size_t n) {
    if (n == 0)
        return NAN;
    return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

double bench_percentile(const double *sorted, size_t n, double p) {
    size_t rank;
    if (n == 0)
        return NAN;
    rank = (size_t)ceil(p / 100.0 * (double)n);
    if (rank < 1)
        rank = 1;
    if (rank > n)
        rank = n;
    return sorted[rank - 1];
}

double bench_no_smooth(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    (void)r;
    *d_dr = 0.0;
    return 0.0;
}

tclod_id *bench_parents(const tclod_scene *s) {
    uint32_t n = tclod_scene_node_count(s), i;
    tclod_id *p = (tclod_id *)malloc(((size_t)n + 1u) * sizeof *p);
    if (p == NULL)
        return NULL;
    for (i = 0; i < n; ++i)
        p[i] = tclod_scene_parent(s, i);
    return p;
}

unsigned long bench_world_visible(const world_scene *w) {
    double sum = 0.0;
    int i;
    for (i = 0; i < 16; ++i) {
        tclod_view view;
        world_camera_at(&w->path, (double)i / 16.0, &view);
        sum += (double)world_visible_objects(w, &view);
    }
    return (unsigned long)(sum / 16.0 + 0.5);
}

double bench_world_level1_cost(const world_scene *w) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < w->object_count; ++i) {
        tclod_id id = w->object_root[i] + (w->levels > 1 ? 1u : 0u);
        sum += (double)w->cost_ms[id];
    }
    return w->object_count ? sum / (double)w->object_count : 0.0;
}

double bench_world_budget(const world_scene *w) {
    return (double)bench_world_visible(w) * bench_world_level1_cost(w);
}
