/*
 * test_split — smooth variables (src/solve/split.c and the scene's quadtree in
 * src/core/scene_prepare.c): quadtree order, frustum and small-detail culling, and the
 * splitting criterion of docs/mixed.md, worked out by hand:
 *
 *   a node of n objects with benefit scales c_j (benefit at full resolution),
 *   C = sum c_j, Q = sum c_j^2, all of them visible, keeps one variable when
 *     L = sqrt(X) (sqrt(Q) - C / sqrt(n))
 *   is at most its share of theta * C_root * sqrt(X_root / n_root), with
 *   X_root = n_root * min(1, budget / cost of the root group at full
 *   resolution); a split node hands each of its v visible children theta / v
 *   and X_i = X (C_i^2 / n_i) / sum_k (C_k^2 / n_k), at most n_i, what a
 *   capped child cannot take going to the others.
 *
 * Smooth objects come from the table model (benefit w sqrt(r), cost k r; a
 * group's values are the sums over its members), so C_i is the sum of the
 * members' weights.
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

#include "helpers.h"
#include "table_scene.h"

static tclod_id add_object(helper_fixture *f, float x, float y, float z, float radius, double w) {
    float b[4];
    tclod_id id = TCLOD_NONE;
    b[0] = x;
    b[1] = y;
    b[2] = z;
    b[3] = radius;
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, b, TABLE_POWER, w, 0.5, 1.0, 1.0, 0.0, &id),
        TCLOD_OK);
    return id;
}

static tclod_selector *split_selector(helper_fixture *f, int split, double theta) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(&f->model, &d.callbacks);
    d.mixed.split_smooth = split;
    d.mixed.split_threshold = theta;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

static void select_view(tclod_selector *sel, const tclod_view *view, double budget,
                        tclod_stats *st) {
    tclod_frame fr = helper_frame(view, budget);
    assert_int_equal(tclod_select(sel, &fr, st), TCLOD_OK);
}

/* Position of smooth object id in the scene's smooth order. */
static uint32_t position_of(helper_fixture *f, tclod_id id) {
    const tclod_id *order;
    uint32_t n, i;
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &n), TCLOD_OK);
    for (i = 0; i < n; ++i)
        if (order[i] == id)
            return i;
    fail_msg("smooth object %u is not in the order", id);
    return 0;
}

/* ---- the quadtree order -------------------------------------------------------- */

/* A 4 x 4 grid at x, z in {0, 1, 2, 3}: the root's quadrants are the 2 x 2
 * blocks, so the four objects of each block hold consecutive positions. */
static void quadtree_order_keeps_each_quadrant_contiguous(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id grid[4][4];
    const tclod_id *order;
    uint32_t n, bx, bz, i, j;
    uint8_t seen[16];
    for (i = 0; i < 4; ++i)
        for (j = 0; j < 4; ++j)
            grid[i][j] = add_object(f, (float)i, 0.0f, (float)j, 0.1f, 1.0);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &n), TCLOD_OK);
    assert_int_equal(n, 16);
    memset(seen, 0, sizeof seen);
    for (i = 0; i < n; ++i) {
        assert_true(order[i] < 16);
        assert_int_equal(seen[order[i]], 0);
        seen[order[i]] = 1;
    }
    for (bx = 0; bx < 4; bx += 2)
        for (bz = 0; bz < 4; bz += 2) {
            uint32_t lo = 16, hi = 0;
            for (i = bx; i < bx + 2; ++i)
                for (j = bz; j < bz + 2; ++j) {
                    uint32_t p = position_of(f, grid[i][j]);
                    lo = p < lo ? p : lo;
                    hi = p > hi ? p : hi;
                }
            assert_int_equal(hi - lo, 3);
        }
}

/* ---- culling ----------------------------------------------------------------- */

/* The reference view looks down -z from the origin. Objects at z = -10 are in
 * front, at z = +10 behind: those get no variable and resolution 0, and the
 * budget goes to the others. Two objects in front, sqrt(r), costs r, budget 1:
 * r = 1/2 each. */
