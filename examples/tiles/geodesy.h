/*
 * geodesy — the little geometry a 3D Tiles host needs: the WGS84 ellipsoid,
 * local east/north/up frames, 4x4 column-major transforms, and the oriented box
 * around a 3D Tiles region. Shared by tclod_tiles and tclod_tileset_gen.
 */
#ifndef TILES_GEODESY_H
#define TILES_GEODESY_H

/* WGS84 semi-major axis (m) and flattening: the ellipsoid 3D Tiles regions
 * are defined on. */
#define GEO_WGS84_A 6378137.0
#define GEO_WGS84_F (1.0 / 298.257223563)
#define GEO_PI 3.14159265358979323846

/* Earth-centred, earth-fixed position of longitude lon and latitude lat
 * (geodetic, radians) at height h (m) above the ellipsoid. */
void geo_to_ecef(double lon, double lat, double h, double out[3]);

/* Unit east, north and up (the ellipsoid's normal) at lon, lat (radians). */
void geo_enu_axes(double lon, double lat, double east[3], double north[3], double up[3]);

/* The transform from the local east/north/up frame at lon, lat, h to ECEF,
 * column-major (3D Tiles' eastNorthUpToFixedFrame). */
void geo_enu_matrix(double lon, double lat, double h, double m[16]);

/* The oriented box enclosing a 3D Tiles region (west, south, east, north in
 * radians, minimum and maximum height in m): its centre and three half axes
 * (x, y, z of each, 9 values). The region must be valid (geo_region_valid). */
void geo_region_box(const double region[6], double center[3], double half_axes[9]);

/* 1 when region holds finite numbers with west and east in [-pi, pi], south <=
 * north in [-pi/2, pi/2] and minimum height <= maximum height; else 0. west >
 * east is valid: the region crosses the antimeridian. */
int geo_region_valid(const double region[6]);

/* 4x4 matrices, column-major as 3D Tiles writes them: element (row r, column c)
 * is m[4 c + r], and the translation is m[12], m[13], m[14]. */
void geo_mat4_identity(double m[16]);
/* out = a b (apply b first). out may not alias a or b. */
void geo_mat4_mul(const double a[16], const double b[16], double out[16]);
/* m applied to a point (with the translation) and to a direction (without). */
void geo_mat4_point(const double m[16], const double p[3], double out[3]);
void geo_mat4_vector(const double m[16], const double v[3], double out[3]);
/* The largest length of the upper-left 3x3's columns: how much m can stretch
 * a sphere's radius. */
double geo_mat4_max_scale(const double m[16]);

#endif
