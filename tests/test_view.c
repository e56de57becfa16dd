/*
 * test_view — view helpers (src/core/view.c): validation, sphere-frustum tests,
 * projected screen area and distance, and how a selection fills the query
 * handed to the callbacks (screen_area, distance, view) from a node's bounds.
 * Bounding volumes of every kind (sphere, AABB, OBB): their validation, the
 * frustum test, projected area and distance against hand computations and
 * independent references, the volumes queries carry, and the precision of
 * queries at earth-centred coordinates.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"

#define PI 3.14159265358979323846

/* Relative comparison for float results computed by hand. */
static void assert_close(double got, double want, double rel) {
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("got %.9g, expected %.9g (relative tolerance %g)", got, want, rel);
}

/* The 11 floats of a view after its eye, numbered 3 .. 13 in declaration
 * order. */
static float *view_field(tclod_view *v, int i) {
    if (i < 6)
        return &v->forward[i - 3];
    if (i < 9)
        return &v->up[i - 6];
    switch (i) {
    case 9:
        return &v->fov_y;
    case 10:
        return &v->aspect;
    case 11:
        return &v->near_z;
    case 12:
        return &v->far_z;
    default:
        return &v->viewport_height;
    }
}

/* Sets field i of the 14 numbers of a view, in declaration order. */
static void set_view_field(tclod_view *v, int i, float value) {
    if (i < 3)
        v->eye[i] = (double)value;
    else
        *view_field(v, i) = value;
}

static void validate_accepts_a_normal_view(void **state) {
    tclod_view v;
    (void)state;
    helper_view(&v);
    assert_int_equal(tclod_view_validate(&v), TCLOD_OK);
    /* Not unit length and not orthogonal, but neither zero nor parallel. */
    v.forward[0] = 0.0f;
    v.forward[1] = -1.0f;
    v.forward[2] = -7.0f;
    v.up[0] = 0.3f;
    v.up[1] = 4.0f;
    v.up[2] = 1.0f;
    assert_int_equal(tclod_view_validate(&v), TCLOD_OK);
}

static void validate_rejects_null(void **state) {
    (void)state;
    assert_int_equal(tclod_view_validate(NULL), TCLOD_ERR_ARG);
}

static void validate_rejects_nan_or_inf_in_any_field(void **state) {
    const float bad[] = {NAN, INFINITY, -INFINITY};
    int field;
    size_t i;
    (void)state;
    for (field = 0; field < 14; ++field)
        for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
            tclod_view v;
            helper_view(&v);
            set_view_field(&v, field, bad[i]);
            if (tclod_view_validate(&v) != TCLOD_ERR_ARG)
                fail_msg("field %d = %g accepted", field, (double)bad[i]);
        }
}

static void validate_rejects_degenerate_directions(void **state) {
    tclod_view v;
    (void)state;
    helper_view(&v);
    v.forward[2] = 0.0f; /* zero forward */
    assert_int_equal(tclod_view_validate(&v), TCLOD_ERR_ARG);

    helper_view(&v);
    v.up[1] = 0.0f; /* zero up */
    assert_int_equal(tclod_view_validate(&v), TCLOD_ERR_ARG);

    helper_view(&v);
    v.forward[1] = 2.0f; /* forward parallel to up */
    v.forward[2] = 0.0f;
    assert_int_equal(tclod_view_validate(&v), TCLOD_ERR_ARG);

    helper_view(&v);
    v.forward[1] = -3.0f; /* anti-parallel */
    v.forward[2] = 0.0f;
    assert_int_equal(tclod_view_validate(&v), TCLOD_ERR_ARG);
}

static void validate_rejects_out_of_range_parameters(void **state) {
    /* field index, bad value */
    const struct {
        int field;
        float value;
    } cases[] = {
        {9, 0.0f},      /* fov_y <= 0 */
        {9, -0.5f},     /* fov_y < 0 */
        {9, (float)PI}, /* rounds to 3.1415927f > pi */
        {9, 3.5f},      /* fov_y > pi */
        {10, 0.0f},     /* aspect <= 0 */
        {10, -1.0f},    /* aspect < 0 */
        {11, 0.0f},     /* near_z <= 0 */
        {11, -0.1f},    /* near_z < 0 */
        {12, 0.1f},     /* far_z == near_z */
        {12, 0.05f},    /* far_z < near_z */
        {13, 0.0f},     /* viewport_height <= 0 */
        {13, -1000.0f}, /* viewport_height < 0 */
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        tclod_view v;
        helper_view(&v);
        set_view_field(&v, cases[i].field, cases[i].value);
        if (tclod_view_validate(&v) != TCLOD_ERR_ARG)
            fail_msg("field %d = %g accepted", cases[i].field, (double)cases[i].value);
    }
    {
        tclod_view v;
        helper_view(&v);
        v.fov_y = 3.1f; /* just below pi is fine */
        assert_int_equal(tclod_view_validate(&v), TCLOD_OK);
    }
}

/* Spheres around the reference view (eye at 0, looking down -z, fov 90°,
 * aspect 1, near 0.1, far 100). The side planes are |x| = -z and |y| = -z:
 * a centre (x, 0, -10) lies (x - 10) / sqrt(2) outside the right plane. */
static void sphere_visibility_against_each_plane(void **state) {
    const struct {
        float bounds[4];
        int visible;
    } cases[] = {
        {{0.0f, 0.0f, -10.0f, 1.0f}, 1},   /* straight ahead */
        {{0.0f, 0.0f, 10.0f, 1.0f}, 0},    /* behind the eye */
        {{0.0f, 0.0f, -0.05f, 0.01f}, 0},  /* before the near plane (0.04 .. 0.06) */
        {{0.0f, 0.0f, -0.05f, 0.1f}, 1},   /* straddles the near plane */
        {{0.0f, 0.0f, -200.0f, 1.0f}, 0},  /* far beyond far_z */
        {{0.0f, 0.0f, -100.5f, 1.0f}, 1},  /* straddles the far plane */
        {{20.0f, 0.0f, -10.0f, 1.0f}, 0},  /* right: 10 / sqrt 2 = 7.07 outside */
        {{-20.0f, 0.0f, -10.0f, 1.0f}, 0}, /* left */
        {{0.0f, 20.0f, -10.0f, 1.0f}, 0},  /* above */
        {{0.0f, -20.0f, -10.0f, 1.0f}, 0}, /* below */
        {{12.0f, 0.0f, -10.0f, 1.0f}, 0},  /* 2 / sqrt 2 = 1.41 > r outside */
        {{0.0f, -12.0f, -10.0f, 1.0f}, 0},
        {{11.0f, 0.0f, -10.0f, 1.0f}, 1}, /* centre 0.71 outside, r = 1: straddles */
        {{-11.0f, 0.0f, -10.0f, 1.0f}, 1},
        {{0.0f, 11.0f, -10.0f, 1.0f}, 1},
        {{0.0f, -11.0f, -10.0f, 1.0f}, 1},
        {{9.0f, 0.0f, -10.0f, 0.1f}, 1}, /* inside, near the right plane */
        {{0.0f, 0.0f, 0.0f, 1.0f}, 1},   /* contains the eye */
    };
    tclod_view v;
    size_t i;
    (void)state;
    helper_view(&v);
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        if (tclod_view_sphere_visible(&v, cases[i].bounds) != cases[i].visible)
            fail_msg("case %u: (%g, %g, %g, r %g) expected %s", (unsigned)i,
                     (double)cases[i].bounds[0], (double)cases[i].bounds[1],
                     (double)cases[i].bounds[2], (double)cases[i].bounds[3],
                     cases[i].visible ? "visible" : "outside");
}

static void sphere_visibility_uses_aspect_for_the_side_planes(void **state) {
    /* aspect 2: tan(half horizontal fov) = 2 * tan(45°) = 2, so the side
     * planes are |x| = -2z; (15, 0, -10) is inside, (0, 15, -10) still above. */
    const float right[4] = {15.0f, 0.0f, -10.0f, 1.0f};
    const float up[4] = {0.0f, 15.0f, -10.0f, 1.0f};
    /* The right plane's normal is (1, 0, 2) / sqrt 5: (25 - 20) / sqrt 5 = 2.2 out. */
    const float far_right[4] = {25.0f, 0.0f, -10.0f, 1.0f};
    tclod_view v;
    (void)state;
    helper_view(&v);
    assert_int_equal(tclod_view_sphere_visible(&v, right), 0);
    v.aspect = 2.0f;
    assert_int_equal(tclod_view_sphere_visible(&v, right), 1);
    assert_int_equal(tclod_view_sphere_visible(&v, up), 0);
    assert_int_equal(tclod_view_sphere_visible(&v, far_right), 0);
}

static void sphere_visibility_follows_a_moved_and_turned_view(void **state) {
    /* Eye at (10, 5, 3) looking along +x with up +z, given unnormalised and
     * not orthogonal; the orthonormal frame is forward +x, up +z. */
    const float ahead[4] = {20.0f, 5.0f, 3.0f, 1.0f};
    const float behind[4] = {0.0f, 5.0f, 3.0f, 1.0f};
    const float above[4] = {20.0f, 5.0f, 23.0f, 1.0f};  /* 20 up at 10 ahead */
    const float beside[4] = {20.0f, 25.0f, 3.0f, 1.0f}; /* 20 aside at 10 ahead */
    const float edge[4] = {20.0f, 5.0f, 13.5f, 1.0f};   /* 0.35 outside the top plane */
    tclod_view v;
    (void)state;
    helper_view(&v);
    v.eye[0] = 10.0f;
    v.eye[1] = 5.0f;
    v.eye[2] = 3.0f;
    v.forward[0] = 4.0f;
    v.forward[1] = 0.0f;
    v.forward[2] = 0.0f;
    v.up[0] = 0.5f;
    v.up[1] = 0.0f;
    v.up[2] = 2.0f;
    assert_int_equal(tclod_view_validate(&v), TCLOD_OK);
    assert_int_equal(tclod_view_sphere_visible(&v, ahead), 1);
    assert_int_equal(tclod_view_sphere_visible(&v, behind), 0);
    assert_int_equal(tclod_view_sphere_visible(&v, above), 0);
    assert_int_equal(tclod_view_sphere_visible(&v, beside), 0);
    assert_int_equal(tclod_view_sphere_visible(&v, edge), 1);
}

static void screen_area_matches_hand_computation(void **state) {
    tclod_view v;
    /* r = 1 at distance sqrt 2: r_px = 500 * 1 / sqrt(2 - 1) = 500 px,
     * area = pi * 500² = 785398.16 px². */
    const float at_sqrt2[4] = {0.0f, 0.0f, -1.41421356f, 1.0f};
    /* r = 1 at distance 10: r_px² = 500² / 99, area = pi * 2525.2525 = 7933.3065. */
    const float at_10[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    const float behind_10[4] = {0.0f, 0.0f, 10.0f, 1.0f};
    const float aside_10[4] = {6.0f, 0.0f, -8.0f, 1.0f}; /* also at distance 10 */
    (void)state;
    helper_view(&v);
    assert_close(tclod_view_screen_area(&v, at_sqrt2), PI * 250000.0, 1e-4);
    assert_close(tclod_view_screen_area(&v, at_10), PI * 250000.0 / 99.0, 1e-4);
    /* The frustum is not tested, only the distance matters. */
    assert_close(tclod_view_screen_area(&v, behind_10), PI * 250000.0 / 99.0, 1e-4);
    assert_close(tclod_view_screen_area(&v, aside_10), PI * 250000.0 / 99.0, 1e-4);
    /* fov_y = pi/3: focal = 500 / tan(pi/6), focal² = 250000 * 3,
     * area = pi * 750000 / 99 = 23799.9 px². */
    v.fov_y = (float)(PI / 3.0);
    assert_close(tclod_view_screen_area(&v, at_10), PI * 750000.0 / 99.0, 1e-4);
}

static void screen_area_is_clamped_to_the_viewport(void **state) {
    tclod_view v;
    /* r = 1 at distance 1.1: r_px² = 500² / 0.21, area = 3.74e6 px², more than
     * the viewport's 1000² * aspect. */
    const float close[4] = {0.0f, 0.0f, -1.1f, 1.0f};
    /* The eye inside the sphere: the whole viewport. */
    const float around[4] = {0.0f, 0.0f, -0.5f, 1.0f};
    (void)state;
    helper_view(&v);
    assert_close(tclod_view_screen_area(&v, close), 1.0e6, 1e-6);
    assert_close(tclod_view_screen_area(&v, around), 1.0e6, 1e-6);
    v.aspect = 2.0f;
    assert_close(tclod_view_screen_area(&v, close), 2.0e6, 1e-6);
    assert_close(tclod_view_screen_area(&v, around), 2.0e6, 1e-6);
}

static void distance_is_eye_to_the_sphere(void **state) {
    tclod_view v;
    const float a[4] = {4.0f, 6.0f, 3.0f, 7.0f};  /* (3, 4, 0) from the eye: inside */
    const float b[4] = {1.0f, 2.0f, -9.0f, 0.0f}; /* (0, 0, -12), a point */
    const float c[4] = {4.0f, 6.0f, 3.0f, 2.0f};  /* 5 away, radius 2 */
    (void)state;
    helper_view(&v);
    v.eye[0] = 1.0;
    v.eye[1] = 2.0;
    v.eye[2] = 3.0;
    assert_true(tclod_view_distance(&v, a) == 0.0f);
    assert_close(tclod_view_distance(&v, b), 12.0, 1e-6);
    assert_close(tclod_view_distance(&v, c), 3.0, 1e-6);
}

/* What the callbacks saw, per node. */
typedef struct captured {
    int calls[3];
    tclod_query query[3];
    int has_view[3];
    tclod_view view[3];
} captured;

static double capture_benefit(void *user, const tclod_query *q) {
    captured *c = (captured *)user;
    if (q->id < 3) {
        c->calls[q->id]++;
        c->query[q->id] = *q;
        c->has_view[q->id] = q->view != NULL;
        if (q->view != NULL)
            c->view[q->id] = *q->view;
    }
    return 1.0;
}

static double capture_cost(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static void query_carries_screen_area_and_distance_from_bounds(void **state) {
    /* Three roots: 0 in front at distance 10 (9 to its sphere), 1 behind the
     * eye at distance 10, 2 without bounds. */
    const float front[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    const float behind[4] = {0.0f, 0.0f, 10.0f, 1.0f};
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    tclod_view v;
    tclod_frame f;
    tclod_stats st;
    captured c;
    tclod_id id;
    int i;
    (void)state;
    helper_view(&v);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, front, &id), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, behind, &id), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &id), TCLOD_OK);
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = capture_benefit;
    d.callbacks.cost = capture_cost;
    d.callbacks.user = &c;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);

    memset(&c, 0, sizeof c);
    f = helper_frame(&v, 100.0);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    for (i = 0; i < 3; ++i) {
        assert_int_equal(c.calls[i], 1);
        assert_int_equal(c.query[i].id, i);
        assert_int_equal(c.query[i].count, 1);
        assert_true(c.has_view[i]);
        assert_memory_equal(&c.view[i], &v, sizeof v);
    }
    /* pi * 500² / 99, as in screen_area_matches_hand_computation. */
    assert_close(c.query[0].screen_area, PI * 250000.0 / 99.0, 1e-4);
    assert_close(c.query[0].distance, 9.0, 1e-6);
    assert_true(c.query[1].screen_area == 0.0f);
    assert_close(c.query[1].distance, 9.0, 1e-6);
    assert_true(c.query[2].screen_area == -1.0f);
    assert_true(c.query[2].distance == -1.0f);

    /* The same scene without a view: nothing is known about any node. */
    memset(&c, 0, sizeof c);
    f = helper_frame(NULL, 100.0);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    for (i = 0; i < 3; ++i) {
        assert_int_equal(c.calls[i], 1);
        assert_false(c.has_view[i]);
        assert_true(c.query[i].screen_area == -1.0f);
        assert_true(c.query[i].distance == -1.0f);
    }
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

