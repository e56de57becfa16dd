/*
 * test_models — the ready-made benefit and cost models of the header's
 * "Benefit and cost models" section (src/core/models.c): the terrain patch benefit
 * ([Thesis8 eq. 8.21]), the tree-group benefit (eq. 8.20), the kinked splat cost
 * (eq. 8.18), the triangle-strip cost (eq. 8.19, [GEO §4.2]) and the
 * accuracy benefit of [GEO §4.2], against values worked out by hand, with
 * the thesis's measured constants where it gives them.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>

#include <tclod/tclod.h>

/* The thesis's measured constants, in microseconds. */
#define C_SPLAT 0.0775
#define C_TREE 1.385
#define C_VERTEX 0.06

/* Asserts |got - want| <= rel * |want| (values that come from decimal
 * constants, which are not exact in binary). */
static void assert_close(double got, double want, double rel) {
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("got %.17g, want %.17g (relative tolerance %g)", got, want, rel);
}

/* Asserts got == want exactly (hand values that are exact in binary). */
static void assert_exact(double got, double want) {
    if (got != want)
        fail_msg("got %.17g, want exactly %.17g", got, want);
}

/* ---- terrain ------------------------------------------------------------ */

static void terrain_benefit_is_the_area_at_the_finest_depth_and_halves_per_level_up(void **state) {
    /* S 2^(d - dmax) with S = 1000 px², dmax = 5: d = 5 gives 1000, d = 4
     * 500, d = 3 250, d = 0 1000 / 32 = 31.25 (all exact in binary). */
    uint32_t d;
    (void)state;
    assert_exact(tclod_benefit_terrain(1000.0, 5, 5), 1000.0);
    assert_exact(tclod_benefit_terrain(1000.0, 4, 5), 500.0);
    assert_exact(tclod_benefit_terrain(1000.0, 3, 5), 250.0);
    assert_exact(tclod_benefit_terrain(1000.0, 0, 5), 31.25);
    /* Every level up halves it, down a tree of height 20: 2^(d - 20) S. */
    for (d = 20; d > 0; --d)
        assert_exact(tclod_benefit_terrain(777.0, d - 1, 20),
                     0.5 * tclod_benefit_terrain(777.0, d, 20));
    assert_exact(tclod_benefit_terrain(777.0, 20, 20), 777.0);
    /* A single-level tree: the area itself. */
    assert_exact(tclod_benefit_terrain(3.5, 0, 0), 3.5);
}

static void terrain_benefit_is_zero_without_a_visible_area(void **state) {
    /* "0 for a negative screen_area": -1 is what a query without bounds or
     * view carries. 0 px² gives 0 * 2^k = 0 by the formula. */
    (void)state;
    assert_exact(tclod_benefit_terrain(-1.0, 3, 5), 0.0);
    assert_exact(tclod_benefit_terrain(-1.0, 5, 5), 0.0);
    assert_exact(tclod_benefit_terrain(-1e30, 0, 0), 0.0);
    assert_exact(tclod_benefit_terrain(0.0, 2, 7), 0.0);
}

/* ---- tree groups -------------------------------------------------------- */

static void tree_group_benefit_is_k_s_n_over_64_root_r(void **state) {
    /* k S (N / 64) sqrt(r) and its derivative k S (N / 64) / (2 sqrt(r)):
     *  k 50, S 400, N 64, r 1/4: 50 * 400 * 1 * 1/2 = 10000;
     *      d/dr = 20000 / (2 * 1/2) = 20000.
     *  k 50, S 400, N 64, r 1: 20000; d/dr = 20000 / 2 = 10000.
     *  k 50, S 1000, N 16, r 1/16: 50 * 1000 * 1/4 * 1/4 = 3125;
     *      d/dr = 12500 / (2 * 1/4) = 25000.
     *  k 2, S 9, N 32, r 1/4: 2 * 9 * 1/2 * 1/2 = 4.5; d/dr = 9 / 1 = 9.
     * All exact in binary. */
    double d = -1.0;
    (void)state;
    assert_exact(tclod_benefit_tree_group(50.0, 400.0, 64.0, 0.25, &d), 10000.0);
    assert_exact(d, 20000.0);
    assert_exact(tclod_benefit_tree_group(50.0, 400.0, 64.0, 1.0, &d), 20000.0);
    assert_exact(d, 10000.0);
    assert_exact(tclod_benefit_tree_group(50.0, 1000.0, 16.0, 0.0625, &d), 3125.0);
    assert_exact(d, 25000.0);
    assert_exact(tclod_benefit_tree_group(2.0, 9.0, 32.0, 0.25, &d), 4.5);
    assert_exact(d, 9.0);
    /* d_dr may be NULL. */
    assert_exact(tclod_benefit_tree_group(50.0, 400.0, 64.0, 0.25, NULL), 10000.0);
}

