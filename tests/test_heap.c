/*
 * test_heap — the priority queues of the greedy solver (src/core/heap.c, internal),
 * observed through the selection: increments leave in decreasing ratio
 * Δbenefit/Δcost with ties going to the lower node id, whatever order they
 * were pushed in, and decrements leave least loss per saved cost first.
 * max_iterations = k stops after the k-th increment tried, which exposes the
 * order one element at a time.
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
#include "helpers.h"
#include "table_scene.h"

/* Selects with an unlimited budget and at most k iterations (0 = no limit). */
static void select_iterations(tclod_selector *sel, uint32_t k, tclod_stats *st) {
    tclod_frame f = helper_frame(NULL, INFINITY);
    f.max_iterations = k;
    assert_int_equal(tclod_select(sel, &f, st), TCLOD_OK);
}

static void equal_ratios_take_the_lower_node_id_first(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    /* Roots 0 and 1 (b 1, c 1); the child of root 1 is created first (id 2),
     * then the child of root 0 (id 3), both b 2, c 2. Both increments gain
     * 2 - 1 = 1 for 2 - 1 = 1: ratio 1. Root 0 has the lower id. */
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 1, 2.0, 2.0);
    helper_add(f, 0, 2.0, 2.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_iterations(sel, 1, &st);
    {
        const tclod_id want[] = {3, 1};
        helper_assert_cut(sel, want, 2);
    }
    select_iterations(sel, 2, &st);
    {
        const tclod_id want[] = {3, 2};
        helper_assert_cut(sel, want, 2);
    }
    tclod_selector_destroy(sel);
}

static void a_later_pushed_increment_with_lower_id_wins_the_tie(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    /* A = 0 (b 1, c 1) -> A1 = 1 (b 6, c 2) -> A2 = 4 (b 7, c 3);
     * B = 2 (b 1, c 1) -> B1 = 3 (b 2, c 2).
     * Ratios: A 5/1 = 5, B 1/1 = 1 (queued from the start), A1 1/1 = 1
     * (queued only after A was taken). A1 has id 1 < 2, so it goes first. */
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 6.0, 2.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 2, 2.0, 2.0);
    helper_add(f, 1, 7.0, 3.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_iterations(sel, 1, &st);
    {
        const tclod_id want[] = {1, 2};
        helper_assert_cut(sel, want, 2);
    }
    select_iterations(sel, 2, &st);
    {
        const tclod_id want[] = {4, 2};
        helper_assert_cut(sel, want, 2);
    }
    select_iterations(sel, 3, &st);
    {
        const tclod_id want[] = {4, 3};
        helper_assert_cut(sel, want, 2);
    }
    tclod_selector_destroy(sel);
}

static void an_earlier_pushed_increment_with_lower_id_wins_the_tie(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    /* Mirror of the previous case: B = 0 (b 1, c 1) -> B1 = 1 (b 2, c 2);
     * A = 2 (b 1, c 1) -> A1 = 3 (b 6, c 2) -> A2 = 4 (b 7, c 3).
     * A goes first (ratio 5); then B (id 0, queued first) beats A1 (id 3). */
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 2.0, 2.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 2, 6.0, 2.0);
    helper_add(f, 3, 7.0, 3.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_iterations(sel, 2, &st);
    {
        const tclod_id want[] = {1, 3};
        helper_assert_cut(sel, want, 2);
    }
    tclod_selector_destroy(sel);
}

/* Ordering key of root i in the large test below: ratio descending, id ascending. */
typedef struct ranked {
    double ratio;
    tclod_id root;
} ranked;

static int ranked_compare(const void *a, const void *b) {
    const ranked *x = (const ranked *)a, *y = (const ranked *)b;
    if (x->ratio != y->ratio)
        return x->ratio > y->ratio ? -1 : 1;
    return (x->root > y->root) - (x->root < y->root);
}

/* n roots (ids 0..n-1, b 1, c 1), each with one child (id n + i). Root i's
 * increment costs dc = 1 + i % 3 and gains dc * ratio(i), integers, so the
 * library's Δb / Δc is exactly ratio(i). With max_iterations = k and no
 * budget limit the refined roots must be the first k in (ratio desc, id asc). */
