/*
 * helpers — see helpers.h.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include "exact.h"

#include <stdlib.h>
#include <string.h>

int helper_fixture_setup(void **state) {
    helper_fixture *f = (helper_fixture *)calloc(1, sizeof *f);
    if (f == NULL)
        return -1;
    if (tclod_scene_create(NULL, &f->scene) != TCLOD_OK) {
        free(f);
        return -1;
    }
    table_init(&f->model);
    *state = f;
    return 0;
}

int helper_fixture_teardown(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_scene_destroy(f->scene);
    table_free(&f->model);
    free(f);
    return 0;
}

tclod_id helper_add(helper_fixture *f, tclod_id parent, double benefit, double cost) {
    tclod_id id = TCLOD_NONE;
    assert_int_equal(table_add_node(&f->model, f->scene, parent, NULL, benefit, cost, &id),
                     TCLOD_OK);
    return id;
}

void helper_view(tclod_view *v) {
    memset(v, 0, sizeof *v);
    v->forward[2] = -1.0f;
    v->up[1] = 1.0f;
    v->fov_y = 1.57079632679489661923f;
    v->aspect = 1.0f;
    v->near_z = 0.1f;
    v->far_z = 100.0f;
    v->viewport_height = 1000.0f;
}

tclod_frame helper_frame(const tclod_view *view, double budget) {
    tclod_frame f;
    memset(&f, 0, sizeof f);
    f.view = view;
    f.budget = budget;
    return f;
}

tclod_selector *helper_selector(const tclod_scene *s, table_model *m, int warm_start) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_callbacks(m, &d.callbacks);
    d.cold_start = !(warm_start);
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    assert_non_null(sel);
    return sel;
}

size_t helper_sorted_cut(const tclod_selector *sel, tclod_id *out, size_t cap) {
    const tclod_id *ids = NULL;
    size_t n = 0;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_true(n <= cap);
    if (n > 0) {
        assert_non_null(ids);
        memcpy(out, ids, n * sizeof *ids);
    }
    exact_sort_ids(out, n);
    return n;
}

void helper_assert_ids(const char *what, const tclod_id *got, size_t got_n, const tclod_id *want,
                       size_t n) {
    size_t i;
    if (got_n == n && (n == 0 || memcmp(got, want, n * sizeof *got) == 0))
        return;
    if (what != NULL)
        print_error("%s: ", what);
    print_error("cut differs: expected {");
    for (i = 0; i < n; ++i)
        print_error(" %u", (unsigned)want[i]);
    print_error(" } got {");
    for (i = 0; i < got_n; ++i)
        print_error(" %u", (unsigned)got[i]);
    print_error(" }\n");
    fail();
}

void helper_assert_cut(const tclod_selector *sel, const tclod_id *expected, size_t n) {
    tclod_id got[64], want[64];
    size_t got_n;
    assert_true(n <= 64);
    got_n = helper_sorted_cut(sel, got, 64);
    if (n > 0)
        memcpy(want, expected, n * sizeof *expected);
    exact_sort_ids(want, n);
    helper_assert_ids(NULL, got, got_n, want, n);
}

void helper_check_result(const tclod_selector *sel, const table_model *m, const tclod_stats *st,
                         double budget, int roots_may_drop) {
    const tclod_id *ids = NULL;
    size_t n = 0;
    double cost, benefit;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    if (n > 0)
        assert_non_null(ids);
    assert_true(exact_check_cut(m, ids, n, roots_may_drop));
    cost = table_sum_cost(m, ids, n);
    benefit = table_sum_benefit(m, ids, n);
    if (!(cost <= budget))
        fail_msg("cost %.17g in result order exceeds budget %.17g", cost, budget);
    if (st != NULL) {
        if (st->cost != cost)
            fail_msg("stats.cost %.17g != %.17g summed in result order", st->cost, cost);
        if (st->benefit != benefit)
            fail_msg("stats.benefit %.17g != %.17g summed in result order", st->benefit, benefit);
    }
}
