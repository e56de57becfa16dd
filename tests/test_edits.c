/*
 * test_edits — a scene changed between frames (docs/scenes.md): nodes and
 * smooth objects removed and moved, the rule by which removed ids are given
 * again, bad edits refused without a change, and warm starts that survive the
 * edits with work in proportion to the selection and the edits.
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

#define FIXTURE_TEST(f) \
    cmocka_unit_test_setup_teardown(f, helper_fixture_setup, helper_fixture_teardown)

static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                        TCLOD_SOLVER_ROBIN_HOOD};

static tclod_selector *solver_selector(const tclod_scene *s, table_model *m, tclod_solver solver) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    d.solver = solver;
    table_mixed_callbacks(m, &d.callbacks);
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

static tclod_stats select_at(tclod_selector *sel, double budget) {
    tclod_frame f = helper_frame(NULL, budget);
    tclod_stats st;
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    return st;
}

/* Asserts that every id of the current result is a live node. */
static void assert_result_live(const tclod_selector *sel, const tclod_scene *s) {
    const tclod_id *ids = NULL;
    size_t n = 0, i;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (i = 0; i < n; ++i)
        if (!tclod_scene_node_live(s, ids[i]))
            fail_msg("removed node %u in a result", (unsigned)ids[i]);
}

/* ---- removals and moves ------------------------------------------------------ */

/* Roots A (1, 1) and B (1, 1); A's children A1, A2 (2, 1 each); A1's child
 * A11 (3, 1). Unlimited budget: {A11, A2, B}. Removing A1 takes A11 with it:
 * {A2, B} (A stays refined, its one child left drawn), live flags say so, and
 * no later result of any solver names A1 or A11. Removing A too leaves {B}. */
static void removing_a_node_removes_its_subtree_from_every_later_result(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_id b = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_id a1 = helper_add(f, a, 2.0, 1.0);
    tclod_id a2 = helper_add(f, a, 2.0, 1.0);
    tclod_id a11 = helper_add(f, a1, 3.0, 1.0);
    const tclod_id all[] = {a11, a2, b}, left[] = {a2, b}, only_b[] = {b};
    tclod_selector *sel[3];
    int k;
    for (k = 0; k < 3; ++k) {
        sel[k] = solver_selector(f->scene, &f->model, solvers[k]);
        select_at(sel[k], INFINITY);
        helper_assert_cut(sel[k], all, 3);
    }
    assert_int_equal(table_remove_node(&f->model, f->scene, a1), TCLOD_OK);
    assert_false(tclod_scene_node_live(f->scene, a1));
    assert_false(tclod_scene_node_live(f->scene, a11));
    assert_true(tclod_scene_node_live(f->scene, a2));
    assert_int_equal(tclod_scene_parent(f->scene, a11), TCLOD_NONE);
    for (k = 0; k < 3; ++k) {
        tclod_stats st = select_at(sel[k], INFINITY);
        helper_assert_cut(sel[k], left, 2);
        helper_check_result(sel[k], &f->model, &st, INFINITY, 0);
        assert_result_live(sel[k], f->scene);
    }
    assert_int_equal(table_remove_node(&f->model, f->scene, a), TCLOD_OK);
    for (k = 0; k < 3; ++k) {
        select_at(sel[k], INFINITY);
        helper_assert_cut(sel[k], only_b, 1);
        tclod_selector_destroy(sel[k]);
    }
}

/* A node moved: its next query carries the new bounds. A sphere of radius 1
 * at distance 10 straight ahead projects to pi 500² / 99 px² and lies 9 away;
 * moved to distance 5, pi 500² / 24 and 4. */
typedef struct seen {
    float area, distance;
    tclod_bounds bounds;
} seen;

static double seen_benefit(void *user, const tclod_query *q) {
    seen *s = (seen *)user;
    s->area = q->screen_area;
    s->distance = q->distance;
    if (q->bounds)
        s->bounds = *q->bounds;
    return 1.0;
}

