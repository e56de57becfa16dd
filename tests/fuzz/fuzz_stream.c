/*
 * fuzz_stream — libFuzzer target over residency and streaming
 * (docs/streaming.md): scenes built and edited as fuzz_select builds them
 * (fuzz_host.c), nodes and smooth objects loaded and unloaded, sizes set
 * (NaN, infinities, negatives, beyond FLT_MAX among them), stream descs set
 * (bad fields too), the bytes callback answering any value, and selects
 * with every solver between the flips.
 *
 * The input's bytes choose a selector description, a first scene and its
 * residency and sizes, the answers of the bytes callback, and up to six
 * frames, each after a batch of operations: residency and size calls on any
 * id (live, removed, hidden, beyond the count) with any argument, nodes and
 * smooth objects added (then maybe unloaded and sized), fuzz_host's edits,
 * stream descs, changed callback values; and a residency call tried from
 * inside the first callback of each select and while a resumable solve is
 * pending. Two selectors see the same frames: the first through
 * tclod_select, the second through tclod_select or the resumable calls.
 * After every call the target checks:
 *  - residency and size calls fail with TCLOD_ERR_ARG exactly when the id is
 *    not a live node (smooth object), the residency not 0 or 1 or the size
 *    not in [0, FLT_MAX]; with TCLOD_ERR_STATE (or their own error) from a
 *    callback or while a solve is pending; and then change nothing: every
 *    id's residency and size read back as the model has them, and the
 *    resident bytes are the model's sum (to the rounding of a running sum);
 *    a new node is resident with no size;
 *  - tclod_selector_set_stream fails with TCLOD_ERR_ARG naming the first bad
 *    field exactly when one is NaN, infinite or negative, and with
 *    TCLOD_ERR_STATE from a callback; the lists are refused from one;
 *  - a select succeeds unless the frame is bad or strict mode saw a bad
 *    value (the bytes callback's included); a failed one leaves the result
 *    and the lists as they were;
 *  - a result lists only live nodes that draw, once each, resident, none
 *    below a node that is not resident and the top of its hierarchy (a root
 *    or an additive node's child); its smooth groups hold resident objects
 *    only; its cost (the cut's callback costs, then the groups') is within
 *    the budget unless the roots were drawn over it, and is stats.cost;
 *    stats.absent_roots counts the visible roots that are not resident, and
 *    every root that is not resident was asked about;
 *  - the load requests are live nodes (smooth objects) that are not
 *    resident, each once, at most max_requests; the evictions, listed only
 *    with a memory budget, are live resident ones that are neither drawn
 *    nor above a drawn node (in no group), each once; TCLOD_STREAM_LISTED
 *    is set exactly on the items the previous select listed too, and
 *    TCLOD_STREAM_EXPAND exactly on requests for unexpanded nodes (added
 *    between frames, never resident, refusing residency and children);
 *  - the bytes callback is asked only about a live node (smooth object)
 *    that is not resident and has no size, at most once per select;
 *  - the two selectors agree, lists included, when no limit is involved.
 */
#include <tclod/tclod.h>

#include "fuzz_host.h"

#define MAX_FRAMES 6u
#define FIRST_NODES 96u
#define FIRST_SMOOTH 24u
#define MAX_LIST (MAX_NODES + MAX_SMOOTH)

/* ---- tallies ------------------------------------------------------------------- */

/* FUZZ_STATS=1 in the environment prints, at exit, how often the inputs
 * reached the paths this target is about. */
enum {
    T_CALL_OK,
    T_CALL_REFUSED,
    T_CALL_HELD,
    T_SELECT_OK,
    T_ABSENT_ROOTS,
    T_ABSENT_DRAWN_BELOW, /* a drawn node below one not resident (passed over) */
    T_ABSENT_IN_VIEW,     /* a select that saw a visible node not resident */
    T_SMOOTH_ABSENT,      /* a select over a smooth object not resident */
    T_REQUESTS,
    T_EVICTIONS,
    T_BYTES_ASKED,
    T_STREAM_DESC_BAD,
    T_EXPAND_LISTED, /* a request to expand an unexpanded node */
    T_COUNT
};
static unsigned long tallies_[T_COUNT];
static int tallying_ = -1;

static void print_tallies_(void) {
    static const char *const names[T_COUNT] = {"residency calls accepted",
                                               "residency calls refused",
                                               "refused (solve holds)",
                                               "selects",
                                               "selects with absent roots",
                                               "drawn below not resident",
                                               "saw visible not resident",
                                               "smooth not resident",
                                               "selects with requests",
                                               "selects with evictions",
                                               "bytes asked",
                                               "bad stream descs",
                                               "expansions requested"};
    int i;
    for (i = 0; i < T_COUNT; ++i)
        fprintf(stderr, "tally: %-30s %lu\n", names[i], tallies_[i]);
}

static void count(int what) {
    if (tallying_ < 0) {
        tallying_ = getenv("FUZZ_STATS") != NULL;
        if (tallying_)
            atexit(print_tallies_);
    }
    tallies_[what]++;
}

