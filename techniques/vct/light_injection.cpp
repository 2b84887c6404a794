#include "techniques/vct/light_injection.h"

#include "core/passes/light_view.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/scene/scene.h"
#include "core/technique/technique.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab::vct {
namespace {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

/** Mirrors InjectPush in shaders/vct/inject_common.glsl. */
struct InjectPush {
    GpuVoxelGrid grid;
    glm::vec4 scale{0.0f};  // x units per W, y W per unit
    glm::uvec4 counts{0u};  // x photon count
};

/** Orthographic: ndc = (x.(p - c), y.(p - c)) / r; depth = 1 - distance from the entry plane /
 *  (2r) (reversed Z), entry plane through c - f r. */
glm::mat4 orthoViewProj(const glm::vec3& c, const glm::vec3& f, const glm::vec3& x,
                        const glm::vec3& y, float r) {
    glm::mat4 m(0.0f);
    const glm::vec3 entry = c - f * r;
    for (int i = 0; i < 3; ++i) {
        m[i][0] = x[i] / r;
        m[i][1] = y[i] / r;
        m[i][2] = -f[i] / (2.0f * r);
    }
    m[3][0] = -glm::dot(x, c) / r;
    m[3][1] = -glm::dot(y, c) / r;
    m[3][2] = 1.0f + glm::dot(f, entry) / (2.0f * r);
    m[3][3] = 1.0f;
    return m;
}

void basisFor(const glm::vec3& f, glm::vec3& x, glm::vec3& y) {
    const glm::vec3 up = std::abs(f.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    x = glm::normalize(glm::cross(f, up));
    y = glm::cross(f, x);  // right-handed (x, y, f); y points "down" in the map
}

}  // namespace

std::vector<GpuLightView> buildLightViews(const Scene& scene, const VoxelGrid& grid) {
    std::vector<GpuLightView> views;
    const glm::vec3 centre = grid.origin() + glm::vec3(0.5f * grid.side());
    const float radius = 0.5f * std::sqrt(3.0f) * grid.side() * 1.01f;
    const float nearZ = 1e-3f * grid.voxelSize();
    for (size_t li = 0; li < scene.lights.size(); ++li) {
        const Light& l = scene.lights[li];
        const glm::vec3 dir =
            glm::length(l.direction) > 0.0f ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
        GpuLightView base;
        base.intensity = glm::vec4(l.intensity, 0.0f);
        base.cone = glm::vec4(std::cos(l.innerConeRad), std::cos(l.outerConeRad), float(li), 0.0f);
        if (l.type == LightType::Directional) {
            glm::vec3 x, y;
            basisFor(dir, x, y);
            GpuLightView v = base;
            v.viewProj = orthoViewProj(centre, dir, x, y, radius);
            v.positionKind = glm::vec4(centre, 1.0f);
            v.forward = glm::vec4(dir, 0.0f);
            v.axisX = glm::vec4(x * radius, radius);
            v.axisY = glm::vec4(y * radius, radius);
            views.push_back(v);
            continue;
        }
        const bool spot = l.type == LightType::Spot;
        if (spot) base.spotAxis = glm::vec4(dir, 1.0f);
        if (spot && glm::degrees(l.outerConeRad) <= kSpotCubeOuterDeg) {
            // One perspective map whose square just contains the outer cone
            const float tanHalf = std::tan(std::max(l.outerConeRad, 1e-3f));
            glm::vec3 x, y;
            basisFor(dir, x, y);
            GpuLightView v = base;
            v.viewProj = pinholeViewProj(l.position, dir, x, y, tanHalf, nearZ);
            v.positionKind = glm::vec4(l.position, 0.0f);
            v.forward = glm::vec4(dir, 0.0f);
            v.axisX = glm::vec4(x * tanHalf, tanHalf);
            v.axisY = glm::vec4(y * tanHalf, tanHalf);
            views.push_back(v);
            continue;
        }
        for (const CubeFace& face : kCubeFaces) {
            GpuLightView v = base;
            v.viewProj = pinholeViewProj(l.position, face.m, face.s, face.t, 1.0f, nearZ);
            v.positionKind = glm::vec4(l.position, 0.0f);
            v.forward = glm::vec4(face.m, 0.0f);
            v.axisX = glm::vec4(face.s, 1.0f);
            v.axisY = glm::vec4(face.t, 1.0f);
            views.push_back(v);
        }
    }
    return views;
}

glm::dvec3 lightViewFluxBound(const GpuLightView& view) {
    const glm::dvec3 intensity(view.intensity);
    if (view.positionKind.w > 0.5f) {
        const double side = 2.0 * double(view.axisX.w);
        return intensity * side * side;
    }
    // Solid angle of the square pinhole frustum: 4 asin(t^2 / (1 + t^2)) for half-width t
    const double t = double(view.axisX.w);
    return intensity * 4.0 * std::asin(t * t / (1.0 + t * t));
}

LightInjection::LightInjection(TechniqueContext& ctx, const VoxelGrid& grid, uint32_t mapResolution)
    : m_vk(ctx.vk), m_scene(ctx.gpuScene), m_grid(grid), m_mapResolution(mapResolution) {
    if (mapResolution < 8 || mapResolution > 4096) {
        throw Error("vct: light_map_resolution = " + std::to_string(mapResolution) +
                    " outside [8, 4096]");
    }
    m_views = buildLightViews(ctx.scene, grid);
    m_floatAtomics = ctx.vk.hasFloatAtomics();
    const uint64_t photons = uint64_t(m_views.size()) * mapResolution * mapResolution;
    const uint64_t photonBytes = std::max<uint64_t>(photons, 1) * sizeof(GpuPhoton);
    if (photonBytes > ctx.vk.properties().limits.maxStorageBufferRange) {
        throw Error("vct: light_map_resolution = " + std::to_string(mapResolution) + " gives " +
                    std::to_string(photons) + " photons (" + std::to_string(photonBytes >> 20) +
                    " MiB), above the device's maxStorageBufferRange");
    }
    m_photonCount = uint32_t(photons);

    // Fixed-point scale: the whole flux of every light fits in 2^31 units, so no voxel overflows
    double fluxBound = 0.0;
    for (const GpuLightView& v : m_views) {
        const glm::dvec3 f = lightViewFluxBound(v);
        fluxBound += std::max({f.x, f.y, f.z});
    }
    m_fixedScale = fluxBound > 0.0 ? 2.0e9 / fluxBound : 1.0;

    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    m_photons =
        vk::Buffer(ctx.vk, photonBytes, storage, vk::MemoryUsage::DeviceLocal, ctx.tag("photons"));
    m_viewBuffer = vk::Buffer(ctx.vk, std::max<size_t>(m_views.size(), 1) * sizeof(GpuLightView),
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::DeviceLocal,
                              ctx.tag("light_views"));
    m_viewBuffer.uploadVector(m_views);

    vk::ImageDesc pos;
    pos.kind = vk::ImageKind::Image2DArray;
    pos.format = kPositionFormat;
    pos.width = pos.height = mapResolution;
    pos.layers = std::max<uint32_t>(uint32_t(m_views.size()), 1);
    pos.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    pos.name = ctx.tag("light_view_positions");
    m_positionMap = vk::Image(ctx.vk, pos);
    vk::ImageDesc depth;
    depth.format = kDepthFormat;
    depth.width = depth.height = mapResolution;
    depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    depth.name = ctx.tag("light_view_depth");
    m_depth = vk::Image(ctx.vk, depth);

    m_rasterLayout = vk::PipelineLayout(ctx.vk, {m_scene.layout().handle()}, sizeof(glm::mat4));
    vk::GraphicsPipelineDesc desc;
    desc.vertexShader = "vct/light_view.vert";
    desc.fragmentShader = "vct/light_view.frag";
    desc.sceneVertexInput = false;
    desc.colorFormats = {kPositionFormat};
    desc.depthFormat = kDepthFormat;
    desc.depthCompare = VK_COMPARE_OP_GREATER;  // reversed Z
    desc.cull = VK_CULL_MODE_NONE;
    desc.name = ctx.tag("light_view");
    m_raster = vk::GraphicsPipeline(ctx.vk, desc, m_rasterLayout);

    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_photonSetLayout = vk::DescriptorSetLayout(ctx.vk,
                                                {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                                 {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                                 {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                                ctx.tag("photons"));
    m_photonSet = vk::DescriptorSet(ctx.vk, m_photonSetLayout, 0, ctx.tag("photons"));
    m_photonSet.writeStorageImage(0, m_positionMap.view());
    m_photonSet.writeBuffer(1, m_viewBuffer);
    m_photonSet.writeBuffer(2, m_photons);
    m_photonLayout = vk::PipelineLayout(ctx.vk, {m_photonSetLayout.handle()}, sizeof(glm::uvec4));
    m_photonPipeline = vk::ComputePipeline(ctx.vk, "vct/photon_generate.comp", m_photonLayout);
}

void LightInjection::recordPhotons(TechniqueContext& ctx, VkCommandBuffer cmd) {
    {
        PassScope pass(ctx, cmd, "inject.light_view");
        m_positionMap.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        m_raster.bind(cmd);
        VkDescriptorSet set = m_scene.set().handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_rasterLayout.handle(), 0, 1,
                                &set, 0, nullptr);
        for (uint32_t layer = 0; layer < m_views.size(); ++layer) {
            m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
            vk::ColorTarget color{m_positionMap.layerView(layer, 0),
                                  VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}},
                                  VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
            vk::DepthTarget depth;
            depth.view = m_depth.view();
            depth.clear = 0.0f;  // reversed Z
            depth.store = false;
            vk::RenderingScope scope(cmd, {m_mapResolution, m_mapResolution}, {color}, depth);
            m_rasterLayout.push(cmd, m_views[layer].viewProj);
            if (m_scene.triangleCount() > 0) vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
        m_positionMap.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    }
    {
        PassScope pass(ctx, cmd, "inject.photons");
        vkCmdFillBuffer(cmd, m_photons.handle(), 0, VK_WHOLE_SIZE, 0);
        vk::memoryBarrier(cmd);
        if (!m_views.empty()) {
            m_photonPipeline.bind(cmd);
            VkDescriptorSet set = m_photonSet.handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_photonLayout.handle(), 0,
                                    1, &set, 0, nullptr);
            m_photonLayout.push(cmd, glm::uvec4(m_mapResolution, uint32_t(m_views.size()), 0, 0));
            const uint32_t groups = (m_mapResolution + 7) / 8;
            vkCmdDispatch(cmd, groups, groups, uint32_t(m_views.size()));
        }
        vk::memoryBarrier(cmd);
    }
}

void LightInjection::ensureDenseResources(TechniqueContext& ctx) {
    if (!m_flux.empty()) return;
    const VkDeviceSize planeBytes = VkDeviceSize(m_grid.voxelCount()) * 4;
    if (planeBytes > ctx.vk.properties().limits.maxStorageBufferRange) {
        throw Error("vct: voxel_resolution = " + std::to_string(m_grid.resolution()) +
                    " needs a flux plane above the device's maxStorageBufferRange");
    }
    static const char* kPlane[3] = {"flux.r", "flux.g", "flux.b"};
    for (const char* name : kPlane) {
        m_flux.emplace_back(ctx.vk, planeBytes,
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                            vk::MemoryUsage::DeviceLocal, ctx.tag(name));
    }
    if (m_splatLayout.handle() != VK_NULL_HANDLE) return;
    vk::SamplerDesc s;
    s.filter = VK_FILTER_NEAREST;
    s.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    s.name = ctx.tag("nearest");
    m_nearest = vk::Sampler(ctx.vk, s);
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_splatSetLayout =
        vk::DescriptorSetLayout(ctx.vk,
                                {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                 {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
                                 {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3, cs},
                                 {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}},
                                ctx.tag("splat"));
    m_splatLayout = vk::PipelineLayout(ctx.vk, {m_splatSetLayout.handle()}, sizeof(InjectPush));
    m_splat = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/splat_dense.comp" : "vct/splat_dense_fixed.comp",
        m_splatLayout);
    m_shade16 = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/inject_shade.comp" : "vct/inject_shade_fixed.comp",
        m_splatLayout);
    m_shade32 = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/inject_shade_f32.comp" : "vct/inject_shade_fixed_f32.comp",
        m_splatLayout);
}

