/* prepared_cache.c — prepared technique state shared by the sessions that draw the same thing.
 *
 * A prepared scene is one sl_pipeline: a dataset, a technique and the
 * technique's prepared state (on llvmpipe its GPU buffers live in host
 * memory: tornado with tubes_mesh holds 165 MB). Sessions showing the same
 * dataset source with the same technique and parameters that agree up to
 * the frame level (sl_params_compare < SL_INVALIDATE_PREPARED) render
 * through one prepared scene, so N such sessions cost one prepare and one
 * copy; frame-level parameters (colormap, radius, ...) are handed to the
 * pipeline at every render (techniques re-sync what they cache from them;
 * a scene made for exactly a session's values is preferred, because a
 * technique may rebuild a cache in render when a frame-level value changes:
 * voxel_lines re-voxelizes for another `attribute`, so two sessions that
 * share its scene and render by turns with different attributes pay that
 * on every switch).
 * The pipeline's target follows the size of the frame it last rendered.
 * Reference-counted by the sessions holding it; the last release destroys
 * it (GL objects too). Render thread only (it owns every GL object), so no
 * lock. Does not load datasets (dataset_cache.c does).
 */
#include "sl_render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pipeline/sl_pipeline.h"

sl_prepared *sl_prepared_find(sl_prepared_cache *c, const char *source, const sl_technique *t,
                              const sl_params *params, const sl_dataset *ds)
{
    /* First a scene made for exactly these values, then one that differs at the frame level only. */
    for (int pass = 0; pass < 2; pass++)
        for (sl_prepared *p = c->list; p; p = p->next)
            if (p->technique == t && p->dataset == ds && strcmp(p->source, source) == 0 &&
                sl_params_compare(&p->key, params) <= (pass ? SL_INVALIDATE_FRAME : SL_INVALIDATE_NONE)) {
                p->refs++;
                return p;
            }
    return NULL;
}

sl_dataset *sl_prepared_dataset_of(sl_prepared_cache *c, const char *source)
{
    for (sl_prepared *p = c->list; p; p = p->next)
        if (strcmp(p->source, source) == 0)
            return sl_dataset_retain(p->dataset);
    return NULL;
}

sl_status sl_prepared_create(sl_prepared_cache *c, const char *source, sl_dataset *ds, const sl_technique *t,
                             const sl_params *params, sl_prepared **out, sl_err *err)
{
    *out = NULL;
    sl_prepared *p = calloc(1, sizeof *p);
    sl_status rc = p ? SL_OK : sl_err_set(err, SL_ERR_NOMEM, "out of memory for a prepared scene");
    if (rc == SL_OK && strlen(source) >= sizeof p->source)
        rc = sl_err_set(err, SL_ERR_LIMIT, "dataset source longer than %d bytes", SL_SOURCE_MAX - 1);
    if (rc == SL_OK)
        rc = sl_pipeline_create(c->gpu, &p->pipeline, err);
    if (rc != SL_OK) {
        free(p);
        sl_dataset_destroy(ds);
        return rc;
    }
    sl_pipeline_set_dataset(p->pipeline, ds);
    if ((rc = sl_pipeline_set_technique(p->pipeline, t, params, err)) != SL_OK) {
        sl_pipeline_destroy(p->pipeline);
        free(p);
        return rc;
    }
    snprintf(p->source, sizeof p->source, "%s", source);
    p->technique = t;
    p->key = *params;
    p->dataset = ds;
    p->refs = 1;
    p->next = c->list;
    c->list = p;
    c->count++;
    *out = p;
    return SL_OK;
}

void sl_prepared_release(sl_prepared_cache *c, sl_prepared *p)
{
    if (!p || --p->refs > 0)
        return;
    for (sl_prepared **pp = &c->list; *pp; pp = &(*pp)->next)
        if (*pp == p) {
            *pp = p->next;
            break;
        }
    c->count--;
    sl_pipeline_destroy(p->pipeline);
    free(p);
}
