/* sightline_info.c — describes a dataset: sightline-info FILE | GENERATOR-JSON | BUILTIN-NAME.
 *
 * Loads a file (renderer/data/sl_load.h), runs a generator call such as
 * '{"generator":"tornado","lines":100}' or a built-in dataset name
 * (renderer/data/sl_generate.h), and prints one JSON object on stdout: kind,
 * name, counts, world bounds, origin, attributes with their ranges (lines) or
 * dims, voxel type, spacing, value range and NaN voxels (volumes), degree,
 * dim, element / basis / mesh-rectangle counts, refinement levels, domain and
 * the sampled value range (LR-spline volumes), and load_ms.
 * `sightline-info --list` prints the generator families and built-ins;
 * `sightline-info --backends` opens the GL device and prints, for every technique
 * with two executions (core/sl_backend.h), which one `backend = auto` picks here.
 * Does no loading or generating itself. Single-threaded.
 * Exit status: 0 success; 1 usage error (usage on stderr); 2 bad input, with
 * the reason on stderr and {"error", "status"} on stdout.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_backend.h"
#include "core/sl_technique.h"
#include "data/sl_dataset.h"
#include "gpu/sl_gpu.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "lrspline/sl_lr.h"

#define EXIT_USAGE 1
#define EXIT_BAD_INPUT 2

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sightline-info FILE | GENERATOR-JSON | BUILTIN-NAME\n"
            "       sightline-info --list\n"
            "       sightline-info --backends\n"
            "Prints a JSON description of the dataset (counts, bounds, attributes,\n"
            "volume dims and value range; LR-spline degree, elements, basis functions,\n"
            "refinement levels, domain and sampled value range; load_ms).\n"
            "Exit 0 ok, 1 usage, 2 bad input.\n");
}

static cJSON *vec3_json(sl_vec3 v)
{
    const double a[3] = {v.x, v.y, v.z};
    return cJSON_CreateDoubleArray(a, 3);
}

static cJSON *attributes_json(const sl_attribute *set, int count)
{
    cJSON *arr = cJSON_CreateArray();
    for (int i = 0; i < count; i++) {
        cJSON *a = cJSON_CreateObject();
        cJSON_AddStringToObject(a, "name", set[i].name);
        cJSON_AddNumberToObject(a, "min", set[i].min);
        cJSON_AddNumberToObject(a, "max", set[i].max);
        cJSON_AddItemToArray(arr, a);
    }
    return arr;
}

static void add_lines(cJSON *root, const sl_lines *l)
{
    size_t segments = 0;
    for (size_t k = 0; k < l->line_count; k++) {
        uint32_t n = l->line_offsets[k + 1] - l->line_offsets[k];
        segments += n > 0 ? n - 1 : 0;
    }
    cJSON *counts = cJSON_AddObjectToObject(root, "counts");
    cJSON_AddNumberToObject(counts, "lines", (double)l->line_count);
    cJSON_AddNumberToObject(counts, "vertices", (double)l->vertex_count);
    cJSON_AddNumberToObject(counts, "segments", (double)segments);
    cJSON_AddBoolToObject(root, "radii", l->radii != NULL);
    cJSON_AddBoolToObject(root, "tangents", l->tangents != NULL);
    cJSON_AddBoolToObject(root, "normals", l->normals != NULL);
    cJSON_AddItemToObject(root, "attributes", attributes_json(l->attributes, l->attribute_count));
    cJSON_AddItemToObject(root, "line_attributes", attributes_json(l->line_attributes, l->line_attribute_count));
}

static void add_volume(cJSON *root, const sl_volume *v)
{
    cJSON_AddItemToObject(root, "dims", cJSON_CreateIntArray(v->dims, 3));
    cJSON_AddStringToObject(root, "voxel_type", sl_voxel_type_name(v->type));
    cJSON_AddNumberToObject(root, "components", v->components);
    cJSON *counts = cJSON_AddObjectToObject(root, "counts");
    size_t n = (size_t)v->dims[0] * v->dims[1] * v->dims[2];
    cJSON_AddNumberToObject(counts, "voxels", (double)n);
    /* NaN voxels (f32 only): the volume techniques draw them transparent. */
    size_t nan = 0;
    if (v->type == SL_VOXEL_F32)
        for (size_t i = 0; i < n * (size_t)v->components; i++)
            nan += isnan(((const float *)v->data)[i]);
    cJSON_AddNumberToObject(counts, "nan_voxels", (double)nan);
    cJSON_AddItemToObject(root, "spacing", cJSON_CreateDoubleArray(v->spacing, 3));
    const double range[2] = {v->value_min, v->value_max};
    cJSON_AddItemToObject(root, "value_range", cJSON_CreateDoubleArray(range, 2));
}

