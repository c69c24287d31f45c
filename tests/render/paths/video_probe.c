/* video_probe.c — checks a video that sightline-render wrote, by reading it back (tests/support/video_reader).
 *
 * usage: video-probe VIDEO --frames N --size WxH --codec NAME --fps F
 *                    [--compare PNG --index K --max-mean M [--background R,G,B]]
 * Requires one video stream of libavcodec codec NAME ("h264", "vp9"), exactly
 * N decoded frames of W x H, BT.709 tagged, at F frames per second; with
 * --compare, decoded frame K against the PNG the same render wrote: mean
 * |dRGB| over the PNG's covered pixels (a channel more than 8 off the
 * background, default 26,26,31) at most M. Prints what it measured.
 * exit: 0 pass, 1 a check failed, 2 bad input (usage, unreadable files).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"
#include "video_reader.h"

static int usage(void)
{
    fprintf(stderr, "usage: video-probe VIDEO --frames N --size WxH --codec NAME --fps F\n"
                    "                   [--compare PNG --index K --max-mean M [--background R,G,B]]\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage();
    const char *video = argv[1], *codec = NULL, *png = NULL;
    int frames = -1, w = 0, h = 0, index = 0, bg[3] = {26, 26, 31};
    double fps = 0.0, max_mean = -1.0;
    for (int i = 2; i + 1 < argc; i += 2) {
        const char *o = argv[i], *v = argv[i + 1];
        if (strcmp(o, "--frames") == 0) frames = atoi(v);
        else if (strcmp(o, "--size") == 0 && sscanf(v, "%dx%d", &w, &h) == 2) {}
        else if (strcmp(o, "--codec") == 0) codec = v;
        else if (strcmp(o, "--fps") == 0) fps = atof(v);
        else if (strcmp(o, "--compare") == 0) png = v;
        else if (strcmp(o, "--index") == 0) index = atoi(v);
        else if (strcmp(o, "--max-mean") == 0) max_mean = atof(v);
        else if (strcmp(o, "--background") == 0 && sscanf(v, "%d,%d,%d", &bg[0], &bg[1], &bg[2]) == 3) {}
        else return usage();
    }
    if (argc % 2 || frames < 0 || w < 1 || h < 1 || !codec || !(fps > 0) || (png && max_mean < 0))
        return usage();
    size_t size = (size_t)w * (size_t)h * 4u;
    uint8_t *rgba = png ? malloc(size) : NULL;
    video_info info;
    char msg[512] = "";
    if ((png && !rgba) || video_read(video, index, rgba, size, &info, msg, sizeof msg) != 0) {
        fprintf(stderr, "video-probe: %s\n", msg[0] ? msg : "out of memory");
        free(rgba);
        return 2;
    }
    printf("video-probe: %s, %d frames, %dx%d, %.3f fps, BT.709 %s\n", info.codec, info.frames, info.width,
           info.height, info.fps, info.bt709 ? "yes" : "no");
    int rc = 0;
    if (strcmp(info.codec, codec) != 0 || info.frames != frames || info.width != w || info.height != h ||
        !info.bt709 || fabs(info.fps - fps) > 1e-3) {
        fprintf(stderr, "FAIL: want %s, %d frames, %dx%d, %g fps, BT.709\n", codec, frames, w, h, fps);
        rc = 1;
    }
    if (png && rc == 0) {
        sl_image img = {0};
        sl_err err;
        if (sl_png_read(png, &img, &err) != SL_OK || img.width != w || img.height != h) {
            fprintf(stderr, "video-probe: %s: %s\n", png, img.width ? "size differs from the video" : err.message);
            free(rgba);
            sl_image_deinit(&img);
            return 2;
        }
        double sum = 0.0;
        long covered = 0;
        for (size_t i = 0; i < (size_t)w * h; i++) {
            const uint8_t *p = img.rgba + 4 * i, *q = rgba + 4 * i;
            if (abs(p[0] - bg[0]) <= 8 && abs(p[1] - bg[1]) <= 8 && abs(p[2] - bg[2]) <= 8)
                continue;
            covered++;
            for (int k = 0; k < 3; k++)
                sum += abs((int)p[k] - (int)q[k]);
        }
        double mean = covered ? sum / (3.0 * covered) : 0.0;
        printf("video-probe: frame %d against %s: mean |dRGB| %.2f over %ld covered pixels (max %g)\n", index, png,
               mean, covered, max_mean);
        if (!covered || mean > max_mean) {
            fprintf(stderr, "FAIL: frame %d is %.2f off %s on average (max %g, %ld covered pixels)\n", index, mean, png,
                    max_mean, covered);
            rc = 1;
        }
        sl_image_deinit(&img);
    }
    free(rgba);
    return rc;
}
