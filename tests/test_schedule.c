/*
 * test_schedule — the predictive geomorph scheduler (src/schedule.c; seed 004
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

#include <math.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"
#include "table_scene.h"
#include "world_scene.h"

#define PI 3.14159265358979323846

/* ---- a host whose wishes change at known times ----------------------------- */

/* Nodes without bounds; node n sits at depth[n] of its hierarchy. A node is
 * worth 10 (depth + 1) up to the depth `target` and 1 below it, so the
 * greedy refines exactly down to `target`; it costs depth + 1. Smooth
 * objects are worth weight[i] sqrt(r) and cost r. */
typedef struct wish_host {
    uint32_t depth[16];
    uint32_t target;
    double weight[4];
} wish_host;

static double wish_benefit(void *user, const tclod_query *q) {
    const wish_host *h = (const wish_host *)user;
    uint32_t d = h->depth[q->id];
    return d <= h->target ? 10.0 * (double)(d + 1u) : 1.0;
}

static double wish_cost(void *user, const tclod_query *q) {
    const wish_host *h = (const wish_host *)user;
    return (double)(h->depth[q->id] + 1u);
}

static double wish_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    const wish_host *h = (const wish_host *)user;
    double w = 0.0;
    uint32_t k;
    for (k = 0; k < q->count; ++k) w += h->weight[q->members[k]];
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
    sd.warm_start = 0;
    if (mixed) {
        sd.solver = TCLOD_SOLVER_MIXED;
        sd.smooth_cull_area = 0.0;
    }
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.samples = 1;
    d.confidence = 0.0;
    d.morph = morph;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    return sch;
}

/* A chain of `levels` nodes; node k at depth k. */
static tclod_scene *chain(wish_host *h, uint32_t levels) {
    tclod_scene *s = NULL;
    tclod_id parent = TCLOD_NONE, id;
    uint32_t k;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < levels; ++k) {
        assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
        h->depth[id] = k;
        parent = id;
    }
    return s;
}

/* Runs the scheduler at 10 frames per second from frame `from` to frame
 * `to` (exclusive), time frame / 10. */
static void run_frames(tclod_scheduler *sch, uint32_t from, uint32_t to) {
    tclod_view v;
    uint32_t f;
    helper_view(&v);
    for (f = from; f < to; ++f)
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 10.0, &v, 100.0, 0.0), TCLOD_OK);
}

/* Asserts the draw list after the frame at time frame / 10 is exactly one
 * item. */
static void expect_one(tclod_scheduler *sch, uint32_t frame, tclod_id fine, tclod_id coarse,
                       double weight) {
    const tclod_draw *items = NULL;
    size_t n = 0;
    run_frames(sch, frame, frame + 1u);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    if (n != 1u || items[0].fine != fine || items[0].coarse != coarse ||
        fabs((double)items[0].weight - weight) > 1e-5)
        fail_msg("t = %.1f: %u items, first %u <- %u weight %g; expected %u <- %u weight %g",
                 (double)frame / 10.0, (unsigned)n, n ? (unsigned)items[0].fine : 0u,
                 n ? (unsigned)items[0].coarse : 0u, n ? (double)items[0].weight : 0.0,
                 (unsigned)fine, (unsigned)coarse, weight);
}

/* ---- the conservative camera and the prediction --------------------------- */

