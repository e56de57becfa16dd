/*
 * The predictive geomorph scheduler ([GEO §3.3-3.4, §4.2-4.5];
 * docs/scheduler.md).
 *
 * Time is cut into intervals I_j = [b_j, b_j + tau). The selection begun at
 * b_j runs in slices during I_j for the target interval I_{j+L} (L = 2 with
 * morphing, 1 without) and lands at b_{j+1} as S_{j+L}. Its benefit is the
 * host's, summed over views predicted for the target interval, plus lambda
 * times the host's under the conservative camera, which is also the solve's
 * frame view (so it culls); its cost is the host's maximum over the predicted
 * views that saw the node.
 *
 * With morphing, the frames of I_j go from X_j = meet(S_{j-1}, S_j) to
 * Y_j = meet(S_j, S_{j+1}), meet taking per part of the hierarchies the
 * coarser of two cuts: an object coarser in S_{j+1} morphs down during I_j
 * (reached when I_{j+1} begins), one finer in S_j than in S_{j-1} morphs up
 * during I_j (reached at its end), and when both happen in I_j (an up-morph
 * overridden by a down-morph) the two collapse into X_j -> Y_j. Since X_j and
 * Y_j are both no finer than S_j, the frames of I_j cost no more than S_j as
 * long as a node costs no more than its descendants. Each region of
 * meet(X_j, Y_j) -- a node q with the finer side's nodes below it -- morphs
 * level by level: d levels take d equal parts of the interval, each drawing
 * the nodes at the next depth geomorphed from their parents. The predicted
 * cost of every state a region passes through is checked against the cost of
 * S_j in that region when the plan is made; a region that would exceed it
 * draws S_j's nodes as they are (a switch, counted as a pop). Each frame the
 * draw list's cost is checked against the budget in force; should it exceed
 * it (the budget fell, or the calibration raised it), the scheduler selects
 * at once for the current view and draws that.
 *
 * With streaming, only resident nodes are drawn. A landed selection that
 * holds a node no longer resident draws its nearest resident ancestor in its
 * place, as a selector would (repair); a region morphs only through resident
 * nodes, else it draws S_j's nodes as they are. The selector's plan keeps the
 * nodes of the landed selections, whose paths hold every node a draw list
 * draws (keep_landed).
 *
 * Node relations are found with epoch marks on per-node arrays: the members
 * of a cut are marked black, and a node belongs to the meet of two cuts when
 * no proper ancestor of it is marked ([GEO §4.4]'s black and grey nodes).
 *
 * An update is all or nothing. It grows every buffer (the selector's too)
 * before it changes anything; it keeps the pipeline's state from its start,
 * makes its plan in a second plan buffer, copies a finished selection out of
 * the selector at once, and has the selector keep its committed state before
 * the first commit, so that a failure puts everything back. Only a selection
 * under way cannot be kept: the next update begins it again.
 */
#include "selector.h"

#include <float.h>
#include <math.h>
#include <string.h>

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

/* ---- desc ------------------------------------------------------------------- */

void tclod_scheduler_desc_default(tclod_scheduler_desc *d) {
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->tau = 0.5;
    d->samples = 3;
    d->confidence = 1.0;
    d->max_speed = 0.0;
    d->max_turn_rate = 0.0;
    d->two_stage = 0;
    tclod_calib_desc_default(&d->calib);
}

static int finite_nonnegative(double x) {
    return x >= 0.0 && !isinf(x);
}

/* tau: a normal positive number whose horizon (up to 4 tau, the longest gap
 * before a restart) is finite. */
static int tau_valid(double tau) {
    return isnormal(tau) && tau > 0.0 && !isinf(4.0 * tau);
}

const char *tclod_scheduler_desc_check(const tclod_scheduler_desc *d) {
    if (!d)
        return "desc is NULL";
    if (!(d->tau == 0.0 || tau_valid(d->tau)))
        return "desc.tau must be a normal number > 0 with 4 tau finite, or 0 (default)";
    if (d->samples > TCLOD_MAX_SAMPLES)
        return "desc.samples must be at most TCLOD_MAX_SAMPLES (8)";
    if (!(d->confidence == (double)TCLOD_OFF || finite_nonnegative(d->confidence)))
        return "desc.confidence must be finite and > 0, 0 (default) or TCLOD_OFF";
    if (!finite_nonnegative(d->max_speed))
        return "desc.max_speed must be finite and >= 0";
    if (!finite_nonnegative(d->max_turn_rate))
        return "desc.max_turn_rate must be finite and >= 0";
    if (d->two_stage != 0 && d->two_stage != 1)
        return "desc.two_stage must be 0 or 1";
    return tclod_calib_check(&d->calib, 1);
}

/* A valid desc with its defaults filled in. */
static tclod_scheduler_desc schedule_resolved(const tclod_scheduler_desc *d) {
    tclod_scheduler_desc r = *d;
    if (r.tau == 0.0)
        r.tau = 0.5;
    if (r.samples == 0)
        r.samples = 3;
    r.confidence = r.confidence == 0.0 ? 1.0 : (r.confidence < 0.0 ? 0.0 : r.confidence);
    return r;
}

/* ---- vectors ------------------------------------------------------------------- */

static double schedule_dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double length3(const double a[3]) {
    return sqrt(schedule_dot3(a, a));
}

static void schedule_load3(const float in[3], double out[3]) {
    out[0] = (double)in[0];
    out[1] = (double)in[1];
    out[2] = (double)in[2];
}

static void store3(const double in[3], float out[3]) {
    out[0] = (float)in[0];
    out[1] = (float)in[1];
    out[2] = (float)in[2];
}

/* ---- the conservative camera ------------------------------------------------------- */

tclod_status tclod_conservative_view(const tclod_view *view, double horizon, double max_speed,
                                     double max_turn_rate, tclod_view *out) {
    double turn, fov_y, fov_x, half, back, f[3], reach;
    tclod_view v;
    if (!view || !out || tclod_view_validate(view) != TCLOD_OK)
        return TCLOD_ERR_ARG;
    if (!finite_nonnegative(horizon) || !finite_nonnegative(max_speed) ||
        !finite_nonnegative(max_turn_rate))
        return TCLOD_ERR_ARG;
    v = *view;
    turn = horizon * max_turn_rate;
    reach = horizon * max_speed;
    fov_y = (double)view->fov_y;
    fov_x = 2.0 * atan((double)view->aspect * tan(0.5 * fov_y));
    fov_y = fov_y + 2.0 * turn < MAX_FOV ? fov_y + 2.0 * turn : MAX_FOV;
    fov_x = fov_x + 2.0 * turn < MAX_FOV ? fov_x + 2.0 * turn : MAX_FOV;
    half = 0.5 * (fov_y < fov_x ? fov_y : fov_x);
    /* every eye within `reach` of the current one lies inside the cone of
     * half-angle `half` whose apex is `back` behind it */
    back = reach > 0.0 ? reach / sin(half) : 0.0;
    schedule_load3(view->forward, f);
    {
        double len = length3(f);
        v.eye[0] = view->eye[0] - back * f[0] / len;
        v.eye[1] = view->eye[1] - back * f[1] / len;
        v.eye[2] = view->eye[2] - back * f[2] / len;
    }
    v.fov_y = (float)fov_y;
    v.aspect = (float)(tan(0.5 * fov_x) / tan(0.5 * fov_y));
    v.far_z = (float)((double)view->far_z + back + reach);
    if (tclod_view_validate(&v) != TCLOD_OK)
        return TCLOD_ERR_ARG; /* overflowed */
    *out = v;
    return TCLOD_OK;
}

/* ---- prediction ---------------------------------------------------------------------- */

/* Rotates unit vector a towards unit vector b by at most angle (radians),
 * in their common plane; out unit length. */
static void turn_towards(const double a[3], const double b[3], double angle, double out[3]) {
    double c = schedule_dot3(a, b), s, w[3], len;
    int k;
    if (c > 1.0)
        c = 1.0;
    if (c < -1.0)
        c = -1.0;
    if (acos(c) <= angle) {
        for (k = 0; k < 3; ++k)
            out[k] = b[k];
        return;
    }
    for (k = 0; k < 3; ++k)
        w[k] = b[k] - c * a[k];
    len = length3(w);
    if (!(len > 0.0)) { /* opposite: no plane, stay */
        for (k = 0; k < 3; ++k)
            out[k] = a[k];
        return;
    }
    s = sin(angle);
    c = cos(angle);
    for (k = 0; k < 3; ++k)
        out[k] = c * a[k] + s * w[k] / len;
}

/* The recorded views used for the prediction: those of the last tau seconds,
 * and at least the last two. Returns their count; index 0 is the newest. */
static uint32_t history_window(const tclod_scheduler *sch, uint32_t *slots) {
    uint32_t n = 0, k;
    for (k = 0; k < sch->p.hist_count; ++k) {
        uint32_t slot = (sch->p.hist_next + HISTORY - 1u - k) % HISTORY;
        if (n >= 2u && sch->hist_t[slot] < sch->p.now - sch->desc.tau)
            break;
        slots[n++] = slot;
    }
    return n;
}