/* ========================================================================= */
/* Bounding volumes: spheres, axis-aligned and oriented boxes                */
/* ========================================================================= */

/* ---- independent references ----------------------------------------------- */

/* The references below are computed in long double, relative to the eye, from
 * the numbers the view and the bounds hold, and by other means than the
 * library where one exists: a box's screen area is the area of the convex
 * hull of its eight projected corners (the silhouette of a convex body wholly
 * in front of the eye), not a sum over faces. */
typedef long double ldbl;

static ldbl ref_dot(const ldbl a[3], const ldbl b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void ref_cross(const ldbl a[3], const ldbl b[3], ldbl out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void ref_normalize(ldbl v[3]) {
    ldbl len = sqrtl(ref_dot(v, v));
    if (len > 0.0L) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
}

/* A view's frame as tclod_view describes it: forward normalised, right =
 * forward x up, up = right x forward; the focal length in pixels
 * f = (viewport_height / 2) / tan(fov_y / 2) and the horizontal half-angle's
 * tangent aspect * tan(fov_y / 2). */
typedef struct ref_view {
    ldbl eye[3], right[3], up[3], fwd[3];
    ldbl focal, tan_x, tan_y, near_z, far_z, viewport_area;
} ref_view;

static void ref_view_init(ref_view *r, const tclod_view *v) {
    ldbl up0[3];
    int k;
    for (k = 0; k < 3; ++k) {
        r->eye[k] = (ldbl)v->eye[k];
        r->fwd[k] = (ldbl)v->forward[k];
        up0[k] = (ldbl)v->up[k];
    }
    ref_normalize(r->fwd);
    ref_cross(r->fwd, up0, r->right);
    ref_normalize(r->right);
    ref_cross(r->right, r->fwd, r->up);
    r->tan_y = tanl(0.5L * (ldbl)v->fov_y);
    r->tan_x = (ldbl)v->aspect * r->tan_y;
    r->focal = 0.5L * (ldbl)v->viewport_height / r->tan_y;
    r->near_z = (ldbl)v->near_z;
    r->far_z = (ldbl)v->far_z;
    r->viewport_area = (ldbl)v->viewport_height * (ldbl)v->viewport_height * (ldbl)v->aspect;
}

/* q, a point relative to the eye, in view coordinates (right, up, depth). */
static void ref_view_coords(const ref_view *r, const ldbl q[3], ldbl out[3]) {
    out[0] = ref_dot(q, r->right);
    out[1] = ref_dot(q, r->up);
    out[2] = ref_dot(q, r->fwd);
}

/* Whether the world point p (double) lies inside the frustum. */
static int ref_in_frustum(const ref_view *r, const double p[3]) {
    ldbl q[3], v[3];
    int k;
    for (k = 0; k < 3; ++k)
        q[k] = (ldbl)p[k] - r->eye[k];
    ref_view_coords(r, q, v);
    return v[2] >= r->near_z && v[2] <= r->far_z && fabsl(v[0]) <= v[2] * r->tan_x &&
           fabsl(v[1]) <= v[2] * r->tan_y;
}

/* A box: centre relative to the eye, unit axes, half lengths. */
typedef struct ref_box {
    ldbl p[3];
    ldbl u[3][3];
    ldbl h[3];
} ref_box;

/* The box of AABB or OBB bounds b, read from their double fields; a zero axis
 * of an OBB (one at most here) is completed by the cross product of the other
 * two, to measure distances along it. */
static void ref_box_of(const ref_view *r, const tclod_bounds *b, ref_box *box) {
    int i, k;
    for (k = 0; k < 3; ++k)
        box->p[k] = (ldbl)b->center[k] - r->eye[k];
    for (i = 0; i < 3; ++i) {
        if (b->kind == TCLOD_BOUNDS_AABB) {
            for (k = 0; k < 3; ++k)
                box->u[i][k] = i == k ? 1.0L : 0.0L;
            box->h[i] = (ldbl)b->half_extents[i];
        } else {
            ldbl len = 0.0L;
            for (k = 0; k < 3; ++k)
                len += (ldbl)b->half_axes[i][k] * (ldbl)b->half_axes[i][k];
            box->h[i] = sqrtl(len);
            for (k = 0; k < 3; ++k)
                box->u[i][k] = box->h[i] > 0.0L ? (ldbl)b->half_axes[i][k] / box->h[i] : 0.0L;
        }
    }
    for (i = 0; i < 3; ++i)
        if (box->h[i] == 0.0L && b->kind == TCLOD_BOUNDS_OBB) {
            ref_cross(box->u[(i + 1) % 3], box->u[(i + 2) % 3], box->u[i]);
            ref_normalize(box->u[i]);
        }
}

/* The eye in the box's frame: t_i = (eye - centre) . u_i. */
static void ref_box_eye(const ref_box *box, ldbl t[3]) {
    int i;
    for (i = 0; i < 3; ++i)
        t[i] = -ref_dot(box->p, box->u[i]);
}

static ldbl ref_turn(const ldbl o[2], const ldbl a[2], const ldbl b[2]) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* The area of the convex hull of n <= 8 points (Andrew's monotone chain, then
 * the shoelace formula). Sorts pts. */
static ldbl hull_area(ldbl (*pts)[2], int n) {
    ldbl hull[16][2], area = 0.0L;
    int i, j, k = 0, lower;
    for (i = 1; i < n; ++i)
        for (j = i; j > 0 && (pts[j][0] < pts[j - 1][0] ||
                              (pts[j][0] == pts[j - 1][0] && pts[j][1] < pts[j - 1][1]));
             --j) {
            ldbl x = pts[j][0], y = pts[j][1];
            pts[j][0] = pts[j - 1][0];
            pts[j][1] = pts[j - 1][1];
            pts[j - 1][0] = x;
            pts[j - 1][1] = y;
        }
    for (i = 0; i < n; ++i) {
        while (k >= 2 && ref_turn(hull[k - 2], hull[k - 1], pts[i]) <= 0.0L)
            --k;
        hull[k][0] = pts[i][0];
        hull[k][1] = pts[i][1];
        ++k;
    }
    for (i = n - 2, lower = k + 1; i >= 0; --i) {
        while (k >= lower && ref_turn(hull[k - 2], hull[k - 1], pts[i]) <= 0.0L)
            --k;
        hull[k][0] = pts[i][0];
        hull[k][1] = pts[i][1];
        ++k;
    }
    for (i = 0; i + 1 < k; ++i)
        area += hull[i][0] * hull[i + 1][1] - hull[i + 1][0] * hull[i][1];
    return fabsl(area) / 2.0L;
}

/* The projected area of a box: the whole viewport with the eye inside, else
 * the hull of its projected corners (all of which must lie beyond the near
 * plane: the reference does not clip), at most the viewport. */
static ldbl ref_box_area(const ref_view *r, const tclod_bounds *b) {
    ref_box box;
    ldbl t[3], pts[8][2], area;
    int c, i, k;
    ref_box_of(r, b, &box);
    ref_box_eye(&box, t);
    if (fabsl(t[0]) <= box.h[0] && fabsl(t[1]) <= box.h[1] && fabsl(t[2]) <= box.h[2])
        return r->viewport_area;
    for (c = 0; c < 8; ++c) {
        ldbl q[3], v[3];
        for (k = 0; k < 3; ++k) {
            q[k] = box.p[k];
            for (i = 0; i < 3; ++i)
                q[k] += ((c >> i) & 1 ? 1.0L : -1.0L) * box.h[i] * box.u[i][k];
        }
        ref_view_coords(r, q, v);
        if (!(v[2] >= r->near_z))
            fail_msg("reference: corner %d at depth %g is before the near plane", c, (double)v[2]);
        pts[c][0] = r->focal * v[0] / v[2];
        pts[c][1] = r->focal * v[1] / v[2];
    }
    area = hull_area(pts, 8);
    return area < r->viewport_area ? area : r->viewport_area;
}

/* The distance from the eye to a box: the length of the eye's excess over the
 * half lengths in the box's frame. */
static ldbl ref_box_distance(const ref_view *r, const tclod_bounds *b) {
    ref_box box;
    ldbl t[3], d2 = 0.0L;
    int i;
    ref_box_of(r, b, &box);
    ref_box_eye(&box, t);
    for (i = 0; i < 3; ++i) {
        ldbl e = fabsl(t[i]) - box.h[i];
        if (e > 0.0L)
            d2 += e * e;
    }
    return sqrtl(d2);
}

static ldbl ref_sphere_d2(const ref_view *r, const tclod_bounds *b) {
    ldbl p[3];
    int k;
    for (k = 0; k < 3; ++k)
        p[k] = (ldbl)b->center[k] - r->eye[k];
    return ref_dot(p, p);
}

/* Both for any bounds with a volume. A sphere: pi f² r² / (d² - r²) (the
 * viewport with the eye inside, at most the viewport) and |c - eye| - r. */
static ldbl ref_area(const ref_view *r, const tclod_bounds *b) {
    ldbl d2, r2, area;
    if (b->kind != TCLOD_BOUNDS_SPHERE)
        return ref_box_area(r, b);
    d2 = ref_sphere_d2(r, b);
    r2 = (ldbl)b->radius * (ldbl)b->radius;
    if (d2 <= r2)
        return r->viewport_area;
    area = 3.14159265358979323846264338327950288L * r->focal * r->focal * r2 / (d2 - r2);
    return area < r->viewport_area ? area : r->viewport_area;
}

static ldbl ref_distance(const ref_view *r, const tclod_bounds *b) {
    ldbl d;
    if (b->kind != TCLOD_BOUNDS_SPHERE)
        return ref_box_distance(r, b);
    d = sqrtl(ref_sphere_d2(r, b)) - (ldbl)b->radius;
    return d > 0.0L ? d : 0.0L;
}

/* The focal length of a view in pixels, from the float fov_y it holds. */
static double focal_of(const tclod_view *v) {
    return 0.5 * (double)v->viewport_height / tan(0.5 * (double)v->fov_y);
}

/* Relative comparison with a description. */
static void check_close(double got, double want, double rel, const char *what) {
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("%s: got %.12g, expected %.12g (relative tolerance %g)", what, got, want, rel);
}

/* The unit axes u[i] = R e_i of the rotation by `angle` about `axis`
 * (Rodrigues: v cos a + (k x v) sin a + k (k . v)(1 - cos a)). */
static void rotation_axes(const double axis[3], double angle, double u[3][3]) {
    double k[3], len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double c = cos(angle), s = sin(angle);
    int i, j;
    for (j = 0; j < 3; ++j)
        k[j] = axis[j] / len;
    for (i = 0; i < 3; ++i) {
        /* v = e_i: k x e_i, k . e_i = k[i] */
        double kxv[3];
        kxv[0] = i == 0 ? 0.0 : (i == 1 ? -k[2] : k[1]);
        kxv[1] = i == 1 ? 0.0 : (i == 0 ? k[2] : -k[0]);
        kxv[2] = i == 2 ? 0.0 : (i == 0 ? -k[1] : k[0]);
        for (j = 0; j < 3; ++j)
            u[i][j] = (i == j ? c : 0.0) + kxv[j] * s + k[j] * k[i] * (1.0 - c);
    }
}

/* An oriented box with unit axes u and half lengths h. */
static tclod_bounds obb_of(const double center[3], const double u[3][3], const double h[3]) {
    double half_axes[9];
    int i, k;
    for (i = 0; i < 3; ++i)
        for (k = 0; k < 3; ++k)
            half_axes[3 * i + k] = h[i] * u[i][k];
    return tclod_bounds_obb(center, half_axes);
}

static tclod_bounds aabb_of(double x, double y, double z, double hx, double hy, double hz) {
    const double c[3] = {x, y, z}, h[3] = {hx, hy, hz};
    return tclod_bounds_aabb(c, h);
}

/* Whether a and b hold the same volume: the same kind and, bit for bit, the
 * fields of that kind. */
static int bounds_identical(const tclod_bounds *a, const tclod_bounds *b) {
    if (a->kind != b->kind)
        return 0;
    if (a->kind == TCLOD_BOUNDS_NONE)
        return 1;
    if (memcmp(a->center, b->center, sizeof a->center) != 0)
        return 0;
    switch (a->kind) {
    case TCLOD_BOUNDS_SPHERE:
        return memcmp(&a->radius, &b->radius, sizeof a->radius) == 0;
    case TCLOD_BOUNDS_AABB:
        return memcmp(a->half_extents, b->half_extents, sizeof a->half_extents) == 0;
    case TCLOD_BOUNDS_OBB:
        return memcmp(a->half_axes, b->half_axes, sizeof a->half_axes) == 0;
    default:
        return 0;
    }
}

/* ---- validation -------------------------------------------------------------- */

/* The fields a kind reads, in declaration order: a sphere's centre and radius
 * (4), an AABB's centre and half extents (6), an OBB's centre and half axes
 * (12). */
static int kind_field_count(tclod_bounds_kind kind) {
    return kind == TCLOD_BOUNDS_SPHERE ? 4 : (kind == TCLOD_BOUNDS_AABB ? 6 : 12);
}

static double *kind_field(tclod_bounds *b, int i) {
    if (i < 3)
        return &b->center[i];
    if (b->kind == TCLOD_BOUNDS_SPHERE)
        return &b->radius;
    if (b->kind == TCLOD_BOUNDS_AABB)
        return &b->half_extents[i - 3];
    return &b->half_axes[(i - 3) / 3][(i - 3) % 3];
}

/* Good bounds of every kind, the first three the bases of bad_cases. */
#define GOOD_CASES 16
static size_t good_cases(tclod_bounds out[GOOD_CASES], const char *what[GOOD_CASES]) {
    static const double c[3] = {1.5, -2.0, 30.0};
    static const double big[3] = {4194304.25, 1159000.5, 4650000.75}; /* earth-centred */
    static const double axis[3] = {1.0, 2.0, 3.0};
    double u[3][3], h[3] = {2.0, 0.5, 7.0}, half[9];
    size_t n = 0;
    int i;
    rotation_axes(axis, 0.7, u);
    what[n] = "sphere";
    out[n++] = tclod_bounds_sphere(1.0, 2.0, 3.0, 2.5);
    what[n] = "aabb";
    out[n++] = aabb_of(1.0, 2.0, 3.0, 1.0, 2.0, 3.0);
    what[n] = "rotated obb";
    out[n++] = obb_of(c, (const double(*)[3])u, h);
    what[n] = "sphere of radius 0";
    out[n++] = tclod_bounds_sphere(-5.0, 0.0, 1e-300, 0.0);
    what[n] = "earth-centred sphere";
    out[n++] = tclod_bounds_sphere(big[0], big[1], big[2], 1e4);
    what[n] = "zero aabb";
    out[n++] = aabb_of(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    what[n] = "flat aabb";
    out[n++] = aabb_of(1.0, 1.0, 1.0, 3.0, 0.0, 2.0);
    what[n] = "flat obb (one zero axis)";
    h[1] = 0.0;
    out[n++] = obb_of(c, (const double(*)[3])u, h);
    what[n] = "obb with two zero axes (a segment)";
    h[2] = 0.0;
    out[n++] = obb_of(big, (const double(*)[3])u, h);
    what[n] = "obb of three zero axes (a point)";
    memset(half, 0, sizeof half);
    out[n++] = tclod_bounds_obb(c, half);
    /* |cos| = 9e-4 between axes 0 and 1: within the 1e-3 allowed */
    what[n] = "obb with axes 0 and 1 at |cos| 9e-4";
    memset(half, 0, sizeof half);
    half[0] = 2.0;
    half[3] = 3.0 * 9e-4;
    half[4] = 3.0 * sqrt(1.0 - 9e-4 * 9e-4);
    half[8] = 0.25;
    out[n++] = tclod_bounds_obb(c, half);
    /* only the fields of its kind are read: NaN elsewhere is ignored */
    what[n] = "none with NaN everywhere";
    memset(&out[n], 0, sizeof out[n]);
    out[n].kind = TCLOD_BOUNDS_NONE;
    out[n].center[0] = out[n].center[1] = out[n].center[2] = NAN;
    out[n].radius = -1.0;
    for (i = 0; i < 3; ++i)
        out[n].half_extents[i] = out[n].half_axes[i][0] = out[n].half_axes[i][1] =
            out[n].half_axes[i][2] = NAN;
    ++n;
    what[n] = "sphere with bad box fields";
    out[n] = tclod_bounds_sphere(0.0, 0.0, -4.0, 1.0);
    out[n].half_extents[0] = -1.0;
    out[n].half_axes[1][1] = NAN;
    ++n;
    what[n] = "aabb with NaN radius and half axes";
    out[n] = aabb_of(0.0, 0.0, -4.0, 1.0, 1.0, 1.0);
    out[n].radius = NAN;
    out[n].half_axes[0][0] = INFINITY;
    out[n].half_axes[0][1] = 1.0; /* skewed, were it read */
    out[n].half_axes[1][0] = 1.0;
    ++n;
    what[n] = "obb with NaN radius and half extents";
    h[1] = 0.5;
    h[2] = 7.0;
    out[n] = obb_of(c, (const double(*)[3])u, h);
    out[n].radius = NAN;
    out[n].half_extents[2] = -INFINITY;
    ++n;
    what[n] = "none";
    memset(&out[n], 0, sizeof out[n]);
    ++n;
    assert_int_equal(n, GOOD_CASES);
    return n;
}

typedef struct bad_case {
    tclod_bounds b;
    char what[80];
} bad_case;

/* Bounds that tclod_bounds_validate must reject: NaN, +inf and -inf in every
 * field of each kind, negative radius and half extents, skewed OBB axes,
 * unknown kinds. Returns the count (at most cap). */
static size_t bad_cases(bad_case *out, size_t cap) {
    static const double bad[3] = {NAN, INFINITY, -INFINITY};
    static const char *bad_name[3] = {"NaN", "+inf", "-inf"};
    tclod_bounds good[GOOD_CASES];
    const char *good_what[GOOD_CASES];
    size_t n = 0;
    int g, i, j, a;
    good_cases(good, good_what);
    for (g = 0; g < 3; ++g) /* a sphere, an AABB, a rotated OBB */
        for (i = 0; i < kind_field_count(good[g].kind); ++i)
            for (j = 0; j < 3; ++j) {
                assert_true(n < cap);
                out[n].b = good[g];
                *kind_field(&out[n].b, i) = bad[j];
                snprintf(out[n].what, sizeof out[n].what, "%s: field %d = %s", good_what[g], i,
                         bad_name[j]);
                ++n;
            }
    assert_true(n + 16 <= cap);
    out[n].b = good[0];
    out[n].b.radius = -1.0;
    snprintf(out[n].what, sizeof out[n].what, "sphere of radius -1");
    ++n;
    out[n].b = good[0];
    out[n].b.radius = -1e-300;
    snprintf(out[n].what, sizeof out[n].what, "sphere of radius -1e-300");
    ++n;
    for (i = 0; i < 3; ++i) {
        out[n].b = good[1];
        out[n].b.half_extents[i] = -0.5;
        snprintf(out[n].what, sizeof out[n].what, "aabb with half extent %d = -0.5", i);
        ++n;
    }
    /* Two axes at 45°, each pair in turn: half_axes[a] = e_a + e_b (|cos| 0.71). */
    for (a = 0; a < 3; ++a) {
        int b = (a + 1) % 3;
        memset(&out[n].b, 0, sizeof out[n].b);
        out[n].b.kind = TCLOD_BOUNDS_OBB;
        for (i = 0; i < 3; ++i)
            out[n].b.half_axes[i][i] = 1.0 + i;
        out[n].b.half_axes[a][b] = out[n].b.half_axes[a][a];
        snprintf(out[n].what, sizeof out[n].what, "obb with axes %d and %d at 45 degrees", a, b);
        ++n;
    }
    /* just outside the tolerance: |cos| = 1.1e-3 between axes 0 and 1 */
    memset(&out[n].b, 0, sizeof out[n].b);
    out[n].b.kind = TCLOD_BOUNDS_OBB;
    out[n].b.half_axes[0][0] = 2.0;
    out[n].b.half_axes[1][0] = 3.0 * 1.1e-3;
    out[n].b.half_axes[1][1] = 3.0 * sqrt(1.0 - 1.1e-3 * 1.1e-3);
    out[n].b.half_axes[2][2] = 0.25;
    snprintf(out[n].what, sizeof out[n].what, "obb with axes 0 and 1 at |cos| 1.1e-3");
    ++n;
    /* a flat box whose two non-zero axes are skewed */
    memset(&out[n].b, 0, sizeof out[n].b);
    out[n].b.kind = TCLOD_BOUNDS_OBB;
    out[n].b.half_axes[0][0] = 1.0;
    out[n].b.half_axes[2][0] = 1.0;
    out[n].b.half_axes[2][2] = 1.0;
    snprintf(out[n].what, sizeof out[n].what, "flat obb with skewed axes 0 and 2");
    ++n;
    /* unknown kinds, with a good sphere's fields */
    out[n].b = good[0];
    out[n].b.kind = (tclod_bounds_kind)4;
    snprintf(out[n].what, sizeof out[n].what, "kind 4");
    ++n;
    out[n].b = good[0];
    out[n].b.kind = (tclod_bounds_kind)7;
    snprintf(out[n].what, sizeof out[n].what, "kind 7");
    ++n;
    return n;
}

static void bounds_validate_accepts_good_values_of_every_kind(void **state) {
    tclod_bounds good[GOOD_CASES];
    const char *what[GOOD_CASES];
    size_t i, n = good_cases(good, what);
    (void)state;
    for (i = 0; i < n; ++i)
        if (tclod_bounds_validate(&good[i]) != TCLOD_OK)
            fail_msg("%s rejected", what[i]);
}

static void bounds_validate_rejects_bad_values_of_every_kind(void **state) {
    bad_case bad[160];
    size_t i, n = bad_cases(bad, sizeof bad / sizeof bad[0]);
    (void)state;
    /* 3 bad values in 4 + 6 + 12 fields, 2 radii, 3 half extents, 5 skews, 2 kinds */
    assert_int_equal(n, 3 * 22 + 2 + 3 + 5 + 2);
    assert_int_equal(tclod_bounds_validate(NULL), TCLOD_ERR_ARG);
    for (i = 0; i < n; ++i)
        if (tclod_bounds_validate(&bad[i].b) != TCLOD_ERR_ARG)
            fail_msg("%s accepted", bad[i].what);
}

/* A scene of four roots with known bounds: an OBB, a sphere, none, an AABB. */
static void scene_of_four(tclod_scene **s, tclod_bounds kept[4]) {
    tclod_bounds good[GOOD_CASES];
    const char *what[GOOD_CASES];
    tclod_node_desc d;
    tclod_id id;
    int i;
    good_cases(good, what);
    kept[0] = good[2];
    kept[1] = good[0];
    memset(&kept[2], 0, sizeof kept[2]);
    kept[3] = good[1];
    assert_int_equal(tclod_scene_create(NULL, s), TCLOD_OK);
    for (i = 0; i < 4; ++i) {
        tclod_node_desc_default(&d);
        d.bounds = kept[i];
        assert_int_equal(tclod_scene_add_node_desc(*s, &d, &id), TCLOD_OK);
        assert_int_equal(id, i);
    }
}

static void good_bounds_are_stored_and_read_back_exactly(void **state) {
    tclod_bounds good[GOOD_CASES], kept[4], got;
    const char *what[GOOD_CASES];
    size_t i, n = good_cases(good, what);
    tclod_scene *s = NULL;
    tclod_node_desc d;
    tclod_id id;
    int node;
    (void)state;
    scene_of_four(&s, kept);
    for (node = 0; node < 4; ++node) {
        assert_int_equal(tclod_scene_node_bounds(s, (tclod_id)node, &got), TCLOD_OK);
        assert_true(bounds_identical(&got, &kept[node]));
    }
    for (i = 0; i < n; ++i) {
        tclod_node_desc_default(&d);
        d.bounds = good[i];
        if (tclod_scene_add_node_desc(s, &d, &id) != TCLOD_OK)
            fail_msg("%s rejected by tclod_scene_add_node_desc", what[i]);
        assert_int_equal(tclod_scene_node_bounds(s, id, &got), TCLOD_OK);
        if (!bounds_identical(&got, &good[i]))
            fail_msg("%s: tclod_scene_node_bounds differs after add", what[i]);
        /* and moved onto each of the four nodes, whatever their kind */
        for (node = 0; node < 4; ++node) {
            if (tclod_scene_set_node_bounds(s, (tclod_id)node, &good[i]) != TCLOD_OK)
                fail_msg("%s rejected by tclod_scene_set_node_bounds", what[i]);
            assert_int_equal(tclod_scene_node_bounds(s, (tclod_id)node, &got), TCLOD_OK);
            if (!bounds_identical(&got, &good[i]))
                fail_msg("%s: node %d's bounds differ after set", what[i], node);
            assert_int_equal(tclod_scene_set_node_bounds(s, (tclod_id)node, &kept[node]), TCLOD_OK);
            assert_int_equal(tclod_scene_node_bounds(s, (tclod_id)node, &got), TCLOD_OK);
            assert_true(bounds_identical(&got, &kept[node]));
        }
    }
    /* NULL sets no bounds */
    assert_int_equal(tclod_scene_set_node_bounds(s, 0, NULL), TCLOD_OK);
    assert_int_equal(tclod_scene_node_bounds(s, 0, &got), TCLOD_OK);
    assert_int_equal(got.kind, TCLOD_BOUNDS_NONE);
    tclod_scene_destroy(s);
}

static void bad_bounds_are_rejected_and_change_nothing_in_a_scene(void **state) {
    bad_case bad[160];
    size_t i, n = bad_cases(bad, sizeof bad / sizeof bad[0]);
    tclod_bounds kept[4], got;
    tclod_scene *s = NULL;
    tclod_node_desc d;
    uint32_t count;
    int node;
    (void)state;
    scene_of_four(&s, kept);
    count = tclod_scene_node_count(s);
    assert_int_equal(count, 4);
    for (i = 0; i < n; ++i) {
        tclod_id id = 12345u;
        tclod_node_desc_default(&d);
        d.bounds = bad[i].b;
        if (tclod_scene_add_node_desc(s, &d, &id) != TCLOD_ERR_ARG)
            fail_msg("%s accepted by tclod_scene_add_node_desc", bad[i].what);
        assert_int_equal(id, 12345u); /* outputs only on success */
        assert_int_equal(tclod_scene_node_count(s), count);
        d.parent = 0; /* as a child, too */
        if (tclod_scene_add_node_desc(s, &d, &id) != TCLOD_ERR_ARG)
            fail_msg("%s accepted by tclod_scene_add_node_desc under node 0", bad[i].what);
        assert_int_equal(tclod_scene_node_count(s), count);
        for (node = 0; node < 4; ++node) {
            if (tclod_scene_set_node_bounds(s, (tclod_id)node, &bad[i].b) != TCLOD_ERR_ARG)
                fail_msg("%s accepted by tclod_scene_set_node_bounds on node %d", bad[i].what,
                         node);
            assert_int_equal(tclod_scene_node_bounds(s, (tclod_id)node, &got), TCLOD_OK);
            if (!bounds_identical(&got, &kept[node]))
                fail_msg("%s changed node %d's bounds", bad[i].what, node);
        }
    }
    assert_int_equal(tclod_scene_node_count(s), count);
    for (node = 0; node < 4; ++node)
        assert_int_equal(tclod_scene_parent(s, (tclod_id)node), TCLOD_NONE);
    tclod_scene_destroy(s);
}

/* ---- frustum ------------------------------------------------------------------ */

/* The six planes of the reference view (eye at 0 looking down -z, fov 90°,
 * aspect 1, near 0.1, far 100): a point of each plane well inside the other
 * five, its outward unit normal, and a size for boxes there. The side planes
 * are |x| = -z and |y| = -z, so the right plane's outward normal is
 * (1, 0, 1) / sqrt 2. */
typedef struct frustum_plane {
    const char *name;
    double point[3];
    double normal[3];
    double scale;
} frustum_plane;

#define RSQRT2 0.70710678118654752440
static const frustum_plane reference_planes[6] = {
    {"near", {0.0, 0.0, -0.1}, {0.0, 0.0, 1.0}, 0.02},
    {"far", {0.0, 0.0, -100.0}, {0.0, 0.0, -1.0}, 1.0},
    {"right", {10.0, 0.0, -10.0}, {RSQRT2, 0.0, RSQRT2}, 1.0},
    {"left", {-10.0, 0.0, -10.0}, {-RSQRT2, 0.0, RSQRT2}, 1.0},
    {"top", {0.0, 10.0, -10.0}, {0.0, RSQRT2, RSQRT2}, 1.0},
    {"bottom", {0.0, -10.0, -10.0}, {0.0, -RSQRT2, RSQRT2}, 1.0},
};

/* Three orientations: the world axes and two rotations about skew axes. */
static void orientation(int which, double u[3][3]) {
    static const double axis1[3] = {1.0, 2.0, 3.0}, axis2[3] = {-2.0, 1.0, 0.5};
    if (which == 0) {
        memset(u, 0, 9 * sizeof(double));
        u[0][0] = u[1][1] = u[2][2] = 1.0;
    } else {
        rotation_axes(which == 1 ? axis1 : axis2, which == 1 ? 0.7 : 2.1, u);
    }
}

static double dot3d(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Corner k (bits: signs along the axes) of the box centre c, axes u, halves h. */
static void box_corner(const double c[3], const double u[3][3], const double h[3], int k,
                       double out[3]) {
    int i, j;
    for (j = 0; j < 3; ++j) {
        out[j] = c[j];
        for (i = 0; i < 3; ++i)
            out[j] += ((k >> i) & 1 ? 1.0 : -1.0) * h[i] * u[i][j];
    }
}

/* Whether p lies in the box (centre c, unit axes u, halves h). */
static int box_contains(const double c[3], const double u[3][3], const double h[3],
                        const double p[3]) {
    double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    int i;
    for (i = 0; i < 3; ++i)
        if (!(fabs(dot3d(d, u[i])) <= h[i]))
            return 0;
    return 1;
}

/* Boxes (as AABBs for the world axes, and as OBBs in three orientations) put
 * beyond one plane: the centre at the plane's point plus (reach + margin)
 * along its normal, reach = sum_i h_i |u_i . n| the box's extent along n.
 * That all eight corners lie beyond the plane is checked here first. */
static void boxes_wholly_outside_one_plane_are_invisible(void **state) {
    tclod_view v;
    int p, o, k, j;
    (void)state;
    helper_view(&v);
    for (p = 0; p < 6; ++p) {
        const frustum_plane *pl = &reference_planes[p];
        for (o = 0; o < 3; ++o) {
            double u[3][3], h[3], c[3], reach = 0.0;
            tclod_bounds b;
            orientation(o, u);
            h[0] = 1.0 * pl->scale;
            h[1] = 2.0 * pl->scale;
            h[2] = 0.5 * pl->scale;
            for (k = 0; k < 3; ++k)
                reach += h[k] * fabs(dot3d(u[k], pl->normal));
            for (j = 0; j < 3; ++j)
                c[j] = pl->point[j] + (reach + 0.05 * pl->scale) * pl->normal[j];
            for (k = 0; k < 8; ++k) {
                double q[3], d[3];
                box_corner(c, (const double(*)[3])u, h, k, q);
                for (j = 0; j < 3; ++j)
                    d[j] = q[j] - pl->point[j];
                if (!(dot3d(d, pl->normal) > 0.0))
                    fail_msg("premise: corner %d of the box beyond %s is not beyond it", k,
                             pl->name);
            }
            b = obb_of(c, (const double(*)[3])u, h);
            if (tclod_view_bounds_visible(&v, &b) != 0)
                fail_msg("obb (orientation %d) beyond the %s plane reported visible", o, pl->name);
            if (o == 0) {
                b = tclod_bounds_aabb(c, h);
                if (tclod_view_bounds_visible(&v, &b) != 0)
                    fail_msg("aabb beyond the %s plane reported visible", pl->name);
            }
        }
    }
}

/* Boxes whose centre lies beyond a plane by half their smallest half length
 * m but that reach in: the point 0.9 m back inside from the centre is in
 * the box (within its inscribed sphere) and in the frustum (checked here). */
static void boxes_straddling_a_plane_are_visible(void **state) {
    tclod_view v;
    ref_view r;
    int p, o, j;
    (void)state;
    helper_view(&v);
    ref_view_init(&r, &v);
    for (p = 0; p < 6; ++p) {
        const frustum_plane *pl = &reference_planes[p];
        for (o = 0; o < 3; ++o) {
            double u[3][3], h[3], c[3], w[3], m;
            tclod_bounds b;
            orientation(o, u);
            h[0] = 1.0 * pl->scale;
            h[1] = 2.0 * pl->scale;
            h[2] = 0.5 * pl->scale;
            m = h[2];
            for (j = 0; j < 3; ++j) {
                c[j] = pl->point[j] + 0.5 * m * pl->normal[j];
                w[j] = c[j] - 0.9 * m * pl->normal[j];
            }
            assert_false(ref_in_frustum(&r, c));
            assert_true(ref_in_frustum(&r, w));
            assert_true(box_contains(c, (const double(*)[3])u, h, w));
            b = obb_of(c, (const double(*)[3])u, h);
            if (tclod_view_bounds_visible(&v, &b) != 1)
                fail_msg("obb (orientation %d) straddling the %s plane reported invisible", o,
                         pl->name);
            if (o == 0) {
                b = tclod_bounds_aabb(c, h);
                if (tclod_view_bounds_visible(&v, &b) != 1)
                    fail_msg("aabb straddling the %s plane reported invisible", pl->name);
            }
        }
    }
    /* Inside, and around the eye (the eye is no point of the frustum, but the
     * box reaches past the near plane). */
    {
        tclod_bounds in = aabb_of(1.0, -2.0, -30.0, 0.5, 0.5, 0.5);
        tclod_bounds around = aabb_of(0.0, 0.0, 0.0, 1.0, 1.0, 1.0);
        assert_int_equal(tclod_view_bounds_visible(&v, &in), 1);
        assert_int_equal(tclod_view_bounds_visible(&v, &around), 1);
    }
}

/* The case that motivates boxes: a 13 m x 13 m x 571 m box laid along the
 * right plane of a view that reaches 1000 m, 2 m beyond it. Its long axis
 * L = cos 10° a + sin 10° y, with a = (1, 0, -1) / sqrt 2 the plane's
 * direction away from the eye, so the box is tilted within the plane; its
 * short axes are the outward normal n = (1, 0, 1) / sqrt 2 and
 * W = -sin 10° a + cos 10° y. Centre: P0 + 8.5 n, P0 = (300, 0, -300) on the
 * plane: the box's reach along n is 6.5, so its nearest point is 2 m outside,
 * while its enclosing sphere (radius sqrt(285.5² + 2 * 6.5²) = 285.57) meets
 * the frustum. Moved to P0 + 4 n it reaches 2.5 m in and is visible. */
static void a_long_thin_box_beside_the_frustum_is_invisible_though_its_sphere_is_not(void **state) {
    const double deg10 = 10.0 * PI / 180.0;
    double u[3][3], h[3] = {285.5, 6.5, 6.5}, c[3], w[3], a[3] = {RSQRT2, 0.0, -RSQRT2};
    const double n[3] = {RSQRT2, 0.0, RSQRT2}, p0[3] = {300.0, 0.0, -300.0};
    tclod_view v;
    tclod_bounds box, sphere;
    ref_view r;
    int j, k;
    (void)state;
    helper_view(&v);
    v.far_z = 1000.0f;
    ref_view_init(&r, &v);
    for (j = 0; j < 3; ++j) {
        double y = j == 1 ? 1.0 : 0.0;
        u[0][j] = cos(deg10) * a[j] + sin(deg10) * y;
        u[1][j] = n[j];
        u[2][j] = -sin(deg10) * a[j] + cos(deg10) * y;
        c[j] = p0[j] + 8.5 * n[j];
    }
    for (k = 0; k < 8; ++k) {
        double q[3];
        box_corner(c, (const double(*)[3])u, h, k, q);
        if (!(dot3d(q, n) > 1.99)) /* the plane passes through the eye */
            fail_msg("premise: corner %d only %g beyond the right plane", k, dot3d(q, n));
    }
    box = obb_of(c, (const double(*)[3])u, h);
    assert_int_equal(tclod_bounds_validate(&box), TCLOD_OK);
    sphere = tclod_bounds_sphere(c[0], c[1], c[2], sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]));
    assert_int_equal(tclod_view_bounds_visible(&v, &sphere), 1);
    assert_int_equal(tclod_view_bounds_visible(&v, &box), 0);

    for (j = 0; j < 3; ++j) {
        c[j] = p0[j] + 4.0 * n[j];
        w[j] = p0[j] - 2.0 * n[j];
    }
    assert_true(ref_in_frustum(&r, w));
    assert_true(box_contains(c, (const double(*)[3])u, h, w));
    box = obb_of(c, (const double(*)[3])u, h);
    assert_int_equal(tclod_view_bounds_visible(&v, &box), 1);
}

/* ---- projected area ------------------------------------------------------------ */

/* A 4 m x 2 m box, 1 m deep, whose front face is 10 m straight ahead: from
 * the eye in its frame, t = (0, 0, 10.5) against halves (2, 1, 0.5), only the
 * front face is turned to the eye. It projects to a rectangle f 4 / 10 by
 * f 2 / 10 pixels: f² 8 / 100, 20000 px² with f = 500. f is taken from the
 * float fov_y the view holds (tan(fov_y / 2) is 1 + 4e-8). A 6 x 3 face at 20
 * m: f² 18 / 400. A cube of half size 1e99 at 1e100 (its front face at
 * 9e99, where the product of four corner depths would overflow a double):
 * f² 4 / 81. */
static void a_box_seen_face_on_projects_to_its_rectangle(void **state) {
    tclod_view v;
    tclod_bounds b;
    double f;
    (void)state;
    helper_view(&v);
    f = focal_of(&v);
    assert_close(f, 500.0, 1e-7);
    b = aabb_of(0.0, 0.0, -10.5, 2.0, 1.0, 0.5);
    check_close(tclod_view_bounds_area(&v, &b), f * f * 8.0 / 100.0, 1e-12, "4 x 2 at 10");
    b = aabb_of(0.0, 0.0, -23.0, 3.0, 1.5, 3.0);
    check_close(tclod_view_bounds_area(&v, &b), f * f * 18.0 / 400.0, 1e-12, "6 x 3 at 20");
    b = aabb_of(0.0, 0.0, -1e100, 1e99, 1e99, 1e99);
    check_close(tclod_view_bounds_area(&v, &b), f * f * 4.0 / 81.0, 1e-12, "2e99 at 9e99");
    /* a viewport twice as high doubles f */
    v.viewport_height = 2000.0f;
    b = aabb_of(0.0, 0.0, -10.5, 2.0, 1.0, 0.5);
    check_close(tclod_view_bounds_area(&v, &b), 4.0 * f * f * 8.0 / 100.0, 1e-12, "f doubled");
}

/* The same box as an OBB turned about the view axis (z) by 45° and by 30°:
 * the front face turns within its plane, which is perpendicular to the view
 * axis, so its projection turns too and keeps its area f² 8 / 100. */
static void a_box_turned_about_the_view_axis_keeps_its_area(void **state) {
    static const double zaxis[3] = {0.0, 0.0, 1.0};
    const double c[3] = {0.0, 0.0, -10.5}, h[3] = {2.0, 1.0, 0.5};
    const double angles[3] = {PI / 4.0, PI / 6.0, 2.5};
    tclod_view v;
    double f, u[3][3];
    int i;
    (void)state;
    helper_view(&v);
    f = focal_of(&v);
    for (i = 0; i < 3; ++i) {
        tclod_bounds b;
        rotation_axes(zaxis, angles[i], u);
        b = obb_of(c, (const double(*)[3])u, h);
        check_close(tclod_view_bounds_area(&v, &b), f * f * 8.0 / 100.0, 1e-12,
                    "turned about the view axis");
    }
}

/* A cube of half size 1 centred at (-4, -4, -4), the eye at the origin
 * looking at its centre along (-1, -1, -1) with up +y: in the cube's frame
 * the eye is at (4, 4, 4), beyond the +x, +y and +z faces, which it sees.
 * Their projections tile the hexagon of the six corners other than the
 * nearest (+,+,+) and the farthest (-,-,-), listed around the diagonal. The
 * reference projects them with the view's own frame (forward (-1,-1,-1)/√3,
 * right = forward x up = (1, 0, -1)/√2, up = right x forward
 * = (-1, 2, -1)/√6) and takes the shoelace area. Seen from afar the hexagon
 * would be 2² √3 = 6.93 m² at 4√3 = 6.93 m, f² 6.93 / 48 = 36084 px²: the
 * reference is checked to be near that, and against the hull reference. */
static void a_cube_seen_from_a_corner_shows_three_faces(void **state) {
    static const int signs[6][3] = {{1, 1, -1},  {1, -1, -1}, {1, -1, 1},
                                    {-1, -1, 1}, {-1, 1, 1},  {-1, 1, -1}};
    const double s3 = sqrt(3.0), s2 = sqrt(2.0), s6 = sqrt(6.0);
    const double fwd[3] = {-1.0 / s3, -1.0 / s3, -1.0 / s3};
    const double right[3] = {1.0 / s2, 0.0, -1.0 / s2};
    const double up[3] = {-1.0 / s6, 2.0 / s6, -1.0 / s6};
    double px[6], py[6], f, want = 0.0;
    tclod_view v;
    tclod_bounds cube;
    ref_view r;
    int i, j;
    (void)state;
    helper_view(&v);
    v.forward[0] = v.forward[1] = v.forward[2] = -1.0f;
    v.up[0] = 0.0f;
    v.up[1] = 1.0f;
    v.up[2] = 0.0f;
    f = focal_of(&v);
    for (i = 0; i < 6; ++i) {
        double q[3], x, y, z;
        for (j = 0; j < 3; ++j)
            q[j] = -4.0 + signs[i][j];
        x = dot3d(q, right);
        y = dot3d(q, up);
        z = dot3d(q, fwd);
        assert_true(z > 0.1);
        px[i] = f * x / z;
        py[i] = f * y / z;
    }
    for (i = 0; i < 6; ++i)
        want += px[i] * py[(i + 1) % 6] - px[(i + 1) % 6] * py[i];
    want = 0.5 * fabs(want);
    assert_true(want > 0.8 * 36084.0 && want < 1.25 * 36084.0);
    cube = aabb_of(-4.0, -4.0, -4.0, 1.0, 1.0, 1.0);
    ref_view_init(&r, &v);
    check_close((double)ref_area(&r, &cube), want, 1e-12, "hull reference");
    check_close(tclod_view_bounds_area(&v, &cube), want, 1e-9, "cube from a corner");
    /* the same cube as an OBB with its axes permuted and reversed */
    {
        const double c[3] = {-4.0, -4.0, -4.0};
        const double half[9] = {0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0};
        cube = tclod_bounds_obb(c, half);
        check_close(tclod_view_bounds_area(&v, &cube), want, 1e-9, "cube as an obb");
    }
}

/* Boxes showing one, two and three faces, axis-aligned and turned, from the
 * reference view and from a moved and turned one: the area is that of the
 * convex hull of the eight projected corners (ref_box_area). */
static void box_areas_match_the_hull_of_their_projected_corners(void **state) {
    static const double axis1[3] = {0.3, -1.0, 0.2}, axis2[3] = {1.0, 1.0, -1.0};
    const struct {
        double c[3], h[3];
        int turn; /* 0: aabb, 1 and 2: obb about axis1 by 0.4 rad, axis2 by 1.9 rad */
    } cases[] = {
        {{0.0, 0.0, -12.0}, {1.0, 2.0, 0.5}, 0},   /* one face */
        {{4.0, 0.0, -12.0}, {1.0, 2.0, 0.5}, 0},   /* two */
        {{4.0, -3.0, -12.0}, {1.0, 2.0, 0.5}, 0},  /* three */
        {{-6.0, 5.0, -30.0}, {3.0, 0.5, 4.0}, 0},  /* three */
        {{0.0, 0.0, -12.0}, {1.0, 2.0, 0.5}, 1},   /* turned */
        {{4.0, -3.0, -12.0}, {1.0, 2.0, 0.5}, 2},  /* turned */
        {{-2.0, 7.0, -40.0}, {5.0, 0.25, 2.0}, 1}, /* turned, thin */
        {{1.0, 1.0, -3.0}, {0.5, 0.5, 0.5}, 2},    /* near */
        {{0.0, -2.0, -8.0}, {2.0, 0.0, 3.0}, 0},   /* flat: a floor seen from above */
        {{1.0, -2.0, -8.0}, {2.0, 0.0, 3.0}, 2},   /* flat, turned */
        {{30.0, 0.0, -10.0}, {1.0, 1.0, 1.0}, 1},  /* outside the frustum */
    };
    tclod_view views[2];
    size_t i;
    int k, j;
    (void)state;
    helper_view(&views[0]);
    /* eye at (10, 5, 3) looking along +x with up +z, both not unit, not orthogonal */
    helper_view(&views[1]);
    views[1].eye[0] = 10.0;
    views[1].eye[1] = 5.0;
    views[1].eye[2] = 3.0;
    views[1].forward[0] = 4.0f;
    views[1].forward[1] = 0.5f;
    views[1].forward[2] = 0.0f;
    views[1].up[0] = 0.5f;
    views[1].up[1] = 0.0f;
    views[1].up[2] = 2.0f;
    views[1].aspect = 1.5f;
    views[1].fov_y = 1.0f;
    for (k = 0; k < 2; ++k) {
        ref_view r;
        ref_view_init(&r, &views[k]);
        for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
            double c[3], u[3][3], got, want;
            char what[64];
            tclod_bounds b;
            /* the second view sees each case from the side: map (x, y, z) to
             * (eye + (-z, 1.5 - x, y)), in front along its +x (the 1.5 keeps
             * the flat boxes, flat along world y, from being seen edge-on) */
            for (j = 0; j < 3; ++j)
                c[j] = cases[i].c[j];
            if (k == 1) {
                c[0] = views[1].eye[0] - cases[i].c[2];
                c[1] = views[1].eye[1] + 1.5 - cases[i].c[0];
                c[2] = views[1].eye[2] + cases[i].c[1];
            }
            if (cases[i].turn == 0) {
                b = tclod_bounds_aabb(c, cases[i].h);
            } else {
                rotation_axes(cases[i].turn == 1 ? axis1 : axis2, cases[i].turn == 1 ? 0.4 : 1.9,
                              u);
                b = obb_of(c, (const double(*)[3])u, cases[i].h);
            }
            want = (double)ref_area(&r, &b);
            got = tclod_view_bounds_area(&views[k], &b);
            snprintf(what, sizeof what, "view %d, case %u", k, (unsigned)i);
            assert_true(want > 0.0);
            check_close(got, want, 1e-9, what);
        }
    }
}

/* The eye inside a box: the whole viewport, viewport_height² * aspect. */
static void the_eye_inside_a_box_sees_the_whole_viewport(void **state) {
    static const double axis[3] = {1.0, -1.0, 2.0};
    const double c[3] = {0.5, -0.25, 2.0}, h[3] = {1.0, 0.5, 3.0};
    double u[3][3], co[3];
    tclod_view v;
    tclod_bounds aabb, obb;
    ref_view r;
    int j;
    (void)state;
    helper_view(&v);
    ref_view_init(&r, &v);
    rotation_axes(axis, 1.1, u);
    /* the eye at (-0.5, 0.25, -2) from the centre, within the halves, in the
     * AABB's frame and in the OBB's: co = -(-0.5 u_0 + 0.25 u_1 - 2 u_2) */
    for (j = 0; j < 3; ++j)
        co[j] = 0.5 * u[0][j] - 0.25 * u[1][j] + 2.0 * u[2][j];
    aabb = tclod_bounds_aabb(c, h);
    obb = obb_of(co, (const double(*)[3])u, h);
    assert_true(ref_box_distance(&r, &aabb) == 0.0L); /* premise: the eye is inside */
    assert_true(ref_box_distance(&r, &obb) == 0.0L);
    assert_true(tclod_view_bounds_area(&v, &aabb) == 1.0e6);
    assert_true(tclod_view_bounds_area(&v, &obb) == 1.0e6);
    v.aspect = 2.0f;
    assert_true(tclod_view_bounds_area(&v, &aabb) == 2.0e6);
    assert_true(tclod_view_bounds_area(&v, &obb) == 2.0e6);
    v.viewport_height = 600.0f;
    v.aspect = 1.5f;
    assert_true(tclod_view_bounds_area(&v, &aabb) == 600.0 * 600.0 * 1.5);
}

/* However close or large a box, its area is at most the viewport's; a face
 * 200 m wide half a metre ahead (4e10 px² unclamped) gives exactly that. */
static void box_areas_never_exceed_the_viewport(void **state) {
    static const double axis[3] = {2.0, 1.0, -1.0};
    const double aspects[2] = {1.0, 2.5};
    tclod_view v;
    tclod_bounds big;
    int a, i, j, k, o;
    (void)state;
    helper_view(&v);
    for (a = 0; a < 2; ++a) {
        double viewport;
        v.aspect = (float)aspects[a];
        viewport = 1000.0 * 1000.0 * aspects[a];
        big = aabb_of(0.0, 0.0, -1.5, 100.0, 100.0, 1.0);
        assert_true(tclod_view_bounds_area(&v, &big) == viewport);
        for (i = -3; i <= 3; ++i)
            for (j = -3; j <= 3; ++j)
                for (k = 0; k < 6; ++k)
                    for (o = 0; o < 2; ++o) {
                        const double c[3] = {0.7 * i, 0.5 * j, 1.0 - 0.8 * k};
                        const double h[3] = {0.3 + 0.2 * k, 1.5, 0.05 + 0.3 * (i + 3)};
                        double u[3][3], area;
                        tclod_bounds b;
                        if (o == 0) {
                            b = tclod_bounds_aabb(c, h);
                        } else {
                            rotation_axes(axis, 0.3 * (j + 4), u);
                            b = obb_of(c, (const double(*)[3])u, h);
                        }
                        area = tclod_view_bounds_area(&v, &b);
                        if (!(area >= 0.0 && area <= viewport))
                            fail_msg("box at (%g, %g, %g): area %g outside [0, %g]", c[0], c[1],
                                     c[2], area, viewport);
                    }
    }
}

/* A strip x in [-0.05, 0.05], y in [-0.15, -0.05], z in [-1, 0.5] below the
 * eye, reaching behind it. In its frame the eye is at t = (0, 0.1, 0.25)
 * against halves (0.05, 0.05, 0.75): only its top face y = -0.05 is turned
 * to the eye. Clipped at the near plane (depth n) that face keeps depths
 * n .. 1, and projects (x f / d, y f / d) to a trapezoid: at depth n the
 * side from x = -0.05 f / n to 0.05 f / n at y = -0.05 f / n, at depth 1
 * from -0.05 f to 0.05 f at y = -0.05 f. Area (0.1 f / n + 0.1 f) / 2 *
 * (0.05 f / n - 0.05 f) = 0.0025 f² (1 / n² - 1): at n = 0.1, 0.2475 f²
 * (61875 px² at f = 500). The part of the box beyond the near plane also
 * turns its cut to the eye: the section at depth n, x in [-0.05, 0.05] and
 * y in [-0.15, -0.05], projects (scaled f / n) to 0.01 f² / n², f² at
 * n = 0.1, below the trapezoid and not overlapping it. In all 1.2475 f². The
 * view's near_z is the float 0.1f, 1.5e-9 more, which changes that by 1e-8:
 * n is taken from the view. Turned about the view axis with the eye the box
 * keeps that area. Cut short to z in [-1, -0.05], it keeps it too: its top
 * face's corners at depth 0.05, before the near plane, are cut at n all the
 * same, the section is the same, and its end face z = -0.05, now turned to
 * the eye (t_z = 0.525 > 0.475), lies wholly before the near plane and adds
 * nothing.
 *
 * An oblique cut: a square slab whose top face lies in y = -0.05 with its
 * diagonals along x and z (half axes (0.225, 0, -0.225), (0.225, 0, 0.225),
 * (0, 0.05, 0)), centred at (0, -0.1, -0.4): the eye is at t = (-0.283,
 * 0.1, 0.283) in its frame against halves (0.318, 0.05, 0.318), so again
 * only the top face is turned to it. Its corners are A (0, -0.05, -0.85),
 * B (0.45, -0.05, -0.4), C (0, -0.05, 0.05) behind the eye and D (-0.45,
 * -0.05, -0.4). The near plane cuts BC and CD at depth n: along BC the depth
 * falls from 0.4 by 0.45 s while x falls from 0.45 by 0.45 s, so at depth n,
 * x = 0.05 + n: B' (0.05 + n, -0.05, -n), D' (-0.05 - n, -0.05, -n). The
 * pentagon A B B' D' D projects (in units of f) to (0, -1/17), (1.125,
 * -0.125), (X, Y), (-X, Y), (-1.125, -0.125) with X = (0.05 + n) / n,
 * Y = -0.05 / n; the shoelace terms are 1.125/17, 1.125 Y + 0.125 X, 2 X Y,
 * 0.125 X + 1.125 Y, 1.125/17, summing to 2.25/17 + 2.25 Y + 0.25 X + 2 X Y.
 * At n = 0.1 (X = 1.5, Y = -0.5): 2.25/17 - 1.125 + 0.375 - 1.5, area
 * (2.25 - 2.25/17) / 2 = 18/17 f². The near plane cuts the slab along B'D',
 * 2 (0.05 + n) wide, through its 0.1 of height: that section projects to
 * 0.2 (0.05 + n) f² / n², 3 f² at n = 0.1, in all 18/17 f² + 3 f². */
static void a_box_partly_behind_the_near_plane_is_clipped(void **state) {
    static const double zaxis[3] = {0.0, 0.0, 1.0};
    const double c0[3] = {0.0, -0.1, -0.25}, h[3] = {0.05, 0.05, 0.75};
    const double angles[3] = {PI / 6.0, PI / 2.0, 3.5};
    const double slab_c[3] = {0.0, -0.1, -0.4};
    const double slab[9] = {0.225, 0.0, -0.225, 0.225, 0.0, 0.225, 0.0, 0.05, 0.0};
    tclod_view v;
    tclod_bounds b;
    double f, u[3][3], c[3], n, x, y, strip, pentagon;
    int i, j;
    (void)state;
    helper_view(&v);
    f = focal_of(&v);
    n = (double)v.near_z;
    strip = 0.0025 * f * f * (1.0 / (n * n) - 1.0) + 0.01 * f * f / (n * n);
    x = (0.05 + n) / n;
    y = -0.05 / n;
    pentagon = -0.5 * (2.25 / 17.0 + 2.25 * y + 0.25 * x + 2.0 * x * y) * f * f +
               0.2 * (0.05 + n) * f * f / (n * n);
    check_close(strip, 1.2475 * 250000.0, 1e-6, "premise: the strip at n = 0.1, f = 500");
    check_close(pentagon, (18.0 / 17.0 + 3.0) * 250000.0, 1e-6, "premise: the pentagon");
    b = tclod_bounds_aabb(c0, h);
    check_close(tclod_view_bounds_area(&v, &b), strip, 1e-9, "clipped strip");
    b = aabb_of(0.0, -0.1, -0.525, 0.05, 0.05, 0.475);
    check_close(tclod_view_bounds_area(&v, &b), strip, 1e-9, "strip ending before the near plane");
    for (i = 0; i < 3; ++i) {
        rotation_axes(zaxis, angles[i], u);
        /* the centre turned with the axes: c = R c0 = sum_j c0_j u_j */
        for (j = 0; j < 3; ++j)
            c[j] = c0[0] * u[0][j] + c0[1] * u[1][j] + c0[2] * u[2][j];
        b = obb_of(c, (const double(*)[3])u, h);
        check_close(tclod_view_bounds_area(&v, &b), strip, 1e-9, "turned strip");
    }
    b = tclod_bounds_obb(slab_c, slab);
    assert_int_equal(tclod_bounds_validate(&b), TCLOD_OK);
    v.aspect = 2.0f; /* 4.06 f² is more than a square viewport's 4 f² */
    check_close(tclod_view_bounds_area(&v, &b), pentagon, 1e-9, "oblique cut");
}

/* A box beside the eye, reaching far behind it and ahead: x in [-1000 - d,
 * -d], y in [-100, 100], z in [-900, 100], the eye at the origin looking down
 * -z. Its face x = -d is seen edge on, and its section by the near plane
 * (depth n), x in [-1000 - d, -d] and y in [-100, 100], projects to the
 * left half of the screen and beyond: the viewport's whole area (1000² at
 * aspect 1) once clamped, whatever small d is, instead of a sliver that
 * would shrink with d. */
static void a_box_beside_the_eye_fills_the_screen_however_close_its_face(void **state) {
    const double h[3] = {500.0, 100.0, 500.0};
    const double gaps[4] = {1e-2, 1e-3, 1e-6, 1e-9};
    tclod_view v;
    int i;
    (void)state;
    helper_view(&v);
    for (i = 0; i < 4; ++i) {
        const double c[3] = {-500.0 - gaps[i], 0.0, -400.0};
        tclod_bounds b = tclod_bounds_aabb(c, h);
        check_close(tclod_view_bounds_area(&v, &b), 1.0e6, 1e-12, "box beside the eye");
    }
}

/* ---- distance ------------------------------------------------------------------ */

/* The eye at (1, 2, 3), boxes of halves (2, 3, 4) placed relative to it: the
 * eye's excess over the halves in the box's frame is what is left of its
 * offset (a centre 5 to the right leaves 5 - 2 = 3, and so on). */
static void box_distance_is_to_the_nearest_face_edge_or_corner(void **state) {
    const struct {
        double off[3]; /* centre - eye */
        double want;
        const char *what;
    } cases[] = {
        {{0.5, -1.0, 1.0}, 0.0, "inside"},
        {{2.0, 0.0, 0.0}, 0.0, "on a face"},
        {{0.0, 0.0, -10.0}, 6.0, "to a face: 10 - 4"},
        {{0.0, -4.0, 0.0}, 1.0, "to a face: 4 - 3"},
        {{5.0, 0.0, -10.0}, sqrt(45.0), "to an edge: sqrt(3² + 6²)"},
        {{-5.0, 7.0, 0.0}, 5.0, "to an edge: sqrt(3² + 4²)"},
        {{5.0, -7.0, -10.0}, sqrt(61.0), "to a corner: sqrt(3² + 4² + 6²)"},
        {{-2.5, 3.5, 4.5}, sqrt(0.75), "to a corner: sqrt(3 * 0.5²)"},
    };
    const double h[3] = {2.0, 3.0, 4.0};
    tclod_view v;
    size_t i;
    (void)state;
    helper_view(&v);
    v.eye[0] = 1.0;
    v.eye[1] = 2.0;
    v.eye[2] = 3.0;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const double c[3] = {1.0 + cases[i].off[0], 2.0 + cases[i].off[1], 3.0 + cases[i].off[2]};
        tclod_bounds b = tclod_bounds_aabb(c, h);
        double got = tclod_view_bounds_distance(&v, &b);
        if (cases[i].want == 0.0) {
            if (got != 0.0)
                fail_msg("%s: got %.17g, expected 0", cases[i].what, got);
        } else {
            check_close(got, cases[i].want, 1e-15, cases[i].what);
        }
    }
    /* a zero box is a point: |c - eye| = |(3, 4, 12)| = 13 */
    {
        const double c[3] = {4.0, 6.0, 15.0}, zero[3] = {0.0, 0.0, 0.0};
        tclod_bounds b = tclod_bounds_aabb(c, zero);
        check_close(tclod_view_bounds_distance(&v, &b), 13.0, 1e-15, "a point");
    }
}