/* ---- the residency model ---------------------------------------------------------- */

typedef struct residency {
    uint8_t live[MAX_NODES]; /* what the last sync saw live */
    uint8_t resident[MAX_NODES];
    float bytes[MAX_NODES];
    uint8_t smooth_live[MAX_SMOOTH], smooth_resident[MAX_SMOOTH];
    float smooth_bytes[MAX_SMOOTH];
    double answer[MAX_NODES + MAX_SMOOTH]; /* what the bytes callback returns */
    double peak; /* the largest resident sum so far: the running sum's rounding */
} residency;

typedef struct lists {
    tclod_stream_item items[2][MAX_LIST];
    size_t n[2];
} lists;

typedef struct run_state {
    host_model model;
    residency res;
    probe probes[2];
    tclod_selector *sel[2];
    tclod_stream_desc stream; /* the desc both selectors have */
    uint32_t bytes_calls[2][MAX_NODES + MAX_SMOOTH];
    int solving; /* the selector whose select runs, -1: none */
    int held_armed, held_tried;
    uint8_t held_op, held_a, held_b;
    double held_x;
    lists before, after, other, previous[2];
} run_state;

static run_state state;

static int is_live(const host_model *m, tclod_id id) {
    return id < m->nodes && m->state[id] == ID_LIVE;
}

static int is_smooth_live(const host_model *m, tclod_id id) {
    return id < m->smooth && m->smooth_state[id] == ID_LIVE;
}

static double model_sum(const host_model *m, const residency *r) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < m->nodes; ++i) /* an empty node has nothing to load: not counted */
        if (model_draws(m, i) && r->resident[i])
            sum += (double)r->bytes[i];
    for (i = 0; i < m->smooth; ++i)
        if (is_smooth_live(m, i) && r->smooth_resident[i])
            sum += (double)r->smooth_bytes[i];
    return sum;
}

/* Ids that became live since the last sync are resident with no size (what
 * fuzz_host adds), unexpanded ones not resident; ids no longer live are
 * forgotten. */
static void sync(const host_model *m, residency *r) {
    uint32_t i;
    for (i = 0; i < MAX_NODES; ++i) {
        int live = is_live(m, i);
        if (live != r->live[i]) {
            r->resident[i] = (uint8_t)(live && !m->unexpanded[i]);
            r->bytes[i] = 0.0f;
        }
        r->live[i] = (uint8_t)live;
    }
    for (i = 0; i < MAX_SMOOTH; ++i) {
        int live = is_smooth_live(m, i);
        if (live != r->smooth_live[i]) {
            r->smooth_resident[i] = (uint8_t)live;
            r->smooth_bytes[i] = 0.0f;
        }
        r->smooth_live[i] = (uint8_t)live;
    }
}

/* The scene against the model: every id's residency and size, and the
 * resident bytes. */
static void verify_residency(const host_model *m, residency *r) {
    const tclod_scene *s = m->scene;
    double sum = model_sum(m, r), got = tclod_scene_resident_bytes(s);
    uint32_t i;
    if (sum > r->peak)
        r->peak = sum;
    for (i = 0; i < m->nodes + 2u; ++i) {
        int live = is_live(m, i);
        double b = live ? (double)r->bytes[i] : 0.0;
        FUZZ_CHECK(tclod_scene_node_resident(s, i) == (live && r->resident[i]) &&
                       tclod_scene_node_bytes(s, i) == b,
                   "node %u (state %d): resident %d bytes %.9g, the model says %d %.9g",
                   (unsigned)i, i < m->nodes ? (int)m->state[i] : -1,
                   tclod_scene_node_resident(s, i), tclod_scene_node_bytes(s, i),
                   live && r->resident[i], b);
    }
    for (i = 0; i < m->smooth + 2u; ++i) {
        int live = is_smooth_live(m, i);
        double b = live ? (double)r->smooth_bytes[i] : 0.0;
        FUZZ_CHECK(tclod_scene_smooth_resident(s, i) == (live && r->smooth_resident[i]) &&
                       tclod_scene_smooth_bytes(s, i) == b,
                   "smooth %u: resident %d bytes %.9g, the model says %d %.9g", (unsigned)i,
                   tclod_scene_smooth_resident(s, i), tclod_scene_smooth_bytes(s, i),
                   live && r->smooth_resident[i], b);
    }
    FUZZ_CHECK(fabs(got - sum) <= 1e-9 * r->peak, "resident bytes %.17g, the model sums %.17g", got,
               sum);
}

/* ---- residency calls ------------------------------------------------------------------ */

enum { OP_RESIDENT = 0, OP_SMOOTH_RESIDENT, OP_BYTES, OP_SMOOTH_BYTES, OP_KINDS };

static int bytes_bad(double b) {
    return !(b >= 0.0 && b <= (double)FLT_MAX);
}

/* One residency or size call on id with residency `flag` or size x. held: a
 * solve holds the scene (a callback, or a pending solve): TCLOD_ERR_STATE
 * unless the arguments are bad. Checks the status and the scene after. */
