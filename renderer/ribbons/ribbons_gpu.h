/* ribbons_gpu.h — the GL objects of one `ribbons` pipeline and its per-chunk draw ranges.
 *
 * One builder per `pipeline` (plan §3.3): pulling (point SSBOs + a u16
 * chunk pattern with caps, basevertex per chunk), geometry (point SSBOs + u32
 * segment pairs for GL_LINES into ribbons.geom.glsl, caps by the pulling
 * program from a u16 cap-only pattern), mesh (the static CPU mesh of
 * ribbons_mesh.c, u32 index ranges per chunk), flat (point SSBOs + a u16
 * quad pattern, N = 2, no caps, two-sided). Each chunk gets one mantle range
 * and up to two cap ranges, so the per-frame loop in ribbons.c (cull, sort,
 * fill) is the same for all four; it only fills the client-memory multi-draw
 * arrays of the two passes here, no GL buffer is written after the build.
 * Every buffer allocated is counted in buffer_bytes. Render thread only.
 */
#ifndef SL_RIBBONS_GPU_H
#define SL_RIBBONS_GPU_H

#include <stddef.h>
#include <stdint.h>
#include <epoxy/gl.h>

#include "ribbons_prep.h"
#include "../lines/sl_lines_prep.h"

/* The order of the `pipeline` enum of the schema. */
typedef enum rb_pipeline { RB_PIPELINE_PULLING, RB_PIPELINE_GEOMETRY, RB_PIPELINE_MESH, RB_PIPELINE_FLAT } rb_pipeline;

#define RB_CHUNK_SEGMENTS 64u   /* K: 65 rings of <= 32 vertices fit u16 indices */
#define RB_MAX_SIDES 32

typedef struct rb_range {       /* one draw of a chunk; count 0 = none */
    GLsizei count;
    GLint base;                 /* basevertex */
    uintptr_t offset;           /* bytes into the pass' index buffer */
} rb_range;

typedef struct rb_pass {        /* one multi-draw per frame */
    GLuint program, vao;        /* borrowed from rb_gpu; program 0 = pass unused */
    GLenum mode, index_type;
    int cap, cull_faces, clockwise;
    GLsizei drawcount;          /* per frame */
    GLsizei *counts;            /* owned, capacity entries */
    GLint *bases;
    const void **offsets;
} rb_pass;

typedef struct rb_gpu {
    rb_pipeline pipeline;
    int sides;                  /* ring slots drawn: `sides`, or 2 for flat */
    float ring[2 * RB_MAX_SIDES];
    GLuint programs[2];         /* distinct programs; every one gets the uniforms */
    int program_count;
    GLuint vaos[2];
    GLuint buffers[6];          /* owned */
    int buffer_count;
    GLuint point_buffers[3];    /* borrowed from buffers: SSBO bindings 2-4, or 0 (mesh) */
    size_t buffer_bytes;        /* every buffer above */
    rb_range *mantle;           /* per chunk */
    rb_range *caps;             /* 2 per chunk: start, end */
    double *triangles;          /* per chunk, mantle + caps */
    rb_pass passes[2];          /* mantle, caps */
    int gs_invocations, gs_columns; /* geometry only */
    double cpu_ms, compile_ms;  /* of the build: CPU mesh / pair building, program compiles */
} rb_gpu;

/* Builds g for pipeline with `sides` on the packed points and the chunks of
 * l. SL_ERR_LIMIT when the geometry shader limits cannot hold a ring, the
 * mesh does not fit 32-bit indices or points x N exceed the GLint vertex ids
 * of the pattern pipelines, SL_ERR_GPU / SL_ERR_NOMEM; g is released (zeroed)
 * on failure. */
sl_status rb_gpu_build(rb_gpu *g, rb_pipeline pipeline, int sides, const sl_ribbons_points *pts, const sl_lines *l,
                       const sl_line_chunk *chunks, size_t chunk_count, sl_err *err);

/* Appends chunk c's ranges to the passes (after drawcount = 0 per frame). */
void rb_gpu_add_chunk(rb_gpu *g, size_t c);

/* Binds the point SSBOs and issues both passes' multi-draws (uniforms set). */
void rb_gpu_draw(const rb_gpu *g);

void rb_gpu_release(rb_gpu *g); /* zeroed or half-built is fine */

#endif