static void tree_group_derivative_matches_the_benefit_and_is_finite_at_zero(void **state) {
    /* The derivative agrees with a central difference of the benefit itself
     * (relative error of a central difference ~ h² f''' / f' < 1e-6 here).
     * At r = 0 the benefit is 0 and the slope is the one at r = 1e-12:
     * k S (N / 64) / (2 sqrt(1e-12)) = 20000 * 5e5 = 1e10 for k 50, S 400,
     * N 64; the same below 1e-12. */
    static const double rs[] = {0.01, 0.1, 0.3, 0.5, 0.9};
    const double h = 1e-6;
    double d = -1.0;
    size_t i;
    (void)state;
    for (i = 0; i < sizeof rs / sizeof rs[0]; ++i) {
        double up = tclod_benefit_tree_group(50.0, 400.0, 48.0, rs[i] + h, NULL);
        double down = tclod_benefit_tree_group(50.0, 400.0, 48.0, rs[i] - h, NULL);
        tclod_benefit_tree_group(50.0, 400.0, 48.0, rs[i], &d);
        assert_close(d, (up - down) / (2.0 * h), 1e-6);
    }
    assert_exact(tclod_benefit_tree_group(50.0, 400.0, 64.0, 0.0, &d), 0.0);
    assert_true(isfinite(d));
    assert_close(d, 1e10, 1e-12);
    tclod_benefit_tree_group(50.0, 400.0, 64.0, 1e-14, &d);
    assert_close(d, 1e10, 1e-12);
    tclod_benefit_tree_group(50.0, 400.0, 64.0, 1e-12, &d);
    assert_close(d, 1e10, 1e-12);
    /* Just above the floor the true slope is used: r = 4e-12 gives
     * 20000 / (2 * 2e-6) = 5e9. */
    tclod_benefit_tree_group(50.0, 400.0, 64.0, 4e-12, &d);
    assert_close(d, 5e9, 1e-12);
}

/* ---- splat cost --------------------------------------------------------- */

static void splat_cost_is_steeper_before_the_kink_and_continuous_at_it(void **state) {
    /* c_splat 0.5, c_tree 4, 1024 splats, 16 trees: n = 1024 r; the kink is
     * at n = 16, r = 1/64.
     *  r 0:     n 0 < 16: 4.5 * 0 = 0; slope 4.5 * 1024 = 4608.
     *  r 1/128: n 8:  4.5 * 8 = 36; slope 4608.
     *  r 1/64:  n 16: 0.5 * 16 + 4 * 16 = 72 = 4.5 * 16 (continuous);
     *           slope after the kink 0.5 * 1024 = 512.
     *  r 1/2:   n 512: 256 + 64 = 320; slope 512.
     *  r 1:     n 1024: 512 + 64 = 576; slope 512. */
    double d = -1.0;
    (void)state;
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 0.0, &d), 0.0);
    assert_exact(d, 4608.0);
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 1.0 / 128.0, &d), 36.0);
    assert_exact(d, 4608.0);
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 1.0 / 64.0, &d), 72.0);
    assert_exact(d, 512.0);
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 0.5, &d), 320.0);
    assert_exact(d, 512.0);
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 1.0, &d), 576.0);
    assert_exact(d, 512.0);
    assert_exact(tclod_cost_splats(0.5, 4.0, 1024.0, 16.0, 0.5, NULL), 320.0);
}

