/*
 * What the greedy's four files share: greedy.c (the papers' loop and the final
 * repair), greedy_start.c (the cold and warm starts), greedy_lookahead.c
 * (increments that reach below a node's children) and greedy_search.c (the
 * passes after the plain one: the best skipped increment's T(n) and the
 * restarts' search); below, the cut with its increments and decrements, which
 * greedy.c and greedy_start.c compile each (TCLOD_UNIT). Included by those four
 * only: the rest of the library sees greedy.h.
 */
#ifndef TCLOD_GREEDY_INTERNAL_H
#define TCLOD_GREEDY_INTERNAL_H

#include "../../eval/evaluate.h"

/* Relative gain a swap must make, so rounding can never make swaps cycle. */
#define GREEDY_SWAP_MARGIN 1e-12

/* Swaps a solve tries past [MB97]'s balance point, where the best increment's
 * ratio is no longer above the cheapest decrement's: a swap there gains only
 * when the misfit needs less than it costs (greedy.c, exchange_may_gain). */
#define GREEDY_EXCHANGES 16u

/* The stages of a greedy solve (sel->resume.phase). */
enum {
    GREEDY_START = 0,
    GREEDY_IMPROVE,
    GREEDY_PASS, /* a pass after the plain one, with resume.greedy.pick/take */
    GREEDY_IMPROVE_PASS,
    GREEDY_REPLAY, /* the best pass again, when another one ended last */
    GREEDY_IMPROVE_REPLAY,
    GREEDY_END
};

/* ---- the cut and its running sums ------------------------------------------ */

static inline int greedy_counts(const tclod_selector *sel, tclod_id n) {
    return sel->node[n].benefit > 0.0 && !(sel->flags[n] & TCLOD_FLAG_DROPPED);
}

/* Costs are >= 0 or +inf (unaffordable): never NaN, never -inf. */
static inline int greedy_unaffordable(double cost) {
    return cost == HUGE_VAL;
}

/* The budget left to the cut: the frame's, minus what smooth variables hold. */
static inline double greedy_cut_budget(const tclod_selector *sel) {
    return sel->frame->budget - sel->reserved;
}

static inline int greedy_feasible(const tclod_selector *sel) {
    return sel->unaffordable == 0 && sel->cost_sum <= greedy_cut_budget(sel);
}

/* The key of increment (db, dc): NaN when it gains nothing. */
static inline double greedy_ratio_key(double db, double dc) {
    if (!(db > 0.0))
        return (double)NAN;
    return dc > 0.0 ? db / dc : HUGE_VAL;
}

/* 1 when increment n fits the remaining budget, by the running sum and by its
 * compensated total (an increment that fits only because the running sum
 * absorbed costs is not taken: the final summation would give it back). */
static inline int greedy_increment_fits(const tclod_selector *sel, tclod_id n) {
    return sel->unaffordable == 0 &&
           tclod_within(sel, sel->cost_sum + sel->greedy.delta[n].delta_c, greedy_cut_budget(sel));
}

/* ---- what the plain pass records for the search ----------------------------- */

/* A cold solve records the best single skipped increment with the increments
 * above it (sel->resume.greedy.alt_*): one that a pass forcing it reproduces, so not
 * a refit (tclod_greedy_apply_jump keeps those below one out). */
static inline void greedy_consider_alternative(tclod_selector *sel, tclod_id n) {
    tclod_resume *R = &sel->resume;
    const double *path = &sel->path[2u * n];
    double c = R->greedy.alt_roots_c + path[1] + sel->greedy.delta[n].delta_c;
    double b = R->greedy.alt_roots_b + path[0] + sel->greedy.delta[n].delta_b;
    /* fits as greedy_increment_fits has it, with the roots' compensation */
    if (c <= sel->frame->budget && !(c + R->greedy.alt_roots_err > sel->frame->budget) &&
        b > R->greedy.alt_benefit && !(sel->flags[n] & TCLOD_FLAG_REFIT)) {
        R->greedy.alt_node = n;
        R->greedy.alt_benefit = b;
    }
}

/* A cold pass records its first misfit n and the bound of the linear
 * relaxation there: the benefit so far plus n's gain (docs/greedy.md). */
static inline void greedy_note_misfit(tclod_selector *sel, tclod_id n) {
    tclod_resume *R = &sel->resume;
    if (R->greedy.misfit != TCLOD_NONE)
        return;
    R->greedy.misfit = n;
    R->greedy.misfit_key = sel->greedy.inc.items[0].key;
    R->greedy.lp_bound = sel->benefit_sum + sel->greedy.delta[n].delta_b;
}

/* 1 when the current pass leaves node n's increment out. */
static inline int greedy_left_out(const tclod_resume *R, tclod_id n) {
    uint32_t i;
    for (i = 0; i < R->greedy.picks; ++i)
        if (R->greedy.pick[i] == n && !R->greedy.take[i])
            return 1;
    return 0;
}

/* ---- greedy.c, for the other two ---------------------------------------------- */