static double seen_cost(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static void a_moved_node_is_measured_where_it_went(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float ahead[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    tclod_bounds nearer = tclod_bounds_sphere(0.0, 0.0, -5.0, 1.0);
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_view v;
    tclod_frame fr;
    seen s;
    tclod_id id;
    helper_view(&v);
    fr = helper_frame(&v, 10.0);
    assert_int_equal(tclod_scene_add_node(f->scene, TCLOD_NONE, ahead, &id), TCLOD_OK);
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = seen_benefit;
    d.callbacks.cost = seen_cost;
    d.callbacks.user = &s;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, NULL), TCLOD_OK);
    assert_float_equal(s.area, 3.14159265358979 * 250000.0 / 99.0, 0.05);
    assert_float_equal(s.distance, 9.0, 1e-5);
    assert_int_equal(tclod_scene_set_node_bounds(f->scene, id, &nearer), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, NULL), TCLOD_OK);
    assert_float_equal(s.area, 3.14159265358979 * 250000.0 / 24.0, 0.1);
    assert_float_equal(s.distance, 4.0, 1e-5);
    assert_true(s.bounds.kind == TCLOD_BOUNDS_SPHERE && s.bounds.center[2] == -5.0);
    tclod_selector_destroy(sel);
}

/* ---- smooth objects ------------------------------------------------------------- */

/* Four smooth objects on a line; w 1, sqrt benefit, linear cost. */
static void add_smooth_line(table_model *m, tclod_scene *s, const float *x, int n) {
    int i;
    for (i = 0; i < n; ++i) {
        const float b[4] = {x[i], 0.0f, 0.0f, 1.0f};
        assert_int_equal(table_add_smooth(m, s, b, TABLE_POWER, 1.0 + i, 0.5, 1.0, 1.0, 0.0, NULL),
                         TCLOD_OK);
    }
}

/* Smooth object 1 of four removed: it leaves the smooth order, its
 * resolution is 0, no group holds it, and the selection over the other three
 * is the one a scene built without it makes (same objects in the same
 * quadtree order). */
static void a_removed_smooth_object_leaves_groups_and_resolutions(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float x[4] = {0.0f, 100.0f, 200.0f, 300.0f};
    const float x3[3] = {0.0f, 200.0f, 300.0f};
    helper_fixture *g;
    void *gs;
    tclod_selector *a, *b;
    tclod_stats sa, sb;
    const tclod_id *order;
    const tclod_smooth_group *groups;
    uint32_t count, i;
    size_t ng, k;
    int solver;
    add_smooth_line(&f->model, f->scene, x, 4);
    assert_int_equal(helper_fixture_setup(&gs), 0);
    g = (helper_fixture *)gs;
    /* the same objects without object 1: weights 1, 3, 4 */
    for (i = 0; i < 3; ++i) {
        const float bb[4] = {x3[i], 0.0f, 0.0f, 1.0f};
        assert_int_equal(table_add_smooth(&g->model, g->scene, bb, TABLE_POWER,
                                          i == 0 ? 1.0 : 2.0 + i, 0.5, 1.0, 1.0, 0.0, NULL),
                         TCLOD_OK);
    }
    assert_int_equal(tclod_scene_remove_smooth(f->scene, 1), TCLOD_OK);
    assert_false(tclod_scene_smooth_live(f->scene, 1));
    assert_int_equal(tclod_scene_remove_smooth(f->scene, 1), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &count), TCLOD_OK);
    assert_int_equal(count, 3);
    for (i = 0; i < count; ++i)
        assert_int_not_equal(order[i], 1);
    for (solver = 1; solver < 3; ++solver) {
        a = solver_selector(f->scene, &f->model, solvers[solver]);
        b = solver_selector(g->scene, &g->model, solvers[solver]);
        sa = select_at(a, 2.0);
        sb = select_at(b, 2.0);
        assert_true(fabs(sa.benefit - sb.benefit) <= 1e-12 * sb.benefit);
        assert_true(sa.cost <= 2.0);
        assert_true(tclod_selector_resolution(a, 1) == 0.0);
        assert_true(tclod_selector_resolution(a, 0) > 0.0);
        assert_int_equal(tclod_selector_smooth_groups(a, &groups, &ng), TCLOD_OK);
        for (k = 0; k < ng; ++k)
            for (i = groups[k].first; i < groups[k].first + groups[k].count; ++i)
                assert_int_not_equal(order[i], 1);
        tclod_selector_destroy(a);
        tclod_selector_destroy(b);
    }
    helper_fixture_teardown(&gs);
}

