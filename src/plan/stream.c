/*
 * Streaming (docs/streaming.md): the solvers draw only resident nodes, and a
 * select that plans lists the loads and evictions for the host's loader.
 *
 * Residency enters the solvers through the evaluation of a node alone
 * (tclod_evaluate_absent): a node that is not resident keeps its benefit but
 * cannot be drawn. Under a replacing parent it costs +inf, the cost no solver
 * ever spends, so the refinement that would draw it is refused and its
 * parent stays drawn; a warm start that held it in its cut takes it out as it
 * takes out any unaffordable node. A root or an additive node's child counts
 * as invisible instead: its hierarchy (its subtree) draws nothing until it
 * arrives, and an additive node's other children join without it. The true
 * values are kept aside for the plan.
 *
 * Layer: plan, which may call core, eval, solve and plan. Calls: core (alloc.c,
 * heap.c, view.c); eval (evaluate.c).
 */
#include "../eval/evaluate.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* ---- buffers ------------------------------------------------------------------ */

size_t tclod_stream_buffers(tclod_stream_state *S, tclod_array *out) {
    size_t n = 0, i, k;
    out[n++] = (tclod_array){(void **)&S->seen, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&S->benefit, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->cost, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->mark, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&S->smooth_mark, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&S->smooth_used, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&S->cap_value, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->size, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->delta, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->queue, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&S->jump, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&S->level, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&S->look, 2 * sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->size_seen, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&S->used, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&S->seen_value, sizeof(double), 0};
    out[n++] = (tclod_array){(void **)&S->touched, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&S->heap.items, sizeof(tclod_heap_entry), -1};
    out[n++] = (tclod_array){(void **)&S->heap.pos, sizeof(uint32_t), 0xff};
    out[n++] = (tclod_array){(void **)&S->ids, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&S->keys, sizeof(double), -1};
    for (i = 0; i < 2; ++i)
        for (k = 0; k < 2; ++k)
            out[n++] = (tclod_array){(void **)&S->list[i][k], sizeof(tclod_stream_item), -1};
    return n;
}

int tclod_stream_wanted(const tclod_selector *sel) {
    const tclod_stream_desc *d = &sel->stream.desc;
    return tclod_scene_streams(sel->scene) || d->max_requests != 0 || d->memory_budget > 0.0;
}

/* ---- the public calls ----------------------------------------------------------- */

const char *tclod_stream_desc_check(const tclod_stream_desc *d) {
    if (!(d->max_request_bytes >= 0.0 && d->max_request_bytes < HUGE_VAL))
        return "d->max_request_bytes must be finite and >= 0";
    if (!(d->memory_budget >= 0.0 && d->memory_budget < HUGE_VAL))
        return "d->memory_budget must be finite and >= 0";
    if (!(d->bytes_in_flight >= 0.0 && d->bytes_in_flight < HUGE_VAL))
        return "d->bytes_in_flight must be finite and >= 0";
    if (!((d->min_yield >= 0.0 && d->min_yield < HUGE_VAL) || d->min_yield == TCLOD_OFF))
        return "d->min_yield must be finite and >= 0, or TCLOD_OFF";
    return NULL;
}

tclod_status tclod_selector_set_stream(tclod_selector *sel, const tclod_stream_desc *d) {
    static const char fn[] = "tclod_selector_set_stream";
    const char *why;
    if (!sel)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    if (!d) {
        memset(&sel->stream.desc, 0, sizeof sel->stream.desc);
        return TCLOD_OK;
    }
    why = tclod_stream_desc_check(d);
    if (why)
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, why);
    sel->stream.desc = *d;
    return TCLOD_OK;
}

static tclod_status stream_list(const tclod_selector *sel, int which,
                                const tclod_stream_item **items, size_t *n) {
    if (!sel || !items || !n)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return TCLOD_ERR_STATE;
    *items = sel->stream.list[which][0];
    *n = sel->stream.count[which][0];
    return TCLOD_OK;
}

tclod_status tclod_selector_requests(const tclod_selector *sel, const tclod_stream_item **items,
                                     size_t *n) {
    return stream_list(sel, 0, items, n);
}

tclod_status tclod_selector_evictions(const tclod_selector *sel, const tclod_stream_item **items,
                                      size_t *n) {
    return stream_list(sel, 1, items, n);
}

/* ---- the plan -------------------------------------------------------------------- */

/* tclod_stream_state.mark: the plan's target (VCUT: in its selection; PASSED:
 * refined on the way to it), what it keeps (KEEP) and asks for (REQUEST);
 * these are cleared when the plan ends (touched[]). LISTED and EVICTED
 * survive it: the node is in the current request (eviction) list. */
enum {
    STREAM_VCUT = 1u,
    STREAM_PASSED = 2u,
    STREAM_KEEP = 4u,
    STREAM_REQUEST = 8u,
    STREAM_LISTED = 16u,
    STREAM_EVICTED = 32u,
    STREAM_TRANSIENT = 15u
};

static void mark(tclod_stream_state *S, tclod_id n, uint8_t bits) {
    if (!(S->mark[n] & STREAM_TRANSIENT))
        S->touched[S->touched_count++] = n;
    S->mark[n] |= bits;
}

static void unmark_all(tclod_stream_state *S) {
    uint32_t i;
    for (i = 0; i < S->touched_count; ++i)
        S->mark[S->touched[i]] &= (uint8_t)~STREAM_TRANSIENT;
    S->touched_count = 0;
    tclod_heap_clear(&S->heap);
}

/* Clears the smooth objects' KEEP marks (keep_all set them on the drawn ones). */
static void unmark_smooth(tclod_selector *sel) {
    const tclod_vars *V = &sel->mixed.vars;
    uint32_t i, k;
    for (i = 0; i < V->count; ++i)
        for (k = V->first[i]; k < V->first[i] + V->size[i]; ++k)
            sel->stream.smooth_mark[sel->scene->smooth_order[k]] &= (uint8_t)~STREAM_KEEP;
}

/* Node n's benefit and cost as if it were resident (a self leaf: its
 * owner's), evaluating it if this solve has not. Returns 0, or -1 when strict
 * mode saw a bad value. */
