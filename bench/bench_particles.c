/* bench_particles.c — the paper's Table 2 and Fig. 11a for `particles`, frames, run time against error,
 * the targets, and VTK's isosurface as the peer.
 *
 *   bench-particles [--small | --size WxH] [--frames N] [--counts 10000,30000,60000,100000,200000]
 *                   [--steps 0,5,10,25,50] [--part 1..5 (repeatable)] [--reps R] [--no-vtk] [--only KEY]
 *
 * van Pelt, Vilanova, van de Wetering, "Illustrative Volume Visualization
 * Using GPU-Based Particle Systems", sec. 5, Table 2, Table 3, Fig. 11;
 * docs/particles_plan.md §5. Datasets: the CT (data/samples/cranium.nhdr,
 * s16 HU: skin -500, bone 400), the MRI (ch2.nii.gz, u8: skin 80), the
 * sphere and torus generators (part 4); missing samples -> "not fetched".
 * The particle system is driven directly (renderer/particles/particles_system.h,
 * the code `particles` prepares with), so every phase has its own wall time
 * (each ends with a glFinish); frames go through the pipeline and the
 * harness (sl_bench_time_frames: first GL command to glFinish after the
 * readback). The count of a row is chosen as the plan says: a count-only
 * placement at spacing 1 gives N1, spacing sqrt(N1 / N), one correction
 * step, and the actual count is printed.
 * 1. Table 2 analogue at ~60k: load + upload, placement, redistribution 25 and
 *    15 steps (energy_tol 0), stipple fps at 640x360 and 1280x720 with and
 *    without hidden-surface removal; the paper's GPU column quoted, ratio.
 *    With it the VTK peer (bench/vtk_iso.py under xvfb-run: vtkFlyingEdges3D
 *    + vtkPolyDataMapper) on the same volume, isovalue, cameras and size.
 * 2. Scaling (Fig. 11a): per dataset x count, per sort and look-up method.
 * 3. Frames: one row per style (frame_rows[], one line each).
 * 4. Run time against error: steps 0..50 on sphere, torus and CT skin, with
 *    the metrics of tests/support/particles_reference.h (no renderer code).
 * 5. The targets as facts.
 * Also (part 2): placement with and without the brick skipping, interleaved
 * (the A/B of the skipping; same seeds, asserted).
 * Prints Markdown; checks nothing (tests/render/particles.cmake does).
 * Main thread = render thread.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "particles/particles_system.h"
#include "particles_reference.h"
#include "pipeline/sl_pipeline.h"
#include "volume/sl_volume.h"

#define PROGRAM "bench-particles"
#define MAX_LIST 12
#define REPULSION 1.6 /* the schema's default repulsion_radius (lattice steps) */
#define LOOKUP PT_LOOKUP_BINARY_SEARCH /* the schema's default look-up */

typedef struct options {
    sl_bench_options bench;
    int counts[MAX_LIST], count_n;
    int steps[MAX_LIST], steps_n;
    int parts;   /* bit k: part k + 1 */
    int reps;    /* repetitions of the interleaved A/B */
    int no_vtk;
    const char *only;  /* a dataset key (ct-skin, ct-bone, mri-skin, sphere, torus), or NULL: all */
} options;

/* ---- datasets ---- */

typedef struct vol {
    const char *key, *label;
    const char *file, *generator; /* one of them */
    double iso;
    double area;                  /* known surface area (world), 0: unknown */
    sl_dataset *ds;
    sl_volume_texture tex;
    sl_volume_bricks bricks;
    pt_field field;
    double load_ms, upload_ms;
    char why[160];                /* not loaded: why */
} vol;

static const char *source_dir(void)
{
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    return src ? src : SIGHTLINE_SOURCE_DIR;
}

static const sl_technique *particles(void)
{
    return sl_technique_find("particles");
}

static sl_status vol_load(vol *v, const char *only, sl_err *err)
{
    double t0 = sl_clock_ms();
    sl_status st;
    if (only && strcmp(only, v->key) != 0) {
        snprintf(v->why, sizeof v->why, "not run (--only %s)", only);
        return SL_OK;
    }
    if (v->file) {
        char path[1024];
        snprintf(path, sizeof path, "%s/data/samples/%s", source_dir(), v->file);
        if (access(path, R_OK) != 0) {
            snprintf(v->why, sizeof v->why, "%s not fetched (scripts/fetch-sample-data)", v->file);
            return SL_OK;
        }
        st = sl_load_file(path, &v->ds, err);
    } else {
        st = sl_generate_json(v->generator, &v->ds, err);
    }
    if (st != SL_OK)
        return st;
    v->load_ms = sl_clock_ms() - t0;
    t0 = sl_clock_ms();
    if ((st = sl_volume_texture_create(&v->ds->volume, &v->tex, err)) != SL_OK)
        return st;
    glFinish();
    v->upload_ms = sl_clock_ms() - t0;
    if ((st = sl_volume_bricks_create(&v->ds->volume, &v->bricks, err)) != SL_OK)
        return st;
    sl_volume_geometry g;
    sl_volume_geometry_init(v->ds, &g);
    const sl_volume *vv = &v->ds->volume;
    v->field = (pt_field){.texture = v->tex.tex, .value_scale = v->tex.value_scale,
                          .value_offset = v->tex.value_offset, .min_spacing = g.min_spacing,
                          .value_min = vv->value_min, .value_max = vv->value_max, .bricks = &v->bricks};
    for (int a = 0; a < 3; a++) {
        v->field.dims[a] = vv->dims[a];
        v->field.spacing[a] = vv->spacing[a];
    }
    return SL_OK;
}

