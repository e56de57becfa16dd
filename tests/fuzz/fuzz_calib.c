/*
 * fuzz_calib — libFuzzer target over the frame-time part of the header:
 * tclod_render_budget and the calibration state (tclod_calib_*), driven by
 * byte-chosen descriptions and measurements (NaN, infinities, negatives,
 * denormals, huge values, zeros).
 *
 * What is checked is what the header promises:
 *  - creation and every call fail with TCLOD_ERR_ARG exactly for the
 *    arguments the header calls bad, and a failed call changes nothing;
 *  - tclod_render_budget follows [RH eq. 5-7] (to rounding) and lies in
 *    [0, frame_time / machine_c];
 *  - after a report the logic estimate is the exponentially weighted average
 *    with logic_rate; the ratio is left alone by a frame that drew nothing or
 *    by a change inside the dead band, and otherwise moves towards
 *    measured / predicted by rise_rate or fall_rate, never past it; it stays
 *    > 0 and finite whatever is reported; unless initial_measured, the first
 *    report sets the logic estimate to its logic time, and the first that
 *    drew something sets the ratio to its measured / predicted;
 *  - tclod_calib_budget is the render budget of the logic estimate divided
 *    by the ratio, never NaN or negative.
 */
#include <tclod/tclod.h>

#include "fuzz_host.h"
#include "fuzz_input.h"

/* |a - b| within rel of the larger magnitude (or both tiny). */
static int close_to(double a, double b, double rel) {
    double m = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    return fabs(a - b) <= rel * m || fabs(a - b) <= 1e-300;
}

/* Whether x is from + rate (to - from) up to rounding: the subtraction may
 * cancel, so the error is relative to the larger of from and to. */
static int weighted(double x, double from, double to, double rate) {
    double m = fabs(from) > fabs(to) ? fabs(from) : fabs(to), f, t;
    if (m <= 1.0) /* nothing overflows; denormals round to multiples of 2^-1074 */
        return fabs(x - (from + rate * (to - from))) <=
               (1e-12 * m > 0x1p-1072 ? 1e-12 * m : 0x1p-1072);
    /* scaled to [-1, 1] first, so that near DBL_MAX nothing overflows */
    f = from / m;
    t = to / m;
    return fabs(x / m - (f + rate * (t - f))) <= 1e-12;
}

static int finite_nonnegative(double x) {
    return x >= 0.0 && !isinf(x);
}

static int finite_positive(double x) {
    return x > 0.0 && !isinf(x);
}

/* A value for a field that is valid most of the time. */
static double field(fuzz_reader *in, double def) {
    uint8_t b = fuzz_u8(in);
    if (b < 128)
        return b == 0 ? def : (double)b / 128.0;
    return fuzz_double(in);
}

static void check_render_budget(double ft, double lt, double c) {
    double out = -7.0, l, rho, expect;
    tclod_status st = tclod_render_budget(ft, lt, c, &out);
    if (!finite_positive(ft) || !finite_nonnegative(lt) || !finite_positive(c)) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG && out == -7.0,
                   "render_budget(%g, %g, %g) gave %d and wrote %g", ft, lt, c, (int)st, out);
        return;
    }
    FUZZ_CHECK(st == TCLOD_OK, "render_budget(%g, %g, %g) gave %d", ft, lt, c, (int)st);
    /* eq. 5-7: l = min(1, (t_l / t_f)^2), rho = 1 - l, t_r = rho^2 t_f / C */
    l = lt / ft;
    l = l >= 1.0 ? 1.0 : l * l;
    rho = 1.0 - l;
    expect = rho * rho * ft / c;
    FUZZ_CHECK(out >= 0.0 && !(out > ft / c * (1.0 + 1e-15)),
               "render_budget(%g, %g, %g) = %g, outside [0, %g]", ft, lt, c, out, ft / c);
    FUZZ_CHECK(close_to(out, expect, 1e-12) || (isinf(expect) && isinf(out)),
               "render_budget(%.17g, %.17g, %.17g) = %.17g, eq. 5-7 give %.17g", ft, lt, c, out,
               expect);
    if (lt >= ft)
        FUZZ_CHECK(out == 0.0, "no render time is left when logic takes the frame: %g", out);
    FUZZ_CHECK(tclod_render_budget(ft, lt, c, NULL) == TCLOD_ERR_ARG, "render_budget(NULL)");
}

