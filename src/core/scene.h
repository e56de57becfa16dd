/*
 * scene.c: the scene's nodes, smooth objects, child index and edit log.
 */
#ifndef TCLOD_SCENE_H
#define TCLOD_SCENE_H

#include "view.h"

/* ---- scene.c --------------------------------------------------------------- */

/* A node of the quadtree over the smooth objects' ground positions (x, z). Its
 * objects are smooth_order[first .. first + count); its children are the
 * contiguous nodes child .. child + child_count - 1 (none for a leaf). Every
 * inner node has at least two children, so there are fewer than 2n nodes. A
 * leaf holds one object, or several at (nearly) the same position. */
typedef struct tclod_smooth_node {
    float bounds[4]; /* sphere around the members' spheres: x, y, z, radius */
    uint32_t first, count;
    uint32_t child, child_count;
} tclod_smooth_node;

/* Per-node flags of a scene (tclod_scene.flags). */
enum {
    TCLOD_NODE_LIVE = 1u,       /* added by the host and not removed */
    TCLOD_NODE_ADD = 2u,        /* additive refinement */
    TCLOD_NODE_EMPTY = 4u,      /* nothing to draw */
    TCLOD_NODE_SELF = 8u,       /* the drawing of an additive node among its children (its
                                   "self leaf"): an id no call returns */
    TCLOD_NODE_INDEXED = 16u,   /* in the child index (the tree the solvers see) */
    TCLOD_NODE_ABSENT = 32u,    /* live and not resident (also in smooth_flags) */
    TCLOD_NODE_UNEXPANDED = 64u /* stands for a part of the hierarchy not read yet: a
                                   leaf, absent until the host replaces it */
};

/* What a scene knows of a selector or scheduler over it: enough to refuse
 * changes while one holds the scene, and to give a removed id again only once
 * every user has solved since (docs/scenes.md, ids). Written by its user only,
 * so that users on several threads never write the same memory. */
typedef struct tclod_scene_user {
    uint32_t synced;   /* the scene's epoch when the user's last solve began: it holds
                          no id removed before that (UINT32_MAX before its first) */
    int busy;          /* in a call that reads the scene, callbacks included */
    int holding;       /* a begun solve holds the scene (between begin and its end) */
    uint64_t log_seen; /* the edit log's end when its last solve began (UINT64_MAX
                          before its first): the edits after it are news to it */
} tclod_scene_user;

/* An entry of a scene's edit log: what a warm start needs to bring its cut up
 * to date without looking at the rest of the scene. */
typedef struct tclod_edit {
    tclod_id node;
    uint32_t kind; /* TCLOD_EDIT_* */
} tclod_edit;
enum {
    TCLOD_EDIT_ADDED = 0,   /* node joined the index */
    TCLOD_EDIT_REMOVED = 1, /* node left it (removed, or a self leaf left behind) */
    TCLOD_EDIT_LOST = 2     /* node lost a child in it */
};

/* Removed ids waiting until every user has solved since their removal: a
 * ring in removal order, each with the epoch it was removed in. */
typedef struct tclod_retired {
    tclod_id *id;
    uint32_t *epoch;
    uint32_t head, count;
} tclod_retired;

struct tclod_scene {
    tclod_allocator alloc;
    char error[TCLOD_ERROR_SIZE]; /* tclod_scene_last_error */

    /* nodes, structure of arrays, indexed by id (< node_count) */
    uint32_t node_count, node_cap, live_nodes;
    tclod_id *up; /* the parent the host gave (TCLOD_NONE: a root); a
                     self leaf's owner */
    tclod_id *first_child, *next_sibling, *prev_sibling; /* the host's tree */
    tclod_id *self;            /* a non-empty additive node's self leaf, or TCLOD_NONE */
    tclod_node_bounds *bounds; /* a self leaf has its owner's */
    uint8_t *flags;            /* TCLOD_NODE_* */
    uint64_t *free_bits;       /* ids to give again: a bit per id (node_cap bits), then a bit
                                  per 64-bit word of those that has any (scene.c) */
    uint32_t free_count;
    /* ids not to give again yet, oldest first: a queue linked through the
     * removed nodes' own records, which they no longer use (self[id]: the
     * next one; child_first[id]: the epoch of its removal) */
    tclod_id retired_head, retired_tail;
    uint32_t retired_count;
    uint32_t self_count; /* self leaves in use */

    /* boxes, by slot; free slots on a stack */
    uint32_t box_count, box_cap, box_free_count;
    tclod_box *boxes;
    uint32_t *box_free;

    uint32_t smooth_count, smooth_cap, smooth_live;
    float *smooth_bounds;  /* 4 per smooth object */
    uint8_t *smooth_flags; /* TCLOD_NODE_LIVE */
    tclod_id *smooth_free;
    uint32_t smooth_free_count;
    tclod_retired smooth_retired;

