/*
 * Frame time: the render budget of a target frame time ([RH §5.3],
 * eq. 5-7) and the calibration of predicted cost against measured render time
 * ([GEO §4.2], "feedback strategy ... weighted average"; docs/calibration.md).
 *
 * CPU (logic) and GPU (render) work in parallel, so a frame is neither their
 * sum nor their maximum. [RH] models the render time that fits a frame of
 * t_f with logic t_l as t_r = rho² t_f / C, rho = 1 - min(1, (t_l / t_f)²).
 * Predicted costs are wrong by a factor that drifts with the scene and the
 * driver; after each frame the host reports what it drew and how long it
 * took, an exponentially weighted ratio measured / predicted follows that
 * factor, and the budget to select with is the render time divided by it.
 * The ratio rises quickly and falls slowly (a frame over its target is worse
 * than one under it) and ignores changes within a dead band, so measurement
 * noise does not make the budget, and with it the selection, flicker. The
 * initial ratio and logic time are guesses unless the host says otherwise:
 * the first measurements replace them, so that only the first frame pays for
 * a wrong guess.
 *
 * With features, the ratio gives way to a learned cost model (learn.c): the
 * host reports the frame's summed features instead of one predicted cost, and
 * the render time per unit of each is learned; the budget is then the render
 * time itself, which the selector spends at those coefficients.
 *
 * Layer: schedule, which may call every layer. Calls: core (alloc.c),
 * schedule (learn.c).
 */
#include "learn.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The longest feature name a calibration keeps, with its terminating 0. */
#define CALIB_NAME_SIZE 32

struct tclod_calib {
    tclod_allocator alloc;
    char error[TCLOD_ERROR_SIZE]; /* tclod_calib_last_error */
    tclod_calib_desc desc;
    double scale;                       /* measured render time per unit of predicted cost, in
                                           [DBL_MIN, DBL_MAX] */
    double logic;                       /* logic-time estimate, >= 0, finite */
    int scale_measured, logic_measured; /* the estimates hold a measurement: new
                                           ones blend in; else they replace */
    tclod_learn learn;                  /* feature_count > 0: the learned cost model */
    double coef[TCLOD_MAX_FEATURES];    /* the published coefficients: the model's times
                                           the scale, which follows its error fast */
    tclod_calib_counts counts;
    char names[TCLOD_MAX_FEATURES][CALIB_NAME_SIZE]; /* "" where the host gave none */
};

static int calib_finite_nonnegative(double x) {
    return x >= 0.0 && !isinf(x); /* false for NaN */
}

static int finite_positive(double x) {
    return x > 0.0 && !isinf(x);
}

static int rate_valid(double r) {
    return r > 0.0 && r <= 1.0;
}

tclod_status tclod_render_budget(double frame_time, double logic_time, double machine_c,
                                 double *render_time) {
    double l, rho;
    if (!render_time || !finite_positive(frame_time) || !calib_finite_nonnegative(logic_time) ||
        !finite_positive(machine_c))
        return TCLOD_ERR_ARG;
    /* eq. 5, capped at 1: the frame cannot be shorter than its logic, so a
     * logic time at or above the frame time leaves no render time at all. */
    l = logic_time / frame_time;
    l = l >= 1.0 ? 1.0 : l * l;
    rho = 1.0 - l;                                     /* eq. 6 */
    *render_time = rho * rho * frame_time / machine_c; /* eq. 7 */
    return TCLOD_OK;
}

void tclod_calib_desc_default(tclod_calib_desc *d) {
    if (!d)
        return;
    d->initial_scale = 1.0;
    d->rise_rate = 0.5;
    d->fall_rate = 0.1;
    d->dead_band = 0.01;
    d->logic_rate = 0.2;
    d->initial_logic = 0.0;
    d->machine_c = 1.0;
    d->initial_measured = 0;
    d->feature_count = 0;
    memset(d->feature_names, 0, sizeof d->feature_names);
    memset(d->prior, 0, sizeof d->prior);
    d->forgetting = 0.998;
    d->outlier = 4.0;
    d->prior_weight = 1.0;
    d->least_share = 0.1;
    d->strict = 0;
}

/* A rate: 0 (the default) or in (0, 1]. */
static int rate_or_default(double r) {
    return r == 0.0 || rate_valid(r);
}

/* The rule a calibration desc breaks, named from the desc, or from a
 * scheduler's desc when nested. */
#define FIELD(nested, rule) ((nested) ? "desc.calib." rule : "desc." rule)