static void check_budget(const tclod_calib *c, double ft, double machine_c) {
    double out = -7.0, render = -1.0;
    tclod_status st = tclod_calib_budget(c, ft, &out);
    if (!finite_positive(ft)) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG && out == -7.0, "calib_budget(%g) gave %d", ft, (int)st);
        return;
    }
    FUZZ_CHECK(st == TCLOD_OK, "calib_budget(%g) gave %d", ft, (int)st);
    FUZZ_CHECK(tclod_render_budget(ft, tclod_calib_logic(c), machine_c, &render) == TCLOD_OK,
               "render_budget of the calibration's own logic estimate");
    FUZZ_CHECK(out >= 0.0, "budget %g for frame time %g", out, ft);
    FUZZ_CHECK(out == render / tclod_calib_scale(c),
               "budget %.17g, render budget %.17g / ratio %.17g = %.17g", out, render,
               tclod_calib_scale(c), render / tclod_calib_scale(c));
}

/* Whether the calibration's estimates hold a measurement yet (the model's
 * side of initial_measured). */
typedef struct measured {
    int scale, logic;
} measured;

static void check_report(tclod_calib *c, const tclod_calib_desc *d, measured *m, double pred,
                         double render, double logic) {
    double s = tclod_calib_scale(c), l = tclod_calib_logic(c), s2, l2, ratio;
    tclod_status st = tclod_calib_report(c, pred, render, logic);
    int logic_measured = logic != -1.0; /* TCLOD_OFF: not measured */
    s2 = tclod_calib_scale(c);
    l2 = tclod_calib_logic(c);
    if (!finite_nonnegative(pred) || !finite_nonnegative(render) ||
        (logic_measured && !finite_nonnegative(logic))) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG && s2 == s && l2 == l,
                   "report(%g, %g, %g) gave %d, ratio %g -> %g, logic %g -> %g", pred, render,
                   logic, (int)st, s, s2, l, l2);
        return;
    }
    FUZZ_CHECK(st == TCLOD_OK, "report(%g, %g, %g) gave %d", pred, render, logic, (int)st);
    FUZZ_CHECK(finite_positive(s2), "ratio %g after report(%g, %g, %g)", s2, pred, render, logic);
    FUZZ_CHECK(finite_nonnegative(l2), "logic %g after report(%g, %g, %g)", l2, pred, render,
               logic);
    /* logic: weighted average, between the old estimate and the measurement */
    if (!logic_measured) {
        FUZZ_CHECK(l2 == l, "a report without a logic time moved it %.17g -> %.17g", l, l2);
    } else {
        FUZZ_CHECK((l2 >= l && l2 <= logic) || (l2 <= l && l2 >= logic),
                   "logic %.17g -> %.17g does not move towards %.17g", l, l2, logic);
        if (m->logic)
            FUZZ_CHECK(weighted(l2, l, logic, d->logic_rate),
                       "logic %.17g -> %.17g, the weighted average with rate %g is %.17g", l, l2,
                       d->logic_rate, l + d->logic_rate * (logic - l));
        else
            FUZZ_CHECK(l2 == logic, "the first logic time %.17g gave an estimate of %.17g", logic,
                       l2);
        m->logic = 1;
    }
    if (pred == 0.0) {
        FUZZ_CHECK(s2 == s, "a frame that drew nothing moved the ratio %g -> %g", s, s2);
        return;
    }
    ratio = render / pred;
    if (ratio < DBL_MIN)
        ratio = DBL_MIN; /* the ratio stays > 0 and finite: its range's ends stand in */
    if (ratio > DBL_MAX)
        ratio = DBL_MAX;
    FUZZ_CHECK((s2 >= s && s2 <= ratio) || (s2 <= s && s2 >= ratio),
               "ratio %.17g -> %.17g does not move towards %.17g", s, s2, ratio);
    if (!m->scale) {
        FUZZ_CHECK(s2 == ratio, "the first measured ratio %.17g gave %.17g", ratio, s2);
        m->scale = 1;
        return;
    }
    if (fabs(ratio - s) < d->dead_band * s * (1.0 - 1e-9)) {
        FUZZ_CHECK(s2 == s, "a change inside the dead band moved the ratio %.17g -> %.17g", s, s2);
    } else if (fabs(ratio - s) > d->dead_band * s * (1.0 + 1e-9)) {
        double rate = ratio > s ? d->rise_rate : d->fall_rate;
        FUZZ_CHECK(weighted(s2, s, ratio, rate),
                   "ratio %.17g -> %.17g for a measured %.17g, rate %g gives %.17g", s, s2, ratio,
                   rate, s + rate * (ratio - s));
    }
}

