/* test_load_volumes.c — NRRD, NIfTI-1 and raw+JSON loaders, sl_gunzip,
 * sl_read_file and the sl_load_file dispatch.
 *
 * Every good file is written here byte by byte from known voxel values, so
 * each check compares against values computed independently (in double).
 * Hostile inputs: every truncation prefix of small good files, lying sizes
 * (2^31, 0, negative, above SL_MAX_VOXELS), detached names escaping their
 * folder, gzip bombs against a low limit, mismatched sizes. A hostile input
 * must fail with the expected status, leave *out NULL and leak nothing
 * (ASan). Files live in a fresh folder under /tmp, removed at the end.
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "core/sl_clock.h"
#include "data/sl_load.h"
#include "sl_test.h"

static char tmpdir[256];

/* ---------------------------------------------------------------- helpers */

typedef struct buf {
    uint8_t *p;
    size_t n, cap;
} buf;

static void buf_add(buf *b, const void *data, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 64;
        b->p = realloc(b->p, b->cap);
        if (!b->p)
            abort();
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
}

static void buf_str(buf *b, const char *s) { buf_add(b, s, strlen(s)); }

/* Appends v as w bytes, little- or big-endian. */
static void buf_int(buf *b, uint64_t v, int w, int big)
{
    uint8_t x[8];
    for (int i = 0; i < w; i++)
        x[big ? w - 1 - i : i] = (uint8_t)(v >> (8 * i));
    buf_add(b, x, (size_t)w);
}

static void buf_f32(buf *b, float f, int big)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    buf_int(b, u, 4, big);
}

static void buf_f64(buf *b, double f, int big)
{
    uint64_t u;
    memcpy(&u, &f, 8);
    buf_int(b, u, 8, big);
}

static buf gzip_bytes(const uint8_t *data, size_t n)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        abort();
    buf out = {0};
    out.cap = deflateBound(&zs, (uLong)n) + 64;
    out.p = malloc(out.cap);
    zs.next_in = (Bytef *)(uintptr_t)data;
    zs.avail_in = (uInt)n;
    zs.next_out = out.p;
    zs.avail_out = (uInt)out.cap;
    if (deflate(&zs, Z_FINISH) != Z_STREAM_END)
        abort();
    out.n = zs.total_out;
    deflateEnd(&zs);
    return out;
}

static char written[128][512];
static int written_count;

static const char *tmp_path(const char *name)
{
    static char path[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(path[k], sizeof path[k], "%s/%s", tmpdir, name);
    return path[k];
}

static const char *write_file(const char *name, const void *data, size_t n)
{
    const char *path = tmp_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n)
        abort();
    fclose(f);
    if (written_count < 128)
        snprintf(written[written_count++], sizeof written[0], "%s", path);
    return path;
}

/* Loads from memory and expects failure with status want (0 = any failure). */
static void expect_fail(sl_loader_fn fn, const uint8_t *data, size_t n, const char *path, sl_status want,
                        const char *what)
{
    sl_dataset *ds = (sl_dataset *)(uintptr_t)1;
    sl_err err = {0};
    sl_status st = fn(data, n, path, &ds, &err);
    SL_CHECK_MSG(st != SL_OK && (want == 0 || st == want), "%s: status %d (%s), want %d: %s", what, st,
                 sl_status_name(st), want, err.message);
    SL_CHECK_MSG(ds == NULL, "%s: *out not NULL on failure", what);
    SL_CHECK_MSG(st == SL_OK || err.message[0] != '\0', "%s: empty error message", what);
    if (st == SL_OK)
        sl_dataset_destroy(ds);
}

/* Every prefix shorter than n must fail cleanly. */
static void expect_prefixes_fail(sl_loader_fn fn, const uint8_t *data, size_t n, const char *path, const char *what)
{
    int failures = 0;
    for (size_t len = 0; len < n; len++) {
        uint8_t *copy = malloc(len ? len : 1); /* exact size: ASan catches over-reads */
        memcpy(copy, data, len);
        sl_dataset *ds = NULL;
        sl_err err = {0};
        sl_status st = fn(copy, len, path, &ds, &err);
        if (st == SL_OK || ds != NULL || !err.message[0]) {
            failures++;
            fprintf(stderr, "%s: prefix of %zu/%zu bytes: status %d\n", what, len, n, st);
        }
        sl_dataset_destroy(ds);
        free(copy);
    }
    SL_CHECK_MSG(failures == 0, "%s: %d truncation prefixes did not fail cleanly", what, failures);
}

static sl_dataset *expect_load(sl_loader_fn fn, const uint8_t *data, size_t n, const char *path, const char *what)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    uint8_t *copy = malloc(n ? n : 1);
    memcpy(copy, data, n);
    sl_status st = fn(copy, n, path, &ds, &err);
    free(copy);
    SL_CHECK_MSG(st == SL_OK && ds, "%s: %s", what, err.message);
    return st == SL_OK ? ds : NULL;
}

/* Checks the volume's value range against a brute-force pass over expected values. */
static void check_range(const sl_dataset *ds, const double *expect, size_t n)
{
    double lo = DBL_MAX, hi = -DBL_MAX;
    for (size_t i = 0; i < n; i++) {
        if (expect[i] < lo) lo = expect[i];
        if (expect[i] > hi) hi = expect[i];
    }
    SL_CHECK_NEAR(ds->volume.value_min, lo, 1e-6 * fabs(lo) + 1e-9);
    SL_CHECK_NEAR(ds->volume.value_max, hi, 1e-6 * fabs(hi) + 1e-9);
}

/* Compares every scalar voxel with expect (x fastest) within tol. */
static void check_values(const sl_dataset *ds, const double *expect, double tol, const char *what)
{
    const sl_volume *v = &ds->volume;
    int bad = 0;
    size_t i = 0;
    for (int z = 0; z < v->dims[2]; z++)
        for (int y = 0; y < v->dims[1]; y++)
            for (int x = 0; x < v->dims[0]; x++, i++) {
                double got = sl_volume_value(v, (size_t)x, (size_t)y, (size_t)z, 0);
                if (!(fabs(got - expect[i]) <= tol)) {
                    if (bad++ < 3)
                        fprintf(stderr, "%s: voxel %zu is %.9g, expected %.9g\n", what, i, got, expect[i]);
                }
            }
    SL_CHECK_MSG(bad == 0, "%s: %d voxels differ", what, bad);
}

/* ------------------------------------------------------------------ NRRD */

/* 4x3x2 u16 values 7*i + 1 (big-endian data: swapped on load). */
static buf nrrd_u16(int big, const char *extra_fields)
{
    buf b = {0};
    buf_str(&b, "NRRD0004\n# a comment\ntype: unsigned short\ndimension: 3\nsizes: 4 3 2\n"
                "spacings: 0.5 1 2\nspace origin: (1,-2,3.5)\nkinds: domain domain domain\nfoo:=bar\n");
    buf_str(&b, big ? "endian: big\n" : "endian: little\n");
    buf_str(&b, "encoding: raw\n");
    buf_str(&b, extra_fields);
    buf_str(&b, "\n");
    for (int i = 0; i < 24; i++)
        buf_int(&b, (uint64_t)(7 * i + 1) * 1000u % 65536u, 2, big);
    return b;
}

