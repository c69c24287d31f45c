/* test_volume_histogram.c — the value histogram of a volume
 * (sl_dataset_finish_volume) and the automatic opacity ramp chosen from it
 * (sl_volume_tf_auto_opacity, sl_volume_tf_resolve with "opacity": "auto").
 *
 * Histograms are checked against a brute-force count that places each value
 * by comparing it with the bin edges (no shared code), for every voxel type,
 * NaN and infinite voxels, a constant volume and a vector field (magnitudes).
 * The automatic ramp is checked on histograms with a known shape: a
 * background spike with a valley after it (the ramp starts at the valley),
 * a flat one (starts at 0), one whose peak is in the upper half, an empty
 * one, and a single occupied bin; every ramp is a valid opacity ramp.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset.h"
#include "data/sl_generate.h"
#include "volume/sl_volume.h"
#include "sl_test.h"

/* A dims[0] x 1 x 1 volume of the given type holding values[] (as that type). */
static sl_dataset *make_volume(sl_voxel_type type, int components, const double *values, int n)
{
    sl_err err = {0};
    sl_dataset *ds = sl_dataset_create(components == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, "h");
    int dims[3] = {n, 1, 1};
    if (!ds || sl_volume_alloc(&ds->volume, dims, components, type, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    for (int i = 0; i < n * components; i++) {
        switch (type) {
        case SL_VOXEL_U8: ((uint8_t *)ds->volume.data)[i] = (uint8_t)values[i]; break;
        case SL_VOXEL_U16: ((uint16_t *)ds->volume.data)[i] = (uint16_t)values[i]; break;
        case SL_VOXEL_S16: ((int16_t *)ds->volume.data)[i] = (int16_t)values[i]; break;
        case SL_VOXEL_F32: ((float *)ds->volume.data)[i] = (float)values[i]; break;
        }
    }
    if (sl_dataset_finish_volume(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

/* The expected bin of v by walking the edges lo + k (hi - lo) / BINS. */
static int brute_bin(double v, double lo, double hi)
{
    if (!(hi > lo))
        return 0;
    int k = 0;
    while (k < SL_VOLUME_HISTOGRAM_BINS - 1 && v >= lo + (k + 1) * (hi - lo) / SL_VOLUME_HISTOGRAM_BINS)
        k++;
    return k;
}

static void check_histogram(const sl_dataset *ds, const double *finite, int n, const char *what)
{
    const sl_volume *v = &ds->volume;
    uint64_t expect[SL_VOLUME_HISTOGRAM_BINS] = {0};
    for (int i = 0; i < n; i++)
        expect[brute_bin(finite[i], v->value_min, v->value_max)]++;
    int same = 1;
    uint64_t sum = 0;
    for (int k = 0; k < SL_VOLUME_HISTOGRAM_BINS; k++) {
        same &= expect[k] == v->histogram[k];
        sum += v->histogram[k];
    }
    SL_CHECK_MSG(same, "%s: histogram differs from the brute-force count", what);
    SL_CHECK_MSG(v->finite_count == (uint64_t)n && sum == (uint64_t)n, "%s: %llu finite (sum %llu), expected %d",
                 what, (unsigned long long)v->finite_count, (unsigned long long)sum, n);
}

static void test_histograms(void)
{
    /* Every integer type over a small range, edges included. */
    const double ints[] = {0, 1, 2, 3, 7, 7, 7, 100, 200, 254, 255, 255};
    const sl_voxel_type types[] = {SL_VOXEL_U8, SL_VOXEL_U16, SL_VOXEL_S16, SL_VOXEL_F32};
    for (int t = 0; t < 4; t++) {
        sl_dataset *ds = make_volume(types[t], 1, ints, 12);
        SL_CHECK(ds != NULL);
        if (ds) {
            check_histogram(ds, ints, 12, sl_voxel_type_name(types[t]));
            SL_CHECK(ds->volume.histogram[0] == 1 && ds->volume.histogram[SL_VOLUME_HISTOGRAM_BINS - 1] == 2);
        }
        sl_dataset_destroy(ds);
    }
    /* Signed values, a wide range. */
    const double s16[] = {-32768, -1000, -999, 0, 1, 5000, 32767};
    sl_dataset *ds = make_volume(SL_VOXEL_S16, 1, s16, 7);
    if (ds)
        check_histogram(ds, s16, 7, "s16 wide");
    sl_dataset_destroy(ds);
    /* f32 with NaN and infinities: only the finite values count. */
    const double f[] = {0.25, NAN, -0.5, INFINITY, 1.5, -INFINITY, 0.3, 0.30001};
    const double f_finite[] = {0.25, -0.5, 1.5, 0.3, 0.30001};
    ds = make_volume(SL_VOXEL_F32, 1, f, 8);
    if (ds) {
        SL_CHECK(ds->volume.value_min == -0.5 && ds->volume.value_max == 1.5);
        check_histogram(ds, f_finite, 5, "f32 with NaN");
    }
    sl_dataset_destroy(ds);
    /* A constant volume: everything in bin 0. */
    const double c[] = {4, 4, 4, 4};
    ds = make_volume(SL_VOXEL_F32, 1, c, 4);
    if (ds)
        SL_CHECK(ds->volume.histogram[0] == 4 && ds->volume.finite_count == 4);
    sl_dataset_destroy(ds);
    /* Only NaN: an empty histogram. */
    const double nan4[] = {NAN, NAN, NAN, NAN};
    ds = make_volume(SL_VOXEL_F32, 1, nan4, 4);
    if (ds) {
        uint64_t sum = 0;
        for (int k = 0; k < SL_VOLUME_HISTOGRAM_BINS; k++)
            sum += ds->volume.histogram[k];
        SL_CHECK(sum == 0 && ds->volume.finite_count == 0);
    }
    sl_dataset_destroy(ds);
    /* A vector field counts magnitudes. */
    const double vec[] = {3, 4, 0, 0, 0, 1, 1, 2, 2, NAN, 0, 0};
    const double mags[] = {5, 1, 3};
    ds = make_volume(SL_VOXEL_F32, 3, vec, 4);
    if (ds) {
        SL_CHECK(ds->volume.value_min == 1 && ds->volume.value_max == 5);
        check_histogram(ds, mags, 3, "vector magnitudes");
    }
    sl_dataset_destroy(ds);
}

/* The ramp of a volume whose histogram is set by hand. */
static int ramp_of(const uint64_t *h, double ramp[4][2])
{
    sl_volume v;
    memset(&v, 0, sizeof v);
    v.value_min = 0.0;
    v.value_max = 1.0;
    for (int k = 0; k < SL_VOLUME_HISTOGRAM_BINS; k++) {
        v.histogram[k] = h[k];
        v.finite_count += h[k];
    }
    return sl_volume_tf_auto_opacity(&v, 1, ramp);
}

/* A valid ramp: 1..4 points, t in [0, 1] increasing, alpha in [0, 1],
 * starting at 0 and ending above 0 at most at SL_VOLUME_AUTO_ALPHA (less
 * where the optical-depth bound scaled it down). */
static void check_ramp(const double ramp[4][2], int n, const char *what)
{
    int ok = n >= 2 && n <= 4 && ramp[0][1] == 0.0 && ramp[n - 1][1] > 0.0 &&
             ramp[n - 1][1] <= SL_VOLUME_AUTO_ALPHA;
    for (int k = 0; k < n && ok; k++)
        ok = ramp[k][0] >= 0.0 && ramp[k][0] <= 1.0 && ramp[k][1] >= 0.0 && ramp[k][1] <= 1.0 &&
             (k == 0 || ramp[k][0] > ramp[k - 1][0]);
    SL_CHECK_MSG(ok, "%s: not a valid ramp (%d points, first [%g, %g])", what, n, ramp[0][0], ramp[0][1]);
}

static void test_auto_opacity(void)
{
    enum { B = SL_VOLUME_HISTOGRAM_BINS };
    uint64_t h[B];
    double ramp[4][2];
    /* A background spike at bin 2 falling to a valley at bin 30, tissue
     * from 30 to 120 (a smooth hump), a thin tail to bin 200. */
    memset(h, 0, sizeof h);
    h[2] = 1000000;
    for (int k = 3; k < 30; k++)
        h[k] = (uint64_t)(200000.0 * exp(-(k - 3) / 4.0)) + 50;
    for (int k = 30; k < 120; k++)
        h[k] = 50 + (uint64_t)(20000.0 * sin(M_PI * (k - 30) / 90.0));
    for (int k = 120; k < 200; k++)
        h[k] = 5;
    int n = ramp_of(h, ramp);
    check_ramp(ramp, n, "background spike");
    SL_CHECK_MSG(ramp[0][0] >= 20.0 / B && ramp[0][0] <= 34.0 / B, "ramp starts at t %g, not at the valley near %g",
                 ramp[0][0], 30.0 / B);
    /* 99.5 % of the values above the start lie below bin ~150 here. */
    SL_CHECK_MSG(ramp[n - 1][0] > 100.0 / B && ramp[n - 1][0] < 200.0 / B, "ramp ends at t %g", ramp[n - 1][0]);
    /* Flat: no background, starts at 0, ends at the 99.5th percentile. */
    for (int k = 0; k < B; k++)
        h[k] = 100;
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "flat");
    SL_CHECK(ramp[0][0] == 0.0 && ramp[n - 1][0] > 250.0 / B);
    /* Peak in the upper half (inverted data): no background cut. */
    h[200] = 1000000;
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "upper peak");
    SL_CHECK(ramp[0][0] == 0.0);
    /* A spike holding less than SL_VOLUME_AUTO_PEAK of the values is not background. */
    for (int k = 0; k < B; k++)
        h[k] = 1000;
    h[10] = 5000; /* 5000 / 260000 < 5 % */
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "small spike");
    SL_CHECK(ramp[0][0] == 0.0);
    /* Empty and single-bin histograms still give a valid ramp. */
    memset(h, 0, sizeof h);
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "empty");
    h[0] = 10;
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "all in bin 0");
    memset(h, 0, sizeof h);
    h[B - 1] = 10;
    n = ramp_of(h, ramp);
    check_ramp(ramp, n, "all in the last bin");
}