static void residency_call(host_model *m, residency *r, uint8_t op, tclod_id id, int flag, double x,
                           int held) {
    tclod_scene *s = m->scene;
    int smooth = op == OP_SMOOTH_RESIDENT || op == OP_SMOOTH_BYTES;
    int live = smooth ? is_smooth_live(m, id) : is_live(m, id);
    int bad;
    tclod_status st;
    switch (op % OP_KINDS) {
    case OP_RESIDENT:
        st = tclod_scene_set_resident(s, id, flag);
        bad = !live || (flag != 0 && flag != 1) || m->unexpanded[id];
        break;
    case OP_SMOOTH_RESIDENT:
        st = tclod_scene_set_smooth_resident(s, id, flag);
        bad = !live || (flag != 0 && flag != 1);
        break;
    case OP_BYTES:
        st = tclod_scene_set_node_bytes(s, id, x);
        bad = !live || bytes_bad(x);
        break;
    default:
        st = tclod_scene_set_smooth_bytes(s, id, x);
        bad = !live || bytes_bad(x);
        break;
    }
    FUZZ_CHECK(st == (bad ? TCLOD_ERR_ARG : (held ? TCLOD_ERR_STATE : TCLOD_OK)),
               "residency call %d on %u (live %d, flag %d, bytes %.17g, held %d) gave %d", (int)op,
               (unsigned)id, live, flag, x, held, (int)st);
    count(st == TCLOD_OK ? T_CALL_OK : (st == TCLOD_ERR_STATE ? T_CALL_HELD : T_CALL_REFUSED));
    if (st == TCLOD_OK) {
        switch (op % OP_KINDS) {
        case OP_RESIDENT:
            r->resident[id] = (uint8_t)flag;
            break;
        case OP_SMOOTH_RESIDENT:
            r->smooth_resident[id] = (uint8_t)flag;
            break;
        case OP_BYTES:
            r->bytes[id] = (float)x;
            break;
        default:
            r->smooth_bytes[id] = (float)x;
            break;
        }
    }
    verify_residency(m, r);
}

/* A residency flag from a byte: mostly 0 or 1, sometimes neither. */
static int read_flag(uint8_t b) {
    static const int flags[8] = {0, 1, 0, 1, 0, 1, 2, -1};
    return flags[b % 8u];
}

/* A size: a special double (bad ones among them), FLT_MAX and just beyond
 * it, or an ordinary value. */
static double read_bytes(fuzz_reader *in) {
    uint8_t b = fuzz_u8(in);
    if (b < FUZZ_SPECIAL_DOUBLES)
        return fuzz_special_double(b);
    if (b == 32)
        return (double)FLT_MAX;
    if (b == 33)
        return (double)FLT_MAX * (1.0 + DBL_EPSILON);
    if (b == 34)
        return 0.0;
    return ldexp(1.0 + (double)(b & 15u) / 16.0, (int)(b >> 4) * 3);
}

/* An id for a residency call from byte b: below the count of ids of its
 * kind and two beyond (live, removed, hidden or never given), or TCLOD_NONE. */
static tclod_id pick_id(const host_model *m, uint8_t op, uint8_t b) {
    uint32_t count = op == OP_SMOOTH_RESIDENT || op == OP_SMOOTH_BYTES ? m->smooth : m->nodes;
    return b == 255 ? TCLOD_NONE : (tclod_id)(b % (count + 2u));
}

/* One residency call read from the input. */
static void read_residency_call(fuzz_reader *in, const host_model *m, uint8_t *op, tclod_id *id,
                                int *flag, double *x) {
    uint8_t a = fuzz_u8(in);
    *op = (uint8_t)(a % OP_KINDS);
    *id = pick_id(m, *op, fuzz_u8(in));
    *flag = read_flag((uint8_t)(a / OP_KINDS));
    *x = *op >= OP_BYTES ? read_bytes(in) : 0.0;
}

/* ---- callbacks ------------------------------------------------------------------- */

/* The held residency call and stream calls, once per select, from inside the
 * first callback: each must be refused. */
static void held_now(void) {
    run_state *S = &state;
    const tclod_stream_item *items = NULL;
    size_t n = 0;
    tclod_stream_desc d;
    if (S->held_tried || S->solving < 0)
        return;
    S->held_tried = 1;
    if (S->held_armed)
        residency_call(&S->model, &S->res, S->held_op, pick_id(&S->model, S->held_op, S->held_a),
                       read_flag(S->held_b), S->held_x, 1);
    memset(&d, 0, sizeof d);
    FUZZ_CHECK(tclod_selector_set_stream(S->sel[S->solving], &d) == TCLOD_ERR_STATE,
               "set_stream from a callback");
    FUZZ_CHECK(tclod_selector_requests(S->sel[S->solving], &items, &n) == TCLOD_ERR_STATE &&
                   tclod_selector_evictions(S->sel[S->solving], &items, &n) == TCLOD_ERR_STATE,
               "the lists read from a callback");
}

