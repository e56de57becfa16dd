/*
 * Indexed 4-ary max-heap of node ids keyed by double, and an in-place heapsort
 * using the same order.
 *
 * The greedy solver keeps its increments (best Δbenefit/Δcost first) and its
 * decrements (least loss per saved cost first, stored negated) here. Equal
 * keys are ordered by the smaller id, which makes every selection
 * deterministic. Each id's slot is kept so an entry whose node left the cut can
 * be removed in O(log n). Four children per slot (64 bytes of entries, one
 * cache line) halve the depth of a binary heap, which is what a pop costs.
 *
 * The order is strict and total (no NaN keys, distinct ids), so the best of
 * four children is found by a tournament of three comparisons, and a pop moves
 * the hole left at the top down to the bottom along the best children before
 * the last entry climbs back (Floyd): the heap ends in exactly the arrangement
 * a top-down sift would give, with one comparison per level fewer.
 *
 * Layer: core, which may call core. Calls: libc and libm only.
 */
#include "heap.h"

#define ARITY 4u

/* ka > kb, or equal keys and ia < ib (keys are never NaN). Without
 * short-circuits: the outcome of a heap comparison is unpredictable, and a
 * mispredicted branch costs more than the few instructions saved. */
static int before(double ka, tclod_id ia, double kb, tclod_id ib) {
    return ((ka >= kb) + ((ka > kb) | (ia < ib))) >> 1; /* both, with one branch at most */
}

static int entry_before(const tclod_heap_entry *a, const tclod_heap_entry *b) {
    return before(a->key, a->id, b->key, b->id);
}

static uint32_t *slot_of(const tclod_heap *h, tclod_id id) {
    return &h->pos[id];
}

/* Moves items[from] to items[to] and records its new slot. */
static void move_entry(tclod_heap *h, uint32_t to, uint32_t from) {
    h->items[to] = h->items[from];
    *slot_of(h, h->items[to].id) = to;
}

static void place(tclod_heap *h, uint32_t slot, const tclod_heap_entry *e) {
    h->items[slot] = *e;
    *slot_of(h, e->id) = slot;
}

/* The first in heap order of four entries from items[first]. */
static uint32_t best_of_four(const tclod_heap_entry *items, uint32_t first) {
    const tclod_heap_entry *c = &items[first];
    uint32_t a = (uint32_t)entry_before(&c[1], &c[0]);
    uint32_t b = 2u + (uint32_t)entry_before(&c[3], &c[2]);
    uint32_t take_b = 0u - (uint32_t)entry_before(&c[b], &c[a]);
    return first + (a ^ ((a ^ b) & take_b));
}

/* The first of the children first .. min(first + ARITY, count) - 1 in heap
 * order; first < count. */
static uint32_t best_child(const tclod_heap_entry *items, uint32_t first, uint32_t count) {
    uint32_t best = first, c;
    if (first + ARITY <= count)
        return best_of_four(items, first);
    for (c = first + 1u; c < count; ++c)
        if (entry_before(&items[c], &items[best]))
            best = c;
    return best;
}

/* Lets e climb from slot towards the top while it comes before its parent. */
static void climb(tclod_heap *h, uint32_t slot, const tclod_heap_entry *e) {
    while (slot > 0) {
        uint32_t up = (slot - 1u) / ARITY;
        if (!entry_before(e, &h->items[up]))
            break;
        move_entry(h, slot, up);
        slot = up;
    }
    place(h, slot, e);
}

static void sift_down(tclod_heap *h, uint32_t slot) {
    tclod_heap_entry e = h->items[slot];
    uint32_t count = h->count;
    for (;;) {
        uint32_t first = ARITY * slot + 1u, best;
        if (first >= count)
            break;
        best = best_child(h->items, first, count);
        if (!entry_before(&h->items[best], &e))
            break;
        move_entry(h, slot, best);
        slot = best;
    }
    place(h, slot, &e);
}

void tclod_heap_append(tclod_heap *h, tclod_id id, double key) {
    tclod_heap_entry *e = &h->items[h->count];
    assert(!tclod_heap_contains(h, id));
    assert(key == key); /* never NaN */
    e->key = key;
    e->id = id;
    e->unused = 0;
    *slot_of(h, id) = h->count++;
}

void tclod_heap_build(tclod_heap *h) {
    uint32_t i = h->count > 1u ? (h->count - 2u) / ARITY + 1u : 0u;
    while (i-- > 0)
        sift_down(h, i);
}

