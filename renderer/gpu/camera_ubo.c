/* camera_ubo.c — uploads the frame's camera as the std140 block of gpu/glsl/camera.glsl.
 * Render thread only. */
#include "sl_gpu.h"

#include "../core/sl_camera.h"

typedef struct camera_block {
    float view[16], projection[16], view_projection[16];
    float eye[4], forward[4], right[4], up[4], viewport[4], near[4];
} camera_block;

static void put3(float out[4], sl_vec3 v)
{
    out[0] = (float)v.x;
    out[1] = (float)v.y;
    out[2] = (float)v.z;
    out[3] = 0.0f;
}

void sl_camera_ubo_update(GLuint *buffer, const sl_view *view)
{
    camera_block b;
    sl_mat4_to_float(view->view_matrix, b.view);
    sl_mat4_to_float(view->projection, b.projection);
    sl_mat4_to_float(view->view_projection, b.view_projection);
    put3(b.eye, sl_v3_sub(view->camera.eye, view->origin));
    put3(b.forward, view->forward);
    put3(b.right, view->right);
    put3(b.up, view->upv);
    b.viewport[0] = (float)view->width;
    b.viewport[1] = (float)view->height;
    b.viewport[2] = (float)view->tan_half_fov;
    b.viewport[3] = (float)view->aspect;
    b.near[0] = (float)view->near_plane;
    b.near[1] = b.near[2] = b.near[3] = 0.0f;
    if (!*buffer) {
        glCreateBuffers(1, buffer);
        glNamedBufferStorage(*buffer, sizeof b, NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    glNamedBufferSubData(*buffer, 0, sizeof b, &b);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, *buffer);
}
