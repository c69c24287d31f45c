/* test_video.c — the video writer (renderer/image/sl_video.h) against libavformat's own reading.
 *
 * Writes 13 frames of a moving colour pattern (96x64) as H.264/MP4 and as
 * VP9/WebM, then opens each file independently (tests/support/video_reader,
 * libavformat and libavcodec's decoder): one video stream of the right codec, size and frame
 * rate, exactly 13 decoded frames, the BT.709 tag, and the decoded frame 6
 * converted back to RGB (swscale, BT.709 limited range) within a mean
 * |dRGB| bound of the source at the default quality (measured values are
 * printed). Refusals: odd sizes, unknown extensions, a CRF out of range, a
 * missing folder (SL_ERR_IO), and a writer closed with no frames or aborted
 * leaves no file behind. No GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/sl_video.h"
#include "sl_test.h"
#include "video_reader.h"

#define W 96
#define H 64
#define FRAMES 13

static char tmpdir[64];

static void pattern(uint8_t *rgba, int frame)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            uint8_t *p = rgba + 4 * (y * W + x);
            p[0] = (uint8_t)((x * 255) / (W - 1));
            p[1] = (uint8_t)((y * 255) / (H - 1));
            int d = (x - 10 - 5 * frame) * (x - 10 - 5 * frame) + (y - 32) * (y - 32);
            p[2] = d < 144 ? 230 : 40; /* a disc moving right */
            p[3] = 255;
        }
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static void round_trip(const char *name, const char *codec, double max_mean)
{
    char path[128];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    static uint8_t src[FRAMES][W * H * 4], back[W * H * 4];
    sl_video_writer *w = NULL;
    sl_err err = {0};
    SL_CHECK_MSG(sl_video_open(&(sl_video_desc){path, W, H, 12.0, -1}, &w, &err) == SL_OK, "%s", err.message);
    if (!w)
        return;
    for (int f = 0; f < FRAMES; f++) {
        pattern(src[f], f);
        SL_CHECK_MSG(sl_video_write_rgba(w, src[f], &err) == SL_OK, "%s", err.message);
    }
    sl_video_summary sum;
    SL_CHECK_MSG(sl_video_close(w, &sum, &err) == SL_OK, "%s", err.message);
    SL_CHECK(sum.frames == FRAMES && sum.bytes > 0 && fabs(sum.seconds - FRAMES / 12.0) < 1e-12);
    video_info info;
    char msg[256] = "";
    SL_CHECK_MSG(video_read(path, 6, back, sizeof back, &info, msg, sizeof msg) == 0, "%s", msg);
    SL_CHECK_MSG(strcmp(info.codec, codec) == 0, "%s: codec %s", name, info.codec);
    SL_CHECK_MSG(info.frames == FRAMES, "%s: decoded %d frames, wrote %d", name, info.frames, FRAMES);
    SL_CHECK_MSG(info.width == W && info.height == H, "%s: %dx%d", name, info.width, info.height);
    SL_CHECK_MSG(info.bt709, "%s: not tagged BT.709", name);
    SL_CHECK_MSG(fabs(info.fps - 12.0) < 1e-6, "%s: %g fps", name, info.fps);
    double sum_abs = 0.0;
    for (int i = 0; i < W * H; i++)
        for (int k = 0; k < 3; k++)
            sum_abs += abs((int)back[4 * i + k] - (int)src[6][4 * i + k]);
    double mean = sum_abs / (3.0 * W * H);
    printf("%s (%s, CRF %d): %zu bytes, frame 6 mean |dRGB| %.2f\n", name, sum.codec, sum.crf, sum.bytes, mean);
    SL_CHECK_MSG(mean <= max_mean, "%s: decoded frame 6 is %.2f off on average (bound %g)", name, mean, max_mean);
}

static void refusals(void)
{
    sl_video_writer *w = NULL;
    sl_err err = {0};
    char path[128];
    snprintf(path, sizeof path, "%s/odd.mp4", tmpdir);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 97, 64, 24, -1}, &w, &err) == SL_ERR_INVALID && !w);
    SL_CHECK(strstr(err.message, "even") != NULL && !exists(path));
    snprintf(path, sizeof path, "%s/x.avi", tmpdir);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 96, 64, 24, -1}, &w, &err) == SL_ERR_INVALID);
    SL_CHECK(strstr(err.message, "unknown extension") != NULL);
    snprintf(path, sizeof path, "%s/q.mp4", tmpdir);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 96, 64, 24, 52}, &w, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 96, 64, 0, -1}, &w, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_video_open(&(sl_video_desc){"/nonexistent/dir/v.mp4", 96, 64, 24, -1}, &w, &err) == SL_ERR_IO);
    /* No frames: close fails and removes the file; abort removes it too. */
    snprintf(path, sizeof path, "%s/empty.webm", tmpdir);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 96, 64, 24, -1}, &w, &err) == SL_OK && exists(path));
    SL_CHECK(sl_video_close(w, NULL, &err) == SL_ERR_INVALID && strstr(err.message, "no frames") && !exists(path));
    snprintf(path, sizeof path, "%s/aborted.mp4", tmpdir);
    SL_CHECK(sl_video_open(&(sl_video_desc){path, 96, 64, 24, -1}, &w, &err) == SL_OK && exists(path));
    sl_video_abort(w);
    SL_CHECK(!exists(path));
    SL_CHECK(sl_video_path_known("a/B.MP4") && sl_video_path_known("x.webm") && !sl_video_path_known("x.mp4.png"));
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_video_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "cannot create a temporary folder\n");
        return 1;
    }
    round_trip("pattern.mp4", "h264", 2.5);   /* measured 1.47 */
    round_trip("pattern.webm", "vp9", 3.5);   /* measured 1.95 */
    refusals();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", tmpdir);
    SL_TEST_END();
}
