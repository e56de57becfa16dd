/*
 * tclod_tiles — a headless 3D Tiles host driving libtclod (docs/tiles.md).
 *
 * It reads a tileset.json (3D Tiles 1.0 or 1.1, external tilesets and implicit
 * tiling included),
 * makes every tile a libtclod node with its bounding volume, refinement and
 * emptiness, and flies a camera down a spiral onto it. Every frame it selects
 * the tiles to draw twice:
 *  - libtclod's greedy selector, with a benefit from each tile's screen-space
 *    error (tiles_model.h) and a cost from its content bytes, under a budget;
 *  - the way CesiumJS does by default ("sse16"): refine every visible tile
 *    whose screen-space error exceeds 16 px, whatever that costs.
 * The budget is the sse16 traversal's median cost over the flight unless
 * --budget-ms gives one (or, with --budget-ms sse16, each frame's budget is
 * what the sse16 traversal spends on it). One line per frame compares the
 * two, and a summary line ends the run:
 *
 *   summary: frames=N tiles=T violations=V mean_cost_ratio=R
 *            sse16_cost_max_over_median=X benefit_vs_sse16=Y select_us_median=A
 *            sse16_us_median=B budget_ms=M box_fallbacks=K check_errors=E
 *            max_sse_median=S sse16_max_sse_median=S16
 *
 * (one line; --help explains every key). violations counts the frames whose
 * drawn cost, summed here from this program's cost table over the ids
 * tclod_selector_cut lists, exceeds the budget; check_errors counts where the
 * library disagreed with this program's own sums, distances and areas, or
 * broke 3D Tiles' refinement rules (0 when all is well).
 *
 * With --stream the tiles stream from an empty cache (only the root resident)
 * through libtclod's load plan, beside a Cesium-like loader on a copy of the
 * scene and an all-resident copy for the benefit at best (examples/stream_sim.h,
 * docs/streaming.md). A tile takes its content bytes and has its geometric
 * error; the camera flies the default spiral down and back up and teleports
 * every 200 frames, and the summary adds how fast each loader fills the view
 * (t95) and what it loaded.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <tclod/tclod.h>

#include "stream_sim.h"
#include "tiles_model.h"
#include "tileset.h"

/* The camera: a 1080-line viewport at 16:9 with a 60 degree vertical field of
 * view, as a desktop CesiumJS viewer would have. */
#define VIEWPORT_HEIGHT 1080.0f
#define VIEWPORT_ASPECT (16.0f / 9.0f)
#define FOV_Y_DEGREES 60.0
#define DEFAULT_FRAMES 300ul
/* Render cost of content: milliseconds per 10^6 bytes. Bytes stand for the
 * vertices, indices and textures a tile sends and draws; 1 ms per MB puts the
 * sse16 traversal of a city flight at a few tens of ms per frame. */
#define DEFAULT_MS_PER_MB 1.0
/* The flight (docs/tiles.md, camera): it starts this many root radii from the
 * target, 60 degrees above the horizon, and spirals 1.25 turns down to this
 * fraction of a radius, 15 degrees above it. */
#define FLIGHT_START_RADII 3.0
#define FLIGHT_END_RADII 0.08
#define FLIGHT_START_ELEVATION 60.0
#define FLIGHT_END_ELEVATION 15.0
#define FLIGHT_TURNS 1.25
/* Bounds centred farther than this from the origin are earth-centred: "up" is
 * then the radial direction there, else +z (3D Tiles' local up). */
#define EARTH_CENTRED_MIN 1.0e6
#define PI 3.14159265358979323846
/* --stream over a tileset read on demand without --sizes: what it holds is
 * not known, and the memory defaults to CesiumJS's cache (cacheBytes,
 * 512 MiB). */
#define STREAM_UNKNOWN_MEMORY_MB 536.870912

typedef struct options {
    unsigned long frames;
    const char *tileset_path, *sizes_path, *csv_path;
    double budget_ms;
    int budget_given; /* 1: --budget-ms X; 2: --budget-ms sse16 */
    double ms_per_mb;
    int frames_given;
    int per_node;              /* --per-node: no batch callbacks */
    stream_sim_options stream; /* --stream and its options */
} options;

/* Per-tile scratch of check_cut, stamped so that it needs no clearing. */
typedef struct cut_check {
    uint32_t *drawn_stamp, *refined_stamp, *stack, *refined;
    uint32_t stamp;
} cut_check;

static int cut_check_init(cut_check *c, uint32_t tiles);
static void cut_check_free(cut_check *c);

struct host;

/* One copy of the scene with its ids: the host's own, and with --stream the
 * baseline's and the all-resident one (STREAM_SIM_OURS, _BASE, _ALL). Read on
 * demand, each copy knows the files its own loader read, so that the same
 * tile has other ids in each. */
typedef struct scene_copy {
    struct host *h; /* the callbacks' user is the copy */
    int index;
    tclod_scene *scene;
    tclod_id *id_of_tile; /* per tile: its node here, TCLOD_NONE when not here */
    uint8_t *open;        /* per tile: 1 while its node here is unexpanded */
    uint32_t *tile_of_id; /* per id: TILE_NONE for ids no tile has (an additive node's own) */
    uint32_t id_room;
} scene_copy;

/* Everything the callbacks read. */
typedef struct host {
    tileset ts;
    size_table sizes;
    int have_sizes;
    int on_demand; /* --stream: the tileset is opened (tileset_open) and read on */
    tileset_counts opened; /* the counts when it was opened */
    scene_copy copies[3];
    int copy_count;
    double ms_per_mb;
    /* per tile (tile_room entries; tiles[0 .. known) prepared) */
    uint32_t tile_room, known;
    double *cost_ms;
    double *file_bytes;     /* the size of the file a tile stood for when read unexpanded,
                               < 0 for a tile that never was */
    uint32_t *read_lo;      /* the tiles reading that file added: [read_lo, read_hi) */
    uint32_t *read_hi;
    uint8_t *failed;        /* 1: its file could not be read */
    unsigned long failed_files;
    double expand_us;       /* time spent reading files within the sse16 timing */
    uint32_t *sse_stack, *sse_drawn;
    tiles_model model;
    /* the queries of the current select (tile, screen_area, distance), checked
     * after it against this program's measures (check_queries) */
    uint32_t *query_tile, query_count;
    float *query_area, *query_distance;
    unsigned long unknown_ids, distance_errors, area_errors;
    double worst_distance_error;
    /* checks of the selections against 3D Tiles' rules (check_cut) */
    cut_check rules;
    uint32_t *rule_list;
    unsigned long rule_errors;
} host;

/* One frame of either method. */
typedef struct frame_result {
    double cost, benefit, us;
    double max_sse; /* the largest screen-space error left: of a drawn tile not refined */
    double cwsse;   /* the screen-space error of those tiles, weighted by their
                       projected areas (coverage_error) */
    uint32_t tiles;
} frame_result;

/* The camera path of docs/tiles.md: a spiral around and down onto the target.
 * With --stream the camera flies it down and back up, round and round, with
 * teleports (path). */
typedef struct flight {
    double target[3], east[3], north[3], up[3];
    double radius; /* of the sphere around the root's bounding volume */
    double start, end;
    unsigned long frames; /* of the flight */
    unsigned long spiral; /* of the spiral down: frames, or with --stream DEFAULT_FRAMES */
    const stream_path *path;
} flight;

