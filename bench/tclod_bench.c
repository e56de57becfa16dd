/*
 * tclod_bench — how long tclod_select takes, against scene size, cold and warm.
 *
 * Scenes (examples/scenes/world_scene.h, examples/scenes/thesis_scene.h):
 *   random   N objects × 4 levels under a quadtree of group impostors, N = 10^3 … 10^6.
 *            The world and the camera loop scale with sqrt(N), so the same share of
 *            the world is in view at every N and the work grows with N.
 *   flyover  the example's terrain quadtree plus 5000 objects, budget 10 ms.
 *   thesis   the thesis's test scene ([Thesis8 §8.4]): a 5461-patch terrain quadtree and
 *            1.4 million trees in about 25 000 smooth objects (groups of <= 64 trees),
 *            budget 40 ms, solved by the mixed solver.
 *   churn    a random world (10^4 objects, or --objects N) edited between frames as a
 *            game edits its scene. Before every frame after the first, 1 % of the
 *            objects move (up to 3 m along x and z, on the ground; every level gets the
 *            new bounds), 0.1 % are removed (level 0, which takes the chain with it) and
 *            as many are added: new chains of the world's levels, new triangles, each in
 *            a removed object's place and under its group impostor (so that the
 *            impostors still describe their objects). The edits come from a fixed seed.
 *            The greedy solver, warm, on the world's loop, with the random scene's
 *            budget (of the world as built), in three modes: warm (with the edits),
 *            warm_noedit (the same frames and budget, no edits, on the world as built;
 *            it runs first) and warm_edited (no edits, on the world as the warm run left
 *            it). Times are the select call's; a frame's edits (the world's calls, with
 *            the scene's inside) are timed on their own: columns edits (scene edit calls
 *            per frame: levels moved, chains removed, levels added), edit_us and
 *            edit_p99_us. Then, on stderr, the line "summary: scene=churn objects=N
 *            warm_us_median=A warm_noedit_us_median=B ratio=A/B edit_us_median=E". Every
 *            selection is also checked to name only live nodes. Why warm_edited: the
 *            scene gives a removed id again only once every selector solved since, so
 *            an object added in a removed one's place in the same frame takes other
 *            ids (the first free after its group's); the ids of nodes near one
 *            another, dense as built, scatter as the edits go on (all objects are
 *            replaced in about 1000 frames), and with them the per-node records a
 *            solve reads; warm_edited times that without edits.
 *   absorb   one root of cost 2^53 and 4·10^4 roots of cost 1 (--objects N), each with
 *            a child of cost 2 worth twice its parent, budget 2^53: a running sum that
 *            starts from 2^53 absorbs every cost of 1, so increments of Δc 1 seem to
 *            fit while none does. Every solver (cold) in three modes: limited
 *            (tclod_select with solve_seconds 0.05), step (tclod_select_step slices of
 *            0.01 s; the time is the longest step of a solve) and scheduler (a
 *            tclod_scheduler updated at 60 Hz with slices of 2 ms; the time is the
 *            longest update of each interval, one of which lands a selection). 5 timed
 *            frames (2 with --quick) after one that warms up; the times show whether a
 *            time limit holds.
 *   stream   what streaming (docs/streaming.md) costs the library, on a random world
 *            (10^4 objects, or --objects N) whose every node takes 32 bytes per triangle
 *            it draws (so an object's level k takes 4^k times its level 0; a group
 *            impostor 2 KB per object it stands for, at most 16 KB). Four rows: flips
 *            (10^6 tclod_scene_set_resident calls on nodes drawn at random from a fixed
 *            seed, each making its node resident when it is not and not resident when it
 *            is, in 20 timed batches and no select in between; the times are per batch,
 *            frames the batches, column change_ns the median over the batches of the ns
 *            per change), then the greedy solver, warm, on the random scene's frames and
 *            budget: warm_plain (every node resident, no stream desc: the select as
 *            without streaming), warm_stream (only the roots resident at first; before
 *            every frame the previous select's evictions are made not resident and its
 *            first 20 requests resident, a loader of 20 slots whose loads arrive by the
 *            next frame; stream desc max_requests 20, memory_budget half of all the bytes
 *            (--memory), bytes_in_flight 0; the time is the select's, the plan
 *            included) and warm_resident_only (the residency changes of warm_stream
 *            replayed frame by frame, no stream desc: the same selections without the
 *            plan). Columns requests and evictions: listed per frame; resident_bytes:
 *            the scene's when a select began; means. Then, on stderr, the line
 *            "summary: scene=stream objects=N flip_ns_median=A warm_us_median=B
 *            stream_us_median=C stream_ratio=C/B resident_only_us_median=D
 *            plan_us_median=P requests_per_frame=R evictions_per_frame=E", P the median
 *            over the frames of warm_stream's time less warm_resident_only's. Every
 *            frame is checked: only resident nodes drawn; warm_stream's requests live
 *            and not resident, its evictions resident and neither drawn nor an ancestor
 *            of a drawn node, and once its lists are applied the resident bytes within
 *            the memory budget (unless TCLOD_NOTE_MEMORY_SHORT); warm_resident_only
 *            selects as warm_stream did (a difference is reported).
 * random and flyover have no smooth objects. They run the greedy in two modes: cold
 * (cold_start 1: every frame starts from the roots) and warm (cold_start 0: from the
 * previous frame's cut, with the camera a little further along the loop); robin_hood
 * and mixed, which keep nothing from frame to frame, in one (cold); and, on the same
 * frames and budget, the baselines of bench/baselines.h (mode cold: they recompute every
 * frame): threshold_tuned (threshold LOD, one global bias bisected to the budget every
 * frame), threshold_fixed (the bias tuned on the first warm-up frame's view, then kept),
 * pq_stop (priority queue, largest on screen first, stopping at the first refinement
 * that does not fit) and, on the random world only (the flyover's terrain is not a
 * chain), flat (per-object greedy without the hierarchy of group impostors). Within a
 * scene and size the rows come greedy cold, greedy warm, robin_hood, then mixed and the
 * baselines. After greedy warm comes greedy warm_floor: not a solver but the least a warm
 * solve must spend under the callback contract, the time to project and ask the
 * callbacks of the frontier of the warm row's selection (its nodes, their children,
 * the parents all of whose children are selected) with nothing else (frontier_floor).
 * Then greedy warm_batch (world_batch_callbacks: the same values through the batch
 * callbacks) and warm_parallel (those over the 2 workers of a task_pool; column workers).
 * drift (bench_drift) times cold, warm and warm_batch selectors on the same frames of
 * chains whose benefits drift, and sums up warm against cold on stderr.
 * thesis runs the mixed solver cold, in three modes: split (split_smooth 1: quadtree
 * variable splitting lets nearby smooth objects share a variable), flat
 * (split_smooth 0: one variable per visible smooth object, up to about two thousand),
 * and split_gradient (split, with the papers' plain gradient steps instead of the
 * default preconditioned ones: smooth_precondition 0; timed like split).
 * A cold solve needs no coherence, so instead of following the loop frame by frame
 * both modes cycle through the same 20 views spread evenly over the whole loop (10
 * with --quick), which crosses mountains, hills and forests: flat, the slower mode,
 * times each view once; split times them over and over (200 frames, 40 with --quick,
 * rounded down to whole cycles). Both rows thus average over exactly the same views.
 *
 * Budget of a random world: the number of objects in view (mean over 16 points of the
 * loop) × the mean cost of an object's level 1, i.e. enough for every visible object
 * at level 1 on average; the solver spends it on fine levels near the eye and level 0
 * far away, so only part of the visible objects get refined.
 *
 * Output: CSV on stdout, one row per (scene, solver, mode, size); progress on stderr.
 * Times are per frame, median and p99 (nearest rank) over the timed frames, measured
 * with clock_gettime(CLOCK_MONOTONIC) around tclod_select. objects and nodes are the
 * objects (thesis: smooth objects) and discrete nodes of the scene. Columns after
 * budget: mean_us; visible (objects in view, thesis: smooth objects, mean over the
 * loop); and means per frame of cut (nodes drawn), refined (objects drawn finer than
 * level 0; thesis: smooth objects drawn), evaluations (nodes whose callbacks ran, plus
 * smooth callback calls), iterations, increments, decrements; frames timed; then means
 * per frame of variables (smooth variables after culling and splitting), line_searches,
 * and object_benefit: the benefit of the selection measured object by object, each cut
 * node and each member of a drawn smooth group at its group's resolution, with its own
 * bounds (thesis_selection_benefit). The library's benefit column values a group with
 * the group's bounds, so it changes with the grouping; object_benefit does not, which
 * is what lets split and flat be compared. variables, line_searches and object_benefit
 * are 0 where they do not apply (object_benefit: rows other than thesis). Then
 * ns_per_evaluation (mean_us over the mean evaluations: the time per node a solve looked
 * at), violations (timed frames whose selection cost more than the budget) and
 * max_cost_ratio (the largest cost / budget of a timed frame), then edits, edit_us and
 * edit_p99_us (churn rows with edits; else 0), then requests, evictions, resident_bytes
 * and change_ns (stream rows; else 0), then selector_bytes_per_node and
 * scene_bytes_per_node: the most bytes the row's selector (absorb scheduler rows: the
 * scheduler, its selector included) and the scene held while the row ran, counted by
 * the counting allocator they are created with (bench_counting_allocator), over the
 * nodes column (0 for rows without a selector: baselines, warm_floor, flips; the scene
 * is built before the row, so its growth while building is not in it). After each
 * random world's rows, on stderr, the line "summary: scene=random objects=N nodes=M
 * peak_rss_mb=X selector_bytes_per_node=S scene_bytes_per_node=T": the process's peak
 * resident set (getrusage: the world's own arrays and every earlier world included), the
 * largest selector figure of the world's rows and the scene's bytes then. The baselines'
 * data is made only when a baseline row runs (--solver greedy leaves it out). Every
 * frame's selection
 * is checked against the budget by summing its nodes' (and smooth groups') costs with
 * the callbacks' formulas: a library solver that exceeds it stops the program with an
 * error; a baseline's violations are counted (only threshold_fixed, which ignores the
 * budget, has any).
 *
 * The timed call of every frame goes through bench_solve, a function of its own, so
 * that callgrind can count the instructions of the timed solves alone
 * (bench/callgrind.sh); the churn scene's edits go through bench_edit, likewise
 * (--toggle-collect=bench_edit).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "baselines.h"
#include "bench_util.h"
#include "task_pool.h"
#include "thesis_scene.h"
#include "world_scene.h"

/* One loop of the camera path, in frames (as in flyover_sim): 40 s at 60 Hz, so the
 * camera moves and turns a little each frame. */
#define FRAMES_PER_LOOP 2400u
/* Frames run before timing starts: the first one grows the buffers (and for warm
 * mode comes from the roots), the rest settle caches. */
#define WARMUP_FRAMES 3u
#define FLYOVER_BUDGET_MS 10.0
/* The thesis's rendering budget ([Thesis8 §8.4], Results: 40 ms per frame). */
#define THESIS_BUDGET_MS 40.0
/* Views of the thesis rows, spread over the loop (the flat mode's timed frames: a flat
 * solve moves thousands of variables), and the split mode's timed frames with --quick. */
#define THESIS_VIEWS 20ul
#define THESIS_QUICK_VIEWS 10ul
#define THESIS_QUICK_FRAMES 40ul

typedef struct bench_row {
    double median_us, p99_us, mean_us;
    double benefit, cost, cut, refined, evaluations, iterations, increments, decrements;
    double variables, line_searches, object_benefit;
    unsigned long frames;
    unsigned long violations; /* timed frames whose selection cost more than the budget */
    double max_cost_ratio;    /* largest cost / budget over the timed frames */
    /* churn rows: scene edit calls per frame and their time (median, p99); else 0 */
    double edits, edit_median_us, edit_p99_us;
    /* stream rows: load requests and evictions listed per frame, the scene's resident
     * bytes when a select began (means), and the median ns per residency change (flips);
     * else 0 */
    double requests, evictions, resident_bytes, change_ns;
    /* the host's workers the solve was split over (tclod_tasks): 1 but warm_parallel */
    double workers;
    /* bytes the row's selectors (or scheduler) held at most while it ran, and the scene
     * (built before it) held at most then: counted by their allocators */
    double selector_bytes, scene_bytes;
} bench_row;

/* The counting allocators every scene and every selector or scheduler of the bench is
 * created with (memory columns, docs/benchmarks.md, Memory). */
static bench_counter scene_mem, selector_mem;
static tclod_allocator scene_alloc, selector_alloc;

/* A row begins: the peaks count from here. */
static void mem_row_begin(void) {
    bench_counter_reset_peak(&scene_mem);
    bench_counter_reset_peak(&selector_mem);
}

/* A row ends: the peaks since mem_row_begin into row. */
static void mem_row_end(bench_row *row) {
    row->selector_bytes = (double)selector_mem.peak;
    row->scene_bytes = (double)scene_mem.peak;
}

static const char *solver_name(tclod_solver s) {
    switch (s) {
    case TCLOD_SOLVER_GREEDY:
        return "greedy";
    case TCLOD_SOLVER_MIXED:
        return "mixed";
    case TCLOD_SOLVER_ROBIN_HOOD:
        return "robin_hood";
    }
    return "unknown";
}

/* What a random or flyover row runs: one of the library's solvers, or a baseline of
 * bench/baselines.h. */
typedef enum bench_method {
    METHOD_GREEDY,
    METHOD_MIXED,
    METHOD_ROBIN_HOOD,
    METHOD_THRESHOLD_TUNED,
    METHOD_THRESHOLD_FIXED,
    METHOD_PQ_STOP,
    METHOD_FLAT,
    METHOD_COUNT
} bench_method;

static const char *const method_names[METHOD_COUNT] = {
    "greedy", "mixed", "robin_hood", "threshold_tuned", "threshold_fixed", "pq_stop", "flat"};

static const tclod_solver method_solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                               TCLOD_SOLVER_ROBIN_HOOD};

/* Row filters of --solver and --mode (NULL: every row). */
static const char *only_solver, *only_mode;
/* --lookahead and --restarts: tclod_selector_desc of the random and flyover rows
 * (defaults: the library's) */
static unsigned long opt_lookahead, opt_restarts;
/* --memory: the stream scene's memory budget, as a fraction of all its nodes' bytes */
static double opt_memory = 0.5;
/* --benefit-work: world_scene.benefit_work of the random and flyover worlds */
static unsigned long opt_benefit_work;

static int row_wanted(const char *solver, const char *mode) {
    return (only_solver == NULL || strcmp(only_solver, solver) == 0) &&
           (only_mode == NULL || strcmp(only_mode, mode) == 0);
}

