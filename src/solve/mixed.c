/*
 * TCLOD_SOLVER_MIXED: Mason–Blake increments on discrete nodes interleaved with
 * gradient-ascent steps on smooth variables ([ZMK02 §3.3-3.4]; [Thesis8]
 * ch. 8, eq. 8.1-8.14 and the kinked cost of eq. 8.18).
 *
 * The papers' loop (smooth_precondition = 0) compares the best discrete
 * increment that fits, slope_d = Δb/Δc (eq. 8.8), with the slope of the smooth
 * benefit over the smooth cost along the benefit gradient a (with the barrier
 * of eq. 8.13), slope_c = (a, ∇b) / (a, ∇c) (eq. 8.9-8.11), and takes the
 * steeper: the increment, or a line search along a (eq. 8.12) to t_max (the
 * first variable reaching 1, or the budget) when the slope there still beats
 * slope_d, else to where it has fallen to slope_d (eq. 8.14).
 *
 * Preconditioned (the default), every variable carries a small model of its
 * own benefit slope and of its cost (mixed.md), which predicts where its slope
 * db/dc reaches any given value. The smooth steps between two increments are
 * then predicted rather than made: increments are taken, best first, while
 * their slope beats the slope the smooth variables would have once they shared
 * the budget left (the final state the papers' interleaving reaches); line
 * searches move the variables, all at once, towards the model's targets only
 * when the budget binds, and a last pairwise exchange evens out the slopes the
 * models got wrong. Kinked costs make the slope along a line jump up, so a
 * line search brackets the kinks it finds where the cost's slope along the
 * line falls, and keeps the best of the local maxima on either side of them.
 * Every step keeps the selection within the budget.
 *
 * This file holds the models, the directions, the line search and the steps;
 * mixed_solve.c the solve that runs them. The discrete increments are the
 * greedy's, through greedy.h only.
 *
 * Layer: solve, which may call core, eval and solve. Calls: eval (evaluate.c);
 * solve (greedy).
 */
#include "mixed_internal.h"

#include <math.h>

/* Kinks a line search brackets at most, where the cost slope along the line
 * falls (line_best); the relative change of the cost slope below which it is
 * no kink, and how far a bracket's points lie from the kink, relative to the
 * piece it is put in. */
#define LINE_KINKS 4u
#define KINK_DROP 1e-6
#define KINK_BRACKET 1e-7
/* Secant/bisection steps that refine one crossing or the budget's edge. */
#define REFINE_STEPS 64u
/* The line search keeps this far (relative) inside the budget, so that the
 * drift of running sums never carries the exact total over it. */
#define BUDGET_MARGIN 1e-9

/* The budget less that margin (an unlimited budget stays unlimited). */
static double smooth_limit(double budget) {
    return isinf(budget) ? budget : budget - BUDGET_MARGIN * budget;
}
/* A resolution this close to 0 or 1 is 0 or 1. */
#define SNAP 1e-12
/* The slope along a line counts as the target within this (relative) margin. */
#define SLOPE_TOLERANCE 1e-3
/* A line search gaining less than this (relative) does not count as progress. */
#define STALL 1e-9
/* Smooth steps in a row without a discrete increment, at most. */
#define SMOOTH_RUN 64u
/* Pairwise exchanges at the end of a solve, at most, and the relative gap
 * between slope ratios below which they stop. */
#define POLISH_STEPS 16u
/* Plain gradient steps that spend what the models' tolerances left, at most. */
#define REST_STEPS 4u
#define POLISH_GAP 0.01
/* Exponent assumed until a variable has two points of its own: a square-root
 * benefit, the thesis's model (eq. 8.20). */
#define BETA_PRIOR 0.5
/* Exponents outside this range are not believed (the benefit must grow). */
#define BETA_MIN 0.05
#define BETA_MAX 0.95

TCLOD_ALWAYS_INLINE int var_call(tclod_selector *sel, uint32_t v, double x, double *b, double *db,
                                 double *c, double *dc) {
    const tclod_vars *V = &sel->mixed.vars;
    return tclod_smooth_call_inline(sel, V->first[v], V->size[v], &V->bounds[4u * v], V->area[v],
                                    V->distance[v], x, b, db, c, dc);
}

/* The slope ratio db/dc of a point: +inf for a free gain, 0 for none. */
static double slope_ratio(double db, double dc) {
    double q = dc > 0.0 ? db / dc : (db > 0.0 ? HUGE_VAL : 0.0);
    return q > 0.0 ? q : 0.0;
}

/* ---- the per-variable model of the preconditioner ----------------------------- *
 *
 * Benefit slope: a power law through the anchor (x_a, db_a), db(x) = db_a
 * (x / x_a)^-beta; beta starts at the square root's 1/2 and then follows the
 * secant exponent of the slopes the line searches measured. Cost: two lines,
 * dc0 x from 0 and c1 - dc1 (1 - x) through the cost at full resolution,
 * meeting at the kink xk = (c1 - dc1) / (dc0 - dc1): exact for eq. 8.18's setup
 * cost (xk is then the point where every tree has one splat), and one line
 * through 0 for a linear cost (xk = 0). On each line the best resolution at
 * slope lambda is where db = lambda dc; past the kink the setup cost c1 - dc1
 * has to be paid, which is worth it only below the slope lambda_c where both
 * give the same b - lambda c (docs/mixed.md derives ln lambda_c = lc). */

static double model_cost(const tclod_var_model *m, double x) {
    double c;
    if (!(x > 0.0))
        return 0.0;
    c = x <= m->xk ? m->dc0 * x : m->c1 - m->dc1 * (1.0 - x);
    return c > 0.0 ? c : 0.0;
}

/* The model's best resolution at slope lambda > 0 (ln lambda given too). */
static double model_target(const tclod_var_model *m, double log_lambda) {
    double u, lo, hi;
    if (m->xk > 0.0 && log_lambda > m->lc) { /* before the kink */
        u = m->l0 - log_lambda / m->beta;
        lo = -HUGE_VAL;
        hi = m->lxk;
    } else {
        u = m->l1 - log_lambda / m->beta;
        lo = m->lxk;
        hi = 0.0;
    }
    u = u > hi ? hi : (u < lo ? lo : u);
    return exp(u);
}

