/* particles_reference.h — independent double-precision references for the particles technique.
 *
 * Plan docs/particles_plan.md §4.1. Shares no code with renderer/particles/ or its
 * GLSL: it reads only the sl_volume struct (dims, type, data; voxels decoded here)
 * and computes everything else itself, brute force where that is clearer.
 * Units: voxel coordinates u (voxel (i,j,k) at u = (i,j,k), x fastest) for the
 * field samplers, their gradients and Hessians per voxel unit; pref_voxel_to_world
 * converts with D = diag(spacing). The curvature functions are unit-agnostic: κ comes
 * out in 1/(unit of g, H). Data values are the dataset's raw values (u8/u16/s16 ints,
 * f32 floats; sl_volume has no scale), so a u16/u8 `ellipsoid` isovalue in data units is
 * iso_data = (iso_f + 1.5) / 2.5 · M, M = 65535 / 255 (gen_ellipsoid.c).
 * Signs: n = −∇f/|∇f| (outward for a bright-inside object), κ > 0 where the surface bends
 * away from n (a bright ball: κ1 = κ2 = +1/R). The analytic surfaces below are given in
 * the outward convention; gen_torus is a signed distance (dark inside), so its particle
 * normals point inwards and a test must map the torus reference (κ1, κ2) → (−κ2, −κ1)
 * (negated and reordered; e1 then becomes the other principal direction, the main one stays).
 * Single thread; every function is reentrant. Not in pref: the energy step (§1.3).
 */
#ifndef PARTICLES_REFERENCE_H
#define PARTICLES_REFERENCE_H

#include <stddef.h>
#include <stdint.h>

#include "data/sl_dataset.h"

/* ---- Field samplers (voxel units; clamp-to-edge like a texture; 1-component volumes) ---- */

/* Trilinear value *f and its analytic gradient g (per voxel unit) at u. Each coordinate is
 * clamped to [0, dims − 1]; along a clamped or one-voxel axis the gradient is 0. At an
 * integer coordinate the gradient is the one of the cell above (below at the last voxel).
 * A tap of zero weight is not read into f (at integer u, f is that voxel's value alone).
 * Returns 0, or −1 when a tap of non-zero weight is NaN (then *f and g are NaN); with f
 * finite, g is NaN when any of the cell's 8 voxels is. g may be NULL. */
int pref_trilinear(const sl_volume *vol, const double u[3], double *f, double g[3]);

/* Uniform cubic B-spline (approximating), as the plain sum over the 64 taps
 * floor(u) − 1 .. floor(u) + 2 per axis (indices clamped to the grid), with the weights
 * and their derivatives from the Cox–de Boor recursion. Gives *f, g = ∇ᵤf, H = Hᵤ
 * (row-major 3×3, symmetric). Bias (tested): for a quadratic q(u) = uᵀAu + bᵀu + c
 * sampled at the voxels, away from the border, f = q + tr(A)/3 (the cubic B-spline's
 * variance is 1/3 per axis), while ∇f and H are exact. Returns 0, or −1 on a NaN tap
 * (all outputs NaN). g and H may be NULL. */
int pref_bspline(const sl_volume *vol, const double u[3], double *f, double g[3], double H[9]);

/* The weights of one axis: w[i] = B(t + 1 − i), i = 0..3 for the taps floor(u) − 1 + i,
 * t = u − floor(u), with B the centred cubic B-spline; d1, d2 the first and second
 * derivatives with respect to u. Exposed for the unit test (partition of unity). */
void pref_bspline_weights(double t, double w[4], double d1[4], double d2[4]);

/* ∇ₓf = D⁻¹∇ᵤf, Hₓ = D⁻¹HᵤD⁻¹ with D = diag(spacing). In and out may alias. */
void pref_voxel_to_world(const double spacing[3], const double g_u[3], const double H_u[9], double g_x[3],
                         double H_x[9]);

/* ---- Curvature (§1.5) ---- */

/* G = −P H P / |g|, n = −g/|g|, P = I − n nᵀ, diagonalized by cyclic 3×3 Jacobi (after
 * adding 3‖G‖ n nᵀ, which moves n's eigenvalue 0 away from the tangent ones so a zero
 * curvature cannot mix with n); n's eigenvalue is dropped. *k1 ≥ *k2; e1 (may be NULL)
 * the unit eigenvector of k1, tangent, sign chosen so its largest |component| is positive
 * (arbitrary in the tangent plane at an umbilic). Returns 0, or −1 when |g| = 0 or an
 * input is not finite (outputs 0). */
int pref_curvature(const double g[3], const double H[9], double *k1, double *k2, double e1[3]);

/* Shape index s = (2/π) atan((κ2 + κ1)/(κ2 − κ1)) for κ1 > κ2 (swapped if given the other
 * way); κ1 = κ2 ≠ 0: −sign(κ1); κ1 = κ2 = 0: NaN. Sphere −1, cup +1, ridge −½, valley +½,
 * symmetric saddle 0. */
