/*
 * test_calib — the header's "Frame time" section (src/schedule/calib.c): the render
 * budget of [RH §5.3 (eq. 5-7)] on inputs worked out by hand, and the
 * calibration of predicted cost against measured render time ([GEO §4.2]):
 * convergence on a constant hidden factor, step changes at the rise and fall
 * rates, the dead band, the logic estimate, the budget it gives, and the
 * error contract (bad arguments and allocation failures change nothing).
 *
 * The frame counts come from the exponentially weighted average: outside the
 * dead band the error |factor - scale| shrinks by (1 - rate) every frame, so
 * after k frames it is (1 - rate)^k times the starting error, and a relative
 * error bound b is reached after the smallest k with
 * (1 - rate)^k |factor - s0| / factor <= b. Each test checks that k frames
 * are enough and k - 1 are not.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <float.h>
#include <math.h>

#include <tclod/tclod.h>

#include "test_alloc.h"

/* Asserts |got - want| <= rel * |want| (values from decimal constants, which
 * are not exact in binary). */
static void assert_close(double got, double want, double rel) {
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("got %.17g, want %.17g (relative tolerance %g)", got, want, rel);
}

/* Asserts got == want exactly (hand values that are exact in binary). */
static void assert_exact(double got, double want) {
    if (got != want)
        fail_msg("got %.17g, want exactly %.17g", got, want);
}

static tclod_calib *make_calib(const tclod_calib_desc *d) {
    tclod_calib *c = NULL;
    assert_int_equal(tclod_calib_create(d, NULL, &c), TCLOD_OK);
    assert_non_null(c);
    return c;
}

/* A predicted cost that changes every frame (1, 1.75, 2.5, 3.25, 4, 1, ...),
 * so that the tests show the scale follows the ratio, not the cost level. */
static double predicted_cost(int frame) {
    return 1.0 + 0.75 * (double)(frame % 5);
}

/* Reports one frame whose measured render time is factor times its
 * predicted cost, with a logic time of 1 ms. */
static void report_frame(tclod_calib *c, int frame, double factor) {
    double p = predicted_cost(frame);
    assert_int_equal(tclod_calib_report(c, p, factor * p, 1.0), TCLOD_OK);
}

/* report_frame for frames from .. to - 1. */
static void report_frames(tclod_calib *c, int from, int to, double factor) {
    int k;
    for (k = from; k < to; ++k)
        report_frame(c, k, factor);
}

static double relative_error(const tclod_calib *c, double factor) {
    return fabs(tclod_calib_scale(c) - factor) / factor;
}

/* ---- render budget (eq. 5-7) ------------------------------------------------ */

static void render_budget_follows_eq_5_to_7_on_hand_computed_inputs(void **state) {
    double t = -1.0;
    (void)state;
    /* t_f = 20, t_l = 10, C = 1.5: l = (10/20)² = 0.25, rho = 0.75,
     * t_r = 0.5625 * 20 / 1.5 = 11.25 / 1.5 = 7.5 (every step exact). */
    assert_int_equal(tclod_render_budget(20.0, 10.0, 1.5, &t), TCLOD_OK);
    assert_exact(t, 7.5);
    /* t_f = 10, t_l = 5, C = 1: l = 0.25, rho = 0.75, t_r = 0.5625 * 10 = 5.625. */
    assert_int_equal(tclod_render_budget(10.0, 5.0, 1.0, &t), TCLOD_OK);
    assert_exact(t, 5.625);
    /* No logic: l = 0, rho = 1, t_r = t_f / C = 16 / 2 = 8. */
    assert_int_equal(tclod_render_budget(16.0, 0.0, 2.0, &t), TCLOD_OK);
    assert_exact(t, 8.0);
    /* t_f = 12.5, t_l = 1.875 (15 % of the frame), C = 1: l = 0.15² = 0.0225,
     * rho = 0.9775, rho² = 0.95550625, t_r = 0.95550625 * 12.5 = 11.943828125. */
    assert_int_equal(tclod_render_budget(12.5, 1.875, 1.0, &t), TCLOD_OK);
    assert_close(t, 11.943828125, 1e-15);
    /* t_f = 40, t_l = 10, C = 0.8: l = 0.0625, rho = 0.9375,
     * t_r = 0.87890625 * 40 / 0.8 = 35.15625 / 0.8 = 43.9453125: a machine
     * constant below 1 gives more render time than the frame lasts. */
    assert_int_equal(tclod_render_budget(40.0, 10.0, 0.8, &t), TCLOD_OK);
    assert_close(t, 43.9453125, 1e-15);
}

