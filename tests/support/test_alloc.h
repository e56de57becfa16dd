/*
 * test_alloc — a tclod_allocator for tests that counts every allocation,
 * checks that free receives the size given to alloc, and can be told to fail
 * the k-th allocation from now (a transient failure), or every allocation
 * from the k-th on (a persistent one), to drive TCLOD_ERR_NOMEM paths.
 */
#ifndef TEST_ALLOC_H
#define TEST_ALLOC_H

#include <stddef.h>

#include <tclod/tclod.h>

typedef struct test_alloc {
    size_t outstanding_bytes; /* allocated and not yet freed */
    size_t outstanding_blocks;
    size_t allocations; /* successful alloc calls, ever */
    size_t frees;       /* free calls, ever */
    size_t calls;       /* alloc calls since the last test_alloc_fail_at/_from */
    size_t fail_at;     /* the fail_at-th call since then fails; 0 = never */
    size_t fail_from;   /* every call from the fail_from-th on fails; 0 = never */
    size_t failures;    /* alloc calls answered with NULL, ever */
    size_t bad_frees;   /* frees of a foreign pointer or with a wrong size */
} test_alloc;

/* All counters 0, no failure armed. */
void test_alloc_init(test_alloc *t);

/* Makes the k-th alloc call from now return NULL (only that one); k = 0
 * disarms. Resets t->calls and disarms test_alloc_fail_from. */
void test_alloc_fail_at(test_alloc *t, size_t k);

/* Makes every alloc call from the k-th from now on return NULL; k = 0
 * disarms. Resets t->calls and disarms test_alloc_fail_at. */
void test_alloc_fail_from(test_alloc *t, size_t k);

/* The hooks to pass to tclod_scene_create / tclod_selector_create. */
tclod_allocator test_alloc_hooks(test_alloc *t);

#endif /* TEST_ALLOC_H */
