/* fuzz_gzip_stream.c — fuzz target for the piecewise file reader
 * (sl_load_stream in renderer/data/read_file.c), checked against sl_gunzip.
 *
 * Writes the input to one fixed file in a temporary folder (made on the
 * first call, removed at exit) and reads it back through a stream, first
 * a 100-byte header piece, then up to a 1 MiB limit. Oracle: for gzip input
 * the stream and sl_gunzip (same limit) must agree on success and, when
 * both succeed, on every byte; non-gzip input must come back unchanged. A
 * piece never exceeds what was asked for. Seed corpus:
 * tests/fuzz/corpus/gzip_stream/. Single-threaded.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data/load_common.h"

#define FUZZ_LIMIT (1u << 20)

static char folder[64];
static char file_path[128];

static void remove_folder(void)
{
    unlink(file_path);
    rmdir(folder);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!folder[0]) {
        snprintf(folder, sizeof folder, "/tmp/sl_fuzz_stream_XXXXXX");
        if (!mkdtemp(folder))
            abort();
        snprintf(file_path, sizeof file_path, "%s/in.bin", folder);
        atexit(remove_folder);
    }
    FILE *f = fopen(file_path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size))
        abort();
    fclose(f);

    sl_err err = {0};
    sl_load_stream *s = NULL;
    if (sl_load_stream_open(file_path, SL_STREAM_AUTO, &s, &err) != SL_OK)
        abort(); /* a regular file we just wrote always opens */
    int gz = sl_load_stream_gzipped(s);
    const uint8_t *p;
    size_t n;
    sl_status st = sl_load_stream_fill(s, 100, &p, &n, &err);
    if (st == SL_OK && n > 100)
        abort();
    if (st == SL_OK)
        st = sl_load_stream_fill(s, FUZZ_LIMIT + 1, &p, &n, &err);
    if (st == SL_OK && n > FUZZ_LIMIT)
        st = SL_ERR_LIMIT;
    if (st != SL_OK && err.message[0] == '\0')
        abort();

    if (!gz) {
        if (st != SL_OK || n != size || (n && memcmp(p, data, n) != 0))
            abort();
    } else {
        uint8_t *ref = NULL;
        size_t ref_n = 0;
        sl_err ref_err = {0};
        sl_status ref_st = sl_gunzip(data, size, FUZZ_LIMIT, &ref, &ref_n, &ref_err);
        if ((st == SL_OK) != (ref_st == SL_OK))
            abort();
        if (st == SL_OK && (ref_n != n || (n && memcmp(ref, p, n) != 0)))
            abort();
        free(ref);
    }
    sl_load_stream_close(s);
    return 0;
}
