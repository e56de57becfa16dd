/*
 * robin_hood.c: TCLOD_SOLVER_ROBIN_HOOD's chains and instances.
 */
#ifndef TCLOD_ROBIN_HOOD_H
#define TCLOD_ROBIN_HOOD_H

#include "../core/internal.h"

/* The chain of single children starting at a node (an instance): where its
 * nodes lie in rh.chain, how many there are, and what prepare found out about
 * them once, so that a solve need not look again (TCLOD_RH_*). */
typedef struct tclod_rh_chain {
    uint32_t at, len;
    uint32_t flags;
    float reach;           /* a branch: every bounded child lies within this distance of
                              the last level's centre (rounded up); -1 when that level
                              has no bounds */
    uint32_t first, count; /* a branch: its children's range in the scene's children[]
                              (and in rh.child), so that placing them reads no
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
                           positions in rh.child (the scene's child range) */
    double extra;       /* time left beyond the children's simplest levels */
    double value_left;  /* value of the children not placed yet */
    double alloc, base; /* the time the branch's instance had, and its simplest
                           level's cost in the enclosing branch's accounting */
    int inside;         /* its children's sphere lies inside the frustum */
} tclod_rh_frame;

/* What the Robin Hood solver keeps between solves (tclod_selector.rh): its
 * buffers, cap elements each (tclod_rh_buffers), cap >= nodes + smooth + 1. */
typedef struct tclod_rh_state {
    uint32_t cap;
    uint32_t version; /* scene version the chains and the order describe; 0: none */
    uint32_t order_count;
    uint32_t *first;        /* the scene's child index as of the last scene change, */
    tclod_id *kids;         /* contiguous in id order (robin_hood.c) */
    uint32_t *chain;        /* every chain of single children, coarse to fine, end to end */
    tclod_rh_chain *chains; /* per node that starts a chain: the chain */
    tclod_rh_child *child;  /* per node with several children: them, least complex
                               first (in the scene's child ranges) */
    uint32_t *order;        /* the instances, least complex first: root ids, and smooth
                               ids + node count */
    double *key;            /* 2 per element: complexities and order keys while
                               sorting; then this frame's values by order position
                               (first half) and the cost of each cut slot (second
                               half) */
    tclod_rh_frame *stack;  /* the branches being shared out */
    uint8_t *level;         /* per node that starts a chain: the level the chain
                               took last (at most 255), where the next search
                               starts */
} tclod_rh_state;

/* Lists the Robin Hood solver's buffers into out (room for
 * TCLOD_MAX_ARRAYS); returns how many. */
size_t tclod_rh_buffers(tclod_rh_state *rh, tclod_array *out);

/* Where a Robin Hood solve stands (tclod_resume.rh). */
typedef struct tclod_rh_resume {
    /* time not shared out yet, value of the instances left */
    double pool, value_left;
    int limited; /* an instance could refine further */
    int held;    /* TCLOD_OVERFLOW_DRAW_ROOTS: the roots' simplest levels are held
                    out of the pool (they fit), or drawn over the budget (they do
                    not: overflowing) */
    int overflowing;
    int plain;   /* the solve's heads take the common path (plain_heads) */
    int streams; /* the scene has nodes that are not resident (resident_levels) */
    /* the third cycle: the candidates' ring (robin_hood.c), the value in it
     * and the smallest step it holds (or a lower bound) ... */
    uint32_t ring_first, ring_count;
    double ring_value, min_step;
    double smooth_value;  /* ... the value and number of the smooth objects */
    uint32_t smooth_open; /* below resolution 1 ... */
    uint32_t pass_left;   /* ... the ring entries left in this pass */
    int refined;          /* ... whether it refined an instance, */
    uint32_t passes;      /* ... the passes begun and the pool at the */
    double pass_pool;     /* start of the last one */
} tclod_rh_resume;

/* robin_hood.c: TCLOD_SOLVER_ROBIN_HOOD; returns as tclod_greedy_solve. */
tclod_status tclod_robin_hood_solve(tclod_selector *sel);

#endif /* TCLOD_ROBIN_HOOD_H */
