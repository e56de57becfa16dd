/*
 * heap.c: the indexed 4-ary max-heap and the sort the solvers use.
 */
#ifndef TCLOD_HEAP_H
#define TCLOD_HEAP_H

#include "internal.h"

/* ---- heap.c: indexed 4-ary max-heap ------------------------------------------- */

typedef struct tclod_heap_entry {
    double key;
    tclod_id id;
    uint32_t unused;
} tclod_heap_entry;

/* Orders ids by key, largest first; equal keys by smaller id first. The slot of
 * id i is pos[i], so an entry can be removed or replaced in O(log n). An id is
 * in the heap when its slot is below count and holds it (a sparse set): a
 * slot left behind by an id that is gone is never trusted, so emptying the
 * heap costs nothing. pos[] starts filled with TCLOD_NONE. */
typedef struct tclod_heap {
    tclod_heap_entry *items;
    uint32_t *pos;
    uint32_t count;
} tclod_heap;

/* Adds id without restoring order; call tclod_heap_build before any pop. */
void tclod_heap_append(tclod_heap *h, tclod_id id, double key);
/* Restores heap order over all entries in O(n). */
void tclod_heap_build(tclod_heap *h);
void tclod_heap_push(tclod_heap *h, tclod_id id, double key);
/* Removes and returns the first id; the heap must not be empty. */
tclod_id tclod_heap_pop(tclod_heap *h);
void tclod_heap_remove(tclod_heap *h, tclod_id id);
/* Puts id with key in the place of old_id's entry (id may equal old_id) and
 * restores order: the same heap as removing old_id and pushing id, for the
 * cost of one of the two. */
void tclod_heap_replace(tclod_heap *h, tclod_id old_id, tclod_id id, double key);
/* Empties the heap. */
static inline void tclod_heap_clear(tclod_heap *h) {
    h->count = 0;
}

static inline int tclod_heap_contains(const tclod_heap *h, tclod_id id) {
    uint32_t slot = h->pos[id];
    return slot < h->count && h->items[slot].id == id;
}

/* Sorts ids[0..n) in heap order (largest key first, ties by smaller id),
 * moving keys along. In place, no recursion. */
void tclod_sort_by_key(tclod_id *ids, double *keys, uint32_t n);

#endif /* TCLOD_HEAP_H */
