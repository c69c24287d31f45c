/* test_probe.c — field evaluation at points (renderer/probe/sl_probe.h) and
 * the sightline-probe tool (run as a process from SIGHTLINE_BINARY_DIR).
 *
 * References, sharing no code with probe_cpu.c: trilinear values by a lerp
 * cascade (x, then y, then z) over the voxels around the point, to 1e-12;
 * gradients and Jacobians by central differences of that cascade inside one
 * cell (exact for a trilinear cell up to rounding, bound 1e-7); an
 * LR-spline tensor file (orders 2, 3, 4, uneven knots) whose Greville
 * coefficients reproduce f = x + 2y - z exactly, to 1e-12 in value and
 * (1, 2, -1) in gradient. Also: the domain edges (closed upper face, a
 * one-voxel slab, outside -> empty CSV fields), a NaN neighbour, a line
 * set refused, bad CSV lines refused with their line number. The tool's
 * --gpu against its CPU path on the files of tests/data/lr/ (with
 * gradients) and marschner_lobb (values): the same rows and empty fields,
 * within 1e-5 of the value range; --gpu --gradient on a volume exits 2.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "data/sl_dataset.h"
#include "lr_test_text.h"
#include "probe/sl_probe.h"
#include "sl_test.h"

static char tmpdir[256];

static const char *tmp(const char *name)
{
    static char path[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(path[k], sizeof path[k], "%s/%s", tmpdir, name);
    return path[k];
}

static void write_all(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n) {
        perror(path);
        exit(2);
    }
    fclose(f);
}

static double frand(void) { return rand() / (double)RAND_MAX; }

/* ---- regular volumes ---- */

static double voxel_value(int i, int j, int k, int c) { return sin(0.7 * i + 1.3 * j - 0.4 * k + c) * 3 + c; }

static sl_dataset *make_volume(const int dims[3], int nc, const double spacing[3], const double origin[3])
{
    sl_err err = {0};
    sl_dataset *ds = sl_dataset_create(nc == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, "v");
    if (!ds || sl_volume_alloc(&ds->volume, dims, nc, SL_VOXEL_F32, &err) != SL_OK)
        exit(2);
    float *d = ds->volume.data;
    for (int k = 0; k < dims[2]; k++)
        for (int j = 0; j < dims[1]; j++)
            for (int i = 0; i < dims[0]; i++)
                for (int c = 0; c < nc; c++)
                    d[(((size_t)k * dims[1] + j) * dims[0] + i) * nc + c] = (float)voxel_value(i, j, k, c);
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = spacing[a];
    ds->origin = sl_v3(origin[0], origin[1], origin[2]);
    if (sl_dataset_finish_volume(ds, &err) != SL_OK)
        exit(2);
    return ds;
}

static double stored(const sl_dataset *ds, int i, int j, int k, int c)
{
    const sl_volume *v = &ds->volume;
    return ((const float *)v->data)[(((size_t)k * v->dims[1] + j) * v->dims[0] + i) * v->components + c];
}

