/*
 * Indexed binary max-heap of node ids keyed by double, and an in-place
 * heapsort using the same order.
 *
 * The greedy solver keeps its increments (best Δbenefit/Δcost first) and its
 * decrements (least loss per saved cost first, stored negated) here. Equal
 * keys are ordered by the smaller id, which makes every selection
 * deterministic. pos[] maps an id to its slot so an entry whose node left the
 * cut can be removed in O(log n).
 */
#include "internal.h"

static int before(double ka, tclod_id ia, double kb, tclod_id ib) {
    return ka > kb || (ka == kb && ia < ib);
}

static void place(tclod_heap *h, uint32_t slot, tclod_id id, double key) {
    h->ids[slot] = id;
    h->keys[slot] = key;
    h->pos[id] = slot;
}

static void sift_up(tclod_heap *h, uint32_t slot) {
    tclod_id id = h->ids[slot];
    double key = h->keys[slot];
    while (slot > 0) {
        uint32_t up = (slot - 1u) / 2u;
        if (!before(key, id, h->keys[up], h->ids[up])) break;
        place(h, slot, h->ids[up], h->keys[up]);
        slot = up;
    }
    place(h, slot, id, key);
}

static void sift_down(tclod_heap *h, uint32_t slot) {
    tclod_id id = h->ids[slot];
    double key = h->keys[slot];
    for (;;) {
        uint32_t child = 2u * slot + 1u;
        if (child >= h->count) break;
        if (child + 1u < h->count &&
            before(h->keys[child + 1u], h->ids[child + 1u], h->keys[child], h->ids[child]))
            child++;
        if (!before(h->keys[child], h->ids[child], key, id)) break;
        place(h, slot, h->ids[child], h->keys[child]);
        slot = child;
    }
    place(h, slot, id, key);
}

void tclod_heap_append(tclod_heap *h, tclod_id id, double key) {
    assert(h->pos[id] == TCLOD_NONE);
    assert(key == key); /* never NaN */
    place(h, h->count++, id, key);
}

void tclod_heap_build(tclod_heap *h) {
    uint32_t i = h->count / 2u;
    while (i-- > 0) sift_down(h, i);
}

void tclod_heap_push(tclod_heap *h, tclod_id id, double key) {
    tclod_heap_append(h, id, key);
    sift_up(h, h->count - 1u);
}

tclod_id tclod_heap_pop(tclod_heap *h) {
    tclod_id top = h->ids[0];
    assert(h->count > 0);
    tclod_heap_remove(h, top);
    return top;
}

void tclod_heap_remove(tclod_heap *h, tclod_id id) {
    uint32_t slot = h->pos[id];
    uint32_t last = --h->count;
    assert(slot != TCLOD_NONE);
    h->pos[id] = TCLOD_NONE;
    if (slot == last) return;
    place(h, slot, h->ids[last], h->keys[last]);
    if (slot > 0 && before(h->keys[slot], h->ids[slot], h->keys[(slot - 1u) / 2u],
                           h->ids[(slot - 1u) / 2u]))
        sift_up(h, slot);
    else
        sift_down(h, slot);
}

void tclod_heap_clear(tclod_heap *h) {
    uint32_t i;
    for (i = 0; i < h->count; ++i) h->pos[h->ids[i]] = TCLOD_NONE;
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
