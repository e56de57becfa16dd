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
    if (!out || !tclod_allocator_init(&alloc, a))
        return TCLOD_ERR_ARG;
    s = (tclod_scene *)tclod_mem_alloc(&alloc, sizeof *s);
    if (!s)
        return TCLOD_ERR_NOMEM;
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

/* The arrays of the child index and the smooth quadtree, allocated together
 * so that a failure changes nothing. */
typedef struct index_arrays {
    uint32_t node_cap, smooth_cap;
    uint32_t *child_first;
    tclod_id *children, *roots;
    tclod_id *smooth_order;
    uint32_t *smooth_pos;
    tclod_smooth_node *qt;
} index_arrays;

static void index_arrays_free(const tclod_allocator *a, index_arrays *x) {
    tclod_mem_free(a, x->child_first, sizeof(uint32_t) * (x->node_cap + 1u));
    tclod_mem_free(a, x->children, sizeof(tclod_id) * x->node_cap);
    tclod_mem_free(a, x->roots, sizeof(tclod_id) * x->node_cap);
    tclod_mem_free(a, x->smooth_order, sizeof(tclod_id) * x->smooth_cap);
    tclod_mem_free(a, x->smooth_pos, sizeof(uint32_t) * x->smooth_cap);
    tclod_mem_free(a, x->qt, sizeof(tclod_smooth_node) * 2u * (size_t)x->smooth_cap);
}

void tclod_scene_destroy(tclod_scene *s) {
    tclod_array arrays[2];
    tclod_allocator alloc;
    if (!s)
        return;
    alloc = s->alloc;
    tclod_arrays_free(&alloc, arrays, node_arrays(s, arrays), s->node_cap);
    {
        index_arrays x = {s->index_cap, s->smooth_index_cap, s->child_first, s->children,
                          s->roots,     s->smooth_order,     s->smooth_pos,  s->qt};
        index_arrays_free(&alloc, &x);
    }
    if (s->smooth_cap)
        tclod_mem_free(&alloc, s->smooth_bounds, 4 * sizeof(float) * s->smooth_cap);
    tclod_mem_free(&alloc, s, sizeof *s);
}

