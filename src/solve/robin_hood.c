/*
 * TCLOD_SOLVER_ROBIN_HOOD: proportional time distribution, "Robin Hood's
 * algorithm for TCLOD" ([RH §5]).
 *
 * Every visible instance gets a value (eq. 8-11: its un-projected area over
 * its depth or distance, times its importance). The render time, the frame's
 * budget, is then shared out in proportion to value (eq. 2-4) while the
 * instances are visited from the least to the most complex (complexity: the
 * cost of the finest representation at a reference area, found once per scene
 * change): each takes the finest representation its share affords and hands
 * what it leaves back for the instances after it, so simple objects' surplus
 * reaches complex ones (cycles 1 and 2: values, then shares). What the last
 * ones cannot use goes, in a third and last cycle ([RH §7.2]: spend the
 * remaining time on the quality of the instances), to the instances that can
 * still refine: shared out again in proportion to value, pass after pass,
 * while a pass refines something and a step fits what is left.
 *
 * Instances are chains of single children (an object's levels; the finest
 * affordable level is found by a search over their monotone costs that starts
 * at the level the chain took in the last frame) and smooth objects (the
 * resolution whose cost matches the share, by a monotone inverse). Where a
 * chain ends in a node with several children (a terrain quadtree, a group
 * impostor) libtclod goes on the same way below it: when the instance's share
 * covers all the children's simplest levels, they become instances of their
 * own, each guaranteed its simplest level and sharing the rest by value, so
 * the cut never has a hole.
 *
 * This file holds the three cycles; the instances and their order, remade
 * when the scene changes, are in robin_hood_prepare.c.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (view.c); eval
 * (evaluate.c); solve (greedy, robin_hood_prepare.c).
 */
#include "robin_hood_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* The pass keeps this far (relative) inside the budget, so that the drift of
 * the running pool never carries the exact total over it. */
#define BUDGET_MARGIN 1e-9
/* Regula falsi steps of a smooth object's inverse cost. */
#define INVERSE_STEPS 60u
/* The leftover is shared out again only while it is at least this share of
 * the budget: below it another pass over the candidates, which walks all of
 * them, buys next to nothing (docs/robin_hood.md, the leftover). */
#define REFILL_MIN 5e-4
/* At most this many passes share the leftover out again: each takes most of
 * what is left, the smooth objects whatever the nodes' whole steps leave. */
#define REFILL_PASSES 16u
/* How many instances ahead the walks over the order fetch the records of the
 * next ones (fetch_instance). */
#define ORDER_AHEAD 8u

/* ---- value functions (eq. 8-11) ------------------------------------------------- */

double tclod_value_of(tclod_value f, double area, double depth, double distance,
                      double importance) {
    if (!(area >= 0.0) || !(depth > 0.0) || !(distance > 0.0) || !(importance >= 0.0) ||
        isinf(area) || isinf(depth) || isinf(distance) || isinf(importance) ||
        (unsigned)f > (unsigned)TCLOD_VALUE_BENEFIT)
        return 0.0;
    return value_scale(f, area, depth, distance) * importance;
}

/* ---- the cut -------------------------------------------------------------------- */

/* The cost each cut slot adds to the total (0 for a culled or dropped node),
 * kept in slot order so that the exact total is a sequential sum: the second
 * half of rh.key. */
static double *cut_costs(tclod_selector *sel) {
    return sel->rh.key ? sel->rh.key + sel->rh.cap : NULL; /* NULL: an empty scene */
}

/* Puts n into the cut with `flags`, adding `add` to the total (costs:
 * cut_costs(sel)). */
static inline void cut_put(tclod_selector *sel, tclod_id n, uint8_t flags, double add,
                           double *costs) {
    uint32_t pos = sel->cut_count++;
    sel->node[n].cut_pos = pos;
    sel->cut[pos] = n;
    sel->flags[n] = flags;
    costs[pos] = add;
}

/* cut_add with cut_costs(sel) in costs. */
static inline void cut_add_cost(tclod_selector *sel, tclod_id n, uint8_t flags, double *costs) {
    cut_put(sel, n, flags,
            visible(sel, n) && !(flags & TCLOD_FLAG_DROPPED) ? sel->node[n].cost : 0.0, costs);
}

static void cut_add(tclod_selector *sel, tclod_id n, uint8_t flags) {
    cut_add_cost(sel, n, flags, cut_costs(sel));
}

/* Takes n out of the cut; the last slot fills its place. */
static void cut_remove(tclod_selector *sel, tclod_id n) {
    uint32_t pos = sel->node[n].cut_pos, last = --sel->cut_count;
    sel->node[n].cut_pos = TCLOD_NONE;
    sel->flags[n] = 0;
    if (pos == last)
        return;
    sel->cut[pos] = sel->cut[last];
    sel->node[sel->cut[pos]].cut_pos = pos;
    cut_costs(sel)[pos] = cut_costs(sel)[last];
}

static void cut_clear(tclod_selector *sel) {
    const tclod_id *cut = sel->cut; /* in locals: the stores cannot change them */
    tclod_node_state *node = sel->node;
    uint8_t *flags = sel->flags;
    uint32_t i, count = sel->cut_count;
    for (i = 0; i < count; ++i) {
        if (i + TCLOD_CUT_AHEAD < count)
            TCLOD_PREFETCH(&node[cut[i + TCLOD_CUT_AHEAD]]);
        node[cut[i]].cut_pos = TCLOD_NONE;
        flags[cut[i]] = 0;
    }
    sel->cut_count = 0;
}

/* ---- candidates of the second cycle --------------------------------------------------- */

/* The node instances that can still refine, in the order they were placed: a
 * ring of their chains' first nodes in scratch[], with each one's value and
 * what its next step adds (or a lower bound of it) in path[]. Entries go in at
 * the back while the front is being shared out; a chain is in the ring at
 * most once, so node capacity suffices. */
