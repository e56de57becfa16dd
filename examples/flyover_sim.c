/*
 * flyover_sim — headless flyover: the README's main example.
 *
 * A camera flies a closed loop over one of two scenes:
 *  - flyover (default): the flyover world, a 4^6-patch terrain quadtree and 5000
 *    buildings and trees of 6 levels (examples/scenes/world_scene.h), budget 10 ms;
 *  - thesis (--scene thesis): the thesis's test scene ([Thesis8 §8.4]), a 120 km
 *    terrain quadtree of 5461 patches and 1.4 million trees in about 25 000 smooth
 *    groups whose resolution is continuous (examples/scenes/thesis_scene.h), budget
 *    40 ms, solved by the mixed solver with quadtree variable splitting (--split 0
 *    gives every visible tree group its own variable).
 * Every frame the selector picks the representations that fit the budget (or, with
 * --scheduler, the predictive geomorph scheduler hands over a draw list); the
 * program times the call, checks the budget guarantee itself by summing the costs
 * of what is drawn with the scene's own formulas, prints a short table and ends with
 * one summary line of key=value pairs:
 *
 *   summary: frames=N solver=S mean_select_us=X p99_select_us=Y mean_cost_ratio=Z violations=V ...
 *
 * --help lists the options, the table's and the CSV's columns and every summary
 * key. Other programs read the CSV columns and the summary keys: they are only ever
 * added to, at the end.
 *
 * With --simulate-gpu the program also plays the part of the machine that would draw
 * the selection, to test frame-time adherence the way [RH §7.1 (Table 2)] does:
 * a target frame time T replaces the fixed budget; every frame the budget comes from
 * the calibration (tclod_calib_budget), a hidden "true" render time and logic time are
 * made up for what was selected, the frame time follows from them by the paper's
 * machine model (eq. 5-7), and the measurements go back to the calibration
 * (tclod_calib_report); docs/calibration.md explains the hidden model.
 *
 * --svg FILE plots the flight (examples/frame_plot.h): the predicted cost against the
 * budget, and the selection time, per frame.
 *
 * With --stream the flyover world streams from an empty cache (only the roots
 * resident) through libtclod's load plan, beside a Cesium-like loader on a copy of
 * the world and an all-resident copy for the benefit at best (examples/stream_sim.h,
 * docs/streaming.md): the camera teleports every 200 frames, and the summary adds
 * how fast each loader fills the view (t95) and what it loaded. A node takes 28
 * bytes per triangle (half a vertex of 32 bytes and three 4-byte indices); the
 * baseline's geometric error is (1 - w) r, w the node's benefit weight (its
 * accuracy, world_scene.h) and r its bounding radius.
 *
 * Nothing is drawn: the point is what a host's frame loop around libtclod looks like
 * and how long the selection takes. main reads as the program's outline: parse the
 * options, build the scene, start the flight (a selector, or the scheduler), fly it
 * frame by frame, print the summary, write the plot.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <tclod/tclod.h>

#include "frame_plot.h"
#include "stream_sim.h"
#include "thesis_scene.h"
#include "world_scene.h"

/* One loop of the path takes this many frames: 40 s at 60 Hz, about 200 m/s. */
#define FRAMES_PER_LOOP 2400u
/* The thesis scene's loop is about 197 km long: 12.5 min at 60 Hz, about 260 m/s. */
#define THESIS_FRAMES_PER_LOOP 45000u
/* The thesis's rendering budget ([Thesis8 §8.4], Results: 40 ms per frame). */
#define THESIS_BUDGET_MS 40.0
/* The table on stdout shows every this many frames. */
#define PRINT_EVERY 20u
/* --scheduler: frames per second of the simulated host, and the margin on the
 * camera's measured speed and turn rate it gives the scheduler as bounds. */
#define SCHEDULER_HZ 60.0
#define SCHEDULER_MARGIN 1.25
/* --stream: bytes per triangle of a node's data: about half a vertex of 32
 * bytes (position, normal, texture coordinates) and three 4-byte indices. */
#define FLYOVER_BYTES_PER_TRIANGLE 28.0
/* Without --target-ms, --simulate-gpu aims at 25 ms ([RH Table 2]'s 0.025 s). */
#define DEFAULT_TARGET_MS 25.0

/* The hidden model of --simulate-gpu (docs/calibration.md). True render time =
 * predicted cost x factor x noise, with
 *   factor = FACTOR_MEAN + FACTOR_SWING sin(2 pi frame / FACTOR_PERIOD) + walk,
 *   walk'  = WALK_KEEP walk + WALK_STEP N(0, 1)   (a slow walk that returns to 0),
 *   noise  = 1 + NOISE N(0, 1);
 * true logic time = LOGIC_SHARE T (1 + LOGIC_SWING sin(2 pi frame / LOGIC_PERIOD)
 * + LOGIC_NOISE N(0, 1)). The numbers are deterministic (seed GPU_SEED). */
#define FACTOR_MEAN 1.3
#define FACTOR_SWING 0.4
#define FACTOR_PERIOD 900.0
#define WALK_KEEP 0.999
#define WALK_STEP 0.003
#define NOISE 0.01
#define LOGIC_SHARE 0.15
#define LOGIC_SWING 0.1
#define LOGIC_PERIOD 600.0
#define LOGIC_NOISE 0.02
#define GPU_SEED 0x5eed003ull
#define PI 3.14159265358979323846
/* The hidden factor never falls below this, whatever the walk does. */
#define FACTOR_MIN 0.05
/* --gpu-model features: the hidden machine prices each feature (the scene's:
 * draws and triangles, or draws, vertices and splats) at its prior times these
 * factors, and changes machine half-way through the flight; true render time =
 * hidden coefficients · the frame's features x noise. */
static const double gpu_before[3] = {2.0, 0.6, 1.3};
static const double gpu_after[3] = {0.7, 1.8, 0.8};
/* The frames after the start, and after the change, the summary's settled
 * figures leave out. */
#define SETTLE_START 100u
#define SETTLE_CHANGE 60u

typedef enum scene_kind { SCENE_FLYOVER, SCENE_THESIS } scene_kind;

typedef struct options {
    unsigned long frames;
    double budget_ms;
    int budget_given;
    tclod_solver solver;
    const char *solver_name;
    int solver_given;
    const char *csv_path;
    const char *svg_path;
    int warm;
    scene_kind scene;
    int split; /* -1: the scene's default */
    int simulate_gpu;
    double target_ms;
    int target_given;
    double gpu_c; /* the simulated machine's true C of eq. 7 */
    int gpu_c_given;
    int gpu_features; /* --gpu-model features: the hidden multi-feature machine */
    int learn;        /* --cost-model features: the learned cost model */
    int model_given;  /* --gpu-model or --cost-model given */
    int scheduler;    /* --scheduler: the predictive geomorph scheduler */
    double tau;       /* its interval, s */
    int tau_given;
    int morph; /* its three-stage pipeline with geomorphs */
    int morph_given;
    double slice_us; /* its selection time per frame */
    int slice_given;
    int frames_given;
    stream_sim_options stream; /* --stream and its options */
} options;

static const char usage_options[] =
    "usage: flyover_sim [--scene flyover|thesis] [--frames N] [--budget-ms X]\n"
    "                   [--solver greedy|mixed|robin_hood] [--split 0|1] [--warm 0|1]\n"
    "                   [--csv FILE] [--svg FILE]\n"
    "                   [--simulate-gpu [--target-ms T] [--gpu-c C]\n"
    "                    [--gpu-model factor|features] [--cost-model scale|features]]\n"
    "                   [--scheduler [--tau T] [--morph 0|1] [--slice-us X]]\n"
    "                   [--stream [--latency-ms L] [--bandwidth-mbps W] [--memory-mb M]\n"
    "                   [--teleport-every N]] [--help]\n"
    "\n"
    "Flies a camera over a terrain with 5000 buildings and trees (or, with --scene\n"
    "thesis, over the thesis's 120 km terrain with 1.4 million trees) and selects\n"
    "levels of detail every frame so that the predicted render time fits the budget.\n"
    "\n"
    "Options:\n"
    "  --scene S       flyover: terrain quadtree and 5000 objects of 6 levels (default);\n"
    "                  thesis: terrain quadtree and 1.4 million trees in smooth groups\n"
    "                  of continuous resolution ([Thesis8 §8.4])\n"
    "  --frames N      frames to simulate, N >= 1 (default 600; --stream 2000)\n"
    "  --budget-ms X   render-time budget per frame in ms, X > 0 (default 10; thesis 40)\n"
    "  --solver S      selection algorithm (default greedy; thesis mixed: greedy\n"
    "                  ignores smooth objects and draws none of its trees)\n"
    "  --split 0|1     mixed solver: 1 = nearby smooth objects share a variable while\n"
    "                  the predicted loss allows it (quadtree splitting), 0 = one\n"
    "                  variable per visible smooth object (default: thesis 1, flyover\n"
    "                  the library's default)\n"
    "  --warm 0|1      1: start each frame from the previous selection (default 1)\n"
    "  --csv FILE      also write one CSV row per frame to FILE (columns below)\n"
    "  --svg FILE      also plot the flight to FILE, a self-contained SVG picture: the\n"
    "                  predicted cost against the budget, and the selection time\n"
    "                  (--scheduler: the update time), per frame\n"
    "  --simulate-gpu  aim at a frame time instead of a fixed budget: the budget\n"
    "                  comes from libtclod's calibration, and a simulated machine\n"
    "                  with a hidden, drifting render-time factor reports render and\n"
    "                  logic times back (docs/calibration.md)\n"
    "  --target-ms T   --simulate-gpu: target frame time in ms, T > 0 (default 25)\n"
    "  --gpu-c C       --simulate-gpu: the simulated machine's constant C of [RH]\n"
    "                  eq. 7, C > 0 (default 1, what the calibration assumes)\n"
    "  --gpu-model M   --simulate-gpu: the hidden machine. factor (default): the\n"
    "                  predicted cost times a drifting factor; features: a hidden\n"
    "                  price per feature (draws, triangles; thesis: draws, vertices,\n"
    "                  splats) that changes half-way through the flight\n"
    "  --cost-model M  --simulate-gpu: the host's calibration. scale (default): one\n"
    "                  ratio measured / predicted; features: the learned cost model,\n"
    "                  the scene's features priced by learned coefficients\n"
    "  --scheduler     select through the predictive geomorph scheduler\n"
    "                  (docs/scheduler.md): each selection is for an interval ahead,\n"
    "                  spread over the frames before it, and levels change by\n"
    "                  geomorphs; the frames run at 60 Hz\n"
    "  --tau T         --scheduler: interval and morph time in s, T > 0 (default 0.5)\n"
    "  --morph 0|1     --scheduler: 1 = three stages with geomorphs (default), 0 = two\n"
    "                  stages, selections switch at interval boundaries\n"
    "  --slice-us X    --scheduler: selection time per frame in us, X > 0 (default 500)\n";

