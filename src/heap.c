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
 */
#include "internal.h"

#define ARITY 4u

static int before(double ka, tclod_id ia, double kb, tclod_id ib) {
    return ka > kb || (ka == kb && ia < ib);
}

static int entry_before(const tclod_heap_entry *a, const tclod_heap_entry *b) {
    return before(a->key, a->id, b->key, b->id);
}

static uint32_t *slot_of(const tclod_heap *h, tclod_id id) {
    return &h->pos[(size_t)id * h->pos_stride];
}

static void sift_up(tclod_heap *h, uint32_t slot) {
    tclod_heap_entry e = h->items[slot];
    while (slot > 0) {
        uint32_t up = (slot - 1u) / ARITY;
        if (!entry_before(&e, &h->items[up])) break;
        h->items[slot] = h->items[up];
        *slot_of(h, h->items[slot].id) = slot;
        slot = up;
    }
    h->items[slot] = e;
    *slot_of(h, e.id) = slot;
}

static void sift_down(tclod_heap *h, uint32_t slot) {
    tclod_heap_entry e = h->items[slot];
    for (;;) {
        uint32_t first = ARITY * slot + 1u, best, c, end;
        if (first >= h->count) break;
        end = first + ARITY < h->count ? first + ARITY : h->count;
        best = first;
        for (c = first + 1u; c < end; ++c)
            if (entry_before(&h->items[c], &h->items[best])) best = c;
        if (!entry_before(&h->items[best], &e)) break;
        h->items[slot] = h->items[best];
        *slot_of(h, h->items[slot].id) = slot;
        slot = best;
    }
    h->items[slot] = e;
    *slot_of(h, e.id) = slot;
}

void tclod_heap_append(tclod_heap *h, tclod_id id, double key) {
    tclod_heap_entry *e = &h->items[h->count];
    assert(*slot_of(h, id) == TCLOD_NONE);
    assert(key == key); /* never NaN */
    e->key = key;
    e->id = id;
    e->unused = 0;
    *slot_of(h, id) = h->count++;
}

void tclod_heap_build(tclod_heap *h) {
    uint32_t i = h->count > 1u ? (h->count - 2u) / ARITY + 1u : 0u;
    while (i-- > 0) sift_down(h, i);
}

void tclod_heap_push(tclod_heap *h, tclod_id id, double key) {
    tclod_heap_append(h, id, key);
    sift_up(h, h->count - 1u);
}

tclod_id tclod_heap_pop(tclod_heap *h) {
    tclod_id top = h->items[0].id;
    assert(h->count > 0);
    tclod_heap_remove(h, top);
    return top;
}

void tclod_heap_remove(tclod_heap *h, tclod_id id) {
    uint32_t slot = *slot_of(h, id);
    uint32_t last = --h->count;
    assert(slot != TCLOD_NONE);
    *slot_of(h, id) = TCLOD_NONE;
    if (slot == last) return;
    h->items[slot] = h->items[last];
    *slot_of(h, h->items[slot].id) = slot;
    if (slot > 0 && entry_before(&h->items[slot], &h->items[(slot - 1u) / ARITY]))
        sift_up(h, slot);
    else
        sift_down(h, slot);
}

void tclod_heap_clear(tclod_heap *h) {
    uint32_t i;
    for (i = 0; i < h->count; ++i) *slot_of(h, h->items[i].id) = TCLOD_NONE;
    h->count = 0;
}

/* Sift-down for the sort: a max-heap in "after" order, so that popping the
 * last element first leaves the array in "before" order. */
static void sort_sift(tclod_id *ids, double *keys, uint32_t n, uint32_t slot) {
    tclod_id id = ids[slot];
    double key = keys[slot];
    for (;;) {
        uint32_t child = 2u * slot + 1u;
        if (child >= n) break;
        if (child + 1u < n && before(keys[child], ids[child], keys[child + 1u], ids[child + 1u]))
            child++;
        if (!before(key, id, keys[child], ids[child])) break;
        ids[slot] = ids[child];
        keys[slot] = keys[child];
        slot = child;
    }
    ids[slot] = id;
    keys[slot] = key;
}

void tclod_sort_by_key(tclod_id *ids, double *keys, uint32_t n) {
    uint32_t i = n / 2u;
    while (i-- > 0) sort_sift(ids, keys, n, i);
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
