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
 * and its children. Every edit keeps the index up to date in time
 * proportional to the edit (a child goes into, or out of, its parent's block
 * of children), so that a scene edited every frame costs no rebuild. Moves
 * change no index.
 *
 * Ids are dense and reused, but a removed id is given again only once every
 * user of the scene (selector, scheduler) has begun a solve since the removal:
 * until then it waits in the retired ring, tagged with the removal's epoch.
 * No result a host can still read then names the old node, so a host cannot
 * mistake it for the new one.
 *
 * This file holds the edits (nodes, smooth objects, ids, the child index and
 * the edit log); scene_prepare.c what a solve reads (docs/scenes.md).
 *
 * Layer: core, which may call core. Calls: core (alloc.c, view.c).
 */
#include "scene.h"
#include "scene_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* A per-node or per-object capacity after cap: half as much again (a
 * multiple of 64, which the free-id bitsets' words need), so that the slack
 * of a grown scene averages about a fifth of what it holds. */
static uint32_t grown_capacity(uint32_t cap) {
    uint32_t more;
    if (cap < 64u)
        return 64u;
    if (cap > (UINT32_MAX - 64u) / 3u * 2u)
        return UINT32_MAX - 1u;
    more = cap + cap / 2u;
    return (more + 63u) & ~63u;
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
    s->retired_head = s->retired_tail = TCLOD_NONE;
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
    out[n++] = (tclod_array){(void **)&s->parent, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->child_first, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&s->child_count, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&s->child_cap, sizeof(uint32_t), 0};
    /* tclod_scene_log_cap(cap) entries: bytes per node as its share */
    out[n++] = (tclod_array){(void **)&s->log, sizeof(tclod_edit) / 4u, -1};
    out[n++] = (tclod_array){(void **)&s->bytes, sizeof(float), 0};
    if (s->res_listed) {
        out[n++] = (tclod_array){(void **)&s->res_pos, sizeof(uint32_t), -1};
        out[n++] = (tclod_array){(void **)&s->res_list, sizeof(tclod_id), -1};
    }
    return n;
}

static size_t smooth_arrays(tclod_scene *s, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&s->smooth_bounds, 4 * sizeof(float), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_flags, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&s->smooth_free, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_retired.id, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_retired.epoch, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&s->smooth_bytes, sizeof(float), 0};
    return n;
}

static size_t box_arrays(tclod_scene *s, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&s->boxes, sizeof(tclod_box), -1};
    out[n++] = (tclod_array){(void **)&s->box_free, sizeof(uint32_t), -1};
    return n;
}

/* 64-bit words of the bitset of cap ids, and of its summary. */
static size_t free_map_words(uint32_t cap) {
    return (size_t)cap / 64u + (cap % 64u != 0);
}

static size_t free_summary_size(uint32_t cap) {
    return (free_map_words(cap) + 63u) / 64u;
}

/* The bytes of free_bits for cap ids. */
static size_t free_bits_size(uint32_t cap) {
    return sizeof(uint64_t) * (free_map_words(cap) + free_summary_size(cap));
}

void tclod_scene_quadtree_arrays_free(const tclod_allocator *a, quadtree_arrays *x) {
    tclod_mem_free(a, x->smooth_order, sizeof(tclod_id) * x->smooth_cap);
    tclod_mem_free(a, x->smooth_pos, sizeof(uint32_t) * x->smooth_cap);
    tclod_mem_free(a, x->qt, sizeof(tclod_smooth_node) * 2u * (size_t)x->smooth_cap);
}

tclod_status tclod_scene_destroy(tclod_scene *s) {
    tclod_array arrays[TCLOD_MAX_ARRAYS];
    tclod_allocator alloc;
    quadtree_arrays x;
    if (!s)
        return TCLOD_OK;
    if (s->user_count > 0)
        return tclod_fail(s->error, TCLOD_ERR_STATE, "tclod_scene_destroy",
                          "a selector or scheduler still uses the scene; destroy them first");
    alloc = s->alloc;
    tclod_arrays_free(&alloc, arrays, node_arrays(s, arrays), s->node_cap);
    tclod_mem_free(&alloc, s->free_bits, free_bits_size(s->node_cap));
    tclod_arrays_free(&alloc, arrays, smooth_arrays(s, arrays), s->smooth_cap);
    tclod_arrays_free(&alloc, arrays, box_arrays(s, arrays), s->box_cap);
    tclod_mem_free(&alloc, s->children, sizeof(tclod_id) * s->children_cap);
    tclod_mem_free(&alloc, s->order, sizeof(tclod_id) * s->order_cap);
    x.smooth_cap = s->smooth_index_cap;
    x.smooth_order = s->smooth_order;
    x.smooth_pos = s->smooth_pos;
    x.qt = s->qt;
    tclod_scene_quadtree_arrays_free(&alloc, &x);
    tclod_mem_free(&alloc, s->users, sizeof(tclod_scene_user *) * s->user_cap);
    tclod_mem_free(&alloc, s, sizeof *s);
    return TCLOD_OK;
}

