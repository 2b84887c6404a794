#pragma once
/**
 * The visibility merge of topological clusters: OUR addition after the paper's greedy clusters
 * (E3, skeleton_graph.h), not in Noël & Biri 2014.
 *
 * Why: a paper cluster stands for a quasi-convex piece of the empty space (the union of its
 * maximal balls, in which everything sees everything). The greedy alpha rule does not find it
 * on the simplest case: two rooms joined by a door came out as 4 clusters and 3 gates (the
 * approach to the door is its own cluster: coverage nodes sit just outside the room centre's
 * ball by construction, and the radii along the approach differ by more than alpha). The merge
 * restores the defining property instead of tuning alpha.
 *
 * Rule: two clusters joined by a segmented edge merge when every pair of kept nodes of their
 * union is mutually visible, a node standing for its maximal ball: every sample of one ball
 * (ballSamples: the node's voxel and its six axis poles just inside the ball) sees every sample
 * of the other, i.e. the straight segment between the two voxel centres (segmentVisible) crosses
 * only empty voxels. (The node centres alone are not enough: the skeleton of two rooms joined by
 * a door is one straight line through the doorway, every node of it sees every other, and all
 * would merge into one cluster; the balls' poles beside the door do not see each other through
 * the wall.) Greedy and deterministic: clusters in ascending id
 * (the greedy ids, in seed order by decreasing radius), each with its neighbours in ascending id;
 * a merged cluster keeps the smaller id and is rescanned; passes repeat until none merges. The
 * ids are then made dense in ascending order of the smallest merged id (no merge: unchanged).
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/voxel/grid_dims.h"
#include "skeleton_graph.h"

namespace gilab::topo {

/**
 * True when the segment between the centres of voxels a and b (coordinates + 0.5) crosses only
 * empty voxels (empty[dims.index(v)] != 0; outside the grid counts as solid). Exact integer 3D
 * DDA over the supercover: where the segment passes through a voxel edge or corner, every voxel
 * sharing that edge or corner must be empty too (a diagonal wall of two voxels meeting at an
 * edge blocks). a and b themselves are tested. Symmetric and deterministic.
 */
bool segmentVisible(const std::vector<uint8_t>& empty, const GridDims& dims, glm::ivec3 a,
                    glm::ivec3 b);

/** The voxel a node stands for in segmentVisible: its position rounded (a clump's mean). */
glm::ivec3 nodeVoxel(const SkeletonGraph& graph, uint32_t node);

/** The samples of a node's maximal ball for the merge: nodeVoxel, then (when the radius exceeds
 *  one voxel) the six voxels k = ceil(maxball) - 1 voxels away along -x, +x, -y, +y, -z, +z. */
std::vector<glm::ivec3> ballSamples(const SkeletonGraph& graph, uint32_t node);

/**
 * Merges the clusters of `s` (s.cluster of every graph node, s.clusterCount) as described above,
 * in place; `threshold` < 1 relaxes "every pair" to "this share of all sample pairs of every node
 * pair" (quasi-convex: a few pairs may be blocked, e.g. by a pillar); gates are not touched (the
 * caller places them after). Returns the number of merges.
 */
uint32_t mergeVisibleClusters(const SkeletonGraph& graph, Segmentation& s,
                              const std::vector<uint8_t>& empty, const GridDims& dims,
                              float threshold = 1.0f);

}  // namespace gilab::topo
