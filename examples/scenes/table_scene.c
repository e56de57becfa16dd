/*
 * table_scene — fixed per-node benefit/cost tables, counting callbacks, and
 * random hierarchy and chain builders. See table_scene.h.
 */
#include "table_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void table_init(table_model *m) {
    memset(m, 0, sizeof *m);
}

void table_free(table_model *m) {
    if (m == NULL)
        return;
    free(m->parent);
    free(m->benefit);
    free(m->cost);
    free(m->kind);
    free(m->benefit_calls);
    free(m->cost_calls);
    free(m->smooth.shape);
    free(m->smooth.w);
    free(m->smooth.p);
    free(m->smooth.k);
    free(m->smooth.steep);
    free(m->smooth.kink);
    table_init(m);
}

/* Grows every array to hold at least `need` nodes; 0 on allocation failure
 * (the arrays that did grow keep their old contents, so m stays valid). */
static int table_reserve(table_model *m, uint32_t need) {
    uint32_t cap = m->capacity ? m->capacity : 16u;
    void *p;
    if (need <= m->capacity)
        return 1;
    while (cap < need)
        cap *= 2u;
    if ((p = realloc(m->parent, cap * sizeof *m->parent)) == NULL)
        return 0;
    m->parent = (tclod_id *)p;
    if ((p = realloc(m->benefit, cap * sizeof *m->benefit)) == NULL)
        return 0;
    m->benefit = (double *)p;
    if ((p = realloc(m->cost, cap * sizeof *m->cost)) == NULL)
        return 0;
    m->cost = (double *)p;
    if ((p = realloc(m->kind, cap * sizeof *m->kind)) == NULL)
        return 0;
    m->kind = (uint8_t *)p;
    if ((p = realloc(m->benefit_calls, cap * sizeof *m->benefit_calls)) == NULL)
        return 0;
    m->benefit_calls = (uint32_t *)p;
    if ((p = realloc(m->cost_calls, cap * sizeof *m->cost_calls)) == NULL)
        return 0;
    m->cost_calls = (uint32_t *)p;
    m->capacity = cap;
    return 1;
}

tclod_status table_add_node_desc(table_model *m, tclod_scene *s, const tclod_node_desc *d,
                                 double benefit, double cost, tclod_id *out_id) {
    tclod_id id = TCLOD_NONE;
    uint32_t count, i;
    tclod_status st;
    /* The model is indexed by scene id: both must grow in step. An additive
     * node may take a second id. */
    if (tclod_scene_node_count(s) != m->count)
        return TCLOD_ERR_STATE;
    if (m->count > UINT32_MAX - 2u || !table_reserve(m, m->count + 2u))
        return TCLOD_ERR_NOMEM;
    st = tclod_scene_add_node_desc(s, d, &id);
    if (st != TCLOD_OK)
        return st;
    count = tclod_scene_node_count(s);
    for (i = m->count; i < count; ++i) {
        m->parent[i] = TCLOD_NONE;
        m->kind[i] = TABLE_NONE;
        m->benefit[i] = m->cost[i] = 0.0;
        m->benefit_calls[i] = m->cost_calls[i] = 0;
    }
    m->count = count;
    m->parent[id] = d->parent;
    m->kind[id] = (uint8_t)(d->empty ? TABLE_EMPTY
                                     : (d->refine == TCLOD_REFINE_ADD ? TABLE_ADD : TABLE_REPLACE));
    m->benefit[id] = benefit;
    m->cost[id] = cost;
    m->benefit_calls[id] = 0;
    m->cost_calls[id] = 0;
    if (out_id != NULL)
        *out_id = id;
    return TCLOD_OK;
}

tclod_status table_add_node(table_model *m, tclod_scene *s, tclod_id parent, const float bounds[4],
                            double benefit, double cost, tclod_id *out_id) {
    tclod_node_desc d;
    tclod_node_desc_default(&d);
    d.parent = parent;
    if (bounds)
        d.bounds = tclod_bounds_sphere((double)bounds[0], (double)bounds[1], (double)bounds[2],
                                       (double)bounds[3]);
    return table_add_node_desc(m, s, &d, benefit, cost, out_id);
}

