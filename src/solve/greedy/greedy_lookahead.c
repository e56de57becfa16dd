/*
 * TCLOD_SOLVER_GREEDY's lookahead (desc.greedy.lookahead > 0): an increment
 * may replace its node by the best-ratio cut of its subtree a few levels deep
 * (Dinkelbach's method over the subtree's dynamic program, lookahead_key),
 * for benefits whose returns do not diminish; one that does not fit may give
 * way to a cheaper cut of the subtree that does (tclod_greedy_refit_jump).
 * docs/greedy.md explains both; greedy.c takes the increments this queues.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (view.c); eval
 * (evaluate.c); solve (greedy.c).
 */
#include "greedy_internal.h"

#include <math.h>

/* The lookahead's frames: a node and its children still to visit, for the
 * nodes on the way from a cut node down to the deepest level it looks at. */
#define LOOK_FRAMES (TCLOD_MAX_LOOKAHEAD + 1u)
/* Dinkelbach iterations of one key at most (each is a valid increment; they
 * converge in a few). */
#define LOOK_ITERATIONS 16u
/* Relative margin by which a deeper cut's ratio must beat the one before it,
 * and within which two cuts' values tie (the shallower is kept): rounding
 * never makes a deeper cut of an equal ratio win. */
#define LOOK_MARGIN 1e-12

typedef struct look_frame {
    tclod_id id;
    uint32_t next, end; /* its children still to visit: children[next .. end) */
    int blocked;        /* a child is unaffordable: the node stays */
    double b, c;        /* the best cuts of the visited children's subtrees */
} look_frame;

/* One pass of the lookahead's dynamic program over cut node n's subtree, its
 * children at level 1 and nodes down to level lookahead + 1: at multiplier
 * lambda every node m below n either stays or is replaced by the best cuts of
 * its children's subtrees, whichever has the larger b - lambda c (m stays
 * when they are within tol of each other, or when a child is unaffordable);
 * n itself is always replaced. Invisible nodes stay and cost nothing. The
 * benefit and cost of the resulting cut go to *b and *c; with `write` every
 * node visited records in TCLOD_FLAG_REFINE whether it is replaced. Returns 1
 * when a node below n is replaced, 0 when the cut is n's children, -1 on a
 * strict error. No recursion: the frames live on the stack, one per level. */
static int look_pass(tclod_selector *sel, tclod_id n, double weight, double lambda, double tol,
                     int write, double *b, double *c) {
    const tclod_scene *s = sel->scene;
    tclod_node_state *node = sel->node;
    look_frame st[LOOK_FRAMES];
    uint32_t top = 0, limit = sel->desc.greedy.lookahead;
    int deeper = 0;
    st[0].id = n;
    st[0].next = s->child_first[n];
    st[0].end = st[0].next + s->child_count[n];
    st[0].blocked = 0;
    st[0].b = st[0].c = 0.0;
    for (;;) {
        look_frame *f = &st[top];
        if (f->next < f->end) {
            tclod_id m = s->children[f->next++];
            uint32_t first, end;
            if (tclod_evaluate_node(sel, m) != 0)
                return -1;
            if (write)
                sel->flags[m] &= (uint8_t)~TCLOD_FLAG_REFINE;
            if (greedy_unaffordable(node[m].cost)) {
                f->blocked = 1;
                f->next = f->end; /* f stays: its other children do not matter */
                continue;
            }
            first = s->child_first[m];
            end = first + s->child_count[m];
            if (top == limit || first == end || !(node[m].benefit > 0.0)) {
                f->b += node[m].benefit; /* invisible: +0 */
                f->c += node[m].cost;
                continue;
            }
            f = &st[++top];
            f->id = m;
            f->next = first;
            f->end = end;
            f->blocked = 0;
            f->b = f->c = 0.0;
            continue;
        }
        if (top == 0)
            break;
        {
            tclod_id m = f->id;
            double own = weight * node[m].benefit - lambda * node[m].cost;
            double below = weight * f->b - lambda * f->c;
            double scale = weight * (node[m].benefit + f->b) + lambda * (node[m].cost + f->c);
            int refine = !f->blocked && below > own + tol * scale;
            look_frame *up = &st[--top];
            if (write && refine)
                sel->flags[m] |= (uint8_t)TCLOD_FLAG_REFINE;
            deeper |= refine;
            up->b += refine ? f->b : node[m].benefit;
            up->c += refine ? f->c : node[m].cost;
        }
    }
    *b = st[0].b;
    *c = st[0].c;
    return deeper;
}

/* look_pass over a subtree visited before in this solve: every node in it is
 * evaluated, so no callback is called and no strict error can arise. */
static int look_again(tclod_selector *sel, tclod_id n, double weight, double lambda, double tol,
                      int write, double *b, double *c) {
    int rc = look_pass(sel, n, weight, lambda, tol, write, b, c);
    assert(rc >= 0);
    return rc;
}

