/*
 * exact — enumeration of every selection of a small scene, and checkers.
 * Option lists are built bottom-up: options(n) = {n alone} ∪ the cartesian
 * product of options(child) over n's children (plus n's own benefit and cost
 * when n is additive; only the product when n is empty), each option a
 * (benefit, cost) pair; options over the budget are pruned since costs are
 * >= 0.
 */
#include "exact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct exact_option {
    double benefit, cost;
} exact_option;

typedef struct exact_list {
    exact_option *items;
    size_t count;
} exact_list;

/* product of a and b (pairwise sums) without options over the budget; 0 on
 * allocation failure. */
static int exact_product(const exact_list *a, const exact_list *b, double budget, exact_list *out) {
    size_t i, j, k = 0;
    out->items = (exact_option *)malloc((a->count * b->count + 1u) * sizeof *out->items);
    if (out->items == NULL)
        return 0;
    for (i = 0; i < a->count; ++i)
        for (j = 0; j < b->count; ++j) {
            double c = a->items[i].cost + b->items[j].cost;
            if (c <= budget) {
                out->items[k].benefit = a->items[i].benefit + b->items[j].benefit;
                out->items[k].cost = c;
                k++;
            }
        }
    out->count = k;
    return 1;
}

/* Options of node n's subtree; 0 on allocation failure. */
static int exact_options(const table_model *m, tclod_id n, double budget, exact_list *out) {
    exact_list acc, child, next;
    int has_children = 0;
    tclod_id c;

    out->items = NULL;
    out->count = 0;
    if (m->kind[n] != TABLE_EMPTY && m->benefit[n] == 0.0) {
        out->items = (exact_option *)malloc(sizeof *out->items);
        if (out->items == NULL)
            return 0;
        out->items[0].benefit = 0.0;
        out->items[0].cost = 0.0;
        out->count = 1;
        return 1;
    }
    /* acc starts as the neutral product {(0, 0)}. */
    acc.items = (exact_option *)malloc(sizeof *acc.items);
    if (acc.items == NULL)
        return 0;
    acc.items[0].benefit = 0.0;
    acc.items[0].cost = 0.0;
    acc.count = 1;
    for (c = 0; c < m->count; ++c) {
        if (m->parent[c] != n || m->kind[c] == TABLE_NONE)
            continue;
        has_children = 1;
        if (!exact_options(m, c, budget, &child)) {
            free(acc.items);
            return 0;
        }
        if (!exact_product(&acc, &child, budget, &next)) {
            free(child.items);
            free(acc.items);
            return 0;
        }
        free(child.items);
        free(acc.items);
        acc = next;
    }
    if (m->kind[n] == TABLE_EMPTY) {
        *out = acc; /* its children's, or nothing to draw: {(0, 0)} */
        return 1;
    }
    if (!has_children)
        acc.count = 0;
    out->items = (exact_option *)malloc((acc.count + 1u) * sizeof *out->items);
    if (out->items == NULL) {
        free(acc.items);
        return 0;
    }
    if (m->kind[n] == TABLE_ADD) { /* refined, it stays drawn */
        size_t i, k = 0;
        for (i = 0; i < acc.count; ++i) {
            double with = acc.items[i].cost + m->cost[n];
            if (with <= budget) {
                acc.items[k].benefit = acc.items[i].benefit + m->benefit[n];
                acc.items[k++].cost = with;
            }
        }
        acc.count = k;
    }
    if (acc.count > 0)
        memcpy(out->items, acc.items, acc.count * sizeof *acc.items);
    free(acc.items);
    out->count = acc.count;
    if (m->cost[n] <= budget) {
        out->items[out->count].benefit = m->benefit[n];
        out->items[out->count].cost = m->cost[n];
        out->count++;
    }
    return 1;
}

/* The (benefit, cost) options of all the subtrees whose root's parent is
 * `parent` (TCLOD_NONE: the hierarchies) selected together, within budget, into
 * *out; *found says whether there was any. 0 when memory runs out. */
static int exact_options_below(const table_model *m, tclod_id parent, double budget,
                               exact_list *out, int *found) {
    exact_list acc, sub, next;
    tclod_id i;
    *found = 0;
    acc.items = (exact_option *)malloc(sizeof *acc.items);
    if (acc.items == NULL)
        return 0;
    acc.items[0].benefit = 0.0;
    acc.items[0].cost = 0.0;
    acc.count = 1;
    for (i = 0; i < m->count; ++i) {
        if (m->parent[i] != parent || m->kind[i] == TABLE_NONE)
            continue;
        *found = 1;
        if (!exact_options(m, i, budget, &sub)) {
            free(acc.items);
            return 0;
        }
        if (!exact_product(&acc, &sub, budget, &next)) {
            free(sub.items);
            free(acc.items);
            return 0;
        }
        free(sub.items);
        free(acc.items);
        acc = next;
    }
    *out = acc;
    return 1;
}

double exact_optimum(const table_model *m, double budget, double *cost_out) {
    exact_list acc;
    double best = -1.0, best_cost = 0.0;
    tclod_id i;
    size_t k;
    int found;

    if (m->count > EXACT_MAX_NODES)
        return -2.0;
    for (i = 0; i < m->count; ++i)
        if (m->kind[i] != TABLE_NONE && (!isfinite(m->benefit[i]) || !isfinite(m->cost[i]) ||
                                         m->benefit[i] < 0.0 || m->cost[i] < 0.0))
            return -2.0;
    if (!exact_options_below(m, TCLOD_NONE, budget, &acc, &found))
        return -2.0;
    for (k = 0; k < acc.count; ++k)
        if (acc.items[k].benefit > best) {
            best = acc.items[k].benefit;
            best_cost = acc.items[k].cost;
        }
    free(acc.items);
    if (cost_out != NULL)
        *cost_out = best_cost;
    return best;
}

