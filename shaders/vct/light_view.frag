#version 460
#extension GL_GOOGLE_include_directive : require
// Light-view map (a reflective shadow map reduced to what the photons need): the world position
// of the nearest surface per texel, w = 1. Alpha-masked texels are cut out as in the shadow maps.
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec2 inUv;
layout(location = 2) flat in uint inTriangle;

layout(location = 0) out vec4 outPosition;

void main() {
    Material m = fetchMaterial(inTriangle);
    if (alphaCutout(m, inUv)) discard;
    outPosition = vec4(inWorldPos, 1.0);
}
