/* video_reader.c — decoding a video for tests: see video_reader.h. */
#include "video_reader.h"

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
#include <stdio.h>
#include <string.h>

static int to_rgba(const AVFrame *frame, uint8_t *rgba, size_t rgba_size)
{
    if ((size_t)frame->width * (size_t)frame->height * 4u > rgba_size)
        return -1;
    struct SwsContext *sws = sws_getContext(frame->width, frame->height, frame->format, frame->width, frame->height,
                                            AV_PIX_FMT_RGBA, SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT,
                                            NULL, NULL, NULL);
    if (!sws)
        return -1;
    sws_setColorspaceDetails(sws, sws_getCoefficients(SWS_CS_ITU709), 0, sws_getCoefficients(SWS_CS_ITU709), 1, 0,
                             1 << 16, 1 << 16);
    uint8_t *dst[1] = {rgba};
    int stride[1] = {4 * frame->width};
    sws_scale(sws, (const uint8_t *const *)frame->data, frame->linesize, 0, frame->height, dst, stride);
    sws_freeContext(sws);
    return 0;
}

int video_read(const char *path, int index, uint8_t *rgba, size_t rgba_size, video_info *info, char *msg,
               size_t msg_size)
{
    memset(info, 0, sizeof *info);
    av_log_set_level(AV_LOG_ERROR);
    AVFormatContext *fmt = NULL;
    if (avformat_open_input(&fmt, path, NULL, NULL) < 0) {
        snprintf(msg, msg_size, "%s: not a readable video", path);
        return -1;
    }
    int rc = -1;
    AVCodecContext *cc = NULL;
    AVPacket *pkt = av_packet_alloc();
    AVFrame *frame = av_frame_alloc();
    if (!pkt || !frame || avformat_find_stream_info(fmt, NULL) < 0) {
        snprintf(msg, msg_size, "%s: no stream information", path);
        goto out;
    }
    info->streams = (int)fmt->nb_streams;
    if (fmt->nb_streams != 1 || fmt->streams[0]->codecpar->codec_type != AVMEDIA_TYPE_VIDEO) {
        snprintf(msg, msg_size, "%s: %u streams, expected one video stream", path, fmt->nb_streams);
        goto out;
    }
    const AVStream *st = fmt->streams[0];
    info->width = st->codecpar->width;
    info->height = st->codecpar->height;
    info->bt709 = st->codecpar->color_space == AVCOL_SPC_BT709;
    info->fps = av_q2d(st->avg_frame_rate);
    snprintf(info->codec, sizeof info->codec, "%s", avcodec_get_name(st->codecpar->codec_id));
    const AVCodec *dec = avcodec_find_decoder(st->codecpar->codec_id);
    cc = dec ? avcodec_alloc_context3(dec) : NULL;
    if (!cc || avcodec_parameters_to_context(cc, st->codecpar) < 0 || avcodec_open2(cc, dec, NULL) < 0) {
        snprintf(msg, msg_size, "%s: no %s decoder", path, info->codec);
        goto out;
    }
    int eof = 0, converted = rgba == NULL;
    while (!eof) {
        if (av_read_frame(fmt, pkt) < 0) {
            eof = 1;
            avcodec_send_packet(cc, NULL);
        } else {
            avcodec_send_packet(cc, pkt);
            av_packet_unref(pkt);
        }
        while (avcodec_receive_frame(cc, frame) == 0) {
            if (rgba && info->frames == index) {
                if (to_rgba(frame, rgba, rgba_size) != 0) {
                    snprintf(msg, msg_size, "%s: frame %d does not convert to RGBA", path, index);
                    goto out;
                }
                converted = 1;
            }
            info->frames++;
        }
    }
    if (!converted) {
        snprintf(msg, msg_size, "%s: no frame %d (the video has %d)", path, index, info->frames);
        goto out;
    }
    rc = 0;
out:
    av_frame_free(&frame);
    av_packet_free(&pkt);
    avcodec_free_context(&cc);
    avformat_close_input(&fmt);
    return rc;
}
