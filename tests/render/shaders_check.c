/* shaders_check.c — compiles every embedded GLSL stage file on its own.
 *
 * usage: shaders-check [--file PATH.glsl ...]
 * Without --file: every embedded file (sl_embedded_list, renderer/ and below, *.glsl)
 * whose name ends in .vert/.tesc/.tese/.geom/.frag/.comp.glsl is compiled as
 * that stage, with its #include lines resolved against the embedded files by
 * renderer/gpu/shader.c itself (sl_shader_expand: `#include "gpu/glsl/x.glsl"` pastes an
 * embedded file once per stage, nesting up to 8, #version is ours:
 * "#version 450 core"). Every other embedded file is an include and must be
 * pulled in by at least one stage file, so no shader escapes compilation.
 * With --file: the given files from disk instead (their includes still come
 * from the embedded set) — the negative tests feed broken shaders this way.
 *
 * Shaders that a technique compiles with `defines` (e.g. `#if VX_PASS == 2`)
 * do not compile without them, since GLSL rejects undefined macros in #if.
 * Each macro used in an #if/#elif but never #defined is a variant: it is set
 * to every integer it is compared with (`NAME == k`; when that is a single k,
 * also to k + 1 for the #else branch), or 0 and 1 when it is not compared;
 * #ifdef/#ifndef/defined(NAME) macros are tried undefined and as 1. Every
 * combination is compiled (at most 256).
 *
 * Errors print the file, the variant and the info log with "N:L" mapped to
 * "path:L". Exit 0 all compiled, 1 a compile error, 2 bad input, 3 no GPU.
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_load.h"
#include "gpu/sl_gpu.h"

#define MAX_MACROS 8
#define MAX_VALUES 16
#define MAX_VARIANTS 256

typedef struct buf { char *s; size_t len, cap; } buf;

static void put(buf *b, const char *s, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (b->len + n + 1 > cap)
            cap *= 2;
        char *g = realloc(b->s, cap);
        if (!g) {
            fprintf(stderr, "shaders-check: out of memory\n");
            exit(2);
        }
        b->s = g;
        b->cap = cap;
    }
    memcpy(b->s + b->len, s, n);
    b->len += n;
    b->s[b->len] = '\0';
}

static void puts_(buf *b, const char *s) { put(b, s, strlen(s)); }

/* ---- variants ---- */

typedef struct macro {
    char name[64];
    int ifdef_only;                 /* only tested for being defined */
    int values[MAX_VALUES], value_count;
} macro;

static int is_ident_start(int c) { return isalpha(c) || c == '_'; }
static int is_ident(int c) { return isalnum(c) || c == '_'; }

static int defined_in(const char *src, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = strstr(src, "#define"); p; p = strstr(p + 7, "#define")) {
        const char *q = p + 7;
        while (*q == ' ' || *q == '\t')
            q++;
        if (strncmp(q, name, n) == 0 && !is_ident((unsigned char)q[n]))
            return 1;
    }
    return 0;
}

static macro *find_or_add(macro *m, int *count, const char *name, size_t n)
{
    for (int i = 0; i < *count; i++)
        if (strlen(m[i].name) == n && strncmp(m[i].name, name, n) == 0)
            return &m[i];
    if (*count >= MAX_MACROS || n >= sizeof m[0].name)
        return NULL;
    macro *k = &m[(*count)++];
    memset(k, 0, sizeof *k);
    memcpy(k->name, name, n);
    k->ifdef_only = 1;
    return k;
}

static void add_value(macro *k, int v)
{
    for (int i = 0; i < k->value_count; i++)
        if (k->values[i] == v)
            return;
    if (k->value_count < MAX_VALUES)
        k->values[k->value_count++] = v;
}

