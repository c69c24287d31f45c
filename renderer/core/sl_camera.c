/* sl_camera.c — camera resolution, validation and view matrices (see sl_camera.h).
 * Everything here is double precision; runs on any thread. */
#include "sl_camera.h"

#include <math.h>

const sl_orbit sl_orbit_default = {.azimuth_deg = 30.0, .elevation_deg = 20.0, .distance = 2.5, .fov_y_deg = 45.0};

sl_camera_spec sl_camera_spec_default(void)
{
    return (sl_camera_spec){.is_orbit = 1, .orbit = sl_orbit_default};
}

sl_status sl_camera_from_orbit(const sl_orbit *orbit, sl_vec3 lo, sl_vec3 hi,
                               sl_camera *out, sl_err *err)
{
    if (!isfinite(orbit->azimuth_deg) || !isfinite(orbit->elevation_deg) ||
        !isfinite(orbit->distance) || !isfinite(orbit->fov_y_deg))
        return sl_err_set(err, SL_ERR_INVALID, "camera.orbit: azimuth, elevation, distance and fov_y must be finite numbers");
    if (orbit->distance <= 0.0)
        return sl_err_set(err, SL_ERR_INVALID, "camera.orbit.distance must be > 0 (bounding-sphere radii), got %g", orbit->distance);
    if (fabs(orbit->elevation_deg) > SL_ORBIT_MAX_ELEVATION)
        return sl_err_set(err, SL_ERR_INVALID, "camera.orbit.elevation must be in [%g, %g] degrees, got %g",
                          -SL_ORBIT_MAX_ELEVATION, SL_ORBIT_MAX_ELEVATION, orbit->elevation_deg);
    sl_vec3 centre = sl_v3_scale(sl_v3_add(lo, hi), 0.5);
    double radius = 0.5 * sl_v3_length(sl_v3_sub(hi, lo));
    if (!(radius > 0.0))
        radius = 1.0;
    double az = orbit->azimuth_deg * SL_PI / 180.0;
    double el = orbit->elevation_deg * SL_PI / 180.0;
    sl_vec3 dir = sl_v3(cos(el) * sin(az), sin(el), cos(el) * cos(az));
    out->eye = sl_v3_add(centre, sl_v3_scale(dir, orbit->distance * radius));
    out->target = centre;
    out->up = sl_v3(0, 1, 0);
    out->fov_y_deg = orbit->fov_y_deg;
    return sl_camera_validate(out, err);
}

sl_status sl_camera_validate(const sl_camera *c, sl_err *err)
{
    if (!sl_v3_is_finite(c->eye))
        return sl_err_set(err, SL_ERR_INVALID, "camera.eye must be three finite numbers");
    if (!sl_v3_is_finite(c->target))
        return sl_err_set(err, SL_ERR_INVALID, "camera.target must be three finite numbers");
    if (!sl_v3_is_finite(c->up))
        return sl_err_set(err, SL_ERR_INVALID, "camera.up must be three finite numbers");
    if (!isfinite(c->fov_y_deg) || c->fov_y_deg <= 0.0 || c->fov_y_deg >= 180.0)
        return sl_err_set(err, SL_ERR_INVALID, "camera.fov_y must be in (0, 180) degrees, got %g", c->fov_y_deg);
    sl_vec3 f = sl_v3_sub(c->target, c->eye);
    double fl = sl_v3_length(f);
    double scale = fmax(sl_v3_length(c->eye), sl_v3_length(c->target));
    if (!(fl > 1e-12 * fmax(scale, 1.0)))
        return sl_err_set(err, SL_ERR_INVALID, "camera.eye and camera.target must differ");
    double ul = sl_v3_length(c->up);
    if (!(ul > 0.0))
        return sl_err_set(err, SL_ERR_INVALID, "camera.up must not be the zero vector");
    sl_vec3 r = sl_v3_cross(sl_v3_scale(f, 1.0 / fl), sl_v3_scale(c->up, 1.0 / ul));
    if (!(sl_v3_length(r) > 1e-9))
        return sl_err_set(err, SL_ERR_INVALID, "camera.up must not be parallel to the view direction");
    return SL_OK;
}