/* Least-squares line through (t_k, x_k): the value at t. */
static double fit(const double *t, const double *x, uint32_t n, double at) {
    double mt = 0.0, mx = 0.0, stt = 0.0, stx = 0.0;
    uint32_t k;
    for (k = 0; k < n; ++k) {
        mt += t[k];
        mx += x[k];
    }
    mt /= (double)n;
    mx /= (double)n;
    for (k = 0; k < n; ++k) {
        stt += (t[k] - mt) * (t[k] - mt);
        stx += (t[k] - mt) * (x[k] - mx);
    }
    return stt > 0.0 ? mx + stx / stt * (at - mt) : mx;
}

/* The predicted view at time t (see tclod_scheduler_predict). */
static void predict(const tclod_scheduler *sch, double t, tclod_view *out) {
    uint32_t slots[HISTORY] = {0}, n = history_window(sch, slots), k, c;
    const tclod_view *last = &sch->hist_v[slots[0]];
    double times[HISTORY], x[HISTORY], p[3][3], now[3][3], dt = t - sch->hist_t[slots[0]];
    double limit;
    tclod_view v = *last;
    int field;
    for (k = 0; k < n; ++k)
        times[k] = sch->hist_t[slots[k]] - sch->hist_t[slots[0]];
    for (field = 0; field < 3; ++field) {
        for (c = 0; c < 3; ++c) {
            for (k = 0; k < n; ++k) {
                const tclod_view *h = &sch->hist_v[slots[k]];
                x[k] = field == 0 ? h->eye[c] : (double)(field == 1 ? h->forward : h->up)[c];
            }
            p[field][c] = fit(times, x, n, dt);
            now[field][c] = fit(times, x, n, 0.0);
        }
    }
    if (dt < 0.0)
        dt = 0.0;
    /* the eye moves no faster than max_speed from where the line is now */
    limit = sch->desc.max_speed * dt;
    if (sch->desc.max_speed > 0.0) {
        double d[3], len;
        for (c = 0; c < 3; ++c)
            d[c] = p[0][c] - now[0][c];
        len = length3(d);
        if (len > limit)
            for (c = 0; c < 3; ++c)
                p[0][c] = now[0][c] + d[c] * limit / len;
    }
    /* directions: unit length, turned no faster than max_turn_rate */
    for (field = 1; field < 3; ++field) {
        double a[3], b[3], la, lb;
        for (c = 0; c < 3; ++c) {
            a[c] = now[field][c];
            b[c] = p[field][c];
        }
        la = length3(a);
        lb = length3(b);
        if (!(la > 0.0) || !(lb > 0.0)) { /* degenerate: keep the last view's */
            schedule_load3(field == 1 ? last->forward : last->up, p[field]);
            continue;
        }
        for (c = 0; c < 3; ++c) {
            a[c] /= la;
            b[c] /= lb;
        }
        if (sch->desc.max_turn_rate > 0.0)
            turn_towards(a, b, sch->desc.max_turn_rate * dt, p[field]);
        else
            for (c = 0; c < 3; ++c)
                p[field][c] = b[c];
    }
    v.eye[0] = p[0][0];
    v.eye[1] = p[0][1];
    v.eye[2] = p[0][2];
    store3(p[1], v.forward);
    store3(p[2], v.up);
    if (tclod_view_validate(&v) != TCLOD_OK)
        v = *last; /* e.g. forward parallel to up */
    *out = v;
}

static void record(tclod_scheduler *sch, double now, const tclod_view *view) {
    sch->hist_t[sch->p.hist_next] = now;
    sch->hist_v[sch->p.hist_next] = *view;
    sch->p.hist_next = (sch->p.hist_next + 1u) % HISTORY;
    if (sch->p.hist_count < HISTORY)
        sch->p.hist_count++;
}

tclod_status tclod_scheduler_predict(const tclod_scheduler *sch, double t, tclod_view *out) {
    if (!sch || !out || isnan(t) || isinf(t))
        return TCLOD_ERR_ARG;
    if (sch->p.hist_count == 0)
        return TCLOD_ERR_STATE;
    predict(sch, t, out);
    return TCLOD_OK;
}

/* ---- the callbacks the selector calls ------------------------------------------------- */

static int value_bad(double v) {
    return !(v >= 0.0) || isinf(v);
}

/* A sum of good values, which may overflow: the largest good value instead. */
static double saturate(double sum) {
    return sum < HUGE_VAL ? sum : DBL_MAX;
}

/* q re-measured for view k. */
static tclod_query query_for(const tclod_scheduler *sch, const tclod_query *q, uint32_t k) {
    tclod_query r = *q;
    r.view = &sch->sv.views[k];
    if (q->bounds)
        tclod_view_cache_measure_any(&sch->sv.caches[k], q->bounds, &r.screen_area, &r.distance);
    return r;
}

/* Whether the conservative camera's benefit is asked. */
static int uses_conservative(const tclod_scheduler *sch) {
    return sch->desc.confidence > 0.0;
}

static double wrap_benefit(void *user, const tclod_query *q) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    double sum = 0.0, v;
    uint32_t k;
    if (sch->current_only || !q->view)
        return sch->host.benefit(sch->host.user, q);
    sch->asked = q->id;
    sch->asked_mask = 0;
    for (k = 0; k < sch->sv.count; ++k) {
        tclod_query r = query_for(sch, q, k);
        v = sch->host.benefit(sch->host.user, &r);
        if (value_bad(v))
            return v;
        if (v > 0.0)
            sch->asked_mask |= 1u << k;
        sum += v;
    }
    if (uses_conservative(sch)) {
        v = sch->host.benefit(sch->host.user, q);
        if (value_bad(v))
            return v;
        sum += sch->desc.confidence * v;
    }
    return saturate(sum);
}

static double wrap_cost(void *user, const tclod_query *q) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    double worst = 0.0, v;
    uint32_t k, mask;
    int any = 0;
    if (sch->current_only || !q->view)
        return sch->host.cost(sch->host.user, q);
    /* the views in which the benefit was > 0 (all, if that is not known) */
    mask = sch->asked == q->id ? sch->asked_mask : (1u << sch->sv.count) - 1u;
    for (k = 0; k < sch->sv.count; ++k) {
        tclod_query r;
        if (!(mask & (1u << k)))
            continue;
        r = query_for(sch, q, k);
        v = sch->host.cost(sch->host.user, &r);
        if (value_bad(v))
            return v;
        if (!any || v > worst)
            worst = v;
        any = 1;
    }
    /* seen by the conservative camera only: its cost */
    return any ? worst : sch->host.cost(sch->host.user, q);
}

static double wrap_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    double sum = 0.0, slope = 0.0, v, d;
    uint32_t k;
    if (sch->current_only || !q->view)
        return sch->host.smooth_benefit(sch->host.user, q, r, d_dr);
    for (k = 0; k < sch->sv.count; ++k) {
        tclod_query s = query_for(sch, q, k);
        d = 0.0;
        v = sch->host.smooth_benefit(sch->host.user, &s, r, &d);
        if (value_bad(v) || value_bad(d)) {
            *d_dr = d;
            return v;
        }
        sum += v;
        slope += d;
    }
    if (uses_conservative(sch)) {
        d = 0.0;
        v = sch->host.smooth_benefit(sch->host.user, q, r, &d);
        if (value_bad(v) || value_bad(d)) {
            *d_dr = d;
            return v;
        }
        sum += sch->desc.confidence * v;
        slope += sch->desc.confidence * d;
    }
    *d_dr = saturate(slope);
    return saturate(sum);
}

static double wrap_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    double worst = 0.0, slope = 0.0, v, d;
    uint32_t k;
    int any = 0;
    if (sch->current_only || !q->view)
        return sch->host.smooth_cost(sch->host.user, q, r, d_dr);
    /* the views whose frustum holds the group */
    for (k = 0; k < sch->sv.count; ++k) {
        tclod_query s = query_for(sch, q, k);
        if (q->bounds && !(s.screen_area > 0.0f))
            continue;
        d = 0.0;
        v = sch->host.smooth_cost(sch->host.user, &s, r, &d);
        if (value_bad(v) || value_bad(d)) {
            *d_dr = d;
            return v;
        }
        if (!any || v > worst) {
            worst = v;
            slope = d;
        }
        any = 1;
    }
    if (!any)
        return sch->host.smooth_cost(sch->host.user, q, r, d_dr);
    *d_dr = slope;
    return worst;
}

static double wrap_complexity(void *user, const tclod_query *q) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    return sch->host.complexity(sch->host.user, q);
}

/* The importance of an instance does not depend on the predicted views: the
 * host is asked once, with the query the selector asks. */
static double wrap_importance(void *user, const tclod_query *q) {
    tclod_scheduler *sch = (tclod_scheduler *)user;
    return sch->host.importance(sch->host.user, q);
}

/* ---- buffers ---------------------------------------------------------------------------- */

