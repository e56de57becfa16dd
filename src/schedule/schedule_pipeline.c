/*
 * The predictive geomorph scheduler, its pipeline ([GEO §3.3-3.4, §4.2-4.5];
 * docs/scheduler.md): the relations between cuts (meet, regions), the predicted
 * costs of the states a region morphs through, residency under streaming, the
 * plan of an interval, the draw list of a frame, and the update that runs the
 * pipeline. The model it follows is described at the top of schedule.c.
 *
 * Layer: schedule, which may call every layer. Calls: core (alloc.c, scene.c,
 * scene_prepare.c, view.c); plan (stream.c); select (selector.c); schedule
 * (calib.c, schedule.c).
 */
#include "schedule_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* ---- relations between cuts ---------------------------------------------------------------- */

/* Whether a proper ancestor of n carries mark e. */
static int below_mark(const tclod_scheduler *sch, const uint32_t *mark, uint32_t e, tclod_id n) {
    const tclod_id *parent = sch->scene->parent;
    for (n = parent[n]; n != TCLOD_NONE; n = parent[n])
        if (mark[n] == e)
            return 1;
    return 0;
}

/* out = meet(a, b): the nodes of a and b with no proper ancestor in a or b;
 * per part of the hierarchies the coarser of the two cuts. Returns the
 * count. */
static uint32_t meet(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                     uint32_t nb, tclod_id *out) {
    uint32_t e = tclod_schedule_next_epoch(sch), i, n = 0;
    for (i = 0; i < na; ++i)
        sch->mark_a[a[i]] = e;
    for (i = 0; i < nb; ++i)
        sch->mark_a[b[i]] = e;
    for (i = 0; i < na + nb; ++i) {
        tclod_id v = i < na ? a[i] : b[i - na];
        if (sch->done[v] == e)
            continue;
        sch->done[v] = e;
        if (!below_mark(sch, sch->mark_a, e, v))
            out[n++] = v;
    }
    return n;
}

/* The region of node v: the region of its nearest ancestor-or-self that is a
 * region root (marked e), or TCLOD_NONE. */
static uint32_t region_at(const tclod_scheduler *sch, uint32_t e, tclod_id v) {
    const tclod_id *parent = sch->scene->parent;
    for (; v != TCLOD_NONE; v = parent[v])
        if (sch->region_mark[v] == e)
            return sch->region_of[v];
    return TCLOD_NONE;
}

/* Cuts the hierarchies into the regions of meet(lists 0 and 1), each rooted
 * at a node of that meet, and buckets the nodes of the three lists by region
 * (region_list() gives them back). Marks the members of list 0 with mark_b and
 * those of list 1 with mark_c, epoch returned. */
static uint32_t schedule_partition(tclod_scheduler *sch, const tclod_id *const lists[3],
                                   const uint32_t sizes[3]) {
    uint32_t roots = meet(sch, lists[0], sizes[0], lists[1], sizes[1], sch->list_r);
    uint32_t e = tclod_schedule_next_epoch(sch), r, l, i, total = 0;
    tclod_schedule_writable_plan(sch);
    for (i = 0; i < sizes[0]; ++i)
        sch->mark_b[lists[0][i]] = e;
    for (i = 0; i < sizes[1]; ++i)
        sch->mark_c[lists[1][i]] = e;
    for (r = 0; r < roots; ++r) {
        tclod_id q = sch->list_r[r];
        sch->region_mark[q] = e;
        sch->region_of[q] = r;
        PLAN(sch)->regions[r].root = q;
        PLAN(sch)->regions[r].kind = REGION_STATIC;
        PLAN(sch)->regions[r].depth = 0;
        sch->counts[3u * r] = sch->counts[3u * r + 1u] = sch->counts[3u * r + 2u] = 0;
    }
    for (l = 0; l < 3u; ++l)
        for (i = 0; i < sizes[l]; ++i) {
            r = region_at(sch, e, lists[l][i]);
            if (r != TCLOD_NONE)
                sch->counts[3u * r + l]++;
        }
    for (r = 0; r < roots; ++r) { /* counts become each list's write position */
        uint32_t c0 = sch->counts[3u * r], c1 = sch->counts[3u * r + 1u];
        uint32_t c2 = sch->counts[3u * r + 2u];
        PLAN(sch)->regions[r].first = total;
        PLAN(sch)->regions[r].count = c0 + c1 + c2;
        sch->counts[3u * r] = total;
        sch->counts[3u * r + 1u] = total + c0;
        sch->counts[3u * r + 2u] = total + c0 + c1;
        total += c0 + c1 + c2;
    }
    for (l = 0; l < 3u; ++l)
        for (i = 0; i < sizes[l]; ++i) {
            r = region_at(sch, e, lists[l][i]);
            if (r != TCLOD_NONE)
                PLAN(sch)->nodes[sch->counts[3u * r + l]++] = lists[l][i];
        }
    PLAN(sch)->region_count = roots;
    return e;
}

/* The nodes of list l in region r after schedule_partition(): PLAN(sch)->nodes[*first ..
 * *first + *count). */
static void region_list(const tclod_scheduler *sch, uint32_t r, uint32_t l, uint32_t *first,
                        uint32_t *count) {
    uint32_t start = l == 0u ? PLAN(sch)->regions[r].first : sch->counts[3u * r + l - 1u];
    *first = start;
    *count = sch->counts[3u * r + l] - start;
}

