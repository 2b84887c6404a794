#pragma once
/**
 * The scene model shared by the rasteriser, every technique and the path tracer.
 *
 * Everything is flattened to world space at load time: one triangle list, one material per
 * triangle. Units and the light convention are in docs/conventions.md; in short, linear
 * radiometric RGB, metres, point/spot intensity in W/sr, directional irradiance in W/m^2,
 * emissive surfaces as radiance in W/(m^2 sr).
 */
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/animation.h"
#include "core/scene/camera.h"

namespace gilab {

struct Bounds {
    glm::vec3 lo{std::numeric_limits<float>::max()};
    glm::vec3 hi{-std::numeric_limits<float>::max()};
    void extend(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool valid() const { return lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z; }
    glm::vec3 center() const { return 0.5f * (lo + hi); }
    glm::vec3 extent() const { return hi - lo; }
};

/** One vertex in world space. Normals are unit length; UVs follow glTF (origin top-left). */
struct Vertex {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec2 uv{0.0f};
};

enum class ColorSpace { Linear, Srgb };
enum class WrapMode { Repeat, ClampToEdge, MirroredRepeat };

/** An 8-bit RGBA texture as stored in the file; decoding (sRGB -> linear) happens at lookup. */
struct Texture {
    std::string name;  // file path or "<embedded n>", for messages
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;  // width * height * 4, row 0 = top of the image (v = 0)
    ColorSpace colorSpace = ColorSpace::Srgb;
    WrapMode wrapU = WrapMode::Repeat;
    WrapMode wrapV = WrapMode::Repeat;
};

enum class AlphaMode { Opaque, Mask, Blend };

/**
 * glTF 2.0 metallic-roughness material. All factors are linear. A material is Lambertian
 * (albedo / pi) unless isGlossy(); then the glTF Appendix B BRDF is used (docs/conventions.md).
 */
struct Material {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};  // rgb = albedo, a = coverage
    int baseColorTexture = -1;        // index into Scene::textures (sRGB)
    float metallic = 0.0f;
    float roughness = 1.0f;             // perceptual roughness; GGX alpha = roughness^2
    int metallicRoughnessTexture = -1;  // linear; G = roughness, B = metallic
    glm::vec3 emissiveFactor{0.0f};     // already multiplied by KHR_materials_emissive_strength
    int emissiveTexture = -1;           // sRGB
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;

    bool isEmissive() const {
        return emissiveFactor.x > 0.0f || emissiveFactor.y > 0.0f || emissiveFactor.z > 0.0f;
    }
    /** Glossy = has a specular lobe. roughness == 1 and metallic == 0 means pure Lambertian. */
    bool isGlossy() const { return metallic > 0.0f || roughness < 1.0f; }
};

enum class LightType { Point, Spot, Directional };

/**
 * A punctual light (KHR_lights_punctual semantics, radiometric units).
 *  - Point / Spot: `intensity` is radiant intensity in W/sr per RGB channel.
 *  - Directional: `intensity` is irradiance in W/m^2 on a surface facing the light.
 * `intensity` is what every renderer reads; it always equals `color * strength` (the
 * description's "color" and "intensity", kept apart so an animation can change one of them).
 * Code that only knows the product sets color = intensity, strength = 1.
 * Spot falloff between the outer and inner cone follows the glTF recommendation (conventions.md).
 */
struct Light {
    std::string name;
    LightType type = LightType::Point;
    glm::vec3 position{0.0f};
    glm::vec3 direction{0.0f, -1.0f,
                        0.0f};  // unit; the direction light travels (spot, directional)
    glm::vec3 intensity{1.0f};  // == color * strength
    glm::vec3 color{1.0f};      // linear RGB, each >= 0
    float strength = 1.0f;      // >= 0
    float innerConeRad = 0.0f;  // spot only
    float outerConeRad = 0.7853982f;
    float range = 0.0f;  // 0 = infinite. Stored for completeness; no technique windows by range.
};

/** Computed once per scene so techniques and the harness can skip what the scene lacks. */
struct SceneCaps {
    size_t triangleCount = 0;
    size_t emissiveTriangleCount = 0;
    bool hasEmissive = false;
    bool hasGlossy = false;
    bool hasTextures = false;
    bool hasAlphaMask = false;  // any Mask (or Blend, treated as Mask) material in use
    bool hasPointLights = false;
    bool hasSpotLights = false;
    bool hasDirectionalLights = false;
    Bounds bounds;
};

/** Resolution and display settings. Exposure (in stops) affects tonemapped previews only. */
struct RenderSettings {
    int width = 128;
    int height = 128;
    float exposureEv = 0.0f;
};

struct Scene {
    std::string name;        // e.g. "cornell_box" or "cornell_box#spot"
    std::string sourcePath;  // the scene description (or "<built-in>")

    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;            // 3 per triangle
    std::vector<uint32_t> triangleMaterials;  // 1 per triangle, index into materials
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<Light> lights;
    Camera camera;
    RenderSettings settings;
    SceneAnimation animation;  // empty = static (docs/scenes.md "Animation")

    SceneCaps caps;
    std::vector<std::string> warnings;     // e.g. "dropped 12 degenerate triangles"
    std::vector<std::string> loadedFiles;  // every file read, for provenance and cache keys
    std::vector<std::string> variants;     // the variants its description file offers ("#spot")

    size_t triangleCount() const { return indices.size() / 3; }
    /** Recomputes `caps` from the data; loaders call it last. */
    void computeCaps();
};

/**
 * Moves every position by t, in double and rounded once (so a move by an amount the floats can
 * hold exactly comes back bit for bit): vertices, point and spot lights, the camera's position
 * and target; `caps` recomputed. Directions, radiometry and the animation's keys are kept.
 */
void translateScene(Scene& scene, const glm::dvec3& t);

/** Where the rasteriser's passes put the origin: the centre of the scene's bounds rounded to
 *  whole metres (so a scene moved by whole metres is moved back exactly), 0 without bounds. */
glm::dvec3 renderOrigin(const Scene& scene);

}  // namespace gilab