static void test_nrrd_raw(void)
{
    double expect[24];
    for (int i = 0; i < 24; i++)
        expect[i] = (double)((7 * i + 1) * 1000 % 65536);
    for (int big = 0; big <= 1; big++) {
        buf b = nrrd_u16(big, "");
        sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, "mem.nrrd", "nrrd raw u16");
        if (ds) {
            SL_CHECK(ds->kind == SL_DATASET_VOLUME);
            SL_CHECK(ds->volume.type == SL_VOXEL_U16);
            SL_CHECK(ds->volume.components == 1);
            SL_CHECK(ds->volume.dims[0] == 4 && ds->volume.dims[1] == 3 && ds->volume.dims[2] == 2);
            SL_CHECK_NEAR(ds->volume.spacing[0], 0.5, 0);
            SL_CHECK_NEAR(ds->volume.spacing[1], 1.0, 0);
            SL_CHECK_NEAR(ds->volume.spacing[2], 2.0, 0);
            SL_CHECK_NEAR(ds->origin.x, 1.0, 0);
            SL_CHECK_NEAR(ds->origin.y, -2.0, 0);
            SL_CHECK_NEAR(ds->origin.z, 3.5, 0);
            SL_CHECK_NEAR(ds->bounds_max.x, 1.0 + 3 * 0.5, 1e-12);
            SL_CHECK_NEAR(ds->bounds_max.z, 3.5 + 1 * 2.0, 1e-12);
            SL_CHECK(strcmp(ds->name, "mem") == 0);
            check_values(ds, expect, 0, big ? "nrrd u16 big" : "nrrd u16 little");
            check_range(ds, expect, 24);
        }
        sl_dataset_destroy(ds);
        expect_prefixes_fail(sl_load_nrrd, b.p, b.n, "mem.nrrd", "nrrd raw prefixes");
        /* One byte too many is a size mismatch too. */
        buf_add(&b, "x", 1);
        expect_fail(sl_load_nrrd, b.p, b.n, "mem.nrrd", SL_ERR_FORMAT, "nrrd raw + 1 byte");
        free(b.p);
    }
    /* space directions give the spacing as vector lengths and override spacings. */
    buf b = {0};
    buf_str(&b, "NRRD0005\ntype: int8\ndimension: 3\nsizes: 2 2 1\nspace: right-anterior-superior\n"
                "space directions: (0.6,0.8,0) (0,-2,0) (0,0,3)\nspace origin: (10, 20, 30)\nencoding: raw\n\n");
    int8_t s8[4] = {-128, -1, 0, 127};
    buf_add(&b, s8, 4);
    sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, NULL, "nrrd space directions");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_S16);
        SL_CHECK_NEAR(ds->volume.spacing[0], 1.0, 1e-12);
        SL_CHECK_NEAR(ds->volume.spacing[1], 2.0, 1e-12);
        SL_CHECK_NEAR(ds->volume.spacing[2], 3.0, 1e-12);
        SL_CHECK_NEAR(ds->origin.x, 10.0, 0);
        SL_CHECK_NEAR(ds->origin.z, 30.0, 0);
        double e[4] = {-128, -1, 0, 127};
        check_values(ds, e, 0, "nrrd s8");
        SL_CHECK(strcmp(ds->name, "nrrd") == 0);
    }
    sl_dataset_destroy(ds);
    free(b.p);

    /* int32 and double become f32. */
    b = (buf){0};
    buf_str(&b, "NRRD0004\ntype: double\ndimension: 3\nsizes: 3 1 1\nendian: big\nencoding: raw\n\n");
    buf_f64(&b, -1.25, 1);
    buf_f64(&b, 1e10, 1);
    buf_f64(&b, 3.0, 1);
    ds = expect_load(sl_load_nrrd, b.p, b.n, "d.nrrd", "nrrd double");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_F32);
        double e[3] = {-1.25, (double)(float)1e10, 3.0};
        check_values(ds, e, 0, "nrrd double");
    }
    sl_dataset_destroy(ds);
    free(b.p);

    /* ascii with CRLF header lines and line skip / byte skip not needed. */
    b = (buf){0};
    buf_str(&b, "NRRD0004\r\ntype: uchar\r\ndimension: 3\r\nsizes: 2 2 1\r\nencoding: ascii\r\n\r\n0 17\n255\t3\n");
    ds = expect_load(sl_load_nrrd, b.p, b.n, "a.nrrd", "nrrd ascii");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_U8);
        double e[4] = {0, 17, 255, 3};
        check_values(ds, e, 0, "nrrd ascii");
    }
    sl_dataset_destroy(ds);
    free(b.p);
    b = (buf){0};
    buf_str(&b, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 1\nencoding: ascii\n\n0 17 256 3\n");
    expect_fail(sl_load_nrrd, b.p, b.n, "a.nrrd", SL_ERR_FORMAT, "nrrd ascii out of range");
    free(b.p);
    b = (buf){0};
    buf_str(&b, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 1\nencoding: ascii\n\n0 17 3\n");
    expect_fail(sl_load_nrrd, b.p, b.n, "a.nrrd", SL_ERR_FORMAT, "nrrd ascii too few");
    free(b.p);
}

static void test_nrrd_gzip(void)
{
    /* 3x2x2 floats, little-endian, gzip-encoded with byte skip 4 after inflating. */
    buf raw = {0};
    double expect[12];
    buf_int(&raw, 0xdeadbeef, 4, 0);
    for (int i = 0; i < 12; i++) {
        expect[i] = (double)(float)(0.1 * i - 0.5);
        buf_f32(&raw, (float)(0.1 * i - 0.5), 0);
    }
    buf gz = gzip_bytes(raw.p, raw.n);
    buf b = {0};
    buf_str(&b, "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 2\nendian: little\nencoding: gzip\nbyte skip: 4\n\n");
    buf_add(&b, gz.p, gz.n);
    sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, "g.nrrd", "nrrd gzip");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_F32);
        check_values(ds, expect, 0, "nrrd gzip");
        check_range(ds, expect, 12);
    }
    sl_dataset_destroy(ds);
    expect_prefixes_fail(sl_load_nrrd, b.p, b.n, "g.nrrd", "nrrd gzip prefixes");
    free(b.p);
    free(gz.p);
    free(raw.p);

    /* A gzip bomb: 8 declared bytes, 4 MiB of zeros compressed -> refused at the declared size. */
    size_t big = 4u << 20;
    uint8_t *zeros = calloc(big, 1);
    gz = gzip_bytes(zeros, big);
    free(zeros);
    b = (buf){0};
    buf_str(&b, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gz\n\n");
    buf_add(&b, gz.p, gz.n);
    expect_fail(sl_load_nrrd, b.p, b.n, "bomb.nrrd", SL_ERR_LIMIT, "nrrd gzip bomb");
    free(b.p);
    free(gz.p);
}

static void test_nrrd_vector(void)
{
    /* dimension 4, component axis first: 3 x (2x2x1). */
    buf b = {0};
    buf_str(&b, "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 2 2 1\nspace dimension: 3\n"
                "space directions: none (2,0,0) (0,2,0) (0,0,2)\nkinds: vector domain domain domain\n"
                "endian: big\nencoding: raw\n\n");
    float v[12];
    for (int i = 0; i < 12; i++) {
        v[i] = (float)(i % 3 == 0 ? 3 : i % 3 == 1 ? 4 : 0) * (float)(1 + i / 3);
        buf_f32(&b, v[i], 1);
    }
    sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, "vec.nrrd", "nrrd vector");
    if (ds) {
        SL_CHECK(ds->kind == SL_DATASET_VECTORS);
        SL_CHECK(ds->volume.components == 3 && ds->volume.type == SL_VOXEL_F32);
        SL_CHECK(ds->volume.dims[0] == 2 && ds->volume.dims[1] == 2 && ds->volume.dims[2] == 1);
        SL_CHECK_NEAR(ds->volume.spacing[0], 2.0, 0);
        const float *f = ds->volume.data;
        int same = 1;
        for (int i = 0; i < 12; i++)
            same &= f[i] == v[i];
        SL_CHECK(same);
        /* magnitudes are 5, 10, 15, 20 */
        SL_CHECK_NEAR(ds->volume.value_min, 5.0, 1e-9);
        SL_CHECK_NEAR(ds->volume.value_max, 20.0, 1e-9);
    }
    sl_dataset_destroy(ds);
    expect_prefixes_fail(sl_load_nrrd, b.p, b.n, "vec.nrrd", "nrrd vector prefixes");
    free(b.p);
}

