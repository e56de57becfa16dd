/*
 * Scene: the structure of the LOD hierarchies and the smooth objects, and
 * the host's edits to it (docs/scenes.md).
 *
 * Nodes are stored as structure-of-arrays indexed by id, with the host's tree
 * as parent pointers and sibling lists, so that a subtree is removed in time
 * proportional to its size without any stack. The solvers see another tree,
 * the child index: the live nodes that draw, children contiguous per parent,
 * empty nodes passed over and, below every additive node with children, its
 * "self leaf", a node of its own that stands for the additive node's own
 * drawing among its children. With it every solver's replace-only increment
 * (children in place of their parent) is exact for additive refinement too:
 * refining an additive node draws its self leaf (the same benefit and cost)
 * and its children. The index is rebuilt lazily (a counting sort, linear in
 * the scene) by the first selector that needs it after nodes were added or
 * removed, or by tclod_scene_prepare. Moves change no index.
 *
 * Ids are dense and reused, but a removed id is given again only once every
 * user of the scene (selector, scheduler) has begun a solve since the removal:
 * until then it waits in the retired ring, tagged with the removal's epoch.
 * No result a host can still read then names the old node, so a host cannot
 * mistake it for the new one.
 */
#include "internal.h"

#include <math.h>
#include <string.h>

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
    s->version = s->node_version = s->smooth_version = 1;
    s->epoch = 1;
    *out = s;
    return TCLOD_OK;
}

/* The per-node arrays, grown together. The index's parent array lives here
 * too: it is written for every indexed node when the index is built. */
static size_t node_arrays(tclod_scene *s, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&s->up, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->first_child, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->next_sibling, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->prev_sibling, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->self, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->bounds, sizeof(tclod_node_bounds), -1};
    out[n++] = (tclod_array){(void **)&s->flags, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&s->free_ids, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->retired.id, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->retired.epoch, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&s->parent, sizeof(tclod_id), -1};
    return n;
}

static size_t smooth_arrays(tclod_scene *s, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&s->smooth_bounds, 4 * sizeof(float), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_flags, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&s->smooth_free, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_retired.id, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_retired.epoch, sizeof(uint32_t), -1};
    return n;
}

static size_t box_arrays(tclod_scene *s, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&s->boxes, sizeof(tclod_box), -1};
    out[n++] = (tclod_array){(void **)&s->box_free, sizeof(uint32_t), -1};
    return n;
}

/* The arrays of the child index and the smooth quadtree, allocated together
 * so that a failure changes nothing. */
typedef struct index_arrays {
    uint32_t node_cap, smooth_cap;
    uint32_t *child_first;
    tclod_id *children, *roots, *order;
    tclod_id *smooth_order;
    uint32_t *smooth_pos;
    tclod_smooth_node *qt;
} index_arrays;

static void index_arrays_free(const tclod_allocator *a, index_arrays *x) {
    tclod_mem_free(a, x->child_first, sizeof(uint32_t) * (x->node_cap + 1u));
    tclod_mem_free(a, x->children, sizeof(tclod_id) * x->node_cap);
    tclod_mem_free(a, x->roots, sizeof(tclod_id) * x->node_cap);
    tclod_mem_free(a, x->order, sizeof(tclod_id) * x->node_cap);
    tclod_mem_free(a, x->smooth_order, sizeof(tclod_id) * x->smooth_cap);
    tclod_mem_free(a, x->smooth_pos, sizeof(uint32_t) * x->smooth_cap);
    tclod_mem_free(a, x->qt, sizeof(tclod_smooth_node) * 2u * (size_t)x->smooth_cap);
}

static index_arrays current_index(const tclod_scene *s) {
    index_arrays x;
    x.node_cap = s->index_cap;
    x.smooth_cap = s->smooth_index_cap;
    x.child_first = s->child_first;
    x.children = s->children;
    x.roots = s->roots;
    x.order = s->order;
    x.smooth_order = s->smooth_order;
    x.smooth_pos = s->smooth_pos;
    x.qt = s->qt;
    return x;
}

