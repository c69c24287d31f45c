/* sl_lr_write.h — writes an LR-spline volume in the SINTEF LRsplines text
 * format (the layout LR::LRSplineVolume::write of the reference library
 * produces: header comments, the line "p1 p2 p3 Nbasis Nline Nel dim rat",
 * then the basis functions, mesh rectangles and elements, each under its
 * comment header). Numbers use %.17g so a read back is exact (the reference
 * writes 16 digits). Non-rational only (rat = 0). Any thread; no GL. */
#ifndef SL_LR_WRITE_H
#define SL_LR_WRITE_H

#include <stdio.h>

#include "sl_lr.h"

/* Writes lr to an open stream. Element and basis ids are their indices.
 * SL_ERR_IO when the stream fails. */
sl_status sl_lr_write(const sl_lr_volume *lr, FILE *f, sl_err *err);

/* Writes lr to the file at path; gzip-compressed (zlib) when the name ends
 * in ".gz". SL_ERR_IO naming the path on failure (a partial file may stay). */
sl_status sl_lr_write_file(const sl_lr_volume *lr, const char *path, sl_err *err);

#endif