/* After stream_sim_usage_options. */
static const char usage_stream[] =
    "                  With --stream, flyover_sim streams the flyover scene through\n"
    "                  the selector (not with --scene thesis or --scheduler). A\n"
    "                  node's size is 28 bytes per triangle (32-byte vertices,\n"
    "                  about half a vertex per triangle, and three 4-byte\n"
    "                  indices); its geometric error for the baseline is (1 - w) r,\n"
    "                  w its benefit weight (the accuracy: 1 - 2^-(k+1) for level k\n"
    "                  of an object, 2^(d - 6) for a terrain patch of depth d) and r\n"
    "                  its bounding radius\n"
    "  --help          print this text and exit\n";

static const char usage_output[] =
    "\n"
    "Output: a line on the scene, one on the settings, then a table with a row for\n"
    "every 20th frame and the last:\n"
    "  frame           the frame, from 0\n"
    "  select_us       wall-clock time of tclod_select, us (--scheduler: update_us,\n"
    "                  of tclod_scheduler_update)\n"
    "  drawn           nodes drawn (--scheduler: items of the draw list)\n"
    "  morphing        --scheduler: items of the draw list that morph\n"
    "  cost_ms         predicted cost of what is drawn, ms\n"
    "  budget_ms       the frame's budget, ms\n"
    "  benefit         the selection's benefit (not with --scheduler)\n"
    "  groups          --scene thesis: smooth groups drawn\n"
    "  variables       --scene thesis: smooth variables of the solve\n"
    "  frame_ms        --simulate-gpu: the simulated frame time, ms\n"
    "  selections      --scheduler: selections landed so far\n"
    "\n"
    "CSV (--csv), a header and a row per frame:\n"
    "  frame,select_us,drawn,cost_ms,budget_ms,benefit as in the table;\n"
    "  iterations,increments,decrements,variables,line_searches the solve's\n"
    "  tclod_stats; smooth_groups the smooth groups drawn. --simulate-gpu adds\n"
    "  frame_ms,target_ms,scale,unconstrained_ms,factor: the frame time, the target,\n"
    "  the calibration's scale (measured ms per predicted ms), the frame time with\n"
    "  every visible object at its finest, and the hidden render-time factor (with\n"
    "  --gpu-model features: true render time / predicted cost).\n"
    "  --scheduler writes instead frame,time_s,select_us,drawn,morphing,cost_ms,\n"
    "  budget_ms,selections,unfinished,emergencies,changes,morphs,pops: time_s the\n"
    "  scheduler's clock, the last six its running totals (tclod_scheduler_stats).\n";

static const char usage_summary[] =
    "\n"
    "The last line is the summary: \"summary:\" and key=value pairs in this order:\n"
    "  frames              frames flown\n"
    "  solver              the solver's name\n"
    "  mean_select_us      mean time of tclod_select (--scheduler: of an update), us\n"
    "  p99_select_us       its 99th percentile (nearest rank), us\n"
    "  mean_cost_ratio     mean over the frames of predicted cost / budget\n"
    "  violations          frames whose predicted cost exceeded the budget, by the\n"
    "                      library's figure or by the program's own sum (must be 0)\n"
    "  changes_per_frame   level changes per frame (a drawn node replaced by drawn\n"
    "                      descendants, or the reverse, counts once)\n"
    "  pops_per_frame      of those, the ones switched at once: all of them\n"
    "--simulate-gpu adds:\n"
    "  target_ms           the target frame time, ms\n"
    "  mean_ms stddev_ms   mean and population standard deviation of the frame times\n"
    "  avg_err             mean of |frame time - target| / target\n"
    "  p99_overshoot       99th percentile of max(0, frame time / target - 1)\n"
    "  avg_err_from_100    avg_err over the frames from 100 on (--gpu-model features:\n"
    "                      but the 60 after the change)\n"
    "--gpu-model features adds:\n"
    "  change_frame        the frame the hidden machine changes at (frames / 2)\n"
    "  avg_err_before      avg_err over frames 100 .. change_frame - 1\n"
    "  avg_err_after       avg_err over frames change_frame + 60 .. the last\n"
    "  settle_frames       frames after the change until the first run of 30 frames\n"
    "                      with an avg_err <= 0.01\n"
    "  price_err           --cost-model features: the largest relative error of a\n"
    "                      learned price against the hidden machine's, at the end\n"
    "--scene thesis then adds, as means per frame:\n"
    "  variables line_searches smooth_groups\n"
    "--scheduler has, after violations:\n"
    "  draw_violations     frames whose draw list exceeded the budget (= violations)\n"
    "  morph_coverage      share of the level changes drawn as geomorphs\n"
    "  pops_per_frame      level changes switched at once, per frame\n"
    "  select_us_per_frame mean update time, us\n"
    "  tau morph           the interval (s), and 1 when levels morph\n"
    "  changes_per_frame   level changes per frame\n"
    "  selections unfinished emergencies\n"
    "                      selections landed, of those the ones ended early, and\n"
    "                      the selections made at once (tclod_scheduler_stats)\n";

static const char usage_exit[] =
    "\n"
    "Exit status: 0; 1 when a libtclod call or the machine failed (the message says\n"
    "which); 2 for a bad command line.\n";

