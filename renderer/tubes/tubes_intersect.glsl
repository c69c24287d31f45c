// tubes_intersect.glsl — ray against the sphere sweep of one quadratic sub-segment, in ray
// space (Russig et al. 3.2, "Intersection" and "Root finding").
// With the ray o + l d and control points relative to o, h(t) = p(t).d and
// g(t) = r(t)^2 - |p(t) - h(t) d|^2 (degree 4); the entry distance is
// f(t) = h - sqrt(g), defined where g >= 0. Roots of g come from g'' (solved
// analytically), then g' and g by bracketing; on every interval where g > 0 the
// minima of f come from the roots of f''' (assumed at most one, as observed in
// the paper), f'' and f' by the same bracketing, keeping only - to + crossings of
// f' (minima). Derivatives are used through sign-preserving multiples without
// the square-root singularity: F1 = 2 sqrt(g) h' - g' ~ f', F2 = 4 g^1.5 f'',
// F3 = 8 g^2.5 f'''. Each root search runs u_iterations steps of bisection
// (method 0), of the Illinois variant of regula falsi (method 1), or (method 2)
// of safeguarded Newton for g', g, F3, F2 and of Illinois for F1 in a variable
// theta that removes F1's square-root singularity at the ends of g > 0
// (tubes_root_f1; Newton on F1 or on f' itself converged badly there).

uniform int u_iterations;
uniform int u_method;

// The sub-segment in ray space, scaled by k = 1 / sqrt(max |g coefficient|)
// (keeps F3 ~ g'^3 in float range): radius R(t), lateral position Y(t), Z(t)
// as power-basis quadratics (x + y t + z t^2), and h'(t) = H1[0] + H1[1] t.
// g = R^2 - Y^2 - Z^2 is evaluated from the quadratics, not from its expanded
// quartic: near a hit Y and Z are ~R, while the quartic's coefficients are
// ~(segment length)^2, so the expansion would lose (length / radius)^2 of the
// float precision to cancellation.
vec3 QR, QY, QZ;
float H1[2];

float quad(vec3 q, float t) { return (q.z * t + q.y) * t + q.x; }
float quad1(vec3 q, float t) { return 2.0 * q.z * t + q.y; }

float poly_g(float t)
{
    float r = quad(QR, t), y = quad(QY, t), z = quad(QZ, t);
    return r * r - y * y - z * z;
}
float poly_g1(float t)
{
    return 2.0 * (quad(QR, t) * quad1(QR, t) - quad(QY, t) * quad1(QY, t) - quad(QZ, t) * quad1(QZ, t));
}
float poly_g2(float t)
{
    float r1 = quad1(QR, t), y1 = quad1(QY, t), z1 = quad1(QZ, t);
    return 2.0 * (r1 * r1 + 2.0 * QR.z * quad(QR, t) - y1 * y1 - 2.0 * QY.z * quad(QY, t) - z1 * z1 -
                  2.0 * QZ.z * quad(QZ, t));
}
float poly_g3(float t)
{
    return 12.0 * (QR.z * quad1(QR, t) - QY.z * quad1(QY, t) - QZ.z * quad1(QZ, t));
}

// which: 0 g', 1 g, 2 F3, 3 F2, 4 F1.
float tubes_eval(int which, float t)
{
    if (which == 0) return poly_g1(t);
    if (which == 1) return poly_g(t);
    float g = max(poly_g(t), 0.0), g1 = poly_g1(t);
    if (which == 2) {
        float g2 = poly_g2(t), g3 = poly_g3(t);
        return -4.0 * g * g * g3 + 6.0 * g * g1 * g2 - 3.0 * g1 * g1 * g1;
    }
    float h1 = H1[0] + H1[1] * t;
    if (which == 3) {
        float g2 = poly_g2(t);
        return 4.0 * g * sqrt(g) * H1[1] - 2.0 * g * g2 + g1 * g1;
    }
    return 2.0 * sqrt(g) * h1 - g1;
}

// tubes_eval(which, t) for which = 0..3 and its derivative in t (for the
// Newton steps; F1 goes through tubes_root_f1). g'''' is the constant
// 24 (R2^2 - Y2^2 - Z2^2) of the quadratics' t^2 coefficients;
// F3' = -2 g g' g''' - 4 g^2 g'''' + 6 g g''^2 - 3 g'^2 g'',
// F2' = 6 sqrt(g) g' h'' - 2 g g''' (h''' = 0).
float tubes_eval_d(int which, float t, out float deriv)
{
    float g1 = poly_g1(t), g2 = poly_g2(t);
    if (which == 0) { deriv = g2; return g1; }
    float g = poly_g(t);
    if (which == 1) { deriv = g1; return g; }
    g = max(g, 0.0);
    float g3 = poly_g3(t);
    if (which == 2) {
        float g4 = 24.0 * (QR.z * QR.z - QY.z * QY.z - QZ.z * QZ.z);
        deriv = -2.0 * g * g1 * g3 - 4.0 * g * g * g4 + 6.0 * g * g2 * g2 - 3.0 * g1 * g1 * g2;
        return -4.0 * g * g * g3 + 6.0 * g * g1 * g2 - 3.0 * g1 * g1 * g1;
    }
    float sg = sqrt(g);
    deriv = 6.0 * sg * g1 * H1[1] - 2.0 * g * g3;
    return 4.0 * g * sg * H1[1] - 2.0 * g * g2 + g1 * g1;
}

