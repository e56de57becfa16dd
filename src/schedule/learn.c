/*
 * The learned cost model: render time = coefficients · features ([GEO §4.2]'s
 * per-vertex feedback, extended to several features as in [WIM03]'s
 * rendering-time estimates; docs/calibration.md, the learned cost).
 *
 * Each frame adds one equation z · beta = 1 in normalised coordinates (the
 * features over their first values, the time over the first frame's, divided
 * by the frame's time: the error is relative, the measure frames are judged
 * by). The model keeps the information form of exponentially weighted least
 * squares, r = sum of lambda^age z z^T and b = sum of lambda^age z, whose
 * solution is the estimate recursive least squares with forgetting tracks
 * ([LS83]), and solves r beta = b for beta >= least · prior with the
 * active-set method of [LH74] (at most 8 unknowns). Recursive least squares
 * proper (the covariance update) cannot clip a coefficient without losing
 * track of the others, and its covariance winds up in the directions frames
 * do not excite; here the prior is one more weighted equation per feature,
 * decaying like a frame down to a floor (prior_weight), so a coefficient the
 * frames do not determine stays where the prior put it and one never seen
 * keeps its prior exactly. The least share keeps a selection from buying
 * without bound a feature the frames priced near 0.
 *
 * Outliers (a hitch, a resize): a frame whose relative error exceeds
 * `outlier` times the running mean of the used frames' is ignored, unless
 * TCLOD_LEARN_RUN in a row err the same way: that is a change of machine, and
 * the model starts again from them, the old estimate scaled to them as prior.
 *
 * Layer: schedule, which may call every layer. Calls: nothing outside this file.
 */
#include "learn.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* The prior's weight at the start, in frames (one frame's equation has a
 * weight |z|² of about the number of features it shows; the floor it decays
 * to is the desc's prior_weight), and the least floor, which keeps r positive
 * definite. */
#define TCLOD_LEARN_PRIOR 1.0
#define TCLOD_LEARN_FLOOR 1e-9
/* The least mean relative error the outlier test assumes: a model that fits
 * exactly still lets through the errors of a frame timer. */
#define TCLOD_LEARN_MIN_ERR 0.01
/* How fast the mean relative error follows the frames used. */
#define TCLOD_LEARN_ERR_RATE 0.1

/* A frame whose normalised features reach this is beyond what the model can
 * weigh against its first frames (their products would overflow): ignored. */
#define TCLOD_LEARN_RANGE 1e100

/* v as a coefficient: finite and >= 0 (NaN and negatives 0, beyond DBL_MAX
 * DBL_MAX), so that no input drives a coefficient to inf or NaN. */
static double coefficient(double v) {
    return v >= 0.0 ? (v <= DBL_MAX ? v : DBL_MAX) : 0.0;
}

/* The normalised prior of feature i (0 while it has not been seen). */
static double prior_beta(const tclod_learn *m, uint32_t i) {
    double v = m->s[i] > 0.0 ? m->prior[i] * (m->s[i] / m->y0) : 0.0;
    return v < TCLOD_LEARN_RANGE ? v : TCLOD_LEARN_RANGE;
}

/* Solves a_pp s_p = b_p over the features with p[i] set by Cholesky, s = 0
 * elsewhere. 0 when a_pp is not positive definite to rounding. */
static int solve_passive(const double *a, const double *b, uint32_t n, const int *p, double *s) {
    double l[TCLOD_MAX_FEATURES * TCLOD_MAX_FEATURES], y[TCLOD_MAX_FEATURES];
    uint32_t idx[TCLOD_MAX_FEATURES], m = 0, i, j, k;
    for (i = 0; i < n; ++i) {
        s[i] = 0.0;
        if (p[i])
            idx[m++] = i;
    }
    for (i = 0; i < m; ++i) {
        for (j = 0; j <= i; ++j) {
            double v = a[idx[i] * n + idx[j]];
            for (k = 0; k < j; ++k)
                v -= l[i * m + k] * l[j * m + k];
            if (i == j) {
                if (!(v > 1e-300))
                    return 0;
                l[i * m + i] = sqrt(v);
            } else {
                l[i * m + j] = v / l[j * m + j];
            }
        }
    }
    for (i = 0; i < m; ++i) { /* l y = b */
        double v = b[idx[i]];
        for (k = 0; k < i; ++k)
            v -= l[i * m + k] * y[k];
        y[i] = v / l[i * m + i];
    }
    for (i = m; i-- > 0;) { /* l^T x = y */
        double v = y[i];
        for (k = i + 1; k < m; ++k)
            v -= l[k * m + i] * s[idx[k]];
        s[idx[i]] = v / l[i * m + i];
    }
    return 1;
}