static size_t schedule_node_arrays(tclod_scheduler *sch, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    uint32_t g;
    out[n++] = (tclod_array){(void **)&sch->depth, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->mark_a, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->mark_b, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->mark_c, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->done, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->region_of, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->region_mark, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&sch->list_x, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sch->list_y, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sch->list_r, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sch->counts, 3 * sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&sch->items[0], 3 * sizeof(tclod_draw), -1};
    out[n++] = (tclod_array){(void **)&sch->items[1], 3 * sizeof(tclod_draw), -1};
    out[n++] = (tclod_array){(void **)&sch->kept.cut, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sch->kept.result, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sch->kept.drawn, sizeof(tclod_id), -1};
    for (g = 0; g < 2u; ++g) {
        plan_state *P = &sch->plans[g];
        out[n++] = (tclod_array){(void **)&P->regions, sizeof(region), -1};
        out[n++] = (tclod_array){(void **)&P->nodes, 3 * sizeof(tclod_id), -1};
        out[n++] = (tclod_array){(void **)&P->memo_cost, sizeof(double), 0};
        out[n++] = (tclod_array){(void **)&P->memo_mark, sizeof(uint32_t), 0};
        out[n++] = (tclod_array){(void **)&P->memo_visible, sizeof(uint8_t), 0};
    }
    for (g = 0; g < GEN_SLOTS; ++g) {
        out[n++] = (tclod_array){(void **)&sch->gen[g].ids, sizeof(tclod_id), -1};
        out[n++] = (tclod_array){(void **)&sch->gen[g].cost, sizeof(double), -1};
    }
    assert(n <= TCLOD_MAX_ARRAYS);
    return n;
}

static size_t schedule_smooth_arrays(tclod_scheduler *sch, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    uint32_t g;
    out[n++] = (tclod_array){(void **)&sch->kept.groups, sizeof(tclod_smooth_group), -1};
    for (g = 0; g < GEN_SLOTS; ++g) {
        out[n++] = (tclod_array){(void **)&sch->gen[g].res, sizeof(double), 0};
        out[n++] = (tclod_array){(void **)&sch->gen[g].group_cost, sizeof(double), -1};
    }
    assert(n <= TCLOD_MAX_ARRAYS);
    return n;
}

static uint32_t schedule_grown(uint32_t cap, uint32_t need) {
    while (cap < need)
        cap = cap < 64u ? 64u : (cap > UINT32_MAX / 4u ? need : cap * 2u);
    return cap;
}

/* Grows the per-node and per-smooth-object buffers, the scheduler's and its
 * selector's, to the scene's size, all or nothing: the scheduler's are
 * allocated first and replace the old ones only once the selector's have
 * grown too, so that a failure leaves every buffer as it was. Afterwards
 * nothing in the update allocates. */
static tclod_status schedule_reserve(tclod_scheduler *sch) {
    tclod_array nodes[TCLOD_MAX_ARRAYS], smooth[TCLOD_MAX_ARRAYS];
    void *fresh_n[TCLOD_MAX_ARRAYS], *fresh_s[TCLOD_MAX_ARRAYS];
    size_t nn = schedule_node_arrays(sch, nodes), ns = schedule_smooth_arrays(sch, smooth);
    uint32_t need_n = sch->scene->node_count, need_s = sch->scene->smooth_count;
    uint32_t cap_n = need_n > sch->node_cap ? schedule_grown(sch->node_cap, need_n) : sch->node_cap;
    uint32_t cap_s =
        need_s > sch->smooth_cap ? schedule_grown(sch->smooth_cap, need_s) : sch->smooth_cap;
    int grow_n = cap_n != sch->node_cap, grow_s = cap_s != sch->smooth_cap;
    tclod_status st;
    if (need_n > UINT32_MAX / 3u)
        return TCLOD_ERR_NOMEM;
    if (grow_n && tclod_arrays_alloc(&sch->alloc, nodes, nn, cap_n, fresh_n) != TCLOD_OK)
        return TCLOD_ERR_NOMEM;
    if (grow_s && tclod_arrays_alloc(&sch->alloc, smooth, ns, cap_s, fresh_s) != TCLOD_OK) {
        if (grow_n)
            tclod_arrays_discard(&sch->alloc, nodes, nn, cap_n, fresh_n);
        return TCLOD_ERR_NOMEM;
    }
    st = tclod_selector_reserve(sch->sel);
    if (st != TCLOD_OK) {
        if (grow_s)
            tclod_arrays_discard(&sch->alloc, smooth, ns, cap_s, fresh_s);
        if (grow_n)
            tclod_arrays_discard(&sch->alloc, nodes, nn, cap_n, fresh_n);
        return st;
    }
    if (grow_n) {
        tclod_arrays_commit(&sch->alloc, nodes, nn, sch->node_cap, cap_n, fresh_n);
        sch->node_cap = cap_n;
    }
    if (grow_s) {
        tclod_arrays_commit(&sch->alloc, smooth, ns, sch->smooth_cap, cap_s, fresh_s);
        sch->smooth_cap = cap_s;
    }
    return TCLOD_OK;
}

/* ---- create / destroy ---------------------------------------------------------------------- */

tclod_status tclod_scheduler_create(const tclod_scene *s, const tclod_selector_desc *sd,
                                    const tclod_scheduler_desc *d, const tclod_allocator *a,
                                    tclod_scheduler **out) {
    tclod_allocator alloc;
    tclod_scheduler *sch;
    tclod_selector_desc inner;
    tclod_status st;
    if (!s || !sd || !d || !out || !tclod_allocator_init(&alloc, a) ||
        tclod_scheduler_desc_check(d))
        return TCLOD_ERR_ARG;
    sch = (tclod_scheduler *)tclod_mem_alloc(&alloc, sizeof *sch);
    if (!sch)
        return TCLOD_ERR_NOMEM;
    memset(sch, 0, sizeof *sch);
    sch->alloc = alloc;
    sch->desc = schedule_resolved(d);
    sch->host = sd->callbacks;
    sch->scene = (tclod_scene *)(uintptr_t)s;
    sch->p.prev = sch->p.cur = sch->p.next = 0;
    sch->p.plan = &sch->plans[0];
    sch->back = 1;
    inner = *sd;
    inner.callbacks.user = sch;
    inner.callbacks.benefit = sd->callbacks.benefit ? wrap_benefit : NULL;
    inner.callbacks.cost = sd->callbacks.cost ? wrap_cost : NULL;
    inner.callbacks.smooth_benefit = sd->callbacks.smooth_benefit ? wrap_smooth_benefit : NULL;
    inner.callbacks.smooth_cost = sd->callbacks.smooth_cost ? wrap_smooth_cost : NULL;
    inner.callbacks.complexity = sd->callbacks.complexity ? wrap_complexity : NULL;
    inner.callbacks.importance = sd->callbacks.importance ? wrap_importance : NULL;
    /* the predicted views' values are the wrappers', asked one node at a time
     * on this thread */
    inner.callbacks.benefit_batch = NULL;
    inner.callbacks.cost_batch = NULL;
    memset(&inner.tasks, 0, sizeof inner.tasks);
    st = tclod_calib_create(&sch->desc.calib, &alloc, &sch->calib);
    if (st == TCLOD_OK)
        st = tclod_selector_create(s, &inner, &alloc, &sch->sel);
    if (st == TCLOD_OK) {
        /* its selection under way is begun again when the scene changes */
        sch->sel->holds = 0;
        st = tclod_scene_attach(sch->scene, &sch->user, 1);
    }
    if (st != TCLOD_OK) {
        tclod_selector_destroy(sch->sel);
        tclod_calib_destroy(sch->calib);
        tclod_mem_free(&alloc, sch, sizeof *sch);
        return st;
    }
    *out = sch;
    return TCLOD_OK;
}

void tclod_scheduler_destroy(tclod_scheduler *sch) {
    tclod_array arrays[TCLOD_MAX_ARRAYS];
    tclod_allocator alloc;
    if (!sch || sch->busy)
        return;
    alloc = sch->alloc;
    tclod_scene_detach(sch->scene, &sch->user, 1);
    tclod_selector_destroy(sch->sel);
    tclod_calib_destroy(sch->calib);
    tclod_arrays_free(&alloc, arrays, schedule_node_arrays(sch, arrays), sch->node_cap);
    tclod_arrays_free(&alloc, arrays, schedule_smooth_arrays(sch, arrays), sch->smooth_cap);
    tclod_mem_free(&alloc, sch, sizeof *sch);
}

/* ---- selections ---------------------------------------------------------------------------- */

/* A fresh epoch for the relation marks; they are cleared when it wraps. */
static uint32_t next_epoch(tclod_scheduler *sch) {
    if (++sch->epoch == 0u) {
        uint32_t *marks[5];
        int i;
        marks[0] = sch->mark_a;
        marks[1] = sch->mark_b;
        marks[2] = sch->mark_c;
        marks[3] = sch->done;
        marks[4] = sch->region_mark;
        for (i = 0; i < 5; ++i)
            memset(marks[i], 0, sizeof(uint32_t) * sch->node_cap);
        sch->epoch = 1;
    }
    return sch->epoch;
}

