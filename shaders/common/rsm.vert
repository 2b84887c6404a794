#version 460
#extension GL_GOOGLE_include_directive : require
// Reflective shadow map raster (core/vpl/rsm.h): the scene pulled from the scene set, one draw.
#include "common/scene.glsl"
#include "common/rsm_pc.glsl"

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec2 outUv;
layout(location = 3) flat out uint outTriangle;

void main() {
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outWorldPos = v.position;
    outNormal = v.normal;
    outUv = v.uv;
    outTriangle = uint(gl_VertexIndex) / 3u;
    gl_Position = pc.viewProj * vec4(v.position, 1.0);
}