tclod_status table_remove_node(table_model *m, tclod_scene *s, tclod_id id) {
    tclod_status st = tclod_scene_remove_node(s, id);
    int again = 1;
    uint32_t i;
    if (st != TCLOD_OK)
        return st;
    m->kind[id] = TABLE_NONE;
    /* parents may come after their children in id order: until nothing moves */
    while (again) {
        again = 0;
        for (i = 0; i < m->count; ++i)
            if (m->kind[i] != TABLE_NONE && m->parent[i] != TCLOD_NONE &&
                m->kind[m->parent[i]] == TABLE_NONE) {
                m->kind[i] = TABLE_NONE;
                again = 1;
            }
    }
    return TCLOD_OK;
}

void table_reset_counts(table_model *m) {
    if (m->count > 0) {
        memset(m->benefit_calls, 0, m->count * sizeof *m->benefit_calls);
        memset(m->cost_calls, 0, m->count * sizeof *m->cost_calls);
    }
    m->unknown_ids = 0;
    m->smooth.calls = 0;
}

uint32_t table_max_calls(const table_model *m) {
    uint32_t best = 0;
    uint32_t i;
    for (i = 0; i < m->count; ++i) {
        if (m->benefit_calls[i] > best)
            best = m->benefit_calls[i];
        if (m->cost_calls[i] > best)
            best = m->cost_calls[i];
    }
    return best;
}

uint32_t table_asked_nodes(const table_model *m) {
    uint32_t n = 0;
    uint32_t i;
    for (i = 0; i < m->count; ++i)
        n += m->benefit_calls[i] > 0 ? 1u : 0u;
    return n;
}

double table_benefit(void *user, const tclod_query *q) {
    table_model *m = (table_model *)user;
    if (q->id >= m->count) {
        m->unknown_ids++;
        return NAN;
    }
    m->benefit_calls[q->id]++;
    return m->benefit[q->id];
}

double table_cost(void *user, const tclod_query *q) {
    table_model *m = (table_model *)user;
    if (q->id >= m->count) {
        m->unknown_ids++;
        return NAN;
    }
    m->cost_calls[q->id]++;
    return m->cost[q->id];
}

void table_callbacks(table_model *m, tclod_callbacks *cb) {
    memset(cb, 0, sizeof *cb);
    cb->benefit = table_benefit;
    cb->cost = table_cost;
    cb->user = m;
}

void table_mixed_callbacks(table_model *m, tclod_callbacks *cb) {
    table_callbacks(m, cb);
    cb->smooth_benefit = table_smooth_benefit;
    cb->smooth_cost = table_smooth_cost;
}

/* Grows the smooth arrays to hold `need` objects; 0 on allocation failure
 * (the arrays that did grow keep their contents). */
static int smooth_reserve(table_smooth *t, uint32_t need) {
    uint32_t cap = t->capacity ? t->capacity : 16u;
    double **arrays[5];
    void *p;
    int i;
    if (need <= t->capacity)
        return 1;
    while (cap < need)
        cap *= 2u;
    if ((p = realloc(t->shape, cap)) == NULL)
        return 0;
    t->shape = (uint8_t *)p;
    arrays[0] = &t->w;
    arrays[1] = &t->p;
    arrays[2] = &t->k;
    arrays[3] = &t->steep;
    arrays[4] = &t->kink;
    for (i = 0; i < 5; ++i) {
        if ((p = realloc(*arrays[i], cap * sizeof(double))) == NULL)
            return 0;
        *arrays[i] = (double *)p;
    }
    t->capacity = cap;
    return 1;
}

tclod_status table_add_smooth(table_model *m, tclod_scene *s, const float bounds[4],
                              table_shape shape, double w, double p, double k, double steep,
                              double kink, tclod_id *out_id) {
    table_smooth *t = &m->smooth;
    tclod_id id;
    tclod_status st;
    if (!(w >= 0.0) || !(p > 0.0) || (shape == TABLE_POWER && p > 1.0) || !(k >= 0.0) ||
        !(steep >= k) || !(kink >= 0.0 && kink < 1.0) ||
        (shape != TABLE_POWER && shape != TABLE_LOG))
        return TCLOD_ERR_ARG;
    if (tclod_scene_smooth_count(s) != t->count)
        return TCLOD_ERR_STATE;
    if (!smooth_reserve(t, t->count + 1u))
        return TCLOD_ERR_NOMEM;
    st = tclod_scene_add_smooth(s, bounds, &id);
    if (st != TCLOD_OK)
        return st;
    t->shape[id] = (uint8_t)shape;
    t->w[id] = w;
    t->p[id] = p;
    t->k[id] = k;
    t->steep[id] = steep;
    t->kink[id] = kink;
    t->count++;
    if (out_id)
        *out_id = id;
    return TCLOD_OK;
}

