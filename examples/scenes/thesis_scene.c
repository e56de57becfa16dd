/*
 * thesis_scene — the thesis's terrain flyover with trees ([Thesis8 §8.4]),
 * built procedurally. See thesis_scene.h for the scene and its model.
 *
 * Both the height field and the forest mask are sums of separable terms
 * a · f(u) · g(v) (u = x / side, v = z / side), so every value on a regular grid
 * is a dot product of one row table and one column table: the 2049² terrain
 * samples and the 4 M tree-grid cells are evaluated without a trigonometric call
 * each and without being stored. Building takes three sweeps:
 *  1. the terrain, row by row: the height range of each leaf patch's 33 × 33
 *     vertices, parents the union of their children, then the nodes root first;
 *  2. the tree grid: a histogram of the forest mask, whose upper tail gives the
 *     threshold that puts forest_cover of the cells in forest regions;
 *  3. the tree grid again, block by block: each forest cell gets one tree
 *     (jitter and height from a hash of the cell, no random state), and each
 *     non-empty block becomes a smooth object bounding its trees; with
 *     desc.keep_trees the trees themselves are kept too, for a host that draws them.
 * Finally the scene's smooth order is copied and prefix sums of tree counts and
 * nominal areas over it make every group query O(1).
 */
#include "thesis_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define THESIS_PI 3.14159265358979323846

/* Grids larger than this many cells per side would take minutes to sweep. */
#define THESIS_MAX_GRID_CELLS 8192u
#define THESIS_MAX_DEPTH 8u
/* Histogram of the forest mask: bins over [MASK_LO, MASK_HI]; the mask's terms
 * stay well inside (|sinusoids| <= 0.98, preference in [-1.0, 0.6]). */
#define THESIS_MASK_BINS 16384
#define THESIS_MASK_LO (-3.0)
#define THESIS_MASK_HI 3.0
/* Jitter of a tree in its cell, as a fraction of the spacing either way: keeps
 * neighbouring trees at least 0.2 spacing apart. */
#define THESIS_JITTER 0.4

/* ------------------------------------------------------------------------- */
/* Terrain and forest functions                                              */
/* ------------------------------------------------------------------------- */

/* One separable term a · f(u) · g(v) with f(u) = m(u) · sin(2π fu·u + pu), where a
 * frequency of 0 stands for the factor 1 instead of the sine, and m is the mountain
 * mass (1 where the term is not scaled). */
typedef struct thesis_term {
    double a;
    double fu, pu, fv, pv; /* cycles over the side, phase (radians) */
    int scaled;            /* multiplied by the mountain mass mu(u) · mv(v) */
    int smooth;            /* <= 11 cycles (>= 11 km by default): kept in the camera's envelope */
} thesis_term;

/* Heights as a fraction of desc.height, plus a constant 0.10. The mass term and the
 * scaled ridges make a high, rough corner at u = v = 0 fading to rolling hills; the
 * amplitudes sum to 0.83, so with mass in [0.175, 1] the height stays in
 * [0.029, 0.93]·height. */
static const thesis_term terrain_terms[] = {
    {0.40, 0.0, 0.0, 0.0, 0.0, 1, 1}, /* the mountain mass itself */
    {0.12, 2.0, 0.4, 3.0, 1.3, 1, 1},    {0.09, 5.0, 2.1, 4.0, 0.2, 1, 1},
    {0.07, 9.0, 1.0, 11.0, 2.6, 1, 1},   {0.04, 17.0, 0.7, 13.0, 1.9, 1, 0},
    {0.03, 31.0, 2.9, 29.0, 0.5, 1, 0},  {0.04, 7.0, 1.7, 6.0, 2.2, 0, 1},
    {0.025, 23.0, 0.3, 19.0, 1.1, 0, 0}, {0.015, 41.0, 2.4, 37.0, 0.9, 0, 0},
};
#define TERRAIN_TERMS (sizeof(terrain_terms) / sizeof(terrain_terms[0]))
#define TERRAIN_BASE 0.10

/* Forest regions: a few kilometres to tens of kilometres across. */
static const thesis_term forest_terms[] = {
    {0.35, 3.0, 0.9, 2.0, 2.3, 0, 0},   {0.25, 5.0, 1.6, 7.0, 0.1, 0, 0},
    {0.18, 11.0, 2.8, 9.0, 1.4, 0, 0},  {0.12, 19.0, 0.5, 23.0, 2.0, 0, 0},
    {0.08, 37.0, 1.2, 31.0, 0.7, 0, 0},
};
#define FOREST_TERMS (sizeof(forest_terms) / sizeof(forest_terms[0]))

/* Mountain mass along each axis: 1 at the Alpine edge (0), 0.35 and 0.5 at the far one. */
static double mass_u(double u) {
    return 0.35 + 0.65 * (0.5 + 0.5 * cos(THESIS_PI * u));
}