/* Whether two node lists hold the same set. */
static int same_nodes(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                      uint32_t nb) {
    uint32_t e, i;
    if (na != nb)
        return 0;
    e = tclod_schedule_next_epoch(sch);
    for (i = 0; i < na; ++i)
        sch->done[a[i]] = e;
    for (i = 0; i < nb; ++i)
        if (sch->done[b[i]] != e)
            return 0;
    return 1;
}

/* Counts one level change, morphed or switched. */
static void count_change(tclod_scheduler *sch, int morphed) {
    sch->p.stats.changes++;
    if (morphed)
        sch->p.stats.morphs++;
    else
        sch->p.stats.pops++;
}

/* Counts the level changes of a switch from cut a to cut b: the regions in
 * which a drawn node gives way to drawn nodes below it, or the reverse.
 * Overwrites the plan's regions. */
static void count_switches(tclod_scheduler *sch, const tclod_id *a, uint32_t na, const tclod_id *b,
                           uint32_t nb) {
    const tclod_id *lists[3];
    uint32_t sizes[3], e, r;
    lists[0] = a;
    lists[1] = lists[2] = b;
    sizes[0] = na;
    sizes[1] = sizes[2] = nb;
    e = schedule_partition(sch, lists, sizes);
    for (r = 0; r < PLAN(sch)->region_count; ++r) {
        tclod_id q = PLAN(sch)->regions[r].root;
        uint32_t f, n0, n1;
        int in_a = sch->mark_b[q] == e, in_b = sch->mark_c[q] == e;
        region_list(sch, r, 0, &f, &n0);
        region_list(sch, r, 1, &f, &n1);
        if ((in_a && !in_b && n1 > 0) || (in_b && !in_a && n0 > 0))
            count_change(sch, 0);
    }
}

/* ---- predicted costs ------------------------------------------------------------------------- */

static void memo_set(tclod_scheduler *sch, tclod_id n, double cost) {
    plan_state *P = PLAN(sch);
    P->memo_mark[n] = P->memo_epoch;
    P->memo_cost[n] = cost;
    P->memo_visible[n] = 1;
}

/* Counts a bad value from the scheduler's own evaluations; strict mode fails
 * the update. */
static void bad_value(tclod_scheduler *sch) {
    sch->p.stats.invalid_values++;
    if (sch->sel->desc.strict)
        sch->failed = 1;
}

/* Node n's cost for the latest selection's views, from the callbacks;
 * *visible is 0 (and the cost 0) when those views do not see it. */
static double predicted_cost(tclod_scheduler *sch, tclod_id n, int *visible) {
    const tclod_scene *s = sch->scene;
    tclod_query q;
    tclod_bounds qb;
    double benefit, cost = 0.0;
    memset(&q, 0, sizeof q);
    q.id = tclod_scene_owner(s, n);
    q.count = 1;
    q.view = &sch->sv.conservative;
    q.screen_area = q.distance = -1.0f;
    tclod_scene_public_bounds(s, q.id, &qb);
    q.bounds = qb.kind != TCLOD_BOUNDS_NONE ? &qb : NULL;
    if (q.bounds) {
        double d;
        tclod_view_measure_bounds(&sch->sv.conservative_cache, &s->bounds[n], s->boxes,
                                  &q.screen_area, &d);
        q.distance = (float)d;
    }
    benefit = tclod_schedule_wrap_benefit(sch, &q);
    if (schedule_value_bad(benefit)) {
        bad_value(sch);
        benefit = 0.0;
    }
    if (benefit > 0.0) {
        cost = tclod_schedule_wrap_cost(sch, &q);
        if (schedule_value_bad(cost)) {
            bad_value(sch);
            cost = HUGE_VAL;
        }
    }
    *visible = benefit > 0.0;
    return cost;
}

/* The predicted cost of node n for the current plan: the cost a landed
 * selection drew it with, else predicted_cost(); *visible as there. */
static double memo(tclod_scheduler *sch, tclod_id n, int *visible) {
    plan_state *P = PLAN(sch);
    if (P->memo_mark[n] != P->memo_epoch) {
        int vis;
        P->memo_cost[n] = predicted_cost(sch, n, &vis);
        P->memo_mark[n] = P->memo_epoch;
        P->memo_visible[n] = (uint8_t)vis;
    }
    *visible = P->memo_visible[n];
    return P->memo_cost[n];
}

/* The ancestor of v at depth `depth` (<= v's). */
static tclod_id ancestor_at(const tclod_scheduler *sch, tclod_id v, uint32_t depth) {
    while (sch->depth[v] > depth)
        v = sch->scene->parent[v];
    return v;
}

/* The nodes a morph region draws at level position s in [0, depth]: the
 * coarse node at 0, the fine side at depth, and in between, with
 * k = floor(s), the fine nodes at relative depth <= k and the distinct
 * ancestors at relative depth k + 1 of the others, those geomorphed from their
 * parents with weight s - k. Calls emit(sch, fine, coarse, weight, ctx) for
 * each visible one. */
typedef void (*emit_fn)(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                        void *ctx);