static void push_candidate(tclod_selector *sel, uint32_t id, double value, double step) {
    tclod_resume *R = &sel->resume;
    uint32_t at = R->rh.ring_first + R->rh.ring_count; /* < 2 cap */
    if (at >= sel->cap)
        at -= sel->cap;
    sel->scratch[at] = id;
    sel->path[2u * at] = value;
    sel->path[2u * at + 1u] = step;
    R->rh.ring_count++;
    R->rh.ring_value += value;
    if (step < R->rh.min_step)
        R->rh.min_step = step;
}

static uint32_t pop_candidate(tclod_selector *sel, double *value, double *step) {
    tclod_resume *R = &sel->resume;
    uint32_t at = R->rh.ring_first;
    R->rh.ring_first = at + 1u < sel->cap ? at + 1u : 0u;
    R->rh.ring_count--;
    *value = sel->path[2u * at];
    *step = sel->path[2u * at + 1u];
    return sel->scratch[at];
}

/* The instance starting at `head`, of value `value`, now drawn at node n (or
 * dropped): a candidate when it can refine (a finer level in its chain, or
 * children below its end) and the next step is affordable at all. */
static void node_candidate(tclod_selector *sel, tclod_id head, tclod_id n, double value,
                           double step) {
    if (!(step < HUGE_VAL) || (child_count(sel, n) == 0u && !(sel->flags[n] & TCLOD_FLAG_DROPPED)))
        return;
    push_candidate(sel, head, value, step);
}

/* ---- the first cycle: shares ------------------------------------------------------ */

/* Level k of the chain ch starting at head. */
static inline tclod_id chain_node(const tclod_selector *sel, tclod_id head,
                                  const tclod_rh_chain *ch, uint32_t k) {
    return ch->flags & TCLOD_RH_CONSECUTIVE ? head + k : sel->rh.chain[ch->at + k];
}

/* 1 when node n, a level of the chain ch starting at head, costs at most
 * `time`, 0 when not, -1 on a strict error. */
TCLOD_ALWAYS_INLINE int fits(tclod_selector *sel, tclod_id n, tclod_id head,
                             const tclod_rh_chain *ch, double time) {
    if (sel->node[n].stamp != sel->solve_id &&
        evaluate_level(sel, n, head, (ch->flags & TCLOD_RH_SHARED) != 0) != 0)
        return -1;
    return sel->node[n].cost <= time;
}

/* Streaming: how many levels of the chain ch starting at head come before
 * its first level that is not resident (the head is: it was placed). Such a
 * level costs +inf (tclod_evaluate_absent), which would break the rising
 * costs finest_level searches, so the chain ends there for this solve, as
 * the greedy stops refining there. */
static TCLOD_NOINLINE uint32_t resident_levels(const tclod_selector *sel, tclod_id head,
                                               const tclod_rh_chain *ch) {
    uint32_t k;
    for (k = 1; k < ch->len; ++k)
        if (sel->scene->flags[chain_node(sel, head, ch, k)] & TCLOD_NODE_ABSENT)
            break;
    return k;
}

/* The finest level of the chain ch starting at head whose cost is at most
 * `time`, which must cover the first (evaluated) level. The costs grow level
 * by level, so the levels that fit are a prefix of the chain (of its levels
 * before the first that is not resident: resident_levels). The search
 * starts at the level the chain took last, gallops away from it and ends by
 * bisection: two evaluations when the level has not changed (one at either
 * end of the chain), about 2 log2 of the distance when it has. *step is what
 * the next level adds to the cost (HUGE_VAL at the chain's end). Returns -1
 * on a strict error. */
TCLOD_ALWAYS_INLINE int finest_level(tclod_selector *sel, tclod_id head, const tclod_rh_chain *ch,
                                     double time, tclod_id *out, double *step) {
    uint32_t len = ch->len, lo = 0, hi, d = 1, guess;
    tclod_id lo_node;
    int f;
    assert(sel->node[head].stamp == sel->solve_id && sel->node[head].cost <= time);
    if (TCLOD_UNLIKELY(sel->resume.rh.streams) && len > 1u)
        len = resident_levels(sel, head, ch);
    hi = len;
    if (len == 1u) { /* a single level: nothing to search */
        *out = head;
        set_last_level(sel, head, 0u);
        *step = HUGE_VAL;
        return 0;
    }
    /* from here on level lo fits; level hi does not, or is past the end */
    guess = last_level(sel, head, len);
    if (guess > 0u) {
        if ((f = fits(sel, chain_node(sel, head, ch, guess), head, ch, time)) < 0)
            return -1;
        if (f)
            lo = guess;
        else
            hi = guess;
    }
    if (hi == len) { /* up from lo */
        for (; d < hi - lo; d *= 2u) {
            if ((f = fits(sel, chain_node(sel, head, ch, lo + d), head, ch, time)) < 0)
                return -1;
            if (!f) {
                hi = lo + d;
                break;
            }
            lo += d;
        }
    } else { /* down from hi */
        for (; d < hi - lo; d *= 2u) {
            if ((f = fits(sel, chain_node(sel, head, ch, hi - d), head, ch, time)) < 0)
                return -1;
            if (f) {
                lo = hi - d;
                break;
            }
            hi -= d;
        }
    }
    while (hi - lo > 1u) {
        uint32_t mid = lo + (hi - lo) / 2u;
        if ((f = fits(sel, chain_node(sel, head, ch, mid), head, ch, time)) < 0)
            return -1;
        if (f)
            lo = mid;
        else
            hi = mid;
    }
    lo_node = chain_node(sel, head, ch, lo);
    *out = lo_node;
    set_last_level(sel, head, lo);
    *step = hi < len ? sel->node[chain_node(sel, head, ch, hi)].cost - sel->node[lo_node].cost
                     : HUGE_VAL;
    return 0;
}

