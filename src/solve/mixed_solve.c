/*
 * TCLOD_SOLVER_MIXED, the solve ([ZMK02 §3.3-3.4]; [Thesis8] ch. 8): its start
 * (the variables of this frame), the phases it runs in turn (fill, the
 * gradient or modelled improvement, the polish, what is left to spend), the
 * safeguard that compares the result with the greedy's alternative, and the
 * exact total it ends with. The steps themselves are in mixed.c.
 *
 * Layer: solve, which may call core, eval and solve. Calls: solve (greedy,
 * mixed.c, split.c).
 */
#include "mixed_internal.h"

#include <math.h>

/* The exact total in result order (cut, then the drawn variables). Should the
 * running sums' drift ever carry it over the budget, the smooth variables are
 * dropped and the cut is repaired as the greedy repairs its own. */
static int mixed_finish(tclod_selector *sel) {
    const tclod_vars *V = &sel->mixed.vars;
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id n = sel->cut[i];
        if (sel->node[n].benefit > 0.0 && !(sel->flags[n] & TCLOD_FLAG_DROPPED))
            sum += sel->node[n].cost;
    }
    for (i = 0; i < V->count; ++i)
        if (V->r[i] > 0.0)
            sum += V->c[i];
    if (!isinf(sum) && sum <= sel->frame->budget)
        return 0;
    for (i = 0; i < V->count; ++i)
        V->r[i] = V->b[i] = V->c[i] = 0.0;
    vars_changed(&sel->mixed.vars);
    sel->reserved = 0.0;
    return tclod_greedy_enforce(sel);
}

/* The stages of a mixed solve (sel->resume.phase). */
enum {
    MIXED_START = 0,
    MIXED_IMPROVE, /* the preconditioned loop, or the papers' */
    MIXED_REST,    /* tclod_mixed_spend_the_rest */
    MIXED_FILL,
    MIXED_POLISH,
    MIXED_SAFEGUARD,
    MIXED_FINISH
};

/* The benefit of the working selection: the cut's and the drawn variables'. */
static double working_benefit(const tclod_selector *sel) {
    const tclod_vars *V = &sel->mixed.vars;
    double sum = sel->benefit_sum;
    uint32_t v;
    for (v = 0; v < V->count; ++v)
        if (V->r[v] > 0.0)
            sum += V->b[v];
    return sum;
}

/* Every variable back at resolution 0 (a variable with a bad benefit stays
 * invisible), its model made again. */
static int restart_variables(tclod_selector *sel) {
    tclod_vars *V = &sel->mixed.vars;
    tclod_resume *R = &sel->resume;
    uint32_t v;
    for (v = 0; v < V->count; ++v) {
        if (V->state[v] != TCLOD_VAR_DEAD)
            V->state[v] = TCLOD_VAR_LIVE;
        V->r[v] = V->b[v] = V->c[v] = 0.0;
    }
    sel->reserved = 0.0;
    R->skipped = R->mixed.smooth_done = 0;
    R->mixed.run = 0;
    R->mixed.matched = TCLOD_NONE;
    R->mixed.guess = 1.0;
    return tclod_mixed_start_variables(sel);
}

/* The greedy's safeguard after the solve (docs/mixed.md): ratio order can be
 * arbitrarily bad for a knapsack, so the selection is compared with the best
 * skipped increment's selection alone, T(n) (the roots, n's increment and the
 * increments above it, the smooth variables at 0). When T(n) is worth more,
 * the solve starts again from it: a second pass of the same stages, whose
 * cut only grows from T(n) and whose smooth variables only add to it. After
 * that pass (*next = MIXED_FINISH), should it still end below T(n) (its
 * result repaired to the budget, say), T(n) alone is the result. A solve
 * stopped by a limit makes no second pass. Returns -1 on a strict error. */
static int safeguard(tclod_selector *sel, int *next) {
    tclod_resume *R = &sel->resume;
    double alt = 0.0, now = working_benefit(sel);
    tclod_id n;
    *next = MIXED_FINISH;
    if (R->mixed.alt_pass) {
        uint32_t v;
        double found;
        tclod_id alt_node = tclod_greedy_found_alternative(sel, &found);
        if (now >= found)
            return 0;
        for (v = 0; v < sel->mixed.vars.count; ++v)
            sel->mixed.vars.r[v] = sel->mixed.vars.b[v] = sel->mixed.vars.c[v] = 0.0;
        vars_changed(&sel->mixed.vars);
        sel->reserved = 0.0;
        return tclod_greedy_force(sel, alt_node);
    }
    if (sel->stopped)
        return 0;
    n = tclod_greedy_alternative(sel, &alt);
    if (n == TCLOD_NONE || !(alt > now * (1.0 + 1e-12)))
        return 0;
    R->mixed.alt_pass = 1;
    sel->reserved = 0.0; /* T(n) holds nothing smooth: the cut has the whole budget */
    if (tclod_greedy_force(sel, n) != 0 || restart_variables(sel) != 0)
        return -1;
    *next = MIXED_IMPROVE;
    return 0;
}