static void morph_state(tclod_scheduler *sch, const region *R, double s, emit_fn emit, void *ctx) {
    uint32_t base = sch->depth[R->root], k, i, stamp;
    float w;
    int vis;
    const plan_state *P = PLAN(sch);
    if (s <= 0.0) {
        memo(sch, R->root, &vis);
        if (vis)
            emit(sch, R->root, R->root, 1.0f, ctx);
        return;
    }
    if (s >= (double)R->depth) {
        k = R->depth;
        w = 1.0f;
    } else {
        k = (uint32_t)s;
        w = (float)(s - (double)k);
    }
    stamp = tclod_schedule_next_epoch(sch);
    for (i = 0; i < R->count; ++i) {
        tclod_id leaf = P->nodes[R->first + i], m;
        if (sch->depth[leaf] - base <= k) {
            memo(sch, leaf, &vis);
            if (vis)
                emit(sch, leaf, leaf, 1.0f, ctx);
            continue;
        }
        m = ancestor_at(sch, leaf, base + k + 1u);
        if (sch->done[m] == stamp)
            continue;
        sch->done[m] = stamp;
        memo(sch, m, &vis);
        if (vis)
            emit(sch, m, sch->scene->parent[m], w, ctx);
    }
}

static void add_cost(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                     void *ctx) {
    int vis;
    (void)coarse;
    (void)weight;
    *(double *)ctx += memo(sch, fine, &vis);
}

/* ---- residency ------------------------------------------------------------------------------- */

static void make_plan(tclod_scheduler *sch);

/* Whether every node a morph region passes through is resident: q, its fine
 * side and the nodes between them. The levels in turn draw each of them, and
 * the coarse end of every morph item is one of them. */
static int morph_resident(tclod_scheduler *sch, const region *R) {
    const tclod_scene *s = sch->scene;
    const plan_state *P = PLAN(sch);
    uint32_t stamp, i;
    if (tclod_scene_absent(s, R->root))
        return 0;
    stamp = tclod_schedule_next_epoch(sch);
    for (i = 0; i < R->count; ++i) {
        tclod_id m;
        for (m = P->nodes[R->first + i]; m != R->root && sch->done[m] != stamp; m = s->parent[m]) {
            sch->done[m] = stamp;
            if (tclod_scene_absent(s, m))
                return 0;
        }
    }
    return 1;
}

/* The regions of the plan in use that draw a node not resident at some point
 * of the interval. */
static uint32_t absent_regions(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    const plan_state *P = PLAN(sch);
    uint32_t r, i, hits = 0;
    for (r = 0; r < P->region_count; ++r) {
        const region *R = &P->regions[r];
        int ok = 1;
        if (R->kind == REGION_STATIC)
            for (i = 0; i < R->count && ok; ++i)
                ok = !tclod_scene_absent(s, P->nodes[R->first + i]);
        else
            ok = morph_resident(sch, R);
        hits += !ok;
    }
    return hits;
}

/* What a landed selection draws in place of node n, which is not resident:
 * what a selector would draw, the nearest resident ancestor through
 * replacing parents; TCLOD_NONE (nothing) past a root or an additive node,
 * whose child's hierarchy draws nothing until it arrives. */
static tclod_id fallback(const tclod_scene *s, tclod_id n) {
    for (;;) {
        tclod_id p = s->parent[n];
        if (p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD))
            return TCLOD_NONE;
        if (!tclod_scene_absent(s, p))
            return p;
        n = p;
    }
}

/* Replaces each node of generation g that is not resident by its fallback
 * (costed for the latest selection's views) and takes out what lies below a
 * fallback. Returns whether g changed. */
static int repair(tclod_scheduler *sch, uint32_t g) {
    const tclod_scene *s = sch->scene;
    generation *G = &sch->gen[g];
    uint32_t i, k, e;
    for (i = 0; i < G->count && !tclod_scene_absent(s, G->ids[i]); ++i)
        ;
    if (i == G->count)
        return 0;
    e = tclod_schedule_next_epoch(sch);
    for (; i < G->count; ++i) {
        tclod_id f;
        int vis;
        if (!tclod_scene_absent(s, G->ids[i]))
            continue;
        f = fallback(s, G->ids[i]);
        G->ids[i] = f;
        G->cost[i] = 0.0;
        if (f != TCLOD_NONE && sch->mark_a[f] != e) { /* its first place: costed */
            sch->mark_a[f] = e;
            G->cost[i] = predicted_cost(sch, f, &vis);
        }
    }
    for (i = k = 0; i < G->count; ++i) {
        tclod_id n = G->ids[i];
        if (n == TCLOD_NONE || sch->done[n] == e || below_mark(sch, sch->mark_a, e, n))
            continue;
        sch->done[n] = e;
        G->ids[k] = n;
        G->cost[k++] = G->cost[i];
    }
    G->count = k;
    return 1;
}

/* After the scene's residency changed: the landed selections the pipeline
 * draws from lose the nodes not resident (repair), and a plan that would
 * draw one of them is made again, each region that drew one switching at
 * once (a pop). The changes of the interval are not counted again. */