/* Whether the sphere of radius reach around branching node b, which holds
 * its children, lies inside the frustum: then none of them needs the frustum
 * test. */
static int branch_inside(const tclod_selector *sel, tclod_id b, float reach) {
    const tclod_node_bounds *bb = &sel->scene->bounds[b];
    double p[3];
    if (!sel->has_view || !(reach >= 0.0f))
        return 0;
    p[0] = bb->c[0] - sel->view.eye[0];
    p[1] = bb->c[1] - sel->view.eye[1];
    p[2] = bb->c[2] - sel->view.eye[2];
    return tclod_view_cache_inside(&sel->view, p, (double)reach);
}

/* The children of the branch b that ends chain ch (ch->first, ch->count),
 * evaluated in id order while the summed cost of their simplest levels,
 * *reserve, is at most `time` (invisible children: none); `inside`: b's
 * reach sphere lies inside the frustum (branch_inside), so they need no
 * frustum test. Returns 1 when all of them fit, with each child's value in
 * scratch_key[slot] (its slot in the scene's children[]; -1 when it is not
 * visible) and the visible ones' sum in *value; 0 when they do not
 * (*reserve is then a lower bound of their cost); -1 on a strict error.
 * `plain`: plain_heads(sel) holds (a constant where it is inlined). */
TCLOD_ALWAYS_INLINE int evaluate_children(tclod_selector *sel, const tclod_rh_chain *ch, int inside,
                                          double time, double *reserve, double *value, int plain) {
    const tclod_scene *s = sel->scene;
    uint32_t j, first = ch->first, k = ch->count;
    double r = 0.0, sum = 0.0;
    /* what the loop below and the placement after it will read, fetched all
     * at once so that the misses overlap instead of coming one child at a
     * time (docs/robin_hood.md, memory): their sorted list, their values'
     * slots and, per child, its bounds and the records of its first levels */
    for (j = 0; j < k; j += 64u / sizeof(tclod_rh_child))
        TCLOD_PREFETCH(&sel->rh.child[first + j]);
    TCLOD_PREFETCH(&sel->rh.child[first + k - 1u]);
    for (j = 0; j < k; j += 64u / sizeof(double))
        TCLOD_PREFETCH_WRITE(&sel->scratch_key[first + j]);
    for (j = 0; j < k; ++j) {
        tclod_id c = sel->rh.kids[first + j];
        TCLOD_PREFETCH_WRITE(&sel->node[c]);
        /* the next line, by address: it may lie past the array's end */
        TCLOD_PREFETCH_WRITE((const void *)((uintptr_t)&sel->node[c] + 64u));
        TCLOD_PREFETCH(&s->bounds[c]);
    }
    for (j = 0; j < k; ++j) {
        tclod_id c = sel->rh.kids[first + j];
        double v;
        if (sel->node[c].stamp == sel->solve_id) {
            /* a branch's children are evaluated here only: an earlier call for b
             * in this solve (cycle 3 comes back to branches) kept the value */
            if (!visible(sel, c))
                continue;
            v = sel->scratch_key[first + j];
        } else {
            int seen = evaluate_head(sel, c, inside, plain, &v);
            if (seen < 0)
                return -1;
            sel->scratch_key[first + j] = seen ? v : -1.0; /* -1: culled */
            if (!seen)
                continue;
        }
        r += sel->node[c].cost;
        if (!(r <= time)) {
            *reserve = r;
            return 0;
        }
        sum += v;
    }
    *reserve = r;
    *value = sum;
    return isfinite(r);
}

/* evaluate_children, in a copy of its own for plain_heads. */
TCLOD_ALWAYS_INLINE int branch_children(tclod_selector *sel, const tclod_rh_chain *ch, int inside,
                                        double time, double *reserve, double *value) {
    if (sel->resume.rh.plain)
        return evaluate_children(sel, ch, inside, time, reserve, value, 1);
    return evaluate_children(sel, ch, inside, time, reserve, value, 0);
}

/* The instance of value `value` starting at visible node `head` (its chain
 * ch) with `time`, which covers its first level: its finest affordable level
 * in *level and what refining it further would add in *step (HUGE_VAL: it
 * cannot). When that level is a branch whose children's simplest levels all
 * fit, returns 1 with the children's summed simplest cost in *reserve and
 * their value in *children (branch_children); else 0 (the level is drawn;
 * a branch of benefit 0 is culled with its subtree, as in the other solvers,
 * and the finest visible level above it drawn); -1 on a strict error. *inside: on entry whether the
 * reach sphere of the branch above head lies inside the frustum (0 when not known), then whether
 * the level's does (TCLOD_RH_NESTED, or else branch_inside). */
TCLOD_ALWAYS_INLINE int place_chain(tclod_selector *sel, tclod_id head, const tclod_rh_chain *ch,
                                    double time, tclod_id *level, double *step, double *reserve,
                                    double *children, int *inside) {
    int refine;
    if (finest_level(sel, head, ch, time, level, step) != 0)
        return -1;
    sel->stats.iterations++;
    if (!(ch->flags & TCLOD_RH_BRANCH) || *level != chain_node(sel, head, ch, ch->len - 1u))
        return 0;
    if (!visible(sel, *level)) {
        /* a branch of benefit 0 is culled with its subtree: the finest
         * visible level above it is drawn instead (the head at the latest),
         * as the greedy would never refine into it */
        uint32_t k;
        for (k = ch->len - 2u; k > 0u; --k) {
            int f = fits(sel, chain_node(sel, head, ch, k), head, ch, time);
            if (f < 0)
                return -1;
            if (f && visible(sel, chain_node(sel, head, ch, k)))
                break;
        }
        *level = chain_node(sel, head, ch, k);
        set_last_level(sel, head, k);
        *step = HUGE_VAL;
        return 0;
    }
    *inside = (*inside && (ch->flags & TCLOD_RH_NESTED)) || branch_inside(sel, *level, ch->reach);
    refine = branch_children(sel, ch, *inside, time, reserve, children);
    if (refine == 0)
        *step = *reserve - sel->node[*level].cost;
    return refine;
}

