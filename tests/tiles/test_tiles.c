/*
 * test_tiles — the 3D Tiles host's reader and benefit model
 * (examples/tiles/tileset.c, geodesy.c, tiles_model.c): the box around a
 * region encloses it, a tileset's volumes, transforms, refinement, contents
 * and external tilesets come out as tiles in world coordinates, bad tilesets
 * are refused with a message saying where, and the benefit's shares add up.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <tclod/tclod.h>

#include "geodesy.h"
#include "tiles_model.h"
#include "tileset.h"

/* A scratch directory and the files written into it, removed after each
 * test. */
typedef struct scratch {
    char dir[64];
    char files[32][128];
    int count;
} scratch;

static scratch *scratch_new(void) {
    scratch *s = (scratch *)calloc(1, sizeof(*s));
    assert_non_null(s);
    strcpy(s->dir, "/tmp/test_tiles_XXXXXX");
    assert_non_null(mkdtemp(s->dir));
    return s;
}

/* dir/name into out, a slot of s->files. */
static void scratch_path(const scratch *s, const char *name, char *out) {
    char path[sizeof(s->files[0])];
    snprintf(path, sizeof(path), "%s/%s", s->dir, name);
    memcpy(out, path, sizeof(path));
}

/* Writes n bytes to dir/name. */
static void scratch_write_bytes(scratch *s, const char *name, const void *data, size_t n) {
    char *path = s->files[s->count];
    FILE *f;
    assert_true(s->count < 32);
    scratch_path(s, name, path);
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
    ++s->count;
}

/* Writes text (or, with text NULL, n filler bytes) to dir/name; name may be
 * in a subdirectory created before. Returns the path. */
static const char *scratch_write(scratch *s, const char *name, const char *text, size_t n) {
    char *filler = NULL;
    if (!text) {
        filler = (char *)malloc(n ? n : 1);
        assert_non_null(filler);
        memset(filler, 'x', n);
    }
    scratch_write_bytes(s, name, text ? text : filler, text ? strlen(text) : n);
    free(filler);
    return s->files[s->count - 1];
}

/* A subdirectory, removed last. */
static void scratch_mkdir(scratch *s, const char *name) {
    char *path = s->files[s->count];
    assert_true(s->count < 32);
    scratch_path(s, name, path);
    assert_int_equal(mkdir(path, 0777), 0);
    ++s->count;
}

static void scratch_free(scratch *s) {
    while (s->count > 0) {
        const char *p = s->files[--s->count];
        remove(p); /* files, and the subdirectories after their files */
    }
    rmdir(s->dir);
    free(s);
}

/* Loads dir/name; the error message goes to err. */
static int load(const scratch *s, const char *name, const size_table *sizes, tileset *ts, char *err,
                size_t err_size) {
    char path[160];
    snprintf(path, sizeof(path), "%s/%s", s->dir, name);
    err[0] = '\0';
    return tileset_load(path, sizes, ts, err, err_size);
}

static void assert_close(double got, double want, double tol) {
    if (!(fabs(got - want) <= tol))
        fail_msg("got %.12g, expected %.12g (tolerance %g)", got, want, tol);
}

/* ---- regions ----------------------------------------------------------------- */

/* Every point of a region, on a fine grid of longitude, latitude and height,
 * lies in its box; and a box no wider than pi reaches each face (it is not
 * padded). */
static void region_box_encloses_the_region(void **state) {
    static const double regions[][6] = {
        {0.0837, 0.7982, 0.0851, 0.7992, 150.0, 420.0},         /* a city */
        {-0.1, -0.1, 0.1, 0.1, 0.0, 1000.0},                    /* across the equator */
        {-1.0, -0.5, 0.5, 0.3, -100.0, 9000.0},                 /* wide, deep and high */
        {3.0, 0.2, -3.0, 0.5, 0.0, 100.0},                      /* across the antimeridian */
        {-1.5707963, -0.2, 1.5707963, 1.2, 0.0, 100.0},         /* just under pi wide */
        {-2.0, 1.2, 2.0, 1.5707963, 0.0, 10.0},                 /* a polar cap, band box */
        {-3.14159, -1.5707963, 3.14159, 1.5707963, -10.0, 1e4}, /* the globe */
        {0.5, -1.5, 1.0, 1.5, 0.0, 1e5},                        /* pole to pole */
        {0.2, 0.3, 0.2, 0.3, 5.0, 5.0},                         /* a point */
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof(regions) / sizeof(regions[0]); ++r) {
        const double *g = regions[r];
        double c[3], a[9], reach[3] = {0.0, 0.0, 0.0},
                           east = g[2] < g[0] ? g[2] + 2 * GEO_PI : g[2];
        int i, j, k, ax;
        assert_true(geo_region_valid(g));
        geo_region_box(g, c, a);
        for (i = 0; i <= 60; ++i) {
            for (j = 0; j <= 60; ++j) {
                for (k = 0; k <= 2; ++k) {
                    double p[3];
                    geo_to_ecef(g[0] + (east - g[0]) * i / 60.0, g[1] + (g[3] - g[1]) * j / 60.0,
                                g[4] + (g[5] - g[4]) * k / 2.0, p);
                    for (ax = 0; ax < 3; ++ax) {
                        const double *v = a + 3 * ax;
                        double l2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                        double u =
                            (p[0] - c[0]) * v[0] + (p[1] - c[1]) * v[1] + (p[2] - c[2]) * v[2];
                        /* |u| / |v| is the distance along the axis, at most |v| + 1e-6 m */
                        if (l2 > 0.0) {
                            assert_true(fabs(u) / sqrt(l2) <= sqrt(l2) + 1e-6);
                            if (fabs(u) / l2 > reach[ax])
                                reach[ax] = fabs(u) / l2;
                        } else {
                            assert_true(fabs(u) <= 1e-6);
                        }
                    }
                }
            }
        }
        if (east - g[0] <= GEO_PI && g[0] != g[2])
            for (ax = 0; ax < 3; ++ax)
                assert_true(reach[ax] > 0.999);
    }
}

static void region_validity(void **state) {
    static const double good[6] = {-3.14159, -1.5, 3.14159, 1.5, -100.0, 100.0};
    static const double bad[][6] = {
        {0.1, 0.8, 0.2, 0.7, 0.0, 1.0},  /* south above north */
        {0.1, 0.7, 0.2, 0.8, 10.0, 1.0}, /* heights reversed */
        {0.1, 0.7, 3.2, 0.8, 0.0, 1.0},  /* east past pi */
        {0.1, -1.6, 0.2, 0.8, 0.0, 1.0}, /* south past the pole */
    };
    size_t i;
    (void)state;
    assert_true(geo_region_valid(good));
    for (i = 0; i < sizeof(bad) / sizeof(bad[0]); ++i)
        assert_false(geo_region_valid(bad[i]));
}

/* ---- reading a tileset ----------------------------------------------------------- */

static const char *const main_json =
    "{\"asset\":{\"version\":\"1.1\"},\"geometricError\":100,\"root\":{"
    "\"geometricError\":50,\"refine\":\"add\","
    "\"boundingVolume\":{\"region\":[0.1,0.7,0.1001,0.7001,0,30]},"
    "\"content\":{\"uri\":\"a.glb\"},\"children\":["
    /* 1: scaled by 2 and moved; two contents; a sphere below it */
    "{\"geometricError\":10,\"transform\":[2,0,0,0,0,2,0,0,0,0,2,0,10,20,30,1],"
    "\"boundingVolume\":{\"box\":[1,0,0,1,0,0,0,1,0,0,0,1]},"
    "\"contents\":[{\"uri\":\"b.glb\"},{\"uri\":\"c%20d.glb?v=1\"}],"
    "\"children\":[{\"geometricError\":0,\"boundingVolume\":{\"sphere\":[0,0,0,5]},"
    "\"content\":{\"uri\":\"a.glb\"}}]},"
    /* 2: axes not orthogonal; an external tileset in a subdirectory */
    "{\"geometricError\":10,\"boundingVolume\":{\"box\":[0,0,0,1,0,0,1,1,0,0,0,1]},"
    "\"content\":{\"uri\":\"sub/ext.json\"}},"
    /* 3: no content */
    "{\"geometricError\":10,\"refine\":\"REPLACE\",\"boundingVolume\":{\"sphere\":[0,0,0,1]}}"
    "]}}";

static const char *const ext_json =
    "{\"asset\":{\"version\":\"1.0\"},\"geometricError\":10,\"root\":{"
    "\"geometricError\":5,\"boundingVolume\":{\"sphere\":[1,2,3,4]},\"content\":{\"url\":\"d.glb\"}"
    ","
    "\"children\":[{\"geometricError\":0,\"boundingVolume\":{\"sphere\":[1,2,3,1]},"
    "\"content\":{\"url\":\"e.glb\"}}]}}";

