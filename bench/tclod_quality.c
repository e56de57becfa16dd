/*
 * tclod_quality — how much of the best possible benefit each solver and each baseline
 * reaches at equal budget.
 *
 * Suite "families" (exact): random instances of examples/scenes/family_scene.h — chains
 * (objects with 3-6 levels, 10-100 objects) and trees (2-8 hierarchies, up to 4 levels
 * deep, 2-4 children per node) in four families: uncorrelated, weakly and strongly
 * correlated step benefit and cost, and steps that violate diminishing returns. Costs
 * are integers, so bench/optimum.c finds the exact optimum (tests/test_exact.c checks it
 * against brute force). Each instance is solved at ten budgets, the roots' cost plus a
 * fraction f of what refining everything would add: f = 0.05, 0.1, 0.2, ..., 0.9.
 *
 * Suite "world" (bound): the benchmark's random world (10^3 objects; and 10^4 in a full
 * run) and the flyover (5000 objects and a terrain quadtree), at views spread evenly over
 * the camera loop and at budgets 1/4 ... 4 times tclod_bench's budget. Too large for an
 * exact program, so the reference is the Lagrangian (linear-programming) upper bound of
 * optimum_bound: the quality figures are lower bounds on the fraction of the optimum.
 *
 * Methods: the library's solvers (greedy cold, mixed, robin_hood, all with their default
 * options; greedy_lookahead: the greedy with tclod_selector_desc.greedy.lookahead = 8, more
 * levels than any chain or tree of the families has, or --lookahead N; greedy_restarts:
 * the same with restarts = TCLOD_MAX_RESTARTS)
 * and the baselines of bench/baselines.h (threshold_tuned, threshold_fixed and
 * pq_stop need screen sizes and run only where there is a view, except pq_stop, which
 * then orders by benefit; flat needs objects that are chains: the chain families and the
 * random world). threshold_fixed keeps the bias the tuned rule found at the first view
 * of each budget.
 *
 * Output: CSV on stdout, progress on stderr; one row per suite, scene, family, method and
 * budget, and one row per method with budget "all" pooling every budget:
 *   quality = benefit / optimum (world: / upper bound), its median, worst (smallest) and
 *             mean over the instances (world: views);
 *   gain    = (benefit - coarsest) / (optimum - coarsest), coarsest the benefit of the
 *             roots alone: the share of what refinement could add that was added (1 when
 *             nothing could be added); median and worst;
 *   violations: selections whose cost exceeds the budget; mean and max cost / budget;
 *   incomplete: selections that leave a visible part of the scene undrawn (not a cut;
 *             Robin Hood's default misfit policy and the flat greedy can), counted by
 *             baseline_count_holes;
 *   quality_free: benefit / the optimum (world: bound) of the looser problem in which any
 *             part may be left undrawn (optimum.h, holes), which bounds incomplete
 *             selections too; median and worst.
 * The main quality columns compare with the problem the library solves (every visible
 * part drawn), so an incomplete selection may exceed 1 there.
 * Every selection's benefit and cost are summed here from the callbacks' values, in
 * result order. A solver that exceeds its budget or beats the exact optimum is reported
 * on stderr and makes the program exit with status 1.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "baselines.h"
#include "bench_util.h"
#include "family_scene.h"
#include "optimum.h"
#include "table_scene.h"
#include "world_scene.h"

#define FRACTION_COUNT 10
static const double fractions[FRACTION_COUNT] = {0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9};
#define SCALE_COUNT 5
static const double scales[SCALE_COUNT] = {0.25, 0.5, 1.0, 2.0, 4.0};
/* Instances per family and views per world scene: full run, --quick. */
#define FAMILY_INSTANCES 200u
#define FAMILY_INSTANCES_QUICK 40u
#define WORLD_VIEWS 16u
#define WORLD_VIEWS_QUICK 8u
#define FLYOVER_BUDGET_MS 10.0
/* A benefit above the exact optimum by more than this relative margin is a bug in one of
 * the two (benefits are summed in different orders, so equal values may differ by a few
 * ulps). */
#define ABOVE_OPTIMUM 1e-9

typedef enum method {
    METHOD_GREEDY,
    METHOD_MIXED,
    METHOD_ROBIN_HOOD,
    METHOD_GREEDY_LOOKAHEAD,
    METHOD_GREEDY_RESTARTS,
    METHOD_THRESHOLD_TUNED,
    METHOD_THRESHOLD_FIXED,
    METHOD_PQ_STOP,
    METHOD_FLAT,
    METHOD_COUNT
} method;