/* One frame's solve, as bench_solve runs it. */
typedef struct solve_call {
    bench_method method;
    tclod_selector *sel;     /* the library's solvers */
    baseline_selector *base; /* the baselines */
    tclod_frame frame;       /* view and budget */
    double bias;             /* threshold_fixed: the bias it keeps */
    tclod_stats stats;       /* out, library */
    baseline_result result;  /* out, baselines */
    tclod_status status;     /* out, library */
} solve_call;

static void solve_once(solve_call *c) {
    switch (c->method) {
    case METHOD_GREEDY:
    case METHOD_MIXED:
    case METHOD_ROBIN_HOOD:
        c->status = tclod_select(c->sel, &c->frame, &c->stats);
        break;
    case METHOD_THRESHOLD_TUNED:
        baseline_threshold_tuned(c->base, c->frame.view, c->frame.budget, &c->result);
        break;
    case METHOD_THRESHOLD_FIXED:
        baseline_threshold(c->base, c->frame.view, c->bias, &c->result);
        break;
    case METHOD_PQ_STOP:
        baseline_pq_stop(c->base, c->frame.view, c->frame.budget, &c->result);
        break;
    case METHOD_FLAT:
    case METHOD_COUNT:
        baseline_flat(c->base, c->frame.view, c->frame.budget, &c->result);
        break;
    }
}

/* The timed solve. Out of line, so that callgrind can count the instructions of the
 * timed frames alone: bench/callgrind.sh runs valgrind with
 * --toggle-collect='bench_solve*' (the star also catches a compiler's clones). */
void bench_solve(solve_call *c);
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
void bench_solve(solve_call *c) {
    solve_once(c);
}

/* Frame f's solve: untimed by callgrind in the warm-up frames, through bench_solve
 * after them. Returns its wall-clock time in us. */
static double solve_frame(solve_call *c, unsigned long f) {
    double t0 = bench_now_us();
    if (f < WARMUP_FRAMES)
        solve_once(c);
    else
        bench_solve(c);
    return bench_now_us() - t0;
}

/* Objects drawn finer than their level 0, out of the n cut nodes ids. */
static unsigned long refined_objects(const world_scene *w, const tclod_id *ids, size_t n) {
    unsigned long count = 0;
    size_t i;
    for (i = 0; i < n; ++i)
        count += w->kind[ids[i]] == WORLD_KIND_OBJECT && w->level[ids[i]] > 0;
    return count;
}

/* Turns the sums of the timed frames in row (and their times) into the row's figures. */
static void finish_row(bench_row *row, double *times, unsigned long frames, double sum_us) {
    double n = (double)frames;
    bench_sort(times, frames);
    row->frames = frames;
    row->median_us = bench_median(times, frames);
    row->p99_us = bench_percentile(times, frames, 99.0);
    row->mean_us = sum_us / n;
    row->benefit /= n;
    row->cost /= n;
    row->cut /= n;
    row->refined /= n;
    row->evaluations /= n;
    row->iterations /= n;
    row->increments /= n;
    row->decrements /= n;
    row->variables /= n;
    row->line_searches /= n;
    row->object_benefit /= n;
}

/* Adds one frame's stats to the row's sums. */
static void add_stats(bench_row *row, const tclod_stats *stats, size_t cut) {
    row->benefit += stats->benefit;
    row->cost += stats->cost;
    row->cut += (double)cut;
    row->evaluations += (double)stats->evaluations;
    row->iterations += (double)stats->iterations;
    row->increments += (double)stats->increments;
    row->decrements += (double)stats->decrements;
    row->variables += (double)stats->variables;
    row->line_searches += (double)stats->line_searches;
}

/* The frontier floor of a warm solve: what re-evaluating the frontier of the
 * previous frame's selection costs with nothing else, i.e. the least any warm solve
 * must spend under the callback contract (every node's values are this frame's). The
 * frontier is the selection's visible nodes, their children (to key their
 * increments) and their parents (to key the decrements); each is projected as the
 * library projects it (frustum planes, then the area of its sphere) and asked for its
 * benefit, and for its cost when visible, with the world's own callbacks. No heap, no
 * bookkeeping, no cut. */
typedef struct frontier_floor {
    uint32_t *child_first; /* node_count + 1 entries: node n's children are */
    tclod_id *children;    /* children[child_first[n] .. child_first[n + 1]) */
    tclod_id *parent;      /* bench_parents */
    uint32_t *mark;        /* the frame a node was last listed in, + 1 */
    uint32_t *in_cut;      /* the frame a node was last selected in, + 1 */
    tclod_id *list;        /* this frame's frontier */
    double *times;         /* per timed frame, µs */
} frontier_floor;

static void floor_free(frontier_floor *fl) {
    free(fl->child_first);
    free(fl->children);
    free(fl->parent);
    free(fl->mark);
    free(fl->in_cut);
    free(fl->list);
    free(fl->times);
    memset(fl, 0, sizeof(*fl));
}

static int floor_init(frontier_floor *fl, const world_scene *w, unsigned long frames) {
    uint32_t n = w->node_count, i;
    memset(fl, 0, sizeof(*fl));
    fl->child_first = (uint32_t *)calloc((size_t)n + 1u, sizeof(uint32_t));
    fl->children = (tclod_id *)malloc(((size_t)n + 1u) * sizeof(tclod_id));
    fl->parent = bench_parents(w->scene);
    fl->mark = (uint32_t *)calloc((size_t)n + 1u, sizeof(uint32_t));
    fl->in_cut = (uint32_t *)calloc((size_t)n + 1u, sizeof(uint32_t));
    fl->list = (tclod_id *)malloc(((size_t)n + 1u) * sizeof(tclod_id));
    fl->times = (double *)malloc(frames * sizeof(double));
    if (!fl->child_first || !fl->children || (n && !fl->parent) || !fl->mark || !fl->in_cut ||
        !fl->list || !fl->times) {
        floor_free(fl);
        return 1;
    }
    for (i = 0; i < n; ++i)
        if (fl->parent[i] != TCLOD_NONE)
            fl->child_first[fl->parent[i] + 1u]++;
    for (i = 0; i < n; ++i)
        fl->child_first[i + 1u] += fl->child_first[i];
    for (i = 0; i < n; ++i) /* mark counts the children placed so far */
        if (fl->parent[i] != TCLOD_NONE)
            fl->children[fl->child_first[fl->parent[i]] + fl->mark[fl->parent[i]]++] = i;
    memset(fl->mark, 0, ((size_t)n + 1u) * sizeof(uint32_t));
    return 0;
}

static size_t floor_list(frontier_floor *fl, uint32_t stamp, tclod_id n, size_t m) {
    if (fl->mark[n] != stamp) {
        fl->mark[n] = stamp;
        fl->list[m++] = n;
    }
    return m;
}

/* Whether every child of p is in the selection (in_cut == stamp). */
static int floor_collapsible(const frontier_floor *fl, uint32_t stamp, tclod_id p) {
    uint32_t c;
    for (c = fl->child_first[p]; c < fl->child_first[p + 1u]; ++c)
        if (fl->in_cut[fl->children[c]] != stamp)
            return 0;
    return 1;
}

/* Lists the frontier of selection ids[0..n) (frame stamp > 0): the selected nodes,
 * their children and the parents all of whose children are selected (what a warm
 * solve evaluates, less the invisible nodes of its cut, which the selection does
 * not list). Returns its size. */
static size_t floor_frontier(frontier_floor *fl, uint32_t stamp, const tclod_id *ids, size_t n) {
    size_t i, m = 0;
    for (i = 0; i < n; ++i)
        fl->in_cut[ids[i]] = stamp;
    for (i = 0; i < n; ++i) {
        tclod_id id = ids[i], p = fl->parent[id];
        uint32_t c;
        m = floor_list(fl, stamp, id, m);
        for (c = fl->child_first[id]; c < fl->child_first[id + 1u]; ++c)
            m = floor_list(fl, stamp, fl->children[c], m);
        if (p != TCLOD_NONE && fl->mark[p] != stamp && floor_collapsible(fl, stamp, p))
            m = floor_list(fl, stamp, p, m);
    }
    return m;
}

/* An orthonormal view basis and the constants of its frustum planes. */
typedef struct floor_view {
    double eye[3], forward[3], up[3], right[3];
    double cos_y, sin_y, cos_x, sin_x, near_z, far_z, focal;
} floor_view;

static void floor_normalize(double v[3]) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= len;
    v[1] /= len;
    v[2] /= len;
}

static void floor_view_init(floor_view *fv, const tclod_view *v) {
    double half_y = 0.5 * (double)v->fov_y, half_x = atan((double)v->aspect * tan(half_y));
    int i;
    for (i = 0; i < 3; ++i) {
        fv->eye[i] = (double)v->eye[i];
        fv->forward[i] = (double)v->forward[i];
        fv->up[i] = (double)v->up[i];
    }
    floor_normalize(fv->forward);
    fv->right[0] = fv->forward[1] * fv->up[2] - fv->forward[2] * fv->up[1];
    fv->right[1] = fv->forward[2] * fv->up[0] - fv->forward[0] * fv->up[2];
    fv->right[2] = fv->forward[0] * fv->up[1] - fv->forward[1] * fv->up[0];
    floor_normalize(fv->right);
    fv->up[0] = fv->right[1] * fv->forward[2] - fv->right[2] * fv->forward[1];
    fv->up[1] = fv->right[2] * fv->forward[0] - fv->right[0] * fv->forward[2];
    fv->up[2] = fv->right[0] * fv->forward[1] - fv->right[1] * fv->forward[0];
    fv->cos_y = cos(half_y);
    fv->sin_y = sin(half_y);
    fv->cos_x = cos(half_x);
    fv->sin_x = sin(half_x);
    fv->near_z = (double)v->near_z;
    fv->far_z = (double)v->far_z;
    fv->focal = 0.5 * (double)v->viewport_height / tan(half_y);
}

/* Projected area (0 outside the frustum, as the library measures it) of sphere b. */
static double floor_area(const floor_view *fv, const float *b, double *d2) {
    double p0 = (double)b[0] - fv->eye[0], p1 = (double)b[1] - fv->eye[1],
           p2 = (double)b[2] - fv->eye[2], r = (double)b[3];
    double z = p0 * fv->forward[0] + p1 * fv->forward[1] + p2 * fv->forward[2];
    double y = p0 * fv->up[0] + p1 * fv->up[1] + p2 * fv->up[2];
    double x = p0 * fv->right[0] + p1 * fv->right[1] + p2 * fv->right[2];
    *d2 = p0 * p0 + p1 * p1 + p2 * p2;
    if (z < fv->near_z - r || z > fv->far_z + r || fabs(y) * fv->cos_y - z * fv->sin_y > r ||
        fabs(x) * fv->cos_x - z * fv->sin_x > r || *d2 <= r * r)
        return 0.0;
    return 3.14159265358979323846 * fv->focal * fv->focal * r * r / (*d2 - r * r);
}

/* Projects and asks the callbacks of the m listed nodes; returns a sum to keep. */
static double floor_evaluate(const frontier_floor *fl, world_scene *w, const tclod_view *view,
                             size_t m) {
    tclod_callbacks cb = world_callbacks(w);
    floor_view fv;
    double sum = 0.0;
    size_t i;
    floor_view_init(&fv, view);
    for (i = 0; i < m; ++i) {
        tclod_query q;
        tclod_bounds qb;
        const float *b = &w->bounds[4u * fl->list[i]];
        double d2, benefit;
        q.id = fl->list[i];
        q.count = 1;
        q.view = view;
        q.members = NULL;
        qb = tclod_bounds_sphere((double)b[0], (double)b[1], (double)b[2], (double)b[3]);
        q.bounds = &qb;
        q.screen_area = (float)floor_area(&fv, b, &d2);
        q.distance = (float)(sqrt(d2) > (double)b[3] ? sqrt(d2) - (double)b[3] : 0.0);
        benefit = cb.benefit(cb.user, &q);
        sum += benefit > 0.0 ? benefit + cb.cost(cb.user, &q) : 0.0;
    }
    return sum;
}

/* How run_config's library selector evaluates: with the world's batch callbacks
 * (warm_batch, warm_parallel) and over this many workers of a task_pool (warm_parallel:
 * 2; else 1). */
static int config_batch;
static uint32_t config_workers = 1u;

/* Runs warm-up plus `frames` timed frames along the world's loop with one method: a
 * library solver (warm or cold) or a baseline over base. Returns 0 on success; a library
 * error or a library solver's budget violation is reported and returns 1 (baselines'
 * violations are counted in the row). */
