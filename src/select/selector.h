/*
 * The selector layer (selector.c): what the scheduler, above it, calls of a
 * selector beside the public API.
 */
#ifndef TCLOD_SELECTOR_H
#define TCLOD_SELECTOR_H

#include "../eval/evaluate.h"

/* Whether the selector can solve its scene as it is now: the mixed solver
 * created without smooth callbacks needs a scene without smooth objects. */
int tclod_selector_scene_ok(const tclod_selector *sel);

/* Prepares the scene and grows the selector's buffers to its size, all or
 * nothing (what tclod_select_begin allocates, and nothing else): afterwards
 * a begin allocates nothing until the scene grows. */
tclod_status tclod_selector_reserve(tclod_selector *sel);

/* A selector's committed result and warm-start state, as a scheduler keeps
 * it so that a failed update can put it back (schedule.c). The arrays are
 * the keeper's: cut and result with room for the scene's nodes, groups for
 * its smooth objects. */
typedef struct tclod_selector_saved {
    tclod_id *cut, *result, *drawn;
    tclod_smooth_group *groups;
    uint32_t cut_count, result_count, group_count;
    uint32_t scene_version, node_version, smooth_version;
    int drawn_is_result;
    uint32_t synced;   /* the selector's tclod_scene_user.synced ... */
    uint64_t log_seen; /* ... and log_seen */
    int has_cut;
    double closure_hint;     /* as it was when the keeping began */
    tclod_fallback fallback; /* the same */
    int valid;               /* a commit has happened since: the fields above hold
                                the state before it */
} tclod_selector_saved;

/* Begins keeping (k not NULL) or stops (NULL): from now on the first commit
 * first copies the committed state into k, so that tclod_selector_restore
 * can put back the state of the moment this was called. */
void tclod_selector_keep(tclod_selector *sel, tclod_selector_saved *k);

/* Puts back the state kept in k (no solve may be pending): the committed
 * result, the warm start's cut and the greedy's closure hint. */
void tclod_selector_restore(tclod_selector *sel, const tclod_selector_saved *k);

#endif /* TCLOD_SELECTOR_H */
