/* ribbons_reference.h — CPU double-precision references for the `ribbons` technique (issue 13).
 *
 * Geometry of an elliptic ribbon segment p = x0 + r (w cos phi n + sin phi b) + s t
 * (plan section 1.1: n the thin axis, semi-axis r w; b the wide one, r); the
 * N-gon depth bound of its tessellation; the silhouette (tangent) points of
 * the ellipse seen from a camera, by brute-force search of the tangency
 * condition (deliberately not the paper's polar / conic construction it
 * checks); the halo's lambda from those points; the twist stripes and their
 * corrected width (paper sections 3.2 and 4, plan 1.4 and 1.5).
 * Own plain double[3] arithmetic: includes nothing from the renderer.
 * Limits: one straight segment per call; no pixel loop. Any thread, no state.
 */
#ifndef RIBBONS_REFERENCE_H
#define RIBBONS_REFERENCE_H

/* One straight elliptic cylinder segment, closed by two elliptic disks. */
typedef struct ribbons_ref_segment {
    double x0[3];         /* centre of the segment, world */
    double n[3], b[3], t[3]; /* orthonormal frame: thin axis, wide axis, axis (n x b = t) */
    double r;             /* semi-major axis (along b), > 0 */
    double w;             /* semi-minor / semi-major (along n: r w), > 0 */
    double half_len;      /* the segment spans (p - x0).t in [-half_len, half_len], >= 0 */
} ribbons_ref_segment;

enum { RIBBONS_REF_MANTLE = 0, RIBBONS_REF_CAP_START = 1, RIBBONS_REF_CAP_END = 2 };

typedef struct ribbons_ref_hit {
    double distance;      /* world distance from the ray origin to the first crossing; -1 = miss */
    double cos_in;        /* mantle: incidence cosine in circle space (the cross-section mapped to
                             the unit circle by diag(1/(r w), 1/r)): -q.e/|e|, q the unit-circle hit
                             point, e the mapped direction across the axis; caps: |d.t| */
    double cos_world;     /* -d.N with N the world unit normal at the hit */
    int part;             /* RIBBONS_REF_MANTLE, _CAP_START (at -half_len), _CAP_END */
    int inside;           /* 1 when the origin is inside the closed segment (the hit is an exit) */
} ribbons_ref_hit;

/* The first crossing (smallest s > 0) of the ray o + s d (d any non-zero
 * length; distances are world units) with the mantle or a cap. Returns 1 on
 * a hit, 0 on a miss (hit->distance = -1), -1 on bad input (d = 0, r <= 0,
 * w <= 0). A ray touching the mantle tangentially is a hit with cos_in 0. */
int ribbons_ref_ray_ellipse(const double o[3], const double d[3], const ribbons_ref_segment *seg,
                            ribbons_ref_hit *hit);

/* Largest depth error (world units, along unit d) of the prism through the
 * regular `sides`-gon ring phi_j = 2 pi j / sides against the segment's
 * mantle, for a ray entering the mantle with circle-space cosine cos_in:
 * B(c) / |S d_perp|, B(c) = sin^2(pi/N) / (c + sqrt(c^2 - sin^2(pi/N))),
 * S = diag(1/(r w), 1/r). Head-on: (1 - cos(pi/N)) / |S d_perp|. Returns
 * HUGE_VAL when cos_in < sin(pi/N) (the ray passes outside the polygon's
 * incircle: no bound) or d has no component across the axis. */
double ribbons_ref_polygon_bound(const double d[3], const ribbons_ref_segment *seg, int sides, double cos_in);

/* Eccentric anomalies theta (ascending, in [0, 2 pi)) of the two points of
 * the ellipse e(theta) = (w cos theta, sin theta) (units of r, x along n, y
 * along b) whose tangent passes through the homogeneous camera c: c_z != 0
 * the point (c_x, c_y) / c_z, c_z = 0 the direction (c_x, c_y) (camera at
 * infinity). Brute force: g(theta) = w c_z - c_x cos theta - w c_y sin theta
 * (cross(e - c, e') scaled by c_z) at 2^16 samples, bisection of each sign
 * change to 1e-15. Returns 2, or 0 ("none") when the camera is inside or on
 * the ellipse (c^T diag(1/w^2, 1, -1) c <= 0), when c = 0, or when it lies so
 * close outside (~1e-9) that both roots fall between two samples. */
int ribbons_ref_tangent_points(const double c[3], double w, double theta[2]);

/* The halo parameter of the fragment p (units of r, in the normal plane) for
 * camera c (as above): p' = the crossing of the line through c and p with the
 * chord between the two tangent points P0, P1; lambda = |2 |p' - P0| / |P1 - P0| - 1|
 * (1 at the silhouette, 0 mid-chord). Returns 1 with *lambda set, or 0 with
 * *lambda = 0 when there is no silhouette (camera inside) or the line does
 * not cross the chord's line. */
int ribbons_ref_lambda(const double p[2], const double c[3], double w, double *lambda);

/* Twist stripe centres on the circumference at accumulated twist R (the
 * rotation of the transport frame is theta = f R): phi_m = theta + 2 pi m / k
 * reduced to [0, 2 pi), written ascending to phi[0..k-1]. Returns k, or 0
 * when k < 1. */
int ribbons_ref_twist_stripes(double R, double f, int k, double *phi);

/* Stripe width corrected for the stripe's slope (paper Eq. 6-7):
 * w_u = w_r / cos(atan(slope)), slope = dy/dx. */
double ribbons_ref_twist_width(double w_r, double slope);

/* The slope of a stripe on a tube of radius r: dy / dx = r f dR/ds. */
double ribbons_ref_twist_slope(double r, double f, double dR_ds);

/* 1 when angle phi lies within half of width w_u of one of the stripe
 * centres phi[0..k-1] (angular distance on the circle), else 0. */
int ribbons_ref_twist_covered(double phi_frag, const double *phi, int k, double w_u);

#endif
