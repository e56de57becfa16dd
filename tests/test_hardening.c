/*
 * test_hardening — promises of the header that the fuzz targets, the
 * sanitizers and valgrind found broken, each pinned by the smallest case that
 * shows it, with the numbers worked out by hand:
 *  - strict mode fails a select whenever a callback returned a bad value,
 *    also when the value comes up inside a warm start's swap;
 *  - the Robin Hood solver selects over an empty scene (no pointer
 *    arithmetic on its empty buffers: UBSan's pointer-overflow check);
 *  - the mixed solver builds no variable model from values it never asked
 *    (valgrind: a smooth object whose benefit is bad near resolution 0);
 *  - a group of smooth objects is asked about with a sphere that holds its
 *    members also at coordinates of denormal size;
 *  - the scheduler returns from every update whatever the origin of its
 *    clock; it does not take huge finite benefits for bad values when it adds
 *    them over its predicted views; a failed update keeps the draw list; a
 *    selection that meets a bad value when it lands at a boundary fails a
 *    strict update.
 */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

/* POSIX systems stop a test that waits too long for the library (an update
 * that never returns) with an alarm; elsewhere ctest's timeout does. */
#if defined(__unix__) || defined(__APPLE__)
#define HAVE_ALARM 1
#include <signal.h>
#include <unistd.h>
#else
#define HAVE_ALARM 0
#endif

#include <tclod/tclod.h>

/* ---- strict mode inside a warm swap --------------------------------------------- */

enum { NODE_A, NODE_B, NODE_A1, NODE_A2, NODE_B1, NODE_B2 };

typedef struct swap_host {
    double benefit[6], cost[6];
    int bad_returned;
} swap_host;

static double swap_benefit(void *user, const tclod_query *q) {
    swap_host *h = (swap_host *)user;
    h->bad_returned += isnan(h->benefit[q->id]);
    return h->benefit[q->id];
}

static double swap_cost(void *user, const tclod_query *q) {
    return ((swap_host *)user)->cost[q->id];
}

static void strict_mode_fails_when_a_warm_swap_meets_a_bad_value(void **state) {
    /* Roots A and B (b 1, c 1); A -> A1 (b 5, c 2) -> A2 (b 5.1, c 10);
     * B -> B1 (b 1.5, c 2) -> B2 (b 1.6, c 10). Budget 3: the roots cost 2,
     * A's increment (Δb 4, Δc 1) fits, B's (Δb 0.5, Δc 1) then does not:
     * cut {B, A1}. Next frame B1 is worth 20: B's increment (ratio 19) does
     * not fit, collapsing A1 (loss ratio 4) pays for it, so the warm solve
     * swaps; B1 joins the cut and its child B2 is asked for the first time,
     * and B2's benefit is now NaN. Strict mode: TCLOD_ERR_CALLBACK, and the
     * cut {B, A1} stays. */
    swap_host h = {{1.0, 1.0, 5.0, 5.1, 1.5, 1.6}, {1.0, 1.0, 2.0, 10.0, 2.0, 10.0}, 0};
    static const tclod_id parents[6] = {TCLOD_NONE, TCLOD_NONE, NODE_A, NODE_A1, NODE_B, NODE_B1};
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    tclod_frame f = {NULL, 3.0, 0.0, 0};
    tclod_stats st;
    const tclod_id *ids = NULL;
    size_t n = 0;
    tclod_id id, k;
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < 6; ++k)
        assert_int_equal(tclod_scene_add_node(s, parents[k], NULL, &id), TCLOD_OK);
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = swap_benefit;
    d.callbacks.cost = swap_cost;
    d.callbacks.user = &h;
    d.strict = 1;
    d.cold_start = 0;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    assert_true((ids[0] == NODE_B && ids[1] == NODE_A1) || (ids[0] == NODE_A1 && ids[1] == NODE_B));
    h.benefit[NODE_B1] = 20.0;
    h.benefit[NODE_B2] = (double)NAN;
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_ERR_CALLBACK);
    assert_int_equal(h.bad_returned, 1);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    assert_true((ids[0] == NODE_B && ids[1] == NODE_A1) || (ids[0] == NODE_A1 && ids[1] == NODE_B));
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

