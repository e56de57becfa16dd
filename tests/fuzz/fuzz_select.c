/*
 * fuzz_select — libFuzzer target over scene building, scene edits and
 * selection with every solver (the guarantees every part keeps,
 * docs/api.md).
 *
 * The input's bytes choose a selector description (solver, flags, overflow
 * policy, option values valid or not), a scene (parents valid or not; node
 * kinds replace, additive or empty; bounds none, spheres, axis-aligned and
 * oriented boxes, with NaN, infinities, negative extents or skewed axes;
 * smooth objects), the callbacks' values (NaN, infinities, negatives,
 * denormals, huge values, honest or dishonest slopes), and up to six frames
 * (budget, view, limits; values may change between frames, and the scene is
 * edited: nodes added, removed with their subtrees, removed twice, moved with
 * valid or bad bounds, added under removed parents, smooth objects added,
 * removed and moved, an additive node's hidden id edited). Two selectors
 * with the same description see the same frames: the first through
 * tclod_select, the second through tclod_select or the resumable calls
 * (tclod_select_begin, then tclod_select_step with byte-chosen iteration
 * slices, possibly ended early by tclod_select_finish or dropped by
 * tclod_select_cancel). An edit chosen by the input is also tried while the
 * second selector's solve is pending, and another from inside the first
 * callback of each select. After every call the target checks what the
 * header promises:
 *  - scene calls fail exactly when their arguments are bad (an id that is
 *    not a live node, hidden and removed ones included; a parent that is not
 *    live; bounds tclod_bounds_validate rejects), and then change nothing:
 *    counts, liveness of every id, parents and bounds read back;
 *  - an edit while a solve is pending or from a callback gives
 *    TCLOD_ERR_STATE and changes nothing;
 *  - a new node or smooth object gets the next fresh id, or a removed one
 *    only once every selector that solved at all has solved since its
 *    removal; a non-empty additive node takes a second id no call returns
 *    (not live);
 *  - selector creation fails with TCLOD_ERR_ARG exactly for bad descriptions;
 *  - a select fails with TCLOD_ERR_ARG for a bad frame (asking no callback),
 *    with TCLOD_ERR_CALLBACK in strict mode exactly when a callback returned
 *    a bad value, and otherwise succeeds; a failed select leaves result and
 *    stats as they were;
 *  - callbacks are asked only about live nodes that draw (never an empty,
 *    removed or hidden id), each node's benefit and cost at most once per
 *    select, cost only after a benefit > 0 (but the Robin Hood solver's
 *    default complexity, the cost of a finest level the frame found
 *    invisible or does not look at, asked without a view: that node's one
 *    cost call); a query carries
 *    the node's volume as added or last moved, and the screen area and
 *    distance the view helpers give for it;
 *  - a result is a valid selection in the tree the solvers see (empty nodes
 *    passed over): each live node that draws listed at most once; the
 *    ancestors of listed nodes are the refined ones, listed when additive
 *    and not when replace; below a refined node (and at the top, unless
 *    roots were dropped or the solver is Robin Hood's) every node is listed,
 *    refined, culled, or refined into culled nodes; its costs, then the
 *    smooth groups' costs, summed in result order, are <= the budget unless
 *    stats.over_budget, which only TCLOD_OVERFLOW_DRAW_ROOTS sets, with a
 *    cost above the budget and only roots listed; stats carry exactly those
 *    sums and count every bad value; stop reasons follow the overflow and
 *    dropped roots; smooth groups are disjoint ranges of the smooth order
 *    (its live objects) with resolutions in (0, 1] and the callbacks' values
 *    at those resolutions; every smooth resolution is in [0, 1], 0 for
 *    removed objects;
 *  - the two selectors agree bit for bit (no time limit involved), also when
 *    the second selects in iteration slices; while a resumable solve is
 *    pending, other selects are refused; a cancelled solve keeps the result;
 *  - the view helpers return areas in [0, viewport area] for valid views.
 * The callbacks are the host: they read tables, never the library.
 */
