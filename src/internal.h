/*
 * Declarations shared by the library's source files only. Nothing here is
 * exported; the public contract is include/tclod/tclod.h.
 */
#ifndef TCLOD_INTERNAL_H
#define TCLOD_INTERNAL_H

/* Every file that includes this one is part of the library: TCLOD_API then
 * exports its definitions from a Windows DLL rather than importing them. */
#ifndef TCLOD_BUILDING
#define TCLOD_BUILDING
#endif

#include "tclod/tclod.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ---- alloc.c: memory and time --------------------------------------------- */

/* Copies src (may be NULL) into dst, filling NULL hooks with malloc/free.
 * Returns 0 when src sets only one of alloc/free. */
int tclod_allocator_init(tclod_allocator *dst, const tclod_allocator *src);
void *tclod_mem_alloc(const tclod_allocator *a, size_t size);
void tclod_mem_free(const tclod_allocator *a, void *ptr, size_t size);

/* One array of a structure-of-arrays block that grows as a whole. */
typedef struct tclod_array {
    void **ptr;  /* where the array pointer lives */
    size_t elem; /* element size in bytes */
    int fill;    /* byte written into new elements, or -1 to leave them */
} tclod_array;

/* The most arrays one block may hold. */
#define TCLOD_MAX_ARRAYS 48

/* Grows every array from old_cap to new_cap elements, all or nothing: either
 * every array is replaced by a larger copy (old contents kept, new elements
 * filled) and TCLOD_OK returned, or nothing changes and TCLOD_ERR_NOMEM. */
tclod_status tclod_arrays_grow(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                               size_t old_cap, size_t new_cap);

/* The same in two steps, so that several blocks grow all or nothing together:
 * alloc takes new_cap elements per array into fresh[] (TCLOD_ERR_NOMEM and
 * nothing held on failure); then either commit (copy, fill, free the old) or
 * discard (free fresh[]). */
tclod_status tclod_arrays_alloc(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                                size_t new_cap, void **fresh);
void tclod_arrays_commit(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                         size_t old_cap, size_t new_cap, void **fresh);
void tclod_arrays_discard(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                          size_t new_cap, void **fresh);
void tclod_arrays_free(const tclod_allocator *a, const tclod_array *arrays, size_t count,
                       size_t cap);

/* Monotonic clock in seconds. */
double tclod_now(void);

/* Every object keeps why its last failed call failed: "function: what". */
#define TCLOD_ERROR_SIZE 192
/* Writes "function: what" (what may be NULL: "function") into error,
 * truncated to TCLOD_ERROR_SIZE, and returns st. */
tclod_status tclod_fail(char *error, tclod_status st, const char *function, const char *what);
/* The same with "function: where" followed by what (either may be NULL). */
tclod_status tclod_fail_in(char *error, tclod_status st, const char *function, const char *where,
                           const char *what);
/* Messages more than one module gives. */
#define TCLOD_MSG_BUSY "called from a callback during a solve"
#define TCLOD_MSG_NOMEM "no memory for the scene's size"
#define TCLOD_MSG_SMOOTH \
    "the scene has smooth objects and the mixed solver has no smooth_benefit or smooth_cost"
#define TCLOD_MSG_STRICT "strict mode: a callback returned NaN, inf or a negative value"

/* The rule a calibration desc breaks (NULL: none), its fields named as in a
 * scheduler's desc (desc.calib.*) when nested. */
const char *tclod_calib_check(const tclod_calib_desc *d, int nested);

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

/* A node's bounds as the solvers read them: the sphere around the volume
 * (what culling shortcuts and the Robin Hood values use) and, for a box, its
 * slot. 40 bytes; the padding is kept zero so that records compare with
 * memcmp. */
typedef struct tclod_node_bounds {
    double c[3];   /* centre, world position */
    double r;      /* the sphere's radius, or the box's enclosing sphere's; < 0: no
                      bounds */
    uint32_t box;  /* the box's slot in tclod_scene.boxes, or TCLOD_NONE */
    uint32_t kind; /* tclod_bounds_kind, with TCLOD_BOUNDS_SELF for a self leaf: the
                      evaluation, which reads this record anyway, finds it there */
} tclod_node_bounds;

/* tclod_node_bounds.kind of a self leaf (scene.c): its owner's kind with this
 * bit. */
#define TCLOD_BOUNDS_SELF 0x100u

/* An axis-aligned or oriented box: the half axes as given, and an
 * orthonormal frame with half lengths (zero axes completed by cross
 * products), which the measures use. */
typedef struct tclod_box {
    double axes[3][3]; /* as given; an AABB's are diagonal */
    double u[3][3];    /* unit axes */
    double h[3];       /* half lengths along them, >= 0 */
} tclod_box;

