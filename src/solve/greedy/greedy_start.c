/*
 * TCLOD_SOLVER_GREEDY, its starts ([MB97]; [GEO §3.1-3.2]): the roots that fit
 * (and the refinements that cost less than what they replace, when even the
 * roots do not: shed_cost), the cold start from the roots, and the warm start
 * from the previous cut: the cut repaired after the host's edits (from the
 * edit log while it holds them), sorted for large scenes, given up where
 * residency no longer allows it (stream_repair), and its frontier evaluated
 * and queued. The loop that follows is in greedy.c.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (heap.c,
 * view.c); eval (evaluate.c); solve (greedy.c, greedy_lookahead.c).
 */
#include "greedy_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

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

void tclod_greedy_clear_cut(tclod_selector *sel) {
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
        if (tclod_evaluate_node(sel, c) != 0)
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
        tclod_greedy_clear_cut(sel);
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
int tclod_greedy_start_cold(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t i;
    tclod_greedy_clear_cut(sel);
    for (i = 0; sel->batching && i < s->root_count; ++i)
        if (tclod_batch_add(sel, s->roots[i]) != 0)
            return -1;
    if (tclod_batch_flush(sel) != 0)
        return -1;
    for (i = 0; i < s->root_count; ++i) {
        tclod_id r = s->roots[i];
        if (tclod_evaluate_node(sel, r) != 0)
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
void tclod_greedy_repair_cut(tclod_selector *sel) {
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

/* tclod_greedy_repair_cut from the scene's edit log, entries `from` on: the edits since
 * the previous cut was made, in time proportional to them (times the depth
 * of the nodes they touched). Nodes that left the index leave the cut; an
 * added node not below the cut joins it (its parent was refined), in the order
 * they were added, so that a new parent goes in before its new children, which
 * are then below it; then a node that lost its last child and is not below the
 * cut joins it. Added nodes come first: a node that lost its last child may
 * itself be new, below a new node that joined. */
void tclod_greedy_repair_from_log(tclod_selector *sel, uint32_t from) {
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
        if (tclod_evaluate_node(sel, a) != 0)
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
 * as tclod_greedy_start_warm looks at them, and the children that increments key, rather
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
int tclod_greedy_start_warm(tclod_selector *sel) {
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
            if (tclod_evaluate_node(sel, n) != 0)
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
    return tclod_greedy_take_first_collapses(sel);
}
