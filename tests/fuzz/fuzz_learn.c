/*
 * fuzz_learn — libFuzzer target over the learned cost model: a calibration
 * with features (tclod_calib_report_features, tclod_calib_coefficients,
 * tclod_calib_predict, tclod_calib_budget_fixed, tclod_calib_get_counts),
 * driven by byte-chosen descriptions, features and times (NaN, infinities,
 * negatives, denormals, huge values, zeros, runs of equal frames).
 *
 * What is checked is what the header promises:
 *  - creation fails with TCLOD_ERR_ARG exactly for the descs the header calls
 *    bad;
 *  - a report with a feature or time NaN, infinite or negative changes no
 *    coefficient: counted as invalid, or, strict, TCLOD_ERR_ARG and not even
 *    counted; any other report is TCLOD_OK;
 *  - the coefficients are always finite and >= 0, whatever was reported, and
 *    a feature no frame has shown yet keeps its prior times the scale the
 *    coefficients carry;
 *  - the counts add up: frames = used + invalid + empty + outliers;
 *  - predictions are >= 0 and never NaN; the fixed budget is the budget less
 *    the fixed features' prediction, never below 0, and refuses bad fixed
 *    features without writing.
 */
#include <float.h>

#include <tclod/tclod.h>

#include "fuzz_host.h"
#include "fuzz_input.h"

static int finite_nonnegative(double x) {
    return x >= 0.0 && !isinf(x);
}

/* A value that is a valid feature most of the time: small counts, or any. */
static double feature(fuzz_reader *in) {
    uint8_t b = fuzz_u8(in);
    if (b < 192)
        return b < 32 ? 0.0 : (double)(b - 31) * 100.0;
    return fuzz_double(in);
}

/* A desc field that is valid most of the time. */
static double field(fuzz_reader *in, double def) {
    uint8_t b = fuzz_u8(in);
    if (b < 128)
        return b == 0 ? def : (double)b / 128.0;
    return fuzz_double(in);
}

/* Whether the model fields of d break a rule of the header. */
static int model_desc_invalid(const tclod_calib_desc *d) {
    uint32_t i;
    if (d->feature_count > TCLOD_MAX_FEATURES)
        return 1;
    for (i = 0; i < d->feature_count; ++i)
        if (!finite_nonnegative(d->prior[i]))
            return 1;
    if (!(d->forgetting == 0.0 || (d->forgetting > 0.0 && d->forgetting <= 1.0)))
        return 1;
    if (!(d->outlier == 0.0 || d->outlier == -1.0 || (d->outlier > 1.0 && !isinf(d->outlier))))
        return 1;
    if (!(d->prior_weight == -1.0 || finite_nonnegative(d->prior_weight)))
        return 1;
    return 0;
}

static void check_coefficients(const tclod_calib *c, uint32_t n, const double *prior,
                               const int *seen) {
    const double *coef = tclod_calib_coefficients(c);
    uint32_t i;
    FUZZ_CHECK(coef != NULL, "no coefficients");
    for (i = 0; i < n; ++i) {
        FUZZ_CHECK(finite_nonnegative(coef[i]), "coefficient %u is %g", i, coef[i]);
        if (!seen[i]) /* (at most DBL_MAX: coefficients stay finite) */
            FUZZ_CHECK(coef[i] == (prior[i] * tclod_calib_scale(c) < DBL_MAX
                                       ? prior[i] * tclod_calib_scale(c)
                                       : DBL_MAX),
                       "feature %u, never shown, priced %.17g, its prior %.17g x %.17g", i, coef[i],
                       prior[i], tclod_calib_scale(c));
    }
}