/* Per-node flags of a scene (tclod_scene.flags). */
enum {
    TCLOD_NODE_LIVE = 1u,    /* added by the host and not removed */
    TCLOD_NODE_ADD = 2u,     /* additive refinement */
    TCLOD_NODE_EMPTY = 4u,   /* nothing to draw */
    TCLOD_NODE_SELF = 8u,    /* the drawing of an additive node among its children (its
                                "self leaf"): an id no call returns */
    TCLOD_NODE_INDEXED = 16u /* in the child index (the tree the solvers see) */
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
    uint8_t *free_map;         /* ids to give again: a bitset (64-bit words in the
                                  first node_cap / 8 bytes) ... */
    uint8_t *free_summary;     /* ... and a bit per word of it that has any */
    uint32_t free_count;
    tclod_retired retired; /* ids not to give again yet */
    uint32_t self_count;   /* self leaves in use */

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
     * end, and the slab is compacted when half of it is left behind. */
    tclod_id *parent;      /* the index's parent of an indexed node (TCLOD_NONE: a
                              root); for an empty node, the parent its children
                              hang from */
    uint32_t *child_first; /* n's children: children[child_first[n] ..
                              child_first[n] + child_count[n]) */
    uint32_t *child_count;
    uint32_t *child_cap; /* the size of n's block */
    tclod_id *children;
    uint32_t children_cap, children_used, children_garbage;
    tclod_id *roots; /* ascending ids */
    uint32_t root_count;
    tclod_id *order; /* the indexed nodes, parents before children: made by
                        tclod_scene_prepare while a user reads it */
    uint32_t order_count;
    uint32_t order_version; /* node_version order describes, + 1; 0: none */
    uint32_t order_users;   /* users that read order (Robin Hood selectors,
                               schedulers) */
    /* the edit log: entry i has the sequence number log_base + i; entries
     * every user has seen are let go, and all of them when it is full (a user
     * that had not seen them then looks at its whole selection instead) */
    tclod_edit *log; /* node_cap entries */
    uint32_t log_count;
    uint64_t log_base;

    /* smooth quadtree, rebuilt when smooth objects changed */
    uint32_t smooth_index_cap;
    tclod_id *smooth_order; /* position -> smooth id, quadtree order (live ones) */
    uint32_t *smooth_pos;   /* smooth id -> position */
    tclod_smooth_node *qt;  /* 2 * smooth_index_cap nodes; qt[0] is the root */
    uint32_t qt_count;

    /* users, and the epoch removals are counted in */
    tclod_scene_user **users;
    uint32_t user_count, user_cap;
    uint32_t epoch;

    uint32_t version;        /* bumped by every change */
    uint32_t node_version;   /* bumped when nodes are added or removed */
    uint32_t smooth_version; /* bumped when smooth objects are added, removed or moved */
    uint32_t qt_version;     /* smooth_version the quadtree describes */
};

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

/* The public form of node n's bounds into *out (kind NONE without). */
void tclod_scene_public_bounds(const tclod_scene *s, tclod_id n, tclod_bounds *out);

/* A function of the solvers' inner loops that must be inlined where it is
 * called, whatever the compiler's estimate of its size. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define TCLOD_ALWAYS_INLINE static inline
#endif

/* A hint to fetch the cache line at p (to write it: _WRITE); nothing where
 * the compiler has none. */
#if defined(__GNUC__) || defined(__clang__)
#define TCLOD_PREFETCH(p) __builtin_prefetch(p)
#define TCLOD_PREFETCH_WRITE(p) __builtin_prefetch(p, 1)
#else
#define TCLOD_PREFETCH(p) ((void)0)
#define TCLOD_PREFETCH_WRITE(p) ((void)0)
#endif
/* How many slots ahead a walk over the cut fetches the node record it will
 * read: the cut lists nodes in no order of id, so each is a miss of its own
 * once the nodes outgrow the cache (docs/robin_hood.md, memory). */
#define TCLOD_CUT_AHEAD 16u

/* ---- view.c ---------------------------------------------------------------- */

/* A validated view, orthonormalised once per frame. */
typedef struct tclod_view_cache {
    double eye[3], forward[3], up[3], right[3];
    double cos_y, sin_y; /* of half the vertical field of view */
    double cos_x, sin_x; /* of half the horizontal field of view */
    double near_z, far_z;
    double focal;         /* f = (viewport_height / 2) / tan(fov_y / 2), pixels */
    double pi_focal2;     /* pi f² */
    double viewport_area; /* viewport_height² * aspect */
    double plane[4][3];   /* outward unit normals of the top, bottom, right and left
                             planes, which pass through the eye */
} tclod_view_cache;

/* Fills c from a view that passed tclod_view_validate. */
void tclod_view_cache_init(tclod_view_cache *c, const tclod_view *v);

/* Checks public bounds b and converts them to the solvers' form: *nb and,
 * for a box, *box (nb->box is left for the caller to set). Returns NULL, or
 * the rule b breaks (tclod_bounds_check). */
const char *tclod_bounds_convert(const tclod_bounds *b, tclod_node_bounds *nb, tclod_box *box);

/* The sphere of radius r centred at p (relative to the eye) meets the frustum
 * (view.c explains the planes). */
static inline int tclod_view_cache_visible(const tclod_view_cache *c, const double p[3], double r) {
    double z = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
    if (z < c->near_z - r || z > c->far_z + r)
        return 0;
    if (fabs(p[0] * c->up[0] + p[1] * c->up[1] + p[2] * c->up[2]) * c->cos_y - z * c->sin_y > r)
        return 0;
    return fabs(p[0] * c->right[0] + p[1] * c->right[1] + p[2] * c->right[2]) * c->cos_x -
               z * c->sin_x <=
           r;
}

/* The sphere of radius r centred at p (relative to the eye) lies so far inside
 * the frustum that every sphere within it passes tclod_view_cache_visible,
 * rounding included: each signed distance is at most -r less a margin far
 * above the rounding of the test (a sphere within it has its own distances
 * at most those plus r, which is Lipschitz with constant 1 in p). */
