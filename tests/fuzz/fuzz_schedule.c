/*
 * fuzz_schedule — libFuzzer target over the predictive geomorph scheduler
 * (tclod_scheduler_*, tclod_conservative_view), driven by byte-chosen
 * descriptions, scenes, views, times, budgets, slices and measured render
 * times.
 *
 * The scene and the callbacks are fuzz_host's (node kinds replace, additive
 * and empty; bounds spheres and boxes; values NaN, infinite, negative,
 * denormal or huge among them; costs do not depend on the view). Between
 * updates the scene grows or is edited (nodes removed with their subtrees,
 * moved, added under removed parents; smooth objects added, removed and
 * moved; hidden ids edited), each edit's status as fuzz_host's model
 * predicts; an edit tried from inside the callbacks of an update must be
 * refused with TCLOD_ERR_STATE. Two schedulers with the same descriptions
 * see the same updates. What is checked is what the header promises:
 *  - creation fails with TCLOD_ERR_ARG exactly for bad descriptions;
 *  - an update fails with TCLOD_ERR_ARG for a bad view, time, budget or
 *    slice (or the mixed solver without smooth callbacks once smooth
 *    objects were added), with TCLOD_ERR_CALLBACK in strict mode exactly when a callback
 *    returned a bad value, and otherwise succeeds; a failed update keeps the
 *    last draw list and stats, and records no camera (a later update may be
 *    as early as the last successful one);
 *  - after a successful update the draw list names only live nodes that
 *    draw (never a removed, empty or hidden id: removed nodes leave it at
 *    the update after their removal), each once; their fine sides are
 *    disjoint but for additive nodes drawn with their descendants; each is
 *    drawn as itself with weight 1 or morphing towards its nearest ancestor
 *    that draws with a weight in [0, 1], never a node whose cost is bad; its
 *    predicted cost is within the budget in force (unless overflow draws the
 *    roots over it), and at least the summed costs of its fine nodes; the
 *    budget in force is the update's budget divided by the calibration's
 *    scale (its initial value until the first report);
 *  - smooth resolutions are in [0, 1], and 0 for unknown and removed ids and
 *    solvers that ignore smooth objects;
 *  - callbacks are asked only about live nodes that draw and live smooth
 *    objects, with the node's volume and the view helpers' measures;
 *  - a new node or smooth object gets a removed id only once both
 *    schedulers (those that ever updated successfully) have updated
 *    successfully since its removal;
 *  - report, predict and the conservative camera fail exactly as documented,
 *    and a conservative camera is a valid view that sees at least what its
 *    camera sees;
 *  - the two schedulers agree bit for bit while no slice is time-limited.
 */
#include <tclod/tclod.h>

#include "fuzz_host.h"

#define FIRST_NODES 96u
#define FIRST_SMOOTH 24u
#define MAX_UPDATES 24u

/* Whether the header requires TCLOD_ERR_ARG (1) or success (0) for a
 * scheduling description (0 fields take their defaults; TCLOD_OFF asks for 0
 * in confidence and dead_band). */
static int schedule_desc_invalid(const tclod_scheduler_desc *d) {
    const tclod_calib_desc *c = &d->calib;
    if (!(d->tau == 0.0 || (isnormal(d->tau) && d->tau > 0.0 && !isinf(4.0 * d->tau))) ||
        d->samples > TCLOD_MAX_SAMPLES ||
        !(d->confidence == -1.0 || (d->confidence >= 0.0 && !isinf(d->confidence))) ||
        !(d->max_speed >= 0.0 && !isinf(d->max_speed)) ||
        !(d->max_turn_rate >= 0.0 && !isinf(d->max_turn_rate)) ||
        (d->two_stage != 0 && d->two_stage != 1))
        return 1;
    return calib_desc_invalid(c);
}

static void read_schedule_desc(fuzz_reader *in, tclod_scheduler_desc *d) {
    uint8_t b;
    tclod_scheduler_desc_default(d);
    d->tau = option_value(in, d->tau);
    b = fuzz_u8(in);
    d->samples = b == 0 ? d->samples : (uint32_t)(b % 10u); /* 0: the default; 9: too many */
    d->confidence = option_value(in, d->confidence);
    d->max_speed = option_value(in, 20.0);
    d->max_turn_rate = option_value(in, 1.0);
    d->two_stage = fuzz_u8(in) & 1;
    d->calib.initial_scale = option_value(in, d->calib.initial_scale);
}