static void objects_outside_the_frustum_get_no_variable(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id front1 = add_object(f, -1.0f, 0.0f, -10.0f, 0.5f, 1.0);
    tclod_id front2 = add_object(f, 1.0f, 0.0f, -10.0f, 0.5f, 1.0);
    tclod_id back1 = add_object(f, -1.0f, 0.0f, 10.0f, 0.5f, 1.0);
    tclod_id back2 = add_object(f, 1.0f, 0.0f, 10.0f, 0.5f, 1.0);
    tclod_selector *sel = split_selector(f, 0, 0.0);
    tclod_view view;
    tclod_stats st;
    helper_view(&view);
    select_view(sel, &view, 1.0, &st);
    assert_int_equal(st.variables, 2);
    assert_true(tclod_selector_resolution(sel, back1) == 0.0);
    assert_true(tclod_selector_resolution(sel, back2) == 0.0);
    assert_true(fabs(tclod_selector_resolution(sel, front1) - 0.5) < 1e-6);
    assert_true(fabs(tclod_selector_resolution(sel, front2) - 0.5) < 1e-6);
    tclod_selector_destroy(sel);
}

/* An object of radius 0.01 at 90 m projects to pi (500 / tan(pi/4) * 0.01 /
 * sqrt(90^2 - 0.01^2))^2 = 0.0097 px², below the default small-detail area
 * of 1 px²: no variable. The one of radius 1 at 10 m covers thousands of px².
 * With smooth_cull_area 0 both get variables. */
static void objects_below_the_small_detail_area_get_no_variable(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id near_object = add_object(f, 0.0f, 0.0f, -10.0f, 1.0f, 1.0);
    tclod_id far_object = add_object(f, 5.0f, 0.0f, -90.0f, 0.01f, 1.0);
    tclod_selector_desc d;
    tclod_selector *sel = split_selector(f, 0, 0.0);
    tclod_view view;
    tclod_stats st;
    float area;
    float fb[4] = {5.0f, 0.0f, -90.0f, 0.01f};
    helper_view(&view);
    area = tclod_view_screen_area(&view, fb);
    assert_true(area < 0.01f && area > 0.009f);
    select_view(sel, &view, 1.0, &st);
    assert_int_equal(st.variables, 1);
    assert_true(tclod_selector_resolution(sel, near_object) > 0.0);
    assert_true(tclod_selector_resolution(sel, far_object) == 0.0);
    tclod_selector_destroy(sel);

    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(&f->model, &d.callbacks);
    d.smooth_cull_area = TCLOD_OFF;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    select_view(sel, &view, 1.0, &st);
    assert_int_equal(st.variables, 2);
    assert_true(tclod_selector_resolution(sel, far_object) > 0.0);
    tclod_selector_destroy(sel);
}

/* ---- the splitting criterion ---------------------------------------------------- */

/* Four alike objects (a 2 x 2 grid, each its own quadrant): C_i = 1, n_i = 1,
 * n = 4, so L = sqrt(X) (sqrt(4) - 4 / 2) = 0: one shared variable, even with
 * theta = 0. Budget 2 of the 4 a full group costs: r = 1/2, spread to every
 * member. */
static void alike_objects_share_one_variable(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id ids[4];
    const tclod_smooth_group *groups;
    tclod_selector *sel;
    tclod_stats st;
    size_t n;
    int i;
    for (i = 0; i < 4; ++i)
        ids[i] = add_object(f, (float)(i % 2), 0.0f, (float)(i / 2), 0.1f, 1.0);
    sel = split_selector(f, 1, 0.0);
    select_view(sel, NULL, 2.0, &st);
    assert_int_equal(st.variables, 1);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(groups[0].first, 0);
    assert_int_equal(groups[0].count, 4);
    assert_true(fabs(groups[0].resolution - 0.5) < 1e-6);
    for (i = 0; i < 4; ++i)
        assert_true(tclod_selector_resolution(sel, ids[i]) == groups[0].resolution);
    tclod_selector_destroy(sel);
}

