/*
 * What the scene's two files share (scene.c, scene_prepare.c): the checks and
 * the bookkeeping an edit and a preparation both make.
 */
#ifndef TCLOD_SCENE_INTERNAL_H
#define TCLOD_SCENE_INTERNAL_H

#include "scene.h"

#include <float.h>

/* Why an edit is refused while a solve holds the scene. */
#define HELD "a solve holds the scene (pending, or called from a callback)"

/* A size's rule (scene_bytes_valid). */
#define BYTES_RULE "bytes must be finite, >= 0 and at most FLT_MAX"

/* The smooth quadtree's arrays, allocated together so that a failure changes
 * nothing. */
typedef struct quadtree_arrays {
    uint32_t smooth_cap;
    tclod_id *smooth_order;
    uint32_t *smooth_pos;
    tclod_smooth_node *qt;
} quadtree_arrays;

/* Whether a user holds the scene: a solve begun, or a call under way (the
 * host's callbacks run inside one). Changes are refused then. */
static inline int scene_held(const tclod_scene *s) {
    uint32_t i;
    for (i = 0; i < s->user_count; ++i)
        if (s->users[i]->busy || s->users[i]->holding)
            return 1;
    return 0;
}

static inline int scene_node_live(const tclod_scene *s, tclod_id n) {
    return n < s->node_count && (s->flags[n] & TCLOD_NODE_LIVE);
}

static inline int scene_smooth_live(const tclod_scene *s, tclod_id n) {
    return n < s->smooth_count && (s->smooth_flags[n] & TCLOD_NODE_LIVE);
}

static inline int scene_bytes_valid(double b) {
    return b >= 0.0 && b <= (double)FLT_MAX;
}

/* The indexed nodes breadth first from the roots, parents before children,
 * for the users that read them. */
void tclod_scene_build_order(tclod_scene *s);

/* Frees the smooth quadtree's arrays. */
void tclod_scene_quadtree_arrays_free(const tclod_allocator *a, quadtree_arrays *x);

/* Counts live node n resident (on the list, when kept) with its size. */
void tclod_scene_resident_add(tclod_scene *s, tclod_id n);

/* Takes resident node n off the count (and list) and its size off the total. */
void tclod_scene_resident_remove(tclod_scene *s, tclod_id n);

#endif /* TCLOD_SCENE_INTERNAL_H */