/* A copy of a draw list, and the smooth resolutions. */
typedef struct draw_list {
    tclod_draw items[MAX_NODES];
    size_t n;
    double resolution[MAX_SMOOTH + 2];
} draw_list;

static void take_draws(const tclod_scheduler *sch, uint32_t smooth, draw_list *l) {
    const tclod_draw *items = NULL;
    uint32_t i;
    FUZZ_CHECK(tclod_scheduler_draws(sch, &items, &l->n) == TCLOD_OK, "draws");
    FUZZ_CHECK(l->n <= MAX_NODES, "%lu draws", (unsigned long)l->n);
    if (l->n)
        memcpy(l->items, items, l->n * sizeof *items);
    for (i = 0; i < smooth + 2u; ++i)
        l->resolution[i] = tclod_scheduler_resolution(sch, i);
}

static int same_draws(const draw_list *a, const draw_list *b, uint32_t smooth) {
    return a->n == b->n &&
           (a->n == 0 || memcmp(a->items, b->items, a->n * sizeof a->items[0]) == 0) &&
           memcmp(a->resolution, b->resolution, (smooth + 2u) * sizeof(double)) == 0;
}

/* What a successful update promises about its draw list. */
static void check_draws(const tclod_scheduler *sch, const host_model *m, const draw_list *l,
                        const tclod_selector_desc *sd, double budget_in_force) {
    tclod_scheduler_stats st;
    unsigned char drawn[MAX_NODES];
    double node_cost = 0.0;
    uint32_t morphing = 0, i;
    size_t k;
    memset(drawn, 0, sizeof drawn);
    FUZZ_CHECK(tclod_scheduler_get_stats(sch, &st) == TCLOD_OK, "get_stats");
    for (k = 0; k < l->n; ++k) {
        const tclod_draw *d = &l->items[k];
        FUZZ_CHECK(model_draws(m, d->fine) && !drawn[d->fine],
                   "draw of node %u twice, or of an id that is not a live node that draws (state "
                   "%d kind %d)",
                   (unsigned)d->fine, d->fine < m->nodes ? (int)m->state[d->fine] : -1,
                   d->fine < m->nodes ? (int)m->kind[d->fine] : -1);
        drawn[d->fine] = 1;
        if (d->coarse == d->fine)
            FUZZ_CHECK(d->weight == 1.0f, "node %u drawn as itself with weight %g",
                       (unsigned)d->fine, (double)d->weight);
        else
            FUZZ_CHECK(d->coarse == drawn_parent(m, d->fine) && d->weight >= 0.0f &&
                           d->weight <= 1.0f,
                       "node %u morphs towards %u (its nearest ancestor that draws: %u) with "
                       "weight %g",
                       (unsigned)d->fine, (unsigned)d->coarse, (unsigned)drawn_parent(m, d->fine),
                       (double)d->weight);
        morphing += d->coarse != d->fine;
        FUZZ_CHECK(!fuzz_bad(m->cost[d->fine]), "node %u drawn with cost %g", (unsigned)d->fine,
                   m->cost[d->fine]);
        node_cost += m->cost[d->fine];
    }
    for (k = 0; k < l->n; ++k) {
        tclod_id a;
        for (a = drawn_parent(m, l->items[k].fine); a != TCLOD_NONE; a = drawn_parent(m, a))
            FUZZ_CHECK(!drawn[a] || m->kind[a] == KIND_ADD,
                       "node %u drawn with its ancestor %u, a replace node",
                       (unsigned)l->items[k].fine, (unsigned)a);
    }
    for (i = 0; i < m->smooth + 2u; ++i) {
        double r = l->resolution[i];
        FUZZ_CHECK(r >= 0.0 && r <= 1.0, "resolution %.17g of smooth %u", r, (unsigned)i);
        if (i >= m->smooth || m->smooth_state[i] != ID_LIVE || sd->solver == TCLOD_SOLVER_GREEDY)
            FUZZ_CHECK(r == 0.0, "resolution %.17g of smooth %u, unknown, removed or ignored", r,
                       (unsigned)i);
    }
    FUZZ_CHECK(st.draws == l->n && st.morphing == morphing, "stats: %u draws %u morphing",
               (unsigned)st.draws, (unsigned)st.morphing);
    if (sd->overflow != TCLOD_OVERFLOW_DRAW_ROOTS)
        FUZZ_CHECK(st.draw_cost <= st.budget, "draw list costs %.17g, budget in force %.17g",
                   st.draw_cost, st.budget);
    FUZZ_CHECK(node_cost <= st.draw_cost * (1.0 + 1e-12) || node_cost - st.draw_cost <= 1e-300,
               "the fine nodes cost %.17g, the draw list %.17g", node_cost, st.draw_cost);
    if (budget_in_force >= 0.0)
        FUZZ_CHECK(st.budget == budget_in_force, "budget in force %.17g, expected %.17g", st.budget,
                   budget_in_force);
}

