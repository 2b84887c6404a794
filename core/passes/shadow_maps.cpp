#include "core/passes/shadow_maps.h"

#include "core/passes/light_view.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/passes/distance_map.h"
#include "core/passes/shadow_cascades.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab {
namespace {

constexpr float kNoOccluder = 3.0e38f;           // cleared distance: everything is lit
constexpr float kSpotMarginRad = 0.0872665f;     // 5 deg added to the spot map's fov
constexpr float kMaxSpotFovRad = 2.9670597f;     // 170 deg
constexpr float kCubeSpotOuterRad = 1.4835299f;  // outer cones above 85 deg use a cube

glm::vec3 upFor(const glm::vec3& dir) {
    return std::abs(dir.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

/** Perspective with Vulkan y-down, reversed-Z and an infinite far plane. */
glm::mat4 spotViewProj(const glm::vec3& eye, const glm::vec3& dir, float fov, float nearZ) {
    const float f = 1.0f / std::tan(0.5f * fov);
    glm::mat4 p(0.0f);
    p[0][0] = f;
    p[1][1] = -f;
    p[2][3] = -1.0f;  // clip.w = -z_view
    p[3][2] = nearZ;  // clip.z = near  ->  depth = near / distance
    return p * glm::lookAtRH(eye, eye + dir, upFor(dir));
}

/** The whole-scene orthographic frame of a directional light: the bounding sphere (x 1.02). */
OrthoLightFrame orthoFrame(const glm::vec3& center, float radius, const glm::vec3& dir) {
    OrthoLightFrame f;
    f.radius = 1.02f * radius + 1e-4f;
    f.direction = dir;
    f.origin = center - dir * f.radius;
    return f;
}

vk::Image makeDistanceImage(vk::Context& ctx, vk::ImageKind kind, uint32_t size, uint32_t layers,
                            const char* name) {
    vk::ImageDesc desc;
    desc.kind = kind;
    desc.format = ShadowMaps::kDistanceFormat;
    desc.width = size;
    desc.height = size;
    desc.layers = layers;
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = std::string("shared/shadow.") + name;
    return vk::Image(ctx, desc);
}

}  // namespace

ShadowMaps::ShadowMaps(vk::Context& ctx, vk::GpuScene& scene, const ShadowSettings& settings,
                       uint32_t areaLightSamples, float aspect)
    : m_ctx(ctx), m_scene(scene), m_settings(settings), m_aspect(aspect) {
    if (settings.resolution == 0 || settings.areaResolution == 0) {
        throw Error("ShadowSettings: resolution and areaResolution must be non-zero");
    }
    if (settings.pcfRadius < 0) throw Error("ShadowSettings: pcfRadius must be >= 0");
    if (!(settings.cascadeSplit >= 0.0f && settings.cascadeSplit <= 1.0f))
        throw Error("ShadowSettings: cascadeSplit must be in [0, 1]");
    if (!(settings.cascadeBlend >= 0.0f && settings.cascadeBlend <= 0.5f))
        throw Error("ShadowSettings: cascadeBlend must be in [0, 0.5]");
    if (!(aspect > 0.0f) || !std::isfinite(aspect))
        throw Error("ShadowMaps: the frame's aspect ratio must be positive");
    buildLightTable(scene, areaLightSamples);
    createImages();

    vk::SamplerDesc sampler;
    sampler.filter = VK_FILTER_NEAREST;
    sampler.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sampler.name = "shared/shadow.sampler";
    m_sampler = vk::Sampler(ctx, sampler);

    m_layout = vk::PipelineLayout(ctx, {scene.layout().handle()}, sizeof(Job::Push));
    static_assert(kDistanceFormat == VK_FORMAT_R32_SFLOAT && kDepthFormat == VK_FORMAT_D32_SFLOAT);
    m_pipeline = vk::GraphicsPipeline(ctx, distancePipelineDesc("shared/shadow_maps"), m_layout);
}

ShadowMaps::Frame ShadowMaps::sceneFrame() const {
    const Scene& scene = m_scene.scene();
    const Bounds& b = scene.caps.bounds;
    Frame f;
    f.center = b.valid() ? b.center() : glm::vec3(0.0f);
    f.radius = b.valid() ? std::max(0.5f * glm::length(b.extent()), 1e-3f) : 1.0f;
    f.nearZ = 1e-3f * f.radius;
    return f;
}

void ShadowMaps::addCubeJobs(const PassLight& light, uint32_t lightIndex, ShadowKind kind,
                             uint32_t cube, const Job::Push& base, float nearZ,
                             std::vector<Job>& jobs) const {
    for (int face = 0; face < 6; ++face) {
        Job job{kind, cube * 6 + uint32_t(face), lightIndex, false, base};
        const CubeFace& f = kCubeFaces[face];
        job.push.viewProj =
            pinholeViewProj(glm::vec3(light.positionType), f.m, f.s, f.t, 1.0f, nearZ);
        job.push.origin = glm::vec4(glm::vec3(light.positionType), 0.0f);
        jobs.push_back(job);
    }
}

PassLight ShadowMaps::sceneLightEntry(const Light& l, uint32_t index, ShadowKind kind,
                                      uint32_t slot, std::vector<Job>& jobs) {
    const Frame frame = sceneFrame();
    const float res = float(m_settings.resolution);
    PassLight light;
    light.positionType = glm::vec4(l.position, 0.0f);
    light.direction = glm::vec4(glm::normalize(l.direction), 0.0f);
    light.intensity = glm::vec4(l.intensity, 0.0f);
    light.cone = glm::vec4(std::cos(l.innerConeRad), std::cos(l.outerConeRad), 0.0f, 0.0f);
    light.bias = kVolumeShadowBias;
    light.surfaceBias = glm::vec4(m_settings.constantBias, m_settings.slopeBias,
                                  m_settings.normalOffset, float(m_settings.pcfRadius));
    light.cascades =
        glm::vec4(0.0f, 0.0f, m_settings.receiverPlane ? 1.0f : 0.0f, m_settings.cascadeBlend);
    const glm::vec3 dir(light.direction);
    light.positionType.w = float(l.type == LightType::Point  ? kPassLightPoint
                                 : l.type == LightType::Spot ? kPassLightSpot
                                                             : kPassLightDirectional);
    if (kind == kShadowCube) {
        light.shadow = glm::vec4(float(kShadowCube), float(slot), 2.0f / res, 0.0f);
        addCubeJobs(light, index, kShadowCube, slot, Job::Push{}, frame.nearZ, jobs);
    } else if (kind == kShadowMap2D && l.type == LightType::Spot) {
        const float fov = std::min(2.0f * l.outerConeRad + kSpotMarginRad, kMaxSpotFovRad);
        light.viewProj = spotViewProj(l.position, dir, fov, frame.nearZ);
        light.shadow =
            glm::vec4(float(kShadowMap2D), float(slot), 2.0f * std::tan(0.5f * fov) / res, 0.0f);
        Job job{kShadowMap2D, slot, index, false, {}};
        job.push.viewProj = light.viewProj;
        job.push.origin = glm::vec4(l.position, 0.0f);
        jobs.push_back(job);
    } else if (kind == kShadowMap2D) {  // directional: orthographic over the bounding sphere
        const OrthoLightFrame of = orthoFrame(frame.center, frame.radius, dir);
        light.origin = glm::vec4(of.origin, 1.0f);
        light.viewProj = orthoSceneViewProj(of);
        light.shadow = glm::vec4(float(kShadowMap2D), float(slot), 2.0f * of.radius / res, 1.0f);
        Job job{kShadowMap2D, slot, index, false, {}};
        job.push.viewProj = light.viewProj;
        job.push.origin = light.origin;
        job.push.direction = glm::vec4(dir, 0.0f);
        jobs.push_back(job);
    }
    return light;
}

void ShadowMaps::fitCascades(const PassLight& light, uint32_t index, uint32_t firstEntry,
                             uint32_t firstLayer, std::vector<Job>& jobs) {
    const Scene& scene = m_scene.scene();
    OrthoLightFrame of;
    of.origin = glm::vec3(light.origin);
    of.direction = glm::vec3(light.direction);
    of.radius = 0.5f * light.shadow.z * float(m_settings.resolution);
    CascadeSettings cs;
    cs.count = m_settings.cascades;
    cs.split = m_settings.cascadeSplit;
    cs.resolution = m_settings.resolution;
    cs.snap = m_settings.cascadeSnap;
    cs.marginTexels = uint32_t(m_settings.pcfRadius) + 2;
    const std::vector<ShadowCascade> fitted =
        fitShadowCascades(scene.camera, m_aspect, scene.caps.bounds, of, cs);
    for (uint32_t k = 0; k < uint32_t(fitted.size()); ++k) {
        PassLight c = light;  // same light: its intensity, direction, settings and distance origin
        c.cascades = glm::vec4(0.0f, 0.0f, light.cascades.z, 0.0f);
        c.viewProj = fitted[k].viewProj;
        c.shadow = glm::vec4(float(kShadowMap2D), float(firstLayer + k), fitted[k].texel, 1.0f);
        m_cascades[firstEntry + k] = c;
        Job job{kShadowMap2D, firstLayer + k, index, true, {}};
        job.push.viewProj = c.viewProj;
        job.push.origin = c.origin;
        job.push.direction = glm::vec4(glm::vec3(c.direction), 0.0f);
        jobs.push_back(job);
    }
}

void ShadowMaps::buildLightTable(const vk::GpuScene& gpuScene, uint32_t areaLightSamples) {
    const Scene& scene = gpuScene.scene();
    const bool shadows = m_settings.enabled;
    const Frame frame = sceneFrame();
    m_samples = buildEmitterSamples(scene, areaLightSamples);
    const uint32_t tableSize = uint32_t(scene.lights.size() + m_samples.size());

    for (uint32_t i = 0; i < uint32_t(scene.lights.size()); ++i) {
        const Light& l = scene.lights[i];
        // Each light's map slot is fixed here; an animated light keeps it (updateSceneLights).
        ShadowKind kind = kShadowNone;
        uint32_t slot = 0;
        if (shadows && (l.type == LightType::Point ||
                        (l.type == LightType::Spot && l.outerConeRad > kCubeSpotOuterRad))) {
            kind = kShadowCube;
            slot = m_cubeCount++;
        } else if (shadows) {
            kind = kShadowMap2D;
            slot = m_layers2D++;
        }
        PassLight light = sceneLightEntry(l, i, kind, slot, m_jobs);
        if (kind == kShadowMap2D && l.type == LightType::Directional && m_settings.cascades > 0) {
            const uint32_t first = uint32_t(m_cascades.size());
            m_cascades.resize(first + m_settings.cascades);
            light.cascades.x = float(tableSize + first);
            light.cascades.y = float(m_settings.cascades);
            fitCascades(light, i, first, m_layers2D, m_jobs);
            m_layers2D += m_settings.cascades;
        }
        m_lights.push_back(light);
    }
    m_sceneLightCount = uint32_t(m_lights.size());

    // Emitter samples: cosine-lobe point lights with their own cubes
    const float areaRes = float(m_settings.areaResolution);
    for (const EmitterSample& s : m_samples) {
        PassLight light;
        light.positionType = glm::vec4(s.position, float(kPassLightEmitterSample));
        light.direction = glm::vec4(s.normal, s.twoSided ? 1.0f : 0.0f);
        light.intensity = glm::vec4(s.intensity, s.area / glm::pi<float>());
        light.bias = kVolumeShadowBias;
        light.surfaceBias = glm::vec4(m_settings.constantBias, m_settings.slopeBias,
                                      m_settings.normalOffset, float(m_settings.pcfRadius));
        light.cascades = glm::vec4(0.0f, 0.0f, m_settings.receiverPlane ? 1.0f : 0.0f, 0.0f);
        if (shadows) {
            Job::Push skip;
            skip.skipPlane = glm::vec4(s.normal, glm::dot(s.normal, s.position));
            skip.params.x = 1e-4f * frame.radius;
            light.shadow =
                glm::vec4(float(kShadowAreaCube), float(m_areaCubeCount), 2.0f / areaRes, 0.0f);
            addCubeJobs(light, uint32_t(m_lights.size()), kShadowAreaCube, m_areaCubeCount, skip,
                        frame.nearZ, m_jobs);
            ++m_areaCubeCount;
        }
        m_lights.push_back(light);
    }

    // The emissive triangles behind the samples, for the exact unoccluded irradiance
    std::vector<glm::vec4> polygons;
    if (!m_samples.empty()) {
        for (const EmitterPolygon& p : buildEmitterPolygons(scene)) {
            polygons.push_back(glm::vec4(p.p0, p.twoSided ? 1.0f : 0.0f));
            polygons.push_back(glm::vec4(p.p1, 0.0f));
            polygons.push_back(glm::vec4(p.p2, 0.0f));
            polygons.push_back(glm::vec4(p.radiance, 0.0f));
        }
    }
    m_polygonCount = uint32_t(polygons.size() / 4);
    if (polygons.empty()) polygons.resize(4, glm::vec4(0.0f));
    m_polygonBuffer =
        vk::Buffer(m_ctx, polygons.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                   vk::MemoryUsage::DeviceLocal, "shared/area_lights.polygons");
    m_polygonBuffer.uploadVector(polygons);

    // Skip lines for what the scene lacks
    const bool hasEmitters = countEmitterTriangles(scene) > 0;
    if (areaLightSamples == 0) {
        m_skipped.push_back("area_lights: areaLightSamples = 0 (emitters do not light the scene)");
    } else if (!hasEmitters) {
        m_skipped.push_back("area_lights: scene has no emissive triangles");
    }
    if (!shadows) {
        m_skipped.push_back("shadow_maps: shadows disabled (visibility = 1)");
    } else {
        if (m_layers2D == 0) {
            m_skipped.push_back("shadow.2d: scene has no spot or directional lights");
        }
        if (m_cubeCount == 0) {
            m_skipped.push_back(
                "shadow.cube: scene has no point lights (or spots with an outer "
                "cone over 85 deg)");
        }
        if (m_areaCubeCount == 0) {
            m_skipped.push_back("shadow.area_cube: no emitter samples");
        }
    }

    // Upload the table and tell the scene's light buffer where each light's map is
    m_lightBuffer = vk::Buffer(
        m_ctx, std::max<size_t>(m_lights.size() + m_cascades.size(), 1) * sizeof(PassLight),
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::DeviceLocal, "shared/shadow.lights");
    uploadTable();
    std::vector<int> shadowIndex(gpuScene.lightCount(), -1);
    for (size_t i = 0; i < shadowIndex.size() && i < m_sceneLightCount; ++i) {
        if (m_lights[i].shadow.x != float(kShadowNone)) shadowIndex[i] = int(i);
    }
    if (!shadowIndex.empty()) m_scene.setLightShadowIndices(shadowIndex);
}

void ShadowMaps::uploadTable() {
    std::vector<PassLight> table = m_lights;
    table.insert(table.end(), m_cascades.begin(), m_cascades.end());
    if (!table.empty()) m_lightBuffer.uploadVector(table);
}

void ShadowMaps::createImages() {
    // A 1x1 placeholder stands in for each category the scene lacks
    const uint32_t res = m_settings.resolution;
    const uint32_t areaRes = m_settings.areaResolution;
    m_maps2D =
        m_layers2D > 0
            ? makeDistanceImage(m_ctx, vk::ImageKind::Image2DArray, res, m_layers2D, "maps2d")
            : makeDistanceImage(m_ctx, vk::ImageKind::Image2DArray, 1, 1, "maps2d_empty");
    m_cubes =
        m_cubeCount > 0
            ? makeDistanceImage(m_ctx, vk::ImageKind::CubeArray, res, 6 * m_cubeCount, "cubes")
            : makeDistanceImage(m_ctx, vk::ImageKind::CubeArray, 1, 6, "cubes_empty");
    m_areaCubes = m_areaCubeCount > 0 ? makeDistanceImage(m_ctx, vk::ImageKind::CubeArray, areaRes,
                                                          6 * m_areaCubeCount, "area_cubes")
                                      : makeDistanceImage(m_ctx, vk::ImageKind::CubeArray, 1, 6,
                                                          "area_cubes_empty");
    if (!m_jobs.empty()) {
        uint32_t depthRes = 0;
        for (const Job& job : m_jobs) {
            depthRes = std::max(depthRes, job.kind == kShadowAreaCube ? areaRes : res);
        }
        vk::ImageDesc depth;
        depth.format = kDepthFormat;
        depth.width = depthRes;
        depth.height = depthRes;
        depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
        depth.name = "shared/shadow.depth";
        m_depth = vk::Image(m_ctx, depth);
    }
    m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
        const VkClearColorValue far{{kNoOccluder, 0.0f, 0.0f, 0.0f}};
        for (vk::Image* image : {&m_maps2D, &m_cubes, &m_areaCubes}) {
            image->clearColor(cmd, far);
            image->transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        }
    });
}

