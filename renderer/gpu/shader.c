/* shader.c — embedded GLSL: lookup, #include expansion, compile and link with
 * errors that name the file and line (see sl_gpu.h).
 *
 * Every file gets its own GLSL source-string number through `#line L N`; the
 * compiler's info log refers to "N:L(col)" or "N(L)", which is rewritten to
 * "path:L". A file is included at most once per stage (include guards are
 * not needed); nesting deeper than 8 is an error. Render thread only.
 */
#include "sl_gpu.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

extern const sl_embedded_file sl_embedded_files[];
extern const int sl_embedded_file_count;

const sl_embedded_file *sl_embedded_find(const char *path)
{
    for (int i = 0; i < sl_embedded_file_count; i++)
        if (strcmp(sl_embedded_files[i].path, path) == 0)
            return &sl_embedded_files[i];
    return NULL;
}

const sl_embedded_file *sl_embedded_list(int *count)
{
    *count = sl_embedded_file_count;
    return sl_embedded_files;
}

/* A growable string. */
typedef struct text { char *s; size_t len, cap; int failed; } text;

static void text_append(text *t, const char *s, size_t n)
{
    if (t->failed)
        return;
    if (t->len + n + 1 > t->cap) {
        size_t cap = t->cap ? t->cap : 4096;
        while (t->len + n + 1 > cap)
            cap *= 2;
        char *grown = realloc(t->s, cap);
        if (!grown) { t->failed = 1; return; }
        t->s = grown;
        t->cap = cap;
    }
    memcpy(t->s + t->len, s, n);
    t->len += n;
    t->s[t->len] = '\0';
}

static void text_printf(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void text_printf(text *t, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n > 0)
        text_append(t, buf, (size_t)n < sizeof buf ? (size_t)n : sizeof buf - 1);
}

/* An expansion in progress: the text so far and the files it pasted. */
typedef struct expansion {
    text out;
    const sl_embedded_file *files[SL_SHADER_MAX_FILES]; /* index = GLSL source-string number */
    int file_count;
} expansion;

static sl_status expand(expansion *x, const sl_embedded_file *f, int depth, sl_err *err)
{
    if (depth > 8)
        return sl_err_set(err, SL_ERR_GPU, "%s: #include nested deeper than 8", f->path);
    for (int i = 0; i < x->file_count; i++)
        if (x->files[i] == f)
            return SL_OK; /* included once */
    if (x->file_count >= SL_SHADER_MAX_FILES)
        return sl_err_set(err, SL_ERR_GPU, "%s: more than %d shader files in one stage", f->path, SL_SHADER_MAX_FILES);
    int number = x->file_count;
    x->files[x->file_count++] = f;
    text_printf(&x->out, "#line 1 %d\n", number);
    const char *p = f->text, *end = f->text + f->size;
    int line = 1;
    while (p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        size_t n = eol ? (size_t)(eol - p) : (size_t)(end - p);
        const char *q = p;
        while (q < p + n && (*q == ' ' || *q == '\t'))
            q++;
        if ((size_t)(p + n - q) >= 8 && strncmp(q, "#include", 8) == 0) {
            const char *a = memchr(q, '"', (size_t)(p + n - q));
            const char *b = a ? memchr(a + 1, '"', (size_t)(p + n - a - 1)) : NULL;
            if (!a || !b || b - a - 1 >= 256)
                return sl_err_set(err, SL_ERR_GPU, "%s:%d: malformed #include", f->path, line);
            char name[256];
            memcpy(name, a + 1, (size_t)(b - a - 1));
            name[b - a - 1] = '\0';
            const sl_embedded_file *inc = sl_embedded_find(name);
            if (!inc)
                return sl_err_set(err, SL_ERR_GPU, "%s:%d: #include \"%s\": no such embedded file", f->path, line, name);
            sl_status st = expand(x, inc, depth + 1, err);
            if (st != SL_OK)
                return st;
            text_printf(&x->out, "#line %d %d\n", line + 1, number);
        } else if ((size_t)(p + n - q) >= 8 && strncmp(q, "#version", 8) == 0) {
            text_append(&x->out, "\n", 1); /* the version line is ours to write */
        } else {
            text_append(&x->out, p, n);
            text_append(&x->out, "\n", 1);
        }
        line++;
        p += n + 1;
    }
    return x->out.failed ? sl_err_set(err, SL_ERR_NOMEM, "out of memory expanding %s", f->path) : SL_OK;
}

