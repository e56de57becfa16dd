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

#include <math.h>
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

tclod_scene *helper_chain(uint32_t *depth, uint32_t levels) {
    tclod_scene *s = NULL;
    tclod_id parent = TCLOD_NONE, id;
    uint32_t k;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (k = 0; k < levels; ++k) {
        assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
        assert_int_equal(id, k);
        depth[id] = k;
        parent = id;
    }
    return s;
}

void helper_run_frames(tclod_scheduler *sch, uint32_t from, uint32_t to) {
    tclod_view v;
    uint32_t f;
    helper_view(&v);
    for (f = from; f < to; ++f)
        assert_int_equal(tclod_scheduler_update(sch, (double)f / 10.0, &v, 100.0, 0.0), TCLOD_OK);
}

void helper_expect_one(tclod_scheduler *sch, uint32_t frame, tclod_id fine, tclod_id coarse,
                       double weight) {
    const tclod_draw *items = NULL;
    size_t n = 0;
    helper_run_frames(sch, frame, frame + 1u);
    assert_int_equal(tclod_scheduler_draws(sch, &items, &n), TCLOD_OK);
    if (n != 1u || items[0].fine != fine || items[0].coarse != coarse ||
        fabs((double)items[0].weight - weight) > 1e-5)
        fail_msg("t = %.1f: %u items, first %u <- %u weight %g; expected %u <- %u weight %g",
                 (double)frame / 10.0, (unsigned)n, n ? (unsigned)items[0].fine : 0u,
                 n ? (unsigned)items[0].coarse : 0u, n ? (double)items[0].weight : 0.0,
                 (unsigned)fine, (unsigned)coarse, weight);
}

void helper_walk_start(const world_scene *w, table_rng *rng, tclod_view *v, double *heading,
                       double *turn) {
    world_camera_at(&w->path, 0.0, v);
    v->eye[0] = (float)table_rng_uniform(rng, 0.0, w->side);
    v->eye[2] = (float)table_rng_uniform(rng, 0.0, w->side);
    v->eye[1] = 20.0f;
    *heading = table_rng_uniform(rng, 0.0, 2.0 * 3.14159265358979323846);
    *turn = table_rng_uniform(rng, -1.0, 1.0);
}

void helper_walk_step(tclod_view *v, double speed, double turn, double dt, double *heading) {
    *heading += turn * dt;
    v->eye[0] += (float)(speed * dt * cos(*heading));
    v->eye[2] += (float)(speed * dt * sin(*heading));
    v->forward[0] = (float)cos(*heading);
    v->forward[1] = -0.2f;
    v->forward[2] = (float)sin(*heading);
}