static void test_nrrd_detached(void)
{
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", tmpdir);
    mkdir(sub, 0700);
    /* raw file with one text line to skip and 2 bytes to skip after it. */
    buf raw = {0};
    buf_str(&raw, "junk line\nXY");
    double expect[8];
    for (int i = 0; i < 8; i++) {
        expect[i] = -300 + 100 * i;
        buf_int(&raw, (uint16_t)(int16_t)(-300 + 100 * i), 2, 0);
    }
    write_file("sub/vol.raw", raw.p, raw.n);
    free(raw.p);

    const char *hdr = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nspacings: 1.5 1.5 3\nendian: little\n"
                      "encoding: raw\nline skip: 1\nbyte skip: 2\ndata file: sub/vol.raw\n";
    const char *path = write_file("head.nhdr", hdr, strlen(hdr));
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "detached nhdr: %s", err.message);
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_S16);
        SL_CHECK(strcmp(ds->name, "head") == 0);
        SL_CHECK_NEAR(ds->volume.spacing[2], 3.0, 0);
        check_values(ds, expect, 0, "nrrd detached");
        check_range(ds, expect, 8);
        SL_CHECK(ds->load_ms >= 0.0);
    }
    sl_dataset_destroy(ds);

    /* byte skip -1: the data is the last bytes of the file. */
    const char *hdr_end = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nendian: little\n"
                          "encoding: raw\nbyte skip: -1\ndatafile: sub/vol.raw\n\n";
    path = write_file("end.nhdr", hdr_end, strlen(hdr_end));
    ds = NULL;
    st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "byte skip -1: %s", err.message);
    if (ds)
        check_values(ds, expect, 0, "nrrd byte skip -1");
    sl_dataset_destroy(ds);

    /* Absolute path inside the folder is allowed. */
    char abs_hdr[1400];
    snprintf(abs_hdr, sizeof abs_hdr, "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nendian: little\n"
             "encoding: raw\nbyte skip: -1\ndata file: %s/sub/vol.raw\n", tmpdir);
    path = write_file("abs.nhdr", abs_hdr, strlen(abs_hdr));
    ds = NULL;
    st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "absolute inside: %s", err.message);
    sl_dataset_destroy(ds);

    /* Escapes: "..", absolute outside, NULL path. */
    static const char *escapes[] = {"../etc/passwd", "sub/../../x.raw", "/etc/passwd", ".."};
    for (size_t i = 0; i < sizeof escapes / sizeof escapes[0]; i++) {
        char h[512];
        snprintf(h, sizeof h, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: %s\n",
                 escapes[i]);
        char p[600];
        snprintf(p, sizeof p, "%s/sub/e.nhdr", tmpdir);
        sl_dataset *out = (sl_dataset *)(uintptr_t)1;
        st = sl_load_nrrd((const uint8_t *)h, strlen(h), p, &out, &err);
        SL_CHECK_MSG(st == SL_ERR_FORMAT && out == NULL, "escape '%s': status %d: %s", escapes[i], st, err.message);
        SL_CHECK(strstr(err.message, "data file") != NULL);
    }
    expect_fail(sl_load_nrrd, (const uint8_t *)hdr, strlen(hdr), NULL, SL_ERR_UNSUPPORTED, "detached, no path");
    /* Missing data file -> IO. */
    const char *missing = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: nope.raw\n";
    expect_fail(sl_load_nrrd, (const uint8_t *)missing, strlen(missing), tmp_path("m.nhdr"), SL_ERR_IO, "missing data file");
    const char *list = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: LIST\na.raw\n";
    expect_fail(sl_load_nrrd, (const uint8_t *)list, strlen(list), tmp_path("l.nhdr"), SL_ERR_UNSUPPORTED, "data file LIST");
}

