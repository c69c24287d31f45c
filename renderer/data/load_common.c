/* load_common.c — voxel conversion, detached-file resolution and names for
 * the volume loaders (see load_common.h).
 *
 * Does not read or parse any format. Any thread; no GL; no global state.
 * Invariant: a name written in a file cannot climb out of the header's folder:
 * relative names with ".." are refused before touching the disk, absolute
 * names are compared with realpath(). Symbolic links the folder's owner put
 * inside the folder are followed (that is the owner's choice, not the file's).
 */
#include "load_common.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

size_t sl_src_type_size(sl_src_type t)
{
    switch (t) {
    case SL_SRC_U8: case SL_SRC_S8: return 1;
    case SL_SRC_U16: case SL_SRC_S16: return 2;
    case SL_SRC_U32: case SL_SRC_S32: case SL_SRC_F32: return 4;
    case SL_SRC_F64: return 8;
    }
    return 1;
}

sl_voxel_type sl_src_type_target(sl_src_type t)
{
    switch (t) {
    case SL_SRC_U8: return SL_VOXEL_U8;
    case SL_SRC_S8: case SL_SRC_S16: return SL_VOXEL_S16;
    case SL_SRC_U16: return SL_VOXEL_U16;
    default: return SL_VOXEL_F32;
    }
}

int sl_load_host_big_endian(void)
{
    const uint16_t probe = 0x0102;
    uint8_t first;
    memcpy(&first, &probe, 1);
    return first == 0x01;
}

/* Reads sample i of src as double, swapping bytes when asked. */
static double read_sample(const uint8_t *src, sl_src_type t, int swap, size_t i)
{
    size_t w = sl_src_type_size(t);
    uint8_t b[8];
    memcpy(b, src + i * w, w);
    if (swap)
        for (size_t k = 0; k < w / 2; k++) {
            uint8_t tmp = b[k];
            b[k] = b[w - 1 - k];
            b[w - 1 - k] = tmp;
        }
    switch (t) {
    case SL_SRC_U8: return b[0];
    case SL_SRC_S8: return (int8_t)b[0];
    case SL_SRC_U16: { uint16_t v; memcpy(&v, b, 2); return v; }
    case SL_SRC_S16: { int16_t v; memcpy(&v, b, 2); return v; }
    case SL_SRC_U32: { uint32_t v; memcpy(&v, b, 4); return v; }
    case SL_SRC_S32: { int32_t v; memcpy(&v, b, 4); return v; }
    case SL_SRC_F32: { float v; memcpy(&v, b, 4); return v; }
    case SL_SRC_F64: { double v; memcpy(&v, b, 8); return v; }
    }
    return 0.0;
}

void sl_load_convert(void *dst, sl_voxel_type dst_type, const uint8_t *src, sl_src_type src_type,
                     int swap, size_t n, int scaled, double slope, double inter)
{
    /* Same width, no scaling: a byte copy plus an in-place swap is exact. */
    if (!scaled && sl_voxel_type_size(dst_type) == sl_src_type_size(src_type) &&
        ((dst_type == SL_VOXEL_U8 && src_type == SL_SRC_U8) ||
         (dst_type == SL_VOXEL_U16 && src_type == SL_SRC_U16) ||
         (dst_type == SL_VOXEL_S16 && src_type == SL_SRC_S16) ||
         (dst_type == SL_VOXEL_F32 && src_type == SL_SRC_F32))) {
        size_t w = sl_src_type_size(src_type);
        memcpy(dst, src, n * w);
        if (swap && w > 1) {
            uint8_t *d = dst;
            for (size_t i = 0; i < n; i++)
                for (size_t k = 0; k < w / 2; k++) {
                    uint8_t tmp = d[i * w + k];
                    d[i * w + k] = d[i * w + w - 1 - k];
                    d[i * w + w - 1 - k] = tmp;
                }
        }
        return;
    }
    for (size_t i = 0; i < n; i++) {
        double v = read_sample(src, src_type, swap, i);
        if (scaled)
            v = v * slope + inter;
        switch (dst_type) {
        case SL_VOXEL_U8: ((uint8_t *)dst)[i] = (uint8_t)v; break;   /* only from u8 */
        case SL_VOXEL_U16: ((uint16_t *)dst)[i] = (uint16_t)v; break; /* only from u16 */
        case SL_VOXEL_S16: ((int16_t *)dst)[i] = (int16_t)v; break;  /* from s8 / s16 */
        case SL_VOXEL_F32:
            /* Out-of-range doubles become +-inf rather than an undefined conversion. */
            if (v > FLT_MAX) v = INFINITY;
            else if (v < -FLT_MAX) v = -INFINITY;
            ((float *)dst)[i] = (float)v;
            break;
        }
    }
}