/* Evaluates the children of visible cut node n and computes its plain
 * increment into sel->greedy.delta[n]; returns its key (NaN: no candidate),
 * with 1 in *failed on a strict error. */
double tclod_greedy_increment_key(tclod_selector *sel, tclod_id n, int *failed);
/* Adds n to the working cut and its running sums. */
void tclod_greedy_cut_add(tclod_selector *sel, tclod_id n);
/* Queues n's increment, if it is a candidate, in the place of *held's
 * queued one (then *held = TCLOD_NONE); otherwise pushes it. Returns 0, or
 * -1 on a strict error. */
int tclod_greedy_requeue(tclod_selector *sel, tclod_id n, tclod_id *held);
/* Queues the decrement into p when p is collapsible. Returns 0 or -1. */
int tclod_greedy_queue_decrement(tclod_selector *sel, tclod_id p);
/* Queues lookahead increment n of key `key` (NaN: none), pushed or appended;
 * and the same in the place of *held's queued increment. */
void tclod_greedy_enqueue_looking(tclod_selector *sel, tclod_id n, double key, int append);
void tclod_greedy_rekey_looking(tclod_selector *sel, tclod_id n, tclod_id *held, double key);

/* ---- greedy_lookahead.c ------------------------------------------------------- */

/* queue_increment and requeue_increment for a selector with a lookahead. */
int tclod_greedy_queue_looking(tclod_selector *sel, tclod_id n, int append);
int tclod_greedy_requeue_looking(tclod_selector *sel, tclod_id n, tclod_id *held);
/* The cheapest increment of cut node n with a jump queued. */
double tclod_greedy_cheapest_jump(tclod_selector *sel, tclod_id n);
/* Lookahead increment n that does not fit: the cut of its subtree that fits
 * and gains most becomes its increment (TCLOD_FLAG_REFIT). Returns its key,
 * NaN when none gains. */
double tclod_greedy_refit_jump(tclod_selector *sel, tclod_id n);
/* Applies lookahead increment n (TCLOD_FLAG_JUMP or REFIT). Returns 0 or -1. */
int tclod_greedy_apply_jump(tclod_selector *sel, tclod_id n, int track_dec, tclod_id *held,
                            double path_b, double path_c);

/* ---- greedy_search.c ---------------------------------------------------------- */

/* Starts a pass from the roots with the current decisions (GREEDY_PASS,
 * GREEDY_REPLAY). Returns 0 or -1. */
int tclod_greedy_start_decided(tclod_selector *sel);
/* The stage after a pass of a cold solve (GREEDY_*). */
int tclod_greedy_after_pass(tclod_selector *sel);

/* ==== greedy.c and greedy_start.c: the cut and its increments ==================== */

/* ---- the cut and its running sums ------------------------------------------ */

