/* gen_lr_field.c — LR-spline volumes (dataset kind lr_volume) built with
 * sl_lr_tensor_product, for lr_volume's tests and scenes without a file.
 *
 * Domain [-1, 1]^3. Knots per direction: degree + 1 copies of -1 and of 1,
 * inner knots -1 + 2 s(i / cells), i = 1..cells-1, s(u) = u + grading
 * sin(2 pi u) / (2 pi) (strictly increasing for grading < 1: elements whose
 * sides vary by up to (1 + grading) / (1 - grading), so the adaptive step of
 * lr_volume has something to adapt to). Fields, sampled at the basis
 * functions' Greville points (a quasi-interpolant, not an interpolant):
 *   sphere:         f = 1 - |p|;
 *   marschner_lobb: the Marschner-Lobb signal (fM 6, alpha 0.25; see
 *                   gen_marschner_lobb.c);
 *   trilinear_ml:   degree 1, grading 0: knots at the voxel centres of
 *                   {"generator":"marschner_lobb","size":cells+1} and its f32
 *                   voxel values as coefficients, so the spline IS that
 *                   volume's trilinear interpolant (what volume_dvr samples).
 * components "vector": f (1, x, y) (rendered by magnitude). No randomness,
 * no seed. Any thread.
 */
#include "gen_family.h"
#include "sl_generate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../lrspline/sl_lr.h"

#define LR_PI 3.141592653589793

enum { K_FIELD, K_DEGREE, K_CELLS, K_GRADING, K_COMPONENTS };
enum { F_SPHERE, F_ML, F_TRILINEAR_ML };

typedef struct field_ctx {
    int field, dim;
    const sl_volume *ml;     /* F_TRILINEAR_ML: the voxels */
} field_ctx;

static double ml_value(const double p[3])
{
    double r = sqrt(p[0] * p[0] + p[1] * p[1]);
    double rho = cos(2.0 * LR_PI * 6.0 * cos(LR_PI * r / 2.0));
    return (1.0 - sin(LR_PI * p[2] / 2.0) + 0.25 * (1.0 + rho)) / (2.0 * 1.25);
}

static void field_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    const field_ctx *c = user;
    double f;
    if (c->field == F_TRILINEAR_ML)
        f = sl_volume_value(c->ml, (size_t)ijk[0], (size_t)ijk[1], (size_t)ijk[2], 0);
    else if (c->field == F_ML)
        f = ml_value(g);
    else
        f = 1.0 - sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    coef[0] = f;
    if (c->dim == 3) {
        coef[1] = f * g[0];
        coef[2] = f * g[1];
    }
}

static sl_status lr_field_generate(const double *values, sl_dataset **out, sl_err *err)
{
    int field = (int)values[K_FIELD], degree = (int)values[K_DEGREE], cells = (int)values[K_CELLS];
    double grading = values[K_GRADING];
    int dim = values[K_COMPONENTS] == 1 ? 3 : 1;
    if (field == F_TRILINEAR_ML && (degree != 1 || grading != 0.0 || cells < 7))
        return sl_err_set(err, SL_ERR_INVALID, "lr_field: trilinear_ml needs degree 1, grading 0 and cells >= 7"
                          " (the marschner_lobb volume of cells + 1 voxels)");
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LR, "lr_field");
    sl_dataset *ml = NULL;
    double *knots = NULL;
    if (!ds || !(ds->lr = calloc(1, sizeof *ds->lr)) || !(knots = malloc(sizeof(double) * (size_t)(cells + 9)))) {
        sl_dataset_destroy(ds);
        free(knots);
        return sl_err_set(err, SL_ERR_NOMEM, "lr_field: out of memory");
    }
    field_ctx ctx = {field, dim, NULL};
    sl_status st = SL_OK;
    int n = 0;
    if (field == F_TRILINEAR_ML) {
        char call[96];
        snprintf(call, sizeof call, "{\"generator\":\"marschner_lobb\",\"size\":%d}", cells + 1);
        st = sl_generate_json(call, &ml, err);
        if (st == SL_OK) {
            ctx.ml = &ml->volume;
            double step = ml->volume.spacing[0];
            knots[n++] = -1.0;
            for (int i = 0; i <= cells; i++)
                knots[n++] = -1.0 + step * (double)i; /* as gen_marschner_lobb.c places voxels */
            knots[n] = knots[n - 1];
            n++;
        }
    } else {
        for (int i = 0; i <= degree; i++)
            knots[n++] = -1.0;
        for (int i = 1; i < cells; i++) {
            double u = (double)i / cells;
            knots[n++] = -1.0 + 2.0 * (u + grading * sin(2.0 * LR_PI * u) / (2.0 * LR_PI));
        }
        for (int i = 0; i <= degree; i++)
            knots[n++] = 1.0;
    }
    if (st == SL_OK) {
        const int order[3] = {degree + 1, degree + 1, degree + 1};
        const double *const k3[3] = {knots, knots, knots};
        const int count[3] = {n, n, n};
        st = sl_lr_tensor_product(ds->lr, order, dim, k3, count, field_coef, &ctx, err);
        if (st == SL_OK)
            st = sl_lr_index(ds->lr, err);
    }
    sl_dataset_destroy(ml);
    free(knots);
    if (st != SL_OK) {
        sl_err_prefix(err, "lr_field");
        sl_dataset_destroy(ds);
        return st;
    }
    ds->origin = sl_v3(0.0, 0.0, 0.0);
    ds->bounds_min = sl_v3(ds->lr->domain_lo[0], ds->lr->domain_lo[1], ds->lr->domain_lo[2]);
    ds->bounds_max = sl_v3(ds->lr->domain_hi[0], ds->lr->domain_hi[1], ds->lr->domain_hi[2]);
    *out = ds;
    return SL_OK;
}

const sl_gen_family sl_gen_lr_field = {
    .name = "lr_field",
    .kind = SL_DATASET_LR,
    .description = "LR-spline volume on [-1, 1]^3 from a tensor product: sphere 1 - |p|, the Marschner-Lobb "
                   "signal, or trilinear_ml (exactly the trilinear interpolant of the marschner_lobb volume)",
    .keys_help = "field (\"sphere\" default, \"marschner_lobb\", \"trilinear_ml\": degree 1, cells + 1 voxels), "
                 "degree (0..3, default 2), cells per direction (1..128, default 16), grading of the element "
                 "sizes (0..0.9, default 0), components (\"scalar\" default, \"vector\")",
    .key_count = 5,
    .keys = {
        {.name = "field", .type = SL_GEN_CHOICE, .def = 0, .choices = {"sphere", "marschner_lobb", "trilinear_ml"}},
        {.name = "degree", .type = SL_GEN_INT, .min = 0, .max = 3, .def = 2},
        {.name = "cells", .type = SL_GEN_INT, .min = 1, .max = 128, .def = 16},
        {.name = "grading", .type = SL_GEN_NUMBER, .min = 0, .max = 0.9, .def = 0},
        {.name = "components", .type = SL_GEN_CHOICE, .def = 0, .choices = {"scalar", "vector"}},
    },
    .generate = lr_field_generate,
};