/* ---- users ------------------------------------------------------------------------ */

tclod_status tclod_scene_attach(tclod_scene *s, tclod_scene_user *u, int reads_order) {
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
    u->log_seen = UINT64_MAX;
    u->busy = 0;
    u->holding = 0;
    s->users[s->user_count++] = u;
    s->order_users += reads_order != 0;
    return TCLOD_OK;
}

void tclod_scene_detach(tclod_scene *s, tclod_scene_user *u, int reads_order) {
    uint32_t i;
    s->order_users -= reads_order != 0;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i] == u) {
            s->users[i] = s->users[--s->user_count];
            return;
        }
}

/* A smooth object's sphere rule (sphere_valid). */
#define SPHERE_RULE \
    "bounds must be finite with radius >= 0, each at most TCLOD_SMOOTH_LIMIT (1e30) in magnitude"

/* The oldest epoch a user's results may still come from: ids removed at it
 * or later may still be named by a result a host can read. */
static uint32_t oldest_synced(const tclod_scene *s) {
    uint32_t i, oldest = s->epoch;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i]->synced < oldest)
            oldest = s->users[i]->synced;
    return oldest;
}

/* ---- the edit log ------------------------------------------------------------------- */

/* Lets go of the entries every user has seen (a user that never solved has
 * nothing to bring up to date). */
static void trim_log(tclod_scene *s) {
    uint64_t oldest = s->log_base + s->log_count, drop;
    uint32_t i;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i]->log_seen < oldest && s->users[i]->log_seen >= s->log_base)
            oldest = s->users[i]->log_seen;
    drop = oldest - s->log_base;
    if (drop == 0)
        return;
    memmove(s->log, s->log + drop, sizeof(tclod_edit) * (s->log_count - (uint32_t)drop));
    s->log_count -= (uint32_t)drop;
    s->log_base = oldest;
}

