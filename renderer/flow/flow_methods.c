/* flow_methods.c — the Butcher tableaux of every streamline solver, one
 * table (sl_flow.h lists them). The compute shader receives these same
 * numbers (flow_gpu.c sets them as uniforms, doubles where the variant is), so CPU and GPU run identical
 * coefficients. Sources: Hairer, Norsett, Wanner, "Solving ODEs I" (rk3,
 * rk4, 3/8 rule, Fehlberg 4(5)); Bogacki & Shampine 1989. Constant data.
 */
#include <string.h>

#include "sl_flow.h"

const sl_flow_method sl_flow_methods[SL_FLOW_SOLVER_COUNT] = {
    [SL_FLOW_RK1] = {"rk1", "explicit Euler (order 1)", 1, 1, 0, {{0}}, {1.0}, {0}},
    [SL_FLOW_RK2] = {"rk2", "explicit midpoint rule (order 2)", 2, 2, 0,
                     {{0}, {0.5}}, {0.0, 1.0}, {0}},
    [SL_FLOW_RK3] = {"rk3", "Kutta's third-order method", 3, 3, 0,
                     {{0}, {0.5}, {-1.0, 2.0}}, {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0}, {0}},
    [SL_FLOW_RK4] = {"rk4", "classic fourth-order Runge-Kutta", 4, 4, 0,
                     {{0}, {0.5}, {0.0, 0.5}, {0.0, 0.0, 1.0}},
                     {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0}, {0}},
    [SL_FLOW_RK4_38] = {"rk4_38", "Kutta's 3/8 rule (order 4)", 4, 4, 0,
                        {{0}, {1.0 / 3.0}, {-1.0 / 3.0, 1.0}, {1.0, -1.0, 1.0}},
                        {1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0}, {0}},
    [SL_FLOW_RKF5] = {"rkf5", "Runge-Kutta-Fehlberg, 5th-order solution, fixed step", 6, 5, 0,
                      {{0},
                       {1.0 / 4.0},
                       {3.0 / 32.0, 9.0 / 32.0},
                       {1932.0 / 2197.0, -7200.0 / 2197.0, 7296.0 / 2197.0},
                       {439.0 / 216.0, -8.0, 3680.0 / 513.0, -845.0 / 4104.0},
                       {-8.0 / 27.0, 2.0, -3544.0 / 2565.0, 1859.0 / 4104.0, -11.0 / 40.0}},
                      {16.0 / 135.0, 0.0, 6656.0 / 12825.0, 28561.0 / 56430.0, -9.0 / 50.0, 2.0 / 55.0},
                      {0}},
    [SL_FLOW_HE] = {"he", "Heun-Euler 2(1), adaptive", 2, 2, 1,
                    {{0}, {1.0}}, {0.5, 0.5}, {1.0, 0.0}},
    [SL_FLOW_BS] = {"bs", "Bogacki-Shampine 3(2), adaptive", 4, 3, 2,
                    {{0}, {0.5}, {0.0, 0.75}, {2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0}},
                    {2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0},
                    {7.0 / 24.0, 1.0 / 4.0, 1.0 / 3.0, 1.0 / 8.0}},
    [SL_FLOW_RKF45] = {"rkf45", "Runge-Kutta-Fehlberg 4(5), adaptive, 5th order propagated", 6, 5, 4,
                       {{0},
                        {1.0 / 4.0},
                        {3.0 / 32.0, 9.0 / 32.0},
                        {1932.0 / 2197.0, -7200.0 / 2197.0, 7296.0 / 2197.0},
                        {439.0 / 216.0, -8.0, 3680.0 / 513.0, -845.0 / 4104.0},
                        {-8.0 / 27.0, 2.0, -3544.0 / 2565.0, 1859.0 / 4104.0, -11.0 / 40.0}},
                       {16.0 / 135.0, 0.0, 6656.0 / 12825.0, 28561.0 / 56430.0, -9.0 / 50.0, 2.0 / 55.0},
                       {25.0 / 216.0, 0.0, 1408.0 / 2565.0, 2197.0 / 4104.0, -1.0 / 5.0, 0.0}},
};

const char *const sl_flow_solver_names[SL_FLOW_SOLVER_COUNT + 1] = {
    "rk1", "rk2", "rk3", "rk4", "rk4_38", "rkf5", "he", "bs", "rkf45", NULL,
};

int sl_flow_solver_find(const char *name)
{
    if (!name)
        return -1;
    if (strcmp(name, "rk4-38") == 0 || strcmp(name, "rk4-3/8") == 0)
        return SL_FLOW_RK4_38;
    for (int i = 0; i < SL_FLOW_SOLVER_COUNT; i++)
        if (strcmp(name, sl_flow_methods[i].name) == 0)
            return i;
    return -1;
}
