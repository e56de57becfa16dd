/*
 * helpers — small cmocka-aware helpers shared by the test executables:
 * a reference view, selectors over a table_model, sorted copies of cuts and
 * the checks every selection must pass.
 */
#ifndef HELPERS_H
#define HELPERS_H

#include <stddef.h>
#include <stdint.h>

#include "table_scene.h"
#include "world_scene.h"

/* A scene with its table_model, for cmocka setup/teardown. */
typedef struct helper_fixture {
    tclod_scene *scene;
    table_model model;
} helper_fixture;

/* cmocka setup: *state = a new helper_fixture with an empty scene. */
int helper_fixture_setup(void **state);

/* cmocka teardown: frees what helper_fixture_setup made. */
int helper_fixture_teardown(void **state);

/* Adds a node without bounds to the fixture; asserts success, returns its id. */
tclod_id helper_add(helper_fixture *f, tclod_id parent, double benefit, double cost);

/* Eye at the origin looking down -z, up +y, fov_y = pi/2, aspect 1,
 * near 0.1, far 100, viewport 1000 px high. */
void helper_view(tclod_view *v);

/* A frame with the given view (may be NULL) and budget, no limits. */
tclod_frame helper_frame(const tclod_view *view, double budget);

/* A greedy selector over s with table_model callbacks; asserts success. */
tclod_selector *helper_selector(const tclod_scene *s, table_model *m, int warm_start);

/* Copies the current cut into out (capacity cap), sorted ascending; asserts
 * that tclod_selector_cut succeeds and fits. Returns the number of ids. */
size_t helper_sorted_cut(const tclod_selector *sel, tclod_id *out, size_t cap);

/* Asserts that got[0..got_n) equals want[0..n) (both sorted ascending);
 * on failure prints both lists, after "what: " when what is not NULL. */
void helper_assert_ids(const char *what, const tclod_id *got, size_t got_n, const tclod_id *want,
                       size_t n);

/* Asserts that the current cut, as a set, is expected[0..n) (any order). */
void helper_assert_cut(const tclod_selector *sel, const tclod_id *expected, size_t n);

/* Asserts what every selection over a table_model promises: the listed ids
 * form a cut (hierarchies may be missing only with roots_may_drop), their
 * costs summed in result order are <= budget, and st->benefit / st->cost are
 * exactly the sums in result order. */
void helper_check_result(const tclod_selector *sel, const table_model *m, const tclod_stats *st,
                         double budget, int roots_may_drop);

/* A scene holding a chain of `levels` nodes without bounds, node k at depth
 * k (depth[k] = k); asserts that the ids are 0 to levels - 1. */
tclod_scene *helper_chain(uint32_t *depth, uint32_t levels);

/* Updates sch at 10 frames per second from frame `from` to `to` (exclusive):
 * time frame / 10, the view of helper_view, budget 100, no slice limit. */
void helper_run_frames(tclod_scheduler *sch, uint32_t from, uint32_t to);

/* Updates at frame `frame` (helper_run_frames) and asserts that the draw
 * list is exactly one item, fine <- coarse at weight (within 1e-5). */
void helper_expect_one(tclod_scheduler *sch, uint32_t frame, tclod_id fine, tclod_id coarse,
                       double weight);

/* A random walk's start over w: the path's first view moved to a random
 * (x, 20, z) inside the world, *heading random in [0, 2 pi) and *turn in
 * [-1, 1] rad/s, drawn from rng in that order. */
void helper_walk_start(const world_scene *w, table_rng *rng, tclod_view *v, double *heading,
                       double *turn);

/* A random walk's step: turns *heading by turn * dt, moves v's eye speed * dt
 * along it in the x-z plane and looks that way, 0.2 down. */
void helper_walk_step(tclod_view *v, double speed, double turn, double dt, double *heading);

#endif /* HELPERS_H */
