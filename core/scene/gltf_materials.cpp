// glTF materials and textures -> gilab::Material / gilab::Texture.
#include <cmath>
#include <filesystem>
#include <sstream>

#include <tiny_gltf.h>

#include "core/scene/gltf_loader.h"
#include "core/util/error.h"

namespace gilab::gltf {

namespace {

WrapMode toWrapMode(int wrap) {
    switch (wrap) {
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return WrapMode::ClampToEdge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return WrapMode::MirroredRepeat;
        default:
            return WrapMode::Repeat;
    }
}

bool isDataUri(const std::string& uri) {
    return uri.rfind("data:", 0) == 0;
}

/** Decoded tinygltf image (any channel count, 8 or 16 bit) -> RGBA8. */
std::vector<uint8_t> toRgba8(const tinygltf::Image& image) {
    const size_t pixels = size_t(image.width) * size_t(image.height);
    const int channels = image.component;
    const int bytes = image.bits == 16 ? 2 : 1;
    std::vector<uint8_t> rgba(pixels * 4, 255);
    for (size_t p = 0; p < pixels; ++p) {
        uint8_t src[4] = {0, 0, 0, 255};
        for (int c = 0; c < channels && c < 4; ++c) {
            // 16-bit samples are little-endian in memory; keep the high byte.
            const size_t at = (p * size_t(channels) + size_t(c)) * size_t(bytes);
            src[c] = image.image[at + size_t(bytes - 1)];
        }
        uint8_t* dst = &rgba[p * 4];
        if (channels <= 2) {  // grey (+ alpha)
            dst[0] = dst[1] = dst[2] = src[0];
            dst[3] = channels == 2 ? src[1] : 255;
        } else {
            dst[0] = src[0];
            dst[1] = src[1];
            dst[2] = src[2];
            dst[3] = channels == 4 ? src[3] : 255;
        }
    }
    return rgba;
}

std::string num(double v) {
    std::ostringstream out;
    out.precision(9);
    out << v;
    return out.str();
}

/**
 * Factors must be finite and in [lo, hi] (docs/conventions.md, "Invalid physical inputs"):
 * a negative albedo or emission would put negative pixels into every output.
 */
void checkFactor(double value, double lo, double hi, const std::string& what,
                 const std::string& key) {
    if (!(std::isfinite(float(value)) && value >= lo && value <= hi)) {
        throw Error(what + ": invalid " + key + " " + num(value) +
                    (std::isinf(hi) ? " (must be finite and >= " + num(lo) + ")"
                                    : " (must be in [" + num(lo) + ", " + num(hi) + "])"));
    }
}

void checkFactors(const std::vector<double>& values, size_t size, double lo, double hi,
                  const std::string& what, const std::string& key) {
    if (values.size() != size) {
        throw Error(what + ": " + key + " has " + std::to_string(values.size()) + " numbers (" +
                    std::to_string(size) + " required)");
    }
    for (size_t i = 0; i < size; ++i)
        checkFactor(values[i], lo, hi, what, key + "[" + std::to_string(i) + "]");
}

}  // namespace

void MaterialConverter::convertAll() {
    bool warnedMaps = false;
    for (size_t i = 0; i < m_model.materials.size(); ++i) {
        const tinygltf::Material& src = m_model.materials[i];
        const auto& pbr = src.pbrMetallicRoughness;
        Material mat;
        mat.name = src.name.empty() ? "material_" + std::to_string(i) : src.name;
        const std::string label = "material '" + mat.name + "'";
        const std::string what = m_file + ": material " + std::to_string(i) +
                                 (src.name.empty() ? "" : " '" + src.name + "'");
        checkFactors(pbr.baseColorFactor, 4, 0.0, 1.0, what, "baseColorFactor");
        checkFactor(pbr.metallicFactor, 0.0, 1.0, what, "metallicFactor");
        checkFactor(pbr.roughnessFactor, 0.0, 1.0, what, "roughnessFactor");
        checkFactors(src.emissiveFactor, 3, 0.0, 1.0, what, "emissiveFactor");
        checkFactor(src.alphaCutoff, 0.0, HUGE_VAL, what, "alphaCutoff");
        if (src.alphaMode != "OPAQUE" && src.alphaMode != "MASK" && src.alphaMode != "BLEND") {
            throw Error(what + ": unknown alphaMode '" + src.alphaMode +
                        "' (OPAQUE, MASK or BLEND)");
        }
        mat.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                        pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
        mat.metallic = float(pbr.metallicFactor);
        mat.roughness = float(pbr.roughnessFactor);
        mat.baseColorTexture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                       ColorSpace::Srgb, label);
        mat.metallicRoughnessTexture =
            texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                    ColorSpace::Linear, label);

        // Emission: factor x KHR_materials_emissive_strength
        float strength = 1.0f;
        auto ext = src.extensions.find("KHR_materials_emissive_strength");
        if (ext != src.extensions.end() && ext->second.Has("emissiveStrength")) {
            const tinygltf::Value& v = ext->second.Get("emissiveStrength");
            if (!v.IsNumber()) {
                throw Error(what + ": KHR_materials_emissive_strength.emissiveStrength is not a " +
                            "number");
            }
            const double value = v.GetNumberAsDouble();
            checkFactor(value, 0.0, HUGE_VAL, what,
                        "KHR_materials_emissive_strength.emissiveStrength");
            strength = float(value);
        }
        mat.emissiveFactor = strength * glm::vec3(src.emissiveFactor[0], src.emissiveFactor[1],
                                                  src.emissiveFactor[2]);
        mat.emissiveTexture = texture(src.emissiveTexture.index, src.emissiveTexture.texCoord,
                                      ColorSpace::Srgb, label);

