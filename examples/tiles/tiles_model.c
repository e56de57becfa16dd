/*
 * tiles_model — the benefit model of tclod_tiles (tiles_model.h).
 */
#include "tiles_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A tile in the frustum whose share rounds to nothing still counts this many
 * px², and one that adds nothing to its additive ancestor this fraction of its
 * share: benefit 0 would cull its subtree. */
#define MIN_SHARE 1e-3
#define MIN_GAIN 1e-6

static double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross_product(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* v / |v| (unchanged when 0); returns |v|. */
static double unit(double v[3]) {
    double len = sqrt(dot(v, v));
    if (len > 0.0) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
    return len;
}

/* A tile's volume, prepared as the library prepares valid bounds. Boxes with
 * two or three zero axes (a segment, a point) are left to the library's
 * functions (r = -2), as are volumes without bounds. */
static void prepare_volume(const tclod_bounds *b, model_volume *v) {
    int i, zero = 0;
    memset(v, 0, sizeof(*v));
    for (i = 0; i < 3; ++i)
        v->c[i] = b->center[i];
    v->r = -2.0;
    if (b->kind == TCLOD_BOUNDS_SPHERE) {
        v->r = b->radius;
        return;
    }
    if (b->kind != TCLOD_BOUNDS_AABB && b->kind != TCLOD_BOUNDS_OBB)
        return;
    for (i = 0; i < 3; ++i) {
        if (b->kind == TCLOD_BOUNDS_AABB) {
            v->u[i][i] = 1.0;
            v->h[i] = b->half_extents[i];
        } else {
            memcpy(v->u[i], b->half_axes[i], sizeof(v->u[i]));
            v->h[i] = unit(v->u[i]);
        }
        zero += v->h[i] == 0.0;
    }
    if (zero > 1)
        return;
    for (i = 0; i < 3 && zero; ++i)
        if (v->h[i] == 0.0) { /* a flat box: its normal completes the frame */
            cross_product(v->u[(i + 1) % 3], v->u[(i + 2) % 3], v->u[i]);
            unit(v->u[i]);
        }
    v->r = -1.0;
}

/* What the benefit reads of tile t, from the tileset as it is. */
static void prepare_link(tiles_model *m, uint32_t t) {
    const tileset *ts = m->ts;
    const tile *x = &ts->tiles[t];
    model_link *l = &m->link[t];
    uint32_t i;
    l->geometric_error = x->geometric_error;
    l->parent = x->parent;
    l->add_anchor = x->add_anchor;
    l->first_child = x->first_child;
    l->child_count = x->child_count;
    l->children_bound = x->refine == TCLOD_REFINE_REPLACE && x->child_count > 0 &&
                        x->bounds.kind == TCLOD_BOUNDS_OBB;
    for (i = 0; i < x->child_count && l->children_bound; ++i) {
        const tile *c = &ts->tiles[ts->children[x->first_child + i]];
        if (c->bounds.kind != TCLOD_BOUNDS_OBB || c->loose) /* a child that is no box, or reaches out */
            l->children_bound = 0;
    }
}

/* Grows *p, of `size`-byte entries, from `old` to `room`, the new ones zero. */
static int grow(void *p, size_t size, size_t old, size_t room) {
    void **q = (void **)p;
    char *g = (char *)realloc(*q, room * size);
    if (!g)
        return 0;
    memset(g + old * size, 0, (room - old) * size);
    *q = g;
    return 1;
}

int model_grow(tiles_model *m) {
    const tileset *ts = m->ts;
    size_t old = m->room, room = old ? old : 1u;
    uint32_t t;
    while (room < ts->count)
        room *= 2u;
    if (room > old &&
        !(grow(&m->vol, sizeof(*m->vol), old, room) && grow(&m->link, sizeof(*m->link), old, room) &&
          grow(&m->area_stamp, sizeof(uint32_t), old, room) &&
          grow(&m->share_stamp, sizeof(uint32_t), old, room) &&
          grow(&m->sum_stamp, sizeof(uint32_t), old, room) &&
          grow(&m->distance_stamp, sizeof(uint32_t), old, room) &&
          grow(&m->area, sizeof(double), old, room) && grow(&m->share, sizeof(double), old, room) &&
          grow(&m->child_sum, sizeof(double), old, room) &&
          grow(&m->distance, sizeof(double), old, room)))
        return 1;
    m->room = room;
    if (ts->counts.max_depth + 1u > m->path_room) {
        uint32_t *p = (uint32_t *)realloc(m->path, ((size_t)ts->counts.max_depth + 1) * sizeof(uint32_t));
        if (!p)
            return 1;
        m->path = p;
        m->path_room = ts->counts.max_depth + 1u;
    }
    for (t = m->count; t < ts->count; ++t) {
        uint32_t p = ts->tiles[t].parent;
        prepare_volume(&ts->tiles[t].bounds, &m->vol[t]);
        prepare_link(m, t);
        if (p != TILE_NONE && p < m->count) {
            /* a tile read on: its parent's children changed */
            prepare_link(m, p);
            m->sum_stamp[p] = 0;
        }
    }
    m->count = ts->count;
    return 0;
}

int model_init(tiles_model *m, const tileset *ts) {
    memset(m, 0, sizeof(*m));
    m->ts = ts;
    if (model_grow(m)) {
        model_free(m);
        return 1;
    }
    return 0;
}

void model_free(tiles_model *m) {
    free(m->vol);
    free(m->link);
    free(m->area_stamp);
    free(m->share_stamp);
    free(m->sum_stamp);
    free(m->distance_stamp);
    free(m->area);
    free(m->share);
    free(m->child_sum);
    free(m->distance);
    free(m->path);
    memset(m, 0, sizeof(*m));
}

/* The view as the library orthonormalises it (view.c), so that the frustum
 * tests below give its answers. */
static void prepare_eye(const tclod_view *v, model_eye *e) {
    double half_y = 0.5 * (double)v->fov_y;
    double half_x = atan((double)v->aspect * tan(half_y));
    int i;
    for (i = 0; i < 3; ++i) {
        e->eye[i] = v->eye[i];
        e->forward[i] = (double)v->forward[i];
        e->up[i] = (double)v->up[i];
    }
    unit(e->forward);
    cross_product(e->forward, e->up, e->right);
    unit(e->right);
    cross_product(e->right, e->forward, e->up);
    e->cos_y = cos(half_y);
    e->sin_y = sin(half_y);
    e->cos_x = cos(half_x);
    e->sin_x = sin(half_x);
    e->near_z = (double)v->near_z;
    e->far_z = (double)v->far_z;
    e->focal = 0.5 * (double)v->viewport_height / tan(half_y);
    e->pi_focal2 = 3.14159265358979323846 * e->focal * e->focal;
    e->viewport_area = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
}

void model_set_view(tiles_model *m, const tclod_view *v) {
    m->view = *v;
    prepare_eye(v, &m->eye);
    m->sse_factor = (double)v->viewport_height / (2.0 * tan(0.5 * (double)v->fov_y));
    /* stamp 0 is what calloc left: never a view's */
    if (++m->stamp == 0) {
        size_t n = m->count;
        memset(m->area_stamp, 0, n * sizeof(uint32_t));
        memset(m->share_stamp, 0, n * sizeof(uint32_t));
        memset(m->sum_stamp, 0, n * sizeof(uint32_t));
        memset(m->distance_stamp, 0, n * sizeof(uint32_t));
        m->stamp = 1;
    }
}

/* The eye's coordinates in a box's frame, p its centre relative to the eye. */
static void box_frame(const model_volume *v, const double p[3], double t[3]) {
    int i;
    for (i = 0; i < 3; ++i)
        t[i] = -dot(p, v->u[i]);
}

static double volume_distance(const model_eye *e, const model_volume *v) {
    double p[3], t[3], d2 = 0.0;
    int i;
    for (i = 0; i < 3; ++i)
        p[i] = v->c[i] - e->eye[i];
    if (v->r >= 0.0) {
        double d = sqrt(dot(p, p)) - v->r;
        return d > 0.0 ? d : 0.0;
    }
    box_frame(v, p, t);
    for (i = 0; i < 3; ++i) {
        double x = fabs(t[i]) - v->h[i];
        if (x > 0.0)
            d2 += x * x;
    }
    return sqrt(d2);
}

/* Whether a box meets the frustum, with its centre c and half axes a[i] in
 * view coordinates: the library's test (view.c), outside a plane when the
 * centre's signed distance exceeds its reach along the normal, sum h_i
 * |u_i . n|; in view coordinates the side planes' normals have two
 * components. p is the centre relative to the eye. */
static int box_seen(const model_eye *e, const model_volume *v, const double p[3], double c[3],
                    double a[3][3]) {
    double r[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    int i;
    c[0] = dot(p, e->right);
    c[1] = dot(p, e->up);
    c[2] = dot(p, e->forward);
    for (i = 0; i < 3; ++i) {
        a[i][0] = v->h[i] * dot(v->u[i], e->right);
        a[i][1] = v->h[i] * dot(v->u[i], e->up);
        a[i][2] = v->h[i] * dot(v->u[i], e->forward);
        r[0] += fabs(a[i][2]);
        r[1] += fabs(a[i][1] * e->cos_y - a[i][2] * e->sin_y);
        r[2] += fabs(a[i][1] * e->cos_y + a[i][2] * e->sin_y);
        r[3] += fabs(a[i][0] * e->cos_x - a[i][2] * e->sin_x);
        r[4] += fabs(a[i][0] * e->cos_x + a[i][2] * e->sin_x);
    }
    return !(e->near_z - c[2] > r[0] || c[2] - e->far_z > r[0] ||
             c[1] * e->cos_y - c[2] * e->sin_y > r[1] ||
             -c[1] * e->cos_y - c[2] * e->sin_y > r[2] ||
             c[0] * e->cos_x - c[2] * e->sin_x > r[3] || -c[0] * e->cos_x - c[2] * e->sin_x > r[4]);
}

/* Whether a sphere meets the frustum: the library's test; p as box_seen's. */
static int sphere_seen(const model_eye *e, const model_volume *v, const double p[3]) {
    double z = dot(p, e->forward);
    return !(z < e->near_z - v->r || z > e->far_z + v->r ||
             fabs(dot(p, e->up)) * e->cos_y - z * e->sin_y > v->r ||
             fabs(dot(p, e->right)) * e->cos_x - z * e->sin_x > v->r);
}

/* The projected area of a box that meets the frustum (box_seen: c, a); -1
 * when it reaches through the near plane, where faces are clipped. The area
 * is that of the faces turned towards the eye (they do not overlap), each the
 * shoelace area of its four projected corners. */
static double box_area_here(const model_eye *e, const model_volume *v, const double p[3],
                            const double c[3], const double a[3][3]) {
    double t[3], b0[2][3], b1[4][3], px[8], py[8], area = 0.0, reach = 0.0;
    int i, k;
    for (i = 0; i < 3; ++i) {
        t[i] = -dot(p, v->u[i]);
        reach += fabs(a[i][2]);
    }
    if (fabs(t[0]) <= v->h[0] && fabs(t[1]) <= v->h[1] && fabs(t[2]) <= v->h[2])
        return e->viewport_area; /* the eye inside */
    if (!(c[2] - reach - 1e-9 * (fabs(c[2]) + v->h[0] + v->h[1] + v->h[2]) > e->near_z))
        return -1.0;
    /* corner k: +a[i] where bit i of k is set, -a[i] where not */
    for (i = 0; i < 3; ++i) {
        b0[0][i] = c[i] - a[0][i];
        b0[1][i] = c[i] + a[0][i];
    }
    for (k = 0; k < 4; ++k)
        for (i = 0; i < 3; ++i)
            b1[k][i] = b0[k & 1][i] + ((k & 2) ? a[1][i] : -a[1][i]);
    for (k = 0; k < 8; ++k) {
        const double *q = b1[k & 3];
        double s = (k & 4) ? 1.0 : -1.0, w = e->focal / (q[2] + s * a[2][2]);
        px[k] = (q[0] + s * a[2][0]) * w;
        py[k] = (q[1] + s * a[2][1]) * w;
    }
    for (i = 0; i < 3; ++i) {
        int bj = 1 << ((i + 1) % 3), bl = 1 << ((i + 2) % 3), side;
        for (side = 0; side < 2; ++side) {
            int base = side ? 1 << i : 0, q0, q1, q2, q3;
            if (!((side ? t[i] : -t[i]) > v->h[i]))
                continue; /* turned away */
            /* around the face: (+j, +l), (-j, +l), (-j, -l), (+j, -l); the
             * quadrilateral's area is half the cross product of its diagonals */
            q0 = base | bj | bl;
            q1 = base | bl;
            q2 = base;
            q3 = base | bj;
            area += 0.5 * fabs((px[q2] - px[q0]) * (py[q3] - py[q1]) -
                               (py[q2] - py[q0]) * (px[q3] - px[q1]));
        }
    }
    return area < e->viewport_area ? area : e->viewport_area;
}

/* The projected area of a volume, 0 outside the frustum; -1: ask the
 * library. */
static double volume_area(const model_eye *e, const model_volume *v) {
    double p[3], c[3], a[3][3], d2, r2, area;
    int i;
    for (i = 0; i < 3; ++i)
        p[i] = v->c[i] - e->eye[i];
    if (v->r < -1.5)
        return -1.0;
    if (v->r < 0.0)
        return box_seen(e, v, p, c, a)
                   ? box_area_here(e, v, p, (const double *)c, (const double(*)[3])a)
                   : 0.0;
    /* a sphere: pi f² r² / (d² - r²) */
    if (!sphere_seen(e, v, p))
        return 0.0;
    d2 = dot(p, p);
    r2 = v->r * v->r;
    if (d2 <= r2)
        return e->viewport_area;
    area = e->pi_focal2 * r2 / (d2 - r2);
    return area < e->viewport_area ? area : e->viewport_area;
}

int model_visible(const tiles_model *m, uint32_t t) {
    const model_volume *v = &m->vol[t];
    double p[3], c[3], a[3][3];
    int i;
    if (v->r < -1.5)
        return tclod_view_bounds_visible(&m->view, &m->ts->tiles[t].bounds);
    for (i = 0; i < 3; ++i)
        p[i] = v->c[i] - m->eye.eye[i];
    return v->r < 0.0 ? box_seen(&m->eye, v, p, c, a) : sphere_seen(&m->eye, v, p);
}

double model_distance(tiles_model *m, uint32_t t) {
    if (m->distance_stamp[t] != m->stamp) {
        m->distance[t] = m->vol[t].r < -1.5
                             ? tclod_view_bounds_distance(&m->view, &m->ts->tiles[t].bounds)
                             : volume_distance(&m->eye, &m->vol[t]);
        m->distance_stamp[t] = m->stamp;
    }
    return m->distance[t];
}

double model_measure_area(const tiles_model *m, uint32_t t) {
    double a = volume_area(&m->eye, &m->vol[t]);
    if (a < 0.0) {
        const tclod_bounds *b = &m->ts->tiles[t].bounds;
        a = tclod_view_bounds_visible(&m->view, b) ? tclod_view_bounds_area(&m->view, b) : 0.0;
    }
    return a;
}

double model_area(tiles_model *m, uint32_t t) {
    if (m->area_stamp[t] != m->stamp) {
        m->area[t] = model_measure_area(m, t);
        m->area_stamp[t] = m->stamp;
    }
    return m->area[t];
}

void model_note_area(tiles_model *m, uint32_t t, double area) {
    if (m->area_stamp[t] != m->stamp) {
        m->area[t] = area;
        m->area_stamp[t] = m->stamp;
    }
}

/* The children's projected areas summed: what a parent's share is split by. */
static double children_area(tiles_model *m, uint32_t p) {
    if (m->sum_stamp[p] != m->stamp) {
        const model_link *x = &m->link[p];
        double sum = 0.0;
        uint32_t i;
        for (i = 0; i < x->child_count; ++i)
            sum += model_area(m, m->ts->children[x->first_child + i]);
        m->child_sum[p] = sum;
        m->sum_stamp[p] = m->stamp;
    }
    return m->child_sum[p];
}

/* a_t: the root's projected area, split down the tree. The ancestors without a
 * share for this view are collected first and then filled from the top, so
 * that no tile is measured twice and nothing recurses. */
static double share_of(tiles_model *m, uint32_t t) {
    uint32_t n = 0, x = t;
    while (x != TILE_NONE && m->share_stamp[x] != m->stamp) {
        m->path[n++] = x;
        x = m->link[x].parent;
    }
    while (n > 0) {
        uint32_t p;
        double s;
        x = m->path[--n];
        p = m->link[x].parent;
        if (p == TILE_NONE) {
            s = model_area(m, x);
        } else {
            double sum = children_area(m, p);
            s = sum > 0.0 ? m->share[p] * (model_area(m, x) / sum) : 0.0;
        }
        m->share[x] = s;
        m->share_stamp[x] = m->stamp;
    }
    return m->share[t];
}

double model_sse(const tiles_model *m, uint32_t t, double distance) {
    double d = distance > MODEL_MIN_DISTANCE ? distance : MODEL_MIN_DISTANCE;
    return m->link[t].geometric_error * m->sse_factor / d;
}

/* The error the benefit weighs: CesiumJS's, but from no nearer than the near
 * plane, since nothing nearer is on screen. A camera inside a tile's volume
 * (distance 0) would otherwise see every level of it at an error of 10^10 px,
 * where the quality below no longer tells one level from the next. */
static double model_seen_sse(const tiles_model *m, uint32_t t, double distance) {
    double near = (double)m->view.near_z;
    return model_sse(m, t, distance > near ? distance : near);
}

static double quality(double sse) {
    return 1.0 / (1.0 + sse / MODEL_HALF_QUALITY_SSE);
}

int model_out_of_request(const tiles_model *m, uint32_t t) {
    const tileset *ts = m->ts;
    uint32_t r = ts->tiles[t].request;
    return r != TILE_NONE && r < ts->request_count &&
           model_reference_distance(&ts->requests[r], m->view.eye) > 0.0;
}

int model_culled_by_children(tiles_model *m, uint32_t t) {
    return m->link[t].children_bound && !(children_area(m, t) > 0.0);
}

double model_benefit(tiles_model *m, uint32_t t, double distance) {
    uint32_t anchor = m->link[t].add_anchor;
    double a, q, b;
    if (model_out_of_request(m, t) || model_culled_by_children(m, t))
        return 0.0;
    a = share_of(m, t);
    q = quality(model_seen_sse(m, t, distance));
    if (!(a > 0.0))
        return 0.0; /* an ancestor is out of view: CesiumJS culls its subtree */
    if (a < MIN_SHARE)
        a = MIN_SHARE;
    /* below an additive tile that stays drawn, only the improvement counts:
     * the sums over a drawn subtree then telescope to what its finest tiles
     * show, as with replacement */
    if (anchor != TILE_NONE)
        q -= quality(model_seen_sse(m, anchor, model_distance(m, anchor)));
    b = a * q;
    return b > a * MIN_GAIN ? b : a * MIN_GAIN;
}

double model_reference_distance(const tclod_bounds *b, const double eye[3]) {
    double d[3], p[3], e2 = 0.0;
    int i, k;
    for (i = 0; i < 3; ++i)
        d[i] = eye[i] - b->center[i];
    if (b->kind == TCLOD_BOUNDS_SPHERE) {
        double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - b->radius;
        return r > 0.0 ? r : 0.0;
    }
    if (b->kind == TCLOD_BOUNDS_NONE)
        return -1.0;
    /* a box: the nearest point is the eye's offset clamped along each
     * (orthogonal) axis; a zero axis clamps to 0, so the offset across a flat
     * box counts whole */
    for (i = 0; i < 3; ++i)
        p[i] = d[i];
    for (k = 0; k < 3; ++k) {
        double axis[3], len, u, c;
        for (i = 0; i < 3; ++i)
            axis[i] = b->kind == TCLOD_BOUNDS_AABB ? (i == k ? b->half_extents[k] : 0.0)
                                                   : b->half_axes[k][i];
        len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        if (len == 0.0)
            continue;
        u = (d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]) / len;
        c = u > len ? len : (u < -len ? -len : u);
        for (i = 0; i < 3; ++i)
            p[i] -= c * axis[i] / len;
    }
    for (i = 0; i < 3; ++i)
        e2 += p[i] * p[i];
    return sqrt(e2);
}