void tclod_scene_destroy(tclod_scene *s) {
    tclod_array arrays[TCLOD_MAX_ARRAYS];
    tclod_allocator alloc;
    index_arrays x;
    if (!s)
        return;
    alloc = s->alloc;
    tclod_arrays_free(&alloc, arrays, node_arrays(s, arrays), s->node_cap);
    tclod_arrays_free(&alloc, arrays, smooth_arrays(s, arrays), s->smooth_cap);
    tclod_arrays_free(&alloc, arrays, box_arrays(s, arrays), s->box_cap);
    x = current_index(s);
    index_arrays_free(&alloc, &x);
    tclod_mem_free(&alloc, s->users, sizeof(tclod_scene_user *) * s->user_cap);
    tclod_mem_free(&alloc, s, sizeof *s);
}

/* ---- users ------------------------------------------------------------------------ */

tclod_status tclod_scene_attach(tclod_scene *s, tclod_scene_user *u) {
    if (s->user_count == s->user_cap) {
        uint32_t cap = s->user_cap < 4u ? 4u : s->user_cap * 2u;
        tclod_scene_user **users =
            (tclod_scene_user **)tclod_mem_alloc(&s->alloc, sizeof(tclod_scene_user *) * cap);
        if (!users)
            return TCLOD_ERR_NOMEM;
        if (s->user_count)
            memcpy(users, s->users, sizeof(tclod_scene_user *) * s->user_count);
        tclod_mem_free(&s->alloc, s->users, sizeof(tclod_scene_user *) * s->user_cap);
        s->users = users;
        s->user_cap = cap;
    }
    u->synced = UINT32_MAX; /* no result yet: it names no node */
    u->busy = 0;
    u->holding = 0;
    s->users[s->user_count++] = u;
    return TCLOD_OK;
}

void tclod_scene_detach(tclod_scene *s, tclod_scene_user *u) {
    uint32_t i;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i] == u) {
            s->users[i] = s->users[--s->user_count];
            return;
        }
}

/* Whether a user holds the scene: a solve begun, or a call under way (the
 * host's callbacks run inside one). Changes are refused then. */
static int held(const tclod_scene *s) {
    uint32_t i;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i]->busy || s->users[i]->holding)
            return 1;
    return 0;
}

/* The oldest epoch a user's results may still come from: ids removed at it
 * or later may still be named by a result a host can read. */
static uint32_t oldest_synced(const tclod_scene *s) {
    uint32_t i, oldest = s->epoch;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i]->synced < oldest)
            oldest = s->users[i]->synced;
    return oldest;
}

/* ---- ids ---------------------------------------------------------------------------- */

static void retire(tclod_retired *r, uint32_t cap, tclod_id id, uint32_t epoch) {
    uint32_t at = r->head + r->count;
    if (at >= cap)
        at -= cap;
    assert(r->count < cap);
    r->id[at] = id;
    r->epoch[at] = epoch;
    r->count++;
}

/* Moves the retired ids whose removal every user has solved since onto the
 * free stack. */
static void release(const tclod_scene *s, tclod_retired *r, uint32_t cap, tclod_id *free_ids,
                    uint32_t *free_count) {
    uint32_t oldest;
    if (r->count == 0)
        return;
    oldest = oldest_synced(s);
    while (r->count > 0 && r->epoch[r->head] <= oldest) {
        free_ids[(*free_count)++] = r->id[r->head];
        r->head = r->head + 1u == cap ? 0u : r->head + 1u;
        r->count--;
    }
}

/* Copies a ring of capacity old_cap into one of capacity new_cap, whose
 * arrays tclod_arrays_grow has copied element by element: the part that
 * wrapped moves to the end of the old capacity. */
static void unwrap(tclod_retired *r, uint32_t old_cap) {
    uint32_t i;
    if (r->head + r->count <= old_cap)
        return;
    for (i = 0; i < r->head + r->count - old_cap; ++i) {
        r->id[old_cap + i] = r->id[i];
        r->epoch[old_cap + i] = r->epoch[i];
    }
}