sl_status sl_camera_spec_resolve(const sl_camera_spec *spec, sl_vec3 lo, sl_vec3 hi, sl_camera *out,
                                 sl_err *err)
{
    if (spec->is_orbit)
        return sl_camera_from_orbit(&spec->orbit, lo, hi, out, err);
    *out = spec->look_at;
    return sl_camera_validate(out, err);
}

sl_status sl_view_init(sl_view *v, double scene_radius, sl_err *err)
{
    sl_status st = sl_camera_validate(&v->camera, err);
    if (st != SL_OK)
        return st;
    if (v->width < 1 || v->height < 1)
        return sl_err_set(err, SL_ERR_INVALID, "view size must be at least 1x1, got %dx%d", v->width, v->height);
    if (!sl_v3_is_finite(v->origin))
        v->origin = sl_v3(0, 0, 0);
    if (!(scene_radius > 0.0) || !isfinite(scene_radius))
        scene_radius = 1.0;
    if (!(v->near_plane > 0.0) || !isfinite(v->near_plane))
        v->near_plane = 1e-4 * scene_radius;

    const sl_camera *c = &v->camera;
    v->forward = sl_v3_normalize(sl_v3_sub(c->target, c->eye));
    v->right = sl_v3_normalize(sl_v3_cross(v->forward, c->up));
    v->upv = sl_v3_cross(v->right, v->forward);
    v->tan_half_fov = tan(0.5 * c->fov_y_deg * SL_PI / 180.0);
    v->aspect = (double)v->width / (double)v->height;

    /* View matrix: rows R, U, -F; translation relative to the origin. */
    sl_vec3 e = sl_v3_sub(c->eye, v->origin);
    sl_mat4 m = sl_mat4_identity();
    m.m[0] = v->right.x;    m.m[4] = v->right.y;    m.m[8] = v->right.z;
    m.m[1] = v->upv.x;      m.m[5] = v->upv.y;      m.m[9] = v->upv.z;
    m.m[2] = -v->forward.x; m.m[6] = -v->forward.y; m.m[10] = -v->forward.z;
    m.m[12] = -sl_v3_dot(v->right, e);
    m.m[13] = -sl_v3_dot(v->upv, e);
    m.m[14] = sl_v3_dot(v->forward, e);
    v->view_matrix = m;

    /* Reversed infinite perspective: clip.w = -z, clip.z = near, so that
     * depth = near / (-z): 1 on the near plane, towards 0 at infinity. */
    sl_mat4 p = {{0}};
    p.m[0] = 1.0 / (v->tan_half_fov * v->aspect);
    p.m[5] = 1.0 / v->tan_half_fov;
    p.m[11] = -1.0;
    p.m[14] = v->near_plane;
    v->projection = p;
    v->view_projection = sl_mat4_mul(p, m);
    return SL_OK;
}

sl_vec3 sl_view_ray_dir(const sl_view *v, double i, double j)
{
    double sx = (2.0 * (i + 0.5) / v->width - 1.0) * v->tan_half_fov * v->aspect;
    double sy = (1.0 - 2.0 * (j + 0.5) / v->height) * v->tan_half_fov;
    return sl_v3_normalize(sl_v3_add(v->forward, sl_v3_add(sl_v3_scale(v->right, sx), sl_v3_scale(v->upv, sy))));
}

double sl_view_depth_to_distance(const sl_view *v, double i, double j, double depth)
{
    if (!(depth > 0.0))
        return 0.0;
    double sx = (2.0 * (i + 0.5) / v->width - 1.0) * v->tan_half_fov * v->aspect;
    double sy = (1.0 - 2.0 * (j + 0.5) / v->height) * v->tan_half_fov;
    double z = v->near_plane / depth; /* distance along F */
    return z * sqrt(1.0 + sx * sx + sy * sy);
}
