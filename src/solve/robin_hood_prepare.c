/*
 * TCLOD_SOLVER_ROBIN_HOOD, its instances ([RH §5.1]): what the solver reads of
 * the scene, remade when the scene changes (docs/robin_hood.md): the copy of
 * the child index in id order, the chains of levels and the branching nodes
 * that make instances, their complexity (the finest level's cost, or its
 * nearest kept estimate), which nested instance lies inside which, and the
 * order of the instances by complexity that the cycles walk.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (heap.c,
 * scene.c, view.c); eval (evaluate.c).
 */
#include "robin_hood_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Whether node n (in the index) starts an instance: a root, or one of several
 * children. */
static int is_head(const tclod_selector *sel, tclod_id n) {
    tclod_id p = sel->scene->parent[n];
    return p == TCLOD_NONE || child_count(sel, p) > 1u;
}

/* A sanitised complexity: NaN, infinite or negative (or, when it is a smooth
 * cost, with such a slope) counts as the most complex (visited last) and is
 * counted like any bad callback value. */
static double complexity_value(tclod_selector *sel, double c, double slope) {
    if (!robin_hood_value_bad(c) && !robin_hood_value_bad(slope))
        return c;
    tclod_bad_value(sel);
    return robin_hood_value_bad(c) ? HUGE_VAL : c;
}

/* The complexity of the instance starting at node head (chain end `end`) or
 * of smooth object `smooth` at sorted position pos: the host's complexity
 * callback, or the cost of the finest representation at the reference area
 * with no view. */
static double node_complexity(tclod_selector *sel, tclod_id head, tclod_id end) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_query q;
    tclod_bounds qb;
    q.count = 1;
    q.view = NULL;
    q.screen_area = (float)sel->desc.robin_hood.reference_area;
    q.distance = -1.0f;
    q.members = NULL;
    q.id = tclod_scene_owner(sel->scene, cb->complexity ? head : end);
    tclod_scene_public_bounds(sel->scene, q.id, &qb);
    q.bounds = qb.kind != TCLOD_BOUNDS_NONE ? &qb : NULL;
    return complexity_value(
        sel, cb->complexity ? cb->complexity(cb->user, &q) : tclod_node_cost(sel, &q), 0.0);
}

static double smooth_complexity(tclod_selector *sel, uint32_t pos) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    const tclod_scene *s = sel->scene;
    tclod_query q;
    tclod_bounds qb;
    double c, d;
    q.id = s->smooth_order[pos];
    q.count = 1;
    q.view = NULL;
    q.screen_area = (float)sel->desc.robin_hood.reference_area;
    q.distance = -1.0f;
    q.members = s->smooth_order + pos;
    tclod_sphere_bounds(&s->smooth_bounds[4u * q.id], &qb);
    q.bounds = &qb;
    if (cb->complexity)
        return complexity_value(sel, cb->complexity(cb->user, &q), 0.0);
    d = 0.0;
    c = tclod_smooth_cost(sel, &q, 1.0, &d);
    return complexity_value(sel, c, d);
}

/* The chain head above node n (defined below). */
static tclod_id chain_head(const tclod_selector *sel, tclod_id n);

/* Streaming: when node n (a self leaf: its additive node) is not resident and
 * was evaluated in this solve, the cost its evaluation asked into *out
 * (tclod_evaluate_absent keeps it) and 1; else 0. */
static TCLOD_NOINLINE int kept_cost(const tclod_selector *sel, tclod_id n, double *out) {
    const tclod_stream_state *S = &sel->stream;
    tclod_id owner = tclod_scene_owner(sel->scene, n);
    if (!(sel->scene->flags[owner] & TCLOD_NODE_ABSENT) || owner >= S->cap ||
        S->seen[owner] != sel->solve_id)
        return 0;
    *out = S->cost[owner];
    return 1;
}

/* The default complexity (callbacks.complexity NULL) of the instance starting
 * at head whose finest representation is node end, into *out: end's cost as
 * this select evaluates it for its frame, here, so that the select asks it
 * once; when the frame does not see end (its benefit is 0, and the frame
 * never asks its cost), its cost at the reference area with no view
 * (node_complexity), or for a self leaf its additive node's, found before it
 * (an ancestor's chain comes first). `culled`: head lies below a branch the
 * frame does not see, whose subtree this select never evaluates: end is
 * taken as not seen without asking. An end that is not resident has the
 * cost its evaluation asked (kept_cost). A head that is its own end is
 * evaluated as cycles 1 and 2 evaluate heads, and its value (-1: not
 * visible) waits in path[2 head] for them (keep_values). Returns -1 on a
 * strict error. */