static void vol_free(vol *v)
{
    sl_volume_texture_destroy(&v->tex);
    sl_volume_bricks_destroy(&v->bricks);
    sl_dataset_destroy(v->ds);
    v->ds = NULL;
}

/* ---- one set through the particle system ---- */

typedef struct run {
    pt_set_stats s;
    uint32_t bins;
    size_t bytes;        /* records + table held, + the volume texture */
    double total_ms;     /* pt_set_build wall */
    double redistribution_ms; /* the steps (ms_per_step x steps) */
} run;

typedef struct build_desc {
    double spacing;
    int steps;
    double tol;
    pt_sort_method sort;
    pt_lookup_method lookup;
    int no_skipping;
} build_desc;

/* Builds one set; keeps it in *keep when not NULL (the caller releases). */
static sl_status build(pt_system *sys, const vol *v, const build_desc *bd, run *r, pt_set *keep, sl_err *err)
{
    pt_system_desc d = {.iso = v->iso, .lattice_step = bd->spacing,
                        .sigma = REPULSION * bd->spacing * v->field.min_spacing, .energy_tol = bd->tol,
                        .max_steps = bd->steps, .sort = bd->sort, .lookup = bd->lookup, .max_particles = 4000000,
                        .no_skipping = bd->no_skipping};
    pt_set set;
    double t0 = sl_clock_ms();
    sl_status st = pt_set_build(sys, &v->field, &d, &set, err);
    if (st != SL_OK)
        return st;
    memset(r, 0, sizeof *r);
    r->total_ms = sl_clock_ms() - t0;
    r->s = set.stats;
    r->bins = set.bins;
    r->bytes = set.bytes + v->tex.bytes;
    r->redistribution_ms = set.stats.ms_per_step * set.stats.steps;
    if (keep)
        *keep = set;
    else
        pt_set_release(&set);
    return SL_OK;
}

/* The spacing for about `target` particles: N1 at spacing 1, s = sqrt(N1 / N), one correction. */
static sl_status spacing_for(pt_system *sys, const vol *v, int target, double *spacing, sl_err *err)
{
    build_desc bd = {.spacing = 1.0, .lookup = LOOKUP};
    run r;
    sl_status st = build(sys, v, &bd, &r, NULL, err);
    if (st != SL_OK)
        return st;
    double s = sqrt((double)r.s.seeded / target);
    s = fmin(fmax(s, 0.25), 16.0);
    bd.spacing = s;
    if ((st = build(sys, v, &bd, &r, NULL, err)) != SL_OK)
        return st;
    if (r.s.seeded > 0)
        s = fmin(fmax(s * sqrt((double)r.s.seeded / target), 0.25), 16.0);
    *spacing = s;
    return SL_OK;
}

/* ---- frames ---- */

static const sl_bench_orbit head_orbit = {.distance = 2.2, .elevation_deg = 10.0, .fov_y_deg = 35.0};

/* Frames rows: a label and the parameters it sets ("name=value ..."); hidden_surface_removal is the column. */
typedef struct frame_row { const char *label, *params; } frame_row;
static const frame_row frame_rows[] = {
    {"stipple", "stipple=15"},
    /* other styles add a line here, e.g. {"hatch fixed", "stipple=0 hatch=15"} */
};
#define FRAME_ROWS ((int)(sizeof frame_rows / sizeof frame_rows[0]))

static sl_status set_pairs(sl_params *params, const char *pairs, sl_err *err)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", pairs);
    for (char *save = NULL, *tok = strtok_r(buf, " ", &save); tok; tok = strtok_r(NULL, " ", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq)
            return sl_err_set(err, SL_ERR_INVALID, "frame row: '%s' is not name=value", tok);
        *eq = 0;
        char *end;
        double x = strtod(eq + 1, &end);
        sl_status st = *end ? sl_bench_set_choice(params, tok, eq + 1, err) : sl_bench_set(params, tok, x, err);
        if (st != SL_OK)
            return st;
    }
    return SL_OK;
}

static sl_status particle_params(sl_params *params, double iso, double spacing, int steps, sl_err *err)
{
    sl_params_init(params, particles()->params, particles()->param_count);
    sl_status st = sl_params_set_numbers(params, "isovalues", &iso, 1, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "spacing", spacing, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "max_steps", steps, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "energy_tol", 0.0, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "max_particles", 4000000, err);
    return st;
}

#define SIZES 2
static const int sizes[SIZES][2] = {{1280, 720}, {640, 360}};

typedef struct frames_result {
    int ok;
    sl_bench_timing t[FRAME_ROWS][SIZES][2]; /* [row][size][hsr] */
    double prepare_ms;
    double particles;
} frames_result;

