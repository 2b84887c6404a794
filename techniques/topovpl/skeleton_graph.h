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
 *                 uncovered; the first uncovered node from L1 (or the most uncovered:
 *                 CoverageSplit) becomes an extremum, recurse
 *   segmented     the kept nodes (topology, curvature, coverage) joined along the former lines;
 *                 every skeleton node maps to the nearer extremum of its piece of line
 *   clusters      (E3) greedy: seeds by maxball descending; a neighbour joins when it is not a
 *                 curvature node and |maxball - R_C| <= alpha R_C (or the chained reading:
 *                 ClusterRule); every node inside the
 *                 member's maximal ball and reachable through the graph joins too
 *   merge         (OUR addition, not in the paper; cluster_merge.h) two adjacent clusters merge
 *                 when every pair of kept nodes of their union (each by its voxel and its ball's
 *                 six axis poles) sees each other through the empty voxels: the union of their
 *                 balls is then taken as quasi-convex, which is what a paper cluster stands for.
 *                 Without it two rooms joined by a door gave 4 clusters and 3 gates (the
 *                 approaches to the door were clusters of their own); with it, 2 and 1
 *   gates         (E4) a disk on every segmented edge between two clusters: centre the edge's
 *                 midpoint, normal along the edge, radius min(maxball) of its ends (both ends'
 *                 radii are kept, for a per-frame radius rule)
 *
 * Balls are Euclidean or chessboard cubes (BallMetric). Positions and radii are in voxel units
 * (voxel centres at integer coordinates + 0.5 are the caller's business: positions here are the
 * voxel indices). Deterministic: ties by node index.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/voxel/grid_dims.h"

namespace gilab::topo {

enum class NodeKind : uint8_t { Line = 0, Topology = 1, Curvature = 2, Coverage = 3 };

/**
 * How a maximal ball is measured (the paper says "maximal ball" without a metric):
 *   Euclidean   radius = Euclidean distance to the nearest solid voxel, x in the ball of c iff
 *               |x - c|_2 <= r
 *   Chessboard  radius = L-infinity (26-neighbour) distance, the ball a cube: |x - c|_inf <= r
 *               (the authors' public code measures its distance and opening maps this way)
 */
enum class BallMetric : uint8_t { Euclidean = 0, Chessboard = 1 };

/**
 * E3's radius test, two readings of "does not differ more than alpha % of the maximal radius
 * contained in the cluster" (R_C, the seed's radius since seeds come largest first):
 *   Seed     |maxball(nb) - R_C| <= alpha R_C: every member within alpha of the seed
 *   Chained  |maxball(nb) - maxball(m)| <= alpha R_C: a neighbour within alpha of the member m
 *            that reaches it, so radii may drift along a cluster
 */
enum class ClusterRule : uint8_t { Seed = 0, Chained = 1 };

/** E2's split point on a line with uncovered nodes: the first from L1 (as printed: "the same
 *  procedure", read in order) or the most uncovered (largest distance outside both extrema's
 *  balls, the way E1 takes the most curved). */
enum class CoverageSplit : uint8_t { First = 0, Most = 1 };

/** The skeleton as a graph (one node per skeleton voxel, clumps collapsed). */
struct SkeletonGraph {
    std::vector<glm::vec3> position;  // voxel coordinates (a clump: the mean)
    std::vector<float> maxball;       // maximal-ball radius in voxels
    std::vector<std::vector<uint32_t>> adjacency;
    std::vector<uint32_t> voxelNode;            // per skeleton voxel (input order): its node
    uint32_t prunedNodes = 0;                   // nodes removed with covered spurs
    BallMetric metric = BallMetric::Euclidean;  // how maxball is measured (set-up only)

