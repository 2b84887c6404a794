#pragma once
/**
 * Exact Euclidean distance transform of a 3D binary voxel grid, for the maximal-ball radii of a
 * curve skeleton (Noel & Biri 2014). Separable lower envelope of parabolas of Felzenszwalb &
 * Huttenlocher, "Distance Transforms of Sampled Functions", Theory of Computing 8 (2012), §2.1,
 * Algorithm DT(f): one 1D pass per axis (x, then y, then z), lines of a pass run in parallel.
 *
 * Values are squared distances in voxel units between voxel centres: integers stored as float,
 * exact because they stay below 2^24 (the grid's squared diagonal is checked up front; grids up
 * to 4096 voxels per axis pass, 512^3 comfortably). Parabola intersections are compared as exact
 * int64 rationals rather than rounded floats. A grid with no feature voxel gives +infinity
 * (kNoFeatureDistance) everywhere.
 */
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/voxel/grid_dims.h"

namespace gilab {

/** The value of every voxel when the grid holds no feature voxel at all. */
inline constexpr float kNoFeatureDistance = std::numeric_limits<float>::infinity();

/**
 * Exact squared Euclidean distance from every voxel centre to the nearest voxel centre with
 * feature[i] != 0 (0 on feature voxels, kNoFeatureDistance everywhere without any). Throws
 * gilab::Error when a dimension is 0, feature.size() != dims.count(), or the grid's squared
 * diagonal reaches 2^24 (no longer exact in float).
 */
std::vector<float> squaredDistanceTransform(const std::vector<uint8_t>& feature,
                                            const GridDims& dims);

/** The square roots of squaredDistanceTransform: Euclidean distance in voxel units. */
std::vector<float> distanceTransform(const std::vector<uint8_t>& feature, const GridDims& dims);

}  // namespace gilab