/* LR-spline volumes: the value range is sl_lr_finish's sample (element
 * corners, edge and face midpoints, centres), not a bound. */
static void add_lr(cJSON *root, const sl_lr_volume *lr)
{
    int degree[3] = {lr->order[0] - 1, lr->order[1] - 1, lr->order[2] - 1};
    cJSON_AddItemToObject(root, "degree", cJSON_CreateIntArray(degree, 3));
    cJSON_AddNumberToObject(root, "components", lr->dim);
    cJSON *counts = cJSON_AddObjectToObject(root, "counts");
    cJSON_AddNumberToObject(counts, "elements", (double)lr->element_count);
    cJSON_AddNumberToObject(counts, "basis_functions", (double)lr->basis_count);
    cJSON_AddNumberToObject(counts, "mesh_rectangles", (double)lr->meshrect_count);
    cJSON_AddNumberToObject(root, "refinement_levels", sl_lr_level_ratio(lr));
    cJSON_AddItemToObject(root, "min_element_side", cJSON_CreateDoubleArray(lr->min_side, 3));
    cJSON_AddItemToObject(root, "max_element_side", cJSON_CreateDoubleArray(lr->max_side, 3));
    cJSON *domain = cJSON_AddObjectToObject(root, "domain");
    cJSON_AddItemToObject(domain, "min", cJSON_CreateDoubleArray(lr->domain_lo, 3));
    cJSON_AddItemToObject(domain, "max", cJSON_CreateDoubleArray(lr->domain_hi, 3));
    const double range[2] = {lr->value_min, lr->value_max};
    cJSON_AddItemToObject(root, "value_range", cJSON_CreateDoubleArray(range, 2));
    cJSON_AddStringToObject(root, "value_range_note",
                            lr->dim == 3 ? "sampled (vector magnitude at each element's 8 corners and centre), not a bound"
                                         : "sampled (each element's 8 corners and centre), not a bound");
}

static cJSON *dataset_json(const sl_dataset *ds)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "kind", sl_dataset_kind_name(ds->kind));
    cJSON_AddStringToObject(root, "name", ds->name);
    if (ds->kind == SL_DATASET_LINES)
        add_lines(root, &ds->lines);
    else if (ds->kind == SL_DATASET_LR)
        add_lr(root, ds->lr);
    else
        add_volume(root, &ds->volume);
    cJSON *bounds = cJSON_AddObjectToObject(root, "bounds");
    cJSON_AddItemToObject(bounds, "min", vec3_json(ds->bounds_min));
    cJSON_AddItemToObject(bounds, "max", vec3_json(ds->bounds_max));
    cJSON_AddItemToObject(root, "origin", vec3_json(ds->origin));
    cJSON_AddNumberToObject(root, "load_ms", ds->load_ms);
    return root;
}

