// particles_contours.glsl — the contour segments particles_contours.comp.glsl
// appends and particles_contours.vert.glsl draws (std430, 32 bytes): the two
// end points, relative to the view origin as pt_view_position.
struct pt_segment {
    vec4 a;
    vec4 b;
};