/* increment_key with lookahead: the increment of cut node n may replace it by
 * the cut of its subtree down to lookahead levels below its children with the
 * best ratio (b(Q) - b(n)) / (c(Q) - c(n)), found by Dinkelbach's method:
 * from lambda = the plain increment's ratio (0 when it gains nothing), the
 * cut Q maximising b(Q) - lambda c(Q) (look_pass) has a ratio above lambda
 * unless lambda is the best; lambda moves to it until it no longer rises. Of
 * the cuts of the best ratio the shallowest is taken (docs/greedy.md). A jump
 * sets TCLOD_FLAG_JUMP on n and TCLOD_FLAG_REFINE on the nodes it passes
 * over; its Δb and Δc go to n's delta_b and delta_c. Returns the key as
 * increment_key. */
static TCLOD_NOINLINE double lookahead_key(tclod_selector *sel, tclod_id n, int *failed) {
    const tclod_scene *s = sel->scene;
    tclod_node_state *node = sel->node;
    uint32_t first = s->child_first[n], end = first + s->child_count[n], i, it;
    double key = tclod_greedy_increment_key(sel, n, failed), best, lambda, at = 0.0, b, c, q;
    int deep = 0, rc;
    sel->flags[n] &= (uint8_t)(TCLOD_FLAG_DROPPED | TCLOD_FLAG_MOVED); /* no jump */
    if (*failed || first == end || !greedy_counts(sel, n) || key == HUGE_VAL ||
        !isfinite(sel->greedy.delta[n].delta_c))
        return key;
    for (i = first; i < end; ++i) {
        tclod_id m = s->children[i];
        if (greedy_unaffordable(node[m].cost))
            return key; /* no increment passes one */
        deep |= node[m].benefit > 0.0 && s->child_count[m] != 0u;
    }
    if (!deep)
        return key;
    best = key;
    lambda = key == key ? key : 0.0;
    deep = 0;
    /* the first pass evaluates the subtree; the others find it evaluated */
    rc = look_pass(sel, n, 1.0, lambda, 0.0, 0, &b, &c);
    if (rc < 0) {
        *failed = 1;
        return (double)NAN;
    }
    for (it = 0; it < LOOK_ITERATIONS; ++it) {
        if (it > 0)
            rc = look_again(sel, n, 1.0, lambda, 0.0, 0, &b, &c);
        q = greedy_ratio_key(b - node[n].benefit, c - node[n].cost);
        if (rc == 0 || q != q || (best == best && !(q > best * (1.0 + LOOK_MARGIN))))
            break;
        best = q;
        at = lambda;
        deep = 1;
        if (q == HUGE_VAL)
            break;
        lambda = q;
    }
    if (!deep)
        return key;
    /* The shallowest cut of the best ratio: ties at lambda = best stay. If
     * rounding leaves that one short of it, the cut found at `at` is taken. */
    rc = best < HUGE_VAL ? look_again(sel, n, 1.0, best, LOOK_MARGIN, 1, &b, &c) : 0;
    q = rc > 0 ? greedy_ratio_key(b - node[n].benefit, c - node[n].cost) : (double)NAN;
    if (!(q >= best * (1.0 - LOOK_MARGIN))) {
        look_again(sel, n, 1.0, at, 0.0, 1, &b, &c);
        q = best;
    }
    sel->greedy.delta[n].delta_b = b - node[n].benefit;
    sel->greedy.delta[n].delta_c = c - node[n].cost;
    sel->flags[n] |= (uint8_t)TCLOD_FLAG_JUMP;
    return q;
}

/* The cheapest increment cut node n may make: what orders it in the by-cost
 * heap, which ends the fill when even it does not fit. A lookahead increment
 * that does not fit may give way to a cheaper cut (tclod_greedy_refit_jump), the cheapest
 * of which is its children's or below them (look_pass without benefits). */
TCLOD_NOINLINE double tclod_greedy_cheapest_jump(tclod_selector *sel, tclod_id n) {
    double b, c;
    look_again(sel, n, 0.0, 1.0, 0.0, 0, &b, &c);
    return c - sel->node[n].cost;
}

TCLOD_NOINLINE int tclod_greedy_queue_looking(tclod_selector *sel, tclod_id n, int append) {
    int failed;
    double key = lookahead_key(sel, n, &failed);
    if (failed)
        return -1;
    tclod_greedy_enqueue_looking(sel, n, key, append);
    return 0;
}

TCLOD_NOINLINE int tclod_greedy_requeue_looking(tclod_selector *sel, tclod_id n, tclod_id *held) {
    int failed;
    double key;
    assert(!sel->resume.greedy.closing); /* the closure takes only increments it queued */
    key = lookahead_key(sel, n, &failed);
    if (failed)
        return -1;
    tclod_greedy_rekey_looking(sel, n, held, key);
    return 0;
}