/* Two objects of weights 1 and w. Budget 2 covers the root group at full
 * resolution (cost 2), so X = 2; C_root = 1 + w. L / (theta C_root
 * sqrt(X / 2)) = (sqrt(2) sqrt(1 + w^2) / (1 + w) - 1) / theta:
 *   w = 1.30: sqrt(2.69) = 1.640122, * 1.414214 / 2.3 = 1.008469 -> 0.847
 *   w = 1.35: sqrt(2.8225) = 1.680030, * 1.414214 / 2.35 = 1.011031 -> 1.103
 * with theta = 0.01: the first pair stays one variable, the second splits. */
static void a_pair_splits_once_its_spread_outweighs_the_threshold(void **state) {
    static const double weights[2] = {1.30, 1.35};
    static const uint32_t expected[2] = {1, 2};
    int k;
    (void)state;
    for (k = 0; k < 2; ++k) {
        helper_fixture *f;
        tclod_selector *sel;
        tclod_stats st;
        assert_int_equal(helper_fixture_setup((void **)&f), 0);
        add_object(f, 0.0f, 0.0f, 0.0f, 0.1f, 1.0);
        add_object(f, 1.0f, 0.0f, 0.0f, 0.1f, weights[k]);
        sel = split_selector(f, 1, 0.01);
        select_view(sel, NULL, 2.0, &st);
        assert_int_equal(st.variables, expected[k]);
        tclod_selector_destroy(sel);
        helper_fixture_teardown((void **)&f);
    }
}

/* One object of weight 10 and three of weight 1 in a 2 x 2 grid: L =
 * sqrt(X) (sqrt(100 + 3) - 13 / 2) = 3.65 sqrt(X) against 0.01 * 13 *
 * sqrt(X / 4) = 0.065 sqrt(X): the group splits into its four objects. */
static void a_dominant_object_splits_its_group(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    int i;
    for (i = 0; i < 4; ++i)
        add_object(f, (float)(i % 2), 0.0f, (float)(i / 2), 0.1f, i == 0 ? 10.0 : 1.0);
    sel = split_selector(f, 1, 0.01);
    select_view(sel, NULL, 1.0, &st);
    assert_int_equal(st.variables, 4);
    tclod_selector_destroy(sel);
}

/* The sixteen objects of a 4 x 4 grid; each 2 x 2 block (a quadrant of the
 * root) holds one object of weight 1 and three of 0.01. Every child of the
 * root looks alike (C_i = 1.03, n_i = 4), but the objects inside do not: at
 * the root Q = 4 (1 + 3 * 10^-4) = 4.0012, C = 4.12, n = 16, so L = sqrt(X)
 * (2.000300 - 1.03) > 0, and in each block L = sqrt(X_i) (1.000150 - 0.515)
 * > 0. With theta = 0 no loss is allowed: every object gets a variable of its
 * own. Budget 4, costs r: the optimum gives r_j = X c_j^2 / Q (all below 1),
 * 0.999700 and 0.0000999700, benefit sqrt(X Q) = sqrt(16.0048) = 4.000600;
 * one shared variable (r = 1/4) would give 4.12 / 2 = 2.06. */
static void theta_zero_splits_down_to_objects_unlike_inside_alike_blocks(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    uint32_t i, j;
    for (i = 0; i < 4; ++i)
        for (j = 0; j < 4; ++j)
            add_object(f, (float)i, 0.0f, (float)j, 0.1f, i % 2 == 0 && j % 2 == 0 ? 1.0 : 0.01);
    sel = split_selector(f, 1, 0.0);
    select_view(sel, NULL, 4.0, &st);
    assert_int_equal(st.variables, 16);
    if (!(fabs(st.benefit - 4.000600) <= 1e-6))
        fail_msg("benefit %.9g, the optimum 4.000600", st.benefit);
    assert_true(st.cost <= 4.0);
    tclod_selector_destroy(sel);
}

/* A 4 x 4 grid whose 2 x 2 blocks hold alike objects, of weights 1, 2, 3, 4
 * by block. At the root Q = 4 (1 + 4 + 9 + 16) = 120, C = 40, n = 16; budget
 * 8 of the 16 everything costs: X = 8. L = sqrt(8) (sqrt(120) - 10) =
 * 2.699601 against theta * 40 * sqrt(8 / 16) = 28.284271 theta: the root
 * stays one variable from theta = 0.0954451 on. Below, it splits into its
 * four blocks, each of alike objects (L = 0), one variable each. */
