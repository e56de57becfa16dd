/*
 * baselines — the level-of-detail selection engines use today, for comparison with
 * libtclod's solvers on the same scenes, callbacks and budgets (not part of the library).
 *
 *  - Threshold LOD with one global bias (Unity's LODGroup with QualitySettings.lodBias,
 *    OpenSceneGraph's LOD/PagedLOD ranges, Godot's visibility ranges and mesh LOD
 *    threshold). Each node has a fixed switch size: it is refined while its triangles
 *    would look larger than a pixel across, i.e. while bias^2 * screen_area > triangles
 *    (screen_area in px^2). For a chain whose triangles grow 4x per level this switches
 *    levels at screen sizes that halve per level, the usual LODGroup set-up; the same
 *    rule drives group impostors and terrain patches (hierarchical LOD). The rule knows
 *    nothing of the budget:
 *      fixed  the bias stays what it was tuned to once (the first view a run sees);
 *      tuned  every frame, bisection on log2(bias) finds the largest bias whose selection
 *             fits the budget (BASELINE_BISECTION_STEPS passes over the visible tree).
 *  - Priority-queue refinement that stops at the first node that does not fit (Potree's
 *    point budget, the budget balancers of splat renderers): cut nodes are refined
 *    largest on screen first (the callbacks' benefit when there is no screen size), and
 *    the first refinement that would exceed the budget ends the frame.
 *  - Flat per-object greedy (Funkhouser and Sequin 1993): no hierarchy above the
 *    objects, so no group impostors; every object in view starts at its level 0 (the
 *    lowest-value objects are left out when those do not fit) and level steps are taken
 *    in falling benefit gained per cost, a step that does not fit being skipped.
 *
 * All three evaluate nodes lazily, with the same queries the library builds (screen
 * area from a frustum test and the projected bounding sphere, src/core/view.c), the view
 * set up once per frame, and each node's callbacks called at most once per frame.
 */
#ifndef BASELINES_H
#define BASELINES_H

#include <stddef.h>
#include <stdint.h>

#include <tclod/tclod.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bisection steps of the tuned threshold: log2(bias) in [-16, 16] to 2^-15. */
#define BASELINE_BISECTION_STEPS 20

/* The structure the baselines walk: a scene's hierarchies with children contiguous, plus
 * what the rules need per node. Built once per scene (not per frame). */
typedef struct baseline_scene {
    uint32_t count;        /* nodes */
    uint32_t *child_first; /* count + 1 offsets into children */
    tclod_id *children;    /* children of node n: child_first[n] .. child_first[n + 1] */
    tclod_id *roots;       /* roots in id order */
    uint32_t root_count;
    const float *bounds;    /* 4 per node (x, y, z, radius), or NULL; borrowed */
    const uint32_t *detail; /* triangles per node for the threshold rule, or NULL; borrowed */
    tclod_id *objects;      /* flat baseline: the first node (level 0) of every object */
    uint32_t object_count;  /* 0: the flat baseline does not apply */
} baseline_scene;

/* Builds the structure of scene s. bounds and detail (either may be NULL) are borrowed
 * and must outlive it. objects lists the level-0 nodes of the scene's objects (chains:
 * each node below has at most one child); NULL means every root, when every hierarchy
 * is a chain (otherwise the flat baseline does not apply). Returns TCLOD_ERR_ARG for a
 * NULL argument, TCLOD_ERR_NOMEM. */
tclod_status baseline_scene_init(baseline_scene *b, const tclod_scene *s, const float *bounds,
                                 const uint32_t *detail, const tclod_id *objects,
                                 uint32_t object_count);
void baseline_scene_free(baseline_scene *b);

/* What one baseline selection returned. ids point into the selector: valid until its
 * next call. */
typedef struct baseline_result {
    const tclod_id *ids; /* visible selected nodes, in result order */
    size_t n;
    double benefit, cost; /* summed over ids in that order */
    uint32_t evaluations; /* nodes whose callbacks were called */
    uint32_t iterations;  /* threshold: passes over the tree; others: heap pops */
    uint32_t refinements; /* nodes replaced by their children, levels stepped up */
    double bias;          /* threshold: the bias used */
} baseline_result;

typedef struct baseline_selector baseline_selector;

/* A selector over b with the host's callbacks (benefit and cost used; copied). */
tclod_status baseline_create(const baseline_scene *b, const tclod_callbacks *cb,
                             baseline_selector **out);
void baseline_destroy(baseline_selector *sel);

/* Threshold LOD at a given bias. Needs bounds, detail and a view; returns 0, or -1 when
 * it does not apply. */
int baseline_threshold(baseline_selector *sel, const tclod_view *view, double bias,
                       baseline_result *r);

/* Threshold LOD with the bias bisected to the budget; r->bias is the bias chosen. When
 * even the smallest bias does not fit, that selection is returned (over budget). */
int baseline_threshold_tuned(baseline_selector *sel, const tclod_view *view, double budget,
                             baseline_result *r);

/* Priority-queue refinement that stops at the first misfit. view may be NULL. */
int baseline_pq_stop(baseline_selector *sel, const tclod_view *view, double budget,
                     baseline_result *r);

/* Flat per-object greedy. Returns -1 when the scene has no objects list. */
int baseline_flat(baseline_selector *sel, const tclod_view *view, double budget,
                  baseline_result *r);

/* Benefit and cost of every node at a view, as the library's queries give them: a
 * culled node (benefit 0) gets cost 0, a bad benefit counts as 0 and a bad cost as
 * +inf. For references computed outside the timed selections. Not counted in any
 * result's evaluations. */
void baseline_values(baseline_selector *sel, const tclod_view *view, double *benefit, double *cost);

/* Visible roots whose hierarchy the selection ids[0..n) leaves partly or wholly
 * undrawn: a visible leaf is reached from the root through visible nodes none of which
 * is listed. benefit gives visibility (> 0) per node. */
uint32_t baseline_count_holes(baseline_selector *sel, const double *benefit, const tclod_id *ids,
                              size_t n);

#ifdef __cplusplus
}
#endif

#endif /* BASELINES_H */