static void usage(FILE *out) {
    fputs(usage_options, out);
    fputs(stream_sim_usage_options, out);
    fputs(usage_stream, out);
    fputs(usage_output, out);
    fputs(usage_summary, out);
    fputs(stream_sim_usage_output, out);
    fputs(usage_exit, out);
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

/* Parses "0" or "1" into *out; 0 for anything else. */
static int parse_flag(const char *s, int *out) {
    if (strcmp(s, "0") == 0) {
        *out = 0;
    } else if (strcmp(s, "1") == 0) {
        *out = 1;
    } else {
        return 0;
    }
    return 1;
}

/* What parse_options found: options to run with, --help, or a bad command line
 * (the message printed already). */
enum { OPTIONS_RUN = 0, OPTIONS_HELP = 1, OPTIONS_BAD = 2 };

static int parse_options(int argc, char **argv, options *o) {
    int i;
    o->frames = 600;
    o->budget_ms = 10.0;
    o->budget_given = 0;
    o->solver = TCLOD_SOLVER_GREEDY;
    o->solver_name = "greedy";
    o->solver_given = 0;
    o->csv_path = NULL;
    o->svg_path = NULL;
    o->warm = 1;
    o->scene = SCENE_FLYOVER;
    o->split = -1;
    o->simulate_gpu = 0;
    o->target_ms = DEFAULT_TARGET_MS;
    o->target_given = 0;
    o->gpu_c = 1.0;
    o->gpu_c_given = 0;
    o->gpu_features = 0;
    o->learn = 0;
    o->model_given = 0;
    o->scheduler = 0;
    o->tau = 0.5;
    o->tau_given = 0;
    o->morph = 1;
    o->morph_given = 0;
    o->slice_us = 500.0;
    o->slice_given = 0;
    o->frames_given = 0;
    stream_sim_options_default(&o->stream);
    for (i = 1; i < argc; ++i) {
        const char *opt = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int taken;
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0)
            return OPTIONS_HELP;
        taken = stream_sim_parse_option(&o->stream, "flyover_sim", argc, argv, &i);
        if (taken < 0)
            return OPTIONS_BAD;
        if (taken > 0)
            continue;
        if (strcmp(opt, "--simulate-gpu") == 0) {
            o->simulate_gpu = 1;
        } else if (strcmp(opt, "--scheduler") == 0) {
            o->scheduler = 1;
        } else if (strcmp(opt, "--tau") == 0 || strcmp(opt, "--morph") == 0 ||
                   strcmp(opt, "--slice-us") == 0) {
            if (!val) {
                fprintf(stderr, "flyover_sim: option %s needs a value\n", opt);
                return OPTIONS_BAD;
            }
            ++i;
            if (strcmp(opt, "--tau") == 0) {
                if (!parse_double(val, &o->tau) || !(o->tau > 0.0)) {
                    fprintf(stderr, "flyover_sim: --tau expects a number > 0, got '%s'\n", val);
                    return OPTIONS_BAD;
                }
                o->tau_given = 1;
            } else if (strcmp(opt, "--morph") == 0) {
                if (!parse_flag(val, &o->morph)) {
                    fprintf(stderr, "flyover_sim: --morph expects 0 or 1, got '%s'\n", val);
                    return OPTIONS_BAD;
                }
                o->morph_given = 1;
            } else {
                if (!parse_double(val, &o->slice_us) || !(o->slice_us > 0.0)) {
                    fprintf(stderr, "flyover_sim: --slice-us expects a number > 0, got '%s'\n",
                            val);
                    return OPTIONS_BAD;
                }
                o->slice_given = 1;
            }
        } else if (strcmp(opt, "--frames") == 0 || strcmp(opt, "--budget-ms") == 0 ||
                   strcmp(opt, "--solver") == 0 || strcmp(opt, "--csv") == 0 ||
                   strcmp(opt, "--svg") == 0 || strcmp(opt, "--warm") == 0 ||
                   strcmp(opt, "--scene") == 0 || strcmp(opt, "--split") == 0 ||
                   strcmp(opt, "--target-ms") == 0 || strcmp(opt, "--gpu-c") == 0 ||
                   strcmp(opt, "--gpu-model") == 0 || strcmp(opt, "--cost-model") == 0) {
            if (!val) {
                fprintf(stderr, "flyover_sim: option %s needs a value\n", opt);
                return OPTIONS_BAD;
            }
            ++i;
            if (strcmp(opt, "--frames") == 0) {
                if (!parse_ulong(val, &o->frames) || o->frames < 1 || o->frames > 100000000ul) {
                    fprintf(stderr, "flyover_sim: --frames expects an integer >= 1, got '%s'\n",
                            val);
                    return OPTIONS_BAD;
                }
                o->frames_given = 1;
            } else if (strcmp(opt, "--budget-ms") == 0) {
                if (!parse_double(val, &o->budget_ms) || !(o->budget_ms > 0.0)) {
                    fprintf(stderr, "flyover_sim: --budget-ms expects a number > 0, got '%s'\n",
                            val);
                    return OPTIONS_BAD;
                }
                o->budget_given = 1;
            } else if (strcmp(opt, "--target-ms") == 0) {
                if (!parse_double(val, &o->target_ms) || !(o->target_ms > 0.0)) {
                    fprintf(stderr, "flyover_sim: --target-ms expects a number > 0, got '%s'\n",
                            val);
                    return OPTIONS_BAD;
                }
                o->target_given = 1;
            } else if (strcmp(opt, "--gpu-c") == 0) {
                if (!parse_double(val, &o->gpu_c) || !(o->gpu_c > 0.0)) {
                    fprintf(stderr, "flyover_sim: --gpu-c expects a number > 0, got '%s'\n", val);
                    return OPTIONS_BAD;
                }
                o->gpu_c_given = 1;
            } else if (strcmp(opt, "--gpu-model") == 0 || strcmp(opt, "--cost-model") == 0) {
                int gpu = opt[2] == 'g', on = strcmp(val, "features") == 0;
                if (!on && strcmp(val, gpu ? "factor" : "scale") != 0) {
                    fprintf(stderr, "flyover_sim: %s expects %s or features, got '%s'\n", opt,
                            gpu ? "factor" : "scale", val);
                    return OPTIONS_BAD;
                }
                if (gpu)
                    o->gpu_features = on;
                else
                    o->learn = on;
                o->model_given = 1;
            } else if (strcmp(opt, "--solver") == 0) {
                if (!solver_from_name(val, &o->solver)) {
                    fprintf(stderr,
                            "flyover_sim: unknown solver '%s' (solvers: greedy, mixed, "
                            "robin_hood)\n",
                            val);
                    return OPTIONS_BAD;
                }
                o->solver_name = val;
                o->solver_given = 1;
            } else if (strcmp(opt, "--csv") == 0) {
                if (*val == '\0') {
                    fprintf(stderr, "flyover_sim: --csv expects a file name\n");
                    return OPTIONS_BAD;
                }
                o->csv_path = val;
            } else if (strcmp(opt, "--svg") == 0) {
                if (*val == '\0') {
                    fprintf(stderr, "flyover_sim: --svg expects a file name\n");
                    return OPTIONS_BAD;
                }
                o->svg_path = val;
            } else if (strcmp(opt, "--scene") == 0) {
                if (strcmp(val, "flyover") == 0) {
                    o->scene = SCENE_FLYOVER;
                } else if (strcmp(val, "thesis") == 0) {
                    o->scene = SCENE_THESIS;
                } else {
                    fprintf(stderr, "flyover_sim: unknown scene '%s' (scenes: flyover, thesis)\n",
                            val);
                    return OPTIONS_BAD;
                }
            } else if (strcmp(opt, "--split") == 0) {
                if (!parse_flag(val, &o->split)) {
                    fprintf(stderr, "flyover_sim: --split expects 0 or 1, got '%s'\n", val);
                    return OPTIONS_BAD;
                }
            } else if (!parse_flag(val, &o->warm)) {
                fprintf(stderr, "flyover_sim: --warm expects 0 or 1, got '%s'\n", val);
                return OPTIONS_BAD;
            }
        } else {
            fprintf(stderr, "flyover_sim: unknown option '%s' (try --help)\n", opt);
            return OPTIONS_BAD;
        }
    }
    if (!o->simulate_gpu && (o->target_given || o->gpu_c_given || o->model_given)) {
        fprintf(stderr, "flyover_sim: --target-ms, --gpu-c, --gpu-model and --cost-model need "
                        "--simulate-gpu\n");
        return OPTIONS_BAD;
    }
    if (!o->scheduler && (o->tau_given || o->morph_given || o->slice_given)) {
        fprintf(stderr, "flyover_sim: --tau, --morph and --slice-us need --scheduler\n");
        return OPTIONS_BAD;
    }
    if (o->scheduler && o->simulate_gpu) {
        fprintf(stderr, "flyover_sim: --scheduler runs with a fixed budget (no --simulate-gpu)\n");
        return OPTIONS_BAD;
    }
    if (o->simulate_gpu && o->budget_given) {
        fprintf(stderr, "flyover_sim: --simulate-gpu takes its budget from the calibration; "
                        "give a frame time with --target-ms instead of --budget-ms\n");
        return OPTIONS_BAD;
    }
    if (!stream_sim_options_check(&o->stream, "flyover_sim"))
        return OPTIONS_BAD;
    if (o->stream.enabled && (o->scene == SCENE_THESIS || o->scheduler)) {
        fprintf(stderr, "flyover_sim: --stream streams the flyover scene through the selector "
                        "(not with --scene thesis or --scheduler)\n");
        return OPTIONS_BAD;
    }
    if (o->stream.enabled && !o->frames_given)
        o->frames = STREAM_SIM_DEFAULT_FRAMES;
    if (o->scene == SCENE_THESIS) {
        /* the thesis's budget and solver, unless the command line chose others */
        if (!o->budget_given)
            o->budget_ms = THESIS_BUDGET_MS;
        if (!o->solver_given) {
            o->solver = TCLOD_SOLVER_MIXED;
            o->solver_name = "mixed";
        }
        if (o->split < 0)
            o->split = 1;
    }
    return OPTIONS_RUN;
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

/* ---- the simulated machine of --simulate-gpu ---------------------------------- */

/* The hidden state: what a real host would not know and the calibration must
 * find out from the measurements alone. */
typedef struct gpu_sim {
    uint64_t rng;  /* splitmix64 state */
    double walk;   /* the random-walk part of the render-time factor */
    double true_c; /* the machine's C of eq. 7 */
} gpu_sim;

/* splitmix64: small, fast and the same sequence on every platform. */
static uint64_t rng_next(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in (0, 1): 53 random bits, never 0 (the logarithm below). */
static double rng_uniform(uint64_t *state) {
    return ((double)(rng_next(state) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

/* Standard normal by Box-Muller (one of the pair: simple, and a fixed number
 * of draws per frame keeps every hidden series independent of the solver). */
static double rng_normal(uint64_t *state) {
    double u = rng_uniform(state), v = rng_uniform(state);
    return sqrt(-2.0 * log(u)) * cos(2.0 * PI * v);
}

/* One frame of the hidden machine: the factor true render time / predicted
 * cost, the frame's timing noise (a factor near 1) and the true logic time. */
static void gpu_frame(gpu_sim *g, unsigned long frame, double target_ms, double *factor,
                      double *noise, double *logic_ms) {
    double f, l;
    f = FACTOR_MEAN + FACTOR_SWING * sin(2.0 * PI * (double)frame / FACTOR_PERIOD) + g->walk;
    *factor = f > FACTOR_MIN ? f : FACTOR_MIN;
    g->walk = WALK_KEEP * g->walk + WALK_STEP * rng_normal(&g->rng);
    *noise = 1.0 + NOISE * rng_normal(&g->rng);
    l = LOGIC_SHARE * target_ms *
        (1.0 + LOGIC_SWING * sin(2.0 * PI * (double)frame / LOGIC_PERIOD) +
         LOGIC_NOISE * rng_normal(&g->rng));
    *logic_ms = l > 0.0 ? l : 0.0;
}

/* The render time eq. 5-7 allow a frame of t_f with logic t_l on a machine of
 * constant c: (1 - min(1, (t_l / t_f)²))² t_f / c. */
static double eq7_render(double t_f, double t_l, double c) {
    double l = t_l / t_f;
    l = l >= 1.0 ? 1.0 : l * l;
    return (1.0 - l) * (1.0 - l) * t_f / c;
}

/* The frame time of logic t_l and render t_r on that machine: the t_f >= t_l
 * for which eq. 5-7 give exactly t_r. eq7_render grows with t_f from 0 at t_l
 * (its derivative is (1 - a²)(1 + 3a²) / c with a = t_l / t_f), so bisection
 * finds the one solution. */
static double frame_time_ms(double t_l, double t_r, double c) {
    double lo = t_l, hi, guess = t_l > c * t_r ? t_l : c * t_r;
    int i;
    if (!(t_r > 0.0))
        return t_l;
    hi = 2.0 * guess + 1e-9;
    while (eq7_render(hi, t_l, c) < t_r)
        hi *= 2.0;
    for (i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
        double mid = 0.5 * (lo + hi);
        if (eq7_render(mid, t_l, c) < t_r)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

/* The scene flown over: the result of one of the two builders. */
typedef struct sim_scene {
    scene_kind kind;
    world_flyover_desc world_desc;
    world_scene world;
    thesis_desc thesis_desc;
    thesis_scene thesis;
    double build_ms; /* how long building it took */
    /* --stream: the baseline's and the all-resident copies of the flyover
     * world, and the path with teleports */
    world_scene copy[2];
    int streaming;
    stream_path path;
    double *bytes, *error; /* per node: its size and geometric error */
} sim_scene;

/* --stream: the flyover world's sizes and geometric errors, per node id
 * (--help): 28 bytes per triangle; the error (1 - weight) x bounding radius. */
static void flyover_stream_model(const sim_scene *s, double *bytes, double *error) {
    const world_scene *w = &s->world;
    uint32_t i;
    for (i = 0; i < w->node_count; ++i) {
        bytes[i] = (double)w->triangles[i] * FLYOVER_BYTES_PER_TRIANGLE;
        error[i] = (1.0 - (double)w->weight[i]) * (double)w->bounds[4u * i + 3u];
    }
}

/* The flyover world's view `position` frames along its loop (stream_sim_view_fn). */
static void flyover_view(void *user, double position, tclod_view *view) {
    const sim_scene *s = (const sim_scene *)user;
    world_camera_at(&s->world.path, position / (double)FRAMES_PER_LOOP, view);
}

/* Builds the scene of the given kind, timed (with --stream its two copies and
 * the path); 0 after saying what failed. */
static int build_scene(sim_scene *s, const options *opt) {
    tclod_status st;
    memset(s, 0, sizeof(*s));
    s->kind = opt->scene;
    s->build_ms = now_us();
    if (s->kind == SCENE_THESIS) {
        thesis_desc_default(&s->thesis_desc);
        st = thesis_build(&s->thesis_desc, &s->thesis);
    } else {
        world_flyover_desc_default(&s->world_desc);
        st = world_build_flyover(&s->world_desc, &s->world);
    }
    s->build_ms = (now_us() - s->build_ms) / 1000.0;
    if (st == TCLOD_OK && opt->stream.enabled) {
        s->streaming = 1;
        st = world_build_flyover(&s->world_desc, &s->copy[0]);
        if (st == TCLOD_OK)
            st = world_build_flyover(&s->world_desc, &s->copy[1]);
        if (st == TCLOD_OK) {
            size_t n = s->world.node_count ? s->world.node_count : 1u;
            s->bytes = (double *)malloc(n * sizeof(double));
            s->error = (double *)malloc(n * sizeof(double));
            if (!s->bytes || !s->error)
                st = TCLOD_ERR_NOMEM;
        }
        if (st == TCLOD_OK) {
            flyover_stream_model(s, s->bytes, s->error);
            if (!stream_path_init(&s->path, (double)FRAMES_PER_LOOP, opt->stream.teleport_every,
                                  opt->frames, flyover_view, s, s->world.scene, s->bytes, s->error,
                                  NULL))
                st = TCLOD_ERR_NOMEM;
        }
    }
    if (st != TCLOD_OK)
        fprintf(stderr, "flyover_sim: building the scene failed: %s\n", tclod_status_string(st));
    return st == TCLOD_OK;
}

static void free_scene(sim_scene *s) {
    if (s->kind == SCENE_THESIS)
        thesis_scene_free(&s->thesis);
    else
        world_scene_free(&s->world);
    world_scene_free(&s->copy[0]);
    world_scene_free(&s->copy[1]);
    stream_path_free(&s->path);
    free(s->bytes);
    free(s->error);
}

static void camera_at(const sim_scene *s, unsigned long frame, tclod_view *view) {
    if (s->kind == SCENE_THESIS)
        thesis_camera_at(&s->thesis, (double)frame / (double)THESIS_FRAMES_PER_LOOP, view);
    else if (s->streaming)
        world_camera_at(&s->world.path,
                        stream_path_position(&s->path, frame) / (double)FRAMES_PER_LOOP, view);
    else
        world_camera_at(&s->world.path, (double)frame / (double)FRAMES_PER_LOOP, view);
}

/* Level changes between consecutive selections, counted as the scheduler's
 * statistics count them: a node drawn in one selection whose drawn
 * descendants replace it in the other, or the reverse, counts once. */
typedef struct change_counter {
    uint32_t *in_prev, *in_cur, *counted; /* per node: the stamp of the call */
    tclod_id *prev;
    size_t prev_count;
    uint32_t stamp;
} change_counter;

static int change_counter_init(change_counter *c, uint32_t nodes) {
    memset(c, 0, sizeof(*c));
    c->in_prev = (uint32_t *)calloc(nodes ? nodes : 1u, sizeof(uint32_t));
    c->in_cur = (uint32_t *)calloc(nodes ? nodes : 1u, sizeof(uint32_t));
    c->counted = (uint32_t *)calloc(nodes ? nodes : 1u, sizeof(uint32_t));
    c->prev = (tclod_id *)malloc((nodes ? nodes : 1u) * sizeof(tclod_id));
    return c->in_prev && c->in_cur && c->counted && c->prev;
}

static void change_counter_free(change_counter *c) {
    free(c->in_prev);
    free(c->in_cur);
    free(c->counted);
    free(c->prev);
}

/* The level changes from the last selection passed to the next, cur. */
static unsigned long count_changes(change_counter *c, const tclod_scene *s, const tclod_id *cur,
                                   size_t n) {
    unsigned long changes = 0;
    uint32_t st = ++c->stamp;
    size_t i;
    int pass;
    for (i = 0; i < c->prev_count; ++i)
        c->in_prev[c->prev[i]] = st;
    for (i = 0; i < n; ++i)
        c->in_cur[cur[i]] = st;
    for (pass = 0; pass < 2; ++pass) {
        const tclod_id *list = pass == 0 ? cur : c->prev;
        const uint32_t *own = pass == 0 ? c->in_prev : c->in_cur;
        size_t count = pass == 0 ? n : c->prev_count;
        for (i = 0; i < count; ++i) {
            tclod_id a;
            if (own[list[i]] == st)
                continue; /* drawn in both */
            for (a = tclod_scene_parent(s, list[i]); a != TCLOD_NONE;
                 a = tclod_scene_parent(s, a)) {
                if (own[a] != st)
                    continue;
                if (c->counted[a] != st) {
                    c->counted[a] = st;
                    ++changes;
                }
                break;
            }
        }
    }
    if (n)
        memcpy(c->prev, cur, n * sizeof(*cur));
    c->prev_count = n;
    return changes;
}

/* The camera's largest speed (m/s) and turn rate (rad/s) over the loop at 60
 * frames per second: the bounds theta and omega the scheduler needs, which a
 * host knows from its camera controller. */
static void camera_bounds(const sim_scene *s, double *speed, double *turn) {
    unsigned long loop = s->kind == SCENE_THESIS ? THESIS_FRAMES_PER_LOOP : FRAMES_PER_LOOP, f;
    tclod_view a, b;
    *speed = *turn = 0.0;
    camera_at(s, 0, &a);
    for (f = 1; f <= loop; ++f) {
        double d[3], fa, fb, dot = 0.0, len;
        int k;
        camera_at(s, f, &b);
        for (k = 0; k < 3; ++k)
            d[k] = (double)b.eye[k] - (double)a.eye[k];
        len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * SCHEDULER_HZ;
        if (len > *speed)
            *speed = len;
        fa = sqrt((double)a.forward[0] * a.forward[0] + (double)a.forward[1] * a.forward[1] +
                  (double)a.forward[2] * a.forward[2]);
        fb = sqrt((double)b.forward[0] * b.forward[0] + (double)b.forward[1] * b.forward[1] +
                  (double)b.forward[2] * b.forward[2]);
        for (k = 0; k < 3; ++k)
            dot += (double)a.forward[k] * (double)b.forward[k];
        dot /= fa * fb;
        len = acos(dot > 1.0 ? 1.0 : dot) * SCHEDULER_HZ;
        if (len > *turn)
            *turn = len;
        a = b;
    }
}

/* What run_scheduler needs to check a draw list from outside: room for its
 * fine nodes and, in the thesis scene, for one group per drawn smooth object
 * and each object's place in the smooth order. */
typedef struct draw_check {
    tclod_id *fine;
    tclod_smooth_group *groups;
    uint32_t *position;
} draw_check;

static int draw_check_init(draw_check *c, const tclod_scene *scene) {
    uint32_t nodes = tclod_scene_node_count(scene), smooth = tclod_scene_smooth_count(scene), i;
    const tclod_id *order;
    uint32_t count;
    memset(c, 0, sizeof(*c));
    c->fine = (tclod_id *)malloc(((size_t)nodes * 3u + 1u) * sizeof(tclod_id));
    c->groups = (tclod_smooth_group *)malloc(((size_t)smooth + 1u) * sizeof(tclod_smooth_group));
    c->position = (uint32_t *)malloc(((size_t)smooth + 1u) * sizeof(uint32_t));
    if (!c->fine || !c->groups || !c->position ||
        tclod_scene_smooth_order((tclod_scene *)(uintptr_t)scene, &order, &count) != TCLOD_OK)
        return 0;
    for (i = 0; i < count; ++i)
        c->position[order[i]] = i;
    return 1;
}

static void draw_check_free(draw_check *c) {
    free(c->fine);
    free(c->groups);
    free(c->position);
}

/* The predicted cost of a frame drawn through the scheduler, from the scene's
 * own formulas: every item at its fine node (a morph costs its finer side),
 * and in the thesis scene every smooth object at this frame's resolution, as
 * a group of its own. */
static double draw_cost(const sim_scene *sim, draw_check *c, const tclod_scheduler *sch,
                        const tclod_draw *items, size_t n) {
    const tclod_scene *scene = sim->kind == SCENE_THESIS ? sim->thesis.scene : sim->world.scene;
    uint32_t smooth = tclod_scene_smooth_count(scene), i;
    size_t groups = 0, k;
    for (k = 0; k < n; ++k)
        c->fine[k] = items[k].fine;
    if (sim->kind != SCENE_THESIS)
        return world_sum_cost(&sim->world, c->fine, n);
    for (i = 0; i < smooth; ++i) {
        double r = tclod_scheduler_resolution(sch, i);
        if (!(r > 0.0))
            continue;
        c->groups[groups].first = c->position[i];
        c->groups[groups].count = 1;
        c->groups[groups].resolution = r;
        c->groups[groups].benefit = c->groups[groups].cost = 0.0;
        ++groups;
    }
    return thesis_sum_cost(&sim->thesis, c->fine, n, c->groups, groups);
}

/* ---- the flight ---------------------------------------------------------------- */

/* Frame-time figures of --simulate-gpu over all frames ([RH §7.1] measures
 * every frame too, the first ones included). */
typedef struct frame_figures {
    double sum, sum_sq, sum_err; /* of t_f, t_f², |t_f - T| / T */
    double *overshoot;           /* per frame: max(0, t_f / T - 1) */
    double *err;                 /* per frame: |t_f - T| / T */
} frame_figures;

/* A flight: the host's handles (a selector that selects every frame, or the
 * scheduler), what the summary is made of, and the outputs. */
typedef struct flight {
    const options *opt;
    sim_scene *sim;
    const tclod_scene *scene;
    tclod_selector_desc sd;
    /* selecting every frame */
    tclod_selector *sel;
    tclod_selector *finest; /* --simulate-gpu: the unconstrained frame */
    tclod_calib *calib;     /* --simulate-gpu */
    gpu_sim gpu;
    uint32_t features;                /* the scene's features (2 or 3) */
    double prior[TCLOD_MAX_FEATURES]; /* their prices in the scene's cost model */
    frame_figures ff;
    change_counter cc;
    unsigned long changes, mismatches;
    double sum_variables, sum_line_searches, sum_groups;
    stream_sim stream; /* --stream */
    /* --scheduler */
    tclod_scheduler *sch;
    tclod_scheduler_desc d;
    tclod_scheduler_stats st; /* after the last update */
    draw_check check;
    /* both */
    double *frame_us; /* per frame: the time of the select or update call */
    double sum_us, sum_ratio;
    unsigned long violations;
    FILE *csv;
    frame_plot plot; /* --svg */
} flight;

static int out_of_memory(void) {
    fprintf(stderr, "flyover_sim: out of memory\n");
    return 0;
}

/* A selector over the scene and, with --simulate-gpu, the calibration, the
 * selector of the unconstrained frame and the simulated machine. */
static int start_selector(flight *f) {
    const options *opt = f->opt;
    tclod_status st = tclod_selector_create(f->scene, &f->sd, NULL, &f->sel);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: creating the %s selector failed: %s\n", opt->solver_name,
                tclod_status_string(st));
        return 0;
    }
    if (opt->simulate_gpu) {
        tclod_calib_desc cd;
        tclod_selector_desc fd = f->sd;
        /* The calibration starts from the library's defaults: a scale of 1 (the
         * hidden factor is unknown) and machine_c 1; the simulated machine's C is
         * opt->gpu_c, 1 unless --gpu-c says otherwise. */
        tclod_calib_desc_default(&cd);
        if (opt->learn) { /* the learned model starts from the scene's own prices */
            uint32_t i;
            const char *const *names =
                opt->scene == SCENE_THESIS ? thesis_feature_names : world_feature_names;
            cd.feature_count = f->features;
            for (i = 0; i < f->features; ++i) {
                cd.feature_names[i] = names[i];
                cd.prior[i] = f->prior[i];
            }
        }
        st = tclod_calib_create(&cd, NULL, &f->calib);
        /* The unconstrained frame ([RH Fig. 3]'s bold line): every visible
         * object at its finest, whatever the budget; a second selector with an
         * unlimited budget finds it. Any solver's unlimited selection is the same,
         * so the greedy's does for the flyover scene. */
        if (st == TCLOD_OK) {
            if (opt->scene == SCENE_FLYOVER)
                fd.solver = TCLOD_SOLVER_GREEDY;
            /* with --stream, over the all-resident copy */
            st = tclod_selector_create(f->sim->streaming ? f->sim->copy[1].scene : f->scene, &fd,
                                       NULL, &f->finest);
        }
        if (st != TCLOD_OK) {
            fprintf(stderr, "flyover_sim: setting up the simulated GPU failed: %s\n",
                    tclod_status_string(st));
            return 0;
        }
        f->gpu.rng = GPU_SEED;
        f->gpu.true_c = opt->gpu_c;
        f->ff.overshoot = (double *)malloc(opt->frames * sizeof(*f->ff.overshoot));
        f->ff.err = (double *)malloc(opt->frames * sizeof(*f->ff.err));
        if (!f->ff.overshoot || !f->ff.err)
            return out_of_memory();
    }
    if (!change_counter_init(&f->cc, tclod_scene_node_count(f->scene)))
        return out_of_memory();
    return 1;
}

/* The scheduler over the scene, with the camera's bounds, and what checking
 * its draw lists needs. */
static int start_scheduler(flight *f) {
    const options *opt = f->opt;
    double speed, turn;
    tclod_status st;
    camera_bounds(f->sim, &speed, &turn);
    tclod_scheduler_desc_default(&f->d);
    f->d.tau = opt->tau;
    f->d.two_stage = !opt->morph;
    f->d.max_speed = SCHEDULER_MARGIN * speed;
    f->d.max_turn_rate = SCHEDULER_MARGIN * turn;
    st = tclod_scheduler_create(f->scene, &f->sd, &f->d, NULL, &f->sch);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: creating the scheduler over the %s solver failed: %s\n",
                opt->solver_name, tclod_status_string(st));
        return 0;
    }
    if (!draw_check_init(&f->check, f->scene))
        return out_of_memory();
    return 1;
}

/* The CSV file and its header. */
static int open_csv(flight *f) {
    const options *opt = f->opt;
    f->csv = fopen(opt->csv_path, "w");
    if (!f->csv) {
        fprintf(stderr, "flyover_sim: cannot write %s: %s\n", opt->csv_path, strerror(errno));
        return 0;
    }
    if (opt->scheduler)
        fprintf(f->csv, "frame,time_s,select_us,drawn,morphing,cost_ms,budget_ms,selections,"
                        "unfinished,emergencies,changes,morphs,pops\n");
    else
        fprintf(f->csv,
                "frame,select_us,drawn,cost_ms,budget_ms,benefit,iterations,increments,"
                "decrements,variables,line_searches,smooth_groups%s",
                opt->simulate_gpu ? ",frame_ms,target_ms,scale,unconstrained_ms,factor" : "");
    if (f->sim->streaming)
        stream_sim_csv_header(f->csv);
    if (!opt->scheduler)
        fprintf(f->csv, "\n");
    return 1;
}

/* --stream: the simulation over the three copies. The selectors of the copies share the world's
 * callbacks: the copies are built alike, so every id reads the same entries. */
static int start_stream(flight *f) {
    sim_scene *sim = f->sim;
    return stream_sim_start(&f->stream, &f->opt->stream, f->opt->frames, sim->world.scene, f->sel,
                            sim->copy[0].scene, sim->copy[1].scene, &f->sd, sim->bytes, sim->error,
                            NULL, "flyover_sim");
}

/* Everything before the first frame; 0 after saying what failed (end_flight
 * frees what was made). */
static int start_flight(flight *f, const options *opt, sim_scene *sim) {
    memset(f, 0, sizeof(*f));
    f->opt = opt;
    f->sim = sim;
    f->scene = sim->kind == SCENE_THESIS ? sim->thesis.scene : sim->world.scene;
    tclod_selector_desc_default(&f->sd);
    f->sd.solver = opt->solver;
    f->sd.callbacks =
        sim->kind == SCENE_THESIS ? thesis_callbacks(&sim->thesis) : world_callbacks(&sim->world);
    f->features = sim->kind == SCENE_THESIS ? THESIS_FEATURES : WORLD_FEATURES;
    if (sim->kind == SCENE_THESIS)
        thesis_feature_prior(&sim->thesis, f->prior);
    else
        world_feature_prior(&sim->world_desc.cost, f->prior);
    if (opt->learn) {
        f->sd.callbacks = sim->kind == SCENE_THESIS ? thesis_feature_callbacks(&sim->thesis)
                                                    : world_feature_callbacks(&sim->world);
        f->sd.feature_count = f->features;
        memcpy(f->sd.coefficients, f->prior, sizeof f->prior);
    }
    f->sd.cold_start = !opt->warm;
    if (opt->split >= 0)
        f->sd.mixed.split_smooth = opt->split;
    if (!(opt->scheduler ? start_scheduler(f) : start_selector(f)))
        return 0;
    if (sim->streaming && !start_stream(f))
        return 0;
    f->frame_us = (double *)malloc(opt->frames * sizeof(*f->frame_us));
    if (!f->frame_us || (opt->svg_path && !frame_plot_init(&f->plot, opt->frames)))
        return out_of_memory();
    return !opt->csv_path || open_csv(f);
}

static void print_flyover_scene(const sim_scene *sim) {
    const world_scene *w = &sim->world;
    printf("flyover: %u terrain patches (depth %u), %u objects x %u levels, %u nodes, "
           "%u roots\n",
           w->terrain_count, sim->world_desc.terrain_depth, w->object_count, w->levels,
           w->node_count, w->root_count);
}

/* The scene, the settings and the table's column names. */
static void print_header(const flight *f) {
    const options *opt = f->opt;
    const sim_scene *sim = f->sim;
    if (opt->scheduler) {
        if (sim->kind == SCENE_THESIS)
            printf("thesis: %u terrain patches (depth %u), %u trees in %u smooth groups\n",
                   sim->thesis.node_count, sim->thesis.terrain_depth, sim->thesis.tree_count,
                   sim->thesis.smooth_count);
        else
            print_flyover_scene(sim);
        printf("scheduler over solver %s, warm start %d, tau %.3f s, morph %d, slice %.0f us, "
               "%.0f Hz, max speed %.1f m/s, max turn %.3f rad/s, budget %.3f ms, %lu frames\n\n",
               opt->solver_name, !f->sd.cold_start, f->d.tau, !f->d.two_stage, opt->slice_us,
               SCHEDULER_HZ, f->d.max_speed, f->d.max_turn_rate, opt->budget_ms, opt->frames);
        printf("%7s %10s %7s %9s %9s %10s %10s\n", "frame", "update_us", "drawn", "morphing",
               "cost_ms", "budget_ms", "selections");
    } else if (sim->kind == SCENE_THESIS) {
        const thesis_scene *t = &sim->thesis;
        printf("thesis: %u terrain patches (depth %u), %u trees in %u smooth groups of <= %u, "
               "built in %.0f ms\n",
               t->node_count, t->terrain_depth, t->tree_count, t->smooth_count,
               THESIS_MAX_GROUP_TREES, sim->build_ms);
        if (opt->simulate_gpu)
            printf("solver %s, warm start %d, split %d, target %.3f ms (simulated GPU, C %g), "
                   "%lu frames\n\n",
                   opt->solver_name, opt->warm, f->sd.mixed.split_smooth, opt->target_ms,
                   opt->gpu_c, opt->frames);
        else
            printf("solver %s, warm start %d, split %d, budget %.3f ms, %lu frames\n\n",
                   opt->solver_name, opt->warm, f->sd.mixed.split_smooth, opt->budget_ms,
                   opt->frames);
        printf("%7s %10s %7s %9s %10s %12s %7s %9s%s\n", "frame", "select_us", "drawn", "cost_ms",
               "budget_ms", "benefit", "groups", "variables",
               opt->simulate_gpu ? "  frame_ms" : "");
    } else {
        print_flyover_scene(sim);
        if (sim->streaming)
            stream_sim_print_settings(stdout, &f->stream);
        if (opt->simulate_gpu)
            printf("solver %s, warm start %d, target %.3f ms (simulated GPU, C %g), %lu "
                   "frames\n\n",
                   opt->solver_name, opt->warm, opt->target_ms, opt->gpu_c, opt->frames);
        else
            printf("solver %s, warm start %d, budget %.3f ms, %lu frames\n\n", opt->solver_name,
                   opt->warm, opt->budget_ms, opt->frames);
        printf("%7s %10s %7s %9s %10s %12s%s", "frame", "select_us", "drawn", "cost_ms",
               "budget_ms", "benefit", opt->simulate_gpu ? "  frame_ms" : "");
        if (sim->streaming)
            stream_sim_table_header(stdout);
        printf("\n");
    }
}

/* The features of a selection summed (f->features entries into out), and,
 * priced at coef, its cost as the library sums it: each node's and group's
 * coef · features, in result order. */
static double selection_features(const flight *f, const tclod_id *ids, size_t n,
                                 const tclod_smooth_group *groups, size_t group_count,
                                 const double *coef, double *out) {
    const sim_scene *sim = f->sim;
    double one[TCLOD_MAX_FEATURES], cost = 0.0;
    size_t k;
    uint32_t i;
    memset(out, 0, f->features * sizeof *out);
    for (k = 0; k < n + group_count; ++k) {
        double c = 0.0;
        if (k < n && sim->kind == SCENE_THESIS)
            thesis_features(NULL, NULL, one);
        else if (k < n)
            world_sum_features(&sim->world, ids + k, 1, one);
        else
            thesis_group_features(
                (double)thesis_group_trees(&sim->thesis, groups[k - n].first, groups[k - n].count),
                groups[k - n].resolution, one, NULL);
        for (i = 0; i < f->features; ++i) {
            out[i] += one[i];
            c += coef[i] * one[i];
        }
        cost += c;
    }
    return cost;
}

/* The hidden machine's render time of a frame with features x (--gpu-model
 * features), before its noise. */
static double gpu_feature_time(const flight *f, unsigned long frame, const double *x) {
    const double *m = frame < f->opt->frames / 2u ? gpu_before : gpu_after;
    double t = 0.0;
    uint32_t i;
    for (i = 0; i < f->features; ++i)
        t += f->prior[i] * m[i] * x[i];
    return t;
}

/* The features of the selector's current selection, summed into out. */
static int current_features(const flight *f, const tclod_selector *sel, double *out) {
    const tclod_id *ids;
    const tclod_smooth_group *groups = NULL;
    size_t n, group_count = 0;
    if (tclod_selector_cut(sel, &ids, &n) != TCLOD_OK ||
        (f->sim->kind == SCENE_THESIS &&
         tclod_selector_smooth_groups(sel, &groups, &group_count) != TCLOD_OK))
        return 0;
    selection_features(f, ids, n, groups, group_count, f->prior, out);
    return 1;
}

/* --simulate-gpu, after frame `frame` selected with the frame request fr: the
 * machine draws the selection, and the host measures render and logic time
 * (never the hidden factor) and reports them. */
static int simulate_gpu_frame(flight *f, unsigned long frame, const tclod_frame *fr,
                              const tclod_stats *stats, double *frame_ms, double *unconstrained_ms,
                              double *factor) {
    const options *opt = f->opt;
    tclod_frame unlimited = *fr;
    tclod_stats finest_stats;
    tclod_status st;
    double noise, logic_ms, render_ms, finest_ms, t;
    double x[TCLOD_MAX_FEATURES], xf[TCLOD_MAX_FEATURES];
    gpu_frame(&f->gpu, frame, opt->target_ms, factor, &noise, &logic_ms);
    unlimited.budget = INFINITY;
    st = tclod_select(f->finest, &unlimited, &finest_stats);
    if (st == TCLOD_OK && !(current_features(f, f->sel, x) && current_features(f, f->finest, xf)))
        st = TCLOD_ERR_STATE;
    if (opt->gpu_features) {
        render_ms = gpu_feature_time(f, frame, x) * noise;
        finest_ms = gpu_feature_time(f, frame, xf) * noise;
        *factor = stats->cost > 0.0 ? render_ms / stats->cost : 0.0;
    } else { /* the scene's own cost model, whatever the host learns, times the factor */
        uint32_t i;
        double own = 0.0, own_finest = 0.0;
        for (i = 0; i < f->features; ++i) {
            own += f->prior[i] * x[i];
            own_finest += f->prior[i] * xf[i];
        }
        render_ms = (opt->learn ? own : stats->cost) * *factor * noise;
        finest_ms = (opt->learn ? own_finest : finest_stats.cost) * *factor * noise;
    }
    *frame_ms = frame_time_ms(logic_ms, render_ms, f->gpu.true_c);
    if (st == TCLOD_OK)
        st = opt->learn ? tclod_calib_report_features(f->calib, x, render_ms, logic_ms)
                        : tclod_calib_report(f->calib, stats->cost, render_ms, logic_ms);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: simulating frame %lu failed: %s\n", frame,
                tclod_status_string(st));
        return 0;
    }
    *unconstrained_ms = frame_time_ms(logic_ms, finest_ms, f->gpu.true_c);
    t = *frame_ms / opt->target_ms - 1.0;
    f->ff.sum += *frame_ms;
    f->ff.sum_sq += *frame_ms * *frame_ms;
    f->ff.sum_err += fabs(t);
    f->ff.overshoot[frame] = t > 0.0 ? t : 0.0;
    f->ff.err[frame] = fabs(t);
    return 1;
}

/* One frame selected with the selector: the budget (from the calibration with
 * --simulate-gpu), the selection, its check from outside, and the outputs. */
static int selected_frame(flight *f, unsigned long frame) {
    const options *opt = f->opt;
    tclod_view view;
    tclod_frame fr;
    tclod_stats stats;
    tclod_status st;
    const tclod_id *ids;
    const tclod_smooth_group *groups = NULL;
    size_t drawn, group_count = 0;
    double t0, t1, own_cost, budget = opt->budget_ms, scale = 0.0;
    double frame_ms = 0.0, unconstrained_ms = 0.0, factor = 0.0;

    camera_at(f->sim, frame, &view);
    if (opt->simulate_gpu) {
        scale = tclod_calib_scale(f->calib);
        st = tclod_calib_budget(f->calib, opt->target_ms, &budget);
        if (st == TCLOD_OK && opt->learn) /* the nodes priced as the model learned */
            st = tclod_selector_set_coefficients(f->sel, tclod_calib_coefficients(f->calib));
        if (st != TCLOD_OK) {
            fprintf(stderr, "flyover_sim: tclod_calib_budget failed at frame %lu: %s\n", frame,
                    tclod_status_string(st));
            return 0;
        }
    }
    memset(&fr, 0, sizeof(fr));
    fr.view = &view;
    fr.budget = budget;
    if (f->sim->streaming && !stream_sim_before(&f->stream, frame, "flyover_sim"))
        return 0;

    t0 = now_us();
    st = tclod_select(f->sel, &fr, &stats);
    t1 = now_us();
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: tclod_select failed at frame %lu: %s\n", frame,
                tclod_status_string(st));
        return 0;
    }
    st = tclod_selector_cut(f->sel, &ids, &drawn);
    if (st == TCLOD_OK && opt->scene == SCENE_THESIS)
        st = tclod_selector_smooth_groups(f->sel, &groups, &group_count);
    if (st != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: reading the selection failed: %s\n", tclod_status_string(st));
        return 0;
    }
    f->frame_us[frame] = t1 - t0;
    f->sum_us += t1 - t0;
    if (budget > 0.0)
        f->sum_ratio += stats.cost / budget;
    f->sum_variables += (double)stats.variables;
    f->sum_line_searches += (double)stats.line_searches;
    f->sum_groups += (double)group_count;

    /* The guarantee, checked from outside: what our cost callbacks return for
     * the listed nodes (and drawn smooth groups), summed in result order, must
     * not exceed the budget. */
    if (opt->learn) {
        double x[TCLOD_MAX_FEATURES];
        own_cost = selection_features(f, ids, drawn, groups, group_count,
                                      tclod_calib_coefficients(f->calib), x);
    } else {
        own_cost = opt->scene == SCENE_THESIS
                       ? thesis_sum_cost(&f->sim->thesis, ids, drawn, groups, group_count)
                       : world_sum_cost(&f->sim->world, ids, drawn);
    }
    if (stats.cost > budget || own_cost > budget)
        ++f->violations;
    if (own_cost != stats.cost)
        ++f->mismatches;
    /* every level change of a per-frame selection is a switch (a pop) */
    if (frame > 0)
        f->changes += count_changes(&f->cc, f->scene, ids, drawn);
    else
        count_changes(&f->cc, f->scene, ids, drawn);

    if (opt->simulate_gpu &&
        !simulate_gpu_frame(f, frame, &fr, &stats, &frame_ms, &unconstrained_ms, &factor))
        return 0;
    if (f->sim->streaming &&
        !stream_sim_after(&f->stream, frame, &fr, stats.benefit, "flyover_sim"))
        return 0;

    if (frame % PRINT_EVERY == 0 || frame + 1 == opt->frames) {
        if (opt->scene == SCENE_THESIS)
            printf("%7lu %10.1f %7lu %9.4f %10.4f %12.1f %7lu %9lu", frame, t1 - t0,
                   (unsigned long)drawn, stats.cost, budget, stats.benefit,
                   (unsigned long)group_count, (unsigned long)stats.variables);
        else
            printf("%7lu %10.1f %7lu %9.4f %10.4f %12.1f", frame, t1 - t0, (unsigned long)drawn,
                   stats.cost, budget, stats.benefit);
        if (opt->simulate_gpu)
            printf(" %9.4f", frame_ms);
        if (f->sim->streaming)
            stream_sim_table_row(stdout, &f->stream);
        printf("\n");
    }
    if (f->csv) {
        fprintf(f->csv, "%lu,%.3f,%lu,%.9g,%.9g,%.9g,%lu,%lu,%lu,%lu,%lu,%lu", frame, t1 - t0,
                (unsigned long)drawn, stats.cost, budget, stats.benefit,
                (unsigned long)stats.iterations, (unsigned long)stats.increments,
                (unsigned long)stats.decrements, (unsigned long)stats.variables,
                (unsigned long)stats.line_searches, (unsigned long)group_count);
        if (opt->simulate_gpu)
            fprintf(f->csv, ",%.9g,%.9g,%.9g,%.9g,%.9g", frame_ms, opt->target_ms, scale,
                    unconstrained_ms, factor);
        if (f->sim->streaming)
            stream_sim_csv_row(f->csv, &f->stream);
        fprintf(f->csv, "\n");
    }
    if (opt->svg_path)
        frame_plot_add(&f->plot, frame, stats.cost, budget, t1 - t0);
    return 1;
}