/* Where variable v heads for slope lambda (0: full resolution): its model
 * target, unless the measured slopes say otherwise about the way to go: up
 * only while its slope past the kink (vars.up) beats lambda, down only while
 * its slope falls short of it. vars.ratio and vars.up must be current. */
static double var_target(const tclod_vars *V, uint32_t v, double lambda, double log_lambda) {
    double r = V->r[v], x;
    if (V->state[v] != TCLOD_VAR_LIVE)
        return r;
    x = lambda > 0.0 ? model_target(&V->model[v], log_lambda) : 1.0;
    if ((x > r && !(V->up[v] > lambda)) || (x < r && !(V->ratio[v] < lambda)))
        return r;
    return x;
}

/* What the variables would add in cost at slope lambda, by their models
 * (variables taken down give back what they cost). */
static double model_spend(const tclod_vars *V, double lambda) {
    double spend = 0.0, log_lambda = lambda > 0.0 ? log(lambda) : 0.0;
    uint32_t v;
    for (v = 0; v < V->count; ++v) {
        double x = var_target(V, v, lambda, log_lambda);
        if (x != V->r[v])
            spend += model_cost(&V->model[v], x) - V->c[v];
    }
    return spend;
}

/* Where spend_exceeds puts its bound: at first SPEND_BOUND_REACH below the
 * slope tested (in ln lambda), never more than SPEND_BOUND_MAX_REACH below,
 * and only when the spend there is below `left` by more than SPEND_BOUND_GAP
 * of it. EXP_SLACK and EXP_FLOOR: relative and absolute margins on a target
 * for the rounding of exp (within an ulp in every libm of note). */
#define SPEND_BOUND_REACH 0.5
#define SPEND_BOUND_MAX_REACH 16.0
#define SPEND_BOUND_GAP 0.3
#define EXP_SLACK 1e-14
#define EXP_FLOOR 1e-300

/* At least model_cost(x') for every resolution x' <= x. Each of the two lines
 * rises with x in floating point too: up to the kink, the first line at x;
 * past it, the larger of the first line at the kink and the second at x
 * (+inf where they are not numbers). */
static double model_cost_above(const tclod_var_model *m, double x) {
    double a, b = 0.0;
    if (isnan(x))
        return HUGE_VAL;
    if (!(x > 0.0))
        return 0.0;
    if (x <= m->xk) {
        a = m->dc0 * x;
    } else {
        a = m->dc0 * m->xk;
        b = m->c1 - m->dc1 * (1.0 - x);
    }
    if (isnan(a) || isnan(b))
        return HUGE_VAL;
    a = a > b ? a : b;
    return a > 0.0 ? a : 0.0;
}

/* Sets vars.bound to at least the spend model_spend computes at any slope
 * whose ln is at least log_lambda. Every variable's target there is at least
 * its target at any such slope: ln lambda / beta only grows, each clamp
 * keeps the order, and past lambda_c (from the part past the kink to the
 * one before it) the target falls below x_k; exp keeps the order to within
 * EXP_SLACK. So a live variable adds at most model_cost_above its target here
 * less its cost now, and no less than 0 (where it stays put it adds
 * nothing); summed in the same order, as floating-point addition keeps the
 * order of its terms, the bound is at least model_spend's sum (or that sum
 * is NaN, which model_spend's callers read as not above). */
static void bound_spend(tclod_vars *V, double log_lambda) {
    double bound = 0.0;
    uint32_t v;
    for (v = 0; v < V->count; ++v) {
        double x, t;
        if (V->state[v] != TCLOD_VAR_LIVE)
            continue;
        x = model_target(&V->model[v], log_lambda);
        x = x * (1.0 + EXP_SLACK) + EXP_FLOOR;
        t = model_cost_above(&V->model[v], x) - V->c[v];
        bound += isnan(t) ? HUGE_VAL : (t > 0.0 ? t : 0.0);
    }
    V->bounded = 1;
    V->bound_log = log_lambda;
    V->bound = bound;
}

/* model_spend(lambda) > left, settled by the bound of an earlier call where
 * it can be (a bound within `left` puts the spend within it). The increments
 * are tested best first, at falling slopes and with less and less left, so
 * when the spend is well within `left` a bound is made for the tests that
 * follow at a slope below lambda: twice as far below as the last one when
 * that one stayed within `left`, half as far when it did not. */
static int spend_exceeds(tclod_vars *V, double lambda, double left) {
    double spend;
    if (lambda > 0.0 && V->bounded && log(lambda) >= V->bound_log && !(V->bound > left)) {
        assert(!(model_spend(V, lambda) > V->bound));
        return 0;
    }
    spend = model_spend(V, lambda);
    if (spend > left)
        return 1;
    if (lambda > 0.0 && isfinite(lambda) && isfinite(left) &&
        spend < left - SPEND_BOUND_GAP * fabs(left)) {
        bound_spend(V, log(lambda) - V->bound_reach);
        if (V->bound > left)
            V->bound_reach *= 0.5;
        else if (V->bound_reach < SPEND_BOUND_MAX_REACH)
            V->bound_reach *= 2.0;
    }
    return 0;
}

/* The slope at which the models predict the smooth variables to have spent
 * `left` more than they cost now (left < 0: given back): 0 when they fit at
 * full resolution, +inf when even nothing drawn does not give back enough.
 * Regula falsi with the Illinois correction on ln(lambda) from `guess`, down
 * to a spend within a thousandth of the budget (setup costs make the spend
 * jump; the method then halves). */
