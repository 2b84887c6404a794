#pragma once
/**
 * cvgi's GPU side after set-up (Cosin Ayerbe & Patow 2022 §4.4-4.5): the static buffers built by
 * the CPU set-up (voxels, clusters, per-face visibility lists), the per-emitter-update state and
 * the passes that read them (techniques/cvgi/shaders/). Table 2's passes, recorded by
 * recordEmitterUpdate(): dist_shadow_map       the emitter's distance map (one per spot /
 * directional light) lit_cluster           lit voxels (18-point test + neighbour test), then
 * per-cluster sums camera_visible_voxel  small camera distance map + 12-point test, the gather list
 *   light_bounce          per-face gather from the visible lit clusters
 *   gaussian_filtering    the 5^3 renormalised Gaussian, twice
 * and recordFinalFrame() per frame (final_frame).
 */
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/passes/distance_map.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"
#include "core/voxel/voxel_grid.h"
#include "cvgi_settings.h"
#include "cvgi_setup.h"
#include "cvgi_voxels.h"

namespace gilab {

struct Camera;
struct TechniqueContext;
class SharedPasses;
namespace vk {
class Context;
class GpuScene;
}  // namespace vk

/** Counters read back after an update (debugging, stats and tests). */
struct CvgiCounters {
    uint32_t gathered = 0;    // voxels whose faces the last update gathered
    uint32_t visible = 0;     // camera-visible voxels in the last camera test
    uint32_t litVoxels = 0;   // lit voxels (summed over emitters) in the last emitter update
    uint32_t unresolved = 0;  // pixels of the last frame with no gathered voxel nearby
};

class CvgiGpu {
public:
    CvgiGpu(vk::Context& ctx, const vk::GpuScene& scene, SharedPasses& shared,
            const VoxelGrid& grid, vk::Buffer voxelIndex, vk::Buffer hashedPosition,
            const cvgi::CompactVoxels& voxels, const std::vector<uint8_t>& axis,
            const cvgi::Clusters& clusters, const cvgi::FaceVisibility& visibility,
            const CvgiSettings& settings, const std::string& tag);
    ~CvgiGpu();
    CvgiGpu(const CvgiGpu&) = delete;
    CvgiGpu& operator=(const CvgiGpu&) = delete;

    /** Update-stage parameters (biases, near threshold, Gaussian, interpolation). */
    void setSettings(const CvgiSettings& settings);
    /** The camera of the next camera test (writes the uniforms; call before submitting). */
    void setCamera(const Camera& camera, float aspect);

    /** Full emitter update: clears the cache (every PROCESSED flag), then all five passes. */
    void recordEmitterUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd);
    /** Camera-only update: camera test, gather of the newly visible voxels, filtering. */
    void recordCameraUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd);
    void recordFinalFrame(VkCommandBuffer cmd, vk::Image& indirect);

    CvgiCounters readCounters();
    /** Lit voxels per cluster after the last emitter update (0 = not lit). */
    std::vector<uint32_t> readLitCounts();
    /** Per voxel: rgb its radiosity B after the last emitter update (W/m^2), a lit lights. */
    std::vector<glm::vec4> readVoxelLight();
    /** The camera distance map's size, and whether the device's image limit clamped it. */
    uint32_t cameraMapWidth() const { return m_cameraMapWidth; }
    uint32_t cameraMapHeight() const { return m_cameraMapHeight; }
    bool cameraMapClamped() const { return m_cameraMapClamped; }
    /** Bytes of the buffers the bounce and the frame use (the paper's "Mem. Final"). */
    uint64_t finalBytes() const;
    /** Bytes of the compacted per-face visibility (offsets + cluster ids). */
    uint64_t visibilityBytes() const { return m_faceOffset.size() + m_faceClusters.size(); }
    uint32_t emitterCount() const { return uint32_t(m_emitters.size()); }

private:
    void writeUniforms();
    void recordCameraPasses(const TechniqueContext& ctx, VkCommandBuffer cmd);
    void bindCompute(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline);

    vk::Context& m_ctx;
    SharedPasses& m_shared;
    VoxelGrid m_grid;
    CvgiSettings m_settings;
    uint32_t m_voxelCount = 0, m_clusterCount = 0;
    bool m_packedFaceClusters = false;
    uint32_t m_raysPerFace = 0;
    uint32_t m_cameraMapWidth = 0, m_cameraMapHeight = 0;
    bool m_cameraMapClamped = false;
    std::vector<uint32_t> m_emitters;  // pass light indices with a 2D distance view
    glm::mat4 m_cameraViewProj{1.0f};
    glm::vec3 m_cameraEye{0.0f};

    vk::Buffer m_uniforms;
    vk::Buffer m_voxelIndex, m_hashedPosition, m_voxels, m_clusters, m_clusterVoxels, m_faceOffset,
        m_faceClusters, m_faceWeights;
    vk::Buffer m_voxelLight, m_clusterLight, m_voxelState, m_faceIrradiance, m_faceTemp,
        m_faceFiltered, m_counters, m_gatherList;
    std::unique_ptr<DistanceMap> m_emitterMap, m_cameraMap;
    vk::Sampler m_sampler;
    vk::DescriptorSetLayout m_setLayout, m_frameLayout;
    vk::DescriptorSet m_set, m_frameSet;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
    vk::PipelineLayout m_layout, m_frameLayoutPipeline;
    vk::ComputePipeline m_litVoxels, m_litClusters, m_cameraVisible, m_lightBounce, m_gaussian,
        m_finalFrame;
};

}  // namespace gilab
