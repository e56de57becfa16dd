/*
 * tclod_tileset_gen — writes a synthetic 3D Tiles tileset of a city for
 * tclod_tiles to fly over (docs/tiles.md, the generated tileset).
 *
 *   tclod_tileset_gen DIR [--tiles N]
 *
 * The city is 6 km square around 45.764 N, 4.836 E, so its coordinates are
 * earth-centred (about 6.4e6 m from the origin). DIR receives:
 *  - tileset.json (3D Tiles 1.1): a root region with three subtrees:
 *      terrain    a quadtree of regions (REPLACE), about 40 % of the tiles;
 *      buildings  a tile without content whose transform is the east/north/up
 *                 frame at the city's centre, over a quadtree of boxes in
 *                 metres; a quarter of it is a campus without content with
 *                 a transform of its own (turned 20 degrees), composed with
 *                 the city's; every third block of the second level refines
 *                 by ADD; blocks from the second level down have two contents
 *                 (1.1 "contents"); one campus box leans (its axes are not
 *                 orthogonal);
 *      district   a tile whose content is the external tileset district.json;
 *  - district.json (3D Tiles 1.0, "url" contents): an additive octree of
 *    spheres, about 15 % of the tiles;
 *  - sizes.tsv: uri<TAB>bytes for the contents not on disk, with every 97th
 *    left out so that tclod_tiles falls back to its estimate for them;
 *  - a few small content files (root.glb, terrain/0_0_0.glb, the four
 *    terrain/1_X_Y.glb and district/0_0.pnts: valid glTF binary and point-cloud
 *    headers around pseudo-random bytes), sized from disk.
 * The output depends only on N: the random numbers come from a fixed seed.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "geodesy.h"

#define DEFAULT_TILES 1000ul
#define MIN_TILES 40ul
#define MAX_TILES 200000ul
/* The city: its centre (degrees), the ground's height above the ellipsoid
 * there (m) and half its side (m). */
#define CITY_LAT 45.764
#define CITY_LON 4.836
#define GROUND_HEIGHT 170.0
#define CITY_HALF 3000.0
/* The campus quarter turns by this much (degrees) in its own frame. */
#define CAMPUS_TURN 20.0
/* The district: its centre east and north of the city's (m), the half side of
 * its octree's root cube (m). */
#define DISTRICT_EAST -1600.0
#define DISTRICT_NORTH -900.0
#define DISTRICT_HALF 400.0
/* Every this many contents, one is left out of sizes.tsv. */
#define SIZES_GAP 97u
#define SEED 0x3d711e5ull
/* --implicit: levels per subtree file, and the most terrain levels (40 % of
 * MAX_TILES fill 9 levels of a quadtree breadth first). */
#define SUBTREE_LEVELS 3u
#define TERRAIN_MAX_LEVELS 12u

typedef struct rng {
    uint64_t state;
} rng;

