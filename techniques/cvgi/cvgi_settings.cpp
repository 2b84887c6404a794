#include "cvgi_settings.h"

#include <string>

#include "core/util/error.h"

namespace gilab {
namespace {

constexpr ParamStage kRebuild = ParamStage::Rebuild;

}  // namespace

std::vector<ParamSpec> cvgiParamSpecs() {
    return {
        // Set-up (§4.1-4.3).
        intParam("voxel_resolution", 128, 32, 256, "voxels",
                 "voxels per grid axis N (paper 64, 128, 256; 32 for its Cornell box)", kRebuild),
        intParam("initial_clusters", 0, 0, 2000000, "",
                 "initial empty clusters K on a uniform grid (0 = the paper's Table 4 value: "
                 "25K / 30K / 250K / 120K at N = 32 / 64 / 128 / 256)",
                 kRebuild),
        intParam("cluster_iterations", 10, 1, 100, "", "Algorithm 1 iterations (paper 10)",
                 kRebuild),
        floatParam("cluster_angle_deg", 35.0, 1.0, 180.0, "deg",
                   "Eq. 1 normal-angle threshold (paper 35)", kRebuild),
        intParam("rays_per_face", 128, 1, 1024, "",
                 "3D Bresenham rays per voxel face for the cluster visibility (paper 128; 32 "
                 "and 64 evaluated)",
                 kRebuild),
        intParam("seed", 0, 0, 1000000000, "",
                 "ray pattern: every face's rays rotated about its normal by a hashed angle (a "
                 "Cranley-Patterson shift of the Hammersley azimuths); 0 = the unrotated rays "
                 "(the images from before the parameter)",
                 kRebuild),
        intParam("shadow_map_size", 8192, 64, 16384, "texels",
                 "emitter distance shadow map side (authors' code 8192)", kRebuild),
        intParam("camera_map_size", 256, 16, 4096, "texels",
                 "camera distance map height for the visible-voxel test (paper: \"small\")",
                 kRebuild),
        // Emitter update (§4.4).
        floatParam("lit_bias_voxels", 0.5, 0.0, 4.0, "voxels",
                   "distance tolerance of the 18-point emitter test"),
        floatParam("camera_bias_voxels", 1.0, 0.0, 8.0, "voxels",
                   "distance tolerance of the 12-point camera test"),
        boolParam("neighbour_test", true,
                  "reject a lit voxel with an occupied neighbour toward the light (Fig. 10)"),
        floatParam("near_cluster_voxels", 2.0, 0.0, 64.0, "voxels",
                   "gather a cluster voxel by voxel when its AABB is closer than this to the face "
                   "(paper: \"a given threshold\", value not given)"),
        allowValue(0, requireOdd(intParam("gaussian_kernel", 5, 1, 9, "voxels",
                                          "Gaussian kernel width, odd: a centred kernel (paper 5; "
                                          "3 evaluated); 0 or 1 = no filtering"))),
        intParam("gaussian_passes", 2, 0, 4, "", "Gaussian passes (paper 2)"),
        floatParam(
            "gaussian_sigma_voxels", 1.0, 0.1, 8.0, "voxels",
            "Gaussian standard deviation (not given in the paper; techniques/cvgi/README.md)"),
        boolParam("gaussian_visibility", true,
                  "ours: a neighbour's face enters the Gaussian only if the straight path between "
                  "the two faces' front cells crosses no occupied voxel (false = the paper's "
                  "filter, which spreads lit faces through walls up to the kernel radius)"),
        boolParam("interpolation", true,
                  "bilinear interpolation of the face irradiance between neighbour voxels "
                  "(§4.5; false = Fig. 12 row 5)"),
        enumParam("gather", "paper", {"paper", "ray_weighted"},
                  "light bounce estimator: paper = every listed lit cluster through the "
                  "face-to-cluster form factor (§4.4); ray_weighted = ours, the rays' Monte Carlo "
                  "estimate (2 pi / rays) sum over hits of the cluster's mean radiance x cos",
                  kRebuild),
    };
}

CvgiSettings cvgiSettingsFrom(const ParamSet& p) {
    CvgiSettings s;
    s.voxelResolution = uint32_t(p.getInt("voxel_resolution"));
    s.initialClusters = uint32_t(p.getInt("initial_clusters"));
    s.clusterIterations = uint32_t(p.getInt("cluster_iterations"));
    s.clusterAngleDeg = float(p.getFloat("cluster_angle_deg"));
    s.raysPerFace = uint32_t(p.getInt("rays_per_face"));
    s.seed = uint32_t(p.getInt("seed"));
    s.shadowMapSize = uint32_t(p.getInt("shadow_map_size"));
    s.cameraMapSize = uint32_t(p.getInt("camera_map_size"));
    s.litBiasVoxels = float(p.getFloat("lit_bias_voxels"));
    s.cameraBiasVoxels = float(p.getFloat("camera_bias_voxels"));
    s.neighbourTest = p.getBool("neighbour_test");
    s.nearClusterVoxels = float(p.getFloat("near_cluster_voxels"));
    s.gaussianKernel = uint32_t(p.getInt("gaussian_kernel"));
    s.gaussianPasses = uint32_t(p.getInt("gaussian_passes"));
    s.gaussianSigmaVoxels = float(p.getFloat("gaussian_sigma_voxels"));
    s.gaussianVisibility = p.getBool("gaussian_visibility");
    s.interpolation = p.getBool("interpolation");
    s.gather = p.getEnum("gather") == "ray_weighted" ? CvgiSettings::Gather::RayWeighted
                                                     : CvgiSettings::Gather::Paper;
    return s;
}

}  // namespace gilab