// Root of tubes_eval(which) in [a, b] given values of opposite sign at the ends.
float tubes_root(int which, float a, float b, float fa, float fb)
{
    if (u_method == 2) {
        // Safeguarded Newton (g', g, F3, F2: polynomials in t and sqrt(g)
        // without singularity): start at the regula falsi point of the
        // bracket (free: fa, fb are known); each step evaluates f and f'
        // once, shrinks the bracket by the sign of f and takes the Newton
        // step, or the bracket's midpoint when that step leaves the bracket
        // (or f' = 0). Stops after a Newton step below 1e-7 (quadratic
        // convergence: the next one would be far below float resolution).
        float x = (a * fb - b * fa) / (fb - fa);
        if (!(x > a && x < b))
            x = 0.5 * (a + b);
        for (int i = 0; i < u_iterations; i++) {
            float d;
            float fx = tubes_eval_d(which, x, d);
            if (fx == 0.0)
                return x;
            if ((fx < 0.0) == (fa < 0.0)) { a = x; fa = fx; } else { b = x; fb = fx; }
            float xn = d != 0.0 ? x - fx / d : a - 1.0;
            bool newton = xn > a && xn < b;
            if (!newton)
                xn = 0.5 * (a + b);
            float step = abs(xn - x);
            x = xn;
            if (b - a <= 1e-7 || (newton && step <= 1e-7))
                break;
        }
        return x;
    }
    if (u_method == 0) {
        for (int i = 0; i < u_iterations; i++) {
            float m = 0.5 * (a + b);
            float fm = tubes_eval(which, m);
            if ((fm < 0.0) == (fa < 0.0)) { a = m; fa = fm; } else { b = m; fb = fm; }
        }
        return 0.5 * (a + b);
    }
    int side = 0;
    float m = 0.5 * (a + b);
    for (int i = 0; i < u_iterations; i++) {
        m = (a * fb - b * fa) / (fb - fa);
        if (!(m > a && m < b))
            m = 0.5 * (a + b);
        float fm = tubes_eval(which, m);
        if (fm == 0.0)
            return m;
        if ((fm < 0.0) == (fa < 0.0)) {
            a = m; fa = fm;
            if (side == -1) fb *= 0.5;
            side = -1;
        } else {
            b = m; fb = fm;
            if (side == 1) fa *= 0.5;
            side = 1;
        }
        if (b - a <= 1e-7)
            break;
    }
    return m;
}

// Root of F1 in [lo, hi], a piece of the g > 0 interval [A, B], in the
// variable theta of t = A + (B - A) sin^2(theta / 2), theta in [0, pi]: where g
// has a root at A or B, sqrt(g) ~ sin theta is smooth in theta, while in t F1
// has the infinite slope of a square root there. Both maps are written from
// the nearer end (sin^2 of a half angle, asin of a square root) so that float
// keeps the resolution of t near A and B.
float tubes_theta_of(float A, float B, float t)
{
    float w = B - A;
    float u = clamp((t - A) / w, 0.0, 1.0);
    return u <= 0.5 ? 2.0 * asin(sqrt(u)) : 3.14159265 - 2.0 * asin(sqrt(clamp((B - t) / w, 0.0, 1.0)));
}
float tubes_t_of(float A, float B, float x)
{
    float w = B - A;
    if (x <= 1.57079633) {
        float s = sin(0.5 * x);
        return A + w * s * s;
    }
    float s = sin(0.5 * (3.14159265 - x));
    return B - w * s * s;
}
float tubes_root_f1(float A, float B, float lo, float hi, float flo, float fhi)
{
    float a = tubes_theta_of(A, B, lo), b = tubes_theta_of(A, B, hi);
    float fa = flo, fb = fhi;
    float x = (a * fb - b * fa) / (fb - fa);
    if (!(x > a && x < b))
        x = 0.5 * (a + b);
    int side = 0;
    for (int i = 0; i < u_iterations; i++) {
        float fx = tubes_eval(4, tubes_t_of(A, B, x));
        if (fx == 0.0)
            break;
        if ((fx < 0.0) == (fa < 0.0)) {
            a = x; fa = fx;
            if (side == -1) fb *= 0.5;
            side = -1;
        } else {
            b = x; fb = fx;
            if (side == 1) fa *= 0.5;
            side = 1;
        }
        // The next point, also after the last step (no evaluation needed).
        x = (a * fb - b * fa) / (fb - fa);
        if (!(x > a && x < b))
            x = 0.5 * (a + b);
        if (b - a <= 1e-7)
            break;
    }
    return tubes_t_of(A, B, x);
}

