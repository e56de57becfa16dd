/*
 * test_misuse — what a host gets wrong, diagnosed instead of punished
 * (docs/api.md, errors):
 *  - a zeroed desc is the defaults (sokol's convention): a selector desc with
 *    only the callbacks set works with every solver, and zeroed scheduler and
 *    calibration descs behave as their _default() fills;
 *  - destroying a scene that a selector or scheduler still reads is refused
 *    and frees nothing;
 *  - every refusal names the argument or field and the rule it broke: the
 *    exact message of each check of the descs, views and bounds
 *    (tclod_*_check), and of the scene, selector, scheduler and calibration
 *    calls (tclod_*_last_error);
 *  - a select that draws nothing, or ignores smooth objects, or had no view
 *    or bad values, says so in tclod_stats.notes; a budget of 0 stops for
 *    the budget, never "finest".
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"
#include "table_scene.h"

/* ---- zeroed descs ----------------------------------------------------------------- */

/* A root (benefit 1, cost 1) with two children (benefit 3 and 2, cost 2
 * each), all in a sphere 10 m ahead, and a smooth object beside them. */
static void small_world(helper_fixture *f) {
    const float b[4] = {0.0f, 0.0f, -10.0f, 1.0f}, sb[4] = {3.0f, 0.0f, -10.0f, 1.0f};
    tclod_id root;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, b, 1.0, 1.0, &root), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, root, b, 3.0, 2.0, NULL), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, root, b, 2.0, 2.0, NULL), TCLOD_OK);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, sb, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, NULL),
        TCLOD_OK);
}