/* Object 3 moved from x = 300 next to object 0 (x = 1): the quadtree puts the
 * two side by side in the smooth order, and the mixed solver with variable
 * splitting selects bit for bit what it selects on a scene built with the
 * object there from the start. */
static void a_moved_smooth_object_changes_quadtree_cell(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float x[4] = {0.0f, 100.0f, 200.0f, 300.0f};
    const float moved_x[4] = {0.0f, 100.0f, 200.0f, 1.0f};
    const float moved[4] = {1.0f, 0.0f, 0.0f, 1.0f};
    helper_fixture *g;
    void *gs;
    const tclod_id *order, *order_g;
    uint32_t count, count_g, i, pos0 = 0, pos3 = 0;
    tclod_selector_desc d;
    tclod_selector *a, *b;
    tclod_view v;
    tclod_frame fr;
    tclod_stats sa, sb;
    const tclod_smooth_group *ga, *gb;
    size_t na, nb;
    add_smooth_line(&f->model, f->scene, x, 4);
    assert_int_equal(helper_fixture_setup(&gs), 0);
    g = (helper_fixture *)gs;
    add_smooth_line(&g->model, g->scene, moved_x, 4);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &count), TCLOD_OK);
    assert_int_equal(order[3], 3); /* at the far end */
    assert_int_equal(tclod_scene_set_smooth_bounds(f->scene, 3, moved), TCLOD_OK);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &count), TCLOD_OK);
    assert_int_equal(tclod_scene_smooth_order(g->scene, &order_g, &count_g), TCLOD_OK);
    assert_int_equal(count, count_g);
    assert_memory_equal(order, order_g, sizeof *order * count);
    for (i = 0; i < count; ++i) {
        if (order[i] == 0)
            pos0 = i;
        if (order[i] == 3)
            pos3 = i;
    }
    assert_int_equal(pos0 > pos3 ? pos0 - pos3 : pos3 - pos0, 1);
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    d.mixed.split_smooth = 1;
    d.mixed.split_threshold = 1.0;
    d.smooth_cull_area = TCLOD_OFF;
    table_mixed_callbacks(&f->model, &d.callbacks);
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &a), TCLOD_OK);
    table_mixed_callbacks(&g->model, &d.callbacks);
    assert_int_equal(tclod_selector_create(g->scene, &d, NULL, &b), TCLOD_OK);
    helper_view(&v);
    v.eye[0] = 150.0;
    v.eye[1] = 400.0;
    v.forward[1] = -1.0f;
    v.forward[2] = 0.0f;
    v.up[1] = 0.0f;
    v.up[2] = -1.0f;
    v.far_z = 1000.0f;
    fr = helper_frame(&v, 1.5);
    assert_int_equal(tclod_select(a, &fr, &sa), TCLOD_OK);
    assert_int_equal(tclod_select(b, &fr, &sb), TCLOD_OK);
    assert_true(sa.benefit == sb.benefit && sa.cost == sb.cost && sa.cost <= 1.5);
    assert_int_equal(tclod_selector_smooth_groups(a, &ga, &na), TCLOD_OK);
    assert_int_equal(tclod_selector_smooth_groups(b, &gb, &nb), TCLOD_OK);
    assert_int_equal(na, nb);
    assert_memory_equal(ga, gb, sizeof *ga * na);
    tclod_selector_destroy(a);
    tclod_selector_destroy(b);
    helper_fixture_teardown(&gs);
}

/* ---- ids -------------------------------------------------------------------------- */