/* Loads the file again into a pipeline (it owns its dataset) and times every row, size and HSR. */
static sl_status time_frames(sl_gpu *gpu, const options *o, const vol *v, double spacing, frames_result *fr,
                             sl_err *err)
{
    memset(fr, 0, sizeof *fr);
    char path[1024];
    snprintf(path, sizeof path, "%s/data/samples/%s", source_dir(), v->file);
    sl_dataset *ds = NULL;
    sl_pipeline *p = NULL;
    sl_status st = sl_load_file(path, &ds, err);
    if (st != SL_OK)
        return st;
    if ((st = sl_pipeline_create(gpu, &p, err)) != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    sl_pipeline_set_dataset(p, ds);
    for (int row = 0; st == SL_OK && row < FRAME_ROWS; row++)
        for (int z = 0; st == SL_OK && z < SIZES; z++)
            for (int h = 1; st == SL_OK && h >= 0; h--) {
                sl_params params;
                if ((st = particle_params(&params, v->iso, spacing, 25, err)) != SL_OK ||
                    (st = set_pairs(&params, frame_rows[row].params, err)) != SL_OK ||
                    (st = sl_bench_set(&params, "hidden_surface_removal", h ? 15 : 0, err)) != SL_OK)
                    break;
                sl_bench_options bo = o->bench;
                bo.width = sizes[z][0];
                bo.height = sizes[z][1];
                fprintf(stderr, PROGRAM ": frames %s %s %dx%d hsr %d\n", v->key, frame_rows[row].label, bo.width,
                        bo.height, h);
                sl_bench_timing *t = &fr->t[row][z][h];
                st = sl_bench_time_frames(p, particles(), &params, &bo, SL_QUALITY_STILL, sl_bench_orbit_camera,
                                          &head_orbit, t, err);
                if (t->prepare_ms > 0)
                    fr->prepare_ms = t->prepare_ms;
            }
    sl_pipeline_destroy(p);
    fr->ok = st == SL_OK;
    return st;
}

/* ---- the VTK peer ---- */

typedef struct vtk_result {
    int ok;
    char reason[256], filter[32];
    double filter_ms, frame_ms, first_frame_ms, triangles;
} vtk_result;

static void run_vtk(const options *o, const vol *v, int w, int h, vtk_result *r)
{
    memset(r, 0, sizeof *r);
    char dir[] = "/tmp/sl-bench-particles-XXXXXX";
    if (!mkdtemp(dir)) {
        snprintf(r->reason, sizeof r->reason, "no temporary folder");
        return;
    }
    char raw[96], cams[96];
    snprintf(raw, sizeof raw, "%s/volume.raw", dir);
    snprintf(cams, sizeof cams, "%s/cameras.txt", dir);
    const sl_volume *vv = &v->ds->volume;
    size_t n = (size_t)vv->dims[0] * vv->dims[1] * vv->dims[2];
    FILE *f = fopen(raw, "wb");
    int wrote = f && fwrite(vv->data, sl_voxel_type_size(vv->type), n, f) == n;
    if (f)
        fclose(f);
    f = wrote ? fopen(cams, "w") : NULL;
    sl_err err = {0};
    for (int k = -1; f && k < o->bench.frames; k++) {
        sl_camera c;
        if (sl_bench_orbit_camera(v->ds, k < 0 ? 0 : k, o->bench.frames, &head_orbit, &c, &err) == SL_OK)
            fprintf(f, "v %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k, c.eye.x, c.eye.y,
                    c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg);
    }
    if (f)
        fclose(f);
    if (!wrote || !f) {
        snprintf(r->reason, sizeof r->reason, "cannot write the volume or the cameras into %s", dir);
    } else {
        static const char *const types[] = {"uint8", "uint16", "int16", "float32"};
        char cmd[2048];
        snprintf(cmd, sizeof cmd, "xvfb-run -a /usr/bin/python3 %s/bench/vtk_iso.py --raw %s --type %s --dims %d %d %d "
                 "--spacing %.17g %.17g %.17g --origin %.17g %.17g %.17g --iso %.17g --cameras %s --size %dx%d "
                 "2>/dev/null", source_dir(), raw, types[vv->type], vv->dims[0], vv->dims[1], vv->dims[2],
                 vv->spacing[0], vv->spacing[1], vv->spacing[2], v->ds->origin.x, v->ds->origin.y, v->ds->origin.z,
                 v->iso, cams, w, h);
        FILE *p = popen(cmd, "r");
        char line[8192] = "";
        if (p) {
            while (fgets(line, sizeof line, p) && line[0] != '{')
                ;
            pclose(p);
        }
        cJSON *j = cJSON_Parse(line);
        if (!cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(j, "ok"))) {
            const cJSON *e = cJSON_GetObjectItemCaseSensitive(j, "error");
            snprintf(r->reason, sizeof r->reason, "%s",
                     cJSON_IsString(e) ? e->valuestring
                                       : "no output from xvfb-run /usr/bin/python3 bench/vtk_iso.py (python3-vtk9, "
                                         "xvfb, xauth: scripts/install-deps bench/packages.txt)");
        } else {
            r->ok = 1;
            const cJSON *views = cJSON_GetObjectItemCaseSensitive(j, "views");
            const cJSON *m = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(views, "v"), "median_ms");
            const cJSON *fi = cJSON_GetObjectItemCaseSensitive(j, "filter");
            r->frame_ms = cJSON_IsNumber(m) ? m->valuedouble : 0.0;
            r->filter_ms = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(j, "filter_ms"));
            r->first_frame_ms = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(j, "first_frame_ms"));
            r->triangles = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(j, "triangles"));
            snprintf(r->filter, sizeof r->filter, "%s", cJSON_IsString(fi) ? fi->valuestring : "?");
        }
        cJSON_Delete(j);
    }
    unlink(raw);
    unlink(cams);
    rmdir(dir);
}