/* The first lines of the children's lists (the scene's and the sorted one)
 * of the branches that end the chains of the children at positions first ..
 * end of rh.child: what their evaluation reads first, anywhere in memory.
 * Fetched while the earlier siblings are placed, so that a branch that
 * refines waits for one miss (its children's records) instead of two
 * (docs/robin_hood.md, memory). */
static inline void fetch_branches(const tclod_selector *sel, uint32_t first, uint32_t end) {
    uint32_t j;
    for (j = first; j < end; ++j) {
        const tclod_rh_chain *ch = &sel->rh.child[j].chain;
        if (ch->flags & TCLOD_RH_BRANCH) {
            TCLOD_PREFETCH(&sel->rh.kids[ch->first]);
            TCLOD_PREFETCH(&sel->rh.child[ch->first]);
        }
    }
}

/* Places the instance of value `value` starting at visible node `head` (its
 * chain ch) with `time` (which covers its first level) and, below it, the
 * instances of every branch its share reaches, depth first with an explicit
 * stack: a branch's children share what its time leaves beyond their
 * simplest levels, in proportion to value and least complex first, each
 * handing what it does not use on to the next. A leaf's level goes into the
 * cut and, when it can refine, into the candidates of cycle 3. Returns the
 * time used in *used; -1 on a strict error. */
static int place_node(tclod_selector *sel, tclod_id head, const tclod_rh_chain *ch, double value,
                      double time, double *used) {
    tclod_rh_frame *stack = sel->rh.stack;
    double *costs = cut_costs(sel);
    double step, reserve, children;
    uint32_t top = 0;
    tclod_id level;
    int inside = 0; /* not known above an instance of cycle 2 or 3 */
    int refine = place_chain(sel, head, ch, time, &level, &step, &reserve, &children, &inside);
    if (refine < 0)
        return -1;
    if (!refine) {
        /* a placed level: evaluated, not dropped, cost 0 when invisible */
        *used = sel->node[level].cost;
        cut_put(sel, level, 0, *used, costs);
        if (step < HUGE_VAL)
            push_candidate(sel, head, value, step);
        return 0;
    }
    for (;;) {
        tclod_rh_frame *f;
        uint32_t next, end;
        double extra, value_left;
        if (refine) { /* the children of `level` (ch's end) become instances sharing `time` */
            f = &stack[top++];
            f->next = ch->first;
            f->end = ch->first + ch->count;
            fetch_branches(sel, f->next, f->end);
            f->extra = time - reserve;
            f->value_left = children;
            f->alloc = time;
            f->base = top > 1u ? sel->node[head].cost : 0.0;
            f->inside = inside;
            refine = 0;
        }
        f = &stack[top - 1u];
        next = f->next;
        end = f->end;
        extra = f->extra;
        value_left = f->value_left;
        for (; next < end; ++next) {
            const tclod_rh_child *c = &sel->rh.child[next];
            tclod_id id = c->id;
            double v = sel->scratch_key[c->slot], share, base, u;
            if (v < 0.0) { /* culled: in the cut, not drawn */
                cut_put(sel, id, 0, 0.0, costs);
                continue;
            }
            share = value_left > 0.0 ? v * extra / value_left : 0.0;
            share = share > extra ? extra : (share > 0.0 ? share : 0.0);
            value_left -= v;
            base = sel->node[id].cost;
            inside = f->inside;
            refine = place_chain(sel, id, &c->chain, base + share, &level, &step, &reserve,
                                 &children, &inside);
            if (refine < 0)
                return -1;
            if (refine) {
                head = id;
                ch = &c->chain;
                time = base + share;
                ++next;
                break;
            }
            u = sel->node[level].cost;
            cut_put(sel, level, 0, u, costs); /* as above */
            if (step < HUGE_VAL)
                push_candidate(sel, id, v, step);
            extra -= u - base;
        }
        f->next = next;
        f->extra = extra;
        f->value_left = value_left;
        if (refine)
            continue;
        /* the branch is done: what its children used goes back to its parent
         * (an unlimited budget: every time is infinite and stays so, and
         * inf - inf would make it NaN) */
        {
            double b = f->base, u = isinf(f->alloc) ? b : f->alloc - extra;
            if (--top == 0) {
                *used = u;
                return 0;
            }
            stack[top - 1u].extra -= u - b;
        }
    }
}

/* The projected area and distance of smooth object pos (-1 without a view). */
static void smooth_measure(const tclod_selector *sel, uint32_t pos, float *area, float *distance) {
    const float *b = &sel->scene->smooth_bounds[4u * sel->scene->smooth_order[pos]];
    *area = *distance = -1.0f;
    if (sel->has_view)
        tclod_view_cache_measure(&sel->view, b, area, distance);
}

/* The smooth object at sorted position pos: culled like the mixed solver's
 * (and by a benefit of 0 at full resolution), its importance the importance
 * callback's or that benefit. Returns the value (0: not drawn), or -1 on a
 * strict error. */
