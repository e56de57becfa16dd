/*
 * test_view — view helpers (src/view.c): validation, sphere-frustum tests,
 * projected screen area and distance, and how a selection fills the query
 * handed to the callbacks (screen_area, distance, view) from a node's bounds.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
