/*
 * fuzz_host — the host the fuzz targets play: a scene model mirrored id by
 * id, callbacks that read it (and check every query they are given against
 * the header), edits whose statuses the model predicts, and the readers that
 * build descriptions, scenes, edits and views from the fuzzer's bytes while
 * checking the statuses the header promises.
 */
#include "fuzz_host.h"

#include "world_scene.h"

/* ---- tallies ------------------------------------------------------------------- */

static unsigned long tallies[TALLY_COUNT];
static int tallying = -1;

static void print_tallies(void) {
    static const char *const names[TALLY_COUNT] = {
        "scene calls accepted", "scene calls refused",       "refused (solve holds)",
        "subtrees removed",     "node ids given again",      "smooth ids given again",
        "hidden ids known",     "hidden ids unknown",        "bad bounds refused",
        "queries with AABBs",   "queries with OBBs",         "additive nodes listed refined",
        "selects over budget",  "selects with dropped roots"};
    int i;
    for (i = 0; i < TALLY_COUNT; ++i)
        fprintf(stderr, "tally: %-30s %lu\n", names[i], tallies[i]);
}

void tally(int what) {
    if (tallying < 0) {
        tallying = getenv("FUZZ_STATS") != NULL;
        if (tallying)
            atexit(print_tallies);
    }
    tallies[what]++;
}

/* ---- the model ------------------------------------------------------------------ */

void model_init(host_model *m, tclod_scene *s, uint32_t users) {
    uint32_t u;
    memset(m, 0, sizeof *m);
    m->scene = s;
    m->users = users;
    for (u = 0; u < MAX_USERS; ++u)
        m->synced[u] = UINT32_MAX;
}

void model_user_solved(host_model *m, uint32_t u) {
    m->synced[u] = m->epoch;
}

int model_reuse_allowed(const host_model *m, uint32_t at) {
    uint32_t u;
    for (u = 0; u < m->users; ++u)
        if (m->synced[u] != UINT32_MAX && m->synced[u] < at)
            return 0;
    return 1;
}

int model_draws(const host_model *m, tclod_id v) {
    return v < m->nodes && m->state[v] == ID_LIVE && m->kind[v] != KIND_EMPTY;
}

tclod_id drawn_parent(const host_model *m, tclod_id v) {
    tclod_id p = m->parent[v];
    while (p != TCLOD_NONE && m->kind[p] == KIND_EMPTY)
        p = m->parent[p];
    return p;
}

/* The k-th id (from 0) of state `state` below m->nodes; TCLOD_NONE if none. */
static tclod_id kth_node(const host_model *m, uint32_t k, int state) {
    uint32_t i;
    for (i = 0; i < m->nodes; ++i)
        if (m->state[i] == state && k-- == 0)
            return i;
    return TCLOD_NONE;
}

static uint32_t count_state(const host_model *m, int state) {
    uint32_t i, n = 0;
    for (i = 0; i < m->nodes; ++i)
        n += m->state[i] == state;
    return n;
}

static tclod_id kth_smooth(const host_model *m, uint32_t k) {
    uint32_t i;
    for (i = 0; i < m->smooth; ++i)
        if (m->smooth_state[i] == ID_LIVE && k-- == 0)
            return i;
    return TCLOD_NONE;
}

int same_bounds(const tclod_bounds *a, const tclod_bounds *b) {
    if (a->kind != b->kind)
        return 0;
    switch (a->kind) {
    case TCLOD_BOUNDS_NONE:
        return 1;
    case TCLOD_BOUNDS_SPHERE:
        return memcmp(a->center, b->center, sizeof a->center) == 0 &&
               memcmp(&a->radius, &b->radius, sizeof a->radius) == 0;
    case TCLOD_BOUNDS_AABB:
        return memcmp(a->center, b->center, sizeof a->center) == 0 &&
               memcmp(a->half_extents, b->half_extents, sizeof a->half_extents) == 0;
    case TCLOD_BOUNDS_OBB:
        return memcmp(a->center, b->center, sizeof a->center) == 0 &&
               memcmp(a->half_axes, b->half_axes, sizeof a->half_axes) == 0;
    default:
        return 0;
    }
}

static tclod_bounds float_sphere(const float b[4]) {
    return tclod_bounds_sphere((double)b[0], (double)b[1], (double)b[2], (double)b[3]);
}

void verify_scene(const host_model *m) {
    const tclod_scene *s = m->scene;
    static const tclod_id beyond[3] = {0u, 1u, 100u};
    tclod_bounds got, pattern;
    uint32_t i;
    FUZZ_CHECK(tclod_scene_node_count(s) == m->nodes && tclod_scene_smooth_count(s) == m->smooth,
               "the scene has %u node and %u smooth ids, the model %u and %u",
               (unsigned)tclod_scene_node_count(s), (unsigned)tclod_scene_smooth_count(s),
               (unsigned)m->nodes, (unsigned)m->smooth);
    memset(&pattern, 0x5a, sizeof pattern);
    for (i = 0; i < m->nodes; ++i) {
        int live = tclod_scene_node_live(s, i);
        tclod_status st;
        FUZZ_CHECK(live == (m->state[i] == ID_LIVE), "node %u live %d, the model says state %d",
                   (unsigned)i, live, (int)m->state[i]);
        got = pattern;
        st = tclod_scene_node_bounds(s, i, &got);
        if (m->state[i] == ID_LIVE) {
            FUZZ_CHECK(tclod_scene_parent(s, i) == m->parent[i], "parent of %u is %u, not %u",
                       (unsigned)i, (unsigned)tclod_scene_parent(s, i), (unsigned)m->parent[i]);
            FUZZ_CHECK(st == TCLOD_OK && same_bounds(&got, &m->bounds[i]),
                       "bounds of node %u read back as kind %d (status %d), added or moved as "
                       "kind %d",
                       (unsigned)i, (int)got.kind, (int)st, (int)m->bounds[i].kind);
        } else {
            FUZZ_CHECK(tclod_scene_parent(s, i) == TCLOD_NONE &&
                           memcmp(&got, &pattern, sizeof got) == 0 && st == TCLOD_ERR_ARG,
                       "node id %u (state %d) is not live, yet has a parent or bounds (%d)",
                       (unsigned)i, (int)m->state[i], (int)st);
        }
    }
    for (i = 0; i < 3; ++i)
        FUZZ_CHECK(!tclod_scene_node_live(s, m->nodes + beyond[i]) &&
                       !tclod_scene_smooth_live(s, m->smooth + beyond[i]),
                   "an id beyond the count is live");
    FUZZ_CHECK(!tclod_scene_node_live(s, TCLOD_NONE) && !tclod_scene_smooth_live(s, TCLOD_NONE),
               "TCLOD_NONE is live");
    for (i = 0; i < m->smooth; ++i)
        FUZZ_CHECK(tclod_scene_smooth_live(s, i) == (m->smooth_state[i] == ID_LIVE),
                   "smooth %u live %d, the model says state %d", (unsigned)i,
                   tclod_scene_smooth_live(s, i), (int)m->smooth_state[i]);
}

/* ---- callbacks ------------------------------------------------------------------ */

void probe_reset(probe *p, const tclod_view *view) {
    const host_model *m = p->m;
    const edit *held = p->held_edit;
    int any_view = p->any_view;
    memset(p, 0, sizeof *p);
    p->m = m;
    p->any_view = any_view;
    p->held_edit = held;
    p->frame_view = view;
}

/* Whether a query carries the frame's view: none when the frame has none,
 * else the same numbers (the library may hold a copy). */