static int run_config(world_scene *w, bench_method method, int warm, double budget,
                      unsigned long frames, double *times, baseline_selector *base, bench_row *row,
                      frontier_floor *fl, bench_row *floor_row) {
    solve_call call;
    unsigned long f, total = frames + WARMUP_FRAMES;
    double sum_us = 0.0;
    int library = method <= METHOD_ROBIN_HOOD;
    task_pool *pool = NULL;

    double floor_sum_us = 0.0, floor_sink = 0.0;

    memset(row, 0, sizeof(*row));
    if (floor_row)
        memset(floor_row, 0, sizeof(*floor_row));
    mem_row_begin();
    memset(&call, 0, sizeof(call));
    call.method = method;
    call.base = base;
    if (library) {
        tclod_selector_desc sd;
        tclod_status st;
        tclod_selector_desc_default(&sd);
        sd.solver = method_solvers[method];
        sd.callbacks = config_batch ? world_batch_callbacks(w) : world_callbacks(w);
        if (method == METHOD_MIXED) {
            /* the worlds have no smooth objects; the mixed solver requires the callbacks */
            sd.callbacks.smooth_benefit = bench_no_smooth;
            sd.callbacks.smooth_cost = bench_no_smooth;
        }
        sd.cold_start = !(warm);
        sd.greedy.lookahead = (uint32_t)opt_lookahead;
        sd.greedy.restarts = opt_restarts > 0 ? (int32_t)opt_restarts : TCLOD_OFF;
        if (config_workers > 1u) {
            pool = task_pool_create(config_workers);
            if (!pool) {
                fprintf(stderr, "tclod_bench: no threads for %u workers\n",
                        (unsigned)config_workers);
                return 1;
            }
            sd.tasks = task_pool_tasks(pool);
        }
        st = tclod_selector_create(w->scene, &sd, &selector_alloc, &call.sel);
        if (st != TCLOD_OK) {
            task_pool_destroy(pool);
            fprintf(stderr, "tclod_bench: creating a %s selector failed: %s\n",
                    solver_name(sd.solver), tclod_status_string(st));
            return 1;
        }
    }
    for (f = 0; f < total; ++f) {
        tclod_view view;
        const tclod_id *ids;
        size_t n;
        double us, cost;

        world_camera_at(&w->path, (double)f / (double)FRAMES_PER_LOOP, &view);
        memset(&call.frame, 0, sizeof(call.frame));
        call.frame.view = &view;
        call.frame.budget = budget;
        if (method == METHOD_THRESHOLD_FIXED && f == 0) {
            /* tuned once, on the first view, then kept whatever the view */
            baseline_threshold_tuned(base, &view, budget, &call.result);
            call.bias = call.result.bias;
        }
        us = solve_frame(&call, f);
        if (library) {
            tclod_status st = call.status;
            if (st == TCLOD_OK)
                st = tclod_selector_cut(call.sel, &ids, &n);
            if (st != TCLOD_OK) {
                fprintf(stderr, "tclod_bench: tclod_select failed: %s\n", tclod_status_string(st));
                tclod_selector_destroy(call.sel);
                task_pool_destroy(pool);
                return 1;
            }
            cost = world_sum_cost(w, ids, n);
            if (call.stats.cost > budget || cost > budget) {
                fprintf(stderr, "tclod_bench: budget exceeded: cost %.17g > budget %.17g\n", cost,
                        budget);
                tclod_selector_destroy(call.sel);
                task_pool_destroy(pool);
                return 1;
            }
        } else {
            ids = call.result.ids;
            n = call.result.n;
            cost = world_sum_cost(w, ids, n);
        }
        if (f < WARMUP_FRAMES)
            continue;
        times[f - WARMUP_FRAMES] = us;
        sum_us += us;
        if (floor_row) { /* this selection's frontier, which the next warm solve evaluates */
            size_t m = floor_frontier(fl, (uint32_t)f + 1u, ids, n);
            double t2 = bench_now_us(), t3;
            floor_sink += floor_evaluate(fl, w, &view, m);
            t3 = bench_now_us();
            fl->times[f - WARMUP_FRAMES] = t3 - t2;
            floor_sum_us += t3 - t2;
            floor_row->evaluations += (double)m;
            floor_row->cut += (double)n;
            floor_row->benefit += call.stats.benefit;
            floor_row->cost += call.stats.cost;
        }
        if (library) {
            add_stats(row, &call.stats, n);
        } else {
            row->benefit += call.result.benefit;
            row->cost += call.result.cost;
            row->cut += (double)n;
            row->evaluations += (double)call.result.evaluations;
            row->iterations += (double)call.result.iterations;
            row->increments += (double)call.result.refinements;
        }
        row->violations += cost > budget;
        if (budget > 0.0 && cost / budget > row->max_cost_ratio)
            row->max_cost_ratio = cost / budget;
        row->refined += (double)refined_objects(w, ids, n);
    }
    tclod_selector_destroy(call.sel);
    task_pool_destroy(pool);
    row->workers = (double)config_workers;
    mem_row_end(row);
    finish_row(row, times, frames, sum_us);
    if (floor_row) {
        floor_row->scene_bytes = row->scene_bytes; /* it holds no selector */
        finish_row(floor_row, fl->times, frames, floor_sum_us);
        floor_row->refined = floor_sink > 0.0 ? row->refined : 0.0; /* keeps the sum alive */
    }
    return 0;
}

/* The thesis rows: the mixed solver, cold, with (split = 1) or without quadtree
 * variable splitting, over warm-up plus `frames` timed frames that cycle through
 * `views` views spread evenly over the camera loop. Returns 0 on success; a budget
 * violation or a library error is reported and returns 1. */
static int run_thesis(thesis_scene *t, int split, int precondition, double theta, double budget,
                      unsigned long frames, unsigned long views, double *times, bench_row *row) {
    tclod_selector_desc sd;
    tclod_selector *sel = NULL;
    tclod_status st;
    unsigned long f, total = frames + WARMUP_FRAMES;
    double sum_us = 0.0;

    memset(row, 0, sizeof(*row));
    mem_row_begin();
    tclod_selector_desc_default(&sd);
    sd.solver = TCLOD_SOLVER_MIXED;
    sd.callbacks = thesis_callbacks(t);
    sd.cold_start = 1;
    sd.mixed.split_smooth = split;
    sd.mixed.plain_gradient = !(precondition);
    if (theta >= 0.0)
        sd.mixed.split_threshold = theta;
    st = tclod_selector_create(t->scene, &sd, &selector_alloc, &sel);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: creating a mixed selector failed: %s\n",
                tclod_status_string(st));
        return 1;
    }
    for (f = 0; f < total; ++f) {
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats;
        const tclod_id *ids;
        const tclod_smooth_group *groups;
        size_t n, group_count, g;
        double us, own_cost;

        thesis_camera_at(
            t, (double)((f < WARMUP_FRAMES ? f : f - WARMUP_FRAMES) % views) / (double)views,
            &view);
        memset(&fr, 0, sizeof(fr));
        fr.view = &view;
        fr.budget = budget;
        {
            solve_call call;
            memset(&call, 0, sizeof(call));
            call.method = METHOD_MIXED;
            call.sel = sel;
            call.frame = fr;
            us = solve_frame(&call, f);
            st = call.status;
            stats = call.stats;
        }
        if (st == TCLOD_OK)
            st = tclod_selector_cut(sel, &ids, &n);
        if (st == TCLOD_OK)
            st = tclod_selector_smooth_groups(sel, &groups, &group_count);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: tclod_select failed: %s\n", tclod_status_string(st));
            tclod_selector_destroy(sel);
            return 1;
        }
        own_cost = thesis_sum_cost(t, ids, n, groups, group_count);
        if (stats.cost > budget || own_cost > budget) {
            fprintf(stderr, "tclod_bench: budget exceeded: cost %.17g > budget %.17g\n", own_cost,
                    budget);
            tclod_selector_destroy(sel);
            return 1;
        }
        if (f < WARMUP_FRAMES)
            continue;
        times[f - WARMUP_FRAMES] = us;
        sum_us += us;
        add_stats(row, &stats, n);
        if (budget > 0.0 && own_cost / budget > row->max_cost_ratio)
            row->max_cost_ratio = own_cost / budget;
        for (g = 0; g < group_count; ++g)
            row->refined += (double)groups[g].count;
        row->object_benefit += thesis_selection_benefit(t, &view, ids, n, groups, group_count);
    }
    tclod_selector_destroy(sel);
    mem_row_end(row);
    finish_row(row, times, frames, sum_us);
    return 0;
}

static void print_header(void) {
    printf("scene,solver,mode,objects,nodes,median_us,p99_us,benefit,cost,budget,mean_us,"
           "visible,cut,refined,evaluations,iterations,increments,decrements,frames,"
           "variables,line_searches,object_benefit,ns_per_evaluation,violations,"
           "max_cost_ratio,edits,edit_us,edit_p99_us,requests,evictions,resident_bytes,"
           "change_ns,workers,selector_bytes_per_node,scene_bytes_per_node\n");
}

static void print_row(const char *scene, const char *solver, const char *mode,
                      unsigned long objects, unsigned long nodes, double budget,
                      unsigned long visible, const bench_row *r) {
    /* mean time over mean evaluations: the time per node the solve looked at */
    double ns_per_evaluation = r->evaluations > 0.0 ? r->mean_us * 1000.0 / r->evaluations : 0.0;
    double per_node = nodes > 0 ? 1.0 / (double)nodes : 0.0;
    printf("%s,%s,%s,%lu,%lu,%.2f,%.2f,%.6g,%.6g,%.6g,%.2f,%lu,%.0f,%.0f,%.0f,%.0f,%.0f,%.0f,%lu,"
           "%.1f,%.1f,%.6g,%.1f,%lu,%.4f,%.0f,%.2f,%.2f,%.2f,%.2f,%.6g,%.2f,%.0f,%.1f,%.1f\n",
           scene, solver, mode, objects, nodes, r->median_us, r->p99_us, r->benefit, r->cost,
           budget, r->mean_us, visible, r->cut, r->refined, r->evaluations, r->iterations,
           r->increments, r->decrements, r->frames, r->variables, r->line_searches,
           r->object_benefit, ns_per_evaluation, r->violations, r->max_cost_ratio, r->edits,
           r->edit_median_us, r->edit_p99_us, r->requests, r->evictions, r->resident_bytes,
           r->change_ns, r->workers > 0.0 ? r->workers : 1.0, r->selector_bytes * per_node,
           r->scene_bytes * per_node);
    fflush(stdout);
}

/* The random and flyover rows: the library's solvers for discrete hierarchies, cold and
 * warm (greedy first, then robin_hood, the rows this program has always printed), then
 * the mixed solver and the baselines on the same frames and budget. The mixed and Robin
 * Hood solvers keep nothing from frame to frame (the warm start is the greedy's) and
 * the baselines recompute every frame: one row each. flat needs objects that are chains
 * (objects may be NULL: no flat row). The baselines' data is made only when one of their
 * rows runs. *selector_bytes: the most bytes a row's selector held. */
static int bench_scene(const char *scene, world_scene *w, double budget, unsigned long visible,
                       unsigned long frames, const tclod_id *objects, uint32_t object_count,
                       double *selector_bytes) {
    static const bench_method order[] = {
        METHOD_GREEDY,          METHOD_ROBIN_HOOD, METHOD_MIXED, METHOD_THRESHOLD_TUNED,
        METHOD_THRESHOLD_FIXED, METHOD_PQ_STOP,    METHOD_FLAT};
    double *times = (double *)malloc(frames * sizeof(*times));
    baseline_scene bs;
    baseline_selector *base = NULL;
    tclod_callbacks cb = world_callbacks(w);
    size_t s;
    int variant, rc = 0, baselines = 0;
    *selector_bytes = 0.0;
    if (!times) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        return 1;
    }
    for (s = 0; s < sizeof(order) / sizeof(order[0]); ++s)
        baselines |= order[s] > METHOD_ROBIN_HOOD && row_wanted(method_names[order[s]], "cold");
    memset(&bs, 0, sizeof(bs));
    if (baselines && (baseline_scene_init(&bs, w->scene, w->bounds, w->triangles, objects,
                                          object_count) != TCLOD_OK ||
                      baseline_create(&bs, &cb, &base) != TCLOD_OK)) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        baseline_scene_free(&bs);
        free(times);
        return 1;
    }
    for (s = 0; s < sizeof(order) / sizeof(order[0]) && rc == 0; ++s) {
        bench_method m = order[s];
        if (m > METHOD_ROBIN_HOOD && !baselines)
            continue;
        if (m == METHOD_FLAT && bs.object_count == 0)
            continue;
        /* greedy: cold, warm (+ warm_floor), warm_batch, warm_parallel */
        for (variant = 0; variant < (m == METHOD_GREEDY ? 4 : 1) && rc == 0; ++variant) {
            static const char *const modes[] = {"cold", "warm", "warm_batch", "warm_parallel"};
            bench_row row, floor_row;
            const char *mode = modes[variant];
            int warm = variant > 0;
            int with_floor = variant == 1 && row_wanted(method_names[m], "warm_floor");
            frontier_floor fl;
            if (!row_wanted(method_names[m], mode) && !with_floor)
                continue;
            config_batch = variant >= 2;
            config_workers = variant == 3 ? 2u : 1u;
            if (with_floor && floor_init(&fl, w, frames) != 0) {
                fprintf(stderr, "tclod_bench: out of memory\n");
                rc = 1;
                break;
            }
            if (run_config(w, m, warm, budget, frames, times, base, &row, with_floor ? &fl : NULL,
                           with_floor ? &floor_row : NULL) != 0)
                rc = 1;
            config_batch = 0;
            config_workers = 1u;
            if (row.selector_bytes > *selector_bytes)
                *selector_bytes = row.selector_bytes;
            if (rc == 0 && row_wanted(method_names[m], mode))
                print_row(scene, method_names[m], mode, (unsigned long)w->object_count,
                          (unsigned long)w->node_count, budget, visible, &row);
            if (rc == 0 && with_floor)
                print_row(scene, method_names[m], "warm_floor", (unsigned long)w->object_count,
                          (unsigned long)w->node_count, budget, visible, &floor_row);
            if (with_floor)
                floor_free(&fl);
        }
    }
    baseline_destroy(base);
    baseline_scene_free(&bs);
    free(times);
    return rc;
}

/* ---- churn: a random world edited between frames ------------------------------------ */

/* The churn scene's world when --objects does not say, its edits' seed (fixed, so that
 * runs repeat), the timed frames with --quick and how far a move goes. */
#define CHURN_OBJECTS 10000u
#define CHURN_SEED 0x636875726eull
#define CHURN_QUICK_FRAMES 50ul
/* A move shifts an object by up to this many metres along x and along z (a walk, not a
 * jump: the objects stay near the group impostors they were built under). */
#define CHURN_STEP_M 3.0f

/* splitmix64: the bench's own generator (world_scene's is private to it). */
static uint64_t churn_next(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, n), n > 0 (the modulo bias is negligible for n < 2^32). */
static uint32_t churn_below(uint64_t *state, uint32_t n) {
    return (uint32_t)(churn_next(state) % n);
}

/* Uniform in [lo, hi). */
static float churn_range(uint64_t *state, float lo, float hi) {
    return lo + (hi - lo) * (float)(churn_next(state) >> 40) * (1.0f / 16777216.0f);
}

/* One frame's edits, drawn before they are timed: the objects to move (indices and
 * displacements), the objects to remove (an index into the objects left after the
 * removals before it) and the level-0 triangles of the objects added, one in the place
 * of each removed one. */
typedef struct churn_plan {
    uint32_t moves, removals; /* objects moved and removed (= added) per frame */
    uint32_t *move_object;
    float *move_step; /* 2 per move: dx, dz, m */
    uint32_t *remove_object;
    uint32_t *add_triangles;
    tclod_id *add_parent; /* filled while editing: each removed object's group */
    float *add_bounds;    /* and its bounds, 4 per removal */
    const world_cost_model *cost;
    uint64_t rng;
} churn_plan;

static void churn_plan_free(churn_plan *p) {
    free(p->move_object);
    free(p->move_step);
    free(p->remove_object);
    free(p->add_triangles);
    free(p->add_parent);
    free(p->add_bounds);
    memset(p, 0, sizeof(*p));
}

