/* sl_lr_bezier.h — the Bézier-block form of an LR-spline volume (issue 15):
 * every element converted by an exact change of basis to one tensor
 * Bernstein polynomial of degrees order[d]-1 on its box, its CPU evaluation
 * by de Casteljau in double, the per-element value hull, and the packing of
 * the blocks into GPU shader storage buffers (lr_bezier_gpu.c, GL).
 *
 * Change of basis (univariate, per basis function and direction): a
 * B-spline N of degree p on knots t_0..t_{p+1}, restricted to its
 * polynomial piece P on the span [t_s, t_{s+1}] that holds the element side
 * [a, b], has on [a, b] the Bernstein form
 *     P(x) = sum_j beta_j B_j^p((x - a) / (b - a)),
 *     beta_j = blossom of P at (a, ..., a, b, ..., b), p - j a's and j b's.
 * (Insert a and b to full multiplicity p + 1: the refined B-splines living
 * on [a, b] are then the Bernstein polynomials B_j^p, and the coefficient of
 * the refined B-spline with knots tau_i..tau_{i+p+1} is the blossom at its
 * inner knots tau_{i+1}..tau_{i+p}, here a^(p-j) b^j.) The blossom is
 * de Boor's recurrence on span s with the control vector of N (1 at N, 0
 * elsewhere) and argument u_r at level r. The element's block is
 *     C_{ijk} = sum_{b in element} gamma_b c_b beta^u_i beta^v_j beta^w_k.
 *
 * Hull: by the convex-hull property of the Bernstein form, the values on
 * the element lie in [min C, max C] (scalar); for vectors the magnitude
 * lies in [distance from 0 to the box of the control points, max |C|].
 * These are true bounds (up to rounding), unlike sl_lr_volume.value_min/max.
 *
 * GPU layout (std430, float; lr_bezier.glsl reads it):
 *   binding LR_BOX_BINDING:  struct { vec4 lo; vec4 hi; } box[element_count];
 *                            lo.xyz/hi.xyz the element box, lo.w/hi.w the hull.
 *   binding LR_COEF_BINDING: float coef[element_count * stride], stride =
 *                            order0*order1*order2*dim, block e at e*stride,
 *                            component c of C_{ijk} at ((k*o1 + j)*o0 + i)*dim + c.
 * The double variant (GLSL 4.00+ doubles) uses the same layout with
 * dvec4/double at bindings LR_BOX_BINDING_D / LR_COEF_BINDING_D.
 *
 * Any thread for the CPU part; the upload needs the GL context (render
 * thread). Blocks are read-only once built.
 */
#ifndef SL_LR_BEZIER_H
#define SL_LR_BEZIER_H

#include <stddef.h>

#include "../core/sl_status.h"
#include "sl_lr.h"
#include "sl_lr_lookup.h"

typedef struct sl_lr_bezier {
    int order[3];
    int dim;
    size_t element_count;
    size_t stride;          /* order0 * order1 * order2 * dim doubles per block */
    double *lo, *hi;        /* 3 per element */
    double *coef;           /* element_count * stride, layout as above */
    double *hull_min, *hull_max; /* per element; the magnitude for vectors */
    double hull_lo, hull_hi; /* over all elements */
    float domain_lo[3], domain_hi[3]; /* the union of the element boxes in float (u_lr_domain_lo/hi), once */
    /* The element look-up the GPU uses (sl_lr_lookup.h): the model's own
     * index when it is the structure asked for (sl_lr_index_match; borrowed,
     * so the model must outlive every sl_lr_bezier_upload of these blocks),
     * else own_lookup, built with the blocks (then lookup points into this
     * struct: a built sl_lr_bezier is not copied). lookup_kind is its kind
     * (kept for the #defines after the model is gone). */
    const sl_lr_lookup *lookup;
    sl_lr_lookup own_lookup;
    sl_lr_lookup_kind lookup_kind;
} sl_lr_bezier;

/* Bernstein coefficients beta[0..order-1] of the piece of the univariate
 * B-spline on knots t[0..order] on [a, b] (a knot span inside its support
 * must hold [a, b]); all 0 when none does. */
void sl_lr_bernstein_piece(const double *t, int order, double a, double b, double *beta);

/* Converts every element of a finished model and takes the element look-up
 * of the given kind (SL_LR_LOOKUP_AUTO: the texture where the knots allow,
 * else the k-d forest; forest_axis 0: the default) from the model's index
 * when that is the same structure, else builds it. SL_ERR_NOMEM,
 * SL_ERR_LIMIT (blocks above 2^31 floats: the GPU buffers' index range), the
 * look-up's refusals (an octree on non-dyadic knots, ...). */
sl_status sl_lr_bezier_build(const sl_lr_volume *lr, sl_lr_lookup_kind lookup, int forest_axis,
                             sl_lr_bezier *bz, sl_err *err);
void sl_lr_bezier_free(sl_lr_bezier *bz);

/* Evaluates block `element` at p (any p: the polynomial is extended), by
 * de Casteljau in double: value[dim]; gradient (may be NULL) gradient[c*3+j]
 * = d f_c / d x_j (the Jacobian for vectors). */
void sl_lr_bezier_eval(const sl_lr_bezier *bz, size_t element, const double p[3],
                       double *value, double *gradient);

/* GPU buffers of the blocks (lr_bezier_gpu.c; needs the GL context). */
typedef struct sl_lr_bezier_gpu {
    unsigned box_buffer, coef_buffer;       /* float, always */
    unsigned box_buffer_d, coef_buffer_d;   /* double, when made with want_double */
    size_t element_count;
    sl_lr_lookup_gpu lookup;                /* the look-up's buffers (bindings 10..12) */
    size_t bytes;                           /* GPU memory held, look-up included */
} sl_lr_bezier_gpu;

#define SL_LR_BOX_BINDING 6
#define SL_LR_COEF_BINDING 7
#define SL_LR_BOX_BINDING_D 8
#define SL_LR_COEF_BINDING_D 9

sl_status sl_lr_bezier_upload(const sl_lr_bezier *bz, int want_double, sl_lr_bezier_gpu *gpu, sl_err *err);
/* Adds the double buffers to blocks uploaded without them (nothing when
 * present), so a double program can share blocks first made for float
 * (lr_volume's streamlines). SL_ERR_NOMEM, SL_ERR_GPU; on failure gpu is
 * unchanged. */
sl_status sl_lr_bezier_upload_double(const sl_lr_bezier *bz, sl_lr_bezier_gpu *gpu, sl_err *err);
/* Binds the buffers to their bindings (the double ones when present) and
 * the look-up's, setting the look-up's uniforms on `program` (made current). */
void sl_lr_bezier_bind(const sl_lr_bezier_gpu *gpu, unsigned program);
void sl_lr_bezier_release(sl_lr_bezier_gpu *gpu);

/* The #defines lr_bezier.glsl and lr_lookup.glsl need for this model: the
 * orders, dim, LR_DOUBLE (want_double) and LR_LOOKUP_KIND. Writes at most
 * size bytes. */
void sl_lr_bezier_defines(const sl_lr_bezier *bz, int want_double, char *out, size_t size);
/* Sets the uniforms of lr_bezier.glsl (element count, the domain box
 * computed once by sl_lr_bezier_build) on `program` (which must be current). */
void sl_lr_bezier_set_uniforms(unsigned program, const sl_lr_bezier *bz);

/* Stage files include "lrspline/lr_find.glsl", which pastes lr_bezier.glsl
 * and the element look-up (lr_lookup.glsl); its buffers are uploaded and
 * bound with the blocks by sl_lr_bezier_upload / _bind. */

#endif
