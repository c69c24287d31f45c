/* test_load_lines.c — TrackVis .trk, MRtrix .tck and OBJ line loaders.
 *
 * Good files are written in memory from a formula (positions, scalars,
 * properties), loaded, and compared value by value with the formula:
 * positions within 1e-6 * (1 + |x|) after re-centring (float rounding of
 * the stored offset; the original value is a float), attributes exactly,
 * attribute ranges against a brute-force min/max. Hostile inputs: every
 * strict prefix of a good file, lying counts (2^31, negative, larger than
 * the file), out-of-range indices, non-finite coordinates, empty input —
 * each must fail with *out NULL and a message naming the file (ASan/UBSan
 * catch over-reads and huge allocations). Single thread; no GPU.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "load_test_util.h"

/* The formula every good file follows. */
static double pos_value(int k, int i, int c) { return (c == 0 ? 10.0 * k + i + 0.25 : c == 1 ? -0.5 * i : 1000.125 + k); }
static float scalar_value(int k, int i, int j) { return (float)(k * 100 + i * 10 + j) + 0.5f; }
static float prop_value(int k, int j) { return -1.5f * (float)((k + 1) * (j + 1)); }

static void check_positions(const sl_dataset *ds, int n_lines, const int *lens)
{
    const sl_lines *l = &ds->lines;
    SL_CHECK(l->line_count == (size_t)n_lines);
    if (l->line_count != (size_t)n_lines)
        return;
    size_t v = 0;
    int bad = 0;
    for (int k = 0; k < n_lines; k++) {
        SL_CHECK(l->line_offsets[k] == v);
        for (int i = 0; i < lens[k]; i++, v++)
            for (int c = 0; c < 3; c++) {
                double want = (float)pos_value(k, i, c);
                if (fabs(world(ds, v, c) - want) > 1e-6 * (1.0 + fabs(want)))
                    bad++;
            }
    }
    SL_CHECK(l->vertex_count == v);
    SL_CHECK_MSG(bad == 0, "%d coordinates differ from the formula", bad);
}

/* ---------------- TrackVis ---------------- */

typedef struct trk_spec {
    int version, be, n_scalars, n_props, n_lines;
    const int *lens;
    int n_count;          /* written to the header */
    const char *const *scalar_names, *const *prop_names;
} trk_spec;

static void write_trk(tbuf *b, const trk_spec *s)
{
    uint8_t h[1000];
    memset(h, 0, sizeof h);
    memcpy(h, "TRACK", 6);
    tb_put(b, h, sizeof h);
    tb_set_i16(b, 6, 10, s->be);
    tbuf t = {0};
    for (int c = 0; c < 3; c++)
        tb_f32(&t, 2.0f, s->be);
    memcpy(b->data + 12, t.data, 12);
    tb_free(&t);
    tb_set_i16(b, 36, (int16_t)s->n_scalars, s->be);
    for (int j = 0; s->scalar_names && j < s->n_scalars && j < 10; j++)
        if (s->scalar_names[j])
            memcpy(b->data + 38 + 20 * j, s->scalar_names[j], strlen(s->scalar_names[j]));
    tb_set_i16(b, 238, (int16_t)s->n_props, s->be);
    for (int j = 0; s->prop_names && j < s->n_props && j < 10; j++)
        if (s->prop_names[j])
            memcpy(b->data + 240 + 20 * j, s->prop_names[j], strlen(s->prop_names[j]));
    if (s->version == 2) {
        /* vox_to_ras: a scaling that, if the loader applied it, would move the points */
        for (int r = 0; r < 4; r++) {
            tbuf m = {0};
            tb_f32(&m, r == 3 ? 1.0f : 3.0f, s->be);
            memcpy(b->data + 440 + 4 * (r * 4 + r), m.data, 4);
            tb_free(&m);
        }
    }
    memcpy(b->data + 948, "LAS", 3);
    tb_set_i32(b, 988, s->n_count, s->be);
    tb_set_i32(b, 992, s->version, s->be);
    tb_set_i32(b, 996, 1000, s->be);
    for (int k = 0; k < s->n_lines; k++) {
        tb_i32(b, s->lens[k], s->be);
        for (int i = 0; i < s->lens[k]; i++) {
            for (int c = 0; c < 3; c++)
                tb_f32(b, (float)pos_value(k, i, c), s->be);
            for (int j = 0; j < s->n_scalars; j++)
                tb_f32(b, scalar_value(k, i, j), s->be);
        }
        for (int j = 0; j < s->n_props; j++)
            tb_f32(b, prop_value(k, j), s->be);
    }
}

