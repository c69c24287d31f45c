// lr_find.glsl — the one place that picks the GPU element look-up providing
// int lr_find_element(vec3 p) (with lr_bezier_gpu.c on the C side, which uploads what it
// reads): the structures of sl_lr_lookup.h (lr_lookup.glsl; the kind is a #define from
// sl_lr_bezier_defines). A linear scan is no option on llvmpipe: it cuts long loops, and
// rays over ~10^3 elements ended early.
#include "lrspline/lr_bezier.glsl"
#include "lrspline/lr_lookup.glsl"
