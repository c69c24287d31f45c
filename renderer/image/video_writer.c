/* video_writer.c — frames to an H.264/MP4 or VP9/WebM file through libav*: see sl_video.h.
 * One thread per writer. Invariant: after any failure the writer is freed
 * and its partial file removed, so a caller never finds half a video. */
#include "sl_video.h"

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

struct sl_video_writer {
    AVFormatContext *format;
    AVCodecContext *codec;
    AVStream *stream;
    AVFrame *frame;
    AVPacket *packet;
    struct SwsContext *scale;
    int width, height, crf;
    long frames;
    double fps;
    const char *codec_label;
    char path[4096];
};

typedef struct codec_choice {
    const char *extension, *encoder, *label;
    int crf_default, crf_max;
} codec_choice;

static const codec_choice codecs[] = {
    {".mp4", "libx264", "H.264", 18, 51},
    {".webm", "libvpx-vp9", "VP9", 24, 63},
};

static const codec_choice *choice_for(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    for (size_t i = 0; i < sizeof codecs / sizeof codecs[0]; i++) {
        size_t m = strlen(codecs[i].extension);
        if (n > m && strcasecmp(path + n - m, codecs[i].extension) == 0)
            return &codecs[i];
    }
    return NULL;
}

int sl_video_path_known(const char *path)
{
    return choice_for(path) != NULL;
}

sl_status sl_video_check(const sl_video_desc *d, sl_err *err)
{
    const codec_choice *c = choice_for(d->path);
    if (!c)
        return sl_err_set(err, SL_ERR_INVALID, "video %s: unknown extension (expected .mp4 for H.264 or .webm for VP9)",
                          d->path ? d->path : "(none)");
    if (strlen(d->path) >= sizeof ((sl_video_writer *)0)->path)
        return sl_err_set(err, SL_ERR_INVALID, "video path longer than 4095 bytes");
    if (d->width < 2 || d->height < 2 || d->width > SL_VIDEO_MAX_SIZE || d->height > SL_VIDEO_MAX_SIZE ||
        d->width % 2 || d->height % 2)
        return sl_err_set(err, SL_ERR_INVALID,
                          "video %dx%d: width and height must be even (4:2:0 colour) and in [2, %d]", d->width,
                          d->height, SL_VIDEO_MAX_SIZE);
    if (!(d->fps > 0.0 && d->fps <= 240.0))
        return sl_err_set(err, SL_ERR_INVALID, "video frame rate must be in (0, 240], got %g", d->fps);
    if (d->crf > c->crf_max)
        return sl_err_set(err, SL_ERR_INVALID, "video quality (CRF) for %s must be in [0, %d], got %d", c->label,
                          c->crf_max, d->crf);
    return SL_OK;
}

static sl_status av_fail(sl_err *err, sl_status st, const char *what, int code)
{
    char text[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, text, sizeof text);
    return sl_err_set(err, st, "video: %s: %s", what, text);
}

static void release(sl_video_writer *w, int remove_file)
{
    if (!w)
        return;
    sws_freeContext(w->scale);
    av_frame_free(&w->frame);
    av_packet_free(&w->packet);
    avcodec_free_context(&w->codec);
    if (w->format) {
        if (w->format->pb)
            avio_closep(&w->format->pb);
        avformat_free_context(w->format);
    }
    if (remove_file && w->path[0])
        unlink(w->path);
    free(w);
}

void sl_video_abort(sl_video_writer *w)
{
    release(w, 1);
}

/* Sets up the encoder of choice c on w (format already allocated). */
static sl_status open_encoder(sl_video_writer *w, const codec_choice *c, sl_err *err)
{
    const AVCodec *codec = avcodec_find_encoder_by_name(c->encoder);
    if (!codec)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "video: this libavcodec has no %s encoder (%s)", c->label,
                          c->encoder);
    w->stream = avformat_new_stream(w->format, NULL);
    w->codec = avcodec_alloc_context3(codec);
    if (!w->stream || !w->codec)
        return sl_err_set(err, SL_ERR_NOMEM, "video: out of memory");
    AVRational rate = av_d2q(w->fps, 100000);
    AVCodecContext *cc = w->codec;
    cc->width = w->width;
    cc->height = w->height;
    cc->pix_fmt = AV_PIX_FMT_YUV420P;
    cc->time_base = av_inv_q(rate);
    cc->framerate = rate;
    cc->gop_size = (int)fmin(250.0, ceil(w->fps * 2.0)); /* a key frame every 2 s: seeking in a player */
    cc->color_range = AVCOL_RANGE_MPEG;
    cc->colorspace = AVCOL_SPC_BT709;
    cc->color_primaries = AVCOL_PRI_BT709;
    cc->color_trc = AVCOL_TRC_BT709;
    cc->bit_rate = 0;
    if (w->format->oformat->flags & AVFMT_GLOBALHEADER)
        cc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary *opts = NULL;
    char crf[16];
    snprintf(crf, sizeof crf, "%d", w->crf);
    av_dict_set(&opts, "crf", crf, 0);
    if (strcmp(c->encoder, "libx264") == 0) {
        av_dict_set(&opts, "preset", "medium", 0);
    } else {
        av_dict_set(&opts, "deadline", "good", 0);
        av_dict_set(&opts, "cpu-used", "2", 0);
        av_dict_set(&opts, "row-mt", "1", 0);
    }
    int rc = avcodec_open2(cc, codec, &opts);
    av_dict_free(&opts);
    if (rc < 0)
        return av_fail(err, SL_ERR_UNSUPPORTED, "opening the encoder", rc);
    if ((rc = avcodec_parameters_from_context(w->stream->codecpar, cc)) < 0)
        return av_fail(err, SL_ERR_NOMEM, "stream parameters", rc);
    w->stream->time_base = cc->time_base;
    w->stream->avg_frame_rate = rate;
    w->frame = av_frame_alloc();
    w->packet = av_packet_alloc();
    if (!w->frame || !w->packet)
        return sl_err_set(err, SL_ERR_NOMEM, "video: out of memory");
    w->frame->format = cc->pix_fmt;
    w->frame->width = cc->width;
    w->frame->height = cc->height;
    if ((rc = av_frame_get_buffer(w->frame, 0)) < 0)
        return av_fail(err, SL_ERR_NOMEM, "frame buffer", rc);
    w->scale = sws_getContext(w->width, w->height, AV_PIX_FMT_RGBA, w->width, w->height, AV_PIX_FMT_YUV420P,
                              SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, NULL, NULL, NULL);
    if (!w->scale)
        return sl_err_set(err, SL_ERR_NOMEM, "video: no RGBA -> YUV 4:2:0 converter");
    /* RGB in full range to BT.709 limited-range YUV. */
    sws_setColorspaceDetails(w->scale, sws_getCoefficients(SWS_CS_ITU709), 1, sws_getCoefficients(SWS_CS_ITU709), 0,
                             0, 1 << 16, 1 << 16);
    return SL_OK;
}

