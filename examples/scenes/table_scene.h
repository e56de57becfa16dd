/*
 * table_scene — a view-independent scene model for tests and benchmarks.
 *
 * Every node has a fixed benefit and cost held in arrays indexed by node id;
 * the callbacks table_benefit and table_cost return them and count how often
 * each node was asked, so a caller can check that a solve asks each node at
 * most once. The model mirrors the structure of the tclod_scene it was built
 * with (node i of the model is node i of the scene), which lets exact solvers
 * enumerate the same cuts the library chooses from.
 *
 * Also here: a small deterministic random generator (xorshift64*) and builders
 * for random hierarchies and for chains (objects with L discrete levels).
 *
 * C99, prefix table_. Not part of the installed library.
 */
#ifndef TABLE_SCENE_H
#define TABLE_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include <tclod/tclod.h>

#ifdef __cplusplus
extern "C" {
#endif

/* How a smooth object's benefit grows with its resolution r in [0, 1]. */
typedef enum table_shape {
    TABLE_POWER = 0, /* w * r^p, p in (0, 1]; p = 1/2 is the thesis's square root */
    TABLE_LOG = 1    /* w * ln(1 + p r), p > 0 */
} table_shape;

/* Smooth objects, structure-of-arrays by smooth id. Object i has benefit
 * shape[i] with weight w[i] and parameter p[i], and cost steep[i] * r up to
 * r = kink[i], then steep[i] * kink[i] + k[i] * (r - kink[i]): a linear cost
 * k r when steep == k (or kink == 0), and a setup cost in the manner of the
 * thesis's eq. 8.18 when steep > k. A group's values (tclod_query.count > 1)
 * are the sums over its members, all at the same r. */
typedef struct table_smooth {
    uint32_t count, capacity;
    uint8_t *shape;           /* a table_shape */
    double *w, *p;            /* benefit weight and parameter */
    double *k, *steep, *kink; /* cost slopes after and before the kink, kink position */
    uint32_t calls;           /* smooth callback calls since table_smooth_reset */
    uint32_t bad_after;       /* 0, or: the bad_after-th benefit call from now on
                                 returns bad_value (to test sanitising) */
    double bad_value;
} table_smooth;

/* What an id of the model is (table_model.kind). */
typedef enum table_kind {
    TABLE_REPLACE = 0, /* a node whose children replace it */
    TABLE_ADD = 1,     /* a node that stays drawn under its children */
    TABLE_EMPTY = 2,   /* a node with nothing to draw */
    TABLE_NONE = 3     /* no node: removed, or an id the scene keeps for itself */
} table_kind;

/* Per-node values and call counters, structure-of-arrays, indexed by node id. */
typedef struct table_model {
    uint32_t count;          /* ids in the model (== tclod_scene_node_count of its scene) */
    uint32_t capacity;       /* allocated length of the arrays below */
    tclod_id *parent;        /* parent id, TCLOD_NONE for roots */
    uint8_t *kind;           /* a table_kind */
    double *benefit;         /* what table_benefit returns for the node */
    double *cost;            /* what table_cost returns for the node */
    uint32_t *benefit_calls; /* table_benefit calls since table_reset_counts */
    uint32_t *cost_calls;    /* table_cost calls since table_reset_counts */
    uint32_t unknown_ids;    /* queries whose id was not in the model */
    table_smooth smooth;     /* the smooth objects, by smooth id */
} table_model;

/* Empty model; no allocation until the first node. Free with table_free. */
void table_init(table_model *m);

/* Frees the arrays and leaves an empty model. NULL is allowed. */
void table_free(table_model *m);

/* Adds a node to scene s (tclod_scene_add_node with parent and bounds, which
 * may be NULL) and records its benefit and cost. Returns the library's status,
 * TCLOD_ERR_NOMEM when the model's arrays cannot grow, or TCLOD_ERR_STATE when
 * s holds a different number of ids than m (the model must mirror s); on
 * error neither s nor m changes. out_id may be NULL. */
tclod_status table_add_node(table_model *m, tclod_scene *s, tclod_id parent, const float bounds[4],
                            double benefit, double cost, tclod_id *out_id);

/* Adds the node that d describes to scene s (tclod_scene_add_node_desc) and
 * records its benefit and cost and its kind; ids the scene takes besides it
 * (an additive node's) are recorded as TABLE_NONE. Errors as table_add_node.
 * out_id may be NULL. */
tclod_status table_add_node_desc(table_model *m, tclod_scene *s, const tclod_node_desc *d,
                                 double benefit, double cost, tclod_id *out_id);

/* Removes node id with its subtree from scene s (tclod_scene_remove_node)
 * and marks them TABLE_NONE in m. Returns the library's status. */
tclod_status table_remove_node(table_model *m, tclod_scene *s, tclod_id id);

/* Sets every call counter (and unknown_ids, and the smooth calls) to 0. */
void table_reset_counts(table_model *m);

/* Largest per-node number of table_benefit / table_cost calls since the last
 * reset (max over both callbacks). */
uint32_t table_max_calls(const table_model *m);

/* Number of nodes whose benefit was asked since the last reset. */
uint32_t table_asked_nodes(const table_model *m);

/* Callbacks for tclod_callbacks: user must be a table_model. They return the
 * stored value for q->id (NaN and counted in unknown_ids for an id outside
 * the model) and count the call. Views are ignored. */
double table_benefit(void *user, const tclod_query *q);
double table_cost(void *user, const tclod_query *q);

/* Fills cb with table_benefit, table_cost, user = m, smooth callbacks NULL. */
void table_callbacks(table_model *m, tclod_callbacks *cb);

/* Adds a smooth object to scene s (tclod_scene_add_smooth with bounds) and
 * to m's smooth table; parameters as table_smooth describes (kink 0 and steep
 * == k for a linear cost). Errors as table_add_node; TCLOD_ERR_ARG for
 * parameters out of range (w < 0, p <= 0, power p > 1, k < 0, steep < k,
 * kink outside [0, 1)). out_id may be NULL. */
tclod_status table_add_smooth(table_model *m, tclod_scene *s, const float bounds[4],
                              table_shape shape, double w, double p, double k, double steep,
                              double kink, tclod_id *out_id);

/* Benefit and cost of smooth object `id` alone at resolution r in [0, 1], and
 * their derivatives (either pointer may be NULL): what the callbacks add up. */
double table_smooth_benefit_of(const table_model *m, tclod_id id, double r, double *d_dr);
double table_smooth_cost_of(const table_model *m, tclod_id id, double r, double *d_dr);

/* Smooth callbacks for tclod_callbacks: user must be a table_model. */
double table_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr);
double table_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr);