/* splitmix64: the same sequence on every platform. */
static uint64_t rng_next(rng *r) {
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [lo, hi). */
static double rng_range(rng *r, double lo, double hi) {
    return lo + (hi - lo) * ((double)(rng_next(r) >> 11) * (1.0 / 9007199254740992.0));
}

/* What is being written. */
typedef struct gen {
    const char *dir;
    rng r;
    FILE *sizes;
    unsigned contents; /* contents not on disk so far */
    unsigned long tiles;
    double lon0, lat0, dlon, dlat; /* the city's centre and half sides, radians */
    int leaning_done;
    int implicit;                           /* --implicit: the terrain by implicit tiling */
    unsigned subtrees;                      /* subtree files written */
    uint8_t *available[TERRAIN_MAX_LEVELS]; /* --implicit: per level, a byte per cell */
} gen;

static void usage(FILE *out) {
    fprintf(out,
            "usage: tclod_tileset_gen DIR [--tiles N] [--implicit]\n"
            "\n"
            "Writes a synthetic 3D Tiles tileset of a 6 km city, earth-centred at 45.764 N,\n"
            "4.836 E, into DIR (created if missing): tileset.json (1.1) with a region\n"
            "quadtree, a box quadtree under a transform with an additive part and an\n"
            "external tileset district.json (1.0, an additive octree of spheres); sizes.tsv\n"
            "(uri<TAB>bytes) for the contents not on disk; and a few small content files.\n"
            "\n"
            "  --tiles N   tiles in all, %lu <= N <= %lu (default %lu)\n"
            "  --implicit  the terrain as an implicit quadtree (3D Tiles 1.1 implicit\n"
            "              tiling): the same tiles, listed by binary subtree files\n"
            "              terrain/L_X_Y.subtree of %u levels each; its tiles' regions\n"
            "              keep the root's heights\n"
            "  --help      print this text and exit\n",
            MIN_TILES, MAX_TILES, DEFAULT_TILES, SUBTREE_LEVELS);
}

/* ---- files ----------------------------------------------------------------------- */

static char *join(const char *dir, const char *name) {
    size_t a = strlen(dir), b = strlen(name);
    char *p = (char *)malloc(a + b + 2);
    if (p) {
        memcpy(p, dir, a);
        p[a] = '/';
        memcpy(p + a + 1, name, b + 1);
    }
    return p;
}

/* Creates path and its missing parents, like mkdir -p. */
static int make_dir(const char *path) {
    char *p = join(path, "");
    size_t i, n;
    int bad = 0;
    if (!p) {
        fprintf(stderr, "tclod_tileset_gen: out of memory\n");
        return 1;
    }
    n = strlen(p);
    for (i = 1; i < n && !bad; ++i) {
        if (p[i] != '/')
            continue;
        p[i] = '\0';
        if (mkdir(p, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "tclod_tileset_gen: cannot create %s: %s\n", p, strerror(errno));
            bad = 1;
        }
        p[i] = '/';
    }
    free(p);
    return bad;
}

static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

/* Writes n bytes, or says why not. */
static int write_bytes(const char *path, const unsigned char *data, size_t n) {
    FILE *f = fopen(path, "wb");
    int bad = !f || fwrite(data, 1, n, f) != n;
    if (f && fclose(f) != 0)
        bad = 1;
    if (bad)
        fprintf(stderr, "tclod_tileset_gen: cannot write %s: %s\n", path, strerror(errno));
    return bad;
}

/* A glTF 2.0 binary: the header, a JSON chunk naming one buffer, and that
 * buffer of `payload` pseudo-random bytes (a multiple of 4). */
/* Writes n bytes to DIR/name. */
static int write_bytes_in(const gen *g, const char *name, const unsigned char *data, size_t n) {
    char *path = join(g->dir, name);
    int bad;
    if (!path) {
        fprintf(stderr, "tclod_tileset_gen: out of memory\n");
        return 1;
    }
    bad = write_bytes(path, data, n);
    free(path);
    return bad;
}

static int write_glb(gen *g, const char *name, uint32_t payload) {
    char json[160];
    size_t jl, total, i;
    unsigned char *b;
    int bad;
    snprintf(json, sizeof(json),
             "{\"asset\":{\"version\":\"2.0\",\"generator\":\"tclod_tileset_gen\"},"
             "\"buffers\":[{\"byteLength\":%lu}]}",
             (unsigned long)payload);
    jl = (strlen(json) + 3) & ~(size_t)3; /* chunks are 4-byte aligned, JSON padded by spaces */
    total = 12 + 8 + jl + 8 + payload;
    b = (unsigned char *)malloc(total);
    if (!b) {
        fprintf(stderr, "tclod_tileset_gen: out of memory\n");
        return 1;
    }
    memcpy(b, "glTF", 4);
    put_u32(b + 4, 2);
    put_u32(b + 8, (uint32_t)total);
    put_u32(b + 12, (uint32_t)jl);
    memcpy(b + 16, "JSON", 4);
    memset(b + 20, ' ', jl);
    memcpy(b + 20, json, strlen(json));
    put_u32(b + 20 + jl, payload);
    memcpy(b + 24 + jl, "BIN\0", 4);
    for (i = 0; i < payload; ++i)
        b[28 + jl + i] = (unsigned char)(rng_next(&g->r) >> 56);
    bad = write_bytes_in(g, name, b, total);
    free(b);
    return bad;
}

/* A 3D Tiles 1.0 point cloud: the header, a feature table of `points`
 * positions (float32, in a 10 m cube) and no batch table. */
static int write_pnts(gen *g, const char *name, uint32_t points) {
    char json[96];
    size_t jl, total, i;
    unsigned char *b;
    int bad;
    snprintf(json, sizeof(json), "{\"POINTS_LENGTH\":%lu,\"POSITION\":{\"byteOffset\":0}}",
             (unsigned long)points);
    jl = strlen(json);
    jl += (8 - (28 + jl) % 8) % 8; /* the binary body starts 8-byte aligned */
    total = 28 + jl + 12 * (size_t)points;
    b = (unsigned char *)malloc(total);
    if (!b) {
        fprintf(stderr, "tclod_tileset_gen: out of memory\n");
        return 1;
    }
    memcpy(b, "pnts", 4);
    put_u32(b + 4, 1);
    put_u32(b + 8, (uint32_t)total);
    put_u32(b + 12, (uint32_t)jl);
    put_u32(b + 16, 12u * points);
    put_u32(b + 20, 0);
    put_u32(b + 24, 0);
    memset(b + 28, ' ', jl);
    memcpy(b + 28, json, strlen(json));
    for (i = 0; i < 3 * (size_t)points; ++i) {
        float v = (float)rng_range(&g->r, -5.0, 5.0);
        uint32_t u;
        memcpy(&u, &v, sizeof(u));
        put_u32(b + 28 + jl + 4 * i, u);
    }
    bad = write_bytes_in(g, name, b, total);
    free(b);
    return bad;
}

/* Records a content that is not on disk: its bytes go to sizes.tsv, except
 * every SIZES_GAP-th. */
static void size_line(gen *g, const char *uri, double bytes) {
    if (++g->contents % SIZES_GAP != 0)
        fprintf(g->sizes, "%s\t%.0f\n", uri, bytes);
}

/* ---- tiles ------------------------------------------------------------------------ */

/* A new tile object with its geometric error and refinement (NULL: inherited). */
static cJSON *new_tile(gen *g, double geometric_error, const char *refine) {
    cJSON *t = cJSON_CreateObject();
    if (t) {
        cJSON_AddNumberToObject(t, "geometricError", geometric_error);
        if (refine)
            cJSON_AddStringToObject(t, "refine", refine);
    }
    ++g->tiles;
    return t;
}

static void add_volume(cJSON *tile, const char *kind, const double *v, int n) {
    cJSON *bv = cJSON_AddObjectToObject(tile, "boundingVolume");
    if (bv)
        cJSON_AddItemToObject(bv, kind, cJSON_CreateDoubleArray(v, n));
}

/* One content ("content": {"uri"} in 1.1, {"url"} in 1.0). */
static void add_content(cJSON *tile, const char *key, const char *uri) {
    cJSON *c = cJSON_AddObjectToObject(tile, "content");
    if (c)
        cJSON_AddStringToObject(c, key, uri);
}

static cJSON *children_of(cJSON *tile) {
    cJSON *c = cJSON_GetObjectItemCaseSensitive(tile, "children");
    return c ? c : cJSON_AddArrayToObject(tile, "children");
}

/* Leaves refine into nothing: 3D Tiles gives them geometric error 0. */
static void mark_leaf(cJSON *tile) {
    if (!cJSON_GetObjectItemCaseSensitive(tile, "children"))
        cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(tile, "geometricError"), 0.0);
}

