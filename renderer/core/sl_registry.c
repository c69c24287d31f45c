/* sl_registry.c — the one table of techniques. A new technique adds one line
 * here (and its folder under renderer/); nothing else names techniques. */
#include "sl_technique.h"

#include <stdio.h>
#include <string.h>

extern const sl_technique sl_tubes_mesh_technique;
extern const sl_technique sl_tubes_technique;
extern const sl_technique sl_voxel_lines_technique;
extern const sl_technique sl_lines_oit_technique;
extern const sl_technique sl_volume_dvr_technique;
extern const sl_technique sl_ribbons_technique;
extern const sl_technique sl_particles_technique;
extern const sl_technique sl_lr_volume_technique;

static const sl_technique *const techniques[] = {
    &sl_tubes_mesh_technique,
    &sl_tubes_technique,
    &sl_voxel_lines_technique,
    &sl_lines_oit_technique,
    &sl_volume_dvr_technique,
    &sl_ribbons_technique,
    &sl_particles_technique,
    &sl_lr_volume_technique,
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

int sl_technique_exports(const sl_technique *t)
{
    return t && t->export_geometry && t->export_ext && t->export_ext[0];
}

void sl_technique_exporters(char *list, size_t size)
{
    int listed = 0;
    list[0] = '\0';
    for (size_t i = 0; i < sizeof techniques / sizeof techniques[0]; i++) {
        if (!sl_technique_exports(techniques[i]))
            continue;
        size_t used = strlen(list);
        snprintf(list + used, size - used, "%s%s", listed++ ? ", " : "", techniques[i]->name);
    }
    if (!listed)
        snprintf(list, size, "none yet");
}
