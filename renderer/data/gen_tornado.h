/* gen_tornado.h — the tornado generator's field with its exact curl, for tests and derived data.
 *
 * The same formula the `tornado` family traces (gen_tornado.c), evaluated on
 * forward-mode dual numbers (gen_dual.h): the value and the curl come from
 * one code path, with analytic derivatives, not finite differences. The
 * field is piecewise smooth: at its branch switches (|r - dist| = r2, the
 * clamp of z0 at 0, the axis dist = 0) the curl is that of the branch picked
 * by value. Internal to data/ and its tests; any thread; no state.
 */
#ifndef SL_GEN_TORNADO_H
#define SL_GEN_TORNADO_H

/* v = field(p) at time phase `phase`, curl = (curl v)(p). */
void sl_gen_tornado_eval(const double p[3], double phase, double v[3], double curl[3]);

#endif