const char *tclod_calib_check(const tclod_calib_desc *d, int nested) {
    uint32_t i;
    if (!d)
        return nested ? "desc.calib is NULL" : "desc is NULL";
    if (!(d->initial_scale == 0.0 || finite_positive(d->initial_scale)))
        return FIELD(nested, "initial_scale must be finite and > 0, or 0 (default)");
    if (!rate_or_default(d->rise_rate))
        return FIELD(nested, "rise_rate must be in (0, 1], or 0 (default)");
    if (!rate_or_default(d->fall_rate))
        return FIELD(nested, "fall_rate must be in (0, 1], or 0 (default)");
    if (!(d->dead_band == 0.0 || d->dead_band == (double)TCLOD_OFF ||
          (d->dead_band > 0.0 && d->dead_band < 1.0)))
        return FIELD(nested, "dead_band must be in (0, 1), 0 (default) or TCLOD_OFF");
    if (!rate_or_default(d->logic_rate))
        return FIELD(nested, "logic_rate must be in (0, 1], or 0 (default)");
    if (!calib_finite_nonnegative(d->initial_logic))
        return FIELD(nested, "initial_logic must be finite and >= 0");
    if (!(d->machine_c == 0.0 || finite_positive(d->machine_c)))
        return FIELD(nested, "machine_c must be finite and > 0, or 0 (default)");
    if (d->initial_measured != 0 && d->initial_measured != 1)
        return FIELD(nested, "initial_measured must be 0 or 1");
    if (d->feature_count > TCLOD_MAX_FEATURES)
        return FIELD(nested, "feature_count must be at most TCLOD_MAX_FEATURES (8)");
    if (nested && d->feature_count != 0)
        return "desc.calib.feature_count must be 0: the scheduler calibrates a scale";
    for (i = 0; i < d->feature_count; ++i)
        if (!calib_finite_nonnegative(d->prior[i]))
            return FIELD(nested, "prior: each of the first feature_count must be finite and >= 0");
    if (!(d->forgetting == 0.0 || rate_valid(d->forgetting)))
        return FIELD(nested, "forgetting must be in (0, 1], or 0 (default)");
    if (!(d->outlier == 0.0 || d->outlier == (double)TCLOD_OFF ||
          (d->outlier > 1.0 && !isinf(d->outlier))))
        return FIELD(nested, "outlier must be finite and > 1, 0 (default) or TCLOD_OFF");
    if (!(d->least_share == (double)TCLOD_OFF || (d->least_share >= 0.0 && d->least_share <= 1.0)))
        return FIELD(nested, "least_share must be in [0, 1], or TCLOD_OFF");
    if (!(d->prior_weight == (double)TCLOD_OFF || calib_finite_nonnegative(d->prior_weight)))
        return FIELD(nested, "prior_weight must be finite and >= 0, or TCLOD_OFF");
    if (d->strict != 0 && d->strict != 1)
        return FIELD(nested, "strict must be 0 or 1");
    return NULL;
}

const char *tclod_calib_desc_check(const tclod_calib_desc *d) {
    return tclod_calib_check(d, 0);
}

/* A valid desc with its defaults filled in. */
static tclod_calib_desc calib_resolved(const tclod_calib_desc *d) {
    tclod_calib_desc r = *d, def;
    tclod_calib_desc_default(&def);
    if (r.initial_scale == 0.0)
        r.initial_scale = def.initial_scale;
    if (r.rise_rate == 0.0)
        r.rise_rate = def.rise_rate;
    if (r.fall_rate == 0.0)
        r.fall_rate = def.fall_rate;
    r.dead_band = r.dead_band == 0.0 ? def.dead_band : (r.dead_band < 0.0 ? 0.0 : r.dead_band);
    if (r.logic_rate == 0.0)
        r.logic_rate = def.logic_rate;
    if (r.machine_c == 0.0)
        r.machine_c = def.machine_c;
    if (r.forgetting == 0.0)
        r.forgetting = def.forgetting;
    r.outlier = r.outlier == 0.0 ? def.outlier : (r.outlier < 0.0 ? 0.0 : r.outlier);
    r.least_share =
        r.least_share == 0.0 ? def.least_share : (r.least_share < 0.0 ? 0.0 : r.least_share);
    r.prior_weight =
        r.prior_weight == 0.0 ? def.prior_weight : (r.prior_weight < 0.0 ? 0.0 : r.prior_weight);
    return r;
}