/* A cell of a quadtree (or octree): its tile and where it lies. */
typedef struct cell {
    cJSON *json;
    double x0, y0, x1, y1, z0, z1; /* local metres (terrain: fractions of the city) */
    unsigned level, ix, iy, iz;
    int campus; /* in the campus frame */
} cell;

/* Queue of cells, split breadth first until the subtree holds `target`
 * tiles: an explicit queue, no recursion. */
typedef struct cell_queue {
    cell *cells;
    size_t head, count, cap;
} cell_queue;

static cell *queue_add(cell_queue *q, const cell *c) {
    if (q->count == q->cap) {
        size_t cap = q->cap ? 2 * q->cap : 64;
        cell *cells = (cell *)realloc(q->cells, cap * sizeof(*cells));
        if (!cells)
            return NULL;
        q->cells = cells;
        q->cap = cap;
    }
    q->cells[q->count] = *c;
    return &q->cells[q->count++];
}

/* Terrain height bound (m above the ellipsoid) over a cell: a hill west of
 * the centre, the ground 170 m elsewhere, measured at the cell's point
 * nearest the hilltop. */
static double terrain_top(double x0, double y0, double x1, double y1) {
    double hx = -1500.0, hy = 300.0;
    double x = hx < x0 ? x0 : (hx > x1 ? x1 : hx), y = hy < y0 ? y0 : (hy > y1 ? y1 : hy);
    double d2 = (x - hx) * (x - hx) + (y - hy) * (y - hy);
    return GROUND_HEIGHT + 130.0 * exp(-d2 / (1200.0 * 1200.0)) + 10.0;
}

/* Building height bound (m above the ground) over a cell: towers in the
 * centre, at the cell's point nearest it. */
static double skyline_top(double x0, double y0, double x1, double y1, int campus) {
    double x = 0.0 < x0 ? x0 : (0.0 > x1 ? x1 : 0.0), y = 0.0 < y0 ? y0 : (0.0 > y1 ? y1 : 0.0);
    if (campus)
        return 45.0; /* low buildings */
    return 25.0 + 175.0 * exp(-(x * x + y * y) / (900.0 * 900.0)) + 10.0;
}