sl_status sl_load_orient_volume(sl_dataset *ds, const double axes[3][3], const double origin[3], int *applied,
                                sl_err *err)
{
    *applied = 0;
    sl_volume *v = &ds->volume;
    int perm[3], sign[3], used[3] = {0, 0, 0};
    double len[3];
    for (int k = 0; k < 3; k++) {
        const double *a = axes[k];
        double norm = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        if (!(norm > 0.0) || !isfinite(norm))
            return SL_OK;
        int m = 0;
        for (int c = 1; c < 3; c++)
            if (fabs(a[c]) > fabs(a[m]))
                m = c;
        for (int c = 0; c < 3; c++)
            if (c != m && fabs(a[c]) > 1e-6 * norm)
                return SL_OK; /* oblique */
        if (used[m])
            return SL_OK; /* two storage axes along one world axis */
        used[m] = 1;
        perm[k] = m;
        sign[k] = a[m] < 0.0 ? -1 : 1;
        len[k] = fabs(a[m]);
    }
    int dims[3];
    double spacing[3], o[3];
    for (int k = 0; k < 3; k++) {
        int m = perm[k];
        dims[m] = v->dims[k];
        spacing[m] = len[k];
        o[m] = origin[m] - (sign[k] < 0 ? (double)(v->dims[k] - 1) * len[k] : 0.0);
    }
    int identity = 1;
    for (int k = 0; k < 3; k++)
        identity &= perm[k] == k && sign[k] > 0;
    if (!identity) {
        size_t elem = sl_voxel_type_size(v->type) * (size_t)v->components;
        size_t total = (size_t)v->dims[0] * (size_t)v->dims[1] * (size_t)v->dims[2];
        uint8_t *dst = malloc(total * elem);
        if (!dst)
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu voxels", total);
        const uint8_t *src = v->data;
        /* Destination stride of each source axis, and where source index 0 lands. */
        size_t dstride[3] = {1, (size_t)dims[0], (size_t)dims[0] * (size_t)dims[1]};
        ptrdiff_t step[3];
        size_t base = 0;
        for (int k = 0; k < 3; k++) {
            size_t st = dstride[perm[k]];
            step[k] = sign[k] > 0 ? (ptrdiff_t)st : -(ptrdiff_t)st;
            if (sign[k] < 0)
                base += (size_t)(v->dims[k] - 1) * st;
        }
        size_t i = 0;
        for (int z = 0; z < v->dims[2]; z++)
            for (int y = 0; y < v->dims[1]; y++) {
                size_t d = (size_t)((ptrdiff_t)base + (ptrdiff_t)z * step[2] + (ptrdiff_t)y * step[1]);
                for (int x = 0; x < v->dims[0]; x++, i++, d = (size_t)((ptrdiff_t)d + step[0]))
                    memcpy(dst + d * elem, src + i * elem, elem);
            }
        free(v->data);
        v->data = dst;
    }
    for (int c = 0; c < 3; c++) {
        v->dims[c] = dims[c];
        v->spacing[c] = spacing[c];
    }
    ds->origin = sl_v3(o[0], o[1], o[2]);
    *applied = 1;
    return SL_OK;
}

const char *sl_load_display_name(const char *path)
{
    return path ? path : "(memory)";
}