/* The conservative camera on the input's numbers. */
static void check_conservative(fuzz_reader *in, const tclod_view *v) {
    double horizon = option_value(in, 1.0), speed = option_value(in, 10.0),
           turn = option_value(in, 0.5);
    tclod_view out;
    tclod_status st;
    double back;
    int bad;
    memset(&out, 0x5a, sizeof out);
    st = tclod_conservative_view(v, horizon, speed, turn, &out);
    bad = v == NULL || tclod_view_validate(v) != TCLOD_OK || !(horizon >= 0.0) || isinf(horizon) ||
          !(speed >= 0.0) || isinf(speed) || !(turn >= 0.0) || isinf(turn);
    if (bad) {
        unsigned char pattern[sizeof out];
        memset(pattern, 0x5a, sizeof pattern);
        FUZZ_CHECK(st == TCLOD_ERR_ARG && memcmp(&out, pattern, sizeof out) == 0,
                   "conservative_view(horizon %g, speed %g, turn %g) gave %d", horizon, speed, turn,
                   (int)st);
        return;
    }
    {
        /* the header's step back, horizon theta / sin(fov / 2 + horizon omega)
         * with fov the smaller field of view: when it carries the eye or far_z
         * out of float's range, no valid view exists */
        double turn2 = 2.0 * horizon * turn, max_fov = 179.0 * 3.14159265358979323846 / 180.0;
        double fy = (double)v->fov_y, fx = 2.0 * atan((double)v->aspect * tan(0.5 * fy));
        fy = fy + turn2 < max_fov ? fy + turn2 : max_fov;
        fx = fx + turn2 < max_fov ? fx + turn2 : max_fov;
        back = horizon * speed / sin(0.5 * (fy < fx ? fy : fx));
        if (st == TCLOD_ERR_ARG &&
            !((double)v->far_z + back + horizon * speed < 0.5 * FLT_MAX &&
              fabs((double)v->eye[0]) + fabs((double)v->eye[1]) + fabs((double)v->eye[2]) + back <
                  0.5 * FLT_MAX))
            return;
    }
    FUZZ_CHECK(st == TCLOD_OK, "conservative_view(horizon %g, speed %g, turn %g) gave %d", horizon,
               speed, turn, (int)st);
    FUZZ_CHECK(tclod_view_validate(&out) == TCLOD_OK,
               "the conservative camera is not a valid view");
    FUZZ_CHECK(out.fov_y >= v->fov_y && out.far_z >= v->far_z,
               "conservative fov %g far %g from fov %g far %g", (double)out.fov_y,
               (double)out.far_z, (double)v->fov_y, (double)v->far_z);
    /* what the camera sees now it can reach, so the conservative camera sees
     * it: a small sphere in the middle of the view (while the field of view
     * has not stopped at 179 degrees, and the step back and the coordinates
     * stay where float keeps them to well under the sphere's size) */
    if ((double)out.fov_y < 179.0 * 3.14159265358979323846 / 180.0 - 1e-3 && back < 1e4 &&
        fabs(v->eye[0]) + fabs(v->eye[1]) + fabs(v->eye[2]) < 1e4 && v->far_z < 1e4f) {
        double f[3], len, depth = 0.5 * ((double)v->near_z + (double)v->far_z);
        float probe_sphere[4];
        int k;
        for (k = 0; k < 3; ++k)
            f[k] = (double)v->forward[k];
        len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        for (k = 0; k < 3; ++k)
            probe_sphere[k] = (float)((double)v->eye[k] + f[k] / len * depth);
        probe_sphere[3] = (float)(1e-3 * depth);
        if (tclod_view_sphere_visible(v, probe_sphere))
            FUZZ_CHECK(tclod_view_sphere_visible(&out, probe_sphere),
                       "the conservative camera does not see the middle of the view");
    }
}

typedef struct run_state {
    host_model model;
    probe probes[2];
    draw_list before, after[2];
    edit edit, callback_edit;
} run_state;

static run_state state;

