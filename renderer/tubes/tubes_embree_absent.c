/* tubes_embree_absent.c — tubes_embree.h in a build without Embree (CMake compiles this
 * file instead of tubes_embree.c): not available, and create says which package is missing. */
#include "tubes_embree.h"

int sl_tubes_embree_available(void) { return 0; }

sl_status sl_tubes_embree_create(const sl_tubes_nodes *nodes, sl_tubes_embree **out, sl_err *err)
{
    (void)nodes;
    *out = NULL;
    return sl_err_set(err, SL_ERR_UNSUPPORTED,
                      "tubes: this build has no Embree (install Debian libembree-dev, Embree 3.13, and rebuild)");
}

void sl_tubes_embree_destroy(sl_tubes_embree *e) { (void)e; }

sl_status sl_tubes_embree_ensure(sl_tubes_embree *e, float radius, float radius_scale, double *rebuilt_ms,
                                 sl_err *err)
{
    (void)e, (void)radius, (void)radius_scale;
    *rebuilt_ms = 0.0;
    return sl_err_set(err, SL_ERR_UNSUPPORTED, "tubes: this build has no Embree");
}

sl_status sl_tubes_embree_render(sl_tubes_embree *e, const sl_view *view, const sl_line_shader *shader,
                                 const float *colors, float radius, float radius_scale, sl_host_frame *frame,
                                 double *rebuilt_ms, sl_err *err)
{
    (void)e, (void)view, (void)shader, (void)colors, (void)radius, (void)radius_scale, (void)frame;
    *rebuilt_ms = 0.0;
    return sl_err_set(err, SL_ERR_UNSUPPORTED, "tubes: this build has no Embree");
}

void sl_tubes_embree_stats_get(const sl_tubes_embree *e, sl_tubes_embree_stats *out)
{
    (void)e;
    *out = (sl_tubes_embree_stats){0};
}