static void render_budget_is_zero_when_the_logic_fills_the_frame(void **state) {
    double t = -1.0;
    (void)state;
    /* t_l = t_f: l = min(1, 1) = 1, rho = 0, t_r = 0. */
    assert_int_equal(tclod_render_budget(20.0, 20.0, 1.0, &t), TCLOD_OK);
    assert_exact(t, 0.0);
    /* t_l > t_f: (t_l / t_f)² = 4 is capped at 1 by the min, so rho = 0, not
     * 1 - 4 = -3 (whose square would give 9 t_f). */
    t = -1.0;
    assert_int_equal(tclod_render_budget(10.0, 20.0, 1.0, &t), TCLOD_OK);
    assert_exact(t, 0.0);
    t = -1.0;
    assert_int_equal(tclod_render_budget(1.0, 1e300, 3.0, &t), TCLOD_OK);
    assert_exact(t, 0.0);
}

static void render_budget_grows_with_the_frame_time(void **state) {
    /* d/dt [(1 - a²/t²)² t] = (1 - a²/t²)(1 + 3a²/t²) >= 0 for t >= a: a
     * longer frame never gets less render time. From t_f = t_l = 4 up. */
    double prev = 0.0, tf;
    (void)state;
    for (tf = 4.0; tf < 400.0; tf *= 1.01) {
        double t = -1.0;
        assert_int_equal(tclod_render_budget(tf, 4.0, 1.25, &t), TCLOD_OK);
        assert_true(t >= prev);
        assert_true(t <= tf / 1.25); /* rho <= 1 */
        prev = t;
    }
}

static void render_budget_rejects_bad_arguments_and_leaves_the_output_unwritten(void **state) {
    const double bad_positive[] = {0.0, -1.0, -0.0, NAN, INFINITY, -INFINITY};
    const double bad_nonnegative[] = {-1.0, -1e-300, NAN, INFINITY, -INFINITY};
    size_t i;
    double t;
    (void)state;
    assert_int_equal(tclod_render_budget(20.0, 10.0, 1.5, NULL), TCLOD_ERR_ARG);
    for (i = 0; i < sizeof bad_positive / sizeof bad_positive[0]; ++i) {
        t = 123.0;
        assert_int_equal(tclod_render_budget(bad_positive[i], 1.0, 1.0, &t), TCLOD_ERR_ARG);
        assert_exact(t, 123.0);
        assert_int_equal(tclod_render_budget(20.0, 1.0, bad_positive[i], &t), TCLOD_ERR_ARG);
        assert_exact(t, 123.0);
    }
    for (i = 0; i < sizeof bad_nonnegative / sizeof bad_nonnegative[0]; ++i) {
        t = 123.0;
        assert_int_equal(tclod_render_budget(20.0, bad_nonnegative[i], 1.0, &t), TCLOD_ERR_ARG);
        assert_exact(t, 123.0);
    }
}

/* ---- calibration: creation ------------------------------------------------- */

static void calib_desc_default_gives_the_documented_values(void **state) {
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    assert_exact(d.initial_scale, 1.0);
    assert_exact(d.rise_rate, 0.5);
    assert_exact(d.fall_rate, 0.1);
    assert_exact(d.dead_band, 0.01);
    assert_exact(d.logic_rate, 0.2);
    assert_exact(d.initial_logic, 0.0);
    assert_exact(d.machine_c, 1.0);
    assert_int_equal(d.initial_measured, 0);
    c = make_calib(&d);
    assert_exact(tclod_calib_scale(c), 1.0);
    assert_exact(tclod_calib_logic(c), 0.0);
    tclod_calib_destroy(c);
}

static void calib_starts_from_the_initial_scale_and_logic(void **state) {
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_scale = 1.75;
    d.initial_logic = 3.5;
    c = make_calib(&d);
    assert_exact(tclod_calib_scale(c), 1.75);
    assert_exact(tclod_calib_logic(c), 3.5);
    tclod_calib_destroy(c);
}

/* Sets field i of d (in declaration order) to v. */
static void set_field(tclod_calib_desc *d, int i, double v) {
    switch (i) {
    case 0:
        d->initial_scale = v;
        break;
    case 1:
        d->rise_rate = v;
        break;
    case 2:
        d->fall_rate = v;
        break;
    case 3:
        d->dead_band = v;
        break;
    case 4:
        d->logic_rate = v;
        break;
    case 5:
        d->initial_logic = v;
        break;
    default:
        d->machine_c = v;
        break;
    }
}

