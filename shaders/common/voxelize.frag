#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
// Voxelization with float atomics (VK_EXT_shader_atomic_float): see voxel_voxelize_body.glsl.
#include "common/voxel_voxelize_body.glsl"
