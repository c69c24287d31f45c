/* particles_check.c — checks of `particles` on its exported particles
 * (sightline-render --export), against the independent double-precision
 * references of tests/support/particles_reference.h.
 *
 * usage: particles-check surface --dataset D --csv C --iso V [--set K] [--max-dist X] [--pct P]
 *        particles-check evenness --csv C --area A [--set K] [--max-cv X] [--ratio-lo L] [--ratio-hi H]
 *        particles-check curvature --csv C --shape sphere|ellipsoid|torus --center X,Y,Z
 *                        (--axes A,B,C | --radius R | --major R0 --minor r) [--inward] [--set K]
 *                        [--min-rho R] [--eps E] [--max-mean-rel X] [--max-p90-rel X]
 *        particles-check placement --dataset D --stats S --iso V --spacing S [--set K]
 *        particles-check count --csv C --stats S [--set K] [--min N] [--max N]
 *        particles-check depth --pfm P [--min N] [--max N]
 *        particles-check write-volume --dataset D --origin X,Y,Z --out BASE
 *        particles-check offset --dataset D --csv A --csv-b B --origin X,Y,Z [--max-pos E] [--max-normal E]
 *                        [--max-rel-k E]
 *
 * surface: for every exported particle of set K (default 0), its distance to
 *   the isosurface to first order, |f(p) - iso| / |grad f(p)| with f the
 *   trilinear field in double (pref_trilinear), in voxels (the smallest
 *   spacing). The P-th percentile (default 99) must be at most X (default
 *   0.05) and no distance may be NaN (a particle where grad f = 0 counts as
 *   infinitely far). Prints p50, p99 and max.
 * evenness: the exact nearest-neighbour distances (pref_nn) of set K: the
 *   coefficient of variation must be at most X (default 0.25) and the
 *   packing ratio n pi (mean/2)^2 / A (A the known area of the surface,
 *   world units; 0.907 for a perfect hexagonal packing) within [L, H]
 *   (default 0.6 .. 1.0). Prints both and the count A / (pi (mean/2)^2).
 * curvature: per particle the analytic principal curvatures at its nearest
 *   point of the shape (a sphere, an ellipsoid with semi-axes A,B,C, or a
 *   torus about z) centred at X,Y,Z, outward convention; --inward flips it
 *   (a dark-inside volume such as gen_torus: (k1, k2) -> (-k2, -k1)). Over
 *   the particles whose reference reliability is at least R (default 0;
 *   eps E in 1/world, default 0) the mean of max(|dk1|, |dk2|) /
 *   max(|k1_ref|, |k2_ref|) must be at most --max-mean-rel (default 0.05)
 *   and its 90th percentile at most --max-p90-rel (default: not checked).
 * placement: the seeded count in the stats (setK.seeded, with max_steps 0)
 *   must equal Algorithm 1's count on the CPU (pref_placement_count) exactly.
 * count: set K's exported rows equal setK.particles of the stats and lie in
 *   [N_min, N_max] (defaults 0 and unlimited).
 * depth: every value of the depth map (PFM, eye distance, 0 = no hit) is
 *   finite and >= 0, and the hit pixels number within [N_min, N_max].
 * write-volume: writes the scalar volume D as BASE.nhdr + BASE.raw (f32)
 *   with its voxel (0,0,0) at world X,Y,Z (the same voxels and spacing):
 *   the same data far from the world origin.
 * offset: two exports of the same voxels (--dataset D names the first), A at
 *   D's own origin, B from write-volume at X,Y,Z: row for row the same set,
 *   positions equal after subtracting each origin within E (world, default
 *   1e-5),
 *   normals within --max-normal (default 1e-6), curvatures within
 *   --max-rel-k of the largest |k| (default 1e-6): huge coordinates lose no
 *   precision (positions are stored relative to the volume's origin).
 * exit: 0 pass, 1 a limit failed, 2 bad input. Any thread, no GL.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "data/sl_dataset_open.h"
#include "image/sl_image.h"
#include "particles_reference.h"

typedef struct options {
    const char *dataset, *csv, *csv_b, *stats, *shape, *pfm, *out;
    double origin[3], max_pos, max_normal, max_rel_k;
    int have_origin;
    double iso, max_dist, pct, area, max_cv, ratio_lo, ratio_hi, spacing;
    double center[3], axes[3], radius, major, minor, min_rho, eps, max_mean_rel, max_p90_rel;
    double count_min, count_max;
    int set, inward, have_axes;
} options;

static int usage(void)
{
    fprintf(stderr,
            "usage: particles-check surface --dataset D --csv C --iso V [--set K] [--max-dist X] [--pct P]\n"
            "       particles-check evenness --csv C --area A [--set K] [--max-cv X] [--ratio-lo L] [--ratio-hi H]\n"
            "       particles-check curvature --csv C --shape sphere|ellipsoid|torus --center X,Y,Z\n"
            "                       (--axes A,B,C | --radius R | --major R0 --minor r) [--inward] [--set K]\n"
            "                       [--min-rho R] [--eps E] [--max-mean-rel X] [--max-p90-rel X]\n"
            "       particles-check placement --dataset D --stats S --iso V --spacing S [--set K]\n"
            "       particles-check count --csv C --stats S [--set K] [--min N] [--max N]\n"
            "       particles-check depth --pfm P [--min N] [--max N]\n"
            "       particles-check write-volume --dataset D --origin X,Y,Z --out BASE\n"
            "       particles-check offset --csv A --csv-b B --origin X,Y,Z [--max-pos E] [--max-normal E]\n"
            "                              [--max-rel-k E]\n");
    return 2;
}

static int parse_vec3(const char *s, double v[3])
{
    char *end = NULL;
    for (int k = 0; k < 3; k++) {
        v[k] = strtod(s, &end);
        if (end == s || (k < 2 && *end != ',') || (k == 2 && *end != '\0'))
            return -1;
        s = end + 1;
    }
    return 0;
}

static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.max_dist = 0.05, .pct = 99, .max_cv = 0.25, .ratio_lo = 0.6, .ratio_hi = 1.0,
                   .max_mean_rel = 0.05, .max_p90_rel = -1, .count_max = 1e300, .iso = NAN, .spacing = NAN,
                   .max_pos = 1e-5, .max_normal = 1e-6, .max_rel_k = 1e-6};
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--inward") == 0) {
            o->inward = 1;
            continue;
        }
        if (i + 1 >= argc)
            return -1;
        const char *v = argv[++i];
        double *num = NULL;
        if (strcmp(a, "--dataset") == 0) o->dataset = v;
        else if (strcmp(a, "--csv") == 0) o->csv = v;
        else if (strcmp(a, "--stats") == 0) o->stats = v;
        else if (strcmp(a, "--shape") == 0) o->shape = v;
        else if (strcmp(a, "--pfm") == 0) o->pfm = v;
        else if (strcmp(a, "--csv-b") == 0) o->csv_b = v;
        else if (strcmp(a, "--out") == 0) o->out = v;
        else if (strcmp(a, "--origin") == 0) { if (parse_vec3(v, o->origin)) return -1; o->have_origin = 1; }
        else if (strcmp(a, "--max-pos") == 0) num = &o->max_pos;
        else if (strcmp(a, "--max-normal") == 0) num = &o->max_normal;
        else if (strcmp(a, "--max-rel-k") == 0) num = &o->max_rel_k;
        else if (strcmp(a, "--center") == 0) { if (parse_vec3(v, o->center)) return -1; }
        else if (strcmp(a, "--axes") == 0) { if (parse_vec3(v, o->axes)) return -1; o->have_axes = 1; }
        else if (strcmp(a, "--set") == 0) o->set = atoi(v);
        else if (strcmp(a, "--iso") == 0) num = &o->iso;
        else if (strcmp(a, "--max-dist") == 0) num = &o->max_dist;
        else if (strcmp(a, "--pct") == 0) num = &o->pct;
        else if (strcmp(a, "--area") == 0) num = &o->area;
        else if (strcmp(a, "--max-cv") == 0) num = &o->max_cv;
        else if (strcmp(a, "--ratio-lo") == 0) num = &o->ratio_lo;
        else if (strcmp(a, "--ratio-hi") == 0) num = &o->ratio_hi;
        else if (strcmp(a, "--spacing") == 0) num = &o->spacing;
        else if (strcmp(a, "--radius") == 0) num = &o->radius;
        else if (strcmp(a, "--major") == 0) num = &o->major;
        else if (strcmp(a, "--minor") == 0) num = &o->minor;
        else if (strcmp(a, "--min-rho") == 0) num = &o->min_rho;
        else if (strcmp(a, "--eps") == 0) num = &o->eps;
        else if (strcmp(a, "--max-mean-rel") == 0) num = &o->max_mean_rel;
        else if (strcmp(a, "--max-p90-rel") == 0) num = &o->max_p90_rel;
        else if (strcmp(a, "--min") == 0) num = &o->count_min;
        else if (strcmp(a, "--max") == 0) num = &o->count_max;
        else return -1;
        if (num) {
            char *end = NULL;
            *num = strtod(v, &end);
            if (end == v || *end != '\0')
                return -1;
        }
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The q-th percentile (0..100) of sorted values, nearest rank. */
static double percentile(const double *sorted, size_t n, double q)
{
    size_t k = (size_t)ceil(q / 100.0 * (double)n);
    return sorted[k ? k - 1 : 0];
}