static void log_edit(tclod_scene *s, tclod_id node, uint32_t kind) {
    uint32_t cap = tclod_scene_log_cap(s->node_cap);
    if (s->log_count == cap)
        trim_log(s);
    if (s->log_count == cap) { /* full: users behind look at their selections */
        s->log_base += s->log_count;
        s->log_count = 0;
    }
    s->log[s->log_count].node = node;
    s->log[s->log_count].kind = kind;
    s->log_count++;
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

/* ---- the free node ids, by position ----------------------------------------------------
 *
 * An id given again is the first free one at or after a hint (the new node's
 * parent, or an additive node for its self leaf): a node removed and another
 * added in its place take the same ids, and the ids of nodes near each other
 * in the hierarchies stay near each other in memory, where a solve finds them
 * in fewer cache lines. A bit per id, and a bit per 64 ids that has any. */

static uint64_t *free_words(const tclod_scene *s) {
    return s->free_bits;
}

static uint64_t *free_summary_words(const tclod_scene *s) {
    return s->free_bits + free_map_words(s->node_cap);
}

/* The free ids' bits of the current capacity copied into fresh, sized for
 * cap ids, the rest clear; the old ones freed. */
static void free_bits_move(tclod_scene *s, uint64_t *fresh, uint32_t cap) {
    size_t old_words = free_map_words(s->node_cap), words = free_map_words(cap);
    size_t old_summary = free_summary_size(s->node_cap);
    memset(fresh, 0, free_bits_size(cap));
    if (s->free_bits) {
        memcpy(fresh, s->free_bits, sizeof(uint64_t) * old_words);
        memcpy(fresh + words, s->free_bits + old_words, sizeof(uint64_t) * old_summary);
    }
    tclod_mem_free(&s->alloc, s->free_bits, free_bits_size(s->node_cap));
    s->free_bits = fresh;
}

/* The lowest set bit's position; w != 0. */
static uint32_t lowest_bit(uint64_t w) {
#if defined(__GNUC__) || defined(__clang__)
    return (uint32_t)__builtin_ctzll(w);
#else
    uint32_t k = 0;
    while (!(w & 1u)) {
        w >>= 1;
        k++;
    }
    return k;
#endif
}

static void free_id(tclod_scene *s, tclod_id id) {
    free_words(s)[id >> 6] |= UINT64_C(1) << (id & 63u);
    free_summary_words(s)[id >> 12] |= UINT64_C(1) << ((id >> 6) & 63u);
    s->free_count++;
}

/* The first free id at or after `from`, or TCLOD_NONE. */
static tclod_id first_free(const tclod_scene *s, uint32_t from) {
    const uint64_t *w = free_words(s), *sum = free_summary_words(s);
    uint32_t words = (s->node_count + 63u) / 64u, wi = from >> 6, si;
    uint64_t m;
    if (wi >= words)
        return TCLOD_NONE;
    m = w[wi] & (~UINT64_C(0) << (from & 63u));
    if (m)
        return (wi << 6) + lowest_bit(m);
    for (wi++, si = wi >> 6; si <= (words - 1u) >> 6; ++si) {
        m = sum[si];
        if (si == wi >> 6)
            m &= ~UINT64_C(0) << (wi & 63u);
        if (m) {
            uint32_t word = (si << 6) + lowest_bit(m);
            return (word << 6) + lowest_bit(w[word]);
        }
    }
    return TCLOD_NONE;
}

/* Takes a free id, the first at or after hint (or the first of all). */
static tclod_id take_free(tclod_scene *s, tclod_id hint) {
    tclod_id id = first_free(s, hint < s->node_count ? hint : 0u);
    uint64_t *w = free_words(s);
    if (id == TCLOD_NONE)
        id = first_free(s, 0u);
    w[id >> 6] &= ~(UINT64_C(1) << (id & 63u));
    if (!w[id >> 6])
        free_summary_words(s)[id >> 12] &= ~(UINT64_C(1) << ((id >> 6) & 63u));
    s->free_count--;
    return id;
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

/* Puts the removed node id at the end of the retired queue, removed in
 * epoch (its record's self and child_first are free for the queue). */
static void retire_node(tclod_scene *s, tclod_id id, uint32_t epoch) {
    s->self[id] = TCLOD_NONE;
    s->child_first[id] = epoch;
    if (s->retired_tail == TCLOD_NONE)
        s->retired_head = id;
    else
        s->self[s->retired_tail] = id;
    s->retired_tail = id;
    s->retired_count++;
}

/* Makes the retired ids every user has solved since free again. */
static void release_nodes(tclod_scene *s) {
    uint32_t oldest = s->retired_count ? oldest_synced(s) : 0u;
    while (s->retired_count > 0 && s->child_first[s->retired_head] <= oldest) {
        tclod_id id = s->retired_head;
        s->retired_head = s->self[id];
        s->self[id] = TCLOD_NONE;
        free_id(s, id);
        if (--s->retired_count == 0)
            s->retired_tail = TCLOD_NONE;
    }
}

/* What an add may need to grow: the per-node arrays, the boxes and the slab
 * of children, each taken fresh (room_alloc) before any replaces what it grows
 * (room_commit), so that running out of memory for one leaves the others as
 * they were too. */
typedef struct room {
    tclod_array node[TCLOD_MAX_ARRAYS], box[TCLOD_MAX_ARRAYS];
    void *node_fresh[TCLOD_MAX_ARRAYS], *box_fresh[TCLOD_MAX_ARRAYS];
    size_t node_n, box_n;
    uint32_t node_cap, box_cap, slab_cap; /* 0: no growth */
    tclod_id *slab;
    uint64_t *bits; /* free_bits for node_cap */
} room;

static void room_discard(tclod_scene *s, room *r) {
    if (r->node_cap) {
        tclod_arrays_discard(&s->alloc, r->node, r->node_n, r->node_cap, r->node_fresh);
        tclod_mem_free(&s->alloc, r->bits, free_bits_size(r->node_cap));
    }
    if (r->box_cap)
        tclod_arrays_discard(&s->alloc, r->box, r->box_n, r->box_cap, r->box_fresh);
    tclod_mem_free(&s->alloc, r->slab, sizeof(tclod_id) * r->slab_cap);
}

/* Room for `ids` new node ids, a box when `box`, and `slab` more slots of
 * children, all or nothing. */
static tclod_status room_alloc(tclod_scene *s, room *r, uint32_t ids, int box, uint32_t slab) {
    memset(r, 0, sizeof *r);
    release_nodes(s);
    if (s->free_count < ids) {
        uint32_t fresh = ids - s->free_count, cap = s->node_cap;
        if (s->node_count > UINT32_MAX - 2u - fresh)
            return TCLOD_ERR_NOMEM; /* ids exhausted */
        if (s->node_count + fresh > cap) {
            while (cap < s->node_count + fresh)
                cap = grown_capacity(cap);
            r->node_n = node_arrays(s, r->node);
            if (tclod_arrays_alloc(&s->alloc, r->node, r->node_n, cap, r->node_fresh) != TCLOD_OK)
                return TCLOD_ERR_NOMEM;
            r->bits = (uint64_t *)tclod_mem_alloc(&s->alloc, free_bits_size(cap));
            if (!r->bits) {
                tclod_arrays_discard(&s->alloc, r->node, r->node_n, cap, r->node_fresh);
                return TCLOD_ERR_NOMEM;
            }
            r->node_cap = cap;
        }
    }
    if (box && s->box_free_count == 0 && s->box_count == s->box_cap) {
        uint32_t cap = grown_capacity(s->box_cap);
        r->box_n = box_arrays(s, r->box);
        if (tclod_arrays_alloc(&s->alloc, r->box, r->box_n, cap, r->box_fresh) != TCLOD_OK) {
            room_discard(s, r);
            return TCLOD_ERR_NOMEM;
        }
        r->box_cap = cap;
    }
    if (s->children_used > UINT32_MAX - slab || s->children_used + slab > s->children_cap) {
        /* the slab is made again, half as large again as what it holds:
         * blocks that move use the room left until the next time */
        uint32_t live = s->children_used - s->children_garbage, cap;
        if (live > UINT32_MAX / 4u - slab) {
            room_discard(s, r);
            return TCLOD_ERR_NOMEM;
        }
        cap = live + slab;
        cap = (cap + cap / 2u + 63u) & ~63u;
        r->slab = (tclod_id *)tclod_mem_alloc(&s->alloc, sizeof(tclod_id) * cap);
        if (!r->slab) {
            room_discard(s, r);
            return TCLOD_ERR_NOMEM;
        }
        r->slab_cap = cap;
    }
    return TCLOD_OK;
}

/* The slab of children made again in fresh (cap slots): its blocks packed in
 * id order, each as large as what it holds; what moved blocks left behind
 * goes. */
static void slab_rebuild(tclod_scene *s, tclod_id *fresh, uint32_t cap) {
    uint32_t n, at = s->root_count;
    if (s->root_count) /* the roots first */
        memcpy(fresh, s->roots, sizeof(tclod_id) * s->root_count);
    s->root_first = 0;
    s->root_cap = s->root_count;
    for (n = 0; n < s->node_count; ++n) {
        if (s->child_cap[n] == 0u)
            continue;
        if (s->child_count[n])
            memcpy(fresh + at, s->children + s->child_first[n],
                   sizeof(tclod_id) * s->child_count[n]);
        s->child_first[n] = at;
        s->child_cap[n] = s->child_count[n];
        at += s->child_count[n];
    }
    tclod_mem_free(&s->alloc, s->children, sizeof(tclod_id) * s->children_cap);
    s->children = fresh;
    s->children_cap = cap;
    s->children_used = at;
    s->children_garbage = 0;
    s->roots = fresh;
}

static void room_commit(tclod_scene *s, room *r) {
    if (r->node_cap) {
        tclod_arrays_commit(&s->alloc, r->node, r->node_n, s->node_cap, r->node_cap, r->node_fresh);
        free_bits_move(s, r->bits, r->node_cap);
        s->node_cap = r->node_cap;
    }
    if (r->box_cap) {
        tclod_arrays_commit(&s->alloc, r->box, r->box_n, s->box_cap, r->box_cap, r->box_fresh);
        s->box_cap = r->box_cap;
    }
    if (r->slab)
        slab_rebuild(s, r->slab, r->slab_cap);
}

/* A new node id (room reserved): a free one near hint, else a fresh one. */
static tclod_id take_node_id(tclod_scene *s, tclod_id hint) {
    if (s->free_count > 0)
        return take_free(s, hint);
    return s->node_count++;
}

/* A box slot for b; there is room (room_alloc, or box_reserve). */
static uint32_t take_box(tclod_scene *s, const tclod_box *b) {
    uint32_t slot = s->box_free_count > 0 ? s->box_free[--s->box_free_count] : s->box_count++;
    assert(slot < s->box_cap);
    s->boxes[slot] = *b;
    return slot;
}

static void free_box(tclod_scene *s, uint32_t slot) {
    if (slot != TCLOD_NONE)
        s->box_free[s->box_free_count++] = slot;
}

/* ---- the child index --------------------------------------------------------------- */

/* The slab room that attaching a child to p may need: p's block (the roots'
 * for TCLOD_NONE) moved to the end at twice its size, and room for a self
 * leaf. */
static uint32_t attach_room(const tclod_scene *s, tclod_id p) {
    return 2u * (p == TCLOD_NONE ? s->root_cap : s->child_cap[p]) + 4u;
}

/* A full block of children (*first, *cap, holding count) moves to the end of
 * the slab at twice its size (there is room: attach_room). */
static void move_block(tclod_scene *s, uint32_t *first, uint32_t *cap, uint32_t count) {
    uint32_t grown = *cap ? 2u * *cap : 2u;
    assert(s->children_used + grown <= s->children_cap);
    if (count)
        memcpy(s->children + s->children_used, s->children + *first, sizeof(tclod_id) * count);
    s->children_garbage += *cap;
    *first = s->children_used;
    *cap = grown;
    s->children_used += grown;
}

/* Where x goes in (or is in) the ascending ids a[0..n). */
static uint32_t lower_bound(const tclod_id *a, uint32_t n, tclod_id x) {
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u;
        if (a[mid] < x)
            lo = mid + 1u;
        else
            hi = mid;
    }
    return lo;
}

/* Puts node x into the index below p (TCLOD_NONE: a root), in id order; the
 * slab has room (attach_room). */
static void attach(tclod_scene *s, tclod_id x, tclod_id p) {
    tclod_id *list;
    uint32_t count, at;
    s->parent[x] = p;
    s->flags[x] |= TCLOD_NODE_INDEXED;
    log_edit(s, x, TCLOD_EDIT_ADDED);
    if (p == TCLOD_NONE) {
        if (s->root_count == s->root_cap) {
            move_block(s, &s->root_first, &s->root_cap, s->root_count);
            s->roots = s->children + s->root_first;
        }
        list = s->roots;
        count = s->root_count++;
    } else {
        if (s->child_count[p] == s->child_cap[p])
            move_block(s, &s->child_first[p], &s->child_cap[p], s->child_count[p]);
        list = s->children + s->child_first[p];
        count = s->child_count[p]++;
    }
    at = lower_bound(list, count, x);
    memmove(list + at + 1u, list + at, sizeof(tclod_id) * (count - at));
    list[at] = x;
}

/* Takes indexed node x out of its parent's children (or the roots). */
static void detach(tclod_scene *s, tclod_id x) {
    tclod_id p = s->parent[x], *list;
    uint32_t count, at;
    if (p == TCLOD_NONE) {
        list = s->roots;
        count = s->root_count--;
    } else {
        list = s->children + s->child_first[p];
        count = s->child_count[p]--;
    }
    at = lower_bound(list, count, x);
    assert(at < count && list[at] == x);
    memmove(list + at, list + at + 1u, sizeof(tclod_id) * (count - at - 1u));
    s->flags[x] &= (uint8_t)~TCLOD_NODE_INDEXED;
    log_edit(s, x, TCLOD_EDIT_REMOVED);
    if (p != TCLOD_NONE)
        log_edit(s, p, TCLOD_EDIT_LOST);
}

/* Below p a child that draws was attached (`gained`) or detached: a
 * non-empty additive node draws itself among its children while it has any
 * other, through its self leaf. */
static void update_self(tclod_scene *s, tclod_id p, int gained) {
    tclod_id self;
    if (p == TCLOD_NONE || (self = s->self[p]) == TCLOD_NONE)
        return;
    if (gained && !(s->flags[self] & TCLOD_NODE_INDEXED))
        attach(s, self, p);
    else if (!gained && (s->flags[self] & TCLOD_NODE_INDEXED) && s->child_count[p] == 1u)
        detach(s, self);
}

/* The nodes of the host's subtree at top, in preorder along the sibling
 * lists: the one after n (TCLOD_NONE after the last). */
static tclod_id next_in_subtree(const tclod_scene *s, tclod_id n, tclod_id top) {
    if (s->first_child[n] != TCLOD_NONE)
        return s->first_child[n];
    while (n != top) {
        if (s->next_sibling[n] != TCLOD_NONE)
            return s->next_sibling[n];
        n = s->up[n];
    }
    return TCLOD_NONE;
}

/* The indexed nodes breadth first from the roots, parents before children,
 * for the users that read them. */
void tclod_scene_build_order(tclod_scene *s) {
    uint32_t head, tail = 0, i;
    for (i = 0; i < s->root_count; ++i)
        s->order[tail++] = s->roots[i];
    for (head = 0; head < tail; ++head) {
        tclod_id p = s->order[head];
        for (i = 0; i < s->child_count[p]; ++i)
            s->order[tail++] = s->children[s->child_first[p] + i];
    }
    s->order_count = tail;
    s->order_version = s->node_version + 1u;
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

/* ---- residency ---------------------------------------------------------------- */

/* Counts live node n resident (on the list, when kept) with its size. */
void tclod_scene_resident_add(tclod_scene *s, tclod_id n) {
    if (s->res_listed) {
        s->res_pos[n] = s->res_count;
        s->res_list[s->res_count] = n;
    }
    s->res_count++;
    s->resident_bytes += (double)s->bytes[n];
    s->residency_version++;
}

/* Takes resident node n off the count (and list) and its size off the total. */
void tclod_scene_resident_remove(tclod_scene *s, tclod_id n) {
    s->res_count--;
    if (s->res_listed) {
        uint32_t slot = s->res_pos[n];
        tclod_id last = s->res_list[s->res_count];
        s->res_list[slot] = last;
        s->res_pos[last] = slot;
        s->res_pos[n] = TCLOD_NONE;
    }
    s->resident_bytes -= (double)s->bytes[n];
    if (s->res_count == 0 && s->smooth_live == s->smooth_absent_count)
        s->resident_bytes = 0.0; /* let go of what rounding left */
    s->residency_version++;
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

/* tclod_scene_add_node_desc, its errors named after fn. */
static tclod_status add_node(tclod_scene *s, const tclod_node_desc *d, tclod_id *out_id,
                             const char *fn) {
    tclod_node_bounds nb;
    tclod_box box;
    uint32_t slot = TCLOD_NONE;
    int additive;
    tclod_id id, self = TCLOD_NONE, ip;
    tclod_status st;
    room r;
    const char *why;
    if (!s)
        return TCLOD_ERR_ARG;
    if (!d)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "d is NULL");
    if (!out_id)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "out_id is NULL");
    why = tclod_bounds_convert(&d->bounds, &nb, &box);
    if (why)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, why);
    if ((unsigned)d->refine > (unsigned)TCLOD_REFINE_ADD)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "refine is not a tclod_refine");
    if (d->empty != 0 && d->empty != 1)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "empty must be 0 or 1");
    if (d->not_resident != 0 && d->not_resident != 1)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "not_resident must be 0 or 1");
    if (d->unexpanded != 0 && d->unexpanded != 1)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "unexpanded must be 0 or 1");
    if (d->unexpanded && d->empty)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn,
                          "an unexpanded node cannot be empty: it is valued as what its "
                          "expansion draws first");
    if (!scene_bytes_valid(d->bytes))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, BYTES_RULE);
    if (d->parent != TCLOD_NONE && !scene_node_live(s, d->parent))
        return tclod_fail(s->error, TCLOD_ERR_HIERARCHY, fn,
                          "parent is neither TCLOD_NONE nor a live node");
    if (d->parent != TCLOD_NONE && (s->flags[d->parent] & TCLOD_NODE_UNEXPANDED))
        return tclod_fail(s->error, TCLOD_ERR_HIERARCHY, fn,
                          "parent is unexpanded: remove it and add what its expansion "
                          "read in its place");
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, fn, HELD);
    additive = d->refine == TCLOD_REFINE_ADD && !d->empty;
    /* where it goes in the index: below its parent, or where an empty one's
     * children go */
    ip = d->parent;
    if (ip != TCLOD_NONE && (s->flags[ip] & TCLOD_NODE_EMPTY))
        ip = s->parent[ip];
    st = room_alloc(s, &r, additive ? 2u : 1u, nb.kind > TCLOD_BOUNDS_SPHERE,
                    d->empty ? 0u : attach_room(s, ip));
    if (st != TCLOD_OK)
        return tclod_fail(s->error, st, fn, "no memory (or no id left) for the node");
    room_commit(s, &r);
    if (nb.kind > TCLOD_BOUNDS_SPHERE)
        slot = take_box(s, &box);
    nb.box = slot;
    id = take_node_id(s, d->parent);
    link_child(s, id, d->parent);
    s->bounds[id] = nb;
    s->flags[id] =
        (uint8_t)(TCLOD_NODE_LIVE | (d->refine == TCLOD_REFINE_ADD ? TCLOD_NODE_ADD : 0u) |
                  (d->empty ? TCLOD_NODE_EMPTY : 0u));
    s->child_count[id] = s->child_cap[id] = 0;
    s->bytes[id] = (float)d->bytes;
    s->res_wanted |= d->bytes > 0.0;
    if (s->res_listed)
        s->res_pos[id] = TCLOD_NONE;
    if (d->not_resident || d->unexpanded)
        s->flags[id] |= TCLOD_NODE_ABSENT;
    if (d->unexpanded)
        s->flags[id] |= TCLOD_NODE_UNEXPANDED;
    if (!d->empty) {
        if (d->not_resident || d->unexpanded)
            s->absent_count++;
        else
            tclod_scene_resident_add(s, id);
    }
    if (additive) {
        self = take_node_id(s, id);
        s->up[self] = id;
        s->first_child[self] = s->next_sibling[self] = s->prev_sibling[self] = TCLOD_NONE;
        s->self[self] = TCLOD_NONE;
        s->bounds[self] = nb;
        s->bounds[self].kind |= TCLOD_BOUNDS_SELF;
        s->flags[self] = TCLOD_NODE_SELF;
        s->child_count[self] = s->child_cap[self] = 0;
        s->bytes[self] = 0.0f;
        if (s->res_listed)
            s->res_pos[self] = TCLOD_NONE;
        s->self_count++;
    }
    s->self[id] = self;
    if (d->empty) {
        s->parent[id] = ip; /* where its children go */
    } else {
        attach(s, id, ip);
        update_self(s, ip, 1);
    }
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
    return add_node(s, &d, out_id, "tclod_scene_add_node");
}