#include <tclod/tclod.h>

#include "fuzz_host.h"

#define MAX_FRAMES 6u
/* The first nodes and smooth objects; more may be added between frames. */
#define FIRST_NODES 128u
#define FIRST_SMOOTH 32u

/* ---- results ------------------------------------------------------------------ */

typedef struct result {
    tclod_id ids[MAX_NODES];
    size_t n;
    tclod_smooth_group groups[MAX_SMOOTH];
    size_t groups_n;
} result;

static void take_result(const tclod_selector *sel, result *r) {
    const tclod_id *ids = NULL;
    const tclod_smooth_group *groups = NULL;
    FUZZ_CHECK(tclod_selector_cut(sel, &ids, &r->n) == TCLOD_OK, "cut");
    FUZZ_CHECK(r->n <= MAX_NODES, "cut of %lu nodes", (unsigned long)r->n);
    if (r->n)
        memcpy(r->ids, ids, r->n * sizeof *ids);
    FUZZ_CHECK(tclod_selector_smooth_groups(sel, &groups, &r->groups_n) == TCLOD_OK, "groups");
    FUZZ_CHECK(r->groups_n <= MAX_SMOOTH, "%lu groups", (unsigned long)r->groups_n);
    if (r->groups_n)
        memcpy(r->groups, groups, r->groups_n * sizeof *groups);
}

static int same_result(const result *a, const result *b) {
    return a->n == b->n && a->groups_n == b->groups_n &&
           (a->n == 0 || memcmp(a->ids, b->ids, a->n * sizeof a->ids[0]) == 0) &&
           (a->groups_n == 0 ||
            memcmp(a->groups, b->groups, a->groups_n * sizeof a->groups[0]) == 0);
}

static int same_stats(const tclod_stats *a, const tclod_stats *b) {
    return memcmp(&a->benefit, &b->benefit, sizeof a->benefit) == 0 &&
           memcmp(&a->cost, &b->cost, sizeof a->cost) == 0 && a->iterations == b->iterations &&
           a->increments == b->increments && a->decrements == b->decrements &&
           a->line_searches == b->line_searches && a->variables == b->variables &&
           a->dropped_roots == b->dropped_roots && a->over_budget == b->over_budget &&
           a->invalid_values == b->invalid_values && a->evaluations == b->evaluations &&
           a->stop_reason == b->stop_reason;
}

/* What the probe saw of node v this select: asked, with a benefit > 0 that
 * is not bad (visible), or asked with one that is 0 or bad (culled). */
static int culled(const probe *p, tclod_id v) {
    return p->benefit_calls[v] == 1 &&
           (!(p->benefit_seen[v] > 0.0) || fuzz_bad(p->benefit_seen[v]));
}

/* The tree the solvers see: children of live nodes that draw, per drawn
 * parent (TCLOD_NONE: the roots, at index MAX_NODES). */
typedef struct drawn_tree {
    uint32_t first[MAX_NODES + 2], next[MAX_NODES];
    int8_t covered[MAX_NODES]; /* -1 unknown */
} drawn_tree;

static drawn_tree tree;

static void build_tree(const host_model *m) {
    uint32_t v;
    for (v = 0; v < MAX_NODES + 2u; ++v)
        tree.first[v] = TCLOD_NONE;
    for (v = m->nodes; v-- > 0;) {
        tclod_id p;
        tree.covered[v] = -1;
        if (!model_draws(m, v))
            continue;
        p = drawn_parent(m, v);
        if (p == TCLOD_NONE)
            p = MAX_NODES;
        tree.next[v] = tree.first[p];
        tree.first[p] = v;
    }
}

/* Whether node v (listed nowhere below) stands for a cut of culled nodes:
 * it has children that draw, each culled or covered so in turn. A warm
 * start keeps such a cut when the nodes culled since. */