static double mass_v(double v) {
    return 0.5 + 0.5 * (0.5 + 0.5 * cos(THESIS_PI * v));
}

static double wave(double f, double p, double t) {
    return f == 0.0 ? 1.0 : sin(2.0 * THESIS_PI * f * t + p);
}

/* The u and v factors of a term; a is folded into the u factor. */
static double term_u(const thesis_term *k, double u) {
    return k->a * (k->scaled ? mass_u(u) : 1.0) * wave(k->fu, k->pu, u);
}

static double term_v(const thesis_term *k, double v) {
    return (k->scaled ? mass_v(v) : 1.0) * wave(k->fv, k->pv, v);
}

/* Forest preference by relative height t = h / height: best at 0.45, none in the
 * lowest valleys' fields nor above the tree line at about 0.8. */
static double height_preference(double t) {
    double x = (t - 0.45) / 0.3;
    return 0.6 * (1.0 - x * x);
}

float thesis_terrain_height(float x, float z, float side, float height) {
    double u = (double)x / (double)side, v = (double)z / (double)side, h = TERRAIN_BASE;
    size_t k;
    for (k = 0; k < TERRAIN_TERMS; ++k)
        h += term_u(&terrain_terms[k], u) * term_v(&terrain_terms[k], v);
    return (float)(h * (double)height);
}

float thesis_forest_mask(const thesis_scene *t, float x, float z) {
    double u = (double)x / (double)t->side, v = (double)z / (double)t->side, m = 0.0;
    double rel = t->height > 0.0f
                     ? (double)thesis_terrain_height(x, z, t->side, t->height) / (double)t->height
                     : 0.45;
    size_t k;
    for (k = 0; k < FOREST_TERMS; ++k)
        m += term_u(&forest_terms[k], u) * term_v(&forest_terms[k], v);
    return (float)(m + height_preference(rel) - t->forest_threshold);
}

/* An upper bound of the terrain height near (x, z) without its short wavelengths:
 * the smooth terms as they are, the others at their largest amplitude. */
static double terrain_envelope(double u, double v, double height) {
    double h = TERRAIN_BASE;
    size_t k;
    for (k = 0; k < TERRAIN_TERMS; ++k) {
        const thesis_term *t = &terrain_terms[k];
        if (t->smooth)
            h += term_u(t, u) * term_v(t, v);
        else
            h += t->a * (t->scaled ? mass_u(u) * mass_v(v) : 1.0);
    }
    return h * height;
}

/* Row and column tables of `count` terms on a grid of n points u_i = (i + offset) · step. */
static void fill_tables(const thesis_term *terms, size_t count, uint32_t n, double offset,
                        double step, double *tu, double *tv) {
    size_t k;
    uint32_t i;
    for (k = 0; k < count; ++k) {
        for (i = 0; i < n; ++i) {
            double t = ((double)i + offset) * step;
            tu[k * n + i] = term_u(&terms[k], t);
            tv[k * n + i] = term_v(&terms[k], t);
        }
    }
}

/* Value of the terms at grid point (i, j) from their tables (n points per side). */
static double table_sum(const double *tu, const double *tv, size_t count, uint32_t n, uint32_t i,
                        uint32_t j) {
    double s = 0.0;
    size_t k;
    for (k = 0; k < count; ++k)
        s += tu[k * n + i] * tv[k * n + j];
    return s;
}

/* ------------------------------------------------------------------------- */
/* Defaults and validation                                                   */
/* ------------------------------------------------------------------------- */

void thesis_desc_default(thesis_desc *d) {
    memset(d, 0, sizeof(*d));
    d->side = 120000.0f;
    d->height = 2400.0f;
    d->terrain_depth = 6;
    d->tree_spacing = 60.0f;
    d->forest_cover = 0.35f;
    d->tree_height_min = 20.0f;
    d->tree_height_max = 40.0f;
    d->block_cells = 8;
    d->seed = 11;
    d->k = 50.0;
    d->c_splat_ms = 0.0775e-3;
    d->c_tree_ms = 1.385e-3;
    d->c_vertex_ms = 0.06e-3;
}

static int positive(double x) {
    return isfinite(x) && x > 0.0;
}

static uint32_t grid_cells(const thesis_desc *d) {
    double n = floor((double)d->side / (double)d->tree_spacing);
    return n >= 1.0 && n <= (double)THESIS_MAX_GRID_CELLS ? (uint32_t)n : 0u;
}

static int desc_valid(const thesis_desc *d) {
    return positive((double)d->side) && isfinite(d->height) && d->height >= 0.0f &&
           d->terrain_depth <= THESIS_MAX_DEPTH && positive((double)d->tree_spacing) &&
           grid_cells(d) > 0u && isfinite(d->forest_cover) && d->forest_cover > 0.0f &&
           d->forest_cover <= 1.0f && positive((double)d->tree_height_min) &&
           isfinite(d->tree_height_max) && d->tree_height_max >= d->tree_height_min &&
           d->block_cells >= 1u && d->block_cells <= 8u && positive(d->k) &&
           positive(d->c_splat_ms) && isfinite(d->c_tree_ms) && d->c_tree_ms >= 0.0 &&
           positive(d->c_vertex_ms);
}

