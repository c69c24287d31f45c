/* flow-check — the helper of tests/render/flow.cmake (sightline-trace).
 *   flow-check write-helix DIR   writes DIR/helix.nrrd (the rotation field
 *       v = (-y, x, 0.5) at 17x17x9 voxel centres on [-2,2]^2 x [-1,3], f32
 *       values exact, so trilinear is exact) and DIR/seeds.csv (2 seeds,
 *       with a header line).
 *   flow-check verify L.csv LINES T_MAX TOL   the CSV has the header
 *       line,t,x,y,z,vx,vy,vz, lines 0..LINES-1 in order with times rising
 *       from 0 to T_MAX, every position within TOL of the exact helix from
 *       the line's first sample, every velocity = (-y, x, 0.5) to 1e-9.
 *   flow-check verify-exp L.csv LINES TOL   the identity field v(x) = x on
 *       [0,1]^3 (tests/data/lr/refined_quadratic.lr.gz): lines 0..LINES-1,
 *       times rising from 0, every position within TOL of the exact
 *       x0 e^t, every velocity = its position to TOL, each line's last
 *       sample on the face x_c = 1 of its largest coordinate (to TOL).
 *   flow-check compare A.csv B.csv BOUND [SIDE]   same rows and line ids;
 *       max |x_a - x_b| / SIDE (the box side, default 4) <= BOUND.
 * Exit 0 and "pass" on success, 1 and "check failed: ..." otherwise.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct csv_row { long line; double v[7]; } csv_row;

static csv_row *read_csv(const char *path, size_t *n, int *header_ok)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    char buf[1024];
    *header_ok = fgets(buf, sizeof buf, f) && strcmp(buf, "line,t,x,y,z,vx,vy,vz\n") == 0;
    size_t cap = 1024;
    csv_row *r = malloc(cap * sizeof *r);
    *n = 0;
    while (r && fgets(buf, sizeof buf, f)) {
        if (*n == cap) {
            csv_row *nr = realloc(r, 2 * cap * sizeof *r);
            if (!nr)
                break;
            r = nr;
            cap *= 2;
        }
        csv_row *x = &r[*n];
        if (sscanf(buf, "%ld,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &x->line, &x->v[0], &x->v[1], &x->v[2], &x->v[3],
                   &x->v[4], &x->v[5], &x->v[6]) != 8) {
            *header_ok = 0;
            break;
        }
        (*n)++;
    }
    fclose(f);
    return r;
}

static int fail(const char *msg)
{
    printf("check failed: %s\n", msg);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "write-helix") == 0) {
        char path[1024];
        snprintf(path, sizeof path, "%s/helix.nrrd", argv[2]);
        FILE *f = fopen(path, "wb");
        if (!f)
            return fail("cannot write helix.nrrd");
        fprintf(f, "NRRD0004\ntype: float\ndimension: 4\nsizes: 3 17 17 9\nspace dimension: 3\n"
                   "space directions: none (0.25,0,0) (0,0.25,0) (0,0,0.5)\nspace origin: (-2,-2,-1)\n"
                   "endian: little\nencoding: raw\n\n");
        for (int k = 0; k < 9; k++)
            for (int j = 0; j < 17; j++)
                for (int i = 0; i < 17; i++) {
                    float v[3] = {-(float)(-2 + 0.25 * j), (float)(-2 + 0.25 * i), 0.5f};
                    fwrite(v, sizeof v, 1, f);
                }
        fclose(f);
        snprintf(path, sizeof path, "%s/seeds.csv", argv[2]);
        f = fopen(path, "w");
        if (!f)
            return fail("cannot write seeds.csv");
        fprintf(f, "x,y,z\n1,0.3,0\n-0.5,1.2,1\n");
        fclose(f);
        printf("pass\n");
        return 0;
    }
    if (argc == 6 && strcmp(argv[1], "verify") == 0) {
        size_t n;
        int header;
        csv_row *r = read_csv(argv[2], &n, &header);
        long lines = atol(argv[3]);
        double t_max = atof(argv[4]), tol = atof(argv[5]), worst = 0;
        if (!r || !header || n == 0)
            return fail("missing rows or header line,t,x,y,z,vx,vy,vz");
        long expect = 0;
        size_t first = 0;
        for (size_t i = 0; i < n; i++) {
            if (i == 0 || r[i].line != r[i - 1].line) {
                if (r[i].line != expect++ || r[i].v[0] != 0)
                    return fail("line ids not 0..N-1 in order, or a line not starting at t = 0");
                if (i > 0 && r[i - 1].v[0] != t_max)
                    return fail("a line does not end at t_max");
                first = i;
            } else if (!(r[i].v[0] > r[i - 1].v[0])) {
                return fail("times do not rise");
            }
            const double *s = r[first].v + 1, t = r[i].v[0];
            double ex[3] = {cos(t) * s[0] - sin(t) * s[1], sin(t) * s[0] + cos(t) * s[1], s[2] + 0.5 * t};
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(ex[c] - r[i].v[1 + c]));
            const double *x = r[i].v + 1, *v = r[i].v + 4;
            if (fabs(v[0] + x[1]) > 1e-9 || fabs(v[1] - x[0]) > 1e-9 || fabs(v[2] - 0.5) > 1e-9)
                return fail("a velocity is not the field at its position");
        }
        if (r[n - 1].v[0] != t_max)
            return fail("the last line does not end at t_max");
        if (expect != lines)
            return fail("wrong number of lines");
        free(r);
        printf("max error against the exact helix %.3g (bound %g)\n", worst, tol);
        if (!(worst <= tol))
            return fail("error above the bound");
        printf("pass\n");
        return 0;
    }
    if (argc == 5 && strcmp(argv[1], "verify-exp") == 0) {
        size_t n;
        int header;
        csv_row *r = read_csv(argv[2], &n, &header);
        long lines = atol(argv[3]);
        double tol = atof(argv[4]), worst = 0;
        if (!r || !header || n == 0)
            return fail("missing rows or header line,t,x,y,z,vx,vy,vz");
        long expect = 0;
        size_t first = 0;
        for (size_t i = 0; i <= n; i++) {
            if (i == n || i == 0 || r[i].line != r[i - 1].line) {
                if (i > 0) { /* the previous line ends on a face x_c = 1 */
                    const double *x = r[i - 1].v + 1;
                    double m = fmax(fmax(x[0], x[1]), x[2]);
                    if (!(fabs(m - 1.0) <= tol))
                        return fail("a line does not end on the face x_c = 1");
                }
                if (i == n)
                    break;
                if (r[i].line != expect++ || r[i].v[0] != 0)
                    return fail("line ids not 0..N-1 in order, or a line not starting at t = 0");
                first = i;
            } else if (!(r[i].v[0] > r[i - 1].v[0])) {
                return fail("times do not rise");
            }
            const double *s = r[first].v + 1, t = r[i].v[0], *x = r[i].v + 1, *v = r[i].v + 4;
            for (int c = 0; c < 3; c++) {
                worst = fmax(worst, fabs(s[c] * exp(t) - x[c]));
                if (!(fabs(v[c] - x[c]) <= tol))
                    return fail("a velocity is not the field (= the position) at its position");
            }
        }
        free(r);
        if (expect != lines)
            return fail("wrong number of lines");
        printf("max error against the exact x0 e^t %.3g (bound %g)\n", worst, tol);
        if (!(worst <= tol))
            return fail("error above the bound");
        printf("pass\n");
        return 0;
    }
    if ((argc == 5 || argc == 6) && strcmp(argv[1], "compare") == 0) {
        size_t na, nb;
        int ha, hb;
        csv_row *a = read_csv(argv[2], &na, &ha), *b = read_csv(argv[3], &nb, &hb);
        double bound = atof(argv[4]), side = argc == 6 ? atof(argv[5]) : 4.0, worst = 0;
        if (!(side > 0))
            return fail("the box side must be positive");
        if (!a || !b || !ha || !hb || na != nb)
            return fail("the two files differ in rows or headers");
        for (size_t i = 0; i < na; i++) {
            if (a[i].line != b[i].line)
                return fail("line ids differ");
            for (int c = 1; c < 4; c++)
                worst = fmax(worst, fabs(a[i].v[c] - b[i].v[c]) / side);
        }
        free(a);
        free(b);
        printf("max relative difference %.3g (bound %g)\n", worst, bound);
        if (!(worst <= bound))
            return fail("difference above the bound");
        printf("pass\n");
        return 0;
    }
    fprintf(stderr, "usage: flow-check write-helix DIR | verify L.csv LINES T_MAX TOL | verify-exp L.csv LINES TOL | compare A B BOUND [SIDE]\n");
    return 2;
}