int same_view(const tclod_view *q, const tclod_view *frame) {
    if (frame == NULL || q == NULL)
        return q == frame;
    /* field by field, bit for bit: the struct's padding is not compared */
    return memcmp(q->eye, frame->eye, sizeof q->eye) == 0 &&
           memcmp(q->forward, frame->forward, sizeof q->forward) == 0 &&
           memcmp(q->up, frame->up, sizeof q->up) == 0 &&
           memcmp(&q->fov_y, &frame->fov_y, sizeof q->fov_y) == 0 &&
           memcmp(&q->aspect, &frame->aspect, sizeof q->aspect) == 0 &&
           memcmp(&q->near_z, &frame->near_z, sizeof q->near_z) == 0 &&
           memcmp(&q->far_z, &frame->far_z, sizeof q->far_z) == 0 &&
           memcmp(&q->viewport_height, &frame->viewport_height, sizeof q->viewport_height) == 0;
}

int is_complexity_query(const tclod_query *q) {
    return q->view == NULL && q->screen_area != -1.0f;
}

/* A query's area and distance against the view helpers on volume b: -1
 * without view or volume; else the helpers' area (0 outside the frustum) and
 * distance, both as floats, bit for bit. */
static void check_measures(const tclod_query *q, const tclod_bounds *b, const char *what) {
    float area, distance;
    if (q->view == NULL || b == NULL || b->kind == TCLOD_BOUNDS_NONE) {
        FUZZ_CHECK(q->screen_area == -1.0f && q->distance == -1.0f,
                   "%s %u: no view or bounds, yet area %g distance %g", what, (unsigned)q->id,
                   (double)q->screen_area, (double)q->distance);
        return;
    }
    {
        /* the helpers' answer for the last view and volume asked (solvers ask
         * about one group at many resolutions, and each helper sets up the
         * view anew) */
        static tclod_view last_view;
        static tclod_bounds last_bounds;
        static float last_area, last_distance;
        static int filled;
        if (!filled || !same_view(&last_view, q->view) || !same_bounds(&last_bounds, b)) {
            last_view = *q->view;
            last_bounds = *b;
            last_area = tclod_view_bounds_visible(q->view, b)
                            ? (float)tclod_view_bounds_area(q->view, b)
                            : 0.0f;
            last_distance = (float)tclod_view_bounds_distance(q->view, b);
            filled = 1;
        }
        area = last_area;
        distance = last_distance;
    }
    FUZZ_CHECK(memcmp(&area, &q->screen_area, sizeof area) == 0 &&
                   memcmp(&distance, &q->distance, sizeof distance) == 0,
               "%s %u (bounds kind %d, centre %.9g %.9g %.9g, radius %.9g): area %.9g distance "
               "%.9g, the view helpers say %.9g %.9g",
               what, (unsigned)q->id, (int)b->kind, b->center[0], b->center[1], b->center[2],
               b->radius, (double)q->screen_area, (double)q->distance, (double)area,
               (double)distance);
}

void check_node_query(const probe *p, const tclod_query *q) {
    const host_model *m = p->m;
    const tclod_bounds *b;
    FUZZ_CHECK(model_draws(m, q->id), "node query about id %u (state %d, kind %d, of %u ids)",
               (unsigned)q->id, q->id < m->nodes ? (int)m->state[q->id] : -1,
               q->id < m->nodes ? (int)m->kind[q->id] : -1, (unsigned)m->nodes);
    FUZZ_CHECK(q->count == 1 && q->members == NULL, "node query with count %u", (unsigned)q->count);
    if (is_complexity_query(q))
        return;
    FUZZ_CHECK(p->any_view || same_view(q->view, p->frame_view),
               "node query without the frame's view");
    b = &m->bounds[q->id];
    if (b->kind == TCLOD_BOUNDS_NONE)
        FUZZ_CHECK(q->bounds == NULL, "node %u has no bounds, its query carries kind %d",
                   (unsigned)q->id, (int)q->bounds->kind);
    else
        FUZZ_CHECK(q->bounds != NULL && same_bounds(q->bounds, b),
                   "node %u: the query's volume (kind %d) is not the node's (kind %d)",
                   (unsigned)q->id, q->bounds ? (int)q->bounds->kind : -1, (int)b->kind);
    if (b->kind == TCLOD_BOUNDS_AABB || b->kind == TCLOD_BOUNDS_OBB)
        tally(b->kind == TCLOD_BOUNDS_AABB ? TALLY_QUERY_AABB : TALLY_QUERY_OBB);
    check_measures(q, b, "node");
}

/* The probe's held edit, once per select, from inside a callback. */
static void held_edit_now(probe *p) {
    if (p->held_edit && !p->held_edit_tried) {
        p->held_edit_tried = 1;
        try_held_edit(p->m, p->held_edit);
    }
}

double host_benefit(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    check_node_query(p, q);
    FUZZ_CHECK(!is_complexity_query(q), "benefit asked as a complexity");
    held_edit_now(p);
    v = p->m->benefit[q->id];
    if (p->m->view_dependent && q->screen_area >= 0.0f)
        v *= (double)q->screen_area; /* 0 outside the frustum: culled */
    p->benefit_calls[q->id]++;
    p->benefit_seen[q->id] = v;
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    return v;
}

/* The batch forms: each node asked through the per-node callbacks with the
 * query the batch describes (the node's own volume), so that every check of
 * a query holds for the batch's areas and distances too. */
static void batch_query(const probe *p, const tclod_batch *b, uint32_t i, tclod_query *q) {
    const tclod_bounds *v = &p->m->bounds[b->ids[i]];
    memset(q, 0, sizeof *q);
    q->id = b->ids[i];
    q->count = 1;
    q->view = b->view;
    q->screen_area = b->screen_area[i];
    q->distance = b->distance[i];
    q->bounds = v->kind == TCLOD_BOUNDS_NONE ? NULL : v;
}

/* Asks one() of every node of batch b, as its own query, into out[]. */
static void batch_through(void *user, const tclod_batch *b, double *out,
                          double (*one)(void *, const tclod_query *)) {
    uint32_t i;
    FUZZ_CHECK(b->worker == 0 && b->count > 0, "a serial batch of %u from worker %u",
               (unsigned)b->count, (unsigned)b->worker);
    for (i = 0; i < b->count; ++i) {
        tclod_query q;
        batch_query((const probe *)user, b, i, &q);
        out[i] = one(user, &q);
    }
}

void host_benefit_batch(void *user, const tclod_batch *b, double *out) {
    batch_through(user, b, out, host_benefit);
}

void host_cost_batch(void *user, const tclod_batch *b, double *out) {
    batch_through(user, b, out, host_cost);
}

double host_cost(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    check_node_query(p, q);
    held_edit_now(p);
    v = p->m->cost[q->id];
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    if (is_complexity_query(q)) {
        /* the Robin Hood solver's default complexity: asked only about a
         * finest level the frame found invisible or does not look at (below
         * a culled branch; else the frame's cost serves), and it counts as
         * the node's one cost call of the select */
        FUZZ_CHECK(p->any_view || p->benefit_calls[q->id] == 0 ||
                       (p->benefit_calls[q->id] == 1 &&
                        (!(p->benefit_seen[q->id] > 0.0) || fuzz_bad(p->benefit_seen[q->id]))),
                   "complexity of node %u asked as a cost after %u benefit calls (last %g)",
                   (unsigned)q->id, (unsigned)p->benefit_calls[q->id], p->benefit_seen[q->id]);
        p->cost_calls[q->id]++;
        return v;
    }
    FUZZ_CHECK(p->any_view || (p->benefit_calls[q->id] == 1 && p->benefit_seen[q->id] > 0.0),
               "cost of node %u asked after %u benefit calls (last %g)", (unsigned)q->id,
               (unsigned)p->benefit_calls[q->id], p->benefit_seen[q->id]);
    p->cost_calls[q->id]++;
    p->cost_seen[q->id] = v;
    return v;
}

