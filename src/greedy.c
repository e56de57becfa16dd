/*
 * TCLOD_SOLVER_GREEDY: the Mason–Blake increment over LOD hierarchies
 * ([MB97], as summarised in [GEO §3.1–3.2] and [ZMK02 §2.1.1]).
 *
 * A selection is a cut through the hierarchies. An increment replaces a cut
 * node by its children; increments are taken best Δbenefit/Δcost first from an
 * indexed heap, and one that does not fit is skipped while smaller ones are
 * still tried (fill). A cold solve starts from the roots and, because plain
 * ratio order can be arbitrarily bad, finally compares its result with the best
 * skipped increment taken alone (with the increments above it), which keeps it
 * within half of the optimum when benefits show diminishing returns. The
 * increments keyed above the previous cold solve's first misfit, the heap's
 * first pops, are taken without ordering them when they surely fit
 * (take_closure). With lookahead an increment may replace its node by the
 * best-ratio cut of its subtree a few levels deep (Dinkelbach's method over
 * the subtree's dynamic program, lookahead_key), for benefits whose returns
 * do not diminish. When even the roots do not fit, refinements that cost
 * less than what they replace (children out of view cost nothing) come
 * before roots are left out (shed_cost). A warm solve starts from the
 * previous cut: it re-evaluates only the frontier (cut nodes, their children
 * and their collapsible parents), first takes the collapses a cold solve
 * would have made (free ones, into invisible parents, those that gain),
 * applies decrements (children -> parent, least benefit lost per cost saved
 * first) while over budget, then increments and increment/decrement swaps
 * while they gain; on a scene with nodes that are
 * not resident it first gives up the cut nodes residency no longer allows
 * (stream_repair).
 * A final exact re-summation in result order repairs any rounding drift, so the
 * budget guarantee holds to the last bit.
 *
 * This file holds the papers' loop, the starts and the final repair; the
 * lookahead is in greedy_lookahead.c, the passes after the plain cold one
 * (T(n) and the restarts' search) in greedy_search.c, and what the three
 * share in greedy_internal.h.
 */
#include "greedy_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Iterations between two reads of the clock. */
#define CLOCK_STRIDE 16u

/* ---- evaluation ------------------------------------------------------------ */

/* Screen area and distance of node n's bounds in this solve. The levels of
 * one object usually share its bounds: a parent evaluated in this solve
 * already (the parent of a chain's level always is) lends its figures. */
static void greedy_measure(const tclod_selector *sel, tclod_id n, float *area, double *distance) {
    const tclod_scene *s = sel->scene;
    const tclod_node_bounds *bounds = &s->bounds[n];
    tclod_id p = s->parent[n];
    if (p != TCLOD_NONE && sel->node[p].stamp == sel->solve_id &&
        memcmp(bounds, &s->bounds[p], sizeof *bounds) == 0) {
        *area = sel->node[p].area;
        *distance = (double)sel->node[p].distance;
    } else {
        tclod_view_measure_bounds(&sel->view, bounds, s->boxes, area, distance);
    }
}

/* The callbacks of node n, not evaluated in this solve yet. */
static int evaluate_fresh(tclod_selector *sel, tclod_id n) {
    float area = -1.0f;
    double distance = -1.0;
    if (sel->has_view && sel->scene->bounds[n].r >= 0.0)
        greedy_measure(sel, n, &area, &distance);
    return tclod_evaluate_measured(sel, n, area, distance);
}

/* Values are cached for the solve: stamp == solve_id. */
static int evaluate(tclod_selector *sel, tclod_id n) {
    return sel->node[n].stamp == sel->solve_id ? 0 : evaluate_fresh(sel, n);
}

int tclod_evaluate_node(tclod_selector *sel, tclod_id n) {
    return evaluate(sel, n);
}

int tclod_evaluate_self(tclod_selector *sel, tclod_id n) {
    tclod_id owner = sel->scene->up[n];
    tclod_node_state *st = &sel->node[n];
    const tclod_node_state *o = &sel->node[owner];
    tclod_query *q = &sel->query;
    if (o->stamp != sel->solve_id && evaluate_fresh(sel, owner) < 0)
        return -1;
    st->stamp = sel->solve_id;
    st->benefit = o->benefit;
    st->cost = o->cost;
    st->area = o->area;
    st->distance = o->distance;
    q->id = owner;
    q->screen_area = o->area;
    q->distance = o->distance;
    q->bounds = sel->scene->bounds[owner].r >= 0.0 ? tclod_query_bounds(sel, owner) : NULL;
    return o->benefit > 0.0;
}

void tclod_bad_value(tclod_selector *sel) {
    sel->stats.invalid_values++;
    if (sel->desc.strict)
        sel->failed = 1;
}

int tclod_evaluate_invisible(tclod_selector *sel, tclod_node_state *st, double b) {
    if (!(b >= 0.0 && b < HUGE_VAL)) { /* NaN, infinite or negative */
        tclod_bad_value(sel);
        b = 0.0;
    }
    st->benefit = b; /* 0 or -0 */
    st->cost = 0.0;
    return sel->failed ? -1 : 0;
}

int tclod_evaluate_bad_cost(tclod_selector *sel, tclod_node_state *st, double c) {
    tclod_id n = (tclod_id)(st - sel->node); /* st is node n's record */
    if (!(c >= 0.0 && c < HUGE_VAL)) {       /* NaN, infinite or negative; -0 passes */
        tclod_bad_value(sel);
        c = HUGE_VAL;
    }
    st->cost = c;
    if (sel->failed)
        return -1;
    if (tclod_scene_streams(sel->scene) && (sel->scene->flags[n] & TCLOD_NODE_ABSENT))
        return tclod_evaluate_absent(sel, n);
    return 1;
}

/* ---- the cut and its running sums ------------------------------------------ */

static void account(tclod_selector *sel, tclod_id n, double sign) {
    const tclod_node_state *st = &sel->node[n];
    if (!greedy_counts(sel, n))
        return;
    sel->benefit_sum += sign * st->benefit;
    if (greedy_unaffordable(st->cost)) {
        if (sign > 0.0)
            sel->unaffordable++;
        else
            sel->unaffordable--;
    } else {
        tclod_add_compensated(&sel->cost_sum, &sel->cost_err, sign * st->cost);
    }
}

static void greedy_cut_add(tclod_selector *sel, tclod_id n) {
    assert(sel->node[n].cut_pos == TCLOD_NONE);
    sel->node[n].cut_pos = sel->cut_count;
    sel->cut[sel->cut_count++] = n;
    sel->flags[n] |= TCLOD_FLAG_MOVED;
    account(sel, n, 1.0);
}

static void greedy_cut_remove(tclod_selector *sel, tclod_id n) {
    uint32_t slot = sel->node[n].cut_pos;
    tclod_id last = sel->cut[--sel->cut_count];
    account(sel, n, -1.0);
    sel->cut[slot] = last;
    sel->node[last].cut_pos = slot;
    sel->flags[last] |= TCLOD_FLAG_MOVED;
    sel->node[n].cut_pos = TCLOD_NONE;
}

static const tclod_id *children_of(const tclod_selector *sel, tclod_id n, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    *count = s->child_count[n];
    /* no slab at all while no node has had a child */
    return *count ? s->children + s->child_first[n] : NULL;
}

/* Gathers the children of node n that increment_key will evaluate (those of
 * a visible node), without lookahead, whose increments reach further down.
 * Returns 0 or -1. */
static int gather_children(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    uint32_t k, first = s->child_first[n], count = s->child_count[n];
    if (count == 0 || sel->desc.greedy.lookahead > 0 || !greedy_counts(sel, n))
        return 0;
    for (k = 0; k < count; ++k)
        if (tclod_batch_add(sel, s->children[first + k]) != 0)
            return -1;
    return 0;
}

/* gather_children for the m nodes ns[], evaluated in one batch. */
static int gather_all_children(tclod_selector *sel, const tclod_id *ns, uint32_t m) {
    uint32_t i;
    for (i = 0; i < m; ++i)
        if (gather_children(sel, ns[i]) != 0)
            return -1;
    return tclod_batch_flush(sel);
}

/* ---- increments and decrements ------------------------------------------------ */

/* Evaluates the children of a visible cut node and computes its increment.
 * Returns the heap key, or NaN when it is no candidate (no children, no gain,
 * an unaffordable child); -1 in *failed on a strict error. */
static double increment_key(tclod_selector *sel, tclod_id n, int *failed) {
    const tclod_scene *s = sel->scene;
    tclod_node_state *node = sel->node;
    uint32_t i = s->child_first[n], end = i + s->child_count[n];
    double sum_b = 0.0, sum_c = 0.0, db, dc;
    int affordable = 1;
    *failed = 0;
    if (i == end || !greedy_counts(sel, n))
        return (double)NAN;
    for (; i < end; ++i) {
        tclod_id c = s->children[i];
        double cost;
        if (node[c].stamp != sel->solve_id && evaluate_fresh(sel, c) != 0) {
            *failed = 1;
            return (double)NAN;
        }
        sum_b += node[c].benefit;
        cost = node[c].cost;
        affordable &= !greedy_unaffordable(cost);
        sum_c += greedy_unaffordable(cost) ? 0.0 : cost; /* sum_c >= +0: adding +0 changes no bit */
    }
    db = sum_b - node[n].benefit;
    dc = sum_c - node[n].cost; /* -inf when n itself is unaffordable */
    sel->greedy.delta[n].delta_b = db;
    sel->greedy.delta[n].delta_c = dc;
    if (!affordable || !isfinite(sum_c) || !(db > 0.0))
        return (double)NAN;
    return dc > 0.0 ? db / dc : HUGE_VAL;
}

/* The by-cost heap's key of queued increment n; `look`: the selector has a
 * lookahead (a constant wherever this is inlined). */
static inline double cheap_key(tclod_selector *sel, tclod_id n, int look) {
    if (look && (sel->flags[n] & TCLOD_FLAG_JUMP))
        return -tclod_greedy_cheapest_jump(sel, n);
    return -sel->greedy.delta[n].delta_c;
}

/* 1 when an increment of this key waits in the plain pass's closure queue
 * rather than in the heap (see take_closure). */
static int closes(const tclod_selector *sel, double key) {
    return sel->resume.greedy.closing && key >= sel->resume.greedy.closure_key;
}

/* sel->greedy.cheap_live: the by-cost heap is not kept (none), holds every
 * queued increment in heap order (live), or holds them all, order not yet
 * restored (pending: a warm start queues them there while their Δc is at
 * hand, and the first misfit heaps them). */
enum { CHEAP_NONE = 0, CHEAP_LIVE = 1, CHEAP_PENDING = 2 };

/* Queues n's increment of key `key` (NaN: no candidate), pushed, or appended
 * (heap order restored by the caller); `look` as cheap_key. */