static void usage(FILE *out) {
    fprintf(out,
            "usage: tclod_tiles [--frames N] [--sizes FILE] [--csv FILE]\n"
            "                   [--budget-ms X|sse16] [--ms-per-mb X] [--per-node]\n"
            "                   [--stream [--latency-ms L] [--bandwidth-mbps W] [--memory-mb M]\n"
            "                   [--teleport-every N] [--min-yield Y]] [--help] TILESET.json\n"
            "\n"
            "Flies a camera down a spiral onto a 3D Tiles tileset (1.0 or 1.1) and selects\n"
            "the tiles to draw every frame twice: with libtclod under a render-time budget,\n"
            "and as CesiumJS does by default (refine while the screen-space error exceeds\n"
            "16 px, the \"sse16\" traversal). Nothing is drawn.\n"
            "\n"
            "  --frames N      frames of the flight, N >= 1 (default %lu; --stream %lu)\n"
            "  --sizes FILE    content sizes, lines path<TAB>bytes (the content's path from\n"
            "                  the tileset's directory), for contents not on disk beside it\n"
            "  --csv FILE      also write the per-frame columns below to FILE (with a header)\n"
            "  --budget-ms X   budget per frame in ms, X >= 0 (default: the median of the\n"
            "                  sse16 traversal's per-frame cost over the flight); sse16:\n"
            "                  each frame's budget is the sse16 traversal's cost at that\n"
            "                  frame, to compare the two at equal cost\n"
            "  --ms-per-mb X   render cost of content in ms per 10^6 bytes, X > 0 (default %g)\n"
            "  --per-node      give libtclod only the per-node callbacks (default: the batch\n"
            "                  forms too, which take the areas of a whole batch before they\n"
            "                  split any share, so that the model measures fewer boxes itself)\n",
            DEFAULT_FRAMES, STREAM_SIM_DEFAULT_FRAMES, DEFAULT_MS_PER_MB);
    fputs(stream_sim_usage_options, out);
    fprintf(out,
            "                  With --stream, a tile's size is its content bytes (below)\n"
            "                  and its geometric error the tileset's; the camera flies the\n"
            "                  spiral of %lu frames down and back up, round and round,\n"
            "                  whatever --frames, and the budget, the sse16 traversal and\n"
            "                  the columns and keys below are of that flight and of ours\n"
            "  --help          print this text and exit\n"
            "\n"
            "A content's bytes are its file's size when it is beside the tileset, else its\n"
            "line in --sizes, else %.0f. Tiles without content cost nothing. The benefit of\n"
            "a tile is its share of the screen times 1 / (1 + sse / %.0f) (docs/tiles.md).\n"
            "\n"
            "Per frame (stdout, and --csv):\n"
            "  frame          frame number, from 0\n"
            "  budget_ms      the budget\n"
            "  cost_ms        libtclod's selection: its cost, summed over the drawn tiles\n"
            "  benefit        its benefit\n"
            "  tiles          tiles it draws\n"
            "  select_us      wall-clock time of tclod_select\n"
            "  sse16_cost_ms, sse16_benefit, sse16_tiles\n"
            "                 the same for the sse16 traversal\n"
            "  sse16_us       wall-clock time of one sse16 traversal\n"
            "  distance_m     the camera's distance to the target (CSV only)\n"
            "  max_sse, sse16_max_sse\n"
            "                 the largest screen-space error left on screen, in px: of\n"
            "                 the drawn tiles not refined further (CSV only)\n"
            "  cwsse, sse16_cwsse\n"
            "                 the screen-space error of those tiles weighted by their\n"
            "                 projected areas, px: the mean error per pixel covered\n"
            "                 (CSV only)\n"
            "\n"
            "Summary line (last line of stdout):\n"
            "  frames                      frames flown\n"
            "  tiles                       tiles loaded, external tilesets and implicit\n"
            "                              tiling included\n"
            "  violations                  frames whose drawn cost exceeds the budget\n"
            "  mean_cost_ratio             mean over frames of cost_ms / budget_ms\n"
            "  sse16_cost_max_over_median  the sse16 traversal's largest cost over its median\n"
            "  benefit_vs_sse16            mean over frames of benefit / sse16_benefit (frames\n"
            "                              where sse16_benefit is 0 left out)\n"
            "  select_us_median            median of select_us\n"
            "  sse16_us_median             median of sse16_us\n"
            "  budget_ms                   the budget (with --budget-ms sse16, its median)\n"
            "  box_fallbacks               boxes with axes that are not orthogonal, drawn as\n"
            "                              their enclosing sphere\n"
            "  check_errors                frames or queries where libtclod's cost, benefit,\n"
            "                              distance or area disagreed with this program's,\n"
            "                              or its selection broke 3D Tiles' refinement rules\n"
            "  max_sse_median              median over frames of max_sse\n"
            "  sse16_max_sse_median        median over frames of sse16_max_sse\n"
            "  cwsse_median                median over frames of cwsse\n"
            "  sse16_cwsse_median          median over frames of sse16_cwsse\n",
            DEFAULT_FRAMES, TILESET_ESTIMATE_BYTES, MODEL_HALF_QUALITY_SSE);
    fputs(stream_sim_usage_output, out);
    fputs("  baseline_vs_sse16      mean over frames of the baseline loader's benefit /\n"
          "                         sse16_benefit\n"
          "  all_resident_vs_sse16  the same for the all-resident benefit: what a loader\n"
          "                         can reach at best under the budget\n",
          out);
    fputs("\n"
          "Exit status: 0 on success, 1 when the tileset or a file cannot be read or\n"
          "libtclod fails, 2 for a bad command line.\n",
          out);
}

static int parse_ulong(const char *s, unsigned long *out) {
    char *end;
    unsigned long v;
    if (!s || *s == '\0' || *s == '-' || *s == '+')
        return 0;
    errno = 0;
    v = strtoul(s, &end, 10);
    if (errno != 0 || *end != '\0')
        return 0;
    *out = v;
    return 1;
}

