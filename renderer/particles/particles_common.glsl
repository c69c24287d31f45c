// particles_common.glsl — the particle record every particles pass shares.
// Positions are local world units: world - volume origin (the voxel (0,0,0)).
// p.w is the step length lambda (> 0) of an alive particle, or -1 for a
// dead one (dropped where |grad f| vanished or a value was not finite: never
// drawn, never exported, keyed past the last bin). n.xyz is the unit normal
// -grad f / |grad f| of the last reprojection (trilinear), n.w the particle's
// energy at the step before (the step-length rule), +inf before the first.
struct pt_particle {
    vec4 p;
    vec4 n;
};

const float PT_DEAD = -1.0;
const float PT_PI = 3.14159265358979;

bool pt_alive(pt_particle q)
{
    return q.p.w > 0.0;
}
