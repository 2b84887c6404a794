#include "core/gpu/gpu_scene.h"

#include <cmath>
#include <cstring>

#include "core/util/error.h"
#include "core/vk/context.h"

namespace gilab::vk {

GpuMaterial toGpuMaterial(const Material& m) {
    GpuMaterial g{};
    g.baseColor = m.baseColorFactor;
    g.emissive = glm::vec4(m.emissiveFactor, 0.0f);
    g.metallic = m.metallic;
    g.roughness = m.roughness;
    g.alphaCutoff = m.alphaCutoff;
    g.flags = 0;
    if (m.alphaMode != AlphaMode::Opaque) g.flags |= kMaterialAlphaMask;
    if (m.doubleSided) g.flags |= kMaterialDoubleSided;
    if (m.isGlossy()) g.flags |= kMaterialGlossy;
    if (m.isEmissive()) g.flags |= kMaterialEmissive;
    g.baseColorTexture = m.baseColorTexture;
    g.metallicRoughnessTexture = m.metallicRoughnessTexture;
    g.emissiveTexture = m.emissiveTexture;
    g.pad = 0;
    return g;
}

GpuLight toGpuLight(const Light& l) {
    GpuLight g{};
    float type = 0.0f;
    switch (l.type) {
        case LightType::Point:
            type = float(kLightPoint);
            break;
        case LightType::Spot:
            type = float(kLightSpot);
            break;
        case LightType::Directional:
            type = float(kLightDirectional);
            break;
    }
    g.positionType = glm::vec4(l.position, type);
    g.directionRange = glm::vec4(l.direction, l.range);
    g.intensity = glm::vec4(l.intensity, 0.0f);
    g.cone = glm::vec4(std::cos(l.innerConeRad), std::cos(l.outerConeRad), -1.0f, 0.0f);
    return g;
}

namespace {
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
}  // namespace

GpuScene::GpuScene(Context& ctx, const Scene& scene) : m_ctx(&ctx), m_scene(&scene) {
    size_t triangles = scene.indices.size() / 3;
    if (scene.indices.size() % 3 != 0 || scene.triangleMaterials.size() != triangles) {
        throw Error("scene '" + scene.name + "': " + std::to_string(scene.indices.size()) +
                    " indices and " + std::to_string(scene.triangleMaterials.size()) +
                    " triangle materials do not describe a triangle list");
    }
    for (uint32_t index : scene.indices) {
        if (index >= scene.vertices.size()) {
            throw Error("scene '" + scene.name + "': index " + std::to_string(index) +
                        " out of range");
        }
    }
    for (const Material& m : scene.materials) {
        for (int t : {m.baseColorTexture, m.metallicRoughnessTexture, m.emissiveTexture}) {
            if (t >= int(scene.textures.size())) {
                throw Error("scene '" + scene.name + "': material '" + m.name + "' uses texture " +
                            std::to_string(t) + " of " + std::to_string(scene.textures.size()));
            }
        }
    }
    for (size_t t = 0; t < triangles; ++t) {
        uint32_t id = scene.triangleMaterials[t];
        if (id >= scene.materials.size()) {
            throw Error("scene '" + scene.name + "': triangle " + std::to_string(t) +
                        " uses material " + std::to_string(id) + " of " +
                        std::to_string(scene.materials.size()));
        }
        if (scene.materials[id].isEmissive()) m_emissiveIds.push_back(uint32_t(t));
    }

    static_assert(sizeof(Vertex) == 32, "gilab::Vertex must be 8 packed floats");
    const VkBufferUsageFlags vertexUsage = kStorage | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
    const VkBufferUsageFlags indexUsage = kStorage | VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    m_vertices = Buffer(ctx, scene.vertices.size() * sizeof(Vertex), vertexUsage,
                        MemoryUsage::DeviceLocal, "scene/vertices");
    m_vertices.uploadVector(scene.vertices);
    m_indices = Buffer(ctx, scene.indices.size() * 4, indexUsage, MemoryUsage::DeviceLocal,
                       "scene/indices");
    m_indices.uploadVector(scene.indices);
    m_triangleMaterials = Buffer(ctx, scene.triangleMaterials.size() * 4, kStorage,
                                 MemoryUsage::DeviceLocal, "scene/triangleMaterials");
    m_triangleMaterials.uploadVector(scene.triangleMaterials);

    for (const Material& m : scene.materials)
        m_gpuMaterials.push_back(toGpuMaterial(m));
    m_materials = Buffer(ctx, m_gpuMaterials.size() * sizeof(GpuMaterial), kStorage,
                         MemoryUsage::DeviceLocal, "scene/materials");
    m_materials.uploadVector(m_gpuMaterials);

    for (const Light& l : scene.lights)
        m_gpuLights.push_back(toGpuLight(l));
    m_lights = Buffer(ctx, m_gpuLights.size() * sizeof(GpuLight), kStorage,
                      MemoryUsage::DeviceLocal, "scene/lights");
    m_lights.uploadVector(m_gpuLights);

    m_emissiveTriangles = Buffer(ctx, m_emissiveIds.size() * 4, kStorage, MemoryUsage::DeviceLocal,
                                 "scene/emissiveTriangles");
    m_emissiveTriangles.uploadVector(m_emissiveIds);

    PackedTextures packed = packTextures(scene.textures);
    VkDeviceSize texelBytes = packed.texels.size() * 4;
    VkDeviceSize maxRange = ctx.properties().limits.maxStorageBufferRange;
    if (texelBytes > maxRange) {
        throw DeviceLimitError("scene '" + scene.name + "': textures need " +
                               std::to_string(texelBytes) + " bytes with mips, more than the " +
                               std::to_string(maxRange) + "-byte storage buffer limit of " +
                               ctx.deviceName());
    }
    m_textureMeta = Buffer(ctx, packed.meta.size() * sizeof(glm::uvec4), kStorage,
                           MemoryUsage::DeviceLocal, "scene/textureMeta");
    m_textureMeta.uploadVector(packed.meta);
    m_texels = Buffer(ctx, texelBytes, kStorage, MemoryUsage::DeviceLocal, "scene/texels");
    m_texels.uploadVector(packed.texels);

    const VkShaderStageFlags stages = VK_SHADER_STAGE_ALL;
    std::vector<DescriptorBinding> bindings;
    for (uint32_t b = kSceneVertices; b <= kSceneTexels; ++b) {
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, false});
    }
    m_layout = DescriptorSetLayout(ctx, bindings, "scene/setLayout");
    m_set = DescriptorSet(ctx, m_layout, 0, "scene/set");
    m_set.writeBuffer(kSceneVertices, m_vertices);
    m_set.writeBuffer(kSceneIndices, m_indices);
    m_set.writeBuffer(kSceneTriangleMaterials, m_triangleMaterials);
    m_set.writeBuffer(kSceneMaterials, m_materials);
    m_set.writeBuffer(kSceneLights, m_lights);
    m_set.writeBuffer(kSceneTextureMeta, m_textureMeta);
    m_set.writeBuffer(kSceneTexels, m_texels);
}

