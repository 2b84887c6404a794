#include "cvgi_gpu.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/passes/gbuffer.h"
#include "core/passes/pass_light.h"
#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/scene/camera.h"
#include "core/technique/technique.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

/** Mirrors CvgiVoxel / CvgiCluster / CvgiClusterLight in techniques/cvgi/shaders/cvgi_common.glsl.
 */
struct GpuCvgiVoxel {
    glm::vec4 albedoAxis;
    glm::vec4 normalCluster;
};
struct GpuCvgiCluster {
    glm::vec4 normal;
    glm::ivec4 aabbMin;
    glm::ivec4 aabbMax;
};
constexpr VkDeviceSize kClusterLightBytes = 32;

/** Mirrors CvgiUniforms (std140). */
struct CvgiUniforms {
    GpuVoxelGrid grid;
    glm::uvec4 counts;
    glm::vec4 biases;
    glm::uvec4 options;
    glm::mat4 cameraViewProj;
    glm::vec4 cameraEye;
    glm::uvec4 packing;  // x 1 = face cluster ids packed two per word, y 1 = ray-weighted
                         // gather, z rays per face
};

struct LitPush {
    DistanceView view;  // viewProj, origin, direction (skipPlane / params unused)
};
struct GaussianPush {
    uint32_t src, dst, copy, stride;
};

constexpr uint32_t kCounterWords = 4;
constexpr uint32_t kMaxGroups = 65535;
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

float asFloat(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

template <class T>
vk::Buffer upload(vk::Context& ctx, const std::vector<T>& data, const std::string& name) {
    const VkDeviceSize bytes = std::max<VkDeviceSize>(data.size() * sizeof(T), 16);
    const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
    if (bytes > range) {
        throw DeviceLimitError(name + ": " + std::to_string(bytes >> 20) +
                               " MiB in one binding, above the device's maxStorageBufferRange (" +
                               std::to_string(range >> 20) +
                               " MiB); lower voxel_resolution or rays_per_face");
    }
    vk::Buffer b(ctx, bytes, kStorage, vk::MemoryUsage::DeviceLocal, name);
    b.uploadVector(data);
    return b;
}

vk::Buffer storage(vk::Context& ctx, VkDeviceSize bytes, const std::string& name) {
    const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
    if (bytes > range) {
        throw DeviceLimitError(name + ": " + std::to_string(bytes >> 20) +
                               " MiB in one binding, above the device's maxStorageBufferRange (" +
                               std::to_string(range >> 20) + " MiB); lower voxel_resolution");
    }
    return vk::Buffer(ctx, std::max<VkDeviceSize>(bytes, 16), kStorage,
                      vk::MemoryUsage::DeviceLocal, name);
}

}  // namespace