/* Room for `more` new node ids, all or nothing. */
static tclod_status reserve_nodes(tclod_scene *s, uint32_t more) {
    tclod_array arrays[TCLOD_MAX_ARRAYS];
    size_t n;
    uint32_t cap = s->node_cap;
    tclod_status st;
    release(s, &s->retired, s->node_cap, s->free_ids, &s->free_count);
    if (s->free_count >= more)
        return TCLOD_OK;
    more -= s->free_count;
    if (s->node_count > UINT32_MAX - 2u - more)
        return TCLOD_ERR_NOMEM; /* ids exhausted */
    if (s->node_count + more <= s->node_cap)
        return TCLOD_OK;
    while (cap < s->node_count + more)
        cap = grown_capacity(cap);
    n = node_arrays(s, arrays);
    st = tclod_arrays_grow(&s->alloc, arrays, n, s->node_cap, cap);
    if (st != TCLOD_OK)
        return st;
    unwrap(&s->retired, s->node_cap);
    s->node_cap = cap;
    return TCLOD_OK;
}

/* A new node id (room reserved). */
static tclod_id take_node_id(tclod_scene *s) {
    if (s->free_count > 0)
        return s->free_ids[--s->free_count];
    return s->node_count++;
}

/* A box slot for b (NOMEM leaves nothing changed). */
static tclod_status take_box(tclod_scene *s, const tclod_box *b, uint32_t *slot) {
    if (s->box_free_count == 0 && s->box_count == s->box_cap) {
        tclod_array arrays[TCLOD_MAX_ARRAYS];
        uint32_t cap = grown_capacity(s->box_cap);
        tclod_status st =
            tclod_arrays_grow(&s->alloc, arrays, box_arrays(s, arrays), s->box_cap, cap);
        if (st != TCLOD_OK)
            return st;
        s->box_cap = cap;
    }
    *slot = s->box_free_count > 0 ? s->box_free[--s->box_free_count] : s->box_count++;
    s->boxes[*slot] = *b;
    return TCLOD_OK;
}

static void free_box(tclod_scene *s, uint32_t slot) {
    if (slot != TCLOD_NONE)
        s->box_free[s->box_free_count++] = slot;
}

/* ---- nodes -------------------------------------------------------------------------- */

void tclod_node_desc_default(tclod_node_desc *d) {
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->parent = TCLOD_NONE;
    d->bounds.kind = TCLOD_BOUNDS_NONE;
    d->refine = TCLOD_REFINE_REPLACE;
}

static int node_live(const tclod_scene *s, tclod_id n) {
    return n < s->node_count && (s->flags[n] & TCLOD_NODE_LIVE);
}

static void changed(tclod_scene *s) {
    s->version++;
}

static void nodes_changed(tclod_scene *s) {
    s->version++;
    s->node_version++;
}

/* Links n as the last child of p in the host's tree (or as a root). */
static void link_child(tclod_scene *s, tclod_id n, tclod_id p) {
    s->up[n] = p;
    s->first_child[n] = TCLOD_NONE;
    s->next_sibling[n] = TCLOD_NONE;
    s->prev_sibling[n] = TCLOD_NONE;
    if (p == TCLOD_NONE)
        return;
    if (s->first_child[p] == TCLOD_NONE) {
        s->first_child[p] = n;
    } else {
        /* the first child's prev_sibling is the last child */
        tclod_id first = s->first_child[p], last = s->prev_sibling[first];
        s->next_sibling[last] = n;
        s->prev_sibling[n] = last;
    }
    s->prev_sibling[s->first_child[p]] = n;
}

static void unlink_child(tclod_scene *s, tclod_id n) {
    tclod_id p = s->up[n], prev = s->prev_sibling[n], next = s->next_sibling[n];
    if (p == TCLOD_NONE)
        return;
    if (s->first_child[p] == n) {
        s->first_child[p] = next;
        if (next != TCLOD_NONE)
            s->prev_sibling[next] = prev; /* the last child */
    } else {
        s->next_sibling[prev] = next;
        if (next != TCLOD_NONE)
            s->prev_sibling[next] = prev;
        else
            s->prev_sibling[s->first_child[p]] = prev;
    }
}

