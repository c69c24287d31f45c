/* standalone_driver.c — runs a libFuzzer target without libFuzzer (gcc builds).
 *
 * Replays every file of the corpus folder given as argv[1], then 2000 seeded
 * mutations of them (bit flips, truncations, overwritten integers), so the
 * same target finds crashes under ASan/UBSan in every build. Deterministic.
 */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t next_random(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static uint8_t *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *buf = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? cap * 2 : 4096;
            uint8_t *grown = realloc(buf, cap);
            if (!grown) { free(buf); fclose(f); return NULL; }
            buf = grown;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    fclose(f);
    *size = n;
    return buf;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
        return 2;
    }
    DIR *dir = opendir(argv[1]);
    if (!dir) {
        fprintf(stderr, "cannot open corpus %s\n", argv[1]);
        return 2;
    }
    uint8_t *seeds[256];
    size_t sizes[256];
    int count = 0;
    struct dirent *e;
    while ((e = readdir(dir)) && count < 256) {
        if (e->d_name[0] == '.')
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", argv[1], e->d_name);
        size_t size = 0;
        uint8_t *data = read_all(path, &size);
        if (!data)
            continue;
        LLVMFuzzerTestOneInput(data, size);
        seeds[count] = data;
        sizes[count++] = size;
    }
    closedir(dir);
    for (int round = 0; round < 2000 && count > 0; round++) {
        int k = (int)(next_random() % (uint64_t)count);
        size_t size = sizes[k];
        uint8_t *copy = malloc(size ? size : 1);
        if (!copy)
            return 1;
        memcpy(copy, seeds[k], size);
        int edits = 1 + (int)(next_random() % 8);
        for (int m = 0; m < edits && size > 0; m++) {
            size_t at = (size_t)(next_random() % size);
            switch (next_random() % 4) {
            case 0: copy[at] ^= (uint8_t)(1u << (next_random() % 8)); break;
            case 1: copy[at] = (uint8_t)next_random(); break;
            case 2: size = at; break; /* truncate */
            default:
                if (at + 4 <= size) {
                    uint32_t v = (uint32_t)next_random();
                    if (next_random() % 2) v = 0xFFFFFFFFu >> (next_random() % 32);
                    memcpy(copy + at, &v, 4);
                }
            }
        }
        LLVMFuzzerTestOneInput(copy, size);
        free(copy);
    }
    for (int i = 0; i < count; i++)
        free(seeds[i]);
    printf("replayed %d corpus files and 2000 mutations\n", count);
    return 0;
}
