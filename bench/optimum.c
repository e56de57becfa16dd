/*
 * optimum — exact optima of cut problems by dynamic programming over integer costs, and
 * the Lagrangian upper bound. See optimum.h.
 *
 * Tables: T_n[x] is the largest benefit of a cut of n's subtree whose cost is at most x
 * quanta, -inf when none is that cheap. A table is nondecreasing in x and is stored only
 * up to the most its subtree can cost (later entries repeat the last one), so small
 * subtrees keep small tables. The table of an inner node is the max-plus convolution of
 * its children's tables, raised to b_n from x = c_n on (the node drawn itself). A
 * convolution walks the breakpoints of the table that has fewer of them (the costs at
 * which it rises): between two breakpoints the table is flat, so only they can start a
 * best pair. With holes every table is at least 0 from x = 0 on: the subtree left
 * undrawn.
 */
#include "optimum.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest table: 2^24 quanta (128 MiB of doubles). */
#define OPTIMUM_MAX_UNITS 16777216.0
/* Largest cost of one node in quanta (fits the uint32_t arithmetic with room to add). */
#define OPTIMUM_MAX_NODE_UNITS 2147483648.0
/* Bisection steps of optimum_bound: lambda to about 2^-100 of its range. */
#define OPTIMUM_BOUND_STEPS 100

/* The forest of an instance: children contiguous per node, and a post-order (every node
 * after all of its descendants). */
typedef struct optimum_forest {
    uint32_t *child_first; /* count + 1 offsets into children */
    tclod_id *children;
    tclod_id *post;  /* count nodes, post-order */
    uint32_t *stack; /* scratch: count (node, cursor) pairs */
} optimum_forest;

static void optimum_forest_free(optimum_forest *f) {
    free(f->child_first);
    free(f->children);
    free(f->post);
    free(f->stack);
    memset(f, 0, sizeof *f);
}

static int optimum_value_ok(double v) {
    return v >= 0.0 && v < INFINITY;
}

/* Checks the values and builds the forest. */
static optimum_status optimum_forest_build(const optimum_instance *in, optimum_forest *f) {
    uint32_t n = in->count, i, emitted = 0, top;
    memset(f, 0, sizeof *f);
    if (in->parent == NULL || in->benefit == NULL || in->cost == NULL)
        return OPTIMUM_BAD_VALUE;
    for (i = 0; i < n; ++i)
        if ((in->parent[i] != TCLOD_NONE && in->parent[i] >= n) ||
            !optimum_value_ok(in->benefit[i]) || !optimum_value_ok(in->cost[i]))
            return OPTIMUM_BAD_VALUE;
    f->child_first = (uint32_t *)calloc((size_t)n + 2u, sizeof *f->child_first);
    f->children = (tclod_id *)malloc(((size_t)n + 1u) * sizeof *f->children);
    f->post = (tclod_id *)malloc(((size_t)n + 1u) * sizeof *f->post);
    f->stack = (uint32_t *)malloc(((size_t)n + 1u) * 2u * sizeof *f->stack);
    if (!f->child_first || !f->children || !f->post || !f->stack) {
        optimum_forest_free(f);
        return OPTIMUM_NOMEM;
    }
    /* Counting sort of the nodes by parent: children in id order. */
    for (i = 0; i < n; ++i)
        if (in->parent[i] != TCLOD_NONE)
            f->child_first[in->parent[i] + 2u]++;
    for (i = 0; i < n; ++i)
        f->child_first[i + 2u] += f->child_first[i + 1u];
    for (i = 0; i < n; ++i)
        if (in->parent[i] != TCLOD_NONE)
            f->children[f->child_first[in->parent[i] + 1u]++] = i;
    /* Depth-first from every root with an explicit stack of (node, next child). */
    for (i = 0; i < n; ++i) {
        if (in->parent[i] != TCLOD_NONE)
            continue;
        top = 0;
        f->stack[0] = i;
        f->stack[1] = f->child_first[i];
        top = 1;
        while (top > 0) {
            uint32_t node = f->stack[2u * (top - 1u)], *cursor = &f->stack[2u * (top - 1u) + 1u];
            if (*cursor < f->child_first[node + 1u]) {
                tclod_id c = f->children[(*cursor)++];
                f->stack[2u * top] = c;
                f->stack[2u * top + 1u] = f->child_first[c];
                top++;
            } else {
                f->post[emitted++] = node;
                top--;
            }
        }
    }
    /* A node no root reaches sits on a cycle of parents. */
    if (emitted != n) {
        optimum_forest_free(f);
        return OPTIMUM_BAD_VALUE;
    }
    return OPTIMUM_OK;
}