/* The rows of one set, or NULL (message printed; *n = 0 is not an error). */
static pref_csv_row *read_set(const char *path, int set, size_t *n)
{
    pref_csv_row *rows = NULL;
    size_t count = 0;
    char err[256];
    *n = 0;
    if (pref_csv_read(path, &rows, &count, err, sizeof err) != 0) {
        fprintf(stderr, "particles-check: %s: %s\n", path, err);
        return NULL;
    }
    size_t k = 0;
    for (size_t i = 0; i < count; i++)
        if (rows[i].set == set)
            rows[k++] = rows[i];
    *n = k;
    if (!rows)
        rows = malloc(sizeof *rows);
    return rows;
}

static sl_dataset *open_dataset(const char *source)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_dataset_dirs dirs = {0};
    if (sl_dataset_open(source, &dirs, &ds, &err) != SL_OK) {
        fprintf(stderr, "particles-check: dataset %s: %s\n", source, err.message);
        return NULL;
    }
    if (ds->kind != SL_DATASET_VOLUME) {
        fprintf(stderr, "particles-check: dataset %s is not a scalar volume\n", source);
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

/* setK.NAME from a --stats file, or NAN. */
static double stats_value(const char *path, int set, const char *name)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NAN;
    static char text[1 << 20];
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    cJSON *root = cJSON_Parse(text);
    char key[64];
    snprintf(key, sizeof key, "set%d.%s", set, name);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "prepare_extra"), key);
    double out = cJSON_IsNumber(v) ? v->valuedouble : NAN;
    cJSON_Delete(root);
    return out;
}