static void alike_blocks_share_a_variable_while_their_spread_is_within_theta(void **state) {
    static const double thetas[2] = {0.0954, 0.0955};
    static const uint32_t expected[2] = {4, 1};
    int k;
    (void)state;
    for (k = 0; k < 2; ++k) {
        helper_fixture *f;
        tclod_selector *sel;
        tclod_stats st;
        uint32_t i, j;
        assert_int_equal(helper_fixture_setup((void **)&f), 0);
        for (i = 0; i < 4; ++i)
            for (j = 0; j < 4; ++j)
                add_object(f, (float)i, 0.0f, (float)j, 0.1f, 1.0 + (double)(i / 2 + 2 * (j / 2)));
        sel = split_selector(f, 1, thetas[k]);
        select_view(sel, NULL, 8.0, &st);
        assert_int_equal(st.variables, expected[k]);
        tclod_selector_destroy(sel);
        helper_fixture_teardown((void **)&f);
    }
}

/* Three objects in front of the reference view (z = -10) and one behind it
 * (z = +10), all of weight 1, splitting with theta = 10 (any spread would be
 * allowed). The quadtree's cell is the square of side 20 from (-1, -10), so
 * the root has two quadrants: the three in front, and the one behind, which
 * is culled. The root holds it, so it must not become a group (the culled
 * object would be drawn and paid for): it splits, the three in front are one
 * group (alike, all visible) and the object behind gets nothing. Budget 1.5,
 * costs r: the three visible objects at r = 0.5 each (1.5 in all), the one
 * behind at 0. */
static void a_group_never_holds_a_culled_object(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = add_object(f, -1.0f, 0.0f, -10.0f, 0.5f, 1.0);
    tclod_id b = add_object(f, 0.0f, 0.0f, -10.0f, 0.5f, 1.0);
    tclod_id c = add_object(f, 1.0f, 0.0f, -10.0f, 0.5f, 1.0);
    tclod_id behind = add_object(f, 0.0f, 0.0f, 10.0f, 0.5f, 1.0);
    tclod_selector *sel = split_selector(f, 1, 10.0);
    const tclod_smooth_group *groups;
    tclod_view view;
    tclod_stats st;
    size_t n, i;
    helper_view(&view);
    select_view(sel, &view, 1.5, &st);
    assert_int_equal(st.variables, 1);
    assert_true(tclod_selector_resolution(sel, behind) == 0.0);
    assert_true(fabs(tclod_selector_resolution(sel, a) - 0.5) < 1e-6);
    assert_true(fabs(tclod_selector_resolution(sel, b) - 0.5) < 1e-6);
    assert_true(fabs(tclod_selector_resolution(sel, c) - 0.5) < 1e-6);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    for (i = 0; i < n; ++i) {
        uint32_t p;
        for (p = groups[i].first; p < groups[i].first + groups[i].count; ++p)
            assert_true(p != position_of(f, behind));
    }
    assert_true(fabs(st.cost - 1.5) < 1e-6);
    tclod_selector_destroy(sel);
}

/* A child's expected resolution is at most its object count; what it cannot
 * take goes to its siblings. D (weight 10) alone in one quadrant, the pair G
 * (weights 1 and 2) in another; budget 2.4 of the 3 everything costs: X =
 * 2.4, theta = 0.015. The root splits: L = sqrt(2.4) (sqrt(105) - 13 /
 * sqrt(3)) = 4.246954 > 0.015 * 13 * sqrt(0.8) = 0.174413. By C_i^2 / n_i
 * (100 and 4.5), D would get 2.296651 > 1: it takes 1, and G the other 1.4
 * (without the hand-over 0.103349). G's loss sqrt(1.4) (sqrt(5) - 3 /
 * sqrt(2)) = 0.135771 is above its share 0.174413 / 2 = 0.087207, so G splits
 * too (at X = 0.103349 it would have been 0.036889, within it): three
 * variables. */