tclod_status tclod_scene_add_node_desc(tclod_scene *s, const tclod_node_desc *d, tclod_id *out_id) {
    return add_node(s, d, out_id, "tclod_scene_add_node_desc");
}

/* Takes node n out of the scene (its id retired, its box and its block of
 * children freed). */
static void drop_node(tclod_scene *s, tclod_id n) {
    tclod_id self = s->self[n];
    /* the index's nodes below one that was taken out: a cut may hold them */
    if (s->flags[n] & TCLOD_NODE_INDEXED)
        log_edit(s, n, TCLOD_EDIT_REMOVED);
    if (self != TCLOD_NONE && (s->flags[self] & TCLOD_NODE_INDEXED))
        log_edit(s, self, TCLOD_EDIT_REMOVED);
    if (s->flags[n] & TCLOD_NODE_EMPTY)
        ; /* nothing to load: not counted */
    else if (s->flags[n] & TCLOD_NODE_ABSENT)
        s->absent_count--;
    else
        tclod_scene_resident_remove(s, n);
    free_box(s, s->bounds[n].box);
    s->children_garbage += s->child_cap[n];
    s->child_count[n] = s->child_cap[n] = 0;
    s->flags[n] = 0;
    retire_node(s, n, s->epoch);
    s->live_nodes--;
    if (self != TCLOD_NONE) {
        s->flags[self] = 0;
        retire_node(s, self, s->epoch);
        s->self_count--;
    }
}

