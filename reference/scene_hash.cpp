#include "reference/scene_hash.h"

#include <xxhash.h>

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <type_traits>

#include "core/util/error.h"

namespace gilab::ref {
namespace {

// Tripwires: a new field in one of these structs changes its size. Hash the field (or say
// why it does not change the image), then update the size here.
static_assert(sizeof(Vertex) == 32, "Vertex changed: update hashVertices()");
static_assert(sizeof(Camera) == 48, "Camera changed: update hashCamera()");
static_assert(sizeof(RenderSettings) == 12, "RenderSettings changed: update the scene hash");
// Light::color and ::strength are not hashed: renderers read intensity (== their product).
static_assert(sizeof(Light) == sizeof(std::string) + 72, "Light changed: update hashLight()");
static_assert(sizeof(Material) == sizeof(std::string) + 64,
              "Material changed: update hashMaterial()");
static_assert(sizeof(Texture) == sizeof(std::string) + sizeof(std::vector<uint8_t>) + 24,
              "Texture changed: update hashTexture()");
// ReferenceSettings has its tripwire in settingsJson() (reference_settings.cpp).
static_assert(std::endian::native == std::endian::little, "hashes assume little-endian data");

std::string toHex(XXH128_hash_t h) {
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, h);  // big-endian digest bytes: high64 then low64
    static const char kDigits[] = "0123456789abcdef";
    std::string hex(32, '0');
    for (int i = 0; i < 16; ++i) {
        hex[size_t(2 * i)] = kDigits[c.digest[i] >> 4];
        hex[size_t(2 * i + 1)] = kDigits[c.digest[i] & 15];
    }
    return hex;
}

/** Streaming XXH3-128 with typed, tagged, length-prefixed inputs (no concatenation ambiguity). */
class Hasher {
public:
    Hasher() : m_state(XXH3_createState(), XXH3_freeState) {
        if (!m_state || XXH3_128bits_reset(m_state.get()) != XXH_OK)
            throw Error("XXH3: cannot create a hash state");
    }
    void bytes(const void* data, size_t size) {
        if (size) XXH3_128bits_update(m_state.get(), data, size);
    }
    void u64(uint64_t v) { bytes(&v, sizeof v); }
    void i32(int32_t v) { bytes(&v, sizeof v); }
    void f32(float v) {
        const uint32_t bits = std::bit_cast<uint32_t>(v);
        bytes(&bits, sizeof bits);
    }
    void vec(const glm::vec2& v) {
        f32(v.x);
        f32(v.y);
    }
    void vec(const glm::vec3& v) {
        vec(glm::vec2(v));
        f32(v.z);
    }
    void vec(const glm::vec4& v) {
        vec(glm::vec3(v));
        f32(v.w);
    }
    void str(const std::string& s) {
        u64(s.size());
        bytes(s.data(), s.size());
    }
    void tag(const char* t) { str(t); }
    template <class T>
    void array(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        u64(v.size());
        bytes(v.data(), v.size() * sizeof(T));
    }
    std::string hex() const { return toHex(XXH3_128bits_digest(m_state.get())); }

private:
    std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> m_state;
};

void hashVertices(Hasher& h, const std::vector<Vertex>& vertices) {
    h.tag("vertices");
    h.u64(vertices.size());
    for (const Vertex& v : vertices) {
        h.vec(v.position);
        h.vec(v.normal);
        h.vec(v.uv);
    }
}

void hashMaterial(Hasher& h, const Material& m) {
    h.tag("material");  // the name is a label only
    h.vec(m.baseColorFactor);
    h.i32(m.baseColorTexture);
    h.f32(m.metallic);
    h.f32(m.roughness);
    h.i32(m.metallicRoughnessTexture);
    h.vec(m.emissiveFactor);
    h.i32(m.emissiveTexture);
    h.i32(int32_t(m.alphaMode));
    h.f32(m.alphaCutoff);
    h.i32(m.doubleSided ? 1 : 0);
}

void hashTexture(Hasher& h, const Texture& t) {
    h.tag("texture");  // the name is a label only; the pixels are what matter
    h.i32(t.width);
    h.i32(t.height);
    h.array(t.rgba);
    h.i32(int32_t(t.colorSpace));
    h.i32(int32_t(t.wrapU));
    h.i32(int32_t(t.wrapV));
}

void hashLight(Hasher& h, const Light& l) {
    h.tag("light");  // the name is a label only
    h.i32(int32_t(l.type));
    h.vec(l.position);
    h.vec(l.direction);
    h.vec(l.intensity);
    h.f32(l.innerConeRad);
    h.f32(l.outerConeRad);
    h.f32(l.range);  // ignored by every renderer today; hashed in case that changes
}

void hashCamera(Hasher& h, const Camera& c) {
    h.tag("camera");
    h.vec(c.position);
    h.vec(c.target);
    h.vec(c.up);
    h.f32(c.vfovRad);
    h.f32(c.nearZ);
    h.f32(c.farZ);
}

void hashSceneInto(Hasher& h, const Scene& scene) {
    h.tag("gilab-scene");
    hashVertices(h, scene.vertices);
    h.tag("indices");
    h.array(scene.indices);
    h.tag("triangle_materials");
    h.array(scene.triangleMaterials);
    h.u64(scene.materials.size());
    for (const Material& m : scene.materials)
        hashMaterial(h, m);
    h.u64(scene.textures.size());
    for (const Texture& t : scene.textures)
        hashTexture(h, t);
    h.u64(scene.lights.size());
    for (const Light& l : scene.lights)
        hashLight(h, l);
    hashCamera(h, scene.camera);
    h.tag("resolution");  // exposureEv changes previews only
    h.i32(scene.settings.width);
    h.i32(scene.settings.height);
}

}  // namespace

