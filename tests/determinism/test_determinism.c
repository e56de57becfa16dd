/*
 * test_determinism — golden hashes of the selections along fixed camera
 * paths (docs/api.md, "Determinism": same scene, callbacks and frames give
 * a bit-identical selection, on every compiler and optimisation level), in
 * the manner of Box2D's test/test_determinism.c.
 *
 * Scenes: the shared flyover world (examples/scenes/world_scene.h: a terrain
 * quadtree of depth 4 and 1000 objects of 4 levels) and the shared thesis
 * scene (examples/scenes/thesis_scene.h: a 24 km terrain of depth 4 with
 * about 2000 smooth tree groups). Each is flown along its own camera loop,
 * FRAMES frames at t = f / FRAMES, one selector per configuration below
 * (warm starts carry from frame to frame).
 *
 * What is hashed, per configuration: 64-bit FNV-1a (offset basis
 * 0xcbf29ce484222325, prime 0x100000001b3) over, for every frame in order,
 *   the frame number and the select's status, as 32-bit little-endian;
 *   the number of cut ids, then each id of tclod_selector_cut in result
 *     order, as 32-bit little-endian;
 *   the number of smooth groups, then for each group of
 *     tclod_selector_smooth_groups in result order its first and count as
 *     32-bit little-endian and the IEEE-754 bits of its resolution as 64-bit
 *     little-endian.
 * Two configurations select through the predictive scheduler instead
 * (tclod_scheduler, run_scheduler below); their hashes cover its draw lists,
 * morph weights and smooth resolutions.
 * Costs and benefits are not hashed: they follow from the selection and the
 * callbacks. The expected values are below; a change to a solver that
 * changes its selections changes its hash, and the new value is then
 * printed by this test (run it with --print to see them all).
 *
 * The scene builders and callbacks are compiled into this program with the
 * library's own floating-point flags (-ffp-contract=off -fno-fast-math), so
 * that the host side computes the same benefits and costs under every
 * compiler and flag as well: what is compared is the library.
 * tests/determinism/check_matrix.sh builds the program across compilers,
 * optimisation levels, -march=x86-64-v3 and static/shared libraries and
 * compares the hashes.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <tclod/tclod.h>

#include "task_pool.h"
#include "thesis_scene.h"
#include "world_scene.h"

#define FRAMES 48u

typedef struct fnv {
    uint64_t h;
} fnv;

static void fnv_init(fnv *f) {
    f->h = 0xcbf29ce484222325ull;
}

static void fnv_byte(fnv *f, unsigned char b) {
    f->h ^= b;
    f->h *= 0x100000001b3ull;
}

static void fnv_u32(fnv *f, uint32_t v) {
    int i;
    for (i = 0; i < 4; ++i)
        fnv_byte(f, (unsigned char)(v >> (8 * i)));
}

static void fnv_double(fnv *f, double d) {
    uint64_t bits;
    int i;
    memcpy(&bits, &d, sizeof bits);
    for (i = 0; i < 8; ++i)
        fnv_byte(f, (unsigned char)(bits >> (8 * i)));
}

/* The two scenes, built once for all configurations. */
typedef struct scenes {
    world_scene flyover;
    thesis_scene thesis;
} scenes;

static scenes shared;

typedef enum scene_kind { FLYOVER, THESIS } scene_kind;

/* One selector configuration and its expected hash; `scheduled`: the
 * selections are made through a tclod_scheduler (default description, every
 * selection run to its end) and its draw lists are hashed. */
typedef struct config {
    scene_kind scene;
    tclod_solver solver;
    int warm_start, split_smooth, scheduled;
    double budget_ms;
    uint64_t golden;
    /* how nodes are evaluated: 0 the per-node callbacks; 1 the batch ones
     * (world_batch_callbacks); 2 the batch ones over two workers of a
     * task_pool. The selections must not change: the golden hash of a batch
     * configuration is its per-node twin's */
    int batch;
} config;

/* The pool of configurations with batch 2. */
static task_pool *pool;

/* The world's callbacks have no smooth part; the mixed solver requires one,
 * and over a scene without smooth objects it is never called. */
static double no_smooth(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    (void)r;
    *d_dr = 0.0;
    fail_msg("a smooth callback was called for a scene without smooth objects");
    return 0.0;
}

/* The selector description of configuration c, and its scene. */
static const tclod_scene *describe(const config *c, tclod_selector_desc *d) {
    tclod_selector_desc_default(d);
    d->solver = c->solver;
    d->cold_start = !(c->warm_start);
    d->mixed.split_smooth = c->split_smooth;
    if (c->batch == 2)
        d->tasks = task_pool_tasks(pool);
    if (c->scene == FLYOVER) {
        d->callbacks =
            c->batch ? world_batch_callbacks(&shared.flyover) : world_callbacks(&shared.flyover);
        d->callbacks.smooth_benefit = no_smooth;
        d->callbacks.smooth_cost = no_smooth;
        return shared.flyover.scene;
    }
    d->callbacks = thesis_callbacks(&shared.thesis);
    return shared.thesis.scene;
}