/* A flag of removal: the node is in the subtree being removed. */
#define DYING 0x80u

tclod_status tclod_scene_remove_node(tclod_scene *s, tclod_id node) {
    tclod_id n;
    if (!s)
        return TCLOD_ERR_ARG;
    if (!scene_node_live(s, node))
        return tclod_fail(s->error, TCLOD_ERR_ARG, "tclod_scene_remove_node",
                          "node is not a live node");
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, "tclod_scene_remove_node", HELD);
    /* the subtree is walked three times along the sibling lists (no stack):
     * marked, taken out of the index where it hangs from a node that stays,
     * and dropped */
    for (n = node; n != TCLOD_NONE; n = next_in_subtree(s, n, node))
        s->flags[n] |= DYING;
    for (n = node; n != TCLOD_NONE; n = next_in_subtree(s, n, node)) {
        tclod_id p = s->parent[n];
        if (!(s->flags[n] & TCLOD_NODE_INDEXED) || (p != TCLOD_NONE && (s->flags[p] & DYING)))
            continue;
        detach(s, n);
        update_self(s, p, 0);
    }
    unlink_child(s, node);
    s->epoch++;
    for (n = node; n != TCLOD_NONE;) {
        tclod_id next = next_in_subtree(s, n, node);
        drop_node(s, n);
        n = next;
    }
    nodes_changed(s);
    return TCLOD_OK;
}