sl_status sl_video_open(const sl_video_desc *d, sl_video_writer **out, sl_err *err)
{
    *out = NULL;
    sl_status st = sl_video_check(d, err);
    if (st != SL_OK)
        return st;
    const codec_choice *c = choice_for(d->path);
    av_log_set_level(AV_LOG_ERROR);
    sl_video_writer *w = calloc(1, sizeof *w);
    if (!w)
        return sl_err_set(err, SL_ERR_NOMEM, "video: out of memory");
    w->width = d->width;
    w->height = d->height;
    w->fps = d->fps;
    w->crf = d->crf < 0 ? c->crf_default : d->crf;
    w->codec_label = c->label;
    int rc = avformat_alloc_output_context2(&w->format, NULL, NULL, d->path);
    if (rc < 0 || !w->format) {
        release(w, 0);
        return av_fail(err, SL_ERR_UNSUPPORTED, "no container for this file name", rc);
    }
    if ((st = open_encoder(w, c, err)) != SL_OK) {
        release(w, 0);
        return st;
    }
    if ((rc = avio_open(&w->format->pb, d->path, AVIO_FLAG_WRITE)) < 0) {
        release(w, 0);
        return av_fail(err, SL_ERR_IO, d->path, rc);
    }
    snprintf(w->path, sizeof w->path, "%s", d->path); /* from here on a failure removes the file */
    if ((rc = avformat_write_header(w->format, NULL)) < 0) {
        release(w, 1);
        return av_fail(err, SL_ERR_IO, "writing the header", rc);
    }
    *out = w;
    return SL_OK;
}

/* Sends frame (NULL: flush) and writes every packet the encoder has ready. */
static sl_status encode(sl_video_writer *w, AVFrame *frame, sl_err *err)
{
    int rc = avcodec_send_frame(w->codec, frame);
    if (rc < 0)
        return av_fail(err, SL_ERR_IO, "encoding", rc);
    for (;;) {
        rc = avcodec_receive_packet(w->codec, w->packet);
        if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF)
            return SL_OK;
        if (rc < 0)
            return av_fail(err, SL_ERR_IO, "encoding", rc);
        av_packet_rescale_ts(w->packet, w->codec->time_base, w->stream->time_base);
        w->packet->stream_index = w->stream->index;
        rc = av_interleaved_write_frame(w->format, w->packet); /* takes the packet's data */
        if (rc < 0)
            return av_fail(err, SL_ERR_IO, "writing a packet", rc);
    }
}

sl_status sl_video_write_rgba(sl_video_writer *w, const uint8_t *rgba, sl_err *err)
{
    int rc = av_frame_make_writable(w->frame);
    if (rc < 0)
        return av_fail(err, SL_ERR_NOMEM, "frame buffer", rc);
    const uint8_t *src[1] = {rgba};
    const int stride[1] = {4 * w->width};
    sws_scale(w->scale, src, stride, 0, w->height, w->frame->data, w->frame->linesize);
    w->frame->pts = w->frames;
    sl_status st = encode(w, w->frame, err);
    if (st == SL_OK)
        w->frames++;
    return st;
}

sl_status sl_video_close(sl_video_writer *w, sl_video_summary *summary, sl_err *err)
{
    sl_status st = encode(w, NULL, err);
    int rc = st == SL_OK ? av_write_trailer(w->format) : 0;
    if (st == SL_OK && rc < 0)
        st = av_fail(err, SL_ERR_IO, "finishing the file", rc);
    if (st == SL_OK && w->frames == 0)
        st = sl_err_set(err, SL_ERR_INVALID, "video %s: no frames were written", w->path);
    if (st == SL_OK && (rc = avio_closep(&w->format->pb)) < 0)
        st = av_fail(err, SL_ERR_IO, w->path, rc);
    if (st == SL_OK && summary) {
        struct stat sb;
        *summary = (sl_video_summary){.frames = w->frames,
                                      .bytes = stat(w->path, &sb) == 0 ? (size_t)sb.st_size : 0,
                                      .seconds = (double)w->frames / w->fps,
                                      .codec = w->codec_label,
                                      .crf = w->crf};
    }
    release(w, st != SL_OK);
    return st;
}