static int true_values(tclod_selector *sel, tclod_id n, double *b, double *c) {
    const tclod_stream_state *S = &sel->stream;
    tclod_id o = tclod_scene_owner(sel->scene, n);
    if (sel->node[o].stamp != sel->solve_id && tclod_evaluate_node(sel, o) != 0)
        return -1;
    if (S->seen[o] == sel->solve_id) {
        *b = S->benefit[o];
        *c = S->cost[o];
    } else {
        *b = sel->node[o].benefit;
        *c = sel->node[o].cost;
    }
    return 0;
}

/* The size a request for node n counts: the scene's, else the bytes callback's,
 * else the mean size of the resident nodes (1 byte when there is none).
 * Returns 0 with *bytes > 0, 1 when a bad callback value leaves n out, -1
 * when strict mode failed on it. */
static int request_bytes(tclod_selector *sel, tclod_id n, double *bytes) {
    const tclod_scene *s = sel->scene;
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_stream_state *S = &sel->stream;
    double z = (double)s->bytes[n];
    if (S->size_seen[n] == sel->solve_id) { /* asked already (a pass made again) */
        *bytes = S->size[n];
        return *bytes > 0.0 ? 0 : 1;
    }
    S->size_seen[n] = sel->solve_id;
    if (z == 0.0 && cb->bytes) {
        tclod_query *q = &sel->query;
        q->id = n;
        q->screen_area = sel->node[n].area;
        q->distance = sel->node[n].distance;
        q->bounds = s->bounds[n].r >= 0.0 ? tclod_query_bounds(sel, n) : NULL;
        z = cb->bytes(cb->user, q);
        if (!(z >= 0.0 && z < HUGE_VAL)) {
            tclod_bad_value(sel);
            S->size[n] = -1.0;
            return sel->failed ? -1 : 1;
        }
    }
    if (z == 0.0)
        z = s->res_count > 0 ? s->resident_bytes / s->res_count : 0.0;
    *bytes = z > 1.0 ? z : 1.0;
    S->size[n] = *bytes;
    return 0;
}

/* The target's lookahead (docs/streaming.md, the target) mirrors the
 * solver's (docs/greedy.md): with greedy.lookahead L > 0 the increment of a
 * target node n may replace it by the cut of its subtree within L levels
 * below its children of the best ratio, found by Dinkelbach's method over
 * the subtree's dynamic program, on the nodes' values as if resident; and
 * such a jump that does not fit gives way to the cut that gains most among
 * those on the hull that fit. Per node, in tclod_stream_state.jump: */
enum {
    LOOK_JUMP = 0x10u,   /* its increment reaches below its children */
    LOOK_EXPAND = 0x20u, /* below a node whose increment is a jump: replaced by it */
    LOOK_OPEN = 0x40u,   /* while a subtree is looked at: its children are in it */
    LOOK_REFIT = 0x80u   /* its jump gave way to a cut that fits */
};
/* The relative margin by which a deeper cut's ratio must beat a shallower
 * one's, and Dinkelbach's iterations at most (as the solver's). */
#define JUMP_MARGIN 1e-12
#define JUMP_ITERATIONS 16u

/* An increment's key: gain per cost, +inf when it costs nothing. */
static double ratio(double db, double dc) {
    return dc > 0.0 ? db / dc : HUGE_VAL;
}

/* The visible children of node m, as if resident, summed into *b and *c;
 * with `grow`, those with children of their own are appended to S->level at
 * *top. Returns 0, 1 when a child's cost is unaffordable (m cannot be
 * replaced; nothing appended), -1 (strict). */
static int visible_children(tclod_selector *sel, tclod_id m, int grow, uint32_t *top, double *b,
                            double *c) {
    const tclod_scene *s = sel->scene;
    uint32_t i = s->child_first[m], end = i + s->child_count[m], from = *top;
    double sum_b = 0.0, sum_c = 0.0;
    for (; i < end; ++i) {
        tclod_id ch = s->children[i];
        double cb, cc;
        if (true_values(sel, ch, &cb, &cc) != 0)
            return -1;
        if (!(cb > 0.0))
            continue;
        if (isinf(cc)) {
            *top = from;
            return 1;
        }
        sum_b += cb;
        sum_c += cc;
        if (grow && s->child_count[ch] > 0)
            sel->stream.level[(*top)++] = ch;
    }
    *b = sum_b;
    *c = sum_c;
    return 0;
}

/* The subtree target node p's lookahead sees: its visible nodes down to L
 * levels below its children, breadth first, into S->level[S->level_top ..
 * returned end); those whose children are in it carry LOOK_OPEN (not those
 * with an unaffordable child, nor those L + 1 levels down). Returns the end,
 * 0 after a strict error. */
static uint32_t look_nodes(tclod_selector *sel, tclod_id p) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t look = sel->desc.greedy.lookahead, head = S->level_top, tail = head, k, i;
    double b, c;
    S->level[tail++] = p;
    for (k = 0; k <= look + 1u && head < tail; ++k) {
        uint32_t end = tail;
        for (i = head; i < end; ++i) {
            tclod_id m = S->level[i];
            int r = k <= look ? visible_children(sel, m, 1, &tail, &b, &c) : 1;
            if (r < 0)
                return 0;
            S->jump[m] = (uint8_t)(r == 0 && s->child_count[m] > 0 ? LOOK_OPEN : 0u);
        }
        head = end;
    }
    return tail;
}

/* One pass of the lookahead's dynamic program over the subtree of
 * S->level[base] (look_nodes, S->level[base .. end)), children before
 * parents: every open node below the subtree's root either stays or is
 * replaced by its children's best cuts, whichever has the larger
 * weight x b - lambda x c (it stays on a tie); the root itself is always
 * replaced. The sums of the cut go to *b, *c; with `write` the nodes replaced
 * carry LOOK_EXPAND. Returns 1 when a node below the root's children is
 * replaced. */