static void test_nrrd_hostile(void)
{
    static const struct { const char *hdr; sl_status want; const char *what; } cases[] = {
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2147483648 1 1\nencoding: raw\n\n", SL_ERR_LIMIT, "size 2^31"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2147483647 2147483647 2147483647\nencoding: raw\n\n",
         SL_ERR_LIMIT, "sizes above max voxels"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 65536 65536 65536\nencoding: gzip\n\n", SL_ERR_LIMIT,
         "2^48 voxels gzip"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 0 1 1\nencoding: raw\n\n", SL_ERR_FORMAT, "zero size"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: -4 1 1\nencoding: raw\n\n", SL_ERR_FORMAT, "negative size"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1\nencoding: raw\n\n", SL_ERR_FORMAT, "too few sizes"},
        {"NRRD0004\ntype: uchar\ndimension: 2\nsizes: 1 1\nencoding: raw\n\n", SL_ERR_UNSUPPORTED, "2D"},
        {"NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 1 1 1\nencoding: raw\n\n", SL_ERR_UNSUPPORTED, "4D not vector"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\n", SL_ERR_UNSUPPORTED, "bzip2"},
        {"NRRD0004\ntype: int64\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", SL_ERR_UNSUPPORTED, "int64"},
        {"NRRD0004\ntype: quux\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", SL_ERR_FORMAT, "unknown type"},
        {"NRRD0004\ntype: uchar\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", SL_ERR_FORMAT,
         "duplicate field"},
        {"NRRD0004\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n", SL_ERR_FORMAT, "missing type"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 0 1\nencoding: raw\n\n", SL_ERR_FORMAT,
         "zero spacing"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspace directions: (1,0,0) (0,0,0) (0,0,1)\nencoding: raw\n\n",
         SL_ERR_FORMAT, "zero direction"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspace directions: (1,0) (0,1) (0,0)\nencoding: raw\n\n",
         SL_ERR_FORMAT, "2D directions"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspace origin: (inf,0,0)\nencoding: raw\n\n",
         SL_ERR_FORMAT, "infinite origin"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nbyte skip: -1\n\n", SL_ERR_FORMAT,
         "byte skip -1, no data"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: gzip\nbyte skip: -1\n\nx", SL_ERR_FORMAT,
         "byte skip -1 gzip"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nline skip: 5\n\nx", SL_ERR_FORMAT,
         "line skip past end"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nnot a field\n\nx", SL_ERR_FORMAT,
         "malformed line"},
        {"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n", SL_ERR_FORMAT, "no blank line"},
        {"NRRX0004\ntype: uchar\n\n", SL_ERR_FORMAT, "bad magic"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        expect_fail(sl_load_nrrd, (const uint8_t *)cases[i].hdr, strlen(cases[i].hdr), "h.nrrd", cases[i].want,
                    cases[i].what);
    /* Messages name the file and the field. */
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_load_nrrd((const uint8_t *)cases[0].hdr, strlen(cases[0].hdr), "h.nrrd", &ds, &err);
    SL_CHECK_MSG(strstr(err.message, "h.nrrd") && strstr(err.message, "sizes"), "message: %s", err.message);
    /* A very long header line. */
    buf b = {0};
    buf_str(&b, "NRRD0004\ncontent: ");
    for (int i = 0; i < 5000; i++)
        buf_str(&b, "x");
    buf_str(&b, "\n\n");
    expect_fail(sl_load_nrrd, b.p, b.n, "long.nrrd", SL_ERR_FORMAT, "long line");
    free(b.p);
}

/* ----------------------------------------------------------------- NIfTI */

typedef struct nii_opts {
    int big, datatype, bitpix;
    int dim[8];
    float pixdim[4];
    float vox_offset, slope, inter;
    int sform, qform;
    float offs[3];
    const char *magic;
    int sizeof_hdr;
    int use_srow;      /* write srow[][] as the sform's 3x3 part (else diag(pixdim)) */
    float srow[3][3];  /* srow[r][c]: world row r per index c */
    float quat[3];     /* quatern_b, c, d */
} nii_opts;

static buf nii_header(const nii_opts *o)
{
    uint8_t h[348];
    memset(h, 0, sizeof h);
    buf b = {0};
    buf_int(&b, (uint64_t)(o->sizeof_hdr ? o->sizeof_hdr : 348), 4, o->big);
    memcpy(h, b.p, 4);
    b.n = 0;
    for (int i = 0; i < 8; i++)
        buf_int(&b, (uint16_t)o->dim[i], 2, o->big);
    memcpy(h + 40, b.p, 16);
    b.n = 0;
    buf_int(&b, (uint16_t)o->datatype, 2, o->big);
    buf_int(&b, (uint16_t)o->bitpix, 2, o->big);
    memcpy(h + 70, b.p, 4);
    b.n = 0;
    for (int i = 0; i < 4; i++)
        buf_f32(&b, o->pixdim[i], o->big);
    memcpy(h + 76, b.p, 16);
    b.n = 0;
    buf_f32(&b, o->vox_offset, o->big);
    buf_f32(&b, o->slope, o->big);
    buf_f32(&b, o->inter, o->big);
    memcpy(h + 108, b.p, 12);
    b.n = 0;
    buf_int(&b, (uint16_t)o->qform, 2, o->big);
    buf_int(&b, (uint16_t)o->sform, 2, o->big);
    memcpy(h + 252, b.p, 4);
    b.n = 0;
    for (int i = 0; i < 3; i++)
        buf_f32(&b, o->offs[i] + 100.0f, o->big); /* qoffset: distinct from srow */
    memcpy(h + 268, b.p, 12);
    b.n = 0;
    for (int i = 0; i < 3; i++)
        buf_f32(&b, o->quat[i], o->big);
    memcpy(h + 256, b.p, 12);
    for (int r = 0; r < 3; r++) {
        b.n = 0;
        for (int c = 0; c < 4; c++)
            buf_f32(&b, c == 3 ? o->offs[r] : o->use_srow ? o->srow[r][c] : (float)(r == c) * o->pixdim[r + 1],
                    o->big);
        memcpy(h + 280 + 16 * r, b.p, 16);
    }
    memcpy(h + 344, o->magic ? o->magic : "n+1\0", 4);
    b.n = 0;
    buf_add(&b, h, sizeof h);
    while (o->vox_offset <= 4096 && b.n < (size_t)o->vox_offset)
        buf_add(&b, "\0", 1);
    return b;
}

static void test_nifti(void)
{
    for (int big = 0; big <= 1; big++) {
        nii_opts o = {.big = big, .datatype = 4, .bitpix = 16, .dim = {3, 4, 3, 2, 1, 1, 1, 1},
                      .pixdim = {1, 1.5f, 2, 2.5f}, .vox_offset = 352, .sform = 1, .offs = {-90, 126, -72}};
        buf b = nii_header(&o);
        double expect[24];
        for (int i = 0; i < 24; i++) {
            expect[i] = -1000 + 97 * i;
            buf_int(&b, (uint16_t)(int16_t)(-1000 + 97 * i), 2, big);
        }
        sl_dataset *ds = expect_load(sl_load_nifti, b.p, b.n, "t1.nii", big ? "nifti swapped" : "nifti native");
        if (ds) {
            SL_CHECK(ds->volume.type == SL_VOXEL_S16);
            SL_CHECK(ds->volume.dims[0] == 4 && ds->volume.dims[1] == 3 && ds->volume.dims[2] == 2);
            SL_CHECK_NEAR(ds->volume.spacing[0], 1.5, 0);
            SL_CHECK_NEAR(ds->volume.spacing[2], 2.5, 0);
            SL_CHECK_NEAR(ds->origin.x, -90, 0);
            SL_CHECK_NEAR(ds->origin.y, 126, 0);
            SL_CHECK_NEAR(ds->origin.z, -72, 0);
            check_values(ds, expect, 0, "nifti s16");
            check_range(ds, expect, 24);
        }
        sl_dataset_destroy(ds);
        expect_prefixes_fail(sl_load_nifti, b.p, b.n, "t1.nii", "nifti prefixes");
        free(b.p);
    }
    /* qform only: origin from qoffset. Scaling u8 -> f32: v * 0.5 - 10. */
    nii_opts o = {.datatype = 2, .bitpix = 8, .dim = {3, 3, 1, 1, 1, 1, 1, 1}, .pixdim = {1, 1, 1, 1},
                  .vox_offset = 348, .slope = 0.5f, .inter = -10, .qform = 1, .offs = {1, 2, 3}};
    buf b = nii_header(&o);
    uint8_t u8[3] = {0, 7, 255};
    buf_add(&b, u8, 3);
    sl_dataset *ds = expect_load(sl_load_nifti, b.p, b.n, NULL, "nifti scaled");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_F32);
        double e[3] = {-10, -6.5, 117.5};
        check_values(ds, e, 0, "nifti scaled");
        SL_CHECK_NEAR(ds->origin.x, 101, 0);
    }
    sl_dataset_destroy(ds);
    free(b.p);
    /* slope 1, inter 0: kept as u8. f64 -> f32. */
    o.slope = 1;
    o.inter = 0;
    b = nii_header(&o);
    buf_add(&b, u8, 3);
    ds = expect_load(sl_load_nifti, b.p, b.n, NULL, "nifti identity scale");
    if (ds)
        SL_CHECK(ds->volume.type == SL_VOXEL_U8);
    sl_dataset_destroy(ds);
    free(b.p);
    nii_opts o64 = {.big = 1, .datatype = 64, .bitpix = 64, .dim = {3, 2, 1, 1, 1, 1, 1, 1},
                    .pixdim = {1, 0, 1, 1}, .vox_offset = 352};
    b = nii_header(&o64);
    buf_f64(&b, 0.25, 1);
    buf_f64(&b, -1e300, 1);
    ds = expect_load(sl_load_nifti, b.p, b.n, NULL, "nifti f64");
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_F32);
        SL_CHECK_NEAR(ds->volume.spacing[0], 1.0, 0); /* pixdim 0 means unknown */
        const float *f = ds->volume.data;
        SL_CHECK(f[0] == 0.25f && isinf(f[1]) && f[1] < 0);
    }
    sl_dataset_destroy(ds);
    free(b.p);
    /* Vector field: three planes interleaved. */
    nii_opts ov = {.datatype = 16, .bitpix = 32, .dim = {5, 2, 1, 1, 1, 3, 1, 1}, .pixdim = {1, 1, 1, 1},
                   .vox_offset = 352};
    b = nii_header(&ov);
    float planes[6] = {1, 2, 10, 20, 100, 200}; /* x of voxel 0,1; y of 0,1; z of 0,1 */
    for (int i = 0; i < 6; i++)
        buf_f32(&b, planes[i], 0);
    ds = expect_load(sl_load_nifti, b.p, b.n, NULL, "nifti vector");
    if (ds) {
        SL_CHECK(ds->kind == SL_DATASET_VECTORS && ds->volume.components == 3);
        const float *f = ds->volume.data;
        SL_CHECK(f[0] == 1 && f[1] == 10 && f[2] == 100 && f[3] == 2 && f[4] == 20 && f[5] == 200);
    }
    sl_dataset_destroy(ds);
    free(b.p);

    /* Hostile headers. */
    struct { nii_opts o; size_t data; sl_status want; const char *what; } bad[] = {
        {{.datatype = 2, .dim = {3, -1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_FORMAT, "negative dim"},
        {{.datatype = 2, .dim = {3, 0, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_FORMAT, "zero dim"},
        {{.datatype = 2, .dim = {3, 32767, 32767, 32767}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_LIMIT,
         "2^45 voxels"},
        {{.datatype = 2, .dim = {3, 32767, 32767, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_FORMAT,
         "lying dims"},
        {{.datatype = 2, .dim = {9, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_FORMAT, "dim[0] 9"},
        {{.datatype = 2, .dim = {4, 1, 1, 1, 2}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_UNSUPPORTED,
         "time series"},
        {{.datatype = 128, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352}, 4, SL_ERR_UNSUPPORTED, "rgb"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 1e6f}, 4, SL_ERR_FORMAT,
         "vox_offset past end"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 1e9f}, 4, SL_ERR_LIMIT,
         "vox_offset above 64 MiB"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 100}, 4, SL_ERR_FORMAT,
         "vox_offset in header"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, INFINITY, 1, 1}, .vox_offset = 352}, 4, SL_ERR_FORMAT,
         "infinite pixdim"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352, .magic = "ni1\0"}, 4,
         SL_ERR_UNSUPPORTED, "ni1 pair"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352, .magic = "abc\0"}, 4,
         SL_ERR_FORMAT, "no magic"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352, .sizeof_hdr = 540}, 4,
         SL_ERR_UNSUPPORTED, "nifti-2"},
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 352, .sizeof_hdr = 12}, 4,
         SL_ERR_FORMAT, "bad sizeof_hdr"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        b = nii_header(&bad[i].o);
        for (size_t k = 0; k < bad[i].data; k++)
            buf_add(&b, "\1", 1);
        expect_fail(sl_load_nifti, b.p, b.n, "bad.nii", bad[i].want, bad[i].what);
        free(b.p);
    }
}

/* ------------------------------------------------------------- raw+json */