void LightInjection::recordSplat(TechniqueContext& ctx, VkCommandBuffer cmd,
                                 vk::Image& albedoOpacity) {
    ensureDenseResources(ctx);
    m_splatSet = vk::DescriptorSet(ctx.vk, m_splatSetLayout, 0, ctx.tag("splat"));
    m_splatSet.writeBuffer(0, m_photons);
    m_splatSet.writeSampledImage(1, albedoOpacity.view(), m_nearest.handle(),
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    for (uint32_t k = 0; k < 3; ++k)
        m_splatSet.writeBuffer(2, m_flux[k], k);

    PassScope pass(ctx, cmd, "inject.splat");
    for (const vk::Buffer& plane : m_flux)
        vkCmdFillBuffer(cmd, plane.handle(), 0, VK_WHOLE_SIZE, 0);
    vk::memoryBarrier(cmd);
    m_splat.bind(cmd);
    VkDescriptorSet set = m_splatSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_splatLayout.handle(), 0, 1, &set,
                            0, nullptr);
    InjectPush push{m_grid.gpu(), glm::vec4(float(m_fixedScale), float(1.0 / m_fixedScale), 0, 0),
                    glm::uvec4(m_photonCount, 0, 0, 0)};
    m_splatLayout.push(cmd, push);
    vk::dispatch1D(cmd, m_photonCount, 64);
    vk::memoryBarrier(cmd);
}