void GpuScene::setLightShadowIndex(uint32_t light, int shadowIndex) {
    if (light >= m_gpuLights.size()) {
        throw Error("setLightShadowIndex: light " + std::to_string(light) + " of " +
                    std::to_string(m_gpuLights.size()));
    }
    m_gpuLights[light].cone.z = float(shadowIndex);
    m_lights.upload(&m_gpuLights[light], sizeof(GpuLight), light * sizeof(GpuLight));
}

void GpuScene::setLightShadowIndices(const std::vector<int>& shadowIndices) {
    if (shadowIndices.size() != m_gpuLights.size()) {
        throw Error("setLightShadowIndices: " + std::to_string(shadowIndices.size()) +
                    " indices for " + std::to_string(m_gpuLights.size()) + " lights");
    }
    for (size_t i = 0; i < shadowIndices.size(); ++i) {
        m_gpuLights[i].cone.z = float(shadowIndices[i]);
    }
    m_lights.uploadVector(m_gpuLights);
}

void GpuScene::updateLights(const std::vector<uint32_t>& changed) {
    if (m_scene->lights.size() != m_gpuLights.size())
        throw Error("updateLights: the scene has " + std::to_string(m_scene->lights.size()) +
                    " lights, the GPU scene " + std::to_string(m_gpuLights.size()));
    for (uint32_t i : changed) {
        if (i >= m_gpuLights.size())
            throw Error("updateLights: light " + std::to_string(i) + " of " +
                        std::to_string(m_gpuLights.size()));
        const float shadowIndex = m_gpuLights[i].cone.z;
        m_gpuLights[i] = toGpuLight(m_scene->lights[i]);
        m_gpuLights[i].cone.z = shadowIndex;
    }
    if (!changed.empty()) m_lights.uploadVector(m_gpuLights);
}

void GpuScene::bindGeometry(VkCommandBuffer cmd) const {
    VkBuffer vertexBuffer = m_vertices.handle();
    VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertexBuffer, &offset);
    vkCmdBindIndexBuffer(cmd, m_indices.handle(), 0, VK_INDEX_TYPE_UINT32);
}

void GpuScene::draw(VkCommandBuffer cmd) const {
    if (indexCount() == 0) return;
    bindGeometry(cmd);
    vkCmdDrawIndexed(cmd, indexCount(), 1, 0, 0, 0);
}

}  // namespace gilab::vk