static double level(const tclod_selector *sel, double left, double guess) {
    const tclod_vars *V = &sel->mixed.vars;
    double tol = 1e-3 * fabs(sel->frame->budget), lo, hi, flo, fhi, spent;
    uint32_t k;
    int side = 0;
    if (!(model_spend(V, 0.0) > left))
        return 0.0;
    if (!(-sel->reserved <= left))
        return HUGE_VAL;
    hi = log(guess > 0.0 && isfinite(guess) ? guess : 1.0);
    if ((fhi = model_spend(V, exp(hi)) - left) > 0.0) {
        /* the spend at hi is the low end's once the one at hi + 4 is not
         * above left */
        flo = fhi;
        for (k = 0; (fhi = model_spend(V, exp(hi + 4.0)) - left) > 0.0; ++k) {
            if (k == 64)
                return HUGE_VAL;
            hi += 4.0;
            flo = fhi;
        }
        lo = hi;
        hi += 4.0;
    } else {
        for (lo = hi - 4.0, k = 0; !((flo = model_spend(V, exp(lo)) - left) > 0.0); ++k) {
            if (k == 64)
                return exp(lo);
            hi = lo;
            fhi = flo;
            lo -= 4.0;
        }
    }
    /* spent: the spend at hi as evaluated; fhi may be halved by the Illinois
     * correction, and only steers the next point */
    for (k = 0, spent = fhi; k < 64 && hi - lo > 1e-9 && -spent > tol; ++k) {
        double u = lo + (hi - lo) * flo / (flo - fhi), f;
        if (!(u > lo && u < hi))
            u = 0.5 * (lo + hi);
        f = model_spend(V, exp(u)) - left;
        if (f > 0.0) {
            lo = u;
            flo = f;
            if (side > 0)
                fhi *= 0.5;
            side = 1;
        } else {
            hi = u;
            fhi = spent = f;
            if (side < 0)
                flo *= 0.5;
            side = -1;
        }
    }
    return exp(hi);
}

/* The model's logarithms, kept so that a target costs one exponential. With
 * db(x) = D x^-beta (D = db_a x_a^beta) and gamma = (1 - beta) / beta, the
 * best b - lambda c on a line of slope s is K + beta / (1 - beta) D^(1+gamma)
 * (lambda s)^-gamma minus lambda times its intercept, so the part past the
 * kink wins below lambda_c = (A / c0)^beta, A = beta / (1 - beta) D^(1+gamma)
 * (dc1^-gamma - dc0^-gamma), c0 = c1 - dc1 its setup cost. */
static void model_refresh(tclod_var_model *m) {
    double beta = m->beta, gamma = (1.0 - beta) / beta, log_d, w;
    if (!(m->db > 0.0)) { /* no gain: stays at 0 */
        m->l0 = m->l1 = -HUGE_VAL;
        m->lc = HUGE_VAL;
        return;
    }
    /* ln 1 = 0: the first anchor, at full resolution */
    log_d = log(m->db) + beta * (m->x == 1.0 ? 0.0 : log(m->x));
    m->l1 = m->dc1 > 0.0 ? (log_d - m->ldc1) / beta : HUGE_VAL;
    m->l0 = m->dc0 > 0.0 ? (log_d - m->ldc0) / beta : HUGE_VAL;
    m->lc = -HUGE_VAL;
    if (m->xk > 0.0 && m->c1 - m->dc1 > 0.0 &&
        (w = pow(m->dc1, -gamma) - pow(m->dc0, -gamma)) > 0.0)
        m->lc = beta * (log(beta / (1.0 - beta)) + (1.0 + gamma) * log_d + log(w) - m->lsetup);
}

/* Anchors a benefit model at (x, db). */
static void anchor_model(tclod_var_model *m, double x, double db) {
    m->x = x;
    m->db = db;
    model_refresh(m);
}

/* The cost model from the slope just above 0 and the cost and slope at 1. */
static void cost_model(tclod_var_model *m, double dc0, double c1, double dc1) {
    m->dc0 = dc0;
    m->c1 = c1;
    m->dc1 = dc1;
    m->xk = 0.0;
    if (dc0 > dc1 * (1.0 + 1e-9) && c1 > dc1) {
        double xk = (c1 - dc1) / (dc0 - dc1);
        m->xk = xk < 1.0 ? xk : 1.0;
    }
    /* the logarithms model_refresh needs of them, taken once */
    m->lxk = m->xk > 0.0 ? log(m->xk) : -HUGE_VAL;
    m->ldc0 = dc0 > 0.0 ? log(dc0) : 0.0;
    m->ldc1 = dc1 > 0.0 ? log(dc1) : 0.0;
    m->lsetup = c1 - dc1 > 0.0 ? log(c1 - dc1) : 0.0;
}

/* After variable v moved to its trial point: the model is re-anchored there,
 * with the exponent of the secant (in log-log space) through the benefit slope
 * at the trial point evaluated before it, which the line search's refinement
 * leaves close by. */
static void update_model(tclod_vars *V, uint32_t v) {
    const tclod_var_trial *t = &V->trial[v];
    tclod_var_model *m = &V->model[v];
    if (!(t->x > 0.0) || !(t->db > 0.0))
        return;
    if (t->qx > 0.0 && t->qdb > 0.0 && fabs(t->x - t->qx) > 1e-6 * t->x) {
        double secant = log(t->qdb / t->db) / log(t->x / t->qx);
        if (secant >= BETA_MIN && secant <= BETA_MAX)
            m->beta = secant;
    }
    anchor_model(m, t->x, t->db);
}

/* Every variable starts at 0 (not drawn, no benefit, no cost) with the slopes
 * just above it, and its model from one probe at full resolution: a model
 * anchored just above 0 would extrapolate over orders of magnitude, and a
 * kinked cost's slope there is not the one further on. A bad benefit makes the
 * variable invisible for this solve. */