/* The lerp cascade at world p (inside the closed box of voxel centres). */
static double cascade(const sl_dataset *ds, const double p[3], int c)
{
    const sl_volume *v = &ds->volume;
    const double o[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    int i0[3];
    double t[3];
    for (int a = 0; a < 3; a++) {
        double u = (p[a] - o[a]) / v->spacing[a];
        if (v->dims[a] == 1) {
            i0[a] = 0;
            t[a] = 0;
            continue;
        }
        i0[a] = (int)floor(u);
        if (i0[a] > v->dims[a] - 2)
            i0[a] = v->dims[a] - 2;
        t[a] = u - i0[a];
    }
    int i1[3];
    for (int a = 0; a < 3; a++)
        i1[a] = v->dims[a] == 1 ? 0 : i0[a] + 1;
    double z[2];
    for (int kk = 0; kk < 2; kk++) {
        int k = kk ? i1[2] : i0[2];
        double y[2];
        for (int jj = 0; jj < 2; jj++) {
            int j = jj ? i1[1] : i0[1];
            double a = stored(ds, i0[0], j, k, c), b = stored(ds, i1[0], j, k, c);
            y[jj] = a + t[0] * (b - a);
        }
        z[kk] = y[0] + t[1] * (y[1] - y[0]);
    }
    return z[0] + t[2] * (z[1] - z[0]);
}

static void check_volume(int nc)
{
    const int dims[3] = {4, 3, 5};
    const double spacing[3] = {0.5, 2.0, 1.25}, origin[3] = {1.0, -3.0, 0.25};
    sl_dataset *ds = make_volume(dims, nc, spacing, origin);
    sl_err err = {0};
    double worst_v = 0, worst_g = 0;
    for (int s = 0; s < 3000; s++) {
        /* Inside one cell, away from its faces, so p +- h stays in it. */
        double p[3];
        for (int a = 0; a < 3; a++) {
            int cell = rand() % (dims[a] - 1);
            p[a] = origin[a] + spacing[a] * (cell + 0.01 + 0.98 * frand());
        }
        double v[3], g[9];
        int in = 0;
        SL_CHECK(sl_probe_eval(ds, p, v, g, &in, &err) == SL_OK && in);
        for (int c = 0; c < nc; c++) {
            worst_v = fmax(worst_v, fabs(v[c] - cascade(ds, p, c)));
            for (int a = 0; a < 3; a++) {
                double h = 1e-5 * spacing[a], q[3] = {p[0], p[1], p[2]}, r[3] = {p[0], p[1], p[2]};
                q[a] += h;
                r[a] -= h;
                double fd = (cascade(ds, q, c) - cascade(ds, r, c)) / (2 * h);
                worst_g = fmax(worst_g, fabs(g[c * 3 + a] - fd));
            }
        }
    }
    SL_CHECK_MSG(worst_v <= 1e-12, "components %d: value off by %.3g", nc, worst_v);
    SL_CHECK_MSG(worst_g <= 1e-7, "components %d: gradient off by %.3g", nc, worst_g);
    /* Voxel centres and the closed upper corner give the voxel values. */
    double corner[3] = {origin[0] + 3 * 0.5, origin[1] + 2 * 2.0, origin[2] + 4 * 1.25}, v[3];
    int in = 0;
    SL_CHECK(sl_probe_eval(ds, corner, v, NULL, &in, &err) == SL_OK && in);
    SL_CHECK(in && v[nc - 1] == stored(ds, 3, 2, 4, nc - 1));
    double mid[3] = {origin[0] + 0.5, origin[1] + 2.0, origin[2]};
    SL_CHECK(sl_probe_eval(ds, mid, v, NULL, &in, &err) == SL_OK && in && v[0] == stored(ds, 1, 1, 0, 0));
    /* Just outside each face. */
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            double p[3] = {origin[0] + 0.7, origin[1] + 1.1, origin[2] + 2.0};
            p[a] = side ? corner[a] + 1e-9 : origin[a] - 1e-9;
            in = 1;
            SL_CHECK(sl_probe_eval(ds, p, v, NULL, &in, &err) == SL_OK && in == 0);
        }
    double nan_p[3] = {NAN, 0, 0};
    in = 1;
    SL_CHECK(sl_probe_eval(ds, nan_p, v, NULL, &in, &err) == SL_OK && in == 0);
    sl_dataset_destroy(ds);
}

static void test_volume_edges(void)
{
    /* One voxel along z: a slab one spacing thick, constant across it. */
    const int dims[3] = {3, 2, 1};
    const double spacing[3] = {1, 1, 2}, origin[3] = {0, 0, 10};
    sl_dataset *ds = make_volume(dims, 1, spacing, origin);
    sl_err err = {0};
    double v, g[3];
    int in = 0;
    double p[3] = {1.5, 0.25, 10.9};
    SL_CHECK(sl_probe_eval(ds, p, &v, g, &in, &err) == SL_OK && in);
    SL_CHECK_NEAR(v, cascade(ds, p, 0), 1e-12);
    SL_CHECK(g[2] == 0.0);
    p[2] = 11.01;
    SL_CHECK(sl_probe_eval(ds, p, &v, g, &in, &err) == SL_OK && in == 0);
    /* A NaN voxel does not reach a probe on its neighbour. */
    ((float *)ds->volume.data)[1] = NAN;
    double on0[3] = {0, 0, 10}, cell[3] = {0.5, 0, 10};
    SL_CHECK(sl_probe_eval(ds, on0, &v, NULL, &in, &err) == SL_OK && in && v == stored(ds, 0, 0, 0, 0));
    SL_CHECK(sl_probe_eval(ds, cell, &v, NULL, &in, &err) == SL_OK && in && isnan(v));
    sl_dataset_destroy(ds);
    sl_dataset *lines = sl_dataset_create(SL_DATASET_LINES, "l");
    SL_CHECK(sl_probe_components(lines) == 0);
    SL_CHECK(sl_probe_eval(lines, p, &v, NULL, &in, &err) == SL_ERR_UNSUPPORTED && strstr(err.message, "no field"));
    sl_dataset_destroy(lines);
}

/* ---- the tool ---- */

