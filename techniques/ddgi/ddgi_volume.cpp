#include "ddgi_volume.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/gpu/gpu_scene.h"
#include "core/passes/gbuffer.h"
#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/rt/gpu_bvh.h"
#include "core/scene/scene.h"
#include "core/technique/technique.h"
#include "core/util/error.h"
#include "core/util/random.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

constexpr float kPi = 3.14159265358979f;

/** Mirrors DdgiUniforms in techniques/ddgi/shaders/ddgi_common.glsl (std140). */
struct DdgiUniforms {
    glm::vec4 gridOrigin;
    glm::vec4 gridSpacing;
    glm::uvec4 counts;
    glm::uvec4 texels;
    glm::uvec4 lights;
    glm::uvec4 flags;
    glm::vec4 blend;
    glm::vec4 bias;
    glm::vec4 thresholds;
    glm::vec4 misc;
    glm::vec4 camera;
    glm::mat4 rotation;
    glm::uvec4 size;
};

enum Binding : uint32_t {
    kUniforms = 0,
    kIrradiance = 1,
    kDistance = 2,
    kRays = 3,
    kProbes = 4,
    kGPosition = 5,
    kGNormal = 6,
    kGAlbedo = 7,
    kGMaterial = 8,
    kIndirect = 9,
    kBvh = 10,
    kShadow = 12,
    kRayDirections = 16,
};

/** The next uniform in [0, 1) of a SplitMix64 stream. */
float uniform01(uint64_t& state) {
    return toUnitFloat(mix64(state += kSplitMixIncrement));
}

}  // namespace

DdgiGrid makeDdgiGrid(const Bounds& bounds, const DdgiSettings& s) {
    if (!bounds.valid())
        throw Error("ddgi: the scene has no bounds (no geometry) to place probes in");
    DdgiGrid g;
    const glm::vec3 extent = (bounds.hi - bounds.lo) * s.volumeScale;
    const float longest = std::max(extent.x, std::max(extent.y, extent.z));
    if (!(longest > 0.0f) || !std::isfinite(longest))
        throw Error("ddgi: the scene bounds have no extent to place probes in");
    const float target = longest / float(s.probeGrid - 1);
    for (int a = 0; a < 3; ++a) {
        int count = s.probeCounts[a];
        if (count == 0) count = std::max(2, int(std::lround(extent[a] / target)) + 1);
        g.counts[a] = count;
        g.spacing[a] = extent[a] > 0.0f ? extent[a] / float(count - 1) : target;
    }
    g.origin = bounds.center() - 0.5f * g.spacing * glm::vec3(g.counts - 1);
    g.maxDistance = s.maxDistanceFactor * glm::length(g.spacing);
    return g;
}

glm::mat3 arvoRotation(float u1, float u2, float u3) {
    const float theta = 2.0f * kPi * u1;  // rotation about the pole
    const float phi = 2.0f * kPi * u2;    // direction of the pole deflection
    const float z = u3;                   // amount of deflection
    const glm::mat3 r(glm::vec3(std::cos(theta), std::sin(theta), 0.0f),
                      glm::vec3(-std::sin(theta), std::cos(theta), 0.0f),
                      glm::vec3(0.0f, 0.0f, 1.0f));
    const glm::vec3 v(std::cos(phi) * std::sqrt(z), std::sin(phi) * std::sqrt(z),
                      std::sqrt(1.0f - z));
    const glm::mat3 householder = 2.0f * glm::outerProduct(v, v) - glm::mat3(1.0f);
    return householder * r;
}

glm::vec3 sphericalFibonacci(uint32_t i, uint32_t n) {
    const double goldenMinusOne = 0.6180339887498949;
    const double frac = double(i) * goldenMinusOne - std::floor(double(i) * goldenMinusOne);
    const double phi = 2.0 * 3.141592653589793 * frac;
    const double cosTheta = 1.0 - (2.0 * i + 1.0) / double(n);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    return glm::vec3(float(std::cos(phi) * sinTheta), float(std::sin(phi) * sinTheta),
                     float(cosTheta));
}

std::vector<glm::vec4> ddgiRayDirections(uint32_t rays, uint32_t fixedRays,
                                         const glm::mat3& rotation) {
    std::vector<glm::vec4> out(rays);
    for (uint32_t r = 0; r < rays; ++r) {
        const glm::vec3 d =
            r < fixedRays
                ? sphericalFibonacci(r, fixedRays)
                : glm::normalize(rotation * sphericalFibonacci(r - fixedRays, rays - fixedRays));
        out[r] = glm::vec4(d, 0.0f);
    }
    return out;
}