static inline int tclod_view_cache_inside(const tclod_view_cache *c, const double p[3], double r) {
    double z = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
    double rm = r + 1e-6 * (fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + r + c->far_z);
    if (z - rm < c->near_z || z + rm > c->far_z)
        return 0;
    if (fabs(p[0] * c->up[0] + p[1] * c->up[1] + p[2] * c->up[2]) * c->cos_y - z * c->sin_y > -rm)
        return 0;
    return fabs(p[0] * c->right[0] + p[1] * c->right[1] + p[2] * c->right[2]) * c->cos_x -
               z * c->sin_x <=
           -rm;
}

/* Projected area in px² of a sphere of radius r whose centre is d2 away from
 * the eye, squared; clamped to the viewport. */
static inline double tclod_view_cache_area(const tclod_view_cache *c, double d2, double r) {
    double r2 = r * r, area;
    if (d2 <= r2)
        return c->viewport_area;
    area = c->pi_focal2 * r2 / (d2 - r2);
    return area < c->viewport_area ? area : c->viewport_area;
}

/* Distance from the eye to a sphere of radius r whose centre is d2 away,
 * squared: 0 inside. */
static inline double tclod_sphere_distance(double d2, double r) {
    double d = sqrt(d2) - r;
    return d > 0.0 ? d : 0.0;
}

/* Projected area (0 outside the frustum) and distance (0 inside) of a box,
 * p its centre relative to the eye. */
void tclod_view_cache_measure_box(const tclod_view_cache *c, const double p[3],
                                  const tclod_box *box, float *area, double *distance);

/* Projected area (0 outside the frustum) and distance (to the volume, 0
 * inside) of node bounds b (with a bounded sphere: b->r >= 0); boxes from
 * boxes[]. */
static inline void tclod_view_measure_bounds(const tclod_view_cache *c, const tclod_node_bounds *b,
                                             const tclod_box *boxes, float *area,
                                             double *distance) {
    double p[3], r = b->r, d2;
    p[0] = b->c[0] - c->eye[0];
    p[1] = b->c[1] - c->eye[1];
    p[2] = b->c[2] - c->eye[2];
    if (b->box != TCLOD_NONE) {
        tclod_view_cache_measure_box(c, p, &boxes[b->box], area, distance);
        return;
    }
    d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    *distance = tclod_sphere_distance(d2, r);
    *area = tclod_view_cache_visible(c, p, r) ? (float)tclod_view_cache_area(c, d2, r) : 0.0f;
}

/* The same for a sphere given as floats (x, y, z, radius): smooth objects and
 * their groups. */
static inline void tclod_view_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                                      float *distance) {
    double p[3], r = (double)bounds[3], d2;
    p[0] = (double)bounds[0] - c->eye[0];
    p[1] = (double)bounds[1] - c->eye[1];
    p[2] = (double)bounds[2] - c->eye[2];
    d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    *distance = (float)tclod_sphere_distance(d2, r);
    *area = tclod_view_cache_visible(c, p, r) ? (float)tclod_view_cache_area(c, d2, r) : 0.0f;
}

/* Projected area (0 outside the frustum) and distance of valid public bounds
 * (kind NONE: -1 and -1). */
void tclod_view_cache_measure_any(const tclod_view_cache *c, const tclod_bounds *b, float *area,
                                  float *distance);

/* tclod_view_measure, out of line. */
void tclod_view_cache_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                              float *distance);

/* A public sphere for a float one (x, y, z, radius), for queries. */
static inline void tclod_sphere_bounds(const float b[4], tclod_bounds *out) {
    out->kind = TCLOD_BOUNDS_SPHERE;
    out->center[0] = (double)b[0];
    out->center[1] = (double)b[1];
    out->center[2] = (double)b[2];
    out->radius = (double)b[3];
}

/* ---- heap.c: indexed 4-ary max-heap ------------------------------------------- */

typedef struct tclod_heap_entry {
    double key;
    tclod_id id;
    uint32_t unused;
} tclod_heap_entry;

/* Orders ids by key, largest first; equal keys by smaller id first. The slot of
 * id i is pos[i] (TCLOD_NONE when absent), so an entry can be removed or
 * replaced in O(log n). */
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
/* Empties the heap, resetting the slots of its entries. */
void tclod_heap_clear(tclod_heap *h);

static inline int tclod_heap_contains(const tclod_heap *h, tclod_id id) {
    return h->pos[id] != TCLOD_NONE;
}

/* Sorts ids[0..n) in heap order (largest key first, ties by smaller id),
 * moving keys along. In place, no recursion. */
void tclod_sort_by_key(tclod_id *ids, double *keys, uint32_t n);

/* ---- selector.c / greedy.c / split.c / mixed.c ------------------------------- */

/* A variable at the line search's trial point, and at the one before it. */
typedef struct tclod_var_trial {
    double x, b, c, db, dc; /* resolution, callback values and slopes there */
    double qx, qdb;         /* the previous trial point's resolution and benefit slope */
} tclod_var_trial;

/* The preconditioner's model of a variable (mixed.c). */
typedef struct tclod_var_model {
    double x, db, beta;        /* benefit slope: anchor, slope there, exponent */
    double dc0, c1, dc1, xk;   /* cost: two lines meeting at the kink xk */
    double lxk, l0, l1;        /* ln xk, and ln of the targets at slope 1 before
                                  and after the kink */
    double lc;                 /* ln of the slope above which the part before the
                                  kink is the better choice */
    double ldc0, ldc1, lsetup; /* ln dc0, ln dc1 and ln (c1 - dc1), where positive */
} tclod_var_model;

