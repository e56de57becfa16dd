/*
 * libtclod — time-critical level-of-detail selection.
 *
 * Every frame a host engine asks libtclod which representation of each object
 * to draw so that the frame fits its time budget and looks as good as possible.
 * The host describes its objects as a scene (LOD hierarchies of discrete nodes,
 * and smooth objects with a continuous resolution) and supplies two callbacks,
 * benefit and cost; a selector returns a selection whose predicted cost never
 * exceeds the budget. libtclod draws nothing and knows no graphics API.
 *
 * Conventions used throughout this header:
 *  - Every function that can fail returns a tclod_status and writes its outputs
 *    only on success; on failure nothing observable changes.
 *  - Ids are dense indices starting at 0, below tclod_scene_node_count (nodes)
 *    or tclod_scene_smooth_count (smooth objects): a host may index its own
 *    arrays with them. Nodes and smooth objects have separate id spaces. A
 *    removed id is given again only once every selector and scheduler over
 *    the scene has solved since the removal (docs/scenes.md, ids).
 *  - Costs and budgets are in the host's unit (milliseconds in all examples).
 *  - No global state. A scene may be read by several selectors at once (also
 *    from several threads) while nobody modifies it; a selector is used by one
 *    thread at a time.
 *
 * C99. Compiles as C++.
 */
#ifndef TCLOD_H
#define TCLOD_H

#include <stddef.h>
#include <stdint.h>

#define TCLOD_VERSION_MAJOR 0
#define TCLOD_VERSION_MINOR 6
#define TCLOD_VERSION_PATCH 0
/* MAJOR * 10000 + MINOR * 100 + PATCH, what tclod_version() returns. */
#define TCLOD_VERSION_NUMBER \
    (TCLOD_VERSION_MAJOR * 10000 + TCLOD_VERSION_MINOR * 100 + TCLOD_VERSION_PATCH)

/* Export macro. Define TCLOD_STATIC when linking the static library on Windows. */
#if defined(_WIN32) && !defined(TCLOD_STATIC)
#if defined(TCLOD_BUILDING)
#define TCLOD_API __declspec(dllexport)
#else
#define TCLOD_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define TCLOD_API __attribute__((visibility("default")))
#else
#define TCLOD_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------- */
/* Basics                                                                    */
/* ------------------------------------------------------------------------- */

/* Index of a node or of a smooth object. */
typedef uint32_t tclod_id;

/* The most features a cost model takes (tclod_selector_desc.feature_count,
 * tclod_calib_desc.feature_count; docs/calibration.md, the learned cost). */
#define TCLOD_MAX_FEATURES 8u
/* "No node": the parent of a root, and the invalid id. */
#define TCLOD_NONE ((tclod_id)0xffffffffu)

/* Result of every fallible call. The values are stable and never renumbered. */
typedef enum tclod_status {
    TCLOD_OK = 0,
    TCLOD_ERR_ARG = 1,       /* NULL where not allowed, id out of range, bad option value */
    TCLOD_ERR_NOMEM = 2,     /* an allocation failed; nothing was changed */
    TCLOD_ERR_HIERARCHY = 3, /* unknown parent, or the change would make a cycle */
    TCLOD_ERR_CALLBACK = 4,  /* strict mode only: a callback returned NaN, inf or < 0 */
    TCLOD_ERR_STATE = 5      /* call out of order, or re-entered from a callback */
} tclod_status;

/* Short English description of a status ("ok", "invalid argument", ...).
 * Never NULL; an unknown value gives "unknown status". The string is static. */
TCLOD_API const char *tclod_status_string(tclod_status s);

/* Why a call failed (docs/api.md, errors). Every object keeps the message of
 * its last call that failed, "function: what was wrong" (the argument or
 * field and the rule it broke), until another call on it fails; "" before
 * any failure and for NULL. Calls that fail on a NULL object, and calls that
 * take a const object, record nothing. A desc, view or bounds refused by a
 * create or an add is named by tclod_*_check. Functions:
 * tclod_scene_last_error, tclod_selector_last_error, tclod_scheduler_last_error
 * and tclod_calib_last_error. */

/* Version of the built library, as TCLOD_VERSION_NUMBER. Compare it with the
 * header's macro to detect a header/library mismatch. */
TCLOD_API unsigned tclod_version(void);
/* Version of the built library as "MAJOR.MINOR.PATCH". Static string. */
TCLOD_API const char *tclod_version_string(void);

/* Optional memory hooks, one per scene or selector. Either both functions are
 * set or both are NULL (NULL = malloc/free). free receives the size that was
 * passed to alloc. alloc must return memory aligned for any type (like malloc)
 * or NULL on failure; libtclod then returns TCLOD_ERR_NOMEM. */
typedef struct tclod_allocator {
    void *(*alloc)(size_t size, void *ctx);
    void (*free)(void *ptr, size_t size, void *ctx);
    void *ctx; /* passed through unchanged */
} tclod_allocator;

/* ------------------------------------------------------------------------- */
/* Views                                                                     */
/* ------------------------------------------------------------------------- */

/* A perspective camera. forward and up need not be unit length or exactly
 * orthogonal (they are orthonormalised), but must not be zero or parallel. */
typedef struct tclod_view {
    double eye[3];         /* world position (double: earth-centred coordinates
                              keep millimetres, docs/scenes.md) */
    float forward[3];      /* viewing direction */
    float up[3];           /* approximate up direction */
    float fov_y;           /* vertical field of view, radians, in (0, pi) */
    float aspect;          /* width / height, > 0 */
    float near_z, far_z;   /* clip distances along forward, 0 < near_z < far_z */
    float viewport_height; /* pixels, > 0 */
} tclod_view;

/* Checks a view: finite numbers, non-degenerate directions, ranges above.
 * Returns TCLOD_OK or TCLOD_ERR_ARG (also for view == NULL). */
TCLOD_API tclod_status tclod_view_validate(const tclod_view *view);

/* NULL when the view is valid, else the rule it breaks ("view->fov_y must be
 * in (0, pi)"). */
TCLOD_API const char *tclod_view_check(const tclod_view *view);

/* Bounding volumes of nodes (docs/scenes.md, bounds). Every kind has a
 * world-space centre in double. */
typedef enum tclod_bounds_kind {
    TCLOD_BOUNDS_NONE = 0,   /* no bounds: queries carry screen_area and distance -1 */
    TCLOD_BOUNDS_SPHERE = 1, /* centre and radius */
    TCLOD_BOUNDS_AABB = 2,   /* axis-aligned box: centre and half extents */
    TCLOD_BOUNDS_OBB = 3     /* oriented box: centre and three half axes (3D Tiles' box) */
} tclod_bounds_kind;

/* A bounding volume; only the fields of its kind are read. */
typedef struct tclod_bounds {
    tclod_bounds_kind kind;
    double center[3];       /* world position */
    double radius;          /* SPHERE: >= 0 */
    double half_extents[3]; /* AABB: half sizes along x, y, z, each >= 0 */
    double half_axes[3][3]; /* OBB: half_axes[i] goes from the centre to the middle of
                               a face; mutually orthogonal (|cos| <= 1e-3 between
                               non-zero axes); zero axes allowed (a flat box) */
} tclod_bounds;

/* Constructors: a sphere; an axis-aligned box (half_extents: 3 values); an
 * oriented box (half_axes: 9 values, three axes of x, y, z). No checks: see
 * tclod_bounds_validate. */
TCLOD_API tclod_bounds tclod_bounds_sphere(double x, double y, double z, double radius);
TCLOD_API tclod_bounds tclod_bounds_aabb(const double center[3], const double half_extents[3]);
TCLOD_API tclod_bounds tclod_bounds_obb(const double center[3], const double half_axes[9]);

/* Checks a bounding volume: a known kind, finite numbers, radius and half
 * extents >= 0, orthogonal half axes. Returns TCLOD_OK or TCLOD_ERR_ARG (also
 * for NULL). Kind NONE is valid. */
TCLOD_API tclod_status tclod_bounds_validate(const tclod_bounds *b);

/* NULL when the volume is valid, else the rule it breaks ("bounds.radius must
 * be finite and >= 0"). */
TCLOD_API const char *tclod_bounds_check(const tclod_bounds *b);

/* 1 if bounds b intersects the view frustum (the six planes), 0 if it lies
 * wholly outside. Conservative near frustum corners. NONE is visible.
 * Preconditions: a valid view, valid bounds. */
TCLOD_API int tclod_view_bounds_visible(const tclod_view *view, const tclod_bounds *b);

/* Projected area of b in pixels² (the query's screen_area, without the
 * frustum test): a sphere as pi r_px², r_px = f r / sqrt(d² - r²) with
 * f = (viewport_height / 2) / tan(fov_y / 2); a box as the area of its
 * silhouette (its faces towards the eye, clipped at the near plane). At most
 * the viewport's area (viewport_height² * aspect), which it is when the eye is
 * inside. -1 for NONE. Preconditions: a valid view, valid bounds. */
TCLOD_API double tclod_view_bounds_area(const tclod_view *view, const tclod_bounds *b);