static void check_trk_good(const trk_spec *s, const char *path)
{
    tbuf b = {0};
    write_trk(&b, s);
    sl_dataset *ds;
    sl_err err;
    sl_status st = run_loader(sl_load_trk, b.data, b.size, path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "trk v%d be%d: %s", s->version, s->be, err.message);
    if (st == SL_OK) {
        SL_CHECK(ds->kind == SL_DATASET_LINES);
        check_positions(ds, s->n_lines, s->lens);
        const sl_lines *l = &ds->lines;
        SL_CHECK(l->attribute_count == s->n_scalars);
        SL_CHECK(l->line_attribute_count == s->n_props);
        for (int j = 0; j < l->attribute_count; j++) {
            const char *want = s->scalar_names && j < 10 && s->scalar_names[j] ? s->scalar_names[j] : NULL;
            char fb[32];
            snprintf(fb, sizeof fb, "scalar%d", j);
            SL_CHECK_MSG(strcmp(l->attributes[j].name, want ? want : fb) == 0, "scalar %d named '%s'", j,
                         l->attributes[j].name);
            int bad = 0;
            size_t v = 0;
            for (int k = 0; k < s->n_lines; k++)
                for (int i = 0; i < s->lens[k]; i++, v++)
                    bad += l->attributes[j].values[v] != scalar_value(k, i, j);
            SL_CHECK_MSG(bad == 0, "%d scalar values differ", bad);
            check_range(&l->attributes[j], l->vertex_count);
        }
        for (int j = 0; j < l->line_attribute_count; j++) {
            const char *want = s->prop_names && j < 10 && s->prop_names[j] ? s->prop_names[j] : NULL;
            char fb[32];
            snprintf(fb, sizeof fb, "property%d", j);
            SL_CHECK_MSG(strcmp(l->line_attributes[j].name, want ? want : fb) == 0, "property %d named '%s'", j,
                         l->line_attributes[j].name);
            for (int k = 0; k < s->n_lines; k++)
                SL_CHECK(l->line_attributes[j].values[k] == prop_value(k, j));
            check_range(&l->line_attributes[j], l->line_count);
        }
        if (path)
            SL_CHECK_MSG(strcmp(ds->name, "bundle") == 0, "name '%s'", ds->name);
        /* bounds: brute force over the formula */
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int k = 0; k < s->n_lines; k++)
            for (int i = 0; i < s->lens[k]; i++)
                for (int c = 0; c < 3; c++) {
                    double x = (float)pos_value(k, i, c);
                    lo[c] = x < lo[c] ? x : lo[c];
                    hi[c] = x > hi[c] ? x : hi[c];
                }
        SL_CHECK_NEAR(ds->bounds_min.x, lo[0], 1e-9);
        SL_CHECK_NEAR(ds->bounds_max.z, hi[2], 1e-9);
        sl_dataset_destroy(ds);
    }
    tb_free(&b);
}