void thesis_scene_free(thesis_scene *t) {
    if (!t)
        return;
    tclod_scene_destroy(t->scene);
    free(t->depth);
    free(t->node_bounds);
    free(t->trees);
    free(t->smooth_bounds);
    free(t->smooth_order);
    free(t->smooth_pos);
    free(t->tree_prefix);
    free(t->area_prefix);
    free(t->tree_first);
    free(t->tree_xyzh);
    memset(t, 0, sizeof(*t));
}

/* ------------------------------------------------------------------------- */
/* Terrain                                                                   */
/* ------------------------------------------------------------------------- */

/* Node ids of the terrain quadtree run root first, level by level, row-major
 * within a level: node (level, ix, iz) is level_first(level) + iz · 2^level + ix,
 * the levels above it holding (4^level − 1) / 3 nodes. */
static uint32_t level_first(uint32_t level) {
    return ((1u << (2u * level)) - 1u) / 3u;
}

/* Height range of every patch: leaves from their 33 × 33 vertices, one row of
 * samples at a time; coarser patches draw a subset of their children's vertices,
 * so the union of the children's ranges bounds them. minmax holds 2 floats per
 * node, in node id order (level by level, row-major). */
static tclod_status terrain_ranges(const thesis_desc *d, uint32_t node_count, float *minmax) {
    uint32_t depth = d->terrain_depth, leaves = 1u << depth;
    uint32_t samples = THESIS_PATCH_CELLS * leaves + 1u, i, j, level;
    uint32_t leaf_first = (node_count - leaves * leaves);
    double *tu = (double *)malloc(TERRAIN_TERMS * (size_t)samples * sizeof(double));
    double *tv = (double *)malloc(TERRAIN_TERMS * (size_t)samples * sizeof(double));
    double *row = (double *)malloc((size_t)samples * sizeof(double));
    float *leaf = minmax + 2u * (size_t)leaf_first;
    if (!tu || !tv || !row) {
        free(tu);
        free(tv);
        free(row);
        return TCLOD_ERR_NOMEM;
    }
    fill_tables(terrain_terms, TERRAIN_TERMS, samples, 0.0, 1.0 / (double)(samples - 1u), tu, tv);
    for (i = 0; i < 2u * leaves * leaves; i += 2u) {
        leaf[i] = INFINITY;
        leaf[i + 1u] = -INFINITY;
    }
    for (j = 0; j < samples; ++j) {
        /* row j belongs to the patch row below it and, on a patch edge, the one above */
        uint32_t pz_hi = j / THESIS_PATCH_CELLS < leaves ? j / THESIS_PATCH_CELLS : leaves - 1u;
        uint32_t pz_lo =
            j % THESIS_PATCH_CELLS == 0u && j > 0u ? pz_hi - (j < samples - 1u) : pz_hi;
        uint32_t pz;
        for (i = 0; i < samples; ++i)
            row[i] = (TERRAIN_BASE + table_sum(tu, tv, TERRAIN_TERMS, samples, i, j)) *
                     (double)d->height;
        for (pz = pz_lo; pz <= pz_hi; ++pz) {
            uint32_t px;
            for (px = 0; px < leaves; ++px) {
                float *mm = leaf + 2u * ((size_t)pz * leaves + px);
                for (i = px * THESIS_PATCH_CELLS; i <= (px + 1u) * THESIS_PATCH_CELLS; ++i) {
                    float h = (float)row[i];
                    if (h < mm[0])
                        mm[0] = h;
                    if (h > mm[1])
                        mm[1] = h;
                }
            }
        }
    }
    free(tu);
    free(tv);
    free(row);
    /* parents from children, deepest level first */
    for (level = depth; level-- > 0;) {
        uint32_t m = 1u << level, first = level_first(level);
        uint32_t child_first = first + m * m, ix, iz, s;
        for (iz = 0; iz < m; ++iz) {
            for (ix = 0; ix < m; ++ix) {
                float *mm = minmax + 2u * ((size_t)first + (size_t)iz * m + ix);
                mm[0] = INFINITY;
                mm[1] = -INFINITY;
                for (s = 0; s < 4u; ++s) {
                    size_t c = child_first + (size_t)(2u * iz + (s >> 1)) * (2u * m) +
                               (2u * ix + (s & 1u));
                    if (minmax[2u * c] < mm[0])
                        mm[0] = minmax[2u * c];
                    if (minmax[2u * c + 1u] > mm[1])
                        mm[1] = minmax[2u * c + 1u];
                }
            }
        }
    }
    return TCLOD_OK;
}