static double stream_benefit(void *user, const tclod_query *q) {
    held_now();
    return host_benefit(user, q);
}

static double stream_bytes(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    run_state *S = &state;
    int k = p == &S->probes[0] ? 0 : 1;
    uint32_t slot;
    double v;
    FUZZ_CHECK(S->solving == k, "bytes asked outside a select");
    if (q->members) {
        FUZZ_CHECK(is_smooth_live(&S->model, q->id) && !S->res.smooth_resident[q->id] &&
                       S->res.smooth_bytes[q->id] == 0.0f,
                   "bytes asked of smooth object %u (live %d, resident %d, bytes %g)",
                   (unsigned)q->id, is_smooth_live(&S->model, q->id),
                   q->id < MAX_SMOOTH ? S->res.smooth_resident[q->id] : -1,
                   q->id < MAX_SMOOTH ? (double)S->res.smooth_bytes[q->id] : -1.0);
        slot = MAX_NODES + q->id;
    } else {
        FUZZ_CHECK(model_draws(&S->model, q->id) && !S->res.resident[q->id] &&
                       S->res.bytes[q->id] == 0.0f,
                   "bytes asked of node %u (draws %d, resident %d, bytes %g)", (unsigned)q->id,
                   model_draws(&S->model, q->id), q->id < MAX_NODES ? S->res.resident[q->id] : -1,
                   q->id < MAX_NODES ? (double)S->res.bytes[q->id] : -1.0);
        slot = q->id;
    }
    FUZZ_CHECK(++S->bytes_calls[k][slot] == 1u, "bytes of %u asked twice in a select",
               (unsigned)q->id);
    v = S->res.answer[slot];
    count(T_BYTES_ASKED);
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    return v;
}

/* ---- results ------------------------------------------------------------------- */

static void take_lists(const tclod_selector *sel, lists *l) {
    const tclod_stream_item *items = NULL;
    int k;
    for (k = 0; k < 2; ++k) {
        FUZZ_CHECK((k == 0 ? tclod_selector_requests(sel, &items, &l->n[k])
                           : tclod_selector_evictions(sel, &items, &l->n[k])) == TCLOD_OK,
                   "reading the lists");
        FUZZ_CHECK(l->n[k] <= MAX_LIST, "%lu items", (unsigned long)l->n[k]);
        if (l->n[k])
            memcpy(l->items[k], items, l->n[k] * sizeof *items);
    }
}

static int same_lists(const lists *a, const lists *b) {
    int k;
    for (k = 0; k < 2; ++k)
        if (a->n[k] != b->n[k] ||
            (a->n[k] && memcmp(a->items[k], b->items[k], a->n[k] * sizeof a->items[k][0]) != 0))
            return 0;
    return 1;
}

typedef struct result {
    tclod_id ids[MAX_NODES];
    size_t n;
    tclod_smooth_group groups[MAX_SMOOTH];
    size_t groups_n;
} result;

static result results[3];

static void take_result(const tclod_selector *sel, result *r) {
    const tclod_id *ids = NULL;
    const tclod_smooth_group *g = NULL;
    FUZZ_CHECK(tclod_selector_cut(sel, &ids, &r->n) == TCLOD_OK && r->n <= MAX_NODES, "cut");
    if (r->n)
        memcpy(r->ids, ids, r->n * sizeof *ids);
    FUZZ_CHECK(tclod_selector_smooth_groups(sel, &g, &r->groups_n) == TCLOD_OK &&
                   r->groups_n <= MAX_SMOOTH,
               "groups");
    if (r->groups_n)
        memcpy(r->groups, g, r->groups_n * sizeof *g);
}

static int same_result(const result *a, const result *b) {
    return a->n == b->n && a->groups_n == b->groups_n &&
           (a->n == 0 || memcmp(a->ids, b->ids, a->n * sizeof a->ids[0]) == 0) &&
           (a->groups_n == 0 ||
            memcmp(a->groups, b->groups, a->groups_n * sizeof a->groups[0]) == 0);
}

/* Whether live node v is the top of a hierarchy for residency: a root, or
 * a child of an additive node, in the tree the solvers see. */
static int top(const host_model *m, tclod_id v) {
    tclod_id p = drawn_parent(m, v);
    return p == TCLOD_NONE || m->kind[p] == KIND_ADD;
}

static int visible_value(double b) {
    return b > 0.0 && !fuzz_bad(b);
}

/* What a successful select of selector k promises (previous: its lists
 * before the select). */