int tclod_mixed_start_variables(tclod_selector *sel) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t v;
    vars_changed(V);
    V->bound_reach = SPEND_BOUND_REACH;
    for (v = 0; v < V->count; ++v) {
        double b, c = 0.0, db = 0.0, dc = 0.0;
        tclod_var_model *m = &V->model[v];
        if (V->state[v] == TCLOD_VAR_DEAD)
            continue; /* known invisible: not asked again */
        if (var_call(sel, v, 0.0, &b, &V->db[v], &c, &V->dc[v]) ||
            var_call(sel, v, 1.0, &b, &db, &c, &dc)) {
            V->state[v] = TCLOD_VAR_DEAD; /* a model of no gain, from no value it was not given */
            c = db = dc = 0.0;
        }
        if (sel->failed)
            return -1;
        m->beta = BETA_PRIOR;
        cost_model(m, V->dc[v], c, dc);
        anchor_model(m, 1.0, db);
        V->trial[v].qx = 0.0;
    }
    return 0;
}

/* Variable v's own slope db/dc into vars.ratio (0 when it cannot gain: not
 * live, no benefit slope, or an infinite cost slope) and, when it is live,
 * the slope of a step up into vars.up (where a unit costs less past the
 * kink, with the cost slope there). */
static void var_ratio(tclod_vars *V, uint32_t v) {
    const tclod_var_model *m = &V->model[v];
    V->ratio[v] = 0.0;
    if (V->state[v] != TCLOD_VAR_LIVE)
        return;
    V->up[v] = slope_ratio(V->db[v], V->r[v] < m->xk && m->dc1 < V->dc[v] ? m->dc1 : V->dc[v]);
    if (V->db[v] > 0.0)
        V->ratio[v] = slope_ratio(V->db[v], V->dc[v]);
}

/* Makes vars.ratio and vars.up current: var_ratio of every variable. They
 * change only with the variables, so only those that changed are done again
 * (moving_changed), or all after vars_changed. */
static void ratios(tclod_selector *sel) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t v;
    if (!V->fresh)
        for (v = 0; v < V->count; ++v)
            var_ratio(V, v);
    V->fresh = 1;
}

/* ratios, then the largest ratio among the variables below full resolution. */
static double top_ratio(tclod_selector *sel) {
    const tclod_vars *V = &sel->mixed.vars;
    double best = 0.0;
    uint32_t v;
    ratios(sel);
    for (v = 0; v < V->count; ++v)
        if (V->r[v] < 1.0 && V->ratio[v] > best)
            best = V->ratio[v];
    return best;
}

/* The n variables of vars.moving changed: their ratios are made again (the
 * others' stand) and the bound on the models' spend no longer holds. */
static void moving_changed(tclod_vars *V, uint32_t n) {
    uint32_t i;
    V->bounded = 0;
    if (V->fresh)
        for (i = 0; i < n; ++i)
            var_ratio(V, V->moving[i]);
}

/* ---- search directions ------------------------------------------------------------ */

/* Lists the moving variables in vars.moving, scales a to a largest component
 * of 1 and returns their number, with slope_c = (a, db) / (a, dc) (eq. 8.11)
 * in *slope: +inf when the step gains benefit without adding cost. 0 when the
 * direction gains no benefit. */
static uint32_t finish_direction(tclod_selector *sel, double *slope) {
    tclod_vars *V = &sel->mixed.vars;
    double a_max = 0.0, num = 0.0, den = 0.0;
    uint32_t v, n = 0, i;
    for (v = 0; v < V->count; ++v)
        if (V->a[v] != 0.0) {
            V->moving[n++] = v;
            if (fabs(V->a[v]) > a_max)
                a_max = fabs(V->a[v]);
        }
    for (i = 0; i < n; ++i) {
        v = V->moving[i];
        V->a[v] /= a_max;
        num += V->a[v] * V->db[v];
        den += V->a[v] * V->dc[v];
    }
    if (!(num > 0.0))
        return 0;
    *slope = den > 0.0 ? num / den : HUGE_VAL;
    return n;
}

/* The papers' direction: a_v = db/dr - eps' / (1 - r) with the barrier eps'
 * of eq. 8.13 taken relative to the variable's slope (eps' = eps db/dr), so
 * that it does not depend on the benefit's scale; 0 for saturated variables. */
static uint32_t gradient_direction(tclod_selector *sel, double eps, double *slope) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t v;
    for (v = 0; v < V->count; ++v) {
        double f = V->ratio[v] > 0.0 && V->r[v] < 1.0 ? 1.0 - eps / (1.0 - V->r[v]) : 0.0;
        V->a[v] = f > 0.0 ? V->db[v] * f : 0.0;
    }
    return finish_direction(sel, slope);
}

/* The preconditioned direction towards slope `target`: every variable heads
 * for var_target, up when its slope is above the target and down when an
 * earlier step took it past (a diagonal quasi-Newton step). */
static uint32_t model_direction(tclod_selector *sel, double target, double *slope) {
    tclod_vars *V = &sel->mixed.vars;
    double log_target = target > 0.0 ? log(target) : 0.0;
    uint32_t v;
    for (v = 0; v < V->count; ++v) {
        double dx = var_target(V, v, target, log_target) - V->r[v];
        V->a[v] = fabs(dx) > SNAP ? dx : 0.0;
    }
    return finish_direction(sel, slope);
}

/* Scales down the rising components of the n moving variables' direction so
 * that, to first order, the falling ones pay for them: a step that trades
 * resolution between variables at constant cost. Returns 0 when nothing falls
 * to pay for it. */
static int level_direction(tclod_selector *sel, uint32_t n) {
    tclod_vars *V = &sel->mixed.vars;
    double up = 0.0, down = 0.0, scale;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        double dc = V->a[V->moving[i]] * V->dc[V->moving[i]];
        if (dc > 0.0)
            up += dc;
        else
            down -= dc;
    }
    if (!(down > 0.0) || !(up > down))
        return 0;
    scale = down / up;
    for (i = 0; i < n; ++i)
        if (V->a[V->moving[i]] * V->dc[V->moving[i]] > 0.0)
            V->a[V->moving[i]] *= scale;
    return 1;
}

/* ---- the line search (eq. 8.12-8.14) ---------------------------------------- */