static int smooth_live_id(const host_model *m, tclod_id id) {
    return id < m->smooth && m->smooth_state[id] == ID_LIVE;
}

double host_complexity(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    FUZZ_CHECK(q->view == NULL, "complexity asked with a view");
    held_edit_now(p);
    if (q->members) {
        FUZZ_CHECK(smooth_live_id(p->m, q->id) && q->members[0] == q->id && q->count == 1,
                   "complexity of smooth object %u", (unsigned)q->id);
        v = p->m->complexity[MAX_NODES + q->id];
    } else {
        FUZZ_CHECK(model_draws(p->m, q->id) && q->count == 1, "complexity of node %u",
                   (unsigned)q->id);
        v = p->m->complexity[q->id];
    }
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    return v;
}

/* Robin Hood's importance: the input's complexity values stand in (bad ones
 * included), asked about a node during the solve or about one smooth object. */
double host_importance(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    FUZZ_CHECK(!is_complexity_query(q), "importance asked as a complexity");
    held_edit_now(p);
    if (q->members) {
        FUZZ_CHECK(smooth_live_id(p->m, q->id) && q->members[0] == q->id && q->count == 1,
                   "importance of smooth object %u", (unsigned)q->id);
        FUZZ_CHECK(p->any_view || same_view(q->view, p->frame_view),
                   "smooth importance without the frame's view");
        v = p->m->complexity[MAX_NODES + q->id];
    } else {
        check_node_query(p, q);
        FUZZ_CHECK(p->any_view || (p->benefit_calls[q->id] == 1 && p->benefit_seen[q->id] > 0.0),
                   "importance of node %u asked after %u benefit calls (last %g)", (unsigned)q->id,
                   (unsigned)p->benefit_calls[q->id], p->benefit_seen[q->id]);
        v = p->m->complexity[q->id];
    }
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    return v;
}

/* The host's smooth value (cost != 0: cost) of a group at resolution r, the
 * sum over its members, and its slope in *d_dr. */
double smooth_value(const host_model *m, const tclod_query *q, double r, double *d_dr, int cost) {
    double sum = 0.0, slope = 0.0;
    uint32_t i;
    for (i = 0; i < q->count; ++i) {
        const smooth_model *o = &m->sm[q->members[i]];
        double v, d;
        if (!cost) {
            v = o->w * pow(r, o->p);
            d = o->w * o->p * pow(r, o->p - 1.0);
        } else if (r < o->kink) {
            v = o->steep * r;
            d = o->steep;
        } else {
            v = o->steep * o->kink + o->k * (r - o->kink);
            d = o->k;
        }
        if (o->dishonest)
            d = o->fake_slope;
        if (o->bad_kind == (cost ? 3 : 1))
            v = o->bad_value;
        if (o->bad_kind == (cost ? 4 : 2))
            d = o->bad_value;
        sum += v;
        slope += d;
    }
    *d_dr = slope;
    return sum;
}

/* The sphere of a smooth group's query: one that holds every member (to
 * float's rounding; a group of one may carry its object's own sphere or,
 * from the quadtree, one a little larger), so at the members' latest
 * places. */
static void check_smooth_volume(const host_model *m, const tclod_query *q) {
    const tclod_bounds *b = q->bounds;
    uint32_t i;
    FUZZ_CHECK(b != NULL && b->kind == TCLOD_BOUNDS_SPHERE,
               "smooth query %u (count %u) without a sphere (kind %d)", (unsigned)q->id,
               (unsigned)q->count, b ? (int)b->kind : -1);
    for (i = 0; i < q->count; ++i) {
        const float *o = m->smooth_bounds[q->members[i]];
        double d[3], dist, scale;
        int k;
        scale = b->radius + fabs(b->center[0]) + fabs(b->center[1]) + fabs(b->center[2]);
        for (k = 0; k < 3; ++k) {
            d[k] = (double)o[k] - b->center[k];
            scale += fabs((double)o[k]);
        }
        dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!isfinite(scale) || !isfinite(dist))
            continue; /* coordinates near float's end: no telling */
        FUZZ_CHECK(dist + (double)o[3] <= b->radius + 1e-5 * (scale + (double)o[3]),
                   "smooth group %u: member %u (r %.9g) lies %.9g from the group's centre, radius "
                   "%.9g",
                   (unsigned)q->id, (unsigned)q->members[i], (double)o[3], dist, b->radius);
    }
}

void check_smooth_query(const probe *p, const tclod_query *q, double r, const double *d_dr) {
    unsigned char seen[MAX_SMOOTH];
    uint32_t i;
    FUZZ_CHECK(d_dr != NULL, "smooth callback without d_dr");
    FUZZ_CHECK(r >= 1e-9 && r <= 1.0, "smooth callback at r = %.17g", r);
    FUZZ_CHECK(q->members != NULL && q->count >= 1 && q->count <= p->m->live_smooth &&
                   q->members[0] == q->id,
               "smooth query id %u count %u", (unsigned)q->id, (unsigned)q->count);
    memset(seen, 0, sizeof seen);
    for (i = 0; i < q->count; ++i) {
        FUZZ_CHECK(smooth_live_id(p->m, q->members[i]) && !seen[q->members[i]],
                   "member %u: not a live smooth object, or twice", (unsigned)q->members[i]);
        seen[q->members[i]] = 1;
    }
    if (is_complexity_query(q))
        return;
    if (!p->any_view)
        FUZZ_CHECK(same_view(q->view, p->frame_view), "smooth query without the frame's view");
    check_smooth_volume(p->m, q);
    check_measures(q, q->bounds, "smooth group");
}

double host_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    probe *p = (probe *)user;
    double v;
    check_smooth_query(p, q, r, d_dr);
    held_edit_now(p);
    v = smooth_value(p->m, q, r, d_dr, 0);
    p->calls++;
    p->bad += (uint32_t)(fuzz_bad(v) || fuzz_bad(*d_dr));
    return v;
}

double host_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    probe *p = (probe *)user;
    double v;
    check_smooth_query(p, q, r, d_dr);
    held_edit_now(p);
    v = smooth_value(p->m, q, r, d_dr, 1);
    p->calls++;
    p->bad += (uint32_t)(fuzz_bad(v) || fuzz_bad(*d_dr));
    return v;
}

/* ---- reading the input ------------------------------------------------------ */

/* An option value: 0 keeps the default, small bytes pick ordinary values,
 * the rest special ones (bad ones among them). */
double option_value(fuzz_reader *in, double def) {
    uint8_t b = fuzz_u8(in);
    if (b == 0 || b >= 64)
        return def;
    if (b < 16)
        return (double)b / 16.0;
    return fuzz_special_double(b);
}

int smooth_callbacks_missing(const tclod_selector_desc *d, uint32_t smooth) {
    return d->solver == TCLOD_SOLVER_MIXED && smooth > 0 &&
           (!d->callbacks.smooth_benefit || !d->callbacks.smooth_cost);
}

/* A real desc field whose 0 means the default: 0, TCLOD_OFF or in (lo, hi). */
static int defaulted_ok(double v, double lo, double hi) {
    return v == 0.0 || v == -1.0 || (v > lo && v < hi);
}