/* Fills cb like table_callbacks, with the smooth callbacks too. */
void table_mixed_callbacks(table_model *m, tclod_callbacks *cb);

/* Sum of the stored benefits / costs of ids[0..n), added in double in the
 * given order starting from 0.0 (the order the library's guarantee uses). */
double table_sum_benefit(const table_model *m, const tclod_id *ids, size_t n);
double table_sum_cost(const table_model *m, const tclod_id *ids, size_t n);

/* Sum of the costs of the roots (the coarsest cut), in id order. */
double table_roots_cost(const table_model *m);

/* Sum of the costs of the leaves (the finest cut), in id order. */
double table_leaves_cost(const table_model *m);

/* Deterministic generator, xorshift64*; identical sequences on every platform. */
typedef struct table_rng {
    uint64_t state;
} table_rng;

/* Seeds the generator; any seed (also 0) gives a valid, distinct stream. */
void table_rng_seed(table_rng *r, uint64_t seed);

/* Next 32 random bits. */
uint32_t table_rng_next(table_rng *r);

/* Uniform integer in [0, n); n > 0. */
uint32_t table_rng_below(table_rng *r, uint32_t n);

/* Uniform double in [lo, hi). */
double table_rng_uniform(table_rng *r, double lo, double hi);

/* How table_random_hierarchy draws values. */
typedef enum table_values {
    /* Diminishing returns: every increment (node -> its children) has
     * Δbenefit > 0 and Δcost > 0, and its ratio Δbenefit/Δcost is at most
     * 0.95 times the ratio of its parent's increment. */
    TABLE_DIMINISHING = 0,
    /* Benefits and costs drawn independently from [0.1, 10): increments may
     * gain nothing or even save cost. */
    TABLE_ARBITRARY = 1,
    /* Returns that need not diminish: as TABLE_DIMINISHING (every increment
     * gains and costs more), but an increment's ratio is 0.2 to 5 times its
     * parent's, so a poor step may lead to excellent ones. */
    TABLE_RISING = 2
} table_values;

/* Adds `nodes` nodes without bounds to s and m: the first `roots` are roots,
 * each later node's parent is drawn uniformly among the new nodes before it,
 * so hierarchies have random shapes (a node may have a single child). Values
 * as `values` says; all benefits and costs are > 0. Returns TCLOD_ERR_ARG
 * unless 1 <= roots <= nodes (nodes == 0 adds nothing), else the first
 * failing status of table_add_node (the nodes added before it stay). */
tclod_status table_random_hierarchy(table_model *m, tclod_scene *s, table_rng *r, uint32_t nodes,
                                    uint32_t roots, table_values values);

/* Adds `objects` chains of `levels` nodes each (level 0 the root, level k the
 * only child of level k-1), object by object. Level k of an object costs
 * c0 * 2^k and has benefit w * (2 - 2^-k), c0 in [0.5, 2) and w in [1, 10)
 * drawn per object: increment k (level k-1 -> k) gains w * 2^-k for
 * c0 * 2^(k-1) more cost, so ratios fall by 4 per level (diminishing returns).
 * With extent > 0 every object gets bounds (x, 0, z, 1), x and z uniform in
 * [-extent, extent), shared by its levels; with extent <= 0 no bounds. */
tclod_status table_chains(table_model *m, tclod_scene *s, table_rng *r, uint32_t objects,
                          uint32_t levels, float extent);

#ifdef __cplusplus
}
#endif

#endif /* TABLE_SCENE_H */