/* The chain of single children starting at a node (an instance): where its
 * nodes lie in rh_chain, how many there are, and what prepare found out about
 * them once, so that a solve need not look again (TCLOD_RH_*). */
typedef struct tclod_rh_chain {
    uint32_t at, len;
    uint32_t flags;
    float reach;           /* a branch: every bounded child lies within this distance of
                              the last level's centre (rounded up); -1 when that level
                              has no bounds */
    uint32_t first, count; /* a branch: its children's range in the scene's children[]
                              (and in rh_child), so that placing them reads no
                              child_first[]; else 0, 0 */
} tclod_rh_chain;
enum {
    TCLOD_RH_CONSECUTIVE = 1u, /* level k is node head + k (rh_chain need not be read) */
    TCLOD_RH_SHARED = 2u,      /* every level has the head's bounds */
    TCLOD_RH_BRANCH = 4u,      /* the last level has several children */
    TCLOD_RH_NESTED = 8u       /* a branch whose children's sphere (reach) lies within
                                  that of the branch above the chain's head */
};
/* A branch's child as its instance: the child's slot in the scene's
 * children[], its id and its chain. */
typedef struct tclod_rh_child {
    uint32_t slot;
    tclod_id id;
    tclod_rh_chain chain;
} tclod_rh_child;

/* A branch whose children share the time of the instance that ended at it,
 * while they are placed. */
typedef struct tclod_rh_frame {
    uint32_t next, end; /* its next child to place and the end of its children, as
                           positions in rh_child (the scene's child range) */
    double extra;       /* time left beyond the children's simplest levels */
    double value_left;  /* value of the children not placed yet */
    double alloc, base; /* the time the branch's instance had, and its simplest
                           level's cost in the enclosing branch's accounting */
    int inside;         /* its children's sphere lies inside the frustum */
} tclod_rh_frame;

/* The smooth variables of one solve (split.c fills the first block, mixed.c
 * the rest), structure of arrays, one entry per variable; room for one
 * variable per smooth object. */
typedef struct tclod_vars {
    uint32_t count;
    uint32_t *first, *size; /* members: smooth order positions first .. first + size */
    float *bounds;          /* 4 per variable: the group's sphere */
    float *area, *distance; /* the query's screen_area and distance */
    double *r;              /* resolution in [0, 1] */
    double *b, *c;          /* callback values at r (counted only when r > 0) */
    double *db, *dc;        /* derivatives at max(r, TCLOD_SLOPE_FLOOR) */
    double *a;              /* search direction */
    double *ratio;          /* db / dc: the variable's own benefit/cost slope */
    double *up;             /* db / dc for a step up (the cost slope past the kink) */
    int fresh;              /* ratio and up are those of the current values (mixed.c) */
    /* mixed.c: while bounded, the models' predicted spend at every slope whose ln is at
     * least bound_log is at most bound; the next bound goes bound_reach (in ln) below the
     * slope tested */
    int bounded;
    double bound_log, bound, bound_reach;
    uint32_t *moving;       /* the variables of the current line search */
    uint8_t *state;         /* TCLOD_VAR_* */
    tclod_var_trial *trial; /* the line search's trial points */
    tclod_var_model *model; /* the preconditioner's model (mixed.c) */
} tclod_vars;

enum {
    TCLOD_VAR_LIVE = 0,   /* may move */
    TCLOD_VAR_DEAD = 1,   /* a bad benefit: invisible, stays at 0 */
    TCLOD_VAR_BLOCKED = 2 /* could not move within the budget; out of this solve */
};

/* The most decisions on one path of the greedy's search (restarts). */
#define TCLOD_SEARCH_DEPTH 32u

/* Smallest resolution at which derivatives are asked (a square-root benefit
 * has an infinite slope at 0). */
#define TCLOD_SLOPE_FLOOR 1e-9

/* Per-node flags (tclod_selector.flags): a root left out of the selection;
 * with lookahead, a cut node whose queued increment reaches below its
 * children (the greedy's JUMP), one whose increment gave way to a cut that
 * fits (REFIT), and a node below a cut node that its increment passes over
 * (REFINE: replaced by its children's cuts). */
enum {
    TCLOD_FLAG_DROPPED = 1u,
    TCLOD_FLAG_JUMP = 2u,
    TCLOD_FLAG_REFINE = 4u,
    TCLOD_FLAG_REFIT = 8u,
    TCLOD_FLAG_ABOVE = 16u /* while a warm start repairs its cut after the scene
                              changed: a node above the cut */
};

/* What a selector knows of one node, packed in one record because the solvers
 * touch these fields together at random ids (32 bytes: two records per cache
 * line, an object's levels in as few lines as can be). */
typedef struct tclod_node_state {
    double benefit, cost; /* callback values of this solve (stamp == solve_id);
                             cost 0 when invisible, +inf when unaffordable */
    uint32_t stamp;
    uint32_t cut_pos;     /* slot in cut[], or TCLOD_NONE */
    float area, distance; /* the query's screen_area and distance in this solve:
                             a child with the same bounds reuses them */
} tclod_node_state;

/* The greedy's increment of a node: its children (with lookahead, the cut its
 * key found) replace it, for delta_b more benefit and delta_c more cost. Apart
 * from the node records, which every solver reads. */
typedef struct tclod_delta {
    double delta_b, delta_c;
} tclod_delta;

