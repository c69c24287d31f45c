// tubes_silhouette.frag.glsl — the empty fragment stage of the paper's silhouette-cost
// experiment (Russig et al. 4): every box fragment is discarded, so a frame measures
// vertex, geometry and rasterization work only. Used when `silhouette_only` is on.
layout(location = 0) out vec4 o_color;

void main()
{
    discard;
}