static const char *const method_names[METHOD_COUNT] = {
    "greedy",           "mixed",           "robin_hood",
    "greedy_lookahead", "greedy_restarts", "threshold_tuned",
    "threshold_fixed",  "pq_stop",         "flat"};

/* The methods that are the library's solvers come first. */
#define LIBRARY_METHODS 5
/* greedy_lookahead and greedy_restarts: the greedy with this lookahead (--lookahead; by
 * default more than any chain's or tree's levels); greedy_restarts also with the most
 * restarts. */
static unsigned lookahead = 8u;

/* The samples of one row. */
typedef struct cell {
    double *quality, *gain, *quality_free;
    size_t n, cap;
    unsigned long violations, incomplete;
    double sum_cost_ratio, max_cost_ratio;
} cell;

static int failures;

/* One selection: its quality against both references, its gain, cost and budget, and
 * whether it left a visible part of the scene undrawn. */
static int cell_add(cell *c, double quality, double gain, double quality_free, double cost,
                    double budget, int incomplete) {
    double ratio = budget > 0.0 ? cost / budget : (cost > 0.0 ? HUGE_VAL : 0.0);
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2u * c->cap : 64u;
        double *q = (double *)realloc(c->quality, cap * sizeof *q), *g, *f;
        if (q == NULL)
            return 0;
        c->quality = q;
        g = (double *)realloc(c->gain, cap * sizeof *g);
        if (g == NULL)
            return 0;
        c->gain = g;
        f = (double *)realloc(c->quality_free, cap * sizeof *f);
        if (f == NULL)
            return 0;
        c->quality_free = f;
        c->cap = cap;
    }
    c->quality[c->n] = quality;
    c->gain[c->n] = gain;
    c->quality_free[c->n] = quality_free;
    c->n++;
    c->violations += cost > budget;
    c->incomplete += incomplete != 0;
    c->sum_cost_ratio += ratio;
    if (ratio > c->max_cost_ratio)
        c->max_cost_ratio = ratio;
    return 1;
}

static void cell_free(cell *c) {
    free(c->quality);
    free(c->gain);
    free(c->quality_free);
    memset(c, 0, sizeof *c);
}

static void print_header(void) {
    printf("suite,scene,family,method,budget,instances,median_quality,worst_quality,"
           "mean_quality,median_gain,worst_gain,violations,mean_cost_ratio,max_cost_ratio,"
           "incomplete,median_quality_free,worst_quality_free\n");
}

static void print_cell(const char *suite, const char *scene, const char *family, method m,
                       const char *budget, cell *c) {
    double mean = 0.0;
    size_t i;
    if (c->n == 0)
        return;
    for (i = 0; i < c->n; ++i)
        mean += c->quality[i];
    mean /= (double)c->n;
    bench_sort(c->quality, c->n);
    bench_sort(c->gain, c->n);
    bench_sort(c->quality_free, c->n);
    printf("%s,%s,%s,%s,%s,%lu,%.6f,%.6f,%.6f,%.6f,%.6f,%lu,%.6f,%.6f,%lu,%.6f,%.6f\n", suite,
           scene, family, method_names[m], budget, (unsigned long)c->n,
           bench_median(c->quality, c->n), c->quality[0], mean, bench_median(c->gain, c->n),
           c->gain[0], c->violations, c->sum_cost_ratio / (double)c->n, c->max_cost_ratio,
           c->incomplete, bench_median(c->quality_free, c->n), c->quality_free[0]);
}

/* The library's solvers over one scene: a selector per solver, created once. */
typedef struct solvers {
    tclod_selector *sel[LIBRARY_METHODS]; /* in method order */
} solvers;

static tclod_status solvers_create(const tclod_scene *s, tclod_callbacks cb, solvers *out) {
    static const tclod_solver kinds[LIBRARY_METHODS] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                                        TCLOD_SOLVER_ROBIN_HOOD,
                                                        TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_GREEDY};
    int i;
    memset(out, 0, sizeof *out);
    if (cb.smooth_benefit == NULL) {
        cb.smooth_benefit = bench_no_smooth;
        cb.smooth_cost = bench_no_smooth;
    }
    for (i = 0; i < LIBRARY_METHODS; ++i) {
        tclod_selector_desc d;
        tclod_status st;
        tclod_selector_desc_default(&d);
        d.solver = kinds[i];
        d.callbacks = cb;
        d.cold_start = 1; /* every budget and view on its own */
        if (i >= METHOD_GREEDY_LOOKAHEAD)
            d.greedy.lookahead = lookahead;
        if (i == METHOD_GREEDY_RESTARTS)
            d.greedy.restarts = TCLOD_MAX_RESTARTS;
        st = tclod_selector_create(s, &d, NULL, &out->sel[i]);
        if (st != TCLOD_OK)
            return st;
    }
    return TCLOD_OK;
}