/* Makes the plan in use one the update may write: not the one the outputs
 * were made with, which a failed update must leave as it was. */
static void writable_plan(tclod_scheduler *sch) {
    if (sch->p.plan == sch->saved.plan)
        sch->p.plan = sch->p.plan == &sch->plans[0] ? &sch->plans[1] : &sch->plans[0];
}

/* A fresh epoch for the predicted costs of a plan. */
static uint32_t next_memo_epoch(tclod_scheduler *sch) {
    if (++PLAN(sch)->memo_epoch == 0u) {
        memset(PLAN(sch)->memo_mark, 0, sizeof(uint32_t) * sch->node_cap);
        PLAN(sch)->memo_epoch = 1;
    }
    return PLAN(sch)->memo_epoch;
}

/* The depth of every node in the index, when nodes were added or removed. */
static void update_depths(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    uint32_t i;
    if (sch->depth_version == s->node_version + 1u)
        return;
    for (i = 0; i < s->order_count; ++i) { /* parents before children */
        tclod_id n = s->order[i];
        sch->depth[n] = s->parent[n] == TCLOD_NONE ? 0u : sch->depth[s->parent[n]] + 1u;
    }
    sch->depth_version = s->node_version + 1u;
}

/* Sets the callbacks' views for a selection begun now: samples of the target
 * interval, and the conservative camera as the frame's view. */
static void set_views(tclod_scheduler *sch, const tclod_view *view) {
    const tclod_scheduler_desc *d = &sch->desc;
    double lag = d->two_stage ? 1.0 : 2.0, start = sch->p.boundary + lag * d->tau;
    uint32_t k;
    if (!sch->views_saved) { /* those of the selection pending before the update */
        sch->saved_views = sch->sv;
        sch->views_saved = 1;
    }
    sch->current_only = 0;
    sch->sv.count = d->samples;
    for (k = 0; k < d->samples; ++k) {
        predict(sch, start + ((double)k + 0.5) * d->tau / (double)d->samples, &sch->sv.views[k]);
        tclod_view_cache_init(&sch->sv.caches[k], &sch->sv.views[k]);
    }
    if (tclod_conservative_view(view, (lag + 1.0) * d->tau, d->max_speed, d->max_turn_rate,
                                &sch->sv.conservative) != TCLOD_OK)
        sch->sv.conservative = *view;
    tclod_view_cache_init(&sch->sv.conservative_cache, &sch->sv.conservative);
    sch->asked = TCLOD_NONE;
}

/* Begins the selection for the target interval of the current boundary. */
static tclod_status begin(tclod_scheduler *sch, const tclod_view *view) {
    tclod_frame f;
    set_views(sch, view);
    memset(&f, 0, sizeof f);
    f.view = &sch->sv.conservative;
    f.budget = sch->p.budget;
    sch->p.pending_budget = f.budget;
    sch->p.redo = 0;
    sch->touched = 1;
    return tclod_select_begin(sch->sel, &f);
}

/* Begins again the selection a failed update lost, with the views and the
 * budget it began with; it runs to its end when it lands. */
static tclod_status begin_again(tclod_scheduler *sch) {
    tclod_frame f;
    memset(&f, 0, sizeof f);
    f.view = &sch->sv.conservative;
    f.budget = sch->p.pending_budget;
    sch->asked = TCLOD_NONE;
    sch->touched = 1;
    sch->p.lost = 0;
    sch->p.redo = 1;
    return tclod_select_begin(sch->sel, &f);
}

/* Copies the selector's result into generation g, with its costs. */
static void store(tclod_scheduler *sch, uint32_t g) {
    generation *G = &sch->gen[g];
    const tclod_id *ids = sch->sel->result, *order = NULL; /* the index's ids */
    const tclod_smooth_group *groups = NULL;
    size_t n = sch->sel->result_count, ng = 0, i;
    uint32_t order_count = 0, k;
    for (i = 0; i < n; ++i) {
        G->ids[i] = ids[i];
        G->cost[i] = sch->sel->node[ids[i]].cost;
    }
    G->count = (uint32_t)n;
    for (k = 0; k < sch->scene->smooth_count; ++k)
        G->res[k] = 0.0;
    tclod_selector_smooth_groups(sch->sel, &groups, &ng);
    G->groups = (uint32_t)ng;
    if (ng == 0)
        return;
    tclod_scene_smooth_order(sch->scene, &order, &order_count); /* prepared: cannot fail */
    for (i = 0; i < ng; ++i) {
        for (k = 0; k < groups[i].count; ++k)
            G->res[order[groups[i].first + k]] = groups[i].resolution;
        G->group_cost[i] = groups[i].cost;
    }
}

/* A generation slot neither the pipeline nor the outputs use. */
static uint32_t fresh_slot(const tclod_scheduler *sch) {
    uint32_t g;
    for (g = 0; g < GEN_SLOTS; ++g)
        if (g != sch->p.prev && g != sch->p.cur && g != sch->p.next && g != sch->shown.prev &&
            g != sch->shown.cur && g != sch->shown.next && (!sch->p.ready || g != sch->p.landing))
            return g;
    assert(0);
    return 0;
}

/* ---- relations between cuts ---------------------------------------------------------------- */

/* Whether a proper ancestor of n carries mark e. */
static int below_mark(const tclod_scheduler *sch, const uint32_t *mark, uint32_t e, tclod_id n) {
    const tclod_id *parent = sch->scene->parent;
    for (n = parent[n]; n != TCLOD_NONE; n = parent[n])
        if (mark[n] == e)
            return 1;
    return 0;
}

/* out = meet(a, b): the nodes of a and b with no proper ancestor in a or b;
 * per part of the hierarchies the coarser of the two cuts. Returns the
 * count. */
static uint32_t meet(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                     uint32_t nb, tclod_id *out) {
    uint32_t e = next_epoch(sch), i, n = 0;
    for (i = 0; i < na; ++i)
        sch->mark_a[a[i]] = e;
    for (i = 0; i < nb; ++i)
        sch->mark_a[b[i]] = e;
    for (i = 0; i < na + nb; ++i) {
        tclod_id v = i < na ? a[i] : b[i - na];
        if (sch->done[v] == e)
            continue;
        sch->done[v] = e;
        if (!below_mark(sch, sch->mark_a, e, v))
            out[n++] = v;
    }
    return n;
}

/* The region of node v: the region of its nearest ancestor-or-self that is a
 * region root (marked e), or TCLOD_NONE. */
static uint32_t region_at(const tclod_scheduler *sch, uint32_t e, tclod_id v) {
    const tclod_id *parent = sch->scene->parent;
    for (; v != TCLOD_NONE; v = parent[v])
        if (sch->region_mark[v] == e)
            return sch->region_of[v];
    return TCLOD_NONE;
}

/* Cuts the hierarchies into the regions of meet(lists 0 and 1), each rooted
 * at a node of that meet, and buckets the nodes of the three lists by region
 * (region_list() gives them back). Marks the members of list 0 with mark_b and
 * those of list 1 with mark_c, epoch returned. */
static uint32_t schedule_partition(tclod_scheduler *sch, const tclod_id *const lists[3],
                                   const uint32_t sizes[3]) {
    uint32_t roots = meet(sch, lists[0], sizes[0], lists[1], sizes[1], sch->list_r);
    uint32_t e = next_epoch(sch), r, l, i, total = 0;
    writable_plan(sch);
    for (i = 0; i < sizes[0]; ++i)
        sch->mark_b[lists[0][i]] = e;
    for (i = 0; i < sizes[1]; ++i)
        sch->mark_c[lists[1][i]] = e;
    for (r = 0; r < roots; ++r) {
        tclod_id q = sch->list_r[r];
        sch->region_mark[q] = e;
        sch->region_of[q] = r;
        PLAN(sch)->regions[r].root = q;
        PLAN(sch)->regions[r].kind = REGION_STATIC;
        PLAN(sch)->regions[r].depth = 0;
        sch->counts[3u * r] = sch->counts[3u * r + 1u] = sch->counts[3u * r + 2u] = 0;
    }
    for (l = 0; l < 3u; ++l)
        for (i = 0; i < sizes[l]; ++i) {
            r = region_at(sch, e, lists[l][i]);
            if (r != TCLOD_NONE)
                sch->counts[3u * r + l]++;
        }
    for (r = 0; r < roots; ++r) { /* counts become each list's write position */
        uint32_t c0 = sch->counts[3u * r], c1 = sch->counts[3u * r + 1u];
        uint32_t c2 = sch->counts[3u * r + 2u];
        PLAN(sch)->regions[r].first = total;
        PLAN(sch)->regions[r].count = c0 + c1 + c2;
        sch->counts[3u * r] = total;
        sch->counts[3u * r + 1u] = total + c0;
        sch->counts[3u * r + 2u] = total + c0 + c1;
        total += c0 + c1 + c2;
    }
    for (l = 0; l < 3u; ++l)
        for (i = 0; i < sizes[l]; ++i) {
            r = region_at(sch, e, lists[l][i]);
            if (r != TCLOD_NONE)
                PLAN(sch)->nodes[sch->counts[3u * r + l]++] = lists[l][i];
        }
    PLAN(sch)->region_count = roots;
    return e;
}

