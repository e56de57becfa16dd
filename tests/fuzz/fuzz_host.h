/*
 * fuzz_host — the host the fuzz targets play (fuzz_host.c): a scene model
 * mirrored id by id (which ids are live, removed or an additive node's
 * hidden one, each node's kind, parent and bounds), callbacks that read it
 * and check every query they are given, edits between frames whose status
 * the model predicts, and readers that turn the fuzzer's bytes into
 * selector descriptions, scenes, edits and views, checking the statuses the
 * header promises on the way.
 */
#ifndef FUZZ_HOST_H
#define FUZZ_HOST_H

#include <tclod/tclod.h>

#include "fuzz_input.h"

/* Id spaces the model mirrors: node ids (live, removed and hidden ones all
 * count) and smooth ids. Adds stop short of them. */
#define MAX_NODES 384u
#define MAX_SMOOTH 80u
/* Selectors and schedulers a target keeps over its scene. */
#define MAX_USERS 2u

/* What the model knows of an id. */
enum { ID_FREE = 0, ID_LIVE = 1, ID_REMOVED = 2, ID_HIDDEN = 3 };
/* A node's kind. An empty node is empty whatever its refinement. */
enum { KIND_REPLACE = 0, KIND_ADD = 1, KIND_EMPTY = 2 };
/* An additive node whose hidden id was a reused one, which no call tells. */
#define HIDDEN_UNKNOWN (TCLOD_NONE - 1u)

/* A smooth object's model: benefit w r^p, cost steep r up to r = kink then
 * k per unit, slopes honest or not, and optionally one bad value or slope. */
typedef struct smooth_model {
    double w, p;
    double k, steep, kink;
    int dishonest; /* slopes are fake_slope whatever r */
    double fake_slope;
    int bad_kind; /* 0 none; 1 benefit, 2 benefit slope, 3 cost, 4 cost slope */
    double bad_value;
} smooth_model;

/* The host's scene model, mirrored id by id. */
typedef struct host_model {
    tclod_scene *scene;
    uint32_t nodes, smooth;           /* the id bounds: tclod_scene_node_count, _smooth_count */
    uint32_t live_nodes, live_smooth; /* of those, live (nodes: public ones) */
    uint8_t state[MAX_NODES];         /* ID_* */
    uint8_t kind[MAX_NODES];          /* KIND_*, of live and removed nodes */
    uint8_t unexpanded[MAX_NODES];    /* added with tclod_node_desc.unexpanded: no child
                                         can be added below it */
    tclod_id parent[MAX_NODES];       /* as added (empty ones included) */
    tclod_id hidden[MAX_NODES];       /* an additive node's hidden id, TCLOD_NONE or
                                         HIDDEN_UNKNOWN; for a hidden id its owner */
    tclod_bounds bounds[MAX_NODES];   /* as added or last moved */
    double benefit[MAX_NODES], cost[MAX_NODES];
    double complexity[MAX_NODES + MAX_SMOOTH]; /* nodes, then smooth objects */
    int view_dependent;                        /* benefit x screen area when the query has one */
    uint8_t smooth_state[MAX_SMOOTH];          /* ID_FREE, ID_LIVE or ID_REMOVED */
    float smooth_bounds[MAX_SMOOTH][4];
    smooth_model sm[MAX_SMOOTH];
    /* id reuse: the scene's removals counted as its epoch (one per removal
     * call), the epoch each id was removed at, and per user (selector or
     * scheduler of the target) the epoch at its last solve, UINT32_MAX
     * before its first: a removed id may be given again once every user
     * that solved at all solved since its removal */
    uint32_t epoch;
    uint32_t removed_at[MAX_NODES], smooth_removed_at[MAX_SMOOTH];
    uint32_t users;
    uint32_t synced[MAX_USERS];
    uint32_t edits, held_edits; /* edits made and refused, for the curious */
} host_model;

/* Tallies of what the inputs reached, printed at exit when FUZZ_STATS is
 * set in the environment (to see that a corpus reaches the new paths). */
enum {
    TALLY_EDIT_OK,
    TALLY_EDIT_REFUSED,
    TALLY_HELD_REFUSED,
    TALLY_REMOVED_SUBTREE,
    TALLY_NODE_ID_REUSED,
    TALLY_SMOOTH_ID_REUSED,
    TALLY_HIDDEN_KNOWN,
    TALLY_HIDDEN_UNKNOWN,
    TALLY_BAD_BOUNDS,
    TALLY_QUERY_AABB,
    TALLY_QUERY_OBB,
    TALLY_LISTED_ADDITIVE_REFINED,
    TALLY_OVER_BUDGET,
    TALLY_ROOTS_DROPPED,
    TALLY_COUNT
};
void tally(int what);

/* Starts a model of an empty scene s with `users` users. */
void model_init(host_model *m, tclod_scene *s, uint32_t users);

