#include "core/vk/pipeline.h"

#include <cstring>

#include "core/util/error.h"
#include "core/vk/check.h"
#include "core/vk/context.h"
#include "core/vk/image.h"
#include "core/vk/shader.h"

namespace gilab::vk {

PipelineLayout::PipelineLayout(Context& ctx, std::vector<VkDescriptorSetLayout> setLayouts,
                               uint32_t pushConstantBytes, VkShaderStageFlags pushStages,
                               const std::string& name)
    : m_pushBytes(pushConstantBytes), m_pushStages(pushStages) {
    uint32_t maxPush = ctx.properties().limits.maxPushConstantsSize;
    if (pushConstantBytes > maxPush) {
        throw Error("pipeline layout '" + name + "': " + std::to_string(pushConstantBytes) +
                    " bytes of push constants exceed the device limit of " +
                    std::to_string(maxPush));
    }
    VkPushConstantRange range{pushStages, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    info.setLayoutCount = uint32_t(setLayouts.size());
    info.pSetLayouts = setLayouts.data();
    info.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(ctx.device(), &info, nullptr, &layout));
    m_layout = PipelineLayoutHandle(ctx.device(), layout);
    ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE_LAYOUT, uint64_t(layout), name);
}

void PipelineLayout::push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const {
    if (bytes > m_pushBytes) {
        throw Error("push of " + std::to_string(bytes) + " bytes exceeds the layout's " +
                    std::to_string(m_pushBytes) + " bytes of push constants");
    }
    vkCmdPushConstants(cmd, m_layout.handle(), m_pushStages, 0, bytes, data);
}

SpecConstant specFloat(uint32_t id, float value) {
    uint32_t bits;
    std::memcpy(&bits, &value, 4);
    return {id, bits};
}

SpecConstant specInt(uint32_t id, int32_t value) {
    return {id, uint32_t(value)};
}

SpecConstant specBool(uint32_t id, bool value) {
    return {id, value ? 1u : 0u};
}

namespace {

/** Owns the storage a VkSpecializationInfo points to. */
struct Specialization {
    explicit Specialization(const std::vector<SpecConstant>& spec) {
        for (size_t i = 0; i < spec.size(); ++i) {
            entries.push_back({spec[i].id, uint32_t(i * 4), 4});
            data.push_back(spec[i].value);
        }
        info.mapEntryCount = uint32_t(entries.size());
        info.pMapEntries = entries.data();
        info.dataSize = data.size() * 4;
        info.pData = data.data();
    }
    const VkSpecializationInfo* get() const { return entries.empty() ? nullptr : &info; }
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> data;
    VkSpecializationInfo info{};
};

}  // namespace

ComputePipeline::ComputePipeline(Context& ctx, const std::string& shaderName,
                                 const PipelineLayout& layout,
                                 const std::vector<SpecConstant>& spec)
    : m_layout(layout.handle()) {
    ShaderModule module(ctx, shaderName);
    Specialization specialization(spec);
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module.handle();
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = specialization.get();
    info.layout = layout.handle();
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    m_pipeline = PipelineHandle(ctx.device(), pipeline);
    ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline), shaderName);
}

void ComputePipeline::bind(VkCommandBuffer cmd) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_pipeline.handle());
}

