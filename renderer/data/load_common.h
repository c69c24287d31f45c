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

/* Reads the last `n` bytes of a regular file (NRRD "byte skip: -1").
 * SL_ERR_IO when it cannot be opened or read, or is not a regular file (a
 * device or pipe has no end to count from); SL_ERR_FORMAT when it holds
 * fewer than n bytes. *data is malloc'd (never NULL on success). */
sl_status sl_load_read_tail(const char *path, size_t n, uint8_t **data, sl_err *err);

/* The most compressed bytes a gzip stream inflating to `out` bytes needs:
 * out + out/256 + 64 KiB (deflate's stored blocks add 5 bytes per 64 KiB,
 * members and headers a few dozen bytes). Readers refuse longer input, so
 * a huge file or a stream of empty blocks cannot keep them busy. */
uint64_t sl_load_gzip_input_bound(uint64_t out);

/* A file read in pieces, gunzipped on the fly when asked or when it starts
 * with the gzip magic (SL_STREAM_AUTO). A loader can ask for its header
 * first and then for exactly the bytes the header describes; nothing past
 * the bytes asked for is read, inflated or allocated. Single owner; any
 * thread. */
typedef struct sl_load_stream sl_load_stream;
typedef enum sl_load_stream_mode {
    SL_STREAM_AUTO,  /* gunzip when the file starts with 1f 8b */
    SL_STREAM_RAW,   /* never gunzip */
    SL_STREAM_GZIP   /* the file must be gzip (else SL_ERR_FORMAT) */
} sl_load_stream_mode;

/* SL_ERR_IO when the file cannot be opened or is a directory. */
sl_status sl_load_stream_open(const char *path, sl_load_stream_mode mode, sl_load_stream **out, sl_err *err);
void sl_load_stream_close(sl_load_stream *s); /* NULL is fine */
int sl_load_stream_gzipped(const sl_load_stream *s);
/* 1 for a regular file, with its on-disk size in *file_size (may be NULL). */
int sl_load_stream_regular(const sl_load_stream *s, uint64_t *file_size);

/* Makes the first min(want, content size) bytes of the content available in
 * *data / *size (borrowed: valid until the next call or take); *size < want
 * means the content ended. Never allocates more than `want` bytes and reads
 * at most sl_load_gzip_input_bound(want) compressed bytes (else
 * SL_ERR_LIMIT). SL_ERR_FORMAT for corrupt or truncated gzip, SL_ERR_IO for
 * read errors. */
sl_status sl_load_stream_fill(sl_load_stream *s, uint64_t want, const uint8_t **data, size_t *size, sl_err *err);

/* Hands the content filled so far to the caller (malloc'd, never NULL
 * unless out of memory); the stream keeps nothing. */
uint8_t *sl_load_stream_take(sl_load_stream *s, size_t *size);

/* How many content bytes a loader will read, judged from the first n bytes
 * (`complete`: there are no more). 0: not enough bytes yet, ask again with
 * more (with `complete`, 0 only for n == 0). UINT64_MAX: the header does not say (read the whole file). A header
 * the loader will refuse gives n, so the loader sees it and says why.
 * sl_load_file uses these to read a .nii.gz or .nrrd only as far as its
 * header describes, so a gzip bomb behind a small header costs nothing. */
uint64_t sl_load_nifti_content_size(const uint8_t *head, size_t n, int complete);
uint64_t sl_load_nrrd_content_size(const uint8_t *head, size_t n, int complete);

/* Puts a filled volume into Sightline's frame (storage axes along +x, +y,
 * +z world, spacing > 0) when the file's storage axes are world axes up to
 * order and sign: axes[k] is the world step of storage axis k (NRRD space
 * directions, NIfTI sform/qform columns) and origin the world position of
 * voxel (0,0,0). Each axes[k] must have one non-zero component and the
 * others within 1e-6 of its length, each on a different world axis; then
 * the voxels are permuted and mirrored so every world position is kept:
 * spacing = the step lengths, ds->origin = the world position of the new
 * first voxel (for a negative step, origin - (dims - 1) * length). Vector
 * components are taken as world-frame and kept. *applied = 0 and nothing
 * changes when the axes are oblique, degenerate or not a permutation (the
 * caller then keeps its fallback). SL_ERR_NOMEM only. */
sl_status sl_load_orient_volume(sl_dataset *ds, const double axes[3][3], const double origin[3], int *applied,
                                sl_err *err);

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