static double smooth_value(tclod_selector *sel, uint32_t pos) {
    const tclod_scene *s = sel->scene;
    const float *b = &s->smooth_bounds[4u * s->smooth_order[pos]];
    double benefit, importance, db, c[3];
    float area, distance;
    tclod_query q;
    tclod_bounds qb;
    if (s->smooth_flags[s->smooth_order[pos]] & TCLOD_NODE_ABSENT)
        return 0.0; /* not resident: not drawn, like a culled one */
    smooth_measure(sel, pos, &area, &distance);
    if (sel->has_view && (!(area > 0.0f) || (double)area < sel->desc.smooth_cull_area))
        return 0.0;
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, 1.0, &benefit, &db, NULL, NULL);
    if (sel->failed)
        return -1.0;
    if (!(benefit > 0.0))
        return 0.0;
    q.id = s->smooth_order[pos];
    q.count = 1;
    q.view = sel->frame->view;
    q.screen_area = area;
    q.distance = distance;
    q.members = s->smooth_order + pos;
    tclod_sphere_bounds(b, &qb);
    q.bounds = &qb;
    importance = importance_of(sel, &q, benefit, 0);
    if (importance < 0.0)
        return -1.0;
    c[0] = (double)b[0];
    c[1] = (double)b[1];
    c[2] = (double)b[2];
    return importance > 0.0 ? instance_value(sel, c, (double)b[3], importance) : 0.0;
}

/* The resolution of smooth object pos whose cost is `time` (the largest that
 * fits, the cost growing with the resolution): regula falsi with the Illinois
 * correction, keeping the lower end within `time`. Returns it (0 when not even
 * the smallest fits) with its cost in *cost; -1 on a strict error. */
static double smooth_resolution(tclod_selector *sel, uint32_t pos, float area, float distance,
                                double time, double *cost) {
    double lo = TCLOD_SLOPE_FLOOR, hi = 1.0, clo, chi, dc;
    int side = 0;
    uint32_t k;
    *cost = 0.0;
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, 1.0, NULL, NULL, &chi, &dc);
    if (sel->failed)
        return -1.0;
    if (chi <= time) {
        *cost = chi;
        return 1.0;
    }
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, lo, NULL, NULL, &clo, &dc);
    if (sel->failed)
        return -1.0;
    if (!(clo <= time))
        return 0.0;
    for (k = 0; k < INVERSE_STEPS && hi - lo > 1e-12 && clo < time * (1.0 - 1e-9); ++k) {
        double x = isfinite(chi) ? lo + (hi - lo) * (time - clo) / (chi - clo) : 0.5 * (lo + hi);
        double c;
        if (!(x > lo && x < hi))
            x = 0.5 * (lo + hi);
        tclod_smooth_call(sel, pos, 1, NULL, area, distance, x, NULL, NULL, &c, &dc);
        if (sel->failed)
            return -1.0;
        if (c <= time) {
            lo = x;
            clo = c;
            if (side < 0)
                chi = time + 0.5 * (chi - time);
            side = -1;
        } else {
            hi = x;
            chi = c;
            if (side > 0)
                clo = time - 0.5 * (time - clo);
            side = 1;
        }
    }
    /* the Illinois correction moved the bracket's values: ask the cost of lo */
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, lo, NULL, NULL, cost, &dc);
    if (sel->failed)
        return -1.0;
    return *cost <= time ? lo : 0.0;
}

/* Draws smooth object pos at resolution r as a group of one. */
static int add_group(tclod_selector *sel, uint32_t pos, float area, float distance, double r,
                     double cost) {
    tclod_vars *V = &sel->mixed.vars;
    const float *b = &sel->scene->smooth_bounds[4u * sel->scene->smooth_order[pos]];
    uint32_t v = pos; /* variables sit at their position: groups come out in order */
    double db;
    V->r[v] = r;
    V->area[v] = area;
    V->distance[v] = distance;
    memcpy(&V->bounds[4u * v], b, 4 * sizeof(float));
    tclod_smooth_call(sel, pos, 1, NULL, area, distance, r, &V->b[v], &db, NULL, NULL);
    V->c[v] = cost;
    return sel->failed ? -1 : 0;
}

/* Smooth object pos gets `time`: it takes the largest resolution that costs
 * no more (under TCLOD_MISFIT_COARSEST, when not even the smallest does, the
 * smallest while `pool` covers it) if that is above the one it has. Returns
 * the cost it then holds in *used (0 when not drawn) and whether the
 * resolution rose; -1 on a strict error. */
static int place_smooth(tclod_selector *sel, uint32_t pos, double time, double pool, double *used) {
    tclod_vars *V = &sel->mixed.vars;
    float area, distance;
    double r, cost;
    int rose = 0;
    /* the culling and importance were worked out in cycle 1; the measures are
     * cheap and the callbacks cached nothing */
    smooth_measure(sel, pos, &area, &distance);
    r = smooth_resolution(sel, pos, area, distance, time, &cost);
    if (r < 0.0)
        return -1;
    if (r == 0.0 && V->r[pos] == 0.0 && sel->desc.robin_hood.misfit == TCLOD_MISFIT_COARSEST) {
        tclod_smooth_call(sel, pos, 1, NULL, area, distance, TCLOD_SLOPE_FLOOR, NULL, NULL, &cost,
                          &r);
        r = cost <= pool ? TCLOD_SLOPE_FLOOR : 0.0;
    }
    *used = V->c[pos];
    if (r > V->r[pos]) {
        if (add_group(sel, pos, area, distance, r, cost) != 0)
            return -1;
        *used = cost;
        rose = 1;
    }
    return rose;
}

/* The exact total in result order; should the pool's drift ever carry it
 * over the budget, smooth objects go first, then the cut is repaired as the
 * greedy repairs its own. */
static int finish(tclod_selector *sel) {
    const double *costs = cut_costs(sel);
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i)
        sum += costs[i];
    sel->cost_sum = sum;
    sel->cost_err = 0.0; /* the repair below counts from this sum */
    for (i = 0; i < sel->mixed.vars.count; ++i)
        sum += sel->mixed.vars.c[i];
    if (!isinf(sum) && sum <= sel->frame->budget)
        return 0;
    if (sel->resume.rh.overflowing) {
        sel->stats.over_budget = 1; /* the roots alone exceed it */
        return 0;
    }
    sel->mixed.vars.count = 0;
    return tclod_greedy_enforce(sel);
}

