/* voxel_grid.h — the voxel model of a line set (Kanzler et al., Sec. 3, 5.2).
 *
 * Curves are clipped exactly against a regular grid of unit cubes (grid
 * coordinates = (position - lo) / h, h = world size of one voxel); each piece
 * between two consecutive face crossings becomes one line of the voxel it
 * lies in. The partial pieces before a curve's first and after its last face
 * crossing are dropped as in the paper (Sec. 3.1); a curve that never leaves
 * one voxel therefore contributes nothing (counted in curves_without_pieces).
 * A first vertex lying exactly on a face and moving into its voxel counts as
 * a crossing. Endpoints are quantized to the centres of an N x N subdivision
 * of the face they lie on and bit-packed (see sl_voxel_encode_line). Per voxel
 * a header holds a 32-bit offset and an 8-bit count; a voxel with more lines
 * than max_per_voxel keeps its first ones in curve order and the rest are
 * counted in dropped_overflow — never wrapped.
 * CPU only, any thread, no GL. The GPU build (voxelize_gpu.c) produces the
 * same encoded lines per voxel, attribute byte included.
 */
#ifndef SL_VOXEL_GRID_H
#define SL_VOXEL_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"

#define SL_VOXEL_LINE_ID_MIN_BITS 5   /* local line id: at least 5 bits (the paper's), see sl_voxel_line_id_bits */
#define SL_VOXEL_COUNT_MAX 255        /* what the 8-bit header count can express */
#define SL_VOXEL_MAX_DIM 1024
#define SL_VOXEL_MAX_VOXELS (512ull * 512ull * 512ull)

/* Face ids: 2 * axis + side, side 0 = the face at the lower coordinate. */
enum { SL_VOXEL_FACE_XN = 0, SL_VOXEL_FACE_XP, SL_VOXEL_FACE_YN, SL_VOXEL_FACE_YP,
       SL_VOXEL_FACE_ZN, SL_VOXEL_FACE_ZP };

/* Placement of the grid in dataset coordinates (relative to ds->origin). */
typedef struct sl_voxel_frame {
    int dims[3];        /* voxels along x, y, z, padding included */
    double lo[3];       /* dataset coordinates of grid point (0, 0, 0) */
    double h;           /* voxel side in world units */
} sl_voxel_frame;

/* One clipped piece, exact, in grid coordinates. */
typedef struct sl_voxel_piece {
    int cell[3];
    uint32_t curve;
    double a[3], b[3];   /* entry and exit point */
    int face_a, face_b;  /* faces of `cell` they lie on */
    double attr_a, attr_b; /* attribute at a and b, 0..1 (0 without attribute) */
    uint32_t seg_a, seg_b; /* polyline segment (from vertex seg to seg + 1) holding a and b */
} sl_voxel_piece;

/* Returns 0 to continue, non-zero to stop clipping. */
typedef int (*sl_voxel_piece_fn)(void *user, const sl_voxel_piece *piece);

typedef struct sl_voxel_clip_stats {
    size_t pieces;              /* pieces handed to the callback */
    size_t degenerate;          /* zero-length pieces dropped (entry == exit) */
} sl_voxel_clip_stats;

/* Clips one polyline of n points (grid coordinates, 3n doubles, each within
 * [0, dims]) against the grid; attr (n values in 0..1) may be NULL. Calls fn
 * for every complete piece, in curve order. Points outside the grid are
 * clamped to it. Returns SL_OK, or SL_ERR_INVALID for a non-finite point. */
sl_status sl_voxel_clip_polyline(const int dims[3], const double *points, const double *attr,
                                 size_t n, uint32_t curve, sl_voxel_piece_fn fn, void *user,
                                 sl_voxel_clip_stats *stats, sl_err *err);

/* Places a grid of `resolution` voxels along the longest side of the line
 * positions' bounding box (aspect kept, at least 1 voxel per axis) plus
 * `padding` empty voxels on every side. resolution 0 picks one from the data
 * (sl_voxel_auto_resolution). Fails on a non-line dataset or a grid above
 * SL_VOXEL_MAX_DIM / SL_VOXEL_MAX_VOXELS. */
sl_status sl_voxel_frame_init(sl_voxel_frame *f, const sl_dataset *ds, int resolution, int padding,
                              sl_err *err);

/* The documented automatic grid: about two mean segment lengths per voxel,
 * rounded up to a power of two, clamped to [32, 256] (256 is the paper's
 * recommended grid). */
int sl_voxel_auto_resolution(const sl_dataset *ds);

/* --- Quantization and bit packing ---------------------------------------- */

/* log2(N) for N a power of two in [2, 256], else -1. */
int sl_voxel_quant_bits(int n);

/* Bytes of one encoded line for quantization N (= 2^k): the fewest whole
 * bytes holding 2 * (3 + 2k) endpoint bits, 8 attribute bits and 5 line-id
 * bits (the paper's layout). The local line id then takes every bit left in
 * those bytes (sl_voxel_line_id_bits: 10 for N = 4, 16, 64, 256; 6 for 2, 8,
 * 32, 128), so it is the curve index mod 2^bits at no memory cost: the ray
 * caster merges overlapping hits of one id as one tube, and a wider id makes
 * two different curves with one id (whose tubes overlap, in a dense bundle)
 * rarer. sl_voxel_line_bits = 8 x bytes. */
