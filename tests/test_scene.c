/*
 * test_scene — building scenes (src/core/scene.c): dense node and smooth-object
 * ids, parents and hierarchy errors, bounds validation, counts, prepare and
 * memory release; plus the status strings and the version functions.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <tclod/tclod.h>

#include "test_alloc.h"

static tclod_scene *new_scene(void) {
    tclod_scene *s = NULL;
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_non_null(s);
    return s;
}

static tclod_id add_node(tclod_scene *s, tclod_id parent) {
    tclod_id id = TCLOD_NONE;
    assert_int_equal(tclod_scene_add_node(s, parent, NULL, &id), TCLOD_OK);
    return id;
}

static void scene_create_rejects_null_out(void **state) {
    (void)state;
    assert_int_equal(tclod_scene_create(NULL, NULL), TCLOD_ERR_ARG);
}

static void new_scene_is_empty(void **state) {
    tclod_scene *s = new_scene();
    (void)state;
    assert_int_equal(tclod_scene_node_count(s), 0);
    assert_int_equal(tclod_scene_smooth_count(s), 0);
    assert_int_equal(tclod_scene_parent(s, 0), TCLOD_NONE);
    tclod_scene_destroy(s);
}

static void node_ids_are_dense_from_zero_across_hierarchies(void **state) {
    tclod_scene *s = new_scene();
    (void)state;
    /* Two hierarchies built interleaved, then a third root. */
    assert_int_equal(add_node(s, TCLOD_NONE), 0);
    assert_int_equal(add_node(s, TCLOD_NONE), 1);
    assert_int_equal(add_node(s, 0), 2);
    assert_int_equal(add_node(s, 1), 3);
    assert_int_equal(add_node(s, 2), 4);
    assert_int_equal(add_node(s, 0), 5);
    assert_int_equal(add_node(s, TCLOD_NONE), 6);
    assert_int_equal(tclod_scene_node_count(s), 7);
    assert_int_equal(tclod_scene_parent(s, 0), TCLOD_NONE);
    assert_int_equal(tclod_scene_parent(s, 1), TCLOD_NONE);
    assert_int_equal(tclod_scene_parent(s, 2), 0);
    assert_int_equal(tclod_scene_parent(s, 3), 1);
    assert_int_equal(tclod_scene_parent(s, 4), 2);
    assert_int_equal(tclod_scene_parent(s, 5), 0);
    assert_int_equal(tclod_scene_parent(s, 6), TCLOD_NONE);
    tclod_scene_destroy(s);
}

static void add_node_with_unknown_parent_fails_and_adds_nothing(void **state) {
    tclod_scene *s = new_scene();
    const tclod_id bad_parents[] = {3, 4, 12345, TCLOD_NONE - 1u};
    size_t i;
    (void)state;
    add_node(s, TCLOD_NONE);
    add_node(s, 0);
    add_node(s, 1);
    for (i = 0; i < sizeof bad_parents / sizeof bad_parents[0]; ++i) {
        tclod_id id = 777;
        /* 3 == node count: the id the new node itself would get. */
        assert_int_equal(tclod_scene_add_node(s, bad_parents[i], NULL, &id), TCLOD_ERR_HIERARCHY);
        assert_int_equal(id, 777);
        assert_int_equal(tclod_scene_node_count(s), 3);
    }
    /* The scene is still usable and ids stay dense. */
    assert_int_equal(add_node(s, 2), 3);
    tclod_scene_destroy(s);
}

static void add_node_stores_bounds_and_accepts_zero_radius(void **state) {
    tclod_scene *s = new_scene();
    const float bounds[4] = {1.0f, -2.0f, 3.0f, 0.5f};
    const float point[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float huge[4] = {-FLT_MAX, FLT_MAX, 0.0f, FLT_MAX};
    tclod_id id = TCLOD_NONE;
    (void)state;
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, bounds, &id), TCLOD_OK);
    assert_int_equal(id, 0);
    assert_int_equal(tclod_scene_add_node(s, 0, point, &id), TCLOD_OK);
    assert_int_equal(id, 1);
    assert_int_equal(tclod_scene_add_node(s, 0, NULL, &id), TCLOD_OK);
    assert_int_equal(id, 2);
    assert_int_equal(tclod_scene_add_node(s, 2, huge, &id), TCLOD_OK);
    assert_int_equal(id, 3);
    assert_int_equal(tclod_scene_node_count(s), 4);
    tclod_scene_destroy(s);
}