CvgiGpu::CvgiGpu(vk::Context& ctx, const vk::GpuScene& scene, SharedPasses& shared,
                 const VoxelGrid& grid, vk::Buffer voxelIndex, vk::Buffer hashedPosition,
                 const cvgi::CompactVoxels& vox, const std::vector<uint8_t>& axis,
                 const cvgi::Clusters& cl, const cvgi::FaceVisibility& vis,
                 const CvgiSettings& settings, const std::string& tag)
    : m_ctx(ctx),
      m_shared(shared),
      m_grid(grid),
      m_settings(settings),
      m_voxelIndex(std::move(voxelIndex)),
      m_hashedPosition(std::move(hashedPosition)) {
    m_voxelCount = vox.count();
    m_clusterCount = cl.count();
    if (uint64_t(m_voxelCount) > uint64_t(kMaxGroups) * 64) {
        throw Error("cvgi: " + std::to_string(m_voxelCount) +
                    " occupied voxels, above the 4.19M one dispatch covers; lower "
                    "voxel_resolution");
    }
    // Static data from the set-up.
    std::vector<GpuCvgiVoxel> voxels(m_voxelCount);
    for (uint32_t i = 0; i < m_voxelCount; ++i) {
        voxels[i].albedoAxis = glm::vec4(vox.albedo[i], float(axis[i]));
        voxels[i].normalCluster = glm::vec4(vox.meanNormal[i], asFloat(cl.owner[i]));
    }
    std::vector<GpuCvgiCluster> clusters(m_clusterCount);
    for (uint32_t c = 0; c < m_clusterCount; ++c) {
        clusters[c].normal = glm::vec4(cl.normal[c], 0.0f);
        clusters[c].aabbMin = glm::ivec4(cl.aabbMin[c], int(cl.voxelOffset[c]));
        clusters[c].aabbMax =
            glm::ivec4(cl.aabbMax[c], int(cl.voxelOffset[c + 1] - cl.voxelOffset[c]));
    }
    m_voxels = upload(ctx, voxels, tag + "/voxels");
    m_clusters = upload(ctx, clusters, tag + "/clusters");
    m_clusterVoxels = upload(ctx, cl.voxels, tag + "/cluster_voxels");
    m_faceOffset = upload(ctx, vis.offset, tag + "/face_offset");
    // Cluster ids in 16 bits, two per word, when they fit (they do for the paper's < 10K
    // clusters): halves the largest buffer (the paper: 37-53 % of the final memory).
    m_packedFaceClusters = m_clusterCount <= 0xFFFFu;
    if (m_packedFaceClusters) {
        std::vector<uint32_t> packed((vis.clusters.size() + 1) / 2, 0u);
        for (size_t k = 0; k < vis.clusters.size(); ++k)
            packed[k / 2] |= vis.clusters[k] << (16 * (k % 2));
        m_faceClusters = upload(ctx, packed, tag + "/face_clusters");
    } else {
        m_faceClusters = upload(ctx, vis.clusters, tag + "/face_clusters");
    }
    m_raysPerFace = vis.rays;
    m_faceWeights = settings.gather == CvgiSettings::Gather::RayWeighted
                        ? upload(ctx, vis.cosineSums, tag + "/face_weights")
                        : upload(ctx, std::vector<float>{0.0f}, tag + "/face_weights");
    // Per-update state.
    const VkDeviceSize v = m_voxelCount;
    m_voxelLight = storage(ctx, v * 16, tag + "/voxel_light");
    m_clusterLight =
        storage(ctx, VkDeviceSize(m_clusterCount) * kClusterLightBytes, tag + "/cluster_light");
    m_voxelState = storage(ctx, v * 4, tag + "/voxel_state");
    m_faceIrradiance = storage(ctx, v * 6 * 16, tag + "/face_irradiance");
    m_faceTemp = storage(ctx, v * 6 * 16, tag + "/face_temp");
    m_faceFiltered = storage(ctx, v * 6 * 16, tag + "/face_filtered");
    m_counters = vk::Buffer(ctx, kCounterWords * 4, kStorage, vk::MemoryUsage::DeviceLocal,
                            tag + "/counters");
    m_gatherList = storage(ctx, v * 4, tag + "/gather_list");
    m_uniforms = vk::Buffer(ctx, sizeof(CvgiUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                            vk::MemoryUsage::Upload, tag + "/uniforms");

    // Emitters: the scene's spot and directional lights (their pass-table 2D views).
    const ShadowMaps& shadows = shared.shadows();
    for (uint32_t i = 0; i < shadows.sceneLightCount(); ++i)
        if (uint32_t(shadows.lights()[i].shadow.x) == kShadowMap2D) m_emitters.push_back(i);
    m_emitterMap = std::make_unique<DistanceMap>(ctx, scene, settings.shadowMapSize,
                                                 settings.shadowMapSize, tag + "/emitter_map");
    // The camera map keeps the frame's aspect, within the device's image limit (its projection is
    // the camera's whatever its size: a clamped axis only has fewer texels).
    const float aspect = float(shared.width()) / float(std::max(shared.height(), 1u));
    const uint32_t maxSide = ctx.properties().limits.maxImageDimension2D;
    const uint32_t wantH = settings.cameraMapSize;
    const double wantW = std::max(1.0, std::round(double(wantH) * double(aspect)));
    m_cameraMapWidth = uint32_t(std::min<double>(wantW, maxSide));
    m_cameraMapHeight = std::min(wantH, maxSide);
    m_cameraMapClamped = m_cameraMapWidth != wantW || m_cameraMapHeight != wantH;
    m_cameraMap = std::make_unique<DistanceMap>(ctx, scene, m_cameraMapWidth, m_cameraMapHeight,
                                                tag + "/camera_map");
    vk::SamplerDesc sd;
    sd.filter = VK_FILTER_NEAREST;
    sd.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sd.name = tag + "/map_sampler";
    m_sampler = vk::Sampler(ctx, sd);

    // Descriptors: set 0 for every pass, set 1 for the final frame's images.
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    std::vector<vk::DescriptorBinding> bindings{{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, cs}};
    for (uint32_t b = 1; b <= 16; ++b)
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs});
    bindings.push_back({17, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs});
    bindings.push_back({18, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs});
    bindings.push_back({19, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs});
    m_setLayout = vk::DescriptorSetLayout(ctx, bindings, tag + "/passes");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/passes");
    m_set.writeUniformBuffer(0, m_uniforms);
    const vk::Buffer* buffers[] = {
        &m_voxelIndex,    &m_hashedPosition, &m_voxels,         &m_clusters,
        &m_clusterVoxels, &m_faceOffset,     &m_faceClusters,   &m_voxelLight,
        &m_clusterLight,  &m_voxelState,     &m_faceIrradiance, &m_faceTemp,
        &m_faceFiltered,  &m_counters,       &m_gatherList,     &shadows.lightBuffer()};
    for (uint32_t b = 0; b < 16; ++b)
        m_set.writeBuffer(b + 1, *buffers[b]);
    m_set.writeSampledImage(17, m_emitterMap->image().view(), m_sampler.handle());
    m_set.writeSampledImage(18, m_cameraMap->image().view(), m_sampler.handle());
    m_set.writeBuffer(19, m_faceWeights);
    m_frameLayout = vk::DescriptorSetLayout(ctx,
                                            {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                             {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                             {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                             {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}},
                                            tag + "/frame");
    m_frameSet = vk::DescriptorSet(ctx, m_frameLayout, 0, tag + "/frame");
    GBuffer& gb = shared.gbuffer();
    m_frameSet.writeStorageImage(0, gb.position.view());
    m_frameSet.writeStorageImage(1, gb.normal.view());
    m_frameSet.writeStorageImage(2, gb.albedo.view());

    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(LitPush));
    m_frameLayoutPipeline = vk::PipelineLayout(ctx, {m_setLayout.handle(), m_frameLayout.handle()});
    m_litVoxels = vk::ComputePipeline(ctx, "cvgi/lit_voxels.comp", m_layout);
    m_litClusters = vk::ComputePipeline(ctx, "cvgi/lit_clusters.comp", m_layout);
    m_cameraVisible = vk::ComputePipeline(ctx, "cvgi/camera_visible.comp", m_layout);
    m_lightBounce = vk::ComputePipeline(ctx, "cvgi/light_bounce.comp", m_layout);
    m_gaussian = vk::ComputePipeline(ctx, "cvgi/gaussian.comp", m_layout);
    m_finalFrame = vk::ComputePipeline(ctx, "cvgi/final_frame.comp", m_frameLayoutPipeline);
    writeUniforms();
}

