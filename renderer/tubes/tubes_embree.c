/* tubes_embree.c — tubes_embree.h: Embree 3 scene of the quadratic sub-segments, tiled
 * packet tracing on all cores, double refinement, shading into a host frame. */
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../core/sl_parallel.h"
#include "tubes_embree.h"
#include "tubes_sweep.h"

#define TILE 16
#define MAX_RETRACE 8
#define RESIDUAL_OK 1e-4

/* One quadratic sub-segment and where its colour comes from. */
typedef struct piece {
    sl_tubes_sweep sweep;    /* double copy of the float controls */
    uint32_t node0, node1;   /* the Hermite segment's nodes */
    uint8_t half;            /* 0: node0 .. joint, 1: joint .. node1 */
} piece;

/* A sphere point at an envelope's end: the node and the piece end that shades it. */
typedef struct cap {
    uint32_t piece;
    uint8_t at_end;          /* 0: t = 0, 1: t = 1 */
} cap;

enum { GEOM_CURVES = 0, GEOM_CAPS = 1, GEOM_EXACT = 2 };

struct sl_tubes_embree {
    RTCDevice device;
    RTCScene scene;
    size_t node_count, segment_count;
    float *geometry;         /* SL_TUBES_NODE_FLOATS per node */
    uint32_t *segments;
    int has_radii;
    float built_radius;      /* radius (no data radii) or radius_scale the BVH holds; NAN: none */
    piece *pieces;           /* 2 per segment */
    uint32_t *curve_piece, *exact_piece; /* primID -> piece */
    cap *caps;
    size_t curves, cap_count, exact;
    atomic_llong bytes;      /* memory monitor */
    int packet;
    sl_tubes_embree_stats stats;
    pthread_mutex_t error_lock;
    char error[256];         /* first device error, guarded by error_lock */
};

int sl_tubes_embree_available(void) { return 1; }

static void on_error(void *user, enum RTCError code, const char *str)
{
    sl_tubes_embree *e = user;
    pthread_mutex_lock(&e->error_lock);
    if (!e->error[0])
        snprintf(e->error, sizeof e->error, "Embree error %d: %s", (int)code, str ? str : "(no message)");
    pthread_mutex_unlock(&e->error_lock);
}

static bool on_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;
    sl_tubes_embree *e = user;
    atomic_fetch_add(&e->bytes, (long long)bytes);
    return true;
}

sl_status sl_tubes_embree_create(const sl_tubes_nodes *nodes, sl_tubes_embree **out, sl_err *err)
{
    *out = NULL;
    sl_tubes_embree *e = calloc(1, sizeof *e);
    if (!e)
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory");
    pthread_mutex_init(&e->error_lock, NULL);
    atomic_init(&e->bytes, 0);
    e->built_radius = NAN;
    e->node_count = nodes->node_count;
    e->segment_count = nodes->segment_count;
    e->has_radii = nodes->has_radii;
    size_t nn = e->node_count ? e->node_count : 1, ns = e->segment_count ? e->segment_count : 1;
    e->geometry = malloc(nn * SL_TUBES_NODE_FLOATS * sizeof(float));
    e->segments = malloc(ns * 2 * sizeof(uint32_t));
    e->pieces = malloc(ns * 2 * sizeof(piece));
    e->curve_piece = malloc(ns * 2 * sizeof(uint32_t));
    e->exact_piece = malloc(ns * 2 * sizeof(uint32_t));
    e->caps = malloc(ns * 4 * sizeof(cap));
    if (!e->geometry || !e->segments || !e->pieces || !e->curve_piece || !e->exact_piece || !e->caps) {
        size_t segments = e->segment_count;
        sl_tubes_embree_destroy(e);
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory for %zu segments", segments);
    }
    if (e->node_count)
        memcpy(e->geometry, nodes->geometry, e->node_count * SL_TUBES_NODE_FLOATS * sizeof(float));
    if (e->segment_count)
        memcpy(e->segments, nodes->segments, e->segment_count * 2 * sizeof(uint32_t));
    char config[64];
    snprintf(config, sizeof config, "threads=%d", sl_parallel_threads());
    e->device = rtcNewDevice(config);
    if (!e->device) {
        int code = (int)rtcGetDeviceError(NULL);
        sl_tubes_embree_destroy(e);
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "tubes (embree): rtcNewDevice failed (Embree error %d)", code);
    }
    rtcSetDeviceErrorFunction(e->device, on_error, e);
    rtcSetDeviceMemoryMonitorFunction(e->device, on_memory, e);
    if (!rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_CURVE_GEOMETRY_SUPPORTED) ||
        !rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED) ||
        !rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_USER_GEOMETRY_SUPPORTED)) {
        sl_tubes_embree_destroy(e);
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "tubes (embree): this Embree was built without curve, point or user geometry");
    }
    e->packet = rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)  ? 16
                : rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? 8
                : rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) ? 4
                                                                                             : 1;
    *out = e;
    return SL_OK;
}