static int parse_double(const char *s, double *out) {
    char *end;
    double v;
    if (!s || *s == '\0')
        return 0;
    errno = 0;
    v = strtod(s, &end);
    if (errno != 0 || *end != '\0' || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

/* 0 = run, 1 = --help given, 2 = bad command line (message already printed). */
static int parse_options(int argc, char **argv, options *o) {
    int i;
    memset(o, 0, sizeof(*o));
    o->frames = DEFAULT_FRAMES;
    o->ms_per_mb = DEFAULT_MS_PER_MB;
    stream_sim_options_default(&o->stream);
    for (i = 1; i < argc; ++i) {
        const char *opt = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int taken;
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0)
            return 1;
        if (strcmp(opt, "--per-node") == 0) {
            o->per_node = 1;
            continue;
        }
        taken = stream_sim_parse_option(&o->stream, "tclod_tiles", argc, argv, &i);
        if (taken < 0)
            return 2;
        if (taken > 0)
            continue;
        if (opt[0] != '-' || opt[1] == '\0') {
            if (o->tileset_path) {
                fprintf(stderr, "tclod_tiles: one tileset only, got '%s' and '%s'\n",
                        o->tileset_path, opt);
                return 2;
            }
            o->tileset_path = opt;
            continue;
        }
        if (strcmp(opt, "--frames") != 0 && strcmp(opt, "--sizes") != 0 &&
            strcmp(opt, "--csv") != 0 && strcmp(opt, "--budget-ms") != 0 &&
            strcmp(opt, "--ms-per-mb") != 0) {
            fprintf(stderr, "tclod_tiles: unknown option '%s' (try --help)\n", opt);
            return 2;
        }
        if (!val) {
            fprintf(stderr, "tclod_tiles: option %s needs a value\n", opt);
            return 2;
        }
        ++i;
        if (strcmp(opt, "--frames") == 0) {
            if (!parse_ulong(val, &o->frames) || o->frames < 1 || o->frames > 100000000ul) {
                fprintf(stderr, "tclod_tiles: --frames expects an integer >= 1, got '%s'\n", val);
                return 2;
            }
            o->frames_given = 1;
        } else if (strcmp(opt, "--sizes") == 0) {
            o->sizes_path = val;
        } else if (strcmp(opt, "--csv") == 0) {
            o->csv_path = val;
        } else if (strcmp(opt, "--budget-ms") == 0) {
            if (strcmp(val, "sse16") == 0) {
                o->budget_given = 2;
            } else if (!parse_double(val, &o->budget_ms) || o->budget_ms < 0.0) {
                fprintf(stderr,
                        "tclod_tiles: --budget-ms expects a number >= 0 or sse16, got '%s'\n", val);
                return 2;
            } else {
                o->budget_given = 1;
            }
        } else {
            if (!parse_double(val, &o->ms_per_mb) || !(o->ms_per_mb > 0.0)) {
                fprintf(stderr, "tclod_tiles: --ms-per-mb expects a number > 0, got '%s'\n", val);
                return 2;
            }
        }
    }
    if (!o->tileset_path) {
        fprintf(stderr, "tclod_tiles: no tileset given (try --help)\n");
        return 2;
    }
    if (!stream_sim_options_check(&o->stream, "tclod_tiles"))
        return 2;
    if (o->stream.enabled && !o->frames_given)
        o->frames = STREAM_SIM_DEFAULT_FRAMES;
    return 0;
}

static double now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of n values (the mean of the middle two for even n); sorts v. */
static double median(double *v, size_t n) {
    if (n == 0)
        return 0.0;
    qsort(v, n, sizeof(*v), compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* ---- the tileset as a libtclod scene ------------------------------------------ */

static int load_tileset(const options *o, host *h) {
    char err[1024];
    int bad;
    if (o->sizes_path) {
        if (size_table_load(o->sizes_path, &h->sizes, err, sizeof(err))) {
            fprintf(stderr, "tclod_tiles: %s\n", err);
            return 1;
        }
        h->have_sizes = 1;
    }
    /* --stream reads the root tileset alone, and the rest as the loaders ask */
    h->on_demand = o->stream.enabled;
    if (h->on_demand)
        bad = tileset_open(o->tileset_path, h->have_sizes ? &h->sizes : NULL, TILESET_MAX_TILES,
                           &h->ts, err, sizeof(err));
    else
        bad = tileset_load(o->tileset_path, h->have_sizes ? &h->sizes : NULL, &h->ts, err,
                           sizeof(err));
    if (bad) {
        fprintf(stderr, "tclod_tiles: %s\n", err);
        return 1;
    }
    h->opened = h->ts.counts;
    return 0;
}

/* A cost in ms rounded to a whole multiple of COST_QUANTUM (2^-30 ms, under
 * a picosecond): sums of such costs below 2^22 ms are exact in any order, so
 * that the sse16 traversal's cost, given as a budget, admits the same tiles
 * summed in the library's order (docs/tiles.md, cost). */
#define COST_QUANTUM (1.0 / 1073741824.0)
static double exact_cost(double ms) {
    return ms < 4194304.0 ? floor(ms / COST_QUANTUM + 0.5) * COST_QUANTUM : ms;
}

/* Grows *p, of `size`-byte entries, from `old` to `room` entries, the new ones
 * zero. 0 when out of memory (*p as it was). */
static int grow(void *p, size_t size, size_t old, size_t room) {
    void **q = (void **)p;
    char *g = (char *)realloc(*q, room * size);
    if (!g)
        return 0;
    memset(g + old * size, 0, (room - old) * size);
    *q = g;
    return 1;
}

/* The per-tile tables, grown to the tiles the tileset has now, and the
 * tiles read since the last call prepared. 0 when out of memory. */
static int grow_tiles(host *h) {
    uint32_t old = h->tile_room, room = old ? old : 64u, t;
    int c;
    while (room < h->ts.count)
        room *= 2u;
    if (room > old) {
        int ok = grow(&h->cost_ms, sizeof(double), old, room) &&
                 grow(&h->file_bytes, sizeof(double), old, room) &&
                 grow(&h->read_lo, sizeof(uint32_t), old, room) &&
                 grow(&h->read_hi, sizeof(uint32_t), old, room) &&
                 grow(&h->failed, 1, old, room) &&
                 grow(&h->sse_stack, sizeof(uint32_t), old, room) &&
                 grow(&h->sse_drawn, sizeof(uint32_t), old, room) &&
                 grow(&h->rule_list, sizeof(uint32_t), old, room) &&
                 grow(&h->query_tile, sizeof(uint32_t), 3u * (size_t)old, 3u * (size_t)room) &&
                 grow(&h->query_area, sizeof(float), 3u * (size_t)old, 3u * (size_t)room) &&
                 grow(&h->query_distance, sizeof(float), 3u * (size_t)old, 3u * (size_t)room) &&
                 grow(&h->rules.drawn_stamp, sizeof(uint32_t), old, room) &&
                 grow(&h->rules.refined_stamp, sizeof(uint32_t), old, room) &&
                 grow(&h->rules.stack, sizeof(uint32_t), old, room) &&
                 grow(&h->rules.refined, sizeof(uint32_t), old, room);
        for (c = 0; c < 3 && ok; ++c) {
            scene_copy *k = &h->copies[c];
            ok = grow(&k->id_of_tile, sizeof(tclod_id), old, room) && grow(&k->open, 1, old, room);
            for (t = old; ok && t < room; ++t)
                k->id_of_tile[t] = TCLOD_NONE;
        }
        if (!ok)
            return 0;
        h->tile_room = room;
    }
    for (t = h->known; t < h->ts.count; ++t) {
        const tile *x = &h->ts.tiles[t];
        h->cost_ms[t] = exact_cost(x->bytes * 1e-6 * h->ms_per_mb);
        h->file_bytes[t] = x->unexpanded ? x->file_bytes : -1.0;
    }
    h->known = h->ts.count;
    return h->model.ts == NULL || model_grow(&h->model) == 0;
}

/* Reads the file tile t stands for into the tileset (once, whichever copy
 * asks first). A file that cannot be read is said once and leaves t a tile
 * without content or children. 0 when out of memory. */
static int read_tile(host *h, uint32_t t) {
    char err[1024];
    uint32_t before = h->ts.count;
    if (!h->ts.tiles[t].unexpanded || h->failed[t])
        return 1;
    if (tileset_expand(&h->ts, t, err, sizeof(err))) {
        h->failed[t] = 1;
        if (h->failed_files++ == 0)
            fprintf(stderr, "tclod_tiles: %s (the tile stays without content)\n", err);
        return 1;
    }
    h->read_lo[t] = before;
    h->read_hi[t] = h->ts.count;
    /* a subtree's root took its content */
    h->cost_ms[t] = exact_cost(h->ts.tiles[t].bytes * 1e-6 * h->ms_per_mb);
    return grow_tiles(h);
}

/* The copy's id room for the scene's ids, new ones naming no tile. */
static int grow_ids(scene_copy *k) {
    uint32_t count = tclod_scene_node_count(k->scene), room = k->id_room ? k->id_room : 64u, i;
    if (count <= k->id_room)
        return 1;
    while (room < count)
        room *= 2u;
    if (!grow(&k->tile_of_id, sizeof(uint32_t), k->id_room, room))
        return 0;
    for (i = k->id_room; i < room; ++i)
        k->tile_of_id[i] = TILE_NONE;
    k->id_room = room;
    return 1;
}

/* Adds tile t to the copy below its parent's node. as_read: t as its file
 * was read, unexpanded if it then stood for a file (whatever another copy
 * read since); else as it is now. 0 after saying what failed. */
static int add_tile(scene_copy *k, uint32_t t, int as_read) {
    host *h = k->h;
    const tile *x = &h->ts.tiles[t];
    tclod_node_desc d;
    tclod_id id;
    tclod_status st;
    tile_node_desc(x, x->parent == TILE_NONE ? TCLOD_NONE : k->id_of_tile[x->parent], &d);
    if (h->failed[t]) {
        d.unexpanded = 0;
        d.empty = 1;
    } else if (as_read && h->file_bytes[t] >= 0.0) {
        d.unexpanded = 1;
        d.empty = 0;
    }
    if (d.unexpanded)
        d.bytes = h->file_bytes[t];
    st = tclod_scene_add_node_desc(k->scene, &d, &id);
    if (st == TCLOD_OK && !grow_ids(k))
        st = TCLOD_ERR_NOMEM;
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_tiles: adding tile %lu as a node failed: %s\n", (unsigned long)t,
                tclod_status_string(st));
        return 0;
    }
    k->id_of_tile[t] = id;
    k->tile_of_id[id] = t;
    k->open[t] = (uint8_t)d.unexpanded;
    return 1;
}

/* Every tile known into the copy, parents first (the tiles' order). */
static int add_tiles(scene_copy *k) {
    uint32_t t;
    for (t = 0; t < k->h->ts.count; ++t)
        if (!add_tile(k, t, 0))
            return 0;
    return 1;
}

/* The copy's scene, the callbacks' user k. 0 after saying what failed. */
static int build_copy(host *h, int index) {
    scene_copy *k = &h->copies[index];
    tclod_status st = tclod_scene_create(NULL, &k->scene);
    k->h = h;
    k->index = index;
    if (st == TCLOD_OK && !add_tiles(k))
        return 0;
    if (st == TCLOD_OK)
        st = tclod_scene_prepare(k->scene);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_tiles: building the scene failed: %s\n", tclod_status_string(st));
        return 0;
    }
    h->copy_count = index + 1;
    return 1;
}

/* stream_host.expand: unexpanded node id of copy c is read (the tileset
 * reads the file if no copy did) and replaced by what the file holds: the
 * tile itself, now with its content or as a link, and the tiles the file
 * added, unexpanded where they stand for files in turn. */