void tclod_heap_push(tclod_heap *h, tclod_id id, double key) {
    tclod_heap_entry e;
    assert(!tclod_heap_contains(h, id));
    assert(key == key); /* never NaN */
    e.key = key;
    e.id = id;
    e.unused = 0;
    climb(h, h->count++, &e);
}

/* Moves the hole at slot down to the bottom along the best children, then
 * lets e climb back from there (Floyd): e must not come before the entry
 * above slot. The next level's candidates (16 entries, four lines) are
 * fetched while a level is compared. */
static void fill_hole(tclod_heap *h, uint32_t slot, const tclod_heap_entry *e) {
    const tclod_heap_entry *items = h->items;
    uint32_t count = h->count, first = ARITY * slot + 1u;
    while (first + ARITY <= count) {
        uint32_t best;
        if (ARITY * first + 1u < count) {
            const tclod_heap_entry *next = &items[ARITY * first + 1u];
            TCLOD_PREFETCH(next);
            TCLOD_PREFETCH(next + 4);
            TCLOD_PREFETCH(next + 8);
            TCLOD_PREFETCH(next + 12);
        }
        best = best_of_four(items, first);
        move_entry(h, slot, best);
        slot = best;
        first = ARITY * slot + 1u;
    }
    if (first < count) {
        uint32_t best = best_child(items, first, count);
        move_entry(h, slot, best);
        slot = best;
    }
    climb(h, slot, e);
}

/* Puts e into the hole at slot, up or down as its key says. */
static void settle(tclod_heap *h, uint32_t slot, const tclod_heap_entry *e) {
    if (slot > 0 && entry_before(e, &h->items[(slot - 1u) / ARITY]))
        climb(h, slot, e);
    else
        fill_hole(h, slot, e);
}

tclod_id tclod_heap_pop(tclod_heap *h) {
    tclod_id top = h->items[0].id;
    tclod_heap_entry e;
    assert(h->count > 0);
    *slot_of(h, top) = TCLOD_NONE;
    if (--h->count == 0)
        return top;
    e = h->items[h->count];
    fill_hole(h, 0, &e);
    return top;
}

void tclod_heap_replace(tclod_heap *h, tclod_id old_id, tclod_id id, double key) {
    uint32_t slot = *slot_of(h, old_id);
    tclod_heap_entry e;
    assert(tclod_heap_contains(h, old_id));
    assert(old_id == id || !tclod_heap_contains(h, id));
    assert(key == key); /* never NaN */
    *slot_of(h, old_id) = TCLOD_NONE;
    e.key = key;
    e.id = id;
    e.unused = 0;
    settle(h, slot, &e);
}

void tclod_heap_remove(tclod_heap *h, tclod_id id) {
    uint32_t slot = *slot_of(h, id);
    tclod_heap_entry e;
    assert(tclod_heap_contains(h, id));
    *slot_of(h, id) = TCLOD_NONE;
    if (slot == --h->count)
        return;
    e = h->items[h->count];
    settle(h, slot, &e);
}

/* Sift-down for the sort: a max-heap in "after" order, so that popping the
 * last element first leaves the array in "before" order. */
static void sort_sift(tclod_id *ids, double *keys, uint32_t n, uint32_t slot) {
    tclod_id id = ids[slot];
    double key = keys[slot];
    for (;;) {
        uint32_t child = 2u * slot + 1u;
        if (child >= n)
            break;
        if (child + 1u < n && before(keys[child], ids[child], keys[child + 1u], ids[child + 1u]))
            child++;
        if (!before(key, id, keys[child], ids[child]))
            break;
        ids[slot] = ids[child];
        keys[slot] = keys[child];
        slot = child;
    }
    ids[slot] = id;
    keys[slot] = key;
}

void tclod_sort_by_key(tclod_id *ids, double *keys, uint32_t n) {
    uint32_t i = n / 2u;
    while (i-- > 0)
        sort_sift(ids, keys, n, i);
    for (i = n; i > 1u; --i) {
        tclod_id id = ids[0];
        double key = keys[0];
        ids[0] = ids[i - 1u];
        keys[0] = keys[i - 1u];
        ids[i - 1u] = id;
        keys[i - 1u] = key;
        sort_sift(ids, keys, i - 1u, 0);
    }
}