/* 1 % of the objects moved and 0.1 % removed and added every frame, at least one each. */
static int churn_plan_init(churn_plan *p, uint32_t objects, const world_cost_model *cost) {
    memset(p, 0, sizeof(*p));
    p->moves = (objects + 50u) / 100u;
    p->removals = (objects + 500u) / 1000u;
    if (p->moves < 1u)
        p->moves = 1u;
    if (p->removals < 1u)
        p->removals = 1u;
    if (p->removals >= objects) /* a world of one object keeps it */
        p->removals = objects - 1u;
    p->move_object = (uint32_t *)malloc(p->moves * sizeof(uint32_t));
    p->move_step = (float *)malloc(2u * (size_t)p->moves * sizeof(float));
    p->remove_object = (uint32_t *)malloc((p->removals + 1u) * sizeof(uint32_t));
    p->add_triangles = (uint32_t *)malloc((p->removals + 1u) * sizeof(uint32_t));
    p->add_parent = (tclod_id *)malloc((p->removals + 1u) * sizeof(tclod_id));
    p->add_bounds = (float *)malloc(4u * ((size_t)p->removals + 1u) * sizeof(float));
    p->cost = cost;
    p->rng = CHURN_SEED;
    if (!p->move_object || !p->move_step || !p->remove_object || !p->add_triangles ||
        !p->add_parent || !p->add_bounds) {
        churn_plan_free(p);
        return 1;
    }
    return 0;
}

/* Draws the next frame's edits for a world of `objects` objects. Moved objects are drawn
 * with replacement (one may move twice in a frame, as in a game). */
static void churn_plan_draw(churn_plan *p, uint32_t objects) {
    uint32_t i;
    for (i = 0; i < p->moves; ++i) {
        p->move_object[i] = churn_below(&p->rng, objects);
        p->move_step[2u * i] = churn_range(&p->rng, -CHURN_STEP_M, CHURN_STEP_M);
        p->move_step[2u * i + 1u] = churn_range(&p->rng, -CHURN_STEP_M, CHURN_STEP_M);
    }
    for (i = 0; i < p->removals; ++i) {
        p->remove_object[i] = churn_below(&p->rng, objects - i);
        /* the world's distribution of level-0 triangles (world_build_random) */
        p->add_triangles[i] = 512u + churn_below(&p->rng, 1536u);
    }
}

static float churn_clamp(float x, float lo, float hi) {
    return x < lo ? lo : (x > hi ? hi : x);
}

/* The timed edits of one frame, out of line like bench_solve so that callgrind can count
 * them alone (--toggle-collect=bench_edit): the moves (every level of an object gets its
 * new bounds; it stays on the ground, its centre on the world's square), then the
 * removals (level 0, which takes the levels with it), then the additions: a new object
 * (a chain of the world's levels, new triangles) in each removed object's place, under
 * its group impostor, so that the impostors' bounds and cover still describe their
 * objects. Returns the scene edit calls made, or 0 on an error (reported). */
unsigned long bench_edit(churn_plan *p, world_scene *w);
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
unsigned long
bench_edit(churn_plan *p, world_scene *w) {
    unsigned long calls = 0;
    uint32_t i;
    tclod_status st = TCLOD_OK;
    for (i = 0; i < p->moves && st == TCLOD_OK; ++i) {
        const float *ob = w->object_bounds + 4u * (size_t)p->move_object[i];
        float b[4];
        b[0] = churn_clamp(ob[0] + p->move_step[2u * i], 0.0f, w->side);
        b[1] = ob[1];
        b[2] = churn_clamp(ob[2] + p->move_step[2u * i + 1u], 0.0f, w->side);
        b[3] = ob[3];
        st = world_move_object(w, p->move_object[i], b);
        calls += w->levels;
    }
    for (i = 0; i < p->removals && st == TCLOD_OK; ++i) {
        uint32_t o = p->remove_object[i];
        p->add_parent[i] = tclod_scene_parent(w->scene, world_object_level(w, o, 0));
        memcpy(p->add_bounds + 4u * (size_t)i, w->object_bounds + 4u * (size_t)o,
               4u * sizeof(float));
        st = world_remove_object(w, o);
        calls += 1u;
    }
    for (i = 0; i < p->removals && st == TCLOD_OK; ++i) {
        st = world_add_object(w, p->add_parent[i], p->add_bounds + 4u * (size_t)i,
                              p->add_triangles[i], p->cost, NULL);
        calls += w->levels;
    }
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: churn: editing the world failed: %s\n",
                tclod_status_string(st));
        return 0;
    }
    return calls;
}

/* A warm greedy selector over w with the options' lookahead and restarts,
 * in a zeroed call. */
static tclod_status warm_greedy(world_scene *w, solve_call *call) {
    tclod_selector_desc sd;
    memset(call, 0, sizeof(*call));
    call->method = METHOD_GREEDY;
    tclod_selector_desc_default(&sd);
    sd.solver = TCLOD_SOLVER_GREEDY;
    sd.callbacks = world_callbacks(w);
    sd.cold_start = 0;
    sd.greedy.lookahead = (uint32_t)opt_lookahead;
    sd.greedy.restarts = opt_restarts > 0 ? (int32_t)opt_restarts : TCLOD_OFF;
    return tclod_selector_create(w->scene, &sd, &selector_alloc, &call->sel);
}

/* Frame f of w's camera path within budget: solved once in the warm-up,
 * timed after it (*us), its cut in *ids, *n. */
static tclod_status path_frame(solve_call *call, const world_scene *w, unsigned long f,
                               double budget, tclod_view *view, double *us, const tclod_id **ids,
                               size_t *n) {

    world_camera_at(&w->path, (double)f / (double)FRAMES_PER_LOOP, view);
    memset(&call->frame, 0, sizeof(call->frame));
    call->frame.view = view;
    call->frame.budget = budget;
    *us = solve_frame(call, f);
    return call->status == TCLOD_OK ? tclod_selector_cut(call->sel, ids, n) : call->status;
}

/* Warm-up plus `frames` timed frames of the greedy solver, warm, along the world's loop
 * with a fixed budget, with the plan's edits before every frame after the first (the
 * first solves from the roots, with no cut to repair) when plan is not NULL. times gets
 * the select calls' times, edit_times (with plan) the edits'. Every frame's selection
 * is checked: within the budget, and only live nodes. Returns 0 on success, 1 on an
 * error (reported). */
static int run_churn(world_scene *w, churn_plan *plan, double budget, unsigned long frames,
                     double *times, double *edit_times, bench_row *row) {
    solve_call call;
    tclod_status st;
    unsigned long f, total = frames + WARMUP_FRAMES;
    double sum_us = 0.0, edits = 0.0;

    memset(row, 0, sizeof(*row));
    mem_row_begin();
    st = warm_greedy(w, &call);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: creating a greedy selector failed: %s\n",
                tclod_status_string(st));
        return 1;
    }
    for (f = 0; f < total; ++f) {
        tclod_view view;
        const tclod_id *ids;
        size_t n, i;
        double us, e0 = 0.0, e1 = 0.0, cost;
        unsigned long calls = 0;

        if (plan && f > 0) {
            churn_plan_draw(plan, w->object_count);
            e0 = bench_now_us();
            calls = bench_edit(plan, w);
            e1 = bench_now_us();
            if (calls == 0) {
                tclod_selector_destroy(call.sel);
                return 1;
            }
        }
        st = path_frame(&call, w, f, budget, &view, &us, &ids, &n);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: tclod_select failed: %s\n", tclod_status_string(st));
            tclod_selector_destroy(call.sel);
            return 1;
        }
        cost = world_sum_cost(w, ids, n);
        if (call.stats.cost > budget || cost > budget) {
            fprintf(stderr, "tclod_bench: budget exceeded: cost %.17g > budget %.17g\n", cost,
                    budget);
            tclod_selector_destroy(call.sel);
            return 1;
        }
        for (i = 0; i < n; ++i) {
            if (!tclod_scene_node_live(w->scene, ids[i])) {
                fprintf(stderr, "tclod_bench: churn: frame %lu selects node %u, not live\n", f,
                        (unsigned)ids[i]);
                tclod_selector_destroy(call.sel);
                return 1;
            }
        }
        if (f < WARMUP_FRAMES)
            continue;
        times[f - WARMUP_FRAMES] = us;
        sum_us += us;
        if (plan)
            edit_times[f - WARMUP_FRAMES] = e1 - e0;
        edits += (double)calls;
        add_stats(row, &call.stats, n);
        if (budget > 0.0 && cost / budget > row->max_cost_ratio)
            row->max_cost_ratio = cost / budget;
        row->refined += (double)refined_objects(w, ids, n);
    }
    tclod_selector_destroy(call.sel);
    mem_row_end(row);
    finish_row(row, times, frames, sum_us);
    row->edits = edits / (double)frames;
    if (plan) {
        bench_sort(edit_times, frames);
        row->edit_median_us = bench_median(edit_times, frames);
        row->edit_p99_us = bench_percentile(edit_times, frames, 99.0);
    }
    return 0;
}

/* The churn rows, in the order they are printed: warm (edits), warm_noedit (no edits,
 * the world as built) and warm_edited (no edits, the world as the warm run left it). */
enum { CHURN_WARM, CHURN_NOEDIT, CHURN_EDITED, CHURN_MODES };
static const char *const churn_modes[CHURN_MODES] = {"warm", "warm_noedit", "warm_edited"};

/* The churn rows: warm_noedit on the world as built, then warm on the same world with
 * the edits (which change it), then warm_edited on the world they left; printed warm
 * first; then the summary line (stderr, so that stdout stays CSV). */
static int bench_churn(uint32_t objects, unsigned long frames) {
    static const int run_order[CHURN_MODES] = {CHURN_NOEDIT, CHURN_WARM, CHURN_EDITED};
    world_random_desc d;
    world_scene w;
    churn_plan plan;
    bench_row rows[CHURN_MODES];
    unsigned long nodes[CHURN_MODES], visible;
    int ran[CHURN_MODES] = {0, 0, 0}, k, rc = 0;
    double budget, t0 = bench_now_us();
    double *times = (double *)malloc(frames * sizeof(*times));
    double *edit_times = (double *)malloc(frames * sizeof(*edit_times));
    tclod_status st;

    if (!times || !edit_times) {
        free(times);
        free(edit_times);
        fprintf(stderr, "tclod_bench: out of memory\n");
        return 1;
    }
    world_random_desc_default(&d);
    d.objects = objects;
    d.alloc = &scene_alloc;
    st = world_build_random(&d, &w);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: building %u objects failed: %s\n", objects,
                tclod_status_string(st));
        free(times);
        free(edit_times);
        return 1;
    }
    if (churn_plan_init(&plan, objects, &d.cost) != 0) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        world_scene_free(&w);
        free(times);
        free(edit_times);
        return 1;
    }
    /* the random scene's budget, on the world as built, kept for every row */
    visible = bench_world_visible(&w);
    budget = (double)visible * bench_world_level1_cost(&w);
    fprintf(stderr,
            "tclod_bench: churn %u objects: %u nodes (%u groups), built in %.0f ms; "
            "%lu objects in view, budget %.3f ms; per frame %u objects moved, %u removed, "
            "%u added\n",
            objects, w.node_count, w.group_count, (bench_now_us() - t0) / 1000.0, visible, budget,
            plan.moves, plan.removals, plan.removals);
    for (k = 0; k < CHURN_MODES && rc == 0; ++k) {
        int m = run_order[k];
        /* warm_edited needs the world the warm run edited: warm runs for either */
        int wanted = row_wanted("greedy", churn_modes[m]) ||
                     (m == CHURN_WARM && row_wanted("greedy", churn_modes[CHURN_EDITED]));
        if (!wanted || (m == CHURN_EDITED && !ran[CHURN_WARM]))
            continue;
        nodes[m] = (unsigned long)w.node_count;
        if (run_churn(&w, m == CHURN_WARM ? &plan : NULL, budget, frames, times, edit_times,
                      &rows[m]) != 0)
            rc = 1;
        else
            ran[m] = 1;
        if (m == CHURN_WARM)
            nodes[m] = (unsigned long)w.node_count; /* the id range the edits left */
    }
    for (k = 0; k < CHURN_MODES && rc == 0; ++k)
        if (ran[k] && row_wanted("greedy", churn_modes[k]))
            print_row("churn", "greedy", churn_modes[k], (unsigned long)objects, nodes[k], budget,
                      visible, &rows[k]);
    if (rc == 0 && ran[CHURN_WARM] && ran[CHURN_NOEDIT])
        fprintf(stderr,
                "summary: scene=churn objects=%u warm_us_median=%.2f warm_noedit_us_median=%.2f "
                "ratio=%.3f edit_us_median=%.2f\n",
                objects, rows[CHURN_WARM].median_us, rows[CHURN_NOEDIT].median_us,
                rows[CHURN_NOEDIT].median_us > 0.0
                    ? rows[CHURN_WARM].median_us / rows[CHURN_NOEDIT].median_us
                    : 0.0,
                rows[CHURN_WARM].edit_median_us);
    churn_plan_free(&plan);
    world_scene_free(&w);
    free(times);
    free(edit_times);
    return rc;
}

/* ---- stream: what streaming costs the library --------------------------------------- */

/* The stream scene's world when --objects does not say, the timed frames with --quick,
 * the bytes a node takes per triangle it draws (an indexed mesh: three 32-bit indices and
 * about half a 32-byte vertex per triangle), a loader's slots (K: loads made resident per
 * frame, and the stream desc's max_requests), and the flips: residency changes timed in
 * batches, and the seed that picks their nodes. */
#define STREAM_OBJECTS 10000u
#define STREAM_QUICK_FRAMES 50ul
#define STREAM_BYTES_PER_TRIANGLE 32.0
#define STREAM_SLOTS 20u
#define STREAM_FLIP_CALLS 1000000ul
#define STREAM_FLIP_BATCHES 20ul
#define STREAM_SEED 0x73747265616dull

/* The stream rows, in the order they are printed (and run, but flips, which runs last:
 * its changes scramble the scene's list of resident nodes, which the evictions walk). */
enum { STREAM_FLIPS, STREAM_PLAIN, STREAM_STREAM, STREAM_RESIDENT_ONLY, STREAM_MODES };
static const char *const stream_modes[STREAM_MODES] = {"flips", "warm_plain", "warm_stream",
                                                       "warm_resident_only"};

/* The residency changes the warm_stream run made before each frame, replayed by
 * warm_resident_only: frame f's are ids[end[f - 1] .. end[f]) (end[-1] = 0), made
 * resident when value is 1, not resident when 0. */
typedef struct stream_log {
    tclod_id *ids;
    uint8_t *value;
    size_t count, cap;
    size_t *end;      /* per frame, warm-up included */
    double *benefit;  /* per frame: the selection's benefit, which the replay must match */
    size_t *cut;      /* and its size */
    double *times;    /* per timed frame: warm_stream's select time, µs, in frame order */
    double *replay;   /* and warm_resident_only's */
    tclod_id *parent; /* bench_parents: to check what the evictions may not free */
    uint32_t *drawn;  /* the frame (+ 1) a node was last drawn or an ancestor of a drawn one */
} stream_log;

