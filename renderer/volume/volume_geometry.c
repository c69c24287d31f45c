/* volume_geometry.c — a volume's box in voxel and world coordinates (see sl_volume.h).
 * Values at voxel centres; the box spans them (a one-voxel axis: a slab one
 * spacing thick). Any thread; no GL. */
#include "sl_volume.h"

void sl_volume_geometry_init(const sl_dataset *ds, sl_volume_geometry *g)
{
    const sl_volume *v = &ds->volume;
    g->origin = ds->origin;
    g->min_spacing = v->spacing[0];
    for (int a = 0; a < 3; a++) {
        g->dims[a] = v->dims[a];
        g->spacing[a] = v->spacing[a];
        if (v->spacing[a] < g->min_spacing)
            g->min_spacing = v->spacing[a];
        g->box_lo[a] = v->dims[a] > 1 ? 0.0 : -0.5;
        g->box_hi[a] = v->dims[a] > 1 ? (double)(v->dims[a] - 1) : 0.5;
    }
}