static void solvers_destroy(solvers *s) {
    int i;
    for (i = 0; i < LIBRARY_METHODS; ++i)
        tclod_selector_destroy(s->sel[i]);
    memset(s, 0, sizeof *s);
}

/* Runs method m; *ids and *n receive the selection. 0 when the method does not apply. */
static int run_method(method m, solvers *lib, baseline_selector *bl, const tclod_view *view,
                      double budget, double *fixed_bias, const tclod_id **ids, size_t *n) {
    baseline_result r;
    int rc = 0;
    if (m <= METHOD_GREEDY_RESTARTS) {
        tclod_selector *sel = lib->sel[m];
        tclod_frame f;
        tclod_status st;
        if (sel == NULL)
            return 0;
        memset(&f, 0, sizeof f);
        f.view = view;
        f.budget = budget;
        st = tclod_select(sel, &f, NULL);
        if (st == TCLOD_OK)
            st = tclod_selector_cut(sel, ids, n);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_quality: %s failed: %s\n", method_names[m],
                    tclod_status_string(st));
            failures++;
            return 0;
        }
        return 1;
    }
    switch (m) {
    case METHOD_THRESHOLD_TUNED:
        rc = baseline_threshold_tuned(bl, view, budget, &r);
        break;
    case METHOD_THRESHOLD_FIXED:
        if (isnan(*fixed_bias)) {
            rc = baseline_threshold_tuned(bl, view, budget, &r);
            *fixed_bias = r.bias;
        } else {
            rc = baseline_threshold(bl, view, *fixed_bias, &r);
        }
        break;
    case METHOD_PQ_STOP:
        rc = baseline_pq_stop(bl, view, budget, &r);
        break;
    case METHOD_FLAT:
        rc = baseline_flat(bl, view, budget, &r);
        break;
    default:
        rc = -1;
        break;
    }
    if (rc != 0)
        return 0;
    *ids = r.ids;
    *n = r.n;
    return 1;
}

static double sum_over(const double *v, const tclod_id *ids, size_t n) {
    double s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        s += v[ids[i]];
    return s;
}

/* ---- families -------------------------------------------------------------------- */