static int covered(const probe *p, tclod_id v) {
    tclod_id c;
    if (tree.covered[v] >= 0)
        return tree.covered[v];
    tree.covered[v] = tree.first[v] != TCLOD_NONE;
    for (c = tree.first[v]; c != TCLOD_NONE && tree.covered[v]; c = tree.next[c])
        if (!culled(p, c) && !covered(p, c))
            tree.covered[v] = 0;
    return tree.covered[v];
}

/* Everything a successful select promises about its result. */
static void check_result(const tclod_selector *sel, tclod_scene *s, const probe *p,
                         const tclod_selector_desc *d, const tclod_frame *f, const tclod_stats *st,
                         const result *r) {
    const host_model *m = p->m;
    unsigned char mark[MAX_NODES]; /* 1 listed, 2 above a listed node (refined) */
    const tclod_id *order = NULL;
    uint32_t order_n = 0, pos[MAX_SMOOTH], roots = 0;
    double cost = 0.0, benefit = 0.0;
    int roots_may_drop = d->solver == TCLOD_SOLVER_ROBIN_HOOD || st->dropped_roots > 0;
    size_t i;
    tclod_id v;
    memset(mark, 0, sizeof mark);
    for (i = 0; i < r->n; ++i) {
        tclod_id id = r->ids[i];
        FUZZ_CHECK(model_draws(m, id) && !mark[id],
                   "the result lists %u twice, or an id that is not a live node that draws "
                   "(state %d kind %d)",
                   (unsigned)id, id < m->nodes ? (int)m->state[id] : -1,
                   id < m->nodes ? (int)m->kind[id] : -1);
        mark[id] = 1;
        FUZZ_CHECK(p->benefit_calls[id] == 1 && p->cost_calls[id] == 1,
                   "cut node %u was asked benefit %u and cost %u times this select", (unsigned)id,
                   (unsigned)p->benefit_calls[id], (unsigned)p->cost_calls[id]);
        FUZZ_CHECK(p->benefit_seen[id] > 0.0 && !fuzz_bad(p->benefit_seen[id]) &&
                       !fuzz_bad(p->cost_seen[id]),
                   "cut node %u has benefit %g cost %g", (unsigned)id, p->benefit_seen[id],
                   p->cost_seen[id]);
        cost += p->cost_seen[id];
        benefit += p->benefit_seen[id];
    }
    for (i = 0; i < r->n; ++i)
        for (v = drawn_parent(m, r->ids[i]); v != TCLOD_NONE; v = drawn_parent(m, v))
            mark[v] |= 2u;
    build_tree(m);
    for (v = 0; v < m->nodes; ++v) {
        tclod_id up;
        FUZZ_CHECK(p->benefit_calls[v] <= 1 && p->cost_calls[v] <= 1,
                   "node %u asked %u and %u times in one select", (unsigned)v,
                   (unsigned)p->benefit_calls[v], (unsigned)p->cost_calls[v]);
        if (!model_draws(m, v))
            continue;
        up = drawn_parent(m, v);
        roots += up == TCLOD_NONE;
        /* a refined node: additive ones are listed, replace ones not */
        if ((mark[v] & 2u) && (mark[v] & 1u))
            tally(TALLY_LISTED_ADDITIVE_REFINED);
        if (mark[v] & 2u)
            FUZZ_CHECK((m->kind[v] == KIND_ADD) == ((mark[v] & 1u) != 0),
                       "%s node %u is refined (a node below it is listed) and %slisted",
                       m->kind[v] == KIND_ADD ? "additive" : "replace", (unsigned)v,
                       (mark[v] & 1u) ? "" : "not ");
        /* no hole: below a refined node, and at the top, every node is
         * listed, refined, culled or refined into culled nodes */
        if (mark[v] == 0 && !culled(p, v) &&
            ((up != TCLOD_NONE && (mark[up] & 2u)) || (up == TCLOD_NONE && !roots_may_drop)))
            FUZZ_CHECK(covered(p, v),
                       "node %u (benefit asked %u times, %g) is left out below refined node %u: a "
                       "hole",
                       (unsigned)v, (unsigned)p->benefit_calls[v], p->benefit_seen[v],
                       (unsigned)up);
        /* over the budget, the roots at their coarsest and nothing more
         * (docs/scenes.md, overflow) */
        if (st->over_budget)
            FUZZ_CHECK(!(mark[v] & 1u) || up == TCLOD_NONE,
                       "over the budget, node %u below %u is listed: not the roots' coarsest",
                       (unsigned)v, (unsigned)up);
    }

    FUZZ_CHECK(tclod_scene_smooth_order(s, &order, &order_n) == TCLOD_OK &&
                   order_n == m->live_smooth,
               "smooth order of %u objects, %u live", (unsigned)order_n, (unsigned)m->live_smooth);
    memset(pos, 0xff, sizeof pos);
    for (i = 0; i < order_n; ++i) {
        FUZZ_CHECK(order[i] < m->smooth && m->smooth_state[order[i]] == ID_LIVE &&
                       pos[order[i]] == 0xffffffffu,
                   "smooth order lists %u: not live, or twice", (unsigned)order[i]);
        pos[order[i]] = (uint32_t)i;
    }
    if (d->solver == TCLOD_SOLVER_GREEDY)
        FUZZ_CHECK(r->groups_n == 0, "the greedy solver drew %lu smooth groups",
                   (unsigned long)r->groups_n);
    for (i = 0; i < r->groups_n; ++i) {
        const tclod_smooth_group *g = &r->groups[i];
        tclod_query q;
        double res, b, c, slope;
        FUZZ_CHECK((uint64_t)g->first + g->count <= order_n && g->count > 0, "group %u + %u of %u",
                   (unsigned)g->first, (unsigned)g->count, (unsigned)order_n);
        if (i > 0)
            FUZZ_CHECK(g->first >= r->groups[i - 1].first + r->groups[i - 1].count,
                       "groups overlap or are out of order");
        FUZZ_CHECK(g->resolution > 0.0 && g->resolution <= 1.0, "resolution %.17g", g->resolution);
        memset(&q, 0, sizeof q);
        q.id = order[g->first];
        q.count = g->count;
        q.members = order + g->first;
        res = g->resolution > 1e-9 ? g->resolution : 1e-9;
        b = smooth_value(m, &q, res, &slope, 0);
        c = smooth_value(m, &q, res, &slope, 1);
        FUZZ_CHECK(memcmp(&b, &g->benefit, sizeof b) == 0 && memcmp(&c, &g->cost, sizeof c) == 0,
                   "group at %.17g has benefit %.17g cost %.17g, the callbacks say %.17g %.17g",
                   g->resolution, g->benefit, g->cost, b, c);
        FUZZ_CHECK(!fuzz_bad(b) && !fuzz_bad(c), "drawn group with benefit %g cost %g", b, c);
        cost += c;
        benefit += b;
    }
    for (i = 0; i < m->smooth + 2u; ++i) {
        double x = tclod_selector_resolution(sel, (tclod_id)i), expect = 0.0;
        size_t k;
        if (i < m->smooth && m->smooth_state[i] == ID_LIVE)
            for (k = 0; k < r->groups_n; ++k)
                if (pos[i] >= r->groups[k].first &&
                    pos[i] < r->groups[k].first + r->groups[k].count)
                    expect = r->groups[k].resolution;
        FUZZ_CHECK(x >= 0.0 && x <= 1.0 && x == expect,
                   "resolution of smooth %u (state %d) is %.17g, its group says %.17g", (unsigned)i,
                   i < m->smooth ? (int)m->smooth_state[i] : -1, x, expect);
    }

    FUZZ_CHECK(st->over_budget <= 1u, "over_budget %u", (unsigned)st->over_budget);
    if (st->over_budget)
        tally(TALLY_OVER_BUDGET);
    if (st->dropped_roots)
        tally(TALLY_ROOTS_DROPPED);
    if (st->over_budget)
        FUZZ_CHECK(d->overflow == TCLOD_OVERFLOW_DRAW_ROOTS && cost > f->budget,
                   "over_budget with overflow policy %d, cost %.17g, budget %.17g",
                   (int)d->overflow, cost, f->budget);
    else
        FUZZ_CHECK(cost <= f->budget, "selection costs %.17g, budget %.17g", cost, f->budget);
    FUZZ_CHECK(st->cost == cost && st->benefit == benefit,
               "stats say benefit %.17g cost %.17g, the result sums to %.17g and %.17g",
               st->benefit, st->cost, benefit, cost);
    FUZZ_CHECK(st->invalid_values == p->bad, "%u invalid values counted, %u returned",
               (unsigned)st->invalid_values, (unsigned)p->bad);
    FUZZ_CHECK(st->stop_reason >= TCLOD_STOP_BUDGET && st->stop_reason <= TCLOD_STOP_OVER_BUDGET,
               "stop reason %d", (int)st->stop_reason);
    FUZZ_CHECK((st->stop_reason == TCLOD_STOP_OVER_BUDGET) == (st->over_budget == 1u),
               "stop reason %d with over_budget %u", (int)st->stop_reason,
               (unsigned)st->over_budget);
    /* roots left out are said, unless a limit stopped the search or the
     * roots were drawn over the budget */
    FUZZ_CHECK((st->stop_reason == TCLOD_STOP_ROOTS_DROPPED) ==
                   (st->dropped_roots > 0 && !st->over_budget &&
                    st->stop_reason != TCLOD_STOP_ITERATIONS &&
                    st->stop_reason != TCLOD_STOP_TIME && st->stop_reason != TCLOD_STOP_FINISHED),
               "stop reason %d with %u roots dropped", (int)st->stop_reason,
               (unsigned)st->dropped_roots);
    FUZZ_CHECK(st->variables <= m->live_smooth, "%u variables", (unsigned)st->variables);
    FUZZ_CHECK(st->dropped_roots <= roots + m->live_smooth, "%u roots dropped of %u and %u",
               (unsigned)st->dropped_roots, (unsigned)roots, (unsigned)m->live_smooth);
}