/* One frame drawn through the scheduler: the update, the draw list, its check
 * from outside, and the outputs. */
static int scheduled_frame(flight *f, unsigned long frame) {
    const options *opt = f->opt;
    tclod_view view;
    const tclod_draw *items;
    size_t n;
    tclod_status status;
    double t0, t1, own_cost, now = (double)frame / SCHEDULER_HZ;

    camera_at(f->sim, frame, &view);
    t0 = now_us();
    status = tclod_scheduler_update(f->sch, now, &view, opt->budget_ms, opt->slice_us * 1e-6);
    t1 = now_us();
    if (status == TCLOD_OK)
        status = tclod_scheduler_draws(f->sch, &items, &n);
    if (status == TCLOD_OK)
        status = tclod_scheduler_get_stats(f->sch, &f->st);
    if (status != TCLOD_OK) {
        fprintf(stderr, "flyover_sim: the scheduler failed at frame %lu: %s\n", frame,
                tclod_status_string(status));
        return 0;
    }
    /* the invariant, checked from outside */
    own_cost = draw_cost(f->sim, &f->check, f->sch, items, n);
    if (own_cost > opt->budget_ms || f->st.draw_cost > f->st.budget)
        ++f->violations;
    f->frame_us[frame] = t1 - t0;
    f->sum_us += t1 - t0;
    f->sum_ratio += f->st.draw_cost / opt->budget_ms;
    if (frame % PRINT_EVERY == 0 || frame + 1 == opt->frames)
        printf("%7lu %10.1f %7lu %9lu %9.4f %10.4f %10lu\n", frame, t1 - t0, (unsigned long)n,
               (unsigned long)f->st.morphing, f->st.draw_cost, opt->budget_ms,
               (unsigned long)f->st.selections);
    if (f->csv)
        fprintf(f->csv, "%lu,%.6f,%.3f,%lu,%lu,%.9g,%.9g,%lu,%lu,%lu,%llu,%llu,%llu\n", frame, now,
                t1 - t0, (unsigned long)n, (unsigned long)f->st.morphing, f->st.draw_cost,
                opt->budget_ms, (unsigned long)f->st.selections, (unsigned long)f->st.unfinished,
                (unsigned long)f->st.emergencies, (unsigned long long)f->st.changes,
                (unsigned long long)f->st.morphs, (unsigned long long)f->st.pops);
    if (opt->svg_path)
        frame_plot_add(&f->plot, frame, f->st.draw_cost, opt->budget_ms, t1 - t0);
    return 1;
}