static cJSON *list_json(void)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *gens = cJSON_AddArrayToObject(root, "generators");
    int n = 0;
    const sl_generator_info *g = sl_generator_list(&n);
    for (int i = 0; i < n; i++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", g[i].name);
        cJSON_AddStringToObject(o, "kind", sl_dataset_kind_name(g[i].kind));
        cJSON_AddStringToObject(o, "description", g[i].description);
        cJSON_AddStringToObject(o, "keys", g[i].keys_help);
        cJSON_AddItemToArray(gens, o);
    }
    cJSON *builtins = cJSON_AddArrayToObject(root, "builtins");
    const sl_builtin_dataset *b = sl_builtin_datasets(&n);
    for (int i = 0; i < n; i++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", b[i].name);
        cJSON_AddStringToObject(o, "generator", b[i].generator_json);
        cJSON_AddStringToObject(o, "description", b[i].description);
        cJSON_AddItemToArray(builtins, o);
    }
    return root;
}

/* {"renderer", "software", "techniques": {name: {"auto", "built": [...], "missing"}}} or NULL. */
static cJSON *backends_json(void)
{
    sl_gpu *gpu = NULL;
    sl_err err = {0};
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "sightline-info: %s\n", err.message);
        return NULL;
    }
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "renderer", sl_gpu_renderer(gpu));
    cJSON_AddBoolToObject(o, "software", sl_gpu_is_software(gpu));
    cJSON *list = cJSON_AddObjectToObject(o, "techniques");
    int count = 0;
    const sl_technique *const *all = sl_technique_list(&count);
    for (int i = 0; i < count; i++) {
        if (!all[i]->backend_cpu)
            continue;
        sl_backend_cpu cpu;
        all[i]->backend_cpu(&cpu);
        sl_backend pick = SL_BACKEND_GL;
        sl_backend_decide(all[i]->name, SL_BACKEND_AUTO, sl_gpu_is_software(gpu), &cpu, &pick, NULL);
        cJSON *t = cJSON_AddObjectToObject(list, all[i]->name);
        cJSON_AddStringToObject(t, "auto", sl_backend_name(pick, &cpu));
        cJSON *built = cJSON_AddArrayToObject(t, "built");
        cJSON_AddItemToArray(built, cJSON_CreateString("gl"));
        if (cpu.built)
            cJSON_AddItemToArray(built, cJSON_CreateString(cpu.name));
        else
            cJSON_AddStringToObject(t, "missing", cpu.missing);
    }
    sl_gpu_destroy(gpu);
    return o;
}

static int print_json(cJSON *root)
{
    char *text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        fprintf(stderr, "sightline-info: out of memory\n");
        return EXIT_BAD_INPUT;
    }
    puts(text);
    cJSON_free(text);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2 || !argv[1][0] || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        usage(argc == 2 && argv[1][0] ? stdout : stderr);
        return argc == 2 && argv[1][0] ? 0 : EXIT_USAGE;
    }
    const char *input = argv[1];
    if (strcmp(input, "--list") == 0)
        return print_json(list_json());
    if (strcmp(input, "--backends") == 0) {
        cJSON *b = backends_json();
        return b ? print_json(b) : 3;
    }
    if (input[0] == '-') {
        fprintf(stderr, "sightline-info: unknown option %s\n", input);
        usage(stderr);
        return EXIT_USAGE;
    }
    const char *p = input;
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
        p++;
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st;
    const char *builtin = sl_builtin_lookup(input);
    if (*p == '{') {
        st = sl_generate_json(input, &ds, &err);
    } else if (builtin) {
        st = sl_generate_json(builtin, &ds, &err);
        if (st == SL_OK)
            snprintf(ds->name, sizeof ds->name, "%s", input);
    } else {
        st = sl_load_file(input, &ds, &err);
    }
    if (st != SL_OK) {
        fprintf(stderr, "sightline-info: %s\n", err.message);
        cJSON *e = cJSON_CreateObject();
        cJSON_AddStringToObject(e, "error", err.message);
        cJSON_AddStringToObject(e, "status", sl_status_name(st));
        print_json(e);
        return EXIT_BAD_INPUT;
    }
    int rc = print_json(dataset_json(ds));
    sl_dataset_destroy(ds);
    return rc;
}