static void test_raw_json(void)
{
    buf raw = {0};
    double expect[6];
    for (int i = 0; i < 6; i++) {
        expect[i] = 60000 - 11111 * i;
        buf_int(&raw, (uint64_t)(60000 - 11111 * i), 2, 1);
    }
    write_file("r.raw", raw.p, raw.n);
    const char *json = "{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"spacing\": [0.25, 0.5, 4],"
                       " \"origin\": [-1, -2, -3], \"endian\": \"big\"}";
    const char *path = write_file("r.json", json, strlen(json));
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "raw json: %s", err.message);
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_U16);
        SL_CHECK(strcmp(ds->name, "r") == 0);
        SL_CHECK_NEAR(ds->volume.spacing[0], 0.25, 0);
        SL_CHECK_NEAR(ds->volume.spacing[2], 4, 0);
        SL_CHECK_NEAR(ds->origin.y, -2, 0);
        check_values(ds, expect, 0, "raw json u16");
        check_range(ds, expect, 6);
    }
    sl_dataset_destroy(ds);

    /* gzipped raw, f32 vectors. */
    buf vec = {0};
    for (int i = 0; i < 6; i++)
        buf_f32(&vec, (float)(i + 1), 0);
    buf gz = gzip_bytes(vec.p, vec.n);
    write_file("v.raw.gz", gz.p, gz.n);
    free(gz.p);
    const char *vjson = "{\"raw\": \"v.raw.gz\", \"dims\": [2, 1, 1], \"type\": \"f32\", \"components\": 3}";
    ds = expect_load(sl_load_raw_json, (const uint8_t *)vjson, strlen(vjson), tmp_path("v.json"), "raw json vector");
    if (ds) {
        SL_CHECK(ds->kind == SL_DATASET_VECTORS);
        SL_CHECK_NEAR(ds->volume.value_max, sqrt(16.0 + 25 + 36), 1e-6);
        SL_CHECK(((float *)ds->volume.data)[5] == 6.0f);
    }
    sl_dataset_destroy(ds);
    free(vec.p);

    /* Hostile sidecars. */
    static const struct { const char *json; sl_status want; const char *what; } bad[] = {
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 2], \"type\": \"u16\"}", SL_ERR_FORMAT, "file too short"},
        {"{\"raw\": \"r.raw\", \"dims\": [5, 1, 1], \"type\": \"u16\"}", SL_ERR_FORMAT, "file too long"},
        {"{\"raw\": \"r.raw\", \"dims\": [2147483648, 1, 1], \"type\": \"u8\"}", SL_ERR_LIMIT, "dims 2^31"},
        {"{\"raw\": \"r.raw\", \"dims\": [2000000, 2000000, 1], \"type\": \"u8\"}", SL_ERR_LIMIT, "dims over max voxels"},
        {"{\"raw\": \"r.raw\", \"dims\": [0, 1, 1], \"type\": \"u8\"}", SL_ERR_FORMAT, "zero dim"},
        {"{\"raw\": \"r.raw\", \"dims\": [-3, 1, 1], \"type\": \"u8\"}", SL_ERR_FORMAT, "negative dim"},
        {"{\"raw\": \"r.raw\", \"dims\": [1.5, 1, 1], \"type\": \"u8\"}", SL_ERR_FORMAT, "fractional dim"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2], \"type\": \"u8\"}", SL_ERR_FORMAT, "two dims"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"s32\"}", SL_ERR_FORMAT, "bad type"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"spacing\": [1, 0, 1]}", SL_ERR_FORMAT,
         "zero spacing"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"endian\": \"middle\"}", SL_ERR_FORMAT,
         "bad endian"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"components\": 2}", SL_ERR_FORMAT,
         "two components"},
        {"{\"raw\": \"../r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\"}", SL_ERR_FORMAT, "escape .."},
        {"{\"raw\": \"/etc/passwd\", \"dims\": [3, 2, 1], \"type\": \"u8\"}", SL_ERR_FORMAT, "escape absolute"},
        {"{\"raw\": \"none.raw\", \"dims\": [3, 2, 1], \"type\": \"u8\"}", SL_ERR_IO, "missing raw"},
        {"{\"dims\": [3, 2, 1], \"type\": \"u8\"}", SL_ERR_FORMAT, "no raw"},
        {"[1, 2]", SL_ERR_FORMAT, "not an object"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\"", SL_ERR_FORMAT, "truncated json"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        expect_fail(sl_load_raw_json, (const uint8_t *)bad[i].json, strlen(bad[i].json), tmp_path("bad.json"),
                    bad[i].want, bad[i].what);
    expect_fail(sl_load_raw_json, (const uint8_t *)json, strlen(json), NULL, SL_ERR_UNSUPPORTED, "json, no path");
    /* Strict keys: a typo must not silently read little-endian; a repeated key is refused too. */
    static const struct { const char *json, *word; } strict[] = {
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"endianness\": \"big\"}",
         "unknown key 'endianness'"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"Spacing\": [1, 1, 1]}",
         "unknown key 'Spacing'"},
        {"{\"raw\": \"r.raw\", \"dims\": [3, 2, 1], \"type\": \"u16\", \"endian\": \"big\", \"endian\": \"little\"}",
         "key 'endian' appears twice"},
    };
    for (size_t i = 0; i < sizeof strict / sizeof strict[0]; i++) {
        sl_dataset *out = (sl_dataset *)(uintptr_t)1;
        st = sl_load_raw_json((const uint8_t *)strict[i].json, strlen(strict[i].json), tmp_path("s.json"), &out, &err);
        SL_CHECK_MSG(st == SL_ERR_FORMAT && out == NULL && strstr(err.message, strict[i].word) &&
                         strstr(err.message, "s.json"),
                     "strict sidecar %zu: status %d: %s", i, st, err.message);
    }
    /* A .gz raw file that is /dev/zero: refused after at most the input bound, at once. */
    const char *zgz = tmp_path("zero.raw.gz");
    unlink(zgz);
    if (symlink("/dev/zero", zgz) != 0)
        abort();
    const char *zjson = "{\"raw\": \"zero.raw.gz\", \"dims\": [2, 2, 2], \"type\": \"u8\"}";
    sl_dataset *zout = NULL;
    st = sl_load_raw_json((const uint8_t *)zjson, strlen(zjson), tmp_path("z.json"), &zout, &err);
    SL_CHECK_MSG(st == SL_ERR_FORMAT && zout == NULL && strstr(err.message, "zero.raw.gz") &&
                     strstr(err.message, "larger than a gzip stream of the 8 bytes"),
                 "raw.gz -> /dev/zero: status %d: %s", st, err.message);
    unlink(zgz);
    expect_prefixes_fail(sl_load_raw_json, (const uint8_t *)json, strlen(json), tmp_path("r.json"), "json prefixes");
    free(raw.p);
}

/* ------------------------------------------------------- gunzip, files */

static void test_gunzip(void)
{
    uint8_t text[3000];
    for (size_t i = 0; i < sizeof text; i++)
        text[i] = (uint8_t)(i * 31 + i / 7);
    buf gz = gzip_bytes(text, sizeof text);
    uint8_t *out = NULL;
    size_t n = 0;
    sl_err err = {0};
    SL_CHECK(sl_gunzip(gz.p, gz.n, sizeof text, &out, &n, &err) == SL_OK);
    SL_CHECK(n == sizeof text && out && memcmp(out, text, n) == 0);
    free(out);
    /* One byte under the output size: limit. */
    SL_CHECK(sl_gunzip(gz.p, gz.n, sizeof text - 1, &out, &n, &err) == SL_ERR_LIMIT && out == NULL);
    /* Every truncation fails with FORMAT. */
    int bad = 0;
    for (size_t len = 0; len < gz.n; len++) {
        uint8_t *copy = malloc(len ? len : 1);
        memcpy(copy, gz.p, len);
        sl_status st = sl_gunzip(copy, len, 1 << 20, &out, &n, &err);
        if (st != SL_ERR_FORMAT || out != NULL)
            bad++;
        free(out);
        out = NULL;
        free(copy);
    }
    SL_CHECK_MSG(bad == 0, "%d gzip truncations did not give SL_ERR_FORMAT", bad);
    /* Corrupt CRC. */
    gz.p[gz.n - 6] ^= 0x55;
    SL_CHECK(sl_gunzip(gz.p, gz.n, 1 << 20, &out, &n, &err) == SL_ERR_FORMAT && out == NULL);
    gz.p[gz.n - 6] ^= 0x55;
    /* Two members concatenated, then trailing zeros. */
    buf two = {0};
    buf_add(&two, gz.p, gz.n);
    buf_add(&two, gz.p, gz.n);
    buf_add(&two, "\0\0\0\0", 4);
    SL_CHECK(sl_gunzip(two.p, two.n, 2 * sizeof text, &out, &n, &err) == SL_OK);
    SL_CHECK(n == 2 * sizeof text && out && memcmp(out + sizeof text, text, sizeof text) == 0);
    free(out);
    free(two.p);
    free(gz.p);
    /* Bomb: 16 MiB of zeros in ~16 KiB, limit 1 MiB -> LIMIT quickly, little memory. */
    size_t big = 16u << 20;
    uint8_t *zeros = calloc(big, 1);
    gz = gzip_bytes(zeros, big);
    free(zeros);
    SL_CHECK_MSG(gz.n < big / 500, "bomb compresses to %zu bytes", gz.n);
    SL_CHECK(sl_gunzip(gz.p, gz.n, 1u << 20, &out, &n, &err) == SL_ERR_LIMIT && out == NULL);
    SL_CHECK(strstr(err.message, "limit") != NULL);
    /* And through sl_read_file. */
    const char *path = write_file("bomb.bin.gz", gz.p, gz.n);
    SL_CHECK(sl_read_file(path, 1u << 20, &out, &n, &err) == SL_ERR_LIMIT && out == NULL);
    SL_CHECK(strstr(err.message, "bomb.bin.gz") != NULL);
    SL_CHECK(sl_read_file(path, big, &out, &n, &err) == SL_OK && n == big);
    free(out);
    free(gz.p);
    /* Not gzip. */
    SL_CHECK(sl_gunzip((const uint8_t *)"hello world, not gzip", 21, 100, &out, &n, &err) == SL_ERR_FORMAT);
}