/* Four roots; selectors A and B over them, and a scheduler. Node 2 is
 * removed. Its id is not given again until A, B and the scheduler have each
 * begun a solve since the removal: until then new nodes take fresh ids, so
 * that no result a host can still read names an old node under a new one's
 * id. A selector that never solved holds no id and does not hold the id
 * back. */
static double one(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static void a_removed_id_is_given_again_only_after_every_user_solved(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *a, *b, *idle;
    tclod_scheduler *sch;
    tclod_scheduler_desc sd;
    tclod_selector_desc d;
    tclod_view v;
    tclod_id id;
    uint32_t i;
    for (i = 0; i < 4; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1.0);
    a = helper_selector(f->scene, &f->model, 1);
    b = helper_selector(f->scene, &f->model, 1);
    idle = helper_selector(f->scene, &f->model, 1);
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = one;
    d.callbacks.cost = one;
    tclod_scheduler_desc_default(&sd);
    assert_int_equal(tclod_scheduler_create(f->scene, &d, &sd, NULL, &sch), TCLOD_OK);
    helper_view(&v);
    select_at(a, INFINITY);
    select_at(b, INFINITY);
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 10.0, 0.0), TCLOD_OK);
    assert_int_equal(table_remove_node(&f->model, f->scene, 2), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, NULL, 1.0, 1.0, &id),
                     TCLOD_OK);
    assert_int_equal(id, 4); /* A, B and the scheduler still show node 2 */
    select_at(a, INFINITY);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, NULL, 1.0, 1.0, &id),
                     TCLOD_OK);
    assert_int_equal(id, 5); /* B and the scheduler still do */
    select_at(b, INFINITY);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, NULL, 1.0, 1.0, &id),
                     TCLOD_OK);
    assert_int_equal(id, 6); /* the scheduler still does */
    /* the scheduler's next update drops node 2 from its draw list and begins
     * its selection again, which (with no time limit) it runs to its end */
    assert_int_equal(tclod_scheduler_update(sch, 0.1, &v, 10.0, 0.0), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, NULL, 1.0, 1.0, &id),
                     TCLOD_OK);
    assert_int_equal(id, 2); /* every user solved since: node 2 is gone from all */
    assert_int_equal(tclod_scene_node_count(f->scene), 7);
    tclod_scheduler_destroy(sch);
    tclod_selector_destroy(idle);
    tclod_selector_destroy(a);
    tclod_selector_destroy(b);
}

/* ---- bad edits -------------------------------------------------------------------- */

/* Every bad edit is refused and changes nothing: removing twice, an unknown
 * id, the id an additive node keeps for itself; moving a removed node;
 * adding below a removed parent; NaN, infinite, negative or skewed bounds. */