/* Distance from the eye to b: 0 inside, else to the nearest point of the
 * sphere or box (what 3D Tiles' screen-space error divides by). -1 for NONE.
 * Preconditions: a valid view, valid bounds. */
TCLOD_API double tclod_view_bounds_distance(const tclod_view *view, const tclod_bounds *b);

/* The same three for a sphere given as floats (x, y, z, radius). */
TCLOD_API int tclod_view_sphere_visible(const tclod_view *view, const float bounds[4]);
TCLOD_API float tclod_view_screen_area(const tclod_view *view, const float bounds[4]);
TCLOD_API float tclod_view_distance(const tclod_view *view, const float bounds[4]);

/* ------------------------------------------------------------------------- */
/* Callbacks                                                                 */
/* ------------------------------------------------------------------------- */

/* What a callback is asked about. Valid only during the call. */
typedef struct tclod_query {
    tclod_id id;                /* node id, or first smooth object of a group */
    uint32_t count;             /* smooth objects in the group (1 for nodes) */
    const tclod_view *view;     /* the frame's view; NULL when the frame has none */
    float screen_area;          /* projected bounds in px² (tclod_view_bounds_area); 0
                                   when the bounds are outside the frustum; -1 when
                                   no bounds or no view */
    float distance;             /* eye to the bounds, 0 inside
                                   (tclod_view_bounds_distance, in float: 0.5 mm at
                                   10 km); -1 when no bounds or no view */
    const tclod_id *members;    /* smooth queries: the count member ids of the group, in
                                   the scene's smooth order (members[0] == id); the
                                   array belongs to the scene. NULL for nodes */
    const tclod_bounds *bounds; /* the volume screen_area and distance were measured on,
                                   its kind saying which: the node's or object's, or
                                   the sphere around a group's members; NULL without
                                   bounds */
} tclod_query;

/* What a batch callback is asked about: count nodes, as arrays of count
 * entries (docs/api.md, batch evaluation). Valid only during the call. */
typedef struct tclod_batch {
    uint32_t count;
    const tclod_id *ids;      /* node ids, each once (an additive node's own drawing:
                                 the additive node's id) */
    const float *screen_area; /* as tclod_query.screen_area, per node */
    const float *distance;    /* as tclod_query.distance, per node */
    const tclod_view *view;   /* the frame's view; NULL when the frame has none */
    uint32_t worker;          /* the worker that calls (tclod_tasks; 0 when serial) */
} tclod_batch;

/* The host's model of quality and render time (docs/api.md, callbacks). Each
 * is called at most once per node per select. Callbacks may read anything but
 * must not call into the selector that calls them nor edit the scene
 * (TCLOD_ERR_STATE). NaN, inf and negative values are counted in
 * tclod_stats.invalid_values and sanitised (a bad benefit: invisible; a bad
 * cost: never selected), or fail the call in strict mode. */
typedef struct tclod_callbacks {
    /* Visual quality of drawing node q->id, >= 0; 0 = invisible: culled with
     * its subtree. Required. */
    double (*benefit)(void *user, const tclod_query *q);
    /* Predicted render time of node q->id in budget units, >= 0; asked only
     * when its benefit is > 0. Required. */
    double (*cost)(void *user, const tclod_query *q);
    /* Benefit and cost of a smooth object, or of a group of q->count objects
     * sharing resolution r in [0, 1], with d/dr in *d_dr (never NULL; r >=
     * 1e-9 when a slope is asked). Benefit concave, cost nondecreasing and 0
     * at r = 0. Required by the mixed solver over smooth objects; NULL: they
     * are not drawn (TCLOD_NOTE_SMOOTH_IGNORED). */
    double (*smooth_benefit)(void *user, const tclod_query *q, double r, double *d_dr);
    double (*smooth_cost)(void *user, const tclod_query *q, double r, double *d_dr);
    void *user; /* passed to every callback unchanged */
    /* Robin Hood solver, optional: how costly instance q->id is to draw well,
     * asked once per instance after the scene changed, with no view. NULL:
     * the cost of its finest representation, as the next select asks it (at
     * robin_hood.reference_area with no view when that select does not see
     * it), so that no cost is asked twice (docs/robin_hood.md, the pass). */
    double (*complexity)(void *user, const tclod_query *q);
    /* Robin Hood solver, optional: the importance I the value functions
     * multiply ([RH eq. 8-11]), >= 0, asked once per visible instance per
     * select. NULL: its benefit. A benefit that grows with screen area counts
     * the area twice: give the per-object weight here (docs/robin_hood.md). */
    double (*importance)(void *user, const tclod_query *q);
    /* Streaming, optional: the size in bytes node (or smooth object) q->id
     * will take once loaded, asked once per select for a non-resident one the
     * scene knows no size of (0) when the select ranks it as a load request.
     * NULL: the scene's size. A bad value is counted and the node is not
     * requested (docs/streaming.md). */
    double (*bytes)(void *user, const tclod_query *q);
    /* Optional batch forms of benefit and cost: out[i] is the value of node
     * b->ids[i], as the per-node callback would return it for the same query
     * (what is valid, sanitised and counted is the same; out holds NaN on
     * entry, so an entry left unwritten is a bad value). cost_batch is asked
     * only of nodes whose benefit is > 0 and finite. The greedy solver gathers
     * the nodes it evaluates together (a warm start's frontier, the children of
     * what an increment adds) into batches; elsewhere, and when a form is NULL,
     * the per-node callbacks are asked, which stay required. Selections are
     * bit-identical either way (docs/api.md, batch evaluation). */
    void (*benefit_batch)(void *user, const tclod_batch *b, double *out);
    void (*cost_batch)(void *user, const tclod_batch *b, double *out);
    /* Optional cost from features (docs/calibration.md, the learned cost):
     * the selector's feature_count features of drawing node q->id (draws,
     * vertices, splats, ...: what the host counts while it draws, each >= 0
     * and finite) into out, which holds NaN on entry (an entry left unwritten
     * is a bad value). The node's cost is then coefficients · features
     * (tclod_selector_desc.coefficients, tclod_selector_set_coefficients),
     * plus the cost callback's value when that is set too: cost may be NULL.
     * A bad feature is a bad cost. With features, cost_batch is not asked. */
    void (*features)(void *user, const tclod_query *q, double *out);
    /* The same for a smooth object or group at resolution r: its features
     * into out and their d/dr into d_dr (feature_count entries each, NaN on
     * entry), every feature nondecreasing in r and 0 at r = 0. Its cost is
     * coefficients · out, plus smooth_cost when set: smooth_cost may be NULL. */
    void (*smooth_features)(void *user, const tclod_query *q, double r, double *out, double *d_dr);
} tclod_callbacks;

/* ------------------------------------------------------------------------- */
/* Scene                                                                     */
/* ------------------------------------------------------------------------- */

/* Structure only: nodes of one or more LOD hierarchies, and smooth objects
 * (docs/scenes.md). The host adds, removes and moves them between frames; a
 * selector's next warm solve picks the changes up (its work grows with the
 * changes, not with the scene). No change is allowed while a selector over the
 * scene has a solve begun, or from a callback: TCLOD_ERR_STATE. */
typedef struct tclod_scene tclod_scene;

/* Creates an empty scene. a may be NULL (malloc/free); it is copied. */
TCLOD_API tclod_status tclod_scene_create(const tclod_allocator *a, tclod_scene **out);

/* Frees the scene. NULL is allowed (TCLOD_OK). Errors: TCLOD_ERR_STATE while a
 * selector or scheduler created over it is alive (the scene is then not freed;
 * destroy them first). */
TCLOD_API tclod_status tclod_scene_destroy(tclod_scene *s);

/* Why the last failed call on s failed (see tclod_status_string). */
TCLOD_API const char *tclod_scene_last_error(const tclod_scene *s);

/* How a node's children refine it (docs/scenes.md, refinement). */
typedef enum tclod_refine {
    TCLOD_REFINE_REPLACE = 0, /* the children together replace the node (terrain quadtrees,
                                 an object's levels, 3D Tiles REPLACE) */
    TCLOD_REFINE_ADD = 1      /* the node stays drawn and its children add to it
                                 (point-cloud octrees, 3D Tiles ADD) */
} tclod_refine;

/* A node to add. Start from tclod_node_desc_default, not from zeros: parent 0
 * is node 0, the default parent is TCLOD_NONE. */
typedef struct tclod_node_desc {
    tclod_id parent;     /* TCLOD_NONE: the root of a new hierarchy; else a live node.
                            Default TCLOD_NONE */
    tclod_bounds bounds; /* kind TCLOD_BOUNDS_NONE: no bounds (queries carry -1).
                            Default none */
    tclod_refine refine; /* Default TCLOD_REFINE_REPLACE */
    int empty;           /* 1: nothing to draw (a grouping node, a tile without
                            content): never drawn, costs nothing, no callback asks
                            about it, its children are selected as if they hung
                            from its parent (or were roots). Default 0 */
    int not_resident;    /* 1: its data is not loaded: never drawn until
                            tclod_scene_set_resident (docs/streaming.md). Default 0 */
    double bytes;        /* its size once resident, >= 0 and finite (0: not known
                            yet). Default 0 */
    int unexpanded;      /* 1: it stands for a part of the hierarchy not read yet (an
                            external tileset, an implicit subtree): a leaf, never
                            drawn, that the load plan values as what reading it
                            draws first (its callbacks, as any node's) and lists
                            with TCLOD_STREAM_EXPAND for bytes (the file's size).
                            Once read, the host removes it and adds what it read in
                            its place (docs/streaming.md, hierarchy on demand). Not
                            with empty; no child can be added below it. Default 0 */
} tclod_node_desc;