/* ---- parts ---- */

typedef struct table2 {
    int ok;
    double spacing;
    run r25, r15;
    frames_result fr;
    vtk_result vtk[SIZES];
} table2;

static double fps(const sl_bench_timing *t)
{
    return t->median_ms > 0 ? 1000.0 / t->median_ms : 0.0;
}

static void print_target(const char *what, int met)
{
    printf("- %s: target %s.\n", what, met ? "**met**" : "**not met**");
}

static sl_status part1(sl_gpu *gpu, pt_system *sys, const options *o, vol *v, table2 *tb, sl_err *err)
{
    memset(tb, 0, sizeof *tb);
    sl_status st = spacing_for(sys, v, 60000, &tb->spacing, err);
    build_desc bd = {.spacing = tb->spacing, .steps = 25, .lookup = LOOKUP};
    if (st == SL_OK)
        st = build(sys, v, &bd, &tb->r25, NULL, err);
    bd.steps = 15;
    if (st == SL_OK)
        st = build(sys, v, &bd, &tb->r15, NULL, err);
    if (st == SL_OK && (o->parts & (1 << 0 | 1 << 2 | 1 << 4)))
        st = time_frames(gpu, o, v, tb->spacing, &tb->fr, err);
    for (int z = 0; st == SL_OK && !o->no_vtk && z < SIZES; z++) {
        fprintf(stderr, PROGRAM ": VTK %s %dx%d\n", v->key, sizes[z][0], sizes[z][1]);
        run_vtk(o, v, sizes[z][0], sizes[z][1], &tb->vtk[z]);
        if (!tb->vtk[z].ok)
            fprintf(stderr, PROGRAM ": VTK: %s\n", tb->vtk[z].reason);
    }
    tb->ok = st == SL_OK;
    return st;
}

static void print_part1(const options *o, vol *const *vs, table2 *const *tbs, int n)
{
    printf("\n## 1. Table 2 analogue (~60k particles, redistribution with energy_tol 0)\n\n");
    printf("The paper's GPU column: GeForce 8800 GTX, CT head 256^3 x 8 bit, 60,000 particles (its Table 2); "
           "ours: llvmpipe, %s. Ratio = ours / paper (> 1: slower than the paper's GPU).\n\n",
           "the CT 256x256x108 s16 (1.5 / 0.957 mm) and the MRI 181x217x181 u8");
    printf("| row | paper GPU |");
    for (int k = 0; k < n; k++)
        printf(" %s | ratio |", vs[k]->label);
    printf("\n|---|---:|");
    for (int k = 0; k < n; k++)
        printf("---:|---:|");
    printf("\n");
    const double paper[] = {140, 140, 4000, 2580};
    const char *rows[] = {"load volume (file + texture upload) ms", "placement ms", "redistribution 25 steps ms",
                          "redistribution 15 steps ms"};
    for (int row = 0; row < 4; row++) {
        printf("| %s | %.0f |", rows[row], paper[row]);
        for (int k = 0; k < n; k++) {
            const table2 *t = tbs[k];
            if (!t->ok) {
                printf(" %s | |", vs[k]->why[0] ? vs[k]->why : "failed");
                continue;
            }
            double x = row == 0 ? vs[k]->load_ms + vs[k]->upload_ms
                     : row == 1 ? t->r25.s.placement_ms
                     : row == 2 ? t->r25.redistribution_ms
                                : t->r15.redistribution_ms;
            printf(" %.0f | %.2f |", x, x / paper[row]);
        }
        printf("\n");
    }
    for (int z = SIZES - 1; z >= 0; z--)
        for (int h = 1; h >= 0; h--) {
            printf("| stipple fps %dx%d, HSR %s | %s |", sizes[z][0], sizes[z][1], h ? "on" : "off",
                   z == 1 && h ? "1135" : "");
            for (int k = 0; k < n; k++) {
                const table2 *t = tbs[k];
                if (!t->ok || !t->fr.ok) {
                    printf(" | |");
                    continue;
                }
                double f = fps(&t->fr.t[0][z][h]);
                if (z == 1 && h)
                    printf(" %.1f | %.4f |", f, f / 1135.0);
                else
                    printf(" %.1f | |", f);
            }
            printf("\n");
        }
    printf("\nParticles (alive after settling) / seeded, spacing (voxels), bins, settle + curvature ms, "
           "load | upload ms:\n\n");
    for (int k = 0; k < n; k++) {
        const table2 *t = tbs[k];
        if (!t->ok)
            continue;
        printf("- %s (iso %g): %u / %u particles, spacing %.3f, %u bins, settle + curvature %.0f ms, load %.0f | "
               "upload %.0f ms; 15 steps: %u particles.\n", vs[k]->label, vs[k]->iso, t->r25.s.alive,
               t->r25.s.seeded, t->spacing, t->r25.bins, t->r25.s.settle_ms + t->r25.s.final_ms, vs[k]->load_ms,
               vs[k]->upload_ms, t->r15.s.alive);
    }
    printf("\nThe stipple fps at 640x360 with HSR is compared with the paper's 1135 fps (its size is not given; "
           "Table 3 has Skull a, fig. 8a, stipples, 57,030 particles: 51.3 fps). Frames: orbit of %d frames "
           "(distance 2.2 bounding radii, elevation 10, fov 35), wall ms to glFinish after the readback.\n",
           o->bench.frames);
    if (o->no_vtk)
        return;
    printf("\n### Peer: VTK isosurface (the same volume, isovalue, cameras and sizes)\n\n");
    printf("| dataset | VTK filter | triangles | extraction ms | ours placement + 25 steps ms | ratio ours / VTK | "
           "size | VTK frame ms | ours stipple HSR frame ms | ratio ours / VTK |\n");
    printf("|---|---|---:|---:|---:|---:|---|---:|---:|---:|\n");
    for (int k = 0; k < n; k++) {
        const table2 *t = tbs[k];
        if (!t->ok)
            continue;
        for (int z = 0; z < SIZES; z++) {
            const vtk_result *r = &t->vtk[z];
            if (!r->ok) {
                printf("| %s | not run: %s | | | | | %dx%d | | | |\n", vs[k]->label, r->reason, sizes[z][0],
                       sizes[z][1]);
                continue;
            }
            double ours_prep = t->r25.s.placement_ms + t->r25.redistribution_ms;
            double ours_frame = t->fr.ok ? t->fr.t[0][z][1].median_ms : 0.0;
            printf("| %s | %s | %.0f | %.0f | %.0f | %.1f | %dx%d | %.1f | %.1f | %.2f |\n", vs[k]->label, r->filter,
                   r->triangles, r->filter_ms, ours_prep, ours_prep / r->filter_ms, sizes[z][0], sizes[z][1],
                   r->frame_ms, ours_frame, r->frame_ms > 0 ? ours_frame / r->frame_ms : 0.0);
        }
    }
    printf("\nVTK: vtkFlyingEdges3D with normals (Update timed alone) + vtkPolyDataMapper under xvfb-run on the same "
           "llvmpipe, glFinish + readback per frame (bench/vtk_iso.py). Ours: placement + 25 redistribution steps "
           "(settle and curvature not included) against the mesh extraction.\n");
}