static void terrain_region(const gen *g, const cell *c, double out[6]) {
    out[0] = g->lon0 + (2.0 * c->x0 - 1.0) * g->dlon;
    out[1] = g->lat0 + (2.0 * c->y0 - 1.0) * g->dlat;
    out[2] = g->lon0 + (2.0 * c->x1 - 1.0) * g->dlon;
    out[3] = g->lat0 + (2.0 * c->y1 - 1.0) * g->dlat;
    out[4] = GROUND_HEIGHT - 20.0;
    out[5] = terrain_top((2.0 * c->x0 - 1.0) * CITY_HALF, (2.0 * c->y0 - 1.0) * CITY_HALF,
                         (2.0 * c->x1 - 1.0) * CITY_HALF, (2.0 * c->y1 - 1.0) * CITY_HALF);
}

/* --implicit: whether terrain tile (level, x, y) exists. */
static int terrain_has(const gen *g, unsigned level, unsigned x, unsigned y) {
    return level < TERRAIN_MAX_LEVELS && g->available[level] &&
           g->available[level][(size_t)y << level | x];
}

/* --implicit: marks terrain tile (level, x, y) as existing. */
static int terrain_mark(gen *g, unsigned level, unsigned x, unsigned y) {
    if (!g->available[level]) {
        g->available[level] = (uint8_t *)calloc((size_t)1 << (2 * level), 1);
        if (!g->available[level]) {
            fprintf(stderr, "tclod_tileset_gen: out of memory\n");
            return 1;
        }
    }
    g->available[level][(size_t)y << level | x] = 1;
    return 0;
}

/* --implicit: the subtree file of the tiles SUBTREE_LEVELS deep below
 * terrain tile (level, x, y), binary: the tiles' availability (their
 * contents' too: every terrain tile has one) in a bitstream, in Morton order
 * level by level, then the child subtrees' (a constant 0 when there are none). */
static int write_subtree(gen *g, unsigned level, unsigned x, unsigned y) {
    unsigned char file[512], bits[16];
    char name[64], json[320];
    unsigned k, m, any = 0, bit = 0;
    size_t json_len, n;
    memset(bits, 0, sizeof(bits));
    for (k = 0; k <= SUBTREE_LEVELS; ++k) {
        if (k == SUBTREE_LEVELS)
            bit = 64; /* the child subtrees' bits: bytes 8 to 15 */
        for (m = 0; m < 1u << (2 * k); ++m, ++bit) {
            unsigned lx = 0, ly = 0, b;
            for (b = 0; b < k; ++b) {
                lx |= (m >> (2 * b) & 1u) << b;
                ly |= (m >> (2 * b + 1) & 1u) << b;
            }
            if (terrain_has(g, level + k, x << k | lx, y << k | ly)) {
                bits[bit >> 3] |= (unsigned char)(1u << (bit & 7));
                any |= k == SUBTREE_LEVELS;
            }
        }
    }
    snprintf(json, sizeof(json),
             "{\"buffers\":[{\"byteLength\":16}],\"bufferViews\":[{\"buffer\":0,"
             "\"byteOffset\":0,\"byteLength\":3},{\"buffer\":0,\"byteOffset\":8,"
             "\"byteLength\":8}],\"tileAvailability\":{\"bitstream\":0},"
             "\"contentAvailability\":[{\"bitstream\":0}],\"childSubtreeAvailability\":%s}",
             any ? "{\"bitstream\":1}" : "{\"constant\":0}");
    json_len = (strlen(json) + 7) / 8 * 8; /* padded with spaces */
    memcpy(file, "subt", 4);
    put_u32(file + 4, 1);
    put_u32(file + 8, (uint32_t)json_len);
    put_u32(file + 12, 0);
    put_u32(file + 16, (uint32_t)sizeof(bits));
    put_u32(file + 20, 0);
    memset(file + 24, ' ', json_len);
    memcpy(file + 24, json, strlen(json));
    memcpy(file + 24 + json_len, bits, sizeof(bits));
    n = 24 + json_len + sizeof(bits);
    snprintf(name, sizeof(name), "terrain/%u_%u_%u.subtree", level, x, y);
    ++g->subtrees;
    return write_bytes_in(g, name, file, n);
}

/* The terrain: a region quadtree of `target` tiles below `parent`, filled
 * breadth first; with --implicit, its root alone is in the tileset, over
 * subtree files saying which of its tiles exist. */