tclod_status tclod_scene_add_node(tclod_scene *s, tclod_id parent, const float bounds[4],
                                  tclod_id *out_id) {
    tclod_id id;
    if (!s || !out_id || (bounds && !bounds_valid(bounds)))
        return TCLOD_ERR_ARG;
    if (parent != TCLOD_NONE && parent >= s->node_count)
        return TCLOD_ERR_HIERARCHY;
    if (s->node_count == UINT32_MAX - 1u)
        return TCLOD_ERR_NOMEM; /* ids exhausted */
    if (s->node_count == s->node_cap) {
        tclod_array arrays[2];
        size_t n = node_arrays(s, arrays);
        uint32_t cap = grown_capacity(s->node_cap);
        tclod_status st = tclod_arrays_grow(&s->alloc, arrays, n, s->node_cap, cap);
        if (st != TCLOD_OK)
            return st;
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
    if (!s || !out_id || !bounds || !bounds_valid(bounds))
        return TCLOD_ERR_ARG;
    if (s->smooth_count == UINT32_MAX - 1u)
        return TCLOD_ERR_NOMEM;
    if (s->smooth_count == s->smooth_cap) {
        tclod_array arr = {(void **)&s->smooth_bounds, 4 * sizeof(float), -1};
        uint32_t cap = grown_capacity(s->smooth_cap);
        tclod_status st = tclod_arrays_grow(&s->alloc, &arr, 1, s->smooth_cap, cap);
        if (st != TCLOD_OK)
            return st;
        s->smooth_cap = cap;
    }
    id = s->smooth_count++;
    memcpy(&s->smooth_bounds[4u * id], bounds, 4 * sizeof(float));
    s->version++;
    *out_id = id;
    return TCLOD_OK;
}

/* Below this depth the quadtree stops splitting: the remaining objects share a
 * cell 2^-40 of the whole extent wide, i.e. the same position in float. */
#define QT_MAX_DEPTH 40u

/* Where a quadtree node lies while the tree is built. */
typedef struct qt_cell {
    double x0, z0, size;
    uint32_t depth;
} qt_cell;

/* Grows the index arrays to the scene's capacities, all or nothing. */
static tclod_status index_reserve(tclod_scene *s) {
    tclod_allocator *a = &s->alloc;
    index_arrays old = {s->index_cap, s->smooth_index_cap, s->child_first, s->children,
                        s->roots,     s->smooth_order,     s->smooth_pos,  s->qt};
    index_arrays fresh = {0, 0, NULL, NULL, NULL, NULL, NULL, NULL};
    int nodes = s->node_count > s->index_cap || !s->child_first;
    int smooth = s->smooth_count > s->smooth_index_cap;
    if (!nodes && !smooth)
        return TCLOD_OK;
    if (nodes) {
        fresh.node_cap = s->node_cap;
        /* child_first needs one entry more than there are nodes */
        fresh.child_first =
            (uint32_t *)tclod_mem_alloc(a, sizeof(uint32_t) * (fresh.node_cap + 1u));
        fresh.children = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.node_cap);
        fresh.roots = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.node_cap);
        if (!fresh.child_first || !fresh.children || !fresh.roots) {
            index_arrays_free(a, &fresh);
            return TCLOD_ERR_NOMEM;
        }
    }
    if (smooth) {
        fresh.smooth_cap = s->smooth_cap;
        fresh.smooth_order = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.smooth_cap);
        fresh.smooth_pos = (uint32_t *)tclod_mem_alloc(a, sizeof(uint32_t) * fresh.smooth_cap);
        fresh.qt = (tclod_smooth_node *)tclod_mem_alloc(a, sizeof(tclod_smooth_node) * 2u *
                                                               (size_t)fresh.smooth_cap);
        if (!fresh.smooth_order || !fresh.smooth_pos || !fresh.qt) {
            index_arrays_free(a, &fresh);
            return TCLOD_ERR_NOMEM;
        }
    }
    if (nodes) {
        index_arrays gone = {old.node_cap, 0,   old.child_first, old.children, old.roots, NULL,
                             NULL,         NULL};
        index_arrays_free(a, &gone);
        s->index_cap = fresh.node_cap;
        s->child_first = fresh.child_first;
        s->children = fresh.children;
        s->roots = fresh.roots;
    }
    if (smooth) {
        index_arrays gone = {0,    old.smooth_cap,   NULL,           NULL,
                             NULL, old.smooth_order, old.smooth_pos, old.qt};
        index_arrays_free(a, &gone);
        s->smooth_index_cap = fresh.smooth_cap;
        s->smooth_order = fresh.smooth_order;
        s->smooth_pos = fresh.smooth_pos;
        s->qt = fresh.qt;
    }
    return TCLOD_OK;
}

/* Counting sort of the nodes by parent; id order within a parent. */
static void build_child_index(tclod_scene *s) {
    uint32_t n = s->node_count, i, roots = 0;
    memset(s->child_first, 0, sizeof(uint32_t) * (n + 1u));
    for (i = 0; i < n; ++i) {
        tclod_id p = s->parent[i];
        if (p == TCLOD_NONE)
            s->roots[roots++] = i;
        else
            s->child_first[p + 1u]++;
    }
    for (i = 0; i < n; ++i)
        s->child_first[i + 1u] += s->child_first[i];
    for (i = 0; i < n; ++i) {
        tclod_id p = s->parent[i];
        if (p != TCLOD_NONE)
            s->children[s->child_first[p]++] = i;
    }
    /* child_first[p] now holds the end of p's range: shift back by one slot */
    for (i = n; i > 0; --i)
        s->child_first[i] = s->child_first[i - 1u];
    s->child_first[0] = 0;
    s->root_count = roots;
}