/* The moving variables at x + t a: their summed benefit and cost, and the
 * derivatives of those sums along the line (saturated variables no longer
 * move). */
typedef struct line_point {
    double t, benefit, cost, slope_b, slope_c;
    double abs_b, abs_c; /* sums of |a db| and |a dc|: how large the slopes' terms are */
} line_point;

typedef struct line {
    uint32_t n;        /* vars.moving[0 .. n) */
    double t_sat;      /* the first variable reaches 0 or 1 */
    double other_cost; /* the rest of the selection */
    double limit;      /* the budget, less the margin */
    double lambda;     /* slope to match: slope_d, or the best ratio left out */
    double last_t;     /* the trial arrays hold this point */
} line;

static int line_eval(tclod_selector *sel, line *L, double t, line_point *p) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t i;
    p->t = t;
    p->benefit = p->cost = p->slope_b = p->slope_c = p->abs_b = p->abs_c = 0.0;
    for (i = 0; i < L->n; ++i) {
        uint32_t v = V->moving[i];
        double x = V->r[v] + t * V->a[v];
        /* past a bound a variable stays there; on it, its slope still counts
         * (from inside), so that t_max is judged by the slope that led there */
        int saturated = x > 1.0 + SNAP || x < -SNAP;
        x = x >= 1.0 - SNAP ? 1.0 : (x <= SNAP ? 0.0 : x);
        /* the callbacks are asked no lower; the resolution is what they saw */
        if (x > 0.0 && x < TCLOD_SLOPE_FLOOR)
            x = TCLOD_SLOPE_FLOOR;
        V->trial[v].qx = V->trial[v].x;
        V->trial[v].qdb = V->trial[v].db;
        var_call(sel, v, x, &V->trial[v].b, &V->trial[v].db, &V->trial[v].c, &V->trial[v].dc);
        if (x == 0.0)
            V->trial[v].b = V->trial[v].c = 0.0; /* not drawn; slopes kept */
        V->trial[v].x = x;
        p->benefit += V->trial[v].b;
        p->cost += V->trial[v].c;
        if (!saturated) {
            p->slope_b += V->a[v] * V->trial[v].db;
            p->slope_c += V->a[v] * V->trial[v].dc;
            p->abs_b += fabs(V->a[v]) * V->trial[v].db;
            p->abs_c += fabs(V->a[v]) * V->trial[v].dc;
        }
    }
    L->last_t = t;
    return sel->failed ? -1 : 0;
}

static int line_fits(const line *L, const line_point *p) {
    return L->other_cost + p->cost <= L->limit;
}

/* The objective whose stationary points are eq. 8.14's, and its derivative. */
static double line_value(const line *L, const line_point *p) {
    return p->benefit - L->lambda * p->cost;
}

static double line_slope(const line *L, const line_point *p) {
    return p->slope_b - L->lambda * p->slope_c;
}

static int slope_matched(const line *L, const line_point *p) {
    double g = line_slope(L, p);
    return fabs(g) <= SLOPE_TOLERANCE * (p->abs_b + L->lambda * p->abs_c);
}

/* Moves *lo (fits) towards hi (does not) to the budget's edge: regula falsi
 * on the total cost with the Illinois correction, bisection where the cost is
 * not finite. */
static int seek_budget(tclod_selector *sel, line *L, line_point *lo, line_point hi) {
    double flo = L->other_cost + lo->cost - L->limit, fhi = L->other_cost + hi.cost - L->limit;
    int side = 0;
    uint32_t k;
    for (k = 0; k < REFINE_STEPS; ++k) {
        double w = hi.t - lo->t, t, f;
        line_point p;
        /* the test reads lo's own cost: flo may be halved by the Illinois
         * correction */
        if (w <= 1e-12 * L->t_sat || L->other_cost + lo->cost - L->limit >= -1e-12 * fabs(L->limit))
            break;
        t = isfinite(fhi) ? lo->t + w * (-flo) / (fhi - flo) : lo->t + 0.5 * w;
        if (!(t > lo->t && t < hi.t))
            t = lo->t + 0.5 * w;
        if (line_eval(sel, L, t, &p) != 0)
            return -1;
        f = L->other_cost + p.cost - L->limit;
        if (f <= 0.0) {
            *lo = p;
            flo = f;
            if (side < 0)
                fhi *= 0.5;
            side = -1;
        } else {
            hi = p;
            fhi = f;
            if (side > 0)
                flo *= 0.5;
            side = 1;
        }
    }
    return 0;
}

/* Where the slope along the line falls from above lambda (at a) to lambda or
 * below (at b): regula falsi with the Illinois correction; at a kink where it
 * jumps across lambda, the kink. The better end (by line_value) goes to *out;
 * only points that fit are kept. */
static int seek_slope(tclod_selector *sel, line *L, line_point a, line_point b, line_point *out) {
    double ga = line_slope(L, &a), gb = line_slope(L, &b);
    int side = 0;
    uint32_t k;
    for (k = 0; k < REFINE_STEPS; ++k) {
        double w = b.t - a.t, t, g;
        line_point p;
        if (w <= 1e-12 * L->t_sat)
            break;
        t = isfinite(gb) ? a.t + w * ga / (ga - gb) : a.t + 0.5 * w;
        if (!(t > a.t && t < b.t))
            t = a.t + 0.5 * w;
        if (line_eval(sel, L, t, &p) != 0)
            return -1;
        if (!line_fits(L, &p)) {
            b = p;
            gb = -HUGE_VAL;
            continue;
        }
        g = line_slope(L, &p);
        if (slope_matched(L, &p)) {
            a = b = p;
            break;
        }
        if (g > 0.0) {
            a = p;
            ga = g;
            if (side > 0)
                gb *= 0.5;
            side = 1;
        } else {
            b = p;
            gb = g;
            if (side < 0)
                ga *= 0.5;
            side = -1;
        }
    }
    *out = (line_fits(L, &b) && line_value(L, &b) > line_value(L, &a)) ? b : a;
    return 0;
}