tclod_status tclod_scene_add_node_desc(tclod_scene *s, const tclod_node_desc *d, tclod_id *out_id) {
    tclod_node_bounds nb;
    tclod_box box;
    uint32_t slot = TCLOD_NONE;
    int additive;
    tclod_id id, self = TCLOD_NONE;
    tclod_status st;
    if (!s || !d || !out_id || tclod_bounds_convert(&d->bounds, &nb, &box) != TCLOD_OK)
        return TCLOD_ERR_ARG;
    if ((unsigned)d->refine > (unsigned)TCLOD_REFINE_ADD || (d->empty != 0 && d->empty != 1))
        return TCLOD_ERR_ARG;
    if (d->parent != TCLOD_NONE && !node_live(s, d->parent))
        return TCLOD_ERR_HIERARCHY;
    if (held(s))
        return TCLOD_ERR_STATE;
    additive = d->refine == TCLOD_REFINE_ADD && !d->empty;
    st = reserve_nodes(s, additive ? 2u : 1u);
    if (st == TCLOD_OK && nb.kind > TCLOD_BOUNDS_SPHERE)
        st = take_box(s, &box, &slot);
    if (st != TCLOD_OK)
        return st;
    nb.box = slot;
    id = take_node_id(s);
    link_child(s, id, d->parent);
    s->bounds[id] = nb;
    s->flags[id] =
        (uint8_t)(TCLOD_NODE_LIVE | (d->refine == TCLOD_REFINE_ADD ? TCLOD_NODE_ADD : 0u) |
                  (d->empty ? TCLOD_NODE_EMPTY : 0u));
    if (additive) {
        self = take_node_id(s);
        s->up[self] = id;
        s->first_child[self] = s->next_sibling[self] = s->prev_sibling[self] = TCLOD_NONE;
        s->self[self] = TCLOD_NONE;
        s->bounds[self] = nb;
        s->flags[self] = TCLOD_NODE_SELF;
        s->self_count++;
    }
    s->self[id] = self;
    s->live_nodes++;
    nodes_changed(s);
    *out_id = id;
    return TCLOD_OK;
}

tclod_status tclod_scene_add_node(tclod_scene *s, tclod_id parent, const float bounds[4],
                                  tclod_id *out_id) {
    tclod_node_desc d;
    tclod_node_desc_default(&d);
    d.parent = parent;
    if (bounds)
        d.bounds = tclod_bounds_sphere((double)bounds[0], (double)bounds[1], (double)bounds[2],
                                       (double)bounds[3]);
    return tclod_scene_add_node_desc(s, &d, out_id);
}

/* Takes node n out of the scene (its id retired, its box freed). */
static void drop_node(tclod_scene *s, tclod_id n) {
    tclod_id self = s->self[n];
    free_box(s, s->bounds[n].box);
    s->flags[n] = 0;
    retire(&s->retired, s->node_cap, n, s->epoch);
    s->live_nodes--;
    if (self != TCLOD_NONE) {
        s->flags[self] = 0;
        retire(&s->retired, s->node_cap, self, s->epoch);
        s->self_count--;
    }
}

tclod_status tclod_scene_remove_node(tclod_scene *s, tclod_id node) {
    tclod_id n;
    if (!s || !node_live(s, node))
        return TCLOD_ERR_ARG;
    if (held(s))
        return TCLOD_ERR_STATE;
    unlink_child(s, node);
    s->epoch++;
    /* the subtree in preorder along the sibling lists: no stack */
    n = node;
    for (;;) {
        tclod_id next = s->first_child[n];
        if (next == TCLOD_NONE) {
            /* climb until a node with a next sibling, stopping at `node` */
            tclod_id m = n;
            for (;;) {
                tclod_id up = s->up[m], sibling = s->next_sibling[m];
                drop_node(s, m);
                if (m == node) {
                    nodes_changed(s);
                    return TCLOD_OK;
                }
                if (sibling != TCLOD_NONE) {
                    next = sibling;
                    break;
                }
                m = up;
            }
        }
        n = next;
    }
}