/* Every strict prefix must fail (n_count is set, so nothing shorter is complete). */
static void check_all_prefixes_fail(sl_loader_fn fn, const tbuf *b, const char *what)
{
    int ok_count = 0;
    for (size_t n = 0; n < b->size; n++) {
        sl_dataset *ds;
        sl_err err;
        /* Copy into an exact-size heap block so ASan sees any over-read. */
        uint8_t *copy = malloc(n ? n : 1);
        memcpy(copy, b->data, n);
        if (run_loader(fn, n ? copy : NULL, n, "cut.bin", &ds, &err) == SL_OK) {
            ok_count++;
            sl_dataset_destroy(ds);
        }
        free(copy);
    }
    SL_CHECK_MSG(ok_count == 0, "%s: %d of %zu prefixes loaded", what, ok_count, b->size);
}

static void test_trk(void)
{
    static const int lens[] = {2, 3, 1, 4};
    static const char *const snames[] = {"fa", NULL, "md"};
    static const char *const pnames[] = {"length", "weight"};
    trk_spec v1 = {.version = 1, .be = 0, .n_scalars = 3, .n_props = 2, .n_lines = 4, .lens = lens,
                   .n_count = 4, .scalar_names = snames, .prop_names = pnames};
    check_trk_good(&v1, "/tmp/some dir/bundle.trk");
    /* v1 big-endian: byte order from hdr_size (1000) alone, v1 has no vox_to_ras to help. */
    trk_spec v1be = v1;
    v1be.be = 1;
    check_trk_good(&v1be, "bundle.trk");
    {
        tbuf be1 = {0};
        write_trk(&be1, &v1be);
        check_all_prefixes_fail(sl_load_trk, &be1, "trk v1 BE");
        tb_free(&be1);
    }
    trk_spec v2 = v1;
    v2.version = 2;
    check_trk_good(&v2, "bundle.trk");
    trk_spec v2be = v2;
    v2be.be = 1;
    check_trk_good(&v2be, "bundle.trk");
    trk_spec plain = {.version = 2, .be = 1, .n_lines = 4, .lens = lens, .n_count = 0};
    check_trk_good(&plain, NULL); /* n_count 0: read to the end */
    static const int with_empty[] = {3, 0, 2};
    trk_spec empty_track = {.version = 1, .n_scalars = 1, .n_props = 1, .n_lines = 3, .lens = with_empty, .n_count = 3};
    check_trk_good(&empty_track, NULL);

    /* TrackVis 2 multi-valued scalar: byte 19 of a name holds its value count */
    {
        static const char *const mnames[] = {"fa", "rgb", NULL, NULL};
        static const int mlens[] = {2, 2};
        trk_spec multi = {.version = 2, .n_scalars = 4, .n_lines = 2, .lens = mlens, .n_count = 2, .scalar_names = mnames};
        tbuf m = {0};
        write_trk(&m, &multi);
        m.data[38 + 20 + 19] = 3;
        sl_dataset *ds;
        sl_err err;
        if (run_loader(sl_load_trk, m.data, m.size, NULL, &ds, &err) == SL_OK) {
            static const char *want[] = {"fa", "rgb[0]", "rgb[1]", "rgb[2]"};
            SL_CHECK(ds->lines.attribute_count == 4);
            for (int j = 0; j < 4 && j < ds->lines.attribute_count; j++) {
                SL_CHECK_MSG(strcmp(ds->lines.attributes[j].name, want[j]) == 0, "multi %d: '%s'", j,
                             ds->lines.attributes[j].name);
                SL_CHECK(ds->lines.attributes[j].values[3] == scalar_value(1, 1, j));
            }
            sl_dataset_destroy(ds);
        } else {
            SL_CHECK_MSG(0, "multi-valued trk: %s", err.message);
        }
        tb_free(&m);
    }

    /* truncation at every byte, both byte orders */
    static const int small_lens[] = {2, 1};
    trk_spec small = {.version = 2, .be = 0, .n_scalars = 1, .n_props = 1, .n_lines = 2, .lens = small_lens, .n_count = 2};
    tbuf b = {0};
    write_trk(&b, &small);
    check_all_prefixes_fail(sl_load_trk, &b, "trk LE");
    tb_free(&b);
    small.be = 1;
    write_trk(&b, &small);
    check_all_prefixes_fail(sl_load_trk, &b, "trk BE");

    /* lying headers */
    struct { size_t off; int32_t v; int is16; sl_status want; const char *field; } lies[] = {
        {988, INT32_MIN, 0, SL_ERR_FORMAT, "n_count"},     /* 2^31 read as int32 */
        {988, INT32_MAX, 0, SL_ERR_LIMIT, "n_count"},
        {988, -1, 0, SL_ERR_FORMAT, "n_count"},
        {988, 3, 0, SL_ERR_FORMAT, "track 2"},             /* more tracks than present */
        {1000, INT32_MAX, 0, SL_ERR_FORMAT, "track 0"},    /* first track's point count */
        {1000, INT32_MIN, 0, SL_ERR_FORMAT, "track 0"},
        {1000, -1, 0, SL_ERR_FORMAT, "negative"},
        {36, 32767, 1, SL_ERR_LIMIT, "n_scalars"},
        {36, -1, 1, SL_ERR_LIMIT, "n_scalars"},
        {238, -7, 1, SL_ERR_LIMIT, "n_properties"},
        {992, 3, 0, SL_ERR_FORMAT, "version"},
        {996, 999, 0, SL_ERR_FORMAT, "hdr_size"},
    };
    for (size_t i = 0; i < sizeof lies / sizeof lies[0]; i++) {
        tbuf c = {0};
        small.be = (int)(i & 1);
        write_trk(&c, &small);
        if (lies[i].is16)
            tb_set_i16(&c, lies[i].off, (int16_t)lies[i].v, small.be);
        else
            tb_set_i32(&c, lies[i].off, lies[i].v, small.be);
        sl_dataset *ds;
        sl_err err;
        sl_status st = run_loader(sl_load_trk, c.data, c.size, "lie.trk", &ds, &err);
        SL_CHECK_MSG(st == lies[i].want, "lie %zu: status %d (%s)", i, (int)st, err.message);
        SL_CHECK_MSG(strstr(err.message, lies[i].field) != NULL, "lie %zu: message '%s' lacks '%s'", i, err.message,
                     lies[i].field);
        if (st == SL_OK)
            sl_dataset_destroy(ds);
        tb_free(&c);
    }
    /* NaN coordinate */
    tbuf c = {0};
    small.be = 0;
    write_trk(&c, &small);
    float nan = NAN;
    memcpy(c.data + 1000 + 4 + 4, &nan, 4); /* y of the first point (LE host assumed below) */
    {
        const uint16_t probe = 1;
        if (*(const uint8_t *)&probe == 1) {
            sl_dataset *ds;
            sl_err err;
            sl_status st = run_loader(sl_load_trk, c.data, c.size, "nan.trk", &ds, &err);
            SL_CHECK_MSG(st == SL_ERR_FORMAT && strstr(err.message, "coordinate"), "NaN: %s", err.message);
        }
    }
    /* bad magic, empty */
    c.data[0] = 'X';
    sl_dataset *ds;
    sl_err err;
    SL_CHECK(run_loader(sl_load_trk, c.data, c.size, "magic.trk", &ds, &err) == SL_ERR_FORMAT);
    SL_CHECK(run_loader(sl_load_trk, NULL, 0, "empty.trk", &ds, &err) == SL_ERR_FORMAT);
    SL_CHECK(run_loader(sl_load_trk, NULL, 0, NULL, &ds, &err) == SL_ERR_FORMAT);
    tb_free(&c);
    tb_free(&b);
}