static void check_counts(const tclod_calib *c) {
    tclod_calib_counts k;
    FUZZ_CHECK(tclod_calib_get_counts(c, &k) == TCLOD_OK, "get_counts");
    FUZZ_CHECK(k.frames == k.used + k.invalid + k.empty + k.outliers,
               "counts: %u frames, %u used, %u invalid, %u empty, %u outliers", k.frames, k.used,
               k.invalid, k.empty, k.outliers);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    fuzz_reader in;
    tclod_calib_desc d;
    tclod_calib *c = NULL;
    double prior[TCLOD_MAX_FEATURES], x[TCLOD_MAX_FEATURES], repeat[TCLOD_MAX_FEATURES];
    int seen[TCLOD_MAX_FEATURES] = {0}, invalid, ops;
    uint32_t n, i;
    tclod_status st;

    fuzz_reader_init(&in, data, size);
    tclod_calib_desc_default(&d);
    n = fuzz_u8(&in) % (TCLOD_MAX_FEATURES + 2u); /* 0 and 9 are bad for this target */
    d.feature_count = n;
    for (i = 0; i < TCLOD_MAX_FEATURES; ++i)
        d.prior[i] = fuzz_u8(&in) < 200 ? (double)fuzz_u8(&in) * 1e-4 : fuzz_double(&in);
    d.forgetting = field(&in, 0.0);
    d.outlier = fuzz_u8(&in) & 1 ? -1.0 : 1.0 + 8.0 * field(&in, 3.0);
    d.prior_weight = fuzz_u8(&in) & 1 ? -1.0 : field(&in, 0.0);
    d.dead_band = field(&in, 0.0) * 0.5;
    d.rise_rate = field(&in, 0.0);
    d.fall_rate = field(&in, 0.0);
    d.strict = fuzz_u8(&in) & 1;
    invalid =
        model_desc_invalid(&d) ||
        !(d.rise_rate == 0.0 || (d.rise_rate > 0.0 && d.rise_rate <= 1.0)) ||
        !(d.fall_rate == 0.0 || (d.fall_rate > 0.0 && d.fall_rate <= 1.0)) ||
        !(d.dead_band == 0.0 || d.dead_band == -1.0 || (d.dead_band > 0.0 && d.dead_band < 1.0));
    st = tclod_calib_create(&d, NULL, &c);
    if (invalid) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG, "calib_create accepted a bad desc (%d)", (int)st);
        return 0;
    }
    FUZZ_CHECK(st == TCLOD_OK, "calib_create gave %d", (int)st);
    if (n == 0) { /* the scale calibration: it has no features */
        FUZZ_CHECK(tclod_calib_coefficients(c) == NULL, "coefficients without features");
        FUZZ_CHECK(tclod_calib_report_features(c, x, 1.0, 1.0) == TCLOD_ERR_ARG,
                   "report_features without features");
        tclod_calib_destroy(c);
        return 0;
    }
    memcpy(prior, d.prior, sizeof prior);
    for (i = 0; i < n; ++i)
        repeat[i] = 100.0 * (double)(i + 1);

    for (ops = 0; ops < 96 && in.pos < in.size; ++ops) {
        uint8_t op = fuzz_u8(&in);
        double y, logic, before[TCLOD_MAX_FEATURES];
        tclod_calib_counts k0, k1;
        int bad = 0;
        if (op % 4u == 3u) { /* the fixed budget */
            double b = -7.0, plain = -7.0, ft = fuzz_u8(&in) < 200 ? 50.0 : fuzz_double(&in);
            for (i = 0; i < n; ++i) {
                x[i] = feature(&in);
                bad |= !finite_nonnegative(x[i]);
            }
            st = tclod_calib_budget_fixed(c, ft, x, &b);
            if (bad || !(ft > 0.0 && !isinf(ft))) {
                FUZZ_CHECK(st == TCLOD_ERR_ARG && b == -7.0, "budget_fixed took bad input");
                continue;
            }
            FUZZ_CHECK(st == TCLOD_OK && tclod_calib_budget(c, ft, &plain) == TCLOD_OK,
                       "budget_fixed gave %d", (int)st);
            FUZZ_CHECK(b >= 0.0 && b <= plain, "fixed budget %g, budget %g", b, plain);
            FUZZ_CHECK(tclod_calib_predict(c, x) >= 0.0, "prediction %g",
                       tclod_calib_predict(c, x));
            continue;
        }
        /* a frame: often the same one again (a steady view), else new values */
        for (i = 0; i < n; ++i) {
            x[i] = op % 4u == 0u ? repeat[i] : feature(&in);
            bad |= !finite_nonnegative(x[i]);
        }
        y = fuzz_u8(&in) < 200 ? 0.01 * (double)(fuzz_u8(&in) + 1) * (1.0 + (double)n)
                               : fuzz_double(&in);
        logic = fuzz_u8(&in) < 128 ? -1.0 : fuzz_double(&in);
        bad |= !finite_nonnegative(y) || (logic != -1.0 && !finite_nonnegative(logic));
        memcpy(before, tclod_calib_coefficients(c), sizeof before);
        FUZZ_CHECK(tclod_calib_get_counts(c, &k0) == TCLOD_OK, "get_counts");
        st = tclod_calib_report_features(c, x, y, logic);
        FUZZ_CHECK(tclod_calib_get_counts(c, &k1) == TCLOD_OK, "get_counts");
        if (bad) {
            FUZZ_CHECK(memcmp(before, tclod_calib_coefficients(c), n * sizeof(double)) == 0,
                       "a bad report moved the coefficients");
            if (d.strict)
                FUZZ_CHECK(st == TCLOD_ERR_ARG && k1.frames == k0.frames,
                           "strict: a bad report gave %d", (int)st);
            else
                FUZZ_CHECK(st == TCLOD_OK && k1.invalid == k0.invalid + 1u &&
                               k1.frames == k0.frames + 1u,
                           "a bad report gave %d and was not counted", (int)st);
        } else {
            FUZZ_CHECK(st == TCLOD_OK, "report gave %d", (int)st);
            FUZZ_CHECK(k1.frames == k0.frames + 1u, "a report not counted");
            if (y > 0.0)
                for (i = 0; i < n; ++i)
                    seen[i] |= x[i] > 0.0;
        }
        check_coefficients(c, n, prior, seen);
        check_counts(c);
        FUZZ_CHECK(!isnan(tclod_calib_predict(c, repeat)) && tclod_calib_predict(c, repeat) >= 0.0,
                   "prediction %g", tclod_calib_predict(c, repeat));
    }
    tclod_calib_destroy(c);
    return 0;
}