int desc_invalid(const tclod_selector_desc *d, uint32_t smooth) {
    if ((unsigned)d->solver > 2u || !d->callbacks.benefit || !d->callbacks.cost ||
        d->greedy.lookahead > TCLOD_MAX_LOOKAHEAD ||
        (d->greedy.restarts != TCLOD_OFF &&
         (d->greedy.restarts < 0 || d->greedy.restarts > TCLOD_MAX_RESTARTS)) ||
        (unsigned)d->overflow > (unsigned)TCLOD_OVERFLOW_DRAW_ROOTS)
        return 1;
    if (smooth_callbacks_missing(d, smooth))
        return 1;
    if (!defaulted_ok(d->mixed.split_threshold, 0.0, HUGE_VAL) ||
        !defaulted_ok(d->mixed.smooth_epsilon, 0.0, 1.0) ||
        !defaulted_ok(d->mixed.smooth_tolerance, 0.0, 1.0) ||
        !defaulted_ok(d->smooth_cull_area, 0.0, HUGE_VAL) ||
        (unsigned)d->robin_hood.value > (unsigned)TCLOD_VALUE_BENEFIT ||
        (unsigned)d->robin_hood.misfit > (unsigned)TCLOD_MISFIT_COARSEST ||
        !(d->robin_hood.reference_area == 0.0 ||
          (d->robin_hood.reference_area > 0.0 && d->robin_hood.reference_area < HUGE_VAL)))
        return 1;
    return 0;
}

/* A rate field: 0 (the default) or in (0, 1]. */
static int rate_ok(double r) {
    return r == 0.0 || (r > 0.0 && r <= 1.0);
}

int calib_desc_invalid(const tclod_calib_desc *c) {
    return !(c->initial_scale == 0.0 || (c->initial_scale > 0.0 && !isinf(c->initial_scale))) ||
           !rate_ok(c->rise_rate) || !rate_ok(c->fall_rate) ||
           !defaulted_ok(c->dead_band, 0.0, 1.0) || !rate_ok(c->logic_rate) ||
           !(c->initial_logic >= 0.0 && !isinf(c->initial_logic)) ||
           !(c->machine_c == 0.0 || (c->machine_c > 0.0 && !isinf(c->machine_c))) ||
           (c->initial_measured != 0 && c->initial_measured != 1);
}

void read_desc(fuzz_reader *in, tclod_selector_desc *d, host_model *m) {
    uint8_t solver = fuzz_u8(in), flags = fuzz_u8(in), enums = fuzz_u8(in), overflow;
    tclod_selector_desc_default(d);
    d->solver = solver >= 250 ? (tclod_solver)(solver - 247) /* 3 .. 8: unknown */
                              : (tclod_solver)(solver % 3u);
    if (solver < 250) { /* 0 .. 7, the most, or one more */
        uint32_t r = (uint32_t)(solver / 3u) % 10u;
        /* none, 1 .. 7, the most, or one more */
        d->greedy.restarts =
            r == 0 ? TCLOD_OFF : (r < 8u ? (int32_t)r : TCLOD_MAX_RESTARTS + (int32_t)r - 8);
    }
    d->cold_start = !(flags & 1);
    d->mixed.split_smooth = (flags >> 1) & 1;
    d->strict = (flags >> 2) & 1;
    d->mixed.plain_gradient = (flags >> 3) & 1;
    d->callbacks.benefit = host_benefit;
    d->callbacks.cost = host_cost;
    if (!((flags >> 4) & 1)) {
        d->callbacks.smooth_benefit = host_smooth_benefit;
        d->callbacks.smooth_cost = host_smooth_cost;
    }
    if ((flags >> 5) & 1) { /* and the importance, from the same values */
        d->callbacks.complexity = host_complexity;
        d->callbacks.importance = host_importance;
    }
    m->view_dependent = (flags >> 6) & 1;
    if (flags >> 7) /* 1 .. 3 levels, or one more than allowed */
        d->greedy.lookahead = enums >> 6 == 3 ? TCLOD_MAX_LOOKAHEAD + 1u : 1u + (enums >> 6);
    if (flags == 0xff) /* the required callbacks missing */
        d->callbacks.cost = NULL;
    d->robin_hood.value = (tclod_value)(enums % 6u);          /* 5: unknown */
    d->robin_hood.misfit = (tclod_misfit)((enums >> 3) % 3u); /* 2: unknown */
    d->mixed.split_threshold = option_value(in, d->mixed.split_threshold);
    d->mixed.smooth_epsilon = option_value(in, d->mixed.smooth_epsilon);
    d->mixed.smooth_tolerance = option_value(in, d->mixed.smooth_tolerance);
    d->smooth_cull_area = option_value(in, d->smooth_cull_area);
    d->robin_hood.reference_area = option_value(in, d->robin_hood.reference_area);
    overflow = fuzz_u8(in); /* 0xff: unknown */
    d->overflow = overflow == 0xff ? (tclod_overflow)2 : (tclod_overflow)(overflow & 1u);
}

int bounds_bad(const float b[4]) {
    return !isfinite(b[0]) || !isfinite(b[1]) || !isfinite(b[2]) || !isfinite(b[3]) || b[3] < 0.0f;
}

/* A smooth object's sphere is also refused beyond TCLOD_SMOOTH_LIMIT. */
static int smooth_bounds_bad(const float b[4]) {
    return bounds_bad(b) || fabsf(b[0]) > TCLOD_SMOOTH_LIMIT || fabsf(b[1]) > TCLOD_SMOOTH_LIMIT ||
           fabsf(b[2]) > TCLOD_SMOOTH_LIMIT || b[3] > TCLOD_SMOOTH_LIMIT;
}

void read_bounds(fuzz_reader *in, float b[4]) {
    int k;
    for (k = 0; k < 3; ++k)
        b[k] = fuzz_float(in);
    b[3] = fabsf(fuzz_float(in)) * (fuzz_u8(in) == 0x80 ? -1.0f : 1.0f);
}