/* Macros used by #if/#elif/#ifdef/#ifndef that the source never #defines. */
static int find_macros(const char *src, macro *m)
{
    int count = 0;
    for (const char *p = src; *p;) {
        const char *eol = strchr(p, '\n');
        size_t n = eol ? (size_t)(eol - p) : strlen(p);
        const char *q = p;
        while (*q == ' ' || *q == '\t')
            q++;
        int ifdef = strncmp(q, "#ifdef", 6) == 0 || strncmp(q, "#ifndef", 7) == 0;
        int ifexpr = !ifdef && (strncmp(q, "#if", 3) == 0 || strncmp(q, "#elif", 5) == 0);
        if (ifdef || ifexpr) {
            q += ifdef ? (q[3] == 'n' ? 7 : 6) : (q[1] == 'e' ? 5 : 3);
            const char *end = p + n;
            while (q < end) {
                if (!is_ident_start((unsigned char)*q)) {
                    q++;
                    continue;
                }
                const char *s = q;
                while (q < end && is_ident((unsigned char)*q))
                    q++;
                size_t len = (size_t)(q - s);
                char name[64];
                if (len >= sizeof name || (len == 7 && strncmp(s, "defined", 7) == 0) ||
                    strncmp(s, "GL_", 3) == 0 || strncmp(s, "__", 2) == 0)
                    continue;
                memcpy(name, s, len);
                name[len] = '\0';
                if (defined_in(src, name))
                    continue;
                /* `defined(NAME)` / `defined NAME`: only defined-ness matters. */
                const char *b = s;
                while (b > p && (b[-1] == ' ' || b[-1] == '('))
                    b--;
                int as_defined = ifdef || (b - p >= 7 && strncmp(b - 7, "defined", 7) == 0);
                macro *k = find_or_add(m, &count, s, len);
                if (!k)
                    continue;
                if (!as_defined)
                    k->ifdef_only = 0;
                const char *r = q;
                while (r < end && (*r == ' ' || *r == '\t'))
                    r++;
                if (!as_defined && r + 1 < end && r[0] == '=' && r[1] == '=') {
                    r += 2;
                    while (r < end && (*r == ' ' || *r == '\t'))
                        r++;
                    if (r < end && (isdigit((unsigned char)*r) || *r == '-'))
                        add_value(k, atoi(r));
                }
            }
        }
        p += n + (eol ? 1 : 0);
    }
    for (int i = 0; i < count; i++) {
        if (m[i].value_count == 0)
            add_value(&m[i], 0);
        if (m[i].value_count == 1) /* `#if NAME == k ... #else`: k and another value */
            add_value(&m[i], m[i].values[0] + 1);
    }
    return count;
}

/* ---- compile ---- */

static GLenum stage_of(const char *path, const char **name)
{
    static const struct { const char *suffix, *name; GLenum stage; } stages[] = {
        {".vert.glsl", "vertex", GL_VERTEX_SHADER},
        {".tesc.glsl", "tessellation control", GL_TESS_CONTROL_SHADER},
        {".tese.glsl", "tessellation evaluation", GL_TESS_EVALUATION_SHADER},
        {".geom.glsl", "geometry", GL_GEOMETRY_SHADER},
        {".frag.glsl", "fragment", GL_FRAGMENT_SHADER},
        {".comp.glsl", "compute", GL_COMPUTE_SHADER},
    };
    size_t n = strlen(path);
    for (size_t i = 0; i < sizeof stages / sizeof stages[0]; i++) {
        size_t m = strlen(stages[i].suffix);
        if (n > m && strcmp(path + n - m, stages[i].suffix) == 0) {
            *name = stages[i].name;
            return stages[i].stage;
        }
    }
    return 0;
}

/* Prints a compile error's info log (already mapped to "path:L"), indented,
 * without its first line ("compiling PATH:"). */
static void print_log(const char *message)
{
    const char *p = strchr(message, '\n');
    for (p = p ? p + 1 : message; *p;) {
        const char *eol = strchr(p, '\n');
        size_t n = eol ? (size_t)(eol - p) : strlen(p);
        if (n)
            fprintf(stderr, "  %.*s\n", (int)n, p);
        p += n + (eol ? 1 : 0);
    }
}

