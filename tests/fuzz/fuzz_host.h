/*
 * fuzz_host — the host the fuzz targets play (fuzz_host.c): a scene model
 * mirrored node by node, callbacks that read it and check every query they
 * are given, and readers that turn the fuzzer's bytes into selector
 * descriptions, scenes and views, checking the statuses the header promises
 * on the way.
 */
#ifndef FUZZ_HOST_H
#define FUZZ_HOST_H

#include <tclod/tclod.h>

#include "fuzz_input.h"

#define MAX_NODES 192u
#define MAX_SMOOTH 48u

/* A smooth object's model: benefit w r^p, cost steep r up to r = kink then
 * k per unit, slopes honest or not, and optionally one bad value or slope. */
typedef struct smooth_model {
    double w, p;
    double k, steep, kink;
    int dishonest; /* slopes are fake_slope whatever r */
    double fake_slope;
    int bad_kind; /* 0 none; 1 benefit, 2 benefit slope, 3 cost, 4 cost slope */
    double bad_value;
} smooth_model;

/* The host's scene model, mirrored node by node and object by object. */
typedef struct host_model {
    uint32_t nodes, smooth;
    tclod_id parent[MAX_NODES];
    float bounds[MAX_NODES][4]; /* radius -1: none */
    double benefit[MAX_NODES], cost[MAX_NODES];
    double complexity[MAX_NODES + MAX_SMOOTH]; /* nodes, then smooth objects */
    int view_dependent;                        /* benefit x screen area when the query has one */
    smooth_model sm[MAX_SMOOTH];
} host_model;

/* What one selector's callbacks saw during the current select. */
typedef struct probe {
    const host_model *m;
    const tclod_view *frame_view;
    uint32_t benefit_calls[MAX_NODES], cost_calls[MAX_NODES];
    double benefit_seen[MAX_NODES], cost_seen[MAX_NODES];
    uint32_t calls; /* every callback call */
    uint32_t bad;   /* callback calls that returned a bad value or slope */
    int any_view;   /* 1: queries may carry any valid view (the scheduler's
                       predicted ones), and a node may be asked once per
                       view: the once-per-select accounting is off */
} probe;

/* Forgets what the probe saw, before a select with the given view. */
void probe_reset(probe *p, const tclod_view *view);

/* Whether a query carries the frame's view: none when the frame has none,
 * else the same numbers (the library may hold a copy). */
int same_view(const tclod_view *q, const tclod_view *frame);

/* A query about a node's own benefit or cost during the solve, as opposed
 * to the Robin Hood solver's complexity question (no view, the reference
 * area as screen area), which a normal query without a view never has: its
 * screen area is then -1. */
int is_complexity_query(const tclod_query *q);

/* Stops the run when a node query breaks the header: an unknown id,
 * members, a view other than the frame's, screen area and distance other
 * than the view helpers give for the node's bounds. */
void check_node_query(const probe *p, const tclod_query *q);

/* The callbacks, user = a probe: the model's values (benefit times the
 * screen area when the model says so), each call counted and checked; cost
 * only after a benefit > 0 in the same select. */
double host_benefit(void *user, const tclod_query *q);
double host_cost(void *user, const tclod_query *q);
double host_complexity(void *user, const tclod_query *q);
double host_importance(void *user, const tclod_query *q);

/* The host's smooth value (cost != 0: cost) of a group at resolution r, the
 * sum over its members, and its slope in *d_dr. */
double smooth_value(const host_model *m, const tclod_query *q, double r, double *d_dr, int cost);

/* Stops the run when a smooth query breaks the header: r outside
 * [1e-9, 1], no d_dr, members that are not the group's. */
void check_smooth_query(const probe *p, const tclod_query *q, double r, const double *d_dr);

/* The smooth callbacks, user = a probe. */
double host_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr);
double host_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr);

/* An option value: 0 keeps the default, small bytes pick ordinary values,
 * the rest special ones (bad ones among them). */
double option_value(fuzz_reader *in, double def);

/* Whether the header promises TCLOD_ERR_ARG for this description over a
 * scene of `smooth` smooth objects; -1 when it leaves the value open (an
 * infinite threshold, cull area or reference area: "NaN or out of range" with
 * ranges written as ">= 0" and "> 0"). */
int desc_invalid(const tclod_selector_desc *d, uint32_t smooth);

/* Whether a selector of this (valid) description refuses to solve a scene of
 * `smooth` smooth objects: the mixed solver without smooth callbacks. */
int smooth_callbacks_missing(const tclod_selector_desc *d, uint32_t smooth);

/* A selector description from the input: solver (sometimes an unknown
 * one), flags, value and misfit policies, options (sometimes out of range),
 * the host's callbacks with user NULL (the caller sets it). */
void read_desc(fuzz_reader *in, tclod_selector_desc *d, host_model *m);

/* A parent: a root, an existing node, or an id that does not exist. */
tclod_id read_parent(fuzz_reader *in, uint32_t count);

/* Whether bounds are bad for the header: not finite, or radius < 0. */
int bounds_bad(const float b[4]);

/* Bounds from the input, bad ones among them. */
void read_bounds(fuzz_reader *in, float b[4]);

/* Adds one node as the input says, and checks the status the header
 * promises; on failure nothing may change. */
void add_node(fuzz_reader *in, tclod_scene *s, host_model *m);

/* Adds one smooth object and its model as the input says, checking the
 * status as add_node does. */
void add_smooth(fuzz_reader *in, tclod_scene *s, host_model *m);

/* Whether the header requires tclod_view_validate to accept (1) or reject
 * (0) v; -1 when forward and up are so close to parallel that either is
 * right. */
int view_valid(const tclod_view *v);

/* A view: none, one of the shared flyover loop's, or one made of the input. */
const tclod_view *read_view(fuzz_reader *in, tclod_view *v);

/* The view helpers on a valid view and the nodes' bounds: areas in
 * [0, viewport area], distances >= 0, never NaN. */
void check_view_helpers(const tclod_view *v, const host_model *m);

#endif /* FUZZ_HOST_H */