static int jump_pass(tclod_selector *sel, uint32_t base, uint32_t end, double weight, double lambda,
                     int write, double *b, double *c) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    tclod_id root = S->level[base];
    uint32_t i;
    int deeper = 0;
    for (i = end; i-- > base;) {
        tclod_id m = S->level[i];
        double mb = 0.0, mc = 0.0, cb = 0.0, cc = 0.0;
        uint32_t k, first = s->child_first[m], last = first + s->child_count[m];
        (void)true_values(sel, m, &mb, &mc); /* evaluated by look_nodes */
        if (write)
            S->jump[m] &= (uint8_t)~LOOK_EXPAND;
        if (S->jump[m] & LOOK_OPEN) {
            for (k = first; k < last; ++k) {
                tclod_id ch = s->children[k];
                double xb = 0.0, xc = 0.0;
                (void)true_values(sel, ch, &xb, &xc);
                if (!(xb > 0.0))
                    continue;
                if (s->child_count[ch] > 0 && (S->jump[ch] & LOOK_OPEN)) {
                    xb = S->look[2u * ch];
                    xc = S->look[2u * ch + 1u];
                }
                cb += xb;
                cc += xc;
            }
            if (m == root || weight * cb - lambda * cc > weight * mb - lambda * mc) {
                mb = cb;
                mc = cc;
                if (m != root) {
                    deeper = 1;
                    if (write)
                        S->jump[m] |= LOOK_EXPAND;
                }
            }
        }
        S->look[2u * m] = mb;
        S->look[2u * m + 1u] = mc;
    }
    *b = S->look[2u * root];
    *c = S->look[2u * root + 1u];
    return deeper;
}

/* Target node n's lookahead (b, c its values; *sum_b, *sum_c its children's
 * sums, the plain increment's): from lambda = the plain ratio (0 when it
 * gains nothing), each pass's cut has a better ratio until lambda is the
 * best; the shallowest cut of the best ratio is taken (a last pass at it,
 * ties staying). A jump sets LOOK_JUMP on n, LOOK_EXPAND below it, and its
 * sums in *sum_b, *sum_c. Returns 0, -1 (strict). */
static int target_look(tclod_selector *sel, tclod_id n, double b, double c, double *sum_b,
                       double *sum_c) {
    tclod_stream_state *S = &sel->stream;
    uint32_t base = S->level_top, end, it;
    double B, C, q, best, lambda, at = 0.0;
    int deep = 0;
    if (sel->desc.solver != TCLOD_SOLVER_GREEDY || sel->desc.greedy.lookahead == 0)
        return 0;
    end = look_nodes(sel, n);
    if (end == 0)
        return -1;
    if (end == base + 1u || !(S->jump[n] & LOOK_OPEN))
        return 0; /* nothing below the children to look at */
    best = *sum_b - b > 0.0 ? ratio(*sum_b - b, *sum_c - c) : (double)NAN;
    if (best == HUGE_VAL)
        return 0;
    lambda = best == best ? best : 0.0;
    for (it = 0; it < JUMP_ITERATIONS; ++it) {
        int rc = jump_pass(sel, base, end, 1.0, lambda, 0, &B, &C);
        q = B - b > 0.0 ? ratio(B - b, C - c) : (double)NAN;
        if (rc == 0 || q != q || (best == best && !(q > best * (1.0 + JUMP_MARGIN))))
            break;
        best = q;
        at = lambda;
        deep = 1;
        if (q == HUGE_VAL)
            break;
        lambda = q;
    }
    if (!deep)
        return 0;
    (void)jump_pass(sel, base, end, 1.0, best < HUGE_VAL ? best : at, 1, &B, &C);
    q = B - b > 0.0 ? ratio(B - b, C - c) : (double)NAN;
    if (!(q >= best * (1.0 - JUMP_MARGIN)))
        (void)jump_pass(sel, base, end, 1.0, at, 1, &B, &C);
    S->jump[n] |= LOOK_JUMP;
    *sum_b = B;
    *sum_c = C;
    return 0;
}

/* The increment of target node n: its visible children in its place, or
 * with lookahead the jump target_look finds. Queues it when it gains
 * benefit and no child's cost is unaffordable, nor their sum (costs near
 * DBL_MAX overflow it: inf / inf would key the heap with NaN). Returns 0 or
 * -1 (strict). */
static int target_queue(tclod_selector *sel, tclod_id n, double b, double c) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t top = 0;
    double sum_b = 0.0, sum_c = 0.0, db, dc;
    int r = visible_children(sel, n, 0, &top, &sum_b, &sum_c);
    S->jump[n] = 0;
    if (r != 0)
        return r < 0 ? -1 : 0;
    if (s->child_count[n] > 0 && isfinite(sum_c) && target_look(sel, n, b, c, &sum_b, &sum_c) != 0)
        return -1;
    db = sum_b - b;
    dc = sum_c - c;
    S->delta[2u * n] = db;
    S->delta[2u * n + 1u] = dc;
    if (s->child_count[n] > 0 && db > 0.0 && isfinite(sum_c)) {
        double key = ratio(db, dc);
        if (S->filling && key >= S->closure)
            S->queue[S->tail++] = n;
        else
            tclod_heap_push(&S->heap, n, key);
    }
    return 0;
}

/* Target node p's jump that does not fit the room left: once, it gives way
 * to the cut of p's subtree that gains most among those on the upper hull of
 * the cuts' (cost, benefit) that fit, as the solver's refit (docs/greedy.md),
 * queued again by its own key; nothing when even the cheapest cut does not
 * fit or gain. Returns 0 or -1 (strict). */
