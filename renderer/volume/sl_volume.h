/* sl_volume.h — shared preparation of scalar volumes for the volume techniques.
 *
 * What volume_dvr uses and particles / lr_volume are meant to reuse: the
 * volume's geometry (values at voxel centres, the box spanning them), its 3D
 * texture (every voxel type, exact data values), the transfer function
 * resolved for a dataset and baked into a small 1D texture, and the min-max
 * brick grid with a per-transfer-function "visible bricks" mask and its
 * runs (distance maps: how far a ray may go without a brick lookup). GLSL halves:
 * volume/volume_ray.glsl (ray–box + clip box), volume/volume_sample.glsl
 * (values), volume/volume_tf.glsl (lookup + opacity correction). And the one
 * ray marcher both volume_dvr and particles draw with (sl_volume_marcher,
 * volume_march.c, volume/volume_march.glsl + volume_march.frag.glsl).
 * Invariants: the min-max grid is built once per volume; a new transfer
 * function re-bakes the TF texture and rebuilds the mask from that grid only
 * (counted in sl_volume_counters). Vector fields are drawn by magnitude.
 * Not here: techniques' parameters (the marcher takes a descriptor). GL functions run
 * on the render thread; the CPU functions (resolve, bake, mask) on any.
 */
#ifndef SL_VOLUME_H
#define SL_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_camera.h"
#include "../core/sl_params.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"

/* Geometry: voxel (i,j,k) sits at origin + spacing·(i,j,k); the box spans
 * the voxel centres, [0, dims-1] per axis in voxel coordinates — except an
 * axis with one voxel, which gets a slab one spacing thick centred on it,
 * [-0.5, 0.5] (the value is constant across it), so 1×1×N and N×N×1
 * volumes are visible. World = origin + spacing · voxel coordinate. */
typedef struct sl_volume_geometry {
    int dims[3];
    double spacing[3];
    double min_spacing;       /* the unit of `step` (step_ref = 1) */
    sl_vec3 origin;           /* world of voxel (0,0,0) */
    double box_lo[3], box_hi[3]; /* voxel coordinates */
} sl_volume_geometry;

void sl_volume_geometry_init(const sl_dataset *ds, sl_volume_geometry *g);

/* The volume as a 3D texture: texel (i,j,k) holds voxel (i,j,k); the data
 * value is texel · value_scale + value_offset (u8 as R8, u16 as R16, s16 as
 * R16 after adding 32768 so every value is exact, f32 as R32F with NaN kept;
 * vector fields as the R32F magnitude). Clamp to edge; linear or nearest. */
typedef struct sl_volume_texture {
    GLuint tex;
    float value_scale, value_offset;
    size_t bytes;
} sl_volume_texture;

/* SL_ERR_UNSUPPORTED above GL_MAX_3D_TEXTURE_SIZE, SL_ERR_NOMEM, SL_ERR_GPU
 * (sl_gl_check_errors). On failure *t is zeroed and nothing is held. */
sl_status sl_volume_texture_create(const sl_volume *vol, sl_volume_texture *t, sl_err *err);
void sl_volume_texture_destroy(sl_volume_texture *t); /* zeroed is fine */
void sl_volume_texture_set_filter(const sl_volume_texture *t, int linear);

/* A precomputed gradient: per voxel the central difference of the voxel
 * values (one-sided at the edges, divided by the spacing: world units),
 * normalized and stored as RGBA8_SNORM (xyz; zero where the difference is
 * zero or touches NaN), filtered linearly. For shading only (direction).
 * SL_ERR_NOMEM, SL_ERR_GPU; on failure *tex is 0. Counted as a gradient build. */
sl_status sl_volume_gradient_create(const sl_volume *vol, GLuint *tex, size_t *bytes, sl_err *err);

/* A transfer function resolved for a dataset: control points in data units,
 * piecewise linear, constant beyond the ends. The colormap form becomes the
 * union of the colormap's own control points and the opacity ramp's (exact:
 * both are piecewise linear in t), over tf's range or vol's value range; a
 * range of one value (constant volume) is widened to [v - 0.5, v + 0.5].
 * auto_opacity takes the ramp of sl_volume_tf_auto_opacity(vol,
 * emission_absorption): 1 for composite rendering, 0 for a mode that shows
 * one sample per ray (MIP). */
#define SL_VOLUME_TF_MAX (SL_TF_MAX_POINTS + 16)
typedef struct sl_volume_tf_points {
    int count;
    double value[SL_VOLUME_TF_MAX];
    double rgba[SL_VOLUME_TF_MAX][4];
} sl_volume_tf_points;

