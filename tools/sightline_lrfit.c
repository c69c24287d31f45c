/* sightline-lrfit — fits an adaptive LR-spline volume to a regular scalar
 * volume or vector field and writes it in the LRsplines text format (issue
 * 15). The work is in renderer/lrspline (lr_fit.c, lr_refine.c,
 * lr_write.c); this is a thin main.
 * Usage: sightline-lrfit VOLUME --out F.lr[.gz] [--degree 2] [--tol E]
 *        [--max-levels L] [--max-basis N] [--cells N] [--fraction F]
 *        [--stride S] [--max-iterations N] [--cg-iterations N] [--cg-tol T]
 *        [--strategy structured|minimal-span]
 * VOLUME: anything sl_dataset_open accepts that is a scalar volume or vector
 * field (a file such as data/samples/ch2.nii.gz, a built-in, generator
 * JSON), or field:abc[:N] / field:tornado[:N], the analytic fields sampled
 * on N^3 voxels (default 64). Exit 0 on success, 1 on failure, 2 on a bad
 * command line.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset_open.h"
#include "data/sl_lr_fit_dataset.h"
#include "lrspline/sl_lr_write.h"

static void usage(void)
{
    fprintf(stderr, "usage: sightline-lrfit VOLUME --out F.lr[.gz] [--degree 1..3] [--tol E] [--max-levels L]\n"
                    "       [--max-basis N] [--cells N] [--fraction F] [--stride S] [--max-iterations N]\n"
                    "       [--cg-iterations N] [--cg-tol T] [--strategy structured|minimal-span]\n"
                    "VOLUME: a scalar volume or vector field sl_dataset_open accepts, or field:abc[:N] /\n"
                    "        field:tornado[:N] (analytic fields on N^3 voxels, default 64)\n");
}

static int parse_long(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi)
        return 0;
    *out = v;
    return 1;
}

static int parse_double(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v >= lo && v <= hi))
        return 0;
    *out = v;
    return 1;
}

int main(int argc, char **argv)
{
    sl_lr_fit_params p;
    sl_lr_fit_defaults(&p);
    p.log = stdout;
    const char *source = NULL, *out_path = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (a[0] != '-' || a[1] != '-') {
            if (source) {
                fprintf(stderr, "sightline-lrfit: more than one VOLUME ('%s' and '%s')\n", source, a);
                usage();
                return 2;
            }
            source = a;
            continue;
        }
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            fprintf(stderr, "sightline-lrfit: %s needs a value\n", a);
            usage();
            return 2;
        }
        i++;
        long l = 0;
        int ok = 1;
        if (strcmp(a, "--out") == 0) out_path = v;
        else if (strcmp(a, "--degree") == 0) { ok = parse_long(v, 1, 3, &l); p.degree = (int)l; }
        else if (strcmp(a, "--tol") == 0) ok = parse_double(v, 0.0, 1e300, &p.tol);
        else if (strcmp(a, "--max-levels") == 0) { ok = parse_long(v, 0, 16, &l); p.max_levels = (int)l; }
        else if (strcmp(a, "--max-basis") == 0) { ok = parse_long(v, 1, 8L * 1024 * 1024, &l); p.max_basis = (size_t)l; }
        else if (strcmp(a, "--cells") == 0) { ok = parse_long(v, 1, 1024, &l); p.cells_longest = (int)l; }
        else if (strcmp(a, "--fraction") == 0) ok = parse_double(v, 1e-9, 1.0, &p.fraction);
        else if (strcmp(a, "--stride") == 0) { ok = parse_long(v, 1, 1024, &l); p.stride = (int)l; }
        else if (strcmp(a, "--max-iterations") == 0) { ok = parse_long(v, 0, 100000, &l); p.max_iterations = (int)l; }
        else if (strcmp(a, "--strategy") == 0) {
            ok = strcmp(v, "structured") == 0 || strcmp(v, "minimal-span") == 0;
            p.strategy = strcmp(v, "minimal-span") == 0 ? SL_LR_FIT_MINIMAL_SPAN : SL_LR_FIT_STRUCTURED;
        } else if (strcmp(a, "--cg-tol") == 0) ok = parse_double(v, 1e-300, 0.5, &p.cg_tol);
        else if (strcmp(a, "--cg-iterations") == 0) { ok = parse_long(v, 1, 100000, &l); p.cg_iterations = (int)l; }
        else {
            fprintf(stderr, "sightline-lrfit: unknown option %s\n", a);
            usage();
            return 2;
        }
        if (!ok) {
            fprintf(stderr, "sightline-lrfit: bad value for %s: %s\n", a, v);
            usage();
            return 2;
        }
    }
    if (!source || !out_path) {
        fprintf(stderr, "sightline-lrfit: %s\n", !source ? "no VOLUME given" : "no --out file given");
        usage();
        return 2;
    }
    sl_err err = {0};
    sl_dataset *ds = NULL;
    sl_status st;
    if (strncmp(source, "field:", 6) == 0) {
        char name[32];
        long n = 64;
        const char *colon = strchr(source + 6, ':');
        size_t len = colon ? (size_t)(colon - source - 6) : strlen(source + 6);
        if (len >= sizeof name || (colon && !parse_long(colon + 1, 2, 512, &n))) {
            fprintf(stderr, "sightline-lrfit: bad field source '%s' (field:abc[:N] or field:tornado[:N],"
                            " N in 2..512)\n", source);
            return 2;
        }
        memcpy(name, source + 6, len);
        name[len] = 0;
        st = sl_lr_sample_field(name, (int)n, &ds, &err);
    } else {
        st = sl_dataset_open(source, NULL, &ds, &err);
    }
    if (st != SL_OK) {
        fprintf(stderr, "sightline-lrfit: %s\n", err.message);
        return 1;
    }
    if (ds->kind != SL_DATASET_VOLUME && ds->kind != SL_DATASET_VECTORS) {
        fprintf(stderr, "sightline-lrfit: %s is a %s dataset, not a scalar volume or vector field\n", source,
                sl_dataset_kind_name(ds->kind));
        sl_dataset_destroy(ds);
        return 1;
    }
    printf("%s: %d x %d x %d voxels, %d component(s), value range [%g, %g]\n", source, ds->volume.dims[0],
           ds->volume.dims[1], ds->volume.dims[2], ds->volume.components, ds->volume.value_min,
           ds->volume.value_max);
    sl_lr_volume lr;
    sl_lr_fit_stats s;
    st = sl_lr_fit(ds, &p, &lr, &s, &err);
    sl_dataset_destroy(ds);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-lrfit: %s\n", err.message);
        return 1;
    }
    const char *why = s.max_error <= p.tol  ? "tolerance reached"
                      : s.cap_hit           ? "basis-function cap reached (--max-basis)"
                      : s.levels_exhausted  ? "nothing above the tolerance can be refined (its spans are at --max-levels"
                                              " or at two sample spacings)"
                                            : "iteration limit reached";
    printf("final: %zu elements, %zu basis functions, %d levels (level ratio %g), %zu samples, max error %.6g,"
           " mean error %.6g, %d iterations, %.2f s: %s\n", s.elements, s.basis, s.levels, sl_lr_level_ratio(&lr),
           s.samples, s.max_error, s.mean_error, s.iterations, s.seconds, why);
    st = sl_lr_write_file(&lr, out_path, &err);
    sl_lr_free(&lr);
    if (st != SL_OK) {
        fprintf(stderr, "sightline-lrfit: %s\n", err.message);
        return 1;
    }
    printf("wrote %s\n", out_path);
    return 0;
}
