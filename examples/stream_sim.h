/*
 * stream_sim — the loader simulation of flyover_sim --stream and tclod_tiles
 * --stream: what a host that streams its levels of detail from a server sees,
 * with libtclod planning the loads (docs/streaming.md) and, side by side on a
 * second copy of the scene, a loader that works the way CesiumJS does.
 *
 * Three copies of one scene, one camera path, one budget per frame:
 *  - ours: a selector with tclod_selector_set_stream; after each select its
 *    evictions are applied and its requests issued (in the listed order,
 *    skipping those in flight);
 *  - baseline: the same selector over a scene of its own, whose loads come
 *    from a screen-space-error traversal ("Cesium-like"): a visible node is
 *    wanted when it is a root or its parent's screen-space error exceeds
 *    STREAM_SIM_MAX_SSE (16 px), and wanted nodes that are not resident are
 *    requested in descending order of their error; when memory is needed the
 *    least recently used nodes (last frame wanted or drawn) are evicted,
 *    never a root, a drawn node, an ancestor of a drawn node or a node wanted
 *    in this frame;
 *  - all resident: the same selector over a scene where everything is loaded,
 *    whose benefit is what the budget gives at best.
 *
 * The loader of either: time advances 1 / STREAM_SIM_HZ s per frame. A load
 * starts when it is issued, at most STREAM_SIM_MAX_LOADS in flight; the
 * server answers after the latency, and the answers share the link one after
 * the other: a load issued at t completes at max(t + latency, the link's end
 * of the load before) + bytes / bandwidth. A completed load makes its node
 * resident (tclod_scene_set_resident) at the start of the first frame at or
 * after its completion, before that frame's selects. A load is issued only
 * while resident bytes, the bytes in flight and its own fit the memory
 * budget (ours: the plan promises it; the baseline evicts first), so that
 * memory holds every load that completes.
 *
 * Sizes and errors come from the host: bytes per node (0: nothing to load,
 * a grouping node or a tile without content: resident from the start, and
 * always refined through by the traversal) and the geometric error (m) the
 * traversal's screen-space error is made of,
 *   sse = error x viewport_height / (2 x max(distance, 1e-7) x tan(fov_y / 2)),
 * distance to the node's bounding volume (tclod_view_bounds_distance). Both
 * simulations start with the roots resident and nothing else.
 *
 * A scene read on demand (stream_host): an unexpanded node is loaded as its
 * file (its bytes), ours when the plan lists it with TCLOD_STREAM_EXPAND, the
 * baseline when its traversal reaches it; on arrival the host replaces it by
 * what the file holds (stream_host.expand) and the copy's structure is read
 * again. The all-resident copy expands what its own plan lists at once.
 *
 * Not part of the library: the examples' own module.
 */
#ifndef STREAM_SIM_H
#define STREAM_SIM_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <tclod/tclod.h>

/* Frames per simulated second. */
#define STREAM_SIM_HZ 60.0
/* Loads in flight at most, for both loaders. */
#define STREAM_SIM_MAX_LOADS 20u
/* The baseline refines a visible node while its screen-space error exceeds
 * this (px): CesiumJS's default maximumScreenSpaceError. */
#define STREAM_SIM_MAX_SSE 16.0
/* t95: the share of the all-resident benefit a selection must reach. */
#define STREAM_SIM_T95_SHARE 0.95
/* A teleport lands on the point, among this many points spread along the
 * path by the golden-ratio sequence (starting at STREAM_SIM_TELEPORT_SEED),
 * whose view needs the most new data: the most bytes the screen-space-error
 * traversal wants there and not where the camera is. */
#define STREAM_SIM_TELEPORT_CANDIDATES 8u
#define STREAM_SIM_TELEPORT_SEED 0.5
/* The all-resident copy of a scene read on demand expands at most this
 * many nodes per select, and selects again at most this many times a frame. */
#define STREAM_SIM_EXPAND_BATCH 64u
#define STREAM_SIM_EXPAND_ROUNDS 32u
/* With --stream, the programs fly this many frames unless --frames says. */
#define STREAM_SIM_DEFAULT_FRAMES 2000ul

/* The options --stream adds to both programs. */
typedef struct stream_sim_options {
    int enabled;                  /* --stream */
    double latency_ms;            /* --latency-ms L, >= 0; default 50 */
    double bandwidth_mbps;        /* --bandwidth-mbps W, > 0, Mbit/s; default 100 */
    double memory_mb;             /* --memory-mb M, > 0, 10^6 bytes; 0: half the scene */
    unsigned long teleport_every; /* --teleport-every N, frames; 0: never; default 200 */
    double min_yield;             /* --min-yield Y: tclod_stream_desc.min_yield; default 0 */
    int given;                    /* one of the five was given (they need --stream) */
} stream_sim_options;

void stream_sim_options_default(stream_sim_options *o);

/* Parses argv[*i] when it is one of the options above, taking its value from
 * argv[*i + 1] (then *i moves past it): 1 when taken, 0 when it is no option
 * of this module, -1 after a message on stderr ("prog: --latency-ms expects
 * ...") for a bad or missing value. */