static int expand_node(void *user, int c, tclod_id id) {
    host *h = (host *)user;
    scene_copy *k = &h->copies[c];
    uint32_t t = id < k->id_room ? k->tile_of_id[id] : TILE_NONE, u;
    tclod_status st;
    if (t == TILE_NONE || !k->open[t]) {
        fprintf(stderr, "tclod_tiles: node %lu to expand is no unexpanded tile\n",
                (unsigned long)id);
        return 0;
    }
    if (!read_tile(h, t)) {
        fprintf(stderr, "tclod_tiles: out of memory\n");
        return 0;
    }
    st = tclod_scene_remove_node(k->scene, id);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_tiles: removing node %lu failed: %s\n", (unsigned long)id,
                tclod_status_string(st));
        return 0;
    }
    k->tile_of_id[id] = TILE_NONE;
    k->id_of_tile[t] = TCLOD_NONE;
    k->open[t] = 0;
    if (!add_tile(k, t, 0))
        return 0;
    if (!h->failed[t])
        for (u = h->read_lo[t]; u < h->read_hi[t]; ++u)
            if (!add_tile(k, u, 1))
                return 0;
    return 1;
}

/* The host's scene (copy 0) and the tables the callbacks index. 1 after
 * saying what failed. */
static int build_scene(host *h, double ms_per_mb) {
    h->ms_per_mb = ms_per_mb;
    if (!cut_check_init(&h->rules, 0) || !grow_tiles(h) || model_init(&h->model, &h->ts)) {
        fprintf(stderr, "tclod_tiles: out of memory\n");
        return 1;
    }
    return !build_copy(h, STREAM_SIM_OURS);
}

static void free_host(host *h) {
    int c;
    cut_check_free(&h->rules);
    free(h->rule_list);
    free(h->query_tile);
    free(h->query_area);
    free(h->query_distance);
    model_free(&h->model);
    for (c = 0; c < 3; ++c) {
        tclod_scene_destroy(h->copies[c].scene);
        free(h->copies[c].id_of_tile);
        free(h->copies[c].open);
        free(h->copies[c].tile_of_id);
    }
    free(h->cost_ms);
    free(h->file_bytes);
    free(h->read_lo);
    free(h->read_hi);
    free(h->failed);
    free(h->sse_stack);
    free(h->sse_drawn);
    tileset_free(&h->ts);
    if (h->have_sizes)
        size_table_free(&h->sizes);
}

/* ---- callbacks ----------------------------------------------------------------- */

/* The tile of node id of copy k, or TILE_NONE. */
static uint32_t tile_of(const scene_copy *k, tclod_id id) {
    return id < k->id_room ? k->tile_of_id[id] : TILE_NONE;
}

/* The tile of a queried node, or TILE_NONE (counted) for an id that is not one
 * the scene returned: the library promises never to ask about those. */
static uint32_t queried_tile(const scene_copy *k, tclod_id id) {
    uint32_t t = tile_of(k, id);
    if (t == TILE_NONE)
        ++k->h->unknown_ids;
    return t;
}

/* stream_host's functions */
static double node_bytes(void *user, int c, tclod_id id) {
    const host *h = (const host *)user;
    uint32_t t = tile_of(&h->copies[c], id);
    if (t == TILE_NONE)
        return 0.0;
    return h->copies[c].open[t] ? h->file_bytes[t] : h->ts.tiles[t].bytes;
}

static double node_error(void *user, int c, tclod_id id) {
    const host *h = (const host *)user;
    uint32_t t = tile_of(&h->copies[c], id);
    return t == TILE_NONE ? 0.0 : h->ts.tiles[t].geometric_error;
}

static int node_unexpanded(void *user, int c, tclod_id id) {
    const host *h = (const host *)user;
    uint32_t t = tile_of(&h->copies[c], id);
    return t != TILE_NONE && h->copies[c].open[t];
}

/* Keeps a query for check_queries, after the select: each node is asked once
 * per select, and at most three selects (--stream: ours, then the copies') run
 * between two checks. The library's area becomes the model's (model_note_area):
 * the box is not measured twice. */
static void take_query(host *h, uint32_t t, float area, float distance) {
    if (h->query_count < 3u * h->ts.count) {
        h->query_tile[h->query_count] = t;
        h->query_area[h->query_count] = area;
        h->query_distance[h->query_count++] = distance;
    }
    if (area >= 0.0f)
        model_note_area(&h->model, t, (double)area);
}

static double tile_benefit(host *h, uint32_t t, float area, float distance) {
    if (!(area > 0.0f))
        return 0.0; /* outside the frustum */
    return model_benefit(&h->model, t, (double)distance);
}

static double benefit_cb(void *user, const tclod_query *q) {
    scene_copy *k = (scene_copy *)user;
    uint32_t t = queried_tile(k, q->id);
    if (t == TILE_NONE || !q->view)
        return 0.0;
    take_query(k->h, t, q->screen_area, q->distance);
    return tile_benefit(k->h, t, q->screen_area, q->distance);
}

/* The batch form: every area of the batch is taken first, so that a tile's
 * share finds its siblings' areas measured (they come together). */
static void benefit_batch_cb(void *user, const tclod_batch *b, double *out) {
    scene_copy *k = (scene_copy *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i) {
        uint32_t t = queried_tile(k, b->ids[i]);
        if (t != TILE_NONE && b->view)
            take_query(k->h, t, b->screen_area[i], b->distance[i]);
    }
    for (i = 0; i < b->count; ++i) {
        uint32_t t = tile_of(k, b->ids[i]); /* counted above */
        out[i] = t == TILE_NONE || !b->view
                     ? 0.0
                     : tile_benefit(k->h, t, b->screen_area[i], b->distance[i]);
    }
}

/* The measures of the last select's queries against this program's: the
 * distance computed apart from the library (exact up to rounding), the area
 * against the library's own functions (q->screen_area is a float) and against
 * this program's, which measures the tiles the shares need before a query
 * brings their areas. */
static void check_queries(host *h) {
    const tclod_view *v = &h->model.view;
    uint32_t i;
    for (i = 0; i < h->query_count; ++i) {
        uint32_t t = h->query_tile[i];
        const tclod_bounds *b = &h->ts.tiles[t].bounds;
        double reference = model_reference_distance(b, v->eye);
        double d = (double)h->query_distance[i], a = (double)h->query_area[i];
        double lib = tclod_view_bounds_visible(v, b) ? tclod_view_bounds_area(v, b) : 0.0;
        double mine = model_measure_area(&h->model, t);
        if (fabs(d - reference) > 1e-6 * (1.0 + reference)) {
            ++h->distance_errors;
            if (fabs(d - reference) > h->worst_distance_error)
                h->worst_distance_error = fabs(d - reference);
        }
        if (fabs(a - lib) > 1e-5 * (1.0 + lib) || fabs(mine - lib) > 1e-9 * (1.0 + lib))
            ++h->area_errors;
    }
    h->query_count = 0;
}

/* A tile's cost; an unexpanded node's is that of the content it is expected
 * to bring first, which is not known before its file is read: its nearest
 * ancestor's with content (a level below costs about as much as the level
 * above in the trees producers write), 0 when it has none. */
static double copy_cost(const scene_copy *k, uint32_t t) {
    const tileset *ts = &k->h->ts;
    uint32_t a;
    if (!k->open[t])
        return k->h->cost_ms[t];
    for (a = ts->tiles[t].parent; a != TILE_NONE && ts->tiles[a].empty; a = ts->tiles[a].parent)
        ;
    return a == TILE_NONE ? 0.0 : k->h->cost_ms[a];
}

static double cost_cb(void *user, const tclod_query *q) {
    const scene_copy *k = (const scene_copy *)user;
    uint32_t t = queried_tile(k, q->id);
    return t == TILE_NONE ? 0.0 : copy_cost(k, t);
}

static void cost_batch_cb(void *user, const tclod_batch *b, double *out) {
    const scene_copy *k = (const scene_copy *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i) {
        uint32_t t = queried_tile(k, b->ids[i]);
        out[i] = t == TILE_NONE ? 0.0 : copy_cost(k, t);
    }
}

/* ---- the flight ------------------------------------------------------------------ */