void LightInjection::recordShade(TechniqueContext& ctx, VkCommandBuffer cmd,
                                 vk::Image& albedoOpacity, vk::Image& target) {
    ensureDenseResources(ctx);
    const bool f32 = target.format() == VK_FORMAT_R32G32B32A32_SFLOAT;
    if (!f32 && target.format() != VK_FORMAT_R16G16B16A16_SFLOAT) {
        throw Error("vct: radiance volume must be RGBA16F or RGBA32F");
    }
    m_shadeSet = vk::DescriptorSet(ctx.vk, m_splatSetLayout, 0, ctx.tag("shade"));
    m_shadeSet.writeSampledImage(1, albedoOpacity.view(), m_nearest.handle(),
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    for (uint32_t k = 0; k < 3; ++k)
        m_shadeSet.writeBuffer(2, m_flux[k], k);
    m_shadeSet.writeStorageImage(3, target.view());

    PassScope pass(ctx, cmd, "inject.shade");
    target.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    (f32 ? m_shade32 : m_shade16).bind(cmd);
    VkDescriptorSet set = m_shadeSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_splatLayout.handle(), 0, 1, &set,
                            0, nullptr);
    InjectPush push{m_grid.gpu(), glm::vec4(float(m_fixedScale), float(1.0 / m_fixedScale), 0, 0),
                    glm::uvec4(m_photonCount, 0, 0, 0)};
    m_splatLayout.push(cmd, push);
    const uint32_t groups = (m_grid.resolution() + 3) / 4;
    vkCmdDispatch(cmd, groups, groups, groups);
    vk::memoryBarrier(cmd);
}