static void conservative_camera_widens_and_steps_back_as_seed_004_says(void **state) {
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
        if (f == 30) h.weight[a] = 3.0;
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
        if (b == a) return 1;
    return 0;
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
    world_random_desc wd;
    world_scene w;
    table_rng rng;
    uint32_t trial;
    (void)state;
    world_random_desc_default(&wd);
    wd.objects = 150;
    wd.spacing = 12.0f;
    assert_int_equal(world_build_random(&wd, &w), TCLOD_OK);
    table_rng_seed(&rng, 4004u);
    for (trial = 0; trial < 24u; ++trial) {
        tclod_selector_desc sd;
        tclod_scheduler_desc d;
        tclod_scheduler *sch = NULL;
        tclod_scheduler_stats st;
        tclod_view v;
        double t = 0.0, speed = table_rng_uniform(&rng, 1.0, 30.0), heading, turn;
        double budget = table_rng_uniform(&rng, 0.002, 0.05);
        uint32_t f;
        tclod_selector_desc_default(&sd);
        sd.callbacks = world_callbacks(&w);
        sd.solver = trial % 3u == 2u ? TCLOD_SOLVER_ROBIN_HOOD : TCLOD_SOLVER_GREEDY;
        sd.warm_start = (int)(trial % 2u);
        tclod_scheduler_desc_default(&d);
        d.tau = table_rng_uniform(&rng, 0.1, 0.6);
        d.samples = 1u + table_rng_below(&rng, TCLOD_MAX_SAMPLES);
        d.confidence = table_rng_uniform(&rng, 0.0, 2.0);
        d.max_speed = speed;
        d.max_turn_rate = 1.0;
        d.morph = trial % 4u != 3u;
        assert_int_equal(tclod_scheduler_create(w.scene, &sd, &d, NULL, &sch), TCLOD_OK);
        world_camera_at(&w.path, 0.0, &v);
        v.eye[0] = (float)table_rng_uniform(&rng, 0.0, w.side);
        v.eye[2] = (float)table_rng_uniform(&rng, 0.0, w.side);
        v.eye[1] = 20.0f;
        heading = table_rng_uniform(&rng, 0.0, 2.0 * PI);
        turn = table_rng_uniform(&rng, -1.0, 1.0);
        for (f = 0; f < 400u; ++f) {
            double dt = table_rng_uniform(&rng, 0.005, 0.05), slice;
            /* now and then the path turns the other way, or the budget
             * falls or rises */
            if (table_rng_below(&rng, 60) == 0) turn = table_rng_uniform(&rng, -1.0, 1.0);
            if (table_rng_below(&rng, 80) == 0) budget *= table_rng_uniform(&rng, 0.5, 1.5);
            t += dt;
            heading += turn * dt;
            v.eye[0] += (float)(speed * dt * cos(heading));
            v.eye[2] += (float)(speed * dt * sin(heading));
            v.forward[0] = (float)cos(heading);
            v.forward[1] = -0.2f;
            v.forward[2] = (float)sin(heading);
            slice = table_rng_below(&rng, 4) == 0 ? 0.0 : table_rng_uniform(&rng, 1e-6, 2e-4);
            assert_int_equal(tclod_scheduler_update(sch, t, &v, budget, slice), TCLOD_OK);
            assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
            {
                double cost = check_draws(sch, &w);
                if (!(cost <= budget))
                    fail_msg("trial %u frame %u: draw list costs %.17g > budget %.17g", trial, f,
                             cost, budget);
                assert_true(st.draw_cost <= st.budget);
                assert_float_equal(st.draw_cost, cost, 1e-12 + 1e-9 * cost);
            }
        }
        assert_true(st.selections > 0u);
        assert_int_equal(st.changes, st.morphs + st.pops);
        tclod_scheduler_destroy(sch);
    }
    world_scene_free(&w);
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
    assert_int_equal(d.morph, 1);
    d.tau = 0.0;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_ERR_ARG);
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
    assert_int_equal(tclod_scheduler_report(sch, 1.0), TCLOD_ERR_STATE);
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
    assert_int_equal(tclod_scheduler_report(sch, -1.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report(sch, NAN), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_report(NULL, 1.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_draws(NULL, &items, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_get_stats(sch, NULL), TCLOD_ERR_ARG);
    assert_float_equal(tclod_scheduler_resolution(sch, 0), 0.0, 0.0);
    assert_float_equal(tclod_scheduler_resolution(NULL, 0), 0.0, 0.0);
    tclod_scheduler_destroy(sch);
    tclod_scheduler_destroy(NULL);
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
        assert_int_equal(tclod_scheduler_report(sch, 2.0 * st.draw_cost), TCLOD_OK);
    }
    assert_float_equal(st.budget, 1.5, 0.02);
    assert_float_equal(st.draw_cost, 1.0, 0.0);
    assert_true(st.emergencies >= 2u);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(conservative_camera_widens_and_steps_back_as_seed_004_says),
        cmocka_unit_test(prediction_is_exact_on_a_straight_path),
        cmocka_unit_test(prediction_keeps_to_the_speed_and_turn_bounds),
        cmocka_unit_test(up_morph_ends_with_its_interval_and_down_morph_before_its_interval),
        cmocka_unit_test(successive_monotone_up_morphs_follow_each_other),
        cmocka_unit_test(an_up_morph_overridden_by_a_down_morph_collapses),
        cmocka_unit_test(a_jump_of_three_levels_is_three_adjacent_morphs),
        cmocka_unit_test(a_split_morphs_each_child_from_its_parent),
        cmocka_unit_test(smooth_resolutions_move_linearly_with_the_same_asymmetry),
        cmocka_unit_test(without_morphing_a_selection_switches_in_at_its_interval),
        cmocka_unit_test(draw_lists_stay_within_the_budget_over_random_paths),
        cmocka_unit_test(the_scheduler_asks_the_hosts_importance_with_the_hosts_user),
        cmocka_unit_test(bad_arguments_are_refused_and_change_nothing),
        cmocka_unit_test(a_slower_machine_lowers_the_budget_through_the_calibration),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
