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
#include "../core/sl_leak_check.h"
#include "../core/sl_parallel.h"
#include "tubes_embree.h"
#include "tubes_sweep.h"

#define TILE 16
#define MAX_RETRACE 16
/* Curves and caps go to Embree this much fatter: its float intersector drops rays that graze a
 * tube within ~1e-5 r (random set seed 2: a rim ray 3e-5 r inside the sweep missed, so the
 * tube behind showed, 8.8 r deeper). Every candidate is then decided on the true sweep in
 * double: refined, or, where the ray misses it, traced on. Exact pieces' boxes are as fat (the
 * float ray finds them), their intersection is the true sweep's with the double ray. */
#define INFLATE 1.02
#define END_T 1e-7 /* a hit parameter this close to a piece's end is at the end */

/* One quadratic sub-segment and where its colour comes from. */
typedef struct piece {
    sl_tubes_sweep sweep;    /* double copy of the float controls */
    uint32_t node0, node1;   /* the Hermite segment's nodes */
    uint8_t half;            /* 0: node0 .. joint, 1: joint .. node1 */
    float t0, t1;            /* the part of the half it covers: half parameter = t0 + t (t1 - t0) */
    int64_t prev, next;      /* the piece this one continues at t = 0 / t = 1 (C1 joint), -1: none */
    uint8_t exact;           /* a user primitive (else an Embree curve) */
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
    piece *pieces;           /* >= 2 per segment: each half cut into pieces by its turn */
    size_t piece_count, piece_capacity;
    uint32_t *half_first;    /* per half (2 per segment): its first piece; its pieces follow */
    uint8_t *half_cuts;      /* per half: its piece count */
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
    e->half_first = malloc(ns * 2 * sizeof(uint32_t));
    e->half_cuts = malloc(ns * 2);
    e->caps = malloc(ns * 2 * sizeof(cap));
    if (!e->geometry || !e->segments || !e->half_first || !e->half_cuts || !e->caps) {
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
    free(e->half_first);
    free(e->half_cuts);
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
    double rmax = INFLATE * fmax(fabs(s->r[0]), fmax(fabs(s->r[1]), fabs(s->r[2])));
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

/* Every trace's context: Embree's, then the double rays the float ones stand for (by ray id)
 * and, per ray, the last entry an exact primitive reported. */
typedef struct trace_context {
    struct RTCIntersectContext embree; /* first: Embree hands the callbacks this pointer */
    const double *eye;
    const double (*dirs)[3];
    double tnear[16];                  /* the double ray starts here */
    double exact_l[16], exact_t[16];
} trace_context;

enum { RAY_ID = 10 };

/* Exact primitives are decided at once on the true sweep with the pixel's double ray: their
 * reported entry is the true one (rounded to float), so they need no inflation, and a trace
 * that starts past a candidate (tnear) sees the next true entry. */
static void exact_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const sl_tubes_embree *e = args->geometryUserPtr;
    trace_context *tc = (trace_context *)args->context;
    unsigned n = args->N;
    float *ray = (float *)args->rayhit;
    uint32_t *ray_u = (uint32_t *)ray;
    float *hit = ray + RAY_FLOATS * n;
    uint32_t *hit_u = (uint32_t *)hit;
    const sl_tubes_sweep *s = &e->pieces[e->exact_piece[args->primID]].sweep;
    for (unsigned i = 0; i < n; i++) {
        if (!args->valid[i])
            continue;
        unsigned id = ray_u[RAY_ID * n + i];
        const double *o = tc->eye, *d = tc->dirs[id];
        double l, t;
        if (!sl_tubes_sweep_intersect(s, o, d, tc->tnear[id], ray[RAY_TFAR * n + i], &l, &t))
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
        tc->exact_l[id] = l;
        tc->exact_t[id] = t;
    }
}

/* A segment end for linking: its node's position and tangent, bit for bit. */
typedef struct joint_key {
    float key[6];
    int64_t piece;  /* the piece that ends (is_start 0, t = 1) or starts (1, t = 0) there */
    int is_start;
} joint_key;

static int compare_joint(const void *pa, const void *pb)
{
    const joint_key *a = pa, *b = pb;
    int c = memcmp(a->key, b->key, sizeof a->key);
    return c ? c : a->is_start - b->is_start;
}

static size_t first_of(const sl_tubes_embree *e, size_t half) { return e->half_first[half]; }
static size_t last_of(const sl_tubes_embree *e, size_t half) { return e->half_first[half] + e->half_cuts[half] - 1u; }

static void link(sl_tubes_embree *e, size_t from, size_t to)
{
    e->pieces[from].next = (int64_t)to;
    e->pieces[to].prev = (int64_t)from;
}

/* prev / next: the pieces of a half in turn, the two halves of a segment, and across a joint
 * where exactly one segment ends and one starts at the same position with the same tangent (a
 * polyline's vertex, or explicit Hermite segments that share a node; each segment has its own
 * node copies then). */
static void link_pieces(sl_tubes_embree *e)
{
    for (size_t p = 0; p < e->piece_count; p++)
        e->pieces[p].prev = e->pieces[p].next = -1;
    for (size_t h = 0; h < 2 * e->segment_count; h++)
        for (size_t p = first_of(e, h); p < last_of(e, h); p++)
            link(e, p, p + 1);
    for (size_t k = 0; k < e->segment_count; k++)
        link(e, last_of(e, 2 * k), first_of(e, 2 * k + 1));
    joint_key *keys = e->segment_count ? malloc(2 * e->segment_count * sizeof *keys) : NULL;
    if (!keys)
        return; /* no links across joints: refinement stays within segments */
    for (size_t k = 0; k < e->segment_count; k++)
        for (int end = 0; end < 2; end++) {
            const float *n = e->geometry + (size_t)e->segments[2 * k + (size_t)end] * SL_TUBES_NODE_FLOATS;
            joint_key *j = &keys[2 * k + (size_t)end];
            memset(j, 0, sizeof *j);
            for (int c = 0; c < 3; c++) {
                j->key[c] = n[c] + 0.0f; /* -0 as +0 */
                j->key[3 + c] = n[4 + c] + 0.0f;
            }
            j->is_start = end == 0;
            j->piece = (int64_t)(end == 0 ? first_of(e, 2 * k) : last_of(e, 2 * k + 1));
        }
    size_t count = 2 * e->segment_count;
    qsort(keys, count, sizeof *keys, compare_joint);
    for (size_t i = 0; i < count;) {
        size_t j = i + 1;
        while (j < count && !memcmp(keys[j].key, keys[i].key, sizeof keys[i].key))
            j++;
        if (j - i == 2 && !keys[i].is_start && keys[i + 1].is_start)
            link(e, (size_t)keys[i].piece, (size_t)keys[i + 1].piece);
        i = j;
    }
    free(keys);
}

/* Appends one half as a piece to e->pieces (the piece table allows a half to be cut into
 * several; one piece per half is what the accuracy tests measured). */
static sl_status add_half(sl_tubes_embree *e, const piece *half, size_t index)
{
    if (e->piece_count + 1 > e->piece_capacity) {
        size_t cap = e->piece_capacity ? 2 * e->piece_capacity : 2 * e->segment_count + 16;
        piece *grown = realloc(e->pieces, cap * sizeof *grown);
        if (!grown)
            return SL_ERR_NOMEM;
        e->pieces = grown;
        e->piece_capacity = cap;
    }
    e->half_first[index] = (uint32_t)e->piece_count;
    e->half_cuts[index] = 1;
    piece *p = &e->pieces[e->piece_count++];
    *p = *half;
    p->exact = 0;
    p->t0 = 0.0f;
    p->t1 = 1.0f;
    return SL_OK;
}

/* (Re)builds the scene for radius_or_scale. */
static sl_status build(sl_tubes_embree *e, float radius_or_scale, sl_err *err)
{
    double t0 = sl_clock_ms();
    if (e->scene)
        rtcReleaseScene(e->scene);
    e->scene = NULL;
    e->curves = e->cap_count = e->exact = 0;
    e->piece_count = 0;
    for (size_t k = 0; k < e->segment_count; k++) {
        piece halves[2];
        split_segment(e, k, radius_or_scale, halves);
        for (int h = 0; h < 2; h++)
            if (add_half(e, &halves[h], 2 * k + (size_t)h) != SL_OK)
                return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory for %zu segments",
                                  e->segment_count);
    }
    size_t np = e->piece_count ? e->piece_count : 1;
    uint32_t *curve_piece = realloc(e->curve_piece, np * sizeof(uint32_t));
    if (curve_piece)
        e->curve_piece = curve_piece;
    uint32_t *exact_piece = realloc(e->exact_piece, np * sizeof(uint32_t));
    if (exact_piece)
        e->exact_piece = exact_piece;
    if (!curve_piece || !exact_piece)
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory for %zu pieces", e->piece_count);
    link_pieces(e);
    /* Regular pieces go to Embree, except beside an exact one: Embree cuts a curve at the plane
     * through its end, and an entry just past that plane belongs to no Embree primitive when
     * the neighbour is exact (random set seed 1: 17 r of depth lost). */
    uint8_t *regular = malloc(np);
    if (!regular)
        return sl_err_set(err, SL_ERR_NOMEM, "tubes (embree): out of memory for %zu pieces", e->piece_count);
    for (size_t p = 0; p < e->piece_count; p++)
        regular[p] = (uint8_t)sl_tubes_sweep_regular(&e->pieces[p].sweep);
    for (size_t p = 0; p < e->piece_count; p++) {
        const piece *q = &e->pieces[p];
        int beside_exact = (q->prev >= 0 && !regular[q->prev]) || (q->next >= 0 && !regular[q->next]);
        if (regular[p] && !beside_exact)
            e->curve_piece[e->curves++] = (uint32_t)p;
        else
            e->exact_piece[e->exact++] = (uint32_t)p;
        if (!regular[p] || beside_exact)
            e->pieces[p].exact = 1;
    }
    free(regular);
    /* Envelope ends: a regular piece's end that continues into no other piece (line end,
     * bifurcation, corner); exact pieces hold their end spheres themselves. */
    for (size_t k = 0; k < 2 * e->segment_count; k++) {
        size_t p = (k & 1) ? last_of(e, k) : first_of(e, k);
        int at_end = (int)(k & 1);
        const piece *q = &e->pieces[p];
        if ((at_end ? q->next : q->prev) < 0 && !q->exact)
            e->caps[e->cap_count++] = (cap){(uint32_t)p, (uint8_t)at_end};
    }

    e->scene = rtcNewScene(e->device);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    if (e->curves) {
        RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_ROUND_BEZIER_CURVE);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                           4 * e->curves);
        uint32_t *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t),
                                               e->curves);
        if (v && ix) {
            for (size_t k = 0; k < e->curves; k++) {
                const sl_tubes_sweep *s = &e->pieces[e->curve_piece[k]].sweep;
                /* the quadratic as a cubic Bezier (degree elevation): b0, (b0 + 2 b1) / 3, (2 b1 + b2) / 3, b2,
                 * the radius likewise */
                for (int c = 0; c < 4; c++) {
                    double w0 = c == 0 ? 1.0 : c == 1 ? 1.0 / 3.0 : 0.0;
                    double w1 = c == 1 || c == 2 ? 2.0 / 3.0 : 0.0;
                    double w2 = c == 3 ? 1.0 : c == 2 ? 1.0 / 3.0 : 0.0;
                    for (int x = 0; x < 3; x++)
                        v[16 * k + 4 * c + x] = (float)(w0 * s->b[0][x] + w1 * s->b[1][x] + w2 * s->b[2][x]);
                    v[16 * k + 4 * c + 3] = (float)(INFLATE * (w0 * s->r[0] + w1 * s->r[1] + w2 * s->r[2]));
                }
                ix[k] = (uint32_t)(4 * k);
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
                v[4 * k + 3] = (float)(INFLATE * fabs(s->r[end]));
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
    /* The build started oneTBB's workers and its exit-time teardown; the
     * sanitizer's leak check must run before that teardown (sl_leak_check.h). */
    sl_leak_check_early();
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

/* Polishes a hit (l, t) on piece p in double: Newton on p from t when `newton` (else the exact
 * search on p; NULL when the ray misses p's true sweep), then, while
 * the hit sits at an end of its piece that joins another, Newton in that one from the joint
 * (Embree's round curves end at a plane through the end point, so an entry whose parameter
 * lies just past a joint can come back as the neighbour's end or an end sphere). Keeps the
 * nearest entry found; returns its piece. */
static const piece *refine_hit(const sl_tubes_embree *e, const piece *p, const double o[3], const double d[3],
                               double l_min, int newton, double *l, double *t)
{
    double lr, tr;
    if (newton) {
        if (sl_tubes_sweep_refine(&p->sweep, o, d, l_min, *t, &lr, &tr) ||
            sl_tubes_sweep_intersect(&p->sweep, o, d, l_min, INFINITY, &lr, &tr)) {
            *l = lr;
            *t = tr;
        } else {
            /* p's true sweep is missed: the candidate grazed its inflated one, or came from
             * past a joint (Embree cuts a curve at its ends): the neighbours decide */
            const piece *found = NULL;
            for (int side = 0; side < 2; side++) {
                int64_t other = side ? p->next : p->prev;
                double lq, tq;
                if (other >= 0 && sl_tubes_sweep_intersect(&e->pieces[other].sweep, o, d, l_min, INFINITY, &lq, &tq) &&
                    (!found || lq < *l)) {
                    found = &e->pieces[other];
                    *l = lq;
                    *t = tq;
                }
            }
            return found;
        }
    }
    for (int hop = 0; hop < 2; hop++) {
        int64_t other = *t <= END_T ? p->prev : *t >= 1.0 - END_T ? p->next : -1;
        if (other < 0)
            break;
        const piece *q = &e->pieces[other];
        double lq, tq;
        if (!sl_tubes_sweep_refine(&q->sweep, o, d, l_min, *t <= END_T ? 1.0 : 0.0, &lq, &tq) || !(lq < *l))
            break;
        p = q;
        *l = lq;
        *t = tq;
    }
    return p;
}

/* One ray from tnear (float, and the double ray's own start) to tfar; an exact primitive's
 * entry comes back in *exact_l, *exact_t. */
static void trace_one(const sl_tubes_embree *e, const double eye[3], const double dir[3], float tnear,
                      double tnear_double, float tfar, struct RTCRayHit *rh, double *exact_l, double *exact_t)
{
    trace_context ctx = {.eye = eye, .dirs = (const double(*)[3])dir, .tnear = {tnear_double}};
    rtcInitIntersectContext(&ctx.embree);
    *rh = (struct RTCRayHit){0};
    rh->ray.org_x = (float)eye[0];
    rh->ray.org_y = (float)eye[1];
    rh->ray.org_z = (float)eye[2];
    rh->ray.dir_x = (float)dir[0];
    rh->ray.dir_y = (float)dir[1];
    rh->ray.dir_z = (float)dir[2];
    rh->ray.tnear = tnear;
    rh->ray.tfar = tfar;
    rh->ray.mask = 0xffffffffu;
    rh->ray.id = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scene, &ctx.embree, rh);
    *exact_l = ctx.exact_l[0];
    *exact_t = ctx.exact_t[0];
}

/* A candidate from Embree decided on the true sweep in double: 1 with the entry (*l, *t) on
 * *out; 0 when the ray leaves there (an exit: the ray started inside the sweep) or misses the
 * true sweep (it grazed the inflated one). An exact primitive's candidate is its true entry
 * already (exact_l, exact_t). */
static int decide_candidate(const sl_tubes_embree *e, const double o[3], const double d[3], double l_min,
                            unsigned geom, unsigned prim, float u, float tfar, double exact_l, double exact_t,
                            const piece **out, double *l, double *t, atomic_llong *refined)
{
    const piece *p = hit_piece(e, geom, prim, u, t);
    *l = tfar;
    if (geom == GEOM_CURVES) {
        /* Embree's u and Ng are not reliable enough to tell an entry from an exit (measured:
         * u 0.68 for an entry at 0.89): the piece's true sweep decides */
        atomic_fetch_add_explicit(refined, 1, memory_order_relaxed);
        p = refine_hit(e, p, o, d, l_min, 1, l, t);
    } else if (geom == GEOM_CAPS) {
        double c[3], r;
        sl_tubes_sweep_eval(&p->sweep, *t, c, &r);
        double q[3] = {c[0] - o[0], c[1] - o[1], c[2] - o[2]};
        double a = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
        double disc = r * r - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - a * a);
        if (!(disc >= 0.0) || !(a - sqrt(disc) >= l_min))
            return 0; /* missed, or an exit of a ray that starts inside the sphere */
        *l = a - sqrt(disc);
        p = refine_hit(e, p, o, d, l_min, 1, l, t);
    } else {
        *l = exact_l;
        *t = exact_t;
        if (*t <= END_T || *t >= 1.0 - END_T) /* an end sphere: the neighbour may hold a nearer entry */
            p = refine_hit(e, p, o, d, l_min, 0, l, t);
    }
    *out = p;
    return p != NULL;
}