static void bad_edits_are_refused_and_change_nothing(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const double c[3] = {0.0, 0.0, 0.0}, skew[9] = {1, 0, 0, 1, 1, 0, 0, 0, 1};
    const double bad_half[3] = {1.0, NAN, 1.0};
    const float nan_sphere[4] = {0.0f, NAN, 0.0f, 1.0f};
    const float sphere[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tclod_bounds good = tclod_bounds_sphere(1.0, 2.0, 3.0, 4.0), got;
    tclod_bounds bad[4];
    tclod_node_desc d;
    tclod_id r = helper_add(f, TCLOD_NONE, 1.0, 1.0), gone = helper_add(f, r, 1.0, 1.0), add, s;
    uint32_t count, k;
    bad[0] = tclod_bounds_aabb(c, bad_half);
    bad[1] = tclod_bounds_obb(c, skew);
    bad[2] = tclod_bounds_sphere(0.0, 0.0, INFINITY, 1.0);
    bad[3] = tclod_bounds_sphere(0.0, 0.0, 0.0, -1.0);
    tclod_node_desc_default(&d);
    d.refine = TCLOD_REFINE_ADD;
    assert_int_equal(tclod_scene_add_node_desc(f->scene, &d, &add), TCLOD_OK);
    assert_int_equal(tclod_scene_set_node_bounds(f->scene, r, &good), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(f->scene, sphere, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_remove_node(f->scene, gone), TCLOD_OK);
    count = tclod_scene_node_count(f->scene);
    /* removing */
    assert_int_equal(tclod_scene_remove_node(f->scene, gone), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_remove_node(f->scene, count), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_remove_node(f->scene, TCLOD_NONE), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_remove_node(f->scene, add + 1u), TCLOD_ERR_ARG); /* its own */
    assert_int_equal(tclod_scene_remove_node(NULL, r), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_remove_smooth(f->scene, s + 1u), TCLOD_ERR_ARG);
    /* moving */
    assert_int_equal(tclod_scene_set_node_bounds(f->scene, gone, &good), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_set_node_bounds(f->scene, add + 1u, &good), TCLOD_ERR_ARG);
    for (k = 0; k < 4; ++k) {
        assert_int_equal(tclod_scene_set_node_bounds(f->scene, r, &bad[k]), TCLOD_ERR_ARG);
        d.bounds = bad[k];
        assert_int_equal(tclod_scene_add_node_desc(f->scene, &d, &add), TCLOD_ERR_ARG);
    }
    assert_int_equal(tclod_scene_set_smooth_bounds(f->scene, s, nan_sphere), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_set_smooth_bounds(f->scene, s + 1u, sphere), TCLOD_ERR_ARG);
    /* adding below a removed parent */
    assert_int_equal(tclod_scene_add_node(f->scene, gone, NULL, &add), TCLOD_ERR_HIERARCHY);
    d.bounds.kind = TCLOD_BOUNDS_NONE;
    d.parent = gone;
    assert_int_equal(tclod_scene_add_node_desc(f->scene, &d, &add), TCLOD_ERR_HIERARCHY);
    d.parent = TCLOD_NONE;
    d.refine = (tclod_refine)2;
    assert_int_equal(tclod_scene_add_node_desc(f->scene, &d, &add), TCLOD_ERR_ARG);
    d.refine = TCLOD_REFINE_REPLACE;
    d.empty = 2;
    assert_int_equal(tclod_scene_add_node_desc(f->scene, &d, &add), TCLOD_ERR_ARG);
    /* nothing changed */
    assert_int_equal(tclod_scene_node_count(f->scene), count);
    assert_true(tclod_scene_node_live(f->scene, r));
    assert_int_equal(tclod_scene_node_bounds(f->scene, r, &got), TCLOD_OK);
    assert_memory_equal(&got, &good, sizeof got);
    assert_int_equal(tclod_scene_node_bounds(f->scene, gone, &got), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_smooth_count(f->scene), 1);
    assert_true(tclod_scene_smooth_live(f->scene, s));
}

/* ---- warm starts after edits ---------------------------------------------------- */

/* Roots 0 (1, 1) and 1 (2, 1); root 0 refined into 2 (3, 1) and 3 (3, 1).
 * Unlimited budget: {2, 3, 1}. A child 4 (4, 1) added to root 0, which the
 * warm cut refined, joins at once: {2, 3, 4, 1}. Node 3 removed: {2, 4, 1}.
 * Node 2 and 4 removed: root 0 has no child left and is drawn again:
 * {0, 1}. */
static void
a_warm_start_takes_added_children_of_a_refined_node_and_drops_removed_ones(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id first[] = {1, 2, 3}, grown[] = {1, 2, 3, 4}, shrunk[] = {1, 2, 4},
                          back[] = {0, 1};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 2.0, 1.0);
    helper_add(f, 0, 3.0, 1.0);
    helper_add(f, 0, 3.0, 1.0);
    sel = helper_selector(f->scene, &f->model, 1);
    st = select_at(sel, INFINITY);
    helper_assert_cut(sel, first, 3);
    helper_add(f, 0, 4.0, 1.0);
    table_reset_counts(&f->model);
    st = select_at(sel, INFINITY);
    helper_assert_cut(sel, grown, 4);
    assert_true(st.benefit == 12.0 && st.cost == 4.0);
    assert_int_equal(table_remove_node(&f->model, f->scene, 3), TCLOD_OK);
    st = select_at(sel, INFINITY);
    helper_assert_cut(sel, shrunk, 3);
    assert_int_equal(table_remove_node(&f->model, f->scene, 2), TCLOD_OK);
    assert_int_equal(table_remove_node(&f->model, f->scene, 4), TCLOD_OK);
    st = select_at(sel, INFINITY);
    helper_assert_cut(sel, back, 2);
    assert_true(st.benefit == 3.0 && st.cost == 2.0);
    tclod_selector_destroy(sel);
}

/* Objects of 16 levels (table_chains: diminishing returns) and a budget that
 * refines them part of the way. Every frame removes 3 objects, adds 3 and
 * moves 6 nodes (k = 12 edits), then selects warm: the warm solve asks the
 * callbacks of no more nodes than three per node of the previous cut and of
 * each edited object's levels (its frontier: a cut node, its child and its
 * parent), a quarter of the scene at most, its result names no removed node,
 * and its benefit is within 0.1 % of a cold solve's on the edited scene. */
static void warm_starts_survive_edits_with_work_in_proportion(void **state) {
    enum { objects = 400, levels = 16, frames = 40, removes = 3, adds = 3, moves = 6 };
    enum { MAX_IDS = (objects + adds * frames) * levels };
    static unsigned char listed[MAX_IDS];
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *warm, *cold;
    tclod_selector_desc d;
    table_rng rng;
    tclod_id roots[objects + adds * frames];
    uint32_t root_count = 0, frame, i, most = 0;
    double budget, worst = HUGE_VAL;
    table_rng_seed(&rng, 12345u);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, objects, levels, 50.0f), TCLOD_OK);
    memset(listed, 0, sizeof listed);
    for (i = 0; i < f->model.count; ++i)
        if (f->model.parent[i] == TCLOD_NONE) {
            listed[i] = 1;
            roots[root_count++] = i;
        }
    budget = table_roots_cost(&f->model) * 6.0;
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    d.greedy.fallback = TCLOD_OFF; /* every solve warm: no audit adds a cold one's work */
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &warm), TCLOD_OK);
    d.greedy.fallback = 0;
    d.cold_start = 1;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &cold), TCLOD_OK);
    select_at(warm, budget);
    for (frame = 0; frame < frames; ++frame) {
        size_t before;
        const tclod_id *ids;
        tclod_stats ws, cs;
        uint32_t k;
        assert_int_equal(tclod_selector_cut(warm, &ids, &before), TCLOD_OK);
        for (k = 0; k < removes; ++k) {
            uint32_t at = table_rng_below(&rng, root_count);
            assert_int_equal(table_remove_node(&f->model, f->scene, roots[at]), TCLOD_OK);
            listed[roots[at]] = 0;
            roots[at] = roots[--root_count];
        }
        for (k = 0; k < adds; ++k) {
            tclod_id id = TCLOD_NONE;
            /* an object of `levels` levels: its root is the live root no list
             * holds yet (a fresh id, or one given again) */
            assert_int_equal(table_chains(&f->model, f->scene, &rng, 1, levels, 50.0f), TCLOD_OK);
            assert_true(f->model.count < MAX_IDS);
            for (i = 0; i < f->model.count && id == TCLOD_NONE; ++i)
                if (f->model.kind[i] != TABLE_NONE && f->model.parent[i] == TCLOD_NONE &&
                    !listed[i])
                    id = i;
            assert_true(id != TCLOD_NONE);
            listed[id] = 1;
            roots[root_count++] = id;
        }
        for (k = 0; k < moves; ++k) {
            tclod_id n = roots[table_rng_below(&rng, root_count)];
            tclod_bounds b = tclod_bounds_sphere(table_rng_uniform(&rng, -50.0, 50.0), 0.0,
                                                 table_rng_uniform(&rng, -50.0, 50.0), 1.0);
            assert_int_equal(tclod_scene_set_node_bounds(f->scene, n, &b), TCLOD_OK);
        }
        ws = select_at(warm, budget);
        cs = select_at(cold, budget);
        helper_check_result(warm, &f->model, &ws, budget, 0);
        assert_result_live(warm, f->scene);
        if (ws.benefit / cs.benefit < worst)
            worst = ws.benefit / cs.benefit;
        most = ws.evaluations > most ? ws.evaluations : most;
        if (ws.benefit < cs.benefit * (1.0 - 1e-3))
            fail_msg("frame %u: warm %.17g below cold %.17g by more than 0.1 %%", (unsigned)frame,
                     ws.benefit, cs.benefit);
        if (ws.evaluations > 3u * ((uint32_t)before + (removes + adds + moves) * levels) ||
            ws.evaluations * 4u > tclod_scene_node_count(f->scene))
            fail_msg("frame %u: warm solve evaluated %u nodes, with a cut of %u before it, "
                     "in a scene of %u",
                     (unsigned)frame, (unsigned)ws.evaluations, (unsigned)before,
                     (unsigned)tclod_scene_node_count(f->scene));
    }
    print_message("warm after edits: benefit at least %.6f of the cold solve's, at most %u "
                  "nodes evaluated of %u\n",
                  worst, (unsigned)most, (unsigned)tclod_scene_node_count(f->scene));
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

