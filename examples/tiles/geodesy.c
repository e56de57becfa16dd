/*
 * geodesy — WGS84 positions, east/north/up frames, 4x4 transforms and the
 * oriented box around a 3D Tiles region (geodesy.h).
 */
#include "geodesy.h"

#include <math.h>
#include <string.h>

/* First eccentricity squared of WGS84: f (2 - f). */
#define GEO_E2 (GEO_WGS84_F * (2.0 - GEO_WGS84_F))

void geo_to_ecef(double lon, double lat, double h, double out[3]) {
    double s = sin(lat), c = cos(lat);
    /* prime vertical radius of curvature */
    double n = GEO_WGS84_A / sqrt(1.0 - GEO_E2 * s * s);
    out[0] = (n + h) * c * cos(lon);
    out[1] = (n + h) * c * sin(lon);
    out[2] = (n * (1.0 - GEO_E2) + h) * s;
}

void geo_enu_axes(double lon, double lat, double east[3], double north[3], double up[3]) {
    double sl = sin(lon), cl = cos(lon), sp = sin(lat), cp = cos(lat);
    east[0] = -sl;
    east[1] = cl;
    east[2] = 0.0;
    north[0] = -sp * cl;
    north[1] = -sp * sl;
    north[2] = cp;
    /* geodetic latitude is the angle of the ellipsoid's normal, so this is the
     * normal (not the radial direction) */
    up[0] = cp * cl;
    up[1] = cp * sl;
    up[2] = sp;
}

void geo_enu_matrix(double lon, double lat, double h, double m[16]) {
    double e[3], n[3], u[3], o[3];
    int i;
    geo_enu_axes(lon, lat, e, n, u);
    geo_to_ecef(lon, lat, h, o);
    for (i = 0; i < 3; ++i) {
        m[0 + i] = e[i];
        m[4 + i] = n[i];
        m[8 + i] = u[i];
        m[12 + i] = o[i];
    }
    m[3] = m[7] = m[11] = 0.0;
    m[15] = 1.0;
}

int geo_region_valid(const double r[6]) {
    int i;
    for (i = 0; i < 6; ++i)
        if (!isfinite(r[i]))
            return 0;
    return r[0] >= -GEO_PI && r[0] <= GEO_PI && r[2] >= -GEO_PI && r[2] <= GEO_PI &&
           r[1] >= -GEO_PI / 2 && r[3] <= GEO_PI / 2 && r[1] <= r[3] && r[4] <= r[5];
}

/* A region spanning more than half the globe in longitude: the box of the
 * latitude band, axis-aligned in ECEF. Every point of the band is within
 * a + max(0, h) of the polar axis ((N + h) cos lat <= a + h for h >= 0, and
 * N cos lat <= a), and its z = (N (1 - e²) + h) sin lat grows with the latitude
 * and is linear in h, so the band's z lies between the values at the four
 * corners (south, north) x (minimum, maximum height). */
static void band_box(const double r[6], double center[3], double half_axes[9]) {
    double rxy = GEO_WGS84_A + (r[5] > 0.0 ? r[5] : 0.0);
    double zmin = HUGE_VAL, zmax = -HUGE_VAL, p[3];
    int i, j;
    for (i = 0; i < 2; ++i) {
        for (j = 0; j < 2; ++j) {
            geo_to_ecef(0.0, i ? r[3] : r[1], j ? r[5] : r[4], p);
            zmin = p[2] < zmin ? p[2] : zmin;
            zmax = p[2] > zmax ? p[2] : zmax;
        }
    }
    memset(half_axes, 0, 9 * sizeof(double));
    center[0] = center[1] = 0.0;
    center[2] = 0.5 * (zmin + zmax);
    half_axes[0] = rxy;
    half_axes[4] = rxy;
    half_axes[8] = 0.5 * (zmax - zmin);
}

