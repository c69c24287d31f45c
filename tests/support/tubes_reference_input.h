/* tubes_reference_input.h — the Hermite segments the tubes reference
 * (tubes_reference.h) intersects, built from a scene's data without the
 * renderer's node builder (renderer/tubes/tubes_nodes.c), so a fault there
 * shows as a depth error instead of being shared by both sides.
 *
 * Two sources:
 * - explicit Hermite JSON, {"nodes": [{"p", "t", "r", "dr", "c", "dc"}],
 *   "segments": [[i, j]]} (proto/scene.md), read here with cJSON in double:
 *   world coordinates, origin 0;
 * - any polyline set (generators, file loaders): one segment per consecutive
 *   vertex pair, tangents by the rule documented for `tubes` (scene.md,
 *   tubes README): Catmull-Rom (x[i+1] - x[i-1]) / 2 inside a line, one-sided
 *   x[1] - x[0] and x[n] - x[n-1] at its ends; with data tangents, mode
 *   `auto` takes their direction with the Catmull-Rom length and `data` takes
 *   them as they are. Radii: the data's (|r|), a per-vertex attribute
 *   (|value|, derivative from "<name>_derivative" or by the same finite
 *   differences) or the constant radius; the first two times radius_scale.
 *   Coordinates relative to the dataset origin, in double.
 * Errors fill msg and return -1; out is then empty. Any thread.
 */
#ifndef TUBES_REFERENCE_INPUT_H
#define TUBES_REFERENCE_INPUT_H

#include <stddef.h>

#include "data/sl_dataset.h"
#include "tubes_reference.h"

struct cJSON;

typedef struct tubes_ref_input {
    tubes_ref_segment *segments;
    size_t count;
    sl_vec3 origin; /* world position the segments are relative to */
} tubes_ref_input;

typedef enum tubes_ref_tangents {
    TUBES_REF_TANGENTS_AUTO = 0,        /* data tangents' direction, Catmull-Rom length */
    TUBES_REF_TANGENTS_CATMULL_ROM = 1, /* always finite differences */
    TUBES_REF_TANGENTS_DATA = 2,        /* the data's tangents as they are */
} tubes_ref_tangents;

/* 1 when root is explicit Hermite JSON (an object with "nodes" and "segments"). */
int tubes_ref_is_hermite_json(const struct cJSON *root);

/* From explicit Hermite JSON. radius_from_scalar: the radius and its
 * derivative are the colour scalar's (c, dc), as params.radius_attribute
 * naming the "scalar" attribute does; a node without "r" takes `radius`. */
int tubes_ref_input_hermite_json(const struct cJSON *root, int radius_from_scalar, double radius, double radius_scale,
                                 tubes_ref_input *out, char *msg, size_t msg_size);

/* From a loaded polyline set. radius_attribute < 0: the data's radii, else
 * the constant radius. */
int tubes_ref_input_lines(const sl_dataset *ds, tubes_ref_tangents tangents, int radius_attribute, double radius,
                          double radius_scale, tubes_ref_input *out, char *msg, size_t msg_size);

void tubes_ref_input_free(tubes_ref_input *in);

#endif