double table_smooth_benefit_of(const table_model *m, tclod_id id, double r, double *d_dr) {
    const table_smooth *t = &m->smooth;
    double w = t->w[id], p = t->p[id], b, d;
    if (t->shape[id] == TABLE_POWER) {
        b = w * pow(r, p);
        d = r > 0.0 ? w * p * pow(r, p - 1.0) : HUGE_VAL;
    } else {
        b = w * log1p(p * r);
        d = w * p / (1.0 + p * r);
    }
    if (d_dr)
        *d_dr = d;
    return b;
}

double table_smooth_cost_of(const table_model *m, tclod_id id, double r, double *d_dr) {
    const table_smooth *t = &m->smooth;
    double kink = t->kink[id];
    if (r < kink) {
        if (d_dr)
            *d_dr = t->steep[id];
        return t->steep[id] * r;
    }
    if (d_dr)
        *d_dr = t->k[id];
    return t->steep[id] * kink + t->k[id] * (r - kink);
}

/* Sums f over the members of the query's group. */
static double smooth_sum(table_model *m, const tclod_query *q, double r, double *d_dr,
                         double (*f)(const table_model *, tclod_id, double, double *)) {
    double sum = 0.0, dsum = 0.0;
    uint32_t i;
    for (i = 0; i < q->count; ++i) {
        double d;
        sum += f(m, q->members[i], r, &d);
        dsum += d;
    }
    *d_dr = dsum;
    return sum;
}

double table_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    table_model *m = (table_model *)user;
    m->smooth.calls++;
    if (m->smooth.bad_after && --m->smooth.bad_after == 0) {
        m->smooth.bad_after = 1; /* and every call after it */
        *d_dr = m->smooth.bad_value;
        return m->smooth.bad_value;
    }
    return smooth_sum(m, q, r, d_dr, table_smooth_benefit_of);
}

double table_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    table_model *m = (table_model *)user;
    m->smooth.calls++;
    return smooth_sum(m, q, r, d_dr, table_smooth_cost_of);
}

double table_sum_benefit(const table_model *m, const tclod_id *ids, size_t n) {
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        sum += m->benefit[ids[i]];
    return sum;
}

double table_sum_cost(const table_model *m, const tclod_id *ids, size_t n) {
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        sum += m->cost[ids[i]];
    return sum;
}

double table_roots_cost(const table_model *m) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < m->count; ++i)
        if (m->parent[i] == TCLOD_NONE)
            sum += m->cost[i];
    return sum;
}

double table_leaves_cost(const table_model *m) {
    double sum = 0.0;
    uint32_t i;
    unsigned char *has_child = (unsigned char *)calloc(m->count ? m->count : 1u, 1);
    if (has_child == NULL)
        return NAN;
    for (i = 0; i < m->count; ++i)
        if (m->parent[i] != TCLOD_NONE)
            has_child[m->parent[i]] = 1;
    for (i = 0; i < m->count; ++i)
        if (!has_child[i])
            sum += m->cost[i];
    free(has_child);
    return sum;
}

/* splitmix64: spreads a user seed over the state so nearby seeds differ. */
static uint64_t table_splitmix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

void table_rng_seed(table_rng *r, uint64_t seed) {
    r->state = table_splitmix(seed);
    if (r->state == 0)
        r->state = 0x2545f4914f6cdd1dull; /* xorshift must not start at 0 */
}

uint32_t table_rng_next(table_rng *r) {
    uint64_t x = r->state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    r->state = x;
    return (uint32_t)((x * 0x2545f4914f6cdd1dull) >> 32);
}

uint32_t table_rng_below(table_rng *r, uint32_t n) {
    return (uint32_t)(((uint64_t)table_rng_next(r) * n) >> 32);
}

double table_rng_uniform(table_rng *r, double lo, double hi) {
    return lo + (hi - lo) * ((double)table_rng_next(r) / 4294967296.0);
}