static void expect_file_fails_fast(const char *path, sl_status want, const char *word, double max_s,
                                   const char *what);

static void test_files(void)
{
    uint8_t *data = NULL;
    size_t n = 0;
    sl_err err = {0};
    const char *path = write_file("plain.txt", "0123456789", 10);
    SL_CHECK(sl_read_file(path, 10, &data, &n, &err) == SL_OK && n == 10 && memcmp(data, "0123456789", 10) == 0);
    free(data);
    SL_CHECK(sl_read_file(path, 9, &data, &n, &err) == SL_ERR_LIMIT && data == NULL);
    SL_CHECK(sl_read_file(tmp_path("absent.bin"), 100, &data, &n, &err) == SL_ERR_IO && data == NULL);
    SL_CHECK(strstr(err.message, "absent.bin") != NULL);
    SL_CHECK(sl_read_file(tmpdir, 100, &data, &n, &err) == SL_ERR_IO && data == NULL);
    path = write_file("empty.bin", "", 0);
    SL_CHECK(sl_read_file(path, 100, &data, &n, &err) == SL_OK && n == 0 && data != NULL);
    free(data);

    sl_dataset *ds = (sl_dataset *)(uintptr_t)1;
    SL_CHECK(sl_load_file(tmp_path("x.png"), &ds, &err) == SL_ERR_UNSUPPORTED && ds == NULL);
    SL_CHECK(strstr(err.message, ".nrrd") && strstr(err.message, ".nii.gz") && strstr(err.message, "x.png"));
    SL_CHECK(sl_load_file(tmp_path("missing.nrrd"), &ds, &err) == SL_ERR_IO && ds == NULL);

    /* .nii.gz: gunzipped by sl_read_file, name without both extensions; upper case extension. */
    nii_opts o = {.datatype = 512, .bitpix = 16, .dim = {3, 2, 2, 1, 1, 1, 1, 1}, .pixdim = {1, 1, 1, 1},
                  .vox_offset = 352};
    buf b = nii_header(&o);
    for (int i = 0; i < 4; i++)
        buf_int(&b, (uint64_t)(65535 - i), 2, 0);
    buf gz = gzip_bytes(b.p, b.n);
    path = write_file("brain.NII.GZ", gz.p, gz.n);
    ds = NULL;
    SL_CHECK_MSG(sl_load_file(path, &ds, &err) == SL_OK, "nii.gz: %s", err.message);
    if (ds) {
        SL_CHECK(strcmp(ds->name, "brain") == 0);
        SL_CHECK(ds->volume.type == SL_VOXEL_U16);
        SL_CHECK_NEAR(ds->volume.value_max, 65535, 0);
        SL_CHECK_NEAR(ds->volume.value_min, 65532, 0);
    }
    sl_dataset_destroy(ds);
    /* Empty files of the header-probed formats: a clear error, no endless probing. */
    expect_file_fails_fast(write_file("empty.nii", "", 0), SL_ERR_FORMAT, "348", 1.0, "empty .nii");
    expect_file_fails_fast(write_file("empty.nrrd", "", 0), SL_ERR_FORMAT, "NRRD", 1.0, "empty .nrrd");
    /* Truncated .nii.gz -> FORMAT naming the file. */
    path = write_file("cut.nii.gz", gz.p, gz.n / 2);
    ds = NULL;
    SL_CHECK(sl_load_file(path, &ds, &err) == SL_ERR_FORMAT && ds == NULL);
    SL_CHECK(strstr(err.message, "cut.nii.gz") != NULL);
    free(gz.p);
    free(b.p);
}

/* ------------------------------------------- hostile files on disk */

/* Peak resident memory of this process so far, in MiB. */
static double peak_rss_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* A symbolic link name -> target in the test folder (removed at the end). */
static const char *make_link(const char *name, const char *target)
{
    const char *path = tmp_path(name);
    unlink(path);
    if (symlink(target, path) != 0)
        abort();
    if (written_count < 128)
        snprintf(written[written_count++], sizeof written[0], "%s", path);
    return path;
}

/* A sparse file of `size` bytes (all zeros, no disk blocks). */
static const char *make_sparse(const char *name, off_t size)
{
    const char *path = write_file(name, "", 0);
    if (truncate(path, size) != 0)
        abort();
    return path;
}

/* sl_load_file(path) must fail with status want, within max_s seconds,
 * naming the file and the given word. */
static void expect_file_fails_fast(const char *path, sl_status want, const char *word, double max_s, const char *what)
{
    sl_dataset *ds = (sl_dataset *)(uintptr_t)1;
    sl_err err = {0};
    double t0 = sl_clock_ms();
    sl_status st = sl_load_file(path, &ds, &err);
    double dt = (sl_clock_ms() - t0) / 1e3;
    SL_CHECK_MSG(st == want && ds == NULL, "%s: status %s, want %s: %s", what, sl_status_name(st),
                 sl_status_name(want), err.message);
    SL_CHECK_MSG(dt < max_s, "%s: took %.2f s (bound %.1f s)", what, dt, max_s);
    SL_CHECK_MSG(strstr(err.message, word) != NULL, "%s: message lacks '%s': %s", what, word, err.message);
    if (st == SL_OK)
        sl_dataset_destroy(ds);
}

/* Audit item: a tiny .nhdr whose data file is /dev/zero or a huge file must
 * not make the loader read more than the header can use. */
static void test_nrrd_detached_bounded(void)
{
    double rss0 = peak_rss_mib();
    make_link("zero.raw", "/dev/zero");
    make_sparse("huge.raw", (off_t)5 << 30); /* 5 GiB, above the 4 GiB general limit */
    static const struct { const char *name, *hdr, *word; sl_status want; } cases[] = {
        {"z_raw.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: zero.raw\n",
         "holds more than the 8 bytes", SL_ERR_FORMAT},
        {"z_skip.nhdr",
         "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nbyte skip: 16\ndata file: zero.raw\n",
         "holds more than the 24 bytes", SL_ERR_FORMAT},
        {"z_lines.nhdr",
         "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nline skip: 2\ndata file: zero.raw\n",
         "data file", SL_ERR_FORMAT},
        {"z_gzip.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\ndata file: zero.raw\n",
         "data file", SL_ERR_FORMAT},
        {"z_ascii.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\ndata file: zero.raw\n",
         "data file", SL_ERR_FORMAT},
        {"z_end.nhdr",
         "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nbyte skip: -1\ndata file: zero.raw\n",
         "not a regular file", SL_ERR_IO},
        {"h_raw.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: huge.raw\n",
         "holds more than the 8 bytes", SL_ERR_FORMAT},
        {"h_gzip.nhdr", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\ndata file: huge.raw\n",
         "data file", SL_ERR_FORMAT},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *path = write_file(cases[i].name, cases[i].hdr, strlen(cases[i].hdr));
        expect_file_fails_fast(path, cases[i].want, cases[i].word, 2.0, cases[i].name);
    }
    /* byte skip -1 on the sparse 5 GiB file: its last 8 bytes are the data (seeked to, not read through). */
    const char *end = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 1\nencoding: raw\nbyte skip: -1\n"
                      "data file: huge.raw\n";
    const char *path = write_file("h_end.nhdr", end, strlen(end));
    sl_dataset *ds = NULL;
    sl_err err = {0};
    double t0 = sl_clock_ms();
    sl_status st = sl_load_file(path, &ds, &err);
    double dt = (sl_clock_ms() - t0) / 1e3;
    SL_CHECK_MSG(st == SL_OK && ds, "byte skip -1 on a sparse 5 GiB file: %s", err.message);
    SL_CHECK_MSG(dt < 2.0, "byte skip -1 on a sparse 5 GiB file took %.2f s", dt);
    if (ds) {
        double zero[4] = {0, 0, 0, 0};
        check_values(ds, zero, 0, "tail of sparse file");
    }
    sl_dataset_destroy(ds);
    /* A data file shorter than byte skip -1 needs. */
    write_file("short.raw", "abc", 3);
    const char *shorter = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 1\nencoding: raw\nbyte skip: -1\n"
                          "data file: short.raw\n";
    path = write_file("short.nhdr", shorter, strlen(shorter));
    expect_file_fails_fast(path, SL_ERR_FORMAT, "fewer than the 8 needed", 2.0, "byte skip -1, short file");
    double grown = peak_rss_mib() - rss0;
    SL_CHECK_MSG(grown < 64.0, "hostile detached files raised the peak RSS by %.0f MiB", grown);
    /* An attached .nrrd or a .nii that is /dev/zero: refused from the first bytes. */
    expect_file_fails_fast(make_link("zero.nrrd", "/dev/zero"), SL_ERR_FORMAT, "NRRD", 2.0, ".nrrd -> /dev/zero");
    expect_file_fails_fast(make_link("zero.nii", "/dev/zero"), SL_ERR_FORMAT, "sizeof_hdr", 2.0, ".nii -> /dev/zero");
    expect_file_fails_fast(make_link("zero.nhdr", "/dev/zero"), SL_ERR_FORMAT, "NRRD", 2.0, ".nhdr -> /dev/zero");
}