static int gen_terrain(gen *g, cJSON *parent, unsigned long target) {
    cell_queue q;
    cell root;
    unsigned long made = 1;
    int rc = 1;
    memset(&q, 0, sizeof(q));
    memset(&root, 0, sizeof(root));
    root.x1 = root.y1 = 1.0;
    root.json = new_tile(g, 256.0, "REPLACE");
    if (!root.json || !queue_add(&q, &root))
        goto done;
    cJSON_AddItemToArray(children_of(parent), root.json);
    for (q.head = 0; q.head < q.count; ++q.head) {
        cell c = q.cells[q.head];
        double region[6];
        char uri[64];
        int k;
        terrain_region(g, &c, region);
        if (c.json)
            add_volume(c.json, "region", region, 6);
        snprintf(uri, sizeof(uri), "terrain/%u_%u_%u.glb", c.level, c.ix, c.iy);
        if (c.json && !g->implicit)
            add_content(c.json, "uri", uri);
        if (g->implicit && terrain_mark(g, c.level, c.ix, c.iy))
            goto done;
        if (c.level <= 1) {
            /* the top levels are on disk */
            if (write_glb(g, uri, (uint32_t)(4 * (int)rng_range(&g->r, 4000.0, 12000.0))))
                goto done;
        } else {
            size_line(g, uri, rng_range(&g->r, 40e3, 160e3));
        }
        for (k = 0; k < 4 && made < target; ++k, ++made) {
            cell child = c;
            double mx = 0.5 * (c.x0 + c.x1), my = 0.5 * (c.y0 + c.y1);
            child.level = c.level + 1;
            child.ix = 2 * c.ix + (unsigned)(k & 1);
            child.iy = 2 * c.iy + (unsigned)(k >> 1);
            child.x0 = k & 1 ? mx : c.x0;
            child.x1 = k & 1 ? c.x1 : mx;
            child.y0 = k >> 1 ? my : c.y0;
            child.y1 = k >> 1 ? c.y1 : my;
            if (g->implicit) { /* no tile object: availability says it */
                child.json = NULL;
                ++g->tiles;
            } else {
                child.json = new_tile(g, 256.0 / (double)(1u << child.level), NULL);
                if (!child.json)
                    goto done;
                cJSON_AddItemToArray(children_of(c.json), child.json);
            }
            if (!queue_add(&q, &child))
                goto done;
        }
    }
    if (g->implicit) {
        /* the root's region (the city's, as high as the hill) holds every tile */
        unsigned levels = q.cells[q.count - 1].level + 1;
        cJSON *it = cJSON_AddObjectToObject(root.json, "implicitTiling"), *sub;
        add_content(root.json, "uri", "terrain/{level}_{x}_{y}.glb");
        cJSON_AddStringToObject(it, "subdivisionScheme", "QUADTREE");
        cJSON_AddNumberToObject(it, "subtreeLevels", SUBTREE_LEVELS);
        cJSON_AddNumberToObject(it, "availableLevels", levels);
        sub = cJSON_AddObjectToObject(it, "subtrees");
        cJSON_AddStringToObject(sub, "uri", "terrain/{level}_{x}_{y}.subtree");
        for (q.head = 0; q.head < q.count; ++q.head) {
            const cell *c = &q.cells[q.head];
            if (c->level % SUBTREE_LEVELS == 0 && write_subtree(g, c->level, c->ix, c->iy))
                goto done;
        }
    } else {
        for (q.head = 0; q.head < q.count; ++q.head)
            mark_leaf(q.cells[q.head].json);
    }
    rc = 0;
done:
    free(q.cells);
    return rc;
}

/* A block of buildings: its box, in its frame's metres; the campus's first
 * leaf leans (its y axis tilts towards x), which libtclod cannot take as a
 * box. */
static void building_box(gen *g, const cell *c, int leaf, double box[12]) {
    double h = skyline_top(c->x0, c->y0, c->x1, c->y1, c->campus);
    memset(box, 0, 12 * sizeof(double));
    box[0] = 0.5 * (c->x0 + c->x1);
    box[1] = 0.5 * (c->y0 + c->y1);
    box[2] = 0.5 * h;
    box[3] = 0.5 * (c->x1 - c->x0);
    box[7] = 0.5 * (c->y1 - c->y0);
    box[11] = 0.5 * h;
    if (leaf && c->campus && !g->leaning_done) {
        box[6] = 0.35 * box[7];
        g->leaning_done = 1;
    }
}

/* The buildings: a tile without content carrying the city's east/north/up
 * frame, over a box quadtree of `target` tiles (itself included). */