tclod_status tclod_scene_set_node_bounds(tclod_scene *s, tclod_id node,
                                         const tclod_bounds *bounds) {
    tclod_node_bounds nb;
    tclod_box box;
    uint32_t slot;
    tclod_bounds none;
    const char *why;
    if (!bounds) {
        memset(&none, 0, sizeof none);
        bounds = &none;
    }
    if (!s)
        return TCLOD_ERR_ARG;
    if (!scene_node_live(s, node))
        return tclod_fail(s->error, TCLOD_ERR_ARG, "tclod_scene_set_node_bounds",
                          "node is not a live node");
    why = tclod_bounds_convert(bounds, &nb, &box);
    if (why)
        return tclod_fail(s->error, TCLOD_ERR_ARG, "tclod_scene_set_node_bounds", why);
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, "tclod_scene_set_node_bounds", HELD);
    slot = s->bounds[node].box;
    if (nb.kind > TCLOD_BOUNDS_SPHERE) {
        if (slot == TCLOD_NONE) {
            room r;
            tclod_status st = room_alloc(s, &r, 0u, 1, 0u);
            if (st != TCLOD_OK)
                return tclod_fail(s->error, st, "tclod_scene_set_node_bounds",
                                  "no memory for the box");
            room_commit(s, &r);
            slot = take_box(s, &box);
        } else {
            s->boxes[slot] = box;
        }
    } else {
        free_box(s, slot);
        slot = TCLOD_NONE;
    }
    nb.box = slot;
    s->bounds[node] = nb;
    if (s->self[node] != TCLOD_NONE) {
        s->bounds[s->self[node]] = nb;
        s->bounds[s->self[node]].kind |= TCLOD_BOUNDS_SELF;
    }
    changed(s);
    return TCLOD_OK;
}