/* Where a solve stands between two tclod_select_step calls: the state of the
 * solver's loops, so that a step resumes exactly where the last one paused. */
typedef struct tclod_resume {
    int phase;        /* the solver's stage; 0 = not started */
    int as_greedy;    /* mixed solver: no smooth variable, the greedy solves */
    int warm;         /* greedy: the solve started from the previous cut */
    int skipped;      /* an increment did not fit */
    int smooth_done;  /* papers' loop: the smooth variables stopped */
    int alt_pass;     /* mixed solver: the pass from the best skipped
                         increment's selection alone is under way (1) */
    uint32_t run;     /* smooth steps since the last increment */
    uint32_t k;       /* steps of a bounded stage, or the next instance */
    tclod_id matched; /* papers' loop: the increment whose slope was matched */
    double guess;     /* preconditioned loop: the last level */
    /* greedy, cold start: the skipped increment whose T(n) (the increment with
     * the increments above it) fits and gives the most benefit */
    tclod_id alt_node;
    double alt_benefit, alt_roots_b, alt_roots_c;
    double alt_roots_err; /* alt_roots_c's compensation (tclod_selector.cost_err) */
    int use_alt;
    /* greedy, cold start: the passes after the plain one (restarts). A pass
     * forces the increments of its decisions marked taken (with those above
     * them) and leaves out the others; the search below explores decisions
     * depth first. The current pass's decisions and the best pass's */
    tclod_id pick[TCLOD_SEARCH_DEPTH], best_pick[TCLOD_SEARCH_DEPTH];
    uint8_t take[TCLOD_SEARCH_DEPTH], best_take[TCLOD_SEARCH_DEPTH];
    uint32_t picks, best_picks, left_out; /* left_out: decisions not taken */
    uint32_t tries;                       /* passes made after the plain one */
    int searching;                        /* the passes are the search's (not the T(n) one) */
    int cut_is_best;                      /* the working cut is the best pass's */
    int infeasible;                       /* the current pass's decisions do not fit */
    double best_benefit;
    tclod_id misfit;      /* the current pass's first increment that did not fit */
    double lp_bound;      /* its benefit there plus the misfit's gain (0: none) */
    tclod_id root_misfit; /* the plain pass's, where the search begins */
    double root_bound;
    double misfit_key; /* the key of the current pass's first misfit */
    /* greedy, the plain cold pass: increments keyed at or above closure_key
     * wait in a queue (sel->scratch[closure_head .. closure_tail)) instead of
     * the heap and are taken first, while closure_cost (the roots' cost plus
     * every positive Δc taken from the queue) fits */
    int closing;
    uint32_t closure_head, closure_tail;
    double closure_key, closure_cost, closure_err; /* closure_err: closure_cost's
                                                      compensation, as cost_err */
    /* Robin Hood: time not shared out yet, value of the instances left */
    double pool, value_left;
    int limited; /* an instance could refine further */
    int held;    /* TCLOD_OVERFLOW_DRAW_ROOTS: the roots' simplest levels are held
                    out of the pool (they fit), or drawn over the budget (they do
                    not: overflowing) */
    int overflowing;
    int plain; /* the solve's heads take the common path (plain_heads) */
    /* Robin Hood's third cycle: the candidates' ring (robin_hood.c), the value
     * in it and the smallest step it holds (or a lower bound) ... */
    uint32_t ring_first, ring_count;
    double ring_value, min_step;
    double smooth_value;  /* ... the value and number of the smooth objects */
    uint32_t smooth_open; /* below resolution 1 ... */
    uint32_t pass_left;   /* ... the ring entries left in this pass */
    int refined;          /* ... whether it refined an instance, */
    uint32_t passes;      /* ... the passes begun and the pool at the */
    double pass_pool;     /* start of the last one */
} tclod_resume;

struct tclod_selector {
    tclod_scene *scene; /* read-only except for its lazy child index */
    tclod_allocator alloc;
    char error[TCLOD_ERROR_SIZE]; /* tclod_selector_last_error */
    tclod_selector_desc desc;
    int busy;              /* a solve is running: re-entry is refused */
    tclod_scene_user user; /* what the scene knows of this selector */
    int holds;             /* a begun solve holds the scene against changes (0 for a
                              scheduler's own selector, whose solve is begun again
                              when the scene changed) */

    /* per-node buffers, cap elements each */
    uint32_t cap;
    tclod_node_state *node;
    tclod_delta *delta; /* the greedy's increments */
    double *path;       /* 2 per node: benefit and cost of the increments
                           taken above it (cold solve) */
    uint8_t *flags;
    tclod_heap inc;                             /* increments, best Δb/Δc first */
    tclod_heap cheap;                           /* the same increments, smallest Δc first */
    int cheap_live;                             /* cheap holds every queued increment */
    tclod_heap dec;                             /* decrements, least loss per saved cost first */
    uint32_t *inc_slot, *cheap_slot, *dec_slot; /* the greedy's heap slots, in dense
                                  arrays: moving heap entries touches few lines */
    tclod_heap_entry *inc_block, *cheap_block, *dec_block; /* the heaps' entries start
                                  inside these, where a slot's four children share
                                  one cache line (cap >= nodes + 3) */
    tclod_id *cut, *prev_cut, *result, *scratch;
    tclod_id *drawn; /* the result as tclod_selector_cut lists it: self leaves as
                        their additive nodes (result itself when it has none) */
    int drawn_is_result;
    double *scratch_key;

