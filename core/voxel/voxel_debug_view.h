#pragma once
/**
 * Debug view of a Voxelizer's volumes: a compute pass ray-marches the grid voxel by voxel from
 * a Camera and writes the first covered voxel's albedo / normal / emission / normal length into
 * a width x height RGBA32F image (tag "voxel/debug_view"), ready to expose as a DebugView.
 * The image is left in GENERAL.
 */
#include <cstdint>

#include <vulkan/vulkan.h>

#include "core/scene/camera.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"

namespace gilab {
class Voxelizer;

enum class VoxelDebugMode : uint32_t { Albedo = 0, Normal = 1, Emission = 2, NormalLength = 3 };

class VoxelDebugView {
public:
    VoxelDebugView(vk::Context& ctx, Voxelizer& voxelizer, uint32_t width, uint32_t height);
    VoxelDebugView(const VoxelDebugView&) = delete;
    VoxelDebugView& operator=(const VoxelDebugView&) = delete;

    /** The volumes must be in SHADER_READ_ONLY_OPTIMAL (as Voxelizer::record leaves them). */
    void record(VkCommandBuffer cmd, const Camera& camera, VoxelDebugMode mode);
    vk::Image& image() { return m_image; }

private:
    Voxelizer& m_voxelizer;
    vk::Image m_image;
    vk::Sampler m_sampler;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
};

}  // namespace gilab