/* Fills d with the defaults above. */
TCLOD_API void tclod_node_desc_default(tclod_node_desc *d);

/* Adds a node described by d. Errors: TCLOD_ERR_ARG (s, d or out_id NULL; bounds
 * rejected by tclod_bounds_validate; refine, empty or unexpanded out of range;
 * unexpanded and empty), TCLOD_ERR_HIERARCHY (parent neither TCLOD_NONE nor a
 * live node, or unexpanded),
 * TCLOD_ERR_STATE (a solve holds the scene), TCLOD_ERR_NOMEM. An additive node
 * that is not empty takes a second id for its own drawing among its children,
 * which no call returns (docs/scenes.md, ids). */
TCLOD_API tclod_status tclod_scene_add_node_desc(tclod_scene *s, const tclod_node_desc *d,
                                                 tclod_id *out_id);

/* The short form: a replace node with a sphere (x, y, z, radius; NULL: no
 * bounds). Errors as tclod_scene_add_node_desc (bounds not finite, radius < 0:
 * TCLOD_ERR_ARG). */
TCLOD_API tclod_status tclod_scene_add_node(tclod_scene *s, tclod_id parent, const float bounds[4],
                                            tclod_id *out_id);

/* The largest magnitude of a smooth object's coordinates and radius. */
#define TCLOD_SMOOTH_LIMIT 1e30f

/* Adds a smooth object (continuous resolution r in [0, 1]). bounds: x, y, z,
 * radius, required (its ground position x, z places it in the quadtree), each
 * at most TCLOD_SMOOTH_LIMIT in magnitude, radius >= 0. Errors as
 * tclod_scene_add_node (TCLOD_ERR_ARG also beyond the limit), without
 * TCLOD_ERR_HIERARCHY. */
TCLOD_API tclod_status tclod_scene_add_smooth(tclod_scene *s, const float bounds[4],
                                              tclod_id *out_id);

/* Removes a node with its whole subtree. Removed ids never appear in a later
 * result. Errors: TCLOD_ERR_ARG (s NULL, node not a live node: unknown, removed
 * already, or an id no call returned), TCLOD_ERR_STATE (a solve holds the
 * scene); nothing changes on error. */
TCLOD_API tclod_status tclod_scene_remove_node(tclod_scene *s, tclod_id node);

/* Removes a smooth object. Errors as tclod_scene_remove_node. */
TCLOD_API tclod_status tclod_scene_remove_smooth(tclod_scene *s, tclod_id smooth);

/* Moves a node: new bounds (NULL or kind NONE: none). Errors: TCLOD_ERR_ARG (s
 * NULL, node not live, bounds rejected by tclod_bounds_validate),
 * TCLOD_ERR_STATE, TCLOD_ERR_NOMEM (a box where there was none); nothing
 * changes on error. */
TCLOD_API tclod_status tclod_scene_set_node_bounds(tclod_scene *s, tclod_id node,
                                                   const tclod_bounds *bounds);

/* Moves a smooth object (bounds x, y, z, radius, required): it may change
 * quadtree cell. Errors as tclod_scene_set_node_bounds. */
TCLOD_API tclod_status tclod_scene_set_smooth_bounds(tclod_scene *s, tclod_id smooth,
                                                     const float bounds[4]);

/* A node's bounds into *out. Errors: TCLOD_ERR_ARG (NULL argument, node not
 * live). */
TCLOD_API tclod_status tclod_scene_node_bounds(const tclod_scene *s, tclod_id node,
                                               tclod_bounds *out);

/* Builds now what selectors build on demand after the scene changed (the smooth
 * quadtree; the node order Robin Hood selectors and schedulers read). Optional;
 * call it after changing a scene that several threads then select from
 * concurrently. Errors: TCLOD_ERR_ARG (NULL), TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_scene_prepare(tclod_scene *s);

/* The live smooth objects in the scene's quadtree order: groups of smooth
 * objects (tclod_query.members, tclod_smooth_group) are contiguous ranges of
 * it. The quadtree is built over the objects' ground positions (x, z) when the
 * scene is prepared, so this prepares the scene if it changed. *order points
 * into the scene: valid until the scene next changes or is destroyed. Errors:
 * TCLOD_ERR_ARG (NULL argument), TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_scene_smooth_order(tclod_scene *s, const tclod_id **order,
                                                uint32_t *count);

/* The id bounds: every node id is below tclod_scene_node_count, every smooth
 * id below tclod_scene_smooth_count (0 for NULL); size the host's arrays by
 * them. Removed ids and those an additive node takes for itself count too. */
TCLOD_API uint32_t tclod_scene_node_count(const tclod_scene *s);
TCLOD_API uint32_t tclod_scene_smooth_count(const tclod_scene *s);
/* 1 when node (smooth object) is live: added and not removed. 0 otherwise. */
TCLOD_API int tclod_scene_node_live(const tclod_scene *s, tclod_id node);
TCLOD_API int tclod_scene_smooth_live(const tclod_scene *s, tclod_id smooth);
/* Parent of a live node; TCLOD_NONE for a root or an id that is not live. */
TCLOD_API tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node);

/* Streaming (docs/streaming.md): a node or smooth object is drawn only while
 * resident (its data loaded). Every node is resident unless added with
 * not_resident or marked otherwise here. Each call is O(1) and changes no
 * selection state: a select picks the residency up as it evaluates. Errors:
 * TCLOD_ERR_ARG (s NULL; node not a live node; resident not 0 or 1; node
 * unexpanded),
 * TCLOD_ERR_STATE (a solve holds the scene, or from a callback); nothing
 * changes on error. */
TCLOD_API tclod_status tclod_scene_set_resident(tclod_scene *s, tclod_id node, int resident);
TCLOD_API tclod_status tclod_scene_set_smooth_resident(tclod_scene *s, tclod_id smooth,
                                                       int resident);
/* Sets the size in bytes a node (smooth object) takes once resident: >= 0 and
 * finite, at most FLT_MAX (0: not known yet; tclod_callbacks.bytes may then
 * estimate it). Errors as tclod_scene_set_resident (bytes out of range:
 * TCLOD_ERR_ARG). */
TCLOD_API tclod_status tclod_scene_set_node_bytes(tclod_scene *s, tclod_id node, double bytes);
TCLOD_API tclod_status tclod_scene_set_smooth_bytes(tclod_scene *s, tclod_id smooth, double bytes);
/* 1 when node (smooth object) is live and resident, else 0. */
TCLOD_API int tclod_scene_node_resident(const tclod_scene *s, tclod_id node);
TCLOD_API int tclod_scene_smooth_resident(const tclod_scene *s, tclod_id smooth);
/* The size set for a live node (smooth object); 0 otherwise. */
TCLOD_API double tclod_scene_node_bytes(const tclod_scene *s, tclod_id node);
TCLOD_API double tclod_scene_smooth_bytes(const tclod_scene *s, tclod_id smooth);
/* The sizes of the live resident nodes and smooth objects, summed (0 for NULL). */
TCLOD_API double tclod_scene_resident_bytes(const tclod_scene *s);

/* ------------------------------------------------------------------------- */
/* Selector                                                                  */
/* ------------------------------------------------------------------------- */

typedef enum tclod_solver {
    TCLOD_SOLVER_GREEDY = 0,    /* Mason–Blake increments with fill, decrements, coherence */
    TCLOD_SOLVER_MIXED = 1,     /* discrete increments + gradient ascent on smooth objects */
    TCLOD_SOLVER_ROBIN_HOOD = 2 /* proportional time distribution: one pass of shares, then a
                                  few bounded passes over what they leave */
} tclod_solver;

/* Value functions of the Robin Hood solver ([RH eq. 8-11]): how an
 * instance's share of the render time follows its size and place. a is the
 * instance's un-projected area (pi r² of its bounds), z its depth along the
 * view direction, d its distance from the eye, I its importance: the
 * importance callback's value for the instance, or without one its benefit
 * (the benefit callback's for its first node, smooth_benefit at r = 1 for a
 * smooth object). */
typedef enum tclod_value {
    TCLOD_VALUE_AREA_SQRT_DEPTH = 0,     /* a / sqrt(z) * I (eq. 8): even shares */
    TCLOD_VALUE_AREA_DEPTH = 1,          /* a / z * I (eq. 9) */
    TCLOD_VALUE_AREA_DEPTH2 = 2,         /* a / z² * I (eq. 10): near objects first */
    TCLOD_VALUE_SQRT_AREA_DISTANCE2 = 3, /* sqrt(a) / d² * I (eq. 11): the screen's middle */
    TCLOD_VALUE_BENEFIT = 4              /* I alone: the host's own value */
} tclod_value;