tclod_status tclod_scene_set_node_bounds(tclod_scene *s, tclod_id node,
                                         const tclod_bounds *bounds) {
    tclod_node_bounds nb;
    tclod_box box;
    uint32_t slot;
    tclod_bounds none;
    if (!bounds) {
        memset(&none, 0, sizeof none);
        bounds = &none;
    }
    if (!s || !node_live(s, node) || tclod_bounds_convert(bounds, &nb, &box) != TCLOD_OK)
        return TCLOD_ERR_ARG;
    if (held(s))
        return TCLOD_ERR_STATE;
    slot = s->bounds[node].box;
    if (nb.kind > TCLOD_BOUNDS_SPHERE) {
        if (slot == TCLOD_NONE) {
            tclod_status st = take_box(s, &box, &slot);
            if (st != TCLOD_OK)
                return st;
        } else {
            s->boxes[slot] = box;
        }
    } else {
        free_box(s, slot);
        slot = TCLOD_NONE;
    }
    nb.box = slot;
    s->bounds[node] = nb;
    if (s->self[node] != TCLOD_NONE)
        s->bounds[s->self[node]] = nb;
    changed(s);
    return TCLOD_OK;
}

void tclod_scene_public_bounds(const tclod_scene *s, tclod_id n, tclod_bounds *out) {
    const tclod_node_bounds *b = &s->bounds[n];
    int i;
    memset(out, 0, sizeof *out);
    out->kind = (tclod_bounds_kind)b->kind;
    if (b->kind == TCLOD_BOUNDS_NONE)
        return;
    out->center[0] = b->c[0];
    out->center[1] = b->c[1];
    out->center[2] = b->c[2];
    if (b->kind == TCLOD_BOUNDS_SPHERE) {
        out->radius = b->r;
        return;
    }
    for (i = 0; i < 3; ++i) {
        if (b->kind == TCLOD_BOUNDS_AABB)
            out->half_extents[i] = s->boxes[b->box].h[i];
        else
            memcpy(out->half_axes[i], s->boxes[b->box].axes[i], sizeof(double) * 3);
    }
}

tclod_status tclod_scene_node_bounds(const tclod_scene *s, tclod_id node, tclod_bounds *out) {
    if (!s || !out || !node_live(s, node))
        return TCLOD_ERR_ARG;
    tclod_scene_public_bounds(s, node, out);
    return TCLOD_OK;
}

/* ---- smooth objects -------------------------------------------------------------------- */

static int sphere_valid(const float b[4]) {
    return isfinite(b[0]) && isfinite(b[1]) && isfinite(b[2]) && isfinite(b[3]) && b[3] >= 0.0f;
}

static int smooth_live(const tclod_scene *s, tclod_id n) {
    return n < s->smooth_count && (s->smooth_flags[n] & TCLOD_NODE_LIVE);
}

static void smooth_changed(tclod_scene *s) {
    s->version++;
    s->smooth_version++;
}

tclod_status tclod_scene_add_smooth(tclod_scene *s, const float bounds[4], tclod_id *out_id) {
    tclod_id id;
    if (!s || !out_id || !bounds || !sphere_valid(bounds))
        return TCLOD_ERR_ARG;
    if (held(s))
        return TCLOD_ERR_STATE;
    release(s, &s->smooth_retired, s->smooth_cap, s->smooth_free, &s->smooth_free_count);
    if (s->smooth_free_count > 0) {
        id = s->smooth_free[--s->smooth_free_count];
    } else {
        if (s->smooth_count == UINT32_MAX - 1u)
            return TCLOD_ERR_NOMEM;
        if (s->smooth_count == s->smooth_cap) {
            tclod_array arrays[TCLOD_MAX_ARRAYS];
            uint32_t cap = grown_capacity(s->smooth_cap);
            tclod_status st =
                tclod_arrays_grow(&s->alloc, arrays, smooth_arrays(s, arrays), s->smooth_cap, cap);
            if (st != TCLOD_OK)
                return st;
            unwrap(&s->smooth_retired, s->smooth_cap);
            s->smooth_cap = cap;
        }
        id = s->smooth_count++;
    }
    memcpy(&s->smooth_bounds[4u * id], bounds, 4 * sizeof(float));
    s->smooth_flags[id] = TCLOD_NODE_LIVE;
    s->smooth_live++;
    smooth_changed(s);
    *out_id = id;
    return TCLOD_OK;
}

