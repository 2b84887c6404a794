#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer rasterisation (core/passes/gbuffer.cpp): the whole scene in one vkCmdDraw of
// 3 vertices per triangle, pulled from the scene set, so the triangle id is exact and needs no
// gl_PrimitiveID (geometry-shader capability).
#include "common/scene.glsl"
#include "common/gbuffer_pc.glsl"

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