/* ---- resumable selection ---------------------------------------------------------- */

/* The selection of a frame through tclod_select_begin and tclod_select_step
 * with slices of slice iterations (how / 4 % 16 + 1); by how % 4: 0, 2 to the
 * end (the result must then equal tclod_select's), 1 ended early by
 * tclod_select_finish after a few steps, 3 cancelled after a few steps
 * (*dropped = 1: the previous result must stay). Checks the pending state,
 * that other selects are refused meanwhile, and that the scene refuses the
 * edit `held` (if not NULL) after begin and after the first step. */
static tclod_status select_resumable(tclod_selector *sel, const tclod_frame *f, tclod_stats *st,
                                     uint8_t how, int *dropped, const host_model *m,
                                     const edit *held) {
    uint32_t slice = (uint32_t)(how / 4u % 16u) + 1u, steps = 0, stop_after = how / 64u;
    tclod_stats other;
    tclod_status status;
    int done = 0;
    *dropped = 0;
    FUZZ_CHECK(!tclod_select_pending(sel), "a solve is pending before begin");
    status = tclod_select_begin(sel, f);
    if (status != TCLOD_OK) {
        FUZZ_CHECK(!tclod_select_pending(sel), "a failed begin left a solve pending");
        return status;
    }
    FUZZ_CHECK(tclod_select_pending(sel), "no solve pending after begin");
    FUZZ_CHECK(tclod_select(sel, f, &other) == TCLOD_ERR_STATE &&
                   tclod_select_begin(sel, f) == TCLOD_ERR_STATE,
               "select or begin while a solve is pending");
    if (held)
        try_held_edit(m, held);
    for (;;) {
        if (how % 4u == 1u && steps == stop_after) {
            status = tclod_select_finish(sel, st);
            break;
        }
        if (how % 4u == 3u && steps == stop_after) {
            FUZZ_CHECK(tclod_select_cancel(sel) == TCLOD_OK, "cancel");
            *dropped = 1;
            status = TCLOD_OK;
            break;
        }
        status = tclod_select_step(sel, 0.0, slice, &done, st);
        steps++;
        if (status != TCLOD_OK || done)
            break;
        if (held && steps == 1)
            try_held_edit(m, held);
        FUZZ_CHECK(steps < 1000000u, "no end after %u steps of %u iterations", (unsigned)steps,
                   (unsigned)slice);
    }
    FUZZ_CHECK(!tclod_select_pending(sel), "a solve is still pending (status %d)", (int)status);
    return status;
}