/* Whether the slope along the line may fall to lambda or below somewhere in
 * (p, q) and rise above it again: the line's cost slope fell from p to q (a
 * variable passed a kink where its cost gets cheaper, as eq. 8.18's setup
 * ends, and the slope of phi jumps up there), and phi's slope is not surely
 * positive all the way (benefit slopes fall along the line, so it is at least
 * q's benefit slope less lambda times the larger cost slope). */
static int may_hide_kink(const line *L, const line_point *p, const line_point *q) {
    double steepest = p->slope_c > q->slope_c ? p->slope_c : q->slope_c;
    return p->slope_c - q->slope_c > KINK_DROP * (p->abs_c + q->abs_c) &&
           !(q->slope_b - L->lambda * steepest > 0.0);
}

/* A point of line_best's list, and whether the piece up to the next point is
 * settled: one kink, bracketed, lies just past the point. */
typedef struct line_node {
    line_point p;
    int settled;
} line_node;

/* The best point of phi on [origin, top] (eq. 8.14, kinked costs included).
 * Breakpoints first: where the line's cost slope falls between two points
 * (may_hide_kink), a kink is put where the two points' cost tangents meet
 * (exactly there for one kink of a piecewise-linear cost) and a point just
 * before it is evaluated, at most LINE_KINKS times. If that point still lies
 * on p's tangent, the piece up to it is linear and the kink is the only one
 * up to q: bracketed. Past the kink the slope of phi is higher than just
 * before it, so a point just after it is needed only when phi falls just
 * before it (another crossing may follow). Then on every piece between two
 * points at which the slope falls from above lambda to below it, the crossing
 * is refined; every crossing and every point is a candidate, and the one with
 * the largest phi wins (the earliest of equal ones). Without a kink this is
 * the plain eq. 8.14: t_max when the slope there still beats lambda, else the
 * one crossing. */
static int line_best(tclod_selector *sel, line *L, const line_point *origin, const line_point *top,
                     line_point *best) {
    line_node pts[2u + 2u * LINE_KINKS];
    uint32_t count = 2, kinks = 0, i, j;
    pts[0].p = *origin;
    pts[1].p = *top;
    pts[0].settled = pts[1].settled = 0;
    for (i = 0; i + 1u < count && kinks < LINE_KINKS;) {
        const line_point *p = &pts[i].p, *q = &pts[i + 1u].p;
        double t, w = q->t - p->t, scale = p->abs_c + q->abs_c;
        line_node at[2];
        uint32_t added = 0;
        if (pts[i].settled || !may_hide_kink(L, p, q)) {
            ++i;
            continue;
        }
        kinks++;
        t = (q->cost - p->cost + p->slope_c * p->t - q->slope_c * q->t) / (p->slope_c - q->slope_c);
        if (!(t > p->t + KINK_BRACKET * w && t < q->t))
            t = p->t + 0.5 * w;
        if (line_eval(sel, L, t - KINK_BRACKET * w, &at[0].p) != 0)
            return -1;
        if (!line_fits(L, &at[0].p))
            break; /* a cost that is not monotone: no bracket */
        at[0].settled =
            fabs(at[0].p.slope_c - p->slope_c) <= KINK_DROP * scale &&
            fabs(at[0].p.cost - p->cost - p->slope_c * (at[0].p.t - p->t)) <= KINK_DROP * scale * w;
        added = 1;
        if (at[0].settled && !(line_slope(L, &at[0].p) > 0.0)) {
            if (line_eval(sel, L, t + KINK_BRACKET * w, &at[1].p) != 0)
                return -1;
            at[1].settled = 0;
            added += (uint32_t)line_fits(L, &at[1].p);
        }
        /* the points after p move up to make room, in order */
        for (j = count; j-- > i + 1u;)
            pts[j + added] = pts[j];
        for (j = 0; j < added; ++j)
            pts[i + 1u + j] = at[j];
        count += added;
    }
    *best = pts[0].p;
    for (i = 0; i < count; ++i) {
        const line_point *p = &pts[i].p;
        if (i > 0 && line_slope(L, &pts[i - 1u].p) > 0.0 && !(line_slope(L, p) > 0.0) &&
            !slope_matched(L, p) && !slope_matched(L, &pts[i - 1u].p)) {
            line_point found;
            if (seek_slope(sel, L, pts[i - 1u].p, *p, &found) != 0)
                return -1;
            if (line_value(L, &found) > line_value(L, best))
                *best = found;
        }
        if (line_value(L, p) > line_value(L, best))
            *best = *p;
    }
    return 0;
}

/* One line search over the n moving variables. Returns 1 when they moved (the
 * new resolutions and values are in place), 0 when no step fits, -1 on a strict
 * error. *budget_bound says whether t_max came from the budget; *matched
 * whether the step ended where the slope fell to lambda; *stalled whether it
 * gained next to nothing. */