static int run(const char *cmd, char **out)
{
    FILE *p = popen(cmd, "r");
    *out = NULL;
    if (!p)
        return -1;
    size_t cap = 1 << 20, len = 0, got;
    char *buf = malloc(cap);
    while ((got = fread(buf + len, 1, cap - 1 - len, p)) > 0)
        len += got;
    buf[len] = '\0';
    *out = buf;
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static const char *bin_dir(void)
{
    const char *b = getenv("SIGHTLINE_BINARY_DIR");
    return b ? b : "build";
}

/* Parses "x,y,z,f..." rows (after the header) into rows[n][cols]; empty fields become NAN and flag[n] = 1. */
static int parse_rows(char *text, int cols, double rows[][16], int *empty, int max)
{
    int n = 0;
    char *line = strtok(text, "\n");
    if (!line)
        return 0;
    while ((line = strtok(NULL, "\n")) && n < max) {
        int k = 0;
        empty[n] = 0;
        char *p = line;
        while (k < cols) {
            char *c = strchr(p, ',');
            if (c)
                *c = '\0';
            if (*p == '\0') {
                rows[n][k] = NAN;
                empty[n] = 1;
            } else {
                rows[n][k] = strtod(p, NULL);
            }
            k++;
            if (!c)
                break;
            p = c + 1;
        }
        if (k != cols)
            return -1;
        n++;
    }
    return n;
}

static void lr_linear_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)ijk;
    coef[0] = g[0] + 2 * g[1] - g[2];
}

static void test_tool_lr(void)
{
    const double ku[] = {0, 0, 0.4, 1, 1};                   /* order 2 */
    const double kv[] = {-1, -1, -1, 0, 2, 2, 2};            /* order 3 */
    const double kw[] = {0, 0, 0, 0, 0.5, 3, 3, 3, 3};       /* order 4 */
    const double *knots[3] = {ku, kv, kw};
    const int order[3] = {2, 3, 4}, count[3] = {5, 7, 9};
    char *text = lr_text_tensor(order, 1, knots, count, lr_linear_coef, NULL);
    const char *lr_path = tmp("plane.lr");
    write_all(lr_path, text, strlen(text));
    free(text);
    char csv[8192];
    int n = snprintf(csv, sizeof csv, "# probe points\nx, y, z\n\n");
    double pts[64][3];
    int np = 0;
    for (; np < 60; np++) {
        pts[np][0] = frand();
        pts[np][1] = -1 + 3 * frand();
        pts[np][2] = 3 * frand();
    }
    const double special[3][3] = {{1, 2, 3}, {0.4, 0, 0.5}, {1.0000001, 0, 0}}; /* corner, knot planes, outside */
    for (int s = 0; s < 3; s++, np++)
        memcpy(pts[np], special[s], sizeof pts[np]);
    for (int i = 0; i < np; i++)
        n += snprintf(csv + n, sizeof csv - (size_t)n, "%.17g,%.17g,%.17g%s\n", pts[i][0], pts[i][1], pts[i][2],
                      i == 5 ? "  # trailing comment" : "");
    const char *pts_path = tmp("points.csv");
    write_all(pts_path, csv, (size_t)n);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' '%s' --points '%s' --gradient 2>&1", bin_dir(), lr_path,
             pts_path);
    char *out = NULL;
    int rc = run(cmd, &out);
    SL_CHECK_MSG(rc == 0, "sightline-probe (LR) exit %d: %.300s", rc, out ? out : "");
    SL_CHECK(out && strncmp(out, "x,y,z,value,gx,gy,gz\n", 21) == 0);
    static double rows[128][16];
    int empty[128];
    int got = out ? parse_rows(out, 7, rows, empty, 128) : 0;
    SL_CHECK_MSG(got == np, "%d rows for %d points", got, np);
    double worst_v = 0, worst_g = 0;
    for (int i = 0; i < got && i < np; i++) {
        SL_CHECK(rows[i][0] == pts[i][0] && rows[i][1] == pts[i][1] && rows[i][2] == pts[i][2]);
        if (i == np - 1) {
            SL_CHECK_MSG(empty[i], "the point outside the domain has a value");
            continue;
        }
        SL_CHECK(!empty[i]);
        double want = pts[i][0] + 2 * pts[i][1] - pts[i][2];
        worst_v = fmax(worst_v, fabs(rows[i][3] - want));
        worst_g = fmax(worst_g, fmax(fabs(rows[i][4] - 1), fmax(fabs(rows[i][5] - 2), fabs(rows[i][6] + 1))));
    }
    SL_CHECK_MSG(worst_v <= 1e-12 && worst_g <= 1e-11, "x+2y-z: value off by %.3g, gradient by %.3g", worst_v,
                 worst_g);
    free(out);

    /* Bad CSV lines name their line. */
    const char *bad[] = {"x,y,z\n0,0,0\n1,2\n", "0,0,0\n\n1,2,abc\n", "0,0,0\n1,2,3,4\n", "x,y,z\nx,y,z\n",
                         "0,0,0\n1,inf,0\n"};
    const int bad_line[] = {3, 3, 2, 2, 2};
    for (int b = 0; b < 5; b++) {
        const char *bp = tmp("bad.csv");
        write_all(bp, bad[b], strlen(bad[b]));
        snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' '%s' --points '%s' 2>&1 >/dev/null", bin_dir(), lr_path,
                 bp);
        rc = run(cmd, &out);
        char want[64];
        snprintf(want, sizeof want, "bad.csv:%d:", bad_line[b]);
        SL_CHECK_MSG(rc == 2 && out && strstr(out, want), "bad csv %d: exit %d, %s", b, rc, out ? out : "");
        free(out);
    }
    snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' tornado --points '%s' 2>&1 >/dev/null", bin_dir(), pts_path);
    rc = run(cmd, &out);
    SL_CHECK_MSG(rc == 2 && out && strstr(out, "no field"), "lines dataset: exit %d, %s", rc, out ? out : "");
    free(out);
    snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' '%s' 2>&1 >/dev/null", bin_dir(), lr_path);
    rc = run(cmd, &out);
    SL_CHECK_MSG(rc == 1, "no --points: exit %d", rc);
    free(out);
}