static int finite3(const double v[3]) {
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

int bounds_verdict(const tclod_bounds *b) {
    double len[3], sum;
    int i, j;
    switch (b->kind) {
    case TCLOD_BOUNDS_NONE:
        return 0;
    case TCLOD_BOUNDS_SPHERE:
        return finite3(b->center) && isfinite(b->radius) && b->radius >= 0.0 ? 0 : 1;
    case TCLOD_BOUNDS_AABB:
        if (!finite3(b->center) || !finite3(b->half_extents) || !(b->half_extents[0] >= 0.0) ||
            !(b->half_extents[1] >= 0.0) || !(b->half_extents[2] >= 0.0))
            return 1;
        sum = b->half_extents[0] * b->half_extents[0] + b->half_extents[1] * b->half_extents[1] +
              b->half_extents[2] * b->half_extents[2];
        return isfinite(sum) ? 0 : -1; /* the corners' distance overflows: open */
    case TCLOD_BOUNDS_OBB:
        if (!finite3(b->center))
            return 1;
        for (i = 0; i < 3; ++i)
            if (!finite3(b->half_axes[i]))
                return 1;
        for (i = 0; i < 3; ++i) {
            const double *a = b->half_axes[i];
            int nonzero = a[0] != 0.0 || a[1] != 0.0 || a[2] != 0.0;
            len[i] = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            /* lengths that overflow or underflow: the header says nothing */
            if (!isfinite(len[i]) || len[i] > 1e150 || (nonzero && len[i] < 1e-150))
                return -1;
        }
        for (i = 0; i < 3; ++i)
            for (j = i + 1; j < 3; ++j) {
                const double *a = b->half_axes[i], *c = b->half_axes[j];
                double cosine;
                if (len[i] == 0.0 || len[j] == 0.0)
                    continue; /* zero axes: a flat box */
                cosine = fabs(a[0] * c[0] + a[1] * c[1] + a[2] * c[2]) / (len[i] * len[j]);
                if (cosine > 1e-3 * (1.0 + 1e-6))
                    return 1;
                if (cosine >= 1e-3 * (1.0 - 1e-6))
                    return -1; /* at the tolerance: rounding decides */
            }
        return 0;
    default:
        return 1;
    }
}

/* A length: fuzz_float's magnitudes. */
static double read_length(fuzz_reader *in) {
    return fabs((double)fuzz_float(in));
}

/* A rotation matrix (columns are the axes) from the input: the identity, a
 * turn about one world axis, three turns, or a signed permutation. */
static void read_rotation(fuzz_reader *in, double r[3][3]) {
    static const double turn = 6.283185307179586 / 256.0;
    uint8_t b = fuzz_u8(in);
    int i, j;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            r[i][j] = i == j;
    switch (b & 3u) {
    case 1: {
        int a = (b >> 2) % 3, u = (a + 1) % 3, v = (a + 2) % 3;
        double t = turn * fuzz_u8(in);
        r[u][u] = cos(t);
        r[u][v] = -sin(t);
        r[v][u] = sin(t);
        r[v][v] = cos(t);
        break;
    }
    case 2: {
        double x = turn * fuzz_u8(in), y = turn * fuzz_u8(in), z = turn * fuzz_u8(in);
        double cx = cos(x), sx = sin(x), cy = cos(y), sy = sin(y), cz = cos(z), sz = sin(z);
        /* Rz Ry Rx */
        r[0][0] = cz * cy;
        r[0][1] = cz * sy * sx - sz * cx;
        r[0][2] = cz * sy * cx + sz * sx;
        r[1][0] = sz * cy;
        r[1][1] = sz * sy * sx + cz * cx;
        r[1][2] = sz * sy * cx - cz * sx;
        r[2][0] = -sy;
        r[2][1] = cy * sx;
        r[2][2] = cy * cx;
        break;
    }
    case 3: {
        static const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                        {1, 0, 2}, {0, 2, 1}, {2, 1, 0}};
        const int *pm = perms[(b >> 2) % 6u];
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j)
                r[i][j] = (pm[j] == i) ? ((b >> (5 + j % 3)) & 1 ? -1.0 : 1.0) : 0.0;
        break;
    }
    default:
        break;
    }
}

/* Volume of shape 1 (a sphere in double), 2 (an axis-aligned box) or 3 (an
 * oriented box), then a byte that may spoil it. */
static void read_shape(fuzz_reader *in, int shape, tclod_bounds *b) {
    static const double skews[8] = {5e-4, 9.99e-4, 1.001e-3, 2e-3, 0.1, 1.0, 1e-7, 0.0};
    double c[3], h[3], r[3][3], axes[9];
    uint8_t spoil, at;
    int k, i;
    for (k = 0; k < 3; ++k)
        c[k] = (double)fuzz_float(in);
    if (shape == 1) {
        *b = tclod_bounds_sphere(c[0], c[1], c[2], read_length(in));
    } else if (shape == 2) {
        for (k = 0; k < 3; ++k)
            h[k] = read_length(in);
        *b = tclod_bounds_aabb(c, h);
    } else {
        uint8_t skew;
        read_rotation(in, r);
        for (k = 0; k < 3; ++k)
            h[k] = read_length(in);
        for (i = 0; i < 3; ++i)
            for (k = 0; k < 3; ++k)
                axes[3 * i + k] = h[i] * r[k][i];
        skew = fuzz_u8(in);
        if ((skew & 0xf0) == 0xf0) /* axis 1 leans towards axis 0 */
            for (k = 0; k < 3; ++k)
                axes[3 + k] += skews[skew & 7u] * h[1] * r[k][0];
        *b = tclod_bounds_obb(c, axes);
    }
    spoil = fuzz_u8(in);
    if (spoil < 0x80 || spoil > 0x86)
        return;
    at = fuzz_u8(in);
    {
        /* the field spoiled: the radius, a half extent or a component of a
         * half axis, or the centre */
        double *field = shape == 1   ? &b->radius
                        : shape == 2 ? &b->half_extents[at % 3u]
                                     : &b->half_axes[at % 3u][(at / 3u) % 3u];
        switch (spoil) {
        case 0x80:
            *field = -*field - 1.0; /* negative (an axis component: still a box) */
            break;
        case 0x81:
            *field = (double)NAN;
            break;
        case 0x82:
            *field = (at & 0x80) ? -(double)INFINITY : (double)INFINITY;
            break;
        case 0x83:
            *field = 1e300; /* finite, but the corners' distance overflows */
            break;
        case 0x84:
            b->center[at % 3u] = (at & 0x80) ? -1e300 : (double)NAN;
            break;
        case 0x85:
            b->kind = (tclod_bounds_kind)(4 + (at & 1u)); /* unknown kind */
            break;
        default:
            *field = 0.0; /* a flat box, a point */
            break;
        }
    }
}

int read_node_bounds(fuzz_reader *in, tclod_bounds *b) {
    uint8_t shape = fuzz_u8(in);
    memset(b, 0, sizeof *b);
    switch (shape % 5u) {
    case 0:
        b->kind = TCLOD_BOUNDS_NONE;
        break;
    case 1: {
        float sphere[4];
        read_bounds(in, sphere);
        *b = float_sphere(sphere);
        break;
    }
    default:
        read_shape(in, (int)(shape % 5u) - 1, b);
        break;
    }
    return bounds_verdict(b);
}

/* The index of an item among n from byte b and, when n is larger than the
 * span one byte reaches, another byte. */
static uint32_t pick(fuzz_reader *in, uint32_t b, uint32_t n, uint32_t span) {
    if (n > span)
        b += span * (uint32_t)fuzz_u8(in);
    return b % n;
}

/* A parent: a live node, a root, an id that is removed or hidden, or one
 * that does not exist. */
static tclod_id read_parent(fuzz_reader *in, const host_model *m) {
    uint8_t b = fuzz_u8(in);
    if (b == 0xff || m->nodes == 0)
        return b == 0xfe ? m->nodes : TCLOD_NONE;
    if (b == 0xfe)
        return m->nodes + fuzz_u8(in); /* not yet created */
    if (b == 0xfd)
        return TCLOD_NONE - 1u;
    if (b >= 0xe0 || m->live_nodes == 0) /* any id: removed and hidden ones too */
        return pick(in, b - 0xe0u, m->nodes, 29u);
    return kth_node(m, pick(in, b, m->live_nodes, 0xe0u), ID_LIVE);
}

/* A node id to edit: mostly a live node; else any id below the count, a
 * hidden one, or one beyond. */
static tclod_id read_node_id(fuzz_reader *in, const host_model *m) {
    uint8_t b = fuzz_u8(in);
    if (b < 0xc0 && m->live_nodes > 0)
        return kth_node(m, pick(in, b, m->live_nodes, 0xc0u), ID_LIVE);
    if (b < 0xf0 && m->nodes > 0)
        return pick(in, b - 0xc0u, m->nodes, 0x30u);
    switch (b & 3u) {
    case 0:
        return m->nodes;
    case 1:
        return TCLOD_NONE;
    case 2: {
        uint32_t hidden = count_state(m, ID_HIDDEN);
        return hidden ? kth_node(m, fuzz_u8(in) % hidden, ID_HIDDEN) : m->nodes + 1u;
    }
    default:
        return m->nodes + 100u;
    }
}

