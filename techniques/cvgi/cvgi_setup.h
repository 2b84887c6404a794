#pragma once
/**
 * cvgi set-up on the CPU (Cosin Ayerbe & Patow 2022, C&G 103, §4.2-4.3; notes 000 §2.2-2.4, §8):
 *   heuristicNormals()  the axis-aligned "heuristic normal" of each voxel (§4.2, Fig. 7)
 *   clusterVoxels()     Algorithm 1, a deterministic emulation of the GPU SLIC-like race
 *   faceVisibility()    per voxel face, the clusters seen by 3D Bresenham rays (§4.3)
 * Every choice the paper leaves open is listed in techniques/cvgi/README.md ("Set-up on the CPU").
 * Not reproduced (authors' code only, not in the paper): the cluster-merge pass and the voxel-face
 * penalty. Results are deterministic and independent of the TBB thread count.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "cvgi_voxels.h"

namespace gilab::cvgi {

/** §4.2, Fig. 7: face index 0..5 (order -x,+x,-y,+y,-z,+z) of each voxel's heuristic normal. */
std::vector<uint8_t> heuristicNormals(const CompactVoxels& voxels);

struct ClusteringParams {
    uint32_t initialClusters = 0;  // K, the requested number of (initially empty) clusters
    uint32_t iterations = 10;      // Algorithm 1 line 2
    float angleDeg = 35.f;         // Eq. 1 threshold, in (0, 180]
};

struct Clusters {
    std::vector<uint32_t> owner;  // [V] cluster id or kEmpty (unassigned)
    // Per final (compacted, non-empty) cluster:
    std::vector<glm::vec3> centre;  // grid units (voxel i spans [i,i+1)), mean of voxel centres
    std::vector<glm::vec3> normal;  // normalised mean of its voxels' axis normals
    std::vector<glm::ivec3> aabbMin, aabbMax;   // inclusive voxel coordinates
    std::vector<glm::vec3> reflectance;         // mean voxel albedo
    std::vector<uint32_t> voxelOffset, voxels;  // CSR [C+1]; compact voxel indices, ascending
    // CSR [C+1]: the clusters owning a 26-neighbour of any of its voxels, sorted, without itself.
    std::vector<uint32_t> neighbourOffset, neighbours;
    // Statistics
    uint32_t seeds = 0;       // seeds placed on the uniform grid
    uint32_t deadSeeds = 0;   // seeds whose window holds no occupied voxel (never iterated)
    float seedSpacing = 0;    // S, voxels
    uint32_t unassigned = 0;  // voxels with no owner
    std::vector<uint32_t> nonEmptyPerIteration;  // as the paper's Fig. 8

    uint32_t count() const { return uint32_t(centre.size()); }
};

/** Algorithm 1 (§4.2); `axis` is heuristicNormals(voxels). Throws gilab::Error on bad params. */
Clusters clusterVoxels(const CompactVoxels& voxels, const std::vector<uint8_t>& axis,
                       const ClusteringParams& params);

/**
 * K the authors use for a grid of N^3 (their code; Table 4 "SupePixel #"): 32 -> 25000,
 * 64 -> 30000, 128 -> 250000, 256 -> 120000, 512 -> 250000. Other N keep the seed spacing of the
 * nearest listed N (nearest in log2 N, the smaller on a tie): K = K_listed * (N / N_listed)^3.
 */
uint32_t paperInitialClusters(uint32_t resolution);

struct VisibilityParams {
    uint32_t raysPerFace = 128;  // §4.3 default; 32 and 64 also evaluated in the paper
    /** Rotation of every face's ray set about its face normal, in turns [0, 1): the
     *  technique's `seed` (0 = none, the rays from before the parameter). */
    double rotation = 0.0;
};

struct FaceVisibility {
    std::vector<uint32_t> offset;    // [6V + 1] CSR, face f of voxel i at 6 * i + f
    std::vector<uint32_t> clusters;  // distinct cluster ids per face, in first-hit ray order
    // Per entry (parallel to `clusters`): the face's rays that stopped in that cluster, and the
    // sum of their cosines to the face's axis over the rays that met the cluster's front (its
    // mean normal against the ray): the `ray_weighted` gather's weights (ours, not the paper's).
    std::vector<uint32_t> hits;
    std::vector<float> cosineSums;
    std::vector<uint8_t> buried;  // [6V] 1 = the voxel in front of the face is occupied
    uint32_t rays = 0;            // rays per face
    uint64_t raysTraced = 0;      // V * 6 * rays (a buried face's rays all stop at the start voxel)
    uint32_t maxPerFace = 0;
    uint64_t uncompactedEntries = 0;  // V * 6 * rays: one entry per ray and face
    uint64_t paperEntries = 0;        // V * N * 6: the paper's brute-force layout (§4.3 "14-22%")

    uint32_t countOf(uint32_t voxel, uint32_t face) const {
        return offset[6 * voxel + face + 1] - offset[6 * voxel + face];
    }
};

/** §4.3: the clusters each voxel face sees. Throws gilab::Error on bad params. */
FaceVisibility faceVisibility(const CompactVoxels& voxels, const Clusters& clusters,
                              const VisibilityParams& params);

/**
 * What the open faces (not buried) of a FaceVisibility see, summed per cluster id: the sampling
 * statistics of §4.3's lists (ours), kept after the set-up so each emitter update can say how
 * many of its lit clusters any face can gather and what share of the rays see one.
 */
struct ClusterSightings {
    std::vector<uint64_t> rayHits;   // [cluster id] rays of open faces that stopped in it
    std::vector<uint32_t> faceHits;  // [cluster id] open faces whose lists hold it
    uint64_t openFaces = 0;
    uint64_t openEntries = 0;  // distinct (open face, cluster) pairs
    uint32_t rays = 0;         // rays per face

    double clustersPerFace() const { return openFaces ? double(openEntries) / openFaces : 0.0; }
};
ClusterSightings clusterSightings(const FaceVisibility& visibility, uint32_t clusterIds);

/**
 * `rays` unit directions about +z, uniform in solid angle (Hammersley at stratum centres:
 * cos theta = 1 - (i + 1/2)/rays, phi = 2 pi ((radicalInverse2(i) + rotation) mod 1)); the
 * cosines sum to exactly rays / 2 whatever the rotation. `rotation` (turns in [0, 1)) is a
 * Cranley-Patterson rotation (Cranley & Patterson 1976) of the azimuth coordinate alone, i.e. a
 * rotation of the whole set about +z: the cos-theta strata, and so the cosine sum, stay exact.
 * 0 gives the unrotated set bit for bit. Deterministic.
 */
std::vector<glm::vec3> hemisphereDirections(uint32_t rays, double rotation = 0.0);

/** The rotation (turns in [0, 1)) of cvgi's `seed` parameter: 0 for seed 0, else the first
 *  coordinate of vpl::cranleyPattersonShift(seed) (a hash of the seed). */
double seedRotation(uint32_t seed);

/** Rotates a direction about +z so that +z maps to the axis of `face` (order -x,+x,-y,+y,-z,+z). */
glm::vec3 toFaceFrame(const glm::vec3& local, uint32_t face);

/**
 * The voxels of the integer 3D Bresenham line from `from` to `to` (both included), driven by the
 * dominant axis with one error term per other axis. Exposed for the tests.
 */
std::vector<glm::ivec3> bresenhamLine(glm::ivec3 from, glm::ivec3 to);

}  // namespace gilab::cvgi