void sl_tubes_embree_destroy(sl_tubes_embree *e)
{
    if (!e)
        return;
    if (e->scene)
        rtcReleaseScene(e->scene);
    if (e->device)
        rtcReleaseDevice(e->device);
    free(e->geometry);
    free(e->segments);
    free(e->pieces);
    free(e->curve_piece);
    free(e->exact_piece);
    free(e->caps);
    pthread_mutex_destroy(&e->error_lock);
    free(e);
}

/* The two quadratic sub-segments of segment k, in float exactly as tubes.geom.glsl. */
static void split_segment(const sl_tubes_embree *e, size_t k, float radius_or_scale, piece out[2])
{
    uint32_t i0 = e->segments[2 * k], i1 = e->segments[2 * k + 1];
    const float *n0 = e->geometry + (size_t)i0 * SL_TUBES_NODE_FLOATS;
    const float *n1 = e->geometry + (size_t)i1 * SL_TUBES_NODE_FLOATS;
    float r0 = e->has_radii ? n0[3] * radius_or_scale : radius_or_scale;
    float r1 = e->has_radii ? n1[3] * radius_or_scale : radius_or_scale;
    float dr0 = e->has_radii ? n0[7] * radius_or_scale : 0.0f;
    float dr1 = e->has_radii ? n1[7] * radius_or_scale : 0.0f;
    float a2[3], b2[3], m[3];
    for (int c = 0; c < 3; c++) {
        a2[c] = n0[c] + n0[4 + c] / 3.0f;
        b2[c] = n1[c] - n1[4 + c] / 3.0f;
        m[c] = 0.5f * (a2[c] + b2[c]);
    }
    float ra2 = r0 + dr0 / 3.0f, rb2 = r1 - dr1 / 3.0f, rm = 0.5f * (ra2 + rb2);
    for (int c = 0; c < 3; c++) {
        out[0].sweep.b[0][c] = n0[c];
        out[0].sweep.b[1][c] = a2[c];
        out[0].sweep.b[2][c] = m[c];
        out[1].sweep.b[0][c] = m[c];
        out[1].sweep.b[1][c] = b2[c];
        out[1].sweep.b[2][c] = n1[c];
    }
    out[0].sweep.r[0] = r0;
    out[0].sweep.r[1] = ra2;
    out[0].sweep.r[2] = rm;
    out[1].sweep.r[0] = rm;
    out[1].sweep.r[1] = rb2;
    out[1].sweep.r[2] = r1;
    for (int h = 0; h < 2; h++) {
        out[h].node0 = i0;
        out[h].node1 = i1;
        out[h].half = (uint8_t)h;
    }
}

static void exact_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const sl_tubes_embree *e = args->geometryUserPtr;
    const sl_tubes_sweep *s = &e->pieces[e->exact_piece[args->primID]].sweep;
    double rmax = fmax(fabs(s->r[0]), fmax(fabs(s->r[1]), fabs(s->r[2])));
    double lo[3], hi[3];
    for (int c = 0; c < 3; c++) {
        lo[c] = fmin(s->b[0][c], fmin(s->b[1][c], s->b[2][c])) - rmax;
        hi[c] = fmax(s->b[0][c], fmax(s->b[1][c], s->b[2][c])) + rmax;
    }
    /* widen by a float ulp or two so that rounding never cuts the sweep */
    struct RTCBounds *b = args->bounds_o;
    b->lower_x = nextafterf(nextafterf((float)lo[0], -INFINITY), -INFINITY);
    b->lower_y = nextafterf(nextafterf((float)lo[1], -INFINITY), -INFINITY);
    b->lower_z = nextafterf(nextafterf((float)lo[2], -INFINITY), -INFINITY);
    b->upper_x = nextafterf(nextafterf((float)hi[0], INFINITY), INFINITY);
    b->upper_y = nextafterf(nextafterf((float)hi[1], INFINITY), INFINITY);
    b->upper_z = nextafterf(nextafterf((float)hi[2], INFINITY), INFINITY);
}

