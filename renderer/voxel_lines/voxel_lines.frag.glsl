// voxel_lines.frag.glsl — one ray per pixel through the voxel model
// (Kanzler et al., Sec. 4): 3D DDA front to back; in each visited voxel the
// lines of the voxel (and, when u_neighbors = R > 0, of the voxels within R)
// are intersected as capsules (cylinder + spheres at both ends, radius
// u_radius_g in voxels) and kept sorted in a small pending list. Own voxel
// only: a voxel's hits are composited when it is left. With neighbours each
// voxel's lines are tested once (a neighbour already within R of the
// previous voxel was tested then: the voxels a ray visits near a box are
// consecutive), and a pending hit is composited once the ray leaves the voxel
// holding its entry point — by then every capsule entering there was tested,
// since its voxel is within R of that one (radius <= R voxels). Hits of one
// curve (same local id) whose intervals overlap are one tube (the joint
// spheres), blended once: up to MAX_OPEN open tube intervals per ray (local
// id, far end); a slot is reused only once its interval has ended before the
// hit at hand (else the one that ended first), so a ray inside many tubes at
// once does not forget one and blend its next piece again. Local ids are
// curve index mod 2^bits (64 or 1024: the record's spare bits), so two
// curves merge wrongly only when their ids collide and their tubes overlap.
// Speed (llvmpipe runs 8 pixels in SIMD lanes whose rays visit different
// voxels): a voxel whose box grown by the radius the ray misses is skipped
// without reading its lines; the lines of all voxels to test at a step are
// walked in one flat loop (a bit mask of voxels), so a lane does not idle
// while another works through a full voxel; a line record is read with three
// word loads; a ray missing a line's infinite cylinder skips its end spheres.
// Opaque (u_opacity >= 1): the first hit ends the ray. Writes premultiplied
// colour for blending (ONE, ONE_MINUS_SRC_ALPHA) and reversed-Z depth of the
// first composited hit.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"
#include "voxel_lines/voxel_lines_grid.glsl"
uniform float u_radius_g;      // tube radius in voxels
#include "voxel_lines/voxel_lines_light.glsl"

uniform vec3 u_eye_g;          // eye in grid coordinates
uniform float u_inv_h;         // 1 / voxel size (world)
uniform float u_opacity;
uniform float u_alpha_stop;    // alpha termination threshold
uniform int u_neighbors;       // 0: own voxel only; R: (2R+1)^3 block
uniform int u_opacity_by_distance;
uniform int u_use_colormap;
uniform int u_opacity_ramp;    // opacity x colormap coordinate
uniform vec2 u_attr_range;     // colormap t of attribute bytes 0 and 255
uniform sampler2D u_colormap;
uniform vec3 u_color;
uniform vec3 u_light_eye;
uniform vec4 u_material;
uniform usampler3D u_occupancy; // per level: 1 when a voxel within 2 of the block holds lines
uniform int u_skip_levels;      // coarsest occupancy level used for empty-space skipping; < 0 = off

layout(location = 0) out vec4 o_color;

#define MAX_HITS 32
float h_in[MAX_HITS], h_out[MAX_HITS];
vec3 h_n[MAX_HITS];
uint h_key[MAX_HITS]; // attribute byte << 16 | local id
int h_count;

// Open tube intervals (joint merging): per slot a local id and the far end
// of the merged interval along the ray.
#define MAX_OPEN 32
float open_out[MAX_OPEN];
uint open_id[MAX_OPEN];
int open_count;

// Merges pending hit i into an open interval of its id that it overlaps
// (true), or opens a new one in a slot whose interval ended before this hit
// (or else the one that ended first).
bool join_open(int i)
{
    uint hid = h_key[i] & 0xffffu;
    int victim = 0;
    float victim_out = 1e30;
    for (int j = 0; j < open_count; j++) {
        if (open_id[j] == hid && h_in[i] <= open_out[j] + 1e-4 * h_in[i]) {
            open_out[j] = max(open_out[j], h_out[i]);
            return true;
        }
        if (open_out[j] < victim_out) {
            victim_out = open_out[j];
            victim = j;
        }
    }
    if (open_count < MAX_OPEN && victim_out >= h_in[i])
        victim = open_count++; // no slot has ended yet: take a new one
    open_id[victim] = hid;
    open_out[victim] = h_out[i];
    return false;
}