static int finest_cost(tclod_selector *sel, tclod_id head, tclod_id end, int culled, double *out) {
    int seen = 0;
    if (culled) {
        /* not evaluated: nothing below a culled branch is */
    } else if (end == head) {
        double v;
        seen = evaluate_head(sel, head, 0, 0, &v);
        if (seen < 0)
            return -1;
        sel->path[2u * head] = seen ? v : -1.0;
    } else {
        if (tclod_evaluate_node(sel, end) != 0)
            return -1;
        seen = visible(sel, end);
    }
    /* not resident: its cost as asked, not the +inf that makes it undrawable in
     * this solve (the order outlives the residency) */
    if (TCLOD_UNLIKELY(sel->scene->absent_count != 0) && kept_cost(sel, end, out))
        return sel->failed ? -1 : 0;
    if (seen)
        *out = sel->node[end].cost; /* sanitised: a bad one is +inf, counted once */
    else if (sel->scene->bounds[end].kind & TCLOD_BOUNDS_SELF)
        *out = sel->rh.key[chain_head(sel, sel->scene->up[end])];
    else
        *out = node_complexity(sel, head, end);
    return sel->failed ? -1 : 0;
}

/* The distance from branching node b's centre within which every bounded
 * child lies, padded well beyond its rounding (-1 when b has no bounds), for
 * tclod_view_cache_inside. */
static float branch_reach(const tclod_selector *sel, tclod_id b) {
    const tclod_scene *s = sel->scene;
    const tclod_node_bounds *bb = &s->bounds[b];
    uint32_t j, first = sel->rh.first[b], k = child_count(sel, b);
    double reach = 0.0;
    if (!(bb->r >= 0.0))
        return -1.0f;
    for (j = 0; j < k; ++j) {
        const tclod_node_bounds *cb = &s->bounds[sel->rh.kids[first + j]];
        double dx = cb->c[0] - bb->c[0], dy = cb->c[1] - bb->c[1], dz = cb->c[2] - bb->c[2], r;
        if (!(cb->r >= 0.0))
            continue;
        r = sqrt(dx * dx + dy * dy + dz * dz) + cb->r;
        if (r > reach)
            reach = r;
    }
    /* a margin relative to the coordinates: the inside test works in double
     * relative to the eye, so what earth-centred coordinates lose is far below
     * it */
    reach += 1e-6 * reach + 1e-12 * (fabs(bb->c[0]) + fabs(bb->c[1]) + fabs(bb->c[2]));
    return reach < (double)FLT_MAX ? (float)reach : -1.0f;
}

/* The head of the chain that node n belongs to. */
static tclod_id chain_head(const tclod_selector *sel, tclod_id n) {
    while (!is_head(sel, n))
        n = sel->scene->parent[n];
    return n;
}

/* Whether the sphere of radius r around centre c lies within the one of
 * radius R around C, by a margin far above the rounding of the test. */
static int sphere_within(const double c[3], float r, const double C[3], float R) {
    double dx = c[0] - C[0], dy = c[1] - C[1], dz = c[2] - C[2];
    return r >= 0.0f && R >= 0.0f &&
           sqrt(dx * dx + dy * dy + dz * dz) + (double)r <= (double)R * (1.0 - 1e-9);
}

/* TCLOD_RH_NESTED for every chain that ends in a branch whose reach sphere
 * lies within the reach sphere of the branch its head is a child of: when
 * that one lies inside the frustum (tclod_view_cache_inside), so does this
 * one, and every sphere within it passes the frustum test. */
static void mark_nested(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t i;
    for (i = 0; i < s->order_count; ++i) {
        tclod_id id = s->order[i];
        tclod_rh_chain *ch = &sel->rh.chains[id];
        const tclod_rh_chain *up;
        tclod_id end, above;
        if (!is_head(sel, id) || !(ch->flags & TCLOD_RH_BRANCH) || s->parent[id] == TCLOD_NONE)
            continue;
        above = s->parent[id];
        up = &sel->rh.chains[chain_head(sel, above)];
        end = sel->rh.chain[ch->at + ch->len - 1u];
        if (sphere_within(s->bounds[end].c, ch->reach, s->bounds[above].c, up->reach))
            ch->flags |= TCLOD_RH_NESTED;
    }
}

/* Whether head n lies below a branch that this select found invisible, or
 * did not evaluate because it lies below one itself: prepare evaluates every
 * other finest node (a branch is its chain's), parents first. */
static int culled_below(const tclod_selector *sel, tclod_id n) {
    tclod_id p = sel->scene->parent[n];
    return p != TCLOD_NONE && (sel->node[p].stamp != sel->solve_id || !visible(sel, p));
}

/* The values of the heads finest_cost evaluated, for cycles 1 and 2: a
 * branch's children's in scratch_key by slot, as evaluate_children keeps
 * them; the top-level ones stay in path[2 id] for values(). */
