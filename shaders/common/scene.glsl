// The scene set (set = 0), mirrored from core/gpu/gpu_scene.h. Include after #version.
//
// Options (define before #include):
//   SCENE_SET n            descriptor set number (default 0)
//   SCENE_NO_BINDINGS      only the structs and constants, no declarations or helpers
//   SCENE_IMPLICIT_LOD     fragment shaders: pick the texture mip from uv derivatives
//                          (trilinear) instead of sampling mip 0 (compute and other stages)
//
// Textures are sampled in software from two storage buffers (see core/gpu/gpu_scene.h):
// bilinear within a mip, linear between mips, per-texture wrap modes, sRGB decoded before
// filtering, like a LINEAR / MIPMAP_LINEAR sampler. No descriptor indexing is needed.
//   SCENE_LIGHTS_WRITABLE  declare the lights buffer without readonly
#ifndef GILAB_SCENE_GLSL
#define GILAB_SCENE_GLSL

#extension GL_EXT_scalar_block_layout : require

#ifndef SCENE_SET
#define SCENE_SET 0
#endif

// Light types (Light.positionType.w).
#define LIGHT_POINT 0
#define LIGHT_SPOT 1
#define LIGHT_DIRECTIONAL 2

// Texture wrap codes (texture meta .w: u | v << 4).
#define TEXTURE_WRAP_REPEAT 0u
#define TEXTURE_WRAP_CLAMP 1u
#define TEXTURE_WRAP_MIRRORED 2u

// Material.flags bits.
#define MATERIAL_ALPHA_MASK 1u
#define MATERIAL_DOUBLE_SIDED 2u
#define MATERIAL_GLOSSY 4u
#define MATERIAL_EMISSIVE 8u

struct Material {
    vec4 baseColor;     // rgb albedo, a coverage
    vec4 emissive;      // rgb radiance W/(m^2 sr)
    float metallic;
    float roughness;    // perceptual; GGX alpha = roughness^2
    float alphaCutoff;
    uint flags;
    int baseColorTexture;  // -1 = none; else a Scene::textures index
    int metallicRoughnessTexture;
    int emissiveTexture;
    int pad;
};

struct Light {
    vec4 positionType;    // xyz position, w type (LIGHT_*)
    vec4 directionRange;  // xyz direction light travels (unit), w range (0 = infinite)
    vec4 intensity;       // rgb W/sr (point, spot) or W/m^2 (directional)
    vec4 cone;            // x cos(inner), y cos(outer), z shadow map index (-1 = none)
};

struct SceneVertex {
    vec3 position;
    vec3 normal;
    vec2 uv;
};

#ifndef SCENE_NO_BINDINGS

