/* sl_camera.h — the one camera every technique honours, and the view of a frame.
 *
 * A camera is eye/target/up/fov_y in world units, or an orbit about the
 * dataset's bounds centre; sl_camera_spec holds either form as given and
 * resolves per dataset. The defaults and the elevation limit live here only
 * (the web page gets them in the server's welcome). The pixel (i, j), row 0
 * at the top, is sampled at its centre along
 *   normalize(F + sx R + sy U),  sx = (2(i+.5)/W - 1) tan(fov/2) W/H,
 *                                sy = (1 - 2(j+.5)/H) tan(fov/2),
 * F = normalize(target - eye), R = normalize(F x up), U = R x F.
 * sl_view's matrices give rasterizers the same rays: reversed infinite-far
 * depth (clip control 0..1, depth 1 at the near plane, 0 at infinity,
 * GL_GREATER), relative to `origin` (the dataset's float origin) so data far
 * from the world origin keeps float precision. Any thread; no GL.
 */
#ifndef SL_CAMERA_H
#define SL_CAMERA_H

#include "sl_math.h"
#include "sl_status.h"

typedef struct sl_camera {
    sl_vec3 eye, target, up;
    double fov_y_deg; /* vertical field of view, degrees, in (0, 180) */
} sl_camera;

/* An orbit about the bounds centre: azimuth about +y from +z towards +x,
 * elevation towards +y, distance in bounding-sphere radii, up = +y.
 * Elevation is limited to +-SL_ORBIT_MAX_ELEVATION degrees, off the poles,
 * where up = +y would be parallel to the view direction. */
#define SL_ORBIT_MAX_ELEVATION 89.9
typedef struct sl_orbit {
    double azimuth_deg, elevation_deg, distance;
    double fov_y_deg;
} sl_orbit;

/* The default camera: azimuth 30, elevation 20, distance 2.5, fov_y 45. Its
 * fov_y is also the default of an eye/target/up camera. */
extern const sl_orbit sl_orbit_default;

/* A camera in either form, as given (orbits are resolved per dataset). */
typedef struct sl_camera_spec {
    int is_orbit;              /* 1: orbit; 0: look_at */
    sl_orbit orbit;            /* when is_orbit */
    sl_camera look_at;         /* when !is_orbit: eye/target/up/fov in world units */
} sl_camera_spec;

/* The default spec: an orbit of sl_orbit_default. */
sl_camera_spec sl_camera_spec_default(void);

typedef enum sl_quality { SL_QUALITY_STILL = 0, SL_QUALITY_INTERACTIVE = 1 } sl_quality;

typedef struct sl_view {
    sl_camera camera;
    int width, height;
    sl_quality quality;
    float background[4];      /* linear RGBA in 0..1 */
    sl_vec3 origin;           /* world position that GPU coordinates are relative to */
    double near_plane;        /* eye distance of the near plane along F */
    /* Derived by sl_view_init: */
    sl_vec3 forward, right, upv;   /* F, R, U of the header comment */
    double tan_half_fov, aspect;
    sl_mat4 view_matrix;           /* (world - origin) -> eye space, -z forward */
    sl_mat4 projection;            /* reversed infinite-far perspective */
    sl_mat4 view_projection;
} sl_view;

/* Camera from an orbit about bounds [lo, hi]. Fails (SL_ERR_INVALID, naming
 * the field and range) on NaN, a distance <= 0 or an elevation outside
 * [-SL_ORBIT_MAX_ELEVATION, SL_ORBIT_MAX_ELEVATION]. */
sl_status sl_camera_from_orbit(const sl_orbit *orbit, sl_vec3 lo, sl_vec3 hi,
                               sl_camera *out, sl_err *err);

/* Checks that every number is finite, eye != target, up not parallel to the
 * view direction, fov in (0, 180). Returns SL_ERR_INVALID naming the field. */
sl_status sl_camera_validate(const sl_camera *camera, sl_err *err);

/* The camera of spec for bounds [lo, hi]: an orbit through
 * sl_camera_from_orbit, look_at as given after sl_camera_validate. Fails
 * (SL_ERR_INVALID) as those do; *out is then unspecified. */
sl_status sl_camera_spec_resolve(const sl_camera_spec *spec, sl_vec3 lo, sl_vec3 hi, sl_camera *out,
                                 sl_err *err);

/* Fills the derived fields of view from view->camera, width, height, origin
 * and near_plane (which the caller may leave 0 for a default derived from
 * the scene radius `scene_radius`). */
sl_status sl_view_init(sl_view *view, double scene_radius, sl_err *err);

/* Unit direction of the ray through the centre of pixel (i, j), row 0 at top. */
sl_vec3 sl_view_ray_dir(const sl_view *view, double i, double j);

/* Converts a reversed-Z depth value at pixel (i, j) to the Euclidean eye
 * distance in world units; depth 0 (nothing hit) gives 0. */
double sl_view_depth_to_distance(const sl_view *view, double i, double j, double depth);

#endif