static inline void enqueue_as(tclod_selector *sel, tclod_id n, double key, int append, int look) {
    if (closes(sel, key)) {
        sel->scratch[sel->resume.greedy.closure_tail++] = n;
    } else if (key == key) {
        if (append || sel->resume.greedy.closing) /* the closure's end builds the heap */
            tclod_heap_append(&sel->greedy.inc, n, key);
        else
            tclod_heap_push(&sel->greedy.inc, n, key);
        if (sel->greedy.cheap_live == CHEAP_LIVE)
            tclod_heap_push(&sel->greedy.cheap, n, cheap_key(sel, n, look));
        else if (sel->greedy.cheap_live == CHEAP_PENDING)
            tclod_heap_append(&sel->greedy.cheap, n, cheap_key(sel, n, look));
    }
}

void tclod_greedy_enqueue_looking(tclod_selector *sel, tclod_id n, double key, int append) {
    enqueue_as(sel, n, key, append, 1);
}

/* queue_increment without a lookahead (greedy_lookahead.c has the other). */
static inline int queue_plain(tclod_selector *sel, tclod_id n, int append) {
    int failed;
    double key = increment_key(sel, n, &failed);
    if (failed)
        return -1;
    enqueue_as(sel, n, key, append, 0);
    return 0;
}

/* Queues n's increment if it is a candidate (append: heap order restored by
 * the caller; otherwise pushed). The by-cost heap exists only once the fill
 * has begun (see increment_may_fit). */
TCLOD_ALWAYS_INLINE int queue_increment(tclod_selector *sel, tclod_id n, int append) {
    return sel->desc.greedy.lookahead > 0 ? tclod_greedy_queue_looking(sel, n, append)
                                          : queue_plain(sel, n, append);
}

/* Puts n's increment of key `key` in the place of *held's queued one, which
 * is then gone; nothing when it is no candidate. `look` as cheap_key. */
static inline void rekey_as(tclod_selector *sel, tclod_id n, tclod_id *held, double key, int look) {
    if (key == key) {
        tclod_heap_replace(&sel->greedy.inc, *held, n, key);
        if (sel->greedy.cheap_live)
            tclod_heap_replace(&sel->greedy.cheap, *held, n, cheap_key(sel, n, look));
        *held = TCLOD_NONE;
    }
}

void tclod_greedy_rekey_looking(tclod_selector *sel, tclod_id n, tclod_id *held, double key) {
    rekey_as(sel, n, held, key, 1);
}

/* requeue_increment without a lookahead, as queue_plain. */
static inline int requeue_plain(tclod_selector *sel, tclod_id n, tclod_id *held) {
    int failed;
    double key;
    assert(!sel->resume.greedy.closing); /* the closure takes only increments it queued */
    key = increment_key(sel, n, &failed);
    if (failed)
        return -1;
    rekey_as(sel, n, held, key, 0);
    return 0;
}

/* Queues n's increment, if it is a candidate, in the place of old's queued
 * one, which is then gone (*held = TCLOD_NONE); otherwise pushes it. */
static int requeue_increment(tclod_selector *sel, tclod_id n, tclod_id *held) {
    if (*held == TCLOD_NONE)
        return queue_increment(sel, n, 0);
    return sel->desc.greedy.lookahead > 0 ? tclod_greedy_requeue_looking(sel, n, held)
                                          : requeue_plain(sel, n, held);
}

static void unqueue_increment(tclod_selector *sel, tclod_id n) {
    if (!tclod_heap_contains(&sel->greedy.inc, n))
        return;
    tclod_heap_remove(&sel->greedy.inc, n);
    if (sel->greedy.cheap_live)
        tclod_heap_remove(&sel->greedy.cheap, n);
}

static void clear_heaps(tclod_selector *sel) {
    tclod_heap_clear(&sel->greedy.inc);
    tclod_heap_clear(&sel->greedy.cheap);
    tclod_heap_clear(&sel->greedy.dec);
    sel->greedy.cheap_live = CHEAP_NONE;
}

static tclod_id pop_increment(tclod_selector *sel) {
    tclod_id n = sel->greedy.inc.items[0].id;
    unqueue_increment(sel, n);
    return n;
}

/* Pops misfit n; a lookahead increment is queued again as a cut that fits
 * (tclod_greedy_refit_jump), when one gains. */
static void skip_misfit(tclod_selector *sel, tclod_id n) {
    double key;
    pop_increment(sel);
    sel->stats.iterations++;
    if (!(sel->flags[n] & TCLOD_FLAG_JUMP))
        return;
    key = tclod_greedy_refit_jump(sel, n);
    if (key == key) {
        tclod_heap_push(&sel->greedy.inc, n, key);
        if (sel->greedy.cheap_live == CHEAP_LIVE)
            tclod_heap_push(&sel->greedy.cheap, n, cheap_key(sel, n, 1));
        else if (sel->greedy.cheap_live == CHEAP_PENDING)
            tclod_heap_append(&sel->greedy.cheap, n, cheap_key(sel, n, 1));
    }
}

/* Parks misfit n, which the warm fill skips (a plain increment, not a
 * lookahead's jump or refit, still queued): the swaps that follow the fill
 * want the best increments, and the fill skips the best that do not fit. */
static void park_misfit(tclod_selector *sel, tclod_id n) {
    uint32_t at = sel->cap - ++sel->resume.greedy.parked;
    sel->scratch[at] = n;
    sel->scratch_key[at] = sel->greedy.inc.items[0].key;
    pop_increment(sel);
    sel->stats.iterations++;
}

/* Queues the parked misfits again, those still in the cut and not queued. */
static void unpark_misfits(tclod_selector *sel) {
    uint32_t at;
    for (at = sel->cap - sel->resume.greedy.parked; at < sel->cap; ++at) {
        tclod_id n = sel->scratch[at];
        if (sel->node[n].cut_pos != TCLOD_NONE && !tclod_heap_contains(&sel->greedy.inc, n))
            enqueue_as(sel, n, sel->scratch_key[at], 0, sel->desc.greedy.lookahead > 0);
    }
    sel->resume.greedy.parked = 0;
}

/* 1 when some queued increment fits the remaining budget. Increments that do
 * not fit stay unfit while the search only adds cost, so this ends the fill.
 * The increments ordered by cost are needed only from the first misfit on, so
 * they are heaped then, in O(n), and kept up to date after that. */
static int increment_may_fit(tclod_selector *sel) {
    if (sel->greedy.cheap_live == CHEAP_PENDING) {
        tclod_heap_build(&sel->greedy.cheap);
        sel->greedy.cheap_live = CHEAP_LIVE;
    } else if (sel->greedy.cheap_live == CHEAP_NONE) {
        uint32_t i;
        if (sel->desc.greedy.lookahead > 0) {
            for (i = 0; i < sel->greedy.inc.count; ++i) {
                tclod_id n = sel->greedy.inc.items[i].id;
                tclod_heap_append(&sel->greedy.cheap, n, cheap_key(sel, n, 1));
            }
        } else {
            for (i = 0; i < sel->greedy.inc.count; ++i) {
                tclod_id n = sel->greedy.inc.items[i].id;
                tclod_heap_append(&sel->greedy.cheap, n, -sel->greedy.delta[n].delta_c);
            }
        }
        tclod_heap_build(&sel->greedy.cheap);
        sel->greedy.cheap_live = CHEAP_LIVE;
    }
    return sel->greedy.cheap.count > 0 && sel->unaffordable == 0 &&
           tclod_within(sel, sel->cost_sum - sel->greedy.cheap.items[0].key,
                        greedy_cut_budget(sel));
}

/* 1 when every child of p is in the cut. */
static int collapsible(const tclod_selector *sel, tclod_id p) {
    uint32_t count, i;
    const tclod_id *ch = children_of(sel, p, &count);
    for (i = 0; i < count; ++i)
        if (sel->node[ch[i]].cut_pos == TCLOD_NONE)
            return 0;
    return count > 0;
}

/* Key of the decrement collapsing p's children (all in the cut) into p:
 * smallest loss per saved cost first, so the heap stores it negated. Free
 * collapses (no loss, no extra cost), collapses into an invisible p (which a
 * cold solve culls with its subtree, whatever its children's own volumes
 * say) and those removing unaffordable children come first; collapses that
 * save nothing come last. */
static double decrement_key(tclod_selector *sel, tclod_id p) {
    uint32_t count, i;
    const tclod_id *ch = children_of(sel, p, &count);
    double sum_b = 0.0, sum_c = 0.0, loss, saved;
    int unaffordable = 0;
    for (i = 0; i < count; ++i) {
        if (!greedy_counts(sel, ch[i]))
            continue;
        sum_b += sel->node[ch[i]].benefit;
        if (isinf(sel->node[ch[i]].cost))
            unaffordable = 1;
        else
            sum_c += sel->node[ch[i]].cost;
    }
    loss = sum_b - sel->node[p].benefit;
    saved = sum_c - sel->node[p].cost;
    sel->greedy.delta[p].delta_b = loss;
    sel->greedy.delta[p].delta_c = saved;
    if (isinf(sel->node[p].cost) || !isfinite(sum_c))
        return -HUGE_VAL;
    if (unaffordable || !(sel->node[p].benefit > 0.0))
        return HUGE_VAL;
    if (loss <= 0.0 && saved >= 0.0)
        return HUGE_VAL;
    if (saved > 0.0)
        return -(loss / saved);
    return -HUGE_VAL;
}

/* Queues the decrement into p, known collapsible and not queued. */
static int queue_collapsible(tclod_selector *sel, tclod_id p, int append) {
    double key;
    if (evaluate(sel, p) != 0)
        return -1;
    key = decrement_key(sel, p);
    if (append)
        tclod_heap_append(&sel->greedy.dec, p, key);
    else
        tclod_heap_push(&sel->greedy.dec, p, key);
    return 0;
}

/* Queues the decrement into p when p is collapsible. */
static int queue_decrement(tclod_selector *sel, tclod_id p, int append) {
    if (p == TCLOD_NONE || tclod_heap_contains(&sel->greedy.dec, p) || !collapsible(sel, p))
        return 0;
    return queue_collapsible(sel, p, append);
}

/* Replaces cut node n by its children (or, with lookahead, by the deeper cut
 * its key found). The first child with a candidate increment takes the place
 * of n's queued increment: one heap update instead of a removal and an
 * insertion. */