static int check_surface(const options *o)
{
    if (!o->dataset || !o->csv || isnan(o->iso))
        return usage();
    sl_dataset *ds = open_dataset(o->dataset);
    if (!ds)
        return 2;
    size_t n = 0;
    pref_csv_row *rows = read_set(o->csv, o->set, &n);
    if (!rows) {
        sl_dataset_destroy(ds);
        return 2;
    }
    const sl_volume *vol = &ds->volume;
    double min_spacing = fmin(vol->spacing[0], fmin(vol->spacing[1], vol->spacing[2]));
    const double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    double *dist = malloc((n ? n : 1) * sizeof *dist);
    size_t nan_count = 0, worst = 0;
    double worst_dist = -1.0, worst_f = 0.0, worst_g = 0.0;
    for (size_t i = 0; i < n; i++) {
        double u[3], f, g[3];
        for (int a = 0; a < 3; a++)
            u[a] = (rows[i].p[a] - origin[a]) / vol->spacing[a];
        pref_trilinear(vol, u, &f, g);
        double gl = 0.0;
        for (int a = 0; a < 3; a++)
            gl += (g[a] / vol->spacing[a]) * (g[a] / vol->spacing[a]);
        gl = sqrt(gl);
        double d = fabs(f - o->iso) / gl / min_spacing;
        if (isnan(d)) {
            nan_count++;
            d = INFINITY;
        }
        dist[i] = d;
        if (d > worst_dist) {
            worst_dist = d;
            worst = i;
            worst_f = f;
            worst_g = gl;
        }
    }
    int rc = 0;
    if (n == 0) {
        fprintf(stderr, "FAIL: set %d has no particles\n", o->set);
        rc = 1;
    } else {
        qsort(dist, n, sizeof *dist, cmp_double);
        double p50 = percentile(dist, n, 50), pq = percentile(dist, n, o->pct), max = dist[n - 1];
        printf("surface: %zu particles, distance to the surface (voxels): p50 %.3g, p%g %.3g, max %.3g\n", n, p50,
               o->pct, pq, max);
        if (nan_count) {
            fprintf(stderr, "FAIL: %zu particles where the distance is not defined (NaN value or zero gradient)\n",
                    nan_count);
            rc = 1;
        }
        if (!(pq <= o->max_dist)) {
            fprintf(stderr, "FAIL: p%g distance %.4g voxels above %.4g (farthest: %.4g voxels at %.9g, %.9g, %.9g)\n",
                    o->pct, pq, o->max_dist, worst_dist, rows[worst].p[0], rows[worst].p[1], rows[worst].p[2]);
            fprintf(stderr, "      there f - iso = %.6g, |grad f| = %.6g per world unit\n", worst_f - o->iso, worst_g);
            rc = 1;
        }
    }
    free(dist);
    free(rows);
    sl_dataset_destroy(ds);
    return rc;
}

