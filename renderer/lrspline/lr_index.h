/* lr_index.h — internal to renderer/lrspline: frees the look-up attached to
 * a model by sl_lr_index (lr_index.c), for sl_lr_free and sl_lr_finish.
 * Any thread that owns lr. */
#ifndef SL_LR_INDEX_H
#define SL_LR_INDEX_H

#include "sl_lr.h"

void sl_lr_drop_index(sl_lr_volume *lr);

#endif