void ShadowMaps::updateSceneLights(const std::vector<uint32_t>& changed) {
    const Scene& scene = m_scene.scene();
    const uint32_t tableSize = lightCount();
    for (uint32_t i : changed) {
        if (i >= m_sceneLightCount || i >= scene.lights.size())
            throw Error("ShadowMaps::updateSceneLights: light " + std::to_string(i) + " of " +
                        std::to_string(m_sceneLightCount));
        const PassLight old = m_lights[i];
        std::vector<Job> jobs;
        PassLight light = sceneLightEntry(scene.lights[i], i, ShadowKind(uint32_t(old.shadow.x)),
                                          uint32_t(old.shadow.y), jobs);
        light.cascades = old.cascades;
        if (old.cascades.y > 0.0f) {
            const uint32_t first = uint32_t(old.cascades.x) - tableSize;
            fitCascades(light, i, first, uint32_t(m_cascades[first].shadow.y), jobs);
        }
        m_lights[i] = light;
        size_t k = 0;  // same light type, same slots: its jobs are replaced in place, in order
        for (Job& job : m_jobs)
            if (job.light == i && k < jobs.size()) job = jobs[k++];
    }
    if (!changed.empty()) uploadTable();
}

std::vector<uint32_t> ShadowMaps::updateCamera() {
    std::vector<uint32_t> refitted;
    const uint32_t tableSize = lightCount();
    for (uint32_t i = 0; i < m_sceneLightCount; ++i) {
        const PassLight& light = m_lights[i];
        if (light.cascades.y <= 0.0f) continue;
        const uint32_t first = uint32_t(light.cascades.x) - tableSize;
        std::vector<Job> jobs;
        fitCascades(light, i, first, uint32_t(m_cascades[first].shadow.y), jobs);
        size_t k = 0;
        for (Job& job : m_jobs)
            if (job.light == i && job.cascade && k < jobs.size()) job = jobs[k++];
        refitted.push_back(i);
    }
    if (!refitted.empty()) uploadTable();
    return refitted;
}

