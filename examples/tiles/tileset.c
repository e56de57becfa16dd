/*
 * tileset — the 3D Tiles reader of tileset.h.
 *
 * Tiles are read depth first from an explicit stack (a tileset's depth is the
 * file's business, not the C stack's). Each stack entry carries what a tile
 * inherits from its parent: the composed transform and the refinement. A
 * content whose uri ends in .json is an external tileset: its file is parsed
 * and its root goes on the stack below the tile that names it, with that
 * tile's transform. Every parsed document stays alive until the end, since the
 * stack points into them.
 */
#include "tileset.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "geodesy.h"

#define DOC_NONE 0xffffffffu
/* The largest JSON file read: far above any real tileset.json, low enough that
 * a wrong path (a disk image, say) fails at once. */
#define MAX_FILE_BYTES (1L << 30)

/* One parsed tileset file. */
typedef struct document {
    char *path; /* as opened */
    char *dir;  /* its directory with a trailing '/', or "" */
    dev_t dev;  /* the file's identity, for cycles */
    ino_t ino;
    cJSON *json;
    uint32_t parent; /* the document naming it, DOC_NONE for the main one */
    uint32_t depth;  /* external levels above it */
} document;

/* A tile waiting to be read, with what it inherits. */
typedef struct pending {
    const cJSON *json;
    uint32_t parent; /* tile */
    uint32_t doc;
    int32_t index; /* position in the parent's "children"; -1 for a document's root */
    tclod_refine refine;
    double transform[16];
    double error;     /* the parent's geometricError as written (the main root: the
                         tileset's, -1 when it has none): a tile without one takes it */
    int in_region;    /* 1: the parent's volume is the region below */
    double region[6]; /* the parent's region, to tell whether the tile reaches out */
} pending;

/* A file not read yet that an unexpanded tile stands for (tileset_open). */
typedef struct file_link {
    uint32_t tile;
    uint32_t implicit;      /* its implicit tiling, loader.implicits[implicit]; DOC_NONE:
                               an external tileset */
    pending via;            /* external: the linking tile's entry (messages, cycles) */
    pending root;           /* external: what the linked root inherits, json aside */
    uint32_t level, xyz[3]; /* implicit: the subtree's root tile */
    char *path;
} file_link;

struct implicit;

typedef struct loader {
    const size_table *sizes;
    uint32_t max_tiles;
    int lazy; /* tileset_open: files other than the first become unexpanded tiles */
    document *docs;
    uint32_t doc_count, doc_cap;
    pending *stack;
    size_t top, stack_cap;
    tile *tiles;
    uint32_t count, tile_cap;
    tclod_bounds *requests; /* viewerRequestVolumes */
    uint32_t request_count, request_cap;
    uint32_t *tile_doc;  /* per tile: its document, for messages */
    int32_t *tile_index; /* per tile: its position in its parent's "children" */
    uint32_t *tile_file; /* per tile: its entry in files, TILE_NONE when expanded */
    uint32_t *children;  /* tileset.children */
    size_t child_count, child_cap;
    file_link *files;
    uint32_t file_count, file_cap;
    struct implicit *implicits;
    uint32_t implicit_count;
    size_t implicit_cap;
    tileset_counts counts;
    char *err;
    size_t err_size;
} loader;

/* ---- messages ---------------------------------------------------------------- */

/* Lets the compiler check the messages' formats. */
#if defined(__GNUC__) || defined(__clang__)
#define PRINTF_LIKE(f, a) __attribute__((format(printf, f, a)))
#else
#define PRINTF_LIKE(f, a)
#endif

static void fail(loader *l, const char *fmt, ...) PRINTF_LIKE(2, 3);
static void fail_tile(loader *l, const pending *p, const char *fmt, ...) PRINTF_LIKE(3, 4);

static void fail(loader *l, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(l->err, l->err_size, fmt, ap);
    va_end(ap);
}

/* "root.children[2].children[0]": where a tile sits in its document, walked up
 * from its parent. */
static void tile_path(const loader *l, uint32_t doc, uint32_t parent, int32_t index, char *out,
                      size_t size) {
    int32_t chain[64];
    int n = 0, truncated = 0;
    size_t len;
    if (index >= 0)
        chain[n++] = index;
    while (index >= 0 && parent != TILE_NONE && l->tile_doc[parent] == doc &&
           l->tile_index[parent] >= 0) {
        if (n == 64) {
            truncated = 1;
            break;
        }
        chain[n++] = l->tile_index[parent];
        parent = l->tiles[parent].parent;
    }
    snprintf(out, size, "%s", truncated ? "root..." : "root");
    while (n > 0) {
        len = strlen(out);
        if (len + 1 >= size)
            break;
        snprintf(out + len, size - len, ".children[%ld]", (long)chain[--n]);
    }
}

/* A message about the tile of entry p: "FILE: tile PATH: WHAT". */
static void fail_tile(loader *l, const pending *p, const char *fmt, ...) {
    char where[256], what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof(what), fmt, ap);
    va_end(ap);
    tile_path(l, p->doc, p->parent, p->index, where, sizeof(where));
    fail(l, "%s: tile %s: %s", l->docs[p->doc].path, where, what);
}

/* ---- small helpers ------------------------------------------------------------- */

static char *copy_string(const char *s, size_t n) {
    char *c = (char *)malloc(n + 1);
    if (c) {
        memcpy(c, s, n);
        c[n] = '\0';
    }
    return c;
}

/* ASCII case-insensitive equality (3D Tiles' keywords are ASCII). */
static int same_word(const char *a, const char *b) {
    for (; *a && *b; ++a, ++b) {
        char x = *a >= 'a' && *a <= 'z' ? (char)(*a - 32) : *a;
        char y = *b >= 'a' && *b <= 'z' ? (char)(*b - 32) : *b;
        if (x != y)
            return 0;
    }
    return *a == *b;
}

/* The n numbers of a JSON array of exactly n finite numbers into out; 0 if the
 * item is anything else. */
static int read_numbers(const cJSON *item, double *out, int n) {
    const cJSON *e;
    int i = 0;
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n)
        return 0;
    cJSON_ArrayForEach(e, item) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return 0;
        out[i++] = e->valuedouble;
    }
    return 1;
}

static int all_finite(const double *v, int n) {
    int i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Reads a whole file, NUL-terminated. NULL with errno set on failure. */
static char *read_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;
    int saved;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0)
        goto fail;
    if (n > MAX_FILE_BYTES) {
        errno = EFBIG;
        goto fail;
    }
    buf = (char *)malloc((size_t)n + 1);
    if (!buf)
        goto fail;
    if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
        errno = EIO;
        goto fail;
    }
    buf[n] = '\0';
    fclose(f);
    *size = (size_t)n;
    return buf;
fail:
    saved = errno;
    free(buf);
    fclose(f);
    errno = saved ? saved : EIO;
    return NULL;
}

/* Whether a uri names a file relative to (or absolute on) the local disk: no
 * scheme such as http:// and no data: uri. */
static int uri_is_local(const char *uri) {
    const char *c;
    if (strncmp(uri, "data:", 5) == 0)
        return 0;
    for (c = uri; *c && *c != '/' && *c != '?' && *c != '#'; ++c)
        if (c[0] == ':' && c[1] == '/' && c[2] == '/')
            return 0;
    return 1;
}