static void calib_create_rejects_every_out_of_range_field_without_allocating(void **state) {
    /* Per field, values outside the header's ranges: initial_scale > 0,
     * rates in (0, 1], dead_band in (0, 1), initial_logic >= 0,
     * machine_c > 0; none NaN or infinite. 0 is every field's default, and
     * TCLOD_OFF (-1) valid in dead_band only. */
    static const double bad[7][6] = {
        {-1e-300, -1.0, NAN, INFINITY, -INFINITY, -2.0}, /* initial_scale */
        {-1.0, -0.5, 1.0000001, 2.0, NAN, INFINITY},     /* rise_rate */
        {-1.0, -0.5, 1.0000001, 2.0, NAN, INFINITY},     /* fall_rate */
        {-0.01, 1.0, 1.5, NAN, INFINITY, -INFINITY},     /* dead_band */
        {-1.0, -0.5, 1.0000001, 2.0, NAN, INFINITY},     /* logic_rate */
        {-1.0, -1e-300, NAN, INFINITY, -INFINITY, -5.0}, /* initial_logic */
        {-1e-300, -1.0, NAN, INFINITY, -INFINITY, -2.0}, /* machine_c */
    };
    test_alloc counter;
    tclod_allocator hooks;
    tclod_calib_desc d;
    tclod_calib *sentinel = (tclod_calib *)&counter;
    tclod_calib *c;
    int f, k;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    for (f = 0; f < 7; ++f) {
        for (k = 0; k < 6; ++k) {
            tclod_calib_desc_default(&d);
            set_field(&d, f, bad[f][k]);
            c = sentinel;
            if (tclod_calib_create(&d, &hooks, &c) != TCLOD_ERR_ARG)
                fail_msg("field %d = %g was accepted", f, bad[f][k]);
            assert_ptr_equal(c, sentinel);
        }
    }
    tclod_calib_desc_default(&d);
    c = sentinel;
    assert_int_equal(tclod_calib_create(NULL, &hooks, &c), TCLOD_ERR_ARG);
    assert_ptr_equal(c, sentinel);
    assert_int_equal(tclod_calib_create(&d, &hooks, NULL), TCLOD_ERR_ARG);
    assert_int_equal(counter.allocations + counter.failures, 0);
}

static void calib_create_accepts_the_ends_of_the_ranges(void **state) {
    /* Rates of exactly 1, a dead band of 0, no initial logic time. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    d.rise_rate = 1.0;
    d.fall_rate = 1.0;
    d.logic_rate = 1.0;
    d.dead_band = TCLOD_OFF;
    d.initial_logic = 0.0;
    c = make_calib(&d);
    /* With rates 1 and no dead band the scale is the last ratio: 3, then 0.5. */
    assert_int_equal(tclod_calib_report(c, 2.0, 6.0, 4.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 3.0);
    assert_exact(tclod_calib_logic(c), 4.0);
    assert_int_equal(tclod_calib_report(c, 2.0, 1.0, 0.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 0.5);
    assert_exact(tclod_calib_logic(c), 0.0);
    tclod_calib_destroy(c);
}

static void calib_create_rejects_an_allocator_with_only_one_hook(void **state) {
    test_alloc counter;
    tclod_allocator hooks;
    tclod_calib_desc d;
    tclod_calib *sentinel = (tclod_calib *)&counter, *c = sentinel;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    hooks.free = NULL;
    tclod_calib_desc_default(&d);
    assert_int_equal(tclod_calib_create(&d, &hooks, &c), TCLOD_ERR_ARG);
    assert_ptr_equal(c, sentinel);
    assert_int_equal(counter.allocations + counter.failures, 0);
}

static void calib_create_fails_with_nomem_and_leaks_nothing(void **state) {
    test_alloc counter;
    tclod_allocator hooks;
    tclod_calib_desc d;
    tclod_calib *sentinel = (tclod_calib *)&counter, *c = sentinel;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    tclod_calib_desc_default(&d);
    test_alloc_fail_at(&counter, 1);
    assert_int_equal(tclod_calib_create(&d, &hooks, &c), TCLOD_ERR_NOMEM);
    assert_ptr_equal(c, sentinel);
    assert_int_equal(counter.failures, 1);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.outstanding_bytes, 0);
    /* The next attempt succeeds, and destroy gives everything back through
     * the same hooks with the sizes it was given. */
    test_alloc_fail_at(&counter, 0);
    assert_int_equal(tclod_calib_create(&d, &hooks, &c), TCLOD_OK);
    assert_true(c != sentinel);
    assert_true(counter.outstanding_blocks > 0);
    assert_int_equal(tclod_calib_report(c, 1.0, 2.0, 0.5), TCLOD_OK);
    tclod_calib_destroy(c);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.outstanding_bytes, 0);
    assert_int_equal(counter.bad_frees, 0);
}