    /** Is point x inside the maximal ball of node c (in this graph's metric)? */
    bool inBall(uint32_t c, const glm::vec3& x) const { return ballDistance(c, x) <= maxball[c]; }
    /** |x - position[c]| in this graph's metric. */
    float ballDistance(uint32_t c, const glm::vec3& x) const;
};

/** Voxels per skeleton node: the largest node's share of the skeleton voxels, in percent (a
 *  clump of empty space that did not thin, e.g. open sky, shows as one node holding much). */
float largestNodeSkeletonPercent(const SkeletonGraph& graph, uint32_t* node = nullptr);

/**
 * Builds the graph from skeleton voxels (x, y, z) and their maximal-ball radii. With
 * `pruneCoveredSpurs`, end branches whose tip lies inside the maximal ball of the junction they
 * leave from are removed, repeatedly (their voxels map to that junction): branches that carry no
 * shape the junction's ball does not already hold. It stands in for the lifespan (persistence)
 * filter of the paper's thinning (Chaussard et al. 2013), which our thinning does not have.
 */
SkeletonGraph buildSkeletonGraph(const std::vector<glm::ivec3>& voxels,
                                 const std::vector<float>& maxball, bool pruneCoveredSpurs = true,
                                 BallMetric metric = BallMetric::Euclidean);

struct Gate {
    glm::vec3 centre{0.0f};
    glm::vec3 normal{0.0f};                // unit, from node a's side to node b's
    float radius = 0.0f;                   // min(radiusA, radiusB)
    float radiusA = 0.0f, radiusB = 0.0f;  // maxball of the edge's ends a and b
    uint32_t clusterA = 0, clusterB = 0;   // the clusters of the edge's ends a and b
    float radiusNeck = 0.0f;               // the smallest maxball on the line from a to b
};

/** A piece of a skeleton line between two kept nodes a and b: the degree-2 nodes between them,
 *  in order from a. */
struct LinePiece {
    uint32_t a = 0, b = 0;
    std::vector<uint32_t> chain;
};

/**
 * Where a gate sits on its line (E4 places it at the midpoint of the segmented edge):
 *   Midpoint    the paper: centre (p(a) + p(b)) / 2, normal along b - a
 *   Bottleneck  ours: the node of smallest maxball on the line from a to b (the doorway; ties:
 *               the one nearest the middle), normal along the line there; the line's nodes on
 *               each side of it take that side's cluster, so the pixel clusters meet at the gate
 */
enum class GatePlacement : uint8_t { Midpoint = 0, Bottleneck = 1 };

struct Segmentation {
    std::vector<NodeKind> kind;           // per graph node
    std::vector<uint32_t> segmentedNode;  // per graph node: its kept node (itself when kept)
    std::vector<uint32_t> kept;           // graph indices of the kept nodes, ascending
    std::vector<std::vector<uint32_t>> segmentedAdjacency;  // per graph node (kept ones only)
    std::vector<uint32_t> cluster;  // per graph node (kept: own, else its kept node's)
    uint32_t clusterCount = 0;
    uint32_t greedyClusters = 0;  // E3's count, before the visibility merge
    std::vector<Gate> gates;
    uint32_t curvatureNodes = 0, coverageNodes = 0, topologyNodes = 0;
    /** The pieces of line between kept nodes (set-up only: not stored in the topology cache). */
    std::vector<LinePiece> pieces;
};

/** Segments the graph: lines, curvature (E1) and coverage (E2) nodes, the segmented edges and
 *  every node's kept node. Clusters and gates are left empty (clusterSkeleton). */
Segmentation segmentSkeleton(const SkeletonGraph& graph,
                             CoverageSplit split = CoverageSplit::First);

/**
 * Clusters a segmentation (E3) with tolerance alpha (0.2 = the paper's 20 %); with
 * `mergeVisible`, merges mutually visible adjacent clusters (cluster_merge.h; `empty` is the
 * empty-voxel grid of `dims`, the graph's positions index it; `mergeThreshold`: the share of
 * visible sample pairs it needs, cluster_merge.h); then places the gates (E4) by
 * `placement`. Replaces any clusters and gates `s` had. Without the merge, `empty` is not read
 * (may be empty).
 */
void clusterSkeleton(const SkeletonGraph& graph, Segmentation& s, float alpha,
                     const std::vector<uint8_t>& empty, const GridDims& dims, bool mergeVisible,
                     GatePlacement placement = GatePlacement::Midpoint, float mergeThreshold = 1.0f,
                     ClusterRule rule = ClusterRule::Seed);

/** segmentSkeleton then clusterSkeleton without the merge: the paper's literal clusters. */
Segmentation segmentSkeleton(const SkeletonGraph& graph, float alpha);

/** (E4) Recomputes s.gates from s.cluster: one per piece of line between two clusters (two
 *  parallel lines between the same kept nodes are two gates). Bottleneck placement also moves
 *  the line's nodes to the cluster of their side of the gate. */
void placeGates(const SkeletonGraph& graph, Segmentation& s, GatePlacement placement);

}  // namespace gilab::topo