/* The terrain quadtree in node id order (level_first). */
static tclod_status build_terrain(const thesis_desc *d, thesis_scene *t) {
    uint32_t depth = d->terrain_depth, level;
    uint32_t count = level_first(depth + 1u);
    float *minmax;
    tclod_status st;
    t->depth = (uint8_t *)malloc(count);
    t->node_bounds = (float *)malloc(4u * (size_t)count * sizeof(float));
    minmax = (float *)malloc(2u * (size_t)count * sizeof(float));
    if (!t->depth || !t->node_bounds || !minmax) {
        free(minmax);
        return TCLOD_ERR_NOMEM;
    }
    st = terrain_ranges(d, count, minmax);
    for (level = 0; level <= depth && st == TCLOD_OK; ++level) {
        uint32_t m = 1u << level, first = level_first(level), ix, iz;
        uint32_t parent_first = level ? level_first(level - 1u) : 0u;
        float patch = d->side / (float)m;
        for (iz = 0; iz < m && st == TCLOD_OK; ++iz) {
            for (ix = 0; ix < m; ++ix) {
                tclod_id id = first + iz * m + ix, got;
                tclod_id parent =
                    level ? parent_first + (iz / 2u) * (m / 2u) + ix / 2u : TCLOD_NONE;
                float lo = minmax[2u * (size_t)id], hi = minmax[2u * (size_t)id + 1u];
                float half = 0.5f * patch, half_h = 0.5f * (hi - lo);
                float *b = t->node_bounds + 4u * (size_t)id;
                b[0] = ((float)ix + 0.5f) * patch;
                b[1] = 0.5f * (lo + hi);
                b[2] = ((float)iz + 0.5f) * patch;
                b[3] = sqrtf(2.0f * half * half + half_h * half_h);
                st = tclod_scene_add_node(t->scene, parent, b, &got);
                if (st != TCLOD_OK)
                    break;
                if (got != id) {
                    st = TCLOD_ERR_STATE; /* ids are dense, in creation order */
                    break;
                }
                t->depth[id] = (uint8_t)level;
                t->node_count = id + 1u;
            }
        }
    }
    free(minmax);
    t->terrain_depth = depth;
    t->patch_cost_ms = tclod_cost_vertices(d->c_vertex_ms, (double)THESIS_PATCH_VERTICES);
    return st;
}

void thesis_patch_cell(const thesis_scene *t, tclod_id node, uint32_t *level, uint32_t *ix,
                       uint32_t *iz) {
    uint32_t l = t->depth[node], m = 1u << l, k = node - level_first(l);
    *level = l;
    *ix = k % m;
    *iz = k / m;
}

/* ------------------------------------------------------------------------- */
/* Trees                                                                     */
/* ------------------------------------------------------------------------- */

/* The tree grid's tables: terrain and forest terms at the cell centres. */
typedef struct tree_grid {
    uint32_t n;        /* cells per side */
    double height;     /* desc.height */
    double *hu, *hv;   /* TERRAIN_TERMS × n each */
    double *fu, *fv;   /* FOREST_TERMS × n each */
    int threshold_bin; /* cells whose mask falls in this bin or above are forest */
} tree_grid;

static double cell_ground(const tree_grid *g, uint32_t ix, uint32_t iz) {
    return (TERRAIN_BASE + table_sum(g->hu, g->hv, TERRAIN_TERMS, g->n, ix, iz)) * g->height;
}

/* Histogram bin of the forest mask of a cell; the same arithmetic in both sweeps,
 * so the threshold splits the cells exactly as the histogram counted them. */
static int cell_mask_bin(const tree_grid *g, uint32_t ix, uint32_t iz) {
    double rel = g->height > 0.0 ? cell_ground(g, ix, iz) / g->height : 0.45;
    double m = table_sum(g->fu, g->fv, FOREST_TERMS, g->n, ix, iz) + height_preference(rel);
    double b = floor((m - THESIS_MASK_LO) * (THESIS_MASK_BINS / (THESIS_MASK_HI - THESIS_MASK_LO)));
    if (!(b >= 0.0))
        return 0;
    return b < (double)(THESIS_MASK_BINS - 1) ? (int)b : THESIS_MASK_BINS - 1;
}

/* SplitMix64 finaliser (Steele et al. 2014): a well-mixed hash of a cell. */
static uint64_t mix64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* Uniform in [0, 1) from 21 bits of h starting at bit `shift`. */
static double hash_unit(uint64_t h, int shift) {
    return (double)((h >> shift) & 0x1fffffu) * (1.0 / 2097152.0);
}