static void check_result(int k, const tclod_frame *f, const tclod_stats *st, const result *r,
                         const lists *l, const lists *previous) {
    const host_model *m = &state.model;
    const residency *res = &state.res;
    const probe *p = &state.probes[k];
    const tclod_id *order = NULL;
    uint32_t order_n = 0, absent = 0, i;
    uint8_t mark[MAX_NODES], in_group[MAX_SMOOTH], seen[MAX_LIST];
    double cost = 0.0;
    size_t j;
    int kind;
    memset(mark, 0, sizeof mark);
    memset(in_group, 0, sizeof in_group);
    for (j = 0; j < r->n; ++j) {
        tclod_id v = r->ids[j], a;
        FUZZ_CHECK(model_draws(m, v) && !(mark[v] & 1u),
                   "the result lists %u twice, or a node that does not draw", (unsigned)v);
        mark[v] |= 1u;
        FUZZ_CHECK(res->resident[v], "node %u is drawn and not resident", (unsigned)v);
        FUZZ_CHECK(p->benefit_calls[v] == 1 && p->cost_calls[v] == 1 &&
                       visible_value(p->benefit_seen[v]) && !fuzz_bad(p->cost_seen[v]),
                   "cut node %u: benefit asked %u times (%g), cost %u times (%g)", (unsigned)v,
                   (unsigned)p->benefit_calls[v], p->benefit_seen[v], (unsigned)p->cost_calls[v],
                   p->cost_seen[v]);
        cost += p->cost_seen[v];
        for (a = drawn_parent(m, v); a != TCLOD_NONE; a = drawn_parent(m, a)) {
            mark[a] |= 2u;
            if (!res->resident[a])
                count(T_ABSENT_DRAWN_BELOW);
            FUZZ_CHECK(res->resident[a] || !top(m, a),
                       "node %u is drawn below %u, which is not resident and heads a hierarchy",
                       (unsigned)v, (unsigned)a);
        }
    }
    FUZZ_CHECK(tclod_scene_smooth_order(m->scene, &order, &order_n) == TCLOD_OK, "smooth order");
    for (j = 0; j < r->groups_n; ++j) {
        const tclod_smooth_group *g = &r->groups[j];
        FUZZ_CHECK((uint64_t)g->first + g->count <= order_n, "group past the order");
        for (i = g->first; i < g->first + g->count; ++i) {
            FUZZ_CHECK(res->smooth_resident[order[i]], "smooth object %u drawn, not resident",
                       (unsigned)order[i]);
            in_group[order[i]] = 1;
        }
        FUZZ_CHECK(!fuzz_bad(g->cost), "group cost %g", g->cost);
        cost += g->cost;
    }
    if (st->over_budget)
        FUZZ_CHECK(cost > f->budget, "over_budget at cost %.17g, budget %.17g", cost, f->budget);
    else
        FUZZ_CHECK(cost <= f->budget, "selection costs %.17g, budget %.17g", cost, f->budget);
    FUZZ_CHECK(st->cost == cost, "stats.cost %.17g, the result sums %.17g", st->cost, cost);
    FUZZ_CHECK(st->invalid_values == p->bad, "%u invalid values counted, %u returned",
               (unsigned)st->invalid_values, (unsigned)p->bad);
    for (i = 0; i < m->nodes; ++i) {
        if (!model_draws(m, i) || drawn_parent(m, i) != TCLOD_NONE || res->resident[i])
            continue;
        FUZZ_CHECK(p->benefit_calls[i] == 1, "root %u is not resident and was not asked about",
                   (unsigned)i);
        absent += visible_value(p->benefit_seen[i]);
    }
    FUZZ_CHECK(st->absent_roots == absent, "absent_roots %u, %u visible roots not resident",
               (unsigned)st->absent_roots, (unsigned)absent);
    count(T_SELECT_OK);
    if (absent)
        count(T_ABSENT_ROOTS);
    for (i = 0; i < m->nodes; ++i)
        if (model_draws(m, i) && !res->resident[i] && p->benefit_calls[i] &&
            visible_value(p->benefit_seen[i])) {
            count(T_ABSENT_IN_VIEW);
            break;
        }
    for (i = 0; i < m->smooth; ++i)
        if (is_smooth_live(m, i) && !res->smooth_resident[i]) {
            count(T_SMOOTH_ABSENT);
            break;
        }
    if (l->n[0])
        count(T_REQUESTS);
    if (l->n[1])
        count(T_EVICTIONS);
    /* the lists */
    for (kind = 0; kind < 2; ++kind) {
        memset(seen, 0, sizeof seen);
        if (kind == 0)
            FUZZ_CHECK(l->n[0] <= state.stream.max_requests, "%lu requests, at most %u",
                       (unsigned long)l->n[0], (unsigned)state.stream.max_requests);
        else
            FUZZ_CHECK(l->n[1] == 0 || state.stream.memory_budget > 0.0,
                       "%lu evictions without a memory budget", (unsigned long)l->n[1]);
        for (j = 0; j < l->n[kind]; ++j) {
            const tclod_stream_item *it = &l->items[kind][j];
            int smooth = (it->flags & TCLOD_STREAM_SMOOTH) != 0, was = 0;
            uint32_t slot = smooth ? MAX_NODES + it->id : it->id;
            size_t q;
            FUZZ_CHECK((it->flags & ~(TCLOD_STREAM_SMOOTH | TCLOD_STREAM_LISTED |
                                      TCLOD_STREAM_EXPAND)) == 0,
                       "item flags %x", (unsigned)it->flags);
            FUZZ_CHECK(((it->flags & TCLOD_STREAM_EXPAND) != 0) ==
                           (kind == 0 && !smooth && m->unexpanded[it->id]),
                       "%s: %u (unexpanded %d) flagged %x", kind ? "evictions" : "requests",
                       (unsigned)it->id, !smooth && m->unexpanded[it->id], (unsigned)it->flags);
            if (!smooth && m->unexpanded[it->id])
                count(T_EXPAND_LISTED);
            FUZZ_CHECK(smooth ? is_smooth_live(m, it->id) : model_draws(m, it->id),
                       "%s lists %s %u, not live", kind ? "evictions" : "requests",
                       smooth ? "smooth object" : "node", (unsigned)it->id);
            FUZZ_CHECK(!seen[slot], "%u listed twice", (unsigned)it->id);
            seen[slot] = 1;
            if (kind == 0) {
                FUZZ_CHECK(!(smooth ? res->smooth_resident[it->id] : res->resident[it->id]),
                           "request for %u, which is resident", (unsigned)it->id);
            } else {
                FUZZ_CHECK(smooth ? res->smooth_resident[it->id] : res->resident[it->id],
                           "eviction of %u, which is not resident", (unsigned)it->id);
                FUZZ_CHECK(smooth ? !in_group[it->id] : !mark[it->id],
                           "eviction of %u, which is drawn or above a drawn node",
                           (unsigned)it->id);
            }
            for (q = 0; q < previous->n[kind]; ++q)
                if (previous->items[kind][q].id == it->id &&
                    (previous->items[kind][q].flags & TCLOD_STREAM_SMOOTH) ==
                        (it->flags & TCLOD_STREAM_SMOOTH))
                    was = 1;
            FUZZ_CHECK(was == ((it->flags & TCLOD_STREAM_LISTED) != 0),
                       "%u: listed before %d, flag says %d", (unsigned)it->id, was,
                       (it->flags & TCLOD_STREAM_LISTED) != 0);
        }
    }
}