    /* per-smooth-object buffers, smooth_cap elements each */
    uint32_t smooth_cap;
    tclod_vars vars;            /* the solve's variables */
    tclod_smooth_group *groups; /* the committed smooth result */
    uint32_t group_count;
    uint32_t *split_node;          /* split.c's stack: quadtree nodes ... */
    double *split_x, *split_theta; /* ... their expected resolution and loss share */
    uint32_t *split_order;         /* split.c, per quadtree node (2 per object): the inner
                                      nodes reached, in order; and by node: */
    double *split_c, *split_q;     /* the sums of its visible objects' benefit scales
                                      and of their squares, */
    uint8_t *split_whole;          /* 1 when all of its objects are visible */

    /* Robin Hood (robin_hood.c): rh_cap elements each, rh_cap >= nodes + smooth */
    uint32_t rh_cap;
    uint32_t rh_version; /* scene version the chains and the order describe; 0: none */
    uint32_t rh_order_count;
    uint32_t *rh_first;        /* the scene's child index as of the last scene change, */
    tclod_id *rh_kids;         /* contiguous in id order (robin_hood.c) */
    uint32_t *rh_chain;        /* every chain of single children, coarse to fine, end to end */
    tclod_rh_chain *rh_chains; /* per node that starts a chain: the chain */
    tclod_rh_child *rh_child;  /* per node with several children: them, least complex
                                  first (in the scene's child ranges) */
    uint32_t *rh_order;        /* the instances, least complex first: root ids, and smooth
                                  ids + node count */
    double *rh_key;            /* 2 per element: complexities and order keys while
                                  sorting; then this frame's values by order position
                                  (first half) and the cost of each cut slot (second
                                  half) */
    tclod_rh_frame *rh_stack;  /* the branches being shared out */
    uint8_t *rh_level;         /* per node that starts a chain: the level the chain
                                  took last (at most 255), where the next search
                                  starts */
    /* The Robin Hood solver also keeps, in the per-node buffers it does not
     * otherwise use: the values of a branch's children in scratch_key, by slot
     * in the scene's children[] (-1: not visible); the ring of its third cycle's candidates in
     * scratch and path. */

    uint32_t cut_count, prev_count, result_count;
    uint32_t solve_id;
    uint32_t scene_version;  /* scene version the cut belongs to */
    uint32_t node_version;   /* the scene's node version the cut belongs to */
    uint32_t smooth_version; /* the smooth version the groups belong to */
    int has_cut;             /* cut/prev_cut describe a selection (of that node version,
                                or repaired to the scene's at the next warm start) */

    /* the solve in progress */
    int pending;              /* begun and not finished, cancelled or failed */
    uint32_t pending_version; /* scene version at its beginning */
    uint32_t begin_epoch;     /* the scene's epoch at its beginning */
    tclod_frame frame_data;   /* the frame it solves, copied at its beginning ... */
    tclod_view view_data;     /* ... with its view */
    tclod_resume resume;
    int paused;                /* the step's slice ran out */
    int stopped;               /* the frame's limit was reached, or the caller
                                  finished the solve early */
    double slice_end;          /* clock at which the step's slice ends; 0: none */
    uint32_t slice_iterations; /* iteration count at which it ends; 0: none */
    uint32_t step_start;       /* iteration count at the step's beginning */
    double elapsed;            /* time spent in the solve's earlier steps */
    const tclod_frame *frame;  /* &frame_data while a step runs, else NULL */
    tclod_query query;         /* a node's query while a step runs: the frame's view,
                                  count 1, no members; tclod_evaluate_measured sets the
                                  rest */
    tclod_bounds qbounds;      /* the volume the query points at */
    tclod_view_cache view;
    int has_view;
    int failed;      /* strict mode: a bad callback value was seen */
    double cost_sum; /* running: finite costs of visible, kept cut nodes */
    double cost_err; /* running: what rounding took from cost_sum
                        (tclod_add_compensated), so that cost_sum + cost_err is
                        their total to within rounding of the total, absorbed
                        costs included */
    double reserved; /* running: cost held by smooth variables (mixed) */
    double benefit_sum;
    uint32_t unaffordable; /* visible, kept cut nodes with infinite cost */
    double start_time;
    uint64_t begin_log;  /* the edit log's end at the solve's beginning */
    double closure_hint; /* the key of the last plain cold pass's first misfit:
                            DBL_MIN when it had none, 0 before the first */
    tclod_stats stats;
    struct tclod_selector_saved *keep; /* see tclod_selector_keep; NULL: none */
};

/* Whether the selector can solve its scene as it is now: the mixed solver
 * created without smooth callbacks needs a scene without smooth objects. */
int tclod_selector_scene_ok(const tclod_selector *sel);

/* Prepares the scene and grows the selector's buffers to its size, all or
 * nothing (what tclod_select_begin allocates, and nothing else): afterwards
 * a begin allocates nothing until the scene grows. */
tclod_status tclod_selector_reserve(tclod_selector *sel);

/* A selector's committed result and warm-start state, as a scheduler keeps
 * it so that a failed update can put it back (schedule.c). The arrays are
 * the keeper's: cut and result with room for the scene's nodes, groups for
 * its smooth objects. */