static int mixed_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int rc;
    sel->reserved = 0.0;
    R->skipped = R->mixed.smooth_done = 0;
    R->mixed.run = R->k = 0;
    R->mixed.matched = TCLOD_NONE;
    R->mixed.guess = 1.0;
    rc = tclod_split_variables(sel);
    sel->stats.variables = sel->mixed.vars.count;
    /* no smooth variable this frame: the discrete problem alone, which the
     * greedy solves with its safeguards (the best skipped increment, warm
     * starts) */
    if (rc == 0 && sel->mixed.vars.count == 0) {
        R->mixed.as_greedy = 1;
        return 0;
    }
    if (rc == 0)
        rc = tclod_greedy_start(sel);
    if (rc == 0) {
        tclod_greedy_track(sel);
        rc = tclod_mixed_start_variables(sel);
    }
    return rc;
}

tclod_status tclod_mixed_solve(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int modelled = !sel->desc.mixed.plain_gradient, rc = 0;
    if (R->mixed.as_greedy)
        return tclod_greedy_solve(sel);
    while (rc == 0 && !sel->paused) {
        int next;
        switch (R->phase) {
        case MIXED_START:
            rc = mixed_start(sel);
            if (rc == 0 && R->mixed.as_greedy) {
                R->phase = 0; /* the greedy's start */
                return tclod_greedy_solve(sel);
            }
            next = MIXED_IMPROVE;
            break;
        case MIXED_IMPROVE:
            rc = modelled ? tclod_mixed_improve_modelled(sel) : tclod_mixed_improve_gradient(sel);
            next = modelled ? MIXED_REST : MIXED_SAFEGUARD;
            break;
        case MIXED_REST:
            rc = tclod_mixed_spend_the_rest(sel);
            next = MIXED_FILL;
            break;
        case MIXED_FILL:
            rc = tclod_mixed_fill(sel);
            next = MIXED_POLISH;
            break;
        case MIXED_POLISH:
            rc = tclod_mixed_polish(sel);
            next = MIXED_SAFEGUARD;
            break;
        case MIXED_SAFEGUARD:
            rc = safeguard(sel, &next);
            break;
        default:
            rc = mixed_finish(sel);
            tclod_greedy_end(sel);
            return rc == 0 ? TCLOD_OK : TCLOD_ERR_CALLBACK;
        }
        if (!sel->paused) {
            R->phase = next;
            R->k = 0;
        }
    }
    if (rc == 0)
        return TCLOD_OK;
    tclod_greedy_end(sel);
    return TCLOD_ERR_CALLBACK;
}

/* ---- buffers ------------------------------------------------------------------ */

/* The split stack holds up to one entry per quadtree node, i.e. fewer than
 * two per object. */
size_t tclod_mixed_buffers(tclod_mixed_state *m, tclod_array *out) {
    tclod_vars *v = &m->vars;
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&v->first, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&v->size, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&v->bounds, 4 * sizeof(float), -1};
    out[n++] = (tclod_array){(void **)&v->area, sizeof(float), -1};
    out[n++] = (tclod_array){(void **)&v->distance, sizeof(float), -1};
    out[n++] = (tclod_array){(void **)&v->r, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->b, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->c, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->db, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->dc, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->a, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->ratio, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->up, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&v->moving, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&v->state, sizeof(uint8_t), -1};
    out[n++] = (tclod_array){(void **)&v->trial, sizeof(tclod_var_trial), -1};
    out[n++] = (tclod_array){(void **)&v->model, sizeof(tclod_var_model), -1};
    out[n++] = (tclod_array){(void **)&m->split_node, 2 * sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&m->split_x, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&m->split_theta, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&m->split_order, 2 * sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&m->split_c, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&m->split_q, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&m->split_whole, 2 * sizeof(uint8_t), -1};
    return n;
}