/* ---- tracing ------------------------------------------------------------------- */

/* FUZZ_TRACE=1 in the environment prints the scene and each select, to read
 * a reproducer by. */
static int tracing = -1;

static void trace_model(const host_model *m) {
    uint32_t i;
    for (i = 0; i < m->nodes; ++i)
        fprintf(stderr, "  node %u: state %d kind %d parent %d hidden %d bounds %d b %g c %g\n",
                (unsigned)i, (int)m->state[i], (int)m->kind[i], (int)m->parent[i],
                (int)m->hidden[i], (int)m->bounds[i].kind, m->benefit[i], m->cost[i]);
    for (i = 0; i < m->smooth; ++i)
        fprintf(stderr, "  smooth %u: state %d\n", (unsigned)i, (int)m->smooth_state[i]);
}

static void trace_select(uint32_t k, const tclod_frame *f, tclod_status got, const tclod_stats *st,
                         const result *r, const probe *p) {
    size_t i;
    fprintf(stderr, "select %u: budget %.17g view %d limit %u -> %d", (unsigned)k, f->budget,
            f->view != NULL, (unsigned)f->max_iterations, (int)got);
    if (got == TCLOD_OK)
        fprintf(stderr, " cost %.17g benefit %.17g stop %d dropped %u over %u iter %u", st->cost,
                st->benefit, (int)st->stop_reason, (unsigned)st->dropped_roots,
                (unsigned)st->over_budget, (unsigned)st->iterations);
    fprintf(stderr, "\n  cut:");
    for (i = 0; i < r->n; ++i)
        fprintf(stderr, " %u", (unsigned)r->ids[i]);
    fprintf(stderr, "\n  asked:");
    for (i = 0; i < p->m->nodes; ++i)
        if (p->benefit_calls[i])
            fprintf(stderr, " %u(b %g c %g)", (unsigned)i, p->benefit_seen[i],
                    p->cost_calls[i] ? p->cost_seen[i] : -1.0);
    fprintf(stderr, "\n");
}