static void normalize(double v[3]) {
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

static void cross(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* The sphere around a bounding volume: the flight's scale. */
static double enclosing_radius(const tclod_bounds *b) {
    int i, k;
    double r2 = 0.0;
    if (b->kind == TCLOD_BOUNDS_SPHERE)
        return b->radius;
    for (k = 0; k < 3; ++k)
        for (i = 0; i < 3; ++i)
            r2 += b->kind == TCLOD_BOUNDS_AABB
                      ? (i == k ? b->half_extents[k] * b->half_extents[k] : 0.0)
                      : b->half_axes[k][i] * b->half_axes[k][i];
    return sqrt(r2);
}

/* Fits the flight to the root's bounding volume: the target is its centre,
 * "up" the radial direction there (earth-centred) or +z (a local tileset). */
static void fit_flight(const tileset *ts, unsigned long frames, flight *f) {
    const tclod_bounds *b = &ts->tiles[0].bounds;
    static const double z[3] = {0.0, 0.0, 1.0}, x[3] = {1.0, 0.0, 0.0};
    double c2;
    int i;
    memset(f, 0, sizeof(*f));
    for (i = 0; i < 3; ++i)
        f->target[i] = b->center[i];
    c2 = f->target[0] * f->target[0] + f->target[1] * f->target[1] + f->target[2] * f->target[2];
    if (c2 > EARTH_CENTRED_MIN * EARTH_CENTRED_MIN) {
        memcpy(f->up, f->target, sizeof(f->up));
        normalize(f->up);
    } else {
        memcpy(f->up, z, sizeof(f->up));
    }
    cross(z, f->up, f->east);
    if (f->east[0] * f->east[0] + f->east[1] * f->east[1] + f->east[2] * f->east[2] < 1e-12)
        cross(f->up, x, f->east); /* up is the polar axis: any east will do */
    normalize(f->east);
    cross(f->up, f->east, f->north);
    f->radius = enclosing_radius(b);
    if (!(f->radius > 1.0))
        f->radius = 1.0; /* a point-like root still gets a flight of metres */
    f->start = FLIGHT_START_RADII * f->radius;
    f->end = FLIGHT_END_RADII * f->radius;
    f->frames = frames;
    f->spiral = frames;
}

/* The view at t in [0, 1] down the spiral: distance shrinking geometrically
 * from start to end, elevation falling linearly, azimuth turning; the camera
 * looks at the target with the local up as its up. */
static void view_at(const flight *f, double t, tclod_view *v, double *distance) {
    double d = f->start * pow(f->end / f->start, t);
    double el =
        (FLIGHT_START_ELEVATION + (FLIGHT_END_ELEVATION - FLIGHT_START_ELEVATION) * t) * PI / 180.0;
    double az = 2.0 * PI * FLIGHT_TURNS * t;
    int i;
    memset(v, 0, sizeof(*v));
    for (i = 0; i < 3; ++i) {
        double dir = cos(el) * (cos(az) * f->east[i] + sin(az) * f->north[i]) + sin(el) * f->up[i];
        v->eye[i] = f->target[i] + d * dir;
        v->forward[i] = (float)-dir;
        v->up[i] = (float)f->up[i];
    }
    v->fov_y = (float)(FOV_Y_DEGREES * PI / 180.0);
    v->aspect = VIEWPORT_ASPECT;
    /* near close enough for the ground under a low camera, far beyond the
     * root's far side */
    v->near_z = (float)(d * 1e-3 > 0.1 ? d * 1e-3 : 0.1);
    v->far_z = (float)(d + 2.0 * f->radius);
    v->viewport_height = VIEWPORT_HEIGHT;
    *distance = d;
}

/* --stream: t down the spiral at `position` frames along the loop down and
 * back up. */
static double loop_t(const flight *f, double position) {
    double last = (double)(f->spiral > 1 ? f->spiral - 1 : 1);
    double u = position <= last ? position : 2.0 * last - position;
    return u / last;
}

/* The view at a frame: down the spiral, or with --stream where the path is. */
static void camera_at(const flight *f, unsigned long frame, tclod_view *v, double *distance) {
    double t = f->frames > 1 ? (double)frame / (double)(f->frames - 1) : 0.0;
    if (f->path)
        t = loop_t(f, stream_path_position(f->path, frame));
    view_at(f, t, v, distance);
}

/* The view `position` frames along the loop (stream_sim_view_fn). */
static void loop_view(void *user, double position, tclod_view *v) {
    const flight *f = (const flight *)user;
    double distance;
    view_at(f, loop_t(f, position), v, &distance);
}

/* ---- 3D Tiles' rules, checked on a selection ----------------------------------------- */

static int cut_check_init(cut_check *c, uint32_t tiles) {
    size_t n = tiles ? tiles : 1;
    memset(c, 0, sizeof(*c));
    c->drawn_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    c->refined_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    c->stack = (uint32_t *)malloc(n * sizeof(uint32_t));
    c->refined = (uint32_t *)malloc(n * sizeof(uint32_t));
    return c->drawn_stamp && c->refined_stamp && c->stack && c->refined;
}

static void cut_check_free(cut_check *c) {
    free(c->drawn_stamp);
    free(c->refined_stamp);
    free(c->stack);
    free(c->refined);
}

/* Whether tile t is in libtclod's copy, read and resident. */
static int tile_resident(const host *h, const stream_loader *L, uint32_t t) {
    const scene_copy *k = &h->copies[STREAM_SIM_OURS];
    tclod_id id = k->id_of_tile[t];
    return id != TCLOD_NONE && !k->open[t] && id < L->nodes.count &&
           L->state[id] == STREAM_RESIDENT;
}

/* Whether the drawn tiles (list[0 .. n), in drawing order) obey 3D Tiles:
 * no tile twice; above a drawn tile, every tile with content is refined,
 * which a REPLACE tile is by not being drawn and an ADD tile by being drawn
 * too, and listed first; and no hole: below a refined tile, every tile in the
 * frustum that neither draws nor has drawn descendants must be refined into
 * nothing visible, so that each leaf with content reached through such tiles
 * in the frustum is drawn. With --stream, state (libtclod's loader, else
 * NULL) says which tiles are not there yet (not read, or not resident): no
 * hole is looked for in them, nor in tiles whose file is not read. 0 when they do; else 1 and a message for the first
 * fault in why. */
static int check_cut(host *h, cut_check *c, const uint32_t *list, size_t n,
                     const stream_loader *state, char *why, size_t why_size) {
    const tileset *ts = &h->ts;
    size_t i, refined = 0;
    uint32_t s = ++c->stamp;
    int faults = 0;
    if (s == 0) {
        memset(c->drawn_stamp, 0, ts->count * sizeof(uint32_t));
        memset(c->refined_stamp, 0, ts->count * sizeof(uint32_t));
        s = c->stamp = 1;
    }
    /* every check goes on after a fault, so that the stamps are whole for
     * max_error; the first fault is the one reported */
    for (i = 0; i < n; ++i) {
        uint32_t t = list[i];
        if (c->drawn_stamp[t] == s && !faults++)
            snprintf(why, why_size, "tile %lu is listed twice", (unsigned long)t);
        c->drawn_stamp[t] = s;
    }
    for (i = 0; i < n; ++i) {
        uint32_t a = ts->tiles[list[i]].parent;
        for (; a != TILE_NONE; a = ts->tiles[a].parent) {
            const tile *x = &ts->tiles[a];
            if (c->refined_stamp[a] != s) {
                c->refined_stamp[a] = s;
                c->refined[refined++] = a;
            }
            if (x->empty)
                continue;
            if (x->refine == TCLOD_REFINE_REPLACE && c->drawn_stamp[a] == s && !faults++)
                snprintf(why, why_size, "tile %lu is drawn with its replaced ancestor %lu",
                         (unsigned long)list[i], (unsigned long)a);
            if (x->refine == TCLOD_REFINE_ADD && c->drawn_stamp[a] != s && !faults++)
                snprintf(why, why_size, "tile %lu is drawn but its additive ancestor %lu is not",
                         (unsigned long)list[i], (unsigned long)a);
        }
    }
    /* holes: a refined tile's children, looked through where they draw nothing */
    for (i = 0; i < refined; ++i) {
        const tile *p = &ts->tiles[c->refined[i]];
        size_t top = 0;
        uint32_t k;
        if (p->empty)
            continue;
        for (k = 0; k < p->child_count; ++k)
            c->stack[top++] = ts->children[p->first_child + k];
        while (top > 0) {
            uint32_t t = c->stack[--top];
            const tile *x = &ts->tiles[t];
            if (x->unexpanded || model_area(&h->model, t) <= 0.0 ||
                model_out_of_request(&h->model, t) || c->drawn_stamp[t] == s ||
                c->refined_stamp[t] == s || (state && !tile_resident(h, state, t)))
                continue;
            if (x->child_count == 0 && !x->empty && !faults++)
                snprintf(why, why_size,
                         "tile %lu is refined but %lu, a leaf in the frustum below it, is not "
                         "drawn",
                         (unsigned long)c->refined[i], (unsigned long)t);
            for (k = 0; k < x->child_count; ++k)
                c->stack[top++] = ts->children[x->first_child + k];
        }
    }
    return faults > 0;
}

/* Checks one method's selection at a frame (state as check_cut's); the first
 * fault is reported. */
static void check_rules(host *h, const char *method, unsigned long frame, const uint32_t *list,
                        size_t n, const stream_loader *state) {
    char why[256];
    if (check_cut(h, &h->rules, list, n, state, why, sizeof(why))) {
        if (h->rule_errors++ == 0)
            fprintf(stderr, "tclod_tiles: frame %lu: %s's selection breaks 3D Tiles' rules: %s\n",
                    frame, method, why);
    }
}

/* The largest screen-space error among the drawn tiles that check_rules has
 * just found unrefined (an additive tile drawn with its children is refined,
 * its error no longer on screen). */
static double max_error(host *h, const uint32_t *list, size_t n) {
    double worst = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        uint32_t t = list[i];
        if (h->rules.refined_stamp[t] != h->rules.stamp) {
            double e = model_sse(&h->model, t, model_distance(&h->model, t));
            worst = e > worst ? e : worst;
        }
    }
    return worst;
}

/* The screen-coverage-weighted screen-space error of the drawn tiles that
 * check_rules has just found unrefined: their errors weighted by their
 * projected areas (tclod_view_bounds_area, at most the viewport's, 0 outside
 * the frustum), the mean error per pixel of what is on screen. 0 when they
 * cover nothing. */
static double coverage_error(host *h, const uint32_t *list, size_t n) {
    double area = 0.0, sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        uint32_t t = list[i];
        if (h->rules.refined_stamp[t] != h->rules.stamp) {
            double a = model_area(&h->model, t);
            area += a;
            sum += a * model_sse(&h->model, t, model_distance(&h->model, t));
        }
    }
    return area > 0.0 ? sum / area : 0.0;
}