/* The box of a region no wider than pi in longitude, in the east/north/up
 * frame at its centre (longitude and latitude midway, the mean height): each of
 * the three frame coordinates is measured at the sample points below, and the
 * box spans their minimum and maximum.
 *
 * Why the samples enclose the region. A frame coordinate is a linear function
 * of position. For fixed latitude and longitude it is linear in the height, so
 * its extremes are at the minimum or maximum height. At a fixed height the
 * region lies on a convex surface (the ellipsoid's offset, whose normal at
 * geodetic latitude lat is the ellipsoid's), where a linear function has
 * critical points only where the normal is parallel to its axis: for east at
 * 90 degrees from the centre's longitude (at most the region's edge), for
 * north at 90 degrees of latitude from the centre along its meridian (outside,
 * or on the edge at a pole), for up at the centre (its maximum: sampled) and
 * the antipode (outside). So the extremes lie on the region's four edges.
 * Along a parallel the coordinates depend on the longitude offset d only
 * through sin d (east) or cos d (north, up), monotonic for |d| <= pi / 2:
 * extremes at the corners or at d = 0, the edge's midpoint. Along a meridian
 * a coordinate is the projection of the meridian's curve onto a direction in
 * its plane, which turns where the normal is parallel to that direction: for
 * east at the equator (sampled when the region spans it), for north at 90
 * degrees from the centre's latitude or beyond (outside), for up at the
 * latitude facing the centre, a maximum below the centre's, its minimum being
 * on the far side of the globe. Hence the samples: the corners, the edges'
 * midpoints, the centre and, when the region spans the equator, its east and
 * west edges at latitude 0, each at both heights. The argument is exact on
 * the ellipsoid, not only on a sphere, because it uses normals alone. */
void geo_region_box(const double r[6], double center[3], double half_axes[9]) {
    double west = r[0], south = r[1], east = r[2], north = r[3];
    double lon0, lat0, h0, origin[3], axes[3][3], lo[3], hi[3];
    double lats[4], lons[3];
    int nlat = 3, i, j, k, a;

    if (east < west)
        east += 2.0 * GEO_PI; /* crosses the antimeridian */
    if (east - west > GEO_PI) {
        band_box(r, center, half_axes);
        return;
    }
    lon0 = 0.5 * (west + east);
    lat0 = 0.5 * (south + north);
    h0 = 0.5 * (r[4] + r[5]);
    geo_enu_axes(lon0, lat0, axes[0], axes[1], axes[2]);
    geo_to_ecef(lon0, lat0, h0, origin);
    lats[0] = south;
    lats[1] = lat0;
    lats[2] = north;
    if (south < 0.0 && north > 0.0)
        lats[nlat++] = 0.0;
    lons[0] = west;
    lons[1] = lon0;
    lons[2] = east;
    for (a = 0; a < 3; ++a) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (i = 0; i < nlat; ++i) {
        for (j = 0; j < 3; ++j) {
            for (k = 0; k < 2; ++k) {
                double p[3], d[3];
                geo_to_ecef(lons[j], lats[i], k ? r[5] : r[4], p);
                d[0] = p[0] - origin[0];
                d[1] = p[1] - origin[1];
                d[2] = p[2] - origin[2];
                for (a = 0; a < 3; ++a) {
                    double c = d[0] * axes[a][0] + d[1] * axes[a][1] + d[2] * axes[a][2];
                    lo[a] = c < lo[a] ? c : lo[a];
                    hi[a] = c > hi[a] ? c : hi[a];
                }
            }
        }
    }
    for (i = 0; i < 3; ++i) {
        center[i] = origin[i];
        for (a = 0; a < 3; ++a)
            center[i] += 0.5 * (lo[a] + hi[a]) * axes[a][i];
    }
    for (a = 0; a < 3; ++a)
        for (i = 0; i < 3; ++i)
            half_axes[3 * a + i] = 0.5 * (hi[a] - lo[a]) * axes[a][i];
}

void geo_mat4_identity(double m[16]) {
    int i;
    for (i = 0; i < 16; ++i)
        m[i] = i % 5 == 0 ? 1.0 : 0.0;
}

void geo_mat4_mul(const double a[16], const double b[16], double out[16]) {
    int r, c, k;
    for (c = 0; c < 4; ++c) {
        for (r = 0; r < 4; ++r) {
            double s = 0.0;
            for (k = 0; k < 4; ++k)
                s += a[4 * k + r] * b[4 * c + k];
            out[4 * c + r] = s;
        }
    }
}

void geo_mat4_point(const double m[16], const double p[3], double out[3]) {
    int r;
    for (r = 0; r < 3; ++r)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

void geo_mat4_vector(const double m[16], const double v[3], double out[3]) {
    int r;
    for (r = 0; r < 3; ++r)
        out[r] = m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2];
}

double geo_mat4_max_scale(const double m[16]) {
    double best = 0.0;
    int c;
    for (c = 0; c < 3; ++c) {
        double l =
            sqrt(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]);
        best = l > best ? l : best;
    }
    return best;
}
