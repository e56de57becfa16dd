/*
 * optimum — exact reference answers for the benchmarks (not part of the library).
 *
 * The problem every solver of libtclod approximates (docs/greedy.md, "Problem"): choose a
 * cut of one or more LOD hierarchies — for every root either the root or, recursively, a
 * cut of each of its children — with the largest summed benefit whose summed cost fits a
 * budget. A node with benefit 0 is invisible: it stays in the cut as itself, costs
 * nothing and is not refined (tests/support/exact.h, which enumerates every cut of tiny
 * scenes, uses the same rules).
 *
 * With holes = 1 the programs solve the looser problem in which any part of a hierarchy
 * may be left undrawn: the best set of visible nodes none of which is an ancestor of
 * another. Selections that leave visible objects out (Robin Hood's default misfit
 * policy drops instances whose share does not cover their simplest level) belong to it,
 * so its optimum bounds them too.
 *
 *  - optimum_chains: hierarchies that are chains (objects with discrete levels) form a
 *    multiple-choice knapsack; dynamic programming over integer costs (Dudzinski and
 *    Walukiewicz 1987), O(objects x levels x budget).
 *  - optimum_tree: any hierarchies; dynamic programming over the tree (a max-plus
 *    convolution of the children's tables per inner node), exact for integer costs.
 *  - optimum_bound: an upper bound for large scenes with real costs, the Lagrangian
 *    relaxation of the budget (equal to the linear-programming bound).
 *
 * The two dynamic programs are exact when every cost is an integer multiple of a
 * quantum (the random families of examples/scenes/family_scene.h have integer costs);
 * they refuse instances where one is not. Both answer every budget up to a maximum at
 * once: the table of the best benefit per budget.
 */
#ifndef OPTIMUM_H
#define OPTIMUM_H

#include <stddef.h>
#include <stdint.h>

#include <tclod/tclod.h>

#ifdef __cplusplus
extern "C" {
#endif

/* An instance: node i has parent parent[i] (TCLOD_NONE for a root), benefit[i] >= 0 and
 * cost[i] >= 0, all finite. Nodes may come in any order, but the parents must form a
 * forest. The arrays are only read. */
typedef struct optimum_instance {
    uint32_t count;
    const tclod_id *parent;
    const double *benefit;
    const double *cost;
} optimum_instance;

typedef enum optimum_status {
    OPTIMUM_OK = 0,
    OPTIMUM_NOT_CHAINS = 1,   /* optimum_chains: a node has more than one child */
    OPTIMUM_NOT_INTEGRAL = 2, /* a visible node's cost is not a whole number of quanta,
                                 or exceeds 2^31 quanta */
    OPTIMUM_BAD_VALUE = 3,    /* NaN, infinite or negative value; a parent out of range or
                                 a cycle; quantum not > 0 and finite; budget not >= 0 and
                                 finite; more than 2^24 budget quanta */
    OPTIMUM_NOMEM = 4
} optimum_status;

/* The best benefit for every budget from 0 to units quanta. */
typedef struct optimum_curve {
    double quantum; /* cost unit */
    uint32_t units; /* largest budget, in quanta */
    double *best;   /* units + 1 entries: best[x] = the largest benefit of a cut whose cost
                       is <= x quanta, or -1 when no cut fits (the roots alone cost more) */
} optimum_curve;

/* Exact optimum of a scene of chains for every budget up to max_budget (rounded down to
 * whole quanta); holes as above (for chains: an object may be left out). Fills *out on
 * success; free it with optimum_curve_free. */
optimum_status optimum_chains(const optimum_instance *in, double quantum, double max_budget,
                              int holes, optimum_curve *out);

/* Exact optimum of any forest, as optimum_chains. */
optimum_status optimum_tree(const optimum_instance *in, double quantum, double max_budget,
                            int holes, optimum_curve *out);

/* The optimum at a budget: best[floor(budget / quantum)] (costs are whole quanta, so a
 * cut fits budget exactly when it fits that many quanta). -1 when no cut fits; NaN for a
 * budget above units quanta or below 0. */
double optimum_at(const optimum_curve *c, double budget);

/* Frees the table and zeroes *c. NULL is allowed. */
void optimum_curve_free(optimum_curve *c);

/* An upper bound on the benefit of every selection whose cost fits budget, including
 * selections that leave whole hierarchies out (as the solvers do when even the roots do
 * not fit), and with holes = 1 also those that leave any part out: min over lambda >= 0
 * of
 *     lambda * budget + sum over roots of max(0, f(root)),
 *     f(n) = max(benefit(n) - lambda cost(n), sum over children m of f(m))
 *            for a visible node with children; benefit(n) - lambda cost(n) for a
 *            visible leaf; 0 for an invisible node; with holes, at least 0.
 * Any lambda gives a bound (for a selection S, sum b = sum (b - lambda c) + lambda sum c);
 * the minimum is the linear-programming bound, within one increment of the optimum when
 * the increments show diminishing returns. Found by bisection on the subgradient
 * (budget minus the cost of the maximising cut). Real costs allowed. Returns NaN on bad
 * input or when memory runs out. */
double optimum_bound(const optimum_instance *in, double budget, int holes);

#ifdef __cplusplus
}
#endif

#endif /* OPTIMUM_H */
