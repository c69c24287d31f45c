/* lines_v3f.h — float 3-vectors for renderer/lines/ only (not a public header).
 *
 * Float on purpose: the tangents, normals and rings of the swept meshes are
 * computed in float in this exact order, which keeps tubes_mesh's golden
 * images bit-identical. vnorm of a zero vector is the zero vector. Any thread.
 */
#ifndef SL_LINES_V3F_H
#define SL_LINES_V3F_H

#include <math.h>

typedef struct v3f { float x, y, z; } v3f;

static inline v3f vsub(v3f a, v3f b) { return (v3f){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline v3f vadd(v3f a, v3f b) { return (v3f){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline v3f vscale(v3f a, float s) { return (v3f){a.x * s, a.y * s, a.z * s}; }
static inline float vdot(v3f a, v3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline v3f vcross(v3f a, v3f b)
{
    return (v3f){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline float vlen(v3f a) { return sqrtf(vdot(a, a)); }
static inline v3f vnorm(v3f a) { float l = vlen(a); return l > 0.0f ? vscale(a, 1.0f / l) : (v3f){0, 0, 0}; }
static inline v3f load(const float *p) { return (v3f){p[0], p[1], p[2]}; }
static inline void store(float *o, v3f a) { o[0] = a.x; o[1] = a.y; o[2] = a.z; }

#endif