/* The node records that cycle 1 (`evaluating`: with the bounds) or cycle 2
 * (with the chain) will read for the instance at position k of the order,
 * if it is a node: the order lists them by complexity, in no order of id, so
 * each is a miss of its own once the nodes outgrow the cache. */
static inline void fetch_instance(const tclod_selector *sel, uint32_t k, int evaluating) {
    uint32_t id;
    if (k >= sel->rh.order_count || (id = sel->rh.order[k]) >= sel->scene->node_count)
        return;
    if (evaluating) {
        TCLOD_PREFETCH_WRITE(&sel->node[id]);
        TCLOD_PREFETCH(&sel->scene->bounds[id]);
    } else {
        TCLOD_PREFETCH(&sel->node[id]);
        TCLOD_PREFETCH(&sel->rh.chains[id]);
    }
}

/* Cycle 1 of §5.2: the value of every instance (0: not drawn) into rh.key,
 * and their total. `prepared`: prepare ran in this solve and may have
 * evaluated top-level heads already (finest_cost); a constant where this is
 * inlined, so that the other solves test nothing. */
TCLOD_ALWAYS_INLINE int values_as(tclod_selector *sel, double *total, int prepared) {
    const tclod_scene *s = sel->scene;
    uint32_t k;
    *total = 0.0;
    for (k = 0; k < sel->rh.order_count; ++k) {
        uint32_t id = sel->rh.order[k];
        double v;
        fetch_instance(sel, k + ORDER_AHEAD, 1);
        if (id < s->node_count) {
            if (prepared && sel->node[id].stamp == sel->solve_id) /* by finest_cost */
                v = sel->path[2u * id] > 0.0 ? sel->path[2u * id] : 0.0;
            else if (evaluate_head(sel, id, 0, 0, &v) < 0)
                return -1;
        } else {
            v = smooth_value(sel, id - s->node_count);
            if (v < 0.0)
                return -1;
        }
        sel->rh.key[k] = v;
        *total += v;
    }
    return 0;
}

/* values_as for a solve that did (not) prepare, each out of line as the one
 * loop was. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
static int
values_prepared(tclod_selector *sel, double *total) {
    return values_as(sel, total, 1);
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
static int
values(tclod_selector *sel, double *total) {
    return values_as(sel, total, 0);
}

/* One variable per smooth object, at its position in the smooth order, all
 * at resolution 0 (not drawn) until the object's share comes. */
static void empty_variables(tclod_selector *sel) {
    tclod_vars *V = &sel->mixed.vars;
    uint32_t i;
    V->count = with_smooth(sel) ? sel->scene->smooth_live : 0u;
    for (i = 0; i < V->count; ++i) {
        V->first[i] = i;
        V->size[i] = 1;
        V->r[i] = V->b[i] = V->c[i] = 0.0;
    }
}

/* Cycle 1 and the start of cycle 2. Returns 0 or -1 (strict error). */
static int robin_hood_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    double budget = sel->frame->budget, total;
    int prepared = sel->rh.version != sel->scene->version;
    if (prepared && tclod_rh_prepare(sel) != 0) {
        sel->rh.version = 0; /* strict: ask again next time */
        return -1;
    }
    cut_clear(sel);
    empty_variables(sel);
    sel->reserved = 0.0;
    if ((prepared ? values_prepared(sel, &total) : values(sel, &total)) != 0)
        return -1;
    R->rh.plain = plain_heads(sel);
    R->rh.streams = sel->scene->absent_count != 0;
    R->rh.pool = isinf(budget) ? budget : budget - BUDGET_MARGIN * budget;
    R->rh.held = sel->desc.overflow == TCLOD_OVERFLOW_DRAW_ROOTS;
    R->rh.overflowing = 0;
    if (R->rh.held) {
        /* every visible root is drawn: their simplest levels first, then the
         * rest shared out, as a branch's children share (docs/scenes.md) */
        double roots = 0.0;
        uint32_t k;
        for (k = 0; k < sel->rh.order_count; ++k) {
            uint32_t id = sel->rh.order[k];
            if (id < sel->scene->node_count && visible(sel, id) && !isinf(sel->node[id].cost))
                roots += sel->node[id].cost;
        }
        if (roots <= R->rh.pool) {
            R->rh.pool -= roots;
        } else {
            R->rh.overflowing = 1; /* nothing but the roots is drawn */
            R->rh.pool = 0.0;
        }
    }
    R->rh.value_left = total;
    R->rh.limited = 0;
    R->k = 0;
    R->rh.ring_first = R->rh.ring_count = 0;
    R->rh.ring_value = R->rh.smooth_value = 0.0;
    R->rh.smooth_open = 0;
    R->rh.min_step = HUGE_VAL;
    return 0;
}

/* The share of the next instance, of value v: v t_r / v_f of what is left
 * (eq. 2), and never more than that. */
static inline double share_of(double v, double pool, double value_left) {
    double share = value_left > 0.0 ? (isinf(pool) ? pool : v * pool / value_left) : 0.0;
    return share > pool ? pool : share;
}

static double share_for(const tclod_resume *R, double v) {
    return share_of(v, R->rh.pool, R->rh.value_left);
}

/* Cycle 2: least complex first, each share v_i t_r / v_f of what is left
 * (eq. 2-4), what an instance leaves going on to the next. Once the search
 * is stopped, the instances left get their simplest level while it fits.
 * Returns 0 (also when the step's slice ran out) or -1 (strict error). */