static int run_families(unsigned instances) {
    int shape, kind;
    for (shape = 0; shape < 2; ++shape)
        for (kind = 0; kind < FAMILY_KIND_COUNT; ++kind) {
            cell cells[METHOD_COUNT][FRACTION_COUNT + 1];
            double t0 = bench_now_us();
            unsigned i;
            int m, f;
            memset(cells, 0, sizeof cells);
            for (i = 0; i < instances; ++i) {
                family_desc d;
                table_model model;
                tclod_scene *scene = NULL;
                table_rng rng;
                optimum_instance oi;
                optimum_curve curve, curve_free;
                optimum_status ost;
                baseline_scene bs;
                baseline_selector *bl = NULL;
                solvers lib;
                tclod_callbacks cb;
                double roots_cost, leaves_cost, coarsest = 0.0, budgets[FRACTION_COUNT];
                uint32_t k;

                family_desc_default(&d, (family_shape)shape, (family_kind)kind);
                table_init(&model);
                if (tclod_scene_create(NULL, &scene) != TCLOD_OK)
                    return 1;
                table_rng_seed(&rng, 0x5eedull * (uint64_t)(shape * FAMILY_KIND_COUNT + kind + 1) +
                                         (uint64_t)i);
                if (family_build(&d, &model, scene, &rng) != TCLOD_OK) {
                    fprintf(stderr, "tclod_quality: building an instance failed\n");
                    return 1;
                }
                roots_cost = table_roots_cost(&model);
                leaves_cost = table_leaves_cost(&model);
                for (k = 0; k < model.count; ++k)
                    if (model.parent[k] == TCLOD_NONE)
                        coarsest += model.benefit[k];
                for (f = 0; f < FRACTION_COUNT; ++f)
                    budgets[f] = floor(roots_cost + fractions[f] * (leaves_cost - roots_cost));
                oi.count = model.count;
                oi.parent = model.parent;
                oi.benefit = model.benefit;
                oi.cost = model.cost;
                if (shape == FAMILY_CHAINS) {
                    ost = optimum_chains(&oi, 1.0, budgets[FRACTION_COUNT - 1], 0, &curve);
                    if (ost == OPTIMUM_OK)
                        ost = optimum_chains(&oi, 1.0, budgets[FRACTION_COUNT - 1], 1, &curve_free);
                } else {
                    ost = optimum_tree(&oi, 1.0, budgets[FRACTION_COUNT - 1], 0, &curve);
                    if (ost == OPTIMUM_OK)
                        ost = optimum_tree(&oi, 1.0, budgets[FRACTION_COUNT - 1], 1, &curve_free);
                }
                if (ost != OPTIMUM_OK) {
                    fprintf(stderr, "tclod_quality: the exact program failed (%d)\n", (int)ost);
                    return 1;
                }
                table_callbacks(&model, &cb);
                if (solvers_create(scene, cb, &lib) != TCLOD_OK ||
                    baseline_scene_init(&bs, scene, NULL, NULL, NULL, 0) != TCLOD_OK ||
                    baseline_create(&bs, &cb, &bl) != TCLOD_OK) {
                    fprintf(stderr, "tclod_quality: creating the selectors failed\n");
                    return 1;
                }
                for (f = 0; f < FRACTION_COUNT; ++f) {
                    double opt = optimum_at(&curve, budgets[f]);
                    double opt_free = optimum_at(&curve_free, budgets[f]);
                    for (m = 0; m < METHOD_COUNT; ++m) {
                        const tclod_id *ids;
                        size_t n;
                        double benefit, cost, quality, gain, bias = NAN;
                        uint32_t holes;
                        if (!run_method((method)m, &lib, bl, NULL, budgets[f], &bias, &ids, &n))
                            continue;
                        benefit = table_sum_benefit(&model, ids, n);
                        cost = table_sum_cost(&model, ids, n);
                        holes = baseline_count_holes(bl, model.benefit, ids, n);
                        quality = benefit / opt;
                        gain = opt > coarsest ? (benefit - coarsest) / (opt - coarsest) : 1.0;
                        /* A complete selection is a cut: the cut optimum bounds it. Any
                         * selection is bounded by the optimum with holes. */
                        if (benefit > opt_free * (1.0 + ABOVE_OPTIMUM) ||
                            (holes == 0 && benefit > opt * (1.0 + ABOVE_OPTIMUM)) ||
                            (m <= METHOD_GREEDY_RESTARTS && cost > budgets[f])) {
                            fprintf(stderr,
                                    "tclod_quality: %s on %s %s instance %u, budget %g: benefit "
                                    "%.17g, cost %.17g, optimum %.17g\n",
                                    method_names[m], family_shape_name((family_shape)shape),
                                    family_kind_name((family_kind)kind), i, budgets[f], benefit,
                                    cost, opt);
                            failures++;
                        }
                        if (!cell_add(&cells[m][f], quality, gain, benefit / opt_free, cost,
                                      budgets[f], holes > 0) ||
                            !cell_add(&cells[m][FRACTION_COUNT], quality, gain, benefit / opt_free,
                                      cost, budgets[f], holes > 0)) {
                            fprintf(stderr, "tclod_quality: out of memory\n");
                            return 1;
                        }
                    }
                }
                baseline_destroy(bl);
                baseline_scene_free(&bs);
                solvers_destroy(&lib);
                optimum_curve_free(&curve);
                optimum_curve_free(&curve_free);
                tclod_scene_destroy(scene);
                table_free(&model);
            }
            for (m = 0; m < METHOD_COUNT; ++m) {
                for (f = 0; f <= FRACTION_COUNT; ++f) {
                    char budget[32];
                    if (f < FRACTION_COUNT)
                        snprintf(budget, sizeof budget, "%.2f", fractions[f]);
                    else
                        snprintf(budget, sizeof budget, "all");
                    print_cell("families", family_shape_name((family_shape)shape),
                               family_kind_name((family_kind)kind), (method)m, budget,
                               &cells[m][f]);
                    cell_free(&cells[m][f]);
                }
            }
            fflush(stdout);
            fprintf(stderr, "tclod_quality: %s %s: %u instances in %.1f s\n",
                    family_shape_name((family_shape)shape), family_kind_name((family_kind)kind),
                    instances, (bench_now_us() - t0) / 1e6);
        }
    return 0;
}

/* ---- world scenes ------------------------------------------------------------------ */

