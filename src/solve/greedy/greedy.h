/*
 * greedy.c: TCLOD_SOLVER_GREEDY's types and the steps the mixed solver
 * takes from it.
 */
#ifndef TCLOD_GREEDY_H
#define TCLOD_GREEDY_H

#include "../../core/heap.h"

/* The most decisions on one path of the greedy's search (restarts). */
#define TCLOD_SEARCH_DEPTH 32u

/* The greedy's increment of a node: its children (with lookahead, the cut its
 * key found) replace it, for delta_b more benefit and delta_c more cost. Apart
 * from the node records, which every solver reads. */
typedef struct tclod_delta {
    double delta_b, delta_c;
} tclod_delta;

/* Whether warm starts pay (docs/greedy.md, falling back): the work of the
 * last cold solve and the running mean of warm ones' (evaluations plus
 * iterations: counts, so that the choice is deterministic), the cold solves
 * left before a warm start is tried again, and how many that was. */
typedef struct tclod_fallback {
    double cold_work, warm_work;
    uint32_t left, span;
    uint32_t since_audit; /* warm solves since the last audit */
} tclod_fallback;

/* Every this many warm solves, the solve is audited: a cold solve follows the
 * warm one and the better of the two is kept (greedy.c, docs/greedy.md). */
#define TCLOD_AUDIT_PERIOD 32u

/* The most cold solves in a row before a warm start is tried again, and by
 * how much warm solves' mean work must exceed a cold one's to send them. */
#define TCLOD_FALLBACK_SPAN_MAX 64u
#define TCLOD_FALLBACK_MARGIN 1.25

/* What the greedy keeps between solves (tclod_selector.greedy). The arrays
 * are per-node buffers of the selector (tclod_greedy_buffers). */
typedef struct tclod_greedy_state {
    tclod_delta *delta;                         /* the nodes' increments */
    tclod_heap inc;                             /* increments, best Δb/Δc first */
    tclod_heap cheap;                           /* the same increments, smallest Δc first */
    int cheap_live;                             /* cheap holds every queued increment */
    tclod_heap dec;                             /* decrements, least loss per saved cost first */
    uint32_t *inc_slot, *cheap_slot, *dec_slot; /* the heaps' slots, in dense arrays:
                                                   moving heap entries touches few lines */
    tclod_heap_entry *inc_block, *cheap_block, *dec_block; /* the heaps' entries start
                                  inside these, where a slot's four children share
                                  one cache line (cap >= nodes + 3) */
    tclod_fallback fallback;
    tclod_id *audit_cut; /* an audited solve's warm cut (tclod_greedy_resume.audit) */
    double closure_hint; /* the key of the last plain cold pass's first misfit:
                            DBL_MIN when it had none, 0 before the first */
} tclod_greedy_state;

/* Lists the greedy's per-node buffers into out (room for TCLOD_MAX_ARRAYS);
 * returns how many. */
size_t tclod_greedy_buffers(tclod_greedy_state *g, tclod_array *out);

/* Points the heaps at their entries and slots, after the buffers moved. */
void tclod_greedy_bind(tclod_greedy_state *g);

/* Where a greedy solve stands (tclod_resume.greedy). */
typedef struct tclod_greedy_resume {
    int warm;      /* the solve started from the previous cut */
    int fell_back; /* a warm start was due, and it started from the roots */
    /* cold start: the skipped increment whose T(n) (the increment with the
     * increments above it) fits and gives the most benefit */
    tclod_id alt_node;
    double alt_benefit, alt_roots_b, alt_roots_c;
    double alt_roots_err; /* alt_roots_c's compensation (tclod_selector.cost_err) */
    int use_alt;
    /* cold start: the passes after the plain one (restarts). A pass forces
     * the increments of its decisions marked taken (with those above them)
     * and leaves out the others; the search below explores decisions depth
     * first. The current pass's decisions and the best pass's */
    tclod_id pick[TCLOD_SEARCH_DEPTH], best_pick[TCLOD_SEARCH_DEPTH];
    uint8_t take[TCLOD_SEARCH_DEPTH], best_take[TCLOD_SEARCH_DEPTH];
    uint32_t picks, best_picks, left_out; /* left_out: decisions not taken */
    uint32_t tries;                       /* passes made after the plain one */
    int searching;                        /* the passes are the search's (not the T(n) one) */
    int cut_is_best;                      /* the working cut is the best pass's */
    int infeasible;                       /* the current pass's decisions do not fit */
    double best_benefit;
    tclod_id misfit;      /* the current pass's first increment that did not fit */
    double lp_bound;      /* its benefit there plus the misfit's gain (0: none) */
    tclod_id root_misfit; /* the plain pass's, where the search begins */
    double root_bound;
    double misfit_key; /* the key of the current pass's first misfit */
    /* the plain cold pass: increments keyed at or above closure_key wait in a
     * queue (sel->scratch[closure_head .. closure_tail)) instead of the heap
     * and are taken first, while closure_cost (the roots' cost plus every
     * positive Δc taken from the queue) fits */
    int closing;
    uint32_t closure_head, closure_tail;
    /* a warm solve: the misfits its fill skipped, parked at the end of
     * sel->scratch (scratch[cap - parked .. cap), their keys in scratch_key)
     * until the fill ends and they are queued again for the swaps */
    uint32_t parked;
    double closure_key, closure_cost, closure_err; /* closure_err: closure_cost's
                                                      compensation, as cost_err */
    /* a warm solve's phase of improve (greedy.c), and the swaps it tried past
     * the balance point (GREEDY_EXCHANGES at most) */
    int phase;
    uint32_t exchanges;
    /* an audited solve: 1 while its warm solve runs, 2 while its cold one does;
     * the warm solve's cut is kept in tclod_greedy_state.audit_cut meanwhile,
     * with its benefit and stop reason */
    int audit;
    uint32_t audit_count;
    double audit_benefit;
    tclod_stop_reason audit_stop;
} tclod_greedy_resume;

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
int tclod_greedy_take(tclod_selector *sel, tclod_id n);                    /* applies a candidate */
double tclod_greedy_increment_cost(const tclod_selector *sel, tclod_id n); /* its Δcost */
void tclod_greedy_skip(tclod_selector *sel); /* drops the best candidate */
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
/* The alternative tclod_greedy_alternative returned last, its worth in
 * *benefit: what a second pass that must end above it compares with. */
tclod_id tclod_greedy_found_alternative(const tclod_selector *sel, double *benefit);
/* Repairs the exact sum of the cut's costs to be within the budget. */
int tclod_greedy_enforce(tclod_selector *sel);
void tclod_greedy_end(tclod_selector *sel); /* empties the heaps after a solve */

#endif /* TCLOD_GREEDY_H */