static int share_out(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_resume *R = &sel->resume;
    for (; R->k < sel->rh.order_count; ++R->k) {
        uint32_t id = sel->rh.order[R->k];
        double v = sel->rh.key[R->k], share, used = 0.0;
        int stopped;
        fetch_instance(sel, R->k + ORDER_AHEAD, 0);
        if (!sel->stopped && tclod_out_of_time(sel) && sel->paused)
            return 0;
        stopped = sel->stopped;
        share = share_for(R, v);
        R->rh.value_left -= v;
        if (stopped)
            share = 0.0;
        if (id < s->node_count) {
            double held = 0.0;
            if (!visible(sel, id)) {
                cut_add(sel, id, 0);
                continue;
            }
            if (R->rh.held && !isinf(sel->node[id].cost)) {
                if (R->rh.overflowing) { /* every root at its simplest, over the budget */
                    cut_add(sel, id, 0);
                    continue;
                }
                held = sel->node[id].cost; /* out of the pool already */
                share += held;
            }
            if (sel->node[id].cost <= share) {
                if (place_node(sel, id, &sel->rh.chains[id], v, share, &used) != 0)
                    return -1;
                used -= held;
            } else {
                set_last_level(sel, id, 0u); /* drawn, if at all, at its first level */
                if ((sel->desc.robin_hood.misfit == TCLOD_MISFIT_COARSEST || stopped) &&
                    sel->node[id].cost <= R->rh.pool) {
                    cut_add(sel, id, 0);
                    used = sel->node[id].cost;
                    node_candidate(sel, id, id, v, 0.0); /* its next step is not known */
                } else {
                    cut_add(sel, id, TCLOD_FLAG_DROPPED);
                    sel->stats.dropped_roots++;
                    node_candidate(sel, id, id, v, sel->node[id].cost);
                }
            }
        } else if (v > 0.0) {
            uint32_t pos = id - s->node_count;
            sel->stats.variables++;
            sel->stats.iterations++;
            if (place_smooth(sel, pos, share, R->rh.pool, &used) < 0)
                return -1;
            if (sel->mixed.vars.r[pos] < 1.0) { /* a candidate of cycle 3 */
                R->rh.smooth_value += v;
                R->rh.smooth_open++;
            }
        }
        R->rh.pool -= used;
        if (R->rh.pool < 0.0)
            R->rh.pool = 0.0;
    }
    return 0;
}

/* ---- the third cycle: the leftover ----------------------------------------------- */

/* Candidate `head` of value v (next step `step`), which gets `share`, is
 * placed again with the time it holds plus its share: it refines as far as
 * that reaches, its branches included, and leaves the rest. Returns whether
 * it refined; -1 on a strict error. */
static int refine_node(tclod_selector *sel, tclod_id head, double v, double step, double share) {
    tclod_resume *R = &sel->resume;
    const tclod_rh_chain *ch = &sel->rh.chains[head];
    tclod_id n = chain_node(sel, head, ch, last_level(sel, head, ch->len));
    int dropped = (sel->flags[n] & TCLOD_FLAG_DROPPED) != 0;
    double held = dropped ? 0.0 : sel->node[n].cost, used;
    uint32_t at;
    if (!(sel->node[head].cost <= held + share)) { /* costs that do not grow by level */
        push_candidate(sel, head, v, step);
        return 0;
    }
    cut_remove(sel, n);
    if (dropped)
        sel->stats.dropped_roots--;
    at = sel->cut_count;
    if (place_node(sel, head, ch, v, held + share, &used) != 0)
        return -1;
    R->rh.pool -= used - held;
    if (R->rh.pool < 0.0)
        R->rh.pool = 0.0;
    return dropped || sel->cut_count > at + 1u || sel->cut[at] != n;
}

/* Smooth object pos of value v, at a resolution below 1, gets `share`. */
static int refine_smooth(tclod_selector *sel, uint32_t pos, double v, double share) {
    tclod_resume *R = &sel->resume;
    double held = sel->mixed.vars.c[pos], used;
    int rose = place_smooth(sel, pos, held + share, R->rh.pool, &used);
    if (rose > 0) {
        R->rh.pool -= used - held;
        if (R->rh.pool < 0.0)
            R->rh.pool = 0.0;
        if (!(sel->mixed.vars.r[pos] < 1.0)) {
            R->rh.smooth_value -= v;
            R->rh.smooth_open--;
        }
    }
    return rose;
}

/* The node candidates at the front of this pass that do not try (their step
 * exceeds their share or what is left), with the pass's state in locals:
 * most of a pass. One whose step exceeds what is left is done (and the
 * instances could have refined further); one whose step exceeds its share
 * waits at the back of the ring for the next pass. Stops at the first that
 * tries, or at the end of the pass. */
static void skip_waiting(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    uint32_t *ids = sel->scratch;
    double *path = sel->path;
    size_t cap = sel->cap, first = R->rh.ring_first, back = first + R->rh.ring_count; /* < 2 cap */
    uint32_t count = R->rh.ring_count, left = R->rh.pass_left;
    double pool = R->rh.pool, value_left = R->rh.value_left, ring_value = R->rh.ring_value;
    double min_step = R->rh.min_step;
    int limited = R->rh.limited;
    if (isinf(pool))
        return; /* every step that fits tries */
    if (back >= cap)
        back -= cap; /* where a waiting one goes */
    for (; left > 0u; --left) {
        const double *e = &path[2u * first];
        double v = e[0], step = e[1];
        if (step <= pool) {
            /* its share, v pool / v_left as share_for has it (the cap at pool
             * does not matter once the step fits the pool) */
            if (step <= (value_left > 0.0 ? v * pool / value_left : 0.0))
                break; /* it tries */
            /* it waits, at the back */
            ids[back] = ids[first];
            path[2u * back] = v;
            path[2u * back + 1u] = step;
            back = back + 1u == cap ? 0u : back + 1u;
            ring_value += v;
            min_step = step < min_step ? step : min_step;
        } else { /* done */
            limited = 1;
            count--;
        }
        first = first + 1u == cap ? 0u : first + 1u;
        value_left -= v;
    }
    R->rh.ring_first = (uint32_t)first;
    R->rh.ring_count = count;
    R->rh.pass_left = left;
    R->rh.value_left = value_left;
    R->rh.ring_value = ring_value;
    R->rh.min_step = min_step;
    R->rh.limited = limited;
}

