/*
 * What the scheduler's two files share (schedule.c: its desc, prediction,
 * buffers and selections; schedule_pipeline.c: the relations between cuts,
 * the plans, the draw list and the pipeline): the scheduler's state and the
 * steps both take.
 */
#ifndef TCLOD_SCHEDULE_INTERNAL_H
#define TCLOD_SCHEDULE_INTERNAL_H

#include "../select/selector.h"

/* Views kept for the prediction. */
#define HISTORY 16u
/* Largest field of view of the conservative camera, radians (179 degrees). */
#define MAX_FOV 3.12413936106985
/* A gap between updates longer than this many intervals restarts the pipeline. */
#define MAX_GAP 3.0

/* The kinds of region of a plan. */
enum { REGION_STATIC = 0, REGION_UP = 1, REGION_DOWN = 2 };

/* One part of the hierarchies in the current interval: a node q and the
 * nodes below it that the interval starts or ends with. */
typedef struct region {
    tclod_id root;         /* q: the coarse side of a morph */
    uint32_t kind;         /* REGION_* */
    uint32_t first, count; /* the nodes drawn (static) or the fine side (morph) in
                            sch->nodes */
    uint32_t depth;        /* morph: levels between q and its deepest fine node */
} region;

/* Generations kept: the three the pipeline works with, the three the outputs
 * show (the same unless an update is under way), and one for a selection
 * that has finished and waits to land. An update that crosses several
 * boundaries lands one selection at each, leaving the pipeline a slot ahead
 * of the outputs every time; it can cross four before it restarts, and the
 * seven slots hold that. */
#define GEN_SLOTS 7u

/* A landed selection: its visible cut with the costs of this selection, the
 * resolution of every smooth object and the costs of its smooth groups. */
typedef struct generation {
    tclod_id *ids;
    double *cost;
    uint32_t count;
    double *res;
    double *group_cost;
    uint32_t groups;
} generation;

/* The plan of an interval: its regions and the predicted costs of the nodes
 * they draw. Two are kept, the one the outputs were made with and the one an
 * update makes, so that a failed update leaves the first as it was. */
typedef struct plan_state {
    region *regions;
    uint32_t region_count;
    tclod_id *nodes;     /* 3 per node: the regions' node lists */
    double *memo_cost;   /* predicted cost of a node for the plan */
    uint32_t *memo_mark; /* epoch marks of memo_cost */
    uint8_t *memo_visible;
    uint32_t memo_epoch;
} plan_state;

/* The plan in use. */
#define PLAN(sch) ((sch)->p.plan)

/* The views the callbacks answer for, set when a selection begins. */
typedef struct solve_views {
    uint32_t count;
    tclod_view views[TCLOD_MAX_SAMPLES];
    tclod_view_cache caches[TCLOD_MAX_SAMPLES];
    tclod_view conservative; /* the solve's frame view */
    tclod_view_cache conservative_cache;
} solve_views;

/* What an update changes besides the buffers. tclod_scheduler_update keeps a
 * copy from its start and puts it back when it fails, so that the next update
 * goes on as if the failed one had not been made. */
typedef struct pipeline {
    int started;
    double boundary;                    /* b_j, the start of the current interval */
    double now, budget;                 /* of the last update; budget in cost units */
    uint32_t node_version;              /* the scene's node version the landed selections
                                           were purged to */
    uint32_t smooth_version;            /* and its smooth version */
    uint32_t residency_version;         /* the scene's residency version the landed
                                           selections and the plan were checked at */
    uint32_t prev, cur, next;           /* S_{j-1}, S_j, S_{j+1} in gen[] (may coincide) */
    int ready;                          /* the pending selection finished: it lands next, ... */
    uint32_t landing;                   /* ... from gen[landing] */
    uint32_t landed_invalid;            /* the bad values it saw ... */
    double landed_benefit, landed_cost; /* ... and its benefit and cost */
    double u;                           /* position in the current interval, [0, 1] */
    struct plan_state *plan;            /* the plan in use, one of plans[] */
    double pending_budget;              /* the budget the pending selection began with */
    int lost;                           /* the pending selection went with a failed update:
                                           the next update begins it again */
    int redo;                           /* the pending selection is one begun again: it runs
                                           to its end when it lands */
    uint32_t hist_count, hist_next;     /* the recorded camera path's ring */
    tclod_scheduler_stats stats;
} pipeline;

struct tclod_scheduler {
    tclod_allocator alloc;
    char error[TCLOD_ERROR_SIZE]; /* tclod_scheduler_last_error */
    tclod_scheduler_desc desc;
    tclod_callbacks host; /* the host's callbacks */
    tclod_scene *scene;
    tclod_selector *sel; /* solves with the callbacks below */
    tclod_calib *calib;
    int busy;
    tclod_scene_user user; /* what the scene knows of this scheduler */

