/* sl_backend.h — the one rule that picks a technique's execution: GL, or its CPU twin.
 *
 * A technique with two executions of one model (tubes: gl | embree; voxel_lines:
 * gl | cpu) offers an enum parameter `backend` = auto | gl | <cpu name>, declared
 * with SL_BACKEND_PARAM so every such technique spells it the same. auto picks the
 * CPU execution when the GL device is a software rasterizer (llvmpipe, softpipe,
 * swrast: sl_gpu_is_software) and the CPU execution was built in; gl otherwise.
 * Asking for the CPU execution in a build without it is an error that names what
 * is missing, never a silent fall-back. Pure decision: no GL, any thread.
 */
#ifndef SL_BACKEND_H
#define SL_BACKEND_H

#include "sl_status.h"

/* The choices' indices (a technique's choices array is {"auto", "gl", "<cpu>", NULL}). */
typedef enum sl_backend_choice { SL_BACKEND_AUTO = 0, SL_BACKEND_CHOICE_GL = 1, SL_BACKEND_CHOICE_CPU = 2 } sl_backend_choice;
typedef enum sl_backend { SL_BACKEND_GL = 0, SL_BACKEND_CPU = 1 } sl_backend;

/* The schema entry (re-prepares: each execution prepares its own data). */
#define SL_BACKEND_PARAM(choices, cpu_text) \
    {"backend", SL_PARAM_ENUM, 0, 0, {0}, choices, "", \
     "where the frame is drawn: auto (" cpu_text " on a software GL device such as llvmpipe, gl on a GPU), gl, or " \
     cpu_text " (the same model and picture)", SL_INVALIDATE_PREPARED}

/* What the rule needs to know about one technique's CPU execution. */
typedef struct sl_backend_cpu {
    const char *name;      /* the choice's name: "embree", "cpu" */
    int built;             /* 1 when this build has it */
    const char *missing;   /* when not built: what to install, e.g. "Debian libembree-dev (Embree 3.13)" */
} sl_backend_cpu;

/* Decides the execution for `choice` (an sl_backend_choice) on a GL device that
 * is software (1) or not (0). SL_ERR_UNSUPPORTED, naming the technique, the choice
 * and cpu->missing, when the CPU execution is asked for and not built;
 * SL_ERR_INVALID for a choice outside the enum. *out is set on success only. */
sl_status sl_backend_decide(const char *technique, int choice, int gpu_is_software, const sl_backend_cpu *cpu,
                            sl_backend *out, sl_err *err);

/* "gl" or cpu->name. */
const char *sl_backend_name(sl_backend backend, const sl_backend_cpu *cpu);

#endif