tclod_status tclod_scene_remove_smooth(tclod_scene *s, tclod_id smooth) {
    if (!s || !smooth_live(s, smooth))
        return TCLOD_ERR_ARG;
    if (held(s))
        return TCLOD_ERR_STATE;
    s->epoch++;
    s->smooth_flags[smooth] = 0;
    retire(&s->smooth_retired, s->smooth_cap, smooth, s->epoch);
    s->smooth_live--;
    smooth_changed(s);
    return TCLOD_OK;
}

tclod_status tclod_scene_set_smooth_bounds(tclod_scene *s, tclod_id smooth, const float bounds[4]) {
    if (!s || !bounds || !smooth_live(s, smooth) || !sphere_valid(bounds))
        return TCLOD_ERR_ARG;
    if (held(s))
        return TCLOD_ERR_STATE;
    memcpy(&s->smooth_bounds[4u * smooth], bounds, 4 * sizeof(float));
    smooth_changed(s);
    return TCLOD_OK;
}

/* ---- the child index and the quadtree ------------------------------------------------ */

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
    index_arrays old = current_index(s);
    index_arrays fresh;
    int nodes = s->node_cap > s->index_cap || !s->child_first;
    int smooth = s->smooth_cap > s->smooth_index_cap;
    memset(&fresh, 0, sizeof fresh);
    if (!nodes && !smooth)
        return TCLOD_OK;
    if (nodes) {
        fresh.node_cap = s->node_cap;
        /* child_first needs one entry more than there are nodes */
        fresh.child_first =
            (uint32_t *)tclod_mem_alloc(a, sizeof(uint32_t) * (fresh.node_cap + 1u));
        fresh.children = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.node_cap);
        fresh.roots = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.node_cap);
        fresh.order = (tclod_id *)tclod_mem_alloc(a, sizeof(tclod_id) * fresh.node_cap);
        if (!fresh.child_first || !fresh.children || !fresh.roots || !fresh.order) {
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
        index_arrays gone = old;
        gone.smooth_cap = 0;
        gone.smooth_order = NULL;
        gone.smooth_pos = NULL;
        gone.qt = NULL;
        index_arrays_free(a, &gone);
        s->index_cap = fresh.node_cap;
        s->child_first = fresh.child_first;
        s->children = fresh.children;
        s->roots = fresh.roots;
        s->order = fresh.order;
    }
    if (smooth) {
        index_arrays gone = old;
        gone.node_cap = 0;
        gone.child_first = NULL;
        gone.children = gone.roots = gone.order = NULL;
        index_arrays_free(a, &gone);
        s->smooth_index_cap = fresh.smooth_cap;
        s->smooth_order = fresh.smooth_order;
        s->smooth_pos = fresh.smooth_pos;
        s->qt = fresh.qt;
    }
    return TCLOD_OK;
}

/* The index's parent of every live node that draws: its nearest ancestor that
 * draws (empty ancestors passed over), TCLOD_NONE for a root. An empty node's
 * entry in parent[] holds the same for its children, found once per empty
 * node: a walk up a chain of empty nodes resolves them all (the chain waits in
 * order[], which is free until the index's order is made). */
static void index_parents(tclod_scene *s) {
    uint8_t *flags = s->flags;
    uint32_t n = s->node_count, i;
    for (i = 0; i < n; ++i) {
        flags[i] &= (uint8_t)~TCLOD_NODE_INDEXED;
        if ((flags[i] & (TCLOD_NODE_LIVE | TCLOD_NODE_EMPTY)) ==
            (TCLOD_NODE_LIVE | TCLOD_NODE_EMPTY))
            s->parent[i] = TCLOD_NONE - 1u; /* not resolved yet */
    }
    for (i = 0; i < n; ++i) {
        tclod_id p, top;
        uint32_t chain = 0, k;
        if ((flags[i] & (TCLOD_NODE_LIVE | TCLOD_NODE_EMPTY)) != TCLOD_NODE_LIVE)
            continue;
        p = s->up[i];
        while (p != TCLOD_NONE && (flags[p] & TCLOD_NODE_EMPTY) &&
               s->parent[p] == TCLOD_NONE - 1u) {
            s->order[chain++] = p;
            p = s->up[p];
        }
        /* p: none, a node that draws, or an empty node resolved before */
        top = p != TCLOD_NONE && (flags[p] & TCLOD_NODE_EMPTY) ? s->parent[p] : p;
        for (k = 0; k < chain; ++k)
            s->parent[s->order[k]] = top;
        p = s->up[i];
        s->parent[i] = p != TCLOD_NONE && (flags[p] & TCLOD_NODE_EMPTY) ? s->parent[p] : p;
        flags[i] |= TCLOD_NODE_INDEXED;
    }
}