/* A valid desc with the defaults the header gives its 0 fields (and 0 for
 * a dead_band of TCLOD_OFF). */
static void resolve_defaults(tclod_calib_desc *d) {
    tclod_calib_desc def;
    tclod_calib_desc_default(&def);
    d->initial_scale = d->initial_scale == 0.0 ? def.initial_scale : d->initial_scale;
    d->rise_rate = d->rise_rate == 0.0 ? def.rise_rate : d->rise_rate;
    d->fall_rate = d->fall_rate == 0.0 ? def.fall_rate : d->fall_rate;
    d->dead_band = d->dead_band == 0.0 ? def.dead_band : (d->dead_band < 0.0 ? 0.0 : d->dead_band);
    d->logic_rate = d->logic_rate == 0.0 ? def.logic_rate : d->logic_rate;
    d->machine_c = d->machine_c == 0.0 ? def.machine_c : d->machine_c;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    fuzz_reader in;
    tclod_calib_desc d;
    tclod_calib *const sentinel = (tclod_calib *)(void *)&in;
    tclod_calib *c = sentinel;
    tclod_status st;
    measured m;
    int invalid, ops;

    fuzz_reader_init(&in, data, size);
    tclod_calib_desc_default(&d);
    d.initial_scale = field(&in, d.initial_scale);
    d.rise_rate = field(&in, d.rise_rate);
    d.fall_rate = field(&in, d.fall_rate);
    d.dead_band = field(&in, d.dead_band);
    d.logic_rate = field(&in, d.logic_rate);
    d.initial_logic = field(&in, d.initial_logic);
    d.machine_c = field(&in, d.machine_c);
    d.initial_measured = fuzz_u8(&in) & 1;
    m.scale = m.logic = d.initial_measured;
    invalid = calib_desc_invalid(&d);
    st = tclod_calib_create(&d, NULL, &c);
    if (invalid) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG && c == sentinel, "calib_create accepted a bad desc (%d)",
                   (int)st);
        check_render_budget(fuzz_double(&in), fuzz_double(&in), fuzz_double(&in));
        return 0;
    }
    FUZZ_CHECK(st == TCLOD_OK && c != sentinel, "calib_create gave %d", (int)st);
    resolve_defaults(&d); /* what the calibration follows: 0 fields take their defaults */
    FUZZ_CHECK(finite_positive(tclod_calib_scale(c)), "initial ratio %g", tclod_calib_scale(c));
    if (d.initial_scale >= DBL_MIN)
        FUZZ_CHECK(tclod_calib_scale(c) == d.initial_scale, "initial ratio %g, desc %g",
                   tclod_calib_scale(c), d.initial_scale);
    FUZZ_CHECK(tclod_calib_logic(c) == d.initial_logic, "initial logic %g, desc %g",
               tclod_calib_logic(c), d.initial_logic);

    for (ops = 0; ops < 64 && in.pos < in.size; ++ops) {
        switch (fuzz_u8(&in) % 4u) {
        case 0: {
            double pred = fuzz_double(&in), render = fuzz_double(&in), logic = fuzz_double(&in);
            check_report(c, &d, &m, pred, render, logic);
            break;
        }
        case 1:
            check_budget(c, fuzz_double(&in), d.machine_c);
            break;
        case 2: {
            double ft = fuzz_double(&in), lt = fuzz_double(&in), mc = fuzz_double(&in);
            check_render_budget(ft, lt, mc);
            break;
        }
        default:
            FUZZ_CHECK(tclod_calib_report(NULL, 1.0, 1.0, 1.0) == TCLOD_ERR_ARG, "report(NULL)");
            FUZZ_CHECK(tclod_calib_budget(c, 1.0, NULL) == TCLOD_ERR_ARG, "budget(NULL)");
            break;
        }
    }
    tclod_calib_destroy(c);
    return 0;
}