static int hex_digit(char c) {
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* The file a local uri names: dir + the uri without query or fragment, with its
 * %XX escapes decoded (absolute uris keep no dir). Malloc'd; NULL when out of
 * memory. */
static char *uri_file(const char *dir, const char *uri) {
    size_t dl = uri[0] == '/' ? 0 : strlen(dir), ul = strcspn(uri, "?#"), i, o;
    char *p = (char *)malloc(dl + ul + 1);
    if (!p)
        return NULL;
    memcpy(p, dir, dl);
    for (i = 0, o = dl; i < ul; ++i) {
        int hi, lo;
        if (uri[i] == '%' && i + 2 < ul && (hi = hex_digit(uri[i + 1])) >= 0 &&
            (lo = hex_digit(uri[i + 2])) >= 0 && (hi | lo) != 0) {
            p[o++] = (char)(hi * 16 + lo);
            i += 2;
        } else {
            p[o++] = uri[i];
        }
    }
    p[o] = '\0';
    return p;
}

/* Whether the path part of a uri ends in ".json" (any case): an external
 * tileset. */
static int uri_is_tileset(const char *uri) {
    size_t n = strcspn(uri, "?#"), i;
    const char *suffix = ".json";
    if (n < 5)
        return 0;
    for (i = 0; i < 5; ++i) {
        char c = uri[n - 5 + i];
        if ((c >= 'A' && c <= 'Z' ? (char)(c + 32) : c) != suffix[i])
            return 0;
    }
    return 1;
}

/* ---- the sizes file ------------------------------------------------------------ */

static int compare_entries(const void *a, const void *b) {
    return strcmp(((const size_entry *)a)->uri, ((const size_entry *)b)->uri);
}

int size_table_load(const char *path, size_table *t, char *err, size_t err_size) {
    size_t size, capacity = 1, n = 0, i;
    unsigned long line_no = 0;
    char *text = read_file(path, &size), *line;
    size_entry *entries;
    if (!text) {
        snprintf(err, err_size, "%s: cannot read: %s", path, strerror(errno));
        return 1;
    }
    for (i = 0; i < size; ++i)
        capacity += text[i] == '\n';
    entries = (size_entry *)malloc(capacity * sizeof(*entries));
    if (!entries) {
        free(text);
        snprintf(err, err_size, "%s: out of memory", path);
        return 1;
    }
    for (line = text; line && line < text + size;) {
        char *next = strchr(line, '\n'), *tab, *end;
        size_t len;
        double bytes;
        if (next)
            *next++ = '\0';
        ++line_no;
        len = strlen(line);
        if (len > 0 && line[len - 1] == '\r')
            line[--len] = '\0';
        if (len > 0 && line[0] != '#') {
            tab = strchr(line, '\t');
            if (!tab || tab == line) {
                snprintf(err, err_size, "%s: line %lu: expected uri<TAB>bytes", path, line_no);
                goto fail;
            }
            *tab = '\0';
            errno = 0;
            bytes = strtod(tab + 1, &end);
            if (end == tab + 1 || *end != '\0' || errno != 0 || !isfinite(bytes) || bytes < 0.0) {
                snprintf(err, err_size, "%s: line %lu: bytes must be a number >= 0, got '%s'", path,
                         line_no, tab + 1);
                goto fail;
            }
            entries[n].uri = line;
            entries[n].bytes = bytes;
            ++n;
        }
        line = next;
    }
    qsort(entries, n, sizeof(*entries), compare_entries);
    for (i = 1; i < n; ++i) {
        if (strcmp(entries[i - 1].uri, entries[i].uri) == 0) {
            snprintf(err, err_size, "%s: uri '%s' is given twice", path, entries[i].uri);
            goto fail;
        }
    }
    t->entries = entries;
    t->count = n;
    t->text = text;
    return 0;
fail:
    free(entries);
    free(text);
    return 1;
}

void size_table_free(size_table *t) {
    free(t->entries);
    free(t->text);
    memset(t, 0, sizeof(*t));
}

static const size_entry *size_lookup(const size_table *t, const char *uri) {
    size_entry key;
    if (!t || t->count == 0)
        return NULL;
    key.uri = uri;
    key.bytes = 0.0;
    return (const size_entry *)bsearch(&key, t->entries, t->count, sizeof(key), compare_entries);
}

/* ---- documents ----------------------------------------------------------------- */

/* "a.json -> b.json -> c.json": the chain of documents from the main one down
 * to doc, then next. */
static void document_chain(const loader *l, uint32_t doc, const char *next, char *out,
                           size_t size) {
    uint32_t chain[TILESET_MAX_EXTERNAL_DEPTH + 1];
    int n = 0;
    size_t len;
    for (; doc != DOC_NONE && n < TILESET_MAX_EXTERNAL_DEPTH + 1; doc = l->docs[doc].parent)
        chain[n++] = doc;
    out[0] = '\0';
    while (n > 0) {
        len = strlen(out);
        snprintf(out + len, size - len, "%s -> ", l->docs[chain[--n]].path);
    }
    len = strlen(out);
    snprintf(out + len, size - len, "%s", next);
}

/* Parses the tileset file at path, named by tile entry `via` (NULL for the main
 * file), into a new document. 0 on success with its index in *out. */
static int load_document(loader *l, const char *path, const pending *via, uint32_t *out) {
    struct stat st;
    const char *end = NULL;
    char *text, *dir;
    const char *slash;
    size_t size;
    cJSON *json;
    const cJSON *asset, *version;
    uint32_t d, parent = via ? via->doc : DOC_NONE;
    document *doc;

    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) {
        const char *why = errno ? strerror(errno) : "not a regular file";
        if (via)
            fail_tile(l, via, "cannot open external tileset %s: %s", path, why);
        else
            fail(l, "%s: cannot open: %s", path, why);
        return 1;
    }
    if (via) {
        for (d = parent; d != DOC_NONE; d = l->docs[d].parent) {
            if (l->docs[d].dev == st.st_dev && l->docs[d].ino == st.st_ino) {
                char chain[1024];
                document_chain(l, parent, path, chain, sizeof(chain));
                fail_tile(l, via, "external tilesets form a cycle: %s", chain);
                return 1;
            }
        }
        if (l->docs[parent].depth + 1 > TILESET_MAX_EXTERNAL_DEPTH) {
            fail_tile(l, via, "external tilesets nest deeper than %d levels at %s",
                      TILESET_MAX_EXTERNAL_DEPTH, path);
            return 1;
        }
    }
    errno = 0;
    text = read_file(path, &size);
    if (!text) {
        fail(l, "%s: cannot read: %s", path, strerror(errno));
        return 1;
    }
    json = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (!json) {
        /* cJSON points at where it gave up: turn that into a line and column */
        size_t at = end && end >= text && end <= text + size ? (size_t)(end - text) : 0, i;
        unsigned long line = 1, column = 1;
        for (i = 0; i < at; ++i) {
            if (text[i] == '\n') {
                ++line;
                column = 1;
            } else {
                ++column;
            }
        }
        fail(l, "%s: malformed JSON near line %lu, column %lu", path, line, column);
        free(text);
        return 1;
    }
    free(text);
    asset = cJSON_GetObjectItemCaseSensitive(json, "asset");
    version = cJSON_GetObjectItemCaseSensitive(asset, "version");
    if (!cJSON_IsObject(json)) {
        fail(l, "%s: not a tileset: the top level is not a JSON object", path);
    } else if (!cJSON_IsObject(asset)) {
        fail(l, "%s: no \"asset\" object", path);
    } else if (!cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(json, "root"))) {
        fail(l, "%s: no \"root\" tile object", path);
    } else {
        goto parsed;
    }
    cJSON_Delete(json);
    return 1;
parsed:
    /* CesiumJS refuses versions other than these three, cesium-native reads
     * any: a version says nothing this reader needs */
    if (!version)
        ++l->counts.missing_versions;
    else if (!cJSON_IsString(version) ||
             (strcmp(version->valuestring, "0.0") != 0 &&
              strcmp(version->valuestring, "1.0") != 0 && strcmp(version->valuestring, "1.1") != 0))
        ++l->counts.other_versions;
    if (l->doc_count == l->doc_cap) {
        uint32_t cap = l->doc_cap ? 2 * l->doc_cap : 4;
        document *docs = (document *)realloc(l->docs, cap * sizeof(*docs));
        if (!docs)
            goto nomem;
        l->docs = docs;
        l->doc_cap = cap;
    }
    slash = strrchr(path, '/');
    dir = copy_string(path, slash ? (size_t)(slash - path) + 1 : 0);
    doc = &l->docs[l->doc_count];
    doc->path = copy_string(path, strlen(path));
    doc->dir = dir;
    if (!doc->path || !dir) {
        free(doc->path);
        free(dir);
        goto nomem;
    }
    doc->dev = st.st_dev;
    doc->ino = st.st_ino;
    doc->json = json;
    doc->parent = parent;
    doc->depth = parent == DOC_NONE ? 0 : l->docs[parent].depth + 1;
    *out = l->doc_count++;
    return 0;
nomem:
    cJSON_Delete(json);
    fail(l, "%s: out of memory", path);
    return 1;
}

/* ---- tiles --------------------------------------------------------------------- */

/* Grows a list to hold n more. */
static int reserve(loader *l, void **list, size_t *cap, size_t used, size_t more, size_t elem) {
    void *p;
    size_t c = *cap ? *cap : 64;
    if (used + more <= *cap)
        return 0;
    while (c < used + more)
        c *= 2;
    p = realloc(*list, c * elem);
    if (!p) {
        fail(l, "out of memory");
        return 1;
    }
    *list = p;
    *cap = c;
    return 0;
}

static int push(loader *l, const pending *p) {
    if (reserve(l, (void **)&l->stack, &l->stack_cap, l->top, 1, sizeof(*l->stack)))
        return 1;
    l->stack[l->top++] = *p;
    return 0;
}

/* The smallest sphere around the box's corners about its centre: what a box
 * libtclod cannot take (axes not orthogonal) becomes. */
static tclod_bounds box_sphere(const double c[3], const double a[9]) {
    double r2 = 0.0;
    int s1, s2, i;
    for (s1 = -1; s1 <= 1; s1 += 2) {
        for (s2 = -1; s2 <= 1; s2 += 2) {
            double d2 = 0.0;
            for (i = 0; i < 3; ++i) {
                double v = a[i] + s1 * a[3 + i] + s2 * a[6 + i];
                d2 += v * v;
            }
            r2 = d2 > r2 ? d2 : r2;
        }
    }
    return tclod_bounds_sphere(c[0], c[1], c[2], sqrt(r2));
}

/* An oriented box into *out, or the sphere around it when libtclod cannot
 * take it (axes not orthogonal), counted. 1 when neither is valid (a box so
 * large that its sphere overflows). */
static int oriented_box(loader *l, const double c[3], const double a[9], tclod_bounds *out) {
    *out = tclod_bounds_obb(c, a);
    if (tclod_bounds_validate(out) == TCLOD_OK)
        return 0;
    *out = box_sphere(c, a);
    if (tclod_bounds_validate(out) != TCLOD_OK)
        return 1;
    ++l->counts.box_fallbacks;
    return 0;
}

/* A box as 3D Tiles writes it (v: centre, then the x, y and z half axes) under
 * the transform m: the centre as a point, the half axes as directions. 1 when
 * it overflows. */
static int box_volume(loader *l, const double v[12], const double m[16], tclod_bounds *out) {
    double c[3], a[9];
    int i;
    geo_mat4_point(m, v, c);
    for (i = 0; i < 3; ++i)
        geo_mat4_vector(m, v + 3 + 3 * i, a + 3 * i);
    return !all_finite(c, 3) || !all_finite(a, 9) || oriented_box(l, c, a, out);
}

/* A valid region (geo_region_valid) as its oriented box. 1 when it overflows
 * (only heights near the largest double can). */
static int region_volume(loader *l, const double v[6], tclod_bounds *out) {
    double c[3], a[9];
    geo_region_box(v, c, a);
    return !all_finite(c, 3) || !all_finite(a, 9) || oriented_box(l, c, a, out);
}

/* The kinds of bounding volume, as written. */
enum { VOLUME_BOX = 1, VOLUME_REGION, VOLUME_SPHERE };

/* A bounding volume ("boundingVolume" of a tile or a content, `name` in
 * messages) in world coordinates; region[] gets a region as written. A box
 * goes through the composed transform whole (centre as a point, half axes as
 * directions); a sphere's radius grows by the transform's largest scale
 * (CesiumJS does the same); a region is in earth-centred coordinates already
 * and ignores the transform (3D Tiles 1.1, "Bounding volumes"). Where a volume
 * has several kinds the box wins, then the region, as in CesiumJS. Returns
 * the kind, or 0 after a message. */
