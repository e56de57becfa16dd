/*
 * world_scene — shared scene builders for the benchmark and the flyover example.
 *
 * Two worlds, one node model:
 *  - the random world: N objects at random on a square ground plane, each a chain
 *    of L discrete levels, grouped by a quadtree of group impostors so that a
 *    region outside the frustum collapses to one invisible node (docs/api.md);
 *  - the flyover world: a height-field terrain as a quadtree of patches plus
 *    thousands of buildings and trees, each a chain of discrete levels with its
 *    own root, and a closed camera loop over it.
 *
 * Both share one benefit/cost model, precomputed per node in structure-of-arrays
 * form so that the callbacks are a multiply and two loads:
 *   benefit = screen area (px²) × weight,   cost = ms_per_draw + ms_per_triangle × triangles.
 * The weights follow [GEO §4.2] (benefit = accuracy × projected size): object
 * level k has accuracy 1 − 2^−(k+1), group impostors less, a terrain patch at depth
 * d 2^(d − dmax) ([Thesis8 eq. 8.21]); the cost is linear in the triangles sent
 * plus a per-draw setup ([Thesis8 eq. 8.18, 8.19]; [GEO §4.2]). world_scene.c
 * explains the weights and why every chain shows diminishing returns.
 *
 * Not part of the library: no header of libtclod depends on this one.
 */
#ifndef WORLD_SCENE_H
#define WORLD_SCENE_H

#include <stdint.h>

#include <tclod/tclod.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What a node represents; world_scene.kind holds one per node. */
typedef enum world_kind {
    WORLD_KIND_GROUP = 0,  /* quadtree group impostor of the random world */
    WORLD_KIND_OBJECT = 1, /* level k of one object (a chain of levels) */
    WORLD_KIND_TERRAIN = 2 /* terrain quadtree patch */
} world_kind;

/* Render-time model shared by both worlds, in milliseconds. */
typedef struct world_cost_model {
    double ms_per_triangle; /* > 0; default 1e-6 (1 ns per triangle, ~1 Gtri/s) */
    double ms_per_draw;     /* >= 0, per-draw setup; default 5e-4 (0.5 us) */
} world_cost_model;

/* A closed camera loop: t in [0, 1) goes once round, t and t + 1 give the same
 * view. The eye follows
 *   x = cx + radius·cos θ + wobble·cos 3θ,  z = cz + radius·sin θ − wobble·sin 2θ,
 *   y = altitude + altitude_swing·sin 2θ,   θ = 2πt,
 * and looks along the direction of travel, pitched down by `pitch`. */
typedef struct world_path {
    float centre[2];       /* x, z of the loop's centre, m */
    float radius;          /* m, > 0 */
    float wobble;          /* m, < radius / 4 keeps the loop free of cusps */
    float altitude;        /* mean eye height, m */
    float altitude_swing;  /* m */
    float pitch;           /* radians below the horizon, in [0, pi/2) */
    float fov_y;           /* radians */
    float aspect;          /* width / height */
    float near_z, far_z;   /* m */
    float viewport_height; /* px */
} world_path;

/* The view at parameter t of the loop (any real t; only its fraction matters).
 * The result passes tclod_view_validate. */
void world_camera_at(const world_path *path, double t, tclod_view *view);

/* x rounded to float, on every compiler and optimisation level: the camera
 * paths keep their eyes in float, so that the paths (and with them the
 * selections the determinism test hashes) are the same under any build. */
double world_float(double x);

/* A built world: the tclod scene plus the per-node model data the callbacks read.
 * Node ids are the scene's ids. All arrays are owned by the world. */
