/* camera_path.c — cameras between keyframes: see sl_camera_path.h. Any thread, no allocation.
 * Segment i evaluates on the window of keys i-1 .. i+2 only: the Catmull-Rom
 * tangents at keys i and i+1 depend on nothing else, so the window gives the
 * same curve as the whole list. */
#include "sl_camera_path.h"

#include <math.h>

#define WINDOW 4

/* The segment i with times[i] <= t < times[i+1], for times[0] < t < times[count-1]. */
static int segment_of(const double *times, int count, double t)
{
    int lo = 0, hi = count - 1; /* times[lo] <= t < times[hi] */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (times[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static double tangent(const double *times, const double *v, int count, int k)
{
    int a = k > 0 ? k - 1 : k, b = k < count - 1 ? k + 1 : k;
    return (v[b] - v[a]) / (times[b] - times[a]);
}

double sl_path_scalar_at(const double *times, const double *v, int count, sl_path_interpolation mode, double t)
{
    if (count <= 1 || !(t > times[0]))
        return v[0];
    if (t >= times[count - 1])
        return v[count - 1];
    int i = segment_of(times, count, t);
    double h = times[i + 1] - times[i], s = (t - times[i]) / h;
    if (mode == SL_PATH_LINEAR)
        return v[i] + s * (v[i + 1] - v[i]);
    double s2 = s * s, s3 = s2 * s;
    double m0 = tangent(times, v, count, i), m1 = tangent(times, v, count, i + 1);
    return (2 * s3 - 3 * s2 + 1) * v[i] + (s3 - 2 * s2 + s) * h * m0 + (-2 * s3 + 3 * s2) * v[i + 1] +
           (s3 - s2) * h * m1;
}

int sl_camera_path_is_orbit(const sl_camera_key *keys, int count)
{
    for (int k = 0; k < count; k++)
        if (!keys[k].camera.is_orbit)
            return 0;
    return 1;
}

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

/* angle - 360 k in (-180, 180]. */
static double wrap180(double deg)
{
    double w = fmod(deg, 360.0);
    if (w > 180.0)
        w -= 360.0;
    else if (w <= -180.0)
        w += 360.0;
    return w;
}

/* Any unit vector perpendicular to unit a. */
static sl_vec3 any_perpendicular(sl_vec3 a)
{
    sl_vec3 axis = fabs(a.x) < 0.9 ? sl_v3(1, 0, 0) : sl_v3(0, 1, 0);
    return sl_v3_normalize(sl_v3_cross(a, axis));
}

/* Spherical linear interpolation of unit vectors; opposite ones turn about a perpendicular. */
static sl_vec3 slerp(sl_vec3 a, sl_vec3 b, double s)
{
    double d = clamp(sl_v3_dot(a, b), -1.0, 1.0);
    if (d > 0.9999995)
        return sl_v3_normalize(sl_v3_add(sl_v3_scale(a, 1.0 - s), sl_v3_scale(b, s)));
    if (d < -0.9999995) {
        sl_vec3 p = any_perpendicular(a);
        return sl_v3_add(sl_v3_scale(a, cos(M_PI * s)), sl_v3_scale(p, sin(M_PI * s)));
    }
    double theta = acos(d), k = 1.0 / sin(theta);
    return sl_v3_add(sl_v3_scale(a, sin((1.0 - s) * theta) * k), sl_v3_scale(b, sin(s * theta) * k));
}

/* up made orthogonal to unit f; when parallel, the fallback, then any perpendicular. */
static sl_vec3 orthogonal_up(sl_vec3 up, sl_vec3 fallback, sl_vec3 f)
{
    sl_vec3 u = sl_v3_sub(up, sl_v3_scale(f, sl_v3_dot(f, up)));
    if (sl_v3_length(u) > 1e-9)
        return sl_v3_normalize(u);
    u = sl_v3_sub(fallback, sl_v3_scale(f, sl_v3_dot(f, fallback)));
    return sl_v3_length(u) > 1e-9 ? sl_v3_normalize(u) : any_perpendicular(f);
}

/* The keys segment i at t depends on: first = i - 1 .. i + 2 (clamped to
 * the list); a single key before the first or after the last time.
 * Returns how many. */
static int window_of(const sl_camera_key *keys, int count, double t, int *first)
{
    if (count == 1 || !(t > keys[0].t)) {
        *first = 0;
        return 1;
    }
    if (t >= keys[count - 1].t) {
        *first = count - 1;
        return 1;
    }
    int lo = 0, hi = count - 1; /* keys[lo].t <= t < keys[hi].t */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (keys[mid].t <= t)
            lo = mid;
        else
            hi = mid;
    }
    *first = lo > 0 ? lo - 1 : 0;
    int last = lo + 2 < count ? lo + 2 : count - 1;
    return last - *first + 1;
}

sl_status sl_camera_path_at(const sl_camera_key *keys, int count, sl_path_interpolation mode, double t,
                            sl_vec3 lo, sl_vec3 hi, sl_camera_spec *out, sl_err *err)
{
    if (count < 1)
        return sl_err_set(err, SL_ERR_INVALID, "a camera path needs at least one key");
    if (!isfinite(t))
        return sl_err_set(err, SL_ERR_INVALID, "camera path time must be finite");
    for (int k = 0; k < count; k++)
        if (!isfinite(keys[k].t) || (k > 0 && !(keys[k].t > keys[k - 1].t)))
            return sl_err_set(err, SL_ERR_INVALID, "camera path key %d: times must be finite and strictly ascending",
                              k);
    int first = 0, n = window_of(keys, count, t, &first);
    double times[WINDOW];
    for (int k = 0; k < n; k++)
        times[k] = keys[first + k].t;

    if (sl_camera_path_is_orbit(keys, count)) {
        double az[WINDOW], el[WINDOW], logd[WINDOW], fov[WINDOW];
        for (int k = 0; k < n; k++) {
            const sl_orbit *o = &keys[first + k].camera.orbit;
            double step = k == 0 ? 0.0 : wrap180(o->azimuth_deg - keys[first + k - 1].camera.orbit.azimuth_deg);
            az[k] = k == 0 ? o->azimuth_deg : az[k - 1] + step;
            el[k] = o->elevation_deg;
            if (!(o->distance > 0.0) || !isfinite(o->distance))
                return sl_err_set(err, SL_ERR_INVALID, "camera path key %d: orbit distance must be > 0", first + k);
            logd[k] = log(o->distance);
            fov[k] = o->fov_y_deg;
        }
        sl_orbit r;
        r.azimuth_deg = sl_path_scalar_at(times, az, n, mode, t);
        r.elevation_deg = clamp(sl_path_scalar_at(times, el, n, mode, t), -SL_ORBIT_MAX_ELEVATION, SL_ORBIT_MAX_ELEVATION);
        r.distance = exp(sl_path_scalar_at(times, logd, n, mode, t));
        r.fov_y_deg = clamp(sl_path_scalar_at(times, fov, n, mode, t), SL_PATH_MIN_FOV, SL_PATH_MAX_FOV);
        *out = (sl_camera_spec){.is_orbit = 1, .orbit = r};
        return SL_OK;
    }

    sl_camera cams[WINDOW];
    double ex[WINDOW], ey[WINDOW], ez[WINDOW], logd[WINDOW], fov[WINDOW];
    for (int k = 0; k < n; k++) {
        sl_status st = sl_camera_spec_resolve(&keys[first + k].camera, lo, hi, &cams[k], err);
        if (st != SL_OK) {
            sl_err_prefix(err, "camera path key");
            return st;
        }
        ex[k] = cams[k].eye.x;
        ey[k] = cams[k].eye.y;
        ez[k] = cams[k].eye.z;
        logd[k] = log(sl_v3_length(sl_v3_sub(cams[k].target, cams[k].eye)));
        fov[k] = cams[k].fov_y_deg;
    }
    sl_camera c;
    if (n == 1) {
        c = cams[0];
        c.up = orthogonal_up(c.up, c.up, sl_v3_normalize(sl_v3_sub(c.target, c.eye)));
    } else {
        int i = 0; /* the window's segment */
        while (i + 1 < n - 1 && times[i + 1] <= t)
            i++;
        double s = (t - times[i]) / (times[i + 1] - times[i]);
        sl_vec3 f0 = sl_v3_normalize(sl_v3_sub(cams[i].target, cams[i].eye));
        sl_vec3 f1 = sl_v3_normalize(sl_v3_sub(cams[i + 1].target, cams[i + 1].eye));
        sl_vec3 f = slerp(f0, f1, s);
        sl_vec3 u0 = orthogonal_up(cams[i].up, cams[i].up, f0), u1 = orthogonal_up(cams[i + 1].up, u0, f1);
        c.eye = sl_v3(sl_path_scalar_at(times, ex, n, mode, t), sl_path_scalar_at(times, ey, n, mode, t),
                      sl_path_scalar_at(times, ez, n, mode, t));
        c.target = sl_v3_add(c.eye, sl_v3_scale(f, exp(sl_path_scalar_at(times, logd, n, mode, t))));
        c.up = orthogonal_up(slerp(u0, u1, s), u0, f);
        c.fov_y_deg = clamp(sl_path_scalar_at(times, fov, n, mode, t), SL_PATH_MIN_FOV, SL_PATH_MAX_FOV);
    }
    *out = (sl_camera_spec){.is_orbit = 0, .look_at = c};
    return SL_OK;
}
