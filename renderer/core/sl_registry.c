/* sl_registry.c — the one table of techniques. A new technique adds one line
 * here (and its folder under renderer/); nothing else names techniques. */
#include "sl_technique.h"

#include <string.h>

extern const sl_technique sl_tubes_mesh_technique;
extern const sl_technique sl_tubes_technique;
extern const sl_technique sl_voxel_lines_technique;
extern const sl_technique sl_lines_oit_technique;
extern const sl_technique sl_volume_dvr_technique;
extern const sl_technique sl_ribbons_technique;

static const sl_technique *const techniques[] = {
    &sl_tubes_mesh_technique,
    &sl_tubes_technique,
    &sl_voxel_lines_technique,
    &sl_lines_oit_technique,
    &sl_volume_dvr_technique,
    &sl_ribbons_technique,
};

const sl_technique *const *sl_technique_list(int *count)
{
    *count = (int)(sizeof techniques / sizeof techniques[0]);
    return techniques;
}

const sl_technique *sl_technique_find(const char *name)
{
    for (size_t i = 0; i < sizeof techniques / sizeof techniques[0]; i++)
        if (strcmp(techniques[i]->name, name) == 0)
            return techniques[i];
    return NULL;
}