/* ---- the sse16 traversal ---------------------------------------------------------- */

/* CesiumJS's default selection without its loading logic: from the root,
 * visible tiles (frustum test) are refined while their screen-space error
 * exceeds 16 px; a replaced tile is not drawn, an additive one is, and so is
 * every visible tile reached and not refined. Tiles without content draw
 * nothing and are always refined through (libtclod's empty nodes too hand
 * their place to their children). Explicit stack; the drawn tiles go to
 * drawn[]. As a 3D Tiles renderer does, it measures with the view prepared
 * once per frame (its frustum's planes, within the timing) and the volumes
 * prepared once (the model's, tiles_model.h), not with the library's public
 * helpers, which prepare both on every call. */
static int sse16_frame(host *h, unsigned long frame, const tclod_view *v, frame_result *out) {
    const tileset *ts = &h->ts;
    tiles_model *m = &h->model;
    size_t top = 0;
    uint32_t n = 0, i;
    double cost = 0.0, benefit = 0.0, t0, t1;

    h->expand_us = 0.0;
    t0 = now_us();
    model_set_view(m, v);
    h->sse_stack[top++] = 0;
    while (top > 0) {
        uint32_t t = h->sse_stack[--top];
        const tile *x;
        int refine;
        if (!model_visible(m, t) || model_out_of_request(m, t))
            continue;
        if (ts->tiles[t].unexpanded) {
            /* read on demand: the traversal sees the tileset whole, the file
             * it reaches read now, outside its time */
            double e0 = now_us();
            if (!read_tile(h, t)) {
                fprintf(stderr, "tclod_tiles: out of memory\n");
                return 1;
            }
            h->expand_us += now_us() - e0;
        }
        x = &ts->tiles[t];
        if (x->unexpanded)
            continue; /* its file could not be read */
        refine = x->child_count > 0 &&
                 (x->empty || model_sse(m, t, model_distance(m, t)) > MODEL_SSE_REF);
        if (refine || m->link[t].children_bound) {
            int seen = 0;
            for (i = 0; i < x->child_count && !seen; ++i)
                seen = model_visible(m, ts->children[x->first_child + i]);
            if (!seen && m->link[t].children_bound)
                continue;            /* its children bound what it shows, and none is in view */
            refine = refine && seen; /* none in view: the tile is drawn instead */
        }
        if (!x->empty && (!refine || x->refine == TCLOD_REFINE_ADD)) {
            h->sse_drawn[n++] = t;
            cost += h->cost_ms[t];
        }
        if (refine)
            for (i = x->child_count; i > 0; --i)
                h->sse_stack[top++] = ts->children[x->first_child + i - 1];
    }
    t1 = now_us() - h->expand_us;
    /* its benefit under the same model, outside the timing */
    for (i = 0; i < n; ++i)
        benefit += model_benefit(m, h->sse_drawn[i], model_distance(m, h->sse_drawn[i]));
    check_rules(h, "the sse16 traversal", frame, h->sse_drawn, n, NULL);
    out->max_sse = max_error(h, h->sse_drawn, n);
    out->cwsse = coverage_error(h, h->sse_drawn, n);
    out->cost = cost;
    out->benefit = benefit;
    out->tiles = n;
    out->us = t1 - t0;
    return 0;
}

/* The whole flight's sse16 frames, first: their median cost is the budget.
 * Read on demand, it reads the files its views reach. */
static int run_sse16(host *h, const flight *f, frame_result *results) {
    unsigned long frame;
    for (frame = 0; frame < f->frames; ++frame) {
        tclod_view view;
        double distance;
        camera_at(f, frame, &view, &distance);
        if (sse16_frame(h, frame, &view, &results[frame]))
            return 1;
    }
    return 0;
}

/* ---- libtclod's frames ------------------------------------------------------------- */

/* Figures over the flight, for the summary. */
typedef struct totals {
    unsigned long violations, cost_mismatches, benefit_mismatches, dropped_frames;
    double sum_cost_ratio, sum_benefit_ratio;
    double sum_base_ratio, sum_all_ratio; /* --stream: the baseline's, the all-resident's */
    unsigned long benefit_frames;
} totals;

/* A row of the table or the CSV; ss: --stream's simulation, else NULL. */
static void print_row(FILE *out, int csv, unsigned long frame, double budget,
                      const frame_result *mine, const frame_result *base, double distance,
                      const stream_sim *ss) {
    if (csv)
        fprintf(out, "%lu,%.9g,%.9g,%.9g,%lu,%.3f,%.9g,%.9g,%lu,%.3f,%.3f,%.6g,%.6g,%.6g,%.6g",
                frame, budget, mine->cost, mine->benefit, (unsigned long)mine->tiles, mine->us,
                base->cost, base->benefit, (unsigned long)base->tiles, base->us, distance,
                mine->max_sse, base->max_sse, mine->cwsse, base->cwsse);
    else
        fprintf(out, "%6lu %9.3f %9.3f %12.1f %6lu %9.1f %13.3f %13.1f %11lu %9.1f", frame, budget,
                mine->cost, mine->benefit, (unsigned long)mine->tiles, mine->us, base->cost,
                base->benefit, (unsigned long)base->tiles, base->us);
    if (ss && csv)
        stream_sim_csv_row(out, ss);
    else if (ss)
        stream_sim_table_row(out, ss);
    fputc('\n', out);
}

/* The host's side of the simulation: sizes, errors and expansions by copy. */
static stream_host stream_host_of(host *h) {
    stream_host sh;
    memset(&sh, 0, sizeof(sh));
    sh.user = h;
    sh.bytes = node_bytes;
    sh.error = node_error;
    sh.unexpanded = node_unexpanded;
    sh.expand = expand_node;
    sh.selector_user[0] = &h->copies[STREAM_SIM_BASE];
    sh.selector_user[1] = &h->copies[STREAM_SIM_ALL];
    /* read on demand, the sizes file tells what the whole tileset holds */
    if (h->opened.unexpanded && h->have_sizes) {
        size_t i;
        for (i = 0; i < h->sizes.count; ++i)
            sh.scene_bytes += h->sizes.entries[i].bytes;
    }
    return sh;
}