static void stream_log_free(stream_log *g) {
    free(g->ids);
    free(g->value);
    free(g->end);
    free(g->benefit);
    free(g->cut);
    free(g->times);
    free(g->replay);
    free(g->parent);
    free(g->drawn);
    memset(g, 0, sizeof(*g));
}

static int stream_log_init(stream_log *g, const world_scene *w, unsigned long frames) {
    unsigned long total = frames + WARMUP_FRAMES;
    memset(g, 0, sizeof(*g));
    g->cap = (size_t)total * STREAM_SLOTS;
    g->ids = (tclod_id *)malloc(g->cap * sizeof(tclod_id));
    g->value = (uint8_t *)malloc(g->cap);
    g->end = (size_t *)malloc(total * sizeof(size_t));
    g->benefit = (double *)malloc(total * sizeof(double));
    g->cut = (size_t *)malloc(total * sizeof(size_t));
    g->times = (double *)malloc(frames * sizeof(double));
    g->replay = (double *)malloc(frames * sizeof(double));
    g->parent = bench_parents(w->scene);
    g->drawn = (uint32_t *)calloc((size_t)w->node_count + 1u, sizeof(uint32_t));
    if (!g->ids || !g->value || !g->end || !g->benefit || !g->cut || !g->times || !g->replay ||
        (w->node_count && !g->parent) || !g->drawn) {
        stream_log_free(g);
        return 1;
    }
    return 0;
}

/* Makes node id resident (value 1) or not (0) and logs the change; 1 on an error
 * (reported). */
static int stream_change(stream_log *g, tclod_scene *s, tclod_id id, int value) {
    tclod_status st;
    if (g->count == g->cap) {
        size_t cap = 2u * g->cap + 64u;
        tclod_id *ids = (tclod_id *)realloc(g->ids, cap * sizeof(tclod_id));
        uint8_t *v;
        if (!ids)
            return 1;
        g->ids = ids;
        v = (uint8_t *)realloc(g->value, cap);
        if (!v)
            return 1;
        g->value = v;
        g->cap = cap;
    }
    st = tclod_scene_set_resident(s, id, value);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: stream: tclod_scene_set_resident(%u, %d) failed: %s (%s)\n",
                (unsigned)id, value, tclod_status_string(st), tclod_scene_last_error(s));
        return 1;
    }
    g->ids[g->count] = id;
    g->value[g->count++] = (uint8_t)value;
    return 0;
}

/* Every node resident (all 1), or only the roots (the start of a streamed scene).
 * Returns 1 on an error (reported). */
static int stream_reset(world_scene *w, int all) {
    uint32_t i;
    for (i = 0; i < w->node_count; ++i) {
        int value = all || tclod_scene_parent(w->scene, i) == TCLOD_NONE;
        tclod_status st = tclod_scene_set_resident(w->scene, i, value);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: stream: tclod_scene_set_resident(%u, %d) failed: %s\n",
                    (unsigned)i, value, tclod_status_string(st));
            return 1;
        }
    }
    return 0;
}

/* Checks warm_stream's frame against the contract of docs/streaming.md: every drawn node
 * resident; every request live and not resident; every eviction resident, not drawn and
 * no ancestor of a drawn node. Returns 1 on a violation (reported). */
static int stream_check(stream_log *g, const world_scene *w, uint32_t stamp, const tclod_id *ids,
                        size_t n, const tclod_stream_item *req, size_t n_req,
                        const tclod_stream_item *ev, size_t n_ev, unsigned long f) {
    size_t i;
    for (i = 0; i < n; ++i) {
        tclod_id a;
        if (!tclod_scene_node_resident(w->scene, ids[i])) {
            fprintf(stderr, "tclod_bench: stream: frame %lu draws node %u, not resident\n", f,
                    (unsigned)ids[i]);
            return 1;
        }
        for (a = ids[i]; a != TCLOD_NONE && g->drawn[a] != stamp; a = g->parent[a])
            g->drawn[a] = stamp;
    }
    for (i = 0; i < n_req; ++i)
        if ((req[i].flags & TCLOD_STREAM_SMOOTH) || !tclod_scene_node_live(w->scene, req[i].id) ||
            tclod_scene_node_resident(w->scene, req[i].id)) {
            fprintf(stderr,
                    "tclod_bench: stream: frame %lu requests node %u (flags %u), not a live "
                    "non-resident node\n",
                    f, (unsigned)req[i].id, (unsigned)req[i].flags);
            return 1;
        }
    for (i = 0; i < n_ev; ++i)
        if ((ev[i].flags & TCLOD_STREAM_SMOOTH) || !tclod_scene_node_resident(w->scene, ev[i].id) ||
            g->drawn[ev[i].id] == stamp) {
            fprintf(stderr,
                    "tclod_bench: stream: frame %lu evicts node %u (flags %u): not resident, "
                    "or drawn or an ancestor of a drawn node\n",
                    f, (unsigned)ev[i].id, (unsigned)ev[i].flags);
            return 1;
        }
    return 0;
}

/* Warm-up plus `frames` timed frames of the greedy solver, warm, along the world's loop
 * with a fixed budget, in one of the select modes: warm_plain (every node resident, no
 * stream desc), warm_stream (desc; before every frame, the previous select's evictions
 * freed and its first STREAM_SLOTS requests made resident, logged in g) or
 * warm_resident_only (no plan: the residency changes of g replayed). times gets the
 * select calls' times. Every frame's selection is checked: within the budget, only
 * resident nodes; warm_stream's lists and memory (stream_check), warm_resident_only's
 * selection the same as warm_stream's. Returns 0 on success, 1 on an error (reported). */
static int run_stream(world_scene *w, int mode, const tclod_stream_desc *desc, double budget,
                      unsigned long frames, double *times, stream_log *g, bench_row *row) {
    solve_call call;
    tclod_status st;
    unsigned long f, total = frames + WARMUP_FRAMES, differ = 0;
    double sum_us = 0.0;
    size_t replayed = 0;

    memset(row, 0, sizeof(*row));
    mem_row_begin();
    st = warm_greedy(w, &call);
    if (st == TCLOD_OK && mode == STREAM_STREAM)
        st = tclod_selector_set_stream(call.sel, desc);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: stream: creating a greedy selector failed: %s\n",
                tclod_status_string(st));
        tclod_selector_destroy(call.sel);
        return 1;
    }
    if (mode == STREAM_STREAM)
        g->count = 0;
    for (f = 0; f < total; ++f) {
        tclod_view view;
        const tclod_id *ids;
        const tclod_stream_item *req = NULL, *ev = NULL;
        size_t n, n_req = 0, n_ev = 0, i;
        double us, cost;
        int rc = 0;

        if (mode == STREAM_STREAM && f > 0) {
            /* the previous select's lists: evictions first (they make the room), then
             * as many requests as the loader has slots, all arrived */
            st = tclod_selector_evictions(call.sel, &ev, &n_ev);
            if (st == TCLOD_OK)
                st = tclod_selector_requests(call.sel, &req, &n_req);
            for (i = 0; i < n_ev && st == TCLOD_OK && rc == 0; ++i)
                rc = stream_change(g, w->scene, ev[i].id, 0);
            for (i = 0; i < n_req && i < STREAM_SLOTS && st == TCLOD_OK && rc == 0; ++i)
                rc = stream_change(g, w->scene, req[i].id, 1);
            if (st != TCLOD_OK || rc != 0) {
                fprintf(stderr, "tclod_bench: stream: applying frame %lu's lists failed: %s\n", f,
                        st != TCLOD_OK ? tclod_status_string(st) : "out of memory");
                tclod_selector_destroy(call.sel);
                return 1;
            }
            if (tclod_scene_resident_bytes(w->scene) > desc->memory_budget &&
                !(call.stats.notes & TCLOD_NOTE_MEMORY_SHORT)) {
                fprintf(stderr,
                        "tclod_bench: stream: frame %lu: resident bytes %.17g over the memory "
                        "budget %.17g once the lists are applied\n",
                        f, tclod_scene_resident_bytes(w->scene), desc->memory_budget);
                tclod_selector_destroy(call.sel);
                return 1;
            }
        }
        if (mode == STREAM_STREAM)
            g->end[f] = g->count;
        if (mode == STREAM_RESIDENT_ONLY) {
            for (; replayed < g->end[f] && st == TCLOD_OK; ++replayed)
                st = tclod_scene_set_resident(w->scene, g->ids[replayed], g->value[replayed]);
            if (st != TCLOD_OK) {
                fprintf(stderr, "tclod_bench: stream: replaying frame %lu's changes failed: %s\n",
                        f, tclod_status_string(st));
                tclod_selector_destroy(call.sel);
                return 1;
            }
        }
        st = path_frame(&call, w, f, budget, &view, &us, &ids, &n);
        if (st == TCLOD_OK && mode == STREAM_STREAM)
            st = tclod_selector_requests(call.sel, &req, &n_req);
        if (st == TCLOD_OK && mode == STREAM_STREAM)
            st = tclod_selector_evictions(call.sel, &ev, &n_ev);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: tclod_select failed: %s\n", tclod_status_string(st));
            tclod_selector_destroy(call.sel);
            return 1;
        }
        cost = world_sum_cost(w, ids, n);
        if (call.stats.cost > budget || cost > budget) {
            fprintf(stderr, "tclod_bench: budget exceeded: cost %.17g > budget %.17g\n", cost,
                    budget);
            rc = 1;
        }
        for (i = 0; i < n && rc == 0; ++i)
            if (!tclod_scene_node_resident(w->scene, ids[i])) {
                fprintf(stderr, "tclod_bench: stream: %s frame %lu draws node %u, not resident\n",
                        stream_modes[mode], f, (unsigned)ids[i]);
                rc = 1;
            }
        if (rc == 0 && mode == STREAM_STREAM) {
            rc = stream_check(g, w, (uint32_t)f + 1u, ids, n, req, n_req, ev, n_ev, f);
            g->benefit[f] = call.stats.benefit;
            g->cut[f] = n;
        }
        if (mode == STREAM_RESIDENT_ONLY && (call.stats.benefit != g->benefit[f] || n != g->cut[f]))
            ++differ;
        if (rc != 0) {
            tclod_selector_destroy(call.sel);
            return 1;
        }
        if (f < WARMUP_FRAMES)
            continue;
        times[f - WARMUP_FRAMES] = us;
        if (mode == STREAM_STREAM)
            g->times[f - WARMUP_FRAMES] = us;
        if (mode == STREAM_RESIDENT_ONLY)
            g->replay[f - WARMUP_FRAMES] = us;
        sum_us += us;
        add_stats(row, &call.stats, n);
        row->requests += (double)call.stats.requests;
        row->evictions += (double)call.stats.evictions;
        row->resident_bytes += call.stats.resident_bytes;
        if (budget > 0.0 && cost / budget > row->max_cost_ratio)
            row->max_cost_ratio = cost / budget;
        row->refined += (double)refined_objects(w, ids, n);
    }
    tclod_selector_destroy(call.sel);
    mem_row_end(row);
    if (differ > 0)
        fprintf(stderr,
                "tclod_bench: stream: warning: warm_resident_only selected otherwise than "
                "warm_stream in %lu of %lu frames on the same residency\n",
                differ, total);
    finish_row(row, times, frames, sum_us);
    row->requests /= (double)frames;
    row->evictions /= (double)frames;
    row->resident_bytes /= (double)frames;
    return 0;
}

/* The timed residency changes of one flips batch, out of line like bench_solve: node
 * ids[i] becomes resident when it is not and not resident when it is (state, the bench's
 * copy of the scene's flags, says which), so that every call is a change. Returns the
 * calls that failed. */
unsigned long bench_flip(tclod_scene *s, const tclod_id *ids, uint8_t *state, size_t n);
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
unsigned long
bench_flip(tclod_scene *s, const tclod_id *ids, uint8_t *state, size_t n) {
    unsigned long failed = 0;
    size_t i;
    for (i = 0; i < n; ++i) {
        tclod_id id = ids[i];
        uint8_t v = (uint8_t)!state[id];
        state[id] = v;
        failed += tclod_scene_set_resident(s, id, v) != TCLOD_OK;
    }
    return failed;
}

/* The flips row: STREAM_FLIP_CALLS residency changes on nodes drawn at random (with
 * replacement, from a fixed seed), in STREAM_FLIP_BATCHES timed batches, no select in
 * between. The row's times are per batch, its frames the batches; change_ns is the median
 * over the batches of a batch's time per change. Leaves every node resident. */
static int run_flips(world_scene *w, bench_row *row) {
    size_t per_batch = STREAM_FLIP_CALLS / STREAM_FLIP_BATCHES, i;
    tclod_id *ids = (tclod_id *)malloc(per_batch * sizeof(tclod_id));
    uint8_t *state = (uint8_t *)malloc((size_t)w->node_count + 1u);
    double times[STREAM_FLIP_BATCHES], per_change[STREAM_FLIP_BATCHES], sum_us = 0.0;
    uint64_t rng = STREAM_SEED;
    unsigned long b, failed = 0;
    memset(row, 0, sizeof(*row));
    mem_row_begin();
    if (!ids || !state || w->node_count == 0) {
        fprintf(stderr, "tclod_bench: stream: out of memory\n");
        free(ids);
        free(state);
        return 1;
    }
    for (i = 0; i < w->node_count; ++i)
        state[i] = (uint8_t)tclod_scene_node_resident(w->scene, (tclod_id)i);
    for (b = 0; b < STREAM_FLIP_BATCHES; ++b) {
        double t0;
        for (i = 0; i < per_batch; ++i)
            ids[i] = churn_below(&rng, w->node_count);
        t0 = bench_now_us();
        failed += bench_flip(w->scene, ids, state, per_batch);
        times[b] = bench_now_us() - t0;
        per_change[b] = times[b] * 1000.0 / (double)per_batch;
        sum_us += times[b];
    }
    free(ids);
    free(state);
    if (failed > 0) {
        fprintf(stderr, "tclod_bench: stream: %lu of %lu residency changes failed\n", failed,
                STREAM_FLIP_CALLS);
        return 1;
    }
    mem_row_end(row);
    finish_row(row, times, STREAM_FLIP_BATCHES, sum_us);
    bench_sort(per_change, STREAM_FLIP_BATCHES);
    row->change_ns = bench_median(per_change, STREAM_FLIP_BATCHES);
    return stream_reset(w, 1);
}

