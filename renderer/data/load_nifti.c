/* load_nifti.c — NIfTI-1 single-file volumes (.nii; .nii.gz arrives here
 * already gunzipped by sl_load_file, which inflates only the 348-byte
 * header and then vox_offset + the voxel bytes: sl_load_nifti_content_size).
 *
 * Reads the 348-byte header in either byte order (sizeof_hdr tells which),
 * dim[0..3] (dims 4..7 must be 1, except dim[5] = 3 with dim[4] = 1: a vector
 * field stored as three planes, interleaved on load), datatype u8, s8, s16,
 * u16, s32, u32, f32, f64, pixdim[1..3] (absolute values; 0 means unknown ->
 * 1), vox_offset (at most 64 MiB), scl_slope / scl_inter (applied, giving
 * f32, unless the slope is 0 or the pair is the identity), and the sform
 * (or, without one, the qform: quaternion, qfac and offsets). When its axes
 * are world axes in any order and sign (e.g. the x flip of LPS-stored
 * data), the voxels are permuted / mirrored so every world position is kept
 * (sl_load_orient_volume); spacing then comes from the sform/qform. An
 * oblique (rotated) sform/qform is not honoured: axes stay axis-aligned with
 * pixdim spacing and only its offsets are used. Does not read .hdr/.img
 * pairs ("ni1"), Analyze 7.5, NIfTI-2, complex or RGB types, extensions
 * (skipped). Vector components are kept as stored. Any thread; no GL.
 * Invariant: nothing is allocated before vox_offset + the voxel bytes are
 * known to lie inside the buffer.
 */
#include "load_common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NIFTI1_HEADER_SIZE 348
/* Largest vox_offset (header + extensions) accepted: real extensions are
 * kilobytes; this keeps a lying header from making a .nii.gz inflate far. */
#define NIFTI_MAX_VOX_OFFSET (64 * 1024 * 1024)

enum {
    DT_UINT8 = 2, DT_INT16 = 4, DT_INT32 = 8, DT_FLOAT32 = 16, DT_FLOAT64 = 64,
    DT_INT8 = 256, DT_UINT16 = 512, DT_UINT32 = 768
};

typedef struct nifti_reader {
    const uint8_t *h;
    int swap;
} nifti_reader;

static void swap_bytes(uint8_t *b, size_t w)
{
    for (size_t k = 0; k < w / 2; k++) {
        uint8_t t = b[k];
        b[k] = b[w - 1 - k];
        b[w - 1 - k] = t;
    }
}

static int32_t get_i32(const nifti_reader *r, size_t off)
{
    uint8_t b[4];
    memcpy(b, r->h + off, 4);
    if (r->swap)
        swap_bytes(b, 4);
    int32_t v;
    memcpy(&v, b, 4);
    return v;
}

static int16_t get_i16(const nifti_reader *r, size_t off)
{
    uint8_t b[2];
    memcpy(b, r->h + off, 2);
    if (r->swap)
        swap_bytes(b, 2);
    int16_t v;
    memcpy(&v, b, 2);
    return v;
}

static double get_f32(const nifti_reader *r, size_t off)
{
    uint8_t b[4];
    memcpy(b, r->h + off, 4);
    if (r->swap)
        swap_bytes(b, 4);
    float v;
    memcpy(&v, b, 4);
    return v;
}

static int source_type(int datatype, sl_src_type *t)
{
    switch (datatype) {
    case DT_UINT8: *t = SL_SRC_U8; return 1;
    case DT_INT8: *t = SL_SRC_S8; return 1;
    case DT_INT16: *t = SL_SRC_S16; return 1;
    case DT_UINT16: *t = SL_SRC_U16; return 1;
    case DT_INT32: *t = SL_SRC_S32; return 1;
    case DT_UINT32: *t = SL_SRC_U32; return 1;
    case DT_FLOAT32: *t = SL_SRC_F32; return 1;
    case DT_FLOAT64: *t = SL_SRC_F64; return 1;
    }
    return 0;
}

/* What the header says, checked on its own (the 348 bytes). */
typedef struct nifti_header {
    nifti_reader r;
    int dims[3], comps;
    sl_src_type type;
    size_t offset, n, needed; /* vox_offset, values, voxel bytes */
    double spacing[3], slope, inter;
    int scaled;
    double origin[3];
    int oriented;             /* axes[][] holds an sform or qform (world step per storage axis) */
    double axes[3][3];
} nifti_header;

/* Checks every header field that does not depend on the file's size.
 * `size` >= 348. */