void tclod_scene_public_bounds(const tclod_scene *s, tclod_id n, tclod_bounds *out) {
    const tclod_node_bounds *b = &s->bounds[n];
    int i;
    uint32_t kind = b->kind & ~TCLOD_BOUNDS_SELF;
    memset(out, 0, sizeof *out);
    out->kind = (tclod_bounds_kind)kind;
    if (kind == TCLOD_BOUNDS_NONE)
        return;
    out->center[0] = b->c[0];
    out->center[1] = b->c[1];
    out->center[2] = b->c[2];
    if (kind == TCLOD_BOUNDS_SPHERE) {
        out->radius = b->r;
        return;
    }
    for (i = 0; i < 3; ++i) {
        if (kind == TCLOD_BOUNDS_AABB)
            out->half_extents[i] = s->boxes[b->box].h[i];
        else
            memcpy(out->half_axes[i], s->boxes[b->box].axes[i], sizeof(double) * 3);
    }
}

tclod_status tclod_scene_node_bounds(const tclod_scene *s, tclod_id node, tclod_bounds *out) {
    if (!s || !out || !scene_node_live(s, node))
        return TCLOD_ERR_ARG;
    tclod_scene_public_bounds(s, node, out);
    return TCLOD_OK;
}

/* ---- smooth objects -------------------------------------------------------------------- */

