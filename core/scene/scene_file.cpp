// Scene description files: reading, variants, and applying a description to its geometry.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "core/scene/gltf_loader.h"
#include "core/scene/scene_description.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"

namespace gilab {

namespace {

namespace fs = std::filesystem;

nlohmann::json readJson(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(path + ": scene file not found");
    // Duplicate keys, out-of-range numbers and syntax errors name the file, line and key
    return readJsonFile(path, "scene file");
}

void applyMaterials(Scene& scene, const SceneDescription& d) {
    for (const MaterialOverride& o : d.materialOverrides) {
        bool found = false;
        for (Material& m : scene.materials) {
            if (m.name != o.name) continue;
            found = true;
            if (o.baseColor) {
                const float alpha = o.baseColorHasAlpha ? o.baseColor->w : m.baseColorFactor.a;
                m.baseColorFactor = glm::vec4(glm::vec3(*o.baseColor), alpha);
            }
            if (o.roughness) m.roughness = *o.roughness;
            if (o.metallic) m.metallic = *o.metallic;
            if (o.emissive) m.emissiveFactor = *o.emissive;
        }
        if (!found) {
            std::string names;
            for (const Material& m : scene.materials)
                names += (names.empty() ? "" : ", ") + m.name;
            throw Error(d.context + ": \"material_overrides\": unknown material \"" + o.name +
                        "\" (the scene has: " + names + ")");
        }
    }
    // Last, so it also removes emission an override added.
    if (d.removeEmissive) {
        for (Material& m : scene.materials) {
            m.emissiveFactor = glm::vec3(0.0f);
            m.emissiveTexture = -1;
        }
    }
}

void applyCamera(Scene& scene, const SceneDescription& d, bool sourceHasCamera) {
    const bool placed = d.camera && d.camera->placesCamera();
    if (!sourceHasCamera && !placed) {
        scene.camera = makeFramingCamera(scene.caps.bounds);
        scene.warnings.push_back(d.context + ": no camera in the scene or the file; framing " +
                                 "the bounds");
    }
    if (!d.camera) return;
    Camera& c = scene.camera;
    const CameraOverride& o = *d.camera;
    if (o.position) c.position = *o.position;
    if (o.target) c.target = *o.target;
    if (o.up) c.up = glm::normalize(*o.up);
    if (o.vfovRad) c.vfovRad = *o.vfovRad;
    if (o.nearZ) c.nearZ = *o.nearZ;
    if (o.farZ) c.farZ = *o.farZ;
    const std::string where = d.context + ": \"camera\": ";
    const glm::vec3 forward = c.target - c.position;
    if (!(glm::length(forward) > 1e-6f)) throw Error(where + "position equals target");
    if (!(glm::length(glm::cross(glm::normalize(forward), c.up)) > 1e-4f)) {
        throw Error(where + "up is parallel to the viewing direction");
    }
    if (!(c.farZ > c.nearZ)) throw Error(where + "far must exceed near");
}

/**
 * Multiplies every length by `s`: vertex positions, point and spot light positions, the camera's
 * position, target and clip planes. Radiance, intensities and directions are kept, so an
 * emitter-lit scene renders the same image at any scale (point lights: irradiance / s^2).
 */
void applyScale(Scene& scene, double s) {
    const float f = float(s);
    for (Vertex& v : scene.vertices)
        v.position *= f;
    for (Light& l : scene.lights)
        if (l.type != LightType::Directional) l.position *= f;
    scene.camera.position *= f;
    scene.camera.target *= f;
    scene.camera.nearZ *= f;
    scene.camera.farZ *= f;
    scene.computeCaps();
}

/** Loads the geometry source and applies everything else in the description. */
Scene buildScene(const SceneDescription& d) {
    Scene scene;
    bool hasCamera = true;
    if (d.cornellBox || d.twoRooms) {
        try {
            scene = d.cornellBox ? makeCornellBox(*d.cornellBox) : makeTwoRooms(*d.twoRooms);
        } catch (const Error& e) {
            throw Error(d.context + ": \"procedural\": " + e.what());
        }
    } else {
        gltf::LoadResult loaded;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(d.gltfPath, ec)) {
            // Shipped descriptions refer to scene data kept outside the repository (issue 31: a
            // fresh clone could not load Sponza and was not told where to get it).
            const std::filesystem::path folder = std::filesystem::path(d.gltfPath).parent_path();
            throw Error(d.context + ": \"gltf\": " + d.gltfPath +
                        ": glTF file not found. The scene's data is not part of the repository: "
                        "put it in " +
                        folder.string() +
                        (std::filesystem::is_directory(folder, ec) ? " (the folder exists)"
                                                                   : " (no such folder)") +
                        "; scenes/README.md lists each scene's public source, licence and "
                        "conversion steps");
        }
        try {
            loaded = gltf::loadFile(d.gltfPath);
        } catch (const Error& e) {  // name the description that refers to the glTF too
            throw Error(d.context + ": \"gltf\": " + e.what());
        }
        scene = std::move(loaded.scene);
        hasCamera = loaded.hasCamera;
    }
    applyMaterials(scene, d);
    if (d.lights) scene.lights = *d.lights;
    scene.lights.insert(scene.lights.end(), d.extraLights.begin(), d.extraLights.end());
    scene.computeCaps();  // bounds for a framing camera
    applyCamera(scene, d, hasCamera);
    if (d.scale != 1.0) applyScale(scene, d.scale);
    if (d.translate != glm::dvec3(0.0)) translateScene(scene, d.translate);
    if (d.resolution) {
        scene.settings.width = d.resolution->x;
        scene.settings.height = d.resolution->y;
    }
    if (d.exposureEv) scene.settings.exposureEv = *d.exposureEv;
    scene.animation = resolveAnimation(d, scene);  // the lights and camera are final
    // A loaded scene shows frame 0 (tracks own what they animate, so later frames are unaffected)
    if (scene.animation.animated()) applyFrameState(scene, frameState(scene, 0));
    return scene;
}

}  // namespace