/* The header, then every frame; 0 after saying what failed. */
static int fly(flight *f) {
    unsigned long frame;
    print_header(f);
    for (frame = 0; frame < f->opt->frames; ++frame)
        if (!(f->opt->scheduler ? scheduled_frame(f, frame) : selected_frame(f, frame)))
            return 0;
    return 1;
}

/* The mean of the frames' relative errors over [from, to) (0 when empty). */
static double mean_err(const flight *f, unsigned long from, unsigned long to) {
    double sum = 0.0;
    unsigned long k;
    for (k = from; k < to; ++k)
        sum += f->ff.err[k];
    return to > from ? sum / (double)(to - from) : 0.0;
}

/* The summary's figures of the frames once the calibration has settled. */
static void print_settled(const flight *f) {
    unsigned long n = f->opt->frames, change = n / 2u, k, settle;
    const unsigned long window = 30u;
    if (!f->opt->gpu_features) {
        printf(" avg_err_from_100=%.5f", mean_err(f, n < SETTLE_START ? n : SETTLE_START, n));
        return;
    }
    /* the first frame after the change from which a window of 30 has an
     * avg_err <= 0.01, as frames after the change */
    settle = n - change;
    for (k = change; k + window <= n; ++k)
        if (mean_err(f, k, k + window) <= 0.01) {
            settle = k - change;
            break;
        }
    {
        unsigned long b0 = SETTLE_START < change ? SETTLE_START : change;
        unsigned long a0 = change + SETTLE_CHANGE < n ? change + SETTLE_CHANGE : n;
        double both =
            (double)(change - b0) * mean_err(f, b0, change) + (double)(n - a0) * mean_err(f, a0, n);
        printf(" avg_err_from_100=%.5f change_frame=%lu avg_err_before=%.5f avg_err_after=%.5f "
               "settle_frames=%lu",
               (change - b0) + (n - a0) > 0 ? both / (double)((change - b0) + (n - a0)) : 0.0,
               change, mean_err(f, b0, change), mean_err(f, a0, n), settle);
        if (f->opt->learn) { /* the learned prices against the hidden machine's, at the end */
            const double *coef = tclod_calib_coefficients(f->calib);
            double worst = 0.0;
            uint32_t i;
            for (i = 0; i < f->features; ++i) {
                double hidden = f->prior[i] * gpu_after[i];
                double e = hidden > 0.0 ? fabs(coef[i] / hidden - 1.0) : 0.0;
                worst = e > worst ? e : worst;
            }
            printf(" price_err=%.5f", worst);
        }
    }
}

