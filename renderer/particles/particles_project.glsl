// particles_project.glsl — moving a particle back onto the trilinear
// isosurface f = u_iso by Newton steps (the paper's Eq. 2,
// p <- p - (f - iso) g/|g|^2), inside the volume box [0, box] (local world).
// Where a step would leave the box through a face, the gradient's
// components normal to those faces are dropped and the step is taken
// again: the particle then moves along the face onto the curve where the
// surface meets it (surfaces that leave the volume end there). Steps are
// capped at `cap` (world).
//   pt_reproject: one step (the energy pass's Eq. 2); false when the gradient
//     vanishes (|g| < gmin) or a value is not finite, p unchanged;
//   pt_polish: up to 8 steps, each halved until |f - iso| decreases (the
//     trilinear gradient jumps across cell faces, where a full step can
//     overshoot back and forth), then, if still off the surface, a bracketed
//     bisection along the gradient line within `cap`.
uniform float u_iso;

// The face-aware Newton step at p for residual r and world gradient g.
vec3 pt_newton_delta(vec3 p, float r, vec3 g, float gmin, vec3 box)
{
    vec3 delta = r * g / dot(g, g);
    vec3 q = p - delta;
    bvec3 out_lo = lessThan(q, vec3(0.0)), out_hi = greaterThan(q, box);
    if (any(out_lo) || any(out_hi)) {
        vec3 gf = g * vec3(not(out_lo)) * vec3(not(out_hi));
        float gf2 = dot(gf, gf);
        delta = gf2 > 0.0 && gf2 >= gmin * gmin ? r * gf / gf2 : vec3(0.0);
    }
    return delta;
}

bool pt_usable_gradient(float f, vec3 g, float gmin)
{
    float g2 = dot(g, g);
    return g2 > 0.0 && g2 >= gmin * gmin && pt_finite(f) && pt_finite3(g);
}

bool pt_reproject(inout vec3 p, float cap, float gmin, vec3 box, out vec3 g_out)
{
    vec3 gu;
    float f = pt_trilinear(p / u_spacing, gu);
    vec3 g = pt_world_gradient(gu);
    g_out = g;
    if (!pt_usable_gradient(f, g, gmin))
        return false;
    vec3 delta = pt_newton_delta(p, f - u_iso, g, gmin, box);
    float dl = length(delta);
    if (dl > cap)
        delta *= cap / dl;
    p = clamp(p - delta, vec3(0.0), box);
    return true;
}

void pt_polish(inout vec3 p, float cap, vec3 box)
{
    vec3 gu;
    float f = pt_trilinear(p / u_spacing, gu);
    for (int k = 0; k < 8; k++) {
        vec3 g = pt_world_gradient(gu);
        float r = f - u_iso;
        if (r == 0.0 || !pt_usable_gradient(f, g, 0.0))
            return;
        vec3 delta = pt_newton_delta(p, r, g, 0.0, box);
        float dl = length(delta);
        if (dl > cap)
            delta *= cap / dl;
        bool improved = false;
        for (int h = 0; h < 6 && !improved; h++) {
            vec3 q = clamp(p - delta, vec3(0.0), box);
            vec3 gq;
            float fq = pt_trilinear(q / u_spacing, gq);
            if (pt_finite(fq) && abs(fq - u_iso) < abs(r)) {
                p = q;
                f = fq;
                gu = gq;
                improved = true;
            }
            delta *= 0.5;
        }
        if (!improved)
            break;
    }
    // Still off the surface (a crease of the trilinear field at a cell face
    // stops Newton): bracket the crossing along the gradient line, towards
    // the side f says, then the other way, within `cap`, and bisect.
    vec3 g = pt_world_gradient(gu);
    float r = f - u_iso;
    float gl = length(g);
    if (r == 0.0 || !(gl > 0.0) || !pt_finite(f) || abs(r) / gl < 1e-4 * cap)
        return;
    for (int side = 0; side < 2; side++) {
        vec3 d = (side == 0 ? -sign(r) : sign(r)) * g / gl;
        float t_lo = 0.0, t_hi = 0.0;
        bool bracketed = false;
        for (float t = cap / 64.0; t <= cap * 1.0001 && !bracketed; t *= 2.0) {
            vec3 gt;
            float ft = pt_trilinear(clamp(p + t * d, vec3(0.0), box) / u_spacing, gt);
            if (pt_finite(ft) && (ft < u_iso) != (f < u_iso)) {
                t_hi = t;
                bracketed = true;
            } else {
                t_lo = t;
            }
        }
        if (!bracketed)
            continue;
        for (int k = 0; k < 24; k++) {
            float t = 0.5 * (t_lo + t_hi);
            vec3 gt;
            float ft = pt_trilinear(clamp(p + t * d, vec3(0.0), box) / u_spacing, gt);
            if ((ft < u_iso) == (f < u_iso))
                t_lo = t;
            else
                t_hi = t;
        }
        p = clamp(p + 0.5 * (t_lo + t_hi) * d, vec3(0.0), box);
        return;
    }
}