Camera makeFramingCamera(const Bounds& bounds) {
    Camera cam;
    if (!bounds.valid()) return cam;
    const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
    const float distance = radius / std::sin(0.5f * cam.vfovRad);
    cam.target = bounds.center();
    cam.position = cam.target + glm::vec3(0.0f, 0.0f, distance);
    cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
    cam.nearZ = std::max(1e-3f, 1e-3f * distance);
    cam.farZ = std::max(1000.0f, 4.0f * (distance + radius));
    return cam;
}

Scene loadScene(const std::string& spec) {
    if (spec.empty() || spec == "builtin") return makeBuiltinDefaultScene();
    const size_t hash = spec.rfind('#');
    const std::string file = spec.substr(0, hash);
    std::string ext = fs::path(file).extension().string();
    for (char& c : ext)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".gltf" || ext == ".glb") {
        if (hash != std::string::npos)
            throw Error(file + ": a glTF file has no variants (\"#" + spec.substr(hash + 1) +
                        "\"); variants belong to scene descriptions (.json, docs/scenes.md)");
        return loadGltf(file);
    }
    if (ext == ".json") return loadSceneFile(spec);
    throw Error(file + ": not a scene: expected a scene description (.json, optionally " +
                "#variant), a glTF file (.gltf or .glb) or \"builtin\"");
}

Scene loadSceneFile(const std::string& pathWithVariant, const std::string& variantArg) {
    // "file.json#variant" or (file.json, variant)
    std::string path = pathWithVariant, variant = variantArg;
    if (const size_t hash = path.rfind('#'); hash != std::string::npos) {
        const std::string fromPath = path.substr(hash + 1);
        path = path.substr(0, hash);
        if (!variant.empty() && variant != fromPath) {
            throw Error(path + ": variant given twice (\"" + fromPath + "\" and \"" + variant +
                        "\")");
        }
        variant = fromPath;
    }
    nlohmann::json doc = readJson(path);
    const std::string baseDir = fs::path(path).parent_path().string();

    // Validate the base and every variant (cheap: no geometry yet), then pick one
    nlohmann::json variants = nlohmann::json::object();
    if (doc.is_object() && doc.contains("variants")) {
        variants = doc["variants"];
        doc.erase("variants");
        if (!variants.is_object()) JsonNode(variants, path, "variants").fail("expected an object");
    }
    std::map<std::string, SceneDescription> descriptions;
    descriptions.emplace("", parseSceneDescription(JsonNode(doc, path), baseDir));
    for (const auto& item : variants.items()) {
        const std::string context = path + " (variant \"" + item.key() + "\")";
        if (!item.value().is_object()) {
            JsonNode(item.value(), path, "variants." + item.key()).fail("expected an object");
        }
        nlohmann::json merged = doc;
        // A variant's "animation" replaces the base's as a whole (no key-by-key merge)
        if (item.value().contains("animation")) merged.erase("animation");
        merged.merge_patch(item.value());  // RFC 7386: objects merge, null deletes a key
        descriptions.emplace(item.key(), parseSceneDescription(JsonNode(merged, context), baseDir));
    }
    auto selected = descriptions.find(variant);
    if (selected == descriptions.end()) {
        std::string names;
        for (const auto& item : variants.items())
            names += (names.empty() ? "" : ", ") + item.key();
        throw Error(path + ": unknown variant \"" + variant +
                    "\" (available: " + (names.empty() ? "none" : names) + ")");
    }

    Scene scene = buildScene(selected->second);
    const SceneDescription& d = selected->second;
    scene.name = (d.name ? *d.name : fs::path(path).stem().string()) +
                 (variant.empty() ? "" : "#" + variant);
    scene.sourcePath = path;
    scene.loadedFiles.insert(scene.loadedFiles.begin(), path);
    for (const auto& item : variants.items())
        scene.variants.push_back(item.key());
    scene.computeCaps();
    return scene;
}

Scene makeBuiltinDefaultScene() {
    Scene scene = makeCornellBox(CornellBoxParams{});
    scene.name = "cornell_box";
    scene.sourcePath = "<built-in>";
    scene.settings = RenderSettings{};
    scene.settings.width = 128;
    scene.settings.height = 128;
    return scene;
}

}  // namespace gilab