/* What the Robin Hood solver does with an instance whose simplest
 * representation costs more than its share. */
typedef enum tclod_misfit {
    TCLOD_MISFIT_DROP = 0,    /* not drawn; its share goes on to the instances after it
                                 ([RH §5.2]) */
    TCLOD_MISFIT_COARSEST = 1 /* drawn at its simplest representation when the render
                                 time still left covers it, else not drawn */
} tclod_misfit;

/* What a solve does when even the coarsest representation of every visible
 * hierarchy (its root, or below empty roots the first nodes that draw) does not
 * fit the budget (docs/scenes.md, overflow). */
typedef enum tclod_overflow {
    TCLOD_OVERFLOW_DROP_ROOTS = 0, /* the guarantee: the lowest-value roots are left out
                                      until the rest fits (tclod_stats.dropped_roots,
                                      stop reason TCLOD_STOP_ROOTS_DROPPED) */
    TCLOD_OVERFLOW_DRAW_ROOTS = 1  /* every visible root is drawn at its coarsest, over
                                      the budget, and tclod_stats.over_budget says so:
                                      the only way a selection may exceed its budget */
} tclod_overflow;

/* Options of the discrete increments: the greedy solver's, and the mixed
 * solver's increments on nodes (docs/greedy.md, lookahead and restarts). */
typedef struct tclod_greedy_desc {
    uint32_t lookahead; /* levels below a node's children one increment may reach,
                           0 .. TCLOD_MAX_LOOKAHEAD. 0 (default): one level, the
                           papers' increment; 2 finds refinements whose first
                           step gains little, at about the branching factor
                           more work per level */
    int32_t restarts;   /* cold solves: passes after the plain greedy pass that
                           look for a better selection (the half-optimum
                           guarantee, then a bounded search), 1 ..
                           TCLOD_MAX_RESTARTS. 0: default 32; TCLOD_OFF: none */
    int32_t fallback;   /* warm starts: 0 (default) or 1: while warm solves do more
                           work than cold ones, solves start from the roots for a
                           while, and every 32nd warm solve (no frame limits, no
                           lookahead, no streaming) is followed by a cold one, which
                           is kept when it has more benefit (TCLOD_NOTE_COLD_FALLBACK; docs/greedy.md,
                           falling back). TCLOD_OFF: every solve after the first
                           starts warm and stays so */
} tclod_greedy_desc;

/* Options of the mixed solver's smooth variables (docs/mixed.md). */
typedef struct tclod_mixed_desc {
    int split_smooth;        /* 1: nearby smooth objects share a variable while the
                                predicted loss allows (quadtree splitting);
                                0 (default): a variable per visible object */
    double split_threshold;  /* theta, with split_smooth: the benefit loss allowed,
                                as a fraction of the smooth objects' benefit, > 0.
                                0: default 0.1; TCLOD_OFF: only groups of alike
                                objects */
    int plain_gradient;      /* 1: the papers' line search on the plain gradient;
                                0 (default): with a per-variable model of slope
                                and cost (a diagonal preconditioner) */
    double smooth_epsilon;   /* plain_gradient: barrier of the search direction
                                ([Thesis8 eq. 8.13]), in (0, 1). 0: default 1e-3;
                                TCLOD_OFF: none */
    double smooth_tolerance; /* plain_gradient: how far below slope_d a line search
                                may take the slope ([Thesis8 eq. 8.14]), in (0, 1).
                                0: default 0.05; TCLOD_OFF: exactly eq. 8.14 */
} tclod_mixed_desc;

/* Options of the Robin Hood solver (docs/robin_hood.md). */
typedef struct tclod_robin_hood_desc {
    tclod_value value;     /* how shares follow size and place. Default
                              TCLOD_VALUE_AREA_SQRT_DEPTH */
    tclod_misfit misfit;   /* instances whose coarsest representation exceeds their
                              share. Default TCLOD_MISFIT_DROP */
    double reference_area; /* px²: where an instance's complexity is measured when
                              callbacks.complexity is NULL, > 0. 0: default 10000 */
} tclod_robin_hood_desc;

/* A task of the library for the host's task system: items [start, end) of it,
 * run by worker `worker` (< tclod_tasks.worker_count). */
typedef void tclod_task_fn(uint32_t start, uint32_t end, uint32_t worker, void *task_ctx);

/* The host's worker threads (docs/api.md, worker threads): the library never
 * creates threads; it splits evaluation into tasks the host runs. A zeroed
 * struct is serial. */
typedef struct tclod_tasks {
    uint32_t worker_count; /* workers, the calling thread's included, at most
                              TCLOD_MAX_WORKERS; 0 or 1: serial (enqueue and finish
                              not called) */
    /* Runs task over items [0, item_count): calls it on ranges of at least
     * min_range items (the last may be shorter) that cover each item once,
     * at most worker_count at a time, each with a worker index no range
     * running at the same time has. Returns a handle for finish, or NULL when
     * every range has run before it returns. (Nodes of a range left out or
     * run with an index >= worker_count are evaluated on the calling thread
     * after finish: TCLOD_NOTE_TASKS_MISSED; nodes a range runs again after
     * another ran them are not: TCLOD_NOTE_TASKS_REPEATED.) */
    void *(*enqueue)(tclod_task_fn *task, uint32_t item_count, uint32_t min_range, void *task_ctx,
                     void *user);
    /* Returns once every range of the task enqueue returned `task` for ran. */
    void (*finish)(void *task, void *user);
    void *user; /* passed to enqueue and finish unchanged */
} tclod_tasks;

/* The largest tclod_tasks.worker_count. */
#define TCLOD_MAX_WORKERS 64u

/* How a selector solves. A zeroed desc with the benefit and cost callbacks set
 * is a working greedy selector: every field left 0 takes its default.
 * TCLOD_OFF asks for 0 (none, off) where the default is not 0. */
typedef struct tclod_selector_desc {
    tclod_solver solver;              /* default TCLOD_SOLVER_GREEDY */
    tclod_callbacks callbacks;        /* benefit and cost required */
    int cold_start;                   /* 1: every solve starts from the roots. 0 (default):
                                         the greedy solver starts from the previous
                                         selection (warm start, docs/api.md) */
    int strict;                       /* 1: a bad callback value fails the call with
                                         TCLOD_ERR_CALLBACK. 0 (default): it is sanitised
                                         and counted (tclod_stats.invalid_values) */
    tclod_overflow overflow;          /* when even the visible roots do not fit. Default
                                         TCLOD_OVERFLOW_DROP_ROOTS */
    double smooth_cull_area;          /* mixed and Robin Hood solvers: smooth objects and
                                         groups projecting to fewer px² are not drawn.
                                         0: default 1; TCLOD_OFF: no culling */
    tclod_greedy_desc greedy;         /* greedy and mixed solvers */
    tclod_mixed_desc mixed;           /* mixed solver */
    tclod_robin_hood_desc robin_hood; /* Robin Hood solver */
    tclod_tasks tasks;                /* the host's worker threads; zeroed: serial. With
                                         worker_count > 1, callbacks that evaluate nodes
                                         (benefit, cost and their batch forms) are called
                                         from the workers at the same time, on different
                                         nodes */
    /* The features of callbacks.features and smooth_features, 1 ..
     * TCLOD_MAX_FEATURES; 0 (default): none. */
    uint32_t feature_count;
    /* Cost per unit of each feature, finite and >= 0, until
     * tclod_selector_set_coefficients; entries past feature_count unused. */
    double coefficients[TCLOD_MAX_FEATURES];
} tclod_selector_desc;

/* Asks for 0 in a desc field whose 0 means "the default" (restarts,
 * split_threshold, smooth_epsilon, smooth_tolerance, smooth_cull_area,
 * confidence, dead_band). */
#define TCLOD_OFF (-1)
/* The largest tclod_greedy_desc.lookahead. */
#define TCLOD_MAX_LOOKAHEAD 63u
/* The largest tclod_greedy_desc.restarts. */
#define TCLOD_MAX_RESTARTS 256

/* Fills d with the explicit defaults: the same selector as a zeroed desc. */
TCLOD_API void tclod_selector_desc_default(tclod_selector_desc *d);

/* NULL when d is valid for a selector or scheduler over s, else the rule it
 * breaks ("desc.callbacks.benefit is NULL"): why tclod_selector_create or
 * tclod_scheduler_create returned TCLOD_ERR_ARG. s may be NULL: the rule that
 * needs the scene (smooth callbacks of the mixed solver) is then not checked. */
TCLOD_API const char *tclod_selector_desc_check(const tclod_scene *s, const tclod_selector_desc *d);

/* One frame's request. */
typedef struct tclod_frame {
    const tclod_view *view;  /* may be NULL: queries then carry screen_area and
                                distance -1 */
    double budget;           /* cost units, >= 0 (+inf = unlimited) */
    double solve_seconds;    /* wall-clock limit for the solve, >= 0; 0 = none */
    uint32_t max_iterations; /* limit on increments/decrements tried; 0 = none.
                                Either limit stops the search with a feasible
                                selection; the decrements that bring a warm
                                start back within a lowered budget always run */
} tclod_frame;

