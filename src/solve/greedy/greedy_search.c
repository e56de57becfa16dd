/*
 * TCLOD_SOLVER_GREEDY's passes after the plain cold one: the pass from the
 * best skipped increment's T(n) (the increment with those above it), which
 * keeps a cold solve within half of the optimum when benefits show
 * diminishing returns, and with restarts > 1 a depth-first search over
 * forced and left-out increments, bounded by the linear relaxation at each
 * pass's first misfit (docs/greedy.md). greedy.c runs the passes.
 *
 * Layer: solve, which may call core, eval and solve. Calls: solve (greedy.c,
 * greedy_lookahead.c).
 */
#include "greedy_internal.h"

#include <float.h>
#include <string.h>

/* The relative shortfall from the relaxation's bound below which a solve
 * searches no further. */
#define RESTART_GAP 1e-2

/* Takes node n's increment and those above it that are not taken yet. Returns
 * 1 when one of them is left out by the current pass (nothing is taken
 * then), 0 when done, -1 on a strict error. */
static int force_path(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    uint32_t depth = 0;
    int below = 1; /* a is not refined yet: the cut is at a or above it */
    tclod_id a;
    for (a = n; a != TCLOD_NONE; a = s->parent[a]) {
        if (below && sel->resume.greedy.left_out > 0 && greedy_left_out(&sel->resume, a))
            return 1;
        below &= sel->node[a].cut_pos == TCLOD_NONE;
        sel->scratch[depth++] = a;
    }
    while (depth-- > 0) {
        a = sel->scratch[depth];
        /* taken already, or passed over by a lookahead increment above */
        if (sel->node[a].cut_pos == TCLOD_NONE)
            continue;
        /* n's own lookahead increment, when it does not fit: the cut that does */
        if (depth == 0 && (sel->flags[a] & TCLOD_FLAG_JUMP) && !greedy_increment_fits(sel, a)) {
            double key = tclod_greedy_refit_jump(sel, a);
            if (key != key)
                return 1;
        }
        if (tclod_greedy_take(sel, a) != 0)
            return -1;
    }
    return 0;
}

/* Starts a pass from the roots with the current decisions: the increments
 * taken forced (with those above them), the others left out by improve.
 * Sets resume.greedy.infeasible when the forced ones do not fit. */
int tclod_greedy_start_decided(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    uint32_t i;
    if (tclod_greedy_start(sel) != 0)
        return -1;
    R->greedy.left_out = 0;
    for (i = 0; i < R->greedy.picks; ++i)
        R->greedy.left_out += !R->greedy.take[i];
    R->greedy.infeasible = 0;
    R->greedy.misfit = TCLOD_NONE;
    R->greedy.lp_bound = 0.0;
    R->skipped = 0;
    sel->stats.stop_reason = TCLOD_STOP_FINEST;
    for (i = 0; i < R->greedy.picks && !R->greedy.infeasible; ++i) {
        int rc;
        if (!R->greedy.take[i])
            continue;
        rc = force_path(sel, R->greedy.pick[i]);
        if (rc < 0)
            return -1;
        R->greedy.infeasible = rc > 0;
    }
    if (!greedy_feasible(sel) || !tclod_within(sel, sel->cost_sum, greedy_cut_budget(sel)))
        R->greedy.infeasible = 1;
    return 0;
}

/* Whether the search may go on below a pass whose bound is `bound`: passes
 * left, no limit in the frame, and a bound more than RESTART_GAP above the
 * best result. */
static int worth_searching(const tclod_selector *sel, double bound) {
    const tclod_resume *R = &sel->resume;
    const tclod_frame *f = sel->frame;
    return sel->desc.greedy.restarts > 1 && R->greedy.tries < (uint32_t)sel->desc.greedy.restarts &&
           f->max_iterations == 0 && f->solve_seconds == 0.0 &&
           bound > R->greedy.best_benefit * (1.0 + RESTART_GAP);
}

/* The search's next decisions after a pass (depth first): below a pass whose
 * bound leaves room, its first misfit taken; otherwise the last decision
 * taken is left out instead, the decisions after it dropped. Returns 0 when
 * the search is over. */
static int next_decisions(tclod_selector *sel, int below) {
    tclod_resume *R = &sel->resume;
    if (below && R->greedy.picks < TCLOD_SEARCH_DEPTH) {
        R->greedy.pick[R->greedy.picks] = R->greedy.misfit;
        R->greedy.take[R->greedy.picks++] = 1;
        return 1;
    }
    while (R->greedy.picks > 0 && !R->greedy.take[R->greedy.picks - 1u])
        R->greedy.picks--;
    if (R->greedy.picks == 0)
        return 0;
    R->greedy.take[R->greedy.picks - 1u] = 0;
    return 1;
}