static void sync_residency(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    uint32_t hits;
    if (sch->p.residency_version == s->residency_version)
        return;
    sch->p.residency_version = s->residency_version;
    if (!tclod_scene_streams(s))
        return;
    repair(sch, sch->p.prev);
    repair(sch, sch->p.cur);
    repair(sch, sch->p.next);
    if (sch->p.ready)
        repair(sch, sch->p.landing);
    hits = absent_regions(sch);
    if (hits > 0) {
        tclod_scheduler_stats kept = sch->p.stats;
        make_plan(sch);
        sch->p.stats.changes = kept.changes + hits;
        sch->p.stats.morphs = kept.morphs;
        sch->p.stats.pops = kept.pops + hits;
    }
}

/* Names the nodes of the landed selections the pipeline draws from as the
 * ones the selector's plan keeps, with their ancestors (which hold every node
 * a morph draws, at either end), for the selector call that follows (then
 * unkeep). Only a plan with a memory budget evicts. */
static void keep_landed(tclod_scheduler *sch) {
    tclod_stream_state *S = &sch->sel->stream;
    uint32_t slots[4], count = 3, e, k, i, n = 0;
    if (!(S->desc.memory_budget > 0.0))
        return;
    slots[0] = sch->p.prev;
    slots[1] = sch->p.cur;
    slots[2] = sch->p.next;
    if (sch->p.ready)
        slots[count++] = sch->p.landing;
    e = tclod_schedule_next_epoch(sch);
    for (k = 0; k < count; ++k)
        for (i = 0; i < sch->gen[slots[k]].count; ++i) {
            tclod_id id = sch->gen[slots[k]].ids[i];
            if (sch->done[id] != e) {
                sch->done[id] = e;
                sch->list_r[n++] = id;
            }
        }
    S->keep = sch->list_r;
    S->keep_count = n;
}

static void unkeep(tclod_scheduler *sch) {
    sch->sel->stream.keep = NULL;
    sch->sel->stream.keep_count = 0;
}

/* ---- plans ----------------------------------------------------------------------------------- */

/* Makes region r of the plan: q alone, or a morph from its X side (list 0) to
 * its Y side (list 1) -- when every state it passes through costs no more
 * than S_j's nodes in it (list 2) and every node it draws is resident; else
 * S_j's nodes as they are. */
static void plan_region(tclod_scheduler *sch, uint32_t r, uint32_t e) {
    region *R = &PLAN(sch)->regions[r], plan = *R;
    tclod_id q = R->root;
    uint32_t fx, nx, fy, ny, fc, nc, i;
    int in_x = sch->mark_b[q] == e, in_y = sch->mark_c[q] == e, vis;
    double allowed = 0.0, worst = 0.0;
    region_list(sch, r, 0, &fx, &nx);
    region_list(sch, r, 1, &fy, &ny);
    region_list(sch, r, 2, &fc, &nc);
    for (i = 0; i < nc; ++i)
        allowed += memo(sch, PLAN(sch)->nodes[fc + i], &vis);
    if (in_x && !in_y && ny > 0) {
        plan.kind = REGION_UP;
        plan.first = fy;
        plan.count = ny;
    } else if (in_y && !in_x && nx > 0) {
        plan.kind = REGION_DOWN;
        plan.first = fx;
        plan.count = nx;
    } else { /* q alone: in both, or appearing, or disappearing */
        plan.kind = REGION_STATIC;
        plan.first = in_x ? fx : fy;
        plan.count = 1;
    }
    if (plan.kind == REGION_STATIC) {
        worst = memo(sch, q, &vis);
    } else {
        uint32_t k;
        plan.depth = 0;
        for (i = 0; i < plan.count; ++i) {
            uint32_t rel = sch->depth[PLAN(sch)->nodes[plan.first + i]] - sch->depth[q];
            if (rel > plan.depth)
                plan.depth = rel;
        }
        /* the states: q, each level's morph, the fine side */
        for (k = 0; k <= plan.depth + 1u && worst <= allowed; ++k) {
            double c = 0.0;
            morph_state(sch, &plan,
                        k == 0u           ? 0.0
                        : k <= plan.depth ? (double)k - 0.5
                                          : (double)plan.depth,
                        add_cost, &c);
            if (c > worst)
                worst = c;
        }
    }
    if (worst <= allowed && (plan.kind == REGION_STATIC || !tclod_scene_streams(sch->scene) ||
                             morph_resident(sch, &plan))) {
        *R = plan;
        if (plan.kind != REGION_STATIC)
            count_change(sch, 1);
        return;
    }
    /* too dear somewhere, or not resident: S_j's nodes, switched to at the
     * start and from at the end */
    if (nx > 0 && nc > 0 && !same_nodes(sch, PLAN(sch)->nodes + fx, nx, PLAN(sch)->nodes + fc, nc))
        count_change(sch, 0);
    if (ny > 0 && nc > 0 && !same_nodes(sch, PLAN(sch)->nodes + fc, nc, PLAN(sch)->nodes + fy, ny))
        count_change(sch, 0);
    R->kind = REGION_STATIC;
    R->first = fc;
    R->count = nc;
    R->depth = 0;
}

/* The plan of the current interval: with morphing from
 * X_j = meet(S_{j-1}, S_j) to Y_j = meet(S_j, S_{j+1}); without, S_j. */
