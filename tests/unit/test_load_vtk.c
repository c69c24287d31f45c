/* test_load_vtk.c — legacy VTK loader: POLYDATA lines and STRUCTURED_POINTS.
 *
 * Good files (ASCII and big-endian BINARY, classic and 5.1 cell layouts)
 * are written in memory; the loaded data is compared value by value with
 * the values written: positions within 1e-6 (re-centring rounds the float
 * offset), attributes, volume voxels and ranges exactly (float inputs are
 * exact in f32; double inputs are compared with their float rounding).
 * Shared points must be copied into every line that uses them, and
 * CELL_DATA must be matched to the LINES cells past any VERTICES cells.
 * Hostile inputs: prefixes of good files, negative / 2^31 counts,
 * out-of-range indices, NaN coordinates, mismatched POINT_DATA, empty input.
 * Single thread; no GPU.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "load_test_util.h"

static const float pts[5][3] = {{0, 0, 0}, {1.5f, 0, 0}, {1.5f, 2.25f, 0}, {-3, 2.25f, 1}, {1.5f, 2.25f, 7.5f}};
/* line 0: 0 1 2, line 1: 2 4 3 (point 2 shared) */
static const int line_idx[] = {0, 1, 2, 2, 4, 3};
static const float temp[5] = {10, 11.5f, -2, 40, 0.25f};
static const float vel[5][2] = {{1, 2}, {3, 4}, {5, 6}, {7, 8}, {9, 10}};

static void check_poly(const sl_dataset *ds, int with_vel, int with_cell)
{
    const sl_lines *l = &ds->lines;
    SL_CHECK(ds->kind == SL_DATASET_LINES);
    SL_CHECK(l->line_count == 2 && l->vertex_count == 6);
    if (l->line_count != 2 || l->vertex_count != 6)
        return;
    SL_CHECK(l->line_offsets[1] == 3);
    int bad = 0;
    for (size_t v = 0; v < 6; v++)
        for (int c = 0; c < 3; c++)
            bad += fabs(world(ds, v, c) - pts[line_idx[v]][c]) > 1e-6;
    SL_CHECK_MSG(bad == 0, "%d positions differ", bad);
    int t = sl_lines_find_attribute(l, "temp");
    SL_CHECK(t >= 0);
    if (t >= 0) {
        for (size_t v = 0; v < 6; v++)
            SL_CHECK(l->attributes[t].values[v] == temp[line_idx[v]]);
        check_range(&l->attributes[t], 6);
        SL_CHECK(l->attributes[t].min == -2.0f && l->attributes[t].max == 40.0f);
    }
    if (with_vel) {
        int a = sl_lines_find_attribute(l, "vel[0]"), b = sl_lines_find_attribute(l, "vel[1]");
        SL_CHECK(a >= 0 && b >= 0);
        if (a >= 0 && b >= 0)
            for (size_t v = 0; v < 6; v++) {
                SL_CHECK(l->attributes[a].values[v] == vel[line_idx[v]][0]);
                SL_CHECK(l->attributes[b].values[v] == vel[line_idx[v]][1]);
            }
    }
    if (with_cell) {
        SL_CHECK(l->line_attribute_count == 1);
        if (l->line_attribute_count == 1) {
            SL_CHECK(strcmp(l->line_attributes[0].name, "cell_id") == 0);
            SL_CHECK(l->line_attributes[0].values[0] == 70.0f && l->line_attributes[0].values[1] == 71.0f);
        }
    }
    SL_CHECK_NEAR(ds->bounds_min.x, -3.0, 1e-9);
    SL_CHECK_NEAR(ds->bounds_max.z, 7.5, 1e-9);
}

static const char *poly_ascii =
    "# vtk DataFile Version 3.0\n"
    "streamlines from a test\n"
    "ASCII\n"
    "DATASET POLYDATA\n"
    "POINTS 5 float\n"
    "0 0 0 1.5 0 0\n1.5 2.25 0\n-3 2.25 1 1.5 2.25 7.5\n"
    "LINES 2 8\n"
    "3 0 1 2\n"
    "3 2 4 3\n"
    "CELL_DATA 2\n"
    "SCALARS cell_id int 1\n"
    "LOOKUP_TABLE default\n"
    "70 71\n"
    "POINT_DATA 5\n"
    "SCALARS temp float\n"
    "LOOKUP_TABLE default\n"
    "10 11.5 -2 40 0.25\n"
    "SCALARS vel float 2\n"
    "LOOKUP_TABLE default\n"
    "1 2 3 4 5 6 7 8 9 10\n";