/* Moves the objects of order[begin, end) whose coordinate (0 = x, 2 = z) is
 * below split to the front, keeping nothing else; returns where the rest
 * starts. */
static uint32_t partition(const tclod_scene *s, uint32_t begin, uint32_t end, int axis,
                          double split) {
    tclod_id *order = s->smooth_order;
    while (begin < end) {
        if ((double)s->smooth_bounds[4u * order[begin] + (uint32_t)axis] < split) {
            ++begin;
        } else {
            tclod_id t = order[begin];
            order[begin] = order[--end];
            order[end] = t;
        }
    }
    return begin;
}

/* Splits node k's objects into the quadrants of its cell, descending into the
 * only non-empty quadrant until the objects separate, and appends a child node
 * per non-empty quadrant. cells[] holds every node's cell. */
static void qt_split(tclod_scene *s, qt_cell *cells, uint32_t k) {
    tclod_smooth_node *node = &s->qt[k];
    qt_cell cell = cells[k];
    uint32_t bound[5], q, nonempty;
    for (;;) {
        double half = 0.5 * cell.size, mx = cell.x0 + half, mz = cell.z0 + half;
        if (cell.depth >= QT_MAX_DEPTH || !(half > 0.0))
            return; /* a leaf of several */
        bound[0] = node->first;
        bound[4] = node->first + node->count;
        bound[2] = partition(s, bound[0], bound[4], 2, mz);
        bound[1] = partition(s, bound[0], bound[2], 0, mx);
        bound[3] = partition(s, bound[2], bound[4], 0, mx);
        nonempty = 0;
        for (q = 0; q < 4; ++q)
            nonempty += bound[q + 1u] > bound[q];
        cell.size = half;
        cell.depth++;
        if (nonempty > 1)
            break;
        for (q = 0; q < 4; ++q)
            if (bound[q + 1u] > bound[q]) {
                cell.x0 += (q & 1u) ? half : 0.0;
                cell.z0 += (q & 2u) ? half : 0.0;
            }
    }
    node->child = s->qt_count;
    node->child_count = nonempty;
    for (q = 0; q < 4; ++q) {
        tclod_smooth_node *c;
        if (bound[q + 1u] == bound[q])
            continue;
        c = &s->qt[s->qt_count];
        c->first = bound[q];
        c->count = bound[q + 1u] - bound[q];
        c->child = 0;
        c->child_count = 0;
        cells[s->qt_count].x0 = cell.x0 + ((q & 1u) ? cell.size : 0.0);
        cells[s->qt_count].z0 = cell.z0 + ((q & 2u) ? cell.size : 0.0);
        cells[s->qt_count].size = cell.size;
        cells[s->qt_count].depth = cell.depth;
        s->qt_count++;
    }
}

/* Sphere around a set of spheres (4 floats each, `stride` floats apart): the
 * centre of their bounding box, the radius reaching the farthest one, rounded
 * outwards so the float result still encloses them. */
static void enclose(const float *spheres, size_t stride, uint32_t n, const tclod_id *ids,
                    float out[4]) {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double c[3], radius = 0.0;
    uint32_t i;
    int k;
    for (i = 0; i < n; ++i) {
        const float *b = spheres + stride * (ids ? ids[i] : i);
        for (k = 0; k < 3; ++k) {
            double l = (double)b[k] - (double)b[3], h = (double)b[k] + (double)b[3];
            if (l < lo[k])
                lo[k] = l;
            if (h > hi[k])
                hi[k] = h;
        }
    }
    for (k = 0; k < 3; ++k)
        c[k] = 0.5 * (lo[k] + hi[k]);
    for (i = 0; i < n; ++i) {
        const float *b = spheres + stride * (ids ? ids[i] : i);
        double dx = (double)b[0] - c[0], dy = (double)b[1] - c[1], dz = (double)b[2] - c[2];
        double r = sqrt(dx * dx + dy * dy + dz * dz) + (double)b[3];
        if (r > radius)
            radius = r;
    }
    for (k = 0; k < 3; ++k)
        out[k] = (float)c[k];
    out[3] = (float)(radius * (1.0 + 1e-6) + 1e-6 * (fabs(c[0]) + fabs(c[1]) + fabs(c[2])));
}

