/*
 * fuzz_host — the host the fuzz targets play: a scene model mirrored node by
 * node, callbacks that read it (and check every query they are given against
 * the header), and the readers that build descriptions, scenes and views
 * from the fuzzer's bytes while checking the statuses the header promises.
 */
#include "fuzz_host.h"

#include "world_scene.h"

void probe_reset(probe *p, const tclod_view *view) {
    const host_model *m = p->m;
    int any_view = p->any_view;
    memset(p, 0, sizeof *p);
    p->m = m;
    p->any_view = any_view;
    p->frame_view = view;
}

/* Whether a query carries the frame's view: none when the frame has none,
 * else the same numbers (the library may hold a copy). */
int same_view(const tclod_view *q, const tclod_view *frame) {
    if (frame == NULL || q == NULL)
        return q == frame;
    return memcmp(q, frame, sizeof *q) == 0;
}

/* A query about a node's own benefit or cost during the solve, as opposed
 * to the Robin Hood solver's complexity question (no view, the reference
 * area as screen area), which a normal query without a view never has: its
 * screen area is then -1. */
int is_complexity_query(const tclod_query *q) {
    return q->view == NULL && q->screen_area != -1.0f;
}

void check_node_query(const probe *p, const tclod_query *q) {
    FUZZ_CHECK(q->id < p->m->nodes, "node query about id %u of %u", (unsigned)q->id,
               (unsigned)p->m->nodes);
    FUZZ_CHECK(q->count == 1 && q->members == NULL, "node query with count %u", (unsigned)q->count);
    if (is_complexity_query(q))
        return;
    FUZZ_CHECK(p->any_view || same_view(q->view, p->frame_view),
               "node query without the frame's view");
    if (q->view == NULL || p->m->bounds[q->id][3] < 0.0f) {
        FUZZ_CHECK(q->screen_area == -1.0f && q->distance == -1.0f,
                   "no view or bounds, yet area %g distance %g", (double)q->screen_area,
                   (double)q->distance);
    } else {
        /* the helpers' figures: 0 outside the frustum */
        const float *b = p->m->bounds[q->id];
        float area =
            tclod_view_sphere_visible(q->view, b) ? tclod_view_screen_area(q->view, b) : 0.0f;
        float distance = tclod_view_distance(q->view, b); /* to the sphere, 0 inside */
        FUZZ_CHECK(memcmp(&area, &q->screen_area, sizeof area) == 0 &&
                       memcmp(&distance, &q->distance, sizeof distance) == 0,
                   "node %u: area %.9g distance %.9g, the view helpers say %.9g %.9g",
                   (unsigned)q->id, (double)q->screen_area, (double)q->distance, (double)area,
                   (double)distance);
    }
}

double host_benefit(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    check_node_query(p, q);
    FUZZ_CHECK(!is_complexity_query(q), "benefit asked as a complexity");
    v = p->m->benefit[q->id];
    if (p->m->view_dependent && q->screen_area >= 0.0f)
        v *= (double)q->screen_area; /* 0 outside the frustum: culled */
    p->benefit_calls[q->id]++;
    p->benefit_seen[q->id] = v;
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    return v;
}

double host_cost(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    check_node_query(p, q);
    v = p->m->cost[q->id];
    p->calls++;
    p->bad += (uint32_t)fuzz_bad(v);
    if (is_complexity_query(q))
        return v;
    FUZZ_CHECK(p->any_view || (p->benefit_calls[q->id] == 1 && p->benefit_seen[q->id] > 0.0),
               "cost of node %u asked after %u benefit calls (last %g)", (unsigned)q->id,
               (unsigned)p->benefit_calls[q->id], p->benefit_seen[q->id]);
    p->cost_calls[q->id]++;
    p->cost_seen[q->id] = v;
    return v;
}

