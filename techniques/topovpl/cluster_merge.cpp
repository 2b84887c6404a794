#include "cluster_merge.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <unordered_map>

#include "core/util/error.h"

namespace gilab::topo {
namespace {

bool isEmpty(const std::vector<uint8_t>& empty, const GridDims& dims, const glm::ivec3& v) {
    if (v.x < 0 || v.y < 0 || v.z < 0 || uint32_t(v.x) >= dims.nx || uint32_t(v.y) >= dims.ny ||
        uint32_t(v.z) >= dims.nz)
        return false;
    return empty[dims.index(uint32_t(v.x), uint32_t(v.y), uint32_t(v.z))] != 0;
}

}  // namespace

bool segmentVisible(const std::vector<uint8_t>& empty, const GridDims& dims, glm::ivec3 a,
                    glm::ivec3 b) {
    if (empty.size() != dims.count())
        throw Error("segmentVisible: " + std::to_string(empty.size()) + " voxels for a grid of " +
                    std::to_string(dims.count()));
    // Symmetric by construction: always walk from the lexicographically smaller end (the
    // supercover is symmetric anyway; this makes the visited order, hence any early exit, too).
    if (b.x < a.x || (b.x == a.x && (b.y < a.y || (b.y == a.y && b.z < a.z)))) std::swap(a, b);
    if (!isEmpty(empty, dims, a)) return false;
    // The segment a + 0.5 + t (b - a), t in [0, 1], crosses the k-th plane of axis i (k = 0 ..
    // n_i - 1, n_i = |b_i - a_i|) at t = (2 k + 1) / (2 n_i): crossings compare exactly by
    // cross-multiplication in integers.
    const glm::ivec3 d = b - a;
    const int64_t n[3] = {std::abs(d.x), std::abs(d.y), std::abs(d.z)};
    const int step[3] = {d.x < 0 ? -1 : 1, d.y < 0 ? -1 : 1, d.z < 0 ? -1 : 1};
    int64_t k[3] = {0, 0, 0};
    glm::ivec3 v = a;
    for (;;) {
        int tied[3], count = 0;
        for (int i = 0; i < 3; ++i) {
            if (k[i] >= n[i]) continue;
            if (count == 0) {
                tied[count++] = i;
                continue;
            }
            // t_i vs t_best: (2 k_i + 1) / n_i vs (2 k_b + 1) / n_b.
            const int best = tied[0];
            const int64_t lhs = (2 * k[i] + 1) * n[best], rhs = (2 * k[best] + 1) * n[i];
            if (lhs < rhs) {
                count = 0;
                tied[count++] = i;
            } else if (lhs == rhs) {
                tied[count++] = i;
            }
        }
        if (count == 0) break;
        // Through an edge or a corner: every voxel around it, the partial steps first.
        for (int mask = 1; mask + 1 < (1 << count); ++mask) {
            glm::ivec3 w = v;
            for (int j = 0; j < count; ++j)
                if (mask & (1 << j)) w[tied[j]] += step[tied[j]];
            if (!isEmpty(empty, dims, w)) return false;
        }
        for (int j = 0; j < count; ++j) {
            v[tied[j]] += step[tied[j]];
            ++k[tied[j]];
        }
        if (!isEmpty(empty, dims, v)) return false;
    }
    return true;
}

glm::ivec3 nodeVoxel(const SkeletonGraph& graph, uint32_t node) {
    return glm::ivec3(glm::round(graph.position[node]));
}

std::vector<glm::ivec3> ballSamples(const SkeletonGraph& graph, uint32_t node) {
    const glm::ivec3 c = nodeVoxel(graph, node);
    std::vector<glm::ivec3> out{c};
    // The largest whole number of voxels strictly inside the ball: a voxel nearer than the
    // maximal-ball radius to the node's voxel is empty (the radius is the distance to the nearest
    // solid voxel).
    const int k = std::max(0, int(std::ceil(graph.maxball[node])) - 1);
    if (k == 0) return out;
    for (int axis = 0; axis < 3; ++axis)
        for (int sign : {-1, 1}) {
            glm::ivec3 p = c;
            p[axis] += sign * k;
            out.push_back(p);
        }
    return out;
}

uint32_t mergeVisibleClusters(const SkeletonGraph& g, Segmentation& s,
                              const std::vector<uint8_t>& empty, const GridDims& dims,
                              float threshold) {
    const uint32_t clusters = s.clusterCount;
    if (clusters < 2) return 0;
    // Kept nodes per cluster, ascending.
    std::vector<std::vector<uint32_t>> members(clusters);
    for (uint32_t k : s.kept)
        members[s.cluster[k]].push_back(k);

    std::unordered_map<uint32_t, std::vector<glm::ivec3>> samples;
    auto samplesOf = [&](uint32_t node) -> const std::vector<glm::ivec3>& {
        auto it = samples.find(node);
        if (it == samples.end()) it = samples.emplace(node, ballSamples(g, node)).first;
        return it->second;
    };
    // Per node pair: visible sample pairs and all sample pairs.
    std::unordered_map<uint64_t, glm::uvec2> memo;
    auto visible = [&](uint32_t p, uint32_t q) {
        const uint64_t key = (uint64_t(std::min(p, q)) << 32) | std::max(p, q);
        const auto it = memo.find(key);
        if (it != memo.end()) return it->second;
        glm::uvec2 v(0u);
        for (const glm::ivec3& x : samplesOf(std::min(p, q)))
            for (const glm::ivec3& y : samplesOf(std::max(p, q))) {
                v.x += segmentVisible(empty, dims, x, y) ? 1u : 0u;
                ++v.y;
            }
        memo.emplace(key, v);
        return v;
    };
    // The share of visible sample pairs over every node pair of x and y reaches `threshold`
    // (1: every pair; the test stops at the first blocked one then).
    auto allVisible = [&](const std::vector<uint32_t>& x, const std::vector<uint32_t>& y) {
        uint64_t seen = 0, total = 0;
        for (uint32_t p : x)
            for (uint32_t q : y) {
                if (p == q) continue;
                const glm::uvec2 v = visible(p, q);
                if (threshold >= 1.0f && v.x < v.y) return false;
                seen += v.x;
                total += v.y;
            }
        return total == 0 || double(seen) >= double(threshold) * double(total);
    };
    // Whether a cluster is quasi-convex on its own (a greedy cluster need not be): one that is
    // not can never be part of a merged one.
    std::vector<int8_t> selfVisible(clusters, -1);
    auto selfOk = [&](uint32_t c) {
        if (selfVisible[c] < 0) selfVisible[c] = allVisible(members[c], members[c]) ? 1 : 0;
        return selfVisible[c] == 1;
    };
    // label[c]: the cluster c has merged into (itself while alive).
    std::vector<uint32_t> label(clusters);
    for (uint32_t c = 0; c < clusters; ++c)
        label[c] = c;
    auto neighbours = [&](uint32_t c) {
        std::vector<uint32_t> out;
        for (uint32_t m : members[c])
            for (uint32_t nb : s.segmentedAdjacency[m]) {
                const uint32_t d = label[s.cluster[nb]];
                if (d != c) out.push_back(d);
            }
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    };

    uint32_t merges = 0;
    for (bool changed = true; changed;) {
        changed = false;
        for (uint32_t c = 0; c < clusters; ++c) {
            bool rescan = true;
            while (rescan && label[c] == c) {
                rescan = false;
                if (!selfOk(c)) break;
                for (uint32_t d : neighbours(c)) {
                    if (!selfOk(d) || !allVisible(members[c], members[d])) continue;
                    const uint32_t keep = std::min(c, d), gone = std::max(c, d);
                    members[keep].insert(members[keep].end(), members[gone].begin(),
                                         members[gone].end());
                    std::sort(members[keep].begin(), members[keep].end());
                    members[gone].clear();
                    selfVisible[keep] = 1;
                    for (uint32_t& l : label)
                        if (l == gone) l = keep;
                    ++merges;
                    changed = rescan = true;
                    break;
                }
            }
        }
    }
    if (merges == 0) return 0;
    // Dense ids in ascending order of the surviving (smallest merged) id.
    std::vector<uint32_t> dense(clusters, std::numeric_limits<uint32_t>::max());
    uint32_t next = 0;
    for (uint32_t c = 0; c < clusters; ++c)
        if (label[c] == c) dense[c] = next++;
    for (uint32_t& c : s.cluster)
        c = dense[label[c]];
    s.clusterCount = next;
    return merges;
}

}  // namespace gilab::topo