static const char *poly_51 =
    "# vtk DataFile Version 5.1\n"
    "vtk output\n"
    "ASCII\n"
    "DATASET POLYDATA\n"
    "POINTS 5 double\n"
    "0 0 0 1.5 0 0 1.5 2.25 0\n-3 2.25 1 1.5 2.25 7.5\n"
    "METADATA\nINFORMATION 0\n\n"
    "LINES 3 6\n"
    "OFFSETS vtktypeint64\n0 3 6\n"
    "CONNECTIVITY vtktypeint64\n0 1 2 2 4 3\n"
    "POINT_DATA 5\n"
    "FIELD FieldData 2\n"
    "temp 1 5 float\n10 11.5 -2 40 0.25\n"
    "METADATA\nINFORMATION 0\n\n"
    "vel 2 5 float\n1 2 3 4 5 6 7 8 9 10\n";

/* The same polydata in BINARY, with POINTS as double, a VERTICES cell before
 * the LINES (so CELL_DATA tuple 1, 2 are the lines) and NORMALS. Returns the
 * offset of "POINT_DATA"'s preceding newline via *required_end. */
static void write_poly_binary(tbuf *b, size_t *required_end)
{
    tb_printf(b, "# vtk DataFile Version 3.0\nbinary lines\nBINARY\nDATASET POLYDATA\nPOINTS 5 double\n");
    for (int p = 0; p < 5; p++)
        for (int c = 0; c < 3; c++)
            tb_f64(b, pts[p][c], 1);
    tb_printf(b, "\nVERTICES 1 2\n");
    tb_i32(b, 1, 1);
    tb_i32(b, 3, 1);
    tb_printf(b, "\nLINES 2 8\n");
    tb_i32(b, 3, 1);
    for (int i = 0; i < 3; i++) tb_i32(b, line_idx[i], 1);
    tb_i32(b, 3, 1);
    for (int i = 3; i < 6; i++) tb_i32(b, line_idx[i], 1);
    *required_end = b->size;
    tb_printf(b, "\nCELL_DATA 3\nSCALARS cell_id short\nLOOKUP_TABLE default\n");
    tb_i16(b, 69, 1);
    tb_i16(b, 70, 1);
    tb_i16(b, 71, 1);
    tb_printf(b, "\nPOINT_DATA 5\nSCALARS temp float 1\nLOOKUP_TABLE default\n");
    for (int p = 0; p < 5; p++)
        tb_f32(b, temp[p], 1);
    tb_printf(b, "\nNORMALS n float\n");
    for (int p = 0; p < 5; p++)
        for (int c = 0; c < 3; c++)
            tb_f32(b, (float)(p * 3 + c), 1);
    tb_printf(b, "\nSCALARS vel float 2\nLOOKUP_TABLE default\n");
    for (int p = 0; p < 5; p++)
        for (int c = 0; c < 2; c++)
            tb_f32(b, vel[p][c], 1);
    tb_printf(b, "\n");
}

static sl_dataset *load_text(const char *text, const char *path, sl_status want, const char *what)
{
    sl_dataset *ds;
    sl_err err;
    size_t n = strlen(text);
    uint8_t *copy = malloc(n ? n : 1); /* exact size: ASan sees over-reads */
    memcpy(copy, text, n);
    sl_status st = run_loader(sl_load_vtk, copy, n, path, &ds, &err);
    free(copy);
    SL_CHECK_MSG(st == want, "%s: status %d, wanted %d: %s", what, (int)st, (int)want, st ? err.message : "ok");
    if (st != SL_OK)
        return NULL;
    return ds;
}

/* Every prefix: no crash, error or consistent result; those shorter than
 * `must_fail_below` must fail. */
static void check_prefixes(const uint8_t *data, size_t size, size_t must_fail_below, const char *what)
{
    int wrong = 0;
    for (size_t n = 0; n < size; n++) {
        uint8_t *copy = malloc(n ? n : 1);
        memcpy(copy, data, n);
        sl_dataset *ds;
        sl_err err;
        if (run_loader(sl_load_vtk, copy, n, "cut.vtk", &ds, &err) == SL_OK) {
            if (n < must_fail_below)
                wrong++;
            sl_dataset_destroy(ds);
        }
        free(copy);
    }
    SL_CHECK_MSG(wrong == 0, "%s: %d prefixes shorter than %zu loaded", what, wrong, must_fail_below);
}

