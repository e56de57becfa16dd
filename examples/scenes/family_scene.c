/*
 * family_scene — random chains and hierarchies with integer costs in the knapsack
 * literature's families. See family_scene.h.
 */
#include "family_scene.h"

#include <stdlib.h>
#include <string.h>

/* A tree node's step is drawn again at most this many times to gain no more per unit of
 * cost than its parent's; after that the lowest-ratio draw is scaled down to the
 * parent's ratio, so every family keeps diminishing returns. */
#define FAMILY_TREE_DRAWS 32

void family_desc_default(family_desc *d, family_shape shape, family_kind kind) {
    memset(d, 0, sizeof *d);
    d->shape = shape;
    d->kind = kind;
    d->range = 100;
    if (shape == FAMILY_CHAINS) {
        d->objects_min = 10;
        d->objects_max = 100;
        d->levels_min = 3;
        d->levels_max = 6;
    } else {
        d->objects_min = 2;
        d->objects_max = 8;
        d->levels_min = 2;
        d->levels_max = 4;
    }
    d->children_min = 2;
    d->children_max = 4;
    d->leaf_chance = 25;
    d->max_nodes = 200;
}

const char *family_kind_name(family_kind k) {
    switch (k) {
    case FAMILY_UNCORRELATED:
        return "uncorrelated";
    case FAMILY_WEAKLY_CORRELATED:
        return "weak";
    case FAMILY_STRONGLY_CORRELATED:
        return "strong";
    case FAMILY_NOT_DIMINISHING:
        return "not_diminishing";
    }
    return "unknown";
}

const char *family_shape_name(family_shape s) {
    switch (s) {
    case FAMILY_CHAINS:
        return "chains";
    case FAMILY_TREES:
        return "trees";
    }
    return "unknown";
}

/* Uniform integer in [lo, hi]. */
static uint32_t family_between(table_rng *r, uint32_t lo, uint32_t hi) {
    return lo + table_rng_below(r, hi - lo + 1u);
}

/* One step (cost w, benefit p) of the family. */
static void family_step(const family_desc *d, table_rng *r, double *w, double *p) {
    uint32_t range = d->range, spread = d->range / 10u;
    uint32_t cost = family_between(r, 1u, range);
    *w = (double)cost;
    switch (d->kind) {
    case FAMILY_WEAKLY_CORRELATED: {
        uint32_t lo = cost > spread ? cost - spread : 1u;
        *p = (double)family_between(r, lo, cost + spread);
        break;
    }
    case FAMILY_STRONGLY_CORRELATED:
        *p = (double)(cost + spread);
        break;
    case FAMILY_UNCORRELATED:
    case FAMILY_NOT_DIMINISHING:
    default:
        *p = (double)family_between(r, 1u, range);
        break;
    }
}

static int family_valid(const family_desc *d) {
    if (d->shape != FAMILY_CHAINS && d->shape != FAMILY_TREES)
        return 0;
    if ((unsigned)d->kind >= FAMILY_KIND_COUNT || d->range < 10u || d->range > 1000000u)
        return 0;
    if (d->objects_min < 1u || d->objects_max < d->objects_min || d->objects_max > 1000000u)
        return 0;
    if (d->levels_min < 1u || d->levels_max < d->levels_min || d->levels_max > 16u)
        return 0;
    if (d->shape == FAMILY_TREES &&
        (d->children_min < 1u || d->children_max < d->children_min || d->children_max > 16u ||
         d->leaf_chance > 100u || d->max_nodes < d->objects_max))
        return 0;
    return 1;
}

/* Step pairs sorted by falling benefit per cost (ties: the cheaper first), the order in
 * which diminishing returns puts them along a chain. */
typedef struct family_pair {
    double w, p;
} family_pair;

static int family_by_ratio(const void *a, const void *b) {
    const family_pair *x = (const family_pair *)a, *y = (const family_pair *)b;
    double lhs = x->p * y->w, rhs = y->p * x->w; /* x->p / x->w vs y->p / y->w */
    if (lhs != rhs)
        return lhs > rhs ? -1 : 1;
    return (x->w > y->w) - (x->w < y->w);
}

static tclod_status family_chains(const family_desc *d, table_model *m, tclod_scene *s,
                                  table_rng *r) {
    uint32_t objects = family_between(r, d->objects_min, d->objects_max), o;
    family_pair steps[16];
    for (o = 0; o < objects; ++o) {
        uint32_t levels = family_between(r, d->levels_min, d->levels_max), k;
        double cost = 0.0, benefit = 0.0;
        tclod_id parent = TCLOD_NONE;
        for (k = 0; k < levels; ++k)
            family_step(d, r, &steps[k].w, &steps[k].p);
        /* Level 0 is drawn whatever it gains; only the steps after it are ordered. */
        if (d->kind != FAMILY_NOT_DIMINISHING && levels > 2u)
            qsort(steps + 1, levels - 1u, sizeof steps[0], family_by_ratio);
        for (k = 0; k < levels; ++k) {
            tclod_status st;
            cost += steps[k].w;
            benefit += steps[k].p;
            st = table_add_node(m, s, parent, NULL, benefit, cost, &parent);
            if (st != TCLOD_OK)
                return st;
        }
    }
    return TCLOD_OK;
}

