/*
 * helpers — small cmocka-aware helpers shared by the test executables:
 * a reference view, selectors over a table_model, sorted copies of cuts and
 * the checks every selection must pass.
 */
#ifndef HELPERS_H
#define HELPERS_H

#include <stddef.h>

#include "table_scene.h"

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

#endif /* HELPERS_H */
