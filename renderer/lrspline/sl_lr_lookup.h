/* sl_lr_lookup.h — element look-up structures of an LR-spline volume, CPU
 * queries and their flattened GPU form (issue 15; paper 003, sections 3.2,
 * 3.2.1 and Algorithm 1).
 *
 * Built from the element boxes and the domain of a finished sl_lr_volume
 * only. Every structure answers exactly what sl_lr_find_element_linear
 * answers (the element rule of sl_lr.h: half-open boxes, closed at the
 * domain's upper face; -1 outside the closed domain or for NaN), on the CPU
 * for double points and on the GPU for float points (see "GPU exactness").
 *
 *  texture  — every knot of direction d lies on a regular grid of n[d] cells
 *             (n[d] <= SL_LR_TEXTURE_MAX_AXIS, n0*n1*n2 <=
 *             SL_LR_TEXTURE_MAX_CELLS): one element index per cell, O(1).
 *             Refused (SL_ERR_UNSUPPORTED, saying which direction and limit)
 *             otherwise.
 *  octree   — every knot is domain_lo + k * side / 2^i (i <=
 *             SL_LR_OCTREE_MAX_LEVEL, relative tolerance 1e-12 of side, the
 *             knot itself becomes the split plane); a cell is split in 8
 *             while more than one element meets it. Refused naming the first
 *             non-dyadic knot (element, direction, value); SL_ERR_LIMIT past
 *             SL_LR_OCTREE_MAX_CELLS split cells.
 *  kdtree   — one depth-balanced k-d tree: at a node with more than one
 *             element, for each direction the median of the element faces
 *             strictly inside the node's cell is a candidate plane; the one
 *             whose larger side holds the fewest elements wins (ties: fewer
 *             elements cut, then x before y before z). Point < plane goes
 *             left, else right. Leaves hold one element.
 *  kdforest — the domain cut into I x J x K regular blocks, one such k-d
 *             tree per block over the elements meeting the block; a block
 *             met by one element stores it directly (depth 0).
 *  auto     — the texture where it applies, else the k-d forest of
 *             SL_LR_FOREST_DEFAULT_AXIS^3 blocks. Measured by bench-lr-lookup
 *             (bench/RESULTS.md, llvmpipe, loaded machine): the texture is
 *             the fastest where it applies; on the GPU the 32^3 forest beat
 *             the octree in 2 of 3 runs on a dyadic refined mesh and one
 *             k-d tree by 3-6x; 32^3 was best or near-best on the uniform
 *             and dyadic refined meshes (8^3-16^3 did better on the
 *             non-dyadic one, whose elements straddle more blocks).
 *
 * Any thread for building and CPU queries (read-only once built); the GPU
 * functions need the render thread's GL context.
 */
#ifndef SL_LR_LOOKUP_H
#define SL_LR_LOOKUP_H

#include <stddef.h>
#include <stdint.h>

#include "sl_lr.h"

#define SL_LR_TEXTURE_MAX_AXIS 1024u
#define SL_LR_TEXTURE_MAX_CELLS (16u * 1024u * 1024u)   /* 64 MiB of uint32 */
#define SL_LR_OCTREE_MAX_LEVEL 30
#define SL_LR_OCTREE_MAX_CELLS (1024u * 1024u)            /* split cells, 44 B each on the GPU */
#define SL_LR_FOREST_MAX_BLOCKS (2u * 1024u * 1024u)   /* 128^3 */
#define SL_LR_FOREST_DEFAULT_AXIS 32                   /* see RESULTS.md */

typedef enum sl_lr_lookup_kind {
    SL_LR_LOOKUP_AUTO = 0,
    SL_LR_LOOKUP_TEXTURE = 1,
    SL_LR_LOOKUP_OCTREE = 2,
    SL_LR_LOOKUP_KDTREE = 3,
    SL_LR_LOOKUP_KDFOREST = 4
} sl_lr_lookup_kind;

/* "auto", "texture", "octree", "kdtree", "kdforest"; SL_ERR_INVALID naming
 * the accepted words otherwise. */