/* A warm start whose selector fell behind by more edits than the scene's
 * edit log holds (it keeps as many as the scene has room for nodes) brings
 * its cut up to date by looking at its whole selection: its result is the
 * same as that of a selector that saw every edit, and valid. */
static void a_warm_start_behind_a_full_edit_log_looks_at_its_selection(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *steady, *behind;
    tclod_stats a, b;
    uint32_t i;
    tclod_id keep = helper_add(f, TCLOD_NONE, 1.0, 1.0), child;
    helper_add(f, keep, 3.0, 1.0);
    helper_add(f, keep, 3.0, 1.0);
    steady = helper_selector(f->scene, &f->model, 1);
    behind = helper_selector(f->scene, &f->model, 1);
    select_at(steady, INFINITY);
    select_at(behind, INFINITY);
    /* far more edits than the 64 entries the log has room for */
    for (i = 0; i < 200; ++i) {
        child = helper_add(f, keep, 2.0, 1.0);
        select_at(steady, INFINITY);
        if (i % 2)
            assert_int_equal(table_remove_node(&f->model, f->scene, child), TCLOD_OK);
    }
    a = select_at(steady, INFINITY);
    b = select_at(behind, INFINITY);
    helper_check_result(behind, &f->model, &b, INFINITY, 0);
    assert_result_live(behind, f->scene);
    assert_true(a.benefit == b.benefit && a.cost == b.cost);
    assert_int_equal(a.benefit, 2.0 * 3.0 + 100.0 * 2.0);
    tclod_selector_destroy(steady);
    tclod_selector_destroy(behind);
}