static void a_capped_child_hands_its_excess_resolution_to_the_others(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    add_object(f, 0.0f, 0.0f, 0.0f, 0.1f, 10.0);
    add_object(f, 10.0f, 0.0f, 0.0f, 0.1f, 1.0);
    add_object(f, 10.0f, 0.0f, 1.0f, 0.1f, 2.0);
    sel = split_selector(f, 1, 0.015);
    select_view(sel, NULL, 2.4, &st);
    assert_int_equal(st.variables, 3);
    tclod_selector_destroy(sel);
}

/* ---- splitting against one variable per object ------------------------------------ */

/* 64 objects on an 8 x 8 grid whose weights vary smoothly, as screen sizes do
 * across a view. Splitting with theta = 0.05 uses fewer variables than one per
 * object and loses at most theta of the benefit the unsplit solve reaches,
 * counted object by object. */
static void splitting_keeps_the_benefit_within_the_threshold(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *flat, *split;
    tclod_stats st_flat, st_split;
    double b_flat = 0.0, b_split = 0.0;
    tclod_id i;
    for (i = 0; i < 64; ++i) {
        double x = (double)(i % 8), z = (double)(i / 8);
        add_object(f, (float)x, 0.0f, (float)z, 0.1f, 1.0 + 0.02 * x * x + 0.01 * z);
    }
    flat = split_selector(f, 0, 0.0);
    split = split_selector(f, 1, 0.05);
    select_view(flat, NULL, 16.0, &st_flat);
    select_view(split, NULL, 16.0, &st_split);
    for (i = 0; i < 64; ++i) {
        b_flat += table_smooth_benefit_of(&f->model, i, tclod_selector_resolution(flat, i), NULL);
        b_split += table_smooth_benefit_of(&f->model, i, tclod_selector_resolution(split, i), NULL);
    }
    assert_int_equal(st_flat.variables, 64);
    assert_true(st_split.variables < 64);
    if (!(b_split >= b_flat * (1.0 - 0.05)))
        fail_msg("split benefit %.9g, flat %.9g", b_split, b_flat);
    assert_true(st_split.cost <= 16.0);
    tclod_selector_destroy(flat);
    tclod_selector_destroy(split);
}

/* Positions belong to the quadtree the result was made with: after the scene
 * changes, lookups say 0 until the next selection. */
static void resolutions_read_zero_after_the_scene_changed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = add_object(f, 0.0f, 0.0f, 0.0f, 0.1f, 1.0), b;
    tclod_selector *sel = split_selector(f, 0, 0.0);
    tclod_stats st;
    select_view(sel, NULL, 0.5, &st);
    assert_true(fabs(tclod_selector_resolution(sel, a) - 0.5) < 1e-6);
    b = add_object(f, 1.0f, 0.0f, 0.0f, 0.1f, 1.0);
    assert_true(tclod_selector_resolution(sel, a) == 0.0);
    assert_true(tclod_selector_resolution(sel, b) == 0.0);
    select_view(sel, NULL, 0.5, &st);
    assert_true(fabs(tclod_selector_resolution(sel, a) - 0.25) < 1e-6);
    assert_true(fabs(tclod_selector_resolution(sel, b) - 0.25) < 1e-6);
    tclod_selector_destroy(sel);
}

#define FIXTURE_TEST(t) \
    cmocka_unit_test_setup_teardown(t, helper_fixture_setup, helper_fixture_teardown)

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(quadtree_order_keeps_each_quadrant_contiguous),
        FIXTURE_TEST(objects_outside_the_frustum_get_no_variable),
        FIXTURE_TEST(objects_below_the_small_detail_area_get_no_variable),
        FIXTURE_TEST(alike_objects_share_one_variable),
        cmocka_unit_test(a_pair_splits_once_its_spread_outweighs_the_threshold),
        FIXTURE_TEST(a_dominant_object_splits_its_group),
        FIXTURE_TEST(theta_zero_splits_down_to_objects_unlike_inside_alike_blocks),
        cmocka_unit_test(alike_blocks_share_a_variable_while_their_spread_is_within_theta),
        FIXTURE_TEST(a_group_never_holds_a_culled_object),
        FIXTURE_TEST(a_capped_child_hands_its_excess_resolution_to_the_others),
        FIXTURE_TEST(splitting_keeps_the_benefit_within_the_threshold),
        FIXTURE_TEST(resolutions_read_zero_after_the_scene_changed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
