/*
 * world_scene — the random world (benchmark) and the flyover world (example),
 * their camera loop and their benefit/cost model. See world_scene.h.
 *
 * Model, per node, precomputed at build time (the callbacks only multiply):
 *   cost    = ms_per_draw + ms_per_triangle × triangles            ([Thesis8 eq. 8.18/8.19],
 *                                                                   [GEO §4.2])
 *   benefit = screen area × weight                                 ([GEO §4.2]:
 *                                                                   accuracy × screen size)
 *   importance = weight: Robin Hood's I ([RH eq. 8-11]), whose value functions
 *       measure size and place themselves, so the area must not enter it twice
 * with these weights:
 *   object level k (of a chain):  1 − 2^−(k+1)  and triangles T0·4^k, so each finer
 *       level adds half the benefit of the previous step for four times the triangles;
 *   terrain patch at depth d:     2^(d − dmax) ([Thesis8 eq. 8.21]: the share of the
 *       full-resolution texels shown) and a fixed triangle count per patch (eq. 8.19),
 *       so four children cost four times their parent. Doubling per level (rather
 *       than the objects' 1 − 2^−(k+1)) keeps a split worth taking while more than
 *       half of a patch's screen area stays in view after it: with a flatter weight
 *       a patch cut by the frustum's edge loses benefit when refined and stays coarse;
 *   group impostor of height h (h = 1 just above level 0 of its objects):
 *       cover × ¼ · 2^−h, cover = Σ r_i² / R² the share of the group's bounding
 *       sphere its objects fill, so that screen area × cover estimates the objects'
 *       own screen area; an impostor is half as accurate as its sub-groups, and a
 *       leaf impostor a quarter as accurate as its objects' level 0. That margin
 *       matters: when only part of a group is in view, refining it still gains as
 *       long as more than a quarter of its objects are visible (with ½ it would
 *       take half, and groups at the screen's edges would stay impostors).
 *
 * Diminishing returns (benefit gained per ms falls down every chain), checked by
 * hand for the defaults (s = 0.5 µs per draw, c = 1 ns per triangle):
 *   object k → k+1:      Δb/Δc = A·2^−(k+2) / (3·c·T0·4^k) falls 8× per level; the first
 *                        step is below the level-0 ratio A/2 / (s + c·T0) when 5·c·T0 > s,
 *                        hence T0 >= 256 triangles (flyover objects: 256–1023).
 *   terrain d → d+1:     the four children cover the parent's screen area, Δb = S·2^(d−dmax)
 *                        for Δc = 3 patches: 1/3 of the parent's ratio, then halving.
 *   group h → h−1:       Δb = A·¼·2^−h for Δc = 3 impostors: the same 1/3-then-halving.
 *   leaf group → objects: random-world objects have T0 = 512–2047 (mean 1280: level 0
 *                        costs 1.78 µs, an impostor of >= 8 objects 1.01 µs). A leaf of 8
 *                        gains 3/8·A for 8·1.78 − 1.01 = 13.2 µs, a third of the ratio of
 *                        the split above it (4 leaves: A/4 for 3.0 µs) and 3.5× the ratio
 *                        of its objects' first step (A/32 each for 3.8 µs). Leaves of fewer
 *                        objects keep the order with less margin; with T0 around 256 they
 *                        would not, once perspective makes a group look bigger than its
 *                        objects.
 * These hold on average over a parent's children. A child nearer the eye (or, in the
 * random world, denser) than its siblings gains more than their average, and near the
 * camera screen areas clamp at the viewport: along the camera loops about 1% of the
 * object steps, 7% of the terrain splits and 13% of the group splits gain more per ms
 * than the step above them, all for these reasons, none on the flyover's chains.
 */
#include "world_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define WORLD_PI 3.14159265358979323846

/* Group impostors: triangles per represented object, capped at this many objects,
 * so an impostor of a large region costs the same as one of a leaf. */
#define WORLD_IMPOSTOR_TRIANGLES_PER_OBJECT 64u
#define WORLD_IMPOSTOR_MAX_OBJECTS 8u
/* A quadtree deeper than this would only come from (near-)coincident objects. */
#define WORLD_MAX_QUADTREE_DEPTH 24u

/* ------------------------------------------------------------------------- */
/* Random numbers: PCG32 (O'Neill 2014), deterministic on every platform.     */
/* ------------------------------------------------------------------------- */

typedef struct world_rng {
    uint64_t state;
    uint64_t inc;
} world_rng;

