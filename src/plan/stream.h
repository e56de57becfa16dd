/*
 * stream.c: residency in the solvers' evaluation, and the plan of load
 * requests and evictions a select makes for the host's loader
 * (docs/streaming.md).
 */
#ifndef TCLOD_STREAM_H
#define TCLOD_STREAM_H

#include "../core/heap.h"

/* What a selector keeps for streaming (tclod_selector.stream). Its per-node
 * buffers (cap elements each) are allocated by the first select that plans
 * or sees a node that is not resident. */
typedef struct tclod_stream_state {
    tclod_stream_desc desc; /* tclod_selector_set_stream */
    uint32_t cap;
    /* the true values of the nodes not resident that this solve evaluated
     * (valid where seen[n] == the solve's id): the solver itself sees them
     * as not drawable (stream.c, tclod_evaluate_absent) */
    uint32_t *seen;
    double *benefit, *cost;
    /* the plan: per node its state in it (STREAM_* in stream.c), the rank
     * a requested node may have at most (the lowest of its requested
     * ancestors'), and the plan when it was last protected (least recently
     * used first among evictions of equal value) */
    uint8_t *mark;
    uint8_t *smooth_mark;  /* the same per smooth object (LISTED, EVICTED, KEEP) */
    uint32_t *smooth_used; /* the plan when it was last drawn */
    double *cap_value;
    double *size;          /* a request candidate's size (request_bytes) */
    double *delta;         /* 2 per node: its increment's gain and cost in the target */
    double target_benefit; /* the target's benefit */
    /* the target's lookahead (the selector's greedy.lookahead): per node the
     * levels below it that its increment replaces it by (1: its children),
     * and the scratch of its walks down, used from `level_top` up */
    uint8_t *jump;
    tclod_id *level;
    double *look; /* 2 per node: a refit's best cut below it, benefit and cost */
    uint32_t level_top;
    uint32_t *size_seen; /* the solve that sized it (size valid) */
    /* the target's closure: increments keyed at least `closure` are taken
     * first in first out (queue[head .. tail)) while `filling`; `least`: the
     * least key the heap took */
    tclod_id *queue;
    uint32_t head, tail;
    int filling;
    double closure, least;
    uint32_t *used;
    double *seen_value; /* per node: its benefit per byte when last seen visible */
    tclod_id *touched;  /* the nodes whose mark the plan set */
    uint32_t touched_count;
    tclod_heap heap; /* the plan's increments, then the eviction candidates */
    tclod_id *ids;   /* scratch: candidates */
    double *keys;
    uint32_t plans;       /* plans made: the clock of used[] */
    uint32_t absent_seen; /* nodes this solve evaluated and found not resident */
    /* the lists: the current ones (read by the host) and the ones the next
     * plan writes, swapped when a select commits */
    tclod_stream_item *list[2][2]; /* [requests, evictions][current, next] */
    uint32_t count[2][2];
    /* nodes the plan keeps besides the drawn ones and what it needs next (a
     * scheduler's: what its morphs draw at either end), with their
     * ancestors; set by the selector's owner, never freed by it */
    const tclod_id *keep;
    uint32_t keep_count;
} tclod_stream_state;

/* Lists the streaming buffers into out (room for TCLOD_MAX_ARRAYS); returns
 * how many. */
size_t tclod_stream_buffers(tclod_stream_state *S, tclod_array *out);

/* NULL when d is valid for tclod_selector_set_stream, else the rule it breaks. */
const char *tclod_stream_desc_check(const tclod_stream_desc *d);

/* ---- for the selector -------------------------------------------------------- */

/* Whether the selector needs its streaming buffers: the scene has nodes not
 * resident, or the stream desc asks for a plan. */
int tclod_stream_wanted(const tclod_selector *sel);

/* Plans the requests and evictions of the solve that ends (its working cut,
 * before the commit) into the lists the commit makes current. Returns 0, or
 * -1 when strict mode saw a bad size. */
int tclod_stream_plan(tclod_selector *sel);

/* Makes the planned lists current (with the commit of the solve). */
void tclod_stream_commit(tclod_selector *sel);

#endif /* TCLOD_STREAM_H */