/* An OBB turned about (1, -2, 0.5) by 0.9 rad, centred at (100, -50, 20),
 * with the eye placed at t = (5, -7, -10) in its frame (eye = c + sum t_i
 * u_i): against halves (2, 3, 4) the excess is (3, 4, 6), distance sqrt 61.
 * A flat OBB (halves (2, 3, 0)) with the eye at t = (1, 1, 5) is 5 away (the
 * eye above the face), at t = (4, 1, -5) sqrt(2² + 5²). */
static void turned_box_distance_is_measured_in_its_frame(void **state) {
    static const double axis[3] = {1.0, -2.0, 0.5};
    const double c[3] = {100.0, -50.0, 20.0};
    const struct {
        double h[3], t[3], want;
    } cases[] = {
        {{2.0, 3.0, 4.0}, {5.0, -7.0, -10.0}, 7.810249675906654}, /* sqrt 61 */
        {{2.0, 3.0, 4.0}, {1.0, -2.0, 3.0}, 0.0},                 /* inside */
        {{2.0, 3.0, 4.0}, {1.0, 8.0, 0.0}, 5.0},                  /* a face */
        {{2.0, 3.0, 0.0}, {1.0, 1.0, 5.0}, 5.0},                  /* flat, above */
        {{2.0, 3.0, 0.0}, {4.0, 1.0, -5.0}, 5.385164807134504},   /* sqrt 29 */
        {{0.0, 3.0, 4.0}, {-6.0, 0.0, 0.0}, 6.0},                 /* flat, before */
    };
    tclod_view v;
    double u[3][3];
    size_t i;
    int j;
    (void)state;
    rotation_axes(axis, 0.9, u);
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        tclod_bounds b = obb_of(c, (const double(*)[3])u, cases[i].h);
        double got;
        helper_view(&v);
        for (j = 0; j < 3; ++j)
            v.eye[j] =
                c[j] + cases[i].t[0] * u[0][j] + cases[i].t[1] * u[1][j] + cases[i].t[2] * u[2][j];
        got = tclod_view_bounds_distance(&v, &b);
        if (cases[i].want == 0.0) {
            if (got != 0.0)
                fail_msg("case %u: got %.17g, expected 0", (unsigned)i, got);
        } else {
            check_close(got, cases[i].want, 1e-12, "turned box");
        }
    }
}