std::vector<GpuPhoton> LightInjection::readPhotons() {
    return m_photons.downloadVector<GpuPhoton>(m_photonCount);
}

std::vector<glm::vec3> LightInjection::readVoxelFlux() {
    if (m_flux.empty()) throw Error("vct: flux accumulators were released or never made");
    const size_t n = m_grid.voxelCount();
    std::vector<glm::vec3> out(n, glm::vec3(0.0f));
    for (int k = 0; k < 3; ++k) {
        if (m_floatAtomics) {
            const std::vector<float> v = m_flux[k].downloadVector<float>(n);
            for (size_t i = 0; i < n; ++i)
                out[i][k] = v[i];
        } else {
            const std::vector<uint32_t> v = m_flux[k].downloadVector<uint32_t>(n);
            for (size_t i = 0; i < n; ++i)
                out[i][k] = float(double(v[i]) / m_fixedScale);
        }
    }
    return out;
}

size_t LightInjection::memoryBytes() const {
    size_t bytes = size_t(m_photons.size()) + size_t(m_viewBuffer.size());
    const size_t texels = size_t(m_mapResolution) * m_mapResolution;
    bytes += texels * 16 * std::max<size_t>(m_views.size(), 1) + texels * 4;
    for (const vk::Buffer& b : m_flux)
        bytes += size_t(b.size());
    return bytes;
}

}  // namespace gilab::vct
