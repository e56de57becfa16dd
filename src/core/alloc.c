/*
 * Memory hooks and the monotonic clock.
 *
 * Every allocation goes through the scene's or selector's tclod_allocator so a
 * host can account for or pool libtclod's memory. Structure-of-arrays blocks
 * grow all or nothing (tclod_arrays_grow): an out-of-memory failure in the
 * middle of a growth leaves every array as it was, which is what lets each API
 * call promise "TCLOD_ERR_NOMEM, nothing changed".
 *
 * Layer: core, which may call core. Calls: libc and libm only.
 */
/* clock_gettime and CLOCK_MONOTONIC are POSIX, not C99: asked for here, before
 * any header, so that the file compiles as plain C99 without a -D flag. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L
#endif

#include "internal.h"

#include <stdlib.h>
#include <string.h>

#if defined(_WIN32)
#include <windows.h>
#else
#include <time.h>
#endif

static void *default_alloc(size_t size, void *ctx) {
    (void)ctx;
    return malloc(size);
}

static void default_free(void *ptr, size_t size, void *ctx) {
    (void)size;
    (void)ctx;
    free(ptr);
}

int tclod_allocator_init(tclod_allocator *dst, const tclod_allocator *src) {
    if (src && (src->alloc == NULL) != (src->free == NULL))
        return 0;
    if (src && src->alloc) {
        *dst = *src;
    } else {
        dst->alloc = default_alloc;
        dst->free = default_free;
        dst->ctx = NULL;
    }
    return 1;
}

void *tclod_mem_alloc(const tclod_allocator *a, size_t size) {
    return a->alloc(size ? size : 1, a->ctx);
}

void tclod_mem_free(const tclod_allocator *a, void *ptr, size_t size) {
    if (ptr)
        a->free(ptr, size ? size : 1, a->ctx);
}

tclod_status tclod_arrays_alloc(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                                size_t new_cap, void **fresh) {
    size_t i;
    for (i = 0; i < count; ++i) {
        if (new_cap > SIZE_MAX / arrays[i].elem)
            break;
        fresh[i] = tclod_mem_alloc(a, arrays[i].elem * new_cap);
        if (!fresh[i])
            break;
    }
    if (i == count)
        return TCLOD_OK;
    while (i-- > 0)
        tclod_mem_free(a, fresh[i], arrays[i].elem * new_cap);
    return TCLOD_ERR_NOMEM;
}

void tclod_arrays_discard(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                          size_t new_cap, void **fresh) {
    size_t i;
    for (i = 0; i < count; ++i)
        tclod_mem_free(a, fresh[i], arrays[i].elem * new_cap);
}

void tclod_arrays_commit(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                         size_t old_cap, size_t new_cap, void **fresh) {
    size_t i;
    assert(new_cap >= old_cap);
    for (i = 0; i < count; ++i) {
        unsigned char *to = (unsigned char *)fresh[i];
        size_t elem = arrays[i].elem;
        if (old_cap)
            memcpy(to, *arrays[i].ptr, elem * old_cap);
        if (arrays[i].fill >= 0)
            memset(to + elem * old_cap, arrays[i].fill, elem * (new_cap - old_cap));
        tclod_mem_free(a, *arrays[i].ptr, elem * old_cap);
        *arrays[i].ptr = fresh[i];
    }
}

tclod_status tclod_arrays_grow(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                               size_t old_cap, size_t new_cap) {
    void *fresh[TCLOD_MAX_ARRAYS];
    tclod_status st;
    assert(count <= TCLOD_MAX_ARRAYS);
    st = tclod_arrays_alloc(a, arrays, count, new_cap, fresh);
    if (st == TCLOD_OK)
        tclod_arrays_commit(a, arrays, count, old_cap, new_cap, fresh);
    return st;
}

void tclod_arrays_free(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                       size_t cap) {
    size_t i;
    for (i = 0; i < count; ++i) {
        if (cap)
            tclod_mem_free(a, *arrays[i].ptr, arrays[i].elem * cap);
        *arrays[i].ptr = NULL;
    }
}

double tclod_now(void) {
#if defined(_WIN32)
    LARGE_INTEGER freq, now;
    QueryPerformanceFrequency(&freq);
    QueryPerformanceCounter(&now);
    return (double)now.QuadPart / (double)freq.QuadPart;
#else
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
#endif
}

/* Appends src to dst (holding n characters of cap), truncating. */
static size_t append(char *dst, size_t n, size_t cap, const char *src) {
    while (*src && n + 1 < cap)
        dst[n++] = *src++;
    dst[n] = '\0';
    return n;
}

tclod_status tclod_fail_in(char *error, tclod_status st, const char *function, const char *where,
                           const char *what) {
    size_t n = append(error, 0, TCLOD_ERROR_SIZE, function);
    if (where || what)
        n = append(error, n, TCLOD_ERROR_SIZE, ": ");
    if (where)
        n = append(error, n, TCLOD_ERROR_SIZE, where);
    if (what)
        append(error, n, TCLOD_ERROR_SIZE, what);
    return st;
}

tclod_status tclod_fail(char *error, tclod_status st, const char *function, const char *what) {
    return tclod_fail_in(error, st, function, NULL, what);
}