DdgiVolume::DdgiVolume(TechniqueContext& ctx, const DdgiSettings& s) : m_vk(ctx.vk), m_settings(s) {
    m_grid = makeDdgiGrid(ctx.scene.caps.bounds, s);
    m_rays = uint32_t(s.raysPerProbe);
    m_width = ctx.width;
    m_height = ctx.height;
    m_punctualLights = ctx.gpuScene.lightCount();
    m_emitterSamples = uint32_t(ctx.shared.shadows().emitterSamples().size());
    const Bounds& b = ctx.scene.caps.bounds;
    m_rayEpsilon = std::max(1e-4f * glm::length(b.hi - b.lo), 1e-6f);

    const uint32_t probes = m_grid.probeCount();
    const uint64_t rayBytes = uint64_t(probes) * m_rays * 16u;
    if (rayBytes > (uint64_t(1) << 30))
        throw Error("ddgi: " + std::to_string(probes) + " probes x " + std::to_string(m_rays) +
                    " rays need " + std::to_string(rayBytes >> 20) +
                    " MiB of ray buffer (limit 1024 MiB); use fewer probes or rays");
    const uint32_t limit = ctx.vk.properties().limits.maxImageDimension2D;
    auto atlasImage = [&](int interior, const std::string& name) {
        const uint32_t tile = uint32_t(interior) + 2u;
        const uint32_t w = tile * uint32_t(m_grid.counts.x * m_grid.counts.y);
        const uint32_t h = tile * uint32_t(m_grid.counts.z);
        if (w > limit || h > limit)
            throw Error("ddgi: the " + name + " atlas would be " + std::to_string(w) + " x " +
                        std::to_string(h) + " texels; the device allows " + std::to_string(limit) +
                        "; use fewer probes or texels");
        return vk::Image(
            ctx.vk, vk::imageDesc2D(w, h, VK_FORMAT_R32G32B32A32_SFLOAT,
                                    VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                        VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                    ctx.tag(name + "_atlas")));
    };
    m_irradiance = atlasImage(s.irradianceTexels, "irradiance");
    m_distance = atlasImage(s.distanceTexels, "distance");
    m_probeRays = vk::Buffer(ctx.vk, rayBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                             vk::MemoryUsage::DeviceLocal, ctx.tag("probe_rays"));
    m_probeData = vk::Buffer(ctx.vk, uint64_t(probes) * 16u,
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                 VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                             vk::MemoryUsage::DeviceLocal, ctx.tag("probe_data"));
    m_uniforms = vk::Buffer(ctx.vk, sizeof(DdgiUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                            vk::MemoryUsage::Upload, ctx.tag("uniforms"));
    m_rayDirections =
        vk::Buffer(ctx.vk, uint64_t(m_rays) * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                   vk::MemoryUsage::Upload, ctx.tag("ray_directions"));
    ctx.timeCpu("bvh_build",
                [&] { m_bvh = std::make_unique<rt::GpuBvh>(ctx.vk, ctx.scene, ctx.tag("bvh")); });

    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    std::vector<vk::DescriptorBinding> bindings = {
        {kUniforms, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, cs},
        {kIrradiance, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
        {kDistance, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
        {kRays, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
        {kProbes, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
    };
    for (uint32_t b = kGPosition; b <= kIndirect; ++b)
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs});
    rt::GpuBvh::addLayoutBindings(bindings, kBvh, cs);
    for (const vk::DescriptorBinding& b : ShadowMaps::descriptorBindings(kShadow, cs))
        bindings.push_back(b);
    bindings.push_back({kRayDirections, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs});
    m_setLayout = vk::DescriptorSetLayout(ctx.vk, bindings, ctx.tag("set"));
    m_set = vk::DescriptorSet(ctx.vk, m_setLayout, 0, ctx.tag("set"));
    m_set.writeUniformBuffer(kUniforms, m_uniforms);
    m_set.writeStorageImage(kIrradiance, m_irradiance.view());
    m_set.writeStorageImage(kDistance, m_distance.view());
    m_set.writeBuffer(kRays, m_probeRays);
    m_set.writeBuffer(kProbes, m_probeData);
    m_set.writeBuffer(kRayDirections, m_rayDirections);
    GBuffer& gb = ctx.shared.gbuffer();
    m_set.writeStorageImage(kGPosition, gb.position.view());
    m_set.writeStorageImage(kGNormal, gb.normal.view());
    m_set.writeStorageImage(kGAlbedo, gb.albedo.view());
    m_set.writeStorageImage(kGMaterial, gb.material.view());
    m_bvh->writeDescriptors(m_set, kBvh);
    ctx.shared.shadows().writeDescriptors(m_set, kShadow);
    m_sceneSet = ctx.gpuScene.set().handle();
    m_layout = vk::PipelineLayout(ctx.vk, {ctx.gpuScene.layout().handle(), m_setLayout.handle()},
                                  sizeof(uint32_t), cs);
    m_trace = vk::ComputePipeline(ctx.vk, "ddgi/probe_trace.comp", m_layout);
    m_blend = vk::ComputePipeline(ctx.vk, "ddgi/probe_blend.comp", m_layout);
    m_border = vk::ComputePipeline(ctx.vk, "ddgi/probe_border.comp", m_layout);
    if (s.relocation)
        m_relocation = vk::ComputePipeline(ctx.vk, "ddgi/probe_relocation.comp", m_layout);
    if (s.classification)
        m_classification = vk::ComputePipeline(ctx.vk, "ddgi/probe_classification.comp", m_layout);
    m_gather = vk::ComputePipeline(ctx.vk, "ddgi/gather.comp", m_layout);
}

DdgiVolume::~DdgiVolume() = default;

void DdgiVolume::rebuildBvh(const Scene& scene) {
    if (m_bvh->rebuild(scene)) m_bvh->writeDescriptors(m_set, kBvh);
}

void DdgiVolume::recordClear(VkCommandBuffer cmd) {
    const VkClearColorValue zero{};
    m_irradiance.clearColor(cmd, zero);
    m_distance.clearColor(cmd, zero);
    vkCmdFillBuffer(cmd, m_probeData.handle(), 0, VK_WHOLE_SIZE, 0u);
    vk::memoryBarrier(cmd);
}

void DdgiVolume::setFrame(const DdgiSettings& s, const DdgiFrameInputs& in) {
    m_settings = s;
    DdgiUniforms u{};
    u.gridOrigin = glm::vec4(m_grid.origin, m_grid.minSpacing());
    u.gridSpacing = glm::vec4(m_grid.spacing, m_grid.maxDistance);
    u.counts = glm::uvec4(glm::uvec3(m_grid.counts), m_grid.probeCount());
    u.texels = glm::uvec4(uint32_t(s.irradianceTexels), uint32_t(s.distanceTexels), m_rays,
                          uint32_t(s.fixedRays()));
    u.lights =
        glm::uvec4(m_punctualLights, m_emitterSamples, uint32_t(s.hitLightSamples), in.updateIndex);
    u.flags = glm::uvec4(s.feedback ? 1u : 0u, s.emissionInProbes ? 1u : 0u, s.relocation ? 1u : 0u,
                         s.classification ? 1u : 0u);
    u.blend = glm::vec4(in.hysteresis, s.irradianceGamma, s.distanceExponent, s.energyPreservation);
    const bool selfShadow = s.biasMode == DdgiBias::SelfShadow;
    u.bias = glm::vec4(selfShadow ? 0.0f : 1.0f, s.selfShadowBias * 0.75f * m_grid.minSpacing(),
                       s.normalBias, s.viewBias);
    u.thresholds = glm::vec4(s.irradianceThreshold, s.brightnessThreshold, s.backfaceThreshold,
                             s.randomBackfaceThreshold);
    u.misc = glm::vec4(m_rayEpsilon, s.minFrontfaceDistance * m_grid.minSpacing(), s.hitTextureLod,
                       s.chebyshevFloor);
    u.camera = glm::vec4(in.camera, 0.0f);
    uint64_t state = (uint64_t(s.seed) << 32) ^ in.updateIndex;
    const float u1 = uniform01(state), u2 = uniform01(state), u3 = uniform01(state);
    const glm::mat3 rotation = arvoRotation(u1, u2, u3);
    u.rotation = glm::mat4(rotation);
    m_rayDirections.uploadVector(ddgiRayDirections(m_rays, uint32_t(s.fixedRays()), rotation));
    u.size = glm::uvec4(m_width, m_height, s.seed, 0u);
    m_uniforms.upload(&u, sizeof(u));
}

void DdgiVolume::bindAndDispatch(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                                 uint32_t pushValue, uint32_t x, uint32_t y, bool twoD) {
    pipeline.bind(cmd);
    const VkDescriptorSet sets[2] = {m_sceneSet, m_set.handle()};
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 2, sets, 0,
                            nullptr);
    m_layout.push(cmd, pushValue);
    if (twoD)
        vk::dispatch2D(cmd, x, y);
    else
        vk::dispatch1D(cmd, x, 64);
}

void DdgiVolume::recordUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd) {
    const uint32_t probes = m_grid.probeCount();
    {
        PassScope pass(ctx, cmd, "probe_trace");
        bindAndDispatch(cmd, m_trace, 0u, probes * m_rays, 1, false);
        vk::memoryBarrier(cmd);
    }
    {
        PassScope pass(ctx, cmd, "probe_blend_irradiance");
        bindAndDispatch(cmd, m_blend, 0u, m_irradiance.width(), m_irradiance.height(), true);
    }
    {
        PassScope pass(ctx, cmd, "probe_blend_distance");
        bindAndDispatch(cmd, m_blend, 1u, m_distance.width(), m_distance.height(), true);
        vk::memoryBarrier(cmd);
    }
    {
        PassScope pass(ctx, cmd, "probe_border");
        bindAndDispatch(cmd, m_border, 0u, m_irradiance.width(), m_irradiance.height(), true);
        bindAndDispatch(cmd, m_border, 1u, m_distance.width(), m_distance.height(), true);
        vk::memoryBarrier(cmd);
    }
    if (m_settings.relocation) {
        PassScope pass(ctx, cmd, "probe_relocation");
        bindAndDispatch(cmd, m_relocation, 0u, probes, 1, false);
        vk::memoryBarrier(cmd);
    }
    if (m_settings.classification) {
        PassScope pass(ctx, cmd, "probe_classification");
        bindAndDispatch(cmd, m_classification, 0u, probes, 1, false);
        vk::memoryBarrier(cmd);
    }
}

void DdgiVolume::setIndirectTarget(vk::Image& indirect) {
    if (indirect.view() == m_boundIndirect) return;
    m_set.writeStorageImage(kIndirect, indirect.view());
    m_boundIndirect = indirect.view();
}

void DdgiVolume::recordGather(const TechniqueContext& ctx, VkCommandBuffer cmd) {
    PassScope pass(ctx, cmd, "gather");
    bindAndDispatch(cmd, m_gather, 0u, m_width, m_height, true);
    vk::memoryBarrier(cmd);
}

double DdgiVolume::meanIrradiance() {
    const std::vector<float> texels = m_irradiance.readbackFloat(m_vk);
    const std::vector<glm::vec4> probes = readProbeData();
    const int n = m_settings.irradianceTexels, tile = n + 2;
    const int width = int(m_irradiance.width());
    const double gamma = m_settings.irradianceGamma;
    double sum = 0.0;
    size_t count = 0;
    for (uint32_t p = 0; p < m_grid.probeCount(); ++p) {
        if (m_settings.classification && probes[p].w > 0.5f) continue;
        const int x = int(p % uint32_t(m_grid.counts.x)),
                  y = int((p / m_grid.counts.x) % m_grid.counts.y);
        const int z = int(p / uint32_t(m_grid.counts.x * m_grid.counts.y));
        const int ox = (x + y * m_grid.counts.x) * tile + 1, oy = z * tile + 1;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const float* t = &texels[4 * (size_t(oy + j) * width + (ox + i))];
                const double lum = 0.2126 * std::pow(std::max(0.0f, t[0]), gamma) +
                                   0.7152 * std::pow(std::max(0.0f, t[1]), gamma) +
                                   0.0722 * std::pow(std::max(0.0f, t[2]), gamma);
                sum += lum;
                ++count;
            }
    }
    return count ? sum / double(count) : 0.0;
}

std::vector<glm::vec4> DdgiVolume::readProbeData() {
    return m_probeData.downloadVector<glm::vec4>(m_grid.probeCount());
}

}  // namespace gilab