/* Sweep 2: the mask bin that puts the forest_cover share of the cells above it. */
static tclod_status find_threshold(const thesis_desc *d, tree_grid *g) {
    uint32_t *hist = (uint32_t *)calloc(THESIS_MASK_BINS, sizeof(uint32_t));
    double target = (double)d->forest_cover * (double)g->n * (double)g->n, above = 0.0;
    uint32_t ix, iz;
    int b;
    if (!hist)
        return TCLOD_ERR_NOMEM;
    for (iz = 0; iz < g->n; ++iz)
        for (ix = 0; ix < g->n; ++ix)
            hist[cell_mask_bin(g, ix, iz)]++;
    g->threshold_bin = THESIS_MASK_BINS;
    for (b = THESIS_MASK_BINS - 1; b >= 0; --b) {
        double with = above + (double)hist[b];
        if (with >= target) {
            /* take the bin only if that lands nearer the target than leaving it out */
            g->threshold_bin = with - target <= target - above ? b : b + 1;
            break;
        }
        above = with;
        g->threshold_bin = b;
    }
    free(hist);
    return TCLOD_OK;
}

/* Appends one tree to t->tree_xyzh (desc.keep_trees), growing it by half as needed;
 * *cap counts trees. */
static tclod_status keep_tree(thesis_scene *t, size_t *cap, size_t index, double x, double y,
                              double z, double tall) {
    float *p;
    if (index == *cap) {
        size_t grown = *cap + *cap / 2u + 4096u;
        p = (float *)realloc(t->tree_xyzh, 4u * grown * sizeof(float));
        if (!p)
            return TCLOD_ERR_NOMEM;
        t->tree_xyzh = p;
        *cap = grown;
    }
    p = t->tree_xyzh + 4u * index;
    p[0] = (float)x;
    p[1] = (float)y;
    p[2] = (float)z;
    p[3] = (float)tall;
    return TCLOD_OK;
}

/* Sweep 3: one smooth object per non-empty block of block_cells² cells. */
static tclod_status place_trees(const thesis_desc *d, const tree_grid *g, thesis_scene *t) {
    uint32_t bc = d->block_cells, blocks = (g->n + bc - 1u) / bc, bx, bz;
    size_t cap = (size_t)blocks * blocks, kept_cap = 0;
    double cell = (double)d->side / (double)g->n;
    double hmin = (double)d->tree_height_min,
           hspan = (double)(d->tree_height_max - d->tree_height_min);
    uint64_t seed = mix64(d->seed);
    t->trees = (uint8_t *)malloc(cap);
    t->smooth_bounds = (float *)malloc(4u * cap * sizeof(float));
    if (!t->trees || !t->smooth_bounds)
        return TCLOD_ERR_NOMEM;
    if (d->keep_trees) {
        t->tree_first = (uint32_t *)malloc((cap + 1u) * sizeof(uint32_t));
        if (!t->tree_first)
            return TCLOD_ERR_NOMEM;
        t->tree_first[0] = 0;
    }
    for (bz = 0; bz < blocks; ++bz) {
        for (bx = 0; bx < blocks; ++bx) {
            double lo[3] = {INFINITY, INFINITY, INFINITY},
                   hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            uint32_t n = 0, ix, iz;
            uint32_t ix_end = (bx + 1u) * bc < g->n ? (bx + 1u) * bc : g->n;
            uint32_t iz_end = (bz + 1u) * bc < g->n ? (bz + 1u) * bc : g->n;
            for (iz = bz * bc; iz < iz_end; ++iz) {
                for (ix = bx * bc; ix < ix_end; ++ix) {
                    uint64_t h;
                    double x, z, ground, tall, crown;
                    if (cell_mask_bin(g, ix, iz) < g->threshold_bin)
                        continue;
                    h = mix64(seed ^ ((uint64_t)iz * g->n + ix));
                    x = ((double)ix + 0.5 + THESIS_JITTER * (2.0 * hash_unit(h, 0) - 1.0)) * cell;
                    z = ((double)iz + 0.5 + THESIS_JITTER * (2.0 * hash_unit(h, 21) - 1.0)) * cell;
                    tall = hmin + hspan * hash_unit(h, 42);
                    crown = THESIS_CROWN_RATIO * tall;
                    /* the tree stands at its cell centre's height: the jitter moves it by
                     * at most 0.4 spacing, a few metres of height on these slopes, which
                     * the bounding sphere's slack around a block of trees absorbs */
                    ground = cell_ground(g, ix, iz);
                    if (x - crown < lo[0])
                        lo[0] = x - crown;
                    if (x + crown > hi[0])
                        hi[0] = x + crown;
                    if (ground < lo[1])
                        lo[1] = ground;
                    if (ground + tall > hi[1])
                        hi[1] = ground + tall;
                    if (z - crown < lo[2])
                        lo[2] = z - crown;
                    if (z + crown > hi[2])
                        hi[2] = z + crown;
                    if (d->keep_trees) {
                        tclod_status st =
                            keep_tree(t, &kept_cap, (size_t)t->tree_count + n, x, ground, z, tall);
                        if (st != TCLOD_OK)
                            return st;
                    }
                    ++n;
                }
            }
            if (n > 0) {
                float bounds[4];
                double ex = hi[0] - lo[0], ey = hi[1] - lo[1], ez = hi[2] - lo[2];
                tclod_id id;
                tclod_status st;
                bounds[0] = (float)(0.5 * (lo[0] + hi[0]));
                bounds[1] = (float)(0.5 * (lo[1] + hi[1]));
                bounds[2] = (float)(0.5 * (lo[2] + hi[2]));
                /* half the box diagonal, rounded up past float rounding of the centre */
                bounds[3] = (float)(0.5 * sqrt(ex * ex + ey * ey + ez * ez) * (1.0 + 1e-6));
                st = tclod_scene_add_smooth(t->scene, bounds, &id);
                if (st != TCLOD_OK)
                    return st;
                if (id != t->smooth_count)
                    return TCLOD_ERR_STATE; /* ids are dense, in creation order */
                t->trees[id] = (uint8_t)n;
                memcpy(t->smooth_bounds + 4u * (size_t)id, bounds, sizeof(bounds));
                t->smooth_count = id + 1u;
                t->tree_count += n;
                if (t->tree_first)
                    t->tree_first[t->smooth_count] = t->tree_count;
            }
        }
    }
    return TCLOD_OK;
}