static void test_tool_volume(void)
{
    /* A raw f32 vector field with a JSON sidecar, probed with --gradient into --out. */
    const int dims[3] = {3, 4, 2};
    const double spacing[3] = {0.5, 1.5, 2}, origin[3] = {-1, 2, 0};
    sl_dataset *ref = make_volume(dims, 3, spacing, origin);
    write_all(tmp("field.raw"), ref->volume.data, (size_t)3 * 4 * 2 * 3 * sizeof(float));
    const char *json = "{\"raw\": \"field.raw\", \"dims\": [3, 4, 2], \"type\": \"f32\", \"components\": 3,"
                       " \"spacing\": [0.5, 1.5, 2], \"origin\": [-1, 2, 0]}";
    const char *jpath = tmp("field.json");
    write_all(jpath, json, strlen(json));
    char csv[4096];
    int n = 0;
    double pts[40][3];
    for (int i = 0; i < 40; i++) {
        pts[i][0] = -1 + 1.0 * frand();
        pts[i][1] = 2 + 4.5 * frand();
        pts[i][2] = 2 * frand();
        if (i == 0) { /* a voxel and the upper corner */
            pts[i][0] = -0.5;
            pts[i][1] = 3.5;
            pts[i][2] = 2;
        }
        n += snprintf(csv + n, sizeof csv - (size_t)n, "%.17g,%.17g,%.17g\n", pts[i][0], pts[i][1], pts[i][2]);
    }
    write_all(tmp("vpts.csv"), csv, (size_t)n);
    const char *out_path = tmp("vout.csv");
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' '%s' --points '%s' --gradient --out '%s' 2>&1", bin_dir(),
             jpath, tmp("vpts.csv"), out_path);
    char *out = NULL;
    int rc = run(cmd, &out);
    SL_CHECK_MSG(rc == 0, "sightline-probe (vectors) exit %d: %s", rc, out ? out : "");
    free(out);
    FILE *f = fopen(out_path, "r");
    static char text[1 << 16];
    size_t len = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[len] = '\0';
    if (f)
        fclose(f);
    SL_CHECK(strncmp(text, "x,y,z,vx,vy,vz,dvx_dx,dvx_dy,dvx_dz,dvy_dx", 42) == 0);
    static double rows[64][16];
    int empty[64];
    int got = parse_rows(text, 15, rows, empty, 64);
    SL_CHECK_MSG(got == 40, "%d rows", got);
    double worst = 0;
    for (int i = 0; i < got; i++)
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(rows[i][3 + c] - cascade(ref, pts[i], c)));
    SL_CHECK_MSG(worst <= 1e-12, "vector field through the tool: off by %.3g", worst);
    SL_CHECK(rows[0][3] == stored(ref, 1, 1, 1, 0) && rows[0][5] == stored(ref, 1, 1, 1, 2));
    sl_dataset_destroy(ref);
}

/* --gpu against the CPU path through the tool: the same rows, the same
 * empty fields, values and gradients within 1e-5 (test_probe_gpu.c checks
 * the library in depth). On the LR test files; a regular volume's values
 * too, and its gradient on the GPU refused with exit 2. */
