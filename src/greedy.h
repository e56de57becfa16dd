/*
 * greedy.c: TCLOD_SOLVER_GREEDY's types and the steps the mixed solver
 * takes from it.
 */
#ifndef TCLOD_GREEDY_H
#define TCLOD_GREEDY_H

#include "internal.h"

/* The most decisions on one path of the greedy's search (restarts). */
#define TCLOD_SEARCH_DEPTH 32u

/* The greedy's increment of a node: its children (with lookahead, the cut its
 * key found) replace it, for delta_b more benefit and delta_c more cost. Apart
 * from the node records, which every solver reads. */
typedef struct tclod_delta {
    double delta_b, delta_c;
} tclod_delta;

/* Runs TCLOD_SOLVER_GREEDY for sel->frame into the working cut, from where
 * sel->resume says it stands. Returns TCLOD_OK or TCLOD_ERR_CALLBACK (strict);
 * the caller commits or rolls back. With TCLOD_OK and sel->paused set, the
 * step's slice ran out: the solve is not finished, and the working state is
 * feasible. */
tclod_status tclod_greedy_solve(tclod_selector *sel);

/* The greedy's steps, for the mixed solver. Each returns 0, or -1 when strict
 * mode saw a bad callback value. The budget left to the cut is the frame's
 * budget minus sel->reserved. */
int tclod_greedy_start(tclod_selector *sel); /* cut = the roots, increments queued */
/* The best queued increment that fits (ratio in *ratio), discarding those that
 * do not fit and never will; TCLOD_NONE when none fits. *skipped is set to 1
 * when an increment was discarded or none fits while some are queued. */
tclod_id tclod_greedy_candidate(tclod_selector *sel, double *ratio, int *skipped);
int tclod_greedy_take(tclod_selector *sel, tclod_id n); /* applies a candidate */
void tclod_greedy_skip(tclod_selector *sel);            /* drops the best candidate */
/* The greedy's safeguard for the mixed solver: after tclod_greedy_start,
 * tclod_greedy_track records every increment that candidate and skip drop
 * (and, in tclod_greedy_alternative, those still queued) with the increments
 * above it, as a cold greedy solve does. tclod_greedy_alternative returns the
 * one whose selection alone (the roots, it and those above it) fits the
 * budget and is worth most, with that worth in *benefit; TCLOD_NONE when none
 * fits, or when roots were dropped or restarts is 0. tclod_greedy_force
 * starts from the roots again with n's increment and those above it taken. */
void tclod_greedy_track(tclod_selector *sel);
tclod_id tclod_greedy_alternative(tclod_selector *sel, double *benefit);
int tclod_greedy_force(tclod_selector *sel, tclod_id n);
/* Repairs the exact sum of the cut's costs to be within the budget. */
int tclod_greedy_enforce(tclod_selector *sel);
void tclod_greedy_end(tclod_selector *sel); /* empties the heaps after a solve */

#endif /* TCLOD_GREEDY_H */