static int check_evenness(const options *o)
{
    if (!o->csv || !(o->area > 0))
        return usage();
    size_t n = 0;
    pref_csv_row *rows = read_set(o->csv, o->set, &n);
    if (!rows)
        return 2;
    int rc = 0;
    double *xyz = malloc((n ? n : 1) * 3 * sizeof *xyz);
    for (size_t i = 0; i < n; i++)
        memcpy(xyz + 3 * i, rows[i].p, sizeof rows[i].p);
    double mean = 0, cv = 0;
    if (n < 2 || pref_nn(xyz, n, PREF_NN_AUTO, &mean, &cv, NULL) != 0) {
        fprintf(stderr, "FAIL: set %d: %zu particles, no nearest-neighbour statistics\n", o->set, n);
        rc = 1;
    } else {
        double ratio = pref_packing_ratio(n, mean, o->area);
        printf("evenness: %zu particles, mean nearest-neighbour distance %.5g, cv %.4f, packing ratio %.4f "
               "(area / (pi (mean/2)^2) = %.0f)\n",
               n, mean, cv, ratio, o->area / (M_PI * mean * mean / 4.0));
        if (!(cv <= o->max_cv)) {
            fprintf(stderr, "FAIL: nearest-neighbour cv %.4f above %.4f\n", cv, o->max_cv);
            rc = 1;
        }
        if (!(ratio >= o->ratio_lo && ratio <= o->ratio_hi)) {
            fprintf(stderr, "FAIL: packing ratio %.4f outside [%.3f, %.3f]\n", ratio, o->ratio_lo, o->ratio_hi);
            rc = 1;
        }
    }
    free(xyz);
    free(rows);
    return rc;
}

