/*
 * family_scene — random instance families for measuring selection quality against the
 * exact optimum (bench/tclod_quality.c, tests/test_exact.c).
 *
 * An instance is a table_model scene (table_scene.h) with integer costs, so that an exact
 * dynamic program over costs (bench/optimum.h) finds its optimum. Two shapes:
 *   chains  objects with L discrete levels (a multiple-choice knapsack: one level per
 *           object);
 *   trees   random hierarchies in which a node's children together refine it (a
 *           tree-cut knapsack).
 * Every refinement step (an increment: a node replaced by its children, or level k by
 * k + 1) adds a cost w >= 1 and a benefit p > 0 drawn as in the knapsack literature's
 * classic families (Pisinger, "Where are the hard knapsack problems?", 2005), with R the
 * range:
 *   uncorrelated         w, p uniform in [1, R], independent;
 *   weakly correlated    w uniform in [1, R], p uniform in [w - R/10, w + R/10], p >= 1;
 *   strongly correlated  w uniform in [1, R], p = w + R/10;
 *   not diminishing      as uncorrelated, but nothing orders the steps.
 * In the first three families the steps show diminishing returns, as docs/api.md asks of
 * a host: along a chain the steps are sorted by falling p/w, and in a tree a node's step
 * never gains more per unit of cost than its parent's (drawn again until it does). The
 * fourth family keeps the steps in the order drawn, so a step often gains more per unit
 * of cost than the one before it, which is what the greedy's bound does not cover.
 *
 * C99, prefix family_. Not part of the installed library.
 */
#ifndef FAMILY_SCENE_H
#define FAMILY_SCENE_H

#include <stdint.h>

#include <tclod/tclod.h>

#include "table_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum family_shape {
    FAMILY_CHAINS = 0, /* objects with discrete levels */
    FAMILY_TREES = 1   /* random hierarchies */
} family_shape;

typedef enum family_kind {
    FAMILY_UNCORRELATED = 0,
    FAMILY_WEAKLY_CORRELATED = 1,
    FAMILY_STRONGLY_CORRELATED = 2,
    FAMILY_NOT_DIMINISHING = 3
} family_kind;

#define FAMILY_KIND_COUNT 4

/* Sizes of the instances of a family; each instance draws its own within the ranges. */
typedef struct family_desc {
    family_shape shape;
    family_kind kind;
    uint32_t range;        /* R: step costs and benefits in [1, R]; >= 10. Default 100 */
    uint32_t objects_min;  /* chains: objects; trees: roots (hierarchies). >= 1 */
    uint32_t objects_max;  /* >= objects_min. Defaults: chains 10-100, trees 2-8 */
    uint32_t levels_min;   /* chains: levels per object; trees: levels of depth (a root
                              alone is 1). >= 1 */
    uint32_t levels_max;   /* >= levels_min, <= 16. Defaults: chains 3-6, trees 2-4 */
    uint32_t children_min; /* trees: children of an inner node, >= 1. Default 2 */
    uint32_t children_max; /* trees: >= children_min, <= 16. Default 4 */
    uint32_t leaf_chance;  /* trees: percent chance that a node below a root, above the
                              deepest level, is a leaf anyway, in [0, 100]. Default 25 */
    uint32_t max_nodes;    /* trees: nodes per instance at most (nodes past it become
                              leaves), >= objects_max. Default 200 */
} family_desc;

/* Fills d with the defaults above for a shape and a kind. */
void family_desc_default(family_desc *d, family_shape shape, family_kind kind);

/* Adds one random instance to s and m (which must mirror each other, as table_add_node
 * requires; normally both empty). Costs are integers in [1, 2^24); benefits are > 0
 * (integers for chains). Returns TCLOD_ERR_ARG for a desc out of range, else the first
 * failing status of table_add_node. The same seed of r gives the same instance. */
tclod_status family_build(const family_desc *d, table_model *m, tclod_scene *s, table_rng *r);

/* "uncorrelated", "weak", "strong", "not_diminishing"; "unknown" otherwise. */
const char *family_kind_name(family_kind k);

/* "chains", "trees"; "unknown" otherwise. */
const char *family_shape_name(family_shape s);

#ifdef __cplusplus
}
#endif

#endif /* FAMILY_SCENE_H */
