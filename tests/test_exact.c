/*
 * test_exact — the benchmarks' exact reference (bench/optimum.c) checked against the
 * brute-force enumeration of tests/support/exact.c and against optima worked out by
 * hand. docs/benchmarks.md reports every solver's benefit as a fraction of what
 * optimum_chains and optimum_tree return, so those must be right first.
 *
 * Conventions of both references (docs/greedy.md, "Problem"): every hierarchy is in the
 * cut (-1 when even the roots do not fit); an invisible node (benefit 0) costs nothing
 * and is never refined.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "exact.h"
#include "family_scene.h"
#include "optimum.h"
#include "table_scene.h"

/* Random tiny instances per shape and family for the brute-force comparison. */
#define TINY_INSTANCES 150

typedef struct instance {
    tclod_scene *scene;
    table_model model;
} instance;

static void instance_init(instance *in) {
    assert_int_equal(tclod_scene_create(NULL, &in->scene), TCLOD_OK);
    table_init(&in->model);
}

static void instance_free(instance *in) {
    tclod_scene_destroy(in->scene);
    table_free(&in->model);
}

static tclod_id add(instance *in, tclod_id parent, double benefit, double cost) {
    tclod_id id = TCLOD_NONE;
    assert_int_equal(table_add_node(&in->model, in->scene, parent, NULL, benefit, cost, &id),
                     TCLOD_OK);
    return id;
}

static optimum_instance view_of(const table_model *m) {
    optimum_instance o;
    o.count = m->count;
    o.parent = m->parent;
    o.benefit = m->benefit;
    o.cost = m->cost;
    return o;
}

/* Asserts a curve's value at each budget from 0 (expected[0]) upwards. */
static void assert_curve(const optimum_curve *c, const double *expected, size_t n) {
    size_t x;
    for (x = 0; x < n; ++x)
        if (optimum_at(c, (double)x) != expected[x])
            fail_msg("budget %u: optimum %.17g, expected %.17g", (unsigned)x,
                     optimum_at(c, (double)x), expected[x]);
}

/* Three objects (levels as (cost, benefit), coarse to fine):
 *   A: (1, 2) (3, 5) (6, 7)   B: (2, 3) (4, 6)   C: (1, 1) (2, 4)
 * The roots cost 1 + 2 + 1 = 4 and give 2 + 3 + 1 = 6. Over the roots, each object
 * offers (extra cost, extra benefit): A (2, 3) or (5, 5); B (2, 3); C (1, 3). The best
 * choice for each extra e = budget - 4:
 *   e 0: nothing                       +0   6
 *   e 1: C                             +3   9
 *   e 2: one of C, A1, B1               +3   9
 *   e 3: C + A1 (or C + B1)            +6  12
 *   e 4: A1 + B1 (or C + A1)           +6  12
 *   e 5: C + A1 + B1                   +9  15   (A2 alone: +5)
 *   e 6: C + A1 + B1                   +9  15   (A2 + C: +8)
 *   e 7: C + A1 + B1                   +9  15   (A2 + B1: +8)
 *   e 8: A2 + B1 + C (every finest)   +11  17
 * and below the roots' cost (budgets 0 to 3) no cut fits. */
static void build_three_chains(instance *in) {
    tclod_id a, b, c;
    a = add(in, TCLOD_NONE, 2.0, 1.0);
    a = add(in, a, 5.0, 3.0);
    add(in, a, 7.0, 6.0);
    b = add(in, TCLOD_NONE, 3.0, 2.0);
    add(in, b, 6.0, 4.0);
    c = add(in, TCLOD_NONE, 1.0, 1.0);
    add(in, c, 4.0, 2.0);
}

static const double three_chains_optimum[14] = {-1, -1, -1, -1, 6,  9,  9,
                                                12, 12, 15, 15, 15, 17, 17};

static void chain_program_finds_the_hand_worked_optimum(void **state) {
    instance in;
    optimum_instance o;
    optimum_curve c;
    (void)state;
    instance_init(&in);
    build_three_chains(&in);
    o = view_of(&in.model);
    assert_int_equal(optimum_chains(&o, 1.0, 13.0, 0, &c), OPTIMUM_OK);
    assert_int_equal(c.units, 13);
    assert_curve(&c, three_chains_optimum, 14);
    optimum_curve_free(&c);
    instance_free(&in);
}

static void tree_program_finds_the_hand_worked_optimum_of_chains(void **state) {
    instance in;
    optimum_instance o;
    optimum_curve c;
    (void)state;
    instance_init(&in);
    build_three_chains(&in);
    o = view_of(&in.model);
    assert_int_equal(optimum_tree(&o, 1.0, 13.0, 0, &c), OPTIMUM_OK);
    assert_curve(&c, three_chains_optimum, 14);
    optimum_curve_free(&c);
    instance_free(&in);
}