void sl_volume_tf_resolve(const sl_transfer_function *tf, const sl_volume *vol, int emission_absorption,
                          sl_volume_tf_points *out);

/* The opacity ramp of the colormap form's "opacity": "auto", from the
 * volume's histogram: [t, alpha] points over its value range (t in 0..1,
 * at most 4). When the histogram has a background peak in its lower half
 * (one bin holding >= SL_VOLUME_AUTO_PEAK of the values: air around a CT,
 * the zeros around an MRI), the ramp starts at 0 where that peak falls to
 * its first minimum (smoothed over 5 bins); it rises to SL_VOLUME_AUTO_ALPHA
 * at the 99.5th percentile of the values above, and stays there; convex
 * (SL_VOLUME_AUTO_MID of it half-way), so low values (skin, soft tissue)
 * stay translucent and the high ones (bone, white matter) show through. Without such a peak: 0 at t = 0 to the same alpha at the
 * 99.5th percentile. A volume without finite values: [[0, 0], [1, alpha]].
 * Then, for emission-absorption (composite; emission_absorption 1, not for
 * MIP, which shows one sample per ray), the opacity is bounded so the
 * first look shows what lies inside: when the ramp's optical depth
 * (sl_volume_tf_ramp_depth) exceeds
 * SL_VOLUME_AUTO_DEPTH, every point's extinction -ln(1 - alpha) is scaled
 * down by one factor to meet it (exact at the points; alpha is linear
 * between them, so the estimate lands within 5 % of the bound). A big bulk
 * of soft tissue or brain would otherwise hide everything inside it: a
 * uniform egg (the head phantom's estimate was 4.4). */
#define SL_VOLUME_AUTO_PEAK 0.05
#define SL_VOLUME_AUTO_ALPHA 0.2
#define SL_VOLUME_AUTO_MID 0.125 /* alpha at the ramp's middle, as a share of AUTO_ALPHA */
#define SL_VOLUME_AUTO_DEPTH 1.5 /* optical depth: 1 - e^-1.5 = 78 % opacity through the middle */
int sl_volume_tf_auto_opacity(const sl_volume *vol, int emission_absorption, double ramp[4][2]);

/* An estimate of the optical depth of the [t, alpha] ramp (n points, t over
 * the value range) through the middle of vol, from its histogram alone: the
 * voxels the ramp gives an opacity (their share of the histogram times
 * the box, dims x spacing, in cubes of the smallest spacing: the unit of
 * alpha), as one ball, crossed through its centre — the ball's diameter
 * (6 N / pi)^(1/3) times their mean extinction -ln(1 - alpha). An upper
 * estimate for a compact body; a shell (a skull) is crossed over fewer
 * voxels. 0 when the ramp makes nothing visible. */
double sl_volume_tf_ramp_depth(const sl_volume *vol, const double ramp[][2], int n);

/* The automatic isovalue of vol (an "auto" isovalue of volume_dvr, the
 * default set of particles): where the automatic opacity ramp starts — the
 * end of the background peak, the boundary of the object — or mid-range
 * without a background peak. Inside the value range when it is not constant. */
double sl_volume_auto_isovalue(const sl_volume *vol);
/* rgba at value v (NaN: transparent black). */
void sl_volume_tf_eval(const sl_volume_tf_points *pts, double v, double rgba[4]);

/* The baked table: SL_VOLUME_TF_TEXELS texels, texel k = the function at
 * lo + k (hi - lo) / (TEXELS - 1); the shader interpolates linearly between
 * two texels (volume_tf.glsl), clamping beyond the ends. lo = first point,
 * hi = last (hi = lo + 1 when they coincide). */
#define SL_VOLUME_TF_TEXELS 4096
typedef struct sl_volume_tf_table {
    double lo, hi;
    float rgba[SL_VOLUME_TF_TEXELS][4];
    uint32_t nonzero_before[SL_VOLUME_TF_TEXELS + 1]; /* texels < k with alpha > 0 */
} sl_volume_tf_table;

void sl_volume_tf_bake(const sl_volume_tf_points *pts, sl_volume_tf_table *table);
/* 1 when the baked function has alpha > 0 anywhere in [lo, hi] (as the
 * shader interpolates it: every texel the interval touches). */
int sl_volume_tf_table_visible(const sl_volume_tf_table *table, double lo, double hi);

/* The TF texture: a 1D RGBA32F texture of SL_VOLUME_TF_TEXELS (create once,
 * upload per change). */
sl_status sl_volume_tf_texture_create(GLuint *tex, sl_err *err);
void sl_volume_tf_texture_upload(GLuint tex, const sl_volume_tf_table *table);