static void null_calib_reads_as_zero_and_destroys_quietly(void **state) {
    (void)state;
    assert_exact(tclod_calib_scale(NULL), 0.0);
    assert_exact(tclod_calib_logic(NULL), 0.0);
    tclod_calib_destroy(NULL);
}

/* ---- calibration: convergence and tracking --------------------------------- */

/* The tests below count the frames the rates take from a start the
 * calibration trusts (initial_measured = 1: the initial values are
 * measurements); with the default a first measurement replaces the guess. */

static void the_first_measurements_replace_the_guessed_scale_and_logic(void **state) {
    /* Defaults: initial_scale 1 and initial_logic 0 are guesses. The first
     * report (predicted 2, rendered 2.6, logic 3) sets the scale to 1.3 and
     * the logic to 3 at once, where blending would have given 1.15 and 0.6.
     * From there the rates and the dead band apply: a ratio of 1.3 * 1.005 is
     * inside the band (the scale stays), a ratio of 2 rises by half the
     * difference to 1.65, a logic time of 5 moves the estimate by a fifth of
     * the difference to 3.4. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    assert_int_equal(d.initial_measured, 0);
    c = make_calib(&d);
    assert_int_equal(tclod_calib_report(c, 2.0, 2.6, 3.0), TCLOD_OK);
    assert_close(tclod_calib_scale(c), 1.3, 1e-15);
    assert_exact(tclod_calib_logic(c), 3.0);
    assert_int_equal(tclod_calib_report(c, 1.0, 1.3 * 1.005, 3.0), TCLOD_OK);
    assert_close(tclod_calib_scale(c), 1.3, 1e-15);
    assert_int_equal(tclod_calib_report(c, 1.0, 2.0, 5.0), TCLOD_OK);
    assert_close(tclod_calib_scale(c), 1.65, 1e-15);
    assert_close(tclod_calib_logic(c), 3.4, 1e-15);
    tclod_calib_destroy(c);
}

static void a_first_frame_that_drew_nothing_leaves_the_guessed_scale_to_the_next(void **state) {
    /* A frame of predicted cost 0 measures no ratio: the guess (1.75) stays,
     * while its logic time (2) replaces the guessed logic; the next frame
     * that drew something (ratio 0.5, below the guess) sets the scale to 0.5
     * at once, where the fall rate would have taken it only to 1.625. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_scale = 1.75;
    c = make_calib(&d);
    assert_int_equal(tclod_calib_report(c, 0.0, 3.0, 2.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 1.75);
    assert_exact(tclod_calib_logic(c), 2.0);
    assert_int_equal(tclod_calib_report(c, 4.0, 2.0, 2.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 0.5);
    tclod_calib_destroy(c);
}

static void scale_converges_on_a_constant_factor_of_2_within_1_percent_in_6_frames(void **state) {
    /* Defaults: s0 = 1, rise rate 1/2, dead band 1 %. Every frame measures
     * exactly 2 * p_k for its predicted cost p_k (the ratio is exactly 2), so
     * the error 2 - s halves per frame: s = 1.5, 1.75, 1.875, 1.9375, 1.96875,
     * 1.984375. The relative error 2^-(k+1) is <= 1 % for k + 1 >= log2(100)
     * = 6.64, so 6 frames are needed: after 5 it is 1/64 = 1.56 %, after 6
     * 1/128 = 0.78 %. Then |2 - 1.984375| = 0.015625 <= 1 % of 1.984375
     * (0.0198...): the dead band holds the scale there for good. */
    const double expected[6] = {1.5, 1.75, 1.875, 1.9375, 1.96875, 1.984375};
    tclod_calib_desc d;
    tclod_calib *c;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    c = make_calib(&d);
    for (k = 0; k < 6; ++k) {
        report_frame(c, k, 2.0);
        assert_exact(tclod_calib_scale(c), expected[k]);
        if (k == 4)
            assert_true(relative_error(c, 2.0) > 0.01);
    }
    assert_true(relative_error(c, 2.0) <= 0.01);
    for (k = 6; k < 200; ++k) {
        report_frame(c, k, 2.0);
        assert_exact(tclod_calib_scale(c), 1.984375);
    }
    tclod_calib_destroy(c);
}