/* Reference curvatures at the nearest point of the shape to p (world,
 * relative to the centre), outward convention; -1 when undefined there. */
static int reference_curvature(const options *o, const double p[3], double *k1, double *k2)
{
    if (strcmp(o->shape, "sphere") == 0) {
        *k1 = *k2 = 1.0 / o->radius;
        return 0;
    }
    if (strcmp(o->shape, "ellipsoid") == 0) {
        double q[3];
        pref_ellipsoid_nearest(o->axes, p, q);
        return pref_ellipsoid_curvature(o->axes, q, k1, k2, NULL);
    }
    double q[3];
    pref_torus_nearest(o->major, o->minor, p, q);
    return pref_torus_curvature(o->major, o->minor, q, k1, k2, NULL, NULL);
}

static int check_curvature(const options *o)
{
    if (!o->csv || !o->shape)
        return usage();
    int sphere = strcmp(o->shape, "sphere") == 0, ellipsoid = strcmp(o->shape, "ellipsoid") == 0,
        torus = strcmp(o->shape, "torus") == 0;
    if ((!sphere && !ellipsoid && !torus) || (sphere && !(o->radius > 0)) || (ellipsoid && !o->have_axes) ||
        (torus && !(o->major > 0 && o->minor > 0)))
        return usage();
    size_t n = 0;
    pref_csv_row *rows = read_set(o->csv, o->set, &n);
    if (!rows)
        return 2;
    double *rel = malloc((n ? n : 1) * sizeof *rel);
    size_t used = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double p[3], k1r, k2r;
        for (int a = 0; a < 3; a++)
            p[a] = rows[i].p[a] - o->center[a];
        if (reference_curvature(o, p, &k1r, &k2r) != 0)
            continue;
        if (o->inward) {
            double t = k1r;
            k1r = -k2r;
            k2r = -t;
        }
        if (pref_reliability(k1r, k2r, o->eps) < o->min_rho)
            continue;
        double scale = fmax(fabs(k1r), fabs(k2r));
        double e = fmax(fabs(rows[i].k1 - k1r), fabs(rows[i].k2 - k2r)) / scale;
        rel[used++] = e;
        sum += e;
    }
    int rc = 0;
    if (used == 0) {
        fprintf(stderr, "FAIL: no particle of set %d with reference reliability >= %g\n", o->set, o->min_rho);
        rc = 1;
    } else {
        qsort(rel, used, sizeof *rel, cmp_double);
        double mean = sum / (double)used, p90 = percentile(rel, used, 90);
        printf("curvature: %zu of %zu particles compared, relative error: mean %.4f, p50 %.4f, p90 %.4f, max %.4f\n",
               used, n, mean, percentile(rel, used, 50), p90, rel[used - 1]);
        if (!(mean <= o->max_mean_rel)) {
            fprintf(stderr, "FAIL: mean relative curvature error %.4f above %.4f\n", mean, o->max_mean_rel);
            rc = 1;
        }
        if (o->max_p90_rel >= 0 && !(p90 <= o->max_p90_rel)) {
            fprintf(stderr, "FAIL: p90 relative curvature error %.4f above %.4f\n", p90, o->max_p90_rel);
            rc = 1;
        }
    }
    free(rel);
    free(rows);
    return rc;
}

static int check_placement(const options *o)
{
    if (!o->dataset || !o->stats || isnan(o->iso) || !(o->spacing > 0))
        return usage();
    double seeded = stats_value(o->stats, o->set, "seeded");
    if (isnan(seeded)) {
        fprintf(stderr, "particles-check: %s has no set%d.seeded\n", o->stats, o->set);
        return 2;
    }
    sl_dataset *ds = open_dataset(o->dataset);
    if (!ds)
        return 2;
    uint64_t want = pref_placement_count(&ds->volume, o->iso, o->spacing);
    sl_dataset_destroy(ds);
    printf("placement: GPU %.0f seeds, CPU reference %llu\n", seeded, (unsigned long long)want);
    if (seeded != (double)want) {
        fprintf(stderr, "FAIL: the GPU seeded %.0f particles, Algorithm 1 on the CPU %llu\n", seeded,
                (unsigned long long)want);
        return 1;
    }
    return 0;
}

