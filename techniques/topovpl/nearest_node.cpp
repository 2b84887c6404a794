#include "techniques/topovpl/nearest_node.h"

#include <cmath>
#include <queue>
#include <string>
#include <utility>

#include "core/util/error.h"

namespace gilab::topo {

std::vector<uint32_t> nearestNodeGrid(const std::vector<uint8_t>& empty, const GridDims& dims,
                                      const std::vector<glm::ivec3>& skeletonVoxels,
                                      const std::vector<uint32_t>& voxelNode) {
    if (empty.size() != dims.count())
        throw Error("nearest-node grid: " + std::to_string(empty.size()) + " voxels for a " +
                    std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" +
                    std::to_string(dims.nz) + " grid");
    if (skeletonVoxels.size() != voxelNode.size())
        throw Error("nearest-node grid: skeleton voxels and their nodes differ in number");
    std::vector<uint32_t> label(empty.size(), kNoNode);
    std::vector<float> dist(empty.size(), std::numeric_limits<float>::infinity());
    using Entry = std::pair<float, size_t>;  // (distance, voxel): smaller first
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    for (size_t k = 0; k < skeletonVoxels.size(); ++k) {
        const glm::ivec3 v = skeletonVoxels[k];
        const size_t i = dims.index(uint32_t(v.x), uint32_t(v.y), uint32_t(v.z));
        if (!empty[i]) continue;
        dist[i] = 0.0f;
        label[i] = voxelNode[k];
        queue.push({0.0f, i});
    }
    const float step[4] = {0.0f, 1.0f, std::sqrt(2.0f), std::sqrt(3.0f)};
    while (!queue.empty()) {
        const auto [d, i] = queue.top();
        queue.pop();
        if (d > dist[i]) continue;  // a stale entry
        const int x = int(i % dims.nx), y = int((i / dims.nx) % dims.ny);
        const int z = int(i / (size_t(dims.nx) * dims.ny));
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = x + dx, ny = y + dy, nz = z + dz;
                    if ((!dx && !dy && !dz) || nx < 0 || ny < 0 || nz < 0 || nx >= int(dims.nx) ||
                        ny >= int(dims.ny) || nz >= int(dims.nz))
                        continue;
                    const size_t j = dims.index(uint32_t(nx), uint32_t(ny), uint32_t(nz));
                    if (!empty[j]) continue;
                    const float nd = d + step[std::abs(dx) + std::abs(dy) + std::abs(dz)];
                    if (nd < dist[j]) {
                        dist[j] = nd;
                        label[j] = label[i];
                        queue.push({nd, j});
                    }
                }
    }
    return label;
}

}  // namespace gilab::topo
