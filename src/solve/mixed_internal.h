/*
 * What the mixed solver's two files share (mixed.c, its steps; mixed_solve.c,
 * the solve that runs them): the phases a solve runs, each resumable.
 */
#ifndef TCLOD_MIXED_INTERNAL_H
#define TCLOD_MIXED_INTERNAL_H

#include "../eval/evaluate.h"

/* The variables' values, slopes, states or models changed: what was computed
 * from them (ratios, the bound on the models' spend) has to be made again. */
static inline void vars_changed(tclod_vars *V) {
    V->fresh = 0;
    V->bounded = 0;
}

/* What is left after the smooth variables: the increments that still fit
 * (fill). */
int tclod_mixed_fill(tclod_selector *sel);

/* The papers' loop (eq. 8.8-8.14) with the gradient direction. */
int tclod_mixed_improve_gradient(tclod_selector *sel);

/* The preconditioned loop: increments best first while their slope beats the
 * slope the smooth variables would have after sharing the budget left with
 * them (a smooth step first makes room when they hold it now), then smooth
 * steps towards the slope at which they spend what is left, until they stop
 * gaining; then the increments that still fit. */
int tclod_mixed_improve_modelled(tclod_selector *sel);

/* Exchanges between the variable whose slope ratio db/dc is highest among
 * those that can go up and the one whose ratio is lowest among those that can
 * come down, while the two differ by more than POLISH_GAP: a line search over
 * the pair at first-order constant cost for the most benefit within the
 * budget. At the optimum of a separable problem all ratios are equal; this
 * evens out the few variables the models left behind, at the cost of two
 * variables' callbacks per step. */
int tclod_mixed_polish(tclod_selector *sel);

/* What the models' tolerances left of the budget goes to the smooth variables
 * along the plain gradient, up to t_max (the papers' step without a discrete
 * step to compare with). */
int tclod_mixed_spend_the_rest(tclod_selector *sel);

/* Every variable starts at 0 (not drawn, no benefit, no cost) with the slopes
 * just above it, and its model from one probe at full resolution: a model
 * anchored just above 0 would extrapolate over orders of magnitude, and a
 * kinked cost's slope there is not the one further on. A bad benefit makes the
 * variable invisible for this solve. */
int tclod_mixed_start_variables(tclod_selector *sel);

#endif /* TCLOD_MIXED_INTERNAL_H */