static void part2(pt_system *sys, const options *o, vol *const *vs, int n, sl_err *err)
{
    printf("\n## 2. Scaling (Fig. 11a): per count, sort and look-up (25 steps, energy_tol 0)\n\n");
    printf("ms per step: the phase's total over the steps + the final sort, divided by steps + 1 (sort includes the "
           "key pass; look-up = the bin table). GPU MB: records + bin table held + the volume texture. The paper: "
           "\"for particle sets up to 100,000 particles, the redistribution time stays well under five seconds\" "
           "(Fig. 11a, 8800 GTX).\n\n");
    printf("| dataset | particles | spacing | bins | placement ms | sort ms/step radix \\| bitonic | look-up ms/step "
           "prefix_sum \\| binary_search | energy ms/step | redistribution 25 steps ms (radix, binary_search) | GPU MB |"
           "\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int k = 0; k < n; k++) {
        if (!vs[k]->ds) {
            printf("| %s | %s | | | | | | | | |\n", vs[k]->label, vs[k]->why);
            continue;
        }
        for (int c = 0; c < o->count_n; c++) {
            double spacing;
            fprintf(stderr, PROGRAM ": scaling %s %d\n", vs[k]->key, o->counts[c]);
            if (spacing_for(sys, vs[k], o->counts[c], &spacing, err) != SL_OK) {
                printf("| %s | %d: %s | | | | | | | | |\n", vs[k]->label, o->counts[c], err->message);
                continue;
            }
            run r[3];
            const build_desc bd[3] = {{spacing, 25, 0.0, PT_SORT_RADIX, PT_LOOKUP_BINARY_SEARCH, 0},
                                      {spacing, 25, 0.0, PT_SORT_BITONIC, PT_LOOKUP_BINARY_SEARCH, 0},
                                      {spacing, 25, 0.0, PT_SORT_RADIX, PT_LOOKUP_PREFIX_SUM, 0}};
            int ok = 1;
            for (int m = 0; m < 3 && ok; m++)
                ok = build(sys, vs[k], &bd[m], &r[m], NULL, err) == SL_OK;
            if (!ok) {
                printf("| %s | %d: %s | | | | | | | | |\n", vs[k]->label, o->counts[c], err->message);
                continue;
            }
            double per = r[0].s.steps + 1.0;
            printf("| %s | %u | %.3f | %u | %.0f | %.1f \\| %.1f | %.1f \\| %.1f | %.1f | %.0f | %.1f |\n",
                   vs[k]->label, r[0].s.alive, spacing, r[0].bins, r[0].s.placement_ms, r[0].s.sort_ms / per,
                   r[1].s.sort_ms / per, r[2].s.lookup_ms / per, r[0].s.lookup_ms / per,
                   r[0].s.energy_ms / fmax(r[0].s.steps, 1), r[0].redistribution_ms, r[0].bytes / 1e6);
        }
    }
}