static int gen_buildings(gen *g, cJSON *parent, unsigned long target) {
    cell_queue q;
    cell root;
    unsigned long made = 1, i;
    double frame[16], box[12];
    int rc = 1;
    memset(&q, 0, sizeof(q));
    memset(&root, 0, sizeof(root));
    root.x0 = root.y0 = -CITY_HALF;
    root.x1 = root.y1 = CITY_HALF;
    root.json = new_tile(g, 256.0, "REPLACE");
    if (!root.json || !queue_add(&q, &root))
        goto done;
    cJSON_AddItemToArray(children_of(parent), root.json);
    geo_enu_matrix(g->lon0, g->lat0, GROUND_HEIGHT, frame);
    cJSON_AddItemToObject(root.json, "transform", cJSON_CreateDoubleArray(frame, 16));
    building_box(g, &root, 0, box);
    add_volume(root.json, "box", box, 12);
    for (q.head = 0; q.head < q.count; ++q.head) {
        cell c = q.cells[q.head];
        int k;
        for (k = 0; k < 4 && made < target; ++k, ++made) {
            cell child = c;
            double mx = 0.5 * (c.x0 + c.x1), my = 0.5 * (c.y0 + c.y1);
            const char *refine = NULL;
            child.level = c.level + 1;
            child.ix = 2 * c.ix + (unsigned)(k & 1);
            child.iy = 2 * c.iy + (unsigned)(k >> 1);
            child.x0 = k & 1 ? mx : c.x0;
            child.x1 = k & 1 ? c.x1 : mx;
            child.y0 = k >> 1 ? my : c.y0;
            child.y1 = k >> 1 ? c.y1 : my;
            if (child.level == 2 && !child.campus && (child.ix + child.iy) % 3 == 0)
                refine = "ADD"; /* a block whose detail adds to it: street furniture, trees */
            child.json = new_tile(g, 256.0 / (double)(1u << child.level), refine);
            if (!child.json)
                goto done;
            if (child.level == 1 && k == 3) {
                /* the campus: its own frame, turned about the quarter's centre */
                double t = CAMPUS_TURN * GEO_PI / 180.0, m[16];
                double hx = 0.5 * (child.x1 - child.x0), hy = 0.5 * (child.y1 - child.y0);
                geo_mat4_identity(m);
                m[0] = cos(t);
                m[1] = sin(t);
                m[4] = -sin(t);
                m[5] = cos(t);
                m[12] = 0.5 * (child.x0 + child.x1);
                m[13] = 0.5 * (child.y0 + child.y1);
                cJSON_AddItemToObject(child.json, "transform", cJSON_CreateDoubleArray(m, 16));
                child.campus = 1;
                child.x0 = -hx;
                child.x1 = hx;
                child.y0 = -hy;
                child.y1 = hy;
            }
            if (!queue_add(&q, &child))
                goto done;
            cJSON_AddItemToArray(children_of(c.json), child.json);
        }
    }
    /* boxes and contents once the tree is known, so that leaves can lean */
    for (i = 1; i < q.count; ++i) {
        cell *c = &q.cells[i];
        int leaf = !cJSON_GetObjectItemCaseSensitive(c->json, "children");
        double bytes = (150e3 + 900e3 * exp(-(c->x0 * c->x0 + c->y0 * c->y0) / (1500.0 * 1500.0))) *
                       rng_range(&g->r, 0.7, 1.3);
        char uri[64];
        building_box(g, c, leaf, box);
        add_volume(c->json, "box", box, 12);
        if (c->level == 1 && c->campus) {
            continue; /* the campus groups its blocks and draws nothing itself */
        } else if (c->level <= 1) {
            snprintf(uri, sizeof(uri), "buildings/%u_%u_%u.glb", c->level, c->ix, c->iy);
            add_content(c->json, "uri", uri);
            size_line(g, uri, bytes);
        } else {
            /* 3D Tiles 1.1: several contents, facades and roofs */
            cJSON *contents = cJSON_AddArrayToObject(c->json, "contents");
            int part;
            for (part = 0; part < 2; ++part) {
                cJSON *one = cJSON_CreateObject();
                snprintf(uri, sizeof(uri), "buildings/%u_%u_%u%s_%s.glb", c->level, c->ix, c->iy,
                         c->campus ? "_campus" : "", part ? "roofs" : "facades");
                cJSON_AddStringToObject(one, "uri", uri);
                cJSON_AddItemToArray(contents, one);
                size_line(g, uri, bytes * (part ? 0.3 : 0.7));
            }
        }
    }
    for (i = 0; i < q.count; ++i)
        mark_leaf(q.cells[i].json);
    rc = 0;
done:
    free(q.cells);
    return rc;
}

/* The district's octree: `target` spheres of 3D Tiles 1.0 under `root`, in
 * earth-centred coordinates. */
