#pragma once
/**
 * A disk cache of the precomputed scene topology (scene_topology.h): the curve skeleton alone
 * took 109 s at 256^3 in the paper, so a topology is built once per scene geometry and set-up
 * and read back afterwards. Conventions follow the reference cache (docs/reference_cache.md):
 * content-hash keys, `$GILAB_CACHE/topology` else `results/cache/topology`, a message on stderr
 * when the folder is created, atomic writes (core/util/atomic_file.h).
 *
 * The key (topologyKey) is the XXH3-128 of a tagged, length-prefixed byte stream of what the
 * topology depends on: the two versions below, resolution, alpha (float bits), mergeVisible (one
 * byte, 0 or 1), gatePlacement (one byte), mergeVisibility (float bits) and the grid
 * margin (float bits), the scene bounds (the grid is fitted to them),
 * every vertex position and every index, and, for triangles whose material is alpha-masked (Mask or
 * Blend: the voxelizer discards fragments with alpha < cutoff,
 * shaders/common/voxel_voxelize_body.glsl), their vertex UVs, the material's alpha factor and
 * cutoff and the alpha channel, size and wrap modes of its base colour texture. Colours, normals,
 * lights, the camera, the image size and names are not hashed: the voxel occupancy does not read
 * them.
 *
 * One file per entry, `<dir>/<key>.topo`, little-endian:
 *   magic "GILABTOP" (8 bytes), format version (u32), algorithm version (u32), key (u32 length +
 *   bytes); grid origin xyz, side (f32), resolution (u32); dims nx ny nz (u32); skeletonVoxels,
 *   emptyVoxels, solidVoxels (u32); graph: position, maxball, adjacency, voxelNode, prunedNodes;
 *   segmentation: kind (u8), segmentedNode, kept, segmentedAdjacency, cluster, clusterCount,
 *   greedyClusters, gates, curvatureNodes, coverageNodes, topologyNodes; voxelCluster; world
 *   gates; then the XXH3-128 of every byte before it (16 bytes, high 64 bits first, each
 *   big-endian: the canonical XXH128 form, the digits of hashHex128). Every array is a u64
 *   element count then its elements (a vec3 is 3 f32; a gate is centre, normal (3 f32 each),
 *   radiusNeck, radius, radiusA, radiusB (f32), clusterA, clusterB (u32): 48 bytes); a list of
 * lists is a u64 count of lists, each a u64 count then u32s.
 */
#include <filesystem>
#include <optional>
#include <string>

#include "scene_topology.h"

namespace gilab {
struct Scene;

namespace topo {

/** The file layout above; bump it with any change to the layout or to SceneTopology's fields. */
inline constexpr int kTopologyFormatVersion = 4;  // 2: gate end radii, greedyClusters; 3: neck;
                                                  // 4: anchored voxels, ball metric
/** Bump when the pipeline (voxelization, distance transform, thinning, graph, segmentation,
 *  clustering, nearest node, VoxelGrid placement) changes its output: every key changes, so old
 *  entries are never read again. */
// 2: visibility merge; 3: gate placement; 4: closed at the scene's bounds, E2/E3 readings,
// ball metric, lifespan filter
inline constexpr int kTopologyAlgorithmVersion = 4;

/** 32 lower-case hex digits; see the header comment for what is hashed. Throws gilab::Error
 *  naming the scene when a triangle's material or a material's texture is out of range. */
std::string topologyKey(const Scene& scene, const TopologySettings& settings);

/** `$GILAB_CACHE/topology` when GILAB_CACHE is set and not empty, else
 *  `results/cache/topology` (relative to the working folder). */
std::filesystem::path defaultTopologyCacheDir();

/** The file of `key` in `dir`: `<dir>/<key>.topo`. */
std::filesystem::path topologyCacheFile(const std::filesystem::path& dir, const std::string& key);

/**
 * Writes `<dir>/<key>.topo` atomically (a temporary file renamed over it), creating `dir` (and
 * saying so on stderr) when it does not exist. Throws gilab::Error for a key that is not 32
 * lower-case hex digits, an inconsistent topology (the checks of loadTopology) or an I/O error.
 */
void storeTopology(const std::filesystem::path& dir, const std::string& key,
                   const SceneTopology& topology);

/**
 * Reads `<dir>/<key>.topo`. Absent: nullopt, `*why` cleared. Unreadable, truncated, wrong magic
 * or version, another key, a length beyond the file, sizes that disagree (graph arrays, voxel
 * grid, voxel counts), indices or cluster ids out of range, a gate radius that is not the minimum
 * of its end radii, greedyClusters below clusterCount, trailing bytes or a checksum
 * mismatch: nullopt with the reason (naming the file) in `*why`. Never throws.
 */
std::optional<SceneTopology> loadTopology(const std::filesystem::path& dir, const std::string& key,
                                          std::string* why = nullptr);

}  // namespace topo
}  // namespace gilab