/* The nodes of list l in region r after schedule_partition(): PLAN(sch)->nodes[*first ..
 * *first + *count). */
static void region_list(const tclod_scheduler *sch, uint32_t r, uint32_t l, uint32_t *first,
                        uint32_t *count) {
    uint32_t start = l == 0u ? PLAN(sch)->regions[r].first : sch->counts[3u * r + l - 1u];
    *first = start;
    *count = sch->counts[3u * r + l] - start;
}

/* Whether two node lists hold the same set. */
static int same_nodes(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                      uint32_t nb) {
    uint32_t e, i;
    if (na != nb)
        return 0;
    e = next_epoch(sch);
    for (i = 0; i < na; ++i)
        sch->done[a[i]] = e;
    for (i = 0; i < nb; ++i)
        if (sch->done[b[i]] != e)
            return 0;
    return 1;
}

/* Counts one level change, morphed or switched. */
static void count_change(tclod_scheduler *sch, int morphed) {
    sch->p.stats.changes++;
    if (morphed)
        sch->p.stats.morphs++;
    else
        sch->p.stats.pops++;
}

/* Counts the level changes of a switch from cut a to cut b: the regions in
 * which a drawn node gives way to drawn nodes below it, or the reverse.
 * Overwrites the plan's regions. */
static void count_switches(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                           uint32_t nb) {
    const tclod_id *lists[3];
    uint32_t sizes[3], e, r;
    lists[0] = a;
    lists[1] = lists[2] = b;
    sizes[0] = na;
    sizes[1] = sizes[2] = nb;
    e = schedule_partition(sch, lists, sizes);
    for (r = 0; r < PLAN(sch)->region_count; ++r) {
        tclod_id q = PLAN(sch)->regions[r].root;
        uint32_t f, n0, n1;
        int in_a = sch->mark_b[q] == e, in_b = sch->mark_c[q] == e;
        region_list(sch, r, 0, &f, &n0);
        region_list(sch, r, 1, &f, &n1);
        if ((in_a && !in_b && n1 > 0) || (in_b && !in_a && n0 > 0))
            count_change(sch, 0);
    }
}

/* ---- predicted costs ------------------------------------------------------------------------- */

static void memo_set(tclod_scheduler *sch, tclod_id n, double cost) {
    plan_state *P = PLAN(sch);
    P->memo_mark[n] = P->memo_epoch;
    P->memo_cost[n] = cost;
    P->memo_visible[n] = 1;
}

/* Counts a bad value from the scheduler's own evaluations; strict mode fails
 * the update. */
static void bad_value(tclod_scheduler *sch) {
    sch->p.stats.invalid_values++;
    if (sch->sel->desc.strict)
        sch->failed = 1;
}

/* Node n's cost for the latest selection's views, from the callbacks;
 * *visible is 0 (and the cost 0) when those views do not see it. */
static double predicted_cost(tclod_scheduler *sch, tclod_id n, int *visible) {
    const tclod_scene *s = sch->scene;
    tclod_query q;
    tclod_bounds qb;
    double benefit, cost = 0.0;
    memset(&q, 0, sizeof q);
    q.id = tclod_scene_owner(s, n);
    q.count = 1;
    q.view = &sch->sv.conservative;
    q.screen_area = q.distance = -1.0f;
    tclod_scene_public_bounds(s, q.id, &qb);
    q.bounds = qb.kind != TCLOD_BOUNDS_NONE ? &qb : NULL;
    if (q.bounds) {
        double d;
        tclod_view_measure_bounds(&sch->sv.conservative_cache, &s->bounds[n], s->boxes,
                                  &q.screen_area, &d);
        q.distance = (float)d;
    }
    benefit = wrap_benefit(sch, &q);
    if (value_bad(benefit)) {
        bad_value(sch);
        benefit = 0.0;
    }
    if (benefit > 0.0) {
        cost = wrap_cost(sch, &q);
        if (value_bad(cost)) {
            bad_value(sch);
            cost = HUGE_VAL;
        }
    }
    *visible = benefit > 0.0;
    return cost;
}

/* The predicted cost of node n for the current plan: the cost a landed
 * selection drew it with, else predicted_cost(); *visible as there. */
static double memo(tclod_scheduler *sch, tclod_id n, int *visible) {
    plan_state *P = PLAN(sch);
    if (P->memo_mark[n] != P->memo_epoch) {
        int vis;
        P->memo_cost[n] = predicted_cost(sch, n, &vis);
        P->memo_mark[n] = P->memo_epoch;
        P->memo_visible[n] = (uint8_t)vis;
    }
    *visible = P->memo_visible[n];
    return P->memo_cost[n];
}

/* The ancestor of v at depth `depth` (<= v's). */
static tclod_id ancestor_at(const tclod_scheduler *sch, tclod_id v, uint32_t depth) {
    while (sch->depth[v] > depth)
        v = sch->scene->parent[v];
    return v;
}

/* The nodes a morph region draws at level position s in [0, depth]: the
 * coarse node at 0, the fine side at depth, and in between, with
 * k = floor(s), the fine nodes at relative depth <= k and the distinct
 * ancestors at relative depth k + 1 of the others, those geomorphed from their
 * parents with weight s - k. Calls emit(sch, fine, coarse, weight, ctx) for
 * each visible one. */
typedef void (*emit_fn)(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                        void *ctx);

static void morph_state(tclod_scheduler *sch, const region *R, double s, emit_fn emit, void *ctx) {
    uint32_t base = sch->depth[R->root], k, i, stamp;
    float w;
    int vis;
    const plan_state *P = PLAN(sch);
    if (s <= 0.0) {
        memo(sch, R->root, &vis);
        if (vis)
            emit(sch, R->root, R->root, 1.0f, ctx);
        return;
    }
    if (s >= (double)R->depth) {
        k = R->depth;
        w = 1.0f;
    } else {
        k = (uint32_t)s;
        w = (float)(s - (double)k);
    }
    stamp = next_epoch(sch);
    for (i = 0; i < R->count; ++i) {
        tclod_id leaf = P->nodes[R->first + i], m;
        if (sch->depth[leaf] - base <= k) {
            memo(sch, leaf, &vis);
            if (vis)
                emit(sch, leaf, leaf, 1.0f, ctx);
            continue;
        }
        m = ancestor_at(sch, leaf, base + k + 1u);
        if (sch->done[m] == stamp)
            continue;
        sch->done[m] = stamp;
        memo(sch, m, &vis);
        if (vis)
            emit(sch, m, sch->scene->parent[m], w, ctx);
    }
}

static void add_cost(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                     void *ctx) {
    int vis;
    (void)coarse;
    (void)weight;
    *(double *)ctx += memo(sch, fine, &vis);
}

/* ---- residency ------------------------------------------------------------------------------- */

static void make_plan(tclod_scheduler *sch);

/* Whether every node a morph region passes through is resident: q, its fine
 * side and the nodes between them. The levels in turn draw each of them, and
 * the coarse end of every morph item is one of them. */
static int morph_resident(tclod_scheduler *sch, const region *R) {
    const tclod_scene *s = sch->scene;
    const plan_state *P = PLAN(sch);
    uint32_t stamp, i;
    if (tclod_scene_absent(s, R->root))
        return 0;
    stamp = next_epoch(sch);
    for (i = 0; i < R->count; ++i) {
        tclod_id m;
        for (m = P->nodes[R->first + i]; m != R->root && sch->done[m] != stamp; m = s->parent[m]) {
            sch->done[m] = stamp;
            if (tclod_scene_absent(s, m))
                return 0;
        }
    }
    return 1;
}

/* The regions of the plan in use that draw a node not resident at some point
 * of the interval. */
static uint32_t absent_regions(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    const plan_state *P = PLAN(sch);
    uint32_t r, i, hits = 0;
    for (r = 0; r < P->region_count; ++r) {
        const region *R = &P->regions[r];
        int ok = 1;
        if (R->kind == REGION_STATIC)
            for (i = 0; i < R->count && ok; ++i)
                ok = !tclod_scene_absent(s, P->nodes[R->first + i]);
        else
            ok = morph_resident(sch, R);
        hits += !ok;
    }
    return hits;
}

/* What a landed selection draws in place of node n, which is not resident:
 * what a selector would draw, the nearest resident ancestor through
 * replacing parents; TCLOD_NONE (nothing) past a root or an additive node,
 * whose child's hierarchy draws nothing until it arrives. */
static tclod_id fallback(const tclod_scene *s, tclod_id n) {
    for (;;) {
        tclod_id p = s->parent[n];
        if (p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD))
            return TCLOD_NONE;
        if (!tclod_scene_absent(s, p))
            return p;
        n = p;
    }
}

/* Replaces each node of generation g that is not resident by its fallback
 * (costed for the latest selection's views) and takes out what lies below a
 * fallback. Returns whether g changed. */