/* Min-max bricks: brick b covers the voxels [B b, B b + B] of each axis
 * (one voxel of overlap: a trilinear sample anywhere in the brick reads
 * only these), min and max of their finite values (min > max: none). */
#define SL_VOLUME_BRICK 8
typedef struct sl_volume_bricks {
    int dims[3];              /* bricks per axis */
    float *minmax;            /* 2 per brick, x fastest; owned */
    uint8_t *mask;            /* 1 per brick: 1 = visible; owned */
    uint8_t *runs;            /* 1 per brick: sl_volume_brick_runs of mask; owned */
    GLuint minmax_tex;        /* RG32F */
    GLuint runs_tex;          /* R8UI: runs */
    size_t bytes;             /* GPU bytes */
} sl_volume_bricks;

/* Builds the min-max grid (CPU, once) and both textures; mask all visible.
 * SL_ERR_NOMEM, SL_ERR_GPU. On failure nothing is held. */
sl_status sl_volume_bricks_create(const sl_volume *vol, sl_volume_bricks *b, sl_err *err);
void sl_volume_bricks_destroy(sl_volume_bricks *b); /* zeroed is fine */

typedef enum sl_volume_mask_rule {
    SL_VOLUME_MASK_TF,        /* visible where the baked TF has alpha > 0 on [min, max] */
    SL_VOLUME_MASK_ISO,       /* visible where min <= iso <= max */
    SL_VOLUME_MASK_FINITE,    /* visible where the brick has a finite value */
} sl_volume_mask_rule;
/* Rebuilds the mask and its runs from the min-max grid (never rebuilds the
 * grid) and uploads the runs; returns the number of visible bricks. When
 * the runs' scratch cannot be allocated every brick is a run of its own
 * (d = 1: one lookup per brick, still exact). */
size_t sl_volume_bricks_update_mask(sl_volume_bricks *b, sl_volume_mask_rule rule, const sl_volume_tf_table *table,
                                    double iso);

/* Runs of a brick mask (visible: 1 byte per brick, nonzero = visible), for
 * rays to cross without a lookup per brick. An invisible brick gets d in
 * 1..SL_VOLUME_RUN_MAX: its Chebyshev distance in bricks to the nearest
 * visible one (capped, also when none is visible); a visible brick gets
 * SL_VOLUME_RUN_VISIBLE + d, d its distance to the nearest invisible one.
 * Either way every brick within d - 1 of it (the cube of 2d - 1 bricks per
 * side around it) is of its kind: a ray may skip, or sample without looking
 * bricks up, until it leaves that cube. Returns 0, or -1 when out of memory
 * (out unchanged). */
#define SL_VOLUME_RUN_MAX 127
#define SL_VOLUME_RUN_VISIBLE 128
int sl_volume_brick_runs(const uint8_t *visible, const int dims[3], uint8_t *out);

/* The ray marcher (volume_march.c; volume_march.frag.glsl over volume_march.glsl):
 * one full-screen pass, a ray per pixel, the model of volume_dvr/README.md.
 * The marcher owns what marching needs besides the volume's own preparation:
 * its programs (one per variant, compiled on first use), the TF texture with
 * its baked table and the transfer function it was baked from (re-baked only
 * when the desc's one differs), the brick mask's state (rebuilt only when the
 * rule, TF or isovalue changes), the per-row sample counters, a camera UBO
 * and an empty VAO. It borrows the volume it was made for (resolves transfer
 * functions against its value range and histogram). Render thread only. */
typedef enum sl_volume_march_mode {
    SL_VOLUME_MARCH_COMPOSITE = 0, /* emission-absorption, front to back */
    SL_VOLUME_MARCH_MIP,           /* maximum intensity, then the TF */
    SL_VOLUME_MARCH_ISO,           /* first crossing of iso, shaded */
} sl_volume_march_mode;

/* Focus + context (docs/particles_plan.md §1.11): radius > 0 selects the
 * SL_FOCUS 1 program. The ray interval is clipped to the sphere and ended at
 * the opaque marks' depth; the output is premultiplied (C, A), blended
 * (ONE, ONE_MINUS_SRC_ALPHA) over the target, and the depth written is the
 * larger (nearer, reversed-Z) of the mark's and the marcher's (A > 0.5). */
typedef struct sl_volume_march_focus {
    double centre[3];         /* world */
    double radius;            /* world; 0 = no focus (the plain path) */
    GLuint opaque_depth_tex;  /* borrowed: a 2D depth (or R32F) texture of the
                                 view's size, the marks' reversed-Z depth (texel
                                 0: no mark there); not attached to the bound
                                 framebuffer. Name 0: no marks at all */
} sl_volume_march_focus;