static void compare_tool_gpu(const char *dataset, const char *pts_path, int cols, const char *opts, double bound)
{
    char cmd[2048];
    char *out[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' '%s' --points '%s' %s%s 2>&1", bin_dir(), dataset,
                 pts_path, opts, k ? " --gpu" : "");
        int rc = run(cmd, &out[k]);
        SL_CHECK_MSG(rc == 0, "sightline-probe %s%s: exit %d: %.300s", dataset, k ? " --gpu" : "", rc,
                     out[k] ? out[k] : "");
    }
    if (out[0] && out[1]) {
        SL_CHECK_MSG(strcspn(out[0], "\n") == strcspn(out[1], "\n") &&
                         strncmp(out[0], out[1], strcspn(out[0], "\n")) == 0, "%s: headers differ", dataset);
        static double rows[2][256][16];
        int empty[2][256];
        int n0 = parse_rows(out[0], cols, rows[0], empty[0], 256), n1 = parse_rows(out[1], cols, rows[1], empty[1], 256);
        SL_CHECK_MSG(n0 == n1 && n0 > 0, "%s: %d CPU rows, %d GPU rows", dataset, n0, n1);
        double worst = 0.0;
        int empties = 0, same = 1;
        for (int i = 0; i < n0 && i < n1; i++) {
            same &= empty[0][i] == empty[1][i] && rows[0][i][0] == rows[1][i][0] && rows[0][i][1] == rows[1][i][1] &&
                    rows[0][i][2] == rows[1][i][2];
            empties += empty[0][i];
            for (int c = 3; c < cols && !empty[0][i]; c++)
                worst = fmax(worst, fabs(rows[0][i][c] - rows[1][i][c]));
        }
        SL_CHECK_MSG(same, "%s: the points or their empty fields differ between the paths", dataset);
        SL_CHECK_MSG(empties > 0, "%s: no point outside", dataset);
        SL_CHECK_MSG(worst <= bound, "%s: --gpu differs by %.3g > %.0e", dataset, worst, bound);
        printf("sightline-probe %s --gpu: max difference %.3g over %d rows (%d outside)\n", dataset, worst, n0,
               empties);
    }
    free(out[0]);
    free(out[1]);
}

static void test_tool_gpu(void)
{
    /* Points in [-0.25, 1.25]^3 on a 1/16 lattice (the knot planes of
     * refined_quadratic), random ones, and some outside both files' domains. */
    char csv[16384];
    int n = 0;
    for (int i = 0; i < 200; i++) {
        double p[3];
        for (int d = 0; d < 3; d++)
            p[d] = i % 2 ? -0.25 + 1.5 * frand() : floor(frand() * 20.0 - 2.0) / 16.0;
        n += snprintf(csv + n, sizeof csv - (size_t)n, "%.17g,%.17g,%.17g\n", p[0], p[1], p[2]);
    }
    const char *pts_path = tmp("gpts.csv");
    write_all(pts_path, csv, (size_t)n);
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/data/lr/refined_quadratic.lr.gz", src ? src : ".");
    compare_tool_gpu(path, pts_path, 15, "--gradient", 1e-5);  /* identity map: value range and Jacobian 1 */
    snprintf(path, sizeof path, "%s/tests/data/lr/two_lines.lr", src ? src : ".");
    compare_tool_gpu(path, pts_path, 7, "--gradient", 4e-5);   /* value range 4: 1e-5 of it */
    /* marschner_lobb on [-1, 1]^3, values in [0, 1]: the points cover part of it. */
    compare_tool_gpu("marschner_lobb", pts_path, 4, "", 1e-5);
    char cmd[2048];
    char *out = NULL;
    snprintf(cmd, sizeof cmd, "'%s/bin/sightline-probe' marschner_lobb --points '%s' --gradient --gpu 2>&1 >/dev/null",
             bin_dir(), pts_path);
    int rc = run(cmd, &out);
    SL_CHECK_MSG(rc == 2 && out && strstr(out, "gradient"), "--gpu --gradient on a volume: exit %d, %s", rc,
                 out ? out : "");
    free(out);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_probe_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    srand(7);
    check_volume(1);
    check_volume(3);
    test_volume_edges();
    test_tool_lr();
    test_tool_volume();
    test_tool_gpu();
    const char *names[] = {"plane.lr", "points.csv", "bad.csv", "field.raw", "field.json", "vpts.csv", "vout.csv",
                           "gpts.csv"};
    for (int i = 0; i < 8; i++)
        unlink(tmp(names[i]));
    rmdir(tmpdir);
    SL_TEST_END();
}