/* ---------------- MRtrix tck ---------------- */

static void write_tck(tbuf *b, int f64, int be, int n_lines, const int *lens, int pad)
{
    char type[16];
    snprintf(type, sizeof type, "Float%d%s", f64 ? 64 : 32, be ? "BE" : "LE");
    char head[512];
    /* offset depends on the header's own length: iterate to a fixed point */
    size_t off = 0, prev = 1;
    while (off != prev) {
        prev = off;
        int n = snprintf(head, sizeof head,
                         "mrtrix tracks\ncommand_history: tckgen in.mif out.tck\ncount: %d\n"
                         "datatype: %s\nfile: . %zu\nEND\n", n_lines, type, prev);
        off = (size_t)n + (size_t)pad;
    }
    tb_put(b, head, strlen(head));
    for (int i = 0; i < pad; i++)
        tb_put(b, "\0", 1);
    for (int k = 0; k < n_lines; k++) {
        for (int i = 0; i < lens[k]; i++)
            for (int c = 0; c < 3; c++) {
                if (f64) tb_f64(b, (float)pos_value(k, i, c), be);
                else tb_f32(b, (float)pos_value(k, i, c), be);
            }
        for (int c = 0; c < 3; c++) {
            if (f64) tb_f64(b, NAN, be);
            else tb_f32(b, NAN, be);
        }
    }
    for (int c = 0; c < 3; c++) {
        if (f64) tb_f64(b, INFINITY, be);
        else tb_f32(b, INFINITY, be);
    }
}