/* The skipping against the whole lattice and whole-box bins, interleaved, o->reps times each. */
static void part2_ab(pt_system *sys, const options *o, vol *const *vs, int n, sl_err *err)
{
    printf("\n### Before / after, same run, interleaved ABBA (~60k, 25 steps, radix; medians of %d). Before: the whole "
           "lattice, bins over the whole volume, look-up prefix_sum; after: only the lattice tiles whose bricks may "
           "straddle the isovalue, bins over those bricks, look-up binary_search (the new default)\n\n", o->reps);
    printf("| dataset | particles | tiles dispatched / all | bins before → after | placement ms before → after "
           "(ratio) | look-up ms/step before → after (ratio) | sort ms/step before → after | energy ms/step before → "
           "after | 25 steps ms before → after (ratio) | same seeds |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    for (int k = 0; k < n; k++) {
        if (!vs[k]->ds)
            continue;
        double spacing;
        if (spacing_for(sys, vs[k], 60000, &spacing, err) != SL_OK)
            continue;
        enum { PLACE, LOOK, SORT, ENERGY, STEPS, Q };
        double v[2][Q][16];
        run r[2] = {0};
        int ok = 1, same = 1, reps = o->reps < 16 ? o->reps : 16;
        for (int rep = 0; rep < reps && ok; rep++)
            for (int ab = 0; ab < 2 && ok; ab++) {
                int variant = (rep & 1) ? 1 - ab : ab; /* ABBA */
                /* before: the lead's code (whole lattice, bins over the volume, prefix_sum); after: ours */
                build_desc bd = {spacing, 25, 0.0, PT_SORT_RADIX, variant ? LOOKUP : PT_LOOKUP_PREFIX_SUM, variant == 0};
                fprintf(stderr, PROGRAM ": A/B %s rep %d %s\n", vs[k]->key, rep, variant ? "after" : "before");
                ok = build(sys, vs[k], &bd, &r[variant], NULL, err) == SL_OK;
                double per = r[variant].s.steps + 1.0;
                v[variant][PLACE][rep] = r[variant].s.placement_ms;
                v[variant][LOOK][rep] = r[variant].s.lookup_ms / per;
                v[variant][SORT][rep] = r[variant].s.sort_ms / per;
                v[variant][ENERGY][rep] = r[variant].s.energy_ms / fmax(r[variant].s.steps, 1);
                v[variant][STEPS][rep] = r[variant].redistribution_ms;
            }
        if (!ok)
            continue;
        same = r[0].s.seeded == r[1].s.seeded && r[0].s.alive == r[1].s.alive &&
               r[0].s.final_energy == r[1].s.final_energy;
        double m[2][Q];
        for (int ab = 0; ab < 2; ab++)
            for (int q = 0; q < Q; q++)
                m[ab][q] = sl_bench_median(v[ab][q], reps);
        printf("| %s | %u | %u / %u | %u → %u | %.0f → %.0f (%.2f) | %.1f → %.1f (%.2f) | %.1f → %.1f | %.1f → %.1f | "
               "%.0f → %.0f (%.2f) | %s |\n", vs[k]->label, r[1].s.alive, r[1].s.tiles, r[1].s.tiles_total, r[0].bins,
               r[1].bins, m[0][PLACE], m[1][PLACE], m[1][PLACE] / m[0][PLACE], m[0][LOOK], m[1][LOOK],
               m[1][LOOK] / m[0][LOOK], m[0][SORT], m[1][SORT], m[0][ENERGY], m[1][ENERGY], m[0][STEPS],
               m[1][STEPS], m[1][STEPS] / m[0][STEPS],
               same ? "yes (seeded, alive, final energy equal)" : "**no**");
    }
}

static void print_part3(const options *o, vol *const *vs, table2 *const *tbs, int n)
{
    printf("\n## 3. Frames (~60k particles, orbit of %d frames; wall ms median (min-max), fps)\n\n", o->bench.frames);
    printf("| dataset | style | size | HSR off ms | HSR on ms | HSR off fps | HSR on fps |\n"
           "|---|---|---|---:|---:|---:|---:|\n");
    for (int k = 0; k < n; k++) {
        const table2 *t = tbs[k];
        if (!t->ok || !t->fr.ok)
            continue;
        for (int row = 0; row < FRAME_ROWS; row++)
            for (int z = 0; z < SIZES; z++) {
                const sl_bench_timing *off = &t->fr.t[row][z][0], *on = &t->fr.t[row][z][1];
                printf("| %s | %s | %dx%d | %.1f (%.1f-%.1f) | %.1f (%.1f-%.1f) | %.1f | %.1f |\n", vs[k]->label,
                       frame_rows[row].label, sizes[z][0], sizes[z][1], off->median_ms, off->min_ms, off->max_ms,
                       on->median_ms, on->min_ms, on->max_ms, fps(off), fps(on));
            }
    }
    printf("\nPaper, Table 3 (8800 GTX, quoted only): Skull a (fig. 8a, stipples) 57,030 particles 51.3 fps; "
           "Skull c (fig. 8c, contours) 11.3 fps.\n");
}

