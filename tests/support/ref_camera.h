/* ref_camera.h — the pixel rays of proto/scene.md, computed here in double for the references.
 *
 * Pixel (i, j), row 0 at the top, is sampled at its centre along
 * normalize(F + sx R + sy U) with sx = (2(i + 0.5)/W - 1) tan(fov/2) W/H,
 * sy = (1 - 2(j + 0.5)/H) tan(fov/2), F = normalize(target - eye),
 * R = normalize(F x up), U = R x F. Written from the document, not from the
 * renderer's sl_view (the benchmarks and render tests compare the renderer's
 * depth against references that use these rays). Any thread, no state.
 */
#ifndef REF_CAMERA_H
#define REF_CAMERA_H

typedef struct ref_camera {
    double eye[3];
    double forward[3], right[3], up[3]; /* F, R, U */
    double tan_half_fov, aspect;
    int width, height;
} ref_camera;

/* 0, or -1 when eye = target, up is parallel to the view, fov is outside
 * (0, 180) or the size is not positive (*c is then unspecified). */
int ref_camera_init(ref_camera *c, const double eye[3], const double target[3], const double up[3],
                    double fov_y_deg, int width, int height);

/* Unit direction of the ray through the centre of pixel (i, j). */
void ref_camera_ray(const ref_camera *c, int i, int j, double d[3]);

/* Height in world units of one pixel at eye distance `distance` along F. */
double ref_camera_pixel_size(const ref_camera *c, double distance);

#endif