static void test_tck(void)
{
    static const int lens[] = {3, 1, 5, 2};
    for (int f64 = 0; f64 < 2; f64++)
        for (int be = 0; be < 2; be++) {
            tbuf b = {0};
            write_tck(&b, f64, be, 4, lens, f64 * 3);
            sl_dataset *ds;
            sl_err err;
            sl_status st = run_loader(sl_load_tck, b.data, b.size, "dir/whole_brain.tck", &ds, &err);
            SL_CHECK_MSG(st == SL_OK, "tck f64=%d be=%d: %s", f64, be, err.message);
            if (st == SL_OK) {
                check_positions(ds, 4, lens);
                SL_CHECK(strcmp(ds->name, "whole_brain") == 0);
                sl_dataset_destroy(ds);
            }
            if (f64 == be) /* Float32LE and Float64BE: every prefix */
                check_all_prefixes_fail(sl_load_tck, &b, f64 ? "tck Float64BE" : "tck Float32LE");
            tb_free(&b);
        }
    /* an empty streamline is kept (indices match a .tsf) */
    static const int with_empty[] = {2, 0, 3};
    tbuf b = {0};
    write_tck(&b, 0, 0, 3, with_empty, 0);
    sl_dataset *ds;
    sl_err err;
    if (run_loader(sl_load_tck, b.data, b.size, NULL, &ds, &err) == SL_OK) {
        check_positions(ds, 3, with_empty);
        sl_dataset_destroy(ds);
    } else {
        SL_CHECK_MSG(0, "tck with an empty streamline: %s", err.message);
    }
    tb_free(&b);

    /* hostile headers */
    const char *bad[] = {
        "",
        "mrtrix tracks\n",
        "mrtrix tracks\ndatatype: Float32LE\nEND\n",
        "mrtrix tracks\nfile: . 60\nEND\n",
        "mrtrix tracks\ndatatype: Int16LE\nfile: . 50\nEND\n",
        "mrtrix tracks\ndatatype: Float32LE\nfile: . 4294967296\nEND\n",
        "mrtrix tracks\ndatatype: Float32LE\nfile: . 5\nEND\n",             /* offset inside header */
        "mrtrix tracks\ndatatype: Float32LE\nfile: . -12\nEND\n",
        "mrtrix tracks\ndatatype: Float32LE\nfile: other.dat 0\nEND\n",
        "mrtrix image\ndatatype: Float32LE\nfile: . 50\nEND\n",
        "mrtrix tracks\ndatatype: Float32LE\nfile: . 47\nEND\n",             /* no data, no end triplet */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        SL_CHECK_MSG(run_loader(sl_load_tck, (const uint8_t *)bad[i], strlen(bad[i]), "bad.tck", &ds, &err) != SL_OK,
                     "bad tck %zu loaded", i);
    }
    /* a triplet mixing NaN and numbers; a coordinate beyond float range */
    for (int which = 0; which < 2; which++) {
        tbuf c = {0};
        const char *h = "mrtrix tracks\ndatatype: Float64LE\nfile: . 48\nEND\n";
        tb_put(&c, h, strlen(h));
        while (c.size < 48)
            tb_put(&c, "\0", 1);
        tb_f64(&c, 1.0, 0);
        tb_f64(&c, which ? 1e300 : NAN, 0);
        tb_f64(&c, 2.0, 0);
        for (int r = 0; r < 2; r++)
            for (int k = 0; k < 3; k++)
                tb_f64(&c, r ? INFINITY : NAN, 0);
        sl_status st = run_loader(sl_load_tck, c.data, c.size, "nan.tck", &ds, &err);
        SL_CHECK_MSG(st == SL_ERR_FORMAT, "tck bad triplet %d: %d %s", which, (int)st, err.message);
        tb_free(&c);
    }
}