/* ---- the Robin Hood solver over an empty scene ------------------------------------ */

static double one(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static void robin_hood_selects_nothing_from_an_empty_scene(void **state) {
    /* No node, no smooth object: an empty result of benefit and cost 0. */
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    tclod_frame f = {NULL, 1.0, 0.0, 0};
    tclod_stats st;
    const tclod_id *ids = NULL;
    size_t n = 7;
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_ROBIN_HOOD;
    d.callbacks.benefit = one;
    d.callbacks.cost = one;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_true(st.benefit == 0.0 && st.cost == 0.0);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

/* ---- the mixed solver and a smooth object bad near resolution 0 ------------------- */

static double zero(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 0.0;
}

/* sqrt(r), but NaN below r = 1e-6 */
static double sqrt_bad_near_zero(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 0.5 / sqrt(r);
    return r < 1e-6 ? (double)NAN : sqrt(r);
}

static double linear_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 1.0;
    return r;
}

static void mixed_solver_leaves_a_smooth_object_bad_at_zero_undrawn(void **state) {
    /* One smooth object whose benefit is NaN at the smallest resolution the
     * solver asks: a bad benefit makes it invisible (not drawn, counted), and
     * its model is never built from unasked values (valgrind checks that). */
    static const float bounds[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    tclod_frame f = {NULL, 10.0, 0.0, 0};
    tclod_stats st;
    const tclod_smooth_group *groups = NULL;
    size_t n = 7;
    tclod_id id;
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(s, bounds, &id), TCLOD_OK);
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    d.callbacks.benefit = zero;
    d.callbacks.cost = zero;
    d.callbacks.smooth_benefit = sqrt_bad_near_zero;
    d.callbacks.smooth_cost = linear_cost;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_true(tclod_selector_resolution(sel, 0) == 0.0);
    assert_true(st.invalid_values >= 1);
    assert_true(st.cost == 0.0);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

/* What the smooth callbacks saw of groups: queries of several members, and
 * those whose sphere left a member out. */
typedef struct group_probe {
    float bounds[2][4];
    int groups, outside;
} group_probe;

static double sqrt_seeing_groups(void *user, const tclod_query *q, double r, double *d_dr) {
    group_probe *g = (group_probe *)user;
    uint32_t i;
    if (q->count > 1) {
        g->groups++;
        for (i = 0; i < q->count; ++i) {
            const float *b = g->bounds[q->members[i]];
            double dx = (double)b[0] - q->bounds->center[0],
                   dy = (double)b[1] - q->bounds->center[1];
            double dz = (double)b[2] - q->bounds->center[2];
            g->outside += sqrt(dx * dx + dy * dy + dz * dz) + (double)b[3] > q->bounds->radius;
        }
    }
    *d_dr = 0.5 / sqrt(r);
    return sqrt(r);
}

static void a_group_sphere_holds_its_members_at_denormal_coordinates(void **state) {
    /* Two smooth objects of radius 0 at (0, 0, 0) and (d, d, d), d = 2^-149
     * (the smallest float), alike: the mixed solver with split variables
     * gives them one shared variable, asked about with the sphere of their
     * quadtree node. Their box's centre (d/2, d/2, d/2) is no float: it rounds
     * to (0, 0, 0). The radius reaching the far member from the true centre,
     * sqrt(3) d/2 = 0.87 d, with margins relative to it and to the centre (of
     * the order of 1e-6 d) rounds to d; from (0, 0, 0) the member lies
     * sqrt(3) d = 1.73 d away, outside. Every group's sphere must hold its
     * members (the radius then becomes 2 d, the first float above 1.73 d). */
    const float d = 0x1p-149f;
    group_probe g;
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc desc;
    tclod_frame f = {NULL, 10.0, 0.0, 0};
    tclod_stats st;
    tclod_id id;
    int k;
    (void)state;
    memset(&g, 0, sizeof g);
    g.bounds[1][0] = g.bounds[1][1] = g.bounds[1][2] = d;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < 2; ++k) {
        assert_int_equal(tclod_scene_add_smooth(s, g.bounds[k], &id), TCLOD_OK);
        assert_int_equal(id, (tclod_id)k);
    }
    tclod_selector_desc_default(&desc);
    desc.solver = TCLOD_SOLVER_MIXED;
    desc.mixed.split_smooth = 1;
    desc.callbacks.benefit = zero;
    desc.callbacks.cost = zero;
    desc.callbacks.smooth_benefit = sqrt_seeing_groups;
    desc.callbacks.smooth_cost = linear_cost;
    desc.callbacks.user = &g;
    assert_int_equal(tclod_selector_create(s, &desc, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    assert_true(g.groups > 0);
    assert_int_equal(g.outside, 0);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

/* ---- the scheduler --------------------------------------------------------------- */

#if HAVE_ALARM
/* Where a SIGALRM handler takes a test that waited too long for the library. */
static sigjmp_buf too_long;

static void give_up(int sig) {
    (void)sig;
    siglongjmp(too_long, 1);
}
#endif

static tclod_view straight_view(void) {
    tclod_view v;
    memset(&v, 0, sizeof v);
    v.forward[2] = -1.0f;
    v.up[1] = 1.0f;
    v.fov_y = 1.0f;
    v.aspect = 1.0f;
    v.near_z = 0.1f;
    v.far_z = 100.0f;
    v.viewport_height = 720.0f;
    return v;
}

/* A scheduler over a new scene *s of a chain of `nodes` nodes, all of cost 1
 * and of the given benefit, with the default scheduling description but
 * max_turn_rate. */
static tclod_scheduler *chain_scheduler(tclod_scene **s, tclod_id nodes,
                                        double (*benefit)(void *, const tclod_query *), int strict,
                                        double max_turn_rate) {
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_id k, id, parent = TCLOD_NONE;
    assert_int_equal(tclod_scene_create(NULL, s), TCLOD_OK);
    for (k = 0; k < nodes; ++k) {
        assert_int_equal(tclod_scene_add_node(*s, parent, NULL, &id), TCLOD_OK);
        parent = id;
    }
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = benefit;
    sd.callbacks.cost = one;
    sd.strict = strict;
    tclod_scheduler_desc_default(&d);
    d.max_turn_rate = max_turn_rate;
    assert_int_equal(tclod_scheduler_create(*s, &sd, &d, NULL, &sch), TCLOD_OK);
    return sch;
}

static void scheduler_updates_return_whatever_the_clock_origin(void **state) {
    /* "now (seconds, any origin, never decreasing)": a clock that reads 1e17 s
     * (where adding tau = 0.5 s changes nothing) still gives updates that
     * return (the test gives up after 10 s). */
    tclod_scene *s = NULL;
    tclod_scheduler *sch = chain_scheduler(&s, 1, one, 0, 0.0);
    tclod_view v = straight_view();
    (void)state;
#if HAVE_ALARM
    if (sigsetjmp(too_long, 1) != 0) /* the scheduler is left busy: not destroyed */
        fail_msg("tclod_scheduler_update at now = 1e17 did not return within 10 s");
    signal(SIGALRM, give_up);
    alarm(10);
#endif
    assert_int_equal(tclod_scheduler_update(sch, 1e17, &v, 10.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_update(sch, 1e17, &v, 10.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_update(sch, 1e17 + 64.0, &v, 10.0, 0.0), TCLOD_OK);
#if HAVE_ALARM
    alarm(0);
#endif
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* Asserts that the scheduler's draw list is node `node` alone. */
static void assert_draws_node(const tclod_scheduler *sch, tclod_id node) {
    const tclod_draw *items = NULL;
    size_t n = 0;
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, node);
}

static double huge(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1e308;
}

static void scheduler_takes_huge_finite_benefits_for_good_values(void **state) {
    /* One node of benefit 1e308 (finite, valid) and cost 1, strict mode: the
     * benefit over 3 predicted views plus the conservative camera's is more
     * than DBL_MAX, yet no callback returned a bad value, so the update
     * succeeds and draws the node. */
    tclod_scene *s = NULL;
    tclod_scheduler *sch = chain_scheduler(&s, 1, huge, 1, 0.0);
    tclod_view v = straight_view();
    (void)state;
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 10.0, 0.0), TCLOD_OK);
    assert_draws_node(sch, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* NaN for views wider than 1 radian (the conservative camera, which widens
 * the field of view by the turn rate), 1 otherwise. */
static double bad_when_wide(void *user, const tclod_query *q) {
    (void)user;
    return q->view && q->view->fov_y > 1.0f ? (double)NAN : 1.0;
}

static void a_failed_first_update_keeps_the_empty_draw_list(void **state) {
    /* Strict mode, max_turn_rate 0.5: the benefit under the conservative
     * camera is NaN, so the first update fails with TCLOD_ERR_CALLBACK, and
     * "on error the last draw list stays": the empty one. */
    tclod_scene *s = NULL;
    tclod_scheduler *sch = chain_scheduler(&s, 2, bad_when_wide, 1, 0.5);
    tclod_view v = straight_view();
    const tclod_draw *items = NULL;
    size_t n = 7;
    (void)state;
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 10.0, 0.0), TCLOD_ERR_CALLBACK);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* NaN for the next `nan_benefits` calls, 1 after them. */
static uint32_t nan_benefits;

static double nan_first(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    if (nan_benefits > 0u) {
        nan_benefits--;
        return (double)NAN;
    }
    return 1.0;
}

static void a_selection_landed_on_a_bad_value_fails_a_strict_update(void **state) {
    /* Strict mode, one node, tau = 0.5 s. The update at t = 0 selects at
     * once and runs the selection for the next interval to its end. The
     * update at t = 1.25 crosses the boundaries at 0.5 and 1: at 1 it
     * finishes the selection begun at 0.5, whose first benefit is NaN (the
     * selection begun at 1 then sees only good values). "A callback returned
     * a bad value": the update fails with TCLOD_ERR_CALLBACK and keeps the
     * draw list; the next one succeeds. */
    tclod_scene *s = NULL;
    tclod_scheduler *sch = chain_scheduler(&s, 1, nan_first, 1, 0.0);
    tclod_view v = straight_view();
    (void)state;
    nan_benefits = 0;
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 10.0, 0.0), TCLOD_OK);
    nan_benefits = 1;
    assert_int_equal(tclod_scheduler_update(sch, 1.25, &v, 10.0, 0.0), TCLOD_ERR_CALLBACK);
    assert_int_equal(nan_benefits, 0);
    assert_draws_node(sch, 0);
    assert_int_equal(tclod_scheduler_update(sch, 1.3, &v, 10.0, 0.0), TCLOD_OK);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(strict_mode_fails_when_a_warm_swap_meets_a_bad_value),
        cmocka_unit_test(robin_hood_selects_nothing_from_an_empty_scene),
        cmocka_unit_test(mixed_solver_leaves_a_smooth_object_bad_at_zero_undrawn),
        cmocka_unit_test(a_group_sphere_holds_its_members_at_denormal_coordinates),
        cmocka_unit_test(scheduler_updates_return_whatever_the_clock_origin),
        cmocka_unit_test(scheduler_takes_huge_finite_benefits_for_good_values),
        cmocka_unit_test(a_failed_first_update_keeps_the_empty_draw_list),
        cmocka_unit_test(a_selection_landed_on_a_bad_value_fails_a_strict_update),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