/* Cycle 3 ([RH §7.2]: what the instances cannot use is better spent on
 * their quality): what is left is shared out again, pass after pass, among
 * the instances that can still refine, in proportion to value and with what
 * each leaves going on to the next, as in cycle 2: first the nodes' instances
 * in the order they were placed, then the smooth objects below resolution 1,
 * least complex first, which can take any share and so take what the nodes'
 * whole steps leave. Each refines as far as the time it holds plus its share
 * reaches. An instance whose next step exceeds its share waits for the next
 * pass; one whose step exceeds all that is left is done. The passes end when
 * one refines nothing or uses less than REFILL_MIN of the budget (refining a
 * smooth object by less than the pool's rounding would go on for ever), after
 * REFILL_PASSES, or when what is left is below every step or below REFILL_MIN
 * of the budget. Returns 0 (also when the step's slice ran out or
 * the search was stopped) or -1 (strict error). */
static int refill(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_resume *R = &sel->resume;
    for (;;) {
        int rose;
        if (R->rh.pass_left == 0u && R->k >= sel->rh.order_count) { /* a pass is over */
            double least = REFILL_MIN * sel->frame->budget;
            if (!R->rh.refined || (R->rh.ring_count == 0u && R->rh.smooth_open == 0u) ||
                R->rh.pool < least || R->rh.passes == REFILL_PASSES ||
                (R->rh.passes > 0u && !(R->rh.pass_pool - R->rh.pool >= least)) ||
                (R->rh.smooth_open == 0u && !(R->rh.pool >= R->rh.min_step)))
                return 0;
            R->rh.pass_left = R->rh.ring_count;
            R->rh.value_left = R->rh.ring_value + R->rh.smooth_value;
            R->rh.ring_value = 0.0;
            R->rh.min_step = HUGE_VAL;
            R->rh.refined = 0;
            R->rh.pass_pool = R->rh.pool;
            R->rh.passes++;
            R->k = R->rh.smooth_open > 0u ? 0u : sel->rh.order_count;
        }
        if (R->rh.pass_left > 0u) {
            uint32_t at, id;
            double v, step, share;
            int tries;
            skip_waiting(sel);
            if (R->rh.pass_left == 0u)
                continue;
            at = R->rh.ring_first;
            id = sel->scratch[at];
            v = sel->path[2u * at];
            step = sel->path[2u * at + 1u];
            share = share_for(R, v);
            tries = step <= R->rh.pool && step <= share;
            if (tries && tclod_out_of_time(sel))
                return 0;
            pop_candidate(sel, &v, &step);
            R->rh.pass_left--;
            R->rh.value_left -= v;
            if (!(step <= R->rh.pool)) {
                R->rh.limited = 1;
                continue;
            }
            if (!tries) {
                push_candidate(sel, id, v, step);
                continue;
            }
            rose = refine_node(sel, id, v, step, share);
        } else {
            uint32_t id = sel->rh.order[R->k];
            double v = sel->rh.key[R->k];
            if (id < s->node_count || !(v > 0.0) ||
                !(sel->mixed.vars.r[id - s->node_count] < 1.0)) {
                R->k++;
                continue;
            }
            if (tclod_out_of_time(sel))
                return 0;
            sel->stats.iterations++;
            rose = refine_smooth(sel, id - s->node_count, v, share_for(R, v));
            R->rh.value_left -= v;
            R->k++;
        }
        if (rose < 0)
            return -1;
        if (rose) {
            sel->stats.increments++;
            R->rh.refined = 1;
        }
    }
}

/* Cycle 3 begins, unless the search was stopped. */
static void refill_start(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    R->rh.pass_left = 0;
    R->k = sel->rh.order_count;
    R->rh.refined = !sel->stopped;
    R->rh.passes = 0;
}

tclod_status tclod_robin_hood_solve(tclod_selector *sel) {
    tclod_resume *R = &sel->resume;
    int rc = 0;
    if (R->phase == 0) {
        rc = robin_hood_start(sel);
        R->phase = 1;
    }
    if (rc == 0 && R->phase == 1) {
        rc = share_out(sel);
        if (rc == 0 && !sel->paused) {
            refill_start(sel);
            R->phase = 2;
        }
    }
    if (rc == 0 && R->phase == 2 && !sel->paused)
        rc = refill(sel);
    if (rc == 0 && sel->paused)
        return TCLOD_OK;
    if (rc == 0)
        rc = finish(sel);
    tclod_greedy_end(sel);
    if (rc != 0)
        return TCLOD_ERR_CALLBACK;
    if (!sel->stopped)
        sel->stats.stop_reason = R->rh.limited || R->rh.ring_count > 0u || R->rh.smooth_open > 0u ||
                                         sel->stats.dropped_roots > 0u
                                     ? TCLOD_STOP_BUDGET
                                     : TCLOD_STOP_FINEST;
    return sel->failed ? TCLOD_ERR_CALLBACK : TCLOD_OK;
}

/* ---- buffers ------------------------------------------------------------------ */

size_t tclod_rh_buffers(tclod_rh_state *rh, tclod_array *out) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&rh->first, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&rh->kids, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&rh->chain, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&rh->chains, sizeof(tclod_rh_chain), -1};
    out[n++] = (tclod_array){(void **)&rh->child, sizeof(tclod_rh_child), -1};
    out[n++] = (tclod_array){(void **)&rh->order, sizeof(uint32_t), -1};
    out[n++] = (tclod_array){(void **)&rh->key, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&rh->stack, sizeof(tclod_rh_frame), -1};
    out[n++] = (tclod_array){(void **)&rh->level, sizeof(uint8_t), -1};
    return n;
}
