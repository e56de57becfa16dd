/*
 * mixed.c and split.c: TCLOD_SOLVER_MIXED's smooth variables.
 */
#ifndef TCLOD_MIXED_H
#define TCLOD_MIXED_H

#include "../core/internal.h"

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

/* What the mixed solver keeps between solves (tclod_selector.mixed): the
 * variables and split.c's work arrays, per-smooth-object buffers of the
 * selector (tclod_mixed_buffers). */
typedef struct tclod_mixed_state {
    tclod_vars vars;               /* the solve's variables */
    uint32_t *split_node;          /* split.c's stack: quadtree nodes ... */
    double *split_x, *split_theta; /* ... their expected resolution and loss share */
    uint32_t *split_order;         /* split.c, per quadtree node (2 per object): the inner
                                      nodes reached, in order; and by node: */
    double *split_c, *split_q;     /* the sums of its visible objects' benefit scales
                                      and of their squares, */
    uint8_t *split_whole;          /* 1 when all of its objects are visible */
} tclod_mixed_state;

/* Lists the mixed solver's per-smooth-object buffers into out (room for
 * TCLOD_MAX_ARRAYS); returns how many. */
size_t tclod_mixed_buffers(tclod_mixed_state *m, tclod_array *out);

/* Where a mixed solve stands (tclod_resume.mixed). */
typedef struct tclod_mixed_resume {
    int as_greedy;    /* no smooth variable: the greedy solves */
    int smooth_done;  /* papers' loop: the smooth variables stopped */
    int alt_pass;     /* the pass from the best skipped increment's selection
                         alone is under way (1) */
    uint32_t run;     /* smooth steps since the last increment */
    tclod_id matched; /* papers' loop: the increment whose slope was matched */
    double guess;     /* preconditioned loop: the last level */
} tclod_mixed_resume;

/* Smallest resolution at which derivatives are asked (a square-root benefit
 * has an infinite slope at 0). */
#define TCLOD_SLOPE_FLOOR 1e-9

/* split.c: the variables of this frame: the smooth quadtree is culled against
 * the view and, with desc.split_smooth, split while the predicted loss of a
 * shared variable exceeds its share of the threshold. Returns 0 or -1 (strict
 * error). */
int tclod_split_variables(tclod_selector *sel);

/* mixed.c: TCLOD_SOLVER_MIXED; returns as tclod_greedy_solve. */
tclod_status tclod_mixed_solve(tclod_selector *sel);

#endif /* TCLOD_MIXED_H */
