/* sl_dataset.h — the one in-memory model for every dataset Sightline renders.
 *
 * Four kinds: line sets (polylines), regular scalar volumes, regular
 * vector fields and LR-spline volumes (scalar or vector; the model is in
 * lrspline/sl_lr.h, held by pointer). Positions are float and relative to a double `origin`
 * (world = origin + stored), so data 1e5 units from the world origin keeps
 * float precision; loaders and generators set origin to the bounds centre
 * (sl_lines_recentre). Bounds are always world coordinates, in double.
 * All arrays are owned by the dataset and freed by sl_dataset_destroy.
 * Does not load or generate anything (see sl_load.h, sl_generate.h).
 */
#ifndef SL_DATASET_H
#define SL_DATASET_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/sl_math.h"
#include "../core/sl_status.h"

/* Hard limits every loader enforces before it allocates. */
#define SL_MAX_VERTICES   (64u * 1024u * 1024u)   /* per line set */
#define SL_MAX_LINES      (16u * 1024u * 1024u)
#define SL_MAX_ATTRIBUTES 32
#define SL_MAX_VOXELS     (1024ull * 1024ull * 1024ull) /* per volume, all components */
#define SL_NAME_MAX       64

typedef enum sl_dataset_kind {
    SL_DATASET_LINES = 1,
    SL_DATASET_VOLUME = 2,  /* scalar, 1 component */
    SL_DATASET_VECTORS = 4, /* f32 x 3 per voxel */
    SL_DATASET_LR = 8,      /* LR-spline volume, dim 1 or 3 (sl_dataset.lr) */
} sl_dataset_kind;

/* Every kind, in enum order, for code that lists or names them all. */
#define SL_DATASET_KIND_COUNT 4
extern const sl_dataset_kind sl_dataset_kinds[SL_DATASET_KIND_COUNT];

struct sl_lr_volume;

/* A named float array: one value per vertex (line sets: vertex attributes),
 * or one per line (line attributes, e.g. TrackVis per-streamline properties). */
typedef struct sl_attribute {
    char name[SL_NAME_MAX];
    float *values;     /* owned */
    float min, max;    /* of the finite values; 0, 0 when none */
} sl_attribute;

typedef struct sl_lines {
    size_t line_count;
    size_t vertex_count;
    uint32_t *line_offsets;  /* line_count + 1 entries; line k is [off[k], off[k+1]) */
    float *positions;        /* 3 * vertex_count, relative to the dataset origin */
    float *radii;            /* vertex_count, or NULL when the data gives none */
    float *tangents;         /* 3 * vertex_count, or NULL (derivatives as given, not normalized) */
    float *normals;          /* 3 * vertex_count, or NULL */
    int attribute_count;     /* per-vertex scalar attributes */
    sl_attribute attributes[SL_MAX_ATTRIBUTES];
    int line_attribute_count; /* per-line scalar attributes */
    sl_attribute line_attributes[SL_MAX_ATTRIBUTES];
} sl_lines;

typedef enum sl_voxel_type {
    SL_VOXEL_U8, SL_VOXEL_U16, SL_VOXEL_S16, SL_VOXEL_F32
} sl_voxel_type;

/* Bins of a volume's value histogram (sl_volume.histogram). */
#define SL_VOLUME_HISTOGRAM_BINS 256

typedef struct sl_volume {
    int dims[3];             /* voxels along x, y, z; x fastest in memory */
    int components;          /* 1 for scalar volumes, 3 for vector fields (always f32) */
    sl_voxel_type type;
    void *data;              /* dims[0]*dims[1]*dims[2]*components values, native byte order */
    double spacing[3];       /* world units between voxel centres, > 0 */
    double value_min, value_max; /* over all finite values (vector fields: of the magnitude) */
    /* Counts of the finite values (magnitudes) over [value_min, value_max]:
     * bin k = floor((v - min) / (max - min) * BINS), value_max in the last
     * bin; a constant volume has every value in bin 0. Filled with the range. */
    uint64_t histogram[SL_VOLUME_HISTOGRAM_BINS];
    uint64_t finite_count;       /* the sum of histogram */
} sl_volume;