static int run_world(const char *name, world_scene *w, double base_budget, int flat,
                     unsigned views) {
    cell cells[METHOD_COUNT][SCALE_COUNT + 1];
    baseline_scene bs;
    baseline_selector *bl = NULL, *values = NULL;
    solvers lib;
    tclod_callbacks cb = world_callbacks(w);
    tclod_id *parent = bench_parents(w->scene);
    double *benefit = (double *)malloc(((size_t)w->node_count + 1u) * sizeof *benefit);
    double *cost = (double *)malloc(((size_t)w->node_count + 1u) * sizeof *cost);
    double t0 = bench_now_us();
    int m, s, rc = 0;

    memset(cells, 0, sizeof cells);
    if (parent == NULL || benefit == NULL || cost == NULL ||
        solvers_create(w->scene, cb, &lib) != TCLOD_OK ||
        baseline_scene_init(&bs, w->scene, w->bounds, w->triangles, flat ? w->object_root : NULL,
                            flat ? w->object_count : 0) != TCLOD_OK ||
        baseline_create(&bs, &cb, &bl) != TCLOD_OK ||
        baseline_create(&bs, &cb, &values) != TCLOD_OK) {
        fprintf(stderr, "tclod_quality: setting up %s failed\n", name);
        free(parent);
        free(benefit);
        free(cost);
        return 1;
    }
    for (s = 0; s < SCALE_COUNT; ++s) {
        double budget = scales[s] * base_budget, bias = NAN;
        unsigned v;
        for (v = 0; v < views; ++v) {
            tclod_view view;
            optimum_instance oi;
            double bound, bound_free, coarsest = 0.0;
            uint32_t k;
            world_camera_at(&w->path, (double)v / (double)views, &view);
            baseline_values(values, &view, benefit, cost);
            oi.count = w->node_count;
            oi.parent = parent;
            oi.benefit = benefit;
            oi.cost = cost;
            bound = optimum_bound(&oi, budget, 0);
            bound_free = optimum_bound(&oi, budget, 1);
            for (k = 0; k < bs.root_count; ++k)
                coarsest += benefit[bs.roots[k]];
            for (m = 0; m < METHOD_COUNT; ++m) {
                const tclod_id *ids;
                size_t n;
                double b, c, gain;
                uint32_t holes;
                if (!run_method((method)m, &lib, bl, &view, budget, &bias, &ids, &n))
                    continue;
                b = sum_over(benefit, ids, n);
                c = sum_over(cost, ids, n);
                holes = baseline_count_holes(values, benefit, ids, n);
                gain = bound > coarsest ? (b - coarsest) / (bound - coarsest) : 1.0;
                if (m <= METHOD_GREEDY_RESTARTS && c > budget) {
                    fprintf(stderr, "tclod_quality: %s on %s exceeded the budget: %.17g > %.17g\n",
                            method_names[m], name, c, budget);
                    failures++;
                }
                if (!cell_add(&cells[m][s], b / bound, gain, b / bound_free, c, budget,
                              holes > 0) ||
                    !cell_add(&cells[m][SCALE_COUNT], b / bound, gain, b / bound_free, c, budget,
                              holes > 0)) {
                    rc = 1;
                    break;
                }
            }
        }
    }
    for (m = 0; m < METHOD_COUNT; ++m)
        for (s = 0; s <= SCALE_COUNT; ++s) {
            char label[32];
            if (s < SCALE_COUNT)
                snprintf(label, sizeof label, "%.2f", scales[s]);
            else
                snprintf(label, sizeof label, "all");
            print_cell("world", name, "bound", (method)m, label, &cells[m][s]);
            cell_free(&cells[m][s]);
        }
    fflush(stdout);
    fprintf(stderr,
            "tclod_quality: %s: %u nodes, budget %.4f ms x {0.25 .. 4}, %u views in %.1f s\n", name,
            w->node_count, base_budget, views, (bench_now_us() - t0) / 1e6);
    baseline_destroy(bl);
    baseline_destroy(values);
    baseline_scene_free(&bs);
    solvers_destroy(&lib);
    free(parent);
    free(benefit);
    free(cost);
    return rc;
}