/* |c - eye| - r, 0 inside: the eye at (1, 2, 3), centres (3, 4, 12) away
 * (13). */
static void sphere_distance_is_centre_distance_less_radius(void **state) {
    const double radii[5] = {0.0, 5.0, 12.5, 13.0, 20.0};
    const double want[5] = {13.0, 8.0, 0.5, 0.0, 0.0};
    tclod_view v;
    int i;
    (void)state;
    helper_view(&v);
    v.eye[0] = 1.0;
    v.eye[1] = 2.0;
    v.eye[2] = 3.0;
    for (i = 0; i < 5; ++i) {
        tclod_bounds b = tclod_bounds_sphere(4.0, 6.0, 15.0, radii[i]);
        double got = tclod_view_bounds_distance(&v, &b);
        if (want[i] == 0.0)
            assert_true(got == 0.0);
        else
            check_close(got, want[i], 1e-15, "sphere");
    }
    /* the same in double at earth scale: 6.4e6 m out, 1e-3 m resolved */
    v.eye[0] = 6400000.0;
    v.eye[1] = 0.0;
    v.eye[2] = 0.0;
    {
        tclod_bounds b = tclod_bounds_sphere(6400000.0 + 3.0, 4.0, 12.0, 12.999);
        check_close(tclod_view_bounds_distance(&v, &b), 0.001, 1e-9, "earth-scale sphere");
    }
}

