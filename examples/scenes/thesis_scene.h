/*
 * thesis_scene — the terrain flyover with 1.4 million trees of the thesis's test
 * application ([Thesis8 §8.4], "Test Application" and "Benefit and Cost
 * Heuristics"), for the mixed solver's example and benchmark.
 *
 * The thesis flies over a 2049 × 2049 height field of 120 km × 120 km (Styria)
 * organised as a quadtree of patches of 33 × 33 vertices, the discrete LOD
 * hierarchy, with about 1.4 million point-splatted trees on a jittered grid
 * inside the forest regions, grouped into sets of at most 64 spatially close
 * trees whose resolution is continuous. Here the height field and the forest
 * regions are procedural (sums of separable sinusoids, so that neither the
 * 4 M height samples nor the individual trees are ever stored):
 *  - terrain: 4^dmax leaf patches (dmax = 6 by default, 5461 nodes in one
 *    quadtree); every patch, at every depth, is 32 × 32 cells sent as 32 strips
 *    of 66 vertices, and gets a bounding sphere around its x/z extent and the
 *    height range of its vertices;
 *  - trees: one per cell of a jittered grid (60 m) where a smooth forest mask
 *    exceeds the threshold that covers 35% of the cells; the mask prefers
 *    middle heights (few trees in the valleys, none above the tree line).
 *    Every non-empty block of 8 × 8 cells is one smooth object (N_i <= 64 trees).
 *
 * Model ([Thesis8 eq. 8.18–8.21]), in milliseconds:
 *   terrain patch at depth d:  benefit = S · 2^(d − dmax)                  (eq. 8.21)
 *                              cost    = c_vertex · 2112                    (eq. 8.19)
 *   group of smooth objects sharing the resolution r (count members, N trees in all,
 *   S the projected area of the group's bounds):
 *                              benefit = k · S · (N / (64 · count)) · sqrt(r)   (eq. 8.20)
 *                              cost    = splat cost of N trees of
 *                                        THESIS_SPLATS_PER_TREE splats at r     (eq. 8.18)
 * Below one splat per tree (r < 1 / THESIS_SPLATS_PER_TREE) a group draws only
 * r · N · THESIS_SPLATS_PER_TREE of its trees, one splat each ("only the corresponding
 * fraction of the group is rendered", thesis §8.4): the steep first part of eq. 8.18,
 * where every splat pays a tree's setup.
 * The thesis's group benefit k · S · (N/64) · sqrt(x/N) (x = r · N, its resolution
 * in [0, N]) is for one set of at most 64 trees, N/64 being its density. A group of
 * several sets shares one screen area S that already grows with the number of sets,
 * so it uses their mean density N / count: for count = 1 this is eq. 8.20 exactly,
 * and a group of sets of equal density and size has (up to perspective) the sum of
 * their benefits. Both callbacks are O(1) whatever the group's size: a prefix sum of
 * tree counts over the scene's smooth order gives N.
 *
 * Not part of the library: no header of libtclod depends on this one.
 */
#ifndef THESIS_SCENE_H
#define THESIS_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include <tclod/tclod.h>

#include "world_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Full-resolution splats of one tree: the thesis draws an adjustable prefix of a
 * template's point samples; 16384 is the point count of a detailed Weber–Penn tree
 * that looks closed near the camera (the thesis does not state its number). At
 * c_splat = 0.0775 us a full tree costs 1.27 ms, so a 40 ms budget pays for a few
 * dozen full trees or tens of thousands of sparse ones: the resolutions stay low. */
#define THESIS_SPLATS_PER_TREE 16384u
/* Cells per side of every terrain patch (33 × 33 vertices). */
#define THESIS_PATCH_CELLS 32u
/* Vertices sent per patch: 32 triangle strips of 2 × 33 vertices. */
#define THESIS_PATCH_VERTICES (THESIS_PATCH_CELLS * 2u * (THESIS_PATCH_CELLS + 1u))
/* Crown half-width over tree height: a conifer's crown (4–8 m for 20–40 m trees).
 * Tree bounds and drawn trees both use it. */
#define THESIS_CROWN_RATIO 0.2
/* Trees per smooth object at most: the thesis's sets of at most 64 trees. */
#define THESIS_MAX_GROUP_TREES 64u

