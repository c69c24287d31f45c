// flow_trace_regular.comp.glsl — streamlines of a regular vector field: the
// number types, the trilinear field, then the integrator (one invocation per
// streamline). An LR field gets its own 3-line stage file with its field.
#include "flow/flow_real.glsl"
#include "flow/flow_field_regular.glsl"
#include "flow/flow_integrate.glsl"
