/* lr_test_text.h — test-only: the LRsplines text of a tensor-product volume,
 * laid out as the reference writer (LR::LRSplineVolume::write) lays it out,
 * for the loader and probe tests (test_load_lr.c, test_probe.c).
 *
 * Built from global open knot vectors the way a reader of the format would
 * by hand (basis (i,j,k) on knots t[i..i+order], i fastest; one element per
 * non-empty cell listing the order^3 functions over it; one mesh rectangle
 * per distinct knot value), independent of renderer/lrspline/lr_tensor.c.
 * Not the library's writer (sightline-lrfit owns that). Single thread.
 */
#ifndef SL_LR_TEST_TEXT_H
#define SL_LR_TEST_TEXT_H

#include <stdio.h>
#include <stdlib.h>

/* Coefficient(s) of basis (i, j, k), like sl_lr_coef_fn. */
typedef void (*lr_text_coef_fn)(void *user, const int ijk[3], const double g[3], double *coef);

/* Returns a malloc'd NUL-terminated text (caller frees); NULL on failure. */
static inline char *lr_text_tensor(const int order[3], int dim, const double *const knots[3], const int count[3],
                                   lr_text_coef_fn coef, void *user)
{
    size_t cap = 1u << 20, n = 0;
    char *s = malloc(cap);
    if (!s)
        return NULL;
#define LR_PUT(...)                                                                  \
    do {                                                                             \
        int w_ = snprintf(s + n, cap - n, __VA_ARGS__);                              \
        if (w_ < 0 || (size_t)w_ >= cap - n) {                                       \
            char *t_ = realloc(s, cap *= 4);                                         \
            if (!t_) {                                                               \
                free(s);                                                             \
                return NULL;                                                         \
            }                                                                        \
            s = t_;                                                                  \
            w_ = snprintf(s + n, cap - n, __VA_ARGS__);                              \
        }                                                                            \
        n += (size_t)w_;                                                             \
    } while (0)
    int nb[3], ncells = 1, nrects = 0;
    int span[3][64], nspan[3];
    for (int d = 0; d < 3; d++) {
        nb[d] = count[d] - order[d];
        nspan[d] = 0;
        for (int s2 = 0; s2 + 1 < count[d]; s2++)
            if (knots[d][s2] < knots[d][s2 + 1])
                span[d][nspan[d]++] = s2;
        ncells *= nspan[d];
        nrects += nspan[d] + 1;
    }
    LR_PUT("# LRSPLINE VOLUME\n#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat\n\t%d\t%d\t%d\t%d\t%d\t%d\t%d\t0\n",
           order[0], order[1], order[2], nb[0] * nb[1] * nb[2], nrects, ncells, dim);
    LR_PUT("# Basis functions:\n");
    for (int k = 0; k < nb[2]; k++)
        for (int j = 0; j < nb[1]; j++)
            for (int i = 0; i < nb[0]; i++) {
                int ijk[3] = {i, j, k};
                double g[3], c[3] = {0, 0, 0};
                LR_PUT("%d: ", (k * nb[1] + j) * nb[0] + i);
                for (int d = 0; d < 3; d++) {
                    g[d] = 0;
                    LR_PUT("%s[", d ? "x " : "");
                    for (int q = 0; q <= order[d]; q++) {
                        LR_PUT("%.17g ", knots[d][ijk[d] + q]);
                        if (q > 0 && q < order[d])
                            g[d] += knots[d][ijk[d] + q] / (order[d] - 1);
                    }
                    if (order[d] == 1)
                        g[d] = 0.5 * (knots[d][ijk[d]] + knots[d][ijk[d] + 1]);
                    LR_PUT("] ");
                }
                coef(user, ijk, g, c);
                for (int q = 0; q < dim; q++)
                    LR_PUT("%.17g ", c[q]);
                LR_PUT("(1)\n");
            }
    LR_PUT("# Mesh rectangles:\n");
    for (int d = 0; d < 3; d++) {
        const double *t = knots[d];
        for (int a = 0; a < count[d]; a++) {
            if (a > 0 && t[a] == t[a - 1])
                continue;
            int mult = 0;
            for (int b = 0; b < count[d]; b++)
                mult += t[b] == t[a];
            double lo[3], hi[3];
            for (int e = 0; e < 3; e++) {
                lo[e] = knots[e][0];
                hi[e] = knots[e][count[e] - 1];
            }
            lo[d] = hi[d] = t[a];
            LR_PUT("[%.17g, %.17g] x [%.17g, %.17g] x [%.17g, %.17g] (%d)\n", lo[0], hi[0], lo[1], hi[1], lo[2], hi[2],
                   mult);
        }
    }
    LR_PUT("# Elements:\n");
    int id = 0;
    for (int c = 0; c < nspan[2]; c++)
        for (int b = 0; b < nspan[1]; b++)
            for (int a = 0; a < nspan[0]; a++) {
                int s3[3] = {span[0][a], span[1][b], span[2][c]};
                LR_PUT("%d [3] : (%.17g, %.17g, %.17g) x (%.17g, %.17g, %.17g)    {", id++, knots[0][s3[0]],
                       knots[1][s3[1]], knots[2][s3[2]], knots[0][s3[0] + 1], knots[1][s3[1] + 1],
                       knots[2][s3[2] + 1]);
                int first = 1;
                for (int k = s3[2] - order[2] + 1; k <= s3[2]; k++)
                    for (int j = s3[1] - order[1] + 1; j <= s3[1]; j++)
                        for (int i = s3[0] - order[0] + 1; i <= s3[0]; i++) {
                            LR_PUT("%s%d", first ? "" : ", ", (k * nb[1] + j) * nb[0] + i);
                            first = 0;
                        }
                LR_PUT("}\n");
            }
#undef LR_PUT
    return s;
}

#endif