// Entry/exit of ray o + s d with the capsule a-b of radius r; false when missed.
// The quadratics are solved from the ray's point nearest a (parameter s0),
// not from the eye: from a far eye |o - a| is thousands of radii and their
// terms cancel in float (a lattice 400 bounding radii away came out 8 tube
// radii deep).
bool capsule(vec3 o, vec3 d, vec3 a, vec3 b, float r, out float t_in, out float t_out, out vec3 n)
{
    t_in = 1e30;
    t_out = -1e30;
    float s0 = dot(a - o, d) / dot(d, d);
    o += s0 * d;
    vec3 ba = b - a, oa = o - a;
    float baba = dot(ba, ba), bard = dot(ba, d), baoa = dot(ba, oa);
    float dd = dot(d, d), rdoa = dot(d, oa), oaoa = dot(oa, oa);
    float qa = baba * dd - bard * bard;
    if (qa > 1e-12 * baba * dd) {
        float qb = baba * rdoa - baoa * bard;
        float qc = baba * oaoa - baoa * baoa - r * r * baba;
        float h = qb * qb - qa * qc;
        if (h < 0.0) {
            // Misses the infinite cylinder, which holds the capsule, so the
            // end spheres are missed too. Only when clearly negative: h is a
            // difference of large terms (the eye is far away); its rounding
            // error is ~1e-7 qb^2 / sin^2 of the ray-line angle, and when it is
            // not clearly negative the sphere tests decide as before.
            if (h < -1e-3 * qb * qb)
                return false;
        } else {
            h = sqrt(h);
            float t0 = (-qb - h) / qa, t1 = (-qb + h) / qa;
            float y0 = baoa + t0 * bard, y1 = baoa + t1 * bard;
            if (y0 > 0.0 && y0 < baba) {
                t_in = t0;
                n = (oa + t0 * d - ba * (y0 / baba)) / r;
            }
            if (y1 > 0.0 && y1 < baba)
                t_out = t1;
        }
    }
    for (int e = 0; e < 2; e++) {
        vec3 c = e == 0 ? a : b;
        vec3 oc = o - c;
        float sb = dot(oc, d), sc = dot(oc, oc) - r * r;
        float h = sb * sb - dd * sc;
        if (h < 0.0)
            continue;
        h = sqrt(h);
        float t0 = (-sb - h) / dd, t1 = (-sb + h) / dd;
        if (t0 < t_in) {
            t_in = t0;
            n = (oc + t0 * d) / r;
        }
        t_out = max(t_out, t1);
    }
    bool hit = t_in < 1e29;
    t_in += s0;
    t_out += s0;
    return hit;
}

// Adds a capsule hit to the pending list (sorted by entry). A pending hit of
// the same id whose interval it overlaps is the same tube (a joint): the two
// become one, entered where the nearer enters, so a ray along a bundle keeps
// one pending entry per tube crossing, not one per piece.
void add_hit(float tin, float tout, vec3 n, uint attr, uint id)
{
    uint key = attr << 16u | id;
    for (int k = 0; k < h_count; k++) {
        if ((h_key[k] & 0xffffu) != id || tin > h_out[k] || tout < h_in[k])
            continue;
        h_out[k] = max(h_out[k], tout);
        if (tin >= h_in[k])
            return;
        // The new piece enters first: take the merged entry out, reinsert it.
        tout = h_out[k];
        h_count--;
        for (int m = k; m < h_count; m++) {
            h_in[m] = h_in[m + 1];
            h_out[m] = h_out[m + 1];
            h_n[m] = h_n[m + 1];
            h_key[m] = h_key[m + 1];
        }
        break;
    }
    int i = h_count;
    if (h_count == MAX_HITS) {
        if (tin >= h_in[MAX_HITS - 1])
            return; // keep the nearest MAX_HITS crossings
        i = MAX_HITS - 1;
    } else {
        h_count++;
    }
    while (i > 0 && h_in[i - 1] > tin) {
        h_in[i] = h_in[i - 1];
        h_out[i] = h_out[i - 1];
        h_n[i] = h_n[i - 1];
        h_key[i] = h_key[i - 1];
        i--;
    }
    h_in[i] = tin;
    h_out[i] = tout;
    h_n[i] = n;
    h_key[i] = key;
}