/* x = argmin 1/2 x^T a x - b^T x over x >= 0, a symmetric positive definite
 * (n x n, row-major): [LH74]'s active set, on the normal equations. */
static void solve_nonnegative(const double *a, const double *b, uint32_t n, double *x) {
    int passive[TCLOD_MAX_FEATURES];
    double s[TCLOD_MAX_FEATURES];
    uint32_t i, k, round, step;
    for (i = 0; i < n; ++i) {
        x[i] = 0.0;
        passive[i] = 0;
    }
    for (round = 0; round < 4u * n + 8u; ++round) {
        uint32_t j = n;
        double best = 0.0;
        for (i = 0; i < n; ++i) { /* the most negative slope among the bound ones */
            double w = b[i], scale = fabs(b[i]);
            if (passive[i])
                continue;
            for (k = 0; k < n; ++k) {
                w -= a[i * n + k] * x[k];
                scale += fabs(a[i * n + k] * x[k]);
            }
            if (w > 1e-12 * scale && w > best) {
                best = w;
                j = i;
            }
        }
        if (j == n)
            return;
        passive[j] = 1;
        /* each step that clips frees at least one unknown: at most n steps */
        for (step = 0; step <= n; ++step) {
            double alpha = 1.0;
            uint32_t first = n; /* the unknown whose clipping limits the step */
            if (!solve_passive(a, b, n, passive, s)) {
                passive[j] = 0;
                return;
            }
            for (i = 0; i < n; ++i)
                if (passive[i] && s[i] <= 0.0) {
                    double t = x[i] / (x[i] - s[i]); /* NaN when both are 0: no limit */
                    if (t < alpha || (first == n && t == alpha)) {
                        alpha = t;
                        first = i;
                    }
                }
            if (first == n) {
                for (i = 0; i < n; ++i)
                    x[i] = passive[i] ? s[i] : 0.0;
                break;
            }
            for (i = 0; i < n; ++i) {
                if (!passive[i])
                    continue;
                x[i] += alpha * (s[i] - x[i]);
                if (i == first || x[i] <= 0.0) { /* rounding may leave it a hair above 0 */
                    x[i] = 0.0;
                    passive[i] = 0;
                }
            }
        }
    }
}

void tclod_learn_init(tclod_learn *m, uint32_t n, const double *prior, double forgetting,
                      double outlier, double floor, double least) {
    uint32_t i;
    memset(m, 0, sizeof *m);
    m->n = n;
    m->forgetting = forgetting;
    m->outlier = outlier;
    memcpy(m->prior, prior, n * sizeof *prior);
    memcpy(m->theta, prior, n * sizeof *prior);
    m->floor = floor > TCLOD_LEARN_FLOOR ? floor : TCLOD_LEARN_FLOOR;
    m->least = least;
    m->prior_weight = m->floor > TCLOD_LEARN_PRIOR ? m->floor : TCLOD_LEARN_PRIOR;
    for (i = 0; i < n; ++i)
        m->r[i * n + i] = m->prior_weight;
    m->warm = n + 2u;
}

double tclod_learn_predict(const tclod_learn *m, const double *x) {
    double p = 0.0;
    uint32_t i;
    for (i = 0; i < m->n; ++i)
        p += m->theta[i] * x[i];
    return p;
}

/* Adds the equation of frame (x, y) with forgetting, and solves. */
static void learn_add(tclod_learn *m, const double *x, double y) {
    double z[TCLOD_MAX_FEATURES], lambda = m->forgetting, q = m->prior_weight * lambda, top;
    double low[TCLOD_MAX_FEATURES], shifted[TCLOD_MAX_FEATURES];
    uint32_t n = m->n, i, j;
    for (i = 0; i < n; ++i) {
        if (x[i] > 0.0 && m->s[i] == 0.0) { /* first seen: its prior joins b */
            m->s[i] = x[i];
            m->b[i] = m->prior_weight * prior_beta(m, i);
        }
        z[i] = m->s[i] > 0.0 ? x[i] / m->s[i] * (m->y0 / y) : 0.0;
    }
    top = q < m->floor ? m->floor - q : 0.0;
    m->prior_weight = q + top;
    for (i = 0; i < n; ++i) {
        for (j = 0; j < n; ++j)
            m->r[i * n + j] = lambda * m->r[i * n + j] + z[i] * z[j];
        m->r[i * n + i] += top;
        m->b[i] = lambda * m->b[i] + z[i] + top * prior_beta(m, i);
    }
    /* beta >= least * prior: beta = low + d with d >= 0 minimises
     * 1/2 d^T r d - (b - r low)^T d */
    for (i = 0; i < n; ++i)
        low[i] = m->least * prior_beta(m, i);
    for (i = 0; i < n; ++i) {
        shifted[i] = m->b[i];
        for (j = 0; j < n; ++j)
            shifted[i] -= m->r[i * n + j] * low[j];
    }
    solve_nonnegative(m->r, shifted, n, m->beta);
    for (i = 0; i < n; ++i)
        m->beta[i] += low[i];
    for (i = 0; i < n; ++i)
        m->theta[i] = m->s[i] > 0.0 ? coefficient(m->beta[i] * (m->y0 / m->s[i])) : m->prior[i];
    if (m->warm > 0u)
        m->warm--;
}