tclod_status tclod_calib_create(const tclod_calib_desc *desc, const tclod_allocator *a,
                                tclod_calib **out) {
    tclod_allocator alloc;
    tclod_calib *c;
    tclod_calib_desc d;
    if (!desc || !out || !tclod_allocator_init(&alloc, a) || tclod_calib_desc_check(desc))
        return TCLOD_ERR_ARG;
    d = calib_resolved(desc);
    c = (tclod_calib *)tclod_mem_alloc(&alloc, sizeof *c);
    if (!c)
        return TCLOD_ERR_NOMEM;
    memset(c, 0, sizeof *c);
    c->alloc = alloc;
    c->desc = d;
    /* A positive finite initial_scale below DBL_MIN (a subnormal) would let
     * the scale leave the range report keeps it in. */
    c->scale = d.initial_scale < DBL_MIN ? DBL_MIN : d.initial_scale;
    c->logic = d.initial_logic;
    c->scale_measured = c->logic_measured = d.initial_measured != 0;
    if (d.feature_count > 0) {
        uint32_t i;
        c->scale = 1.0; /* the coefficients are in render time */
        tclod_learn_init(&c->learn, d.feature_count, d.prior, d.forgetting, d.outlier,
                         d.prior_weight, d.least_share);
        memcpy(c->coef, d.prior, sizeof c->coef);
        for (i = 0; i < d.feature_count; ++i)
            if (d.feature_names[i])
                snprintf(c->names[i], CALIB_NAME_SIZE, "%s", d.feature_names[i]);
        memset(c->desc.feature_names, 0, sizeof c->desc.feature_names); /* not kept */
    }
    *out = c;
    return TCLOD_OK;
}

void tclod_calib_destroy(tclod_calib *c) {
    tclod_allocator alloc;
    if (!c)
        return;
    alloc = c->alloc;
    tclod_mem_free(&alloc, c, sizeof *c);
}

/* from + rate * (to - from) for rate in (0, 1], clamped so that rounding can
 * never carry it past to: the result lies between from and to, so a value
 * kept in a range stays in it. */
static double approach(double from, double to, double rate) {
    double x = from + rate * (to - from);
    if (to >= from)
        return x > to ? to : x;
    return x < to ? to : x;
}

/* Moves the scale towards a measured ratio at the rise or fall rate, unless
 * the ratio is within the dead band. */
static void calib_scale(tclod_calib *c, double ratio) {
    double s = c->scale;
    if (fabs(ratio - s) > c->desc.dead_band * s)
        c->scale = approach(s, ratio, ratio > s ? c->desc.rise_rate : c->desc.fall_rate);
}

/* Blends a measured logic time into the estimate (the first replaces a guess). */
static void calib_logic(tclod_calib *c, double logic_time) {
    c->logic = c->logic_measured ? approach(c->logic, logic_time, c->desc.logic_rate) : logic_time;
    c->logic_measured = 1;
}

tclod_status tclod_calib_report(tclod_calib *c, double predicted_cost, double render_time,
                                double logic_time) {
    static const char fn[] = "tclod_calib_report";
    int logic = logic_time != (double)TCLOD_OFF; /* TCLOD_OFF: not measured */
    if (!c)
        return TCLOD_ERR_ARG;
    if (c->desc.feature_count > 0)
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn,
                          "the calibration learns features: report with "
                          "tclod_calib_report_features");
    if (!calib_finite_nonnegative(predicted_cost))
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn, "predicted_cost must be finite and >= 0");
    if (!calib_finite_nonnegative(render_time))
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn, "render_time must be finite and >= 0");
    if (logic && !calib_finite_nonnegative(logic_time))
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn,
                          "logic_time must be finite and >= 0, or TCLOD_OFF");
    /* A frame that drew nothing says nothing about the cost model. */
    if (predicted_cost > 0.0) {
        double ratio = render_time / predicted_cost;
        /* A render time of 0, or a tiny predicted cost that overflows the
         * division, would drive the scale to 0 or inf, from which no budget
         * (or only NaN) follows; the ends of the range stand in for them. */
        if (ratio < DBL_MIN)
            ratio = DBL_MIN;
        if (ratio > DBL_MAX)
            ratio = DBL_MAX;
        if (!c->scale_measured)
            c->scale = ratio; /* the first measurement, against a guess */
        else
            calib_scale(c, ratio);
        c->scale_measured = 1;
    }
    if (logic)
        calib_logic(c, logic_time);
    return TCLOD_OK;
}

/* A report's bad value: counted and the frame ignored, or the strict call
 * fails naming it (and then changes nothing). */
static tclod_status calib_bad(tclod_calib *c, const char *what) {
    if (c->desc.strict)
        return tclod_fail(c->error, TCLOD_ERR_ARG, "tclod_calib_report_features", what);
    c->counts.frames++;
    c->counts.invalid++;
    return TCLOD_OK;
}