// Inserts the root of `which` on each piece between sorted knots k[0..n)
// where the ends differ in sign (one root: the piece is monotone) into r,
// sorted; returns the new count (at most 2n - 1).
int tubes_refine(int which, float k[12], int n, out float r[12])
{
    int m = 0;
    r[m++] = k[0];
    float fa = tubes_eval(which, k[0]);
    for (int i = 0; i + 1 < n; i++) {
        float fb = tubes_eval(which, k[i + 1]);
        if ((fa < 0.0) != (fb < 0.0) && fa != 0.0 && fb != 0.0)
            r[m++] = tubes_root(which, k[i], k[i + 1], fa, fb);
        r[m++] = k[i + 1];
        fa = fb;
    }
    return m;
}

// Power-basis coefficients of a quadratic Bezier (c0, c1, c2): c0 + B t + A t^2.
vec3 bezier_power(float c0, float c1, float c2) { return vec3(c0, 2.0 * (c1 - c0), c0 - 2.0 * c1 + c2); }

// Keeps t when the entry into its sphere (distance h - sqrt(g)) lies beyond l_min and
// before the best so far.
void tubes_consider(float t, vec3 pr, vec3 py, vec3 pz, vec3 ph, float l_min, inout float l_hit,
                    inout float t_hit, inout bool found)
{
    float r = quad(pr, t), y = quad(py, t), z = quad(pz, t);
    float l = quad(ph, t) - sqrt(max(r * r - y * y - z * z, 0.0));
    if (l >= l_min && l < l_hit) {
        l_hit = l;
        t_hit = t;
        found = true;
    }
}