/* A hierarchy built and cut back between two frames: after a select over an
 * empty scene, R (b 1, c 1), its child C (2, 1) and C's child G (3, 1) are
 * added and G removed. R's increment into C gains 1 for nothing, C has no
 * child left: budget 10 draws {C}, benefit 2, cost 1, C once, for every
 * solver, warm as cold. */
static void a_warm_start_after_a_subtree_came_and_went_takes_each_node_once(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    int k;
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k]);
        tclod_id r, c, g;
        tclod_stats st = select_at(sel, 10.0);
        assert_true(st.cost == 0.0);
        r = helper_add(f, TCLOD_NONE, 1.0, 1.0);
        c = helper_add(f, r, 2.0, 1.0);
        g = helper_add(f, c, 3.0, 1.0);
        assert_int_equal(table_remove_node(&f->model, f->scene, g), TCLOD_OK);
        st = select_at(sel, 10.0);
        helper_assert_cut(sel, &c, 1);
        assert_true(st.benefit == 2.0 && st.cost == 1.0);
        tclod_selector_destroy(sel);
        assert_int_equal(table_remove_node(&f->model, f->scene, r), TCLOD_OK);
    }
}

/* Random hierarchies of replace, additive and empty nodes edited at random
 * between frames (nodes added anywhere, subtrees removed, nodes moved): every
 * solver's warm selection stays a valid selection of the edited scene within
 * its budget, naming live nodes only. */