/* RTCRayHitN layout (rtcore_ray.h; its accessors are C++ only): ray fields then hit fields,
 * each an array of N. */
enum { RAY_ORG = 0, RAY_TNEAR = 3, RAY_DIR = 4, RAY_TFAR = 8, RAY_FLOATS = 12, HIT_NG = 0, HIT_U = 3, HIT_V = 4,
       HIT_PRIM = 5, HIT_GEOM = 6, HIT_INST = 7 };

static void exact_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const sl_tubes_embree *e = args->geometryUserPtr;
    unsigned n = args->N;
    float *ray = (float *)args->rayhit;
    float *hit = ray + RAY_FLOATS * n;
    uint32_t *hit_u = (uint32_t *)hit;
    const sl_tubes_sweep *s = &e->pieces[e->exact_piece[args->primID]].sweep;
    for (unsigned i = 0; i < n; i++) {
        if (!args->valid[i])
            continue;
        double o[3] = {ray[(RAY_ORG + 0) * n + i], ray[(RAY_ORG + 1) * n + i], ray[(RAY_ORG + 2) * n + i]};
        double d[3] = {ray[(RAY_DIR + 0) * n + i], ray[(RAY_DIR + 1) * n + i], ray[(RAY_DIR + 2) * n + i]};
        double l, t;
        if (!sl_tubes_sweep_intersect(s, o, d, ray[RAY_TNEAR * n + i], ray[RAY_TFAR * n + i], &l, &t))
            continue;
        double c[3], r;
        sl_tubes_sweep_eval(s, t, c, &r);
        ray[RAY_TFAR * n + i] = (float)l;
        for (int k = 0; k < 3; k++)
            hit[(HIT_NG + k) * n + i] = (float)(o[k] + l * d[k] - c[k]);
        hit[HIT_U * n + i] = (float)t;
        hit[HIT_V * n + i] = 0.0f;
        hit_u[HIT_PRIM * n + i] = args->primID;
        hit_u[HIT_GEOM * n + i] = args->geomID;
        hit_u[HIT_INST * n + i] = args->context->instID[0];
    }
}

