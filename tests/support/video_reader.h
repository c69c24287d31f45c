/* video_reader.h — reading a video back for tests, independently of the writer (renderer/image/video_writer.c).
 *
 * Opens the file with libavformat, decodes every frame of its one video
 * stream with libavcodec's decoder, and converts one chosen frame to RGBA
 * with swscale (BT.709 limited range to full-range RGB, the tag the writer
 * sets). Limits: one video stream, frames up to 8192 x 8192. Any thread.
 */
#ifndef VIDEO_READER_H
#define VIDEO_READER_H

#include <stddef.h>
#include <stdint.h>

typedef struct video_info {
    int streams, frames, width, height;
    int bt709;             /* the stream is tagged BT.709 */
    double fps;            /* average frame rate of the stream */
    char codec[32];        /* libavcodec's codec name: "h264", "vp9" */
} video_info;

/* Fills info; when rgba is not NULL and the video has frame `index`, that
 * frame as RGBA8 rows top-down (rgba_size >= width * height * 4). Returns 0,
 * or -1 with a reason in msg. */
int video_read(const char *path, int index, uint8_t *rgba, size_t rgba_size, video_info *info, char *msg,
               size_t msg_size);

#endif
