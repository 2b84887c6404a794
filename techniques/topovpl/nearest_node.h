#pragma once
/**
 * The nearest-node grid of the topological segmentation (Noël & Biri 2014 §IV-A: "a 3D grid that
 * gives for each voxel the index of the nearest node of the skeleton, with respect to the
 * geometry of the empty space"; notes 004 §2.A2, §7 point 2): a multi-source Dijkstra from every
 * skeleton voxel through the empty voxels, 26-neighbour steps of length 1, sqrt 2, sqrt 3, so a
 * voxel is labelled by the node it reaches first without crossing a wall. Solid voxels stay
 * unlabelled: a surface point is looked up through the empty voxel on its normal's side (at
 * render time, where the normal is known). Ties: the smaller voxel index is settled first.
 */
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "core/voxel/grid_dims.h"

namespace gilab::topo {

inline constexpr uint32_t kNoNode = std::numeric_limits<uint32_t>::max();

/** labels[i] = node of empty voxel i (voxelNode[k] for skeleton voxel k), kNoNode where solid or
 *  unreachable from every skeleton voxel. */
std::vector<uint32_t> nearestNodeGrid(const std::vector<uint8_t>& empty, const GridDims& dims,
                                      const std::vector<glm::ivec3>& skeletonVoxels,
                                      const std::vector<uint32_t>& voxelNode);

}  // namespace gilab::topo
