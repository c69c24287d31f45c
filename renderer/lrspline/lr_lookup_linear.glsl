// lr_lookup_linear.glsl — placeholder element look-up for the GPU: int lr_find_element(vec3 p)
// by a linear scan over the Bézier blocks' boxes (lrspline/lr_bezier.glsl), implementing the
// element rule of sl_lr.h: lo <= p < hi per direction, closed at the domain's upper face
// (p == domain_hi takes the element with hi == domain_hi); -1 outside the closed domain or
// for NaN. O(elements) per call: for tests and small models only; the real structures are
// lr_lookup*.c / lr_lookup.glsl (the choice is made in lrspline/lr_find.glsl and lr_gpu.c).
// Needs lr_bezier.glsl included first (boxes, u_lr_element_count, u_lr_domain_hi).
int lr_find_element(vec3 p)
{
    if (!all(greaterThanEqual(p, u_lr_domain_lo)) || !all(lessThanEqual(p, u_lr_domain_hi)))
        return -1; // also NaN
    int found = -1;
    for (int e = 0; e < u_lr_element_count && found < 0; e++) {
        vec3 lo = lr_box_data[e].lo.xyz, hi = lr_box_data[e].hi.xyz;
        bvec3 upper = bvec3(p.x == hi.x && hi.x == u_lr_domain_hi.x, p.y == hi.y && hi.y == u_lr_domain_hi.y,
                            p.z == hi.z && hi.z == u_lr_domain_hi.z);
        bvec3 below = lessThan(p, hi);
        if (all(greaterThanEqual(p, lo)) && all(bvec3(below.x || upper.x, below.y || upper.y, below.z || upper.z)))
            found = e;
    }
    return found;
}
