/*
 * exact — brute-force reference answers for small table_model scenes.
 *
 * A cut chooses, for every root, either the root itself or, recursively, a
 * cut of each of its children. A node with benefit 0 is invisible: it stays in
 * the cut as itself, costs nothing and its subtree is not refined. An additive
 * node refined stays drawn (its benefit and cost count with its children's);
 * an empty node draws nothing and is always refined. exact_optimum enumerates
 * every selection and returns the largest total benefit whose total cost fits
 * the budget; exact_check_cut checks that a list of ids is a cut,
 * exact_check_selection that it is what a selection with additive and empty
 * nodes draws.
 */
#ifndef EXACT_H
#define EXACT_H

#include <stddef.h>

#include "table_scene.h"

/* Largest benefit of a cut of all of m's hierarchies (no root left out) whose
 * cost is <= budget; -1 when no cut fits (the roots alone are too expensive).
 * *cost_out (may be NULL) receives that cut's cost. For scenes up to
 * EXACT_MAX_NODES nodes with valid (finite, >= 0) values; -2 otherwise or when
 * memory runs out. */
#define EXACT_MAX_NODES 16u
double exact_optimum(const table_model *m, double budget, double *cost_out);

/* The best ratio (b(Q) - b(n)) / (c(Q) - c(n)) over every cut Q of node n's
 * subtree other than n alone, among the cuts that gain (b(Q) > b(n)); +inf
 * for one that gains at no extra cost. -1 when no cut gains (or n has no
 * children); -2 as exact_optimum. */
double exact_best_ratio(const table_model *m, tclod_id n);

/* 1 when ids[0..n) are the visible nodes of a cut of m: every id exists and is
 * listed once, no listed node is an ancestor of another, and every root-to-leaf
 * path that contains no invisible node (benefit 0, or NaN, inf or negative)
 * contains exactly one listed node; with roots_may_drop, whole hierarchies with
 * nothing listed are also accepted. Listed nodes must be visible. 0 otherwise. */
int exact_check_cut(const table_model *m, const tclod_id *ids, size_t n, int roots_may_drop);

/* 1 when ids[0..n) are the nodes a selection draws, with additive and empty
 * nodes (table_model.kind): every id is a live node that is not empty, visible
 * and listed once; in the tree the solvers see (empty nodes passed over), the
 * ancestors of listed nodes (the refined ones) are listed when additive and
 * not when replace nodes, and every visible node below a refined one is
 * listed, refined or culled (every visible root too, unless roots_may_drop). */
int exact_check_selection(const table_model *m, const tclod_id *ids, size_t n, int roots_may_drop);

/* Sorts n ids ascending (result order is deterministic but not sorted). */
void exact_sort_ids(tclod_id *ids, size_t n);

#endif /* EXACT_H */