static void scale_converges_on_a_factor_of_1_3_within_1_percent_in_5_frames(void **state) {
    /* A factor that is not exact in binary: from s0 = 1 the error is
     * 0.3 * 0.5^k, relative 0.3 / 1.3 * 0.5^k <= 1 % for 0.5^k <= 0.0433,
     * k >= log2(23.1) = 4.53: 5 frames (4 leave 1.44 %, 5 leave 0.72 %).
     * At k = 4 the error 0.01875 is outside the band (1 % of 1.28125 =
     * 0.0128), at k = 5 the error 0.009375 is inside (1 % of 1.290625), so the
     * scale stays at 1.290625 afterwards. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    c = make_calib(&d);
    report_frames(c, 0, 4, 1.3);
    assert_close(relative_error(c, 1.3), 0.3 / 1.3 / 16.0, 1e-9);
    assert_true(relative_error(c, 1.3) > 0.01);
    report_frame(c, 4, 1.3);
    assert_close(relative_error(c, 1.3), 0.3 / 1.3 / 32.0, 1e-9);
    assert_true(relative_error(c, 1.3) <= 0.01);
    report_frames(c, 5, 100, 1.3);
    assert_close(tclod_calib_scale(c), 1.290625, 1e-14);
    tclod_calib_destroy(c);
}

static void scale_without_a_dead_band_is_an_exponentially_weighted_average(void **state) {
    /* Dead band 0, rise 1/4: s_k = f - (f - s0) (3/4)^k, here 2 - 0.75^k
     * from s0 = 1 towards 2, every frame. Then fall 1/8 from there towards
     * 0.5: s_j = 0.5 + (s_20 - 0.5) (7/8)^j. */
    tclod_calib_desc d;
    tclod_calib *c;
    double s20;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    d.dead_band = TCLOD_OFF;
    d.rise_rate = 0.25;
    d.fall_rate = 0.125;
    c = make_calib(&d);
    for (k = 1; k <= 20; ++k) {
        report_frame(c, k, 2.0);
        assert_close(tclod_calib_scale(c), 2.0 - pow(0.75, k), 1e-14);
    }
    s20 = tclod_calib_scale(c);
    for (k = 1; k <= 30; ++k) {
        report_frame(c, k, 0.5);
        assert_close(tclod_calib_scale(c), 0.5 + (s20 - 0.5) * pow(0.875, k), 1e-14);
    }
    tclod_calib_destroy(c);
}

static void scale_tracks_a_threefold_step_up_within_1_percent_in_7_frames(void **state) {
    /* Settled at a factor of 1 (s = 1), the factor jumps to 3. Rise rate 1/2:
     * the error 2 * 0.5^k, relative (2/3) 0.5^k <= 1 % for 0.5^k <= 0.015,
     * k >= log2(66.7) = 6.06: 7 frames. After 6 the error is 0.03125 (1.04 %,
     * outside the band: 1 % of 2.96875 is 0.0297), after 7 it is 0.015625
     * (0.52 %, inside the band of 0.0298), where the scale then stays. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    c = make_calib(&d);
    report_frames(c, 0, 50, 1.0);
    assert_exact(tclod_calib_scale(c), 1.0);
    report_frames(c, 0, 6, 3.0);
    assert_exact(tclod_calib_scale(c), 2.96875);
    assert_true(relative_error(c, 3.0) > 0.01);
    report_frame(c, 6, 3.0);
    assert_exact(tclod_calib_scale(c), 2.984375);
    assert_true(relative_error(c, 3.0) <= 0.01);
    report_frames(c, 7, 100, 3.0);
    assert_exact(tclod_calib_scale(c), 2.984375);
    tclod_calib_destroy(c);
}

static void scale_tracks_a_halving_step_down_within_1_percent_in_44_frames(void **state) {
    /* Settled at 2 (initial_scale 2), the factor drops to 1. Fall rate 0.1:
     * the error 0.9^k, relative 0.9^k <= 1 % for k >= ln 0.01 / ln 0.9 =
     * 43.7: 44 frames. After 43 the error is 0.9^43 = 0.01078 (outside the
     * band, 1 % of 1.01078 = 0.01011), after 44 it is 0.9^44 = 0.00970
     * (inside the band of 0.01010), where the scale then stays. A fall takes
     * seven times as many frames as a rise of the same ratio (6, above):
     * frames that run short are cheaper than frames that run long. */
    tclod_calib_desc d;
    tclod_calib *c;
    double held;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    d.initial_scale = 2.0;
    c = make_calib(&d);
    report_frames(c, 0, 43, 1.0);
    assert_close(tclod_calib_scale(c), 1.0 + pow(0.9, 43), 1e-12);
    assert_true(relative_error(c, 1.0) > 0.01);
    report_frame(c, 43, 1.0);
    assert_close(tclod_calib_scale(c), 1.0 + pow(0.9, 44), 1e-12);
    assert_true(relative_error(c, 1.0) <= 0.01);
    held = tclod_calib_scale(c);
    report_frames(c, 44, 300, 1.0);
    assert_exact(tclod_calib_scale(c), held);
    tclod_calib_destroy(c);
}