typedef struct thesis_desc {
    float side;             /* terrain side, m, > 0; default 120000 (120 km) */
    float height;           /* relief: heights lie in [0, height], m, >= 0; default 2400 */
    uint32_t terrain_depth; /* dmax, quadtree height, in [0, 8]: 4^dmax leaf patches and
                               32·2^dmax + 1 samples per side; default 6 (2049 samples) */
    float tree_spacing;     /* jittered grid spacing, m, > 0, at most side / 8192 grid cells
                               per side; default 60 (2000 × 2000 cells) */
    float forest_cover;     /* share of the grid cells inside forest regions, in (0, 1];
                               default 0.35 (about 1.4 million trees with the defaults) */
    float tree_height_min;  /* m, > 0; default 20 (exaggerated, thesis §8.4) */
    float tree_height_max;  /* m, >= tree_height_min; default 40 */
    uint32_t block_cells;   /* a smooth object is a block of block_cells × block_cells grid
                               cells, in [1, 8] (at most 64 trees); default 8 */
    uint64_t seed;          /* jitter and tree heights; default 11 */
    double k;               /* tree benefit weight (eq. 8.20), > 0; default 50 */
    double c_splat_ms;      /* time per splat, ms, > 0; default 0.0775e-3 (0.0775 us) */
    double c_tree_ms;       /* setup time per drawn tree, ms, >= 0; default 1.385e-3 */
    double c_vertex_ms;     /* time per strip vertex, ms, > 0; default 0.06e-3 (0.06 us) */
    int keep_trees;         /* 1: also keep every tree (thesis_scene.tree_xyzh, 16 bytes a
                               tree) for hosts that draw them; 0: only the groups, as the
                               selection needs; default 0 */
    /* the scene's allocator; default NULL (malloc) */
    const tclod_allocator *alloc;
} thesis_desc;

/* Fills d with the defaults above (the thesis's scene and constants). */
void thesis_desc_default(thesis_desc *d);

/* A built thesis scene: the tclod scene plus what the callbacks read. Terrain
 * nodes are the scene's node ids (level by level from the root, row-major within
 * a level); smooth ids are the scene's smooth ids. All arrays are owned here. */
typedef struct thesis_scene {
    tclod_scene *scene;
    /* terrain, structure-of-arrays by node id */
    uint32_t node_count;    /* (4^(dmax+1) − 1) / 3 */
    uint32_t terrain_depth; /* dmax */
    uint8_t *depth;         /* quadtree depth of each node, 0 = root */
    float *node_bounds;     /* 4 per node: x, y, z, radius (m) */
    double patch_cost_ms;   /* what the cost callback returns for every patch */
    /* trees, structure-of-arrays by smooth id */
    uint32_t smooth_count; /* tree groups (non-empty blocks) */
    uint32_t tree_count;   /* trees in all */
    uint8_t *trees;        /* N_i, in [1, 64] */
    float *smooth_bounds;  /* 4 per smooth object: x, y, z, radius (m) */
    /* the scene's smooth order and the prefix sums that make group queries O(1) */
    tclod_id *smooth_order; /* copy of tclod_scene_smooth_order */
    uint32_t *smooth_pos;   /* position of each smooth id in smooth_order */
    uint32_t *tree_prefix;  /* smooth_count + 1: trees at positions [0, p) */
    double *area_prefix;    /* smooth_count + 1: sum of pi·radius² over positions [0, p),
                               the nominal screen area used when a query has no view */
    /* the individual trees, only with desc.keep_trees (else both NULL): smooth object
     * id's trees are tree_first[id] .. tree_first[id + 1] − 1, in grid order (row by
     * row within its block) */
    uint32_t *tree_first; /* smooth_count + 1, by smooth id */
    float *tree_xyzh;     /* 4 per tree: x, ground height y, z (m) of its foot, and its
                             height (m); its crown is THESIS_CROWN_RATIO × height wide
                             on either side */
    /* model */
    double k, c_splat_ms, c_tree_ms, c_vertex_ms;
    /* world */
    float side, height;      /* m */
    uint32_t grid_cells;     /* tree grid cells per side */
    double forest_threshold; /* forest mask value from which a grid cell has a tree */
    /* The camera loop. Its x/z track, direction and optics are those of
     * world_camera_at; altitude and altitude_swing are heights above the terrain's
     * smooth upper envelope (thesis_camera_at), not above sea level. */
    world_path path;
} thesis_scene;

/* Builds the scene into *out (a few hundred ms with the defaults). On failure
 * *out is left empty (all zero), nothing is leaked, and the status says why:
 * TCLOD_ERR_ARG (NULL argument, a desc field out of range), TCLOD_ERR_NOMEM. */
tclod_status thesis_build(const thesis_desc *d, thesis_scene *out);

/* Frees everything thesis_build allocated and zeroes *t. NULL and an already
 * freed scene are allowed. Destroy the scene's selectors first. */
void thesis_scene_free(thesis_scene *t);

/* Terrain height at (x, z), m, in [0, height]: separable sinusoids, higher and
 * rougher towards x = z = 0 (the Alpine corner), rolling hills elsewhere. Smooth
 * and deterministic. */
float thesis_terrain_height(float x, float z, float side, float height);

/* The place of terrain node `node` (< t->node_count) in the quadtree: its depth
 * *level (0 = root) and its cell (*ix, *iz) among the 2^level × 2^level patches of
 * that depth, so that it covers x in [ix, ix + 1] · side / 2^level and z likewise
 * with iz. The one definition of the node id layout a host needs to draw the
 * patches. */