/* The run of outliers is a change of machine: starts again from the old
 * estimate scaled to the run's frames as prior, and learns them. */
static void learn_restart(tclod_learn *m) {
    double ratio = 0.0;
    uint32_t n = m->n, i, k, counted = 0;
    for (k = 0; k < TCLOD_LEARN_RUN; ++k) {
        double p = tclod_learn_predict(m, m->run_x[k]);
        if (p > 0.0) {
            ratio += m->run_y[k] / p;
            counted++;
        }
    }
    ratio = counted > 0u ? ratio / (double)counted : 1.0;
    for (i = 0; i < n; ++i)
        if (m->s[i] > 0.0)
            m->prior[i] = coefficient(m->theta[i] * ratio);
    memset(m->r, 0, sizeof m->r);
    m->prior_weight = m->floor > TCLOD_LEARN_PRIOR ? m->floor : TCLOD_LEARN_PRIOR;
    for (i = 0; i < n; ++i) {
        m->r[i * n + i] = m->prior_weight;
        m->b[i] = m->prior_weight * prior_beta(m, i);
        m->theta[i] = m->prior[i];
    }
    for (k = 0; k < TCLOD_LEARN_RUN; ++k)
        learn_add(m, m->run_x[k], m->run_y[k]);
    m->warm = n + 2u;
    m->run = 0u;
    m->mean_err = 0.0;
}

tclod_learn_result tclod_learn_frame(tclod_learn *m, const double *x, double y) {
    uint32_t n = m->n, i, shown = 0;
    int seen = 0;
    double p, u;
    for (i = 0; i < n; ++i)
        seen |= x[i] > 0.0;
    if (!seen || !(y > 0.0))
        return TCLOD_LEARN_EMPTY;
    p = tclod_learn_predict(m, x);
    if (!m->started) {
        /* the cold start: the prior's scale from the first frame (a one-feature
         * calibration's first measurement), its mix from the host; with no
         * prior for what the frame drew, its time shared equally among the
         * features it drew */
        for (i = 0; i < n; ++i)
            shown += x[i] > 0.0;
        for (i = 0; i < n; ++i)
            if (x[i] > 0.0) {
                m->prior[i] =
                    coefficient(p > 0.0 ? m->prior[i] * (y / p) : y / ((double)shown * x[i]));
                m->theta[i] = m->prior[i];
            }
        m->y0 = y;
        m->started = 1;
        p = tclod_learn_predict(m, x);
    }
    if (!(m->y0 / y < TCLOD_LEARN_RANGE)) /* within the model's range of its first frames */
        return TCLOD_LEARN_OUTLIER;
    for (i = 0; i < n; ++i)
        if (x[i] > 0.0 && m->s[i] > 0.0 && !(x[i] / m->s[i] * (m->y0 / y) < TCLOD_LEARN_RANGE))
            return TCLOD_LEARN_OUTLIER;
    u = (y - p) / y;
    if (m->outlier > 0.0 && m->warm == 0u &&
        fabs(u) > m->outlier * fmax(m->mean_err, TCLOD_LEARN_MIN_ERR)) {
        int sign = u > 0.0 ? 1 : -1;
        if (m->run > 0u && sign != m->run_sign)
            m->run = 0u;
        memcpy(m->run_x[m->run], x, n * sizeof *x);
        m->run_y[m->run] = y;
        m->run_sign = sign;
        if (++m->run < TCLOD_LEARN_RUN)
            return TCLOD_LEARN_OUTLIER;
        learn_restart(m);
        return TCLOD_LEARN_CHANGE;
    }
    m->run = 0u;
    m->mean_err =
        m->mean_err == 0.0 ? fabs(u) : m->mean_err + TCLOD_LEARN_ERR_RATE * (fabs(u) - m->mean_err);
    learn_add(m, x, y);
    return TCLOD_LEARN_USED;
}
