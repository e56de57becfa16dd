/*
 * test_learn — the learned cost model (the header's tclod_calib_report_features,
 * src/schedule/learn.c; docs/calibration.md, the learned cost) and the
 * selector's costs from features (tclod_callbacks.features,
 * tclod_selector_set_coefficients).
 *
 * Frames are made by hand from known coefficients: the render time of a frame
 * is exactly hidden · features. Least squares over frames whose features are
 * linearly independent has that one solution, so once the prior's weight has
 * decayed to its floor (1e-9 of a frame) the coefficients are the hidden ones
 * to about 1e-9; the tests allow 1e-7. Forgetting by lambda per frame leaves
 * the frames before a change a weight lambda^k after k frames; the tests
 * derive their frame counts from that.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include <tclod/tclod.h>

#include "test_alloc.h"

static void assert_close(double got, double want, double rel) {
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("got %.17g, want %.17g (relative tolerance %g)", got, want, rel);
}

static const char *const names[3] = {"draws", "vertices", "splats"};

/* A calibration of n features with the given prior (NULL: none), forgetting
 * and outlier settings (0: defaults), strict or not, and a prior that weighs
 * nothing once the frames came. */
static tclod_calib *make_model(uint32_t n, const double *prior, double forgetting, double outlier,
                               int strict) {
    tclod_calib_desc d;
    tclod_calib *c = NULL;
    uint32_t i;
    tclod_calib_desc_default(&d);
    d.feature_count = n;
    for (i = 0; i < n; ++i) {
        d.feature_names[i] = i < 3 ? names[i] : NULL;
        d.prior[i] = prior ? prior[i] : 0.0;
    }
    if (forgetting != 0.0)
        d.forgetting = forgetting;
    if (outlier != 0.0)
        d.outlier = outlier;
    d.strict = strict;
    d.prior_weight = TCLOD_OFF; /* the frames alone, once enough came: exact fits */
    assert_int_equal(tclod_calib_create(&d, NULL, &c), TCLOD_OK);
    return c;
}

/* Frame k's features: three that vary independently (periods 7, 11 and 13),
 * every one above 0. */
static void features_of(int k, double *x) {
    x[0] = 100.0 + 40.0 * (double)(k % 7);
    x[1] = 2e5 + 3e4 * (double)(k % 11);
    x[2] = 5e5 + 1e5 * (double)((k * 5) % 13);
}