static void splat_cost_is_continuous_at_the_kink_with_the_thesis_constants(void **state) {
    /* 64 trees of 16384 splats: 1048576 splats, kink at r = 64 / 1048576 =
     * 2^-14. Slopes (c_splat + c_tree) * splats = 1.4625 * 1048576 =
     * 1533542.4 us before and c_splat * splats = 81264.64 us after; the cost
     * at the kink is 1.4625 * 64 = 93.6 us from both sides, and a step e
     * either side moves it by slope * e. */
    const double splats = 64.0 * 16384.0, kink = 1.0 / 16384.0, e = 1e-12;
    double d = -1.0, at, before, after;
    (void)state;
    at = tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, kink, &d);
    assert_close(at, 93.6, 1e-12);
    assert_close(d, 81264.64, 1e-12);
    before = tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, kink - e, &d);
    assert_close(d, 1533542.4, 1e-12);
    assert_close(at - before, 1533542.4 * e, 1e-3);
    after = tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, kink + e, &d);
    assert_close(d, 81264.64, 1e-12);
    assert_close(after - at, 81264.64 * e, 1e-3);
}

static void thesis_constants_give_the_hand_computed_group_costs(void **state) {
    /* 64 trees with 16384 splats each at full resolution: n = 1048576 >= 64,
     * 0.0775 * 1048576 + 1.385 * 64 = 81264.64 + 88.64 = 81353.28 us.
     * At half resolution: n = 524288, 0.0775 * 524288 + 88.64 = 40632.32 +
     * 88.64 = 40720.96 us. One splat per tree (r = 2^-14): 64 * (0.0775 +
     * 1.385) = 93.6 us. Half a splat per tree (r = 2^-15): n = 32 < 64,
     * 32 * 1.4625 = 46.8 us. */
    const double splats = 64.0 * 16384.0;
    (void)state;
    assert_close(tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, 1.0, NULL), 81353.28, 1e-12);
    assert_close(tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, 0.5, NULL), 40720.96, 1e-12);
    assert_close(tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, 1.0 / 16384.0, NULL), 93.6,
                 1e-12);
    assert_close(tclod_cost_splats(C_SPLAT, C_TREE, splats, 64.0, 1.0 / 32768.0, NULL), 46.8,
                 1e-12);
}

/* ---- vertex cost -------------------------------------------------------- */

static void thesis_vertex_cost_gives_the_hand_computed_patch_cost(void **state) {
    /* A 33 x 33 terrain patch sent as 32 strips of 66 vertices: 32 * 66 =
     * 2112 vertices, 0.06 * 2112 = 126.72 us. Linear: twice the vertices,
     * twice the cost (253.44 us); none, nothing. */
    (void)state;
    assert_close(tclod_cost_vertices(C_VERTEX, 32.0 * 66.0), 126.72, 1e-12);
    assert_close(tclod_cost_vertices(C_VERTEX, 2.0 * 32.0 * 66.0), 253.44, 1e-12);
    assert_exact(tclod_cost_vertices(C_VERTEX, 0.0), 0.0);
    assert_exact(tclod_cost_vertices(0.25, 8.0), 2.0);
}

/* ---- accuracy ----------------------------------------------------------- */

static void accuracy_is_the_face_share_while_faces_are_fewer_than_pixels(void **state) {
    /* accuracy = max(1, S / F0) / max(1, S / F), benefit = accuracy * S.
     * S 1000 px², F0 500, F 100: max(1, 2) / max(1, 10) = 0.2 = 100 / 500,
     *     benefit 200.
     * S 1000, F0 500, F 250: 2 / 4 = 0.5 = 250 / 500, benefit 500.
     * S 1000, F0 500, F 500 (the original itself): 2 / 2 = 1, benefit 1000.
     * S 4096, F0 1024, F 1: 4 / 4096 = 1 / 1024, benefit 4. */
    (void)state;
    assert_exact(tclod_benefit_accuracy(1000.0, 100.0, 500.0), 200.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 250.0, 500.0), 500.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 500.0, 500.0), 1000.0);
    assert_exact(tclod_benefit_accuracy(4096.0, 1.0, 1024.0), 4.0);
}

