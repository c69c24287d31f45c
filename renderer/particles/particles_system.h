/* particles_system.h — one particle set of `particles` on the GPU: feature
 * location, redistribution and the final curvature pass (the paper's sec.
 * 4.1 and 4.2.3; README.md "The particle system").
 *
 * pt_set_build places particles on the isosurface f = iso of the trilinear
 * field (Algorithm 1 on a lattice of `lattice_step` voxels; with the
 * field's min-max bricks only the lattice tiles of 4^3 points whose bricks
 * may straddle iso are dispatched, and the bins cover only those bricks:
 * the same particles, plan §1.1 "Skipping"), sorts them by
 * edge id (a deterministic order), runs up to max_steps energy steps
 * (keys -> sort by bin -> gather -> bin table -> energy step -> group sums
 * read back and added in double; stop when the relative energy change is
 * at most energy_tol), settles every particle back onto the surface
 * (Newton, then bisection along the gradient; one still farther than 0.01
 * voxel has lost its surface and is dropped), then sorts once more and
 * computes per particle the
 * B-spline normal, curvatures and nearest-neighbour distance. The result
 * is `records` (pt_record of particles_final.comp.glsl, alive first) and
 * the bin table of that last sort. Every phase ends with a glFinish so its
 * wall time is known (prepare is not interactive; llvmpipe's timer queries
 * miss work). Render thread only, GL context current.
 */
#ifndef PARTICLES_SYSTEM_H
#define PARTICLES_SYSTEM_H

#include <stddef.h>
#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_status.h"
#include "../volume/sl_volume.h"
#include "particles_sort.h"

/* The volume as the passes read it (a sl_volume_texture and its geometry). */
typedef struct pt_field {
    GLuint texture;               /* R8/R16/R32F, texel (i,j,k) = voxel (i,j,k) */
    float value_scale, value_offset;
    int dims[3];
    double spacing[3];            /* world units per voxel */
    double min_spacing;
    double value_min, value_max;  /* finite data range */
    const sl_volume_bricks *bricks; /* borrowed min-max bricks of the same volume; NULL: no skipping */
} pt_field;

typedef struct pt_system_desc {
    double iso;                   /* data units, inside (value_min, value_max) */
    double lattice_step;          /* voxels, > 0 */
    double sigma;                 /* repulsion radius, world units, > 0 */
    double energy_tol;            /* relative change that stops; 0: run max_steps */
    int max_steps;
    pt_sort_method sort;
    pt_lookup_method lookup;
    uint32_t max_particles;       /* seeds above: SL_ERR_LIMIT */
    int no_skipping;              /* 1: the whole lattice and bins over the whole volume box (same
                                   * particles, for checks and benchmarks) */
} pt_system_desc;

typedef struct pt_set_stats {
    uint32_t seeded;              /* Algorithm 1's crossings */
    uint32_t alive;               /* drawn and exported */
    uint32_t dropped;             /* seeded - alive: flat or non-finite field, surface lost */
    int steps;                    /* energy passes run */
    double first_energy, final_energy;
    double mean_nn, nn_cv;        /* nearest-neighbour distance (world) over alive particles with one */
    double placement_ms, id_sort_ms, sort_ms, lookup_ms, gather_ms, energy_ms, settle_ms, final_ms;
    double ms_per_step;           /* keys + sort + gather + table + energy + read-back, per step */
    uint32_t tiles, tiles_total;  /* lattice tiles of 4^3 points dispatched, of all */
} pt_set_stats;

typedef struct pt_set {
    GLuint records;               /* pt_record[count]; alive ones first */
    GLuint table;                 /* uint start[bins + 1] of the last sort */
    uint32_t count;               /* records held (alive + dead) */
    double bin_size;              /* world */
    int bin_origin[3];            /* first bin of the grid over the volume box (see choose_bins) */
    int bin_dims[3];
    uint32_t bins;
    pt_set_stats stats;
    size_t bytes;                 /* GPU memory held by records + table */
} pt_set;

typedef struct pt_system pt_system; /* programs and the sorter, shared by sets */

sl_status pt_system_create(pt_system **out, sl_err *err);
void pt_system_destroy(pt_system *sys); /* NULL is fine */

/* Builds one set. SL_ERR_LIMIT when the seeds exceed max_particles or the
 * lattice is too large for 32-bit edge ids; SL_ERR_GPU from GL errors;
 * SL_ERR_NOMEM. On failure *out is zeroed and holds nothing. An isovalue no
 * lattice edge crosses gives an empty set (count 0), not an error. */
sl_status pt_set_build(pt_system *sys, const pt_field *field, const pt_system_desc *d, pt_set *out, sl_err *err);
void pt_set_release(pt_set *set); /* zeroed is fine */

/* The record layout of the final pass (std430, 48 bytes). */
typedef struct pt_record {
    float x[3], alive;            /* local world (world - volume origin) */
    float n[3], k1;
    float e1[3], k2;
} pt_record;

#endif
