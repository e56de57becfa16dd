/*
 * View helpers: frustum test, projected screen area and distance of bounding
 * spheres (DESIGN.md §3, "View helpers").
 *
 * A view is orthonormalised once per frame into a tclod_view_cache. The four
 * side planes pass through the eye; with a point p (relative to the eye) in
 * view coordinates x = p·right, y = p·up, z = p·forward, p lies inside the top
 * and bottom planes when |y| <= tan(a) z, a = fov_y / 2, i.e. when
 * |y| cos a - z sin a <= 0, a signed distance (the plane normals are unit
 * vectors); a sphere is outside when that distance exceeds its radius. The left
 * and right planes are the same with x and the horizontal half-angle. The
 * projected radius of a sphere seen at distance d is r / sqrt(d² - r²) (the
 * tangent of its angular radius) times the focal length f in pixels, so its
 * projected area is pi f² r² / (d² - r²), with no square root.
 */
#include "internal.h"

#include <math.h>

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double normalize3(double v[3]) {
    double len = sqrt(dot3(v, v));
    if (len > 0.0) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
    return len;
}

static void load3(const float in[3], double out[3]) {
    out[0] = (double)in[0];
    out[1] = (double)in[1];
    out[2] = (double)in[2];
}

tclod_status tclod_view_validate(const tclod_view *v) {
    double f[3], u[3], side[3];
    double pi = 3.14159265358979323846;
    int i;
    if (!v)
        return TCLOD_ERR_ARG;
    for (i = 0; i < 3; ++i)
        if (!isfinite(v->eye[i]) || !isfinite(v->forward[i]) || !isfinite(v->up[i]))
            return TCLOD_ERR_ARG;
    if (!isfinite(v->fov_y) || !isfinite(v->aspect) || !isfinite(v->near_z) ||
        !isfinite(v->far_z) || !isfinite(v->viewport_height))
        return TCLOD_ERR_ARG;
    if (!(v->fov_y > 0.0f) || !((double)v->fov_y < pi) || !(v->aspect > 0.0f) ||
        !(v->near_z > 0.0f) || !(v->far_z > v->near_z) || !(v->viewport_height > 0.0f))
        return TCLOD_ERR_ARG;
    load3(v->forward, f);
    load3(v->up, u);
    if (normalize3(f) <= 0.0 || normalize3(u) <= 0.0)
        return TCLOD_ERR_ARG;
    cross3(f, u, side);
    if (sqrt(dot3(side, side)) < 1e-6)
        return TCLOD_ERR_ARG; /* forward parallel to up */
    return TCLOD_OK;
}

void tclod_view_cache_init(tclod_view_cache *c, const tclod_view *v) {
    double half_y = 0.5 * (double)v->fov_y;
    double half_x = atan((double)v->aspect * tan(half_y)), focal;
    load3(v->eye, c->eye);
    load3(v->forward, c->forward);
    load3(v->up, c->up);
    normalize3(c->forward);
    cross3(c->forward, c->up, c->right);
    normalize3(c->right);
    cross3(c->right, c->forward, c->up); /* exact orthonormal up */
    c->cos_y = cos(half_y);
    c->sin_y = sin(half_y);
    c->cos_x = cos(half_x);
    c->sin_x = sin(half_x);
    c->near_z = (double)v->near_z;
    c->far_z = (double)v->far_z;
    focal = 0.5 * (double)v->viewport_height / tan(half_y);
    c->pi_focal2 = 3.14159265358979323846 * focal * focal;
    c->viewport_area = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
}

void tclod_view_cache_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                              float *distance) {
    tclod_view_measure(c, bounds, area, distance);
}

int tclod_view_sphere_visible(const tclod_view *view, const float bounds[4]) {
    tclod_view_cache c;
    double p[3];
    if (!view || !bounds)
        return 0;
    tclod_view_cache_init(&c, view);
    p[0] = (double)bounds[0] - c.eye[0];
    p[1] = (double)bounds[1] - c.eye[1];
    p[2] = (double)bounds[2] - c.eye[2];
    return tclod_view_cache_visible(&c, p, (double)bounds[3]);
}

float tclod_view_screen_area(const tclod_view *view, const float bounds[4]) {
    tclod_view_cache c;
    double p[3];
    if (!view || !bounds)
        return 0.0f;
    tclod_view_cache_init(&c, view);
    p[0] = (double)bounds[0] - c.eye[0];
    p[1] = (double)bounds[1] - c.eye[1];
    p[2] = (double)bounds[2] - c.eye[2];
    return (float)tclod_view_cache_area(&c, dot3(p, p), (double)bounds[3]);
}

float tclod_view_distance(const tclod_view *view, const float bounds[4]) {
    double d[3];
    if (!view || !bounds)
        return 0.0f;
    d[0] = (double)bounds[0] - (double)view->eye[0];
    d[1] = (double)bounds[1] - (double)view->eye[1];
    d[2] = (double)bounds[2] - (double)view->eye[2];
    return (float)sqrt(dot3(d, d));
}