/* Everything one draw decides; zero-initialized = the defaults noted. */
typedef struct sl_volume_march_desc {
    sl_volume_march_mode mode;
    const sl_transfer_function *tf; /* borrowed; required */
    double step;              /* in units of min_spacing; 0 = 0.5. Doubled (at most 16) on
                                 interactive views */
    double iso;               /* ISO: the surface's value */
    double alpha_stop;        /* COMPOSITE: stop at this opacity; 0 = 0.99 */
    int jitter;               /* 1: per-pixel random start within a step; 0: midpoints */
    int no_skipping;          /* 1: sample every brick (same image, for checks) */
    int nearest;              /* 1: nearest voxel; 0: trilinear */
    int shading;              /* COMPOSITE: Blinn-Phong with the gradient (ISO always shades) */
    GLuint gradient_tex;      /* borrowed; when shading: normals from it (sl_volume_gradient_create);
                                 0 = central differences per sample */
    int clip;                 /* 1: clip to [clip_min, clip_max] (0..1 of the box) */
    double clip_min[3], clip_max[3];
    double light_dir[3];      /* eye space (x right, y up, z to the viewer), towards the
                                 light, any length; zero = (0, 0, 1) */
    double material[4];       /* ambient, diffuse, specular, shininess; all zero =
                                 0.25, 0.75, 0.3, 32 */
    sl_volume_march_focus focus;
} sl_volume_march_desc;

#define SL_VOLUME_MARCH_VARIANTS 24 /* mode x shading x gradient source x focus */
typedef struct sl_volume_marcher {
    const sl_volume *data;    /* borrowed */
    GLuint programs[SL_VOLUME_MARCH_VARIANTS]; /* 0 until first used */
    GLuint vao, camera_ubo, tf_tex, rows_buf;
    int rows_capacity;        /* pixel rows rows_buf holds */
    sl_volume_tf_table *table; /* owned; baked from tf_loaded */
    sl_transfer_function tf_loaded;
    int tf_emission_absorption;  /* the mode the table was resolved for (auto opacity) */
    int tf_valid;
    int mask_rule;            /* sl_volume_mask_rule of the bricks' mask, or -1 */
    double mask_iso;
    size_t visible_bricks;
    size_t bytes;             /* GPU bytes held: the TF texture */
} sl_volume_marcher;

/* Compiles the plain composite program, creates the TF texture and the VAO.
 * data: borrowed, must outlive m. SL_ERR_NOMEM, SL_ERR_GPU (a compile or
 * link log included); on failure *m holds nothing (deinit is still safe). */
sl_status sl_volume_marcher_init(sl_volume_marcher *m, const sl_volume *data, sl_err *err);
void sl_volume_marcher_deinit(sl_volume_marcher *m); /* zeroed or failed init is fine */

/* One pass into the bound framebuffer (viewport = view's size). vol, b and g
 * come from m's volume; b's mask is rebuilt when the mode's rule, the TF or
 * the isovalue changed. Sets every state it relies on and leaves: its program,
 * texture units 0-4 (volume, TF, runs, min-max, gradient) and 6 (focus:
 * opaque depth), the SSBO at binding 5, the camera UBO at binding 0, VAO 0,
 * depth test on with GL_GREATER, depth writes on, blending off, culling off.
 * stats: primitives (pixels), samples taken and skipped, culled (bricks not
 * visible). SL_ERR_INVALID for a mode out of range, no tf, a negative or
 * NaN step or focus radius (nothing drawn); SL_ERR_GPU when a variant fails
 * to compile (the log in err). */
sl_status sl_volume_marcher_draw(sl_volume_marcher *m, const sl_volume_texture *vol, sl_volume_bricks *b,
                                 const sl_volume_geometry *g, const sl_view *view, const sl_volume_march_desc *d,
                                 sl_render_stats *stats, sl_err *err);

/* Work counters: process-wide totals, never reset (compare two readings).
 * Render thread only, unlocked. */
typedef struct sl_volume_counters {
    unsigned long texture_uploads;   /* 3D volume textures created */
    unsigned long minmax_builds;     /* min-max grids built */
    unsigned long mask_builds;       /* visible-brick masks rebuilt and uploaded */
    unsigned long tf_uploads;        /* TF textures uploaded */
    unsigned long gradient_builds;   /* precomputed gradient textures built */
} sl_volume_counters;
void sl_volume_get_counters(sl_volume_counters *out);

#endif
