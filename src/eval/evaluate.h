/*
 * The evaluation layer (evaluate.c): the selector's state, which the layers
 * from here up work in (it holds each solver's and the plan's state, whose
 * types their headers give: types only, no call goes up), the evaluation of
 * nodes and smooth objects that every solver shares (the common path inline),
 * batches, and residency as the solvers see it.
 */
#ifndef TCLOD_EVALUATE_H
#define TCLOD_EVALUATE_H

#include "../core/heap.h"
#include "../core/scene.h"
#include "../plan/stream.h"
#include "../solve/greedy/greedy.h"
#include "../solve/mixed.h"
#include "../solve/robin_hood.h"

#include <float.h>
#include <string.h>

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
    TCLOD_FLAG_ABOVE = 16u,    /* while a warm start repairs its cut after the scene
                                  changed: a node above the cut */
    TCLOD_FLAG_MOVED = 64u,    /* a cut node put where the cut's order by id may not hold
                                  (appended, or moved into a hole) since a warm start
                                  sorted it (sort_cut) */
    TCLOD_FLAG_CULL = 32u,     /* while a warm start repairs its cut against residency:
                                  a node above the cut whose subtree leaves it */
    TCLOD_FLAG_COLLAPSE = 128u /* while a batching warm start keys its frontier: a cut
                                  node whose parent it found collapsible (from its
                                  first child) and gathered */
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

/* Batch evaluation (evaluate.c): nodes are gathered into a list of at most
 * TCLOD_GATHER ids, which is evaluated when full or when the solver needs the
 * values, in chunks of TCLOD_BATCH_CHUNK nodes, the ranges a task splits
 * into. */
#define TCLOD_GATHER 8192u
#define TCLOD_BATCH_CHUNK 256u

/* A worker's scratch for one chunk, and what it counts for the solve. */
typedef struct tclod_batch_worker {
    uint32_t invalid;     /* bad callback values seen */
    uint32_t absent;      /* visible nodes seen not resident */
    uint32_t repeated;    /* nodes of its ranges an earlier range had evaluated */
    tclod_query query;    /* the per-node callbacks' query ... */
    tclod_bounds qbounds; /* ... and its volume */
    double px[TCLOD_BATCH_CHUNK], py[TCLOD_BATCH_CHUNK], pz[TCLOD_BATCH_CHUNK];
    double pr[TCLOD_BATCH_CHUNK];
    double benefit[TCLOD_BATCH_CHUNK], cost[TCLOD_BATCH_CHUNK];
    float area[TCLOD_BATCH_CHUNK], dist[TCLOD_BATCH_CHUNK];
    tclod_id vis[TCLOD_BATCH_CHUNK]; /* the visible ones, asked for their cost */
    float varea[TCLOD_BATCH_CHUNK], vdist[TCLOD_BATCH_CHUNK];
} tclod_batch_worker;

/* Where a solve stands between two tclod_select_step calls: the state of the
 * solver's loops, so that a step resumes exactly where the last one paused.
 * Zeroed when a solve begins. */