TCLOD_ALWAYS_INLINE int apply_increment_as(tclod_selector *sel, tclod_id n, int track_dec) {
    uint32_t count, i;
    const tclod_id *ch = children_of(sel, n, &count);
    tclod_id parent = sel->scene->parent[n];
    tclod_id held = tclod_heap_contains(&sel->greedy.inc, n) ? n : TCLOD_NONE;
    double path_b = sel->path[2u * n] + sel->greedy.delta[n].delta_b;
    double path_c = sel->path[2u * n + 1u] + sel->greedy.delta[n].delta_c;
    greedy_cut_remove(sel, n);
    if (sel->flags[n] & (TCLOD_FLAG_JUMP | TCLOD_FLAG_REFIT)) {
        if (tclod_greedy_apply_jump(sel, n, track_dec, &held, path_b, path_c) != 0)
            return -1;
    } else {
        if (sel->batching && gather_all_children(sel, ch, count) != 0)
            return -1;
        for (i = 0; i < count; ++i) {
            greedy_cut_add(sel, ch[i]);
            sel->path[2u * ch[i]] = path_b;
            sel->path[2u * ch[i] + 1u] = path_c;
            if (requeue_increment(sel, ch[i], &held) != 0)
                return -1;
        }
        if (track_dec && queue_decrement(sel, n, 0) != 0)
            return -1;
    }
    if (held != TCLOD_NONE)
        unqueue_increment(sel, held);
    sel->stats.increments++;
    if (track_dec && parent != TCLOD_NONE && tclod_heap_contains(&sel->greedy.dec, parent))
        tclod_heap_remove(&sel->greedy.dec, parent);
    return 0;
}

static int apply_increment(tclod_selector *sel, tclod_id n, int track_dec) {
    return apply_increment_as(sel, n, track_dec);
}

/* apply_increment without decrements to track: a cold pass's. */
static int apply_increment_cold(tclod_selector *sel, tclod_id n) {
    return apply_increment_as(sel, n, 0);
}

static int apply_decrement(tclod_selector *sel, tclod_id p) {
    uint32_t count, i;
    const tclod_id *ch = children_of(sel, p, &count);
    if (tclod_heap_contains(&sel->greedy.dec, p))
        tclod_heap_remove(&sel->greedy.dec, p);
    for (i = 0; i < count; ++i) {
        unqueue_increment(sel, ch[i]);
        if (tclod_heap_contains(&sel->greedy.dec, ch[i]))
            tclod_heap_remove(&sel->greedy.dec, ch[i]);
        greedy_cut_remove(sel, ch[i]);
    }
    greedy_cut_add(sel, p);
    sel->stats.decrements++;
    if (queue_increment(sel, p, 0) != 0)
        return -1;
    return queue_decrement(sel, sel->scene->parent[p], 0);
}

/* ---- for greedy_lookahead.c -------------------------------------------------- */

double tclod_greedy_increment_key(tclod_selector *sel, tclod_id n, int *failed) {
    return increment_key(sel, n, failed);
}

void tclod_greedy_cut_add(tclod_selector *sel, tclod_id n) {
    greedy_cut_add(sel, n);
}

int tclod_greedy_requeue(tclod_selector *sel, tclod_id n, tclod_id *held) {
    return requeue_increment(sel, n, held);
}

int tclod_greedy_queue_decrement(tclod_selector *sel, tclod_id p) {
    return queue_decrement(sel, p, 0);
}

/* ---- roots ------------------------------------------------------------------- */

/* 1 when root r fits on top of `used` (an unaffordable root never does, even
 * under an unlimited budget). */
static int fits_alone(const tclod_selector *sel, tclod_id r, double used) {
    return !isinf(sel->node[r].cost) && used + sel->node[r].cost <= greedy_cut_budget(sel);
}

/* Keeps the visible roots of the cut in scratch[0..n) order, starting with
 * scratch[first] when first is not TCLOD_NONE, each one that still fits on
 * top of those kept before it; flags the others as dropped. The running sums
 * are recounted from scratch, since subtracting from a sum that overflowed to
 * inf would leave it inf. */
static void keep_roots(tclod_selector *sel, uint32_t n, uint32_t first) {
    double used = 0.0;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        uint32_t k = first == TCLOD_NONE ? i : (i == 0 ? first : (i <= first ? i - 1u : i));
        tclod_id r = sel->scratch[k];
        if (fits_alone(sel, r, used)) {
            sel->flags[r] &= (uint8_t)~TCLOD_FLAG_DROPPED;
            used += sel->node[r].cost;
        } else {
            sel->flags[r] |= TCLOD_FLAG_DROPPED;
        }
    }
    sel->cost_sum = sel->cost_err = sel->benefit_sum = 0.0;
    sel->unaffordable = 0;
    for (i = 0; i < sel->cut_count; ++i)
        account(sel, sel->cut[i], 1.0);
}

/* TCLOD_OVERFLOW_DRAW_ROOTS: every visible root in the cut stays, over the
 * budget, but for the unaffordable ones (an infinite cost is never drawn),
 * which are dropped. The selection is flagged over budget. */
static void draw_roots(tclod_selector *sel) {
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id r = sel->cut[i];
        if (!greedy_counts(sel, r) || !isinf(sel->node[r].cost))
            continue;
        account(sel, r, -1.0);
        sel->flags[r] |= TCLOD_FLAG_DROPPED;
        sel->stats.dropped_roots++;
        unqueue_increment(sel, r);
    }
    sel->stats.over_budget = sel->cost_sum > greedy_cut_budget(sel);
}

/* When even the visible roots in the cut do not fit: keeps the highest value
 * (benefit / cost) roots while they fit, skipping those that do not (fill).
 * Unaffordable roots come last and are never kept. Like every ratio greedy
 * for a knapsack this alone can be arbitrarily bad, so the most beneficial
 * root that fits alone is tried as the starting point too. */
static void drop_roots(tclod_selector *sel) {
    uint32_t n = 0, i, best = TCLOD_NONE;
    if (sel->desc.overflow == TCLOD_OVERFLOW_DRAW_ROOTS) {
        draw_roots(sel);
        return;
    }
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id r = sel->cut[i];
        double c;
        if (!greedy_counts(sel, r))
            continue;
        assert(sel->scene->parent[r] == TCLOD_NONE); /* see drop_order */
        c = sel->node[r].cost;
        sel->scratch[n] = r;
        sel->scratch_key[n] =
            isinf(c) ? -HUGE_VAL : (c > 0.0 ? sel->node[r].benefit / c : HUGE_VAL);
        n++;
    }
    tclod_sort_by_key(sel->scratch, sel->scratch_key, n);
    keep_roots(sel, n, TCLOD_NONE);
    for (i = 0; i < n; ++i) {
        tclod_id r = sel->scratch[i];
        if (fits_alone(sel, r, 0.0) && sel->node[r].benefit > sel->benefit_sum &&
            (best == TCLOD_NONE || sel->node[r].benefit > sel->node[sel->scratch[best]].benefit))
            best = i;
    }
    if (best != TCLOD_NONE)
        keep_roots(sel, n, best);
    for (i = 0; i < n; ++i) {
        tclod_id r = sel->scratch[i];
        if (!(sel->flags[r] & TCLOD_FLAG_DROPPED))
            continue;
        sel->stats.dropped_roots++;
        unqueue_increment(sel, r);
    }
}

/* ---- starts --------------------------------------------------------------------- */

static void clear_cut(tclod_selector *sel) {
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        sel->node[sel->cut[i]].cut_pos = TCLOD_NONE;
        sel->flags[sel->cut[i]] = 0;
    }
    sel->cut_count = 0;
    sel->cost_sum = sel->cost_err = sel->benefit_sum = 0.0;
    sel->unaffordable = 0;
    clear_heaps(sel);
}

/* Queues in the decrement heap, unused by a cold start, the refinement of
 * visible cut node n when its children cost less than n (children outside the
 * frustum cost nothing), keyed by least benefit lost per cost saved (negated,
 * as decrements are); append: heap order restored by the caller. */
static int queue_saving(tclod_selector *sel, tclod_id n, int append) {
    const tclod_scene *s = sel->scene;
    uint32_t i = s->child_first[n], end = i + s->child_count[n];
    double sum_b = 0.0, sum_c = 0.0, loss, saved, key;
    if (i == end || !greedy_counts(sel, n))
        return 0;
    for (; i < end; ++i) {
        tclod_id c = s->children[i];
        if (evaluate(sel, c) != 0)
            return -1;
        if (greedy_unaffordable(sel->node[c].cost))
            return 0;
        sum_b += sel->node[c].benefit;
        sum_c += sel->node[c].cost;
    }
    loss = sel->node[n].benefit - sum_b;
    saved = sel->node[n].cost - sum_c;
    if (!(saved > 0.0) || !isfinite(sum_c))
        return 0;
    sel->greedy.delta[n].delta_b = -loss;
    sel->greedy.delta[n].delta_c = -saved;
    key = loss <= 0.0 || isinf(saved) ? HUGE_VAL : -(loss / saved);
    if (append)
        tclod_heap_append(&sel->greedy.dec, n, key);
    else
        tclod_heap_push(&sel->greedy.dec, n, key);
    return 0;
}

/* When the roots do not fit the budget: the refinements that cost less than
 * the nodes they replace, least benefit lost per cost saved first, until the
 * cut fits (docs/greedy.md, when the roots do not fit); then, newest first,
 * every one of them that gave benefit away is undone where the budget still
 * allows (the order may have taken one that a later, larger saving made
 * needless). When none brings the cut within the budget it is the roots
 * again, and roots are left out. */
static int shed_cost(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t i, shed = 0, k;
    for (i = 0; i < sel->cut_count; ++i)
        if (queue_saving(sel, sel->cut[i], 1) != 0)
            return -1;
    tclod_heap_build(&sel->greedy.dec);
    while (!greedy_feasible(sel) && sel->greedy.dec.count > 0) {
        tclod_id n = tclod_heap_pop(&sel->greedy.dec);
        uint32_t first = s->child_first[n], end = first + s->child_count[n];
        sel->scratch[shed++] = n;
        sel->stats.iterations++;
        sel->stats.increments++;
        greedy_cut_remove(sel, n);
        for (k = first; k < end; ++k) {
            tclod_id c = s->children[k];
            greedy_cut_add(sel, c);
            sel->path[2u * c] = sel->path[2u * c + 1u] = 0.0; /* where the safeguard counts from */
            if (queue_saving(sel, c, 0) != 0)
                return -1;
        }
    }
    tclod_heap_clear(&sel->greedy.dec);
    if (!greedy_feasible(sel)) {
        clear_cut(sel);
        for (i = 0; i < s->root_count; ++i)
            greedy_cut_add(sel, s->roots[i]);
        return 0;
    }
    while (shed > 0) {
        tclod_id n = sel->scratch[--shed];
        uint32_t first = s->child_first[n], end = first + s->child_count[n];
        const tclod_delta *d = &sel->greedy.delta[n];
        for (k = first; k < end && sel->node[s->children[k]].cut_pos != TCLOD_NONE; ++k)
            ;
        if (k < end || !(d->delta_b < 0.0) ||
            !tclod_within(sel, sel->cost_sum - d->delta_c, greedy_cut_budget(sel)))
            continue;
        sel->stats.decrements++;
        for (k = first; k < end; ++k)
            greedy_cut_remove(sel, s->children[k]);
        greedy_cut_add(sel, n);
    }
    return 0;
}