static tclod_stats select_with(helper_fixture *f, const tclod_selector_desc *d, double budget,
                               tclod_id *cut, size_t *n) {
    tclod_selector *sel = NULL;
    tclod_view v;
    tclod_frame fr;
    tclod_stats st;
    helper_view(&v);
    fr = helper_frame(&v, budget);
    assert_int_equal(tclod_selector_create(f->scene, d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    *n = helper_sorted_cut(sel, cut, 8);
    tclod_selector_destroy(sel);
    return st;
}

static void a_zeroed_selector_desc_with_callbacks_is_the_default(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                           TCLOD_SOLVER_ROBIN_HOOD};
    size_t s;
    small_world(f);
    for (s = 0; s < 3; ++s) {
        tclod_selector_desc zero, def;
        tclod_id cut_zero[8], cut_def[8];
        size_t n_zero, n_def;
        tclod_stats a, b;
        memset(&zero, 0, sizeof zero);
        zero.solver = solvers[s];
        table_mixed_callbacks(&f->model, &zero.callbacks);
        assert_null(tclod_selector_desc_check(f->scene, &zero));
        tclod_selector_desc_default(&def);
        def.solver = solvers[s];
        def.callbacks = zero.callbacks;
        a = select_with(f, &zero, 5.0, cut_zero, &n_zero);
        b = select_with(f, &def, 5.0, cut_def, &n_def);
        assert_int_equal(n_zero, n_def);
        assert_memory_equal(cut_zero, cut_def, n_zero * sizeof cut_zero[0]);
        assert_true(a.benefit == b.benefit && a.cost == b.cost);
        if (solvers[s] == TCLOD_SOLVER_GREEDY) {
            /* budget 5: both children (cost 4, benefit 5) beat the root
             * (cost 1, benefit 1); the smooth object is the mixed solver's */
            assert_int_equal(n_zero, 2);
            assert_int_equal(cut_zero[0], 1);
            assert_int_equal(cut_zero[1], 2);
            assert_true(a.cost == 4.0 && a.benefit == 5.0);
        }
    }
}

static void zeroed_scheduler_and_calibration_descs_are_the_defaults(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc sd;
    tclod_scheduler_desc zero, def;
    tclod_calib_desc czero, cdef;
    tclod_calib *c0 = NULL, *c1 = NULL;
    tclod_scheduler *s0 = NULL, *s1 = NULL;
    tclod_view v;
    double b0, b1;
    int k;
    small_world(f);
    memset(&sd, 0, sizeof sd);
    table_callbacks(&f->model, &sd.callbacks);
    memset(&zero, 0, sizeof zero);
    tclod_scheduler_desc_default(&def);
    assert_null(tclod_scheduler_desc_check(&zero));
    assert_int_equal(tclod_scheduler_create(f->scene, &sd, &zero, NULL, &s0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_create(f->scene, &sd, &def, NULL, &s1), TCLOD_OK);
    helper_view(&v);
    for (k = 0; k < 40; ++k) {
        const tclod_draw *d0, *d1;
        size_t n0, n1;
        double t = k / 20.0;
        assert_int_equal(tclod_scheduler_update(s0, t, &v, 5.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(s1, t, &v, 5.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(s0, &d0, &n0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(s1, &d1, &n1), TCLOD_OK);
        assert_int_equal(n0, n1);
        assert_memory_equal(d0, d1, n0 * sizeof *d0);
        /* frames take 1.5 ms per unit: both calibrations follow alike */
        assert_int_equal(tclod_scheduler_report_frame(s0, 6.0, 2.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_report_frame(s1, 6.0, 2.0), TCLOD_OK);
    }
    assert_true(tclod_calib_scale(tclod_scheduler_calib(s0)) ==
                tclod_calib_scale(tclod_scheduler_calib(s1)));
    tclod_scheduler_destroy(s0);
    tclod_scheduler_destroy(s1);
    /* a calibration alone: rise 0.5 from the first measured ratio 2 towards
     * 4 gives 3, as the default rates say */
    memset(&czero, 0, sizeof czero);
    tclod_calib_desc_default(&cdef);
    assert_int_equal(tclod_calib_create(&czero, NULL, &c0), TCLOD_OK);
    assert_int_equal(tclod_calib_create(&cdef, NULL, &c1), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c0, 1.0, 2.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c0, 1.0, 4.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c1, 1.0, 2.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c1, 1.0, 4.0, 1.0), TCLOD_OK);
    assert_true(tclod_calib_scale(c0) == 3.0 && tclod_calib_scale(c1) == 3.0);
    assert_int_equal(tclod_calib_budget(c0, 20.0, &b0), TCLOD_OK);
    assert_int_equal(tclod_calib_budget(c1, 20.0, &b1), TCLOD_OK);
    assert_true(b0 == b1);
    tclod_calib_destroy(c0);
    tclod_calib_destroy(c1);
}

/* ---- destroying a scene in use ---------------------------------------------------- */

static void a_scene_in_use_is_not_destroyed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scene *s = NULL;
    tclod_id id;
    small_world(f);
    sel = helper_selector(f->scene, &f->model, 1);
    /* refused while the selector reads it; the scene still works */
    assert_int_equal(tclod_scene_destroy(f->scene), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_node_count(f->scene), 3);
    tclod_selector_destroy(sel);
    /* and while a scheduler does */
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &id), TCLOD_OK);
    memset(&sd, 0, sizeof sd);
    table_callbacks(&f->model, &sd.callbacks);
    memset(&d, 0, sizeof d);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    assert_int_equal(tclod_scene_destroy(s), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_add_node(s, id, NULL, &id), TCLOD_OK);
    tclod_scheduler_destroy(sch);
    assert_int_equal(tclod_scene_destroy(s), TCLOD_OK);
    assert_int_equal(tclod_scene_destroy(NULL), TCLOD_OK);
}

/* ---- every refusal names what was wrong ----------------------------------------- */

static double one(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static double nan_cost(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return (double)NAN;
}

static double smooth_one(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 1.0;
    return r;
}

static void expect_desc(const tclod_scene *s, const tclod_selector_desc *d, const char *message) {
    tclod_selector *sel = NULL;
    assert_string_equal(tclod_selector_desc_check(s, d), message);
    assert_int_equal(tclod_selector_create(s, d, NULL, &sel), TCLOD_ERR_ARG);
    assert_null(sel);
}

static void selector_descs_name_the_field_and_rule(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float sb[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    tclod_selector_desc good, d;
    tclod_id id;
    memset(&good, 0, sizeof good);
    good.callbacks.benefit = good.callbacks.cost = one;
    assert_null(tclod_selector_desc_check(f->scene, &good));
    assert_string_equal(tclod_selector_desc_check(f->scene, NULL), "desc is NULL");
#define BAD(field, value, message)          \
    do {                                    \
        d = good;                           \
        d.field = value;                    \
        expect_desc(f->scene, &d, message); \
    } while (0)
    BAD(solver, (tclod_solver)3, "desc.solver is not a tclod_solver");
    BAD(callbacks.benefit, NULL, "desc.callbacks.benefit is NULL");
    BAD(callbacks.cost, NULL, "desc.callbacks.cost and features are NULL: one of them prices the nodes");
    BAD(cold_start, 2, "desc.cold_start must be 0 or 1");
    BAD(strict, -1, "desc.strict must be 0 or 1");
    BAD(overflow, (tclod_overflow)2, "desc.overflow is not a tclod_overflow");
    BAD(smooth_cull_area, -0.5,
        "desc.smooth_cull_area must be finite and > 0, 0 (default) or TCLOD_OFF");
    BAD(greedy.lookahead, 64u, "desc.greedy.lookahead must be at most TCLOD_MAX_LOOKAHEAD (63)");
    BAD(greedy.restarts, 257,
        "desc.greedy.restarts must be 0 (default), TCLOD_OFF or 1 .. TCLOD_MAX_RESTARTS (256)");
    BAD(greedy.restarts, -2,
        "desc.greedy.restarts must be 0 (default), TCLOD_OFF or 1 .. TCLOD_MAX_RESTARTS (256)");
    BAD(mixed.split_smooth, 2, "desc.mixed.split_smooth must be 0 or 1");
    BAD(mixed.split_threshold, (double)INFINITY,
        "desc.mixed.split_threshold must be finite and > 0, 0 (default) or TCLOD_OFF");
    BAD(mixed.plain_gradient, 3, "desc.mixed.plain_gradient must be 0 or 1");
    BAD(mixed.smooth_epsilon, 1.0,
        "desc.mixed.smooth_epsilon must be in (0, 1), 0 (default) or TCLOD_OFF");
    BAD(mixed.smooth_tolerance, (double)NAN,
        "desc.mixed.smooth_tolerance must be in (0, 1), 0 (default) or TCLOD_OFF");
    BAD(robin_hood.value, (tclod_value)5, "desc.robin_hood.value is not a tclod_value");
    BAD(robin_hood.misfit, (tclod_misfit)2, "desc.robin_hood.misfit is not a tclod_misfit");
    BAD(robin_hood.reference_area, -1.0,
        "desc.robin_hood.reference_area must be finite and > 0, or 0 (default)");
#undef BAD
    /* the mixed solver without smooth callbacks: refused once the scene has
     * smooth objects, and checked only with a scene */
    d = good;
    d.solver = TCLOD_SOLVER_MIXED;
    assert_null(tclod_selector_desc_check(f->scene, &d));
    assert_int_equal(tclod_scene_add_smooth(f->scene, sb, &id), TCLOD_OK);
    expect_desc(f->scene, &d,
                "desc.callbacks.smooth_benefit and smooth_cost are NULL: the mixed solver needs "
                "both on a scene with smooth objects");
    assert_null(tclod_selector_desc_check(NULL, &d));
}

static void scheduler_and_calibration_descs_name_the_field_and_rule(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc sd;
    tclod_scheduler_desc good, d;
    tclod_calib_desc cgood, c;
    tclod_scheduler *sch = NULL;
    tclod_calib *cal = NULL;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    memset(&sd, 0, sizeof sd);
    sd.callbacks.benefit = sd.callbacks.cost = one;
    memset(&good, 0, sizeof good);
#define BAD(field, value, message)                                                              \
    do {                                                                                        \
        d = good;                                                                               \
        d.field = value;                                                                        \
        assert_string_equal(tclod_scheduler_desc_check(&d), message);                           \
        assert_int_equal(tclod_scheduler_create(f->scene, &sd, &d, NULL, &sch), TCLOD_ERR_ARG); \
        assert_null(sch);                                                                       \
    } while (0)
    BAD(tau, 1e-310, "desc.tau must be a normal number > 0 with 4 tau finite, or 0 (default)");
    BAD(samples, 9u, "desc.samples must be at most TCLOD_MAX_SAMPLES (8)");
    BAD(confidence, -3.0, "desc.confidence must be finite and > 0, 0 (default) or TCLOD_OFF");
    BAD(max_speed, (double)NAN, "desc.max_speed must be finite and >= 0");
    BAD(max_turn_rate, -1.0, "desc.max_turn_rate must be finite and >= 0");
    BAD(two_stage, 2, "desc.two_stage must be 0 or 1");
    BAD(calib.rise_rate, 1.5, "desc.calib.rise_rate must be in (0, 1], or 0 (default)");
#undef BAD
    memset(&cgood, 0, sizeof cgood);
#define BAD(field, value, message)                                           \
    do {                                                                     \
        c = cgood;                                                           \
        c.field = value;                                                     \
        assert_string_equal(tclod_calib_desc_check(&c), message);            \
        assert_int_equal(tclod_calib_create(&c, NULL, &cal), TCLOD_ERR_ARG); \
        assert_null(cal);                                                    \
    } while (0)
    BAD(initial_scale, -1.0, "desc.initial_scale must be finite and > 0, or 0 (default)");
    BAD(rise_rate, 2.0, "desc.rise_rate must be in (0, 1], or 0 (default)");
    BAD(fall_rate, -0.5, "desc.fall_rate must be in (0, 1], or 0 (default)");
    BAD(dead_band, 1.0, "desc.dead_band must be in (0, 1), 0 (default) or TCLOD_OFF");
    BAD(logic_rate, (double)NAN, "desc.logic_rate must be in (0, 1], or 0 (default)");
    BAD(initial_logic, -1.0, "desc.initial_logic must be finite and >= 0");
    BAD(machine_c, (double)INFINITY, "desc.machine_c must be finite and > 0, or 0 (default)");
    BAD(initial_measured, 2, "desc.initial_measured must be 0 or 1");
#undef BAD
    assert_string_equal(tclod_calib_desc_check(NULL), "desc is NULL");
    assert_string_equal(tclod_scheduler_desc_check(NULL), "desc is NULL");
}

static void views_and_bounds_name_the_field_and_rule(void **state) {
    tclod_view good, v;
    tclod_bounds b;
    const double c[3] = {0.0, 0.0, 0.0}, h[3] = {1.0, -1.0, 1.0};
    const double skew[9] = {1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0};
    (void)state;
    helper_view(&good);
    assert_null(tclod_view_check(&good));
#define BAD(field, value, message)                                \
    do {                                                          \
        v = good;                                                 \
        v.field = value;                                          \
        assert_string_equal(tclod_view_check(&v), message);       \
        assert_int_equal(tclod_view_validate(&v), TCLOD_ERR_ARG); \
    } while (0)
    BAD(eye[1], (double)INFINITY, "view->eye must be finite");
    BAD(forward[2], NAN, "view->forward must be finite");
    BAD(up[0], INFINITY, "view->up must be finite");
    BAD(fov_y, 3.2f, "view->fov_y must be in (0, pi)");
    BAD(aspect, 0.0f, "view->aspect must be finite and > 0");
    BAD(near_z, -1.0f, "view->near_z must be finite and > 0");
    BAD(far_z, 0.05f, "view->far_z must be finite and > near_z");
    BAD(viewport_height, NAN, "view->viewport_height must be finite and > 0");
    BAD(up[1], 0.0f, "view->up must not be zero");
#undef BAD
    v = good;
    v.forward[0] = v.forward[1] = v.forward[2] = 0.0f;
    assert_string_equal(tclod_view_check(&v), "view->forward must not be zero");
    v = good;
    v.up[0] = v.forward[0];
    v.up[1] = v.forward[1];
    v.up[2] = v.forward[2];
    assert_string_equal(tclod_view_check(&v), "view->up must not be parallel to forward");
    assert_string_equal(tclod_view_check(NULL), "view is NULL");

    b = tclod_bounds_sphere(0.0, 0.0, (double)NAN, 1.0);
    assert_string_equal(tclod_bounds_check(&b), "bounds.center must be finite");
    b = tclod_bounds_sphere(0.0, 0.0, 0.0, -1.0);
    assert_string_equal(tclod_bounds_check(&b), "bounds.radius must be finite and >= 0");
    b = tclod_bounds_aabb(c, h);
    assert_string_equal(tclod_bounds_check(&b), "bounds.half_extents must be finite and >= 0");
    b = tclod_bounds_obb(c, skew);
    assert_string_equal(tclod_bounds_check(&b), "bounds.half_axes must be orthogonal");
    b.kind = (tclod_bounds_kind)7;
    assert_string_equal(tclod_bounds_check(&b), "bounds.kind is not a tclod_bounds_kind");
    assert_int_equal(tclod_bounds_validate(&b), TCLOD_ERR_ARG);
}

static void scene_calls_record_why_they_failed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_scene *s = f->scene;
    const float bad_sphere[4] = {0.0f, 0.0f, 0.0f, -1.0f}, sphere[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tclod_node_desc d;
    tclod_bounds b;
    tclod_id id, root;
    assert_string_equal(tclod_scene_last_error(s), "");
    assert_string_equal(tclod_scene_last_error(NULL), "");
    root = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    assert_int_equal(tclod_scene_add_node(s, 42, NULL, &id), TCLOD_ERR_HIERARCHY);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_add_node: parent is neither TCLOD_NONE nor a live node");
    assert_int_equal(tclod_scene_add_node(s, root, bad_sphere, &id), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_add_node: bounds.radius must be finite and >= 0");
    tclod_node_desc_default(&d);
    d.refine = (tclod_refine)2;
    assert_int_equal(tclod_scene_add_node_desc(s, &d, &id), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_add_node_desc: refine is not a tclod_refine");
    d.refine = TCLOD_REFINE_REPLACE;
    d.empty = 2;
    assert_int_equal(tclod_scene_add_node_desc(s, &d, &id), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_add_node_desc: empty must be 0 or 1");
    assert_int_equal(tclod_scene_add_node_desc(s, NULL, &id), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s), "tclod_scene_add_node_desc: d is NULL");
    assert_int_equal(tclod_scene_add_node(s, root, NULL, NULL), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s), "tclod_scene_add_node: out_id is NULL");
    assert_int_equal(tclod_scene_remove_node(s, 7), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_remove_node: node is not a live node");
    b = tclod_bounds_sphere(0.0, 0.0, 0.0, (double)INFINITY);
    assert_int_equal(tclod_scene_set_node_bounds(s, root, &b), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_set_node_bounds: bounds.radius must be finite and >= 0");
    assert_int_equal(tclod_scene_add_smooth(s, bad_sphere, &id), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_add_smooth: bounds must be finite with radius >= 0, each at "
                        "most TCLOD_SMOOTH_LIMIT (1e30) in magnitude");
    assert_int_equal(tclod_scene_remove_smooth(s, 0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s),
                        "tclod_scene_remove_smooth: smooth is not a live smooth object");
    assert_int_equal(tclod_scene_add_smooth(s, sphere, &id), TCLOD_OK);
    assert_int_equal(tclod_scene_set_smooth_bounds(s, id, NULL), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scene_last_error(s), "tclod_scene_set_smooth_bounds: bounds is NULL");
    /* a success leaves the message of the last failure */
    assert_int_equal(tclod_scene_add_node(s, root, NULL, &id), TCLOD_OK);
    assert_string_equal(tclod_scene_last_error(s), "tclod_scene_set_smooth_bounds: bounds is NULL");
}

/* A scene whose benefit callback edits it: the edit is refused. */
static tclod_scene *edited_scene;
static tclod_status edit_status;

static double editing_benefit(void *user, const tclod_query *q) {
    tclod_id id;
    (void)user;
    (void)q;
    edit_status = tclod_scene_add_node(edited_scene, TCLOD_NONE, NULL, &id);
    return 1.0;
}

static void selector_calls_record_why_they_failed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_frame fr;
    tclod_view v;
    tclod_stats st;
    int done = 0;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    memset(&d, 0, sizeof d);
    d.callbacks.benefit = d.callbacks.cost = one;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_string_equal(tclod_selector_last_error(sel), "");
    helper_view(&v);
    fr = helper_frame(&v, (double)NAN);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_ARG);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select: frame->budget must be >= 0 (not NaN)");
    fr = helper_frame(&v, 1.0);
    fr.solve_seconds = -1.0;
    assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_ERR_ARG);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select_begin: frame->solve_seconds must be >= 0 (not NaN)");
    fr = helper_frame(&v, 1.0);
    v.fov_y = 0.0f;
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_ARG);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select: frame->view->fov_y must be in (0, pi)");
    assert_int_equal(tclod_select(sel, NULL, &st), TCLOD_ERR_ARG);
    assert_string_equal(tclod_selector_last_error(sel), "tclod_select: frame is NULL");
    assert_int_equal(tclod_select_step(sel, 0.0, 0, &done, &st), TCLOD_ERR_STATE);
    assert_string_equal(tclod_selector_last_error(sel), "tclod_select_step: no solve is pending");
    assert_int_equal(tclod_select_finish(sel, &st), TCLOD_ERR_STATE);
    assert_string_equal(tclod_selector_last_error(sel), "tclod_select_finish: no solve is pending");
    helper_view(&v);
    assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_OK);
    assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_ERR_STATE);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select_begin: a solve is pending: step, finish or cancel it first");
    assert_int_equal(tclod_select_step(sel, -1.0, 0, &done, &st), TCLOD_ERR_ARG);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select_step: slice_seconds must be >= 0 (not NaN)");
    assert_int_equal(tclod_select_cancel(sel), TCLOD_OK);
    tclod_selector_destroy(sel);
    /* strict mode: a NaN cost */
    d.strict = 1;
    d.callbacks.cost = nan_cost;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_CALLBACK);
    assert_string_equal(tclod_selector_last_error(sel),
                        "tclod_select: strict mode: a callback returned NaN, inf or a negative "
                        "value");
    tclod_selector_destroy(sel);
    /* a callback that edits the scene: the edit is refused and named */
    d.strict = 0;
    d.callbacks.cost = one;
    d.callbacks.benefit = editing_benefit;
    edited_scene = f->scene;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_int_equal(edit_status, TCLOD_ERR_STATE);
    assert_string_equal(tclod_scene_last_error(f->scene),
                        "tclod_scene_add_node: a solve holds the scene (pending, or called from a "
                        "callback)");
    tclod_selector_destroy(sel);
    /* the mixed solver without smooth callbacks, after smooth objects came */
    {
        const float sb[4] = {0.0f, 0.0f, -10.0f, 1.0f};
        tclod_id id;
        memset(&d, 0, sizeof d);
        d.solver = TCLOD_SOLVER_MIXED;
        d.callbacks.benefit = d.callbacks.cost = one;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        assert_int_equal(tclod_scene_add_smooth(f->scene, sb, &id), TCLOD_OK);
        assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_ARG);
        assert_string_equal(tclod_selector_last_error(sel),
                            "tclod_select: the scene has smooth objects and the mixed solver has "
                            "no smooth_benefit or smooth_cost");
        tclod_selector_destroy(sel);
    }
}