static tclod_id read_smooth_id(fuzz_reader *in, const host_model *m) {
    uint8_t b = fuzz_u8(in);
    if (b < 0xc0 && m->live_smooth > 0)
        return kth_smooth(m, b % m->live_smooth);
    if (b < 0xf0 && m->smooth > 0)
        return (b - 0xc0u) % m->smooth;
    return (b & 1u) ? TCLOD_NONE : m->smooth + (b & 6u);
}

void read_node_spec(fuzz_reader *in, const host_model *m, node_spec *ns) {
    uint8_t k;
    int has_bounds, shape, nk, alt;
    memset(ns, 0, sizeof *ns);
    tclod_node_desc_default(&ns->desc);
    ns->desc.parent = read_parent(in, m);
    /* bit 0: bounds; bits 1-2: their shape (a float sphere, a double one, an
     * axis-aligned box, an oriented box); bits 3-4: replace (0, 1), additive
     * (2) or empty (3); bit 5: the desc form for what the short form could
     * add, or an empty node refined additively; bits 5-7 all set on an empty
     * node: refine or empty out of range */
    k = fuzz_u8(in);
    has_bounds = k & 1;
    shape = (k >> 1) & 3;
    nk = (k >> 3) & 3;
    alt = (k >> 5) & 1;
    if (has_bounds) {
        if (shape == 0) {
            read_bounds(in, ns->sphere);
            ns->has_sphere = 1;
            ns->desc.bounds = float_sphere(ns->sphere);
        } else {
            read_shape(in, shape, &ns->desc.bounds);
        }
    }
    ns->verdict = bounds_verdict(&ns->desc.bounds);
    if (ns->has_sphere) /* what the short form checks: floats */
        ns->verdict = bounds_bad(ns->sphere);
    ns->desc.refine = nk == 2 || (nk == 3 && alt) ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
    ns->desc.empty = nk == 3;
    ns->short_form = nk <= 1 && !alt && (!has_bounds || shape == 0);
    if (nk == 3 && (k >> 5) == 7) {
        ns->bad_enum = 1;
        if (k & 4)
            ns->desc.refine = (tclod_refine)(2 + (k & 2));
        else
            ns->desc.empty = (k & 2) ? -1 : 2;
    }
    ns->benefit = fuzz_double(in);
    ns->cost = fuzz_double(in);
    ns->complexity = fuzz_double(in);
}

void read_smooth_spec(fuzz_reader *in, smooth_spec *ss) {
    static const double powers[8] = {0.5, 0.25, 1.0, 0.75, 2.0, 0.5, 0.125, 1.0};
    smooth_model *o = &ss->sm;
    uint8_t mode;
    memset(ss, 0, sizeof *ss);
    read_bounds(in, ss->bounds);
    mode = fuzz_u8(in);
    o->w = fuzz_double(in);
    o->p = powers[mode & 7u];
    o->k = fuzz_double(in);
    o->steep = (mode & 8u) ? o->k * (1.0 + (double)(mode >> 4)) : o->k;
    o->kink = (mode & 8u) ? 1.0 / (2.0 + (double)(mode >> 4)) : 0.0;
    o->dishonest = fuzz_u8(in) == 0x5a;
    o->fake_slope = o->dishonest ? fuzz_double(in) : 0.0;
    o->bad_kind = (mode >> 4) < 5 && (mode & 8u) == 0 ? (mode >> 4) : 0;
    o->bad_value = o->bad_kind ? fuzz_double(in) : 0.0;
    ss->complexity = fuzz_double(in);
}

void read_edit(fuzz_reader *in, const host_model *m, edit *e) {
    uint8_t op = fuzz_u8(in);
    memset(e, 0, sizeof *e);
    e->op = op % 8u;
    switch (e->op) {
    case EDIT_REMOVE_NODE:
    case EDIT_REMOVE_TWICE:
        e->id = read_node_id(in, m);
        break;
    case EDIT_REMOVE_SMOOTH:
        e->id = read_smooth_id(in, m);
        break;
    case EDIT_MOVE_NODE:
        e->id = read_node_id(in, m);
        e->null_bounds = (op >> 3) == 0x1f;
        if (!e->null_bounds)
            e->verdict = read_node_bounds(in, &e->bounds);
        break;
    case EDIT_MOVE_SMOOTH:
        e->id = read_smooth_id(in, m);
        read_bounds(in, e->sphere);
        break;
    case EDIT_ADD_NODE:
        read_node_spec(in, m, &e->node);
        break;
    case EDIT_ADD_SMOOTH:
        read_smooth_spec(in, &e->smooth);
        break;
    default: { /* EDIT_HIDDEN */
        uint32_t hidden = count_state(m, ID_HIDDEN);
        uint8_t b = fuzz_u8(in);
        e->sub = (uint8_t)((op >> 3) % 3u);
        e->id = hidden ? kth_node(m, b % hidden, ID_HIDDEN) : m->nodes + b;
        if (e->sub == 1)
            e->verdict = read_node_bounds(in, &e->bounds);
        else if (e->sub == 2)
            read_node_spec(in, m, &e->node);
        break;
    }
    }
}

/* ---- edits ------------------------------------------------------------------------- */

/* FUZZ_TRACE=1 in the environment: each scene call and its status. */
static int tracing = -1;

static const char *status_name(tclod_status st) {
    return tclod_status_string(st);
}

/* Whether status st is what the header promises for an edit: bad_arg and
 * bad_hier say which errors its arguments give, open that TCLOD_ERR_ARG is
 * allowed beside success; a held scene refuses with TCLOD_ERR_STATE (or the
 * edit's own error). */
static void expect(tclod_status st, int bad_arg, int bad_hier, int open, int held, const char *what,
                   tclod_id id) {
    int ok;
    if (held)
        ok = st == TCLOD_ERR_STATE || (st == TCLOD_ERR_ARG && (bad_arg || open)) ||
             (st == TCLOD_ERR_HIERARCHY && bad_hier);
    else if (bad_arg || bad_hier)
        ok = (st == TCLOD_ERR_ARG && (bad_arg || open)) || (st == TCLOD_ERR_HIERARCHY && bad_hier);
    else
        ok = st == TCLOD_OK || (st == TCLOD_ERR_ARG && open);
    if (tracing < 0)
        tracing = getenv("FUZZ_TRACE") != NULL;
    if (tracing)
        fprintf(stderr, "  %s%s %u: %s\n", held ? "(held) " : "", what, (unsigned)id,
                status_name(st));
    FUZZ_CHECK(ok, "%s %u gave %s (bad argument %d, bad parent %d, open %d, held %d)", what,
               (unsigned)id, status_name(st), bad_arg, bad_hier, open, held);
    tally(st == TCLOD_OK ? TALLY_EDIT_OK
                         : (st == TCLOD_ERR_STATE ? TALLY_HELD_REFUSED : TALLY_EDIT_REFUSED));
}

static int node_live_model(const host_model *m, tclod_id id) {
    return id < m->nodes && m->state[id] == ID_LIVE;
}

/* Whether v is x or below it in the host's tree. */
static int in_subtree(const host_model *m, tclod_id v, tclod_id x) {
    while (v != TCLOD_NONE) {
        if (v == x)
            return 1;
        v = m->parent[v];
    }
    return 0;
}