static void make_plan(tclod_scheduler *sch) {
    const generation *P = &sch->gen[sch->p.prev], *C = &sch->gen[sch->p.cur];
    const generation *N = &sch->gen[sch->p.next];
    const generation *by_priority[3];
    const tclod_id *lists[3];
    uint32_t sizes[3], e, r, i;
    int g;
    tclod_schedule_writable_plan(sch);
    tclod_schedule_update_depths(sch);
    tclod_schedule_next_memo_epoch(sch);
    /* predicted costs: S_j's where it drew the node, else the newest's */
    by_priority[0] = P;
    by_priority[1] = N;
    by_priority[2] = C;
    for (g = 0; g < 3; ++g)
        for (i = 0; i < by_priority[g]->count; ++i)
            memo_set(sch, by_priority[g]->ids[i], by_priority[g]->cost[i]);
    if (!sch->desc.two_stage) {
        sizes[0] = meet(sch, P->ids, P->count, C->ids, C->count, sch->list_x);
        sizes[1] = meet(sch, C->ids, C->count, N->ids, N->count, sch->list_y);
        lists[0] = sch->list_x;
        lists[1] = sch->list_y;
    } else {
        lists[0] = lists[1] = C->ids;
        sizes[0] = sizes[1] = C->count;
    }
    lists[2] = C->ids;
    sizes[2] = C->count;
    e = schedule_partition(sch, lists, sizes);
    for (r = 0; r < PLAN(sch)->region_count; ++r)
        plan_region(sch, r, e);
}

/* ---- the draw list -----------------------------------------------------------------------------
 */

static void emit_item(tclod_scheduler *sch, tclod_id fine, tclod_id coarse, float weight,
                      void *ctx) {
    tclod_draw *d = &sch->items[sch->back][sch->item_count[sch->back]++];
    int vis;
    /* the host's ids: a self leaf is its additive node, which does not morph */
    d->fine = tclod_scene_owner(sch->scene, fine);
    d->coarse = tclod_scene_owner(sch->scene, coarse);
    d->weight = d->fine == d->coarse ? 1.0f : weight;
    *(double *)ctx += memo(sch, fine, &vis);
}

/* This frame's draw list at position u of the interval, and its predicted
 * cost: the items' in order, then S_j's smooth groups' (an object's
 * resolution never exceeds S_j's in the interval), summed as the selector
 * sums its result. */
static void make_draws(tclod_scheduler *sch) {
    const tclod_draw *items = sch->items[sch->back];
    double cost = 0.0;
    uint32_t r, i, morphing = 0;
    const plan_state *P = PLAN(sch);
    sch->item_count[sch->back] = 0;
    for (r = 0; r < P->region_count; ++r) {
        const region *R = &P->regions[r];
        if (R->kind == REGION_STATIC) {
            for (i = 0; i < R->count; ++i) {
                tclod_id n = P->nodes[R->first + i];
                emit_item(sch, n, n, 1.0f, &cost);
            }
            continue;
        }
        morph_state(sch, R, (double)R->depth * (R->kind == REGION_UP ? sch->p.u : 1.0 - sch->p.u),
                    emit_item, &cost);
    }
    for (i = 0; i < sch->item_count[sch->back]; ++i)
        morphing += items[i].fine != items[i].coarse;
    for (i = 0; i < sch->gen[sch->p.cur].groups; ++i)
        cost += sch->gen[sch->p.cur].group_cost[i];
    sch->p.stats.draw_cost = cost;
    sch->p.stats.draws = sch->item_count[sch->back];
    sch->p.stats.morphing = morphing;
}

/* ---- the pipeline -------------------------------------------------------------------------------
 */

/* Selection time of an update: clock_in before a selector call, clock_out
 * after it. */
static double clock_in(void) {
    return tclod_now();
}

static void clock_out(tclod_scheduler *sch, double start) {
    sch->p.stats.select_seconds += tclod_now() - start;
}

/* Selects at once for the current view alone and draws that from now on,
 * without morphs: the first update, after a gap, a changed scene, or a draw
 * list over the budget. The pending selection is dropped and begun again. */
static tclod_status select_now(tclod_scheduler *sch, const tclod_view *view, int count_pops) {
    tclod_frame f;
    tclod_stats stats;
    tclod_status st;
    uint32_t i, n, g;
    double start = clock_in();
    sch->touched = 1;
    tclod_select_cancel(sch->sel);
    sch->p.ready = 0;
    sch->p.lost = 0;
    g = tclod_schedule_fresh_slot(sch);
    memset(&f, 0, sizeof f);
    f.view = view;
    f.budget = sch->p.budget;
    sch->current_only = 1;
    st = tclod_select(sch->sel, &f, &stats);
    sch->current_only = 0;
    clock_out(sch, start);
    if (st != TCLOD_OK)
        return st;
    sch->p.stats.invalid_values += stats.invalid_values;
    sch->p.stats.emergencies++;
    sch->p.stats.selection_benefit = stats.benefit;
    sch->p.stats.selection_cost = stats.cost;
    tclod_schedule_store(sch, g);
    if (count_pops) { /* from what this frame would have drawn */
        n = sch->item_count[sch->back];
        for (i = 0; i < n; ++i)
            sch->list_x[i] = sch->items[sch->back][i].fine;
        count_switches(sch, sch->list_x, n, sch->gen[g].ids, sch->gen[g].count);
    }
    sch->p.prev = sch->p.cur = sch->p.next = g;
    sch->p.node_version = sch->scene->node_version;
    sch->p.smooth_version = sch->scene->smooth_version;
    sch->p.residency_version = sch->scene->residency_version; /* it drew resident nodes */
    make_plan(sch);
    start = clock_in();
    st = tclod_schedule_begin(sch, view);
    clock_out(sch, start);
    return st;
}