GraphicsPipeline::GraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc,
                                   const PipelineLayout& layout)
    : m_layout(layout.handle()) {
    const std::string name = desc.name.empty() ? desc.vertexShader : desc.name;
    if (desc.conservativeRaster && !ctx.hasConservativeRaster()) {
        throw Error("pipeline '" + name + "' wants conservative rasterization, which " +
                    ctx.deviceName() + " lacks (VK_EXT_conservative_rasterization)");
    }
    if (desc.wireframe && !ctx.hasFillModeNonSolid()) {
        throw Error("pipeline '" + name + "' wants wireframe, which " + ctx.deviceName() +
                    " lacks (fillModeNonSolid)");
    }
    if (desc.viewMask != 0 && !ctx.hasMultiview()) {
        throw Error("pipeline '" + name + "' uses a view mask, but " + ctx.deviceName() +
                    " lacks multiview");
    }

    Specialization specialization(desc.spec);
    std::vector<ShaderModule> modules;
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    auto addStage = [&](const std::string& shader, VkShaderStageFlagBits stage) {
        if (shader.empty()) return;
        modules.emplace_back(ctx, shader);
        VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        s.stage = stage;
        s.module = modules.back().handle();
        s.pName = "main";
        s.pSpecializationInfo = specialization.get();
        stages.push_back(s);
    };
    if (desc.vertexShader.empty()) throw Error("pipeline '" + name + "' has no vertex shader");
    addStage(desc.vertexShader, VK_SHADER_STAGE_VERTEX_BIT);
    addStage(desc.geometryShader, VK_SHADER_STAGE_GEOMETRY_BIT);
    addStage(desc.fragmentShader, VK_SHADER_STAGE_FRAGMENT_BIT);

    VkVertexInputBindingDescription binding{0, 32, VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12},
        {2, 0, VK_FORMAT_R32G32_SFLOAT, 24},
    };
    VkPipelineVertexInputStateCreateInfo vertexInput{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    if (desc.sceneVertexInput) {
        vertexInput.vertexBindingDescriptionCount = 1;
        vertexInput.pVertexBindingDescriptions = &binding;
        vertexInput.vertexAttributeDescriptionCount = 3;
        vertexInput.pVertexAttributeDescriptions = attributes;
    }
    VkPipelineInputAssemblyStateCreateInfo inputAssembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    inputAssembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;

    VkPipelineRasterizationConservativeStateCreateInfoEXT conservative{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_CONSERVATIVE_STATE_CREATE_INFO_EXT};
    conservative.conservativeRasterizationMode =
        VK_CONSERVATIVE_RASTERIZATION_MODE_OVERESTIMATE_EXT;
    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.pNext = desc.conservativeRaster ? &conservative : nullptr;
    raster.depthClampEnable = desc.depthClamp ? VK_TRUE : VK_FALSE;
    raster.polygonMode = desc.wireframe ? VK_POLYGON_MODE_LINE : VK_POLYGON_MODE_FILL;
    raster.cullMode = desc.cull;
    raster.frontFace = desc.frontFace;
    raster.depthBiasEnable = desc.depthBias ? VK_TRUE : VK_FALSE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

    bool hasDepth = desc.depthFormat != VK_FORMAT_UNDEFINED;
    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = hasDepth && desc.depthTest ? VK_TRUE : VK_FALSE;
    depth.depthWriteEnable = hasDepth && desc.depthWrite ? VK_TRUE : VK_FALSE;
    depth.depthCompareOp = desc.depthCompare;
    depth.minDepthBounds = 0.0f;
    depth.maxDepthBounds = 1.0f;

    std::vector<VkPipelineColorBlendAttachmentState> blends(desc.colorFormats.size());
    for (auto& b : blends) {
        b = {};
        b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                           VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
        if (desc.additiveBlend) {
            b.blendEnable = VK_TRUE;
            b.srcColorBlendFactor = b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
            b.srcAlphaBlendFactor = b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
            b.colorBlendOp = b.alphaBlendOp = VK_BLEND_OP_ADD;
        }
    }
    VkPipelineColorBlendStateCreateInfo blend{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = uint32_t(blends.size());
    blend.pAttachments = blends.data();

    std::vector<VkDynamicState> dynamic = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    if (desc.depthBias) dynamic.push_back(VK_DYNAMIC_STATE_DEPTH_BIAS);
    VkPipelineDynamicStateCreateInfo dynamicState{
        VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamicState.dynamicStateCount = uint32_t(dynamic.size());
    dynamicState.pDynamicStates = dynamic.data();

    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.viewMask = desc.viewMask;
    rendering.colorAttachmentCount = uint32_t(desc.colorFormats.size());
    rendering.pColorAttachmentFormats = desc.colorFormats.data();
    rendering.depthAttachmentFormat = desc.depthFormat;
    rendering.stencilAttachmentFormat =
        hasStencil(desc.depthFormat) ? desc.depthFormat : VK_FORMAT_UNDEFINED;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = uint32_t(stages.size());
    info.pStages = stages.data();
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &inputAssembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamicState;
    info.layout = layout.handle();
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkCreateGraphicsPipelines(ctx.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    m_pipeline = PipelineHandle(ctx.device(), pipeline);
    ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline), name);
}

void GraphicsPipeline::bind(VkCommandBuffer cmd) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_pipeline.handle());
}

void dispatch2D(VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t groupX,
                uint32_t groupY) {
    vkCmdDispatch(cmd, (width + groupX - 1) / groupX, (height + groupY - 1) / groupY, 1);
}

void dispatch1D(VkCommandBuffer cmd, uint32_t count, uint32_t groupSize) {
    vkCmdDispatch(cmd, (count + groupSize - 1) / groupSize, 1, 1);
}

}  // namespace gilab::vk
