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
 *  - Ids are dense indices assigned in creation order, starting at 0. Nodes and
 *    smooth objects have separate id spaces.
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
#define TCLOD_VERSION_MINOR 1
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
    float eye[3];          /* world position */
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

/* 1 if a sphere (bounds = x, y, z, radius) intersects the view frustum (the
 * six planes: near, far, left, right, top, bottom), 0 if it lies wholly
 * outside. Conservative: a sphere near a frustum corner may be reported
 * inside. Precondition: tclod_view_validate(view) == TCLOD_OK. */
TCLOD_API int tclod_view_sphere_visible(const tclod_view *view, const float bounds[4]);

/* Projected area of a bounding sphere in pixels²: pi * r_px² with
 * r_px = (viewport_height / 2) / tan(fov_y / 2) * r / sqrt(d² - r²), d the
 * distance from the eye to the centre, clamped to the viewport area
 * (viewport_height² * aspect); the whole viewport when the eye is inside the
 * sphere. Does not test the frustum. Precondition: a valid view. */
TCLOD_API float tclod_view_screen_area(const tclod_view *view, const float bounds[4]);

/* Distance from the eye to the centre of bounds. */
TCLOD_API float tclod_view_distance(const tclod_view *view, const float bounds[4]);

/* ------------------------------------------------------------------------- */
/* Callbacks                                                                 */
/* ------------------------------------------------------------------------- */

/* What a callback is asked about. Valid only during the call. */
typedef struct tclod_query {
    tclod_id id;           /* node id, or first smooth object of a group */
    uint32_t count;        /* smooth objects in the group (1 for nodes) */
    const tclod_view *view; /* the frame's view; NULL when the frame has none */
    float screen_area;     /* projected bounds in px²; 0 when the bounds are
                              outside the frustum; -1 when no bounds or no view */
    float distance;        /* eye to bounds centre, or -1 when no bounds or no view */
} tclod_query;

/* The host's model of quality and render time. Callbacks may read anything but
 * must not call into the same selector (that returns TCLOD_ERR_STATE) nor
 * modify the scene being solved.
 *
 * benefit: visual quality of drawing node q->id, >= 0. 0 = invisible: the node
 *          is culled with its whole subtree (kept in the cut, not drawn, no
 *          cost). Should show diminishing returns down a hierarchy (a finer
 *          level adds less benefit per unit of cost than its parent did).
 * cost:    predicted render time of node q->id, >= 0, in budget units. Only
 *          asked for nodes whose benefit is > 0.
 * NaN, inf and negative values are counted in tclod_stats.invalid_values: a
 * bad benefit makes the node invisible, a bad cost makes it unaffordable (it
 * is never selected); with tclod_selector_desc.strict they fail the call with
 * TCLOD_ERR_CALLBACK instead. Each callback is called at most once per node
 * per tclod_select.
 *
 * smooth_benefit / smooth_cost: value at resolution r in [0, 1] of smooth
 *          objects (or groups) and its derivative in *d_dr; used by the mixed
 *          solver. May be NULL for the greedy solver, which ignores smooth
 *          objects. */
typedef struct tclod_callbacks {
    double (*benefit)(void *user, const tclod_query *q);
    double (*cost)(void *user, const tclod_query *q);
    double (*smooth_benefit)(void *user, const tclod_query *q, double r, double *d_dr);
    double (*smooth_cost)(void *user, const tclod_query *q, double r, double *d_dr);
    void *user; /* passed through unchanged */
} tclod_callbacks;

/* ------------------------------------------------------------------------- */
/* Scene                                                                     */
/* ------------------------------------------------------------------------- */

/* Structure only: nodes of one or more LOD hierarchies, and smooth objects.
 * Nodes are never removed; build a new scene to start over. */
typedef struct tclod_scene tclod_scene;

/* Creates an empty scene. a may be NULL (malloc/free); it is copied. */
TCLOD_API tclod_status tclod_scene_create(const tclod_allocator *a, tclod_scene **out);