/* Detached .nhdr with encoding gzip: good, and a bomb. */
static void test_nrrd_detached_gzip(void)
{
    buf raw = {0};
    double expect[12];
    buf_str(&raw, "SKIP");
    for (int i = 0; i < 12; i++) {
        expect[i] = -50 + 9 * i;
        buf_int(&raw, (uint16_t)(int16_t)(-50 + 9 * i), 2, 1);
    }
    buf gz = gzip_bytes(raw.p, raw.n);
    write_file("g.raw.gz", gz.p, gz.n);
    free(gz.p);
    free(raw.p);
    const char *hdr = "NRRD0005\ntype: int16\ndimension: 3\nsizes: 3 2 2\nendian: big\nencoding: gzip\n"
                      "byte skip: 4\ndata file: g.raw.gz\n";
    const char *path = write_file("g.nhdr", hdr, strlen(hdr));
    sl_dataset *ds = NULL;
    sl_err err = {0};
    SL_CHECK_MSG(sl_load_file(path, &ds, &err) == SL_OK, "detached gzip: %s", err.message);
    if (ds) {
        SL_CHECK(ds->volume.type == SL_VOXEL_S16 && ds->volume.dims[0] == 3 && ds->volume.dims[2] == 2);
        check_values(ds, expect, 0, "nrrd detached gzip");
        check_range(ds, expect, 12);
    }
    sl_dataset_destroy(ds);
    /* The same file with no byte skip is 4 bytes too long once inflated. */
    const char *no_skip = "NRRD0005\ntype: int16\ndimension: 3\nsizes: 3 2 2\nendian: big\nencoding: gzip\n"
                          "data file: g.raw.gz\n";
    path = write_file("g2.nhdr", no_skip, strlen(no_skip));
    expect_file_fails_fast(path, SL_ERR_LIMIT, "limit of 24", 2.0, "detached gzip without byte skip");
    /* Bomb: 64 MiB of zeros (~64 KiB compressed) behind a 2x2x2 header. */
    size_t big = 64u << 20;
    uint8_t *zeros = calloc(big, 1);
    gz = gzip_bytes(zeros, big);
    free(zeros);
    write_file("bomb.raw.gz", gz.p, gz.n);
    free(gz.p);
    const char *bomb = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\ndata file: bomb.raw.gz\n";
    path = write_file("bomb.nhdr", bomb, strlen(bomb));
    expect_file_fails_fast(path, SL_ERR_LIMIT, "inflates past the limit of 8", 2.0, "detached gzip bomb");
}

/* A gzip file of `prefix` followed by `mib` MiB of zeros: one member for
 * the prefix, then one ~1 KB member per MiB of zeros (concatenated gzip is
 * one file to every reader, and this is fast to build). */
static buf gzip_with_zeros(const uint8_t *prefix, size_t n, unsigned mib)
{
    buf out = {0};
    if (n) {
        buf head = gzip_bytes(prefix, n);
        buf_add(&out, head.p, head.n);
        free(head.p);
    }
    uint8_t *zeros = calloc(1u << 20, 1);
    buf member = gzip_bytes(zeros, 1u << 20);
    free(zeros);
    for (unsigned k = 0; k < mib; k++)
        buf_add(&out, member.p, member.n);
    free(member.p);
    return out;
}

/* Audit item: a 1 MB .nii.gz that inflates to 1 GiB is read only as far as
 * its header says; formats without a stated size are capped by ratio. */