static void test_polydata(void)
{
    sl_dataset *ds = load_text(poly_ascii, "x/tracts.vtk", SL_OK, "polydata ascii");
    if (ds) {
        check_poly(ds, 1, 1);
        SL_CHECK(strcmp(ds->name, "tracts") == 0);
        sl_dataset_destroy(ds);
    }
    ds = load_text(poly_51, NULL, SL_OK, "polydata 5.1");
    if (ds) {
        check_poly(ds, 1, 0);
        sl_dataset_destroy(ds);
    }
    /* ASCII prefixes: anything cut inside POINTS or LINES must fail */
    const char *after_lines = strstr(poly_ascii, "CELL_DATA");
    check_prefixes((const uint8_t *)poly_ascii, strlen(poly_ascii), (size_t)(after_lines - poly_ascii) - 3,
                   "polydata ascii");

    tbuf b = {0};
    size_t required_end;
    write_poly_binary(&b, &required_end);
    sl_dataset *bin;
    sl_err err;
    sl_status st = run_loader(sl_load_vtk, b.data, b.size, "bin.vtk", &bin, &err);
    SL_CHECK_MSG(st == SL_OK, "polydata binary: %s", err.message);
    if (st == SL_OK) {
        check_poly(bin, 1, 1);
        const sl_lines *l = &bin->lines;
        SL_CHECK(l->normals != NULL);
        if (l->normals && l->vertex_count == 6)
            for (size_t v = 0; v < 6; v++)
                SL_CHECK(l->normals[3 * v + 2] == (float)(line_idx[v] * 3 + 2));
        sl_dataset_destroy(bin);
    }
    check_prefixes(b.data, b.size, required_end, "polydata binary");

    /* hostile POLYDATA */
    static const struct { const char *text; sl_status want; const char *what; } bad[] = {
        {"", SL_ERR_FORMAT, "empty"},
        {"# vtk DataFile Version 3.0\n", SL_ERR_FORMAT, "header only"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n", SL_ERR_FORMAT, "no points"},
        {"# vtk DataFile Version 3.0\nt\nXML\nDATASET POLYDATA\n", SL_ERR_FORMAT, "bad mode"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n", SL_ERR_UNSUPPORTED, "dataset"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2147483648 float\n0 0 0\n", SL_ERR_LIMIT, "2^31 points"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS -5 float\n0 0 0\n", SL_ERR_FORMAT, "negative points"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 1000000 float\n0 0 0\n", SL_ERR_FORMAT, "points > bytes"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 2\n", SL_ERR_FORMAT, "index = n"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 -1\n", SL_ERR_FORMAT, "index -1"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 4294967296\n", SL_ERR_FORMAT, "index 2^32"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n5 0 1\n", SL_ERR_FORMAT, "cell count > size"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n-2 0 1\n", SL_ERR_FORMAT, "negative cell count"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 2147483648 3\n2 0 1\n", SL_ERR_FORMAT, "2^31 lines"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 2147483648\n2 0 1\n", SL_ERR_FORMAT, "2^31 size"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 nan 0 1 1 1\nLINES 1 3\n2 0 1\n", SL_ERR_FORMAT, "NaN point"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 1e39 0 1 1 1\nLINES 1 3\n2 0 1\n", SL_ERR_FORMAT, "point beyond float"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nPOINT_DATA 3\nSCALARS s float\n1 2 3\n", SL_ERR_FORMAT, "POINT_DATA mismatch"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nPOINT_DATA 2\nSCALARS s float 9\n1 2\n", SL_ERR_LIMIT, "components"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nPOINT_DATA 2\nSCALARS s bit\n1 0\n", SL_ERR_UNSUPPORTED, "bit"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nPOINT_DATA 2\nSCALARS s float\n1\n", SL_ERR_FORMAT, "short scalars"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nBOGUS 1\n", SL_ERR_FORMAT, "keyword"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nLINES 1 3\n2 0 1\n", SL_ERR_FORMAT, "lines before points"},
        {"# vtk DataFile Version 5.1\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 3 2\nOFFSETS vtktypeint64\n0 2 1\nCONNECTIVITY vtktypeint64\n0 1\n", SL_ERR_FORMAT, "decreasing offsets"},
        {"# vtk DataFile Version 5.1\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 2 2\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n0 1\n", SL_ERR_FORMAT, "offsets past connectivity"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1.5\n", SL_ERR_FORMAT, "fractional index"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ds = load_text(bad[i].text, "bad.vtk", bad[i].want, bad[i].what);
        sl_dataset_destroy(ds);
    }
    /* the same file cut at every byte never crashes */
    check_prefixes((const uint8_t *)poly_51, strlen(poly_51), 0, "polydata 5.1");
    tb_free(&b);
}

static void test_structured(void)
{
    const char *ascii =
        "# vtk DataFile Version 2.0\n"
        "density\n"
        "ASCII\n"
        "DATASET STRUCTURED_POINTS\n"
        "DIMENSIONS 3 2 2\n"
        "ORIGIN -1 2 0.5\n"
        "SPACING 0.5 1 2\n"
        "POINT_DATA 12\n"
        "SCALARS density unsigned_short 1\n"
        "LOOKUP_TABLE default\n"
        "0 1 2 3 4 5\n6 7 8 9 10 65535\n";
    sl_dataset *ds = load_text(ascii, "d.vtk", SL_OK, "structured ascii");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(ds->kind == SL_DATASET_VOLUME && v->type == SL_VOXEL_U16 && v->components == 1);
        SL_CHECK(v->dims[0] == 3 && v->dims[1] == 2 && v->dims[2] == 2);
        SL_CHECK(v->spacing[0] == 0.5 && v->spacing[1] == 1 && v->spacing[2] == 2);
        SL_CHECK(ds->origin.x == -1 && ds->origin.y == 2 && ds->origin.z == 0.5);
        SL_CHECK(sl_volume_value(v, 2, 1, 1, 0) == 65535 && sl_volume_value(v, 1, 0, 1, 0) == 7);
        SL_CHECK(v->value_min == 0 && v->value_max == 65535);
        SL_CHECK_NEAR(ds->bounds_max.z, 0.5 + 2.0, 0);
        sl_dataset_destroy(ds);
    }
    const char *data_at = strstr(ascii, "0 1 2 3");
    check_prefixes((const uint8_t *)ascii, strlen(ascii), (size_t)(data_at - ascii) + 20, "structured ascii");

    /* BINARY: one file per scalar type, and a vector field */
    static const char *types[] = {"unsigned_char", "short", "float", "double", "char", "int"};
    static const sl_voxel_type want_type[] = {SL_VOXEL_U8, SL_VOXEL_S16, SL_VOXEL_F32, SL_VOXEL_F32, SL_VOXEL_S16, SL_VOXEL_F32};
    for (int t = 0; t < 6; t++) {
        tbuf b = {0};
        tb_printf(&b, "# vtk DataFile Version 3.0\nbin\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3 2\n"
                      "ASPECT_RATIO 1 2 3\nORIGIN 0 0 0\nPOINT_DATA 24\nSCALARS s %s\nLOOKUP_TABLE default\n", types[t]);
        double expect[24];
        for (int i = 0; i < 24; i++) {
            switch (t) {
            case 0: { uint8_t u = (uint8_t)(i * 10); tb_put(&b, &u, 1); expect[i] = u; break; }
            case 1: tb_i16(&b, (int16_t)(i * 1000 - 12000), 1); expect[i] = i * 1000 - 12000; break;
            case 2: tb_f32(&b, (float)i * 0.125f - 1, 1); expect[i] = i * 0.125 - 1; break;
            case 3: tb_f64(&b, i * 0.1, 1); expect[i] = (float)(i * 0.1); break;
            case 4: { int8_t s = (int8_t)(i * 5 - 60); tb_put(&b, &s, 1); expect[i] = s; break; }
            case 5: tb_i32(&b, i * 100000, 1); expect[i] = (float)(i * 100000); break;
            }
        }
        size_t data_end = b.size;
        tb_printf(&b, "\n");
        sl_dataset *vol;
        sl_err err;
        sl_status st = run_loader(sl_load_vtk, b.data, b.size, "v.vtk", &vol, &err);
        SL_CHECK_MSG(st == SL_OK, "structured binary %s: %s", types[t], err.message);
        if (st == SL_OK) {
            const sl_volume *v = &vol->volume;
            SL_CHECK(v->type == want_type[t]);
            SL_CHECK(v->spacing[1] == 2 && v->spacing[2] == 3);
            int bad = 0;
            double lo = 1e300, hi = -1e300;
            for (int i = 0; i < 24; i++) {
                double got = sl_volume_value(v, (size_t)(i % 4), (size_t)(i / 4 % 3), (size_t)(i / 12), 0);
                bad += got != expect[i];
                lo = expect[i] < lo ? expect[i] : lo;
                hi = expect[i] > hi ? expect[i] : hi;
            }
            SL_CHECK_MSG(bad == 0, "%s: %d voxels differ", types[t], bad);
            SL_CHECK(v->value_min == lo && v->value_max == hi);
            sl_dataset_destroy(vol);
        }
        if (t == 1)
            check_prefixes(b.data, b.size, data_end, "structured binary short");
        tb_free(&b);
    }
    tbuf b = {0};
    tb_printf(&b, "# vtk DataFile Version 3.0\nvec\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\n"
                  "SPACING 1 1 1\nORIGIN 5 6 7\nPOINT_DATA 4\nVECTORS wind float\n");
    for (int i = 0; i < 12; i++)
        tb_f32(&b, (float)(i - 6), 1);
    sl_dataset *vec;
    sl_err err;
    sl_status st = run_loader(sl_load_vtk, b.data, b.size, "w.vtk", &vec, &err);
    SL_CHECK_MSG(st == SL_OK, "vectors: %s", err.message);
    if (st == SL_OK) {
        SL_CHECK(vec->kind == SL_DATASET_VECTORS && vec->volume.components == 3);
        SL_CHECK(sl_volume_value(&vec->volume, 1, 1, 0, 2) == 5.0);
        /* magnitudes: brute force */
        double hi = 0;
        for (int i = 0; i < 4; i++) {
            double x = 3 * i - 6, y = 3 * i - 5, z = 3 * i - 4;
            double m = sqrt(x * x + y * y + z * z);
            hi = m > hi ? m : hi;
        }
        SL_CHECK_NEAR(vec->volume.value_max, hi, 1e-12);
        SL_CHECK(vec->origin.x == 5 && vec->origin.z == 7);
        sl_dataset_destroy(vec);
    }
    tb_free(&b);

    static const struct { const char *text; sl_status want; const char *what; } bad[] = {
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2147483648 1 1\n", SL_ERR_LIMIT, "2^31 dim"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS -2 1 1\n", SL_ERR_FORMAT, "negative dim"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 0 1 1\n", SL_ERR_FORMAT, "zero dim"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 1000\nPOINT_DATA 10000000000000\nSCALARS s float\n1\n", SL_ERR_LIMIT, "huge count"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100\nPOINT_DATA 1000000000000\nSCALARS s float\n1\n", SL_ERR_FORMAT, "huge volume, no bytes"},
        {"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100\nPOINT_DATA 1000000000000\nSCALARS s float\n1234\n", SL_ERR_FORMAT, "huge binary volume, no bytes"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\nPOINT_DATA 3\nSCALARS s float\n1 2 3\n", SL_ERR_FORMAT, "count mismatch"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\nSPACING 0 1 1\nPOINT_DATA 2\nSCALARS s float\n1 2\n", SL_ERR_FORMAT, "zero spacing"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\nORIGIN nan 0 0\nPOINT_DATA 2\nSCALARS s float\n1 2\n", SL_ERR_FORMAT, "NaN origin"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\nPOINT_DATA 2\nSCALARS s unsigned_char\n1 256\n", SL_ERR_FORMAT, "u8 out of range"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\nPOINT_DATA 2\nSCALARS s float 3\n1 2 3 4 5 6\n", SL_ERR_UNSUPPORTED, "3-component scalars"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nPOINT_DATA 2\nSCALARS s float\n1 2\n", SL_ERR_FORMAT, "no dims"},
        {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\n", SL_ERR_FORMAT, "no data"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ds = load_text(bad[i].text, "bad.vtk", bad[i].want, bad[i].what);
        sl_dataset_destroy(ds);
    }
}

/* Points far from the origin keep their double precision: the loader stores
 * them relative to their bounds centre (the dataset origin), so a 1 mm step
 * at 1e6 survives (as float alone it would snap to 1/16). */
static void test_polydata_offset(void)
{
    const char *text = "# vtk DataFile Version 3.0\noffset\nASCII\nDATASET POLYDATA\n"
                       "POINTS 3 double\n1000000.001 -2000000.3 5\n1000000.002 -2000000.3 5\n"
                       "1000000.003 -1999999.3 5.1\nLINES 1 4\n3 0 1 2\n";
    sl_dataset *ds = load_text(text, "far.vtk", SL_OK, "polydata offset");
    if (!ds)
        return;
    const double want_x[3] = {1000000.001, 1000000.002, 1000000.003};
    for (int v = 0; v < 3; v++) {
        double x = ds->origin.x + (double)ds->lines.positions[3 * v];
        SL_CHECK_MSG(fabs(x - want_x[v]) < 1e-6, "vertex %d x = %.9f, want %.9f", v, x, want_x[v]);
    }
    SL_CHECK_NEAR(ds->bounds_min.y, -2000000.3, 1e-6);
    SL_CHECK_NEAR(ds->bounds_max.y, -1999999.3, 1e-6);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_polydata();
    test_polydata_offset();
    test_structured();
    SL_TEST_END();
}