/* Per node of a tree being built: its depth and the benefit per cost of its own step
 * (0 until it has one), indexed by position in the instance. */
typedef struct family_tree_node {
    uint32_t depth;
    double ratio;
} family_tree_node;

static tclod_status family_trees(const family_desc *d, table_model *m, tclod_scene *s,
                                 table_rng *r) {
    uint32_t roots = family_between(r, d->objects_min, d->objects_max);
    uint32_t depth_levels = family_between(r, d->levels_min, d->levels_max);
    uint32_t first = m->count, count = 0, next;
    family_tree_node *info;
    tclod_status st = TCLOD_OK;

    info = (family_tree_node *)malloc(d->max_nodes * sizeof *info);
    if (info == NULL)
        return TCLOD_ERR_NOMEM;
    for (count = 0; count < roots && st == TCLOD_OK; ++count) {
        double w, p;
        family_step(d, r, &w, &p);
        info[count].depth = 0;
        info[count].ratio = 0.0;
        st = table_add_node(m, s, TCLOD_NONE, NULL, p, w, NULL);
    }
    /* Breadth first: node `next` gets its children once every node before it has. */
    for (next = 0; next < count && st == TCLOD_OK; ++next) {
        tclod_id id = first + next;
        uint32_t k, c, tries;
        double w = 0.0, p = 0.0, total_cost, total_benefit, wsum = 0.0, psum = 0.0;
        double wshare[16], pshare[16], limit;
        uint32_t cost_left;
        if (info[next].depth + 1u >= depth_levels)
            continue;
        if (info[next].depth > 0u && table_rng_below(r, 100u) < d->leaf_chance)
            continue;
        k = family_between(r, d->children_min, d->children_max);
        if (count + k > d->max_nodes)
            continue;
        /* The step: within the parent's benefit per cost when the family diminishes. */
        limit = info[next].depth > 0u ? info[m->parent[id] - first].ratio : 0.0;
        for (tries = 0; tries < FAMILY_TREE_DRAWS; ++tries) {
            double tw, tp;
            family_step(d, r, &tw, &tp);
            if (tries == 0 || tp * w < p * tw) {
                w = tw;
                p = tp;
            }
            if (d->kind == FAMILY_NOT_DIMINISHING || limit == 0.0 || p <= limit * w)
                break;
        }
        if (d->kind != FAMILY_NOT_DIMINISHING && limit > 0.0 && p > limit * w)
            p = limit * w;
        /* The children's costs must be integers >= 1 that add up. */
        if (m->cost[id] + w < (double)k)
            w = (double)k - m->cost[id];
        info[next].ratio = p / w;
        total_cost = m->cost[id] + w;
        total_benefit = m->benefit[id] + p;
        for (c = 0; c < k; ++c) {
            wshare[c] = table_rng_uniform(r, 0.5, 1.5);
            pshare[c] = table_rng_uniform(r, 0.5, 1.5);
            wsum += wshare[c];
            psum += pshare[c];
        }
        /* Each child gets 1 plus its share of the rest, rounded down; the first children
         * take what rounding left over, one unit each. */
        cost_left = (uint32_t)total_cost - k;
        {
            uint32_t units[16], given = 0;
            for (c = 0; c < k; ++c) {
                units[c] = (uint32_t)((double)cost_left * (wshare[c] / wsum));
                given += units[c];
            }
            for (c = 0; given < cost_left; c = (c + 1u) % k, ++given)
                units[c]++;
            for (c = 0; c < k && st == TCLOD_OK; ++c) {
                info[count].depth = info[next].depth + 1u;
                info[count].ratio = 0.0;
                st = table_add_node(m, s, id, NULL, total_benefit * (pshare[c] / psum),
                                    (double)(units[c] + 1u), NULL);
                count++;
            }
        }
    }
    free(info);
    return st;
}

tclod_status family_build(const family_desc *d, table_model *m, tclod_scene *s, table_rng *r) {
    if (d == NULL || m == NULL || s == NULL || r == NULL || !family_valid(d))
        return TCLOD_ERR_ARG;
    return d->shape == FAMILY_CHAINS ? family_chains(d, m, s, r) : family_trees(d, m, s, r);
}
