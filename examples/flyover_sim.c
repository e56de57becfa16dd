/*
 * flyover_sim — headless flyover: the README's main example.
 *
 * A camera flies a closed loop over the flyover world (a 4^6-patch terrain
 * quadtree and 5000 buildings and trees of 4 levels, examples/scenes/world_scene.h).
 * Every frame the selector picks the representations that fit the budget; the
 * program times tclod_select, checks the budget guarantee itself by summing the
 * costs of the returned nodes, prints a short table and ends with one summary line:
 *
 *   summary: frames=N solver=S mean_select_us=X p99_select_us=Y mean_cost_ratio=Z violations=V
 *
 * Nothing is drawn: the point is what a host's frame loop around libtclod looks like
 * and how long the selection takes.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <tclod/tclod.h>

#include "world_scene.h"

/* One loop of the path takes this many frames: 40 s at 60 Hz, about 200 m/s. */
#define FRAMES_PER_LOOP 2400u
/* The table on stdout shows every this many frames. */
#define PRINT_EVERY 20u

typedef struct options {
    unsigned long frames;
    double budget_ms;
    tclod_solver solver;
    const char *solver_name;
    const char *csv_path;
    int warm;
} options;

static void usage(FILE *out) {
    fprintf(out, "usage: flyover_sim [--frames N] [--budget-ms X] [--solver greedy] [--csv FILE]\n"
                 "                   [--warm 0|1] [--help]\n"
                 "\n"
                 "Flies a camera over a terrain with 5000 buildings and trees and selects levels\n"
                 "of detail every frame so that the predicted render time fits the budget.\n"
                 "\n"
                 "  --frames N      frames to simulate, N >= 1 (default 600)\n"
                 "  --budget-ms X   render-time budget per frame in ms, X > 0 (default 10)\n"
                 "  --solver S      selection algorithm (default greedy)\n"
                 "  --csv FILE      also write one CSV row per frame to FILE\n"
                 "  --warm 0|1      1: start each frame from the previous selection (default 1)\n"
                 "  --help          print this text and exit\n");
}

static int parse_ulong(const char *s, unsigned long *out) {
    char *end;
    unsigned long v;
    if (!s || *s == '\0' || *s == '-' || *s == '+')
        return 0;
    errno = 0;
    v = strtoul(s, &end, 10);
    if (errno != 0 || *end != '\0')
        return 0;
    *out = v;
    return 1;
}

