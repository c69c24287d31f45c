/* gen_tornado_field.h — Crawfis' tornado formula, written once for two number types.
 *
 * Included twice by gen_tornado.c (and by nothing else): with SL_TORNADO_NUM
 * `double` for the tracer (values only, as fast as plain code) and with
 * `sl_dual3` for the curl (values with exact gradients, gen_dual.h). The
 * includer names the two functions (SL_TORNADO_SLICE, SL_TORNADO_FIELD);
 * this file #undefs the three names at its end. The operations are the
 * type-generic SL_NUM_* macros, so both instances run the same operations in
 * the same order and their values agree bit for bit. Branches are taken by
 * value. No include guard on purpose.
 */
#define SL_TN SL_TORNADO_NUM

/* The vortex at height z: centre (xc, yc), funnel radius r, damping radius r2. */
static void SL_TORNADO_SLICE(SL_TN z, double phase, SL_TN *xc, SL_TN *yc, SL_TN *r, SL_TN *r2)
{
    *xc = SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.5),
                     SL_NUM_SCALE(0.1, SL_NUM_SIN(SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.04 * phase), SL_NUM_SCALE(10.0, z)))));
    *yc = SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.5),
                     SL_NUM_SCALE(0.1, SL_NUM_COS(SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.03 * phase), SL_NUM_SCALE(3.0, z)))));
    *r = SL_NUM_ADD(SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.1), SL_NUM_MUL(SL_NUM_SCALE(0.4, z), z)),
                    SL_NUM_MUL(SL_NUM_SCALE(0.1, z), SL_NUM_SIN(SL_NUM_SCALE(8.0, z))));
    *r2 = SL_NUM_ADD(SL_NUM_CONST(SL_TN, 0.2), SL_NUM_SCALE(0.1, z));
}

/* v = field(p) at time phase `phase`. */
static void SL_TORNADO_FIELD(const double p[3], double phase, SL_TN v[3])
{
    SL_TN x = SL_NUM_VAR(SL_TN, p[0], 0), y = SL_NUM_VAR(SL_TN, p[1], 1), z = SL_NUM_VAR(SL_TN, p[2], 2);
    SL_TN xc, yc, r, r2;
    SL_TORNADO_SLICE(z, phase, &xc, &yc, &r, &r2);
    SL_TN dx = SL_NUM_SUB(x, xc), dy = SL_NUM_SUB(y, yc);
    SL_TN dist = SL_NUM_SQRT(SL_NUM_ADD(SL_NUM_MUL(dx, dx), SL_NUM_MUL(dy, dy)));
    SL_TN scale = SL_NUM_FABS(SL_NUM_SUB(r, dist));
    scale = SL_NUM_VALUE(scale) > SL_NUM_VALUE(r2) ? SL_NUM_SUB(SL_NUM_CONST(SL_TN, 0.8), scale)
                                                   : SL_NUM_CONST(SL_TN, 1.0);
    SL_TN z0 = SL_NUM_SCALE(0.1, SL_NUM_SUB(SL_NUM_CONST(SL_TN, 0.1), SL_NUM_MUL(dist, z)));
    if (SL_NUM_VALUE(z0) < 0.0)
        z0 = SL_NUM_CONST(SL_TN, 0.0);
    SL_TN d3 = SL_NUM_SQRT(SL_NUM_ADD(SL_NUM_MUL(dist, dist), SL_NUM_MUL(z0, z0)));
    scale = SL_NUM_DIV(SL_NUM_MUL(SL_NUM_SUB(SL_NUM_ADD(r, r2), d3), scale),
                       SL_NUM_ADD(d3, SL_NUM_CONST(SL_TN, 1e-11)));
    /* The field is singular at z = -1, far below the box; lines never get
     * there, but a rejected trial line might, so keep it finite. */
    scale = SL_NUM_DIV(scale, SL_NUM_FMAX(SL_NUM_ADD(SL_NUM_CONST(SL_TN, 1.0), z), SL_NUM_CONST(SL_TN, 1e-3)));
    v[0] = SL_NUM_ADD(SL_NUM_MUL(scale, dy), SL_NUM_SCALE(0.1, dx));
    v[1] = SL_NUM_ADD(SL_NUM_MUL(SL_NUM_SCALE(-1.0, scale), dx), SL_NUM_SCALE(0.1, dy));
    v[2] = SL_NUM_MUL(scale, z0);
}

#undef SL_TN
#undef SL_TORNADO_NUM
#undef SL_TORNADO_SLICE
#undef SL_TORNADO_FIELD