static void run(fuzz_reader *in) {
    static const double steps[8] = {0.0, 1.0 / 60.0, 1.0 / 30.0, 0.1, 0.25, 0.5, 1.0, 5.0};
    host_model *m = &state.model;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch[2] = {NULL, NULL};
    tclod_scene *s = NULL;
    double now = 0.0, last_ok = 0.0;
    uint32_t n, i, updates, u;
    int invalid, compare = 1, updated = 0, tried = 0, reported = 0;
    tclod_status st;

    memset(&state, 0, sizeof state);
    FUZZ_CHECK(tclod_scene_create(NULL, &s) == TCLOD_OK, "scene_create");
    model_init(m, s, 2);
    read_desc(in, &sd, m);
    read_schedule_desc(in, &d);
    n = fuzz_u8(in) % (FIRST_NODES + 1u);
    for (i = 0; i < n; ++i)
        add_node(in, m);
    n = fuzz_u8(in) % (FIRST_SMOOTH + 1u);
    for (i = 0; i < n; ++i)
        add_smooth(in, m);
    verify_scene(m);

    invalid = desc_invalid(&sd, m->live_smooth);
    if (invalid == 0)
        invalid = schedule_desc_invalid(&d);
    for (i = 0; i < 2; ++i) {
        tclod_scheduler *const sentinel = (tclod_scheduler *)(void *)&state;
        sch[i] = sentinel;
        state.probes[i].m = m;
        state.probes[i].any_view = 1;
        sd.callbacks.user = &state.probes[i];
        st = tclod_scheduler_create(s, &sd, &d, NULL, &sch[i]);
        if (invalid) {
            FUZZ_CHECK(st == TCLOD_ERR_ARG && sch[i] == sentinel,
                       "scheduler_create accepted a bad description (%d)", (int)st);
            if (i == 1)
                tclod_scheduler_destroy(sch[0]);
            tclod_scene_destroy(s);
            return;
        }
        FUZZ_CHECK(st == TCLOD_OK && sch[i] != sentinel, "scheduler_create gave %d", (int)st);
    }
    {
        tclod_view v;
        double x = 0.0;
        FUZZ_CHECK(tclod_scheduler_predict(sch[0], 0.0, &v) == TCLOD_ERR_STATE,
                   "predict before the first update");
        FUZZ_CHECK(tclod_scheduler_report_frame(sch[0], 1.0, TCLOD_OFF) == TCLOD_ERR_STATE &&
                       tclod_scheduler_resolution(sch[0], 0) == x,
                   "report before the first update");
    }
    now = ldexp((double)fuzz_u8(in), (int)(fuzz_u8(in) % 64u) - 8);

    updates = 1u + fuzz_u8(in) % MAX_UPDATES;
    for (u = 0; u < updates; ++u) {
        tclod_view view;
        const tclod_view *v;
        double budget, slice, scale = 0.0, t;
        uint8_t b = fuzz_u8(in);
        int bad;

        /* time: a step from the table, sometimes NaN or backwards */
        t = (b & 0xe0) == 0xe0 ? ((b & 1) ? (double)NAN : now - 1.0) : now + steps[b & 7u];
        /* the scene grows, or is edited; an edit to try from the callbacks */
        b = fuzz_u8(in);
        for (i = 0; i < 2; ++i)
            state.probes[i].held_edit = NULL;
        if (b == 0x77) {
            add_node(in, m);
        } else if (b >= 0xd0) {
            uint32_t e;
            for (e = b >= 0xe0 ? 1u + (b & 3u) : 0u; e > 0; --e) {
                read_edit(in, m, &state.edit);
                try_edit(m, &state.edit, 0);
            }
            if (b < 0xe0 || (b & 4u)) {
                read_edit(in, m, &state.callback_edit);
                for (i = 0; i < 2; ++i)
                    state.probes[i].held_edit = &state.callback_edit;
            }
        }
        v = read_view(in, &view);
        for (i = 0; i < m->nodes; ++i)
            if (model_draws(m, i) && !fuzz_bad(m->cost[i]))
                scale += m->cost[i];
        b = fuzz_u8(in);
        budget = b < 32 ? fuzz_special_double(b) : scale * (double)(b - 32) / 128.0;
        b = fuzz_u8(in);
        slice = b < 200 ? 0.0 : (b < 250 ? 1e-300 : (b & 1 ? -1.0 : (double)NAN));
        if (slice > 0.0)
            compare = 0; /* the slice's end depends on the clock */
        /* "now NaN or earlier than the last successful update's": a failed
         * update records nothing, so only the successful ones count */
        bad = v == NULL || tclod_view_validate(v) != TCLOD_OK || t != t ||
              (updated && t < last_ok) || !(budget >= 0.0) || !(slice >= 0.0) ||
              smooth_callbacks_missing(&sd, m->live_smooth);

        for (i = 0; i < 2; ++i) {
            probe *p = &state.probes[i];
            double in_force = -1.0;
            tclod_scheduler_stats before, after;
            memset(&before, 0, sizeof before); /* padding compares equal */
            memset(&after, 0, sizeof after);
            take_draws(sch[i], m->smooth, &state.before);
            FUZZ_CHECK(tclod_scheduler_get_stats(sch[i], &before) == TCLOD_OK, "get_stats");
            probe_reset(p, v);
            st = tclod_scheduler_update(sch[i], t, v, budget, slice);
            take_draws(sch[i], m->smooth, &state.after[i]);
            FUZZ_CHECK(tclod_scheduler_get_stats(sch[i], &after) == TCLOD_OK, "get_stats");
            if (bad) {
                FUZZ_CHECK(st == TCLOD_ERR_ARG && p->calls == 0,
                           "update(t %g after %g, budget %g, slice %g) gave %d after %u calls", t,
                           last_ok, budget, slice, (int)st, (unsigned)p->calls);
            } else if (sd.strict && p->bad > 0) {
                FUZZ_CHECK(st == TCLOD_ERR_CALLBACK, "strict update gave %d after %u bad values",
                           (int)st, (unsigned)p->bad);
            } else {
                FUZZ_CHECK(st == TCLOD_OK, "update gave %d (strict %d, %u bad values)", (int)st,
                           sd.strict, (unsigned)p->bad);
            }
            if (st != TCLOD_OK) {
                FUZZ_CHECK(same_draws(&state.before, &state.after[i], m->smooth) &&
                               memcmp(&before, &after, sizeof before) == 0,
                           "a failed update changed the draw list or the stats");
                continue;
            }
            model_user_solved(m, i);
            if (!reported && d.calib.initial_scale >= DBL_MIN)
                in_force = budget / d.calib.initial_scale;
            check_draws(sch[i], m, &state.after[i], &sd, in_force);
        }
        if (st == TCLOD_OK) {
            now = last_ok = t;
            updated = 1;
        }
        if (st == TCLOD_OK || st == TCLOD_ERR_CALLBACK) {
            tried = 1;
        }
        if (compare)
            FUZZ_CHECK(same_draws(&state.after[0], &state.after[1], m->smooth),
                       "two schedulers given the same updates disagree (update %u)", (unsigned)u);

        /* between frames: a measured render time, a prediction, a conservative camera */
        b = fuzz_u8(in);
        if (b & 1) {
            double render = fuzz_double(in);
            for (i = 0; i < 2; ++i) {
                tclod_status r = tclod_scheduler_report_frame(sch[i], render, TCLOD_OFF);
                int bad_time = !(render >= 0.0) || isinf(render);
                tclod_scheduler_stats shown;
                FUZZ_CHECK(tclod_scheduler_get_stats(sch[i], &shown) == TCLOD_OK, "get_stats");
                if (!tried) /* with a bad time too, either error is right */
                    FUZZ_CHECK(r == TCLOD_ERR_STATE || (bad_time && r == TCLOD_ERR_ARG),
                               "report(%g) before any update gave %d", render, (int)r);
                else if (!updated && r == TCLOD_ERR_STATE)
                    continue; /* only failed updates: "before the first update" is open */
                else if (bad_time)
                    FUZZ_CHECK(r == TCLOD_ERR_ARG, "report(%g) gave %d", render, (int)r);
                else
                    FUZZ_CHECK(r == TCLOD_OK, "report(%g) gave %d", render, (int)r);
                if (r == TCLOD_OK)
                    reported = 1;
            }
        }
        if (b & 2) {
            tclod_view out;
            double when = (b & 4) ? (double)NAN : now + steps[b >> 5];
            tclod_status r = tclod_scheduler_predict(sch[0], when, &out);
            if (when != when)
                FUZZ_CHECK(r == TCLOD_ERR_ARG || (!tried && r == TCLOD_ERR_STATE),
                           "predict(NaN) gave %d", (int)r);
            else if (!tried)
                FUZZ_CHECK(r == TCLOD_ERR_STATE, "predict before any update gave %d", (int)r);
            else if (updated)
                FUZZ_CHECK(r == TCLOD_OK, "predict(%g) gave %d", when, (int)r);
        }
        if (b & 8)
            check_conservative(in, v);
    }
    tclod_scheduler_destroy(sch[1]);
    tclod_scheduler_destroy(sch[0]);
    tclod_scene_destroy(s);
}

FUZZ_ENTRY(run)