static int check_count(const options *o)
{
    if (!o->csv || !o->stats)
        return usage();
    size_t n = 0;
    pref_csv_row *rows = read_set(o->csv, o->set, &n);
    if (!rows)
        return 2;
    free(rows);
    double particles = stats_value(o->stats, o->set, "particles");
    printf("count: set %d: %zu rows exported, %.0f particles in the stats\n", o->set, n, particles);
    if ((double)n != particles) {
        fprintf(stderr, "FAIL: %zu rows exported, the stats say %.0f particles\n", n, particles);
        return 1;
    }
    if ((double)n < o->count_min || (double)n > o->count_max) {
        fprintf(stderr, "FAIL: %zu particles outside [%.0f, %.0f]\n", n, o->count_min, o->count_max);
        return 1;
    }
    return 0;
}

static int check_depth(const options *o)
{
    if (!o->pfm)
        return usage();
    sl_depth_image img = {0};
    sl_err err = {0};
    if (sl_pfm_read(o->pfm, &img, &err) != SL_OK) {
        fprintf(stderr, "particles-check: %s: %s\n", o->pfm, err.message);
        return 2;
    }
    size_t n = (size_t)img.width * img.height, hits = 0, bad = 0;
    for (size_t i = 0; i < n; i++) {
        float v = img.values[i];
        if (!isfinite(v) || v < 0.0f)
            bad++;
        else if (v > 0.0f)
            hits++;
    }
    sl_depth_image_deinit(&img);
    printf("depth: %zu of %zu pixels hit, %zu not finite or negative\n", hits, n, bad);
    if (bad) {
        fprintf(stderr, "FAIL: %zu depth values are not finite or negative\n", bad);
        return 1;
    }
    if ((double)hits < o->count_min || (double)hits > o->count_max) {
        fprintf(stderr, "FAIL: %zu hit pixels outside [%.0f, %.0f]\n", hits, o->count_min, o->count_max);
        return 1;
    }
    return 0;
}

static int write_volume(const options *o)
{
    if (!o->dataset || !o->out || !o->have_origin)
        return usage();
    sl_dataset *ds = open_dataset(o->dataset);
    if (!ds)
        return 2;
    const sl_volume *vol = &ds->volume;
    char path[1024], raw_name[1024];
    const char *slash = strrchr(o->out, '/');
    snprintf(raw_name, sizeof raw_name, "%s.raw", slash ? slash + 1 : o->out);
    snprintf(path, sizeof path, "%s.raw", o->out);
    FILE *raw = fopen(path, "wb");
    int rc = raw ? 0 : 2;
    for (int z = 0; raw && z < vol->dims[2]; z++)
        for (int y = 0; y < vol->dims[1]; y++)
            for (int x = 0; x < vol->dims[0]; x++) {
                float v = (float)sl_volume_value(vol, (size_t)x, (size_t)y, (size_t)z, 0);
                rc |= fwrite(&v, sizeof v, 1, raw) != 1 ? 2 : 0;
            }
    if (raw && fclose(raw) != 0)
        rc = 2;
    snprintf(path, sizeof path, "%s.nhdr", o->out);
    FILE *hdr = rc ? NULL : fopen(path, "w");
    if (hdr) {
        fprintf(hdr, "NRRD0004\ntype: float\ndimension: 3\nsizes: %d %d %d\nspacings: %.17g %.17g %.17g\n"
                     "space origin: (%.17g,%.17g,%.17g)\nendian: little\nencoding: raw\ndata file: %s\n",
                vol->dims[0], vol->dims[1], vol->dims[2], vol->spacing[0], vol->spacing[1], vol->spacing[2],
                o->origin[0], o->origin[1], o->origin[2], raw_name);
        rc = fclose(hdr) != 0 ? 2 : 0;
    } else {
        rc = 2;
    }
    if (rc)
        fprintf(stderr, "particles-check: cannot write %s\n", o->out);
    else
        printf("write-volume: %s.nhdr (%d x %d x %d, origin %g, %g, %g)\n", o->out, vol->dims[0], vol->dims[1],
               vol->dims[2], o->origin[0], o->origin[1], o->origin[2]);
    sl_dataset_destroy(ds);
    return rc;
}