typedef struct tclod_selector_saved {
    tclod_id *cut, *result, *drawn;
    tclod_smooth_group *groups;
    uint32_t cut_count, result_count, group_count;
    uint32_t scene_version, node_version, smooth_version;
    int drawn_is_result;
    uint32_t synced;   /* the selector's tclod_scene_user.synced ... */
    uint64_t log_seen; /* ... and log_seen */
    int has_cut;
    double closure_hint; /* as it was when the keeping began */
    int valid;           /* a commit has happened since: the fields above hold
                            the state before it */
} tclod_selector_saved;

/* Begins keeping (k not NULL) or stops (NULL): from now on the first commit
 * first copies the committed state into k, so that tclod_selector_restore
 * can put back the state of the moment this was called. */
void tclod_selector_keep(tclod_selector *sel, tclod_selector_saved *k);

/* Puts back the state kept in k (no solve may be pending): the committed
 * result, the warm start's cut and the greedy's closure hint. */
void tclod_selector_restore(tclod_selector *sel, const tclod_selector_saved *k);

/* Calls the benefit and cost callbacks for node n once per solve and caches
 * the values in sel->node[n] (cost asked only when the benefit is > 0; a bad
 * benefit counts as 0, a bad cost as +inf). Returns 0, or -1 when strict mode
 * saw a bad value. */
int tclod_evaluate_node(tclod_selector *sel, tclod_id n);

/* Counts a bad callback value (and fails the solve in strict mode). */
void tclod_bad_value(tclod_selector *sel);

/* What tclod_evaluate_measured does with a benefit that is not positive and
 * finite (0, -0, negative, NaN or infinite): the bad ones count (and fail a
 * strict solve) and give 0; the node is invisible, its cost 0. Returns 0, or
 * -1 when strict mode saw a bad value. */
int tclod_evaluate_invisible(tclod_selector *sel, tclod_node_state *st, double b);

/* What tclod_evaluate_measured does with a cost that is not in [0, +inf)
 * (-0 passes, a bad one counts, fails a strict solve and gives +inf) of a
 * visible node. Returns 1, or -1 when strict mode saw a bad value. */
int tclod_evaluate_bad_cost(tclod_selector *sel, tclod_node_state *st, double c);

/* The bits of a double, for the range checks of callback values: as unsigned
 * integers the positive finite doubles are 1 ... TCLOD_BITS_MAX, +0 is 0 and
 * +inf is TCLOD_BITS_MAX + 1; every negative one, NaN or -0 lies above. */
#define TCLOD_BITS_MAX UINT64_C(0x7fefffffffffffff)
static inline uint64_t tclod_bits(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof(u));
    return u;
}

/* Node n is a self leaf (an additive node's own drawing among its children):
 * it takes its owner's values, evaluating the owner first if needed, with no
 * callback of its own; the query is left as the owner's. Returns as
 * tclod_evaluate_bounded. */
int tclod_evaluate_self(tclod_selector *sel, tclod_id n);

/* Puts node n's bounds (it has some) into the query's volume. */
static inline const tclod_bounds *tclod_query_bounds(tclod_selector *sel, tclod_id n) {
    const tclod_node_bounds *b = &sel->scene->bounds[n];
    tclod_bounds *q = &sel->qbounds;
    if (b->box != TCLOD_NONE) {
        tclod_scene_public_bounds(sel->scene, n, q);
        return q;
    }
    q->kind = TCLOD_BOUNDS_SPHERE; /* a self leaf is evaluated as its owner */
    q->center[0] = b->c[0];
    q->center[1] = b->c[1];
    q->center[2] = b->c[2];
    q->radius = b->r;
    return q;
}

/* The callbacks of node n, not evaluated in this solve yet, with the screen
 * area and distance of its bounds already measured (-1 without bounds or
 * view); `bounded`: n has bounds, which the query then carries: what
 * tclod_evaluate_node does once it has measured. Inline for the solvers'
 * inner loops; what is not a positive finite benefit and a finite cost >= 0,
 * and self leaves, go out of line. Returns 1 when n is visible, 0 when not, -1
 * when strict mode saw a bad value. */
static inline int tclod_evaluate_bounded(tclod_selector *sel, tclod_id n, float area,
                                         double distance, int bounded) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_node_state *st = &sel->node[n];
    tclod_query *q = &sel->query; /* view, count and members set for the solve */
    double b, c;
    if (sel->scene->bounds[n].kind & TCLOD_BOUNDS_SELF)
        return tclod_evaluate_self(sel, n);
    st->stamp = sel->solve_id;
    st->area = area;
    st->distance = (float)distance;
    q->id = n;
    q->screen_area = area;
    q->distance = st->distance;
    q->bounds = bounded ? tclod_query_bounds(sel, n) : NULL;
    sel->stats.evaluations++;
    b = cb->benefit(cb->user, q);
    if (tclod_bits(b) - 1u >= TCLOD_BITS_MAX)
        return tclod_evaluate_invisible(sel, st, b);
    c = cb->cost(cb->user, q);
    st->benefit = b;
    if (tclod_bits(c) > TCLOD_BITS_MAX)
        return tclod_evaluate_bad_cost(sel, st, c);
    st->cost = c;
    return 1;
}

/* tclod_evaluate_bounded with whether n has bounds found in the scene. */
static inline int tclod_evaluate_seen(tclod_selector *sel, tclod_id n, float area,
                                      double distance) {
    return tclod_evaluate_bounded(sel, n, area, distance, sel->scene->bounds[n].r >= 0.0);
}

