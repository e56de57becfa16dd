/*
 * What every source file of the library shares: memory, time, error
 * messages and a few compiler hints. Nothing here is exported; the public
 * contract is include/tclod/tclod.h. The other private headers build on this
 * one (README.md, Layout).
 */
#ifndef TCLOD_INTERNAL_H
#define TCLOD_INTERNAL_H

/* Every file that includes this one is part of the library: TCLOD_API then
 * exports its definitions from a Windows DLL rather than importing them. */
#ifndef TCLOD_BUILDING
#define TCLOD_BUILDING
#endif

#include "tclod/tclod.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ---- alloc.c: memory and time --------------------------------------------- */

/* Copies src (may be NULL) into dst, filling NULL hooks with malloc/free.
 * Returns 0 when src sets only one of alloc/free. */
int tclod_allocator_init(tclod_allocator *dst, const tclod_allocator *src);
void *tclod_mem_alloc(const tclod_allocator *a, size_t size);
void tclod_mem_free(const tclod_allocator *a, void *ptr, size_t size);

/* One array of a structure-of-arrays block that grows as a whole. */
typedef struct tclod_array {
    void **ptr;  /* where the array pointer lives */
    size_t elem; /* element size in bytes */
    int fill;    /* byte written into new elements, or -1 to leave them */
} tclod_array;

/* The most arrays one block may hold. */
#define TCLOD_MAX_ARRAYS 48

/* Grows every array from old_cap to new_cap elements, all or nothing: either
 * every array is replaced by a larger copy (old contents kept, new elements
 * filled) and TCLOD_OK returned, or nothing changes and TCLOD_ERR_NOMEM. */
tclod_status tclod_arrays_grow(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                               size_t old_cap, size_t new_cap);

/* The same in two steps, so that several blocks grow all or nothing together:
 * alloc takes new_cap elements per array into fresh[] (TCLOD_ERR_NOMEM and
 * nothing held on failure); then either commit (copy, fill, free the old) or
 * discard (free fresh[]). */
tclod_status tclod_arrays_alloc(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                                size_t new_cap, void **fresh);
void tclod_arrays_commit(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                         size_t old_cap, size_t new_cap, void **fresh);
void tclod_arrays_discard(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                          size_t new_cap, void **fresh);
void tclod_arrays_free(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                       size_t cap);

/* Monotonic clock in seconds. */
double tclod_now(void);

/* Every object keeps why its last failed call failed: "function: what". */
#define TCLOD_ERROR_SIZE 192
/* Writes "function: what" (what may be NULL: "function") into error,
 * truncated to TCLOD_ERROR_SIZE, and returns st. */
tclod_status tclod_fail(char *error, tclod_status st, const char *function, const char *what);
/* The same with "function: where" followed by what (either may be NULL). */
tclod_status tclod_fail_in(char *error, tclod_status st, const char *function, const char *where,
                           const char *what);
/* Messages more than one module gives. */
#define TCLOD_MSG_BUSY "called from a callback during a solve"
#define TCLOD_MSG_NOMEM "no memory for the scene's size"
#define TCLOD_MSG_SMOOTH \
    "the scene has smooth objects and the mixed solver has no smooth_benefit or smooth_cost"
#define TCLOD_MSG_STRICT "strict mode: a callback returned NaN, inf or a negative value"

/* The rule a calibration desc breaks (NULL: none), its fields named as in a
 * scheduler's desc (desc.calib.*) when nested. */
const char *tclod_calib_check(const tclod_calib_desc *d, int nested);

/* A function of the solvers' inner loops that must be inlined where it is
 * called, whatever the compiler's estimate of its size. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define TCLOD_ALWAYS_INLINE static inline
#endif

/* A static function of a header that the few files of one unit share and not
 * every one of them calls: compiled as it would be in a source file (inlined
 * or not by the compiler's own estimate), without the warning an unused one
 * would give. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_UNIT static __attribute__((unused))
#else
#define TCLOD_UNIT static
#endif

/* A function the compiler must not inline: one kept off the common path. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_NOINLINE __attribute__((noinline))
#else
#define TCLOD_NOINLINE
#endif

/* A hint to fetch the cache line at p (to write it: _WRITE); nothing where
 * the compiler has none. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_PREFETCH(p) __builtin_prefetch(p)
#define TCLOD_PREFETCH_WRITE(p) __builtin_prefetch(p, 1)
#define TCLOD_UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define TCLOD_PREFETCH(p) ((void)0)
#define TCLOD_PREFETCH_WRITE(p) ((void)0)
#define TCLOD_UNLIKELY(x) (x)
#endif
/* Whether callbacks price smooth objects: smooth_cost or smooth_features. */
static inline int tclod_smooth_priced(const tclod_callbacks *cb) {
    return cb->smooth_cost != NULL || cb->smooth_features != NULL;
}

/* How many slots ahead a walk over the cut fetches the node record it will
 * read: the cut lists nodes in no order of id, so each is a miss of its own
 * once the nodes outgrow the cache (docs/robin_hood.md, memory). */
#define TCLOD_CUT_AHEAD 16u

/* The bits of a double, for the range checks of callback values: as unsigned
 * integers the positive finite doubles are 1 ... TCLOD_BITS_MAX, +0 is 0 and
 * +inf is TCLOD_BITS_MAX + 1; every negative one, NaN or -0 lies above. */
#define TCLOD_BITS_MAX UINT64_C(0x7fefffffffffffff)
static inline uint64_t tclod_bits(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof(u));
    return u;
}

/* Adds x to the running sum *s, keeping in *e what rounding took from it:
 * (a - t) + x is exactly the rounding error of t = a + x when |a| >= |x|,
 * which a running sum of costs meets but for its first terms (there the
 * error found is off by an ulp of t or so). So *s + *e is the sum to within
 * rounding of the total, also when *s has absorbed terms below half its ulp.
 * An infinite sum makes *e NaN or infinite, which tclod_within then ignores. */
static inline void tclod_add_compensated(double *s, double *e, double x) {
    double a = *s, t = a + x;
    *e += (a - t) + x;
    *s = t;
}

#endif /* TCLOD_INTERNAL_H */
