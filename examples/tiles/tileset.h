/*
 * tileset — reads a 3D Tiles tileset.json (1.0 and 1.1) into a flat array of
 * tiles in world coordinates, ready to become libtclod nodes: bounding volumes
 * converted to tclod_bounds, transforms composed, refinement inherited, content
 * bytes looked up, external tilesets loaded below the tiles that name them,
 * implicit tiling read from its subtree files into tiles like the others.
 */
#ifndef TILES_TILESET_H
#define TILES_TILESET_H

#include <stddef.h>
#include <stdint.h>

#include <tclod/tclod.h>

/* "No tile": the parent of the root. */
#define TILE_NONE 0xffffffffu

/* Bytes assumed for a content that is neither on disk beside its tileset nor
 * in the sizes file: 256 KiB, the order of a typical glTF tile of a city mesh
 * or a few tens of thousands of points. */
#define TILESET_ESTIMATE_BYTES 262144.0

/* External tilesets nest at most this deep (a tileset naming one that names
 * one ...); deeper chains are rejected as runaway. */
#define TILESET_MAX_EXTERNAL_DEPTH 16
/* At most this many tiles, external tilesets included: libtclod's ids are
 * 32-bit, and a tileset that names one external tileset many times over can
 * grow without end. */
#define TILESET_MAX_TILES (1u << 24)

typedef struct tile {
    tclod_bounds bounds;    /* world coordinates (earth-centred for a georeferenced set) */
    double geometric_error; /* m, >= 0: as written (or inherited), times the
                               composed transform's largest scale, as CesiumJS */
    double bytes;           /* content bytes, summed over a 1.1 tile's contents; 0 when empty */
    uint32_t parent;        /* TILE_NONE for the root */
    uint32_t first_child;   /* children: tileset.children[first_child .. + child_count] */
    uint32_t child_count;
    uint32_t add_anchor; /* the nearest ancestor with content that refines by ADD (it
                            stays drawn below), TILE_NONE if there is none */
    uint32_t depth;      /* 0 for the root */
    tclod_refine refine; /* how this tile's children refine it */
    int empty;           /* 1: no content of its own (none given, or an external
                            tileset's link) */
    int loose;           /* 1: its volume reaches out of its parent's (3D Tiles asks
                            that it does not; CesiumJS then culls the parent by its
                            own volume only) */
    uint32_t request;    /* its viewerRequestVolume: tileset.requests[request], or
                            TILE_NONE when it has none */
    int unexpanded;      /* 1 (tileset_open only): it stands for a file not read yet,
                            the external tileset it links or the implicit subtree it is
                            the root of; a leaf until tileset_expand reads the file */
    double file_bytes;   /* with unexpanded: that file's size on disk (0: not found) */
} tile;

/* What the loader met, for the host's header line. */
typedef struct tileset_counts {
    uint32_t regions, boxes, spheres;          /* bounding volumes by kind as written */
    uint32_t box_fallbacks;                    /* boxes whose axes are not orthogonal, kept as
                                                  their enclosing sphere */
    uint32_t empty, additive;                  /* tiles without content; tiles refining by ADD */
    uint32_t external;                         /* external tilesets loaded */
    uint32_t implicit, subtrees;               /* implicit root tiles; subtree files read */
    uint32_t contents;                         /* contents (not external tilesets) */
    uint32_t from_file, from_sizes, estimated; /* where their bytes came from */
    uint32_t max_depth;
    uint32_t unexpanded; /* tiles standing for a file not read yet (tileset_open) */
    uint32_t files;      /* files read: tileset documents and subtrees */
    double bytes;        /* all contents' bytes */
    /* Deviations from 3D Tiles that real producers write and CesiumJS or
     * cesium-native read, read the same way here and counted
     * (docs/tiles.md, what the reader forgives): */
    uint32_t inherited_errors;  /* tiles without geometricError: their parent's, the
                                   root's from the tileset's geometricError */
    uint32_t lowercase_refines; /* refine not in capitals ("add"), read in any case */
    uint32_t unknown_refines;   /* refine neither REPLACE nor ADD: the parent's */
    uint32_t content_urls;      /* contents named by "url" (before 1.0) for "uri" */
    uint32_t empty_uris;        /* content.uri "": the tile has no content */
    uint32_t missing_versions;  /* documents whose asset has no version: read as 1.0 */
    uint32_t other_versions;    /* documents whose asset.version is not 0.0, 1.0 or 1.1 */
    uint32_t content_volumes;   /* content bounding volumes: checked, then unused */
    uint32_t loose_children;    /* tiles whose volume reaches out of their parent's */
} tileset_counts;