/* The camera of configuration c at frame `frame`. */
static void camera(const config *c, uint32_t frame, tclod_view *view) {
    double t = (double)frame / (double)FRAMES;
    if (c->scene == FLYOVER)
        world_camera_at(&shared.flyover.path, t, view);
    else
        thesis_camera_at(&shared.thesis, t, view);
}

/* Runs a selector configuration along its path; returns the hash. */
static uint64_t run_selector(const config *c) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    const tclod_scene *scene = describe(c, &d);
    fnv h;
    uint32_t frame;
    assert_int_equal(tclod_selector_create(scene, &d, NULL, &sel), TCLOD_OK);
    fnv_init(&h);
    for (frame = 0; frame < FRAMES; ++frame) {
        tclod_view view;
        tclod_frame f;
        tclod_stats st;
        const tclod_id *ids = NULL;
        const tclod_smooth_group *groups = NULL;
        size_t n = 0, ng = 0, i;
        tclod_status status;
        camera(c, frame, &view);
        memset(&f, 0, sizeof f);
        f.view = &view;
        f.budget = c->budget_ms;
        status = tclod_select(sel, &f, &st);
        assert_int_equal(status, TCLOD_OK);
        assert_true(st.cost <= f.budget);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng), TCLOD_OK);
        fnv_u32(&h, frame);
        fnv_u32(&h, (uint32_t)status);
        fnv_u32(&h, (uint32_t)n);
        for (i = 0; i < n; ++i)
            fnv_u32(&h, ids[i]);
        fnv_u32(&h, (uint32_t)ng);
        for (i = 0; i < ng; ++i) {
            fnv_u32(&h, groups[i].first);
            fnv_u32(&h, groups[i].count);
            fnv_double(&h, groups[i].resolution);
        }
    }
    tclod_selector_destroy(sel);
    return h.h;
}

/* Runs a scheduled configuration: an update every SCHEDULE_DT seconds (tau
 * 0.5 s: FRAMES frames span several intervals), each hashed as its frame
 * number, status, draw count, each draw's fine and coarse ids and the bits of
 * its weight, and the resolution of every smooth object. */
#define SCHEDULE_DT 0.05
static uint64_t run_scheduler(const config *c) {
    tclod_selector_desc d;
    tclod_scheduler_desc sd;
    tclod_scheduler *sch = NULL;
    const tclod_scene *scene = describe(c, &d);
    uint32_t frame, smooth = tclod_scene_smooth_count(scene), k;
    fnv h;
    tclod_scheduler_desc_default(&sd);
    assert_int_equal(tclod_scheduler_create(scene, &d, &sd, NULL, &sch), TCLOD_OK);
    fnv_init(&h);
    for (frame = 0; frame < FRAMES; ++frame) {
        tclod_view view;
        tclod_scheduler_stats st;
        const tclod_draw *items = NULL;
        size_t n = 0, i;
        tclod_status status;
        camera(c, frame, &view);
        status = tclod_scheduler_update(sch, frame * SCHEDULE_DT, &view, c->budget_ms, 0.0);
        assert_int_equal(status, TCLOD_OK);
        assert_int_equal(tclod_scheduler_get_stats(sch, &st), TCLOD_OK);
        assert_true(st.draw_cost <= st.budget);
        assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
        fnv_u32(&h, frame);
        fnv_u32(&h, (uint32_t)status);
        fnv_u32(&h, (uint32_t)n);
        for (i = 0; i < n; ++i) {
            uint32_t bits;
            memcpy(&bits, &items[i].weight, sizeof bits);
            fnv_u32(&h, items[i].fine);
            fnv_u32(&h, items[i].coarse);
            fnv_u32(&h, bits);
        }
        for (k = 0; k < smooth; ++k)
            fnv_double(&h, tclod_scheduler_resolution(sch, k));
    }
    tclod_scheduler_destroy(sch);
    return h.h;
}

static uint64_t run_config(const config *c) {
    return c->scheduled ? run_scheduler(c) : run_selector(c);
}

static void selections_match_the_golden_hash(void **state) {
    const config *c = (const config *)*state;
    uint64_t got = run_config(c);
    if (got != c->golden)
        fail_msg("hash 0x%016llx, expected 0x%016llx", (unsigned long long)got,
                 (unsigned long long)c->golden);
}

static int build_scenes(void **state) {
    world_flyover_desc wd;
    thesis_desc td;
    (void)state;
    world_flyover_desc_default(&wd);
    wd.terrain_depth = 4;
    wd.objects = 1000;
    wd.levels = 4;
    thesis_desc_default(&td);
    td.side = 24000.0f;
    td.terrain_depth = 4;
    pool = task_pool_create(2);
    if (!pool)
        return -1;
    if (world_build_flyover(&wd, &shared.flyover) != TCLOD_OK)
        return -1;
    if (thesis_build(&td, &shared.thesis) != TCLOD_OK) {
        world_scene_free(&shared.flyover);
        return -1;
    }
    return 0;
}