/* Cut = the roots; when they do not fit, refinements that save cost, else
 * roots left out; queues the cut's increments. */
static int start_cold(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t i;
    clear_cut(sel);
    for (i = 0; sel->batching && i < s->root_count; ++i)
        if (tclod_batch_add(sel, s->roots[i]) != 0)
            return -1;
    if (tclod_batch_flush(sel) != 0)
        return -1;
    for (i = 0; i < s->root_count; ++i) {
        tclod_id r = s->roots[i];
        if (evaluate(sel, r) != 0)
            return -1;
        sel->path[2u * r] = sel->path[2u * r + 1u] = 0.0;
        greedy_cut_add(sel, r);
    }
    if (!greedy_feasible(sel) && shed_cost(sel) != 0)
        return -1;
    if (!greedy_feasible(sel))
        drop_roots(sel);
    if (sel->stats.over_budget)
        return 0; /* the roots over the budget, and nothing more */
    if (sel->batching && gather_all_children(sel, sel->cut, sel->cut_count) != 0)
        return -1;
    for (i = 0; i < sel->cut_count; ++i)
        if (queue_increment(sel, sel->cut[i], 1) != 0)
            return -1;
    tclod_heap_build(&sel->greedy.inc);
    return 0;
}

/* Scenes from this many nodes have their cut sorted by a warm start: their
 * per-node records (about 150 bytes a node) outgrow a core's own caches. */
#define SORT_FROM_NODES 16384u

/* Sorts ids a[0..n) through b[0..n) (least significant digit radix sort, 8
 * bits a pass): one reading counts every digit, a digit all ids share needs no
 * pass. The result is in a. */
static void radix_ids(tclod_id *a, tclod_id *b, uint32_t n) {
    uint32_t count[4][256], i, d;
    tclod_id *src = a, *dst = b;
    if (n < 2u)
        return;
    memset(count, 0, sizeof count);
    for (i = 0; i < n; ++i) {
        tclod_id v = a[i];
        count[0][v & 255u]++;
        count[1][(v >> 8) & 255u]++;
        count[2][(v >> 16) & 255u]++;
        count[3][v >> 24]++;
    }
    for (d = 0; d < 4u; ++d) {
        uint32_t shift = 8u * d, *at = count[d], sum = 0, k;
        tclod_id *t;
        if (at[(src[0] >> shift) & 255u] == n)
            continue;
        for (k = 0; k < 256u; ++k) {
            uint32_t c = at[k];
            at[k] = sum;
            sum += c;
        }
        for (i = 0; i < n; ++i) {
            tclod_id v = src[i];
            dst[at[(v >> shift) & 255u]++] = v;
        }
        t = src;
        src = dst;
        dst = t;
    }
    if (src != a)
        memcpy(a, src, sizeof(tclod_id) * n);
}

/* Sorts the cut by id, so that the warm start visits the per-node records in
 * memory order rather than in the order taking and removing nodes left
 * (docs/greedy.md: at 10^5 objects this halves a warm solve). The previous
 * warm solve sorted it; the nodes it put in since (appended, or moved into a
 * hole) carry TCLOD_FLAG_MOVED, and the others are still in order. Those are
 * kept in place, the moved ones are radix sorted through scratch and merged
 * in from the end. A cut that is not in order after all (one put back after
 * a failed solve) is radix sorted whole. The slots in the records
 * (cut_pos) and the flags are left for the warm start's first pass over the
 * cut to write, which reads those records anyway: until then cut_pos says
 * only that a node is in the cut. */
static void sort_cut(tclod_selector *sel) {
    uint32_t n = sel->cut_count, i, k = 0, m = 0;
    tclod_id *a = sel->cut, *b = sel->scratch;
    uint8_t *flags = sel->flags;
    int sorted = 1;
    for (i = 0; i < n; ++i) {
        tclod_id v = a[i];
        if (flags[v] & TCLOD_FLAG_MOVED)
            b[m++] = v;
        else
            a[k++] = v;
    }
    if (2u * m <= sel->cap) {
        uint32_t w = n;
        radix_ids(b, b + m, m);
        while (m > 0) /* the larger of the two last ones goes last */
            a[--w] = k > 0 && a[k - 1u] > b[m - 1u] ? a[--k] : b[--m];
    } else {
        memcpy(a + k, b, sizeof(tclod_id) * m);
        radix_ids(a, b, n);
    }
    for (i = 1; i < n; ++i)
        sorted &= a[i - 1u] < a[i];
    if (!sorted)
        radix_ids(a, b, n);
}

/* Puts n into the cut as a node of the previous selection would be (the warm
 * start evaluates and counts it). */
static void cut_append(tclod_selector *sel, tclod_id n) {
    sel->node[n].cut_pos = sel->cut_count;
    sel->flags[n] = TCLOD_FLAG_MOVED;
    sel->cut[sel->cut_count++] = n;
}

/* After nodes were added or removed: makes the previous cut a cut of the
 * scene's current index again, in time proportional to the selection (the
 * cut, the nodes above it and their children) and the roots. Removed nodes
 * leave it. The nodes above it that are left (every one is an ancestor of a
 * node still in it) are refined: any child of theirs neither in the cut nor
 * above it (added since, or whose own cut nodes were all removed) joins it,
 * as does any root in neither. No ancestor of a cut node can join it, since
 * the index only gains leaves and loses whole subtrees. */
static void repair_cut(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_node_state *node = sel->node;
    uint8_t *flags = sel->flags;
    uint32_t i, k = 0, above = 0;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id n = sel->cut[i];
        if (tclod_scene_indexed(s, n)) {
            sel->cut[k] = n;
            node[n].cut_pos = k++;
        } else {
            node[n].cut_pos = TCLOD_NONE;
            flags[n] = 0;
        }
    }
    sel->cut_count = k;
    for (i = 0; i < k; ++i) {
        tclod_id p;
        for (p = s->parent[sel->cut[i]]; p != TCLOD_NONE && !(flags[p] & TCLOD_FLAG_ABOVE);
             p = s->parent[p]) {
            flags[p] |= TCLOD_FLAG_ABOVE;
            sel->scratch[above++] = p;
        }
    }
    for (i = 0; i < s->root_count; ++i) {
        tclod_id r = s->roots[i];
        if (node[r].cut_pos == TCLOD_NONE && !(flags[r] & TCLOD_FLAG_ABOVE))
            cut_append(sel, r);
    }
    for (i = 0; i < above; ++i) {
        uint32_t count, j;
        const tclod_id *ch = children_of(sel, sel->scratch[i], &count);
        for (j = 0; j < count; ++j)
            if (node[ch[j]].cut_pos == TCLOD_NONE && !(flags[ch[j]] & TCLOD_FLAG_ABOVE))
                cut_append(sel, ch[j]);
    }
    for (i = 0; i < above; ++i)
        flags[sel->scratch[i]] &= (uint8_t)~TCLOD_FLAG_ABOVE;
}

/* Whether a proper ancestor of indexed node x is in the cut. */
static int below_cut(const tclod_selector *sel, tclod_id x) {
    const tclod_scene *s = sel->scene;
    tclod_id p;
    for (p = s->parent[x]; p != TCLOD_NONE; p = s->parent[p])
        if (sel->node[p].cut_pos != TCLOD_NONE)
            return 1;
    return 0;
}

/* repair_cut from the scene's edit log, entries `from` on: the edits since
 * the previous cut was made, in time proportional to them (times the depth
 * of the nodes they touched). Nodes that left the index leave the cut; an
 * added node not below the cut joins it (its parent was refined), in the order
 * they were added, so that a new parent goes in before its new children, which
 * are then below it; then a node that lost its last child and is not below the
 * cut joins it. Added nodes come first: a node that lost its last child may
 * itself be new, below a new node that joined. */
static void repair_from_log(tclod_selector *sel, uint32_t from) {
    const tclod_scene *s = sel->scene;
    const tclod_edit *log = s->log;
    tclod_node_state *node = sel->node;
    uint32_t i, end = s->log_count;
    for (i = from; i < end; ++i) {
        tclod_id n = log[i].node;
        uint32_t slot = node[n].cut_pos;
        tclod_id last;
        if (log[i].kind != TCLOD_EDIT_REMOVED || slot == TCLOD_NONE)
            continue;
        last = sel->cut[--sel->cut_count];
        sel->cut[slot] = last;
        node[last].cut_pos = slot;
        sel->flags[last] |= TCLOD_FLAG_MOVED;
        node[n].cut_pos = TCLOD_NONE;
        sel->flags[n] = 0;
    }
    for (i = from; i < end; ++i) {
        tclod_id x = log[i].node;
        if (log[i].kind == TCLOD_EDIT_ADDED && tclod_scene_indexed(s, x) &&
            node[x].cut_pos == TCLOD_NONE && !below_cut(sel, x))
            cut_append(sel, x);
    }
    for (i = from; i < end; ++i) {
        tclod_id p = log[i].node;
        if (log[i].kind == TCLOD_EDIT_LOST && tclod_scene_indexed(s, p) &&
            s->child_count[p] == 0u && node[p].cut_pos == TCLOD_NONE && !below_cut(sel, p))
            cut_append(sel, p);
    }
}

/* The `count` additive nodes in scratch[] were refined and are invisible now
 * (a benefit of 0 culls a node with its whole subtree): their subtrees leave
 * the cut and they take their place, as a cold solve would leave them. The
 * sums are counted again. */
static void cull_additive(tclod_selector *sel, uint32_t count) {
    const tclod_scene *s = sel->scene;
    uint32_t i, k = 0;
    for (i = 0; i < count; ++i)
        sel->flags[sel->scratch[i]] |= TCLOD_FLAG_ABOVE;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id n = sel->cut[i], p;
        for (p = s->parent[n]; p != TCLOD_NONE && !(sel->flags[p] & TCLOD_FLAG_ABOVE);
             p = s->parent[p])
            ;
        if (p != TCLOD_NONE) { /* below a culled one */
            sel->node[n].cut_pos = TCLOD_NONE;
            sel->flags[n] = 0;
            continue;
        }
        sel->cut[k] = n;
        sel->node[n].cut_pos = k++;
    }
    sel->cut_count = k;
    /* one inside another culled one stays out (scratch[count + i]: whether
     * the i-th is outermost; each has a self leaf of its own, so 2 count ids
     * fit) */
    for (i = 0; i < count; ++i) {
        tclod_id p;
        for (p = s->parent[sel->scratch[i]]; p != TCLOD_NONE && !(sel->flags[p] & TCLOD_FLAG_ABOVE);
             p = s->parent[p])
            ;
        sel->scratch[count + i] = p == TCLOD_NONE;
    }
    for (i = 0; i < count; ++i)
        sel->flags[sel->scratch[i]] &= (uint8_t)~TCLOD_FLAG_ABOVE;
    for (i = 0; i < count; ++i)
        if (sel->scratch[count + i])
            cut_append(sel, sel->scratch[i]); /* evaluated: its self leaf asked for it */
    sel->cost_sum = sel->cost_err = sel->benefit_sum = 0.0;
    sel->unaffordable = 0;
    for (i = 0; i < sel->cut_count; ++i)
        account(sel, sel->cut[i], 1.0);
}

