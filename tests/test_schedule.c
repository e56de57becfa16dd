/*
 * test_schedule — the predictive geomorph scheduler (src/schedule/schedule.c; [GEO]
 * §3.3-3.4, §4.3-4.5): the conservative camera on hand-computed values, linear
 * prediction (exact on a straight path, clamped to the speed and turn bounds),
 * the timing of Fig. 6 (a down-morph ends when its interval begins, an
 * up-morph ends with its interval), Fig. 7's successive monotone morphs and
 * the collapse of an up-morph overridden by a down-morph, a jump of three
 * levels as three adjacent morphs, a split morphing each child from its
 * parent, smooth resolutions moving linearly with the same asymmetry, the
 * two-stage pipeline's switches, and, over random camera paths, budgets and
 * slices, that every frame's draw list is well formed and within the budget
 * in force.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"
#include "table_scene.h"
#include "world_scene.h"

#define PI 3.14159265358979323846

/* ---- a host whose wishes change at known times ----------------------------- */

/* Nodes without bounds; node n sits at depth[n] of its hierarchy. A node is
 * worth 10 (depth + 1) up to the depth `target` and 1 below it, so the
 * greedy refines exactly down to `target`, or benefit[n] when that is set
 * (> 0); it costs depth + 1, or cost[n] when that is set. The next
 * `nan_costs` cost calls return NaN, and with nan_wide every benefit asked
 * for a view wider than 1.6 radians. Smooth objects are worth
 * weight[i] sqrt(r) and cost r. */
typedef struct wish_host {
    uint32_t depth[128];
    double benefit[128], cost[128];
    uint32_t target;
    uint32_t nan_costs;
    int nan_wide;
    int strict; /* the selector's strict mode */
    double weight[4];
} wish_host;

static double wish_benefit(void *user, const tclod_query *q) {
    const wish_host *h = (const wish_host *)user;
    uint32_t d = h->depth[q->id];
    if (h->nan_wide && q->view && q->view->fov_y > 1.6f)
        return (double)NAN;
    if (h->benefit[q->id] > 0.0)
        return h->benefit[q->id];
    return d <= h->target ? 10.0 * (double)(d + 1u) : 1.0;
}

static double wish_cost(void *user, const tclod_query *q) {
    wish_host *h = (wish_host *)user;
    if (h->nan_costs > 0u) {
        h->nan_costs--;
        return (double)NAN;
    }
    return h->cost[q->id] > 0.0 ? h->cost[q->id] : (double)(h->depth[q->id] + 1u);
}

static double wish_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    const wish_host *h = (const wish_host *)user;
    double w = 0.0;
    uint32_t k;
    for (k = 0; k < q->count; ++k)
        w += h->weight[q->members[k]];
    *d_dr = 0.5 * w / sqrt(r);
    return w * sqrt(r);
}

static double wish_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    *d_dr = (double)q->count;
    return (double)q->count * r;
}

/* A scheduler with tau = 1 s over s, the greedy solver (cold, so that a wish
 * is followed exactly) or the mixed one, one predicted view, no conservative
 * benefit. */
static tclod_scheduler *wish_scheduler(tclod_scene *s, wish_host *h, int morph, int mixed) {
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = wish_benefit;
    sd.callbacks.cost = wish_cost;
    sd.callbacks.smooth_benefit = wish_smooth_benefit;
    sd.callbacks.smooth_cost = wish_smooth_cost;
    sd.callbacks.user = h;
    sd.cold_start = 1;
    sd.strict = h->strict;
    if (mixed) {
        sd.solver = TCLOD_SOLVER_MIXED;
        sd.smooth_cull_area = TCLOD_OFF;
    }
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.samples = 1;
    d.confidence = TCLOD_OFF;
    d.two_stage = !(morph);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    return sch;
}

/* A chain of `levels` nodes; node k at depth k (helper_chain). */
static tclod_scene *chain(wish_host *h, uint32_t levels) {
    return helper_chain(h->depth, levels);
}

/* This file's short names for helper_run_frames and helper_expect_one. */
#define run_frames helper_run_frames
#define expect_one helper_expect_one

/* ---- the conservative camera and the prediction --------------------------- */

static void conservative_camera_widens_and_steps_back_as_the_geomorph_paper_says(void **state) {
    tclod_view v, c;
    (void)state;
    helper_view(&v);
    v.fov_y = (float)(PI / 3.0); /* 60 degrees, aspect 1 */
    /* tau = 0.5 s, omega = 10 deg/s, theta = 10 m/s; with morphing the
     * horizon is 3 tau = 1.5 s: fov 60 + 6 tau omega = 60 + 30 = 90 degrees;
     * the eye steps back 3 tau theta / sin(fov/2 + 3 tau omega)
     * = 15 / sin(45 deg) = 21.2132 m along forward (0, 0, -1), to z = +21.2132;
     * far 100 + 21.2132 + 15 */
    assert_int_equal(tclod_conservative_view(&v, 1.5, 10.0, 10.0 * PI / 180.0, &c), TCLOD_OK);
    assert_float_equal(c.fov_y, PI / 2.0, 1e-6);
    assert_float_equal(c.aspect, 1.0, 1e-6);
    assert_float_equal(c.eye[0], 0.0, 1e-6);
    assert_float_equal(c.eye[2], 21.2132034, 1e-4);
    assert_float_equal(c.far_z, 136.2132034, 1e-3);
    assert_memory_equal(c.forward, v.forward, sizeof v.forward);
    /* without morphing, 2 tau = 1 s: fov 60 + 4 tau omega = 80 degrees, back
     * 2 tau theta / sin(40 deg) = 10 / 0.6427876 = 15.5572 m */
    assert_int_equal(tclod_conservative_view(&v, 1.0, 10.0, 10.0 * PI / 180.0, &c), TCLOD_OK);
    assert_float_equal(c.fov_y, 80.0 * PI / 180.0, 1e-6);
    assert_float_equal(c.eye[2], 15.5572382, 1e-4);
    /* a wide view (aspect 2): the horizontal field, 2 atan(2 tan 30 deg) =
     * 98.2132 degrees, widens by 30 too, to 128.2132; the aspect becomes
     * tan(64.1066 deg) / tan(45 deg) = 2.06000; the narrower (vertical) field
     * sets the step back, 21.2132 m as before */
    v.aspect = 2.0f;
    assert_int_equal(tclod_conservative_view(&v, 1.5, 10.0, 10.0 * PI / 180.0, &c), TCLOD_OK);
    assert_float_equal(c.aspect, 2.06000, 1e-4);
    assert_float_equal(c.eye[2], 21.2132034, 1e-4);
    /* no motion at all: the same view */
    assert_int_equal(tclod_conservative_view(&v, 1.5, 0.0, 0.0, &c), TCLOD_OK);
    assert_memory_equal(&c, &v, sizeof v);
    /* bad arguments leave *out alone */
    memset(&c, 0x5a, sizeof c);
    assert_int_equal(tclod_conservative_view(&v, -1.0, 1.0, 1.0, &c), TCLOD_ERR_ARG);
    assert_int_equal(tclod_conservative_view(&v, 1.0, NAN, 1.0, &c), TCLOD_ERR_ARG);
    assert_int_equal(tclod_conservative_view(&v, 1.0, 1.0, INFINITY, &c), TCLOD_ERR_ARG);
    assert_int_equal(tclod_conservative_view(NULL, 1.0, 1.0, 1.0, &c), TCLOD_ERR_ARG);
    assert_int_equal(tclod_conservative_view(&v, 1.0, 1.0, 1.0, NULL), TCLOD_ERR_ARG);
    assert_true(((unsigned char *)&c)[0] == 0x5a);
    /* fields of view stop at 179 degrees */
    assert_int_equal(tclod_conservative_view(&v, 100.0, 0.0, 1.0, &c), TCLOD_OK);
    assert_true(c.fov_y <= (float)(179.0 * PI / 180.0) + 1e-6f);
}

/* A scheduler over an empty scene, for the prediction tests. */
static tclod_scheduler *path_scheduler(tclod_scene **s, double max_speed, double max_turn) {
    static wish_host h;
    tclod_scheduler *sch;
    tclod_scheduler_desc d;
    tclod_selector_desc sd;
    assert_int_equal(tclod_scene_create(NULL, s), TCLOD_OK);
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = wish_benefit;
    sd.callbacks.cost = wish_cost;
    sd.callbacks.user = &h;
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.max_speed = max_speed;
    d.max_turn_rate = max_turn;
    assert_int_equal(tclod_scheduler_create(*s, &sd, &d, NULL, &sch), TCLOD_OK);
    return sch;
}

