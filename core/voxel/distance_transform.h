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
 *
 * Also the chessboard (L-infinity, 26-neighbour) distance and its opening function, for the
 * lifespan filter of the authors' thinning (Chaussard, Noel, Biri & Couprie, DGCI 2013; see
 * core/voxel/thinning.h). Both are separable with one linear-time 1D pass per axis: the distance
 * as the lower envelope of the cones max(|u - j|, f(j)), the opening as a max over the intervals
 * |u - c| <= f(c) - 1 (a chessboard ball is a cube, the product of three such intervals).
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

/** The chessboard value of every voxel when the grid holds no feature voxel at all. */
inline constexpr uint32_t kNoFeatureChessboard = std::numeric_limits<uint32_t>::max();

/**
 * Exact chessboard (L-infinity, 26-neighbour) distance in voxels from every voxel to the nearest
 * voxel with feature[i] != 0: 0 on feature voxels, 1 on voxels touching one by a face, edge or
 * corner, and so on; kNoFeatureChessboard everywhere without any feature voxel. The empty cube
 * of half-width d - 1 around a voxel of distance d is its chessboard maximal ball. O(voxels),
 * lines in parallel. Throws gilab::Error when a dimension is 0 or feature.size() != dims.count().
 */
std::vector<uint32_t> chessboardDistanceTransform(const std::vector<uint8_t>& feature,
                                                  const GridDims& dims);

/**
 * Opening function of a chessboard distance map: at every voxel x, the largest distance[c] over
 * voxels c with max_i |x_i - c_i| <= distance[c] - 1, i.e. the half-width + 1 of the largest
 * chessboard ball (cube) around any centre that still contains x; >= distance[x] (x is its own
 * centre), == distance[x] where x is the centre of a maximal ball, 0 where distance[x] == 0.
 * Exact for any map of finite values; a map that is kNoFeatureChessboard everywhere (no feature)
 * is returned as it is. O(voxels), lines in parallel. Throws gilab::Error when a dimension is 0,
 * distance.size() != dims.count(), or the map mixes kNoFeatureChessboard with finite values.
 */
std::vector<uint32_t> chessboardOpening(const std::vector<uint32_t>& distance,
                                        const GridDims& dims);

}  // namespace gilab
