/*
 * Scene, what a solve reads of it (docs/scenes.md): its preparation before a
 * solve (the smooth objects' quadtree, the list of resident nodes), the host's
 * queries, and the residency and sizes the host sets for streaming
 * (docs/streaming.md). The edits that build the tree are in scene.c.
 *
 * Layer: core, which may call core. Calls: core (alloc.c, scene.c).
 */
#include "scene_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* ---- the child index and the quadtree ------------------------------------------------ */

/* Below this depth the quadtree stops splitting: the remaining objects share a
 * cell 2^-40 of the whole extent wide, i.e. the same position in float. */
#define QT_MAX_DEPTH 40u

/* Where a quadtree node lies while the tree is built. */
typedef struct qt_cell {
    double x0, z0, size;
    uint32_t depth;
} qt_cell;

/* Grows the quadtree's arrays to the scene's capacity, all or nothing. */
static tclod_status quadtree_reserve(tclod_scene *s) {
    tclod_allocator *a = &s->alloc;
    quadtree_arrays fresh, gone;
    if (s->smooth_cap <= s->smooth_index_cap)
        return TCLOD_OK;
    fresh.smooth_cap = s->smooth_cap;
    fresh.smooth_order = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.smooth_cap);
    fresh.smooth_pos = (uint32_t *)tclod_mem_alloc(a, sizeof(uint32_t) * fresh.smooth_cap);
    fresh.qt = (tclod_smooth_node *)tclod_mem_alloc(a, sizeof(tclod_smooth_node) * 2u *
                                                           (size_t)fresh.smooth_cap);
    if (!fresh.smooth_order || !fresh.smooth_pos || !fresh.qt) {
        tclod_scene_quadtree_arrays_free(a, &fresh);
        return TCLOD_ERR_NOMEM;
    }
    gone.smooth_cap = s->smooth_index_cap;
    gone.smooth_order = s->smooth_order;
    gone.smooth_pos = s->smooth_pos;
    gone.qt = s->qt;
    tclod_scene_quadtree_arrays_free(a, &gone);
    s->smooth_index_cap = fresh.smooth_cap;
    s->smooth_order = fresh.smooth_order;
    s->smooth_pos = fresh.smooth_pos;
    s->qt = fresh.qt;
    return TCLOD_OK;
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
    /* where the margins vanish (coordinates of denormal size), the float
     * centre's rounding is made up for */
    for (i = 0; i < n; ++i) {
        const float *b = spheres + stride * (ids ? ids[i] : i);
        double dx = (double)b[0] - (double)out[0], dy = (double)b[1] - (double)out[1];
        double dz = (double)b[2] - (double)out[2];
        double r = sqrt(dx * dx + dy * dy + dz * dz) + (double)b[3];
        if ((double)out[3] < r) {
            out[3] = (float)r;
            if ((double)out[3] < r)
                out[3] = nextafterf(out[3], HUGE_VALF);
        }
    }
}

/* The quadtree over the live smooth objects' ground positions, breadth first
 * so that the children of a node are contiguous, then the bounds bottom-up. */