static void add_node_rejects_non_finite_bounds_and_negative_radius(void **state) {
    tclod_scene *s = new_scene();
    const float bad_values[] = {NAN, INFINITY, -INFINITY};
    int component;
    size_t i;
    (void)state;
    add_node(s, TCLOD_NONE);
    for (component = 0; component < 4; ++component)
        for (i = 0; i < sizeof bad_values / sizeof bad_values[0]; ++i) {
            float bounds[4] = {1.0f, 2.0f, 3.0f, 1.0f};
            tclod_id id = 777;
            bounds[component] = bad_values[i];
            assert_int_equal(tclod_scene_add_node(s, 0, bounds, &id), TCLOD_ERR_ARG);
            assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, bounds, &id), TCLOD_ERR_ARG);
            assert_int_equal(id, 777);
            assert_int_equal(tclod_scene_node_count(s), 1);
        }
    {
        const float negative[4] = {0.0f, 0.0f, 0.0f, -1.0f};
        const float tiny_negative[4] = {0.0f, 0.0f, 0.0f, -FLT_MIN};
        tclod_id id = 777;
        assert_int_equal(tclod_scene_add_node(s, 0, negative, &id), TCLOD_ERR_ARG);
        assert_int_equal(tclod_scene_add_node(s, 0, tiny_negative, &id), TCLOD_ERR_ARG);
        assert_int_equal(id, 777);
        assert_int_equal(tclod_scene_node_count(s), 1);
    }
    tclod_scene_destroy(s);
}

static void add_node_rejects_null_scene_or_out_id(void **state) {
    tclod_scene *s = new_scene();
    tclod_id id = 777;
    (void)state;
    assert_int_equal(tclod_scene_add_node(NULL, TCLOD_NONE, NULL, &id), TCLOD_ERR_ARG);
    assert_int_equal(id, 777);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_node_count(s), 0);
    tclod_scene_destroy(s);
}

static void smooth_objects_have_their_own_dense_ids(void **state) {
    tclod_scene *s = new_scene();
    const float bounds[4] = {10.0f, 0.0f, -5.0f, 2.0f};
    tclod_id id = TCLOD_NONE;
    (void)state;
    add_node(s, TCLOD_NONE);
    add_node(s, 0);
    assert_int_equal(tclod_scene_add_smooth(s, bounds, &id), TCLOD_OK);
    assert_int_equal(id, 0);
    assert_int_equal(tclod_scene_add_smooth(s, bounds, &id), TCLOD_OK);
    assert_int_equal(id, 1);
    assert_int_equal(tclod_scene_smooth_count(s), 2);
    assert_int_equal(tclod_scene_node_count(s), 2);
    /* Node ids continue where they were, unaffected by smooth objects. */
    assert_int_equal(add_node(s, 1), 2);
    assert_int_equal(tclod_scene_add_smooth(s, bounds, &id), TCLOD_OK);
    assert_int_equal(id, 2);
    assert_int_equal(tclod_scene_node_count(s), 3);
    assert_int_equal(tclod_scene_smooth_count(s), 3);
    tclod_scene_destroy(s);
}