static int read_bounds(loader *l, const pending *p, const cJSON *bv, const char *name,
                       const double m[16], tclod_bounds *out, double region[6]) {
    const cJSON *box = cJSON_GetObjectItemCaseSensitive(bv, "box");
    const cJSON *reg = cJSON_GetObjectItemCaseSensitive(bv, "region");
    const cJSON *sphere = cJSON_GetObjectItemCaseSensitive(bv, "sphere");
    double v[12], c[3];
    if (!cJSON_IsObject(bv)) {
        fail_tile(l, p, "no \"%s\" object", name);
        return 0;
    }
    if (box) {
        if (!read_numbers(box, v, 12)) {
            fail_tile(l, p,
                      "%s.box needs 12 finite numbers (centre, then the x, y and z half axes)",
                      name);
            return 0;
        }
        if (box_volume(l, v, m, out)) {
            fail_tile(l, p, "%s.box overflows (under the tile's transform)", name);
            return 0;
        }
        return VOLUME_BOX;
    }
    if (reg) {
        if (!read_numbers(reg, v, 6)) {
            fail_tile(l, p,
                      "%s.region needs 6 finite numbers (west, south, east, north in radians, "
                      "minimum and maximum height in m)",
                      name);
            return 0;
        }
        if (!geo_region_valid(v)) {
            fail_tile(l, p,
                      "%s.region is out of range (west and east in [-pi, pi], south <= north "
                      "in [-pi/2, pi/2], minimum height <= maximum height)",
                      name);
            return 0;
        }
        if (region_volume(l, v, out)) {
            fail_tile(l, p, "%s.region's heights overflow its box", name);
            return 0;
        }
        memcpy(region, v, 6 * sizeof(double));
        return VOLUME_REGION;
    }
    if (sphere) {
        if (!read_numbers(sphere, v, 4) || v[3] < 0.0) {
            fail_tile(l, p, "%s.sphere needs 4 finite numbers (centre, then a radius >= 0)", name);
            return 0;
        }
        geo_mat4_point(m, v, c);
        *out = tclod_bounds_sphere(c[0], c[1], c[2], v[3] * geo_mat4_max_scale(m));
        if (!all_finite(c, 3) || !isfinite(out->radius) || tclod_bounds_validate(out) != TCLOD_OK) {
            fail_tile(l, p, "%s.sphere overflows under the tile's transform", name);
            return 0;
        }
        return VOLUME_SPHERE;
    }
    fail_tile(l, p, "%s has no box, region or sphere", name);
    return 0;
}

/* The sizes file's key of a local uri named in document doc: its file's path
 * relative to the main document's directory, "." and ".." segments resolved
 * (a path that climbs out of that directory keeps its ".."). Malloc'd; NULL
 * when out of memory. */
static char *size_key(const loader *l, uint32_t doc, const char *uri) {
    const char *base = l->docs[0].dir, *dir = l->docs[doc].dir;
    size_t bl = strlen(base), i = 0, o = 0;
    char *path, *key;
    if (uri[0] == '/' || strncmp(dir, base, bl) != 0)
        return uri_file("", uri);
    path = uri_file(dir + bl, uri);
    key = path ? (char *)malloc(strlen(path) + 1) : NULL;
    if (!key) {
        free(path);
        return NULL;
    }
    while (path[i]) {
        size_t n = strcspn(path + i, "/");
        if (n == 1 && path[i] == '.') {
            /* "./": nothing */
        } else if (n == 2 && path[i] == '.' && path[i + 1] == '.' && o > 0 &&
                   !(o >= 3 && memcmp(key + o - 3, "../", 3) == 0 &&
                     (o == 3 || key[o - 4] == '/'))) {
            /* "..": drop the segment before it */
            o -= 1;
            while (o > 0 && key[o - 1] != '/')
                --o;
        } else {
            memcpy(key + o, path + i, n);
            o += n;
            if (path[i + n] == '/')
                key[o++] = '/';
        }
        i += n + (path[i + n] == '/');
    }
    key[o] = '\0';
    free(path);
    return key;
}

/* Bytes of one content: the file beside the tileset, else the sizes file (by
 * the path relative to the main tileset, else the uri as written), else the
 * estimate. */
static double content_bytes(loader *l, const pending *p, const char *uri) {
    const size_entry *e = NULL;
    ++l->counts.contents;
    if (uri_is_local(uri)) {
        char *file = uri_file(l->docs[p->doc].dir, uri), *key;
        struct stat st;
        int found = file && stat(file, &st) == 0 && S_ISREG(st.st_mode);
        free(file);
        if (found) {
            ++l->counts.from_file;
            return (double)st.st_size;
        }
        if (l->sizes && l->sizes->count > 0 && (key = size_key(l, p->doc, uri)) != NULL) {
            e = size_lookup(l->sizes, key);
            free(key);
        }
    }
    if (!e)
        e = size_lookup(l->sizes, uri);
    if (e) {
        ++l->counts.from_sizes;
        return e->bytes;
    }
    ++l->counts.estimated;
    return TILESET_ESTIMATE_BYTES;
}

/* A tile's content ("content" with "uri", or "url" before 1.0) or contents
 * (1.1): their bytes summed into *bytes, *has_content set when one of them is
 * drawn, and *external set to the uri of an external tileset. A content's own
 * bounding volume is checked under the tile's transform (world). */
static int read_contents(loader *l, const pending *p, const cJSON *j, const double world[16],
                         double *bytes, int *has_content, const char **external) {
    const cJSON *contents = cJSON_GetObjectItemCaseSensitive(j, "contents");
    const cJSON *content = cJSON_GetObjectItemCaseSensitive(j, "content");
    const cJSON *c;
    int n;
    *bytes = 0.0;
    *has_content = 0;
    *external = NULL;
    if (contents) {
        if (!cJSON_IsArray(contents)) {
            fail_tile(l, p, "contents is not an array");
            return 1;
        }
        n = cJSON_GetArraySize(contents);
        c = contents->child;
    } else if (content) {
        n = 1;
        c = content;
    } else {
        return 0;
    }
    for (; n > 0 && c; c = contents ? c->next : NULL) {
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(c, "uri");
        const cJSON *url = cJSON_GetObjectItemCaseSensitive(c, "url");
        const cJSON *bv = cJSON_GetObjectItemCaseSensitive(c, "boundingVolume");
        tclod_bounds unused;
        double region[6];
        if (!cJSON_IsObject(c)) {
            fail_tile(l, p, "a content is not a JSON object");
            return 1;
        }
        if (!(cJSON_IsString(uri) && uri->valuestring[0] != '\0') && cJSON_IsString(url)) {
            uri = url; /* the name before 3D Tiles 1.0, which both Cesiums read */
            ++l->counts.content_urls;
        }
        if (!cJSON_IsString(uri)) {
            fail_tile(l, p, "a content has no \"uri\" string");
            return 1;
        }
        if (bv) { /* CesiumJS culls drawing with it, not refinement: checked only */
            if (!read_bounds(l, p, bv, "content.boundingVolume", world, &unused, region))
                return 1;
            ++l->counts.content_volumes;
        }
        if (uri->valuestring[0] == '\0') { /* CesiumJS: no content */
            ++l->counts.empty_uris;
            continue;
        }
        if (uri_is_tileset(uri->valuestring)) {
            if (n > 1) {
                fail_tile(l, p, "external tileset %s is one of several contents", uri->valuestring);
                return 1;
            }
            *external = uri->valuestring;
        } else {
            *bytes += content_bytes(l, p, uri->valuestring);
            *has_content = 1;
        }
    }
    return 0;
}

/* Appends a tile to the arrays, and counts it. */
static int add_tile(loader *l, const pending *p, const tile *t) {
    if (l->count == l->tile_cap) {
        uint32_t cap = l->tile_cap ? 2 * l->tile_cap : 256;
        tile *tiles = (tile *)realloc(l->tiles, cap * sizeof(*tiles));
        uint32_t *docs, *files;
        int32_t *index;
        if (tiles)
            l->tiles = tiles;
        docs = tiles ? (uint32_t *)realloc(l->tile_doc, cap * sizeof(*docs)) : NULL;
        if (docs)
            l->tile_doc = docs;
        index = docs ? (int32_t *)realloc(l->tile_index, cap * sizeof(*index)) : NULL;
        if (index)
            l->tile_index = index;
        files = index ? (uint32_t *)realloc(l->tile_file, cap * sizeof(*files)) : NULL;
        if (!files) {
            fail(l, "out of memory");
            return 1;
        }
        l->tile_file = files;
        l->tile_cap = cap;
    }
    l->tiles[l->count] = *t;
    l->counts.empty += (uint32_t)t->empty;
    l->counts.additive += t->refine == TCLOD_REFINE_ADD;
    l->counts.bytes += t->bytes;
    l->tile_doc[l->count] = p->doc;
    l->tile_index[l->count] = p->index;
    l->tile_file[l->count] = TILE_NONE;
    ++l->count;
    return 0;
}

/* Makes tile t stand for the file at path (taken over), which tileset_expand
 * reads: an external tileset (implicit DOC_NONE; via, the linking tile's
 * entry, and root, what its root inherits) or the implicit subtree of
 * implicits[implicit] whose root is t, at (level, xyz). */
static int link_file(loader *l, uint32_t t, uint32_t implicit, const pending *via,
                     const pending *root, uint32_t level, const uint32_t xyz[3], char *path) {
    struct stat st;
    file_link *f;
    if (l->file_count == l->file_cap) {
        uint32_t cap = l->file_cap ? 2 * l->file_cap : 16;
        file_link *files = (file_link *)realloc(l->files, cap * sizeof(*files));
        if (!files) {
            free(path);
            fail(l, "out of memory");
            return 1;
        }
        l->files = files;
        l->file_cap = cap;
    }
    f = &l->files[l->file_count];
    memset(f, 0, sizeof(*f));
    f->tile = t;
    f->implicit = implicit;
    if (via)
        f->via = *via;
    if (root)
        f->root = *root;
    f->level = level;
    if (xyz)
        memcpy(f->xyz, xyz, sizeof(f->xyz));
    f->path = path;
    l->tile_file[t] = l->file_count++;
    l->tiles[t].unexpanded = 1;
    /* its size, for the host's request; a file missing now fails when read */
    l->tiles[t].file_bytes = stat(path, &st) == 0 && S_ISREG(st.st_mode) ? (double)st.st_size : 0.0;
    ++l->counts.unexpanded;
    return 0;
}

/* ---- implicit tiling ------------------------------------------------------------ */

/* An implicit root tile (3D Tiles 1.1, "Implicit Tiling") stands for a quadtree
 * or octree of tiles that the tileset does not list: which exist, and which
 * have content, is said by subtree files, each covering subtreeLevels levels
 * and naming the subtrees below its deepest level. Every tile is read here, at
 * load time, into the flat array like an explicit one: its volume the root's
 * cut in halves along x and y (and z for an octree) level by level, its
 * geometric error the root's halved as often, its refinement the root's. */