CvgiGpu::~CvgiGpu() = default;

void CvgiGpu::setSettings(const CvgiSettings& settings) {
    m_settings = settings;
    writeUniforms();
}

void CvgiGpu::setCamera(const Camera& camera, float aspect) {
    const DistanceView view = DistanceView::fromCamera(camera, aspect);
    m_cameraViewProj = view.viewProj;
    m_cameraEye = camera.position;
    writeUniforms();
}

void CvgiGpu::writeUniforms() {
    CvgiUniforms u{};
    u.grid = m_grid.gpu();
    u.counts = glm::uvec4(m_voxelCount, m_clusterCount, m_grid.resolution(), m_shared.width());
    u.biases = glm::vec4(m_settings.litBiasVoxels, m_settings.cameraBiasVoxels,
                         m_settings.nearClusterVoxels, m_settings.gaussianSigmaVoxels);
    const uint32_t radius = m_settings.gaussianKernel > 1 ? m_settings.gaussianKernel / 2 : 0;
    u.options = glm::uvec4(radius, m_settings.neighbourTest ? 1u : 0u,
                           m_settings.interpolation ? 1u : 0u, m_shared.height());
    u.packing = glm::uvec4(m_packedFaceClusters ? 1u : 0u,
                           m_settings.gather == CvgiSettings::Gather::RayWeighted ? 1u : 0u,
                           m_raysPerFace, m_settings.gaussianVisibility ? 1u : 0u);
    u.cameraViewProj = m_cameraViewProj;
    u.cameraEye = glm::vec4(m_cameraEye, 0.0f);
    m_uniforms.upload(&u, sizeof(u));
}

