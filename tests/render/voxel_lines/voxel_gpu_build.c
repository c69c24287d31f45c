/* voxel_gpu_build.c — the compute-shader voxelization equals the CPU one (render test).
 *
 * On llvmpipe (EGL surfaceless; never skipped): for generated tornado and
 * bundle data at several grids and quantizations, and with a low per-voxel
 * cap, sl_voxel_grid_build_gpu and sl_voxel_grid_build must give identical
 * headers (offsets, counts), identical bit-packed line bytes in the same
 * order (so the same encoded lines per voxel), the same overflow counts, and
 * densities within 1e-4 (float sums in the same order) — without a colour
 * attribute and with one (tornado `speed`, bundle `curvature` and `radial`):
 * the attribute bytes must be equal too (and are checked to vary, so the
 * comparison is not vacuous). Last, tornado's speed is made hostile (NaN,
 * ±inf, values far outside the stored range) and a constant attribute is
 * added; both builds must still agree. Dispatch chunking: the same
 * comparisons with at most 7 (or 1) work groups per dispatch (every pass and
 * scan then runs in many chunks, with a partial last one), and one grid above
 * the real 1-D limit: tornado at grid 184 has 4.3 M voxels, more than
 * llvmpipe's 65535 groups x 64 invocations of one dispatch of the per-voxel
 * pass (before chunking that build silently lacked its last pass). Render
 * thread = main.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "sl_test.h"
#include "voxel_lines/voxel_gpu.h"

/* min_distinct: the least number of distinct attribute bytes the build must
 * hold (0 = no check; 1 with the attribute off, where every byte is 0). */
static void compare_chunked(const sl_dataset *ds, int resolution, int quant, int cap, int attribute,
                            int min_distinct, unsigned max_groups)
{
    sl_err err = {0};
    sl_voxel_grid_desc desc = {.resolution = resolution, .quant = quant, .padding = 1, .max_per_voxel = cap,
                               .attribute = attribute};
    sl_voxel_grid a, b;
    sl_status sa = sl_voxel_grid_build(&a, ds, &desc, &err);
    SL_CHECK_MSG(sa == SL_OK, "cpu: %s", err.message);
    sl_status sb = sl_voxel_grid_build_gpu_chunked(&b, ds, &desc, max_groups, &err);
    SL_CHECK_MSG(sb == SL_OK, "gpu: %s", err.message);
    if (sa != SL_OK || sb != SL_OK) {
        sl_voxel_grid_deinit(&a);
        sl_voxel_grid_deinit(&b);
        return;
    }
    SL_CHECK(a.voxel_count == b.voxel_count && a.line_count == b.line_count);
    SL_CHECK(a.dropped_overflow == b.dropped_overflow && a.capped_voxels == b.capped_voxels);
    SL_CHECK(a.max_count == b.max_count && a.pieces == b.pieces);
    SL_CHECK(a.attribute_index == b.attribute_index);
    if (a.voxel_count == b.voxel_count && a.line_count == b.line_count) {
        SL_CHECK(memcmp(a.offsets, b.offsets, a.voxel_count * sizeof *a.offsets) == 0);
        SL_CHECK(memcmp(a.counts, b.counts, a.voxel_count) == 0);
        SL_CHECK(memcmp(a.lines, b.lines, a.line_count * (size_t)a.line_bytes) == 0);
        size_t differ = 0, attr_differ = 0;
        int seen[256] = {0}, distinct = 0;
        for (size_t i = 0; i < a.line_count; i++) {
            uint64_t ca = sl_voxel_grid_line(&a, i), cb = sl_voxel_grid_line(&b, i);
            sl_voxel_line la, lb;
            sl_voxel_decode_line(a.quant_bits, ca, &la);
            sl_voxel_decode_line(b.quant_bits, cb, &lb);
            if (ca != cb && differ++ < 3)
                fprintf(stderr, "line %zu: cpu faces %d %d bins %u %u attr %u id %u, "
                                "gpu faces %d %d bins %u %u attr %u id %u\n", i, la.face_a, la.face_b, la.bin_a,
                        la.bin_b, la.attr, la.id, lb.face_a, lb.face_b, lb.bin_a, lb.bin_b, lb.attr, lb.id);
            attr_differ += la.attr != lb.attr;
            distinct += !seen[la.attr]++;
        }
        SL_CHECK_MSG(differ == 0, "grid %d N %d attribute %d: %zu of %zu lines differ (%zu in the attribute byte)",
                     resolution, quant, attribute, differ, a.line_count, attr_differ);
        if (min_distinct > 0)
            SL_CHECK_MSG(attribute < 0 ? distinct == 1 && seen[0] : distinct >= min_distinct,
                         "grid %d N %d attribute %d: %d distinct attribute bytes, want %s %d", resolution, quant,
                         attribute, distinct, attribute < 0 ? "only 0," : ">=", min_distinct);
        double dmax = 0.0;
        for (size_t v = 0; v < a.voxel_count; v++)
            dmax = fmax(dmax, fabs((double)a.density[v] - b.density[v]));
        SL_CHECK_NEAR(dmax, 0.0, 1e-4);
    }
    printf("grid %d N %d cap %d attribute %d groups/dispatch %u: %zu voxels, %zu lines, cpu %.1f ms, gpu %.1f ms\n",
           resolution, quant, cap, attribute, max_groups, a.voxel_count, a.line_count, a.build_ms, b.build_ms);
    sl_voxel_grid_deinit(&a);
    sl_voxel_grid_deinit(&b);
}

