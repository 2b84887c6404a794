#pragma once
/**
 * The scene on the GPU, uploaded once: vertices, indices, per-triangle material ids, materials,
 * lights and textures, plus the "scene set" every pass binds as set = 0. The GPU structs below
 * are mirrored exactly in shaders/common/scene.glsl. Memory is tagged "scene/...".
 * The Scene must outlive the GpuScene (it is referenced, not copied).
 *
 * Scene set (set = 0):
 *   0 vertices            readonly SSBO, float[8] per vertex (pos.xyz, normal.xyz, uv.xy)
 *   1 indices             readonly SSBO, uint, 3 per triangle
 *   2 triangle materials  readonly SSBO, uint per triangle
 *   3 materials           readonly SSBO, GpuMaterial[]
 *   4 lights              SSBO, GpuLight[] (length() = light count)
 *   5 texture meta        readonly SSBO, uvec4[]: entries [0, textureCount) are textures
 *                         (firstLevel, levelCount, flags bit0 = sRGB, wrapU | wrapV << 4);
 *                         entry firstLevel + l is mip l (texelOffset, width, height, 0)
 *   6 texels              readonly SSBO, uint[] (RGBA8 packed, R in the low byte), every
 *                         texture's full mip chain
 *
 * Textures are sampled in software by scene.glsl (bilinear / trilinear, per-texture wrap modes,
 * sRGB decoded before filtering), so the scene needs no descriptor indexing, no sampler arrays
 * and no non-uniform sampler access: lavapipe (Mesa 22.3) has none of them. Texture indices
 * in materials are Scene::textures indices.
 */
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/scene/scene.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"

namespace gilab::vk {

enum GpuMaterialFlags : uint32_t {
    kMaterialAlphaMask = 1u << 0,  // Mask or Blend
    kMaterialDoubleSided = 1u << 1,
    kMaterialGlossy = 1u << 2,
    kMaterialEmissive = 1u << 3,
};

struct GpuMaterial {
    glm::vec4 baseColor;
    glm::vec4 emissive;  // rgb radiance, w unused
    float metallic;
    float roughness;
    float alphaCutoff;
    uint32_t flags;
    int32_t baseColorTexture;  // -1 = none
    int32_t metallicRoughnessTexture;
    int32_t emissiveTexture;
    int32_t pad;
};
static_assert(sizeof(GpuMaterial) == 64);

enum GpuLightType : uint32_t { kLightPoint = 0, kLightSpot = 1, kLightDirectional = 2 };

struct GpuLight {
    glm::vec4 positionType;    // xyz, w = type (0 point, 1 spot, 2 directional)
    glm::vec4 directionRange;  // xyz direction light travels, w = range (0 = infinite)
    glm::vec4 intensity;       // rgb W/sr (point/spot) or W/m^2 (directional)
    glm::vec4 cone;            // x cos(inner), y cos(outer), z shadow map index (-1 none), w unused
};
static_assert(sizeof(GpuLight) == 64);

GpuMaterial toGpuMaterial(const Material& material);
GpuLight toGpuLight(const Light& light);

/** Binding numbers of the scene set. */
enum SceneBinding : uint32_t {
    kSceneVertices = 0,
    kSceneIndices = 1,
    kSceneTriangleMaterials = 2,
    kSceneMaterials = 3,
    kSceneLights = 4,
    kSceneTextureMeta = 5,
    kSceneTexels = 6,
};

/** Wrap-mode codes in the texture meta entries (mirrored in scene.glsl). */
enum GpuWrapMode : uint32_t { kWrapRepeat = 0, kWrapClampToEdge = 1, kWrapMirroredRepeat = 2 };

/** CPU side of the texture packing (exposed for tests). */
struct PackedTextures {
    std::vector<glm::uvec4> meta;
    std::vector<uint32_t> texels;
};
/** Packs every texture with its full mip chain (box filter; sRGB averaged in linear space). */
PackedTextures packTextures(const std::vector<Texture>& textures);

class GpuScene {
public:
    GpuScene(Context& ctx, const Scene& scene);
    GpuScene(const GpuScene&) = delete;
    GpuScene& operator=(const GpuScene&) = delete;

    const Scene& scene() const { return *m_scene; }
    Buffer& vertices() { return m_vertices; }
    Buffer& indices() { return m_indices; }
    Buffer& triangleMaterials() { return m_triangleMaterials; }
    Buffer& materials() { return m_materials; }
    Buffer& lights() { return m_lights; }
    Buffer& textureMeta() { return m_textureMeta; }
    Buffer& texels() { return m_texels; }
    /** Triangle ids of emissive triangles (uint each), for light sampling. */
    Buffer& emissiveTriangles() { return m_emissiveTriangles; }
    const std::vector<uint32_t>& emissiveTriangleIds() const { return m_emissiveIds; }

    uint32_t vertexCount() const { return static_cast<uint32_t>(m_scene->vertices.size()); }
    uint32_t indexCount() const { return static_cast<uint32_t>(m_scene->indices.size()); }
    uint32_t triangleCount() const { return indexCount() / 3; }
    uint32_t lightCount() const { return static_cast<uint32_t>(m_gpuLights.size()); }
    uint32_t textureCount() const { return static_cast<uint32_t>(m_scene->textures.size()); }
    uint32_t emissiveTriangleCount() const { return static_cast<uint32_t>(m_emissiveIds.size()); }

    const std::vector<GpuLight>& gpuLights() const { return m_gpuLights; }
    const std::vector<GpuMaterial>& gpuMaterials() const { return m_gpuMaterials; }
    /** Sets cone.z of light `light` (-1 = no shadow map) and re-uploads the lights buffer. */
    void setLightShadowIndex(uint32_t light, int shadowIndex);
    /** Same for several lights at once (one upload); size must equal lightCount(). */
    void setLightShadowIndices(const std::vector<int>& shadowIndices);
    /**
     * Re-packs lights `changed` from scene().lights (an animated scene moved them; same count
     * and types) and re-uploads the buffer; each light keeps its shadow index (cone.z).
     */
    void updateLights(const std::vector<uint32_t>& changed);

    const DescriptorSetLayout& layout() const { return m_layout; }
    const DescriptorSet& set() const { return m_set; }

    /** Binds the vertex (binding 0) and index buffers and draws the whole scene once. */
    void draw(VkCommandBuffer cmd) const;
    /** Binds only the vertex and index buffers. */
    void bindGeometry(VkCommandBuffer cmd) const;

private:
    Context* m_ctx;
    const Scene* m_scene;
    std::vector<GpuMaterial> m_gpuMaterials;
    std::vector<GpuLight> m_gpuLights;
    std::vector<uint32_t> m_emissiveIds;

    Buffer m_vertices;
    Buffer m_indices;
    Buffer m_triangleMaterials;
    Buffer m_materials;
    Buffer m_lights;
    Buffer m_emissiveTriangles;
    Buffer m_textureMeta;
    Buffer m_texels;
    DescriptorSetLayout m_layout;
    DescriptorSet m_set;
};

}  // namespace gilab::vk