/* (Re)builds the scene for radius_or_scale. */
static sl_status build(sl_tubes_embree *e, float radius_or_scale, sl_err *err)
{
    double t0 = sl_clock_ms();
    if (e->scene)
        rtcReleaseScene(e->scene);
    e->scene = NULL;
    e->curves = e->cap_count = e->exact = 0;
    uint8_t *uses = calloc(e->node_count ? e->node_count : 1, 1); /* regular piece ends at the node, saturating */
    uint32_t *use_piece = malloc((e->node_count ? e->node_count : 1) * sizeof(uint32_t));
    uint8_t *use_end = malloc(e->node_count ? e->node_count : 1);
    if (!uses || !use_piece || !use_end) {
        free(uses);
        free(use_piece);
        free(use_end);
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory");
    }
    for (size_t k = 0; k < e->segment_count; k++) {
        split_segment(e, k, radius_or_scale, &e->pieces[2 * k]);
        for (int h = 0; h < 2; h++) {
            uint32_t p = (uint32_t)(2 * k + (size_t)h);
            if (sl_tubes_sweep_regular(&e->pieces[p].sweep)) {
                e->curve_piece[e->curves++] = p;
                uint32_t node = h == 0 ? e->segments[2 * k] : e->segments[2 * k + 1];
                if (uses[node] < 255)
                    uses[node]++;
                use_piece[node] = p;
                use_end[node] = (uint8_t)h;
            } else {
                e->exact_piece[e->exact++] = p;
            }
        }
    }
    /* Envelope ends: a node where not exactly two regular pieces meet (line end, bifurcation,
     * one side exact), or where the two differ in tangent (a corner of duplicated nodes has two
     * node indices, each used once). */
    for (size_t node = 0; node < e->node_count; node++)
        if (uses[node] == 1 || uses[node] > 2)
            e->caps[e->cap_count++] = (cap){use_piece[node], use_end[node]};
    free(uses);
    free(use_piece);
    free(use_end);

    e->scene = rtcNewScene(e->device);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    if (e->curves) {
        RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_ROUND_HERMITE_CURVE);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                           2 * e->curves);
        float *tg = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_TANGENT, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                            2 * e->curves);
        uint32_t *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t),
                                               e->curves);
        if (v && tg && ix) {
            for (size_t k = 0; k < e->curves; k++) {
                const sl_tubes_sweep *s = &e->pieces[e->curve_piece[k]].sweep;
                /* the quadratic as a cubic Hermite: p(0), p(1), p'(0) = 2 (b1 - b0), p'(1) = 2 (b2 - b1) */
                for (int c = 0; c < 3; c++) {
                    v[8 * k + c] = (float)s->b[0][c];
                    v[8 * k + 4 + c] = (float)s->b[2][c];
                    tg[8 * k + c] = (float)(2.0 * (s->b[1][c] - s->b[0][c]));
                    tg[8 * k + 4 + c] = (float)(2.0 * (s->b[2][c] - s->b[1][c]));
                }
                v[8 * k + 3] = (float)s->r[0];
                v[8 * k + 7] = (float)s->r[2];
                tg[8 * k + 3] = (float)(2.0 * (s->r[1] - s->r[0]));
                tg[8 * k + 7] = (float)(2.0 * (s->r[2] - s->r[1]));
                ix[k] = (uint32_t)(2 * k);
            }
        }
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(e->scene, g, GEOM_CURVES);
        rtcReleaseGeometry(g);
    }
    if (e->cap_count) {
        RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                           e->cap_count);
        if (v)
            for (size_t k = 0; k < e->cap_count; k++) {
                const sl_tubes_sweep *s = &e->pieces[e->caps[k].piece].sweep;
                int end = e->caps[k].at_end ? 2 : 0;
                for (int c = 0; c < 3; c++)
                    v[4 * k + c] = (float)s->b[end][c];
                v[4 * k + 3] = (float)fabs(s->r[end]);
            }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(e->scene, g, GEOM_CAPS);
        rtcReleaseGeometry(g);
    }
    if (e->exact) {
        RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, (unsigned)e->exact);
        rtcSetGeometryUserData(g, e);
        rtcSetGeometryBoundsFunction(g, exact_bounds, e);
        rtcSetGeometryIntersectFunction(g, exact_intersect);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(e->scene, g, GEOM_EXACT);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(e->scene);
    pthread_mutex_lock(&e->error_lock);
    int failed = e->error[0] != 0;
    char msg[256];
    snprintf(msg, sizeof msg, "%s", e->error);
    e->error[0] = 0;
    pthread_mutex_unlock(&e->error_lock);
    if (failed) {
        rtcReleaseScene(e->scene);
        e->scene = NULL;
        e->built_radius = NAN;
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): building the BVH of %zu segments: %s",
                          e->segment_count, msg);
    }
    e->built_radius = radius_or_scale;
    e->stats.builds++;
    e->stats.build_ms = sl_clock_ms() - t0;
    e->stats.curves = e->curves;
    e->stats.spheres = e->cap_count;
    e->stats.exact = e->exact;
    return SL_OK;
}

/* What every worker of one frame reads; written before the workers start. */
typedef struct frame_job {
    const sl_tubes_embree *e;
    const sl_line_shader *shader;
    const float *colors;
    int width, height, tiles_x;
    double eye[3], forward[3], right[3], up[3]; /* right/up scaled by the image-plane extent */
    double near_plane;
    sl_host_frame *frame;
    atomic_llong refined, retraced;
} frame_job;