/* Deepest level read: a tile's x, y and z stay within 31 bits. */
#define IMPLICIT_MAX_LEVELS 32
/* Most levels a subtree covers: its bitstreams' indices stay within 64 bits. */
#define IMPLICIT_MAX_SUBTREE_LEVELS_QUADTREE 31
#define IMPLICIT_MAX_SUBTREE_LEVELS_OCTREE 21
/* Contents of one implicit root (1.1's "contents"): far above real layers. */
#define IMPLICIT_MAX_CONTENTS 16
#define IMPLICIT_URI_SIZE 1024

/* One kind of availability of a subtree: every bit `constant`, or a bitstream
 * (3D Tiles' booleans: bit i is bit i % 8 of byte i / 8). */
typedef struct availability {
    const uint8_t *bits; /* NULL: constant */
    int constant;
} availability;

static int available(const availability *a, uint64_t i) {
    return a->bits ? (a->bits[i >> 3] >> (i & 7)) & 1 : a->constant;
}

/* A subtree file, read: its JSON, its binary chunk and the external buffers
 * its bitstreams are in. */
typedef struct subtree {
    const char *path;
    char *dir;
    char *file;
    cJSON *json;
    const uint8_t *chunk; /* NULL: no binary chunk */
    uint64_t chunk_size;
    char **buffers; /* per buffer: an external one's bytes, once read */
    size_t *buffer_size;
    int buffer_count;
    availability tiles, contents[IMPLICIT_MAX_CONTENTS], children;
} subtree;

/* What an implicit root gives the tiles below it. */
typedef struct implicit {
    pending root;       /* the implicit root's entry: its document, for uris and messages */
    uint32_t root_tile; /* its tile */
    int octree;         /* 8 children a tile, else 4 */
    uint32_t subtree_levels, available_levels;
    const char *subtree_uri;
    const char *content_uri[IMPLICIT_MAX_CONTENTS];
    int content_count;
    int region;        /* volume: a region (6 numbers), else a box (12) */
    double volume[12]; /* as written, in the root's frame */
    double transform[16];
    double geometric_error;
    tclod_refine refine;
} implicit;

/* A subtree waiting to be read, and a tile of a subtree's level. */
typedef struct subtree_root {
    uint32_t level, xyz[3];
    uint32_t parent; /* its root's parent tile */
    uint32_t tile;   /* the tile its root is already (the implicit root, an unexpanded
                        tile), or TILE_NONE */
} subtree_root;
typedef struct level_tile {
    uint64_t morton; /* within the subtree's level */
    uint32_t tile;
} level_tile;

/* tmpl with {level}, {x}, {y} and {z} replaced by the tile's coordinates, into
 * out. 1 when it does not fit. */
static int expand_template(const char *tmpl, uint32_t level, const uint32_t xyz[3], char *out,
                           size_t size) {
    static const char *const names[4] = {"{level}", "{x}", "{y}", "{z}"};
    size_t o = 0;
    while (*tmpl) {
        int k, used = 0;
        for (k = 0; k < 4; ++k) {
            size_t n = strlen(names[k]);
            if (strncmp(tmpl, names[k], n) == 0) {
                int w = snprintf(out + o, size - o, "%lu",
                                 (unsigned long)(k == 0 ? level : xyz[k - 1]));
                if (w < 0 || (size_t)w >= size - o)
                    return 1;
                o += (size_t)w;
                tmpl += n;
                used = 1;
                break;
            }
        }
        if (!used) {
            if (o + 1 >= size)
                return 1;
            out[o++] = *tmpl++;
        }
    }
    out[o] = '\0';
    return 0;
}

/* A tile's x, y (and z) within its level from its Morton index there: the
 * index's bits taken in turn (x lowest, as 3D Tiles interleaves them). */
static void morton_decode(uint64_t m, uint32_t levels, int octree, uint32_t xyz[3]) {
    uint32_t k, d = octree ? 3u : 2u, i;
    xyz[0] = xyz[1] = xyz[2] = 0;
    for (k = 0; k < levels; ++k)
        for (i = 0; i < d; ++i)
            xyz[i] |= (uint32_t)((m >> (d * k + i)) & 1u) << k;
}

/* A JSON integer in [0, max] into *out; 0 if the item is anything else. */
static int read_count(const cJSON *item, double max, uint64_t *out) {
    double v;
    if (!cJSON_IsNumber(item))
        return 0;
    v = item->valuedouble;
    if (!(v >= 0.0 && v <= max) || v != floor(v))
        return 0;
    *out = (uint64_t)v;
    return 1;
}

static uint64_t u64_le(const unsigned char *b) {
    uint64_t v = 0;
    int i;
    for (i = 7; i >= 0; --i)
        v = v << 8 | b[i];
    return v;
}

/* The bytes of bitstream `view` of subtree s, at least `bits` bits long, into
 * *out. 0 on success. */
static int subtree_bitstream(loader *l, subtree *s, uint64_t view, uint64_t bits, const char *what,
                             const uint8_t **out) {
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(s->json, "bufferViews");
    const cJSON *buffers = cJSON_GetObjectItemCaseSensitive(s->json, "buffers");
    const cJSON *v, *b, *uri;
    uint64_t buffer, offset = 0, length, buffer_length;
    const uint8_t *data;
    if (!cJSON_IsArray(views) || view >= (uint64_t)cJSON_GetArraySize(views)) {
        fail(l, "%s: %s names bufferViews[%lu], which does not exist", s->path, what,
             (unsigned long)view);
        return 1;
    }
    v = cJSON_GetArrayItem(views, (int)view);
    if (!read_count(cJSON_GetObjectItemCaseSensitive(v, "buffer"), 2147483647.0, &buffer) ||
        !read_count(cJSON_GetObjectItemCaseSensitive(v, "byteLength"), 9007199254740992.0,
                    &length) ||
        (cJSON_GetObjectItemCaseSensitive(v, "byteOffset") &&
         !read_count(cJSON_GetObjectItemCaseSensitive(v, "byteOffset"), 9007199254740992.0,
                     &offset))) {
        fail(l,
             "%s: bufferViews[%lu] needs a \"buffer\" index and a \"byteLength\" (and any "
             "\"byteOffset\") that are integers >= 0",
             s->path, (unsigned long)view);
        return 1;
    }
    if (!cJSON_IsArray(buffers) || buffer >= (uint64_t)cJSON_GetArraySize(buffers)) {
        fail(l, "%s: bufferViews[%lu] names buffers[%lu], which does not exist", s->path,
             (unsigned long)view, (unsigned long)buffer);
        return 1;
    }
    b = cJSON_GetArrayItem(buffers, (int)buffer);
    if (!read_count(cJSON_GetObjectItemCaseSensitive(b, "byteLength"), 9007199254740992.0,
                    &buffer_length)) {
        fail(l, "%s: buffers[%lu] needs a \"byteLength\" that is an integer >= 0", s->path,
             (unsigned long)buffer);
        return 1;
    }
    uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
    if (!uri) {
        if (!s->chunk || buffer_length > s->chunk_size) {
            fail(l, "%s: buffers[%lu] has no uri and the file's binary chunk %s", s->path,
                 (unsigned long)buffer, s->chunk ? "is shorter than its byteLength" : "is empty");
            return 1;
        }
        data = s->chunk;
    } else {
        if (!cJSON_IsString(uri) || !uri_is_local(uri->valuestring)) {
            fail(l, "%s: buffers[%lu]: uri is not a local file", s->path, (unsigned long)buffer);
            return 1;
        }
        if (!s->buffers) {
            s->buffer_count = cJSON_GetArraySize(buffers);
            s->buffers = (char **)calloc((size_t)s->buffer_count, sizeof(*s->buffers));
            s->buffer_size = (size_t *)calloc((size_t)s->buffer_count, sizeof(*s->buffer_size));
            if (!s->buffers || !s->buffer_size) {
                fail(l, "out of memory");
                return 1;
            }
        }
        if (!s->buffers[buffer]) {
            char *path = uri_file(s->dir, uri->valuestring);
            if (!path) {
                fail(l, "out of memory");
                return 1;
            }
            errno = 0;
            s->buffers[buffer] = read_file(path, &s->buffer_size[buffer]);
            if (!s->buffers[buffer]) {
                fail(l, "%s: buffers[%lu]: cannot read %s: %s", s->path, (unsigned long)buffer,
                     path, strerror(errno));
                free(path);
                return 1;
            }
            free(path);
        }
        if (s->buffer_size[buffer] < buffer_length) {
            fail(l, "%s: buffers[%lu]: %s holds fewer bytes than its byteLength", s->path,
                 (unsigned long)buffer, uri->valuestring);
            return 1;
        }
        data = (const uint8_t *)s->buffers[buffer];
    }
    if (offset > buffer_length || length > buffer_length - offset) {
        fail(l, "%s: bufferViews[%lu] reaches past the end of buffers[%lu]", s->path,
             (unsigned long)view, (unsigned long)buffer);
        return 1;
    }
    if (length < bits / 8 + (bits % 8 != 0)) {
        fail(l, "%s: %s needs %llu bits, and bufferViews[%lu] holds %llu", s->path, what,
             (unsigned long long)bits, (unsigned long)view, (unsigned long long)length * 8);
        return 1;
    }
    *out = data + offset;
    return 0;
}

/* One availability object of subtree s ("constant" 0 or 1, or a "bitstream":
 * a buffer view of at least `bits` bits) into *a. */
static int subtree_availability(loader *l, subtree *s, const cJSON *item, uint64_t bits,
                                const char *what, availability *a) {
    const cJSON *constant = cJSON_GetObjectItemCaseSensitive(item, "constant");
    const cJSON *stream = cJSON_GetObjectItemCaseSensitive(item, "bitstream");
    uint64_t v;
    if (!stream) /* the name before 3D Tiles 1.1 */
        stream = cJSON_GetObjectItemCaseSensitive(item, "bufferView");
    a->bits = NULL;
    a->constant = 0;
    if (stream) {
        if (!read_count(stream, 2147483647.0, &v)) {
            fail(l, "%s: %s.bitstream must be a buffer view's index", s->path, what);
            return 1;
        }
        return subtree_bitstream(l, s, v, bits, what, &a->bits);
    }
    if (!read_count(constant, 1.0, &v)) {
        fail(l, "%s: %s needs a \"bitstream\", or a \"constant\" of 0 or 1", s->path, what);
        return 1;
    }
    a->constant = (int)v;
    return 0;
}

