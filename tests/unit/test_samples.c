/* test_samples.c — loads the real sample datasets fetched by
 * scripts/fetch-sample-data through sl_load_file and checks them against
 * independent parses done here (header fields read directly, the raw CT
 * scanned in double, TrackVis records walked one by one).
 *
 * Skips (prints "skipped: samples not fetched", exits SL_TEST_SKIP = 77,
 * which tests/CMakeLists.txt declares as SKIP_RETURN_CODE so ctest reports
 * the test as skipped, not passed) only when the folder data/samples is
 * missing; when it exists every sample must be there and load.
 * scripts/test fetches the samples first, so CI runs the checks.
 * Single-threaded; reads only.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "data/sl_load.h"
#include "sl_test.h"

static char samples[1024];

static const char *sample(const char *name)
{
    static char path[4][1400];
    static int k;
    k = (k + 1) % 4;
    snprintf(path[k], sizeof path[k], "%s/%s", samples, name);
    return path[k];
}

static int32_t le32(const uint8_t *p) { return (int32_t)((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24); }
static int16_t le16(const uint8_t *p) { return (int16_t)((uint16_t)p[0] | (uint16_t)p[1] << 8); }
static float lef32(const uint8_t *p)
{
    uint32_t u = (uint32_t)le32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static sl_dataset *load(const char *path)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK && ds, "%s: %s", path, err.message);
    return st == SL_OK ? ds : NULL;
}

/* ch2.nii.gz: Colin27, 181x217x181 u8, 1 mm. Header fields read directly. */
static void test_ch2(void)
{
    const char *path = sample("ch2.nii.gz");
    uint8_t *bytes = NULL;
    size_t n = 0;
    sl_err err = {0};
    SL_CHECK_MSG(sl_read_file(path, SL_MAX_FILE_BYTES, &bytes, &n, &err) == SL_OK, "%s", err.message);
    sl_dataset *ds = load(path);
    if (!ds || n < 352) {
        sl_dataset_destroy(ds);
        free(bytes);
        return;
    }
    SL_CHECK(le32(bytes) == 348);
    int dim[4];
    for (int i = 0; i < 4; i++)
        dim[i] = le16(bytes + 40 + 2 * i);
    SL_CHECK(dim[0] == 3);
    SL_CHECK(ds->volume.dims[0] == dim[1] && ds->volume.dims[1] == dim[2] && ds->volume.dims[2] == dim[3]);
    SL_CHECK(ds->volume.dims[0] == 181 && ds->volume.dims[1] == 217 && ds->volume.dims[2] == 181);
    SL_CHECK(ds->volume.type == SL_VOXEL_U8 && le16(bytes + 70) == 2);
    for (int c = 0; c < 3; c++)
        SL_CHECK_NEAR(ds->volume.spacing[c], fabs(lef32(bytes + 80 + 4 * c)), 0);
    if (le16(bytes + 254) > 0) {
        SL_CHECK_NEAR(ds->origin.x, lef32(bytes + 280 + 12), 0);
        SL_CHECK_NEAR(ds->origin.y, lef32(bytes + 296 + 12), 0);
        SL_CHECK_NEAR(ds->origin.z, lef32(bytes + 312 + 12), 0);
    }
    /* Voxels equal the bytes after vox_offset; range by brute force. */
    size_t off = (size_t)lef32(bytes + 108), count = 181u * 217u * 181u;
    SL_CHECK(off + count <= n);
    if (off + count <= n) {
        SL_CHECK(memcmp(ds->volume.data, bytes + off, count) == 0);
        int lo = 255, hi = 0;
        size_t nonzero = 0;
        for (size_t i = 0; i < count; i++) {
            int v = bytes[off + i];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
            nonzero += v != 0;
        }
        SL_CHECK_NEAR(ds->volume.value_min, lo, 0);
        SL_CHECK_NEAR(ds->volume.value_max, hi, 0);
        SL_CHECK(hi > 100);                                       /* a brain, not an empty volume */
        SL_CHECK(nonzero > count / 10 && nonzero < count * 9 / 10);
    }
    printf("ch2: %dx%dx%d u8, range %g..%g, %.1f ms\n", ds->volume.dims[0], ds->volume.dims[1], ds->volume.dims[2],
           ds->volume.value_min, ds->volume.value_max, ds->load_ms);
    sl_dataset_destroy(ds);
    free(bytes);
}

