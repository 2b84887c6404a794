#pragma once
/**
 * `vct`: voxel cone tracing, Crassin, Neyret, Sainz, Green, Eisemann, "Interactive Indirect
 * Illumination Using Voxel Cone Tracing", CGF 30(7) 2011 (notes 001, techniques/vct/README.md).
 *
 * Set-up (timed): "voxelize" + "voxel_resolve" (core/voxel Voxelizer), "inject" (light-view maps,
 * one photon per texel, splat, voxel shade: techniques/vct/light_injection.h), "filter"
 * (VoxelRadiance mips, anisotropic by default) — or, with storage = octree, "svo_build" and
 * "inject" into the sparse voxel octree (techniques/vct/svo.h).
 * Update (issue 11, a light moved / turned / changed): the voxelization (static geometry) is
 * kept; "inject" (light views re-planned for the new lights, photons, splat, shade; octree: the
 * photons and SparseVoxelOctree::inject, which clears and rewrites all radiance) and "filter"
 * (dense mips; the octree's directional bricks are its nested "svo_filter") run again, as the
 * paper re-injects when a light moves. A camera change redoes nothing (the trace reads the
 * G-buffer every frame); only the "voxels" debug view is re-rendered in the next frame.
 * Per frame: "trace", one compute pass over the G-buffer: diffuse cones, a specular cone on glossy
 * pixels, AO cones for the "ao" debug view; writes the indirect layer (one bounce).
 */
#include <memory>
#include <vector>

#include "core/technique/technique.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
class Voxelizer;
class VoxelRadiance;
class VoxelDebugView;

namespace vct {
class LightInjection;
class SparseVoxelOctree;
}  // namespace vct

class VctTechnique final : public Technique {
public:
    VctTechnique();
    ~VctTechnique() override;
    static TechniqueInfo describe();
    void setup(TechniqueContext& ctx) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    /** power_stats: the photons' and the base volume's power (a diagnostic, after the frame). */
    void frameFinished(TechniqueContext& ctx) override;
    std::vector<DebugView> debugViews() override;

    /** Introspection for tests (valid after setup). */
    const VoxelGrid& grid() const { return m_grid; }
    vct::LightInjection* injection() { return m_injection.get(); }
    VoxelRadiance* radiance() { return m_radiance.get(); }

private:
    void createGather(TechniqueContext& ctx);
    /** Records "inject" (and, dense, "filter") for the scene's current lights. */
    void recordInjection(TechniqueContext& ctx, VkCommandBuffer cmd);

    VoxelGrid m_grid;
    bool m_octree = false;
    bool m_ao = false;
    bool m_powerStatsDue = false;  // power_stats: read the volumes after the next frame
    std::unique_ptr<Voxelizer> m_voxelizer;
    std::unique_ptr<vct::LightInjection> m_injection;
    std::unique_ptr<VoxelRadiance> m_radiance;
    std::unique_ptr<vct::SparseVoxelOctree> m_svo;
    std::unique_ptr<VoxelDebugView> m_voxelView;
    bool m_voxelViewStale = false;  // the camera moved: re-render the debug view in render()

    vk::Image m_aoImage;
    vk::Buffer m_params;  // GpuGatherParams, host-visible uniform
    vk::DescriptorSetLayout m_inputLayout, m_voxelLayout;
    vk::DescriptorSet m_inputSet, m_voxelSet;
    vk::PipelineLayout m_gatherLayout;
    vk::ComputePipeline m_gather;
};

}  // namespace gilab