static void prediction_is_exact_on_a_straight_path(void **state) {
    tclod_scene *s;
    tclod_scheduler *sch = path_scheduler(&s, 0.0, 0.0);
    tclod_view v, p;
    int k;
    (void)state;
    helper_view(&v);
    assert_int_equal(tclod_scheduler_predict(sch, 1.0, &p), TCLOD_ERR_STATE);
    /* 1 m/s along x, 2 m/s along -z, sampled at 10 Hz for a second */
    for (k = 0; k <= 10; ++k) {
        double t = 0.1 * k;
        v.eye[0] = (float)(1.0 * t);
        v.eye[2] = (float)(-2.0 * t);
        assert_int_equal(tclod_scheduler_update(sch, t, &v, 10.0, 0.0), TCLOD_OK);
    }
    /* 2.5 s on: the line continued */
    assert_int_equal(tclod_scheduler_predict(sch, 3.5, &p), TCLOD_OK);
    assert_float_equal(p.eye[0], 3.5, 1e-4);
    assert_float_equal(p.eye[1], 0.0, 1e-6);
    assert_float_equal(p.eye[2], -7.0, 1e-4);
    assert_memory_equal(p.forward, v.forward, sizeof v.forward);
    assert_float_equal(p.fov_y, v.fov_y, 0.0);
    assert_int_equal(tclod_scheduler_predict(sch, NAN, &p), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_predict(sch, INFINITY, &p), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_predict(sch, -INFINITY, &p), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_predict(sch, 1e300, &p), TCLOD_OK);
    assert_int_equal(tclod_view_validate(&p), TCLOD_OK);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void prediction_keeps_to_the_speed_and_turn_bounds(void **state) {
    tclod_scene *s;
    tclod_scheduler *sch = path_scheduler(&s, 1.0, 0.1);
    tclod_view v, p;
    double len, angle;
    int k;
    (void)state;
    helper_view(&v);
    /* 3 m/s along x (over max_speed 1) while turning at 0.5 rad/s about y
     * (over max_turn_rate 0.1) */
    for (k = 0; k <= 10; ++k) {
        double t = 0.1 * k;
        v.eye[0] = (float)(3.0 * t);
        v.forward[0] = (float)sin(0.5 * t);
        v.forward[2] = (float)-cos(0.5 * t);
        assert_int_equal(tclod_scheduler_update(sch, t, &v, 10.0, 0.0), TCLOD_OK);
    }
    assert_int_equal(tclod_scheduler_predict(sch, 3.0, &p), TCLOD_OK);
    /* 2 s ahead: at most 2 m from where the fitted line is now (x = 3),
     * along it: x = 5 */
    assert_float_equal(p.eye[0], 5.0, 1e-3);
    /* and turned by at most 0.2 rad from the fitted direction now */
    len = sqrt((double)p.forward[0] * p.forward[0] + (double)p.forward[2] * p.forward[2]);
    angle = atan2((double)p.forward[0] / len, -(double)p.forward[2] / len);
    assert_true(angle <= 0.5 + 0.2 + 1e-3);
    assert_true(angle >= 0.5 + 0.2 - 0.05);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- what a selection is asked with ------------------------------------------ */

/* A host that records the views its callbacks are asked with. The scene is
 * one node; its benefit is 1 + eye x, its cost 1 + (eye x) / 10, of the
 * view asked with. */
typedef struct recording_host {
    uint32_t benefits, costs;
    tclod_view benefit_view[8], cost_view[8];
} recording_host;

static double recording_benefit(void *user, const tclod_query *q) {
    recording_host *h = (recording_host *)user;
    if (h->benefits < 8u)
        h->benefit_view[h->benefits] = *q->view;
    h->benefits++;
    return 1.0 + (double)q->view->eye[0];
}

static double recording_cost(void *user, const tclod_query *q) {
    recording_host *h = (recording_host *)user;
    if (h->costs < 8u)
        h->cost_view[h->costs] = *q->view;
    h->costs++;
    return 1.0 + 0.1 * (double)q->view->eye[0];
}

/* A smooth object worth (1 + eye x) r, costing r. */
static double recording_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    *d_dr = 1.0 + (double)q->view->eye[0];
    return *d_dr * r;
}

static double recording_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 1.0;
    return r;
}

static void assert_eye(const tclod_view *v, double x, double y, double z) {
    if (fabs((double)v->eye[0] - x) > 1e-4 || fabs((double)v->eye[1] - y) > 1e-4 ||
        fabs((double)v->eye[2] - z) > 1e-4)
        fail_msg("eye (%g, %g, %g), expected (%g, %g, %g)", (double)v->eye[0], (double)v->eye[1],
                 (double)v->eye[2], x, y, z);
}

static void a_selection_is_asked_for_its_target_interval_and_the_conservative_camera(void **state) {
    /* tau = 1 s, 2 samples, lambda = 0.5, theta = 2 m/s, omega = 5 deg/s.
     * The camera moves along x at 1 m/s (eye x = t), looking down -z with a
     * field of view of 60 degrees (aspect 1); an update every 0.1 s.
     *
     * With morphing the selection begun at the boundary b = 1 is for
     * [b + 2 tau, b + 3 tau) = [3, 4). Its samples lie at the middles of the
     * two halves, t = 3.25 and 3.75, where the camera will be at x = 3.25 and
     * 3.75. The conservative camera widens the 60 degrees by 6 tau omega = 30
     * to 90 and steps back from the current eye (x = 1) by
     * 3 tau theta / sin(30 + 15 degrees) = 6 / sin 45 = 8.485281 m against
     * forward, to z = +8.485281. The node's benefit is
     * (1 + 3.25) + (1 + 3.75) + 0.5 (1 + 1) = 10, its cost the larger of
     * the samples' 1.325 and 1.375.
     *
     * Without morphing the target is [b + tau, b + 2 tau) = [2, 3): samples
     * at 2.25 and 2.75, a field of view of 60 + 4 tau omega = 80 degrees, a
     * step back of 2 tau theta / sin(30 + 10 degrees) = 4 / 0.6427876 =
     * 6.222895 m; benefit 3.25 + 3.75 + 0.5 * 2 = 8, cost 1.275.
     *
     * The selection lands at 2, where the stats show its benefit and cost.
     * The mixed solver sees a smooth object too, 20 m ahead, worth
     * (1 + eye x) r and costing r: its benefit is summed the same way, and
     * with budget to spare it is drawn at r = 1, so the selection's benefit
     * and cost are the node's twice and the node's + 1. */
    static const double fov[2] = {80.0, 90.0}, back[2] = {6.22289531, 8.48528137};
    static const double sample[2][2] = {{2.25, 2.75}, {3.25, 3.75}};
    static const double benefit[2] = {8.0, 10.0}, cost[2] = {1.275, 1.375};
    int morph, mixed;
    (void)state;
    for (mixed = 0; mixed <= 1; ++mixed)
        for (morph = 0; morph <= 1; ++morph) {
            static const float tree[4] = {2.0f, 0.0f, -20.0f, 1.0f};
            recording_host h;
            tclod_scene *s = NULL;
            tclod_scheduler *sch = NULL;
            tclod_selector_desc sd;
            tclod_scheduler_desc d;
            tclod_scheduler_stats st;
            tclod_view v;
            tclod_id root;
            uint32_t f, k;
            memset(&h, 0, sizeof h);
            assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
            assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &root), TCLOD_OK);
            tclod_selector_desc_default(&sd);
            sd.callbacks.benefit = recording_benefit;
            sd.callbacks.cost = recording_cost;
            sd.callbacks.user = &h;
            if (mixed) {
                tclod_id smooth;
                assert_int_equal(tclod_scene_add_smooth(s, tree, &smooth), TCLOD_OK);
                sd.solver = TCLOD_SOLVER_MIXED;
                sd.callbacks.smooth_benefit = recording_smooth_benefit;
                sd.callbacks.smooth_cost = recording_smooth_cost;
            }
            tclod_scheduler_desc_default(&d);
            d.tau = 1.0;
            d.samples = 2;
            d.confidence = 0.5;
            d.max_speed = 2.0;
            d.max_turn_rate = 5.0 * PI / 180.0;
            d.two_stage = !(morph);
            assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
            helper_view(&v);
            v.fov_y = (float)(PI / 3.0);
            for (f = 0; f <= 20u; ++f) {
                double t = (double)f / 10.0;
                v.eye[0] = (float)t;
                if (f == 10u)
                    h.benefits = h.costs = 0;
                assert_int_equal(tclod_scheduler_update(sch, t, &v, 100.0, 0.0), TCLOD_OK);
                if (f != 10u)
                    continue;
                /* the update at the boundary 1 began and ran the selection for
                 * the target interval: benefit under the two samples, then the
                 * conservative camera; cost under the samples that saw the node */
                assert_int_equal(h.benefits, 3);
                assert_int_equal(h.costs, 2);
                for (k = 0; k < 2u; ++k) {
                    assert_eye(&h.benefit_view[k], sample[morph][k], 0.0, 0.0);
                    assert_eye(&h.cost_view[k], sample[morph][k], 0.0, 0.0);
                    assert_float_equal(h.benefit_view[k].fov_y, PI / 3.0, 1e-6);
                    assert_memory_equal(h.benefit_view[k].forward, v.forward, sizeof v.forward);
                }
                assert_float_equal(h.benefit_view[2].fov_y, fov[morph] * PI / 180.0, 1e-6);
                assert_float_equal(h.benefit_view[2].aspect, 1.0, 1e-6);
                assert_eye(&h.benefit_view[2], 1.0, 0.0, back[morph]);
                assert_memory_equal(h.benefit_view[2].forward, v.forward, sizeof v.forward);
            }
            assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
            assert_int_equal(st.selections, 2);
            assert_float_equal(st.selection_benefit, (1 + mixed) * benefit[morph], 1e-5);
            assert_float_equal(st.selection_cost, cost[morph] + mixed, 1e-6);
            if (mixed)
                assert_float_equal(tclod_scheduler_resolution(sch, 0), 1.0, 0.0);
            tclod_scheduler_destroy(sch);
            tclod_scene_destroy(s);
        }
}

