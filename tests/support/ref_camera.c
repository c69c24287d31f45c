/* ref_camera.c — proto/scene.md's pixel rays in double (see ref_camera.h). Any thread, no state. */
#include "ref_camera.h"

#include <math.h>

static double normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
    return l;
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

int ref_camera_init(ref_camera *c, const double eye[3], const double target[3], const double up[3],
                    double fov_y_deg, int width, int height)
{
    if (!(fov_y_deg > 0.0 && fov_y_deg < 180.0) || width <= 0 || height <= 0)
        return -1;
    for (int k = 0; k < 3; k++) {
        c->eye[k] = eye[k];
        c->forward[k] = target[k] - eye[k];
    }
    if (!(normalize3(c->forward) > 0.0))
        return -1;
    cross3(c->forward, up, c->right);
    if (!(normalize3(c->right) > 1e-12))
        return -1;
    cross3(c->right, c->forward, c->up);
    c->tan_half_fov = tan(fov_y_deg * 3.14159265358979323846 / 360.0);
    c->aspect = (double)width / (double)height;
    c->width = width;
    c->height = height;
    return 0;
}

void ref_camera_ray(const ref_camera *c, int i, int j, double d[3])
{
    double sx = (2.0 * (i + 0.5) / c->width - 1.0) * c->tan_half_fov * c->aspect;
    double sy = (1.0 - 2.0 * (j + 0.5) / c->height) * c->tan_half_fov;
    for (int k = 0; k < 3; k++)
        d[k] = c->forward[k] + sx * c->right[k] + sy * c->up[k];
    normalize3(d);
}

double ref_camera_pixel_size(const ref_camera *c, double distance)
{
    return 2.0 * distance * c->tan_half_fov / c->height;
}