static void subtree_free(subtree *s) {
    int i;
    for (i = 0; i < s->buffer_count; ++i)
        free(s->buffers[i]);
    free(s->buffers);
    free(s->buffer_size);
    cJSON_Delete(s->json);
    free(s->file);
    free(s->dir);
    memset(s, 0, sizeof(*s));
}

/* Reads the subtree file at path (binary, "subt", or JSON) and its
 * availability. 0 on success; s is to be freed either way. */
static int subtree_read(loader *l, const implicit *im, const char *path, subtree *s) {
    const unsigned char *head;
    const cJSON *item;
    const char *slash = strrchr(path, '/');
    uint64_t n = im->octree ? 8 : 4, per_level = 1, tiles = 0;
    size_t size;
    uint32_t k;
    int c;
    memset(s, 0, sizeof(*s));
    s->path = path;
    s->dir = copy_string(path, slash ? (size_t)(slash - path) + 1 : 0);
    errno = 0;
    s->file = s->dir ? read_file(path, &size) : NULL;
    if (!s->file) {
        fail(l, "%s: cannot read subtree: %s", path, s->dir ? strerror(errno) : "out of memory");
        return 1;
    }
    head = (const unsigned char *)s->file;
    if (size >= 4 && memcmp(head, "subt", 4) == 0) {
        uint64_t json_length, binary_length;
        if (size < 24) {
            fail(l, "%s: a binary subtree's header is 24 bytes; the file has %lu", path,
                 (unsigned long)size);
            return 1;
        }
        json_length = u64_le(head + 8);
        binary_length = u64_le(head + 16);
        if (head[4] != 1 || head[5] || head[6] || head[7]) {
            fail(l, "%s: binary subtree version %lu; only version 1 is read", path,
                 (unsigned long)(head[4] | head[5] << 8 | head[6] << 16 | (uint32_t)head[7] << 24));
            return 1;
        }
        if (json_length > size - 24 || binary_length > size - 24 - json_length) {
            fail(l, "%s: the header's JSON and binary lengths reach past the end of the file",
                 path);
            return 1;
        }
        s->json = cJSON_ParseWithLength(s->file + 24, (size_t)json_length);
        if (binary_length > 0) {
            s->chunk = head + 24 + json_length;
            s->chunk_size = binary_length;
        }
    } else {
        s->json = cJSON_ParseWithLength(s->file, size);
    }
    if (!cJSON_IsObject(s->json)) {
        fail(l, "%s: not a subtree: its JSON is malformed or not an object", path);
        return 1;
    }
    for (k = 0; k < im->subtree_levels; ++k) {
        tiles += per_level;
        per_level *= n;
    }
    if (subtree_availability(l, s, cJSON_GetObjectItemCaseSensitive(s->json, "tileAvailability"),
                             tiles, "tileAvailability", &s->tiles) ||
        subtree_availability(l, s,
                             cJSON_GetObjectItemCaseSensitive(s->json, "childSubtreeAvailability"),
                             per_level, "childSubtreeAvailability", &s->children))
        return 1;
    item = cJSON_GetObjectItemCaseSensitive(s->json, "contentAvailability");
    if (im->content_count > 0 &&
        (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != im->content_count)) {
        fail(
            l,
            "%s: contentAvailability must be an array of %d (one per content of the implicit root)",
            path, im->content_count);
        return 1;
    }
    for (c = 0; c < im->content_count; ++c) {
        char what[48];
        snprintf(what, sizeof(what), "contentAvailability[%d]", c);
        if (subtree_availability(l, s, cJSON_GetArrayItem(item, c), tiles, what, &s->contents[c]))
            return 1;
    }
    if (!available(&s->tiles, 0)) {
        fail(l, "%s: tileAvailability says the subtree's root tile is not available", path);
        return 1;
    }
    return 0;
}

/* The bounding volume of tile (level, xyz) of im: the root's, cut in 2^level
 * slices along each axis the scheme divides, taken from the root's extent
 * directly (3D Tiles 1.1's implementation note: not by halving the parent's). */
static int implicit_bounds(loader *l, const implicit *im, uint32_t level, const uint32_t xyz[3],
                           tclod_bounds *out) {
    double slices = ldexp(1.0, (int)level), v[12];
    int axes = im->octree ? 3 : 2, i;
    if (im->region) {
        /* x: west to east (across the antimeridian when west > east), y: south
         * to north, z: up; the last slice ends on the root's edge exactly */
        double width = im->volume[2] - im->volume[0];
        if (width < 0.0)
            width += 2.0 * GEO_PI;
        memcpy(v, im->volume, 6 * sizeof(double));
        for (i = 0; i < axes; ++i) {
            double lo = im->volume[i == 2 ? 4 : i], hi = im->volume[i == 2 ? 5 : i + 2];
            double size = (i == 0 ? width : hi - lo) / slices;
            v[i == 2 ? 4 : i] = lo + size * xyz[i];
            if (xyz[i] + 1.0 < slices)
                v[i == 2 ? 5 : i + 2] = lo + size * (xyz[i] + 1.0);
        }
        for (i = 0; i <= 2; i += 2)
            if (v[i] > GEO_PI)
                v[i] -= 2.0 * GEO_PI;
        if (region_volume(l, v, out))
            return 1;
        ++l->counts.regions;
        return 0;
    }
    /* a box: the centre moves along each divided half axis, which shrinks */
    memcpy(v, im->volume, 12 * sizeof(double));
    for (i = 0; i < axes; ++i) {
        double t = (2.0 * xyz[i] + 1.0) / slices - 1.0;
        int k;
        for (k = 0; k < 3; ++k) {
            v[k] += t * im->volume[3 + 3 * i + k];
            v[3 + 3 * i + k] = im->volume[3 + 3 * i + k] / slices;
        }
    }
    if (box_volume(l, v, im->transform, out))
        return 1;
    ++l->counts.boxes;
    return 0;
}

/* The contents of tile `bit` of subtree s at (level, xyz): their bytes into
 * *bytes; 1 in *has when one is available. */
static int implicit_contents(loader *l, const implicit *im, const subtree *s, uint64_t bit,
                             uint32_t level, const uint32_t xyz[3], double *bytes, int *has) {
    char uri[IMPLICIT_URI_SIZE];
    int c;
    *bytes = 0.0;
    *has = 0;
    for (c = 0; c < im->content_count; ++c) {
        if (!available(&s->contents[c], bit))
            continue;
        if (expand_template(im->content_uri[c], level, xyz, uri, sizeof(uri))) {
            fail(l, "%s: content uri of tile %lu/%lu/%lu/%lu is longer than %d bytes", s->path,
                 (unsigned long)level, (unsigned long)xyz[0], (unsigned long)xyz[1],
                 (unsigned long)xyz[2], IMPLICIT_URI_SIZE - 1);
            return 1;
        }
        *bytes += content_bytes(l, &im->root, uri);
        *has = 1;
    }
    return 0;
}

/* Appends tile (level, xyz) of im, bit `bit` of subtree s, below parent;
 * without s, the root of a subtree not read (no content yet). */
static int implicit_tile(loader *l, const implicit *im, const subtree *s, uint64_t bit,
                         uint32_t level, const uint32_t xyz[3], uint32_t parent, uint32_t *out) {
    const char *where = s ? s->path : l->docs[im->root.doc].path;
    tile t;
    int has = 0;
    if (l->count >= l->max_tiles) {
        fail(l, "%s: more than %lu tiles", where, (unsigned long)l->max_tiles);
        return 1;
    }
    memset(&t, 0, sizeof(t));
    if (implicit_bounds(l, im, level, xyz, &t.bounds)) {
        fail(l, "%s: tile %lu/%lu/%lu/%lu: its volume overflows", where, (unsigned long)level,
             (unsigned long)xyz[0], (unsigned long)xyz[1], (unsigned long)xyz[2]);
        return 1;
    }
    t.geometric_error = ldexp(im->geometric_error, -(int)level);
    if (s && implicit_contents(l, im, s, bit, level, xyz, &t.bytes, &has))
        return 1;
    t.parent = parent;
    t.refine = im->refine;
    t.empty = !has;
    t.add_anchor = TILE_NONE;
    t.request = TILE_NONE;
    *out = l->count;
    return add_tile(l, &im->root, &t);
}

/* Reads the tiles of subtree r: level by level, each available child of a
 * tile of the level above (a tile whose parent is not available cannot be
 * reached); then queues the child subtrees below its deepest level. */
/* The path of im's subtree at (level, xyz), or NULL after a message. */
static char *subtree_path(loader *l, const implicit *im, uint32_t level, const uint32_t xyz[3]) {
    char uri[IMPLICIT_URI_SIZE];
    char *path;
    if (expand_template(im->subtree_uri, level, xyz, uri, sizeof(uri)) || !uri_is_local(uri)) {
        fail(l, "%s: subtree %lu/%lu/%lu/%lu: its uri is not a local file or is too long",
             l->docs[im->root.doc].path, (unsigned long)level, (unsigned long)xyz[0],
             (unsigned long)xyz[1], (unsigned long)xyz[2]);
        return NULL;
    }
    path = uri_file(l->docs[im->root.doc].dir, uri);
    if (!path)
        fail(l, "out of memory");
    return path;
}