/* --stream: the simulation over the scene and its copies (their selectors'
 * callbacks take the copy). 0 after saying what failed. */
static int start_stream(host *h, const options *o, tclod_selector *sel,
                        const tclod_selector_desc *sd, stream_sim *ss) {
    stream_host sh = stream_host_of(h);
    stream_sim_options so = o->stream;
    if (h->opened.unexpanded && !sh.scene_bytes && !(so.memory_mb > 0.0))
        so.memory_mb = STREAM_UNKNOWN_MEMORY_MB;
    return stream_sim_start(ss, &so, o->frames, h->copies[STREAM_SIM_OURS].scene, sel,
                            h->copies[STREAM_SIM_BASE].scene, h->copies[STREAM_SIM_ALL].scene, sd,
                            NULL, NULL, &sh, "tclod_tiles");
}

/* Selects every frame of the flight under the budget, prints and writes the
 * rows, and sums the figures of the summary. */
static int run_tclod(host *h, const options *o, const flight *f, const double *budgets,
                     const frame_result *base, FILE *csv, frame_result *mine, totals *tot,
                     stream_sim *ss) {
    tclod_selector_desc sd;
    tclod_selector *sel = NULL;
    tclod_status st;
    unsigned long frame;

    tclod_selector_desc_default(&sd);
    sd.callbacks.benefit = benefit_cb;
    sd.callbacks.cost = cost_cb;
    if (!o->per_node) {
        sd.callbacks.benefit_batch = benefit_batch_cb;
        sd.callbacks.cost_batch = cost_batch_cb;
    }
    sd.callbacks.user = &h->copies[STREAM_SIM_OURS];
    /* a tileset's levels need not gain at every step (a producer's child may
     * carry a larger geometric error than its parent): an increment looks
     * one level past the children (docs/tiles.md, the solver) */
    sd.greedy.lookahead = 1;
    st = tclod_selector_create(h->copies[STREAM_SIM_OURS].scene, &sd, NULL, &sel);
    if (st != TCLOD_OK) {
        fprintf(stderr, "tclod_tiles: creating the selector failed: %s\n", tclod_status_string(st));
        return 1;
    }
    if (ss && !start_stream(h, o, sel, &sd, ss)) {
        tclod_selector_destroy(sel);
        return 1;
    }
    if (ss)
        stream_sim_print_settings(stdout, ss);
    printf("%6s %9s %9s %12s %6s %9s %13s %13s %11s %9s", "frame", "budget_ms", "cost_ms",
           "benefit", "tiles", "select_us", "sse16_cost_ms", "sse16_benefit", "sse16_tiles",
           "sse16_us");
    if (ss)
        stream_sim_table_header(stdout);
    printf("\n");
    for (frame = 0; frame < f->frames; ++frame) {
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats;
        const tclod_id *ids;
        size_t n, i;
        double t0, t1, distance, cost = 0.0, benefit = 0.0, budget = budgets[frame];
        frame_result *r = &mine[frame];

        camera_at(f, frame, &view, &distance);
        memset(&fr, 0, sizeof(fr));
        fr.view = &view;
        fr.budget = budget;
        if (ss && !stream_sim_before(ss, frame, "tclod_tiles")) {
            tclod_selector_destroy(sel);
            return 1;
        }
        /* the callbacks' view is prepared within the timing: it is the
         * selection's work */
        t0 = now_us();
        model_set_view(&h->model, &view);
        st = tclod_select(sel, &fr, &stats);
        t1 = now_us();
        check_queries(h);
        if (st == TCLOD_OK)
            st = tclod_selector_cut(sel, &ids, &n);
        if (st != TCLOD_OK) {
            fprintf(stderr, "tclod_tiles: selecting frame %lu failed: %s\n", frame,
                    tclod_status_string(st));
            tclod_selector_destroy(sel);
            return 1;
        }
        /* the budget guarantee, checked from outside: this program's costs of
         * the listed tiles, summed in the listed order */
        for (i = 0; i < n; ++i) {
            uint32_t t = tile_of(&h->copies[STREAM_SIM_OURS], ids[i]);
            if (t == TILE_NONE) {
                fprintf(stderr, "tclod_tiles: frame %lu: the cut lists node %lu, no tile's\n",
                        frame, (unsigned long)ids[i]);
                tclod_selector_destroy(sel);
                return 1;
            }
            cost += h->cost_ms[t];
            benefit += model_benefit(&h->model, t, model_distance(&h->model, t));
            h->rule_list[i] = t;
        }
        check_rules(h, "libtclod", frame, h->rule_list, n, ss ? &ss->ours : NULL);
        r->max_sse = max_error(h, h->rule_list, n);
        r->cwsse = coverage_error(h, h->rule_list, n);
        r->cost = cost;
        r->benefit = benefit;
        r->tiles = (uint32_t)n;
        r->us = t1 - t0;
        tot->violations += cost > budget;
        tot->cost_mismatches += fabs(cost - stats.cost) > 1e-9 * (1.0 + cost);
        tot->benefit_mismatches += fabs(benefit - stats.benefit) > 1e-6 * (1.0 + benefit);
        tot->dropped_frames += stats.dropped_roots > 0;
        tot->sum_cost_ratio += budget > 0.0 ? cost / budget : 0.0;
        if (base[frame].benefit > 0.0) {
            tot->sum_benefit_ratio += benefit / base[frame].benefit;
            ++tot->benefit_frames;
        }
        if (ss && !stream_sim_after(ss, frame, &fr, stats.benefit, "tclod_tiles")) {
            tclod_selector_destroy(sel);
            return 1;
        }
        if (ss && base[frame].benefit > 0.0) {
            tot->sum_base_ratio += ss->base.benefit / base[frame].benefit;
            tot->sum_all_ratio += ss->all_benefit / base[frame].benefit;
        }
        check_queries(h); /* those of the copies' selects (--stream) */
        print_row(stdout, 0, frame, budget, r, &base[frame], distance, ss);
        if (csv)
            print_row(csv, 1, frame, budget, r, &base[frame], distance, ss);
    }
    tclod_selector_destroy(sel);
    return 0;
}

/* ---- reports ------------------------------------------------------------------------ */

static void print_header(const options *o, const host *h, const flight *f, double budget) {
    static const char *const source[3] = {"median of the sse16 traversal's costs", "--budget-ms",
                                          "median; each frame's is the sse16 traversal's cost"};
    const tileset_counts *c = &h->ts.counts;
    char warnings[1024];
    printf("tileset %s: %lu tiles (%lu regions, %lu boxes, %lu spheres), %lu without "
           "content, %lu refining by ADD, %lu external tilesets, %lu implicit roots (%lu "
           "subtrees), depth %lu\n",
           o->tileset_path, (unsigned long)h->ts.count, (unsigned long)c->regions,
           (unsigned long)c->boxes, (unsigned long)c->spheres, (unsigned long)c->empty,
           (unsigned long)c->additive, (unsigned long)c->external, (unsigned long)c->implicit,
           (unsigned long)c->subtrees, (unsigned long)c->max_depth);
    printf("box fallbacks: %lu boxes with axes that are not orthogonal are drawn as their "
           "enclosing sphere\n",
           (unsigned long)c->box_fallbacks);
    printf("content: %lu contents, %.1f MB (%.0f bytes): %lu sized from files, %lu from %s, "
           "%lu estimated at %.0f bytes; cost %g ms per MB\n",
           (unsigned long)c->contents, c->bytes * 1e-6, c->bytes, (unsigned long)c->from_file,
           (unsigned long)c->from_sizes, o->sizes_path ? o->sizes_path : "--sizes",
           (unsigned long)c->estimated, TILESET_ESTIMATE_BYTES, o->ms_per_mb);
    tileset_warning_text(c, warnings, sizeof(warnings));
    printf("reader: %s\n", warnings[0] ? warnings : "no deviation from 3D Tiles");
    if (f->path)
        printf("flight: %lu frames round a spiral of %lu frames down, %.0f m to %.0f m from the "
               "root's centre (radius %.0f m), and back up; budget %.3f ms (%s)\n\n",
               f->frames, f->spiral, f->start, f->end, f->radius, budget, source[o->budget_given]);
    else
        printf("flight: %lu frames, %.0f m down to %.0f m from the root's centre (radius %.0f m); "
               "budget %.3f ms (%s)\n\n",
               f->frames, f->start, f->end, f->radius, budget, source[o->budget_given]);
}