static int target_refit(tclod_selector *sel, tclod_id p, double room) {
    tclod_stream_state *S = &sel->stream;
    double b = 0.0, c = 0.0, ab = S->delta[2u * p], ac = S->delta[2u * p + 1u], bb, bc, cb, cc;
    double weight = 0.0, lambda = 1.0;
    uint32_t base = S->level_top, end, it;
    if ((S->jump[p] & (LOOK_JUMP | LOOK_REFIT)) != LOOK_JUMP)
        return 0;
    end = look_nodes(sel, p);
    if (end == 0)
        return -1;
    (void)true_values(sel, p, &b, &c);                      /* evaluated when it was queued */
    (void)jump_pass(sel, base, end, 0.0, 1.0, 0, &cb, &cc); /* the cheapest cut */
    bb = cb - b;
    bc = cc - c;
    if (!(bc <= room))
        return 0;
    for (it = 0; it < JUMP_ITERATIONS && ab > bb; ++it) {
        double l = (ab - bb) / (ac - bc), db, dc, gap;
        (void)jump_pass(sel, base, end, 1.0, l, 0, &cb, &cc);
        db = cb - b;
        dc = cc - c;
        gap = (db - l * dc) - (bb - l * bc);
        if (!(gap > JUMP_MARGIN * (fabs(db) + fabs(bb) + l * (fabs(dc) + fabs(bc)))))
            break;
        if (dc <= room) {
            bb = db;
            bc = dc;
            weight = 1.0;
            lambda = l;
        } else {
            ab = db;
            ac = dc;
        }
    }
    if (!(bb > 0.0))
        return 0;
    (void)jump_pass(sel, base, end, weight, lambda, 1, &cb, &cc);
    S->jump[p] = (uint8_t)(LOOK_JUMP | LOOK_REFIT | LOOK_OPEN);
    S->delta[2u * p] = cb - b;
    S->delta[2u * p + 1u] = cc - c;
    tclod_heap_push(&S->heap, p, ratio(cb - b, cc - c));
    return 0;
}

/* Adds visible node n to the target with the rank its requested ancestors
 * cap its own requests at, and queues its increment. */
static int target_add(tclod_selector *sel, tclod_id n, double b, double c, double cap) {
    tclod_stream_state *S = &sel->stream;
    S->cap_value[n] = cap;
    mark(S, n, STREAM_VCUT);
    return target_queue(sel, n, b, c);
}

/* Appends node n to the request candidates with key `key`. */
static void candidate(tclod_stream_state *S, tclod_id n, double key, uint32_t *count) {
    mark(S, n, STREAM_REQUEST);
    S->ids[*count] = n;
    S->keys[*count] = key;
    ++*count;
}

/* Makes ch, not resident, a member of a group of request candidates ranked
 * together: its bytes join *group_bytes, or a bad size sets *bad (the group
 * is left out). Returns 0 or -1 (strict). */
static int group_join(tclod_selector *sel, tclod_id ch, double *group_bytes, int *bad,
                      uint32_t *count) {
    double z;
    int r = request_bytes(sel, ch, &z);
    if (r < 0)
        return -1;
    if (r > 0) {
        *bad = 1;
    } else {
        candidate(&sel->stream, ch, 0.0, count);
        *group_bytes += z;
    }
    return 0;
}

/* The children of target node p that are not resident, as request candidates
 * ranked by the benefit their arrival adds per byte, at most p's cap: each
 * child of an additive node by its own benefit (they join one by one), the
 * children of a replacing one as a group, by the increment's gain over their
 * bytes together (a child of bad size leaves the group out). Every child's
 * cap becomes its rank (not resident) or p's. Returns 0 or -1 (strict). */
static int request_children(tclod_selector *sel, tclod_id p, double gain, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t i, first = s->child_first[p], end = first + s->child_count[p], group = *count;
    int additive = (s->flags[p] & TCLOD_NODE_ADD) != 0, bad = 0;
    double cap = S->cap_value[p], group_bytes = 0.0;
    for (i = first; i < end; ++i) {
        tclod_id ch = s->children[i];
        double b, c, z;
        int r;
        S->cap_value[ch] = cap;
        if (!(s->flags[ch] & TCLOD_NODE_ABSENT))
            continue; /* resident, or a self leaf (its owner is p) */
        if (true_values(sel, ch, &b, &c) != 0)
            return -1;
        if (!(b > 0.0))
            continue;
        if (!additive) {
            if (group_join(sel, ch, &group_bytes, &bad, count) != 0)
                return -1;
            continue;
        }
        r = request_bytes(sel, ch, &z);
        if (r < 0)
            return -1;
        if (r > 0)
            bad = 1;
        else
            candidate(S, ch, b / z < cap ? b / z : cap, count);
    }
    if (!additive) {
        double rank = gain / group_bytes < cap ? gain / group_bytes : cap;
        for (i = group; i < *count; ++i) {
            if (bad)
                S->mark[S->ids[i]] &= (uint8_t)~STREAM_REQUEST;
            S->keys[i] = rank;
        }
        if (bad)
            *count = group;
    }
    for (i = group; i < *count; ++i)
        S->cap_value[S->ids[i]] = S->keys[i];
    return 0;
}

/* Takes target node p's jump (LOOK_JUMP: the nodes it replaces below p
 * carry LOOK_EXPAND): the nodes it passes over are marked PASSED, those not
 * resident among them and among the cut it reaches form one group of request
 * candidates, ranked by the jump's gain over their bytes (at most p's cap; a
 * node of bad size leaves the group out: the solver could not pass it), and
 * the cut's nodes join the target. Two walks down, with S->level as their
 * queue: the first marks and ranks, the second adds (target_add may look
 * ahead above the queue). Returns 0 or -1 (strict). */
static int target_jump(tclod_selector *sel, tclod_id p, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t base = S->level_top, head = base, tail = base, group = *count, i, j;
    double cap = S->cap_value[p], group_bytes = 0.0, rank, b = 0.0, c = 0.0;
    int bad = 0, r, walk;
    S->mark[p] = (uint8_t)((S->mark[p] & ~STREAM_VCUT) | STREAM_PASSED);
    for (walk = 0; walk < 2; ++walk) {
        head = tail = base;
        S->level[tail++] = p;
        while (head < tail) {
            tclod_id m = S->level[head++];
            uint32_t first = s->child_first[m], last = first + s->child_count[m];
            for (j = first; j < last; ++j) {
                tclod_id ch = s->children[j];
                (void)true_values(sel, ch, &b, &c); /* evaluated by the lookahead */
                if (!(b > 0.0))
                    continue;
                if (s->child_count[ch] > 0 && (S->jump[ch] & LOOK_EXPAND)) {
                    if (walk == 0)
                        mark(S, ch, STREAM_PASSED);
                    S->level[tail++] = ch;
                } else if (walk == 1) {
                    S->level_top = tail;
                    r = target_add(sel, ch, b, c, S->cap_value[ch]);
                    S->level_top = base;
                    if (r != 0)
                        return -1;
                    continue;
                }
                if (walk == 1)
                    continue;
                S->cap_value[ch] = cap;
                if ((s->flags[ch] & TCLOD_NODE_ABSENT) &&
                    group_join(sel, ch, &group_bytes, &bad, count) != 0)
                    return -1;
            }
        }
        if (walk == 1)
            break;
        rank = S->delta[2u * p] / group_bytes < cap ? S->delta[2u * p] / group_bytes : cap;
        for (i = group; i < *count; ++i) {
            if (bad)
                S->mark[S->ids[i]] &= (uint8_t)~STREAM_REQUEST;
            S->keys[i] = rank;
            S->cap_value[S->ids[i]] = rank;
        }
        if (bad)
            *count = group;
    }
    return 0;
}