    /* The child index: the tree the solvers see, kept up to date by every edit
     * (in time proportional to the edit). It holds the live nodes that draw,
     * each below its nearest ancestor that draws (empty nodes are passed over:
     * their children hang from their parent, or are roots), and below every
     * additive node with children its self leaf. A node's children lie in a
     * block of children[], ascending ids; a block that fills up moves to the
     * end, and the slab is compacted (made again, half as large again as
     * what it holds) when a block finds no room left. */
    tclod_id *parent;      /* the index's parent of an indexed node (TCLOD_NONE: a
                              root); for an empty node, the parent its children
                              hang from */
    uint32_t *child_first; /* n's children: children[child_first[n] ..
                              child_first[n] + child_count[n]) */
    uint32_t *child_count;
    uint32_t *child_cap; /* the size of n's block */
    tclod_id *children;
    uint32_t children_cap, children_used, children_garbage;
    tclod_id *roots; /* ascending ids: a block of children[] too (children +
                        root_first, root_cap entries) */
    uint32_t root_count, root_first, root_cap;
    tclod_id *order; /* the indexed nodes, parents before children: made by
                        tclod_scene_prepare while a user reads it (order_cap
                        entries, allocated then) */
    uint32_t order_count, order_cap;
    uint32_t order_version; /* node_version order describes, + 1; 0: none */
    uint32_t order_users;   /* users that read order (Robin Hood selectors,
                               schedulers) */
    /* the edit log: entry i has the sequence number log_base + i; entries
     * every user has seen are let go, and all of them when it is full (a user
     * that had not seen them then looks at its whole selection instead) */
    tclod_edit *log; /* tclod_scene_log_cap(node_cap) entries */
    uint32_t log_count;
    uint64_t log_base;

    /* smooth quadtree, rebuilt when smooth objects changed */
    uint32_t smooth_index_cap;
    tclod_id *smooth_order; /* position -> smooth id, quadtree order (live ones) */
    uint32_t *smooth_pos;   /* smooth id -> position */
    tclod_smooth_node *qt;  /* 2 * smooth_index_cap nodes; qt[0] is the root */
    uint32_t qt_count;

    /* streaming (docs/streaming.md): sizes, and the live resident nodes
     * counted (res_count) and, once a node has been given a size (only
     * those are evicted), in a list (each node's slot in it, TCLOD_NONE when
     * not in it) so that evictions are planned over them alone: made by
     * tclod_scene_prepare (res_listed), kept up to date from then on. Empty
     * nodes have nothing to load: their flag is kept, but they are in no
     * count, list or sum */
    float *bytes;
    uint32_t *res_pos;
    tclod_id *res_list;
    uint32_t res_count;
    int res_wanted, res_listed; /* a node was given a size; the list is kept */
    uint32_t absent_count;      /* live nodes not resident */
    float *smooth_bytes;
    uint32_t smooth_absent_count;
    double resident_bytes;      /* the sizes of the resident nodes and smooth objects */
    uint32_t residency_version; /* bumped by every change of residency or size */

    /* users, and the epoch removals are counted in */
    tclod_scene_user **users;
    uint32_t user_count, user_cap;
    uint32_t epoch;

    uint32_t version;        /* bumped by every change */
    uint32_t node_version;   /* bumped when nodes are added or removed */
    uint32_t smooth_version; /* bumped when smooth objects are added, removed or moved */
    uint32_t qt_version;     /* smooth_version the quadtree describes */
};

/* The edit log's entries for a node capacity: one per 4 nodes. Edits beyond
 * that many between two solves are as many as a warm start's look at its
 * whole selection costs anyway. */
static inline uint32_t tclod_scene_log_cap(uint32_t node_cap) {
    return node_cap / 4u;
}

/* Registers u as a user of s (holding no id yet, not busy, not holding the
 * scene); `reads_order`: it reads tclod_scene.order, which tclod_scene_prepare
 * then keeps. Errors: TCLOD_ERR_NOMEM. */
tclod_status tclod_scene_attach(tclod_scene *s, tclod_scene_user *u, int reads_order);
/* Unregisters u (attached with reads_order). */
void tclod_scene_detach(tclod_scene *s, tclod_scene_user *u, int reads_order);

/* Whether node n draws in the index (live, not empty, or a self leaf in use). */
static inline int tclod_scene_indexed(const tclod_scene *s, tclod_id n) {
    return (s->flags[n] & TCLOD_NODE_INDEXED) != 0;
}

/* The node a callback is asked about for node n: n, or a self leaf's owner. */
static inline tclod_id tclod_scene_owner(const tclod_scene *s, tclod_id n) {
    return (s->flags[n] & TCLOD_NODE_SELF) ? s->up[n] : n;
}

/* Whether the selectors must look at residency at all. */
static inline int tclod_scene_streams(const tclod_scene *s) {
    return (s->absent_count | s->smooth_absent_count) != 0;
}

/* Whether node n is live, draws something and is resident: on the resident
 * list (when the scene keeps it). */
static inline int tclod_scene_resident(const tclod_scene *s, tclod_id n) {
    return (s->flags[n] & (TCLOD_NODE_LIVE | TCLOD_NODE_EMPTY | TCLOD_NODE_ABSENT |
                           TCLOD_NODE_SELF)) == TCLOD_NODE_LIVE;
}

/* Whether node n (a self leaf: its owner) is not resident. */
static inline int tclod_scene_absent(const tclod_scene *s, tclod_id n) {
    return (s->flags[tclod_scene_owner(s, n)] & TCLOD_NODE_ABSENT) != 0;
}

/* The public form of node n's bounds into *out (kind NONE without). */
void tclod_scene_public_bounds(const tclod_scene *s, tclod_id n, tclod_bounds *out);

#endif /* TCLOD_SCENE_H */
