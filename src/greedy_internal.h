/*
 * What the greedy's three files share: greedy.c (the papers' increments,
 * decrements and warm start), greedy_lookahead.c (increments that reach below
 * a node's children) and greedy_search.c (the passes after the plain one: the
 * best skipped increment's T(n) and the restarts' search). Included by those
 * three only.
 */
#ifndef TCLOD_GREEDY_INTERNAL_H
#define TCLOD_GREEDY_INTERNAL_H

#include "selector.h"

/* Relative gain a swap must make, so rounding can never make swaps cycle. */
#define GREEDY_SWAP_MARGIN 1e-12

/* The stages of a greedy solve (sel->resume.phase). */
enum {
    GREEDY_START = 0,
    GREEDY_IMPROVE,
    GREEDY_PASS, /* a pass after the plain one, with resume.greedy.pick/take */
    GREEDY_IMPROVE_PASS,
    GREEDY_REPLAY, /* the best pass again, when another one ended last */
    GREEDY_IMPROVE_REPLAY,
    GREEDY_END
};

/* ---- the cut and its running sums ------------------------------------------ */

static inline int greedy_counts(const tclod_selector *sel, tclod_id n) {
    return sel->node[n].benefit > 0.0 && !(sel->flags[n] & TCLOD_FLAG_DROPPED);
}

/* Costs are >= 0 or +inf (unaffordable): never NaN, never -inf. */
static inline int greedy_unaffordable(double cost) {
    return cost == HUGE_VAL;
}

/* The budget left to the cut: the frame's, minus what smooth variables hold. */
static inline double greedy_cut_budget(const tclod_selector *sel) {
    return sel->frame->budget - sel->reserved;
}

static inline int greedy_feasible(const tclod_selector *sel) {
    return sel->unaffordable == 0 && sel->cost_sum <= greedy_cut_budget(sel);
}

/* The key of increment (db, dc): NaN when it gains nothing. */
static inline double greedy_ratio_key(double db, double dc) {
    if (!(db > 0.0))
        return (double)NAN;
    return dc > 0.0 ? db / dc : HUGE_VAL;
}

/* 1 when increment n fits the remaining budget, by the running sum and by its
 * compensated total (an increment that fits only because the running sum
 * absorbed costs is not taken: the final summation would give it back). */
static inline int greedy_increment_fits(const tclod_selector *sel, tclod_id n) {
    return sel->unaffordable == 0 &&
           tclod_within(sel, sel->cost_sum + sel->greedy.delta[n].delta_c, greedy_cut_budget(sel));
}

/* ---- what the plain pass records for the search ----------------------------- */

/* A cold solve records the best single skipped increment with the increments
 * above it (sel->resume.greedy.alt_*): one that a pass forcing it reproduces, so not
 * a refit (tclod_greedy_apply_jump keeps those below one out). */
static inline void greedy_consider_alternative(tclod_selector *sel, tclod_id n) {
    tclod_resume *R = &sel->resume;
    const double *path = &sel->path[2u * n];
    double c = R->greedy.alt_roots_c + path[1] + sel->greedy.delta[n].delta_c;
    double b = R->greedy.alt_roots_b + path[0] + sel->greedy.delta[n].delta_b;
    /* fits as greedy_increment_fits has it, with the roots' compensation */
    if (c <= sel->frame->budget && !(c + R->greedy.alt_roots_err > sel->frame->budget) &&
        b > R->greedy.alt_benefit && !(sel->flags[n] & TCLOD_FLAG_REFIT)) {
        R->greedy.alt_node = n;
        R->greedy.alt_benefit = b;
    }
}

/* A cold pass records its first misfit n and the bound of the linear
 * relaxation there: the benefit so far plus n's gain (docs/greedy.md). */
static inline void greedy_note_misfit(tclod_selector *sel, tclod_id n) {
    tclod_resume *R = &sel->resume;
    if (R->greedy.misfit != TCLOD_NONE)
        return;
    R->greedy.misfit = n;
    R->greedy.misfit_key = sel->greedy.inc.items[0].key;
    R->greedy.lp_bound = sel->benefit_sum + sel->greedy.delta[n].delta_b;
}

/* 1 when the current pass leaves node n's increment out. */
static inline int greedy_left_out(const tclod_resume *R, tclod_id n) {
    uint32_t i;
    for (i = 0; i < R->greedy.picks; ++i)
        if (R->greedy.pick[i] == n && !R->greedy.take[i])
            return 1;
    return 0;
}

/* ---- greedy.c, for the other two ---------------------------------------------- */

/* Evaluates the children of visible cut node n and computes its plain
 * increment into sel->greedy.delta[n]; returns its key (NaN: no candidate),
 * with 1 in *failed on a strict error. */
double tclod_greedy_increment_key(tclod_selector *sel, tclod_id n, int *failed);
/* Adds n to the working cut and its running sums. */
void tclod_greedy_cut_add(tclod_selector *sel, tclod_id n);
/* Queues n's increment, if it is a candidate, in the place of *held's
 * queued one (then *held = TCLOD_NONE); otherwise pushes it. Returns 0, or
 * -1 on a strict error. */
int tclod_greedy_requeue(tclod_selector *sel, tclod_id n, tclod_id *held);
/* Queues the decrement into p when p is collapsible. Returns 0 or -1. */
int tclod_greedy_queue_decrement(tclod_selector *sel, tclod_id p);
/* Queues lookahead increment n of key `key` (NaN: none), pushed or appended;
 * and the same in the place of *held's queued increment. */
void tclod_greedy_enqueue_looking(tclod_selector *sel, tclod_id n, double key, int append);
void tclod_greedy_rekey_looking(tclod_selector *sel, tclod_id n, tclod_id *held, double key);

/* ---- greedy_lookahead.c ------------------------------------------------------- */

/* queue_increment and requeue_increment for a selector with a lookahead. */
int tclod_greedy_queue_looking(tclod_selector *sel, tclod_id n, int append);
int tclod_greedy_requeue_looking(tclod_selector *sel, tclod_id n, tclod_id *held);
/* The cheapest increment of cut node n with a jump queued. */
double tclod_greedy_cheapest_jump(tclod_selector *sel, tclod_id n);
/* Lookahead increment n that does not fit: the cut of its subtree that fits
 * and gains most becomes its increment (TCLOD_FLAG_REFIT). Returns its key,
 * NaN when none gains. */
double tclod_greedy_refit_jump(tclod_selector *sel, tclod_id n);
/* Applies lookahead increment n (TCLOD_FLAG_JUMP or REFIT). Returns 0 or -1. */
int tclod_greedy_apply_jump(tclod_selector *sel, tclod_id n, int track_dec, tclod_id *held,
                            double path_b, double path_c);

/* ---- greedy_search.c ---------------------------------------------------------- */

/* Starts a pass from the roots with the current decisions (GREEDY_PASS,
 * GREEDY_REPLAY). Returns 0 or -1. */
int tclod_greedy_start_decided(tclod_selector *sel);
/* The stage after a pass of a cold solve (GREEDY_*). */
int tclod_greedy_after_pass(tclod_selector *sel);

#endif /* TCLOD_GREEDY_INTERNAL_H */