/* User u solved (a committed selection, a successful scheduler update):
 * it names no id removed before now. */
void model_user_solved(host_model *m, uint32_t u);

/* Whether the header allows a node (smooth object) removed at epoch `at` to
 * be given again now. */
int model_reuse_allowed(const host_model *m, uint32_t at);

/* The nearest ancestor of live node v that draws (empty ones passed over):
 * its parent in the tree the solvers see; TCLOD_NONE for the roots. */
tclod_id drawn_parent(const host_model *m, tclod_id v);

/* Whether node id v is live and draws (neither empty, nor hidden, nor
 * removed). */
int model_draws(const host_model *m, tclod_id v);

/* Checks the scene against the model: id bounds, liveness of every id (and
 * of a few ids beyond), parents, and every live node's bounds read back. */
void verify_scene(const host_model *m);

/* A pending edit attempted from inside a callback (the probe carries it). */
struct edit;

/* What one selector's callbacks saw during the current select. */
typedef struct probe {
    const host_model *m;
    const tclod_view *frame_view;
    uint32_t benefit_calls[MAX_NODES], cost_calls[MAX_NODES];
    double benefit_seen[MAX_NODES], cost_seen[MAX_NODES];
    uint32_t calls;               /* every callback call */
    uint32_t bad;                 /* callback calls that returned a bad value or slope */
    int any_view;                 /* 1: queries may carry any valid view (the scheduler's
                                     predicted ones), and a node may be asked once per
                                     view: the once-per-select accounting is off */
    const struct edit *held_edit; /* tried (and refused) from the first callback of
                                     a select, kept across probe_reset */
    int held_edit_tried;
} probe;

/* Forgets what the probe saw, before a select with the given view. */
void probe_reset(probe *p, const tclod_view *view);

/* Whether a query carries the frame's view: none when the frame has none,
 * else the same numbers (the library may hold a copy). */
int same_view(const tclod_view *q, const tclod_view *frame);

/* A query about a node's own benefit or cost during the solve, as opposed
 * to the Robin Hood solver's complexity question (no view, the reference
 * area as screen area), which a normal query without a view never has: its
 * screen area is then -1. */
int is_complexity_query(const tclod_query *q);

/* Whether two volumes are the same: kind, and the fields of the kind bit for
 * bit. */
int same_bounds(const tclod_bounds *a, const tclod_bounds *b);

/* Stops the run when a node query breaks the header: an id that is not a
 * live node that draws, members, a view other than the frame's, a volume
 * other than the node's, screen area and distance other than the view
 * helpers give for it. */
void check_node_query(const probe *p, const tclod_query *q);

/* The callbacks, user = a probe: the model's values (benefit times the
 * screen area when the model says so), each call counted and checked; cost
 * only after a benefit > 0 in the same select. The first call of a select
 * tries the probe's held edit, which the scene must refuse. */
double host_benefit(void *user, const tclod_query *q);
/* benefit and cost's batch forms, through them */
void host_benefit_batch(void *user, const tclod_batch *b, double *out);
void host_cost_batch(void *user, const tclod_batch *b, double *out);
double host_cost(void *user, const tclod_query *q);
double host_complexity(void *user, const tclod_query *q);
double host_importance(void *user, const tclod_query *q);

/* The host's smooth value (cost != 0: cost) of a group at resolution r, the
 * sum over its members, and its slope in *d_dr. */
double smooth_value(const host_model *m, const tclod_query *q, double r, double *d_dr, int cost);

/* Stops the run when a smooth query breaks the header: r outside
 * [1e-9, 1], no d_dr, members that are not live distinct smooth objects,
 * a volume that is not the object's sphere (or one around the group). */
void check_smooth_query(const probe *p, const tclod_query *q, double r, const double *d_dr);

/* The smooth callbacks, user = a probe. */
double host_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr);
double host_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr);

/* An option value: 0 keeps the default, small bytes pick ordinary values,
 * the rest special ones (bad ones among them). */
double option_value(fuzz_reader *in, double def);

/* Whether the header promises TCLOD_ERR_ARG for this description over a
 * scene of `smooth` live smooth objects; -1 when it leaves the value open
 * (an infinite threshold, cull area or reference area: "NaN or out of
 * range" with ranges written as ">= 0" and "> 0"). */
int desc_invalid(const tclod_selector_desc *d, uint32_t smooth);
/* Whether tclod_calib_create must refuse d (1) or accept it (0). */
int calib_desc_invalid(const tclod_calib_desc *c);

/* Whether a selector of this (valid) description refuses to solve a scene of
 * `smooth` live smooth objects: the mixed solver without smooth callbacks. */
int smooth_callbacks_missing(const tclod_selector_desc *d, uint32_t smooth);