static int gen_district(gen *g, cJSON *root, unsigned long target) {
    cell_queue q;
    cell top;
    double e[3], n[3], u[3], centre[3];
    unsigned long made = 1;
    int rc = 1;
    geo_enu_axes(g->lon0, g->lat0, e, n, u);
    geo_to_ecef(g->lon0, g->lat0, GROUND_HEIGHT + DISTRICT_HALF * 0.5, centre);
    memset(&q, 0, sizeof(q));
    memset(&top, 0, sizeof(top));
    /* cells in metres east, north and up of the city's centre */
    top.x0 = DISTRICT_EAST - DISTRICT_HALF;
    top.x1 = DISTRICT_EAST + DISTRICT_HALF;
    top.y0 = DISTRICT_NORTH - DISTRICT_HALF;
    top.y1 = DISTRICT_NORTH + DISTRICT_HALF;
    top.z0 = -DISTRICT_HALF;
    top.z1 = DISTRICT_HALF;
    top.json = root;
    if (!queue_add(&q, &top))
        goto done;
    for (q.head = 0; q.head < q.count; ++q.head) {
        cell c = q.cells[q.head];
        double s[4], x = 0.5 * (c.x0 + c.x1), y = 0.5 * (c.y0 + c.y1), z = 0.5 * (c.z0 + c.z1);
        char uri[64];
        int k, i;
        for (i = 0; i < 3; ++i)
            s[i] = centre[i] + x * e[i] + y * n[i] + z * u[i];
        s[3] = 0.5 * (c.x1 - c.x0) * sqrt(3.0); /* the cube's enclosing sphere */
        add_volume(c.json, "sphere", s, 4);
        snprintf(uri, sizeof(uri), "district/%u_%lu.pnts", c.level, (unsigned long)q.head);
        add_content(c.json, "url", uri);
        if (q.head == 0) {
            if (write_pnts(g, uri, 2000))
                goto done;
        } else {
            size_line(g, uri, rng_range(&g->r, 30e3, 300e3));
        }
        for (k = 0; k < 8 && made < target; ++k, ++made) {
            cell child = c;
            child.level = c.level + 1;
            child.x0 = k & 1 ? x : c.x0;
            child.x1 = k & 1 ? c.x1 : x;
            child.y0 = k & 2 ? y : c.y0;
            child.y1 = k & 2 ? c.y1 : y;
            child.z0 = k & 4 ? z : c.z0;
            child.z1 = k & 4 ? c.z1 : z;
            child.json = new_tile(g, 32.0 / (double)(1u << child.level), NULL);
            if (!child.json || !queue_add(&q, &child))
                goto done;
            cJSON_AddItemToArray(children_of(c.json), child.json);
        }
    }
    for (q.head = 0; q.head < q.count; ++q.head)
        mark_leaf(q.cells[q.head].json);
    rc = 0;
done:
    free(q.cells);
    return rc;
}

/* ---- documents ------------------------------------------------------------------------ */

static cJSON *new_document(const char *version, double geometric_error) {
    cJSON *doc = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(doc, "asset");
    cJSON_AddStringToObject(asset, "version", version);
    cJSON_AddStringToObject(asset, "generator", "tclod_tileset_gen");
    cJSON_AddNumberToObject(doc, "geometricError", geometric_error);
    return doc;
}

static int write_document(const gen *g, const char *name, const cJSON *doc) {
    char *text = cJSON_Print(doc), *path = join(g->dir, name);
    int bad = !text || !path;
    if (!bad)
        bad = write_bytes(path, (const unsigned char *)text, strlen(text));
    else
        fprintf(stderr, "tclod_tileset_gen: out of memory\n");
    free(text);
    free(path);
    return bad;
}

/* tileset.json and district.json, with the tile counts of each part. */
static int gen_tilesets(gen *g, unsigned long tiles) {
    unsigned long district = tiles * 15 / 100, terrain = tiles * 40 / 100;
    unsigned long buildings = tiles - 2 - terrain - district; /* all but the root and the link */
    cJSON *main_doc = new_document("1.1", 1024.0), *ext_doc = new_document("1.0", 64.0);
    cJSON *root, *link, *ext_root;
    double region[6], centre[3], sphere[4];
    int rc = 1, i;

    /* the root: the whole city's region */
    root = new_tile(g, 512.0, "REPLACE");
    cJSON_AddItemToObject(main_doc, "root", root);
    region[0] = g->lon0 - g->dlon;
    region[1] = g->lat0 - g->dlat;
    region[2] = g->lon0 + g->dlon;
    region[3] = g->lat0 + g->dlat;
    region[4] = GROUND_HEIGHT - 20.0;
    region[5] = GROUND_HEIGHT + 250.0;
    add_volume(root, "region", region, 6);
    add_content(root, "uri", "root.glb");
    if (write_glb(g, "root.glb", 4 * 9000))
        goto done;
    if (gen_terrain(g, root, terrain) || gen_buildings(g, root, buildings))
        goto done;

    /* the district: a link tile in tileset.json, the octree in district.json */
    link = new_tile(g, 64.0, NULL);
    cJSON_AddItemToArray(children_of(root), link);
    geo_to_ecef(g->lon0, g->lat0, GROUND_HEIGHT + DISTRICT_HALF * 0.5, centre);
    {
        double e[3], n[3], u[3];
        geo_enu_axes(g->lon0, g->lat0, e, n, u);
        for (i = 0; i < 3; ++i)
            sphere[i] = centre[i] + DISTRICT_EAST * e[i] + DISTRICT_NORTH * n[i];
    }
    sphere[3] = DISTRICT_HALF * sqrt(3.0);
    add_volume(link, "sphere", sphere, 4);
    add_content(link, "uri", "district.json");
    ext_root = new_tile(g, 32.0, "ADD");
    cJSON_AddItemToObject(ext_doc, "root", ext_root);
    if (gen_district(g, ext_root, district))
        goto done;

    if (write_document(g, "tileset.json", main_doc) || write_document(g, "district.json", ext_doc))
        goto done;
    rc = 0;
done:
    cJSON_Delete(main_doc);
    cJSON_Delete(ext_doc);
    return rc;
}

