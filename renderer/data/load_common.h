/* load_common.h — private helpers shared by the volume loaders (NRRD, NIfTI,
 * raw + JSON): file bytes without gunzip, safe resolution of a detached data
 * file beside its header, and voxel conversion from a file's sample type and
 * byte order into the sl_volume types.
 *
 * Not part of the public contract (that is sl_load.h); renderer/data only.
 * Any thread; no GL; no global state.
 * Invariant: a detached file name written in a header cannot climb out of
 * the header's folder (symbolic links placed in the folder are followed).
 */
#ifndef SL_LOAD_COMMON_H
#define SL_LOAD_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include "sl_load.h"

/* Sample types as stored in files; converted to sl_voxel_type on load. */
typedef enum sl_src_type {
    SL_SRC_U8, SL_SRC_S8, SL_SRC_U16, SL_SRC_S16,
    SL_SRC_U32, SL_SRC_S32, SL_SRC_F32, SL_SRC_F64
} sl_src_type;

size_t sl_src_type_size(sl_src_type t);

/* The volume type a file type is stored as: u8, u16 and s16 are kept, s8
 * widens to s16, everything else becomes f32 (u32/s32 above 2^24 and f64
 * lose precision). */
sl_voxel_type sl_src_type_target(sl_src_type t);

/* 1 when this machine stores multi-byte numbers big-endian. */
int sl_load_host_big_endian(void);

/* Converts n samples from src (type src_type, byte-swapped when `swap`) into
 * dst (type dst_type, native order). With `scaled`, dst must be F32 and
 * receives v * slope + inter. src needs n * sl_src_type_size(src_type) bytes;
 * no alignment is required. Cannot fail. */
void sl_load_convert(void *dst, sl_voxel_type dst_type, const uint8_t *src, sl_src_type src_type,
                     int swap, size_t n, int scaled, double slope, double inter);

/* Reads a whole file as it is on disk (no gunzip), refusing more than
 * `limit` bytes. SL_ERR_IO when it cannot be opened or read, SL_ERR_LIMIT
 * when it is larger than limit. *data is malloc'd (never NULL on success). */
sl_status sl_load_read_raw(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err);

/* Resolves `name`, given by the header file `anchor` in its field `field`,
 * to a path in `out`: relative names are taken from anchor's folder and may
 * not contain a ".." component; absolute names must lie inside that folder
 * (compared after resolving symbolic links). anchor NULL -> SL_ERR_UNSUPPORTED
 * (detached data needs a file); escapes -> SL_ERR_FORMAT; too long ->
 * SL_ERR_LIMIT. */
sl_status sl_load_resolve_sibling(const char *anchor, const char *name, const char *field,
                                  char *out, size_t cap, sl_err *err);

/* The file's base name without its folder and without the extensions
 * .gz and one more ("ch2.nii.gz" -> "ch2", "head.nrrd" -> "head"); `fallback`
 * when path is NULL or the result is empty. */
void sl_load_base_name(const char *path, const char *fallback, char *out, size_t cap);

/* path, or "(memory)" when NULL: for messages. */
const char *sl_load_display_name(const char *path);

#endif