/* Two hierarchies and an invisible third, as (benefit, cost):
 *   R (4, 2) with children X (3, 2) and Y (3, 3); X with children X1 (3, 2), X2 (2, 2)
 *   S (1, 1) with the one child S1 (5, 4)
 *   Z (0, 5) invisible, with a child Z1 (9, 1) that must never be drawn
 * Cuts of R: {R} (cost 2, benefit 4), {X, Y} (5, 6), {X1, X2, Y} (7, 8).
 * Cuts of S: {S} (1, 1), {S1} (4, 5). Z adds nothing and costs nothing.
 * Pairs (cost, benefit): {R,S} (3, 5), {R,S1} (6, 4 + 5 = 9), {XY,S} (6, 7),
 * {XY,S1} (9, 6 + 5 = 11), {X1X2Y,S} (8, 9), {X1X2Y,S1} (11, 8 + 5 = 13). Best per
 * budget: 0-2: none (-1); 3-5: 5; 6-8: 9; 9-10: 11; 11-12: 13. */
static void tree_program_finds_the_hand_worked_optimum_of_a_forest(void **state) {
    static const double expected[13] = {-1, -1, -1, 5, 5, 5, 9, 9, 9, 11, 11, 13, 13};
    instance in;
    optimum_instance o;
    optimum_curve c;
    tclod_id r, x, s, z;
    (void)state;
    instance_init(&in);
    r = add(&in, TCLOD_NONE, 4.0, 2.0);
    x = add(&in, r, 3.0, 2.0);
    add(&in, r, 3.0, 3.0);
    add(&in, x, 3.0, 2.0);
    add(&in, x, 2.0, 2.0);
    s = add(&in, TCLOD_NONE, 1.0, 1.0);
    add(&in, s, 5.0, 4.0);
    z = add(&in, TCLOD_NONE, 0.0, 5.0);
    add(&in, z, 9.0, 1.0);
    o = view_of(&in.model);
    assert_int_equal(optimum_tree(&o, 1.0, 12.0, 0, &c), OPTIMUM_OK);
    assert_curve(&c, expected, 13);
    optimum_curve_free(&c);
    /* A chain program refuses the same forest: R has two children. */
    assert_int_equal(optimum_chains(&o, 1.0, 12.0, 0, &c), OPTIMUM_NOT_CHAINS);
    instance_free(&in);
}

/* The three chains again, budget 6 (two units over the roots): the fractional
 * knapsack takes the increments in falling benefit per cost, C (3 per unit), then A1
 * and B1 (1.5 per unit each): C uses 1 unit for +3 and half of A1 the other for +1.5,
 * so the linear-programming bound is 6 + 3 + 1.5 = 10.5, above the optimum 9. With a
 * budget covering every finest level (12) the bound is the optimum, 17. */
static void bound_is_the_fractional_knapsack_of_the_hand_worked_chains(void **state) {
    instance in;
    optimum_instance o;
    (void)state;
    instance_init(&in);
    build_three_chains(&in);
    o = view_of(&in.model);
    assert_true(fabs(optimum_bound(&o, 6.0, 0) - 10.5) < 1e-9);
    assert_true(fabs(optimum_bound(&o, 12.0, 0) - 17.0) < 1e-9);
    instance_free(&in);
}

/* The three chains when objects may be left out. Budget 3 is below the roots' cost (4),
 * yet C at level 1 (cost 2, benefit 4) with A at level 0 (1, 2) fits: 6; nothing better
 * fits (A1 alone 5, A0 + B0 5, B0 + C0 4). At budget 6, where the cut optimum is 9,
 * leaving A out pays: B1 (4, 6) + C1 (2, 4) = 10, against A1 + C1 9 (cost 5),
 * A1 + B0 + C0 9 and A0 + B1 8. */
static void holes_optimum_of_the_hand_worked_chains_leaves_an_object_out(void **state) {
    instance in;
    optimum_instance o;
    optimum_curve c, t;
    (void)state;
    instance_init(&in);
    build_three_chains(&in);
    o = view_of(&in.model);
    assert_int_equal(optimum_chains(&o, 1.0, 13.0, 1, &c), OPTIMUM_OK);
    assert_int_equal(optimum_tree(&o, 1.0, 13.0, 1, &t), OPTIMUM_OK);
    assert_true(optimum_at(&c, 0.0) == 0.0);
    assert_true(optimum_at(&c, 3.0) == 6.0);
    assert_true(optimum_at(&c, 6.0) == 10.0);
    assert_true(optimum_at(&t, 3.0) == 6.0);
    assert_true(optimum_at(&t, 6.0) == 10.0);
    assert_true(optimum_bound(&o, 6.0, 1) >= 10.0 - 1e-9);
    optimum_curve_free(&c);
    optimum_curve_free(&t);
    instance_free(&in);
}