/* Cost of a node in quanta; 0 when not a whole number or too large. */
static int optimum_units(double cost, double quantum, uint32_t *units) {
    double u = cost / quantum;
    if (!(u == floor(u)) || u >= OPTIMUM_MAX_NODE_UNITS)
        return 0;
    *units = (uint32_t)u;
    return 1;
}

static optimum_status optimum_start(const optimum_instance *in, double quantum, double max_budget,
                                    optimum_curve *out) {
    double units;
    memset(out, 0, sizeof *out);
    if (in == NULL || !(quantum > 0.0) || !(quantum < INFINITY) || !(max_budget >= 0.0) ||
        !(max_budget < INFINITY))
        return OPTIMUM_BAD_VALUE;
    units = floor(max_budget / quantum);
    if (units > OPTIMUM_MAX_UNITS)
        return OPTIMUM_BAD_VALUE;
    out->quantum = quantum;
    out->units = (uint32_t)units;
    out->best = (double *)malloc(((size_t)out->units + 1u) * sizeof *out->best);
    return out->best ? OPTIMUM_OK : OPTIMUM_NOMEM;
}

/* best[x] from a saturating table t of length len: -inf becomes -1. */
static void optimum_finish(optimum_curve *out, const double *t, uint32_t len) {
    uint32_t x;
    for (x = 0; x <= out->units; ++x) {
        double v = t[x < len ? x : len - 1u];
        out->best[x] = v == -INFINITY ? -1.0 : v;
    }
}

optimum_status optimum_chains(const optimum_instance *in, double quantum, double max_budget,
                              int holes, optimum_curve *out) {
    optimum_forest f;
    optimum_status st = optimum_start(in, quantum, max_budget, out);
    double *dp = NULL, *next = NULL;
    uint32_t i, x, units;
    if (st != OPTIMUM_OK)
        return st;
    st = optimum_forest_build(in, &f);
    if (st != OPTIMUM_OK) {
        optimum_curve_free(out);
        return st;
    }
    for (i = 0; i < in->count && st == OPTIMUM_OK; ++i)
        if (f.child_first[i + 1u] - f.child_first[i] > 1u)
            st = OPTIMUM_NOT_CHAINS;
        else if (in->benefit[i] > 0.0 && !optimum_units(in->cost[i], quantum, &units))
            st = OPTIMUM_NOT_INTEGRAL;
    units = out->units;
    if (st == OPTIMUM_OK) {
        dp = (double *)malloc(((size_t)units + 1u) * sizeof *dp);
        next = (double *)malloc(((size_t)units + 1u) * sizeof *next);
        if (!dp || !next)
            st = OPTIMUM_NOMEM;
    }
    if (st == OPTIMUM_OK) {
        /* No object yet: the empty selection, benefit 0 at any budget. */
        for (x = 0; x <= units; ++x)
            dp[x] = 0.0;
        for (i = 0; i < in->count; ++i) {
            tclod_id node = i;
            double *swap;
            if (in->parent[i] != TCLOD_NONE)
                continue;
            /* Left out (with holes), or else one of the levels. */
            for (x = 0; x <= units; ++x)
                next[x] = holes ? dp[x] : -INFINITY;
            /* Every level of the object is one choice; an invisible level ends the chain
             * (it is drawn as nothing and never refined). */
            for (;;) {
                uint32_t u = 0;
                double b = in->benefit[node];
                if (b > 0.0)
                    optimum_units(in->cost[node], quantum, &u);
                for (x = u; x <= units; ++x) {
                    double v = dp[x - u] + b;
                    if (v > next[x])
                        next[x] = v;
                }
                if (!(b > 0.0) || f.child_first[node + 1u] == f.child_first[node])
                    break;
                node = f.children[f.child_first[node]];
            }
            swap = dp;
            dp = next;
            next = swap;
        }
        optimum_finish(out, dp, units + 1u);
    }
    free(dp);
    free(next);
    optimum_forest_free(&f);
    if (st != OPTIMUM_OK)
        optimum_curve_free(out);
    return st;
}

/* A saturating table: entries 0 .. len - 1, value len - 1 for every larger cost. */
typedef struct optimum_table {
    double *v;
    uint32_t len;
} optimum_table;

static uint32_t optimum_rises(const optimum_table *t) {
    uint32_t x, n = 0;
    double last = -INFINITY;
    for (x = 0; x < t->len; ++x)
        if (t->v[x] > last) {
            n++;
            last = t->v[x];
        }
    return n;
}