static void print_summary(const host *h, unsigned long frames, double budget, frame_result *mine,
                          frame_result *base, const totals *tot, stream_sim *ss) {
    double *v = (double *)malloc(frames * sizeof(double));
    double base_max = 0.0, base_median, select_median, sse16_median, max_sse, sse16_max_sse;
    double cwsse, sse16_cwsse;
    unsigned long i, check_errors;
    if (!v) {
        fprintf(stderr, "tclod_tiles: out of memory\n");
        return;
    }
    for (i = 0; i < frames; ++i) {
        v[i] = base[i].cost;
        base_max = base[i].cost > base_max ? base[i].cost : base_max;
    }
    base_median = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = mine[i].us;
    select_median = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = base[i].us;
    sse16_median = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = mine[i].max_sse;
    max_sse = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = base[i].max_sse;
    sse16_max_sse = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = mine[i].cwsse;
    cwsse = median(v, frames);
    for (i = 0; i < frames; ++i)
        v[i] = base[i].cwsse;
    sse16_cwsse = median(v, frames);
    free(v);

    check_errors = tot->cost_mismatches + tot->benefit_mismatches + h->unknown_ids +
                   h->distance_errors + h->area_errors + h->rule_errors;
    if (tot->cost_mismatches || tot->benefit_mismatches)
        fprintf(stderr,
                "tclod_tiles: in %lu frames the library's cost, in %lu its benefit, differs "
                "from the sum over the drawn tiles\n",
                tot->cost_mismatches, tot->benefit_mismatches);
    if (h->unknown_ids)
        fprintf(stderr, "tclod_tiles: %lu callback queries named a node that is no tile\n",
                h->unknown_ids);
    if (h->distance_errors)
        fprintf(stderr,
                "tclod_tiles: %lu queries carried a distance off the bounding volume's by up "
                "to %g m\n",
                h->distance_errors, h->worst_distance_error);
    if (h->area_errors)
        fprintf(stderr,
                "tclod_tiles: %lu queries carried a screen area other than "
                "tclod_view_bounds_area's\n",
                h->area_errors);
    if (h->rule_errors)
        fprintf(stderr, "tclod_tiles: %lu selections broke 3D Tiles' rules (the first above)\n",
                h->rule_errors);
    if (tot->dropped_frames)
        fprintf(stderr,
                "tclod_tiles: in %lu frames even the root did not fit the budget and "
                "nothing was drawn\n",
                tot->dropped_frames);
    printf("\nsummary: frames=%lu tiles=%lu violations=%lu mean_cost_ratio=%.4f "
           "sse16_cost_max_over_median=%.4f benefit_vs_sse16=%.4f select_us_median=%.1f "
           "sse16_us_median=%.1f budget_ms=%.4f box_fallbacks=%lu check_errors=%lu "
           "max_sse_median=%.2f sse16_max_sse_median=%.2f cwsse_median=%.3f "
           "sse16_cwsse_median=%.3f",
           frames, (unsigned long)h->ts.count, tot->violations,
           tot->sum_cost_ratio / (double)frames, base_median > 0.0 ? base_max / base_median : 0.0,
           tot->benefit_frames ? tot->sum_benefit_ratio / (double)tot->benefit_frames : 0.0,
           select_median, sse16_median, budget, (unsigned long)h->ts.counts.box_fallbacks,
           check_errors, max_sse, sse16_max_sse, cwsse, sse16_cwsse);
    if (ss) {
        stream_sim_print_summary(stdout, ss);
        printf(" baseline_vs_sse16=%.4f all_resident_vs_sse16=%.4f",
               tot->benefit_frames ? tot->sum_base_ratio / (double)tot->benefit_frames : 0.0,
               tot->benefit_frames ? tot->sum_all_ratio / (double)tot->benefit_frames : 0.0);
    }
    printf("\n");
}

/* The budget of every frame into budgets[]; returns the one the header and
 * summary report: --budget-ms X, else the median of the sse16 traversal's
 * costs (with --budget-ms sse16 each frame's budget is that frame's cost). */
static double choose_budgets(const options *o, const frame_result *base, double *budgets) {
    unsigned long i;
    double budget;
    for (i = 0; i < o->frames; ++i)
        budgets[i] = base[i].cost;
    budget = o->budget_given == 1 ? o->budget_ms : median(budgets, o->frames);
    for (i = 0; i < o->frames; ++i)
        budgets[i] = o->budget_given == 2 ? base[i].cost : budget;
    if (o->budget_given == 0 && !(budget > 0.0))
        fprintf(stderr, "tclod_tiles: the sse16 traversal draws nothing in half the frames, "
                        "so the budget is 0: give one with --budget-ms\n");
    return budget;
}

/* The CSV file with its header, or NULL (said why). */
static FILE *open_csv(const char *path, int streaming) {
    FILE *csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "tclod_tiles: cannot write %s: %s\n", path, strerror(errno));
        return NULL;
    }
    fprintf(csv, "frame,budget_ms,cost_ms,benefit,tiles,select_us,sse16_cost_ms,"
                 "sse16_benefit,sse16_tiles,sse16_us,distance_m,max_sse,sse16_max_sse,cwsse,"
                 "sse16_cwsse");
    if (streaming)
        stream_sim_csv_header(csv);
    fputc('\n', csv);
    return csv;
}

int main(int argc, char **argv) {
    options opt;
    host h;
    flight f;
    totals tot;
    frame_result *base = NULL, *mine = NULL;
    FILE *csv = NULL;
    double budget, *budgets = NULL;
    stream_sim stream, *ss = NULL;
    stream_path path;
    int rc;

    memset(&h, 0, sizeof(h));
    memset(&tot, 0, sizeof(tot));
    memset(&stream, 0, sizeof(stream));
    memset(&path, 0, sizeof(path));
    rc = parse_options(argc, argv, &opt);
    if (rc == 1) {
        usage(stdout);
        return 0;
    }
    if (rc != 0)
        return rc;

    rc = 1;
    if (load_tileset(&opt, &h) || build_scene(&h, opt.ms_per_mb))
        goto done;
    fit_flight(&h.ts, opt.frames, &f);
    if (opt.stream.enabled) {
        /* the spiral of the default flight, down and back up, with teleports */
        f.spiral = DEFAULT_FRAMES;
        stream_host sh = stream_host_of(&h);
        if (!build_copy(&h, STREAM_SIM_BASE) || !build_copy(&h, STREAM_SIM_ALL))
            goto done;
        if (!stream_path_init(&path, 2.0 * (double)(DEFAULT_FRAMES - 1u), opt.stream.teleport_every,
                              opt.frames, loop_view, &f, h.copies[STREAM_SIM_OURS].scene, NULL,
                              NULL, &sh)) {
            fprintf(stderr, "tclod_tiles: out of memory\n");
            goto done;
        }
        f.path = &path;
        ss = &stream;
    }
    base = (frame_result *)calloc(opt.frames, sizeof(*base));
    mine = (frame_result *)calloc(opt.frames, sizeof(*mine));
    budgets = (double *)malloc(opt.frames * sizeof(*budgets));
    if (!base || !mine || !budgets) {
        fprintf(stderr, "tclod_tiles: out of memory\n");
        goto done;
    }
    /* the sse16 traversal over the whole flight first: it sets the budget */
    if (run_sse16(&h, &f, base))
        goto done;
    budget = choose_budgets(&opt, base, budgets);
    if (opt.csv_path && !(csv = open_csv(opt.csv_path, ss != NULL)))
        goto done;
    print_header(&opt, &h, &f, budget);
    if (run_tclod(&h, &opt, &f, budgets, base, csv, mine, &tot, ss))
        goto done;
    print_summary(&h, opt.frames, budget, mine, base, &tot, ss);
    rc = 0;

done:
    if (csv && fclose(csv) != 0 && rc == 0) {
        fprintf(stderr, "tclod_tiles: writing %s failed\n", opt.csv_path);
        rc = 1;
    }
    free(base);
    free(mine);
    free(budgets);
    stream_sim_free(&stream);
    stream_path_free(&path);
    free_host(&h);
    return rc;
}