static void check_order(helper_fixture *f, uint32_t n, double (*ratio_of)(uint32_t)) {
    static const uint32_t limits[] = {1, 2, 3, 10, 100, 333, 999};
    ranked *order = (ranked *)malloc(n * sizeof *order);
    unsigned char *refined = (unsigned char *)malloc(n);
    tclod_id *cut = (tclod_id *)malloc(n * sizeof *cut);
    tclod_selector *sel;
    tclod_stats st;
    uint32_t i;
    size_t l;
    assert_non_null(order);
    assert_non_null(refined);
    assert_non_null(cut);
    for (i = 0; i < n; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (i = 0; i < n; ++i) {
        double dc = 1.0 + (double)(i % 3u);
        helper_add(f, i, 1.0 + dc * ratio_of(i), 1.0 + dc);
        order[i].ratio = ratio_of(i);
        order[i].root = i;
    }
    qsort(order, n, sizeof *order, ranked_compare);
    sel = helper_selector(f->scene, &f->model, 0);
    for (l = 0; l < sizeof limits / sizeof limits[0]; ++l) {
        uint32_t k = limits[l];
        size_t got;
        if (k >= n)
            continue;
        select_iterations(sel, k, &st);
        assert_int_equal(st.iterations, k);
        assert_int_equal(st.increments, k);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
        memset(refined, 0, n);
        for (i = 0; i < k; ++i)
            refined[order[i].root] = 1;
        got = helper_sorted_cut(sel, cut, n);
        assert_int_equal(got, n);
        /* Sorted: unrefined roots ascending, then children n + i ascending. */
        {
            size_t at = 0;
            for (i = 0; i < n; ++i)
                if (!refined[i]) {
                    if (cut[at] != i)
                        fail_msg("k = %u: root %u should be unrefined", k, i);
                    at++;
                }
            for (i = 0; i < n; ++i)
                if (refined[i]) {
                    if (cut[at] != n + i)
                        fail_msg("k = %u: root %u should be refined", k, i);
                    at++;
                }
        }
    }
    select_iterations(sel, 0, &st);
    assert_int_equal(st.increments, n);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    tclod_selector_destroy(sel);
    free(cut);
    free(refined);
    free(order);
}

/* 7919 is prime, so i -> 7919 i mod 1000 permutes 0..999: distinct ratios. */
static double distinct_ratio(uint32_t i) {
    return 1.0 + (double)((i * 7919u) % 1000u);
}

/* Only 10 distinct ratios among 1000 roots: long runs of ties. */
static double tied_ratio(uint32_t i) {
    return 1.0 + (double)(((i * 7919u) % 1000u) % 10u);
}

static void increments_leave_in_decreasing_ratio_order(void **state) {
    check_order((helper_fixture *)*state, 1000, distinct_ratio);
}

static void many_ties_leave_in_id_order(void **state) {
    check_order((helper_fixture *)*state, 1000, tied_ratio);
}

static void decrements_give_back_least_benefit_per_saved_cost_first(void **state) {
    /* 50 chains: root i (id i, b 1, c 1), child (id 50 + i, b 1 + g(i), c 2),
     * g(i) = 1 + (17 i mod 50) distinct (17 and 50 coprime). With everything
     * refined the cost is 50 * 2 = 100; each decrement saves exactly 1 and
     * loses g(i). Budget 100 - 7 needs 7 decrements: the roots with the seven
     * smallest g, i.e. 17 i mod 50 in 0..6. Budget 80 then needs 13 more:
     * 17 i mod 50 in 0..19. No swap gains afterwards (every coarse object gains
     * less than any refined one loses), so this is also the optimum. */
    helper_fixture *f = (helper_fixture *)*state;
    const uint32_t n = 50;
    const struct {
        double budget;
        uint32_t coarse_below; /* roots with 17 i mod 50 < this stay coarse */
    } frames[] = {{INFINITY, 0}, {93.0, 7}, {80.0, 20}, {INFINITY, 0}};
    tclod_selector *sel;
    tclod_id cut[50];
    tclod_stats st;
    uint32_t i;
    size_t fr;
    for (i = 0; i < n; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (i = 0; i < n; ++i)
        helper_add(f, i, 2.0 + (double)((17u * i) % 50u), 2.0);
    sel = helper_selector(f->scene, &f->model, 1);
    for (fr = 0; fr < sizeof frames / sizeof frames[0]; ++fr) {
        tclod_frame frame = helper_frame(NULL, frames[fr].budget);
        assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
        helper_check_result(sel, &f->model, &st, frames[fr].budget, 0);
        assert_int_equal(helper_sorted_cut(sel, cut, n), n);
        for (i = 0; i < n; ++i) {
            int coarse = (17u * i) % 50u < frames[fr].coarse_below;
            int listed_root = 0, j;
            for (j = 0; j < (int)n; ++j)
                listed_root |= cut[j] == i;
            if (listed_root != coarse)
                fail_msg("frame %u: object %u should be %s", (unsigned)fr, i,
                         coarse ? "coarse" : "refined");
        }
        if (fr == 1)
            assert_true(st.decrements >= 7);
        if (fr == 2)
            assert_true(st.decrements >= 13);
    }
    tclod_selector_destroy(sel);
}

#define FIXTURE_TEST(name) \
    cmocka_unit_test_setup_teardown(name, helper_fixture_setup, helper_fixture_teardown)

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(equal_ratios_take_the_lower_node_id_first),
        FIXTURE_TEST(a_later_pushed_increment_with_lower_id_wins_the_tie),
        FIXTURE_TEST(an_earlier_pushed_increment_with_lower_id_wins_the_tie),
        FIXTURE_TEST(increments_leave_in_decreasing_ratio_order),
        FIXTURE_TEST(many_ties_leave_in_id_order),
        FIXTURE_TEST(decrements_give_back_least_benefit_per_saved_cost_first),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