/* ---- timing of single morphs (Fig. 6) ------------------------------------- */

static void up_morph_ends_with_its_interval_and_down_morph_before_its_interval(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_scheduler_stats st;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 2); /* A = 0, B = 1 */
    sch = wish_scheduler(s, &h, 1, 0);
    /* tau = 1: intervals [k, k + 1). The wish for B comes at t = 3: the
     * selection begun at 3 is for [5, 6) and lands at 4; the up-morph runs
     * during [5, 6) and B is reached at 6 */
    run_frames(sch, 0, 30);
    h.target = 1;
    run_frames(sch, 30, 50);
    expect_one(sch, 50, 0, 0, 1.0);
    expect_one(sch, 51, 1, 0, 0.1);
    run_frames(sch, 52, 55);
    expect_one(sch, 55, 1, 0, 0.5);
    run_frames(sch, 56, 59);
    expect_one(sch, 59, 1, 0, 0.9);
    expect_one(sch, 60, 1, 1, 1.0);
    /* back to A at t = 8: the selection for [10, 11) lands at 9 and the
     * down-morph runs during [9, 10), so that A is there when [10, 11)
     * begins */
    run_frames(sch, 61, 80);
    h.target = 0;
    run_frames(sch, 80, 90);
    expect_one(sch, 90, 1, 1, 1.0);
    run_frames(sch, 91, 95);
    expect_one(sch, 95, 1, 0, 0.5);
    run_frames(sch, 96, 99);
    expect_one(sch, 99, 1, 0, 0.1);
    expect_one(sch, 100, 0, 0, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.changes, 2);
    assert_int_equal(st.morphs, 2);
    assert_int_equal(st.pops, 0);
    assert_int_equal(st.emergencies, 1); /* the first update */
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- successive morphs (Fig. 7) ------------------------------------------- */

/* Runs to t = 4: the host wishes for depth `first` from t = 3 (the selection
 * begun then is for [5, 6)) and for `second` from t = 4 (for [6, 7)). */
static void two_wishes(tclod_scheduler *sch, wish_host *h, uint32_t first, uint32_t second) {
    run_frames(sch, 0, 30);
    h->target = first;
    run_frames(sch, 30, 40);
    h->target = second;
}

static void successive_monotone_up_morphs_follow_each_other(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 3); /* A, B, C */
    sch = wish_scheduler(s, &h, 1, 0);
    /* B wished at 3 (for [5, 6)), C at 4 (for [6, 7)): A -> B during [5, 6),
     * then B -> C during [6, 7) */
    two_wishes(sch, &h, 1, 2);
    run_frames(sch, 40, 55);
    expect_one(sch, 55, 1, 0, 0.5);
    expect_one(sch, 56, 1, 0, 0.6);
    run_frames(sch, 57, 65);
    expect_one(sch, 65, 2, 1, 0.5);
    run_frames(sch, 66, 70);
    expect_one(sch, 70, 2, 2, 1.0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void an_up_morph_overridden_by_a_down_morph_collapses(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_scheduler_stats st;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 3); /* A, B, C */
    sch = wish_scheduler(s, &h, 1, 0);
    /* C wished at 3 (for [5, 6): an up-morph A -> C during [5, 6)), then B at
     * 4 (for [6, 7): a down-morph C -> B, also during [5, 6)). The two
     * collapse into one transition from A, the level at the start of
     * [5, 6), to B, the level required at its end */
    two_wishes(sch, &h, 2, 1);
    run_frames(sch, 40, 50);
    expect_one(sch, 50, 0, 0, 1.0);
    run_frames(sch, 51, 55);
    expect_one(sch, 55, 1, 0, 0.5);
    run_frames(sch, 56, 60);
    expect_one(sch, 60, 1, 1, 1.0);
    run_frames(sch, 61, 80);
    expect_one(sch, 80, 1, 1, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.morphs, 1);
    assert_int_equal(st.pops, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_jump_of_three_levels_is_three_adjacent_morphs(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 4); /* A, B, C, D */
    sch = wish_scheduler(s, &h, 1, 0);
    run_frames(sch, 0, 30);
    h.target = 3;
    run_frames(sch, 30, 50);
    /* during [5, 6): A -> B in [5, 5 1/3), B -> C in [5 1/3, 5 2/3), C -> D
     * in [5 2/3, 6), each from weight 0 to 1 */
    expect_one(sch, 50, 0, 0, 1.0);
    expect_one(sch, 51, 1, 0, 0.3);
    expect_one(sch, 52, 1, 0, 0.6);
    expect_one(sch, 53, 1, 0, 0.9);
    expect_one(sch, 54, 2, 1, 0.2);
    run_frames(sch, 55, 58);
    expect_one(sch, 58, 3, 2, 0.4);
    expect_one(sch, 59, 3, 2, 0.7);
    expect_one(sch, 60, 3, 3, 1.0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* Runs to t = 4 from the finest of `levels` levels, as two_wishes. */
static tclod_scheduler *from_the_finest(tclod_scene **s, wish_host *h, uint32_t levels,
                                        uint32_t first, uint32_t second) {
    tclod_scheduler *sch;
    memset(h, 0, sizeof *h);
    *s = chain(h, levels);
    h->target = levels - 1u;
    sch = wish_scheduler(*s, h, 1, 0);
    two_wishes(sch, h, first, second);
    return sch;
}

static void successive_down_morphs_each_end_when_their_interval_begins(void **state) {
    /* C until B is wished at 3 (for [5, 6)) and A at 4 (for [6, 7)): C -> B
     * during [4, 5), so that B is there when [5, 6) begins, then B -> A
     * during [5, 6), A there at 6; each weight goes from 1 to 0 */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch = from_the_finest(&s, &h, 3, 1, 0);
    tclod_scheduler_stats st;
    (void)state;
    expect_one(sch, 40, 2, 2, 1.0);
    expect_one(sch, 41, 2, 1, 0.9);
    run_frames(sch, 42, 45);
    expect_one(sch, 45, 2, 1, 0.5);
    run_frames(sch, 46, 49);
    expect_one(sch, 49, 2, 1, 0.1);
    expect_one(sch, 50, 1, 1, 1.0);
    expect_one(sch, 51, 1, 0, 0.9);
    run_frames(sch, 52, 55);
    expect_one(sch, 55, 1, 0, 0.5);
    run_frames(sch, 56, 60);
    expect_one(sch, 60, 0, 0, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.morphs, 2);
    assert_int_equal(st.pops, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_down_morph_then_an_up_morph_follow_each_other(void **state) {
    /* C until A is wished at 3 (for [5, 6)) and B at 4 (for [6, 7)): C -> A,
     * two levels, during [4, 5) (C from B in [4, 4.5), B from A in
     * [4.5, 5)); A stays during [5, 6) (Fig. 7a: no conflict), and A -> B
     * runs during [6, 7), B reached at 7 */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch = from_the_finest(&s, &h, 3, 0, 1);
    tclod_scheduler_stats st;
    (void)state;
    expect_one(sch, 40, 2, 2, 1.0);
    run_frames(sch, 41, 42);
    expect_one(sch, 42, 2, 1, 0.6); /* s = 2 (1 - 0.2) = 1.6 */
    run_frames(sch, 43, 47);
    expect_one(sch, 47, 1, 0, 0.6); /* s = 2 (1 - 0.7) = 0.6 */
    run_frames(sch, 48, 50);
    expect_one(sch, 50, 0, 0, 1.0);
    run_frames(sch, 51, 55);
    expect_one(sch, 55, 0, 0, 1.0);
    run_frames(sch, 56, 60);
    expect_one(sch, 60, 0, 0, 1.0);
    expect_one(sch, 61, 1, 0, 0.1);
    run_frames(sch, 62, 65);
    expect_one(sch, 65, 1, 0, 0.5);
    run_frames(sch, 66, 70);
    expect_one(sch, 70, 1, 1, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.morphs, 2);
    assert_int_equal(st.pops, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_downward_jump_of_three_levels_is_three_adjacent_morphs(void **state) {
    /* D until A is wished at 3 (for [5, 6)): during [4, 5), with
     * s = 3 (1 - u), D from C while s > 2, C from B while s > 1, B from A
     * after, each weight s - floor(s); A is there at 5 */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch = from_the_finest(&s, &h, 4, 0, 0);
    (void)state;
    expect_one(sch, 40, 3, 3, 1.0);
    expect_one(sch, 41, 3, 2, 0.7);
    expect_one(sch, 42, 3, 2, 0.4);
    expect_one(sch, 43, 3, 2, 0.1);
    expect_one(sch, 44, 2, 1, 0.8);
    expect_one(sch, 45, 2, 1, 0.5);
    expect_one(sch, 46, 2, 1, 0.2);
    expect_one(sch, 47, 1, 0, 0.9);
    expect_one(sch, 48, 1, 0, 0.6);
    expect_one(sch, 49, 1, 0, 0.3);
    expect_one(sch, 50, 0, 0, 1.0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_split_morphs_each_child_from_its_parent(void **state) {
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch;
    const tclod_draw *items;
    size_t n;
    tclod_id p, c1, c2, g;
    (void)state;
    memset(&h, 0, sizeof h);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &p), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, p, NULL, &c1), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, p, NULL, &c2), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, c1, NULL, &g), TCLOD_OK);
    h.depth[c1] = h.depth[c2] = 1;
    h.depth[g] = 2;
    sch = wish_scheduler(s, &h, 1, 0);
    run_frames(sch, 0, 30);
    h.target = 2; /* P -> {G (two levels down), C2 (one)} */
    run_frames(sch, 30, 53);
    /* [5, 5.5): the first level, both children from P */
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    assert_int_equal(items[0].coarse, p);
    assert_int_equal(items[1].coarse, p);
    assert_true((items[0].fine == c1 && items[1].fine == c2) ||
                (items[0].fine == c2 && items[1].fine == c1));
    assert_float_equal(items[0].weight, 0.4, 1e-5);
    assert_float_equal(items[1].weight, 0.4, 1e-5);
    /* [5.5, 6): C2 stays, G morphs from C1 */
    run_frames(sch, 53, 58);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    {
        const tclod_draw *gi = items[0].fine == g ? &items[0] : &items[1];
        const tclod_draw *ci = items[0].fine == g ? &items[1] : &items[0];
        assert_int_equal(gi->fine, g);
        assert_int_equal(gi->coarse, c1);
        assert_float_equal(gi->weight, 0.4, 1e-5);
        assert_int_equal(ci->fine, c2);
        assert_int_equal(ci->coarse, c2);
    }
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* The split above, with scene edits mid-morph: at t = 5.2 both children morph
 * from P; C2 removed then is gone from the next update's draw list (C1 still
 * morphs from P), and with P removed too (its subtree with it) nothing is
 * drawn at the update after. */
static void a_removed_node_leaves_the_draw_list_mid_morph(void **state) {
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch;
    const tclod_draw *items;
    size_t n;
    tclod_id p, c1, c2, g;
    (void)state;
    memset(&h, 0, sizeof h);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &p), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, p, NULL, &c1), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, p, NULL, &c2), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, c1, NULL, &g), TCLOD_OK);
    h.depth[c1] = h.depth[c2] = 1;
    h.depth[g] = 2;
    sch = wish_scheduler(s, &h, 1, 0);
    run_frames(sch, 0, 30);
    h.target = 2;
    run_frames(sch, 30, 53);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    /* edits between updates are allowed although a selection is under way */
    assert_int_equal(tclod_scene_remove_node(s, c2), TCLOD_OK);
    run_frames(sch, 53, 54);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, c1);
    assert_int_equal(items[0].coarse, p);
    assert_int_equal(tclod_scene_remove_node(s, p), TCLOD_OK);
    run_frames(sch, 54, 55);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    /* and it goes on: a new root is drawn once a selection with it lands */
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &p), TCLOD_OK);
    h.depth[p] = 0;
    run_frames(sch, 55, 80);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, p);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* An additive node A with one child B, which costs more than the budget
 * (1000 of 100) until t = 3 and 2 from then on: B fades in during [5, 6)
 * from A, which stays drawn as it is: the draw list holds A (A <- A, weight
 * 1) and B (B <- A, the weight rising), and both at the end. */
