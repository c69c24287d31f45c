/* tubes_sweep.h — one quadratic sub-segment of `tubes` as a sphere sweep, in double, for
 * the CPU execution (tubes_embree.c): the union of the spheres centred on the quadratic
 * Bézier c(t) with radius |r(t)|, t in [0, 1].
 *
 * Along a ray o + l d (d unit) the entry into the sphere of parameter t is
 *   l(t) = d.q(t) - sqrt(r(t)^2 - |q(t)|^2 + (d.q(t))^2),   q = c - o,
 * where the root is real; the sweep's entry is the smallest local minimum of l(t) over
 * [0, 1] (the ends count) that lies at or beyond l_min. Rays that start inside a sphere
 * see the next entry beyond l_min, the GL path's rule (tubes_intersect.glsl).
 * sl_tubes_sweep_intersect first rejects rays that cannot meet the sweep in [l_min, l_max)
 * (the control triangle grown by the largest radius, and the depth range), then finds the
 * parameter intervals where the ray meets the spheres exactly (the roots of the quartic
 * r^2 - |q|^2 + (d.q)^2 about the ray's point level with the middle control, isolated between
 * the roots of its derivatives), samples l at 33 points of each and polishes every sampled
 * minimum by golden-section search finished by Newton; sl_tubes_sweep_refine polishes a float hit near a known t by
 * Newton steps on l'(t). sl_tubes_sweep_regular says whether the sweep has the smooth envelope that
 * Embree's round curves assume. Pure functions, any thread.
 */
#ifndef SL_TUBES_SWEEP_H
#define SL_TUBES_SWEEP_H

/* Controls of one sub-segment, relative to the dataset origin. */
typedef struct sl_tubes_sweep {
    double b[3][3];  /* Bézier controls of the centre */
    double r[3];     /* Bézier controls of the radius (sign ignored: |r|) */
} sl_tubes_sweep;

/* 1 when r > 0 on [0, 1], |c'(t)| >= 1.05 |r'(t)| everywhere and the largest radius times
 * the largest curvature stays below 0.2 (tubes_sweep.c says why): the sweep's surface is the envelope of its spheres with
 * no fold, which Embree's round curves (with end spheres) reproduce. */
int sl_tubes_sweep_regular(const sl_tubes_sweep *s);

/* The nearest entry at l >= l_min and l < l_max: 1 and *l, *t; 0 when none. */
int sl_tubes_sweep_intersect(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min,
                             double l_max, double *l, double *t);

/* Newton on l'(t) from t0 (steps of at most 0.1, downhill where l is not convex, at most
 * 16, clamped to [0, 1]): 1 with the refined *l, *t when it converged to a local minimum
 * of l (an end counts where l rises into the piece) that is an entry >= l_min; else 0,
 * leaving them unchanged. */
int sl_tubes_sweep_refine(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min, double t0,
                          double *l, double *t);

/* Centre and radius at t. */
void sl_tubes_sweep_eval(const sl_tubes_sweep *s, double t, double c[3], double *r);

#endif