int main(int argc, char **argv) {
    gen g;
    unsigned long tiles = DEFAULT_TILES;
    char *sizes_path = NULL, *sub;
    int i, rc = 1;

    memset(&g, 0, sizeof(g));
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--tiles") == 0) {
            char *end;
            if (i + 1 >= argc || argv[i + 1][0] == '-') {
                fprintf(stderr, "tclod_tileset_gen: --tiles needs a value\n");
                return 2;
            }
            errno = 0;
            tiles = strtoul(argv[++i], &end, 10);
            if (errno != 0 || *end != '\0' || tiles < MIN_TILES || tiles > MAX_TILES) {
                fprintf(stderr, "tclod_tileset_gen: --tiles expects %lu .. %lu, got '%s'\n",
                        MIN_TILES, MAX_TILES, argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--implicit") == 0) {
            g.implicit = 1;
        } else if (argv[i][0] == '-' || g.dir) {
            fprintf(stderr, "tclod_tileset_gen: unexpected argument '%s' (try --help)\n", argv[i]);
            return 2;
        } else {
            g.dir = argv[i];
        }
    }
    if (!g.dir) {
        fprintf(stderr, "tclod_tileset_gen: no output directory given (try --help)\n");
        return 2;
    }
    g.r.state = SEED;
    g.lon0 = CITY_LON * GEO_PI / 180.0;
    g.lat0 = CITY_LAT * GEO_PI / 180.0;
    {
        /* half the city's side in radians: metres over the radii of curvature */
        double e2 = GEO_WGS84_F * (2.0 - GEO_WGS84_F), s = sin(g.lat0);
        double w = sqrt(1.0 - e2 * s * s);
        g.dlat = CITY_HALF / (GEO_WGS84_A * (1.0 - e2) / (w * w * w));
        g.dlon = CITY_HALF / (GEO_WGS84_A / w * cos(g.lat0));
    }
    if (make_dir(g.dir))
        return 1;
    sub = join(g.dir, "terrain");
    if (!sub || make_dir(sub)) {
        free(sub);
        return 1;
    }
    free(sub);
    sub = join(g.dir, "district");
    if (!sub || make_dir(sub)) {
        free(sub);
        return 1;
    }
    free(sub);
    sizes_path = join(g.dir, "sizes.tsv");
    g.sizes = sizes_path ? fopen(sizes_path, "w") : NULL;
    if (!g.sizes) {
        fprintf(stderr, "tclod_tileset_gen: cannot write %s: %s\n",
                sizes_path ? sizes_path : "sizes.tsv", strerror(errno));
        free(sizes_path);
        return 1;
    }
    fprintf(g.sizes, "# content bytes of tileset.json and district.json: uri<TAB>bytes\n");
    rc = gen_tilesets(&g, tiles);
    if (fclose(g.sizes) != 0 && rc == 0) {
        fprintf(stderr, "tclod_tileset_gen: writing %s failed\n", sizes_path);
        rc = 1;
    }
    if (rc == 0)
        printf("tclod_tileset_gen: %lu tiles in %s/tileset.json and %s/district.json\n", g.tiles,
               g.dir, g.dir);
    if (rc == 0 && g.implicit)
        printf("tclod_tileset_gen: the terrain by implicit tiling, %u subtree files\n", g.subtrees);
    for (i = 0; i < (int)TERRAIN_MAX_LEVELS; ++i)
        free(g.available[i]);
    free(sizes_path);
    return rc;
}