tclod_status table_random_hierarchy(table_model *m, tclod_scene *s, table_rng *r, uint32_t nodes,
                                    uint32_t roots, table_values values) {
    /* Scratch per new node: child weights (cost, benefit), their sums, the
     * node's increment ratio and its children's total cost and benefit. */
    double *w_cost, *w_benefit, *sum_cost, *sum_benefit, *ratio, *total_cost, *total_benefit;
    uint32_t first = m->count;
    uint32_t i;
    tclod_status st = TCLOD_OK;

    if (nodes == 0)
        return TCLOD_OK;
    if (roots == 0 || roots > nodes)
        return TCLOD_ERR_ARG;
    w_cost = (double *)calloc((size_t)nodes * 7u, sizeof(double));
    if (w_cost == NULL)
        return TCLOD_ERR_NOMEM;
    w_benefit = w_cost + nodes;
    sum_cost = w_benefit + nodes;
    sum_benefit = sum_cost + nodes;
    ratio = sum_benefit + nodes;
    total_cost = ratio + nodes;
    total_benefit = total_cost + nodes;

    /* Structure first: node i (local index) hangs below a random earlier node. */
    for (i = 0; i < nodes && st == TCLOD_OK; ++i) {
        tclod_id parent = TCLOD_NONE;
        if (i >= roots)
            parent = first + table_rng_below(r, i);
        st = table_add_node(m, s, parent, NULL, 0.0, 0.0, NULL);
    }
    if (st != TCLOD_OK) {
        free(w_cost);
        return st;
    }
    for (i = roots; i < nodes; ++i) {
        uint32_t p = m->parent[first + i] - first;
        w_cost[i] = table_rng_uniform(r, 0.5, 1.5);
        w_benefit[i] = table_rng_uniform(r, 0.5, 1.5);
        sum_cost[p] += w_cost[i];
        sum_benefit[p] += w_benefit[i];
    }

    /* Values top-down: parents precede their children in id order. */
    for (i = 0; i < nodes; ++i) {
        tclod_id id = first + i;
        double b, c;
        if (values == TABLE_ARBITRARY) {
            m->benefit[id] = table_rng_uniform(r, 0.1, 10.0);
            m->cost[id] = table_rng_uniform(r, 0.1, 10.0);
            continue;
        }
        if (i < roots) {
            b = table_rng_uniform(r, 1.0, 10.0);
            c = table_rng_uniform(r, 0.5, 5.0);
        } else {
            uint32_t p = m->parent[id] - first;
            b = total_benefit[p] * (w_benefit[i] / sum_benefit[p]);
            c = total_cost[p] * (w_cost[i] / sum_cost[p]);
        }
        m->benefit[id] = b;
        m->cost[id] = c;
        if (sum_cost[i] > 0.0) {
            double dc = c * table_rng_uniform(r, 0.5, 2.0);
            if (i < roots)
                ratio[i] = table_rng_uniform(r, 0.5, 3.0);
            else if (values == TABLE_RISING)
                ratio[i] = ratio[m->parent[id] - first] * table_rng_uniform(r, 0.2, 5.0);
            else
                ratio[i] = ratio[m->parent[id] - first] * table_rng_uniform(r, 0.3, 0.95);
            total_cost[i] = c + dc;
            total_benefit[i] = b + ratio[i] * dc;
        }
    }
    free(w_cost);
    return TCLOD_OK;
}

tclod_status table_chains(table_model *m, tclod_scene *s, table_rng *r, uint32_t objects,
                          uint32_t levels, float extent) {
    uint32_t o, k;
    for (o = 0; o < objects; ++o) {
        double c0 = table_rng_uniform(r, 0.5, 2.0);
        double w = table_rng_uniform(r, 1.0, 10.0);
        float bounds[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        const float *b = NULL;
        tclod_id parent = TCLOD_NONE;
        if (extent > 0.0f) {
            bounds[0] = (float)table_rng_uniform(r, -extent, extent);
            bounds[2] = (float)table_rng_uniform(r, -extent, extent);
            b = bounds;
        }
        for (k = 0; k < levels; ++k) {
            double scale = ldexp(1.0, (int)k); /* 2^k */
            tclod_status st =
                table_add_node(m, s, parent, b, w * (2.0 - 1.0 / scale), c0 * scale, &parent);
            if (st != TCLOD_OK)
                return st;
        }
    }
    return TCLOD_OK;
}