sl_status sl_lr_lookup_kind_parse(const char *name, sl_lr_lookup_kind *kind, sl_err *err);
const char *sl_lr_lookup_kind_name(sl_lr_lookup_kind kind);

/* A k-d node (kdtree, kdforest). Internal: axis 0..2, split, left child at
 * `index`, right child at this node + 1 (Algorithm 1). Leaf: axis 3,
 * element at `index` (UINT32_MAX: none, only in an empty block). */
typedef struct sl_lr_kdnode {
    double split;
    uint32_t index;
    uint32_t axis;
} sl_lr_kdnode;

/* An octree cell that is split: its three middle planes and its 8 children
 * (child c holds the half p[d] >= mid[d] when bit d of c is set). A child
 * ref with bit 31 set is a leaf (element in the low 31 bits, 0x7FFFFFFF
 * none), else the index of another split cell. */
typedef struct sl_lr_octnode {
    double mid[3];
    uint32_t child[8];
} sl_lr_octnode;

#define SL_LR_REF_LEAF 0x80000000u
#define SL_LR_REF_NONE 0x7FFFFFFFu

typedef struct sl_lr_lookup_stats {
    size_t trees;            /* blocks (forest), 1 (kdtree, octree), cells (texture) */
    size_t nodes;            /* k-d nodes / octree split cells (texture: 0) */
    size_t direct_blocks;    /* forest blocks holding their element directly */
    int depth_min, depth_max;/* over trees: a tree's depth = its longest root-leaf path */
    double depth_mean, depth_var;
    size_t bytes;            /* CPU arrays; the GPU form is in sl_lr_lookup_gpu_bytes */
    double build_ms;
} sl_lr_lookup_stats;

typedef struct sl_lr_lookup {
    sl_lr_lookup_kind kind;          /* never AUTO once built */
    double lo[3], hi[3];             /* domain */
    /* texture and kdforest: n[d] cells/blocks; cell c of d spans
     * [planes[d][c], planes[d][c+1]), the last closed at hi. */
    int n[3];
    double *planes[3];
    uint32_t *heads;                 /* n0*n1*n2, x fastest. texture: element;
                                        kdforest/kdtree: SL_LR_REF_LEAF|element or a node index */
    size_t node_count;
    sl_lr_kdnode *nodes;
    size_t oct_count;
    sl_lr_octnode *oct;
    uint32_t oct_root;               /* a ref as in sl_lr_octnode.child */
    sl_lr_lookup_stats stats;
} sl_lr_lookup;

/* Builds `kind` into the caller's *lk (owns its arrays; the volume is only
 * read); forest_axis = blocks per direction for kdforest (0: the default;
 * 1..128; ignored by the others). Refusals as above (SL_ERR_UNSUPPORTED,
 * the octree's cell cap SL_ERR_LIMIT), SL_ERR_INVALID for an empty domain
 * or overlapping elements, SL_ERR_NOMEM; on failure *lk is zeroed, owning
 * nothing. The volume needs elements and domain_lo/hi (sl_lr_finish). */
sl_status sl_lr_lookup_init(sl_lr_lookup *lk, const sl_lr_volume *lr, sl_lr_lookup_kind kind,
                            int forest_axis, sl_err *err);
/* Frees the arrays; safe on a zeroed or failed *lk. */
void sl_lr_lookup_deinit(sl_lr_lookup *lk);

/* The element containing p (element rule), -1 outside or for NaN. */
long sl_lr_lookup_find(const sl_lr_lookup *lk, const double p[3]);

/* The look-up the model carries (sl_lr_index: always the `auto` build) when
 * it is exactly what sl_lr_lookup_init(kind, forest_axis) would build on
 * lr: kind auto; texture when the index is the texture; kdforest with
 * forest_axis 0 or the default when the index fell back to the default
 * forest. NULL otherwise (no index, or another structure): build one.
 * Lets the GPU blocks reuse the index instead of building it twice
 * (lr_index.c). */