/* ---- selects ------------------------------------------------------------------- */

/* The select of selector 1 through tclod_select_begin and steps of `slice`
 * iterations (how / 4 % 16 + 1); how % 4: 0, 2 to the end, 1 ended by
 * tclod_select_finish after a few steps, 3 cancelled (*dropped = 1). The
 * held residency call is tried after begin. */
static tclod_status select_resumable(const tclod_frame *f, tclod_stats *st, uint8_t how,
                                     int *dropped) {
    run_state *S = &state;
    tclod_selector *sel = S->sel[1];
    uint32_t slice = (uint32_t)(how / 4u % 16u) + 1u, steps = 0, stop_after = how / 64u;
    tclod_status status;
    int done = 0;
    *dropped = 0;
    status = tclod_select_begin(sel, f);
    if (status != TCLOD_OK)
        return status;
    if (S->held_armed) {
        S->solving = -1; /* between steps no callback runs */
        residency_call(&S->model, &S->res, S->held_op, pick_id(&S->model, S->held_op, S->held_a),
                       read_flag(S->held_b), S->held_x, 1);
        S->solving = 1;
    }
    for (;;) {
        if (how % 4u == 1u && steps == stop_after) {
            status = tclod_select_finish(sel, st);
            break;
        }
        if (how % 4u == 3u && steps == stop_after) {
            FUZZ_CHECK(tclod_select_cancel(sel) == TCLOD_OK, "cancel");
            *dropped = 1;
            break;
        }
        status = tclod_select_step(sel, 0.0, slice, &done, st);
        steps++;
        if (status != TCLOD_OK || done)
            break;
        FUZZ_CHECK(steps < 1000000u, "no end after %u steps", (unsigned)steps);
    }
    FUZZ_CHECK(!tclod_select_pending(sel), "a solve is still pending");
    return status;
}

/* A stream desc from the input; *bad: the field the library must name, or
 * NULL. */
static void read_stream_desc(fuzz_reader *in, tclod_stream_desc *d, const char **bad) {
    uint8_t b = fuzz_u8(in);
    double v[3];
    int k;
    static const char *const names[3] = {"max_request_bytes", "memory_budget", "bytes_in_flight"};
    memset(d, 0, sizeof *d);
    d->max_requests = b < 128 ? (uint32_t)(b % 8u) : (b < 250 ? (uint32_t)b : UINT32_MAX);
    *bad = NULL;
    for (k = 0; k < 3; ++k) {
        uint8_t c = fuzz_u8(in);
        v[k] = c < FUZZ_SPECIAL_DOUBLES ? fuzz_special_double(c)
                                        : ldexp((double)(c & 15u), (int)(c >> 4) * 3);
        if (!*bad && !(v[k] >= 0.0 && v[k] < HUGE_VAL))
            *bad = names[k];
    }
    d->max_request_bytes = v[0];
    d->memory_budget = v[1];
    d->bytes_in_flight = v[2];
}

/* ---- the run ------------------------------------------------------------------- */

static void poison(tclod_stats *st) {
    memset(st, 0xa5, sizeof *st);
}

