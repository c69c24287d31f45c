/* particles_frame.c — the per-frame data of `particles` (particles_frame.h). */
#include "particles_frame.h"

#include <math.h>

void pt_frame_init(pt_frame *f, const sl_view *view, const sl_params *params, sl_vec3 volume_origin,
                   float max_point)
{
    f->view = view;
    float l[3];
    sl_params_vec3(params, "light_direction", l);
    double ll = sqrt((double)l[0] * l[0] + (double)l[1] * l[1] + (double)l[2] * l[2]);
    double le[3] = {0.0, 0.0, 1.0};
    if (ll > 0.0)
        for (int c = 0; c < 3; c++)
            le[c] = l[c] / ll;
    /* Eye space (x right, y up, z towards the viewer) to world. */
    sl_vec3 lw = sl_v3_add(sl_v3_add(sl_v3_scale(view->right, le[0]), sl_v3_scale(view->upv, le[1])),
                           sl_v3_scale(view->forward, -le[2]));
    f->light_world[0] = (float)lw.x;
    f->light_world[1] = (float)lw.y;
    f->light_world[2] = (float)lw.z;
    f->volume_offset[0] = (float)(volume_origin.x - view->origin.x);
    f->volume_offset[1] = (float)(volume_origin.y - view->origin.y);
    f->volume_offset[2] = (float)(volume_origin.z - view->origin.z);
    f->px_per_world = (float)(view->height / (2.0 * view->tan_half_fov));
    f->max_point = max_point;
    float c[3];
    sl_params_vec3(params, "focus_center", c);
    f->focus[0] = (float)(c[0] - volume_origin.x);
    f->focus[1] = (float)(c[1] - volume_origin.y);
    f->focus[2] = (float)(c[2] - volume_origin.z);
    f->focus[3] = (float)sl_params_float(params, "focus_radius");
}

void pt_frame_uniforms(GLuint program, const pt_frame *f)
{
    glUniform3fv(glGetUniformLocation(program, "u_volume_offset"), 1, f->volume_offset);
    glUniform1f(glGetUniformLocation(program, "u_px_per_world"), f->px_per_world);
    glUniform1f(glGetUniformLocation(program, "u_max_point"), f->max_point);
    glUniform4fv(glGetUniformLocation(program, "u_focus"), 1, f->focus);
}