/* Resolves one pixel from its first candidate: candidates come in the order of their inflated
 * surfaces, and a primitive's inflated entry is never behind its true one, so taking them in
 * turn until the next lies beyond the best true entry finds the nearest entry. Shades it into
 * the frame (colour and depth; 0: nothing). */
static void resolve_pixel(frame_job *job, int x, int y, const double d[3], unsigned geom, unsigned prim, float u,
                          float tfar, double exact_l, double exact_t)
{
    const sl_tubes_embree *e = job->e;
    size_t at = (size_t)(job->height - 1 - y) * (size_t)job->width + (size_t)x;
    float df = (float)(d[0] * job->forward[0] + d[1] * job->forward[1] + d[2] * job->forward[2]);
    double l_min = job->near_plane / fmax(df, 1e-30);
    const float dir[3] = {(float)d[0], (float)d[1], (float)d[2]};
    const piece *best = NULL;
    double best_l = INFINITY, best_t = 0.0;
    for (int round = 0; round <= MAX_RETRACE && geom != RTC_INVALID_GEOMETRY_ID && tfar < best_l; round++) {
        const piece *p;
        double l, t;
        int okc = decide_candidate(e, job->eye, d, l_min, geom, prim, u, tfar, exact_l, exact_t, &p, &l, &t,
                                   &job->refined);
        if (okc && l < best_l) {
            best = p;
            best_l = l;
            best_t = t;
        }
        /* an exact candidate is its true entry and the nearest reported one; no primitive's
         * reported entry lies behind its true one, so none is nearer: nothing to trace on */
        if (okc && geom == GEOM_EXACT && l <= exact_l)
            break;
        /* the next candidate beyond this one, nearer than the best entry */
        atomic_fetch_add_explicit(&job->retraced, 1, memory_order_relaxed);
        struct RTCRayHit rh;
        float from = nextafterf(tfar, INFINITY);
        trace_one(e, job->eye, d, from, fmax(from, l_min), isfinite(best_l) ? (float)best_l : INFINITY, &rh,
                  &exact_l, &exact_t);
        geom = rh.hit.geomID;
        prim = rh.hit.primID;
        u = rh.hit.u;
        tfar = rh.ray.tfar;
    }
    if (!best) {
        memset(job->frame->rgba + 4 * at, 0, 4);
        job->frame->depth[at] = 0.0f;
        return;
    }
    double c[3], r;
    sl_tubes_sweep_eval(&best->sweep, best_t, c, &r);
    float n[3], v[3] = {-dir[0], -dir[1], -dir[2]};
    double nl = 0.0;
    for (int k = 0; k < 3; k++) {
        n[k] = (float)(job->eye[k] + best_l * d[k] - c[k]);
        nl += (double)n[k] * n[k];
    }
    nl = sqrt(nl);
    for (int k = 0; k < 3; k++)
        n[k] = nl > 0.0 ? (float)(n[k] / nl) : v[k];
    const float *cs0 = job->colors + 2 * (size_t)best->node0, *cs1 = job->colors + 2 * (size_t)best->node1;
    float ca2 = cs0[0] + cs0[1] / 3.0f, cb2 = cs1[0] - cs1[1] / 3.0f, cm = 0.5f * (ca2 + cb2);
    float c0 = best->half ? cm : cs0[0], c1 = best->half ? cb2 : ca2, c2 = best->half ? cs1[0] : cm;
    float ft = best->t0 + (float)best_t * (best->t1 - best->t0), fs = 1.0f - ft;
    float scalar = fs * fs * c0 + 2.0f * fs * ft * c1 + ft * ft * c2;
    sl_line_shader_color(job->shader, scalar, n, v, job->frame->rgba + 4 * at);
    job->frame->depth[at] = (float)(job->near_plane / (best_l * df));
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
    double dirs[16][3];
    trace_context ctx = {.eye = job->eye, .dirs = (const double(*)[3])dirs};
    rtcInitIntersectContext(&ctx.embree);
    ctx.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
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
                ctx.tnear[i] = job->near_plane / fmax(df, 1e-30);
                pk.f[RAY_TNEAR * n + i] = (float)ctx.tnear[i];
                pk.f[7 * n + i] = 0.0f;             /* time */
                pk.f[RAY_TFAR * n + i] = INFINITY;
                pk.u[9 * n + i] = 0xffffffffu;      /* mask */
                pk.u[10 * n + i] = (uint32_t)i;     /* id */
                pk.u[11 * n + i] = 0;               /* flags */
                hit_u[HIT_GEOM * n + i] = RTC_INVALID_GEOMETRY_ID;
                hit_u[HIT_INST * n + i] = RTC_INVALID_GEOMETRY_ID;
            }
            if (n == 16)
                rtcIntersect16(valid, e->scene, &ctx.embree, &pk.p16);
            else if (n == 8)
                rtcIntersect8(valid, e->scene, &ctx.embree, &pk.p8);
            else if (n == 4)
                rtcIntersect4(valid, e->scene, &ctx.embree, &pk.p4);
            else
                rtcIntersect1(e->scene, &ctx.embree, (struct RTCRayHit *)pk.f);
            for (int i = 0; i < n; i++) {
                if (!valid[i])
                    continue;
                resolve_pixel(job, bx + i % bw, by + i / bw, dirs[i], hit_u[HIT_GEOM * n + i], hit_u[HIT_PRIM * n + i],
                              hit[HIT_U * n + i], pk.f[RAY_TFAR * n + i], ctx.exact_l[i], ctx.exact_t[i]);
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