/* A lookahead increment n that does not fit the room left: its node's
 * increment becomes the cut of its subtree that gains most among those on
 * the upper hull of the cuts' (cost, benefit) that fit (look_pass's
 * multipliers select exactly the hull's vertices). The search runs over the
 * breakpoints between the jump, too dear (a), and the cheapest cut (b): the
 * multiplier of the segment a-b selects a vertex between them, or ties them
 * when they are adjacent and b is the answer. Returns its key, NaN when no
 * cut that fits gains (n's increment unchanged then). */
TCLOD_NOINLINE double tclod_greedy_refit_jump(tclod_selector *sel, tclod_id n) {
    tclod_node_state *node = sel->node;
    double ab = sel->greedy.delta[n].delta_b, ac = sel->greedy.delta[n].delta_c, bb, bc, b, c,
           weight = 0.0, lambda = 1.0;
    double key;
    uint32_t it;
    int rc;
    if (sel->unaffordable != 0)
        return (double)NAN;
    look_again(sel, n, 0.0, 1.0, 0.0, 0, &b, &c); /* the cheapest cut */
    bb = b - node[n].benefit;
    bc = c - node[n].cost;
    if (!tclod_within(sel, sel->cost_sum + bc, greedy_cut_budget(sel)))
        return (double)NAN;
    for (it = 0; it < LOOK_ITERATIONS && ab > bb; ++it) {
        double l = (ab - bb) / (ac - bc), db, dc, gap;
        look_again(sel, n, 1.0, l, 0.0, 0, &b, &c);
        db = b - node[n].benefit;
        dc = c - node[n].cost;
        gap = (db - l * dc) - (bb - l * bc);
        if (!(gap > LOOK_MARGIN * (fabs(db) + fabs(bb) + l * (fabs(dc) + fabs(bc)))))
            break;
        if (tclod_within(sel, sel->cost_sum + dc, greedy_cut_budget(sel))) { /* as increment_fits */
            bb = db;
            bc = dc;
            weight = 1.0;
            lambda = l;
        } else {
            ab = db;
            ac = dc;
        }
    }
    key = greedy_ratio_key(bb, bc);
    if (key != key)
        return key;
    rc = look_again(sel, n, weight, lambda, 0.0, 1, &b, &c);
    sel->greedy.delta[n].delta_b = b - node[n].benefit;
    sel->greedy.delta[n].delta_c = c - node[n].cost;
    sel->flags[n] |= (uint8_t)TCLOD_FLAG_REFIT;
    if (rc == 0)
        sel->flags[n] &= (uint8_t)~TCLOD_FLAG_JUMP;
    return key;
}

/* A lookahead increment (TCLOD_FLAG_JUMP or REFIT): replaces cut node n by
 * the cut its key or tclod_greedy_refit_jump found, walking down through the nodes
 * flagged TCLOD_FLAG_REFINE (frames on the stack, one per level); the other
 * nodes it meets enter the cut. The first with a candidate increment takes
 * n's heap entry (*held). A warm start queues the decrements of the nodes
 * passed over whose children all entered the cut. Below a refit no skipped
 * increment's T(n) is recorded (its path cost is made infinite): a pass that
 * forces it would take n's own increment, not the refit. */
TCLOD_NOINLINE int tclod_greedy_apply_jump(tclod_selector *sel, tclod_id n, int track_dec,
                                           tclod_id *held, double path_b, double path_c) {
    const tclod_scene *s = sel->scene;
    struct {
        tclod_id id;
        uint32_t next, end;
    } st[LOOK_FRAMES];
    uint32_t top = 0;
    if (sel->flags[n] & TCLOD_FLAG_REFIT)
        path_c = HUGE_VAL;
    sel->flags[n] &= (uint8_t)(TCLOD_FLAG_DROPPED | TCLOD_FLAG_MOVED);
    st[0].id = n;
    st[0].next = s->child_first[n];
    st[0].end = st[0].next + s->child_count[n];
    for (;;) {
        if (st[top].next < st[top].end) {
            tclod_id m = s->children[st[top].next++];
            if (sel->flags[m] & TCLOD_FLAG_REFINE) {
                assert(top + 1u < LOOK_FRAMES);
                ++top;
                st[top].id = m;
                st[top].next = s->child_first[m];
                st[top].end = st[top].next + s->child_count[m];
                continue;
            }
            tclod_greedy_cut_add(sel, m);
            sel->path[2u * m] = path_b;
            sel->path[2u * m + 1u] = path_c;
            if (tclod_greedy_requeue(sel, m, held) != 0)
                return -1;
            continue;
        }
        if (track_dec && tclod_greedy_queue_decrement(sel, st[top].id) != 0)
            return -1;
        if (top == 0)
            return 0;
        --top;
    }
}