static void build_smooth_quadtree(tclod_scene *s, qt_cell *cells) {
    uint32_t n = 0, i, k;
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
    s->qt_count = 0;
    for (i = 0; i < s->smooth_count; ++i) {
        const float *b = &s->smooth_bounds[4u * i];
        s->smooth_pos[i] = TCLOD_NONE;
        if (!(s->smooth_flags[i] & TCLOD_NODE_LIVE))
            continue;
        s->smooth_order[n++] = i;
        if ((double)b[0] < lo[0])
            lo[0] = (double)b[0];
        if ((double)b[0] > hi[0])
            hi[0] = (double)b[0];
        if ((double)b[2] < lo[1])
            lo[1] = (double)b[2];
        if ((double)b[2] > hi[1])
            hi[1] = (double)b[2];
    }
    if (n == 0)
        return;
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

/* Makes the list of the resident nodes, kept from then on. */
static tclod_status list_resident(tclod_scene *s) {
    tclod_array arrays[2];
    uint32_t n, k = 0;
    arrays[0] = (tclod_array){(void **)&s->res_pos, sizeof(uint32_t), -1};
    arrays[1] = (tclod_array){(void **)&s->res_list, sizeof(tclod_id), -1};
    if (s->node_cap && tclod_arrays_grow(&s->alloc, arrays, 2, 0, s->node_cap) != TCLOD_OK)
        return TCLOD_ERR_NOMEM;
    for (n = 0; n < s->node_count; ++n) {
        s->res_pos[n] = TCLOD_NONE;
        if (tclod_scene_resident(s, n)) {
            s->res_pos[n] = k;
            s->res_list[k++] = n;
        }
    }
    assert(k == s->res_count);
    s->res_listed = 1;
    return TCLOD_OK;
}

tclod_status tclod_scene_prepare(tclod_scene *s) {
    size_t cells_size = 0;
    qt_cell *cells = NULL;
    tclod_status st;
    if (!s)
        return TCLOD_ERR_ARG;
    if (s->res_wanted && !s->res_listed && list_resident(s) != TCLOD_OK)
        return tclod_fail(s->error, TCLOD_ERR_NOMEM, "tclod_scene_prepare",
                          "no memory for the list of resident nodes");
    if (s->order_users > 0 && s->order_version != s->node_version + 1u) {
        if (s->order_cap < s->node_count) { /* made again, not copied */
            tclod_id *order =
                (tclod_id *)tclod_mem_alloc(&s->alloc, sizeof(tclod_id) * s->node_cap);
            if (!order)
                return tclod_fail(s->error, TCLOD_ERR_NOMEM, "tclod_scene_prepare",
                                  "no memory for the node order");
            tclod_mem_free(&s->alloc, s->order, sizeof(tclod_id) * s->order_cap);
            s->order = order;
            s->order_cap = s->node_cap;
        }
        tclod_scene_build_order(s);
    }
    if (s->qt_version == s->smooth_version)
        return TCLOD_OK;
    /* the quadtree's build-time cells, taken first so no failure comes after
     * the arrays have been replaced */
    if (s->smooth_live) {
        cells_size = sizeof(qt_cell) * 2u * (size_t)s->smooth_live;
        cells = (qt_cell *)tclod_mem_alloc(&s->alloc, cells_size);
        if (!cells)
            return tclod_fail(s->error, TCLOD_ERR_NOMEM, "tclod_scene_prepare",
                              "no memory for the smooth objects' quadtree");
    }
    st = quadtree_reserve(s);
    if (st == TCLOD_OK)
        build_smooth_quadtree(s, cells);
    tclod_mem_free(&s->alloc, cells, cells_size);
    if (st != TCLOD_OK)
        return tclod_fail(s->error, st, "tclod_scene_prepare",
                          "no memory for the smooth objects' quadtree");
    s->qt_version = s->smooth_version;
    return TCLOD_OK;
}

tclod_status tclod_scene_smooth_order(tclod_scene *s, const tclod_id **order, uint32_t *count) {
    tclod_status st;
    if (!s)
        return TCLOD_ERR_ARG;
    if (!order || !count)
        return tclod_fail(s->error, TCLOD_ERR_ARG, "tclod_scene_smooth_order",
                          !order ? "order is NULL" : "count is NULL");
    st = tclod_scene_prepare(s);
    if (st != TCLOD_OK)
        return st;
    *order = s->smooth_order;
    *count = s->smooth_live;
    return TCLOD_OK;
}

uint32_t tclod_scene_node_count(const tclod_scene *s) {
    return s ? s->node_count : 0u;
}

uint32_t tclod_scene_smooth_count(const tclod_scene *s) {
    return s ? s->smooth_count : 0u;
}

int tclod_scene_node_live(const tclod_scene *s, tclod_id node) {
    return s && scene_node_live(s, node);
}

int tclod_scene_smooth_live(const tclod_scene *s, tclod_id smooth) {
    return s && scene_smooth_live(s, smooth);
}

tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node) {
    return (s && scene_node_live(s, node)) ? s->up[node] : TCLOD_NONE;
}

const char *tclod_scene_last_error(const tclod_scene *s) {
    return s ? s->error : "";
}

/* ---- streaming ------------------------------------------------------------------ */

/* Points *flags and *bytes at node (smooth object) id's, or fails naming fn
 * when it is not live. */