int stream_sim_parse_option(stream_sim_options *o, const char *prog, int argc, char **argv, int *i);

/* After the command line: 0 after a message when a stream option came
 * without --stream, else 1. */
int stream_sim_options_check(const stream_sim_options *o, const char *prog);

/* --help text: the options (lines "  --stream ..."), and the per-frame
 * columns and summary keys --stream adds. */
extern const char stream_sim_usage_options[];
extern const char stream_sim_usage_output[];

/* The copies (stream_host's `copy` argument). */
enum { STREAM_SIM_OURS = 0, STREAM_SIM_BASE = 1, STREAM_SIM_ALL = 2 };

/* What the simulation asks of a host whose scene is read on demand
 * (tclod_node_desc.unexpanded, docs/streaming.md), or whose copies do not
 * share ids. Every function takes the copy (STREAM_SIM_OURS, _BASE, _ALL) and
 * a live node id of it. */
typedef struct stream_host {
    void *user;
    double (*bytes)(void *user, int copy, tclod_id id); /* its size; an unexpanded
                                                           node's: its file's */
    double (*error)(void *user, int copy, tclod_id id); /* its geometric error, m */
    int (*unexpanded)(void *user, int copy, tclod_id id);
    /* Reads what unexpanded node id stands for and puts it in the copy's
     * scene in the node's place: removes the node, adds what it read below
     * its parent (with bounds; new ids). Called when the load of its file
     * completes (ours, base) or when the all-resident selection's plan asks
     * for it. 0 after a message on stderr. */
    int (*expand)(void *user, int copy, tclod_id id);
    void *selector_user[2]; /* the callbacks' user of base's and all's selectors
                               (NULL: the selector desc's) */
    double scene_bytes;     /* what the whole scene needs, when the host knows more of
                               it than its nodes say (0: their sum) */
} stream_host;

/* ---- the camera path with teleports -------------------------------------------- */

/* The view at `position` frames along a closed path (any real; the path
 * repeats every `loop` frames). */
typedef void (*stream_sim_view_fn)(void *user, double position, tclod_view *view);

/* Where the camera is in each frame: without teleports at frame f it is f
 * frames along the path; every `every` frames it jumps to a point of the path
 * whose view has the least in common with where it is (see
 * STREAM_SIM_TELEPORT_CANDIDATES) and flies on from there. */
typedef struct stream_path {
    double loop;         /* frames per round of the path, > 0 */
    unsigned long every; /* frames between teleports; 0: none */
    double *start;       /* per event (the start, then each teleport): its position */
    size_t events;
} stream_path;

/* The path of a flight of `frames` frames, its teleports chosen now over
 * the scene with the host's sizes and errors (as stream_sim_start; host's
 * copy STREAM_SIM_OURS), as much of it as is read: candidates that tie (a
 * scene not read yet needs as much everywhere) go to the point farthest
 * along the path from the one the camera leaves. 0 when out of memory (p can
 * still be freed). */
int stream_path_init(stream_path *p, double loop, unsigned long every, unsigned long frames,
                     stream_sim_view_fn view, void *user, const tclod_scene *scene,
                     const double *bytes, const double *error, const stream_host *host);
void stream_path_free(stream_path *p);
/* The position along the path, in [0, loop), at frame `frame`. */
double stream_path_position(const stream_path *p, unsigned long frame);

/* ---- the simulation -------------------------------------------------------------- */

/* A copy's structure, read again after each expansion. */
typedef struct stream_nodes {
    uint32_t count;   /* tclod_scene_node_count */
    uint8_t *live;    /* 1 for a live node (not an additive node's self leaf) */
    uint8_t *unexpanded;
    tclod_id *parent; /* TCLOD_NONE for a root */
    uint32_t *first;  /* children of n: child[first[n] .. first[n + 1]) */
    tclod_id *child;  /* live children, in id order */
    tclod_id *roots;  /* live roots */
    uint32_t root_count;
    uint32_t *depth; /* 0 for a root */
    tclod_bounds *bounds;
    double *bytes;      /* the host's sizes */
    double *error;      /* the host's geometric errors, m */
    double total_bytes; /* over the live nodes that are not unexpanded */
    uint32_t unexpanded_count;
} stream_nodes;

/* A load in flight. */
typedef struct stream_load {
    tclod_id id;
    double bytes;
    double done; /* s: when its last byte arrives */
} stream_load;

/* A node in one of the baseline's orders: by key, then deeper (wanted: less
 * deep) first, then by id. */
typedef struct stream_rank {
    double key; /* wanted: -(its screen-space error); lru: its last use */
    uint32_t depth;
    tclod_id id;
} stream_rank;

/* One loader over its copy of the scene (or the all-resident copy, which
 * loads nothing and expands at once). */