const sl_lr_lookup *sl_lr_index_match(const sl_lr_volume *lr, sl_lr_lookup_kind kind, int forest_axis);

/* ---- GPU form (lr_lookup_gpu.c, lr_lookup.glsl) ----
 *
 * Three std430 SSBOs of 32-bit words, bound to fixed points:
 *   binding 10 LrLookupHeads  { uint lr_heads[]; }  texture/forest/kdtree:
 *              one word per cell/block, x fastest (as sl_lr_lookup.heads);
 *              octree: one word, the root ref.
 *   binding 11 LrLookupNodes  { uint lr_nodes[]; }  kd: 2 words per node,
 *              [0] = axis << 30 | index (axis 3 = leaf; index 0x3FFFFFFF =
 *              no element), [1] = floatBitsToUint(split);  octree: 11 words
 *              per split cell, [0..2] mid planes (float bits), [3..10] child
 *              refs (bit 31 leaf, else the cell's index).
 *   binding 12 LrLookupPlanes { float lr_planes[]; } texture/forest: the
 *              cell/block planes of x (n0+1), then y (n1+1), then z (n2+1).
 *   (6..9 are the Bézier blocks' of sl_lr_bezier.h.)
 *   texture unit 8: when asked for, the heads again as a GL_R32UI 3D
 *              texture n0 x n1 x n2 (texture/forest/kdtree; read instead of
 *              binding 10 when the shader #defines LR_LOOKUP_HEADS_TEXTURE,
 *              as the paper does; not faster on llvmpipe, see RESULTS.md).
 * Uniforms (set by sl_lr_lookup_gpu_bind on the given program):
 *   ivec3 lr_lookup_n; vec3 lr_lookup_lo, lr_lookup_hi (domain, rounded
 *   inwards to float); vec3 lr_lookup_origin, lr_lookup_scale (cell index
 *   estimate (p - origin) * scale, corrected against the planes);
 *   int lr_lookup_kind (used when LR_LOOKUP_KIND is not #defined).
 *
 * GPU exactness: every plane s is stored as the smallest float >= s, so
 * for a float p the test p < float_up(s) equals p < s in double; the
 * domain's lower bound is rounded up and its upper bound down the same way.
 * Float points therefore get exactly the CPU (double) answer.
 */
#define SL_LR_LOOKUP_BINDING_HEADS 10
#define SL_LR_LOOKUP_BINDING_NODES 11
#define SL_LR_LOOKUP_BINDING_PLANES 12
#define SL_LR_LOOKUP_UNIT_HEADS 8

typedef struct sl_lr_lookup_gpu {
    unsigned int heads, nodes, planes;   /* GL buffer names */
    unsigned int heads_texture;          /* GL texture name; 0 when not asked for, or octree */
    sl_lr_lookup_kind kind;
    int n[3];
    float lo[3], hi[3], origin[3], scale[3];
    size_t bytes;
} sl_lr_lookup_gpu;

/* Uploads a built structure into GL objects owned by *g (render thread);
 * heads_texture: also the 3D heads texture (for LR_LOOKUP_HEADS_TEXTURE
 * shaders; skipped above GL_MAX_3D_TEXTURE_SIZE). SL_ERR_GPU on a GL error,
 * SL_ERR_NOMEM; on failure *g owns nothing. deinit is safe on a zeroed *g. */
sl_status sl_lr_lookup_gpu_init(sl_lr_lookup_gpu *g, const sl_lr_lookup *lk, int heads_texture, sl_err *err);
/* Binds the buffers to 10..12 and the heads texture to unit 8 and sets the
 * uniforms of `program` (which is made current). */
void sl_lr_lookup_gpu_bind(const sl_lr_lookup_gpu *g, unsigned int program);
void sl_lr_lookup_gpu_deinit(sl_lr_lookup_gpu *g);
/* "#define LR_LOOKUP_KIND k\n" for sl_program_desc.defines: the look-up of
 * that kind alone is compiled (else lr_lookup_kind picks at run time). */
const char *sl_lr_lookup_glsl_define(sl_lr_lookup_kind kind);

#endif