static tclod_status build_trees(const thesis_desc *d, thesis_scene *t) {
    tree_grid g;
    uint32_t n = grid_cells(d);
    double step = 1.0 / (double)n;
    tclod_status st = TCLOD_ERR_NOMEM;
    memset(&g, 0, sizeof(g));
    g.n = n;
    g.height = (double)d->height;
    g.hu = (double *)malloc(TERRAIN_TERMS * (size_t)n * sizeof(double));
    g.hv = (double *)malloc(TERRAIN_TERMS * (size_t)n * sizeof(double));
    g.fu = (double *)malloc(FOREST_TERMS * (size_t)n * sizeof(double));
    g.fv = (double *)malloc(FOREST_TERMS * (size_t)n * sizeof(double));
    if (g.hu && g.hv && g.fu && g.fv) {
        fill_tables(terrain_terms, TERRAIN_TERMS, n, 0.5, step, g.hu, g.hv);
        fill_tables(forest_terms, FOREST_TERMS, n, 0.5, step, g.fu, g.fv);
        st = find_threshold(d, &g);
        /* bin b holds the masks in [LO + b·w, LO + (b + 1)·w) */
        t->forest_threshold =
            THESIS_MASK_LO +
            (double)g.threshold_bin * ((THESIS_MASK_HI - THESIS_MASK_LO) / THESIS_MASK_BINS);
        if (st == TCLOD_OK)
            st = place_trees(d, &g, t);
    }
    free(g.hu);
    free(g.hv);
    free(g.fu);
    free(g.fv);
    t->grid_cells = n;
    return st;
}

/* The scene's smooth order, each id's position in it, and the prefix sums over it. */
static tclod_status build_prefix(thesis_scene *t) {
    const tclod_id *order;
    uint32_t count, p;
    size_t n = (size_t)t->smooth_count;
    tclod_status st = tclod_scene_smooth_order(t->scene, &order, &count);
    if (st != TCLOD_OK)
        return st;
    if (count != t->smooth_count)
        return TCLOD_ERR_STATE;
    /* at least one element: malloc(0) may return NULL */
    t->smooth_order = (tclod_id *)malloc((n ? n : 1u) * sizeof(tclod_id));
    t->smooth_pos = (uint32_t *)malloc((n ? n : 1u) * sizeof(uint32_t));
    t->tree_prefix = (uint32_t *)malloc((n + 1u) * sizeof(uint32_t));
    t->area_prefix = (double *)malloc((n + 1u) * sizeof(double));
    if (!t->smooth_order || !t->smooth_pos || !t->tree_prefix || !t->area_prefix)
        return TCLOD_ERR_NOMEM;
    if (n)
        memcpy(t->smooth_order, order, n * sizeof(tclod_id));
    t->tree_prefix[0] = 0;
    t->area_prefix[0] = 0.0;
    for (p = 0; p < count; ++p) {
        tclod_id id = t->smooth_order[p];
        double r = (double)t->smooth_bounds[4u * (size_t)id + 3u];
        if (id >= count)
            return TCLOD_ERR_STATE;
        t->smooth_pos[id] = p;
        t->tree_prefix[p + 1u] = t->tree_prefix[p] + t->trees[id];
        t->area_prefix[p + 1u] = t->area_prefix[p] + THESIS_PI * r * r;
    }
    return TCLOD_OK;
}