/* cranium.nhdr + cranium.raw: 256x256x108 int16 little-endian CT. */
static void test_cranium(void)
{
    sl_dataset *ds = load(sample("cranium.nhdr"));
    if (!ds)
        return;
    SL_CHECK(ds->volume.dims[0] == 256 && ds->volume.dims[1] == 256 && ds->volume.dims[2] == 108);
    SL_CHECK(ds->volume.type == SL_VOXEL_S16 && ds->volume.components == 1);
    SL_CHECK_NEAR(ds->volume.spacing[0], 0.9570312, 1e-12);
    SL_CHECK_NEAR(ds->volume.spacing[2], 1.5, 0);
    FILE *f = fopen(sample("cranium.raw"), "rb");
    SL_CHECK(f != NULL);
    size_t count = 256u * 256u * 108u;
    uint8_t *raw = malloc(2 * count);
    if (f && raw && fread(raw, 2, count, f) == count) {
        int lo = 32767, hi = -32768, bad = 0;
        const int16_t *vox = ds->volume.data;
        for (size_t i = 0; i < count; i++) {
            int v = le16(raw + 2 * i);
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
            bad += vox[i] != v;
        }
        SL_CHECK_MSG(bad == 0, "%d voxels differ from cranium.raw", bad);
        SL_CHECK_NEAR(ds->volume.value_min, lo, 0);
        SL_CHECK_NEAR(ds->volume.value_max, hi, 0);
        SL_CHECK(lo == -1024);           /* CT air */
        SL_CHECK(hi > 1500 && hi < 4096); /* bone */
    } else {
        SL_CHECK_MSG(0, "cannot read cranium.raw");
    }
    if (f)
        fclose(f);
    free(raw);
    printf("cranium: %dx%dx%d s16, range %g..%g, %.1f ms\n", ds->volume.dims[0], ds->volume.dims[1],
           ds->volume.dims[2], ds->volume.value_min, ds->volume.value_max, ds->load_ms);
    sl_dataset_destroy(ds);
}

/* Walks a TrackVis file's records: streamline and vertex counts, or -1. */
static int trk_counts(const char *path, size_t *lines, size_t *vertices)
{
    uint8_t *b = NULL;
    size_t n = 0;
    sl_err err = {0};
    if (sl_read_file(path, SL_MAX_FILE_BYTES, &b, &n, &err) != SL_OK || n < 1000 || le32(b + 996) != 1000) {
        free(b);
        return -1;
    }
    size_t per_point = 3 + (size_t)le16(b + 36), props = (size_t)le16(b + 238), pos = 1000;
    *lines = *vertices = 0;
    while (pos + 4 <= n) {
        int32_t m = le32(b + pos);
        if (m < 0)
            break;
        size_t rec = 4 + ((size_t)m * per_point + props) * 4;
        if (pos + rec > n)
            break;
        pos += rec;
        ++*lines;
        *vertices += (size_t)m;
    }
    int32_t declared = le32(b + 988);
    free(b);
    if (pos != n || (declared != 0 && (size_t)declared != *lines))
        return -1;
    return 0;
}

static void test_bundles(void)
{
    static const char *names[] = {"AF_L", "CC_ForcepsMajor", "CST_R"};
    int files = 0;
    for (int s = 1; s <= 5; s++)
        for (int k = 0; k < 3; k++) {
            char rel[256];
            snprintf(rel, sizeof rel, "minimal_bundles/sub_%d/%s.trk", s, names[k]);
            const char *path = sample(rel);
            size_t lines = 0, verts = 0;
            SL_CHECK_MSG(trk_counts(path, &lines, &verts) == 0, "%s: independent walk failed", path);
            sl_dataset *ds = load(path);
            if (!ds)
                continue;
            files++;
            SL_CHECK(ds->kind == SL_DATASET_LINES);
            SL_CHECK_MSG(ds->lines.line_count == lines && ds->lines.vertex_count == verts,
                         "%s: loaded %zu lines / %zu vertices, file has %zu / %zu", path, ds->lines.line_count,
                         ds->lines.vertex_count, lines, verts);
            SL_CHECK(lines > 0 && verts >= 2 * lines);
            SL_CHECK(strcmp(ds->name, names[k]) == 0);
            double extent = sl_v3_length(sl_v3_sub(ds->bounds_max, ds->bounds_min));
            SL_CHECK_MSG(sl_v3_is_finite(ds->bounds_min) && extent > 10.0 && extent < 1000.0,
                         "%s: bounds extent %g (a brain bundle spans centimetres)", path, extent);
            sl_dataset_destroy(ds);
        }
    printf("minimal_bundles: %d .trk files loaded\n", files);
}

/* Exit code for "not run": the SKIP_RETURN_CODE of unit.test_samples. */
#define SL_TEST_SKIP 77

int main(void)
{
    const char *root = getenv("SIGHTLINE_SOURCE_DIR");
    snprintf(samples, sizeof samples, "%s/data/samples", root && root[0] ? root : ".");
    struct stat st;
    if (stat(samples, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("skipped: samples not fetched (%s missing; run scripts/fetch-sample-data)\n", samples);
        return SL_TEST_SKIP;
    }
    test_ch2();
    test_cranium();
    test_bundles();
    SL_TEST_END();
}
