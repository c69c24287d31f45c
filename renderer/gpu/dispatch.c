/* dispatch.c — 1-D compute dispatches of any size, split at the driver's work-group limit.
 *
 * GL guarantees only 65535 work groups per dimension (llvmpipe gives exactly
 * that), so every 1-D dispatch of a data-sized grid goes through here: each
 * chunk tells the shader its first group in a uniform. Render thread only.
 */
#include "sl_gpu.h"

unsigned sl_gpu_max_groups(void)
{
    GLint limit = 0;
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &limit);
    return limit > 0 ? (unsigned)limit : 65535u; /* the GL 4.3 minimum */
}

void sl_gpu_dispatch_chunked(GLint group_base_location, size_t groups, unsigned max_groups)
{
    unsigned limit = sl_gpu_max_groups();
    if (max_groups == 0 || max_groups > limit)
        max_groups = limit;
    for (size_t first = 0; first < groups; first += max_groups) {
        size_t count = groups - first < max_groups ? groups - first : max_groups;
        if (group_base_location >= 0)
            glUniform1ui(group_base_location, (GLuint)first);
        glDispatchCompute((GLuint)count, 1, 1);
    }
}
