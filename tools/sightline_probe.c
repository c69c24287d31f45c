/* sightline_probe.c — the value of a dataset's field at given points:
 *   sightline-probe DATASET --points P.csv [--gradient] [--out F.csv]
 *
 * DATASET is anything sl_dataset_open takes (a file, a built-in name, a
 * generator call). P.csv holds one point "x,y,z" per line (world
 * coordinates); '#' starts a comment, blank lines are skipped, and the first
 * line may be a header (its first field is not a number). Any other line
 * that is not three finite numbers is an error naming the file and line.
 * Output (stdout or --out): a header line, then per point x,y,z (as read,
 * %.17g) and the value (scalars: value; vectors: vx,vy,vz), with
 * --gradient also gx,gy,gz (scalars) or the 9 Jacobian entries
 * dvx_dx..dvz_dz (vectors). A point outside the dataset's domain gets empty
 * value (and gradient) fields: "x,y,z,," — so it is told apart from a NaN
 * voxel, which prints as nan.
 * Evaluation: renderer/probe/sl_probe.h on the CPU in double (trilinear,
 * spline); with --gpu, renderer/probe/sl_probe_gpu.h through the shaders the
 * renderers sample with (LR: Bézier blocks in float, value and gradient;
 * volumes: volume_dvr's filtered texture; vector fields: the streamline
 * field; no gradients of regular volumes), the same points left empty.
 * Points go to the evaluator in batches of BATCH. Single-threaded (the
 * main thread owns the GL context).
 * Exit status: 0 success; 1 usage error; 2 bad input (message on stderr);
 * 3 no GPU or a GPU error (--gpu).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset.h"
#include "data/sl_dataset_open.h"
#include "gpu/sl_gpu.h"
#include "probe/sl_probe.h"
#include "probe/sl_probe_gpu.h"

#define EXIT_USAGE 1
#define EXIT_BAD_INPUT 2
#define EXIT_GPU 3
#define BATCH 4096
#define LINE_MAX_BYTES 4096

/* Evaluates n points (3n doubles): values[n*nc], gradients[n*3*nc] (NULL:
 * none), inside[n]; through the shaders when gpu is not NULL, else on the
 * CPU in double. */
static sl_status evaluate(const sl_dataset *ds, sl_probe_gpu *gpu, size_t n, const double *points, double *values,
                          double *gradients, unsigned char *inside, sl_err *err)
{
    if (gpu)
        return sl_probe_gpu_eval(gpu, n, points, values, gradients, inside, err);
    int nc = sl_probe_components(ds);
    for (size_t i = 0; i < n; i++) {
        int in = 0;
        sl_status st = sl_probe_eval(ds, points + 3 * i, values + i * (size_t)nc,
                                     gradients ? gradients + i * 3 * (size_t)nc : NULL, &in, err);
        if (st != SL_OK)
            return st;
        inside[i] = (unsigned char)in;
    }
    return SL_OK;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: sightline-probe DATASET --points P.csv [--gradient] [--gpu] [--out F.csv]\n"
               "Evaluates the dataset's field (trilinear for volumes and vector fields, the spline for\n"
               "LR-spline volumes; double precision on the CPU) at the points x,y,z of P.csv and writes\n"
               "x,y,z,value... as CSV ('#' comments and a header line allowed in P.csv). Points outside\n"
               "the domain get empty value fields. --gpu: through the renderers' shaders instead (float;\n"
               "LR: the Bezier blocks; volumes: volume_dvr's filtered texture; vector fields: the\n"
               "streamline field; --gradient only for LR volumes). Exit 0 ok, 1 usage, 2 bad input,\n"
               "3 no GPU or a GPU error.\n");
}

/* Parses one CSV field as a finite double; 0 when it is not one. */
static int parse_field(const char *s, size_t len, double *v)
{
    while (len && (*s == ' ' || *s == '\t')) {
        s++;
        len--;
    }
    while (len && (s[len - 1] == ' ' || s[len - 1] == '\t' || s[len - 1] == '\r' || s[len - 1] == '\n'))
        len--;
    char buf[128];
    if (len == 0 || len >= sizeof buf)
        return 0;
    memcpy(buf, s, len);
    buf[len] = '\0';
    char *end = NULL;
    errno = 0;
    *v = strtod(buf, &end);
    return end == buf + len && isfinite(*v);
}