/* Whether node n is the top of a hierarchy of its own for residency: a root,
 * or a child of an additive node (a self leaf is one). Not resident, such a
 * node is invisible and its subtree draws nothing; any other node that is not
 * resident costs +inf (tclod_evaluate_absent). */
static int stream_top(const tclod_scene *s, tclod_id n) {
    tclod_id p = s->parent[n];
    return p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD);
}

/* Whether node a (TCLOD_NONE, or a node above the cut: stream_repair flagged
 * it TCLOD_FLAG_ABOVE) is flagged TCLOD_FLAG_CULL or lies below one that is.
 * Settles every node on the way up: each then carries the answer (CULL when
 * covered, else neither flag), so that every node is walked once. */
static int stream_covered(tclod_selector *sel, tclod_id a) {
    const tclod_scene *s = sel->scene;
    uint8_t *flags = sel->flags;
    tclod_id p, q;
    int covered;
    for (p = a;
         p != TCLOD_NONE && (flags[p] & (TCLOD_FLAG_ABOVE | TCLOD_FLAG_CULL)) == TCLOD_FLAG_ABOVE;
         p = s->parent[p])
        ;
    covered = p != TCLOD_NONE && (flags[p] & TCLOD_FLAG_CULL);
    for (q = a; q != p; q = s->parent[q])
        flags[q] = (uint8_t)((flags[q] & ~(unsigned)TCLOD_FLAG_ABOVE) |
                             (covered ? (unsigned)TCLOD_FLAG_CULL : 0u));
    return covered;
}

/* Streaming: the evaluated previous cut made a cut the residency of now
 * allows, as a cold solve would have left it (docs/streaming.md). A
 * hierarchy whose top is not resident draws nothing: the top takes the
 * place of its cut nodes. A visible cut node that is not resident (and not
 * a top: it costs +inf) falls back to its nearest resident ancestor, or to
 * the top above it that is not resident, which takes the place of its cut
 * nodes; refining it again waits for the node. The nodes that take a place
 * are evaluated: roots not resident above the cut are so counted in
 * stats.absent_roots. O(cut + the nodes above it). Returns 0, or -1 on a
 * strict error. */
static TCLOD_NOINLINE int stream_repair(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_node_state *node = sel->node;
    uint8_t *flags = sel->flags;
    uint32_t i, k = 0, above = 0, joined = 0;
    int culls = 0;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id n = sel->cut[i], o = tclod_scene_owner(s, n), p;
        if (greedy_counts(sel, n) && tclod_scene_absent(s, n) && !stream_top(s, o)) {
            for (p = s->parent[o]; (s->flags[p] & TCLOD_NODE_ABSENT) && !stream_top(s, p);
                 p = s->parent[p])
                ;
            flags[p] |= TCLOD_FLAG_CULL;
            culls = 1;
        }
        for (p = s->parent[n]; p != TCLOD_NONE && !(flags[p] & TCLOD_FLAG_ABOVE);
             p = s->parent[p]) {
            flags[p] |= TCLOD_FLAG_ABOVE;
            sel->scratch[above++] = p;
            if ((s->flags[p] & TCLOD_NODE_ABSENT) && stream_top(s, p)) {
                flags[p] |= TCLOD_FLAG_CULL;
                culls = 1;
            }
        }
    }
    if (culls) {
        for (i = 0; i < sel->cut_count; ++i) {
            tclod_id n = sel->cut[i];
            if (stream_covered(sel, s->parent[n])) {
                node[n].cut_pos = TCLOD_NONE;
                flags[n] = 0;
                continue;
            }
            sel->cut[k] = n;
            node[n].cut_pos = k++;
        }
        sel->cut_count = k;
        /* the outermost covered nodes, after the cut's end until their
         * flags are cleared */
        for (i = 0; i < above; ++i) {
            tclod_id a = sel->scratch[i];
            if (stream_covered(sel, a) && !stream_covered(sel, s->parent[a]))
                sel->cut[k + joined++] = a;
        }
    }
    for (i = 0; i < above; ++i)
        flags[sel->scratch[i]] &= (uint8_t) ~(TCLOD_FLAG_ABOVE | TCLOD_FLAG_CULL);
    if (!culls)
        return 0;
    for (i = 0; i < joined; ++i) {
        tclod_id a = sel->cut[k + i];
        cut_append(sel, a);
        if (evaluate(sel, a) != 0)
            return -1;
    }
    sel->cost_sum = sel->cost_err = sel->benefit_sum = 0.0;
    sel->unaffordable = 0;
    for (i = 0; i < sel->cut_count; ++i)
        account(sel, sel->cut[i], 1.0);
    return 0;
}

/* With batch evaluation, a warm start evaluates the cut and then its frontier
 * in blocks of about this many nodes, each used while its records are in
 * cache (and worth splitting over workers). */
#define WARM_BLOCK 1024u

/* Gathers the cut nodes from cut[i] on until about WARM_BLOCK nodes wait
 * (`frontier`: their parents that decrements key, each from its first child
 * as start_warm looks at them, and the children that increments key, rather
 * than the cut nodes themselves), evaluates them and returns the end of the
 * block; the whole cut without batch evaluation. -1 on a strict error. */
static int64_t warm_block(tclod_selector *sel, uint32_t i, int frontier) {
    const tclod_scene *s = sel->scene;
    if (!sel->batching)
        return sel->cut_count;
    for (; i < sel->cut_count && sel->gather_count < WARM_BLOCK; ++i) {
        tclod_id n = sel->cut[i], p = s->parent[n];
        if (!frontier) {
            sel->node[n].cut_pos = i; /* sort_cut leaves it to this pass */
            if (tclod_batch_add(sel, n) != 0)
                return -1;
            continue;
        }
        if (p != TCLOD_NONE && s->children[s->child_first[p]] == n && collapsible(sel, p)) {
            sel->flags[n] |= TCLOD_FLAG_COLLAPSE;
            if (tclod_batch_add(sel, p) != 0)
                return -1;
        }
        if (gather_children(sel, n) != 0)
            return -1;
    }
    return tclod_batch_flush(sel) != 0 ? -1 : (int64_t)i;
}

/* Cut = the previous cut, re-evaluated; queues its increments and decrements. */
static int take_first_collapses(tclod_selector *sel);

static int start_warm(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t i, culled = 0;
    int64_t end;
    if (s->node_count >= SORT_FROM_NODES)
        sort_cut(sel);
    sel->cost_sum = sel->cost_err = sel->benefit_sum = 0.0;
    sel->unaffordable = 0;
    for (i = 0; i < sel->cut_count;) {
        if ((end = warm_block(sel, i, 0)) < 0)
            return -1;
        for (; i < (uint32_t)end; ++i) {
            tclod_id n = sel->cut[i];
            sel->node[n].cut_pos = i;
            sel->flags[n] = 0;
            if (evaluate(sel, n) != 0)
                return -1;
            account(sel, n, 1.0);
            /* an additive node that stays drawn, invisible now */
            if ((s->bounds[n].kind & TCLOD_BOUNDS_SELF) && !(sel->node[n].benefit > 0.0))
                sel->scratch[culled++] = s->up[n];
        }
    }
    if (culled)
        cull_additive(sel, culled);
    if (TCLOD_UNLIKELY(s->absent_count != 0) && stream_repair(sel) != 0)
        return -1;
    if (sel->desc.greedy.lookahead == 0)
        sel->greedy.cheap_live = CHEAP_PENDING;
    for (i = 0; i < sel->cut_count;) {
        if ((end = warm_block(sel, i, 1)) < 0)
            return -1;
        for (; i < (uint32_t)end; ++i) {
            tclod_id n = sel->cut[i];
            tclod_id p = s->parent[n];
            /* each parent is looked at once: from its first child (which
             * warm_block has done when batching; the flag is taken before
             * the increment, whose lookahead rewrites the flags) */
            int collapse = sel->batching ? (sel->flags[n] & TCLOD_FLAG_COLLAPSE) != 0
                                         : p != TCLOD_NONE && s->children[s->child_first[p]] == n;
            sel->flags[n] &= (uint8_t)~TCLOD_FLAG_COLLAPSE;
            if (queue_increment(sel, n, 1) != 0)
                return -1;
            if (collapse &&
                (sel->batching ? queue_collapsible(sel, p, 1) : queue_decrement(sel, p, 1)) != 0)
                return -1;
        }
    }
    tclod_heap_build(&sel->greedy.inc);
    tclod_heap_build(&sel->greedy.dec);
    return take_first_collapses(sel);
}

/* ---- the search ------------------------------------------------------------------ */

int tclod_out_of_time(tclod_selector *sel) {
    const tclod_frame *f = sel->frame;
    uint32_t it = sel->stats.iterations;
    int read_clock = it % CLOCK_STRIDE == 0;
    double now = 0.0;
    if (sel->stopped)
        return 1;
    if (f->max_iterations && it >= f->max_iterations) {
        sel->stats.stop_reason = TCLOD_STOP_ITERATIONS;
        sel->stopped = 1;
        return 1;
    }
    if (read_clock && (f->solve_seconds > 0.0 || sel->slice_end > 0.0))
        now = tclod_now();
    if (read_clock && f->solve_seconds > 0.0 &&
        sel->elapsed + (now - sel->start_time) >= f->solve_seconds) {
        sel->stats.stop_reason = TCLOD_STOP_TIME;
        sel->stopped = 1;
        return 1;
    }
    /* a step makes at least one iteration, so that steps always progress */
    if (it != sel->step_start && ((sel->slice_iterations && it >= sel->slice_iterations) ||
                                  (read_clock && sel->slice_end > 0.0 && now >= sel->slice_end))) {
        sel->paused = 1;
        return 1;
    }
    return 0;
}

/* Restores feasibility of a warm start: decrements while over budget (by the
 * running sum, or by its compensated total while decrements are left).
 * Returns 1 when no decrement that saves cost is left and the cut is still
 * over: the solve then starts cold, where refinements that save cost come
 * before roots are left out (start_cold). Always completes. */