void CvgiGpu::bindCompute(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline) {
    pipeline.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
}

void CvgiGpu::recordEmitterUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd) {
    // An emitter change invalidates every cached face (§4.4).
    for (vk::Buffer* b : {&m_voxelLight, &m_voxelState, &m_faceIrradiance, &m_faceTemp,
                          &m_faceFiltered, &m_counters})
        vkCmdFillBuffer(cmd, b->handle(), 0, VK_WHOLE_SIZE, 0);
    vk::memoryBarrier(cmd);
    const ShadowMaps& shadows = m_shared.shadows();
    for (uint32_t light : m_emitters) {
        const DistanceView view = DistanceView::fromPassLight(shadows.lights()[light]);
        {
            PassScope pass(ctx, cmd, "dist_shadow_map");
            m_emitterMap->record(cmd, view);
        }
        PassScope pass(ctx, cmd, "lit_cluster");
        bindCompute(cmd, m_litVoxels);
        struct {
            glm::mat4 viewProj;
            glm::vec4 origin, direction;
            glm::uvec4 light;
        } push{view.viewProj, view.origin, view.direction, glm::uvec4(light, 0, 0, 0)};
        vkCmdPushConstants(cmd, m_layout.handle(), m_layout.pushStages(), 0, sizeof(push), &push);
        vk::dispatch1D(cmd, m_voxelCount, 64);
        vk::memoryBarrier(cmd);
    }
    {
        PassScope pass(ctx, cmd, "lit_cluster");
        bindCompute(cmd, m_litClusters);
        vk::dispatch1D(cmd, m_clusterCount, 64);
        vk::memoryBarrier(cmd);
    }
    recordCameraPasses(ctx, cmd);
}

void CvgiGpu::recordCameraUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd) {
    // Keep PROCESSED (the cache); only the newly visible voxels are gathered.
    vkCmdFillBuffer(cmd, m_counters.handle(), 0, 8, 0);  // gather and visible counts
    vk::memoryBarrier(cmd);
    recordCameraPasses(ctx, cmd);
}