static int line_search(tclod_selector *sel, uint32_t n, double lambda, int *budget_bound,
                       int *matched, int *stalled) {
    tclod_vars *V = &sel->mixed.vars;
    double budget = sel->frame->budget, moving_cost = 0.0;
    line_point origin, top, best;
    line L;
    uint32_t i;
    int limited = 0;
    L.n = n;
    L.lambda = lambda;
    L.t_sat = HUGE_VAL;
    L.last_t = -1.0;
    L.limit = smooth_limit(budget);
    origin.t = origin.benefit = origin.cost = origin.slope_b = origin.slope_c = 0.0;
    origin.abs_b = origin.abs_c = 0.0;
    for (i = 0; i < n; ++i) {
        uint32_t v = V->moving[i];
        double t = V->a[v] > 0.0 ? (1.0 - V->r[v]) / V->a[v] : V->r[v] / -V->a[v];
        if (t < L.t_sat)
            L.t_sat = t;
        origin.benefit += V->b[v];
        origin.cost += V->c[v];
        origin.slope_b += V->a[v] * V->db[v];
        origin.slope_c += V->a[v] * V->dc[v];
        origin.abs_b += fabs(V->a[v]) * V->db[v];
        origin.abs_c += fabs(V->a[v]) * V->dc[v];
        /* the origin is the first point the trial arrays remember */
        V->trial[v].x = V->r[v];
        V->trial[v].db = V->db[v];
        V->trial[v].dc = V->dc[v];
    }
    moving_cost = origin.cost;
    L.other_cost = sel->cost_sum + sel->reserved - moving_cost;
    *budget_bound = *matched = *stalled = 0;

    if (line_eval(sel, &L, L.t_sat, &top) != 0)
        return -1;
    if (!line_fits(&L, &top)) {
        line_point lo = origin;
        limited = 1;
        if (seek_budget(sel, &L, &lo, top) != 0)
            return -1;
        top = lo;
        if (!(top.t > 0.0)) {
            *budget_bound = 1;
            return 0;
        }
    }
    if (line_best(sel, &L, &origin, &top, &best) != 0)
        return -1;
    *matched = best.t < top.t;
    *budget_bound = limited && !*matched;
    /* no step at all when the line only loses (its slope starts below lambda) */
    if (!(best.t > 0.0) || !(line_value(&L, &best) > line_value(&L, &origin)))
        return 0;
    if (L.last_t != best.t && line_eval(sel, &L, best.t, &best) != 0)
        return -1;
    if (!line_fits(&L, &best))
        return 0; /* a host whose values changed */
    for (i = 0; i < n; ++i) {
        uint32_t v = V->moving[i];
        update_model(V, v);
        V->r[v] = V->trial[v].x;
        V->b[v] = V->trial[v].b;
        V->c[v] = V->trial[v].c;
        V->db[v] = V->trial[v].db;
        V->dc[v] = V->trial[v].dc;
    }
    moving_changed(V, n);
    sel->reserved += best.cost - moving_cost;
    *stalled = line_value(&L, &best) - line_value(&L, &origin) <=
               STALL * (fabs(origin.benefit) + fabs(best.benefit));
    return 1;
}

/* ---- the solve ------------------------------------------------------------------ */

static void block_moving(tclod_selector *sel, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; ++i)
        sel->mixed.vars.state[sel->mixed.vars.moving[i]] = TCLOD_VAR_BLOCKED;
    moving_changed(&sel->mixed.vars, n);
}

/* The papers' loop (eq. 8.8-8.14) with the gradient direction. */
int tclod_mixed_improve_gradient(tclod_selector *sel) {
    const tclod_selector_desc *d = &sel->desc;
    double keep = 1.0 - d->mixed.smooth_tolerance;
    tclod_resume *R = &sel->resume;
    for (;;) {
        double slope_d = 0.0, slope_c = 0.0, target;
        uint32_t n = 0;
        int moved, budget_bound, at_slope, stalled;
        tclod_id cand;
        if (tclod_out_of_time(sel))
            return 0;
        cand = tclod_greedy_candidate(sel, &slope_d, &R->skipped);
        if (cand != TCLOD_NONE && cand == R->mixed.matched) { /* Figure 8.1: Q, then P */
            if (tclod_greedy_take(sel, cand) != 0)
                return -1;
            R->mixed.matched = TCLOD_NONE;
            R->mixed.run = 0;
            continue;
        }
        if (!R->mixed.smooth_done && top_ratio(sel) > 0.0) {
            n = gradient_direction(sel, d->mixed.smooth_epsilon, &slope_c);
            if (n == 0 && d->mixed.smooth_epsilon > 0.0)
                n = gradient_direction(sel, 0.0, &slope_c);
        }
        if (cand == TCLOD_NONE && n == 0)
            break;
        if (cand != TCLOD_NONE && (n == 0 || slope_d >= slope_c)) {
            if (tclod_greedy_take(sel, cand) != 0)
                return -1;
            R->mixed.run = 0;
            continue;
        }
        target = cand != TCLOD_NONE ? keep * slope_d : 0.0;
        sel->stats.iterations++;
        sel->stats.line_searches++;
        moved = line_search(sel, n, target, &budget_bound, &at_slope, &stalled);
        if (moved < 0)
            return -1;
        if (budget_bound) {
            R->skipped = 1;
            R->mixed.smooth_done = 1; /* t_max came from the budget: it is spent */
        }
        if (moved && !stalled) {
            if (++R->mixed.run >= SMOOTH_RUN)
                R->mixed.smooth_done = 1;
            if (at_slope && cand != TCLOD_NONE)
                R->mixed.matched = cand;
        } else if (cand != TCLOD_NONE) {
            if (tclod_greedy_take(sel, cand) != 0)
                return -1;
            R->mixed.run = 0;
        } else if (moved || budget_bound) {
            R->mixed.smooth_done = 1;
        } else {
            block_moving(sel, n);
        }
    }
    sel->stats.stop_reason = R->skipped ? TCLOD_STOP_BUDGET : TCLOD_STOP_FINEST;
    return 0;
}

/* One preconditioned smooth step towards slope `target`. Returns 1 when the
 * variables moved and gained, 0 when not, -1 on a strict error; *budget_bound
 * as line_search's. */
static int smooth_step(tclod_selector *sel, double target, int *budget_bound) {
    double slope;
    int moved, at_slope, stalled;
    uint32_t n;
    *budget_bound = 0;
    n = model_direction(sel, target, &slope);
    if (n == 0)
        return 0;
    sel->stats.iterations++;
    sel->stats.line_searches++;
    moved = line_search(sel, n, target, budget_bound, &at_slope, &stalled);
    if (moved == 0 && *budget_bound && level_direction(sel, n)) {
        /* at the budget the models' spend was off: trade at constant cost */
        sel->stats.iterations++;
        sel->stats.line_searches++;
        moved = line_search(sel, n, target, budget_bound, &at_slope, &stalled);
    }
    return moved < 0 ? -1 : (moved && !stalled);
}

/* What the models' tolerances left of the budget goes to the smooth variables
 * along the plain gradient, up to t_max (the papers' step without a discrete
 * step to compare with). */
