#pragma once
/**
 * The compacted voxelization cvgi's set-up works on (Cosin Ayerbe & Patow 2022 §4.1, Figs. 3-4):
 * the occupied voxels in prefix-sum order (ascending linear index, the paper's "hashed position"
 * buffer), each with the summary of its fragment list. Filled from the GPU voxelizer's fragment
 * lists (core/voxel/voxel_fragments.h) or built directly by the CPU tests.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gilab::cvgi {

inline constexpr uint32_t kEmpty = 0xFFFFFFFFu;

/** Face / axis-direction order used everywhere in cvgi: -x, +x, -y, +y, -z, +z. */
inline glm::ivec3 axisDirection(uint32_t face) {
    glm::ivec3 d(0);
    d[int(face / 2)] = (face & 1u) ? 1 : -1;
    return d;
}

struct CompactVoxels {
    uint32_t resolution = 0;               // N voxels per axis
    std::vector<uint32_t> linear;          // [V] x + N (y + N z), strictly ascending
    std::vector<uint32_t> indexOf;         // [N^3] compact index of a voxel, kEmpty if empty
    std::vector<glm::vec3> albedo;         // [V] mean fragment reflectance (linear)
    std::vector<glm::vec3> meanNormal;     // [V] normalised mean fragment normal (0 if they cancel)
    std::vector<uint32_t> fragmentOffset;  // [V + 1] CSR into fragmentNormal
    std::vector<glm::vec3> fragmentNormal;  // unit normals of each voxel's fragments

    uint32_t count() const { return uint32_t(linear.size()); }
    glm::ivec3 coord(uint32_t i) const {
        const uint32_t h = linear[i], n = resolution;
        return glm::ivec3(int(h % n), int((h / n) % n), int(h / (n * n)));
    }
    bool inside(const glm::ivec3& c) const {
        return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < int(resolution) && c.y < int(resolution) &&
               c.z < int(resolution);
    }
    /** Compact index at c, kEmpty when c is outside the grid or empty. */
    uint32_t at(const glm::ivec3& c) const {
        if (!inside(c)) return kEmpty;
        return indexOf[size_t(c.x) + resolution * (size_t(c.y) + size_t(resolution) * c.z)];
    }
};

}  // namespace gilab::cvgi