/* Leaving a part of a hierarchy out is the same as choosing, above each node, a stand-in
 * that draws nothing: every node n of the instance gets a new parent V_n of cost 0 and a
 * tiny benefit HOLE_EPSILON (a benefit of 0 would make V_n invisible and its subtree
 * unreachable). The brute-force optimum of that instance exceeds the holes optimum of
 * the original by at most HOLE_EPSILON per node. Chains stay chains. */
#define HOLE_EPSILON 1e-7

static void build_with_stand_ins(const table_model *m, instance *out) {
    tclod_id *copy = (tclod_id *)malloc(((size_t)m->count + 1u) * sizeof *copy);
    uint32_t n;
    assert_non_null(copy);
    for (n = 0; n < m->count; ++n) {
        /* family_build adds parents before their children */
        tclod_id parent = m->parent[n] == TCLOD_NONE ? TCLOD_NONE : copy[m->parent[n]];
        tclod_id stand_in = add(out, parent, HOLE_EPSILON, 0.0);
        copy[n] = add(out, stand_in, m->benefit[n], m->cost[n]);
    }
    free(copy);
}

static void holes_optima_match_brute_force_over_stand_ins(void **state) {
    int shape, kind;
    (void)state;
    for (shape = 0; shape < 2; ++shape)
        for (kind = 0; kind < FAMILY_KIND_COUNT; ++kind) {
            family_desc d;
            unsigned i;
            family_desc_default(&d, (family_shape)shape, (family_kind)kind);
            d.range = 20;
            d.objects_min = 1;
            d.objects_max = 3;
            d.levels_min = 1;
            d.levels_max = 3;
            d.children_min = 1;
            d.children_max = 2;
            d.max_nodes = EXACT_MAX_NODES / 2u;
            for (i = 0; i < TINY_INSTANCES; ++i) {
                instance in, wrapped;
                table_rng r;
                optimum_instance o;
                optimum_curve tree, chain;
                double budget, top;
                instance_init(&in);
                instance_init(&wrapped);
                table_rng_seed(&r,
                               5000u + 1000u * (unsigned)(shape * FAMILY_KIND_COUNT + kind) + i);
                assert_int_equal(family_build(&d, &in.model, in.scene, &r), TCLOD_OK);
                if (in.model.count > EXACT_MAX_NODES / 2u) {
                    /* chains of 3 objects x 3 levels: too many to wrap; skip the draw */
                    instance_free(&in);
                    instance_free(&wrapped);
                    continue;
                }
                build_with_stand_ins(&in.model, &wrapped);
                o = view_of(&in.model);
                top = table_leaves_cost(&in.model) + 1.0;
                assert_int_equal(optimum_tree(&o, 1.0, top, 1, &tree), OPTIMUM_OK);
                memset(&chain, 0, sizeof chain);
                if (shape == FAMILY_CHAINS)
                    assert_int_equal(optimum_chains(&o, 1.0, top, 1, &chain), OPTIMUM_OK);
                for (budget = 0.0; budget <= top; budget += 1.0) {
                    double brute = exact_optimum(&wrapped.model, budget, NULL);
                    double slack = HOLE_EPSILON * (double)in.model.count + 1e-9 * (1.0 + brute);
                    double by_tree = optimum_at(&tree, budget);
                    if (!(by_tree <= brute + 1e-9 * (1.0 + brute) && brute - by_tree <= slack))
                        fail_msg("%s instance %u, budget %g: tree program %.17g, brute force "
                                 "over stand-ins %.17g",
                                 family_kind_name((family_kind)kind), i, budget, by_tree, brute);
                    if (shape == FAMILY_CHAINS && optimum_at(&chain, budget) != by_tree)
                        fail_msg("%s instance %u, budget %g: chain program %.17g, tree %.17g",
                                 family_kind_name((family_kind)kind), i, budget,
                                 optimum_at(&chain, budget), by_tree);
                    if (!(optimum_bound(&o, budget, 1) >= by_tree - 1e-9 * (1.0 + by_tree)))
                        fail_msg("%s instance %u, budget %g: holes bound below the optimum",
                                 family_kind_name((family_kind)kind), i, budget);
                }
                optimum_curve_free(&tree);
                optimum_curve_free(&chain);
                instance_free(&in);
                instance_free(&wrapped);
            }
        }
}