/* The pending selection has finished (stats st): its result is copied now,
 * while the selector's costs are this solve's, and lands at the next
 * boundary. */
static void finished(tclod_scheduler *sch, const tclod_stats *st) {
    sch->p.landing = tclod_schedule_fresh_slot(sch);
    tclod_schedule_store(sch, sch->p.landing);
    if (tclod_scene_streams(sch->scene)) /* what was evicted since it saw it */
        repair(sch, sch->p.landing);
    sch->p.ready = 1;
    sch->p.landed_invalid = st->invalid_values;
    sch->p.landed_benefit = st->benefit;
    sch->p.landed_cost = st->cost;
}

/* At a boundary: the pending selection ends (early if need be; one begun
 * again after a failed update runs to its end) and joins the landed ones;
 * the plan of the new interval is made. A selection that fails in strict
 * mode fails the update. */
static tclod_status land(tclod_scheduler *sch) {
    uint32_t fresh;
    if (!sch->p.ready) {
        tclod_stats st;
        tclod_status status;
        int done = 0;
        double start = clock_in();
        sch->touched = 1;
        keep_landed(sch);
        if (sch->p.redo)
            status = tclod_select_step(sch->sel, 0.0, 0, &done, &st);
        else
            status = tclod_select_finish(sch->sel, &st);
        unkeep(sch);
        clock_out(sch, start);
        if (status != TCLOD_OK)
            return status;
        if (st.stop_reason == TCLOD_STOP_FINISHED)
            sch->p.stats.unfinished++;
        finished(sch, &st);
    }
    fresh = sch->p.landing;
    sch->p.stats.invalid_values += sch->p.landed_invalid;
    sch->p.stats.selection_benefit = sch->p.landed_benefit;
    sch->p.stats.selection_cost = sch->p.landed_cost;
    if (!sch->desc.two_stage) {
        /* S_{j-1}, S_j, S_{j+1} <- S_j, S_{j+1}, the new one */
        sch->p.prev = sch->p.cur;
        sch->p.cur = sch->p.next;
        sch->p.next = fresh;
    } else {
        sch->p.prev = sch->p.cur;
        sch->p.cur = sch->p.next = fresh;
        count_switches(sch, sch->gen[sch->p.prev].ids, sch->gen[sch->p.prev].count,
                       sch->gen[sch->p.cur].ids, sch->gen[sch->p.cur].count);
    }
    sch->p.ready = 0;
    sch->p.redo = 0;
    sch->p.stats.selections++;
    make_plan(sch);
    return TCLOD_OK;
}

/* Why an update's arguments are refused (NULL: they are not), written after
 * the "view->" of a view's rule. */
static const char *arguments_why(const tclod_scheduler *sch, double now, const tclod_view *view,
                                 double budget, double slice) {
    if (!view)
        return "view is NULL";
    if (tclod_view_check(view))
        return tclod_view_check(view);
    if (isnan(now) || isinf(now))
        return "now must be finite";
    if (sch->shown.started && now < sch->p.now)
        return "now must not be earlier than the last successful update's";
    if (!(budget >= 0.0))
        return "budget must be >= 0 (not NaN)";
    if (!(slice >= 0.0) || isinf(slice))
        return "slice_seconds must be finite and >= 0";
    if (!tclod_selector_scene_ok(sch->sel))
        return TCLOD_MSG_SMOOTH;
    return NULL;
}

/* Generation slot g is one the pipeline or the outputs use. */
static int slot_used(const tclod_scheduler *sch, uint32_t g) {
    return g == sch->p.prev || g == sch->p.cur || g == sch->p.next || g == sch->shown.prev ||
           g == sch->shown.cur || g == sch->shown.next || (sch->p.ready && g == sch->p.landing);
}

/* After the scene changed: the landed selections lose the nodes removed
 * since (the scene's index no longer holds them), so that they leave the
 * draw list now, mid-morph too. Removed smooth objects leave at the update's
 * success (clear_removed_smooth): until then the outputs show the last
 * successful update's resolutions. Returns whether the plan must be made
 * again. */
static int purge(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    int nodes = sch->p.node_version != s->node_version;
    uint32_t g, i, k;
    if (nodes)
        for (g = 0; g < GEN_SLOTS; ++g) {
            generation *G = &sch->gen[g];
            if (!slot_used(sch, g))
                continue;
            for (i = k = 0; i < G->count; ++i)
                if (tclod_scene_indexed(s, G->ids[i])) {
                    G->ids[k] = G->ids[i];
                    G->cost[k++] = G->cost[i];
                }
            G->count = k;
        }
    if (sch->p.smooth_version != s->smooth_version)
        sch->smooth_removed = 1;
    sch->p.node_version = s->node_version;
    sch->p.smooth_version = s->smooth_version;
    return nodes;
}

/* A successful update: the smooth objects removed before it show resolution
 * 0 in every generation it left in use. */