/* out = max-plus convolution of a and b, capped at units; 0 when memory runs out. */
static int optimum_convolve(const optimum_table *a, const optimum_table *b, uint32_t units,
                            optimum_table *out) {
    const optimum_table *sparse = a, *dense = b;
    uint64_t span = (uint64_t)(a->len - 1u) + (uint64_t)(b->len - 1u);
    uint32_t len = (uint32_t)(span < units ? span : units) + 1u, x, y;
    double last = -INFINITY;
    if (optimum_rises(b) < optimum_rises(a)) {
        sparse = b;
        dense = a;
    }
    out->v = (double *)malloc((size_t)len * sizeof *out->v);
    if (out->v == NULL)
        return 0;
    out->len = len;
    for (x = 0; x < len; ++x)
        out->v[x] = -INFINITY;
    for (y = 0; y < sparse->len && y < len; ++y) {
        double s = sparse->v[y];
        if (!(s > last))
            continue;
        last = s;
        for (x = y; x < len; ++x) {
            uint32_t k = x - y;
            double v = s + dense->v[k < dense->len ? k : dense->len - 1u];
            if (v > out->v[x])
                out->v[x] = v;
        }
    }
    return 1;
}

optimum_status optimum_tree(const optimum_instance *in, double quantum, double max_budget,
                            int holes, optimum_curve *out) {
    optimum_forest f;
    optimum_table *tab = NULL, acc = {NULL, 0};
    optimum_status st = optimum_start(in, quantum, max_budget, out);
    uint32_t i, k, units;
    if (st != OPTIMUM_OK)
        return st;
    st = optimum_forest_build(in, &f);
    if (st != OPTIMUM_OK) {
        optimum_curve_free(out);
        return st;
    }
    units = out->units;
    for (i = 0; i < in->count && st == OPTIMUM_OK; ++i)
        if (in->benefit[i] > 0.0 && !optimum_units(in->cost[i], quantum, &k))
            st = OPTIMUM_NOT_INTEGRAL;
    if (st == OPTIMUM_OK) {
        tab = (optimum_table *)calloc((size_t)in->count + 1u, sizeof *tab);
        if (tab == NULL)
            st = OPTIMUM_NOMEM;
    }
    for (k = 0; k < in->count && st == OPTIMUM_OK; ++k) {
        tclod_id n = f.post[k];
        uint32_t first = f.child_first[n], end = f.child_first[n + 1u], c, u = 0, len, x;
        optimum_table h = {NULL, 0};
        double b = in->benefit[n];
        if (!(b > 0.0)) {
            /* Invisible: drawn as nothing, its subtree never refined. */
            tab[n].v = (double *)malloc(sizeof *tab[n].v);
            if (tab[n].v == NULL) {
                st = OPTIMUM_NOMEM;
                break;
            }
            tab[n].v[0] = 0.0;
            tab[n].len = 1;
            continue;
        }
        optimum_units(in->cost[n], quantum, &u);
        /* h = the children's cuts combined. */
        for (c = first; c < end && st == OPTIMUM_OK; ++c) {
            optimum_table *t = &tab[f.children[c]];
            if (h.v == NULL) {
                h = *t;
            } else {
                optimum_table m;
                if (!optimum_convolve(&h, t, units, &m))
                    st = OPTIMUM_NOMEM;
                else {
                    free(h.v);
                    h = m;
                }
                free(t->v);
            }
            t->v = NULL;
        }
        if (st != OPTIMUM_OK) {
            free(h.v);
            break;
        }
        len = (u < units ? u : units) + 1u;
        if (h.v != NULL && h.len > len)
            len = h.len;
        tab[n].v = (double *)malloc((size_t)len * sizeof *tab[n].v);
        if (tab[n].v == NULL) {
            free(h.v);
            st = OPTIMUM_NOMEM;
            break;
        }
        tab[n].len = len;
        for (x = 0; x < len; ++x) {
            double v = h.v ? h.v[x < h.len ? x : h.len - 1u] : -INFINITY;
            if (x >= u && b > v)
                v = b;
            if (holes && v < 0.0)
                v = 0.0; /* the subtree left undrawn */
            tab[n].v[x] = v;
        }
        free(h.v);
    }
    /* The roots' tables combined, starting from the empty selection. */
    if (st == OPTIMUM_OK) {
        acc.v = (double *)malloc(sizeof *acc.v);
        if (acc.v == NULL)
            st = OPTIMUM_NOMEM;
        else {
            acc.v[0] = 0.0;
            acc.len = 1;
        }
    }
    for (i = 0; i < in->count && st == OPTIMUM_OK; ++i) {
        optimum_table m;
        if (in->parent[i] != TCLOD_NONE)
            continue;
        if (!optimum_convolve(&acc, &tab[i], units, &m)) {
            st = OPTIMUM_NOMEM;
            break;
        }
        free(acc.v);
        acc = m;
    }
    if (st == OPTIMUM_OK)
        optimum_finish(out, acc.v, acc.len);
    free(acc.v);
    if (tab != NULL)
        for (i = 0; i < in->count; ++i)
            free(tab[i].v);
    free(tab);
    optimum_forest_free(&f);
    if (st != OPTIMUM_OK)
        optimum_curve_free(out);
    return st;
}