static sl_status parse_header(const uint8_t *data, const char *name, nifti_header *h, sl_err *err)
{
    memset(h, 0, sizeof *h);
    nifti_reader r = {data, 0};
    int32_t native = get_i32(&r, 0);
    r.swap = 1;
    int32_t swapped = get_i32(&r, 0);
    r.swap = native != NIFTI1_HEADER_SIZE;
    h->r = r;
    if (native != NIFTI1_HEADER_SIZE && swapped != NIFTI1_HEADER_SIZE) {
        if (native == 540 || swapped == 540)
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: field 'sizeof_hdr' is 540: NIfTI-2, unsupported (NIfTI-1 only)", name);
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'sizeof_hdr' is not 348 in either byte order: not NIfTI-1",
                          name);
    }
    const uint8_t *magic = data + 344;
    if (memcmp(magic, "ni1\0", 4) == 0)
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "%s: field 'magic' is 'ni1': a .hdr/.img pair, unsupported (single-file .nii only)", name);
    if (memcmp(magic, "n+1\0", 4) != 0)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'magic' is not 'n+1' (Analyze 7.5 or corrupt), unsupported",
                          name);

    int dim[8];
    for (int i = 0; i < 8; i++)
        dim[i] = get_i16(&r, 40 + 2 * (size_t)i);
    if (dim[0] < 1 || dim[0] > 7)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'dim[0]' is %d, must be 1..7", name, dim[0]);
    for (int i = dim[0] + 1; i < 8; i++)
        dim[i] = 1; /* unused dimensions are 1 whatever the file holds */
    for (int i = 1; i <= dim[0]; i++)
        if (dim[i] < 1)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'dim[%d]' is %d, must be >= 1", name, i, dim[i]);
    int comps = 1;
    if (dim[4] == 1 && dim[5] == 3 && dim[6] == 1 && dim[7] == 1)
        comps = 3;
    else if (dim[4] != 1 || dim[5] != 1 || dim[6] != 1 || dim[7] != 1)
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "%s: field 'dim' is %d %d %d %d %d %d %d: only 3D volumes (dims 4..7 = 1) and vector fields "
                          "(dim[5] = 3) are supported",
                          name, dim[1], dim[2], dim[3], dim[4], dim[5], dim[6], dim[7]);
    int datatype = get_i16(&r, 70);
    if (!source_type(datatype, &h->type))
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "%s: field 'datatype' is %d, unsupported (2 u8, 256 s8, 4 s16, 512 u16, 8 s32, 768 u32, "
                          "16 f32, 64 f64)",
                          name, datatype);
    unsigned long long values = (unsigned long long)comps;
    for (int c = 1; c <= 3; c++) {
        values *= (unsigned long long)dim[c];
        if (values > SL_MAX_VOXELS)
            return sl_err_set(err, SL_ERR_LIMIT, "%s: field 'dim' is %dx%dx%d x%d, above the limit of %llu values", name,
                              dim[1], dim[2], dim[3], comps, SL_MAX_VOXELS);
    }
    double vox_offset = get_f32(&r, 108);
    if (!isfinite(vox_offset) || vox_offset < NIFTI1_HEADER_SIZE || vox_offset != floor(vox_offset))
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'vox_offset' is %g, must be a whole number >= 348", name,
                          vox_offset);
    if (vox_offset > NIFTI_MAX_VOX_OFFSET)
        return sl_err_set(err, SL_ERR_LIMIT,
                          "%s: field 'vox_offset' is %.0f, above the limit of %d (header plus extensions)", name,
                          vox_offset, NIFTI_MAX_VOX_OFFSET);
    h->offset = (size_t)vox_offset;
    h->n = (size_t)values;
    h->needed = h->n * sl_src_type_size(h->type);
    h->comps = comps;
    for (int c = 0; c < 3; c++)
        h->dims[c] = dim[c + 1];

    double pixdim[4];
    for (int c = 0; c < 4; c++)
        pixdim[c] = get_f32(&r, 76 + 4 * (size_t)c);
    for (int c = 0; c < 3; c++) {
        double s = fabs(pixdim[c + 1]);
        if (!isfinite(s))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'pixdim[%d]' is not finite", name, c + 1);
        h->spacing[c] = s > 0.0 ? s : 1.0;
    }
    h->slope = get_f32(&r, 112);
    h->inter = get_f32(&r, 116);
    if (isfinite(h->slope) && h->slope != 0.0) {
        if (!isfinite(h->inter))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'scl_inter' is not finite", name);
        h->scaled = h->slope != 1.0 || h->inter != 0.0;
    }
    int sform_code = get_i16(&r, 254), qform_code = get_i16(&r, 252);
    for (int c = 0; c < 3; c++) {
        if (sform_code > 0)
            h->origin[c] = get_f32(&r, 280 + 16 * (size_t)c + 12);
        else if (qform_code > 0)
            h->origin[c] = get_f32(&r, 268 + 4 * (size_t)c);
        if (!isfinite(h->origin[c]))
            return sl_err_set(err, SL_ERR_FORMAT, "%s: field '%s' offset %d is not finite", name,
                              sform_code > 0 ? "srow" : "qoffset", c);
    }
    if (sform_code > 0) {
        /* srow_x/y/z: world row r = sum_c srow_r[c] * index_c + srow_r[3]. */
        for (int row = 0; row < 3; row++)
            for (int c = 0; c < 3; c++)
                h->axes[c][row] = get_f32(&r, 280 + 16 * (size_t)row + 4 * (size_t)c);
        h->oriented = 1;
    } else if (qform_code > 0) {
        /* NIfTI-1 method 2: R from the quaternion (b, c, d), a = sqrt(1 - b^2 - c^2 - d^2);
         * step along axis k is R column k times pixdim[k] (times qfac for k = 3). */
        double b = get_f32(&r, 256), c = get_f32(&r, 260), d = get_f32(&r, 264);
        double a2 = 1.0 - (b * b + c * c + d * d);
        double a = a2 > 0.0 ? sqrt(a2) : 0.0;
        double R[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                          {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                          {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
        double qfac = pixdim[0] < 0.0 ? -1.0 : 1.0;
        for (int k = 0; k < 3; k++)
            for (int row = 0; row < 3; row++)
                h->axes[k][row] = R[row][k] * h->spacing[k] * (k == 2 ? qfac : 1.0);
        h->oriented = 1;
    }
    for (int k = 0; k < 3 && h->oriented; k++)
        for (int row = 0; row < 3; row++)
            if (!isfinite(h->axes[k][row]))
                h->oriented = 0; /* unusable: keep pixdim and the offsets */
    return SL_OK;
}

uint64_t sl_load_nifti_content_size(const uint8_t *head, size_t n, int complete)
{
    if (n < NIFTI1_HEADER_SIZE)
        return complete ? n : 0;
    nifti_header h;
    sl_err err = {0};
    if (parse_header(head, NULL, &h, &err) != SL_OK)
        return NIFTI1_HEADER_SIZE;
    return (uint64_t)h.offset + (uint64_t)h.needed;
}

sl_status sl_load_nifti(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *name = sl_load_display_name(path);
    if (size < NIFTI1_HEADER_SIZE)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: %zu bytes, shorter than the %d-byte NIfTI-1 header", name, size,
                          NIFTI1_HEADER_SIZE);
    nifti_header hdr;
    sl_status st = parse_header(data, name, &hdr, err);
    if (st != SL_OK)
        return st;
    if (hdr.offset > size)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field 'vox_offset' is %zu, past the end of the %zu-byte file", name,
                          hdr.offset, size);
    const nifti_reader r = hdr.r;
    size_t offset = hdr.offset, n = hdr.n, needed = hdr.needed;
    sl_src_type type = hdr.type;
    int comps = hdr.comps, scaled = hdr.scaled;
    double slope = hdr.slope, inter = hdr.inter;
    if (size - offset < needed)
        return sl_err_set(err, SL_ERR_FORMAT,
                          "%s: %zu voxel bytes after field 'vox_offset' %zu, fields 'dim' and 'datatype' need %zu "
                          "(truncated)",
                          name, size - offset, offset, needed);

    char ds_name[SL_NAME_MAX];
    sl_load_base_name(path, "nifti", ds_name, sizeof ds_name);
    sl_dataset *ds = sl_dataset_create(comps == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, ds_name);
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", name);
    sl_voxel_type target = comps == 3 || scaled ? SL_VOXEL_F32 : sl_src_type_target(type);
    st = sl_volume_alloc(&ds->volume, hdr.dims, comps, target, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    const uint8_t *src = data + offset;
    if (comps == 1) {
        sl_load_convert(ds->volume.data, target, src, type, r.swap, n, scaled, slope, inter);
    } else {
        /* NIfTI stores vector components as planes (dim[5] slowest): interleave. */
        size_t plane = n / 3, w = sl_src_type_size(type);
        float *tmp = malloc(plane * sizeof(float));
        if (!tmp) {
            st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu voxels", name, plane);
            goto fail;
        }
        float *dst = ds->volume.data;
        for (int c = 0; c < 3; c++) {
            sl_load_convert(tmp, SL_VOXEL_F32, src + (size_t)c * plane * w, type, r.swap, plane, scaled, slope, inter);
            for (size_t i = 0; i < plane; i++)
                dst[3 * i + (size_t)c] = tmp[i];
        }
        free(tmp);
    }
    int oriented = 0;
    if (hdr.oriented) {
        st = sl_load_orient_volume(ds, hdr.axes, hdr.origin, &oriented, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "%s", name);
            goto fail;
        }
    }
    if (!oriented) {
        /* No usable sform/qform, or an oblique one: axis-aligned from pixdim and the offsets. */
        for (int c = 0; c < 3; c++)
            ds->volume.spacing[c] = hdr.spacing[c];
        ds->origin = sl_v3(hdr.origin[0], hdr.origin[1], hdr.origin[2]);
    }
    st = sl_dataset_finish_volume(ds, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", name);
        goto fail;
    }
    *out = ds;
    return SL_OK;
fail:
    sl_dataset_destroy(ds);
    return st;
}
