/*
 * fuzz_tileset — the 3D Tiles reader (examples/tiles/tileset.c) on files made
 * from the fuzzer's bytes (tests/fuzz/README.md, the tileset target).
 *
 * Input: tileset.json's text up to the first NUL byte, then records that
 * write the other files a tileset may name: a byte choosing the name (of
 * FILE_NAMES, modulo their count), a little-endian 16-bit length, and that
 * many bytes. Every file not written by the input is removed first, so that
 * each input reads only its own.
 *
 * Checks, whatever the files hold:
 *  - a failed load says why (a message naming a file) and leaves the tileset
 *    untouched;
 *  - a tileset that loads has its tiles parents first, children lists that
 *    agree with the parents, depths and ADD anchors that follow them, finite
 *    geometric errors and bytes >= 0, volumes tclod_bounds_validate takes, and
 *    its counts add up;
 *  - libtclod takes every tile as a node (tclod_scene_add_node_desc, as
 *    tclod_tiles adds them);
 *  - opened on demand (tileset_open), the same holds after the open and after
 *    each tileset_expand of its unexpanded tiles in turn (leaves without
 *    children, counted); a failed expansion says why and changes no count;
 *    when the whole load succeeds, so does every expansion, and they end
 *    with the same tiles and files read.
 * Tilesets are loaded with at most FUZZ_MAX_TILES tiles.
 * A broken check aborts. FUZZ_TRACE=1 in the environment prints what each input
 * loaded, or why it was refused.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <tclod/tclod.h>

#include "tileset.h"

/* The files an input may write beside tileset.json: the names its seeds'
 * tilesets use (subtrees s{level}{x}{y}.subtree, a buffer, an external
 * tileset). */
static const char *const FILE_NAMES[] = {"s000.subtree", "s110.subtree", "s101.subtree",
                                         "s232.subtree", "b.bin",        "e.json"};
#define FILE_COUNT (sizeof(FILE_NAMES) / sizeof(FILE_NAMES[0]))
/* Tiles an input may make: implicit tiling reaches TILESET_MAX_TILES with a
 * few bytes (an octree of 8 levels, every tile available, is 2.4 million),
 * which takes seconds, not a finding. */
#define FUZZ_MAX_TILES 20000u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64];

static void remove_files(void) {
    char path[128];
    size_t i;
    for (i = 0; i < FILE_COUNT; ++i) {
        snprintf(path, sizeof(path), "%s/%s", dir, FILE_NAMES[i]);
        remove(path);
    }
    snprintf(path, sizeof(path), "%s/tileset.json", dir);
    remove(path);
}

static void cleanup(void) {
    remove_files();
    rmdir(dir);
}

static void check(int ok, const char *what) {
    if (!ok) {
        fprintf(stderr, "fuzz_tileset: guarantee broken: %s\n", what);
        abort();
    }
}

static void write_file(const char *name, const uint8_t *bytes, size_t n) {
    char path[128];
    FILE *f;
    snprintf(path, sizeof(path), "%s/%s", dir, name);
    f = fopen(path, "wb");
    check(f != NULL, "the scratch directory takes files");
    check(fwrite(bytes, 1, n, f) == n && fclose(f) == 0, "the scratch files are written");
}

/* Everything a loaded tileset promises (tileset.h). */
static void check_tileset(const tileset *ts) {
    uint32_t i, k, empty = 0, additive = 0, unexpanded = 0, volumes;
    tclod_scene *scene = NULL;
    tclod_id *ids;
    const tileset_counts *c = &ts->counts;
    check(ts->count >= 1 && ts->tiles && ts->children, "a loaded tileset has its root");
    check(ts->tiles[0].parent == TILE_NONE && ts->tiles[0].depth == 0, "tile 0 is the root");
    for (i = 0; i < ts->count; ++i) {
        const tile *t = &ts->tiles[i];
        check(i == 0 || (t->parent < i && t->parent != TILE_NONE), "parents come first");
        check(isfinite(t->geometric_error) && t->geometric_error >= 0.0,
              "geometric errors are finite and >= 0");
        check(isfinite(t->bytes) && t->bytes >= 0.0 && (!t->empty || t->bytes == 0.0),
              "bytes are finite, >= 0, and 0 when empty");
        check(t->refine == TCLOD_REFINE_REPLACE || t->refine == TCLOD_REFINE_ADD,
              "refinement is REPLACE or ADD");
        check(tclod_bounds_validate(&t->bounds) == TCLOD_OK, "volumes are valid");
        check(t->first_child <= ts->count - 1 && t->child_count <= ts->count - 1 - t->first_child,
              "children lists lie in the array");
        for (k = 0; k < t->child_count; ++k)
            check(ts->tiles[ts->children[t->first_child + k]].parent == i,
                  "a tile's children have it as their parent");
        if (i > 0) {
            const tile *p = &ts->tiles[t->parent];
            check(t->depth == p->depth + 1, "depths follow the parents");
            check(t->add_anchor ==
                      (!p->empty && p->refine == TCLOD_REFINE_ADD ? t->parent : p->add_anchor),
                  "ADD anchors are the nearest drawn additive ancestors");
        }
        check(!t->unexpanded || (t->child_count == 0 && t->empty && t->bytes == 0.0),
              "an unexpanded tile is an empty leaf");
        check(isfinite(t->file_bytes) && t->file_bytes >= 0.0 && (t->unexpanded || t->file_bytes == 0.0),
              "file bytes are finite, >= 0, and 0 once expanded");
        empty += (uint32_t)t->empty;
        additive += t->refine == TCLOD_REFINE_ADD;
        unexpanded += (uint32_t)t->unexpanded;
    }
    check(unexpanded == c->unexpanded, "the count of unexpanded tiles");
    volumes = c->regions + c->boxes + c->spheres;
    check(empty == c->empty && additive == c->additive, "the counts of empty and ADD tiles");
    check(volumes == ts->count, "every tile's volume is counted once by kind");
    check(c->from_file + c->from_sizes + c->estimated == c->contents,
          "every content is sized one way");

    /* libtclod takes them all */
    ids = (tclod_id *)malloc(ts->count * sizeof(*ids));
    check(ids && tclod_scene_create(NULL, &scene) == TCLOD_OK, "memory");
    for (i = 0; i < ts->count; ++i) {
        const tile *t = &ts->tiles[i];
        tclod_node_desc d;
        tile_node_desc(t, t->parent == TILE_NONE ? TCLOD_NONE : ids[t->parent], &d);
        check(tclod_scene_add_node_desc(scene, &d, &ids[i]) == TCLOD_OK,
              "libtclod takes every tile as a node");
    }
    tclod_scene_destroy(scene);
    free(ids);
}