static int implicit_subtree(loader *l, const implicit *im, const subtree_root *r,
                            subtree_root **queue, size_t *queued, size_t *queue_cap,
                            level_tile **rows, size_t *row_cap) {
    char *path;
    subtree s;
    level_tile *row;
    uint64_t n = im->octree ? 8 : 4, offset = 0, width = 1;
    size_t count = 1, c, first;
    uint32_t k, xyz[3], levels = im->subtree_levels;
    int rc = 1;

    path = subtree_path(l, im, r->level, r->xyz);
    if (!path)
        return 1;
    if (subtree_read(l, im, path, &s))
        goto done;
    ++l->counts.subtrees;
    if (reserve(l, (void **)rows, row_cap, 0, 2, sizeof(**rows)))
        goto done;
    row = *rows;
    row[0].morton = 0;
    if (r->tile != TILE_NONE) {
        /* the implicit root, read from the tileset, or an unexpanded tile */
        tile *root = &l->tiles[r->tile];
        int has;
        row[0].tile = r->tile;
        if (implicit_contents(l, im, &s, 0, r->level, r->xyz, &root->bytes, &has))
            goto done;
        root->empty = !has; /* add_tile counted it empty */
        l->counts.empty -= (uint32_t)has;
        l->counts.bytes += root->bytes;
        if (root->unexpanded) {
            root->unexpanded = 0;
            root->file_bytes = 0.0;
            l->tile_file[r->tile] = TILE_NONE;
            --l->counts.unexpanded;
        }
    } else if (implicit_tile(l, im, &s, 0, r->level, r->xyz, r->parent, &row[0].tile)) {
        goto done;
    }
    if (levels > im->available_levels - r->level)
        levels = im->available_levels - r->level;
    /* rows[0 .. count) holds the tiles of local level k, in Morton order; the
     * next level's are appended after them, then moved down */
    for (k = 1; k < levels; ++k) {
        size_t next = 0;
        offset += width;
        width *= n;
        for (c = 0; c < count; ++c) {
            uint64_t child;
            for (child = 0; child < n; ++child) {
                uint64_t m = (*rows)[c].morton * n + child;
                uint32_t parent = (*rows)[c].tile, t;
                if (!available(&s.tiles, offset + m))
                    continue;
                morton_decode(m, k, im->octree, xyz);
                xyz[0] |= r->xyz[0] << k;
                xyz[1] |= r->xyz[1] << k;
                xyz[2] |= r->xyz[2] << k;
                if (implicit_tile(l, im, &s, offset + m, r->level + k, xyz, parent, &t) ||
                    reserve(l, (void **)rows, row_cap, count + next, 1, sizeof(**rows)))
                    goto done;
                (*rows)[count + next].morton = m;
                (*rows)[count + next].tile = t;
                ++next;
            }
        }
        memmove(*rows, *rows + count, next * sizeof(**rows));
        count = next;
    }
    /* the child subtrees, below the deepest level when the tree goes on; on
     * the stack last first, so that they are read in Morton order */
    first = *queued;
    if (levels == im->subtree_levels && r->level + levels < im->available_levels) {
        for (c = 0; c < count; ++c) {
            uint64_t child;
            for (child = 0; child < n; ++child) {
                uint64_t m = (*rows)[c].morton * n + child;
                subtree_root *q;
                if (!available(&s.children, m))
                    continue;
                if (reserve(l, (void **)queue, queue_cap, *queued, 1, sizeof(**queue)))
                    goto done;
                q = &(*queue)[(*queued)++];
                q->level = r->level + levels;
                morton_decode(m, levels, im->octree, q->xyz);
                q->xyz[0] |= r->xyz[0] << levels;
                q->xyz[1] |= r->xyz[1] << levels;
                q->xyz[2] |= r->xyz[2] << levels;
                q->parent = (*rows)[c].tile;
                q->tile = TILE_NONE;
                if (l->lazy) {
                    /* not read now: its root becomes a tile standing for it */
                    subtree_root at = *q;
                    char *child_path;
                    --*queued;
                    if (implicit_tile(l, im, NULL, 0, at.level, at.xyz, at.parent, &at.tile))
                        goto done;
                    child_path = subtree_path(l, im, at.level, at.xyz);
                    if (!child_path || link_file(l, at.tile, (uint32_t)(im - l->implicits), NULL,
                                                 NULL, at.level, at.xyz, child_path))
                        goto done;
                }
            }
        }
    }
    for (c = 0; c < (*queued - first) / 2; ++c) {
        subtree_root tmp = (*queue)[first + c];
        (*queue)[first + c] = (*queue)[*queued - 1 - c];
        (*queue)[*queued - 1 - c] = tmp;
    }
    rc = 0;
done:
    subtree_free(&s);
    free(path);
    return rc;
}

/* Reads the implicit tiling of tile j (entry p, tile self, its transform
 * composed in world): the implicit root's fields, then its subtrees, depth
 * first. */
static int read_implicit(loader *l, const pending *p, const cJSON *j, const cJSON *it,
                         uint32_t self, const double world[16]) {
    const cJSON *bv = cJSON_GetObjectItemCaseSensitive(j, "boundingVolume");
    const cJSON *scheme = cJSON_GetObjectItemCaseSensitive(it, "subdivisionScheme");
    const cJSON *subtrees = cJSON_GetObjectItemCaseSensitive(it, "subtrees");
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(subtrees, "uri");
    const cJSON *contents = cJSON_GetObjectItemCaseSensitive(j, "contents");
    const cJSON *c;
    implicit im;
    subtree_root *queue = NULL;
    level_tile *rows = NULL;
    size_t queued = 1, queue_cap = 0, row_cap = 0;
    uint64_t v;
    int rc = 1;

    memset(&im, 0, sizeof(im));
    im.root = *p;
    im.root.index = -1; /* its tiles are in no "children" array */
    im.root_tile = self;
    if (!cJSON_IsObject(it)) {
        fail_tile(l, p, "implicitTiling is not an object");
        return 1;
    }
    if (cJSON_IsString(scheme) && strcmp(scheme->valuestring, "QUADTREE") == 0) {
        im.octree = 0;
    } else if (cJSON_IsString(scheme) && strcmp(scheme->valuestring, "OCTREE") == 0) {
        im.octree = 1;
    } else {
        fail_tile(l, p, "implicitTiling.subdivisionScheme must be \"QUADTREE\" or \"OCTREE\"");
        return 1;
    }
    if (!read_count(cJSON_GetObjectItemCaseSensitive(it, "subtreeLevels"),
                    im.octree ? IMPLICIT_MAX_SUBTREE_LEVELS_OCTREE
                              : IMPLICIT_MAX_SUBTREE_LEVELS_QUADTREE,
                    &v) ||
        v < 1) {
        fail_tile(l, p, "implicitTiling.subtreeLevels must be an integer in [1, %d]",
                  im.octree ? IMPLICIT_MAX_SUBTREE_LEVELS_OCTREE
                            : IMPLICIT_MAX_SUBTREE_LEVELS_QUADTREE);
        return 1;
    }
    im.subtree_levels = (uint32_t)v;
    if (!read_count(cJSON_GetObjectItemCaseSensitive(it, "availableLevels"), IMPLICIT_MAX_LEVELS,
                    &v) ||
        v < 1) {
        fail_tile(l, p, "implicitTiling.availableLevels must be an integer in [1, %d]",
                  IMPLICIT_MAX_LEVELS);
        return 1;
    }
    im.available_levels = (uint32_t)v;
    if (!cJSON_IsString(uri) || uri->valuestring[0] == '\0') {
        fail_tile(l, p, "implicitTiling.subtrees needs a \"uri\" template");
        return 1;
    }
    im.subtree_uri = uri->valuestring;
    if (cJSON_GetObjectItemCaseSensitive(j, "children")) {
        fail_tile(l, p, "an implicit root tile has no \"children\": its subtrees say them");
        return 1;
    }
    /* contents: uri templates, none an external tileset */
    c = contents ? contents->child : cJSON_GetObjectItemCaseSensitive(j, "content");
    if (contents && !cJSON_IsArray(contents)) {
        fail_tile(l, p, "contents is not an array");
        return 1;
    }
    for (; c; c = contents ? c->next : NULL) {
        const cJSON *u = cJSON_GetObjectItemCaseSensitive(c, "uri");
        if (!cJSON_IsString(u) || u->valuestring[0] == '\0') {
            fail_tile(l, p, "a content has no \"uri\" string");
            return 1;
        }
        if (uri_is_tileset(u->valuestring)) {
            fail_tile(l, p, "the content of an implicit root tile, %s, is an external tileset",
                      u->valuestring);
            return 1;
        }
        if (im.content_count == IMPLICIT_MAX_CONTENTS) {
            fail_tile(l, p, "an implicit root tile with more than %d contents",
                      IMPLICIT_MAX_CONTENTS);
            return 1;
        }
        im.content_uri[im.content_count++] = u->valuestring;
    }
    /* the volume to divide, as written (read_bounds checked it) */
    if (cJSON_GetObjectItemCaseSensitive(bv, "box")) {
        read_numbers(cJSON_GetObjectItemCaseSensitive(bv, "box"), im.volume, 12);
    } else if (cJSON_GetObjectItemCaseSensitive(bv, "region")) {
        read_numbers(cJSON_GetObjectItemCaseSensitive(bv, "region"), im.volume, 6);
        im.region = 1;
    } else {
        fail_tile(l, p, "implicit tiling divides a box or a region, not a sphere");
        return 1;
    }
    memcpy(im.transform, world, sizeof(im.transform));
    im.geometric_error = l->tiles[self].geometric_error;
    im.refine = l->tiles[self].refine;

    if (l->lazy) {
        /* kept for tileset_expand; the root tile stands for subtree 0 */
        static const uint32_t origin[3] = {0, 0, 0};
        char *path;
        if (reserve(l, (void **)&l->implicits, &l->implicit_cap, l->implicit_count, 1, sizeof(im)))
            return 1;
        l->implicits[l->implicit_count] = im;
        path = subtree_path(l, &im, 0, origin);
        if (!path || link_file(l, self, l->implicit_count, NULL, NULL, 0, origin, path))
            return 1;
        ++l->implicit_count;
        ++l->counts.implicit;
        return 0;
    }
    if (reserve(l, (void **)&queue, &queue_cap, 0, 1, sizeof(*queue)))
        return 1;
    memset(queue, 0, sizeof(*queue));
    queue[0].parent = l->tiles[self].parent;
    queue[0].tile = self;
    while (queued > 0) {
        subtree_root r = queue[--queued];
        if (implicit_subtree(l, &im, &r, &queue, &queued, &queue_cap, &rows, &row_cap))
            goto done;
    }
    ++l->counts.implicit;
    rc = 0;
done:
    free(queue);
    free(rows);
    return rc;
}

/* Whether a tile's volume (b, of that kind; region as written) lies within its
 * parent's (entry p), which 3D Tiles asks of every tile and not every producer
 * keeps. Regions compare as regions; other volumes in world coordinates. The
 * tolerance, 1e-4 of the parent's size and 1 mm, forgives written decimals. */