/* Takes target node p's increment: its visible children replace it, and
 * those not resident become request candidates (deeper with lookahead:
 * target_jump). Returns 0 or -1. */
static int target_take(tclod_selector *sel, tclod_id p, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t k, end = s->child_first[p] + s->child_count[p];
    if (S->jump[p] & LOOK_JUMP)
        return target_jump(sel, p, count);
    S->mark[p] = (uint8_t)((S->mark[p] & ~STREAM_VCUT) | STREAM_PASSED);
    if (request_children(sel, p, S->delta[2u * p], count) != 0)
        return -1;
    for (k = s->child_first[p]; k < end; ++k) {
        tclod_id ch = s->children[k];
        double cb = 0.0, cc = 0.0;
        (void)true_values(sel, ch, &cb, &cc); /* evaluated when p was queued */
        if (cb > 0.0 && target_add(sel, ch, cb, cc, S->cap_value[ch]) != 0)
            return -1;
    }
    return 0;
}

/* One pass of the target (plan_target). Increments keyed at or above
 * S->closure go first, first in first out, the rest by the heap. Returns 0,
 * -1 (strict), or 1 when the first ones did not all fit (the pass must be
 * made again with the heap alone). */
static int target_pass(tclod_selector *sel, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    double budget = sel->frame->budget, total = 0.0, grow = 0.0;
    uint32_t i;
    *count = 0;
    S->target_benefit = 0.0;
    S->head = S->tail = 0;
    S->level_top = 0;
    S->least = HUGE_VAL;
    for (i = 0; i < s->root_count; ++i) {
        tclod_id r = s->roots[i];
        double b, c, z = 1.0, cap = HUGE_VAL;
        int absent = (s->flags[r] & TCLOD_NODE_ABSENT) != 0;
        if (true_values(sel, r, &b, &c) != 0)
            return -1;
        if (!(b > 0.0) || !(total + c <= budget))
            continue;
        if (absent) {
            int k = request_bytes(sel, r, &z);
            if (k < 0)
                return -1;
            if (k > 0)
                continue;
            cap = b / z;
            candidate(S, r, cap, count);
        }
        total += c;
        S->target_benefit += b;
        if (target_add(sel, r, b, c, cap) != 0)
            return -1;
    }
    /* the closure: in any order, as long as its growth fits, it is what the
     * heap would take first (the greedy's closure, docs/greedy.md) */
    while (S->head < S->tail) {
        tclod_id p = S->queue[S->head++];
        double dc = S->delta[2u * p + 1u];
        grow += dc > 0.0 ? dc : 0.0;
        if (!(total + grow <= budget))
            return 1;
        S->target_benefit += S->delta[2u * p];
        if (target_take(sel, p, count) != 0)
            return -1;
    }
    total += grow;
    S->filling = 0; /* from now on every increment goes to the heap */
    while (S->heap.count > 0) {
        double key = S->heap.items[0].key;
        tclod_id p = tclod_heap_pop(&S->heap);
        double dc = S->delta[2u * p + 1u];
        if (!(total + dc <= budget)) {
            int r = target_refit(sel, p, budget - total);
            if (r < 0)
                return -1;
            continue;
        }
        total += dc;
        S->target_benefit += S->delta[2u * p];
        if (key < S->least)
            S->least = key;
        if (target_take(sel, p, count) != 0)
            return -1;
    }
    return 0;
}

/* The plan's target: the greedy ([MB97]) over the tree as if every node were
 * resident, from the roots, within the frame's budget, without lookahead:
 * the increments by benefit gained per cost, each taken when it fits. The
 * nodes it draws or passes through that are not resident become request
 * candidates (ids[0 .. *count), keys their ranks). The increments above the
 * last target's least taken key, with a margin, are taken first in first
 * out, which saves most of the heap's work on a frame like the last; when
 * they do not fit, the pass is made again with the heap alone. Returns 0 or
 * -1. */
static int plan_target(tclod_selector *sel, uint32_t *count) {
    tclod_stream_state *S = &sel->stream;
    int r;
    S->filling = S->closure > 0.0;
    r = target_pass(sel, count);
    if (r == 1) {
        unmark_all(S);
        S->closure *= 4.0; /* a smaller closure next time */
        S->filling = 0;
        r = target_pass(sel, count);
    }
    if (r == 0 && S->filling == 0 && S->least < HUGE_VAL && S->least > 0.0)
        S->closure = 1.25 * S->least; /* the heap's part began below it */
    return r;
}

/* The smooth objects not resident that the mixed solver would draw: the
 * visible ones above the small-detail area, found best first by the screen
 * area of the quadtree's cells, at most max_requests of them, each ranked
 * by its benefit at full resolution per byte (one smooth_benefit call).
 * Appends them to the candidates (ids node_count + smooth id). Returns 0 or
 * -1 (strict). */
