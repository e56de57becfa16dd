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
} pending;

typedef struct loader {
    const size_table *sizes;
    document *docs;
    uint32_t doc_count, doc_cap;
    pending *stack;
    size_t top, stack_cap;
    tile *tiles;
    uint32_t count, tile_cap;
    uint32_t *tile_doc;  /* per tile: its document, for messages */
    int32_t *tile_index; /* per tile: its position in its parent's "children" */
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
    } else if (!cJSON_IsObject(asset) || !cJSON_IsString(version)) {
        fail(l, "%s: no \"asset\" object with a \"version\" string", path);
    } else if (!cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(json, "root"))) {
        fail(l, "%s: no \"root\" tile object", path);
    } else {
        goto parsed;
    }
    cJSON_Delete(json);
    return 1;
parsed:
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

static int push(loader *l, const pending *p) {
    if (l->top == l->stack_cap) {
        size_t cap = l->stack_cap ? 2 * l->stack_cap : 64;
        pending *s = (pending *)realloc(l->stack, cap * sizeof(*s));
        if (!s) {
            fail(l, "out of memory");
            return 1;
        }
        l->stack = s;
        l->stack_cap = cap;
    }
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

/* The tile's bounding volume in world coordinates. A box goes through the
 * composed transform whole (centre as a point, half axes as directions); a
 * sphere's radius grows by the transform's largest scale (CesiumJS does the
 * same); a region is in earth-centred coordinates already and ignores the
 * transform (3D Tiles 1.1, "Bounding volumes"). Where a tile has several kinds
 * the box wins, then the region, as in CesiumJS. */
static int read_bounds(loader *l, const pending *p, const cJSON *bv, const double m[16],
                       tclod_bounds *out) {
    const cJSON *box = cJSON_GetObjectItemCaseSensitive(bv, "box");
    const cJSON *region = cJSON_GetObjectItemCaseSensitive(bv, "region");
    const cJSON *sphere = cJSON_GetObjectItemCaseSensitive(bv, "sphere");
    double v[12], c[3], a[9];
    int i;
    if (!cJSON_IsObject(bv)) {
        fail_tile(l, p, "no \"boundingVolume\" object");
        return 1;
    }
    if (box) {
        if (!read_numbers(box, v, 12)) {
            fail_tile(l, p,
                      "boundingVolume.box needs 12 finite numbers (centre, then the x, y "
                      "and z half axes)");
            return 1;
        }
        geo_mat4_point(m, v, c);
        for (i = 0; i < 3; ++i)
            geo_mat4_vector(m, v + 3 + 3 * i, a + 3 * i);
        if (!all_finite(c, 3) || !all_finite(a, 9)) {
            fail_tile(l, p, "boundingVolume.box overflows under the tile's transform");
            return 1;
        }
        *out = tclod_bounds_obb(c, a);
        if (tclod_bounds_validate(out) != TCLOD_OK) {
            *out = box_sphere(c, a);
            ++l->counts.box_fallbacks;
        }
        ++l->counts.boxes;
    } else if (region) {
        if (!read_numbers(region, v, 6)) {
            fail_tile(l, p,
                      "boundingVolume.region needs 6 finite numbers (west, south, east, "
                      "north in radians, minimum and maximum height in m)");
            return 1;
        }
        if (!geo_region_valid(v)) {
            fail_tile(l, p,
                      "boundingVolume.region is out of range (west and east in [-pi, pi], "
                      "south <= north in [-pi/2, pi/2], minimum height <= maximum height)");
            return 1;
        }
        geo_region_box(v, c, a);
        *out = tclod_bounds_obb(c, a);
        if (tclod_bounds_validate(out) != TCLOD_OK) {
            *out = box_sphere(c, a);
            ++l->counts.box_fallbacks;
        }
        ++l->counts.regions;
    } else if (sphere) {
        if (!read_numbers(sphere, v, 4) || v[3] < 0.0) {
            fail_tile(l, p,
                      "boundingVolume.sphere needs 4 finite numbers (centre, then a radius "
                      ">= 0)");
            return 1;
        }
        geo_mat4_point(m, v, c);
        *out = tclod_bounds_sphere(c[0], c[1], c[2], v[3] * geo_mat4_max_scale(m));
        if (!all_finite(c, 3) || !isfinite(out->radius) || tclod_bounds_validate(out) != TCLOD_OK) {
            fail_tile(l, p, "boundingVolume.sphere overflows under the tile's transform");
            return 1;
        }
        ++l->counts.spheres;
    } else {
        fail_tile(l, p, "boundingVolume has no box, region or sphere");
        return 1;
    }
    return 0;
}

/* Bytes of one content: the file beside the tileset, else the sizes file, else
 * the estimate. */
static double content_bytes(loader *l, const pending *p, const char *uri) {
    const size_entry *e;
    ++l->counts.contents;
    if (uri_is_local(uri)) {
        char *file = uri_file(l->docs[p->doc].dir, uri);
        struct stat st;
        int found = file && stat(file, &st) == 0 && S_ISREG(st.st_mode);
        free(file);
        if (found) {
            ++l->counts.from_file;
            return (double)st.st_size;
        }
    }
    e = size_lookup(l->sizes, uri);
    if (e) {
        ++l->counts.from_sizes;
        return e->bytes;
    }
    ++l->counts.estimated;
    return TILESET_ESTIMATE_BYTES;
}

/* A tile's content ("content" with "uri", or 1.0's "url") or contents (1.1):
 * their bytes summed into *bytes, *has_content set when one of them is drawn,
 * and *external set to the uri of an external tileset. */
static int read_contents(loader *l, const pending *p, const cJSON *j, double *bytes,
                         int *has_content, const char **external) {
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
        if (!uri)
            uri = cJSON_GetObjectItemCaseSensitive(c, "url"); /* 3D Tiles 1.0 */
        if (!cJSON_IsObject(c) || !cJSON_IsString(uri) || uri->valuestring[0] == '\0') {
            fail_tile(l, p, "a content has no \"uri\" string");
            return 1;
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

/* Appends a tile to the arrays. */
static int add_tile(loader *l, const pending *p, const tile *t) {
    if (l->count == l->tile_cap) {
        uint32_t cap = l->tile_cap ? 2 * l->tile_cap : 256;
        tile *tiles = (tile *)realloc(l->tiles, cap * sizeof(*tiles));
        uint32_t *docs;
        int32_t *index;
        if (tiles)
            l->tiles = tiles;
        docs = tiles ? (uint32_t *)realloc(l->tile_doc, cap * sizeof(*docs)) : NULL;
        if (docs)
            l->tile_doc = docs;
        index = docs ? (int32_t *)realloc(l->tile_index, cap * sizeof(*index)) : NULL;
        if (!index) {
            fail(l, "out of memory");
            return 1;
        }
        l->tile_index = index;
        l->tile_cap = cap;
    }
    l->tiles[l->count] = *t;
    l->tile_doc[l->count] = p->doc;
    l->tile_index[l->count] = p->index;
    ++l->count;
    return 0;
}

/* Reads the tile of entry p into a new tile, and puts its children (and the
 * root of the external tileset it names) on the stack. */
static int read_tile(loader *l, const pending *p) {
    const cJSON *j = p->json, *item, *child;
    const char *external;
    double world[16];
    tile t;
    int has_content, n, i;
    uint32_t self;
    size_t first;

    if (!cJSON_IsObject(j)) {
        fail_tile(l, p, "not a JSON object");
        return 1;
    }
    if (l->count >= TILESET_MAX_TILES) {
        fail_tile(l, p, "more than %u tiles", TILESET_MAX_TILES);
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
        if (cJSON_IsString(item) && same_word(item->valuestring, "REPLACE")) {
            t.refine = TCLOD_REFINE_REPLACE;
        } else if (cJSON_IsString(item) && same_word(item->valuestring, "ADD")) {
            t.refine = TCLOD_REFINE_ADD;
        } else {
            fail_tile(l, p, "refine must be \"REPLACE\" or \"ADD\"");
            return 1;
        }
    }
    item = cJSON_GetObjectItemCaseSensitive(j, "geometricError");
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || item->valuedouble < 0.0) {
        fail_tile(l, p, "geometricError must be a number >= 0");
        return 1;
    }
    t.geometric_error = item->valuedouble;
    if (read_bounds(l, p, cJSON_GetObjectItemCaseSensitive(j, "boundingVolume"), world,
                    &t.bounds) ||
        read_contents(l, p, j, &t.bytes, &has_content, &external))
        return 1;
    item = cJSON_GetObjectItemCaseSensitive(j, "children");
    if (item && !cJSON_IsArray(item)) {
        fail_tile(l, p, "children is not an array");
        return 1;
    }
    t.parent = p->parent;
    t.empty = !has_content;
    t.add_anchor = TILE_NONE;
    l->counts.empty += (uint32_t)t.empty;
    l->counts.additive += t.refine == TCLOD_REFINE_ADD;
    l->counts.bytes += t.bytes;
    self = l->count;
    if (add_tile(l, p, &t))
        return 1;

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
        bad = load_document(l, path, p, &doc);
        free(path);
        if (bad)
            return 1;
        ++l->counts.external;
        c.json = cJSON_GetObjectItemCaseSensitive(l->docs[doc].json, "root");
        c.parent = self;
        c.doc = doc;
        c.index = -1;
        c.refine = t.refine;
        memcpy(c.transform, world, sizeof(world));
        if (push(l, &c))
            return 1;
    }
    return 0;
}

/* Children lists, ADD anchors and depths, once every tile is read. Tiles are in
 * depth-first order, so a parent is always finished before its children. */
static int link_tiles(loader *l, uint32_t **children_out) {
    uint32_t *children = (uint32_t *)malloc((l->count ? l->count : 1) * sizeof(*children));
    uint32_t i, next = 0;
    if (!children) {
        fail(l, "out of memory");
        return 1;
    }
    for (i = 0; i < l->count; ++i)
        l->tiles[i].child_count = 0;
    for (i = 1; i < l->count; ++i)
        ++l->tiles[l->tiles[i].parent].child_count;
    for (i = 0; i < l->count; ++i) {
        l->tiles[i].first_child = next;
        next += l->tiles[i].child_count;
        l->tiles[i].child_count = 0;
    }
    for (i = 1; i < l->count; ++i) {
        tile *p = &l->tiles[l->tiles[i].parent];
        children[p->first_child + p->child_count++] = i;
        l->tiles[i].add_anchor =
            !p->empty && p->refine == TCLOD_REFINE_ADD ? l->tiles[i].parent : p->add_anchor;
        l->tiles[i].depth = p->depth + 1;
        if (l->tiles[i].depth > l->counts.max_depth)
            l->counts.max_depth = l->tiles[i].depth;
    }
    *children_out = children;
    return 0;
}

static void loader_free(loader *l) {
    uint32_t i;
    for (i = 0; i < l->doc_count; ++i) {
        cJSON_Delete(l->docs[i].json);
        free(l->docs[i].path);
        free(l->docs[i].dir);
    }
    free(l->docs);
    free(l->stack);
    free(l->tile_doc);
    free(l->tile_index);
}

int tileset_load(const char *path, const size_table *sizes, tileset *ts, char *err,
                 size_t err_size) {
    loader l;
    pending root;
    uint32_t *children = NULL;
    int rc = 1;

    memset(&l, 0, sizeof(l));
    l.sizes = sizes;
    l.err = err;
    l.err_size = err_size;
    if (load_document(&l, path, NULL, &root.doc))
        goto done;
    root.json = cJSON_GetObjectItemCaseSensitive(l.docs[0].json, "root");
    root.parent = TILE_NONE;
    root.index = -1;
    /* 3D Tiles requires the root to say how it refines; one that does not
     * is read as REPLACE, the more common kind */
    root.refine = TCLOD_REFINE_REPLACE;
    geo_mat4_identity(root.transform);
    if (push(&l, &root))
        goto done;
    while (l.top > 0) {
        pending p = l.stack[--l.top];
        if (read_tile(&l, &p))
            goto done;
    }
    if (link_tiles(&l, &children))
        goto done;
    ts->tiles = l.tiles;
    ts->count = l.count;
    ts->children = children;
    ts->counts = l.counts;
    l.tiles = NULL;
    rc = 0;
done:
    free(l.tiles);
    loader_free(&l);
    return rc;
}

void tileset_free(tileset *ts) {
    free(ts->tiles);
    free(ts->children);
    memset(ts, 0, sizeof(*ts));
}