static void pixel_dir(const frame_job *job, int x, int y, double d[3])
{
    double sx = 2.0 * (x + 0.5) / job->width - 1.0, sy = 1.0 - 2.0 * (y + 0.5) / job->height;
    double len = 0.0;
    for (int c = 0; c < 3; c++) {
        d[c] = job->forward[c] + sx * job->right[c] + sy * job->up[c];
        len += d[c] * d[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; c++)
        d[c] /= len;
}

/* The piece and its parameter a hit stands for. */
static const piece *hit_piece(const sl_tubes_embree *e, unsigned geom, unsigned prim, float u, double *t)
{
    if (geom == GEOM_CURVES) {
        *t = u;
        return &e->pieces[e->curve_piece[prim]];
    }
    if (geom == GEOM_CAPS) {
        *t = e->caps[prim].at_end ? 1.0 : 0.0;
        return &e->pieces[e->caps[prim].piece];
    }
    *t = u;
    return &e->pieces[e->exact_piece[prim]];
}

static void trace_one(const sl_tubes_embree *e, const float org[3], const float dir[3], float tnear,
                      struct RTCRayHit *rh)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    *rh = (struct RTCRayHit){0};
    rh->ray.org_x = org[0];
    rh->ray.org_y = org[1];
    rh->ray.org_z = org[2];
    rh->ray.dir_x = dir[0];
    rh->ray.dir_y = dir[1];
    rh->ray.dir_z = dir[2];
    rh->ray.tnear = tnear;
    rh->ray.tfar = INFINITY;
    rh->ray.mask = 0xffffffffu;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scene, &ctx, rh);
}

/* Resolves one pixel from its first hit: refines it in double, skips exits (rays that start
 * inside the sweep), shades. Writes the pixel's colour and depth (0: nothing). */
static void resolve_pixel(frame_job *job, int x, int y, const double d[3], unsigned geom, unsigned prim, float u,
                          float tfar, float ng[3])
{
    const sl_tubes_embree *e = job->e;
    size_t at = (size_t)(job->height - 1 - y) * (size_t)job->width + (size_t)x;
    float df = (float)(d[0] * job->forward[0] + d[1] * job->forward[1] + d[2] * job->forward[2]);
    double l_min = job->near_plane / fmax(df, 1e-30);
    const float org[3] = {(float)job->eye[0], (float)job->eye[1], (float)job->eye[2]};
    const float dir[3] = {(float)d[0], (float)d[1], (float)d[2]};
    for (int round = 0; round <= MAX_RETRACE && geom != RTC_INVALID_GEOMETRY_ID; round++) {
        double t, l = tfar;
        const piece *p = hit_piece(e, geom, prim, u, &t);
        int entry = 1;
        if (geom == GEOM_CURVES) {
            /* a back-facing hit is the exit of a ray that started inside the sweep */
            entry = ng[0] * dir[0] + ng[1] * dir[1] + ng[2] * dir[2] < 0.0f;
            if (entry && sl_tubes_sweep_residual(&p->sweep, job->eye, d, l, t) > RESIDUAL_OK) {
                double lr, tr;
                if (sl_tubes_sweep_refine(&p->sweep, job->eye, d, l_min, t, &lr, &tr)) {
                    l = lr;
                    t = tr;
                    atomic_fetch_add_explicit(&job->refined, 1, memory_order_relaxed);
                }
            }
        } else if (geom == GEOM_CAPS) {
            /* the sphere's entry in double; an exit when the ray starts inside it */
            double c[3], r;
            sl_tubes_sweep_eval(&p->sweep, t, c, &r);
            double q[3] = {c[0] - job->eye[0], c[1] - job->eye[1], c[2] - job->eye[2]};
            double a = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
            double disc = r * r - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - a * a);
            double le = a - sqrt(fmax(disc, 0.0));
            entry = le >= l_min;
            if (entry)
                l = le;
        }
        if (entry) {
            double c[3], r;
            sl_tubes_sweep_eval(&p->sweep, t, c, &r);
            float n[3], v[3] = {-dir[0], -dir[1], -dir[2]};
            double nl = 0.0;
            for (int k = 0; k < 3; k++) {
                n[k] = (float)(job->eye[k] + l * d[k] - c[k]);
                nl += (double)n[k] * n[k];
            }
            nl = sqrt(nl);
            for (int k = 0; k < 3; k++)
                n[k] = nl > 0.0 ? (float)(n[k] / nl) : v[k];
            const float *cs0 = job->colors + 2 * (size_t)p->node0, *cs1 = job->colors + 2 * (size_t)p->node1;
            float ca2 = cs0[0] + cs0[1] / 3.0f, cb2 = cs1[0] - cs1[1] / 3.0f, cm = 0.5f * (ca2 + cb2);
            float c0 = p->half ? cm : cs0[0], c1 = p->half ? cb2 : ca2, c2 = p->half ? cs1[0] : cm;
            float ft = (float)t, fs = 1.0f - ft;
            float scalar = fs * fs * c0 + 2.0f * fs * ft * c1 + ft * ft * c2;
            sl_line_shader_color(job->shader, scalar, n, v, job->frame->rgba + 4 * at);
            job->frame->depth[at] = (float)(job->near_plane / (l * df));
            return;
        }
        /* an exit: trace on from just beyond it */
        atomic_fetch_add_explicit(&job->retraced, 1, memory_order_relaxed);
        struct RTCRayHit rh;
        trace_one(e, org, dir, nextafterf(tfar, INFINITY) * (1.0f + 1e-6f), &rh);
        geom = rh.hit.geomID;
        prim = rh.hit.primID;
        u = rh.hit.u;
        tfar = rh.ray.tfar;
        ng[0] = rh.hit.Ng_x;
        ng[1] = rh.hit.Ng_y;
        ng[2] = rh.hit.Ng_z;
    }
    memset(job->frame->rgba + 4 * at, 0, 4);
    job->frame->depth[at] = 0.0f;
}