/* Frees the scene. Destroy its selectors first. NULL is allowed. */
TCLOD_API void tclod_scene_destroy(tclod_scene *s);

/* Adds a node. parent is TCLOD_NONE for the root of a new hierarchy, else an
 * existing node id (a node's children together refine it; a plain object with
 * L levels is a chain of L nodes). Because a parent must exist before its
 * children, cycles are impossible. bounds is x, y, z, radius (world units) or
 * NULL for a node without bounds; with bounds the callbacks' query carries
 * screen_area and distance.
 * Errors: TCLOD_ERR_ARG (s or out_id NULL; bounds not finite; radius < 0),
 * TCLOD_ERR_HIERARCHY (parent is neither TCLOD_NONE nor an existing node),
 * TCLOD_ERR_NOMEM. Must not be called while a selector on s is solving. */
TCLOD_API tclod_status tclod_scene_add_node(tclod_scene *s, tclod_id parent,
                                            const float bounds[4], tclod_id *out_id);

/* Adds a smooth object (continuous resolution r in [0, 1]). bounds: x, y, z,
 * radius, required (its ground position x, z places it in the quadtree).
 * Errors as tclod_scene_add_node, without TCLOD_ERR_HIERARCHY. */
TCLOD_API tclod_status tclod_scene_add_smooth(tclod_scene *s, const float bounds[4],
                                              tclod_id *out_id);

/* Builds the scene's child index now (children stored contiguously). Optional:
 * selectors build it on demand after the scene changed. Call it after changing a
 * scene that several threads then select from concurrently. */
TCLOD_API tclod_status tclod_scene_prepare(tclod_scene *s);

/* Number of nodes / smooth objects (0 for NULL). */
TCLOD_API uint32_t tclod_scene_node_count(const tclod_scene *s);
TCLOD_API uint32_t tclod_scene_smooth_count(const tclod_scene *s);
/* Parent of a node; TCLOD_NONE for a root or an unknown id. */
TCLOD_API tclod_id tclod_scene_parent(const tclod_scene *s, tclod_id node);

/* ------------------------------------------------------------------------- */
/* Selector                                                                  */
/* ------------------------------------------------------------------------- */

typedef enum tclod_solver {
    TCLOD_SOLVER_GREEDY = 0,    /* Mason–Blake increments with fill, decrements, coherence */
    TCLOD_SOLVER_MIXED = 1,     /* discrete increments + gradient ascent on smooth objects */
    TCLOD_SOLVER_ROBIN_HOOD = 2 /* proportional time distribution, non-iterative */
} tclod_solver;

/* Whether a solver is provided by this build of the library (1) or not (0);
 * tclod_selector_create rejects the others with TCLOD_ERR_ARG. */
TCLOD_API int tclod_solver_available(tclod_solver solver);

typedef struct tclod_selector_desc {
    tclod_solver solver;       /* default TCLOD_SOLVER_GREEDY */
    tclod_callbacks callbacks; /* benefit and cost required; default all NULL */
    int warm_start;            /* 1: start from the previous frame's selection (faster,
                                  coherent); 0: from the roots. Default 1 */
    int split_smooth;          /* quadtree variable splitting (mixed solver). Default 0 */
    double split_threshold;    /* theta, benefit loss allowed by splitting, >= 0.
                                  Default 0.01 */
    int strict;                /* 1: a bad callback value fails the call with
                                  TCLOD_ERR_CALLBACK (previous result kept);
                                  0: it is sanitised and counted. Default 0 */
} tclod_selector_desc;

/* Fills d with the defaults above. */
TCLOD_API void tclod_selector_desc_default(tclod_selector_desc *d);

/* One frame's request. */
typedef struct tclod_frame {
    const tclod_view *view;   /* may be NULL: queries then carry screen_area and
                                 distance -1 */
    double budget;            /* cost units, >= 0 (+inf = unlimited) */
    double solve_seconds;     /* wall-clock limit for the solve, >= 0; 0 = none */
    uint32_t max_iterations;  /* limit on increments/decrements tried; 0 = none.
                                 Either limit stops the search with a feasible
                                 selection; the decrements that bring a warm
                                 start back within a lowered budget always run */
} tclod_frame;