/* The summary line (--help lists its keys). Sorts the frame times. */
static void print_summary(flight *f) {
    const options *opt = f->opt;
    double frames = (double)opt->frames;
    qsort(f->frame_us, opt->frames, sizeof(*f->frame_us), compare_double);
    if (opt->scheduler) {
        const tclod_scheduler_stats *st = &f->st;
        printf("\nsummary: frames=%lu solver=%s mean_select_us=%.1f p99_select_us=%.1f "
               "mean_cost_ratio=%.4f violations=%lu draw_violations=%lu morph_coverage=%.4f "
               "pops_per_frame=%.4f select_us_per_frame=%.1f tau=%.3f morph=%d "
               "changes_per_frame=%.4f selections=%lu unfinished=%lu emergencies=%lu\n",
               opt->frames, opt->solver_name, f->sum_us / frames,
               percentile(f->frame_us, opt->frames, 99.0), f->sum_ratio / frames, f->violations,
               f->violations, st->changes ? (double)st->morphs / (double)st->changes : 1.0,
               (double)st->pops / frames, f->sum_us / frames, f->d.tau, !f->d.two_stage,
               (double)st->changes / frames, (unsigned long)st->selections,
               (unsigned long)st->unfinished, (unsigned long)st->emergencies);
        return;
    }
    if (f->mismatches)
        fprintf(stderr,
                "flyover_sim: in %lu frames the library's cost differs from the sum of the "
                "returned nodes' costs\n",
                f->mismatches);
    printf("\nsummary: frames=%lu solver=%s mean_select_us=%.1f p99_select_us=%.1f "
           "mean_cost_ratio=%.4f violations=%lu",
           opt->frames, opt->solver_name, f->sum_us / frames,
           percentile(f->frame_us, opt->frames, 99.0), f->sum_ratio / frames, f->violations);
    printf(" changes_per_frame=%.4f pops_per_frame=%.4f", (double)f->changes / frames,
           (double)f->changes / frames);
    if (opt->simulate_gpu) {
        double mean = f->ff.sum / frames;
        double var = f->ff.sum_sq / frames - mean * mean;
        qsort(f->ff.overshoot, opt->frames, sizeof(*f->ff.overshoot), compare_double);
        /* population standard deviation over all frames */
        printf(" target_ms=%.3f mean_ms=%.4f stddev_ms=%.4f avg_err=%.5f p99_overshoot=%.5f",
               opt->target_ms, mean, sqrt(var > 0.0 ? var : 0.0), f->ff.sum_err / frames,
               percentile(f->ff.overshoot, opt->frames, 99.0));
        print_settled(f);
    }
    if (opt->scene == SCENE_THESIS)
        printf(" variables=%.1f line_searches=%.1f smooth_groups=%.1f", f->sum_variables / frames,
               f->sum_line_searches / frames, f->sum_groups / frames);
    if (f->sim->streaming)
        stream_sim_print_summary(stdout, &f->stream);
    printf("\n");
}