double host_complexity(void *user, const tclod_query *q) {
    probe *p = (probe *)user;
    double v;
    FUZZ_CHECK(q->view == NULL, "complexity asked with a view");
    if (q->members) {
        FUZZ_CHECK(q->id < p->m->smooth && q->members[0] == q->id && q->count == 1,
                   "complexity of smooth object %u", (unsigned)q->id);
        v = p->m->complexity[MAX_NODES + q->id];
    } else {
        FUZZ_CHECK(q->id < p->m->nodes && q->count == 1, "complexity of node %u", (unsigned)q->id);
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
    if (q->members) {
        FUZZ_CHECK(q->id < p->m->smooth && q->members[0] == q->id && q->count == 1,
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

void check_smooth_query(const probe *p, const tclod_query *q, double r, const double *d_dr) {
    uint32_t i;
    FUZZ_CHECK(d_dr != NULL, "smooth callback without d_dr");
    FUZZ_CHECK(r >= 1e-9 && r <= 1.0, "smooth callback at r = %.17g", r);
    FUZZ_CHECK(q->members != NULL && q->count >= 1 && q->count <= p->m->smooth &&
                   q->members[0] == q->id,
               "smooth query id %u count %u", (unsigned)q->id, (unsigned)q->count);
    for (i = 0; i < q->count; ++i)
        FUZZ_CHECK(q->members[i] < p->m->smooth, "member %u", (unsigned)q->members[i]);
    if (!is_complexity_query(q) && !p->any_view)
        FUZZ_CHECK(same_view(q->view, p->frame_view), "smooth query without the frame's view");
}

double host_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    probe *p = (probe *)user;
    double v;
    check_smooth_query(p, q, r, d_dr);
    v = smooth_value(p->m, q, r, d_dr, 0);
    p->calls++;
    p->bad += (uint32_t)(fuzz_bad(v) || fuzz_bad(*d_dr));
    return v;
}

double host_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    probe *p = (probe *)user;
    double v;
    check_smooth_query(p, q, r, d_dr);
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

/* Whether the header promises TCLOD_ERR_ARG for this description; -1 when it
 * leaves the value open (an infinite threshold, cull area or reference area:
 * "NaN or out of range" with ranges written as ">= 0" and "> 0"). */
int smooth_callbacks_missing(const tclod_selector_desc *d, uint32_t smooth) {
    return d->solver == TCLOD_SOLVER_MIXED && smooth > 0 &&
           (!d->callbacks.smooth_benefit || !d->callbacks.smooth_cost);
}

int desc_invalid(const tclod_selector_desc *d, uint32_t smooth) {
    int open = 0;
    if (!tclod_solver_available(d->solver) || !d->callbacks.benefit || !d->callbacks.cost ||
        d->lookahead > TCLOD_MAX_LOOKAHEAD || d->restarts > TCLOD_MAX_RESTARTS)
        return 1;
    if (smooth_callbacks_missing(d, smooth))
        return 1;
    if (!(d->split_threshold >= 0.0) || !(d->smooth_epsilon >= 0.0 && d->smooth_epsilon < 1.0) ||
        !(d->smooth_tolerance >= 0.0 && d->smooth_tolerance < 1.0) ||
        !(d->smooth_cull_area >= 0.0) || (unsigned)d->value > (unsigned)TCLOD_VALUE_BENEFIT ||
        (unsigned)d->misfit > (unsigned)TCLOD_MISFIT_COARSEST || !(d->reference_area > 0.0))
        return 1;
    open = isinf(d->split_threshold) || isinf(d->smooth_cull_area) || isinf(d->reference_area);
    return open ? -1 : 0;
}

void read_desc(fuzz_reader *in, tclod_selector_desc *d, host_model *m) {
    uint8_t solver = fuzz_u8(in), flags = fuzz_u8(in), enums = fuzz_u8(in);
    tclod_selector_desc_default(d);
    d->solver = solver >= 250 ? (tclod_solver)(solver - 247) /* 3 .. 8: unknown */
                              : (tclod_solver)(solver % 3u);
    if (solver < 250) { /* 0 .. 7, the most, or one more */
        uint32_t r = (uint32_t)(solver / 3u) % 10u;
        d->restarts = r < 8u ? r : TCLOD_MAX_RESTARTS + r - 8u;
    }
    d->warm_start = flags & 1;
    d->split_smooth = (flags >> 1) & 1;
    d->strict = (flags >> 2) & 1;
    d->smooth_precondition = !((flags >> 3) & 1);
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
        d->lookahead = enums >> 6 == 3 ? TCLOD_MAX_LOOKAHEAD + 1u : 1u + (enums >> 6);
    if (flags == 0xff) /* the required callbacks missing */
        d->callbacks.cost = NULL;
    d->value = (tclod_value)(enums % 6u);          /* 5: unknown */
    d->misfit = (tclod_misfit)((enums >> 3) % 3u); /* 2: unknown */
    d->split_threshold = option_value(in, d->split_threshold);
    d->smooth_epsilon = option_value(in, d->smooth_epsilon);
    d->smooth_tolerance = option_value(in, d->smooth_tolerance);
    d->smooth_cull_area = option_value(in, d->smooth_cull_area);
    d->reference_area = option_value(in, d->reference_area);
}

/* A parent: a root, an existing node, or an id that does not exist. */
tclod_id read_parent(fuzz_reader *in, uint32_t count) {
    uint8_t b = fuzz_u8(in);
    if (b == 0xff || count == 0)
        return b == 0xfe ? count : TCLOD_NONE;
    if (b == 0xfe)
        return count + fuzz_u8(in); /* not yet created */
    if (b == 0xfd)
        return TCLOD_NONE - 1u;
    return b % count;
}

int bounds_bad(const float b[4]) {
    return !isfinite(b[0]) || !isfinite(b[1]) || !isfinite(b[2]) || !isfinite(b[3]) || b[3] < 0.0f;
}

void read_bounds(fuzz_reader *in, float b[4]) {
    int k;
    for (k = 0; k < 3; ++k)
        b[k] = fuzz_float(in);
    b[3] = fabsf(fuzz_float(in)) * (fuzz_u8(in) == 0x80 ? -1.0f : 1.0f);
}

/* Adds one node as the input says, and checks the status the header
 * promises; on failure nothing may change. */
void add_node(fuzz_reader *in, tclod_scene *s, host_model *m) {
    tclod_id parent = read_parent(in, m->nodes), id = 12345u;
    uint8_t kind = fuzz_u8(in);
    float bounds[4];
    int bad_bounds = 0, bad_parent = parent != TCLOD_NONE && parent >= m->nodes;
    tclod_status st;
    if (kind & 1) {
        read_bounds(in, bounds);
        bad_bounds = bounds_bad(bounds);
    }
    st = tclod_scene_add_node(s, parent, (kind & 1) ? bounds : NULL, &id);
    if (bad_bounds || bad_parent) {
        FUZZ_CHECK((bad_bounds && st == TCLOD_ERR_ARG) || (bad_parent && st == TCLOD_ERR_HIERARCHY),
                   "add_node(parent %u of %u, bad bounds %d) gave %d", (unsigned)parent,
                   (unsigned)m->nodes, bad_bounds, (int)st);
        FUZZ_CHECK(id == 12345u && tclod_scene_node_count(s) == m->nodes,
                   "a failed add_node changed the scene");
        return;
    }
    FUZZ_CHECK(st == TCLOD_OK && id == m->nodes, "add_node gave %d, id %u, expected %u", (int)st,
               (unsigned)id, (unsigned)m->nodes);
    FUZZ_CHECK(tclod_scene_parent(s, id) == parent, "parent of %u", (unsigned)id);
    m->parent[id] = parent;
    if (kind & 1) {
        memcpy(m->bounds[id], bounds, sizeof bounds);
    } else {
        m->bounds[id][0] = m->bounds[id][1] = m->bounds[id][2] = 0.0f;
        m->bounds[id][3] = -1.0f;
    }
    m->benefit[id] = fuzz_double(in);
    m->cost[id] = fuzz_double(in);
    m->complexity[id] = fuzz_double(in);
    m->nodes++;
}

void add_smooth(fuzz_reader *in, tclod_scene *s, host_model *m) {
    static const double powers[8] = {0.5, 0.25, 1.0, 0.75, 2.0, 0.5, 0.125, 1.0};
    smooth_model *o = &m->sm[m->smooth];
    float bounds[4];
    uint8_t mode;
    tclod_id id = 12345u;
    tclod_status st;
    read_bounds(in, bounds);
    st = tclod_scene_add_smooth(s, bounds, &id);
    if (bounds_bad(bounds)) {
        FUZZ_CHECK(st == TCLOD_ERR_ARG && id == 12345u && tclod_scene_smooth_count(s) == m->smooth,
                   "add_smooth with bad bounds gave %d", (int)st);
        return;
    }
    FUZZ_CHECK(st == TCLOD_OK && id == m->smooth, "add_smooth gave %d", (int)st);
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
    m->complexity[MAX_NODES + m->smooth] = fuzz_double(in);
    m->smooth++;
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

/* The view helpers on a valid view and the nodes' bounds: areas in
 * [0, viewport area], distances >= 0, never NaN. */
void check_view_helpers(const tclod_view *v, const host_model *m) {
    double viewport = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
    uint32_t i;
    for (i = 0; i < m->nodes; ++i) {
        const float *bounds = m->bounds[i];
        float area, distance;
        int visible;
        if (bounds[3] < 0.0f)
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