static int restore_budget(tclod_selector *sel) {
    while (!greedy_feasible(sel) || (sel->greedy.dec.count > 0 &&
                                     !tclod_within(sel, sel->cost_sum, greedy_cut_budget(sel)))) {
        if (sel->greedy.dec.count == 0 || sel->greedy.dec.items[0].key == -HUGE_VAL)
            return greedy_feasible(sel) ? 0 : 1;
        sel->stats.iterations++;
        if (apply_decrement(sel, tclod_heap_pop(&sel->greedy.dec)) != 0)
            return -1;
    }
    return 0;
}

/* Loss per saved cost of the cheapest decrement that saves cost, or +inf. */
static double min_loss_ratio(const tclod_selector *sel) {
    if (sel->greedy.dec.count == 0)
        return HUGE_VAL;
    tclod_id p = sel->greedy.dec.items[0].id;
    if (!(sel->greedy.delta[p].delta_c > 0.0))
        return HUGE_VAL;
    return -sel->greedy.dec.items[0].key;
}

/* After decrement p is taken for a swap: the collapse of p's parent q, when
 * q's other children are in the cut, is queued too (a chain collapses level
 * by level), unless q is n's parent. A swap that fails takes these out again
 * (untake_parents). */
static int take_parent_too(tclod_selector *sel, tclod_id p, tclod_id n_parent) {
    tclod_id q = sel->scene->parent[p];
    uint32_t count, i;
    const tclod_id *ch;
    if (q == TCLOD_NONE || q == n_parent || tclod_heap_contains(&sel->greedy.dec, q))
        return 0;
    ch = children_of(sel, q, &count);
    for (i = 0; i < count; ++i)
        if (ch[i] != p && sel->node[ch[i]].cut_pos == TCLOD_NONE)
            return 0;
    return queue_collapsible(sel, q, 0);
}

/* A failed swap's decrements taken (scratch[0 .. taken)) leave the cut as it
 * was: their parents, queued by take_parent_too (and taken, maybe, then put
 * back), are not collapsible and go. */
static void untake_parents(tclod_selector *sel, uint32_t taken) {
    uint32_t i;
    for (i = 0; i < taken; ++i) {
        tclod_id q = sel->scene->parent[sel->scratch[i]];
        if (q != TCLOD_NONE && tclod_heap_contains(&sel->greedy.dec, q) && !collapsible(sel, q))
            tclod_heap_remove(&sel->greedy.dec, q);
    }
}

/* Makes room for increment n (with collapse, for the collapse into n, out of
 * the decrement heap, that gains: take_first_collapses) by decrements whose
 * summed loss stays below its gain, least loss per saved cost first. A taken
 * decrement makes its parent's collapse a candidate when the parent's other
 * children are in the cut (take_parent_too). Returns 1 when the swap was
 * made, 0 when it would not gain. */
static int try_swap(tclod_selector *sel, tclod_id n, int collapse, int *failed) {
    double sign = collapse ? -1.0 : 1.0;
    double need = sel->cost_sum + sign * sel->greedy.delta[n].delta_c - sel->frame->budget;
    double gain = sign * sel->greedy.delta[n].delta_b, freed = 0.0, loss = 0.0;
    tclod_id parent = collapse ? TCLOD_NONE : sel->scene->parent[n];
    uint32_t taken = 0, i;
    int ok = 0;
    if (sel->cost_err > 0.0) /* what the running sum absorbed needs room too */
        need += sel->cost_err;
    *failed = 0;
    /* decrements come least loss per saved cost first, so freeing `need`
     * loses at least that ratio times need */
    if (gain <= min_loss_ratio(sel) * need)
        return 0;
    while (sel->greedy.dec.count > 0) {
        double key = sel->greedy.dec.items[0].key;
        tclod_id p = sel->greedy.dec.items[0].id;
        if (p != parent && !(sel->greedy.delta[p].delta_c > 0.0))
            break; /* the rest saves nothing */
        tclod_heap_pop(&sel->greedy.dec);
        sel->scratch[taken] = p;
        sel->scratch_key[taken] = key;
        taken++;
        if (p == parent)
            continue; /* would remove n itself */
        freed += sel->greedy.delta[p].delta_c;
        loss += sel->greedy.delta[p].delta_b;
        if (gain - loss <= GREEDY_SWAP_MARGIN * fabs(gain))
            break;
        if (freed >= need) {
            ok = 1;
            break;
        }
        if (take_parent_too(sel, p, parent) != 0) {
            *failed = 1;
            break;
        }
    }
    for (i = 0; i < taken; ++i) {
        tclod_id p = sel->scratch[i];
        if (!ok || p == parent)
            tclod_heap_push(&sel->greedy.dec, p, sel->scratch_key[i]);
    }
    if (!ok) {
        untake_parents(sel, taken);
        return 0;
    }
    for (i = 0; i < taken; ++i) {
        tclod_id p = sel->scratch[i];
        if (p == parent)
            continue;
        sel->stats.iterations++;
        if (apply_decrement(sel, p) != 0) {
            *failed = 1;
            return 0;
        }
    }
    if ((collapse ? apply_decrement(sel, n) : apply_increment(sel, n, 1)) != 0)
        *failed = 1;
    return 1;
}

/* 1 when the collapse into p, queued, is free (no loss, no extra cost), into
 * an invisible p, or removes an unaffordable child (decrement_key's first
 * ones). */
static int free_collapse(const tclod_selector *sel, tclod_id p) {
    return tclod_heap_contains(&sel->greedy.dec, p) &&
           sel->greedy.dec.items[sel->greedy.dec.pos[p]].key == HUGE_VAL;
}

/* 1 when the collapse into p, queued, gains benefit at a cost: p is worth more
 * than its children in the cut, typically children that left the frustum
 * while p is still in it. A cold solve never refines such a p (its increment
 * gains nothing), and the decrements' order, which puts collapses that save
 * nothing last, would never undo it. */
static int gaining_collapse(const tclod_selector *sel, tclod_id p) {
    const tclod_delta *d = &sel->greedy.delta[p];
    return tclod_heap_contains(&sel->greedy.dec, p) && d->delta_c < 0.0 &&
           d->delta_b < -GREEDY_SWAP_MARGIN * sel->node[p].benefit;
}

/* Benefit gained per cost added by the gaining collapse into p. */
static double gain_ratio(const tclod_selector *sel, tclod_id p) {
    const tclod_delta *d = &sel->greedy.delta[p];
    return d->delta_b / d->delta_c; /* both < 0 */
}

/* A warm start's first moves, before the budget is restored: the free
 * collapses, and those that gain where they fit or a swap makes room for
 * them (try_swap), cascading up to the parents that become such. Only here
 * and in the last fill (fill_gaining_collapses): in the increments and swaps
 * between, a collapse that gains at a cost is a trade among others (a
 * lookahead's jump may take cheaper children at a loss). The pending ones
 * wait at the top of scratch, below any parked misfits (none at a warm
 * start), as try_swap uses its bottom. */
static int take_first_collapses(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->greedy.dec.count; ++i) {
        tclod_id p = sel->greedy.dec.items[i].id;
        if (free_collapse(sel, p) || gaining_collapse(sel, p))
            sel->scratch[sel->cap - ++n] = p;
    }
    while (n > 0) {
        tclod_id p = sel->scratch[sel->cap - n--], up = sel->scene->parent[p];
        int failed = 0;
        if (free_collapse(sel, p) ||
            (gaining_collapse(sel, p) &&
             tclod_within(sel, sel->cost_sum - sel->greedy.delta[p].delta_c,
                          greedy_cut_budget(sel)))) {
            sel->stats.iterations++;
            if (apply_decrement(sel, p) != 0)
                return -1;
        } else if (gaining_collapse(sel, p)) {
            uint32_t slot = sel->greedy.dec.pos[p];
            double key = sel->greedy.dec.items[slot].key;
            sel->stats.iterations++;
            tclod_heap_remove(&sel->greedy.dec, p);
            if (!try_swap(sel, p, 1, &failed))
                tclod_heap_push(&sel->greedy.dec, p, key);
            if (failed)
                return -1;
        } else {
            continue;
        }
        if (up != TCLOD_NONE && (free_collapse(sel, up) || gaining_collapse(sel, up)))
            sel->scratch[sel->cap - ++n] = up;
    }
    return 0;
}

/* A warm solve's last fill: the gaining collapses still queued, best ratio
 * first, each one that fits. */
static int fill_gaining_collapses(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->greedy.dec.count; ++i) {
        tclod_id p = sel->greedy.dec.items[i].id;
        if (gaining_collapse(sel, p)) {
            sel->scratch[n] = p;
            sel->scratch_key[n++] = gain_ratio(sel, p);
        }
    }
    tclod_sort_by_key(sel->scratch, sel->scratch_key, n);
    for (i = 0; i < n; ++i) {
        tclod_id p = sel->scratch[i];
        if (!gaining_collapse(sel, p) ||
            !tclod_within(sel, sel->cost_sum - sel->greedy.delta[p].delta_c,
                          greedy_cut_budget(sel)))
            continue;
        sel->stats.iterations++;
        if (apply_decrement(sel, p) != 0)
            return -1;
    }
    return 0;
}

/* Relative margin above the previous solve's first misfit from which the
 * plain cold pass takes increments without ordering them. */
#define CLOSURE_MARGIN 1.25

/* The plain cold pass takes the increments keyed at or above closure_key and
 * those they lead to with such keys (the closure) before any other, in the
 * order they were queued, not by key (first in, first out: on large scenes
 * faster than last in, first out, docs/greedy.md). The heap would take the
 * same set first, and if the closure's cost grows by at most the budget left
 * none of its prefixes misfits, so the cut after it is the heap's after as
 * many increments. If the closure does not fit that way the pass starts over
 * with the heap alone. Takes one increment when the solve runs in slices (a
 * slice may end after any), else all of them; ends the closure when none is
 * left. */
static int take_closure(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int sliced = sel->slice_end > 0.0 || sel->slice_iterations != 0;
    uint32_t dropped;
    while (R->greedy.closure_tail > R->greedy.closure_head) {
        tclod_id n = sel->scratch[R->greedy.closure_head];
        double grow = sel->greedy.delta[n].delta_c > 0.0 ? sel->greedy.delta[n].delta_c : 0.0;
        double total = R->greedy.closure_cost + grow;
        if (sel->unaffordable != 0 || !(total <= greedy_cut_budget(sel)) ||
            total + R->greedy.closure_err > greedy_cut_budget(sel))
            break;
        R->greedy.closure_head++;
        tclod_add_compensated(&R->greedy.closure_cost, &R->greedy.closure_err, grow);
        sel->stats.iterations++;
        if (apply_increment_cold(sel, n) != 0)
            return -1;
        if (sliced)
            return 0;
    }
    if (R->greedy.closure_tail == R->greedy.closure_head) {
        R->greedy.closing = 0;
        tclod_heap_build(&sel->greedy.inc);
        return 0;
    }
    R->greedy.closing = 0;
    R->greedy.closure_head = R->greedy.closure_tail = 0;
    dropped = sel->stats.dropped_roots; /* the roots are dropped again, the same way */
    if (start_cold(sel) != 0)
        return -1;
    sel->stats.dropped_roots = dropped;
    return 0;
}