int tclod_mixed_spend_the_rest(tclod_selector *sel) {
    uint32_t *k = &sel->resume.k;
    for (; *k < REST_STEPS; ++*k) {
        double slope;
        int moved, budget_bound, at_slope, stalled;
        uint32_t n;
        if (tclod_out_of_time(sel))
            return 0;
        ratios(sel);
        n = gradient_direction(sel, 0.0, &slope);
        if (n == 0)
            return 0;
        sel->stats.iterations++;
        sel->stats.line_searches++;
        moved = line_search(sel, n, 0.0, &budget_bound, &at_slope, &stalled);
        if (moved < 0)
            return -1;
        if (!moved || stalled || budget_bound)
            return 0;
    }
    return 0;
}

/* The preconditioned loop: increments best first while their slope beats the
 * slope the smooth variables would have after sharing the budget left with
 * them (a smooth step first makes room when they hold it now), then smooth
 * steps towards the slope at which they spend what is left, until they stop
 * gaining; then the increments that still fit. */
int tclod_mixed_improve_modelled(tclod_selector *sel) {
    const double budget = sel->frame->budget;
    const double limit = smooth_limit(budget);
    tclod_resume *R = &sel->resume;
    int budget_bound;
    for (;;) {
        double slope_d = 0.0, held = sel->reserved, at;
        tclod_id cand;
        int moved;
        if (tclod_out_of_time(sel))
            return 0;
        ratios(sel);
        /* what fits with the smooth variables at nothing; the rest never will */
        sel->reserved = 0.0;
        cand = tclod_greedy_candidate(sel, &slope_d, &R->skipped);
        sel->reserved = held;
        if (cand != TCLOD_NONE) {
            double dc = tclod_greedy_increment_cost(sel, cand),
                   left = budget - sel->cost_sum - held;
            if (dc > 0.0)
                left -= dc;
            /* its slope beats the smooth variables' at the budget left after it
             * exactly when, at its slope, they would spend no more than that */
            if (!spend_exceeds(&sel->mixed.vars, slope_d, left)) {
                if (tclod_within(sel, sel->cost_sum + held + dc, budget)) {
                    if (tclod_greedy_take(sel, cand) != 0)
                        return -1;
                    R->mixed.run = 0;
                    continue;
                }
                /* make room: the smooth variables come down to where they
                 * leave it */
                at = level(sel, left - (budget - limit), slope_d);
                moved = smooth_step(sel, at, &budget_bound);
                if (moved < 0)
                    return -1;
                if (!moved || ++R->mixed.run >= SMOOTH_RUN) {
                    tclod_greedy_skip(sel);
                    R->skipped = 1;
                }
                continue;
            }
        }
        at = level(sel, limit - sel->cost_sum - held, R->mixed.guess);
        if (isfinite(at) && at > 0.0)
            R->mixed.guess = at;
        moved = smooth_step(sel, at, &budget_bound);
        if (moved < 0)
            return -1;
        if (budget_bound)
            R->skipped = 1;
        if (!moved || ++R->mixed.run >= SMOOTH_RUN)
            return 0;
    }
}

/* What is left after the smooth variables: the increments that still fit
 * (tclod_mixed_fill). */
int tclod_mixed_fill(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    for (;;) {
        double slope_d;
        tclod_id cand = tclod_greedy_candidate(sel, &slope_d, &R->skipped);
        if (cand == TCLOD_NONE || tclod_out_of_time(sel))
            break;
        if (tclod_greedy_take(sel, cand) != 0)
            return -1;
    }
    if (!sel->paused && !sel->stopped)
        sel->stats.stop_reason = R->skipped ? TCLOD_STOP_BUDGET : TCLOD_STOP_FINEST;
    return 0;
}

/* Exchanges between the variable whose slope ratio db/dc is highest among
 * those that can go up and the one whose ratio is lowest among those that can
 * come down, while the two differ by more than POLISH_GAP: a line search over
 * the pair at first-order constant cost for the most benefit within the
 * budget. At the optimum of a separable problem all ratios are equal; this
 * evens out the few variables the models left behind, at the cost of two
 * variables' callbacks per step. */
int tclod_mixed_polish(tclod_selector *sel) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t *k = &sel->resume.k;
    for (; *k < POLISH_STEPS; ++*k) {
        uint32_t v, hi = TCLOD_NONE, lo = TCLOD_NONE;
        double scale;
        int moved, budget_bound, at_slope, stalled;
        if (tclod_out_of_time(sel))
            return 0;
        ratios(sel);
        for (v = 0; v < V->count; ++v) {
            if (V->state[v] != TCLOD_VAR_LIVE)
                continue;
            if (V->r[v] < 1.0 && V->ratio[v] > 0.0 && !isinf(V->ratio[v]) &&
                (hi == TCLOD_NONE || V->ratio[v] > V->ratio[hi]))
                hi = v;
            if (V->r[v] > 0.0 && isfinite(V->dc[v]) && V->dc[v] > 0.0 &&
                (lo == TCLOD_NONE || V->ratio[v] < V->ratio[lo]))
                lo = v;
        }
        if (hi == TCLOD_NONE || lo == TCLOD_NONE || hi == lo ||
            !(V->ratio[hi] > V->ratio[lo] * (1.0 + POLISH_GAP)))
            return 0;
        scale = 1.0 / V->dc[hi] > 1.0 / V->dc[lo] ? V->dc[hi] : V->dc[lo];
        V->a[hi] = scale / V->dc[hi];
        V->a[lo] = -scale / V->dc[lo];
        V->moving[0] = hi;
        V->moving[1] = lo;
        sel->stats.iterations++;
        sel->stats.line_searches++;
        moved = line_search(sel, 2, 0.0, &budget_bound, &at_slope, &stalled);
        V->a[hi] = V->a[lo] = 0.0;
        if (moved < 0)
            return -1;
        if (!moved || stalled)
            return 0;
    }
    return 0;
}