static double dot(const double *a, const double *b, uint32_t n) {
    double s = 0.0;
    uint32_t i;
    for (i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* Reports frames from .. to - 1, each taking hidden · its features. */
static void report_exact(tclod_calib *c, const double *hidden, int from, int to) {
    double x[3];
    int k;
    for (k = from; k < to; ++k) {
        features_of(k, x);
        assert_int_equal(tclod_calib_report_features(c, x, dot(hidden, x, 3), TCLOD_OFF), TCLOD_OK);
    }
}

static tclod_calib_counts counts_of(const tclod_calib *c) {
    tclod_calib_counts n;
    assert_int_equal(tclod_calib_get_counts(c, &n), TCLOD_OK);
    return n;
}

/* ---- the model ----------------------------------------------------------- */

static void coefficients_are_exact_after_enough_independent_frames(void **state) {
    /* ms per draw, per vertex, per splat; a prior off by factors 3, 0.5, 2 */
    const double hidden[3] = {2e-3, 6e-5, 8e-5}, prior[3] = {6e-3, 3e-5, 1.6e-4};
    tclod_calib *c = make_model(3, prior, 0.99, TCLOD_OFF, 0); /* every frame used */
    const double *coef;
    double x[3];
    (void)state;
    /* The prior's weight starts at one frame's and decays by lambda = 0.99 a
     * frame to the floor of 1e-9 after ln(1e-9) / ln(0.99) = 2062 frames. */
    report_exact(c, hidden, 0, 2200);
    coef = tclod_calib_coefficients(c);
    assert_non_null(coef);
    assert_close(coef[0], hidden[0], 1e-7);
    assert_close(coef[1], hidden[1], 1e-7);
    assert_close(coef[2], hidden[2], 1e-7);
    features_of(5000, x);
    assert_close(tclod_calib_predict(c, x), dot(hidden, x, 3), 1e-7);
    assert_int_equal(counts_of(c).used, 2200);
    assert_int_equal(counts_of(c).outliers, 0);
    tclod_calib_destroy(c);
}

static void the_first_frame_scales_the_prior_or_shares_its_time(void **state) {
    const double prior[2] = {1.0, 1.0}, x[2] = {2.0, 3.0}, y[2] = {2.0, 8.0};
    tclod_calib *c = make_model(2, prior, 0.0, 0.0, 0);
    const double *coef;
    (void)state;
    /* prior · x = 5, the frame took 10: the prior times 10 / 5 = 2, and the
     * frame's equation (which it then fits exactly) leaves it there. */
    assert_int_equal(tclod_calib_report_features(c, x, 10.0, TCLOD_OFF), TCLOD_OK);
    coef = tclod_calib_coefficients(c);
    assert_close(coef[0], 2.0, 1e-15);
    assert_close(coef[1], 2.0, 1e-15);
    tclod_calib_destroy(c);
    /* No prior: 10 ms shared by the two features the frame drew, 5 each:
     * 5 / 2 per unit of the first, 5 / 8 of the second. */
    c = make_model(2, NULL, 0.0, 0.0, 0);
    assert_int_equal(tclod_calib_report_features(c, y, 10.0, TCLOD_OFF), TCLOD_OK);
    coef = tclod_calib_coefficients(c);
    assert_close(coef[0], 2.5, 1e-15);
    assert_close(coef[1], 0.625, 1e-15);
    tclod_calib_destroy(c);
}

static void a_feature_that_is_always_zero_keeps_its_prior(void **state) {
    const double hidden[3] = {2e-3, 6e-5, 0.0}, prior[3] = {1e-3, 1e-4, 0.123};
    tclod_calib *c = make_model(3, prior, 0.99, 0.0, 0);
    double x[3];
    int k;
    (void)state;
    for (k = 0; k < 2200; ++k) { /* the prior's weight at its floor, as above */
        features_of(k, x);
        x[2] = 0.0;
        assert_int_equal(tclod_calib_report_features(c, x, dot(hidden, x, 3), TCLOD_OFF), TCLOD_OK);
    }
    assert_true(tclod_calib_coefficients(c)[2] == 0.123);
    assert_close(tclod_calib_coefficients(c)[0], hidden[0], 1e-6);
    tclod_calib_destroy(c);
}

static void coefficients_never_go_negative(void **state) {
    /* The times fall as the second feature grows (as if it were negative):
     * unconstrained least squares gives it a negative price; the model must
     * price it 0, and the first at the best non-negative fit. */
    tclod_calib_desc d;
    tclod_calib *c = NULL;
    double x[2];
    int k;
    (void)state;
    tclod_calib_desc_default(&d);
    d.feature_count = 2;
    d.outlier = TCLOD_OFF;
    d.least_share = TCLOD_OFF; /* no least price: the fit alone */
    assert_int_equal(tclod_calib_create(&d, NULL, &c), TCLOD_OK);
    for (k = 0; k < 300; ++k) {
        x[0] = 10.0 + (double)(k % 5);
        x[1] = 1.0 + (double)(k % 3);
        assert_int_equal(tclod_calib_report_features(c, x, 2.0 * x[0] - 0.5 * x[1], TCLOD_OFF),
                         TCLOD_OK);
        assert_true(tclod_calib_coefficients(c)[0] >= 0.0);
        assert_true(tclod_calib_coefficients(c)[1] >= 0.0);
    }
    assert_true(tclod_calib_coefficients(c)[1] == 0.0);
    assert_true(tclod_calib_coefficients(c)[0] > 0.0);
    tclod_calib_destroy(c);
}

static void forgetting_follows_a_change_and_without_it_the_past_stays(void **state) {
    const double before[3] = {2e-3, 6e-5, 8e-5}, after[3] = {1e-3, 1.2e-4, 4e-5};
    tclod_calib *c = make_model(3, before, 0.9, TCLOD_OFF, 0), *keep;
    (void)state;
    /* lambda 0.9: 600 frames after the change the old frames weigh
     * 0.9^600 = 4e-28 of the new ones' total, and the published prices, which
     * follow the model's at mix_rate 0.05, are 0.95^600 = 4e-14 of the step
     * away from them: the new prices to 1e-7. */
    report_exact(c, before, 0, 300);
    report_exact(c, after, 300, 900);
    assert_close(tclod_calib_coefficients(c)[0], after[0], 1e-7);
    assert_close(tclod_calib_coefficients(c)[1], after[1], 1e-7);
    assert_close(tclod_calib_coefficients(c)[2], after[2], 1e-7);
    /* Without forgetting (lambda 1), 600 frames of the first machine and 300
     * of the second weigh alike: the prices lie between the two, far from the
     * second's. */
    keep = make_model(3, before, 1.0, TCLOD_OFF, 0);
    report_exact(keep, before, 0, 300);
    report_exact(keep, after, 300, 600);
    report_exact(keep, before, 600, 900);
    assert_true(fabs(tclod_calib_coefficients(keep)[1] - after[1]) > 0.1 * after[1]);
    tclod_calib_destroy(keep);
    tclod_calib_destroy(c);
}

static void a_hitch_is_ignored_and_a_run_of_them_is_a_change(void **state) {
    const double hidden[3] = {2e-3, 6e-5, 8e-5};
    tclod_calib *c = make_model(3, hidden, 0.0, 0.0, 0);
    double x[3], kept[3], changed[3];
    int k;
    (void)state;
    report_exact(c, hidden, 0, 200);
    memcpy(kept, tclod_calib_coefficients(c), sizeof kept);
    /* one frame five times as long: an outlier; the coefficients do not move */
    features_of(200, x);
    assert_int_equal(tclod_calib_report_features(c, x, 5.0 * dot(hidden, x, 3), 1.0), TCLOD_OK);
    assert_memory_equal(tclod_calib_coefficients(c), kept, sizeof kept);
    assert_int_equal(counts_of(c).outliers, 1);
    /* a normal frame, then another hitch: two outliers, no change */
    report_exact(c, hidden, 201, 202);
    features_of(202, x);
    assert_int_equal(tclod_calib_report_features(c, x, 4.0 * dot(hidden, x, 3), 1.0), TCLOD_OK);
    assert_int_equal(counts_of(c).outliers, 2);
    assert_int_equal(counts_of(c).changes, 0);
    report_exact(c, hidden, 203, 204);
    /* the machine becomes 1.5 times slower for good: the second slow frame in
     * a row starts the model again, from the old prices scaled by 1.5 */
    for (k = 0; k < 3; ++k)
        changed[k] = 1.5 * hidden[k];
    report_exact(c, changed, 204, 206);
    assert_int_equal(counts_of(c).changes, 1);
    assert_int_equal(counts_of(c).outliers, 2);
    report_exact(c, changed, 206, 236);
    features_of(999, x);
    assert_close(tclod_calib_predict(c, x), dot(changed, x, 3), 1e-3);
    {
        tclod_calib_counts n = counts_of(c);
        assert_int_equal(n.frames, 236);
        assert_int_equal(n.used + n.outliers + n.invalid + n.empty, n.frames);
    }
    tclod_calib_destroy(c);
}

static void one_feature_is_the_scale_calibration(void **state) {
    /* the feature is the predicted cost: its coefficient is the ratio
     * measured / predicted, 1.3 here */
    tclod_calib *c = make_model(1, NULL, 0.0, 0.0, 0);
    double p;
    int k;
    (void)state;
    for (k = 0; k < 50; ++k) {
        p = 1.0 + 0.75 * (double)(k % 5);
        assert_int_equal(tclod_calib_report_features(c, &p, 1.3 * p, TCLOD_OFF), TCLOD_OK);
    }
    assert_close(tclod_calib_coefficients(c)[0], 1.3, 1e-12);
    /* and the budget is the render time itself: coefficients are in ms */
    assert_int_equal(tclod_calib_budget(c, 20.0, &p), TCLOD_OK);
    assert_close(p, 20.0, 1e-15);
    assert_close(tclod_calib_scale(c), 1.0, 0.0);
    tclod_calib_destroy(c);
}

static void the_fixed_budget_leaves_out_the_frames_own_work(void **state) {
    const double hidden[3] = {2e-3, 6e-5, 8e-5};
    tclod_calib *c = make_model(3, hidden, 0.0, 0.0, 0);
    const double fixed[3] = {0.0, 0.0, 1e5}, bad[3] = {0.0, -1.0, 0.0};
    double b = -1.0;
    (void)state;
    report_exact(c, hidden, 0, 50);
    /* 40 ms of render time less 1e5 splats at 8e-5 ms = 8 ms: 32 ms */
    assert_int_equal(tclod_calib_budget_fixed(c, 40.0, fixed, &b), TCLOD_OK);
    assert_close(b, 32.0, 1e-9);
    assert_int_equal(tclod_calib_budget_fixed(c, 40.0, NULL, &b), TCLOD_OK);
    assert_close(b, 40.0, 1e-15);
    /* more than the frame: no budget at all, never a negative one */
    assert_int_equal(tclod_calib_budget_fixed(c, 4.0, fixed, &b), TCLOD_OK);
    assert_true(b == 0.0);
    b = -1.0;
    assert_int_equal(tclod_calib_budget_fixed(c, 40.0, bad, &b), TCLOD_ERR_ARG);
    assert_true(b == -1.0);
    tclod_calib_destroy(c);
}

/* ---- bad input ------------------------------------------------------------ */

static void bad_reports_are_counted_and_ignored_or_fail_when_strict(void **state) {
    const double hidden[3] = {2e-3, 6e-5, 8e-5};
    const double bad[] = {NAN, INFINITY, -INFINITY, -1.0, -1e-300};
    tclod_calib *c = make_model(3, hidden, 0.0, 0.0, 0);
    tclod_calib *s = make_model(3, hidden, 0.0, 0.0, 1);
    double x[3], kept[3], kept_s[3], y;
    size_t i;
    uint32_t f;
    (void)state;
    report_exact(c, hidden, 0, 20);
    report_exact(s, hidden, 0, 20);
    memcpy(kept, tclod_calib_coefficients(c), sizeof kept);
    memcpy(kept_s, tclod_calib_coefficients(s), sizeof kept_s);
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        for (f = 0; f < 4; ++f) { /* each feature, then the render time */
            features_of(20, x);
            y = dot(hidden, x, 3);
            if (f < 3)
                x[f] = bad[i];
            else
                y = bad[i];
            assert_int_equal(tclod_calib_report_features(c, x, y, 1.0), TCLOD_OK);
            assert_int_equal(tclod_calib_report_features(s, x, y, 1.0), TCLOD_ERR_ARG);
            assert_non_null(strstr(tclod_calib_last_error(s), f == 1  ? "features[1] (vertices)"
                                                              : f < 3 ? "must be finite and >= 0"
                                                                      : "render_time"));
        }
        if (bad[i] == (double)TCLOD_OFF)
            continue;       /* -1 says the logic time was not measured */
        features_of(20, x); /* a bad logic time */
        assert_int_equal(tclod_calib_report_features(c, x, dot(hidden, x, 3), bad[i]), TCLOD_OK);
        assert_int_equal(tclod_calib_report_features(s, x, dot(hidden, x, 3), bad[i]),
                         TCLOD_ERR_ARG);
    }
    assert_memory_equal(tclod_calib_coefficients(c), kept, sizeof kept);
    assert_memory_equal(tclod_calib_coefficients(s), kept_s, sizeof kept_s);
    assert_int_equal(counts_of(c).invalid, 24); /* 5 x 4, and 4 logic times */
    assert_int_equal(counts_of(c).frames, 44);
    assert_int_equal(counts_of(s).invalid, 0);
    assert_int_equal(counts_of(s).frames, 20);
    /* the wrong kind of report, and NULL */
    assert_int_equal(tclod_calib_report(c, 1.0, 1.0, 1.0), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_calib_last_error(c), "tclod_calib_report_features"));
    assert_int_equal(tclod_calib_report_features(c, NULL, 1.0, 1.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_calib_report_features(NULL, x, 1.0, 1.0), TCLOD_ERR_ARG);
    assert_null(tclod_calib_coefficients(NULL));
    assert_true(tclod_calib_predict(c, NULL) == 0.0);
    tclod_calib_destroy(c);
    tclod_calib_destroy(s);
    /* a scale calibration has no features to learn */
    {
        tclod_calib_desc d;
        tclod_calib_desc_default(&d);
        assert_int_equal(tclod_calib_create(&d, NULL, &c), TCLOD_OK);
        assert_int_equal(tclod_calib_report_features(c, x, 1.0, 1.0), TCLOD_ERR_ARG);
        assert_non_null(strstr(tclod_calib_last_error(c), "feature_count 0"));
        assert_null(tclod_calib_coefficients(c));
        tclod_calib_destroy(c);
    }
}

static void descs_with_bad_model_fields_are_refused_naming_them(void **state) {
    tclod_calib_desc d;
    tclod_calib *c = NULL;
    (void)state;
    tclod_calib_desc_default(&d);
    d.feature_count = TCLOD_MAX_FEATURES + 1u;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.feature_count"));
    assert_int_equal(tclod_calib_create(&d, NULL, &c), TCLOD_ERR_ARG);
    assert_null(c);
    d.feature_count = 2;
    d.prior[1] = -1.0;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.prior"));
    d.prior[1] = NAN;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.prior"));
    d.prior[1] = 0.0;
    d.forgetting = 1.5;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.forgetting"));
    d.forgetting = 0.0;
    d.outlier = 0.5;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.outlier"));
    d.outlier = 0.0;
    d.strict = 2;
    assert_non_null(strstr(tclod_calib_desc_check(&d), "desc.strict"));
    d.strict = 0;
    assert_null(tclod_calib_desc_check(&d));
}

static void allocation_failure_creates_nothing(void **state) {
    test_alloc counter;
    tclod_allocator hooks;
    tclod_calib_desc d;
    tclod_calib *c = NULL;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    tclod_calib_desc_default(&d);
    d.feature_count = 3;
    test_alloc_fail_at(&counter, 1);
    assert_int_equal(tclod_calib_create(&d, &hooks, &c), TCLOD_ERR_NOMEM);
    assert_null(c);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(tclod_calib_create(&d, &hooks, &c), TCLOD_OK);
    tclod_calib_destroy(c);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.bad_frees, 0);
}

