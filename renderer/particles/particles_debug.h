/* particles_debug.h — checker-only views into `particles` internals, not part
 * of the technique table: tests that drive sl_pipeline in process include it
 * to count hatch-cache builds and to read the strokes back. Nothing in the
 * library calls these hooks but the hatch build. Render thread only (the
 * observer runs inside render, GL context current).
 */
#ifndef PARTICLES_DEBUG_H
#define PARTICLES_DEBUG_H

#include <stdint.h>

#include <epoxy/gl.h>

/* One hatch-cache build of one set, as the observer sees it. Both buffers are
 * borrowed and valid only during the call: records holds pt_record
 * (particles_system.h) for the set's alive particles first; strokes holds,
 * for particle i and stroke s (0 main, 1 cross) of strokes_per_particle, the
 * vertices v = 0 .. segments at ((i * strokes_per_particle + s) *
 * (segments + 1) + v) * 16 bytes: x, y, z (local world), then k1 and k2 as
 * packHalf2x16 in the bits of the fourth float. The particle sits at vertex
 * segments / 2 (integer division). */
typedef struct pt_debug_hatch_build {
    int set;
    uint32_t particles;
    int strokes_per_particle;
    int segments;
    GLuint records, strokes;
} pt_debug_hatch_build;

typedef void (*pt_debug_hatch_fn)(void *user, const pt_debug_hatch_build *build);

/* Installs fn (NULL removes it): called after every hatch-cache build. */
void pt_debug_hatch_observe(pt_debug_hatch_fn fn, void *user);
/* Hatch-cache builds (one per set and build) in this process so far. */
unsigned long pt_debug_hatch_builds(void);

#endif
