/*
 * tclod_mixed_figure — data for docs/figures/slope_matching.svg: the slope
 * matching of the mixed solver's line search (thesis, [Thesis8 §8.3], Figure
 * 8.1 and eq. 8.8-8.14), benefit against predicted cost.
 *
 * The scene is as small as the picture: one discrete root with a single child
 * (one increment of known slope_d = Δbenefit / Δcost, eq. 8.8) and two smooth
 * objects with benefit w_i sqrt(r) and cost k_i r. It is solved by the papers'
 * loop (smooth_precondition 0, smooth_tolerance 0: the benefit gradient as the
 * direction and eq. 8.14 matched exactly). From the roots O the smooth slope is
 * infinite, so a line search goes first and stops at Q where the slope along
 * the line has fallen to slope_d; the increment is taken next and gives R.
 * The budget leaves a little after R, which the last line search spends.
 *
 * Output: CSV on stdout, columns kind, iterations, t, r1, r2, cost, benefit:
 *   curve    the selection along the first line search's ray (t in [0, t_max],
 *            r_i = t w_i / max w), cost and benefit including the root's;
 *            iterations 0.
 *   step     the selection returned with tclod_frame.max_iterations = 1, 2, ...
 *            (stats.cost and stats.benefit, the resolutions r1 and r2) until it
 *            stops changing; t empty.
 *   tangent  two points of the line with slope slope_d through Q; iterations
 *            0, t and resolutions empty.
 * Lines starting with '#' give the scene's figures (slope_d, budget, O, P)
 * and t_opt derived by hand against the t the library reached. Along the ray
 * the smooth slope falls as t^(-1/2), so the slope at the reached t is
 * slope_d * sqrt(t_opt / t). The program exits with 1 when that differs from
 * slope_d by more than 1e-3 (relative: the line search's tolerance on eq.
 * 8.14), or when the selection after the first iteration is not on the ray.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <tclod/tclod.h>

#include "table_scene.h"

/* The discrete root (O, with the smooth objects at 0) and its single child:
 * the increment adds 0.75 benefit for 0.5 ms, slope_d = 1.5. */
#define ROOT_BENEFIT 1.0
#define ROOT_COST 0.25
#define INCREMENT_BENEFIT 0.75
#define INCREMENT_COST 0.5
/* Q costs 0.54 ms and the increment 0.5, so R costs 1.29 ms with the root:
 * 1.3 ms lets the increment follow the line search, with 0.007 ms to spare. */
#define BUDGET_MS 1.3
#define SMOOTH_COUNT 2u
/* Points on the curve; squared spacing in t, because the square root bends
 * most near t = 0. */
#define CURVE_SAMPLES 200u
/* Half the tangent's extent along the cost axis, ms. */
#define TANGENT_HALF 0.3
/* A solve that is still changing after this many iterations is a bug here. */
#define MAX_STEPS 32u
#define SLOPE_TOLERANCE 1e-3

static const double smooth_w[SMOOTH_COUNT] = {2.0, 1.0};
static const double smooth_k[SMOOTH_COUNT] = {1.0, 1.0};

typedef struct figure {
    table_model model;
    tclod_scene *scene;
    tclod_id smooth[SMOOTH_COUNT];
} figure;

static int build(figure *f) {
    tclod_id root;
    uint32_t i;
    tclod_status st;
    table_init(&f->model);
    st = tclod_scene_create(NULL, &f->scene);
    if (st == TCLOD_OK)
        st = table_add_node(&f->model, f->scene, TCLOD_NONE, NULL, ROOT_BENEFIT, ROOT_COST, &root);
    if (st == TCLOD_OK)
        st = table_add_node(&f->model, f->scene, root, NULL, ROOT_BENEFIT + INCREMENT_BENEFIT,
                            ROOT_COST + INCREMENT_COST, NULL);
    for (i = 0; i < SMOOTH_COUNT && st == TCLOD_OK; ++i) {
        /* bounds are required for smooth objects; without a view they do not matter */
        const float bounds[4] = {4.0f * (float)i, 0.0f, 0.0f, 1.0f};
        st = table_add_smooth(&f->model, f->scene, bounds, TABLE_POWER, smooth_w[i], 0.5,
                              smooth_k[i], smooth_k[i], 0.0, &f->smooth[i]);
    }
    if (st != TCLOD_OK)
        fprintf(stderr, "tclod_mixed_figure: building the scene failed: %s\n",
                tclod_status_string(st));
    return st == TCLOD_OK ? 0 : 1;
}

/* One solve from the roots with at most max_iterations iterations (0: no
 * limit); the selection's resolutions go to r. */