double pref_shape_index(double k1, double k2);

/* ρ = 0 if |κ1| < eps and |κ2| < eps, else 1 − |2(|s| − ½)|. */
double pref_reliability(double k1, double k2, double eps);

/* ---- Analytic surfaces (outward normals, world units) ---- */

/* Ellipsoid x²/a² + y²/b² + z²/c² = 1 (axes = a, b, c): principal curvatures of the level
 * set of F = x²/a² + y²/b² + z²/c² through p (p need not be on the surface; p ≠ 0),
 * convex → positive, through pref_curvature on F's exact gradient and Hessian.
 * Returns pref_curvature's code. e1 may be NULL. */
int pref_ellipsoid_curvature(const double axes[3], const double p[3], double *k1, double *k2, double e1[3]);

/* Nearest point q on the ellipsoid to p (robust for any p, inside, outside, on the axes,
 * the centre): Lagrange parameter t of q_i = a_i² p_i/(a_i² + t) by bisection in double to
 * the last bit, plus the degenerate candidate on the smallest axis when p has a zero
 * component there. Returns |p − q|. */
double pref_ellipsoid_nearest(const double axes[3], const double p[3], double q[3]);

/* Torus around the z axis (major R0, minor r < R0), at p off the ring and the axis: tube angle
 * v from the ring point nearest p (cos v = (ρ_xy − R0)/|p − ring|), κ1 = 1/r (meridian, e1),
 * κ2 = cos v/(R0 + r cos v) (parallel). main (may be NULL) = the direction of the larger
 * |κ| (the meridian unless r > R0/2 near the inner equator). For gen_torus negate (header).
 * Returns 0, or −1 on the ring or the axis. */
int pref_torus_curvature(double R0, double r, const double p[3], double *k1, double *k2, double e1[3],
                         double main_dir[3]);

/* Nearest point on the torus to p (p off the ring and the axis); returns |p − q|. */
double pref_torus_nearest(double R0, double r, const double p[3], double q[3]);

double pref_sphere_area(double R);              /* 4πR² */
double pref_torus_area(double R0, double r);    /* 4π²R0 r */
/* Ellipsoid area in double: one octant over (cos θ, φ), the pole on the shortest axis, by
 * 64×64-point Gauss–Legendre on panels graded toward the rim (width c/a) and toward φ = 0
 * (width b/a). ~1e-14 relative against the spheroid closed forms up to axis ratio 19. */
double pref_ellipsoid_area(const double axes[3]);

/* ---- Placement count (§1.1, Alg. 1) ---- */

/* Lattice points r = s·(i,j,k), i = 0..n_x with n_a = floor((dims_a − 1)/s) (in double), and
 * per axis a with i_a + 1 ≤ n_a the edge to r + s·e_a counts when (f0 < iso) != (f1 < iso),
 * f = pref_trilinear (the voxel values at integer s), edges with a NaN end skipped. s > 0. */
uint64_t pref_placement_count(const sl_volume *vol, double iso, double s);

/* ---- Nearest-neighbour statistics ---- */

typedef enum pref_nn_method { PREF_NN_AUTO, PREF_NN_BRUTE, PREF_NN_GRID } pref_nn_method;

/* Exact nearest-neighbour distance of each of the n points xyz[3i..3i+2] (n ≥ 2): brute force
 * (AUTO below 2000 points) or a uniform grid searched ring by ring until exact. *mean, *cv
 * (std/mean, population std) and dist (n entries) may each be NULL. Returns 0, or −1 when
 * n < 2, a coordinate is not finite, or out of memory. */
int pref_nn(const double *xyz, size_t n, pref_nn_method method, double *mean, double *cv, double *dist);

/* Packing ratio n·π(mean/2)²/area: π/(2√3) ≈ 0.9069 for a perfect hexagonal packing. */
double pref_packing_ratio(size_t n, double mean, double area);

/* ---- Export CSV ---- */

#define PREF_CSV_HEADER "set,x,y,z,nx,ny,nz,k1,k2,reliability"

typedef struct pref_csv_row {
    int set;                 /* 0..3 */
    double p[3], n[3];       /* as written (the exporter's world / normal) */
    double k1, k2, reliability;
} pref_csv_row;

/* Reads an export CSV: the first line exactly PREF_CSV_HEADER, then rows of 10 comma-separated
 * fields, set an integer 0..3, the others finite numbers (strtod, whole field); "\n" or "\r\n"
 * line ends; a final line end optional; no blank lines. *rows (malloc'd, the caller frees; NULL
 * when 0 rows) and *count on success. Returns 0, or −1 with err naming the line and the fault
 * ("line 7: 9 columns, want 10"); then *rows = NULL, *count = 0. */
int pref_csv_read(const char *path, pref_csv_row **rows, size_t *count, char *err, size_t err_size);

#endif