static int repair(tclod_scheduler *sch, uint32_t g) {
    const tclod_scene *s = sch->scene;
    generation *G = &sch->gen[g];
    uint32_t i, k, e;
    for (i = 0; i < G->count && !tclod_scene_absent(s, G->ids[i]); ++i)
        ;
    if (i == G->count)
        return 0;
    e = next_epoch(sch);
    for (; i < G->count; ++i) {
        tclod_id f;
        int vis;
        if (!tclod_scene_absent(s, G->ids[i]))
            continue;
        f = fallback(s, G->ids[i]);
        G->ids[i] = f;
        G->cost[i] = 0.0;
        if (f != TCLOD_NONE && sch->mark_a[f] != e) { /* its first place: costed */
            sch->mark_a[f] = e;
            G->cost[i] = predicted_cost(sch, f, &vis);
        }
    }
    for (i = k = 0; i < G->count; ++i) {
        tclod_id n = G->ids[i];
        if (n == TCLOD_NONE || sch->done[n] == e || below_mark(sch, sch->mark_a, e, n))
            continue;
        sch->done[n] = e;
        G->ids[k] = n;
        G->cost[k++] = G->cost[i];
    }
    G->count = k;
    return 1;
}

/* After the scene's residency changed: the landed selections the pipeline
 * draws from lose the nodes not resident (repair), and a plan that would
 * draw one of them is made again, each region that drew one switching at
 * once (a pop). The changes of the interval are not counted again. */
static void sync_residency(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    uint32_t hits;
    if (sch->p.residency_version == s->residency_version)
        return;
    sch->p.residency_version = s->residency_version;
    if (!tclod_scene_streams(s))
        return;
    repair(sch, sch->p.prev);
    repair(sch, sch->p.cur);
    repair(sch, sch->p.next);
    if (sch->p.ready)
        repair(sch, sch->p.landing);
    hits = absent_regions(sch);
    if (hits > 0) {
        tclod_scheduler_stats kept = sch->p.stats;
        make_plan(sch);
        sch->p.stats.changes = kept.changes + hits;
        sch->p.stats.morphs = kept.morphs;
        sch->p.stats.pops = kept.pops + hits;
    }
}

/* Names the nodes of the landed selections the pipeline draws from as the
 * ones the selector's plan keeps, with their ancestors (which hold every node
 * a morph draws, at either end), for the selector call that follows (then
 * unkeep). Only a plan with a memory budget evicts. */
static void keep_landed(tclod_scheduler *sch) {
    tclod_stream_state *S = &sch->sel->stream;
    uint32_t slots[4], count = 3, e, k, i, n = 0;
    if (!(S->desc.memory_budget > 0.0))
        return;
    slots[0] = sch->p.prev;
    slots[1] = sch->p.cur;
    slots[2] = sch->p.next;
    if (sch->p.ready)
        slots[count++] = sch->p.landing;
    e = next_epoch(sch);
    for (k = 0; k < count; ++k)
        for (i = 0; i < sch->gen[slots[k]].count; ++i) {
            tclod_id id = sch->gen[slots[k]].ids[i];
            if (sch->done[id] != e) {
                sch->done[id] = e;
                sch->list_r[n++] = id;
            }
        }
    S->keep = sch->list_r;
    S->keep_count = n;
}

static void unkeep(tclod_scheduler *sch) {
    sch->sel->stream.keep = NULL;
    sch->sel->stream.keep_count = 0;
}

/* ---- plans ----------------------------------------------------------------------------------- */

/* Makes region r of the plan: q alone, or a morph from its X side (list 0) to
 * its Y side (list 1) -- when every state it passes through costs no more
 * than S_j's nodes in it (list 2) and every node it draws is resident; else
 * S_j's nodes as they are. */
static void plan_region(tclod_scheduler *sch, uint32_t r, uint32_t e) {
    region *R = &PLAN(sch)->regions[r], plan = *R;
    tclod_id q = R->root;
    uint32_t fx, nx, fy, ny, fc, nc, i;
    int in_x = sch->mark_b[q] == e, in_y = sch->mark_c[q] == e, vis;
    double allowed = 0.0, worst = 0.0;
    region_list(sch, r, 0, &fx, &nx);
    region_list(sch, r, 1, &fy, &ny);
    region_list(sch, r, 2, &fc, &nc);
    for (i = 0; i < nc; ++i)
        allowed += memo(sch, PLAN(sch)->nodes[fc + i], &vis);
    if (in_x && !in_y && ny > 0) {
        plan.kind = REGION_UP;
        plan.first = fy;
        plan.count = ny;
    } else if (in_y && !in_x && nx > 0) {
        plan.kind = REGION_DOWN;
        plan.first = fx;
        plan.count = nx;
    } else { /* q alone: in both, or appearing, or disappearing */
        plan.kind = REGION_STATIC;
        plan.first = in_x ? fx : fy;
        plan.count = 1;
    }
    if (plan.kind == REGION_STATIC) {
        worst = memo(sch, q, &vis);
    } else {
        uint32_t k;
        plan.depth = 0;
        for (i = 0; i < plan.count; ++i) {
            uint32_t rel = sch->depth[PLAN(sch)->nodes[plan.first + i]] - sch->depth[q];
            if (rel > plan.depth)
                plan.depth = rel;
        }
        /* the states: q, each level's morph, the fine side */
        for (k = 0; k <= plan.depth + 1u && worst <= allowed; ++k) {
            double c = 0.0;
            morph_state(sch, &plan,
                        k == 0u           ? 0.0
                        : k <= plan.depth ? (double)k - 0.5
                                          : (double)plan.depth,
                        add_cost, &c);
            if (c > worst)
                worst = c;
        }
    }
    if (worst <= allowed && (plan.kind == REGION_STATIC || !tclod_scene_streams(sch->scene) ||
                             morph_resident(sch, &plan))) {
        *R = plan;
        if (plan.kind != REGION_STATIC)
            count_change(sch, 1);
        return;
    }
    /* too dear somewhere, or not resident: S_j's nodes, switched to at the
     * start and from at the end */
    if (nx > 0 && nc > 0 && !same_nodes(sch, PLAN(sch)->nodes + fx, nx, PLAN(sch)->nodes + fc, nc))
        count_change(sch, 0);
    if (ny > 0 && nc > 0 && !same_nodes(sch, PLAN(sch)->nodes + fc, nc, PLAN(sch)->nodes + fy, ny))
        count_change(sch, 0);
    R->kind = REGION_STATIC;
    R->first = fc;
    R->count = nc;
    R->depth = 0;
}

/* The plan of the current interval: with morphing from
 * X_j = meet(S_{j-1}, S_j) to Y_j = meet(S_j, S_{j+1}); without, S_j. */
static void make_plan(tclod_scheduler *sch) {
    const generation *P = &sch->gen[sch->p.prev], *C = &sch->gen[sch->p.cur];
    const generation *N = &sch->gen[sch->p.next];
    const generation *by_priority[3];
    const tclod_id *lists[3];
    uint32_t sizes[3], e, r, i;
    int g;
    writable_plan(sch);
    update_depths(sch);
    next_memo_epoch(sch);
    /* predicted costs: S_j's where it drew the node, else the newest's */
    by_priority[0] = P;
    by_priority[1] = N;
    by_priority[2] = C;
    for (g = 0; g < 3; ++g)
        for (i = 0; i < by_priority[g]->count; ++i)
            memo_set(sch, by_priority[g]->ids[i], by_priority[g]->cost[i]);
    if (!sch->desc.two_stage) {
        sizes[0] = meet(sch, P->ids, P->count, C->ids, C->count, sch->list_x);
        sizes[1] = meet(sch, C->ids, C->count, N->ids, N->count, sch->list_y);
        lists[0] = sch->list_x;
        lists[1] = sch->list_y;
    } else {
        lists[0] = lists[1] = C->ids;
        sizes[0] = sizes[1] = C->count;
    }
    lists[2] = C->ids;
    sizes[2] = C->count;
    e = schedule_partition(sch, lists, sizes);
    for (r = 0; r < PLAN(sch)->region_count; ++r)
        plan_region(sch, r, e);
}

/* ---- the draw list -----------------------------------------------------------------------------
 */

static void emit_item(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                      void *ctx) {
    tclod_draw *d = &sch->items[sch->back][sch->item_count[sch->back]++];
    int vis;
    /* the host's ids: a self leaf is its additive node, which does not morph */
    d->fine = tclod_scene_owner(sch->scene, fine);
    d->coarse = tclod_scene_owner(sch->scene, coarse);
    d->weight = d->fine == d->coarse ? 1.0f : weight;
    *(double *)ctx += memo(sch, fine, &vis);
}

/* This frame's draw list at position u of the interval, and its predicted
 * cost: the items' in order, then S_j's smooth groups' (an object's
 * resolution never exceeds S_j's in the interval), summed as the selector
 * sums its result. */