typedef struct tclod_resume {
    int phase;                  /* the solver's stage; 0 = not started */
    int skipped;                /* an increment did not fit (greedy, mixed) */
    uint32_t k;                 /* steps of a bounded stage (mixed), or the next
                                   instance (Robin Hood) */
    tclod_greedy_resume greedy; /* the greedy's, also when the mixed solver runs it */
    tclod_mixed_resume mixed;
    tclod_rh_resume rh;
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
    tclod_greedy_state greedy; /* its per-node buffers among these */
    double *path;              /* 2 per node: benefit and cost of the increments
                                  taken above it (the greedy's cold solve) */
    uint8_t *flags;
    tclod_id *cut, *prev_cut, *result, *scratch;
    tclod_id *drawn; /* the result as tclod_selector_cut lists it: self leaves as
                        their additive nodes (result itself when it has none); drawn_cap
                        elements, allocated once the scene has self leaves */
    uint32_t drawn_cap;
    int drawn_is_result;
    double *scratch_key;

    /* per-smooth-object buffers, smooth_cap elements each */
    uint32_t smooth_cap;
    tclod_mixed_state mixed;    /* its per-smooth-object buffers among these */
    tclod_smooth_group *groups; /* the committed smooth result */
    uint32_t group_count;

    /* the Robin Hood solver's own buffers; it also keeps, in the per-node
     * buffers it does not otherwise use: the values of a branch's children in
     * scratch_key, by slot in the scene's children[] (-1: not visible); the
     * ring of its third cycle's candidates in scratch and path */
    tclod_rh_state rh;
    tclod_stream_state stream;    /* residency and the plan of loads (stream.c) */
    tclod_batch_worker *workers;  /* batch evaluation (evaluate.c): one per worker;
                                     NULL without batching */
    tclod_id *gather;             /* the nodes gathered, TCLOD_GATHER room */
    unsigned char *gathered_done; /* per gathered node, while a flush splits: 1 once a
                                     task's range evaluated it */
    uint32_t gather_count;
    int batching; /* batch callbacks or workers: the greedy gathers what it
                     evaluates (else it asks node by node, as it needs them) */

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
    uint64_t begin_log; /* the edit log's end at the solve's beginning */
    tclod_stats stats;
    struct tclod_selector_saved *keep; /* see tclod_selector_keep; NULL: none */
};

/* Costs from features (evaluate.c): coefficients · the host's features of
 * node q->id, plus its cost callback's value when set; NaN when a feature or
 * that value is bad, so that the caller's checks count it once. The smooth
 * form also prices d/dr into *d_dr (NaN when a slope is bad). */
double tclod_feature_cost(const tclod_selector *sel, const tclod_query *q);
double tclod_feature_smooth_cost(const tclod_selector *sel, const tclod_query *q, double r,
                                 double *d_dr);

/* The host's predicted cost of node q->id: its cost callback, or its features
 * priced. */
static inline double tclod_node_cost(const tclod_selector *sel, const tclod_query *q) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    if (TCLOD_UNLIKELY(cb->features != NULL))
        return tclod_feature_cost(sel, q);
    return cb->cost(cb->user, q);
}

/* The same for a smooth object or group at r, its slope into *d_dr. */
static inline double tclod_smooth_cost(const tclod_selector *sel, const tclod_query *q, double r,
                                       double *d_dr) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    if (TCLOD_UNLIKELY(cb->smooth_features != NULL))
        return tclod_feature_smooth_cost(sel, q, r, d_dr);
    return cb->smooth_cost(cb->user, q, r, d_dr);
}

/* Counts a bad callback value (and fails the solve in strict mode). */
static inline void tclod_bad_value(tclod_selector *sel) {
    sel->stats.invalid_values++;
    if (sel->desc.strict)
        sel->failed = 1;
}

/* What tclod_evaluate_measured does with a benefit that is not positive and
 * finite (0, -0, negative, NaN or infinite): the bad ones count (and fail a
 * strict solve) and give 0; the node is invisible, its cost 0. Returns 0, or
 * -1 when strict mode saw a bad value. */
static inline int tclod_evaluate_invisible(tclod_selector *sel, tclod_node_state *st, double b) {
    if (!(b >= 0.0 && b < HUGE_VAL)) { /* NaN, infinite or negative */
        tclod_bad_value(sel);
        b = 0.0;
    }
    st->benefit = b; /* 0 or -0 */
    st->cost = 0.0;
    return sel->failed ? -1 : 0;
}

/* What tclod_evaluate_measured does with a cost that is not in [0, +inf)
 * (-0 passes, a bad one counts, fails a strict solve and gives +inf) of the
 * visible node whose record st is, which then goes on as one of a finite
 * cost would: when it is not resident, tclod_evaluate_absent. Returns as
 * tclod_evaluate_bounded. */
int tclod_evaluate_bad_cost(tclod_selector *sel, tclod_node_state *st, double c);

