/*
 * The learned cost model of a calibration (learn.c; docs/calibration.md, the
 * learned cost): render time = coefficients · features, fitted to the frames
 * reported by exponentially weighted least squares in information form (the
 * estimate of recursive least squares with forgetting), solved with
 * non-negative coefficients.
 */
#ifndef TCLOD_LEARN_H
#define TCLOD_LEARN_H

#include "../core/internal.h"

/* The frames of a run of outliers kept, to start again from when the run is
 * a change of machine: this many in a row, erring the same way. */
#define TCLOD_LEARN_RUN 2u

typedef struct tclod_learn {
    uint32_t n;                       /* features, 1 .. TCLOD_MAX_FEATURES */
    double forgetting;                /* lambda, (0, 1] */
    double outlier;                   /* outlier threshold in mean relative errors; 0: none */
    double theta[TCLOD_MAX_FEATURES]; /* the coefficients, host units, >= 0 */
    /* Normalised coordinates: feature i in units of s[i] (its first value
     * above 0; 0 while never seen), time in units of y0 (the first frame's).
     * A frame is the equation z · beta = 1, z_i = x_i / s_i · y0 / y: the
     * error relative to the frame's time, the measure the frame time is
     * judged by. */
    double s[TCLOD_MAX_FEATURES];
    double y0;
    double prior[TCLOD_MAX_FEATURES];                  /* the prior, host units: the host's, scaled
                                                          by the first frame, then the estimate a
                                                          change starts again from */
    double r[TCLOD_MAX_FEATURES * TCLOD_MAX_FEATURES]; /* information: sum lambda^age z z^T
                                                           + the prior's weight */
    double b[TCLOD_MAX_FEATURES];                      /* sum lambda^age z + its prior */
    double beta[TCLOD_MAX_FEATURES];                   /* the solution, >= 0 */
    double prior_weight;                               /* the prior's weight left in r, >= floor */
    double floor;                                      /* the least weight the prior keeps, > 0 */
    double least;    /* the least coefficient as a share of the prior, [0, 1] */
    double mean_err; /* running mean |relative error| of the frames used */
    uint32_t warm;   /* frames still to use without the outlier test */
    uint32_t run;    /* outliers in a row erring the same way */
    int run_sign;
    double run_x[TCLOD_LEARN_RUN][TCLOD_MAX_FEATURES], run_y[TCLOD_LEARN_RUN];
    int started; /* a frame has been used: y0 is set */
} tclod_learn;

/* What tclod_learn_frame did with a frame. */
typedef enum tclod_learn_result {
    TCLOD_LEARN_USED = 0,
    TCLOD_LEARN_EMPTY = 1,   /* no feature above 0, or no time: nothing to learn */
    TCLOD_LEARN_OUTLIER = 2, /* ignored */
    TCLOD_LEARN_CHANGE = 3   /* the last of a run of outliers: started again */
} tclod_learn_result;

/* Starts a model of n features from the prior (host units, >= 0, finite),
 * which weighs at least `floor` frames (at least 1e-9); no coefficient falls
 * below `least` times its prior. */
void tclod_learn_init(tclod_learn *m, uint32_t n, const double *prior, double forgetting,
                      double outlier, double floor, double least);

/* Learns from one frame: features x (>= 0, finite) and time y (>= 0, finite). */
tclod_learn_result tclod_learn_frame(tclod_learn *m, const double *x, double y);

/* coefficients · x. */
double tclod_learn_predict(const tclod_learn *m, const double *x);

#endif /* TCLOD_LEARN_H */