/* Compares both programs with the brute force on one instance at every budget from 0
 * to one past the finest cut's cost; also checks the bound lies above the optimum. */
static void compare_with_brute_force(const table_model *m, int chains, const char *what,
                                     unsigned index) {
    optimum_instance o = view_of(m);
    optimum_curve tree, chain;
    double top = table_leaves_cost(m) + 1.0, budget;
    memset(&chain, 0, sizeof chain);
    assert_int_equal(optimum_tree(&o, 1.0, top, 0, &tree), OPTIMUM_OK);
    if (chains)
        assert_int_equal(optimum_chains(&o, 1.0, top, 0, &chain), OPTIMUM_OK);
    for (budget = 0.0; budget <= top; budget += 1.0) {
        double brute = exact_optimum(m, budget, NULL);
        double by_tree = optimum_at(&tree, budget);
        double bound;
        assert_true(brute >= -1.0);
        /* Benefits are summed in a different order: equal within rounding. */
        if (fabs(by_tree - brute) > 1e-9 * (1.0 + fabs(brute)))
            fail_msg("%s instance %u, budget %g: tree program %.17g, brute force %.17g", what,
                     index, budget, by_tree, brute);
        if (chains && fabs(optimum_at(&chain, budget) - brute) > 1e-9 * (1.0 + fabs(brute)))
            fail_msg("%s instance %u, budget %g: chain program %.17g, brute force %.17g", what,
                     index, budget, optimum_at(&chain, budget), brute);
        bound = optimum_bound(&o, budget, 0);
        if (brute >= 0.0 && !(bound >= brute - 1e-9 * (1.0 + brute)))
            fail_msg("%s instance %u, budget %g: bound %.17g below the optimum %.17g", what, index,
                     budget, bound, brute);
    }
    optimum_curve_free(&tree);
    optimum_curve_free(&chain);
}

/* Tiny instances of every family (at most EXACT_MAX_NODES nodes), a tenth of their
 * nodes made invisible so that culling is covered too. */
static void programs_match_brute_force_on_tiny_random_instances(void **state) {
    int shape, kind;
    (void)state;
    for (shape = 0; shape < 2; ++shape)
        for (kind = 0; kind < FAMILY_KIND_COUNT; ++kind) {
            family_desc d;
            unsigned i;
            family_desc_default(&d, (family_shape)shape, (family_kind)kind);
            d.range = 20;
            if (shape == FAMILY_CHAINS) {
                d.objects_min = 1;
                d.objects_max = 4;
                d.levels_min = 1;
                d.levels_max = 4;
            } else {
                d.objects_min = 1;
                d.objects_max = 3;
                d.levels_min = 1;
                d.levels_max = 3;
                d.children_min = 1;
                d.children_max = 3;
                d.max_nodes = EXACT_MAX_NODES;
            }
            for (i = 0; i < TINY_INSTANCES; ++i) {
                instance in;
                table_rng r;
                uint32_t n;
                instance_init(&in);
                table_rng_seed(&r, 1000u * (unsigned)(shape * FAMILY_KIND_COUNT + kind) + i);
                assert_int_equal(family_build(&d, &in.model, in.scene, &r), TCLOD_OK);
                assert_true(in.model.count <= EXACT_MAX_NODES);
                for (n = 0; n < in.model.count; ++n)
                    if (table_rng_below(&r, 10u) == 0u)
                        in.model.benefit[n] = 0.0;
                compare_with_brute_force(&in.model, shape == FAMILY_CHAINS,
                                         family_kind_name((family_kind)kind), i);
                instance_free(&in);
            }
        }
}

/* On the benchmark's own chain instances (too large for brute force) the two programs,
 * which share no code but the input checks, agree at every budget. */