typedef union packet16 {
    struct RTCRayHit16 p16;
    struct RTCRayHit8 p8;
    struct RTCRayHit4 p4;
    float f[(RAY_FLOATS + 8 + RTC_MAX_INSTANCE_LEVEL_COUNT) * 16];
    uint32_t u[(RAY_FLOATS + 8 + RTC_MAX_INSTANCE_LEVEL_COUNT) * 16];
} packet16;

static void trace_tile(void *opaque, int tile, int worker)
{
    (void)worker;
    frame_job *job = opaque;
    const sl_tubes_embree *e = job->e;
    int x0 = (tile % job->tiles_x) * TILE, y0 = (tile / job->tiles_x) * TILE;
    int x1 = x0 + TILE < job->width ? x0 + TILE : job->width, y1 = y0 + TILE < job->height ? y0 + TILE : job->height;
    const int n = e->packet, bw = n >= 4 ? (n == 4 ? 2 : 4) : 1, bh = n / bw;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    double dirs[16][3];
    for (int by = y0; by < y1; by += bh)
        for (int bx = x0; bx < x1; bx += bw) {
            RTC_ALIGN(64) packet16 pk;
            RTC_ALIGN(64) int valid[16];
            float *hit = pk.f + RAY_FLOATS * n;
            uint32_t *hit_u = pk.u + RAY_FLOATS * n;
            for (int i = 0; i < n; i++) {
                int x = bx + i % bw, y = by + i / bw;
                valid[i] = x < x1 && y < y1 ? -1 : 0;
                pixel_dir(job, x < x1 ? x : x1 - 1, y < y1 ? y : y1 - 1, dirs[i]);
                float df = (float)(dirs[i][0] * job->forward[0] + dirs[i][1] * job->forward[1] +
                                   dirs[i][2] * job->forward[2]);
                for (int c = 0; c < 3; c++) {
                    pk.f[(RAY_ORG + c) * n + i] = (float)job->eye[c];
                    pk.f[(RAY_DIR + c) * n + i] = (float)dirs[i][c];
                }
                pk.f[RAY_TNEAR * n + i] = (float)(job->near_plane / fmax(df, 1e-30));
                pk.f[7 * n + i] = 0.0f;             /* time */
                pk.f[RAY_TFAR * n + i] = INFINITY;
                pk.u[9 * n + i] = 0xffffffffu;      /* mask */
                pk.u[10 * n + i] = (uint32_t)i;     /* id */
                pk.u[11 * n + i] = 0;               /* flags */
                hit_u[HIT_GEOM * n + i] = RTC_INVALID_GEOMETRY_ID;
                hit_u[HIT_INST * n + i] = RTC_INVALID_GEOMETRY_ID;
            }
            if (n == 16)
                rtcIntersect16(valid, e->scene, &ctx, &pk.p16);
            else if (n == 8)
                rtcIntersect8(valid, e->scene, &ctx, &pk.p8);
            else if (n == 4)
                rtcIntersect4(valid, e->scene, &ctx, &pk.p4);
            else
                rtcIntersect1(e->scene, &ctx, (struct RTCRayHit *)pk.f);
            for (int i = 0; i < n; i++) {
                if (!valid[i])
                    continue;
                float ng[3] = {hit[(HIT_NG + 0) * n + i], hit[(HIT_NG + 1) * n + i], hit[(HIT_NG + 2) * n + i]};
                resolve_pixel(job, bx + i % bw, by + i / bw, dirs[i], hit_u[HIT_GEOM * n + i], hit_u[HIT_PRIM * n + i],
                              hit[HIT_U * n + i], pk.f[RAY_TFAR * n + i], ng);
            }
        }
}