static int within_parent(const loader *l, const pending *p, int kind, const double region[6],
                         const tclod_bounds *b) {
    const tclod_bounds *q;
    double d[3], reach = 0.0, tol;
    int i, k;
    if (p->parent == TILE_NONE)
        return 1;
    q = &l->tiles[p->parent].bounds;
    if (p->in_region && kind == VOLUME_REGION) {
        const double *r = p->region;
        double pw = r[2] >= r[0] ? r[2] - r[0] : r[2] - r[0] + 2.0 * GEO_PI;
        double cw =
            region[2] >= region[0] ? region[2] - region[0] : region[2] - region[0] + 2.0 * GEO_PI;
        double west = region[0] - r[0], a = 1e-4 * pw + 1e-12, h = 1e-4 * (r[5] - r[4]) + 1e-3;
        if (west < -a)
            west += 2.0 * GEO_PI; /* the child starts east of the antimeridian */
        return west >= -a && west + cw <= pw + a &&
               region[1] >= r[1] - 1e-4 * (r[3] - r[1]) - 1e-12 &&
               region[3] <= r[3] + 1e-4 * (r[3] - r[1]) + 1e-12 && region[4] >= r[4] - h &&
               region[5] <= r[5] + h;
    }
    for (i = 0; i < 3; ++i)
        d[i] = b->center[i] - q->center[i];
    if (q->kind == TCLOD_BOUNDS_SPHERE) {
        tol = 1e-4 * q->radius + 1e-3;
        if (b->kind == TCLOD_BOUNDS_SPHERE)
            return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + b->radius <= q->radius + tol;
        for (k = 0; k < 8; ++k) { /* a box: its corners */
            double c2 = 0.0;
            for (i = 0; i < 3; ++i) {
                double x = d[i] + ((k & 1) ? 1 : -1) * b->half_axes[0][i] +
                           ((k & 2) ? 1 : -1) * b->half_axes[1][i] +
                           ((k & 4) ? 1 : -1) * b->half_axes[2][i];
                c2 += x * x;
            }
            if (sqrt(c2) > q->radius + tol)
                return 0;
        }
        return 1;
    }
    /* a box parent: along each of its axes, the child's centre offset and its
     * reach within the half length (a zero axis takes the other two's normal) */
    for (i = 0; i < 3; ++i) {
        double h =
            sqrt(q->half_axes[i][0] * q->half_axes[i][0] + q->half_axes[i][1] * q->half_axes[i][1] +
                 q->half_axes[i][2] * q->half_axes[i][2]);
        reach = h > reach ? h : reach;
    }
    tol = 1e-4 * reach + 1e-3;
    for (i = 0; i < 3; ++i) {
        const double *a = q->half_axes[i], *e = q->half_axes[(i + 1) % 3],
                     *f = q->half_axes[(i + 2) % 3];
        double u[3], h = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), len, off = 0.0, ext = 0.0;
        if (h > 0.0) {
            for (k = 0; k < 3; ++k)
                u[k] = a[k] / h;
        } else {
            u[0] = e[1] * f[2] - e[2] * f[1];
            u[1] = e[2] * f[0] - e[0] * f[2];
            u[2] = e[0] * f[1] - e[1] * f[0];
            len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            if (!(len > 0.0))
                return 1; /* a segment or a point: nothing to compare with */
            for (k = 0; k < 3; ++k)
                u[k] /= len;
        }
        for (k = 0; k < 3; ++k)
            off += d[k] * u[k];
        if (b->kind == TCLOD_BOUNDS_SPHERE)
            ext = b->radius;
        else
            for (k = 0; k < 3; ++k)
                ext += fabs(b->half_axes[k][0] * u[0] + b->half_axes[k][1] * u[1] +
                            b->half_axes[k][2] * u[2]);
        if (fabs(off) + ext > h + tol)
            return 0;
    }
    return 1;
}

/* Reads the tile of entry p into a new tile, and puts its children (and the
 * root of the external tileset it names) on the stack. */
static int linked_root(loader *l, uint32_t doc, pending *c);

static int read_tile(loader *l, const pending *p) {
    const cJSON *j = p->json, *item, *child, *implicit_tiling;
    const char *external;
    double world[16], error, region[6];
    tile t;
    int has_content, n, i, kind;
    uint32_t self;
    size_t first;

    if (!cJSON_IsObject(j)) {
        fail_tile(l, p, "not a JSON object");
        return 1;
    }
    if (l->count >= l->max_tiles) {
        fail_tile(l, p, "more than %lu tiles", (unsigned long)l->max_tiles);
        return 1;
    }
    memset(&t, 0, sizeof(t));
    item = cJSON_GetObjectItemCaseSensitive(j, "transform");
    if (item) {
        double local[16];
        if (!read_numbers(item, local, 16)) {
            fail_tile(l, p, "transform needs 16 finite numbers (a 4x4 matrix, column-major)");
            return 1;
        }
        geo_mat4_mul(p->transform, local, world);
    } else {
        memcpy(world, p->transform, sizeof(world));
    }
    item = cJSON_GetObjectItemCaseSensitive(j, "refine");
    t.refine = p->refine;
    if (item) {
        const char *r = cJSON_IsString(item) ? item->valuestring : NULL;
        if (!r) {
            fail_tile(l, p, "refine must be a string, \"REPLACE\" or \"ADD\"");
            return 1;
        }
        if (same_word(r, "REPLACE") || same_word(r, "ADD")) {
            t.refine = same_word(r, "ADD") ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
            l->counts.lowercase_refines += strcmp(r, "REPLACE") != 0 && strcmp(r, "ADD") != 0;
        } else {
            ++l->counts.unknown_refines; /* cesium-native keeps the parent's */
        }
    }
    /* a missing geometricError is the parent's, as CesiumJS reads it (the
     * root's: the tileset's); every error scales with the composed
     * transform, as in both Cesiums */
    item = cJSON_GetObjectItemCaseSensitive(j, "geometricError");
    if (item) {
        if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || item->valuedouble < 0.0) {
            fail_tile(l, p, "geometricError must be a number >= 0");
            return 1;
        }
        error = item->valuedouble;
    } else if (p->error >= 0.0) {
        error = p->error;
        ++l->counts.inherited_errors;
    } else {
        fail_tile(l, p, "geometricError is missing, and there is no parent's or tileset's to take");
        return 1;
    }
    t.geometric_error = error * geo_mat4_max_scale(world);
    if (!isfinite(t.geometric_error)) {
        fail_tile(l, p, "geometricError overflows under the tile's transform");
        return 1;
    }
    implicit_tiling = cJSON_GetObjectItemCaseSensitive(j, "implicitTiling");
    item = cJSON_GetObjectItemCaseSensitive(j, "extensions");
    if (cJSON_GetObjectItemCaseSensitive(item, "3DTILES_implicit_tiling")) {
        fail_tile(l, p,
                  "the 3DTILES_implicit_tiling extension (before 3D Tiles 1.1) is not read; "
                  "1.1's implicitTiling is");
        return 1;
    }
    kind = read_bounds(l, p, cJSON_GetObjectItemCaseSensitive(j, "boundingVolume"),
                       "boundingVolume", world, &t.bounds, region);
    if (!kind)
        return 1;
    l->counts.boxes += kind == VOLUME_BOX;
    l->counts.regions += kind == VOLUME_REGION;
    l->counts.spheres += kind == VOLUME_SPHERE;
    t.loose = !within_parent(l, p, kind, region, &t.bounds);
    l->counts.loose_children += (uint32_t)t.loose;
    t.request = TILE_NONE;
    item = cJSON_GetObjectItemCaseSensitive(j, "viewerRequestVolume");
    if (item) {
        tclod_bounds rv;
        double unused[6];
        if (!read_bounds(l, p, item, "viewerRequestVolume", world, &rv, unused))
            return 1;
        if (l->request_count == l->request_cap) {
            uint32_t cap = l->request_cap ? 2 * l->request_cap : 16;
            tclod_bounds *r = (tclod_bounds *)realloc(l->requests, cap * sizeof(*r));
            if (!r) {
                fail(l, "out of memory");
                return 1;
            }
            l->requests = r;
            l->request_cap = cap;
        }
        t.request = l->request_count;
        l->requests[l->request_count++] = rv;
    }
    if (implicit_tiling) { /* its contents are templates: read_implicit reads them */
        has_content = 0;
        external = NULL;
    } else if (read_contents(l, p, j, world, &t.bytes, &has_content, &external)) {
        return 1;
    }
    item = cJSON_GetObjectItemCaseSensitive(j, "children");
    if (item && !cJSON_IsArray(item)) {
        fail_tile(l, p, "children is not an array");
        return 1;
    }
    t.parent = p->parent;
    t.empty = !has_content;
    t.add_anchor = TILE_NONE;
    self = l->count;
    if (add_tile(l, p, &t))
        return 1;
    if (implicit_tiling)
        return read_implicit(l, p, j, implicit_tiling, self, world);

    /* children go on the stack last first, so that they come off in file order */
    first = l->top;
    n = 0;
    cJSON_ArrayForEach(child, item) {
        pending c;
        c.json = child;
        c.parent = self;
        c.doc = p->doc;
        c.index = n++;
        c.refine = t.refine;
        memcpy(c.transform, world, sizeof(world));
        c.error = error;
        c.in_region = kind == VOLUME_REGION;
        memcpy(c.region, region, sizeof(region));
        if (push(l, &c))
            return 1;
    }
    for (i = 0; i < n / 2; ++i) {
        pending tmp = l->stack[first + (size_t)i];
        l->stack[first + (size_t)i] = l->stack[first + (size_t)(n - 1 - i)];
        l->stack[first + (size_t)(n - 1 - i)] = tmp;
    }
    if (external) {
        pending c;
        char *path;
        uint32_t doc;
        int bad;
        if (!uri_is_local(external)) {
            fail_tile(l, p, "external tileset %s is not a local file", external);
            return 1;
        }
        path = uri_file(l->docs[p->doc].dir, external);
        if (!path) {
            fail(l, "out of memory");
            return 1;
        }
        c.json = NULL;
        c.parent = self;
        c.doc = p->doc;
        c.index = -1;
        c.refine = t.refine;
        memcpy(c.transform, world, sizeof(world));
        c.error = error;
        c.in_region = kind == VOLUME_REGION;
        memcpy(c.region, region, sizeof(region));
        /* opened lazily, a link without children of its own is read later
         * (with some, they and the linked root are read at once) */
        if (l->lazy && n == 0)
            return link_file(l, self, DOC_NONE, p, &c, 0, NULL, path);
        bad = load_document(l, path, p, &doc);
        free(path);
        if (bad)
            return 1;
        return linked_root(l, doc, &c);
    }
    return 0;
}

/* Reads on below the root of external tileset doc, just loaded: entry c. */
static int linked_root(loader *l, uint32_t doc, pending *c) {
    ++l->counts.external;
    c->json = cJSON_GetObjectItemCaseSensitive(l->docs[doc].json, "root");
    c->doc = doc;
    return push(l, c);
}

