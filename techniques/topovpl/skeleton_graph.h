#pragma once
/**
 * The topological segmentation of the empty space (Noël & Biri 2014 §IV; notes 004 §2.A3-A5),
 * on the CPU, from a curve skeleton of the empty voxels and their maximal-ball radii:
 *
 *   graph         every skeleton voxel a node, 26-neighbour edges; connected groups of nodes of
 *                 degree != 2 (junction clumps) collapse into one topology node
 *   lines         maximal chains of degree-2 nodes between two topology nodes (a closed loop
 *                 without one gets its lowest-index node as topology node)
 *   curvature     (E1) curv(n) = dist(n, chord L1 Lk) / maxball(n); the node of largest
 *                 curv > 1 becomes an extremum, both halves recurse
 *   coverage      (E2) a node outside the maximal balls of both extrema of its line is
 *                 uncovered; the first uncovered node from L1 becomes an extremum, recurse
 *   segmented     the kept nodes (topology, curvature, coverage) joined along the former lines;
 *                 every skeleton node maps to the nearer extremum of its piece of line
 *   clusters      (E3) greedy: seeds by maxball descending; a neighbour joins when it is not a
 *                 curvature node and |maxball - R_C| <= alpha R_C; every node inside the
 *                 member's maximal ball and reachable through the graph joins too
 *   gates         (E4) a disk on every segmented edge between two clusters: centre the edge's
 *                 midpoint, normal along the edge, radius min(maxball) of its ends
 *
 * Positions and radii are in voxel units (voxel centres at integer coordinates + 0.5 are the
 * caller's business: positions here are the voxel indices). Deterministic: ties by node index.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gilab::topo {

enum class NodeKind : uint8_t { Line = 0, Topology = 1, Curvature = 2, Coverage = 3 };

/** The skeleton as a graph (one node per skeleton voxel, clumps collapsed). */
struct SkeletonGraph {
    std::vector<glm::vec3> position;  // voxel coordinates (a clump: the mean)
    std::vector<float> maxball;       // maximal-ball radius in voxels
    std::vector<std::vector<uint32_t>> adjacency;
    std::vector<uint32_t> voxelNode;  // per skeleton voxel (input order): its node
    uint32_t prunedNodes = 0;         // nodes removed with covered spurs
};

/**
 * Builds the graph from skeleton voxels (x, y, z) and their maximal-ball radii. With
 * `pruneCoveredSpurs`, end branches whose tip lies inside the maximal ball of the junction they
 * leave from are removed, repeatedly (their voxels map to that junction): branches that carry no
 * shape the junction's ball does not already hold. It stands in for the lifespan (persistence)
 * filter of the paper's thinning (Chaussard et al. 2013), which our thinning does not have.
 */
SkeletonGraph buildSkeletonGraph(const std::vector<glm::ivec3>& voxels,
                                 const std::vector<float>& maxball, bool pruneCoveredSpurs = true);

struct Gate {
    glm::vec3 centre{0.0f};
    glm::vec3 normal{0.0f};  // unit, from node a to node b
    float radius = 0.0f;
    uint32_t clusterA = 0, clusterB = 0;  // the clusters of the edge's ends a and b
};

struct Segmentation {
    std::vector<NodeKind> kind;           // per graph node
    std::vector<uint32_t> segmentedNode;  // per graph node: its kept node (itself when kept)
    std::vector<uint32_t> kept;           // graph indices of the kept nodes, ascending
    std::vector<std::vector<uint32_t>> segmentedAdjacency;  // per graph node (kept ones only)
    std::vector<uint32_t> cluster;  // per graph node (kept: own, else its kept node's)
    uint32_t clusterCount = 0;
    std::vector<Gate> gates;
    uint32_t curvatureNodes = 0, coverageNodes = 0, topologyNodes = 0;
};

/** Segments the graph, clusters it with tolerance alpha (0.2 = the paper's 20 %) and places the
 *  gates. */
Segmentation segmentSkeleton(const SkeletonGraph& graph, float alpha);

}  // namespace gilab::topo
