// Push constants of the shadow-map pipeline (mirrored by ShadowPush in shadow_maps.cpp).
#ifndef GILAB_SHADOW_PC_GLSL
#define GILAB_SHADOW_PC_GLSL

layout(push_constant, std430) uniform ShadowPush {
    mat4 viewProj;     // world -> clip of this face / layer
    vec4 origin;       // xyz light position or entry-plane point; w 1 = orthographic
    vec4 direction;    // xyz light direction (orthographic distance axis)
    vec4 skipPlane;    // xyz unit normal, w = dot(normal, point): emitter plane of a sample
    vec4 params;       // x skip-plane half thickness (0 = no plane)
} pc;

#endif  // GILAB_SHADOW_PC_GLSL