/* The stage after a pass of a cold solve. The plain pass is followed by the
 * one from the best skipped increment's T(n) when that alone beats it (the
 * half-optimum safeguard), and, with restarts > 1, by the search: passes with
 * increments forced or left out, branching on each pass's first misfit while
 * the relaxation's bound there says the optimum may be more than RESTART_GAP
 * better, as many as restarts allows. Then the best pass is made again if it
 * is not the last one. A pass stopped by a limit ends the solve. */
int tclod_greedy_after_pass(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int plain = R->greedy.tries == 0 && !R->greedy.searching && R->greedy.picks == 0;
    if (sel->stopped || (sel->stats.stop_reason != TCLOD_STOP_BUDGET &&
                         sel->stats.stop_reason != TCLOD_STOP_FINEST))
        return GREEDY_END;
    R->greedy.cut_is_best = 0;
    if (plain || (!R->greedy.infeasible &&
                  sel->benefit_sum > R->greedy.best_benefit * (1.0 + GREEDY_SWAP_MARGIN))) {
        R->greedy.best_benefit = sel->benefit_sum;
        R->greedy.best_picks = R->greedy.picks;
        memcpy(R->greedy.best_pick, R->greedy.pick, sizeof(tclod_id) * R->greedy.picks);
        memcpy(R->greedy.best_take, R->greedy.take, R->greedy.picks);
        R->greedy.cut_is_best = 1;
    }
    if (plain) {
        R->greedy.root_misfit = R->greedy.misfit;
        R->greedy.root_bound = R->greedy.lp_bound;
        sel->greedy.closure_hint = R->greedy.misfit != TCLOD_NONE ? R->greedy.misfit_key : DBL_MIN;
        if (R->greedy.use_alt && R->greedy.alt_node != TCLOD_NONE &&
            R->greedy.alt_benefit > R->greedy.best_benefit * (1.0 + GREEDY_SWAP_MARGIN)) {
            R->greedy.pick[0] = R->greedy.alt_node; /* the T(n) pass */
            R->greedy.take[0] = 1;
            R->greedy.picks = 1;
            return GREEDY_PASS;
        }
    }
    if (R->greedy.use_alt && !R->greedy.searching) { /* the search begins below the plain pass */
        R->greedy.searching = 1;
        R->greedy.picks = 0;
        R->greedy.misfit = R->greedy.root_misfit;
        if (R->greedy.root_misfit != TCLOD_NONE && worth_searching(sel, R->greedy.root_bound) &&
            next_decisions(sel, 1))
            return GREEDY_PASS;
    } else if (R->greedy.searching && R->greedy.tries < (uint32_t)sel->desc.greedy.restarts &&
               next_decisions(sel, !R->greedy.infeasible && R->greedy.misfit != TCLOD_NONE &&
                                       worth_searching(sel, R->greedy.lp_bound))) {
        return GREEDY_PASS;
    }
    return R->greedy.cut_is_best ? GREEDY_END : GREEDY_REPLAY;
}

/* ---- the safeguard's steps, for the mixed solver ----------------------------- */

void tclod_greedy_track(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    R->greedy.alt_node = TCLOD_NONE;
    R->greedy.alt_benefit = 0.0;
    R->greedy.alt_roots_b = sel->benefit_sum;
    R->greedy.alt_roots_c = sel->cost_sum;
    R->greedy.alt_roots_err = sel->cost_err;
    R->greedy.use_alt =
        sel->stats.dropped_roots == 0 && !sel->stats.over_budget && sel->desc.greedy.restarts > 0;
}

tclod_id tclod_greedy_alternative(tclod_selector *sel, double *benefit) {
    tclod_resume *R = &sel->resume;
    uint32_t i;
    if (!R->greedy.use_alt)
        return TCLOD_NONE;
    for (i = 0; i < sel->greedy.inc.count; ++i)
        greedy_consider_alternative(sel, sel->greedy.inc.items[i].id);
    *benefit = R->greedy.alt_benefit;
    return R->greedy.alt_node;
}

tclod_id tclod_greedy_found_alternative(const tclod_selector *sel, double *benefit) {
    *benefit = sel->resume.greedy.alt_benefit;
    return sel->resume.greedy.alt_node;
}

int tclod_greedy_force(tclod_selector *sel, tclod_id n) {
    sel->resume.greedy.picks = sel->resume.greedy.left_out = 0;
    if (tclod_greedy_start(sel) != 0)
        return -1;
    /* 1: n's lookahead jump no longer fits and no cut of it does; the path
     * above it is taken, a cut within the budget like T(n) without n */
    return force_path(sel, n) < 0 ? -1 : 0;
}
