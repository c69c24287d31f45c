/* voxel_lines.h — work counters of the `voxel_lines` technique (voxel_lines.c).
 *
 * The technique itself is reached through sl_technique (core/sl_technique.h);
 * this header only lets tests and benchmarks see which preprocessing a frame
 * caused, since sl_render_stats has no field for it: voxelizations (prepare,
 * a changed colour attribute, a radius needing more padding), density passes
 * (the transfer-function-weighted density and its mips), AO passes and the
 * frames the cpu backend cast.
 * Process-wide totals over every voxel_lines instance, never reset; compare
 * two readings. Render thread only (the counters are updated there, unlocked).
 * Does not count frames or time anything.
 */
#ifndef SL_VOXEL_LINES_H
#define SL_VOXEL_LINES_H

typedef struct sl_voxel_lines_counters {
    unsigned long builds;          /* grid built and uploaded */
    unsigned long density_passes;  /* density level 0 recomputed (+ mip chain) */
    unsigned long ao_passes;       /* ambient occlusion recomputed */
    unsigned long cpu_frames;      /* frames cast by the cpu backend (voxel_cast_cpu.c) */
} sl_voxel_lines_counters;

void sl_voxel_lines_get_counters(sl_voxel_lines_counters *out);

#endif
