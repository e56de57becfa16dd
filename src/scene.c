/*
 * Scene: the structure of the LOD hierarchies and the smooth objects.
 *
 * Nodes are stored as structure-of-arrays indexed by id. A node's parent must
 * exist before it, so parent < id always: cycles cannot be expressed and id
 * order is a topological order. Children are kept contiguous in a child index
 * (counting sort over the parent array, ascending ids per parent) that is
 * rebuilt lazily, once per batch of changes, by the first selector that needs
 * it or by tclod_scene_prepare.
 */
#include "internal.h"

#include <math.h>
#include <string.h>

static int bounds_valid(const float b[4]) {
    return isfinite(b[0]) && isfinite(b[1]) && isfinite(b[2]) && isfinite(b[3]) && b[3] >= 0.0f;
}

static uint32_t grown_capacity(uint32_t cap) {
    return cap < 64u ? 64u : (cap > UINT32_MAX / 2u ? UINT32_MAX - 1u : cap * 2u);
}

tclod_status tclod_scene_create(const tclod_allocator *a, tclod_scene **out) {
    tclod_allocator alloc;
    tclod_scene *s;
    if (!out || !tclod_allocator_init(&alloc, a)) return TCLOD_ERR_ARG;
    s = (tclod_scene *)tclod_mem_alloc(&alloc, sizeof *s);
    if (!s) return TCLOD_ERR_NOMEM;
    memset(s, 0, sizeof *s);
    s->alloc = alloc;
    s->version = 1;
    *out = s;
    return TCLOD_OK;
}

static size_t node_arrays(tclod_scene *s, tclod_array out[2]) {
    out[0] = (tclod_array){(void **)&s->parent, sizeof(tclod_id), -1};
    out[1] = (tclod_array){(void **)&s->bounds, 4 * sizeof(float), -1};
    return 2;
}

void tclod_scene_destroy(tclod_scene *s) {
    tclod_array arrays[2];
    tclod_allocator alloc;
    if (!s) return;
    alloc = s->alloc;
    tclod_arrays_free(&alloc, arrays, node_arrays(s, arrays), s->node_cap);
    /* child_first holds one entry more than the other index arrays */
    tclod_mem_free(&alloc, s->child_first, sizeof(uint32_t) * (s->index_cap + 1u));
    tclod_mem_free(&alloc, s->children, sizeof(tclod_id) * s->index_cap);
    tclod_mem_free(&alloc, s->roots, sizeof(tclod_id) * s->index_cap);
    if (s->smooth_cap) tclod_mem_free(&alloc, s->smooth_bounds, 4 * sizeof(float) * s->smooth_cap);
    tclod_mem_free(&alloc, s, sizeof *s);
}

tclod_status tclod_scene_add_node(tclod_scene *s, tclod_id parent, const float bounds[4],
                                  tclod_id *out_id) {
    tclod_id id;
    if (!s || !out_id || (bounds && !bounds_valid(bounds))) return TCLOD_ERR_ARG;
    if (parent != TCLOD_NONE && parent >= s->node_count) return TCLOD_ERR_HIERARCHY;
    if (s->node_count == UINT32_MAX - 1u) return TCLOD_ERR_NOMEM; /* ids exhausted */
    if (s->node_count == s->node_cap) {
        tclod_array arrays[2];
        size_t n = node_arrays(s, arrays);
        uint32_t cap = grown_capacity(s->node_cap);
        tclod_status st = tclod_arrays_grow(&s->alloc, arrays, n, s->node_cap, cap);
        if (st != TCLOD_OK) return st;
        s->node_cap = cap;
    }
    id = s->node_count++;
    s->parent[id] = parent;
    if (bounds) {
        memcpy(&s->bounds[4u * id], bounds, 4 * sizeof(float));
    } else {
        s->bounds[4u * id] = s->bounds[4u * id + 1] = s->bounds[4u * id + 2] = 0.0f;
        s->bounds[4u * id + 3] = -1.0f;
    }
    s->version++;
    *out_id = id;
    return TCLOD_OK;
}

tclod_status tclod_scene_add_smooth(tclod_scene *s, const float bounds[4], tclod_id *out_id) {
    tclod_id id;
    if (!s || !out_id || !bounds || !bounds_valid(bounds)) return TCLOD_ERR_ARG;
    if (s->smooth_count == UINT32_MAX - 1u) return TCLOD_ERR_NOMEM;
    if (s->smooth_count == s->smooth_cap) {
        tclod_array arr = {(void **)&s->smooth_bounds, 4 * sizeof(float), -1};
        uint32_t cap = grown_capacity(s->smooth_cap);
        tclod_status st = tclod_arrays_grow(&s->alloc, &arr, 1, s->smooth_cap, cap);
        if (st != TCLOD_OK) return st;
        s->smooth_cap = cap;
    }
    id = s->smooth_count++;
    memcpy(&s->smooth_bounds[4u * id], bounds, 4 * sizeof(float));
    s->version++;
    *out_id = id;
    return TCLOD_OK;
}

tclod_status tclod_scene_prepare(tclod_scene *s) {
    uint32_t n, i, roots = 0;
    if (!s) return TCLOD_ERR_ARG;
    if (s->index_version == s->version) return TCLOD_OK;
    n = s->node_count;
    if (n > s->index_cap || !s->child_first) {
        /* child_first needs n + 1 entries: grow it by one extra element */
        tclod_allocator *a = &s->alloc;
        uint32_t cap = s->node_cap;
        uint32_t *first = (uint32_t *)tclod_mem_alloc(a, sizeof(uint32_t) * (cap + 1u));
        tclod_id *children = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * cap);
        tclod_id *root_ids = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * cap);
        if (!first || !children || !root_ids) {
            tclod_mem_free(a, first, sizeof(uint32_t) * (cap + 1u));
            tclod_mem_free(a, children, sizeof(tclod_id) * cap);
            tclod_mem_free(a, root_ids, sizeof(tclod_id) * cap);
            return TCLOD_ERR_NOMEM;
        }
        tclod_mem_free(a, s->child_first, sizeof(uint32_t) * (s->index_cap + 1u));
        tclod_mem_free(a, s->children, sizeof(tclod_id) * s->index_cap);
        tclod_mem_free(a, s->roots, sizeof(tclod_id) * s->index_cap);
        s->child_first = first;
        s->children = children;
        s->roots = root_ids;
        s->index_cap = cap;
    }
    /* counting sort of the nodes by parent; id order within a parent */
    memset(s->child_first, 0, sizeof(uint32_t) * (n + 1u));
    for (i = 0; i < n; ++i) {
        tclod_id p = s->parent[i];
        if (p == TCLOD_NONE)
            s->roots[roots++] = i;
        else
            s->child_first[p + 1u]++;
    }
    for (i = 0; i < n; ++i) s->child_first[i + 1u] += s->child_first[i];
    for (i = 0; i < n; ++i) {
        tclod_id p = s->parent[i];
        if (p != TCLOD_NONE) s->children[s->child_first[p]++] = i;
    }
    /* child_first[p] now holds the end of p's range: shift back by one slot */
    for (i = n; i > 0; --i) s->child_first[i] = s->child_first[i - 1u];
    s->child_first[0] = 0;
    s->root_count = roots;
    s->index_version = s->version;
    return TCLOD_OK;
}

uint32_t tclod_scene_node_count(const tclod_scene *s) { return s ? s->node_count : 0u; }

uint32_t tclod_scene_smooth_count(const tclod_scene *s) { return s ? s->smooth_count : 0u; }

tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node) {
    return (s && node < s->node_count) ? s->parent[node] : TCLOD_NONE;
}
