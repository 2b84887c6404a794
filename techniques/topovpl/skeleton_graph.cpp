#include "skeleton_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "cluster_merge.h"
#include "core/util/error.h"

namespace gilab::topo {
namespace {

uint64_t packVoxel(const glm::ivec3& v) {
    return (uint64_t(uint32_t(v.x) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(v.y) & 0x1FFFFF) << 21) |
           uint64_t(uint32_t(v.z) & 0x1FFFFF);
}

using Piece = LinePiece;

/** Distance from p to the straight line through a and b (to a when they coincide). */
float distanceToChord(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
    const glm::vec3 ab = b - a;
    const float len2 = glm::dot(ab, ab);
    if (len2 <= 1e-12f) return glm::length(p - a);
    return glm::length(glm::cross(p - a, ab)) / std::sqrt(len2);
}

/** The lines of the graph between nodes of degree != 2 (closed loops get a topology node). */
std::vector<Piece> traceLines(const SkeletonGraph& g, std::vector<NodeKind>& kind) {
    const uint32_t n = uint32_t(g.position.size());
    auto degree = [&](uint32_t i) { return g.adjacency[i].size(); };
    std::vector<uint8_t> visited(n, 0);
    std::vector<Piece> pieces;
    auto walk = [&](uint32_t start, uint32_t first) {
        Piece p;
        p.a = start;
        uint32_t prev = start, cur = first;
        while (degree(cur) == 2 && kind[cur] != NodeKind::Topology) {
            if (visited[cur]) return;  // already traced from its other end
            visited[cur] = 1;
            p.chain.push_back(cur);
            const auto& adj = g.adjacency[cur];
            const uint32_t next = adj[0] == prev ? adj[1] : adj[0];
            prev = cur;
            cur = next;
        }
        p.b = cur;
        if (p.chain.empty() && p.b < p.a) return;  // a direct edge: once, from its lower end
        pieces.push_back(std::move(p));
    };
    for (uint32_t i = 0; i < n; ++i)
        if (degree(i) != 2) kind[i] = NodeKind::Topology;
    for (uint32_t i = 0; i < n; ++i)
        if (kind[i] == NodeKind::Topology)
            for (uint32_t nb : g.adjacency[i])
                walk(i, nb);
    // Closed loops of degree-2 nodes: the lowest index becomes a topology node.
    for (uint32_t i = 0; i < n; ++i) {
        if (visited[i] || kind[i] == NodeKind::Topology) continue;
        kind[i] = NodeKind::Topology;
        visited[i] = 1;
        walk(i, g.adjacency[i][0]);
    }
    return pieces;
}

/** (E1): splits pieces at their most curved node until no node has curv > 1. */
void splitAtCurvature(const SkeletonGraph& g, std::vector<Piece>& pieces,
                      std::vector<NodeKind>& kind) {
    std::vector<Piece> done, work = std::move(pieces);
    while (!work.empty()) {
        Piece p = std::move(work.back());
        work.pop_back();
        float worst = 1.0f;
        int at = -1;
        for (size_t k = 0; k < p.chain.size(); ++k) {
            const uint32_t m = p.chain[k];
            const float d = distanceToChord(g.position[m], g.position[p.a], g.position[p.b]);
            const float curv =
                g.maxball[m] > 0.0f ? d / g.maxball[m] : std::numeric_limits<float>::infinity();
            if (curv > worst) {
                worst = curv;
                at = int(k);
            }
        }
        if (at < 0) {
            done.push_back(std::move(p));
            continue;
        }
        const uint32_t m = p.chain[size_t(at)];
        kind[m] = NodeKind::Curvature;
        work.push_back({p.a, m, {p.chain.begin(), p.chain.begin() + at}});
        work.push_back({m, p.b, {p.chain.begin() + at + 1, p.chain.end()}});
    }
    pieces = std::move(done);
}

/** (E2): splits pieces at the first node (from a) outside both extrema's maximal balls, or at
 *  the most uncovered one (CoverageSplit::Most: the largest distance outside the nearer ball). */
void splitAtCoverage(const SkeletonGraph& g, std::vector<Piece>& pieces,
                     std::vector<NodeKind>& kind, CoverageSplit split) {
    std::vector<Piece> done, work = std::move(pieces);
    while (!work.empty()) {
        Piece p = std::move(work.back());
        work.pop_back();
        int at = -1;
        float worst = 0.0f;
        for (size_t k = 0; k < p.chain.size(); ++k) {
            const glm::vec3& x = g.position[p.chain[k]];
            const float outside = std::min(g.ballDistance(p.a, x) - g.maxball[p.a],
                                           g.ballDistance(p.b, x) - g.maxball[p.b]);
            if (outside <= worst) continue;  // covered (or less uncovered than the worst)
            worst = outside;
            at = int(k);
            if (split == CoverageSplit::First) break;
        }
        if (at < 0) {
            done.push_back(std::move(p));
            continue;
        }
        const uint32_t m = p.chain[size_t(at)];
        kind[m] = NodeKind::Coverage;
        work.push_back({p.a, m, {p.chain.begin(), p.chain.begin() + at}});
        work.push_back({m, p.b, {p.chain.begin() + at + 1, p.chain.end()}});
    }
    pieces = std::move(done);
}

void addEdge(std::vector<std::vector<uint32_t>>& adj, uint32_t a, uint32_t b) {
    if (a == b) return;
    if (std::find(adj[a].begin(), adj[a].end(), b) == adj[a].end()) adj[a].push_back(b);
    if (std::find(adj[b].begin(), adj[b].end(), a) == adj[b].end()) adj[b].push_back(a);
}

/** (E3): greedy clusters of the kept nodes, seeds by decreasing maxball. */
void clusterNodes(const SkeletonGraph& g, Segmentation& s, float alpha, ClusterRule rule) {
    const uint32_t none = std::numeric_limits<uint32_t>::max();
    std::vector<uint32_t> order = s.kept;
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return g.maxball[a] > g.maxball[b]; });
    std::vector<uint32_t>& cluster = s.cluster;
    std::vector<uint8_t> queued(g.position.size(), 0);
    for (uint32_t seed : order) {
        if (cluster[seed] != none) continue;
        const uint32_t c = s.clusterCount++;
        const float radius = g.maxball[seed];
        std::vector<uint32_t> stack{seed};
        queued[seed] = 1;
        while (!stack.empty()) {
            const uint32_t m = stack.back();
            stack.pop_back();
            cluster[m] = c;
            auto push = [&](uint32_t x) {
                if (cluster[x] != none || queued[x]) return;
                queued[x] = 1;
                stack.push_back(x);
            };
            const float reference = rule == ClusterRule::Seed ? radius : g.maxball[m];
            for (uint32_t nb : s.segmentedAdjacency[m])
                if (s.kind[nb] != NodeKind::Curvature &&
                    std::abs(g.maxball[nb] - reference) <= alpha * radius)
                    push(nb);
            // Every node inside m's maximal ball that the graph reaches from m through the ball.
            std::vector<uint32_t> inside{m}, seen{m};
            while (!inside.empty()) {
                const uint32_t x = inside.back();
                inside.pop_back();
                for (uint32_t nb : s.segmentedAdjacency[x]) {
                    if (std::find(seen.begin(), seen.end(), nb) != seen.end()) continue;
                    seen.push_back(nb);
                    if (!g.inBall(m, g.position[nb])) continue;
                    inside.push_back(nb);
                    push(nb);
                }
            }
        }
    }
}

