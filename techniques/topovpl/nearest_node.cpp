#include "nearest_node.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <queue>
#include <string>
#include <utility>

#include "core/util/error.h"

namespace gilab::topo {

namespace {

void checkInputs(const std::vector<uint8_t>& empty, const GridDims& dims,
                 const std::vector<glm::ivec3>& skeletonVoxels,
                 const std::vector<uint32_t>& voxelNode) {
    if (empty.size() != dims.count())
        throw Error("nearest-node grid: " + std::to_string(empty.size()) + " voxels for a " +
                    std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" +
                    std::to_string(dims.nz) + " grid");
    if (skeletonVoxels.size() != voxelNode.size())
        throw Error("nearest-node grid: skeleton voxels and their nodes differ in number");
    for (const glm::ivec3& v : skeletonVoxels)
        if (v.x < 0 || v.y < 0 || v.z < 0 || uint32_t(v.x) >= dims.nx || uint32_t(v.y) >= dims.ny ||
            uint32_t(v.z) >= dims.nz)
            throw Error("nearest-node grid: skeleton voxel (" + std::to_string(v.x) + ", " +
                        std::to_string(v.y) + ", " + std::to_string(v.z) + ") outside the grid");
}

// Voxel states of the bucket version: 0-25 the direction (index in the neighbour table) of the
// step that gave a queued voxel its distance, then the ones below. Solid and settled voxels
// have the top bit, so one test skips both.
constexpr uint8_t kSeed = 26, kUnreached = 27, kSettled = 0x80, kSolid = 0xff;

}  // namespace

std::vector<uint32_t> nearestNodeGrid(const std::vector<uint8_t>& empty, const GridDims& dims,
                                      const std::vector<glm::ivec3>& skeletonVoxels,
                                      const std::vector<uint32_t>& voxelNode) {
    checkInputs(empty, dims, skeletonVoxels, voxelNode);
    const size_t count = empty.size();
    if (count > size_t(std::numeric_limits<uint32_t>::max()))
        throw Error("nearest-node grid: " + std::to_string(count) + " voxels, more than 2^32");
    if (count == 0) return {};
    std::vector<uint32_t> label(count, kNoNode);
    std::vector<float> dist(count, std::numeric_limits<float>::infinity());
    std::vector<uint8_t> state(count);
    for (size_t i = 0; i < count; ++i)
        state[i] = empty[i] ? kUnreached : kSolid;
    // Bucket k % 4 holds the voxels queued at a distance in [k, k + 1): a step adds at least 1,
    // so a bucket only feeds later ones and its voxels' distances are final when it is reached;
    // a step adds at most sqrt 3 < 2, so live entries span 3 buckets.
    std::array<std::vector<uint32_t>, 4> buckets;
    size_t pending = 0;
    auto push = [&](float d, uint32_t voxel) {
        buckets[uint32_t(d) & 3].push_back(voxel);
        ++pending;
    };
    for (size_t k = 0; k < skeletonVoxels.size(); ++k) {
        const glm::ivec3 v = skeletonVoxels[k];
        const size_t i = dims.index(uint32_t(v.x), uint32_t(v.y), uint32_t(v.z));
        if (state[i] == kSolid) continue;
        label[i] = voxelNode[k];  // a voxel listed twice takes its last node
        if (state[i] == kSeed) continue;
        state[i] = kSeed;
        dist[i] = 0.0f;
        push(0.0f, uint32_t(i));
    }
    const float step[4] = {0.0f, 1.0f, std::sqrt(2.0f), std::sqrt(3.0f)};
    const int64_t sy = int64_t(dims.nx), sz = int64_t(dims.nx) * dims.ny;
    int64_t offset[26];  // from a voxel to its neighbour, in the exact version's order
    float weight[26];
    int n = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (!dx && !dy && !dz) continue;
                offset[n] = dx + dy * sy + dz * sz;
                weight[n++] = step[std::abs(dx) + std::abs(dy) + std::abs(dz)];
            }
    uint8_t* const st = state.data();  // raw pointers: the pushes cannot move them
    float* const ds = dist.data();
    uint32_t* const lb = label.data();
    // Relaxes neighbour j = i + offset[m] of voxel i, settled at distance d with node l: the
    // exact version's float sum; of equal sums, the one from the smaller (distance, voxel) wins,
    // the predecessor the exact version's heap settles first.
    auto relax = [&](size_t j, int m, size_t i, float d, uint32_t l) {
        const uint8_t s = st[j];
        if (s & kSettled) return;  // solid, or settled at a distance <= d
        const float nd = d + weight[m];
        if (nd < ds[j]) {
            ds[j] = nd;
            lb[j] = l;
            st[j] = uint8_t(m);
            push(nd, uint32_t(j));
        } else if (nd == ds[j]) {  // a tie; s is a direction (a seed's 0 is below any sum)
            const size_t p = size_t(int64_t(j) - offset[s]);
            if (d < ds[p] || (d == ds[p] && i < p)) {
                lb[j] = l;
                st[j] = uint8_t(m);
            }
        }
    };
    // Orders a bucket by blocks of voxels (a counting sort on the index's high bits, first in
    // first out within a block): any order gives the same labels (the rule above), this one
    // walks the grids in memory order.
    int shift = 0;
    while ((count - 1) >> shift >= 4096)
        ++shift;
    std::vector<uint32_t> sorted, blockStart;
    auto order = [&](std::vector<uint32_t>& bucket) {
        if (bucket.size() < 1024) {
            std::sort(bucket.begin(), bucket.end());
            return;
        }
        blockStart.assign(((count - 1) >> shift) + 2, 0);
        for (const uint32_t i : bucket)
            ++blockStart[(i >> shift) + 1];
        for (size_t b = 1; b < blockStart.size(); ++b)
            blockStart[b] += blockStart[b - 1];
        sorted.resize(bucket.size());
        for (const uint32_t i : bucket)
            sorted[blockStart[i >> shift]++] = i;
        bucket.swap(sorted);
    };
    const uint32_t nx = dims.nx, ny = dims.ny, nz = dims.nz, nxy = nx * ny;  // < 2^32: see above
    for (uint32_t k = 0; pending > 0; ++k) {
        std::vector<uint32_t>& bucket = buckets[k & 3];
        order(bucket);
        // By index: beyond 2^24 voxels of distance, float steps of 1 round to 0 and the bucket
        // grows while read (the exact version degrades there too).
        for (size_t b = 0; b < bucket.size(); ++b) {
            const uint32_t i = bucket[b];
            if (st[i] & kSettled) continue;  // a stale or repeated entry
            st[i] = kSettled;
            const float d = ds[i];
            const uint32_t l = lb[i];
            const uint32_t z = i / nxy, r = i - z * nxy, y = r / nx, x = r - y * nx;
            if (x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz) {
                for (int m = 0; m < 26; ++m)
                    relax(size_t(int64_t(i) + offset[m]), m, i, d, l);
                continue;
            }
            int m = 0;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        if (!dx && !dy && !dz) continue;
                        const int64_t ax = int64_t(x) + dx, ay = int64_t(y) + dy,
                                      az = int64_t(z) + dz;
                        if (ax >= 0 && ay >= 0 && az >= 0 && ax < nx && ay < ny && az < nz)
                            relax(size_t(int64_t(i) + offset[m]), m, i, d, l);
                        ++m;
                    }
        }
        pending -= bucket.size();
        bucket.clear();
    }
    return label;
}

std::vector<uint32_t> nearestNodeGridExact(const std::vector<uint8_t>& empty, const GridDims& dims,
                                           const std::vector<glm::ivec3>& skeletonVoxels,
                                           const std::vector<uint32_t>& voxelNode) {
    checkInputs(empty, dims, skeletonVoxels, voxelNode);
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
