/*
 * test_schedule_stream — streaming with the predictive geomorph scheduler
 * (src/schedule.c; docs/scheduler.md, Streaming): a morph never starts
 * towards a node that is not resident (an evicted fine end holds the old
 * level, an evicted coarse end mid-morph switches at once), a selection
 * never lands a node evicted while it ran, and over random paths with
 * residency flipped between updates no draw item ever names a node that is
 * not resident.
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

/* A chain of `levels` nodes; node k at depth k. */
static tclod_scene *chain(wish_host *h, uint32_t levels) {
    tclod_scene *s = NULL;
    tclod_id parent = TCLOD_NONE, id;
    uint32_t k;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < levels; ++k) {
        assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
        assert_int_equal(id, k);
        h->depth[id] = k;
        parent = id;
    }
    return s;
}

/* Updates at 10 frames per second from frame `from` to `to` (exclusive),
 * time frame / 10, budget 100. */
static void run_frames(tclod_scheduler *sch, uint32_t from, uint32_t to) {
    tclod_view v;
    uint32_t f;
    helper_view(&v);
    for (f = from; f < to; ++f)
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 10.0, &v, 100.0, 0.0), TCLOD_OK);
}

/* Updates at frame `frame` and asserts the draw list is exactly one item. */
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
    s = chain(&h, 2);
    sch = wish_scheduler(s, &h);
    run_frames(sch, 0, 30);
    h.target = 1;
    run_frames(sch, 30, 45);
    expect_one(sch, 45, 0, 0, 1.0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 0), TCLOD_OK);
    run_frames(sch, 46, 50);
    expect_one(sch, 50, 0, 0, 1.0);
    expect_one(sch, 51, 0, 0, 1.0); /* not B <- A at weight 0.1 */
    run_frames(sch, 52, 55);
    expect_one(sch, 55, 0, 0, 1.0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 1), TCLOD_OK);
    run_frames(sch, 56, 70);
    expect_one(sch, 70, 0, 0, 1.0); /* S_7 = {A} */
    run_frames(sch, 71, 80);
    expect_one(sch, 80, 0, 0, 1.0);
    expect_one(sch, 81, 1, 0, 0.1);
    run_frames(sch, 82, 90);
    expect_one(sch, 90, 1, 1, 1.0);
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
    s = chain(&h, 3);
    h.target = 2;
    sch = wish_scheduler(s, &h);
    run_frames(sch, 0, 30);
    h.target = 1;
    run_frames(sch, 30, 40);
    expect_one(sch, 40, 2, 2, 1.0);
    run_frames(sch, 41, 45);
    expect_one(sch, 45, 2, 1, 0.5);
    expect_counts(sch, 1, 1, 0);
    assert_int_equal(tclod_scene_set_resident(s, 1, 0), TCLOD_OK);
    expect_one(sch, 46, 2, 2, 1.0);
    expect_counts(sch, 2, 1, 1);
    run_frames(sch, 47, 50);
    expect_one(sch, 49, 2, 2, 1.0);
    expect_one(sch, 50, 0, 0, 1.0);
    run_frames(sch, 51, 60);
    expect_one(sch, 60, 0, 0, 1.0);
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
    s = chain(&h, 3);
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
        world_camera_at(&w.path, 0.0, &v);
        v.eye[0] = (float)table_rng_uniform(&rng, 0.0, w.side);
        v.eye[2] = (float)table_rng_uniform(&rng, 0.0, w.side);
        v.eye[1] = 20.0f;
        heading = table_rng_uniform(&rng, 0.0, 2.0 * PI);
        turn = table_rng_uniform(&rng, -1.0, 1.0);
        for (f = 0; f < 300u; ++f) {
            const tclod_draw *items;
            const tclod_stream_item *req, *ev;
            size_t n, nr, ne, k;
            double dt = table_rng_uniform(&rng, 0.005, 0.05), slice;
            if (table_rng_below(&rng, 60) == 0)
                turn = table_rng_uniform(&rng, -1.0, 1.0);
            t += dt;
            heading += turn * dt;
            v.eye[0] += (float)(speed * dt * cos(heading));
            v.eye[2] += (float)(speed * dt * sin(heading));
            v.forward[0] = (float)cos(heading);
            v.forward[1] = -0.2f;
            v.forward[2] = (float)sin(heading);
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

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(an_up_morph_never_starts_towards_an_evicted_fine_end),
        cmocka_unit_test(a_down_morph_whose_coarse_end_is_evicted_holds_the_old_level),
        cmocka_unit_test(a_selection_never_lands_a_node_evicted_while_it_ran),
        cmocka_unit_test(no_draw_item_names_a_node_that_is_not_resident),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