/* A warm solve's phases in improve (sel->resume.greedy.phase): the fill,
 * which parks the misfits it skips; the swaps, with every misfit queued again
 * and no skipping (an increment that fits is taken, the best one that does
 * not is swapped in or dropped); then a last fill for the room the swaps left,
 * which drops what it skips. */
enum { PHASE_FILL = 0, PHASE_SWAPS = 1, PHASE_LAST_FILL = 2 };

/* Increments while any fits, best ratio first, skipping those that do not fit
 * (fill). Then a warm solve makes swaps while the best increment's ratio beats
 * the cheapest decrement's (Mason–Blake's balance), and a cold solve records
 * the skipped increments as alternatives. Warm solves also take free
 * collapses first. Stops early at a limit. */
static int improve(tclod_selector *sel, int warm, int alt) {
    tclod_greedy_resume *R = &sel->resume.greedy;
    int *skipped = &sel->resume.skipped, failed = 0;
    uint32_t i;
    for (;;) {
        tclod_id n;
        int swapped;
        if (tclod_out_of_time(sel))
            return 0;
        if (R->closing) {
            if (take_closure(sel) != 0)
                return -1;
            continue;
        }
        if (warm && sel->greedy.dec.count > 0 && sel->greedy.dec.items[0].key == HUGE_VAL) {
            sel->stats.iterations++;
            if (apply_decrement(sel, tclod_heap_pop(&sel->greedy.dec)) != 0)
                return -1;
            continue;
        }
        if (sel->greedy.inc.count == 0 && R->parked == 0)
            break;
        if (sel->greedy.inc.count > 0) {
            n = sel->greedy.inc.items[0].id;
            if (R->left_out > 0 && greedy_left_out(&sel->resume, n)) {
                pop_increment(sel);
                continue;
            }
            if (greedy_increment_fits(sel, n)) { /* its entry goes in apply_increment */
                sel->stats.iterations++;
                if (apply_increment(sel, n, warm) != 0)
                    return -1;
                continue;
            }
            if (!warm)
                greedy_note_misfit(sel, n);
            if (R->phase != PHASE_SWAPS && increment_may_fit(sel)) {
                /* fill: skip the misfit, try smaller ones */
                *skipped = 1;
                if (alt)
                    greedy_consider_alternative(sel, n);
                if (warm && R->phase == PHASE_FILL &&
                    !(sel->flags[n] & (TCLOD_FLAG_JUMP | TCLOD_FLAG_REFIT)))
                    park_misfit(sel, n);
                else
                    skip_misfit(sel, n);
                continue;
            }
            *skipped = 1;
        }
        if (R->parked > 0) { /* the fill ended: the swaps see every misfit */
            unpark_misfits(sel);
            R->phase = PHASE_SWAPS;
            continue;
        }
        if (!warm || R->phase == PHASE_LAST_FILL ||
            !(sel->greedy.inc.items[0].key > min_loss_ratio(sel))) {
            if (R->phase != PHASE_SWAPS)
                break;
            R->phase = PHASE_LAST_FILL;
            continue;
        }
        n = pop_increment(sel);
        sel->stats.iterations++;
        swapped = try_swap(sel, n, 0, &failed);
        if (failed)
            return -1;
        if (swapped)
            continue;
    }
    if (alt)
        for (i = 0; i < sel->greedy.inc.count; ++i)
            greedy_consider_alternative(sel, sel->greedy.inc.items[i].id);
    if (warm && fill_gaining_collapses(sel) != 0)
        return -1;
    sel->stats.stop_reason = *skipped ? TCLOD_STOP_BUDGET : TCLOD_STOP_FINEST;
    return 0;
}

/* The cut's total as the budget guarantee sums it: the costs of its visible,
 * kept nodes in result order (docs/api.md); +inf with an unaffordable one. */
static double result_total(const tclod_selector *sel) {
    const tclod_id *cut = sel->cut;
    double sum = 0.0;
    uint32_t i, count = sel->cut_count;
    for (i = 0; i < count; ++i) {
        if (i + TCLOD_CUT_AHEAD < count) /* as the commit reads them */
            TCLOD_PREFETCH(&sel->node[cut[i + TCLOD_CUT_AHEAD]]);
        if (greedy_counts(sel, cut[i]))
            sum += sel->node[cut[i]].cost;
    }
    return sum;
}

/* Whether the frame's time limit or the step's slice has run out: the repair
 * then undoes what its estimate asks for in one round (TCLOD_STOP_TIME when it
 * is the frame's limit). */
static int repair_late(tclod_selector *sel) {
    const tclod_frame *f = sel->frame;
    double now;
    if (sel->stats.stop_reason == TCLOD_STOP_TIME)
        return 1;
    if (!(f->solve_seconds > 0.0) && !(sel->slice_end > 0.0))
        return 0;
    now = tclod_now();
    if (f->solve_seconds > 0.0 && sel->elapsed + (now - sel->start_time) >= f->solve_seconds) {
        if (!sel->stats.over_budget)
            sel->stats.stop_reason = TCLOD_STOP_TIME;
        sel->stopped = 1;
        return 1;
    }
    return sel->slice_end > 0.0 && now >= sel->slice_end;
}

/* The counted nodes of the cut in scratch[0 .. count), in the order the
 * repair leaves them out: lowest value (benefit / cost) first, ties larger id
 * first (stored complemented, so that the sort's ties by smaller id put them
 * so). Returns count. */
static uint32_t drop_order(tclod_selector *sel) {
    uint32_t i, n = 0;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id r = sel->cut[i];
        double c;
        if (!greedy_counts(sel, r))
            continue;
        /* with no decrement queued the cut holds roots only: below a refined
         * node, its deepest refined descendant would be collapsible, and the
         * decrement heap holds every collapsible parent of the cut */
        assert(sel->scene->parent[r] == TCLOD_NONE);
        c = sel->node[r].cost;
        sel->scratch[n] = ~r;
        sel->scratch_key[n] = -(c > 0.0 ? sel->node[r].benefit / c : HUGE_VAL);
        n++;
    }
    tclod_sort_by_key(sel->scratch, sel->scratch_key, n);
    return n;
}

/* Brings the total in result order (result_total) within the budget when
 * rounding carried it over (the order of the final sum, or costs the running
 * sums absorbed): decrements, the cheapest first, and once none is left the
 * lowest-value roots left out, one at a time in that order, until the total
 * fits. Summing again after every step would be O(n) per step; instead each
 * round takes the steps an estimate asks for (the last total less the exact
 * cost each step saves), at most 2^r in round r (from 0) and at least half
 * that from round 2 on, and then sums again. A total the estimate gets right
 * is done in the round after the one that found it over; any total in about
 * 2 log2(k) rounds for k steps: O(n log k + k log n) for a cut of n nodes.
 * Roots are left out only after a sum that the decrements could not bring
 * within the budget. Once the frame's time limit (TCLOD_STOP_TIME) or the
 * step's slice has run out, a round takes all the steps the estimate asks for.
 * Always ends within the budget. */
static int enforce_budget(tclod_selector *sel, int dec_built) {
    const tclod_scene *s = sel->scene;
    double limit = greedy_cut_budget(sel), sum = result_total(sel);
    uint32_t round = 0, drops = 0, next_drop = 0, i;
    int dropping = 0, late = 0;
    for (;;) {
        uint32_t most, least, undone = 0;
        double est = sum;
        /* an unaffordable node makes the sum infinite: never within budget */
        if (!isinf(sum) && sum <= limit) {
            sel->cost_sum = sum;
            sel->cost_err = 0.0;
            sel->stats.over_budget = 0; /* the roots' running sum had rounded up */
            return 0;
        }
        if (sel->stats.over_budget)
            return 0; /* the roots alone exceed the budget, and overflow draws them */
        if (!dec_built) {
            tclod_heap_clear(&sel->greedy.dec);
            for (i = 0; i < sel->cut_count; ++i) {
                tclod_id p = s->parent[sel->cut[i]];
                if (queue_decrement(sel, p, 0) != 0)
                    return -1;
            }
            dec_built = 1;
        }
        late = late || repair_late(sel);
        most = late || round > 30u ? UINT32_MAX : 1u << round;
        least = round < 2u ? 1u : 1u << (round > 31u ? 30u : round - 1u);
        while (undone < least || (undone < most && !(est <= limit))) {
            if (sel->greedy.dec.count > 0) {
                tclod_id p = tclod_heap_pop(&sel->greedy.dec);
                est -= sel->greedy.delta[p].delta_c; /* the cost the collapse saves */
                if (apply_decrement(sel, p) != 0)
                    return -1;
            } else {
                tclod_id r;
                if (!dropping) {
                    if (undone > 0)
                        break; /* sum again before leaving out any root */
                    drops = drop_order(sel);
                    dropping = 1;
                }
                if (next_drop == drops)
                    break;
                r = ~sel->scratch[next_drop++];
                est -= sel->node[r].cost;
                account(sel, r, -1.0);
                sel->flags[r] |= TCLOD_FLAG_DROPPED;
                sel->stats.dropped_roots++;
            }
            if (++undone % CLOCK_STRIDE == 0 && !late && repair_late(sel)) {
                late = 1;
                most = UINT32_MAX;
            }
        }
        /* nothing is left to undo: no node is counted, and the total is 0 */
        assert(undone > 0);
        if (undone == 0)
            return 0;
        sum = result_total(sel);
        round++;
    }
}

/* Starts the solve: a warm start is brought within the budget, a cold one
 * starts from the roots. Always completes. */
