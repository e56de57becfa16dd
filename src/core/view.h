/*
 * view.c: node bounds, boxes and the view as the solvers measure them.
 */
#ifndef TCLOD_VIEW_H
#define TCLOD_VIEW_H

#include "internal.h"

/* A node's bounds as the solvers read them: the sphere around the volume
 * (what culling shortcuts and the Robin Hood values use) and, for a box, its
 * slot. 40 bytes; the padding is kept zero so that records compare with
 * memcmp. */
typedef struct tclod_node_bounds {
    double c[3];   /* centre, world position */
    double r;      /* the sphere's radius, or the box's enclosing sphere's; < 0: no
                      bounds */
    uint32_t box;  /* the box's slot in tclod_scene.boxes, or TCLOD_NONE */
    uint32_t kind; /* tclod_bounds_kind, with TCLOD_BOUNDS_SELF for a self leaf: the
                      evaluation, which reads this record anyway, finds it there */
} tclod_node_bounds;

/* tclod_node_bounds.kind of a self leaf (scene.c): its owner's kind with this
 * bit. */
#define TCLOD_BOUNDS_SELF 0x100u

/* An axis-aligned or oriented box: the half axes as given, and an
 * orthonormal frame with half lengths (zero axes completed by cross
 * products), which the measures use. */
typedef struct tclod_box {
    double axes[3][3]; /* as given; an AABB's are diagonal */
    double u[3][3];    /* unit axes */
    double h[3];       /* half lengths along them, >= 0 */
} tclod_box;

/* ---- view.c ---------------------------------------------------------------- */

/* A validated view, orthonormalised once per frame. */
typedef struct tclod_view_cache {
    double eye[3], forward[3], up[3], right[3];
    double cos_y, sin_y; /* of half the vertical field of view */
    double cos_x, sin_x; /* of half the horizontal field of view */
    double near_z, far_z;
    double focal;         /* f = (viewport_height / 2) / tan(fov_y / 2), pixels */
    double pi_focal2;     /* pi f² */
    double viewport_area; /* viewport_height² * aspect */
} tclod_view_cache;

/* Fills c from a view that passed tclod_view_validate. */
void tclod_view_cache_init(tclod_view_cache *c, const tclod_view *v);

/* Checks public bounds b and converts them to the solvers' form: *nb and,
 * for a box, *box (nb->box is left for the caller to set). Returns NULL, or
 * the rule b breaks (tclod_bounds_check). */
const char *tclod_bounds_convert(const tclod_bounds *b, tclod_node_bounds *nb, tclod_box *box);

/* The sphere of radius r centred at p (relative to the eye) meets the frustum
 * (box_seen in view.c explains the planes). */
static inline int tclod_view_cache_visible(const tclod_view_cache *c, const double p[3], double r) {
    double z = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
    if (z < c->near_z - r || z > c->far_z + r)
        return 0;
    if (fabs(p[0] * c->up[0] + p[1] * c->up[1] + p[2] * c->up[2]) * c->cos_y - z * c->sin_y > r)
        return 0;
    return fabs(p[0] * c->right[0] + p[1] * c->right[1] + p[2] * c->right[2]) * c->cos_x -
               z * c->sin_x <=
           r;
}

/* The sphere of radius r centred at p (relative to the eye) lies so far inside
 * the frustum that every sphere within it passes tclod_view_cache_visible,
 * rounding included: each signed distance is at most -r less a margin far
 * above the rounding of the test (a sphere within it has its own distances
 * at most those plus r, which is Lipschitz with constant 1 in p). */
static inline int tclod_view_cache_inside(const tclod_view_cache *c, const double p[3], double r) {
    double z = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
    double rm = r + 1e-6 * (fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + r + c->far_z);
    if (z - rm < c->near_z || z + rm > c->far_z)
        return 0;
    if (fabs(p[0] * c->up[0] + p[1] * c->up[1] + p[2] * c->up[2]) * c->cos_y - z * c->sin_y > -rm)
        return 0;
    return fabs(p[0] * c->right[0] + p[1] * c->right[1] + p[2] * c->right[2]) * c->cos_x -
               z * c->sin_x <=
           -rm;
}

/* Projected area in px² of a sphere of radius r whose centre is d2 away from
 * the eye, squared; clamped to the viewport. */
static inline double tclod_view_cache_area(const tclod_view_cache *c, double d2, double r) {
    double r2 = r * r, area;
    if (d2 <= r2)
        return c->viewport_area;
    area = c->pi_focal2 * r2 / (d2 - r2);
    return area < c->viewport_area ? area : c->viewport_area;
}

/* Distance from the eye to a sphere of radius r whose centre is d2 away,
 * squared: 0 inside. */
static inline double tclod_sphere_distance(double d2, double r) {
    double d = sqrt(d2) - r;
    return d > 0.0 ? d : 0.0;
}

/* Projected area (0 outside the frustum) and distance (0 inside) of a box,
 * p its centre relative to the eye. */
void tclod_view_cache_measure_box(const tclod_view_cache *c, const double p[3],
                                  const tclod_box *box, float *area, double *distance);

/* Projected area (0 outside the frustum) and distance (to the volume, 0
 * inside) of node bounds b (with a bounded sphere: b->r >= 0); boxes from
 * boxes[]. */
static inline void tclod_view_measure_bounds(const tclod_view_cache *c, const tclod_node_bounds *b,
                                             const tclod_box *boxes, float *area,
                                             double *distance) {
    double p[3], r = b->r, d2;
    p[0] = b->c[0] - c->eye[0];
    p[1] = b->c[1] - c->eye[1];
    p[2] = b->c[2] - c->eye[2];
    if (b->box != TCLOD_NONE) {
        tclod_view_cache_measure_box(c, p, &boxes[b->box], area, distance);
        return;
    }
    d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    *distance = tclod_sphere_distance(d2, r);
    *area = tclod_view_cache_visible(c, p, r) ? (float)tclod_view_cache_area(c, d2, r) : 0.0f;
}

/* The same for a sphere given as floats (x, y, z, radius): smooth objects and
 * their groups. */
static inline void tclod_view_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                                      float *distance) {
    double p[3], r = (double)bounds[3], d2;
    p[0] = (double)bounds[0] - c->eye[0];
    p[1] = (double)bounds[1] - c->eye[1];
    p[2] = (double)bounds[2] - c->eye[2];
    d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    *distance = (float)tclod_sphere_distance(d2, r);
    *area = tclod_view_cache_visible(c, p, r) ? (float)tclod_view_cache_area(c, d2, r) : 0.0f;
}

/* Projected area (0 outside the frustum) and distance of valid public bounds
 * (kind NONE: -1 and -1). */
void tclod_view_cache_measure_any(const tclod_view_cache *c, const tclod_bounds *b, float *area,
                                  float *distance);

/* tclod_view_measure, out of line. */
void tclod_view_cache_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                              float *distance);

/* A public sphere for a float one (x, y, z, radius), for queries. */
static inline void tclod_sphere_bounds(const float b[4], tclod_bounds *out) {
    out->kind = TCLOD_BOUNDS_SPHERE;
    out->center[0] = (double)b[0];
    out->center[1] = (double)b[1];
    out->center[2] = (double)b[2];
    out->radius = (double)b[3];
}

#endif /* TCLOD_VIEW_H */