/* Rewrites "N:L(c)" and "N(L)" at line starts of a Mesa/NVIDIA info log to "path:L". */
static void map_log(const sl_shader_source *x, const char *log, text *out)
{
    const char *p = log;
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t n = eol ? (size_t)(eol - p) : strlen(p);
        int file = -1, line = -1, used = 0;
        if (sscanf(p, "%d:%d%n", &file, &line, &used) == 2 ||
            sscanf(p, "%d(%d)%n", &file, &line, &used) == 2) {
            if (file >= 0 && file < x->file_count && used > 0 && (size_t)used <= n) {
                text_printf(out, "%s:%d", x->paths[file], line);
                text_append(out, p + used, n - (size_t)used);
                text_append(out, "\n", 1);
                p += n + (eol ? 1 : 0);
                continue;
            }
        }
        text_append(out, p, n);
        text_append(out, "\n", 1);
        p += n + (eol ? 1 : 0);
    }
}

sl_status sl_shader_expand(const sl_embedded_file *file, const char *defines, sl_shader_source *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    expansion x = {0};
    /* Appended, not printed: text_printf truncates at 512 bytes and defines
     * may be longer (flow/ pastes Butcher tableaux). */
    text_printf(&x.out, "#version 450 core\n");
    if (defines)
        text_append(&x.out, defines, strlen(defines));
    sl_status st = expand(&x, file, 0, err);
    if (st == SL_OK && x.out.failed)
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory expanding %s", file->path);
    if (st != SL_OK) {
        free(x.out.s);
        return st;
    }
    out->text = x.out.s;
    out->file_count = x.file_count;
    for (int i = 0; i < x.file_count; i++)
        out->paths[i] = x.files[i]->path;
    return SL_OK;
}

void sl_shader_source_free(sl_shader_source *src)
{
    if (src) {
        free(src->text);
        memset(src, 0, sizeof *src);
    }
}

sl_status sl_shader_compile(GLenum stage, const sl_shader_source *src, GLuint *shader, sl_err *err)
{
    *shader = 0;
    GLuint s = glCreateShader(stage);
    const char *source = src->text;
    glShaderSource(s, 1, &source, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = "";
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        text mapped = {0};
        map_log(src, log, &mapped);
        sl_err_set(err, SL_ERR_GPU, "compiling %s:\n%s", src->file_count ? src->paths[0] : "shader",
                   mapped.s ? mapped.s : log);
        free(mapped.s);
        glDeleteShader(s);
        return SL_ERR_GPU;
    }
    *shader = s;
    return SL_OK;
}

static sl_status compile_stage(GLenum stage, const char *path, const char *defines, GLuint *shader, sl_err *err)
{
    const sl_embedded_file *f = sl_embedded_find(path);
    if (!f)
        return sl_err_set(err, SL_ERR_GPU, "no embedded shader '%s' (is the file under renderer/?)", path);
    sl_shader_source src;
    sl_status st = sl_shader_expand(f, defines, &src, err);
    if (st == SL_OK)
        st = sl_shader_compile(stage, &src, shader, err);
    sl_shader_source_free(&src);
    return st;
}

sl_status sl_gl_program_create(const sl_program_desc *d, GLuint *program, sl_err *err)
{
    *program = 0;
    const char *paths[4] = {d->vertex, d->geometry, d->fragment, d->compute};
    const GLenum stages[4] = {GL_VERTEX_SHADER, GL_GEOMETRY_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER};
    GLuint shaders[4] = {0};
    sl_status st = SL_OK;
    GLuint p = glCreateProgram();
    for (int i = 0; i < 4 && st == SL_OK; i++) {
        if (!paths[i])
            continue;
        st = compile_stage(stages[i], paths[i], d->defines, &shaders[i], err);
        if (st == SL_OK)
            glAttachShader(p, shaders[i]);
    }
    if (st == SL_OK) {
        glLinkProgram(p);
        GLint ok = 0;
        glGetProgramiv(p, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[4096] = "";
            glGetProgramInfoLog(p, sizeof log, NULL, log);
            st = sl_err_set(err, SL_ERR_GPU, "linking %s: %s", d->label ? d->label : "program", log);
        }
    }
    for (int i = 0; i < 4; i++)
        if (shaders[i]) {
            glDetachShader(p, shaders[i]);
            glDeleteShader(shaders[i]);
        }
    if (st != SL_OK) {
        glDeleteProgram(p);
        return st;
    }
    if (d->label)
        glObjectLabel(GL_PROGRAM, p, -1, d->label);
    *program = p;
    return SL_OK;
}