/* resolve with "opacity": "auto" is the colormap form with the automatic
 * ramp written out, in the dataset's range or re-mapped onto a given one. */
static void test_resolve_auto(void)
{
    double values[64];
    for (int i = 0; i < 64; i++)
        values[i] = i < 40 ? 0.0 : i; /* a background of zeros, then 40 .. 63 */
    sl_dataset *ds = make_volume(SL_VOXEL_F32, 1, values, 64);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    double ramp[4][2];
    int n = sl_volume_tf_auto_opacity(&ds->volume, 1, ramp);
    check_ramp(ramp, n, "zeros then 40..63");
    SL_CHECK_MSG(ramp[0][0] > 0.0, "the zeros were not taken as background (t %g)", ramp[0][0]);
    sl_transfer_function autotf, explicit;
    memset(&autotf, 0, sizeof autotf);
    autotf.colormap = 0;
    autotf.auto_opacity = 1;
    explicit = autotf;
    explicit.auto_opacity = 0;
    explicit.count = n;
    for (int k = 0; k < n; k++)
        explicit.point[k][0] = ramp[k][0], explicit.point[k][1] = ramp[k][1];
    sl_volume_tf_points a, b;
    sl_volume_tf_resolve(&autotf, &ds->volume, 1, &a);
    sl_volume_tf_resolve(&explicit, &ds->volume, 1, &b);
    SL_CHECK(a.count == b.count && memcmp(a.value, b.value, sizeof a.value) == 0 &&
             memcmp(a.rgba, b.rgba, sizeof a.rgba) == 0);
    /* With a range twice as wide, the same values keep their opacity. */
    autotf.has_range = 1;
    autotf.range[0] = -63.0;
    autotf.range[1] = 63.0;
    sl_volume_tf_resolve(&autotf, &ds->volume, 1, &a);
    int same = 1;
    for (double v = 0.0; v <= 63.0; v += 0.5) {
        double ra[4], rb[4];
        sl_volume_tf_eval(&a, v, ra);
        sl_volume_tf_eval(&b, v, rb);
        same &= fabs(ra[3] - rb[3]) < 1e-12;
    }
    SL_CHECK_MSG(same, "a given range changed the automatic opacity of a value");
    sl_dataset_destroy(ds);
}