/* Off-surface distance (voxels, first order, pref_trilinear) and NN of the alive particles of set. */
static void set_metrics(const vol *v, const pt_set *set, double *p99, double *cv, double *packing)
{
    *p99 = *cv = *packing = NAN;
    uint32_t n = set->stats.alive;
    pt_record *rec = n ? malloc((size_t)n * sizeof *rec) : NULL;
    double *xyz = n ? malloc((size_t)n * 3 * sizeof *xyz) : NULL, *dist = n ? malloc((size_t)n * sizeof *dist) : NULL;
    if (!rec || !xyz || !dist) {
        free(rec), free(xyz), free(dist);
        return;
    }
    glGetNamedBufferSubData(set->records, 0, (GLsizeiptr)((size_t)n * sizeof *rec), rec);
    const double *sp = v->ds->volume.spacing;
    double ms = v->field.min_spacing;
    for (uint32_t i = 0; i < n; i++) {
        double u[3], f, g[3];
        for (int a = 0; a < 3; a++) {
            xyz[3 * i + a] = rec[i].x[a];
            u[a] = rec[i].x[a] / sp[a];
        }
        if (pref_trilinear(&v->ds->volume, u, &f, g) != 0) {
            dist[i] = INFINITY;
            continue;
        }
        double gw = sqrt(g[0] / sp[0] * g[0] / sp[0] + g[1] / sp[1] * g[1] / sp[1] + g[2] / sp[2] * g[2] / sp[2]);
        dist[i] = gw > 0 ? fabs(f - v->iso) / gw / ms : INFINITY;
    }
    double mean = 0;
    if (n >= 2 && pref_nn(xyz, n, PREF_NN_AUTO, &mean, cv, NULL) == 0 && v->area > 0)
        *packing = pref_packing_ratio(n, mean, v->area);
    sl_bench_median(dist, (int)n); /* sorts dist */
    *p99 = dist[(size_t)floor(0.99 * (n - 1))];
    free(rec), free(xyz), free(dist);
}

static sl_status part4(pt_system *sys, const options *o, vol *const *vs, int n, sl_err *err)
{
    printf("\n## 4. Run time against error (energy_tol 0, radix, binary_search)\n\n");
    printf("Off-surface: |f - iso| / |grad f| (first order, trilinear in double, pref_trilinear) in voxels, p99; "
           "NN CV and packing ratio n pi (mean/2)^2 / area from the exact nearest neighbours (pref_nn; 0.907 = "
           "hexagonal); areas: sphere 4 pi 0.45^2, torus 4 pi^2 0.55 0.25. Redistribution ms = the steps alone.\n\n");
    printf("| dataset | particles | steps | redistribution ms | off-surface p99 (voxels) | NN CV | packing ratio | "
           "final energy |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int k = 0; k < n; k++) {
        if (!vs[k]->ds) {
            printf("| %s | %s | | | | | | |\n", vs[k]->label, vs[k]->why);
            continue;
        }
        double spacing = 1.25; /* the schema's default for the generated volumes */
        sl_status st = SL_OK;
        if (vs[k]->file && (st = spacing_for(sys, vs[k], 60000, &spacing, err)) != SL_OK)
            return st;
        for (int s = 0; s < o->steps_n; s++) {
            build_desc bd = {.spacing = spacing, .steps = o->steps[s], .lookup = LOOKUP};
            run r;
            pt_set set;
            fprintf(stderr, PROGRAM ": error %s steps %d\n", vs[k]->key, o->steps[s]);
            if ((st = build(sys, vs[k], &bd, &r, &set, err)) != SL_OK)
                return st;
            double p99, cv, packing;
            set_metrics(vs[k], &set, &p99, &cv, &packing);
            pt_set_release(&set);
            char pk[32] = "n/a";
            if (!isnan(packing))
                snprintf(pk, sizeof pk, "%.3f", packing);
            printf("| %s | %u | %d | %.0f | %.2e | %.3f | %s | %.4g |\n", vs[k]->label, r.s.alive, r.s.steps,
                   r.redistribution_ms, p99, cv, pk, r.s.final_energy);
        }
    }
    return SL_OK;
}

static void print_part5(vol *const *vs, table2 *const *tbs, int n)
{
    printf("\n## 5. Targets (issue 14)\n\n");
    for (int k = 0; k < n; k++) {
        const table2 *t = tbs[k];
        char what[256];
        if (!t->ok) {
            printf("- %s: %s.\n", vs[k]->label, vs[k]->why[0] ? vs[k]->why : "not run");
            continue;
        }
        snprintf(what, sizeof what, "%s: %u particles x 25 steps in %.2f s (placement %.2f s more)", vs[k]->label,
                 t->r25.s.alive, t->r25.redistribution_ms / 1000.0, t->r25.s.placement_ms / 1000.0);
        print_target(what, t->r25.redistribution_ms < 4000.0);
        if (t->fr.ok) {
            double on = fps(&t->fr.t[0][1][1]), off = fps(&t->fr.t[0][1][0]);
            printf("- %s: stippling %u particles at 640x360: %.1f fps with HSR, %.1f without: target >= 10 fps "
                   "%s with HSR, %s without.\n", vs[k]->label, t->r25.s.alive, on, off,
                   on >= 10.0 ? "**met**" : "**not met**", off >= 10.0 ? "**met**" : "**not met**");
        }
    }
}

/* ---- arguments ---- */