int sl_voxel_line_bits(int k);
int sl_voxel_line_bytes(int k);
int sl_voxel_line_id_bits(int k);

/* Bin of local point u (in [0,1]^3, on `face`) on an N x N face grid:
 * bin = q(u[s]) + N q(u[t]), s < t the two axes other than the face's,
 * q(x) = min(N - 1, floor(x N)). */
uint32_t sl_voxel_quantize(const double u[3], int face, int n);

/* Local position (in [0,1]^3) of the centre of `bin` on `face`. */
void sl_voxel_dequantize(int face, uint32_t bin, int n, double u[3]);

typedef struct sl_voxel_line {
    int face_a, face_b;
    uint32_t bin_a, bin_b;
    uint32_t attr;      /* 0..255 */
    uint32_t id;        /* 0 .. 2^sl_voxel_line_id_bits(k) - 1 */
} sl_voxel_line;

/* Packs a line, least significant bit first: face_a(3) bin_a(2k) face_b(3)
 * bin_b(2k) attr(8) id(sl_voxel_line_id_bits(k)). Fields must be in range (asserted). */
uint64_t sl_voxel_encode_line(int k, const sl_voxel_line *line);
void sl_voxel_decode_line(int k, uint64_t code, sl_voxel_line *line);

/* --- Attribute byte --------------------------------------------------------
 * One definition for the CPU and the GPU build, bit for bit:
 *  1. per vertex (on the CPU, sl_voxel_attr_normalize, in both builds):
 *     a_i = ((double)v_i - (double)min) / ((double)max - (double)min), or 0
 *     when v_i is not finite or max <= min;
 *  2. at a face crossing at segment parameter t (the clipping's own double):
 *     a = a_i + t * (a_{i+1} - a_i), in that order, no fused multiply-add;
 *  3. per piece (sl_voxel_attr_byte): m = 0.5 * (a_entry + a_exit), clamped
 *     to [0, 1], y = m * 255, byte = floor(y) + (y - floor(y) >= 0.5) — i.e.
 *     round half up (= lround(y)), written out so GLSL can do the same.
 * Steps 2 and 3 use only IEEE double add, subtract, multiply and floor
 * (exact or correctly rounded; the shader marks them `precise`), the only
 * division is done on the CPU and uploaded, so voxelize_gpu.comp.glsl
 * reproduces the bytes exactly. */

/* out[i] = a_i of values[i] (step 1) for the per-vertex attribute at; n values. */
void sl_voxel_attr_normalize(const sl_attribute *at, const float *values, size_t n, double *out);

/* The attribute byte of a piece from its entry and exit values (step 3). */
uint32_t sl_voxel_attr_byte(double attr_a, double attr_b);

/* --- The built grid ------------------------------------------------------ */

typedef struct sl_voxel_grid_desc {
    int resolution;       /* 0: automatic */
    int quant;            /* N: power of two in [2, 256]; 0 = 32 */
    int padding;          /* empty voxels on each side; < 0 = 1 */
    int max_per_voxel;    /* 1..255; 0 = 255 */
    int attribute;        /* per-vertex attribute index for the attribute byte (normalized to
                           * its range, see "Attribute byte"); -1 or out of range = none (byte 0) */
} sl_voxel_grid_desc;

typedef struct sl_voxel_grid {
    sl_voxel_frame frame;
    int quant, quant_bits, line_bytes;
    size_t voxel_count;
    uint32_t *offsets;    /* voxel_count: index of the voxel's first line */
    uint8_t *counts;      /* voxel_count: its number of lines (<= max_per_voxel) */
    size_t line_count;
    uint8_t *lines;       /* line_count * line_bytes bytes, little-endian records, + 8 zero bytes */
    float *density;       /* voxel_count: sum of the dequantized lines' lengths (voxel units) */
    /* Statistics. */
    size_t pieces;              /* non-degenerate pieces clipped */
    size_t degenerate;          /* zero-length pieces (exact or after quantization) dropped */
    size_t dropped_overflow;    /* lines beyond max_per_voxel, dropped */
    size_t capped_voxels;       /* voxels that hit max_per_voxel */
    size_t curves_without_pieces;
    int max_count;              /* largest count before capping */
    int attribute_index;        /* per-vertex attribute used, or -1 */
    double build_ms;
} sl_voxel_grid;

/* Voxelizes a line dataset on the CPU. *grid is zeroed first; on failure it
 * holds nothing. Errors: SL_ERR_INVALID (kind, quant), SL_ERR_LIMIT (grid or
 * line count above limits), SL_ERR_NOMEM. */
sl_status sl_voxel_grid_build(sl_voxel_grid *grid, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                              sl_err *err);
void sl_voxel_grid_deinit(sl_voxel_grid *grid);   /* NULL or zeroed is fine */

/* The 64-bit code of line i (no bounds check beyond an assert). */
uint64_t sl_voxel_grid_line(const sl_voxel_grid *grid, size_t i);

/* Bytes the GPU copy holds (headers 5 B per voxel + lines + density). */
size_t sl_voxel_grid_bytes(const sl_voxel_grid *grid);

/* Linear voxel id of cell c. */
static inline size_t sl_voxel_index(const int dims[3], const int c[3])
{
    return (size_t)c[0] + (size_t)dims[0] * ((size_t)c[1] + (size_t)dims[1] * (size_t)c[2]);
}

#endif