static int run_worlds(int quick, unsigned views) {
    static const uint32_t sizes[2] = {1000u, 10000u};
    world_flyover_desc fd;
    world_scene w;
    int k;
    for (k = 0; k < 2; ++k) {
        world_random_desc d;
        char name[32];
        if (quick && sizes[k] > 1000u)
            break;
        world_random_desc_default(&d);
        d.objects = sizes[k];
        if (world_build_random(&d, &w) != TCLOD_OK) {
            fprintf(stderr, "tclod_quality: building the random world failed\n");
            return 1;
        }
        snprintf(name, sizeof name, "random_%u", sizes[k]);
        if (run_world(name, &w, bench_world_budget(&w), 1, views) != 0) {
            world_scene_free(&w);
            return 1;
        }
        world_scene_free(&w);
    }
    world_flyover_desc_default(&fd);
    if (world_build_flyover(&fd, &w) != TCLOD_OK) {
        fprintf(stderr, "tclod_quality: building the flyover failed\n");
        return 1;
    }
    /* The flyover's terrain is a quadtree, not a chain: no flat rows. */
    if (run_world("flyover", &w, FLYOVER_BUDGET_MS, 0, views) != 0) {
        world_scene_free(&w);
        return 1;
    }
    world_scene_free(&w);
    return 0;
}

static void usage(FILE *out) {
    fprintf(out,
            "usage: tclod_quality [--quick] [--suite families|world] [--instances N]\n"
            "                     [--views N] [--lookahead N] [--help]\n"
            "\n"
            "Benefit of every solver and baseline as a fraction of the exact optimum on random\n"
            "instance families, and of an upper bound on the benchmark's scenes; CSV on stdout.\n"
            "\n"
            "  --quick         40 instances per family, 8 views, no 10^4-object world\n"
            "  --suite NAME    families or world only\n"
            "  --instances N   instances per family (default 200)\n"
            "  --views N       views per world scene and budget (default 16)\n"
            "  --lookahead N   the lookahead of greedy_lookahead and greedy_restarts, in\n"
            "                  [1, TCLOD_MAX_LOOKAHEAD] (default 8)\n"
            "  --help          print this text and exit\n");
}

static int parse_count(const char *opt, const char *val, unsigned *out) {
    char *end;
    unsigned long v;
    errno = 0;
    v = val ? strtoul(val, &end, 10) : 0;
    if (val == NULL || errno != 0 || *end != '\0' || val[0] == '-' || v < 1 || v > 100000ul) {
        fprintf(stderr, "tclod_quality: %s expects an integer in [1, 100000]\n", opt);
        return 0;
    }
    *out = (unsigned)v;
    return 1;
}

int main(int argc, char **argv) {
    const char *suite = NULL;
    unsigned instances = 0, views = 0;
    int quick = 0, i;
    double t0 = bench_now_us();
    for (i = 1; i < argc; ++i) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--suite") == 0) {
            if (val == NULL || (strcmp(val, "families") != 0 && strcmp(val, "world") != 0)) {
                fprintf(stderr, "tclod_quality: --suite expects families or world\n");
                return 2;
            }
            suite = val;
            ++i;
        } else if (strcmp(argv[i], "--instances") == 0) {
            if (!parse_count("--instances", val, &instances))
                return 2;
            ++i;
        } else if (strcmp(argv[i], "--views") == 0) {
            if (!parse_count("--views", val, &views))
                return 2;
            ++i;
        } else if (strcmp(argv[i], "--lookahead") == 0) {
            if (!parse_count("--lookahead", val, &lookahead) || lookahead > TCLOD_MAX_LOOKAHEAD) {
                fprintf(stderr, "tclod_quality: --lookahead expects an integer in [1, %u]\n",
                        (unsigned)TCLOD_MAX_LOOKAHEAD);
                return 2;
            }
            ++i;
        } else {
            fprintf(stderr, "tclod_quality: unknown option '%s' (try --help)\n", argv[i]);
            return 2;
        }
    }
    if (instances == 0)
        instances = quick ? FAMILY_INSTANCES_QUICK : FAMILY_INSTANCES;
    if (views == 0)
        views = quick ? WORLD_VIEWS_QUICK : WORLD_VIEWS;
    fprintf(stderr, "tclod_quality: libtclod %s, %s run\n", tclod_version_string(),
            quick ? "quick" : "full");
    print_header();
    if ((suite == NULL || strcmp(suite, "families") == 0) && run_families(instances) != 0)
        return 1;
    if ((suite == NULL || strcmp(suite, "world") == 0) && run_worlds(quick, views) != 0)
        return 1;
    fprintf(stderr, "tclod_quality: done in %.1f s\n", (bench_now_us() - t0) / 1e6);
    if (failures > 0) {
        fprintf(stderr, "tclod_quality: %d selections broke the budget or beat the optimum\n",
                failures);
        return 1;
    }
    return 0;
}