/* Compiles one stage file in every variant; returns the number that failed. */
static int check_file(const char *path, const char *text, size_t size, int *variants_done)
{
    const char *stage_name = NULL;
    GLenum stage = stage_of(path, &stage_name);
    if (!stage) {
        fprintf(stderr, "shaders-check: %s: not a stage file (.vert/.tesc/.tese/.geom/.frag/.comp.glsl)\n", path);
        return 1;
    }
    const sl_embedded_file file = {path, text, size};
    sl_shader_source plain;
    sl_err err = {0};
    if (sl_shader_expand(&file, NULL, &plain, &err) != SL_OK) {
        fprintf(stderr, "shaders-check: FAIL %s: %s\n", path, err.message);
        return 1;
    }
    macro macros[MAX_MACROS];
    int mc = find_macros(plain.text, macros);
    sl_shader_source_free(&plain);
    int combos = 1;
    for (int i = 0; i < mc; i++)
        combos *= macros[i].ifdef_only ? 2 : macros[i].value_count;
    if (combos > MAX_VARIANTS) {
        fprintf(stderr, "shaders-check: FAIL %s: %d macro combinations (more than %d)\n", path, combos, MAX_VARIANTS);
        return 1;
    }
    int failed = 0;
    for (int v = 0; v < combos; v++) {
        buf defines = {0}, label = {0};
        for (int i = 0, rest = v; i < mc; i++) {
            int k = macros[i].ifdef_only ? 2 : macros[i].value_count, pick = rest % k;
            rest /= k;
            char def[1200]; /* a macro name is at most a source line */
            if (macros[i].ifdef_only && pick == 0)
                snprintf(def, sizeof def, "(%s undefined) ", macros[i].name);
            else {
                int value = macros[i].ifdef_only ? 1 : macros[i].values[pick];
                snprintf(def, sizeof def, "#define %s %d\n", macros[i].name, value);
                puts_(&defines, def);
                snprintf(def, sizeof def, "%s=%d ", macros[i].name, value);
            }
            puts_(&label, def);
        }
        sl_shader_source src;
        GLuint sh = 0;
        sl_status st = sl_shader_expand(&file, defines.s, &src, &err);
        if (st == SL_OK)
            st = sl_shader_compile(stage, &src, &sh, &err);
        if (st != SL_OK) {
            fprintf(stderr, "shaders-check: FAIL %s (%s shader%s%s):\n", path, stage_name, label.s ? ", " : "",
                    label.s ? label.s : "");
            print_log(err.message);
            failed++;
        } else {
            printf("ok   %-44s %-9s %s\n", path, stage_name, label.s ? label.s : "");
        }
        if (sh)
            glDeleteShader(sh);
        sl_shader_source_free(&src);
        free(defines.s);
        free(label.s);
        (*variants_done)++;
    }
    return failed;
}

/* 1 when `path` is pulled in (directly or not) by some stage file. */
static int included_by_a_stage(const char *path, const sl_embedded_file *files, int n)
{
    for (int i = 0; i < n; i++) {
        const char *stage_name;
        if (!stage_of(files[i].path, &stage_name))
            continue;
        sl_shader_source src;
        sl_err err = {0};
        int used = 0;
        if (sl_shader_expand(&files[i], NULL, &src, &err) == SL_OK)
            for (int k = 1; k < src.file_count; k++)
                used |= strcmp(src.paths[k], path) == 0;
        sl_shader_source_free(&src);
        if (used)
            return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *disk[64];
    int ndisk = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--file") == 0 && i + 1 < argc && ndisk < 64)
            disk[ndisk++] = argv[++i];
        else {
            fprintf(stderr, "usage: shaders-check [--file PATH.glsl ...]\n");
            return 2;
        }
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "shaders-check: GPU: %s\n", err.message);
        return 3;
    }
    int failed = 0, stages = 0, variants = 0, bad_input = 0;
    if (ndisk) {
        for (int i = 0; i < ndisk; i++) {
            uint8_t *data = NULL;
            size_t size = 0;
            if (sl_read_file(disk[i], 1u << 20, &data, &size, &err) != SL_OK) {
                fprintf(stderr, "shaders-check: %s\n", err.message);
                bad_input = 1;
                continue;
            }
            failed += check_file(disk[i], (const char *)data, size, &variants);
            stages++;
            free(data);
        }
    } else {
        int n = 0;
        const sl_embedded_file *files = sl_embedded_list(&n);
        for (int i = 0; i < n; i++) {
            const char *stage_name;
            if (stage_of(files[i].path, &stage_name)) {
                failed += check_file(files[i].path, files[i].text, files[i].size, &variants);
                stages++;
            } else if (!included_by_a_stage(files[i].path, files, n)) {
                fprintf(stderr, "shaders-check: FAIL %s: neither a stage file nor included by one, so never compiled\n",
                        files[i].path);
                failed++;
            }
        }
        if (stages == 0) {
            fprintf(stderr, "shaders-check: FAIL no stage files among the %d embedded files\n", n);
            failed++;
        }
    }
    printf("shaders-check: %d stage file%s, %d compile%s, %d failure%s\n", stages, stages == 1 ? "" : "s", variants,
           variants == 1 ? "" : "s", failed, failed == 1 ? "" : "s");
    sl_gpu_destroy(gpu);
    return bad_input ? 2 : failed ? 1 : 0;
}