static tclod_status residency_of(tclod_scene *s, tclod_id id, int smooth, const char *fn,
                                 uint8_t **flags, float **bytes) {
    if (!(smooth ? scene_smooth_live(s, id) : scene_node_live(s, id)))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn,
                          smooth ? "smooth is not a live smooth object"
                                 : "node is not a live node");
    *flags = smooth ? &s->smooth_flags[id] : &s->flags[id];
    *bytes = smooth ? &s->smooth_bytes[id] : &s->bytes[id];
    return TCLOD_OK;
}

static tclod_status set_resident(tclod_scene *s, tclod_id id, int resident, int smooth,
                                 const char *fn) {
    uint8_t *flags = NULL;
    float *bytes = NULL;
    if (!s)
        return TCLOD_ERR_ARG;
    if (residency_of(s, id, smooth, fn, &flags, &bytes) != TCLOD_OK)
        return TCLOD_ERR_ARG;
    if (resident != 0 && resident != 1)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "resident must be 0 or 1");
    if (!smooth && (*flags & TCLOD_NODE_UNEXPANDED))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn,
                          "node is unexpanded: remove it and add what its expansion read in "
                          "its place");
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, fn, HELD);
    if (resident == !(*flags & TCLOD_NODE_ABSENT))
        return TCLOD_OK;
    *flags ^= TCLOD_NODE_ABSENT;
    if (!smooth && (*flags & TCLOD_NODE_EMPTY))
        return TCLOD_OK; /* nothing to load: not counted */
    if (smooth) {
        if (resident)
            s->smooth_absent_count--;
        else
            s->smooth_absent_count++;
        s->resident_bytes += resident ? (double)*bytes : -(double)*bytes;
        s->residency_version++;
    } else {
        if (resident) {
            s->absent_count--;
            tclod_scene_resident_add(s, id);
        } else {
            s->absent_count++;
            tclod_scene_resident_remove(s, id);
        }
    }
    return TCLOD_OK;
}

tclod_status tclod_scene_set_resident(tclod_scene *s, tclod_id node, int resident) {
    return set_resident(s, node, resident, 0, "tclod_scene_set_resident");
}

tclod_status tclod_scene_set_smooth_resident(tclod_scene *s, tclod_id smooth, int resident) {
    return set_resident(s, smooth, resident, 1, "tclod_scene_set_smooth_resident");
}

static tclod_status set_bytes(tclod_scene *s, tclod_id id, double b, int smooth, const char *fn) {
    uint8_t *flags = NULL;
    float *bytes = NULL;
    if (!s)
        return TCLOD_ERR_ARG;
    if (residency_of(s, id, smooth, fn, &flags, &bytes) != TCLOD_OK)
        return TCLOD_ERR_ARG;
    if (!scene_bytes_valid(b))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, BYTES_RULE);
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, fn, HELD);
    if (!(*flags & (TCLOD_NODE_ABSENT | TCLOD_NODE_EMPTY)))
        s->resident_bytes += (double)(float)b - (double)*bytes;
    *bytes = (float)b;
    if (!smooth)
        s->res_wanted |= b > 0.0; /* the next prepare lists the resident nodes */
    s->residency_version++;
    return TCLOD_OK;
}

tclod_status tclod_scene_set_node_bytes(tclod_scene *s, tclod_id node, double bytes) {
    return set_bytes(s, node, bytes, 0, "tclod_scene_set_node_bytes");
}

tclod_status tclod_scene_set_smooth_bytes(tclod_scene *s, tclod_id smooth, double bytes) {
    return set_bytes(s, smooth, bytes, 1, "tclod_scene_set_smooth_bytes");
}

int tclod_scene_node_resident(const tclod_scene *s, tclod_id node) {
    return s && scene_node_live(s, node) && !(s->flags[node] & TCLOD_NODE_ABSENT);
}

int tclod_scene_smooth_resident(const tclod_scene *s, tclod_id smooth) {
    return s && scene_smooth_live(s, smooth) && !(s->smooth_flags[smooth] & TCLOD_NODE_ABSENT);
}

double tclod_scene_node_bytes(const tclod_scene *s, tclod_id node) {
    return s && scene_node_live(s, node) ? (double)s->bytes[node] : 0.0;
}

double tclod_scene_smooth_bytes(const tclod_scene *s, tclod_id smooth) {
    return s && scene_smooth_live(s, smooth) ? (double)s->smooth_bytes[smooth] : 0.0;
}

double tclod_scene_resident_bytes(const tclod_scene *s) {
    return s ? s->resident_bytes : 0.0;
}