typedef struct world_scene {
    tclod_scene *scene;
    uint32_t node_count;
    /* structure-of-arrays, indexed by node id */
    uint8_t *kind;       /* a world_kind */
    uint8_t *level;      /* object: LOD level k (0 = coarsest); group, terrain: quadtree depth */
    uint32_t *triangles; /* triangles drawn by the node */
    float *weight;       /* benefit per px² of screen area */
    float *cost_ms;      /* predicted render time, ms (what the cost callback returns) */
    float *bounds;       /* 4 per node: x, y, z, radius (m), as given to the scene; the radius
                            also gives a view-independent benefit when there is no view */
    /* the objects (chains): node id of level 0 and bounds x, y, z, radius */
    uint32_t object_count;
    uint32_t levels;        /* levels per object */
    tclod_id *object_root;  /* object_count entries */
    float *object_bounds;   /* 4 × object_count */
    uint32_t root_count;    /* hierarchies in the scene */
    uint32_t group_count;   /* group impostors (random world) */
    uint32_t terrain_count; /* terrain patches (flyover world) */
    float side;             /* the ground is [0, side] × [0, side] in x, z; m */
    world_path path;        /* a camera loop suited to this world */
    /* Kept by the edit functions below (world_add_object ...); zero as built. */
    uint32_t node_capacity;   /* entries of the per-node arrays; 0: node_count */
    uint32_t object_capacity; /* entries of the per-object arrays; 0: object_count */
    tclod_id *object_nodes;   /* levels per object: the node ids of its levels 0 .. L-1;
                                 NULL until the first edit (as built, object i's level k
                                 is object_root[i] + k) */
    uint32_t benefit_work;    /* rounds of a hash every benefit computes and throws away,
                                 to play a host whose evaluation is dear; the values are
                                 the same (0 as built) */
} world_scene;

/* The random world of the benchmark. */
typedef struct world_random_desc {
    uint32_t objects;      /* N >= 1 */
    uint32_t levels;       /* L in [1, 8]; default 4 */
    uint32_t leaf_objects; /* objects per leaf group, in [1, 8]; default 8 */
    float spacing; /* mean distance between objects, m; side = spacing·sqrt(N); default 25 */
    uint64_t seed; /* default 1 */
    world_cost_model cost;
    const tclod_allocator *alloc; /* the scene's allocator; default NULL (malloc) */
} world_random_desc;

/* The flyover world of the example. */
typedef struct world_flyover_desc {
    uint32_t terrain_depth;   /* quadtree depth, in [0, 10]: 4^depth leaf patches; default 6 */
    uint32_t patch_triangles; /* triangles per patch at any depth; default 2048 (32×32 quads) */
    float side;               /* terrain side, m; default 4096 */
    float height;             /* terrain relief, m; default 300 */
    uint32_t objects;         /* buildings and trees; default 5000 */
    uint32_t levels;          /* levels per object, in [1, 8]; default 6 */
    uint64_t seed;            /* default 7 */
    world_cost_model cost;
    const tclod_allocator *alloc; /* the scene's allocator; default NULL (malloc) */
} world_flyover_desc;

void world_cost_model_default(world_cost_model *m);
void world_random_desc_default(world_random_desc *d);
void world_flyover_desc_default(world_flyover_desc *d);

/* Builds the random world into *out. On failure *out is left empty (all zero)
 * and the status says why: TCLOD_ERR_ARG for a bad desc, TCLOD_ERR_NOMEM. */
tclod_status world_build_random(const world_random_desc *d, world_scene *out);

/* Builds the flyover world into *out; errors as world_build_random. */
tclod_status world_build_flyover(const world_flyover_desc *d, world_scene *out);

/* Frees everything a builder allocated and zeroes *w. NULL and an already freed
 * world are allowed. Destroy the world's selectors first. */
void world_scene_free(world_scene *w);

/* Terrain height at (x, z), m: a sum of a few sinusoids, smooth and
 * deterministic. The flyover world places its objects on it. */
float world_terrain_height(float x, float z, float side, float height);