/* Splits a line (comment removed) at ','; fields[k] = start, lens[k] = length. */
static int split(const char *line, const char **fields, size_t *lens, int max)
{
    int n = 0;
    const char *p = line;
    for (;;) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        if (n < max) {
            fields[n] = p;
            lens[n] = len;
        }
        n++;
        if (!c)
            return n;
        p = c + 1;
    }
}

static int blank(const char *s)
{
    return s[strspn(s, " \t\r\n")] == '\0';
}

typedef struct probe_out {
    FILE *f;
    int nc, gradient;
} probe_out;

static void write_header(const probe_out *o)
{
    static const char *const axes = "xyz";
    fputs("x,y,z", o->f);
    if (o->nc == 1)
        fputs(",value", o->f);
    else
        for (int c = 0; c < 3; c++)
            fprintf(o->f, ",v%c", axes[c]);
    if (o->gradient)
        for (int c = 0; c < o->nc; c++)
            for (int j = 0; j < 3; j++) {
                if (o->nc == 1)
                    fprintf(o->f, ",g%c", axes[j]);
                else
                    fprintf(o->f, ",dv%c_d%c", axes[c], axes[j]);
            }
    fputc('\n', o->f);
}

static void write_rows(const probe_out *o, size_t n, const double *pts, const double *val, const double *grad,
                       const unsigned char *inside)
{
    int cols = o->nc * (o->gradient ? 4 : 1);
    for (size_t i = 0; i < n; i++) {
        fprintf(o->f, "%.17g,%.17g,%.17g", pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
        for (int k = 0; k < cols; k++) {
            if (!inside[i]) {
                fputc(',', o->f);
                continue;
            }
            double v = k < o->nc ? val[i * (size_t)o->nc + (size_t)k]
                                 : grad[i * 3 * (size_t)o->nc + (size_t)(k - o->nc)];
            fprintf(o->f, ",%.17g", v);
        }
        fputc('\n', o->f);
    }
}

/* Reads the points file, evaluating and writing in batches. */
static int run(const sl_dataset *ds, const char *points_path, FILE *in, const probe_out *o, sl_probe_gpu *gpu)
{
    static double pts[3 * BATCH], val[SL_PROBE_MAX_COMPONENTS * BATCH], grad[9 * BATCH];
    static unsigned char inside[BATCH];
    char line[LINE_MAX_BYTES];
    size_t n = 0, lineno = 0;
    int seen_data = 0;
    sl_err err = {0};
    write_header(o);
    for (;;) {
        int eof = !fgets(line, sizeof line, in);
        if (!eof) {
            lineno++;
            size_t len = strlen(line);
            if (len == sizeof line - 1 && line[len - 1] != '\n' && !feof(in)) {
                fprintf(stderr, "sightline-probe: %s:%zu: line longer than %d bytes\n", points_path, lineno,
                        LINE_MAX_BYTES - 2);
                return EXIT_BAD_INPUT;
            }
            char *hash = strchr(line, '#');
            if (hash)
                *hash = '\0';
            if (blank(line))
                continue;
            const char *f[4];
            size_t fl[4];
            int nf = split(line, f, fl, 4);
            double xyz[3];
            int ok = nf == 3;
            for (int k = 0; k < 3 && ok; k++)
                ok = parse_field(f[k], fl[k], &xyz[k]);
            if (!ok) {
                double first;
                if (!seen_data && !parse_field(f[0], fl[0], &first)) {
                    seen_data = 1; /* the header line */
                    continue;
                }
                line[strcspn(line, "\r\n")] = '\0';
                fprintf(stderr, "sightline-probe: %s:%zu: expected three finite numbers x,y,z, found \"%.80s\"\n",
                        points_path, lineno, line);
                return EXIT_BAD_INPUT;
            }
            seen_data = 1;
            memcpy(pts + 3 * n, xyz, sizeof xyz);
            n++;
        }
        if (n == BATCH || (eof && n > 0)) {
            sl_status st = evaluate(ds, gpu, n, pts, val, o->gradient ? grad : NULL, inside, &err);
            if (st != SL_OK) {
                fprintf(stderr, "sightline-probe: %s\n", err.message);
                return st == SL_ERR_GPU ? EXIT_GPU : EXIT_BAD_INPUT;
            }
            write_rows(o, n, pts, val, grad, inside);
            n = 0;
        }
        if (eof)
            break;
    }
    if (ferror(in)) {
        fprintf(stderr, "sightline-probe: %s: read error\n", points_path);
        return EXIT_BAD_INPUT;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *source = NULL, *points = NULL, *out_path = NULL;
    int gradient = 0, use_gpu = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--points") == 0 && i + 1 < argc) {
            points = argv[++i];
        } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out_path = argv[++i];
        } else if (strcmp(argv[i], "--gradient") == 0) {
            gradient = 1;
        } else if (strcmp(argv[i], "--gpu") == 0) {
            use_gpu = 1;
        } else if (argv[i][0] == '-' && argv[i][1] == '-') {
            fprintf(stderr, "sightline-probe: unknown option or missing value: %s\n", argv[i]);
            usage(stderr);
            return EXIT_USAGE;
        } else if (!source) {
            source = argv[i];
        } else {
            fprintf(stderr, "sightline-probe: more than one dataset given (%s)\n", argv[i]);
            usage(stderr);
            return EXIT_USAGE;
        }
    }
    if (!source || !points) {
        usage(stderr);
        return EXIT_USAGE;
    }
    sl_dataset *ds = NULL;
    sl_err err = {0};
    if (sl_dataset_open(source, NULL, &ds, &err) != SL_OK) {
        fprintf(stderr, "sightline-probe: %s\n", err.message);
        return EXIT_BAD_INPUT;
    }
    int rc = EXIT_BAD_INPUT;
    FILE *in = NULL, *out = NULL;
    sl_gpu *gpu = NULL;
    sl_probe_gpu *probe = NULL;
    probe_out o = {.nc = sl_probe_components(ds), .gradient = gradient};
    if (o.nc == 0) {
        fprintf(stderr, "sightline-probe: %s is a %s dataset: it has no field to probe (volumes, vector fields"
                        " and LR-spline volumes do)\n", source, sl_dataset_kind_name(ds->kind));
        goto done;
    }
    if (use_gpu) {
        if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
            fprintf(stderr, "sightline-probe: --gpu: %s\n", err.message);
            rc = EXIT_GPU;
            goto done;
        }
        sl_status st = sl_probe_gpu_create(ds, gradient, &probe, &err);
        if (st != SL_OK) {
            fprintf(stderr, "sightline-probe: %s\n", err.message);
            rc = st == SL_ERR_UNSUPPORTED ? EXIT_BAD_INPUT : EXIT_GPU;
            goto done;
        }
    }
    in = strcmp(points, "-") == 0 ? stdin : fopen(points, "r");
    if (!in) {
        fprintf(stderr, "sightline-probe: cannot open %s: %s\n", points, strerror(errno));
        goto done;
    }
    out = out_path ? fopen(out_path, "w") : stdout;
    if (!out) {
        fprintf(stderr, "sightline-probe: cannot write %s: %s\n", out_path, strerror(errno));
        goto done;
    }
    o.f = out;
    rc = run(ds, points, in, &o, probe);
    if (fflush(out) != 0 || ferror(out)) {
        fprintf(stderr, "sightline-probe: write error on %s\n", out_path ? out_path : "stdout");
        rc = EXIT_BAD_INPUT;
    }
done:
    if (in && in != stdin)
        fclose(in);
    if (out && out != stdout && fclose(out) != 0 && rc == 0) {
        fprintf(stderr, "sightline-probe: write error on %s\n", out_path);
        rc = EXIT_BAD_INPUT;
    }
    sl_probe_gpu_destroy(probe);
    sl_gpu_destroy(gpu);
    sl_dataset_destroy(ds);
    return rc;
}