TCLOD_UNIT void account(tclod_selector *sel, tclod_id n, double sign) {
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

TCLOD_UNIT void greedy_cut_add(tclod_selector *sel, tclod_id n) {
    assert(sel->node[n].cut_pos == TCLOD_NONE);
    sel->node[n].cut_pos = sel->cut_count;
    sel->cut[sel->cut_count++] = n;
    sel->flags[n] |= TCLOD_FLAG_MOVED;
    account(sel, n, 1.0);
}

TCLOD_UNIT void greedy_cut_remove(tclod_selector *sel, tclod_id n) {
    uint32_t slot = sel->node[n].cut_pos;
    tclod_id last = sel->cut[--sel->cut_count];
    account(sel, n, -1.0);
    sel->cut[slot] = last;
    sel->node[last].cut_pos = slot;
    sel->flags[last] |= TCLOD_FLAG_MOVED;
    sel->node[n].cut_pos = TCLOD_NONE;
}

TCLOD_UNIT const tclod_id *children_of(const tclod_selector *sel, tclod_id n, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    *count = s->child_count[n];
    /* no slab at all while no node has had a child */
    return *count ? s->children + s->child_first[n] : NULL;
}

/* Gathers the children of node n that increment_key will evaluate (those of
 * a visible node), without lookahead, whose increments reach further down.
 * Returns 0 or -1. */
TCLOD_UNIT int gather_children(tclod_selector *sel, tclod_id n) {
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
TCLOD_UNIT int gather_all_children(tclod_selector *sel, const tclod_id *ns, uint32_t m) {
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
TCLOD_UNIT double increment_key(tclod_selector *sel, tclod_id n, int *failed) {
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
        if (node[c].stamp != sel->solve_id && tclod_evaluate_fresh(sel, c) != 0) {
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
TCLOD_UNIT int closes(const tclod_selector *sel, double key) {
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
TCLOD_UNIT int requeue_increment(tclod_selector *sel, tclod_id n, tclod_id *held) {
    if (*held == TCLOD_NONE)
        return queue_increment(sel, n, 0);
    return sel->desc.greedy.lookahead > 0 ? tclod_greedy_requeue_looking(sel, n, held)
                                          : requeue_plain(sel, n, held);
}

TCLOD_UNIT void unqueue_increment(tclod_selector *sel, tclod_id n) {
    if (!tclod_heap_contains(&sel->greedy.inc, n))
        return;
    tclod_heap_remove(&sel->greedy.inc, n);
    if (sel->greedy.cheap_live)
        tclod_heap_remove(&sel->greedy.cheap, n);
}

TCLOD_UNIT void clear_heaps(tclod_selector *sel) {
    tclod_heap_clear(&sel->greedy.inc);
    tclod_heap_clear(&sel->greedy.cheap);
    tclod_heap_clear(&sel->greedy.dec);
    sel->greedy.cheap_live = CHEAP_NONE;
}

TCLOD_UNIT tclod_id pop_increment(tclod_selector *sel) {
    tclod_id n = sel->greedy.inc.items[0].id;
    unqueue_increment(sel, n);
    return n;
}

/* Pops misfit n; a lookahead increment is queued again as a cut that fits
 * (tclod_greedy_refit_jump), when one gains. */
TCLOD_UNIT void skip_misfit(tclod_selector *sel, tclod_id n) {
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
TCLOD_UNIT void park_misfit(tclod_selector *sel, tclod_id n) {
    uint32_t at = sel->cap - ++sel->resume.greedy.parked;
    sel->scratch[at] = n;
    sel->scratch_key[at] = sel->greedy.inc.items[0].key;
    pop_increment(sel);
    sel->stats.iterations++;
}

/* Queues the parked misfits again, those still in the cut and not queued. */
TCLOD_UNIT void unpark_misfits(tclod_selector *sel) {
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
TCLOD_UNIT int increment_may_fit(tclod_selector *sel) {
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
TCLOD_UNIT int collapsible(const tclod_selector *sel, tclod_id p) {
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
TCLOD_UNIT double decrement_key(tclod_selector *sel, tclod_id p) {
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
TCLOD_UNIT int queue_collapsible(tclod_selector *sel, tclod_id p, int append) {
    double key;
    if (tclod_evaluate_node(sel, p) != 0)
        return -1;
    key = decrement_key(sel, p);
    if (append)
        tclod_heap_append(&sel->greedy.dec, p, key);
    else
        tclod_heap_push(&sel->greedy.dec, p, key);
    return 0;
}

/* Queues the decrement into p when p is collapsible. */
TCLOD_UNIT int queue_decrement(tclod_selector *sel, tclod_id p, int append) {
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

TCLOD_UNIT int apply_increment(tclod_selector *sel, tclod_id n, int track_dec) {
    return apply_increment_as(sel, n, track_dec);
}

/* apply_increment without decrements to track: a cold pass's. */
TCLOD_UNIT int apply_increment_cold(tclod_selector *sel, tclod_id n) {
    return apply_increment_as(sel, n, 0);
}

TCLOD_UNIT int apply_decrement(tclod_selector *sel, tclod_id p) {
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

/* ---- greedy_start.c ------------------------------------------------------------ */

/* Empties the cut and its running sums. */
void tclod_greedy_clear_cut(tclod_selector *sel);

/* After nodes were added or removed: makes the previous cut a cut of the
 * scene's current index again, in time proportional to the selection (the
 * cut, the nodes above it and their children) and the roots. Removed nodes
 * leave it. The nodes above it that are left (every one is an ancestor of a
 * node still in it) are refined: any child of theirs neither in the cut nor
 * above it (added since, or whose own cut nodes were all removed) joins it,
 * as does any root in neither. No ancestor of a cut node can join it, since
 * the index only gains leaves and loses whole subtrees. */
void tclod_greedy_repair_cut(tclod_selector *sel);

/* tclod_greedy_repair_cut from the scene's edit log, entries `from` on: the
 * edits since the previous cut was made, in time proportional to them (times the depth
 * of the nodes they touched). Nodes that left the index leave the cut; an
 * added node not below the cut joins it (its parent was refined), in the order
 * they were added, so that a new parent goes in before its new children, which
 * are then below it; then a node that lost its last child and is not below the
 * cut joins it. Added nodes come first: a node that lost its last child may
 * itself be new, below a new node that joined. */
void tclod_greedy_repair_from_log(tclod_selector *sel, uint32_t from);

/* Cut = the roots; when they do not fit, refinements that save cost, else
 * roots left out; queues the cut's increments. */
int tclod_greedy_start_cold(tclod_selector *sel);

/* Cut = the previous cut, re-evaluated; queues its increments and decrements. */
int tclod_greedy_start_warm(tclod_selector *sel);

/* A warm start's first moves, before the budget is restored: the free
 * collapses, and those that gain where they fit or a swap makes room for
 * them (try_swap), cascading up to the parents that become such. Only here
 * and in the last fill (fill_gaining_collapses): in the increments and swaps
 * between, a collapse that gains at a cost is a trade among others (a
 * lookahead's jump may take cheaper children at a loss). The pending ones
 * wait at the top of scratch, below any parked misfits (none at a warm
 * start), as try_swap uses its bottom. */
int tclod_greedy_take_first_collapses(tclod_selector *sel);

#endif /* TCLOD_GREEDY_INTERNAL_H */