static void an_additive_node_stays_drawn_while_its_child_fades_in(void **state) {
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch;
    const tclod_draw *items;
    size_t n, k;
    tclod_node_desc d;
    tclod_id a, b;
    (void)state;
    memset(&h, 0, sizeof h);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    tclod_node_desc_default(&d);
    d.refine = TCLOD_REFINE_ADD;
    assert_int_equal(tclod_scene_add_node_desc(s, &d, &a), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, a, NULL, &b), TCLOD_OK);
    h.depth[b] = 1;
    h.cost[b] = 1000.0;
    sch = wish_scheduler(s, &h, 1, 0);
    run_frames(sch, 0, 30);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, a);
    h.cost[b] = 0.0;
    run_frames(sch, 30, 56);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    for (k = 0; k < n; ++k) {
        if (items[k].fine == a) {
            assert_int_equal(items[k].coarse, a);
            assert_float_equal(items[k].weight, 1.0, 0.0);
        } else {
            assert_int_equal(items[k].fine, b);
            assert_int_equal(items[k].coarse, a);
            assert_float_equal(items[k].weight, 0.5, 1e-5);
        }
    }
    run_frames(sch, 56, 61);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    assert_float_equal(items[0].weight, 1.0, 0.0);
    assert_float_equal(items[1].weight, 1.0, 0.0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_region_that_would_cost_more_while_it_morphs_switches(void **state) {
    /* A costs 5 and its child B 2, against "a node costs no more than the
     * nodes below it". B, wished from 3, lands as S_5: the up-morph A -> B
     * of [5, 6) would draw A (5) at its start, more than S_5's B (2) in that
     * region, so B is drawn as it is from 5 on: a switch, one pop. A, wished
     * from 8, lands as S_10: the down-morph B -> A of [9, 10) would end at
     * A (5), more than S_9's B, so B stays until A is switched in at 10:
     * another pop. No morph at all. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_scheduler_stats st;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 2);
    h.cost[0] = 5.0;
    h.cost[1] = 2.0;
    sch = wish_scheduler(s, &h, 1, 0);
    run_frames(sch, 0, 30);
    h.target = 1;
    run_frames(sch, 30, 49);
    expect_one(sch, 49, 0, 0, 1.0);
    expect_one(sch, 50, 1, 1, 1.0);
    run_frames(sch, 51, 55);
    expect_one(sch, 55, 1, 1, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.changes, 1);
    assert_int_equal(st.pops, 1);
    assert_int_equal(st.morphs, 0);
    run_frames(sch, 56, 80);
    h.target = 0;
    run_frames(sch, 80, 95);
    expect_one(sch, 95, 1, 1, 1.0);
    run_frames(sch, 96, 99);
    expect_one(sch, 99, 1, 1, 1.0);
    expect_one(sch, 100, 0, 0, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.changes, 2);
    assert_int_equal(st.pops, 2);
    assert_int_equal(st.morphs, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- smooth resolutions -------------------------------------------------- */

static void smooth_resolutions_move_linearly_with_the_same_asymmetry(void **state) {
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch;
    tclod_id root, a, b;
    float ba[4] = {-2.0f, 0.0f, -10.0f, 1.0f}, bb[4] = {2.0f, 0.0f, -10.0f, 1.0f};
    tclod_view v;
    double a0, b0, a1, b1;
    uint32_t f;
    (void)state;
    memset(&h, 0, sizeof h);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &root), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(s, ba, &a), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(s, bb, &b), TCLOD_OK);
    h.weight[a] = h.weight[b] = 1.0;
    sch = wish_scheduler(s, &h, 1, 1);
    helper_view(&v);
    /* budget 2: the root costs 1 and the two objects share the other 1; with
     * benefit w sqrt(r) and cost r the optimum has r proportional to w²:
     * 1/2 each for equal weights, 9/10 and 1/10 once a is worth 3 times b */
    for (f = 0; f < 30; ++f)
        assert_int_equal(tclod_scheduler_update(sch, f / 10.0, &v, 2.0, 0.0), TCLOD_OK);
    a0 = tclod_scheduler_resolution(sch, a);
    b0 = tclod_scheduler_resolution(sch, b);
    assert_float_equal(a0, 0.5, 1e-3);
    assert_float_equal(b0, 0.5, 1e-3);
    h.weight[a] = 3.0;
    for (f = 30; f < 80; ++f)
        assert_int_equal(tclod_scheduler_update(sch, f / 10.0, &v, 2.0, 0.0), TCLOD_OK);
    a1 = tclod_scheduler_resolution(sch, a);
    b1 = tclod_scheduler_resolution(sch, b);
    assert_float_equal(a1, 0.9, 1e-2);
    assert_float_equal(b1, 0.1, 1e-2);
    tclod_scheduler_destroy(sch);
    /* again, checking the path: b comes down during [4, 5), reaching b1 when
     * [5, 6) begins; a goes up during [5, 6), reaching a1 at its end */
    h.weight[a] = 1.0;
    sch = wish_scheduler(s, &h, 1, 1);
    for (f = 0; f < 80; ++f) {
        double t = f / 10.0, ra, rb, u = t - floor(t + 1e-9);
        if (f == 30)
            h.weight[a] = 3.0;
        assert_int_equal(tclod_scheduler_update(sch, t, &v, 2.0, 0.0), TCLOD_OK);
        ra = tclod_scheduler_resolution(sch, a);
        rb = tclod_scheduler_resolution(sch, b);
        if (f < 40) {
            assert_float_equal(ra, a0, 1e-9);
            assert_float_equal(rb, b0, 1e-9);
        } else if (f < 50) {
            assert_float_equal(ra, a0, 1e-9);
            assert_float_equal(rb, b0 + (b1 - b0) * u, 1e-9);
        } else if (f < 60) {
            assert_float_equal(ra, a0 + (a1 - a0) * u, 1e-9);
            assert_float_equal(rb, b1, 1e-9);
        } else {
            assert_float_equal(ra, a1, 1e-9);
            assert_float_equal(rb, b1, 1e-9);
        }
    }
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- two stages ------------------------------------------------------------ */

static void without_morphing_a_selection_switches_in_at_its_interval(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_scheduler_stats st;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 3);
    sch = wish_scheduler(s, &h, 0, 0);
    /* the selection begun at 3 is for [4, 5) and replaces A at 4, two
     * levels at once */
    run_frames(sch, 0, 30);
    h.target = 2;
    run_frames(sch, 30, 39);
    expect_one(sch, 39, 0, 0, 1.0);
    expect_one(sch, 40, 2, 2, 1.0);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.changes, 1);
    assert_int_equal(st.pops, 1);
    assert_int_equal(st.morphs, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- the budget invariant over random paths ------------------------------ */

/* Whether a is a proper ancestor of b. */
static int is_ancestor(const tclod_scene *s, tclod_id a, tclod_id b) {
    for (b = tclod_scene_parent(s, b); b != TCLOD_NONE; b = tclod_scene_parent(s, b))
        if (b == a)
            return 1;
    return 0;
}

/* The random world with smooth objects ("trees") at random places: object i
 * is worth weight[i] * area * sqrt(r) (area: its projected px²) and costs
 * k[i] r whatever the view. The nodes keep the world's own callbacks. */
#define TREES 60u
typedef struct tree_world {
    world_scene w;
    double weight[TREES], k[TREES];
    const tclod_id *order; /* the scene's smooth order, TREES entries */
} tree_world;

static double tree_benefit(void *user, const tclod_query *q) {
    return world_benefit(&((tree_world *)user)->w, q);
}

static double tree_cost(void *user, const tclod_query *q) {
    return world_cost(&((tree_world *)user)->w, q);
}

static double tree_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    const tree_world *t = (const tree_world *)user;
    double w = 0.0, area = q->screen_area > 0.0f ? (double)q->screen_area : 0.0;
    uint32_t k;
    for (k = 0; k < q->count; ++k)
        w += t->weight[q->members[k]];
    *d_dr = 0.5 * w * area / sqrt(r);
    return w * area * sqrt(r);
}

