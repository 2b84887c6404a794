// Push constants of the reflective shadow map raster (core/vpl/rsm.cpp, RsmPush).
#ifndef GILAB_RSM_PC_GLSL
#define GILAB_RSM_PC_GLSL
layout(push_constant, std430) uniform RsmPush {
    mat4 viewProj;  // world -> clip of the light's 2D view (reversed Z)
    vec4 toLight;   // xyz light position (w = 0) or unit direction toward the light (w = 1)
} pc;
#endif