static void tree_program_agrees_with_chain_program_on_benchmark_chains(void **state) {
    int kind;
    (void)state;
    for (kind = 0; kind < FAMILY_KIND_COUNT; ++kind) {
        unsigned i;
        for (i = 0; i < 4u; ++i) {
            family_desc d;
            instance in;
            table_rng r;
            optimum_instance o;
            optimum_curve a, b;
            uint32_t x;
            family_desc_default(&d, FAMILY_CHAINS, (family_kind)kind);
            d.objects_max = 30;
            instance_init(&in);
            table_rng_seed(&r, 77u + 10u * (unsigned)kind + i);
            assert_int_equal(family_build(&d, &in.model, in.scene, &r), TCLOD_OK);
            o = view_of(&in.model);
            assert_int_equal(optimum_chains(&o, 1.0, table_leaves_cost(&in.model), 0, &a),
                             OPTIMUM_OK);
            assert_int_equal(optimum_tree(&o, 1.0, table_leaves_cost(&in.model), 0, &b),
                             OPTIMUM_OK);
            assert_int_equal(a.units, b.units);
            for (x = 0; x <= a.units; ++x)
                if (a.best[x] != b.best[x]) /* integer benefits: exact in any order */
                    fail_msg("%s instance %u, budget %u: chains %.17g, tree %.17g",
                             family_kind_name((family_kind)kind), i, (unsigned)x, a.best[x],
                             b.best[x]);
            optimum_curve_free(&a);
            optimum_curve_free(&b);
            instance_free(&in);
        }
    }
}

/* The programs are exact only over whole quanta: a cost of 1.5 is refused with quantum
 * 1 and accepted with quantum 0.5. Root (b 1, c 1.5) with child (b 3, c 2.5): the root
 * fits a budget of 1.5 (three half quanta) and the child from 2.5 on. */
static void costs_that_are_not_whole_quanta_are_refused(void **state) {
    static const tclod_id parent[2] = {TCLOD_NONE, 0};
    static const double benefit[2] = {1.0, 3.0}, cost[2] = {1.5, 2.5};
    optimum_instance o;
    optimum_curve c;
    (void)state;
    o.count = 2;
    o.parent = parent;
    o.benefit = benefit;
    o.cost = cost;
    assert_int_equal(optimum_chains(&o, 1.0, 3.0, 0, &c), OPTIMUM_NOT_INTEGRAL);
    assert_null(c.best);
    assert_int_equal(optimum_tree(&o, 1.0, 3.0, 0, &c), OPTIMUM_NOT_INTEGRAL);
    assert_int_equal(optimum_chains(&o, 0.5, 3.0, 0, &c), OPTIMUM_OK);
    assert_true(optimum_at(&c, 1.4) == -1.0);
    assert_true(optimum_at(&c, 1.5) == 1.0);
    assert_true(optimum_at(&c, 2.4) == 1.0);
    assert_true(optimum_at(&c, 2.5) == 3.0);
    assert_true(isnan(optimum_at(&c, 3.5)));
    optimum_curve_free(&c);
}

/* Inputs no cut problem has: a cycle of parents, a negative cost, a NaN benefit. */
static void malformed_instances_are_refused(void **state) {
    static const tclod_id cycle[2] = {1, 0};
    static const tclod_id forest[2] = {TCLOD_NONE, 0};
    static const double ones[2] = {1.0, 1.0}, negative[2] = {1.0, -1.0};
    double nan_benefit[2] = {1.0, 1.0};
    optimum_instance o;
    optimum_curve c;
    (void)state;
    nan_benefit[1] = NAN;
    o.count = 2;
    o.parent = cycle;
    o.benefit = ones;
    o.cost = ones;
    assert_int_equal(optimum_tree(&o, 1.0, 4.0, 0, &c), OPTIMUM_BAD_VALUE);
    assert_true(isnan(optimum_bound(&o, 4.0, 0)));
    o.parent = forest;
    o.cost = negative;
    assert_int_equal(optimum_tree(&o, 1.0, 4.0, 0, &c), OPTIMUM_BAD_VALUE);
    o.cost = ones;
    o.benefit = nan_benefit;
    assert_int_equal(optimum_chains(&o, 1.0, 4.0, 0, &c), OPTIMUM_BAD_VALUE);
    o.benefit = ones;
    assert_int_equal(optimum_tree(&o, 0.0, 4.0, 0, &c), OPTIMUM_BAD_VALUE);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(chain_program_finds_the_hand_worked_optimum),
        cmocka_unit_test(tree_program_finds_the_hand_worked_optimum_of_chains),
        cmocka_unit_test(tree_program_finds_the_hand_worked_optimum_of_a_forest),
        cmocka_unit_test(bound_is_the_fractional_knapsack_of_the_hand_worked_chains),
        cmocka_unit_test(programs_match_brute_force_on_tiny_random_instances),
        cmocka_unit_test(holes_optimum_of_the_hand_worked_chains_leaves_an_object_out),
        cmocka_unit_test(holes_optima_match_brute_force_over_stand_ins),
        cmocka_unit_test(tree_program_agrees_with_chain_program_on_benchmark_chains),
        cmocka_unit_test(costs_that_are_not_whole_quanta_are_refused),
        cmocka_unit_test(malformed_instances_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