/** Removes end branches covered by their junction's ball (see the header), then reindexes. */
void pruneCoveredSpurs(SkeletonGraph& g) {
    const uint32_t n = uint32_t(g.position.size());
    std::vector<uint8_t> removed(n, 0);
    std::vector<uint32_t> mergedInto(n);
    std::iota(mergedInto.begin(), mergedInto.end(), 0u);
    auto degree = [&](uint32_t i) {
        uint32_t d = 0;
        for (uint32_t w : g.adjacency[i])
            d += removed[w] ? 0 : 1;
        return d;
    };
    for (bool changed = true; changed;) {
        changed = false;
        for (uint32_t tip = 0; tip < n; ++tip) {
            if (removed[tip] || degree(tip) != 1) continue;
            // Walk from the tip to the first node of degree >= 3.
            std::vector<uint32_t> branch{tip};
            uint32_t prev = tip, cur = tip;
            for (;;) {
                uint32_t next = prev;
                for (uint32_t w : g.adjacency[cur])
                    if (!removed[w] && w != prev && (cur == tip || w != branch.front())) {
                        next = w;
                        break;
                    }
                if (next == prev || next == cur) break;
                prev = cur;
                cur = next;
                if (degree(cur) != 2) break;
                branch.push_back(cur);
            }
            if (degree(cur) < 3) continue;  // an isolated line: nothing to prune against
            if (!g.inBall(cur, g.position[tip])) continue;
            for (uint32_t b : branch) {
                removed[b] = 1;
                mergedInto[b] = cur;
            }
            changed = true;
        }
    }
    // Reindex the kept nodes; removed ones follow their junction.
    std::vector<uint32_t> newIndex(n, 0);
    uint32_t kept = 0;
    for (uint32_t i = 0; i < n; ++i)
        if (!removed[i]) newIndex[i] = kept++;
    auto finalNode = [&](uint32_t i) {
        while (removed[i])
            i = mergedInto[i];
        return newIndex[i];
    };
    SkeletonGraph out;
    out.metric = g.metric;
    out.prunedNodes = n - kept;
    for (uint32_t i = 0; i < n; ++i) {
        if (removed[i]) continue;
        out.position.push_back(g.position[i]);
        out.maxball.push_back(g.maxball[i]);
        std::vector<uint32_t> adj;
        for (uint32_t w : g.adjacency[i])
            if (!removed[w]) adj.push_back(newIndex[w]);
        out.adjacency.push_back(std::move(adj));
    }
    out.voxelNode.resize(g.voxelNode.size());
    for (size_t v = 0; v < g.voxelNode.size(); ++v)
        out.voxelNode[v] = finalNode(g.voxelNode[v]);
    g = std::move(out);
}

}  // namespace

