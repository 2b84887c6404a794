#pragma once
/**
 * The voxel grid shared by the voxel GI techniques (docs/voxelization.md): an axis-aligned cube
 * fitted to the scene bounds, `resolution` voxels per axis. Grid space g = (p - origin) /
 * voxelSize; voxel i spans [i, i+1)^3 and is sampled at its centre (notes 003 §7.6). Mirrored
 * in shaders/common/voxel_grid.glsl through GpuVoxelGrid.
 */
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab {

/** Mirrors VoxelGridInfo in shaders/common/voxel_grid.glsl. */
struct GpuVoxelGrid {
    glm::vec4 originVoxelSize;  // xyz minimum corner, w voxel size
    glm::uvec4 resolution;      // x voxels per axis, y accumulator mode (0 float, 1 fixed)
};
static_assert(sizeof(GpuVoxelGrid) == 32);

class VoxelGrid {
public:
    static constexpr uint32_t kMinResolution = 32;
    static constexpr uint32_t kMaxResolution = 512;
    /** Relative margin added to the largest extent so surfaces on the bounds stay inside. */
    static constexpr float kDefaultMargin = 0.02f;

    VoxelGrid() = default;
    /** Cube of side = largest extent x (1 + margin), centred on the bounds. Throws gilab::Error
     *  naming "resolution" outside [32, 512], or for invalid bounds / negative margin. */
    VoxelGrid(const Bounds& bounds, uint32_t resolution, float margin = kDefaultMargin);
    /** An explicit cube (tests, or a technique with its own placement). Same checks. */
    static VoxelGrid fromCube(const glm::vec3& origin, float side, uint32_t resolution);

    uint32_t resolution() const { return m_resolution; }
    const glm::vec3& origin() const { return m_origin; }
    float side() const { return m_side; }
    float voxelSize() const { return m_side / float(m_resolution); }
    size_t voxelCount() const { return size_t(m_resolution) * m_resolution * m_resolution; }

    glm::vec3 worldToGrid(const glm::vec3& p) const { return (p - m_origin) / voxelSize(); }
    glm::vec3 gridToWorld(const glm::vec3& g) const { return m_origin + g * voxelSize(); }
    /** Texture coordinate in [0, 1]^3 for sampling the volumes. */
    glm::vec3 worldToUvw(const glm::vec3& p) const { return (p - m_origin) / m_side; }
    glm::ivec3 voxelOf(const glm::vec3& p) const { return glm::ivec3(glm::floor(worldToGrid(p))); }
    glm::vec3 voxelCenter(const glm::ivec3& c) const { return gridToWorld(glm::vec3(c) + 0.5f); }
    bool contains(const glm::ivec3& c) const;
    /** x + N (y + N z), the layout of readbacks and accumulators. */
    size_t linearIndex(const glm::ivec3& c) const {
        return size_t(c.x) + m_resolution * (size_t(c.y) + size_t(m_resolution) * size_t(c.z));
    }
    GpuVoxelGrid gpu(uint32_t accumulatorMode = 0) const;

private:
    glm::vec3 m_origin{0.0f};
    float m_side = 1.0f;
    uint32_t m_resolution = kMinResolution;
};

/** Throws gilab::Error naming `resolution` unless 32 <= resolution <= 512. */
void checkVoxelResolution(uint32_t resolution);

}  // namespace gilab
