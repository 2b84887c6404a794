#pragma once
/**
 * G-buffer pass: rasterises the whole scene once from a Camera (one vkCmdDraw of 3 vertices per
 * triangle, pulled from the scene set, culling off) into five RGBA32F layers and a D32 depth
 * buffer. Layer contents are documented in shaders/common/gbuffer.frag and
 * docs/shared_passes.md. Background pixels are 0 in every layer.
 *
 * Layouts after record(): the five colour layers are in GENERAL (read them as storage images,
 * or sampled with layout GENERAL); depth is in SHADER_READ_ONLY_OPTIMAL.
 */
#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/image/image.h"
#include "core/scene/camera.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {

namespace vk {
class Context;
class GpuScene;
}  // namespace vk

struct GBuffer {
    vk::Image position;  // xyz world position, w = 1 covered / 0 background
    vk::Image normal;    // xyz unit shading normal on the viewer's side, w = 1 front face seen
    vk::Image albedo;    // rgb linear base colour x texture, a = perceptual roughness
    vk::Image material;  // x metallic, y roughness, z float(material flags), w triangle id + 1
    vk::Image emission;  // rgb emitted radiance toward the camera (Le), a = 0
    vk::Image depth;     // D32_SFLOAT, hardware depth (less test)
    uint32_t width = 0;
    uint32_t height = 0;
};

class GBufferPass {
public:
    static constexpr VkFormat kColorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
    static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

    GBufferPass(vk::Context& ctx, const vk::GpuScene& scene, uint32_t width, uint32_t height);
    GBufferPass(const GBufferPass&) = delete;
    GBufferPass& operator=(const GBufferPass&) = delete;

    /** Renders the G-buffer; aspect = width / height. Leaves the layouts above. */
    void record(VkCommandBuffer cmd, const Camera& camera);
    GBuffer& images() { return m_gbuffer; }
    const GBuffer& images() const { return m_gbuffer; }

private:
    vk::Context& m_ctx;
    const vk::GpuScene& m_scene;
    GBuffer m_gbuffer;
    vk::PipelineLayout m_layout;
    vk::GraphicsPipeline m_pipeline;
};

/**
 * The "depth" output layer: distance along the camera's forward axis, dot(p - eye, forward),
 * from a read-back position layer (RGBA, row-major); 0 on the background. CPU, exact.
 */
Image computeLinearDepth(const std::vector<float>& positionRgba, uint32_t width, uint32_t height,
                         const Camera& camera);

}  // namespace gilab
