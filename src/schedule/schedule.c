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
 *
 * This file holds the desc, the prediction, the callbacks the selector calls,
 * the buffers and the selections; schedule_pipeline.c the relations between
 * cuts, the plans, the draw list and the update.
 *
 * Layer: schedule, which may call every layer. Calls: core (alloc.c, scene.c,
 * scene_prepare.c, view.c); select (selector.c); schedule (calib.c).
 */
#include "schedule_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

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
    if (!(d->confidence == (double)TCLOD_OFF || schedule_finite_nonnegative(d->confidence)))
        return "desc.confidence must be finite and > 0, 0 (default) or TCLOD_OFF";
    if (!schedule_finite_nonnegative(d->max_speed))
        return "desc.max_speed must be finite and >= 0";
    if (!schedule_finite_nonnegative(d->max_turn_rate))
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
    if (!schedule_finite_nonnegative(horizon) || !schedule_finite_nonnegative(max_speed) ||
        !schedule_finite_nonnegative(max_turn_rate))
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

void tclod_schedule_record(tclod_scheduler *sch, double now, const tclod_view *view) {
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

double tclod_schedule_wrap_benefit(void *user, const tclod_query *q) {
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
        if (schedule_value_bad(v))
            return v;
        if (v > 0.0)
            sch->asked_mask |= 1u << k;
        sum += v;
    }
    if (uses_conservative(sch)) {
        v = sch->host.benefit(sch->host.user, q);
        if (schedule_value_bad(v))
            return v;
        sum += sch->desc.confidence * v;
    }
    return saturate(sum);
}

double tclod_schedule_wrap_cost(void *user, const tclod_query *q) {
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
        if (schedule_value_bad(v))
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
        if (schedule_value_bad(v) || schedule_value_bad(d)) {
            *d_dr = d;
            return v;
        }
        sum += v;
        slope += d;
    }
    if (uses_conservative(sch)) {
        d = 0.0;
        v = sch->host.smooth_benefit(sch->host.user, q, r, &d);
        if (schedule_value_bad(v) || schedule_value_bad(d)) {
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
        if (schedule_value_bad(v) || schedule_value_bad(d)) {
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
tclod_status tclod_schedule_reserve(tclod_scheduler *sch) {
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
        tclod_scheduler_desc_check(d) || sd->feature_count != 0 || sd->callbacks.features ||
        sd->callbacks.smooth_features)
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
    inner.callbacks.benefit = sd->callbacks.benefit ? tclod_schedule_wrap_benefit : NULL;
    inner.callbacks.cost = sd->callbacks.cost ? tclod_schedule_wrap_cost : NULL;
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
uint32_t tclod_schedule_next_epoch(tclod_scheduler *sch) {
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
void tclod_schedule_writable_plan(tclod_scheduler *sch) {
    if (sch->p.plan == sch->saved.plan)
        sch->p.plan = sch->p.plan == &sch->plans[0] ? &sch->plans[1] : &sch->plans[0];
}

/* A fresh epoch for the predicted costs of a plan. */
uint32_t tclod_schedule_next_memo_epoch(tclod_scheduler *sch) {
    if (++PLAN(sch)->memo_epoch == 0u) {
        memset(PLAN(sch)->memo_mark, 0, sizeof(uint32_t) * sch->node_cap);
        PLAN(sch)->memo_epoch = 1;
    }
    return PLAN(sch)->memo_epoch;
}

/* The depth of every node in the index, when nodes were added or removed. */
void tclod_schedule_update_depths(tclod_scheduler *sch) {
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
tclod_status tclod_schedule_begin(tclod_scheduler *sch, const tclod_view *view) {
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
tclod_status tclod_schedule_begin_again(tclod_scheduler *sch) {
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
void tclod_schedule_store(tclod_scheduler *sch, uint32_t g) {
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
uint32_t tclod_schedule_fresh_slot(const tclod_scheduler *sch) {
    uint32_t g;
    for (g = 0; g < GEN_SLOTS; ++g)
        if (g != sch->p.prev && g != sch->p.cur && g != sch->p.next && g != sch->shown.prev &&
            g != sch->shown.cur && g != sch->shown.next && (!sch->p.ready || g != sch->p.landing))
            return g;
    assert(0);
    return 0;
}