static uint32_t rng_next(world_rng *r) {
    uint64_t old = r->state;
    uint32_t xorshifted, rot;
    r->state = old * 6364136223846793005ull + r->inc;
    xorshifted = (uint32_t)(((old >> 18) ^ old) >> 27);
    rot = (uint32_t)(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

static void rng_seed(world_rng *r, uint64_t seed) {
    r->state = 0;
    r->inc = (seed << 1) | 1u;
    (void)rng_next(r);
    r->state += 0x853c49e6748fea9bull ^ seed;
    (void)rng_next(r);
}

/* Uniform in [0, 1), 24 bits: exact in float. */
static float rng_unit(world_rng *r) {
    return (float)(rng_next(r) >> 8) * (1.0f / 16777216.0f);
}

static float rng_range(world_rng *r, float lo, float hi) {
    return lo + (hi - lo) * rng_unit(r);
}

static uint32_t rng_range_u32(world_rng *r, uint32_t lo, uint32_t hi) {
    /* hi - lo is small here; the modulo bias is irrelevant for scene building */
    return lo + rng_next(r) % (hi - lo);
}

/* ------------------------------------------------------------------------- */
/* Defaults                                                                  */
/* ------------------------------------------------------------------------- */

void world_cost_model_default(world_cost_model *m) {
    m->ms_per_triangle = 1e-6;
    m->ms_per_draw = 5e-4;
}

void world_random_desc_default(world_random_desc *d) {
    memset(d, 0, sizeof(*d));
    d->objects = 10000;
    d->levels = 4;
    d->leaf_objects = 8;
    d->spacing = 25.0f;
    d->seed = 1;
    world_cost_model_default(&d->cost);
}

void world_flyover_desc_default(world_flyover_desc *d) {
    memset(d, 0, sizeof(*d));
    d->terrain_depth = 6;
    d->patch_triangles = 2048;
    d->side = 4096.0f;
    d->height = 300.0f;
    d->objects = 5000;
    d->levels = 6;
    d->seed = 7;
    world_cost_model_default(&d->cost);
}

static int cost_model_valid(const world_cost_model *m) {
    return isfinite(m->ms_per_triangle) && m->ms_per_triangle > 0.0 && isfinite(m->ms_per_draw) &&
           m->ms_per_draw >= 0.0;
}

/* ------------------------------------------------------------------------- */
/* Growing the world node by node                                            */
/* ------------------------------------------------------------------------- */

static void *grow(void *p, size_t count, size_t size) {
    if (count > SIZE_MAX / size)
        return NULL;
    return realloc(p, count * size);
}

typedef struct world_builder {
    world_scene *w;
    uint32_t capacity;
    tclod_id *parent; /* build-time only: the group heights are found bottom-up */
    world_cost_model cost;
} world_builder;

/* The world's per-node arrays with room for cap nodes; each array is replaced
 * as soon as it has grown, so a failure leaks nothing. */
static tclod_status grow_node_arrays(world_scene *w, uint32_t cap) {
    void *p;
    if (!(p = grow(w->kind, cap, sizeof(*w->kind))))
        return TCLOD_ERR_NOMEM;
    w->kind = (uint8_t *)p;
    if (!(p = grow(w->level, cap, sizeof(*w->level))))
        return TCLOD_ERR_NOMEM;
    w->level = (uint8_t *)p;
    if (!(p = grow(w->triangles, cap, sizeof(*w->triangles))))
        return TCLOD_ERR_NOMEM;
    w->triangles = (uint32_t *)p;
    if (!(p = grow(w->weight, cap, sizeof(*w->weight))))
        return TCLOD_ERR_NOMEM;
    w->weight = (float *)p;
    if (!(p = grow(w->cost_ms, cap, sizeof(*w->cost_ms))))
        return TCLOD_ERR_NOMEM;
    w->cost_ms = (float *)p;
    if (!(p = grow(w->bounds, cap, 4u * sizeof(*w->bounds))))
        return TCLOD_ERR_NOMEM;
    w->bounds = (float *)p;
    return TCLOD_OK;
}

static tclod_status builder_reserve(world_builder *b, uint32_t need) {
    world_scene *w = b->w;
    uint32_t cap;
    void *p;
    if (need <= b->capacity)
        return TCLOD_OK;
    cap = b->capacity ? b->capacity : 1024u;
    while (cap < need)
        cap = cap > UINT32_MAX / 2u ? UINT32_MAX : cap * 2u;
    if (grow_node_arrays(w, cap) != TCLOD_OK)
        return TCLOD_ERR_NOMEM;
    if (!(p = grow(b->parent, cap, sizeof(*b->parent))))
        return TCLOD_ERR_NOMEM;
    b->parent = (tclod_id *)p;
    b->capacity = cap;
    return TCLOD_OK;
}

static tclod_status builder_add(world_builder *b, tclod_id parent, const float bounds[4],
                                world_kind kind, uint32_t level, uint32_t triangles, float weight,
                                tclod_id *out_id) {
    world_scene *w = b->w;
    tclod_id id;
    tclod_status st;
    if (w->node_count == UINT32_MAX - 1u)
        return TCLOD_ERR_NOMEM;
    st = builder_reserve(b, w->node_count + 1u);
    if (st != TCLOD_OK)
        return st;
    st = tclod_scene_add_node(w->scene, parent, bounds, &id);
    if (st != TCLOD_OK)
        return st;
    if (id != w->node_count)
        return TCLOD_ERR_STATE; /* ids are dense, in creation order */
    w->kind[id] = (uint8_t)kind;
    w->level[id] = (uint8_t)level;
    w->triangles[id] = triangles;
    w->weight[id] = weight;
    w->cost_ms[id] = (float)(b->cost.ms_per_draw + b->cost.ms_per_triangle * (double)triangles);
    memcpy(w->bounds + 4u * (size_t)id, bounds, 4u * sizeof(float));
    b->parent[id] = parent;
    if (parent == TCLOD_NONE)
        w->root_count++;
    w->node_count = id + 1u;
    if (out_id)
        *out_id = id;
    return TCLOD_OK;
}

/* Accuracy of object level k: 1 − 2^−(k+1). */
static float level_accuracy(uint32_t k) {
    return 1.0f - ldexpf(1.0f, -(int)(k + 1u));
}

/* Adds object i as a chain of w->levels nodes below parent (TCLOD_NONE: own root). */
static tclod_status builder_add_object(world_builder *b, tclod_id parent, uint32_t i,
                                       uint32_t base_triangles) {
    world_scene *w = b->w;
    const float *bounds = w->object_bounds + 4u * (size_t)i;
    uint32_t k, triangles = base_triangles;
    tclod_id id = parent;
    tclod_status st;
    for (k = 0; k < w->levels; ++k) {
        st = builder_add(b, id, bounds, WORLD_KIND_OBJECT, k, triangles, level_accuracy(k), &id);
        if (st != TCLOD_OK)
            return st;
        if (k == 0)
            w->object_root[i] = id;
        triangles *= 4u;
    }
    return TCLOD_OK;
}

static void builder_finish(world_builder *b) {
    free(b->parent);
    b->parent = NULL;
}

static tclod_status world_begin(world_scene *out, world_builder *b, uint32_t objects,
                                uint32_t levels, const world_cost_model *cost,
                                const tclod_allocator *alloc) {
    tclod_status st;
    memset(out, 0, sizeof(*out));
    memset(b, 0, sizeof(*b));
    b->w = out;
    b->cost = *cost;
    out->levels = levels;
    out->object_count = objects;
    /* at least one element: calloc(0) may return NULL */
    out->object_root = (tclod_id *)calloc(objects ? objects : 1u, sizeof(*out->object_root));
    out->object_bounds = (float *)calloc((size_t)(objects ? objects : 1u) * 4u, sizeof(float));
    if (!out->object_root || !out->object_bounds)
        return TCLOD_ERR_NOMEM;
    st = tclod_scene_create(alloc, &out->scene);
    return st;
}

void world_scene_free(world_scene *w) {
    if (!w)
        return;
    tclod_scene_destroy(w->scene);
    free(w->kind);
    free(w->level);
    free(w->triangles);
    free(w->weight);
    free(w->cost_ms);
    free(w->bounds);
    free(w->object_root);
    free(w->object_bounds);
    free(w->object_nodes);
    memset(w, 0, sizeof(*w));
}

/* ------------------------------------------------------------------------- */
/* Random world                                                              */
/* ------------------------------------------------------------------------- */

/* A quadtree cell waiting for its group node: objects order[begin, end). */
typedef struct world_cell {
    float x0, z0, size;
    uint32_t begin, end;
    uint32_t depth;
    tclod_id parent;
} world_cell;

/* Moves the entries of order[begin, end) whose coordinate (0 = x, 2 = z) is below
 * split to the front; returns the first index of the rest. */
static uint32_t partition_objects(uint32_t *order, const float *bounds, uint32_t begin,
                                  uint32_t end, int axis, float split) {
    uint32_t i = begin, j = end;
    while (i < j) {
        if (bounds[4u * (size_t)order[i] + (uint32_t)axis] < split) {
            ++i;
        } else {
            uint32_t t = order[i];
            order[i] = order[--j];
            order[j] = t;
        }
    }
    return i;
}

/* Bounding sphere of objects order[begin, end) and the share of it they fill. */
static void group_sphere(const world_scene *w, const uint32_t *order, uint32_t begin, uint32_t end,
                         float out_bounds[4], float *out_cover) {
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float centre[3], radius = 0.0f;
    double area = 0.0;
    uint32_t i;
    int a;
    for (i = begin; i < end; ++i) {
        const float *ob = w->object_bounds + 4u * (size_t)order[i];
        for (a = 0; a < 3; ++a) {
            if (ob[a] - ob[3] < lo[a])
                lo[a] = ob[a] - ob[3];
            if (ob[a] + ob[3] > hi[a])
                hi[a] = ob[a] + ob[3];
        }
    }
    for (a = 0; a < 3; ++a)
        centre[a] = 0.5f * (lo[a] + hi[a]);
    for (i = begin; i < end; ++i) {
        const float *ob = w->object_bounds + 4u * (size_t)order[i];
        float dx = ob[0] - centre[0], dy = ob[1] - centre[1], dz = ob[2] - centre[2];
        float r = sqrtf(dx * dx + dy * dy + dz * dz) + ob[3];
        if (r > radius)
            radius = r;
        area += (double)ob[3] * (double)ob[3];
    }
    out_bounds[0] = centre[0];
    out_bounds[1] = centre[1];
    out_bounds[2] = centre[2];
    out_bounds[3] = radius;
    *out_cover = radius > 0.0f ? (float)(area / ((double)radius * (double)radius)) : 1.0f;
    if (*out_cover > 1.0f)
        *out_cover = 1.0f;
}

/* Group weights need the group's height above its objects, known only once the
 * subtree exists: parents precede children, so one backward pass finds it. */
static tclod_status finish_group_weights(world_builder *b) {
    world_scene *w = b->w;
    uint8_t *height = (uint8_t *)calloc(w->node_count ? w->node_count : 1u, 1);
    uint32_t id;
    if (!height)
        return TCLOD_ERR_NOMEM;
    for (id = w->node_count; id-- > 0;) {
        tclod_id p = b->parent[id];
        int counts = w->kind[id] == WORLD_KIND_GROUP ||
                     (w->kind[id] == WORLD_KIND_OBJECT && w->level[id] == 0);
        if (counts && p != TCLOD_NONE && w->kind[p] == WORLD_KIND_GROUP &&
            height[p] < height[id] + 1u)
            height[p] = (uint8_t)(height[id] + 1u);
    }
    for (id = 0; id < w->node_count; ++id)
        if (w->kind[id] == WORLD_KIND_GROUP)
            w->weight[id] *= 0.25f * ldexpf(1.0f, -(int)height[id]);
    free(height);
    return TCLOD_OK;
}

static tclod_status build_random(const world_random_desc *d, world_scene *out, world_builder *b) {
    world_rng rng;
    uint32_t *order = NULL, *base_triangles = NULL;
    world_cell *queue = NULL;
    size_t queue_head = 0, queue_tail = 0, queue_cap = 0;
    tclod_status st;
    uint32_t i;
    float side = d->spacing * sqrtf((float)d->objects);

    st = world_begin(out, b, d->objects, d->levels, &d->cost, d->alloc);
    if (st != TCLOD_OK)
        return st;
    out->side = side;
    order = (uint32_t *)malloc((size_t)d->objects * sizeof(*order));
    base_triangles = (uint32_t *)malloc((size_t)d->objects * sizeof(*base_triangles));
    if (!order || !base_triangles) {
        st = TCLOD_ERR_NOMEM;
        goto done;
    }

    /* Objects: 2–8 m radius resting on the ground, 512–2047 triangles at level 0
     * (keeps the returns diminishing from leaf group to objects, see the file comment). */
    rng_seed(&rng, d->seed);
    for (i = 0; i < d->objects; ++i) {
        float *ob = out->object_bounds + 4u * (size_t)i;
        ob[0] = rng_range(&rng, 0.0f, side);
        ob[2] = rng_range(&rng, 0.0f, side);
        ob[3] = rng_range(&rng, 2.0f, 8.0f);
        ob[1] = ob[3];
        base_triangles[i] = rng_range_u32(&rng, 512u, 2048u);
        order[i] = i;
    }

    /* Breadth-first over the quadtree with an explicit queue: a group is added
     * when its cell is taken from the queue, so parents always precede children. */
    queue_cap = 64;
    queue = (world_cell *)malloc(queue_cap * sizeof(*queue));
    if (!queue) {
        st = TCLOD_ERR_NOMEM;
        goto done;
    }
    queue[queue_tail].x0 = 0.0f;
    queue[queue_tail].z0 = 0.0f;
    queue[queue_tail].size = side;
    queue[queue_tail].begin = 0;
    queue[queue_tail].end = d->objects;
    queue[queue_tail].depth = 0;
    queue[queue_tail].parent = TCLOD_NONE;
    ++queue_tail;
    while (queue_head < queue_tail) {
        world_cell cell = queue[queue_head++];
        uint32_t n = cell.end - cell.begin;
        float bounds[4], cover;
        tclod_id group;
        group_sphere(out, order, cell.begin, cell.end, bounds, &cover);
        st = builder_add(b, cell.parent, bounds, WORLD_KIND_GROUP, cell.depth,
                         WORLD_IMPOSTOR_TRIANGLES_PER_OBJECT *
                             (n < WORLD_IMPOSTOR_MAX_OBJECTS ? n : WORLD_IMPOSTOR_MAX_OBJECTS),
                         cover, &group);
        if (st != TCLOD_OK)
            goto done;
        out->group_count++;
        if (n <= d->leaf_objects || cell.depth >= WORLD_MAX_QUADTREE_DEPTH) {
            for (i = cell.begin; i < cell.end; ++i) {
                st = builder_add_object(b, group, order[i], base_triangles[order[i]]);
                if (st != TCLOD_OK)
                    goto done;
            }
        } else {
            float half = 0.5f * cell.size;
            uint32_t split_x = partition_objects(order, out->object_bounds, cell.begin, cell.end, 0,
                                                 cell.x0 + half);
            uint32_t split_lo = partition_objects(order, out->object_bounds, cell.begin, split_x, 2,
                                                  cell.z0 + half);
            uint32_t split_hi =
                partition_objects(order, out->object_bounds, split_x, cell.end, 2, cell.z0 + half);
            /* order[] now holds, one after another, the quadrants (x low, z low),
             * (x low, z high), (x high, z low), (x high, z high) */
            uint32_t edges[5];
            int q;
            edges[0] = cell.begin;
            edges[1] = split_lo;
            edges[2] = split_x;
            edges[3] = split_hi;
            edges[4] = cell.end;
            for (q = 0; q < 4; ++q) {
                if (edges[q] == edges[q + 1])
                    continue; /* empty quadrants get no node */
                if (queue_tail == queue_cap) {
                    world_cell *p = (world_cell *)grow(queue, queue_cap * 2u, sizeof(*queue));
                    if (!p) {
                        st = TCLOD_ERR_NOMEM;
                        goto done;
                    }
                    queue = p;
                    queue_cap *= 2u;
                }
                queue[queue_tail].x0 = cell.x0 + (float)(q >> 1) * half;
                queue[queue_tail].z0 = cell.z0 + (float)(q & 1) * half;
                queue[queue_tail].size = half;
                queue[queue_tail].begin = edges[q];
                queue[queue_tail].end = edges[q + 1];
                queue[queue_tail].depth = cell.depth + 1u;
                queue[queue_tail].parent = group;
                ++queue_tail;
            }
        }
    }
    st = finish_group_weights(b);
    if (st != TCLOD_OK)
        goto done;

    /* The bench's loop: 30% of the side from the centre, at 8% of the side in the
     * air, pitched 20° down, seeing up to 70% of the side ahead. Scaling the loop
     * with the world keeps the share of the world in view the same at every N. */
    out->path.centre[0] = 0.5f * side;
    out->path.centre[1] = 0.5f * side;
    out->path.radius = 0.30f * side;
    out->path.wobble = 0.05f * side;
    out->path.altitude = 0.08f * side;
    out->path.altitude_swing = 0.02f * side;
    out->path.pitch = 0.35f;
    out->path.fov_y = 1.0471976f;
    out->path.aspect = 16.0f / 9.0f;
    out->path.near_z = 1.0f;
    out->path.far_z = 0.70f * side;
    out->path.viewport_height = 1080.0f;

done:
    free(queue);
    free(order);
    free(base_triangles);
    return st;
}

tclod_status world_build_random(const world_random_desc *d, world_scene *out) {
    world_builder b;
    tclod_status st;
    if (out)
        memset(out, 0, sizeof(*out));
    if (!d || !out || d->objects == 0 || d->levels < 1 || d->levels > 8 || d->leaf_objects < 1 ||
        d->leaf_objects > 8 || !isfinite(d->spacing) || !(d->spacing > 0.0f) ||
        !cost_model_valid(&d->cost))
        return TCLOD_ERR_ARG;
    /* level L−1 has T0·4^(L−1) <= 2047·4^7 triangles: fits in uint32_t */
    st = build_random(d, out, &b);
    builder_finish(&b);
    if (st == TCLOD_OK)
        st = tclod_scene_prepare(out->scene);
    if (st != TCLOD_OK)
        world_scene_free(out);
    return st;
}

/* ------------------------------------------------------------------------- */
/* Flyover world                                                             */
/* ------------------------------------------------------------------------- */

float world_terrain_height(float x, float z, float side, float height) {
    /* amplitudes sum to 0.5, so the relief stays within [0, height] */
    const double k = 2.0 * WORLD_PI / (double)side;
    double u = (double)x * k, v = (double)z * k;
    double h = 0.5 + 0.25 * sin(u + 0.3) * cos(v - 0.7) + 0.15 * sin(3.0 * (u + v) + 1.1) +
               0.10 * cos(5.0 * u - 1.9) * sin(4.0 * v + 0.4);
    return (float)(h * (double)height);
}

/* Height range of each patch at every depth, leaves sampled on a 9×9 grid, parents
 * the union of their children. minmax[depth] holds 2 floats per patch, row-major
 * (iz · 2^depth + ix). */
static float **terrain_ranges(const world_flyover_desc *d) {
    uint32_t depth = d->terrain_depth, n = 1u << depth, ix, iz, s, t;
    float **minmax = (float **)calloc(depth + 1u, sizeof(*minmax));
    float patch = d->side / (float)n;
    uint32_t level;
    if (!minmax)
        return NULL;
    for (level = 0; level <= depth; ++level) {
        size_t cells = (size_t)1 << (2u * level);
        minmax[level] = (float *)malloc(cells * 2u * sizeof(float));
        if (!minmax[level]) {
            for (t = 0; t <= level; ++t)
                free(minmax[t]);
            free(minmax);
            return NULL;
        }
    }
    for (iz = 0; iz < n; ++iz) {
        for (ix = 0; ix < n; ++ix) {
            float lo = INFINITY, hi = -INFINITY;
            for (s = 0; s <= 8u; ++s) {
                for (t = 0; t <= 8u; ++t) {
                    float h = world_terrain_height(((float)ix + (float)s / 8.0f) * patch,
                                                   ((float)iz + (float)t / 8.0f) * patch, d->side,
                                                   d->height);
                    if (h < lo)
                        lo = h;
                    if (h > hi)
                        hi = h;
                }
            }
            /* the grid can miss a crest between samples: a small margin covers it */
            minmax[depth][2u * ((size_t)iz * n + ix)] = lo - 0.01f * d->height;
            minmax[depth][2u * ((size_t)iz * n + ix) + 1u] = hi + 0.01f * d->height;
        }
    }
    for (level = depth; level-- > 0;) {
        uint32_t m = 1u << level;
        for (iz = 0; iz < m; ++iz) {
            for (ix = 0; ix < m; ++ix) {
                float lo = INFINITY, hi = -INFINITY;
                for (s = 0; s < 4u; ++s) {
                    size_t c = (size_t)(2u * iz + (s >> 1)) * (2u * m) + (2u * ix + (s & 1u));
                    if (minmax[level + 1u][2u * c] < lo)
                        lo = minmax[level + 1u][2u * c];
                    if (minmax[level + 1u][2u * c + 1u] > hi)
                        hi = minmax[level + 1u][2u * c + 1u];
                }
                minmax[level][2u * ((size_t)iz * m + ix)] = lo;
                minmax[level][2u * ((size_t)iz * m + ix) + 1u] = hi;
            }
        }
    }
    return minmax;
}

/* Terrain patches, level by level (parents first). prev/next hold the node ids of
 * one level in row-major patch order. */
static tclod_status build_terrain(const world_flyover_desc *d, world_builder *b) {
    world_scene *w = b->w;
    uint32_t depth = d->terrain_depth, level, ix, iz;
    float **minmax = terrain_ranges(d);
    tclod_id *prev = NULL, *next = NULL;
    tclod_status st = TCLOD_OK;
    size_t leaves = (size_t)1 << (2u * depth);
    if (!minmax)
        return TCLOD_ERR_NOMEM;
    prev = (tclod_id *)malloc(leaves * sizeof(*prev));
    next = (tclod_id *)malloc(leaves * sizeof(*next));
    if (!prev || !next) {
        st = TCLOD_ERR_NOMEM;
        goto done;
    }
    for (level = 0; level <= depth && st == TCLOD_OK; ++level) {
        uint32_t m = 1u << level;
        float patch = d->side / (float)m;
        float weight = ldexpf(1.0f, (int)level - (int)depth);
        tclod_id *swap;
        for (iz = 0; iz < m && st == TCLOD_OK; ++iz) {
            for (ix = 0; ix < m; ++ix) {
                size_t c = (size_t)iz * m + ix;
                float lo = minmax[level][2u * c], hi = minmax[level][2u * c + 1u];
                float half = 0.5f * patch, half_h = 0.5f * (hi - lo);
                float bounds[4];
                tclod_id parent =
                    level == 0 ? TCLOD_NONE : prev[(size_t)(iz / 2u) * (m / 2u) + ix / 2u];
                bounds[0] = ((float)ix + 0.5f) * patch;
                bounds[1] = 0.5f * (lo + hi);
                bounds[2] = ((float)iz + 0.5f) * patch;
                bounds[3] = sqrtf(2.0f * half * half + half_h * half_h);
                st = builder_add(b, parent, bounds, WORLD_KIND_TERRAIN, level, d->patch_triangles,
                                 weight, &next[c]);
                if (st != TCLOD_OK)
                    break;
                w->terrain_count++;
            }
        }
        swap = prev;
        prev = next;
        next = swap;
    }
done:
    free(prev);
    free(next);
    for (level = 0; level <= depth; ++level)
        free(minmax[level]);
    free(minmax);
    return st;
}

static tclod_status build_flyover(const world_flyover_desc *d, world_scene *out, world_builder *b) {
    world_rng rng;
    uint32_t i;
    float margin = 0.02f * d->side;
    tclod_status st = world_begin(out, b, d->objects, d->levels, &d->cost, d->alloc);
    if (st != TCLOD_OK)
        return st;
    out->side = d->side;
    st = build_terrain(d, b);
    if (st != TCLOD_OK)
        return st;

    /* 70% trees (3–8 m, 256–511 triangles at level 0), 30% buildings (8–20 m,
     * 512–1023 triangles), standing on the terrain, each its own hierarchy. */
    rng_seed(&rng, d->seed);
    for (i = 0; i < d->objects; ++i) {
        float *ob = out->object_bounds + 4u * (size_t)i;
        int tree = rng_unit(&rng) < 0.7f;
        uint32_t triangles =
            tree ? rng_range_u32(&rng, 256u, 512u) : rng_range_u32(&rng, 512u, 1024u);
        ob[0] = rng_range(&rng, margin, d->side - margin);
        ob[2] = rng_range(&rng, margin, d->side - margin);
        ob[3] = tree ? rng_range(&rng, 3.0f, 8.0f) : rng_range(&rng, 8.0f, 20.0f);
        ob[1] = world_terrain_height(ob[0], ob[2], d->side, d->height) + 0.7f * ob[3];
        st = builder_add_object(b, TCLOD_NONE, i, triangles);
        if (st != TCLOD_OK)
            return st;
    }

    /* A loop over the middle of the terrain, 120 m (± 40 m) above its highest point,
     * looking ahead and 11° down, seeing 3/4 of the terrain's side ahead. */
    out->path.centre[0] = 0.5f * d->side;
    out->path.centre[1] = 0.5f * d->side;
    out->path.radius = 0.32f * d->side;
    out->path.wobble = 0.06f * d->side;
    out->path.altitude = d->height + 120.0f;
    out->path.altitude_swing = 40.0f;
    out->path.pitch = 0.2f;
    out->path.fov_y = 1.0471976f;
    out->path.aspect = 16.0f / 9.0f;
    out->path.near_z = 1.0f;
    out->path.far_z = 0.75f * d->side;
    out->path.viewport_height = 1080.0f;
    return TCLOD_OK;
}

tclod_status world_build_flyover(const world_flyover_desc *d, world_scene *out) {
    world_builder b;
    tclod_status st;
    if (out)
        memset(out, 0, sizeof(*out));
    if (!d || !out || d->terrain_depth > 10 || d->patch_triangles == 0 || d->levels < 1 ||
        d->levels > 8 || !isfinite(d->side) || !(d->side > 0.0f) || !isfinite(d->height) ||
        d->height < 0.0f || !cost_model_valid(&d->cost))
        return TCLOD_ERR_ARG;
    st = build_flyover(d, out, &b);
    builder_finish(&b);
    if (st == TCLOD_OK)
        st = tclod_scene_prepare(out->scene);
    if (st != TCLOD_OK)
        world_scene_free(out);
    return st;
}

/* ------------------------------------------------------------------------- */
/* Edits between frames                                                      */
/* ------------------------------------------------------------------------- */

/* Grows every per-node array to hold `need` entries (doubling, so that a world that
 * gains a few nodes a frame reallocates rarely). A built world's arrays hold at least
 * node_count entries (its builder's capacity is not kept), hence that default. */
static tclod_status edit_reserve_nodes(world_scene *w, uint32_t need) {
    uint32_t cap = w->node_capacity > w->node_count ? w->node_capacity : w->node_count;
    if (need <= cap)
        return TCLOD_OK;
    if (cap < 1024u)
        cap = 1024u;
    while (cap < need)
        cap = cap > UINT32_MAX / 2u ? UINT32_MAX : cap * 2u;
    if (grow_node_arrays(w, cap) != TCLOD_OK)
        return TCLOD_ERR_NOMEM;
    w->node_capacity = cap;
    return TCLOD_OK;
}

/* The per-object arrays with room for `need` objects, and object_nodes filled in for
 * the objects as built (their levels have consecutive ids from object_root) on the
 * first edit. */
static tclod_status edit_reserve_objects(world_scene *w, uint32_t need) {
    uint32_t cap = w->object_capacity > w->object_count ? w->object_capacity : w->object_count;
    size_t levels = w->levels;
    void *p;
    if (!w->object_nodes) {
        uint32_t i, k;
        tclod_id *nodes = (tclod_id *)malloc((cap ? cap : 1u) * levels * sizeof(*nodes));
        if (!nodes)
            return TCLOD_ERR_NOMEM;
        for (i = 0; i < w->object_count; ++i)
            for (k = 0; k < w->levels; ++k)
                nodes[levels * i + k] = w->object_root[i] + k;
        w->object_nodes = nodes;
        w->object_capacity = cap;
    }
    if (need <= cap)
        return TCLOD_OK;
    if (cap < 64u)
        cap = 64u;
    while (cap < need)
        cap = cap > UINT32_MAX / 2u ? UINT32_MAX : cap * 2u;
    if (!(p = grow(w->object_root, cap, sizeof(*w->object_root))))
        return TCLOD_ERR_NOMEM;
    w->object_root = (tclod_id *)p;
    if (!(p = grow(w->object_bounds, cap, 4u * sizeof(*w->object_bounds))))
        return TCLOD_ERR_NOMEM;
    w->object_bounds = (float *)p;
    if (!(p = grow(w->object_nodes, cap, levels * sizeof(*w->object_nodes))))
        return TCLOD_ERR_NOMEM;
    w->object_nodes = (tclod_id *)p;
    w->object_capacity = cap;
    return TCLOD_OK;
}

static int edit_bounds_valid(const float b[4]) {
    return b && isfinite(b[0]) && isfinite(b[1]) && isfinite(b[2]) && isfinite(b[3]) &&
           b[3] >= 0.0f;
}

tclod_id world_object_level(const world_scene *w, uint32_t i, uint32_t k) {
    if (i >= w->object_count || k >= w->levels)
        return TCLOD_NONE;
    return w->object_nodes ? w->object_nodes[(size_t)w->levels * i + k] : w->object_root[i] + k;
}

tclod_status world_add_object(world_scene *w, tclod_id parent, const float bounds[4],
                              uint32_t base_triangles, const world_cost_model *model,
                              uint32_t *out_object) {
    tclod_id ids[8], id = parent;
    uint32_t k, triangles = base_triangles, i, count;
    tclod_status st;
    if (!w || !w->scene || !edit_bounds_valid(bounds) || !model || !cost_model_valid(model) ||
        w->levels < 1u || w->levels > 8u || w->object_count == UINT32_MAX ||
        base_triangles > UINT32_MAX >> (2u * (w->levels - 1u)))
        return TCLOD_ERR_ARG;
    st = edit_reserve_objects(w, w->object_count + 1u);
    if (st != TCLOD_OK)
        return st;
    /* every level may take a fresh id at the end */
    count = tclod_scene_node_count(w->scene);
    if (count > UINT32_MAX - 1u - w->levels)
        return TCLOD_ERR_NOMEM;
    st = edit_reserve_nodes(w, count + w->levels);
    if (st != TCLOD_OK)
        return st;
    for (k = 0; k < w->levels; ++k) {
        st = tclod_scene_add_node(w->scene, id, bounds, &id);
        if (st != TCLOD_OK) {
            /* the levels added so far go with level 0, so that nothing changed */
            if (k > 0)
                (void)tclod_scene_remove_node(w->scene, ids[0]);
            return st;
        }
        ids[k] = id;
    }
    for (k = 0; k < w->levels; ++k, triangles *= 4u) {
        id = ids[k];
        w->kind[id] = (uint8_t)WORLD_KIND_OBJECT;
        w->level[id] = (uint8_t)k;
        w->triangles[id] = triangles;
        w->weight[id] = level_accuracy(k);
        w->cost_ms[id] = (float)(model->ms_per_draw + model->ms_per_triangle * (double)triangles);
        memcpy(w->bounds + 4u * (size_t)id, bounds, 4u * sizeof(float));
    }
    i = w->object_count++;
    w->object_root[i] = ids[0];
    memcpy(w->object_bounds + 4u * (size_t)i, bounds, 4u * sizeof(float));
    memcpy(w->object_nodes + (size_t)w->levels * i, ids, w->levels * sizeof(tclod_id));
    w->node_count = tclod_scene_node_count(w->scene);
    if (parent == TCLOD_NONE)
        w->root_count++;
    if (out_object)
        *out_object = i;
    return TCLOD_OK;
}

tclod_status world_remove_object(world_scene *w, uint32_t i) {
    uint32_t last;
    size_t levels;
    tclod_id root, parent;
    tclod_status st;
    if (!w || !w->scene || i >= w->object_count)
        return TCLOD_ERR_ARG;
    st = edit_reserve_objects(w, w->object_count);
    if (st != TCLOD_OK)
        return st;
    levels = w->levels;
    root = w->object_nodes[levels * i];
    parent = tclod_scene_parent(w->scene, root);
    st = tclod_scene_remove_node(w->scene, root);
    if (st != TCLOD_OK)
        return st;
    if (parent == TCLOD_NONE)
        w->root_count--;
    last = --w->object_count;
    if (i != last) {
        w->object_root[i] = w->object_root[last];
        memcpy(w->object_bounds + 4u * (size_t)i, w->object_bounds + 4u * (size_t)last,
               4u * sizeof(float));
        memcpy(w->object_nodes + levels * i, w->object_nodes + levels * last,
               levels * sizeof(tclod_id));
    }
    return TCLOD_OK;
}

tclod_status world_move_object(world_scene *w, uint32_t i, const float bounds[4]) {
    tclod_bounds b;
    uint32_t k;
    if (!w || !w->scene || i >= w->object_count || !edit_bounds_valid(bounds))
        return TCLOD_ERR_ARG;
    b = tclod_bounds_sphere((double)bounds[0], (double)bounds[1], (double)bounds[2],
                            (double)bounds[3]);
    for (k = 0; k < w->levels; ++k) {
        tclod_id id = world_object_level(w, i, k);
        /* valid bounds of a live node: only a solve under way can refuse, and it
         * refuses the first level already */
        tclod_status st = tclod_scene_set_node_bounds(w->scene, id, &b);
        if (st != TCLOD_OK)
            return st;
        memcpy(w->bounds + 4u * (size_t)id, bounds, 4u * sizeof(float));
    }
    memcpy(w->object_bounds + 4u * (size_t)i, bounds, 4u * sizeof(float));
    return TCLOD_OK;
}

/* ------------------------------------------------------------------------- */
/* Camera loop                                                               */
/* ------------------------------------------------------------------------- */

double world_float(double x) {
    /* through memory the compiler cannot keep in a register: some optimisers
     * (GCC 12's vectoriser) drop a double -> float -> double conversion */
    volatile float f = (float)x;
    return (double)f;
}

void world_camera_at(const world_path *p, double t, tclod_view *view) {
    double theta = 2.0 * WORLD_PI * (t - floor(t));
    double r = (double)p->radius, wob = (double)p->wobble;
    double dx = -r * sin(theta) - 3.0 * wob * sin(3.0 * theta);
    double dz = r * cos(theta) - 2.0 * wob * cos(2.0 * theta);
    double len = sqrt(dx * dx + dz * dz);
    double cp = cos((double)p->pitch), sp = sin((double)p->pitch);
    view->eye[0] = world_float((double)p->centre[0] + r * cos(theta) + wob * cos(3.0 * theta));
    view->eye[1] = world_float((double)p->altitude + (double)p->altitude_swing * sin(2.0 * theta));
    view->eye[2] = world_float((double)p->centre[1] + r * sin(theta) - wob * sin(2.0 * theta));
    view->forward[0] = (float)(dx / len * cp);
    view->forward[1] = (float)-sp;
    view->forward[2] = (float)(dz / len * cp);
    view->up[0] = 0.0f;
    view->up[1] = 1.0f;
    view->up[2] = 0.0f;
    view->fov_y = p->fov_y;
    view->aspect = p->aspect;
    view->near_z = p->near_z;
    view->far_z = p->far_z;
    view->viewport_height = p->viewport_height;
}

/* ------------------------------------------------------------------------- */
/* Callbacks                                                                 */
/* ------------------------------------------------------------------------- */

/* benefit_work rounds of a hash of node id, kept in a volatile so that the
 * compiler computes them: a dear evaluation that changes no value. */
static void busy_work(uint32_t id, uint32_t rounds) {
    volatile uint32_t kept;
    uint32_t h = id, k;
    for (k = 0; k < rounds; ++k)
        h = h * 2654435761u + k;
    kept = h;
    (void)kept;
}

double world_benefit(void *user, const tclod_query *q) {
    const world_scene *w = (const world_scene *)user;
    float area = q->screen_area;
    if (w->benefit_work)
        busy_work(q->id, w->benefit_work);
    if (area < 0.0f) {
        float r = w->bounds[4u * (size_t)q->id + 3u];
        area = (float)WORLD_PI * r * r;
    }
    return (double)area * (double)w->weight[q->id];
}

double world_cost(void *user, const tclod_query *q) {
    const world_scene *w = (const world_scene *)user;
    return (double)w->cost_ms[q->id];
}

void world_benefit_batch(void *user, const tclod_batch *b, double *out) {
    const world_scene *w = (const world_scene *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i) {
        float area = b->screen_area[i];
        if (w->benefit_work)
            busy_work(b->ids[i], w->benefit_work);
        if (area < 0.0f) {
            float r = w->bounds[4u * (size_t)b->ids[i] + 3u];
            area = (float)WORLD_PI * r * r;
        }
        out[i] = (double)area * (double)w->weight[b->ids[i]];
    }
}

void world_cost_batch(void *user, const tclod_batch *b, double *out) {
    const world_scene *w = (const world_scene *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i)
        out[i] = (double)w->cost_ms[b->ids[i]];
}

double world_importance(void *user, const tclod_query *q) {
    const world_scene *w = (const world_scene *)user;
    return (double)w->weight[q->id];
}

tclod_callbacks world_callbacks(world_scene *w) {
    tclod_callbacks cb;
    memset(&cb, 0, sizeof(cb));
    cb.benefit = world_benefit;
    cb.cost = world_cost;
    cb.importance = world_importance;
    cb.user = w;
    return cb;
}

tclod_callbacks world_batch_callbacks(world_scene *w) {
    tclod_callbacks cb = world_callbacks(w);
    cb.benefit_batch = world_benefit_batch;
    cb.cost_batch = world_cost_batch;
    return cb;
}

const char *const world_feature_names[WORLD_FEATURES] = {"draws", "triangles"};

void world_features(void *user, const tclod_query *q, double *out) {
    const world_scene *w = (const world_scene *)user;
    out[WORLD_DRAWS] = 1.0;
    out[WORLD_TRIANGLES] = (double)w->triangles[q->id];
}

tclod_callbacks world_feature_callbacks(world_scene *w) {
    tclod_callbacks cb = world_callbacks(w);
    cb.cost = NULL;
    cb.features = world_features;
    return cb;
}

void world_sum_features(const world_scene *w, const tclod_id *ids, size_t n, double *out) {
    size_t i;
    out[WORLD_DRAWS] = (double)n;
    out[WORLD_TRIANGLES] = 0.0;
    for (i = 0; i < n; ++i)
        out[WORLD_TRIANGLES] += (double)w->triangles[ids[i]];
}

void world_feature_prior(const world_cost_model *m, double *out) {
    out[WORLD_DRAWS] = m->ms_per_draw;
    out[WORLD_TRIANGLES] = m->ms_per_triangle;
}

double world_sum_cost(const world_scene *w, const tclod_id *ids, size_t n) {
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        sum += (double)w->cost_ms[ids[i]];
    return sum;
}

uint32_t world_visible_objects(const world_scene *w, const tclod_view *view) {
    uint32_t i, n = 0;
    for (i = 0; i < w->object_count; ++i)
        n += (uint32_t)tclod_view_sphere_visible(view, w->object_bounds + 4u * (size_t)i);
    return n;
}
