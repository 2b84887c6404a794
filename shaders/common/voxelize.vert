#version 460
#extension GL_GOOGLE_include_directive : require
// Voxelization (core/voxel/voxelizer.cpp), stage 1: pulls the scene's vertices (one vkCmdDraw of
// 3 vertices per triangle, like gbuffer.vert) and moves them to grid space.
#include "common/scene.glsl"
#include "common/voxel_pc.glsl"

layout(location = 0) out vec3 outGrid;
layout(location = 1) flat out uint outTriangle;

void main() {
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outGrid = voxelWorldToGrid(pc.grid, v.position);
    outTriangle = uint(gl_VertexIndex) / 3u;
    gl_Position = vec4(0.0, 0.0, 0.5, 1.0);  // placed by the geometry shader
}
