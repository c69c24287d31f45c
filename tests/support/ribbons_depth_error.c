/* ribbons_depth_error.c — depth of one rendered straight ribbon against the analytic ellipse (see the header).
 * Any thread, no state.
 */
#include "ribbons_depth_error.h"

#include <math.h>
#include <string.h>

#define RDE_PI 3.14159265358979323846

/* seg with both semi-axes scaled by `scale` and then grown by `grow` (world; negative shrinks). */
static ribbons_ref_segment resized(const ribbons_ref_segment *seg, double scale, double grow)
{
    ribbons_ref_segment s = *seg;
    double a_n = seg->r * seg->w * scale + grow, a_b = seg->r * scale + grow;
    s.r = a_b > 0.0 ? a_b : 1e-300;
    s.w = a_n > 0.0 ? a_n / s.r : 1e-300;
    s.half_len = fmax(seg->half_len + grow, 0.0);
    return s;
}

static void note_bad(ribbons_depth_error *out, int i, int j, double gpu, double ref, double bound)
{
    if (out->bad_i >= 0)
        return;
    out->bad_i = i;
    out->bad_j = j;
    out->bad_gpu = gpu;
    out->bad_ref = ref;
    out->bad_bound = bound;
}

int ribbons_depth_error_measure(const float *distance, const ref_camera *cam, const ribbons_ref_segment *seg,
                                const ribbons_depth_limits *limits, ribbons_depth_error *out)
{
    memset(out, 0, sizeof *out);
    out->bad_i = out->bad_j = -1;
    if (!(seg->r > 0.0) || !(seg->w > 0.0) || limits->sides < 3)
        return -1;
    double to_centre[3], eye_distance = 0.0;
    for (int k = 0; k < 3; k++) {
        to_centre[k] = seg->x0[k] - cam->eye[k];
        eye_distance += to_centre[k] * to_centre[k];
    }
    double margin = limits->margin_px * ref_camera_pixel_size(cam, sqrt(eye_distance));
    const ribbons_ref_segment inner = resized(seg, cos(RDE_PI / limits->sides), -margin);
    const ribbons_ref_segment outer = resized(seg, 1.0, margin);
    double sum = 0.0;
    for (int j = 0; j < cam->height; j++)
        for (int i = 0; i < cam->width; i++) {
            double d[3];
            ref_camera_ray(cam, i, j, d);
            ribbons_ref_hit hit, in_hit, out_hit;
            ribbons_ref_ray_ellipse(cam->eye, d, seg, &hit);
            ribbons_ref_ray_ellipse(cam->eye, d, &inner, &in_hit);
            ribbons_ref_ray_ellipse(cam->eye, d, &outer, &out_hit);
            double t_gpu = distance[(size_t)j * (size_t)cam->width + (size_t)i];
            int gpu_hit = t_gpu > 0.0, ref_hit = hit.distance > 0.0 && !hit.inside;
            out->ref_hits += (size_t)ref_hit;
            out->gpu_hits += (size_t)gpu_hit;
            if (gpu_hit != ref_hit)
                out->mismatch++;
            if (!gpu_hit && in_hit.distance > 0.0) {
                out->missed++;
                note_bad(out, i, j, t_gpu, hit.distance, 0.0);
            }
            if (gpu_hit && !(out_hit.distance > 0.0)) {
                out->spurious++;
                note_bad(out, i, j, t_gpu, hit.distance, 0.0);
            }
            if (!gpu_hit || !ref_hit)
                continue;
            double e = fabs(t_gpu - hit.distance) / seg->r;
            out->both++;
            sum += e;
            out->max_err = fmax(out->max_err, e);
            if (hit.part == RIBBONS_REF_MANTLE && hit.cos_in >= limits->head_on_cos)
                out->max_head_on = fmax(out->max_head_on, e);
            double bound;
            if (hit.part == RIBBONS_REF_MANTLE)
                bound = ribbons_ref_polygon_bound(d, seg, limits->sides, hit.cos_in);
            else /* a cap: held only where the ray crosses the inscribed polygon's cap */
                bound = in_hit.distance > 0.0 && in_hit.part == hit.part ? 0.0 : HUGE_VAL;
            if (!isfinite(bound))
                continue;
            out->checked++;
            out->max_bound = fmax(out->max_bound, bound / seg->r);
            if (bound > 0.0)
                out->max_over_bound = fmax(out->max_over_bound, (t_gpu - hit.distance) / bound);
            if (t_gpu < hit.distance - limits->eps || t_gpu > hit.distance + bound + limits->eps) {
                out->outside_bound++;
                note_bad(out, i, j, t_gpu, hit.distance, bound);
            }
        }
    out->mean_err = out->both ? sum / (double)out->both : 0.0;
    return 0;
}