static void reads_volumes_transforms_refinement_and_contents(void **state) {
    scratch *s = scratch_new();
    size_table sizes;
    tileset ts;
    char err[512];
    const tile *t;
    (void)state;
    scratch_write(s, "tileset.json", main_json, 0);
    scratch_write(s, "a.glb", NULL, 1234);
    scratch_write(s, "c d.glb", NULL, 300);
    scratch_mkdir(s, "sub");
    scratch_write(s, "sub/ext.json", ext_json, 0);
    scratch_write(s, "sub/d.glb", NULL, 77);
    assert_int_equal(size_table_load(scratch_write(s, "sizes.tsv",
                                                   "# uri<TAB>bytes\nb.glb\t1000\n\na.glb\t5\n", 0),
                                     &sizes, err, sizeof(err)),
                     0);
    if (load(s, "tileset.json", &sizes, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 7);
    t = ts.tiles;

    /* depth-first order: root, 1, its sphere, 2, the external root and its
     * child, 3 */
    assert_int_equal(t[0].parent, TILE_NONE);
    assert_int_equal(t[1].parent, 0);
    assert_int_equal(t[2].parent, 1);
    assert_int_equal(t[3].parent, 0);
    assert_int_equal(t[4].parent, 3);
    assert_int_equal(t[5].parent, 4);
    assert_int_equal(t[6].parent, 0);
    assert_int_equal(t[0].child_count, 3);
    assert_int_equal(ts.children[t[0].first_child + 2], 6);

    /* the region became a box; the transformed box and sphere */
    assert_int_equal(t[0].bounds.kind, TCLOD_BOUNDS_OBB);
    assert_int_equal(t[1].bounds.kind, TCLOD_BOUNDS_OBB);
    assert_close(t[1].bounds.center[0], 12.0, 1e-12);
    assert_close(t[1].bounds.center[1], 20.0, 1e-12);
    assert_close(t[1].bounds.center[2], 30.0, 1e-12);
    assert_close(t[1].bounds.half_axes[0][0], 2.0, 1e-12);
    assert_close(t[1].bounds.half_axes[2][2], 2.0, 1e-12);
    assert_int_equal(t[2].bounds.kind, TCLOD_BOUNDS_SPHERE);
    assert_close(t[2].bounds.center[0], 10.0, 1e-12);
    assert_close(t[2].bounds.radius, 10.0, 1e-12);
    /* the leaning box: its enclosing sphere, through the corner a + b + c */
    assert_int_equal(t[3].bounds.kind, TCLOD_BOUNDS_SPHERE);
    assert_close(t[3].bounds.radius, sqrt(6.0), 1e-12);
    assert_int_equal(ts.counts.box_fallbacks, 1);
    /* the external tileset's volumes are its own (no transform above it) */
    assert_close(t[4].bounds.center[2], 3.0, 1e-12);
    assert_close(t[4].bounds.radius, 4.0, 1e-12);

    /* refinement inherited (the root's "add" in any case), ADD anchors */
    assert_int_equal(t[0].refine, TCLOD_REFINE_ADD);
    assert_int_equal(t[2].refine, TCLOD_REFINE_ADD);
    assert_int_equal(t[5].refine, TCLOD_REFINE_ADD);
    assert_int_equal(t[6].refine, TCLOD_REFINE_REPLACE);
    assert_int_equal(t[0].add_anchor, TILE_NONE);
    assert_int_equal(t[1].add_anchor, 0);
    assert_int_equal(t[2].add_anchor, 1);
    assert_int_equal(t[4].add_anchor, 0); /* tile 3 has no content: it draws nothing */
    assert_int_equal(t[5].add_anchor, 4);
    assert_int_equal(t[5].depth, 3);
    assert_int_equal(ts.counts.max_depth, 3);

    /* bytes: files beside their tileset first (a.glb's size on disk, not
     * sizes.tsv's 5; "c%20d.glb?v=1" is the file "c d.glb"; d.glb beside the
     * external tileset), then sizes.tsv, then the estimate */
    assert_close(t[0].bytes, 1234.0, 0.0);
    assert_close(t[1].bytes, 1300.0, 0.0);
    assert_close(t[4].bytes, 77.0, 0.0);
    assert_close(t[5].bytes, TILESET_ESTIMATE_BYTES, 0.0);
    assert_false(t[0].empty);
    assert_true(t[3].empty); /* the external tileset's link */
    assert_true(t[6].empty);
    assert_int_equal(ts.counts.contents, 6);
    assert_int_equal(ts.counts.from_file, 4);
    assert_int_equal(ts.counts.from_sizes, 1);
    assert_int_equal(ts.counts.estimated, 1);
    assert_int_equal(ts.counts.external, 1);
    assert_int_equal(ts.counts.empty, 2);
    assert_int_equal(ts.counts.regions, 1);
    assert_int_equal(ts.counts.boxes, 2);
    assert_int_equal(ts.counts.spheres, 4);

    tileset_free(&ts);
    size_table_free(&sizes);
    scratch_free(s);
}

/* What real producers write that CesiumJS or cesium-native read, read alike
 * and counted (docs/tiles.md, what the reader forgives):
 *   root (the tileset's geometricError 40, none of its own; "Replace"),
 *     0: child a: no geometricError (its parent's 40), scaled by 3 (120),
 *        its content named by "url", its content's box checked;
 *        child a1: "add", geometricError 10 under a's scale (30), reaching
 *        out of a's box
 *     1: child b: refine "MERGE" (its parent's REPLACE), content uri "" (no
 *        content), an external tileset below it with no asset.version,
 *        whose root's content is sized by its path from the main tileset's
 *        directory (sub/e.glb in sizes.tsv) */
static void reads_what_real_producers_write_and_counts_it(void **state) {
    scratch *s = scratch_new();
    size_table sizes;
    tileset ts;
    char err[512], text[1024];
    const tile *t;
    (void)state;
    scratch_write(
        s, "tileset.json",
        "{\"asset\":{\"version\":\"2.0\"},\"geometricError\":40,\"root\":{\"refine\":\"Replace\","
        "\"boundingVolume\":{\"box\":[0,0,0,10,0,0,0,10,0,0,0,10]},\"children\":["
        "{\"transform\":[3,0,0,0,0,3,0,0,0,0,3,0,0,0,0,1],"
        "\"boundingVolume\":{\"box\":[0,0,0,1,0,0,0,1,0,0,0,1]},"
        "\"content\":{\"url\":\"a.glb\",\"boundingVolume\":{\"box\":[0,0,0,1,0,0,0,1,0,0,0,1]}},"
        "\"children\":[{\"geometricError\":10,\"refine\":\"add\","
        "\"boundingVolume\":{\"box\":[2,0,0,1,0,0,0,1,0,0,0,1]},\"content\":{\"uri\":\"a.glb\"}}]},"
        "{\"geometricError\":5,\"refine\":\"MERGE\",\"boundingVolume\":{\"sphere\":[0,0,0,1]},"
        "\"content\":{\"uri\":\"\"},\"children\":[{\"geometricError\":4,"
        "\"boundingVolume\":{\"sphere\":[0,0,0,1]},\"content\":{\"uri\":\"sub/ext.json\"}}]}]}}",
        0);
    scratch_mkdir(s, "sub");
    scratch_write(s, "sub/ext.json",
                  "{\"asset\":{},\"root\":{\"boundingVolume\":{\"sphere\":[0,0,0,1]},"
                  "\"content\":{\"uri\":\"e.glb\"}}}",
                  0);
    assert_int_equal(size_table_load(scratch_write(s, "sizes.tsv", "a.glb\t100\nsub/e.glb\t7\n", 0),
                                     &sizes, err, sizeof(err)),
                     0);
    if (load(s, "tileset.json", &sizes, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    t = ts.tiles;
    /* root, a, a1, b, the link below b, the external root */
    assert_int_equal(ts.count, 6);
    assert_close(t[0].geometric_error, 40.0, 0.0);  /* the tileset's */
    assert_close(t[1].geometric_error, 120.0, 0.0); /* the root's 40, times 3 */
    assert_close(t[2].geometric_error, 30.0, 0.0);  /* 10 under a's scale */
    assert_int_equal(t[0].refine, TCLOD_REFINE_REPLACE);
    assert_int_equal(t[2].refine, TCLOD_REFINE_ADD);
    assert_int_equal(t[3].refine, TCLOD_REFINE_REPLACE);
    assert_close(t[1].bytes, 100.0, 0.0);
    assert_true(t[3].empty);
    assert_true(t[4].empty);
    assert_close(t[5].geometric_error, 4.0, 0.0); /* the link's */
    assert_close(t[5].bytes, 7.0, 0.0);
    assert_false(t[1].loose);
    assert_true(t[2].loose); /* centre 6 from a's, reach 3 + 3 against 3 */
    assert_false(t[3].loose);
    assert_int_equal(ts.counts.inherited_errors, 3); /* root, a, the external root */
    assert_int_equal(ts.counts.lowercase_refines, 2);
    assert_int_equal(ts.counts.unknown_refines, 1);
    assert_int_equal(ts.counts.content_urls, 1);
    assert_int_equal(ts.counts.empty_uris, 1);
    assert_int_equal(ts.counts.missing_versions, 1);
    assert_int_equal(ts.counts.other_versions, 1);
    assert_int_equal(ts.counts.content_volumes, 1);
    assert_int_equal(ts.counts.loose_children, 1);
    assert_int_equal(tileset_warning_count(&ts.counts), 12);
    tileset_warning_text(&ts.counts, text, sizeof(text));
    assert_non_null(strstr(text, "3 tiles without geometricError took their parent's"));
    assert_non_null(strstr(text, "1 tiles reach out of their parent's volume"));
    tileset_free(&ts);
    size_table_free(&sizes);
    scratch_free(s);
}

/* One bad tileset: loading fails and the message holds `expect`. */
static void assert_refused(scratch *s, const char *json, const char *expect) {
    tileset ts;
    char err[512];
    scratch_write(s, "bad.json", json, 0);
    memset(&ts, 0, sizeof(ts));
    assert_int_equal(load(s, "bad.json", NULL, &ts, err, sizeof(err)), 1);
    if (!strstr(err, expect))
        fail_msg("message '%s' does not say '%s'", err, expect);
    assert_null(ts.tiles);
    remove(s->files[--s->count]); /* the next case writes bad.json again */
}

#define TILE(body) "{\"asset\":{\"version\":\"1.1\"},\"root\":{" body "}}"
#define SPHERE "\"boundingVolume\":{\"sphere\":[0,0,0,1]}"

static void refuses_bad_tilesets_saying_where(void **state) {
    scratch *s = scratch_new();
    (void)state;
    assert_refused(s, "{\"root\":{}}", "bad.json: no \"asset\" object");
    assert_refused(s, "[1, 2]", "the top level is not a JSON object");
    assert_refused(s, "{\"asset\":{\"version\":\"1.1\"},\n\"root\": {,}}",
                   "malformed JSON near line 2, column 1");
    assert_refused(s, TILE("\"geometricError\":-1," SPHERE), "tile root: geometricError");
    assert_refused(s, TILE(SPHERE), "tile root: geometricError");
    assert_refused(s, TILE("\"geometricError\":1"), "no \"boundingVolume\" object");
    assert_refused(s, TILE("\"geometricError\":1,\"boundingVolume\":{}"),
                   "boundingVolume has no box, region or sphere");
    assert_refused(s, TILE("\"geometricError\":1,\"boundingVolume\":{\"sphere\":[0,0,0,-1]}"),
                   "boundingVolume.sphere needs 4");
    assert_refused(
        s, TILE("\"geometricError\":1,\"boundingVolume\":{\"box\":[0,0,0,1,0,0,0,1,0,0,0,\"1\"]}"),
        "boundingVolume.box needs 12");
    assert_refused(s, TILE("\"geometricError\":1,\"refine\":7," SPHERE),
                   "tile root: refine must be a string");
    assert_refused(s, TILE(SPHERE), "tile root: geometricError is missing");
    assert_refused(s,
                   TILE("\"geometricError\":1," SPHERE ",\"viewerRequestVolume\":{\"sphere\":[1]}"),
                   "tile root: viewerRequestVolume.sphere needs 4");
    assert_refused(s,
                   TILE("\"geometricError\":1," SPHERE
                        ",\"content\":{\"uri\":\"a.glb\",\"boundingVolume\":{\"box\":[0,0,0]}}"),
                   "tile root: content.boundingVolume.box needs 12");
    assert_refused(s,
                   "{\"asset\":{\"version\":\"1.0\"},\"geometricError\":-2,\"root\":{" SPHERE "}}",
                   "tile root: geometricError is missing");
    assert_refused(
        s, TILE("\"geometricError\":1,\"transform\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0]," SPHERE),
        "transform needs 16");
    assert_refused(s, TILE("\"geometricError\":1,\"contents\":{}," SPHERE),
                   "contents is not an array");
    assert_refused(s, TILE("\"geometricError\":1,\"content\":{\"uri\":7}," SPHERE),
                   "a content has no \"uri\" string");
    assert_refused(s, TILE("\"geometricError\":1,\"children\":{}," SPHERE),
                   "children is not an array");
    assert_refused(s,
                   TILE("\"geometricError\":1," SPHERE
                        ",\"children\":[{\"geometricError\":1," SPHERE
                        "},{\"geometricError\":1," SPHERE ",\"children\":[7]}]"),
                   "tile root.children[1].children[0]: not a JSON object");
    assert_refused(s, TILE("\"geometricError\":1,\"content\":{\"uri\":\"none.json\"}," SPHERE),
                   "cannot open external tileset");
    assert_refused(
        s,
        TILE("\"geometricError\":1,\"content\":{\"uri\":\"https://example.com/t.json\"}," SPHERE),
        "is not a local file");
    assert_refused(
        s,
        TILE(
            "\"geometricError\":1,\"contents\":[{\"uri\":\"a.glb\"},{\"uri\":\"t.json\"}]," SPHERE),
        "one of several contents");
    scratch_free(s);
}

/* A chain of external tilesets one longer than allowed. */
static void refuses_external_tilesets_nested_too_deep(void **state) {
    scratch *s = scratch_new();
    tileset ts;
    char err[512], name[32], json[256];
    int i;
    (void)state;
    for (i = 0; i <= TILESET_MAX_EXTERNAL_DEPTH + 1; ++i) {
        snprintf(name, sizeof(name), "n%d.json", i);
        snprintf(json, sizeof(json),
                 TILE("\"geometricError\":1," SPHERE ",\"content\":{\"uri\":\"n%d.json\"}"), i + 1);
        scratch_write(s, name,
                      i <= TILESET_MAX_EXTERNAL_DEPTH ? json : TILE("\"geometricError\":1," SPHERE),
                      0);
    }
    assert_int_equal(load(s, "n0.json", NULL, &ts, err, sizeof(err)), 1);
    if (!strstr(err, "nest deeper than"))
        fail_msg("%s", err);
    /* one level less loads */
    assert_int_equal(load(s, "n1.json", NULL, &ts, err, sizeof(err)), 0);
    assert_int_equal(ts.counts.external, TILESET_MAX_EXTERNAL_DEPTH);
    tileset_free(&ts);
    scratch_free(s);
}

/* ---- implicit tiling ------------------------------------------------------------- */

/* A binary subtree file: the header, json padded with spaces to 8 bytes, then
 * the binary chunk of n bytes. */
static void scratch_write_subtree(scratch *s, const char *name, const char *json,
                                  const unsigned char *chunk, size_t n) {
    unsigned char file[1024];
    size_t jl = (strlen(json) + 7) / 8 * 8, i;
    uint64_t lengths[2];
    assert_true(24 + jl + n <= sizeof(file));
    memcpy(file, "subt", 4);
    file[4] = 1;
    file[5] = file[6] = file[7] = 0;
    lengths[0] = jl;
    lengths[1] = n;
    for (i = 0; i < 16; ++i) /* little-endian */
        file[8 + i] = (unsigned char)(lengths[i / 8] >> (8 * (i % 8)));
    memset(file + 24, ' ', jl);
    memcpy(file + 24, json, strlen(json));
    if (n)
        memcpy(file + 24 + jl, chunk, n);
    scratch_write_bytes(s, name, file, 24 + jl + n);
}

static void assert_box(const tile *t, double cx, double cy, double cz, double ax, double ay,
                       double az) {
    assert_int_equal(t->bounds.kind, TCLOD_BOUNDS_OBB);
    assert_close(t->bounds.center[0], cx, 1e-12);
    assert_close(t->bounds.center[1], cy, 1e-12);
    assert_close(t->bounds.center[2], cz, 1e-12);
    assert_close(t->bounds.half_axes[0][0], ax, 1e-12);
    assert_close(t->bounds.half_axes[1][1], ay, 1e-12);
    assert_close(t->bounds.half_axes[2][2], az, 1e-12);
    assert_close(t->bounds.half_axes[0][1], 0.0, 1e-12);
    assert_close(t->bounds.half_axes[1][2], 0.0, 1e-12);
}

/* Writes the files of the quadtree below. */
static void write_quadtree_of_boxes(scratch *s) {
    static const unsigned char chunk[24] = {0x13, 0, 0, 0, 0, 0, 0, 0,    0x12,
                                            0,    0, 0, 0, 0, 0, 0, 0x20, 0x20};
    static const unsigned char one = 1;
    scratch_write(
        s, "tileset.json",
        "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":64,\"refine\":\"ADD\","
        "\"boundingVolume\":{\"box\":[0,0,0,8,0,0,0,8,0,0,0,2]},"
        "\"transform\":[1,0,0,0,0,1,0,0,0,0,1,0,100,0,0,1],"
        "\"content\":{\"uri\":\"c/{level}/{x}/{y}.glb\"},"
        "\"implicitTiling\":{\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":2,"
        "\"availableLevels\":3,\"subtrees\":{\"uri\":\"s/{level}.{x}.{y}.subtree\"}}}}",
        0);
    scratch_mkdir(s, "s");
    scratch_write_subtree(
        s, "s/0.0.0.subtree",
        "{\"buffers\":[{\"byteLength\":18}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,"
        "\"byteLength\":1},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":1},{\"buffer\":0,"
        "\"byteOffset\":16,\"byteLength\":2}],\"tileAvailability\":{\"bitstream\":0},"
        "\"contentAvailability\":[{\"bitstream\":1}],\"childSubtreeAvailability\":{"
        "\"bitstream\":2}}",
        chunk, sizeof(chunk));
    scratch_write(s, "s/2.3.2.subtree",
                  "{\"buffers\":[{\"uri\":\"avail.bin\",\"byteLength\":1}],\"bufferViews\":[{"
                  "\"buffer\":0,\"byteLength\":1}],\"tileAvailability\":{\"constant\":1},"
                  "\"contentAvailability\":[{\"bitstream\":0}],\"childSubtreeAvailability\":{"
                  "\"constant\":1}}",
                  0);
    scratch_write_bytes(s, "s/avail.bin", &one, 1);
}

/* A quadtree of boxes under a transform, 3 levels in subtrees of 2: the root
 * subtree (binary, its bitstreams in its chunk) makes level 1's tiles (0, 0)
 * and (1, 1) available, content at both but not at the root, and the child
 * subtrees at Morton indices 5 (below (1, 0), which is not available: out of
 * reach) and 13 (below (1, 1): tile 2/3/2); that subtree is JSON, its
 * content bit in an external buffer. Worked by hand: a tile of level L at
 * (x, y) is centred at c + (-1 + (2x + 1) / 2^L) u + (-1 + (2y + 1) / 2^L) v,
 * its half axes u / 2^L, v / 2^L and w; its geometric error 64 / 2^L. */
static void reads_an_implicit_quadtree_of_boxes(void **state) {
    scratch *s = scratch_new();
    size_table sizes;
    tileset ts;
    char err[512];
    const tile *t;
    (void)state;
    write_quadtree_of_boxes(s);
    assert_int_equal(
        size_table_load(scratch_write(s, "sizes.tsv", "c/1/0/0.glb\t100\nc/1/1/1.glb\t200\n", 0),
                        &sizes, err, sizeof(err)),
        0);
    if (load(s, "tileset.json", &sizes, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 4);
    t = ts.tiles;
    assert_int_equal(t[0].parent, TILE_NONE);
    assert_int_equal(t[1].parent, 0);
    assert_int_equal(t[2].parent, 0);
    assert_int_equal(t[3].parent, 2);
    assert_box(&t[0], 100.0, 0.0, 0.0, 8.0, 8.0, 2.0);
    assert_box(&t[1], 96.0, -4.0, 0.0, 4.0, 4.0, 2.0);
    assert_box(&t[2], 104.0, 4.0, 0.0, 4.0, 4.0, 2.0);
    assert_box(&t[3], 106.0, 2.0, 0.0, 2.0, 2.0, 2.0);
    assert_close(t[0].geometric_error, 64.0, 0.0);
    assert_close(t[1].geometric_error, 32.0, 0.0);
    assert_close(t[3].geometric_error, 16.0, 0.0);
    assert_true(t[0].empty);
    assert_false(t[1].empty);
    assert_close(t[1].bytes, 100.0, 0.0);
    assert_close(t[2].bytes, 200.0, 0.0);
    assert_close(t[3].bytes, TILESET_ESTIMATE_BYTES, 0.0); /* c/2/3/2.glb: in no table */
    assert_int_equal(t[3].refine, TCLOD_REFINE_ADD);
    assert_int_equal(t[3].add_anchor, 2);
    assert_int_equal(t[3].depth, 2);
    assert_int_equal(ts.counts.implicit, 1);
    assert_int_equal(ts.counts.subtrees, 2);
    assert_int_equal(ts.counts.contents, 3);
    assert_int_equal(ts.counts.from_sizes, 2);
    assert_int_equal(ts.counts.estimated, 1);
    assert_int_equal(ts.counts.empty, 1);
    assert_int_equal(ts.counts.boxes, 4);
    tileset_free(&ts);
    size_table_free(&sizes);
    scratch_free(s);
}

/* An octree (constant availability, one subtree: the root and its 8
 * children, in Morton order) and a region quadtree across the antimeridian
 * whose child subtrees are its level-1 tiles (x, y) = (1, 0) and (0, 1). */
static void reads_implicit_octrees_and_regions(void **state) {
    scratch *s = scratch_new();
    size_table sizes;
    tileset ts;
    char err[512];
    const tile *t;
    double width = -3.0 - 3.0 + 2.0 * GEO_PI, r[6], c[3], a[9];
    int k;
    (void)state;
    scratch_write(s, "octree.json",
                  "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":10,"
                  "\"boundingVolume\":{\"box\":[0,0,0,2,0,0,0,4,0,0,0,6]},"
                  "\"contents\":[{\"uri\":\"o/{level}/{x}/{y}/{z}.pnts\"}],"
                  "\"implicitTiling\":{\"subdivisionScheme\":\"OCTREE\",\"subtreeLevels\":2,"
                  "\"availableLevels\":2,\"subtrees\":{\"uri\":\"o{level}{x}{y}{z}.json\"}}}}",
                  0);
    scratch_write(s, "o0000.json",
                  "{\"tileAvailability\":{\"constant\":1},\"contentAvailability\":[{"
                  "\"constant\":1}],\"childSubtreeAvailability\":{\"constant\":0}}",
                  0);
    assert_int_equal(size_table_load(scratch_write(s, "sizes.tsv", "o/1/1/0/1.pnts\t555\n", 0),
                                     &sizes, err, sizeof(err)),
                     0);
    if (load(s, "octree.json", &sizes, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 9);
    t = ts.tiles;
    /* Morton 5 = 0b101: x 1, y 0, z 1 */
    assert_box(&t[6], 1.0, -2.0, 3.0, 1.0, 2.0, 3.0);
    assert_close(t[6].bytes, 555.0, 0.0);
    assert_close(t[6].geometric_error, 5.0, 0.0);
    assert_int_equal(t[6].refine, TCLOD_REFINE_REPLACE);
    for (k = 1; k < 9; ++k)
        assert_int_equal(t[k].parent, 0);
    assert_int_equal(ts.counts.contents, 9);
    tileset_free(&ts);

    scratch_write(s, "region.json",
                  "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":10,"
                  "\"boundingVolume\":{\"region\":[3.0,-0.1,-3.0,0.1,0,100]},"
                  "\"implicitTiling\":{\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":1,"
                  "\"availableLevels\":2,\"subtrees\":{\"uri\":\"r{level}{x}{y}.json\"}}}}",
                  0);
    scratch_write(s, "r000.json",
                  "{\"buffers\":[{\"uri\":\"r.bin\",\"byteLength\":1}],\"bufferViews\":[{"
                  "\"buffer\":0,\"byteLength\":1}],\"tileAvailability\":{\"constant\":1},"
                  "\"childSubtreeAvailability\":{\"bitstream\":0}}",
                  0);
    scratch_write_bytes(s, "r.bin", "\x06", 1);
    scratch_write(s, "r110.json",
                  "{\"tileAvailability\":{\"constant\":1},\"childSubtreeAvailability\":{"
                  "\"constant\":1}}",
                  0);
    scratch_write(s, "r101.json",
                  "{\"tileAvailability\":{\"constant\":1},\"childSubtreeAvailability\":{"
                  "\"constant\":0}}",
                  0);
    if (load(s, "region.json", NULL, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 3);
    assert_int_equal(ts.counts.subtrees, 3);
    assert_int_equal(ts.counts.regions, 3);
    assert_int_equal(ts.counts.empty, 3);
    t = ts.tiles;
    /* (1, 0): from half way across to the root's east edge, the south half,
     * the root's heights */
    r[0] = 3.0 + 0.5 * width;
    if (r[0] > GEO_PI)
        r[0] -= 2.0 * GEO_PI;
    r[1] = -0.1;
    r[2] = -3.0;
    r[3] = 0.0;
    r[4] = 0.0;
    r[5] = 100.0;
    geo_region_box(r, c, a);
    for (k = 0; k < 3; ++k)
        assert_close(t[1].bounds.center[k], c[k], 1e-6);
    assert_close(t[1].bounds.half_axes[2][2], a[8], 1e-6);
    /* (0, 1): the west half, the north half */
    r[0] = 3.0;
    r[1] = 0.0;
    r[2] = 3.0 + 0.5 * width;
    r[3] = 0.1;
    if (r[2] > GEO_PI)
        r[2] -= 2.0 * GEO_PI;
    geo_region_box(r, c, a);
    for (k = 0; k < 3; ++k)
        assert_close(t[2].bounds.center[k], c[k], 1e-6);
    assert_int_equal(t[1].parent, 0);
    assert_int_equal(t[2].parent, 0);
    tileset_free(&ts);
    size_table_free(&sizes);
    scratch_free(s);
}

#define IMPLICIT(volume, it) \
    TILE("\"geometricError\":1,\"boundingVolume\":{" volume "},\"implicitTiling\":{" it "}")
#define QUAD "\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":2,\"availableLevels\":3,"
#define SUBTREES "\"subtrees\":{\"uri\":\"st{level}{x}{y}.json\"}"
#define BOX "\"box\":[0,0,0,1,0,0,0,1,0,0,0,1]"

/* One implicit tileset whose root subtree (st000.json) is `subtree`, refused
 * with `expect`. */
static void assert_subtree_refused(scratch *s, const char *subtree, const char *expect) {
    scratch_write(s, "st000.json", subtree, 0);
    assert_refused(s, IMPLICIT(BOX, QUAD SUBTREES), expect);
    remove(s->files[--s->count]);
}

static void refuses_bad_implicit_tilesets_saying_what(void **state) {
    static const unsigned char chunk[8] = {1};
    scratch *s = scratch_new();
    (void)state;
    assert_refused(s, IMPLICIT("\"sphere\":[0,0,0,1]", QUAD SUBTREES), "a box or a region");
    assert_refused(s,
                   IMPLICIT(BOX, "\"subdivisionScheme\":\"quadtree\",\"subtreeLevels\":2,"
                                 "\"availableLevels\":3," SUBTREES),
                   "subdivisionScheme must be \"QUADTREE\" or \"OCTREE\"");
    assert_refused(s,
                   IMPLICIT(BOX, "\"subdivisionScheme\":\"OCTREE\",\"subtreeLevels\":22,"
                                 "\"availableLevels\":3," SUBTREES),
                   "subtreeLevels must be an integer in [1, 21]");
    assert_refused(s,
                   IMPLICIT(BOX, "\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":2,"
                                 "\"availableLevels\":2.5," SUBTREES),
                   "availableLevels must be an integer in [1, 32]");
    assert_refused(s, IMPLICIT(BOX, QUAD "\"subtrees\":{}"), "subtrees needs a \"uri\"");
    assert_refused(s,
                   TILE("\"geometricError\":1,\"boundingVolume\":{" BOX "},\"children\":[],"
                        "\"implicitTiling\":{" QUAD SUBTREES "}"),
                   "an implicit root tile has no \"children\"");
    assert_refused(s,
                   TILE("\"geometricError\":1,\"boundingVolume\":{" BOX "},\"content\":{\"uri\":"
                        "\"t.json\"},\"implicitTiling\":{" QUAD SUBTREES "}"),
                   "is an external tileset");
    assert_refused(
        s, TILE("\"geometricError\":1," SPHERE ",\"extensions\":{\"3DTILES_implicit_tiling\":{}}"),
        "3DTILES_implicit_tiling extension");
    assert_refused(s, IMPLICIT(BOX, QUAD SUBTREES), "st000.json: cannot read subtree");
    assert_subtree_refused(s, "{\"childSubtreeAvailability\":{\"constant\":0}}",
                           "tileAvailability needs a \"bitstream\", or a \"constant\" of 0 or 1");
    assert_subtree_refused(s,
                           "{\"tileAvailability\":{\"constant\":0},\"childSubtreeAvailability\":"
                           "{\"constant\":0}}",
                           "the subtree's root tile is not available");
    assert_subtree_refused(s,
                           "{\"tileAvailability\":{\"bitstream\":0},\"childSubtreeAvailability\":"
                           "{\"constant\":0}}",
                           "tileAvailability names bufferViews[0], which does not exist");
    /* 5 tiles' bits need a byte: a view of none is too short; a view past
     * its buffer; a buffer with no uri in a JSON subtree (no binary chunk) */
    scratch_write_bytes(s, "st.bin", chunk, 1);
    assert_subtree_refused(
        s,
        "{\"buffers\":[{\"uri\":\"st.bin\",\"byteLength\":1}],\"bufferViews\":[{\"buffer\":0,"
        "\"byteLength\":0}],\"tileAvailability\":{\"bitstream\":0},"
        "\"childSubtreeAvailability\":{\"constant\":0}}",
        "tileAvailability needs 5 bits, and bufferViews[0] holds 0");
    assert_subtree_refused(
        s,
        "{\"buffers\":[{\"uri\":\"st.bin\",\"byteLength\":1}],\"bufferViews\":[{\"buffer\":0,"
        "\"byteOffset\":1,\"byteLength\":1}],\"tileAvailability\":{\"bitstream\":0},"
        "\"childSubtreeAvailability\":{\"constant\":0}}",
        "bufferViews[0] reaches past the end of buffers[0]");
    assert_subtree_refused(
        s,
        "{\"buffers\":[{\"uri\":\"st.bin\",\"byteLength\":2}],\"bufferViews\":[{\"buffer\":0,"
        "\"byteLength\":1}],\"tileAvailability\":{\"bitstream\":0},"
        "\"childSubtreeAvailability\":{\"constant\":0}}",
        "st.bin holds fewer bytes than its byteLength");
    assert_subtree_refused(
        s,
        "{\"buffers\":[{\"byteLength\":1}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":1}],"
        "\"tileAvailability\":{\"bitstream\":0},\"childSubtreeAvailability\":{\"constant\":0}}",
        "buffers[0] has no uri and the file's binary chunk is empty");
    /* a binary subtree whose chunk is shorter than its header says */
    {
        unsigned char bad[40];
        memset(bad, 0, sizeof(bad));
        memcpy(bad, "subt", 4);
        bad[4] = 1;
        bad[8] = 8;
        bad[16] = 64;
        scratch_write_bytes(s, "st000.json", bad, sizeof(bad));
        assert_refused(s, IMPLICIT(BOX, QUAD SUBTREES), "reach past the end of the file");
        remove(s->files[--s->count]);
    }
    /* at most so many tiles: an octree of 3 levels has 1 + 8 + 64 */
    {
        tileset ts;
        char err[512], path[160];
        scratch_write(s, "st000.json",
                      "{\"tileAvailability\":{\"constant\":1},\"childSubtreeAvailability\":{"
                      "\"constant\":0}}",
                      0);
        scratch_write(s, "octree.json",
                      IMPLICIT(BOX, "\"subdivisionScheme\":\"OCTREE\",\"subtreeLevels\":3,"
                                    "\"availableLevels\":3," SUBTREES),
                      0);
        snprintf(path, sizeof(path), "%s/octree.json", s->dir);
        assert_int_equal(tileset_load_at_most(path, NULL, 72, &ts, err, sizeof(err)), 1);
        if (!strstr(err, "st000.json: more than 72 tiles"))
            fail_msg("%s", err);
        if (tileset_load_at_most(path, NULL, 73, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(ts.count, 73);
        tileset_free(&ts);
        remove(s->files[--s->count]);
        remove(s->files[--s->count]);
    }
    /* and a good one with a chunk loads */
    scratch_write_subtree(s, "st000.json",
                          "{\"buffers\":[{\"byteLength\":1}],\"bufferViews\":[{\"buffer\":0,"
                          "\"byteLength\":1}],\"tileAvailability\":{\"bitstream\":0},"
                          "\"childSubtreeAvailability\":{\"constant\":0}}",
                          chunk, sizeof(chunk));
    {
        tileset ts;
        char err[512];
        scratch_write(s, "good.json", IMPLICIT(BOX, QUAD SUBTREES), 0);
        if (load(s, "good.json", NULL, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(ts.count, 1);
        tileset_free(&ts);
    }
    scratch_free(s);
}

/* ---- the benefit model -------------------------------------------------------------- */

/* A view from the origin down -z. */
static tclod_view view_down_z(void) {
    tclod_view v;
    memset(&v, 0, sizeof(v));
    v.forward[2] = -1.0f;
    v.up[1] = 1.0f;
    v.fov_y = 1.0f;
    v.aspect = 1.5f;
    v.near_z = 0.1f;
    v.far_z = 1000.0f;
    v.viewport_height = 600.0f;
    return v;
}


/* ---- reading on demand ------------------------------------------------------------ */

/* Opens dir/name lazily (tileset_open); the error message goes to err. */
static int open_lazily(const scratch *s, const char *name, uint32_t max_tiles, tileset *ts,
                       char *err, size_t err_size) {
    char path[160];
    snprintf(path, sizeof(path), "%s/%s", s->dir, name);
    err[0] = '\0';
    return tileset_open(path, NULL, max_tiles, ts, err, err_size);
}

static void expand_or_fail(tileset *ts, uint32_t t) {
    char err[512];
    if (tileset_expand(ts, t, err, sizeof(err)))
        fail_msg("expanding tile %u: %s", (unsigned)t, err);
}

/* The bytes of a file, for file_bytes. */
static double file_size(const scratch *s, const char *name) {
    char path[160];
    struct stat st;
    snprintf(path, sizeof(path), "%s/%s", s->dir, name);
    assert_int_equal(stat(path, &st), 0);
    return (double)st.st_size;
}

/* The quadtree of reads_an_implicit_quadtree_of_boxes, opened: the tileset
 * alone is read, its root standing for subtree 0; expanding it reads that
 * file (the root takes its content, none, and level 1's tiles come) and makes
 * tile 2/3/2 stand for its subtree; expanding that gives it its content.
 * Then every figure is the whole read's. */
static void opens_an_implicit_tileset_reading_subtrees_on_demand(void **state) {
    scratch *s = scratch_new();
    tileset ts;
    char err[512];
    const tile *t;
    (void)state;
    write_quadtree_of_boxes(s);
    if (open_lazily(s, "tileset.json", TILESET_MAX_TILES, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 1);
    assert_int_equal(ts.counts.files, 1);
    assert_int_equal(ts.counts.unexpanded, 1);
    t = ts.tiles;
    assert_true(t[0].unexpanded);
    assert_int_equal(t[0].child_count, 0);
    assert_close(t[0].file_bytes, file_size(s, "s/0.0.0.subtree"), 0.0);
    assert_box(&t[0], 100.0, 0.0, 0.0, 8.0, 8.0, 2.0);
    expand_or_fail(&ts, 0);
    t = ts.tiles;
    assert_int_equal(ts.count, 4);
    assert_int_equal(ts.counts.files, 2);
    assert_false(t[0].unexpanded);
    assert_true(t[0].empty);
    assert_int_equal(t[0].child_count, 2);
    assert_int_equal(ts.children[t[0].first_child], 1);
    assert_int_equal(ts.children[t[0].first_child + 1], 2);
    assert_box(&t[1], 96.0, -4.0, 0.0, 4.0, 4.0, 2.0);
    assert_box(&t[2], 104.0, 4.0, 0.0, 4.0, 4.0, 2.0);
    assert_false(t[1].empty || t[1].unexpanded || t[2].unexpanded);
    /* 2/3/2 stands for its subtree: its volume and error known, its content not */
    assert_int_equal(t[3].parent, 2);
    assert_true(t[3].unexpanded);
    assert_true(t[3].empty);
    assert_close(t[3].file_bytes, file_size(s, "s/2.3.2.subtree"), 0.0);
    assert_box(&t[3], 106.0, 2.0, 0.0, 2.0, 2.0, 2.0);
    assert_close(t[3].geometric_error, 16.0, 0.0);
    assert_int_equal(t[3].depth, 2);
    assert_int_equal(t[3].add_anchor, 2);
    /* expanded ones are refused, and so is a tile out of range */
    assert_int_equal(tileset_expand(&ts, 1, err, sizeof(err)), 1);
    assert_non_null(strstr(err, "tile 1: not unexpanded"));
    assert_int_equal(tileset_expand(&ts, 4, err, sizeof(err)), 1);
    assert_non_null(strstr(err, "tile 4: no such tile"));
    expand_or_fail(&ts, 3);
    t = ts.tiles;
    assert_int_equal(ts.count, 4);
    assert_false(t[3].unexpanded || t[3].empty);
    assert_close(t[3].bytes, TILESET_ESTIMATE_BYTES, 0.0);
    /* the whole read's counts (reads_an_implicit_quadtree_of_boxes, without sizes) */
    assert_int_equal(ts.counts.files, 3);
    assert_int_equal(ts.counts.unexpanded, 0);
    assert_int_equal(ts.counts.implicit, 1);
    assert_int_equal(ts.counts.subtrees, 2);
    assert_int_equal(ts.counts.contents, 3);
    assert_int_equal(ts.counts.empty, 1);
    assert_int_equal(ts.counts.boxes, 4);
    tileset_free(&ts);
    scratch_free(s);
}

/* A tile's place, to compare tilesets read in different orders. */
typedef struct tile_key {
    uint32_t depth;
    double x, y, error, bytes, parent_x, parent_y;
    int empty;
} tile_key;

static int by_tile_key(const void *a, const void *b) {
    const tile_key *p = (const tile_key *)a, *q = (const tile_key *)b;
    if (p->depth != q->depth)
        return p->depth < q->depth ? -1 : 1;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->y > q->y) - (p->y < q->y);
}

static tile_key *tile_keys(const tileset *ts) {
    tile_key *k = (tile_key *)calloc(ts->count, sizeof(*k));
    uint32_t i;
    assert_non_null(k);
    for (i = 0; i < ts->count; ++i) {
        const tile *t = &ts->tiles[i];
        k[i].depth = t->depth;
        k[i].x = t->bounds.center[0];
        k[i].y = t->bounds.center[1];
        k[i].error = t->geometric_error;
        k[i].bytes = t->bytes;
        k[i].empty = t->empty;
        k[i].parent_x = t->parent == TILE_NONE ? 0.0 : ts->tiles[t->parent].bounds.center[0];
        k[i].parent_y = t->parent == TILE_NONE ? 0.0 : ts->tiles[t->parent].bounds.center[1];
    }
    qsort(k, ts->count, sizeof(*k), by_tile_key);
    return k;
}

/* A quadtree of 4 levels in subtrees of 2, every tile available, one
 * subtree file a level ({level} alone in the template): expanding every
 * unexpanded tile until none is left gives the tiles the whole read gives,
 * 1 + 4 + 16 + 64 = 85, each below the same parent; and an external tileset
 * read on demand likewise. */
static void expanding_everything_reads_what_the_whole_read_does(void **state) {
    scratch *s = scratch_new();
    tileset whole, lazy;
    char err[512];
    tile_key *a, *b;
    uint32_t i;
    (void)state;
    scratch_write(s, "implicit.json",
                  "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":80,"
                  "\"refine\":\"REPLACE\",\"boundingVolume\":{\"box\":[0,0,0,64,0,0,0,64,0,0,0,1]},"
                  "\"content\":{\"uri\":\"c/{level}/{x}/{y}.glb\"},"
                  "\"implicitTiling\":{\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":2,"
                  "\"availableLevels\":4,\"subtrees\":{\"uri\":\"s{level}.json\"}}}}",
                  0);
    scratch_write(s, "s0.json",
                  "{\"tileAvailability\":{\"constant\":1},\"contentAvailability\":[{\"constant\":"
                  "1}],\"childSubtreeAvailability\":{\"constant\":1}}",
                  0);
    scratch_write(s, "s2.json",
                  "{\"tileAvailability\":{\"constant\":1},\"contentAvailability\":[{\"constant\":"
                  "1}],\"childSubtreeAvailability\":{\"constant\":0}}",
                  0);
    /* a tileset whose second child links the quadtree, whose first one a
     * tileset without children */
    scratch_write(s, "tileset.json",
                  TILE("\"geometricError\":100,\"refine\":\"ADD\","
                       "\"boundingVolume\":{\"box\":[0,0,0,64,0,0,0,64,0,0,0,1]},"
                       "\"children\":[{\"geometricError\":90," SPHERE
                       ",\"content\":{\"uri\":\"leaf.json\"}},{\"geometricError\":90,"
                       "\"boundingVolume\":{\"box\":[0,0,0,64,0,0,0,64,0,0,0,1]},"
                       "\"content\":{\"uri\":\"implicit.json\"}}]"),
                  0);
    scratch_write(s, "leaf.json", TILE("\"geometricError\":0," SPHERE), 0);
    if (load(s, "tileset.json", NULL, &whole, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(whole.count, 3 + 1 + 85);
    if (open_lazily(s, "tileset.json", TILESET_MAX_TILES, &lazy, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(lazy.count, 3);
    assert_int_equal(lazy.counts.files, 1);
    assert_int_equal(lazy.counts.unexpanded, 2);
    assert_true(lazy.tiles[1].unexpanded && lazy.tiles[2].unexpanded);
    assert_close(lazy.tiles[1].file_bytes, file_size(s, "leaf.json"), 0.0);
    for (i = 0; i < lazy.count; ++i)
        if (lazy.tiles[i].unexpanded)
            expand_or_fail(&lazy, i);
    assert_int_equal(lazy.count, whole.count);
    assert_int_equal(lazy.counts.unexpanded, 0);
    /* the tileset, the two linked ones, and subtrees: 1 at level 0, 16 at 2 */
    assert_int_equal(lazy.counts.files, 3 + 17);
    assert_int_equal(lazy.counts.files, whole.counts.files);
    assert_int_equal(lazy.counts.external, 2);
    assert_int_equal(lazy.counts.max_depth, whole.counts.max_depth);
    a = tile_keys(&whole);
    b = tile_keys(&lazy);
    for (i = 0; i < whole.count; ++i) {
        assert_int_equal(a[i].depth, b[i].depth);
        assert_close(b[i].x, a[i].x, 0.0);
        assert_close(b[i].y, a[i].y, 0.0);
        assert_close(b[i].error, a[i].error, 0.0);
        assert_close(b[i].bytes, a[i].bytes, 0.0);
        assert_int_equal(b[i].empty, a[i].empty);
        assert_close(b[i].parent_x, a[i].parent_x, 0.0);
        assert_close(b[i].parent_y, a[i].parent_y, 0.0);
    }
    free(a);
    free(b);
    tileset_free(&whole);
    tileset_free(&lazy);
    scratch_free(s);
}

/* 1 398 101 tiles (a quadtree of 11 levels, every tile a subtree of its own,
 * one subtree file a level): opened, one file is read and one tile known;
 * down one branch to the finest level, 11 subtrees more and 41 tiles, each
 * level's 4 (one expanded), the deepest hand-worked: level 10's tile
 * (1023, 1023) of a root box of half axes 1024 is centred at (1023, 1023),
 * half axes 1, error 2^20 / 2^10. The whole read refuses it under a cap of
 * 100 tiles (it would read every tile's subtree), the lazy one stays within
 * it. */
static void a_million_implicit_tiles_open_by_one_file(void **state) {
    scratch *s = scratch_new();
    tileset ts;
    char err[512];
    const tile *t;
    uint32_t level, last = 0;
    (void)state;
    scratch_write(s, "tileset.json",
                  "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":1048576,"
                  "\"refine\":\"REPLACE\","
                  "\"boundingVolume\":{\"box\":[0,0,0,1024,0,0,0,1024,0,0,0,1]},"
                  "\"content\":{\"uri\":\"c/{level}/{x}/{y}.glb\"},"
                  "\"implicitTiling\":{\"subdivisionScheme\":\"QUADTREE\",\"subtreeLevels\":1,"
                  "\"availableLevels\":11,\"subtrees\":{\"uri\":\"{level}.json\"}}}}",
                  0);
    for (level = 0; level < 11; ++level) {
        char name[16];
        snprintf(name, sizeof(name), "%u.json", (unsigned)level);
        scratch_write(s, name,
                      "{\"tileAvailability\":{\"constant\":1},\"contentAvailability\":[{"
                      "\"constant\":1}],\"childSubtreeAvailability\":{\"constant\":1}}",
                      0);
    }
    {
        char path[160];
        snprintf(path, sizeof(path), "%s/tileset.json", s->dir);
        assert_int_equal(tileset_load_at_most(path, NULL, 100, &ts, err, sizeof(err)), 1);
        assert_non_null(strstr(err, "more than 100 tiles"));
    }
    if (open_lazily(s, "tileset.json", 100, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 1);
    assert_int_equal(ts.counts.files, 1);
    for (level = 0; level < 11; ++level) {
        assert_true(ts.tiles[last].unexpanded);
        expand_or_fail(&ts, last);
        assert_int_equal(ts.count, 1 + 4 * (level + 1 < 11 ? level + 1 : 10));
        last = ts.count - 1; /* the child at Morton index 3: (2x + 1, 2y + 1) */
    }
    assert_int_equal(ts.counts.files, 12);
    assert_int_equal(ts.counts.unexpanded, 30);
    assert_int_equal(ts.counts.max_depth, 10);
    t = &ts.tiles[last];
    assert_int_equal(t->depth, 10);
    assert_false(t->unexpanded || t->empty);
    assert_int_equal(t->child_count, 0);
    assert_box(t, 1023.0, 1023.0, 0.0, 1.0, 1.0, 1.0);
    assert_close(t->geometric_error, 1024.0, 0.0);
    tileset_free(&ts);
    scratch_free(s);
}

/* An expansion that fails (a missing file, a cycle, the tile cap) says which
 * file and what, and leaves the tileset as it was; it can be tried again. */
static void a_failed_expansion_changes_nothing(void **state) {
    scratch *s = scratch_new();
    tileset ts;
    tileset_counts before;
    char err[512];
    (void)state;
    scratch_write(s, "tileset.json",
                  TILE("\"geometricError\":100," SPHERE
                       ",\"children\":[{\"geometricError\":50," SPHERE
                       ",\"content\":{\"uri\":\"a.json\"}},{\"geometricError\":50," SPHERE
                       ",\"content\":{\"uri\":\"gone.json\"}}]"),
                  0);
    /* a.json: two tiles, and a link back to tileset.json */
    scratch_write(s, "a.json",
                  TILE("\"geometricError\":40," SPHERE ",\"children\":[{\"geometricError\":30," SPHERE
                       ",\"content\":{\"uri\":\"tileset.json\"}}]"),
                  0);
    if (open_lazily(s, "tileset.json", 5, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 3);
    assert_close(ts.tiles[2].file_bytes, 0.0, 0.0); /* gone.json is nowhere */
    before = ts.counts;
    assert_int_equal(tileset_expand(&ts, 2, err, sizeof(err)), 1);
    if (!strstr(err, "gone.json") || !strstr(err, "cannot open external tileset"))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 3);
    assert_true(ts.tiles[2].unexpanded);
    assert_int_equal(memcmp(&before, &ts.counts, sizeof(before)), 0);
    expand_or_fail(&ts, 1);
    assert_int_equal(ts.count, 5);
    assert_int_equal(ts.tiles[3].parent, 1);
    assert_int_equal(ts.tiles[4].parent, 3);
    assert_true(ts.tiles[4].unexpanded);
    before = ts.counts;
    assert_int_equal(tileset_expand(&ts, 4, err, sizeof(err)), 1);
    if (!strstr(err, "cycle"))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 5);
    assert_true(ts.tiles[4].unexpanded);
    assert_int_equal(ts.tiles[4].child_count, 0);
    assert_int_equal(memcmp(&before, &ts.counts, sizeof(before)), 0);
    /* gone.json arrives; the cap of 5 tiles then refuses its one tile */
    scratch_write(s, "gone.json", TILE("\"geometricError\":0," SPHERE), 0);
    assert_int_equal(tileset_expand(&ts, 2, err, sizeof(err)), 1);
    if (!strstr(err, "more than 5 tiles"))
        fail_msg("%s", err);
    assert_int_equal(ts.count, 5);
    assert_int_equal(memcmp(&before, &ts.counts, sizeof(before)), 0);
    tileset_free(&ts);
    /* a tileset loaded whole has nothing to expand */
    assert_int_equal(load(s, "gone.json", NULL, &ts, err, sizeof(err)), 0);
    assert_int_equal(tileset_expand(&ts, 0, err, sizeof(err)), 1);
    assert_non_null(strstr(err, "loaded whole"));
    tileset_free(&ts);
    scratch_free(s);
}

/* Children split their parent's share: refining a tile by ADD adds what the
 * children improve on it, by REPLACE what they improve on it too; with exact
 * children (error 0) either way the drawn tiles' benefits sum to the parent's
 * share. */
static void benefits_telescope_to_the_parents_share(void **state) {
    static const char *const kinds[2] = {"ADD", "REPLACE"};
    int k;
    (void)state;
    for (k = 0; k < 2; ++k) {
        scratch *s = scratch_new();
        tileset ts;
        tiles_model m;
        tclod_view v = view_down_z();
        char err[512], json[512];
        double root, c1, c2, sum, d;
        snprintf(
            json, sizeof(json),
            "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":8,\"refine\":\"%s\","
            "\"boundingVolume\":{\"sphere\":[0,0,-100,12]},\"content\":{\"uri\":\"r.glb\"},"
            "\"children\":[{\"geometricError\":0,\"boundingVolume\":{\"sphere\":[-5,0,-100,5]},"
            "\"content\":{\"uri\":\"a.glb\"}},{\"geometricError\":0,\"boundingVolume\":"
            "{\"sphere\":[6,1,-100,4]},\"content\":{\"uri\":\"b.glb\"}}]}}",
            kinds[k]);
        scratch_write(s, "t.json", json, 0);
        if (load(s, "t.json", NULL, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(model_init(&m, &ts), 0);
        model_set_view(&m, &v);
        d = model_distance(&m, 0);
        assert_close(d, 88.0, 1e-9);
        assert_close(model_sse(&m, 0, d), 8.0 * 300.0 / tan(0.5) / 88.0, 1e-9);
        root = model_benefit(&m, 0, d);
        c1 = model_benefit(&m, 1, model_distance(&m, 1));
        c2 = model_benefit(&m, 2, model_distance(&m, 2));
        sum = k == 0 ? root + c1 + c2 : c1 + c2;
        /* the root's share is its projected area; error-free children hold it whole */
        assert_close(sum, model_area(&m, 0), 1e-9 * model_area(&m, 0));
        assert_true(root < model_area(&m, 0));
        /* the shares follow the children's areas */
        assert_close(c1 / c2, model_area(&m, 1) / model_area(&m, 2), 1e-9);
        model_free(&m);
        tileset_free(&ts);
        scratch_free(s);
    }
}

/* The benefit culls what CesiumJS culls and weighs what is on screen (and
 * a tile is shown only to an eye inside its viewerRequestVolume):
 *  - a REPLACE box whose children are boxes within it, none in view, shows
 *    nothing (CesiumJS's cullWithChildrenBounds): benefit 0; with a child
 *    that reaches out of it, it is drawn as seen;
 *  - a tile whose parent is out of view has no share and is culled, though
 *    its own volume (reaching out of the parent's) is in view;
 *  - from inside a volume the error is seen from the near plane: a sphere of
 *    error 1 around the eye, 0.1 m near, shows 1 x 300 / tan(0.5) / 0.1 px
 *    over the whole viewport, at quality 1 / (1 + s / 256). */
static void the_benefit_culls_what_cesiumjs_culls(void **state) {
    static const char *const boxes =
        "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":8,\"refine\":\"REPLACE\","
        "\"boundingVolume\":{\"box\":[0,0,-100,20,0,0,0,20,0,0,0,20]},\"content\":{\"uri\":\"r\"},"
        "\"children\":[{\"geometricError\":0,\"boundingVolume\":{\"box\":[-10,0,-100,5,0,0,0,5,0,"
        "0,0,5]},\"content\":{\"uri\":\"a\"}},{\"geometricError\":0,\"boundingVolume\":{\"box\":["
        "10,0,-100,%d,0,0,0,5,0,0,0,5]},\"content\":{\"uri\":\"b\"}}]}}";
    static const char *const spheres =
        "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":1,"
        "\"boundingVolume\":{\"sphere\":[0,0,0,10]},\"content\":{\"uri\":\"r\"},"
        "\"children\":[{\"geometricError\":0,\"boundingVolume\":{\"sphere\":[100,0,-100,4]},"
        "\"content\":{\"uri\":\"a\"},\"children\":[{\"geometricError\":0,\"boundingVolume\":{"
        "\"sphere\":[0,0,-100,1]},\"content\":{\"uri\":\"b\"}}]}]}}";
    int loose;
    (void)state;
    for (loose = 0; loose < 2; ++loose) {
        scratch *s = scratch_new();
        tileset ts;
        tiles_model m;
        tclod_view v = view_down_z();
        char err[512], json[512];
        double b;
        snprintf(json, sizeof(json), boxes, loose ? 30 : 5);
        scratch_write(s, "t.json", json, 0);
        if (load(s, "t.json", NULL, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(ts.tiles[2].loose, loose);
        assert_int_equal(model_init(&m, &ts), 0);
        /* inside the root's box above the children, looking away from them */
        v.eye[1] = 15.0;
        v.eye[2] = -100.0;
        v.forward[1] = 1.0f;
        v.forward[2] = 0.0f;
        v.up[1] = 0.0f;
        v.up[2] = 1.0f;
        model_set_view(&m, &v);
        assert_true(model_area(&m, 0) > 0.0);
        assert_true(model_area(&m, 1) == 0.0);
        b = model_benefit(&m, 0, model_distance(&m, 0));
        if (loose)
            assert_true(b > 0.0 && model_area(&m, 2) == 0.0);
        else
            assert_true(b == 0.0);
        model_free(&m);
        tileset_free(&ts);
        scratch_free(s);
    }
    {
        scratch *s = scratch_new();
        tileset ts;
        tiles_model m;
        tclod_view v = view_down_z();
        char err[512];
        double sse = 1.0 * 300.0 / tan(0.5) / 0.1, area;
        scratch_write(s, "t.json", spheres, 0);
        if (load(s, "t.json", NULL, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(model_init(&m, &ts), 0);
        model_set_view(&m, &v);
        assert_true(model_area(&m, 1) == 0.0 && model_area(&m, 2) > 0.0);
        assert_true(model_benefit(&m, 2, model_distance(&m, 2)) == 0.0);
        area = model_area(&m, 0);
        assert_close(area, 600.0 * 600.0 * 1.5, 1e-6);
        assert_close(model_distance(&m, 0), 0.0, 0.0);
        assert_close(model_benefit(&m, 0, 0.0), area / (1.0 + sse / MODEL_HALF_QUALITY_SSE),
                     1e-9 * area);
        model_free(&m);
        tileset_free(&ts);
        scratch_free(s);
    }
    { /* a viewerRequestVolume: the tile is shown only to an eye inside it */
        scratch *s = scratch_new();
        tileset ts;
        tiles_model m;
        tclod_view v = view_down_z();
        char err[512];
        scratch_write(s, "t.json",
                      "{\"asset\":{\"version\":\"1.0\"},\"root\":{\"geometricError\":1,"
                      "\"boundingVolume\":{\"sphere\":[0,0,-100,20]},\"children\":[{"
                      "\"geometricError\":0,\"boundingVolume\":{\"sphere\":[0,0,-100,5]},"
                      "\"viewerRequestVolume\":{\"sphere\":[0,0,-100,10]},"
                      "\"content\":{\"uri\":\"a\"}}]}}",
                      0);
        if (load(s, "t.json", NULL, &ts, err, sizeof(err)))
            fail_msg("%s", err);
        assert_int_equal(ts.request_count, 1);
        assert_int_equal(ts.tiles[0].request, TILE_NONE);
        assert_int_equal(ts.tiles[1].request, 0);
        assert_close(ts.requests[0].radius, 10.0, 0.0);
        assert_int_equal(model_init(&m, &ts), 0);
        model_set_view(&m, &v); /* the eye at the origin: 90 m out of the request volume */
        assert_true(model_area(&m, 1) > 0.0 && model_out_of_request(&m, 1));
        assert_true(model_benefit(&m, 1, model_distance(&m, 1)) == 0.0);
        v.eye[2] = -95.0; /* inside it */
        model_set_view(&m, &v);
        assert_false(model_out_of_request(&m, 1));
        assert_true(model_benefit(&m, 1, model_distance(&m, 1)) > 0.0);
        model_free(&m);
        tileset_free(&ts);
        scratch_free(s);
    }
}

/* Areas the callbacks take from the queries (model_note_area) are the tiles'
 * for the view: the shares are split by them, by hand 1000 x 300 / (300 + 100)
 * = 750 and 1000 x 100 / 400 = 250 for the two error-free children (quality
 * 1). A tile measured before keeps its own area, and the next view forgets
 * the notes. */
static void noted_areas_are_the_models_for_the_view(void **state) {
    scratch *s = scratch_new();
    tileset ts;
    tiles_model m;
    tclod_view v = view_down_z();
    char err[512];
    double measured;
    (void)state;
    scratch_write(s, "t.json",
                  "{\"asset\":{\"version\":\"1.1\"},\"root\":{\"geometricError\":8,"
                  "\"refine\":\"REPLACE\",\"boundingVolume\":{\"sphere\":[0,0,-100,12]},"
                  "\"content\":{\"uri\":\"r.glb\"},\"children\":[{\"geometricError\":0,"
                  "\"boundingVolume\":{\"sphere\":[-5,0,-100,5]},\"content\":{\"uri\":\"a.glb\"}},"
                  "{\"geometricError\":0,\"boundingVolume\":{\"sphere\":[6,1,-100,4]},"
                  "\"content\":{\"uri\":\"b.glb\"}}]}}",
                  0);
    if (load(s, "t.json", NULL, &ts, err, sizeof(err)))
        fail_msg("%s", err);
    assert_int_equal(model_init(&m, &ts), 0);
    model_set_view(&m, &v);
    model_note_area(&m, 0, 1000.0);
    model_note_area(&m, 1, 300.0);
    model_note_area(&m, 2, 100.0);
    assert_true(model_area(&m, 1) == 300.0);
    assert_close(model_benefit(&m, 1, model_distance(&m, 1)), 750.0, 1e-12);
    assert_close(model_benefit(&m, 2, model_distance(&m, 2)), 250.0, 1e-12);
    model_set_view(&m, &v);
    measured = model_area(&m, 1);
    assert_true(measured == model_measure_area(&m, 1) && measured != 300.0);
    model_note_area(&m, 1, 5.0);
    assert_true(model_area(&m, 1) == measured);
    model_free(&m);
    tileset_free(&ts);
    scratch_free(s);
}

/* The host's own distance, which checks the library's queries, against the
 * library's tclod_view_bounds_distance for every kind of volume. */
static void reference_distance_matches_the_library(void **state) {
    tclod_view v = view_down_z();
    static const double c[3] = {3.0, -4.0, -50.0};
    const double s = sqrt(0.5);
    const double turned[9] = {2.0 * s, 2.0 * s, 0.0, -s, s, 0.0, 0.0, 0.0, 5.0};
    const double flat[9] = {10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0};
    const double ext[3] = {1.0, 2.0, 3.0};
    tclod_bounds b[5];
    int i;
    (void)state;
    b[0] = tclod_bounds_sphere(c[0], c[1], c[2], 7.0);
    b[1] = tclod_bounds_obb(c, turned);
    b[2] = tclod_bounds_obb(c, flat);
    b[3] = tclod_bounds_aabb(c, ext);
    b[4] = tclod_bounds_sphere(0.0, 0.0, 0.0, 2.0); /* the eye inside */
    for (i = 0; i < 5; ++i) {
        double want = model_reference_distance(&b[i], v.eye);
        assert_int_equal(tclod_bounds_validate(&b[i]), TCLOD_OK);
        assert_close(tclod_view_bounds_distance(&v, &b[i]), want, 1e-9 * (1.0 + want));
    }
    assert_close(model_reference_distance(&b[0], v.eye), sqrt(9.0 + 16.0 + 2500.0) - 7.0, 1e-12);
    assert_close(model_reference_distance(&b[4], v.eye), 0.0, 0.0);
}

/* The model measures volumes itself, with the library's definitions: its
 * areas (0 outside the frustum), frustum tests and distances against
 * tclod_view_bounds_area, _visible and _distance for every kind of volume,
 * from views along and
 * across the axes: a sphere, boxes turned, flat, axis-aligned, far and near,
 * one with the eye inside, one reaching through the near plane (which the
 * model hands to the library), one outside the frustum. */
static void model_measures_match_the_library(void **state) {
    static const double c[3] = {3.0, -4.0, -50.0}, near_c[3] = {0.0, 0.0, -1.0};
    static const double off[3] = {400.0, 0.0, -50.0}, ext[3] = {1.0, 2.0, 3.0};
    const double s = sqrt(0.5);
    const double turned[9] = {2.0 * s, 2.0 * s, 0.0, -s, s, 0.0, 0.0, 0.0, 5.0};
    const double tilted[9] = {3.0, 0.0, 0.0, 0.0, 2.0 * s, 2.0 * s, 0.0, -s, s};
    const double flat[9] = {10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0};
    const double big[9] = {4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 4.0};
    tile tiles[9];
    tileset ts;
    tiles_model m;
    tclod_view views[3];
    int i, k;
    (void)state;
    memset(tiles, 0, sizeof(tiles));
    memset(&ts, 0, sizeof(ts));
    tiles[0].bounds = tclod_bounds_sphere(c[0], c[1], c[2], 7.0);
    tiles[1].bounds = tclod_bounds_obb(c, turned);
    tiles[2].bounds = tclod_bounds_obb(c, tilted);
    tiles[3].bounds = tclod_bounds_obb(c, flat);
    tiles[4].bounds = tclod_bounds_aabb(c, ext);
    tiles[5].bounds = tclod_bounds_obb(near_c, big);  /* the eye inside */
    tiles[6].bounds = tclod_bounds_aabb(near_c, ext); /* through the near plane */
    tiles[7].bounds = tclod_bounds_aabb(off, ext);    /* outside the frustum */
    tiles[8].bounds = tclod_bounds_obb(off, tilted);
    for (i = 0; i < 9; ++i)
        tiles[i].parent = TILE_NONE;
    ts.tiles = tiles;
    ts.count = 9;
    views[0] = view_down_z();
    views[1] = view_down_z(); /* from the side, looking across the boxes */
    views[1].eye[0] = -60.0;
    views[1].eye[2] = -45.0;
    views[1].forward[0] = 1.0f;
    views[1].forward[2] = 0.1f;
    views[2] = view_down_z(); /* turned about the view axis, from above */
    views[2].eye[1] = 20.0;
    views[2].up[0] = 0.6f;
    views[2].up[1] = 0.8f;
    assert_int_equal(model_init(&m, &ts), 0);
    for (k = 0; k < 3; ++k) {
        assert_int_equal(tclod_view_validate(&views[k]), TCLOD_OK);
        model_set_view(&m, &views[k]);
        for (i = 0; i < 9; ++i) {
            const tclod_bounds *b = &tiles[i].bounds;
            double want = tclod_view_bounds_visible(&views[k], b)
                              ? tclod_view_bounds_area(&views[k], b)
                              : 0.0;
            double d = tclod_view_bounds_distance(&views[k], b);
            assert_close(model_area(&m, (uint32_t)i), want, 1e-9 * (1.0 + want));
            assert_close(model_distance(&m, (uint32_t)i), d, 1e-9 * (1.0 + d));
            assert_int_equal(model_visible(&m, (uint32_t)i),
                             tclod_view_bounds_visible(&views[k], b));
        }
    }
    /* the cases the views were chosen for */
    model_set_view(&m, &views[0]);
    assert_true(model_area(&m, 1) > 0.0);
    assert_close(model_area(&m, 5), 600.0 * 600.0 * 1.5, 1e-6);
    assert_true(model_area(&m, 6) > 0.0);
    assert_true(model_area(&m, 7) == 0.0);
    assert_true(model_visible(&m, 0) && model_visible(&m, 6) && !model_visible(&m, 7));
    model_free(&m);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(region_box_encloses_the_region),
        cmocka_unit_test(region_validity),
        cmocka_unit_test(reads_volumes_transforms_refinement_and_contents),
        cmocka_unit_test(reads_what_real_producers_write_and_counts_it),
        cmocka_unit_test(refuses_bad_tilesets_saying_where),
        cmocka_unit_test(refuses_external_tilesets_nested_too_deep),
        cmocka_unit_test(reads_an_implicit_quadtree_of_boxes),
        cmocka_unit_test(reads_implicit_octrees_and_regions),
        cmocka_unit_test(refuses_bad_implicit_tilesets_saying_what),
        cmocka_unit_test(opens_an_implicit_tileset_reading_subtrees_on_demand),
        cmocka_unit_test(expanding_everything_reads_what_the_whole_read_does),
        cmocka_unit_test(a_million_implicit_tiles_open_by_one_file),
        cmocka_unit_test(a_failed_expansion_changes_nothing),
        cmocka_unit_test(benefits_telescope_to_the_parents_share),
        cmocka_unit_test(the_benefit_culls_what_cesiumjs_culls),
        cmocka_unit_test(noted_areas_are_the_models_for_the_view),
        cmocka_unit_test(reference_distance_matches_the_library),
        cmocka_unit_test(model_measures_match_the_library),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
