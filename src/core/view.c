/*
 * View helpers: frustum test, projected screen area and distance of bounding
 * volumes: spheres, axis-aligned and oriented boxes (docs/scenes.md, bounds).
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
 *
 * A box is tested plane by plane: it is outside a plane when its centre's
 * signed distance exceeds its reach along the plane's normal n,
 * sum_i h_i |u_i · n| (u_i its unit axes, h_i its half lengths). Its projected
 * area is that of its silhouette: the faces turned towards the eye (at most
 * three) project without overlapping, so the silhouette's area is the sum of
 * theirs, each a quadrilateral clipped at the near plane and projected, plus,
 * for a box reaching through the near plane, the section the plane cuts (the
 * face that clipping gives the part of the box beyond it). Its
 * distance from the eye is the length of the eye's excess over the half
 * lengths in the box's frame (0 inside), what 3D Tiles' screen-space error
 * divides by. Everything is computed in double relative to the eye, so that
 * earth-centred coordinates (|x| about 6.4e6 m) keep their millimetres.
 *
 * Layer: core, which may call core. Calls: libc and libm only.
 */
#include "view.h"

#include <math.h>
#include <string.h>

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

static void copy3(const double in[3], double out[3]) {
    out[0] = in[0];
    out[1] = in[1];
    out[2] = in[2];
}

const char *tclod_view_check(const tclod_view *v) {
    double f[3], u[3], side[3];
    double pi = 3.14159265358979323846;
    int i;
    if (!v)
        return "view is NULL";
    for (i = 0; i < 3; ++i)
        if (!isfinite(v->eye[i]))
            return "view->eye must be finite";
    for (i = 0; i < 3; ++i)
        if (!isfinite(v->forward[i]))
            return "view->forward must be finite";
    for (i = 0; i < 3; ++i)
        if (!isfinite(v->up[i]))
            return "view->up must be finite";
    if (!(v->fov_y > 0.0f) || !((double)v->fov_y < pi))
        return "view->fov_y must be in (0, pi)";
    if (!(v->aspect > 0.0f) || !isfinite(v->aspect))
        return "view->aspect must be finite and > 0";
    if (!(v->near_z > 0.0f) || !isfinite(v->near_z))
        return "view->near_z must be finite and > 0";
    if (!(v->far_z > v->near_z) || !isfinite(v->far_z))
        return "view->far_z must be finite and > near_z";
    if (!(v->viewport_height > 0.0f) || !isfinite(v->viewport_height))
        return "view->viewport_height must be finite and > 0";
    load3(v->forward, f);
    load3(v->up, u);
    if (normalize3(f) <= 0.0)
        return "view->forward must not be zero";
    if (normalize3(u) <= 0.0)
        return "view->up must not be zero";
    cross3(f, u, side);
    if (sqrt(dot3(side, side)) < 1e-6)
        return "view->up must not be parallel to forward";
    return NULL;
}

tclod_status tclod_view_validate(const tclod_view *v) {
    return tclod_view_check(v) ? TCLOD_ERR_ARG : TCLOD_OK;
}

void tclod_view_cache_init(tclod_view_cache *c, const tclod_view *v) {
    double half_y = 0.5 * (double)v->fov_y;
    double half_x = atan((double)v->aspect * tan(half_y)), focal;
    copy3(v->eye, c->eye);
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
    c->focal = focal;
    c->pi_focal2 = 3.14159265358979323846 * focal * focal;
    c->viewport_area = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
}

/* ---- bounds ------------------------------------------------------------------ */

/* Largest |cos| between two non-zero half axes of an oriented box. */
#define ORTHOGONAL_TOLERANCE 1e-3

tclod_bounds tclod_bounds_sphere(double x, double y, double z, double radius) {
    tclod_bounds b;
    memset(&b, 0, sizeof b);
    b.kind = TCLOD_BOUNDS_SPHERE;
    b.center[0] = x;
    b.center[1] = y;
    b.center[2] = z;
    b.radius = radius;
    return b;
}

tclod_bounds tclod_bounds_aabb(const double center[3], const double half_extents[3]) {
    tclod_bounds b;
    memset(&b, 0, sizeof b);
    b.kind = TCLOD_BOUNDS_AABB;
    if (center)
        copy3(center, b.center);
    if (half_extents)
        copy3(half_extents, b.half_extents);
    return b;
}