/* ---------------- OBJ ---------------- */

static void test_obj(void)
{
    const char *good =
        "# polylines\n"
        "o curves\n"
        "v 1.5 2 3\n"
        "v -4 5.25 6 1.0\n"          /* w ignored */
        "vn 0 0 1\n"
        "v 7 8 9 0.5 0.5 0.5\n"      /* colour ignored */
        "l 1 2 3\n"
        "v 10 11 12\n"
        "l -1 -4 2/7\n"              /* relative: 4, 1, 2 */
        "f 1 2 3\n"
        "l 3 1\r\n"
        "l 4\n";
    static const double pts[4][3] = {{1.5, 2, 3}, {-4, 5.25, 6}, {7, 8, 9}, {10, 11, 12}};
    static const int idx[] = {0, 1, 2, 3, 0, 1, 2, 0, 3};
    static const uint32_t offs[] = {0, 3, 6, 8, 9};
    sl_dataset *ds;
    sl_err err;
    sl_status st = run_loader(sl_load_obj, (const uint8_t *)good, strlen(good), "a/b/curves.obj", &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "obj: %s", err.message);
    if (st == SL_OK) {
        const sl_lines *l = &ds->lines;
        SL_CHECK(l->line_count == 4 && l->vertex_count == 9);
        for (size_t k = 0; k <= 4 && l->line_count == 4; k++)
            SL_CHECK(l->line_offsets[k] == offs[k]);
        int bad = 0;
        for (size_t v = 0; v < 9 && l->vertex_count == 9; v++)
            for (int c = 0; c < 3; c++)
                bad += fabs(world(ds, v, c) - pts[idx[v]][c]) > 1e-6;
        SL_CHECK_MSG(bad == 0, "%d OBJ coordinates differ", bad);
        SL_CHECK(strcmp(ds->name, "curves") == 0);
        SL_CHECK_NEAR(ds->bounds_min.x, -4.0, 1e-9);
        SL_CHECK_NEAR(ds->bounds_max.z, 12.0, 1e-9);
        sl_dataset_destroy(ds);
    }
    /* Every prefix: either an error, or a consistent smaller line set. */
    size_t n = strlen(good);
    int failed = 0;
    for (size_t k = 0; k < n; k++) {
        uint8_t *copy = malloc(k ? k : 1);
        memcpy(copy, good, k);
        if (run_loader(sl_load_obj, copy, k, "cut.obj", &ds, &err) == SL_OK) {
            SL_CHECK(ds->lines.vertex_count <= 9);
            sl_dataset_destroy(ds);
        } else {
            failed++;
        }
        free(copy);
    }
    SL_CHECK(failed > 0);
    const char *bad[] = {
        "",
        "v 1 2 3\n",                          /* no lines */
        "v 1 2 3\nl 1 0\n",                   /* index 0 */
        "v 1 2 3\nl 1 2\n",                   /* past the end */
        "v 1 2 3\nl -2 1\n",                  /* relative before the first */
        "v 1 2 3\nl 2147483648 1\n",          /* 2^31 */
        "v 1 2 3\nl -2147483649 1\n",
        "v 1 2\nl 1\n",                       /* 2 coordinates */
        "v nan 2 3\nl 1\n",
        "v 1 inf 3\nl 1\n",
        "v 1 2 1e39\nl 1\n",                  /* beyond float */
        "v 1 2 3\nl\n",                       /* empty polyline */
        "v 1 2 x\nl 1\n",
        "v 1 2 3\nl 1 abc\n",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        size_t len = strlen(bad[i]);
        uint8_t *copy = malloc(len ? len : 1);
        memcpy(copy, bad[i], len);
        st = run_loader(sl_load_obj, copy, len, "bad.obj", &ds, &err);
        SL_CHECK_MSG(st != SL_OK, "bad obj %zu loaded", i);
        if (st == SL_OK)
            sl_dataset_destroy(ds);
        free(copy);
    }
    /* forward references with positive indices are allowed */
    const char *fwd = "l 1 2\nv 0 0 0\nv 1 1 1\n";
    st = run_loader(sl_load_obj, (const uint8_t *)fwd, strlen(fwd), NULL, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "forward reference: %s", err.message);
    if (st == SL_OK) {
        SL_CHECK(strcmp(ds->name, "obj") == 0);
        sl_dataset_destroy(ds);
    }
}