    /* the views the callbacks answer for */
    int current_only; /* pass the host's values through */
    solve_views sv;
    tclod_id asked;      /* the node of the last benefit call ... */
    uint32_t asked_mask; /* ... and the views that saw it (benefit > 0) */

    /* the recorded camera path, a ring (its count and next slot in p) */
    double hist_t[HISTORY];
    tclod_view hist_v[HISTORY];

    pipeline p;
    generation gen[GEN_SLOTS];
    plan_state plans[2];
    int failed;         /* strict mode: the scheduler's own evaluations saw a
                           bad value during this update */
    int smooth_removed; /* smooth objects were removed since the landed
                           selections: their resolutions go to 0 when the
                           update succeeds */

    /* what a failed update puts back: the pipeline, the views (once a
     * selection began), the slot the update recorded into, and the
     * selector's committed state (kept by the selector before its first
     * commit in the update) */
    pipeline saved;
    solve_views saved_views;
    int views_saved;
    double saved_hist_t;
    tclod_view saved_hist_v;
    int touched;          /* the update called the selector */
    int pending_at_start; /* a selection was pending when it began */
    tclod_selector_saved kept;

    /* what the outputs show: the last successful update's */
    struct {
        int started;
        uint32_t prev, cur, next;
        double u;
        uint32_t items; /* which of items[] */
        tclod_scheduler_stats stats;
    } shown;

    /* per node, node_cap elements */
    uint32_t node_cap;
    uint32_t *depth;
    uint32_t depth_version;                    /* scene version depth[] describes, +1; 0 none */
    uint32_t *mark_a, *mark_b, *mark_c, *done; /* epoch marks */
    uint32_t *region_of, *region_mark;
    uint32_t epoch;
    tclod_id *list_x, *list_y; /* X_j and Y_j, or other pairs of cuts */
    tclod_id *list_r;          /* the region roots; during a selector call, the nodes
                                  its plan keeps (stream.keep) */
    uint32_t *counts;          /* 3 per node: per-region counts while bucketing */
    tclod_draw *items[2];      /* 3 per node each: the shown draw list, and the next */
    uint32_t item_count[2];
    uint32_t back; /* the one being made */

    /* per smooth object, smooth_cap elements */
    uint32_t smooth_cap;
};

static inline int schedule_finite_nonnegative(double x) {
    return x >= 0.0 && !isinf(x);
}

/* ---- the callbacks the selector calls ------------------------------------------------- */

static inline int schedule_value_bad(double v) {
    return !(v >= 0.0) || isinf(v);
}

/* Begins the selection for the target interval of the current boundary. */
tclod_status tclod_schedule_begin(tclod_scheduler *sch, const tclod_view *view);

/* Begins again the selection a failed update lost, with the views and the
 * budget it began with; it runs to its end when it lands. */
tclod_status tclod_schedule_begin_again(tclod_scheduler *sch);

/* A generation slot neither the pipeline nor the outputs use. */
uint32_t tclod_schedule_fresh_slot(const tclod_scheduler *sch);

/* A fresh epoch for the relation marks; they are cleared when it wraps. */
uint32_t tclod_schedule_next_epoch(tclod_scheduler *sch);

/* A fresh epoch for the predicted costs of a plan. */
uint32_t tclod_schedule_next_memo_epoch(tclod_scheduler *sch);

void tclod_schedule_record(tclod_scheduler *sch, double now, const tclod_view *view);

/* Grows the per-node and per-smooth-object buffers, the scheduler's and its
 * selector's, to the scene's size, all or nothing: the scheduler's are
 * allocated first and replace the old ones only once the selector's have
 * grown too, so that a failure leaves every buffer as it was. Afterwards
 * nothing in the update allocates. */
tclod_status tclod_schedule_reserve(tclod_scheduler *sch);

/* Copies the selector's result into generation g, with its costs. */
void tclod_schedule_store(tclod_scheduler *sch, uint32_t g);

/* The depth of every node in the index, when nodes were added or removed. */
void tclod_schedule_update_depths(tclod_scheduler *sch);

double tclod_schedule_wrap_benefit(void *user, const tclod_query *q);

double tclod_schedule_wrap_cost(void *user, const tclod_query *q);

/* Makes the plan in use one the update may write: not the one the outputs
 * were made with, which a failed update must leave as it was. */
void tclod_schedule_writable_plan(tclod_scheduler *sch);

#endif /* TCLOD_SCHEDULE_INTERNAL_H */
