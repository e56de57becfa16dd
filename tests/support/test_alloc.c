/*
 * test_alloc — counting and failing allocator. Each block carries a header
 * with its size and a tag, so free can check what the library passes back.
 */
#include "test_alloc.h"

#include <stdlib.h>
#include <string.h>

/* Header in front of every block; its size is a multiple of the strictest
 * alignment among these types, so the user pointer stays aligned like malloc's. */
typedef union test_alloc_header {
    struct {
        size_t size;
        size_t tag;
    } info;
    long double align_ld;
    long long align_ll;
    void *align_p;
    double align_d;
} test_alloc_header;

#define TEST_ALLOC_TAG ((size_t)0x7c10dbadu)

void test_alloc_init(test_alloc *t) {
    memset(t, 0, sizeof *t);
}

void test_alloc_fail_at(test_alloc *t, size_t k) {
    t->fail_at = k;
    t->fail_from = 0;
    t->calls = 0;
}

void test_alloc_fail_from(test_alloc *t, size_t k) {
    t->fail_at = 0;
    t->fail_from = k;
    t->calls = 0;
}

static void *test_alloc_alloc(size_t size, void *ctx) {
    test_alloc *t = (test_alloc *)ctx;
    test_alloc_header *h;
    t->calls++;
    if ((t->fail_at != 0 && t->calls == t->fail_at) ||
        (t->fail_from != 0 && t->calls >= t->fail_from)) {
        t->failures++;
        return NULL;
    }
    h = (test_alloc_header *)malloc(sizeof *h + size);
    if (h == NULL) {
        t->failures++;
        return NULL;
    }
    h->info.size = size;
    h->info.tag = TEST_ALLOC_TAG;
    t->outstanding_bytes += size;
    t->outstanding_blocks++;
    t->allocations++;
    return h + 1;
}

static void test_alloc_free(void *ptr, size_t size, void *ctx) {
    test_alloc *t = (test_alloc *)ctx;
    test_alloc_header *h;
    t->frees++;
    if (ptr == NULL)
        return;
    h = (test_alloc_header *)ptr - 1;
    if (h->info.tag != TEST_ALLOC_TAG || h->info.size != size) {
        t->bad_frees++;
        return; /* leak rather than corrupt the heap */
    }
    h->info.tag = 0;
    t->outstanding_bytes -= size;
    t->outstanding_blocks--;
    free(h);
}

tclod_allocator test_alloc_hooks(test_alloc *t) {
    tclod_allocator a;
    a.alloc = test_alloc_alloc;
    a.free = test_alloc_free;
    a.ctx = t;
    return a;
}