/* Editing a world between frames (tclod_bench --scene churn). The scene gives ids
 * again once they are free (tclod.h), so a new level's id may be an old one or a
 * fresh one at the end; these functions grow the per-node arrays to the scene's
 * tclod_scene_node_count and fill the new levels' entries, and keep the objects dense:
 * object indices run over [0, object_count) and removing object i moves the last
 * object to index i. After an edit a level's id is object_nodes[L·i + k] (object_root[i]
 * + k only for the objects as built) and the entries of removed ids are stale (no
 * selection names them). Group impostors are left as they are: their bounds and weights
 * keep describing the objects they were built over. Every function returns TCLOD_OK,
 * TCLOD_ERR_ARG (an object index out of range, bad bounds), TCLOD_ERR_HIERARCHY (add:
 * parent not live), TCLOD_ERR_STATE (a selector over the scene has a solve begun) or
 * TCLOD_ERR_NOMEM, and leaves world and scene in step on error (the arrays may have
 * grown; nothing else changed). */

/* Adds an object: a chain of w->levels levels under parent (a live group, or
 * TCLOD_NONE: its own root), with the given bounds (x, y, z, radius) at every level,
 * base_triangles at level 0 and four times more per level, weighted and costed as the
 * builders do (cost from model). *out_object (may be NULL) receives its index. */
tclod_status world_add_object(world_scene *w, tclod_id parent, const float bounds[4],
                              uint32_t base_triangles, const world_cost_model *model,
                              uint32_t *out_object);

/* Removes object i: its level-0 node, which takes the other levels with it. */
tclod_status world_remove_object(world_scene *w, uint32_t i);

/* Moves object i: every level gets bounds (x, y, z, radius). */
tclod_status world_move_object(world_scene *w, uint32_t i, const float bounds[4]);

/* The node id of object i's level k (k < levels), as built or edited. */
tclod_id world_object_level(const world_scene *w, uint32_t i, uint32_t k);

/* The callbacks, with user = w (which must outlive the selectors using them).
 * benefit: screen_area × weight (after benefit_work rounds of busy work);
 *          screen_area 0 (outside the frustum) gives 0,
 *          so the node is culled with its subtree; without a view (-1) a
 *          nominal area π·radius² stands in, which keeps the ordering sensible.
 * cost:    cost_ms of the node.
 * importance (Robin Hood's value functions): the weight alone. The value
 *          functions measure the instance's size and place themselves; the
 *          benefit would count its screen area a second time.
 * Smooth callbacks are NULL (no smooth objects). */
tclod_callbacks world_callbacks(world_scene *w);
double world_benefit(void *user, const tclod_query *q);
double world_importance(void *user, const tclod_query *q);
double world_cost(void *user, const tclod_query *q);

/* world_callbacks with the batch forms of benefit and cost too: loops over
 * the batch's arrays giving the per-node callbacks' values bit for bit. */
tclod_callbacks world_batch_callbacks(world_scene *w);
void world_benefit_batch(void *user, const tclod_batch *b, double *out);
void world_cost_batch(void *user, const tclod_batch *b, double *out);

/* Sum of cost_ms over ids, in the given order, in double: what the library's
 * budget guarantee is about, computed independently of it. */
double world_sum_cost(const world_scene *w, const tclod_id *ids, size_t n);

/* Cost from features (docs/calibration.md, the learned cost): a node's
 * WORLD_FEATURES features are its draw (1) and its triangles, priced at
 * ms_per_draw and ms_per_triangle by world_cost_model's prior. */
enum { WORLD_DRAWS = 0, WORLD_TRIANGLES = 1, WORLD_FEATURES = 2 };
extern const char *const world_feature_names[WORLD_FEATURES];
void world_features(void *user, const tclod_query *q, double *out);
/* world_callbacks pricing by features instead of cost_ms (cost NULL). */
tclod_callbacks world_feature_callbacks(world_scene *w);
/* The features of the n nodes ids summed into out (WORLD_FEATURES entries). */
void world_sum_features(const world_scene *w, const tclod_id *ids, size_t n, double *out);
/* The prior of a cost model: out[WORLD_DRAWS], out[WORLD_TRIANGLES]. */
void world_feature_prior(const world_cost_model *m, double *out);

/* Objects whose level-0 bounds intersect the view frustum. */
uint32_t world_visible_objects(const world_scene *w, const tclod_view *view);

#ifdef __cplusplus
}
#endif

#endif /* WORLD_SCENE_H */
