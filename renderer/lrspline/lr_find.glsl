// lr_find.glsl — the one place that picks the GPU element look-up providing
// int lr_find_element(vec3 p) (with lr_gpu.c on the C side, which uploads what it reads).
// Now: the linear scan placeholder; switch to "lrspline/lr_lookup.glsl" when it lands.
#include "lrspline/lr_bezier.glsl"
#include "lrspline/lr_lookup_linear.glsl"