void CvgiGpu::recordCameraPasses(const TechniqueContext& ctx, VkCommandBuffer cmd) {
    {
        PassScope pass(ctx, cmd, "camera_visible_voxel");
        DistanceView view;
        view.viewProj = m_cameraViewProj;
        view.origin = glm::vec4(m_cameraEye, 0.0f);
        m_cameraMap->record(cmd, view);
        bindCompute(cmd, m_cameraVisible);
        vk::dispatch1D(cmd, m_voxelCount, 64);
        vk::memoryBarrier(cmd);
    }
    {
        PassScope pass(ctx, cmd, "light_bounce");
        bindCompute(cmd, m_lightBounce);
        vkCmdDispatch(cmd, std::clamp<uint32_t>(m_voxelCount * 6, 1, 16384), 1, 1);
        vk::memoryBarrier(cmd);
    }
    PassScope pass(ctx, cmd, "gaussian_filtering");
    bindCompute(cmd, m_gaussian);
    const uint32_t threads = m_voxelCount * 6;
    const uint32_t groups = std::max(1u, (threads + 63) / 64);
    const uint32_t gx = std::min(groups, kMaxGroups), gy = (groups + gx - 1) / gx;
    auto run = [&](uint32_t src, uint32_t dst, bool copy) {
        const GaussianPush push{src, dst, copy ? 1u : 0u, gx * 64};
        vkCmdPushConstants(cmd, m_layout.handle(), m_layout.pushStages(), 0, sizeof(push), &push);
        vkCmdDispatch(cmd, gx, gy, 1);
        vk::memoryBarrier(cmd);
    };
    const bool filter = m_settings.gaussianKernel > 1 && m_settings.gaussianPasses > 0;
    if (!filter) {
        run(0, 2, true);
        return;
    }
    // Buffers 0 irradiance, 1 temp, 2 filtered: 0 -> 1 -> 2 -> 1 -> 2 ...; an odd count ends
    // in temp and is copied to filtered.
    uint32_t src = 0;
    for (uint32_t k = 0; k < m_settings.gaussianPasses; ++k) {
        const uint32_t dst = (k % 2 == 0) ? 1 : 2;
        run(src, dst, false);
        src = dst;
    }
    if (src != 2) run(src, 2, true);
}

void CvgiGpu::recordFinalFrame(VkCommandBuffer cmd, vk::Image& indirect) {
    if (indirect.view() != m_boundIndirect) {
        m_frameSet.writeStorageImage(3, indirect.view());
        m_boundIndirect = indirect.view();
    }
    vkCmdFillBuffer(cmd, m_counters.handle(), 12, 4, 0);  // unresolved pixels of this frame
    vk::memoryBarrier(cmd);
    m_finalFrame.bind(cmd);
    VkDescriptorSet sets[2] = {m_set.handle(), m_frameSet.handle()};
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_frameLayoutPipeline.handle(), 0,
                            2, sets, 0, nullptr);
    vk::dispatch2D(cmd, m_shared.width(), m_shared.height());
    vk::memoryBarrier(cmd);
}

std::vector<uint32_t> CvgiGpu::readLitCounts() {
    std::vector<float> light(size_t(m_clusterCount) * 8);
    if (!light.empty()) m_clusterLight.download(light.data(), light.size() * sizeof(float));
    std::vector<uint32_t> lit(m_clusterCount);
    for (uint32_t c = 0; c < m_clusterCount; ++c)
        lit[c] = uint32_t(light[size_t(c) * 8 + 3] + 0.5f);
    return lit;
}

std::vector<glm::vec4> CvgiGpu::readVoxelLight() {
    std::vector<glm::vec4> light(m_voxelCount);
    if (!light.empty()) m_voxelLight.download(light.data(), light.size() * sizeof(glm::vec4));
    return light;
}

CvgiCounters CvgiGpu::readCounters() {
    uint32_t words[kCounterWords] = {};
    m_counters.download(words, sizeof(words));
    return {words[0], words[1], words[2], words[3]};
}

uint64_t CvgiGpu::finalBytes() const {
    uint64_t sum = 0;
    for (const vk::Buffer* b :
         {&m_voxelIndex, &m_hashedPosition, &m_voxels, &m_clusters, &m_clusterVoxels, &m_faceOffset,
          &m_faceClusters, &m_faceWeights, &m_voxelLight, &m_clusterLight, &m_voxelState,
          &m_faceIrradiance, &m_faceTemp, &m_faceFiltered, &m_counters, &m_gatherList})
        sum += b->size();
    return sum;
}

}  // namespace gilab