/* Why a solve stopped (tclod_stats.stop_reason). */
typedef enum tclod_stop_reason {
    TCLOD_STOP_BUDGET = 0,        /* no further increment fits the budget */
    TCLOD_STOP_FINEST = 1,        /* no increment is left: every visible selected node is
                                     at its finest level or refining it gains nothing
                                     (never with budget 0: TCLOD_STOP_BUDGET) */
    TCLOD_STOP_ITERATIONS = 2,    /* tclod_frame.max_iterations reached */
    TCLOD_STOP_TIME = 3,          /* tclod_frame.solve_seconds reached */
    TCLOD_STOP_FINISHED = 4,      /* ended early by tclod_select_finish */
    TCLOD_STOP_ROOTS_DROPPED = 5, /* even the visible roots did not fit: some were left
                                     out (tclod_stats.dropped_roots) */
    TCLOD_STOP_OVER_BUDGET = 6    /* even the visible roots did not fit, and
                                     TCLOD_OVERFLOW_DRAW_ROOTS drew them over the budget */
} tclod_stop_reason;

/* Figures of one tclod_select, returned by value. */
typedef struct tclod_stats {
    double benefit, cost;          /* of the returned selection, summed in result order
                                      (cut, then smooth groups); cost <= budget unless
                                      over_budget */
    uint32_t iterations;           /* increments and decrements tried (taken or not),
                                      and line searches */
    uint32_t increments;           /* increments taken */
    uint32_t decrements;           /* decrements taken */
    uint32_t line_searches;        /* gradient steps on smooth variables (mixed solver) */
    uint32_t variables;            /* smooth variables after culling and splitting
                                      (mixed solver) */
    uint32_t dropped_roots;        /* visible roots left out because even they did not fit */
    uint32_t over_budget;          /* 1: TCLOD_OVERFLOW_DRAW_ROOTS drew the roots over the
                                      budget (cost > budget); else 0 */
    uint32_t invalid_values;       /* callback values that were NaN, inf or negative */
    uint32_t evaluations;          /* nodes whose callbacks were called, plus smooth
                                      callback calls */
    double solve_seconds;          /* wall-clock time of the solve */
    tclod_stop_reason stop_reason; /* why the solve stopped */
    uint32_t notes;                /* TCLOD_NOTE_* bits: what the host may not have meant */
    uint32_t absent_roots;         /* roots not resident: their hierarchies draw nothing */
    uint32_t requests;             /* load requests listed (tclod_selector_requests) */
    uint32_t evictions;            /* evictions listed (tclod_selector_evictions) */
    double resident_bytes;         /* the scene's resident bytes when the solve began */
    double request_bytes;          /* the listed requests' bytes */
    double eviction_bytes;         /* the listed evictions' bytes */
} tclod_stats;

/* tclod_stats.notes: conditions a select does not fail on (strict mode fails on
 * bad values; docs/api.md, errors). */
#define TCLOD_NOTE_INVALID_VALUES 0x1u /* callbacks returned bad values (invalid_values) */
#define TCLOD_NOTE_NO_VIEW 0x2u        /* frame.view was NULL: nothing was projected */
#define TCLOD_NOTE_SMOOTH_IGNORED                            \
    0x4u /* the scene has smooth objects the solver does not \
            draw: the greedy solver, or no smooth callbacks */
#define TCLOD_NOTE_NOTHING_DRAWN                           \
    0x8u /* the scene is not empty and the selection draws \
            nothing */
#define TCLOD_NOTE_MEMORY_SHORT                               \
    0x10u /* the memory budget is smaller than what must stay \
             resident: no load was requested (docs/streaming.md) */
#define TCLOD_NOTE_COLD_FALLBACK                                   \
    0x20u /* a warm start was due but the selection is a cold      \
             solve's: warm starts were not paying, or the audit of \
             a warm solve found a better cold one (docs/greedy.md) */
#define TCLOD_NOTE_TASKS_MISSED                                  \
    0x40u /* the host's task system left nodes unevaluated (a    \
             range not run, a worker index >= worker_count): the \
             calling thread evaluated them (docs/api.md, threads) */
#define TCLOD_NOTE_TASKS_REPEATED                                 \
    0x80u /* the host's task system ran nodes twice (a range run  \
             again, or ranges that overlap, one after the other): \
             each was evaluated once (docs/api.md, threads) */

/* Per-view solver state and the current result. */
typedef struct tclod_selector tclod_selector;

/* Creates a selector over scene s, which must outlive it (tclod_scene_destroy
 * refuses while it lives). d is copied; a may be NULL (malloc/free). Errors:
 * TCLOD_ERR_ARG (NULL s, d or out; a desc tclod_selector_desc_check refuses,
 * naming the field), TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_selector_create(const tclod_scene *s, const tclod_selector_desc *d,
                                             const tclod_allocator *a, tclod_selector **out);

/* Frees the selector. NULL is allowed. Must not be called from its callbacks
 * (it is then ignored). */
TCLOD_API void tclod_selector_destroy(tclod_selector *sel);

/* Why the last failed call on sel failed (see tclod_status_string). */
TCLOD_API const char *tclod_selector_last_error(const tclod_selector *sel);

/* Selects for one frame; the result replaces the previous one. Guarantee: the
 * callbacks' costs of the drawn nodes summed in double in tclod_selector_cut's
 * order, then the smooth groups' costs, are <= budget (docs/api.md, budget
 * guarantee); roots that do not fit are dropped (tclod_stats.dropped_roots)
 * unless desc.overflow says otherwise. Allocates only when the scene grew.
 * st may be NULL. Errors: TCLOD_ERR_ARG (a bad frame or view),
 * TCLOD_ERR_CALLBACK (strict mode), TCLOD_ERR_NOMEM, TCLOD_ERR_STATE (a solve
 * pending, or from a callback); the previous result stays. */
TCLOD_API tclod_status tclod_select(tclod_selector *sel, const tclod_frame *f, tclod_stats *st);

/* Begins a solve of frame f (copied, with its view) to be run in slices over
 * several calls while the previous result stays readable (docs/api.md,
 * spreading a solve). Does the solve's only allocation. Errors as
 * tclod_select. */
TCLOD_API tclod_status tclod_select_begin(tclod_selector *sel, const tclod_frame *f);

/* Runs the pending solve for at most slice_seconds or slice_iterations more
 * iterations (0 = no limit; the solver's starting work always completes).
 * *done = 1 when it finished and its result replaced the previous one (*st
 * then holds its stats), else 0. Iteration slices give tclod_select's result.
 * Errors: TCLOD_ERR_ARG (NULL done, slice_seconds NaN or < 0), TCLOD_ERR_STATE
 * (no solve pending, from a callback), TCLOD_ERR_CALLBACK (strict mode: the
 * solve is cancelled). */
TCLOD_API tclod_status tclod_select_step(tclod_selector *sel, double slice_seconds,
                                         uint32_t slice_iterations, int *done, tclod_stats *st);

/* Ends the pending solve where it stands and commits it, within the budget
 * (stop reason TCLOD_STOP_FINISHED). Errors as tclod_select_step. */
TCLOD_API tclod_status tclod_select_finish(tclod_selector *sel, tclod_stats *st);

/* Sets the cost per unit of each of the desc's feature_count features
 * (coefficients[i] finite and >= 0), as tclod_calib_coefficients gives them;
 * the next select prices every node and smooth group with them. Errors:
 * TCLOD_ERR_ARG (NULL argument, a selector without features, a coefficient
 * NaN, infinite or negative, naming it), TCLOD_ERR_STATE (a solve is pending,
 * or from a callback); nothing changes on error. */
TCLOD_API tclod_status tclod_selector_set_coefficients(tclod_selector *sel,
                                                       const double *coefficients);

/* Drops the pending solve, if any; the previous result stays. Errors:
 * TCLOD_ERR_ARG (NULL), TCLOD_ERR_STATE (from a callback). */
TCLOD_API tclod_status tclod_select_cancel(tclod_selector *sel);
/* 1 while a begun solve has neither finished nor been cancelled, else 0. */
TCLOD_API int tclod_select_pending(const tclod_selector *sel);

/* The nodes the current selection draws, in result order: the visible nodes
 * of its cut (culled, dropped and empty nodes are not listed) and the additive
 * nodes it refined. *ids points into the selector: valid until the
 * next tclod_select or tclod_selector_destroy. Before the first selection
 * *n = 0. Errors: TCLOD_ERR_ARG (NULL argument), TCLOD_ERR_STATE (called
 * from a callback during a solve). */
TCLOD_API tclod_status tclod_selector_cut(const tclod_selector *sel, const tclod_id **ids,
                                          size_t *n);

/* A drawn group of smooth objects sharing one resolution (a variable of the
 * mixed solver; a single object when count == 1). */
typedef struct tclod_smooth_group {
    uint32_t first;    /* position of the first member in tclod_scene_smooth_order */
    uint32_t count;    /* members: positions first .. first + count - 1 */
    double resolution; /* every member's resolution, in (0, 1] */
    double benefit;    /* smooth_benefit of the group at that resolution */
    double cost;       /* smooth_cost of the group at that resolution */
} tclod_smooth_group;