/* tclod_evaluate_seen, returning 0 whether or not n is visible. */
static inline int tclod_evaluate_measured(tclod_selector *sel, tclod_id n, float area,
                                          double distance) {
    return tclod_evaluate_seen(sel, n, area, distance) < 0 ? -1 : 0;
}

/* Adds x to the running sum *s, keeping in *e what rounding took from it:
 * (a - t) + x is exactly the rounding error of t = a + x when |a| >= |x|,
 * which a running sum of costs meets but for its first terms (there the
 * error found is off by an ulp of t or so). So *s + *e is the sum to within
 * rounding of the total, also when *s has absorbed terms below half its ulp.
 * An infinite sum makes *e NaN or infinite, which tclod_within then ignores. */
static inline void tclod_add_compensated(double *s, double *e, double x) {
    double a = *s, t = a + x;
    *e += (a - t) + x;
    *s = t;
}

/* A fit test of the cut's running cost: `total` (cost_sum and what is added
 * to it, as the caller sums it) is within `limit`, and so is it with cost_err,
 * the rounding the running sum lost, added. Where cost_sum is exact (cost_err
 * 0) this is the plain test total <= limit; otherwise it refuses what fits
 * only because the running sum absorbed costs, and never admits what the
 * plain test refuses. (cost_err is NaN only after an infinite sum, which the
 * plain test refuses.) */
static inline int tclod_within(const tclod_selector *sel, double total, double limit) {
    return total <= limit && total + sel->cost_err <= limit;
}

/* Runs TCLOD_SOLVER_GREEDY for sel->frame into the working cut, from where
 * sel->resume says it stands. Returns TCLOD_OK or TCLOD_ERR_CALLBACK (strict);
 * the caller commits or rolls back. With TCLOD_OK and sel->paused set, the
 * step's slice ran out: the solve is not finished, and the working state is
 * feasible. */
tclod_status tclod_greedy_solve(tclod_selector *sel);

/* The greedy's steps, for the mixed solver. Each returns 0, or -1 when strict
 * mode saw a bad callback value. The budget left to the cut is the frame's
 * budget minus sel->reserved. */
int tclod_greedy_start(tclod_selector *sel); /* cut = the roots, increments queued */
/* The best queued increment that fits (ratio in *ratio), discarding those that
 * do not fit and never will; TCLOD_NONE when none fits. *skipped is set to 1
 * when an increment was discarded or none fits while some are queued. */
tclod_id tclod_greedy_candidate(tclod_selector *sel, double *ratio, int *skipped);
int tclod_greedy_take(tclod_selector *sel, tclod_id n); /* applies a candidate */
void tclod_greedy_skip(tclod_selector *sel);            /* drops the best candidate */
/* The greedy's safeguard for the mixed solver: after tclod_greedy_start,
 * tclod_greedy_track records every increment that candidate and skip drop
 * (and, in tclod_greedy_alternative, those still queued) with the increments
 * above it, as a cold greedy solve does. tclod_greedy_alternative returns the
 * one whose selection alone (the roots, it and those above it) fits the
 * budget and is worth most, with that worth in *benefit; TCLOD_NONE when none
 * fits, or when roots were dropped or restarts is 0. tclod_greedy_force
 * starts from the roots again with n's increment and those above it taken. */
void tclod_greedy_track(tclod_selector *sel);
tclod_id tclod_greedy_alternative(tclod_selector *sel, double *benefit);
int tclod_greedy_force(tclod_selector *sel, tclod_id n);
/* Repairs the exact sum of the cut's costs to be within the budget. */
int tclod_greedy_enforce(tclod_selector *sel);
void tclod_greedy_end(tclod_selector *sel); /* empties the heaps after a solve */
/* 1 when the search must stop: the frame's limit (sets stop_reason and
 * sel->stopped; final) or the step's slice (sets sel->paused; the solver
 * returns and resumes from sel->resume at the next step). */
int tclod_out_of_time(tclod_selector *sel);

/* Calls the host's smooth callbacks for the group of smooth order positions
 * first .. first + count at resolution x in (0, 1] (the query carries area and
 * distance, measured on bounds: the group's sphere, or NULL for a single
 * object's own bounds) and sanitises what they return: a bad benefit gives *b = *db = 0,
 * a bad benefit slope *db = 0, a bad cost *c = +inf, a bad cost slope
 * *dc = +inf; each is counted, and sets sel->failed in strict mode. Slopes are
 * asked at max(x, TCLOD_SLOPE_FLOOR). c and dc may be NULL: no cost asked;
 * b and db may be NULL: no benefit asked. Returns 1 when the benefit was bad,
 * else 0. */
int tclod_smooth_call(tclod_selector *sel, uint32_t first, uint32_t count, const float *bounds,
                      float area, float distance, double x, double *b, double *db, double *c,
                      double *dc);

/* split.c: the variables of this frame: the smooth quadtree is culled against
 * the view and, with desc.split_smooth, split while the predicted loss of a
 * shared variable exceeds its share of the threshold. Returns 0 or -1 (strict
 * error). */
int tclod_split_variables(tclod_selector *sel);

/* mixed.c: TCLOD_SOLVER_MIXED; returns as tclod_greedy_solve. */
tclod_status tclod_mixed_solve(tclod_selector *sel);

/* robin_hood.c: TCLOD_SOLVER_ROBIN_HOOD; returns as tclod_greedy_solve. */
tclod_status tclod_robin_hood_solve(tclod_selector *sel);

#endif /* TCLOD_INTERNAL_H */
