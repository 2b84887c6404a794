// Push constants of the G-buffer pipeline (mirrored by GBufferPush in core/passes/gbuffer.cpp).
#ifndef GILAB_GBUFFER_PC_GLSL
#define GILAB_GBUFFER_PC_GLSL

layout(push_constant, std430) uniform GBufferPush {
    mat4 viewProj;       // camera.projection(aspect) * camera.view()
    vec4 cameraPosition; // xyz world
} pc;

#endif  // GILAB_GBUFFER_PC_GLSL