typedef struct stream_loader {
    int copy;            /* STREAM_SIM_OURS, _BASE or _ALL */
    tclod_scene *scene;  /* its copy */
    tclod_selector *sel; /* its selector (ours: the host's own) */
    stream_nodes nodes;  /* its copy's structure */
    uint32_t room;       /* per-node arrays hold this many entries */
    uint8_t *state;      /* per node: STREAM_ABSENT, STREAM_LOADING or STREAM_RESIDENT */
    stream_load loads[STREAM_SIM_MAX_LOADS]; /* in flight, in order of completion */
    size_t load_count;
    double link_free;      /* s: when the link has sent what is in flight */
    double resident_bytes; /* this simulation's own sum */
    double flight_bytes;
    double loaded_bytes; /* loads completed, summed (files read included) */
    unsigned long files; /* expansions: unexpanded nodes' files read */
    int grown;           /* an expansion since its structure was read */
    /* the current frame */
    double frame_resident_bytes; /* when the frame was selected */
    unsigned long issued;        /* loads issued after its select */
    double benefit;              /* its selection's */
    /* over the flight */
    unsigned long nonresident_draws; /* drawn nodes its own residency says are absent */
    unsigned long mem_violations;    /* frames with resident bytes > the memory budget */
    unsigned long stale_requests;    /* ours: listed requests resident already (0) */
    unsigned long lost_drawn;        /* ours: listed evictions of drawn nodes (0) */
    double *t95_ms;                  /* per event: time to STREAM_SIM_T95_SHARE */
    int reached;                     /* the current event's share was reached */
    /* the baseline's scratch */
    unsigned long *used; /* per node: 1 + the last frame it was wanted or drawn; 0 never */
    unsigned long *kept; /* per node: 1 + the last frame it was drawn or above a drawn node */
    tclod_id *stack;     /* the traversal's */
    tclod_id *walk;      /* the nodes it wants */
    double *walk_sse;    /* and their errors */
    stream_rank *wanted; /* wanted nodes not resident, the largest error first */
    stream_rank *lru;    /* eviction candidates, the least recently used first */
    size_t lru_count, lru_next;
    double lru_bytes; /* of lru[lru_next .. lru_count) */
} stream_loader;

/* per node stream_loader.state */
enum { STREAM_ABSENT = 0, STREAM_LOADING = 1, STREAM_RESIDENT = 2 };

/* The whole simulation. */
typedef struct stream_sim {
    stream_sim_options opt;
    double memory_bytes; /* the memory budget M, bytes */
    double scene_bytes;  /* what the whole scene needs (stream_host.scene_bytes) */
    double latency_s, bytes_per_s;
    unsigned long frames;
    const double *bytes, *error; /* per node id, the copies alike; or NULL with host */
    stream_host host;            /* zero without one */
    stream_loader ours, base, all;
    double all_benefit; /* the all-resident copy's benefit, this frame */
    size_t events;           /* the start and the teleports */
    size_t event;            /* the current one */
    unsigned long event_frame;
    uint8_t *drawn; /* per node of any copy: 1 while in its cut (scratch) */
    uint32_t drawn_room;
    double *needed; /* per frame: bytes the all-resident selection draws and
                       refines through (what memory must hold to draw it) */
} stream_sim;

/* Starts the simulation of a flight of `frames` frames. ours is the host's
 * scene and selector; base and all are two more copies of the scene, over
 * which it creates selectors with sd. Sizes and errors: with host NULL, bytes
 * and error per node id, the copies having the same nodes with the same ids
 * (tclod_scene_node_count entries; entries of ids that are not live are not
 * read); else host's functions (bytes and error NULL). Sets the sizes in the
 * copies, and marks every node in ours and base that is no root and has
 * bytes absent. 0 after a message on stderr naming prog (stream_sim_free
 * frees what was made). */
int stream_sim_start(stream_sim *s, const stream_sim_options *opt, unsigned long frames,
                     tclod_scene *ours, tclod_selector *ours_sel, tclod_scene *base,
                     tclod_scene *all, const tclod_selector_desc *sd, const double *bytes,
                     const double *error, const stream_host *host, const char *prog);

/* Before the frame's select of ours: the loads completed by now become
 * resident, and ours is told its stream desc. 0 after a message. */
int stream_sim_before(stream_sim *s, unsigned long frame, const char *prog);

/* After the host selected ours with fr (and read its result): ours' plan is
 * carried out, the baseline and the all-resident copy select with fr, the
 * baseline's loader runs, t95 is followed. benefit: ours' selection's. 0 after
 * a message. */
int stream_sim_after(stream_sim *s, unsigned long frame, const tclod_frame *fr, double benefit,
                     const char *prog);

/* The table's columns --stream adds (each with a leading space): its header,
 * and this frame's row. */
void stream_sim_table_header(FILE *out);
void stream_sim_table_row(FILE *out, const stream_sim *s);

/* The CSV columns --stream adds (with a leading comma), and this frame's. */
void stream_sim_csv_header(FILE *out);
void stream_sim_csv_row(FILE *out, const stream_sim *s);

/* The summary keys --stream adds (each with a leading space), after the last
 * frame. Sorts the per-event times. */
void stream_sim_print_summary(FILE *out, stream_sim *s);

/* A line on the settings, for the programs' headers. */
void stream_sim_print_settings(FILE *out, const stream_sim *s);

void stream_sim_free(stream_sim *s);

#endif /* STREAM_SIM_H */
