// The octree's description (mirrors gilab::vct::GpuSvoInfo, std140 uniform buffer).
#ifndef GILAB_VCT_SVO_INFO_GLSL
#define GILAB_VCT_SVO_INFO_GLSL

struct SvoInfo {
    vec4 originVoxelSize;  // grid minimum corner, w = v0
    uvec4 dims;            // x N, y leaf depth D, z bricks per pool row (x), w levels (D + 1)
    uvec4 capacity;        // x nodes, y bricks, z 1 = float atomics, w bricks per pool column (y)
    uvec4 radiance;        // x radiance bricks, y per pool row (x), z per pool column (y),
                           // w 0 isotropic, else anisotropic (6 directional bricks per
                           // non-leaf node; 1 pair filter, 2 slab filter)
    uvec4 depthInfo[16];   // per depth: x occupancy word offset, y cells per axis, z node bound
};

#endif  // GILAB_VCT_SVO_INFO_GLSL