/* The optical-depth bound, checked by brute force: a ball of radius R
 * voxels of one value (1) in a background of zeros, with a shell of a
 * higher value (2) around it; the extinction -ln(1 - alpha) of every voxel
 * on the line through the centre, summed (unit spacing: the unit of
 * alpha), is the ray's optical depth. Without the bound it would be about
 * R * 0.2 (ball at mid-ramp, ~0.025) plus the shell's; with it, it stays
 * within SL_VOLUME_AUTO_DEPTH and is not cut far below it. */
static void test_depth_bound(void)
{
    enum { N = 96 };
    const double R = 36.0, shell = 3.0, c = 0.5 * (N - 1);
    sl_err err = {0};
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "ball");
    int dims[3] = {N, N, N};
    SL_CHECK(ds && sl_volume_alloc(&ds->volume, dims, 1, SL_VOXEL_F32, &err) == SL_OK);
    if (!ds || !ds->volume.data) {
        sl_dataset_destroy(ds);
        return;
    }
    float *v = ds->volume.data;
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double r = sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                v[((size_t)z * N + y) * N + x] = r < R ? 1.0f : r < R + shell ? 2.0f : 0.0f;
            }
    SL_CHECK(sl_dataset_finish_volume(ds, &err) == SL_OK);
    double ramp[4][2];
    int n = sl_volume_tf_auto_opacity(&ds->volume, 1, ramp);
    check_ramp(ramp, n, "ball in a shell");
    SL_CHECK_MSG(ramp[n - 1][1] < SL_VOLUME_AUTO_ALPHA, "the bound did not scale this ramp (top alpha %g)",
                 ramp[n - 1][1]);
    sl_transfer_function tf;
    memset(&tf, 0, sizeof tf);
    tf.colormap = 0;
    tf.auto_opacity = 1;
    sl_volume_tf_points pts;
    sl_volume_tf_resolve(&tf, &ds->volume, 1, &pts);
    double depth = 0.0;
    int y = N / 2, z = N / 2;
    for (int x = 0; x < N; x++) {
        double rgba[4];
        sl_volume_tf_eval(&pts, v[((size_t)z * N + y) * N + x], rgba);
        depth += -log1p(-rgba[3]);
    }
    printf("ball R %g + shell %g: optical depth through the centre %.3f (bound %g), estimate %.3f\n", R, shell,
           depth, SL_VOLUME_AUTO_DEPTH, sl_volume_tf_ramp_depth(&ds->volume, ramp, n));
    /* MIP (one sample per ray) keeps the unbounded ramp. */
    double mip[4][2];
    int nm = sl_volume_tf_auto_opacity(&ds->volume, 0, mip);
    SL_CHECK_MSG(nm == n && mip[nm - 1][1] == SL_VOLUME_AUTO_ALPHA && mip[0][0] == ramp[0][0],
                 "the MIP ramp: top alpha %g, start %g (composite %g)", mip[nm - 1][1], mip[0][0], ramp[0][0]);
    SL_CHECK_MSG(depth <= SL_VOLUME_AUTO_DEPTH * 1.05 && depth >= 0.5 * SL_VOLUME_AUTO_DEPTH,
                 "optical depth %g through the centre, bound %g", depth, SL_VOLUME_AUTO_DEPTH);
    sl_dataset_destroy(ds);
}