static double tree_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    const tree_world *t = (const tree_world *)user;
    double k = 0.0;
    uint32_t i;
    for (i = 0; i < q->count; ++i)
        k += t->k[q->members[i]];
    *d_dr = k;
    return k * r;
}

/* `cost` plus the cost of this frame's smooth resolutions from the trees'
 * own formula, added in the smooth order (the order of the selection's
 * groups, one object each without splitting), as the scheduler adds its
 * groups' after its draw list; asserts every resolution is in [0, 1]. */
static double check_resolutions(const tclod_scheduler *sch, const tree_world *t, double cost) {
    uint32_t p;
    for (p = 0; p < TREES; ++p) {
        tclod_id i = t->order[p];
        double r = tclod_scheduler_resolution(sch, i);
        assert_true(r >= 0.0 && r <= 1.0);
        if (r > 0.0)
            cost += t->k[i] * r;
    }
    return cost;
}

/* Asserts the draw list is well formed and returns its cost from the
 * world's own table. */
static double check_draws(const tclod_scheduler *sch, const world_scene *w) {
    const tclod_draw *items;
    size_t n, i, j;
    double cost = 0.0;
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    for (i = 0; i < n; ++i) {
        assert_true(items[i].fine < w->node_count);
        assert_true(items[i].weight >= 0.0f && items[i].weight <= 1.0f);
        if (items[i].fine == items[i].coarse)
            assert_true(items[i].weight == 1.0f);
        else
            assert_int_equal(tclod_scene_parent(w->scene, items[i].fine), items[i].coarse);
        cost += (double)w->cost_ms[items[i].fine];
    }
    for (i = 0; i < n && n < 400u; ++i)
        for (j = 0; j < n; ++j)
            if (i != j) {
                assert_true(items[i].fine != items[j].fine);
                assert_false(is_ancestor(w->scene, items[i].fine, items[j].fine));
            }
    return cost;
}

static void draw_lists_stay_within_the_budget_over_random_paths(void **state) {
    /* 32 trials: the greedy and Robin Hood solvers over the world's nodes,
     * and (the last 8) the mixed solver over its nodes and trees, where the
     * draw list's cost includes the trees' at this frame's resolutions */
    world_random_desc wd;
    tree_world *tw = (tree_world *)calloc(1, sizeof *tw);
    world_scene *w;
    table_rng rng;
    uint32_t trial, i, count = 0;
    tclod_id id;
    (void)state;
    assert_non_null(tw);
    w = &tw->w;
    world_random_desc_default(&wd);
    wd.objects = 150;
    wd.spacing = 12.0f;
    assert_int_equal(world_build_random(&wd, w), TCLOD_OK);
    table_rng_seed(&rng, 4004u);
    for (i = 0; i < TREES; ++i) {
        float b[4];
        b[0] = (float)table_rng_uniform(&rng, 0.0, w->side);
        b[1] = 2.0f;
        b[2] = (float)table_rng_uniform(&rng, 0.0, w->side);
        b[3] = 2.0f;
        tw->weight[i] = table_rng_uniform(&rng, 0.2, 1.0);
        tw->k[i] = table_rng_uniform(&rng, 2e-4, 2e-3);
        assert_int_equal(tclod_scene_add_smooth(w->scene, b, &id), TCLOD_OK);
        assert_int_equal(id, i);
    }
    assert_int_equal(tclod_scene_smooth_order(w->scene, &tw->order, &count), TCLOD_OK);
    assert_int_equal(count, TREES);
    for (trial = 0; trial < 32u; ++trial) {
        tclod_selector_desc sd;
        tclod_scheduler_desc d;
        tclod_scheduler *sch = NULL;
        tclod_scheduler_stats st;
        tclod_view v;
        double t = 0.0, speed = table_rng_uniform(&rng, 1.0, 30.0), heading, turn;
        double budget = table_rng_uniform(&rng, 0.002, 0.05);
        int mixed = trial >= 24u;
        uint32_t f, drawn_trees = 0;
        tclod_selector_desc_default(&sd);
        sd.callbacks = world_callbacks(w);
        sd.solver = trial % 3u == 2u ? TCLOD_SOLVER_ROBIN_HOOD : TCLOD_SOLVER_GREEDY;
        sd.cold_start = !((int)(trial % 2u));
        if (mixed) {
            sd.solver = TCLOD_SOLVER_MIXED;
            sd.callbacks.benefit = tree_benefit;
            sd.callbacks.cost = tree_cost;
            sd.callbacks.smooth_benefit = tree_smooth_benefit;
            sd.callbacks.smooth_cost = tree_smooth_cost;
            sd.callbacks.user = tw;
        }
        tclod_scheduler_desc_default(&d);
        d.tau = table_rng_uniform(&rng, 0.1, 0.6);
        d.samples = 1u + table_rng_below(&rng, TCLOD_MAX_SAMPLES);
        d.confidence = table_rng_uniform(&rng, 0.0, 2.0);
        d.max_speed = speed;
        d.max_turn_rate = 1.0;
        d.two_stage = !(trial % 4u != 3u);
        assert_int_equal(tclod_scheduler_create(w->scene, &sd, &d, NULL, &sch), TCLOD_OK);
        helper_walk_start(w, &rng, &v, &heading, &turn);
        for (f = 0; f < 400u; ++f) {
            double dt = table_rng_uniform(&rng, 0.005, 0.05), slice;
            /* now and then the path turns the other way, or the budget
             * falls or rises */
            if (table_rng_below(&rng, 60) == 0)
                turn = table_rng_uniform(&rng, -1.0, 1.0);
            if (table_rng_below(&rng, 80) == 0)
                budget *= table_rng_uniform(&rng, 0.5, 1.5);
            t += dt;
            helper_walk_step(&v, speed, turn, dt, &heading);
            slice = table_rng_below(&rng, 4) == 0 ? 0.0 : table_rng_uniform(&rng, 1e-6, 2e-4);
            assert_int_equal(tclod_scheduler_update(sch, t, &v, budget, slice), TCLOD_OK);
            assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
            {
                double nodes = check_draws(sch, w), cost = check_resolutions(sch, tw, nodes);
                if (!(cost <= budget))
                    fail_msg("trial %u frame %u: draw list costs %.17g > budget %.17g", trial, f,
                             cost, budget);
                assert_true(st.draw_cost <= st.budget);
                if (mixed) { /* the trees' costs in st are their selection's, >= these */
                    assert_true(cost <= st.draw_cost);
                    drawn_trees += cost > nodes;
                } else {
                    assert_true(cost == nodes);
                    assert_float_equal(st.draw_cost, cost, 1e-12 + 1e-9 * cost);
                }
            }
        }
        assert_true(st.selections > 0u);
        assert_int_equal(st.changes, st.morphs + st.pops);
        if (mixed)
            assert_true(drawn_trees > 0u);
        tclod_scheduler_destroy(sch);
    }
    world_scene_free(w);
    free(tw);
}

/* A Robin Hood scheduler hands the host's importance callback through with
 * the host's user pointer (it wraps the others with its own). */
static const world_scene *importance_world;
static unsigned importance_calls;

static double checked_importance(void *user, const tclod_query *q) {
    assert_ptr_equal(user, importance_world);
    importance_calls++;
    return world_importance(user, q);
}