/* A smooth object's sphere: finite, radius >= 0, and every number at most
 * TCLOD_SMOOTH_LIMIT in magnitude, so that the spheres around groups of them
 * stay finite in float. */
static int sphere_valid(const float b[4]) {
    return fabsf(b[0]) <= TCLOD_SMOOTH_LIMIT && fabsf(b[1]) <= TCLOD_SMOOTH_LIMIT &&
           fabsf(b[2]) <= TCLOD_SMOOTH_LIMIT && b[3] >= 0.0f && b[3] <= TCLOD_SMOOTH_LIMIT;
}

static void smooth_changed(tclod_scene *s) {
    s->version++;
    s->smooth_version++;
}

tclod_status tclod_scene_add_smooth(tclod_scene *s, const float bounds[4], tclod_id *out_id) {
    static const char fn[] = "tclod_scene_add_smooth";
    tclod_id id;
    if (!s)
        return TCLOD_ERR_ARG;
    if (!out_id)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "out_id is NULL");
    if (!bounds)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "bounds is NULL");
    if (!sphere_valid(bounds))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, SPHERE_RULE);
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, fn, HELD);
    release(s, &s->smooth_retired, s->smooth_cap, s->smooth_free, &s->smooth_free_count);
    if (s->smooth_free_count > 0) {
        id = s->smooth_free[--s->smooth_free_count];
    } else {
        if (s->smooth_count == UINT32_MAX - 1u)
            return tclod_fail(s->error, TCLOD_ERR_NOMEM, fn, "smooth ids exhausted");
        if (s->smooth_count == s->smooth_cap) {
            tclod_array arrays[TCLOD_MAX_ARRAYS];
            uint32_t cap = grown_capacity(s->smooth_cap);
            tclod_status st =
                tclod_arrays_grow(&s->alloc, arrays, smooth_arrays(s, arrays), s->smooth_cap, cap);
            if (st != TCLOD_OK)
                return tclod_fail(s->error, st, fn, "no memory for the smooth object");
            unwrap(&s->smooth_retired, s->smooth_cap);
            s->smooth_cap = cap;
        }
        id = s->smooth_count++;
    }
    memcpy(&s->smooth_bounds[4u * id], bounds, 4 * sizeof(float));
    s->smooth_flags[id] = TCLOD_NODE_LIVE;
    s->smooth_bytes[id] = 0.0f;
    s->smooth_live++;
    smooth_changed(s);
    *out_id = id;
    return TCLOD_OK;
}

tclod_status tclod_scene_remove_smooth(tclod_scene *s, tclod_id smooth) {
    if (!s)
        return TCLOD_ERR_ARG;
    if (!scene_smooth_live(s, smooth))
        return tclod_fail(s->error, TCLOD_ERR_ARG, "tclod_scene_remove_smooth",
                          "smooth is not a live smooth object");
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, "tclod_scene_remove_smooth", HELD);
    s->epoch++;
    if (s->smooth_flags[smooth] & TCLOD_NODE_ABSENT)
        s->smooth_absent_count--;
    else
        s->resident_bytes -= (double)s->smooth_bytes[smooth];
    s->residency_version++;
    s->smooth_flags[smooth] = 0;
    retire(&s->smooth_retired, s->smooth_cap, smooth, s->epoch);
    s->smooth_live--;
    smooth_changed(s);
    return TCLOD_OK;
}

tclod_status tclod_scene_set_smooth_bounds(tclod_scene *s, tclod_id smooth, const float bounds[4]) {
    static const char fn[] = "tclod_scene_set_smooth_bounds";
    if (!s)
        return TCLOD_ERR_ARG;
    if (!scene_smooth_live(s, smooth))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "smooth is not a live smooth object");
    if (!bounds)
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, "bounds is NULL");
    if (!sphere_valid(bounds))
        return tclod_fail(s->error, TCLOD_ERR_ARG, fn, SPHERE_RULE);
    if (scene_held(s))
        return tclod_fail(s->error, TCLOD_ERR_STATE, fn, HELD);
    memcpy(&s->smooth_bounds[4u * smooth], bounds, 4 * sizeof(float));
    smooth_changed(s);
    return TCLOD_OK;
}