/* The nodes and smooth objects fuzz_host added since the last sync may be
 * unloaded and sized, one byte each. */
static void settle_new(fuzz_reader *in, const uint8_t *was_live, const uint8_t *was_smooth) {
    run_state *S = &state;
    host_model *m = &S->model;
    uint32_t i;
    for (i = 0; i < m->nodes; ++i)
        if (is_live(m, i) && !was_live[i]) {
            uint8_t b = fuzz_u8(in);
            if (b & 1)
                residency_call(m, &S->res, OP_RESIDENT, i, 0, 0.0, 0);
            if (b & 2)
                residency_call(m, &S->res, OP_BYTES, i, 0, (double)(b >> 2) * 1024.0, 0);
        }
    for (i = 0; i < m->smooth; ++i)
        if (is_smooth_live(m, i) && !was_smooth[i]) {
            uint8_t b = fuzz_u8(in);
            if (b & 1)
                residency_call(m, &S->res, OP_SMOOTH_RESIDENT, i, 0, 0.0, 0);
            if (b & 2)
                residency_call(m, &S->res, OP_SMOOTH_BYTES, i, 0, (double)(b >> 2) * 512.0, 0);
        }
}

static void grow(fuzz_reader *in, uint32_t nodes, uint32_t smooth, int unexpanded) {
    run_state *S = &state;
    uint8_t was_live[MAX_NODES], was_smooth[MAX_SMOOTH];
    uint32_t i;
    memcpy(was_live, S->res.live, sizeof was_live);
    memcpy(was_smooth, S->res.smooth_live, sizeof was_smooth);
    for (i = 0; i < nodes; ++i) {
        if (unexpanded)
            add_unexpanded(in, &S->model);
        else
            add_node(in, &S->model);
    }
    for (i = 0; i < smooth; ++i)
        add_smooth(in, &S->model);
    sync(&S->model, &S->res);
    verify_residency(&S->model, &S->res);
    settle_new(in, was_live, was_smooth);
}

/* One operation between frames. */
static void operate(fuzz_reader *in) {
    run_state *S = &state;
    host_model *m = &S->model;
    uint8_t what = fuzz_u8(in) % 8u;
    switch (what) {
    case 0:
    case 1:
    case 2: {
        uint8_t op;
        tclod_id id;
        int flag;
        double x;
        read_residency_call(in, m, &op, &id, &flag, &x);
        residency_call(m, &S->res, op, id, flag, x, 0);
        break;
    }
    case 3: {
        uint8_t b = fuzz_u8(in);
        grow(in, 1, b & 1, (b & 6) == 6); /* one in four: a part not read yet */
        break;
    }
    case 4: {
        edit e;
        uint8_t was_live[MAX_NODES], was_smooth[MAX_SMOOTH];
        memcpy(was_live, S->res.live, sizeof was_live);
        memcpy(was_smooth, S->res.smooth_live, sizeof was_smooth);
        read_edit(in, m, &e);
        try_edit(m, &e, 0);
        sync(m, &S->res);
        verify_residency(m, &S->res);
        settle_new(in, was_live, was_smooth);
        break;
    }
    case 5: {
        tclod_stream_desc d;
        const char *bad;
        int k;
        read_stream_desc(in, &d, &bad);
        for (k = 0; k < 2; ++k) {
            tclod_status st = tclod_selector_set_stream(S->sel[k], &d);
            if (bad) {
                FUZZ_CHECK(st == TCLOD_ERR_ARG &&
                               strstr(tclod_selector_last_error(S->sel[k]), bad) != NULL,
                           "set_stream with a bad %s gave %d (%s)", bad, (int)st,
                           tclod_selector_last_error(S->sel[k]));
            } else {
                FUZZ_CHECK(st == TCLOD_OK, "set_stream gave %d", (int)st);
            }
        }
        if (!bad)
            S->stream = d;
        else
            count(T_STREAM_DESC_BAD);
        break;
    }
    case 6: {
        uint32_t slot = fuzz_u8(in) % (MAX_NODES + MAX_SMOOTH);
        S->res.answer[slot] = fuzz_double(in);
        break;
    }
    default:
        if (m->nodes > 0) {
            uint32_t id = fuzz_u8(in) % m->nodes;
            if (fuzz_u8(in) & 1)
                m->cost[id] = fuzz_double(in);
            else
                m->benefit[id] = fuzz_double(in);
        }
        break;
    }
}