static void add_smooth_requires_valid_bounds(void **state) {
    tclod_scene *s = new_scene();
    const float nan_bounds[4] = {0.0f, NAN, 0.0f, 1.0f};
    const float inf_bounds[4] = {INFINITY, 0.0f, 0.0f, 1.0f};
    const float negative[4] = {0.0f, 0.0f, 0.0f, -0.5f};
    const float good[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    /* beyond TCLOD_SMOOTH_LIMIT, where a sphere around two of them would not
     * be finite in float */
    const float huge_radius[4] = {0.0f, 0.0f, 0.0f, FLT_MAX};
    const float far_away[4] = {0.0f, 0.0f, -2e30f, 1.0f};
    const float at_limit[4] = {TCLOD_SMOOTH_LIMIT, 0.0f, -TCLOD_SMOOTH_LIMIT, TCLOD_SMOOTH_LIMIT};
    tclod_id id = 777;
    (void)state;
    assert_int_equal(tclod_scene_add_smooth(s, huge_radius, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, far_away, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_set_smooth_bounds(s, 0, good), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, NULL, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, nan_bounds, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, inf_bounds, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, negative, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(NULL, good, &id), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_add_smooth(s, good, NULL), TCLOD_ERR_ARG);
    assert_int_equal(id, 777);
    assert_int_equal(tclod_scene_smooth_count(s), 0);
    assert_int_equal(tclod_scene_node_count(s), 0);
    assert_int_equal(tclod_scene_add_smooth(s, at_limit, &id), TCLOD_OK);
    assert_int_equal(tclod_scene_set_smooth_bounds(s, id, huge_radius), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_smooth_count(s), 1);
    tclod_scene_destroy(s);
}

static void queries_on_null_scene_or_unknown_node_return_defaults(void **state) {
    tclod_scene *s = new_scene();
    (void)state;
    assert_int_equal(tclod_scene_node_count(NULL), 0);
    assert_int_equal(tclod_scene_smooth_count(NULL), 0);
    assert_int_equal(tclod_scene_parent(NULL, 0), TCLOD_NONE);
    add_node(s, TCLOD_NONE);
    add_node(s, 0);
    assert_int_equal(tclod_scene_parent(s, 1), 0);
    assert_int_equal(tclod_scene_parent(s, 2), TCLOD_NONE);
    assert_int_equal(tclod_scene_parent(s, 12345), TCLOD_NONE);
    assert_int_equal(tclod_scene_parent(s, TCLOD_NONE), TCLOD_NONE);
    tclod_scene_destroy(s);
    tclod_scene_destroy(NULL);
}

static void prepare_succeeds_and_scene_can_grow_after_it(void **state) {
    tclod_scene *s = new_scene();
    (void)state;
    assert_int_equal(tclod_scene_prepare(NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    add_node(s, TCLOD_NONE);
    add_node(s, 0);
    add_node(s, 0);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(add_node(s, 1), 3);
    assert_int_equal(add_node(s, TCLOD_NONE), 4);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(tclod_scene_node_count(s), 5);
    assert_int_equal(tclod_scene_parent(s, 3), 1);
    tclod_scene_destroy(s);
}

static void many_nodes_keep_their_parents(void **state) {
    /* Enough nodes for the scene's arrays to grow many times; parent of node
     * i is i / 3 for i >= 4 (four roots), so children of one parent are
     * added next to each other and parents are far from their children. */
    enum { count = 20000 };
    tclod_scene *s = new_scene();
    tclod_id i;
    (void)state;
    for (i = 0; i < count; ++i) {
        const float bounds[4] = {(float)i, 0.0f, 0.0f, 1.0f};
        tclod_id id = TCLOD_NONE;
        tclod_id parent = i < 4 ? TCLOD_NONE : i / 3;
        assert_int_equal(tclod_scene_add_node(s, parent, (i & 1) ? bounds : NULL, &id), TCLOD_OK);
        assert_int_equal(id, i);
    }
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(tclod_scene_node_count(s), count);
    for (i = 0; i < count; ++i)
        assert_int_equal(tclod_scene_parent(s, i), i < 4 ? TCLOD_NONE : i / 3);
    tclod_scene_destroy(s);
}

static void deep_chain_prepares_without_recursion_limits(void **state) {
    /* One object with 300000 levels: a recursive walk would need a stack
     * frame per level. */
    enum { levels = 300000 };
    tclod_scene *s = new_scene();
    tclod_id parent = TCLOD_NONE, i;
    (void)state;
    for (i = 0; i < levels; ++i)
        parent = add_node(s, parent);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(tclod_scene_parent(s, levels - 1), levels - 2);
    tclod_scene_destroy(s);
}

static void scene_destroy_returns_all_memory(void **state) {
    test_alloc counter;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_id i, id;
    const float bounds[4] = {1.0f, 2.0f, 3.0f, 4.0f};
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    assert_true(counter.allocations > 0);
    for (i = 0; i < 3000; ++i)
        assert_int_equal(tclod_scene_add_node(s, i < 10 ? TCLOD_NONE : i / 2, bounds, &id),
                         TCLOD_OK);
    for (i = 0; i < 500; ++i)
        assert_int_equal(tclod_scene_add_smooth(s, bounds, &id), TCLOD_OK);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    tclod_scene_destroy(s);
    assert_int_equal(counter.outstanding_bytes, 0);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.bad_frees, 0);
}

static void status_strings_are_distinct_and_never_null(void **state) {
    const tclod_status all[] = {TCLOD_OK,           TCLOD_ERR_ARG,
                                TCLOD_ERR_NOMEM,    TCLOD_ERR_HIERARCHY,
                                TCLOD_ERR_CALLBACK, TCLOD_ERR_STATE};
    size_t i, j;
    (void)state;
    /* The values are part of the ABI and never renumbered. */
    assert_int_equal(TCLOD_OK, 0);
    assert_int_equal(TCLOD_ERR_ARG, 1);
    assert_int_equal(TCLOD_ERR_NOMEM, 2);
    assert_int_equal(TCLOD_ERR_HIERARCHY, 3);
    assert_int_equal(TCLOD_ERR_CALLBACK, 4);
    assert_int_equal(TCLOD_ERR_STATE, 5);
    for (i = 0; i < sizeof all / sizeof all[0]; ++i) {
        const char *text = tclod_status_string(all[i]);
        assert_non_null(text);
        assert_true(strlen(text) > 0);
        assert_string_not_equal(text, "unknown status");
        for (j = 0; j < i; ++j)
            assert_string_not_equal(text, tclod_status_string(all[j]));
    }
    assert_string_equal(tclod_status_string(TCLOD_OK), "ok");
    assert_string_equal(tclod_status_string(TCLOD_ERR_ARG), "invalid argument");
}

static void unknown_status_has_a_fixed_string(void **state) {
    (void)state;
    assert_string_equal(tclod_status_string((tclod_status)6), "unknown status");
    assert_string_equal(tclod_status_string((tclod_status)12345), "unknown status");
    assert_string_equal(tclod_status_string((tclod_status)-1), "unknown status");
}

static void version_matches_the_header(void **state) {
    char expected[32];
    (void)state;
    assert_int_equal(TCLOD_VERSION_NUMBER, 600); /* 0 * 10000 + 6 * 100 + 0 */
    assert_int_equal(tclod_version(), TCLOD_VERSION_NUMBER);
    assert_non_null(tclod_version_string());
    assert_string_equal(tclod_version_string(), "0.6.0");
    snprintf(expected, sizeof expected, "%d.%d.%d", TCLOD_VERSION_MAJOR, TCLOD_VERSION_MINOR,
             TCLOD_VERSION_PATCH);
    assert_string_equal(tclod_version_string(), expected);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(scene_create_rejects_null_out),
        cmocka_unit_test(new_scene_is_empty),
        cmocka_unit_test(node_ids_are_dense_from_zero_across_hierarchies),
        cmocka_unit_test(add_node_with_unknown_parent_fails_and_adds_nothing),
        cmocka_unit_test(add_node_stores_bounds_and_accepts_zero_radius),
        cmocka_unit_test(add_node_rejects_non_finite_bounds_and_negative_radius),
        cmocka_unit_test(add_node_rejects_null_scene_or_out_id),
        cmocka_unit_test(smooth_objects_have_their_own_dense_ids),
        cmocka_unit_test(add_smooth_requires_valid_bounds),
        cmocka_unit_test(queries_on_null_scene_or_unknown_node_return_defaults),
        cmocka_unit_test(prepare_succeeds_and_scene_can_grow_after_it),
        cmocka_unit_test(many_nodes_keep_their_parents),
        cmocka_unit_test(deep_chain_prepares_without_recursion_limits),
        cmocka_unit_test(scene_destroy_returns_all_memory),
        cmocka_unit_test(status_strings_are_distinct_and_never_null),
        cmocka_unit_test(unknown_status_has_a_fixed_string),
        cmocka_unit_test(version_matches_the_header),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