static void clear_removed_smooth(tclod_scheduler *sch) {
    const tclod_scene *s = sch->scene;
    uint32_t g, i;
    for (g = 0; g < GEN_SLOTS; ++g)
        if (slot_used(sch, g))
            for (i = 0; i < s->smooth_count; ++i)
                if (!tclod_scene_smooth_live(s, i))
                    sch->gen[g].res[i] = 0.0;
}

/* The pipeline's work of one update; the outputs are made in the back
 * buffers. */
static tclod_status advance(tclod_scheduler *sch, double now, const tclod_view *view,
                            double slice_seconds) {
    const double tau = sch->desc.tau;
    tclod_status st = TCLOD_OK;
    /* a restart: the first update, a changed scene, a long gap, or times so
     * large that tau no longer moves the boundary (checked at every step:
     * rounding to even can move it once and then not again) */
    int restart = !sch->p.started || now - sch->p.boundary > (MAX_GAP + 1.0) * tau;
    if (!restart && purge(sch))
        make_plan(sch);
    if (!restart)
        sync_residency(sch);
    if (!restart && sch->p.lost) {
        double start = clock_in();
        st = tclod_schedule_begin_again(sch);
        clock_out(sch, start);
        if (st != TCLOD_OK)
            return st;
    }
    while (!restart && now >= sch->p.boundary + tau) {
        double start;
        if (!(sch->p.boundary + tau > sch->p.boundary)) {
            restart = 1;
            break;
        }
        sch->p.boundary += tau;
        st = land(sch);
        if (st != TCLOD_OK)
            return st;
        start = clock_in();
        st = tclod_schedule_begin(sch, view);
        clock_out(sch, start);
        if (st != TCLOD_OK)
            return st;
    }
    if (restart) {
        sch->p.boundary = now;
        sch->item_count[sch->back] = 0;
        st = select_now(sch, view, 0);
        if (st != TCLOD_OK)
            return st;
        sch->p.started = 1;
    }
    sch->p.u = (now - sch->p.boundary) / tau;
    if (!(sch->p.u >= 0.0))
        sch->p.u = 0.0;
    if (sch->p.u > 1.0)
        sch->p.u = 1.0;
    make_draws(sch);
    if (sch->p.stats.draw_cost > sch->p.budget) {
        st = select_now(sch, view, 1);
        if (st != TCLOD_OK)
            return st;
        make_draws(sch);
    }
    if (!sch->p.ready) {
        tclod_stats stats;
        int done = 0;
        double start = clock_in();
        sch->touched = 1;
        keep_landed(sch);
        st = tclod_select_step(sch->sel, slice_seconds, 0, &done, &stats);
        unkeep(sch);
        clock_out(sch, start);
        if (st == TCLOD_OK && done)
            finished(sch, &stats);
    }
    return st;
}

/* Keeps what an update may change, so that a failure can put it back. */
static void keep(tclod_scheduler *sch) {
    sch->saved = sch->p;
    sch->saved_hist_t = sch->hist_t[sch->p.hist_next];
    sch->saved_hist_v = sch->hist_v[sch->p.hist_next];
    sch->views_saved = 0;
    sch->touched = 0;
    sch->pending_at_start = tclod_select_pending(sch->sel);
    sch->smooth_removed = 0;
    tclod_selector_keep(sch->sel, &sch->kept);
}

/* Puts back what keep() kept: the update failed. The selection pending
 * before it is lost if the update called the selector (it may have ended,
 * landed or been dropped): the next update begins it again. */
static void put_back(tclod_scheduler *sch) {
    sch->p = sch->saved;
    sch->hist_t[sch->p.hist_next] = sch->saved_hist_t;
    sch->hist_v[sch->p.hist_next] = sch->saved_hist_v;
    if (sch->views_saved)
        sch->sv = sch->saved_views;
    if (sch->touched) {
        tclod_select_cancel(sch->sel);
        tclod_selector_restore(sch->sel, &sch->kept);
        if (sch->pending_at_start)
            sch->p.lost = 1;
    }
    sch->asked = TCLOD_NONE;
}