/* Children lists, ADD anchors and depths of tiles[from .. count), just read:
 * tiles are in depth-first order, so a parent is finished before its
 * children, and the parents of these are among them or (from > 0) the
 * unexpanded tile `up` they were read for, which had none. Their lists are
 * appended to the children array. */
static int link_tiles(loader *l, uint32_t from, uint32_t up) {
    uint32_t i, next;
    size_t need = l->child_count + (l->count - from);
    if (reserve(l, (void **)&l->children, &l->child_cap, 0, need ? need : 1, sizeof(uint32_t)))
        return 1;
    for (i = from; i < l->count; ++i)
        l->tiles[i].child_count = 0;
    if (up != TILE_NONE)
        l->tiles[up].child_count = 0;
    for (i = from; i < l->count; ++i)
        if (l->tiles[i].parent != TILE_NONE)
            ++l->tiles[l->tiles[i].parent].child_count;
    next = (uint32_t)l->child_count;
    if (up != TILE_NONE) {
        l->tiles[up].first_child = next;
        next += l->tiles[up].child_count;
        l->tiles[up].child_count = 0;
    }
    for (i = from; i < l->count; ++i) {
        l->tiles[i].first_child = next;
        next += l->tiles[i].child_count;
        l->tiles[i].child_count = 0;
    }
    for (i = from; i < l->count; ++i) {
        tile *p;
        if (l->tiles[i].parent == TILE_NONE)
            continue;
        p = &l->tiles[l->tiles[i].parent];
        l->children[p->first_child + p->child_count++] = i;
        l->tiles[i].add_anchor =
            !p->empty && p->refine == TCLOD_REFINE_ADD ? l->tiles[i].parent : p->add_anchor;
        l->tiles[i].depth = p->depth + 1;
        if (l->tiles[i].depth > l->counts.max_depth)
            l->counts.max_depth = l->tiles[i].depth;
    }
    l->child_count = next;
    return 0;
}

/* Frees documents docs[from ..) and file links files[from_file ..). */
static void drop_documents(loader *l, uint32_t from, uint32_t from_file) {
    uint32_t i;
    for (i = from; i < l->doc_count; ++i) {
        cJSON_Delete(l->docs[i].json);
        free(l->docs[i].path);
        free(l->docs[i].dir);
    }
    l->doc_count = from;
    for (i = from_file; i < l->file_count; ++i)
        free(l->files[i].path);
    l->file_count = from_file;
}

static void loader_free(loader *l) {
    drop_documents(l, 0, 0);
    free(l->docs);
    free(l->stack);
    free(l->tile_doc);
    free(l->tile_index);
    free(l->tile_file);
    free(l->files);
    free(l->implicits);
    free(l->requests);
    free(l->children);
    free(l->tiles);
}

/* Reads the tiles on the stack, depth first. */
static int read_stack(loader *l) {
    while (l->top > 0) {
        pending p = l->stack[--l->top];
        if (read_tile(l, &p))
            return 1;
    }
    return 0;
}

/* The tileset's view of what l holds. */
static void publish(loader *l, tileset *ts) {
    ts->tiles = l->tiles;
    ts->count = l->count;
    ts->children = l->children;
    ts->requests = l->requests;
    ts->request_count = l->request_count;
    l->counts.files = l->doc_count + l->counts.subtrees;
    ts->counts = l->counts;
}

/* Reads the tileset at path into l (set up by the caller). */
static int read_tileset(loader *l, const char *path) {
    pending root;
    const cJSON *error;
    if (load_document(l, path, NULL, &root.doc))
        return 1;
    root.json = cJSON_GetObjectItemCaseSensitive(l->docs[0].json, "root");
    root.parent = TILE_NONE;
    root.index = -1;
    error = cJSON_GetObjectItemCaseSensitive(l->docs[0].json, "geometricError");
    root.error = cJSON_IsNumber(error) && isfinite(error->valuedouble) && error->valuedouble >= 0.0
                     ? error->valuedouble
                     : -1.0;
    root.in_region = 0;
    /* 3D Tiles requires the root to say how it refines; one that does not
     * is read as REPLACE, the more common kind */
    root.refine = TCLOD_REFINE_REPLACE;
    geo_mat4_identity(root.transform);
    return push(l, &root) || read_stack(l) || link_tiles(l, 0, TILE_NONE);
}

int tileset_load(const char *path, const size_table *sizes, tileset *ts, char *err,
                 size_t err_size) {
    return tileset_load_at_most(path, sizes, TILESET_MAX_TILES, ts, err, err_size);
}

static int open_as(const char *path, const size_table *sizes, uint32_t max_tiles, int lazy,
                   tileset *ts, char *err, size_t err_size) {
    loader *l = (loader *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_size, "%s: out of memory", path);
        return 1;
    }
    l->sizes = sizes;
    l->max_tiles = max_tiles < TILESET_MAX_TILES ? max_tiles : TILESET_MAX_TILES;
    l->lazy = lazy;
    l->err = err;
    l->err_size = err_size;
    if (read_tileset(l, path)) {
        loader_free(l);
        free(l);
        return 1;
    }
    memset(ts, 0, sizeof(*ts));
    publish(l, ts);
    if (lazy) {
        ts->lazy = l;
        return 0;
    }
    /* the tiles outlive the loader */
    l->tiles = NULL;
    l->children = NULL;
    l->requests = NULL;
    loader_free(l);
    free(l);
    return 0;
}

int tileset_load_at_most(const char *path, const size_table *sizes, uint32_t max_tiles, tileset *ts,
                         char *err, size_t err_size) {
    return open_as(path, sizes, max_tiles, 0, ts, err, err_size);
}

int tileset_open(const char *path, const size_table *sizes, uint32_t max_tiles, tileset *ts,
                 char *err, size_t err_size) {
    return open_as(path, sizes, max_tiles, 1, ts, err, err_size);
}

int tileset_expand(tileset *ts, uint32_t t, char *err, size_t err_size) {
    loader *l = ts->lazy;
    file_link link;
    uint32_t count, docs, files, requests, implicits, index;
    size_t children;
    tileset_counts counts;
    tile before;
    int bad;
    if (!l || t >= l->count || !l->tiles[t].unexpanded) {
        snprintf(err, err_size, "tile %lu: %s", (unsigned long)t,
                 !l ? "the tileset was loaded whole, not opened"
                    : t >= l->count ? "no such tile" : "not unexpanded");
        return 1;
    }
    l->err = err;
    l->err_size = err_size;
    index = l->tile_file[t];
    link = l->files[index];
    count = l->count;
    docs = l->doc_count;
    files = l->file_count;
    requests = l->request_count;
    implicits = l->implicit_count;
    children = l->child_count;
    counts = l->counts;
    before = l->tiles[t];
    if (link.implicit == DOC_NONE) {
        /* t becomes the link it is, its tileset's root below it */
        uint32_t doc;
        pending root = link.root;
        l->tiles[t].unexpanded = 0;
        l->tiles[t].file_bytes = 0.0;
        l->tile_file[t] = TILE_NONE;
        --l->counts.unexpanded;
        bad = load_document(l, link.path, &link.via, &doc) || linked_root(l, doc, &root) ||
              read_stack(l);
    } else {
        /* t is the subtree's root: the subtree gives its content */
        const implicit *im = &l->implicits[link.implicit];
        subtree_root r;
        subtree_root *queue = NULL;
        level_tile *rows = NULL;
        size_t queued = 0, queue_cap = 0, row_cap = 0;
        r.level = link.level;
        memcpy(r.xyz, link.xyz, sizeof(r.xyz));
        r.parent = l->tiles[t].parent;
        r.tile = t;
        bad = implicit_subtree(l, im, &r, &queue, &queued, &queue_cap, &rows, &row_cap);
        free(queue);
        free(rows);
    }
    if (!bad)
        bad = link_tiles(l, count, t);
    if (bad) {
        /* as it was: the file links made since, the documents read, the tiles */
        l->top = 0;
        drop_documents(l, docs, files);
        l->count = count;
        l->request_count = requests;
        l->implicit_count = implicits;
        l->child_count = children;
        l->counts = counts;
        l->tiles[t] = before;
        l->tile_file[t] = index;
        publish(l, ts);
        return 1;
    }
    free(link.path);
    l->files[index].path = NULL;
    publish(l, ts);
    return 0;
}

void tile_node_desc(const tile *t, tclod_id parent, tclod_node_desc *d) {
    tclod_node_desc_default(d);
    d->parent = parent;
    d->bounds = t->bounds;
    d->refine = t->refine;
    d->empty = t->empty && !t->unexpanded;
    d->unexpanded = t->unexpanded;
}

void tileset_free(tileset *ts) {
    if (ts->lazy) {
        loader_free(ts->lazy);
        free(ts->lazy);
    } else {
        free(ts->tiles);
        free(ts->children);
        free(ts->requests);
    }
    memset(ts, 0, sizeof(*ts));
}

uint32_t tileset_warning_count(const tileset_counts *c) {
    return c->inherited_errors + c->lowercase_refines + c->unknown_refines + c->content_urls +
           c->empty_uris + c->missing_versions + c->other_versions + c->content_volumes +
           c->loose_children;
}

void tileset_warning_text(const tileset_counts *c, char *out, size_t size) {
    const struct {
        uint32_t n;
        const char *what;
    } kinds[] = {
        {c->inherited_errors, "tiles without geometricError took their parent's"},
        {c->lowercase_refines, "refine values not in capitals were read in any case"},
        {c->unknown_refines, "unknown refine values kept their parent's"},
        {c->content_urls, "contents named by \"url\" were read as \"uri\""},
        {c->empty_uris, "empty content uris were read as no content"},
        {c->missing_versions, "tilesets without asset.version were read as 1.0"},
        {c->other_versions, "tilesets of an asset.version other than 0.0, 1.0 and 1.1 were read"},
        {c->content_volumes, "content bounding volumes were checked, not used"},
        {c->loose_children, "tiles reach out of their parent's volume"},
    };
    size_t i, len = 0;
    if (size > 0)
        out[0] = '\0';
    for (i = 0; i < sizeof(kinds) / sizeof(kinds[0]); ++i) {
        int w;
        if (kinds[i].n == 0 || len >= size)
            continue;
        w = snprintf(out + len, size - len, "%s%lu %s", len ? "; " : "", (unsigned long)kinds[i].n,
                     kinds[i].what);
        len = w < 0 ? size : len + (size_t)w;
    }
}