/* The child index: counting sort of the indexed nodes by parent (id order
 * within a parent), self leaves below the additive nodes that have children,
 * then the nodes in breadth-first order. */
static void build_child_index(tclod_scene *s) {
    uint32_t n = s->node_count, i, roots = 0, head, tail;
    uint32_t *first = s->child_first;
    index_parents(s);
    memset(first, 0, sizeof(uint32_t) * (n + 1u));
    for (i = 0; i < n; ++i)
        if ((s->flags[i] & TCLOD_NODE_INDEXED) && s->parent[i] != TCLOD_NONE)
            first[s->parent[i] + 1u]++;
    /* a self leaf joins when its node has children in the index */
    for (i = 0; i < n; ++i)
        if ((s->flags[i] & TCLOD_NODE_SELF) && first[s->up[i] + 1u] > 0u) {
            s->flags[i] |= TCLOD_NODE_INDEXED;
            s->parent[i] = s->up[i];
            first[s->up[i] + 1u]++;
        }
    for (i = 0; i < n; ++i)
        first[i + 1u] += first[i];
    for (i = 0; i < n; ++i) {
        tclod_id p;
        if (!(s->flags[i] & TCLOD_NODE_INDEXED))
            continue;
        p = s->parent[i];
        if (p == TCLOD_NONE)
            s->roots[roots++] = i;
        else
            s->children[first[p]++] = i;
    }
    /* first[p] now holds the end of p's range: shift back by one slot */
    for (i = n; i > 0; --i)
        first[i] = first[i - 1u];
    first[0] = 0;
    s->root_count = roots;
    /* breadth first: parents before children */
    tail = 0;
    for (i = 0; i < roots; ++i)
        s->order[tail++] = s->roots[i];
    for (head = 0; head < tail; ++head) {
        tclod_id p = s->order[head];
        uint32_t k;
        for (k = first[p]; k < first[p + 1u]; ++k)
            s->order[tail++] = s->children[k];
    }
    s->order_count = tail;
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

tclod_status tclod_scene_prepare(tclod_scene *s) {
    size_t cells_size = 0;
    qt_cell *cells = NULL;
    tclod_status st;
    int nodes, smooth;
    if (!s)
        return TCLOD_ERR_ARG;
    nodes = s->index_version != s->node_version;
    smooth = s->qt_version != s->smooth_version;
    if (!nodes && !smooth)
        return TCLOD_OK;
    /* the quadtree's build-time cells, taken first so no failure comes after
     * the index arrays have been replaced */
    if (smooth && s->smooth_live) {
        cells_size = sizeof(qt_cell) * 2u * (size_t)s->smooth_live;
        cells = (qt_cell *)tclod_mem_alloc(&s->alloc, cells_size);
        if (!cells)
            return TCLOD_ERR_NOMEM;
    }
    st = index_reserve(s);
    if (st == TCLOD_OK) {
        if (smooth)
            build_smooth_quadtree(s, cells);
        if (nodes)
            build_child_index(s);
    }
    tclod_mem_free(&s->alloc, cells, cells_size);
    if (st != TCLOD_OK)
        return st;
    s->index_version = s->node_version;
    s->qt_version = s->smooth_version;
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
    return s && node_live(s, node);
}

int tclod_scene_smooth_live(const tclod_scene *s, tclod_id smooth) {
    return s && smooth_live(s, smooth);
}

tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node) {
    return (s && node_live(s, node)) ? s->up[node] : TCLOD_NONE;
}
