/* sightline-voxel-quality — the accuracy tables of voxel_lines (Kanzler et al., Fig. 16).
 *
 * Voxelizes a generated or loaded line dataset at several grid resolutions
 * and face quantizations and prints three Markdown tables: mean Hausdorff
 * distance (in voxels of a 64-voxel grid), mean tangent deviation (degrees)
 * and the share of lines that fall onto another line of their voxel.
 * Work is in renderer/voxel_lines/voxel_quality.c; this is a thin main.
 * Usage: sightline-voxel-quality [--data JSON | --file PATH] [--grids 64,128,256,512]
 *        [--quants 4,8,16,32,64,128] [--curves N]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "voxel_lines/voxel_quality.h"

static int parse_list(const char *s, int *out, int max)
{
    int n = 0;
    while (*s && n < max) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 4096)
            return -1;
        out[n++] = (int)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return -1;
    }
    return *s ? -1 : n;
}

static void usage(void)
{
    fprintf(stderr, "usage: sightline-voxel-quality [--data GENERATOR_JSON | --file PATH]\n"
                    "       [--grids 64,128,256,512] [--quants 4,8,16,32,64,128] [--curves N (0 = all)]\n");
}

int main(int argc, char **argv)
{
    const char *data = "{\"generator\":\"tornado\",\"lines\":1000,\"seed\":1}";
    const char *file = NULL;
    int grids[8] = {64, 128, 256, 512}, ngrids = 4;
    int quants[SL_VOXEL_QUALITY_MAX_QUANT] = {4, 8, 16, 32, 64, 128}, nquants = 6;
    long curves = 200;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            usage();
            return 2;
        }
        if (strcmp(a, "--data") == 0) data = v;
        else if (strcmp(a, "--file") == 0) file = v;
        else if (strcmp(a, "--grids") == 0) ngrids = parse_list(v, grids, 8);
        else if (strcmp(a, "--quants") == 0) nquants = parse_list(v, quants, SL_VOXEL_QUALITY_MAX_QUANT);
        else if (strcmp(a, "--curves") == 0) curves = strtol(v, NULL, 10);
        else {
            usage();
            return 2;
        }
        i++;
        if (ngrids < 1 || nquants < 1 || curves < 0) {
            fprintf(stderr, "sightline-voxel-quality: bad value for %s: %s\n", a, v);
            return 2;
        }
    }
    sl_err err = {0};
    sl_dataset *ds = NULL;
    sl_status st = file ? sl_load_file(file, &ds, &err) : sl_generate_json(data, &ds, &err);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-voxel-quality: %s\n", err.message);
        return 1;
    }
    sl_voxel_quality (*q)[SL_VOXEL_QUALITY_MAX_QUANT] = calloc((size_t)ngrids, sizeof *q);
    if (!q) {
        sl_dataset_destroy(ds);
        return 1;
    }
    for (int g = 0; g < ngrids; g++) {
        st = sl_voxel_quality_measure(ds, grids[g], quants, nquants, (size_t)curves, q[g], &err);
        if (st != SL_OK) {
            fprintf(stderr, "sightline-voxel-quality: grid %d: %s\n", grids[g], err.message);
            free(q);
            sl_dataset_destroy(ds);
            return 1;
        }
    }
    printf("Dataset: %s (%zu lines, %zu vertices); distances over %zu sampled curves, duplicates over all.\n\n",
           file ? file : data, ds->lines.line_count, ds->lines.vertex_count, q[0][0].curves);
    const char *titles[3] = {"Mean Hausdorff distance (voxels of a 64^3 grid)", "Mean tangent deviation (degrees)",
                             "Duplicate lines after quantization (% of encoded lines)"};
    for (int t = 0; t < 3; t++) {
        printf("%s\n\n| grid |", titles[t]);
        for (int k = 0; k < nquants; k++)
            printf(" N=%d |", quants[k]);
        printf("\n|---|");
        for (int k = 0; k < nquants; k++)
            printf("---|");
        printf("\n");
        for (int g = 0; g < ngrids; g++) {
            printf("| %d^3 |", grids[g]);
            for (int k = 0; k < nquants; k++) {
                const sl_voxel_quality *x = &q[g][k];
                if (t == 0) printf(" %.4f |", x->hausdorff_mean);
                else if (t == 1) printf(" %.2f |", x->tangent_deg_mean);
                else printf(" %.3f |", 100.0 * x->duplicate_share);
            }
            printf("\n");
        }
        printf("\n");
    }
    free(q);
    sl_dataset_destroy(ds);
    return 0;
}