static void scheduler_and_calibration_calls_record_why_they_failed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_calib_desc cd;
    tclod_scheduler *sch = NULL;
    tclod_calib *c = NULL;
    tclod_view v;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    memset(&sd, 0, sizeof sd);
    sd.callbacks.benefit = sd.callbacks.cost = one;
    sd.callbacks.smooth_benefit = sd.callbacks.smooth_cost = smooth_one;
    memset(&d, 0, sizeof d);
    assert_int_equal(tclod_scheduler_create(f->scene, &sd, &d, NULL, &sch), TCLOD_OK);
    assert_string_equal(tclod_scheduler_last_error(sch), "");
    helper_view(&v);
    assert_int_equal(tclod_scheduler_report_frame(sch, 1.0, 1.0), TCLOD_ERR_STATE);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_report_frame: no update has succeeded yet");
    assert_int_equal(tclod_scheduler_update(sch, 0.0, NULL, 1.0, 0.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch), "tclod_scheduler_update: view is NULL");
    assert_int_equal(tclod_scheduler_update(sch, 1.0, &v, 1.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_update(sch, 0.5, &v, 1.0, 0.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_update: now must not be earlier than the last "
                        "successful update's");
    assert_int_equal(tclod_scheduler_update(sch, 1.1, &v, -1.0, 0.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_update: budget must be >= 0 (not NaN)");
    assert_int_equal(tclod_scheduler_update(sch, 1.1, &v, 1.0, (double)INFINITY), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_update: slice_seconds must be finite and >= 0");
    v.near_z = 0.0f;
    assert_int_equal(tclod_scheduler_update(sch, 1.1, &v, 1.0, 0.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_update: view->near_z must be finite and > 0");
    assert_int_equal(tclod_scheduler_report_frame(sch, (double)NAN, 1.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_report_frame: render_time must be finite and >= 0");
    assert_int_equal(tclod_scheduler_report_frame(sch, 1.0, -2.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_scheduler_last_error(sch),
                        "tclod_scheduler_report_frame: logic_time must be finite and >= 0, or "
                        "TCLOD_OFF");
    tclod_scheduler_destroy(sch);
    memset(&cd, 0, sizeof cd);
    assert_int_equal(tclod_calib_create(&cd, NULL, &c), TCLOD_OK);
    assert_string_equal(tclod_calib_last_error(c), "");
    assert_int_equal(tclod_calib_report(c, -1.0, 1.0, 1.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_calib_last_error(c),
                        "tclod_calib_report: predicted_cost must be finite and >= 0");
    assert_int_equal(tclod_calib_report(c, 1.0, (double)INFINITY, 1.0), TCLOD_ERR_ARG);
    assert_string_equal(tclod_calib_last_error(c),
                        "tclod_calib_report: render_time must be finite and >= 0");
    assert_int_equal(tclod_calib_report(c, 1.0, 1.0, (double)NAN), TCLOD_ERR_ARG);
    assert_string_equal(tclod_calib_last_error(c),
                        "tclod_calib_report: logic_time must be finite and >= 0, or TCLOD_OFF");
    tclod_calib_destroy(c);
}

/* ---- loud where it would be silent ---------------------------------------------- */

static double nan_benefit(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return (double)NAN;
}

static tclod_stats select_once(tclod_scene *s, const tclod_selector_desc *d, const tclod_view *view,
                               double budget) {
    tclod_selector *sel = NULL;
    tclod_frame fr;
    tclod_stats st;
    fr = helper_frame(view, budget);
    assert_int_equal(tclod_selector_create(s, d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    tclod_selector_destroy(sel);
    return st;
}

static void frames_that_draw_nothing_say_why(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float sb[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    tclod_selector_desc d;
    tclod_stats st;
    tclod_view v;
    tclod_id id;
    helper_view(&v);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    memset(&d, 0, sizeof d);
    d.callbacks.benefit = d.callbacks.cost = one;
    /* a root of cost 1 under budget 2 with a view: drawn, nothing to note */
    st = select_once(f->scene, &d, &v, 2.0);
    assert_int_equal(st.notes, 0u);
    /* no view */
    st = select_once(f->scene, &d, NULL, 2.0);
    assert_int_equal(st.notes, TCLOD_NOTE_NO_VIEW);
    /* every benefit NaN: sanitised to 0, the root is not drawn */
    d.callbacks.benefit = nan_benefit;
    st = select_once(f->scene, &d, &v, 2.0);
    assert_int_equal(st.notes, TCLOD_NOTE_INVALID_VALUES | TCLOD_NOTE_NOTHING_DRAWN);
    assert_true(st.invalid_values >= 1u);
    /* strict mode fails on it instead */
    d.strict = 1;
    {
        tclod_selector *sel = NULL;
        tclod_frame fr = helper_frame(&v, 2.0);
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_CALLBACK);
        tclod_selector_destroy(sel);
    }
    d.strict = 0;
    d.callbacks.benefit = one;
    /* smooth objects the greedy solver does not draw, and the Robin Hood
     * solver without smooth callbacks */
    assert_int_equal(tclod_scene_add_smooth(f->scene, sb, &id), TCLOD_OK);
    st = select_once(f->scene, &d, &v, 2.0);
    assert_int_equal(st.notes, TCLOD_NOTE_SMOOTH_IGNORED);
    d.solver = TCLOD_SOLVER_ROBIN_HOOD;
    st = select_once(f->scene, &d, &v, 2.0);
    assert_int_equal(st.notes & TCLOD_NOTE_SMOOTH_IGNORED, TCLOD_NOTE_SMOOTH_IGNORED);
    d.callbacks.smooth_benefit = d.callbacks.smooth_cost = smooth_one;
    st = select_once(f->scene, &d, &v, 2.0);
    assert_int_equal(st.notes & TCLOD_NOTE_SMOOTH_IGNORED, 0u);
}

static void a_budget_of_zero_never_reports_finest(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                           TCLOD_SOLVER_ROBIN_HOOD};
    tclod_selector_desc d;
    tclod_stats st;
    size_t k;
    /* a root of cost 0 whose child (cost 2) gains 2: at budget 0 the child
     * cannot fit, and budget is why the solve stopped; the same root alone
     * (nothing left to refine) at budget 0 says budget too */
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 0.0);
    int children;
    for (children = 0; children < 2; ++children) {
        if (children)
            helper_add(f, root, 3.0, 2.0);
        for (k = 0; k < 3; ++k) {
            memset(&d, 0, sizeof d);
            d.solver = solvers[k];
            table_mixed_callbacks(&f->model, &d.callbacks);
            st = select_once(f->scene, &d, NULL, 0.0);
            assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
            assert_true(st.cost == 0.0);
        }
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
#define FIXTURE_TEST(t) \
    cmocka_unit_test_setup_teardown(t, helper_fixture_setup, helper_fixture_teardown)
        FIXTURE_TEST(a_zeroed_selector_desc_with_callbacks_is_the_default),
        FIXTURE_TEST(zeroed_scheduler_and_calibration_descs_are_the_defaults),
        FIXTURE_TEST(a_scene_in_use_is_not_destroyed),
        FIXTURE_TEST(selector_descs_name_the_field_and_rule),
        FIXTURE_TEST(scheduler_and_calibration_descs_name_the_field_and_rule),
        cmocka_unit_test(views_and_bounds_name_the_field_and_rule),
        FIXTURE_TEST(scene_calls_record_why_they_failed),
        FIXTURE_TEST(selector_calls_record_why_they_failed),
        FIXTURE_TEST(scheduler_and_calibration_calls_record_why_they_failed),
        FIXTURE_TEST(frames_that_draw_nothing_say_why),
        FIXTURE_TEST(a_budget_of_zero_never_reports_finest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
