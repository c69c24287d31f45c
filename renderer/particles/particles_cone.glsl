// particles_cone.glsl — the cone sprite of one particle (the paper's
// Algorithm 3), shared by the hidden-surface id pass (particles_cone.*.glsl)
// and the splats (particles_splat.*.glsl): the point size that holds the
// particle's tangent disk of radius `radius` (world) on screen, and per
// fragment the pixel ray's hit on that disk with the depth of the cone
// surface, rising from the apex at the particle to `radius` behind it at the
// rim, along the ray. With `facing`, nearly edge-on tangent planes use a
// disk facing the viewer instead, so silhouette particles still cover their
// pixel (the id pass; a splat keeps its tangent disk, which does not stick
// out of the silhouette); the footprint is at least 1.5 px in radius (the
// apex pixel is covered).
// Include after gpu/glsl/camera.glsl and particles/particles_record.glsl.

// The disk's projected diameter plus a pixel each side, at least 3 px.
float pt_cone_point_size(vec3 p, float radius, float max_point)
{
    return clamp(2.0 * radius * u_px_per_world / pt_eye_distance(p) + 2.0, 3.0, max_point);
}

// False where the ray through window position frag_xy (gl_FragCoord.xy)
// misses the disk (discard the fragment); else the
// cone's gl_FragDepth in `depth`.
bool pt_cone_fragment(vec2 frag_xy, vec3 center, vec3 normal, float radius, bool facing, out float depth)
{
    vec3 rd = normalize(sl_ray_direction(frag_xy));
    vec3 n = normal;
    if (facing && abs(dot(n, rd)) < 0.1)
        n = -rd;
    float t = dot(center - sl_eye.xyz, n) / dot(rd, n);
    vec3 x = sl_eye.xyz + t * rd;
    float z = pt_eye_distance(center);
    float r = max(radius, 1.5 * z / u_px_per_world);
    float rho = length(x - center);
    depth = 0.0;
    if (rho > r || !(t > 0.0))
        return false;
    depth = sl_depth_of(x + (radius * rho / r) * rd);
    return true;
}
