#pragma once
/** Pipeline layouts, compute pipelines and dynamic-rendering graphics pipelines. */
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/vk/handle.h"

namespace gilab::vk {

class Context;

class PipelineLayout {
public:
    PipelineLayout() = default;
    PipelineLayout(Context& ctx, std::vector<VkDescriptorSetLayout> setLayouts,
                   uint32_t pushConstantBytes = 0,
                   VkShaderStageFlags pushStages = VK_SHADER_STAGE_ALL,
                   const std::string& name = {});
    VkPipelineLayout handle() const { return m_layout.handle(); }
    uint32_t pushConstantBytes() const { return m_pushBytes; }
    VkShaderStageFlags pushStages() const { return m_pushStages; }
    /** vkCmdPushConstants over the whole declared range (bytes <= pushConstantBytes()). */
    void push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const;
    template <class T>
    void push(VkCommandBuffer cmd, const T& value) const {
        push(cmd, &value, uint32_t(sizeof(T)));
    }

private:
    PipelineLayoutHandle m_layout;
    uint32_t m_pushBytes = 0;
    VkShaderStageFlags m_pushStages = 0;
};

/** Specialisation constant: 32 bits (uint32, int or float bits, see specFloat). */
struct SpecConstant {
    uint32_t id;
    uint32_t value;
};
SpecConstant specFloat(uint32_t id, float value);
SpecConstant specInt(uint32_t id, int32_t value);
SpecConstant specBool(uint32_t id, bool value);

class ComputePipeline {
public:
    ComputePipeline() = default;
    ComputePipeline(Context& ctx, const std::string& shaderName, const PipelineLayout& layout,
                    const std::vector<SpecConstant>& spec = {});
    VkPipeline handle() const { return m_pipeline.handle(); }
    VkPipelineLayout layout() const { return m_layout; }
    /** vkCmdBindPipeline(COMPUTE). */
    void bind(VkCommandBuffer cmd) const;

private:
    PipelineHandle m_pipeline;
    VkPipelineLayout m_layout = VK_NULL_HANDLE;
};

struct GraphicsPipelineDesc {
    std::string vertexShader;
    std::string geometryShader;  // optional
    std::string fragmentShader;  // optional for depth-only
    /** Binding 0 = gilab::Vertex: pos vec3 @0, normal vec3 @12, uv vec2 @24, stride 32. */
    bool sceneVertexInput = true;
    std::vector<VkFormat> colorFormats;
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    bool depthTest = true, depthWrite = true;
    VkCompareOp depthCompare = VK_COMPARE_OP_LESS;
    VkCullModeFlags cull = VK_CULL_MODE_NONE;
    VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    bool depthBias = false;  // dynamic depth bias state (vkCmdSetDepthBias)
    bool depthClamp = false;
    bool conservativeRaster = false;  // needs VK_EXT_conservative_rasterization, else throws
    bool wireframe = false;           // needs fillModeNonSolid, else throws
    bool additiveBlend = false;       // ONE + ONE on every colour attachment
    uint32_t viewMask = 0;
    std::vector<SpecConstant> spec;  // applied to every stage
    std::string name;
};

class GraphicsPipeline {
public:
    GraphicsPipeline() = default;
    GraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc, const PipelineLayout& layout);
    VkPipeline handle() const { return m_pipeline.handle(); }
    VkPipelineLayout layout() const { return m_layout; }
    /** vkCmdBindPipeline(GRAPHICS). */
    void bind(VkCommandBuffer cmd) const;

private:
    PipelineHandle m_pipeline;
    VkPipelineLayout m_layout = VK_NULL_HANDLE;
};

/** vkCmdDispatch with the group count rounded up to cover width x height. */
void dispatch2D(VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t groupX = 8,
                uint32_t groupY = 8);
/** 1D: ceil(count / groupSize) groups. */
void dispatch1D(VkCommandBuffer cmd, uint32_t count, uint32_t groupSize = 64);

}  // namespace gilab::vk
