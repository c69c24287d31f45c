/* sl_lr_refine.h — local refinement of an LR-spline volume by mesh
 * rectangle insertion (Dokken, Lyche, Pettersen, "Polynomial splines over
 * locally refined box-partitions"; Johannessen, Kvamsdal, Dokken,
 * "Isogeometric analysis using LR B-splines").
 *
 * Inserting a rectangle splits every element it crosses and then, until no
 * basis function is traversed by a mesh plane that is not among its knots,
 * splits such basis functions by knot insertion,
 *     B = alpha1 B1 + alpha2 B2,  gamma1 = gamma alpha1, gamma2 = gamma alpha2,
 * both children keeping the coefficient; a child equal to an existing basis
 * function is merged, g = g1 + g2, c = (g1 c1 + g2 c2) / g. So f is unchanged
 * (up to rounding) and the scaled basis stays a partition of unity. Finally
 * the element basis lists are rebuilt and sl_lr_finish is called.
 *
 * Limits: inserted rectangles have multiplicity 1 (interior knots stay simple,
 * C^(p-1) continuity); a rectangle is first extended (never shrunk) in its two
 * free directions to the boundaries of the elements it crosses, so the mesh
 * stays a box partition. Mesh planes are compared exactly (the same value
 * must be the same double). Any thread; no GL; lr is rebuilt in place (on an
 * error it is left as it was).
 */
#ifndef SL_LR_REFINE_H
#define SL_LR_REFINE_H

#include <stddef.h>
#include <stdint.h>

#include "sl_lr.h"

/* Inserts n rectangles (each flat in exactly one direction d, its value
 * strictly inside the domain in d, its extent inside the domain and non-empty
 * in the other two; multiplicity ignored, taken as 1). Rectangles on planes
 * already in the mesh are harmless. SL_ERR_INVALID for a bad rectangle,
 * SL_ERR_LIMIT/NOMEM when the model would grow beyond the limits. */
sl_status sl_lr_refine(sl_lr_volume *lr, const sl_lr_meshrect *rects, size_t n, sl_err *err);

/* "Structured" refinement (Johannessen et al., section 5): for each listed
 * basis function, the planes halving each of its knot spans longer than
 * min_span[d] (per direction; 0 for no limit), over its whole support, are
 * inserted as sl_lr_refine does. *inserted (may be NULL) gets the number of
 * rectangles; 0 means nothing could be refined. check = 0 skips the final
 * sl_lr_finish (its cost dominates a refinement step): the geometry fields
 * are still set, value_min/max are left as they were, and the caller must
 * run sl_lr_finish before the model is used (sl_lr_fit does, at its end). */
sl_status sl_lr_refine_basis(sl_lr_volume *lr, const uint32_t *ids, size_t n, const double min_span[3], int check,
                             size_t *inserted, sl_err *err);

/* "Minimal span" refinement (Johannessen et al., section 5): for each
 * listed element and each direction d in which its side is at least
 * 2 min_span[d], one rectangle flat in d through the element's midpoint,
 * spanning in the other two directions the support of the basis function
 * on that element whose support there is smallest (the shortest mesh
 * rectangle that splits at least one basis function: that one). Inserted as
 * sl_lr_refine does; *inserted and check as for sl_lr_refine_basis.
 * Refines less per step than the structured strategy (one rectangle per
 * direction and element instead of one per knot span of every function),
 * so it reaches a tolerance with fewer basis functions on local features. */
sl_status sl_lr_refine_elements(sl_lr_volume *lr, const uint32_t *elements, size_t n, const double min_span[3],
                                int check, size_t *inserted, sl_err *err);

#endif
