/* fuzz_raw_json.c — fuzz target for the raw volume + JSON sidecar loader
 * (sl_load_raw_json in renderer/data/load_raw_json.c).
 *
 * The input is the sidecar; it is loaded as "<folder>/x.json", where the
 * folder is a fresh temporary directory made on the first call, holding
 * fixed raw files the sidecar can name: r.raw (24 bytes), v.raw.gz (24
 * bytes gzipped), empty.raw (0 bytes). Names that leave the folder are
 * refused by the loader, so the fuzzer cannot read or write elsewhere; the
 * folder is removed at exit. On success the dataset must be a consistent
 * volume (dims >= 1, exactly the raw file's bytes, 1 or 3 components,
 * value range ordered) and every voxel is read so ASan sees the whole
 * array; on failure *out must stay NULL and the message be non-empty.
 * Seed corpus: tests/fuzz/corpus/raw_json/. Single-threaded.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "data/sl_load.h"
#include "fuzz_check.h"

static char folder[64];
static char json_path[128];

static void write_bytes(const char *name, const void *data, size_t n)
{
    char path[192];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n)
        abort();
    fclose(f);
}

static void remove_folder(void)
{
    static const char *const names[] = {"r.raw", "v.raw.gz", "empty.raw"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char path[192];
        snprintf(path, sizeof path, "%s/%s", folder, names[i]);
        unlink(path);
    }
    rmdir(folder);
}

/* Makes the folder and its raw files once. */
static void setup(void)
{
    snprintf(folder, sizeof folder, "/tmp/sl_fuzz_raw_json_XXXXXX");
    if (!mkdtemp(folder))
        abort();
    snprintf(json_path, sizeof json_path, "%s/x.json", folder);
    uint8_t raw[24];
    for (int i = 0; i < 24; i++)
        raw[i] = (uint8_t)(i * 37 + 11);
    write_bytes("r.raw", raw, sizeof raw);
    write_bytes("empty.raw", "", 0);
    uint8_t gz[128];
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        abort();
    zs.next_in = raw;
    zs.avail_in = sizeof raw;
    zs.next_out = gz;
    zs.avail_out = sizeof gz;
    if (deflate(&zs, Z_FINISH) != Z_STREAM_END)
        abort();
    write_bytes("v.raw.gz", gz, zs.total_out);
    deflateEnd(&zs);
    atexit(remove_folder);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!folder[0])
        setup();
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_raw_json(data, size, json_path, &ds, &err);
    /* The raw files hold 24 bytes: never more values than that. */
    if (st == SL_OK && ds && (uint64_t)ds->volume.dims[0] * (uint64_t)ds->volume.dims[1] *
                                     (uint64_t)ds->volume.dims[2] * (uint64_t)ds->volume.components > 24)
        abort();
    sl_fuzz_check(st, ds, &err);
    return 0;
}
