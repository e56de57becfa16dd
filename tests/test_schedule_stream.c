/*
 * test_schedule_stream — streaming with the predictive geomorph scheduler
 * (src/schedule/schedule.c; docs/scheduler.md, Streaming): a morph never starts
 * towards a node that is not resident (an evicted fine end holds the old
 * level, an evicted coarse end mid-morph switches at once), a selection
 * never lands a node evicted while it ran, the evictions never name what a
 * running morph draws at either end, the requests cover a node only a
 * predicted view sees, the streaming calls refuse bad arguments and calls
 * from callbacks, and over random paths with residency flipped between
 * updates no draw item ever names a node that is not resident.
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
#include "world_scene.h"

#define PI 3.14159265358979323846

/* ---- a host whose wishes change at known times ----------------------------- */

/* Nodes without bounds; node n sits at depth[n] of its hierarchy. A node is
 * worth 10 (depth + 1) up to the depth `target` and 1 below it, so that the
 * greedy refines exactly down to `target`, or benefit[n] when that is set
 * (> 0); it costs depth + 1, or cost[n] when that is set. */
typedef struct wish_host {
    uint32_t depth[256];
    double benefit[256], cost[256];
    uint32_t target;
} wish_host;

static double wish_benefit(void *user, const tclod_query *q) {
    const wish_host *h = (const wish_host *)user;
    if (h->benefit[q->id] > 0.0)
        return h->benefit[q->id];
    return h->depth[q->id] <= h->target ? 10.0 * (double)(h->depth[q->id] + 1u) : 1.0;
}

static double wish_cost(void *user, const tclod_query *q) {
    const wish_host *h = (const wish_host *)user;
    return h->cost[q->id] > 0.0 ? h->cost[q->id] : (double)(h->depth[q->id] + 1u);
}

/* A scheduler with tau = 1 s, three stages, one predicted view and no
 * conservative benefit, over the cold greedy (a wish is followed exactly). */
static tclod_scheduler *wish_scheduler(tclod_scene *s, wish_host *h) {
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = wish_benefit;
    sd.callbacks.cost = wish_cost;
    sd.callbacks.user = h;
    sd.cold_start = 1;
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.samples = 1;
    d.confidence = TCLOD_OFF;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    return sch;
}

static void expect_counts(const tclod_scheduler *sch, uint64_t changes, uint64_t morphs,
                          uint64_t pops) {
    tclod_scheduler_stats st;
    assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
    assert_int_equal(st.changes, changes);
    assert_int_equal(st.morphs, morphs);
    assert_int_equal(st.pops, pops);
}

/* ---- morphs and residency ------------------------------------------------- */