/* Why a solve stopped (tclod_stats.stop_reason). */
typedef enum tclod_stop_reason {
    TCLOD_STOP_BUDGET = 0,     /* no further increment fits the budget */
    TCLOD_STOP_FINEST = 1,     /* no increment is left: every visible selected node is
                                  at its finest level or refining it gains nothing */
    TCLOD_STOP_ITERATIONS = 2, /* tclod_frame.max_iterations reached */
    TCLOD_STOP_TIME = 3        /* tclod_frame.solve_seconds reached */
} tclod_stop_reason;

/* Figures of one tclod_select, returned by value. */
typedef struct tclod_stats {
    double benefit, cost;    /* of the returned selection, summed in result order;
                                cost <= budget */
    uint32_t iterations;     /* increments and decrements tried (taken or not) */
    uint32_t increments;     /* increments taken */
    uint32_t decrements;     /* decrements taken */
    uint32_t line_searches;  /* mixed solver */
    uint32_t variables;      /* smooth variables after splitting (mixed solver) */
    uint32_t dropped_roots;  /* visible roots left out because even they did not fit */
    uint32_t invalid_values; /* callback values that were NaN, inf or negative */
    uint32_t evaluations;    /* nodes whose callbacks were called */
    double solve_seconds;    /* wall-clock time of the solve */
    int stop_reason;         /* a tclod_stop_reason */
} tclod_stats;

/* Per-view solver state and the current result. */
typedef struct tclod_selector tclod_selector;

/* Creates a selector over scene s, which must outlive it. d is copied; a may be
 * NULL (malloc/free). Errors: TCLOD_ERR_ARG (NULL s, d or out; a solver this
 * build does not provide; benefit or cost callback NULL; split_threshold NaN or
 * < 0), TCLOD_ERR_NOMEM. */
TCLOD_API tclod_status tclod_selector_create(const tclod_scene *s, const tclod_selector_desc *d,
                                             const tclod_allocator *a, tclod_selector **out);

/* Frees the selector. NULL is allowed. Must not be called from its callbacks
 * (it is then ignored). */
TCLOD_API void tclod_selector_destroy(tclod_selector *sel);

/* Selects representations for one frame; the result replaces the previous one.
 * Guarantee: the costs the callbacks returned for the visible selected nodes,
 * summed in double in the order tclod_selector_cut lists them, are <= budget.
 * Roots are selected first; if even the visible roots do not fit, the lowest
 * value (benefit / cost) roots are left out and counted in st->dropped_roots.
 * Allocates only while its buffers grow to the scene's size (the first call,
 * and after the scene grew). A changed scene restarts from the roots.
 * st may be NULL.
 * Errors: TCLOD_ERR_ARG (NULL sel or f; budget NaN or < 0; solve_seconds NaN
 * or < 0; an invalid view), TCLOD_ERR_CALLBACK (strict mode), TCLOD_ERR_NOMEM,
 * TCLOD_ERR_STATE (re-entered from a callback). On error the previous result
 * and its stats stay as they were. */
TCLOD_API tclod_status tclod_select(tclod_selector *sel, const tclod_frame *f, tclod_stats *st);

/* The visible nodes of the current cut (culled and dropped nodes are not
 * listed), in result order. *ids points into the selector: valid until the
 * next tclod_select or tclod_selector_destroy. Before the first selection
 * *n = 0. Errors: TCLOD_ERR_ARG (NULL argument), TCLOD_ERR_STATE (called
 * from a callback during a solve). */
TCLOD_API tclod_status tclod_selector_cut(const tclod_selector *sel, const tclod_id **ids,
                                          size_t *n);

/* Resolution in [0, 1] selected for a smooth object; 0 = not drawn (also for
 * unknown ids, NULL, and solvers that do not solve smooth objects). */
TCLOD_API double tclod_selector_resolution(const tclod_selector *sel, tclod_id smooth);

#ifdef __cplusplus
}
#endif

#endif /* TCLOD_H */
