#version 460
#extension GL_GOOGLE_include_directive : require
// Shadow-map rasterisation (core/passes/shadow_maps.cpp): one face / layer per draw, the whole
// scene pulled from the scene set (vkCmdDraw of 3 vertices per triangle, no vertex buffers).
#include "common/scene.glsl"
#include "common/shadow_pc.glsl"

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec2 outUv;
layout(location = 2) flat out uint outTriangle;

void main() {
    uint triangle = uint(gl_VertexIndex) / 3u;
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outWorldPos = v.position;
    outUv = v.uv;
    outTriangle = triangle;
    gl_Position = pc.viewProj * vec4(v.position, 1.0);
}