tclod_status tclod_scheduler_update(tclod_scheduler *sch, double now, const tclod_view *view,
                                    double budget, double slice_seconds) {
    static const char fn[] = "tclod_scheduler_update";
    tclod_status st;
    uint32_t epoch;
    const char *why;
    if (!sch)
        return TCLOD_ERR_ARG;
    why = arguments_why(sch, now, view, budget, slice_seconds);
    if (why)
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, why);
    if (sch->busy)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    sch->busy = sch->user.busy = 1;
    st = tclod_scene_prepare(sch->scene);
    if (st == TCLOD_OK)
        st = tclod_schedule_reserve(sch);
    if (st != TCLOD_OK) {
        sch->busy = sch->user.busy = 0;
        return tclod_fail(sch->error, st, fn, TCLOD_MSG_NOMEM);
    }
    /* a selection under way on a scene that changed since it began is begun
     * again (it saw part of the old scene) */
    if (tclod_select_pending(sch->sel) && sch->sel->pending_version != sch->scene->version) {
        tclod_select_cancel(sch->sel);
        sch->p.lost = 1;
    }
    /* so is one that finished before nodes were added or removed and waits to
     * land: it would leave the added ones out for an interval more */
    if (sch->p.ready && sch->p.node_version != sch->scene->node_version) {
        sch->p.ready = 0;
        sch->p.lost = 1;
    }
    keep(sch);
    epoch = sch->scene->epoch;
    sch->p.stats.select_seconds = 0.0;
    sch->p.budget = budget / tclod_calib_scale(sch->calib);
    sch->p.stats.budget = sch->p.budget;
    sch->p.now = now;
    sch->failed = 0;
    tclod_schedule_record(sch, now, view);
    st = advance(sch, now, view, slice_seconds);
    if (st == TCLOD_OK && sch->failed)
        st = TCLOD_ERR_CALLBACK;
    if (st == TCLOD_OK) { /* the outputs show this update */
        sch->shown.started = 1;
        sch->shown.prev = sch->p.prev;
        sch->shown.cur = sch->p.cur;
        sch->shown.next = sch->p.next;
        sch->shown.u = sch->p.u;
        sch->shown.items = sch->back;
        sch->shown.stats = sch->p.stats;
        sch->back = 1u - sch->back;
        if (sch->smooth_removed)
            clear_removed_smooth(sch);
        sch->user.synced = epoch; /* its selections name no node removed before that */
    } else {
        if (st == TCLOD_ERR_CALLBACK)
            tclod_fail(sch->error, st, fn, TCLOD_MSG_STRICT);
        else /* the selector's own error */
            tclod_fail(sch->error, st, fn, sch->sel->error);
        put_back(sch);
    }
    tclod_selector_keep(sch->sel, NULL);
    sch->busy = sch->user.busy = 0;
    return st;
}

tclod_status tclod_scheduler_draws(const tclod_scheduler *sch, const tclod_draw **items,
                                   size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    *items = sch->shown.started ? sch->items[sch->shown.items] : NULL;
    *n = sch->shown.started ? sch->item_count[sch->shown.items] : 0u;
    return TCLOD_OK;
}

double tclod_scheduler_resolution(const tclod_scheduler *sch, tclod_id smooth) {
    double p, c, n, from, to;
    if (!sch || !sch->shown.started || smooth >= sch->scene->smooth_count ||
        smooth >= sch->smooth_cap)
        return 0.0;
    if (sch->scene->smooth_flags[smooth] & TCLOD_NODE_ABSENT)
        return 0.0; /* not resident (evicted since a selection drew it): not drawn */
    c = sch->gen[sch->shown.cur].res[smooth];
    if (sch->desc.two_stage)
        return c;
    p = sch->gen[sch->shown.prev].res[smooth];
    n = sch->gen[sch->shown.next].res[smooth];
    from = p < c ? p : c;
    to = c < n ? c : n;
    return from + (to - from) * sch->shown.u;
}

tclod_status tclod_scheduler_report_frame(tclod_scheduler *sch, double render_time,
                                          double logic_time) {
    static const char fn[] = "tclod_scheduler_report_frame";
    if (!sch)
        return TCLOD_ERR_ARG;
    if (!schedule_finite_nonnegative(render_time))
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, "render_time must be finite and >= 0");
    if (!(logic_time == (double)TCLOD_OFF || schedule_finite_nonnegative(logic_time)))
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn,
                          "logic_time must be finite and >= 0, or TCLOD_OFF");
    if (!sch->shown.started)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, "no update has succeeded yet");
    /* a draw list whose predicted cost overflowed (its roots over the budget)
     * tells nothing about the ratio: only the logic time is followed */
    return tclod_calib_report(sch->calib,
                              isinf(sch->shown.stats.draw_cost) ? 0.0 : sch->shown.stats.draw_cost,
                              render_time, logic_time);
}

const tclod_calib *tclod_scheduler_calib(const tclod_scheduler *sch) {
    return sch ? sch->calib : NULL;
}

tclod_status tclod_scheduler_get_stats(const tclod_scheduler *sch, tclod_scheduler_stats *st) {
    if (!sch || !st)
        return TCLOD_ERR_ARG;
    *st = sch->shown.stats;
    return TCLOD_OK;
}

const char *tclod_scheduler_last_error(const tclod_scheduler *sch) {
    return sch ? sch->error : "";
}

/* ---- streaming ------------------------------------------------------------------ */

tclod_status tclod_scheduler_set_stream(tclod_scheduler *sch, const tclod_stream_desc *d) {
    static const char fn[] = "tclod_scheduler_set_stream";
    const char *why;
    if (!sch)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return tclod_fail(sch->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    why = d ? tclod_stream_desc_check(d) : NULL;
    if (why)
        return tclod_fail(sch->error, TCLOD_ERR_ARG, fn, why);
    return tclod_selector_set_stream(sch->sel, d);
}

tclod_status tclod_scheduler_requests(const tclod_scheduler *sch, const tclod_stream_item **items,
                                      size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return TCLOD_ERR_STATE;
    return tclod_selector_requests(sch->sel, items, n);
}

tclod_status tclod_scheduler_evictions(const tclod_scheduler *sch, const tclod_stream_item **items,
                                       size_t *n) {
    if (!sch || !items || !n)
        return TCLOD_ERR_ARG;
    if (sch->busy)
        return TCLOD_ERR_STATE;
    return tclod_selector_evictions(sch->sel, items, n);
}