static int plan_smooth(tclod_selector *sel, uint32_t *count) {
    const tclod_scene *s = sel->scene;
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_stream_state *S = &sel->stream;
    uint32_t found = 0, want = S->desc.max_requests;
    double mean = s->res_count > 0 ? s->resident_bytes / s->res_count : 0.0;
    float area, distance;
    if (sel->desc.solver != TCLOD_SOLVER_MIXED || !cb->smooth_benefit || !tclod_smooth_priced(cb) ||
        s->smooth_absent_count == 0 || !sel->has_view || s->qt_count == 0 || want == 0)
        return 0;
    tclod_view_cache_measure(&sel->view, s->qt[0].bounds, &area, &distance);
    if (area > 0.0f)
        tclod_heap_push(&S->heap, 0, (double)area);
    while (S->heap.count > 0 && found < want) {
        const tclod_smooth_node *q = &s->qt[tclod_heap_pop(&S->heap)];
        uint32_t i;
        if (q->child_count > 0) {
            for (i = 0; i < q->child_count; ++i) {
                tclod_view_cache_measure(&sel->view, s->qt[q->child + i].bounds, &area, &distance);
                if (area > 0.0f && (double)area >= sel->desc.smooth_cull_area)
                    tclod_heap_push(&S->heap, q->child + i, (double)area);
            }
            continue;
        }
        for (i = q->first; i < q->first + q->count && found < want; ++i) {
            tclod_id id = s->smooth_order[i];
            double b, db, z = (double)s->smooth_bytes[id];
            if (!(s->smooth_flags[id] & TCLOD_NODE_ABSENT))
                continue;
            tclod_view_cache_measure(&sel->view, &s->smooth_bounds[4u * id], &area, &distance);
            if (!(area > 0.0f) || (double)area < sel->desc.smooth_cull_area)
                continue;
            (void)tclod_smooth_call(sel, i, 1, NULL, area, distance, 1.0, &b, &db, NULL, NULL);
            if (sel->failed) /* strict: a bad benefit or slope */
                return -1;
            if (!(b > 0.0))
                continue;
            if (z == 0.0)
                z = mean;
            z = z > 1.0 ? z : 1.0;
            S->size[s->node_count + id] = z;
            S->ids[*count] = s->node_count + id;
            S->keys[*count] = b / z;
            ++*count;
            ++found;
        }
    }
    tclod_heap_clear(&S->heap);
    return 0;
}

/* Remembers node n's benefit per byte when this solve saw it visible. */
static void remember(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    if (sel->node[n].stamp == sel->solve_id && sel->node[n].benefit > 0.0 && s->bytes[n] > 0.0f &&
        !(s->flags[n] & TCLOD_NODE_ABSENT))
        sel->stream.seen_value[n] = sel->node[n].benefit / (double)s->bytes[n];
}

/* Marks node n and its ancestors kept (until one is kept already), and
 * notes them used now. */
static void keep_path(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    for (n = tclod_scene_owner(s, n); n != TCLOD_NONE && !(S->mark[n] & STREAM_KEEP);
         n = s->up[n]) {
        mark(S, n, STREAM_KEEP);
        S->used[n] = S->plans;
        remember(sel, n);
    }
}

/* 1 when cut node n is out of view and its absence would refine nothing
 * back: a root, or a child of an additive node (either counts as invisible
 * when not resident, tclod_evaluate_absent). A replacing parent's culled
 * child must stay: without it the parent could not stay refined. */
static int culled_alone(const tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    tclod_id o = tclod_scene_owner(s, n), p;
    if (o != n || sel->node[n].stamp != sel->solve_id || sel->node[n].benefit > 0.0)
        return 0;
    p = s->parent[n];
    return p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD) != 0;
}

/* What must stay resident: the selection's cut, drawn or culled (a culled
 * node coming into view would otherwise undo its parent's refinement until
 * it came back), the target's and the owner's keep list, each with its
 * ancestors. */
static void keep_all(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    uint32_t i, n = S->touched_count;
    for (i = 0; i < sel->cut_count; ++i) {
        tclod_id id = sel->cut[i];
        if (!(sel->flags[id] & TCLOD_FLAG_DROPPED) && !culled_alone(sel, id))
            keep_path(sel, id);
    }
    for (i = 0; i < n; ++i) /* the target: marked before this began */
        if (S->mark[S->touched[i]] & (STREAM_VCUT | STREAM_PASSED))
            keep_path(sel, S->touched[i]);
    for (i = 0; i < sel->mixed.vars.count; ++i) {
        const tclod_vars *V = &sel->mixed.vars;
        uint32_t k;
        if (V->r[i] > 0.0)
            for (k = V->first[i]; k < V->first[i] + V->size[i]; ++k) {
                S->smooth_mark[s->smooth_order[k]] |= STREAM_KEEP;
                S->smooth_used[s->smooth_order[k]] = S->plans;
            }
    }
    for (i = 0; i < S->keep_count; ++i)
        if (S->keep[i] < s->node_count &&
            (s->flags[tclod_scene_owner(s, S->keep[i])] & (TCLOD_NODE_LIVE | TCLOD_NODE_SELF)))
            keep_path(sel, S->keep[i]);
}

/* The resident node after position *i (0 first) in the scene's list, or
 * when it keeps none (no node was given a size before the solve began) in
 * id order; TCLOD_NONE after the last. */
static tclod_id stream_next_resident(const tclod_scene *s, uint32_t *i) {
    if (s->res_listed)
        return *i < s->res_count ? s->res_list[(*i)++] : TCLOD_NONE;
    while (*i < s->node_count) {
        tclod_id n = (*i)++;
        if (tclod_scene_resident(s, n))
            return n;
    }
    return TCLOD_NONE;
}

/* Queues every resident node and smooth object not kept (of nonzero size)
 * as an eviction candidate, least valuable first. A node's value is the
 * benefit per byte it gave when a solve last saw it visible (this one, if it
 * did): what it is worth when the view comes back to it. One no solve saw,
 * and a smooth object not drawn, are worth less than any of those: the
 * longer since it was last kept, the less. A node is worth more
 * than any resident node below it, which cannot be drawn without it: its
 * descendants go first. */