static int greedy_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    R->greedy.warm = !sel->desc.cold_start && sel->has_cut && R->greedy.audit != 2;
    R->greedy.fell_back = R->greedy.warm && sel->greedy.fallback.left > 0;
    if (R->greedy.fell_back) {
        R->greedy.warm = 0;
        sel->stats.notes |= TCLOD_NOTE_COLD_FALLBACK;
    }
    R->skipped = 0;
    if (R->greedy.warm && sel->greedy.fallback.since_audit >= TCLOD_AUDIT_PERIOD &&
        sel->desc.solver == TCLOD_SOLVER_GREEDY && sel->desc.greedy.fallback != TCLOD_OFF &&
        sel->desc.greedy.lookahead == 0 && sel->frame->max_iterations == 0 &&
        sel->frame->solve_seconds == 0.0 && !tclod_scene_streams(sel->scene)) {
        R->greedy.audit = 1;
        sel->greedy.fallback.since_audit = 0;
    }
    if (R->greedy.warm && sel->node_version != sel->scene->node_version) {
        /* the edits since the cut was made, from the log while it holds them */
        const tclod_scene *s = sel->scene;
        uint64_t seen = sel->user.log_seen;
        if (seen >= s->log_base && seen <= s->log_base + s->log_count)
            repair_from_log(sel, (uint32_t)(seen - s->log_base));
        else
            repair_cut(sel);
    }
    if (R->greedy.warm) {
        int rc = start_warm(sel);
        if (rc == 0)
            rc = restore_budget(sel);
        if (rc <= 0)
            return rc;
        R->greedy.warm = 0; /* nothing left to collapse fits: start from the roots */
        R->greedy.audit = 0;
    }
    R->greedy.closure_head = R->greedy.closure_tail = 0;
    R->greedy.closing = sel->greedy.closure_hint > 0.0 && sel->frame->max_iterations == 0 &&
                        sel->frame->solve_seconds == 0.0;
    R->greedy.closure_key = sel->greedy.closure_hint * CLOSURE_MARGIN;
    if (start_cold(sel) != 0)
        return -1;
    R->greedy.closure_cost = sel->cost_sum;
    R->greedy.closure_err = sel->cost_err;
    tclod_greedy_track(sel); /* the safeguard's state, from the roots' sums */
    R->greedy.misfit = TCLOD_NONE;
    R->greedy.lp_bound = 0.0;
    R->greedy.picks = R->greedy.best_picks = R->greedy.left_out = R->greedy.tries = 0;
    R->greedy.searching = 0;
    return 0;
}

/* After a solve: whether the next one starts warm (docs/greedy.md, falling
 * back). Warm solves keep a running mean of their work (weight 1/8 for the
 * newest); once it exceeds the last cold solve's by TCLOD_FALLBACK_MARGIN,
 * the next span of solves (1, doubling up to TCLOD_FALLBACK_SPAN_MAX while
 * warm starts keep losing) starts from the roots and the mean starts again
 * after them. A mean within the margin resets the span. Not with
 * tclod_greedy_desc.fallback TCLOD_OFF. */
static void weigh_start(tclod_selector *sel) {
    tclod_fallback *fb = &sel->greedy.fallback;
    const tclod_resume *R = &sel->resume;
    double work = (double)sel->stats.evaluations + (double)sel->stats.iterations;
    if (!R->greedy.warm) {
        fb->cold_work = work;
        if (R->greedy.fell_back && fb->left > 0)
            fb->left--;
        return;
    }
    fb->since_audit++;
    fb->warm_work = fb->warm_work > 0.0 ? fb->warm_work + (work - fb->warm_work) / 8.0 : work;
    if (fb->cold_work > 0.0 && fb->warm_work > TCLOD_FALLBACK_MARGIN * fb->cold_work &&
        sel->desc.greedy.fallback != TCLOD_OFF) {
        fb->span = fb->span == 0
                       ? 1u
                       : (fb->span < TCLOD_FALLBACK_SPAN_MAX / 2u ? 2u * fb->span
                                                                  : TCLOD_FALLBACK_SPAN_MAX);
        fb->left = fb->span;
        fb->warm_work = 0.0;
    } else {
        fb->span = 0;
    }
}

/* The audit (docs/greedy.md, warm start). A warm start improves the previous
 * cut one increment, decrement or swap at a time, and can stay in a selection
 * a cold solve beats: where the benefit of a node above the cut grew past what
 * its refined subtree gives, no single decrement shows it. Every
 * TCLOD_AUDIT_PERIOD warm solves without limits, the warm solve's cut is set
 * aside and a cold solve follows; the cold one is kept (and the solve says it
 * fell back) when it has more benefit, else the warm cut is put back. Audits
 * thus bound how long a warm start stays behind. */

/* After an audited warm solve: sets its cut aside and starts the cold one.
 * Returns 0 when there is nothing to compare (roots dropped, over budget). */
static int audit_begin(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    if (sel->stats.dropped_roots || sel->stats.over_budget) {
        R->greedy.audit = 0;
        return 0;
    }
    memcpy(sel->greedy.audit_cut, sel->cut, sizeof(tclod_id) * sel->cut_count);
    memset(&R->greedy, 0, sizeof R->greedy); /* the cold solve starts afresh */
    R->greedy.audit_count = sel->cut_count;
    R->greedy.audit_benefit = sel->benefit_sum;
    R->greedy.audit_stop = sel->stats.stop_reason;
    R->greedy.audit = 2;
    R->skipped = 0;
    R->phase = GREEDY_START;
    return 1;
}

/* After the audit's cold solve: keeps the better cut. */
static void audit_end(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    uint32_t i;
    if (sel->stats.dropped_roots || sel->stats.over_budget ||
        !(sel->benefit_sum > R->greedy.audit_benefit)) { /* the warm cut stays */
        clear_cut(sel);
        sel->cut_count = R->greedy.audit_count;
        memcpy(sel->cut, sel->greedy.audit_cut, sizeof(tclod_id) * sel->cut_count);
        for (i = 0; i < sel->cut_count; ++i) {
            sel->node[sel->cut[i]].cut_pos = i;
            account(sel, sel->cut[i], 1.0);
        }
        sel->stats.stop_reason = R->greedy.audit_stop;
        sel->stats.dropped_roots = 0; /* the warm solve's, as audit_begin found them */
        sel->stats.over_budget = 0;
    } else {
        sel->stats.notes |= TCLOD_NOTE_COLD_FALLBACK;
    }
    R->greedy.audit = 0;
}

tclod_status tclod_greedy_solve(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int rc = 0;
    while (rc == 0 && !sel->paused) {
        switch (R->phase) {
        case GREEDY_START:
            rc = greedy_start(sel);
            R->phase = GREEDY_IMPROVE;
            break;
        case GREEDY_IMPROVE:
            rc = improve(sel, R->greedy.warm, !R->greedy.warm && R->greedy.use_alt);
            if (!sel->paused)
                R->phase = R->greedy.warm ? GREEDY_END : tclod_greedy_after_pass(sel);
            break;
        case GREEDY_PASS:
            R->greedy.tries++;
            rc = tclod_greedy_start_decided(sel);
            R->phase = GREEDY_IMPROVE_PASS;
            break;
        case GREEDY_IMPROVE_PASS:
            if (!R->greedy.infeasible)
                rc = improve(sel, 0, 0);
            if (!sel->paused)
                R->phase = tclod_greedy_after_pass(sel);
            break;
        case GREEDY_REPLAY:
            R->greedy.picks = R->greedy.best_picks;
            memcpy(R->greedy.pick, R->greedy.best_pick, sizeof(tclod_id) * R->greedy.picks);
            memcpy(R->greedy.take, R->greedy.best_take, R->greedy.picks);
            rc = tclod_greedy_start_decided(sel);
            R->phase = GREEDY_IMPROVE_REPLAY;
            break;
        case GREEDY_IMPROVE_REPLAY:
            rc = improve(sel, 0, 0);
            if (!sel->paused)
                R->phase = GREEDY_END;
            break;
        default:
            rc = enforce_budget(sel, R->greedy.warm);
            clear_heaps(sel);
            if (rc != 0)
                return TCLOD_ERR_CALLBACK;
            if (R->greedy.audit == 2) {
                audit_end(sel);
                return TCLOD_OK;
            }
            weigh_start(sel);
            if (R->greedy.audit == 1 && audit_begin(sel))
                break;
            return TCLOD_OK;
        }
    }
    if (rc == 0)
        return TCLOD_OK;
    clear_heaps(sel);
    return TCLOD_ERR_CALLBACK;
}

/* ---- buffers ------------------------------------------------------------------ */

size_t tclod_greedy_buffers(tclod_greedy_state *g, tclod_array *out) {
    size_t n = 0;
    /* increments are NaN until computed; no heap slot is TCLOD_NONE */
    out[n++] = (tclod_array){(void **)&g->delta, sizeof(tclod_delta), 0xff};
    out[n++] = (tclod_array){(void **)&g->inc_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->cheap_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->dec_slot, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&g->inc_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->cheap_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->dec_block, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&g->audit_cut, sizeof(tclod_id), -1};
    return n;
}

/* Where a heap's entries start in its block: entry 1 on a 64-byte boundary,
 * so that every slot's four children lie in one cache line. Up to three
 * entries are skipped. */
static tclod_heap_entry *heap_items(tclod_heap_entry *block) {
    uintptr_t a = (uintptr_t)(void *)block;
    if (a % sizeof(tclod_heap_entry) != 0)
        return block;
    return block + (64u + 48u - a % 64u) % 64u / sizeof(tclod_heap_entry);
}

/* The heaps find their entries in their blocks and their slots in dense
 * arrays. */
void tclod_greedy_bind(tclod_greedy_state *g) {
    g->inc.items = heap_items(g->inc_block);
    g->cheap.items = heap_items(g->cheap_block);
    g->dec.items = heap_items(g->dec_block);
    g->inc.pos = g->inc_slot;
    g->cheap.pos = g->cheap_slot;
    g->dec.pos = g->dec_slot;
}

/* ---- the steps the mixed solver interleaves with its smooth ones ------------ */

int tclod_greedy_start(tclod_selector *sel) {
    return start_cold(sel);
}

tclod_id tclod_greedy_candidate(tclod_selector *sel, double *ratio, int *skipped) {
    for (;;) {
        tclod_id n;
        if (sel->greedy.inc.count == 0)
            return TCLOD_NONE;
        n = sel->greedy.inc.items[0].id;
        if (greedy_increment_fits(sel, n)) {
            *ratio = sel->greedy.inc.items[0].key;
            return n;
        }
        *skipped = 1;
        if (!increment_may_fit(sel))
            return TCLOD_NONE;
        /* smooth steps only add cost too: a misfit never fits again */
        if (sel->resume.greedy.use_alt)
            greedy_consider_alternative(sel, n);
        skip_misfit(sel, n);
    }
}

void tclod_greedy_skip(tclod_selector *sel) {
    tclod_id n = pop_increment(sel);
    sel->stats.iterations++;
    if (sel->resume.greedy.use_alt)
        greedy_consider_alternative(sel, n);
}

int tclod_greedy_take(tclod_selector *sel, tclod_id n) {
    sel->stats.iterations++;
    return apply_increment_cold(sel, n);
}

int tclod_greedy_enforce(tclod_selector *sel) {
    return enforce_budget(sel, 0);
}

void tclod_greedy_end(tclod_selector *sel) {
    clear_heaps(sel);
}
