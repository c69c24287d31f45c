// line_style.glsl — the uniforms of the shared line style (line_style/sl_line_style.h) that
// every shaded line technique reads: colour by a scalar through a colormap or one colour, and
// the light and material of lighting.glsl.
uniform sampler2D u_colormap;
uniform vec2 u_scalar_range;    // scalar at colormap ends (min > max inverts)
uniform int u_use_colormap;     // 0: u_color
uniform vec3 u_color;
uniform vec3 u_light_eye;       // direction to the light in eye space (x right, y up, z to viewer)
uniform vec4 u_material;        // ambient, diffuse, specular, shininess