static int check_offset(const options *o)
{
    if (!o->csv || !o->csv_b || !o->have_origin || !o->dataset)
        return usage();
    sl_dataset *ds = open_dataset(o->dataset);
    if (!ds)
        return 2;
    const double base[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    sl_dataset_destroy(ds);
    pref_csv_row *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    char err[256];
    if (pref_csv_read(o->csv, &a, &na, err, sizeof err) != 0 || pref_csv_read(o->csv_b, &b, &nb, err, sizeof err) != 0) {
        fprintf(stderr, "particles-check: %s\n", err);
        free(a);
        return 2;
    }
    double pos = 0.0, normal = 0.0, kmax = 0.0, kdiff = 0.0;
    int rc = 0;
    if (na != nb || na == 0) {
        fprintf(stderr, "FAIL: %zu particles at the dataset's origin, %zu far away\n", na, nb);
        rc = 1;
    }
    for (size_t i = 0; !rc && i < na; i++) {
        if (a[i].set != b[i].set) {
            fprintf(stderr, "FAIL: row %zu: set %d and %d\n", i + 1, a[i].set, b[i].set);
            rc = 1;
            break;
        }
        for (int c = 0; c < 3; c++) {
            pos = fmax(pos, fabs((b[i].p[c] - o->origin[c]) - (a[i].p[c] - base[c])));
            normal = fmax(normal, fabs(b[i].n[c] - a[i].n[c]));
        }
        kmax = fmax(kmax, fmax(fabs(a[i].k1), fabs(a[i].k2)));
        kdiff = fmax(kdiff, fmax(fabs(a[i].k1 - b[i].k1), fabs(a[i].k2 - b[i].k2)));
    }
    if (!rc) {
        double krel = kmax > 0 ? kdiff / kmax : kdiff;
        printf("offset: %zu particles; position %.3g, normal %.3g, curvature %.3g of max |k|\n", na, pos, normal,
               krel);
        if (!(pos <= o->max_pos) || !(normal <= o->max_normal) || !(krel <= o->max_rel_k)) {
            fprintf(stderr, "FAIL: far from the origin the particles moved: position %.3g (max %.3g), normal %.3g "
                            "(max %.3g), curvature %.3g (max %.3g)\n",
                    pos, o->max_pos, normal, o->max_normal, krel, o->max_rel_k);
            rc = 1;
        }
    }
    free(a);
    free(b);
    return rc;
}

int main(int argc, char **argv)
{
    options o;
    if (argc < 2 || parse_options(argc, argv, &o) != 0)
        return usage();
    if (strcmp(argv[1], "surface") == 0)
        return check_surface(&o);
    if (strcmp(argv[1], "evenness") == 0)
        return check_evenness(&o);
    if (strcmp(argv[1], "curvature") == 0)
        return check_curvature(&o);
    if (strcmp(argv[1], "placement") == 0)
        return check_placement(&o);
    if (strcmp(argv[1], "count") == 0)
        return check_count(&o);
    if (strcmp(argv[1], "depth") == 0)
        return check_depth(&o);
    if (strcmp(argv[1], "write-volume") == 0)
        return write_volume(&o);
    if (strcmp(argv[1], "offset") == 0)
        return check_offset(&o);
    return usage();
}