static void accuracy_is_one_once_faces_reach_the_pixels(void **state) {
    /* S 1000, F0 8000, F 2000: max(1, 1/8) / max(1, 1/2) = 1, benefit 1000.
     * F = S = 1000 (a face per pixel exactly): 1 / 1 = 1, benefit 1000.
     * Finer representations of the same object add nothing: F 4000 and F
     * 8000 give 1000 too (diminishing returns). */
    (void)state;
    assert_exact(tclod_benefit_accuracy(1000.0, 2000.0, 8000.0), 1000.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 1000.0, 8000.0), 1000.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 4000.0, 8000.0), 1000.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 8000.0, 8000.0), 1000.0);
}

static void accuracy_follows_the_formula_when_only_the_original_reaches_the_pixels(void **state) {
    /* F < S <= F0: by the header's (and [GEO]'s) formula
     * max(1, S / F0) / max(1, S / F) = 1 / (S / F) = F / S.
     * S 1000, F0 4000, F 250: 1 / 4 = 0.25, benefit 250.
     * S 1000, F0 1000, F 500: 1 / 2, benefit 500.
     * (The header's paraphrase "faces / original_faces while the
     * representation has fewer faces than the object covers pixels" would
     * give 250 / 4000 = 1/16 here, and "1 once either has at least a face per
     * pixel" 1: the formula, which the paper states, is what is tested.) */
    (void)state;
    assert_exact(tclod_benefit_accuracy(1000.0, 250.0, 4000.0), 250.0);
    assert_exact(tclod_benefit_accuracy(1000.0, 500.0, 1000.0), 500.0);
}

static void accuracy_benefit_is_zero_without_a_visible_area(void **state) {
    /* "0 for a negative screen_size"; 0 px² gives accuracy * 0 = 0. */
    (void)state;
    assert_exact(tclod_benefit_accuracy(-1.0, 100.0, 500.0), 0.0);
    assert_exact(tclod_benefit_accuracy(-1e30, 100.0, 500.0), 0.0);
    assert_exact(tclod_benefit_accuracy(0.0, 100.0, 500.0), 0.0);
}

static void accuracy_benefit_grows_with_the_faces_and_stops_at_the_pixels(void **state) {
    /* For S 1000 and F0 10000, the benefit min(F, S) for F = 1 .. 20000
     * (F < S <= F0: F / S * S = F; F >= S: S): nondecreasing, and flat
     * once F reaches the pixels. */
    double prev = 0.0, f;
    (void)state;
    for (f = 1.0; f <= 20000.0; f *= 1.5) {
        double b = tclod_benefit_accuracy(1000.0, f, 10000.0);
        assert_close(b, f < 1000.0 ? f : 1000.0, 1e-15);
        assert_true(b >= prev);
        prev = b;
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(terrain_benefit_is_the_area_at_the_finest_depth_and_halves_per_level_up),
        cmocka_unit_test(terrain_benefit_is_zero_without_a_visible_area),
        cmocka_unit_test(tree_group_benefit_is_k_s_n_over_64_root_r),
        cmocka_unit_test(tree_group_derivative_matches_the_benefit_and_is_finite_at_zero),
        cmocka_unit_test(splat_cost_is_steeper_before_the_kink_and_continuous_at_it),
        cmocka_unit_test(splat_cost_is_continuous_at_the_kink_with_the_thesis_constants),
        cmocka_unit_test(thesis_constants_give_the_hand_computed_group_costs),
        cmocka_unit_test(thesis_vertex_cost_gives_the_hand_computed_patch_cost),
        cmocka_unit_test(accuracy_is_the_face_share_while_faces_are_fewer_than_pixels),
        cmocka_unit_test(accuracy_is_one_once_faces_reach_the_pixels),
        cmocka_unit_test(accuracy_follows_the_formula_when_only_the_original_reaches_the_pixels),
        cmocka_unit_test(accuracy_benefit_is_zero_without_a_visible_area),
        cmocka_unit_test(accuracy_benefit_grows_with_the_faces_and_stops_at_the_pixels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
