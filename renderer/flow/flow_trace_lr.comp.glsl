// flow_trace_lr.comp.glsl — streamlines of an LR-spline vector field: the
// number types, the Bézier-block field with its element look-up, then the
// shared integrator (one invocation per streamline).
#include "flow/flow_real.glsl"
#include "flow/flow_field_lr.glsl"
#include "flow/flow_integrate.glsl"