typedef struct sl_dataset {
    sl_dataset_kind kind;
    char name[128];
    sl_vec3 origin;          /* lines: world = origin + position; volumes: world of voxel (0,0,0) */
    sl_vec3 bounds_min, bounds_max; /* world, including radii where given */
    sl_lines lines;          /* kind == SL_DATASET_LINES */
    sl_volume volume;        /* kind == SL_DATASET_VOLUME or SL_DATASET_VECTORS */
    struct sl_lr_volume *lr; /* kind == SL_DATASET_LR: owned (sl_lr_free + free);
                                origin = 0: the parameter domain is the world box */
    double load_ms;
    atomic_int extra_owners;  /* owners besides the creator (sl_dataset_retain) */
} sl_dataset;

/* Allocates an empty dataset of the given kind; NULL on allocation failure. */
sl_dataset *sl_dataset_create(sl_dataset_kind kind, const char *name);
/* Drops one owner's reference; the last one frees everything. NULL is fine. */
void sl_dataset_destroy(sl_dataset *ds);
/* Adds an owner (a cache and the pipelines that draw the same data); each
 * owner calls sl_dataset_destroy once. A dataset is read-only once loaded, so
 * owners on different threads may read it at the same time. Returns ds. */
sl_dataset *sl_dataset_retain(sl_dataset *ds);

/* Allocates the arrays of an empty line set: offsets and positions, plus
 * radii / tangents when asked. Fails with SL_ERR_LIMIT above the limits. */
sl_status sl_lines_alloc(sl_lines *lines, size_t line_count, size_t vertex_count,
                         int with_radii, int with_tangents, sl_err *err);

/* Per-vertex attribute names that carry explicit derivatives (Hermite data,
 * see sl_load_hermite_json): the derivative of attribute NAME along the line
 * parameter is NAME + SL_ATTR_DERIVATIVE_SUFFIX. */
#define SL_ATTR_SCALAR "scalar"
#define SL_ATTR_DERIVATIVE_SUFFIX "_derivative"
#define SL_ATTR_RADIUS_DERIVATIVE "radius_derivative"

/* Per-vertex flow attributes of streamlines (the `tornado` and `abc`
 * generators; any loaded line set may carry them under these names):
 * helicity h = (curl v).v and the vorticity magnitude |curl v|. */
#define SL_ATTR_HELICITY "helicity"
#define SL_ATTR_VORTICITY "vorticity_magnitude"

/* Adds a zero-filled per-vertex (per_line = 0) or per-line attribute and
 * returns its values array, or NULL (err filled) past SL_MAX_ATTRIBUTES. */
float *sl_lines_add_attribute(sl_lines *lines, const char *name, int per_line, sl_err *err);

/* Index of the named per-vertex attribute, or -1. */
int sl_lines_find_attribute(const sl_lines *lines, const char *name);

/* Recomputes attribute ranges, subtracts the bounds centre from the
 * positions (adding it to ds->origin, in double) and sets ds->bounds.
 * Call once after filling a line set with world coordinates given relative
 * to ds->origin (usually 0). Rejects non-finite positions. */
sl_status sl_dataset_finish_lines(sl_dataset *ds, sl_err *err);

/* Allocates the voxel array of an empty volume after checking the limits. */
sl_status sl_volume_alloc(sl_volume *vol, const int dims[3], int components,
                          sl_voxel_type type, sl_err *err);

/* Computes value_min/max, the histogram and ds->bounds from origin, dims and spacing. */
sl_status sl_dataset_finish_volume(sl_dataset *ds, sl_err *err);

/* Voxel value as double (component c) at integer coordinates; no bounds check. */
double sl_volume_value(const sl_volume *vol, size_t x, size_t y, size_t z, int c);

size_t sl_voxel_type_size(sl_voxel_type t);
const char *sl_voxel_type_name(sl_voxel_type t);
const char *sl_dataset_kind_name(sl_dataset_kind k);

/* Radius of the bounding sphere of ds->bounds (> 0; 1 when the bounds are empty). */
double sl_dataset_radius(const sl_dataset *ds);

#endif
