#pragma once
/**
 * A single distance map: the scene rasterised from one view into an R32F image holding the
 * linear distance to the view origin (or, orthographic, along the view direction), with the
 * shadow-map shaders (shaders/common/shadow.vert/.frag) and reversed-Z depth. For techniques that
 * need their own map at their own size, e.g. the clustered voxel GI's emitter "scene geometry
 * distance shadow map" and its small camera map (Cosin Ayerbe & Patow 2022 §4.4).
 * After record() the image is SHADER_READ_ONLY_OPTIMAL; texels with no geometry hold kFar.
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {
namespace vk {
class Context;
class GpuScene;
}  // namespace vk
struct Camera;
struct PassLight;

/** One view of a distance map (mirrors shaders/common/shadow_pc.glsl). */
struct DistanceView {
    glm::mat4 viewProj{1.0f};   // world -> Vulkan clip, reversed-Z (light_view.h)
    glm::vec4 origin{0.0f};     // xyz eye or entry-plane point; w 1 = orthographic
    glm::vec4 direction{0.0f};  // xyz view axis (orthographic distance axis)
    glm::vec4 skipPlane{0.0f};
    glm::vec4 params{0.0f};

    /** The view of a light's 2D shadow map (spot or directional entry of the pass table). */
    static DistanceView fromPassLight(const PassLight& light);
    /** The camera's own view at this aspect (width / height). */
    static DistanceView fromCamera(const Camera& camera, float aspect);
};
static_assert(sizeof(DistanceView) == 128);

/** The pipeline both the shared shadow maps and DistanceMap draw with: shaders/common/shadow.*,
 *  R32F distance + D32 reversed-Z depth (GREATER), no culling (thin walls and one-sided quads
 *  must cast). Push constants: DistanceView (128 bytes). */
vk::GraphicsPipelineDesc distancePipelineDesc(const std::string& name);

class DistanceMap {
public:
    static constexpr float kFar = 3.0e38f;

    DistanceMap(vk::Context& ctx, const vk::GpuScene& scene, uint32_t width, uint32_t height,
                const std::string& name);
    DistanceMap(const DistanceMap&) = delete;
    DistanceMap& operator=(const DistanceMap&) = delete;

    void record(VkCommandBuffer cmd, const DistanceView& view);
    vk::Image& image() { return m_distance; }
    uint32_t width() const { return m_distance.width(); }
    uint32_t height() const { return m_distance.height(); }

private:
    const vk::GpuScene& m_scene;
    vk::Image m_distance, m_depth;
    vk::PipelineLayout m_layout;
    vk::GraphicsPipeline m_pipeline;
};

}  // namespace gilab
