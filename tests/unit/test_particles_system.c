/* test_particles_system.c — the placement's brick skipping changes nothing
 * (docs/particles_plan.md §1.1 "Skipping"): pt_set_build with the min-max
 * bricks (only the lattice tiles that may hold a crossing dispatched, bins
 * over the surface's bricks) and with no_skipping (the whole lattice, bins
 * over the whole volume) gives the same seeds and byte-equal records after
 * redistribution, at an integer and a fractional lattice step, while the
 * skipping does skip tiles. Needs GL (llvmpipe in CI). Main thread.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "particles/particles_system.h"
#include "sl_test.h"
#include "volume/sl_volume.h"

typedef struct one_case { const char *json; double iso, step; } one_case;

static void check_case(pt_system *sys, const one_case *c)
{
    sl_err err = {0};
    sl_dataset *ds = NULL;
    sl_volume_texture tex = {0};
    sl_volume_bricks bricks = {0};
    sl_status st = sl_generate_json(c->json, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", c->json, err.message);
    if (st == SL_OK)
        st = sl_volume_texture_create(&ds->volume, &tex, &err);
    if (st == SL_OK)
        st = sl_volume_bricks_create(&ds->volume, &bricks, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    if (st != SL_OK) {
        sl_volume_texture_destroy(&tex);
        sl_dataset_destroy(ds);
        return;
    }
    sl_volume_geometry g;
    sl_volume_geometry_init(ds, &g);
    pt_field f = {.texture = tex.tex, .value_scale = tex.value_scale, .value_offset = tex.value_offset,
                  .min_spacing = g.min_spacing, .value_min = ds->volume.value_min,
                  .value_max = ds->volume.value_max, .bricks = &bricks};
    for (int a = 0; a < 3; a++) {
        f.dims[a] = ds->volume.dims[a];
        f.spacing[a] = ds->volume.spacing[a];
    }
    pt_set sets[2];
    pt_record *rec[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        pt_system_desc d = {.iso = c->iso, .lattice_step = c->step, .sigma = 1.6 * c->step * g.min_spacing,
                            .max_steps = 5, .max_particles = 1000000, .no_skipping = k};
        st = pt_set_build(sys, &f, &d, &sets[k], &err);
        SL_CHECK_MSG(st == SL_OK, "%s no_skipping %d: %s", c->json, k, err.message);
        if (st != SL_OK)
            memset(&sets[k], 0, sizeof sets[k]);
        size_t bytes = (size_t)sets[k].count * sizeof(pt_record);
        rec[k] = malloc(bytes ? bytes : 1);
        if (rec[k] && bytes)
            glGetNamedBufferSubData(sets[k].records, 0, (GLsizeiptr)bytes, rec[k]);
    }
    const pt_set_stats *a = &sets[0].stats, *b = &sets[1].stats;
    SL_CHECK_MSG(a->seeded == b->seeded && a->seeded > 0, "%s step %g: seeded %u skipping, %u whole lattice",
                 c->json, c->step, a->seeded, b->seeded);
    SL_CHECK_MSG(a->alive == b->alive, "%s: alive %u / %u", c->json, a->alive, b->alive);
    SL_CHECK_MSG(a->tiles < a->tiles_total && b->tiles == b->tiles_total, "%s: tiles %u of %u, whole %u of %u",
                 c->json, a->tiles, a->tiles_total, b->tiles, b->tiles_total);
    SL_CHECK_MSG(sets[0].bins <= sets[1].bins, "%s: bins %u > %u", c->json, sets[0].bins, sets[1].bins);
    SL_CHECK_MSG(sets[0].count == sets[1].count && rec[0] && rec[1] &&
                     memcmp(rec[0], rec[1], (size_t)sets[0].count * sizeof(pt_record)) == 0,
                 "%s step %g: the records differ", c->json, c->step);
    printf("%s step %g: %u seeds, tiles %u of %u, bins %u of %u\n", c->json, c->step, a->seeded, a->tiles,
           a->tiles_total, sets[0].bins, sets[1].bins);
    for (int k = 0; k < 2; k++) {
        free(rec[k]);
        pt_set_release(&sets[k]);
    }
    sl_volume_bricks_destroy(&bricks);
    sl_volume_texture_destroy(&tex);
    sl_dataset_destroy(ds);
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_particles_system: %s\n", err.message);
        return 1;
    }
    pt_system *sys = NULL;
    sl_status st = pt_system_create(&sys, &err);
    SL_CHECK_MSG(st == SL_OK, "pt_system_create: %s", err.message);
    static const one_case cases[] = {
        {"{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.5,\"b\":0.4,\"c\":0.3}", 0.5, 1.0},
        {"{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.5,\"b\":0.4,\"c\":0.3}", 0.5, 1.25},
        {"{\"generator\":\"torus\",\"size\":64,\"minor\":0.25,\"sphere\":0.01}", 0.0, 2.0},
    };
    for (size_t i = 0; st == SL_OK && i < sizeof cases / sizeof cases[0]; i++)
        check_case(sys, &cases[i]);
    SL_CHECK_MSG(sl_gl_check_errors("test", &err) == SL_OK, "%s", err.message);
    pt_system_destroy(sys);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