double optimum_at(const optimum_curve *c, double budget) {
    double x;
    if (c == NULL || c->best == NULL || !(budget >= 0.0))
        return NAN;
    x = floor(budget / c->quantum);
    if (x > (double)c->units)
        return NAN;
    return c->best[(uint32_t)x];
}

void optimum_curve_free(optimum_curve *c) {
    if (c == NULL)
        return;
    free(c->best);
    memset(c, 0, sizeof *c);
}

/* phi(lambda) and the cost of the cut that attains it (the subgradient is budget minus
 * that cost). f and cut are count-long scratch arrays. */
static double optimum_phi(const optimum_instance *in, const optimum_forest *f, double lambda,
                          double budget, int holes, double *fv, double *cut_cost,
                          double *cost_out) {
    uint32_t k, i;
    double phi = lambda * budget, cost = 0.0;
    for (k = 0; k < in->count; ++k) {
        tclod_id n = f->post[k];
        uint32_t c, first = f->child_first[n], end = f->child_first[n + 1u];
        double own, sum = 0.0, sum_cost = 0.0;
        if (!(in->benefit[n] > 0.0)) {
            fv[n] = 0.0;
            cut_cost[n] = 0.0;
            continue;
        }
        own = in->benefit[n] - lambda * in->cost[n];
        fv[n] = own;
        cut_cost[n] = in->cost[n];
        if (first < end) {
            for (c = first; c < end; ++c) {
                sum += fv[f->children[c]];
                sum_cost += cut_cost[f->children[c]];
            }
            if (sum > own) {
                fv[n] = sum;
                cut_cost[n] = sum_cost;
            }
        }
        if (holes && fv[n] < 0.0) {
            fv[n] = 0.0;
            cut_cost[n] = 0.0;
        }
    }
    for (i = 0; i < in->count; ++i)
        if (in->parent[i] == TCLOD_NONE && fv[i] > 0.0) {
            phi += fv[i];
            cost += cut_cost[i];
        }
    *cost_out = cost;
    return phi;
}

double optimum_bound(const optimum_instance *in, double budget, int holes) {
    optimum_forest f;
    double *fv, *cut_cost, lo = 0.0, hi = 0.0, best, cost;
    uint32_t i;
    int step;
    if (in == NULL || !(budget >= 0.0) || !(budget < INFINITY))
        return NAN;
    if (optimum_forest_build(in, &f) != OPTIMUM_OK)
        return NAN;
    fv = (double *)malloc(((size_t)in->count + 1u) * 2u * sizeof *fv);
    if (fv == NULL) {
        optimum_forest_free(&f);
        return NAN;
    }
    cut_cost = fv + in->count + 1u;
    /* Past the highest benefit per cost no node gains: the subgradient is the budget. */
    for (i = 0; i < in->count; ++i)
        if (in->benefit[i] > 0.0 && in->cost[i] > 0.0 && in->benefit[i] / in->cost[i] > hi)
            hi = in->benefit[i] / in->cost[i];
    best = optimum_phi(in, &f, 0.0, budget, holes, fv, cut_cost, &cost);
    if (cost > budget) {
        for (step = 0; step < OPTIMUM_BOUND_STEPS; ++step) {
            double mid = 0.5 * (lo + hi);
            double phi = optimum_phi(in, &f, mid, budget, holes, fv, cut_cost, &cost);
            if (phi < best)
                best = phi;
            if (cost > budget)
                lo = mid;
            else
                hi = mid;
        }
        {
            double phi = optimum_phi(in, &f, hi, budget, holes, fv, cut_cost, &cost);
            if (phi < best)
                best = phi;
        }
    }
    free(fv);
    optimum_forest_free(&f);
    return best;
}