/* ---- the selector's costs from features ------------------------------------ */

/* Ten chains of three levels: level k of chain i draws once with
 * 100 · 4^k vertices; its benefit grows with the level. */
typedef struct chains {
    tclod_scene *scene;
    tclod_id level_of[64];
    int bad; /* 1: node 4's vertex count is NaN */
} chains;

static double chain_benefit(void *user, const tclod_query *q) {
    const chains *h = (const chains *)user;
    return 1.0 + 2.0 * (double)h->level_of[q->id] + 0.01 * (double)q->id;
}

static void chain_features(void *user, const tclod_query *q, double *out) {
    const chains *h = (const chains *)user;
    out[0] = 1.0;
    out[1] = h->bad && q->id == 4 ? (double)NAN : 100.0 * pow(4.0, (double)h->level_of[q->id]);
}

static void make_chains(chains *h) {
    int i, k;
    memset(h, 0, sizeof *h);
    assert_int_equal(tclod_scene_create(NULL, &h->scene), TCLOD_OK);
    for (i = 0; i < 10; ++i) {
        tclod_id parent = TCLOD_NONE, id;
        for (k = 0; k < 3; ++k) {
            assert_int_equal(tclod_scene_add_node(h->scene, parent, NULL, &id), TCLOD_OK);
            h->level_of[id] = (tclod_id)k;
            parent = id;
        }
    }
}