/* Node n is a self leaf (an additive node's own drawing among its children):
 * it takes its owner's values, evaluating the owner first if needed, with no
 * callback of its own; the query is left as the owner's. Returns as
 * tclod_evaluate_bounded. */
int tclod_evaluate_self(tclod_selector *sel, tclod_id n);

/* ---- residency as the solvers see it ------------------------------------------ */

/* Node n, visible, is not resident: keeps its values for the plan and makes
 * it undrawable. Returns as tclod_evaluate_bounded. */
int tclod_evaluate_absent(tclod_selector *sel, tclod_id n);

/* Node n's bounds (it has some) into *q: its kind, centre and the fields of
 * that kind; the others keep what they held (the kind says which are read). */
static inline void tclod_node_public_bounds(const tclod_scene *s, tclod_id n, tclod_bounds *q) {
    const tclod_node_bounds *b = &s->bounds[n];
    q->center[0] = b->c[0];
    q->center[1] = b->c[1];
    q->center[2] = b->c[2];
    if (b->box != TCLOD_NONE) {
        const tclod_box *x = &s->boxes[b->box];
        if ((b->kind & ~TCLOD_BOUNDS_SELF) == TCLOD_BOUNDS_AABB) {
            q->kind = TCLOD_BOUNDS_AABB;
            memcpy(q->half_extents, x->h, sizeof q->half_extents);
        } else {
            q->kind = TCLOD_BOUNDS_OBB;
            memcpy(q->half_axes, x->axes, sizeof q->half_axes);
        }
        return;
    }
    q->kind = TCLOD_BOUNDS_SPHERE; /* a self leaf is evaluated as its owner */
    q->radius = b->r;
}

/* Puts node n's bounds (it has some) into the query's volume. */
static inline const tclod_bounds *tclod_query_bounds(tclod_selector *sel, tclod_id n) {
    tclod_node_public_bounds(sel->scene, n, &sel->qbounds);
    return &sel->qbounds;
}

/* ---- evaluate.c ---------------------------------------------------------------- */

/* Sets sel->batching and, when it is set, allocates the batch workspace
 * (sel->workers, sel->gather); frees it. */
tclod_status tclod_batch_create(tclod_selector *sel);
void tclod_batch_destroy(tclod_selector *sel);

/* Evaluates the gathered nodes (over the host's workers when it gave them)
 * and empties the list. Returns 0, or -1 when strict mode saw a bad value. */
int tclod_batch_flush(tclod_selector *sel);

/* Gathers node n unless it is evaluated or gathered in this solve already,
 * or a self leaf (evaluated as its owner when asked for): it counts as
 * evaluated from now on, so its values must not be read before the next
 * tclod_batch_flush. No node may be gathered with its parent between two
 * flushes (the measure takes a parent's figures). Returns as the flush. */