void thesis_patch_cell(const thesis_scene *t, tclod_id node, uint32_t *level, uint32_t *ix,
                       uint32_t *iz);

/* How far (x, z) lies inside the forest regions: the forest mask that placed the
 * trees, minus its threshold; > 0 where the tree grid's cells have trees (at the
 * cell centres exactly), < 0 outside. Smooth: within about [−1.2, 1] over the
 * whole terrain, changing by at most about 0.6 per km. For hosts that shade the
 * ground under the forest where they draw no trees. */
float thesis_forest_mask(const thesis_scene *t, float x, float z);

/* The view at parameter t of the loop (only its fraction matters): the track of
 * world_camera_at(&t->path, ...), raised onto the terrain's smooth upper envelope
 * (an upper bound of the height nearby, free of the short-wavelength relief), so
 * the eye stays path.altitude ± path.altitude_swing above it: a few hundred metres
 * above the ground, never below it. The result passes tclod_view_validate. */
void thesis_camera_at(const thesis_scene *t, double time, tclod_view *view);

/* The callbacks, with user = t (which must outlive the selectors using them):
 * benefit, cost for terrain nodes; smooth_benefit, smooth_cost for a smooth object
 * or a group (the formulas above; both write *d_dr). A screen area of 0 (outside
 * the frustum) gives benefit 0; without a view (screen area −1) nominal areas
 * stand in: π·radius² of a patch, the sum of π·radius² of a group's members. */
tclod_callbacks thesis_callbacks(thesis_scene *t);
double thesis_benefit(void *user, const tclod_query *q);
double thesis_cost(void *user, const tclod_query *q);
double thesis_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr);
double thesis_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr);

/* Cost from features (docs/calibration.md, the learned cost): what drawing
 * a patch or a group sends, THESIS_FEATURES of them: draws (a patch is one, a
 * group at r one per tree it draws, min(r · S · N, N) for its N trees with S
 * THESIS_SPLATS_PER_TREE splats each), strip vertices (a patch's
 * THESIS_PATCH_VERTICES) and splats (r · S · N). eq. 8.18 and 8.19 are these
 * features priced at c_tree, c_vertex and c_splat (thesis_feature_prior), but
 * for the c_tree a patch's draw adds. */
enum { THESIS_DRAWS = 0, THESIS_VERTICES = 1, THESIS_SPLATS = 2, THESIS_FEATURES = 3 };
extern const char *const thesis_feature_names[THESIS_FEATURES];
void thesis_features(void *user, const tclod_query *q, double *out);
void thesis_smooth_features(void *user, const tclod_query *q, double r, double *out, double *d_dr);
/* thesis_callbacks pricing by features (cost and smooth_cost NULL). */
tclod_callbacks thesis_feature_callbacks(thesis_scene *t);
/* The features of a group of `trees` trees at r into out, d/dr into d_dr (may be NULL). */
void thesis_group_features(double trees, double r, double *out, double *d_dr);
/* The prior: c_tree, c_vertex and c_splat of the scene, ms per unit. */
void thesis_feature_prior(const thesis_scene *t, double *out);

/* Benefit of terrain node `node` alone under view (NULL: the nominal area), with
 * its own frustum test and screen area; 0 outside the frustum or for an unknown id. */
double thesis_node_benefit(const thesis_scene *t, const tclod_view *view, tclod_id node);

/* Benefit of smooth object `smooth` alone at resolution r under view (NULL: the
 * nominal area): eq. 8.20 with its own N_i, frustum test and screen area. Lets
 * selections that group objects differently be compared on the same scale; 0
 * outside the frustum, for r <= 0 or an unknown id. */
double thesis_object_benefit(const thesis_scene *t, const tclod_view *view, tclod_id smooth,
                             double r);

/* Benefit of a whole selection measured object by object: thesis_node_benefit of
 * the n cut nodes plus thesis_object_benefit of every member of the drawn smooth
 * groups at its group's resolution. */
double thesis_selection_benefit(const thesis_scene *t, const tclod_view *view, const tclod_id *ids,
                                size_t n, const tclod_smooth_group *groups, size_t group_count);

/* Predicted cost of a selection, computed independently of the library with the
 * callbacks' own formulas: the patch cost of each of the n cut nodes in cut order,
 * then each group's splat cost in the given order, summed in double. What the
 * library's budget guarantee is about. groups may be NULL when group_count is 0. */
double thesis_sum_cost(const thesis_scene *t, const tclod_id *ids, size_t n,
                       const tclod_smooth_group *groups, size_t group_count);

/* Trees in the smooth objects at positions [first, first + count) of the scene's
 * smooth order (0 for a range outside it). */
uint32_t thesis_group_trees(const thesis_scene *t, uint32_t first, uint32_t count);

/* Smooth objects whose bounds intersect the view frustum. */
uint32_t thesis_visible_smooth(const thesis_scene *t, const tclod_view *view);

#ifdef __cplusplus
}
#endif

#endif /* THESIS_SCENE_H */
