/* line_style.c — checks and resolves the shared line parameters for one frame (see sl_line_style.h).
 * Any thread; no GL. */
#include "sl_line_style.h"

#include <math.h>

#include "../data/sl_dataset.h"

sl_status sl_line_style_check(const sl_params *p, const sl_dataset *ds, sl_err *err)
{
    return sl_params_check_attributes(p, ds->kind == SL_DATASET_LINES ? ds->lines.attribute_count : 0, err);
}

void sl_line_style_read(const sl_params *p, const sl_dataset *ds, sl_line_style *s)
{
    s->radius = (float)sl_params_float(p, "radius");
    if (!(s->radius > 0.0f))
        s->radius = (float)(sl_dataset_radius(ds) / 300.0);
    s->radius_scale = (float)sl_params_float(p, "radius_scale");
    s->attribute = sl_params_attribute(p, "attribute");
    if (ds->kind != SL_DATASET_LINES || s->attribute >= ds->lines.attribute_count)
        s->attribute = -1;
    s->radius_attribute = sl_params_find(p, "radius_attribute") >= 0 ? sl_params_attribute(p, "radius_attribute") : -1;
    if (ds->kind != SL_DATASET_LINES || s->radius_attribute >= ds->lines.attribute_count)
        s->radius_attribute = -1;
    s->colormap = sl_params_choice(p, "colormap");
    s->scalar_range[0] = (float)sl_params_float(p, "scalar_min");
    s->scalar_range[1] = (float)sl_params_float(p, "scalar_max");
    if (s->scalar_range[0] == s->scalar_range[1] && s->attribute >= 0) {
        s->scalar_range[0] = ds->lines.attributes[s->attribute].min;
        s->scalar_range[1] = ds->lines.attributes[s->attribute].max;
    }
    sl_params_vec3(p, "color", s->color);
    sl_params_vec3(p, "light_direction", s->light_direction);
    float len = sqrtf(s->light_direction[0] * s->light_direction[0] + s->light_direction[1] * s->light_direction[1] +
                      s->light_direction[2] * s->light_direction[2]);
    if (len > 0.0f)
        for (int c = 0; c < 3; c++)
            s->light_direction[c] /= len;
    else {
        s->light_direction[0] = s->light_direction[1] = 0.0f;
        s->light_direction[2] = 1.0f;
    }
    s->material[0] = (float)sl_params_float(p, "ambient");
    s->material[1] = (float)sl_params_float(p, "diffuse");
    s->material[2] = (float)sl_params_float(p, "specular");
    s->material[3] = (float)sl_params_float(p, "shininess");
}