        // Alpha: BLEND is treated as MASK with the material's cutoff (docs/scenes.md)
        mat.alphaCutoff = float(src.alphaCutoff);
        mat.doubleSided = src.doubleSided;
        if (src.alphaMode == "MASK") {
            mat.alphaMode = AlphaMode::Mask;
        } else if (src.alphaMode == "BLEND") {
            mat.alphaMode = AlphaMode::Mask;
            std::ostringstream msg;
            msg << m_file << ": " << label << " uses alphaMode BLEND; treated as MASK with cutoff "
                << mat.alphaCutoff;
            m_scene.warnings.push_back(msg.str());
        }
        if (!warnedMaps && (src.normalTexture.index >= 0 || src.occlusionTexture.index >= 0)) {
            m_scene.warnings.push_back(m_file + ": normal and occlusion textures are ignored");
            warnedMaps = true;
        }
        m_scene.materials.push_back(mat);
    }
}

uint32_t MaterialConverter::defaultMaterial() {
    if (m_defaultMaterial < 0) {
        // glTF's default material is metallic 1; a white Lambertian suits a GI testbed better.
        Material mat;
        mat.name = "default";
        m_defaultMaterial = int(m_scene.materials.size());
        m_scene.materials.push_back(mat);
    }
    return uint32_t(m_defaultMaterial);
}

int MaterialConverter::texture(int gltfTexture, int texCoord, ColorSpace space,
                               const std::string& material) {
    if (gltfTexture == -1) return -1;  // tinygltf's "absent"
    if (texCoord != 0) {
        m_scene.warnings.push_back(m_file + ": " + material + " uses TEXCOORD_" +
                                   std::to_string(texCoord) + "; TEXCOORD_0 is used instead");
    }
    if (gltfTexture < 0 || size_t(gltfTexture) >= m_model.textures.size()) {
        throw Error(m_file + ": " + material + " references missing texture " +
                    std::to_string(gltfTexture) + " (the file has " +
                    std::to_string(m_model.textures.size()) + " textures)");
    }
    const tinygltf::Texture& tex = m_model.textures[size_t(gltfTexture)];
    if (tex.source == -1) {
        throw Error(m_file + ": texture " + std::to_string(gltfTexture) +
                    " has no image source (extension-only sources are unsupported)");
    }
    if (tex.source < 0 || size_t(tex.source) >= m_model.images.size()) {
        throw Error(m_file + ": texture " + std::to_string(gltfTexture) + " references image " +
                    std::to_string(tex.source) + ", which does not exist (the file has " +
                    std::to_string(m_model.images.size()) + " images)");
    }
    tinygltf::Sampler sampler;  // defaults: repeat
    if (tex.sampler != -1) {
        if (tex.sampler < 0 || size_t(tex.sampler) >= m_model.samplers.size()) {
            throw Error(m_file + ": texture " + std::to_string(gltfTexture) +
                        " references sampler " + std::to_string(tex.sampler) +
                        ", which does not exist (the file has " +
                        std::to_string(m_model.samplers.size()) + " samplers)");
        }
        sampler = m_model.samplers[size_t(tex.sampler)];
    }
    // Textures sharing an image and wrap modes share one decoded copy.
    const auto key = std::make_tuple(tex.source, sampler.wrapS, sampler.wrapT, space);
    if (auto it = m_textures.find(key); it != m_textures.end()) return it->second;

    const tinygltf::Image& image = m_model.images[size_t(tex.source)];
    const bool external = !image.uri.empty() && !isDataUri(image.uri);
    const std::filesystem::path dir = std::filesystem::path(m_file).parent_path();
    const std::string imagePath = external ? (dir / image.uri).lexically_normal().string() : "";

    // Missing or undecodable image: tinygltf only warns, the scene must not load.
    if (image.image.empty() || image.width <= 0 || image.height <= 0) {
        if (external && !std::filesystem::exists(imagePath)) {
            throw Error(m_file + ": image " + std::to_string(tex.source) + " '" + image.uri +
                        "' is missing (texture file not found: " + imagePath + ")");
        }
        throw Error(m_file + ": image " + std::to_string(tex.source) + " '" + image.uri +
                    image.name + "' could not be decoded");
    }

    // The decoded pixels must hold width x height x component samples of `bits`
    const size_t samples = size_t(image.width) * size_t(image.height) * size_t(image.component);
    if (image.component < 1 || image.component > 4 || (image.bits != 8 && image.bits != 16) ||
        image.image.size() < samples * size_t(image.bits / 8)) {
        throw Error(m_file + ": image " + std::to_string(tex.source) + " '" + image.uri +
                    image.name + "' has an inconsistent decoded size (" +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + ", " +
                    std::to_string(image.component) + " channels, " + std::to_string(image.bits) +
                    " bits, " + std::to_string(image.image.size()) + " bytes)");
    }

    Texture out;
    out.name = external ? imagePath : "<embedded " + std::to_string(tex.source) + ">";
    out.width = image.width;
    out.height = image.height;
    out.rgba = toRgba8(image);
    out.colorSpace = space;
    out.wrapU = toWrapMode(sampler.wrapS);
    out.wrapV = toWrapMode(sampler.wrapT);
    const int index = int(m_scene.textures.size());
    m_scene.textures.push_back(std::move(out));
    m_textures[key] = index;
    return index;
}

}  // namespace gilab::gltf