/* The tileset at path opened on demand and expanded tile by tile; whole: the
 * whole load, when it succeeded. */
static void on_demand(const char *path, const tileset *whole) {
    tileset ts;
    char err[512];
    uint32_t i, failures = 0;
    memset(&ts, 0, sizeof(ts));
    err[0] = '\0';
    if (tileset_open(path, NULL, FUZZ_MAX_TILES, &ts, err, sizeof(err)) != 0) {
        check(err[0] != '\0', "a failed open says why");
        check(!whole, "what loads whole opens");
        return;
    }
    check_tileset(&ts);
    for (i = 0; i < ts.count; ++i) {
        tileset_counts before;
        uint32_t count = ts.count;
        if (!ts.tiles[i].unexpanded)
            continue;
        before = ts.counts;
        err[0] = '\0';
        if (tileset_expand(&ts, i, err, sizeof(err)) != 0) {
            check(err[0] != '\0', "a failed expansion says why");
            check(ts.count == count && ts.tiles[i].unexpanded &&
                      memcmp(&before, &ts.counts, sizeof(before)) == 0,
                  "a failed expansion changes nothing");
            ++failures;
            continue;
        }
        check(!ts.tiles[i].unexpanded && ts.count >= count, "an expansion adds to the tileset");
        check_tileset(&ts);
    }
    if (getenv("FUZZ_TRACE"))
        fprintf(stderr, "on demand: %lu tiles, %lu files, %lu expansions failed\n",
                (unsigned long)ts.count, (unsigned long)ts.counts.files, (unsigned long)failures);
    if (whole)
        check(failures == 0 && ts.count == whole->count &&
                  ts.counts.files == whole->counts.files,
              "expanded whole, the tileset read on demand is the one loaded whole");
    tileset_free(&ts);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const uint8_t *end = data + size, *nul = (const uint8_t *)memchr(data, 0, size);
    const uint8_t *p = nul ? nul + 1 : end;
    char path[128], err[512];
    tileset ts;
    if (!dir[0]) {
        strcpy(dir, "/tmp/fuzz_tileset_XXXXXX");
        check(mkdtemp(dir) != NULL, "a scratch directory");
        atexit(cleanup);
    }
    remove_files();
    write_file("tileset.json", data, (size_t)((nul ? nul : end) - data));
    while (end - p >= 3) {
        size_t n = (size_t)p[1] | (size_t)p[2] << 8;
        const char *name = FILE_NAMES[p[0] % FILE_COUNT];
        p += 3;
        if (n > (size_t)(end - p))
            n = (size_t)(end - p);
        write_file(name, p, n);
        p += n;
    }
    snprintf(path, sizeof(path), "%s/tileset.json", dir);
    memset(&ts, 0, sizeof(ts));
    err[0] = '\0';
    if (tileset_load_at_most(path, NULL, FUZZ_MAX_TILES, &ts, err, sizeof(err)) != 0) {
        if (getenv("FUZZ_TRACE"))
            fprintf(stderr, "refused: %s\n", err);
        check(err[0] != '\0', "a failed load says why");
        check(ts.tiles == NULL && ts.count == 0, "a failed load leaves the tileset untouched");
        on_demand(path, NULL);
        return 0;
    }
    if (getenv("FUZZ_TRACE"))
        fprintf(stderr, "loaded: %lu tiles, %lu subtrees, %lu external tilesets\n",
                (unsigned long)ts.count, (unsigned long)ts.counts.subtrees,
                (unsigned long)ts.counts.external);
    check_tileset(&ts);
    on_demand(path, &ts);
    tileset_free(&ts);
    return 0;
}
