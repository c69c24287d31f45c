// camera.glsl — the frame's camera as every technique sees it (see core/sl_camera.h).
// Positions are relative to the dataset origin. Depth is reversed and
// infinite-far: depth = near / (distance along the view direction).
layout(std140, binding = 0) uniform sl_camera_block {
    mat4 sl_view_matrix;        // (world - origin) -> eye space, -z forward
    mat4 sl_projection;
    mat4 sl_view_projection;
    vec4 sl_eye;                // xyz: eye relative to origin
    vec4 sl_forward;            // xyz: F
    vec4 sl_right;              // xyz: R
    vec4 sl_up;                 // xyz: U
    vec4 sl_viewport;           // width, height, tan(fov_y/2), aspect
    vec4 sl_near;               // x: near plane distance along F
};

// Ray direction (unnormalized: F + sx R + sy U) through window coordinate
// frag_xy (gl_FragCoord.xy, origin bottom-left, pixel centres at .5).
vec3 sl_ray_direction(vec2 frag_xy)
{
    float sx = (2.0 * frag_xy.x / sl_viewport.x - 1.0) * sl_viewport.z * sl_viewport.w;
    float sy = (2.0 * frag_xy.y / sl_viewport.y - 1.0) * sl_viewport.z;
    return sl_forward.xyz + sx * sl_right.xyz + sy * sl_up.xyz;
}

// The distance t along the unit ray direction d from the eye at which a surface of
// reversed-Z depth `depth` (> 0) lies: depth = near / (distance along F) and that
// distance is t dot(d, F).
float sl_distance_of_depth(float depth, vec3 d)
{
    return sl_near.x / (depth * dot(d, sl_forward.xyz));
}

// gl_FragDepth for a point p (relative to origin).
float sl_depth_of(vec3 p)
{
    float z = dot(p - sl_eye.xyz, sl_forward.xyz);
    return sl_near.x / max(z, 1e-30);
}
