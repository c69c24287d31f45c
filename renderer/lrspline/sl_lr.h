/* sl_lr.h — the in-memory model of an LR-spline volume and its CPU reference
 * evaluation (issue 15; Fuchs, Barrowclough, Hjelmervik, Dahl, paper 003).
 *
 * An LR-spline volume is a sum over basis functions
 *     f(x) = sum_b  gamma_b * c_b * B_b(x),  B_b(x) = N[u_b](x) N[v_b](y) N[w_b](z)
 * where each N[t] is the univariate B-spline on its own local knot vector t
 * of order+1 knots (order = degree + 1, 1..SL_LR_MAX_ORDER per direction),
 * c_b its coefficient (dim = 1 scalar or 3 vector components) and gamma_b the
 * LR scaling weight that makes the basis a partition of unity (not a
 * rational weight). The parameter domain is the world box (no geometry map).
 *
 * The box mesh is kept as the format gives it: mesh rectangles (one extent
 * zero: the constant direction) with multiplicity, and elements (boxes of
 * the mesh, disjoint, tiling the domain) each listing the basis functions
 * whose support covers it. Mesh rectangles may also be segments (two extents
 * zero), as the reference library keeps them from merging overlapping
 * rectangles (issue 31): they split no element and no basis function, so the
 * spline never depends on them; they are kept and written back as read.
 *
 * Element rule (documented once, used by every look-up structure): a point p
 * lies in the element with lo[d] <= p[d] < hi[d] for every d, except that on
 * the domain's upper face (p[d] == domain_hi[d]) the element with
 * hi[d] == domain_hi[d] takes it (closed there). Points outside the closed
 * domain box lie in no element.
 *
 * Evaluation on an element uses each basis function's polynomial piece on
 * that element's box (so values at a knot plane come from the element the
 * rule picks, and the upper face is the limit from inside).
 *
 * Any thread; no GL. A model is read-only once finished, so several threads
 * may evaluate one at the same time. All arrays owned; sl_lr_free frees.
 */
#ifndef SL_LR_H
#define SL_LR_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_status.h"

#define SL_LR_MAX_ORDER 4        /* cubic */
#define SL_LR_MAX_DIM 3
/* Hard limits every reader and builder enforces before it allocates. */
#define SL_LR_MAX_BASIS    (8u * 1024u * 1024u)
#define SL_LR_MAX_ELEMENTS (8u * 1024u * 1024u)
#define SL_LR_MAX_MESHRECTS (16u * 1024u * 1024u)
#define SL_LR_MAX_ELEMENT_BASIS (256u * 1024u * 1024u) /* sum of the elements' basis lists */

typedef struct sl_lr_basis {
    double knots[3][SL_LR_MAX_ORDER + 1]; /* order[d] + 1 nondecreasing knots used per direction */
    double coef[SL_LR_MAX_DIM];           /* dim components used */
    double gamma;                         /* LR scaling weight, > 0 */
} sl_lr_basis;

typedef struct sl_lr_meshrect {
    double lo[3], hi[3];                  /* one d with lo[d] == hi[d], or two (a segment) */
    int multiplicity;                     /* 1..order of sl_lr_meshrect_const_dir */
} sl_lr_meshrect;

typedef struct sl_lr_element {
    double lo[3], hi[3];                  /* lo[d] < hi[d] */
    uint32_t basis_offset;                /* into sl_lr_volume.element_basis */
    uint32_t basis_count;
} sl_lr_element;

typedef struct sl_lr_volume {
    int order[3];                         /* degree + 1 per direction, 1..SL_LR_MAX_ORDER */
    int dim;                              /* 1 (scalar) or 3 (vector) */
    size_t basis_count;
    sl_lr_basis *basis;
    size_t meshrect_count;
    sl_lr_meshrect *meshrects;
    size_t element_count;
    sl_lr_element *elements;
    size_t element_basis_count;
    uint32_t *element_basis;              /* concatenated basis ids of the elements */
    /* Filled by sl_lr_finish: */
    double domain_lo[3], domain_hi[3];    /* union of the element boxes */
    double min_side[3], max_side[3];      /* smallest and largest element side per direction */
    double value_min, value_max;          /* of the value (vectors: magnitude), see sl_lr_finish */
    /* Optional CPU element look-up (sl_lr_index; sl_lr_lookup.h), owned;
     * NULL: sl_lr_find_element searches linearly. */
    struct sl_lr_lookup *index;
} sl_lr_volume;

/* Allocates the arrays of an empty model (zeroed); SL_ERR_LIMIT above the
 * limits, SL_ERR_NOMEM on failure (then nothing stays allocated). */