static int parse_double(const char *s, double *out) {
    char *end;
    double v;
    if (!s || *s == '\0')
        return 0;
    errno = 0;
    v = strtod(s, &end);
    if (errno != 0 || *end != '\0' || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

/* Maps a solver name to the enum; 0 for a name that is no solver at all. */
static int solver_from_name(const char *name, tclod_solver *out) {
    if (strcmp(name, "greedy") == 0) {
        *out = TCLOD_SOLVER_GREEDY;
    } else if (strcmp(name, "mixed") == 0) {
        *out = TCLOD_SOLVER_MIXED;
    } else if (strcmp(name, "robin_hood") == 0 || strcmp(name, "robin-hood") == 0) {
        *out = TCLOD_SOLVER_ROBIN_HOOD;
    } else {
        return 0;
    }
    return 1;
}

/* 0 = run, 1 = --help given, 2 = bad command line (message already printed). */
static int parse_options(int argc, char **argv, options *o) {
    int i;
    o->frames = 600;
    o->budget_ms = 10.0;
    o->solver = TCLOD_SOLVER_GREEDY;
    o->solver_name = "greedy";
    o->csv_path = NULL;
    o->warm = 1;
    for (i = 1; i < argc; ++i) {
        const char *opt = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            return 1;
        } else if (strcmp(opt, "--frames") == 0 || strcmp(opt, "--budget-ms") == 0 ||
                   strcmp(opt, "--solver") == 0 || strcmp(opt, "--csv") == 0 ||
                   strcmp(opt, "--warm") == 0) {
            if (!val) {
                fprintf(stderr, "flyover_sim: option %s needs a value\n", opt);
                return 2;
            }
            ++i;
            if (strcmp(opt, "--frames") == 0) {
                if (!parse_ulong(val, &o->frames) || o->frames < 1 || o->frames > 100000000ul) {
                    fprintf(stderr, "flyover_sim: --frames expects an integer >= 1, got '%s'\n",
                            val);
                    return 2;
                }
            } else if (strcmp(opt, "--budget-ms") == 0) {
                if (!parse_double(val, &o->budget_ms) || !(o->budget_ms > 0.0)) {
                    fprintf(stderr, "flyover_sim: --budget-ms expects a number > 0, got '%s'\n",
                            val);
                    return 2;
                }
            } else if (strcmp(opt, "--solver") == 0) {
                if (!solver_from_name(val, &o->solver)) {
                    fprintf(stderr,
                            "flyover_sim: unknown solver '%s' (solvers: greedy, mixed, "
                            "robin_hood)\n",
                            val);
                    return 2;
                }
                if (!tclod_solver_available(o->solver)) {
                    fprintf(stderr, "flyover_sim: solver %s is not available in this build\n", val);
                    return 2;
                }
                o->solver_name = val;
            } else if (strcmp(opt, "--csv") == 0) {
                if (*val == '\0') {
                    fprintf(stderr, "flyover_sim: --csv expects a file name\n");
                    return 2;
                }
                o->csv_path = val;
            } else {
                if (strcmp(val, "0") == 0) {
                    o->warm = 0;
                } else if (strcmp(val, "1") == 0) {
                    o->warm = 1;
                } else {
                    fprintf(stderr, "flyover_sim: --warm expects 0 or 1, got '%s'\n", val);
                    return 2;
                }
            }
        } else {
            fprintf(stderr, "flyover_sim: unknown option '%s' (try --help)\n", opt);
            return 2;
        }
    }
    return 0;
}

static double now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Nearest-rank percentile (p in (0, 100]) of n sorted values. */
static double percentile(const double *sorted, size_t n, double p) {
    size_t rank = (size_t)ceil(p / 100.0 * (double)n);
    if (rank < 1)
        rank = 1;
    if (rank > n)
        rank = n;
    return sorted[rank - 1];
}

int main(int argc, char **argv) {
    options opt;
    world_flyover_desc wd;
    world_scene world;
    tclod_selector_desc sd;
    tclod_selector *sel = NULL;
    tclod_status st;
    FILE *csv = NULL;
    double *select_us = NULL, sum_us = 0.0, sum_ratio = 0.0;
    unsigned long frame, violations = 0, mismatches = 0;
    int rc;

    rc = parse_options(argc, argv, &opt);
    if (rc == 1) {
        usage(stdout);
        return 0;
    }
    if (rc != 0)
        return rc;

    world_flyover_desc_default(&wd);
    st = world_build_flyover(&wd, &world);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: building the scene failed: %s\n", tclod_status_string(st));
        return 1;
    }
    tclod_selector_desc_default(&sd);
    sd.solver = opt.solver;
    sd.callbacks = world_callbacks(&world);
    sd.warm_start = opt.warm;
    st = tclod_selector_create(world.scene, &sd, NULL, &sel);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: creating the %s selector failed: %s\n", opt.solver_name,
                tclod_status_string(st));
        world_scene_free(&world);
        return 1;
    }
    select_us = (double *)malloc(opt.frames * sizeof(*select_us));
    if (!select_us) {
        fprintf(stderr, "flyover_sim: out of memory\n");
        rc = 1;
        goto done;
    }
    if (opt.csv_path) {
        csv = fopen(opt.csv_path, "w");
        if (!csv) {
            fprintf(stderr, "flyover_sim: cannot write %s: %s\n", opt.csv_path, strerror(errno));
            rc = 1;
            goto done;
        }
        fprintf(csv, "frame,select_us,drawn,cost_ms,budget_ms,benefit,iterations,increments,"
                     "decrements\n");
    }

    printf("flyover: %u terrain patches (depth %u), %u objects x %u levels, %u nodes, "
           "%u roots\n",
           world.terrain_count, wd.terrain_depth, world.object_count, world.levels,
           world.node_count, world.root_count);
    printf("solver %s, warm start %d, budget %.3f ms, %lu frames\n\n", opt.solver_name, opt.warm,
           opt.budget_ms, opt.frames);
    printf("%7s %10s %7s %9s %10s %12s\n", "frame", "select_us", "drawn", "cost_ms", "budget_ms",
           "benefit");

    for (frame = 0; frame < opt.frames; ++frame) {
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats;
        const tclod_id *ids;
        size_t drawn;
        double t0, t1, own_cost;

        world_camera_at(&world.path, (double)frame / (double)FRAMES_PER_LOOP, &view);
        memset(&fr, 0, sizeof(fr));
        fr.view = &view;
        fr.budget = opt.budget_ms;

        t0 = now_us();
        st = tclod_select(sel, &fr, &stats);
        t1 = now_us();
        if (st != TCLOD_OK) {
            fprintf(stderr, "flyover_sim: tclod_select failed at frame %lu: %s\n", frame,
                    tclod_status_string(st));
            rc = 1;
            goto done;
        }
        st = tclod_selector_cut(sel, &ids, &drawn);
        if (st != TCLOD_OK) {
            fprintf(stderr, "flyover_sim: tclod_selector_cut failed: %s\n",
                    tclod_status_string(st));
            rc = 1;
            goto done;
        }
        select_us[frame] = t1 - t0;
        sum_us += t1 - t0;
        sum_ratio += stats.cost / opt.budget_ms;

        /* The guarantee, checked from outside: what our cost callback returns for
         * the listed nodes, summed in result order, must not exceed the budget. */
        own_cost = world_sum_cost(&world, ids, drawn);
        if (stats.cost > opt.budget_ms || own_cost > opt.budget_ms)
            ++violations;
        if (own_cost != stats.cost)
            ++mismatches;

        if (frame % PRINT_EVERY == 0 || frame + 1 == opt.frames)
            printf("%7lu %10.1f %7lu %9.4f %10.4f %12.1f\n", frame, t1 - t0, (unsigned long)drawn,
                   stats.cost, opt.budget_ms, stats.benefit);
        if (csv)
            fprintf(csv, "%lu,%.3f,%lu,%.9g,%.9g,%.9g,%lu,%lu,%lu\n", frame, t1 - t0,
                    (unsigned long)drawn, stats.cost, opt.budget_ms, stats.benefit,
                    (unsigned long)stats.iterations, (unsigned long)stats.increments,
                    (unsigned long)stats.decrements);
    }

    if (mismatches)
        fprintf(stderr,
                "flyover_sim: in %lu frames the library's cost differs from the sum of the "
                "returned nodes' costs\n",
                mismatches);
    qsort(select_us, opt.frames, sizeof(*select_us), compare_double);
    printf("\nsummary: frames=%lu solver=%s mean_select_us=%.1f p99_select_us=%.1f "
           "mean_cost_ratio=%.4f violations=%lu\n",
           opt.frames, opt.solver_name, sum_us / (double)opt.frames,
           percentile(select_us, opt.frames, 99.0), sum_ratio / (double)opt.frames, violations);
    rc = 0;

done:
    if (csv && fclose(csv) != 0 && rc == 0) {
        fprintf(stderr, "flyover_sim: writing %s failed\n", opt.csv_path);
        rc = 1;
    }
    free(select_us);
    tclod_selector_destroy(sel);
    world_scene_free(&world);
    return rc;
}