/* --svg: the plot of the flight. */
static int write_svg(const flight *f) {
    const options *opt = f->opt;
    char title[256], budget[64];
    if (opt->simulate_gpu)
        snprintf(budget, sizeof budget, "target %g ms on a simulated GPU", opt->target_ms);
    else
        snprintf(budget, sizeof budget, "budget %g ms", opt->budget_ms);
    snprintf(title, sizeof title, "flyover_sim: %s scene, %s%s solver, %s, %lu frames",
             opt->scene == SCENE_THESIS ? "thesis" : "flyover",
             opt->scheduler ? "scheduler over the " : "", opt->solver_name, budget, opt->frames);
    if (!frame_plot_write(&f->plot, opt->svg_path, title,
                          opt->scheduler ? "update time" : "selection time")) {
        fprintf(stderr, "flyover_sim: cannot write %s: %s\n", opt->svg_path, strerror(errno));
        return 0;
    }
    return 1;
}

/* Closes the CSV file and frees the flight; ok after the flight went well, and
 * then 0 if the file could not be written. */
static int end_flight(flight *f, int ok) {
    if (f->csv && fclose(f->csv) != 0 && ok) {
        fprintf(stderr, "flyover_sim: writing %s failed\n", f->opt->csv_path);
        ok = 0;
    }
    frame_plot_free(&f->plot);
    free(f->frame_us);
    stream_sim_free(&f->stream);
    draw_check_free(&f->check);
    tclod_scheduler_destroy(f->sch);
    change_counter_free(&f->cc);
    free(f->ff.overshoot);
    free(f->ff.err);
    tclod_calib_destroy(f->calib);
    tclod_selector_destroy(f->finest);
    tclod_selector_destroy(f->sel);
    return ok;
}

int main(int argc, char **argv) {
    options opt;
    sim_scene sim;
    flight fl;
    int ok;

    switch (parse_options(argc, argv, &opt)) {
    case OPTIONS_HELP:
        usage(stdout);
        return 0;
    case OPTIONS_BAD:
        return 2;
    default:
        break;
    }
    if (!build_scene(&sim, &opt))
        return 1;
    ok = start_flight(&fl, &opt, &sim) && fly(&fl);
    if (ok) {
        print_summary(&fl);
        ok = !opt.svg_path || write_svg(&fl);
    }
    ok = end_flight(&fl, ok);
    free_scene(&sim);
    return ok ? 0 : 1;
}
