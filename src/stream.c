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
 */
#include "selector.h"

#include <float.h>
#include <math.h>
#include <string.h>

int tclod_evaluate_absent(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    tclod_node_state *st = &sel->node[n];
    tclod_id p = s->parent[n];
    if (S->seen && n < S->cap) {
        S->seen[n] = sel->solve_id;
        S->benefit[n] = st->benefit;
        S->cost[n] = st->cost;
    }
    if (p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD)) {
        if (p == TCLOD_NONE)
            sel->stats.absent_roots++;
        st->benefit = 0.0;
        st->cost = 0.0;
        return 0;
    }
    st->cost = HUGE_VAL;
    return 1;
}

/* ---- buffers ------------------------------------------------------------------ */

size_t tclod_stream_buffers(tclod_stream_state *S, tclod_array *out) {
    size_t n = 0, i, k;
    out[n++] = (tclod_array){(void **)&S->seen, sizeof(uint32_t), 0};
    out[n++] = (tclod_array){(void **)&S->benefit, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->cost, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->mark, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&S->cap_value, sizeof(double), -1};
    out[n++] = (tclod_array){(void **)&S->used, sizeof(uint32_t), 0};
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

int tclod_stream_plan(tclod_selector *sel) {
    tclod_stream_state *S = &sel->stream;
    S->count[0][1] = S->count[1][1] = 0;
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
