// The visibility cluster of a surface point (Noël & Biri 2014 §V-A; notes 004 §7 point 1), the
// same lookup for G-buffer pixels and for VPLs: the point moved half a voxel along its normal ->
// voxel of the topology grid -> its cluster. A point still in a solid voxel takes the empty
// voxel on its normal's side: the one of its 26 neighbours whose direction has the largest dot
// product with the normal (ties, at corners, go toward `towards`, e.g. the viewer).
// The includer declares `uint voxelCluster[]` (a storage buffer) and includes voxel_grid.glsl.
#ifndef GILAB_TOPOVPL_CLUSTER_LOOKUP_GLSL
#define GILAB_TOPOVPL_CLUSTER_LOOKUP_GLSL

uint topoClusterAt(VoxelGridInfo grid, ivec3 c) {
    if (!voxelInside(grid, c)) return 0xFFFFFFFFu;
    return voxelCluster[voxelLinearIndex(grid, c)];
}

uint topoSurfaceCluster(VoxelGridInfo grid, vec3 p, vec3 n, vec3 towards) {
    // Half a voxel off the surface: the point lies on a voxel face as often as not, and the
    // voxel behind the surface is not its side.
    vec3 q = p + n * (0.5 * voxelSize(grid));
    ivec3 v = voxelCoordOf(grid, q);
    uint id = topoClusterAt(grid, v);
    if (id != 0xFFFFFFFFu) return id;
    float best = -2.0;
    vec3 view = towards - p;
    view = dot(view, view) > 0.0 ? normalize(view) : n;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                ivec3 d = ivec3(dx, dy, dz);
                if (d == ivec3(0)) continue;
                uint c = topoClusterAt(grid, v + d);
                if (c == 0xFFFFFFFFu) continue;
                vec3 dir = normalize(vec3(d));
                float score = dot(dir, n) + 1e-3 * dot(dir, view);
                if (score > best) {
                    best = score;
                    id = c;
                }
            }
    return id;
}

#endif  // GILAB_TOPOVPL_CLUSTER_LOOKUP_GLSL