static void bounds_none_has_no_area_nor_distance_and_is_visible(void **state) {
    tclod_view v;
    tclod_bounds none;
    (void)state;
    helper_view(&v);
    memset(&none, 0, sizeof none);
    assert_int_equal(tclod_bounds_validate(&none), TCLOD_OK);
    assert_int_equal(tclod_view_bounds_visible(&v, &none), 1);
    assert_true(tclod_view_bounds_area(&v, &none) == -1.0);
    assert_true(tclod_view_bounds_distance(&v, &none) == -1.0);
}

/* ---- queries ------------------------------------------------------------------- */

#define CAPTURE_NODES 16

/* What the benefit callback saw with a view, per node; the query's bounds
 * pointer is valid only during the call, so the volume is copied. */
typedef struct volume_capture {
    int calls[CAPTURE_NODES];
    tclod_query query[CAPTURE_NODES];
    int has_bounds[CAPTURE_NODES];
    tclod_bounds bounds[CAPTURE_NODES];
} volume_capture;

static double volume_benefit(void *user, const tclod_query *q) {
    volume_capture *c = (volume_capture *)user;
    if (q->id < CAPTURE_NODES && q->view != NULL) {
        c->calls[q->id]++;
        c->query[q->id] = *q;
        c->query[q->id].bounds = NULL;
        c->has_bounds[q->id] = q->bounds != NULL;
        if (q->bounds != NULL)
            c->bounds[q->id] = *q->bounds;
    }
    return 1.0;
}