static int solve(figure *f, uint32_t max_iterations, tclod_stats *stats, double *r) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_frame frame;
    tclod_status st;
    uint32_t i;
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(&f->model, &d.callbacks);
    d.mixed.plain_gradient = 1;
    d.mixed.smooth_tolerance = TCLOD_OFF;
    memset(&frame, 0, sizeof frame);
    frame.budget = BUDGET_MS;
    frame.max_iterations = max_iterations;
    st = tclod_selector_create(f->scene, &d, NULL, &sel);
    if (st == TCLOD_OK)
        st = tclod_select(sel, &frame, stats);
    if (st == TCLOD_OK)
        for (i = 0; i < SMOOTH_COUNT; ++i)
            r[i] = tclod_selector_resolution(sel, f->smooth[i]);
    tclod_selector_destroy(sel);
    if (st != TCLOD_OK)
        fprintf(stderr, "tclod_mixed_figure: the solve failed: %s\n", tclod_status_string(st));
    return st == TCLOD_OK ? 0 : 1;
}

/* Smooth benefit and cost of resolutions r, as the callbacks add them up. */
static void smooth_values(const figure *f, const double *r, double *benefit, double *cost) {
    uint32_t i;
    *benefit = *cost = 0.0;
    for (i = 0; i < SMOOTH_COUNT; ++i) {
        *benefit += table_smooth_benefit_of(&f->model, f->smooth[i], r[i], NULL);
        *cost += table_smooth_cost_of(&f->model, f->smooth[i], r[i], NULL);
    }
}