static void random_edits_keep_every_selection_valid(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel[3];
    table_rng rng;
    uint32_t frame, k;
    table_rng_seed(&rng, 99u);
    for (k = 0; k < 3; ++k)
        sel[k] = solver_selector(f->scene, &f->model, solvers[k]);
    for (frame = 0; frame < 400; ++frame) {
        uint32_t edits = 1 + table_rng_below(&rng, 4), e;
        double budget = table_rng_uniform(&rng, 1.0, 20.0);
        for (e = 0; e < edits; ++e) {
            uint32_t what = table_rng_below(&rng, 10), live = 0, i, pick;
            tclod_id target = TCLOD_NONE;
            for (i = 0; i < f->model.count; ++i)
                live += f->model.kind[i] != TABLE_NONE;
            if (live > 0) {
                pick = table_rng_below(&rng, live);
                for (i = 0; i < f->model.count; ++i)
                    if (f->model.kind[i] != TABLE_NONE && pick-- == 0u) {
                        target = i;
                        break;
                    }
            }
            if (what < 5 || live < 4) { /* add below target, or a root */
                tclod_node_desc d;
                uint32_t kind = table_rng_below(&rng, 8);
                tclod_node_desc_default(&d);
                d.parent = table_rng_below(&rng, 4) == 0 ? TCLOD_NONE : target;
                d.refine = kind < 2 ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
                d.empty = kind == 7;
                assert_int_equal(table_add_node_desc(&f->model, f->scene, &d,
                                                     table_rng_uniform(&rng, 0.5, 5.0),
                                                     table_rng_uniform(&rng, 0.2, 2.0), NULL),
                                 TCLOD_OK);
            } else if (what < 8) {
                assert_int_equal(table_remove_node(&f->model, f->scene, target), TCLOD_OK);
            } else {
                tclod_bounds b =
                    tclod_bounds_sphere(table_rng_uniform(&rng, -5.0, 5.0), 0.0, -10.0, 1.0);
                assert_int_equal(tclod_scene_set_node_bounds(f->scene, target, &b), TCLOD_OK);
            }
        }
        for (k = 0; k < 3; ++k) {
            tclod_frame fr = helper_frame(NULL, budget);
            const tclod_id *ids;
            size_t n;
            tclod_stats st;
            assert_int_equal(tclod_select(sel[k], &fr, &st), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[k], &ids, &n), TCLOD_OK);
            if (!exact_check_selection(&f->model, ids, n, 1))
                fail_msg("frame %u solver %u: not a selection of the edited scene", (unsigned)frame,
                         (unsigned)k);
            assert_true(table_sum_cost(&f->model, ids, n) <= budget);
            assert_true(st.cost == table_sum_cost(&f->model, ids, n));
            assert_result_live(sel[k], f->scene);
        }
    }
    for (k = 0; k < 3; ++k)
        tclod_selector_destroy(sel[k]);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(removing_a_node_removes_its_subtree_from_every_later_result),
        FIXTURE_TEST(a_moved_node_is_measured_where_it_went),
        FIXTURE_TEST(a_removed_smooth_object_leaves_groups_and_resolutions),
        FIXTURE_TEST(a_moved_smooth_object_changes_quadtree_cell),
        FIXTURE_TEST(a_removed_id_is_given_again_only_after_every_user_solved),
        FIXTURE_TEST(bad_edits_are_refused_and_change_nothing),
        FIXTURE_TEST(a_warm_start_takes_added_children_of_a_refined_node_and_drops_removed_ones),
        FIXTURE_TEST(warm_starts_survive_edits_with_work_in_proportion),
        FIXTURE_TEST(a_warm_start_behind_a_full_edit_log_looks_at_its_selection),
        FIXTURE_TEST(a_warm_start_after_a_subtree_came_and_went_takes_each_node_once),
        FIXTURE_TEST(random_edits_keep_every_selection_valid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
