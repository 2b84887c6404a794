#version 460
#extension GL_GOOGLE_include_directive : require
// Octree build, step 5: leaf geometry bricks (Crassin §4.2.2): sample s of leaf cell n is the
// voxel 2n + s of the voxelizer's volume (its centre), stored as (a * albedo, a); samples past
// the grid are empty. Neighbouring bricks read the same voxel for a shared sample, so the
// duplicates agree without a transfer. The leaf's normal brick (same pool layout) gets the
// voxelizer's normal texel (xyz unit mean normal, w its length; 0 where the voxel is empty), the
// input of the facing weight (common/voxel_facing.glsl; svo_filter_aniso.comp, svo_sample.glsl).
#include "svo_common.glsl"

layout(set = 1, binding = 0) uniform sampler3D voxelAlbedoOpacity;
layout(set = 1, binding = 1) uniform sampler3D voxelNormal;
layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = svo.dims.y;
    uint t = svoThread();
    uint node = svoLevelBegin(d) + t / 27u;
    if (node >= svoLevelEnd(d)) return;
    uint brick = svoWord(node, SVO_W_BRICK);
    if (brick == SVO_NONE) return;
    int k = int(t % 27u);
    ivec3 s = ivec3(k % 3, (k / 3) % 3, k / 9);
    ivec3 v = 2 * ivec3(svoUnpackCoord(svoWord(node, SVO_W_COORD))) + s;
    vec4 g = vec4(0.0), nl = vec4(0.0);
    if (all(lessThan(v, ivec3(svo.dims.x)))) {
        vec4 ao = texelFetch(voxelAlbedoOpacity, v, 0);
        float a = clamp(ao.a, 0.0, 1.0);
        g = vec4(max(ao.rgb, vec3(0.0)) * a, a);
        if (a > 0.0) {
            nl = texelFetch(voxelNormal, v, 0);
            nl = vec4(clamp(nl.xyz, vec3(-1.0), vec3(1.0)), clamp(nl.w, 0.0, 1.0));
        }
    }
    imageStore(svoGeometry, svoBrickOrigin(brick) + s, g);
    imageStore(svoNormals, svoBrickOrigin(brick) + s, nl);
}