static inline int tclod_batch_add(tclod_selector *sel, tclod_id n) {
    if (sel->node[n].stamp == sel->solve_id || (sel->scene->flags[n] & TCLOD_NODE_SELF))
        return 0;
    sel->node[n].stamp = sel->solve_id;
    TCLOD_PREFETCH(&sel->scene->bounds[n]); /* for the measure that follows */
    TCLOD_PREFETCH(&sel->scene->parent[n]);
    sel->gather[sel->gather_count++] = n;
    return sel->gather_count == TCLOD_GATHER ? tclod_batch_flush(sel) : 0;
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
    c = tclod_node_cost(sel, q);
    st->benefit = b;
    if (tclod_bits(c) > TCLOD_BITS_MAX)
        return tclod_evaluate_bad_cost(sel, st, c);
    st->cost = c;
    if (TCLOD_UNLIKELY(tclod_scene_streams(sel->scene)) &&
        (sel->scene->flags[n] & TCLOD_NODE_ABSENT))
        return tclod_evaluate_absent(sel, n);
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

/* Screen area and distance of node n's bounds in this solve. The levels of
 * one object usually share its bounds: a parent evaluated in this solve
 * already (the parent of a chain's level always is) lends its figures. */
static inline void tclod_measure_node(const tclod_selector *sel, tclod_id n, float *area,
                                      double *distance) {
    const tclod_scene *s = sel->scene;
    const tclod_node_bounds *bounds = &s->bounds[n];
    tclod_id p = s->parent[n];
    if (p != TCLOD_NONE && sel->node[p].stamp == sel->solve_id &&
        memcmp(bounds, &s->bounds[p], sizeof *bounds) == 0) {
        *area = sel->node[p].area;
        *distance = (double)sel->node[p].distance;
    } else {
        tclod_view_measure_bounds(&sel->view, bounds, s->boxes, area, distance);
    }
}

/* The callbacks of node n, not evaluated in this solve yet: measured, then
 * tclod_evaluate_measured. */
static inline int tclod_evaluate_fresh(tclod_selector *sel, tclod_id n) {
    float area = -1.0f;
    double distance = -1.0;
    if (sel->has_view && sel->scene->bounds[n].r >= 0.0)
        tclod_measure_node(sel, n, &area, &distance);
    return tclod_evaluate_measured(sel, n, area, distance);
}

/* Calls the benefit and cost callbacks for node n once per solve and caches
 * the values in sel->node[n] (cost asked only when the benefit is > 0; a bad
 * benefit counts as 0, a bad cost as +inf): values are cached for the solve,
 * stamp == solve_id. Returns 0, or -1 when strict mode saw a bad value. */
static inline int tclod_evaluate_node(tclod_selector *sel, tclod_id n) {
    return sel->node[n].stamp == sel->solve_id ? 0 : tclod_evaluate_fresh(sel, n);
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

/* 1 when the search must stop: the frame's limit (sets stop_reason and
 * sel->stopped; final) or the step's slice (sets sel->paused; the solver
 * returns and resumes from sel->resume at the next step). */
int tclod_out_of_time(tclod_selector *sel);

/* Iterations between two reads of the clock (tclod_out_of_time). */
#define TCLOD_CLOCK_STRIDE 16u

/* ---- smooth objects ------------------------------------------------------------- */

/* NaN, negative or infinite: one comparison each way. */
static inline int tclod_smooth_value_bad(double v) {
    return !(v >= 0.0 && v <= DBL_MAX);
}

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

/* tclod_smooth_call inline, for the mixed solver's inner loop. */
static inline int tclod_smooth_call_inline(tclod_selector *sel, uint32_t first, uint32_t count,
                                           const float *bounds, float area, float distance,
                                           double x, double *b, double *db, double *c, double *dc) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    const tclod_scene *s = sel->scene;
    double xs = x > TCLOD_SLOPE_FLOOR ? x : TCLOD_SLOPE_FLOOR;
    int bad = 0;
    tclod_query q;
    tclod_bounds qb;
    q.id = s->smooth_order[first];
    q.count = count;
    q.view = sel->frame->view;
    q.screen_area = area;
    q.distance = distance;
    q.members = s->smooth_order + first;
    tclod_sphere_bounds(bounds ? bounds : &s->smooth_bounds[4u * q.id], &qb);
    q.bounds = &qb;
    sel->stats.evaluations++;
    if (b) {
        *db = 0.0;
        *b = cb->smooth_benefit(cb->user, &q, xs, db);
        if (tclod_smooth_value_bad(*b)) {
            tclod_bad_value(sel);
            *b = *db = 0.0;
            bad = 1;
        } else if (tclod_smooth_value_bad(*db)) {
            tclod_bad_value(sel);
            *db = 0.0;
        }
    }
    if (c) {
        *dc = 0.0;
        *c = tclod_smooth_cost(sel, &q, xs, dc);
        if (tclod_smooth_value_bad(*c)) {
            tclod_bad_value(sel);
            *c = *dc = HUGE_VAL;
        } else if (tclod_smooth_value_bad(*dc)) {
            tclod_bad_value(sel);
            *dc = HUGE_VAL;
        }
    }
    return bad;
}

#endif /* TCLOD_EVALUATE_H */