static double volume_cost(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

static const char *solver_name(tclod_solver solver) {
    return solver == TCLOD_SOLVER_GREEDY ? "greedy"
                                         : (solver == TCLOD_SOLVER_MIXED ? "mixed" : "robin hood");
}

static tclod_selector *volume_selector(const tclod_scene *s, tclod_solver solver,
                                       volume_capture *c) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    d.solver = solver;
    d.callbacks.benefit = volume_benefit;
    d.callbacks.cost = volume_cost;
    d.callbacks.user = c;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

/* Selects once for view v (every node is a root of cost 1 within the
 * budget) and checks that each of the first n nodes was asked about once. */
static void select_and_capture(tclod_selector *sel, const tclod_view *v, volume_capture *c,
                               uint32_t n, const char *solver) {
    tclod_frame f = helper_frame(v, 100.0);
    tclod_stats st;
    uint32_t i;
    memset(c, 0, sizeof *c);
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    for (i = 0; i < n; ++i)
        if (c->calls[i] != 1)
            fail_msg("%s: node %u asked %d times with a view", solver, (unsigned)i, c->calls[i]);
}

/* Checks node i's query against the volume b it was given: the same kind and
 * fields bit for bit, the helpers' area and distance (the distance as a
 * float), and the independent references. */
static void check_query_volume(const volume_capture *c, uint32_t i, const tclod_view *v,
                               const tclod_bounds *b, const char *solver) {
    const tclod_query *q = &c->query[i];
    ref_view r;
    if (b->kind == TCLOD_BOUNDS_NONE) {
        if (c->has_bounds[i] || q->screen_area != -1.0f || q->distance != -1.0f)
            fail_msg("%s: node %u without bounds: bounds %s, area %g, distance %g", solver,
                     (unsigned)i, c->has_bounds[i] ? "set" : "NULL", (double)q->screen_area,
                     (double)q->distance);
        return;
    }
    if (!c->has_bounds[i])
        fail_msg("%s: node %u's query has no bounds", solver, (unsigned)i);
    if (!bounds_identical(&c->bounds[i], b))
        fail_msg("%s: node %u's query volume (kind %d) differs from its bounds (kind %d)", solver,
                 (unsigned)i, (int)c->bounds[i].kind, (int)b->kind);
    assert_int_equal(tclod_view_bounds_visible(v, b), 1);
    if (q->screen_area != (float)tclod_view_bounds_area(v, b))
        fail_msg("%s: node %u: screen_area %.9g, helper %.9g", solver, (unsigned)i,
                 (double)q->screen_area, tclod_view_bounds_area(v, b));
    if (q->distance != (float)tclod_view_bounds_distance(v, b))
        fail_msg("%s: node %u: distance %.9g, helper %.9g", solver, (unsigned)i,
                 (double)q->distance, tclod_view_bounds_distance(v, b));
    ref_view_init(&r, v);
    check_close((double)q->screen_area, (double)ref_area(&r, b), 1e-6, "area against reference");
    check_close((double)q->distance, (double)ref_distance(&r, b), 1e-6,
                "distance against reference");
    assert_true(q->screen_area > 0.0f && q->distance > 0.0f);
}

/* Five roots in front of the reference view: an AABB, an OBB, none, a
 * sphere, a flat OBB; then each moved to another volume with
 * tclod_scene_set_node_bounds, and the next select's queries carry the new
 * ones. With every solver this build provides. */
static void queries_carry_the_node_volume_and_its_measures(void **state) {
    static const double axis[3] = {0.5, 1.0, -0.3};
    const double c1[3] = {-2.0, 1.0, -20.0}, h1[3] = {1.5, 0.75, 3.0};
    const double c4[3] = {3.0, 0.0, -15.0}, h4[3] = {2.0, 0.0, 1.0};
    const double c5[3] = {0.5, -1.0, -9.0}, h5[3] = {0.5, 2.0, 1.0};
    tclod_bounds first[5], second[5];
    double u[3][3];
    tclod_view v;
    int solver;
    uint32_t i;
    (void)state;
    helper_view(&v);
    rotation_axes(axis, 0.8, u);
    first[0] = aabb_of(1.0, -0.5, -12.0, 2.0, 1.0, 0.5);
    first[1] = obb_of(c1, (const double(*)[3])u, h1);
    memset(&first[2], 0, sizeof first[2]);
    first[3] = tclod_bounds_sphere(0.25, 0.125, -7.5, 0.7);
    first[4] = obb_of(c4, (const double(*)[3])u, h4);
    second[0] = obb_of(c5, (const double(*)[3])u, h5);
    memset(&second[1], 0, sizeof second[1]);
    second[2] = aabb_of(-3.0, 2.0, -25.0, 1.0, 1.0, 4.0);
    second[3] = aabb_of(0.0, 0.0, -6.0, 0.25, 0.25, 0.25);
    second[4] = tclod_bounds_sphere(3.0, 0.0, -15.0, 2.0);
    for (solver = 0; solver < 3; ++solver) {
        const char *name = solver_name((tclod_solver)solver);
        volume_capture c;
        tclod_scene *s = NULL;
        tclod_selector *sel;
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        for (i = 0; i < 5; ++i) {
            tclod_node_desc d;
            tclod_id id;
            tclod_node_desc_default(&d);
            d.bounds = first[i];
            assert_int_equal(tclod_scene_add_node_desc(s, &d, &id), TCLOD_OK);
            assert_int_equal(id, i);
        }
        sel = volume_selector(s, (tclod_solver)solver, &c);
        select_and_capture(sel, &v, &c, 5, name);
        for (i = 0; i < 5; ++i)
            check_query_volume(&c, i, &v, &first[i], name);
        for (i = 0; i < 5; ++i)
            assert_int_equal(tclod_scene_set_node_bounds(s, i, i == 1 ? NULL : &second[i]),
                             TCLOD_OK);
        select_and_capture(sel, &v, &c, 5, name);
        for (i = 0; i < 5; ++i)
            check_query_volume(&c, i, &v, &second[i], name);
        /* and back */
        for (i = 0; i < 5; ++i)
            assert_int_equal(tclod_scene_set_node_bounds(s, i, &first[i]), TCLOD_OK);
        select_and_capture(sel, &v, &c, 5, name);
        for (i = 0; i < 5; ++i)
            check_query_volume(&c, i, &v, &first[i], name);
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
    }
}

/* Boxes outside the frustum: the query's screen_area is 0, while
 * tclod_view_bounds_area, which does not test the frustum, gives their
 * silhouette (ref_box_area: all their corners are well in front of the
 * eye); the distance is measured all the same. The AABB at (20, 0, -10) of
 * half size 1 lies 6 / sqrt 2 beyond the right plane; from it the eye is at
 * t = (-20, 0, 10), excess (19, 0, 9): distance sqrt(442). */
static void outside_the_frustum_the_query_area_is_zero_but_the_helper_area_is_not(void **state) {
    static const double axis[3] = {1.0, 1.0, 0.0};
    const double c1[3] = {0.0, -30.0, -12.0}, h1[3] = {2.0, 1.0, 3.0};
    tclod_bounds b[2];
    double u[3][3];
    tclod_view v;
    ref_view r;
    int solver;
    uint32_t i;
    (void)state;
    helper_view(&v);
    ref_view_init(&r, &v);
    rotation_axes(axis, 0.6, u);
    b[0] = aabb_of(20.0, 0.0, -10.0, 1.0, 1.0, 1.0);
    b[1] = obb_of(c1, (const double(*)[3])u, h1); /* below the bottom plane */
    for (i = 0; i < 2; ++i) {
        assert_int_equal(tclod_view_bounds_visible(&v, &b[i]), 0);
        check_close(tclod_view_bounds_area(&v, &b[i]), (double)ref_area(&r, &b[i]), 1e-9,
                    "helper area outside");
        assert_true(tclod_view_bounds_area(&v, &b[i]) > 100.0);
    }
    check_close(tclod_view_bounds_distance(&v, &b[0]), sqrt(442.0), 1e-15, "distance outside");
    for (solver = 0; solver < 3; ++solver) {
        const char *name = solver_name((tclod_solver)solver);
        volume_capture c;
        tclod_scene *s = NULL;
        tclod_selector *sel;
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        for (i = 0; i < 2; ++i) {
            tclod_node_desc d;
            tclod_id id;
            tclod_node_desc_default(&d);
            d.bounds = b[i];
            assert_int_equal(tclod_scene_add_node_desc(s, &d, &id), TCLOD_OK);
        }
        sel = volume_selector(s, (tclod_solver)solver, &c);
        select_and_capture(sel, &v, &c, 2, name);
        for (i = 0; i < 2; ++i) {
            if (c.query[i].screen_area != 0.0f)
                fail_msg("%s: node %u outside: screen_area %g", name, (unsigned)i,
                         (double)c.query[i].screen_area);
            assert_true(c.has_bounds[i]);
            assert_true(bounds_identical(&c.bounds[i], &b[i]));
            assert_true(c.query[i].distance == (float)tclod_view_bounds_distance(&v, &b[i]));
        }
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
    }
}

/* ---- earth-scale precision ----------------------------------------------------- */

/* The WGS84 ellipsoid: semi-major axis and flattening. */
#define WGS84_A 6378137.0L
#define WGS84_F (1.0L / 298.257223563L)

static ldbl radians(ldbl degrees) {
    return degrees * 3.14159265358979323846264338327950288L / 180.0L;
}

/* Earth-centred, earth-fixed coordinates of a geodetic position: with
 * e² = f (2 - f) and N = a / sqrt(1 - e² sin² lat),
 * (N + h) cos lat cos lon, (N + h) cos lat sin lon, (N (1 - e²) + h) sin lat. */
static void geodetic_to_ecef(ldbl lat, ldbl lon, ldbl height, ldbl out[3]) {
    ldbl e2 = WGS84_F * (2.0L - WGS84_F), sl = sinl(lat), cl = cosl(lat);
    ldbl n = WGS84_A / sqrtl(1.0L - e2 * sl * sl);
    out[0] = (n + height) * cl * cosl(lon);
    out[1] = (n + height) * cl * sinl(lon);
    out[2] = (n * (1.0L - e2) + height) * sl;
}

/* The local east, north and up unit vectors at a geodetic position. */
static void enu_frame(ldbl lat, ldbl lon, ldbl east[3], ldbl north[3], ldbl up[3]) {
    east[0] = -sinl(lon);
    east[1] = cosl(lon);
    east[2] = 0.0L;
    north[0] = -sinl(lat) * cosl(lon);
    north[1] = -sinl(lat) * sinl(lon);
    north[2] = cosl(lat);
    up[0] = cosl(lat) * cosl(lon);
    up[1] = cosl(lat) * sinl(lon);
    up[2] = sinl(lat);
}

/* The direction at azimuth az (degrees from north towards east) and elevation
 * el (degrees above the horizon). */
static void enu_direction(const ldbl east[3], const ldbl north[3], const ldbl up[3], ldbl az,
                          ldbl el, ldbl out[3]) {
    int k;
    for (k = 0; k < 3; ++k)
        out[k] = cosl(radians(el)) * (sinl(radians(az)) * east[k] + cosl(radians(az)) * north[k]) +
                 sinl(radians(el)) * up[k];
}

/* Targets seen from 300 m above the ellipsoid at 47.07° N, 15.44° E (Graz),
 * looking at azimuth 40°, 3° down, with a 60° vertical field of view, 16:9, a
 * 1080 px viewport (f = 540 / tan 30° = 935 px) reaching 20 km. Each lies at
 * `range` metres along (az, el), well inside the frustum; boxes are OBBs
 * along the local east/north/up frame turned by `heading` about up, or
 * AABBs along the earth-centred axes; size: radius, or half lengths. */
enum { EARTH_SPHERE, EARTH_AABB, EARTH_OBB };
static const struct earth_target {
    int kind;
    double az, el, range, heading;
    double size[3];
} earth_targets[] = {
    {EARTH_SPHERE, 40.0, -3.0, 10.0, 0.0, {0.5, 0.0, 0.0}},
    {EARTH_SPHERE, 52.0, 2.0, 150.0, 0.0, {5.0, 0.0, 0.0}},
    {EARTH_SPHERE, 30.0, -8.0, 2000.0, 0.0, {40.0, 0.0, 0.0}},
    {EARTH_SPHERE, 45.0, 1.0, 10000.0, 0.0, {300.0, 0.0, 0.0}},
    {EARTH_AABB, 35.0, -10.0, 12.0, 0.0, {1.0, 1.5, 0.8}},
    {EARTH_AABB, 48.0, -1.0, 400.0, 0.0, {10.0, 6.0, 8.0}},
    {EARTH_AABB, 28.0, 4.0, 3000.0, 0.0, {150.0, 100.0, 120.0}},
    {EARTH_AABB, 55.0, -2.0, 9500.0, 0.0, {600.0, 400.0, 500.0}},
    {EARTH_OBB, 42.0, -12.0, 25.0, 0.0, {2.0, 3.0, 1.5}},
    {EARTH_OBB, 33.0, 0.0, 800.0, 30.0, {20.0, 35.0, 12.0}},
    {EARTH_OBB, 50.0, -5.0, 5000.0, -20.0, {1000.0, 600.0, 50.0}},
    {EARTH_OBB, 38.0, 3.0, 10000.0, 10.0, {2000.0, 1500.0, 300.0}},
    {EARTH_OBB, 44.0, -6.0, 60.0, 45.0, {8.0, 5.0, 0.0}}, /* flat: a roof */
};
#define EARTH_TARGETS (sizeof earth_targets / sizeof earth_targets[0])

/* The view, and the targets' bounds in double. */
static void earth_scene(tclod_view *v, tclod_bounds b[EARTH_TARGETS]) {
    const ldbl lat = radians(47.07L), lon = radians(15.44L);
    ldbl eye[3], east[3], north[3], up[3], fwd[3];
    size_t i;
    int k;
    geodetic_to_ecef(lat, lon, 300.0L, eye);
    enu_frame(lat, lon, east, north, up);
    enu_direction(east, north, up, 40.0L, -3.0L, fwd);
    memset(v, 0, sizeof *v);
    for (k = 0; k < 3; ++k) {
        v->eye[k] = (double)eye[k];
        v->forward[k] = (float)fwd[k];
        v->up[k] = (float)up[k];
    }
    v->fov_y = (float)(PI / 3.0);
    v->aspect = 16.0f / 9.0f;
    v->near_z = 0.5f;
    v->far_z = 20000.0f;
    v->viewport_height = 1080.0f;
    for (i = 0; i < EARTH_TARGETS; ++i) {
        const struct earth_target *t = &earth_targets[i];
        ldbl dir[3], e[3], n[3];
        double c[3];
        enu_direction(east, north, up, (ldbl)t->az, (ldbl)t->el, dir);
        for (k = 0; k < 3; ++k)
            c[k] = (double)((ldbl)v->eye[k] + (ldbl)t->range * dir[k]);
        if (t->kind == EARTH_SPHERE) {
            b[i] = tclod_bounds_sphere(c[0], c[1], c[2], t->size[0]);
        } else if (t->kind == EARTH_AABB) {
            b[i] = tclod_bounds_aabb(c, t->size);
        } else {
            double half[9];
            ldbl hd = radians((ldbl)t->heading);
            for (k = 0; k < 3; ++k) {
                e[k] = cosl(hd) * east[k] - sinl(hd) * north[k];
                n[k] = sinl(hd) * east[k] + cosl(hd) * north[k];
                half[k] = (double)((ldbl)t->size[0] * e[k]);
                half[3 + k] = (double)((ldbl)t->size[1] * n[k]);
                half[6 + k] = (double)((ldbl)t->size[2] * up[k]);
            }
            b[i] = tclod_bounds_obb(c, half);
        }
    }
}

/* The requirement: with the eye and the bounds about 6.4e6 m from the
 * earth's centre, for bounds within 10 km of the eye, the query's distance is
 * within 1 mm and its screen area within 1e-4 relative of a computation in
 * higher precision. The references (ref_area, ref_distance) work in long
 * double relative to the eye from the doubles given to the library; the
 * queries are those the benefit callback receives during tclod_select, with
 * every solver this build provides. */
static void earth_scale_queries_keep_millimetres_and_areas(void **state) {
    tclod_bounds b[EARTH_TARGETS];
    tclod_view v;
    ref_view r;
    ldbl radius;
    int solver;
    uint32_t i;
    (void)state;
    earth_scene(&v, b);
    assert_int_equal(tclod_view_validate(&v), TCLOD_OK);
    ref_view_init(&r, &v);
    radius = sqrtl(ref_dot(r.eye, r.eye));
    assert_true(radius > 6.36e6L && radius < 6.38e6L);
    for (i = 0; i < EARTH_TARGETS; ++i) {
        ldbl d = ref_distance(&r, &b[i]);
        assert_int_equal(tclod_bounds_validate(&b[i]), TCLOD_OK);
        assert_true(ref_in_frustum(&r, b[i].center));
        assert_true(d > 9.0L && d <= 10000.0L);
        assert_true(ref_area(&r, &b[i]) < r.viewport_area);
    }
    for (solver = 0; solver < 3; ++solver) {
        const char *name = solver_name((tclod_solver)solver);
        volume_capture c;
        tclod_scene *s = NULL;
        tclod_selector *sel;
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        for (i = 0; i < EARTH_TARGETS; ++i) {
            tclod_node_desc d;
            tclod_id id;
            tclod_node_desc_default(&d);
            d.bounds = b[i];
            assert_int_equal(tclod_scene_add_node_desc(s, &d, &id), TCLOD_OK);
            assert_int_equal(id, i);
        }
        sel = volume_selector(s, (tclod_solver)solver, &c);
        select_and_capture(sel, &v, &c, EARTH_TARGETS, name);
        for (i = 0; i < EARTH_TARGETS; ++i) {
            ldbl want_d = ref_distance(&r, &b[i]), want_a = ref_area(&r, &b[i]);
            ldbl got_d = (ldbl)c.query[i].distance, got_a = (ldbl)c.query[i].screen_area;
            assert_true(c.has_bounds[i]);
            assert_true(bounds_identical(&c.bounds[i], &b[i]));
            if (!(fabsl(got_d - want_d) <= 1e-3L))
                fail_msg("%s: target %u: distance %.6f m, reference %.6f m (off %.3g m)", name,
                         (unsigned)i, (double)got_d, (double)want_d, (double)(got_d - want_d));
            if (!(fabsl(got_a - want_a) <= 1e-4L * want_a))
                fail_msg("%s: target %u: area %.6g px², reference %.6g px² (relative %.3g)", name,
                         (unsigned)i, (double)got_a, (double)want_a,
                         (double)((got_a - want_a) / want_a));
        }
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
    }
}

/* The same scene the old way: float spheres (tclod_scene_add_node; boxes by
 * their enclosing spheres) and the eye rounded to float, as a host without
 * double bounds would give them. Float spacing is 0.125 .. 0.5 m at these
 * coordinates (1.2e6 .. 4.7e6 m), so the distances miss the exact ones (the
 * same spheres, from the exact eye and centres) by far more than the 1 mm
 * the test above allows: that test can fail. */
static void earth_scale_float_bounds_miss_by_more_than_a_millimetre(void **state) {
    tclod_bounds b[EARTH_TARGETS];
    tclod_view v, fv;
    volume_capture c;
    tclod_scene *s = NULL;
    tclod_selector *sel;
    ref_view r;
    ldbl worst_d = 0.0L, worst_a = 0.0L;
    uint32_t i;
    int k;
    (void)state;
    earth_scene(&v, b);
    ref_view_init(&r, &v);
    fv = v;
    for (k = 0; k < 3; ++k)
        fv.eye[k] = (double)(float)v.eye[k];
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (i = 0; i < EARTH_TARGETS; ++i) {
        float fb[4];
        tclod_id id;
        double radius = b[i].radius;
        if (b[i].kind != TCLOD_BOUNDS_SPHERE) {
            double h2 = 0.0;
            for (k = 0; k < 3; ++k)
                h2 += b[i].kind == TCLOD_BOUNDS_AABB ? b[i].half_extents[k] * b[i].half_extents[k]
                                                     : dot3d(b[i].half_axes[k], b[i].half_axes[k]);
            radius = sqrt(h2);
        }
        for (k = 0; k < 3; ++k)
            fb[k] = (float)b[i].center[k];
        fb[3] = (float)radius;
        assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, fb, &id), TCLOD_OK);
        /* the exact sphere: the double centre, the float radius */
        b[i] = tclod_bounds_sphere(b[i].center[0], b[i].center[1], b[i].center[2], (double)fb[3]);
    }
    sel = volume_selector(s, TCLOD_SOLVER_GREEDY, &c);
    select_and_capture(sel, &fv, &c, EARTH_TARGETS, "greedy");
    for (i = 0; i < EARTH_TARGETS; ++i) {
        ldbl want_d = ref_distance(&r, &b[i]), want_a = ref_area(&r, &b[i]);
        ldbl err_d = fabsl((ldbl)c.query[i].distance - want_d);
        ldbl err_a = fabsl((ldbl)c.query[i].screen_area - want_a) / want_a;
        assert_true(want_a > 0.0L);
        if (err_d > worst_d)
            worst_d = err_d;
        if (err_a > worst_a)
            worst_a = err_a;
    }
    if (!(worst_d > 1e-3L))
        fail_msg("float bounds missed the distance by only %.3g m", (double)worst_d);
    if (!(worst_a > 1e-4L))
        fail_msg("float bounds missed the area by only %.3g relative", (double)worst_a);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(validate_accepts_a_normal_view),
        cmocka_unit_test(validate_rejects_null),
        cmocka_unit_test(validate_rejects_nan_or_inf_in_any_field),
        cmocka_unit_test(validate_rejects_degenerate_directions),
        cmocka_unit_test(validate_rejects_out_of_range_parameters),
        cmocka_unit_test(sphere_visibility_against_each_plane),
        cmocka_unit_test(sphere_visibility_uses_aspect_for_the_side_planes),
        cmocka_unit_test(sphere_visibility_follows_a_moved_and_turned_view),
        cmocka_unit_test(screen_area_matches_hand_computation),
        cmocka_unit_test(screen_area_is_clamped_to_the_viewport),
        cmocka_unit_test(distance_is_eye_to_the_sphere),
        cmocka_unit_test(query_carries_screen_area_and_distance_from_bounds),
        cmocka_unit_test(bounds_validate_accepts_good_values_of_every_kind),
        cmocka_unit_test(bounds_validate_rejects_bad_values_of_every_kind),
        cmocka_unit_test(good_bounds_are_stored_and_read_back_exactly),
        cmocka_unit_test(bad_bounds_are_rejected_and_change_nothing_in_a_scene),
        cmocka_unit_test(boxes_wholly_outside_one_plane_are_invisible),
        cmocka_unit_test(boxes_straddling_a_plane_are_visible),
        cmocka_unit_test(a_long_thin_box_beside_the_frustum_is_invisible_though_its_sphere_is_not),
        cmocka_unit_test(a_box_seen_face_on_projects_to_its_rectangle),
        cmocka_unit_test(a_box_beside_the_eye_fills_the_screen_however_close_its_face),
        cmocka_unit_test(a_box_turned_about_the_view_axis_keeps_its_area),
        cmocka_unit_test(a_cube_seen_from_a_corner_shows_three_faces),
        cmocka_unit_test(box_areas_match_the_hull_of_their_projected_corners),
        cmocka_unit_test(the_eye_inside_a_box_sees_the_whole_viewport),
        cmocka_unit_test(box_areas_never_exceed_the_viewport),
        cmocka_unit_test(a_box_partly_behind_the_near_plane_is_clipped),
        cmocka_unit_test(box_distance_is_to_the_nearest_face_edge_or_corner),
        cmocka_unit_test(turned_box_distance_is_measured_in_its_frame),
        cmocka_unit_test(sphere_distance_is_centre_distance_less_radius),
        cmocka_unit_test(bounds_none_has_no_area_nor_distance_and_is_visible),
        cmocka_unit_test(queries_carry_the_node_volume_and_its_measures),
        cmocka_unit_test(outside_the_frustum_the_query_area_is_zero_but_the_helper_area_is_not),
        cmocka_unit_test(earth_scale_queries_keep_millimetres_and_areas),
        cmocka_unit_test(earth_scale_float_bounds_miss_by_more_than_a_millimetre),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
