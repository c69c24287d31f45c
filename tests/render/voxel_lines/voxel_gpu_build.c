/* voxel_gpu_build.c — the compute-shader voxelization equals the CPU one (render test).
 *
 * On llvmpipe (EGL surfaceless; never skipped): for generated tornado and
 * bundle data at several grids and quantizations, and with a low per-voxel
 * cap, sl_voxel_grid_build_gpu and sl_voxel_grid_build (attribute off) must
 * give identical headers (offsets, counts), identical bit-packed line bytes
 * in the same order, the same overflow counts, and densities within 1e-4
 * (float sums in the same order). Render thread = main.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "sl_test.h"
#include "voxel_lines/voxel_gpu.h"

static void compare(const sl_dataset *ds, int resolution, int quant, int cap)
{
    sl_err err = {0};
    sl_voxel_grid_desc desc = {.resolution = resolution, .quant = quant, .padding = 1, .max_per_voxel = cap,
                               .attribute = -1};
    sl_voxel_grid a, b;
    sl_status sa = sl_voxel_grid_build(&a, ds, &desc, &err);
    SL_CHECK_MSG(sa == SL_OK, "cpu: %s", err.message);
    sl_status sb = sl_voxel_grid_build_gpu(&b, ds, &desc, &err);
    SL_CHECK_MSG(sb == SL_OK, "gpu: %s", err.message);
    if (sa != SL_OK || sb != SL_OK) {
        sl_voxel_grid_deinit(&a);
        sl_voxel_grid_deinit(&b);
        return;
    }
    SL_CHECK(a.voxel_count == b.voxel_count && a.line_count == b.line_count);
    SL_CHECK(a.dropped_overflow == b.dropped_overflow && a.capped_voxels == b.capped_voxels);
    SL_CHECK(a.max_count == b.max_count && a.pieces == b.pieces);
    if (a.voxel_count == b.voxel_count && a.line_count == b.line_count) {
        SL_CHECK(memcmp(a.offsets, b.offsets, a.voxel_count * sizeof *a.offsets) == 0);
        SL_CHECK(memcmp(a.counts, b.counts, a.voxel_count) == 0);
        size_t differ = 0;
        for (size_t i = 0; i < a.line_count; i++)
            differ += sl_voxel_grid_line(&a, i) != sl_voxel_grid_line(&b, i);
        SL_CHECK_MSG(differ == 0, "grid %d N %d: %zu of %zu lines differ", resolution, quant, differ, a.line_count);
        double dmax = 0.0;
        for (size_t v = 0; v < a.voxel_count; v++)
            dmax = fmax(dmax, fabs((double)a.density[v] - b.density[v]));
        SL_CHECK_NEAR(dmax, 0.0, 1e-4);
    }
    printf("grid %d N %d cap %d: %zu lines, cpu %.1f ms, gpu %.1f ms\n", resolution, quant, cap, a.line_count,
           a.build_ms, b.build_ms);
    sl_voxel_grid_deinit(&a);
    sl_voxel_grid_deinit(&b);
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "GPU: %s\n", err.message);
        return 1;
    }
    sl_dataset *tornado = NULL, *bundle = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":200,\"seed\":2}", &tornado, &err) == SL_OK);
    SL_CHECK(sl_generate_json("{\"generator\":\"bundle\",\"seed\":4}", &bundle, &err) == SL_OK);
    if (tornado) {
        compare(tornado, 32, 4, 255);
        compare(tornado, 64, 32, 255);
        compare(tornado, 48, 256, 255);
        compare(tornado, 16, 16, 20); /* dense: the cap applies */
    }
    if (bundle)
        compare(bundle, 64, 128, 255);
    sl_dataset_destroy(tornado);
    sl_dataset_destroy(bundle);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