/* A selector description from the input: solver (sometimes an unknown
 * one), flags, value, misfit and overflow policies, options (sometimes out
 * of range), the host's callbacks with user NULL (the caller sets it). */
void read_desc(fuzz_reader *in, tclod_selector_desc *d, host_model *m);

/* Whether bounds are bad for the header: not finite, or radius < 0. */
int bounds_bad(const float b[4]);

/* Sphere bounds (x, y, z, radius) from the input, bad ones among them. */
void read_bounds(fuzz_reader *in, float b[4]);

/* A node's volume from the input: none, a sphere, an axis-aligned or an
 * oriented box, valid or not (NaN, infinities, negative extents, skewed
 * axes). Returns what tclod_bounds_validate must say: 0 valid, 1 invalid,
 * -1 open (an axis so long its length overflows, or skewed right at the
 * tolerance). */
int read_node_bounds(fuzz_reader *in, tclod_bounds *b);

/* The header's verdict on a volume, as read_node_bounds returns it. */
int bounds_verdict(const tclod_bounds *b);

/* A node to add, read whole before it is tried. */
typedef struct node_spec {
    tclod_node_desc desc;
    int short_form; /* tclod_scene_add_node with `sphere` (has_sphere) or NULL */
    int has_sphere;
    float sphere[4];
    int verdict;  /* bounds_verdict of desc.bounds (or of the sphere) */
    int bad_enum; /* refine or empty out of range */
    double benefit, cost, complexity;
} node_spec;

/* A smooth object to add. */
typedef struct smooth_spec {
    float bounds[4];
    smooth_model sm;
    double complexity;
} smooth_spec;

enum {
    EDIT_REMOVE_NODE = 0,
    EDIT_REMOVE_SMOOTH = 1,
    EDIT_MOVE_NODE = 2,
    EDIT_MOVE_SMOOTH = 3,
    EDIT_ADD_NODE = 4,
    EDIT_ADD_SMOOTH = 5,
    EDIT_REMOVE_TWICE = 6,
    EDIT_HIDDEN = 7 /* an additive node's hidden id: removed, moved or given a child */
};

/* One edit of the scene, read whole before it is tried. */
typedef struct edit {
    uint8_t op;  /* EDIT_* */
    uint8_t sub; /* EDIT_HIDDEN: 0 remove, 1 move, 2 add a child */
    tclod_id id;
    int null_bounds; /* move a node with NULL bounds (none) */
    tclod_bounds bounds;
    int verdict;
    float sphere[4];
    node_spec node;
    smooth_spec smooth;
} edit;

/* A node to add, read from the input (the parent: a live node, a root, an
 * id that is removed or hidden, or one that does not exist). */
void read_node_spec(fuzz_reader *in, const host_model *m, node_spec *ns);

/* A smooth object to add. */
void read_smooth_spec(fuzz_reader *in, smooth_spec *ss);

/* An edit from the input. */
void read_edit(fuzz_reader *in, const host_model *m, edit *e);

/* Tries an edit. held = 0: between frames; the status must be what the
 * model predicts (an error exactly when the edit is bad, and then nothing
 * changes), and on success the model follows. held = 1: a solve holds the
 * scene (a pending resumable solve, or a callback): the status must be
 * TCLOD_ERR_STATE (or the edit's own error when it is bad) and nothing
 * changes. The scene is checked against the model after either. */
void try_edit(host_model *m, const edit *e, int held);

/* try_edit with held = 1 (the model is only read). */
void try_held_edit(const host_model *m, const edit *e);

/* Adds a node (smooth object) as the input says, as try_edit does with
 * held = 0; nothing when the model's id space is full. */
void add_node(fuzz_reader *in, host_model *m);
/* The same with tclod_node_desc.unexpanded = 1 (a replace node with no size;
 * one byte in 8 also empty, which the scene refuses). */
void add_unexpanded(fuzz_reader *in, host_model *m);
void add_smooth(fuzz_reader *in, host_model *m);

/* Whether the header requires tclod_view_validate to accept (1) or reject
 * (0) v; -1 when forward and up are so close to parallel that either is
 * right. */
int view_valid(const tclod_view *v);

/* A view: none, one of the shared flyover loop's, or one made of the input. */
const tclod_view *read_view(fuzz_reader *in, tclod_view *v);

/* The view helpers on a valid view and the nodes' and smooth objects'
 * bounds: visible 0 or 1, areas in [0, viewport area], distances >= 0,
 * never NaN. */
void check_view_helpers(const tclod_view *v, const host_model *m);

/* Defines the libFuzzer entry point: run(&reader) over the input. */
#define FUZZ_ENTRY(run)                                            \
    int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);  \
    int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { \
        fuzz_reader in;                                            \
        fuzz_reader_init(&in, data, size);                         \
        run(&in);                                                  \
        return 0;                                                  \
    }

#endif /* FUZZ_HOST_H */