/* Copies anchor's folder (without the trailing '/') into out; "." when none. */
static int folder_of(const char *anchor, char *out, size_t cap)
{
    const char *slash = strrchr(anchor, '/');
    int n;
    if (!slash)
        n = snprintf(out, cap, ".");
    else if (slash == anchor)
        n = snprintf(out, cap, "/");
    else
        n = snprintf(out, cap, "%.*s", (int)(slash - anchor), anchor);
    return n >= 0 && (size_t)n < cap;
}

/* 1 when some '/'-separated component of name is exactly "..". */
static int has_dotdot(const char *name)
{
    const char *p = name;
    while (*p) {
        const char *end = strchr(p, '/');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        if (len == 2 && p[0] == '.' && p[1] == '.')
            return 1;
        if (!end)
            break;
        p = end + 1;
    }
    return 0;
}

sl_status sl_load_resolve_sibling(const char *anchor, const char *name, const char *field,
                                  char *out, size_t cap, sl_err *err)
{
    if (!anchor)
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "(memory): field '%s' names a detached file '%s', which needs the header's path",
                          field, name);
    if (!name[0])
        return sl_err_set(err, SL_ERR_FORMAT, "%s: field '%s' is empty", anchor, field);
    char folder[PATH_MAX];
    if (!folder_of(anchor, folder, sizeof folder))
        return sl_err_set(err, SL_ERR_LIMIT, "%s: path longer than %d bytes", anchor, PATH_MAX);
    if (name[0] != '/') {
        if (has_dotdot(name))
            return sl_err_set(err, SL_ERR_FORMAT,
                              "%s: field '%s' names '%s', which leaves the header's folder (\"..\" is refused)",
                              anchor, field, name);
        int n = snprintf(out, cap, "%s/%s", folder, name);
        if (n < 0 || (size_t)n >= cap)
            return sl_err_set(err, SL_ERR_LIMIT, "%s: field '%s': resolved path longer than %zu bytes",
                              anchor, field, cap - 1);
        return SL_OK;
    }
    /* Absolute: allowed only inside the header's folder, links resolved. */
    char *real_folder = realpath(folder, NULL);
    char *real_file = realpath(name, NULL);
    sl_status st = SL_OK;
    if (!real_folder || !real_file) {
        st = sl_err_set(err, SL_ERR_IO, "%s: field '%s': cannot resolve '%s': %s", anchor, field,
                        real_folder ? name : folder, strerror(errno));
    } else {
        size_t fl = strlen(real_folder);
        int inside = strncmp(real_file, real_folder, fl) == 0 &&
                     (real_file[fl] == '/' || (fl == 1 && real_folder[0] == '/'));
        if (!inside)
            st = sl_err_set(err, SL_ERR_FORMAT,
                            "%s: field '%s' names '%s', which is outside the header's folder %s",
                            anchor, field, name, real_folder);
        else {
            int n = snprintf(out, cap, "%s", real_file);
            if (n < 0 || (size_t)n >= cap)
                st = sl_err_set(err, SL_ERR_LIMIT, "%s: field '%s': path longer than %zu bytes",
                                anchor, field, cap - 1);
        }
    }
    free(real_folder);
    free(real_file);
    return st;
}

void sl_load_base_name(const char *path, const char *fallback, char *out, size_t cap)
{
    if (cap == 0)
        return;
    out[0] = '\0';
    if (path) {
        const char *base = strrchr(path, '/');
        base = base ? base + 1 : path;
        size_t len = strlen(base);
        if (len > 3 && base[len - 3] == '.' && tolower((unsigned char)base[len - 2]) == 'g' &&
            tolower((unsigned char)base[len - 1]) == 'z')
            len -= 3;
        for (size_t i = len; i > 0; i--)
            if (base[i - 1] == '.') {
                len = i - 1;
                break;
            }
        if (len >= cap)
            len = cap - 1;
        memcpy(out, base, len);
        out[len] = '\0';
    }
    if (!out[0])
        snprintf(out, cap, "%s", fallback ? fallback : "");
}