void main()
{
    vec3 d = sl_ray_direction(gl_FragCoord.xy) * u_inv_h; // grid units per unit of eye distance along F
    vec3 o = u_eye_g;
    float s_near = sl_near.x;
    // Ray against the grid box.
    vec3 inv = 1.0 / d;
    vec3 t0 = (vec3(0.0) - o) * inv, t1 = (vec3(u_dims) - o) * inv;
    vec3 tlo = min(t0, t1), thi = max(t0, t1);
    float s_enter = max(max(max(tlo.x, tlo.y), tlo.z), s_near);
    float s_exit = min(min(thi.x, thi.y), thi.z);
    if (s_enter >= s_exit)
        discard;
    vec3 p = o + s_enter * d;
    ivec3 cell = clamp(ivec3(floor(p)), ivec3(0), u_dims - 1);
    ivec3 step_dir = ivec3(sign(d));
    vec3 next_plane = vec3(cell) + max(vec3(step_dir), vec3(0.0));
    vec3 t_max = mix((next_plane - o) * inv, vec3(1e30), equal(step_dir, ivec3(0)));
    vec3 t_delta = mix(abs(inv), vec3(1e30), equal(step_dir, ivec3(0)));
    // Finite 1/d for the voxel box tests (an axis-parallel ray gets a huge slope).
    vec3 inv_b = 1.0 / mix(d, sign(d + 1e-30) * 1e-20, lessThan(abs(d), vec3(1e-20)));
    float reach = u_radius_g + 1e-3; // a capsule stays within its voxel grown by the radius

    vec3 view_dir = -normalize(d);
    vec3 light = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    sl_material mat = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);

    vec3 acc = vec3(0.0);
    float alpha = 0.0;
    float first_s = -1.0;
    open_count = 0;
    int steps = u_dims.x + u_dims.y + u_dims.z + 3;
    int R = u_neighbors;
    ivec3 prev = ivec3(-1000000);
    int step_axis = 0;
    h_count = 0;
    for (int it = 0; it < steps; it++) {
        if (u_skip_levels >= 0 && texelFetch(u_occupancy, cell, 0).r == 0u) {
            // Empty space: no line within 2 voxels, so no tube reaches here.
            // Jump to the exit of the largest empty block holding the cell.
            int L = 0;
            for (int lv = u_skip_levels; lv >= 1; lv--)
                if (texelFetch(u_occupancy, min(cell >> lv, textureSize(u_occupancy, lv) - 1), lv).r == 0u) {
                    L = lv;
                    break;
                }
            vec3 bmin = vec3((cell >> L) << L), bmax = bmin + float(1 << L);
            vec3 tb = max((bmin - o) * inv, (bmax - o) * inv);
            float s_skip = min(min(tb.x, tb.y), tb.z);
            if (s_skip >= s_exit)
                break;
            int axis = tb.x <= tb.y && tb.x <= tb.z ? 0 : (tb.y <= tb.z ? 1 : 2);
            vec3 q = o + s_skip * d;
            ivec3 nc = clamp(ivec3(floor(q)), ivec3(bmin), ivec3(bmax) - 1); // on the block's face
            nc[axis] = step_dir[axis] > 0 ? int(bmax[axis]) : int(bmin[axis]) - 1;
            if (any(lessThan(nc, ivec3(0))) || any(greaterThanEqual(nc, u_dims)))
                break;
            cell = nc;
            next_plane = vec3(cell) + max(vec3(step_dir), vec3(0.0));
            t_max = mix((next_plane - o) * inv, vec3(1e30), equal(step_dir, ivec3(0)));
            prev = ivec3(-1000000);
            continue;
        }
        float s_leave = min(min(t_max.x, t_max.y), min(t_max.z, s_exit));
        // The voxels of the (2R+1)^3 block not tested from the previous voxel:
        // after a DDA step the slab on the stepped axis's far side, else
        // (first voxel, after a skip, or R = 0) the whole block as 2R+1 slabs
        // along z. Per slab a bit mask of the voxels that hold lines and that
        // the ray crosses when grown by the radius, then one flat loop over
        // their lines (so that SIMD lanes with different voxels stay busy).
        bool fresh = prev.x == -1000000;
        int W = 2 * R + 1;
        int slabs = fresh ? W : 1;
        for (int sl = 0; sl < slabs; sl++) {
            int ax = fresh ? 2 : step_axis;
            int off = fresh ? sl - R : R * step_dir[step_axis];
            uint mask = 0u;
            int j = 0;
            for (int dv = -R; dv <= R; dv++)
                for (int du = -R; du <= R; du++, j++) {
                    ivec3 c = cell + (ax == 0 ? ivec3(off, du, dv) : (ax == 1 ? ivec3(du, off, dv) : ivec3(du, dv, off)));
                    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, u_dims)))
                        continue;
                    // The ray must pass through the voxel grown by the radius.
                    vec3 ba0 = (vec3(c) - reach - o) * inv_b, ba1 = (vec3(c) + (1.0 + reach) - o) * inv_b;
                    vec3 bn = min(ba0, ba1), bf = max(ba0, ba1);
                    if (max(max(bn.x, bn.y), bn.z) > min(min(min(bf.x, bf.y), bf.z), s_exit))
                        continue;
                    if (vx_count(vx_index(c)) != 0u)
                        mask |= 1u << uint(j);
                }
            uint l = 0u, count = 0u, first = 0u;
            vec3 corner = vec3(0.0);
            while (mask != 0u || l < count) {
                if (l >= count) {
                    int jb = findLSB(mask);
                    mask &= mask - 1u;
                    int jv = W == 5 ? (jb * 13) >> 6 : (jb * 11) >> 5; // jb / W for W = 1, 3, 5
                    int ju = jb - W * jv - R;
                    jv -= R;
                    ivec3 c = cell + (ax == 0 ? ivec3(off, ju, jv) : (ax == 1 ? ivec3(ju, off, jv) : ivec3(ju, jv, off)));
                    int v = vx_index(c);
                    count = vx_count(v);
                    first = vx_offsets[v];
                    corner = vec3(c);
                    l = 0u;
                }
                vec3 a, b;
                uint attr, id;
                vx_line(first + l, a, b, attr, id);
                l++;
                float tin, tout;
                vec3 n;
                if (!capsule(o, d, corner + a, corner + b, u_radius_g, tin, tout, n))
                    continue;
                if (tout < s_near)
                    continue;
                add_hit(max(tin, s_near), tout, n, attr, id);
            }
        }
        prev = R > 0 ? cell : ivec3(-1000000);
        // Pending hits that start before this voxel's exit are final: every
        // capsule entering there belongs to a voxel adjacent to one visited.
        int used = 0;
        for (int i = 0; i < h_count; i++) {
            if (R > 0 && h_in[i] >= s_leave)
                break;
            used++;
            if (join_open(i))
                continue;
            float t = mix(u_attr_range.x, u_attr_range.y, float(h_key[i] >> 16u) / 255.0);
            vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, t, vec2(0.0, 1.0)) : u_color;
            vec3 pos_g = o + h_in[i] * d;
            vec3 n = normalize(h_n[i]);
            vec3 c = clamp(sl_shade(base, n, light, view_dir, mat), 0.0, 1.0) * vx_light_factor(pos_g, n, light);
            float a = u_opacity_ramp != 0 ? u_opacity * clamp(t, 0.0, 1.0) : u_opacity;
            if (u_opacity_by_distance != 0 && a < 1.0) {
                // Opacity per tube diameter of travelled distance.
                float dist = (h_out[i] - h_in[i]) * length(d);
                a = 1.0 - pow(1.0 - a, clamp(dist / (2.0 * u_radius_g), 0.0, 1.0));
            }
            if (first_s < 0.0)
                first_s = h_in[i];
            acc += (1.0 - alpha) * a * c;
            alpha += (1.0 - alpha) * a;
            if (alpha >= u_alpha_stop)
                break;
        }
        for (int i = used; i < h_count; i++) {
            h_in[i - used] = h_in[i];
            h_out[i - used] = h_out[i];
            h_n[i - used] = h_n[i];
            h_key[i - used] = h_key[i];
        }
        h_count -= used;
        if (alpha >= u_alpha_stop || s_leave >= s_exit)
            break;
        // Step to the next voxel.
        if (t_max.x <= t_max.y && t_max.x <= t_max.z) {
            cell.x += step_dir.x;
            t_max.x += t_delta.x;
            step_axis = 0;
        } else if (t_max.y <= t_max.z) {
            cell.y += step_dir.y;
            t_max.y += t_delta.y;
            step_axis = 1;
        } else {
            cell.z += step_dir.z;
            t_max.z += t_delta.z;
            step_axis = 2;
        }
        if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, u_dims)))
            break;
    }
    if (first_s < 0.0)
        discard;
    gl_FragDepth = sl_near.x / first_s;
    o_color = vec4(acc, alpha);
}