/* Whether a stream row is wanted: the select rows are the greedy's; flips has no solver
 * (--solver does not filter it). */
static int stream_wanted(int mode) {
    return mode == STREAM_FLIPS ? only_mode == NULL || strcmp(only_mode, stream_modes[mode]) == 0
                                : row_wanted("greedy", stream_modes[mode]);
}

/* The stream rows: a random world of `objects` objects whose every node is given
 * STREAM_BYTES_PER_TRIANGLE bytes per triangle; warm_plain (every node resident),
 * warm_stream (from the roots alone, the plan's lists applied before every frame) and
 * warm_resident_only (warm_stream's residency replayed, no plan), then flips; printed
 * flips first; then the summary line (stderr). */
static int bench_stream(uint32_t objects, unsigned long frames) {
    static const int run_order[STREAM_MODES] = {STREAM_PLAIN, STREAM_STREAM, STREAM_RESIDENT_ONLY,
                                                STREAM_FLIPS};
    world_random_desc d;
    world_scene w;
    stream_log g;
    tclod_stream_desc desc;
    bench_row rows[STREAM_MODES];
    unsigned long visible;
    int ran[STREAM_MODES] = {0, 0, 0, 0}, k, rc = 0;
    double budget, total_bytes = 0.0, t0 = bench_now_us(), *diff = NULL;
    double *times = (double *)malloc(frames * sizeof(*times));
    tclod_status st = TCLOD_OK;
    uint32_t i;

    if (!times) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        return 1;
    }
    world_random_desc_default(&d);
    d.objects = objects;
    d.alloc = &scene_alloc;
    st = world_build_random(&d, &w);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: building %u objects failed: %s\n", objects,
                tclod_status_string(st));
        free(times);
        return 1;
    }
    for (i = 0; i < w.node_count && st == TCLOD_OK; ++i) {
        double bytes = STREAM_BYTES_PER_TRIANGLE * (double)w.triangles[i];
        st = tclod_scene_set_node_bytes(w.scene, i, bytes);
        total_bytes += bytes;
    }
    if (st != TCLOD_OK || stream_log_init(&g, &w, frames) != 0) {
        fprintf(stderr, "tclod_bench: stream: setting up failed: %s\n",
                tclod_status_string(st != TCLOD_OK ? st : TCLOD_ERR_NOMEM));
        world_scene_free(&w);
        free(times);
        return 1;
    }
    memset(&desc, 0, sizeof(desc));
    desc.max_requests = STREAM_SLOTS;
    desc.memory_budget = opt_memory * total_bytes;
    desc.bytes_in_flight = 0.0;
    /* the random scene's budget */
    visible = bench_world_visible(&w);
    budget = (double)visible * bench_world_level1_cost(&w);
    fprintf(stderr,
            "tclod_bench: stream %u objects: %u nodes (%u groups), built in %.0f ms; "
            "%lu objects in view, budget %.3f ms; %.4g bytes in all, memory budget %.4g, "
            "%u loads per frame\n",
            objects, w.node_count, w.group_count, (bench_now_us() - t0) / 1000.0, visible, budget,
            total_bytes, desc.memory_budget, STREAM_SLOTS);
    for (k = 0; k < STREAM_MODES && rc == 0; ++k) {
        int m = run_order[k];
        /* warm_resident_only replays what warm_stream did: warm_stream runs for either */
        int wanted =
            stream_wanted(m) || (m == STREAM_STREAM && stream_wanted(STREAM_RESIDENT_ONLY));
        if (!wanted || (m == STREAM_RESIDENT_ONLY && !ran[STREAM_STREAM]))
            continue;
        if (m == STREAM_FLIPS)
            rc = stream_reset(&w, 1) || run_flips(&w, &rows[m]);
        else
            rc = stream_reset(&w, m == STREAM_PLAIN) ||
                 run_stream(&w, m, &desc, budget, frames, times, &g, &rows[m]);
        ran[m] = rc == 0;
        if (rc == 0 && m == STREAM_RESIDENT_ONLY) {
            /* the plan's time, frame by frame: the same selections on the same residency */
            diff = (double *)malloc(frames * sizeof(*diff));
            if (diff) {
                unsigned long f;
                for (f = 0; f < frames; ++f)
                    diff[f] = g.times[f] - g.replay[f];
                bench_sort(diff, frames);
            }
        }
    }
    for (k = 0; k < STREAM_MODES && rc == 0; ++k)
        if (ran[k] && stream_wanted(k))
            print_row("stream", k == STREAM_FLIPS ? "none" : "greedy", stream_modes[k],
                      (unsigned long)objects, (unsigned long)w.node_count, budget, visible,
                      &rows[k]);
    if (rc == 0 && ran[STREAM_FLIPS] && ran[STREAM_PLAIN] && ran[STREAM_STREAM] &&
        ran[STREAM_RESIDENT_ONLY])
        fprintf(stderr,
                "summary: scene=stream objects=%u flip_ns_median=%.2f warm_us_median=%.2f "
                "stream_us_median=%.2f stream_ratio=%.3f resident_only_us_median=%.2f "
                "plan_us_median=%.2f requests_per_frame=%.2f evictions_per_frame=%.2f\n",
                objects, rows[STREAM_FLIPS].change_ns, rows[STREAM_PLAIN].median_us,
                rows[STREAM_STREAM].median_us,
                rows[STREAM_PLAIN].median_us > 0.0
                    ? rows[STREAM_STREAM].median_us / rows[STREAM_PLAIN].median_us
                    : 0.0,
                rows[STREAM_RESIDENT_ONLY].median_us,
                diff ? bench_median(diff, frames) : (double)NAN, rows[STREAM_STREAM].requests,
                rows[STREAM_STREAM].evictions);
    free(diff);
    stream_log_free(&g);
    world_scene_free(&w);
    free(times);
    return rc;
}

/* Mean number of smooth objects in view over 16 points of the thesis loop. */
static unsigned long thesis_mean_visible(const thesis_scene *t) {
    double sum = 0.0;
    int i;
    for (i = 0; i < 16; ++i) {
        tclod_view view;
        thesis_camera_at(t, (double)i / 16.0, &view);
        sum += (double)thesis_visible_smooth(t, &view);
    }
    return (unsigned long)(sum / 16.0 + 0.5);
}

/* The thesis rows: split and flat with the default, preconditioned smooth steps,
 * then split with the papers' plain gradient steps (smooth_precondition 0). */
static int bench_thesis(int quick, unsigned long frames, double theta) {
    thesis_desc d;
    thesis_scene t;
    tclod_status st;
    unsigned long visible, views, split_frames;
    double *times, t0 = bench_now_us();
    int mode, rc = 0;

    split_frames = quick && frames > THESIS_QUICK_FRAMES ? THESIS_QUICK_FRAMES : frames;
    views = quick ? THESIS_QUICK_VIEWS : THESIS_VIEWS;
    if (views > split_frames)
        views = split_frames;
    split_frames -= split_frames % views; /* whole cycles: every view weighs the same */
    times = (double *)malloc(split_frames * sizeof(*times));
    if (!times) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        return 1;
    }
    thesis_desc_default(&d);
    d.alloc = &scene_alloc;
    st = thesis_build(&d, &t);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_bench: building the thesis scene failed: %s\n",
                tclod_status_string(st));
        free(times);
        return 1;
    }
    visible = thesis_mean_visible(&t);
    fprintf(stderr,
            "tclod_bench: thesis: %u terrain nodes, %u trees in %u smooth objects, built in "
            "%.0f ms; %lu smooth objects in view, budget %.3f ms\n",
            t.node_count, t.tree_count, t.smooth_count, (bench_now_us() - t0) / 1000.0, visible,
            THESIS_BUDGET_MS);
    for (mode = 0; mode < 3; ++mode) {
        static const char *const names[3] = {"split", "flat", "split_gradient"};
        bench_row row;
        int split = mode != 1, precondition = mode != 2;
        unsigned long n = split ? split_frames : views;
        if (!row_wanted(solver_name(TCLOD_SOLVER_MIXED), names[mode]))
            continue;
        if (run_thesis(&t, split, precondition, theta, THESIS_BUDGET_MS, n, views, times, &row) !=
            0) {
            rc = 1;
            break;
        }
        print_row("thesis", solver_name(TCLOD_SOLVER_MIXED), names[mode],
                  (unsigned long)t.smooth_count, (unsigned long)t.node_count, THESIS_BUDGET_MS,
                  visible, &row);
    }
    thesis_scene_free(&t);
    free(times);
    return rc;
}

/* ---- drift: benefits that change under a still camera ---------------------------- */

/* The drift scene: DRIFT_OBJECTS chains (default) of DRIFT_LEVELS levels without
 * bounds, selected with no view, whose every node's benefit takes a random step of
 * up to +-5 % per frame (a walk kept within [1/4, 4] of where it began). Level k of
 * chain i is worth v_i (1 - 2^-(k+1)) at first (diminishing returns) and costs
 * c_i 2^k; the budget buys every chain's level 1. Cold and warm (and warm_batch)
 * selectors solve the same frames. */
#define DRIFT_OBJECTS 1000u
#define DRIFT_LEVELS 4u
#define DRIFT_SEED 0x6472696674ull
#define DRIFT_STEP 0.05

typedef struct drift_scene {
    tclod_scene *scene;
    uint32_t nodes;
    double *base, *factor, *cost;
    uint64_t rng;
} drift_scene;

static double drift_benefit(void *user, const tclod_query *q) {
    const drift_scene *d = (const drift_scene *)user;
    return d->base[q->id] * d->factor[q->id];
}

static double drift_cost(void *user, const tclod_query *q) {
    return ((const drift_scene *)user)->cost[q->id];
}

static void drift_benefit_batch(void *user, const tclod_batch *b, double *out) {
    const drift_scene *d = (const drift_scene *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i)
        out[i] = d->base[b->ids[i]] * d->factor[b->ids[i]];
}

static void drift_cost_batch(void *user, const tclod_batch *b, double *out) {
    const drift_scene *d = (const drift_scene *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i)
        out[i] = d->cost[b->ids[i]];
}

static void drift_free(drift_scene *d) {
    tclod_scene_destroy(d->scene);
    free(d->base);
    free(d->factor);
    free(d->cost);
    memset(d, 0, sizeof(*d));
}

/* Builds the chains; returns their budget, or -1 (out of memory). */
static double drift_build(drift_scene *d, uint32_t objects) {
    uint32_t i, k, n = objects * DRIFT_LEVELS;
    double budget = 0.0;
    memset(d, 0, sizeof(*d));
    d->rng = DRIFT_SEED;
    d->base = (double *)malloc(n * sizeof(double));
    d->factor = (double *)malloc(n * sizeof(double));
    d->cost = (double *)malloc(n * sizeof(double));
    if (!d->base || !d->factor || !d->cost ||
        tclod_scene_create(&scene_alloc, &d->scene) != TCLOD_OK) {
        drift_free(d);
        return -1.0;
    }
    for (i = 0; i < objects; ++i) {
        double v = 1.0 + 9.0 * (double)(churn_next(&d->rng) >> 11) / 9007199254740992.0;
        double c = 0.01 + 0.09 * (double)(churn_next(&d->rng) >> 11) / 9007199254740992.0;
        tclod_id parent = TCLOD_NONE, id;
        for (k = 0; k < DRIFT_LEVELS; ++k) {
            if (tclod_scene_add_node(d->scene, parent, NULL, &id) != TCLOD_OK) {
                drift_free(d);
                return -1.0;
            }
            d->base[id] = v * (1.0 - ldexp(1.0, -(int)k - 1));
            d->factor[id] = 1.0;
            d->cost[id] = c * ldexp(1.0, (int)k);
            if (k == 1)
                budget += d->cost[id];
            parent = id;
        }
    }
    d->nodes = n;
    return budget;
}

/* One frame's drift: every node's factor takes a step in [-5 %, +5 %]. */
static void drift_step(drift_scene *d) {
    uint32_t i;
    for (i = 0; i < d->nodes; ++i) {
        double u = (double)(churn_next(&d->rng) >> 11) / 9007199254740992.0;
        double f = d->factor[i] * (1.0 + DRIFT_STEP * (2.0 * u - 1.0));
        d->factor[i] = f < 0.25 ? 0.25 : (f > 4.0 ? 4.0 : f);
    }
}

enum { DRIFT_COLD, DRIFT_WARM, DRIFT_BATCH, DRIFT_MODES };
static const char *const drift_modes[DRIFT_MODES] = {"cold", "warm", "warm_batch"};

