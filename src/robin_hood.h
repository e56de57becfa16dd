/*
 * robin_hood.c: TCLOD_SOLVER_ROBIN_HOOD's chains and instances.
 */
#ifndef TCLOD_ROBIN_HOOD_H
#define TCLOD_ROBIN_HOOD_H

#include "internal.h"

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

/* robin_hood.c: TCLOD_SOLVER_ROBIN_HOOD; returns as tclod_greedy_solve. */
tclod_status tclod_robin_hood_solve(tclod_selector *sel);

#endif /* TCLOD_ROBIN_HOOD_H */