/* ---- the run ------------------------------------------------------------------- */

typedef struct run_state {
    host_model model;
    probe probes[2];
    result before, after, other;
    edit callback_edit, pending_edit, edit;
} run_state;

static run_state state;

static void poison(tclod_stats *st) {
    memset(st, 0xa5, sizeof *st);
}

static int untouched(const tclod_stats *st) {
    tclod_stats pattern;
    poison(&pattern);
    return memcmp(st, &pattern, sizeof pattern) == 0;
}

static void run(fuzz_reader *in) {
    host_model *m = &state.model;
    tclod_selector_desc d;
    tclod_selector *sel[2] = {NULL, NULL};
    tclod_scene *s = NULL;
    uint32_t n, i, frames, f;
    int invalid, compare = 1;
    tclod_status st;

    memset(&state, 0, sizeof state);
    FUZZ_CHECK(tclod_scene_create(NULL, &s) == TCLOD_OK, "scene_create");
    model_init(m, s, 2);
    read_desc(in, &d, m);
    n = fuzz_u8(in) % (FIRST_NODES + 1u);
    for (i = 0; i < n; ++i)
        add_node(in, m);
    n = fuzz_u8(in) % (FIRST_SMOOTH + 1u);
    for (i = 0; i < n; ++i)
        add_smooth(in, m);
    verify_scene(m);

    if (tracing < 0)
        tracing = getenv("FUZZ_TRACE") != NULL;
    if (tracing) {
        fprintf(stderr, "solver %d cold %d strict %d overflow %d lookahead %u restarts %d\n",
                (int)d.solver, d.cold_start, d.strict, (int)d.overflow,
                (unsigned)d.greedy.lookahead, (int)d.greedy.restarts);
        trace_model(m);
    }
    invalid = desc_invalid(&d, m->live_smooth);
    for (i = 0; i < 2; ++i) {
        tclod_selector *const sentinel = (tclod_selector *)(void *)&state;
        sel[i] = sentinel;
        state.probes[i].m = m;
        d.callbacks.user = &state.probes[i];
        /* the second selector is asked in batches where the greedy gathers
         * nodes: it must select what the first selects, bit for bit */
        if (i == 1 && d.callbacks.benefit && d.callbacks.cost) {
            d.callbacks.benefit_batch = host_benefit_batch;
            d.callbacks.cost_batch = host_cost_batch;
        }
        st = tclod_selector_create(s, &d, NULL, &sel[i]);
        if (invalid) {
            FUZZ_CHECK(st == TCLOD_ERR_ARG && sel[i] == sentinel,
                       "selector_create accepted a bad description (%d)", (int)st);
            tclod_scene_destroy(s);
            return;
        }
        FUZZ_CHECK(st == TCLOD_OK && sel[i] != sentinel, "selector_create gave %d", (int)st);
    }
    if (fuzz_u8(in) & 1) /* otherwise the first select prepares the scene */
        FUZZ_CHECK(tclod_scene_prepare(s) == TCLOD_OK, "prepare");

    frames = 1u + fuzz_u8(in) % MAX_FRAMES;
    for (f = 0; f < frames; ++f) {
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats[2];
        tclod_status got[2];
        double scale = 0.0;
        uint8_t b, g, limit, how;
        int bad_frame, valid;
        const edit *pending = NULL;

        /* between frames: changed values, a grown scene, edits; and the
         * edits tried while solves hold the scene */
        for (b = fuzz_u8(in) % 8u; b > 0 && m->nodes > 0; --b) {
            uint32_t id = fuzz_u8(in) % m->nodes;
            if (fuzz_u8(in) & 1)
                m->cost[id] = fuzz_double(in);
            else
                m->benefit[id] = fuzz_double(in);
        }
        g = fuzz_u8(in);
        for (b = g % 4u; b > 0; --b) {
            add_node(in, m);
            if (fuzz_u8(in) & 1)
                add_smooth(in, m);
        }
        for (b = (g >> 2) % 4u; b > 0; --b) {
            read_edit(in, m, &state.edit);
            try_edit(m, &state.edit, 0);
        }
        for (i = 0; i < 2; ++i)
            state.probes[i].held_edit = NULL;
        if (g & 0x40) {
            read_edit(in, m, &state.callback_edit);
            for (i = 0; i < 2; ++i)
                state.probes[i].held_edit = &state.callback_edit;
        }
        if (g & 0x80) {
            read_edit(in, m, &state.pending_edit);
            pending = &state.pending_edit;
        }

        memset(&fr, 0, sizeof fr);
        fr.view = read_view(in, &view);
        for (i = 0; i < m->nodes; ++i)
            if (model_draws(m, i) && !fuzz_bad(m->cost[i]))
                scale += m->cost[i];
        b = fuzz_u8(in);
        fr.budget = b < 32 ? fuzz_special_double(b) : scale * (double)(b - 32) / 128.0;
        limit = fuzz_u8(in);
        fr.max_iterations = limit < 128 ? 0u : (uint32_t)(limit - 127);
        switch (fuzz_u8(in) % 8u) {
        case 1:
            fr.solve_seconds = (double)INFINITY;
            break;
        case 2:
            fr.solve_seconds = (double)NAN;
            break;
        case 3:
            fr.solve_seconds = -1.0;
            break;
        case 4:
            fr.solve_seconds = 1e300;
            break;
        case 5: /* stops at the first look at the clock: results may differ */
            fr.solve_seconds = 1e-300;
            compare = 0;
            break;
        default:
            fr.solve_seconds = 0.0;
            break;
        }
        valid = fr.view ? view_valid(fr.view) : 1;
        if (fr.view && valid != -1)
            FUZZ_CHECK((tclod_view_validate(fr.view) == TCLOD_OK) == (valid == 1),
                       "view_validate disagrees with the header (%d)", valid);
        if (fr.view && tclod_view_validate(fr.view) == TCLOD_OK)
            check_view_helpers(fr.view, m);
        bad_frame = !(fr.budget >= 0.0) || !(fr.solve_seconds >= 0.0) ||
                    (fr.view && tclod_view_validate(fr.view) != TCLOD_OK) ||
                    smooth_callbacks_missing(&d, m->live_smooth);

        how = fuzz_u8(in);
        for (i = 0; i < 2; ++i) {
            probe *p = &state.probes[i];
            result *after = i == 0 ? &state.after : &state.other;
            int dropped = 0;
            take_result(sel[i], &state.before);
            probe_reset(p, fr.view);
            poison(&stats[i]);
            if (i == 0 || how < 64)
                got[i] = tclod_select(sel[i], &fr, &stats[i]);
            else
                got[i] = select_resumable(sel[i], &fr, &stats[i], how, &dropped, m, pending);
            take_result(sel[i], after);
            if (tracing) {
                if (i == 0)
                    trace_model(m);
                trace_select(i, &fr, got[i], &stats[i], after, p);
            }
            if (bad_frame) {
                FUZZ_CHECK(got[i] == TCLOD_ERR_ARG && p->calls == 0,
                           "a bad frame gave %d after %u callback calls", (int)got[i],
                           (unsigned)p->calls);
            } else if (dropped) {
                FUZZ_CHECK(same_result(&state.before, after),
                           "a cancelled solve changed the result");
                compare = 0; /* the other selector moved on */
                continue;
            } else if (d.strict && p->bad > 0) {
                FUZZ_CHECK(got[i] == TCLOD_ERR_CALLBACK,
                           "strict select gave %d after %u bad callback values", (int)got[i],
                           (unsigned)p->bad);
            } else {
                FUZZ_CHECK(got[i] == TCLOD_OK, "select gave %d (strict %d, %u bad values)",
                           (int)got[i], d.strict, (unsigned)p->bad);
            }
            if (got[i] != TCLOD_OK) {
                FUZZ_CHECK(untouched(&stats[i]), "a failed select wrote the stats");
                FUZZ_CHECK(same_result(&state.before, after), "a failed select changed the result");
            } else {
                model_user_solved(m, i);
                check_result(sel[i], s, p, &d, &fr, &stats[i], after);
            }
            if (i == 1 && how >= 64 && how % 4u == 1u)
                compare = 0; /* finished early: a different, still feasible, result */
        }
        if (compare) {
            FUZZ_CHECK(got[0] == got[1] && same_result(&state.after, &state.other) &&
                           (got[0] != TCLOD_OK || same_stats(&stats[0], &stats[1])),
                       "two selectors given the same frames disagree (frame %u, %s)", (unsigned)f,
                       how < 64 ? "tclod_select" : "resumable, iteration slices");
        }
    }
    tclod_selector_destroy(sel[1]);
    tclod_selector_destroy(sel[0]);
    tclod_scene_destroy(s);
}

FUZZ_ENTRY(run)
