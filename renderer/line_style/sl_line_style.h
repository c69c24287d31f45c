/* sl_line_style.h — the parameters every line technique shares, under the same names.
 *
 * Put SL_LINE_STYLE_PARAMS at the start of a line technique's schema, check
 * them against the dataset with sl_line_style_check (prepare and every
 * frame: attribute indices must exist) and read them per frame with
 * sl_line_style_read, which resolves the automatic values (radius 0 = 1/300
 * of the dataset's bounding-sphere radius; scalar range min == max = the
 * attribute's own range). Names: radius, radius_scale, attribute,
 * colormap, scalar_min, scalar_max, color, light_direction, ambient,
 * diffuse, specular, shininess; all invalidate FRAME only. Techniques with
 * per-vertex radii add radius_attribute (PREPARED: radii are baked into
 * their buffers), see SL_LINE_STYLE_RADIUS_ATTRIBUTE_PARAM.
 */
#ifndef SL_LINE_STYLE_H
#define SL_LINE_STYLE_H

#include "../core/sl_colormap.h"
#include "../core/sl_params.h"

struct sl_dataset;

#define SL_LINE_STYLE_PARAM_COUNT 12
#define SL_LINE_STYLE_PARAMS \
    {"radius", SL_PARAM_FLOAT, 0.0, 1e9, {0}, NULL, "world", \
     "tube radius where the data gives none; 0 = automatic (1/300 of the data's bounding radius)", SL_INVALIDATE_FRAME}, \
    {"radius_scale", SL_PARAM_FLOAT, 0.0, 1000.0, {1}, NULL, "", \
     "factor on radii that the data gives", SL_INVALIDATE_FRAME}, \
    {"attribute", SL_PARAM_ATTRIBUTE, -1, 31, {0}, NULL, "", \
     "index of the per-vertex attribute that drives colour; -1 = constant colour", SL_INVALIDATE_FRAME}, \
    {"colormap", SL_PARAM_ENUM, 0, 0, {0}, sl_colormap_names, "", \
     "colormap for the attribute", SL_INVALIDATE_FRAME}, \
    {"scalar_min", SL_PARAM_FLOAT, -1e30, 1e30, {0}, NULL, "", \
     "attribute value at the colormap's start (min == max: the attribute's range; min > max inverts the map)", \
     SL_INVALIDATE_FRAME}, \
    {"scalar_max", SL_PARAM_FLOAT, -1e30, 1e30, {0}, NULL, "", \
     "attribute value at the colormap's end", SL_INVALIDATE_FRAME}, \
    {"color", SL_PARAM_VEC3, 0.0, 1.0, {0.8, 0.8, 0.8}, NULL, "rgb", \
     "constant colour when no attribute is used", SL_INVALIDATE_FRAME}, \
    {"light_direction", SL_PARAM_VEC3, -1.0, 1.0, {0.3, 0.5, 1.0}, NULL, "eye space", \
     "direction towards the light: x right, y up, z towards the viewer", SL_INVALIDATE_FRAME}, \
    {"ambient", SL_PARAM_FLOAT, 0.0, 1.0, {0.25}, NULL, "", "ambient light", SL_INVALIDATE_FRAME}, \
    {"diffuse", SL_PARAM_FLOAT, 0.0, 1.0, {0.75}, NULL, "", "Lambert diffuse weight", SL_INVALIDATE_FRAME}, \
    {"specular", SL_PARAM_FLOAT, 0.0, 1.0, {0.3}, NULL, "", "Blinn-Phong specular weight", SL_INVALIDATE_FRAME}, \
    {"shininess", SL_PARAM_FLOAT, 1.0, 512.0, {32}, NULL, "", "Blinn-Phong exponent", SL_INVALIDATE_FRAME}

/* For techniques whose tubes take per-vertex radii from the data (tubes,
 * tubes_mesh): add after SL_LINE_STYLE_PARAMS. Techniques that draw every
 * tube with the one `radius` (voxel_lines, lines_oit, as in their paper)
 * leave it out, so a scene cannot ask them for what they do not do. */
#define SL_LINE_STYLE_RADIUS_ATTRIBUTE_PARAM \
    {"radius_attribute", SL_PARAM_ATTRIBUTE, -1, 31, {-1}, NULL, "", \
     "index of the per-vertex attribute that gives the tube radius (|value| x radius_scale); -1 = the data's radii, " \
     "else radius", SL_INVALIDATE_PREPARED}

typedef struct sl_line_style {
    float radius;            /* resolved: > 0 unless the parameter and data radius are both 0 */
    float radius_scale;
    int attribute;           /* valid per-vertex attribute index, or -1 */
    int radius_attribute;    /* valid per-vertex attribute index, or -1 (data radii / radius) */
    int colormap;
    float scalar_range[2];   /* resolved */
    float color[3];
    float light_direction[3];/* eye space, normalized (headlight when given as 0) */
    float material[4];       /* ambient, diffuse, specular, shininess */
} sl_line_style;

/* SL_OK, or SL_ERR_INVALID naming the parameter, its value and the number of
 * attributes when an attribute parameter (`attribute`, `radius_attribute`:
 * SL_PARAM_ATTRIBUTE, sl_params_check_attributes) names an attribute the
 * dataset does not have. The default attribute 0 on a dataset without
 * attributes is accepted (constant colour): it means "the first, if any". */
sl_status sl_line_style_check(const sl_params *params, const struct sl_dataset *ds, sl_err *err);

/* Never fails: an index the dataset lacks reads as -1 (call
 * sl_line_style_check first to report it). */
void sl_line_style_read(const sl_params *params, const struct sl_dataset *ds, sl_line_style *style);

#endif