static void eviction_candidates(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    double *value = S->cap_value; /* free once the target is made */
    uint32_t i;
    tclod_id n;
    for (i = 0; (n = stream_next_resident(s, &i)) != TCLOD_NONE;) {
        remember(sel, n);
        if (S->seen_value[n] > 0.0)
            value[n] = S->seen_value[n];
        else
            value[n] = -1.0 - (double)(S->plans - S->used[n]);
    }
    for (i = 0; (n = stream_next_resident(s, &i)) != TCLOD_NONE;) {
        tclod_id a;
        for (a = s->up[n]; a != TCLOD_NONE && tclod_scene_resident(s, a) && value[a] <= value[n];
             n = a, a = s->up[a])
            value[a] = nextafter(value[n], HUGE_VAL);
    }
    for (i = 0; (n = stream_next_resident(s, &i)) != TCLOD_NONE;) {
        if (!(S->mark[n] & STREAM_KEEP) && s->bytes[n] > 0.0f)
            tclod_heap_append(&S->heap, n, -value[n]); /* a max-heap: the least valuable first */
    }
    for (i = 0; i < s->smooth_count; ++i)
        if ((s->smooth_flags[i] & (TCLOD_NODE_LIVE | TCLOD_NODE_ABSENT)) == TCLOD_NODE_LIVE &&
            !(S->smooth_mark[i] & STREAM_KEEP) && s->smooth_bytes[i] > 0.0f)
            tclod_heap_append(&S->heap, s->node_count + i,
                              1.0 + (double)(S->plans - S->smooth_used[i]));
    tclod_heap_build(&S->heap);
}

static void add_item(tclod_stream_item *list, uint32_t *count, tclod_id id, uint32_t flags,
                     double bytes, double value) {
    tclod_stream_item *it = &list[(*count)++];
    it->id = id;
    it->flags = flags;
    it->bytes = bytes;
    it->value = value;
}

/* Lists the least valuable eviction candidate; returns its bytes. */
static double evict_one(tclod_selector *sel) {
    tclod_stream_state *S = &sel->stream;
    double key = S->heap.items[0].key;
    const tclod_scene *s = sel->scene;
    tclod_id n = tclod_heap_pop(&S->heap);
    if (n >= s->node_count) { /* a smooth object */
        n -= s->node_count;
        add_item(S->list[1][1], &S->count[1][1], n,
                 TCLOD_STREAM_SMOOTH |
                     ((S->smooth_mark[n] & STREAM_EVICTED) ? TCLOD_STREAM_LISTED : 0u),
                 (double)s->smooth_bytes[n], 0.0);
        return (double)s->smooth_bytes[n];
    }
    add_item(S->list[1][1], &S->count[1][1], n,
             (S->mark[n] & STREAM_EVICTED) ? TCLOD_STREAM_LISTED : 0u, (double)s->bytes[n],
             -key > 0.0 ? -key : 0.0);
    return (double)s->bytes[n];
}

/* The request candidates ids[0 .. n), keys[0 .. n) as a binary max-heap:
 * higher rank first, equal ranks by smaller id. Only the ones listed are
 * popped: O(n + listed log n), not a sort of all of them. */
static int candidate_before(const tclod_stream_state *S, uint32_t a, uint32_t b) {
    return S->keys[a] > S->keys[b] || (S->keys[a] == S->keys[b] && S->ids[a] < S->ids[b]);
}

static void candidate_swap(tclod_stream_state *S, uint32_t a, uint32_t b) {
    tclod_id id = S->ids[a];
    double key = S->keys[a];
    S->ids[a] = S->ids[b];
    S->keys[a] = S->keys[b];
    S->ids[b] = id;
    S->keys[b] = key;
}

static void candidate_sift(tclod_stream_state *S, uint32_t i, uint32_t n) {
    for (;;) {
        uint32_t best = i, l = 2u * i + 1u, r = l + 1u;
        if (l < n && candidate_before(S, l, best))
            best = l;
        if (r < n && candidate_before(S, r, best))
            best = r;
        if (best == i)
            return;
        candidate_swap(S, i, best);
        i = best;
    }
}

static void candidates_heapify(tclod_stream_state *S, uint32_t n) {
    uint32_t i;
    for (i = n / 2u; i-- > 0;)
        candidate_sift(S, i, n);
}

/* Moves the best of the n in the heap to ids[n - 1] (keys[n - 1]) and
 * returns it. */
static tclod_id candidates_pop(tclod_stream_state *S, uint32_t n) {
    candidate_swap(S, 0, n - 1u);
    candidate_sift(S, 0, n - 1u);
    return S->ids[n - 1u];
}

/* The size node n counts in the target: its own, or the resident nodes'
 * mean when it has none. */
static double target_bytes(const tclod_scene *s, tclod_id n) {
    double z = (double)s->bytes[tclod_scene_owner(s, n)];
    return z > 0.0 ? z : (s->res_count > 0 ? s->resident_bytes / s->res_count : 0.0);
}

/* Leaves out the request candidates that would bring less benefit per byte
 * than the desc's min_yield times what the target draws brings on average:
 * loads that would spend the link and the memory on what adds little (the
 * last few per cent of a view that takes most of its bytes). Of those below
 * that floor, the best are kept again until the ones left out would add at
 * most TCLOD_STREAM_YIELD_LOSS of the target's benefit together (a
 * candidate adds its rank times its bytes): where the benefit per byte is
 * spread wide (point clouds, small scenes seen whole), the floor alone would
 * leave a view short of what it needs for good. A node's rank is capped by
 * its requested ancestors', so a node left out leaves out what lies below
 * it. Returns how many are left (compacted in place). */
static uint32_t worth_loading(tclod_selector *sel, uint32_t count) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    double yield = S->desc.min_yield == 0.0 ? TCLOD_STREAM_MIN_YIELD : S->desc.min_yield;
    double bytes = 0.0, floor, loss;
    uint32_t i, low = 0, drop;
    if (yield <= 0.0)
        return count;
    for (i = 0; i < S->touched_count; ++i)
        if (S->mark[S->touched[i]] & STREAM_VCUT)
            bytes += target_bytes(s, S->touched[i]);
    if (!(bytes > 0.0))
        return count;
    floor = yield * S->target_benefit / bytes;
    for (i = 0; i < count; ++i) /* those below the floor to the front */
        if (S->keys[i] < floor)
            candidate_swap(S, i, low++);
    /* sorted ascending (a heap sort: the best goes last), then left out from
     * the least while their gains fit the loss */
    candidates_heapify(S, low);
    for (i = low; i > 1; --i)
        (void)candidates_pop(S, i);
    loss = TCLOD_STREAM_YIELD_LOSS * S->target_benefit;
    for (drop = 0; drop < low; ++drop) {
        loss -= S->keys[drop] * S->size[S->ids[drop]];
        if (loss < 0.0)
            break;
    }
    for (i = drop; i < count; ++i) {
        S->ids[i - drop] = S->ids[i];
        S->keys[i - drop] = S->keys[i];
    }
    return count - drop;
}