static void make_draws(tclod_scheduler *sch) {
    const tclod_draw *items = sch->items[sch->back];
    double cost = 0.0;
    uint32_t r, i, morphing = 0;
    const plan_state *P = PLAN(sch);
    sch->item_count[sch->back] = 0;
    for (r = 0; r < P->region_count; ++r) {
        const region *R = &P->regions[r];
        if (R->kind == REGION_STATIC) {
            for (i = 0; i < R->count; ++i) {
                tclod_id n = P->nodes[R->first + i];
                emit_item(sch, n, n, 1.0f, &cost);
            }
            continue;
        }
        morph_state(sch, R, (double)R->depth * (R->kind == REGION_UP ? sch->p.u : 1.0 - sch->p.u),
                    emit_item, &cost);
    }
    for (i = 0; i < sch->item_count[sch->back]; ++i)
        morphing += items[i].fine != items[i].coarse;
    for (i = 0; i < sch->gen[sch->p.cur].groups; ++i)
        cost += sch->gen[sch->p.cur].group_cost[i];
    sch->p.stats.draw_cost = cost;
    sch->p.stats.draws = sch->item_count[sch->back];
    sch->p.stats.morphing = morphing;
}

/* ---- the pipeline -------------------------------------------------------------------------------
 */

/* Selection time of an update: clock_in before a selector call, clock_out
 * after it. */
static double clock_in(void) {
    return tclod_now();
}

static void clock_out(tclod_scheduler *sch, double start) {
    sch->p.stats.select_seconds += tclod_now() - start;
}

/* Selects at once for the current view alone and draws that from now on,
 * without morphs: the first update, after a gap, a changed scene, or a draw
 * list over the budget. The pending selection is dropped and begun again. */
static tclod_status select_now(tclod_scheduler *sch, const tclod_view *view, int count_pops) {
    tclod_frame f;
    tclod_stats stats;
    tclod_status st;
    uint32_t i, n, g;
    double start = clock_in();
    sch->touched = 1;
    tclod_select_cancel(sch->sel);
    sch->p.ready = 0;
    sch->p.lost = 0;
    g = fresh_slot(sch);
    memset(&f, 0, sizeof f);
    f.view = view;
    f.budget = sch->p.budget;
    sch->current_only = 1;
    st = tclod_select(sch->sel, &f, &stats);
    sch->current_only = 0;
    clock_out(sch, start);
    if (st != TCLOD_OK)
        return st;
    sch->p.stats.invalid_values += stats.invalid_values;
    sch->p.stats.emergencies++;
    sch->p.stats.selection_benefit = stats.benefit;
    sch->p.stats.selection_cost = stats.cost;
    store(sch, g);
    if (count_pops) { /* from what this frame would have drawn */
        n = sch->item_count[sch->back];
        for (i = 0; i < n; ++i)
            sch->list_x[i] = sch->items[sch->back][i].fine;
        count_switches(sch, sch->list_x, n, sch->gen[g].ids, sch->gen[g].count);
    }
    sch->p.prev = sch->p.cur = sch->p.next = g;
    sch->p.node_version = sch->scene->node_version;
    sch->p.smooth_version = sch->scene->smooth_version;
    sch->p.residency_version = sch->scene->residency_version; /* it drew resident nodes */
    make_plan(sch);
    start = clock_in();
    st = begin(sch, view);
    clock_out(sch, start);
    return st;
}

/* The pending selection has finished (stats st): its result is copied now,
 * while the selector's costs are this solve's, and lands at the next
 * boundary. */
static void finished(tclod_scheduler *sch, const tclod_stats *st) {
    sch->p.landing = fresh_slot(sch);
    store(sch, sch->p.landing);
    if (tclod_scene_streams(sch->scene)) /* what was evicted since it saw it */
        repair(sch, sch->p.landing);
    sch->p.ready = 1;
    sch->p.landed_invalid = st->invalid_values;
    sch->p.landed_benefit = st->benefit;
    sch->p.landed_cost = st->cost;
}

/* At a boundary: the pending selection ends (early if need be; one begun
 * again after a failed update runs to its end) and joins the landed ones;
 * the plan of the new interval is made. A selection that fails in strict
 * mode fails the update. */
static tclod_status land(tclod_scheduler *sch) {
    uint32_t fresh;
    if (!sch->p.ready) {
        tclod_stats st;
        tclod_status status;
        int done = 0;
        double start = clock_in();
        sch->touched = 1;
        keep_landed(sch);
        if (sch->p.redo)
            status = tclod_select_step(sch->sel, 0.0, 0, &done, &st);
        else
            status = tclod_select_finish(sch->sel, &st);
        unkeep(sch);
        clock_out(sch, start);
        if (status != TCLOD_OK)
            return status;
        if (st.stop_reason == TCLOD_STOP_FINISHED)
            sch->p.stats.unfinished++;
        finished(sch, &st);
    }
    fresh = sch->p.landing;
    sch->p.stats.invalid_values += sch->p.landed_invalid;
    sch->p.stats.selection_benefit = sch->p.landed_benefit;
    sch->p.stats.selection_cost = sch->p.landed_cost;
    if (!sch->desc.two_stage) {
        /* S_{j-1}, S_j, S_{j+1} <- S_j, S_{j+1}, the new one */
        sch->p.prev = sch->p.cur;
        sch->p.cur = sch->p.next;
        sch->p.next = fresh;
    } else {
        sch->p.prev = sch->p.cur;
        sch->p.cur = sch->p.next = fresh;
        count_switches(sch, sch->gen[sch->p.prev].ids, sch->gen[sch->p.prev].count,
                       sch->gen[sch->p.cur].ids, sch->gen[sch->p.cur].count);
    }
    sch->p.ready = 0;
    sch->p.redo = 0;
    sch->p.stats.selections++;
    make_plan(sch);
    return TCLOD_OK;
}

/* Why an update's arguments are refused (NULL: they are not), written after
 * the "view->" of a view's rule. */
static const char *arguments_why(const tclod_scheduler *sch, double now, const tclod_view *view,
                                 double budget, double slice) {
    if (!view)
        return "view is NULL";
    if (tclod_view_check(view))
        return tclod_view_check(view);
    if (isnan(now) || isinf(now))
        return "now must be finite";
    if (sch->shown.started && now < sch->p.now)
        return "now must not be earlier than the last successful update's";
    if (!(budget >= 0.0))
        return "budget must be >= 0 (not NaN)";
    if (!(slice >= 0.0) || isinf(slice))
        return "slice_seconds must be finite and >= 0";
    if (!tclod_selector_scene_ok(sch->sel))
        return TCLOD_MSG_SMOOTH;
    return NULL;
}

/* Generation slot g is one the pipeline or the outputs use. */
static int slot_used(const tclod_scheduler *sch, uint32_t g) {
    return g == sch->p.prev || g == sch->p.cur || g == sch->p.next || g == sch->shown.prev ||
           g == sch->shown.cur || g == sch->shown.next || (sch->p.ready && g == sch->p.landing);
}

/* After the scene changed: the landed selections lose the nodes removed
 * since (the scene's index no longer holds them), so that they leave the
 * draw list now, mid-morph too. Removed smooth objects leave at the update's
 * success (clear_removed_smooth): until then the outputs show the last
 * successful update's resolutions. Returns whether the plan must be made
 * again. */
static int purge(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    int nodes = sch->p.node_version != s->node_version;
    uint32_t g, i, k;
    if (nodes)
        for (g = 0; g < GEN_SLOTS; ++g) {
            generation *G = &sch->gen[g];
            if (!slot_used(sch, g))
                continue;
            for (i = k = 0; i < G->count; ++i)
                if (tclod_scene_indexed(s, G->ids[i])) {
                    G->ids[k] = G->ids[i];
                    G->cost[k++] = G->cost[i];
                }
            G->count = k;
        }
    if (sch->p.smooth_version != s->smooth_version)
        sch->smooth_removed = 1;
    sch->p.node_version = s->node_version;
    sch->p.smooth_version = s->smooth_version;
    return nodes;
}

/* A successful update: the smooth objects removed before it show resolution
 * 0 in every generation it left in use. */
static void clear_removed_smooth(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    uint32_t g, i;
    for (g = 0; g < GEN_SLOTS; ++g)
        if (slot_used(sch, g))
            for (i = 0; i < s->smooth_count; ++i)
                if (!tclod_scene_smooth_live(s, i))
                    sch->gen[g].res[i] = 0.0;
}

/* The pipeline's work of one update; the outputs are made in the back
 * buffers. */
