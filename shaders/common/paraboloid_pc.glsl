// Push constants of the layered paraboloid maps (core/vpl/paraboloid_maps.cpp, ParaboloidPush).
#ifndef GILAB_PARABOLOID_PC_GLSL
#define GILAB_PARABOLOID_PC_GLSL
layout(push_constant, std430) uniform ParaboloidPush {
    float far;           // radial distance mapped to depth 1
    float maxEdgeAngle;  // radians: a triangle is split until its edges subtend at most this
    uint maxSubdivision; // most splits per edge (1 = none)
    uint resolution;     // texels per side
} pc;
#endif