static int bench_drift(uint32_t objects, unsigned long frames) {
    drift_scene d;
    tclod_selector *sel[DRIFT_MODES] = {NULL, NULL, NULL};
    bench_row rows[DRIFT_MODES];
    double *times[DRIFT_MODES], sum_us[DRIFT_MODES], budget, ratio_sum = 0.0, ratio_min = 1e300;
    unsigned long f, total = frames + WARMUP_FRAMES, fallbacks = 0;
    int k, ran = 0, rc = 0;
    budget = drift_build(&d, objects);
    mem_row_begin();
    memset(rows, 0, sizeof rows);
    memset(sum_us, 0, sizeof sum_us);
    for (k = 0; k < DRIFT_MODES; ++k)
        times[k] = (double *)malloc(frames * sizeof(double));
    for (k = 0; k < DRIFT_MODES && budget >= 0.0; ++k) {
        tclod_selector_desc sd;
        if (!row_wanted("greedy", drift_modes[k]))
            continue; /* --mode: this selector neither runs nor prints */
        tclod_selector_desc_default(&sd);
        sd.callbacks.benefit = drift_benefit;
        sd.callbacks.cost = drift_cost;
        if (k == DRIFT_BATCH) {
            sd.callbacks.benefit_batch = drift_benefit_batch;
            sd.callbacks.cost_batch = drift_cost_batch;
        }
        sd.callbacks.user = &d;
        sd.cold_start = k == DRIFT_COLD;
        if (!times[k] || tclod_selector_create(d.scene, &sd, &selector_alloc, &sel[k]) != TCLOD_OK)
            budget = -1.0;
    }
    if (budget < 0.0) {
        fprintf(stderr, "tclod_bench: out of memory\n");
        rc = 1;
    }
    for (f = 0; f < total && rc == 0; ++f) {
        double benefit[DRIFT_MODES];
        drift_step(&d);
        for (k = 0; k < DRIFT_MODES && rc == 0; ++k) {
            solve_call call;
            double us;
            if (!sel[k])
                continue;
            memset(&call, 0, sizeof(call));
            call.method = METHOD_GREEDY;
            call.sel = sel[k];
            call.frame.budget = budget;
            us = solve_frame(&call, f);
            if (call.status != TCLOD_OK || call.stats.cost > budget) {
                fprintf(stderr, "tclod_bench: drift: %s select failed or over budget\n",
                        drift_modes[k]);
                rc = 1;
                break;
            }
            benefit[k] = call.stats.benefit;
            if (f < WARMUP_FRAMES)
                continue;
            times[k][f - WARMUP_FRAMES] = us;
            sum_us[k] += us;
            add_stats(&rows[k], &call.stats, 0);
            if (k == DRIFT_WARM)
                fallbacks += (call.stats.notes & TCLOD_NOTE_COLD_FALLBACK) != 0;
        }
        if (rc == 0 && f >= WARMUP_FRAMES && sel[DRIFT_COLD] && sel[DRIFT_WARM]) {
            double r = benefit[DRIFT_WARM] / benefit[DRIFT_COLD];
            ratio_sum += r;
            if (r < ratio_min)
                ratio_min = r;
        }
    }
    for (k = 0; k < DRIFT_MODES && rc == 0; ++k)
        ran += sel[k] != NULL;
    for (k = 0; k < DRIFT_MODES && rc == 0; ++k) {
        if (!sel[k])
            continue;
        mem_row_end(&rows[k]);
        rows[k].selector_bytes /= (double)ran; /* the selectors lived together */
        finish_row(&rows[k], times[k], frames, sum_us[k]);
        print_row("drift", "greedy", drift_modes[k], (unsigned long)objects,
                      (unsigned long)d.nodes, budget, (unsigned long)objects, &rows[k]);
    }
    if (rc == 0 && sel[DRIFT_COLD] && sel[DRIFT_WARM])
        fprintf(stderr,
                "summary: scene=drift objects=%u cold_us_median=%.2f warm_us_median=%.2f "
                "time_ratio=%.3f benefit_ratio=%.5f benefit_ratio_min=%.5f "
                "warm_batch_us_median=%.2f cold_fallbacks=%lu\n",
                (unsigned)objects, rows[DRIFT_COLD].median_us, rows[DRIFT_WARM].median_us,
                rows[DRIFT_WARM].median_us / rows[DRIFT_COLD].median_us, ratio_sum / (double)frames,
                ratio_min, rows[DRIFT_BATCH].median_us, fallbacks);
    for (k = 0; k < DRIFT_MODES; ++k) {
        tclod_selector_destroy(sel[k]);
        free(times[k]);
    }
    drift_free(&d);
    return rc;
}

/* ---- absorb: costs a running sum absorbs ------------------------------------------- */

/* The absorb scene's objects (--objects N overrides), frames per row (--quick: fewer) and
 * its rows' limits: the frame's solve_seconds, the step's slice and the scheduler's. */
#define ABSORB_OBJECTS 40000u
#define ABSORB_FRAMES 5ul
#define ABSORB_QUICK_FRAMES 2ul
#define ABSORB_SOLVE_SECONDS 0.05
#define ABSORB_STEP_SECONDS 0.01
#define ABSORB_SLICE_SECONDS 0.002
/* Scheduler updates per timed frame of a scheduler row: one interval of 0.5 s at 60 Hz,
 * so that every timed frame lands a selection. */
#define ABSORB_UPDATES 30ul

/* One root of cost 2^53 (id 0) and N roots of cost 1 (benefit 1), each with a child of
 * cost 2 (benefit 2): with the budget 2^53 the small roots' costs are absorbed, and each
 * increment (Δc 1) seems to fit a running sum that stays at 2^53. */
typedef struct absorb_scene {
    tclod_scene *scene;
    double *benefit, *cost;
    uint32_t nodes;
} absorb_scene;

static double absorb_benefit(void *user, const tclod_query *q) {
    return ((const absorb_scene *)user)->benefit[q->id];
}

static double absorb_cost(void *user, const tclod_query *q) {
    return ((const absorb_scene *)user)->cost[q->id];
}

static void absorb_free(absorb_scene *a) {
    tclod_scene_destroy(a->scene);
    free(a->benefit);
    free(a->cost);
}

static tclod_status absorb_build(absorb_scene *a, uint32_t objects) {
    tclod_status st;
    uint32_t i;
    memset(a, 0, sizeof(*a));
    a->nodes = 2u * objects + 1u;
    a->benefit = (double *)malloc(a->nodes * sizeof(double));
    a->cost = (double *)malloc(a->nodes * sizeof(double));
    if (!a->benefit || !a->cost)
        return TCLOD_ERR_NOMEM;
    st = tclod_scene_create(&scene_alloc, &a->scene);
    for (i = 0; i < a->nodes && st == TCLOD_OK; ++i) {
        /* ids 1, 3, 5 ... are the small roots, 2, 4, 6 ... their children */
        tclod_id parent = i == 0 || i % 2u == 1u ? TCLOD_NONE : i - 1u, id;
        st = tclod_scene_add_node(a->scene, parent, NULL, &id);
        a->benefit[i] = i == 0 || i % 2u == 1u ? 1.0 : 2.0;
        a->cost[i] = i == 0 ? ldexp(1.0, 53) : (i % 2u == 1u ? 1.0 : 2.0);
    }
    return st;
}

/* The longest call of one timed frame of an absorb row: mode 0 one tclod_select with
 * solve_seconds, 1 tclod_select_step slices, 2 the scheduler's updates of one interval
 * (*now advances). Checks the budget; returns 1 on an error (reported). */
static int absorb_frame(absorb_scene *a, int mode, tclod_selector *sel, tclod_scheduler *sch,
                        double *now, double *longest, tclod_stats *stats, size_t *cut) {
    const double budget = ldexp(1.0, 53);
    tclod_status st = TCLOD_OK;
    const tclod_id *ids = NULL;
    double t0, cost = 0.0;
    size_t i, n = 0;
    *longest = 0.0;
    memset(stats, 0, sizeof(*stats));
    if (mode == 2) {
        tclod_view view;
        tclod_scheduler_stats ss;
        const tclod_draw *draws;
        unsigned long u;
        memset(&view, 0, sizeof(view));
        view.forward[2] = -1.0f;
        view.up[1] = 1.0f;
        view.fov_y = 1.0f;
        view.aspect = 1.0f;
        view.near_z = 0.1f;
        view.far_z = 1000.0f;
        view.viewport_height = 1000.0f;
        for (u = 0; u < ABSORB_UPDATES && st == TCLOD_OK; ++u) {
            t0 = bench_now_us();
            st = tclod_scheduler_update(sch, *now, &view, budget, ABSORB_SLICE_SECONDS);
            t0 = bench_now_us() - t0;
            *longest = t0 > *longest ? t0 : *longest;
            *now += 1.0 / 60.0;
        }
        if (st == TCLOD_OK)
            st = tclod_scheduler_draws(sch, &draws, &n);
        if (st == TCLOD_OK)
            st = tclod_scheduler_get_stats(sch, &ss);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: absorb: a scheduler update failed: %s\n",
                    tclod_status_string(st));
            return 1;
        }
        for (i = 0; i < n; ++i)
            cost += a->cost[draws[i].fine];
        stats->cost = ss.draw_cost;
        stats->benefit = ss.selection_benefit;
        *cut = n;
    } else {
        tclod_frame fr;
        memset(&fr, 0, sizeof(fr));
        fr.budget = budget;
        fr.solve_seconds = mode == 0 ? ABSORB_SOLVE_SECONDS : 0.0;
        if (mode == 0) {
            t0 = bench_now_us();
            st = tclod_select(sel, &fr, stats);
            *longest = bench_now_us() - t0;
        } else {
            int done = 0;
            st = tclod_select_begin(sel, &fr);
            while (st == TCLOD_OK && !done) {
                t0 = bench_now_us();
                st = tclod_select_step(sel, ABSORB_STEP_SECONDS, 0, &done, stats);
                t0 = bench_now_us() - t0;
                *longest = t0 > *longest ? t0 : *longest;
            }
        }
        if (st == TCLOD_OK)
            st = tclod_selector_cut(sel, &ids, &n);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: absorb: tclod_select failed: %s\n",
                    tclod_status_string(st));
            return 1;
        }
        for (i = 0; i < n; ++i)
            cost += a->cost[ids[i]];
        *cut = n;
    }
    if (cost > budget || stats->cost > budget) {
        fprintf(stderr, "tclod_bench: absorb: budget exceeded: cost %.17g > budget %.17g\n", cost,
                budget);
        return 1;
    }
    return 0;
}

/* The absorb rows: for each solver, cold selections under solve_seconds (mode
 * limited), in tclod_select_step slices (step: the longest step of a solve) and by a
 * scheduler in slices (scheduler: the longest update of an interval, which lands a
 * selection). Times are of the longest call of each timed frame. */
static int bench_absorb(uint32_t objects, unsigned long frames) {
    static const char *const modes[3] = {"limited", "step", "scheduler"};
    absorb_scene a;
    tclod_status st = absorb_build(&a, objects);
    double *times = (double *)malloc(frames * sizeof(double));
    int k, mode, rc = 0;
    if (st != TCLOD_OK || !times) {
        fprintf(stderr, "tclod_bench: building the absorb scene failed: %s\n",
                tclod_status_string(st != TCLOD_OK ? st : TCLOD_ERR_NOMEM));
        absorb_free(&a);
        free(times);
        return 1;
    }
    fprintf(stderr,
            "tclod_bench: absorb: %u objects, %u nodes, budget 2^53; limits %.3f s (limited), "
            "%.3f s steps, %.3f s scheduler slices\n",
            objects, a.nodes, ABSORB_SOLVE_SECONDS, ABSORB_STEP_SECONDS, ABSORB_SLICE_SECONDS);
    for (k = 0; k < 3 && rc == 0; ++k)
        for (mode = 0; mode < 3 && rc == 0; ++mode) {
            tclod_selector_desc sd;
            tclod_scheduler_desc dd;
            tclod_selector *sel = NULL;
            tclod_scheduler *sch = NULL;
            bench_row row;
            double sum_us = 0.0, now = 0.0;
            unsigned long f;
            if (!row_wanted(solver_name(method_solvers[k]), modes[mode]))
                continue;
            memset(&row, 0, sizeof(row));
            mem_row_begin();
            tclod_selector_desc_default(&sd);
            sd.solver = method_solvers[k];
            sd.cold_start = 1; /* every frame the cold solve */
            sd.callbacks.benefit = absorb_benefit;
            sd.callbacks.cost = absorb_cost;
            sd.callbacks.smooth_benefit = bench_no_smooth;
            sd.callbacks.smooth_cost = bench_no_smooth;
            sd.callbacks.user = &a;
            tclod_scheduler_desc_default(&dd);
            st = mode == 2 ? tclod_scheduler_create(a.scene, &sd, &dd, &selector_alloc, &sch)
                           : tclod_selector_create(a.scene, &sd, &selector_alloc, &sel);
            if (st != TCLOD_OK) {
                fprintf(stderr, "tclod_bench: absorb: creating a %s failed: %s\n",
                        mode == 2 ? "scheduler" : "selector", tclod_status_string(st));
                rc = 1;
                break;
            }
            for (f = 0; f < frames + 1u && rc == 0; ++f) {
                tclod_stats stats;
                size_t cut;
                double longest;
                /* frame 0 warms up (grows the buffers; the scheduler's first update
                 * selects at once) */
                rc = absorb_frame(&a, mode, sel, sch, &now, &longest, &stats, &cut);
                if (rc != 0 || f == 0)
                    continue;
                times[f - 1u] = longest;
                sum_us += longest;
                add_stats(&row, &stats, cut);
            }
            tclod_selector_destroy(sel);
            tclod_scheduler_destroy(sch);
            if (rc != 0)
                break;
            mem_row_end(&row);
            finish_row(&row, times, frames, sum_us);
            print_row("absorb", solver_name(method_solvers[k]), modes[mode], (unsigned long)objects,
                      (unsigned long)a.nodes, ldexp(1.0, 53), (unsigned long)objects + 1u, &row);
        }
    absorb_free(&a);
    free(times);
    return rc;
}