static tclod_status advance(tclod_scheduler *sch, double now, const tclod_view *view,
                            double slice_seconds) {
    const double tau = sch->desc.tau;
    tclod_status st = TCLOD_OK;
    /* a restart: the first update, a changed scene, a long gap, or times so
     * large that tau no longer moves the boundary (checked at every step:
     * rounding to even can move it once and then not again) */
    int restart = !sch->p.started || now - sch->p.boundary > (MAX_GAP + 1.0) * tau;
    if (!restart && purge(sch))
        make_plan(sch);
    if (!restart)
        sync_residency(sch);
    if (!restart && sch->p.lost) {
        double start = clock_in();
        st = begin_again(sch);
        clock_out(sch, start);
        if (st != TCLOD_OK)
            return st;
    }
    while (!restart && now >= sch->p.boundary + tau) {
        double start;
        if (!(sch->p.boundary + tau > sch->p.boundary)) {
            restart = 1;
            break;
        }
        sch->p.boundary += tau;
        st = land(sch);
        if (st != TCLOD_OK)
            return st;
        start = clock_in();
        st = begin(sch, view);
        clock_out(sch, start);
        if (st != TCLOD_OK)
            return st;
    }
    if (restart) {
        sch->p.boundary = now;
        sch->item_count[sch->back] = 0;
        st = select_now(sch, view, 0);
        if (st != TCLOD_OK)
            return st;
        sch->p.started = 1;
    }
    sch->p.u = (now - sch->p.boundary) / tau;
    if (!(sch->p.u >= 0.0))
        sch->p.u = 0.0;
    if (sch->p.u > 1.0)
        sch->p.u = 1.0;
    make_draws(sch);
    if (sch->p.stats.draw_cost > sch->p.budget) {
        st = select_now(sch, view, 1);
        if (st != TCLOD_OK)
            return st;
        make_draws(sch);
    }
    if (!sch->p.ready) {
        tclod_stats stats;
        int done = 0;
        double start = clock_in();
        sch->touched = 1;
        keep_landed(sch);
        st = tclod_select_step(sch->sel, slice_seconds, 0, &done, &stats);
        unkeep(sch);
        clock_out(sch, start);
        if (st == TCLOD_OK && done)
            finished(sch, &stats);
    }
    return st;
}

/* Keeps what an update may change, so that a failure can put it back. */
static void keep(tclod_scheduler *sch) {
    sch->saved = sch->p;
    sch->saved_hist_t = sch->hist_t[sch->p.hist_next];
    sch->saved_hist_v = sch->hist_v[sch->p.hist_next];
    sch->views_saved = 0;
    sch->touched = 0;
    sch->pending_at_start = tclod_select_pending(sch->sel);
    sch->smooth_removed = 0;
    tclod_selector_keep(sch->sel, &sch->kept);
}

/* Puts back what keep() kept: the update failed. The selection pending
 * before it is lost if the update called the selector (it may have ended,
 * landed or been dropped): the next update begins it again. */
static void put_back(tclod_scheduler *sch) {
    sch->p = sch->saved;
    sch->hist_t[sch->p.hist_next] = sch->saved_hist_t;
    sch->hist_v[sch->p.hist_next] = sch->saved_hist_v;
    if (sch->views_saved)
        sch->sv = sch->saved_views;
    if (sch->touched) {
        tclod_select_cancel(sch->sel);
        tclod_selector_restore(sch->sel, &sch->kept);
        if (sch->pending_at_start)
            sch->p.lost = 1;
    }
    sch->asked = TCLOD_NONE;
}

tclod_status tclod_scheduler_update(tclod_scheduler *sch, double now, const tclod_view *view,
                                    double budget, double slice_seconds) {
    static const char fn[] = "tclod_scheduler_update";
    tclod_status st;
    uint32_t epoch;
    const char *why;
    if (!sch)
        return TCLOD_ERR_ARG;
    why = arguments_why(sch, now, view, budget, slice_seconds);
    if (why)
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, why);
    if (sch->busy)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    sch->busy = sch->user.busy = 1;
    st = tclod_scene_prepare(sch->scene);
    if (st == TCLOD_OK)
        st = schedule_reserve(sch);
    if (st != TCLOD_OK) {
        sch->busy = sch->user.busy = 0;
        return tclod_fail(sch->error, st, fn, TCLOD_MSG_NOMEM);
    }
    /* a selection under way on a scene that changed since it began is begun
     * again (it saw part of the old scene) */
    if (tclod_select_pending(sch->sel) && sch->sel->pending_version != sch->scene->version) {
        tclod_select_cancel(sch->sel);
        sch->p.lost = 1;
    }
    /* so is one that finished before nodes were added or removed and waits to
     * land: it would leave the added ones out for an interval more */
    if (sch->p.ready && sch->p.node_version != sch->scene->node_version) {
        sch->p.ready = 0;
        sch->p.lost = 1;
    }
    keep(sch);
    epoch = sch->scene->epoch;
    sch->p.stats.select_seconds = 0.0;
    sch->p.budget = budget / tclod_calib_scale(sch->calib);
    sch->p.stats.budget = sch->p.budget;
    sch->p.now = now;
    sch->failed = 0;
    record(sch, now, view);
    st = advance(sch, now, view, slice_seconds);
    if (st == TCLOD_OK && sch->failed)
        st = TCLOD_ERR_CALLBACK;
    if (st == TCLOD_OK) { /* the outputs show this update */
        sch->shown.started = 1;
        sch->shown.prev = sch->p.prev;
        sch->shown.cur = sch->p.cur;
        sch->shown.next = sch->p.next;
        sch->shown.u = sch->p.u;
        sch->shown.items = sch->back;
        sch->shown.stats = sch->p.stats;
        sch->back = 1u - sch->back;
        if (sch->smooth_removed)
            clear_removed_smooth(sch);
        sch->user.synced = epoch; /* its selections name no node removed before that */
    } else {
        if (st == TCLOD_ERR_CALLBACK)
            tclod_fail(sch->error, st, fn, TCLOD_MSG_STRICT);
        else /* the selector's own error */
            tclod_fail(sch->error, st, fn, sch->sel->error);
        put_back(sch);
    }
    tclod_selector_keep(sch->sel, NULL);
    sch->busy = sch->user.busy = 0;
    return st;
}

tclod_status tclod_scheduler_draws(const tclod_scheduler *sch, const tclod_draw **items,
                                   size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    *items = sch->shown.started ? sch->items[sch->shown.items] : NULL;
    *n = sch->shown.started ? sch->item_count[sch->shown.items] : 0u;
    return TCLOD_OK;
}

double tclod_scheduler_resolution(const tclod_scheduler *sch, tclod_id smooth) {
    double p, c, n, from, to;
    if (!sch || !sch->shown.started || smooth >= sch->scene->smooth_count ||
        smooth >= sch->smooth_cap)
        return 0.0;
    if (sch->scene->smooth_flags[smooth] & TCLOD_NODE_ABSENT)
        return 0.0; /* not resident (evicted since a selection drew it): not drawn */
    c = sch->gen[sch->shown.cur].res[smooth];
    if (sch->desc.two_stage)
        return c;
    p = sch->gen[sch->shown.prev].res[smooth];
    n = sch->gen[sch->shown.next].res[smooth];
    from = p < c ? p : c;
    to = c < n ? c : n;
    return from + (to - from) * sch->shown.u;
}

tclod_status tclod_scheduler_report_frame(tclod_scheduler *sch, double render_time,
                                          double logic_time) {
    static const char fn[] = "tclod_scheduler_report_frame";
    if (!sch)
        return TCLOD_ERR_ARG;
    if (!finite_nonnegative(render_time))
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, "render_time must be finite and >= 0");
    if (!(logic_time == (double)TCLOD_OFF || finite_nonnegative(logic_time)))
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn,
                          "logic_time must be finite and >= 0, or TCLOD_OFF");
    if (!sch->shown.started)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, "no update has succeeded yet");
    /* a draw list whose predicted cost overflowed (its roots over the budget)
     * tells nothing about the ratio: only the logic time is followed */
    return tclod_calib_report(sch->calib,
                              isinf(sch->shown.stats.draw_cost) ? 0.0 : sch->shown.stats.draw_cost,
                              render_time, logic_time);
}

const tclod_calib *tclod_scheduler_calib(const tclod_scheduler *sch) {
    return sch ? sch->calib : NULL;
}

tclod_status tclod_scheduler_get_stats(const tclod_scheduler *sch, tclod_scheduler_stats *st) {
    if (!sch || !st)
        return TCLOD_ERR_ARG;
    *st = sch->shown.stats;
    return TCLOD_OK;
}

const char *tclod_scheduler_last_error(const tclod_scheduler *sch) {
    return sch ? sch->error : "";
}

/* ---- streaming ------------------------------------------------------------------ */

tclod_status tclod_scheduler_set_stream(tclod_scheduler *sch, const tclod_stream_desc *d) {
    static const char fn[] = "tclod_scheduler_set_stream";
    const char *why;
    if (!sch)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    why = d ? tclod_stream_desc_check(d) : NULL;
    if (why)
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, why);
    return tclod_selector_set_stream(sch->sel, d);
}

tclod_status tclod_scheduler_requests(const tclod_scheduler *sch, const tclod_stream_item **items,
                                      size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return TCLOD_ERR_STATE;
    return tclod_selector_requests(sch->sel, items, n);
}

tclod_status tclod_scheduler_evictions(const tclod_scheduler *sch, const tclod_stream_item **items,
                                       size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return TCLOD_ERR_STATE;
    return tclod_selector_evictions(sch->sel, items, n);
}