double exact_best_ratio(const table_model *m, tclod_id n) {
    exact_list acc;
    double best = -1.0;
    int has_children;
    size_t k;

    if (m->count > EXACT_MAX_NODES || n >= m->count)
        return -2.0;
    if (!exact_options_below(m, n, INFINITY, &acc, &has_children))
        return -2.0;
    for (k = 0; k < acc.count && has_children; ++k) {
        double db = acc.items[k].benefit - m->benefit[n], dc = acc.items[k].cost - m->cost[n];
        double ratio = dc > 0.0 ? db / dc : INFINITY;
        if (db > 0.0 && ratio > best)
            best = ratio;
    }
    free(acc.items);
    return best;
}

/* A benefit the library draws: finite and > 0 (anything else is culled). */
static int exact_visible(double benefit) {
    return benefit > 0.0 && benefit < INFINITY;
}

int exact_check_cut(const table_model *m, const tclod_id *ids, size_t n, int roots_may_drop) {
    unsigned char *listed, *has_child;
    int ok = 1;
    size_t i;
    tclod_id v;

    listed = (unsigned char *)calloc((size_t)m->count + 1u, 2);
    if (listed == NULL)
        return 0;
    has_child = listed + m->count + 1u;
    for (i = 0; i < n && ok; ++i) {
        if (ids[i] >= m->count || listed[ids[i]] || !exact_visible(m->benefit[ids[i]]))
            ok = 0;
        else
            listed[ids[i]] = 1;
    }
    for (v = 0; v < m->count; ++v)
        if (m->parent[v] != TCLOD_NONE && m->kind[v] != TABLE_NONE)
            has_child[m->parent[v]] = 1;
    /* Walk every leaf up to its root: count listed nodes on the path, and
     * whether an invisible node covers it. */
    for (v = 0; v < m->count && ok; ++v) {
        unsigned on_path = 0;
        int culled = 0;
        tclod_id u, root = v;
        if (has_child[v] || m->kind[v] == TABLE_NONE)
            continue;
        for (u = v; u != TCLOD_NONE; u = m->parent[u]) {
            on_path += listed[u];
            culled |= !exact_visible(m->benefit[u]);
            root = u;
        }
        if (on_path > 1)
            ok = 0;
        else if (on_path == 0 && !culled) {
            /* Allowed only when the whole hierarchy of this root is unlisted. */
            tclod_id w;
            if (!roots_may_drop)
                ok = 0;
            for (w = 0; w < m->count && ok; ++w) {
                tclod_id r = w;
                if (!listed[w])
                    continue;
                while (m->parent[r] != TCLOD_NONE)
                    r = m->parent[r];
                if (r == root)
                    ok = 0;
            }
        }
    }
    free(listed);
    return ok;
}

/* The parent a node hangs from in the tree the solvers see: its nearest
 * ancestor that is not empty. */
static tclod_id exact_drawn_parent(const table_model *m, tclod_id v) {
    tclod_id p = m->parent[v];
    while (p != TCLOD_NONE && m->kind[p] == TABLE_EMPTY)
        p = m->parent[p];
    return p;
}

int exact_check_selection(const table_model *m, const tclod_id *ids, size_t n, int roots_may_drop) {
    /* per id: 1 listed, 2 above a listed node (refined) */
    unsigned char *state = (unsigned char *)calloc((size_t)m->count + 1u, 1);
    int ok = 1;
    size_t i;
    tclod_id v;
    if (state == NULL)
        return 0;
    for (i = 0; i < n && ok; ++i) {
        tclod_id id = ids[i];
        if (id >= m->count || state[id] || m->kind[id] == TABLE_NONE ||
            m->kind[id] == TABLE_EMPTY || !exact_visible(m->benefit[id]))
            ok = 0;
        else
            state[id] = 1;
    }
    for (i = 0; i < n && ok; ++i)
        for (v = exact_drawn_parent(m, ids[i]); v != TCLOD_NONE; v = exact_drawn_parent(m, v))
            state[v] |= 2u;
    for (v = 0; v < m->count && ok; ++v) {
        tclod_id p;
        if (m->kind[v] == TABLE_NONE || m->kind[v] == TABLE_EMPTY)
            continue;
        /* a refined node: additive ones are listed, replace ones not */
        if ((state[v] & 2u) && ((m->kind[v] == TABLE_ADD) != ((state[v] & 1u) != 0)))
            ok = 0;
        /* every node that draws below a refined one (or at the top) is
         * listed, refined or culled: no hole */
        p = exact_drawn_parent(m, v);
        if (state[v] == 0 && exact_visible(m->benefit[v]) &&
            ((p != TCLOD_NONE && (state[p] & 2u)) || (p == TCLOD_NONE && !roots_may_drop)))
            ok = 0;
    }
    free(state);
    return ok;
}

static int exact_compare_ids(const void *a, const void *b) {
    tclod_id x = *(const tclod_id *)a, y = *(const tclod_id *)b;
    return (x > y) - (x < y);
}

void exact_sort_ids(tclod_id *ids, size_t n) {
    if (n > 1)
        qsort(ids, n, sizeof *ids, exact_compare_ids);
}