static int free_scenes(void **state) {
    (void)state;
    thesis_scene_free(&shared.thesis);
    world_scene_free(&shared.flyover);
    task_pool_destroy(pool);
    return 0;
}

/* Budgets well below what drawing everything visible at its finest would
 * cost, so that every solver has choices to make (the greedy solver draws
 * the thesis terrain only, hence its smaller budget there). Robin Hood on the
 * flyover takes the world's weights as importance (world_callbacks), no longer
 * its benefits, which count the screen area a second time: other shares, other
 * selections, another hash. */
static config configs[] = {
    {FLYOVER, TCLOD_SOLVER_GREEDY, 1, 0, 0, 2.0, 0xeb7b86086a8d63a2ull, 0},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 0, 0, 0, 2.0, 0x06746d86a0a5600cull, 0},
    {FLYOVER, TCLOD_SOLVER_MIXED, 0, 0, 0, 2.0, 0x06746d86a0a5600cull, 0},
    {FLYOVER, TCLOD_SOLVER_ROBIN_HOOD, 0, 0, 0, 2.0, 0x91f576ead21266ccull, 0},
    {THESIS, TCLOD_SOLVER_GREEDY, 1, 0, 0, 2.0, 0x40f7c4808c1f23c6ull, 0},
    {THESIS, TCLOD_SOLVER_MIXED, 0, 0, 0, 40.0, 0x0b5eaaf2f8200ee9ull, 0},
    {THESIS, TCLOD_SOLVER_MIXED, 0, 1, 0, 40.0, 0x0d1835629c645db3ull, 0},
    {THESIS, TCLOD_SOLVER_ROBIN_HOOD, 0, 0, 0, 40.0, 0x7eb75f54bb322d35ull, 0},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 1, 0, 1, 2.0, 0x8b4f0f3ac350df88ull, 0},
    {THESIS, TCLOD_SOLVER_MIXED, 0, 1, 1, 40.0, 0xeb7379cf290334b1ull, 0},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 1, 0, 0, 2.0, 0xeb7b86086a8d63a2ull, 1},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 1, 0, 0, 2.0, 0xeb7b86086a8d63a2ull, 2},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 0, 0, 0, 2.0, 0x06746d86a0a5600cull, 2},
    {FLYOVER, TCLOD_SOLVER_MIXED, 0, 0, 0, 2.0, 0x06746d86a0a5600cull, 1},
    {FLYOVER, TCLOD_SOLVER_GREEDY, 1, 0, 1, 2.0, 0x8b4f0f3ac350df88ull, 2},
};

static const char *const config_names[] = {
    "greedy_warm_flyover_selections_match_the_golden_hash",
    "greedy_cold_flyover_selections_match_the_golden_hash",
    "mixed_flyover_selections_match_the_golden_hash",
    "robin_hood_flyover_selections_match_the_golden_hash",
    "greedy_warm_thesis_selections_match_the_golden_hash",
    "mixed_thesis_selections_match_the_golden_hash",
    "mixed_split_thesis_selections_match_the_golden_hash",
    "robin_hood_thesis_selections_match_the_golden_hash",
    "scheduled_greedy_flyover_draws_match_the_golden_hash",
    "scheduled_mixed_split_thesis_draws_match_the_golden_hash",
    "greedy_warm_flyover_batch_callbacks_select_as_per_node",
    "greedy_warm_flyover_two_workers_select_as_per_node",
    "greedy_cold_flyover_two_workers_select_as_per_node",
    "mixed_flyover_batch_callbacks_select_as_per_node",
    "scheduled_greedy_flyover_two_workers_draw_as_per_node",
};

#define CONFIGS (sizeof configs / sizeof configs[0])

int main(int argc, char **argv) {
    struct CMUnitTest tests[CONFIGS];
    size_t i;
    if (argc > 1 && strcmp(argv[1], "--print") == 0) {
        /* one line per configuration: its name and hash, for check_matrix.sh */
        if (build_scenes(NULL) != 0) {
            fprintf(stderr, "test_determinism: building the scenes failed\n");
            return 1;
        }
        for (i = 0; i < CONFIGS; ++i)
            printf("%s 0x%016llx\n", config_names[i], (unsigned long long)run_config(&configs[i]));
        free_scenes(NULL);
        return 0;
    }
    for (i = 0; i < CONFIGS; ++i) {
        tests[i].name = config_names[i];
        tests[i].test_func = selections_match_the_golden_hash;
        tests[i].setup_func = NULL;
        tests[i].teardown_func = NULL;
        tests[i].initial_state = &configs[i];
    }
    return cmocka_run_group_tests(tests, build_scenes, free_scenes);
}