static void usage(FILE *out) {
    fprintf(out,
            "usage: tclod_bench [--quick] [--scene NAME] [--theta X] [--objects N] [--frames N]\n"
            "                   [--solver NAME] [--mode NAME] [--lookahead N] [--restarts N]\n"
            "                   [--memory F] [--benefit-work N] [--help]\n"
            "\n"
            "Times tclod_select on random worlds of 10^3 ... 10^6 objects x 4 levels and on\n"
            "the flyover scene, cold (from the roots) and warm (from the previous frame), and\n"
            "the mixed solver on the thesis scene (1.4 million trees) with and without\n"
            "variable splitting, and prints CSV on stdout (progress on stderr). The random and\n"
            "flyover rows also time the baselines engines use (threshold LOD with a tuned or a\n"
            "fixed bias, a priority queue that stops at the first misfit, a flat per-object\n"
            "greedy) on the same frames and budgets. The greedy's random and flyover rows\n"
            "come cold, warm, warm_floor (the frontier's evaluation alone), warm_batch (the\n"
            "batch callbacks) and warm_parallel (the batch callbacks over 2 workers of a\n"
            "task_pool; column workers).\n"
            "\n"
            "The drift scene (10^3 chains of 4 levels without bounds, no view, every\n"
            "benefit a random step of up to +-5%% a frame) times cold, warm and warm_batch\n"
            "selectors on the same frames and prints\n"
            "  summary: scene=drift objects=N cold_us_median=A warm_us_median=B\n"
            "           time_ratio=B/A benefit_ratio=R benefit_ratio_min=M\n"
            "           warm_batch_us_median=C cold_fallbacks=F\n"
            "on stderr (R, M: the mean and the least over the frames of warm's benefit over\n"
            "cold's; F: warm solves that fell back to cold ones).\n"
            "\n"
            "The churn scene edits a random world of 10^4 objects between frames (every\n"
            "frame 1%% of the objects move a few metres, 0.1%% are removed and 0.1%% added,\n"
            "from a fixed seed) and times the greedy solver's warm select call (mode warm;\n"
            "the edits' time in columns edits, edit_us, edit_p99_us) against the same\n"
            "frames without edits on the world as built (warm_noedit) and on the world as\n"
            "the edits left it (warm_edited); it prints\n"
            "  summary: scene=churn objects=N warm_us_median=A warm_noedit_us_median=B\n"
            "           ratio=A/B edit_us_median=E\n"
            "on stderr (one line).\n"
            "\n"
            "The absorb scene (one root of cost 2^53, 4*10^4 roots of cost 1 with children\n"
            "of cost 2, budget 2^53: costs a running sum absorbs) times every solver under\n"
            "solve_seconds 0.05 (mode limited), in tclod_select_step slices of 0.01 s (step:\n"
            "the longest step) and in a scheduler's 2 ms slices (scheduler: the longest\n"
            "update).\n"
            "\n");
    fprintf(out, "The stream scene measures what streaming costs the library on a random world of\n"
                 "10^4 objects whose every node takes 32 bytes per triangle: 10^6 residency\n"
                 "changes on random nodes (mode flips, ns per change in column change_ns), and\n"
                 "the greedy solver's warm select with every node resident and no stream desc\n"
                 "(warm_plain), streamed from the roots with the previous select's evictions\n"
                 "freed and 20 of its requests made resident before every frame (warm_stream:\n"
                 "max_requests 20, memory budget half of all bytes, the plan included), and the\n"
                 "same residency without the plan (warm_resident_only); it prints\n"
                 "  summary: scene=stream objects=N flip_ns_median=A warm_us_median=B\n"
                 "           stream_us_median=C stream_ratio=C/B resident_only_us_median=D\n"
                 "           plan_us_median=P requests_per_frame=R evictions_per_frame=E\n"
                 "on stderr (one line; P: the median of warm_stream less warm_resident_only,\n"
                 "frame by frame).\n"
                 "\n");
    fprintf(out,
            "  --quick       10^3, 10^4 and 10^5 objects only (10^5 with a quarter of the\n"
            "                frames), fewer thesis frames (under a minute), churn: at most\n"
            "                50 frames, stream and drift: at most 50 frames\n"
            "  --scene NAME  one scene only: random, flyover, churn, absorb, stream, drift or\n"
            "                thesis\n"
            "  --theta X     thesis rows: split_threshold X (default: the library's)\n"
            "  --objects N   one random world of N objects (and the other scenes) instead;\n"
            "                churn and stream: their world's objects (default 10^4); absorb:\n"
            "                its small roots (default 4*10^4)\n"
            "  --frames N    timed frames per configuration (default 200; 10^6 objects, and\n"
            "                10^5 with --quick: N/4;\n"
            "                thesis: 20 views (--quick 10), flat times each once, split\n"
            "                cycles through them, at most 40 frames with --quick)\n"
            "  --solver NAME only the rows of one solver or baseline: greedy, mixed,\n"
            "                robin_hood, threshold_tuned, threshold_fixed, pq_stop, flat\n"
            "  --mode NAME   only the rows of one mode: cold, warm, warm_floor,\n"
            "                warm_batch, warm_parallel (drift: cold, warm, warm_batch, only\n"
            "                that selector runs, the summary needs cold and warm; thesis:\n"
            "                split, flat, split_gradient; churn: warm, warm_noedit,\n"
            "                warm_edited; the summary needs warm and warm_noedit; absorb:\n"
            "                limited, step, scheduler; stream: flips, warm_plain,\n"
            "                warm_stream, warm_resident_only, the summary needs all four;\n"
            "                --solver does not filter flips)\n"
            "  --lookahead N random, flyover, churn and stream rows: the greedy and mixed\n"
            "                solvers' tclod_selector_desc.greedy.lookahead (default: the\n"
            "                library's, 0)\n"
            "  --restarts N  random, flyover, churn and stream rows:\n"
            "                tclod_selector_desc.greedy.restarts (default: the library's, 32)\n"
            "  --memory F    stream: the memory budget as a fraction F in (0, 1] of all the\n"
            "                nodes' bytes (default 0.5)\n"
            "  --benefit-work N\n"
            "                random and flyover rows: every benefit the callbacks compute\n"
            "                first spends N rounds of a hash it throws away (a multiply\n"
            "                and an add each), as a host whose evaluation is dear\n"
            "                (default 0); the values and the selections are the same\n"
            "  --help        print this text and exit\n");
}

/* Parses the value of option opt, an integer in [lo, hi], into *out; reports
 * and returns 0 when it is missing or out of range. */
static int parse_count(int argc, char **argv, int *i, unsigned long lo, unsigned long hi,
                       unsigned long *out) {
    const char *opt = argv[*i];
    char *end;
    if (*i + 1 >= argc) {
        fprintf(stderr, "tclod_bench: %s needs a value\n", opt);
        return 0;
    }
    errno = 0;
    *out = strtoul(argv[++*i], &end, 10);
    if (errno != 0 || *end != '\0' || argv[*i][0] == '-' || argv[*i][0] == '\0' || *out < lo ||
        *out > hi) {
        fprintf(stderr, "tclod_bench: %s expects an integer in [%lu, %lu], got '%s'\n", opt, lo, hi,
                argv[*i]);
        return 0;
    }
    return 1;
}

int main(int argc, char **argv) {
    static const uint32_t sizes[] = {1000u, 10000u, 100000u, 1000000u};
    uint32_t only_objects = 0;
    unsigned long frames = 200;
    const char *only_scene = NULL;
    double theta = -1.0;
    int quick = 0, i;
    size_t k;
    double t_start = bench_now_us();
    tclod_selector_desc defaults;

    scene_alloc = bench_counting_allocator(&scene_mem);
    selector_alloc = bench_counting_allocator(&selector_mem);
    tclod_selector_desc_default(&defaults);
    opt_lookahead = defaults.greedy.lookahead;
    opt_restarts = (unsigned long)defaults.greedy.restarts;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--scene") == 0) {
            if (i + 1 >= argc) {
                fprintf(stderr, "tclod_bench: --scene needs a value\n");
                return 2;
            }
            only_scene = argv[++i];
            if (strcmp(only_scene, "random") != 0 && strcmp(only_scene, "flyover") != 0 &&
                strcmp(only_scene, "churn") != 0 && strcmp(only_scene, "thesis") != 0 &&
                strcmp(only_scene, "absorb") != 0 && strcmp(only_scene, "stream") != 0 &&
                strcmp(only_scene, "drift") != 0) {
                fprintf(stderr,
                        "tclod_bench: unknown scene '%s' (scenes: random, flyover, churn, "
                        "absorb, stream, thesis)\n",
                        only_scene);
                return 2;
            }
        } else if (strcmp(argv[i], "--objects") == 0) {
            unsigned long v;
            if (!parse_count(argc, argv, &i, 1ul, 10000000ul, &v))
                return 2;
            only_objects = (uint32_t)v;
        } else if (strcmp(argv[i], "--lookahead") == 0) {
            if (!parse_count(argc, argv, &i, 0ul, TCLOD_MAX_LOOKAHEAD, &opt_lookahead))
                return 2;
        } else if (strcmp(argv[i], "--restarts") == 0) {
            if (!parse_count(argc, argv, &i, 0ul, TCLOD_MAX_RESTARTS, &opt_restarts))
                return 2;
        } else if (strcmp(argv[i], "--benefit-work") == 0) {
            if (!parse_count(argc, argv, &i, 0ul, 1000000ul, &opt_benefit_work))
                return 2;
        } else if (strcmp(argv[i], "--solver") == 0 || strcmp(argv[i], "--mode") == 0) {
            static const char *const modes[] = {
                "cold",       "warm",         "warm_floor",     "warm_noedit", "warm_edited",
                "split",      "flat",         "split_gradient", "limited",     "step",
                "scheduler",  "flips",        "warm_plain",     "warm_stream", "warm_resident_only",
                "warm_batch", "warm_parallel"};
            int is_solver = strcmp(argv[i], "--solver") == 0, known = 0, k2;
            if (i + 1 >= argc) {
                fprintf(stderr, "tclod_bench: %s needs a value\n", argv[i]);
                return 2;
            }
            ++i;
            if (is_solver) {
                for (k2 = 0; k2 < METHOD_COUNT; ++k2)
                    known |= strcmp(argv[i], method_names[k2]) == 0;
                only_solver = argv[i];
            } else {
                for (k2 = 0; k2 < (int)(sizeof(modes) / sizeof(modes[0])); ++k2)
                    known |= strcmp(argv[i], modes[k2]) == 0;
                only_mode = argv[i];
            }
            if (!known) {
                fprintf(stderr, "tclod_bench: unknown %s '%s' (try --help)\n",
                        is_solver ? "solver" : "mode", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--theta") == 0) {
            char *end;
            if (i + 1 >= argc) {
                fprintf(stderr, "tclod_bench: --theta needs a value\n");
                return 2;
            }
            errno = 0;
            theta = strtod(argv[++i], &end);
            if (errno != 0 || *end != '\0' || !(theta >= 0.0) || isinf(theta)) {
                fprintf(stderr, "tclod_bench: --theta expects a number >= 0, got '%s'\n", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--memory") == 0) {
            char *end;
            if (i + 1 >= argc) {
                fprintf(stderr, "tclod_bench: --memory needs a value\n");
                return 2;
            }
            errno = 0;
            opt_memory = strtod(argv[++i], &end);
            if (errno != 0 || *end != '\0' || !(opt_memory > 0.0 && opt_memory <= 1.0)) {
                fprintf(stderr, "tclod_bench: --memory expects a number in (0, 1], got '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--frames") == 0) {
            if (!parse_count(argc, argv, &i, 4ul, 1000000ul, &frames))
                return 2;
        } else {
            fprintf(stderr, "tclod_bench: unknown option '%s' (try --help)\n", argv[i]);
            return 2;
        }
    }

    fprintf(stderr, "tclod_bench: libtclod %s, %s run, %lu frames per configuration\n",
            tclod_version_string(), quick ? "quick" : "full", frames);
    print_header();

    for (k = 0; k < sizeof(sizes) / sizeof(sizes[0]); ++k) {
        world_random_desc d;
        world_scene w;
        tclod_status st;
        uint32_t objects = only_objects ? only_objects : sizes[k];
        /* the largest worlds get a quarter of the frames: 10^6 objects, and 10^5 with --quick */
        unsigned long visible,
            n_frames = objects >= 1000000u || (quick && objects >= 100000u) ? frames / 4 : frames;
        double budget, selector_bytes = 0.0, t0 = bench_now_us();
        if (only_scene && strcmp(only_scene, "random") != 0)
            break;
        if (only_objects && k > 0)
            break;
        if (quick && objects > 100000u)
            break;
        world_random_desc_default(&d);
        d.objects = objects;
        d.alloc = &scene_alloc;
        st = world_build_random(&d, &w);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: building %u objects failed: %s\n", objects,
                    tclod_status_string(st));
            return 1;
        }
        w.benefit_work = (uint32_t)opt_benefit_work;
        visible = bench_world_visible(&w);
        budget = (double)visible * bench_world_level1_cost(&w);
        fprintf(stderr,
                "tclod_bench: random %u objects: %u nodes (%u groups), built in %.0f ms; "
                "%lu objects in view, budget %.3f ms\n",
                objects, w.node_count, w.group_count, (bench_now_us() - t0) / 1000.0, visible,
                budget);
        if (bench_scene("random", &w, budget, visible, n_frames, w.object_root, w.object_count,
                        &selector_bytes) != 0) {
            world_scene_free(&w);
            return 1;
        }
        /* the process's peak, the world's own arrays included; the library's part
         * in the last two figures */
        fprintf(stderr,
                "summary: scene=random objects=%u nodes=%u peak_rss_mb=%.1f "
                "selector_bytes_per_node=%.1f scene_bytes_per_node=%.1f\n",
                objects, w.node_count, bench_peak_rss_mb(),
                w.node_count ? selector_bytes / (double)w.node_count : 0.0,
                w.node_count ? (double)scene_mem.held / (double)w.node_count : 0.0);
        world_scene_free(&w);
    }

    if (!only_scene || strcmp(only_scene, "flyover") == 0) {
        world_flyover_desc d;
        world_scene w;
        tclod_status st;
        unsigned long visible;
        double selector_bytes = 0.0;
        world_flyover_desc_default(&d);
        d.alloc = &scene_alloc;
        st = world_build_flyover(&d, &w);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_bench: building the flyover failed: %s\n",
                    tclod_status_string(st));
            return 1;
        }
        w.benefit_work = (uint32_t)opt_benefit_work;
        visible = bench_world_visible(&w);
        if (bench_scene("flyover", &w, FLYOVER_BUDGET_MS, visible, frames, NULL, 0,
                        &selector_bytes) != 0) {
            world_scene_free(&w);
            return 1;
        }
        world_scene_free(&w);
    }

    if ((!only_scene || strcmp(only_scene, "churn") == 0) &&
        (row_wanted("greedy", "warm") || row_wanted("greedy", "warm_noedit") ||
         row_wanted("greedy", "warm_edited"))) {
        uint32_t objects = only_objects ? only_objects : CHURN_OBJECTS;
        /* frames as for a random world of that size, and few with --quick (CI) */
        unsigned long n_frames =
            objects >= 1000000u || (quick && objects >= 100000u) ? frames / 4 : frames;
        if (quick && n_frames > CHURN_QUICK_FRAMES)
            n_frames = CHURN_QUICK_FRAMES;
        if (bench_churn(objects, n_frames) != 0)
            return 1;
    }

    if ((!only_scene || strcmp(only_scene, "stream") == 0) &&
        (stream_wanted(STREAM_FLIPS) || stream_wanted(STREAM_PLAIN) ||
         stream_wanted(STREAM_STREAM) || stream_wanted(STREAM_RESIDENT_ONLY))) {
        uint32_t objects = only_objects ? only_objects : STREAM_OBJECTS;
        /* frames as for a random world of that size, and few with --quick (CI) */
        unsigned long n_frames =
            objects >= 1000000u || (quick && objects >= 100000u) ? frames / 4 : frames;
        if (quick && n_frames > STREAM_QUICK_FRAMES)
            n_frames = STREAM_QUICK_FRAMES;
        if (bench_stream(objects, n_frames) != 0)
            return 1;
    }

    if ((!only_scene || strcmp(only_scene, "drift") == 0) &&
        (!only_solver || strcmp(only_solver, "greedy") == 0) &&
        bench_drift(only_objects ? only_objects : DRIFT_OBJECTS,
                    quick && frames > CHURN_QUICK_FRAMES ? CHURN_QUICK_FRAMES : frames) != 0)
        return 1;

    if ((!only_scene || strcmp(only_scene, "absorb") == 0) &&
        bench_absorb(only_objects ? only_objects : ABSORB_OBJECTS,
                     quick ? ABSORB_QUICK_FRAMES : ABSORB_FRAMES) != 0)
        return 1;

    if ((!only_scene || strcmp(only_scene, "thesis") == 0) &&
        (!only_solver || strcmp(only_solver, "mixed") == 0) &&
        bench_thesis(quick, frames, theta) != 0)
        return 1;
    fprintf(stderr, "tclod_bench: done in %.1f s\n", (bench_now_us() - t_start) / 1e6);
    return 0;
}