static int parse_list(const char *text, int lo, int hi, int *out, int *n)
{
    *n = 0;
    for (const char *p = text; *p && *n < MAX_LIST;) {
        char *end;
        long v = strtol(p, &end, 10);
        if (end == p || v < lo || v > hi || (*end && *end != ','))
            return 0;
        out[(*n)++] = (int)v;
        p = *end ? end + 1 : end;
    }
    return *n > 0;
}

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.counts = {10000, 30000, 60000, 100000, 200000}, .count_n = 5, .steps = {0, 5, 10, 25, 50},
                   .steps_n = 5, .parts = 0x1f, .reps = 3};
    sl_bench_options_init(&o->bench, 10);
    int parts_given = 0;
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o->bench, argc, argv, &i, PROGRAM);
        if (c < 0)
            return 0;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int part = 0;
        if (strcmp(a, "--no-vtk") == 0) {
            o->no_vtk = 1;
        } else if (strcmp(a, "--counts") == 0 && v && parse_list(v, 100, 4000000, o->counts, &o->count_n)) {
            i++;
        } else if (strcmp(a, "--steps") == 0 && v && parse_list(v, 0, 1000, o->steps, &o->steps_n)) {
            i++;
        } else if (strcmp(a, "--part") == 0 && v && sl_bench_parse_int(v, 1, 5, &part) == 0) {
            o->parts = (parts_given++ ? o->parts : 0) | 1 << (part - 1); /* repeatable */
            i++;
        } else if (strcmp(a, "--only") == 0 && v) {
            o->only = argv[++i];
        } else if (strcmp(a, "--reps") == 0 && v && sl_bench_parse_int(v, 1, 16, &o->reps) == 0) {
            i++;
        } else {
            fprintf(stderr, "usage: " PROGRAM " %s [--counts 10000,30000,...] [--steps 0,5,10,25,50]\n"
                            "       [--part 1..5] [--reps R (1..16)] [--no-vtk] [--only ct-skin|ct-bone|mri-skin|sphere|"
                            "torus]\n", SL_BENCH_OPTIONS_HELP);
            return 0;
        }
    }
    return 1;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse_args(argc, argv, &o))
        return 2;
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    pt_system *sys = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK || pt_system_create(&sys, &err) != SL_OK) {
        fprintf(stderr, PROGRAM ": %s\n", err.message);
        sl_gpu_destroy(gpu);
        return 3;
    }
    double t0 = sl_clock_ms();
    const double pi = 3.14159265358979323846;
    vol ct_skin = {.key = "ct-skin", .label = "CT skin", .file = "cranium.nhdr", .iso = -500};
    vol ct_bone = {.key = "ct-bone", .label = "CT bone", .file = "cranium.nhdr", .iso = 400};
    vol mri = {.key = "mri-skin", .label = "MRI skin", .file = "ch2.nii.gz", .iso = 80};
    vol sphere = {.key = "sphere", .label = "sphere 128^3",
                  .generator = "{\"generator\":\"ellipsoid\",\"size\":128,\"a\":0.9,\"b\":0.9,\"c\":0.9}", .iso = 0.5,
                  .area = 4 * pi * 0.45 * 0.45};
    vol torus = {.key = "torus", .label = "torus 128^3",
                 .generator = "{\"generator\":\"torus\",\"size\":128,\"minor\":0.25,\"sphere\":0.01}", .iso = 0,
                 .area = 4 * pi * pi * 0.55 * 0.25};
    vol *heads[3] = {&ct_skin, &ct_bone, &mri};
    sl_status st = SL_OK;
    for (int k = 0; k < 3 && st == SL_OK; k++)
        st = vol_load(heads[k], o.only, &err);
    printf("# " PROGRAM " — %s\n\nUnder load or not: see the section heading in bench/RESULTS.md. Repulsion radius "
           "%.1f lattice steps (the default); the count of a row is chosen from a count-only run (N ~ 1/spacing^2, "
           "one correction).\n", sl_gpu_renderer(gpu), REPULSION);
    static table2 tbs[3];
    table2 *tbp[3] = {&tbs[0], &tbs[1], &tbs[2]};
    if (st == SL_OK && (o.parts & (1 << 0 | 1 << 2 | 1 << 4)))
        for (int k = 0; k < 3 && st == SL_OK; k++)
            if (heads[k]->ds) {
                fprintf(stderr, PROGRAM ": table 2 %s\n", heads[k]->key);
                st = part1(gpu, sys, &o, heads[k], &tbs[k], &err);
            }
    if (st == SL_OK && (o.parts & 1))
        print_part1(&o, heads, tbp, 3);
    if (st == SL_OK && (o.parts & 2)) {
        part2(sys, &o, heads, 3, &err);
        part2_ab(sys, &o, heads, 3, &err);
    }
    if (st == SL_OK && (o.parts & 4))
        print_part3(&o, heads, tbp, 3);
    if (st == SL_OK && (o.parts & 8)) {
        if ((st = vol_load(&sphere, o.only, &err)) == SL_OK && (st = vol_load(&torus, o.only, &err)) == SL_OK) {
            vol *es[3] = {&sphere, &torus, &ct_skin};
            st = part4(sys, &o, es, 3, &err);
        }
    }
    if (st == SL_OK && (o.parts & 16))
        print_part5(heads, tbp, 3);
    if (st == SL_OK)
        printf("\nWhole run: %.0f s.\n", (sl_clock_ms() - t0) / 1000.0);
    else
        fprintf(stderr, PROGRAM ": %s\n", err.message);
    vol *all[5] = {&ct_skin, &ct_bone, &mri, &sphere, &torus};
    for (int k = 0; k < 5; k++)
        vol_free(all[k]);
    pt_system_destroy(sys);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 1;
}