static void set_path(const thesis_desc *d, thesis_scene *t) {
    /* A loop through the middle half of the terrain, over the Alpine corner and the
     * hills, 100–300 m above the envelope (a few hundred metres above the ground),
     * looking ahead and 7° down, seeing 30 km (a quarter of the side) ahead. */
    t->path.centre[0] = 0.5f * d->side;
    t->path.centre[1] = 0.5f * d->side;
    t->path.radius = 0.25f * d->side;
    t->path.wobble = 0.04f * d->side;
    t->path.altitude = 200.0f;
    t->path.altitude_swing = 100.0f;
    t->path.pitch = 0.12f;
    t->path.fov_y = 1.0471976f;
    t->path.aspect = 4.0f / 3.0f;
    t->path.near_z = 5.0f;
    t->path.far_z = 0.25f * d->side;
    t->path.viewport_height = 1024.0f;
}

tclod_status thesis_build(const thesis_desc *d, thesis_scene *out) {
    tclod_status st;
    if (out)
        memset(out, 0, sizeof(*out));
    if (!d || !out || !desc_valid(d))
        return TCLOD_ERR_ARG;
    out->side = d->side;
    out->height = d->height;
    out->k = d->k;
    out->c_splat_ms = d->c_splat_ms;
    out->c_tree_ms = d->c_tree_ms;
    out->c_vertex_ms = d->c_vertex_ms;
    st = tclod_scene_create(d->alloc, &out->scene);
    if (st == TCLOD_OK)
        st = build_terrain(d, out);
    if (st == TCLOD_OK)
        st = build_trees(d, out);
    if (st == TCLOD_OK)
        st = build_prefix(out);
    if (st == TCLOD_OK)
        st = tclod_scene_prepare(out->scene);
    if (st != TCLOD_OK) {
        thesis_scene_free(out);
        return st;
    }
    set_path(d, out);
    return TCLOD_OK;
}

/* ------------------------------------------------------------------------- */
/* Camera                                                                    */
/* ------------------------------------------------------------------------- */

void thesis_camera_at(const thesis_scene *t, double time, tclod_view *view) {
    double above;
    world_camera_at(&t->path, time, view);
    above = world_float(terrain_envelope(view->eye[0] / (double)t->side,
                                         view->eye[2] / (double)t->side, (double)t->height));
    /* in float, like the rest of the path */
    view->eye[1] = world_float(view->eye[1] + above);
}

/* ------------------------------------------------------------------------- */
/* Callbacks and the independent checks                                      */
/* ------------------------------------------------------------------------- */

uint32_t thesis_group_trees(const thesis_scene *t, uint32_t first, uint32_t count) {
    if (first > t->smooth_count || count > t->smooth_count - first)
        return 0;
    return t->tree_prefix[first + count] - t->tree_prefix[first];
}

/* Splat cost of the count objects at positions [first, first + count) at r: their
 * trees all have the same splats per tree, so the sum of their eq. 8.18 costs is
 * eq. 8.18 of all their trees together. */
static double group_cost(const thesis_scene *t, uint32_t first, uint32_t count, double r,
                         double *d_dr) {
    double n = (double)thesis_group_trees(t, first, count);
    return tclod_cost_splats(t->c_splat_ms, t->c_tree_ms, n * (double)THESIS_SPLATS_PER_TREE, n, r,
                             d_dr);
}

/* The group a smooth query is about, as positions of the smooth order; 0 for a
 * query that is not one (the library never asks such). */
static int query_range(const thesis_scene *t, const tclod_query *q, uint32_t *first,
                       uint32_t *count) {
    if (q->id >= t->smooth_count || q->count == 0u)
        return 0;
    *first = t->smooth_pos[q->id];
    *count = q->count;
    return *count <= t->smooth_count - *first;
}

double thesis_benefit(void *user, const tclod_query *q) {
    const thesis_scene *t = (const thesis_scene *)user;
    double area = (double)q->screen_area;
    if (q->id >= t->node_count)
        return 0.0;
    if (area < 0.0) {
        double r = (double)t->node_bounds[4u * (size_t)q->id + 3u];
        area = THESIS_PI * r * r;
    }
    return tclod_benefit_terrain(area, t->depth[q->id], t->terrain_depth);
}

double thesis_cost(void *user, const tclod_query *q) {
    const thesis_scene *t = (const thesis_scene *)user;
    (void)q;
    return t->patch_cost_ms;
}

double thesis_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    const thesis_scene *t = (const thesis_scene *)user;
    uint32_t first, count;
    double area = (double)q->screen_area, n;
    if (!query_range(t, q, &first, &count)) {
        *d_dr = 0.0;
        return 0.0;
    }
    if (area < 0.0)
        area = t->area_prefix[first + count] - t->area_prefix[first];
    n = (double)thesis_group_trees(t, first, count);
    return tclod_benefit_tree_group(t->k, area, n / (double)count, r, d_dr);
}

double thesis_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    const thesis_scene *t = (const thesis_scene *)user;
    uint32_t first, count;
    if (!query_range(t, q, &first, &count)) {
        *d_dr = 0.0;
        return 0.0;
    }
    return group_cost(t, first, count, r, d_dr);
}

