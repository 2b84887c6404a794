#include "core/voxel/voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"

namespace gilab {

void checkVoxelResolution(uint32_t resolution) {
    if (resolution < VoxelGrid::kMinResolution || resolution > VoxelGrid::kMaxResolution) {
        throw Error("voxel grid: resolution = " + std::to_string(resolution) +
                    " is out of range [" + std::to_string(VoxelGrid::kMinResolution) + ", " +
                    std::to_string(VoxelGrid::kMaxResolution) + "]");
    }
}

VoxelGrid::VoxelGrid(const Bounds& bounds, uint32_t resolution, float margin) {
    checkVoxelResolution(resolution);
    if (!bounds.valid()) throw Error("voxel grid: the scene bounds are empty");
    if (!(margin >= 0.0f)) throw Error("voxel grid: margin must be >= 0");
    const glm::vec3 extent = bounds.extent();
    float side = std::max({extent.x, extent.y, extent.z}) * (1.0f + margin);
    if (!(side > 0.0f) || !std::isfinite(side)) side = 1.0f;  // a single point or plane
    m_resolution = resolution;
    m_side = side;
    m_origin = bounds.center() - glm::vec3(0.5f * side);
}

VoxelGrid VoxelGrid::fromCube(const glm::vec3& origin, float side, uint32_t resolution) {
    checkVoxelResolution(resolution);
    if (!(side > 0.0f) || !std::isfinite(side)) throw Error("voxel grid: side must be > 0");
    VoxelGrid g;
    g.m_origin = origin;
    g.m_side = side;
    g.m_resolution = resolution;
    return g;
}

bool VoxelGrid::contains(const glm::ivec3& c) const {
    const int n = int(m_resolution);
    return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < n && c.y < n && c.z < n;
}

GpuVoxelGrid VoxelGrid::gpu(uint32_t accumulatorMode) const {
    return {glm::vec4(m_origin, voxelSize()), glm::uvec4(m_resolution, accumulatorMode, 0, 0)};
}

}  // namespace gilab