static void test_gzip_bombs(void)
{
    nii_opts o = {.datatype = 2, .bitpix = 8, .dim = {3, 2, 2, 2, 1, 1, 1, 1}, .pixdim = {1, 1, 1, 1},
                  .vox_offset = 352};
    buf b = nii_header(&o);
    for (int i = 0; i < 8; i++)
        buf_int(&b, (uint64_t)(10 + i), 1, 0);
    buf gz = gzip_with_zeros(b.p, b.n, 1024);
    SL_CHECK_MSG(gz.n < (2u << 20), "1 GiB bomb compresses to %zu bytes", gz.n);
    const char *path = write_file("bomb.nii.gz", gz.p, gz.n);
    double rss0 = peak_rss_mib(), t0 = sl_clock_ms();
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(path, &ds, &err);
    double dt = (sl_clock_ms() - t0) / 1e3, grown = peak_rss_mib() - rss0;
    SL_CHECK_MSG(st == SL_OK && ds, "nii.gz bomb with a valid header: %s", err.message);
    SL_CHECK_MSG(dt < 1.0, "nii.gz bomb took %.2f s", dt);
    SL_CHECK_MSG(grown < 16.0, "nii.gz bomb raised the peak RSS by %.0f MiB", grown);
    if (ds) {
        double e[8] = {10, 11, 12, 13, 14, 15, 16, 17};
        check_values(ds, e, 0, "nii.gz bomb voxels");
    }
    sl_dataset_destroy(ds);
    free(gz.p);

    /* The header lies: dims 1024^3 u8 but only 16 MiB of zeros follow: it costs what the file holds. */
    nii_opts lie = o;
    lie.dim[1] = lie.dim[2] = lie.dim[3] = 1024;
    free(b.p);
    b = nii_header(&lie);
    gz = gzip_with_zeros(b.p, b.n, 16);
    path = write_file("liar.nii.gz", gz.p, gz.n);
    rss0 = peak_rss_mib();
    expect_file_fails_fast(path, SL_ERR_FORMAT, "truncated", 5.0, "nii.gz with a lying dim");
    grown = peak_rss_mib() - rss0;
    SL_CHECK_MSG(grown < 96.0, "nii.gz with a lying dim raised the peak RSS by %.0f MiB (16 MiB content)", grown);
    free(gz.p);
    free(b.p);

    /* vox_offset far past the header: refused before inflating. */
    nii_opts far = o;
    far.vox_offset = 1e9f;
    b = nii_header(&far);
    gz = gzip_bytes(b.p, b.n);
    path = write_file("far.nii.gz", gz.p, gz.n);
    expect_file_fails_fast(path, SL_ERR_LIMIT, "vox_offset", 1.0, "nii.gz with vox_offset 1e9");
    free(gz.p);
    free(b.p);

    /* A gzip stream of empty stored blocks: no output, endless input; refused at the input bound. */
    buf empty = {0};
    static const uint8_t gz_header[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3};
    buf_add(&empty, gz_header, sizeof gz_header);
    for (int i = 0; i < 40000; i++)
        buf_add(&empty, "\0\0\0\377\377", 5);
    path = write_file("empty_blocks.nii.gz", empty.p, empty.n);
    expect_file_fails_fast(path, SL_ERR_LIMIT, "compressed bytes", 1.0, "endless empty deflate blocks");
    free(empty.p);

    /* A line format states no size: 1 GiB of zeros in ~1 MB stops at 64 MiB. */
    gz = gzip_with_zeros(NULL, 0, 1024);
    path = write_file("bomb.trk.gz", gz.p, gz.n);
    expect_file_fails_fast(path, SL_ERR_LIMIT, "64 x the compressed size", 5.0, "trk.gz bomb");
    free(gz.p);
    /* Attached .nrrd.gz with raw data: read to header + data + 1 byte, no further. */
    buf n = {0};
    buf_str(&n, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    for (int i = 0; i < 8; i++)
        buf_int(&n, (uint64_t)i, 1, 0);
    gz = gzip_with_zeros(n.p, n.n, 1024);
    path = write_file("bomb.nrrd.gz", gz.p, gz.n);
    rss0 = peak_rss_mib();
    expect_file_fails_fast(path, SL_ERR_FORMAT, "need exactly 8", 1.0, "nrrd.gz with 1 GiB after the data");
    grown = peak_rss_mib() - rss0;
    SL_CHECK_MSG(grown < 16.0, "nrrd.gz bomb raised the peak RSS by %.0f MiB", grown);
    free(gz.p);
    gz = gzip_bytes(n.p, n.n);
    path = write_file("ok.nrrd.gz", gz.p, gz.n);
    ds = NULL;
    SL_CHECK_MSG(sl_load_file(path, &ds, &err) == SL_OK, "nrrd.gz: %s", err.message);
    if (ds) {
        double e[8] = {0, 1, 2, 3, 4, 5, 6, 7};
        check_values(ds, e, 0, "nrrd.gz");
    }
    sl_dataset_destroy(ds);
    free(gz.p);
    free(n.p);
}

/* ------------------------------------------------------------ orientation */

/* Every stored voxel k (x fastest in dims) sits at world origin + sum_a i_a * axes[a];
 * the loaded volume must hold its value at that world position, on its grid. */
static void check_world(const sl_dataset *ds, const int dims[3], const double axes[3][3], const double origin[3],
                        const double *values, const char *what)
{
    const sl_volume *v = &ds->volume;
    const double o[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    int bad = 0;
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX};
    size_t k = 0;
    for (int i2 = 0; i2 < dims[2]; i2++)
        for (int i1 = 0; i1 < dims[1]; i1++)
            for (int i0 = 0; i0 < dims[0]; i0++, k++) {
                size_t idx[3];
                int inside = 1;
                for (int c = 0; c < 3; c++) {
                    double w = origin[c] + i0 * axes[0][c] + i1 * axes[1][c] + i2 * axes[2][c];
                    if (w < lo[c])
                        lo[c] = w;
                    double g = (w - o[c]) / v->spacing[c];
                    long r = lround(g);
                    inside &= fabs(g - (double)r) < 1e-9 && r >= 0 && r < v->dims[c];
                    idx[c] = (size_t)(r < 0 ? 0 : r);
                }
                if (!inside || sl_volume_value(v, idx[0], idx[1], idx[2], 0) != values[k]) {
                    if (bad++ < 3)
                        fprintf(stderr, "%s: stored voxel %zu (value %g) is not at its world position\n", what, k,
                                values[k]);
                }
            }
    SL_CHECK_MSG(bad == 0, "%s: %d voxels misplaced", what, bad);
    SL_CHECK_NEAR(ds->bounds_min.x, lo[0], 1e-9);
    SL_CHECK_NEAR(ds->bounds_min.y, lo[1], 1e-9);
    SL_CHECK_NEAR(ds->bounds_min.z, lo[2], 1e-9);
}

static void test_orientation(void)
{
    /* NRRD: LPS-style negative x and z, and a permutation with flips. */
    static const struct { const char *dirs; double axes[3][3]; int dims[3]; } nrrd_cases[] = {
        {"(-2,0,0) (0,3,0) (0,0,-1)", {{-2, 0, 0}, {0, 3, 0}, {0, 0, -1}}, {3, 2, 2}},
        {"(0,0.5,0) (2,0,0) (0,0,-3)", {{0, 0.5, 0}, {2, 0, 0}, {0, 0, -3}}, {4, 3, 2}},
        {"(0,0,-1.5) (0,-1,0) (4,0,0)", {{0, 0, -1.5}, {0, -1, 0}, {4, 0, 0}}, {2, 3, 4}},
    };
    const double origin[3] = {10, 20, 30};
    for (size_t t = 0; t < sizeof nrrd_cases / sizeof nrrd_cases[0]; t++) {
        const int *d = nrrd_cases[t].dims;
        buf b = {0};
        char hdr[512];
        snprintf(hdr, sizeof hdr,
                 "NRRD0005\ntype: uchar\ndimension: 3\nsizes: %d %d %d\nspace: left-posterior-superior\n"
                 "space directions: %s\nspace origin: (10,20,30)\nencoding: raw\n\n",
                 d[0], d[1], d[2], nrrd_cases[t].dirs);
        buf_str(&b, hdr);
        double values[64];
        int n = d[0] * d[1] * d[2];
        for (int i = 0; i < n; i++) {
            values[i] = 3 * i + 1;
            buf_int(&b, (uint64_t)(3 * i + 1), 1, 0);
        }
        sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, "o.nrrd", nrrd_cases[t].dirs);
        if (ds) {
            for (int c = 0; c < 3; c++)
                SL_CHECK(ds->volume.spacing[c] > 0);
            check_world(ds, d, nrrd_cases[t].axes, origin, values, nrrd_cases[t].dirs);
        }
        sl_dataset_destroy(ds);
        free(b.p);
    }
    /* A 4D vector field with a flipped axis: vectors move with their voxels, unchanged. */
    buf b = {0};
    buf_str(&b, "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 2 1 1\nspace directions: none (-1,0,0) (0,1,0) "
                "(0,0,1)\nspace origin: (5,0,0)\nendian: little\nencoding: raw\n\n");
    for (int i = 0; i < 6; i++)
        buf_f32(&b, (float)(i + 1), 0);
    sl_dataset *ds = expect_load(sl_load_nrrd, b.p, b.n, "ov.nrrd", "nrrd flipped vectors");
    if (ds) {
        const float *f = ds->volume.data;
        SL_CHECK(f[0] == 4 && f[1] == 5 && f[2] == 6 && f[3] == 1 && f[4] == 2 && f[5] == 3);
        SL_CHECK_NEAR(ds->origin.x, 4.0, 0);
    }
    sl_dataset_destroy(ds);
    free(b.p);

    /* NIfTI sform with negative x (RAS from LPS), and a qform with a 180-degree turn about z plus qfac -1. */
    nii_opts os = {.datatype = 2, .bitpix = 8, .dim = {3, 3, 2, 2, 1, 1, 1, 1}, .pixdim = {1, 2, 3, 1},
                   .vox_offset = 352, .sform = 1, .offs = {10, 20, 30}, .use_srow = 1,
                   .srow = {{-2, 0, 0}, {0, 3, 0}, {0, 0, 1}}};
    nii_opts oq = {.datatype = 2, .bitpix = 8, .dim = {3, 3, 2, 2, 1, 1, 1, 1}, .pixdim = {-1, 2, 3, 1},
                   .vox_offset = 352, .qform = 1, .offs = {-90, -80, -70}, .quat = {0, 0, 1}};
    const struct { nii_opts *o; double axes[3][3]; double origin[3]; const char *what; } nii_cases[] = {
        {&os, {{-2, 0, 0}, {0, 3, 0}, {0, 0, 1}}, {10, 20, 30}, "nifti sform flip x"},
        /* qoffset is written as offs + 100; R = diag(-1, -1, 1), qfac -1 flips z. */
        {&oq, {{-2, 0, 0}, {0, -3, 0}, {0, 0, -1}}, {10, 20, 30}, "nifti qform turn + qfac"},
    };
    for (size_t t = 0; t < sizeof nii_cases / sizeof nii_cases[0]; t++) {
        buf nb = nii_header(nii_cases[t].o);
        double values[12];
        for (int i = 0; i < 12; i++) {
            values[i] = 5 * i;
            buf_int(&nb, (uint64_t)(5 * i), 1, 0);
        }
        ds = expect_load(sl_load_nifti, nb.p, nb.n, "o.nii", nii_cases[t].what);
        if (ds) {
            const int d[3] = {3, 2, 2};
            check_world(ds, d, nii_cases[t].axes, nii_cases[t].origin, values, nii_cases[t].what);
        }
        sl_dataset_destroy(ds);
        free(nb.p);
    }
    /* Oblique sform: not handled; axis-aligned from pixdim and the offsets (documented). */
    nii_opts ob = os;
    ob.srow[0][0] = -1.4142f;
    ob.srow[0][1] = 1.4142f;
    buf nb = nii_header(&ob);
    for (int i = 0; i < 12; i++)
        buf_int(&nb, (uint64_t)i, 1, 0);
    ds = expect_load(sl_load_nifti, nb.p, nb.n, "ob.nii", "nifti oblique sform");
    if (ds) {
        SL_CHECK_NEAR(ds->volume.spacing[0], 2, 0);
        SL_CHECK_NEAR(ds->origin.x, 10, 0);
        SL_CHECK(((uint8_t *)ds->volume.data)[1] == 1);
    }
    sl_dataset_destroy(ds);
    free(nb.p);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_volumes_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    test_nrrd_raw();
    test_nrrd_gzip();
    test_nrrd_vector();
    test_nrrd_detached();
    test_nrrd_detached_bounded();
    test_nrrd_detached_gzip();
    test_nrrd_hostile();
    test_nifti();
    test_gzip_bombs();
    test_orientation();
    test_raw_json();
    test_gunzip();
    test_files();
    for (int i = written_count - 1; i >= 0; i--)
        unlink(written[i]);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", tmpdir);
    rmdir(sub);
    rmdir(tmpdir);
    SL_TEST_END();
}