tclod_callbacks thesis_callbacks(thesis_scene *t) {
    tclod_callbacks cb;
    memset(&cb, 0, sizeof(cb));
    cb.benefit = thesis_benefit;
    cb.cost = thesis_cost;
    cb.smooth_benefit = thesis_smooth_benefit;
    cb.smooth_cost = thesis_smooth_cost;
    cb.user = t;
    return cb;
}

const char *const thesis_feature_names[THESIS_FEATURES] = {"draws", "vertices", "splats"};

void thesis_features(void *user, const tclod_query *q, double *out) {
    (void)user;
    (void)q;
    out[THESIS_DRAWS] = 1.0;
    out[THESIS_VERTICES] = (double)THESIS_PATCH_VERTICES;
    out[THESIS_SPLATS] = 0.0;
}

void thesis_group_features(double trees, double r, double *out, double *d_dr) {
    double splats = r * trees * (double)THESIS_SPLATS_PER_TREE;
    out[THESIS_DRAWS] = splats < trees ? splats : trees;
    out[THESIS_VERTICES] = 0.0;
    out[THESIS_SPLATS] = splats;
    if (d_dr) { /* at the kink, the slope after it, as tclod_cost_splats */
        d_dr[THESIS_DRAWS] = splats < trees ? trees * (double)THESIS_SPLATS_PER_TREE : 0.0;
        d_dr[THESIS_VERTICES] = 0.0;
        d_dr[THESIS_SPLATS] = trees * (double)THESIS_SPLATS_PER_TREE;
    }
}

void thesis_smooth_features(void *user, const tclod_query *q, double r, double *out, double *d_dr) {
    const thesis_scene *t = (const thesis_scene *)user;
    uint32_t first, count;
    double trees = 0.0;
    if (query_range(t, q, &first, &count))
        trees = (double)thesis_group_trees(t, first, count);
    thesis_group_features(trees, r, out, d_dr);
}

tclod_callbacks thesis_feature_callbacks(thesis_scene *t) {
    tclod_callbacks cb = thesis_callbacks(t);
    cb.cost = NULL;
    cb.smooth_cost = NULL;
    cb.features = thesis_features;
    cb.smooth_features = thesis_smooth_features;
    return cb;
}

void thesis_feature_prior(const thesis_scene *t, double *out) {
    out[THESIS_DRAWS] = t->c_tree_ms;
    out[THESIS_VERTICES] = t->c_vertex_ms;
    out[THESIS_SPLATS] = t->c_splat_ms;
}

/* Screen area of bounds under view as a callback would see it: 0 outside the
 * frustum, the nominal pi·radius² without a view. */
static double own_area(const tclod_view *view, const float bounds[4]) {
    if (!view)
        return THESIS_PI * (double)bounds[3] * (double)bounds[3];
    if (!tclod_view_sphere_visible(view, bounds))
        return 0.0;
    return (double)tclod_view_screen_area(view, bounds);
}

double thesis_node_benefit(const thesis_scene *t, const tclod_view *view, tclod_id node) {
    if (node >= t->node_count)
        return 0.0;
    return tclod_benefit_terrain(own_area(view, t->node_bounds + 4u * (size_t)node), t->depth[node],
                                 t->terrain_depth);
}

double thesis_object_benefit(const thesis_scene *t, const tclod_view *view, tclod_id smooth,
                             double r) {
    if (smooth >= t->smooth_count || !(r > 0.0))
        return 0.0;
    return tclod_benefit_tree_group(t->k, own_area(view, t->smooth_bounds + 4u * (size_t)smooth),
                                    (double)t->trees[smooth], r, NULL);
}

double thesis_selection_benefit(const thesis_scene *t, const tclod_view *view, const tclod_id *ids,
                                size_t n, const tclod_smooth_group *groups, size_t group_count) {
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        sum += thesis_node_benefit(t, view, ids[i]);
    for (i = 0; i < group_count; ++i) {
        uint32_t p, end = groups[i].first + groups[i].count;
        if (groups[i].first > t->smooth_count ||
            groups[i].count > t->smooth_count - groups[i].first)
            continue;
        for (p = groups[i].first; p < end; ++p)
            sum += thesis_object_benefit(t, view, t->smooth_order[p], groups[i].resolution);
    }
    return sum;
}

double thesis_sum_cost(const thesis_scene *t, const tclod_id *ids, size_t n,
                       const tclod_smooth_group *groups, size_t group_count) {
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        sum += ids[i] < t->node_count ? t->patch_cost_ms : 0.0;
    for (i = 0; i < group_count; ++i)
        sum += group_cost(t, groups[i].first, groups[i].count, groups[i].resolution, NULL);
    return sum;
}

uint32_t thesis_visible_smooth(const thesis_scene *t, const tclod_view *view) {
    uint32_t i, n = 0;
    for (i = 0; i < t->smooth_count; ++i)
        n += (uint32_t)tclod_view_sphere_visible(view, t->smooth_bounds + 4u * (size_t)i);
    return n;
}
