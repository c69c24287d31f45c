/* sl_camera_path.h — the camera between keyframes of a camera path (issue 17, proto/scene.md "Paths").
 *
 * Keys are cameras at strictly ascending times. Between them:
 * - When every key is an orbit, the orbit's numbers are interpolated:
 *   azimuth the short way round (each step from one key to the next is
 *   unwrapped to within 180 degrees, so 350 -> 10 passes through 0), log
 *   distance (zooms at a constant rate), elevation and fov. The result is
 *   an orbit again (resolved per dataset like any other).
 * - Otherwise every key is resolved to eye/target/up for the bounds: the
 *   eye position is interpolated, the view direction and the up vector by
 *   spherical linear interpolation (slerp) per segment, the eye-to-target
 *   distance in log space, fov as a number; up is made orthogonal to the
 *   view direction (the previous key's up, then any perpendicular, when
 *   slerp makes them parallel), also at the ends (the same view: sl_view
 *   derives R = F x up, U = R x F).
 * Numbers (and the eye) follow SL_PATH_LINEAR, or SL_PATH_SMOOTH: the cubic
 * Hermite curve through the keys with Catmull-Rom tangents for uneven key
 * spacing, m_i = (p_{i+1} - p_{i-1}) / (t_{i+1} - t_{i-1}), one-sided at
 * the first and last key. It passes through every key. Its overshoot is
 * clamped where a camera has limits: elevation to +-SL_ORBIT_MAX_ELEVATION,
 * fov to [SL_PATH_MIN_FOV, SL_PATH_MAX_FOV]. Before the first key and after
 * the last, the camera is that key's.
 * Any thread; no state, no allocation.
 */
#ifndef SL_CAMERA_PATH_H
#define SL_CAMERA_PATH_H

#include "sl_camera.h"

#define SL_PATH_MIN_FOV 1e-3
#define SL_PATH_MAX_FOV 179.0

typedef enum sl_path_interpolation { SL_PATH_LINEAR = 0, SL_PATH_SMOOTH = 1 } sl_path_interpolation;

typedef struct sl_camera_key {
    double t;                 /* seconds, finite, strictly ascending over the keys */
    sl_camera_spec camera;
} sl_camera_key;

/* 1 when every key is an orbit (the path then interpolates orbits). */
int sl_camera_path_is_orbit(const sl_camera_key *keys, int count);

/* The camera at time t (any finite value) of keys[0..count-1] (count >= 1)
 * for a dataset with bounds [lo, hi] (used only when some key is not an
 * orbit). Fails (SL_ERR_INVALID) when count < 1, t is not finite, a key
 * does not resolve (sl_camera_spec_resolve) or the times do not ascend. */
sl_status sl_camera_path_at(const sl_camera_key *keys, int count, sl_path_interpolation mode, double t,
                            sl_vec3 lo, sl_vec3 hi, sl_camera_spec *out, sl_err *err);

/* The scalar interpolation of the header (shared with keyframed
 * parameters): values v[0..count-1] at strictly ascending times[], count
 * >= 1, evaluated at t. Before the first time v[0], after the last
 * v[count-1]. */
double sl_path_scalar_at(const double *times, const double *v, int count, sl_path_interpolation mode, double t);

#endif