std::string hashFileContents(const std::string& path, uint64_t* sizeBytes) {
    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!file)
        throw Error(path + ": cannot read this scene file to compute the reference cache key: " +
                    std::strerror(errno));
    Hasher h;
    std::vector<char> buffer(1 << 20);
    uint64_t total = 0;
    size_t n = 0;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), file.get())) > 0) {
        h.bytes(buffer.data(), n);
        total += n;
    }
    if (std::ferror(file.get())) throw Error(path + ": read error while hashing");
    if (sizeBytes) *sizeBytes = total;
    return h.hex();
}

std::string hashSceneData(const Scene& scene) {
    Hasher h;
    hashSceneInto(h, scene);
    return h.hex();
}

nlohmann::ordered_json keySettingsJson(const ReferenceSettings& settings) {
    nlohmann::ordered_json j = settingsJson(settings);
    for (std::string_view name : kSettingsNotInKey)
        j.erase(std::string(name));
    if (settings.sampler != SamplerKind::Sobol)
        for (std::string_view name : kSobolOnlySettings)
            j.erase(std::string(name));
    return j;
}

ReferenceKey computeReferenceKey(const Scene& scene, const ReferenceSettings& settings) {
    ReferenceKey key;
    const std::string dataHash = hashSceneData(scene);

    Hasher h;
    h.tag("gilab-reference-key");
    h.i32(kKeyFormatVersion);
    h.i32(kRendererVersion);
    // The settings as the sidecar serialises them (one serialisation: reference_settings.h),
    // less the named exclusions; floats print exactly (shortest round-trip text)
    const nlohmann::ordered_json keySettings = keySettingsJson(settings);
    h.tag("settings");
    h.str(keySettings.dump());
    h.tag("scene_data");
    h.str(dataHash);

    // File contents, in load order; paths are not hashed (moving a scene keeps its key)
    nlohmann::ordered_json files = nlohmann::ordered_json::array();
    h.tag("files");
    h.u64(scene.loadedFiles.size());
    for (const std::string& path : scene.loadedFiles) {
        uint64_t size = 0;
        const std::string fileHash = hashFileContents(path, &size);
        h.str(fileHash);
        files.push_back({{"path", path}, {"bytes", size}, {"xxh3_128", fileHash}});
    }
    key.hex = h.hex();

    std::string notHashed;
    for (std::string_view name : kSettingsNotInKey)
        notHashed += std::string(name) + ", ";
    for (std::string_view name : kSobolOnlySettings)
        notHashed += std::string(name) + " (unless the sampler is sobol), ";
    notHashed += "names, paths, warnings, exposure_ev (previews only)";

    key.description = {{"key", key.hex},
                       {"hash", "XXH3-128"},
                       {"key_format", kKeyFormatVersion},
                       {"renderer_version", kRendererVersion},
                       {"settings", keySettings},
                       {"scene_data_xxh3_128", dataHash},
                       {"scene_data",
                        {{"vertices", scene.vertices.size()},
                         {"triangles", scene.triangleCount()},
                         {"materials", scene.materials.size()},
                         {"textures", scene.textures.size()},
                         {"lights", scene.lights.size()},
                         {"resolution", {scene.settings.width, scene.settings.height}}}},
                       {"files", files},
                       {"not_hashed", notHashed}};
    return key;
}

std::string referenceKey(const Scene& scene, const ReferenceSettings& settings) {
    return computeReferenceKey(scene, settings).hex;
}

}  // namespace gilab::ref