void ShadowMaps::record(VkCommandBuffer cmd, const std::vector<uint32_t>* onlyLights,
                        bool cascadesOnly) {
    if (m_jobs.empty() || m_scene.triangleCount() == 0) return;
    auto wanted = [&](const Job& job) {
        if (cascadesOnly && !job.cascade) return false;
        return !onlyLights ||
               std::find(onlyLights->begin(), onlyLights->end(), job.light) != onlyLights->end();
    };
    if (std::none_of(m_jobs.begin(), m_jobs.end(), wanted)) return;
    for (vk::Image* image : {&m_maps2D, &m_cubes, &m_areaCubes}) {
        image->transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    }
    m_pipeline.bind(cmd);
    VkDescriptorSet set = m_scene.set().handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
    for (const Job& job : m_jobs) {
        if (!wanted(job)) continue;
        // The shared depth buffer: full barrier between renders (write after write)
        m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
        vk::Image& target = job.kind == kShadowMap2D  ? m_maps2D
                            : job.kind == kShadowCube ? m_cubes
                                                      : m_areaCubes;
        const uint32_t size = target.width();
        vk::ColorTarget color{target.layerView(job.layer, 0),
                              VkClearColorValue{{kNoOccluder, 0.0f, 0.0f, 0.0f}},
                              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
        vk::DepthTarget depth;
        depth.view = m_depth.view();
        depth.clear = 0.0f;  // reversed-Z
        depth.store = false;
        vk::RenderingScope scope(cmd, {size, size}, {color}, depth);
        vkCmdPushConstants(cmd, m_layout.handle(), m_layout.pushStages(), 0, sizeof(job.push),
                           &job.push);
        vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
    }
    for (vk::Image* image : {&m_maps2D, &m_cubes, &m_areaCubes}) {
        image->transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    }
}

std::vector<vk::DescriptorBinding> ShadowMaps::descriptorBindings(uint32_t firstBinding,
                                                                  VkShaderStageFlags stages) {
    const VkDescriptorType sampled = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    return {
        {firstBinding + 0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages},
        {firstBinding + 1, sampled, 1, stages},
        {firstBinding + 2, sampled, 1, stages},
        {firstBinding + 3, sampled, 1, stages},
    };
}

void ShadowMaps::writeDescriptors(vk::DescriptorSet& set, uint32_t firstBinding) {
    const VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    set.writeBuffer(firstBinding + 0, m_lightBuffer);
    set.writeSampledImage(firstBinding + 1, m_maps2D.view(), m_sampler.handle(), layout);
    set.writeSampledImage(firstBinding + 2, m_cubes.mipView(0), m_sampler.handle(), layout);
    set.writeSampledImage(firstBinding + 3, m_areaCubes.mipView(0), m_sampler.handle(), layout);
}

}  // namespace gilab