/* The smooth groups drawn by the current selection (resolution > 0), in
 * result order (increasing first). *groups points into the selector: valid
 * until the next tclod_select or tclod_selector_destroy. Before the first
 * selection, and for solvers that ignore smooth objects, *n = 0. Errors:
 * TCLOD_ERR_ARG (NULL argument), TCLOD_ERR_STATE (called during a solve). */
TCLOD_API tclod_status tclod_selector_smooth_groups(const tclod_selector *sel,
                                                    const tclod_smooth_group **groups, size_t *n);

/* Resolution in [0, 1] selected for a smooth object (the resolution of the
 * group it was drawn in); 0 = not drawn (also for unknown ids, NULL, during a
 * solve, and for solvers that do not solve smooth objects). O(log groups). */
TCLOD_API double tclod_selector_resolution(const tclod_selector *sel, tclod_id smooth);

/* ------------------------------------------------------------------------- */
/* Streaming                                                                 */
/* ------------------------------------------------------------------------- */

/* What a select plans for the host's loader (docs/streaming.md). All zero
 * (the default): nothing; loads and evictions cost the select nothing. */
typedef struct tclod_stream_desc {
    uint32_t max_requests;    /* load requests to list per select; 0: none */
    double max_request_bytes; /* their bytes at most (the first request is listed
                                 whatever its size); 0: no cap */
    double memory_budget;     /* bytes the resident nodes, the loads in flight and
                                 the requests may take together; 0: no budget (no
                                 evictions listed) */
    double bytes_in_flight;   /* bytes of loads requested earlier and not resident
                                 yet: they count against memory_budget */
    double min_yield;         /* a request must bring at least this share of the
                                 benefit per byte the plan's target brings on
                                 average, >= 0: loads that add little for their
                                 bytes are not made. 0: default
                                 TCLOD_STREAM_MIN_YIELD; TCLOD_OFF: any */
} tclod_stream_desc;

/* The default tclod_stream_desc.min_yield (docs/streaming.md, the yield). */
#define TCLOD_STREAM_MIN_YIELD 0.5
/* The share of the target's benefit that the yield may leave out at most:
 * below min_yield, the best candidates are listed again until the ones left
 * out add no more than this together (docs/streaming.md, the yield). */
#define TCLOD_STREAM_YIELD_LOSS 0.02

/* Sets what the next selects plan; d NULL: nothing. Errors: TCLOD_ERR_ARG
 * (NULL sel; a field NaN, infinite or negative, min_yield TCLOD_OFF aside,
 * naming it), TCLOD_ERR_STATE (from a callback); nothing changes on error. */
TCLOD_API tclod_status tclod_selector_set_stream(tclod_selector *sel, const tclod_stream_desc *d);

/* tclod_stream_item.flags */
#define TCLOD_STREAM_SMOOTH 0x1u /* id is a smooth object, not a node */
#define TCLOD_STREAM_LISTED 0x2u /* it was in the previous select's list too */
#define TCLOD_STREAM_EXPAND                                    \
    0x4u /* a request to read an unexpanded node's part of the \
            hierarchy (tclod_node_desc.unexpanded) */

/* A load request or an eviction. */
typedef struct tclod_stream_item {
    tclod_id id;
    uint32_t flags; /* TCLOD_STREAM_* */
    double bytes;   /* its size (the scene's, or tclod_callbacks.bytes) */
    double value;   /* a request: the benefit its arrival would add per byte
                       (ranked highest first); an eviction: the benefit per
                       byte it gave when last seen visible, 0 if never (ranked
                       lowest first) */
} tclod_stream_item;

/* The load requests of the last select, best first: the non-resident nodes
 * its selection or the selections that follow would draw, ranked by the
 * benefit their arrival adds per byte, those that yield too little left out
 * (min_yield), capped by the stream desc; a node is listed after its
 * ancestors it needs. The evictions: resident nodes to free,
 * least valuable first, so that resident bytes, loads in flight and the
 * requests fit the memory budget; never a drawn node, one a drawn node falls
 * back to, or one the plan needs next. *items points into the selector:
 * valid until the next select or destroy. Errors: TCLOD_ERR_ARG (NULL
 * argument), TCLOD_ERR_STATE (during a solve). */
TCLOD_API tclod_status tclod_selector_requests(const tclod_selector *sel,
                                               const tclod_stream_item **items, size_t *n);
TCLOD_API tclod_status tclod_selector_evictions(const tclod_selector *sel,
                                                const tclod_stream_item **items, size_t *n);

/* ------------------------------------------------------------------------- */
/* Benefit and cost models                                                   */
/* ------------------------------------------------------------------------- */

/* Ready-made models from the source papers, for hosts to call from their
 * callbacks. Screen sizes are in px² (tclod_query.screen_area). */

/* Terrain quadtree patch at depth d of a tree of height max_depth (thesis
 * eq. 8.21): screen_area * 2^(d - max_depth), the square root of the share of
 * the full-resolution texels the patch shows. 0 for a negative screen_area. */
TCLOD_API double tclod_benefit_terrain(double screen_area, uint32_t depth, uint32_t max_depth);

/* Group of `trees` trees drawn at resolution r in [0, 1] ([Thesis8 eq. 8.20], with
 * the resolution x_i = r * trees): k * S * (trees / 64) * sqrt(r). Its
 * derivative goes to *d_dr (may be NULL), taken at r = 1e-12 when r is smaller
 * (the square root's slope is infinite at 0). The thesis uses k = 50 with
 * groups of at most 64 trees. */
TCLOD_API double tclod_benefit_tree_group(double k, double screen_area, double trees, double r,
                                          double *d_dr);

/* Splat rendering time of a group of `trees` instances whose full resolution
 * has `splats` splats in all, at resolution r in [0, 1] ([Thesis8 eq. 8.18]): with
 * n = r * splats splats drawn, (c_splat + c_tree) * n while n < trees (every
 * splat is a separate tree that needs its own setup), else
 * c_splat * n + c_tree * trees. Piecewise linear, steeper for the first units.
 * Its derivative goes to *d_dr (may be NULL); at the kink the slope after it.
 * The thesis measured c_splat = 0.0775 us and c_tree = 1.385 us. */
TCLOD_API double tclod_cost_splats(double c_splat, double c_tree, double splats, double trees,
                                   double r, double *d_dr);

/* Triangle-strip rendering time ([Thesis8 eq. 8.19]; [GEO §4.2]):
 * c_vertex * vertices. The thesis measured c_vertex = 0.06 us. */
TCLOD_API double tclod_cost_vertices(double c_vertex, double vertices);

/* Benefit of representation r of an object ([GEO §4.2]):
 * accuracy * screen_size with
 * accuracy = max(1, screen_size / original_faces) / max(1, screen_size / faces):
 * faces / original_faces while both have fewer faces than the object covers
 * pixels, faces / screen_size while only the representation has, and 1 once
 * it has at least a face per pixel: diminishing returns. faces and
 * original_faces > 0; 0 for a screen_size <= 0. */
TCLOD_API double tclod_benefit_accuracy(double screen_size, double faces, double original_faces);

/* Value of an instance by one of the Robin Hood value functions ([RH]
 * eq. 8-11): area a (un-projected, >= 0), depth z and distance d (> 0),
 * importance I (>= 0). 0 for NaN or out-of-range inputs. */
TCLOD_API double tclod_value_of(tclod_value f, double area, double depth, double distance,
                                double importance);

/* ------------------------------------------------------------------------- */
/* Frame time                                                                */
/* ------------------------------------------------------------------------- */

/* The render time that fits a target frame time ([RH eq. 5-7]), for a
 * machine where CPU (logic) and GPU (render) work in parallel: with
 * l = min(1, (logic_time / frame_time)²) and rho = 1 - l,
 * *render_time = rho² * frame_time / machine_c. Times in the host's unit (ms).
 * Errors: TCLOD_ERR_ARG (NULL render_time; frame_time <= 0; logic_time < 0;
 * machine_c <= 0; any of them NaN or inf), and *render_time is not written. */
TCLOD_API tclod_status tclod_render_budget(double frame_time, double logic_time, double machine_c,
                                           double *render_time);

/* Calibration of predicted cost against measured time ([GEO §4.2], [RH]
 * §5.3): the host reports, after each frame, the predicted cost of what it drew
 * (tclod_stats.cost) and the render and logic times it measured; an
 * exponentially weighted ratio measured / predicted then turns a target frame
 * time into the budget to select with. The ratio rises fast (frames became
 * slower than predicted: cut the budget now) and falls slowly, and ignores
 * changes within a dead band, like the frame-rate controllers of engines. */
typedef struct tclod_calib tclod_calib;

/* How a calibration follows measurements (docs/calibration.md). Every field
 * left 0 takes its default; TCLOD_OFF asks for 0 in dead_band. */