static void the_scheduler_asks_the_hosts_importance_with_the_hosts_user(void **state) {
    world_random_desc wd;
    world_scene w;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    tclod_view v;
    uint32_t f;
    (void)state;
    world_random_desc_default(&wd);
    wd.objects = 150;
    assert_int_equal(world_build_random(&wd, &w), TCLOD_OK);
    tclod_selector_desc_default(&sd);
    sd.solver = TCLOD_SOLVER_ROBIN_HOOD;
    sd.callbacks = world_callbacks(&w);
    sd.callbacks.importance = checked_importance;
    importance_world = &w;
    importance_calls = 0;
    tclod_scheduler_desc_default(&d);
    assert_int_equal(tclod_scheduler_create(w.scene, &sd, &d, NULL, &sch), TCLOD_OK);
    for (f = 0; f < 30u; ++f) {
        world_camera_at(&w.path, (double)f / 2400.0, &v);
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 60.0, &v, 0.05, 0.0), TCLOD_OK);
    }
    assert_true(importance_calls > 0u);
    tclod_scheduler_destroy(sch);
    world_scene_free(&w);
}

/* ---- arguments -------------------------------------------------------------- */

static void bad_arguments_are_refused_and_change_nothing(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch = NULL;
    tclod_scheduler_desc d;
    tclod_selector_desc sd;
    tclod_view v, bad;
    const tclod_draw *items;
    size_t n = 7;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 2);
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = wish_benefit;
    sd.callbacks.cost = wish_cost;
    sd.callbacks.user = &h;
    tclod_scheduler_desc_default(&d);
    assert_float_equal(d.tau, 0.5, 0.0);
    assert_int_equal(d.samples, 3);
    assert_int_equal(d.two_stage, 0);
    {
        /* tau: a normal positive number whose 4 tau is finite, or 0 for
         * the default. 1e-310 is subnormal; DBL_MAX / 2 doubles to infinity
         * (the pipeline restarts after a gap of 4 tau); DBL_MAX / 4 and
         * DBL_MIN are the ends accepted */
        static const double bad_tau[] = {-0.5,    1e-310,   -DBL_MIN, DBL_MAX / 2.0,
                                         DBL_MAX, INFINITY, NAN};
        static const double good[] = {0.0, DBL_MIN, 1e-300, DBL_MAX / 4.0};
        size_t i;
        for (i = 0; i < sizeof bad_tau / sizeof bad_tau[0]; ++i) {
            d.tau = bad_tau[i];
            if (tclod_scheduler_create(s, &sd, &d, NULL, &sch) != TCLOD_ERR_ARG)
                fail_msg("tau = %g accepted", bad_tau[i]);
            assert_null(sch);
        }
        for (i = 0; i < sizeof good / sizeof good[0]; ++i) {
            d.tau = good[i];
            if (tclod_scheduler_create(s, &sd, &d, NULL, &sch) != TCLOD_OK)
                fail_msg("tau = %g refused", good[i]);
            tclod_scheduler_destroy(sch);
            sch = NULL;
        }
    }
    d.tau = 0.5;
    d.samples = TCLOD_MAX_SAMPLES + 1u;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
    d.samples = 3;
    d.confidence = NAN;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
    d.confidence = 1.0;
    d.max_speed = -1.0;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
    d.max_speed = 0.0;
    d.calib.rise_rate = 2.0;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
    tclod_scheduler_desc_default(&d);
    sd.callbacks.cost = NULL;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
    sd.callbacks.cost = wish_cost;
    assert_null(sch);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_int_equal(tclod_scheduler_report_frame(sch, 1.0, TCLOD_OFF), TCLOD_ERR_STATE);
    helper_view(&v);
    bad = v;
    bad.fov_y = 0.0f;
    assert_int_equal(tclod_scheduler_update(sch, 1.0, &v, 10.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(tclod_scheduler_update(sch, 0.5, &v, 10.0, 0.0), TCLOD_ERR_ARG); /* back */
    assert_int_equal(tclod_scheduler_update(sch, NAN, &v, 10.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &bad, 10.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(sch, 2.0, NULL, 10.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &v, -1.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &v, NAN, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &v, 10.0, -1.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_update(NULL, 2.0, &v, 10.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(tclod_scheduler_report_frame(sch, -1.0, TCLOD_OFF), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report_frame(sch, NAN, TCLOD_OFF), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report_frame(NULL, 1.0, TCLOD_OFF), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_draws(NULL, &items, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_get_stats(sch, NULL), TCLOD_ERR_ARG);
    assert_float_equal(tclod_scheduler_resolution(sch, 0), 0.0, 0.0);
    assert_float_equal(tclod_scheduler_resolution(NULL, 0), 0.0, 0.0);
    tclod_scheduler_destroy(sch);
    tclod_scheduler_destroy(NULL);
    tclod_scene_destroy(s);
}

/* ---- failed updates ---------------------------------------------------------- */

static tclod_scheduler_stats stats_of(const tclod_scheduler *sch) {
    tclod_scheduler_stats st;
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    return st;
}

/* Whether two stats are the same but for the time they measure. */
static int same_stats(const tclod_scheduler_stats *a, const tclod_scheduler_stats *b) {
    return a->draw_cost == b->draw_cost && a->budget == b->budget && a->draws == b->draws &&
           a->morphing == b->morphing && a->selections == b->selections &&
           a->unfinished == b->unfinished && a->emergencies == b->emergencies &&
           a->changes == b->changes && a->morphs == b->morphs && a->pops == b->pops &&
           a->invalid_values == b->invalid_values && a->selection_benefit == b->selection_benefit &&
           a->selection_cost == b->selection_cost;
}

/* Asserts that two schedulers show the same draw list and stats. */
static void assert_same_outputs(const tclod_scheduler *a, const tclod_scheduler *b, double t) {
    const tclod_draw *ia = NULL, *ib = NULL;
    size_t na = 0, nb = 0;
    tclod_scheduler_stats sa = stats_of(a), sb = stats_of(b);
    assert_int_equal(tclod_scheduler_draws(a, &ia, &na), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(b, &ib, &nb), TCLOD_OK);
    if (na != nb || (na && memcmp(ia, ib, na * sizeof *ia) != 0))
        fail_msg("t = %.1f: the draw lists differ (%u and %u items)", t, (unsigned)na,
                 (unsigned)nb);
    if (!same_stats(&sa, &sb))
        fail_msg("t = %.1f: the stats differ (selections %u and %u, morphs %u and %u)", t,
                 (unsigned)sa.selections, (unsigned)sb.selections, (unsigned)sa.morphs,
                 (unsigned)sb.morphs);
}

static void a_strict_update_that_fails_at_a_boundary_changes_nothing(void **state) {
    /* Strict mode, tau = 1, beside a scheduler that never fails. B is wished
     * from 3. The update at 3, a boundary, lands the selection begun at 2
     * and begins the one for [5, 6), whose first cost is NaN: it fails with
     * TCLOD_ERR_CALLBACK, and must leave the draw list and the stats as they
     * were. Retried at the same time with good values it does what the
     * failed one should have done: the selection for [5, 6) is made, lands
     * at 4, and A -> B runs during [5, 6) (weight 0.5 at 5.5, B at 6), not
     * one interval later; every output after it is the other scheduler's. */
    wish_host h, ref_h;
    tclod_scene *s;
    tclod_scheduler *sch, *ref;
    tclod_scheduler_stats before;
    const tclod_draw *items = NULL;
    size_t n = 0;
    tclod_view v;
    uint32_t f;
    (void)state;
    memset(&h, 0, sizeof h);
    h.strict = 1;
    s = chain(&h, 2);
    ref_h = h;
    sch = wish_scheduler(s, &h, 1, 0);
    ref = wish_scheduler(s, &ref_h, 1, 0);
    run_frames(sch, 0, 30);
    run_frames(ref, 0, 30);
    h.target = ref_h.target = 1;
    h.nan_costs = 1;
    before = stats_of(sch);
    helper_view(&v);
    assert_int_equal(tclod_scheduler_update(sch, 3.0, &v, 100.0, 0.0), TCLOD_ERR_CALLBACK);
    assert_int_equal(h.nan_costs, 0);
    {
        tclod_scheduler_stats after = stats_of(sch);
        assert_true(same_stats(&before, &after) && before.select_seconds == after.select_seconds);
    }
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, 0);
    assert_same_outputs(sch, ref, 2.9);
    for (f = 30; f < 70u; ++f) {
        run_frames(sch, f, f + 1u);
        run_frames(ref, f, f + 1u);
        assert_same_outputs(sch, ref, (double)f / 10.0);
    }
    tclod_scheduler_destroy(sch);
    sch = wish_scheduler(s, &h, 1, 0); /* the morph of [5, 6), by expect_one */
    h.nan_costs = 0;
    h.target = 0;
    run_frames(sch, 0, 30);
    h.target = 1;
    h.nan_costs = 1;
    assert_int_equal(tclod_scheduler_update(sch, 3.0, &v, 100.0, 0.0), TCLOD_ERR_CALLBACK);
    run_frames(sch, 30, 55);
    expect_one(sch, 55, 1, 0, 0.5);
    run_frames(sch, 56, 60);
    expect_one(sch, 60, 1, 1, 1.0);
    assert_int_equal(stats_of(sch).selections, 6); /* one per boundary, 1 to 6 */
    tclod_scheduler_destroy(ref);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_selection_under_way_when_an_update_fails_is_begun_again(void **state) {
    /* 40 objects of three levels, strict mode, the host wishing for the
     * finest; slices of 1e-300 s end a step at every 16th increment, so the
     * selection begun at 0 is still under way after the first update. The
     * update at 0.1 continues it and meets a NaN cost: it fails, and the
     * selection's progress is lost. The update retried at 0.1 begins it
     * again; from then on every draw list and all the stats are those of a
     * scheduler that never failed, the selection landing at 1 as its did. */
    wish_host h, ref_h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch, *ref;
    tclod_view v;
    tclod_id id, parent;
    uint32_t f, k, level;
    (void)state;
    memset(&h, 0, sizeof h);
    h.strict = 1;
    h.target = 2;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < 40u; ++k)
        for (level = 0, parent = TCLOD_NONE; level < 3u; ++level, parent = id) {
            assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
            h.depth[id] = level;
        }
    ref_h = h;
    sch = wish_scheduler(s, &h, 1, 0);
    ref = wish_scheduler(s, &ref_h, 1, 0);
    helper_view(&v);
    for (f = 0; f < 25u; ++f) {
        double t = (double)f / 10.0;
        if (f == 1u) {
            h.nan_costs = 1;
            assert_int_equal(tclod_scheduler_update(sch, t, &v, 1000.0, 1e-300),
                             TCLOD_ERR_CALLBACK);
            assert_int_equal(h.nan_costs, 0);
            assert_same_outputs(sch, ref, 0.0);
        }
        assert_int_equal(tclod_scheduler_update(sch, t, &v, 1000.0, 1e-300), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(ref, t, &v, 1000.0, 1e-300), TCLOD_OK);
        assert_same_outputs(sch, ref, t);
    }
    assert_int_equal(stats_of(sch).selections, 2);
    assert_int_equal(stats_of(sch).draws, 40);
    tclod_scheduler_destroy(ref);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_failed_update_puts_the_warm_start_back(void **state) {
    /* Two objects, X (A_X = 0 -> B_X = 1) and Y (A_Y = 2 -> B_Y = 3), both
     * refined under a budget of 100; warm starts, strict mode, a turn rate
     * so that the conservative camera is wider than the view. At 2.5 the
     * budget falls to 3: the draw list (4) is over it and the scheduler
     * selects at once, from the selector's last selection {B_X, B_Y}, by one
     * decrement. The first try sees B_X worth 21 (X loses 11 per unit saved,
     * Y 10: Y is decremented, {B_X, A_Y}) and then a NaN under the
     * conservative camera, and fails. The retry sees B_X worth 20 again:
     * equal losses, the smaller id first, so X is decremented, {A_X, B_Y},
     * as for a scheduler that never failed -- but only if the retry starts
     * from {B_X, B_Y} again, since {B_X, A_Y} fits and no swap gains. */
    wish_host h, ref_h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch[2];
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    const tclod_draw *items = NULL;
    size_t n = 0;
    tclod_view v;
    tclod_id id;
    uint32_t f, k;
    (void)state;
    memset(&h, 0, sizeof h);
    h.strict = 1;
    h.target = 1;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < 4u; ++k) {
        assert_int_equal(tclod_scene_add_node(s, k % 2u ? k - 1u : TCLOD_NONE, NULL, &id),
                         TCLOD_OK);
        h.depth[id] = k % 2u;
    }
    ref_h = h;
    for (k = 0; k < 2u; ++k) {
        tclod_selector_desc_default(&sd);
        sd.callbacks.benefit = wish_benefit;
        sd.callbacks.cost = wish_cost;
        sd.callbacks.user = k ? &ref_h : &h;
        sd.strict = 1;
        tclod_scheduler_desc_default(&d);
        d.tau = 1.0;
        d.samples = 1;
        d.max_turn_rate = 0.1;
        assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch[k]), TCLOD_OK);
    }
    helper_view(&v);
    for (f = 0; f < 40u; ++f) {
        double t = (double)f / 10.0, budget = f < 25u ? 100.0 : 3.0;
        if (f == 25u) {
            h.benefit[1] = 21.0;
            h.nan_wide = 1;
            assert_int_equal(tclod_scheduler_update(sch[0], t, &v, budget, 0.0),
                             TCLOD_ERR_CALLBACK);
            assert_same_outputs(sch[0], sch[1], t);
            h.benefit[1] = 0.0;
            h.nan_wide = 0;
        }
        for (k = 0; k < 2u; ++k)
            assert_int_equal(tclod_scheduler_update(sch[k], t, &v, budget, 0.0), TCLOD_OK);
        assert_same_outputs(sch[0], sch[1], t);
        if (f != 25u)
            continue;
        assert_int_equal(tclod_scheduler_draws(sch[0], &items, &n), TCLOD_OK);
        assert_int_equal(n, 2);
        assert_true((items[0].fine == 0 && items[1].fine == 3) ||
                    (items[0].fine == 3 && items[1].fine == 0));
    }
    tclod_scheduler_destroy(sch[1]);
    tclod_scheduler_destroy(sch[0]);
    tclod_scene_destroy(s);
}

/* 40 objects of three levels, each worth 10 (depth + 1) and costing
 * depth + 1; the eye x of the first benefit call since `first_x` was reset
 * (NAN), and NaN for views beyond x = nan_beyond (when > 0). */
typedef struct path_host {
    double first_x, nan_beyond;
} path_host;

static double path_benefit(void *user, const tclod_query *q) {
    path_host *h = (path_host *)user;
    double x = (double)q->view->eye[0];
    if (h->first_x != h->first_x)
        h->first_x = x;
    if (h->nan_beyond > 0.0 && x > h->nan_beyond)
        return (double)NAN;
    return 10.0 * (double)(q->id % 3u + 1u);
}

static double path_cost(void *user, const tclod_query *q) {
    (void)user;
    return (double)(q->id % 3u + 1u);
}

static void a_failed_update_begins_the_lost_selection_again_with_its_views(void **state) {
    /* Strict mode, tau = 1, one sample, updates once a second with the eye
     * at x = t; slices of 1e-300 s end a step at every 16th increment, so a
     * selection of the 80 increments is still under way at the boundary
     * after the one it began at. At 2 the selection begun at 1 (for [3, 4),
     * its sample at x = 3.5) is ended and lands, the one for [4, 5) begins
     * with its sample at x = 4.5, and the first benefit there is NaN: the
     * update fails and must show what it showed. The retry at 2 begins the
     * lost selection again with its own view (the first benefit it asks is
     * at x = 3.5, not 4.5), runs it to its end when it lands (not counted
     * as unfinished) and then begins the next. */
    path_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler_stats before;
    const tclod_draw *items = NULL, *kept = NULL;
    size_t n = 0, n_kept = 0;
    tclod_view v;
    tclod_id id, parent;
    uint32_t k, level;
    (void)state;
    memset(&h, 0, sizeof h);
    h.first_x = (double)NAN;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < 40u; ++k)
        for (level = 0, parent = TCLOD_NONE; level < 3u; ++level, parent = id)
            assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = path_benefit;
    sd.callbacks.cost = path_cost;
    sd.callbacks.user = &h;
    sd.strict = 1;
    sd.cold_start = 1;
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.samples = 1;
    d.confidence = TCLOD_OFF;
    d.max_speed = 2.0;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    helper_view(&v);
    for (k = 0; k < 2u; ++k) {
        v.eye[0] = (float)k;
        assert_int_equal(tclod_scheduler_update(sch, (double)k, &v, 1000.0, 1e-300), TCLOD_OK);
    }
    before = stats_of(sch);
    assert_int_equal(tclod_scheduler_draws(sch, &kept, &n_kept), TCLOD_OK);
    v.eye[0] = 2.0f;
    h.nan_beyond = 4.0;
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &v, 1000.0, 1e-300), TCLOD_ERR_CALLBACK);
    {
        tclod_scheduler_stats after = stats_of(sch);
        assert_true(same_stats(&before, &after));
    }
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_ptr_equal(items, kept);
    assert_int_equal(n, n_kept);
    h.nan_beyond = 0.0;
    h.first_x = (double)NAN;
    assert_int_equal(tclod_scheduler_update(sch, 2.0, &v, 1000.0, 1e-300), TCLOD_OK);
    assert_float_equal(h.first_x, 3.5, 1e-4);
    assert_int_equal(stats_of(sch).selections, before.selections + 1u);
    assert_int_equal(stats_of(sch).unfinished, before.unfinished);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_failed_update_records_no_camera(void **state) {
    /* 20 updates at 20 Hz along a zigzag (x = t + 0.1 at odd frames), tau =
     * 1 s: the prediction fits all 16 views the path keeps. An update at 1,
     * a boundary, with the eye far off at x = 100 fails on a NaN cost; the
     * prediction is then what it was, though the ring was full and the
     * failed update wrote over its oldest view. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_view v, p1, p2;
    uint32_t f;
    (void)state;
    memset(&h, 0, sizeof h);
    h.strict = 1;
    s = chain(&h, 2);
    sch = wish_scheduler(s, &h, 1, 0);
    helper_view(&v);
    for (f = 0; f < 20u; ++f) {
        v.eye[0] = (float)((double)f / 20.0 + (f % 2u ? 0.1 : 0.0));
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 20.0, &v, 100.0, 0.0), TCLOD_OK);
    }
    assert_int_equal(tclod_scheduler_predict(sch, 2.0, &p1), TCLOD_OK);
    v.eye[0] = 100.0f;
    h.nan_costs = 1;
    assert_int_equal(tclod_scheduler_update(sch, 1.0, &v, 100.0, 0.0), TCLOD_ERR_CALLBACK);
    assert_int_equal(tclod_scheduler_predict(sch, 2.0, &p2), TCLOD_OK);
    assert_memory_equal(&p1, &p2, sizeof p1);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_failed_update_after_a_removal_shows_what_it_showed(void **state) {
    /* a root (cost 1) and two smooth objects of equal weight under a budget
     * of 2 settle at r = 1/2 each. Object a is then removed and the next
     * update fails on a NaN cost: the draw list and both resolutions stay
     * as the last successful update showed them; the update after drops a */
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch;
    tclod_id root, a, b;
    float ba[4] = {-2.0f, 0.0f, -10.0f, 1.0f}, bb[4] = {2.0f, 0.0f, -10.0f, 1.0f};
    const tclod_draw *items;
    size_t n;
    tclod_view v;
    uint32_t f;
    (void)state;
    memset(&h, 0, sizeof h);
    h.strict = 1;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &root), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(s, ba, &a), TCLOD_OK);
    assert_int_equal(tclod_scene_add_smooth(s, bb, &b), TCLOD_OK);
    h.weight[a] = h.weight[b] = 1.0;
    sch = wish_scheduler(s, &h, 1, 1);
    helper_view(&v);
    for (f = 0; f < 30; ++f)
        assert_int_equal(tclod_scheduler_update(sch, f / 10.0, &v, 2.0, 0.0), TCLOD_OK);
    assert_float_equal(tclod_scheduler_resolution(sch, a), 0.5, 1e-3);
    assert_int_equal(tclod_scene_remove_smooth(s, a), TCLOD_OK);
    h.nan_costs = 1;
    assert_int_equal(tclod_scheduler_update(sch, 3.0, &v, 2.0, 0.0), TCLOD_ERR_CALLBACK);
    assert_float_equal(tclod_scheduler_resolution(sch, a), 0.5, 1e-3);
    assert_float_equal(tclod_scheduler_resolution(sch, b), 0.5, 1e-3);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, root);
    assert_int_equal(tclod_scheduler_update(sch, 3.0, &v, 2.0, 0.0), TCLOD_OK);
    assert_float_equal(tclod_scheduler_resolution(sch, a), 0.0, 0.0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_slower_machine_lowers_the_budget_through_the_calibration(void **state) {
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_scheduler_stats st;
    tclod_view v;
    uint32_t f;
    (void)state;
    memset(&h, 0, sizeof h);
    h.target = 1;
    s = chain(&h, 2); /* A costs 1, B 2 */
    sch = wish_scheduler(s, &h, 1, 0);
    helper_view(&v);
    /* a budget of 3 ms fits B; the frames take 2 ms per unit of predicted
     * cost, so B takes 4 ms: the calibration's ratio climbs to 2 and the
     * budget in cost units falls to 1.5, which only A fits */
    for (f = 0; f < 40u; ++f) {
        assert_int_equal(tclod_scheduler_update(sch, f / 10.0, &v, 3.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
        assert_true(st.draw_cost <= st.budget);
        assert_int_equal(tclod_scheduler_report_frame(sch, 2.0 * st.draw_cost, TCLOD_OFF),
                         TCLOD_OK);
    }
    assert_float_equal(st.budget, 1.5, 0.02);
    assert_float_equal(st.draw_cost, 1.0, 0.0);
    assert_true(st.emergencies >= 2u);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void render_and_logic_times_go_to_the_schedulers_calibration(void **state) {
    /* The default calibration: scale 1 and logic 0 guessed, rates 0.5 up and
     * 0.1 down for the scale, 0.2 for the logic, dead band 1 %. A frame of the
     * one node A (cost 1) reported as 2 ms of render and 10 ms of logic: the
     * first measurements replace the guesses, scale 2, logic 10. A second
     * frame of 4 ms render and no logic: the scale rises halfway to 4, to 3,
     * the logic falls a fifth of the way to 0, to 8. tclod_scheduler_report
     * with 2 ms then leaves the logic as it is (8) while the scale falls a
     * tenth of the way to 2, to 2.9. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    const tclod_calib *c;
    tclod_view v;
    (void)state;
    memset(&h, 0, sizeof h);
    s = chain(&h, 1);
    sch = wish_scheduler(s, &h, 1, 0);
    c = tclod_scheduler_calib(sch);
    assert_non_null(c);
    assert_null(tclod_scheduler_calib(NULL));
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, 10.0), TCLOD_ERR_STATE);
    helper_view(&v);
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 100.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, 10.0), TCLOD_OK);
    assert_float_equal(tclod_calib_scale(c), 2.0, 1e-12);
    assert_float_equal(tclod_calib_logic(c), 10.0, 1e-12);
    assert_int_equal(tclod_scheduler_report_frame(sch, 4.0, 0.0), TCLOD_OK);
    assert_float_equal(tclod_calib_scale(c), 3.0, 1e-12);
    assert_float_equal(tclod_calib_logic(c), 8.0, 1e-12);
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, TCLOD_OFF), TCLOD_OK);
    assert_float_equal(tclod_calib_scale(c), 2.9, 1e-12);
    assert_float_equal(tclod_calib_logic(c), 8.0, 1e-12);
    /* bad times change nothing */
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, -2.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, NAN), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report_frame(sch, INFINITY, 1.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report_frame(NULL, 2.0, 1.0), TCLOD_ERR_ARG);
    assert_float_equal(tclod_calib_scale(c), 2.9, 1e-12);
    assert_float_equal(tclod_calib_logic(c), 8.0, 1e-12);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* Two roots of cost DBL_MAX each, drawn over a budget of 0 under
 * TCLOD_OVERFLOW_DRAW_ROOTS: the draw list's predicted cost overflows to
 * +inf, which says nothing of the render time's ratio to it. Reports of valid
 * times are still taken; the calibration's scale stays at its guess of 1 and
 * only the logic time is followed (10 ms, the first measurement). */
static void roots_drawn_past_the_largest_cost_leave_reports_valid(void **state) {
    wish_host h;
    tclod_scene *s = NULL;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler_stats st;
    tclod_view v;
    tclod_id a, b;
    const tclod_calib *c;
    const tclod_draw *items = NULL;
    size_t n = 0;
    (void)state;
    memset(&h, 0, sizeof h);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &a), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &b), TCLOD_OK);
    h.cost[a] = h.cost[b] = DBL_MAX;
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = wish_benefit;
    sd.callbacks.cost = wish_cost;
    sd.callbacks.user = &h;
    sd.overflow = TCLOD_OVERFLOW_DRAW_ROOTS;
    tclod_scheduler_desc_default(&d);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    c = tclod_scheduler_calib(sch);
    helper_view(&v);
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 0.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 2);
    assert_true(isinf(st.draw_cost));
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, 10.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_report_frame(sch, 2.0, TCLOD_OFF), TCLOD_OK);
    assert_float_equal(tclod_calib_scale(c), 1.0, 0.0);
    assert_float_equal(tclod_calib_logic(c), 10.0, 1e-12);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(conservative_camera_widens_and_steps_back_as_the_geomorph_paper_says),
        cmocka_unit_test(roots_drawn_past_the_largest_cost_leave_reports_valid),
        cmocka_unit_test(prediction_is_exact_on_a_straight_path),
        cmocka_unit_test(prediction_keeps_to_the_speed_and_turn_bounds),
        cmocka_unit_test(a_selection_is_asked_for_its_target_interval_and_the_conservative_camera),
        cmocka_unit_test(up_morph_ends_with_its_interval_and_down_morph_before_its_interval),
        cmocka_unit_test(successive_monotone_up_morphs_follow_each_other),
        cmocka_unit_test(a_removed_node_leaves_the_draw_list_mid_morph),
        cmocka_unit_test(an_additive_node_stays_drawn_while_its_child_fades_in),
        cmocka_unit_test(an_up_morph_overridden_by_a_down_morph_collapses),
        cmocka_unit_test(a_jump_of_three_levels_is_three_adjacent_morphs),
        cmocka_unit_test(successive_down_morphs_each_end_when_their_interval_begins),
        cmocka_unit_test(a_down_morph_then_an_up_morph_follow_each_other),
        cmocka_unit_test(a_downward_jump_of_three_levels_is_three_adjacent_morphs),
        cmocka_unit_test(a_split_morphs_each_child_from_its_parent),
        cmocka_unit_test(a_region_that_would_cost_more_while_it_morphs_switches),
        cmocka_unit_test(smooth_resolutions_move_linearly_with_the_same_asymmetry),
        cmocka_unit_test(without_morphing_a_selection_switches_in_at_its_interval),
        cmocka_unit_test(draw_lists_stay_within_the_budget_over_random_paths),
        cmocka_unit_test(the_scheduler_asks_the_hosts_importance_with_the_hosts_user),
        cmocka_unit_test(bad_arguments_are_refused_and_change_nothing),
        cmocka_unit_test(a_strict_update_that_fails_at_a_boundary_changes_nothing),
        cmocka_unit_test(a_selection_under_way_when_an_update_fails_is_begun_again),
        cmocka_unit_test(a_failed_update_puts_the_warm_start_back),
        cmocka_unit_test(a_failed_update_begins_the_lost_selection_again_with_its_views),
        cmocka_unit_test(a_failed_update_records_no_camera),
        cmocka_unit_test(a_failed_update_after_a_removal_shows_what_it_showed),
        cmocka_unit_test(a_slower_machine_lowers_the_budget_through_the_calibration),
        cmocka_unit_test(render_and_logic_times_go_to_the_schedulers_calibration),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