static tclod_selector_desc chain_desc(chains *h) {
    tclod_selector_desc d;
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = chain_benefit;
    d.callbacks.features = chain_features;
    d.callbacks.user = h;
    d.feature_count = 2;
    d.coefficients[0] = 0.5;   /* ms per draw */
    d.coefficients[1] = 0.001; /* ms per vertex */
    return d;
}

/* The selection's cost as coefficients · its summed features. */
static double cut_cost(const chains *h, const tclod_selector *sel, const double *coef) {
    const tclod_id *ids;
    size_t n, i;
    double c = 0.0;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (i = 0; i < n; ++i)
        c += coef[0] + coef[1] * 100.0 * pow(4.0, (double)h->level_of[ids[i]]);
    return c;
}

static void selections_are_priced_by_the_coefficients_within_the_budget(void **state) {
    chains h;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_frame fr;
    tclod_stats st;
    const double dear[2] = {0.5, 0.004}, bad[2] = {0.5, NAN};
    (void)state;
    make_chains(&h);
    d = chain_desc(&h);
    assert_int_equal(tclod_selector_create(h.scene, &d, NULL, &sel), TCLOD_OK);
    memset(&fr, 0, sizeof fr);
    fr.budget = 12.0;
    /* roots: 10 × (0.5 + 0.1) = 6 ms; level 1: 0.5 + 0.4 = 0.9; level 2:
     * 0.5 + 1.6 = 2.1. Within 12 ms the greedy refines: every cost the
     * selection is charged is coefficients · features, and it fits. */
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_close(st.cost, cut_cost(&h, sel, d.coefficients), 1e-12);
    assert_true(st.cost <= fr.budget);
    assert_true(st.cost > 6.0);
    /* vertices four times dearer: the same budget buys less refinement */
    assert_int_equal(tclod_selector_set_coefficients(sel, dear), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_close(st.cost, cut_cost(&h, sel, dear), 1e-12);
    assert_true(st.cost <= fr.budget);
    /* a bad coefficient changes nothing and is named */
    assert_int_equal(tclod_selector_set_coefficients(sel, bad), TCLOD_ERR_ARG);
    assert_non_null(strstr(tclod_selector_last_error(sel), "coefficients[1]"));
    assert_int_equal(tclod_selector_set_coefficients(sel, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_close(st.cost, cut_cost(&h, sel, dear), 1e-12);
    /* not while a solve is pending */
    assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_OK);
    assert_int_equal(tclod_selector_set_coefficients(sel, dear), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select_cancel(sel), TCLOD_OK);
    tclod_selector_destroy(sel);
    assert_int_equal(tclod_scene_destroy(h.scene), TCLOD_OK);
}

static void a_bad_feature_is_a_bad_cost(void **state) {
    chains h;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_frame fr;
    tclod_stats st;
    const tclod_id *ids;
    size_t n, i;
    (void)state;
    make_chains(&h);
    h.bad = 1; /* node 4 (chain 1, level 1) has a NaN vertex count */
    d = chain_desc(&h);
    assert_int_equal(tclod_selector_create(h.scene, &d, NULL, &sel), TCLOD_OK);
    memset(&fr, 0, sizeof fr);
    fr.budget = 1e9;
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_int_equal(st.invalid_values, 1);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (i = 0; i < n; ++i) /* never selected */
        assert_true(ids[i] != 4);
    tclod_selector_destroy(sel);
    d.strict = 1;
    assert_int_equal(tclod_selector_create(h.scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_CALLBACK);
    tclod_selector_destroy(sel);
    assert_int_equal(tclod_scene_destroy(h.scene), TCLOD_OK);
}

static void feature_descs_are_checked(void **state) {
    chains h;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    (void)state;
    make_chains(&h);
    d = chain_desc(&h);
    d.feature_count = 0;
    assert_non_null(strstr(tclod_selector_desc_check(h.scene, &d), "desc.feature_count is 0"));
    d.feature_count = TCLOD_MAX_FEATURES + 1u;
    assert_non_null(strstr(tclod_selector_desc_check(h.scene, &d), "desc.feature_count"));
    d = chain_desc(&h);
    d.coefficients[1] = -1.0;
    assert_non_null(strstr(tclod_selector_desc_check(h.scene, &d), "desc.coefficients"));
    d = chain_desc(&h);
    d.callbacks.features = NULL;
    assert_non_null(strstr(tclod_selector_desc_check(h.scene, &d), "desc.callbacks.cost"));
    assert_int_equal(tclod_selector_create(h.scene, &d, NULL, &sel), TCLOD_ERR_ARG);
    assert_null(sel);
    /* the scheduler takes costs, not features */
    {
        tclod_scheduler_desc sd;
        tclod_scheduler *sch = NULL;
        tclod_scheduler_desc_default(&sd);
        d = chain_desc(&h);
        assert_int_equal(tclod_scheduler_create(h.scene, &d, &sd, NULL, &sch), TCLOD_ERR_ARG);
        assert_null(sch);
        d.callbacks.features = NULL;
        d.feature_count = 0;
        sd.calib.feature_count = 2;
        assert_non_null(strstr(tclod_scheduler_desc_check(&sd), "desc.calib.feature_count"));
    }
    /* selectors without features have none to set */
    d = chain_desc(&h);
    assert_int_equal(tclod_selector_create(h.scene, &d, NULL, &sel), TCLOD_OK);
    tclod_selector_destroy(sel);
    assert_int_equal(tclod_scene_destroy(h.scene), TCLOD_OK);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(coefficients_are_exact_after_enough_independent_frames),
        cmocka_unit_test(the_first_frame_scales_the_prior_or_shares_its_time),
        cmocka_unit_test(a_feature_that_is_always_zero_keeps_its_prior),
        cmocka_unit_test(coefficients_never_go_negative),
        cmocka_unit_test(forgetting_follows_a_change_and_without_it_the_past_stays),
        cmocka_unit_test(a_hitch_is_ignored_and_a_run_of_them_is_a_change),
        cmocka_unit_test(one_feature_is_the_scale_calibration),
        cmocka_unit_test(the_fixed_budget_leaves_out_the_frames_own_work),
        cmocka_unit_test(bad_reports_are_counted_and_ignored_or_fail_when_strict),
        cmocka_unit_test(descs_with_bad_model_fields_are_refused_naming_them),
        cmocka_unit_test(allocation_failure_creates_nothing),
        cmocka_unit_test(selections_are_priced_by_the_coefficients_within_the_budget),
        cmocka_unit_test(a_bad_feature_is_a_bad_cost),
        cmocka_unit_test(feature_descs_are_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