typedef struct tclod_calib_desc {
    double initial_scale; /* render time per unit of predicted cost to start from, > 0.
                             0: default 1 */
    double rise_rate;     /* weight of a new ratio when it rises, (0, 1]. 0: default 0.5 */
    double fall_rate;     /* weight of a new ratio when it falls, (0, 1]. 0: default 0.1 */
    double dead_band;     /* relative change of the ratio that is ignored, (0, 1).
                             0: default 0.01; TCLOD_OFF: none */
    double logic_rate;    /* weight of a new logic time, (0, 1]. 0: default 0.2 */
    double initial_logic; /* logic time to start from, >= 0, host unit. Default 0 */
    double machine_c;     /* [RH eq. 7]'s machine constant C, > 0. 0: default 1 */
    int initial_measured; /* 1: the initial values are measurements, blended at the
                             rates. 0 (default): guesses, replaced by the first
                             measurements */
    /* The learned cost model (docs/calibration.md, the learned cost): with
     * feature_count > 0 the calibration learns a render time per unit of each
     * feature from tclod_calib_report_features; initial_scale is unused, and
     * the rates and dead_band drive the fast scale on the learned coefficients
     * (docs/calibration.md, the estimator). */
    uint32_t feature_count; /* 1 .. TCLOD_MAX_FEATURES; 0 (default): the scale above */
    /* optional names, for messages; copied (31 bytes at most each) */
    const char *feature_names[TCLOD_MAX_FEATURES];
    /* render time per unit of each feature to start from, finite and >= 0; 0: none known */
    double prior[TCLOD_MAX_FEATURES];
    double forgetting;   /* weight of the past per frame, (0, 1]: the model remembers
                            about 1 / (1 - forgetting) frames. 0: default 0.998 */
    double outlier;      /* a frame whose relative error exceeds this many times the
                            mean relative error is an outlier, > 1. 0: default 4;
                            TCLOD_OFF: none */
    double least_share;  /* the least coefficient as a share of its prior (after the
                            first frame scaled the prior), [0, 1]: no feature gets
                            cheaper than that, so that a selection cannot buy without
                            bound what the frames have not priced. 0: default 0.1;
                            TCLOD_OFF: none */
    double prior_weight; /* the least weight the prior keeps, in frames, >= 0: it holds
                            the coefficients near the prior where the frames say
                            little (a feature that never varies). 0: default 1;
                            TCLOD_OFF: none once enough frames came */
    int strict;          /* 1: a bad report fails with TCLOD_ERR_ARG. 0 (default):
                            it is counted and ignored */
} tclod_calib_desc;

/* Fills d with the explicit defaults: the same calibration as a zeroed desc. */
TCLOD_API void tclod_calib_desc_default(tclod_calib_desc *d);

/* NULL when d is valid, else the rule it breaks ("desc.rise_rate must be in
 * (0, 1], or 0 (default)"): why tclod_calib_create returned TCLOD_ERR_ARG. */
TCLOD_API const char *tclod_calib_desc_check(const tclod_calib_desc *d);

/* Creates a calibration state. d is copied; a may be NULL (malloc/free).
 * Errors: TCLOD_ERR_ARG (NULL d or out, a field out of range or NaN),
 * TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_calib_create(const tclod_calib_desc *d, const tclod_allocator *a,
                                          tclod_calib **out);

/* Frees c. NULL is allowed. */
TCLOD_API void tclod_calib_destroy(tclod_calib *c);

/* Why the last failed call on c failed (see tclod_status_string). */
TCLOD_API const char *tclod_calib_last_error(const tclod_calib *c);

/* Reports one frame: the predicted cost of what was drawn (>= 0; cost 0 leaves
 * the ratio as it is), the measured render time and logic time (>= 0, host
 * unit; logic_time TCLOD_OFF: not measured, the estimate stays). Errors:
 * TCLOD_ERR_ARG (NULL c, a value NaN, inf or < 0); nothing changes. */
TCLOD_API tclod_status tclod_calib_report(tclod_calib *c, double predicted_cost, double render_time,
                                          double logic_time);

/* Reports one frame to the learned cost model (feature_count > 0): the
 * frame's features summed over what it drew (feature_count entries: the
 * nodes' and smooth groups' features, plus those of the frame's own work that
 * no node draws, such as a full-screen pass or a constant 1), the measured
 * render time and logic time (as tclod_calib_report). A feature or time that
 * is NaN, infinite or negative is counted (tclod_calib_counts) and the frame
 * ignored, or, strict, TCLOD_ERR_ARG naming it; an outlier frame (a hitch, a
 * resize) is counted and ignored, unless two in a row err the same way,
 * which is a change of machine the model starts again from. Errors:
 * TCLOD_ERR_ARG (NULL c or features, no features, strict and a bad value),
 * and nothing changes. */
TCLOD_API tclod_status tclod_calib_report_features(tclod_calib *c, const double *features,
                                                   double render_time, double logic_time);

/* The learned render time per unit of each feature (feature_count entries,
 * each finite and >= 0), for tclod_selector_set_coefficients. Valid until the
 * next report or destroy; NULL for NULL or without features. */
TCLOD_API const double *tclod_calib_coefficients(const tclod_calib *c);

/* The learned model's render time for the given features (coefficients ·
 * features), for a host that prices its own nodes. 0 for NULL arguments or
 * without features. */
TCLOD_API double tclod_calib_predict(const tclod_calib *c, const double *features);

/* What the reports to a learned cost model were. */
typedef struct tclod_calib_counts {
    uint32_t frames;   /* reports */
    uint32_t used;     /* frames the model learned from */
    uint32_t invalid;  /* frames with a bad feature or time, ignored */
    uint32_t empty;    /* frames that drew nothing or took no time, ignored */
    uint32_t outliers; /* frames ignored as outliers */
    uint32_t changes;  /* changes of machine the model started again from */
} tclod_calib_counts;

/* The counts of c into *out (zeros for NULL c). Errors: TCLOD_ERR_ARG (NULL out). */
TCLOD_API tclod_status tclod_calib_get_counts(const tclod_calib *c, tclod_calib_counts *out);

/* The budget for a target frame time when the frame's own work (the fixed
 * features, feature_count entries: the parts of the reported features no
 * node draws) takes render time too: tclod_calib_budget's minus
 * tclod_calib_predict(fixed), at least 0. fixed NULL: none. Errors as
 * tclod_calib_budget. */
TCLOD_API tclod_status tclod_calib_budget_fixed(const tclod_calib *c, double frame_time,
                                                const double *fixed, double *budget);

/* The current ratio measured render time / predicted cost (> 0), and logic-time
 * estimate (>= 0); with features, the fast scale the coefficients carry on the
 * model's (1 once the model alone is right to within the dead band). 0 for
 * NULL. */
TCLOD_API double tclod_calib_scale(const tclod_calib *c);
TCLOD_API double tclod_calib_logic(const tclod_calib *c);

/* The budget, in predicted-cost units, for a target frame time: the render
 * time tclod_render_budget gives for the logic estimate and machine_c, divided
 * by the ratio. Errors: TCLOD_ERR_ARG (NULL argument, frame_time <= 0, NaN or
 * inf), and *budget is not written. */
TCLOD_API tclod_status tclod_calib_budget(const tclod_calib *c, double frame_time, double *budget);

/* ------------------------------------------------------------------------- */
/* Predictive geomorph scheduler                                             */
/* ------------------------------------------------------------------------- */

/* Predictive selection with geomorphs ([GEO §3.3-3.4, §4.2-4.5];
 * docs/scheduler.md). Time is cut into intervals of tau seconds; a selection
 * for a future interval runs in per-frame slices, for views predicted from
 * the camera's path and a conservative camera, lands at a boundary, and is
 * morphed to (three stages) or switched to (two). Invariant: every frame's
 * draw list costs at most the budget in force; when it would not, the
 * scheduler selects again at once for the current view. */
typedef struct tclod_scheduler tclod_scheduler;

/* Most predicted views per selection. */
#define TCLOD_MAX_SAMPLES 8u

/* How a scheduler predicts and morphs (docs/scheduler.md). Every field left 0
 * takes its default; TCLOD_OFF asks for 0 in confidence. */
typedef struct tclod_scheduler_desc {
    double tau;             /* seconds: the interval, the horizon unit and the morph
                               duration; normal, > 0, 4 tau finite. 0: default 0.5
                               ([GEO §4.5]: 10 frames at 20 Hz) */
    uint32_t samples;       /* predicted views per selection, 1 .. TCLOD_MAX_SAMPLES.
                               0: default 3 */
    double confidence;      /* lambda > 0: weight of the conservative camera's
                               benefit. 0: default 1; TCLOD_OFF: it only culls */
    double max_speed;       /* theta >= 0, world units per second: the camera's speed
                               bound. Default 0 (the camera does not move) */
    double max_turn_rate;   /* omega >= 0, radians per second: its turn bound.
                               Default 0 */
    int two_stage;          /* 1: two stages, selections switch at boundaries.
                               0 (default): three stages with geomorphs */
    tclod_calib_desc calib; /* the feedback of tclod_scheduler_report_frame */
} tclod_scheduler_desc;

/* Fills d with the explicit defaults: the same scheduler as a zeroed desc. */
TCLOD_API void tclod_scheduler_desc_default(tclod_scheduler_desc *d);