static void remove_node(host_model *m, tclod_id id, int held) {
    tclod_status st = tclod_scene_remove_node(m->scene, id);
    int bad = !node_live_model(m, id);
    uint32_t i;
    expect(st, bad, 0, 0, held, "remove_node", id);
    if (st != TCLOD_OK)
        return;
    /* the subtree, hidden ids included, removed at a new epoch (the walk
     * reads parents only, which removal leaves as they were) */
    m->epoch++;
    tally(TALLY_REMOVED_SUBTREE);
    for (i = 0; i < m->nodes; ++i) {
        tclod_id h;
        if (m->state[i] != ID_LIVE || !in_subtree(m, i, id))
            continue;
        m->state[i] = ID_REMOVED;
        m->removed_at[i] = m->epoch;
        m->live_nodes--;
        h = m->hidden[i];
        if (h != TCLOD_NONE && h != HIDDEN_UNKNOWN) {
            m->state[h] = ID_REMOVED;
            m->removed_at[h] = m->epoch;
        }
    }
}

static void remove_smooth(host_model *m, tclod_id id, int held) {
    tclod_status st = tclod_scene_remove_smooth(m->scene, id);
    int bad = !smooth_live_id(m, id);
    expect(st, bad, 0, 0, held, "remove_smooth", id);
    if (st != TCLOD_OK)
        return;
    m->epoch++;
    m->smooth_state[id] = ID_REMOVED;
    m->smooth_removed_at[id] = m->epoch;
    m->live_smooth--;
}

static void move_node(host_model *m, tclod_id id, const tclod_bounds *b, int verdict, int held) {
    tclod_status st = tclod_scene_set_node_bounds(m->scene, id, b);
    if (verdict == 1 && st == TCLOD_ERR_ARG)
        tally(TALLY_BAD_BOUNDS);
    expect(st, !node_live_model(m, id) || verdict == 1, 0, verdict == -1, held, "set_node_bounds",
           id);
    if (st != TCLOD_OK)
        return;
    if (b)
        m->bounds[id] = *b;
    else
        memset(&m->bounds[id], 0, sizeof m->bounds[id]);
}

static void move_smooth(host_model *m, tclod_id id, const float sphere[4], int held) {
    tclod_status st = tclod_scene_set_smooth_bounds(m->scene, id, sphere);
    expect(st, !smooth_live_id(m, id) || smooth_bounds_bad(sphere), 0, 0, held, "set_smooth_bounds",
           id);
    if (st != TCLOD_OK)
        return;
    memcpy(m->smooth_bounds[id], sphere, sizeof m->smooth_bounds[id]);
}

/* Adds the node ns describes. */
static void add_node_spec(host_model *m, const node_spec *ns, int held) {
    tclod_id id = 12345u, parent = ns->desc.parent;
    uint32_t old = m->nodes, now, growth, fresh;
    int bad_parent =
        parent != TCLOD_NONE && (!node_live_model(m, parent) || m->unexpanded[parent]);
    int bad_arg = ns->verdict == 1 || ns->bad_enum || (ns->desc.unexpanded && ns->desc.empty),
        additive;
    tclod_status st;
    if (m->nodes + 2u > MAX_NODES)
        return; /* the model's id space is full */
    if (ns->short_form)
        st = tclod_scene_add_node(m->scene, parent, ns->has_sphere ? ns->sphere : NULL, &id);
    else
        st = tclod_scene_add_node_desc(m->scene, &ns->desc, &id);
    if (ns->verdict == 1 && st == TCLOD_ERR_ARG)
        tally(TALLY_BAD_BOUNDS);
    expect(st, bad_arg, bad_parent, ns->verdict == -1, held,
           ns->short_form ? "add_node under" : "add_node_desc under", parent);
    if (st != TCLOD_OK) {
        FUZZ_CHECK(id == 12345u, "a failed add wrote the id");
        return;
    }
    /* the id: the next fresh one, or a removed one every user has solved
     * since; an additive node takes a second, hidden one */
    now = tclod_scene_node_count(m->scene);
    growth = now - old;
    additive = ns->desc.refine == TCLOD_REFINE_ADD && !ns->desc.empty;
    fresh = id >= old;
    if (fresh) {
        FUZZ_CHECK(id == old, "new node %u, the next fresh id is %u", (unsigned)id, (unsigned)old);
    } else {
        FUZZ_CHECK(m->state[id] == ID_REMOVED && model_reuse_allowed(m, m->removed_at[id]),
                   "new node %u: an id in state %d (removed at %u; users last solved at %u, %u)",
                   (unsigned)id, (int)m->state[id], (unsigned)m->removed_at[id],
                   (unsigned)m->synced[0], (unsigned)m->synced[1]);
        tally(TALLY_NODE_ID_REUSED);
    }
    FUZZ_CHECK(now >= old && growth >= fresh && growth - fresh <= (uint32_t)additive,
               "adding a%s node took the node count from %u to %u (id %u)",
               additive ? "n additive" : "", (unsigned)old, (unsigned)now, (unsigned)id);
    FUZZ_CHECK(now <= MAX_NODES, "node count %u", (unsigned)now);
    m->nodes = now;
    m->state[id] = ID_LIVE;
    m->kind[id] = ns->desc.empty ? KIND_EMPTY : (additive ? KIND_ADD : KIND_REPLACE);
    m->parent[id] = parent;
    m->unexpanded[id] = (uint8_t)ns->desc.unexpanded;
    m->hidden[id] = TCLOD_NONE;
    if (additive) {
        if (growth > fresh) { /* a fresh hidden id, the last */
            tclod_id h = now - 1u;
            m->state[h] = ID_HIDDEN;
            m->hidden[h] = id;
            m->hidden[id] = h;
            tally(TALLY_HIDDEN_KNOWN);
        } else {
            m->hidden[id] = HIDDEN_UNKNOWN;
            tally(TALLY_HIDDEN_UNKNOWN);
        }
    }
    if (ns->short_form && !ns->has_sphere)
        memset(&m->bounds[id], 0, sizeof m->bounds[id]);
    else
        m->bounds[id] = ns->desc.bounds;
    m->benefit[id] = ns->benefit;
    m->cost[id] = ns->cost;
    m->complexity[id] = ns->complexity;
    m->live_nodes++;
}

static void add_smooth_spec(host_model *m, const smooth_spec *ss, int held) {
    tclod_id id = 12345u;
    uint32_t old = m->smooth;
    tclod_status st;
    if (m->smooth + 1u > MAX_SMOOTH)
        return;
    st = tclod_scene_add_smooth(m->scene, ss->bounds, &id);
    expect(st, smooth_bounds_bad(ss->bounds), 0, 0, held, "add_smooth", 0);
    if (st != TCLOD_OK) {
        FUZZ_CHECK(id == 12345u, "a failed add_smooth wrote the id");
        return;
    }
    if (id >= old) {
        FUZZ_CHECK(id == old && tclod_scene_smooth_count(m->scene) == old + 1u,
                   "new smooth object %u, count %u, the next fresh id is %u", (unsigned)id,
                   (unsigned)tclod_scene_smooth_count(m->scene), (unsigned)old);
    } else {
        FUZZ_CHECK(m->smooth_state[id] == ID_REMOVED &&
                       model_reuse_allowed(m, m->smooth_removed_at[id]) &&
                       tclod_scene_smooth_count(m->scene) == old,
                   "new smooth object %u: an id in state %d (removed at %u; users last solved at "
                   "%u, %u)",
                   (unsigned)id, (int)m->smooth_state[id], (unsigned)m->smooth_removed_at[id],
                   (unsigned)m->synced[0], (unsigned)m->synced[1]);
        tally(TALLY_SMOOTH_ID_REUSED);
    }
    m->smooth = tclod_scene_smooth_count(m->scene);
    m->smooth_state[id] = ID_LIVE;
    memcpy(m->smooth_bounds[id], ss->bounds, sizeof m->smooth_bounds[id]);
    m->sm[id] = ss->sm;
    m->complexity[MAX_NODES + id] = ss->complexity;
    m->live_smooth++;
}