tclod_status tclod_calib_report_features(tclod_calib *c, const double *features, double render_time,
                                         double logic_time) {
    static const char fn[] = "tclod_calib_report_features";
    int logic = logic_time != (double)TCLOD_OFF, started;
    tclod_learn_result res;
    double p;
    uint32_t i;
    if (!c)
        return TCLOD_ERR_ARG;
    if (c->desc.feature_count == 0)
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn,
                          "the calibration has no features (desc.feature_count 0): report "
                          "with tclod_calib_report");
    if (!features)
        return tclod_fail(c->error, TCLOD_ERR_ARG, fn, "features is NULL");
    for (i = 0; i < c->desc.feature_count; ++i)
        if (!calib_finite_nonnegative(features[i])) {
            char what[96];
            snprintf(what, sizeof what, "features[%u]%s%s%s must be finite and >= 0", i,
                     c->names[i][0] ? " (" : "", c->names[i], c->names[i][0] ? ")" : "");
            return calib_bad(c, what);
        }
    if (!calib_finite_nonnegative(render_time))
        return calib_bad(c, "render_time must be finite and >= 0");
    if (logic && !calib_finite_nonnegative(logic_time))
        return calib_bad(c, "logic_time must be finite and >= 0, or TCLOD_OFF");
    c->counts.frames++;
    started = c->learn.started;
    p = tclod_learn_predict(&c->learn, features);
    res = tclod_learn_frame(&c->learn, features, render_time);
    /* The scale follows the model's error fast, at the rates and outside the
     * dead band, as the scale calibration follows its ratio (frames slower than
     * the model said are corrected at once, while the model, which remembers
     * hundreds of frames, catches up), and ends once the model alone is right
     * to within the dead band, and so is the scale. The first frame and a
     * change of machine start it at 1. */
    if (res == TCLOD_LEARN_USED && started && p > 0.0) {
        double q = render_time / p < DBL_MAX ? render_time / p : DBL_MAX; /* p may be tiny */
        double band = c->desc.dead_band;
        if (fabs(q - 1.0) <= band && fabs(c->scale - 1.0) <= band)
            c->scale = 1.0;
        else
            calib_scale(c, q);
    } else if (res == TCLOD_LEARN_CHANGE) {
        c->scale = 1.0;
    }
    for (i = 0; i < c->desc.feature_count; ++i) /* finite, whatever the product */
        c->coef[i] =
            c->learn.theta[i] * c->scale < DBL_MAX ? c->learn.theta[i] * c->scale : DBL_MAX;
    switch (res) {
    case TCLOD_LEARN_USED:
        c->counts.used++;
        break;
    case TCLOD_LEARN_EMPTY:
        c->counts.empty++;
        break;
    case TCLOD_LEARN_OUTLIER:
        c->counts.outliers++;
        break;
    case TCLOD_LEARN_CHANGE:
        c->counts.changes++;
        c->counts.used += TCLOD_LEARN_RUN;
        c->counts.outliers -= TCLOD_LEARN_RUN - 1u; /* the run's first were counted */
        break;
    }
    if (logic)
        calib_logic(c, logic_time);
    return TCLOD_OK;
}

const double *tclod_calib_coefficients(const tclod_calib *c) {
    return c && c->desc.feature_count > 0 ? c->coef : NULL;
}

double tclod_calib_predict(const tclod_calib *c, const double *features) {
    double p = 0.0;
    uint32_t i;
    if (!c || !features)
        return 0.0;
    for (i = 0; i < c->desc.feature_count; ++i)
        p += c->coef[i] * features[i];
    return p;
}

tclod_status tclod_calib_get_counts(const tclod_calib *c, tclod_calib_counts *out) {
    if (!out)
        return TCLOD_ERR_ARG;
    if (c)
        *out = c->counts;
    else
        memset(out, 0, sizeof *out);
    return TCLOD_OK;
}

double tclod_calib_scale(const tclod_calib *c) {
    return c ? c->scale : 0.0;
}

double tclod_calib_logic(const tclod_calib *c) {
    return c ? c->logic : 0.0;
}

tclod_status tclod_calib_budget(const tclod_calib *c, double frame_time, double *budget) {
    double render;
    tclod_status st;
    if (!c || !budget)
        return TCLOD_ERR_ARG;
    st = tclod_render_budget(frame_time, c->logic, c->desc.machine_c, &render);
    if (st != TCLOD_OK)
        return st;
    *budget = c->desc.feature_count > 0 ? render : render / c->scale;
    return TCLOD_OK;
}

tclod_status tclod_calib_budget_fixed(const tclod_calib *c, double frame_time, const double *fixed,
                                      double *budget) {
    double b, f = 0.0;
    uint32_t i;
    tclod_status st;
    if (!c || !budget)
        return TCLOD_ERR_ARG;
    for (i = 0; fixed && i < c->desc.feature_count; ++i)
        if (!calib_finite_nonnegative(fixed[i]))
            return TCLOD_ERR_ARG;
    st = tclod_calib_budget(c, frame_time, &b);
    if (st != TCLOD_OK)
        return st;
    if (fixed && c->desc.feature_count > 0)
        f = tclod_calib_predict(c, fixed);
    *budget = b > f ? b - f : 0.0;
    return TCLOD_OK;
}

const char *tclod_calib_last_error(const tclod_calib *c) {
    return c ? c->error : "";
}