// Returns true and the nearest entry beyond l_min: distance l and parameter t.
// q0..q2: control points relative to the ray origin; d: unit direction.
bool tubes_intersect(vec3 q0, vec3 q1, vec3 q2, vec3 rc, vec3 d, float l_min, out float l_hit, out float t_hit)
{
    vec3 u = abs(d.x) < 0.57 ? normalize(cross(d, vec3(1, 0, 0))) : normalize(cross(d, vec3(0, 1, 0)));
    vec3 w = cross(d, u);
    vec3 ph = bezier_power(dot(q0, d), dot(q1, d), dot(q2, d));
    vec3 py = bezier_power(dot(q0, u), dot(q1, u), dot(q2, u));
    vec3 pz = bezier_power(dot(q0, w), dot(q1, w), dot(q2, w));
    vec3 pr = bezier_power(rc.x, rc.y, rc.z);
    float c[5];
    c[0] = pr.x * pr.x - py.x * py.x - pz.x * pz.x;
    c[1] = 2.0 * (pr.x * pr.y - py.x * py.y - pz.x * pz.y);
    c[2] = pr.y * pr.y + 2.0 * pr.x * pr.z - py.y * py.y - 2.0 * py.x * py.z - pz.y * pz.y - 2.0 * pz.x * pz.z;
    c[3] = 2.0 * (pr.y * pr.z - py.y * py.z - pz.y * pz.z);
    c[4] = pr.z * pr.z - py.z * py.z - pz.z * pz.z;
    // Early exit: g's Bernstein coefficients on each half of [0, 1] bound it
    // from above (convex hull property); a half with all of them negative has
    // no hit, and the search runs on the rest of [0, 1] only.
    float be[5] = float[5](c[0], c[0] + 0.25 * c[1], c[0] + 0.5 * c[1] + c[2] / 6.0,
                           c[0] + 0.75 * c[1] + 0.5 * c[2] + 0.25 * c[3], c[0] + c[1] + c[2] + c[3] + c[4]);
    vec4 l1 = 0.5 * vec4(be[0] + be[1], be[1] + be[2], be[2] + be[3], be[3] + be[4]);
    vec3 l2 = 0.5 * (l1.xyz + l1.yzw);
    vec2 l3 = 0.5 * (l2.xy + l2.yz);
    float l4 = 0.5 * (l3.x + l3.y);
    bool left = max(max(be[0], l1.x), max(max(l2.x, l3.x), l4)) >= 0.0;
    bool right = max(max(l4, l3.y), max(max(l2.z, l1.w), be[4])) >= 0.0;
    if (!left && !right)
        return false;
    float t_lo = left ? 0.0 : 0.5, t_hi = right ? 1.0 : 0.5;
    float big = max(max(max(abs(c[0]), abs(c[1])), max(abs(c[2]), abs(c[3]))), abs(c[4]));
    if (!(big > 0.0) || isinf(big))
        return false;
    float k = sqrt(1.0 / big);
    QR = pr * k;
    QY = py * k;
    QZ = pz * k;
    H1[0] = ph.y * k;
    H1[1] = 2.0 * ph.z * k;
    float G2 = c[2] / big, G3 = c[3] / big, G4 = c[4] / big;   // for the knots only
    // The parameter of the curve's smallest speed |p'(t)| (a quadratic in t). Where the
    // sub-segment folds back on itself (collinear controls, the curve running past an end
    // and returning), p' vanishes there, so f''' = 0 there for every ray on top of up to
    // two other roots: the "at most one root of f'''" assumption fails, and a minimum of f
    // was lost (0.09 r depth errors). It is a knot of the f''' search; elsewhere it only
    // splits an interval once more.
    vec3 e1 = q1 - q0, ed = (q1 - q0) - (q2 - q1);
    float ed2 = dot(ed, ed);
    float t_slow = ed2 > 0.0 ? dot(e1, ed) / ed2 : -1.0;

    // Roots of g'' analytically, then g', then g.
    float knots[12], roots[12];
    int n = 0;
    knots[n++] = t_lo;
    float qa = 12.0 * G4, qb = 6.0 * G3, qc = 2.0 * G2;
    float disc = qb * qb - 4.0 * qa * qc;
    if (qa != 0.0 && disc > 0.0) {
        float s = -0.5 * (qb + (qb >= 0.0 ? sqrt(disc) : -sqrt(disc)));
        float x1 = s / qa, x2 = s != 0.0 ? qc / s : x1;
        float lo = min(x1, x2), hi = max(x1, x2);
        if (lo > t_lo && lo < t_hi) knots[n++] = lo;
        if (hi > t_lo && hi < t_hi && hi != lo) knots[n++] = hi;
    } else if (qa == 0.0 && qb != 0.0) {
        float x = -qc / qb;
        if (x > t_lo && x < t_hi) knots[n++] = x;
    }
    knots[n++] = t_hi;
    n = tubes_refine(0, knots, n, roots);   // g' roots: g monotone between
    n = tubes_refine(1, roots, n, knots);   // g roots inserted
    // Intervals where g > 0: consecutive breakpoints with g(mid) > 0. Merge
    // adjacent positive pieces (split at g' roots) into one interval.
    bool found = false;
    l_hit = 3.4e38;
    t_hit = 0.0;
    int i = 0;
    while (i + 1 < n) {
        if (!(poly_g(0.5 * (knots[i] + knots[i + 1])) > 0.0)) { i++; continue; }
        int j = i + 1;
        while (j + 1 < n && poly_g(0.5 * (knots[j] + knots[j + 1])) > 0.0)
            j++;
        float a = knots[i], b = knots[j];
        i = j;
        float k3[12], k2s[12], k1[12];
        int n3 = 0;
        k3[n3++] = a;
        if (t_slow > a && t_slow < b)
            k3[n3++] = t_slow;
        k3[n3++] = b;
        int m3 = tubes_refine(2, k3, n3, k2s);  // knots a, [t_slow], b and the f''' roots between
        int m2 = tubes_refine(3, k2s, m3, k1);  // + f'' roots: f' monotone between
        // Candidates: t = 0 and t = 1 when inside the interval, and every local
        // minimum of f: a - to + crossing of f' inside a piece between knots (f' is
        // monotone there), or a knot where f' is exactly 0 between a negative and a
        // positive neighbour. The latter was lost before: at a collinear fold f' is 0 in
        // float exactly on the root of f''' that is a knot, so neither piece beside it
        // shows a crossing. (Only minima: for a ray starting inside the sweep an entry
        // into some sphere t can lie inside others, so no other t may be taken.)
        if (a == 0.0)
            tubes_consider(0.0, pr, py, pz, ph, l_min, l_hit, t_hit, found);
        if (b == 1.0)
            tubes_consider(1.0, pr, py, pz, ph, l_min, l_hit, t_hit, found);
        float f_prev = 0.0;
        float fa = tubes_eval(4, k1[0]);
        for (int e = 0; e + 1 < m2; e++) {
            float fb = tubes_eval(4, k1[e + 1]);
            if (fa < 0.0 && fb > 0.0)
                tubes_consider(u_method >= 2 ? tubes_root_f1(a, b, k1[e], k1[e + 1], fa, fb)
                                             : tubes_root(4, k1[e], k1[e + 1], fa, fb),
                               pr, py, pz, ph, l_min, l_hit, t_hit, found);
            if (e > 0 && fa == 0.0 && f_prev < 0.0 && fb > 0.0)
                tubes_consider(k1[e], pr, py, pz, ph, l_min, l_hit, t_hit, found);
            f_prev = fa;
            fa = fb;
        }
    }
    return found;
}