/* One edit; held: the model is not written (nothing may change). */
static void apply(host_model *m, const edit *e, int held) {
    switch (e->op) {
    case EDIT_REMOVE_NODE:
        remove_node(m, e->id, held);
        break;
    case EDIT_REMOVE_TWICE:
        remove_node(m, e->id, held);
        if (!held) /* removed now, or never live: no longer live either way */
            remove_node(m, e->id, held);
        break;
    case EDIT_REMOVE_SMOOTH:
        remove_smooth(m, e->id, held);
        break;
    case EDIT_MOVE_NODE:
        move_node(m, e->id, e->null_bounds ? NULL : &e->bounds, e->null_bounds ? 0 : e->verdict,
                  held);
        break;
    case EDIT_MOVE_SMOOTH:
        move_smooth(m, e->id, e->sphere, held);
        break;
    case EDIT_ADD_NODE:
        add_node_spec(m, &e->node, held);
        break;
    case EDIT_ADD_SMOOTH:
        add_smooth_spec(m, &e->smooth, held);
        break;
    default: /* EDIT_HIDDEN: not live, so every edit of it is refused */
        FUZZ_CHECK(!tclod_scene_node_live(m->scene, e->id) &&
                       tclod_scene_parent(m->scene, e->id) == TCLOD_NONE,
                   "hidden id %u is live or has a parent", (unsigned)e->id);
        if (e->sub == 0) {
            remove_node(m, e->id, held);
        } else if (e->sub == 1) {
            move_node(m, e->id, &e->bounds, e->verdict, held);
        } else {
            node_spec ns = e->node;
            ns.desc.parent = e->id;
            add_node_spec(m, &ns, held);
        }
        break;
    }
}

void try_edit(host_model *m, const edit *e, int held) {
    if (held) {
        try_held_edit(m, e);
        return;
    }
    apply(m, e, 0);
    m->edits++;
    verify_scene(m);
}

void try_held_edit(const host_model *m, const edit *e) {
    /* apply() writes the model only on success, which a held scene must
     * refuse: expect() stops the run first */
    apply((host_model *)(uintptr_t)m, e, 1);
    verify_scene(m);
}

void add_node(fuzz_reader *in, host_model *m) {
    node_spec ns;
    read_node_spec(in, m, &ns);
    add_node_spec(m, &ns, 0);
}

void add_unexpanded(fuzz_reader *in, host_model *m) {
    node_spec ns;
    read_node_spec(in, m, &ns);
    ns.short_form = 0;
    ns.bad_enum = 0;
    ns.desc.refine = TCLOD_REFINE_REPLACE;
    ns.desc.empty = (fuzz_u8(in) & 7u) == 0;
    ns.desc.unexpanded = 1;
    add_node_spec(m, &ns, 0);
}

void add_smooth(fuzz_reader *in, host_model *m) {
    smooth_spec ss;
    read_smooth_spec(in, &ss);
    add_smooth_spec(m, &ss, 0);
}

/* ---- frames ------------------------------------------------------------------ */

/* Whether the header requires tclod_view_validate to accept (1) or reject
 * (0) v; -1 when forward and up are so close to parallel that either is
 * right. */
int view_valid(const tclod_view *v) {
    double f[3], u[3], c[3], lf, lu;
    int k;
    for (k = 0; k < 3; ++k)
        if (!isfinite(v->eye[k]) || !isfinite(v->forward[k]) || !isfinite(v->up[k]))
            return 0;
    if (!isfinite(v->fov_y) || !isfinite(v->aspect) || !isfinite(v->near_z) ||
        !isfinite(v->far_z) || !isfinite(v->viewport_height))
        return 0;
    if (!(v->fov_y > 0.0f) || !((double)v->fov_y < 3.14159265358979323846) || !(v->aspect > 0.0f) ||
        !(v->near_z > 0.0f) || !(v->far_z > v->near_z) || !(v->viewport_height > 0.0f))
        return 0;
    for (k = 0; k < 3; ++k) {
        f[k] = (double)v->forward[k];
        u[k] = (double)v->up[k];
    }
    lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(lf > 0.0) || !(lu > 0.0))
        return 0;
    c[0] = (f[1] * u[2] - f[2] * u[1]) / (lf * lu);
    c[1] = (f[2] * u[0] - f[0] * u[2]) / (lf * lu);
    c[2] = (f[0] * u[1] - f[1] * u[0]) / (lf * lu);
    lf = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (lf == 0.0)
        return 0;
    return lf > 1e-3 ? 1 : -1;
}

/* A view: none, one of the shared flyover loop's, or one made of the input. */
const tclod_view *read_view(fuzz_reader *in, tclod_view *v) {
    uint8_t b = fuzz_u8(in);
    world_path path;
    if (b < 64)
        return NULL;
    if (b < 192) {
        memset(&path, 0, sizeof path);
        path.radius = 60.0f;
        path.wobble = 10.0f;
        path.altitude = 20.0f;
        path.altitude_swing = 5.0f;
        path.pitch = 0.3f;
        path.fov_y = 1.0f;
        path.aspect = 16.0f / 9.0f;
        path.near_z = 0.5f;
        path.far_z = 400.0f;
        path.viewport_height = 720.0f;
        world_camera_at(&path, (double)(b - 64) / 128.0, v);
        return v;
    }
    {
        int k;
        for (k = 0; k < 3; ++k) {
            v->eye[k] = fuzz_float(in);
            v->forward[k] = fuzz_float(in);
            v->up[k] = fuzz_float(in);
        }
        v->fov_y = (float)option_value(in, 1.0);
        v->aspect = (float)option_value(in, 1.5);
        v->near_z = (float)option_value(in, 0.1);
        v->far_z = (float)option_value(in, 1000.0);
        v->viewport_height = (float)option_value(in, 1080.0);
    }
    return v;
}

/* The view helpers on a valid view and the nodes' and smooth objects'
 * bounds: areas in [0, viewport area], distances >= 0, never NaN. */
void check_view_helpers(const tclod_view *v, const host_model *m) {
    double viewport = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
    uint32_t i;
    for (i = 0; i < m->nodes; ++i) {
        const tclod_bounds *b = &m->bounds[i];
        double area, distance;
        int visible;
        if (m->state[i] != ID_LIVE || b->kind == TCLOD_BOUNDS_NONE)
            continue;
        area = tclod_view_bounds_area(v, b);
        distance = tclod_view_bounds_distance(v, b);
        visible = tclod_view_bounds_visible(v, b);
        FUZZ_CHECK(area >= 0.0 && area <= viewport, "node %u (kind %d): screen area %g of %g",
                   (unsigned)i, (int)b->kind, area, viewport);
        FUZZ_CHECK(distance >= 0.0, "node %u (kind %d): distance %g", (unsigned)i, (int)b->kind,
                   distance);
        FUZZ_CHECK(visible == 0 || visible == 1, "visible %d", visible);
    }
    for (i = 0; i < m->smooth; ++i) {
        const float *bounds = m->smooth_bounds[i];
        float area, distance;
        int visible;
        if (m->smooth_state[i] != ID_LIVE)
            continue;
        area = tclod_view_screen_area(v, bounds);
        distance = tclod_view_distance(v, bounds);
        visible = tclod_view_sphere_visible(v, bounds);
        FUZZ_CHECK(area >= 0.0f && area <= (float)viewport, "screen area %g of %g", (double)area,
                   viewport);
        FUZZ_CHECK(distance >= 0.0f, "distance %g", (double)distance);
        FUZZ_CHECK(visible == 0 || visible == 1, "visible %d", visible);
    }
}