/* A real TrackVis file from data/samples, checked against a direct reading
 * of its records (little-endian hosts; the file is little-endian). */
static void test_trk_sample(void)
{
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/data/samples/minimal_bundles/sub_1/AF_L.trk", src ? src : ".");
    FILE *f = fopen(path, "rb");
    SL_CHECK_MSG(f != NULL, "cannot open %s", path);
    if (!f)
        return;
    tbuf b = {0};
    uint8_t chunk[4096];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
        tb_put(&b, chunk, n);
    fclose(f);
    sl_dataset *ds;
    sl_err err;
    sl_status st = run_loader(sl_load_trk, b.data, b.size, path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    const uint16_t probe = 1;
    if (st == SL_OK && *(const uint8_t *)&probe == 1 && b.size > 1000) {
        int16_t ns, np;
        memcpy(&ns, b.data + 36, 2);
        memcpy(&np, b.data + 238, 2);
        size_t pos = 1000, v = 0, k = 0;
        int bad = 0;
        while (pos + 4 <= b.size) {
            int32_t m;
            memcpy(&m, b.data + pos, 4);
            pos += 4;
            SL_CHECK(k < ds->lines.line_count && ds->lines.line_offsets[k] == v);
            for (int32_t i = 0; i < m; i++, v++) {
                for (int c = 0; c < 3; c++) {
                    float x;
                    memcpy(&x, b.data + pos + 4 * (size_t)c, 4);
                    if (v >= ds->lines.vertex_count || fabs(world(ds, v, c) - x) > 1e-6 * (1.0 + fabs(x)))
                        bad++;
                }
                pos += 4 * (3 + (size_t)ns);
            }
            pos += 4 * (size_t)np;
            k++;
        }
        SL_CHECK(k == ds->lines.line_count && v == ds->lines.vertex_count);
        SL_CHECK_MSG(bad == 0, "%d sample coordinates differ", bad);
        SL_CHECK(strcmp(ds->name, "AF_L") == 0);
    }
    if (st == SL_OK)
        sl_dataset_destroy(ds);
    tb_free(&b);
}

int main(void)
{
    test_trk();
    test_trk_sample();
    test_tck();
    test_obj();
    SL_TEST_END();
}