/* Makes the eviction candidates the first time the plan needs room. */
static void need_room(tclod_selector *sel, int *built) {
    if (!*built)
        eviction_candidates(sel);
    *built = 1;
}

/* The lists: the candidates ranked, those that fit the desc's caps, and the
 * evictions that make room for them. */
static void plan_lists(tclod_selector *sel, uint32_t candidates) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    const tclod_stream_desc *d = &S->desc;
    int memory = d->memory_budget > 0.0, built = 0;
    double room = d->memory_budget - s->resident_bytes - d->bytes_in_flight, listed = 0.0;
    uint32_t i;
    if (memory)
        keep_all(sel); /* every plan: it also dates what the drawn nodes use */
    if (memory && room < 0.0) {
        need_room(sel, &built);
        while (room < 0.0 && S->heap.count > 0)
            room += evict_one(sel);
        if (room < 0.0) {
            sel->stats.notes |= TCLOD_NOTE_MEMORY_SHORT;
            return;
        }
    }
    candidates = worth_loading(sel, candidates);
    candidates_heapify(S, candidates);
    for (i = 0; i < candidates && S->count[0][1] < d->max_requests; ++i) {
        tclod_id n = candidates_pop(S, candidates - i); /* now at ids[candidates - i - 1] */
        double rank = S->keys[candidates - i - 1];
        double z = S->size[n];
        if (d->max_request_bytes > 0.0 && S->count[0][1] > 0 && listed + z > d->max_request_bytes)
            break;
        if (memory && room < z)
            need_room(sel, &built);
        while (memory && room < z && S->heap.count > 0 &&
               (-S->heap.items[0].key < 0.0 || -S->heap.items[0].key < rank))
            room += evict_one(sel);
        if (memory && room < z) {
            if (S->count[0][1] == 0 && S->heap.count == 0) /* nothing left to free */
                sel->stats.notes |= TCLOD_NOTE_MEMORY_SHORT;
            break;
        }
        room -= z;
        listed += z;
        if (n >= s->node_count) /* a smooth object */
            add_item(S->list[0][1], &S->count[0][1], n - s->node_count,
                     TCLOD_STREAM_SMOOTH |
                         ((S->smooth_mark[n - s->node_count] & STREAM_LISTED) ? TCLOD_STREAM_LISTED
                                                                              : 0u),
                     z, rank);
        else
            add_item(S->list[0][1], &S->count[0][1], n,
                     ((S->mark[n] & STREAM_LISTED) ? TCLOD_STREAM_LISTED : 0u) |
                         ((s->flags[n] & TCLOD_NODE_UNEXPANDED) ? TCLOD_STREAM_EXPAND : 0u),
                     z, rank);
    }
}

/* The marks of a listed node or smooth object. */
static uint8_t *stream_mark(tclod_stream_state *S, const tclod_stream_item *it) {
    return (it->flags & TCLOD_STREAM_SMOOTH) ? &S->smooth_mark[it->id] : &S->mark[it->id];
}

/* Moves the persistent marks from the current lists to the planned ones. */
static void relist(tclod_stream_state *S) {
    static const uint8_t bit[2] = {STREAM_LISTED, STREAM_EVICTED};
    uint32_t i, k;
    for (k = 0; k < 2; ++k) {
        for (i = 0; i < S->count[k][0]; ++i)
            *stream_mark(S, &S->list[k][0][i]) &= (uint8_t)~bit[k];
        for (i = 0; i < S->count[k][1]; ++i)
            *stream_mark(S, &S->list[k][1][i]) |= bit[k];
    }
}

int tclod_stream_plan(tclod_selector *sel) {
    tclod_stream_state *S = &sel->stream;
    const tclod_stream_desc *d = &S->desc;
    uint32_t candidates = 0;
    int over;
    S->count[0][1] = S->count[1][1] = 0;
    if (!S->seen)
        return 0; /* no streaming buffers: nothing to plan (tclod_stream_wanted) */
    over = d->memory_budget > 0.0 &&
           sel->scene->resident_bytes + d->bytes_in_flight > d->memory_budget;
    if (!over && (d->max_requests == 0 || !tclod_scene_streams(sel->scene))) {
        relist(S);
        return 0;
    }
    S->plans++;
    /* a solve that met no node short of residency drew what the target would:
     * nothing to request there */
    if ((S->absent_seen > 0 && plan_target(sel, &candidates) != 0) ||
        plan_smooth(sel, &candidates) != 0) {
        unmark_all(S);
        S->count[0][1] = S->count[1][1] = 0;
        return -1;
    }
    plan_lists(sel, candidates);
    unmark_smooth(sel);
    unmark_all(S);
    relist(S);
    sel->stats.request_bytes = 0.0;
    sel->stats.eviction_bytes = 0.0;
    {
        uint32_t i;
        for (i = 0; i < S->count[0][1]; ++i)
            sel->stats.request_bytes += S->list[0][1][i].bytes;
        for (i = 0; i < S->count[1][1]; ++i)
            sel->stats.eviction_bytes += S->list[1][1][i].bytes;
    }
    return 0;
}

void tclod_stream_commit(tclod_selector *sel) {
    tclod_stream_state *S = &sel->stream;
    int i;
    for (i = 0; i < 2; ++i) {
        tclod_stream_item *t = S->list[i][0];
        S->list[i][0] = S->list[i][1];
        S->list[i][1] = t;
        S->count[i][0] = S->count[i][1];
        S->count[i][1] = 0;
    }
    sel->stats.requests = S->count[0][0];
    sel->stats.evictions = S->count[1][0];
}