sl_status sl_lr_alloc(sl_lr_volume *lr, size_t basis_count, size_t meshrect_count,
                      size_t element_count, size_t element_basis_count, sl_err *err);
void sl_lr_free(sl_lr_volume *lr);

/* The constant direction of a mesh rectangle, as the reference library
 * reads it (LR::MeshRectangle::read): the last d with lo[d] == hi[d], so a
 * segment's is the higher of its two; -1 when there is none. Its
 * multiplicity is bounded by the order in that direction. */
int sl_lr_meshrect_const_dir(const sl_lr_meshrect *m);

/* Checks a filled model and computes the derived fields. Refuses, by index
 * and reason: an order or dim out of range; non-finite numbers; knots out of
 * order or a basis function of empty support; gamma <= 0; a mesh rectangle
 * that is not flat, is a point (flat in all three directions), reaches
 * outside the domain box or has a multiplicity outside 1..the order in its
 * constant direction (segments are accepted); an element box
 * that is empty, outside the domain or not covered by a listed basis
 * function's support; a basis id out of range; element basis lists that
 * overrun element_basis; elements whose volumes do not add up to the domain
 * box (relative 1e-9, so no gap or overlap). value_min/max are taken over the
 * values at every element's 8 corners and centre (a sample, not a bound; the
 * Bézier blocks give the hull bound). */
sl_status sl_lr_finish(sl_lr_volume *lr, sl_err *err);

/* Index of the element containing p under the element rule, by a linear
 * search over all elements; -1 when p is outside the domain (or not finite).
 * The reference every look-up structure is tested against. */
long sl_lr_find_element_linear(const sl_lr_volume *lr, const double p[3]);

/* Attaches the `auto` look-up structure (sl_lr_lookup.h: the texture where
 * the knots allow, else the k-d forest) to a finished model, so
 * sl_lr_find_element and sl_lr_eval(.., -1, ..) answer in O(log n) instead
 * of a linear search. Loaders and generators call it; sl_lr_finish drops a
 * stale one (refinement rebuilds the model). SL_ERR_NOMEM / LIMIT. */
sl_status sl_lr_index(sl_lr_volume *lr, sl_err *err);

/* The element containing p under the element rule: through the attached
 * index when there is one, else sl_lr_find_element_linear; -1 outside. */
long sl_lr_find_element(const sl_lr_volume *lr, const double p[3]);

/* Value of the univariate B-spline on `order`+1 knots t, restricted to its
 * polynomial piece on [a, b] (a knot span inside its support), and its
 * first derivative, at x (any x: the piece is extended). 0, 0 when [a, b] is
 * outside the support. Cox-de Boor in double. */
void sl_lr_bspline_piece(const double *t, int order, double a, double b, double x,
                         double *value, double *derivative);

/* Evaluates f at p (double, straight from the LR basis, no Bézier form):
 * value[dim]; gradient (may be NULL) gradient[c*3 + j] = d f_c / d x_j, the
 * Jacobian for vectors. element: the element to use, or -1 to look it up
 * with sl_lr_find_element. SL_ERR_INVALID when p is outside. */
sl_status sl_lr_eval(const sl_lr_volume *lr, const double p[3], long element,
                     double *value, double *gradient, sl_err *err);

/* Coefficient callback of sl_lr_tensor_product: the coefficient(s) of the
 * tensor basis function (i, j, k), given its Greville point g (the mean of
 * its inner knots per direction). */
typedef void (*sl_lr_coef_fn)(void *user, const int ijk[3], const double g[3], double *coef);

/* Builds the LR form of a tensor-product B-spline volume: global knot
 * vectors knots[d] of knot_count[d] nondecreasing values with open ends
 * (order[d] equal values at each end, so the basis is a partition of unity
 * on the whole domain),
 * gamma = 1, one element per non-empty cell, one mesh rectangle per distinct
 * knot value and direction spanning the domain (multiplicity = the count of
 * that value). Calls sl_lr_finish. The start of every refined model
 * (sightline-lrfit) and of the tests' volumes. */
sl_status sl_lr_tensor_product(sl_lr_volume *lr, const int order[3], int dim,
                               const double *const knots[3], const int knot_count[3],
                               sl_lr_coef_fn coef, void *user, sl_err *err);

/* Refinement levels as the issue defines them: the ratio of the largest to
 * the smallest element side in one direction, the largest over the three
 * directions (1 for a uniform mesh). */
double sl_lr_level_ratio(const sl_lr_volume *lr);

#endif
