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
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

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

static char written[64][512];
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
    if (written_count < 64)
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
    for (int r = 0; r < 3; r++) {
        b.n = 0;
        for (int c = 0; c < 4; c++)
            buf_f32(&b, c == 3 ? o->offs[r] : (float)(r == c) * o->pixdim[r + 1], o->big);
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
        {{.datatype = 2, .dim = {3, 1, 1, 1}, .pixdim = {1, 1, 1, 1}, .vox_offset = 1e9f}, 4, SL_ERR_FORMAT,
         "vox_offset past end"},
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
                       " \"origin\": [-1, -2, -3], \"endian\": \"big\", \"comment\": \"ignored\"}";
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
    /* Truncated .nii.gz -> FORMAT naming the file. */
    path = write_file("cut.nii.gz", gz.p, gz.n / 2);
    ds = NULL;
    SL_CHECK(sl_load_file(path, &ds, &err) == SL_ERR_FORMAT && ds == NULL);
    SL_CHECK(strstr(err.message, "cut.nii.gz") != NULL);
    free(gz.p);
    free(b.p);
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
    test_nrrd_hostile();
    test_nifti();
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
