/* image.c — lifetime of the image buffers declared in sl_image.h.
 *
 * Only the deinit functions live here; the format codecs are in png.c,
 * pfm.c and jpeg.c. Any thread. Invariant: a deinit'ed struct is all zero,
 * so deinit is idempotent and safe on a zero-initialized struct.
 */
#include "sl_image.h"

#include <stdlib.h>
#include <string.h>

void sl_image_deinit(sl_image *img)
{
    if (!img)
        return;
    free(img->rgba);
    memset(img, 0, sizeof *img);
}

void sl_depth_image_deinit(sl_depth_image *img)
{
    if (!img)
        return;
    free(img->values);
    memset(img, 0, sizeof *img);
}