/* The quadtree over the smooth objects' ground positions, breadth first so
 * that the children of a node are contiguous, then the bounds bottom-up. */
static void build_smooth_quadtree(tclod_scene *s, qt_cell *cells) {
    uint32_t n = s->smooth_count, i, k;
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
    s->qt_count = 0;
    if (n == 0)
        return;
    for (i = 0; i < n; ++i) {
        const float *b = &s->smooth_bounds[4u * i];
        s->smooth_order[i] = i;
        if ((double)b[0] < lo[0])
            lo[0] = (double)b[0];
        if ((double)b[0] > hi[0])
            hi[0] = (double)b[0];
        if ((double)b[2] < lo[1])
            lo[1] = (double)b[2];
        if ((double)b[2] > hi[1])
            hi[1] = (double)b[2];
    }
    s->qt[0].first = 0;
    s->qt[0].count = n;
    s->qt[0].child = s->qt[0].child_count = 0;
    cells[0].x0 = lo[0];
    cells[0].z0 = lo[1];
    /* a little wider than the extent, so the far edge is inside a cell */
    cells[0].size = (hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1]) * 1.0000001;
    cells[0].depth = 0;
    s->qt_count = 1;
    for (k = 0; k < s->qt_count; ++k)
        if (s->qt[k].count > 1)
            qt_split(s, cells, k);
    for (i = 0; i < n; ++i)
        s->smooth_pos[s->smooth_order[i]] = i;
    /* children follow their parents, so a backward pass sees children first */
    for (k = s->qt_count; k-- > 0;) {
        tclod_smooth_node *node = &s->qt[k];
        if (node->child_count == 0)
            enclose(s->smooth_bounds, 4, node->count, s->smooth_order + node->first, node->bounds);
        else
            enclose(s->qt[node->child].bounds, sizeof(tclod_smooth_node) / sizeof(float),
                    node->child_count, NULL, node->bounds);
    }
}

tclod_status tclod_scene_prepare(tclod_scene *s) {
    size_t cells_size;
    qt_cell *cells = NULL;
    tclod_status st;
    if (!s)
        return TCLOD_ERR_ARG;
    if (s->index_version == s->version)
        return TCLOD_OK;
    /* the quadtree's build-time cells, taken first so no failure comes after
     * the index arrays have been replaced */
    cells_size = sizeof(qt_cell) * 2u * (size_t)s->smooth_count;
    if (s->smooth_count) {
        cells = (qt_cell *)tclod_mem_alloc(&s->alloc, cells_size);
        if (!cells)
            return TCLOD_ERR_NOMEM;
    }
    st = index_reserve(s);
    if (st == TCLOD_OK) {
        build_smooth_quadtree(s, cells);
        build_child_index(s);
    }
    tclod_mem_free(&s->alloc, cells, cells_size);
    if (st != TCLOD_OK)
        return st;
    s->index_version = s->version;
    return TCLOD_OK;
}

tclod_status tclod_scene_smooth_order(tclod_scene *s, const tclod_id **order, uint32_t *count) {
    tclod_status st;
    if (!s || !order || !count)
        return TCLOD_ERR_ARG;
    st = tclod_scene_prepare(s);
    if (st != TCLOD_OK)
        return st;
    *order = s->smooth_order;
    *count = s->smooth_count;
    return TCLOD_OK;
}

uint32_t tclod_scene_node_count(const tclod_scene *s) {
    return s ? s->node_count : 0u;
}

uint32_t tclod_scene_smooth_count(const tclod_scene *s) {
    return s ? s->smooth_count : 0u;
}

tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node) {
    return (s && node < s->node_count) ? s->parent[node] : TCLOD_NONE;
}
