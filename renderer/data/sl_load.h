/* sl_load.h — dataset file loaders: one file per format, one entry point.
 *
 * Every loader parses an in-memory byte buffer (so fuzzers can drive it)
 * and never trusts a header: counts are checked against the bytes present
 * and against the limits in sl_dataset.h before anything is allocated. A
 * truncated, corrupt or hostile file gives SL_ERR_FORMAT or SL_ERR_LIMIT with
 * a message naming the file, the field and the offending value; nothing is
 * leaked and *out stays NULL. Any thread; no GL.
 *
 * `path` is the file's path (used in messages and to resolve detached data
 * files such as NRRD .nhdr "data file:" or a raw volume's JSON sidecar); it
 * may be NULL, in which case detached data is refused. A detached data file
 * is read only as far as its header can use (a link to /dev/zero behind a
 * tiny .nhdr fails at once).
 *
 * Volume orientation: NRRD space directions and NIfTI sform/qform along
 * world axes (any order, either sign: LPS data) are honoured by permuting /
 * mirroring the voxels; oblique (rotated) ones are not (axis-aligned, see
 * load_nrrd.c, load_nifti.c).
 *
 * Raw + JSON sidecar keys (load_raw_json.c; any other key is an error):
 * raw, dims, type (u8 u16 s16 f32) required; spacing, origin, endian
 * ("little"/"big"), components (1 or 3) optional.
 */
#ifndef SL_LOAD_H
#define SL_LOAD_H

#include <stddef.h>
#include <stdint.h>

#include "sl_dataset.h"

/* Largest file (after gzip decompression) any loader reads. */
#define SL_MAX_FILE_BYTES (4ull * 1024ull * 1024ull * 1024ull)

typedef sl_status (*sl_loader_fn)(const uint8_t *data, size_t size, const char *path,
                                  sl_dataset **out, sl_err *err);

/* Lines */
sl_status sl_load_trk(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err);
sl_status sl_load_tck(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err);
sl_status sl_load_vtk(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err); /* POLYDATA LINES or STRUCTURED_POINTS */
sl_status sl_load_obj(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err);
/* Explicit Hermite line data (JSON with "nodes" and "segments", see load_hermite.c):
 * one two-vertex line per segment with radii, tangents and the attributes
 * "scalar", "scalar_derivative", "radius_derivative". Errors name the JSON
 * path ("nodes[3].t[1] ..."). The cJSON form serves inline scene datasets. */
struct cJSON;
sl_status sl_load_hermite_json(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err);
sl_status sl_hermite_dataset_from_json(const struct cJSON *root, const char *name, sl_dataset **out, sl_err *err);
int sl_hermite_json_detect(const struct cJSON *root); /* has "nodes" and "segments" */
/* Volumes */
sl_status sl_load_nrrd(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err); /* .nrrd and .nhdr */
sl_status sl_load_nifti(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err); /* .nii (gunzipped by the caller for .nii.gz) */
sl_status sl_load_raw_json(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err); /* the JSON sidecar; the raw file beside it */
/* LR-spline volumes: the SINTEF LRsplines text format (.lr; .lr.gz gunzipped
 * by the caller), scalar or vector, polynomial, degree <= 3 (load_lr.c). */
sl_status sl_load_lr(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err);
/* 1 when the bytes start (after whitespace) with the LRsplines volume header "# LRSPLINE VOLUME". */
int sl_load_lr_detect(const uint8_t *data, size_t size);

/* Reads a whole file (gunzipping when it starts with the gzip magic) into a
 * malloc'd buffer, refusing more than `limit` bytes. */
sl_status sl_read_file(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err);

/* Gunzips a memory buffer, refusing more than `limit` output bytes. */
sl_status sl_gunzip(const uint8_t *data, size_t size, uint64_t limit, uint8_t **out, size_t *out_size, sl_err *err);

/* Picks the loader from the file name (.trk .tck .vtk .obj .nrrd .nhdr .nii
 * .nii.gz .json .lr .lr.gz), reads the file and loads it; a file of another
 * extension whose content starts with "# LRSPLINE VOLUME" is read as .lr. The dataset's name is the
 * file's base name. NIfTI and NRRD files are read (and inflated) only as
 * far as their header says; other gzipped files may inflate to at most
 * max(64 MiB, 64 x their compressed size) (SL_ERR_LIMIT beyond). */
sl_status sl_load_file(const char *path, sl_dataset **out, sl_err *err);

#endif