layout(set = SCENE_SET, binding = 0, scalar) readonly buffer SceneVertices {
    float sceneVertexData[];  // 8 floats per vertex
};
layout(set = SCENE_SET, binding = 1, scalar) readonly buffer SceneIndices {
    uint sceneIndices[];
};
layout(set = SCENE_SET, binding = 2, scalar) readonly buffer SceneTriangleMaterials {
    uint sceneTriangleMaterials[];
};
layout(set = SCENE_SET, binding = 3, scalar) readonly buffer SceneMaterials {
    Material sceneMaterials[];
};
#ifdef SCENE_LIGHTS_WRITABLE
layout(set = SCENE_SET, binding = 4, scalar) buffer SceneLights {
#else
layout(set = SCENE_SET, binding = 4, scalar) readonly buffer SceneLights {
#endif
    Light sceneLights[];
};
layout(set = SCENE_SET, binding = 5, scalar) readonly buffer SceneTextureMeta {
    uvec4 sceneTextureMeta[];  // [texture] = (firstLevel, levelCount, flags, wrap);
};                             // [firstLevel + l] = (texelOffset, width, height, 0)
layout(set = SCENE_SET, binding = 6, scalar) readonly buffer SceneTexels {
    uint sceneTexels[];  // RGBA8, R in the low byte
};

uint sceneLightCount() { return uint(sceneLights.length()); }
uint sceneTriangleCount() { return uint(sceneIndices.length()) / 3u; }

// Floor modulo, exact for |i| < 2^22.
int sceneFloorMod(int i, int n) {
    int m = i - n * int(floor(float(i) / float(n)));
    return clamp(m, 0, n - 1);
}

int sceneWrapCoord(int i, int n, uint mode) {
    if (mode == TEXTURE_WRAP_CLAMP) return clamp(i, 0, n - 1);
    if (mode == TEXTURE_WRAP_MIRRORED) {
        int m = sceneFloorMod(i, 2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return sceneFloorMod(i, n);
}

vec3 sceneSrgbToLinear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec4 sceneFetchTexel(uvec4 level, ivec2 p, bool srgb) {
    vec4 c = unpackUnorm4x8(sceneTexels[level.x + uint(p.y) * level.y + uint(p.x)]);
    if (srgb) c.rgb = sceneSrgbToLinear(c.rgb);
    return c;
}

// Bilinear filtering of one mip level (texel centres at (i + 0.5) / size).
vec4 sceneBilinear(uvec4 level, uint flags, uint wrap, vec2 uv) {
    ivec2 size = ivec2(level.yz);
    vec2 st = uv * vec2(size) - 0.5;
    vec2 base = floor(st);
    vec2 f = st - base;
    ivec2 i0 = ivec2(base);
    int x0 = sceneWrapCoord(i0.x, size.x, wrap & 15u);
    int x1 = sceneWrapCoord(i0.x + 1, size.x, wrap & 15u);
    int y0 = sceneWrapCoord(i0.y, size.y, wrap >> 4);
    int y1 = sceneWrapCoord(i0.y + 1, size.y, wrap >> 4);
    bool srgb = (flags & 1u) != 0u;
    vec4 a = mix(sceneFetchTexel(level, ivec2(x0, y0), srgb),
                 sceneFetchTexel(level, ivec2(x1, y0), srgb), f.x);
    vec4 b = mix(sceneFetchTexel(level, ivec2(x0, y1), srgb),
                 sceneFetchTexel(level, ivec2(x1, y1), srgb), f.x);
    return mix(a, b, f.y);
}

// Texture `index` at mip `lod` (fractional = linear between mips; clamped to the chain).
vec4 sceneSampleTextureLod(int index, vec2 uv, float lod) {
    uvec4 info = sceneTextureMeta[index];
    float l = clamp(lod, 0.0, float(info.y - 1u));
    uint l0 = uint(floor(l));
    float t = l - float(l0);
    vec4 c = sceneBilinear(sceneTextureMeta[info.x + l0], info.z, info.w, uv);
    if (t > 0.0) {
        c = mix(c, sceneBilinear(sceneTextureMeta[info.x + l0 + 1u], info.z, info.w, uv), t);
    }
    return c;
}

// Mip from uv derivatives (the Vulkan isotropic LOD: log2 of the larger footprint axis).
float sceneTextureLod(int index, vec2 dx, vec2 dy) {
    uvec4 info = sceneTextureMeta[index];
    vec2 size = vec2(sceneTextureMeta[info.x].yz);
    float rho = max(length(dx * size), length(dy * size));
    return log2(max(rho, 1e-8));
}

vec4 sceneSampleTextureGrad(int index, vec2 uv, vec2 dx, vec2 dy) {
    return sceneSampleTextureLod(index, uv, sceneTextureLod(index, dx, dy));
}

// Derivatives are taken once at the top of each helper (uniform control flow), then used
// inside the per-material branches.
#ifdef SCENE_IMPLICIT_LOD
#define SCENE_UV_DERIVATIVES(uv) vec2 sceneDx = dFdx(uv), sceneDy = dFdy(uv)
#define SCENE_SAMPLE(index, uv) sceneSampleTextureGrad(index, uv, sceneDx, sceneDy)
#else
#define SCENE_UV_DERIVATIVES(uv)
#define SCENE_SAMPLE(index, uv) sceneSampleTextureLod(index, uv, 0.0)
#endif

vec4 sceneSampleTexture(int index, vec2 uv) {
    SCENE_UV_DERIVATIVES(uv);
    return SCENE_SAMPLE(index, uv);
}

Material fetchMaterialById(uint materialId) { return sceneMaterials[materialId]; }
Material fetchMaterial(uint triangleId) {
    return sceneMaterials[sceneTriangleMaterials[triangleId]];
}

// Base colour factor x texture (sRGB textures are decoded by the sampler). a = coverage.
vec4 sampleBaseColor(Material m, vec2 uv) {
    SCENE_UV_DERIVATIVES(uv);
    vec4 c = m.baseColor;
    if (m.baseColorTexture >= 0) c *= SCENE_SAMPLE(m.baseColorTexture, uv);
    return c;
}
vec4 sampleBaseColorLod(Material m, vec2 uv, float lod) {
    vec4 c = m.baseColor;
    if (m.baseColorTexture >= 0) c *= sceneSampleTextureLod(m.baseColorTexture, uv, lod);
    return c;
}

// Emitted radiance: factor x texture.
vec3 sampleEmission(Material m, vec2 uv) {
    SCENE_UV_DERIVATIVES(uv);
    vec3 e = m.emissive.rgb;
    if (m.emissiveTexture >= 0) e *= SCENE_SAMPLE(m.emissiveTexture, uv).rgb;
    return e;
}

// (metallic, perceptual roughness): factors x texture (B = metallic, G = roughness).
vec2 sampleMetalRough(Material m, vec2 uv) {
    SCENE_UV_DERIVATIVES(uv);
    vec2 mr = vec2(m.metallic, m.roughness);
    if (m.metallicRoughnessTexture >= 0) {
        vec4 t = SCENE_SAMPLE(m.metallicRoughnessTexture, uv);
        mr *= vec2(t.b, t.g);
    }
    return mr;
}

// True = discard: alpha-masked (or blend) material with coverage below the cutoff.
bool alphaCutout(Material m, vec2 uv) {
    if ((m.flags & MATERIAL_ALPHA_MASK) == 0u) return false;
    return sampleBaseColor(m, uv).a < m.alphaCutoff;
}

SceneVertex fetchVertex(uint index) {
    uint b = index * 8u;
    SceneVertex v;
    v.position = vec3(sceneVertexData[b], sceneVertexData[b + 1u], sceneVertexData[b + 2u]);
    v.normal = vec3(sceneVertexData[b + 3u], sceneVertexData[b + 4u], sceneVertexData[b + 5u]);
    v.uv = vec2(sceneVertexData[b + 6u], sceneVertexData[b + 7u]);
    return v;
}

uvec3 fetchTriangle(uint triangleId) {
    uint b = triangleId * 3u;
    return uvec3(sceneIndices[b], sceneIndices[b + 1u], sceneIndices[b + 2u]);
}

// Interpolates the vertex at barycentrics (b1, b2) of the triangle: p = (1-b1-b2) p0 + b1 p1 +
// b2 p2. The normal is renormalised (the shading normal, not the geometric one).
SceneVertex interpolateVertex(uint triangleId, vec2 bary) {
    uvec3 t = fetchTriangle(triangleId);
    SceneVertex v0 = fetchVertex(t.x), v1 = fetchVertex(t.y), v2 = fetchVertex(t.z);
    float b0 = 1.0 - bary.x - bary.y;
    SceneVertex v;
    v.position = b0 * v0.position + bary.x * v1.position + bary.y * v2.position;
    v.normal = normalize(b0 * v0.normal + bary.x * v1.normal + bary.y * v2.normal);
    v.uv = b0 * v0.uv + bary.x * v1.uv + bary.y * v2.uv;
    return v;
}

// Unnormalised geometric normal (cross of edges, counter-clockwise winding); length = 2 x area.
vec3 triangleGeometricNormal(uint triangleId) {
    uvec3 t = fetchTriangle(triangleId);
    vec3 p0 = fetchVertex(t.x).position;
    return cross(fetchVertex(t.y).position - p0, fetchVertex(t.z).position - p0);
}

#endif  // SCENE_NO_BINDINGS
#endif  // GILAB_SCENE_GLSL