static void run(fuzz_reader *in) {
    run_state *S = &state;
    host_model *m = &S->model;
    tclod_selector_desc d;
    tclod_scene *s = NULL;
    uint32_t frames, f, i;
    int compare = 1, k;

    memset(S, 0, sizeof *S);
    S->solving = -1;
    FUZZ_CHECK(tclod_scene_create(NULL, &s) == TCLOD_OK, "scene_create");
    model_init(m, s, 2);
    read_desc(in, &d, m);
    d.callbacks.benefit = stream_benefit;
    if (fuzz_u8(in) & 1)
        d.callbacks.bytes = stream_bytes;
    for (i = 0; i < MAX_NODES + MAX_SMOOTH; ++i)
        S->res.answer[i] = 1.0 + (double)(i % 5u);
    f = fuzz_u8(in) % (FIRST_NODES + 1u); /* read in this order, not as arguments */
    i = fuzz_u8(in) % (FIRST_SMOOTH + 1u);
    grow(in, f, i, 0);
    if (desc_invalid(&d, m->live_smooth)) {
        tclod_selector *sel = NULL;
        FUZZ_CHECK(tclod_selector_create(s, &d, NULL, &sel) == TCLOD_ERR_ARG,
                   "a bad description accepted");
        tclod_scene_destroy(s);
        return;
    }
    for (k = 0; k < 2; ++k) {
        S->probes[k].m = m;
        d.callbacks.user = &S->probes[k];
        FUZZ_CHECK(tclod_selector_create(s, &d, NULL, &S->sel[k]) == TCLOD_OK, "selector_create");
    }

    frames = 1u + fuzz_u8(in) % MAX_FRAMES;
    for (f = 0; f < frames; ++f) {
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats[2];
        tclod_status got[2];
        double scale = 0.0;
        uint8_t b, ops, how;
        int bad_frame;

        for (ops = fuzz_u8(in) % 16u; ops > 0; --ops)
            operate(in);
        b = fuzz_u8(in);
        S->held_armed = b & 1;
        if (S->held_armed) {
            S->held_op = (uint8_t)(fuzz_u8(in) % OP_KINDS);
            S->held_a = fuzz_u8(in);
            S->held_b = fuzz_u8(in);
            S->held_x = S->held_op >= OP_BYTES ? read_bytes(in) : 0.0;
        }
        memset(&fr, 0, sizeof fr);
        fr.view = read_view(in, &view);
        for (i = 0; i < m->nodes; ++i)
            if (model_draws(m, i) && !fuzz_bad(m->cost[i]))
                scale += m->cost[i];
        b = fuzz_u8(in);
        fr.budget = b < 32 ? fuzz_special_double(b) : scale * (double)(b - 32) / 128.0;
        b = fuzz_u8(in);
        fr.max_iterations = b < 160 ? 0u : (uint32_t)(b - 159);
        bad_frame = !(fr.budget >= 0.0) || (fr.view && tclod_view_validate(fr.view) != TCLOD_OK) ||
                    smooth_callbacks_missing(&d, m->live_smooth);
        how = fuzz_u8(in);
        for (k = 0; k < 2; ++k) {
            probe *p = &S->probes[k];
            result *after = &results[k == 0 ? 1 : 2];
            lists *l = k == 0 ? &S->after : &S->other;
            int dropped = 0;
            take_result(S->sel[k], &results[0]);
            take_lists(S->sel[k], &S->before);
            S->previous[k] = S->before;
            probe_reset(p, fr.view);
            memset(S->bytes_calls[k], 0, sizeof S->bytes_calls[k]);
            S->held_tried = 0;
            S->solving = k;
            poison(&stats[k]);
            if (k == 0 || how < 64)
                got[k] = tclod_select(S->sel[k], &fr, &stats[k]);
            else
                got[k] = select_resumable(&fr, &stats[k], how, &dropped);
            S->solving = -1;
            take_result(S->sel[k], after);
            take_lists(S->sel[k], l);
            if (bad_frame) {
                FUZZ_CHECK(got[k] == TCLOD_ERR_ARG, "a bad frame gave %d", (int)got[k]);
            } else if (dropped) {
                FUZZ_CHECK(same_result(&results[0], after) && same_lists(&S->before, l),
                           "a cancelled solve changed the result or the lists");
                compare = 0;
                continue;
            } else if (d.strict && p->bad > 0) {
                FUZZ_CHECK(got[k] == TCLOD_ERR_CALLBACK,
                           "strict select gave %d after %u bad values", (int)got[k],
                           (unsigned)p->bad);
            } else {
                FUZZ_CHECK(got[k] == TCLOD_OK, "select gave %d (strict %d, %u bad values)",
                           (int)got[k], d.strict, (unsigned)p->bad);
            }
            if (got[k] != TCLOD_OK) {
                FUZZ_CHECK(same_result(&results[0], after) && same_lists(&S->before, l),
                           "a failed select changed the result or the lists");
            } else {
                model_user_solved(m, (uint32_t)k);
                check_result(k, &fr, &stats[k], after, l, &S->previous[k]);
            }
            if (k == 1 && how >= 64 && how % 4u == 1u)
                compare = 0; /* finished early: another result, still feasible */
        }
        if (compare)
            FUZZ_CHECK(got[0] == got[1] && same_result(&results[1], &results[2]) &&
                           same_lists(&S->after, &S->other),
                       "two selectors given the same frames disagree (frame %u)", (unsigned)f);
    }
    tclod_selector_destroy(S->sel[1]);
    tclod_selector_destroy(S->sel[0]);
    tclod_scene_destroy(s);
}

FUZZ_ENTRY(run)