float SkeletonGraph::ballDistance(uint32_t c, const glm::vec3& x) const {
    const glm::vec3 d = glm::abs(x - position[c]);
    return metric == BallMetric::Euclidean ? glm::length(d) : std::max({d.x, d.y, d.z});
}

float largestNodeSkeletonPercent(const SkeletonGraph& g, uint32_t* node) {
    if (g.voxelNode.empty()) return 0.0f;
    std::vector<uint32_t> count(g.position.size(), 0);
    for (uint32_t v : g.voxelNode)
        if (v < count.size()) ++count[v];
    const auto it = std::max_element(count.begin(), count.end());
    if (node) *node = uint32_t(it - count.begin());
    return 100.0f * float(*it) / float(g.voxelNode.size());
}

SkeletonGraph buildSkeletonGraph(const std::vector<glm::ivec3>& voxels,
                                 const std::vector<float>& maxball, bool pruneSpurs,
                                 BallMetric metric) {
    if (voxels.size() != maxball.size())
        throw Error("skeleton graph: " + std::to_string(voxels.size()) + " voxels but " +
                    std::to_string(maxball.size()) + " radii");
    const uint32_t n = uint32_t(voxels.size());
    std::unordered_map<uint64_t, uint32_t> index;
    index.reserve(n * 2);
    for (uint32_t i = 0; i < n; ++i)
        index.emplace(packVoxel(voxels[i]), i);
    std::vector<std::vector<uint32_t>> adj(n);
    for (uint32_t i = 0; i < n; ++i)
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (!dx && !dy && !dz) continue;
                    const auto it = index.find(packVoxel(voxels[i] + glm::ivec3(dx, dy, dz)));
                    if (it != index.end()) adj[i].push_back(it->second);
                }
    // Junction clumps: 26-connected groups of voxels of degree != 2 become one node.
    const uint32_t none = std::numeric_limits<uint32_t>::max();
    SkeletonGraph g;
    g.metric = metric;
    g.voxelNode.assign(n, none);
    for (uint32_t i = 0; i < n; ++i) {
        if (g.voxelNode[i] != none) continue;
        const uint32_t node = uint32_t(g.position.size());
        glm::vec3 sum(0.0f);
        float radius = 0.0f;
        uint32_t members = 0;
        std::vector<uint32_t> stack{i};
        g.voxelNode[i] = node;
        const bool clump = adj[i].size() != 2;
        while (!stack.empty()) {
            const uint32_t v = stack.back();
            stack.pop_back();
            sum += glm::vec3(voxels[v]);
            radius = std::max(radius, maxball[v]);
            ++members;
            if (!clump) continue;
            for (uint32_t w : adj[v])
                if (g.voxelNode[w] == none && adj[w].size() != 2) {
                    g.voxelNode[w] = node;
                    stack.push_back(w);
                }
        }
        g.position.push_back(sum / float(members));
        g.maxball.push_back(radius);
    }
    g.adjacency.assign(g.position.size(), {});
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t w : adj[i])
            addEdge(g.adjacency, g.voxelNode[i], g.voxelNode[w]);
    for (auto& a : g.adjacency)
        std::sort(a.begin(), a.end());
    if (pruneSpurs) pruneCoveredSpurs(g);
    return g;
}