sl_status sl_tubes_embree_ensure(sl_tubes_embree *e, float radius, float radius_scale, double *rebuilt_ms,
                                 sl_err *err)
{
    *rebuilt_ms = 0.0;
    float want = e->has_radii ? radius_scale : radius;
    if (e->built_radius == want)
        return SL_OK;
    sl_status st = build(e, want, err);
    if (st == SL_OK)
        *rebuilt_ms = e->stats.build_ms;
    return st;
}

sl_status sl_tubes_embree_render(sl_tubes_embree *e, const sl_view *view, const sl_line_shader *shader,
                                 const float *colors, float radius, float radius_scale, sl_host_frame *frame,
                                 double *rebuilt_ms, sl_err *err)
{
    sl_status st = sl_tubes_embree_ensure(e, radius, radius_scale, rebuilt_ms, err);
    if (st != SL_OK)
        return st;
    st = sl_host_frame_resize(frame, view->width, view->height, err);
    if (st != SL_OK)
        return st;
    double t0 = sl_clock_ms();
    frame_job job = {.e = e, .shader = shader, .colors = colors, .width = view->width, .height = view->height,
                     .tiles_x = (view->width + TILE - 1) / TILE, .near_plane = view->near_plane, .frame = frame};
    atomic_init(&job.refined, 0);
    atomic_init(&job.retraced, 0);
    const sl_vec3 eye = view->camera.eye, origin = view->origin;
    const double ext_y = view->tan_half_fov, ext_x = view->tan_half_fov * view->aspect;
    double e3[3] = {eye.x - origin.x, eye.y - origin.y, eye.z - origin.z};
    double f3[3] = {view->forward.x, view->forward.y, view->forward.z};
    double r3[3] = {view->right.x * ext_x, view->right.y * ext_x, view->right.z * ext_x};
    double u3[3] = {view->upv.x * ext_y, view->upv.y * ext_y, view->upv.z * ext_y};
    memcpy(job.eye, e3, sizeof e3);
    memcpy(job.forward, f3, sizeof f3);
    memcpy(job.right, r3, sizeof r3);
    memcpy(job.up, u3, sizeof u3);
    int tiles = job.tiles_x * ((view->height + TILE - 1) / TILE);
    e->stats.threads = sl_parallel_run(tiles, 0, trace_tile, &job);
    e->stats.packet = e->packet;
    e->stats.rays = (double)view->width * view->height;
    e->stats.refined = (double)atomic_load(&job.refined);
    e->stats.retraced = (double)atomic_load(&job.retraced);
    e->stats.trace_ms = sl_clock_ms() - t0;
    e->stats.bvh_bytes = (double)atomic_load(&e->bytes);
    pthread_mutex_lock(&e->error_lock);
    int failed = e->error[0] != 0;
    char msg[256];
    snprintf(msg, sizeof msg, "%s", e->error);
    e->error[0] = 0;
    pthread_mutex_unlock(&e->error_lock);
    if (failed)
        return sl_err_set(err, SL_ERR_GPU, "tubes (embree): tracing: %s", msg);
    return SL_OK;
}

void sl_tubes_embree_stats_get(const sl_tubes_embree *e, sl_tubes_embree_stats *out)
{
    *out = e ? e->stats : (sl_tubes_embree_stats){0};
    if (e)
        out->bvh_bytes = (double)atomic_load(&((sl_tubes_embree *)e)->bytes);
}