/* The deviations above, summed. */
uint32_t tileset_warning_count(const tileset_counts *c);
/* "2189 tiles without geometricError took their parent's, ...": the
 * deviations that occurred, into out (empty when none). */
void tileset_warning_text(const tileset_counts *c, char *out, size_t size);

typedef struct tileset {
    tile *tiles; /* in depth-first order: a parent before its children */
    uint32_t count;
    uint32_t *children;
    tclod_bounds *requests; /* the viewerRequestVolumes of the tiles that have one, in
                               world coordinates: CesiumJS shows such a tile (and
                               its subtree) only to a camera inside it */
    uint32_t request_count;
    tileset_counts counts;
    struct loader *lazy; /* tileset_open: the documents and implicit tilings that
                            tileset_expand reads on from; NULL after tileset_load */
} tileset;

/* Content sizes given on the command line: lines "path<TAB>bytes", the
 * content's path relative to the directory of the tileset loaded (for the
 * loaded file's own contents, the uri as written, without query or fragment);
 * a line may also give a uri as an external tileset writes it. Blank lines and
 * lines starting with '#' are skipped. */
typedef struct size_entry {
    const char *uri;
    double bytes;
} size_entry;

typedef struct size_table {
    size_entry *entries; /* sorted by uri */
    size_t count;
    char *text; /* the file, which the entries point into */
} size_table;

/* Read path into *t. 0 on success; else 1 with a message naming the file (and
 * line) in err. */
int size_table_load(const char *path, size_table *t, char *err, size_t err_size);
void size_table_free(size_table *t);

/* Loads the tileset at path (sizes may be NULL). 0 on success; else 1 with a
 * message in err naming the file, the tile (as root.children[i]...) and what
 * was wrong, and *ts untouched. */
int tileset_load(const char *path, const size_table *sizes, tileset *ts, char *err,
                 size_t err_size);
/* The same with at most max_tiles tiles (no more than TILESET_MAX_TILES): a
 * tileset with more is refused. */
int tileset_load_at_most(const char *path, const size_table *sizes, uint32_t max_tiles, tileset *ts,
                         char *err, size_t err_size);
void tileset_free(tileset *ts);

/* Opens the tileset at path as tileset_load_at_most does, reading no file but
 * that one: a tile linking an external tileset (with no children of its own)
 * and the root of each implicit subtree (the implicit root tile's included)
 * are read as tiles with `unexpanded` set and the file's size in file_bytes,
 * and no children. Same return and messages. */
int tileset_open(const char *path, const size_table *sizes, uint32_t max_tiles, tileset *ts,
                 char *err, size_t err_size);
/* Reads the file that unexpanded tile t of an opened tileset stands for: its
 * tiles are appended (ts->tiles[old count .. ts->count), a parent before its
 * children, the first of them children of t), with tiles `unexpanded` again
 * for the files they name in turn; t becomes a tile like the others (an
 * implicit subtree's root takes its content). ts->tiles and ts->children may
 * move; other tiles do not change. 0 on success; else 1 with a message in err
 * naming the file and what was wrong, and *ts as it was. */
int tileset_expand(tileset *ts, uint32_t t, char *err, size_t err_size);

/* The libtclod node of tile t below node parent (TCLOD_NONE for the root):
 * its volume, refinement and emptiness, or for an unexpanded tile an
 * unexpanded node (whose bytes are the file's, file_bytes). */
void tile_node_desc(const tile *t, tclod_id parent, tclod_node_desc *d);

#endif