Segmentation segmentSkeleton(const SkeletonGraph& g, CoverageSplit split) {
    const uint32_t n = uint32_t(g.position.size());
    Segmentation s;
    s.kind.assign(n, NodeKind::Line);
    std::vector<Piece> pieces = traceLines(g, s.kind);
    splitAtCurvature(g, pieces, s.kind);
    splitAtCoverage(g, pieces, s.kind, split);

    s.segmentedNode.resize(n);
    std::iota(s.segmentedNode.begin(), s.segmentedNode.end(), 0u);
    s.segmentedAdjacency.assign(n, {});
    for (const Piece& p : pieces) {
        addEdge(s.segmentedAdjacency, p.a, p.b);
        for (uint32_t m : p.chain) {
            const float da = glm::length(g.position[m] - g.position[p.a]);
            const float db = glm::length(g.position[m] - g.position[p.b]);
            s.segmentedNode[m] = db < da ? p.b : p.a;
        }
    }
    for (auto& a : s.segmentedAdjacency)
        std::sort(a.begin(), a.end());
    s.pieces = std::move(pieces);
    for (uint32_t i = 0; i < n; ++i) {
        if (s.kind[i] == NodeKind::Line) continue;
        s.kept.push_back(i);
        s.topologyNodes += s.kind[i] == NodeKind::Topology;
        s.curvatureNodes += s.kind[i] == NodeKind::Curvature;
        s.coverageNodes += s.kind[i] == NodeKind::Coverage;
    }
    return s;
}

void clusterSkeleton(const SkeletonGraph& g, Segmentation& s, float alpha,
                     const std::vector<uint8_t>& empty, const GridDims& dims, bool mergeVisible,
                     GatePlacement placement, float mergeThreshold, ClusterRule rule) {
    const uint32_t n = uint32_t(g.position.size());
    if (s.kind.size() != n || s.segmentedNode.size() != n || s.segmentedAdjacency.size() != n)
        throw Error("clusterSkeleton: the segmentation is not of this graph (" +
                    std::to_string(s.kind.size()) + " nodes, the graph has " + std::to_string(n) +
                    ")");
    if (mergeVisible && empty.size() != dims.count())
        throw Error("clusterSkeleton: " + std::to_string(empty.size()) +
                    " voxels in the empty grid, dims hold " + std::to_string(dims.count()));
    s.cluster.assign(n, std::numeric_limits<uint32_t>::max());
    s.clusterCount = 0;
    clusterNodes(g, s, alpha, rule);
    for (uint32_t i = 0; i < n; ++i)
        if (s.kind[i] == NodeKind::Line) s.cluster[i] = s.cluster[s.segmentedNode[i]];
    s.greedyClusters = s.clusterCount;
    if (mergeVisible) mergeVisibleClusters(g, s, empty, dims, mergeThreshold);
    placeGates(g, s, placement);
}

Segmentation segmentSkeleton(const SkeletonGraph& g, float alpha) {
    Segmentation s = segmentSkeleton(g);
    clusterSkeleton(g, s, alpha, {}, GridDims{}, false, GatePlacement::Midpoint);
    return s;
}

void placeGates(const SkeletonGraph& g, Segmentation& s, GatePlacement placement) {
    s.gates.clear();
    for (const LinePiece& p : s.pieces) {
        if (s.cluster[p.a] == s.cluster[p.b]) continue;
        // The line from a to b, ends included; its narrowest node (ties: nearest the middle).
        std::vector<uint32_t> line{p.a};
        line.insert(line.end(), p.chain.begin(), p.chain.end());
        line.push_back(p.b);
        const size_t last = line.size() - 1;
        size_t neck = 0;
        for (size_t i = 1; i <= last; ++i) {
            const float r = g.maxball[line[i]], best = g.maxball[line[neck]];
            const auto off = [&](size_t k) { return std::abs(2 * long(k) - long(last)); };
            if (r < best || (r == best && off(i) < off(neck))) neck = i;
        }
        Gate gate;
        gate.radiusA = g.maxball[p.a];
        gate.radiusB = g.maxball[p.b];
        gate.radius = std::min(gate.radiusA, gate.radiusB);
        gate.radiusNeck = g.maxball[line[neck]];
        gate.clusterA = s.cluster[p.a];
        gate.clusterB = s.cluster[p.b];
        glm::vec3 d = g.position[p.b] - g.position[p.a];
        if (placement == GatePlacement::Midpoint) {
            gate.centre = 0.5f * (g.position[p.a] + g.position[p.b]);
        } else {
            gate.centre = g.position[line[neck]];
            const glm::vec3 local = g.position[line[std::min(neck + 1, last)]] -
                                    g.position[line[neck > 0 ? neck - 1 : 0]];
            if (glm::dot(local, local) > 0.0f) d = local;
            // The line's nodes before the neck are a's side, after it b's (the neck itself goes
            // to the nearer end), so the clusters of the pixels meet at the gate.
            for (size_t i = 1; i < last; ++i) {
                const uint32_t m = line[i];
                const bool sideA = i < neck || (i == neck && 2 * neck <= last);
                s.segmentedNode[m] = sideA ? p.a : p.b;
                s.cluster[m] = s.cluster[s.segmentedNode[m]];
            }
        }
        const float len = glm::length(d);
        gate.normal = len > 0.0f ? d / len : glm::vec3(0.0f, 0.0f, 1.0f);
        s.gates.push_back(gate);
    }
}

}  // namespace gilab::topo