static void compare(const sl_dataset *ds, int resolution, int quant, int cap, int attribute, int min_distinct)
{
    compare_chunked(ds, resolution, quant, cap, attribute, min_distinct, 0);
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
    /* Attribute byte position (bits 2 (3 + 2k) .. + 8): N = 4 low word, N = 32
     * across the word boundary, N = 128 and 256 high word. */
    if (tornado) {
        int speed = sl_lines_find_attribute(&tornado->lines, "speed");
        SL_CHECK(speed >= 0);
        compare(tornado, 32, 4, 255, -1, 1);
        compare(tornado, 64, 32, 255, -1, 1);
        compare(tornado, 48, 256, 255, -1, 0);
        compare(tornado, 16, 16, 20, -1, 0); /* dense: the cap applies */
        compare(tornado, 32, 4, 255, speed, 100);
        compare(tornado, 64, 32, 255, speed, 100);
        compare(tornado, 48, 256, 255, speed, 100);
        compare(tornado, 16, 16, 20, speed, 50);
        /* Chunked dispatches (a test-only small limit) give the same grid. */
        compare_chunked(tornado, 64, 32, 255, speed, 100, 7);
        compare_chunked(tornado, 16, 16, 20, speed, 50, 1);
        /* Above the real limit: tornado at grid 184 has 4.3 M voxels (186 x
         * 153 x 151 with padding), more than 65535 groups of 64 for the
         * per-voxel pass on a driver at the GL minimum (llvmpipe). */
        GLint limit = 0;
        glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &limit);
        sl_voxel_frame big;
        SL_CHECK(sl_voxel_frame_init(&big, tornado, 184, 1, &err) == SL_OK);
        size_t big_groups = ((size_t)big.dims[0] * big.dims[1] * big.dims[2] + 63) / 64;
        SL_CHECK_MSG(limit > 65535 || big_groups > (size_t)limit, "grid 184: %zu groups, limit %d", big_groups,
                     limit);
        compare(tornado, 184, 4, 255, -1, 1);
    }
    if (bundle) {
        compare(bundle, 64, 128, 255, -1, 1);
        compare(bundle, 64, 128, 255, sl_lines_find_attribute(&bundle->lines, "curvature"), 50);
        compare(bundle, 32, 32, 255, sl_lines_find_attribute(&bundle->lines, "radial"), 200);
    }
    if (tornado) {
        /* Hostile values: non-finite ones give 0 before interpolation, values
         * outside the stored range are clamped after averaging. The stored
         * min/max stay as generated. A constant (all-zero) attribute: byte 0. */
        sl_attribute *at = &tornado->lines.attributes[sl_lines_find_attribute(&tornado->lines, "speed")];
        for (size_t v = 0; v < tornado->lines.vertex_count; v++) {
            if (v % 97 == 0) at->values[v] = NAN;
            else if (v % 89 == 0) at->values[v] = INFINITY;
            else if (v % 83 == 0) at->values[v] = -INFINITY;
            else if (v % 79 == 0) at->values[v] = -1e30f;
            else if (v % 73 == 0) at->values[v] = 10.0f * at->max;
        }
        compare(tornado, 64, 32, 255, (int)(at - tornado->lines.attributes), 100);
        int zero = -1;
        if (sl_lines_add_attribute(&tornado->lines, "zero", 0, &err)) {
            zero = tornado->lines.attribute_count - 1;
            compare(tornado, 32, 16, 255, zero, 0);
        }
        SL_CHECK(zero >= 0);
    }
    sl_dataset_destroy(tornado);
    sl_dataset_destroy(bundle);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