/* NULL when d is valid, else the rule it breaks ("desc.samples must be at
 * most TCLOD_MAX_SAMPLES (8)", "desc.calib.rise_rate ..."): with
 * tclod_selector_desc_check, why tclod_scheduler_create returned
 * TCLOD_ERR_ARG. */
TCLOD_API const char *tclod_scheduler_desc_check(const tclod_scheduler_desc *d);

/* One item of a frame's draw list: node `fine` geomorphed towards its parent
 * `coarse` with `weight` in [0, 1] (1 = exactly fine, 0 = looks like coarse).
 * fine == coarse (weight 1) when the node does not morph. The fine nodes of a
 * draw list are disjoint (none is an ancestor of another) except for additive
 * nodes, drawn with their descendants; coarse is the nearest ancestor that
 * draws (empty nodes are passed over), and for a child of an additive node it
 * is that node, which stays drawn: the child fades in. */
typedef struct tclod_draw {
    tclod_id fine, coarse;
    float weight;
} tclod_draw;

/* Figures of the scheduler, running totals since its creation except where
 * said. */
typedef struct tclod_scheduler_stats {
    double draw_cost;         /* this frame: predicted cost of the draw list */
    double budget;            /* this frame: the budget in cost units (the update's
                                 budget divided by the calibration's scale) */
    double select_seconds;    /* this frame: time spent selecting in the update */
    uint32_t draws;           /* this frame: items in the draw list */
    uint32_t morphing;        /* this frame: items with fine != coarse */
    uint32_t selections;      /* selections landed at boundaries */
    uint32_t unfinished;      /* of those, ended early because their slices were
                                 too short */
    uint32_t emergencies;     /* immediate selections because the draw list would
                                 have exceeded the budget (and restarts after a
                                 gap of more than 4 tau) */
    uint64_t changes;         /* level changes of drawn objects: a drawn node
                                 replaced by drawn descendants, or the reverse */
    uint64_t morphs;          /* of those, the ones drawn as geomorphs */
    uint64_t pops;            /* of those, the ones that switched at once */
    uint32_t invalid_values;  /* callback values that were NaN, inf or negative, in
                               the landed selections and the scheduler's own
                               evaluations */
    double selection_benefit; /* the newest landed (or immediate) selection's
                              benefit and cost as its solve saw them: the
                              benefit summed over the predicted views plus
                              confidence times the conservative camera's, the
                              cost the largest over the predicted views that saw
                              a node (an immediate selection: the current
                              view's) */
    double selection_cost;
} tclod_scheduler_stats;

/* Creates a scheduler over scene s (which must outlive it) with a selector
 * described by sd (its callbacks are the host's; the scheduler calls them for
 * the predicted views, and from tclod_scheduler_update itself) and the
 * scheduling desc d; both are copied. a may be NULL (malloc/free). Errors:
 * TCLOD_ERR_ARG (NULL argument, sd rejected as tclod_selector_create rejects
 * it, sd with features: the scheduler's views take costs, which a cost
 * callback may compute as tclod_calib_predict of its features; a field of d
 * out of range or NaN, d.calib with features, tau not as described above),
 * TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_scheduler_create(const tclod_scene *s, const tclod_selector_desc *sd,
                                              const tclod_scheduler_desc *d,
                                              const tclod_allocator *a, tclod_scheduler **out);

/* Frees the scheduler. NULL is allowed. */
TCLOD_API void tclod_scheduler_destroy(tclod_scheduler *sch);

/* Why the last failed call on sch failed (see tclod_status_string). */
TCLOD_API const char *tclod_scheduler_last_error(const tclod_scheduler *sch);

/* Once per frame, before drawing: records the camera at `now` (seconds, never
 * decreasing), lands and begins selections at boundaries, runs the pending one
 * for at most slice_seconds (0 = to its end) and makes this frame's draw list
 * (docs/scheduler.md, updates). budget is in the unit of the reported render
 * times. The first update, and one more than 4 tau after the current
 * interval began, select at once. The scene may change between updates. All
 * or nothing: on error the outputs are the last successful update's. Errors:
 * TCLOD_ERR_ARG (a bad argument or view), TCLOD_ERR_CALLBACK (strict mode),
 * TCLOD_ERR_NOMEM, TCLOD_ERR_STATE (from a callback). */
TCLOD_API tclod_status tclod_scheduler_update(tclod_scheduler *sch, double now,
                                              const tclod_view *view, double budget,
                                              double slice_seconds);

/* This frame's draw list. Every fine and coarse node in it is resident when
 * the update returns (docs/scheduler.md, Streaming). *items points into the scheduler: valid
 * until the next update or destroy. Before the first update *n = 0. Errors:
 * TCLOD_ERR_ARG (NULL argument). */
TCLOD_API tclod_status tclod_scheduler_draws(const tclod_scheduler *sch, const tclod_draw **items,
                                             size_t *n);

/* This frame's resolution of smooth object `smooth` in [0, 1] (0 = not
 * drawn; also for unknown ids, NULL, one not resident, before the first
 * update and with a solver that ignores smooth objects). O(1). */
TCLOD_API double tclod_scheduler_resolution(const tclod_scheduler *sch, tclod_id smooth);

/* Reports the measured render and logic times (>= 0, the budget's unit) of the
 * frame drawn from the last update's draw list to the scheduler's
 * calibration, which rescales the budget of the frames that follow
 * (docs/calibration.md). logic_time TCLOD_OFF: not measured. Errors:
 * TCLOD_ERR_ARG (NULL sch, a time NaN, inf or < 0), TCLOD_ERR_STATE (before
 * the first update); nothing changes. */
TCLOD_API tclod_status tclod_scheduler_report_frame(tclod_scheduler *sch, double render_time,
                                                    double logic_time);

/* The scheduler's calibration, for tclod_calib_scale and tclod_calib_logic:
 * a host that budgets a frame time gives tclod_scheduler_update the render
 * time tclod_render_budget(frame_time, tclod_calib_logic(c), machine_c)
 * (the update divides it by the scale itself). Valid until the scheduler is
 * destroyed; NULL for NULL. */
TCLOD_API const tclod_calib *tclod_scheduler_calib(const tclod_scheduler *sch);

/* Streaming with a scheduler (docs/scheduler.md, Streaming). Sets what its
 * selections plan, as tclod_selector_set_stream; d NULL: nothing. It applies
 * from the next selection to end: the lists change when a selection ends,
 * about once per tau, and with a selection made at once. Errors:
 * TCLOD_ERR_ARG (NULL sch; a field of d NaN, infinite or negative, naming
 * it), TCLOD_ERR_STATE (from a callback); nothing changes on error. */
TCLOD_API tclod_status tclod_scheduler_set_stream(tclod_scheduler *sch, const tclod_stream_desc *d);
/* The load requests and evictions of the last selection to end, as
 * tclod_selector_requests and tclod_selector_evictions. The requests value
 * nodes by their benefit summed over the predicted views, so they cover what
 * the camera will need; the evictions never name a node the scheduler's draw
 * lists draw, morph from or fall back to until the lists change (the landed
 * selections and their ancestors are kept), nor one the prediction needs
 * next. Empty before the first update. *items points into the scheduler:
 * valid until the next update or destroy. Errors: TCLOD_ERR_ARG (NULL
 * argument), TCLOD_ERR_STATE (from a callback). */
TCLOD_API tclod_status tclod_scheduler_requests(const tclod_scheduler *sch,
                                                const tclod_stream_item **items, size_t *n);
TCLOD_API tclod_status tclod_scheduler_evictions(const tclod_scheduler *sch,
                                                 const tclod_stream_item **items, size_t *n);

/* The scheduler's figures (tclod_scheduler_stats). Errors: TCLOD_ERR_ARG. */
TCLOD_API tclod_status tclod_scheduler_get_stats(const tclod_scheduler *sch,
                                                 tclod_scheduler_stats *st);

/* The camera predicted for time t from the recorded path: eye, forward and
 * up extrapolated linearly (least squares over the views of the last tau
 * seconds, at least the last two), the motion clamped to max_speed and
 * max_turn_rate when they are > 0; the other fields are the last view's.
 * Errors: TCLOD_ERR_ARG (NULL argument, t NaN or infinite), TCLOD_ERR_STATE
 * (no view recorded yet). */
TCLOD_API tclod_status tclod_scheduler_predict(const tclod_scheduler *sch, double t,
                                               tclod_view *out);

/* The conservative camera of [GEO §3.3]: a view containing every view the
 * camera can reach within `horizon` seconds, moving at most max_speed and
 * turning at most max_turn_rate (docs/scheduler.md, conservative camera).
 * Errors: TCLOD_ERR_ARG (NULL argument, invalid view, horizon, max_speed or
 * max_turn_rate NaN, inf or < 0); *out is then not written. */
TCLOD_API tclod_status tclod_conservative_view(const tclod_view *view, double horizon,
                                               double max_speed, double max_turn_rate,
                                               tclod_view *out);

#ifdef __cplusplus
}
#endif

#endif /* TCLOD_H */
