// ribbons_halo.glsl — silhouette points of an elliptic cross-section seen from the camera,
// and a point's position between them (Neuhauser et al., "Efficient high-quality rendering
// of ribbons and twisted lines", Sec. 3.2, Eq. 5; Richter-Gebert, Perspectives on
// Projective Geometry, pp. 149-154 polar, 194-196 line-conic intersection).
// Everything lives in the normal plane of the cylinder, in units of the semi-major axis:
// the ellipse is x²/w² + y² = 1, i.e. the conic A = diag(1/w², 1, -1), with x along the
// ribbon's face normal (the thin axis) and y along its width. The camera c is homogeneous:
// (x, y, 1) for a point, (x, y, 0) for a direction (a camera at infinity), any positive
// scale (callers rescale far cameras so that no entry exceeds ~1: the construction has
// entries of order |c|^4 / w^4).
// Limits: no silhouette when the camera is inside or on the ellipse (c^T A c <= 0); then
// sl_ribbon_silhouette returns false and the halo coordinate is 0. The sub-matrix for
// alpha is the one of the largest |l_k| (the paper's "last entry, if non-zero" whenever
// that is the largest; defined for a camera at infinity too). Pure functions, no uniforms.

// M_l with M_l q = q x l (the paper's matrix; GLSL matrices are built from columns).
mat3 sl_ribbon_cross_matrix(vec3 l)
{
    return mat3(vec3(0.0, -l.z, l.y), vec3(l.z, 0.0, -l.x), vec3(-l.y, l.x, 0.0));
}

// The two points where the tangents from c touch the ellipse x²/w² + y² = 1; false when
// c is inside or on it (or the construction degenerates).
bool sl_ribbon_silhouette(vec3 c, float w, out vec2 p_max, out vec2 p_max2)
{
    p_max = vec2(0.0);
    p_max2 = vec2(0.0);
    float iw2 = 1.0 / (w * w);
    float power = c.x * c.x * iw2 + c.y * c.y - c.z * c.z; // c^T A c
    if (!(power > 0.0))
        return false;
    vec3 l = vec3(c.x * iw2, c.y, -c.z);                  // the polar of c
    mat3 M = sl_ribbon_cross_matrix(l);
    mat3 A = mat3(vec3(iw2, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, -1.0));
    mat3 B = transpose(M) * A * M;
    vec3 al = abs(l);
    int n = al.x >= al.y && al.x >= al.z ? 0 : (al.y >= al.z ? 1 : 2);
    float det = n == 2 ? B[0][0] * B[1][1] - B[1][0] * B[1][0]
              : n == 1 ? B[0][0] * B[2][2] - B[2][0] * B[2][0]
                       : B[1][1] * B[2][2] - B[2][1] * B[2][1];
    float mu = l[n];
    if (!(-det > 0.0) || mu == 0.0)
        return false;
    float alpha = sqrt(-det) / mu;
    mat3 C = B + alpha * M;
    // The entry of largest magnitude: its row and its column are the two points.
    int bi = 0, bj = 0;
    float best = -1.0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            if (abs(C[j][i]) > best) {
                best = abs(C[j][i]);
                bi = i;
                bj = j;
            }
    vec3 row = vec3(C[0][bi], C[1][bi], C[2][bi]), col = C[bj];
    if (!(abs(row.z) > 0.0) || !(abs(col.z) > 0.0))
        return false;
    p_max = row.xy / row.z;
    p_max2 = col.xy / col.z;
    return true;
}

// The halo coordinate of p (a point of the cross-section, same units) seen from c:
// p' = meet(l, join(c, p)) = l x (c x p) is p projected from c onto the chord of the two
// silhouette points; lambda = | |p' - p_max| / |p_max2 - p_max| * 2 - 1 |, 0 on the middle
// of the chord, 1 at a silhouette point. 0 when there is no silhouette or no chord.
float sl_ribbon_halo_lambda(vec2 p, vec3 c, float w, vec2 p_max, vec2 p_max2)
{
    vec3 l = vec3(c.x / (w * w), c.y, -c.z);
    vec3 q = cross(l, cross(c, vec3(p, 1.0)));
    float chord = length(p_max2 - p_max);
    if (!(abs(q.z) > 0.0) || !(chord > 1e-6))
        return 0.0;
    return abs(length(q.xy / q.z - p_max) / chord * 2.0 - 1.0);
}