tclod_bounds tclod_bounds_obb(const double center[3], const double half_axes[9]) {
    tclod_bounds b;
    int i;
    memset(&b, 0, sizeof b);
    b.kind = TCLOD_BOUNDS_OBB;
    if (center)
        copy3(center, b.center);
    if (half_axes)
        for (i = 0; i < 3; ++i)
            copy3(half_axes + 3 * i, b.half_axes[i]);
    return b;
}

static int finite3(const double v[3]) {
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* The unit axes of a box whose non-zero axes (lengths h) are u[i] already:
 * the missing ones completed by cross products into a right-handed frame. */
static void complete_frame(double u[3][3], const double h[3]) {
    int zero = (h[0] == 0.0) + (h[1] == 0.0) + (h[2] == 0.0), i;
    if (zero == 3) {
        for (i = 0; i < 3; ++i) {
            u[i][0] = i == 0;
            u[i][1] = i == 1;
            u[i][2] = i == 2;
        }
        return;
    }
    if (zero == 2) {
        int a = h[0] > 0.0 ? 0 : (h[1] > 0.0 ? 1 : 2), b = (a + 1) % 3, c = (a + 2) % 3, k = 0;
        double e[3] = {0.0, 0.0, 0.0};
        /* the world axis least along u[a] */
        for (i = 1; i < 3; ++i)
            if (fabs(u[a][i]) < fabs(u[a][k]))
                k = i;
        e[k] = 1.0;
        cross3(u[a], e, u[b]);
        normalize3(u[b]);
        cross3(u[a], u[b], u[c]);
        normalize3(u[c]);
        return;
    }
    if (zero == 1) {
        int z = h[0] == 0.0 ? 0 : (h[1] == 0.0 ? 1 : 2);
        cross3(u[(z + 1) % 3], u[(z + 2) % 3], u[z]);
        normalize3(u[z]);
    }
}

const char *tclod_bounds_convert(const tclod_bounds *b, tclod_node_bounds *nb, tclod_box *box) {
    int i, j;
    if (!b)
        return "bounds is NULL";
    memset(nb, 0, sizeof *nb);
    nb->box = TCLOD_NONE;
    nb->kind = TCLOD_BOUNDS_NONE;
    nb->r = -1.0;
    switch (b->kind) {
    case TCLOD_BOUNDS_NONE:
        return NULL;
    case TCLOD_BOUNDS_SPHERE:
        if (!finite3(b->center))
            return "bounds.center must be finite";
        if (!isfinite(b->radius) || !(b->radius >= 0.0))
            return "bounds.radius must be finite and >= 0";
        copy3(b->center, nb->c);
        nb->r = b->radius;
        nb->kind = TCLOD_BOUNDS_SPHERE;
        return NULL;
    case TCLOD_BOUNDS_AABB:
        if (!finite3(b->center))
            return "bounds.center must be finite";
        for (i = 0; i < 3; ++i)
            if (!(b->half_extents[i] >= 0.0) || !isfinite(b->half_extents[i]))
                return "bounds.half_extents must be finite and >= 0";
        memset(box, 0, sizeof *box);
        for (i = 0; i < 3; ++i) {
            box->axes[i][i] = b->half_extents[i];
            box->u[i][i] = 1.0;
            box->h[i] = b->half_extents[i];
        }
        break;
    case TCLOD_BOUNDS_OBB:
        if (!finite3(b->center))
            return "bounds.center must be finite";
        for (i = 0; i < 3; ++i) {
            if (!finite3(b->half_axes[i]))
                return "bounds.half_axes must be finite";
            copy3(b->half_axes[i], box->axes[i]);
            copy3(b->half_axes[i], box->u[i]);
            box->h[i] = normalize3(box->u[i]);
            if (!isfinite(box->h[i]))
                return "bounds.half_axes are too long (their length overflows)";
        }
        for (i = 0; i < 3; ++i)
            for (j = i + 1; j < 3; ++j)
                if (box->h[i] > 0.0 && box->h[j] > 0.0 &&
                    !(fabs(dot3(box->u[i], box->u[j])) <= ORTHOGONAL_TOLERANCE))
                    return "bounds.half_axes must be orthogonal";
        complete_frame(box->u, box->h);
        break;
    default:
        return "bounds.kind is not a tclod_bounds_kind";
    }
    copy3(b->center, nb->c);
    /* the corners' distance from the centre, rounded up */
    nb->r = sqrt(box->h[0] * box->h[0] + box->h[1] * box->h[1] + box->h[2] * box->h[2]);
    nb->r += nb->r * 1e-12;
    if (!isfinite(nb->r))
        return "bounds are too large (the corners' distance overflows)";
    nb->kind = (uint32_t)b->kind;
    return NULL;
}

const char *tclod_bounds_check(const tclod_bounds *b) {
    tclod_node_bounds nb;
    tclod_box box;
    return tclod_bounds_convert(b, &nb, &box);
}

tclod_status tclod_bounds_validate(const tclod_bounds *b) {
    return tclod_bounds_check(b) ? TCLOD_ERR_ARG : TCLOD_OK;
}

/* ---- boxes ------------------------------------------------------------------ */

/* The box with centre p (relative to the eye) in view coordinates (x right,
 * y up, z forward): its centre ctr and its half axes a[i] = h_i u_i. The
 * frustum test and the silhouette both start from them. */
static void box_in_view(const tclod_view_cache *c, const double p[3], const tclod_box *b,
                        double ctr[3], double a[3][3]) {
    int i;
    ctr[0] = dot3(p, c->right);
    ctr[1] = dot3(p, c->up);
    ctr[2] = dot3(p, c->forward);
    for (i = 0; i < 3; ++i) {
        a[i][0] = b->h[i] * dot3(b->u[i], c->right);
        a[i][1] = b->h[i] * dot3(b->u[i], c->up);
        a[i][2] = b->h[i] * dot3(b->u[i], c->forward);
    }
}

/* Whether the box (box_in_view) meets the frustum: it is outside a plane when
 * its centre's signed distance exceeds its reach along the plane's normal,
 * sum |a_i . n|. In view coordinates the near and far normals are -z and +z;
 * the top and bottom planes pass through the eye with outward normals
 * (0, ±cos y, -sin y), the right and left ones (±cos x, 0, -sin x), y and x
 * half the fields of view: a point is above the top plane when
 * y cos y - z sin y > 0, as the sphere test (view.h) has it with |y|. */
static int box_seen(const tclod_view_cache *c, const double ctr[3], const double a[3][3]) {
    double r[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    int i;
    for (i = 0; i < 3; ++i) {
        r[0] += fabs(a[i][2]);
        r[1] += fabs(a[i][1] * c->cos_y - a[i][2] * c->sin_y);
        r[2] += fabs(a[i][1] * c->cos_y + a[i][2] * c->sin_y);
        r[3] += fabs(a[i][0] * c->cos_x - a[i][2] * c->sin_x);
        r[4] += fabs(a[i][0] * c->cos_x + a[i][2] * c->sin_x);
    }
    return !(c->near_z - ctr[2] > r[0] || ctr[2] - c->far_z > r[0] ||
             ctr[1] * c->cos_y - ctr[2] * c->sin_y > r[1] ||
             -ctr[1] * c->cos_y - ctr[2] * c->sin_y > r[2] ||
             ctr[0] * c->cos_x - ctr[2] * c->sin_x > r[3] ||
             -ctr[0] * c->cos_x - ctr[2] * c->sin_x > r[4]);
}

static int box_visible(const tclod_view_cache *c, const double p[3], const tclod_box *b) {
    double ctr[3], a[3][3];
    box_in_view(c, p, b, ctr, a);
    return box_seen(c, ctr, (const double(*)[3])a);
}

/* The eye's coordinates in the frame of a box whose centre is p (relative to
 * the eye): t[i] = -p · u_i. */
static void box_coordinates(const double p[3], const tclod_box *b, double t[3]) {
    int i;
    for (i = 0; i < 3; ++i)
        t[i] = -dot3(p, b->u[i]);
}

/* The area in px² of the projection of the quadrilateral q[0..4) (points
 * relative to the eye), clipped at the near plane. */
static double projected_quad(const tclod_view_cache *c, const double q[4][3]) {
    double vx[4], vy[4], vz[4], px[8], py[8], area = 0.0;
    int i, n = 0;
    for (i = 0; i < 4; ++i) {
        vx[i] = dot3(q[i], c->right);
        vy[i] = dot3(q[i], c->up);
        vz[i] = dot3(q[i], c->forward);
    }
    /* Sutherland-Hodgman against z >= near: at most 5 vertices (8 kept) */
    for (i = 0; i < 4; ++i) {
        int j = (i + 1) % 4;
        int in_i = vz[i] >= c->near_z, in_j = vz[j] >= c->near_z;
        if (in_i) {
            px[n] = c->focal * vx[i] / vz[i];
            py[n] = c->focal * vy[i] / vz[i];
            n++;
        }
        if (in_i != in_j) {
            double t = (c->near_z - vz[i]) / (vz[j] - vz[i]);
            double x = vx[i] + t * (vx[j] - vx[i]), y = vy[i] + t * (vy[j] - vy[i]);
            px[n] = c->focal * x / c->near_z;
            py[n] = c->focal * y / c->near_z;
            n++;
        }
    }
    for (i = 0; i < n; ++i) {
        int j = (i + 1) % n;
        area += px[i] * py[j] - px[j] * py[i];
    }
    return 0.5 * fabs(area);
}

/* The area in px² of the projection of the box's section by the near plane,
 * where it reaches in front of it: the cap that clipping at the near plane
 * gives the part of the box beyond it, turned to the eye. The section is the
 * convex polygon through the points where the box's edges cross the plane. */
static double near_cap(const tclod_view_cache *c, const double p[3], const tclod_box *b) {
    double x[8], y[8], z[8], px[12], py[12], ang[12], cx = 0.0, cy = 0.0, area = 0.0;
    double lo = HUGE_VAL, hi = -HUGE_VAL, n = c->near_z;
    int k, i, j, m = 0;
    for (k = 0; k < 8; ++k) {
        double q[3];
        for (i = 0; i < 3; ++i)
            q[i] = p[i] + ((k & 1) ? b->h[0] : -b->h[0]) * b->u[0][i] +
                   ((k & 2) ? b->h[1] : -b->h[1]) * b->u[1][i] +
                   ((k & 4) ? b->h[2] : -b->h[2]) * b->u[2][i];
        x[k] = dot3(q, c->right);
        y[k] = dot3(q, c->up);
        z[k] = dot3(q, c->forward);
        lo = z[k] < lo ? z[k] : lo;
        hi = z[k] > hi ? z[k] : hi;
    }
    if (!(lo < n && hi > n))
        return 0.0; /* wholly on one side */
    for (k = 0; k < 8; ++k)
        for (i = 0; i < 3; ++i) {
            int l = k | (1 << i); /* the edge from k along axis i */
            double t;
            if (l == k || (z[k] - n) * (z[l] - n) > 0.0 || z[k] == z[l])
                continue;
            t = (n - z[k]) / (z[l] - z[k]);
            px[m] = x[k] + t * (x[l] - x[k]);
            py[m] = y[k] + t * (y[l] - y[k]);
            cx += px[m];
            cy += py[m];
            m++;
        }
    if (m < 3)
        return 0.0;
    cx /= m;
    cy /= m;
    for (i = 0; i < m; ++i)
        ang[i] = atan2(py[i] - cy, px[i] - cx);
    /* the polygon in angular order (insertion sort: at most 12 points) */
    for (i = 1; i < m; ++i)
        for (j = i; j > 0 && ang[j] < ang[j - 1]; --j) {
            double t = ang[j];
            ang[j] = ang[j - 1];
            ang[j - 1] = t;
            t = px[j];
            px[j] = px[j - 1];
            px[j - 1] = t;
            t = py[j];
            py[j] = py[j - 1];
            py[j - 1] = t;
        }
    for (i = 0; i < m; ++i) {
        j = (i + 1) % m;
        area += px[i] * py[j] - px[j] * py[i];
    }
    return 0.5 * fabs(area) * (c->focal / n) * (c->focal / n);
}

/* The silhouette's area of a box wholly beyond the near plane, its half axes
 * a[i] in view coordinates (x right, y up, z forward), t the eye in the box's
 * frame: the sum over the faces turned towards the eye of their projected
 * areas, each in closed form (docs/scenes.md, bounding volumes). The face
 * along axis i on the eye's side lies d = |t_i| - h_i from the eye; its
 * centre is at depth z and its half axes j and l reach z_j and z_l in depth,
 * so that its corners' depths pair up as z0 z2 = (z + z_j + z_l)(z - z_j - z_l)
 * and z1 z3 = (z - z_j + z_l)(z + z_j - z_l), and it projects to
 * 4 f² h_j h_l d z / (z0 z2 z1 z3), computed with every length in units of
 * z so that no product of four depths overflows: two divisions per face, no
 * corner projected. */
static double box_area_unclipped(const tclod_view_cache *c, const double ctr[3],
                                 const double a[3][3], const tclod_box *b, const double t[3]) {
    double area = 0.0;
    int i;
    for (i = 0; i < 3; ++i) {
        int j = (i + 1) % 3, l = (i + 2) % 3;
        double d = fabs(t[i]) - b->h[i], z, s, zj, zl;
        if (!(d > 0.0))
            continue; /* both faces along axis i are turned away */
        z = t[i] > 0.0 ? ctr[2] + a[i][2] : ctr[2] - a[i][2];
        s = 1.0 / z;
        zj = a[j][2] * s;
        zl = a[l][2] * s;
        area += d * s * (b->h[j] * s) * (b->h[l] * s) /
                (((1.0 + zj + zl) * (1.0 - zj - zl)) * ((1.0 - zj + zl) * (1.0 + zj - zl)));
    }
    return 4.0 * c->focal * c->focal * area;
}

/* The area of the silhouette of the box with centre p (relative to the eye),
 * ctr and ax its box_in_view, t the eye in its frame. */
static double box_area(const tclod_view_cache *c, const double p[3], const tclod_box *b,
                       const double t[3], const double ctr[3], const double ax[3][3]) {
    double area = 0.0, zlo = ctr[2];
    int i, k;
    if (fabs(t[0]) <= b->h[0] && fabs(t[1]) <= b->h[1] && fabs(t[2]) <= b->h[2])
        return c->viewport_area;
    /* wholly beyond the near plane (its nearest corner, less a margin for the
     * rounding of the corners' sums), no face is clipped and there is no cap */
    for (i = 0; i < 3; ++i)
        zlo -= fabs(ax[i][2]);
    if (zlo - 1e-9 * (fabs(ctr[2]) + b->h[0] + b->h[1] + b->h[2]) > c->near_z) {
        area = box_area_unclipped(c, ctr, ax, b, t);
        return area < c->viewport_area ? area : c->viewport_area;
    }
    for (i = 0; i < 3; ++i) {
        int j = (i + 1) % 3, l = (i + 2) % 3;
        double side;
        for (side = -1.0; side <= 1.0; side += 2.0) {
            double q[4][3], f[3];
            if (!(side * t[i] > b->h[i]))
                continue; /* the face is turned away */
            for (k = 0; k < 3; ++k)
                f[k] = p[k] + side * b->h[i] * b->u[i][k];
            for (k = 0; k < 3; ++k) {
                double a = b->h[j] * b->u[j][k], e = b->h[l] * b->u[l][k];
                q[0][k] = f[k] + a + e;
                q[1][k] = f[k] - a + e;
                q[2][k] = f[k] - a - e;
                q[3][k] = f[k] + a - e;
            }
            area += projected_quad(c, (const double(*)[3])q);
        }
    }
    area += near_cap(c, p, b);
    return area < c->viewport_area ? area : c->viewport_area;
}

static double box_distance(const tclod_box *b, const double t[3]) {
    double d2 = 0.0;
    int i;
    for (i = 0; i < 3; ++i) {
        double e = fabs(t[i]) - b->h[i];
        if (e > 0.0)
            d2 += e * e;
    }
    return sqrt(d2);
}

void tclod_view_cache_measure_box(const tclod_view_cache *c, const double p[3],
                                  const tclod_box *box, float *area, double *distance) {
    double t[3], ctr[3], ax[3][3];
    box_coordinates(p, box, t);
    *distance = box_distance(box, t);
    box_in_view(c, p, box, ctr, ax);
    *area = box_seen(c, ctr, (const double(*)[3])ax)
                ? (float)box_area(c, p, box, t, ctr, (const double(*)[3])ax)
                : 0.0f;
}

void tclod_view_cache_measure(const tclod_view_cache *c, const float bounds[4], float *area,
                              float *distance) {
    tclod_view_measure(c, bounds, area, distance);
}

void tclod_view_cache_measure_any(const tclod_view_cache *c, const tclod_bounds *b, float *area,
                                  float *distance) {
    tclod_node_bounds nb;
    tclod_box box;
    double d;
    *area = *distance = -1.0f;
    if (tclod_bounds_convert(b, &nb, &box) || nb.r < 0.0)
        return;
    nb.box = nb.kind > TCLOD_BOUNDS_SPHERE ? 0u : TCLOD_NONE;
    tclod_view_measure_bounds(c, &nb, &box, area, &d);
    *distance = (float)d;
}

/* ---- public helpers ---------------------------------------------------------- */

/* The view's cache and b converted, with b's centre relative to the eye in p.
 * Returns 0 when b has no bounds (or an argument is NULL or invalid). */
static int prepare_bounds(const tclod_view *view, const tclod_bounds *b, tclod_view_cache *c,
                          tclod_node_bounds *nb, tclod_box *box, double p[3]) {
    if (!view || !b || tclod_bounds_convert(b, nb, box) || nb->r < 0.0)
        return 0;
    tclod_view_cache_init(c, view);
    p[0] = nb->c[0] - c->eye[0];
    p[1] = nb->c[1] - c->eye[1];
    p[2] = nb->c[2] - c->eye[2];
    return 1;
}

int tclod_view_bounds_visible(const tclod_view *view, const tclod_bounds *b) {
    tclod_view_cache c;
    tclod_node_bounds nb;
    tclod_box box;
    double p[3];
    if (!prepare_bounds(view, b, &c, &nb, &box, p))
        return b && b->kind == TCLOD_BOUNDS_NONE && view != NULL;
    if (nb.kind == TCLOD_BOUNDS_SPHERE)
        return tclod_view_cache_visible(&c, p, nb.r);
    return box_visible(&c, p, &box);
}

double tclod_view_bounds_area(const tclod_view *view, const tclod_bounds *b) {
    tclod_view_cache c;
    tclod_node_bounds nb;
    tclod_box box;
    double p[3], t[3], ctr[3], ax[3][3];
    if (!prepare_bounds(view, b, &c, &nb, &box, p))
        return -1.0;
    if (nb.kind == TCLOD_BOUNDS_SPHERE)
        return tclod_view_cache_area(&c, dot3(p, p), nb.r);
    box_coordinates(p, &box, t);
    box_in_view(&c, p, &box, ctr, ax);
    return box_area(&c, p, &box, t, ctr, (const double(*)[3])ax);
}

double tclod_view_bounds_distance(const tclod_view *view, const tclod_bounds *b) {
    tclod_node_bounds nb;
    tclod_box box;
    double p[3], t[3];
    int k;
    if (!view || !b || tclod_bounds_convert(b, &nb, &box) || nb.r < 0.0)
        return -1.0;
    /* a distance needs only the eye: no frustum to prepare (prepare_bounds
     * would take its angles' sines and tangents on every call) */
    for (k = 0; k < 3; ++k)
        p[k] = nb.c[k] - view->eye[k];
    if (nb.kind == TCLOD_BOUNDS_SPHERE)
        return tclod_sphere_distance(dot3(p, p), nb.r);
    box_coordinates(p, &box, t);
    return box_distance(&box, t);
}

int tclod_view_sphere_visible(const tclod_view *view, const float bounds[4]) {
    tclod_bounds b;
    if (!bounds)
        return 0;
    tclod_sphere_bounds(bounds, &b);
    return tclod_view_bounds_visible(view, &b);
}

float tclod_view_screen_area(const tclod_view *view, const float bounds[4]) {
    tclod_bounds b;
    double area;
    if (!bounds)
        return 0.0f;
    tclod_sphere_bounds(bounds, &b);
    area = tclod_view_bounds_area(view, &b);
    return area < 0.0 ? 0.0f : (float)area;
}

float tclod_view_distance(const tclod_view *view, const float bounds[4]) {
    tclod_bounds b;
    double d;
    if (!bounds)
        return 0.0f;
    tclod_sphere_bounds(bounds, &b);
    d = tclod_view_bounds_distance(view, &b);
    return d < 0.0 ? 0.0f : (float)d;
}
