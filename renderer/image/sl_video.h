/* sl_video.h — writing frames to a video file (libavformat + libavcodec + libswscale).
 *
 * The container and codec follow the file name: .mp4 is H.264 (libx264,
 * constant quality CRF, default 18 — visually lossless for rendered
 * images — preset "medium"), .webm is VP9 (libvpx-vp9, constant quality
 * CRF, default 24, bit rate unbounded, "good" deadline, cpu-used 2). Frames
 * are RGBA8 rows top-down, converted to 4:2:0 YUV (BT.709, limited range,
 * tagged so players show the same colours), at a constant frame rate.
 * 4:2:0 needs an even width and height: sl_video_open refuses odd sizes.
 * A writer that fails or is aborted removes its partial file.
 * One thread per writer; libav* logs only errors.
 */
#ifndef SL_VIDEO_H
#define SL_VIDEO_H

#include <stddef.h>
#include <stdint.h>

#include "core/sl_status.h"

#define SL_VIDEO_MAX_SIZE 8192

typedef struct sl_video_writer sl_video_writer;

typedef struct sl_video_desc {
    const char *path;          /* ends in .mp4 or .webm (case-insensitive) */
    int width, height;         /* even, in [2, SL_VIDEO_MAX_SIZE] */
    double fps;                /* (0, 240] */
    int crf;                   /* < 0: the codec's default above; else 0..51 (H.264) or 0..63 (VP9) */
} sl_video_desc;

typedef struct sl_video_summary {
    long frames;
    size_t bytes;              /* size of the finished file */
    double seconds;            /* frames / fps */
    const char *codec;         /* "H.264" or "VP9" (static) */
    int crf;                   /* the quality used */
} sl_video_summary;

/* 1 when path names a video this module writes (.mp4 or .webm). */
int sl_video_path_known(const char *path);

/* Checks the description (extension, sizes, fps, crf) without touching any
 * file: SL_ERR_INVALID naming what is wrong. */
sl_status sl_video_check(const sl_video_desc *desc, sl_err *err);

/* Opens the file and its encoder: SL_ERR_INVALID (sl_video_check), SL_ERR_IO
 * (cannot create the file), SL_ERR_UNSUPPORTED (the codec is not in this
 * libavcodec), SL_ERR_NOMEM. */
sl_status sl_video_open(const sl_video_desc *desc, sl_video_writer **out, sl_err *err);

/* Appends one frame (width x height RGBA8, rows top-down). */
sl_status sl_video_write_rgba(sl_video_writer *w, const uint8_t *rgba, sl_err *err);

/* Flushes the encoder, finishes the file and frees the writer (also when it
 * fails: then the file is removed). summary may be NULL. */
sl_status sl_video_close(sl_video_writer *w, sl_video_summary *summary, sl_err *err);

/* Frees the writer and removes its file (after an error elsewhere). NULL is fine. */
void sl_video_abort(sl_video_writer *w);

#endif