/* The head phantom (CT-like, 96^3 here): its soft tissue and brain fill
 * most of the head, so the unbounded ramp hides everything inside the
 * skull (the uniform egg of issue 31). The bounded ramp keeps its estimate
 * at SL_VOLUME_AUTO_DEPTH, and the optical depth of the ray through the
 * centre, summed voxel by voxel, stays below the estimate (a shell is
 * crossed over fewer voxels than the ball the estimate assumes). */
static void test_head_first_look(void)
{
    sl_err err = {0};
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\": \"head\", \"size\": 96}", &ds, &err) == SL_OK);
    if (!ds)
        return;
    const sl_volume *vol = &ds->volume;
    double open[4][2], bounded[4][2];
    int n = sl_volume_tf_auto_opacity(vol, 0, open);
    int nb = sl_volume_tf_auto_opacity(vol, 1, bounded);
    double d_open = sl_volume_tf_ramp_depth(vol, open, n), d_bounded = sl_volume_tf_ramp_depth(vol, bounded, nb);
    sl_transfer_function tf;
    memset(&tf, 0, sizeof tf);
    tf.colormap = 0;
    tf.auto_opacity = 1;
    sl_volume_tf_points pts;
    sl_volume_tf_resolve(&tf, vol, 1, &pts);
    double centre = 0.0;
    const uint16_t *v = vol->data;
    int N = vol->dims[0], y = N / 2, z = N / 2;
    for (int x = 0; x < N; x++) {
        double rgba[4];
        sl_volume_tf_eval(&pts, v[((size_t)z * N + y) * N + x], rgba);
        centre += -log1p(-rgba[3]);
    }
    printf("head 96^3: ramp start %.1f, top alpha %.3f -> %.4f; estimated depth %.2f -> %.2f, "
           "centre ray %.2f\n", vol->value_min + bounded[0][0] * (vol->value_max - vol->value_min), open[n - 1][1],
           bounded[nb - 1][1], d_open, d_bounded, centre);
    SL_CHECK_MSG(d_open > 2.0 * SL_VOLUME_AUTO_DEPTH, "the unbounded head ramp is not deep (%g)", d_open);
    /* Extinctions scale exactly at the ramp's points; between them alpha is linear: within 5 %. */
    SL_CHECK_MSG(fabs(d_bounded - SL_VOLUME_AUTO_DEPTH) < 0.05 * SL_VOLUME_AUTO_DEPTH, "bounded estimate %g", d_bounded);
    SL_CHECK_MSG(centre <= d_bounded && centre > 0.1, "centre ray depth %g, estimate %g", centre, d_bounded);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_histograms();
    test_auto_opacity();
    test_resolve_auto();
    test_depth_bound();
    test_head_first_look();
    SL_TEST_END();
}