static void keep_values(tclod_selector *sel) {
    uint32_t n = sel->scene->node_count, first, k, j;
    tclod_id id;
    for (id = 0; id < n; ++id) {
        first = sel->rh.first[id];
        k = child_count(sel, id);
        if (k < 2u)
            continue;
        for (j = 0; j < k; ++j) {
            tclod_id c = sel->rh.kids[first + j];
            if (sel->node[c].stamp == sel->solve_id)
                sel->scratch_key[first + j] = sel->path[2u * c];
        }
    }
}

/* The chains (every node belongs to the chain of the nearest instance start
 * above it), each branching node's children and the top-level instances, in
 * order of complexity. Smooth objects are identified by their position in the
 * scene's smooth order, plus the node count. Returns -1 on a strict error. */
int tclod_rh_prepare(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t n = s->node_count, used = 0, i, count = 0;
    int by_cost = sel->desc.callbacks.complexity == NULL;
    double *keys;
    tclod_id id;
    /* the child index, contiguous */
    for (id = 0; id < n; ++id) {
        sel->rh.first[id] = used;
        if (s->child_count[id])
            memcpy(sel->rh.kids + used, s->children + s->child_first[id],
                   sizeof(tclod_id) * s->child_count[id]);
        used += s->child_count[id];
    }
    sel->rh.first[n] = used;
    used = 0;
    for (i = 0; i < s->order_count; ++i) {
        tclod_rh_chain *ch;
        const tclod_node_bounds *b;
        tclod_id m;
        id = s->order[i];
        if (!is_head(sel, id))
            continue;
        ch = &sel->rh.chains[id];
        b = &s->bounds[id];
        ch->at = used;
        ch->flags = TCLOD_RH_CONSECUTIVE | TCLOD_RH_SHARED;
        for (m = id;; m = sel->rh.kids[sel->rh.first[m]]) {
            if (m != id + (used - ch->at))
                ch->flags &= ~(uint32_t)TCLOD_RH_CONSECUTIVE;
            if (memcmp(&s->bounds[m], b, sizeof *b) != 0)
                ch->flags &= ~(uint32_t)TCLOD_RH_SHARED;
            sel->rh.chain[used++] = m;
            if (child_count(sel, m) != 1u)
                break;
        }
        ch->reach = -1.0f;
        ch->first = ch->count = 0;
        if (child_count(sel, m) > 1u) {
            ch->flags |= TCLOD_RH_BRANCH;
            ch->reach = branch_reach(sel, m);
            ch->first = sel->rh.first[m];
            ch->count = child_count(sel, m);
        }
        ch->len = used - ch->at;
        if (!by_cost)
            sel->rh.key[id] = node_complexity(sel, id, m);
        else if (finest_cost(sel, id, m, culled_below(sel, id), &sel->rh.key[id]) != 0)
            return -1;
    }
    assert(used == s->order_count);
    mark_nested(sel);
    /* each branch's children, least complex first (ties: smaller id, which is the
     * smaller slot: a child range lists its ids in order), sorted in scratch */
    for (id = 0; id < n; ++id) {
        uint32_t first = sel->rh.first[id], k = child_count(sel, id), j;
        if (k < 2u)
            continue;
        for (j = 0; j < k; ++j) {
            sel->scratch[first + j] = first + j;
            sel->scratch_key[first + j] = -sel->rh.key[sel->rh.kids[first + j]];
        }
        tclod_sort_by_key(sel->scratch + first, sel->scratch_key + first, k);
        for (j = 0; j < k; ++j) {
            tclod_rh_child *c = &sel->rh.child[first + j];
            c->slot = sel->scratch[first + j];
            c->id = sel->rh.kids[c->slot];
            c->chain = sel->rh.chains[c->id];
        }
    }
    /* the second half of rh.key holds the order's keys (none: an empty scene) */
    keys = sel->rh.key ? sel->rh.key + sel->rh.cap : NULL;
    for (i = 0; i < s->root_count; ++i) {
        sel->rh.order[count] = s->roots[i];
        keys[count++] = -sel->rh.key[s->roots[i]];
    }
    if (with_smooth(sel))
        for (i = 0; i < s->smooth_live; ++i) {
            sel->rh.order[count] = n + i;
            keys[count++] = -smooth_complexity(sel, i);
        }
    tclod_sort_by_key(sel->rh.order, keys, count);
    sel->rh.order_count = count;
    if (by_cost)
        keep_values(sel);
    /* no chain has taken a level yet: their searches start at the first */
    for (id = 0; id < n; ++id)
        set_last_level(sel, id, 0u);
    if (sel->failed)
        return -1;
    sel->rh.version = s->version;
    return 0;
}
