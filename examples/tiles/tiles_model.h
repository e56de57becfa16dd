/*
 * tiles_model — the benefit model of tclod_tiles (docs/tiles.md, benefit):
 * screen-space error as CesiumJS computes it, turned into the share of the
 * screen a tile shows well.
 *
 * A tile t of geometric error g at distance d (to its bounding volume) has the
 * screen-space error s = g * viewport_height / (d * 2 tan(fov_y / 2)) pixels,
 * and shows its share a_t of the screen at the quality q(s) = 1 / (1 + s / K),
 * K = 64 px: 1 when exact, 0.8 at 16 px (CesiumJS's default maximum
 * screen-space error), 1/2 at K. Its benefit is a_t q(s_t), or for a tile
 * below an additive tile A that stays drawn, a_t (q(s_t) - q(s_A)): what it
 * adds to A. The shares split a parent's share among its children in
 * proportion to their projected areas (the root's is its own area), so that
 * children together hold exactly what their parent held and refining a tile
 * gains only what its error loses: a_t (q(s / 2) - q(s)) when a refinement
 * halves the error. That gain grows with s up to K sqrt(2) = 90 px, where
 * budgets bind, and is as large at 2 K² / s as at s: a tile at 512 px gains as
 * much from a refinement as one at 16 px, and every tile between gains more.
 * A greedy maximiser therefore refines the largest errors first, per unit of
 * screen and of cost; and since a refinement costs more at every level (four
 * or eight children) while its gain at most stays level, the benefit has
 * diminishing returns down the tree.
 */
#ifndef TILES_MODEL_H
#define TILES_MODEL_H

#include <stdint.h>

#include <tclod/tclod.h>

#include "tileset.h"

/* CesiumJS's default maximumScreenSpaceError (px), which the sse16 traversal
 * refines above. */
#define MODEL_SSE_REF 16.0
/* K: the error (px) at which a tile shows half its quality. */
#define MODEL_HALF_QUALITY_SSE 256.0
/* A camera inside a tile's volume is at distance 0: CesiumJS divides by this
 * instead (CesiumMath.EPSILON7). */
#define MODEL_MIN_DISTANCE 1e-7

/* A tile's bounding volume as this program measures it, prepared once: a
 * sphere, or a box with its unit axes (a flat box's missing axis completed by
 * a cross product) and half lengths. */
typedef struct model_volume {
    double c[3]; /* centre, world */
    double r;    /* sphere: radius; box: -1; no bounds: -2 */
    double u[3][3], h[3];
} model_volume;

/* The frame's view, orthonormalised as the library does (tclod_view_bounds_*):
 * the side planes' outward normals pass through the eye. */
typedef struct model_eye {
    double eye[3], right[3], up[3], forward[3];
    double cos_y, sin_y, cos_x, sin_x, near_z, far_z;
    double focal, pi_focal2, viewport_area;
} model_eye;

/* What the benefit reads of a tile, packed: the tiles themselves are large. */
typedef struct model_link {
    double geometric_error;
    uint32_t parent, add_anchor, first_child, child_count;
    uint32_t children_bound; /* 1: a REPLACE box with children, all boxes within it:
                                what it shows lies in them (model_children_bound) */
} model_link;

typedef struct tiles_model {
    const tileset *ts;
    tclod_view view;   /* the frame's */
    model_eye eye;     /* the same, prepared */
    model_volume *vol; /* per tile */
    model_link *link;  /* per tile */
    double sse_factor; /* viewport_height / (2 tan(fov_y / 2)) */
    uint32_t stamp;    /* this view's number: memo entries of another are stale */
    /* per tile, measured once per view when first needed */
    uint32_t *area_stamp, *share_stamp, *sum_stamp, *distance_stamp;
    double *area;      /* projected area, 0 outside the frustum */
    double *share;     /* a_t */
    double *child_sum; /* projected areas of the children, summed */
    double *distance;  /* tclod_view_bounds_distance */
    uint32_t *path;    /* scratch: a tile's ancestors */
    uint32_t count;    /* tiles prepared */
    size_t room;       /* entries of the per-tile arrays */
    uint32_t path_room;
} tiles_model;

/* 0 on success, 1 when out of memory. */
int model_init(tiles_model *m, const tileset *ts);
/* After the tileset grew (tileset_expand): prepares the tiles added since,
 * and their parents again. 0 on success, 1 when out of memory (m still
 * serves the tiles it had). */
int model_grow(tiles_model *m);
void model_free(tiles_model *m);

/* Starts a view: every measure after this is of v (copied). */
void model_set_view(tiles_model *m, const tclod_view *v);

/* tile t's distance to the eye (tclod_view_bounds_distance) and projected area
 * (tclod_view_bounds_area, 0 outside the frustum as tclod_view_bounds_visible
 * says), computed here from the volumes prepared by model_init and the view
 * prepared by model_set_view: the library's definitions, without its checks
 * and its preparation of bounds and view on every call. A box reaching
 * through the near plane takes the library's functions. */
double model_distance(tiles_model *m, uint32_t t);
double model_area(tiles_model *m, uint32_t t);

/* Whether tile t meets the frustum (tclod_view_bounds_visible), from the
 * prepared volume and view as above. */
int model_visible(const tiles_model *m, uint32_t t);

/* The same area measured again, past the memo: what model_area computes when
 * nothing was noted (check_queries compares it with the library's). */
double model_measure_area(const tiles_model *m, uint32_t t);

/* Notes `area`, the library's measure of tile t in this view (a query's
 * screen_area, >= 0), as t's projected area, unless t has one already: the
 * callbacks take what the library measured instead of measuring the box
 * again. */
void model_note_area(tiles_model *m, uint32_t t, double area);

/* The screen-space error of tile t seen from `distance`, in px. */
double model_sse(const tiles_model *m, uint32_t t, double distance);

/* 1 when tile t has a viewerRequestVolume the eye is outside of: CesiumJS
 * then culls t with its subtree, and so does the benefit. */
int model_out_of_request(const tiles_model *m, uint32_t t);

/* 1 when tile t is one whose children bound what it shows (a REPLACE tile
 * with children, itself and every child a box or region, each child within
 * it, as CesiumJS's cullWithChildrenBounds asks) and none of them is in the
 * frustum: CesiumJS then culls t, and so does the benefit. */
int model_culled_by_children(tiles_model *m, uint32_t t);

/* The benefit of drawing tile t, seen from `distance`, when it is in the
 * frustum: > 0 (a tile that adds nothing gets a trace, not 0, which would
 * cull its subtree), or 0 when model_culled_by_children or
 * model_out_of_request. */
double model_benefit(tiles_model *m, uint32_t t, double distance);

/* The distance from eye to b computed here, apart from the library, to check
 * the query's: 0 inside, else to the nearest point of the sphere or box. */
double model_reference_distance(const tclod_bounds *b, const double eye[3]);

#endif