static int run(figure *f) {
    const double slope_d = INCREMENT_BENEFIT / INCREMENT_COST;
    double w_max = 0.0, sum_w32 = 0.0, sum_kw = 0.0, t_opt, t_sat, t_budget, t_max;
    double t_reached[SMOOTH_COUNT], r[SMOOTH_COUNT], previous[SMOOTH_COUNT + 2u];
    double q_benefit, q_cost, b, c;
    tclod_stats stats;
    uint32_t i, it;
    int failed = 0;

    /* The hand derivation. At r -> 0 the gradient of w_i sqrt(r_i) is
     * w_i / (2 sqrt(r_i)), the same multiple of w_i for every object, and the
     * barrier of eq. 8.13 scales all components alike there; the solver scales
     * the direction to a largest component of 1, so the first line search
     * follows r_i = t w_i / W, W = max w. Along it
     *   b(t) = sum w_i sqrt(t w_i / W) = sqrt(t / W) sum w_i^(3/2)
     *   c(t) = t sum k_i w_i / W
     * and the slope of benefit over cost along the line (eq. 8.11) is
     *   db/dc = b'(t) / c'(t) = sqrt(W) sum w_i^(3/2) / (2 sqrt(t) sum k_i w_i)
     * (the same as (1 / (2 sqrt t)) sum u_i^(3/2) / sum u_i k_i with weights
     * u_i = w_i / W, times W for the benefit's scale). It falls from +inf as
     * t grows; eq. 8.14 sets it equal to slope_d:
     *   t_opt = W (sum w_i^(3/2))^2 / (4 slope_d^2 (sum k_i w_i)^2),
     * valid while t_opt < t_max, the first variable reaching 1 (t = 1, the one
     * with w_i = W) or the budget, whichever comes first. */
    for (i = 0; i < SMOOTH_COUNT; ++i)
        if (smooth_w[i] > w_max)
            w_max = smooth_w[i];
    for (i = 0; i < SMOOTH_COUNT; ++i) {
        sum_w32 += smooth_w[i] * sqrt(smooth_w[i]);
        sum_kw += smooth_k[i] * smooth_w[i];
    }
    t_opt = w_max * sum_w32 * sum_w32 / (4.0 * slope_d * slope_d * sum_kw * sum_kw);
    t_sat = 1.0;
    t_budget = (BUDGET_MS - ROOT_COST) * w_max / sum_kw;
    t_max = t_sat < t_budget ? t_sat : t_budget;

    printf("# scene: root benefit %.9g cost %.9g; increment +%.9g benefit for +%.9g ms;"
           " smooth w = %.9g, %.9g, k = %.9g, %.9g; budget %.9g ms\n",
           ROOT_BENEFIT, ROOT_COST, INCREMENT_BENEFIT, INCREMENT_COST, smooth_w[0], smooth_w[1],
           smooth_k[0], smooth_k[1], BUDGET_MS);
    printf("# slope_d = %.9g\n", slope_d);
    printf("# budget = %.9g\n", BUDGET_MS);
    printf("# O = %.9g, %.9g\n", ROOT_COST, ROOT_BENEFIT);
    printf("# P = %.9g, %.9g\n", ROOT_COST + INCREMENT_COST, ROOT_BENEFIT + INCREMENT_BENEFIT);
    printf("# t_max = %.9g\n", t_max);
    printf("# t_opt derived = %.9g\n", t_opt);
    if (!(t_opt < t_max)) {
        fprintf(stderr, "tclod_mixed_figure: t_opt %.9g is not below t_max %.9g\n", t_opt, t_max);
        return 1;
    }

    /* Q: after one iteration, the first line search alone */
    if (solve(f, 1u, &stats, r) != 0)
        return 1;
    for (i = 0; i < SMOOTH_COUNT; ++i)
        t_reached[i] = r[i] * w_max / smooth_w[i];
    printf("# t_opt reached = %.9g (from r1; %.9g from r2)\n", t_reached[0], t_reached[1]);
    printf("# relative difference = %.3g (t), %.3g (slope)\n", fabs(t_reached[0] - t_opt) / t_opt,
           fabs(sqrt(t_opt / t_reached[0]) - 1.0));
    if (!(fabs(sqrt(t_opt / t_reached[0]) - 1.0) <= SLOPE_TOLERANCE)) {
        fprintf(stderr,
                "tclod_mixed_figure: reached t %.9g, derived t_opt %.9g: the slope there is "
                "%.9g of slope_d\n",
                t_reached[0], t_opt, sqrt(t_opt / t_reached[0]));
        failed = 1;
    }
    for (i = 1; i < SMOOTH_COUNT; ++i)
        if (fabs(t_reached[i] - t_reached[0]) > 1e-9 * t_reached[0]) {
            fprintf(stderr, "tclod_mixed_figure: the first step left the ray r_i = t w_i / W\n");
            failed = 1;
        }
    smooth_values(f, r, &q_benefit, &q_cost);
    q_benefit += ROOT_BENEFIT;
    q_cost += ROOT_COST;

    printf("kind,iterations,t,r1,r2,cost,benefit\n");
    for (i = 0; i <= CURVE_SAMPLES; ++i) {
        double s = (double)i / (double)CURVE_SAMPLES, t = t_max * s * s, rc[SMOOTH_COUNT];
        uint32_t j;
        for (j = 0; j < SMOOTH_COUNT; ++j)
            rc[j] = t * smooth_w[j] / w_max;
        smooth_values(f, rc, &b, &c);
        printf("curve,0,%.9g,%.9g,%.9g,%.9g,%.9g\n", t, rc[0], rc[1], ROOT_COST + c,
               ROOT_BENEFIT + b);
    }

    for (it = 1; it <= MAX_STEPS; ++it) {
        if (solve(f, it, &stats, r) != 0)
            return 1;
        if (it > 1 && stats.cost == previous[0] && stats.benefit == previous[1] &&
            r[0] == previous[2] && r[1] == previous[3])
            break;
        printf("step,%u,,%.9g,%.9g,%.9g,%.9g\n", it, r[0], r[1], stats.cost, stats.benefit);
        previous[0] = stats.cost;
        previous[1] = stats.benefit;
        previous[2] = r[0];
        previous[3] = r[1];
    }
    if (it > MAX_STEPS) {
        fprintf(stderr, "tclod_mixed_figure: still changing after %u iterations\n", MAX_STEPS);
        failed = 1;
    }

    printf("tangent,0,,,,%.9g,%.9g\n", q_cost - TANGENT_HALF, q_benefit - slope_d * TANGENT_HALF);
    printf("tangent,0,,,,%.9g,%.9g\n", q_cost + TANGENT_HALF, q_benefit + slope_d * TANGENT_HALF);
    return failed;
}

static const char usage[] =
    "usage: tclod_mixed_figure [--help]\n"
    "\n"
    "Solves a scene of one discrete increment and two smooth objects with the mixed\n"
    "solver's plain loop, and writes the data of docs/figures/slope_matching.svg as CSV\n"
    "on stdout: '#' lines with the scene's figures and t_opt derived by hand against\n"
    "the t reached, then rows kind,iterations,t,r1,r2,cost,benefit:\n"
    "  curve    the selection along the first line search's ray\n"
    "  step     the selection after 1, 2, ... iterations (tclod_frame.max_iterations)\n"
    "  tangent  two points of the line of slope slope_d through Q\n"
    "Exit status 1 when the reached slope differs from slope_d by more than 1e-3, or\n"
    "the first step leaves the ray; 2 for a bad command line.\n";

int main(int argc, char **argv) {
    figure f;
    int rc;
    if (argc > 1) {
        int help = strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0;
        if (!help)
            fprintf(stderr, "tclod_mixed_figure: unknown argument '%s'\n", argv[1]);
        fputs(usage, help ? stdout : stderr);
        return help ? 0 : 2;
    }
    memset(&f, 0, sizeof f);
    rc = build(&f);
    if (rc == 0)
        rc = run(&f);
    tclod_scene_destroy(f.scene);
    table_free(&f.model);
    return rc;
}