static void an_up_morph_never_starts_towards_an_evicted_fine_end(void **state) {
    /* A = 0, B = 1. B is wished from t = 3: the selection begun at 3 (for
     * [5, 6)) lands at 4 as S_5 = {B}, and the one begun at 4 (for [6, 7))
     * finishes at 4 with {B} too; A -> B would morph during [5, 6). B is
     * evicted after the update at 4.4: at 4.5 both selections draw A in its
     * place (B's parent), so [5, 6) and [6, 7) draw A as it is -- no morph
     * starts, and nothing drawn changed, so no pop either. B is loaded again
     * after 5.5: the selection begun at 5 saw it absent ({A}, S_7); the one
     * begun at 6 sees it, lands at 7 as S_8, and A -> B morphs during [8, 9)
     * as usual: one change, a morph. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    (void)state;
    memset(&h, 0, sizeof h);
    s = helper_chain(h.depth, 2);
    sch = wish_scheduler(s, &h);
    helper_run_frames(sch, 0, 30);
    h.target = 1;
    helper_run_frames(sch, 30, 45);
    helper_expect_one(sch, 45, 0, 0, 1.0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 0), TCLOD_OK);
    helper_run_frames(sch, 46, 50);
    helper_expect_one(sch, 50, 0, 0, 1.0);
    helper_expect_one(sch, 51, 0, 0, 1.0); /* not B <- A at weight 0.1 */
    helper_run_frames(sch, 52, 55);
    helper_expect_one(sch, 55, 0, 0, 1.0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 1), TCLOD_OK);
    helper_run_frames(sch, 56, 70);
    helper_expect_one(sch, 70, 0, 0, 1.0); /* S_7 = {A} */
    helper_run_frames(sch, 71, 80);
    helper_expect_one(sch, 80, 0, 0, 1.0);
    helper_expect_one(sch, 81, 1, 0, 0.1);
    helper_run_frames(sch, 82, 90);
    helper_expect_one(sch, 90, 1, 1, 1.0);
    expect_counts(sch, 1, 1, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_down_morph_whose_coarse_end_is_evicted_holds_the_old_level(void **state) {
    /* A = 0, B = 1, C = 2, drawn at C. B is wished from t = 3: S_5 = {B}
     * lands at 4 and C -> B morphs down during [4, 5) (counted then: one
     * change, a morph); at 4.5 the list is C <- B at weight 0.5. B is
     * evicted then: S_5 and the selection waiting to land (begun at 4, {B})
     * draw A, its nearest resident ancestor, instead. The region would now
     * morph C -> A through B, which is not resident, so it draws S_4's C as
     * it is from 4.6 (the region switched at once: a change, a pop); at 5
     * S_5 = {A} is drawn. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    (void)state;
    memset(&h, 0, sizeof h);
    s = helper_chain(h.depth, 3);
    h.target = 2;
    sch = wish_scheduler(s, &h);
    helper_run_frames(sch, 0, 30);
    h.target = 1;
    helper_run_frames(sch, 30, 40);
    helper_expect_one(sch, 40, 2, 2, 1.0);
    helper_run_frames(sch, 41, 45);
    helper_expect_one(sch, 45, 2, 1, 0.5);
    expect_counts(sch, 1, 1, 0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 0), TCLOD_OK);
    helper_expect_one(sch, 46, 2, 2, 1.0);
    expect_counts(sch, 2, 1, 1);
    helper_run_frames(sch, 47, 50);
    helper_expect_one(sch, 49, 2, 2, 1.0);
    helper_expect_one(sch, 50, 0, 0, 1.0);
    helper_run_frames(sch, 51, 60);
    helper_expect_one(sch, 60, 0, 0, 1.0);
    expect_counts(sch, 2, 1, 1);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

static void a_selection_never_lands_a_node_evicted_while_it_ran(void **state) {
    /* The chain A, B, C drawn at C, and 100 roots each with one child (root
     * worth 1, cost 0.1; child worth 1.5, cost 0.2): refining one gains 5
     * per unit of cost, less than A -> B (10), so the cold greedy takes
     * A -> B first and then spends about 100 more iterations on the pairs.
     * Slices of 1e-12 s leave the selection begun at 3 (B wished: {B}) under
     * way for several updates after B went into its cut at 3.0. B is evicted
     * after the update at 3.0; the selection finishes later with B in its
     * cut, and no residency changes after that. It lands at 4 as S_5 drawing
     * A (B's resident ancestor) in B's place, so [4, 5) would morph C -> A
     * through B: it draws S_4's C as it is instead (a switch at 5: a change,
     * a pop), and A from 5 on. Were B left in S_5, [5, 6) would morph B -> A
     * down from it (S_6 = {A}: B absent, the greedy stops at A), and fall
     * back to S_5's B. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_view v;
    uint32_t i, f;
    (void)state;
    memset(&h, 0, sizeof h);
    s = helper_chain(h.depth, 3);
    for (i = 0; i < 100u; ++i) {
        tclod_id r, c;
        assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &r), TCLOD_OK);
        assert_int_equal(tclod_scene_add_node(s, r, NULL, &c), TCLOD_OK);
        assert_true(c < 256u);
        h.benefit[r] = 1.0;
        h.cost[r] = 0.1;
        h.benefit[c] = 1.5;
        h.cost[c] = 0.2;
    }
    h.target = 2;
    sch = wish_scheduler(s, &h);
    helper_view(&v);
    for (f = 0; f <= 60u; ++f) {
        const tclod_draw *items;
        size_t n, k, chain_items = 0;
        if (f == 30u)
            h.target = 1;
        if (f == 31u)
            assert_int_equal(tclod_scene_set_resident(s, 1, 0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 10.0, &v, 100.0, 1e-12), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
        for (k = 0; k < n; ++k) {
            tclod_id expected = f < 50u ? 2u : 0u;
            if (items[k].fine > 2u)
                continue;
            chain_items++;
            if (items[k].fine != expected || items[k].coarse != expected)
                fail_msg("t = %.1f: %u <- %u drawn, expected %u", (double)f / 10.0,
                         (unsigned)items[k].fine, (unsigned)items[k].coarse, (unsigned)expected);
        }
        assert_int_equal(chain_items, 1);
    }
    expect_counts(sch, 1, 0, 1);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- what the evictions keep ---------------------------------------------- */

static int listed(const tclod_stream_item *items, size_t n, tclod_id id) {
    size_t i;
    for (i = 0; i < n; ++i)
        if (items[i].id == id)
            return 1;
    return 0;
}

static void the_evictions_never_name_the_ends_of_a_running_morph(void **state) {
    /* The chain A, B, C of the down-morph above (C <- B during [4, 5)) and a
     * root D worth 5 that costs 1000, more than the budget (100): seen,
     * never drawn. Every node is 100 bytes, 400 resident, and the memory
     * budget is 350: each plan evicts 50 bytes or more, one node. The plan
     * made at 4 (the selection begun then finishes at once) draws {B} and
     * would evict the least valuable node per byte it neither draws nor
     * passes through: C (benefit 1 below the wished depth: 1 / 100 = 0.01)
     * before D (5 / 100 = 0.05). C is the fine end of the running morph, so
     * the scheduler keeps it: the list is D alone, value 0.05, 100 bytes. */
    wish_host h;
    tclod_scene *s;
    tclod_scheduler *sch;
    tclod_stream_desc sd;
    const tclod_draw *items;
    const tclod_stream_item *ev;
    size_t n, ne;
    tclod_id d, k;
    (void)state;
    memset(&h, 0, sizeof h);
    s = helper_chain(h.depth, 3);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &d), TCLOD_OK);
    assert_int_equal(d, 3);
    h.benefit[d] = 5.0;
    h.cost[d] = 1000.0;
    for (k = 0; k < 4; ++k)
        assert_int_equal(tclod_scene_set_node_bytes(s, k, 100.0), TCLOD_OK);
    h.target = 2;
    sch = wish_scheduler(s, &h);
    memset(&sd, 0, sizeof sd);
    sd.memory_budget = 350.0;
    assert_int_equal(tclod_scheduler_set_stream(sch, &sd), TCLOD_OK);
    helper_run_frames(sch, 0, 30);
    h.target = 1;
    helper_run_frames(sch, 30, 46);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(items[0].fine, 2);
    assert_int_equal(items[0].coarse, 1);
    assert_int_equal(tclod_scheduler_evictions(sch, &ev, &ne), TCLOD_OK);
    assert_int_equal(ne, 1);
    assert_int_equal(ev[0].id, d);
    assert_float_equal(ev[0].bytes, 100.0, 0.0);
    assert_float_equal(ev[0].value, 0.05, 1e-12);
    assert_false(listed(ev, ne, 2));
    assert_false(listed(ev, ne, 1));
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- requests for the predicted views ------------------------------------- */

/* Worth 1 when the query's view sees the node, else 0; costs 1. */
static double seen_benefit(void *user, const tclod_query *q) {
    (void)user;
    return q->screen_area > 0.0f ? 1.0 : 0.0;
}

static double unit_cost(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static void the_requests_cover_a_node_only_a_predicted_view_sees(void **state) {
    /* The camera of helper_view (90 degrees, looking down -z) moves along +x
     * at 10 m/s: eye (t * 10, 0, 0). F, a root 1 m in radius at (60, 0, -20),
     * is not resident (1000 bytes). tau = 1, one predicted view at the
     * middle of the target interval: the selection begun at b sees the eye
     * of b + 2.5, at x = 10 b + 25 (the fitted line is exact, and 25 m in
     * 2.5 s is within max_speed 20 m/s).
     * - begun at 1: eye x = 35, F at (25, -20): 51.3 degrees off the axis,
     *   more than 45 + 2.3 (its angular radius at 32 m): unseen;
     * - begun at 2: eye x = 45, F at (15, -20): 36.9 degrees: seen.
     * The view of t = 2 itself (eye x = 20, F at (40, -20): 63.4 degrees)
     * does not see it. So the lists of t = 1.9 (the selection of 1) request
     * nothing, and those of t = 2 request F alone: benefit 1 over 1000
     * bytes, value 0.001. A selector over the current view at t = 2 requests
     * nothing. */
    static const float near_b[4] = {30.0f, 0.0f, -50.0f, 1.0f};
    tclod_scene *s = NULL;
    tclod_node_desc nd;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    tclod_selector *sel = NULL;
    tclod_stream_desc st;
    const tclod_stream_item *req;
    tclod_frame fr;
    tclod_view v;
    size_t n;
    tclod_id near_id, far_id;
    uint32_t f;
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, near_b, &near_id), TCLOD_OK);
    tclod_node_desc_default(&nd);
    nd.bounds = tclod_bounds_sphere(60.0, 0.0, -20.0, 1.0);
    nd.not_resident = 1;
    nd.bytes = 1000.0;
    assert_int_equal(tclod_scene_add_node_desc(s, &nd, &far_id), TCLOD_OK);
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = seen_benefit;
    sd.callbacks.cost = unit_cost;
    tclod_scheduler_desc_default(&d);
    d.tau = 1.0;
    d.samples = 1;
    d.confidence = TCLOD_OFF;
    d.max_speed = 20.0;
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    memset(&st, 0, sizeof st);
    st.max_requests = 4;
    assert_int_equal(tclod_scheduler_set_stream(sch, &st), TCLOD_OK);
    helper_view(&v);
    for (f = 0; f <= 20u; ++f) {
        v.eye[0] = (float)f;
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 10.0, &v, 100.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_requests(sch, &req, &n), TCLOD_OK);
        if (f < 20u && n != 0)
            fail_msg("t = %.1f: %u requests, expected none", (double)f / 10.0, (unsigned)n);
    }
    assert_int_equal(n, 1);
    assert_int_equal(req[0].id, far_id);
    assert_int_equal(req[0].flags, 0);
    assert_float_equal(req[0].bytes, 1000.0, 0.0);
    assert_float_equal(req[0].value, 0.001, 1e-15);
    /* the current view alone asks for nothing */
    assert_int_equal(tclod_selector_create(s, &sd, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_selector_set_stream(sel, &st), TCLOD_OK);
    fr = helper_frame(&v, 100.0);
    assert_int_equal(tclod_select(sel, &fr, NULL), TCLOD_OK);
    assert_int_equal(tclod_selector_requests(sel, &req, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    tclod_selector_destroy(sel);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- errors ------------------------------------------------------------------ */

/* A host that calls the streaming calls from its benefit callback, and
 * counts the calls and the answers other than TCLOD_ERR_STATE. Node n is
 * worth n + 1 and costs 1. */
static tclod_scheduler *calling_sch;
static uint32_t callback_calls, callback_wrong;

static double calling_benefit(void *user, const tclod_query *q) {
    const tclod_stream_item *items;
    size_t n;
    tclod_stream_desc d;
    (void)user;
    memset(&d, 0, sizeof d);
    callback_calls++;
    callback_wrong += tclod_scheduler_set_stream(calling_sch, &d) != TCLOD_ERR_STATE;
    callback_wrong += tclod_scheduler_requests(calling_sch, &items, &n) != TCLOD_ERR_STATE;
    callback_wrong += tclod_scheduler_evictions(calling_sch, &items, &n) != TCLOD_ERR_STATE;
    return (double)q->id + 1.0;
}

static void the_streaming_calls_refuse_bad_arguments_and_callbacks(void **state) {
    /* A chain R, A, B worth 1, 2, 3, B not resident (10 bytes), max_requests
     * 4: each refinement gains 1, so every plan passes through A and requests
     * B. A desc with a bad field is refused with the field named and changes
     * nothing (B is still requested). The callbacks are called from within
     * the selector and, once A is evicted, from the scheduler itself (it
     * costs R, which the landed selections draw in A's place): every
     * streaming call from them is refused. */
    tclod_scene *s = NULL;
    tclod_node_desc nd;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    tclod_stream_desc st, bad;
    const tclod_stream_item *items;
    const tclod_draw *draws;
    size_t n;
    tclod_id r, a, b;
    tclod_view v;
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &r), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, r, NULL, &a), TCLOD_OK);
    tclod_node_desc_default(&nd);
    nd.parent = a;
    nd.not_resident = 1;
    nd.bytes = 10.0;
    assert_int_equal(tclod_scene_add_node_desc(s, &nd, &b), TCLOD_OK);
    assert_int_equal(b, 2);
    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = calling_benefit;
    sd.callbacks.cost = unit_cost;
    tclod_scheduler_desc_default(&d);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    calling_sch = sch;
    memset(&st, 0, sizeof st);
    st.max_requests = 4;
    st.min_yield = TCLOD_OFF; /* b's worth per byte does not matter here */
    assert_int_equal(tclod_scheduler_set_stream(NULL, &st), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_set_stream(sch, &st), TCLOD_OK);
    bad = st;
    bad.memory_budget = (double)NAN;
    assert_int_equal(tclod_scheduler_set_stream(sch, &bad), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_scheduler_last_error(sch), "memory_budget"));
    bad = st;
    bad.bytes_in_flight = -1.0;
    assert_int_equal(tclod_scheduler_set_stream(sch, &bad), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_scheduler_last_error(sch), "bytes_in_flight"));
    bad = st;
    bad.min_yield = -0.5;
    assert_int_equal(tclod_scheduler_set_stream(sch, &bad), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_scheduler_last_error(sch), "min_yield"));
    bad = st;
    bad.max_request_bytes = (double)INFINITY;
    assert_int_equal(tclod_scheduler_set_stream(sch, &bad), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_scheduler_last_error(sch), "max_request_bytes"));
    assert_int_equal(tclod_scheduler_requests(NULL, &items, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_requests(sch, NULL, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_requests(sch, &items, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_evictions(NULL, &items, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_evictions(sch, NULL, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_evictions(sch, &items, NULL), TCLOD_ERR_ARG);
    /* before the first update: empty lists */
    assert_int_equal(tclod_scheduler_requests(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    helper_view(&v);
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 100.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(sch, &draws, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(draws[0].fine, a);
    assert_int_equal(tclod_scheduler_requests(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1); /* the refused descs changed nothing */
    assert_int_equal(items[0].id, b);
    assert_int_equal(tclod_scheduler_evictions(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_int_equal(tclod_scene_set_resident(s, a, 0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_update(sch, 0.1, &v, 100.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_draws(sch, &draws, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(draws[0].fine, r);
    assert_true(callback_calls > 0u);
    assert_int_equal(callback_wrong, 0);
    /* planning off: the lists stay those of the last selection to end (the
     * one begun at 0, finished at once) until the next ends, at the boundary
     * of tau = 0.5 */
    assert_int_equal(tclod_scheduler_set_stream(sch, NULL), TCLOD_OK);
    assert_int_equal(tclod_scheduler_update(sch, 0.25, &v, 100.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_requests(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(tclod_scheduler_update(sch, 0.5, &v, 100.0, 0.0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_requests(sch, &items, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    tclod_scheduler_destroy(sch);
    tclod_scene_destroy(s);
}

/* ---- random paths with residency flipped between updates ------------------ */

/* Marks on[] every node on the path from a draw item's fine node to its root. */
static void mark_paths(const tclod_scene *s, const tclod_draw *items, size_t n, uint8_t *on) {
    size_t i;
    for (i = 0; i < n; ++i) {
        tclod_id m;
        for (m = items[i].fine; m != TCLOD_NONE; m = tclod_scene_parent(s, m))
            on[m] = 1;
    }
}

static void no_draw_item_names_a_node_that_is_not_resident(void **state) {
    /* 12 trials over the random world (greedy, Robin Hood and mixed; two and
     * three stages; slices that often leave a selection pending across
     * updates) with a memory budget of 60 % of the bytes, the host changing
     * residency between updates as below. After every update: every draw item's fine and coarse
     * node is resident, the list is well formed, and no listed eviction lies on the path from a
     * drawn node to its root (a drawn node, a morph's coarse end, a fallback). */
    world_random_desc wd;
    world_scene w;
    table_rng rng;
    uint8_t *on;
    uint32_t trial, i, drawn_evicted = 0;
    double total = 0.0;
    (void)state;
    world_random_desc_default(&wd);
    wd.objects = 120;
    wd.spacing = 12.0f;
    assert_int_equal(world_build_random(&wd, &w), TCLOD_OK);
    on = (uint8_t *)calloc(w.node_count, 1);
    assert_non_null(on);
    for (i = 0; i < w.node_count; ++i) {
        double bytes = 1000.0 + (double)w.triangles[i];
        assert_int_equal(tclod_scene_set_node_bytes(w.scene, i, bytes), TCLOD_OK);
        total += bytes;
    }
    table_rng_seed(&rng, 2207u);
    for (trial = 0; trial < 12u; ++trial) {
        tclod_selector_desc sd;
        tclod_scheduler_desc d;
        tclod_scheduler *sch = NULL;
        tclod_scheduler_stats st;
        tclod_stream_desc sdesc;
        tclod_view v;
        double t = 0.0, speed = table_rng_uniform(&rng, 1.0, 30.0), heading, turn;
        double budget = table_rng_uniform(&rng, 0.002, 0.05);
        uint32_t f;
        for (i = 0; i < w.node_count; ++i) /* a third not resident */
            assert_int_equal(tclod_scene_set_resident(w.scene, i, table_rng_below(&rng, 3) != 0),
                             TCLOD_OK);
        tclod_selector_desc_default(&sd);
        sd.callbacks = world_callbacks(&w);
        sd.solver = trial % 3u == 0u   ? TCLOD_SOLVER_GREEDY
                    : trial % 3u == 1u ? TCLOD_SOLVER_ROBIN_HOOD
                                       : TCLOD_SOLVER_MIXED;
        sd.cold_start = (int)(trial % 2u);
        tclod_scheduler_desc_default(&d);
        d.tau = table_rng_uniform(&rng, 0.1, 0.6);
        d.samples = 1u + table_rng_below(&rng, TCLOD_MAX_SAMPLES);
        d.max_speed = speed;
        d.max_turn_rate = 1.0;
        d.two_stage = trial % 4u == 3u;
        assert_int_equal(tclod_scheduler_create(w.scene, &sd, &d, NULL, &sch), TCLOD_OK);
        memset(&sdesc, 0, sizeof sdesc);
        sdesc.max_requests = 16;
        sdesc.memory_budget = 0.6 * total;
        assert_int_equal(tclod_scheduler_set_stream(sch, &sdesc), TCLOD_OK);
        helper_walk_start(&w, &rng, &v, &heading, &turn);
        for (f = 0; f < 300u; ++f) {
            const tclod_draw *items;
            const tclod_stream_item *req, *ev;
            size_t n, nr, ne, k;
            double dt = table_rng_uniform(&rng, 0.005, 0.05), slice;
            if (table_rng_below(&rng, 60) == 0)
                turn = table_rng_uniform(&rng, -1.0, 1.0);
            t += dt;
            helper_walk_step(&v, speed, turn, dt, &heading);
            slice = table_rng_below(&rng, 8) == 0 ? 0.0 : table_rng_uniform(&rng, 1e-7, 2e-5);
            assert_int_equal(tclod_scheduler_update(sch, t, &v, budget, slice), TCLOD_OK);
            assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
            assert_true(st.draw_cost <= st.budget);
            assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
            memset(on, 0, w.node_count);
            mark_paths(w.scene, items, n, on);
            for (k = 0; k < n; ++k) {
                if (!tclod_scene_node_resident(w.scene, items[k].fine) ||
                    !tclod_scene_node_resident(w.scene, items[k].coarse))
                    fail_msg("trial %u frame %u: item %u <- %u names a node not resident", trial, f,
                             (unsigned)items[k].fine, (unsigned)items[k].coarse);
                if (items[k].fine != items[k].coarse)
                    assert_int_equal(tclod_scene_parent(w.scene, items[k].fine), items[k].coarse);
            }
            assert_int_equal(tclod_scheduler_requests(sch, &req, &nr), TCLOD_OK);
            assert_int_equal(tclod_scheduler_evictions(sch, &ev, &ne), TCLOD_OK);
            for (k = 0; k < ne; ++k)
                if (on[ev[k].id])
                    fail_msg("trial %u frame %u: eviction %u lies under a draw item", trial, f,
                             (unsigned)ev[k].id);
            /* the host, one update in four (the others leave residency as
             * it is): loads the first requests, follows half the evictions,
             * evicts a drawn node, either end of a morph (against the advice,
             * as a host short of memory might), and flips random nodes */
            if (table_rng_below(&rng, 4) != 0)
                continue;
            for (k = 0; k < nr && k < 4u; ++k)
                assert_int_equal(tclod_scene_set_resident(w.scene, req[k].id, 1), TCLOD_OK);
            for (k = 0; k < ne; ++k)
                if (table_rng_below(&rng, 2) == 0)
                    assert_int_equal(tclod_scene_set_resident(w.scene, ev[k].id, 0), TCLOD_OK);
            if (n > 0 && table_rng_below(&rng, 2) == 0) {
                const tclod_draw *it = &items[table_rng_below(&rng, (uint32_t)n)];
                tclod_id victim = table_rng_below(&rng, 2) ? it->fine : it->coarse;
                assert_int_equal(tclod_scene_set_resident(w.scene, victim, 0), TCLOD_OK);
                drawn_evicted++;
            }
            for (k = 0; k < 3u; ++k)
                assert_int_equal(tclod_scene_set_resident(w.scene,
                                                          table_rng_below(&rng, w.node_count),
                                                          table_rng_below(&rng, 2)),
                                 TCLOD_OK);
        }
        assert_true(st.selections > 0u);
        assert_int_equal(st.changes, st.morphs + st.pops);
        tclod_scheduler_destroy(sch);
    }
    assert_true(drawn_evicted > 100u);
    free(on);
    world_scene_free(&w);
}

/* A smooth object 10 m ahead (benefit sqrt(r), cost r) under a mixed
 * scheduler with an ample budget: drawn after the first update. Evicted,
 * it shows resolution 0 at once, before any update, and after the next. */
static void an_evicted_smooth_object_shows_no_resolution(void **state) {
    const float ahead[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    table_model m;
    tclod_scene *s = NULL;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_view v;
    tclod_id a;
    (void)state;
    table_init(&m);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(table_add_smooth(&m, s, ahead, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, &a),
                     TCLOD_OK);
    tclod_selector_desc_default(&sd);
    sd.solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(&m, &sd.callbacks);
    tclod_scheduler_desc_default(&d);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    helper_view(&v);
    assert_int_equal(tclod_scheduler_update(sch, 0.0, &v, 10.0, 0.0), TCLOD_OK);
    assert_true(tclod_scheduler_resolution(sch, a) > 0.0);
    assert_int_equal(tclod_scene_set_smooth_resident(s, a, 0), TCLOD_OK);
    assert_true(tclod_scheduler_resolution(sch, a) == 0.0);
    assert_int_equal(tclod_scheduler_update(sch, 0.02, &v, 10.0, 0.0), TCLOD_OK);
    assert_true(tclod_scheduler_resolution(sch, a) == 0.0);
    tclod_scheduler_destroy(sch);
    assert_int_equal(tclod_scene_destroy(s), TCLOD_OK);
    table_free(&m);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(an_up_morph_never_starts_towards_an_evicted_fine_end),
        cmocka_unit_test(a_down_morph_whose_coarse_end_is_evicted_holds_the_old_level),
        cmocka_unit_test(a_selection_never_lands_a_node_evicted_while_it_ran),
        cmocka_unit_test(the_evictions_never_name_the_ends_of_a_running_morph),
        cmocka_unit_test(the_requests_cover_a_node_only_a_predicted_view_sees),
        cmocka_unit_test(the_streaming_calls_refuse_bad_arguments_and_callbacks),
        cmocka_unit_test(no_draw_item_names_a_node_that_is_not_resident),
        cmocka_unit_test(an_evicted_smooth_object_shows_no_resolution),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
