/* backend.c — the backend rule of sl_backend.h: auto = the CPU execution on a software
 * GL device when it is built, else GL; an explicit choice is obeyed or refused. */
#include "sl_backend.h"

sl_status sl_backend_decide(const char *technique, int choice, int gpu_is_software, const sl_backend_cpu *cpu,
                            sl_backend *out, sl_err *err)
{
    switch (choice) {
    case SL_BACKEND_AUTO:
        *out = gpu_is_software && cpu->built ? SL_BACKEND_CPU : SL_BACKEND_GL;
        return SL_OK;
    case SL_BACKEND_CHOICE_GL:
        *out = SL_BACKEND_GL;
        return SL_OK;
    case SL_BACKEND_CHOICE_CPU:
        if (!cpu->built)
            return sl_err_set(err, SL_ERR_UNSUPPORTED,
                              "%s: backend = %s: this build has no %s execution (install %s and rebuild, or use "
                              "backend = gl or auto)",
                              technique, cpu->name, cpu->name, cpu->missing);
        *out = SL_BACKEND_CPU;
        return SL_OK;
    default:
        return sl_err_set(err, SL_ERR_INVALID, "%s: backend choice %d: want auto, gl or %s", technique, choice,
                          cpu->name);
    }
}

const char *sl_backend_name(sl_backend backend, const sl_backend_cpu *cpu)
{
    return backend == SL_BACKEND_CPU ? cpu->name : "gl";
}