static void dead_band_holds_the_scale_for_small_changes(void **state) {
    /* Band 1 % of the scale. At s = 1 ratios of 1.0099 and 0.9901 (0.99 %
     * away) leave it exactly at 1, however often they come; 1.02 (2 % away)
     * moves it up by half the difference to 1.01; then 0.98 (0.03 below
     * 1.01, outside the band of 0.0101) moves it down by a tenth of the
     * difference to 1.01 - 0.003 = 1.007. The band is relative: at s = 100 a
     * ratio of 100.9 is held, 101.5 moves it to 100.75. */
    const double small[4] = {1.0099, 0.9901, 1.005, 0.995};
    tclod_calib_desc d;
    tclod_calib *c;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    c = make_calib(&d);
    for (k = 0; k < 1000; ++k) {
        assert_int_equal(tclod_calib_report(c, 4.0, 4.0 * small[k % 4], 1.0), TCLOD_OK);
        assert_exact(tclod_calib_scale(c), 1.0);
    }
    assert_int_equal(tclod_calib_report(c, 1.0, 1.02, 1.0), TCLOD_OK);
    assert_close(tclod_calib_scale(c), 1.01, 1e-14);
    assert_int_equal(tclod_calib_report(c, 1.0, 0.98, 1.0), TCLOD_OK);
    assert_close(tclod_calib_scale(c), 1.007, 1e-14);
    tclod_calib_destroy(c);

    d.initial_scale = 100.0;
    c = make_calib(&d);
    assert_int_equal(tclod_calib_report(c, 1.0, 100.9, 1.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 100.0);
    assert_int_equal(tclod_calib_report(c, 2.0, 203.0, 1.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 100.75);
    tclod_calib_destroy(c);
}

static void frame_with_zero_predicted_cost_leaves_the_scale_but_updates_the_logic(void **state) {
    /* "a frame that drew nothing, cost 0, leaves the ratio as it is"; the
     * logic time was still measured: 0 + 0.2 * (5 - 0) = 1. */
    tclod_calib_desc d;
    tclod_calib *c;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    c = make_calib(&d);
    assert_int_equal(tclod_calib_report(c, 0.0, 7.0, 5.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 1.0);
    assert_close(tclod_calib_logic(c), 1.0, 1e-15);
    tclod_calib_destroy(c);
}

static void logic_estimate_converges_within_1_percent_in_21_frames(void **state) {
    /* Logic rate 0.2 from 0 towards a constant 5 ms: L_k = 5 (1 - 0.8^k),
     * relative error 0.8^k <= 1 % for k >= ln 0.01 / ln 0.8 = 20.6: 21
     * frames (0.8^20 = 1.15 %, 0.8^21 = 0.92 %). No dead band on the logic
     * estimate. Then a drop to 2 ms: 2 + (L_21 - 2) 0.8^j. */
    tclod_calib_desc d;
    tclod_calib *c;
    double l21;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_measured = 1; /* the rates from a known start */
    c = make_calib(&d);
    for (k = 1; k <= 21; ++k) {
        assert_int_equal(tclod_calib_report(c, 1.0, 1.0, 5.0), TCLOD_OK);
        assert_close(tclod_calib_logic(c), 5.0 * (1.0 - pow(0.8, k)), 1e-12);
        if (k == 20)
            assert_true(fabs(tclod_calib_logic(c) - 5.0) / 5.0 > 0.01);
    }
    assert_true(fabs(tclod_calib_logic(c) - 5.0) / 5.0 <= 0.01);
    l21 = tclod_calib_logic(c);
    for (k = 1; k <= 10; ++k) {
        assert_int_equal(tclod_calib_report(c, 1.0, 1.0, 2.0), TCLOD_OK);
        assert_close(tclod_calib_logic(c), 2.0 + (l21 - 2.0) * pow(0.8, k), 1e-12);
    }
    tclod_calib_destroy(c);
}

/* ---- calibration: budget --------------------------------------------------- */

static void budget_is_the_render_budget_divided_by_the_scale(void **state) {
    /* initial_scale 2, initial_logic 10, C = 1.5, target 20: eq. 5-7 give
     * 7.5 (the first render-budget case), so the budget is 7.5 / 2 = 3.75. */
    tclod_calib_desc d;
    tclod_calib *c;
    double b = -1.0, r = -1.0;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_scale = 2.0;
    d.initial_logic = 10.0;
    d.machine_c = 1.5;
    c = make_calib(&d);
    assert_int_equal(tclod_calib_budget(c, 20.0, &b), TCLOD_OK);
    assert_exact(b, 3.75);
    /* After some frames, the same formula on the current estimates. */
    for (k = 0; k < 7; ++k)
        assert_int_equal(tclod_calib_report(c, 2.0 + k, (2.0 + k) * 1.37, 3.0 + 0.5 * k), TCLOD_OK);
    assert_int_equal(tclod_calib_budget(c, 33.0, &b), TCLOD_OK);
    assert_int_equal(tclod_render_budget(33.0, tclod_calib_logic(c), 1.5, &r), TCLOD_OK);
    assert_exact(b, r / tclod_calib_scale(c));
    /* A logic estimate at or above the target leaves nothing to render. */
    assert_int_equal(tclod_calib_budget(c, tclod_calib_logic(c), &b), TCLOD_OK);
    assert_exact(b, 0.0);
    tclod_calib_destroy(c);
}

static void budget_rejects_bad_arguments_and_leaves_the_output_unwritten(void **state) {
    const double bad[] = {0.0, -0.0, -5.0, NAN, INFINITY, -INFINITY};
    tclod_calib_desc d;
    tclod_calib *c;
    double b;
    size_t i;
    (void)state;
    tclod_calib_desc_default(&d);
    c = make_calib(&d);
    b = 42.0;
    assert_int_equal(tclod_calib_budget(NULL, 20.0, &b), TCLOD_ERR_ARG);
    assert_exact(b, 42.0);
    assert_int_equal(tclod_calib_budget(c, 20.0, NULL), TCLOD_ERR_ARG);
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        assert_int_equal(tclod_calib_budget(c, bad[i], &b), TCLOD_ERR_ARG);
        assert_exact(b, 42.0);
    }
    tclod_calib_destroy(c);
}

/* ---- calibration: error contract and extremes ------------------------------ */

static void report_rejects_bad_values_and_changes_nothing(void **state) {
    const double bad[] = {-2.0, -1e-300, NAN, INFINITY, -INFINITY}; /* -1: TCLOD_OFF */
    tclod_calib_desc d;
    tclod_calib *c;
    double b0, b;
    size_t i;
    (void)state;
    tclod_calib_desc_default(&d);
    d.initial_scale = 1.5;
    d.initial_logic = 2.0;
    c = make_calib(&d);
    assert_int_equal(tclod_calib_budget(c, 25.0, &b0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(NULL, 1.0, 1.0, 1.0), TCLOD_ERR_ARG);
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        /* each argument bad in turn, the others values that would move both
         * estimates a long way */
        assert_int_equal(tclod_calib_report(c, bad[i], 30.0, 9.0), TCLOD_ERR_ARG);
        assert_int_equal(tclod_calib_report(c, 1.0, bad[i], 9.0), TCLOD_ERR_ARG);
        assert_int_equal(tclod_calib_report(c, 1.0, 30.0, bad[i]), TCLOD_ERR_ARG);
        assert_exact(tclod_calib_scale(c), 1.5);
        assert_exact(tclod_calib_logic(c), 2.0);
    }
    assert_int_equal(tclod_calib_budget(c, 25.0, &b), TCLOD_OK);
    assert_exact(b, b0);
    tclod_calib_destroy(c);
}

static void scale_stays_positive_and_finite_under_extreme_reports(void **state) {
    /* A render time of 0 (ratio 0) with rates 1 and no band, and a
     * subnormal predicted cost whose ratio overflows to inf: the scale is
     * clamped to [DBL_MIN, DBL_MAX] so that budgets stay numbers (never NaN),
     * and ordinary reports afterwards bring it back. The logic estimate
     * follows a measurement of DBL_MAX and back without overflowing. */
    tclod_calib_desc d;
    tclod_calib *c;
    double b = -1.0;
    (void)state;
    tclod_calib_desc_default(&d);
    d.rise_rate = 1.0;
    d.fall_rate = 1.0;
    d.logic_rate = 1.0;
    d.dead_band = TCLOD_OFF;
    c = make_calib(&d);
    assert_int_equal(tclod_calib_report(c, 1.0, 0.0, 0.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), DBL_MIN);
    assert_int_equal(tclod_calib_budget(c, 10.0, &b), TCLOD_OK);
    assert_false(isnan(b));
    assert_true(b > 0.0);
    assert_int_equal(tclod_calib_report(c, 1e-310, 1e300, DBL_MAX), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), DBL_MAX);
    assert_exact(tclod_calib_logic(c), DBL_MAX);
    assert_int_equal(tclod_calib_budget(c, 10.0, &b), TCLOD_OK);
    assert_exact(b, 0.0); /* the logic estimate exceeds the frame */
    assert_int_equal(tclod_calib_report(c, 4.0, 6.0, 1.0), TCLOD_OK);
    assert_exact(tclod_calib_scale(c), 1.5);
    assert_exact(tclod_calib_logic(c), 1.0);
    tclod_calib_destroy(c);
}

static void calibration_is_deterministic(void **state) {
    /* Two calibrations fed the same reports agree bit for bit. */
    tclod_calib_desc d;
    tclod_calib *a, *b;
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    a = make_calib(&d);
    b = make_calib(&d);
    for (k = 0; k < 500; ++k) {
        double p = predicted_cost(k), f = 1.3 + 0.4 * sin(0.01 * k);
        double ba, bb;
        assert_int_equal(tclod_calib_report(a, p, f * p, 0.1 * k), TCLOD_OK);
        assert_int_equal(tclod_calib_report(b, p, f * p, 0.1 * k), TCLOD_OK);
        assert_int_equal(tclod_calib_budget(a, 25.0, &ba), TCLOD_OK);
        assert_int_equal(tclod_calib_budget(b, 25.0, &bb), TCLOD_OK);
        assert_exact(ba, bb);
    }
    tclod_calib_destroy(a);
    tclod_calib_destroy(b);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(render_budget_follows_eq_5_to_7_on_hand_computed_inputs),
        cmocka_unit_test(render_budget_is_zero_when_the_logic_fills_the_frame),
        cmocka_unit_test(render_budget_grows_with_the_frame_time),
        cmocka_unit_test(render_budget_rejects_bad_arguments_and_leaves_the_output_unwritten),
        cmocka_unit_test(calib_desc_default_gives_the_documented_values),
        cmocka_unit_test(calib_starts_from_the_initial_scale_and_logic),
        cmocka_unit_test(calib_create_rejects_every_out_of_range_field_without_allocating),
        cmocka_unit_test(calib_create_accepts_the_ends_of_the_ranges),
        cmocka_unit_test(calib_create_rejects_an_allocator_with_only_one_hook),
        cmocka_unit_test(calib_create_fails_with_nomem_and_leaks_nothing),
        cmocka_unit_test(null_calib_reads_as_zero_and_destroys_quietly),
        cmocka_unit_test(the_first_measurements_replace_the_guessed_scale_and_logic),
        cmocka_unit_test(a_first_frame_that_drew_nothing_leaves_the_guessed_scale_to_the_next),
        cmocka_unit_test(scale_converges_on_a_constant_factor_of_2_within_1_percent_in_6_frames),
        cmocka_unit_test(scale_converges_on_a_factor_of_1_3_within_1_percent_in_5_frames),
        cmocka_unit_test(scale_without_a_dead_band_is_an_exponentially_weighted_average),
        cmocka_unit_test(scale_tracks_a_threefold_step_up_within_1_percent_in_7_frames),
        cmocka_unit_test(scale_tracks_a_halving_step_down_within_1_percent_in_44_frames),
        cmocka_unit_test(dead_band_holds_the_scale_for_small_changes),
        cmocka_unit_test(frame_with_zero_predicted_cost_leaves_the_scale_but_updates_the_logic),
        cmocka_unit_test(logic_estimate_converges_within_1_percent_in_21_frames),
        cmocka_unit_test(budget_is_the_render_budget_divided_by_the_scale),
        cmocka_unit_test(budget_rejects_bad_arguments_and_leaves_the_output_unwritten),
        cmocka_unit_test(report_rejects_bad_values_and_changes_nothing),
        cmocka_unit_test(scale_stays_positive_and_finite_under_extreme_reports),
        cmocka_unit_test(calibration_is_deterministic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
